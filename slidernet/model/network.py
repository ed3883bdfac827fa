"""Networks of sliders: nodes are sliders, edges are springs (docs/model.md section 2).

Units (the same everywhere in slidernet's internals):

* forces in N, the reference normal load;
* stiffnesses in k0 = N / (Ntilde l0), so the paper's spring has ``k = 1``;
* hence lengths in N / k0 = Ntilde l0, and the dilation enters as theta / Ntilde.

In these units every quantity the solver touches is of order one, whatever
Ntilde is; user-facing outputs are converted back to l0 by the solver.

With the oriented incidence matrix B (E x N, one row per spring, -1 at i and
+1 at j, times the unit vector e_e from i to j), the extension of spring e is
``delta_e = (B u)_e - L_e kappa_e theta`` and the forces are affine in u and
theta::

    F = -K u + theta g,    K = B^T diag(k) B,    g = B^T (k L kappa).

Both are assembled once, with scipy.sparse.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import networkx as nx
import numpy as np
import scipy.sparse as sp

from slidernet.errors import ConfigError, param_error


def _per_item(value, size: int, name: str, owner: str) -> np.ndarray:
    try:
        arr = np.broadcast_to(np.asarray(value, dtype=float), (size,)).copy()
    except ValueError:
        raise param_error(name, owner, f"a number or an array of {size} values",
                          f"an array of shape {np.shape(value)}") from None
    if not np.isfinite(arr).all():
        raise param_error(name, owner, "finite", value)
    return arr


def _per_node_vector(value, n: int, d: int, name: str, owner: str) -> np.ndarray:
    """A per-node vector field of shape (N, d) from a number (along x), a d-vector, (N,) or (N, d)."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        out = np.zeros((n, d))
        out[:, 0] = arr
    elif arr.shape == (d,) and n != d:
        out = np.broadcast_to(arr, (n, d)).copy()
    elif arr.shape == (n,) and d == 1:
        out = arr[:, None].copy()
    elif arr.shape == (n, d):
        out = arr.copy()
    else:
        wanted = f"a number or one per slider (shape ({n},))" if d == 1 else \
            f"a number (along x), a vector of {d} components, or one per slider (shape ({n}, {d}))"
        raise param_error(name, owner, wanted, f"an array of shape {arr.shape}")
    if not np.isfinite(out).all():
        raise param_error(name, owner, "finite", value)
    return out


class Network:
    """A 1D or 2D network of sliders joined by linear springs.

    Constructors validate and store; the sparse operators are built by
    :meth:`stiffness_matrix` and :meth:`thermal_load`.

    Parameters
    ----------
    positions : array_like, shape (N,) or (N, 2)
        Reference positions X_i of the sliders, in l0 (along x in 1D).
    edges : array_like of int, shape (E, 2)
        Springs as pairs (i, j) of node indices.
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    k : float or array_like, shape (E,)
        Spring stiffnesses in units of k0 = N / (Ntilde l0) (default 1).
    kappa : float or array_like, shape (E,)
        Thermal expansion of each spring relative to the slider material (default 1).
    rest_length : float or array_like, shape (E,), optional
        Natural length of each spring at theta = 0, in l0, which sets its
        thermal load k L kappa theta (default: the distance ``|X_j - X_i|``).
        The initial state is at rest whatever it is.
    normal_load : float or array_like, shape (N,)
        Normal loads N_i in units of N (default 1); they also weight x_G.
    f_ext : float or array_like, shape (d,), (N,) or (N, d)
        Constant external tangential force on each slider, in units of N
        (default 0): a number is the same force along x on every slider, a
        d-vector the same force on every slider, an (N,) or (N, d) array one
        force per slider. A tilt by an angle alpha is
        ``f_ext = tan(alpha) * normal_load`` along the slope.

    Examples
    --------
    >>> net = chain(3, Ntilde=1e-7)
    >>> net.stiffness_matrix().toarray()
    array([[ 1., -1.,  0.],
           [-1.,  2., -1.],
           [ 0., -1.,  1.]])
    >>> net.thermal_load()
    array([-1.,  0.,  1.])
    """

    def __init__(
        self,
        positions: Sequence[float] | np.ndarray,
        edges: Sequence[Sequence[int]] | np.ndarray,
        Ntilde: float,
        k: float | Sequence[float] = 1.0,
        kappa: float | Sequence[float] = 1.0,
        normal_load: float | Sequence[float] = 1.0,
        rest_length: float | Sequence[float] | None = None,
        f_ext: float | Sequence[float] | np.ndarray = 0.0,
    ) -> None:
        owner = "Network"
        Ntilde = float(Ntilde)
        if not (math.isfinite(Ntilde) and Ntilde > 0):
            raise param_error("Ntilde", owner, "finite and > 0", Ntilde)
        x = np.asarray(positions, dtype=float)
        if x.ndim == 1:
            x = x[:, None]
        if x.ndim != 2 or x.shape[1] not in (1, 2):
            raise param_error("positions", owner, "of shape (N,) or (N, 2)", x.shape)
        if x.shape[0] < 2:
            raise param_error("positions", owner, "at least 2 nodes", x.shape[0])
        if not np.isfinite(x).all():
            raise param_error("positions", owner, "finite", "non-finite values")
        e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        if e.shape[0] == 0:
            raise param_error("edges", owner, "at least one spring", 0)
        if e.min() < 0 or e.max() >= x.shape[0]:
            raise param_error("edges", owner, f"node indices in [0, {x.shape[0] - 1}]",
                              f"indices from {e.min()} to {e.max()}")
        if (e[:, 0] == e[:, 1]).any():
            raise param_error("edges", owner, "free of self-loops", "a self-loop")
        with np.errstate(over="ignore"):  # judged just below, by the springs it concerns
            dx = x[e[:, 1]] - x[e[:, 0]]
            length = np.abs(dx[:, 0]) if x.shape[1] == 1 else np.hypot(dx[:, 0], dx[:, 1])
        if not np.isfinite(length).all():
            # Positions of +-1e308 are finite, their differences not: the unit vectors would be NaN.
            a, b = e[int(np.argmax(~np.isfinite(length)))]
            raise ConfigError(
                f"The sliders {int(a)} and {int(b)}, joined by a spring, lie too far apart, beyond float64: their "
                f"positions differ by more than {np.finfo(np.float64).max:.3g} l0 (the spring's unit vector would "
                f"be NaN)."
            )
        if (length == 0).any():
            raise ConfigError(
                "Two sliders joined by a spring share one position; springs need length > 0."
            )
        degree = np.bincount(e.reshape(-1), minlength=x.shape[0])
        if (degree == 0).any():
            # K_ii = 0: such a slider could never stop sliding.
            raise ConfigError(
                f"Slider {int(np.flatnonzero(degree == 0)[0])} has no spring; every slider "
                "needs at least one."
            )
        self.positions = x
        self.edges = e
        # Kept: K, g and the checks all need them, and at a million nodes
        # recomputing them was a quarter of the setup.
        length.flags.writeable = False
        self._length = length
        self._unit = dx / length[:, None]
        self._unit.flags.writeable = False
        self.Ntilde = Ntilde
        self.k = _per_item(k, e.shape[0], "k", owner)
        if (self.k <= 0).any():
            raise param_error("k", owner, "> 0 for every spring", k)
        self.kappa = _per_item(kappa, e.shape[0], "kappa", owner)
        self.normal_load = _per_item(normal_load, x.shape[0], "normal_load", owner)
        if (self.normal_load <= 0).any():
            raise param_error("normal_load", owner, "> 0 for every slider", normal_load)
        self.f_ext = _per_node_vector(f_ext, x.shape[0], x.shape[1], "f_ext", owner)
        if rest_length is None:
            self.rest_length = length
        else:
            self.rest_length = _per_item(rest_length, e.shape[0], "rest_length", owner)
            if (self.rest_length <= 0).any():
                raise param_error("rest_length", owner, "> 0 for every spring", rest_length)

    @property
    def n_nodes(self) -> int:
        """Number of sliders N."""
        return self.positions.shape[0]

    @property
    def dim(self) -> int:
        """Dimension d of the displacements (1 or 2)."""
        return self.positions.shape[1]

    @property
    def n_edges(self) -> int:
        """Number of springs E."""
        return self.edges.shape[0]

    def unit_vectors(self) -> np.ndarray:
        """Unit vectors e_e from node i to node j of every spring, shape (E, d) (read-only)."""
        return self._unit

    def lengths(self) -> np.ndarray:
        """Distances ``|X_j - X_i|`` of every spring's ends, in l0, shape (E,) (read-only)."""
        return self._length

    def incidence(self) -> sp.csr_matrix:
        """Oriented incidence matrix B times the unit vectors, shape (E, N d).

        Row e gives the extension of spring e: (B u)_e = e_e . (u_j - u_i),
        with u flattened node-major (u[i d + c] is component c of node i).
        """
        d = self.dim
        i, j = self.edges[:, 0], self.edges[:, 1]
        unit = self.unit_vectors()
        comp = np.arange(d)
        rows = np.repeat(np.arange(self.n_edges), 2 * d)
        cols = np.concatenate([i[:, None] * d + comp, j[:, None] * d + comp], axis=1).reshape(-1)
        vals = np.concatenate([-unit, unit], axis=1).reshape(-1)
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n_edges, self.n_nodes * d))

    def stiffness_matrix(self) -> sp.csr_matrix:
        """K = B^T diag(k) B in units of k0, shape (N d, N d), CSR with sorted indices."""
        b = self.incidence()
        K = (b.T @ sp.diags(self.k) @ b).tocsr()
        K.sum_duplicates()
        K.sort_indices()
        return K

    def stiffness_blocks(self) -> sp.bsr_matrix:
        """K as a block-sparse matrix of d x d blocks, assembled directly from the springs.

        The same matrix as :meth:`stiffness_matrix`, built without the sparse
        product: block K_ij = -k_e e_e e_e^T for every spring and K_ii the sum
        of the node's spring blocks, written row by row in one compiled pass
        (:mod:`slidernet.kernels.assembly`); every row carries its diagonal
        block and its columns are sorted.

        >>> K = chain(3, Ntilde=1e-7).stiffness_blocks()
        >>> bool((K.toarray() == chain(3, Ntilde=1e-7).stiffness_matrix().toarray()).all())
        True
        """
        from slidernet.kernels.assembly import assemble_blocks

        N, d = self.n_nodes, self.dim
        indptr, indices, data, duplicate = assemble_blocks(N, self.edges[:, 0], self.edges[:, 1], self.k,
                                                           self.unit_vectors())
        if duplicate:  # parallel springs: let the sparse product sum them
            return self.stiffness_matrix().tobsr(blocksize=(d, d))
        return sp.bsr_matrix((data, indices, indptr), shape=(N * d, N * d), copy=False)

    def stiffness_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """K's block rows, each block an id into a table of blocks: what the 2D kernels read.

        Returns
        -------
        indptr : ndarray of int64, shape (N + 1,)
        indices : ndarray of int32, shape (nnzb,)
            Sorted block columns of each row; each row holds its diagonal block.
        K_id : ndarray of int32, shape (nnzb,)
            K_ij is ``K_table[K_id[p]]`` for the entry p of column j in row i.
        K_table : ndarray, shape (B, d, d)
            The blocks, in k0. Here one per entry (B = nnzb, ``K_id`` = 0, 1, ...);
            a lattice (:class:`~slidernet.model.lattice.Lattice`) stores each
            distinct block once.

        >>> indptr, indices, K_id, K_table = chain(3, Ntilde=1e-7).stiffness_table()
        >>> K_table[K_id[indptr[1]:indptr[2]]].ravel().tolist()
        [-1.0, 2.0, -1.0]
        """
        K = self.stiffness_blocks()
        return (K.indptr.astype(np.int64), K.indices.astype(np.int32),
                np.arange(K.data.shape[0], dtype=np.int32), np.ascontiguousarray(K.data, dtype=np.float64))

    def thermal_load(self) -> np.ndarray:
        """g = B^T (k L kappa): force per unit theta/Ntilde, shape (N d,), node-major.

        Spring e pushes its ends apart along e_e with k L kappa per unit
        theta/Ntilde: node j gets + k L kappa e_e, node i gets - k L kappa e_e.
        Summed with bincount, not through the incidence matrix: the same
        numbers, a fraction of the memory at a million nodes.
        """
        N, d = self.n_nodes, self.dim
        f = (self.k * self.rest_length * self.kappa)[:, None] * self.unit_vectors()
        g = np.empty((N, d))
        for c in range(d):
            g[:, c] = (np.bincount(self.edges[:, 1], f[:, c], minlength=N)
                       - np.bincount(self.edges[:, 0], f[:, c], minlength=N))
        return g.reshape(-1)

    def is_two_slider(self) -> bool:
        """True for the paper's scene, which the two-slider kernel (``kernels.pair``) runs.

        The one rule for that kernel: a pair to which the appendix's tilt
        test applies (:func:`pair_tilt_applies`) with one spring of unit
        length, stiffness and dilation between node 0 and node 1 at X = 0
        and X = 1. The kernel works on scalars with F = theta - u and these
        values built in, so any other value needs the general kernels.

        >>> chain(2, Ntilde=1e-7).is_two_slider(), chain(2, Ntilde=1e-7, k=2.0).is_two_slider()
        (True, False)
        """
        return (
            pair_tilt_applies(self)
            and self.n_edges == 1
            and self.positions[1, 0] - self.positions[0, 0] == 1.0
            and self.rest_length[0] == 1.0
            and tuple(self.edges[0]) == (0, 1)
            and bool((self.k == 1.0).all() and (self.kappa == 1.0).all())
        )

    def to_networkx(self) -> nx.Graph:
        """The network as a networkx graph.

        Node attributes: ``pos`` (a tuple of d floats, in l0),
        ``normal_load`` and, where it is not zero, ``f_ext`` (a tuple of d
        floats, in N); edge attributes: ``k``, ``kappa``, ``rest_length``.
        """
        G = nx.Graph()
        for i in range(self.n_nodes):
            G.add_node(i, pos=tuple(float(c) for c in self.positions[i]),
                       normal_load=float(self.normal_load[i]))
            if self.f_ext[i].any():
                G.nodes[i]["f_ext"] = tuple(float(c) for c in self.f_ext[i])
        for e, (i, j) in enumerate(self.edges):
            G.add_edge(int(i), int(j), k=float(self.k[e]), kappa=float(self.kappa[e]),
                       rest_length=float(self.rest_length[e]))
        return G

    @classmethod
    def from_networkx(cls, G: nx.Graph, Ntilde: float, **overrides) -> Network:
        """Build from a networkx graph whose nodes carry positions (in l0).

        A node's position is its ``pos`` attribute (a sequence of 1 or 2
        floats) or its ``x`` (and ``y``) attributes. Optional attributes:
        ``normal_load`` and ``f_ext`` (a number along x, or d floats; or
        ``f_ext_x`` and ``f_ext_y``) on nodes; ``k``, ``kappa`` and ``rest_length`` on edges. Nodes are
        numbered in ``G.nodes`` order. Keyword ``overrides`` (``k``,
        ``kappa``, ``normal_load``, ``rest_length``, ``f_ext``) replace the
        attributes for every node or edge.
        """
        nodes = list(G.nodes)
        if len(nodes) < 2:
            raise ConfigError(f"A network needs at least 2 sliders; the graph has {len(nodes)}.")
        index = {v: n for n, v in enumerate(nodes)}
        positions = []
        for v in nodes:
            data = G.nodes[v]
            if "pos" in data:
                positions.append([float(c) for c in np.atleast_1d(data["pos"])])
            elif "x" in data:
                positions.append([float(data["x"])] + ([float(data["y"])] if "y" in data else []))
            else:
                raise ConfigError(f"Node {v!r} of the graph has no position ('pos', or 'x' and 'y').")
        edges = [(index[a], index[b]) for a, b in G.edges]
        edata = [d for _, _, d in G.edges(data=True)]
        attrs = {
            "k": [float(d.get("k", 1.0)) for d in edata],
            "kappa": [float(d.get("kappa", 1.0)) for d in edata],
            "normal_load": [float(G.nodes[v].get("normal_load", 1.0)) for v in nodes],
        }
        if any(key in G.nodes[v] for v in nodes for key in ("f_ext", "f_ext_x", "f_ext_y")):
            d = len(positions[0])
            attrs["f_ext"] = [_node_force(G.nodes[v], d, v) for v in nodes]
        if any("rest_length" in d for d in edata):
            geometric = np.linalg.norm(np.subtract([positions[b] for _, b in edges],
                                                   [positions[a] for a, _ in edges]), axis=1)
            attrs["rest_length"] = [float(d.get("rest_length", geometric[e]))
                                    for e, d in enumerate(edata)]
        attrs.update(overrides)
        return cls(positions=positions, edges=edges, Ntilde=Ntilde, **attrs)

    def __repr__(self) -> str:
        return f"Network(N={self.n_nodes}, E={self.n_edges}, Ntilde={self.Ntilde!r})"


def pair_tilt_applies(net: Network) -> bool:
    """True if the appendix's tilt test before every rearrangement (``kernels.tilt``) applies to ``net``.

    The one rule for that test (``mu_eff_at = "rearrangements"``): two
    sliders on a line, each of unit normal load, with no force but the
    springs' (no f_ext, no incline). The appendix writes it for that pair
    alone; any other network takes the network tilt test at the recorded
    times. Springs and geometry do not enter: the test reads the forces and
    the thresholds only.

    Parameters
    ----------
    net : Network

    Returns
    -------
    bool

    Examples
    --------
    >>> pair_tilt_applies(chain(2, Ntilde=1e-7, k=3.0)), pair_tilt_applies(chain(2, Ntilde=1e-7, f_ext=0.1))
    (True, False)
    """
    return (net.n_nodes == 2 and net.dim == 1 and bool((net.normal_load == 1.0).all())
            and not net.f_ext.any())


def _node_force(data: dict, d: int, node) -> list[float]:
    """A node's external force as d floats, from ``f_ext`` (a number along x, or d numbers)
    or from ``f_ext_x`` and ``f_ext_y`` (GraphML attributes are scalars)."""
    if "f_ext" not in data:
        return [float(data.get("f_ext_x", 0.0)), float(data.get("f_ext_y", 0.0))][:d]
    value = data["f_ext"]
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.size == 1:
        return [float(arr[0])] + [0.0] * (d - 1)
    if arr.size != d:
        raise ConfigError(f"The 'f_ext' attribute of node {node!r} must be a number or {d} numbers. "
                          f"Got {value!r} instead.")
    return [float(c) for c in arr]


def chain(n: int, Ntilde: float, **overrides) -> Network:
    """A chain of ``n`` sliders at X_i = i (in l0), free ends, nearest-neighbour springs.

    >>> chain(4, Ntilde=1e-7).edges.tolist()
    [[0, 1], [1, 2], [2, 3]]
    """
    if int(n) != n or n < 2:
        raise param_error("n", "chain", "an integer >= 2", n)
    n = int(n)
    return Network(
        positions=np.arange(n, dtype=float),
        edges=np.column_stack([np.arange(n - 1), np.arange(1, n)]),
        Ntilde=Ntilde,
        **overrides,
    )


def two_slider(Ntilde: float) -> Network:
    """The paper's system: a 2-node chain (slider 1 is node 0, slider 2 is node 1)."""
    return chain(2, Ntilde=Ntilde)
