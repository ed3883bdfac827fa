"""mu_eff of the dynamic tilt test extrapolated to a zero ramp rate.

The dynamic tilt test (``[dynamics] tilt_rate``,
:mod:`slidernet.solver.inertia_tilt`) raises the load at a finite rate r per
tau_dyn, so its mu_eff depends on r: the load rises during every motion,
and a collective motion that starts below the final load can slide before
the state is loaded to its static limit. :func:`zero_rate` takes mu_eff
measured at three or more rates on the same states (one row per independent
realization, the same state and the same draws at every rate: the
realization's tilt tests at a recorded time, run once per rate) and fits

- ``"linear"``: mu_eff(r) = mu_0 + a r, by least squares on each
  realization's row; mu_0 is the mean of the per-realization intercepts and
  its standard error their spread over sqrt(R) (the fit is linear in the
  data, so this is exact and keeps the pairing of the rates);
- ``"power"``: mu_eff(r) = mu_0 + a r^b, b in (0, 3], fitted to the mean over
  realizations, with the jackknife over realizations for the standard error
  (it carries the uncertainty of b).

On the two sliders (docs/guides/dynamic-tilt.md) mu_eff falls linearly with
r over two decades, r = 1e-4 to 1e-2 per tau_dyn (the power fit's exponent
1.13 +- 0.11); on an irregular network of 16 it falls faster than linearly
(exponent 1.87 +- 0.45 over 1e-4 to 1e-3), ten times as steeply.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize

from slidernet._validation import check_array
from slidernet.analysis.trend import mean_sem
from slidernet.errors import ConfigError, param_error

MODELS = ("linear", "power")
#: The range searched for the exponent b of the power model.
B_BOUNDS = (1e-3, 3.0)


@dataclass(frozen=True)
class ZeroRate:
    """mu_eff at a zero ramp rate (:func:`zero_rate`).

    Attributes
    ----------
    mu_eff, se : float
        mu_0 and its standard error from the independent realizations.
    slope : float
        a, the coefficient of r (``"linear"``) or r^b (``"power"``), per unit of r^b.
    exponent, exponent_se : float
        b and its jackknife error: 1 and NaN for ``"linear"``.
    model : str
    realizations : int
    """

    mu_eff: float
    se: float
    slope: float
    exponent: float
    exponent_se: float
    model: str
    realizations: int


def _power_fit(rates: np.ndarray, mean: np.ndarray) -> tuple[float, float, float]:
    """(mu_0, a, b) of mu_0 + a r^b fitted to ``mean`` by least squares; b searched in (0, 3]."""
    def linear_part(b: float) -> tuple[np.ndarray, float]:
        X = np.stack([np.ones_like(rates), rates ** b], axis=1)
        coef, *_ = np.linalg.lstsq(X, mean, rcond=None)
        return coef, float(((X @ coef - mean) ** 2).sum())

    # For a fixed b the model is linear in (mu_0, a): the fit is a one-dimensional search in b.
    res = optimize.minimize_scalar(lambda b: linear_part(b)[1], bounds=B_BOUNDS, method="bounded",
                                   options={"xatol": 1e-10})
    coef, _ = linear_part(float(res.x))
    return float(coef[0]), float(coef[1]), float(res.x)


def zero_rate(rates: ArrayLike, mu_eff: ArrayLike, model: str = "linear") -> ZeroRate:
    """mu_eff of the dynamic tilt test extrapolated to a zero ramp rate, with its standard error.

    Parameters
    ----------
    rates : array_like, shape (K,)
        The ramp rates r, per tau_dyn (``[dynamics] tilt_rate``), > 0 and distinct, K >= 3.
    mu_eff : array_like, shape (R, K)
        mu_eff of realization i at rate k: the same state and draws along a row, the rows independent
        (R >= 2).
    model : {"linear", "power"}
        mu_0 + a r, or mu_0 + a r^b (see the module docstring).

    Returns
    -------
    ZeroRate

    Raises
    ------
    ConfigError
        Fewer than 3 rates, a rate <= 0 or repeated, a shape that does not match, fewer than 2 realizations,
        a non-finite mu_eff, or an unknown model.

    Examples
    --------
    Rows on the lines 0.56 - 2 r and 0.57 - 2 r: mu_0 = 0.565 +- 0.005.

    >>> out = zero_rate([1e-3, 2e-3, 4e-3], [[0.558, 0.556, 0.552], [0.568, 0.566, 0.562]])
    >>> round(out.mu_eff, 12), round(out.se, 12), round(out.slope, 9)
    (0.565, 0.005, -2.0)
    """
    owner = "zero_rate"
    r = check_array(rates, "rates", owner, "> 0")
    if r.ndim != 1 or r.size < 3 or np.unique(r).size != r.size:
        raise param_error("rates", owner, "at least 3 distinct ramp rates > 0, shape (K,)", rates)
    y = check_array(mu_eff, "mu_eff", owner)
    if y.ndim != 2 or y.shape[1] != r.size or y.shape[0] < 2:
        raise ConfigError(f"The 'mu_eff' parameter of {owner} must have the shape (R, {r.size}) with R >= 2 "
                          f"realizations, one column per rate. Got the shape {y.shape} instead.")
    R = y.shape[0]
    if model == "linear":
        X = np.stack([np.ones_like(r), r], axis=1)
        coef = np.linalg.lstsq(X, y.T, rcond=None)[0]  # (2, R): each realization's intercept and slope
        mu0, se, _ = mean_sem(coef[0])
        return ZeroRate(mu0, se, float(coef[1].mean()), 1.0, math.nan, model, R)
    if model == "power":
        mu0, a, b = _power_fit(r, y.mean(axis=0))
        if min(b - B_BOUNDS[0], B_BOUNDS[1] - b) < 1e-3:
            warnings.warn(f"zero_rate: the power law's exponent sits at the end of its range {B_BOUNDS} "
                          f"(b = {b:.4g}): the rates do not determine it; use more rates, or the linear model.",
                          RuntimeWarning, stacklevel=2)
        total = y.sum(axis=0)
        loo = np.array([_power_fit(r, (total - y[i]) / (R - 1)) for i in range(R)])  # (R, 3)
        se_mu0, _, se_b = np.sqrt((R - 1) / R * ((loo - loo.mean(axis=0)) ** 2).sum(axis=0))
        return ZeroRate(mu0, float(se_mu0), a, b, float(se_b), model, R)
    raise param_error("model", owner, f"one of {MODELS}", model)
