"""Built-in laws of mu_s with a bounded support: ``uniform`` and ``constant``.

The largest of m draws approaches the upper end of the support (the Weibull
class of extremes for ``uniform``; ``constant``, clean friction, is a point
mass). Both have the mean of the maximum in closed form.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from slidernet._validation import check_array, check_scalar
from slidernet.errors import param_error
from slidernet.kernels import draws
from slidernet.plugins.distributions.law import Distribution


class Uniform(Distribution):
    """Uniform p(mu_s) on [low, high): bounded, Weibull class of extremes.

    If ``low < mu_d`` slidernet conditions it on mu_s > mu_d with
    :class:`TruncatedBelow` (rejection), which gives Uniform(mu_d, high); if
    ``low >= mu_d`` no truncation is needed. mu_max approaches ``high`` as
    ``high - (high - a) / (m + 1)``, a = max(low, mu_d).

    Parameters
    ----------
    low, high : float
        Ends of the support (dimensionless), finite, ``low < high``.

    Examples
    --------
    >>> import numpy as np
    >>> d = Uniform(low=0.55, high=0.65)
    >>> bool((d.sample(np.random.default_rng(0), 100) >= 0.55).all())
    True
    >>> round(float(d.cdf(0.6)), 12), round(float(d.mean_max(4)), 12)
    (0.5, 0.63)
    """

    name = "uniform"
    example_params: ClassVar[dict[str, Any]] = {"low": 0.45, "high": 0.65}
    _mu_d_param = "high"

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"low": "1", "high": "1"}

    def __init__(self, low: float, high: float) -> None:
        self.low = check_scalar(low, "low", "uniform")
        self.high = check_scalar(high, "high", "uniform")
        if not self.high > self.low:
            raise param_error("high", "uniform", f"> low = {self.low!r}", self.high)
        self.width = self.high - self.low

    def _params(self) -> dict[str, Any]:
        return {"low": self.low, "high": self.high}

    def support(self) -> tuple[float, float]:
        """(low, high)."""
        return self.low, self.high

    def compiled_law(self) -> tuple[int, float, float, float]:
        return draws.UNIFORM, self.low, self.high, 0.0

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``."""
        return rng.uniform(self.low, self.high, size)

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return np.clip((np.asarray(x, dtype=float) - self.low) / self.width, 0.0, 1.0)

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x)."""
        return np.clip((self.high - np.asarray(x, dtype=float)) / self.width, 0.0, 1.0)

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return self.low + np.asarray(u, dtype=float) * self.width

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q."""
        return self.high - np.asarray(q, dtype=float) * self.width

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Closed form a + (high - a) m / (m + 1), a = max(low, lower); see :meth:`Distribution.mean_max_above`."""
        m_arr = check_array(m, "m", "mean_max", ">= 1")
        a = max(self.low, float(lower))
        if a >= self.high:
            raise param_error("high", self.name, f"> lower = {lower!r}", self.high)
        return a + (self.high - a) * m_arr / (m_arr + 1.0)


class Constant(Distribution):
    """Every mu_s equals ``value``: clean friction (Blanc, Pugnaloni & Géminard 2011).

    A point mass. No random number is drawn, so a run's other streams are as
    they would be with any other law. ``value`` must exceed mu_d (the
    slip 2 (mu_s - mu_d) N / k must move the slider forward).

    Parameters
    ----------
    value : float
        The static coefficient of every slider (dimensionless), finite.

    Examples
    --------
    >>> import numpy as np
    >>> d = Constant(value=0.6)
    >>> d.sample(np.random.default_rng(0), 3), float(d.mean_max(10))
    (array([0.6, 0.6, 0.6]), 0.6)
    >>> d.check_mu_d(0.6)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'value' parameter of constant must be > mu_d = 0.6. Got 0.6 instead.
    """

    name = "constant"
    example_params: ClassVar[dict[str, Any]] = {"value": 0.6}
    _mu_d_param = "value"

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"value": "1"}

    def __init__(self, value: float) -> None:
        self.value = check_scalar(value, "value", "constant")

    def _params(self) -> dict[str, Any]:
        return {"value": self.value}

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse ``value <= mu_d`` (a slip would not move the slider)."""
        if not self.value > float(mu_d):
            raise param_error("value", self.name, f"> mu_d = {float(mu_d)!r}", self.value)

    def support(self) -> tuple[float, float]:
        """(value, value)."""
        return self.value, self.value

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` copies of ``value``, shape ``(size,)``; ``rng`` is not used."""
        return np.full(size, self.value)

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x): 0 below ``value``, 1 from it on."""
        return (np.asarray(x, dtype=float) >= self.value).astype(float)

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x)."""
        return (np.asarray(x, dtype=float) < self.value).astype(float)

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """``value`` for every u."""
        return np.full(np.shape(u), self.value)

    def isf(self, q: ArrayLike) -> np.ndarray:
        """``value`` for every q."""
        return np.full(np.shape(q), self.value)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """``value``, whatever m (above ``lower``)."""
        m_arr = check_array(m, "m", "mean_max", ">= 1")
        if not self.value > float(lower):
            raise param_error("value", self.name, f"> lower = {lower!r}", self.value)
        return np.full(m_arr.shape, self.value)
