"""Distributions p(mu_s) of the static friction threshold.

A distribution plugin is any object with

* ``sample(rng, size) -> ndarray`` -- ``size`` independent draws, using only
  the ``numpy.random.Generator`` it is given;
* ``cdf(x) -> ndarray`` -- the cumulative distribution function;
* optionally ``sf(x)`` (the survival function, 1 - cdf, accurate in the
  tail), ``isf(q)`` (its inverse, used by :meth:`TruncatedBelow.mean_max`)
  and ``check_mu_d(mu_d)`` (raise :class:`~slidernet.errors.ConfigError`
  when the parameters make no sense for that mu_d).

A *law of mu_s* is a :class:`Distribution`: ``sample``, ``cdf``, ``sf``,
``ppf``, ``isf``, ``support`` and ``mean_max(m)``, the exact mean of the
largest of ``m`` draws of that law. The built-ins are Distributions, and so
is the law slidernet draws from.

The model requires p(mu_s) = 0 for mu_s <= mu_d (the paper, section II.A).
slidernet enforces this for every plugin with :class:`TruncatedBelow`, the
Distribution that ``load_config(...).distribution()`` returns and the
solver, the theory and the paper figures use: draws at or below mu_d are
rejected and redrawn, and the cdf is renormalised. For a law whose support
starts above mu_d the truncation changes nothing. The solver reads its
draws through a :class:`TruncatedStream`, which calls the plugin with a
fixed number of draws (:data:`RAW_CHUNK`) and keeps the accepted ones it has
not handed out yet, so that the values never depend on ``solver.batch``.

The built-ins (:data:`BUILTINS`, by the name a config uses) and the
extreme-value class of the maximum of many draws (what mu_max ages like):

===============  =========================================  =========================
name             law                                        class of the maximum
===============  =========================================  =========================
``gaussian``     Normal(mean, std)                          Gumbel
``uniform``      Uniform(low, high)                         Weibull (bounded)
``weibull``      loc + scale * Weibull(shape)               Gumbel
``lognormal``    loc + median * exp(sigma * Normal(0, 1))   Gumbel
``exponential``  loc + Exponential(scale)                   Gumbel
``pareto``       loc + scale * Pareto(alpha), x >= 1        Frechet
``empirical``    resampling of measured values (ECDF)       bounded (largest value)
``scipy``        any continuous ``scipy.stats`` law         depends on the law
===============  =========================================  =========================

``mean_max(m)`` is the same on every Distribution: the exact mean of the
largest of ``m`` draws of *that* law -- a built-in as its parameters give
it, a :class:`TruncatedBelow` conditioned on mu_s > mu_d. The truncated law
takes it from the built-in's ``mean_max_above(m, lower)``, the same mean
conditioned on mu_s > lower, in closed form where one exists (uniform,
exponential, pareto, empirical) and otherwise by :func:`mean_max_quadrature`.
"""

from __future__ import annotations

import abc
import csv
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy import special, stats

from slidernet._validation import check_array, check_scalar, checked_output
from slidernet.errors import ConfigError, param_error
from slidernet.kernels import draws

# The least probability a law may put above mu_d (check_mu_d): rejection
# sampling then costs at most 1000 draws per accepted threshold.
MIN_MASS = 1e-3


# ---------------------------------------------------------------------------
# the generic mean of the maximum

# Tanh-sinh (double-exponential) rule on p in (0, 1): p = (1 + tanh(pi/2 sinh t)) / 2,
# t in [-4.5, 4.5] with step 1/32. It integrates the endpoint singularities of a
# quantile function (log for exponential tails, power for Pareto ones) to about
# double precision: the nodes reach p and 1 - p of 1e-61.
_TS_STEP = 1.0 / 32.0
_TS_HALF_WIDTH = 4.5


def _tanh_sinh_rule() -> tuple[np.ndarray, np.ndarray]:
    k = round(_TS_HALF_WIDTH / _TS_STEP)
    t = np.arange(-k, k + 1) * _TS_STEP
    v = 0.5 * math.pi * np.sinh(t)
    log_p = -np.log1p(np.exp(-2.0 * v))  # log p, exact near p = 1
    log_q = -np.log1p(np.exp(2.0 * v))  # log(1 - p), exact near p = 0
    # dp/dt = 2 p (1 - p) (pi/2) cosh t
    weights = _TS_STEP * math.pi * np.cosh(t) * np.exp(log_p + log_q)
    log_p.flags.writeable = False
    weights.flags.writeable = False
    return log_p, weights


_TS_LOG_P, _TS_WEIGHTS = _tanh_sinh_rule()


def mean_max_quadrature(dist: Distribution, m: ArrayLike) -> np.ndarray:
    r"""Mean of the largest of ``m`` i.i.d. draws of ``dist``, by quadrature.

    With Q the quantile function of ``dist``, the maximum of m draws has the
    quantile function :math:`Q(p^{1/m})`, so

    .. math:: E[\max] = \int_0^1 Q(p^{1/m})\,dp ,

    integrated with a tanh-sinh rule (289 nodes). ``Q(p^{1/m})`` is
    evaluated as ``isf(1 - p^{1/m})`` in the upper half of the law, with
    ``1 - p^{1/m} = -expm1(log(p) / m)`` formed without cancellation, so the
    result stays accurate for m up to 1e9 and beyond. The relative error is
    about 1e-12 for laws with a finite variance; it grows for very heavy
    tails (P(X > x) ~ x^-alpha with alpha near 1). The law must have a finite
    mean and a continuous cdf (an atom is integrated only approximately).

    Parameters
    ----------
    dist : Distribution
        The law; only its ``ppf(u)`` and ``isf(q)`` are used, vectorised.
    m : float or array_like
        Number(s) of draws, >= 1 (need not be integers: F^m is used), any shape.

    Returns
    -------
    numpy.ndarray
        E[max of m draws], in the units of mu_s (dimensionless), shape of ``m``.

    Examples
    --------
    >>> round(float(mean_max_quadrature(Uniform(0.5, 0.7), 3)), 12)  # 0.5 + 0.2 * 3 / 4
    0.65
    """
    m_arr = check_array(m, "m", "mean_max", ">= 1")
    log_u = _TS_LOG_P / m_arr[..., None]  # log p^{1/m}
    s = -np.expm1(log_u)  # 1 - p^{1/m}
    upper = s < 0.5
    x = np.where(upper, dist.isf(np.where(upper, s, 0.5)), dist.ppf(np.where(upper, 0.5, np.exp(log_u))))
    return (x * _TS_WEIGHTS).sum(axis=-1)


# ---------------------------------------------------------------------------
# the law of mu_s: base class of the built-ins and of the truncated law


class Distribution(abc.ABC):
    """A law of mu_s: the built-ins, and the law slidernet draws from.

    One interface in the style of ``scipy.stats``: ``sample``, ``cdf``,
    ``sf``, ``ppf``, ``isf``, ``support`` and :meth:`mean_max`. The built-ins
    subclass it (each a law before truncation at mu_d), and so does
    :class:`TruncatedBelow`, the law conditioned on mu_s > mu_d that
    ``load_config(...).distribution()`` returns. A third-party plugin need
    not subclass it (``sample`` and ``cdf`` are enough): slidernet wraps it in
    a TruncatedBelow, which is a Distribution.

    A subclass defines the abstract methods; this class adds
    :meth:`check_mu_d`, :meth:`mean_max` and :meth:`mean_max_above` (by
    :func:`mean_max_quadrature`). A law with a closed form for the mean of
    the maximum overrides :meth:`mean_max_above` only, and :meth:`mean_max`
    follows. ``name`` is the registered name, ``_mu_d_param`` the parameter
    blamed when the law leaves too little mass above mu_d, and
    ``example_params`` (on the built-ins) a valid parameter set for
    mu_d = 0.5, used by :func:`slidernet.testing.check_distribution` and the
    contract tests.
    """

    name = "distribution"
    _mu_d_param = "loc"
    # Every built-in is conditioned on mu_s > mu_d by TruncatedBelow (rejection):
    # a law whose support starts above mu_d loses nothing.
    truncate_below_mu_d: ClassVar[bool] = True

    def compiled_law(self) -> tuple[int, float, float, float] | None:
        """``(code, a, b, c)`` of :mod:`slidernet.kernels.draws` if compiled code draws this law to the
        bit of :meth:`sample`, else None (the default: plugins keep the batched path)."""
        return None

    @abc.abstractmethod
    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` independent draws of mu_s (dimensionless), using only ``rng``.

        Parameters
        ----------
        rng : numpy.random.Generator
            The stream to draw from.
        size : int
            Number of draws, >= 0.

        Returns
        -------
        numpy.ndarray
            float64, shape ``(size,)``.
        """

    @abc.abstractmethod
    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x), elementwise; x dimensionless, any shape; result of the shape of ``x``."""

    @abc.abstractmethod
    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x) = 1 - cdf(x), accurate in the upper tail; shape of ``x``."""

    @abc.abstractmethod
    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The quantile: the x with P(mu_s <= x) = u, u in [0, 1]; shape of ``u``."""

    @abc.abstractmethod
    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q, q in [0, 1], accurate for tiny q; shape of ``q``."""

    @abc.abstractmethod
    def support(self) -> tuple[float, float]:
        """Lower and upper end of the support (may be infinite)."""

    def _params(self) -> dict[str, Any]:
        return {}

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse a law with less than :data:`MIN_MASS` of probability above ``mu_d``.

        Raises
        ------
        ConfigError
            If the support lies at or below mu_d, or P(mu_s > mu_d) < MIN_MASS;
            the message names the parameter to change.
        """
        mu_d = float(mu_d)
        param = self._mu_d_param
        got = self._params().get(param)
        if self.support()[1] <= mu_d:
            raise param_error(param, self.name, f"such that the support reaches above mu_d = {mu_d!r} "
                              f"(it ends at {self.support()[1]!r})", got)
        mass = float(self.sf(mu_d))
        if not mass >= MIN_MASS:
            raise param_error(param, self.name, f"such that P(mu_s > mu_d = {mu_d!r}) >= {MIN_MASS!r} "
                              f"(it is {mass:.3g})", got)

    def _truncated(self, lower: float) -> Distribution:
        """This law conditioned on mu_s > lower (itself where that changes nothing)."""
        if float(lower) <= self.support()[0]:
            return self
        return TruncatedBelow(self, float(lower), self.name, min_mass=np.finfo(float).tiny)

    def mean_max(self, m: ArrayLike) -> np.ndarray:
        """Exact mean of the largest of ``m`` i.i.d. draws of this law.

        On the law slidernet draws from (``load_config(...).distribution()``,
        a :class:`TruncatedBelow`) this is mu_max of the two-slider system
        after ``n = m - 2`` rearrangements, on average.

        Parameters
        ----------
        m : float or array_like
            Number(s) of draws, >= 1 (need not be integers), any shape.

        Returns
        -------
        numpy.ndarray
            E[max], dimensionless like mu_s, shape of ``m``.

        Raises
        ------
        ConfigError
            If an ``m`` is not finite or is below 1.
        """
        # Conditioning on mu_s > -inf leaves the law as it is: one code path
        # (closed form or quadrature) per law.
        return self.mean_max_above(m, -math.inf)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Exact mean of the largest of ``m`` i.i.d. draws, conditioned on mu_s > ``lower``.

        This is what :meth:`TruncatedBelow.mean_max` asks of a built-in, with
        ``lower = mu_d``. A ``lower`` at or below the support changes nothing.
        Here by :func:`mean_max_quadrature`; some subclasses have a closed form.

        Parameters
        ----------
        m : float or array_like
            Number(s) of draws, >= 1, any shape.
        lower : float
            Truncation point (mu_d), dimensionless; ``-inf`` for none.

        Returns
        -------
        numpy.ndarray
            E[max | mu_s > lower], dimensionless like mu_s, shape of ``m``.
        """
        return mean_max_quadrature(self._truncated(lower), m)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._params().items())
        return f"{type(self).__name__}({args})"


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


class Empirical(Distribution):
    """Measured thresholds: resampling of values read from a file (their ECDF).

    ``sample`` draws the values with replacement, uniformly; ``cdf`` is the
    empirical CDF (a step function). Values at or below mu_d are never used:
    slidernet conditions the law on mu_s > mu_d with :class:`TruncatedBelow`
    (rejection), i.e. resamples only the values above mu_d; if every value
    is above mu_d no truncation is needed. mu_max saturates at the largest
    value: E[max of m] = sum_k v_(k) [(k/K)^m - ((k-1)/K)^m] over the K
    sorted values v_(k) above mu_d.

    Parameters
    ----------
    path : str or path-like
        A text file: one value per line, or a CSV table with ``column``.
        Blank lines and lines starting with ``#`` are skipped; a first line
        that is not a number is a header. A relative path is relative to
        the working directory.
    column : int or str, optional
        0-based index or header name of the CSV column to read; without it
        every line must hold a single value.
    delimiter : str
        CSV field separator; default ``","``.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = os.path.join(tmp, "mu_s.csv")
    ...     with open(path, "w") as fh:
    ...         _ = fh.write("sample,mu_s\\na,0.6\\nb,0.7\\nc,0.4\\n")
    ...     d = Empirical(path, column="mu_s")
    >>> d.values.tolist(), float(d.cdf(0.65))
    ([0.4, 0.6, 0.7], 0.6666666666666666)
    >>> round(float(TruncatedBelow(d, lower=0.5, name="empirical").mean_max(2)), 12)  # 0.6 / 4 + 0.7 * 3 / 4
    0.675
    """

    name = "empirical"
    _mu_d_param = "path"

    def __init__(self, path: str | os.PathLike, column: int | str | None = None, delimiter: str = ",") -> None:
        if not isinstance(path, (str, os.PathLike)) or not str(path):
            raise param_error("path", "empirical", "the path of a file", path)
        if column is not None and (isinstance(column, bool) or not isinstance(column, (int, str))):
            raise param_error("column", "empirical", "a column index (int) or a header name (str)", column)
        if isinstance(column, int) and column < 0:
            raise param_error("column", "empirical", ">= 0", column)
        if not isinstance(delimiter, str) or len(delimiter) != 1:
            raise param_error("delimiter", "empirical", "a single character", delimiter)
        self.path = str(path)
        self.column = column
        self.delimiter = delimiter
        values = self._read(Path(path))
        self.values = np.sort(values)
        self.values.flags.writeable = False
        self.size = self.values.size

    def _read(self, path: Path) -> np.ndarray:
        if not path.is_file():
            raise param_error("path", "empirical", "an existing file", str(path))
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise param_error("path", "empirical", f"a readable text file ({exc})", str(path)) from None
        lines = [(i, line) for i, line in enumerate(text.splitlines(), 1)
                 if line.strip() and not line.lstrip().startswith("#")]
        index = self.column if isinstance(self.column, int) else 0
        values: list[float] = []
        for k, (lineno, line) in enumerate(lines):
            row = next(csv.reader([line], delimiter=self.delimiter))
            where = f"{str(path)!r}, line {lineno}"
            if k == 0 and isinstance(self.column, str):
                names = [f.strip() for f in row]
                if self.column not in names:
                    raise param_error("column", "empirical", f"a header name of {where}: {names}", self.column)
                index = names.index(self.column)
                continue
            if self.column is None and len(row) != 1:
                raise ConfigError(f"The 'path' parameter of empirical: {where} has {len(row)} fields; "
                                  "give 'column' to read a CSV table.")
            if index >= len(row):
                raise ConfigError(f"The 'column' parameter of empirical: {where} has no column {index} "
                                  f"(only {len(row)} fields).")
            field = row[index].strip()
            try:
                value = float(field)
            except ValueError:
                if k == 0:  # a header
                    continue
                raise ConfigError(f"The 'path' parameter of empirical: {where}: {field!r} is not a number.") \
                    from None
            if not math.isfinite(value):
                raise ConfigError(f"The 'path' parameter of empirical: {where}: the values must be finite. "
                                  f"Got {field!r}.")
            values.append(value)
        if len(values) < 2:
            raise param_error("path", "empirical", f"a file with at least 2 values (it has {len(values)})",
                              str(path))
        return np.asarray(values, dtype=float)

    def _params(self) -> dict[str, Any]:
        return {"path": self.path, "column": self.column}

    def support(self) -> tuple[float, float]:
        """(smallest value, largest value)."""
        return float(self.values[0]), float(self.values[-1])

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse data with fewer than 2 values above mu_d, or with less than MIN_MASS of them."""
        above = int(self.size - np.searchsorted(self.values, float(mu_d), side="right"))
        if above < 2:
            raise ConfigError(f"The 'path' parameter of empirical must name a file with at least 2 values "
                              f"> mu_d = {mu_d!r}. Got {self.path!r} instead, with {above} of {self.size}.")
        super().check_mu_d(mu_d)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` values drawn with replacement, shape ``(size,)``."""
        return self.values[rng.integers(0, self.size, size)]

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """The ECDF: the fraction of values <= x."""
        return np.searchsorted(self.values, np.asarray(x, dtype=float), side="right") / self.size

    def sf(self, x: ArrayLike) -> np.ndarray:
        """The fraction of values > x."""
        below = np.searchsorted(self.values, np.asarray(x, dtype=float), side="right")
        return (self.size - below) / self.size

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The smallest value v with ECDF(v) >= u."""
        k = np.ceil(np.asarray(u, dtype=float) * self.size).astype(np.intp) - 1
        return self.values[np.clip(k, 0, self.size - 1)]

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The smallest value v with a fraction <= q of values above it."""
        return self.ppf(1.0 - np.asarray(q, dtype=float))

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Exact for the ECDF: sum_k v_(k) [(k/K)^m - ((k-1)/K)^m]; see :meth:`Distribution.mean_max_above`."""
        m_arr = check_array(m, "m", "mean_max", ">= 1")
        v = self.values[self.values > float(lower)]
        if v.size == 0:
            raise param_error("path", self.name, f"a file with values > lower = {lower!r}", self.path)
        k = np.arange(v.size + 1) / v.size
        with np.errstate(divide="ignore"):
            log_k = np.log(k)
        out = np.empty(m_arr.size)
        for i, mi in enumerate(m_arr.ravel()):
            out[i] = np.dot(v, np.diff(np.exp(mi * log_k)))
        return out.reshape(m_arr.shape)


class ScipyStats(Distribution):
    """Any continuous law of :mod:`scipy.stats`, by name and parameters.

    The name is looked up as an attribute of ``scipy.stats`` and must be an
    ``rv_continuous`` instance (``"gamma"``, ``"lognorm"``, ``"genpareto"``,
    ...); nothing else is imported. If the law's support reaches mu_d or
    below, slidernet conditions it on mu_s > mu_d with :class:`TruncatedBelow`
    (rejection); if it starts above mu_d no truncation is needed. The
    extreme-value class is the law's own.

    Parameters
    ----------
    dist : str
        Name of the law in ``scipy.stats``.
    params : mapping of str to float, optional
        Its shape parameters and ``loc``, ``scale`` as scipy names them,
        e.g. ``{"a": 2, "loc": 0.5, "scale": 0.05}`` for ``gamma``.

    Examples
    --------
    >>> import numpy as np
    >>> d = ScipyStats("gamma", {"a": 2, "loc": 0.5, "scale": 0.05})
    >>> d.sample(np.random.default_rng(0), 3).shape
    (3,)
    >>> d.support()
    (0.5, inf)
    >>> ScipyStats("poisson", {"mu": 1})
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'dist' parameter of scipy must be the name of a continuous \
distribution of scipy.stats (e.g. 'gamma'). Got 'poisson' instead.
    """

    name = "scipy"
    example_params: ClassVar[dict[str, Any]] = {"dist": "gamma", "params": {"a": 2.0, "loc": 0.45, "scale": 0.05}}
    _mu_d_param = "params"

    def __init__(self, dist: str, params: Mapping[str, float] | None = None) -> None:
        law = getattr(stats, dist, None) if isinstance(dist, str) and not dist.startswith("_") else None
        if not isinstance(law, stats.rv_continuous):
            raise param_error("dist", "scipy", "the name of a continuous distribution of scipy.stats "
                              "(e.g. 'gamma')", dist)
        params = {} if params is None else params
        if not isinstance(params, Mapping) or not all(isinstance(k, str) for k in params):
            raise param_error("params", "scipy", "a table of named parameters", params)
        for key, value in params.items():
            # Checked only: scipy is given the values as written, as before.
            check_scalar(value, f"params.{key}", "scipy")
        wanted = f"the parameters of scipy.stats.{dist} ({law.shapes + ', ' if law.shapes else ''}loc, scale)"
        try:
            frozen = law(**params)
            lo, hi = (float(v) for v in frozen.support())
        except TypeError as exc:
            raise param_error("params", "scipy", f"{wanted}: {exc}", dict(params)) from None
        if not (lo < hi):  # scipy reports invalid shape, loc or scale as a NaN support
            raise param_error("params", "scipy", f"valid values of {wanted}", dict(params))
        self.dist = dist
        self.params = dict(params)
        self.frozen = frozen
        self._support = (lo, hi)

    def _params(self) -> dict[str, Any]:
        return {"dist": self.dist, "params": self.params}

    def support(self) -> tuple[float, float]:
        """The law's support, from scipy."""
        return self._support

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``, with ``rng`` as scipy's random_state."""
        return np.asarray(self.frozen.rvs(size=size, random_state=rng), dtype=float)

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return np.asarray(self.frozen.cdf(x), dtype=float)

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x), as accurate in the tail as scipy's."""
        return np.asarray(self.frozen.sf(x), dtype=float)

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return np.asarray(self.frozen.ppf(u), dtype=float)

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q."""
        return np.asarray(self.frozen.isf(q), dtype=float)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """By quadrature; inf where scipy says the law's mean is infinite, NaN where undefined."""
        mean = float(self.frozen.mean())
        if not math.isfinite(mean):
            return np.full(check_array(m, "m", "mean_max", ">= 1").shape, mean if mean == math.inf else math.nan)
        return super().mean_max_above(m, lower)


# ---------------------------------------------------------------------------
# truncation below mu_d


class TruncatedBelow(Distribution):
    """A law of mu_s conditioned on mu_s > ``lower`` (normally mu_d), or checked to be.

    This is the law slidernet draws from: ``load_config(...).distribution()``
    returns one, the solver draws its thresholds from it (through a
    :class:`TruncatedStream`), and :mod:`slidernet.analysis.theory` and the
    paper figures compare against it. It is a :class:`Distribution` like the
    built-ins, whatever the plugin it wraps: ``sample``, ``cdf``, ``sf``,
    ``ppf``, ``isf``, ``support`` and ``mean_max(m)`` all describe the
    conditioned law.

    The model needs p(mu_s) = 0 for mu_s <= mu_d. A plugin that declares
    ``truncate_below_mu_d = True`` (every built-in does) is conditioned on
    mu_s > lower: sampling is by rejection in batches, so a plugin written in
    plain numpy stays fast, and one whose mass above ``lower`` is below
    ``min_mass`` is refused, since rejection would then never end. Any other
    plugin must put no mass at or below ``lower``: its ``sf(lower)`` must be
    1 (checked here, before any work), and a draw at or below ``lower`` stops
    the run with a :class:`~slidernet.errors.PluginError` naming the plugin.

    Parameters
    ----------
    dist : Distribution or object
        The plugin distribution: a :class:`Distribution`, or any object with
        ``sample`` and ``cdf`` (``sf``, ``isf`` and ``support`` optional).
    lower : float
        The truncation point (mu_d); draws must be strictly above it.
    name : str
        The plugin's registered name, used in error messages.
    min_mass : float
        Smallest acceptable P(mu_s > lower).

    Examples
    --------
    >>> import numpy as np
    >>> d = TruncatedBelow(Gaussian(0.6, 0.1), lower=0.5, name="gaussian")
    >>> bool((d.sample(np.random.default_rng(1), 1000) > 0.5).all())
    True
    >>> round(float(d.cdf(0.5)), 12)
    0.0
    >>> u = TruncatedBelow(Uniform(0.4, 0.6), lower=0.5, name="uniform")
    >>> isinstance(u, Distribution), u.support()
    (True, (0.5, 0.6))
    >>> round(float(u.mean_max(3)), 12)  # the max of 3 draws of Uniform(0.5, 0.6)
    0.575
    """

    def __init__(self, dist: object, lower: float, name: str, min_mass: float = 1e-6) -> None:
        self.dist = dist
        self.lower = float(lower)
        self.name = name
        mass = float(self._raw_sf(self.lower))
        self.truncate = bool(getattr(dist, "truncate_below_mu_d", False))
        if not self.truncate and not mass >= 1.0 - 1e-12:
            raise ConfigError(
                f"The distribution {name!r} puts probability {1.0 - mass!r} at or below mu_d = {lower!r}, "
                "but p(mu_s) must vanish for mu_s <= mu_d. Move its support above mu_d, or declare "
                "'truncate_below_mu_d = True' on its factory to have slidernet condition it on mu_s > mu_d."
            )
        if not (mass >= min_mass):
            raise ConfigError(
                f"The distribution {name!r} puts probability {mass!r} above mu_d = {lower!r}; "
                f"at least {min_mass!r} is needed (p(mu_s) must vanish for mu_s <= mu_d)."
            )
        self.mass = mass
        self.acceptance = mass

    def _raw_sf(self, x: np.ndarray | float) -> np.ndarray:
        sf = getattr(self.dist, "sf", None)
        if sf is not None:
            return np.asarray(sf(x), dtype=float)
        return 1.0 - np.asarray(self.dist.cdf(x), dtype=float)

    def support(self) -> tuple[float, float]:
        """(max(lower, plugin's lower end), plugin's upper end); inf for an end the plugin does not give."""
        plugin = getattr(self.dist, "support", None)
        lo, hi = plugin() if plugin is not None else (-math.inf, math.inf)
        return max(self.lower, float(lo)), float(hi)

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse a law with less than :data:`MIN_MASS` of probability above ``mu_d``.

        The plugin's own ``check_mu_d`` is asked first, since its message
        names the parameter to change; then the conditioned law's mass.

        Raises
        ------
        ConfigError
            If the plugin refuses ``mu_d``, or P(mu_s > mu_d | mu_s > lower) < MIN_MASS.
        """
        check = getattr(self.dist, "check_mu_d", None)
        if check is not None:
            check(mu_d)
        mass = float(self.sf(float(mu_d)))
        if not mass >= MIN_MASS:
            raise ConfigError(
                f"The distribution {self.name!r}, conditioned on mu_s > {self.lower!r}, puts probability "
                f"{mass!r} above mu_d = {mu_d!r}; at least {MIN_MASS!r} is needed."
            )

    def _checked(self, draws: object, size: int) -> np.ndarray:


        return checked_output(draws, (size,), "distribution", self.name, f"sample(rng, {size})")

    def _refuse_below(self, draws: np.ndarray, bad: np.ndarray, size: int) -> None:
        """Stop the run if a plugin that does not ask for truncation drew at or below ``lower``."""
        if bad.size and not self.truncate:
            from slidernet.errors import PluginError

            raise PluginError(
                f"The distribution {self.name!r} returned {bad.size} values at or below mu_d = {self.lower!r} "
                f"from sample(rng, {size}) (the first: {float(draws[bad[0]])!r}), although its cdf puts no "
                "mass there; p(mu_s) must vanish for mu_s <= mu_d."
            )

    def compiled_law(self) -> tuple[int, float, float, float] | None:
        """The law's compiled draws, for a built-in that has them (a plugin's ``sample`` is always called)."""
        law = getattr(self.dist, "compiled_law", None)
        return law() if self.truncate and isinstance(self.dist, Distribution) and law is not None else None

    def accepted(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """The draws strictly above ``lower`` among ``size`` draws of the plugin, in their order.

        One call of the plugin's ``sample(rng, size)``; the draws at or below
        ``lower`` are dropped (rejection), so the result has ``size`` values
        or fewer. This is the building block of :class:`TruncatedStream`.

        Parameters
        ----------
        rng : numpy.random.Generator
            The stream to draw from.
        size : int
            Number of raw draws asked of the plugin.

        Returns
        -------
        numpy.ndarray
            The accepted draws (dimensionless, like mu_s), float64, shape ``(k,)`` with ``k <= size``.

        Raises
        ------
        PluginError
            If the plugin returns the wrong shape, NaN or inf, or (for a plugin
            that does not declare ``truncate_below_mu_d``) a value at or below ``lower``.
        """
        draws = self._checked(self.dist.sample(rng, size), size)
        keep = draws > self.lower
        if keep.all():
            return draws
        self._refuse_below(draws, np.flatnonzero(~keep), size)
        return draws[keep]

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws strictly above ``lower``, shape ``(size,)``.

        Rejected draws are replaced from further calls of the plugin, so the
        values depend on ``size``: ``sample(rng, 2)`` then ``sample(rng, 3)``
        need not be the first five values of ``sample(rng, 5)`` when draws are
        rejected. The solver reads its thresholds through a
        :class:`TruncatedStream` instead, whose values never depend on how
        many are asked for at a time.
        """
        out = self._checked(self.dist.sample(rng, size), size)
        bad = np.flatnonzero(out <= self.lower)
        self._refuse_below(out, bad, size)
        while bad.size:
            # Ask for extra draws so that the loop ends in one or two passes.
            want = int(bad.size / self.acceptance * 1.2) + 8
            fresh = self._checked(self.dist.sample(rng, want), want)
            fresh = fresh[fresh > self.lower][: bad.size]
            out[bad[: fresh.size]] = fresh
            bad = bad[fresh.size :]
        return out

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s <= x | mu_s > lower)."""
        x = np.asarray(x, dtype=float)
        return np.where(x <= self.lower, 0.0, 1.0 - self.sf(np.maximum(x, self.lower)))

    def sf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s > x | mu_s > lower)."""
        x = np.asarray(x, dtype=float)
        return np.where(x <= self.lower, 1.0, self._raw_sf(np.maximum(x, self.lower)) / self.mass)

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x > lower with P(mu_s > x | mu_s > lower) = q, for q in [0, 1].

        Uses the plugin's own ``isf`` where it has one, and a bisection on
        ``sf`` otherwise.
        """
        q = np.asarray(q, dtype=float)
        isf = getattr(self.dist, "isf", None)
        if isf is not None:
            return np.maximum(np.asarray(isf(q * self.mass), dtype=float), self.lower)
        return self._bisect_isf(q)

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x | mu_s > lower) = u, for u in [0, 1]."""
        return self.isf(1.0 - np.asarray(u, dtype=float))

    def _bisect_isf(self, q: np.ndarray) -> np.ndarray:
        """isf by vectorised bisection on sf, for plugins without isf."""
        lo = np.full(q.shape, self.lower)
        width = max(abs(self.lower), 1.0) * 1e-3
        target = float(q.min()) if q.size else 1.0
        # Double until sf(hi) <= every target (or the doubling runs out).
        for _ in range(1100):
            if float(self.sf(self.lower + width)) <= target or not math.isfinite(self.lower + 2 * width):
                break
            width *= 2.0
        hi = np.full(q.shape, self.lower + width)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            moving = (mid > lo) & (mid < hi)
            if not moving.any():
                break
            above = self.sf(mid) > q  # mid is below the quantile
            lo = np.where(above & moving, mid, lo)
            hi = np.where(~above & moving, mid, hi)
        return hi

    def mean_max(self, m: ArrayLike) -> np.ndarray:
        """Exact mean of the largest of ``m`` i.i.d. draws of this (truncated) law.

        This is the law slidernet draws from: after ``n`` rearrangements of
        the two-slider system, mu_max is the largest of ``m = n + 2`` draws.
        A built-in computes it itself (``dist.mean_max_above(m, lower)``, a
        closed form where there is one); any other plugin goes through
        :func:`mean_max_quadrature` on this object. Where the plugin's
        support starts above ``lower`` it equals the plugin's ``mean_max(m)``.

        Parameters
        ----------
        m : float or array_like
            Number(s) of draws, >= 1 (need not be integers), any shape.

        Returns
        -------
        numpy.ndarray
            E[max | mu_s > lower], dimensionless like mu_s, shape of ``m``.
        """
        return self.mean_max_above(m, self.lower)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Exact mean of the largest of ``m`` draws of this law, conditioned further on mu_s > ``lower``.

        Conditioning on mu_s > a and then on mu_s > b is conditioning on
        mu_s > max(a, b); a ``lower`` at or below :attr:`lower` changes nothing.
        See :meth:`Distribution.mean_max_above`.
        """
        if isinstance(self.dist, Distribution):
            return self.dist.mean_max_above(m, max(self.lower, float(lower)))
        return super().mean_max_above(m, lower)

    def __repr__(self) -> str:
        return f"TruncatedBelow({self.dist!r}, lower={self.lower!r})"


# Raw draws asked of a plugin at a time by TruncatedStream. Fixed, so that the
# accepted values never depend on solver.batch or on how many are asked for:
# 2**16 is the default batch, so at the default settings, without rejections,
# a refill costs one plugin call as before (a plugin's per-call overhead,
# e.g. scipy's rvs, stays amortised), and a chunk is 512 KiB of float64.
RAW_CHUNK = 1 << 16


class TruncatedStream:
    """The draws of a :class:`TruncatedBelow` law from one Generator, in an order set by the seed alone.

    The plugin is always called with the same number of draws,
    :data:`RAW_CHUNK`, whatever is asked for; the draws at or below ``lower``
    are dropped (:meth:`TruncatedBelow.accepted`), and the accepted draws
    that a call of :meth:`take` does not hand out are kept for the next one
    (the *surplus*). The values handed out by ``take(k1)``, ``take(k2)``, ...
    are therefore the filtered raw chunks laid end to end, a function of the
    Generator's initial state alone: asking one at a time or 65536 at a time
    gives the same bits. Its state is the Generator's state plus
    :attr:`surplus` (what :mod:`slidernet.io.checkpoint` saves).

    Nothing is drawn before the first :meth:`take`. For a plugin whose
    ``sample`` is prefix-consistent (``sample(rng, a)`` then ``sample(rng, b)``
    gives the first ``a + b`` values of ``sample(rng, a + b)``, as numpy's
    normal, uniform and exponential draws are) and no rejection, the values
    are those of plain successive ``sample`` calls.

    Parameters
    ----------
    dist : TruncatedBelow
        The law (its plugin, truncation point and checks).
    rng : numpy.random.Generator
        The stream it owns: nothing else may draw from it, or the order of
        the values would depend on who drew when.

    Examples
    --------
    >>> import numpy as np
    >>> law = TruncatedBelow(Gaussian(0.6, 0.1), lower=0.5, name="gaussian")
    >>> one = TruncatedStream(law, np.random.default_rng(1))
    >>> many = TruncatedStream(law, np.random.default_rng(1))
    >>> small = np.concatenate([one.take(1) for _ in range(100)])
    >>> bool((small == many.take(100)).all()), bool((small > 0.5).all())
    (True, True)
    >>> one.surplus.size == many.surplus.size
    True
    """

    def __init__(self, dist: TruncatedBelow, rng: np.random.Generator) -> None:
        self.dist = dist
        self.rng = rng
        self._surplus = np.empty(0)
        # A built-in law with compiled draws is drawn one value at a time: the same values, with
        # no surplus, about 4 times faster (slidernet.kernels.draws).
        self._compiled = dist.compiled_law() if isinstance(dist, TruncatedBelow) else None

    @property
    def surplus(self) -> np.ndarray:
        """The accepted draws not yet handed out, in order; float64, shape ``(k,)``, read-only."""
        view = self._surplus.view()
        view.flags.writeable = False
        return view

    def take(self, size: int) -> np.ndarray:
        """The next ``size`` accepted draws of the stream.

        Parameters
        ----------
        size : int
            Number of values, >= 0.

        Returns
        -------
        numpy.ndarray
            Values strictly above ``dist.lower`` (dimensionless, like mu_s),
            float64, shape ``(size,)``, C-contiguous; the stream never
            reads or writes them again.

        Raises
        ------
        ValueError
            If ``size`` is negative.
        PluginError
            As :meth:`TruncatedBelow.accepted`.
        """
        size = int(size)
        if size < 0:
            raise ValueError(f"The 'size' parameter of TruncatedStream.take must be >= 0. Got {size} instead.")
        if self._compiled is not None and not self._surplus.size:
            out = np.empty(size)
            draws.fill_truncated(self.rng, out, *self._compiled, self.dist.lower)
            return out
        parts = [self._surplus] if self._surplus.size else []
        have = self._surplus.size
        while have < size:
            fresh = self.dist.accepted(self.rng, RAW_CHUNK)
            parts.append(fresh)
            have += fresh.size
        pool = np.concatenate(parts) if len(parts) > 1 else (parts[0] if parts else self._surplus)
        # No copy: the caller's values and the surplus are disjoint parts of one buffer.
        out = pool[:size]
        self._surplus = pool[size:]
        return out

    def restore(self, surplus: ArrayLike) -> None:
        """Replace the surplus, e.g. with one saved by a checkpoint (the Generator's state is the caller's).

        Raises
        ------
        ValueError
            If ``surplus`` is not a 1-D float64 array of finite values above ``dist.lower``.
        """
        arr = np.asarray(surplus)
        if arr.dtype != np.float64 or arr.ndim != 1:
            raise ValueError(f"the surplus of a threshold stream must be a 1-D float64 array, "
                             f"not {arr.dtype}{arr.shape}")
        if arr.size and not (np.isfinite(arr).all() and arr.min() > self.dist.lower):
            raise ValueError(f"the surplus of a threshold stream holds values that are not finite "
                             f"and > mu_d = {self.dist.lower!r}")
        self._surplus = arr.copy()

    def __repr__(self) -> str:
        return f"TruncatedStream({self.dist!r}, surplus={self._surplus.size})"


# The built-in distributions, by the name a config uses (``friction.static.name``).
BUILTINS: dict[str, type] = {
    cls.name: cls
    for cls in (Gaussian, Uniform, Constant, Weibull, Lognormal, Exponential, Pareto, Empirical, ScipyStats)
}
