"""General 1D networks: CSR rows of K, a heap of unstable nodes, two driving heaps.

The force on node i is F_i = a_i + g_i theta, with a = -K u - g theta(0)
(+ f_ext) updated incrementally on the CSR row of the slipped node. A node
is stable while |F_i| <= mu_s,i N_i, i.e. while theta lies between its two
critical values theta_dn,i <= theta <= theta_up,i (eq. `critique` for node i);
these only change when the node or a neighbour slips.
"""

from __future__ import annotations

from slidernet.kernels.heap import (
    avalanche_done,
    buffers_low,
    close_t0,
    end_step,
    heap_set,
    log_event,
    mu_stats,
    next_driving_event,
    open_driving_event,
    open_initial_relaxation,
    redraw_threshold,
)
from slidernet.kernels.state import (
    AV_SLIPS,
    AVALANCHE_LIMIT,
    DONE,
    DOWN_SIZE,
    ERR_NODE,
    HEAP_SIZE,
    IN_AVALANCHE,
    REC,
    RECOMPUTE,
    SINCE_RECOMPUTE,
    STARTED,
    THETA,
    UP_SIZE,
    XG,
    Q,
    kernel_jit,
    write_record,
)
from slidernet.kernels.tilt import tilt_sample


@kernel_jit(inline="always")
def update_node(j, theta, a, g, mu, normal_load, hp, hv, hpos, ist):
    """Re-key node j in the three heaps after its force or threshold changed."""
    F = abs(a[j] + g[j] * theta)
    lim = mu[j] * normal_load[j]
    # Most updated nodes are stable and out of the heap: skip the call then.
    if F > lim or hpos[j, 0] >= 0:
        heap_set(j, F / lim, F > lim, hp, hv, hpos, 0, ist, HEAP_SIZE)
    gj = g[j]
    if gj != 0.0:
        # The two roots of |a_j + g_j theta| = mu_s,j N_j.
        if gj > 0.0:
            up = (lim - a[j]) / gj
            dn = (-lim - a[j]) / gj
        else:
            up = (-lim - a[j]) / gj
            dn = (lim - a[j]) / gj
        heap_set(j, -up, True, hp, hv, hpos, 1, ist, UP_SIZE)
        heap_set(j, dn, True, hp, hv, hpos, 2, ist, DOWN_SIZE)


@kernel_jit()
def init_csr_heaps(a, g, mu, normal_load, hp, hv, hpos, ist, fst):
    """(Re)build the three heaps from scratch, O(N log N)."""
    hpos[:] = -1
    ist[HEAP_SIZE] = 0
    ist[UP_SIZE] = 0
    ist[DOWN_SIZE] = 0
    theta = fst[THETA]
    for j in range(mu.size):
        update_node(j, theta, a, g, mu, normal_load, hp, hv, hpos, ist)


@kernel_jit(inline="always")
def _slip(i, Fi, absF, a, u, mu, indptr, indices, kdata, kdiag, g, normal_load, w,
          ist, fst, mu_buf, mu_d, hp, hv, hpos, node_slips, ev_i, ev_f):
    """Node i slips alone (undamped half-oscillation); its threshold is redrawn."""
    sgn = 1.0 if Fi > 0.0 else -1.0
    du = 2.0 * (absF - mu_d * normal_load[i]) * sgn / kdiag[i]
    log_event(i, du, 0.0, ist, fst, ev_i, ev_f)
    u[i] += du
    for p in range(indptr[i], indptr[i + 1]):
        a[indices[p]] -= kdata[p] * du
    fst[XG] += du * w[i]
    redraw_threshold(i, mu, mu_buf, ist, fst, node_slips)
    theta = fst[THETA]
    for p in range(indptr[i], indptr[i + 1]):
        update_node(indices[p], theta, a, g, mu, normal_load, hp, hv, hpos, ist)


@kernel_jit()
def _record(ist, fst, mu, out_n, out_mu_max, out_xg, out_records, out_mu_mean, out_mu_min):
    k = ist[REC]
    write_record(ist, fst, out_n, out_mu_max, out_xg, out_records)
    out_mu_mean[k], out_mu_min[k] = mu_stats(mu)


@kernel_jit()
def run_csr(
    thetas, rec_times, mu, ist, fst, a, u, mu_buf, tmu, tu, mu_d, do_tilt, max_slips,
    recompute_every, indptr, indices, kdata, kdiag, g, normal_load, w, hp, hv, hpos,
    aval_hist, node_slips, ev_i, ev_f, out_n, out_mu_max, out_xg, out_records, out_mu_mean,
    out_mu_min, fsum, fsq, fcount,
):
    """Advance a 1D network through ``thetas`` (units of Ntilde).

    The heaps must have been built by :func:`init_csr_heaps`. The tilt test
    (``do_tilt``) is defined for 2-node networks only. Returns ``RECOMPUTE``
    every ``recompute_every`` slips (0: never) so that the caller can
    recompute ``a`` from ``u`` and rebuild the heaps, and ``NEED_EVENTS``
    when the event catalogue (``ev_i``, ``ev_f``, see
    :func:`~slidernet.kernels.heap.log_event`) is on and its buffer is full.
    """
    steps = thetas.size - 1
    # A load f_ext above some threshold is relaxed first, as part of t = 0.
    open_initial_relaxation(ist)
    while True:
        while ist[HEAP_SIZE] > 0:
            i = hp[0, 0]
            theta = fst[THETA]
            Fi = a[i] + g[i] * theta
            ist[AV_SLIPS] += 1
            if ist[AV_SLIPS] > max_slips:
                ist[ERR_NODE] = i
                return AVALANCHE_LIMIT
            # The buffer check comes first: a kernel that returns after the
            # tilt sample would take it again on re-entry.
            st = buffers_low(ist, mu_buf, ev_i)
            if st != DONE:
                ist[AV_SLIPS] -= 1
                return st
            if do_tilt:
                st = tilt_sample(a[1] + g[1] * theta, mu[0], mu[1], mu_d, tmu, tu, ist,
                                 ist[REC], fsum, fsq, fcount)
                if st != DONE:
                    ist[AV_SLIPS] -= 1
                    return st
            _slip(i, Fi, abs(Fi), a, u, mu, indptr, indices, kdata, kdiag, g, normal_load, w,
                  ist, fst, mu_buf, mu_d, hp, hv, hpos, node_slips, ev_i, ev_f)
        avalanche_done(ist, aval_hist, AV_SLIPS, IN_AVALANCHE)
        if ist[STARTED] == 0:
            # The tilt test before each rearrangement needs f_ext = 0, so
            # there was no initial relaxation: this is the state at t = 0.
            if do_tilt:
                st = tilt_sample(a[1] + g[1] * fst[THETA], mu[0], mu[1], mu_d, tmu, tu, ist,
                                 ist[REC], fsum, fsq, fcount)
                if st != DONE:
                    return st
            if close_t0(ist, rec_times):
                _record(ist, fst, mu, out_n, out_mu_max, out_xg, out_records, out_mu_mean, out_mu_min)
        if recompute_every > 0 and ist[SINCE_RECOMPUTE] >= recompute_every:
            return RECOMPUTE
        if ist[Q] >= steps:
            return DONE
        best, thc, s = next_driving_event(thetas, ist, fst, hp, hv)
        if best >= 0:
            fst[THETA] = thc
            st = buffers_low(ist, mu_buf, ev_i)
            if st != DONE:
                return st
            if do_tilt:
                st = tilt_sample(a[1] + g[1] * thc, mu[0], mu[1], mu_d, tmu, tu, ist,
                                 ist[REC], fsum, fsq, fcount)
                if st != DONE:
                    return st
            # At theta_c the force on the node is exactly +-mu_s N, with the
            # sign of g s (the direction its force moves).
            lim = mu[best] * normal_load[best]
            sigma = 1.0 if g[best] * s > 0.0 else -1.0
            open_driving_event(thetas, thc, ist, fst)
            _slip(best, sigma * lim, lim, a, u, mu, indptr, indices, kdata, kdiag, g,
                  normal_load, w, ist, fst, mu_buf, mu_d, hp, hv, hpos, node_slips, ev_i, ev_f)
            continue
        if end_step(thetas, rec_times, ist, fst):
            _record(ist, fst, mu, out_n, out_mu_max, out_xg, out_records, out_mu_mean, out_mu_min)
