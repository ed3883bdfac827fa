"""Compile slidernet's kernels into numba's on-disk cache: the test suite's warm-up.

``python tests/warm_kernels.py PART`` runs the tiny scenes of one part of
:data:`PARTS`: the 1D kernels (and the validation's), or the 2D ones, so
that the parts can compile side by side (the few small helpers both use,
such as the output writer, compile in each). ``tests/conftest.py`` runs one process per
part before pytest-xdist starts its workers: without it every worker
compiles every kernel it meets, the same work once per worker. A kernel a
part misses is still compiled where a test first calls it; nothing here
changes a result.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from slidernet.config import load_config
from slidernet.solver import Realization, Scene

_FRICTION = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
_DRIVER = {"name": "gaussian_steps", "sigma_theta": 1e-7}


def _scene(network: dict[str, Any], **extra: Any) -> Scene:
    cfg = {"seed": 1, "realizations": 1, "steps": 4, "record": [0, 2, 4], "network": {"Ntilde": 1e-7, **network},
           "friction": _FRICTION, "driver": _DRIVER, **extra}
    return Scene.from_config(load_config(cfg))


def _advance(network: dict[str, Any], **extra: Any) -> None:
    Realization(_scene(network, **extra), np.random.SeedSequence(1)).advance()


def _pair() -> None:
    _advance({"kind": "two_slider"}, observables=["n", "mu_max", "x_G", "mu_eff"])


def _pair_csr() -> None:
    _advance({"kind": "two_slider"}, solver={"kernel": "csr"})


def _chain() -> None:
    _advance({"kind": "chain", "n": 6}, observables=["n", "mu_max", "x_G", "mu_eff"])


def _pair_validation() -> None:
    from slidernet.validation import tilt_readings
    from slidernet.validation.speed_error import fixed_step_final

    fixed_step_final(_scene({"kind": "two_slider"}), [np.random.SeedSequence(1)], 1.0)
    tilt_readings.readings(tilt_readings.case_config(0.5, 10.0, 4, 1, 1))


def _ou_driver() -> None:
    from slidernet.plugins.drivers import _ar1_in_place

    _ar1_in_place(np.zeros(4), 0.5)


def _lattice() -> None:
    _advance({"kind": "triangular", "shape": [4, 4]}, observables=["n", "mu_max", "x_G", "mu_eff"])


def _lattice_exact() -> None:
    _advance({"kind": "square", "shape": [4, 4]}, solver={"slip": "exact", "recompute_every": 1})


def _irregular() -> None:
    _advance({"kind": "irregular", "n": 64, "seed": 0}, observables=["n", "mu_max", "x_G", "mu_eff"])


#: The 1D kernels and the validation's, and the 2D ones (the 2D part alone: 139 s of CPU on the dev machine,
#: another job beside it).
PARTS: dict[str, list[Callable[[], None]]] = {
    "1d": [_pair, _pair_csr, _chain, _pair_validation, _ou_driver],
    "2d": [_lattice, _lattice_exact, _irregular],
}


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    for part in args:
        for step in PARTS[part]:
            t0 = time.process_time()
            step()
            print(f"{part} {step.__name__}: {time.process_time() - t0:.1f} s CPU", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
