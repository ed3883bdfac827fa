"""The paper's two sliders: a scalar kernel (no arrays in the hot loop, no queue)."""

from __future__ import annotations

from slidernet.kernels.heap import write_output
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.state import AVALANCHE_LIMIT, DONE, NEED_MU, nonneg
from slidernet.kernels.tilt import tilt_sample


@kernel_jit(forceinline=True)
def _most_overloaded(F, mu0, mu1):
    """The slider that slips next in an avalanche under spring force F: (i, F_i), i = -1 if both are stable.

    Largest overload first, ties to the lowest index. With two sliders and the
    paper's slip an avalanche needs mu_min > 3 mu_d (the slipped slider
    overshoots past its new threshold).
    """
    aF = abs(F)
    un0 = aF > mu0 * 1.0
    un1 = aF > mu1 * 1.0
    if un1 and (not un0 or aF / (mu1 * 1.0) > aF / (mu0 * 1.0)):
        return 1, F
    if un0:
        return 0, -F
    return -1, 0.0


@kernel_jit(forceinline=True)
def no_tilt(st, draws, out, k, F, mu1, mu2, mu_d, sf):
    """The ``tilt`` of :func:`run_pair`: no test, DONE (LLVM folds the call away)."""
    return DONE


@kernel_jit()
def run_pair(thetas, out_steps, mu, state, draws, out, settings):
    """Advance the two-slider system through ``thetas`` (units of Ntilde): :func:`_run_pair` without the
    tilt test."""
    return _run_pair(thetas, out_steps, mu, state, draws, out, settings, no_tilt)


@kernel_jit()
def run_pair_tilt(thetas, out_steps, mu, state, draws, out, settings):
    """:func:`run_pair` with the appendix's tilt test before every rearrangement (and at t = 0)."""
    return _run_pair(thetas, out_steps, mu, state, draws, out, settings, tilt_sample)


@kernel_jit(inline="always")
def _run_pair(thetas, out_steps, mu, state, draws, out, settings, tilt):
    """Advance the two-slider system through ``thetas`` (units of Ntilde).

    Slider 1 is index 0, slider 2 is index 1; ``mu`` holds (mu_s,1, mu_s,2).
    The spring force on slider 2 is F = theta - u (eq. `eqF12` in these
    units). The hot state is held in local scalars and written back to
    ``state[0]`` on exit. ``out`` is a :class:`~slidernet.kernels.state.Series`
    without ``mu_mean``, ``mu_min`` and ``y_G``. ``tilt(st, draws, out, k, F,
    mu1, mu2, mu_d, sf)`` is :func:`~slidernet.kernels.tilt.tilt_sample` (the
    appendix's test before every rearrangement) or :func:`no_tilt`. A slip
    is ``c = settings.slip_factor`` times (|F| - mu_d) long (c = 2: the
    paper's eq. `displacement`).
    """
    st = state[0]
    mu_d = settings.mu_d
    c = settings.slip_factor
    max_slips = settings.max_slips
    steps = thetas.size - 1
    if st.started == 0:
        status = tilt(st, draws, out, st.next_out, st.theta - st.u, mu[0], mu[1], mu_d, c)
        if status != DONE:
            return status
        if out_steps[st.next_out] == 0:
            write_output(st, mu, out)
        st.started = 1
    u = st.u
    theta = st.theta
    xg = st.x_G
    mumax = st.mu_max
    mu0 = mu[0]
    mu1 = mu[1]
    n = st.n_slips
    p = st.mu_pos
    nrec = st.n_records
    nev = st.n_events
    av = st.av_slips
    pending = st.pending
    q = st.q
    k = st.next_out
    mu_draws = draws.mu
    nbuf = mu_draws.size
    status = DONE
    while True:
        if pending:
            F = theta - u
            i, Fi = _most_overloaded(F, mu0, mu1)
            if i < 0:
                pending = 0
                continue
            aFi = abs(F)
            av += 1
            if av > max_slips:
                st.err_node = i
                status = AVALANCHE_LIMIT
                break
            # The buffer check comes first: a kernel that returns after the
            # tilt sample would take it again on re-entry.
            if p >= nbuf:
                av -= 1
                status = NEED_MU
                break
            status = tilt(st, draws, out, k, F, mu0, mu1, mu_d, c)
            if status != DONE:
                av -= 1
                break
        else:
            if q >= steps:
                break
            # nonneg on q, p and k (indices >= 0 read from the state record): numba's wrap-around of a
            # negative index goes away from the step's reads and the driving loop's draw (sign tests,
            # sar $63: 16 -> 13; those left are in the inlined tilt test, whose indices are left as
            # they were: nonneg there made LLVM stop inlining tilt_test_pair, slower with the tilt).
            # Interleaved runs on core 0, 10 x 1e5 steps, best of 5 per run (2026-11-26, slips and
            # mu_max unchanged): +2 to +11 %, median of 5 rounds +6 % (single runs: noise, +-25 %).
            qq = nonneg(q)
            theta_b = thetas[qq + 1]
            theta_a = thetas[qq]
            s = 1.0 if theta_b > theta_a else (-1.0 if theta_b < theta_a else 0.0)
            if s != 0.0:
                # The driving events of this step, one slip each, until the step ends, a
                # buffer runs out or a slip leaves a slider unstable (the avalanche branch
                # above takes over). The loop runs in coordinates multiplied by s = +-1
                # (v = s u, vt = s theta, xr = s x_G), where eq. `critique` reads
                # s theta_c = mu_s,i + v and a slip adds 2 (mu_s,i - mu_d) to v whichever
                # slider slips: negation is exact and commutes with rounding, so these are
                # the bits of the unscaled equations, with nothing but an add on u's chain of
                # dependent operations. Which slider slips is a coin toss: a select, not a
                # branch, on mu_s,2 < mu_s,1, which does not wait for v (comparing the
                # rounded theta_c put two more operations on the chain: 75 -> 108 M/s, draws
                # included, benchmarks/ab_versions.py). Where the rounded theta_c tie, slider 1
                # slips, as before and as in the heaps: that check is a branch never taken.
                v = s * u
                vt = s * theta
                vb = s * theta_b
                xr = s * xg
                d0 = c * (mu0 * 1.0 - mu_d * 1.0)
                d1 = c * (mu1 * 1.0 - mu_d * 1.0)
                while True:
                    one = mu1 < mu0
                    tc = (mu1 if one else mu0) * 1.0 + v
                    if one and mu0 * 1.0 + v == tc:
                        one = False  # tie of the rounded theta_c: the lowest index, as in the heaps
                    if tc < vt:
                        tc = vt  # rounding: the slider is already at its threshold
                    if vb < tc:
                        break  # no slider reaches its threshold before theta_b
                    vt = tc
                    if p >= nbuf:
                        status = NEED_MU
                        break
                    # F = theta_c - u, exactly s (tc - v).
                    status = tilt(st, draws, out, k, s * (tc - v), mu0, mu1, mu_d, c)
                    if status != DONE:
                        break
                    d = d1 if one else d0
                    v = v + d
                    xr += (d if one else -d) * 0.5
                    new = mu_draws[nonneg(p)]
                    p += 1
                    nrec += new > mumax
                    d_new = c * (new * 1.0 - mu_d * 1.0)
                    mu1 = new if one else mu1
                    mu0 = mu0 if one else new
                    d1 = d_new if one else d1
                    d0 = d0 if one else d_new
                    mumax = max(mu0, mu1)
                    n += 1
                    nev += 1
                    av = 0
                    aF = abs(vt - v)
                    if aF > mu0 * 1.0 or aF > mu1 * 1.0:
                        pending = 1
                        break
                u = s * v
                theta = s * vt
                xg = s * xr
                if status != DONE:
                    break
                if pending:
                    continue
            # The step ends.
            q += 1
            theta = theta_b
            if k < out_steps.size and out_steps[nonneg(k)] == q:
                st.n_slips = n
                st.mu_max = mumax
                st.x_G = xg
                st.n_records = nrec
                st.next_out = k
                write_output(st, mu, out)
                k += 1
            continue
        # Slider i slips alone (eq. `displacement`); its threshold is redrawn.
        sgn = 1.0 if Fi > 0.0 else -1.0
        du = c * (aFi - mu_d * 1.0) * sgn / 1.0
        if i == 1:
            u = u + du
        else:
            u = u - du
        xg += du * 0.5
        new = mu_draws[nonneg(p)]
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
    st.u = u
    st.theta = theta
    st.x_G = xg
    st.mu_max = mumax
    mu[0] = mu0
    mu[1] = mu1
    st.n_slips = n
    st.mu_pos = p
    st.n_records = nrec
    st.n_events = nev
    st.av_slips = av
    st.pending = pending
    st.q = q
    st.next_out = k
    return status
