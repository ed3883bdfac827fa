"""The file-formats guide (docs/guides/file-formats.md): every example file it shows is read back by the real
reader, every configuration snippet loads with those files, and its table of a result's attributes is the one
the runner writes, so that the guide cannot drift from the code (issue 46, point 3)."""

from __future__ import annotations

import re
import types
from pathlib import Path

import pytest

from slidernet.config import build_network, load_config
from slidernet.ensemble import runner
from slidernet.model.files import read_graph
from slidernet.plugins.distributions import Empirical
from slidernet.plugins.drivers import Series

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "guides" / "file-formats.md"
TEXT = GUIDE.read_text(encoding="utf-8")
#: "File `name`:" and the fenced block after it: the example files of the guide, by name.
FILES = dict(re.findall(r"^File `([^`]+)`:\n\n```\w*\n(.*?)^```", TEXT, re.M | re.S))
#: "In the configuration...:" and the TOML block after it, in the guide's order.
SNIPPETS = re.findall(r"^In the configuration[^\n]*:\n\n```toml\n(.*?)^```", TEXT, re.M | re.S)

FRICTION = '[friction]\nmu_d = 0.5\nstatic = { name = "gaussian", mean = 0.6, std = 0.01 }\n'
DRIVER = '[driver]\nname = "gaussian_steps"\nsigma_theta = 1e-6\n'


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for name, text in FILES.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    return tmp_path


def test_the_guide_shows_every_example_this_test_reads():
    assert set(FILES) == {"ring.edgelist", "ring.nodes.csv", "chain.csv", "chain.nodes.csv", "chain.graphml",
                          "mu_s.txt", "mu_s.csv", "temperature.csv"}
    assert len(SNIPPETS) == 3


def test_the_edge_list_and_its_node_file(folder):
    G = read_graph(folder / "ring.edgelist")
    assert list(G.nodes) == [0, 1, 2, 3] and G.number_of_edges() == 4
    assert G.edges[0, 1]["k"] == 2.0 and G.edges[2, 3]["kappa"] == 0.5 and G.edges[0, 3]["k"] == 1.5
    assert G.nodes[1]["normal_load"] == 2.0 and "normal_load" not in G.nodes[0]  # empty: the default, 1
    assert G.nodes[2]["pos"] == (1.0, 1.0)


@pytest.mark.parametrize("name", ["chain.csv", "chain.graphml"])
def test_the_chain_files_read_as_one_chain(folder, name):
    G = read_graph(folder / name)
    assert sorted(G.edges) == [(0, 1), (1, 2)]
    assert G.edges[0, 1]["k"] in (1.0, 2.0) and "k" not in G.edges[1, 2]


def test_the_network_snippet_loads_with_its_file(folder):
    config = folder / "ring.toml"
    config.write_text(f"steps = 10\n{SNIPPETS[0]}{FRICTION}{DRIVER}", encoding="utf-8")
    net = build_network(load_config(config))
    assert net.n_nodes == 4 and net.dim == 2


def test_the_measured_thresholds(folder):
    assert Empirical(folder / "mu_s.txt").values.tolist() == [0.49, 0.58, 0.61, 0.64]
    assert Empirical(folder / "mu_s.csv", column="mu_s").values.tolist() == [0.58, 0.61, 0.64]
    config = folder / "mu_s.toml"
    config.write_text(f"steps = 10\n[network]\nNtilde = 1e-7\n{SNIPPETS[1]}{DRIVER}", encoding="utf-8")
    assert load_config(config).distribution().dist.values.tolist() == [0.58, 0.61, 0.64]


def test_the_temperature_series(folder):
    series = Series(folder / "temperature.csv", kappa=1.2e-5, T0=15.0, tau_th=1.0)
    assert series.time.tolist() == [0, 1, 2, 3, 4] and series.covered_steps == 4
    config = folder / "series.toml"
    config.write_text(f"steps = 4\n[network]\nNtilde = 1e-7\n{FRICTION}{SNIPPETS[2]}", encoding="utf-8")
    assert load_config(config).driver_plugin().temperature.tolist() == [15.2, 14.8, 14.9, 15.6, 16.3]


def test_the_result_attributes_are_those_the_runner_writes():
    section = TEXT.split("The file's attributes, each text:")[1].split("\n\n", 2)[1]
    listed = re.findall(r"^\| `(\w+)` \|", section, re.M)
    cfg = load_config({"steps": 10, "network": {"Ntilde": 1e-7},
                       "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
                       "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
    written = runner._attrs(cfg, types.SimpleNamespace(kernel="pair", tilt_at=None), 1, None, {})
    assert listed == [*written, "mu_eff_at", "mu_eff_estimator"]
