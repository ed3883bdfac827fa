"""Temperature drivers: the thermal dilation theta(t) = kappa (T(t) - T0).

A driver plugin is any object with ``thetas(rng, steps) -> ndarray``: the
``steps + 1`` values theta(t_q) at t_q = q tau_th, q = 0 ... steps. Between
two values theta is linear in time (the paper, section III.A), which is what
lets the solver resolve every rearrangement exactly.
"""

from __future__ import annotations

import math

import numpy as np

from slidernet.errors import param_error


class GaussianSteps:
    """The paper's driver: theta(t_q) drawn independently from N(0, sigma_theta^2).

    Parameters
    ----------
    sigma_theta : float
        Standard deviation of theta (dimensionless dilation); > 0.

    Examples
    --------
    >>> import numpy as np
    >>> GaussianSteps(sigma_theta=1e-6).thetas(np.random.default_rng(0), 4).shape
    (5,)
    >>> GaussianSteps(sigma_theta=-1e-6)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'sigma_theta' parameter of gaussian_steps must be > 0. Got -1e-06 instead.
    """

    def __init__(self, sigma_theta: float) -> None:
        sigma_theta = float(sigma_theta)
        if not (math.isfinite(sigma_theta) and sigma_theta > 0):
            # NaN fails "> 0" too, but "finite" is then the useful word.
            requirement = "> 0" if math.isfinite(sigma_theta) else "finite and > 0"
            raise param_error("sigma_theta", "gaussian_steps", requirement, sigma_theta)
        self.sigma_theta = sigma_theta

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``."""
        return self.sigma_theta * rng.standard_normal(steps + 1)

    def __repr__(self) -> str:
        return f"GaussianSteps(sigma_theta={self.sigma_theta!r})"


# The built-in drivers, by the name a config uses (``driver.name``).
BUILTINS: dict[str, type] = {"gaussian_steps": GaussianSteps}
