"""Compiled event-driven kernels (numba).

Units are the internal ones of :mod:`slidernet.network`: forces in N,
stiffnesses in k0 = N/(Ntilde l0), lengths in Ntilde l0, and theta enters as
theta/Ntilde. In these units the paper's spring has k = 1, so equation
`critique` reads theta_c = u + mu_min s and equation `displacement` reads
Delta u = 2 (mu_min - mu_d) s.

Two kernels, one per scene ("model only what a scene needs"):

* :func:`run_pair` -- the paper's two sliders: scalars only, no arrays, no queue;
* :func:`run_csr` -- any 1D network: CSR neighbour lists, an indexed max-heap
  of unstable nodes for avalanches.

Both perform the *same floating-point operations* on a 2-node chain, so they
agree to the bit (tested). The kernels are resumable state machines: all state
lives in the arrays ``ist`` (integers) and ``fst`` (floats), and a kernel
returns at a clean point when a buffer of random draws runs low, so that the
Python driver can refill it with the plugin's ``sample`` in batches.

Return codes are the ``DONE``, ``NEED_MU``, ``NEED_TILT``, ``AVALANCHE_LIMIT``
and ``TILT_LIMIT`` constants below.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# Return codes.
DONE = 0
NEED_MU = 1  # the horizontal threshold buffer is empty
NEED_TILT = 2  # the tilt-test buffers ran out during a test (rolled back)
AVALANCHE_LIMIT = 3  # an avalanche exceeded max_slips
TILT_LIMIT = 4  # a tilt test exceeded its iteration cap

# Integer state (ist) slots.
Q = 0  # next thermal step: the segment thetas[q] -> thetas[q+1]
N_SLIPS = 1  # cumulative rearrangements n
REC = 2  # index of the next record time
MU_POS = 3  # read position in the threshold buffer
TMU_POS = 4  # read position in the tilt-test threshold buffer
TU_POS = 5  # read position in the tilt-test uniform buffer
N_RECORDS = 6  # draws that exceeded the running mu_max
ARGMAX = 7  # node holding mu_max
ERR_NODE = 8  # node named by an error
AV_SLIPS = 9  # slips in the current avalanche
HEAP_SIZE = 10  # size of the unstable-node heap (run_csr)
N_EVENTS = 11  # driving events (= avalanches)
STARTED = 12  # 1 once the t = 0 record is written
N_IST = 13

# Float state (fst) slots.
THETA = 0  # current theta / Ntilde
XG = 1  # centre-of-mass displacement / (Ntilde l0)
MU_MAX = 2  # largest threshold mu_s
U = 3  # run_pair only: the paper's u / Ntilde (spring length change)
N_FST = 4

TILT_MAX_ITER = 1_000_000


@njit(cache=True)
def tilt_test_pair(F, mu1, mu2, mu_d, tmu, tu, ist):
    """The appendix's virtual tilt test on a copy of (F, mu1, mu2).

    ``F`` is F_{1->2}, the spring force on slider 2 in units of N. Returns the
    tangential force f at which the whole system slides (mu_eff sample), -1.0
    if the draw buffers ran out (read positions are then left untouched), or
    -2.0 after ``TILT_MAX_ITER`` iterations.
    """
    p_mu = ist[TMU_POS]
    p_u = ist[TU_POS]
    for _ in range(TILT_MAX_ITER):
        f1 = mu1 + F
        f2 = mu2 - F
        if f1 <= f2:  # slider 1 moves first (ties: lowest index)
            i = 1
            f = f1
            bound = mu_d - 0.5 * (mu1 - mu2)
        else:
            i = 2
            f = f2
            bound = mu_d + 0.5 * (mu1 - mu2)
        if f >= bound:  # eq. `stab`: the other slider moves too
            if f > mu_d:
                ist[TMU_POS] = p_mu
                ist[TU_POS] = p_u
                return f
            # Creep: the damped motion stops; the appendix redraws both
            # thresholds and a force uniform in [f - mu1, mu2 - f].
            if p_mu + 2 > tmu.size or p_u + 1 > tu.size:
                return -1.0
            mu1 = tmu[p_mu]
            mu2 = tmu[p_mu + 1]
            p_mu += 2
            lo = f - mu1
            F = lo + ((mu2 - f) - lo) * tu[p_u]
            p_u += 1
        else:
            if p_mu + 1 > tmu.size:
                return -1.0
            if i == 1:
                F += 2.0 * (mu1 - mu_d)
                mu1 = tmu[p_mu]
            else:
                F -= 2.0 * (mu2 - mu_d)
                mu2 = tmu[p_mu]
            p_mu += 1
    return -2.0


@njit(cache=True)
def _tilt_sample(F, mu1, mu2, mu_d, tmu, tu, ist, k, fsum, fsq, fcount):
    """Run one tilt test and add its sample to record bin ``k``; returns a status."""
    f = tilt_test_pair(F, mu1, mu2, mu_d, tmu, tu, ist)
    if f == -1.0:
        return NEED_TILT
    if f == -2.0:
        return TILT_LIMIT
    fsum[k] += f
    fsq[k] += f * f
    fcount[k] += 1
    return DONE


@njit(cache=True)
def _write_record(ist, fst, out_n, out_mu_max, out_xg, out_records):
    k = ist[REC]
    out_n[k] = ist[N_SLIPS]
    out_mu_max[k] = fst[MU_MAX]
    out_xg[k] = fst[XG]
    out_records[k] = ist[N_RECORDS]
    ist[REC] = k + 1


# --------------------------------------------------------------------------
# The paper's two sliders.
# --------------------------------------------------------------------------


@njit(cache=True)
def run_pair(
    thetas, rec_times, mu, ist, fst, mu_buf, tmu, tu, mu_d, do_tilt, max_slips,
    out_n, out_mu_max, out_xg, out_records, fsum, fsq, fcount,
):
    """Advance the two-slider system through ``thetas`` (units of Ntilde).

    Slider 1 is index 0, slider 2 is index 1; ``mu`` holds (mu_s,1, mu_s,2).
    The spring force on slider 2 is F = theta - u (eq. `eqF12` in these
    units). The hot state is held in local scalars and written back on exit.
    """
    steps = thetas.size - 1
    if ist[STARTED] == 0:
        if do_tilt:
            st = _tilt_sample(fst[THETA] - fst[U], mu[0], mu[1], mu_d, tmu, tu, ist,
                              ist[REC], fsum, fsq, fcount)
            if st != DONE:
                return st
        if rec_times[ist[REC]] == 0:
            _write_record(ist, fst, out_n, out_mu_max, out_xg, out_records)
        ist[STARTED] = 1
    u = fst[U]
    theta = fst[THETA]
    xg = fst[XG]
    mumax = fst[MU_MAX]
    mu0 = mu[0]
    mu1 = mu[1]
    n = ist[N_SLIPS]
    p = ist[MU_POS]
    nrec = ist[N_RECORDS]
    nev = ist[N_EVENTS]
    av = ist[AV_SLIPS]
    pending = ist[HEAP_SIZE]  # 1 while a slip has left a slider over its threshold
    q = ist[Q]
    k = ist[REC]
    nbuf = mu_buf.size
    status = DONE
    while True:
        i = -1
        Fi = 0.0
        aFi = 0.0
        if pending:
            # Avalanche: largest overload first, ties to the lowest index.
            # With two sliders this needs mu_min > 3 mu_d (the slipped slider
            # overshoots past its new threshold).
            F = theta - u
            aF = abs(F)
            un0 = aF > mu0 * 1.0
            un1 = aF > mu1 * 1.0
            if un1 and (not un0 or aF / (mu1 * 1.0) > aF / (mu0 * 1.0)):
                i = 1
                Fi = F
            elif un0:
                i = 0
                Fi = -F
            else:
                pending = 0
                continue
            aFi = aF
            av += 1
            if av > max_slips:
                ist[ERR_NODE] = i
                status = AVALANCHE_LIMIT
                break
            # The buffer check comes first: a kernel that returns after the
            # tilt sample would take it again on re-entry.
            if p >= nbuf:
                av -= 1
                status = NEED_MU
                break
            if do_tilt:
                st = _tilt_sample(F, mu0, mu1, mu_d, tmu, tu, ist, k, fsum, fsq, fcount)
                if st != DONE:
                    av -= 1
                    status = st
                    break
        else:
            if q >= steps:
                break
            theta_b = thetas[q + 1]
            theta_a = thetas[q]
            s = 1.0 if theta_b > theta_a else (-1.0 if theta_b < theta_a else 0.0)
            if s != 0.0:
                # eq. `critique` for each slider; the first one reached slips.
                th0 = s * mu0 * 1.0 + u
                th1 = s * mu1 * 1.0 + u
                if s * (th0 - theta) < 0.0:
                    th0 = theta
                if s * (th1 - theta) < 0.0:
                    th1 = theta
                i = 0
                thc = th0
                if s * th1 < s * th0:
                    i = 1
                    thc = th1
                if s * (theta_b - thc) >= 0.0:
                    theta = thc
                    if p >= nbuf:
                        status = NEED_MU
                        break
                    if do_tilt:
                        st = _tilt_sample(thc - u, mu0, mu1, mu_d, tmu, tu, ist, k,
                                          fsum, fsq, fcount)
                        if st != DONE:
                            status = st
                            break
                    # At theta_c the force on slider i is exactly s_i mu_s,i.
                    aFi = (mu1 if i == 1 else mu0) * 1.0
                    Fi = s * aFi if i == 1 else -s * aFi
                    av = 0
                    nev += 1
                else:
                    i = -1
            if i < 0:
                q += 1
                theta = theta_b
                if k < rec_times.size and rec_times[k] == q:
                    out_n[k] = n
                    out_mu_max[k] = mumax
                    out_xg[k] = xg
                    out_records[k] = nrec
                    k += 1
                continue
        # Slider i slips alone (eq. `displacement`); its threshold is redrawn.
        sgn = 1.0 if Fi > 0.0 else -1.0
        du = 2.0 * (aFi - mu_d * 1.0) * sgn / 1.0
        if i == 1:
            u = u + du
        else:
            u = u - du
        xg += du * 0.5
        new = mu_buf[p]
        p += 1
        if new > mumax:
            nrec += 1
        if i == 1:
            mu1 = new
        else:
            mu0 = new
        mumax = max(mu0, mu1)
        n += 1
        aF = abs(theta - u)
        if aF > mu0 * 1.0 or aF > mu1 * 1.0:
            pending = 1
    fst[U] = u
    fst[THETA] = theta
    fst[XG] = xg
    fst[MU_MAX] = mumax
    mu[0] = mu0
    mu[1] = mu1
    ist[N_SLIPS] = n
    ist[MU_POS] = p
    ist[N_RECORDS] = nrec
    ist[N_EVENTS] = nev
    ist[AV_SLIPS] = av
    ist[HEAP_SIZE] = pending
    ist[Q] = q
    ist[REC] = k
    return status


# --------------------------------------------------------------------------
# General 1D networks: CSR neighbour lists and an indexed heap.
# --------------------------------------------------------------------------


@njit(cache=True)
def _before(ka, na, kb, nb):
    """Heap order: larger overload first; ties go to the lower node index."""
    return ka > kb or (ka == kb and na < nb)


@njit(cache=True)
def _heap_swap(heap, pos, a, b):
    na = heap[a]
    nb = heap[b]
    heap[a] = nb
    heap[b] = na
    pos[nb] = a
    pos[na] = b


@njit(cache=True)
def _heap_up(heap, pos, key, h):
    while h > 0:
        p = (h - 1) >> 1
        if _before(key[heap[h]], heap[h], key[heap[p]], heap[p]):
            _heap_swap(heap, pos, h, p)
            h = p
        else:
            break


@njit(cache=True)
def _heap_down(heap, pos, key, h, size):
    while True:
        c = 2 * h + 1
        if c >= size:
            break
        if c + 1 < size and _before(key[heap[c + 1]], heap[c + 1], key[heap[c]], heap[c]):
            c += 1
        if _before(key[heap[c]], heap[c], key[heap[h]], heap[h]):
            _heap_swap(heap, pos, h, c)
            h = c
        else:
            break


@njit(cache=True)
def _heap_update(node, overload, unstable, heap, pos, key, ist):
    """Insert, re-key or remove ``node`` in the heap of unstable nodes."""
    h = pos[node]
    if unstable:
        key[node] = overload
        if h < 0:
            size = ist[HEAP_SIZE]
            heap[size] = node
            pos[node] = size
            ist[HEAP_SIZE] = size + 1
            _heap_up(heap, pos, key, size)
        else:
            _heap_up(heap, pos, key, h)
            _heap_down(heap, pos, key, pos[node], ist[HEAP_SIZE])
    elif h >= 0:
        last = ist[HEAP_SIZE] - 1
        ist[HEAP_SIZE] = last
        pos[node] = -1
        if h != last:
            moved = heap[last]
            heap[h] = moved
            pos[moved] = h
            _heap_up(heap, pos, key, h)
            _heap_down(heap, pos, key, pos[moved], last)


@njit(cache=True)
def _csr_slip(i, Fi, absF, a, u, mu, indptr, indices, kdata, kdiag, g, normal_load, w,
              ist, fst, mu_buf, mu_d, heap, pos, key):
    """Node i slips alone; a = F - theta g is updated for i and its neighbours."""
    sgn = 1.0 if Fi > 0.0 else -1.0
    du = 2.0 * (absF - mu_d * normal_load[i]) * sgn / kdiag[i]
    u[i] += du
    for p in range(indptr[i], indptr[i + 1]):
        a[indices[p]] -= kdata[p] * du
    fst[XG] += du * w[i]
    new = mu_buf[ist[MU_POS]]
    ist[MU_POS] += 1
    old = mu[i]
    mu[i] = new
    if new > fst[MU_MAX]:
        ist[N_RECORDS] += 1
        fst[MU_MAX] = new
        ist[ARGMAX] = i
    elif i == ist[ARGMAX] and new < old:
        # The strongest node slipped (possible in networks): rescan.
        best = 0
        for j in range(mu.size):
            if mu[j] > mu[best]:
                best = j
        ist[ARGMAX] = best
        fst[MU_MAX] = mu[best]
    ist[N_SLIPS] += 1
    theta = fst[THETA]
    for p in range(indptr[i], indptr[i + 1]):
        j = indices[p]
        F = a[j] + g[j] * theta
        lim = mu[j] * normal_load[j]
        _heap_update(j, abs(F) / lim, abs(F) > lim, heap, pos, key, ist)


@njit(cache=True)
def run_csr(
    thetas, rec_times, mu, ist, fst, a, u, mu_buf, tmu, tu, mu_d, do_tilt, max_slips,
    indptr, indices, kdata, kdiag, g, normal_load, w, driven, heap, pos, key,
    out_n, out_mu_max, out_xg, out_records, fsum, fsq, fcount,
):
    """Advance a 1D network through ``thetas`` (units of Ntilde).

    The force on node i is F_i = a_i + g_i theta with a = -K u - g theta(0),
    updated incrementally on the CSR rows of K. ``driven`` lists the nodes
    with g_i != 0 in increasing order: only they can start an avalanche.
    The tilt test (``do_tilt``) is defined for 2-node networks only.
    """
    steps = thetas.size - 1
    if ist[STARTED] == 0:
        if do_tilt:
            F = a[1] + g[1] * fst[THETA]
            st = _tilt_sample(F, mu[0], mu[1], mu_d, tmu, tu, ist,
                              ist[REC], fsum, fsq, fcount)
            if st != DONE:
                return st
        if rec_times[ist[REC]] == 0:
            _write_record(ist, fst, out_n, out_mu_max, out_xg, out_records)
        ist[STARTED] = 1
    while True:
        while ist[HEAP_SIZE] > 0:
            i = heap[0]
            theta = fst[THETA]
            Fi = a[i] + g[i] * theta
            ist[AV_SLIPS] += 1
            if ist[AV_SLIPS] > max_slips:
                ist[ERR_NODE] = i
                return AVALANCHE_LIMIT
            if ist[MU_POS] >= mu_buf.size:
                ist[AV_SLIPS] -= 1
                return NEED_MU
            if do_tilt:
                st = _tilt_sample(a[1] + g[1] * theta, mu[0], mu[1], mu_d, tmu, tu, ist,
                                  ist[REC], fsum, fsq, fcount)
                if st != DONE:
                    ist[AV_SLIPS] -= 1
                    return st
            _csr_slip(i, Fi, abs(Fi), a, u, mu, indptr, indices, kdata, kdiag, g,
                      normal_load, w, ist, fst, mu_buf, mu_d, heap, pos, key)
        q = ist[Q]
        if q >= steps:
            return DONE
        theta_b = thetas[q + 1]
        s = 1.0 if theta_b > thetas[q] else (-1.0 if theta_b < thetas[q] else 0.0)
        if s != 0.0:
            theta = fst[THETA]
            best = -1
            thc = 0.0
            sigma_best = 0.0
            for d in range(driven.size):
                j = driven[d]
                sigma = 1.0 if g[j] * s > 0.0 else -1.0
                th = (sigma * mu[j] * normal_load[j] - a[j]) / g[j]
                if s * (th - theta) < 0.0:
                    th = theta
                if best < 0 or s * th < s * thc:
                    best = j
                    thc = th
                    sigma_best = sigma
            if best >= 0 and s * (theta_b - thc) >= 0.0:
                fst[THETA] = thc
                if ist[MU_POS] >= mu_buf.size:
                    return NEED_MU
                if do_tilt:
                    st = _tilt_sample(a[1] + g[1] * thc, mu[0], mu[1], mu_d, tmu, tu, ist,
                                      ist[REC], fsum, fsq, fcount)
                    if st != DONE:
                        return st
                lim = mu[best] * normal_load[best]
                ist[AV_SLIPS] = 0
                ist[N_EVENTS] += 1
                _csr_slip(best, sigma_best * lim, lim, a, u, mu, indptr, indices, kdata,
                          kdiag, g, normal_load, w, ist, fst, mu_buf, mu_d, heap, pos, key)
                continue
        ist[Q] = q + 1
        fst[THETA] = theta_b
        if ist[REC] < rec_times.size and rec_times[ist[REC]] == q + 1:
            _write_record(ist, fst, out_n, out_mu_max, out_xg, out_records)


def empty_state() -> tuple[np.ndarray, np.ndarray]:
    """Fresh (ist, fst) arrays."""
    return np.zeros(N_IST, dtype=np.int64), np.zeros(N_FST, dtype=np.float64)
