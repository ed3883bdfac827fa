"""Trends in ln t with standard errors from independent realizations.

A realization's records at successive times are correlated (each continues
the last), so time bins of one trajectory are not independent samples and
their scatter says nothing of the error of a trend. Realizations are
independent (each has its own child of the seed): :func:`log_trend` fits
each realization's own line against ln t and takes the standard error from
the spread of those per-realization slopes, and :func:`creep_law` tells
steady from logarithmic creep by each realization's mean velocity over two
successive log-spaced windows. :func:`mean_sem` is the rule under all of
them: the mean of one value per realization and its standard error;
:func:`grouped_mean_sem` is the same where realizations share a quenched
geometry, from the geometries' means.

Two readings of such slopes, with the same errors: :func:`injection_recovery`,
the fraction of an injected effect (a known rise of the thresholds) that an
estimator's slope recovers, paired per realization; :func:`relative_rate`, a
slope relative to its own level above a floor. The inference on top of them
(variance components, equivalence tests, the slope against the size, a family
of q-values) is in :mod:`slidernet.analysis.stats`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy import stats

from slidernet._validation import check_scalar
from slidernet.errors import ConfigError, param_error


def _per_realization(values: xr.DataArray, owner: str) -> tuple[xr.DataArray, np.ndarray]:
    """``values`` as (realization, t) and its recorded times (float64, tau_th); refused with other dims
    or with times out of order."""
    if set(values.dims) != {"realization", "t"}:
        raise ConfigError(f"{owner} needs values of dims (realization, t); got {values.dims}.")
    values = values.transpose("realization", "t")
    t = values["t"].values.astype(np.float64)
    # The windows and the default ends are found by position: the records must be in time order.
    if not (np.isfinite(t).all() and (np.diff(t) > 0).all()):
        raise ConfigError(f"{owner} needs finite, increasing recorded times t; got {t.tolist()}.")
    return values, t


def _like(other: xr.DataArray, values: xr.DataArray, name: str) -> xr.DataArray:
    """``other`` as (realization, t), refused unless it has the dims, times and shape of ``values``."""
    other, _ = _per_realization(other, f"log_trend's {name!r}")
    if other.shape != values.shape:
        raise ConfigError(f"log_trend's {name!r} has the shape {other.shape}, the values {values.shape}.")
    return other


def mean_sem(values: ArrayLike) -> tuple[float, float, int]:
    """Mean, standard error and count of per-realization values, their non-finite ones left out.

    The standard error is std(ddof=1) / sqrt(count): the values must be
    independent, one per realization (never the recorded times of one
    trajectory).

    Parameters
    ----------
    values : array_like, shape (R,)
        One value per realization, in any unit; NaN for a realization that
        has none.

    Returns
    -------
    mean, sem : float
        In the unit of ``values``; NaN without a finite value, and ``sem``
        NaN with a single one.
    count : int
        The finite values used.

    Examples
    --------
    >>> mean_sem([1.0, 3.0, np.nan])
    (2.0, 1.0, 2)
    """
    a = np.asarray(values, dtype=np.float64)
    a = a[np.isfinite(a)]
    if a.size == 0:
        return math.nan, math.nan, 0
    return float(a.mean()), float(a.std(ddof=1) / math.sqrt(a.size)) if a.size > 1 else math.nan, int(a.size)


def grouped_mean_sem(values: ArrayLike, groups: ArrayLike) -> tuple[float, float, int]:
    """Mean and standard error of per-realization values whose realizations share quenched groups (network
    geometries): the two-level estimate.

    Each group's mean over its realizations first, then the mean of the G
    group means and its standard error, std(group means, ddof=1) / sqrt(G),
    with G - 1 degrees of freedom. The spread between groups (another
    network of the same size) is then in the error, as it is not when every
    realization is taken as independent. Non-finite values are left out; a
    group without a finite value does not count. With one group per
    realization this is :func:`mean_sem`.

    Parameters
    ----------
    values : array_like, shape (R,)
        One value per realization, in any unit.
    groups : array_like, shape (R,)
        The group (e.g. the network seed) of each realization.

    Returns
    -------
    mean, sem : float
        In the unit of ``values``; NaN where there is no group (``sem``: fewer
        than two).
    dof : int
        G - 1, the degrees of freedom of ``sem`` (for a Student-t quantile).

    Examples
    --------
    Two geometries of two realizations each: their means are 1 and 3.

    >>> grouped_mean_sem([0.5, 1.5, 3.0, 3.0], [0, 0, 7, 7])
    (2.0, 1.0, 1)
    """
    means = _group_means("grouped_mean_sem", groups, values=values)[:, 0]
    mean, sem, count = mean_sem(means)
    return mean, sem, max(count - 1, 0)


def _group_means(owner: str, groups: ArrayLike | None, **columns: ArrayLike) -> np.ndarray:
    """Each group's means of the ``columns`` (one value per realization each), over its realizations where
    every column is finite: shape (G, len(columns)), groups in sorted order, a group with no such
    realization left out. ``groups`` None: every realization its own group."""
    arrays = {name: np.asarray(column, dtype=np.float64) for name, column in columns.items()}
    g = np.arange(next(iter(arrays.values())).size) if groups is None else np.asarray(groups)
    given = {**arrays, **({"groups": g} if groups is not None else {})}
    shapes = [a.shape for a in given.values()]
    if len(set(shapes)) != 1 or g.ndim != 1:
        raise ConfigError(f"{owner} needs {' and '.join(given)} of one shape (R,), one value per realization; "
                          f"got {' and '.join(map(str, shapes))}.")
    v = np.stack(list(arrays.values()), axis=1)
    finite = np.isfinite(v).all(axis=1)
    if groups is None:
        return v[finite]
    means = [v[(g == key) & finite].mean(axis=0) for key in np.unique(g) if (finite & (g == key)).any()]
    return np.array(means).reshape(len(means), len(arrays))


def log_trend(values: xr.DataArray, *, t_min: float = 1.0, t_max: float | None = None,
              against: xr.DataArray | None = None, where: xr.DataArray | None = None) -> xr.Dataset:
    """The slope d(values)/d(ln t) of every realization, and the ensemble's with its standard error.

    Each realization r gets its least-squares line values_r(t) = a_r + b_r ln t
    over the recorded times t_min <= t <= t_max where its value is finite
    (and ``where`` is True: a window of its own, in slips per node, say);
    the ensemble slope is the mean of the b_r and its standard error
    std(b_r) / sqrt(R), realizations being independent. The values at the
    first and last times of each realization's window get their mean and
    standard error the same way.

    A window after the transient is a choice of ``t_min`` and ``t_max`` (10
    and 1e3 tau_th, say). A window in another variable that each
    realization reaches at its own times (the slips per node ``s``) is the
    mask ``where = (s >= 10) & (s <= 1e3)``; the slope is still against ln t
    unless ``against`` is given too. Where ``where`` keeps every record the
    result is that without it.

    Parameters
    ----------
    values : xarray.DataArray, dims (realization, t)
        A per-realization variable of a result (``mu_max``, ``n``, ``x_G``,
        ...), in its own units.
    t_min, t_max : float
        The times fitted, in tau_th; t_min > 0 (ln t). t_max: the last recorded time.
    against : xarray.DataArray, dims (realization, t), optional
        Another abscissa, per realization and recorded time, > 0 where
        fitted (the slips per node, say): the slopes are then against its
        logarithm, over the same times. Default: t.
    where : xarray.DataArray of bool, dims (realization, t), optional
        Which records each realization may fit, besides t_min <= t <= t_max
        (a window in a per-realization variable). Default: all.

    Returns
    -------
    xarray.Dataset
        ``slope`` (realization,): b_r, in the units of ``values`` per unit of
        ln t (multiply by ln 10 for a slope per decade); ``level``
        (realization,): the mean of the values fitted, which is the line's
        value at the mean abscissa fitted, in the units of ``values`` (the
        level a relative rate divides by: :func:`relative_rate`);
        ``slope_mean``, ``slope_sem``; ``start_mean``, ``start_sem``,
        ``end_mean``, ``end_sem`` (at the first and last times of each
        realization's window; attributes ``t_start``, ``t_end``: the first and
        last times in [t_min, t_max]); ``realizations`` (R, those with at
        least two finite values fitted). A realization with fewer than two
        finite values gets slope and level NaN and is left out of the means.

    Raises
    ------
    ConfigError
        If ``values`` lacks the dims or increasing times, ``t_min`` is not > 0, fewer than two
        times are left in [t_min, t_max], or ``against`` or ``where`` is not of the shape of the
        values (``where``: or not boolean).

    Examples
    --------
    Two realizations on exact lines of slopes 1 and 3 (per unit of ln t):

    >>> t = np.array([0.0, 1.0, 10.0, 100.0])
    >>> v = xr.DataArray([0.2 + 1.0 * np.log(np.maximum(t, 1)), 0.5 + 3.0 * np.log(np.maximum(t, 1))],
    ...                  dims=("realization", "t"), coords={"t": t})
    >>> out = log_trend(v)
    >>> out["slope"].values.round(12).tolist()
    [1.0, 3.0]
    >>> round(float(out["slope_mean"]), 12), round(float(out["slope_sem"]), 12)
    (2.0, 1.0)
    """
    values, t = _per_realization(values, "log_trend")
    t_min = check_scalar(t_min, "t_min", "log_trend", "> 0")   # ln t
    keep = (t >= t_min) & (t <= (t[-1] if t_max is None else t_max))
    if keep.sum() < 2:
        raise ConfigError(f"log_trend: fewer than two recorded times in [{t_min}, {t_max}].")
    y = values.values[:, keep].astype(np.float64)
    if against is None:
        x = np.broadcast_to(np.log(t[keep]), y.shape)
    else:
        a = _like(against, values, "against").values[:, keep].astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = np.log(a)
    if where is None:
        window = np.ones(y.shape, dtype=bool)
    else:
        mask = _like(where, values, "where")
        if mask.dtype != bool:
            raise ConfigError(f"log_trend's 'where' must be boolean; got {mask.dtype}.")
        window = mask.values[:, keep]
    ok = window & np.isfinite(y) & np.isfinite(x)
    slope = np.full(y.shape[0], np.nan)
    level = np.full(y.shape[0], np.nan)
    for r in range(y.shape[0]):
        if ok[r].sum() >= 2:
            xr_, yr = x[r, ok[r]], y[r, ok[r]]
            dx = xr_ - xr_.mean()
            slope[r] = float(dx @ (yr - yr.mean()) / (dx @ dx))
            level[r] = float(yr.mean())
    fitted = np.isfinite(slope)
    R = int(fitted.sum())

    # Each realization's first and last records in its window (without 'where': the first and last kept).
    rows = np.arange(y.shape[0])
    first = np.where(window.any(axis=1), y[rows, window.argmax(axis=1)], np.nan)
    last = np.where(window.any(axis=1), y[rows, window.shape[1] - 1 - window[:, ::-1].argmax(axis=1)], np.nan)
    s_mean, s_sem, _ = mean_sem(slope)
    a_mean, a_sem, _ = mean_sem(np.where(fitted, first, np.nan))
    b_mean, b_sem, _ = mean_sem(np.where(fitted, last, np.nan))
    units = values.attrs.get("units", "")
    out = xr.Dataset(
        {
            "slope": ("realization", slope, {"long_name": "least-squares slope against ln t", "units": units}),
            "level": ("realization", level, {"long_name": "mean of the values fitted", "units": units}),
            "slope_mean": ((), s_mean, {"long_name": "mean of the per-realization slopes", "units": units}),
            "slope_sem": ((), s_sem, {"long_name": "standard error of slope_mean over the realizations",
                                      "units": units}),
            "start_mean": ((), a_mean, {"units": units}),
            "start_sem": ((), a_sem, {"units": units}),
            "end_mean": ((), b_mean, {"units": units}),
            "end_sem": ((), b_sem, {"units": units}),
            "realizations": ((), R),
        },
        coords={"realization": values["realization"].values} if "realization" in values.coords else None,
        attrs={"t_start": float(t[keep][0]), "t_end": float(t[keep][-1]), "t_min": float(t_min)},
    )
    return out


@dataclass(frozen=True)
class Recovery:
    """The response of an estimator's slope to an injected effect, and the fraction of the effect it recovers.

    Attributes
    ----------
    response, response_sem : float
        The mean paired difference <slope_injected - slope_plain> and its
        standard error, in the slopes' units (two-level over geometries when
        there are groups).
    recovery, recovery_sem : float
        ``response / rate`` and its standard error (``rate`` is exact).
    dof : int
        Degrees of freedom of the errors: G - 1 (R - 1 without groups).
    rate : float
        The normalizing rate, in the slopes' units.
    pairs, groups : int
        Realizations with both slopes finite, and the geometries they make
        (without groups: ``pairs``).
    """

    response: float
    response_sem: float
    recovery: float
    recovery_sem: float
    dof: int
    rate: float
    pairs: int
    groups: int


def injection_recovery(plain: ArrayLike, injected: ArrayLike, rate: float,
                       groups: ArrayLike | None = None) -> Recovery:
    """How much of an injected effect an estimator's slope recovers, paired per realization.

    The same realizations are measured twice, without and with the
    injection, on the same states and draws (common random numbers): each
    realization's difference d_r = slope_injected,r - slope_plain,r is its
    response, the noise the two share cancelling in it. The response is the
    mean of the d_r, two-level over geometries (:func:`grouped_mean_sem`:
    each geometry's mean difference, then the mean and spread of those
    means; G - 1 degrees of freedom); the recovery is response / rate.

    The normalizing ``rate`` is what full recovery would give, in the units
    of the slopes. For thresholds raised by c ln(1 + t/t0) and slopes
    per unit of ln t over a window with t >> t0 that is c (c ln 10 per
    decade); otherwise the slope of the injected shift itself, fitted like
    the estimator's (with :func:`log_trend`, as below). Under a selection
    that raises only a fraction q of the contacts, ``rate`` = c answers
    "what fraction of the per-contact shift is seen" and ``rate`` = q c
    "what fraction of the mean shift": call it with each.

    Parameters
    ----------
    plain, injected : array_like, shape (R,)
        Each realization's slope without and with the injection (NaN where
        it has none: the pair is then left out), in one unit.
    rate : float
        The slope that full recovery gives, in the same unit; != 0.
    groups : array_like, shape (R,), optional
        Each realization's geometry (the network seed). Default: every
        realization independent.

    Returns
    -------
    Recovery

    Raises
    ------
    ConfigError
        If the slopes (and groups) are not of one shape (R,), or ``rate`` is 0 or not finite.

    Examples
    --------
    Records of three realizations, and the same records with the shift
    0.01 ln(1 + t/t0), t0 = 1, added: the rate is the slope of the shift
    over the window (near 0.01 for t >> t0), and the recovery exactly 1.

    >>> t = np.array([1.0, 10.0, 100.0, 1000.0])
    >>> rng = np.random.default_rng(0)
    >>> plain = xr.DataArray(rng.normal(0.55, 0.01, (3, 4)), dims=("realization", "t"), coords={"t": t})
    >>> shift = 0.01 * np.log1p(t / 1.0)
    >>> rate = float(log_trend(xr.DataArray(shift[None, :], dims=("realization", "t"), coords={"t": t}),
    ...                        t_min=10)["slope"][0])
    >>> round(rate, 5)
    0.0098
    >>> out = injection_recovery(log_trend(plain, t_min=10)["slope"], log_trend(plain + shift, t_min=10)["slope"],
    ...                          rate)
    >>> round(out.recovery, 12), out.pairs
    (1.0, 3)
    """
    owner = "injection_recovery"
    rate = check_scalar(rate, "rate", owner, "!= 0")
    pairs = _group_means(owner, None, plain=plain, injected=injected)   # the shapes, and the pairs kept
    means = _group_means(owner, groups, plain=plain, injected=injected)
    mean, sem, count = mean_sem(means[:, 1] - means[:, 0])
    return Recovery(response=mean, response_sem=sem, recovery=mean / rate, recovery_sem=sem / abs(rate),
                    dof=max(count - 1, 0), rate=rate, pairs=len(pairs), groups=count)


@dataclass(frozen=True)
class RelativeRate:
    """A slope relative to its own level above a floor.

    Attributes
    ----------
    rate, sem : float
        <slope> / <level - floor> and its delta-method standard error, in
        the slopes' unit per unit of level (per unit of ln t for slopes
        against ln t of the level's own variable: multiply by ln 10 for a
        fraction per decade).
    dof : int
        G - 1 (R - 1 without groups).
    ci : tuple of float
        Fieller's interval at ``confidence``; (-inf, inf) when the level is
        not resolved at that confidence.
    confidence : float
    slope_mean, slope_sem, level_mean, level_sem : float
        The two means (level above the floor) and their standard errors.
    groups : int
        The independent units: geometries, or realizations without groups.
    """

    rate: float
    sem: float
    dof: int
    ci: tuple[float, float]
    confidence: float
    slope_mean: float
    slope_sem: float
    level_mean: float
    level_sem: float
    groups: int


def relative_rate(slopes: ArrayLike, levels: ArrayLike, groups: ArrayLike | None = None, *, floor: float = 0.0,
                  confidence: float = 0.95) -> RelativeRate:
    """A trend relative to the level it acts on: <slope> / <level - floor>, with per-realization errors.

    For an estimator pinned to a floor (mu_eff >= mu_d at e = 1, where the
    excess mu_eff - mu_d shrinks as N^-1/2), an absolute slope says little
    across sizes; its ratio to the estimator's own excess above the floor
    does (the relative aging rate). Each realization r brings its slope b_r
    and its level L_r (:func:`log_trend` gives both: ``slope`` and
    ``level``, the mean over the same window).

    The rate is the ratio of the means, rho = <b> / <L - floor>, not the
    mean of per-realization ratios, which explodes where one level is near
    the floor. Its standard error is the delta method's: the spread of the
    linearised terms (b_r - rho (L_r - floor)) / <L - floor>, which keeps
    the covariance of a realization's slope and level. With geometries the
    means are the two-level ones (:func:`grouped_mean_sem`) and the terms
    are averaged per geometry first. The delta method needs the level well
    resolved; the interval does not: it is Fieller's, the set of rho whose
    contrast <b> - rho <L - floor> is within t SE of 0 (t the Student
    quantile at ``confidence`` with ``dof`` degrees of freedom), bounded
    only when the level is resolved at that confidence. A one-sided upper
    bound at 95 % is the upper end of the interval at ``confidence`` 0.9.

    Parameters
    ----------
    slopes, levels : array_like, shape (R,)
        Each realization's slope and level, in any units (NaN: left out
        with its pair).
    groups : array_like, shape (R,), optional
        Each realization's geometry. Default: every realization independent.
    floor : float
        Subtracted from the levels (mu_d, say), in their unit.
    confidence : float
        Of the interval, in (0, 1).

    Returns
    -------
    RelativeRate

    Raises
    ------
    ConfigError
        If the slopes, levels (and groups) are not of one shape (R,), or ``floor`` or ``confidence``
        is out of range.

    Examples
    --------
    Three realizations whose levels above mu_d = 0.5 are 0.01, 0.012 and
    0.008 and whose slopes are 3 % of them, give or take:

    >>> out = relative_rate([3.1e-4, 3.5e-4, 2.4e-4], [0.510, 0.512, 0.508], floor=0.5)
    >>> round(out.rate, 4), round(out.sem, 4), out.dof
    (0.03, 0.0006, 2)
    """
    owner = "relative_rate"
    floor = check_scalar(floor, "floor", owner)
    confidence = check_scalar(confidence, "confidence", owner, "in (0, 1)")
    means = _group_means(owner, groups, slopes=slopes, levels=levels)
    b, level = means[:, 0], means[:, 1] - floor
    G = len(b)
    b_mean, b_sem, _ = mean_sem(b)
    l_mean, l_sem, _ = mean_sem(level)
    rate = b_mean / l_mean if l_mean != 0 else math.nan
    sem = mean_sem((b - rate * level) / l_mean)[1] if math.isfinite(rate) else math.nan
    return RelativeRate(rate=rate, sem=sem, dof=max(G - 1, 0), ci=_fieller(b, level, confidence),
                        confidence=confidence, slope_mean=b_mean, slope_sem=b_sem, level_mean=l_mean,
                        level_sem=l_sem, groups=G)


def _fieller(b: np.ndarray, level: np.ndarray, confidence: float) -> tuple[float, float]:
    """Fieller's interval of <b> / <level> from G independent pairs: the rho with
    (<b> - rho <level>)^2 <= t^2 var(<b> - rho <level>), a quadratic in rho."""
    G = len(b)
    if G < 2:
        return math.nan, math.nan
    cov = np.cov(b, level, ddof=1) / G          # of the two means
    t = stats.t.ppf(0.5 + confidence / 2, G - 1)
    B, L = float(b.mean()), float(level.mean())
    a = L * L - t * t * cov[1, 1]
    if a <= 0:                                   # the level is not resolved: no bounded interval
        return -math.inf, math.inf
    half = B * L - t * t * cov[0, 1]
    # a > 0 puts rho = B / L inside, so the roots are real; rounding may leave a tiny negative.
    root = math.sqrt(max(half * half - a * (B * B - t * t * cov[0, 0]), 0.0))
    return (half - root) / a, (half + root) / a


def _verdict(steady: bool, log: bool) -> str:
    """The test's answer in words, from whether each law's prediction survived."""
    if steady and not log:
        return "steady: logarithmic creep rejected"
    if log and not steady:
        return "logarithmic: steady creep rejected"
    if steady and log:
        return "undecided: both laws within the error"
    return "neither law: both rejected"


def creep_law(x_G: xr.DataArray, *, t_max: float | None = None, factor: float = 10.0,
              z: float = 2.0) -> xr.Dataset:
    """Steady (x_G ∝ t) or logarithmic (x_G ∝ ln t) creep: mean velocities over two log-spaced windows.

    Every realization r gets its mean velocity over an early and a late
    window that are equally wide in ln t,

        v_early,r = (x_r(t2) - x_r(t1)) / (t2 - t1),
        v_late,r  = (x_r(t3) - x_r(t2)) / (t3 - t2),

    with t3 = t_max, t2 = t_max / factor and t1 = t_max / factor**2, each
    taken as the recorded time nearest to it in ln t (the times used are
    returned). No interpolation: the mean velocity over a window is exact
    whatever happens inside it. The two laws predict the ratio
    v_late / v_early from the times used:

    * steady creep, x = a + v t: 1;
    * logarithmic creep, x = a + c ln t:
      [ln(t3/t2) / (t3 - t2)] / [ln(t2/t1) / (t2 - t1)], which is 1/factor
      (0.1 for decades) when the windows are exactly geometric.

    Errors come from the spread over independent realizations, never from
    the times of one trajectory. The ensemble ratio is the ratio of the mean
    velocities, rho = <v_late> / <v_early>, not the mean of per-realization
    ratios: a realization whose early velocity is near 0 (or negative, from
    noise) would make its own ratio explode. Its standard error is the delta
    method's, computed as the spread of each realization's linearised
    contribution (v_late,r - rho v_early,r) / <v_early>, which keeps the
    covariance of the two velocities of one realization. It only means
    something while <v_early> is resolved (``early_resolved``), so the
    verdicts do not rest on it: each law's prediction rho_h is tested by the
    per-realization contrast g_r = v_late,r - rho_h v_early,r, linear in the
    data, whose mean is 0 under the law whatever <v_early> is; the law is
    consistent when abs(<g>) <= z SE(<g>) (Fieller's test of a ratio; a gap
    within 1e-12 of the velocities is rounding, and passes).

    Parameters
    ----------
    x_G : xarray.DataArray, dims (realization, t)
        A per-realization displacement (``x_G`` of a result, in l0) at the
        recorded times t (coordinate ``t``, in tau_th).
    t_max : float, optional
        End of the late window, in tau_th, within the recorded times
        (default: the last one).
    factor : float
        Width of each window as a ratio of times, > 1 (10: two decades).
    z : float
        The verdicts' threshold, in standard errors (> 0).

    Returns
    -------
    xarray.Dataset
        ``v_early``, ``v_late`` (realization,): each realization's mean
        velocity in the units of ``x_G`` per tau_th (NaN for a realization
        not finite at t1, t2 or t3, left out of everything else);
        ``v_early_mean``, ``v_early_sem``, ``v_late_mean``, ``v_late_sem``;
        ``ratio``, ``ratio_sem`` (rho and its delta-method error);
        ``ratio_steady`` (1), ``ratio_log`` (the predictions);
        ``steady_gap_mean``, ``steady_gap_sem``, ``log_gap_mean``,
        ``log_gap_sem`` (the contrasts <g> and their errors, units of the
        velocities); ``steady_consistent``, ``log_consistent`` (bool:
        abs(<g>) <= z SE); ``early_resolved`` (bool: abs(<v_early>) > z SE, the
        ratio is meaningful); ``realizations`` (R). Attributes ``t1``,
        ``t2``, ``t3`` (the times used), ``factor``, ``z`` and ``verdict``,
        the answer in words. With a single realization the errors are NaN
        and the verdict says neither law.

    Raises
    ------
    ConfigError
        If ``x_G`` lacks the dims or increasing times, ``t_max``, ``factor`` or ``z`` is out of
        range, or fewer than three distinct recorded times serve as t1 < t2 < t3.

    See Also
    --------
    log_trend : the slope of a variable against ln t, per realization.

    Examples
    --------
    Two realizations creeping steadily at 1 and 2 l0 per tau_th (exact
    lines; errors from their spread), then two creeping logarithmically:

    >>> t = np.array([0.0, 1.0, 10.0, 100.0, 1000.0])
    >>> steady = xr.DataArray([1.0 * t, 2.0 * t], dims=("realization", "t"), coords={"t": t})
    >>> out = creep_law(steady)
    >>> out.attrs["t1"], out.attrs["t2"], out.attrs["t3"]
    (10.0, 100.0, 1000.0)
    >>> out["v_early"].values.tolist(), out["v_late"].values.tolist()
    ([1.0, 2.0], [1.0, 2.0])
    >>> float(out["ratio"]), float(out["ratio_log"]), out.attrs["verdict"]
    (1.0, 0.1, 'steady: logarithmic creep rejected')
    >>> ln_t = np.log(np.maximum(t, 1.0))
    >>> logarithmic = xr.DataArray([2.0 * ln_t, 5.0 * ln_t], dims=("realization", "t"), coords={"t": t})
    >>> out = creep_law(logarithmic)
    >>> round(float(out["ratio"]), 12), out.attrs["verdict"]
    (0.1, 'logarithmic: steady creep rejected')
    """
    owner = "creep_law"
    values, t = _per_realization(x_G, owner)
    factor = check_scalar(factor, "factor", owner, "> 1")
    z = check_scalar(z, "z", owner, "> 0")
    positive = t[t > 0]   # ln t
    if positive.size < 3:
        raise ConfigError(f"{owner}: fewer than three recorded times t > 0; got {t.tolist()}.")
    if t_max is None:
        t_max = float(positive[-1])
    t_max = check_scalar(t_max, "t_max", owner, "> 0")
    if t_max > positive[-1]:
        raise param_error("t_max", owner, f"<= the last recorded time {float(positive[-1])!r}", t_max)
    targets = np.array([t_max / factor**2, t_max / factor, t_max])
    if targets[0] < positive[0]:
        raise ConfigError(
            f"{owner}: the early window starts at t_max / factor**2 = {float(targets[0])!r}, before the first "
            f"recorded time t > 0 ({float(positive[0])!r}); lower factor or raise t_max."
        )
    nearest = np.abs(np.log(positive)[None, :] - np.log(targets)[:, None]).argmin(axis=1)
    t1, t2, t3 = (float(positive[i]) for i in nearest)
    if not t1 < t2 < t3:
        raise ConfigError(
            f"{owner}: the recorded times nearest to {targets.tolist()} are {[t1, t2, t3]}, not three "
            "distinct times; record more densely (record = \"log\") or widen the windows (factor)."
        )

    at = values.values[:, np.searchsorted(t, [t1, t2, t3])].astype(np.float64)
    usable = np.isfinite(at).all(axis=1)
    at[~usable] = np.nan
    v_early = (at[:, 1] - at[:, 0]) / (t2 - t1)
    v_late = (at[:, 2] - at[:, 1]) / (t3 - t2)
    R = int(usable.sum())

    e_mean, e_sem, _ = mean_sem(v_early)
    l_mean, l_sem, _ = mean_sem(v_late)
    ratio = l_mean / e_mean if e_mean != 0 else math.nan
    # Delta method: rho - rho_true ~ <v_late - rho v_early> / <v_early>, a mean of independent
    # per-realization terms; its spread keeps the covariance of v_early and v_late.
    ratio_sem = mean_sem((v_late - ratio * v_early) / e_mean)[1] if math.isfinite(ratio) else math.nan
    ratio_log = (math.log(t3 / t2) / (t3 - t2)) / (math.log(t2 / t1) / (t2 - t1))

    gaps = {}
    for name, predicted in (("steady", 1.0), ("log", ratio_log)):
        g_mean, g_sem, _ = mean_sem(v_late - predicted * v_early)
        # Rounding is no evidence: exact synthetic laws have SE ~ 0 and a gap of a few ulps.
        rounding = 1e-12 * (abs(l_mean) + predicted * abs(e_mean))
        # NaN errors (one realization) compare False: no law is then called consistent.
        gaps[name] = (g_mean, g_sem, bool(abs(g_mean) <= z * g_sem + rounding))
    early_resolved = bool(abs(e_mean) > z * e_sem)

    units = values.attrs.get("units", "")
    v_units = f"{units} / tau_th" if units else "per tau_th"
    v_attrs = {"units": v_units}
    out = xr.Dataset(
        {
            "v_early": ("realization", v_early, {"long_name": "mean velocity over [t1, t2]", **v_attrs}),
            "v_late": ("realization", v_late, {"long_name": "mean velocity over [t2, t3]", **v_attrs}),
            "v_early_mean": ((), e_mean, v_attrs),
            "v_early_sem": ((), e_sem, v_attrs),
            "v_late_mean": ((), l_mean, v_attrs),
            "v_late_sem": ((), l_sem, v_attrs),
            "ratio": ((), ratio, {"long_name": "<v_late> / <v_early>", "units": "1"}),
            "ratio_sem": ((), ratio_sem, {"long_name": "standard error of ratio (delta method)", "units": "1"}),
            "ratio_steady": ((), 1.0, {"long_name": "ratio predicted by steady creep", "units": "1"}),
            "ratio_log": ((), ratio_log, {"long_name": "ratio predicted by logarithmic creep", "units": "1"}),
            "steady_gap_mean": ((), gaps["steady"][0], {"long_name": "<v_late - v_early>", **v_attrs}),
            "steady_gap_sem": ((), gaps["steady"][1], v_attrs),
            "log_gap_mean": ((), gaps["log"][0], {"long_name": "<v_late - ratio_log v_early>", **v_attrs}),
            "log_gap_sem": ((), gaps["log"][1], v_attrs),
            "steady_consistent": ((), gaps["steady"][2]),
            "log_consistent": ((), gaps["log"][2]),
            "early_resolved": ((), early_resolved),
            "realizations": ((), R),
        },
        coords={"realization": values["realization"].values} if "realization" in values.coords else None,
        attrs={"t1": t1, "t2": t2, "t3": t3, "factor": factor, "z": z,
               "verdict": _verdict(gaps["steady"][2], gaps["log"][2])},
    )
    return out
