"""Networks of sliders: nodes are sliders, edges are springs (MODEL.md section 2).

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
    arr = np.broadcast_to(np.asarray(value, dtype=float), (size,)).copy()
    if not np.isfinite(arr).all():
        raise param_error(name, owner, "finite", value)
    return arr


class Network:
    """A 1D network of sliders joined by linear springs.

    Constructors validate and store; the sparse operators are built by
    :meth:`stiffness_matrix` and :meth:`thermal_load`.

    Parameters
    ----------
    positions : array_like, shape (N,)
        Reference positions X_i of the sliders along x, in l0.
    edges : array_like of int, shape (E, 2)
        Springs as pairs (i, j) of node indices.
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    k : float or array_like, shape (E,)
        Spring stiffnesses in units of k0 = N / (Ntilde l0) (default 1).
    kappa : float or array_like, shape (E,)
        Thermal expansion of each spring relative to the slider material (default 1).
    normal_load : float or array_like, shape (N,)
        Normal loads N_i in units of N (default 1); they also weight x_G.

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
    ) -> None:
        owner = "Network"
        Ntilde = float(Ntilde)
        if not (math.isfinite(Ntilde) and Ntilde > 0):
            raise param_error("Ntilde", owner, "finite and > 0", Ntilde)
        x = np.asarray(positions, dtype=float).reshape(-1)
        if x.size < 2:
            raise param_error("positions", owner, "at least 2 nodes", x.size)
        if not np.isfinite(x).all():
            raise param_error("positions", owner, "finite", positions)
        e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        if e.shape[0] == 0:
            raise param_error("edges", owner, "at least one spring", 0)
        if e.min() < 0 or e.max() >= x.size:
            raise param_error("edges", owner, f"node indices in [0, {x.size - 1}]", e.tolist())
        if (e[:, 0] == e[:, 1]).any():
            raise param_error("edges", owner, "free of self-loops", e.tolist())
        length = np.abs(x[e[:, 1]] - x[e[:, 0]])
        if (length == 0).any():
            raise ConfigError(
                "Two sliders joined by a spring share one position; springs need length > 0."
            )
        self.positions = x
        self.edges = e
        self.Ntilde = Ntilde
        self.k = _per_item(k, e.shape[0], "k", owner)
        if (self.k <= 0).any():
            raise param_error("k", owner, "> 0 for every spring", k)
        self.kappa = _per_item(kappa, e.shape[0], "kappa", owner)
        self.normal_load = _per_item(normal_load, x.size, "normal_load", owner)
        if (self.normal_load <= 0).any():
            raise param_error("normal_load", owner, "> 0 for every slider", normal_load)

    @property
    def n_nodes(self) -> int:
        """Number of sliders N."""
        return self.positions.size

    @property
    def n_edges(self) -> int:
        """Number of springs E."""
        return self.edges.shape[0]

    def rest_length(self) -> np.ndarray:
        """Spring lengths |X_j - X_i| at theta = 0, in l0, shape (E,)."""
        return np.abs(self.positions[self.edges[:, 1]] - self.positions[self.edges[:, 0]])

    def incidence(self) -> sp.csr_matrix:
        """Oriented incidence matrix B times the unit vectors, shape (E, N)."""
        i, j = self.edges[:, 0], self.edges[:, 1]
        unit = np.sign(self.positions[j] - self.positions[i])
        rows = np.repeat(np.arange(self.n_edges), 2)
        cols = np.column_stack([i, j]).reshape(-1)
        vals = np.column_stack([-unit, unit]).reshape(-1)
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n_edges, self.n_nodes))

    def stiffness_matrix(self) -> sp.csr_matrix:
        """K = B^T diag(k) B in units of k0, shape (N, N), CSR with sorted indices."""
        b = self.incidence()
        K = (b.T @ sp.diags(self.k) @ b).tocsr()
        K.sum_duplicates()
        K.sort_indices()
        return K

    def thermal_load(self) -> np.ndarray:
        """g = B^T (k L kappa): force per unit theta/Ntilde, shape (N,)."""
        return self.incidence().T @ (self.k * self.rest_length() * self.kappa)

    def is_two_slider(self) -> bool:
        """True for the paper's scene: 2 sliders, one spring, all values at their defaults."""
        return (
            self.n_nodes == 2
            and self.n_edges == 1
            and self.positions[1] - self.positions[0] == 1.0
            and tuple(self.edges[0]) == (0, 1)
            and bool((self.k == 1.0).all() and (self.kappa == 1.0).all())
            and bool((self.normal_load == 1.0).all())
        )

    def to_networkx(self) -> nx.Graph:
        """The network as a networkx graph (``x``, ``normal_load``, ``k``, ``kappa`` attributes)."""
        G = nx.Graph()
        for i, (xi, ni) in enumerate(zip(self.positions, self.normal_load, strict=True)):
            G.add_node(i, x=float(xi), normal_load=float(ni))
        for (i, j), ke, kap in zip(self.edges, self.k, self.kappa, strict=True):
            G.add_edge(int(i), int(j), k=float(ke), kappa=float(kap))
        return G

    @classmethod
    def from_networkx(cls, G: nx.Graph, Ntilde: float) -> Network:
        """Build from a networkx graph whose nodes carry an ``x`` position (in l0).

        Optional attributes: ``normal_load`` on nodes, ``k`` and ``kappa`` on edges.
        Nodes are numbered in ``G.nodes`` order.
        """
        nodes = list(G.nodes)
        index = {v: n for n, v in enumerate(nodes)}
        try:
            x = [float(G.nodes[v]["x"]) for v in nodes]
        except KeyError as exc:
            raise ConfigError("Every node of the graph needs an 'x' position attribute.") from exc
        edges = [(index[a], index[b]) for a, b in G.edges]
        return cls(
            positions=x,
            edges=edges,
            Ntilde=Ntilde,
            k=[float(d.get("k", 1.0)) for _, _, d in G.edges(data=True)],
            kappa=[float(d.get("kappa", 1.0)) for _, _, d in G.edges(data=True)],
            normal_load=[float(G.nodes[v].get("normal_load", 1.0)) for v in nodes],
        )

    def __repr__(self) -> str:
        return f"Network(N={self.n_nodes}, E={self.n_edges}, Ntilde={self.Ntilde!r})"


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
