"""The bimodal plugin: slidernet's conformance checks, its own numbers, and the installed route."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import special
from slidernet_bimodal import Bimodal

import slidernet
from slidernet import ConfigError
from slidernet.plugins import registry
from slidernet.testing import check_distribution

PARAMS = Bimodal.example_params


def test_follows_the_plugin_contract():
    check_distribution(Bimodal, PARAMS, mu_d=0.5, name="bimodal")


@pytest.mark.parametrize("mu_d", [0.4, 0.5, 0.59])
def test_follows_the_contract_for_several_mu_d(mu_d):
    check_distribution(Bimodal, PARAMS, mu_d=mu_d, name="bimodal")


def test_mixture_weights_and_moments():
    law = Bimodal(**PARAMS)
    x = law.sample(np.random.default_rng(1), 200_000)
    # Mean 0.7 * 0.58 + 0.3 * 0.62 = 0.592; the standard error of the mean of
    # 2e5 draws is 4.5e-5 (the mixture's std is 0.020), so 2e-4 is 4.4 of them.
    assert abs(x.mean() - 0.592) < 2e-4
    # 0.6 lies 2 std above the first mode and 4 below the second.
    expected = 0.7 * special.ndtr(2.0) + 0.3 * special.ndtr(-4.0)
    assert float(law.cdf(0.6)) == pytest.approx(expected, rel=1e-12)
    assert abs((x <= 0.6).mean() - expected) < 5e-3  # binomial standard error 1e-3


@pytest.mark.parametrize(
    ("change", "match"),
    [({"std1": -0.01}, r"'std1' parameter of bimodal must be finite and > 0"),
     ({"mean2": float("nan")}, r"'mean2' parameter of bimodal must be finite"),
     ({"weight": 0.0}, r"'weight' parameter of bimodal must be in \(0, 1\)")],
)
def test_bad_parameters_are_named(change, match):
    with pytest.raises(ConfigError, match=match):
        Bimodal(**{**PARAMS, **change})


def test_discovered_through_its_entry_point():
    registry.distributions.clear_cache()
    assert "bimodal" in registry.distributions.names()
    assert registry.distributions.get("bimodal") is Bimodal


def test_a_config_using_it_runs():
    cfg = {
        "seed": 3, "realizations": 2, "steps": 50, "observables": ["n", "mu_max"],
        "network": {"kind": "two_slider", "Ntilde": 1e-7},
        "friction": {"mu_d": 0.5, "static": {"name": "bimodal", **PARAMS}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
    }
    ds = slidernet.run(cfg)
    assert (ds["n"].values[:, -1] > 0).all()
    assert (ds["mu_max"].values > 0.5).all()


def test_both_modes_below_mu_d_are_refused():
    cfg = {
        "steps": 5, "network": {"Ntilde": 1e-7},
        "friction": {"mu_d": 0.7, "static": {"name": "bimodal", **PARAMS}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
    }
    with pytest.raises(ConfigError, match=r"'friction\.static' field: The 'mean1' and 'mean2' parameters"):
        slidernet.load_config(cfg)
