"""Builders of slider networks: lattices, random Delaunay networks and graphs.

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

Network files (GraphML, edge lists) are read and written by
:mod:`slidernet.model.files` (:func:`read_graph`, :func:`write_graph`, re-exported
here); :func:`from_graph` builds the network of a graph read from one.

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

import math
from collections.abc import Mapping, Sequence
from typing import Any

import networkx as nx
import numpy as np
import scipy.spatial

from slidernet._validation import is_integral
from slidernet.errors import ConfigError, param_error
from slidernet.model.files import graph_files, read_graph, write_graph
from slidernet.model.lattice import Lattice
from slidernet.model.network import Network, chain

__all__ = [
    "KINDS",
    "KIND_DIMS",
    "build",
    "from_graph",
    "graph_files",
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
    G = read_graph(own["path"], positions=own.get("positions"))
    try:
        return from_graph(G, Ntilde, **overrides)
    except ConfigError as exc:  # what the network makes of the file's values: the file is named
        raise ConfigError(f"The network file {str(own['path'])!r}: {exc}") from None
