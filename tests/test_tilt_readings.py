"""The readings of the appendix's tilt test (slidernet.validation.tilt_readings)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.analysis.trend import log_trend
from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.errors import ConfigError
from slidernet.kernels import Draws, new_state
from slidernet.kernels.tilt import tilt_test_pair
from slidernet.solver import Scene
from slidernet.validation.tilt_readings import (
    READINGS,
    claims,
    readings,
    realization_readings,
    study,
    tilt_test_incline,
)


def _cfg(mu_d: float = 0.5, std: float = 0.02, steps: int = 300, realizations: int = 3, seed: int = 5) -> dict:
    return {"seed": seed, "realizations": realizations, "steps": steps, "record": "log",
            "network": {"kind": "two_slider", "Ntilde": 1e-7},
            "friction": {"mu_d": mu_d, "static": {"name": "gaussian", "mean": 0.6, "std": std}},
            "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
            "observables": ["n", "mu_max", "mu_eff"]}


def _record():
    state = new_state()
    return state, state.view(np.recarray)[0]


def _draws(mu: list[float], u: list[float]) -> Draws:
    return Draws(np.empty(0), np.asarray(mu, float), np.asarray(u, float))


@pytest.mark.parametrize("mu_d,std", [(0.5, 0.02), (0.4, 0.06)], ids=["mu_d-0.5", "mu_d-0.4"])
def test_the_threshold_reading_is_the_solvers_mu_eff_to_the_bit(mu_d, std):
    """An independent transcription of the two sliders, on the same streams, gives slidernet.run's mu_eff."""
    cfg = _cfg(mu_d, std)
    mine = readings(cfg, ["threshold"])
    core = slidernet.run(cfg, progress=False)
    np.testing.assert_array_equal(mine["mu_eff"].sel(reading="threshold").values, core["mu_eff"].values)
    assert float(mine["r_mean"]) == float(core["n"].isel(t=-1).mean()) / cfg["steps"]


def test_every_reading_tests_the_same_evolution():
    """The readings change the test, never the horizontal evolution: one test per rearrangement, plus t = 0."""
    ds = readings(_cfg(), READINGS)
    counts = ds["count"].sum("t").values
    assert (counts == counts[0]).all()
    assert counts[0] == round(float(ds["r_mean"]) * 300 * 3) + 3


def test_the_readings_differ():
    """Copying after the slip changes the samples (the pre-slip copy has a slider at its threshold)."""
    ds = readings(_cfg(), ["threshold", "after"])
    a, b = ds["mu_eff"].values
    assert np.nanmax(np.abs(a - b)) > 1e-3


@given(mu1=st.floats(0.51, 0.8), mu2=st.floats(0.51, 0.8), F=st.floats(-0.4, 0.4))
@settings(max_examples=200, deadline=None)
def test_the_incline_onset_balances_the_forces(mu1, mu2, F):
    """Where the first slider starts, its tangential load, spring force and friction balance on the incline.

    A test that ends at once (the other slider dragged along, f > mu_d) returns tan(alpha) of that onset:
    slider 1 at sin a - F = mu1 cos a or slider 2 at sin a + F = mu2 cos a, whichever comes first.
    """
    _, rec = _record()
    f = tilt_test_incline(rec, _draws([], []), F, mu1, mu2, 0.5)
    if f < 0:  # needs draws: not this property's case
        return
    a = math.atan(f)
    r1 = math.sin(a) - F - mu1 * math.cos(a)
    r2 = math.sin(a) + F - mu2 * math.cos(a)
    assert min(abs(r1), abs(r2)) < 1e-12
    assert max(r1, r2) < 1e-12  # neither slider past its threshold before the onset


@given(mu1=st.floats(0.51, 0.8), mu2=st.floats(0.51, 0.8))
@settings(max_examples=100, deadline=None)
def test_without_spring_force_incline_and_linear_tests_agree(mu1, mu2):
    """With F = 0 a test that ends at its first onset gives the same tilt on the incline: tan(alpha) = min mu."""
    _, r1 = _record()
    _, r2 = _record()
    lin = tilt_test_pair(r1, _draws([], []), 0.0, mu1, mu2, 0.5, 2.0)
    inc = tilt_test_incline(r2, _draws([], []), 0.0, mu1, mu2, 0.5)
    assume(lin > 0)  # -1: the test needed draws (a slider rearranged first, F no longer 0)
    assert inc == pytest.approx(lin, rel=1e-12)
    assert lin == min(mu1, mu2)


def test_the_incline_weighs_the_spring_force_more():
    """A pair held back by its spring slides later on the exact incline: F / cos(alpha) > F."""
    _, r1 = _record()
    _, r2 = _record()
    draws = _draws([], [])
    # Slider 2 pulled back (F < 0) by 0.08, slider 1 pushed: both thresholds 0.6, mu_d = 0.5.
    lin = tilt_test_pair(r1, draws, -0.08, 0.6, 0.6, 0.5, 2.0)
    inc = tilt_test_incline(r2, draws, -0.08, 0.6, 0.6, 0.5)
    assert lin == pytest.approx(0.52)  # slider 1 first, at f = mu1 + F
    assert inc < lin  # -0.08 / cos(alpha) pulls harder: slider 1 starts earlier
    assert inc == pytest.approx(math.tan(math.atan(0.6) + math.asin(-0.08 / math.sqrt(1.36))), rel=1e-12)


@pytest.mark.parametrize("which,match", [(["sideways"], "'which' parameter of readings"),
                                         ([], "'which' parameter of readings")], ids=["unknown", "empty"])
def test_bad_readings_are_refused(which, match):
    with pytest.raises(ConfigError, match=match):
        readings(_cfg(), which)


def test_a_network_other_than_the_pair_is_refused():
    cfg = _cfg()
    cfg["network"] = {"kind": "chain", "n": 3, "Ntilde": 1e-7}
    cfg["observables"] = ["n", "mu_max"]
    with pytest.raises(ConfigError, match=r"'network\.kind' parameter of readings must be 'two_slider'"):
        readings(cfg)


def test_each_realizations_bin_means_are_its_own_tests():
    """mu_eff_realization[r] is realization r's own f_sum / f_count: the seeds of slidernet.run, in order."""
    cfg = _cfg(realizations=3)
    ds = readings(cfg, ["after"])
    scene = Scene.from_config(load_config(cfg))
    for r, seed in enumerate(realization_seeds(cfg["seed"], cfg["realizations"])):
        own = realization_readings(scene, seed, "after")
        with np.errstate(invalid="ignore", divide="ignore"):
            expected = own["f_sum"] / own["f_count"]  # NaN where this realization made no test
        mine = ds["mu_eff_realization"].sel(reading="after", realization=r).values
        np.testing.assert_array_equal(mine, expected)


def test_claims_per_realization_slopes_are_log_trends():
    """claims()'s per-realization slopes are log_trend's over 1 <= t <= t_end, times ln 10 (per decade)."""
    ds = study(300, 3, seed=7, cases=[(0.5, 0.2)], which=["threshold", "incline"], progress=False)
    cases = claims(ds)["cases"]
    assert [c["reading"] for c in cases] == ["threshold", "incline"]
    for c in cases:
        tr = log_trend(ds["mu_eff_realization"].isel(case=0).sel(reading=c["reading"]), t_min=1.0)
        per_decade = math.log(10) * tr["slope"].values
        np.testing.assert_allclose(c["slope_per_decade_realizations"], per_decade, rtol=1e-14)
        assert c["slope_per_decade_realizations_mean"] == pytest.approx(per_decade.mean(), rel=1e-12)
        assert c["slope_per_decade_realizations_sem"] == pytest.approx(per_decade.std(ddof=1) / math.sqrt(3),
                                                                       rel=1e-12)
        assert c["slope_per_decade_realizations_negative"] == int((per_decade < 0).sum())
        assert c["slope_realizations"] == 3


def _lines(slopes: list[float], gap: int | None = None) -> xr.Dataset:
    """A dataset shaped as study()'s: one case, one reading, realization r on mu = 0.55 + slopes[r] log10 t.

    ``gap``: a time bin where realization 0 made no test (NaN).
    """
    t = np.concatenate([[0.0], np.logspace(0, 5, 51)])
    x = np.log10(np.maximum(t, 1.0))
    per = np.array([0.55 + b * x for b in slopes])
    if gap is not None:
        per[0, gap] = np.nan
    pooled = np.nanmean(per, axis=0)
    dims = ("case", "reading", "t")
    ds = xr.Dataset({"mu_eff": (dims, pooled[None, None]),
                     "mu_eff_sem": (dims, np.full((1, 1, t.size), 1e-3)),
                     "mu_eff_realization": (("case", "reading", "realization", "t"), per[None, None]),
                     "phi": (dims, (pooled[None, None] - 0.6) / 0.01),
                     "rt": (dims, t[None, None])},
                    coords={"case": [0], "reading": ["threshold"], "realization": np.arange(len(slopes)), "t": t,
                            "mu_d": ("case", [0.5]), "ratio": ("case", [0.1]), "sigma_mu": ("case", [0.01])})
    return ds


def test_claims_on_exact_lines_worked_by_hand():
    """Three realizations on exact lines of -0.001, +0.002, +0.005 per decade.

    Slopes (-1, 2, 5) e-3: mean 2e-3, std 3e-3, SE 3e-3 / sqrt(3) = sqrt(3) e-3; one negative. The pooled
    bins lie on the mean line, so the weighted fit of the pooled values is the mean slope too.
    """
    c = claims(_lines([-0.001, 0.002, 0.005]))["cases"][0]
    np.testing.assert_allclose(c["slope_per_decade_realizations"], [-0.001, 0.002, 0.005], rtol=1e-10)
    assert c["slope_per_decade_realizations_mean"] == pytest.approx(0.002, rel=1e-10)
    assert c["slope_per_decade_realizations_sem"] == pytest.approx(math.sqrt(3) * 1e-3, rel=1e-10)
    assert c["slope_per_decade_realizations_negative"] == 1
    assert c["slope_realizations"] == 3
    assert c["slope_per_decade_pooled"] == pytest.approx(0.002, rel=1e-10)


def test_a_bin_without_test_is_left_out_of_that_realizations_fit():
    """A NaN bin (no test there) leaves a realization on an exact line with the same slope."""
    c = claims(_lines([-0.001, 0.002, 0.005], gap=20))["cases"][0]
    np.testing.assert_allclose(c["slope_per_decade_realizations"], [-0.001, 0.002, 0.005], rtol=1e-10)
    assert c["slope_realizations"] == 3
