"""A two-Gaussian mixture of static friction thresholds, as a slidernet plugin.

The package declares the entry point ``bimodal`` in the group
``slidernet.distributions``; once installed, a configuration uses it as
``[friction.static] name = "bimodal"``.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from scipy import special

from slidernet.errors import ConfigError, param_error

__all__ = ["Bimodal"]
__version__ = "0.1.0"


def _finite(value: float, param: str) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise param_error(param, "bimodal", "finite", value)
    return value


def _positive(value: float, param: str) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise param_error(param, "bimodal", "finite and > 0", value)
    return value


class Bimodal:
    """Two-Gaussian mixture p(mu_s): N(mean1, std1^2) with probability weight, else N(mean2, std2^2).

    Parameters
    ----------
    mean1, std1 : float
        Mean and standard deviation (> 0) of the first population of thresholds.
    mean2, std2 : float
        The same for the second population.
    weight : float
        Probability of the first population, in (0, 1).

    Examples
    --------
    >>> import numpy as np
    >>> law = Bimodal(mean1=0.58, std1=0.01, mean2=0.62, std2=0.005, weight=0.7)
    >>> law.sample(np.random.default_rng(0), 3).shape
    (3,)
    >>> round(float(law.cdf(0.7)), 6)
    1.0
    >>> Bimodal(0.58, 0.01, 0.62, 0.005, weight=1.5)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'weight' parameter of bimodal must be in (0, 1). Got 1.5 instead.
    """

    #: Parameters for slidernet's plugin contract test (see slidernet.testing).
    example_params: ClassVar[dict[str, float]] = {
        "mean1": 0.58, "std1": 0.01, "mean2": 0.62, "std2": 0.005, "weight": 0.7,
    }
    example_mu_d: ClassVar[float] = 0.5
    #: Gaussian tails reach below mu_d: slidernet conditions the law on mu_s > mu_d.
    truncate_below_mu_d: ClassVar[bool] = True

    def __init__(self, mean1: float, std1: float, mean2: float, std2: float, weight: float = 0.5) -> None:
        self.mean1 = _finite(mean1, "mean1")
        self.std1 = _positive(std1, "std1")
        self.mean2 = _finite(mean2, "mean2")
        self.std2 = _positive(std2, "std2")
        weight = float(weight)
        if not (0.0 < weight < 1.0):
            raise param_error("weight", "bimodal", "in (0, 1)", weight)
        self.weight = weight

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse two populations both at or below mu_d: the truncated law would be a far tail."""
        if max(self.mean1, self.mean2) <= mu_d:
            raise ConfigError(
                f"The 'mean1' and 'mean2' parameters of bimodal must not both be <= mu_d = {mu_d!r}. "
                f"Got {self.mean1!r} and {self.mean2!r} instead."
            )

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``, from the given Generator only."""
        first = rng.random(size) < self.weight
        z = rng.standard_normal(size)
        return np.where(first, self.mean1 + self.std1 * z, self.mean2 + self.std2 * z)

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s <= x)."""
        x = np.asarray(x, dtype=float)
        return self.weight * special.ndtr((x - self.mean1) / self.std1) \
            + (1.0 - self.weight) * special.ndtr((x - self.mean2) / self.std2)

    def sf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s > x), accurate far in the upper tail."""
        x = np.asarray(x, dtype=float)
        return self.weight * special.ndtr((self.mean1 - x) / self.std1) \
            + (1.0 - self.weight) * special.ndtr((self.mean2 - x) / self.std2)

    def __repr__(self) -> str:
        return (f"Bimodal(mean1={self.mean1!r}, std1={self.std1!r}, mean2={self.mean2!r}, "
                f"std2={self.std2!r}, weight={self.weight!r})")
