"""The telegraph plugin: slidernet's conformance checks, its statistics, and the installed route."""

from __future__ import annotations

import math

import numpy as np
import pytest
from slidernet_telegraph import Telegraph

import slidernet
from slidernet import ConfigError
from slidernet.plugins import registry
from slidernet.testing import check_driver


def test_follows_the_plugin_contract():
    check_driver(Telegraph, Telegraph.example_params, name="telegraph")


@pytest.mark.parametrize("rate", [1e-3, 0.5, 20.0])
def test_follows_the_contract_for_several_rates(rate):
    check_driver(Telegraph, {"sigma_theta": 1e-6, "rate": rate}, name="telegraph")


def test_levels_and_switching_statistics():
    steps = 200_000
    th = Telegraph(sigma_theta=2e-6, rate=0.5).thetas(np.random.default_rng(5), steps)
    assert set(np.unique(th).tolist()) == {-2e-6, 2e-6}
    # Switches between samples: probability (1 - e^-1) / 2 = 0.316; the
    # binomial standard error over 2e5 steps is 1e-3, so 5e-3 is 5 of them.
    p = (1.0 - math.exp(-1.0)) / 2.0
    assert abs((np.diff(th) != 0).mean() - p) < 5e-3
    # Correlation e^-1 between samples: about 9e4 independent ones, so the mean's
    # standard error is 6.6e-9; 3e-8 is 4.5 of them.
    assert abs(th.mean()) < 3e-8
    assert float(th.std()) == pytest.approx(2e-6, rel=1e-3)


@pytest.mark.parametrize("param", ["sigma_theta", "rate"])
@pytest.mark.parametrize("value", [-1.0, 0.0, math.inf, math.nan])
def test_bad_parameters_are_named(param, value):
    params = {**Telegraph.example_params, param: value}
    with pytest.raises(ConfigError, match=rf"'{param}' parameter of telegraph must be finite and > 0"):
        Telegraph(**params)


def test_discovered_through_its_entry_point():
    registry.drivers.clear_cache()
    assert "telegraph" in registry.drivers.names()
    assert registry.drivers.get("telegraph") is Telegraph


def test_a_config_using_it_runs():
    cfg = {
        "seed": 4, "realizations": 2, "steps": 100, "observables": ["n", "mu_max", "x_G"],
        "network": {"kind": "two_slider", "Ntilde": 1e-7},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "telegraph", "sigma_theta": 1e-6, "rate": 0.5},
    }
    ds = slidernet.run(cfg)
    n = ds["n"].values[:, -1]
    assert (n > 0).all()
    # Only switches move theta (by 2 sigma_theta each): far fewer rearrangements
    # than the paper's driver at the same sigma_theta (53.6 per tau_th).
    assert (n < 53.6 * 100).all()


def test_units_table_fills_its_sigma_theta():
    cfg = {
        "steps": 5, "units": {"material": "glass", "size": 0.05, "delta_T": 0.01},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "telegraph", "rate": 0.5},
    }
    cfg = slidernet.load_config(cfg)
    assert cfg.driver_plugin().sigma_theta == pytest.approx(9e-8, rel=1e-12)
