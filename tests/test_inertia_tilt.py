"""The dynamic tilt test (``[dynamics] tilt_rate``) against the reference integrator, and the zero-rate fit."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import slidernet
from slidernet.analysis.tilt_rate import zero_rate
from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.errors import ConfigError, TiltTestError
from slidernet.solver import Realization, Scene, inertia_tilt
from slidernet.solver.streams import realization_streams
from slidernet.validation.dynamics import Dynamics

NETWORKS = {
    "pair": {"kind": "two_slider", "Ntilde": 1e-7},
    "chain6": {"kind": "chain", "n": 6, "Ntilde": 1e-7},
    "triangular3x3": {"kind": "triangular", "shape": [3, 3], "Ntilde": 1e-7},
}


def config(network: str, rate: float | None, steps: int = 5, **more) -> dict:
    return {"seed": 5, "realizations": 2, "steps": steps, "record": [steps], "network": NETWORKS[network],
            "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.03}},
            "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7},
            "dynamics": {"tau_ratio": 1e-3, **({} if rate is None else {"tilt_rate": rate})},
            "observables": ["n", "mu_eff", "tilt_loads"], "mu_eff_at": "records", "execution": {"workers": 1},
            **more}


def state_at(network: str, rate: float, steps: int = 5, seed: int = 0) -> Realization:
    """A realization run to ``steps`` without the tilt tests on the way: its tilt stream is unread, so the
    reference fed the stream's own Generator reads the same thresholds."""
    scene = Scene.from_config(load_config(config(network, rate, steps)))
    real = Realization(scene, realization_seeds(5, seed + 1)[seed])
    real._run_kernel(steps, None)
    return real


def tilt_generator(seed: int = 0) -> np.random.Generator:
    """The tilt stream's Generator of realization ``seed``, as it was before any draw."""
    return realization_streams(realization_seeds(5, seed + 1)[seed])["tilt"]


@pytest.mark.parametrize("network, rate, tol", [
    ("pair", 1e-3, 1e-12), ("pair", 3e-2, 1e-12), ("chain6", 1e-3, 1e-12), ("triangular3x3", 1e-3, 1e-8),
], ids=["pair", "pair-fast", "chain6", "triangular3x3"])
def test_the_dynamic_tilt_test_is_the_reference_integrators(network, rate, tol):
    real = state_at(network, rate)
    scene = real.scene
    mu = real.mu.copy()
    u = real.displacements()
    theta = (real.state["theta"][0] - real.thetas[0]) * scene.network.Ntilde
    f = real.tilt_test(mu.copy(), advance=False)
    loads = real._dynamic_loads
    ref = Dynamics(scene, tau_ratio=1e-3).tilt_test(u[:, 0] if scene.network.dim == 1 else u, mu,
                                                     tilt_generator(), theta=theta,
                                                     rate=rate)
    assert ref["starts"] >= 2
    assert f == pytest.approx(ref["mu_eff"], abs=tol)
    assert loads["tilt_first_slip"] == pytest.approx(ref["first_start"], abs=tol)
    assert loads["tilt_all_moving"] == pytest.approx(ref["all_moving"], abs=tol)
    # A stuck contact's force is continuous under the equations of motion: every contact starts at its
    # threshold, so the mean local ratio at the breaks is the mean tested threshold (both weighted by N_i).
    N = scene.operators.normal_load
    assert loads["tilt_break_ratio"] == pytest.approx(float(N @ mu / N.sum()), abs=1e-12)
    assert loads["tilt_first_slip"] <= loads["tilt_half_broken"] <= loads["tilt_all_moving"]


def test_the_rate_changes_the_sample_and_the_quasi_static_test_stays_without_it():
    real = state_at("pair", 1e-4, seed=1)
    samples = []
    for rate in (1e-4, 3e-2, None):
        real.scene = replace(real.scene, dynamics=real.scene.dynamics._replace(tilt_rate=rate))
        samples.append(real.tilt_test(advance=False))
    slow, fast, quasi_static = samples
    assert fast != slow
    # The quasi-static network test of the same state, as without tilt_rate.
    plain = state_at("pair", 1e-4, seed=1)
    plain.scene = replace(plain.scene, dynamics=plain.scene.dynamics._replace(tilt_rate=None))
    assert quasi_static == plain.tilt_test(advance=False)


def test_a_run_with_tilt_rate_records_the_dynamic_samples():
    cfg = config("triangular3x3", 1e-3, steps=4)
    ds = slidernet.run(cfg, progress=False)
    assert (ds["mu_eff_count"].values == 2).all()
    assert np.isfinite(ds["mu_eff"].values).all() and np.isfinite(ds["tilt_break_ratio"].values).all()
    # The samples at t = 4 are the tests of the states there, after the tests at t = 0.
    samples = []
    for ss in realization_seeds(5, 2):
        real = Realization(Scene.from_config(load_config(cfg)), ss).advance(0)
        real._run_kernel(4, None)
        samples.append(real.tilt_test())
    assert float(ds["mu_eff"].values[-1]) == pytest.approx(np.mean(samples), abs=1e-15)


def test_a_test_that_does_not_slide_by_the_cap_says_so(monkeypatch):
    real = state_at("pair", 1e-6)
    monkeypatch.setattr(inertia_tilt, "TILT_CAP", 0.05)
    with pytest.raises(TiltTestError, match=r"reached the load f = .* \(TILT_CAP\) without sliding for good"):
        real.tilt_test(advance=False)


@pytest.mark.parametrize("rate", [0.0, -1e-3, float("nan")], ids=["zero", "negative", "nan"])
def test_tilt_rate_must_be_a_positive_number(rate):
    with pytest.raises(ConfigError, match=r"'dynamics.tilt_rate'"):
        load_config(config("pair", rate))


def test_the_linear_fit_keeps_the_pairing_and_its_error_is_the_intercepts_spread():
    rng = np.random.default_rng(0)
    rates = np.array([1e-4, 1e-3, 3e-3, 1e-2])
    level = 0.56 + 0.01 * rng.standard_normal(50)  # a state's own level, shared by its rates
    y = level[:, None] - 1.5 * rates + 1e-4 * rng.standard_normal((50, 4))
    out = zero_rate(rates, y)
    X = np.stack([np.ones(4), rates], axis=1)
    intercepts = np.linalg.lstsq(X, y.T, rcond=None)[0][0]
    assert out.mu_eff == pytest.approx(intercepts.mean(), abs=1e-15)
    assert out.se == pytest.approx(intercepts.std(ddof=1) / np.sqrt(50), rel=1e-12)
    assert out.slope == pytest.approx(-1.5, abs=0.05) and out.exponent == 1.0


def test_the_power_fit_finds_the_exponent_and_the_level():
    rates = np.array([1e-4, 3e-4, 1e-3, 3e-3, 1e-2])
    rng = np.random.default_rng(1)
    y = 0.56 + 0.01 * rng.standard_normal((30, 1)) - 0.2 * rates ** 0.5
    out = zero_rate(rates, y, model="power")
    assert out.exponent == pytest.approx(0.5, abs=1e-4)
    assert out.slope == pytest.approx(-0.2, rel=1e-3)
    assert out.mu_eff == pytest.approx(float(np.mean(y[:, 0] + 0.2 * rates[0] ** 0.5)), abs=1e-6)
    assert 0 < out.se < 0.01


@pytest.mark.parametrize("rates, mu_eff, model, match", [
    ([1e-3, 2e-3], [[0.5, 0.5], [0.5, 0.5]], "linear", "at least 3 distinct ramp rates"),
    ([1e-3, 1e-3, 2e-3], [[0.5] * 3] * 2, "linear", "at least 3 distinct ramp rates"),
    ([0.0, 1e-3, 2e-3], [[0.5] * 3] * 2, "linear", r"'rates' parameter of zero_rate must be > 0"),
    ([1e-3, 2e-3, 3e-3], [[0.5] * 3], "linear", r"shape \(R, 3\) with R >= 2"),
    ([1e-3, 2e-3, 3e-3], [[0.5] * 3] * 2, "cubic", "one of"),
], ids=["two-rates", "repeated", "zero-rate", "one-realization", "model"])
def test_zero_rate_refuses_what_it_cannot_fit(rates, mu_eff, model, match):
    with pytest.raises(ConfigError, match=match):
        zero_rate(rates, mu_eff, model)


def test_a_run_with_dynamic_tilt_tests_stopped_saved_and_resumed_gives_the_same_bits(tmp_path):
    from slidernet.io.checkpoint import load_realization, save_realization

    cfg = config("pair", 1e-3, steps=12, record="all", solver={"batch": 4})
    scene = Scene.from_config(load_config(cfg))
    ss = realization_seeds(5, 1)[0]
    whole = Realization(scene, ss).advance().result()
    real = Realization(scene, ss).advance(6)
    path = save_realization(real, tmp_path / "r.npz", {"run": "test"})
    resumed = load_realization(scene, ss, path, expect_meta={"run": "test"}).advance().result()
    for name in ("f_sum", "f_sq", "f_count", "tilt_all_moving", "tilt_break_ratio", "n"):
        np.testing.assert_array_equal(resumed[name], whole[name], err_msg=name)
    assert np.isfinite(whole["f_sum"]).all() and (whole["f_count"] == 1).all()


@pytest.mark.parametrize("network", ["pair", "triangular3x3"])
def test_the_quasi_static_tests_break_ratio_is_at_or_above_the_mean_threshold(network):
    # There a slip moves a neighbour's force by a finite jump, which may carry it past its threshold; under the
    # equations of motion the force is continuous (the test against the reference above: equal).
    real = state_at(network, 1e-3)
    N = real.scene.operators.normal_load
    mean = float(N @ real.mu / N.sum())
    _, _, dynamic = real._one_tilt_test(real.mu.copy(), False)
    real.scene = replace(real.scene, dynamics=real.scene.dynamics._replace(tilt_rate=None))
    _, _, quasi_static = real._one_tilt_test(real.mu.copy(), False)
    assert dynamic["tilt_break_ratio"] == pytest.approx(mean, abs=1e-12)
    assert quasi_static["tilt_break_ratio"] > mean + 1e-3


def test_a_power_law_the_rates_cannot_determine_is_flagged():
    rates = np.array([1e-4, 2e-4, 5e-4])
    y = 0.51 + np.array([[0.0, 1e-4, -1e-4], [0.01, 0.0101, 0.0099]])  # no trend at all
    with pytest.warns(RuntimeWarning, match="exponent sits at the end of its range"):
        zero_rate(rates, y, model="power")
