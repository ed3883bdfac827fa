"""Assembly of the stiffness matrix K from the springs, in one compiled pass.

At a million nodes, building K through sparse products or a COO-to-CSR sort
of 7 million entries dominated the setup; the block rows of K can instead
be written in place, since every row's length is known from the degrees.
"""

from __future__ import annotations

import numpy as np

from slidernet.kernels.jit import cached_jit


@cached_jit()
def _assemble(N, i, j, k, unit, indptr):
    """Fill the block rows of K (diagonal block first, then springs in edge order), then sort each row.

    Blocks are copied entry by entry: slicing a block would build an array
    view per access, which cost most of the setup at a million nodes.
    """
    nnz = indptr[N]
    d = unit.shape[1]
    indices = np.empty(nnz, np.int64)
    data = np.empty((nnz, d, d))
    # The diagonal sums the i-side and the j-side separately, then adds them,
    # as two bincounts would: the same bits as the sparse product's assembly.
    diag_i = np.zeros((N, d, d))
    diag_j = np.zeros((N, d, d))
    fill = indptr[:N] + 1
    for e in range(i.size):
        a = i[e]
        c = j[e]
        fa = fill[a]
        fc = fill[c]
        indices[fa] = c
        indices[fc] = a
        for p in range(d):
            for q in range(d):
                # The spring's block b_e = k_e e_e e_e^T, formed here: an (E, d, d)
                # array of them would be 100 MB at a million nodes.
                v = k[e] * unit[e, p] * unit[e, q]
                data[fa, p, q] = -v
                data[fc, p, q] = -v
                diag_i[a, p, q] += v
                diag_j[c, p, q] += v
        fill[a] = fa + 1
        fill[c] = fc + 1
    duplicate = False
    blk = np.empty((d, d))
    for n in range(N):
        start = indptr[n]
        indices[start] = n
        for p in range(d):
            for q in range(d):
                data[start, p, q] = diag_i[n, p, q] + diag_j[n, p, q]
        # Insertion sort by column: rows are short (the degree plus one), and
        # already sorted when the edges are (the lattices' are).
        for s in range(start + 1, indptr[n + 1]):
            col = indices[s]
            if indices[s - 1] < col:
                continue
            for p in range(d):
                for q in range(d):
                    blk[p, q] = data[s, p, q]
            t = s
            while t > start and indices[t - 1] > col:
                indices[t] = indices[t - 1]
                for p in range(d):
                    for q in range(d):
                        data[t, p, q] = data[t - 1, p, q]
                t -= 1
            indices[t] = col
            for p in range(d):
                for q in range(d):
                    data[t, p, q] = blk[p, q]
            if t > start and indices[t - 1] == col:
                duplicate = True
    return indices, data, duplicate


@cached_jit()
def diagonal_positions(indptr, indices):
    """Where each row of a CSR or block-CSR matrix stores its diagonal entry, shape (N,), int64.

    Every row must hold its diagonal (K's rows do). One pass over the
    column indices: at a million nodes, comparing them with a repeated row
    index built two arrays of 7 million entries first.
    """
    N = indptr.size - 1
    diag = np.empty(N, np.int64)
    for n in range(N):
        diag[n] = -1
        for p in range(indptr[n], indptr[n + 1]):
            if indices[p] == n:
                diag[n] = p
                break
    return diag


def assemble_blocks(N: int, i: np.ndarray, j: np.ndarray, k: np.ndarray, unit: np.ndarray):
    """Block-CSR arrays of K from the spring blocks b_e = k_e e_e e_e^T.

    Parameters
    ----------
    N : int
        Number of nodes.
    i, j : ndarray of int64, shape (E,)
        The two ends of every spring.
    k : ndarray, shape (E,)
        Spring stiffnesses, in units of k0.
    unit : ndarray, shape (E, d)
        Unit vectors e_e from i to j; the spring's block is b_e = k_e e_e e_e^T.

    Returns
    -------
    indptr : ndarray of int64, shape (N + 1,)
    indices : ndarray of int64, shape (nnzb,)
        Sorted block columns of each row; each row holds its diagonal block.
    data : ndarray, shape (nnzb, d, d)
        K_ij = -b_e for the spring (i, j) and K_ii = sum of the node's b_e.
    duplicate : bool
        True if two springs join the same pair of nodes (their blocks are
        then not summed; the caller must take another route).
    """
    degree = np.bincount(i, minlength=N) + np.bincount(j, minlength=N)
    indptr = np.zeros(N + 1, np.int64)
    np.cumsum(degree + 1, out=indptr[1:])
    indices, data, duplicate = _assemble(N, i.astype(np.int64), j.astype(np.int64),
                                         np.ascontiguousarray(k, dtype=np.float64),
                                         np.ascontiguousarray(unit, dtype=np.float64), indptr)
    return indptr, indices, data, bool(duplicate)


# --------------------------------------------------------------------------
# Lattices: K and g from the stencil, without per-spring arrays
# --------------------------------------------------------------------------

#: Spring classes of the lattices, in the order a node lists its springs to
#: higher-numbered neighbours (node index ``row * cols + col``): square:
#: right, up; triangular: right, up-left, up-right.
SQUARE, TRIANGULAR = 0, 1


@cached_jit(forceinline=True)
def _forward(kind, rows, cols, n, m):
    """The m-th spring from node n to a higher-numbered neighbour: (j, class), j = -1 if absent."""
    r = n // cols
    c = n - r * cols
    if m == 0:
        return (n + 1, 0) if c < cols - 1 else (-1, 0)
    if r >= rows - 1:
        return -1, m
    if kind == SQUARE:
        return (n + cols, 1) if m == 1 else (-1, m)
    odd = r % 2
    up_left = n + cols - 1 + odd
    if m == 1:
        return (up_left, 1) if (odd == 1 or c > 0) else (-1, 1)
    return (up_left + 1, 2) if (odd == 0 or c < cols - 1) else (-1, 2)


@cached_jit()
def _lattice_rows(kind, rows, cols, n_classes):
    """Block rows of a lattice's K as class ids, and a key per node for its diagonal block and load.

    A node's key encodes the classes of its springs in the order the
    general assembly (:func:`_assemble`, :meth:`Network.thermal_load`) sums
    them: springs to higher-numbered neighbours in increasing neighbour
    index, then springs from lower-numbered ones in increasing index, one
    base-4 digit (class + 1) each. Nodes with equal keys get the same bits
    for K_ii and g_i from either route.
    """
    N = rows * cols
    deg = np.zeros(N, np.int64)
    fwd = np.zeros(N, np.int64)
    bwd = np.zeros(N, np.int64)
    for n in range(N):
        for m in range(n_classes):
            j, c = _forward(kind, rows, cols, n, m)
            if j >= 0:
                deg[n] += 1
                deg[j] += 1
                fwd[n] = 4 * fwd[n] + c + 1
                bwd[j] = 4 * bwd[j] + c + 1
    indptr = np.zeros(N + 1, np.int64)
    for n in range(N):
        indptr[n + 1] = indptr[n] + deg[n] + 1
    nnz = indptr[N]
    indices = np.empty(nnz, np.int32)
    K_id = np.empty(nnz, np.int32)
    fill = indptr[:N].copy()
    # Keys are < 4^3 per side: a dense map from key to the id of its diagonal block.
    seen = np.full(4096, -1, np.int64)
    keys = np.empty(4096, np.int64)
    node_id = np.empty(N, np.int32)
    n_keys = 0
    for n in range(N):
        # The springs from lower-numbered nodes are in place: the diagonal comes next, then the rest.
        p = fill[n]
        indices[p] = n
        key = 64 * fwd[n] + bwd[n]
        if seen[key] < 0:
            seen[key] = n_keys
            keys[n_keys] = key
            n_keys += 1
        node_id[n] = seen[key]
        K_id[p] = n_classes + seen[key]
        fill[n] = p + 1
        for m in range(n_classes):
            j, c = _forward(kind, rows, cols, n, m)
            if j >= 0:
                indices[fill[n]] = j
                K_id[fill[n]] = c
                fill[n] += 1
                indices[fill[j]] = n
                K_id[fill[j]] = c
                fill[j] += 1
    return indptr, indices, K_id, node_id, keys[:n_keys].copy()


def _digits(seq: int) -> list[int]:
    """The classes of a base-4 key, first summed first (digit = class + 1)."""
    out = []
    while seq:
        out.append(seq % 4 - 1)
        seq //= 4
    return out[::-1]


def lattice_operators(triangular: bool, rows: int, cols: int, k: float, unit: np.ndarray, load: np.ndarray):
    """K as a block table and the thermal load g of a lattice whose springs differ only by direction.

    Every spring of class c (a direction of the lattice) has the block
    b_c = k e_c e_c^T and pushes its ends apart with ``load[c]`` per unit
    theta/Ntilde; a node's K_ii and g_i depend only on which classes meet it,
    and in which order the general assembly sums them, so K is stored as
    block ids into a table of a few dozen blocks instead of one block per
    entry (224 MB at a million nodes). The values are those of
    :meth:`~slidernet.model.network.Network.stiffness_blocks` and
    :meth:`~slidernet.model.network.Network.thermal_load` on the same
    springs, to the bit (tested).

    Parameters
    ----------
    triangular : bool
        Triangular (3 classes: right, up-left, up-right) or square (right, up).
    rows, cols : int
        The lattice's shape; node index ``row * cols + col``.
    k : float
        Spring stiffness, in k0.
    unit : ndarray, shape (C, 2)
        Unit vector of each class, from the lower- to the higher-numbered node.
    load : ndarray, shape (C, 2)
        k L kappa e_c of each class: the force per unit theta/Ntilde on the higher-numbered end.

    Returns
    -------
    indptr : ndarray of int64, shape (N + 1,)
    indices : ndarray of int32, shape (nnzb,)
        Sorted block columns of each row, the diagonal included.
    K_id : ndarray of int32, shape (nnzb,)
        Row of ``K_table`` holding K_ij.
    K_table : ndarray, shape (B, 2, 2)
        -b_c for each class c, then the distinct diagonal blocks.
    g : ndarray, shape (N, 2)
        The thermal load of every node, in N per unit theta/Ntilde.
    """
    n_classes = unit.shape[0]
    indptr, indices, K_id, node_id, keys = _lattice_rows(int(triangular), int(rows), int(cols), n_classes)
    # The spring block formed as _assemble forms it: (k e_p) e_q.
    blocks = np.array([[[k * unit[c, p] * unit[c, q] for q in range(2)] for p in range(2)]
                       for c in range(n_classes)])
    table = [-blocks[c] for c in range(n_classes)]
    g_table = []
    for key in keys.tolist():
        to_higher, from_lower = _digits(key // 64), _digits(key % 64)
        # K_ii: the springs where the node is the first end, then those where it is the second, summed
        # apart from 0.0 and then added, as _assemble does.
        first = np.zeros((2, 2))
        second = np.zeros((2, 2))
        for c in to_higher:
            first = first + blocks[c]
        for c in from_lower:
            second = second + blocks[c]
        table.append(first + second)
        # g_i: bincount over the second ends minus bincount over the first ends, each in edge order.
        pulled = np.zeros(2)
        pushed = np.zeros(2)
        for c in from_lower:
            pulled = pulled + load[c]
        for c in to_higher:
            pushed = pushed + load[c]
        g_table.append(pulled - pushed)
    g = np.asarray(g_table).reshape(-1, 2)[node_id]
    return indptr, indices, K_id, np.asarray(table), g
