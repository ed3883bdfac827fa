"""The two rules of a scene: the pair kernel (Network.is_two_slider) and the appendix's tilt test
(pair_tilt_applies). The checks of a configuration and the scene must give the same answer for every
network, since both ask the network built from it."""

from __future__ import annotations

import pytest

from slidernet.config import PAIR_TILT_ONLY, build_network, choose_tilt_at, load_config
from slidernet.errors import ConfigError
from slidernet.model.network import chain, pair_tilt_applies
from slidernet.solver import Scene
from tests.conftest import make_config

NETWORKS = {
    "two_slider": {"kind": "two_slider"},
    "two_slider-n2": {"kind": "two_slider", "n": 2},
    "chain-of-two": {"kind": "chain", "n": 2},
    "stiffer": {"kind": "two_slider", "k": 2.0},
    "kappa": {"kind": "two_slider", "kappa": 0.5},
    "kappa-one": {"kind": "chain", "n": 2, "kappa": 1.0},
    "heavier": {"kind": "chain", "n": 2, "normal_load": 2.0},
    "f_ext": {"kind": "two_slider", "f_ext": 0.01},
    "f_ext-zero": {"kind": "two_slider", "f_ext": 0.0},
    "incline": {"kind": "two_slider", "incline": 5.0},
    "incline-zero": {"kind": "chain", "n": 2, "incline": 0.0},
    "chain-of-three": {"kind": "chain", "n": 3},
    "square-of-two": {"kind": "square", "shape": [1, 2]},
}


def _graph(tmp_path, dim: int, spacing: float = 1.0) -> dict:
    path = tmp_path / f"pair{dim}.edgelist"
    path.write_text("0 1\n", encoding="utf-8")
    header, row = ("node,x\n", "{},{}\n") if dim == 1 else ("node,x,y\n", "{},{},0.0\n")
    (tmp_path / f"pair{dim}.nodes.csv").write_text(header + row.format(0, 0.0) + row.format(1, spacing),
                                                   encoding="utf-8")
    return {"kind": "graph", "path": str(path)}


def _cases(tmp_path) -> dict[str, dict]:
    return {**NETWORKS, "graph-1d": _graph(tmp_path, 1), "graph-1d-longer": _graph(tmp_path, 1, 2.0),
            "graph-2d": _graph(tmp_path, 2)}


def test_the_configuration_answers_as_the_network_it_builds(tmp_path):
    for name, network in _cases(tmp_path).items():
        cfg = load_config(make_config(steps=10, network={"Ntilde": 1e-7, **network}))
        net = build_network(cfg)
        assert cfg.network.is_two_slider() == net.is_two_slider(), name
        assert cfg.network.pair_tilt_applies() == pair_tilt_applies(net), name
        scene = Scene.from_config(cfg)
        assert (scene.kernel == "pair") == net.is_two_slider(), name
        assert scene.tilt_at == ("rearrangements" if pair_tilt_applies(net) else "records"), name


def test_rearrangements_are_accepted_exactly_where_the_scene_runs_them(tmp_path):
    # A 1D pair read from a graph file used to be refused by the configuration and chosen by the scene.
    for name, network in _cases(tmp_path).items():
        cfg = make_config(steps=10, mu_eff_at="rearrangements", network={"Ntilde": 1e-7, **network})
        if pair_tilt_applies(build_network(load_config({**cfg, "mu_eff_at": "records"}))):
            assert Scene.from_config(load_config(cfg)).tilt_at == "rearrangements", name
        else:
            with pytest.raises(ConfigError, match="needs a 1D pair of sliders"):
                load_config(cfg)


def test_a_graph_file_that_cannot_be_read_is_no_pair(tmp_path):
    cfg = load_config(make_config(steps=10, network={"kind": "graph", "path": str(tmp_path / "none.edgelist"),
                                                     "Ntilde": 1e-7}, **{"mu_eff_at": "records"}))
    assert cfg.network.pair_network() is None
    assert not cfg.network.is_two_slider() and not cfg.network.pair_tilt_applies()


def test_the_pair_kernel_s_scene_is_a_pair_of_the_tilt_test():
    for kwargs in ({}, {"k": 2.0}, {"kappa": 0.3}, {"normal_load": 2.0}, {"f_ext": 0.1}):
        net = chain(2, Ntilde=1e-7, **kwargs)
        assert not net.is_two_slider() or pair_tilt_applies(net)
    assert not pair_tilt_applies(chain(3, Ntilde=1e-7))


def test_a_scene_given_another_network_refuses_the_pair_test_with_the_one_message():
    cfg = load_config(make_config(steps=10, mu_eff_at="rearrangements"))
    with pytest.raises(ConfigError) as info:
        Scene.from_config(cfg, network=chain(2, Ntilde=1e-7, normal_load=2.0))
    assert str(info.value) == f"The 'mu_eff_at' field: {PAIR_TILT_ONLY}."
    assert choose_tilt_at("records", True) == "records"
