"""Every reader of a data file refuses a row or an element it cannot read whole, naming the file and where
(issue 43, points 5, 6 and 9).

Edge lists and their node files, GraphML, temperature series and measured thresholds: a row with a
field missing or one too many, a field that is not a number, an attribute that is not a number, a node
without its y, a spring listed twice. Each used to be read as something else (an edge CSV row ``2,3``
under the header ``i,j,k`` gave that spring k = 1.0, exit 0; a GraphML parallel edge was merged), or to
end in a traceback (a GraphML ``k`` that is text, a node without ``y``).
"""

from __future__ import annotations

import re
from pathlib import Path

import networkx as nx
import pytest

from slidernet.config import load_config
from slidernet.errors import ConfigError
from slidernet.model.builders import from_graph, read_graph
from slidernet.plugins.distributions import Empirical
from slidernet.plugins.drivers import Series

NT = 1e-7
NODES_1D = "node,x\n0,0\n1,1\n2,2\n"


def _write(folder: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (folder / name).write_text(text)


# (id, file read, files, pattern of the message): edge lists and node files.
EDGE_LISTS = [
    ("csv-row-missing-k", "net.csv", {"net.csv": "i,j,k\n0,1,2.0\n1,2\n", "net.nodes.csv": NODES_1D},
     r"net\.csv, line 3: 2 fields; the header i,j,k has 3\."),
    ("csv-row-extra-field", "net.csv", {"net.csv": "i,j,k\n0,1,2.0,7\n", "net.nodes.csv": NODES_1D},
     r"net\.csv, line 2: 4 fields; the header i,j,k has 3\."),
    ("csv-k-not-a-number", "net.csv", {"net.csv": "i,j,k\n0,1,stiff\n", "net.nodes.csv": NODES_1D},
     r"net\.csv, line 2: 'k' must be a number\. Got 'stiff' instead\."),
    ("csv-k-underscore", "net.csv", {"net.csv": "i,j,k\n0,1,1_0\n", "net.nodes.csv": NODES_1D},
     r"net\.csv, line 2: 'k' must be a number\. Got '1_0' instead\."),
    ("csv-self-loop", "net.csv", {"net.csv": "i,j\n0,1\n1,1\n", "net.nodes.csv": NODES_1D},
     r"net\.csv, line 3: the spring \(1, 1\) joins node 1 to itself\."),
    ("nodes-row-missing-x", "net.csv", {"net.csv": "i,j\n0,1\n", "net.nodes.csv": "node,x,y\n0,0,0\n1,1\n"},
     r"net\.nodes\.csv, line 3: 2 fields; the header node,x,y has 3\."),
    ("nodes-row-extra-field", "net.csv", {"net.csv": "i,j\n0,1\n", "net.nodes.csv": "node,x\n0,0\n1,1,5\n"},
     r"net\.nodes\.csv, line 3: 3 fields; the header node,x has 2\."),
    ("nodes-empty-x", "net.csv", {"net.csv": "i,j\n0,1\n", "net.nodes.csv": "node,x\n0,0\n1,\n"},
     r"net\.nodes\.csv, line 3: 'x' must be a number\. Got '' instead\."),
    ("nodes-load-not-finite", "net.csv", {"net.csv": "i,j\n0,1\n",
                                          "net.nodes.csv": "node,x,normal_load\n0,0,1\n1,1,inf\n"},
     r"net\.nodes\.csv, line 3: 'normal_load' must be finite\. Got 'inf' instead\."),
    ("text-key-twice", "net.txt", {"net.txt": "0 1 k=2 k=3\n", "net.nodes.csv": NODES_1D},
     r"net\.txt, line 1: the spring attribute 'k' is given twice\."),
    ("text-dict-boolean", "net.txt", {"net.txt": "0 1 {'k': True}\n", "net.nodes.csv": NODES_1D},
     r"net\.txt, line 1: 'k' must be a number\. Got True instead\."),
    ("text-self-loop", "net.txt", {"net.txt": "0 1\n2 2\n", "net.nodes.csv": NODES_1D},
     r"net\.txt, line 2: the spring \(2, 2\) joins node 2 to itself\."),
]


@pytest.mark.parametrize(("name", "files", "match"), [c[1:] for c in EDGE_LISTS], ids=[c[0] for c in EDGE_LISTS])
def test_an_edge_list_or_node_file_refuses_a_row_it_cannot_read_whole(tmp_path, name, files, match):
    _write(tmp_path, files)
    with pytest.raises(ConfigError, match=match):
        read_graph(tmp_path / name)


def test_an_empty_cell_takes_the_default_and_a_full_row_reads(tmp_path):
    _write(tmp_path, {"net.csv": "i,j,k\n0,1,2.0\n1,2,\n",
                      "net.nodes.csv": "node,x,normal_load\n0,0,\n1,1,2.0\n2,2,\n"})
    net = from_graph(read_graph(tmp_path / "net.csv"), NT)
    assert net.k.tolist() == [2.0, 1.0] and net.normal_load.tolist() == [1.0, 2.0, 1.0]


def test_the_issue_s_csv_is_refused_through_the_configuration(tmp_path):
    # The new user's file: header i,j,k, a row '2,3' (its k forgotten): k = 1.0 and exit 0 before.
    _write(tmp_path, {"net.csv": "i,j,k\n0,1,2.0\n1,2,2.0\n2,3\n", "net.nodes.csv": NODES_1D + "3,3\n"})
    cfg = {"steps": 5, "network": {"kind": "graph", "path": str(tmp_path / "net.csv"), "Ntilde": NT},
           "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}
    with pytest.raises(ConfigError, match=r"net\.csv, line 4: 2 fields; the header i,j,k has 3\."):
        load_config(cfg).network.build()


def _graphml(path: Path, graph: nx.Graph) -> Path:
    nx.write_graphml(graph, path)
    return path


def _pair(**edge: object) -> nx.Graph:
    G = nx.Graph()
    G.add_node(0, x=0.0, y=0.0)
    G.add_node(1, x=1.0, y=0.0)
    G.add_edge(0, 1, **edge)
    return G


def _string_load() -> nx.Graph:
    G = _pair()
    G.nodes[1]["normal_load"] = "heavy"
    return G


def _no_y() -> nx.Graph:
    G = _pair()
    del G.nodes[1]["y"]
    return G


def _parallel() -> nx.MultiGraph:
    G = nx.MultiGraph(_pair(k=1.0))
    G.add_edge(0, 1, k=2.0)
    return G


def _both_directions() -> nx.DiGraph:
    G = nx.DiGraph(_pair())
    G.add_edge(1, 0)
    return G


def _nan_k() -> nx.Graph:
    return _pair(k=float("nan"))


def _boolean_kappa() -> nx.Graph:
    return _pair(kappa=True)


def _unknown_attribute() -> nx.Graph:
    return _pair(K=2.0)


def _self_loop() -> nx.Graph:
    G = _pair()
    G.add_edge(1, 1)
    return G


GRAPHML = [
    ("string-k", lambda: _pair(k="stiff"), r"edge \(0, 1\): 'k' must be a number\. Got 'stiff' instead\."),
    ("string-normal-load", _string_load, r"node 1: 'normal_load' must be a number\. Got 'heavy' instead\."),
    ("node-without-y", _no_y, r"node 1 has 'x' but no 'y', while node 0 has both"),
    ("parallel-edge", _parallel, r"the spring \(0, 1\) is listed twice"),
    ("both-directions", _both_directions, r"the spring \(1, 0\) is listed twice"),
    ("nan-k", _nan_k, r"edge \(0, 1\): 'k' must be finite\. Got nan instead\."),
    ("boolean-kappa", _boolean_kappa, r"edge \(0, 1\): 'kappa' must be a number\. Got True instead\."),
    ("unknown-attribute", _unknown_attribute, r"edge \(0, 1\): unknown attribute 'K'; a spring takes 'k', "
                                              r"'kappa', 'rest_length'"),
    ("self-loop", _self_loop, r"the spring \(1, 1\) joins node 1 to itself"),
]


@pytest.mark.parametrize(("make", "match"), [c[1:] for c in GRAPHML], ids=[c[0] for c in GRAPHML])
def test_a_graphml_file_refuses_an_element_it_cannot_read_naming_file_and_element(tmp_path, make, match):
    path = _graphml(tmp_path / "net.graphml", make())
    with pytest.raises(ConfigError, match=rf"The GraphML file '{re.escape(str(path))}': {match}"):
        from_graph(read_graph(path), NT)


def test_a_graphml_number_written_as_text_is_read(tmp_path):
    path = _graphml(tmp_path / "net.graphml", _pair(k="2.5"))
    assert from_graph(read_graph(path), NT).k.tolist() == [2.5]


# Temperature series (the driver 'series') and measured thresholds ('empirical').
def test_a_series_names_the_line_of_a_value_that_is_not_finite(tmp_path):
    path = tmp_path / "T.csv"
    path.write_text("hour,celsius\n0,20.0\n1,nan\n2,21.0\n")
    with pytest.raises(ConfigError, match=r"T\.csv' of the series driver: line 3: 'temperature' must be finite\. "
                                          r"Got 'nan' instead\."):
        Series(path, kappa=1e-5, T0=20.0, tau_th=1.0)


def test_a_series_refuses_a_row_with_a_field_missing(tmp_path):
    path = tmp_path / "T.csv"
    path.write_text("0,20.0\n1\n2,21.0\n")
    with pytest.raises(ConfigError, match=r"line 2 has 1 columns; expected 2"):
        Series(path, kappa=1e-5, T0=20.0, tau_th=1.0)


def test_measured_thresholds_refuse_a_row_wider_than_the_table(tmp_path):
    path = tmp_path / "mu_s.csv"
    path.write_text("sample,mu_s\na,0.6\nb,0.7,0.9\nc,0.65\n")
    with pytest.raises(ConfigError, match=r"mu_s\.csv', line 3: 3 fields; the first line has 2\."):
        Empirical(path, column="mu_s")


def test_measured_thresholds_refuse_a_value_that_is_not_a_number(tmp_path):
    path = tmp_path / "mu_s.txt"
    path.write_text("0.6\n0.7\n0_8\n")
    with pytest.raises(ConfigError, match=r"mu_s\.txt', line 3: the value must be a number\. Got '0_8' instead\."):
        Empirical(path)
