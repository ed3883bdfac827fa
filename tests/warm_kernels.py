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
from slidernet.solver.compile import compile_kernels

_FRICTION = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
_DRIVER = {"name": "gaussian_steps", "sigma_theta": 1e-7}
_MU_EFF = ["n", "mu_max", "x_G", "mu_eff"]


def _compile(network: dict[str, Any], **extra: Any) -> None:
    """Every kernel of the scene, through the solver's own probe (slidernet.solver.compile)."""
    cfg = {"seed": 1, "realizations": 1, "steps": 4, "network": {"Ntilde": 1e-7, **network},
           "friction": _FRICTION, "driver": _DRIVER, **extra}
    compile_kernels(load_config(cfg), notice=None)


def _pair() -> None:
    _compile({"kind": "two_slider"})
    _compile({"kind": "two_slider"}, observables=_MU_EFF)


def _pair_csr() -> None:
    _compile({"kind": "two_slider"}, solver={"kernel": "csr"})
    _compile({"kind": "two_slider"}, solver={"kernel": "csr"}, observables=_MU_EFF)


def _chain() -> None:
    _compile({"kind": "chain", "n": 6}, observables=_MU_EFF)


def _pair_validation() -> None:
    from slidernet.solver import Scene
    from slidernet.validation import tilt_readings
    from slidernet.validation.speed_error import fixed_step_final

    scene = Scene.from_config(load_config({"seed": 1, "realizations": 1, "steps": 4,
                                           "network": {"kind": "two_slider", "Ntilde": 1e-7},
                                           "friction": _FRICTION, "driver": _DRIVER}))
    fixed_step_final(scene, [np.random.SeedSequence(1)], 1.0)
    tilt_readings.readings(tilt_readings.case_config(0.5, 10.0, 4, 1, 1))


def _ou_driver() -> None:
    from slidernet.plugins.drivers import _ar1_in_place

    _ar1_in_place(np.zeros(4), 0.5)


def _lattice() -> None:
    _compile({"kind": "triangular", "shape": [4, 4]}, observables=_MU_EFF)


def _lattice_exact() -> None:
    _compile({"kind": "square", "shape": [4, 4]}, solver={"slip": "exact", "recompute_every": 1},
             observables=_MU_EFF)


def _irregular() -> None:
    _compile({"kind": "irregular", "n": 64, "seed": 0}, observables=_MU_EFF)


#: The 1D kernels and the validation's, and the 2D ones.
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
