"""Checks shared by the creep theory of two sliders and of chains, on an incline with constant thresholds.

:mod:`~slidernet.analysis.theory.creep_pair` and
:mod:`~slidernet.analysis.theory.creep_chain` take the same friction pair
and the same angle, with the same limits: 0 < mu_d < mu_s and
0 < tan(alpha) < mu_d. Both work in the kernels' units: forces in N, theta
and lengths in Ntilde, k = 1, every slider carrying f = tan(alpha) downhill
(+x). The plain finite and sign checks are :mod:`slidernet._validation`'s.
"""

from __future__ import annotations

from slidernet._validation import check_scalar
from slidernet.errors import param_error


def _check_friction(mu_s: float, mu_d: float, owner: str) -> tuple[float, float]:
    """(mu_s, mu_d) as floats, refused unless mu_s > mu_d > 0."""
    md = check_scalar(mu_d, "mu_d", owner, "> 0")
    ms = check_scalar(mu_s, "mu_s", owner)
    if not ms > md:
        raise param_error("mu_s", owner, f"> mu_d = {md!r}", ms)
    return ms, md


def _check_tan(tan_alpha: float, mu_d: float, owner: str) -> float:
    """tan(alpha) as a float, refused unless it lies in (0, mu_d)."""
    f = check_scalar(tan_alpha, "tan_alpha", owner)
    if not 0.0 < f < mu_d:
        # f = 0 makes backward and forward slips tie; f >= mu_d slides away.
        raise param_error("tan_alpha", owner, f"in (0, mu_d = {mu_d!r})", f)
    return f
