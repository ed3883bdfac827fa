"""Indexed binary max-heaps for the event engine, and the bookkeeping of a slip.

A heap holds node indices ordered by a per-node ``key`` (largest first, ties
to the lowest node index, which is the documented tie rule of MODEL.md).
``pos[node]`` is the node's slot in the heap or -1, so that re-keying or
removing a node costs O(log size). Its size lives in ``ist[slot]``.

The kernels use three heaps: unstable nodes keyed by overload
|F_i| / (mu_s,i N_i); driven nodes keyed by minus their upper critical theta
(the next event when theta rises); driven nodes keyed by their lower
critical theta (the next event when theta falls). Negation is exact, so a
min-heap on theta_up is a max-heap on -theta_up with the same tie rule.
"""

from __future__ import annotations

from numba import njit

from slidernet.kernels.state import (
    ARGMAX,
    MU_MAX,
    MU_POS,
    N_RECORDS,
    N_SLIPS,
    SINCE_RECOMPUTE,
)


@njit(cache=True, inline="always")
def _before(ka, na, kb, nb):
    return ka > kb or (ka == kb and na < nb)


# The heaps are rows w of 2D arrays (hp, hpos, hkey), indexed in place: slicing
# a row would build a new array object at every call of the hot loop.


@njit(cache=True, inline="always")
def _swap(hp, hpos, w, a, b):
    na = hp[w, a]
    nb = hp[w, b]
    hp[w, a] = nb
    hp[w, b] = na
    hpos[w, nb] = a
    hpos[w, na] = b


@njit(cache=True)
def _up(hp, hpos, hkey, w, h):
    while h > 0:
        p = (h - 1) >> 1
        if _before(hkey[w, hp[w, h]], hp[w, h], hkey[w, hp[w, p]], hp[w, p]):
            _swap(hp, hpos, w, h, p)
            h = p
        else:
            break


@njit(cache=True)
def _down(hp, hpos, hkey, w, h, size):
    while True:
        c = 2 * h + 1
        if c >= size:
            break
        if c + 1 < size and _before(hkey[w, hp[w, c + 1]], hp[w, c + 1], hkey[w, hp[w, c]], hp[w, c]):
            c += 1
        if _before(hkey[w, hp[w, c]], hp[w, c], hkey[w, hp[w, h]], hp[w, h]):
            _swap(hp, hpos, w, h, c)
            h = c
        else:
            break


@njit(cache=True)
def heap_set(node, value, present, hp, hpos, hkey, w, ist, slot):
    """In heap ``w``: insert ``node`` with key ``value``, re-key it, or (``present`` False) remove it.

    The heap's size lives in ``ist[slot]``.
    """
    h = hpos[w, node]
    if present:
        if h >= 0 and hkey[w, node] == value:
            return
        hkey[w, node] = value
        if h < 0:
            size = ist[slot]
            hp[w, size] = node
            hpos[w, node] = size
            ist[slot] = size + 1
            _up(hp, hpos, hkey, w, size)
        else:
            _up(hp, hpos, hkey, w, h)
            _down(hp, hpos, hkey, w, hpos[w, node], ist[slot])
    elif h >= 0:
        last = ist[slot] - 1
        ist[slot] = last
        hpos[w, node] = -1
        if h != last:
            moved = hp[w, last]
            hp[w, h] = moved
            hpos[w, moved] = h
            _up(hp, hpos, hkey, w, h)
            _down(hp, hpos, hkey, w, hpos[w, moved], last)


@njit(cache=True)
def avalanche_done(ist, aval_hist, av_slot, flag_slot):
    """Close the current avalanche: bin its size (slips) by floor(log2 size)."""
    if ist[flag_slot]:
        size = ist[av_slot] + 1  # the driving slip plus the avalanche slips
        b = 0
        while size > 1:
            size >>= 1
            b += 1
        aval_hist[b] += 1
        ist[flag_slot] = 0


@njit(cache=True)
def redraw_threshold(i, mu, mu_buf, ist, fst, node_slips):
    """After node i slipped: draw its new mu_s, keep mu_max and its holder, count the slip.

    mu_max is kept incrementally; only when the strongest node itself slips
    (possible in networks, never with two sliders) is it found by a rescan.
    """
    new = mu_buf[ist[MU_POS]]
    ist[MU_POS] += 1
    old = mu[i]
    mu[i] = new
    if new > fst[MU_MAX]:
        ist[N_RECORDS] += 1
        fst[MU_MAX] = new
        ist[ARGMAX] = i
    elif i == ist[ARGMAX] and new < old:
        best = 0
        for j in range(mu.size):
            if mu[j] > mu[best]:
                best = j
        ist[ARGMAX] = best
        fst[MU_MAX] = mu[best]
    ist[N_SLIPS] += 1
    ist[SINCE_RECOMPUTE] += 1
    node_slips[i] += 1
