"""The driving trees of the network kernels (kernels.heap.tree_set): their root is the exact next event.

A tree's root must be the driven node with the largest key, ties to the lowest node
index (ARCHITECTURE.md, item 4), after any sequence of re-keys: checked against a
scan of the keys, with keys drawn from a few values so that ties are frequent.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from slidernet.kernels.heap import heap_clear, tree_set, tree_top
from slidernet.kernels.state import TREE_ARITY, Heaps


@njit
def _replay(heaps, r, nodes, keys, tops, top_keys):
    heap_clear(heaps)
    for k in range(nodes.size):
        tree_set(heaps, r, nodes[k], keys[k])
        tops[k], top_keys[k] = tree_top(heaps, r)


@pytest.mark.parametrize(("n_nodes", "n_driven"), [(1, 1), (5, 2), (9, 8), (40, 9), (700, 650), (3000, 3000)])
def test_the_root_is_the_largest_key_then_the_lowest_node(n_nodes: int, n_driven: int) -> None:
    rng = np.random.default_rng(n_nodes)
    driven = np.zeros(n_nodes, bool)
    driven[rng.choice(n_nodes, n_driven, replace=False)] = True
    heaps = Heaps.empty(1, n_nodes, driven)
    # Levels of whole groups, each a TREE_ARITY-th of the one below, up to a root of one entry.
    sizes = np.diff(heaps.toff)
    assert sizes[-1] == 1 and all(s % TREE_ARITY == 0 for s in sizes[:-1])
    assert all(-(-sizes[i] // TREE_ARITY) <= sizes[i + 1] for i in range(sizes.size - 1))
    ids = np.flatnonzero(driven)
    m = 20 * n_driven
    nodes = rng.choice(ids, m)
    # Few distinct keys, so that ties are common; -inf as well (a leaf never keyed).
    keys = rng.choice(np.array([-np.inf, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0]), m)
    for r in (0, 1):
        tops = np.zeros(m, np.int64)
        top_keys = np.zeros(m)
        _replay(heaps, r, nodes, keys, tops, top_keys)
        current = np.full(n_nodes, -np.inf)
        for k in range(m):
            current[nodes[k]] = keys[k]
            best = ids[np.argmax(current[ids])]  # argmax takes the first: the lowest node of the largest key
            assert (tops[k], top_keys[k]) == (best, current[best])


def test_no_driven_node_no_tree() -> None:
    heaps = Heaps.empty(1, 4, np.zeros(4, bool))
    assert heaps.toff.tolist() == [0]
    assert tree_top.py_func(heaps, 0)[0] == -1
