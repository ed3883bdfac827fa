"""The appendix's virtual tilt test for two sliders (docs/model.md section 1)."""

from __future__ import annotations

from slidernet.kernels.state import DONE, NEED_TILT, TILT_LIMIT, TILT_MAX_ITER, TMU_POS, TU_POS, kernel_jit


@kernel_jit()
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


@kernel_jit()
def tilt_sample(F, mu1, mu2, mu_d, tmu, tu, ist, k, fsum, fsq, fcount):
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
