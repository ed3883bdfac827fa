"""Trends in ln t with standard errors from independent realizations.

A realization's records at successive times are correlated (each continues
the last), so time bins of one trajectory are not independent samples and
their scatter says nothing of the error of a trend. Realizations are
independent (each has its own child of the seed): :func:`log_trend` fits
each realization's own line against ln t and takes the standard error from
the spread of those per-realization slopes.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from slidernet.errors import ConfigError


def log_trend(values: xr.DataArray, *, t_min: float = 1.0, t_max: float | None = None) -> xr.Dataset:
    """The slope d(values)/d(ln t) of every realization, and the ensemble's with its standard error.

    Each realization r gets its least-squares line values_r(t) = a_r + b_r ln t
    over the recorded times t_min <= t <= t_max where its value is finite;
    the ensemble slope is the mean of the b_r and its standard error
    std(b_r) / sqrt(R), realizations being independent. The values at the
    first and last of those times get their mean and standard error the same
    way.

    Parameters
    ----------
    values : xarray.DataArray, dims (realization, t)
        A per-realization variable of a result (``mu_max``, ``n``, ``x_G``,
        ...), in its own units.
    t_min, t_max : float
        The times fitted, in tau_th; t_min > 0 (ln t). t_max: the last recorded time.

    Returns
    -------
    xarray.Dataset
        ``slope`` (realization,): b_r, in the units of ``values`` per unit of
        ln t (multiply by ln 10 for a slope per decade); ``slope_mean``,
        ``slope_sem``; ``start_mean``, ``start_sem``, ``end_mean``,
        ``end_sem`` (at the first and last fitted times, attributes
        ``t_start``, ``t_end``); ``realizations`` (R, those with at least two
        finite values fitted). A realization with fewer than two finite values
        gets slope NaN and is left out of the means.

    Raises
    ------
    ConfigError
        If ``values`` lacks the dims, or no time is left in [t_min, t_max].

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
    if set(values.dims) != {"realization", "t"}:
        raise ConfigError(f"log_trend needs values of dims (realization, t); got {values.dims}.")
    if not t_min > 0:
        raise ConfigError(f"The 't_min' parameter of log_trend must be > 0 (ln t). Got {t_min!r} instead.")
    values = values.transpose("realization", "t")
    t = values["t"].values.astype(np.float64)
    keep = (t >= t_min) & (t <= (t[-1] if t_max is None else t_max))
    if keep.sum() < 2:
        raise ConfigError(f"log_trend: fewer than two recorded times in [{t_min}, {t_max}].")
    x = np.log(t[keep])
    y = values.values[:, keep].astype(np.float64)
    ok = np.isfinite(y)
    slope = np.full(y.shape[0], np.nan)
    for r in range(y.shape[0]):
        if ok[r].sum() >= 2:
            xr_, yr = x[ok[r]], y[r, ok[r]]
            dx = xr_ - xr_.mean()
            slope[r] = float(dx @ (yr - yr.mean()) / (dx @ dx))
    fitted = np.isfinite(slope)
    R = int(fitted.sum())

    def mean_sem(a: np.ndarray) -> tuple[float, float]:
        a = a[np.isfinite(a)]
        if a.size == 0:
            return np.nan, np.nan
        return float(a.mean()), float(a.std(ddof=1) / np.sqrt(a.size)) if a.size > 1 else np.nan

    s_mean, s_sem = mean_sem(slope)
    a_mean, a_sem = mean_sem(np.where(fitted, y[:, 0], np.nan))
    b_mean, b_sem = mean_sem(np.where(fitted, y[:, -1], np.nan))
    units = values.attrs.get("units", "")
    out = xr.Dataset(
        {
            "slope": ("realization", slope, {"long_name": "least-squares slope against ln t", "units": units}),
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
