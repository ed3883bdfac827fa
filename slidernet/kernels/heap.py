"""Indexed binary max-heaps for the event engine, and the bookkeeping of a slip.

The helpers are inlined into the kernels (numba's ``inline="always"``): a
call that passes a dozen arrays costs more than the sift it performs, and
inlining the heap and slip helpers made the 2D kernel 35-50 % faster
(A/B in one process, 1e3 and 1e6 nodes).

A heap holds node indices ordered by a per-node key (largest first, ties
to the lowest node index: the tie rule of ARCHITECTURE.md, item 4).
``hpos[node, w]`` is the node's slot in heap w or -1, so that re-keying or
removing a node costs O(log size). Its size lives in ``ist[slot]``.

The kernels use three heaps: unstable nodes keyed by overload
|F_i| / (mu_s,i N_i); driven nodes keyed by minus their upper critical theta
(the next event when theta rises); driven nodes keyed by their lower
critical theta (the next event when theta falls). Negation is exact, so a
min-heap on theta_up is a max-heap on -theta_up with the same tie rule.

The avalanche bookkeeping of t = 0 is here too, in one place for both
network kernels (:func:`open_initial_relaxation`, :func:`close_t0`): a
kernel is re-entered after every buffer refill, and only its first entry
may open the relaxation of an initial overload.
"""

from __future__ import annotations

from slidernet.kernels.state import (
    ARGMAX,
    AV_SLIPS,
    DONE,
    DOWN_SIZE,
    EV_ON,
    EV_POS,
    EV_T,
    HEAP_SIZE,
    IN_AVALANCHE,
    MU_MAX,
    MU_POS,
    N_EVENTS,
    N_RECORDS,
    N_SLIPS,
    NEED_EVENTS,
    NEED_MU,
    REC,
    SINCE_RECOMPUTE,
    STARTED,
    THETA,
    UP_SIZE,
    Q,
    kernel_jit,
)


@kernel_jit(inline="always")
def _before(ka, na, kb, nb):
    return ka > kb or (ka == kb and na < nb)


# The heaps are rows w of 2D arrays, indexed in place (slicing a row would
# build a new array object at every call of the hot loop): hp[w, h] is the
# node in slot h and hv[w, h] its key, so that sifting reads contiguous
# memory; hpos[node, w] is the slot of a node, node-major so that the three
# slots of a node share a cache line.


@kernel_jit(inline="always")
def _place(hp, hv, hpos, w, h, node, key):
    hp[w, h] = node
    hv[w, h] = key
    hpos[node, w] = h


@kernel_jit(inline="always")
def _up(hp, hv, hpos, w, h):
    node = hp[w, h]
    key = hv[w, h]
    while h > 0:
        p = (h - 1) >> 1
        if not _before(key, node, hv[w, p], hp[w, p]):
            break
        _place(hp, hv, hpos, w, h, hp[w, p], hv[w, p])
        h = p
    _place(hp, hv, hpos, w, h, node, key)
    return h


@kernel_jit(inline="always")
def _down(hp, hv, hpos, w, h, size):
    node = hp[w, h]
    key = hv[w, h]
    while True:
        c = 2 * h + 1
        if c >= size:
            break
        if c + 1 < size and _before(hv[w, c + 1], hp[w, c + 1], hv[w, c], hp[w, c]):
            c += 1
        if not _before(hv[w, c], hp[w, c], key, node):
            break
        _place(hp, hv, hpos, w, h, hp[w, c], hv[w, c])
        h = c
    _place(hp, hv, hpos, w, h, node, key)


@kernel_jit(inline="always")
def heap_set(node, value, present, hp, hv, hpos, w, ist, slot):
    """In heap ``w``: insert ``node`` with key ``value``, re-key it, or (``present`` False) remove it.

    The heap's size lives in ``ist[slot]``.
    """
    h = hpos[node, w]
    if present:
        if h >= 0:
            if hv[w, h] == value:
                return
            hv[w, h] = value
            h2 = _up(hp, hv, hpos, w, h)
            if h2 == h:
                _down(hp, hv, hpos, w, h, ist[slot])
        else:
            size = ist[slot]
            _place(hp, hv, hpos, w, size, node, value)
            ist[slot] = size + 1
            _up(hp, hv, hpos, w, size)
    elif h >= 0:
        last = ist[slot] - 1
        ist[slot] = last
        hpos[node, w] = -1
        if h != last:
            _place(hp, hv, hpos, w, h, hp[w, last], hv[w, last])
            if _up(hp, hv, hpos, w, h) == h:
                _down(hp, hv, hpos, w, h, last)


@kernel_jit()
def avalanche_done(ist, aval_hist, av_slot, flag_slot):
    """Close the current avalanche: bin its size (slips) by floor(log2 size).

    ``ist[av_slot]`` counts the slips after the driving slip, so the size is
    one more; the relaxation at t = 0 has no driving slip and starts the
    count at -1 (:func:`open_initial_relaxation`).
    """
    if ist[flag_slot]:
        size = ist[av_slot] + 1
        b = 0
        while size > 1:
            size >>= 1
            b += 1
        aval_hist[b] += 1
        ist[flag_slot] = 0


@kernel_jit(inline="always")
def open_initial_relaxation(ist):
    """Open avalanche 0, the relaxation of an overload at t = 0 (a large f_ext), once.

    Call it on every entry of a network kernel: only the first entry of a
    run whose unstable heap is non-empty opens it. Later entries before t =
    0 is closed (after a buffer refill in the middle of the relaxation) find
    it open and must not restart its count. It has no driving slip, so its
    count starts at -1: its size (``AV_SLIPS`` + 1, see
    :func:`avalanche_done`) is then its slips alone.
    """
    if ist[STARTED] == 0 and ist[IN_AVALANCHE] == 0 and ist[HEAP_SIZE] > 0:
        ist[IN_AVALANCHE] = 1
        ist[AV_SLIPS] = -1


@kernel_jit(inline="always")
def close_t0(ist, rec_times):
    """Close t = 0 once the network is stable; True if the t = 0 record is due now.

    Call it where the unstable heap is empty and the avalanche closed, before
    the first driving event. It returns True at most once per run: the caller
    then writes the record (anything sampled at t = 0, such as the tilt
    test, must come before the call, since a kernel that returned for more
    draws before it would find t = 0 closed on re-entry).
    """
    if ist[STARTED] != 0:
        return False
    ist[STARTED] = 1
    return rec_times[ist[REC]] == 0


@kernel_jit(inline="always")
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


@kernel_jit(inline="always")
def log_event(i, dux, duy, ist, fst, ev_i, ev_f):
    """Append the slip of node i to the event catalogue, if it is recorded.

    ``ev_i`` (cap, 2) int64 gets (node, avalanche id), ``ev_f`` (cap, 3)
    float64 gets (time in tau_th, du_x, du_y in Ntilde l0). The avalanche id
    is the number of driving events so far (0: the relaxation at t = 0).
    The caller checks for room before the slip; with the catalogue off the
    buffers have no rows and nothing is written.
    """
    k = ist[EV_POS]
    if k < ev_i.shape[0]:
        ev_i[k, 0] = i
        ev_i[k, 1] = ist[N_EVENTS]
        ev_f[k, 0] = fst[EV_T]
        ev_f[k, 1] = dux
        ev_f[k, 2] = duy
        ist[EV_POS] = k + 1


@kernel_jit()
def mu_stats(mu):
    """Mean and smallest threshold over the nodes, O(N): called at recorded times only."""
    total = 0.0
    low = mu[0]
    for j in range(mu.size):
        total += mu[j]
        low = min(low, mu[j])
    return total / mu.size, low


@kernel_jit(inline="always")
def buffers_low(ist, mu_buf, ev_i):
    """Why a slip cannot happen now: ``NEED_MU`` (no threshold left to redraw), ``NEED_EVENTS``
    (the catalogue's buffer is full), or ``DONE`` (it can). Checked before every slip, so that a
    kernel returns only at clean points."""
    if ist[MU_POS] >= mu_buf.size:
        return NEED_MU
    if ist[EV_ON] and ist[EV_POS] >= ev_i.shape[0]:
        return NEED_EVENTS
    return DONE


@kernel_jit(inline="always")
def next_driving_event(thetas, ist, fst, hp, hv):
    """The next node to reach its threshold as theta moves linearly from thetas[q] to thetas[q + 1].

    Reads the two driving heaps (upper critical thetas when theta rises,
    lower ones when it falls; eq. `critique` for each node). Returns
    ``(node, theta_c, s)``: node -1 if none is reached within the segment
    (inclusive at its end); theta_c is clamped to the current theta where
    rounding put it behind; s is the sign of d(theta)/dt.
    """
    q = ist[Q]
    theta_b = thetas[q + 1]
    s = 1.0 if theta_b > thetas[q] else (-1.0 if theta_b < thetas[q] else 0.0)
    best = -1
    thc = 0.0
    if s > 0.0 and ist[UP_SIZE] > 0:
        best = hp[1, 0]
        thc = -hv[1, 0]
    elif s < 0.0 and ist[DOWN_SIZE] > 0:
        best = hp[2, 0]
        thc = hv[2, 0]
    if best >= 0:
        theta = fst[THETA]
        if s * (thc - theta) < 0.0:
            thc = theta  # rounding: the node is already at its threshold
        if s * (theta_b - thc) < 0.0:
            best = -1
    return best, thc, s


@kernel_jit(inline="always")
def open_driving_event(thetas, thc, ist, fst):
    """Start the avalanche of a driving event at theta_c: count it, and stamp its time (q + fraction)."""
    q = ist[Q]
    ist[AV_SLIPS] = 0
    ist[IN_AVALANCHE] = 1
    ist[N_EVENTS] += 1
    fst[EV_T] = q + (thc - thetas[q]) / (thetas[q + 1] - thetas[q])


@kernel_jit(inline="always")
def end_step(thetas, rec_times, ist, fst):
    """No node reaches its threshold before thetas[q + 1]: go there; True if that time is recorded."""
    q = ist[Q]
    ist[Q] = q + 1
    fst[THETA] = thetas[q + 1]
    return ist[REC] < rec_times.size and rec_times[ist[REC]] == q + 1
