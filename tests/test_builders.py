"""Tests of slidernet.model.builders: lattices, Delaunay networks, graph files and the build dispatch.

Geometry and linear-elasticity checks (docs/model.md section 2): lattice springs all
have length 1, the thermal load g = B^T (k L kappa) vanishes on interior nodes
of a uniform lattice, forces are invariant under rigid-body motions (K u = 0
and g . u = 0 for translations and the infinitesimal rotation).
"""

from __future__ import annotations

import csv
import math
import re

import networkx as nx
import numpy as np
import pytest
import scipy.spatial

from slidernet import ConfigError
from slidernet.model.builders import (
    KINDS,
    build,
    from_graph,
    irregular,
    read_graph,
    square,
    triangular,
    write_graph,
)
from slidernet.model.network import Network, chain

NT = 1e-7
LATTICES = {"square": square, "triangular": triangular}
FULL_DEGREE = {"square": 4, "triangular": 6}


def n_edges_expected(kind: str, rows: int, cols: int) -> int:
    if kind == "square":
        return rows * (cols - 1) + cols * (rows - 1)
    return rows * (cols - 1) + (rows - 1) * (2 * cols - 1)


def degrees(net: Network) -> np.ndarray:
    return np.bincount(net.edges.ravel(), minlength=net.n_nodes)


def interior_mask(rows: int, cols: int) -> np.ndarray:
    row, col = np.divmod(np.arange(rows * cols), cols)
    return (row > 0) & (row < rows - 1) & (col > 0) & (col < cols - 1)


def rigid_modes(net: Network) -> dict[str, np.ndarray]:
    """Node-major displacement vectors of the 2D rigid-body motions."""
    x, y = net.positions[:, 0], net.positions[:, 1]
    one, zero = np.ones(net.n_nodes), np.zeros(net.n_nodes)
    return {
        "tx": np.column_stack([one, zero]).ravel(),
        "ty": np.column_stack([zero, one]).ravel(),
        "rot": np.column_stack([-y, x]).ravel(),
    }


def zero_mode_count(net: Network) -> int:
    eig = np.linalg.eigvalsh(net.stiffness_matrix().toarray())
    return int((np.abs(eig) < 1e-9 * eig.max()).sum())


def same_network(a: Network, b: Network) -> None:
    for name in ("positions", "edges", "k", "kappa", "rest_length", "normal_load"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.Ntilde == b.Ntilde


def heterogeneous(seed: int = 3) -> Network:
    """An irregular network with random per-spring and per-slider values (exercises exact round trips)."""
    rng = np.random.default_rng(seed)
    base = irregular(25, NT, np.random.default_rng(seed))
    return irregular(25, NT, np.random.default_rng(seed), k=rng.uniform(0.5, 2, base.n_edges),
                     kappa=rng.uniform(-1, 1, base.n_edges), rest_length=rng.uniform(0.5, 2, base.n_edges),
                     normal_load=rng.uniform(0.5, 2, base.n_nodes))


SHAPES = [(1, 2), (2, 1), (1, 5), (5, 1), (2, 2), (4, 5), (5, 4), (6, 7), (7, 6)]
LATTICE_CASES = [pytest.param(kind, shape, id=f"{kind}-{shape[0]}x{shape[1]}")
                 for kind in LATTICES for shape in SHAPES]


# --------------------------------------------------------------------------
# Lattice geometry
# --------------------------------------------------------------------------


@pytest.mark.parametrize(("kind", "shape"), LATTICE_CASES)
def test_lattice_counts_lengths_and_order(kind, shape):
    rows, cols = shape
    net = LATTICES[kind](shape, NT)
    assert (net.n_nodes, net.dim) == (rows * cols, 2)
    assert net.n_edges == n_edges_expected(kind, rows, cols)
    lengths = np.linalg.norm(np.diff(net.positions[net.edges], axis=1)[:, 0], axis=1)
    np.testing.assert_allclose(lengths, 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(net.rest_length, 1.0, rtol=0, atol=1e-12)
    i, j = net.edges.T
    assert (i < j).all()
    key = i * net.n_nodes + j
    assert (np.diff(key) > 0).all(), "edges must be unique and sorted lexicographically"


@pytest.mark.parametrize("kind", LATTICES)
def test_lattice_node_positions_follow_row_major_index(kind):
    rows, cols = 4, 3
    net = LATTICES[kind]((rows, cols), NT)
    row, col = np.divmod(np.arange(rows * cols), cols)
    if kind == "square":
        expected = np.column_stack([col, row]).astype(float)
    else:
        expected = np.column_stack([col + 0.5 * (row % 2), row * math.sqrt(3) / 2])
    np.testing.assert_array_equal(net.positions, expected)


@pytest.mark.parametrize(("kind", "shape"), [c for c in LATTICE_CASES if min(c.values[1]) >= 3])
def test_lattice_degree_is_full_exactly_on_interior(kind, shape):
    net = LATTICES[kind](shape, NT)
    deg = degrees(net)
    full = deg == FULL_DEGREE[kind]
    np.testing.assert_array_equal(full, interior_mask(*shape))
    assert deg.max() == FULL_DEGREE[kind] and deg.min() >= 2


@pytest.mark.parametrize(("kind", "histogram"), [
    pytest.param("square", {2: 4, 3: 4, 4: 1}, id="square-3x3"),
    # Odd rows are shifted right, so the lattice is a rhombus-like patch with
    # zig-zag sides: (1, 0) has 5 neighbours, the corners (0, 0) and (2, 0) only 2.
    pytest.param("triangular", {2: 2, 3: 3, 4: 2, 5: 1, 6: 1}, id="triangular-3x3"),
])
def test_lattice_degree_histogram(kind, histogram):
    deg = degrees(LATTICES[kind]((3, 3), NT))
    values, counts = np.unique(deg, return_counts=True)
    assert dict(zip(values.tolist(), counts.tolist(), strict=True)) == histogram


# --------------------------------------------------------------------------
# Linear elasticity: thermal load and stiffness matrix
# --------------------------------------------------------------------------


@pytest.mark.parametrize(("kind", "shape"), [c for c in LATTICE_CASES if min(c.values[1]) >= 3])
def test_thermal_load_vanishes_on_interior_only(kind, shape):
    net = LATTICES[kind](shape, NT)
    g = net.thermal_load().reshape(-1, 2)
    size = np.linalg.norm(g, axis=1)
    interior = interior_mask(*shape)
    np.testing.assert_allclose(size[interior], 0.0, atol=1e-12)
    assert (size[~interior] > 0.1).all(), "every boundary slider feels the dilation"


NETWORKS_2D = [
    pytest.param(lambda: square((4, 5), NT), id="square-4x5"),
    pytest.param(lambda: triangular((4, 5), NT), id="triangular-4x5"),
    pytest.param(lambda: irregular(30, NT, np.random.default_rng(5)), id="irregular-30"),
    pytest.param(heterogeneous, id="irregular-heterogeneous"),
]


@pytest.mark.parametrize("make", NETWORKS_2D)
def test_rigid_motions_cost_no_force(make):
    net = make()
    K = net.stiffness_matrix()
    g = net.thermal_load()
    np.testing.assert_allclose(np.asarray(K.sum(axis=1)).ravel(), 0.0, atol=1e-12)
    np.testing.assert_allclose(g.reshape(-1, 2).sum(axis=0), 0.0, atol=1e-11)
    for name, mode in rigid_modes(net).items():
        np.testing.assert_allclose(K @ mode, 0.0, atol=1e-10, err_msg=name)
        assert abs(g @ mode) < 1e-9, f"g does work along {name}"


@pytest.mark.parametrize("make", NETWORKS_2D)
def test_stiffness_symmetric_positive_semidefinite(make):
    K = make().stiffness_matrix().toarray()
    np.testing.assert_allclose(K, K.T, rtol=0, atol=1e-14)
    eig = np.linalg.eigvalsh(K)
    assert eig.min() > -1e-10 * eig.max()


@pytest.mark.parametrize("make", [
    *NETWORKS_2D, pytest.param(lambda: chain(7, NT, k=np.arange(1.0, 7.0)), id="chain-7-graded"),
])
def test_block_assembly_equals_the_sparse_product(make):
    """The compiled row-by-row assembly gives B^T diag(k) B, with sorted rows holding K_ii."""
    net = make()
    K = net.stiffness_blocks()
    np.testing.assert_allclose(K.toarray(), net.stiffness_matrix().toarray(), rtol=1e-15, atol=1e-15)
    rows = np.repeat(np.arange(net.n_nodes), np.diff(K.indptr))
    assert (np.diff(K.indices)[np.diff(rows) == 0] > 0).all()
    assert np.bincount(rows[K.indices == rows], minlength=net.n_nodes).tolist() == [1] * net.n_nodes


def test_parallel_springs_are_summed():
    net = Network(positions=[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], edges=[[0, 1], [1, 0], [0, 2]], Ntilde=NT)
    np.testing.assert_allclose(net.stiffness_blocks().toarray(), net.stiffness_matrix().toarray())
    assert net.stiffness_blocks().toarray()[0, 0] == 2.0


@pytest.mark.parametrize(("make", "zero_modes"), [
    pytest.param(lambda: triangular((4, 5), NT), 3, id="triangular-4x5"),
    pytest.param(lambda: triangular((2, 2), NT), 3, id="triangular-2x2"),
    pytest.param(lambda: irregular(30, NT, np.random.default_rng(5)), 3, id="irregular-30"),
    pytest.param(heterogeneous, 3, id="irregular-heterogeneous"),
    # Central nearest-neighbour springs on a square lattice: x motions couple only
    # along rows and y motions only along columns, so rows + cols independent chains.
    pytest.param(lambda: square((4, 5), NT), 4 + 5, id="square-4x5-floppy"),
])
def test_zero_modes(make, zero_modes):
    assert zero_mode_count(make()) == zero_modes


# --------------------------------------------------------------------------
# Overrides
# --------------------------------------------------------------------------


@pytest.mark.parametrize("kind", LATTICES)
def test_per_item_override_arrays_are_applied(kind):
    shape = (3, 4)
    E, N = n_edges_expected(kind, *shape), 12
    k = np.linspace(0.5, 2.0, E)
    kappa = np.linspace(-1.0, 1.0, E)
    rest = np.linspace(0.9, 1.1, E)
    load = np.linspace(1.0, 3.0, N)
    net = LATTICES[kind](shape, NT, k=k, kappa=kappa, rest_length=rest, normal_load=load)
    np.testing.assert_array_equal(net.k, k)
    np.testing.assert_array_equal(net.kappa, kappa)
    np.testing.assert_array_equal(net.rest_length, rest)
    np.testing.assert_array_equal(net.normal_load, load)
    # The thermal load is B^T (k L kappa) with these arrays.
    np.testing.assert_allclose(net.thermal_load(), net.incidence().T @ (k * rest * kappa))


def test_scalar_overrides_broadcast():
    net = triangular((3, 3), NT, k=2.0, kappa=0.5, normal_load=3.0)
    assert set(net.k) == {2.0} and set(net.kappa) == {0.5} and set(net.normal_load) == {3.0}


@pytest.mark.parametrize(("kwargs", "message"), [
    pytest.param({"k": np.ones(5)}, "The 'k' parameter of square must be a number or an array of 17 values "
                 "(one per spring). Got 'an array of shape (5,)' instead.", id="k-length"),
    pytest.param({"normal_load": np.ones(17)}, "The 'normal_load' parameter of square must be a number or an "
                 "array of 12 values (one per slider)", id="normal_load-length"),
    pytest.param({"kapa": 1.0}, "Unknown keyword 'kapa' for square", id="typo"),
])
def test_bad_overrides_refused(kwargs, message):
    with pytest.raises(ConfigError, match=re.escape(message)):
        square((3, 4), NT, **kwargs)


# --------------------------------------------------------------------------
# Shape validation
# --------------------------------------------------------------------------


@pytest.mark.parametrize("kind", LATTICES)
@pytest.mark.parametrize("shape", [
    pytest.param([0, 3], id="zero-rows"),
    pytest.param((3, -1), id="negative"),
    pytest.param((1, 1), id="one-node"),
    pytest.param((3,), id="one-number"),
    pytest.param((2, 3, 4), id="three-numbers"),
    pytest.param((2.5, 3), id="fractional"),
    pytest.param((True, 3), id="bool"),
    pytest.param("ab", id="string"),
    pytest.param(None, id="none"),
    pytest.param(5, id="scalar"),
])
def test_bad_shapes_refused(kind, shape):
    message = (f"The 'shape' parameter of {kind} must be two integers >= 1 with at least 2 nodes. "
               f"Got {shape!r} instead.")
    with pytest.raises(ConfigError, match=re.escape(message)):
        LATTICES[kind](shape, NT)


def test_integral_floats_and_numpy_ints_accepted():
    assert square((2.0, np.int64(3)), NT).n_nodes == 6


# --------------------------------------------------------------------------
# Irregular (Delaunay) networks
# --------------------------------------------------------------------------


def test_irregular_is_deterministic_for_a_seed_and_differs_for_another():
    a = irregular(200, NT, np.random.default_rng(11))
    b = irregular(200, NT, np.random.default_rng(11))
    c = irregular(200, NT, np.random.default_rng(12))
    same_network(a, b)
    assert not np.array_equal(a.positions, c.positions)


def test_irregular_leaves_the_global_rng_alone():
    # The point of this test is the legacy global RNG, hence the NPY002 waivers.
    before = np.random.get_state()[1].copy()  # noqa: NPY002
    irregular(50, NT, np.random.default_rng(1))
    np.testing.assert_array_equal(np.random.get_state()[1], before)  # noqa: NPY002


# The builder numbers the points along strips (for locality); they are the drawn points, and the
# springs are those of their Delaunay triangulation (Qhull called here on the drawn order).
@pytest.mark.parametrize("n", [300, 5000], ids=["n300", "n5000"])
def test_irregular_geometry_and_delaunay_edges(n):
    net = irregular(n, NT, np.random.default_rng(2))
    pos = net.positions
    assert pos.shape == (n, 2)
    assert pos.min() >= 0 and pos.max() < math.sqrt(n)
    drawn = np.random.default_rng(2).uniform(0, math.sqrt(n), (n, 2))
    order = np.lexsort((pos[:, 0], pos[:, 1]))
    np.testing.assert_array_equal(pos[order], drawn[np.lexsort((drawn[:, 0], drawn[:, 1]))])
    # Numbered strip by strip (width 1 l0), each strip along x, alternately rightwards and leftwards.
    strip = np.floor(pos[:, 1])
    assert (np.diff(strip) >= 0).all()
    x = np.where(strip % 2 == 0, pos[:, 0], -pos[:, 0])
    assert (np.diff(x)[np.diff(strip) == 0] > 0).all()
    # Neighbours are close in the numbering: about one strip (sqrt(n) nodes) apart at most, hull aside.
    assert np.median(np.abs(np.diff(net.edges, axis=1))) < 2 * math.sqrt(n)
    perm = np.random.default_rng(3).permutation(n)  # the triangulation does not depend on the order
    pos_shuffled = pos[perm]
    expected = set()
    for s in perm[scipy.spatial.Delaunay(pos_shuffled).simplices].tolist():
        for a, b in ((0, 1), (1, 2), (0, 2)):
            expected.add((min(s[a], s[b]), max(s[a], s[b])))
    assert [tuple(e) for e in net.edges.tolist()] == sorted(expected)
    # Euler: a triangulation of n points with h on the convex hull has 3n - 3 - h edges.
    h = scipy.spatial.ConvexHull(pos).vertices.size
    assert net.n_edges == 3 * n - 3 - h
    np.testing.assert_allclose(net.rest_length, np.linalg.norm(pos[net.edges[:, 1]] - pos[net.edges[:, 0]],
                                                                axis=1))
    # Mean spacing of order l0.
    assert 0.7 < np.median(net.rest_length) < 1.5


@pytest.mark.parametrize(("kwargs", "message"), [
    pytest.param({"n": 2, "rng": np.random.default_rng(0)},
                 "The 'n' parameter of irregular must be an integer >= 3. Got 2 instead.", id="n-small"),
    pytest.param({"n": 10.5, "rng": np.random.default_rng(0)},
                 "The 'n' parameter of irregular must be an integer >= 3. Got 10.5 instead.", id="n-fraction"),
    pytest.param({"n": 10, "rng": 42},
                 "The 'rng' parameter of irregular must be a numpy.random.Generator. Got 'int' instead.",
                 id="seed-not-generator"),
])
def test_irregular_bad_arguments(kwargs, message):
    with pytest.raises(ConfigError, match=re.escape(message)):
        irregular(Ntilde=NT, **kwargs)


# --------------------------------------------------------------------------
# Graph files
# --------------------------------------------------------------------------


ROUND_TRIP_NETS = [
    pytest.param(heterogeneous, id="irregular-heterogeneous"),
    pytest.param(lambda: triangular((3, 4), NT, k=np.arange(1.0, 24.0)), id="triangular-k-array"),
    pytest.param(lambda: chain(5, NT, kappa=[0.1, 0.2, 0.3, 0.4], normal_load=2.0), id="chain-1d"),
]


@pytest.mark.parametrize("make", ROUND_TRIP_NETS)
@pytest.mark.parametrize("suffix", [".graphml", ".edgelist", ".txt", ".csv"])
def test_write_graph_read_graph_round_trip(tmp_path, make, suffix):
    net = make()
    written = write_graph(net, tmp_path / f"net{suffix}")
    assert all(p.is_file() for p in written)
    same_network(from_graph(read_graph(written[0]), NT), net)


@pytest.mark.parametrize("make", ROUND_TRIP_NETS)
def test_graphml_written_by_networkx(tmp_path, make):
    net = make()
    G = net.to_networkx()
    for _, data in G.nodes(data=True):
        data.update(zip("xy", data.pop("pos"), strict=False))
    path = tmp_path / "net.graphml"
    nx.write_graphml(G, path)
    same_network(from_graph(read_graph(path), NT), net)


def write_nodes_csv(path, net: Network) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["node", *"xy"[: net.dim], "normal_load"])
        for v, (pos, load) in enumerate(zip(net.positions.tolist(), net.normal_load.tolist(), strict=True)):
            w.writerow([v, *pos, load])


@pytest.mark.parametrize("make", ROUND_TRIP_NETS)
def test_edgelist_written_by_networkx(tmp_path, make):
    net = make()
    path = tmp_path / "net.edgelist"
    nx.write_edgelist(net.to_networkx(), path)  # default: "i j {'k': .., ...}" lines
    write_nodes_csv(tmp_path / "net.nodes.csv", net)
    same_network(from_graph(read_graph(path), NT), net)


def test_edgelist_key_value_format_and_positions_argument(tmp_path):
    path = tmp_path / "springs.txt"
    path.write_text("# a hand-written network\n0 1 k=2.0 kappa=0.5\n\n1 2   # defaults\n0 2 rest_length=3\n")
    pos = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
    net = from_graph(read_graph(path, positions=pos), NT)
    # Springs come in networkx's G.edges order (by first endpoint), not file order.
    assert net.edges.tolist() == [[0, 1], [0, 2], [1, 2]]
    assert net.k.tolist() == [2.0, 1.0, 1.0]
    assert net.kappa.tolist() == [0.5, 1.0, 1.0]
    np.testing.assert_allclose(net.rest_length, [1.0, 3.0, math.sqrt(2)])
    np.testing.assert_array_equal(net.positions, pos)


def test_csv_edge_list_with_source_target_header(tmp_path):
    (tmp_path / "g.csv").write_text("source,target,k\n0,1,2.5\n1,2,\n")
    (tmp_path / "g.nodes.csv").write_text("node,x\n0,0\n1,1\n2,3\n")
    net = from_graph(read_graph(tmp_path / "g.csv"), NT)
    assert net.dim == 1 and net.k.tolist() == [2.5, 1.0]
    np.testing.assert_array_equal(net.rest_length, [1.0, 2.0])


def test_overrides_replace_file_values(tmp_path):
    path = write_graph(heterogeneous(), tmp_path / "net.graphml")[0]
    net = from_graph(read_graph(path), NT, k=4.0, normal_load=2.0)
    assert set(net.k) == {4.0} and set(net.normal_load) == {2.0}


@pytest.mark.parametrize(("name", "files", "message"), [
    pytest.param("absent.graphml", {}, "The network file", id="missing-file"),
    pytest.param("net.gml", {"net.gml": ""}, "unknown extension '.gml'", id="unknown-extension"),
    pytest.param("net.edgelist", {"net.edgelist": "0 1\n"}, "has no positions: pass positions, or write them "
                 "to", id="edgelist-without-positions"),
    pytest.param("net.graphml", {"net.graphml": None}, "Node 0 of", id="graphml-without-xy"),
    pytest.param("net.txt", {"net.txt": "0 1 k:2\n", "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "line 1: expected key=value after 'i j'. Got 'k:2' instead.", id="bad-token"),
    pytest.param("net.txt", {"net.txt": "0 1 stiffness=2\n", "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "unknown spring attribute 'stiffness'", id="unknown-attribute"),
    pytest.param("net.txt", {"net.txt": "0 1 k=abc\n", "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "line 1: 'k' must be a number. Got 'abc' instead.", id="bad-number"),
    pytest.param("net.txt", {"net.txt": "0 1\n1 5\n", "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "line 2: node 5 has no position.", id="unknown-node"),
    pytest.param("net.txt", {"net.txt": "0 1\n1 0\n", "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "line 2: the spring (1, 0) is listed twice.", id="duplicate-spring"),
    pytest.param("net.txt", {"net.txt": "a 1\n", "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "line 1: i must be an integer node id. Got 'a' instead.", id="bad-node-id"),
    pytest.param("net.csv", {"net.csv": "a,b\n0,1\n", "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "needs the header i,j (or source,target)", id="bad-csv-header"),
    pytest.param("net.txt", {"net.txt": "0 1\n", "net.nodes.csv": "id,x\n0,0\n1,1\n"},
                 "needs the header node,x[,y][,normal_load]", id="bad-nodes-header"),
    # Issue 37: a folder was "a network file that does not exist"; a Latin-1 file a UnicodeDecodeError.
    pytest.param("net.graphml", {"net.graphml": "folder"}, "is a folder, not a file.", id="a-folder"),
    pytest.param("net.txt", {"net.txt": "# r\xe9seau\n0 1\n".encode("latin-1"),
                             "net.nodes.csv": "node,x\n0,0\n1,1\n"},
                 "net.txt' is not UTF-8 text: byte 0xe9 on line 1 cannot be decoded. Save it as UTF-8.",
                 id="edge-list-not-utf8"),
    pytest.param("net.txt", {"net.txt": "0 1\n", "net.nodes.csv": "node,x\n0,0\n\xe91,1\n".encode("latin-1")},
                 "net.nodes.csv' is not UTF-8 text: byte 0xe9 on line 3", id="nodes-file-not-utf8"),
])
def test_read_graph_errors(tmp_path, name, files, message):
    for fname, text in files.items():
        if text is None:  # a GraphML file whose nodes have no positions
            nx.write_graphml(nx.path_graph(3), tmp_path / fname)
        elif text == "folder":
            (tmp_path / fname).mkdir()
        elif isinstance(text, bytes):
            (tmp_path / fname).write_bytes(text)
        else:
            (tmp_path / fname).write_text(text)
    with pytest.raises(ConfigError, match=re.escape(message)):
        read_graph(tmp_path / name)


def test_read_graph_positions_of_wrong_length(tmp_path):
    path = tmp_path / "net.graphml"
    nx.write_graphml(nx.path_graph(3), path)
    with pytest.raises(ConfigError, match=re.escape("one position per node")):
        read_graph(path, positions=[0.0, 1.0])
    G = read_graph(path, positions=[0.0, 1.0, 2.0])
    assert from_graph(G, NT).positions.ravel().tolist() == [0.0, 1.0, 2.0]


# --------------------------------------------------------------------------
# build(): the configuration layer's entry point
# --------------------------------------------------------------------------


@pytest.mark.parametrize(("kind", "params", "expected"), [
    pytest.param("two_slider", {}, two_slider_net := chain(2, NT), id="two_slider"),
    pytest.param("two_slider", {"n": 2}, two_slider_net, id="two_slider-n2"),
    pytest.param("chain", {"n": 4, "k": 2.0}, chain(4, NT, k=2.0), id="chain"),
    pytest.param("square", {"shape": [3, 4]}, square((3, 4), NT), id="square"),
    pytest.param("triangular", {"shape": (3, 4), "kappa": 0.5, "normal_load": None},
                 triangular((3, 4), NT, kappa=0.5), id="triangular-none-ignored"),
    pytest.param("irregular", {"n": 40}, irregular(40, NT, np.random.default_rng(9)), id="irregular"),
])
def test_build_dispatch(kind, params, expected):
    same_network(build(kind, params, NT, np.random.default_rng(9)), expected)


def test_build_two_slider_is_the_papers_scene():
    assert build("two_slider", {}, NT).is_two_slider()
    assert not build("two_slider", {"k": 2.0}, NT).is_two_slider()


def test_build_graph(tmp_path):
    net = heterogeneous()
    path = write_graph(net, tmp_path / "net.edgelist")[0]
    same_network(build("graph", {"path": str(path)}, NT), net)


def test_kinds_cover_the_config_layer():
    assert set(KINDS) == {"two_slider", "chain", "square", "triangular", "irregular", "graph"}


@pytest.mark.parametrize(("kind", "params", "rng", "message"), [
    pytest.param("hexagonal", {}, None, "The 'kind' parameter of build must be one of 'two_slider', 'chain', "
                 "'square', 'triangular', 'irregular', 'graph'. Got 'hexagonal' instead.", id="unknown-kind"),
    pytest.param("square", {}, None, "A 'square' network needs 'shape'.", id="missing-shape"),
    pytest.param("square", {"shape": (2, 2), "n": 4}, None, "A 'square' network does not take 'n'",
                 id="extra-param"),
    pytest.param("two_slider", {"n": 3}, None, "A 'two_slider' network does not take 'n'", id="two_slider-n3"),
    pytest.param("chain", {"n": 1}, None, "The 'n' parameter of chain must be an integer >= 2. Got 1 instead.",
                 id="chain-n1"),
    pytest.param("chain", {"n": 3, "k": [1.0]}, None, "The 'k' parameter of chain must be a number or an array "
                 "of 2 values", id="chain-k-length"),
    pytest.param("irregular", {"n": 10}, None, "An 'irregular' network needs a random generator",
                 id="irregular-no-rng"),
    pytest.param("graph", {"path": "nowhere.graphml"}, None, "The network file 'nowhere.graphml' does not exist.",
                 id="graph-missing-file"),
])
def test_build_errors(kind, params, rng, message):
    with pytest.raises(ConfigError, match=re.escape(message)):
        build(kind, params, NT, rng)


def test_graphml_string_pos_is_ignored_and_string_xy_converted(tmp_path):
    G = nx.Graph()
    G.add_node("a", x="0.5", y="1", pos="(9, 9)")
    G.add_node("b", x="1.5", y="1", pos="(9, 9)")
    G.add_edge("a", "b", k=3.0)
    path = tmp_path / "s.graphml"
    nx.write_graphml(G, path)
    net = from_graph(read_graph(path), NT)
    np.testing.assert_array_equal(net.positions, [[0.5, 1.0], [1.5, 1.0]])
    assert net.k.tolist() == [3.0]
