"""A random telegraph temperature driver, as a slidernet plugin.

The package declares the entry point ``telegraph`` in the group
``slidernet.drivers``; once installed, a configuration uses it as
``[driver] name = "telegraph"``.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from slidernet.errors import param_error

__all__ = ["Telegraph"]
__version__ = "0.1.0"


class Telegraph:
    """Random telegraph theta: +-sigma_theta, switching at ``rate`` per tau_th (a Poisson process).

    theta(0) is +sigma_theta or -sigma_theta with probability 1/2 (the
    stationary state), and between t_q and t_(q+1) the level changes with
    the probability of an odd number of switches, (1 - exp(-2 rate)) / 2.
    So theta has mean 0, standard deviation sigma_theta and correlation
    exp(-2 rate |t - t'| / tau_th) at the sampled times.

    Parameters
    ----------
    sigma_theta : float
        The two levels are +-sigma_theta (dimensionless dilation); > 0.
    rate : float
        Mean number of switches per tau_th; > 0.

    Examples
    --------
    >>> import numpy as np
    >>> th = Telegraph(sigma_theta=1e-6, rate=0.5).thetas(np.random.default_rng(0), 6)
    >>> th.shape, sorted(set(np.abs(th).tolist()))
    ((7,), [1e-06])
    >>> Telegraph(sigma_theta=1e-6, rate=0)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'rate' parameter of telegraph must be finite and > 0. Got 0.0 instead.
    """

    #: Parameters for slidernet's plugin contract test (see slidernet.testing).
    example_params: ClassVar[dict[str, float]] = {"sigma_theta": 1e-6, "rate": 0.5}

    def __init__(self, sigma_theta: float, rate: float = 1.0) -> None:
        self.sigma_theta = self._positive(sigma_theta, "sigma_theta")
        self.rate = self._positive(rate, "rate")
        self.switch_probability = -0.5 * math.expm1(-2.0 * self.rate)

    @staticmethod
    def _positive(value: float, param: str) -> float:
        value = float(value)
        if not (math.isfinite(value) and value > 0):
            raise param_error(param, "telegraph", "finite and > 0", value)
        return value

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``, from the given Generator only."""
        first = 1.0 if rng.random() < 0.5 else -1.0
        switches = np.zeros(steps + 1, dtype=np.int64)
        np.cumsum(rng.random(steps) < self.switch_probability, out=switches[1:])
        return np.where(switches % 2 == 0, first, -first) * self.sigma_theta

    def __repr__(self) -> str:
        return f"Telegraph(sigma_theta={self.sigma_theta!r}, rate={self.rate!r})"
