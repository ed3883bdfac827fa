"""Indexed binary max-heaps for the event engine, and the bookkeeping every kernel shares.

The helpers are inlined into the kernels by LLVM (``forceinline=True``, the
``alwaysinline`` attribute): a call that passes a dozen arrays costs more
than the sift it performs (a named tuple of arrays is passed as a hundred
scalars), and inlining the heap and slip helpers made the 2D kernel
35-50 % faster (A/B in one process, 1e3 and 1e6 nodes). numba's own
``inline="always"``, which the helpers used before, inlines them in numba's
IR, where every copy is typed and lowered again: compiling took 3 to 7
times longer for the same machine code speed (docs/guides/performance.md,
"Compiling").

A heap holds node indices ordered by a per-node key (largest first, ties
to the lowest node index: the tie rule of ARCHITECTURE.md, item 4). The
heaps of a kernel are rows of one :class:`~slidernet.kernels.state.Heaps`;
``heaps.slot[node, w]`` is the node's slot in heap w or -1, so that
re-keying or removing a node costs O(log size). The network kernels keep
the unstable nodes keyed by overload |F_i| / (mu_s,i N_i) in a heap
(``UNSTABLE``).

Their driving events come from two tournament trees over the driven nodes,
with the same order and tie rule: minus their upper critical theta
(``UP``, the next event when theta rises) and their lower critical theta
(``DOWN``, the next event when theta falls). Negation is exact, so a
largest -theta_up is a smallest theta_up with the same tie rule. A tree
has a leaf per driven node in node order and groups of ``TREE_ARITY`` = 8
entries (one cache line of keys) under each inner entry, which holds the
group's lead. Re-keying a leaf walks up only while a lead changes: the
neighbours of a slip are re-keyed at every slip, their keys move a little,
and their leaves share groups (nodes are numbered with locality). A binary
heap sifted the node of a driving event from the top to the bottom at
every event, through a cache miss per level at 1e6 driven nodes; the tree
walks log_8 N levels of contiguous keys, and needs no slot array.

The rest is the bookkeeping every kernel shares, written once: the
avalanche of t = 0 (:func:`open_initial_relaxation`, :func:`close_t0`; a
kernel is re-entered after every buffer refill, and only its first entry may
open the relaxation of an initial overload), the redraw of a threshold, the
event catalogue, the output series, and the steps of the driving loop
(:func:`next_driving_event`, :func:`open_driving_event`, :func:`end_step`).
"""

from __future__ import annotations

import math

import numpy as np

from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.state import AGE_EDGES, DONE, DOWN, NEED_EVENTS, NEED_MU, TREE_ARITY, UNSTABLE, UP, nonneg


@kernel_jit(forceinline=True)
def _before(ka, na, kb, nb):
    return ka > kb or (ka == kb and na < nb)


@kernel_jit(forceinline=True)
def _place(heaps, w, h, node, key):
    heaps.node[w, h] = node
    heaps.key[w, h] = key
    heaps.slot[nonneg(node), w] = h  # a node in a heap is a node index, never -1


@kernel_jit(forceinline=True)
def _up(heaps, w, h):
    node = heaps.node[w, h]
    key = heaps.key[w, h]
    while h > 0:
        p = nonneg((h - 1) >> 1)
        if not _before(key, node, heaps.key[w, p], heaps.node[w, p]):
            break
        _place(heaps, w, h, heaps.node[w, p], heaps.key[w, p])
        h = p
    _place(heaps, w, h, node, key)
    return h


@kernel_jit(forceinline=True)
def _down(heaps, w, h, size):
    node = heaps.node[w, h]
    key = heaps.key[w, h]
    while True:
        c = nonneg(2 * h + 1)
        if c >= size:
            break
        c1 = nonneg(c + 1)
        if c1 < size and _before(heaps.key[w, c1], heaps.node[w, c1], heaps.key[w, c], heaps.node[w, c]):
            c = c1
        if not _before(heaps.key[w, c], heaps.node[w, c], key, node):
            break
        _place(heaps, w, h, heaps.node[w, c], heaps.key[w, c])
        h = c
    _place(heaps, w, h, node, key)


@kernel_jit(forceinline=True)
def heap_set(heaps, w, node, key, present):
    """In heap ``w``: insert ``node`` with ``key``, re-key it, or (``present`` False) remove it."""
    h = heaps.slot[node, w]
    if present:
        if h >= 0:
            if heaps.key[w, h] == key:
                return
            heaps.key[w, h] = key
            h2 = _up(heaps, w, h)
            if h2 == h:
                _down(heaps, w, h, heaps.size[w])
        else:
            size = nonneg(heaps.size[w])
            _place(heaps, w, size, node, key)
            heaps.size[w] = size + 1
            _up(heaps, w, size)
    elif h >= 0:
        last = nonneg(heaps.size[w] - 1)
        heaps.size[w] = last
        heaps.slot[node, w] = -1
        if h != last:
            _place(heaps, w, h, heaps.node[w, last], heaps.key[w, last])
            if _up(heaps, w, h) == h:
                _down(heaps, w, h, last)


@kernel_jit(forceinline=True)
def _group_lead(tk, tw, r, first):
    """(key, node) leading the group of ``TREE_ARITY`` entries from ``first`` in row r of a tree.

    The entries of a group lead disjoint runs of leaves in node order, so the
    first of the largest keys is also the lowest node among them: the tie rule.
    """
    first = nonneg(first)
    best = first
    bk = tk[r, first]
    for c in range(first + 1, first + TREE_ARITY):
        k = tk[r, c]
        if k > bk:
            best = c
            bk = k
    return bk, tw[r, best]


@kernel_jit(forceinline=True)
def tree_set(heaps, r, node, key):
    """Key the leaf of driven node ``node`` in driving tree r, and update the leads above it.

    Walks up while a group's lead changes: O(1) levels for most updates, log_8 L
    levels at most (L leaves).
    """
    tk = heaps.tkey
    tw = heaps.twin
    off = heaps.toff
    # Where every node is driven the leaves are the nodes: no lookup, whose
    # cache miss the key's load would wait for (0.61 -> 0.73 M slips/s,
    # irregular 1e6 nodes, one core).
    i = nonneg(heaps.leaf[node]) if heaps.leaf.size else node
    old_k = tk[r, i]
    if old_k == key:
        return
    tk[r, i] = key
    old_w = node
    new_k = key
    new_w = node
    for lev in range(off.size - 2):
        p = i // TREE_ARITY
        at = nonneg(off[lev + 1] + p)
        pk = tk[r, at]
        pw = tw[r, at]
        if pw == old_w:
            # The changed entry led its group: it still does if it did not fall
            # behind, else the group is scanned again.
            if not _before(new_k, new_w, old_k, old_w) and not (new_k == old_k and new_w == old_w):
                new_k, new_w = _group_lead(tk, tw, r, nonneg(off[lev] + p * TREE_ARITY))
        elif not _before(new_k, new_w, pk, pw):
            return  # another entry leads the group and still does
        if new_k == pk and new_w == pw:
            return
        tk[r, at] = new_k
        tw[r, at] = new_w
        old_k = pk
        old_w = pw
        i = p


@kernel_jit(forceinline=True)
def tree_rebuild(heaps, r):
    """Recompute every lead of driving tree r from its leaves, O(L)."""
    tk = heaps.tkey
    tw = heaps.twin
    off = heaps.toff
    for lev in range(off.size - 2):
        for p in range((off[lev + 1] - off[lev]) // TREE_ARITY):
            tk[r, off[lev + 1] + p], tw[r, off[lev + 1] + p] = _group_lead(tk, tw, r, off[lev] + p * TREE_ARITY)


@kernel_jit(forceinline=True)
def tree_top(heaps, r):
    """(node, key) leading driving tree r: node -1 if the tree has no leaves."""
    off = heaps.toff
    if off.size < 2:
        return -1, 0.0
    top = nonneg(off[off.size - 2])  # an offset into the tree's rows
    return heaps.twin[r, top], heaps.tkey[r, top]


@kernel_jit(forceinline=True)
def set_critical(heaps, j, dn, up):
    """Key a driven node j by its critical thetas theta_dn <= theta_up in the active driving tree,
    and list it as stale in the other (one update instead of two)."""
    if heaps.active[0] == UP:
        tree_set(heaps, UP, j, -up)
    else:
        tree_set(heaps, DOWN, j, dn)
    if not heaps.stale[j]:
        heaps.stale[j] = 1
        heaps.stale_nodes[nonneg(heaps.n_stale[0])] = j
        heaps.n_stale[0] += 1


@kernel_jit(forceinline=True)
def heap_clear(heaps):
    """Empty every heap, and key every leaf of the driving trees -inf (no event)."""
    heaps.slot[:] = -1
    heaps.size[:] = 0
    heaps.stale[:] = 0
    heaps.n_stale[0] = 0
    heaps.tkey[:] = -math.inf
    for r in range(heaps.tkey.shape[0]):
        tree_rebuild(heaps, r)


@kernel_jit()
def avalanche_done(st, avalanche_count):
    """Close the current avalanche: bin its size (slips) by floor(log2 size).

    ``st.av_slips`` counts the slips after the driving slip, so the size is
    one more; the relaxation at t = 0 has no driving slip and starts the
    count at -1 (:func:`open_initial_relaxation`).
    """
    if st.in_avalanche:
        size = st.av_slips + 1
        b = 0
        while size > 1:
            size >>= 1
            b += 1
        avalanche_count[b] += 1
        st.in_avalanche = 0


@kernel_jit(forceinline=True)
def open_initial_relaxation(st, heaps):
    """Open avalanche 0, the relaxation of an overload at t = 0 (a large f_ext), once.

    Call it on every entry of a network kernel: only the first entry of a
    run whose unstable heap is non-empty opens it. Later entries before t =
    0 is closed (after a buffer refill in the middle of the relaxation) find
    it open and must not restart its count. It has no driving slip, so its
    count starts at -1: its size (``av_slips`` + 1, see
    :func:`avalanche_done`) is then its slips alone.
    """
    if st.started == 0 and st.in_avalanche == 0 and heaps.size[UNSTABLE] > 0:
        st.in_avalanche = 1
        st.av_slips = -1


@kernel_jit(forceinline=True)
def open_recomputed_avalanche(st, heaps, thetas):
    """Open an avalanche for nodes that a recomputation of the forces found over their threshold.

    Between avalanches every node is stable; resetting the forces from the
    displacements (``RECOMPUTE``) can still find a node a rounding error
    over its threshold, which is common where thresholds are equal and the
    driver periodic (exact ties by design). Its slips are a new avalanche,
    like a driving event at the current theta: counted in ``n_events`` and
    in the avalanche sizes, stamped with the time of the current theta.
    Without this they ran under the previous avalanche's id and time, and
    the creep observables merged them into it. It has no driving slip, so
    its count starts at -1, as the relaxation at t = 0
    (:func:`open_initial_relaxation`). Call it on every entry of a network
    kernel, after that function; it does nothing inside an avalanche, before
    t = 0 is closed, or with no unstable node.
    """
    if st.started == 0 or st.in_avalanche != 0 or heaps.size[UNSTABLE] == 0:
        return
    q = st.q
    st.av_slips = -1
    st.in_avalanche = 1
    st.n_events += 1
    st.event_time = min(max(theta_time(thetas, q, st.theta), float(q)), math.nextafter(q + 1.0, q))


@kernel_jit(forceinline=True)
def theta_time(thetas, q, theta):
    """The time (tau_th) at which theta, linear in step q, is at ``theta``: q plus the fraction of the step
    covered; q where theta stands still in the step, or after the last step. Not clamped to the step.
    (The solver also calls it from Python, as ``theta_time.py_func``, for the time of a realization's state.)
    """
    if q + 1 < thetas.size and thetas[q + 1] != thetas[q]:
        return q + (theta - thetas[q]) / (thetas[q + 1] - thetas[q])
    return float(q)


@kernel_jit(forceinline=True)
def close_t0(st, out_steps):
    """Close t = 0 once the network is stable; True if the t = 0 output is due now.

    Call it where the unstable heap is empty and the avalanche closed, before
    the first driving event. It returns True at most once per run: the caller
    then writes the output (anything sampled at t = 0, such as the tilt
    test, must come before the call, since a kernel that returned for more
    draws before it would find t = 0 closed on re-entry).
    """
    if st.started != 0:
        return False
    st.started = 1
    return out_steps[st.next_out] == 0


@kernel_jit(forceinline=True)
def redraw_threshold(st, i, mu, mu_draws, node_slips):
    """After node i slipped: draw its new mu_s, keep mu_max and its holder, count the slip.

    mu_max is kept incrementally; only when the strongest node itself slips
    (possible in networks, never with two sliders) is it found by a rescan.
    """
    new = mu_draws[nonneg(st.mu_pos)]
    st.mu_pos += 1
    old = mu[i]
    mu[i] = new
    if new > st.mu_max:
        st.n_records += 1
        st.mu_max = new
        st.argmax = i
    elif i == st.argmax and new < old:
        best = 0
        for j in range(mu.size):
            if mu[j] > mu[best]:
                best = j
        st.argmax = best
        st.mu_max = mu[best]
    st.n_slips += 1
    st.since_recompute += 1
    node_slips[i] += 1


@kernel_jit(forceinline=True)
def replace_threshold(mu, i, new, best):
    """mu[i] = new, keeping ``best`` = (mu_max, its holder, n_records) as :func:`redraw_threshold` keeps
    st.mu_max, st.argmax and st.n_records: the inertial solvers' record statistics (float64, shape (3,);
    the holder and the count are exact integers in float64)."""
    old = mu[i]
    mu[i] = new
    if new > best[0]:
        best[2] += 1.0
        best[0] = new
        best[1] = i
    elif i == int(best[1]) and new < old:
        top = 0
        for j in range(mu.size):
            if mu[j] > mu[top]:
                top = j
        best[1] = top
        best[0] = mu[top]


@kernel_jit(forceinline=True)
def log_event(st, catalogue, i, dux, duy):
    """Append the slip of node i to the event catalogue, if it is recorded.

    ``catalogue.ids`` (rows, 2) int64 gets (node, avalanche id),
    ``catalogue.values`` (rows, 3) float64 gets (time in tau_th, du_x, du_y
    in Ntilde l0). The avalanche id is the number of driving events so far
    (0: the relaxation at t = 0). The caller checks for room before the
    slip; with the catalogue off the buffer has no rows and nothing is
    written.
    """
    k = nonneg(st.ev_pos)  # rows written so far: 0 or more
    if k < catalogue.ids.shape[0]:
        catalogue.ids[k, 0] = i
        catalogue.ids[k, 1] = st.n_events
        catalogue.values[k, 0] = st.event_time
        catalogue.values[k, 1] = dux
        catalogue.values[k, 2] = duy
        st.ev_pos = k + 1


@kernel_jit()
def mu_stats(mu):
    """Mean and smallest threshold over the nodes, O(N): called at output steps only."""
    total = 0.0
    low = mu[0]
    for j in range(mu.size):
        total += mu[j]
        low = min(low, mu[j])
    return total / mu.size, low


@kernel_jit()
def write_output(st, mu, out):
    """Write the state into output slot ``st.next_out`` and advance it.

    Every kernel writes n, mu_max, x_G and n_records; the fields its scene
    has not (0-length arrays of :class:`~slidernet.kernels.state.Series`)
    are left out.
    """
    k = st.next_out
    out.n[k] = st.n_slips
    out.mu_max[k] = st.mu_max
    out.x_G[k] = st.x_G
    out.n_records[k] = st.n_records
    if out.y_G.size:
        out.y_G[k] = st.y_G
    if out.mu_mean.size:
        out.mu_mean[k], out.mu_min[k] = mu_stats(mu)
    st.next_out = k + 1


@kernel_jit()
def write_ages(t, last_slip, out, k):
    """Write the contact ages at time t (tau_th) into output slot k: their mean and their histogram.

    The age of node i is t - ``last_slip[i]`` (the event time of its last
    slip, 0.0 if it has not slipped). The mean is t - mean(last_slip), the
    sum in node order; each age is binned against
    :data:`~slidernet.kernels.state.AGE_EDGES` (bin 0: below the first
    edge). O(N log bins), at output steps only.
    """
    total = 0.0
    for j in range(last_slip.size):
        total += last_slip[j]
        out.contact_age_count[k, np.searchsorted(AGE_EDGES, t - last_slip[j], side="right")] += 1
    out.contact_age[k] = t - total / last_slip.size


@kernel_jit(forceinline=True)
def buffers_low(st, draws, catalogue):
    """Why a slip cannot happen now: ``NEED_MU`` (no threshold left to redraw), ``NEED_EVENTS``
    (the catalogue's buffer is full), or ``DONE`` (it can). Checked before every slip, so that a
    kernel returns only at clean points."""
    if st.mu_pos >= draws.mu.size:
        return NEED_MU
    if st.ev_on and st.ev_pos >= catalogue.ids.shape[0]:
        return NEED_EVENTS
    return DONE


@kernel_jit(forceinline=True)
def next_driving_event(st, heaps, thetas, s):
    """The next node to reach its threshold as theta moves linearly from thetas[q] to thetas[q + 1].

    ``s`` is the sign of d(theta)/dt in the step (:func:`theta_direction`).
    Reads the driving tree of that direction (upper critical thetas when
    theta rises, lower ones when it falls; eq. `critique` for each node).
    Returns ``(node, theta_c)``: node -1 if none is reached within the
    segment (inclusive at its end); theta_c is clamped to the current theta
    where rounding put it behind.
    """
    theta_b = thetas[nonneg(st.q) + 1]
    best = -1
    thc = 0.0
    if s > 0.0:
        best, key = tree_top(heaps, UP)
        thc = -key
    elif s < 0.0:
        best, thc = tree_top(heaps, DOWN)
    if best >= 0:
        theta = st.theta
        if s * (thc - theta) < 0.0:
            thc = theta  # rounding: the node is already at its threshold
        if s * (theta_b - thc) < 0.0:
            best = -1
    return best, thc


@kernel_jit(forceinline=True)
def theta_direction(st, thetas):
    """The sign s of d(theta)/dt in step q: 1.0, -1.0, or 0.0 where theta stands still."""
    q = nonneg(st.q)
    theta_a = thetas[q]
    theta_b = thetas[q + 1]
    return 1.0 if theta_b > theta_a else (-1.0 if theta_b < theta_a else 0.0)


@kernel_jit(forceinline=True)
def open_driving_event(st, thetas, thc):
    """Start the avalanche of a driving event at theta_c: count it, and stamp its time (q + fraction).

    The stamps of step q lie in [q, q + 1). An event at theta(t_{q+1})
    itself (or a fraction that rounds up to 1) happens in step q, before the
    output at q + 1, but q + fraction would read q + 1, the stamp of an event
    at the start of step q + 1, after that output. It is stamped one ulp
    below q + 1 instead. Periodic drivers with constant thresholds put
    events exactly on the samples.
    """
    q = nonneg(st.q)
    st.av_slips = 0
    st.in_avalanche = 1
    st.n_events += 1
    time = q + (thc - thetas[q]) / (thetas[q + 1] - thetas[q])
    st.event_time = time if time < q + 1.0 else math.nextafter(q + 1.0, q)


@kernel_jit(forceinline=True)
def end_step(st, thetas, out_steps):
    """No node reaches its threshold before thetas[q + 1]: go there; True if that step is an output step."""
    q = nonneg(st.q)
    st.q = q + 1
    st.theta = thetas[q + 1]
    return st.next_out < out_steps.size and out_steps[st.next_out] == q + 1
