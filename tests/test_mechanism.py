"""The node states at recorded times (analysis.mechanism) and trends in ln t (analysis.trend), on cases worked
out by hand."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.analysis.mechanism import node_states, node_summary
from slidernet.analysis.trend import grouped_mean_sem, log_trend, mean_sem
from slidernet.errors import ConfigError
from slidernet.plugins.distributions import Uniform, mean_min_quadrature

from .conftest import make_config

PAIR = make_config(**{"seed": 4, "realizations": 3, "steps": 300, "record": "log",
                      "observables": ["n", "mu_max", "x_G"]})
CHAIN = make_config(**{"seed": 4, "realizations": 3, "steps": 100, "record": "log",
                       "observables": ["n", "mu_max", "x_G"], "network": {"kind": "chain", "n": 5, "Ntilde": 1e-7},
                       "driver.sigma_theta": 5e-7})


@pytest.mark.parametrize("cfg", [PAIR, CHAIN], ids=["pair", "chain"])
def test_node_states_are_the_runs_realizations(cfg):
    ds = slidernet.run(cfg)
    times = ds["t"].values
    states = node_states(cfg, times)
    # The strongest threshold and the slip count are the run's, to the bit: the same realizations.
    np.testing.assert_array_equal(states["mu_s"].max("node").values, ds["mu_max"].values)
    np.testing.assert_array_equal(states["n"].values, ds["n"].values)
    # Every spring at rest at t = 0 (no f_ext): no force; every node stable at every recorded time.
    assert (states["load_ratio"].sel(t=0).values == 0.0).all()
    assert (states["load_ratio"].values <= 1.0 + 1e-9).all()


def test_two_sliders_feel_one_spring():
    # One spring: |F_1| = |F_2|, so load_ratio_1 mu_1 = load_ratio_2 mu_2 at every time.
    states = node_states(PAIR, [0, 1, 10, 100, 300])
    force = states["load_ratio"] * states["mu_s"]
    np.testing.assert_allclose(force.isel(node=0), force.isel(node=1), rtol=1e-12, atol=0)


def test_node_summary_uses_realizations_as_the_samples():
    states = node_states(CHAIN, [0, 100])
    out = node_summary(states, law_mean=0.6)
    per_r = states["mu_s"].mean("node")
    np.testing.assert_allclose(out["mu_s_mean"], per_r.mean("realization"))
    np.testing.assert_allclose(out["mu_s_sem"], per_r.std("realization", ddof=1) / np.sqrt(3))
    np.testing.assert_allclose(out["mu_s_shift_mean"], out["mu_s_mean"] - 0.6)
    assert out["mu_s_quantile"].dims == ("quantile", "t")


@pytest.mark.parametrize("times", [[5, 3], [0, 101], [0.5, 2]], ids=["decreasing", "past-the-end", "fractional"])
def test_bad_times_are_refused(times):
    with pytest.raises(ConfigError, match=r"'times' parameter of node_states must be increasing whole"):
        node_states(CHAIN, times)


def test_a_config_without_a_seed_is_refused():
    with pytest.raises(ConfigError, match=r"needs a config with a 'seed'"):
        node_states({**CHAIN, "seed": None}, [0])


def test_log_trend_is_the_mean_of_per_realization_slopes():
    # The least-squares slope is linear in the data: on a common time grid the mean of the
    # per-realization slopes is the slope of the mean, and its error the spread of the slopes.
    rng = np.random.default_rng(3)
    t = np.array([0, 1, 2, 5, 10, 20, 50, 100.0])
    slopes = np.array([0.5, 1.0, 2.0, -1.0])
    y = slopes[:, None] * np.log(np.maximum(t, 1)) + rng.normal(0, 0.01, (4, t.size))
    v = xr.DataArray(y, dims=("realization", "t"), coords={"t": t, "realization": np.arange(4)})
    out = log_trend(v)
    mean_line = log_trend(v.mean("realization").expand_dims(realization=[0]))
    np.testing.assert_allclose(float(out["slope_mean"]), float(mean_line["slope"][0]), rtol=1e-12)
    np.testing.assert_allclose(float(out["slope_sem"]), out["slope"].std(ddof=1) / 2, rtol=1e-12)
    assert np.abs(out["slope"].values - slopes).max() < 0.05
    assert out.attrs["t_start"] == 1.0 and out.attrs["t_end"] == 100.0


def test_log_trend_of_mu_max_of_two_sliders_rises():
    # The strongest threshold of two sliders never decreases (it is the max of n + 2 draws): every
    # realization's slope is >= 0, seed 4, 3 realizations.
    out = log_trend(slidernet.run(PAIR)["mu_max"])
    assert (out["slope"].values >= 0).all() and out["realizations"] == 3


def test_log_trend_against_another_abscissa_fits_its_logarithm():
    # value = 2 ln(x) exactly, with x = 5 t (one realization) and 7 t^2 (the other): slopes 2 in ln x,
    # and 2 and 4 in ln t.
    t = np.array([1.0, 10.0, 100.0])
    x = np.array([5.0 * t, 7.0 * t**2])
    v = xr.DataArray(2.0 * np.log(x), dims=("realization", "t"), coords={"t": t})
    against = xr.DataArray(x, dims=("realization", "t"), coords={"t": t})
    np.testing.assert_allclose(log_trend(v, against=against)["slope"].values, [2.0, 2.0], rtol=1e-12)
    np.testing.assert_allclose(log_trend(v)["slope"].values, [2.0, 4.0], rtol=1e-12)
    with pytest.raises(ConfigError, match="has the shape"):
        log_trend(v, against=against.isel(t=[0, 1]))


def test_grouped_errors_take_the_spread_between_geometries():
    # Four geometries whose realizations agree within each: the plain error sees only the spread inside
    # geometries, the two-level one the spread between them too.
    values = np.array([1.0, 1.01, 2.0, 2.01, 3.0, 3.01, 4.0, 4.01])
    groups = np.repeat([0, 1, 2, 3], 2)
    mean, sem, dof = grouped_mean_sem(values, groups)
    assert (mean, dof) == (pytest.approx(2.505), 3)
    assert sem == pytest.approx(np.std([1.005, 2.005, 3.005, 4.005], ddof=1) / 2)
    assert grouped_mean_sem(values, np.arange(8))[:2] == pytest.approx(mean_sem(values)[:2])
    with pytest.raises(ConfigError, match="one shape"):
        grouped_mean_sem(values, groups[:3])


@pytest.mark.parametrize("m", [1, 2, 16, 1024])
def test_the_mean_of_the_weakest_of_m_draws_is_exact(m):
    # Uniform(a, b): E[min of m] = a + (b - a) / (m + 1).
    assert float(mean_min_quadrature(Uniform(0.5, 0.7), m)) == pytest.approx(0.5 + 0.2 / (m + 1), rel=1e-12)


def test_log_trend_refuses_what_it_cannot_fit():
    v = xr.DataArray(np.zeros((2, 3)), dims=("realization", "t"), coords={"t": [0, 1, 2]})
    with pytest.raises(ConfigError, match=r"'t_min' parameter of log_trend must be > 0"):
        log_trend(v, t_min=0)
    with pytest.raises(ConfigError, match=r"fewer than two recorded times"):
        log_trend(v, t_min=2)
    with pytest.raises(ConfigError, match=r"needs values of dims \(realization, t\)"):
        log_trend(v.isel(realization=0))


@pytest.mark.parametrize("cfg", [PAIR, CHAIN], ids=["pair-rearrangements", "chain-records"])
def test_mu_eff_realization_pools_back_to_mu_eff(cfg, tmp_path):
    # Each realization's own bin means, weighted by their counts, give the pooled mu_eff to rounding;
    # with one test per recorded time (networks) each is that test's sample.
    cfg = {**cfg, "observables": ["n", "mu_max", "x_G", "mu_eff", "mu_eff_realization"]}
    ds = slidernet.run(cfg)
    plain = slidernet.run({**cfg, "observables": ["n", "mu_max", "x_G", "mu_eff"]})
    np.testing.assert_array_equal(ds["mu_eff"].values, plain["mu_eff"].values)  # the same tests
    per = ds["mu_eff_realization"]
    assert per.dims == ("realization", "t")
    with slidernet.run(cfg, out=tmp_path) as streamed:  # the streamed file holds the same values
        np.testing.assert_array_equal(streamed["mu_eff_realization"].values, per.values)
    if cfg["network"]["kind"] == "chain":
        assert np.isfinite(per.values).all()
        np.testing.assert_allclose(per.mean("realization"), ds["mu_eff"], rtol=1e-12)
    else:
        assert np.isfinite(per.sel(t=0).values).all()  # one test per realization on the fresh state
        np.testing.assert_allclose(per.sel(t=0).mean("realization"), ds["mu_eff"].sel(t=0), rtol=1e-12)


def test_mu_eff_realization_needs_mu_eff():
    with pytest.raises(ConfigError, match=r"'mu_eff_realization' observable .* needs the tilt tests"):
        slidernet.load_config({**PAIR, "observables": ["n", "mu_eff_realization"]})


@pytest.mark.parametrize("cfg", [CHAIN, {**PAIR, "mu_eff_at": "records"}], ids=["chain", "pair"])
def test_tilt_loads_bound_the_sample_and_leave_it_unchanged(cfg):
    # The first slip comes first (onset <= collective motion <= sample), and the sample and every other
    # variable are those of a run without the observable.
    base = {**cfg, "observables": ["n", "mu_max", "x_G", "mu_eff", "mu_eff_realization"]}
    plain = slidernet.run(base)
    ds = slidernet.run({**base, "observables": [*base["observables"], "tilt_loads"]})
    for name in plain.data_vars:
        np.testing.assert_array_equal(ds[name].values, plain[name].values, err_msg=name)
    first, moving, sample = ds["tilt_first_slip"], ds["tilt_all_moving"], ds["mu_eff_realization"]
    assert np.isfinite(first.values).all()
    assert (first <= moving + 1e-15).where(np.isfinite(moving), True).all()
    assert (moving <= sample + 1e-15).where(np.isfinite(moving), True).all()
    assert (first <= sample + 1e-15).all()
    if cfg["network"]["kind"] == "two_slider":
        # The two onsets f_1 = mu_1 + F and f_2 = mu_2 - F add up to mu_1 + mu_2: the first is at most
        # their mean.
        states = node_states(cfg, ds["t"].values)
        assert (first <= states["mu_s"].mean("node") + 1e-12).all()


@pytest.mark.parametrize(("changes", "match"), [
    ({"observables": ["n", "tilt_loads"]}, r"'tilt_loads' observable .* needs the tilt tests"),
    ({"observables": ["n", "mu_eff", "tilt_loads"]}, r"'tilt_loads' observable is read from the network tilt"),
], ids=["without-mu_eff", "pair-appendix-test"])
def test_tilt_loads_refusals(changes, match):
    with pytest.raises(ConfigError, match=match):
        slidernet.load_config({**PAIR, **changes})
