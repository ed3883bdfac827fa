"""Built-in laws of mu_s with no upper end: ``gaussian``, ``weibull``, ``lognormal``, ``exponential``, ``pareto``.

The largest of m draws grows without bound: slowly for the first four (the
Gumbel class of extremes: like sqrt(2 ln m) for ``gaussian``, ln m for
``exponential``), as a power of m for ``pareto`` (the Frechet class).
``exponential`` and ``pareto`` have the mean of the maximum in closed form;
the others integrate it (:func:`~slidernet.plugins.distributions.mean_max_quadrature`).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

from slidernet._validation import check_array, check_scalar
from slidernet.errors import param_error
from slidernet.kernels import draws
from slidernet.plugins.distributions.law import Distribution


class Gaussian(Distribution):
    """Gaussian p(mu_s) of the paper (section III), before truncation at mu_d.

    Its support reaches mu_d, so slidernet conditions it on mu_s > mu_d
    with :class:`TruncatedBelow` (rejection); for the paper's parameters
    (mean - mu_d = 10 std) no draw is ever rejected. Extremes: Gumbel class,
    mu_max grows like mean + std sqrt(2 ln m).

    Parameters
    ----------
    mean : float
        mu_s bar, the mean static friction coefficient (dimensionless).
    std : float
        sigma_mu, its standard deviation; > 0.

    Examples
    --------
    >>> import numpy as np
    >>> d = Gaussian(mean=0.6, std=0.01)
    >>> d.sample(np.random.default_rng(0), 3).shape
    (3,)
    >>> float(d.cdf(0.6))
    0.5
    >>> round(float(d.mean_max(2)), 6)  # mean + std / sqrt(pi)
    0.605642
    """

    name = "gaussian"
    example_params: ClassVar[dict[str, Any]] = {"mean": 0.6, "std": 0.01}
    _mu_d_param = "mean"

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"mean": "1", "std": "1"}

    def __init__(self, mean: float, std: float) -> None:
        self.mean = check_scalar(mean, "mean", "gaussian")
        self.std = check_scalar(std, "std", "gaussian", "> 0")

    def _params(self) -> dict[str, Any]:
        return {"mean": self.mean, "std": self.std}

    def support(self) -> tuple[float, float]:
        """(-inf, inf)."""
        return -math.inf, math.inf

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse a mean at or below mu_d: the truncated law would be degenerate."""
        if self.mean <= mu_d:
            raise param_error("mean", "gaussian", f"> mu_d = {mu_d!r}", self.mean)

    def compiled_law(self) -> tuple[int, float, float, float]:
        return draws.GAUSSIAN, self.std, self.mean, 0.0

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``."""
        x = rng.standard_normal(size)
        # In place: sampling is a visible share of the two-slider run time.
        x *= self.std
        x += self.mean
        return x

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return special.ndtr((np.asarray(x, dtype=float) - self.mean) / self.std)

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x), accurate far in the upper tail."""
        return special.ndtr(-(np.asarray(x, dtype=float) - self.mean) / self.std)

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return self.mean + self.std * special.ndtri(np.asarray(u, dtype=float))

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q, accurate for tiny q."""
        return self.mean - self.std * special.ndtri(np.asarray(q, dtype=float))


class Weibull(Distribution):
    """Weibull p(mu_s): mu_s = loc + scale * W, P(W > w) = exp(-w^shape).

    Support (loc, inf). If ``loc < mu_d`` slidernet conditions it on
    mu_s > mu_d with :class:`TruncatedBelow` (rejection); if ``loc >= mu_d``
    no truncation is needed. Its upper tail is lighter than any power, so
    the maximum is in the Gumbel class of extremes (despite the name):
    mu_max ~ loc + scale (ln m)^(1/shape).

    Parameters
    ----------
    shape : float
        Weibull modulus k, > 0 (dimensionless).
    scale : float
        Width of the law, > 0 (dimensionless, like mu_s).
    loc : float
        Lower end of the support; default 0.

    Examples
    --------
    >>> import numpy as np
    >>> d = Weibull(shape=2.0, scale=0.1, loc=0.5)
    >>> d.sample(np.random.default_rng(0), 4).shape
    (4,)
    >>> round(float(d.sf(0.6)), 12) == round(float(np.exp(-1.0)), 12)
    True
    """

    name = "weibull"
    example_params: ClassVar[dict[str, Any]] = {"shape": 2.0, "scale": 0.15, "loc": 0.4}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"shape": "1", "scale": "1", "loc": "1"}

    def __init__(self, shape: float, scale: float, loc: float = 0.0) -> None:
        self.shape = check_scalar(shape, "shape", "weibull", "> 0")
        self.scale = check_scalar(scale, "scale", "weibull", "> 0")
        self.loc = check_scalar(loc, "loc", "weibull")

    def _params(self) -> dict[str, Any]:
        return {"shape": self.shape, "scale": self.scale, "loc": self.loc}

    def support(self) -> tuple[float, float]:
        """(loc, inf)."""
        return self.loc, math.inf

    def _z(self, x: ArrayLike) -> np.ndarray:
        return (np.maximum(np.asarray(x, dtype=float) - self.loc, 0.0) / self.scale) ** self.shape

    def compiled_law(self) -> tuple[int, float, float, float]:
        return draws.WEIBULL, self.loc, self.scale, self.shape

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``."""
        return self.loc + self.scale * rng.weibull(self.shape, size)

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return -np.expm1(-self._z(x))

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x), accurate in the upper tail."""
        return np.exp(-self._z(x))

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return self.loc + self.scale * (-np.log1p(-np.asarray(u, dtype=float))) ** (1.0 / self.shape)

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q, accurate for tiny q."""
        return self.loc + self.scale * (-np.log(np.asarray(q, dtype=float))) ** (1.0 / self.shape)


class Lognormal(Distribution):
    """Log-normal p(mu_s): mu_s = loc + median * exp(sigma * Z), Z ~ Normal(0, 1).

    Support (loc, inf); ln(mu_s - loc) has mean ln(median) and standard
    deviation ``sigma``. If ``loc < mu_d`` slidernet conditions it on
    mu_s > mu_d with :class:`TruncatedBelow` (rejection); if ``loc >= mu_d``
    no truncation is needed. Extremes: Gumbel class (slowly, for large sigma).

    Parameters
    ----------
    median : float
        Median of mu_s - loc, > 0 (dimensionless).
    sigma : float
        Standard deviation of ln(mu_s - loc), > 0.
    loc : float
        Lower end of the support; default 0.

    Examples
    --------
    >>> import numpy as np
    >>> d = Lognormal(median=0.1, sigma=0.5, loc=0.5)
    >>> round(float(d.cdf(0.6)), 12)  # the median of mu_s is loc + median
    0.5
    >>> bool((d.sample(np.random.default_rng(0), 100) > 0.5).all())
    True
    """

    name = "lognormal"
    example_params: ClassVar[dict[str, Any]] = {"median": 0.1, "sigma": 0.5, "loc": 0.45}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"median": "1", "sigma": "1", "loc": "1"}

    def __init__(self, median: float, sigma: float, loc: float = 0.0) -> None:
        self.median = check_scalar(median, "median", "lognormal", "> 0")
        self.sigma = check_scalar(sigma, "sigma", "lognormal", "> 0")
        self.loc = check_scalar(loc, "loc", "lognormal")

    def _params(self) -> dict[str, Any]:
        return {"median": self.median, "sigma": self.sigma, "loc": self.loc}

    def support(self) -> tuple[float, float]:
        """(loc, inf)."""
        return self.loc, math.inf

    def _z(self, x: ArrayLike) -> np.ndarray:
        y = np.asarray(x, dtype=float) - self.loc
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(y > 0, np.log(np.where(y > 0, y, 1.0) / self.median) / self.sigma, -np.inf)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``."""
        return self.loc + self.median * np.exp(self.sigma * rng.standard_normal(size))

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return special.ndtr(self._z(x))

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x), accurate in the upper tail."""
        return special.ndtr(-self._z(x))

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return self.loc + self.median * np.exp(self.sigma * special.ndtri(np.asarray(u, dtype=float)))

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q, accurate for tiny q."""
        return self.loc + self.median * np.exp(-self.sigma * special.ndtri(np.asarray(q, dtype=float)))


class Exponential(Distribution):
    """Shifted exponential p(mu_s): mu_s = loc + scale * E, P(E > e) = exp(-e).

    Support (loc, inf). If ``loc < mu_d`` slidernet conditions it on
    mu_s > mu_d with :class:`TruncatedBelow` (rejection), which by the lack
    of memory gives the same law with loc = mu_d; if ``loc >= mu_d`` no
    truncation is needed. Extremes: Gumbel class, with the exact mean
    E[max of m] = a + scale H_m, a = max(loc, mu_d), H_m the harmonic number.

    Parameters
    ----------
    scale : float
        Mean of mu_s - loc, > 0 (dimensionless).
    loc : float
        Lower end of the support; default 0.

    Examples
    --------
    >>> import numpy as np
    >>> d = Exponential(scale=0.05, loc=0.55)
    >>> d.sample(np.random.default_rng(0), 2).shape
    (2,)
    >>> round(float(d.mean_max(2)), 12)  # 0.55 + 0.05 * (1 + 1/2)
    0.625
    """

    name = "exponential"
    example_params: ClassVar[dict[str, Any]] = {"scale": 0.05, "loc": 0.45}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"scale": "1", "loc": "1"}

    def __init__(self, scale: float, loc: float = 0.0) -> None:
        self.scale = check_scalar(scale, "scale", "exponential", "> 0")
        self.loc = check_scalar(loc, "loc", "exponential")

    def _params(self) -> dict[str, Any]:
        return {"scale": self.scale, "loc": self.loc}

    def support(self) -> tuple[float, float]:
        """(loc, inf)."""
        return self.loc, math.inf

    def _z(self, x: ArrayLike) -> np.ndarray:
        return np.maximum(np.asarray(x, dtype=float) - self.loc, 0.0) / self.scale

    def compiled_law(self) -> tuple[int, float, float, float]:
        return draws.EXPONENTIAL, self.loc, self.scale, 0.0

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``."""
        return self.loc + self.scale * rng.standard_exponential(size)

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return -np.expm1(-self._z(x))

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x), accurate in the upper tail."""
        return np.exp(-self._z(x))

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return self.loc - self.scale * np.log1p(-np.asarray(u, dtype=float))

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q, accurate for tiny q."""
        return self.loc - self.scale * np.log(np.asarray(q, dtype=float))

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Closed form: a + scale H_m, a = max(loc, lower); see :meth:`Distribution.mean_max_above`."""
        m_arr = check_array(m, "m", "mean_max", ">= 1")
        a = max(self.loc, float(lower))
        # H_m = psi(m + 1) + gamma, also for non-integer m.
        return a + self.scale * (special.digamma(m_arr + 1.0) + np.euler_gamma)


class Pareto(Distribution):
    """Pareto (power-law) p(mu_s): P(mu_s > x) = ((x - loc) / scale)^-alpha for x >= loc + scale.

    Support [loc + scale, inf). If ``loc + scale < mu_d`` slidernet
    conditions it on mu_s > mu_d with :class:`TruncatedBelow` (rejection),
    which gives the same law with scale = mu_d - loc; otherwise no
    truncation is needed. Extremes: Frechet class, mu_max grows like
    loc + scale m^(1/alpha): E[max of m] = loc + s Gamma(1 - 1/alpha)
    Gamma(m + 1) / Gamma(m + 1 - 1/alpha), finite only for alpha > 1.

    Parameters
    ----------
    alpha : float
        Tail exponent, > 0 (the mean is finite only for alpha > 1).
    scale : float
        Distance from ``loc`` to the lower end of the support, > 0.
    loc : float
        Shift; default 0.

    Examples
    --------
    >>> import numpy as np
    >>> d = Pareto(alpha=3.0, scale=0.05, loc=0.5)
    >>> round(float(d.sf(0.6)), 12)  # (0.1 / 0.05)^-3
    0.125
    >>> round(float(d.mean_max(1)), 12)  # loc + scale alpha / (alpha - 1)
    0.575
    """

    name = "pareto"
    example_params: ClassVar[dict[str, Any]] = {"alpha": 3.0, "scale": 0.05, "loc": 0.5}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"alpha": "1", "scale": "1", "loc": "1"}

    def __init__(self, alpha: float, scale: float, loc: float = 0.0) -> None:
        self.alpha = check_scalar(alpha, "alpha", "pareto", "> 0")
        self.scale = check_scalar(scale, "scale", "pareto", "> 0")
        self.loc = check_scalar(loc, "loc", "pareto")

    def _params(self) -> dict[str, Any]:
        return {"alpha": self.alpha, "scale": self.scale, "loc": self.loc}

    def support(self) -> tuple[float, float]:
        """(loc + scale, inf)."""
        return self.loc + self.scale, math.inf

    def _log_z(self, x: ArrayLike) -> np.ndarray:
        y = np.asarray(x, dtype=float) - self.loc
        return np.log(np.maximum(y, self.scale) / self.scale)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``: loc + scale exp(E / alpha), E ~ Exp(1)."""
        return self.loc + self.scale * np.exp(rng.standard_exponential(size) / self.alpha)

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return -np.expm1(-self.alpha * self._log_z(x))

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x), accurate in the upper tail."""
        return np.exp(-self.alpha * self._log_z(x))

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return self.loc + self.scale * np.exp(-np.log1p(-np.asarray(u, dtype=float)) / self.alpha)

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q, accurate for tiny q."""
        return self.loc + self.scale * np.asarray(q, dtype=float) ** (-1.0 / self.alpha)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Closed form (inf for alpha <= 1); see the class docstring and :meth:`Distribution.mean_max_above`."""
        m_arr = check_array(m, "m", "mean_max", ">= 1")
        s = max(self.scale, float(lower) - self.loc)
        if self.alpha <= 1.0:
            return np.full(m_arr.shape, math.inf)
        a = 1.0 / self.alpha
        # Gamma(m + 1) / Gamma(m + 1 - a) as a Pochhammer symbol: exact to a few
        # ulp, where a difference of gammaln would lose ~log10(m ln m) digits.
        ratio = special.poch(m_arr + 1.0 - a, a)
        return self.loc + s * special.gamma(1.0 - a) * ratio
