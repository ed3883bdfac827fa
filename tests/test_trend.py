"""Trends of a study (analysis.trend): fit windows in t and in another per-realization variable, the level of
each realization's line, the recovery of an injected effect and a rate relative to a level, on cases worked
by hand and on simulated data with stated seeds and tolerances."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from slidernet.analysis.trend import injection_recovery, log_trend, relative_rate
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


# The recovery of an injected effect: paired slopes with and without it.


def test_recovery_is_the_mean_paired_difference_over_the_rate_by_hand():
    # Two geometries of two realizations: paired differences 1, 3 (geometry 0) and 5, 5 (geometry 7);
    # geometry means 2 and 5, their mean 3.5, standard error std([2, 5]) / sqrt(2) = 1.5, 1 dof.
    plain = np.array([0.0, 1.0, -2.0, 10.0])
    injected = plain + np.array([1.0, 3.0, 5.0, 5.0])
    out = injection_recovery(plain, injected, rate=2.0, groups=[0, 0, 7, 7])
    assert (out.response, out.response_sem, out.dof) == (3.5, pytest.approx(1.5, rel=1e-12), 1)
    assert (out.recovery, out.recovery_sem, out.pairs, out.groups) == (1.75, pytest.approx(0.75, rel=1e-12), 4, 2)
    # Without geometries every realization is independent: mean 3.5, SE std([1, 3, 5, 5]) / 2.
    alone = injection_recovery(plain, injected, rate=2.0)
    assert alone.response_sem == pytest.approx(np.std([1, 3, 5, 5], ddof=1) / 2, rel=1e-12)
    assert alone.dof == 3


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), c=st.floats(1e-4, 1e2), scale=st.floats(1e-6, 1e3),
       sign=st.sampled_from([-1.0, 1.0]))
def test_an_exactly_injected_shift_in_ln_t_is_recovered_exactly(seed, c, scale, sign):
    # Whatever the plain records, adding c ln t to every one of them adds c to every slope against ln t:
    # the recovery with rate c is 1 and its error 0, up to the rounding of the slopes (relative 1e-9 of
    # the records' scale over c).
    rng = np.random.default_rng(seed)
    y = scale * rng.standard_normal((6, T.size))
    c = sign * c
    plain = log_trend(_records(y), t_min=10.0, t_max=1e3)["slope"].values
    injected = log_trend(_records(y + c * np.log(np.maximum(T, 1.0))), t_min=10.0, t_max=1e3)["slope"].values
    out = injection_recovery(plain, injected, rate=c, groups=[0, 0, 1, 1, 2, 2])
    tolerance = 1e-9 * max(1.0, scale / abs(c))
    assert out.recovery == pytest.approx(1.0, abs=tolerance)
    assert out.recovery_sem <= tolerance


def test_recovery_leaves_out_a_realization_without_both_slopes():
    out = injection_recovery([1.0, np.nan, 2.0, 0.0], [2.0, 5.0, np.nan, 2.0], rate=1.0)
    assert (out.response, out.pairs) == (1.5, 2)


def test_recovery_is_refused_for_unpaired_slopes_or_a_zero_rate():
    with pytest.raises(ConfigError, match=r"injection_recovery needs plain and injected of one shape \(R,\)"):
        injection_recovery([1.0, 2.0], [1.0, 2.0, 3.0], rate=1.0)
    with pytest.raises(ConfigError, match=r"The 'rate' parameter of injection_recovery must be != 0"):
        injection_recovery([1.0, 2.0], [1.0, 2.0], rate=0.0)


def test_recovery_interval_covers_the_true_response():
    # Seed 21, 1000 replicates of 8 geometries x 4 realizations: geometry effects on the response of
    # spread 0.5 and noise 1 per realization, and plain slopes of spread 3 (common to both runs: they
    # cancel in the pairs, as common random numbers make them); the 95 % interval response +- t(0.975, 7) SE
    # covers the true response 1.0 in a fraction within 3 standard errors of 0.95 (0.0069).
    rng = np.random.default_rng(21)
    groups = np.repeat(np.arange(8), 4)
    t95 = stats.t.ppf(0.975, 7)
    covered = 0
    for _ in range(1000):
        plain = rng.normal(0.0, 3.0, 32)
        response = 1.0 + rng.normal(0.0, 0.5, 8)[groups] + rng.normal(0.0, 1.0, 32)
        out = injection_recovery(plain, plain + response, rate=2.0, groups=groups)
        covered += abs(out.response - 1.0) <= t95 * out.response_sem
    assert abs(covered / 1000 - 0.95) <= 3 * math.sqrt(0.95 * 0.05 / 1000)


# A rate relative to a level above a floor.


def test_relative_rate_by_hand():
    # Levels known exactly (2 each): rate <b> / <L> = 1, the delta method's error the slopes' own over the
    # level, std([1, 2, 3]) / sqrt(3) / 2, and Fieller's interval is rate +- t SE.
    out = relative_rate([1.0, 2.0, 3.0], [2.5, 2.5, 2.5], floor=0.5)
    se = 1.0 / math.sqrt(3) / 2
    assert (out.rate, out.dof) == (1.0, 2)
    assert out.sem == pytest.approx(se, rel=1e-12)
    t95 = stats.t.ppf(0.975, 2)
    np.testing.assert_allclose(out.ci, (1.0 - t95 * se, 1.0 + t95 * se), rtol=1e-12)
    assert (out.level_mean, out.level_sem) == (2.0, 0.0)


def test_relative_rate_of_slopes_proportional_to_levels_is_exact():
    levels = np.array([0.9, 1.0, 1.1, 1.2, 0.8, 1.0])
    out = relative_rate(0.03 * levels, levels, groups=[0, 0, 1, 1, 2, 2])
    assert out.rate == pytest.approx(0.03, rel=1e-12)
    assert out.sem == pytest.approx(0.0, abs=1e-15)
    np.testing.assert_allclose(out.ci, (0.03, 0.03), rtol=1e-9)


def test_relative_rate_of_an_unresolved_level_has_an_unbounded_interval():
    out = relative_rate([1.0, 1.1, 0.9], [-1.0, 1.0, 0.5])
    assert out.ci == (-math.inf, math.inf)
    assert math.isfinite(out.rate) and math.isfinite(out.sem)


@pytest.mark.parametrize("grouped", [False, True], ids=["realizations", "geometries"])
def test_relative_rate_interval_covers_the_true_ratio(grouped):
    # Seed 22, 2000 replicates of 16 realizations (8 geometries of 2 when grouped): levels of mean 2 and
    # spread 0.5 per realization, slopes 0.1 x level + noise 0.05 (true ratio 0.1); Fieller's 95 % interval
    # covers 0.1 in a fraction within 3 standard errors of 0.95 (0.0049).
    rng = np.random.default_rng(22)
    groups = np.repeat(np.arange(8), 2) if grouped else None
    covered = 0
    for _ in range(2000):
        levels = 2.0 + rng.normal(0.0, 0.5, 16)
        slopes = 0.1 * levels + rng.normal(0.0, 0.05, 16)
        lo, hi = relative_rate(slopes, levels, groups=groups).ci
        covered += lo <= 0.1 <= hi
    assert abs(covered / 2000 - 0.95) <= 3 * math.sqrt(0.95 * 0.05 / 2000)


def test_relative_rate_is_refused_for_unpaired_values():
    with pytest.raises(ConfigError, match=r"relative_rate needs slopes and levels of one shape"):
        relative_rate([1.0, 2.0], [1.0])
    with pytest.raises(ConfigError, match=r"needs slopes and levels and groups of one shape \(R,\), one value per "
                                          r"realization; got \(2,\) and \(2,\) and \(3,\)"):
        relative_rate([1.0, 2.0], [1.0, 1.0], groups=[0, 0, 1])
    with pytest.raises(ConfigError, match=r"The 'confidence' parameter of relative_rate must be in \(0, 1\)"):
        relative_rate([1.0, 2.0], [1.0, 1.0], confidence=1.0)
