"""Steady against logarithmic creep (analysis.trend.creep_law), on x_G(t) worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from hypothesis import given
from hypothesis import strategies as st

from slidernet.analysis.trend import creep_law
from slidernet.errors import ConfigError

T = np.array([0.0, 1.0, 10.0, 100.0])


def series(rows, t=T) -> xr.DataArray:
    return xr.DataArray(np.asarray(rows, dtype=float), dims=("realization", "t"),
                        coords={"t": t, "realization": np.arange(len(rows))},
                        attrs={"units": "l0"})


def test_two_realizations_by_hand():
    # Windows [1, 10] and [10, 100]. Realization 0: x = 0, 9, 99 -> v_early 1, v_late 1;
    # realization 1: x = 0, 27, 207 -> v_early 3, v_late 2.
    out = creep_law(series([[0, 0, 9, 99], [0, 0, 27, 207]]))
    assert (out.attrs["t1"], out.attrs["t2"], out.attrs["t3"]) == (1.0, 10.0, 100.0)
    np.testing.assert_allclose(out["v_early"], [1, 3])
    np.testing.assert_allclose(out["v_late"], [1, 2])
    # <v_early> = 2 +- std([1, 3]) / sqrt 2 = 1; <v_late> = 1.5 +- 0.5.
    np.testing.assert_allclose([out["v_early_mean"], out["v_early_sem"]], [2, 1])
    np.testing.assert_allclose([out["v_late_mean"], out["v_late_sem"]], [1.5, 0.5])
    # rho = 1.5 / 2 = 0.75; linearised terms (v_late - 0.75 v_early) / 2 = [0.125, -0.125]:
    # standard error std([0.125, -0.125]) / sqrt 2 = 0.125.
    np.testing.assert_allclose([out["ratio"], out["ratio_sem"]], [0.75, 0.125])
    # Logarithmic creep over two decades: (ln 10 / 90) / (ln 10 / 9) = 0.1.
    np.testing.assert_allclose(out["ratio_log"], 0.1)
    assert float(out["ratio_steady"]) == 1.0
    # Steady: g = v_late - v_early = [0, -1]: -0.5 +- 0.5, within 2 SE.
    np.testing.assert_allclose([out["steady_gap_mean"], out["steady_gap_sem"]], [-0.5, 0.5])
    # Log: g = v_late - 0.1 v_early = [0.9, 1.7]: 1.3 +- 0.4, beyond 2 SE.
    np.testing.assert_allclose([out["log_gap_mean"], out["log_gap_sem"]], [1.3, 0.4])
    assert bool(out["steady_consistent"]) and not bool(out["log_consistent"])
    assert out.attrs["verdict"] == "steady: logarithmic creep rejected"
    # <v_early> = 2 is 2 SE from 0: not resolved at z = 2 (strictly more is needed).
    assert not bool(out["early_resolved"])
    assert int(out["realizations"]) == 2
    assert out["v_early"].attrs["units"] == "l0 / tau_th"


def test_the_log_prediction_uses_the_recorded_times():
    # Log records rarely hold t_max / 10 exactly: the nearest recorded times in ln t serve, and the
    # log law's ratio is computed from them, so an exact x = c ln t still meets it to rounding.
    t = np.array([0, 1, 2, 3, 9, 11, 90, 110, 1000.0])
    c = np.array([[0.5], [2.0], [4.0]])
    out = creep_law(series(c * np.log(np.maximum(t, 1)), t=t))
    t1, t2, t3 = out.attrs["t1"], out.attrs["t2"], out.attrs["t3"]
    assert (t1, t2, t3) == (11.0, 110.0, 1000.0)
    expected = (math.log(t3 / t2) / (t3 - t2)) / (math.log(t2 / t1) / (t2 - t1))
    np.testing.assert_allclose(out["ratio_log"], expected, rtol=1e-12)
    np.testing.assert_allclose(out["ratio"], expected, rtol=1e-12)
    assert out.attrs["verdict"] == "logarithmic: steady creep rejected"


def test_an_early_velocity_near_zero_leaves_the_verdicts_valid():
    # One realization does not move early and another moves backwards: per-realization ratios
    # would be infinite and negative; the contrasts still test each law.
    rows = [[0, 0, 0, 90], [0, 0, -9, 81], [0, 0, 9, 99]]   # v_early 0, -1, 1; v_late 1, 1, 1
    out = creep_law(series(rows))
    assert float(out["v_early_mean"]) == 0.0
    assert not bool(out["early_resolved"]) and math.isnan(float(out["ratio"]))
    # Steady: g = [1, 2, 0], 1 +- 1/sqrt 3: within 2 SE. Log: g = [1, 1.1, 0.9], 1 +- 0.0577: rejected.
    np.testing.assert_allclose([out["steady_gap_mean"], out["steady_gap_sem"]], [1, 1 / math.sqrt(3)])
    assert out.attrs["verdict"] == "steady: logarithmic creep rejected"


def test_a_realization_with_nan_is_left_out():
    out = creep_law(series([[0, 0, 9, 99], [0, 0, np.nan, 207], [0, 0, 9, 99]]))
    assert int(out["realizations"]) == 2
    assert math.isnan(float(out["v_early"][1])) and math.isnan(float(out["v_late"][1]))
    np.testing.assert_allclose(out["v_early_mean"], 1.0)


def test_one_realization_gives_no_verdict():
    out = creep_law(series([[0, 0, 9, 99]]))
    assert math.isnan(float(out["v_early_sem"]))
    assert out.attrs["verdict"] == "neither law: both rejected"


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"t_max": -1}, r"The 't_max' parameter of creep_law must be > 0\. Got -1\.0 instead\."),
        ({"t_max": 1000}, r"The 't_max' parameter of creep_law must be <= the last recorded time 100\.0\. "
                          r"Got 1000\.0 instead\."),
        ({"factor": 1}, r"The 'factor' parameter of creep_law must be > 1\. Got 1\.0 instead\."),
        ({"factor": "10"}, r"The 'factor' parameter of creep_law must be a real number > 1\. Got '10' instead\."),
        ({"z": 0}, r"The 'z' parameter of creep_law must be > 0\. Got 0\.0 instead\."),
        ({"factor": 20}, r"the early window starts at t_max / factor\*\*2 = 0\.25, before the first recorded"),
        ({"t_max": 10, "factor": 1.5}, r"not three distinct times"),
    ],
    ids=["t_max<0", "t_max-past-end", "factor=1", "factor-str", "z=0", "too-wide", "too-few-times"],
)
def test_bad_parameters_are_refused(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        creep_law(series([[0, 0, 9, 99], [0, 0, 27, 207]]), **kwargs)


def test_bad_values_are_refused():
    with pytest.raises(ConfigError, match=r"creep_law needs values of dims \(realization, t\)"):
        creep_law(xr.DataArray(T, dims=("t",), coords={"t": T}))
    with pytest.raises(ConfigError, match=r"creep_law needs finite, increasing recorded times t"):
        creep_law(series([[0, 0, 9, 99]], t=np.array([0.0, 10.0, 1.0, 100.0])))
    with pytest.raises(ConfigError, match=r"fewer than three recorded times t > 0"):
        creep_law(series([[0, 1, 2]], t=np.array([0.0, 1.0, 2.0])))


@given(
    scale=st.floats(1e-9, 1e9),
    offsets=st.lists(st.floats(-1e3, 1e3), min_size=4, max_size=4),
    seed=st.integers(0, 2**32 - 1),
)
def test_invariant_under_scaling_and_offsets(scale, offsets, seed):
    # The laws compare shapes of x_G(t): a change of length unit scales every velocity and
    # error and leaves the ratio, the predictions and the verdicts alone; a constant offset per
    # realization (x_G measured from elsewhere) changes nothing.
    rng = np.random.default_rng(seed)
    t = np.array([0, 1, 3, 10, 30, 100, 300, 1000.0])
    x = np.cumsum(rng.exponential(1.0, (4, t.size)), axis=1) * (0.5 + t) ** rng.uniform(0, 1)
    base = creep_law(series(x, t=t))
    moved = creep_law(series(scale * x + np.asarray(offsets)[:, None] * scale, t=t))
    for name in ("v_early", "v_late", "v_early_sem", "steady_gap_mean", "log_gap_sem"):
        np.testing.assert_allclose(moved[name], scale * base[name], rtol=1e-6, atol=0)
    for name in ("ratio", "ratio_sem", "ratio_log"):
        np.testing.assert_allclose(moved[name], base[name], rtol=1e-6)
    assert moved.attrs["verdict"] == base.attrs["verdict"] or _near_threshold(base)


def _near_threshold(out: xr.Dataset) -> bool:
    """Whether a contrast sits within rounding of z SE, where a scaling may flip its verdict."""
    z = out.attrs["z"]
    return any(abs(abs(float(out[f"{h}_gap_mean"])) - z * float(out[f"{h}_gap_sem"]))
               <= 1e-6 * abs(float(out[f"{h}_gap_mean"])) for h in ("steady", "log"))
