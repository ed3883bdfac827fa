"""The appendix's virtual tilt test for two sliders (docs/model.md section 1)."""

from __future__ import annotations

from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.state import DONE, NEED_TILT, TILT_LIMIT, TILT_MAX_ITER, TILT_NEED_DRAWS, TILT_TOO_LONG


@kernel_jit(forceinline=True)
def flat_onset(F, mu1, mu2):
    """The slider that starts first on the appendix's substrate, and at which load: (i, f, c).

    Forces are per unit normal load and the spring force F does not change
    with the tilt, so slider 1 starts at f1 = mu1 + F and slider 2 at
    f2 = mu2 - F (ties: slider 1). c = 1: the normal load does not change.
    """
    f1 = mu1 + F
    f2 = mu2 - F
    if f1 <= f2:
        return 1, f1, 1.0
    return 2, f2, 1.0


@kernel_jit(inline="always")
def tilt_iterations(st, draws, F, mu1, mu2, mu_d, sf, onset):
    """The appendix's iteration of the tilt test, for a rule of onset ``onset(F, mu1, mu2) -> (i, f, c)``.

    ``onset`` gives the slider i that starts first, the tangential load f at
    that moment and c, the normal load there over its value on the flat.
    The appendix's rules then act on the forces per unit normal load, the
    spring's being F / c; F is carried in units of the normal load on the
    flat. With :func:`flat_onset` (c = 1) this is the appendix as written.
    A slider that rearranges alone moves the spring force by ``sf`` (mu_i -
    mu_d), sf = 1 + e the slip factor (2: the appendix), and eq. `stab`'s
    bound follows: the other slider is dragged along if, at the end of the
    slip, the force on it reaches its threshold.
    Returns f at which the pair slides, ``TILT_NEED_DRAWS`` if the draw
    buffers ran out (read positions left untouched), ``TILT_TOO_LONG`` after
    ``TILT_MAX_ITER`` iterations.
    """
    tilt_mu = draws.tilt_mu
    tilt_u = draws.tilt_u
    p_mu = st.tilt_mu_pos
    p_u = st.tilt_u_pos
    for _ in range(TILT_MAX_ITER):
        i, f, c = onset(F, mu1, mu2)
        FN = F / c  # exact for c = 1
        # Eq. `stab` for a slip of sf (mu_i - mu_d): (mu1 + mu2 - sf (mu_i - mu_d)) / 2, written so that sf = 2
        # adds an exact 0.0 to the appendix's own expression (the same bits).
        if i == 1:
            bound = mu_d - 0.5 * (mu1 - mu2) + (1.0 - 0.5 * sf) * (mu1 - mu_d)
        else:
            bound = mu_d + 0.5 * (mu1 - mu2) + (1.0 - 0.5 * sf) * (mu2 - mu_d)
        if f >= bound:  # eq. `stab`: the other slider moves too
            if f > mu_d:
                st.tilt_mu_pos = p_mu
                st.tilt_u_pos = p_u
                return f
            # Creep: the damped motion stops; the appendix redraws both
            # thresholds and a force uniform in [f - mu1, mu2 - f].
            if p_mu + 2 > tilt_mu.size or p_u + 1 > tilt_u.size:
                return TILT_NEED_DRAWS
            mu1 = tilt_mu[p_mu]
            mu2 = tilt_mu[p_mu + 1]
            p_mu += 2
            lo = f - mu1
            FN = lo + ((mu2 - f) - lo) * tilt_u[p_u]
            p_u += 1
        else:
            if p_mu + 1 > tilt_mu.size:
                return TILT_NEED_DRAWS
            if i == 1:
                FN += sf * (mu1 - mu_d)
                mu1 = tilt_mu[p_mu]
            else:
                FN -= sf * (mu2 - mu_d)
                mu2 = tilt_mu[p_mu]
            p_mu += 1
        F = FN * c  # exact for c = 1
    return TILT_TOO_LONG


@kernel_jit()
def tilt_test_pair(st, draws, F, mu1, mu2, mu_d, sf):
    """The appendix's virtual tilt test on a copy of (F, mu1, mu2).

    ``F`` is F_{1->2}, the spring force on slider 2 in units of N; ``sf`` is
    the slip factor 1 + e (2 for the appendix's slip). The
    redrawn thresholds and uniforms are read from ``draws.tilt_mu`` and
    ``draws.tilt_u`` at the state's ``tilt_mu_pos`` and ``tilt_u_pos``.
    Returns the tangential force f at which the whole system slides (mu_eff
    sample), ``TILT_NEED_DRAWS`` if the draw buffers ran out (read positions
    are then left untouched), or ``TILT_TOO_LONG`` after ``TILT_MAX_ITER`` iterations.
    """
    return tilt_iterations(st, draws, F, mu1, mu2, mu_d, sf, flat_onset)


@kernel_jit()
def tilt_status(f):
    """The status code of a tilt test's result ``f`` (the pair's or the network's), the one rule for both.

    ``DONE`` for a sample, ``NEED_TILT`` for ``TILT_NEED_DRAWS`` (the buffers
    ran out: refill and test again), ``TILT_LIMIT`` for ``TILT_TOO_LONG``.

    >>> tilt_status(0.57) == DONE, tilt_status(TILT_NEED_DRAWS) == NEED_TILT
    (True, True)
    >>> tilt_status(TILT_TOO_LONG) == TILT_LIMIT
    True
    """
    if f == TILT_NEED_DRAWS:
        return NEED_TILT
    if f == TILT_TOO_LONG:
        return TILT_LIMIT
    return DONE


@kernel_jit(forceinline=True)
def record_tilt(f, out, k):
    """Add a tilt test's result f to output bin ``k`` (``out.f_sum``, ``f_sq``, ``f_count``); returns
    its :func:`tilt_status` (nothing is recorded unless it is ``DONE``)."""
    status = tilt_status(f)
    if status == DONE:
        out.f_sum[k] += f
        out.f_sq[k] += f * f
        out.f_count[k] += 1
    return status


@kernel_jit()
def tilt_sample(st, draws, out, k, F, mu1, mu2, mu_d, sf):
    """Run one tilt test and add its sample to output bin ``k``; returns a status."""
    return record_tilt(tilt_test_pair(st, draws, F, mu1, mu2, mu_d, sf), out, k)
