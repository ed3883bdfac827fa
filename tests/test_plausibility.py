"""Plausibility: a scene far outside what real materials give is refused unless allow_implausible = true.

Issue 46, point 1: sigma_theta = 1.0 (meant as 1 K; sigma_theta / Ntilde = 1e7) passed every check and ran
for hours. slidernet.config.plausibility derives its ranges from the material table of
slidernet.model.units, two decades wide on each side.
"""

from __future__ import annotations

import json
import math
from typing import Any

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.config import load_config
from slidernet.config.plausibility import MARGIN, ranges
from slidernet.errors import ConfigError
from slidernet.model.units import dimensionless


def raw(Ntilde: float = 1e-7, sigma_theta: float = 1e-7, strengthening: dict | None = None,
        **changes: Any) -> dict[str, Any]:
    """A chain of 4 at the paper's point, with the given values."""
    friction: dict[str, Any] = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
    if strengthening is not None:
        friction["strengthening"] = strengthening
    return {"seed": 1, "realizations": 1, "steps": 20, "observables": ["n"],
            "network": {"kind": "chain", "n": 4, "Ntilde": Ntilde}, "friction": friction,
            "driver": {"name": "gaussian_steps", "sigma_theta": sigma_theta}, **changes}


def test_the_issues_unit_slip_is_refused() -> None:
    # sigma_theta = 1 K typed where alpha * 1 K = 1e-5 was meant, with the paper's Ntilde
    with pytest.raises(ConfigError, match=r"sigma_theta = 1 \(sigma_theta / Ntilde = 1e\+07\) is far outside what "
                                          r"real materials give \(about 8e-11 to 0\.07; see `slidernet units`\): "
                                          r"sigma_theta is the dimensionless dilation alpha\*DeltaT .*not a "
                                          r"temperature in kelvin\. Set allow_implausible = true to run it"):
        load_config(raw(sigma_theta=1.0))


REFUSED = [
    pytest.param(raw(Ntilde=1.0), r"Ntilde = 1 is far outside .*not a load in newtons", id="Ntilde-1"),
    pytest.param(raw(Ntilde=1e-15, sigma_theta=1e-15), r"Ntilde = 1e-15 is far outside", id="Ntilde-1e-15"),
    pytest.param(raw(Ntilde=1e-4, sigma_theta=1e-10),
                 r"sigma_theta / Ntilde = 1e-06 is far outside .*one of them is in another unit",
                 id="ratio-1e-6"),
    pytest.param(raw(strengthening={"beta": 10.0, "tau_c": 1.0}),
                 r"strengthening\.beta = 10 is far outside .*not a percentage", id="beta-10"),
    pytest.param(raw(strengthening={"beta": 0.01, "tau_c": 1e6}),
                 r"strengthening\.tau_c = 1e\+06 is far outside .*in units of tau_th", id="tau_c-1e6"),
    pytest.param(raw(driver={"name": "sinusoidal", "amplitude": 3.0, "period": 10.0}),
                 r"amplitude = 3 \(amplitude / Ntilde = 3e\+07\) is far outside .*amplitude is the dimensionless "
                 r"dilation", id="amplitude-3"),
]


@pytest.mark.parametrize(("config", "message"), REFUSED)
def test_an_implausible_scene_is_refused_naming_the_quantity_and_the_slip(config: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message + r".*Set allow_implausible = true"):
        load_config(config)
    load_config({**config, "allow_implausible": True})


def test_every_quantity_outside_its_range_is_named_in_one_message() -> None:
    with pytest.raises(ConfigError, match=r"Ntilde = 1 .*; sigma_theta / Ntilde = 1e-09 "):
        load_config(raw(Ntilde=1.0, sigma_theta=1e-9))


def test_beta_0_switches_strengthening_off_and_is_never_refused() -> None:
    load_config(raw(strengthening={"beta": 0.0, "tau_c": 1e9}))


def test_allow_implausible_runs_it_and_the_result_records_it() -> None:
    # Ntilde = 1 with sigma_theta = 1: implausible twice over, but a run of a few slips
    config = raw(Ntilde=1.0, sigma_theta=1.0, network={"kind": "two_slider", "Ntilde": 1.0})
    with pytest.raises(ConfigError, match="Ntilde = 1 is far outside"):
        load_config(config)
    result = slidernet.run({**config, "allow_implausible": True}, workers=1, progress=False)
    assert json.loads(result.attrs["config"])["allow_implausible"] is True
    assert int(result["n"].isel(t=-1).max()) > 0


def test_a_plausible_configuration_dumps_as_before() -> None:
    # Left out at its default, so that stored results and interrupted runs (run.json) still match
    assert "allow_implausible" not in load_config(raw()).model_dump()


def test_the_ranges_hold_every_material_of_the_table_with_the_margin() -> None:
    r = ranges()
    for name in ("steel", "glass", "granite", "pmma"):
        d = dimensionless(name, size=0.1, delta_T=0.01)  # the paper's setup
        assert r["Ntilde"].low * MARGIN < d.Ntilde < r["Ntilde"].high / MARGIN
        assert r["sigma_theta"].low * MARGIN < d.sigma_theta < r["sigma_theta"].high / MARGIN
        assert r["sigma_theta / Ntilde"].low * MARGIN < d.ratio < r["sigma_theta / Ntilde"].high / MARGIN


def _inside(name: str) -> st.SearchStrategy[float]:
    """Log-uniform values strictly inside the stated range of ``name``."""
    r = ranges()[name]
    low = math.log10(r.low) if r.low > 0 else -6.0
    return st.floats(low + 1e-9, math.log10(r.high) - 1e-9).map(lambda e: 10.0 ** e)


@settings(max_examples=40, deadline=None)
@given(Ntilde=_inside("Ntilde"), ratio=_inside("sigma_theta / Ntilde"), beta=_inside("strengthening.beta"),
       tau_c=_inside("strengthening.tau_c"))
def test_any_value_inside_the_stated_ranges_passes(Ntilde: float, ratio: float, beta: float,
                                                   tau_c: float) -> None:
    sigma_theta = ratio * Ntilde
    r = ranges()["sigma_theta"]
    assume(r.low <= sigma_theta <= r.high)
    # steps = 1: the strengthening's own validity check (growth over the run) stays out of the way
    load_config(raw(Ntilde=Ntilde, sigma_theta=sigma_theta, strengthening={"beta": beta, "tau_c": tau_c},
                    steps=1))
