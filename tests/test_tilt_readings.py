"""The readings of the appendix's tilt test (slidernet.validation.tilt_readings)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.errors import ConfigError
from slidernet.kernels import Draws, new_state
from slidernet.kernels.tilt import tilt_test_pair
from slidernet.validation.tilt_readings import READINGS, readings, tilt_test_incline


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
    lin = tilt_test_pair(r1, _draws([], []), 0.0, mu1, mu2, 0.5)
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
    lin = tilt_test_pair(r1, draws, -0.08, 0.6, 0.6, 0.5)
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
