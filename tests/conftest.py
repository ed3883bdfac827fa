"""Shared fixtures: the reference configuration, scene builders and registry hygiene."""

from __future__ import annotations

import copy
import os
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
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


def _kernels_compiled() -> dict[str, bool]:
    """Whether numba's cache already holds each part's largest kernel (``tests/warm_kernels.py``)."""
    from slidernet import kernels

    def cached(dispatcher: Any) -> bool:
        # numba's own cache index of the function (private names: if they move, compile again, which
        # only loads what is cached).
        try:
            return os.path.exists(dispatcher._cache._cache_file._index_path)
        except AttributeError:
            return False

    return {"1d": cached(kernels.run_chain) and cached(kernels.run_pair), "2d": cached(kernels.run_plane)}


def pytest_configure(config: pytest.Config) -> None:
    """Compile the kernels once, in parallel, before pytest-xdist starts its workers.

    Each worker would otherwise compile every kernel it meets: the same
    minutes of numba's compiler once per worker (224 s of CPU for all of
    them in one process, measured with another job on the machine). The
    controller runs ``tests/warm_kernels.py`` once per part, side by side,
    only for the parts whose kernels are not in the cache yet; the workers
    then load them from the cache.
    """
    workers = getattr(config.option, "numprocesses", None)  # None without pytest-xdist
    if hasattr(config, "workerinput") or not isinstance(workers, int) or workers < 2 \
            or config.option.collectonly:
        return
    parts = [part for part, done in _kernels_compiled().items() if not done]
    if not parts:
        return
    t0 = time.perf_counter()
    # Said at once: pytest prints nothing of its own until the workers have started.
    print(f"slidernet: compiling the kernels for the tests ({' and '.join(parts)} parts side by side), once "
          f"per installation: about {_WARM_SECONDS} s on a 2-core machine; the tests start after.",
          file=sys.stderr, flush=True)
    script = Path(__file__).with_name("warm_kernels.py")
    procs = {part: subprocess.Popen([sys.executable, str(script), part], stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, text=True) for part in parts}
    outputs = {}
    for part, proc in procs.items():
        outputs[part] = proc.communicate()[0]
        print(f"slidernet: {part} kernels compiled ({time.perf_counter() - t0:.0f} s)", file=sys.stderr,
              flush=True)
    note = f"kernels compiled before the workers started: {', '.join(parts)} in {time.perf_counter() - t0:.0f} s"
    failed = [f"{part}: {(outputs[part].strip().splitlines() or ['no output'])[-1]}"
              for part, proc in procs.items() if proc.returncode != 0]
    if failed:
        note += f" (failed, left to the tests: {'; '.join(failed)})"
    config.stash[_WARM_NOTE] = note


_WARM_NOTE = pytest.StashKey[str]()
# Wall seconds of the warm-up from an empty cache on the idle 2-core dev machine (2026-11-27: 22 and 23 s).
_WARM_SECONDS = 25


def pytest_report_header(config: pytest.Config) -> str | None:
    return config.stash.get(_WARM_NOTE, None)


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
