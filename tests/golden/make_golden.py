"""Write the golden result files that tests/test_golden.py requires the code to reproduce bit for bit.

Each case is one configuration run through the public API (``slidernet.run``
or ``slidernet.ensemble.sweep.sweep``) and written with ``slidernet.io.write_netcdf``.
The files were made with this script on main at commit a0cadef plus this script (before the
package was split into layered folders), on Linux x86_64 with numpy 2.4,
numba 0.68 and Python 3.11:

    python tests/golden/make_golden.py

Run it again only when a change of results is intended, and say why in the
commit that replaces the files.

Regenerated since:

- ``triangular_fext_tilt.nc`` (issue 15, the lattices' block table): a
  triangular lattice's springs now take the lattice's exact unit vectors
  (1, 0) and (-+1/2, sqrt(3)/2) instead of differences of the rounded
  positions, which differed by up to an ulp from row to row. K and g changed
  in their last bits, so the trajectories part after a few steps; the
  statistics do not change (final n 5339 / 10159 / 7664 before, 5341 /
  10189 / 7635 after; the kernel agreement and statistics tests hold). The
  other six files are reproduced bit for bit.
- ``irregular_exact.nc`` (issue 15, locality): an irregular network's nodes
  are numbered along strips of width 1 l0 instead of in draw order, so that
  neighbours sit close in memory. The points and springs are the same; which
  point is node i, and so which threshold it draws first, changed.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import slidernet
from slidernet.ensemble.sweep import sweep
from slidernet.io import write_netcdf

HERE = Path(__file__).parent
STATIC = {"name": "gaussian", "mean": 0.6, "std": 0.01}


def _base(**changes: Any) -> dict[str, Any]:
    cfg = {"seed": 2010, "realizations": 3, "steps": 300, "observables": ["n", "mu_max", "x_G"],
           "friction": {"mu_d": 0.5, "static": STATIC},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
           "network": {"kind": "two_slider", "Ntilde": 1e-7}, "execution": {"workers": 1}}
    cfg.update(changes)
    return cfg


CASES: dict[str, dict[str, Any]] = {
    # The paper's pair, with the appendix's tilt test before every rearrangement.
    "pair_mueff": _base(observables=["n", "mu_max", "x_G", "mu_eff", "n_records"]),
    # A chain of 8 with the event catalogue.
    "chain8_events": _base(steps=30, observables=["n", "mu_max", "x_G", "events"],
                           network={"kind": "chain", "n": 8, "Ntilde": 1e-7},
                           driver={"name": "gaussian_steps", "sigma_theta": 3e-7}),
    # Square and triangular lattices under a creep load, with the network tilt test.
    "square_fext_tilt": _base(steps=40, observables=["n", "mu_max", "x_G", "mu_eff"],
                              network={"kind": "square", "shape": [4, 5], "Ntilde": 1e-7, "f_ext": 0.05},
                              driver={"name": "gaussian_steps", "sigma_theta": 2e-7}),
    "triangular_fext_tilt": _base(steps=12, observables=["n", "mu_max", "x_G", "mu_eff", "events"],
                                  network={"kind": "triangular", "shape": [5, 5], "Ntilde": 1e-7,
                                           "f_ext": [0.05, 0.02]},
                                  driver={"name": "gaussian_steps", "sigma_theta": 2e-7}),
    # An irregular network with the exact (integrated) slip.
    "irregular_exact": _base(steps=8, observables=["n", "mu_max", "x_G", "events"],
                             network={"kind": "irregular", "n": 30, "Ntilde": 1e-7, "seed": 4},
                             driver={"name": "gaussian_steps", "sigma_theta": 2e-7},
                             solver={"slip": "exact"}),
}
SWEEP = ("sweep_sigma_theta", _base(steps=200), {"driver.sigma_theta": [1e-7, 1e-6]})
RESUMED = "resumed_pair"


def make(case: str, folder: Path) -> Path:
    """Compute one golden case into ``folder``; return the file."""
    path = folder / f"{case}.nc"
    if case in CASES:
        write_netcdf(slidernet.run(CASES[case]), path)
    elif case == SWEEP[0]:
        write_netcdf(sweep(SWEEP[1], SWEEP[2]), path)
    elif case == RESUMED:
        # Stopped after its first realization, then resumed: the resumed run's file.
        out = folder / f"{case}.run"
        cfg = _base(observables=["n", "mu_max", "x_G", "mu_eff"])

        def stop_after_one(r: int) -> None:
            raise KeyboardInterrupt

        try:
            slidernet.run(cfg, out=out, on_realization=stop_after_one)
        except KeyboardInterrupt:
            pass
        with slidernet.run(cfg, out=out, resume=True) as ds:
            write_netcdf(ds.load(), path)
        (out / "result.nc").unlink()
        out.rmdir()
    else:
        raise KeyError(case)
    return path


NAMES = [*CASES, SWEEP[0], RESUMED]

if __name__ == "__main__":
    for name in sys.argv[1:] or NAMES:
        print(make(name, HERE))
