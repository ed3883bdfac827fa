"""Trends of a study (analysis.trend): fit windows in t and in another per-realization variable, the level of
each realization's line, the recovery of an injected effect and a rate relative to a level, on cases worked
by hand and on simulated data with stated seeds and tolerances."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from slidernet.analysis.trend import log_trend
from slidernet.errors import ConfigError

T = np.array([0.0, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10000.0])


def _records(y: np.ndarray, t: np.ndarray = T) -> xr.DataArray:
    return xr.DataArray(y, dims=("realization", "t"), coords={"t": t, "realization": np.arange(y.shape[0])})


def _by_hand(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """Slope against ln t and mean of y, by numpy's polyfit (no slidernet code)."""
    return float(np.polyfit(np.log(t), y, 1)[0]), float(y.mean())


@pytest.mark.parametrize(("t_min", "t_max"), [(10.0, 1e3), (100.0, 1e3), (1.0, None)],
                         ids=["10-1e3", "100-1e3", "1-end"])
def test_a_window_in_t_fits_only_its_times(t_min, t_max):
    rng = np.random.default_rng(11)
    y = rng.normal(0.0, 1.0, (3, T.size))
    out = log_trend(_records(y), t_min=t_min, t_max=t_max)
    inside = (T >= t_min) & (T <= (T[-1] if t_max is None else t_max))
    for r in range(3):
        slope, level = _by_hand(T[inside], y[r, inside])
        assert float(out["slope"][r]) == pytest.approx(slope, rel=1e-12)
        assert float(out["level"][r]) == pytest.approx(level, rel=1e-12)


def test_a_window_in_slips_per_node_is_each_realization_s_own():
    # Two realizations slip at different rates: s = 0.5 t and s = 5 t slips per node. The window
    # 10 <= s <= 1000 is 30 <= t <= 1000 for the first and 3 <= t <= 100 for the second.
    rng = np.random.default_rng(12)
    y = rng.normal(0.0, 1.0, (2, T.size))
    slips = _records(np.array([0.5 * T, 5.0 * T]))
    out = log_trend(_records(y), where=(slips >= 10) & (slips <= 1000))
    for r, (lo, hi) in enumerate([(30.0, 1000.0), (3.0, 100.0)]):
        inside = (T >= lo) & (T <= hi)
        assert float(out["slope"][r]) == pytest.approx(_by_hand(T[inside], y[r, inside])[0], rel=1e-12)
    # The first and last values are each realization's own, at the ends of its window.
    assert float(out["start_mean"]) == pytest.approx((y[0, T == 30][0] + y[1, T == 3][0]) / 2, rel=1e-12)
    assert float(out["end_mean"]) == pytest.approx((y[0, T == 1000][0] + y[1, T == 100][0]) / 2, rel=1e-12)
    # Against ln s in the same window: the same slopes (ln s = ln t + a constant per realization).
    against = log_trend(_records(y), where=(slips >= 10) & (slips <= 1000), against=slips)
    np.testing.assert_allclose(against["slope"].values, out["slope"].values, rtol=1e-12)


def test_a_window_that_keeps_everything_changes_nothing():
    rng = np.random.default_rng(13)
    y = rng.normal(0.0, 1.0, (4, T.size))
    y[1, 4] = np.nan
    v = _records(y)
    before = log_trend(v, t_min=3.0)
    after = log_trend(v, t_min=3.0, where=xr.ones_like(v, dtype=bool))
    xr.testing.assert_identical(before, after)


def test_a_window_is_refused_unless_it_is_a_mask_of_the_values():
    v = _records(np.zeros((2, T.size)))
    with pytest.raises(ConfigError, match=r"log_trend's 'where' has the shape \(2, 3\), the values \(2, 10\)"):
        log_trend(v, where=xr.ones_like(v, dtype=bool).isel(t=[0, 1, 2]))
    with pytest.raises(ConfigError, match=r"log_trend's 'where' must be boolean; got float64"):
        log_trend(v, where=xr.ones_like(v, dtype=float))
