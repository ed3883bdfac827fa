"""Exact statistics of the thresholds' maximum and of its records: the max of ``n + 2`` draws.

In the two-slider model only the weaker threshold is ever redrawn, so
mu_max after ``n`` rearrangements is the maximum of ``n + 2`` independent
draws of p(mu_s), and each exchange of the strongest slider is a record of
that sequence (docs/model.md, section 4). What follows from that alone holds
for every distribution p(mu_s) and is exact:

- :func:`mu_max_cdf`: the law of mu_max, F^(n+2);
- :func:`mu_max_moments`: its mean and standard deviation, integrated from
  the distribution's own cdf by a composite Gauss-Legendre rule;
- :func:`harmonic` and :func:`mean_records`: the mean number of records.

Shares with the rest of :mod:`slidernet.analysis.theory` only the counting
convention of ``n`` (the package's docstring) and the input checks of
:mod:`slidernet._validation`; the paper's approximate laws for the same
quantities are in :mod:`~slidernet.analysis.theory.paper_laws`.
"""

from __future__ import annotations

import functools
import math
from fractions import Fraction
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

from slidernet._validation import check_array
from slidernet.errors import ConfigError, param_error

# Probability mass left out at each end of the integration range of
# mu_max_moments: far below double precision relative to the moments.
_TAIL_EPS = 1e-17
# Composite Gauss-Legendre rule across that range: panels of a low-order rule
# (a single 2000-point rule costs 0.5 s of eigenvalue work). The panel edges
# are quantiles of mu_max, equally spaced in logit(F^m) between the two tail
# levels, so that every panel holds a similar share of the law: a fixed grid
# in x would leave the bulk to a few panels when the tail is long (a power
# law's x_hi lies ~1e17^(1/alpha) scales above its bulk).
_N_PANELS = 128
_PANEL_ORDER = 16
# H_k is tabulated exactly (correctly rounded from rationals) up to this k;
# above it digamma is accurate to a few ulp and a table would be wasteful.
_H_TABLE_MAX = 1024


def _exact_harmonic_table(kmax: int) -> np.ndarray:
    total = Fraction(0)
    table = [0.0]
    for k in range(1, kmax + 1):
        total += Fraction(1, k)
        table.append(float(total))
    return np.array(table)


_H_TABLE = _exact_harmonic_table(_H_TABLE_MAX)


def _check_dist(dist: Any, owner: str) -> None:
    if not callable(getattr(dist, "cdf", None)):
        raise param_error("dist", owner, "a distribution with a cdf(x) method", dist)


def _log_cdf(dist: Any, x: np.ndarray) -> np.ndarray:
    """log F(x), accurate in the upper tail when ``dist`` has ``sf``."""
    sf = getattr(dist, "sf", None)
    with np.errstate(divide="ignore", invalid="ignore"):
        if sf is not None:
            # log1p(-sf) keeps the tail 1 - F ~ 1e-26 that 1 - cdf rounds to 0.
            return np.log1p(-np.clip(np.asarray(sf(x), dtype=float), 0.0, 1.0))
        return np.log(np.clip(np.asarray(dist.cdf(x), dtype=float), 0.0, 1.0))


def mu_max_cdf(dist: Any, mu: ArrayLike, n: ArrayLike) -> np.ndarray:
    r"""Exact CDF of mu_max after ``n`` rearrangements: :math:`F(\mu)^{n+2}`.

    In the two-slider model only the weaker threshold is ever redrawn, so
    mu_max is the maximum of the ``n + 2`` independent draws (two initial
    ones and one per rearrangement; docs/model.md, section 4).

    Parameters
    ----------
    dist : object
        The distribution of mu_s as the model draws it, i.e. already
        truncated below mu_d (e.g. :class:`~slidernet.plugins.distributions.TruncatedBelow`).
        Needs ``cdf``; ``sf`` is used when present, which keeps the result
        accurate in the upper tail for ``n`` up to 1e9 and beyond.
    mu : float or array_like
        Friction coefficient(s) at which to evaluate the CDF.
    n : float or array_like
        Number of rearrangements, >= 0; broadcast against ``mu``.

    Returns
    -------
    numpy.ndarray
        P(mu_max <= mu), shape ``np.broadcast(mu, n).shape``.

    Examples
    --------
    >>> from slidernet.plugins.distributions import Gaussian
    >>> d = Gaussian(0.6, 0.01)
    >>> float(mu_max_cdf(d, 0.6, 0))
    0.25
    >>> mu_max_cdf(d, [0.6, 0.7], [[0], [1]]).shape
    (2, 2)
    """
    owner = "mu_max_cdf"
    _check_dist(dist, owner)
    m = check_array(n, "n", owner, ">= 0") + 2.0
    mu = check_array(mu, "mu", owner)
    return np.exp(m * _log_cdf(dist, mu))


def _bracket(dist: Any, eps_lo: float, eps_hi: float) -> tuple[float, float]:
    """Points a < b with F(a) <= eps_lo and 1 - F(b) <= eps_hi."""
    lower = getattr(dist, "lower", None)
    lower = None if lower is None else float(lower)
    centre = 0.0 if lower is None else lower
    width = 1.0
    a = centre if lower is not None else centre - width
    b = centre + width
    # Doubling reaches any finite support from an arbitrary starting scale;
    # 1100 doublings would overflow, so stop well before that.
    for _ in range(1000):
        low_ok = lower is not None or float(np.exp(_log_cdf(dist, np.array(a)))) <= eps_lo
        high_ok = -math.expm1(float(_log_cdf(dist, np.array(b)))) <= eps_hi
        if low_ok and high_ok:
            return a, b
        width *= 2.0
        if not low_ok:
            a = centre - width
        if not high_ok:
            b = centre + width
    raise ConfigError(
        f"mu_max_moments could not bracket the support of {dist!r}: its cdf does not "
        "reach 0 and 1 within |x| < 1e300."
    )


def _bisect(pred: Any, a: float | np.ndarray, b: float | np.ndarray,
            size: int | tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised bisection: pred(x) is True at ``a``, False at ``b``, monotone.

    ``a`` and ``b`` broadcast to ``size`` (an int or a shape). Returns the
    final (lo, hi) arrays; lo still satisfies the predicate.
    """
    lo = np.broadcast_to(np.asarray(a, dtype=float), size).copy()
    hi = np.broadcast_to(np.asarray(b, dtype=float), size).copy()
    # 2100 halvings shrink any double interval to adjacent floats; stop early
    # once no midpoint differs from its ends.
    for _ in range(2100):
        mid = 0.5 * (lo + hi)
        moving = (mid > lo) & (mid < hi)
        if not moving.any():
            break
        ok = pred(mid)
        lo = np.where(ok & moving, mid, lo)
        hi = np.where(~ok & moving, mid, hi)
    return lo, hi


@functools.lru_cache(maxsize=4)
def _gauss_legendre(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the ``order``-point Gauss-Legendre rule on [-1, 1]."""
    t, w = np.polynomial.legendre.leggauss(order)
    t.flags.writeable = False
    w.flags.writeable = False
    return t, w


def mu_max_moments(dist: Any, n: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    r"""Exact mean and standard deviation of mu_max after ``n`` rearrangements.

    mu_max is the maximum of ``m = n + 2`` independent draws (see
    :func:`mu_max_cdf`). The moments are integrals of the distribution's own
    CDF -- no Monte Carlo, no asymptotic expansion:

    .. math:: E[X] = x_\mathrm{lo} + \int_{x_\mathrm{lo}}^{x_\mathrm{hi}} (1 - F^m)\,dx,
              \qquad
              E[(X - x_\mathrm{lo})^2] = \int_{x_\mathrm{lo}}^{x_\mathrm{hi}}
              2 (x - x_\mathrm{lo}) (1 - F^m)\,dx,

    where :math:`F(x_\mathrm{lo})^m \approx 10^{-17}` (or ``x_lo = dist.lower``
    when the distribution has that attribute and it is higher) and
    :math:`1 - F(x_\mathrm{hi})^m \approx 10^{-17}`. The integrals use a
    composite Gauss-Legendre rule: 128 panels of 16 nodes, whose edges are
    the quantiles of mu_max at levels equally spaced in logit(F^m) from
    x_lo to x_hi, all found by vectorised bisection; so light and heavy
    tails and bounded supports are all resolved. A step cdf (an empirical
    law) is integrated exactly only where each panel holds at most one step;
    with many more steps than panels the error is ~1e-4 relative.
    The error is at the level of double-precision rounding (about 1e-12
    standard deviations of p(mu_s)) for any ``n`` from 0 to 1e9 and beyond,
    provided ``dist`` has ``sf``; with ``cdf`` only, the tail 1 - F below
    ~1e-16 is lost, which still leaves errors far below 1e-4 standard
    deviations up to n = 1e9. The distribution must have a finite mean; for
    a power-law tail P(mu_s > x) ~ x^-alpha the part beyond x_hi that is
    left out is a relative ~1e-17^(1 - 1/alpha) of the mean (1e-11 for
    alpha = 3), and the standard deviation is finite only for alpha > 2.

    Parameters
    ----------
    dist : object
        The distribution of mu_s as the model draws it (truncated below
        mu_d), with ``cdf`` and optionally ``sf`` and ``lower``.
    n : float or array_like
        Number(s) of rearrangements, >= 0, any shape. Repeated values are
        computed once.

    Returns
    -------
    mean, std : numpy.ndarray
        Mean and standard deviation of mu_max, each with the shape of ``n``.

    Examples
    --------
    >>> from slidernet.plugins.distributions import Gaussian, TruncatedBelow
    >>> d = TruncatedBelow(Gaussian(0.6, 0.01), lower=0.5, name="gaussian")
    >>> mean, std = mu_max_moments(d, [0, 1000])
    >>> mean.round(5).tolist(), std.round(5).tolist()
    ([0.60564, 0.63242], [0.00826, 0.00351])
    """
    owner = "mu_max_moments"
    _check_dist(dist, owner)
    n_arr = check_array(n, "n", owner, ">= 0")
    if n_arr.size == 0:
        return np.empty(n_arr.shape), np.empty(n_arr.shape)
    m_unique, inverse = np.unique(n_arr.ravel() + 2.0, return_inverse=True)
    log_eps_lo = math.log(_TAIL_EPS)

    # The loosest targets of the whole batch (the smallest m at the bottom,
    # the largest at the top) bound a bracket valid for every m.
    eps_lo = math.exp(log_eps_lo / m_unique[0])
    eps_hi = -math.expm1(math.log1p(-_TAIL_EPS) / m_unique[-1])
    a, b = _bracket(dist, eps_lo, eps_hi)
    # Panel edges: the quantiles of the max at logit(F^m) levels spaced equally
    # from logit(eps) to logit(1 - eps); the first edge keeps F^m <= eps.
    logit_eps = log_eps_lo - math.log1p(-_TAIL_EPS)
    levels = np.linspace(logit_eps, -logit_eps, _N_PANELS + 1)
    # Each m is integrated on its own (the bisection stops element by element),
    # so chunks give the same bits as one batch; they keep the work arrays, of
    # _N_PANELS * _PANEL_ORDER values per m, at a few MB (one batch of the
    # paper's 50 500 values of n took 2.8 GB).
    mean = np.empty(m_unique.size)
    var = np.empty(m_unique.size)
    for start in range(0, m_unique.size, _CHUNK):
        part = slice(start, start + _CHUNK)
        mean[part], var[part] = _moments_on_panels(dist, m_unique[part], a, b, levels)
    shape = n_arr.shape
    return mean[inverse].reshape(shape), np.sqrt(var)[inverse].reshape(shape)


_CHUNK = 256  # values of m integrated at a time by mu_max_moments


def _moments_on_panels(dist: Any, m: np.ndarray, a: float, b: float,
                       levels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(mean, variance) of the max of m draws for each m, on the panels of :func:`mu_max_moments`."""
    m_col = m[:, None]

    def at_or_below_level(x: np.ndarray) -> np.ndarray:
        log_g = m_col * _log_cdf(dist, x)  # log F^m
        with np.errstate(divide="ignore"):
            logit = log_g - np.log(-np.expm1(log_g))
        return logit <= levels

    lo, hi = _bisect(at_or_below_level, a, b, (m.size, levels.size))
    edges = np.concatenate([lo[:, :1], hi[:, 1:]], axis=1)
    # Where F jumps across several levels at once (an atom), neighbouring edges
    # end at the same point, up to an ulp; keep them ordered.
    edges = np.maximum.accumulate(edges, axis=1)
    x_lo = edges[:, 0]

    t, w = _gauss_legendre(_PANEL_ORDER)
    half = (0.5 * np.diff(edges, axis=1))[:, :, None]
    x = edges[:, :-1, None] + half * (t + 1.0)
    survival = -np.expm1(m[:, None, None] * _log_cdf(dist, x))  # P(max > x)
    weights = half * w
    above = (weights * survival).sum(axis=(1, 2))  # E[X] - x_lo
    second = (weights * 2.0 * (x - x_lo[:, None, None]) * survival).sum(axis=(1, 2))  # E[(X - x_lo)^2]
    return x_lo + above, np.maximum(second - above**2, 0.0)


def harmonic(n: ArrayLike) -> np.ndarray:
    r"""Harmonic number :math:`H_n = \sum_{k=1}^{n} 1/k`, vectorised.

    Integer n up to 1024 come from an exact rational table (correctly
    rounded); larger or non-integer n use the analytic continuation
    :math:`H_n = \psi(n + 1) + \gamma`, accurate to a few ulp.

    Parameters
    ----------
    n : int, float or array_like
        n >= 0, any shape.

    Returns
    -------
    numpy.ndarray
        H_n, float, shape of ``n``.

    Examples
    --------
    >>> harmonic([0, 1, 2, 3]).tolist() == [0.0, 1.0, 1.5, 11 / 6]
    True
    >>> round(float(harmonic(1e9)), 6)
    21.300482
    """
    n_arr = check_array(n, "n", "harmonic", ">= 0")
    small = (n_arr == np.floor(n_arr)) & (n_arr <= _H_TABLE_MAX)
    index = np.where(small, n_arr, 0).astype(np.intp)
    return np.where(small, _H_TABLE[index], special.digamma(n_arr + 1.0) + np.euler_gamma)


def mean_records(n: ArrayLike) -> np.ndarray:
    r"""Expected number of exchanges of the strongest slider after n rearrangements.

    The k-th draw (k >= 3; the first two are the initial thresholds) makes
    the other slider the strongest exactly when it exceeds every earlier
    draw, i.e. when it is a strict record, which has probability 1/k for
    i.i.d. continuous draws. Hence, exactly,

    .. math:: \langle \text{exchanges} \rangle = \sum_{k=3}^{n+2} \frac1k
              = H_{n+2} - H_2 = H_{n+2} - \tfrac32 .

    docs/model.md's "mean H_n" and the paper's "ln n" are the leading-order
    forms of this: H_{n+2} - 3/2 = H_n - 3/2 + O(1/n) = ln n - (3/2 - gamma)
    + O(1/n), so H_n counts 1.5 too many and ln n about 0.92 too many.

    Parameters
    ----------
    n : int, float or array_like
        Number of rearrangements, >= 0, any shape.

    Returns
    -------
    numpy.ndarray
        Mean number of exchanges (records), shape of ``n``.

    Examples
    --------
    >>> mean_records([0, 1, 2]).round(12).tolist()
    [0.0, 0.333333333333, 0.583333333333]
    """
    n_arr = check_array(n, "n", "mean_records", ">= 0")
    return harmonic(n_arr + 2.0) - 1.5
