"""Assembly of the stiffness matrix K from the springs, in one compiled pass.

At a million nodes, building K through sparse products or a COO-to-CSR sort
of 7 million entries dominated the setup; the block rows of K can instead
be written in place, since every row's length is known from the degrees.
"""

from __future__ import annotations

import numpy as np

from slidernet.kernels.state import cached_jit


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
