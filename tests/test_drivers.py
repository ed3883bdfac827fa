"""Built-in temperature drivers: validation, shape, determinism, statistics, and end-to-end runs."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import slidernet
from slidernet import ConfigError
from slidernet.plugins import registry
from slidernet.plugins.drivers import BUILTINS, GaussianSteps, OrnsteinUhlenbeck, Ramp, Series, Sinusoidal
from tests.conftest import make_config

# A series of 101 samples every 30 s (times 0 ... 3000 s): with tau_th = 60 s it covers 50 steps.
SERIES_TIMES = 30.0 * np.arange(101)
SERIES_TEMPS = 20.0 + 0.1 * np.sin(SERIES_TIMES / 200.0) + 0.05 * np.cos(SERIES_TIMES / 37.0)


def write_csv(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def series_csv(tmp_path_factory) -> Path:
    """A valid recorded series, with a header (module scope: usable under hypothesis)."""
    rows = zip(SERIES_TIMES.tolist(), SERIES_TEMPS.tolist(), strict=True)
    lines = ["time_s,temperature_C"] + [f"{t!r},{T!r}" for t, T in rows]
    return write_csv(tmp_path_factory.mktemp("series") / "T.csv", "\n".join(lines) + "\n")


def driver_params(series_csv: Path) -> dict[str, dict]:
    """Valid parameters of every built-in driver, sized for the reference Ntilde = 1e-7."""
    return {
        "gaussian_steps": {"sigma_theta": 1e-6},
        "ornstein_uhlenbeck": {"sigma_theta": 1e-6, "tau_c": 3.0},
        "sinusoidal": {"amplitude": 1e-6, "period": 10.0, "noise_std": 1e-7},
        "ramp": {"rate": 1e-7, "period": 20.0},
        "constant": {"theta0": 1e-7},
        "series": {"path": str(series_csv), "kappa": 1e-5, "T0": 20.0, "tau_th": 60.0},
    }


def test_builtins_are_registered():
    assert set(BUILTINS) == {"gaussian_steps", "ornstein_uhlenbeck", "sinusoidal", "ramp", "constant", "series"}
    assert set(BUILTINS) <= set(registry.drivers.names())


# --- validation -------------------------------------------------------------------------------------------

BAD_PARAMS = [
    (GaussianSteps, {"sigma_theta": -1e-6},
     r"^The 'sigma_theta' parameter of gaussian_steps must be > 0\. Got -1e-06 instead\.$"),
    (GaussianSteps, {"sigma_theta": math.nan}, r"'sigma_theta' parameter of gaussian_steps must be finite and > 0"
                                               r"\. Got nan instead"),
    (GaussianSteps, {"sigma_theta": "1e-6"}, r"must be a real number > 0\. Got '1e-6' instead"),
    (GaussianSteps, {"sigma_theta": True}, r"must be a real number > 0\. Got True instead"),
    (OrnsteinUhlenbeck, {"sigma_theta": 0.0, "tau_c": 1.0},
     r"^The 'sigma_theta' parameter of ornstein_uhlenbeck must be > 0\. Got 0\.0 instead\.$"),
    (OrnsteinUhlenbeck, {"sigma_theta": 1e-6, "tau_c": -1.0},
     r"'tau_c' parameter of ornstein_uhlenbeck must be > 0\. Got -1\.0"),
    (OrnsteinUhlenbeck, {"sigma_theta": 1e-6, "tau_c": math.inf}, r"'tau_c' .* must be finite and > 0\. Got inf"),
    (OrnsteinUhlenbeck, {"sigma_theta": 1e-6, "tau_c": 1.0, "theta0": math.nan},
     r"'theta0' parameter of ornstein_uhlenbeck must be finite\. Got nan"),
    (Sinusoidal, {"amplitude": -1.0, "period": 24.0},
     r"'amplitude' parameter of sinusoidal must be >= 0\. Got -1\.0"),
    (Sinusoidal, {"amplitude": 1.0, "period": 0}, r"'period' parameter of sinusoidal must be > 0\. Got 0\.0"),
    (Sinusoidal, {"amplitude": 1.0, "period": math.inf}, r"'period' .* must be finite and > 0"),
    (Sinusoidal, {"amplitude": 1.0, "period": 24.0, "phase": math.nan}, r"'phase' .* must be finite\. Got nan"),
    (Sinusoidal, {"amplitude": 1.0, "period": 24.0, "noise_std": -0.1},
     r"'noise_std' .* must be >= 0\. Got -0\.1"),
    (Sinusoidal, {"amplitude": 0.0, "period": 24.0, "noise_std": 0.0},
     r"^The 'amplitude' parameter of sinusoidal must be > 0 when noise_std = 0\. Got 0\.0 instead\.$"),
    (Sinusoidal, {"amplitude": 1.0, "period": "24"}, r"'period' .* must be a real number > 0\. Got '24'"),
    (Ramp, {"rate": 0}, r"^The 'rate' parameter of ramp must be != 0\. Got 0\.0 instead\.$"),
    (Ramp, {"rate": math.nan}, r"'rate' parameter of ramp must be finite and != 0"),
    (Ramp, {"rate": 1.0, "theta0": -math.inf}, r"'theta0' parameter of ramp must be finite\. Got -inf"),
    (Ramp, {"rate": 1.0, "period": 0.0}, r"'period' parameter of ramp must be > 0\. Got 0\.0"),
    (Ramp, {"rate": 1.0, "period": -4}, r"'period' parameter of ramp must be > 0\. Got -4\.0"),
]


@pytest.mark.parametrize(
    ("factory", "params", "match"), BAD_PARAMS,
    ids=["gs-negative", "gs-nan", "gs-string", "gs-bool", "ou-sigma-zero", "ou-tau-negative", "ou-tau-inf",
         "ou-theta0-nan", "sin-amplitude-negative", "sin-period-zero", "sin-period-inf", "sin-phase-nan",
         "sin-noise-negative", "sin-constant", "sin-period-string", "ramp-rate-zero", "ramp-rate-nan",
         "ramp-theta0-inf", "ramp-period-zero", "ramp-period-negative"],
)
def test_invalid_parameters_are_refused(factory, params, match):
    with pytest.raises(ConfigError, match=match):
        factory(**params)


@pytest.mark.parametrize(
    ("change", "match"),
    [({"kappa": 0.0}, r"^The 'kappa' parameter of series must be != 0\. Got 0\.0 instead\.$"),
     ({"T0": math.nan}, r"'T0' parameter of series must be finite\. Got nan"),
     ({"tau_th": 0}, r"'tau_th' parameter of series must be > 0\. Got 0\.0"),
     ({"tau_th": -60.0}, r"'tau_th' parameter of series must be > 0\. Got -60\.0"),
     ({"t0": -1.0}, r"'t0' parameter of series must be within the series' times \[0\.0, 3000\.0\]\. Got -1\.0"),
     ({"t0": 3000.5}, r"'t0' parameter of series must be within"),
     ({"delimiter": ";;"}, r"'delimiter' parameter of series must be one character"),
     ({"path": None}, r"'path' parameter of series must be a non-empty path\. Got None"),
     ({"path": ""}, r"'path' parameter of series must be a non-empty path")],
    ids=["kappa-zero", "T0-nan", "tau_th-zero", "tau_th-negative", "t0-before", "t0-after", "delimiter",
         "path-none", "path-empty"],
)
def test_series_invalid_parameters_are_refused(series_csv, change, match):
    params = {"path": series_csv, "kappa": 1e-5, "T0": 20.0, "tau_th": 60.0, **change}
    with pytest.raises(ConfigError, match=match):
        Series(**params)


# --- shape, finiteness, determinism -----------------------------------------------------------------------

def make_driver(name: str, series_csv: Path):
    return BUILTINS[name](**driver_params(series_csv)[name])


@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(sorted(BUILTINS)), steps=st.integers(0, 50), seed=st.integers(0, 2**32 - 1))
def test_shape_and_finiteness(series_csv, name, steps, seed):
    theta = make_driver(name, series_csv).thetas(np.random.default_rng(seed), steps)
    assert theta.shape == (steps + 1,)
    assert theta.dtype == np.float64
    assert np.isfinite(theta).all()


positive = st.floats(1e-12, 1e3)


@settings(max_examples=60, deadline=None)
@given(
    driver=st.one_of(
        st.builds(GaussianSteps, positive),
        st.builds(OrnsteinUhlenbeck, positive, positive, st.floats(-1e3, 1e3)),
        st.builds(Sinusoidal, positive, positive, st.floats(-10, 10), st.floats(0, 1e3), st.floats(-1e3, 1e3)),
        st.builds(Ramp, st.floats(1e-12, 1e3) | st.floats(-1e3, -1e-12), st.floats(-1e3, 1e3),
                  st.none() | positive),
    ),
    steps=st.integers(0, 2000),
)
def test_shape_and_finiteness_for_any_parameters(driver, steps):
    theta = driver.thetas(np.random.default_rng(0), steps)
    assert theta.shape == (steps + 1,)
    assert np.isfinite(theta).all()


@pytest.mark.parametrize("name", sorted(BUILTINS))
def test_same_seed_same_thetas(series_csv, name):
    first = make_driver(name, series_csv).thetas(np.random.default_rng(42), 50)
    again = make_driver(name, series_csv).thetas(np.random.default_rng(42), 50)
    assert first.tobytes() == again.tobytes()
    other = make_driver(name, series_csv).thetas(np.random.default_rng(43), 50)
    random = name in {"gaussian_steps", "ornstein_uhlenbeck", "sinusoidal"}
    assert (first.tobytes() != other.tobytes()) == random


@pytest.mark.parametrize(
    "driver",
    [Ramp(rate=1.0), Ramp(rate=1.0, period=4.0), Sinusoidal(amplitude=1.0, period=24.0)],
    ids=["ramp", "triangle", "sinusoidal-no-noise"],
)
def test_deterministic_drivers_leave_the_rng_alone(driver):
    rng = np.random.default_rng(7)
    state = rng.bit_generator.state
    driver.thetas(rng, 100)
    assert rng.bit_generator.state == state


def test_gaussian_steps_draws_are_the_papers():
    # Kept bit-identical: sigma_theta times one standard_normal(steps + 1) call.
    theta = GaussianSteps(sigma_theta=1e-6).thetas(np.random.default_rng(3), 100)
    assert theta.tobytes() == (1e-6 * np.random.default_rng(3).standard_normal(101)).tobytes()


# --- Ornstein-Uhlenbeck -----------------------------------------------------------------------------------

def test_ou_stationary_std_and_lag1_autocorrelation():
    # seed 2024, 200 001 samples, tau_c = 5: the estimators' standard errors are about 0.36 % (std, relative)
    # and 0.0013 (lag-1 autocorrelation, absolute); the tolerances are 2 % and 0.01, over 5 standard errors.
    sigma, tau_c = 2e-6, 5.0
    theta = OrnsteinUhlenbeck(sigma_theta=sigma, tau_c=tau_c, theta0=1e-5).thetas(np.random.default_rng(2024),
                                                                                 200_000)
    y = theta - 1e-5
    assert abs(theta.mean() - 1e-5) < 0.05 * sigma  # standard error of the mean: 0.0067 sigma
    assert theta.std() == pytest.approx(sigma, rel=0.02)
    lag1 = np.dot(y[:-1], y[1:]) / np.dot(y, y)
    assert lag1 == pytest.approx(math.exp(-1 / tau_c), abs=0.01)
    lag5 = np.dot(y[:-5], y[5:]) / np.dot(y, y)
    assert lag5 == pytest.approx(math.exp(-5 / tau_c), abs=0.02)


def test_ou_starts_stationary():
    # seed 11, 4000 independent paths of 20 steps with tau_c = 50 (far from decorrelated at q = 20): the std
    # across paths at q = 0 and q = 20 is sigma both times; standard error 1.1 %, tolerance 5 %.
    ou = OrnsteinUhlenbeck(sigma_theta=1.0, tau_c=50.0)
    rng = np.random.default_rng(11)
    paths = np.array([ou.thetas(rng, 20) for _ in range(4000)])
    assert paths[:, 0].std() == pytest.approx(1.0, rel=0.05)
    assert paths[:, 20].std() == pytest.approx(1.0, rel=0.05)


def test_ou_short_correlation_time_is_gaussian_steps():
    # e^{-1/tau_c} underflows to 0 and sqrt(1 - 0) = 1: exactly the paper's independent draws.
    ou = OrnsteinUhlenbeck(sigma_theta=1e-6, tau_c=1e-3).thetas(np.random.default_rng(5), 100)
    gs = GaussianSteps(sigma_theta=1e-6).thetas(np.random.default_rng(5), 100)
    assert ou.tobytes() == gs.tobytes()


def test_ou_long_correlation_time_moves_slowly():
    # seed 8, tau_c = 1e6: increments have std sigma sqrt(2 (1 - e^{-1/tau_c})) = 1.414e-3 sigma; 10 000
    # increments give a standard error of 0.7 %, tolerance 5 %.
    theta = OrnsteinUhlenbeck(sigma_theta=1.0, tau_c=1e6).thetas(np.random.default_rng(8), 10_000)
    assert np.diff(theta).std() == pytest.approx(math.sqrt(-2 * math.expm1(-1e-6)), rel=0.05)


# --- sinusoidal -------------------------------------------------------------------------------------------

def test_sinusoidal_is_periodic_to_the_bit():
    theta = Sinusoidal(amplitude=3e-6, period=24, phase=0.3).thetas(np.random.default_rng(0), 24 * 40)
    assert np.array_equal(theta[24:], theta[:-24])
    assert theta.max() <= 3e-6 and theta.min() >= -3e-6


def test_sinusoidal_values():
    theta = Sinusoidal(amplitude=2.0, period=7.5, phase=-1.0, theta0=0.5).thetas(np.random.default_rng(0), 30)
    t = np.arange(31)
    np.testing.assert_allclose(theta, 0.5 + 2.0 * np.sin(2 * np.pi * t / 7.5 - 1.0), rtol=0, atol=1e-13)
    # Dominant period from the spectrum of a longer, noisy cycle: seed 4, noise 0.5 amplitude.
    long = Sinusoidal(amplitude=1.0, period=50, noise_std=0.5).thetas(np.random.default_rng(4), 4999)
    power = np.abs(np.fft.rfft(long)) ** 2
    assert np.argmax(power[1:]) + 1 == 5000 // 50


def test_sinusoidal_noise():
    # seed 9, 100 001 samples: the residual after removing the cycle has std noise_std (standard error 0.22 %,
    # tolerance 2 %) and mean 0 (standard error 0.0032 noise_std, tolerance 0.02 noise_std).
    steps, amplitude, noise = 100_000, 1e-6, 3e-7
    theta = Sinusoidal(amplitude=amplitude, period=24, noise_std=noise).thetas(np.random.default_rng(9), steps)
    residual = theta - amplitude * np.sin(2 * np.pi * (np.arange(steps + 1) % 24) / 24)
    assert residual.std() == pytest.approx(noise, rel=0.02)
    assert abs(residual.mean()) < 0.02 * noise
    pure = Sinusoidal(amplitude=0.0, period=24, noise_std=noise).thetas(np.random.default_rng(9), steps)
    assert pure.std() == pytest.approx(noise, rel=0.02)


# --- ramp -------------------------------------------------------------------------------------------------

def test_ramp_exact_values():
    theta = Ramp(rate=-0.25, theta0=2.0).thetas(np.random.default_rng(0), 8)
    assert theta.tolist() == [2.0, 1.75, 1.5, 1.25, 1.0, 0.75, 0.5, 0.25, 0.0]


def test_triangle_wave_exact_values():
    theta = Ramp(rate=0.5, theta0=-1.0, period=6).thetas(np.random.default_rng(0), 13)
    assert theta.tolist() == [-1.0, -0.5, 0.0, 0.5, 0.0, -0.5, -1.0, -0.5, 0.0, 0.5, 0.0, -0.5, -1.0, -0.5]


def test_triangle_wave_with_odd_period_cuts_the_corners():
    # Turning points at t = 2.5, 7.5, ...: sampled at the integers, the peak 2.5 is never reached.
    theta = Ramp(rate=1.0, period=5).thetas(np.random.default_rng(0), 10)
    assert theta.tolist() == [0.0, 1.0, 2.0, 2.0, 1.0, 0.0, 1.0, 2.0, 2.0, 1.0, 0.0]


# --- series -----------------------------------------------------------------------------------------------

def test_series_interpolation_is_exact(tmp_path):
    path = write_csv(tmp_path / "T.csv", "0,20.0\n2,22.0\n4,21.0\n8,25.0\n")
    series = Series(path, kappa=0.5, T0=20.0, tau_th=1.0)
    assert series.covered_steps == 8
    theta = series.thetas(np.random.default_rng(0), 8)
    assert theta.tolist() == [0.0, 0.5, 1.0, 0.75, 0.5, 1.0, 1.5, 2.0, 2.5]
    # A start time inside the series and a thermal time of two file units.
    shifted = Series(str(path), kappa=0.5, T0=20.0, tau_th=2.0, t0=1.0)
    assert shifted.covered_steps == 3
    assert shifted.thetas(np.random.default_rng(0), 3).tolist() == [0.5, 0.75, 1.0, 2.0]


def test_series_with_realistic_units(series_csv):
    series = Series(series_csv, kappa=1.2e-5, T0=20.0, tau_th=60.0)
    theta = series.thetas(np.random.default_rng(0), 50)
    np.testing.assert_allclose(theta, 1.2e-5 * (SERIES_TEMPS[::2] - 20.0), rtol=1e-12, atol=1e-20)


@pytest.mark.parametrize(
    "text",
    ["0,1\n1,2\n2,4\n", "time,T\n0,1\n1,2\n2,4\n", "\ufefftime , T\n\n# comment\n0 , 1\n1,2\n\n2,4\n"],
    ids=["no-header", "header", "bom-spaces-comments-blank-lines"],
)
def test_series_header_is_optional(tmp_path, text):
    series = Series(write_csv(tmp_path / "T.csv", text), kappa=1.0, T0=0.0, tau_th=0.5)
    assert series.thetas(np.random.default_rng(0), 4).tolist() == [1.0, 1.5, 2.0, 3.0, 4.0]


def test_series_other_delimiter(tmp_path):
    series = Series(write_csv(tmp_path / "T.txt", "t;T\n0;1\n10;3\n"), kappa=2.0, T0=1.0, tau_th=5.0,
                    delimiter=";")
    assert series.thetas(np.random.default_rng(0), 2).tolist() == [0.0, 2.0, 4.0]


def test_series_grid_ending_on_the_last_sample_counts(tmp_path):
    # 0.1 * 3 = 0.30000000000000004 > 0.3: the rounding must not lose the last step.
    series = Series(write_csv(tmp_path / "T.csv", "0,0\n0.1,1\n0.2,2\n0.3,3\n"), kappa=1.0, T0=0.0, tau_th=0.1)
    assert series.covered_steps == 3
    np.testing.assert_allclose(series.thetas(np.random.default_rng(0), 3), [0.0, 1.0, 2.0, 3.0], atol=1e-12)


def test_series_too_short_is_refused(tmp_path):
    series = Series(write_csv(tmp_path / "T.csv", "0,20\n30,21\n60,22\n90,21\n"), kappa=1e-5, T0=20.0,
                    tau_th=20.0)
    assert series.thetas(np.random.default_rng(0), 4).shape == (5,)
    with pytest.raises(ConfigError, match=r"T\.csv' of the series driver covers 4 steps of tau_th = 20\.0 from "
                                          r"t0 = 0\.0 to its last time 90\.0; 5 steps were asked for\."):
        series.thetas(np.random.default_rng(0), 5)


@pytest.mark.parametrize(
    ("text", "match"),
    [("0,1\n", r"has 1 data row\(s\); at least 2 are needed"),
     ("time,T\n", r"has 0 data row\(s\); at least 2 are needed"),
     ("0,1\n1,2\n1,3\n", r"times must be strictly increasing; data row 3 has time 1\.0 after 1\.0"),
     ("0,1\n2,2\n1,3\n", r"times must be strictly increasing; data row 3 has time 1\.0 after 2\.0"),
     ("0,1\n1,nan\n2,3\n", r": line 2: 'temperature' must be finite\. Got 'nan' instead\."),
     ("0,1\ninf,2\n", r": line 2: 'time' must be finite\. Got 'inf' instead\."),
     ("0,1,5\n1,2,6\n", r"line 1 has 3 columns; expected 2 \(time, temperature\) separated by ','"),
     ("0;1\n1;2\n", r"line 1 has 1 columns; expected 2"),
     ("t,T\n0,1\n1,warm\n", r": line 3: 'temperature' must be a number\. Got 'warm' instead\."),
     ("t,T\nunits,K\n0,1\n1,2\n", r": line 2: 'time' must be a number\. Got 'units' instead\.")],
    ids=["one-row", "header-only", "equal-times", "decreasing-times", "nan", "inf", "three-columns",
         "wrong-delimiter", "text-value", "two-headers"],
)
def test_series_bad_file_is_refused(tmp_path, text, match):
    path = write_csv(tmp_path / "T.csv", text)
    with pytest.raises(ConfigError, match=r"^The temperature file '.*T\.csv' of the series driver.*" + match):
        Series(path, kappa=1e-5, T0=20.0, tau_th=1.0)


def test_series_missing_file_is_refused(tmp_path):
    missing = tmp_path / "nowhere" / "T.csv"
    with pytest.raises(ConfigError, match=rf"^The temperature file {re.escape(repr(str(missing)))} of the series "
                                          r"driver does not exist\.$"):
        Series(missing, kappa=1e-5, T0=20.0, tau_th=1.0)
    with pytest.raises(ConfigError, match=r"of the series driver is not a file"):
        Series(tmp_path, kappa=1e-5, T0=20.0, tau_th=1.0)


# --- end to end -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(BUILTINS))
def test_each_driver_runs_end_to_end(series_csv, name):
    driver = {"name": name, **driver_params(series_csv)[name]}
    cfg = make_config(steps=50, realizations=2, record="all", observables=["n", "mu_max", "x_G"], driver=driver)
    ds = slidernet.run(cfg)
    n = ds["n"].values
    assert n.shape == (2, 51)
    assert (np.diff(n, axis=1) >= 0).all()
    if name == "constant":
        assert (n == 0).all()  # theta never moves: nothing slips
    else:
        assert (n[:, -1] > 0).all()  # every other driver moves theta by many Ntilde: rearrangements happen
    assert np.isfinite(ds["mu_max"].values).all() and np.isfinite(ds["x_G"].values).all()


def test_series_too_short_for_the_run_is_refused(series_csv):
    driver = {"name": "series", **driver_params(series_csv)["series"]}
    with pytest.raises(ConfigError, match=r"covers 50 steps .* 51 steps were asked for"):
        slidernet.run(make_config(steps=51, realizations=1, observables=["n"], driver=driver))


def test_driver_parameters_are_checked_through_the_config():
    cfg = make_config(steps=50, driver={"name": "ornstein_uhlenbeck", "sigma_theta": 1e-6, "tau_c": 0.0})
    with pytest.raises(ConfigError, match=r"'driver' field: The 'tau_c' parameter of ornstein_uhlenbeck "
                                          r"must be > 0\. Got 0\.0 instead\."):
        slidernet.load_config(cfg)


def test_a_series_named_in_a_config_file_is_found_next_to_it(tmp_path):
    # The TOML names "T.csv"; the run happens from another working directory.
    write_csv(tmp_path / "T.csv", "0,20.0\n1,20.5\n2,19.0\n3,21.0\n")
    (tmp_path / "run.toml").write_text(
        'steps = 3\nrecord = "all"\n[network]\nkind = "two_slider"\nNtilde = 1e-7\n'
        '[friction]\nmu_d = 0.5\n[friction.static]\nname = "gaussian"\nmean = 0.6\nstd = 0.01\n'
        '[driver]\nname = "series"\npath = "T.csv"\nkappa = 1e-6\nT0 = 20.0\ntau_th = 1.0\n'
    )
    cfg = slidernet.load_config(tmp_path / "run.toml")
    assert Path(cfg.driver.params["path"]) == tmp_path / "T.csv"


def test_a_series_too_short_for_the_run_is_refused_when_the_config_loads(tmp_path):
    path = write_csv(tmp_path / "T.csv", "0,20.0\n1,20.5\n2,19.0\n")
    cfg = make_config(steps=50, driver={"name": "series", "path": str(path), "kappa": 1e-6, "T0": 20.0,
                                        "tau_th": 1.0})
    with pytest.raises(ConfigError, match=r"The 'driver' field: .* covers 2 steps .* 50 steps were asked for"):
        slidernet.load_config(cfg)
