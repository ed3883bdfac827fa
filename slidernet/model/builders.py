"""Builders of slider networks: lattices, random Delaunay networks and graph files.

Every builder returns a :class:`slidernet.model.network.Network`. Positions are in
l0 (the natural spring length of the paper), so that on the lattices every
spring has length 1. Node and edge orders are deterministic: nodes are
numbered row by row (``index = row * cols + col``) on lattices and along
strips of width 1 l0 for :func:`irregular`; springs are listed as pairs
``(i, j)`` with ``i < j``, sorted lexicographically.

Keyword ``overrides`` (``k``, ``kappa``, ``normal_load``, ``rest_length``) are
passed on to :class:`~slidernet.model.network.Network`: a scalar for every spring
(or slider), or an array with one value per spring (shape (E,)) or per slider
(shape (N,)), in that network's order. ``f_ext``, the constant external force
on each slider, is a number (along x), a d-vector, or one per slider (N, d).

:func:`build` is the entry point of the configuration layer::

    net = build("square", {"shape": (3, 4)}, Ntilde=1e-7, rng=None)

Physics note: in a uniform lattice with free boundaries the thermal load
``g = B^T (k L kappa)`` vanishes on interior nodes, whose springs pull
symmetrically; only boundary nodes feel the dilation directly. The square
lattice of central nearest-neighbour springs is also floppy: in linear
elasticity x displacements couple only along rows and y displacements only
along columns, so K has ``rows + cols`` zero modes (independent chains), not
the 3 rigid-body modes of the triangular and Delaunay networks.
"""

from __future__ import annotations

import ast
import csv
import io
import math
import numbers
from collections.abc import Mapping, Sequence
from os import PathLike
from pathlib import Path
from typing import Any
from xml.etree.ElementTree import ParseError

import networkx as nx
import numpy as np
import scipy.spatial

from slidernet._validation import is_integral
from slidernet.errors import ConfigError, param_error
from slidernet.model.lattice import Lattice
from slidernet.model.network import Network, chain

__all__ = [
    "KINDS",
    "KIND_DIMS",
    "build",
    "from_graph",
    "irregular",
    "read_graph",
    "square",
    "triangular",
    "write_graph",
]

#: Network kinds that :func:`build` knows, with their required parameters.
KINDS: dict[str, tuple[str, ...]] = {
    "two_slider": (),
    "chain": ("n",),
    "square": ("shape",),
    "triangular": ("shape",),
    "irregular": ("n",),
    "graph": ("path",),
}

#: The dimension of each kind's networks, known before building one; None for a
#: graph, whose file says (1 or 2 coordinates per node).
KIND_DIMS: dict[str, int | None] = {
    "two_slider": 1,
    "chain": 1,
    "square": 2,
    "triangular": 2,
    "irregular": 2,
    "graph": None,
}

# Per-spring or per-slider values a builder passes on to Network.
_OVERRIDES: dict[str, str] = {"k": "edge", "kappa": "edge", "rest_length": "edge", "normal_load": "node",
                              "f_ext": "node vector"}

_EDGE_LIST_SUFFIXES = (".edgelist", ".txt", ".csv")
_GRAPH_SUFFIXES = (".graphml", *_EDGE_LIST_SUFFIXES)


# --------------------------------------------------------------------------
# Validation helpers
# --------------------------------------------------------------------------


def _check_overrides(overrides: Mapping[str, Any], n_nodes: int, n_edges: int, owner: str) -> None:
    """Refuse unknown override names and arrays of the wrong length, before Network sees them.

    Network broadcasts with numpy, whose error for a wrong length does not name
    the parameter; checking here gives the standard message instead.
    """
    for name, value in overrides.items():
        if name not in _OVERRIDES:
            raise ConfigError(
                f"Unknown keyword {name!r} for {owner}; expected one of "
                f"{', '.join(repr(o) for o in _OVERRIDES)}."
            )
        if value is None and name == "rest_length":  # None means geometric, as in Network
            continue
        if _OVERRIDES[name] == "node vector":  # Network checks its several accepted shapes
            continue
        size, item = (n_edges, "spring") if _OVERRIDES[name] == "edge" else (n_nodes, "slider")
        shape = np.shape(value)
        if shape not in ((), (size,)):
            raise param_error(name, owner, f"a number or an array of {size} values (one per {item})",
                              f"an array of shape {shape}")


def _lattice_shape(shape: object, owner: str) -> tuple[int, int]:
    """(rows, cols) as ints, or the standard ConfigError."""
    requirement = "two integers >= 1 with at least 2 nodes"
    try:
        rows, cols = shape  # type: ignore[misc]
    except (TypeError, ValueError):
        raise param_error("shape", owner, requirement, shape) from None
    if not (is_integral(rows) and is_integral(cols)):
        raise param_error("shape", owner, requirement, shape)
    rows, cols = int(rows), int(cols)
    if rows < 1 or cols < 1 or rows * cols < 2:
        raise param_error("shape", owner, requirement, shape)
    return rows, cols


# --------------------------------------------------------------------------
# Lattices
# --------------------------------------------------------------------------


def square(shape: Sequence[int], Ntilde: float, **overrides: Any) -> Network:
    """A square lattice of ``rows x cols`` sliders with nearest-neighbour springs.

    Parameters
    ----------
    shape : (int, int)
        ``(rows, cols)``, each >= 1, with at least 2 sliders in all.
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    **overrides
        ``k`` (units of k0 = N / (Ntilde l0)), ``kappa``, ``rest_length`` (l0):
        scalars or arrays of shape (E,); ``normal_load`` (units of N): scalar or
        shape (N,).

    Returns
    -------
    Lattice
        A :class:`~slidernet.model.lattice.Lattice` (a 2D Network that lists
        its springs only on demand) with N = rows * cols nodes at positions ``(col, row)`` in l0
        (spacing 1), node index ``row * cols + col``, and
        E = rows (cols - 1) + cols (rows - 1) springs of length 1 (horizontal and
        vertical), free boundaries. Edges are ``(i, j)`` with i < j, sorted.

    Notes
    -----
    With central springs only, this lattice is floppy in linear elasticity:
    K has ``rows + cols`` zero modes (each row slides along x, each column
    along y, independently). Interior sliders have 4 neighbours and an
    isotropic K_ii = 2 k I.

    Examples
    --------
    >>> net = square((2, 3), Ntilde=1e-7)
    >>> net.positions.tolist()
    [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0]]
    >>> net.edges.tolist()
    [[0, 1], [0, 3], [1, 2], [1, 4], [2, 5], [3, 4], [4, 5]]
    """
    rows, cols = _lattice_shape(shape, "square")
    _check_overrides(overrides, rows * cols, rows * (cols - 1) + cols * (rows - 1), "square")
    return Lattice("square", (rows, cols), Ntilde, **overrides)


def triangular(shape: Sequence[int], Ntilde: float, **overrides: Any) -> Network:
    """A triangular lattice of ``rows x cols`` sliders with nearest-neighbour springs.

    Parameters
    ----------
    shape : (int, int)
        ``(rows, cols)``, each >= 1, with at least 2 sliders in all.
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    **overrides
        ``k`` (units of k0 = N / (Ntilde l0)), ``kappa``, ``rest_length`` (l0):
        scalars or arrays of shape (E,); ``normal_load`` (units of N): scalar or
        shape (N,).

    Returns
    -------
    Lattice
        A :class:`~slidernet.model.lattice.Lattice` (a 2D Network that lists
        its springs only on demand) with N = rows * cols nodes, node index
        ``row * cols + col``, at ``(col + (row % 2) / 2, row * sqrt(3) / 2)``
        in l0: odd rows are shifted right by 1/2, so every spring has length 1
        and one of three unit vectors, (1, 0) and (-+1/2, sqrt(3)/2), exactly. Interior sliders
        have 6 neighbours; boundaries are free. There are
        E = rows (cols - 1) + (rows - 1)(2 cols - 1) springs, ``(i, j)`` with
        i < j, sorted.

    Notes
    -----
    The lattice is a triangulated patch, hence rigid: K has exactly the 3
    zero modes of a rigid body (2 translations, 1 rotation). Interior sliders
    have an isotropic K_ii = 3 k I.

    Examples
    --------
    >>> net = triangular((2, 2), Ntilde=1e-7)
    >>> net.edges.tolist()
    [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    >>> bool(np.allclose(np.linalg.norm(np.diff(net.positions[net.edges], axis=1), axis=-1), 1.0))
    True
    """
    rows, cols = _lattice_shape(shape, "triangular")
    _check_overrides(overrides, rows * cols, rows * (cols - 1) + (rows - 1) * (2 * cols - 1), "triangular")
    return Lattice("triangular", (rows, cols), Ntilde, **overrides)


# --------------------------------------------------------------------------
# Random Delaunay network
# --------------------------------------------------------------------------


def irregular(n: int, Ntilde: float, rng: np.random.Generator, **overrides: Any) -> Network:
    """``n`` random sliders joined by the springs of their Delaunay triangulation.

    Parameters
    ----------
    n : int
        Number of sliders, >= 3.
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    rng : numpy.random.Generator
        Source of the positions (the global numpy RNG is never used): the same
        generator state gives the same network.
    **overrides
        ``k`` (units of k0 = N / (Ntilde l0)), ``kappa``, ``rest_length`` (l0):
        scalars or arrays of shape (E,); ``normal_load`` (units of N): scalar or
        shape (N,). E is only known after the triangulation; build once with
        scalars to learn it.

    Returns
    -------
    Network
        2D network whose positions, shape (n, 2) in l0, are uniform in the
        square [0, sqrt(n))^2 (one slider per l0^2: mean spacing ~ 1 l0),
        numbered along strips of width 1 l0 in y, left to right and right to
        left in turn (so that neighbours sit close in memory, as on a
        lattice's rows); springs are the unique undirected Delaunay
        edges ``(i, j)``, i < j, sorted lexicographically. Their rest length
        is their geometric length (spread around ~1 l0).

    Notes
    -----
    A triangulation of a convex domain is rigid: K has exactly 3 zero modes.
    Springs along the convex hull can be long and thin triangles occur there;
    this is a property of the Delaunay triangulation of uniform points.

    Examples
    --------
    >>> net = irregular(50, Ntilde=1e-7, rng=np.random.default_rng(0))
    >>> net.n_nodes, net.dim
    (50, 2)
    >>> bool((net.edges[:, 0] < net.edges[:, 1]).all())
    True
    """
    if not is_integral(n) or n < 3:
        raise param_error("n", "irregular", "an integer >= 3", n)
    if not isinstance(rng, np.random.Generator):
        raise param_error("rng", "irregular", "a numpy.random.Generator", type(rng).__name__)
    n = int(n)
    drawn = rng.uniform(0.0, math.sqrt(n), size=(n, 2))
    # Nodes are numbered along strips of width 1 l0 (alternately left to right and right to
    # left): in draw order a node's neighbours lie anywhere in memory, and every slip
    # touched several cache lines per neighbour. Qhull, which inserts the points in the
    # order it gets them, also runs faster this way (10.0 -> 7.3 s at a million points).
    strip = np.floor(drawn[:, 1]).astype(np.int64)
    positions = drawn[np.lexsort((np.where(strip % 2 == 0, drawn[:, 0], -drawn[:, 0]), strip))]
    try:
        tri = scipy.spatial.Delaunay(positions)
    except scipy.spatial.QhullError as err:  # only for degenerate (e.g. collinear) draws
        raise ConfigError(f"The Delaunay triangulation of the {n} random points failed: {err}") from err
    s = tri.simplices.astype(np.int64)
    pairs = np.concatenate([s[:, [0, 1]], s[:, [1, 2]], s[:, [0, 2]]])
    pairs.sort(axis=1)
    # Sorting the 1D key i * n + j orders the springs lexicographically by (i, j);
    # sort + mask is ~20x faster than np.unique here (numpy 2.4, 6e6 keys).
    key = np.sort(pairs[:, 0] * n + pairs[:, 1])
    key = key[np.concatenate([[True], key[1:] != key[:-1]])]
    edges = np.column_stack(np.divmod(key, n))
    if not np.bincount(edges.ravel(), minlength=n).all():
        # Qhull drops coincident points (probability zero for a continuous draw);
        # an unconnected slider would have K_ii = 0.
        raise ConfigError(f"Some of the {n} random points are not in the Delaunay triangulation.")
    _check_overrides(overrides, n, edges.shape[0], "irregular")
    return Network(positions=positions, edges=edges, Ntilde=Ntilde, **overrides)


# --------------------------------------------------------------------------
# Graphs and graph files
# --------------------------------------------------------------------------


def from_graph(G: nx.Graph, Ntilde: float, **overrides: Any) -> Network:
    """A network from a networkx graph whose nodes carry positions (in l0).

    Same as :meth:`Network.from_networkx
    <slidernet.model.network.Network.from_networkx>`: node positions are the
    ``pos`` attribute (1 or 2 floats) or ``x`` (and ``y``); optional
    ``normal_load`` on nodes and ``k``, ``kappa``, ``rest_length`` on edges.
    Nodes are numbered in ``G.nodes`` order, springs in ``G.edges`` order
    (networkx lists a node's springs when it first meets the node, so a file
    whose springs are not sorted by first endpoint is renumbered; per-spring
    override arrays follow this order).

    Parameters
    ----------
    G : networkx.Graph
        The graph, for example from :func:`read_graph`.
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    **overrides
        Replace the graph's attributes: scalars, or arrays of shape (E,)
        (``k``, ``kappa``, ``rest_length``) or (N,) (``normal_load``).

    Examples
    --------
    >>> G = nx.path_graph(3)
    >>> nx.set_node_attributes(G, {v: (float(v), 0.0) for v in G}, "pos")
    >>> from_graph(G, Ntilde=1e-7, k=2.0).k.tolist()
    [2.0, 2.0]
    """
    _check_overrides(overrides, G.number_of_nodes(), G.number_of_edges(), "from_graph")
    return Network.from_networkx(G, Ntilde, **overrides)


def _suffix(path: Path, owner: str) -> str:
    suffix = path.suffix.lower()
    if suffix not in _GRAPH_SUFFIXES:
        raise ConfigError(
            f"{owner} cannot handle {str(path)!r}: unknown extension {path.suffix!r}; "
            f"expected one of {', '.join(_GRAPH_SUFFIXES)}."
        )
    return suffix


def _nodes_file(path: Path) -> Path:
    """The companion node file of an edge list: ``net.edgelist`` -> ``net.nodes.csv``."""
    return path.with_name(path.stem + ".nodes.csv")


def graph_files(path: str | PathLike[str]) -> dict[str, Path]:
    """The files :func:`read_graph` reads for ``path`` without ``positions`` (as a configuration reads it).

    Returns
    -------
    dict of str to Path
        ``"graph"``: the file itself; ``"nodes"``: an edge list's companion
        node file (``<stem>.nodes.csv``), where the file is an edge list.
    """
    p = Path(path)
    files = {"graph": p}
    if p.suffix.lower() != ".graphml":
        files["nodes"] = _nodes_file(p)
    return files


def read_graph(path: str | PathLike[str], positions: Any = None) -> nx.Graph:
    """Read a network file into a networkx graph that :func:`from_graph` accepts.

    Formats, chosen by extension:

    ``.graphml``
        GraphML (networkx.read_graphml). GraphML cannot store tuples, so
        positions are node attributes ``x`` and ``y`` (in l0; only ``x`` in
        1D). Optional: ``normal_load`` on nodes; ``k``, ``kappa``,
        ``rest_length`` on edges. Node ids that are all integers become ints.
        Nodes keep the file's order; directed graphs are made undirected.
    ``.edgelist``, ``.txt``
        One spring per line, ``i j`` (integer node ids) then either nothing,
        ``key=value`` tokens (``0 1 k=2.0 kappa=0.5``) or a Python dict (the
        format of networkx.write_edgelist: ``0 1 {'k': 2.0}``); keys among
        ``k``, ``kappa``, ``rest_length``. ``#`` starts a comment.
    ``.csv``
        CSV edge list with a header: ``i,j`` (or ``source,target``), then
        optional columns ``k``, ``kappa``, ``rest_length``.

    Edge lists carry no positions: they come from ``positions`` or else from
    the companion file ``<stem>.nodes.csv`` next to the edge list, a CSV with
    header ``node,x[,y][,normal_load]`` (positions in l0, loads in N). The
    nodes are numbered in the order of that file (or 0..N-1 for
    ``positions``); every spring must join listed nodes, at most once.
    :func:`from_graph` numbers the springs in ``G.edges`` order, which is the
    file's order when the file lists them sorted by (i, j) with i < j (as
    :func:`write_graph` does).

    Parameters
    ----------
    path : str or path-like
        The file to read.
    positions : array_like, shape (N,) or (N, 2), optional
        Positions in l0 of the nodes in graph order (node id i for an edge
        list); they replace any positions in the file.

    Returns
    -------
    networkx.Graph
        Nodes with ``pos`` or ``x``/``y`` (and ``normal_load``) attributes,
        edges with ``k``/``kappa``/``rest_length`` where the file gives them.

    Raises
    ------
    ConfigError
        A missing file, an unknown extension, a malformed line, or no
        positions for some node.

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> with open(os.path.join(d, "net.edgelist"), "w") as f:
    ...     _ = f.write("0 1 k=2.0\\n1 2\\n")
    >>> G = read_graph(os.path.join(d, "net.edgelist"), positions=[0.0, 1.0, 2.0])
    >>> from_graph(G, Ntilde=1e-7).k.tolist()
    [2.0, 1.0]
    """
    p = Path(path)
    suffix = _suffix(p, "read_graph")
    if p.is_dir():
        raise ConfigError(f"The network file {str(p)!r} is a folder, not a file.")
    if not p.is_file():
        raise ConfigError(f"The network file {str(p)!r} does not exist.")
    try:
        return _read_graph(p, suffix, positions)
    except OSError as exc:  # no permission, ...: the reason in the system's words
        raise ConfigError(f"The network file {str(exc.filename or p)!r} cannot be read: "
                          f"{exc.strerror or exc}.") from None


def _read_graph(p: Path, suffix: str, positions: Any) -> nx.Graph:
    """:func:`read_graph` of a file that exists (the reading only)."""
    if suffix == ".graphml":
        G = _read_graphml(p)
        if positions is not None:
            _set_positions(G, list(G.nodes), positions, p)
        _require_positions(G, p)
        return G
    if positions is not None:
        pos = _positions_array(positions)
        G = nx.Graph()
        G.add_nodes_from((v, {"pos": tuple(row)}) for v, row in enumerate(pos.tolist()))
    else:
        nodes = _nodes_file(p)
        if not nodes.is_file():
            raise ConfigError(
                f"The edge list {str(p)!r} has no positions: pass positions, or write them to "
                f"{str(nodes)!r} (CSV with header node,x[,y][,normal_load])."
            )
        G = _read_nodes_csv(nodes)
    if suffix == ".csv":
        _read_edges_csv(p, G)
    else:
        _read_edges_text(p, G)
    return G


def _read_graphml(p: Path) -> nx.Graph:
    try:
        G = nx.read_graphml(p)
    except (ParseError, nx.NetworkXError, ValueError, KeyError) as err:
        raise ConfigError(f"Cannot read the GraphML file {str(p)!r}: {err}") from err
    if G.is_directed() or G.is_multigraph():
        G = nx.Graph(G)
    # GraphML ids are strings; integer ids (as networkx writes them) read back as ints.
    try:
        mapping = {v: int(v) for v in G.nodes}
    except (TypeError, ValueError):
        return G
    if len(set(mapping.values())) == len(mapping):
        G = nx.relabel_nodes(G, mapping, copy=True)  # copy keeps the node order
    return G


def _positions_array(positions: Any) -> np.ndarray:
    try:
        pos = np.asarray(positions, dtype=float)
    except (TypeError, ValueError):
        raise param_error("positions", "read_graph", "an array of shape (N,) or (N, 2)", positions) from None
    if pos.ndim == 1:
        pos = pos[:, None]
    if pos.ndim != 2 or pos.shape[1] not in (1, 2) or pos.shape[0] < 1:
        raise param_error("positions", "read_graph", "an array of shape (N,) or (N, 2)",
                          f"an array of shape {np.shape(positions)}")
    return pos


def _set_positions(G: nx.Graph, nodes: list, positions: Any, p: Path) -> None:
    pos = _positions_array(positions)
    if pos.shape[0] != len(nodes):
        raise param_error("positions", "read_graph", f"one position per node of {str(p)!r} ({len(nodes)})",
                          f"{pos.shape[0]} positions")
    for v, row in zip(nodes, pos.tolist(), strict=True):
        G.nodes[v]["pos"] = tuple(row)


def _require_positions(G: nx.Graph, p: Path) -> None:
    """Check that every GraphML node has a numeric position, converting numeric strings."""
    for v, data in G.nodes(data=True):
        if isinstance(data.get("pos"), tuple):  # set from the positions argument
            continue
        # A GraphML 'pos' can only be a string (GraphML has no tuples): x and y rule.
        data.pop("pos", None)
        if "x" not in data:
            raise ConfigError(
                f"Node {v!r} of {str(p)!r} has no position: GraphML nodes need 'x' (and 'y') "
                f"attributes in l0, or pass positions."
            )
        for c in ("x", "y"):
            if c in data and not isinstance(data[c], numbers.Real):
                try:  # an attribute declared as a string in a hand-written file
                    data[c] = float(data[c])
                except (TypeError, ValueError):
                    raise ConfigError(
                        f"Node {v!r} of {str(p)!r} has a non-numeric {c!r} attribute {data[c]!r}."
                    ) from None


def _float(text: str, what: str, where: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise ConfigError(f"{where}: {what} must be a number. Got {text!r} instead.") from None
    if not math.isfinite(value):
        raise ConfigError(f"{where}: {what} must be finite. Got {text!r} instead.")
    return value


def _int(text: str, what: str, where: str) -> int:
    try:
        return int(text)
    except (TypeError, ValueError):
        raise ConfigError(f"{where}: {what} must be an integer node id. Got {text!r} instead.") from None


def _text(path: Path) -> io.StringIO:
    """A network's text file (edge list, nodes file), read as UTF-8 (a byte-order mark is skipped), as a stream.

    Not the locale's encoding: a file then reads the same on every machine, as the TOML file that names it.
    """
    data = path.read_bytes()
    try:
        return io.StringIO(data.decode("utf-8-sig"), newline="")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise ConfigError(f"The network file {str(path)!r} is not UTF-8 text: byte 0x{data[exc.start]:02x} on "
                          f"line {line} cannot be decoded. Save it as UTF-8.") from None


def _read_nodes_csv(path: Path) -> nx.Graph:
    G = nx.Graph()
    with _text(path) as f:
        reader = csv.DictReader(f)
        columns = [c.strip() for c in (reader.fieldnames or [])]
        allowed = {"node", "x", "y", "normal_load"}
        if "node" not in columns or "x" not in columns or not set(columns) <= allowed:
            raise ConfigError(
                f"The node file {str(path)!r} needs the header node,x[,y][,normal_load]. Got {columns} instead."
            )
        reader.fieldnames = columns
        for row in reader:
            where = f"{path}, line {reader.line_num}"
            v = _int(row["node"], "'node'", where)
            if v in G:
                raise ConfigError(f"{where}: node {v} is listed twice.")
            pos = [_float(row["x"], "'x'", where)]
            if "y" in columns:
                pos.append(_float(row["y"], "'y'", where))
            data: dict[str, Any] = {"pos": tuple(pos)}
            if row.get("normal_load") not in (None, ""):
                data["normal_load"] = _float(row["normal_load"], "'normal_load'", where)
            G.add_node(v, **data)
    return G


def _add_spring(G: nx.Graph, i: int, j: int, data: dict[str, float], where: str) -> None:
    for v in (i, j):
        if v not in G:
            raise ConfigError(f"{where}: node {v} has no position.")
    if G.has_edge(i, j):
        raise ConfigError(f"{where}: the spring ({i}, {j}) is listed twice.")
    G.add_edge(i, j, **data)


def _spring_data(items: Mapping[Any, Any], where: str) -> dict[str, float]:
    data = {}
    for key, value in items.items():
        if key not in ("k", "kappa", "rest_length"):
            raise ConfigError(
                f"{where}: unknown spring attribute {key!r}; expected 'k', 'kappa' or 'rest_length'."
            )
        data[key] = _float(value, repr(key), where)
    return data


def _read_edges_text(path: Path, G: nx.Graph) -> None:
    with _text(path) as f:
        for number, raw in enumerate(f, start=1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            where = f"{path}, line {number}"
            tokens = line.split(None, 2)
            if len(tokens) < 2:
                raise ConfigError(f"{where}: expected 'i j [key=value ...]'. Got {line!r} instead.")
            rest = tokens[2] if len(tokens) == 3 else ""
            if rest.startswith("{"):
                try:
                    items = ast.literal_eval(rest)
                except (ValueError, SyntaxError):
                    items = None
                if not isinstance(items, dict):
                    raise ConfigError(f"{where}: cannot read the spring attributes {rest!r}.")
            else:
                items = {}
                for tok in rest.split():
                    key, eq, value = tok.partition("=")
                    if not eq:
                        raise ConfigError(f"{where}: expected key=value after 'i j'. Got {tok!r} instead.")
                    items[key] = value
            i = _int(tokens[0], "i", where)
            j = _int(tokens[1], "j", where)
            _add_spring(G, i, j, _spring_data(items, where), where)


def _read_edges_csv(path: Path, G: nx.Graph) -> None:
    with _text(path) as f:
        reader = csv.DictReader(f)
        columns = [c.strip() for c in (reader.fieldnames or [])]
        ends = next((pair for pair in (("i", "j"), ("source", "target")) if set(pair) <= set(columns)), None)
        if ends is None or not set(columns) - set(ends) <= {"k", "kappa", "rest_length"}:
            raise ConfigError(
                f"The edge list {str(path)!r} needs the header i,j (or source,target) "
                f"[,k][,kappa][,rest_length]. Got {columns} instead."
            )
        reader.fieldnames = columns
        for row in reader:
            where = f"{path}, line {reader.line_num}"
            data = {c: v for c, v in row.items() if c not in ends and v not in (None, "")}
            _add_spring(G, _int(row[ends[0]], ends[0], where), _int(row[ends[1]], ends[1], where),
                        _spring_data(data, where), where)


def write_graph(net: Network, path: str | PathLike[str]) -> list[Path]:
    """Write a network to a file that :func:`read_graph` reads back exactly.

    ``.graphml`` stores positions as node attributes ``x`` (and ``y``);
    edge lists (``.edgelist``, ``.txt``: ``i j k=.. kappa=.. rest_length=..``;
    ``.csv``: header ``i,j,k,kappa,rest_length``) also write the companion
    ``<stem>.nodes.csv`` (``node,x[,y],normal_load``). Floats are written with
    ``repr``, so reading back gives the same arrays bit for bit. Node ids are
    the indices 0..N-1.

    Parameters
    ----------
    net : Network
        The network to write.
    path : str or path-like
        Destination; its extension chooses the format.

    Returns
    -------
    list of pathlib.Path
        The files written.

    Examples
    --------
    >>> import tempfile, os
    >>> net = square((2, 2), Ntilde=1e-7, k=[1.0, 2.0, 3.0, 4.0])
    >>> path = os.path.join(tempfile.mkdtemp(), "net.graphml")
    >>> back = from_graph(read_graph(write_graph(net, path)[0]), Ntilde=1e-7)
    >>> back.k.tolist(), bool((back.positions == net.positions).all())
    ([1.0, 2.0, 3.0, 4.0], True)
    """
    p = Path(path)
    suffix = _suffix(p, "write_graph")
    axes = ("x", "y")[: net.dim]
    if suffix == ".graphml":
        G = net.to_networkx()
        for _, data in G.nodes(data=True):
            data.update(zip(axes, data.pop("pos"), strict=True))
            if "f_ext" in data:  # GraphML attributes are scalars
                data.update(zip(("f_ext_x", "f_ext_y"), data.pop("f_ext"), strict=False))
        nx.write_graphml(G, p)
        return [p]
    if net.f_ext.any():
        # Refused rather than dropped: the edge-list formats have no column for it.
        raise ConfigError(f"{str(p)!r}: an edge list cannot store the network's external forces f_ext; "
                          "write a '.graphml' file instead.")
    nodes = _nodes_file(p)
    with nodes.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["node", *axes, "normal_load"])
        # tolist() gives Python floats, whose str is the shortest exact repr.
        for v, (pos, load) in enumerate(zip(net.positions.tolist(), net.normal_load.tolist(), strict=True)):
            w.writerow([v, *pos, load])
    cols = zip(net.edges.tolist(), net.k.tolist(), net.kappa.tolist(), net.rest_length.tolist(), strict=True)
    with p.open("w", newline="", encoding="utf-8") as f:
        if suffix == ".csv":
            w = csv.writer(f)
            w.writerow(["i", "j", "k", "kappa", "rest_length"])
            w.writerows([i, j, k, kappa, L] for (i, j), k, kappa, L in cols)
        else:
            f.write("# i j k=.. kappa=.. rest_length=..  (positions in " + nodes.name + ")\n")
            f.writelines(f"{i} {j} k={k!r} kappa={kappa!r} rest_length={L!r}\n" for (i, j), k, kappa, L in cols)
    return [p, nodes]


# --------------------------------------------------------------------------
# Dispatch for the configuration layer
# --------------------------------------------------------------------------


def build(kind: str, params: Mapping[str, Any], Ntilde: float,
          rng: np.random.Generator | None = None) -> Network:
    """Build the network of a configuration: the entry point of the config layer.

    Parameters
    ----------
    kind : str
        One of ``KINDS``: ``"two_slider"`` (the paper's pair; ``n = 2`` is
        accepted), ``"chain"`` (``n``), ``"square"`` and ``"triangular"``
        (``shape = (rows, cols)``), ``"irregular"`` (``n``; draws from ``rng``),
        ``"graph"`` (``path``, optional ``positions``; see :func:`read_graph`).
    params : mapping
        The kind's parameters, plus optional overrides ``k``, ``kappa``,
        ``normal_load`` and ``rest_length`` (scalars or per-item arrays).
        ``None`` values count as absent.
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    rng : numpy.random.Generator, optional
        Needed by ``"irregular"`` only; the caller seeds it (quenched geometry).

    Returns
    -------
    Network

    Examples
    --------
    >>> build("triangular", {"shape": [3, 3], "kappa": 0.5}, Ntilde=1e-7).n_edges
    16
    >>> build("two_slider", {}, Ntilde=1e-7).is_two_slider()
    True
    """
    if kind not in KINDS:
        raise param_error("kind", "build", f"one of {', '.join(repr(k) for k in KINDS)}", kind)
    if not isinstance(params, Mapping):
        raise param_error("params", "build", "a mapping of parameter names to values", params)
    given = {key: value for key, value in params.items() if value is not None}
    required = KINDS[kind]
    optional = ("positions",) if kind == "graph" else ()
    overrides = {key: value for key, value in given.items() if key in _OVERRIDES}
    own = {key: value for key, value in given.items() if key not in _OVERRIDES}
    if kind == "two_slider" and own.get("n", 2) == 2:
        own.pop("n", None)
    unknown = sorted(set(own) - set(required) - set(optional))
    if unknown:
        expected = [*required, *optional, *_OVERRIDES]
        raise ConfigError(
            f"A {kind!r} network does not take {', '.join(repr(u) for u in unknown)}; "
            f"its parameters are {', '.join(repr(e) for e in expected)}."
        )
    missing = [key for key in required if key not in own]
    if missing:
        raise ConfigError(f"A {kind!r} network needs {', '.join(repr(m) for m in missing)}.")
    if kind == "two_slider":
        # With overrides this is a 2-node chain that is no longer the paper's scene
        # (Network.is_two_slider then says False and the general kernels run).
        return chain(2, Ntilde=Ntilde, **overrides)
    if kind == "chain":
        n = own["n"]
        if not is_integral(n) or n < 2:
            raise param_error("n", "chain", "an integer >= 2", n)  # chain()'s own message
        _check_overrides(overrides, int(n), int(n) - 1, "chain")
        return chain(int(n), Ntilde=Ntilde, **overrides)
    if kind == "square":
        return square(own["shape"], Ntilde, **overrides)
    if kind == "triangular":
        return triangular(own["shape"], Ntilde, **overrides)
    if kind == "irregular":
        if rng is None:
            raise ConfigError("An 'irregular' network needs a random generator (rng) for its positions.")
        return irregular(own["n"], Ntilde, rng, **overrides)
    return from_graph(read_graph(own["path"], positions=own.get("positions")), Ntilde, **overrides)
