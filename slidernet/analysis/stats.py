"""Inference for a study of trends: what the per-realization slopes of :mod:`slidernet.analysis.trend` allow one
to say, and with what error.

Realizations of one network geometry share its quenched disorder, so a
study's independent units are the geometries (:func:`~slidernet.analysis.trend.grouped_mean_sem`).
This module answers the questions such a study asks of its slopes:

- :func:`variance_components`: how much of the spread is between geometries
  and how much within one (one-way random effects), with intervals, and what
  error another design (more geometries, more realizations each) would give;
- :func:`meta_regression`: one fit of the slopes of every size against a
  function of the size (a + b ln N, say), each size weighted by its own error
  plus a between-size variance tau^2 (random effects): one test of a trend in
  N instead of one test per size;
- :func:`equivalence_test` and :func:`minimum_detectable_effect`: an absence
  claimed against a margin declared before the data (two one-sided tests),
  and the smallest effect a "not resolved" could have missed;
- :func:`fdr_family`: the q-values of a whole family of slopes
  (Benjamini-Hochberg, or Benjamini-Yekutieli without assumptions), each
  slope named.

Errors are Student-t where a variance is estimated from few units; each
function says what it assumes. References: Searle, Casella & McCulloch,
*Variance Components* (1992); Burdick & Graybill, *Confidence Intervals on
Variance Components* (1992); Thomas & Hultquist, Ann. Stat. 6, 582 (1978);
DerSimonian & Laird, Control. Clin. Trials 7, 177 (1986); Viechtbauer, J.
Educ. Behav. Stat. 30, 261 (2005); Knapp & Hartung, Stat. Med. 22, 2693
(2003); Schuirmann, J. Pharmacokinet. Biopharm. 15, 657 (1987); Benjamini &
Hochberg, J. R. Stat. Soc. B 57, 289 (1995); Benjamini & Yekutieli, Ann.
Stat. 29, 1165 (2001).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

from slidernet._validation import check_array, check_scalar
from slidernet.errors import ConfigError, param_error


def _one_shape(owner: str, what: str, **arrays: ArrayLike) -> list[np.ndarray]:
    """The ``arrays`` as numpy arrays, refused unless they share one 1-D shape."""
    out = [np.asarray(a) for a in arrays.values()]
    shapes = [a.shape for a in out]
    if len(set(shapes)) != 1 or out[0].ndim != 1:
        names = ", ".join(arrays)
        names = " and ".join(names.rsplit(", ", 1))
        raise ConfigError(f"{owner} needs {names} of one shape ({what},); got {' and '.join(map(str, shapes))}.")
    return out


# Variance components.


@dataclass(frozen=True)
class VarianceComponents:
    """The spread of a per-realization quantity split between geometries and within them.

    Attributes
    ----------
    between, within : float
        sigma_b^2 (between geometries, >= 0) and sigma_w^2 (between
        realizations of one geometry), in the squared unit of the values.
    icc : float
        sigma_b^2 / (sigma_b^2 + sigma_w^2), the share of the spread that is
        the geometry's (the intraclass correlation).
    between_ci, within_ci, icc_ci : tuple of float
        Their intervals at ``confidence``.
    confidence : float
    grand_mean, grand_mean_sem : float
        The mean of the geometries' means and the standard error the
        components imply for it, sqrt((between + within / n_h) / G).
    groups, values : int
        G geometries and N values (finite ones).
    per_group : float
        n_h, the harmonic mean of the realizations per geometry.
    balanced : bool
        Whether every geometry has as many values.
    ms_between, ms_within : float
        The mean squares n_h var(geometry means) and the pooled within one.
    dof_between, dof_within : int
        G - 1 and N - G.
    """

    between: float
    within: float
    icc: float
    between_ci: tuple[float, float]
    within_ci: tuple[float, float]
    icc_ci: tuple[float, float]
    confidence: float
    grand_mean: float
    grand_mean_sem: float
    groups: int
    values: int
    per_group: float
    balanced: bool
    ms_between: float
    ms_within: float
    dof_between: int
    dof_within: int

    def sem(self, groups: int, per_group: float) -> float:
        """The standard error of the grand mean that ``groups`` geometries of ``per_group`` realizations each
        would give, by these components: sqrt((between + within / per_group) / groups)."""
        groups = check_scalar(groups, "groups", "VarianceComponents.sem", ">= 1")
        per_group = check_scalar(per_group, "per_group", "VarianceComponents.sem", ">= 1")
        return math.sqrt((self.between + self.within / per_group) / groups)


def variance_components(values: ArrayLike, groups: ArrayLike, *, confidence: float = 0.95) -> VarianceComponents:
    """Between- and within-geometry variances of a per-realization quantity (one-way random effects).

    The model: the value of realization j of geometry g is
    y_gj = m + a_g + e_gj, with a_g ~ N(0, sigma_b^2) the geometry's own
    offset and e_gj ~ N(0, sigma_w^2) independent of it and of each other.
    With G geometries of n_g finite values each (N in all):

    - sigma_w^2 = MS_w, the pooled within-geometry variance, on N - G dof;
      its interval (N - G) MS_w / chi2 is exact;
    - sigma_b^2 = max(0, var(geometry means) - MS_w / n_h), n_h the harmonic
      mean of the n_g: var(geometry means) estimates sigma_b^2 + sigma_w^2 / n_h,
      balanced or not. Balanced, this is the ANOVA estimator
      (MS_b - MS_w) / n with MS_b = n var(geometry means). Its interval is
      the modified large-sample one (Graybill & Wang; Burdick & Graybill
      1992, sec. 3.4): no exact interval exists; its coverage is close to
      nominal (tested at 8 geometries, ICC 1/3, balanced and not);
    - the ICC sigma_b^2 / (sigma_b^2 + sigma_w^2) and its interval from
      F = MS_b / MS_w, exact when balanced (Searle 1971).

    Unbalanced tables use the unweighted-means mean square
    MS_b = n_h var(geometry means), which is approximately
    (sigma_w^2 + n_h sigma_b^2) chi2(G - 1) / (G - 1) (Thomas & Hultquist
    1978): the intervals are then approximate (the ICC's coverage with
    2 to 6 realizations per geometry is tested). A negative estimate of
    sigma_b^2 is set to 0 and its interval's ends are clipped at 0.

    The grand mean is the mean of the geometries' means, as in
    :func:`~slidernet.analysis.trend.grouped_mean_sem`; the standard error
    the components imply for it, sqrt((sigma_b^2 + sigma_w^2 / n_h) / G), is
    that function's when sigma_b^2 > 0, and larger when sigma_b^2 is set to 0.

    Parameters
    ----------
    values : array_like, shape (R,)
        One value per realization, in any unit (NaN: left out).
    groups : array_like, shape (R,)
        The geometry of each realization (the network seed).
    confidence : float
        Of the intervals, in (0, 1).

    Returns
    -------
    VarianceComponents

    Raises
    ------
    ConfigError
        If the shapes differ, fewer than two geometries have a finite value, or no geometry has two
        (no within spread to estimate).

    Examples
    --------
    Three geometries of two realizations: means 2, 5 and 9, within spread 4:

    >>> out = variance_components([1, 3, 4, 6, 7, 11], [0, 0, 1, 1, 2, 2])
    >>> out.within, round(out.between, 4), round(out.icc, 4)
    (4.0, 10.3333, 0.7209)
    >>> [round(x, 2) for x in out.within_ci]
    [1.28, 55.61]
    >>> round(out.sem(16, 4), 4)   # with 16 geometries of 4 realizations
    0.8416
    """
    owner = "variance_components"
    confidence = check_scalar(confidence, "confidence", owner, "in (0, 1)")
    v, g = _one_shape(owner, "R", values=values, groups=groups)
    v = v.astype(np.float64)
    finite = np.isfinite(v)
    members = [v[finite & (g == key)] for key in np.unique(g[finite])]
    G = len(members)
    if G < 2:
        raise ConfigError(f"{owner} needs two geometries or more with finite values; got {G}.")
    sizes = np.array([m.size for m in members])
    N = int(sizes.sum())
    if N == G:
        raise ConfigError(f"{owner} needs a geometry with two finite values or more (a within spread); got one "
                          "value in each.")
    means = np.array([m.mean() for m in members])
    ms_within = float(sum(((m - m.mean()) ** 2).sum() for m in members) / (N - G))
    n_h = float(G / np.sum(1.0 / sizes))
    spread = float(means.var(ddof=1))                    # estimates sigma_b^2 + sigma_w^2 / n_h
    ms_between = n_h * spread
    between = max(spread - ms_within / n_h, 0.0)
    total = between + ms_within
    icc = between / total if total > 0 else math.nan

    n1, n2 = G - 1, N - G
    q = _quantiles(n1, n2, (1.0 - confidence) / 2.0)
    within_ci = (n2 * ms_within / q.chi2_2[1], n2 * ms_within / q.chi2_2[0])
    lo, hi = _mls_difference(ms_between, n1, ms_within, n2, q)
    between_ci = (max(lo / n_h, 0.0), max(hi / n_h, 0.0))
    if ms_within > 0:
        ratio = ms_between / ms_within
        f_lo, f_hi = ratio / q.f[1], ratio / q.f[0]
        icc_ci = (min(max((f_lo - 1.0) / (f_lo + n_h - 1.0), 0.0), 1.0),
                  min(max((f_hi - 1.0) / (f_hi + n_h - 1.0), 0.0), 1.0))
    else:                                                # no within spread: all of it is the geometry's
        icc_ci = (1.0, 1.0) if ms_between > 0 else (math.nan, math.nan)
    return VarianceComponents(
        between=between, within=ms_within, icc=icc, between_ci=between_ci, within_ci=within_ci, icc_ci=icc_ci,
        confidence=confidence, grand_mean=float(means.mean()),
        grand_mean_sem=math.sqrt((between + ms_within / n_h) / G), groups=G, values=N, per_group=n_h,
        balanced=bool((sizes == sizes[0]).all()), ms_between=ms_between, ms_within=ms_within, dof_between=n1,
        dof_within=n2)


@dataclass(frozen=True)
class _Quantiles:
    """The (tail, 1 - tail) quantiles of chi2(n1), chi2(n2) and F(n1, n2)."""

    chi2_1: tuple[float, float]
    chi2_2: tuple[float, float]
    f: tuple[float, float]


@functools.lru_cache(maxsize=256)
def _quantiles(n1: int, n2: int, tail: float) -> _Quantiles:
    """The quantiles of one design, once: a study asks them of every quantity it splits (scipy's are slow)."""
    ends = np.array([tail, 1.0 - tail])
    return _Quantiles(chi2_1=tuple(map(float, stats.chi2.ppf(ends, n1))),
                      chi2_2=tuple(map(float, stats.chi2.ppf(ends, n2))),
                      f=tuple(map(float, stats.f.ppf(ends, n1, n2))))


def _mls_difference(s1: float, n1: int, s2: float, n2: int, q: _Quantiles) -> tuple[float, float]:
    """The modified large-sample interval of E[s1] - E[s2] from independent mean squares s1 (n1 dof) and s2
    (n2 dof), each end with probability ``tail`` of ``q`` outside (Ting, Burdick & Graybill 1990; Burdick &
    Graybill 1992, eqs. 3.11-3.12). Without s2 it is the exact chi-square interval of s1."""
    g1, h1 = 1.0 - n1 / q.chi2_1[1], n1 / q.chi2_1[0] - 1.0
    g2, h2 = 1.0 - n2 / q.chi2_2[1], n2 / q.chi2_2[0] - 1.0
    f_lo, f_hi = q.f
    g12 = ((f_hi - 1.0) ** 2 - g1**2 * f_hi**2 - h2**2) / f_hi
    h12 = ((1.0 - f_lo) ** 2 - h1**2 * f_lo**2 - g2**2) / f_lo
    v_lo = g1**2 * s1**2 + h2**2 * s2**2 + g12 * s1 * s2
    v_hi = h1**2 * s1**2 + g2**2 * s2**2 + h12 * s1 * s2
    return s1 - s2 - math.sqrt(max(v_lo, 0.0)), s1 - s2 + math.sqrt(max(v_hi, 0.0))


# A slope against the size: random-effects meta-regression.


@dataclass(frozen=True)
class MetaRegression:
    """A random-effects fit of estimates y_i = a + b x_i + u_i + e_i (u_i ~ N(0, tau^2), e_i ~ N(0, s_i^2)).

    Attributes
    ----------
    coef, coef_sem, coef_p : numpy.ndarray, shape (p,)
        (a,) or (a, b), their standard errors and two-sided p-values of 0.
    dof : float
        Of the coefficients' test: K - p (``test="t"``) or inf (``"z"``).
    cov : numpy.ndarray, shape (p, p)
        The coefficients' covariance.
    tau2 : float
        The between-estimate variance beyond the s_i^2, >= 0.
    q, q_dof, q_p : float, int, float
        Cochran's residual Q = sum (y_i - fitted_i)^2 / s_i^2 at the
        fixed-effect fit, K - p, and its chi-square p-value (of tau^2 = 0).
    i2 : float
        The share of the spread beyond the s_i: tau^2 / (tau^2 + s~^2), s~^2
        the typical s_i^2 (Higgins & Thompson), in [0, 1).
    fitted, fitted_sem : numpy.ndarray, shape (K,)
        The fit at each x_i and its standard error (of the mean line, tau^2
        not added).
    method, test : str
    """

    coef: np.ndarray
    coef_sem: np.ndarray
    coef_p: np.ndarray
    dof: float
    cov: np.ndarray
    tau2: float
    q: float
    q_dof: int
    q_p: float
    i2: float
    fitted: np.ndarray
    fitted_sem: np.ndarray
    method: str
    test: str

    def predict(self, x: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The fitted line at ``x`` (shape (M,)) and its standard error; an intercept-only fit is its mean at
        every x. Add tau2 to the squared error for the spread of a new estimate."""
        x = np.atleast_1d(np.asarray(x, dtype=np.float64))
        X = _design(x, len(self.coef))
        return X @ self.coef, np.sqrt(np.einsum("ij,jk,ik->i", X, self.cov, X))


def _design(x: np.ndarray, p: int) -> np.ndarray:
    """The rows (1, x_i), or (1,) for an intercept-only fit."""
    return np.column_stack([np.ones_like(x), x][:p])


def _weighted_fit(y: np.ndarray, X: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weighted least squares: the coefficients, (X'WX)^-1 and the projection P = W - W X (X'WX)^-1 X' W
    (P y are the weighted residuals)."""
    inv = np.linalg.inv(X.T @ (w[:, None] * X))
    beta = inv @ (X.T @ (w * y))
    WX = w[:, None] * X
    return beta, inv, np.diag(w) - WX @ inv @ WX.T


def _tau2_reml(y: np.ndarray, X: np.ndarray, s2: np.ndarray, start: float) -> float:
    """The REML estimate of tau^2 >= 0 by Fisher scoring (Viechtbauer 2005, eq. 12), from ``start``."""
    tau2, scale = start, float(s2.mean())
    for _ in range(1000):
        _, _, P = _weighted_fit(y, X, 1.0 / (s2 + tau2))
        Py = P @ y
        step = (Py @ Py - np.trace(P)) / np.sum(P * P.T)
        new = max(tau2 + step, 0.0)
        if abs(new - tau2) <= 1e-8 * max(new, scale):
            return new
        tau2 = new
    return tau2   # pragma: no cover - scoring from the DerSimonian-Laird value converges in a few steps


def meta_regression(estimates: ArrayLike, sems: ArrayLike, x: ArrayLike | None = None, *, method: str = "REML",
                    test: str = "t") -> MetaRegression:
    """One fit of estimates with their errors against a covariate, with a between-estimate variance: slope(N).

    Each size N_i brings an estimate y_i (a slope, two-level over its
    geometries) and its standard error s_i. The model is
    y_i = a + b x_i + u_i + e_i: x_i a function of the size chosen by the
    caller (ln N, N^-1/2, ...), e_i ~ N(0, s_i^2) the estimate's own error
    (s_i taken as known), u_i ~ N(0, tau^2) what the line leaves over
    (heterogeneity). Without ``x`` the fit is the random-effects mean a.

    tau^2 is estimated by REML (Fisher scoring from the DerSimonian-Laird
    value, truncated at 0) or by DerSimonian-Laird's moments,
    tau^2 = max(0, (Q - (K - p)) / tr P); the coefficients are then weighted
    least squares with weights 1 / (s_i^2 + tau^2). The test of the
    coefficients is Knapp-Hartung's (``test="t"``): their covariance
    (X'WX)^-1 scaled by sum w_i r_i^2 / (K - p) and Student-t with K - p
    dof, which allows for the error of tau^2 and keeps its level with few
    sizes (tested with 7); ``"z"`` takes (X'WX)^-1 as exact and the normal
    law.
    With equal s_i and ``test="t"`` the fit is ordinary least squares, its
    errors included.

    What it assumes: independent estimates (sizes measured on separate
    realizations), normal errors, and s_i known. An s_i from G = 8
    geometries is itself uncertain by about 1/sqrt(2 (G - 1)) = 27 %; the
    Knapp-Hartung scale absorbs a common misestimate, not one size's.

    Parameters
    ----------
    estimates, sems : array_like, shape (K,)
        The estimates and their standard errors (> 0), in one unit.
    x : array_like, shape (K,), optional
        The covariate (ln N, say); at least two distinct values. Default:
        none, an intercept-only fit.
    method : {"REML", "DL"}
        The estimator of tau^2.
    test : {"t", "z"}
        Knapp-Hartung's t test, or the z test.

    Returns
    -------
    MetaRegression

    Raises
    ------
    ConfigError
        If the shapes differ, an error is not > 0 or a value not finite, x takes a single value,
        K is not above the number of coefficients, or ``method`` or ``test`` is unknown.

    Examples
    --------
    Slopes of five sizes, falling with ln N, with their errors:

    >>> N = np.array([2, 16, 64, 256, 1024])
    >>> out = meta_regression([0.040, 0.010, 0.012, -0.003, 0.002], [0.004, 0.003, 0.003, 0.002, 0.002],
    ...                       np.log(N))
    >>> out.coef.round(4).tolist(), out.coef_sem.round(4).tolist(), out.dof
    ([0.036, -0.006], [0.0087, 0.0019], 3)
    >>> round(float(out.coef_p[1]), 3), f"{out.tau2:.1e}", round(out.q, 1)
    (0.05, '7.2e-05', 33.6)
    """
    owner = "meta_regression"
    if method not in ("REML", "DL"):
        raise param_error("method", owner, "'REML' or 'DL'", method)
    if test not in ("t", "z"):
        raise param_error("test", owner, "'t' or 'z'", test)
    arrays = {"estimates": estimates, "sems": sems} | ({} if x is None else {"x": x})
    y, s, *rest = _one_shape(owner, "K", **arrays)
    y = check_array(y, "estimates", owner)
    s = check_array(s, "sems", owner, "> 0")
    p = 1 if x is None else 2
    if x is not None:
        xs = check_array(rest[0], "x", owner)
        if np.ptp(xs) == 0:
            raise ConfigError(f"{owner}: x takes a single value ({xs[0]!r}); a slope against it cannot be fitted.")
    else:
        xs = np.zeros_like(y)
    K = y.size
    if K <= p:
        raise ConfigError(f"{owner} needs more estimates ({K}) than coefficients ({p}): the heterogeneity needs "
                          "what the line leaves over.")
    X = _design(xs, p)
    s2 = s**2

    # The fixed-effect fit: Cochran's Q and the DerSimonian-Laird tau^2.
    _, _, P0 = _weighted_fit(y, X, 1.0 / s2)
    q = float(y @ P0 @ y)
    trace0 = float(np.trace(P0))
    tau2 = max((q - (K - p)) / trace0, 0.0)
    if method == "REML":
        tau2 = _tau2_reml(y, X, s2, tau2)

    w = 1.0 / (s2 + tau2)
    beta, inv, _ = _weighted_fit(y, X, w)
    dof: float
    if test == "t":
        residuals = y - X @ beta
        cov, dof = inv * float(w @ residuals**2) / (K - p), K - p
    else:
        cov, dof = inv, math.inf
    sem = np.sqrt(np.diag(cov))
    with np.errstate(divide="ignore", invalid="ignore"):
        coef_p = 2.0 * stats.t.sf(np.abs(beta / sem), dof)
    typical = (K - p) / trace0
    return MetaRegression(
        coef=beta, coef_sem=sem, coef_p=coef_p, dof=dof, cov=cov, tau2=tau2, q=q,
        q_dof=K - p, q_p=float(stats.chi2.sf(q, K - p)), i2=tau2 / (tau2 + typical), fitted=X @ beta,
        fitted_sem=np.sqrt(np.einsum("ij,jk,ik->i", X, cov, X)), method=method, test=test)


# Absence claims: equivalence to a margin, and the smallest effect a test would have seen.


@dataclass(frozen=True)
class Equivalence:
    """Two one-sided tests of an estimate against a margin (low, high).

    Attributes
    ----------
    estimate, sem, dof : float
    margin : tuple of float
        (low, high), in the estimate's unit.
    p_lower, p_upper : float
        The p-values of "theta <= low" and "theta >= high".
    p : float
        max(p_lower, p_upper), the p-value of non-equivalence.
    equivalent : bool
        p < alpha: both nulls rejected, theta within the margin.
    ci : tuple of float
        The (1 - 2 alpha) interval estimate -+ t_{1-alpha} sem; equivalent
        if and only if it lies inside the margin.
    alpha : float
    """

    estimate: float
    sem: float
    dof: float
    margin: tuple[float, float]
    p_lower: float
    p_upper: float
    p: float
    equivalent: bool
    ci: tuple[float, float]
    alpha: float


def _dof(dof: float, owner: str) -> float:
    """Degrees of freedom: > 0, or inf for a normal law."""
    return math.inf if dof == math.inf else check_scalar(dof, "dof", owner, "> 0")


def equivalence_test(estimate: float, sem: float, dof: float, margin: float | tuple[float, float], *,
                     alpha: float = 0.05) -> Equivalence:
    """Whether an estimate is within a margin: the two one-sided tests (TOST, Schuirmann 1987).

    A slope that is "not resolved" is no evidence of absence; an absence
    claim is a test that the true theta lies in (low, high), a margin that
    was declared before the data were seen (e.g. in the study's script).
    With T = (estimate - bound) / sem Student-t on ``dof`` degrees of
    freedom, H0: theta <= low is rejected at level alpha when
    p_lower = P(T_dof > (estimate - low) / sem) < alpha, and H0:
    theta >= high when p_upper = P(T_dof < (estimate - high) / sem) < alpha;
    equivalence is both, which is the (1 - 2 alpha) interval inside the
    margin. The test has level alpha (not 2 alpha). It assumes an estimate
    normal about theta with a standard error on ``dof`` degrees of freedom
    (G - 1 for a two-level mean over G geometries).

    Parameters
    ----------
    estimate : float
        In any unit.
    sem : float
        Its standard error, > 0.
    dof : float
        > 0, or math.inf for a known error.
    margin : float or (float, float)
        m > 0 for (-m, m), or (low, high) with low < high.
    alpha : float
        In (0, 0.5).

    Returns
    -------
    Equivalence

    Raises
    ------
    ConfigError
        If a parameter is out of range.

    Examples
    --------
    A slope of 0.4 +- 0.9 (7 dof) against the margin +-3 declared beforehand:

    >>> out = equivalence_test(0.4, 0.9, 7, 3.0)
    >>> out.equivalent, [round(c, 2) for c in out.ci], round(out.p, 4)
    (True, [-1.31, 2.11], 0.0117)
    """
    owner = "equivalence_test"
    estimate = check_scalar(estimate, "estimate", owner)
    sem = check_scalar(sem, "sem", owner, "> 0")
    dof = _dof(dof, owner)
    alpha = check_scalar(alpha, "alpha", owner, "in (0, 1)")
    if alpha >= 0.5:
        raise param_error("alpha", owner, "in (0, 0.5)", alpha)
    if isinstance(margin, tuple):
        low, high = (check_scalar(m, "margin", owner) for m in margin) if len(margin) == 2 else (1.0, 0.0)
        if not low < high:
            raise param_error("margin", owner, "a number > 0 or a pair low < high", margin)
    else:
        high = check_scalar(margin, "margin", owner, "> 0")
        low = -high
    p_lower = float(stats.t.sf((estimate - low) / sem, dof))
    p_upper = float(stats.t.cdf((estimate - high) / sem, dof))
    half = float(stats.t.ppf(1.0 - alpha, dof)) * sem
    p = max(p_lower, p_upper)
    return Equivalence(estimate=estimate, sem=sem, dof=dof, margin=(low, high), p_lower=p_lower, p_upper=p_upper,
                       p=p, equivalent=p < alpha, ci=(estimate - half, estimate + half), alpha=alpha)


def minimum_detectable_effect(sem: float, dof: float, *, alpha: float = 0.05, power: float = 0.8) -> float:
    """The smallest true effect that a two-sided test at ``alpha`` finds with probability ``power``.

    MDE = (t_{1-alpha/2, dof} + t_{power, dof}) sem: the effect whose
    estimate exceeds the test's threshold t_{1-alpha/2} sem with
    probability ``power`` (the far tail and the error of sem neglected:
    at alpha 0.05 and power 0.8 the exact noncentral-t power is 0.77 on 2
    dof and within 0.02 of 0.8 from 3 dof on, tested). To be written
    beside every "not resolved": it says what the measurement could have
    missed, which mean + t sem does not (that bound shrinks when the
    estimate happens to be negative).

    Parameters
    ----------
    sem : float
        The estimate's standard error, > 0, in its unit.
    dof : float
        > 0, or math.inf.
    alpha, power : float
        In (0, 1).

    Returns
    -------
    float
        In the unit of ``sem``.

    Raises
    ------
    ConfigError
        If a parameter is out of range.

    Examples
    --------
    >>> round(minimum_detectable_effect(1.0, math.inf), 4)   # 1.96 + 0.84
    2.8016
    >>> round(minimum_detectable_effect(1.0, 7), 4)
    3.2607
    """
    owner = "minimum_detectable_effect"
    sem = check_scalar(sem, "sem", owner, "> 0")
    dof = _dof(dof, owner)
    alpha = check_scalar(alpha, "alpha", owner, "in (0, 1)")
    power = check_scalar(power, "power", owner, "in (0, 1)")
    return float((stats.t.ppf(1.0 - alpha / 2.0, dof) + stats.t.ppf(power, dof)) * sem)


# A family of tests.


@dataclass(frozen=True)
class Family:
    """The q-values of a family of tests, each named.

    Attributes
    ----------
    labels : tuple of str
        The members, in the order given.
    p, q : numpy.ndarray, shape (size,)
        Their p-values and q-values (adjusted p-values: the smallest false
        discovery rate at which each is a discovery).
    method : str
        ``"bh"`` or ``"by"``.
    """

    labels: tuple[str, ...]
    p: np.ndarray
    q: np.ndarray
    method: str

    @property
    def size(self) -> int:
        """The family's size m, to be reported with it."""
        return len(self.labels)

    def discoveries(self, level: float = 0.05) -> tuple[str, ...]:
        """The members with q <= ``level``, smallest p first."""
        level = check_scalar(level, "level", "Family.discoveries", "in (0, 1)")
        order = np.argsort(self.p, kind="stable")
        return tuple(self.labels[i] for i in order if self.q[i] <= level)


def fdr_family(p_values: Mapping[str, float], *, method: str = "bh") -> Family:
    """The q-values of a whole family of tests (every slope a study reports), with their names.

    Benjamini-Hochberg (``"bh"``): q_(i) = min over j >= i of m p_(j) / j
    for the p-values in increasing order; reporting the members with
    q <= level keeps the expected share of false discoveries among them at
    most level (:func:`scipy.stats.false_discovery_control`). The family is
    every test whose result is reported, decided before looking: leaving a
    member out shrinks m and the q-values with it.

    BH holds for independent tests and under positive regression dependence
    (PRDS; Benjamini & Yekutieli 2001). Slopes of one parameter set measured
    with common random numbers (the same states and draws with and without
    a change, or estimators read from the same tilt tests) have positively
    correlated test statistics, which is PRDS-like; that is the assumption
    to state. Benjamini-Yekutieli (``"by"``) holds under any dependence, at
    the cost of the factor sum_{i<=m} 1/i (3.3 for m = 15) on every q.

    Parameters
    ----------
    p_values : mapping of str to float
        Each member's name and its p-value in [0, 1].
    method : {"bh", "by"}

    Returns
    -------
    Family

    Raises
    ------
    ConfigError
        If the family is empty, a p-value is not in [0, 1] (NaN included: every member needs one), or
        ``method`` is unknown.

    Examples
    --------
    >>> family = fdr_family({"pair": 0.001, "chain 16": 0.02, "irregular 64": 0.04, "irregular 256": 0.6})
    >>> family.size, family.q.round(3).tolist()
    (4, [0.004, 0.04, 0.053, 0.6])
    >>> family.discoveries(0.05)
    ('pair', 'chain 16')
    """
    owner = "fdr_family"
    if method not in ("bh", "by"):
        raise param_error("method", owner, "'bh' or 'by'", method)
    if not p_values:
        raise ConfigError(f"{owner} needs a family of one p-value or more.")
    keys = list(p_values)
    p = np.array([float(p_values[key]) for key in keys])
    bad = ~((p >= 0) & (p <= 1))                          # NaN included
    if bad.any():
        key = keys[int(np.argmax(bad))]
        raise ConfigError(f"{owner} needs a p-value in [0, 1] for every member; {key!r} has {p_values[key]!r}.")
    labels = tuple(str(key) for key in keys)
    return Family(labels=labels, p=p, q=stats.false_discovery_control(p, method=method), method=method)
