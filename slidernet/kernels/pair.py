"""The paper's two sliders: a scalar kernel (no arrays in the hot loop, no queue)."""

from __future__ import annotations

from slidernet.kernels.state import (
    AV_SLIPS,
    AVALANCHE_LIMIT,
    DONE,
    ERR_NODE,
    HEAP_SIZE,
    MU_MAX,
    MU_POS,
    N_EVENTS,
    N_RECORDS,
    N_SLIPS,
    NEED_MU,
    REC,
    STARTED,
    THETA,
    XG,
    Q,
    U,
    kernel_jit,
    write_record,
)
from slidernet.kernels.tilt import tilt_sample


@kernel_jit()
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
            st = tilt_sample(fst[THETA] - fst[U], mu[0], mu[1], mu_d, tmu, tu, ist,
                              ist[REC], fsum, fsq, fcount)
            if st != DONE:
                return st
        if rec_times[ist[REC]] == 0:
            write_record(ist, fst, out_n, out_mu_max, out_xg, out_records)
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
                st = tilt_sample(F, mu0, mu1, mu_d, tmu, tu, ist, k, fsum, fsq, fcount)
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
                i = 0
                thc = th0
                if s * th1 < s * th0:
                    i = 1
                    thc = th1
                if s * (thc - theta) < 0.0:
                    thc = theta  # rounding: the slider is already at its threshold
                if s * (theta_b - thc) >= 0.0:
                    theta = thc
                    if p >= nbuf:
                        status = NEED_MU
                        break
                    if do_tilt:
                        st = tilt_sample(thc - u, mu0, mu1, mu_d, tmu, tu, ist, k,
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
