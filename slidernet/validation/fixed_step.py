"""The naive fixed-step theta sweep of the two-slider case, for the speed-error comparison.

This is how a script without the event-driven solver does it: walk theta
through each thermal step in sub-steps of at most ``dtheta``, and after each
sub-step slip the most overloaded slider until both are stable. A slider is
found unstable only at the first grid point past its threshold, so its force
there exceeds mu_s by up to ``dtheta`` (units of N) and it slips by
2(|F| - mu_d) Ntilde instead of 2(mu_s - mu_d) Ntilde (eq. `displacement` with
the overshoot included, as a naive script computes it from the current force).
As ``dtheta`` -> 0 it converges to the exact event-driven solution
(:func:`slidernet.kernels.pair.run_pair`); the cost grows like 1/dtheta.

Compiled like the solver's kernels, so that the comparison measures the
algorithm, not the language.
"""

from __future__ import annotations

import math

from slidernet.kernels.jit import kernel_jit

OUT_OF_DRAWS = -1
AVALANCHE_LIMIT = -2


@kernel_jit()
def sweep_pair(thetas, dtheta, out_steps, mu, draws, mu_d, max_slips, out_n, out_mu_max, out_xg):
    """Run one realization of the two sliders with a fixed-step theta sweep.

    Parameters
    ----------
    thetas : ndarray, shape (steps + 1,)
        theta(t_q) / Ntilde.
    dtheta : float
        Largest sub-step of theta / Ntilde; each thermal step is cut into
        ceil(|Delta theta| / dtheta) equal sub-steps ending exactly at theta(t_q+1).
    out_steps : ndarray of int64, shape (T,)
        Recorded steps, increasing.
    mu : ndarray, shape (2,)
        Initial thresholds (mu_s,1, mu_s,2); overwritten with the final ones.
    draws : ndarray, shape (D,)
        Replacement thresholds, used in order (the same stream as the solver's).
    mu_d : float
        Dynamic friction coefficient.
    max_slips : int
        Largest number of slips of one relaxation before giving up.
    out_n, out_mu_max, out_xg : ndarray, shape (T,)
        Records of n, mu_max and x_G / (Ntilde l0).

    Returns
    -------
    int
        Draws used, or ``OUT_OF_DRAWS`` / ``AVALANCHE_LIMIT``.
    """
    u = thetas[0]  # the spring at rest at theta(0)
    xg = 0.0
    n = 0
    p = 0
    k = 0
    mu0 = mu[0]
    mu1 = mu[1]
    if out_steps.size > 0 and out_steps[0] == 0:
        out_n[0] = 0
        out_mu_max[0] = max(mu0, mu1)
        out_xg[0] = 0.0
        k = 1
    for q in range(thetas.size - 1):
        a = thetas[q]
        b = thetas[q + 1]
        m = math.ceil(abs(b - a) / dtheta)
        for j in range(1, m + 1):
            theta = b if j == m else a + (b - a) * (j / m)
            slips = 0
            while True:
                F = theta - u  # force on slider 2; slider 1 feels -F
                aF = abs(F)
                un0 = aF > mu0
                un1 = aF > mu1
                if not (un0 or un1):
                    break
                # largest overload first, ties to the lowest index (as the solver)
                i = 1 if un1 and (not un0 or aF / mu1 > aF / mu0) else 0
                Fi = F if i == 1 else -F
                du = 2.0 * (aF - mu_d) * (1.0 if Fi > 0.0 else -1.0)
                if i == 1:
                    u = u + du
                else:
                    u = u - du
                xg += du * 0.5
                if p >= draws.size:
                    return OUT_OF_DRAWS
                if i == 1:
                    mu1 = draws[p]
                else:
                    mu0 = draws[p]
                p += 1
                n += 1
                slips += 1
                if slips > max_slips:
                    return AVALANCHE_LIMIT
        if k < out_steps.size and out_steps[k] == q + 1:
            out_n[k] = n
            out_mu_max[k] = max(mu0, mu1)
            out_xg[k] = xg
            k += 1
    mu[0] = mu0
    mu[1] = mu1
    return p
