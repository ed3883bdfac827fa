"""Predictions of the model to compare simulations against: the paper's section IV and thermal creep.

Everything here is a reference for the solver, and shares no code with it.
Units follow docs/model.md: lengths in l0, time in tau_th, friction
coefficients dimensionless. ``n`` is always the number of rearrangements
since t = 0, so the initial state holds two drawn thresholds and after ``n``
rearrangements ``n + 2`` thresholds have been drawn in all (docs/model.md,
section 4). The paper counts from an initial step n = 1 and therefore writes
``n + 1`` for the same number.

Three kinds of results live side by side and the docstrings say which is which:

* exact statements about the threshold sequence, which hold for every
  distribution p(mu_s) -- :func:`mu_max_cdf`, :func:`mu_max_moments`,
  :func:`harmonic`, :func:`mean_records`;
* the paper's approximate laws -- :func:`mean_rearrangements` (eq. ``slope``),
  :func:`mu_max_leading` (eq. ``mumaxth``) and :func:`msd` (order of
  magnitude only);
* thermal creep on an incline with constant thresholds: closed forms for
  two sliders (:func:`pair_creep` and its companions) and for three sliders'
  first plateau (:func:`three_slider_onset`), and the exact periodic orbit
  of any chain, followed slip by slip in rational arithmetic
  (:func:`chain_creep`, :func:`chain_creep_segments`,
  :func:`chain_critical_amplitude`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from fractions import Fraction
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

from slidernet._validation import check_array, check_scalar
from slidernet.errors import ConfigError, OrbitError, param_error

__all__ = [
    "ChainOrbit",
    "CreepSegment",
    "chain_creep",
    "chain_creep_segments",
    "chain_critical_amplitude",
    "chain_orbit",
    "harmonic",
    "mean_rearrangements",
    "mean_records",
    "msd",
    "mu_max_cdf",
    "mu_max_leading",
    "mu_max_moments",
    "pair_creep",
    "pair_creep_slips",
    "pair_creep_steps",
    "pair_critical_amplitude",
    "three_slider_onset",
]

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


# ---------------------------------------------------------------------------
# rearrangement rate


def mean_rearrangements(
    sigma_theta: ArrayLike,
    Ntilde: float,
    mu_d: float,
    mu_s_mean: float,
    offset: bool = True,
) -> np.ndarray:
    r"""Mean number of rearrangements per thermal time tau_th (eq. ``slope``).

    With ``offset=True`` this is the paper's phenomenological form

    .. math:: \langle r \rangle = \frac{\sigma_\theta - \mu_d \tilde N}
              {\sqrt{\pi}\,(\bar\mu_s - \mu_d)\,\tilde N},

    and with ``offset=False`` the plain estimate without the shift
    :math:`\mu_d \tilde N`. Both are approximations: docs/model.md (section 4)
    says the first fails when ``sigma_theta`` is below about
    ``2 * mu_d * Ntilde``, and it turns negative, hence meaningless, below
    ``mu_d * Ntilde``. The value is returned as the formula gives it, without
    clipping, so that such a misuse shows.

    Parameters
    ----------
    sigma_theta : float or array_like
        Standard deviation of the dilation theta (dimensionless), > 0; any shape.
    Ntilde : float
        N / (k l0), > 0.
    mu_d : float
        Dynamic friction coefficient, finite.
    mu_s_mean : float
        Mean static friction coefficient (of p(mu_s) before truncation), > mu_d.
    offset : bool
        Subtract the offset mu_d * Ntilde of eq. ``slope`` (default) or not.

    Returns
    -------
    numpy.ndarray
        <r>, rearrangements per tau_th, with the shape of ``sigma_theta``.

    Raises
    ------
    ConfigError
        On a non-finite or non-positive ``sigma_theta`` or ``Ntilde``, a
        non-finite ``mu_d``, or ``mu_s_mean <= mu_d``.

    Examples
    --------
    >>> r = mean_rearrangements(1e-6, Ntilde=1e-7, mu_d=0.5, mu_s_mean=0.6)
    >>> round(float(r), 2)
    53.6
    >>> round(float(mean_rearrangements(1e-6, 1e-7, 0.5, 0.6, offset=False)), 2)
    56.42
    """
    owner = "mean_rearrangements"
    sigma = check_array(sigma_theta, "sigma_theta", owner, "> 0")
    ntilde = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    mu_d = check_scalar(mu_d, "mu_d", owner)
    mu_s_mean = check_scalar(mu_s_mean, "mu_s_mean", owner)
    if not mu_s_mean > mu_d:
        raise param_error("mu_s_mean", owner, f"> mu_d = {mu_d!r}", mu_s_mean)
    shift = mu_d * ntilde if offset else 0.0
    return (sigma - shift) / (math.sqrt(math.pi) * (mu_s_mean - mu_d) * ntilde)


# ---------------------------------------------------------------------------
# statistics of mu_max (exact)


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


def mu_max_leading(mu_s_mean: float, sigma_mu: float, n: ArrayLike) -> np.ndarray:
    r"""Leading-order growth of mu_max (eq. ``mumaxth``).

    .. math:: \mu_\mathrm{max} \approx \bar\mu_s + \sigma_\mu \sqrt{2 \ln n}

    This is only the leading term of the extreme-value asymptotics of a
    Gaussian: it overestimates the exact mean maximum
    (:func:`mu_max_moments`) by about 0.4 to 0.5 ``sigma_mu`` for n = 1e3 to
    1e6 (0.47 at 1e3 falling to 0.39 at 1e6, for p(mu_s) truncated far below
    its mean), since the next terms,
    ``sigma_mu * (ln ln n + ln 4 pi - 2 gamma) / (2 sqrt(2 ln n))``, decay only
    like ln(ln n) / sqrt(ln n). Where n <= 1 the logarithm is not positive
    and ``mu_s_mean`` is returned; the law carries no information there.

    Parameters
    ----------
    mu_s_mean : float
        Mean static friction coefficient, finite.
    sigma_mu : float
        Standard deviation of mu_s, > 0.
    n : float or array_like
        Number of rearrangements, >= 0 (in the paper, ``<r> t / tau_th``).

    Returns
    -------
    numpy.ndarray
        Predicted mu_max, shape of ``n``.

    Examples
    --------
    >>> mu_max_leading(0.6, 0.01, [1, 1e4]).round(4).tolist()
    [0.6, 0.6429]
    """
    owner = "mu_max_leading"
    mu_s_mean = check_scalar(mu_s_mean, "mu_s_mean", owner)
    sigma_mu = check_scalar(sigma_mu, "sigma_mu", owner, "> 0")
    n_arr = check_array(n, "n", owner, ">= 0")
    log_n = np.log(np.maximum(n_arr, 1.0))
    return mu_s_mean + sigma_mu * np.sqrt(2.0 * log_n)


# ---------------------------------------------------------------------------
# diffusion and records


def msd(sigma_theta: ArrayLike, n: ArrayLike) -> np.ndarray:
    r"""Order-of-magnitude law of the centre-of-mass diffusion.

    .. math:: \langle x_G^2 \rangle \approx \sigma_\theta^2\, l_0^2 \ln n

    (the paper's section IV.C): each exchange of the strongest slider moves
    the centre of mass by about sigma_theta l0, and there are about ln n
    exchanges. Only the order of magnitude and the logarithmic growth are
    claimed; see :func:`mean_records` for the exact number of exchanges.
    Returns 0 where n <= 1.

    Parameters
    ----------
    sigma_theta : float or array_like
        Standard deviation of the dilation theta, > 0.
    n : float or array_like
        Number of rearrangements, >= 0; broadcast against ``sigma_theta``.

    Returns
    -------
    numpy.ndarray
        <x_G^2> in units of l0^2, shape ``np.broadcast(sigma_theta, n).shape``.

    Examples
    --------
    >>> float(msd(1e-6, 1.0))
    0.0
    >>> round(float(msd(1e-6, np.e**2)) / 1e-12, 12)
    2.0
    """
    owner = "msd"
    sigma = check_array(sigma_theta, "sigma_theta", owner, "> 0")
    n_arr = check_array(n, "n", owner, ">= 0")
    return sigma**2 * np.log(np.maximum(n_arr, 1.0))


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


# ---------------------------------------------------------------------------
# Thermal creep of two sliders on an incline, clean friction (constant mu_s)
#
# In the kernels' units (forces in N, theta and lengths in Ntilde, k = 1) the
# spring's compression is G = theta - (u_2 - u_1). On an incline every slider
# carries f = tan(alpha) downhill (+x): slider 2 feels f + G and slider 1
# f - G. For 0 < f < mu_d every slip is downhill: slider 2 yields at
# G = U = mu_s - f and slider 1 at G = L = f - mu_s (the backward thresholds
# lie beyond these), each slip has the length D = 2 (mu_s - mu_d) and moves G
# by -D (slider 2) or +D (slider 1), and it moves x_G by D / 2. Between two
# turning points theta is monotone, G follows theta, and each arrival at U
# (or L) is one slip: the motion is a map of G from one turning point to the
# next, exact and closed-form.

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


def _pair_creep_args(tan_alpha: float, mu_s: float, mu_d: float, owner: str) -> tuple[float, float, float]:
    ms, md = _check_friction(mu_s, mu_d, owner)
    f = _check_tan(tan_alpha, md, owner)
    return ms - f, f - ms, 2.0 * (ms - md)


def pair_creep_slips(turning_points: ArrayLike, tan_alpha: float, mu_s: float, mu_d: float) -> np.ndarray:
    """Slips of two sliders with constant thresholds on an incline, per monotone stretch of theta (exact).

    The spring is at rest at the first turning point. On a rise of theta by
    R from G_0, slider 2 slips each time G reaches U = mu_s - f:
    floor((R - (U - G_0)) / D) + 1 times if R >= U - G_0, else never, and
    G ends at G_0 + R - (slips) D; a fall is the mirror image at
    L = f - mu_s (slider 1 slips). f = tan(alpha), D = 2 (mu_s - mu_d).

    Parameters
    ----------
    turning_points : array_like, shape (K,)
        theta / Ntilde at t = 0 and at each later extreme, in order (the
        values of theta where it turns, or any points between which it is
        monotone).
    tan_alpha : float
        Downhill load per unit normal load, in (0, mu_d).
    mu_s, mu_d : float
        The constant static threshold and the dynamic coefficient, mu_s > mu_d.

    Returns
    -------
    numpy.ndarray of int, shape (K - 1,)
        Slips in each stretch: by slider 2 on a rise, by slider 1 on a fall.

    Examples
    --------
    Rest at theta = 0, then theta / Ntilde = 0.6, -0.6, 0.6 with f = 0.1:
    U = 0.5, one slip on the way up (G: 0.5 -> 0.3, then 0.4 at the top),
    two on the way down (at G = -0.5 and again after a further fall of D = 0.2),
    two on the next rise: two slips per stretch from then on.

    >>> pair_creep_slips([0.0, 0.6, -0.6, 0.6], 0.1, 0.6, 0.5).tolist()
    [1, 2, 2]
    """
    owner = "pair_creep_slips"
    U, L, D = _pair_creep_args(tan_alpha, mu_s, mu_d, owner)
    theta = check_array(turning_points, "turning_points", owner).ravel()
    G = 0.0
    slips = np.zeros(max(theta.size - 1, 0), dtype=np.int64)
    for k in range(theta.size - 1):
        R = float(theta[k + 1] - theta[k])
        if R >= 0.0:
            gap = U - G
            n = math.floor((R - gap) / D) + 1 if R >= gap else 0
            G += R - n * D
        else:
            gap = G - L
            n = math.floor((-R - gap) / D) + 1 if -R >= gap else 0
            G += R + n * D
        slips[k] = n
    return slips


def pair_creep(amplitude: ArrayLike, Ntilde: float, tan_alpha: ArrayLike, mu_s: float,
               mu_d: float) -> tuple[np.ndarray, np.ndarray]:
    """Steady creep of two sliders under a symmetric cycle of theta, from rest (closed form).

    theta starts at 0 with the spring at rest, rises to +A, falls to -A, and
    so on (the ``sinusoidal`` driver with phase 0 and a period that is a
    multiple of 4 tau_th samples exactly these extremes). With
    x = A / Ntilde - (mu_s - f), f = tan(alpha), D = 2 (mu_s - mu_d):

    * x < 0: theta never brings a slider to its threshold: no slip, v = 0;
    * x >= 0: after the first rise, G sits D - (x mod D) below U, and from the
      first fall on every stretch of theta has m = 2 floor(x / D) + 2 slips.
      Each slider advances m D per cycle, and so does x_G.

    The velocity is a staircase in the angle: m steps up by 2 wherever
    tan(alpha) crosses mu_s - A / Ntilde + j D (:func:`pair_creep_steps`).
    From rest the critical amplitude is A_c = (mu_s - f) Ntilde; for any
    state, reptation cannot last below (mu_d - f) Ntilde
    (:func:`pair_critical_amplitude`).

    Parameters
    ----------
    amplitude : float or array_like
        A, the amplitude of theta (dimensionless dilation), >= 0.
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float or array_like
        Downhill load per unit normal load, in (0, mu_d); broadcast with ``amplitude``.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient.

    Returns
    -------
    m : numpy.ndarray of int
        Slips per half cycle in the steady state (each slider slips m times per cycle).
    dx : numpy.ndarray
        Advance of x_G per cycle, in l0: m D Ntilde.

    Examples
    --------
    >>> m, dx = pair_creep(0.5e-7, 1e-7, [0.05, 0.15, 0.3, 0.45], 0.6, 0.5)
    >>> m.tolist(), [round(float(v) / 1e-7, 12) for v in dx]
    ([0, 2, 4, 4], [0.0, 0.4, 0.8, 0.8])
    """
    owner = "pair_creep"
    A = check_array(amplitude, "amplitude", owner, ">= 0")
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = check_array(tan_alpha, "tan_alpha", owner)
    for value in np.unique(f):
        _pair_creep_args(value, mu_s, mu_d, owner)
    D = 2.0 * (float(mu_s) - float(mu_d))
    x = A / nt - (float(mu_s) - f)
    m = np.where(x >= 0.0, 2 * np.floor(np.maximum(x, 0.0) / D).astype(np.int64) + 2, 0)
    return m, m * D * nt


def pair_creep_steps(amplitude: float, Ntilde: float, mu_s: float, mu_d: float) -> np.ndarray:
    """The values of tan(alpha) in (0, mu_d) where :func:`pair_creep`'s staircase steps up.

    mu_s - A / Ntilde + j D for j = 0, 1, ... : below the first, no creep;
    above the j-th (j from 0), m = 2 j + 2 slips per half cycle.

    Examples
    --------
    >>> pair_creep_steps(0.6e-7, 1e-7, 0.6, 0.5).round(12).tolist()
    [0.2, 0.4]
    """
    D = 2.0 * (float(mu_s) - float(mu_d))
    first = float(mu_s) - float(amplitude) / float(Ntilde)
    j = np.arange(0, math.ceil((float(mu_d) - first) / D) + 1)
    steps = first + j * D
    return steps[(steps > 0.0) & (steps < float(mu_d))]


def pair_critical_amplitude(Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float) -> tuple[float, float]:
    """The amplitudes of theta below which two sliders on an incline do not creep.

    Returns ``(from_rest, any_state)``:

    * ``from_rest`` = (mu_s - f) Ntilde: starting from rest, no slider
      reaches its threshold below it, and at or above it creep never stops
      (:func:`pair_creep`);
    * ``any_state`` = (mu_d - f) Ntilde: whatever the state, below it the
      peak-to-peak swing 2 A / Ntilde is shorter than the band
      W - D = 2 (mu_d - f) that G must cross between a slip of slider 2
      (which leaves G at least D below U) and one of slider 1, so creep
      stops after at most one stretch of slips. Between the two, whether
      creep lasts depends on the state: every slip is D, so G stays
      congruent to theta modulo D, and a cycle of theta about a mean other
      than the spring's rest value can keep creeping where one from rest
      cannot. Elasticity makes the threshold history-dependent.

    Examples
    --------
    >>> [round(a / 1e-7, 12) for a in pair_critical_amplitude(1e-7, 0.1, 0.6, 0.5)]
    [0.5, 0.4]
    """
    _pair_creep_args(tan_alpha, mu_s, mu_d, "pair_critical_amplitude")
    nt = float(Ntilde)
    return (float(mu_s) - float(tan_alpha)) * nt, (float(mu_d) - float(tan_alpha)) * nt


# Thermal creep of a chain of n sliders on an incline, clean friction
#
# Two sliders have a closed form (above); from three on, the interior
# sliders slip with an overshoot -- an end slip hands D to its neighbour,
# which can then sit above mu_s and slip by 2(|F| - mu_d) / 2, a length that
# depends on f -- and the orbit has no short formula. It is still exact and
# finite: with constant thresholds each slip is an affine map of the forces,
# the choice of which slider slips next is a comparison of affine forms, and
# a symmetric cycle of theta from rest settles into an exactly periodic
# sequence of slips (after at most one cycle for three sliders; from four on
# the transient can be long, and some orbits never repeat: chain_orbit's
# docstring has the numbers). _chain_orbit follows that sequence in
# rational arithmetic, with f and A / Ntilde affine in one parameter p, and
# records every comparison it makes: the set of p where all of them go the
# same way is an interval, on which the steady velocity is one affine
# function of p. That is the derivation of the plateaus (of the slip
# sequence) and of the values and ends of v on each, for any chain.
#
# Units as above: forces in N, theta and lengths in Ntilde (k = 1). The force
# on slider i is F_i = f + s_i - s_{i-1}, with s_e the tension of spring e
# (between sliders e and e + 1); a rise of theta by d theta lengthens every
# rest length and so lowers every tension by d theta; a slip of slider i by
# du = 2 (|F_i| - mu_d) sign(F_i) / deg(i) (the solver's rule, K_ii =
# deg(i) k) moves s_i by -du and s_{i-1} by +du.

class _Affine:
    """The exact affine form ``a + b p`` of one parameter p."""

    __slots__ = ("a", "b")

    def __init__(self, a: Fraction, b: Fraction = Fraction(0)) -> None:
        self.a, self.b = a, b

    def __add__(self, other: _Affine | Fraction) -> _Affine:
        if isinstance(other, _Affine):
            return _Affine(self.a + other.a, self.b + other.b)
        return _Affine(self.a + other, self.b)

    def __sub__(self, other: _Affine | Fraction) -> _Affine:
        if isinstance(other, _Affine):
            return _Affine(self.a - other.a, self.b - other.b)
        return _Affine(self.a - other, self.b)

    def __rsub__(self, other: Fraction) -> _Affine:
        return _Affine(other - self.a, -self.b)

    def __mul__(self, c: Fraction | int) -> _Affine:
        return _Affine(self.a * c, self.b * c)

    def key(self) -> tuple[Fraction, Fraction]:
        return self.a, self.b


class _Window:
    """The values of p around ``p0`` where every comparison made so far comes out the same.

    ``positive(e)`` answers e(p0) > 0 and narrows [lo, hi] to where e keeps
    that sign; a form that vanishes at p0 pins the window to p0 (a tie of
    two events: the orbit on either side differs).
    """

    def __init__(self, p0: Fraction, lo: Fraction, hi: Fraction) -> None:
        self.p0, self.lo, self.hi = p0, lo, hi

    def positive(self, e: _Affine) -> bool:
        value = e.a + e.b * self.p0
        if e.b != 0:
            root = -e.a / e.b
            if value == 0:
                self.lo = self.hi = self.p0
            elif (value > 0) == (e.b > 0):
                self.lo = max(self.lo, root)
            else:
                self.hi = min(self.hi, root)
        return value > 0


def _chain_orbit(n: int, f: _Affine, x: _Affine, mu_s: Fraction, mu_d: Fraction, window: _Window,
                 max_cycles: int) -> tuple[int, int, _Affine, int]:
    """Follow n sliders from rest under theta / Ntilde = 0 -> x -> -x -> 0 -> ... until the cycle repeats.

    Returns (period in cycles, slips per period, advance of x_G per period
    in Ntilde l0, cycles of transient), the last two valid across ``window``.
    """
    zero = _Affine(Fraction(0))
    s = [zero] * (n - 1)
    u = [zero] * n
    theta = zero
    deg = [1 if i in (0, n - 1) else 2 for i in range(n)]

    def force(i: int) -> _Affine:
        F = f
        if i < n - 1:
            F = F + s[i]
        if i > 0:
            F = F - s[i - 1]
        return F

    def slip(i: int, F: _Affine, sign: int) -> None:
        du = (F * sign - mu_d) * Fraction(2 * sign, deg[i])
        u[i] = u[i] + du
        if i < n - 1:
            s[i] = s[i] - du
        if i > 0:
            s[i - 1] = s[i - 1] + du

    def most_overloaded() -> tuple[int, _Affine, int] | None:
        # The solver's avalanche rule: the largest |F_i| / mu_s first, ties to the lowest index.
        best: tuple[int, _Affine, int] | None = None
        for i in range(n):
            F = force(i)
            sign = 1 if window.positive(F) else -1
            if window.positive(F * sign - mu_s) and (
                    best is None or window.positive(F * sign - best[1] * best[2])):
                best = (i, F, sign)
        return best

    def drive(target: _Affine) -> int:
        nonlocal theta, s
        d = 1 if window.positive(target - theta) else -1
        slips = 0
        while True:
            # Only the two ends feel theta: a rise pushes the last slider forward
            # and the first one back (an interior slider's two springs cancel).
            h_best: tuple[_Affine, int, int] | None = None
            for i, sign in ((0, -d), (n - 1, d)):
                F = force(i)
                h = (mu_s - F) if sign > 0 else (F + mu_s)
                if h_best is None or window.positive(h_best[0] - h):
                    h_best = (h, i, sign)
            assert h_best is not None
            h, i, sign = h_best
            if window.positive(h - (target - theta) * d):
                s = [e - (target - theta) for e in s]
                theta = target
                return slips
            s = [e - h * d for e in s]
            theta = theta + h * d
            slip(i, force(i), sign)
            slips += 1
            while (over := most_overloaded()) is not None:
                slip(*over)
                slips += 1

    seen: dict[tuple, int] = {}
    x_G: list[_Affine] = []
    slips_in: list[int] = []
    for cycle in range(max_cycles + 1):
        state = tuple(e.key() for e in s)
        centre = zero
        for ui in u:
            centre = centre + ui
        centre = centre * Fraction(1, n)
        if state in seen:
            first = seen[state]
            return cycle - first, sum(slips_in[first:]), centre - x_G[first], first
        seen[state] = cycle
        x_G.append(centre)
        slips_in.append(drive(x) + drive(zero - x) + drive(zero))
    at = window.p0
    raise OrbitError(f"The creep orbit of {n} sliders did not repeat within max_cycles = {max_cycles} cycles "
                     f"(tan_alpha = {float(f.a + f.b * at)!r}, A / Ntilde = {float(x.a + x.b * at)!r}): "
                     "it may be aperiodic, as some orbits of four sliders and more are; raise max_cycles to look "
                     "further.")


def _chain_args(n_sliders: int, mu_s: float, mu_d: float, owner: str) -> tuple[int, Fraction, Fraction]:
    if isinstance(n_sliders, bool) or not isinstance(n_sliders, (int, np.integer)) or n_sliders < 2:
        raise param_error("n_sliders", owner, "an integer >= 2", n_sliders)
    ms, md = _check_friction(mu_s, mu_d, owner)
    return int(n_sliders), Fraction(ms), Fraction(md)


@dataclasses.dataclass(frozen=True)
class ChainOrbit:
    """The steady creep orbit of a chain from rest (:func:`chain_orbit`).

    Attributes
    ----------
    period : int
        Cycles of theta after which the state at the start of a cycle repeats.
    transient : int
        Cycles before the first cycle of the periodic orbit.
    slips : float
        Slips per cycle in the orbit (all sliders; a mean over the period).
    dx : float
        Advance of x_G per cycle in the orbit, in l0.
    """

    period: int
    transient: int
    slips: float
    dx: float


def _orbit_at(n: int, x: float, f: float, mu_s: Fraction, mu_d: Fraction, max_cycles: int) -> ChainOrbit:
    """The orbit at one point, x = A / Ntilde; dx in Ntilde l0."""
    window = _Window(Fraction(0), Fraction(0), Fraction(0))
    period, count, advance, transient = _chain_orbit(n, _Affine(Fraction(f)), _Affine(Fraction(x)), mu_s, mu_d,
                                                     window, max_cycles)
    return ChainOrbit(period, transient, count / period, float(advance.a / period))


def chain_orbit(n_sliders: int, amplitude: float, Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float, *,
                max_cycles: int = 200) -> ChainOrbit:
    """The steady creep orbit of a chain with constant thresholds at one point: period, transient, velocity.

    As :func:`chain_creep` at one (amplitude, tan_alpha), with the orbit's
    period and transient. For three sliders at generic parameters the
    orbit repeats after at most one cycle, with a period of one cycle (300
    random parameter sets, ``benchmarks/creep_orbit_periods.py``); at an
    exact tie of two events the period can be longer (22 cycles at
    A = 0.75 Ntilde, f = 0.171875, mu_s = 0.59375, mu_d = 0.34375, all exact
    in binary).
    From four sliders on the orbits are richer: of 300 random sets of four
    sliders, 54 did not repeat within 200 cycles, and the others had
    periods of up to 39 cycles after transients of up to 170.

    Parameters
    ----------
    n_sliders : int
        Sliders in the chain, >= 2.
    amplitude : float
        A, the amplitude of theta (dimensionless dilation), >= 0.
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float
        Downhill load per unit normal load, in (0, mu_d).
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient, mu_s > mu_d > 0.
    max_cycles : int
        Cycles to follow before giving up on a repeat.

    Returns
    -------
    ChainOrbit

    Raises
    ------
    OrbitError
        The state did not repeat within ``max_cycles`` cycles.

    Examples
    --------
    >>> orbit = chain_orbit(3, 0.55e-7, 1e-7, 0.22, 0.6, 0.5)
    >>> orbit.period, orbit.transient, orbit.slips, round(orbit.dx / 1e-7, 12)
    (1, 1, 6.0, 0.56)
    """
    owner = "chain_orbit"
    n, ms, md = _chain_args(n_sliders, mu_s, mu_d, owner)
    A = check_scalar(amplitude, "amplitude", owner, ">= 0")
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = _check_tan(tan_alpha, float(md), owner)
    orbit = _orbit_at(n, A / nt, f, ms, md, max_cycles)
    return dataclasses.replace(orbit, dx=orbit.dx * nt)


def chain_creep(n_sliders: int, amplitude: ArrayLike, Ntilde: float, tan_alpha: ArrayLike, mu_s: float,
                mu_d: float, *, max_cycles: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Steady creep of a chain of sliders with constant thresholds under a symmetric cycle of theta (exact).

    The chain starts at rest at theta = 0; theta rises to +A, falls to -A
    and so on (the ``sinusoidal`` driver with phase 0 and a period that is
    a multiple of 4 tau_th). Every slider carries f = tan(alpha) downhill
    and slips by the solver's rule (docs/model.md). The orbit is followed
    slip by slip in rational arithmetic until the state at the start of a
    cycle repeats (:func:`chain_orbit`, which gives the period and the
    transient too). For two sliders this is :func:`pair_creep`. Where the
    orbit does not repeat within ``max_cycles`` (some orbits of four sliders
    and more never do), the result is NaN, with a ``RuntimeWarning``.

    Parameters
    ----------
    n_sliders : int
        Sliders in the chain, >= 2.
    amplitude : float or array_like
        A, the amplitude of theta (dimensionless dilation), >= 0.
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float or array_like
        Downhill load per unit normal load, in (0, mu_d); broadcast with ``amplitude``.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient, mu_s > mu_d > 0.
    max_cycles : int
        Cycles to follow before giving up on a repeat.

    Returns
    -------
    slips : numpy.ndarray of float, broadcast shape
        Slips per cycle in the steady state (all sliders together; a mean
        over the period when it is longer than one cycle).
    dx : numpy.ndarray of float, broadcast shape
        Advance of x_G per cycle in the steady state, in l0.

    Notes
    -----
    The inputs are taken as the exact binary numbers they are. Where two
    events tie (the ends of :func:`chain_creep_segments`), the orbit follows
    the solver's rules in exact arithmetic (``|F| = mu_s`` sticks; equal
    overloads go to the lowest index), but the solver's floating-point
    forces can break such a tie either way: compare inside a segment.

    Examples
    --------
    Three sliders at A = 0.55 Ntilde: at tan(alpha) = 0.12 the two ends slip
    back and forth and the chain stays put; at 0.22 and 0.26, six slips per
    cycle advance it by 2 (mu_d - f) Ntilde (docs/guides/incline-creep.md
    derives it):

    >>> slips, dx = chain_creep(3, 0.55e-7, 1e-7, [0.12, 0.22, 0.26], 0.6, 0.5)
    >>> slips.tolist(), [round(float(v) / 1e-7, 12) for v in dx]
    ([4.0, 6.0, 6.0], [0.0, 0.56, 0.48])
    """
    owner = "chain_creep"
    n, ms, md = _chain_args(n_sliders, mu_s, mu_d, owner)
    A = check_array(amplitude, "amplitude", owner, ">= 0")
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = check_array(tan_alpha, "tan_alpha", owner)
    A, f = np.broadcast_arrays(A, f)
    for value in np.unique(f):
        _check_tan(value, float(md), owner)
    slips = np.zeros(A.shape)
    dx = np.zeros(A.shape)
    aperiodic = 0
    for idx in np.ndindex(A.shape):
        try:
            orbit = _orbit_at(n, float(A[idx]) / nt, float(f[idx]), ms, md, max_cycles)
        except OrbitError:
            aperiodic += 1
            slips[idx] = dx[idx] = np.nan
            continue
        slips[idx] = orbit.slips
        dx[idx] = orbit.dx * nt
    if aperiodic:
        warnings.warn(f"chain_creep: the orbit of {n} sliders did not repeat within max_cycles = {max_cycles} "
                      f"at {aperiodic} of {A.size} points (NaN there); it may be aperiodic, as some orbits of "
                      "four sliders and more are.", RuntimeWarning, stacklevel=2)
    return slips, dx


@dataclasses.dataclass(frozen=True)
class CreepSegment:
    """An interval of one parameter on which a chain's steady cycle is one sequence of slips.

    On it the advance of x_G per cycle is affine in the parameter:
    ``dx = dx_lo + (p - lo) * (dx_hi - dx_lo) / (hi - lo)``.

    Attributes
    ----------
    over : str
        The parameter: ``"tan_alpha"`` or ``"amplitude"``.
    lo, hi : float
        The ends of the interval (amplitude in the units of theta); the
        orbit at the ends themselves may belong to the neighbouring segment.
    period : int
        Cycles of theta per period of the steady orbit.
    slips : float
        Slips per cycle (all sliders), a mean over the period.
    dx_lo, dx_hi : float
        Advance of x_G per cycle at ``lo`` and at ``hi``, in l0 (the limits from inside).
    """

    over: str
    lo: float
    hi: float
    period: int
    slips: float
    dx_lo: float
    dx_hi: float


def chain_creep_segments(n_sliders: int, Ntilde: float, mu_s: float, mu_d: float, *,
                         tan_alpha: float | tuple[float, float], amplitude: float | tuple[float, float],
                         resolution: float = 1e-9, max_cycles: int = 200) -> list[CreepSegment]:
    """The plateaus of a chain's creep along tan(alpha) or along the amplitude, with their exact ends.

    Exactly one of ``tan_alpha`` and ``amplitude`` is a ``(lo, hi)`` range.
    The range is cut into the intervals on which the steady cycle (from
    rest, as in :func:`chain_creep`) is one fixed sequence of slips; on each
    the velocity is affine in the parameter, and the ends are the exact
    values where two events tie. Along the amplitude the velocity is
    constant on each interval (a staircase); along the angle, for three
    sliders and more, it is not: an interior slider's overshoot grows with f.
    Consecutive intervals with the same slips and the same affine velocity
    are merged.

    Parameters
    ----------
    n_sliders : int
        Sliders in the chain, >= 2.
    Ntilde : float
        N / (k l0), > 0.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient, mu_s > mu_d > 0.
    tan_alpha, amplitude : float or (float, float)
        The fixed value of one and the range of the other (tan(alpha) within
        (0, mu_d); the amplitude of theta, dimensionless, >= 0).
    resolution : float
        Each interval is entered this far (relative to the range) past the
        end of the previous one: a segment narrower than that can be missed.
    max_cycles : int
        Cycles to follow before giving up on a repeat.

    Returns
    -------
    list of CreepSegment
        In increasing order, covering the range.

    Examples
    --------
    Two sliders: the staircase of :func:`pair_creep`, steps at mu_s - A / Ntilde + j D.

    >>> for seg in chain_creep_segments(2, 1e-7, 0.6, 0.5, tan_alpha=(0.01, 0.49), amplitude=0.55e-7):
    ...     print(f"{seg.lo:.3f} {seg.hi:.3f} {seg.slips:g} {seg.dx_lo / 1e-7:.3f} {seg.dx_hi / 1e-7:.3f}")
    0.010 0.050 0 0.000 0.000
    0.050 0.250 4 0.400 0.400
    0.250 0.450 8 0.800 0.800
    0.450 0.490 12 1.200 1.200

    Three sliders at tan(alpha) = 0.22: no creep below a critical
    amplitude, then a staircase in the amplitude:

    >>> for seg in chain_creep_segments(3, 1e-7, 0.6, 0.5, tan_alpha=0.22, amplitude=(0.0, 0.95e-7)):
    ...     print(f"{seg.lo / 1e-7:.2f} {seg.hi / 1e-7:.2f} {seg.slips:g} {seg.dx_lo / 1e-7:.3f}")
    0.00 0.46 0 0.000
    0.46 0.66 6 0.560
    0.66 0.82 12 1.120
    0.82 0.86 18 1.680
    0.86 0.95 24 2.240
    """
    owner = "chain_creep_segments"
    n, ms, md = _chain_args(n_sliders, mu_s, mu_d, owner)
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    ranged = [name for name, value in (("tan_alpha", tan_alpha), ("amplitude", amplitude))
              if isinstance(value, (tuple, list))]
    if len(ranged) != 1:
        raise ConfigError(f"Exactly one of 'tan_alpha' and 'amplitude' of {owner} must be a (lo, hi) range. "
                          f"Got tan_alpha={tan_alpha!r} and amplitude={amplitude!r} instead.")
    over = ranged[0]
    lo_f, hi_f = (float(v) for v in (tan_alpha if over == "tan_alpha" else amplitude))  # type: ignore[union-attr]
    if not (math.isfinite(lo_f) and math.isfinite(hi_f) and lo_f < hi_f):
        raise param_error(over, owner, "a range (lo, hi) with lo < hi", (lo_f, hi_f))
    if not 0.0 < float(resolution) < 1.0:
        raise param_error("resolution", owner, "in (0, 1)", resolution)
    unit = Fraction(1)
    if over == "tan_alpha":
        _check_tan(lo_f, float(md), owner)
        _check_tan(hi_f, float(md), owner)
        A = check_scalar(amplitude, "amplitude", owner, ">= 0")
        x = _Affine(Fraction(A / nt))
        f = _Affine(Fraction(0), Fraction(1))
        lo, hi = Fraction(lo_f), Fraction(hi_f)
    else:
        check_scalar(lo_f, "amplitude", owner, ">= 0")
        f = _Affine(Fraction(_check_tan(tan_alpha, float(md), owner)))  # type: ignore[arg-type]
        x = _Affine(Fraction(0), Fraction(1))
        unit = Fraction(nt)
        lo, hi = Fraction(lo_f / nt), Fraction(hi_f / nt)
    step = (hi - lo) * Fraction(float(resolution))
    # (lo, hi, period, slips, a, b): x_G advances (a + b p) Ntilde l0 per cycle on [lo, hi], exactly.
    exact: list[tuple[Fraction, Fraction, int, Fraction, Fraction, Fraction]] = []
    start = lo
    while start < hi:
        if exact and hi - start < step:
            # A sliver narrower than the resolution at the range's end: the last segment takes it.
            exact[-1] = (*exact[-1][:1], hi, *exact[-1][2:])
            break
        window = _Window(start + step, lo, hi)
        period, count, advance, _ = _chain_orbit(n, f, x, ms, md, window, max_cycles)
        end = window.hi if window.hi > start else start + step
        seg = (start, end, period, Fraction(count, period), advance.a / period, advance.b / period)
        if exact and exact[-1][2:] == seg[2:]:
            seg = (exact.pop()[0], *seg[1:])
        exact.append(seg)
        start = end
    return [CreepSegment(over, float(s * unit), float(e * unit), period, float(slips), float((a + b * s) * nt),
                         float((a + b * e) * nt)) for s, e, period, slips, a, b in exact]


def chain_critical_amplitude(n_sliders: int, Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float, *,
                             amplitude_max: float, resolution: float = 1e-9) -> float:
    """The amplitude of theta from which a chain at rest starts to creep for good, with constant thresholds.

    The lower end of the first segment of :func:`chain_creep_segments`
    (along the amplitude, up to ``amplitude_max``) with a positive velocity;
    below it the steady velocity is zero. For two sliders it is
    (mu_s - f) Ntilde (:func:`pair_critical_amplitude`). NaN if the chain does
    not creep below ``amplitude_max``.

    Examples
    --------
    >>> round(chain_critical_amplitude(2, 1e-7, 0.2, 0.6, 0.5, amplitude_max=2e-7) / 1e-7, 12)
    0.4
    >>> round(chain_critical_amplitude(3, 1e-7, 0.2, 0.6, 0.5, amplitude_max=2e-7) / 1e-7, 12)
    0.6
    """
    segments = chain_creep_segments(n_sliders, Ntilde, mu_s, mu_d, tan_alpha=tan_alpha,
                                    amplitude=(0.0, float(amplitude_max)), resolution=resolution)
    for seg in segments:
        if seg.dx_lo > 0 or seg.dx_hi > 0:
            return seg.lo
    return math.nan


def three_slider_onset(Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float) -> tuple[float, float, float]:
    """Closed form of three sliders' first creeping plateau from rest, with constant thresholds.

    With f = tan(alpha) and D = 2 (mu_s - mu_d), for
    max(mu_s - 2 D, mu_d / 2 - D / 4) < f < 3 mu_d - 2 mu_s
    (docs/guides/incline-creep.md derives it):

    * the critical amplitude from rest is A_c = (3 mu_d - mu_s - 2 f) Ntilde:
      the first fall of theta must bring the uphill end to its threshold
      twice, once to push the middle slider over and once more after it;
    * from A_c up to A_c + D Ntilde each half cycle is three slips (an end
      by D, the middle with an overshoot, the same end again) and x_G
      advances by 2 (mu_d - f) Ntilde per cycle, whatever the amplitude.

    :func:`chain_creep_segments` finds the same numbers from the exact
    orbit, and the rest of the plateaus with them.

    Parameters
    ----------
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float
        Downhill load per unit normal load, inside the window above.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient.

    Returns
    -------
    A_c, A_next : float
        The amplitudes of theta where the plateau begins and ends.
    dx : float
        Advance of x_G per cycle on the plateau, in l0.

    Examples
    --------
    >>> [round(v / 1e-7, 12) for v in three_slider_onset(1e-7, 0.22, 0.6, 0.5)]
    [0.46, 0.66, 0.56]
    """
    owner = "three_slider_onset"
    ms, md = _check_friction(mu_s, mu_d, owner)
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = check_scalar(tan_alpha, "tan_alpha", owner)
    D = 2.0 * (ms - md)
    lo, hi = max(ms - 2.0 * D, md / 2.0 - D / 4.0), 3.0 * md - 2.0 * ms
    if not lo < f < hi:
        raise param_error("tan_alpha", owner, f"in ({lo!r}, {hi!r}), where the closed form holds", tan_alpha)
    A_c = (3.0 * md - ms - 2.0 * f) * nt
    return A_c, A_c + D * nt, 2.0 * (md - f) * nt
