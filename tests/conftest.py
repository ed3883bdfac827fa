"""Shared fixtures: the reference configuration, scene builders and registry hygiene."""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import settings

from slidernet.config import load_config
from slidernet.plugins import registry
from slidernet.solver import Realization, Scene

# No hypothesis example may fail for taking long: the suite runs on slow and loaded machines too.
settings.register_profile("slidernet", deadline=None)
settings.load_profile("slidernet")

# docs/model.md section 5, as a dict, exactly as written there.
REFERENCE: dict[str, Any] = {
    "seed": 1,
    "realizations": 200,
    "steps": 10000,
    "record": "log",
    "observables": ["n", "mu_max", "x_G", "mu_eff"],
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}


def make_config(**changes: Any) -> dict[str, Any]:
    """A deep copy of the reference dict with dotted-key changes.

    ``make_config(steps=50, **{"friction.static.std": 0.1})`` sets nested keys;
    a value of ``None`` removes the key.
    """
    cfg = copy.deepcopy(REFERENCE)
    for dotted, value in changes.items():
        *parents, key = dotted.split(".")
        node = cfg
        for p in parents:
            node = node.setdefault(p, {})
        if value is None:
            node.pop(key, None)
        else:
            node[key] = value
    return cfg


def scene_of(cfg: dict[str, Any]) -> Scene:
    """The validated scene of a config dict."""
    return Scene.from_config(load_config(cfg))


def realization_of(cfg: dict[str, Any], seed: int) -> Realization:
    """A fresh realization of ``cfg`` seeded by ``SeedSequence(seed)``."""
    return Realization(scene_of(cfg), np.random.SeedSequence(seed))


class FixedThetas:
    """A driver that returns the thetas it was configured with (tests only)."""

    def __init__(self, values: list[float]) -> None:
        self.values = np.asarray(values, dtype=float)

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        return self.values.copy()


def _snapshot(reg: registry.Registry) -> tuple:
    eps = None if reg._entry_points is None else dict(reg._entry_points)
    return dict(reg._runtime), eps, dict(reg._loaded), dict(reg._errors)


def _restore(reg: registry.Registry, state: tuple) -> None:
    runtime, eps, loaded, errors = state
    reg._runtime.clear()
    reg._runtime.update(runtime)
    reg._entry_points = eps
    reg._loaded.clear()
    reg._loaded.update(loaded)
    reg._errors.clear()
    reg._errors.update(errors)


@pytest.fixture
def clean_registries() -> Iterator[None]:
    """Restore both plugin registries after the test, whatever it registered or discovered."""
    saved = {reg: _snapshot(reg) for reg in (registry.distributions, registry.drivers)}
    yield
    for reg, state in saved.items():
        _restore(reg, state)


@pytest.fixture
def fixed_driver(clean_registries: None) -> Callable[[list[float]], dict[str, Any]]:
    """Register the ``fixed_thetas`` driver; returns a builder of its [driver] table."""
    registry.register_driver("fixed_thetas", FixedThetas)

    def spec(values: list[float]) -> dict[str, Any]:
        return {"name": "fixed_thetas", "values": [float(v) for v in values]}

    return spec
