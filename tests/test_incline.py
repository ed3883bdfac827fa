"""A network on an incline (``network.incline``), and sliding away as an outcome of a realization."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import slidernet
from slidernet.cli import main
from slidernet.config import build_network, load_config
from slidernet.errors import ConfigError, SlidAwayWarning
from slidernet.io.checkpoint import load_realization, save_realization
from slidernet.solver import Realization, Scene

MU_D = 0.5


def degrees(slope: float) -> float:
    """The angle whose tangent is ``slope``."""
    return math.degrees(math.atan(slope))


def incline_config(slope: float, network: dict | None = None, **changes) -> dict:
    """Thresholds all 0.6, mu_d = 0.5, a daily cycle: the issue's clean-friction case on a slope."""
    cfg = {"seed": 3, "realizations": 2, "steps": 40, "record": "all",
           "network": {"kind": "chain", "n": 3, "Ntilde": 1e-7, **(network or {})},
           "friction": {"mu_d": MU_D, "static": {"name": "constant", "value": 0.6}},
           "driver": {"name": "sinusoidal", "amplitude": 1e-6, "period": 10.0}}
    if slope is not None:
        cfg["network"]["incline"] = degrees(slope)
    cfg.update(changes)
    return cfg


def realization(cfg: dict, seed: int = 3) -> Realization:
    return Realization(Scene.from_config(load_config(cfg)), np.random.SeedSequence(seed))


# --- the configuration -----------------------------------------------------


@pytest.mark.parametrize(("network", "static", "match"), [
    ({"incline": 95.0}, None, r"'network.incline' field: must be in \[0, 90\) degrees. Got 95.0"),
    ({"incline": -1.0}, None, r"'network.incline' field: must be in \[0, 90\) degrees. Got -1.0"),
    ({"incline": 90.0}, None, r"must be in \[0, 90\) degrees. Got 90.0"),
    ({"incline": math.inf}, None, r"'network.incline' field must be a finite number"),
    ({"incline": math.nan}, None, r"'network.incline' field must be a finite number"),
    ({"incline": 10.0, "f_ext": 0.1}, None, r"'network.incline' and 'network.f_ext' .* one or the other"),
    ({"incline": 31.0}, None, r"'network.incline' field: tan\(31.0 degrees\) = 0.60086.* ends at mu_s = 0.6\b"),
    ({"incline": degrees(0.8)}, {"name": "uniform", "low": 0.4, "high": 0.8}, r"ends at mu_s = 0.8\b"),
], ids=["above-90", "negative", "90", "inf", "nan", "with-f_ext", "steeper-than-constant", "steeper-than-uniform"])
def test_bad_incline_is_refused_naming_the_key(network, static, match):
    cfg = incline_config(None, network)
    if static is not None:
        cfg["friction"]["static"] = static
    with pytest.raises(ConfigError, match=match):
        load_config(cfg)


def test_an_incline_below_the_laws_upper_end_is_accepted():
    load_config(incline_config(None, {"incline": 30.9}))  # tan = 0.5985 < 0.6
    uniform = incline_config(None, {"incline": degrees(0.79)})
    uniform["friction"]["static"] = {"name": "uniform", "low": 0.4, "high": 0.8}
    load_config(uniform)


@pytest.mark.parametrize("network", [
    {"kind": "two_slider", "normal_load": 2.0},
    {"kind": "chain", "n": 4},
    {"kind": "triangular", "shape": [3, 4], "normal_load": 0.5},
    {"kind": "irregular", "n": 12},
], ids=["two_slider", "chain", "triangular", "irregular"])
def test_incline_is_a_downhill_f_ext_of_N_i_tan_alpha(network):
    network = {"Ntilde": 1e-7, **network, "incline": 20.0}
    cfg = load_config(incline_config(None) | {"network": network})
    net = build_network(cfg)
    expected = np.zeros_like(net.f_ext)
    expected[:, 0] = math.tan(math.radians(20.0)) * net.normal_load
    np.testing.assert_array_equal(net.f_ext, expected)
    assert not net.is_two_slider()
    scene = Scene.from_config(cfg)
    assert scene.kernel == ("csr" if net.dim == 1 else "vec")
    assert scene.records_slide and not scene.slide_away  # tan(20 deg) = 0.364 < mu_d


def test_the_resolved_config_records_the_incline_and_a_horizontal_one_dumps_as_before():
    cfg = load_config(incline_config(0.3))
    assert cfg.model_dump(mode="json")["network"]["incline"] == degrees(0.3)
    assert "incline" not in load_config(incline_config(None)).model_dump(mode="json")["network"]


# --- sliding away --------------------------------------------------------------


def test_a_chain_on_a_slope_above_mu_d_slides_away_and_stops():
    cfg = incline_config(0.55, observables=["n", "mu_max", "x_G", "events"])
    real = realization(cfg).advance()
    res = real.result()
    assert real.slid_away and real.step == cfg["steps"]
    at = float(res["slid_away_at"])
    assert 0.0 < at < cfg["steps"]
    # It stopped in the avalanche that set the 3 nodes in motion, not after max_avalanche slips.
    assert res["n"][-1] <= 3 * 3
    events = res["events"]
    assert set(events["node"][events["avalanche"] == events["avalanche"][-1]].tolist()) == {0, 1, 2}
    assert events["time"][-1] == at
    # The records from the slide on hold the state of that moment.
    t = Scene.from_config(load_config(cfg)).out_steps
    after = t >= at
    for name in ("n", "x_G", "mu_max"):
        assert (res[name][after] == res[name][after][0]).all(), name
    assert res["x_G"][after][0] > 0.0  # downhill
    # Advancing a realization that slid away does nothing.
    before = {k: np.copy(v) for k, v in res.items() if k != "events"}
    real.advance()
    for k, v in before.items():
        np.testing.assert_array_equal(real.result()[k], v)


def test_a_chain_on_a_slope_below_mu_d_never_slides_away():
    ds = slidernet.run(incline_config(0.45))
    assert np.isnan(ds["slid_away_at"].values).all()
    assert ds["slid_away_at"].dims == ("realization",)
    assert ds["n"].values[:, -1].min() > 100  # it crept on through the whole run


def test_a_lattice_on_a_slope_above_mu_d_slides_away():
    cfg = incline_config(0.55, {"kind": "triangular", "shape": [6, 6]}, steps=20)
    del cfg["network"]["n"]
    real = realization(cfg).advance()
    res = real.result()
    assert real.slid_away and np.isfinite(res["slid_away_at"])
    assert res["n"][-1] < 100 * 36
    assert (res["y_G"] == res["y_G"][-1]).sum() >= 1


def test_a_uniform_f_ext_above_mu_d_that_moves_every_node_at_t0_slides_away_at_t0():
    # Before sliding away existed this relaxed to rest after 8 slips (one slider with mu_s < 0.55
    # set the whole chain in motion); by the tilt test's rule that is the network sliding away.
    cfg = incline_config(None, {"kind": "chain", "n": 8, "f_ext": 0.55})
    cfg["friction"]["static"] = {"name": "gaussian", "mean": 0.6, "std": 0.05}
    real = realization(cfg).advance(0)
    assert real.slid_away and real.result()["slid_away_at"] == 0.0
    assert real.n == 8


def test_an_avalanche_past_max_avalanche_on_a_slope_above_mu_d_is_sliding_away():
    cfg = incline_config(0.55, solver={"max_avalanche": 1})
    real = realization(cfg).advance()
    assert real.slid_away


def test_a_run_that_all_slid_away_says_so_once(tmp_path, capsys):
    cfg = incline_config(0.55)
    with pytest.warns(SlidAwayWarning, match=r"Every realization \(2\) slid away"):
        ds = slidernet.run(cfg)
    assert np.isfinite(ds["slid_away_at"].values).all()
    path = tmp_path / "incline.toml"
    path.write_text(
        f"seed = 3\nrealizations = 2\nsteps = 40\n"
        f"[network]\nkind = \"chain\"\nn = 3\nNtilde = 1e-7\nincline = {degrees(0.55)!r}\n"
        f"[friction]\nmu_d = 0.5\n[friction.static]\nname = \"constant\"\nvalue = 0.6\n"
        f"[driver]\nname = \"sinusoidal\"\namplitude = 1e-6\nperiod = 10.0\n"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", SlidAwayWarning)  # the CLI says it in its own line, not as a warning
        assert main(["run", str(path), "--out", str(tmp_path / "out"), "--workers", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line for line in lines if "slid away" in line] == [
        next(line for line in lines if line.startswith("slidernet: every realization (2) slid away"))]


def test_no_warning_when_one_realization_holds():
    cfg = incline_config(0.45)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SlidAwayWarning)
        slidernet.run(cfg)


def test_a_realization_that_slid_away_survives_a_checkpoint(tmp_path):
    cfg = incline_config(0.55)
    scene = Scene.from_config(load_config(cfg))
    real = Realization(scene, np.random.SeedSequence(3)).advance()
    path = save_realization(real, tmp_path / "partial.npz", {})
    back = load_realization(scene, np.random.SeedSequence(3), path, {})
    assert back.slid_away and back.step == cfg["steps"]
    np.testing.assert_array_equal(back.advance().result()["x_G"], real.result()["x_G"])
    assert back.result()["slid_away_at"] == real.result()["slid_away_at"]
