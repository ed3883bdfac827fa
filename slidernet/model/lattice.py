"""Square and triangular lattices: a :class:`Network` whose springs differ only by direction.

A lattice of a million sliders has three million springs. A general
:class:`~slidernet.model.network.Network` keeps seven arrays over them
(ends, unit vectors, lengths, k, kappa, ...) and one 2 x 2 block of K per
entry; a lattice needs none of it. Its springs come in a few directions
(classes), every spring of a class has the same unit vector, length and
block k e e^T, and a node's K_ii and thermal load g_i depend only on which
classes meet it. :class:`Lattice` therefore stores the shape and the
scalars, lists its springs only when asked (:attr:`Lattice.edges`, for
plots, graph files and the general assembly), and builds K as a table of a
few dozen distinct blocks (:func:`slidernet.kernels.assembly.lattice_operators`).

Geometry: spacing 1 (l0); node index ``row * cols + col``. Square: node at
``(col, row)``, classes right (1, 0) and up (0, 1). Triangular: node at
``(col + (row % 2) / 2, row sqrt(3) / 2)``, classes right (1, 0), up-left
(-1/2, sqrt(3)/2) and up-right (1/2, sqrt(3)/2), each of length
``hypot(1/2, sqrt(3)/2)`` (1.0 in float64). The springs take these exact
vectors, not differences of the rounded positions, so that every spring of
a class has the same bits, as the physics says it has.

If k, kappa or rest_length are given per spring (shape (E,)), the springs
differ by more than their direction and K and g come from the general
assembly on :attr:`Lattice.edges`.
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from slidernet.errors import param_error
from slidernet.kernels.assembly import lattice_operators
from slidernet.model.network import Network, _per_item, _per_node_vector

_H = math.sqrt(3.0) / 2.0

#: Reference vector (from the lower- to the higher-numbered node) of each spring class.
CLASS_VECTORS = {
    "square": np.array([[1.0, 0.0], [0.0, 1.0]]),
    "triangular": np.array([[1.0, 0.0], [-0.5, _H], [0.5, _H]]),
}


def _per_spring(value, size: int, name: str, owner: str) -> tuple[np.ndarray, bool]:
    """(values of shape (E,), True if one value for all): a scalar stays one number, broadcast read-only."""
    if np.ndim(value) == 0:
        arr = _per_item(value, 1, name, owner)
        return np.broadcast_to(arr, (size,)), True
    return _per_item(value, size, name, owner), False


class Lattice(Network):
    """A ``rows x cols`` square or triangular lattice of sliders, free boundaries.

    Parameters
    ----------
    kind : {"square", "triangular"}
    shape : (int, int)
        ``(rows, cols)``, already checked by the builder (at least 2 nodes).
    Ntilde : float
        N / (k l0) of the reference spring; > 0.
    k, kappa, rest_length, normal_load, f_ext
        As for :class:`~slidernet.model.network.Network`; a scalar k, kappa
        or rest_length (the default) keeps the lattice free of per-spring
        arrays.

    Examples
    --------
    >>> lat = Lattice("triangular", (2, 2), Ntilde=1e-7)
    >>> lat.edges.tolist()
    [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    >>> lat.unit_vectors()[1].tolist()
    [0.5, 0.8660254037844386]
    """

    def __init__(self, kind: str, shape: tuple[int, int], Ntilde: float, k=1.0, kappa=1.0,
                 normal_load=1.0, rest_length=None, f_ext=0.0) -> None:
        if kind not in CLASS_VECTORS:
            raise param_error("kind", "Lattice", "'square' or 'triangular'", kind)
        Ntilde = float(Ntilde)
        if not (math.isfinite(Ntilde) and Ntilde > 0):
            raise param_error("Ntilde", kind, "finite and > 0", Ntilde)
        self.kind = kind
        self.rows, self.cols = int(shape[0]), int(shape[1])
        self.Ntilde = Ntilde
        vectors = CLASS_VECTORS[kind]
        length = np.hypot(vectors[:, 0], vectors[:, 1])
        # Every spring of either lattice has one length (1.0 in float64), whatever its direction.
        self._spring_length = float(length[0])
        self._class_unit = vectors / length[:, None]
        E = self.n_edges
        self.k, k_one = _per_spring(k, E, "k", kind)
        if (self.k <= 0).any():
            raise param_error("k", kind, "> 0 for every spring", k)
        self.kappa, kappa_one = _per_spring(kappa, E, "kappa", kind)
        self.rest_length, rest_one = _per_spring(self._spring_length if rest_length is None else rest_length, E,
                                                 "rest_length", kind)
        if (self.rest_length <= 0).any():
            raise param_error("rest_length", kind, "> 0 for every spring", rest_length)
        # Every spring of a class alike: K and g from the stencil.
        self.uniform = k_one and kappa_one and rest_one
        N = self.n_nodes
        self.normal_load = _per_item(normal_load, N, "normal_load", kind)
        if (self.normal_load <= 0).any():
            raise param_error("normal_load", kind, "> 0 for every slider", normal_load)
        if np.ndim(f_ext) == 0 and float(f_ext) == 0.0:
            self.f_ext = np.zeros((N, 2))  # left untouched: no memory until written
        else:
            self.f_ext = _per_node_vector(f_ext, N, 2, "f_ext", kind)

    # -- sizes, without listing the springs ---------------------------------------------------

    @property
    def n_nodes(self) -> int:
        return self.rows * self.cols

    @property
    def dim(self) -> int:
        return 2

    @property
    def n_edges(self) -> int:
        rows, cols = self.rows, self.cols
        if self.kind == "square":
            return rows * (cols - 1) + cols * (rows - 1)
        return rows * (cols - 1) + (rows - 1) * (2 * cols - 1)

    # -- the springs, listed on demand ---------------------------------------------------------

    @cached_property
    def positions(self) -> np.ndarray:
        """Reference positions X_i, shape (N, 2), in l0."""
        row, col = np.divmod(np.arange(self.n_nodes, dtype=np.int64), self.cols)
        if self.kind == "square":
            return np.column_stack([col.astype(float), row.astype(float)])
        odd = (row % 2).astype(bool)
        return np.column_stack([col + 0.5 * odd, row * _H])

    @cached_property
    def _springs(self) -> tuple[np.ndarray, np.ndarray]:
        """(edges (E, 2), class of each spring (E,)), edges ``(i, j)`` with i < j, sorted (listed on first use)."""
        rows, cols = self.rows, self.cols
        i = np.arange(self.n_nodes, dtype=np.int64)
        row, col = np.divmod(i, cols)
        has_up = row < rows - 1
        if self.kind == "square":
            # Candidates in increasing j: right (i + 1), then up (i + cols).
            j = np.column_stack([i + 1, i + cols])
            valid = np.column_stack([col < cols - 1, has_up])
        else:
            odd = (row % 2).astype(bool)
            # Neighbours in the row above sit at x -+ 1/2: columns (col - 1, col) from an
            # even row (the row above is shifted right), (col, col + 1) from an odd row.
            up_left = i + cols - 1 + odd
            j = np.column_stack([i + 1, up_left, up_left + 1])
            valid = np.column_stack([col < cols - 1, has_up & (odd | (col > 0)),
                                     has_up & (~odd | (col < cols - 1))])
        # Candidates are listed in increasing j for each i, so boolean indexing in
        # row-major order yields the lexicographic order directly, with no sort.
        src = np.broadcast_to(i[:, None], j.shape)[valid]
        cls = np.broadcast_to(np.arange(j.shape[1]), j.shape)[valid]
        return np.column_stack([src, j[valid]]), cls

    @property
    def edges(self) -> np.ndarray:
        """Springs as pairs (i, j), i < j, sorted, shape (E, 2) (listed on first use)."""
        return self._springs[0]

    def spring_classes(self) -> np.ndarray:
        """The direction class of every spring, shape (E,) (see :data:`CLASS_VECTORS`)."""
        return self._springs[1]

    def unit_vectors(self) -> np.ndarray:
        """Unit vector of every spring, shape (E, 2): its class's, exactly."""
        return self._class_unit[self.spring_classes()]

    def lengths(self) -> np.ndarray:
        """Length of every spring, shape (E,), in l0: its class's."""
        return np.broadcast_to(self._spring_length, (self.n_edges,))

    # -- operators --------------------------------------------------------------------------

    @cached_property
    def _stencil(self) -> tuple[np.ndarray, ...]:
        k = float(self.k[0])
        load = (k * float(self.rest_length[0]) * float(self.kappa[0])) * self._class_unit
        return lattice_operators(self.kind == "triangular", self.rows, self.cols, k, self._class_unit, load)

    def stiffness_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """K's block rows as ids into a table of distinct blocks (see :meth:`Network.stiffness_table`).

        From the stencil when every spring of a class is alike: a table of
        at most a few dozen blocks, the same values as the general assembly.
        """
        if not self.uniform:
            return super().stiffness_table()
        indptr, indices, K_id, K_table, _g = self._stencil
        return indptr, indices, K_id, K_table

    def thermal_load(self) -> np.ndarray:
        """g, shape (2 N,), node-major (see :meth:`Network.thermal_load`); from the stencil when uniform."""
        if not self.uniform:
            return super().thermal_load()
        return self._stencil[-1].reshape(-1)

    def __repr__(self) -> str:
        return f"Lattice({self.kind!r}, shape=({self.rows}, {self.cols}), Ntilde={self.Ntilde!r})"
