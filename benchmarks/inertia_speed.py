"""CPU per slip of the inertial solver of 1D networks, against the reference integrator and the quasi-static
solver.

    python benchmarks/inertia_speed.py [--core 1] [--repeat 5] [--quick] [--csv PATH]

On the same scenes (the paper's two sliders and free chains of 4 and 16,
mu_d = 0.5, mu_s ~ N(0.6, 0.01^2), gaussian_steps with sigma_theta / Ntilde
= 10) and at tau_ratio = tau_dyn / tau_th in {1e-4, 1e-3, 1e-2, 1e-1}, each
row gives the CPU time per start of motion (one rearrangement, ``n``) of

- the inertial solver (:class:`slidernet.solver.inertia.InertialSolver`):
  median over ``--repeat`` runs of one realization;
- the reference integrator (:class:`slidernet.validation.dynamics.Dynamics`,
  defaults: DOP853, rtol 1e-8, max_step 0.05 tau_dyn) on the first steps of
  the same realization (a few hundred slips; one run: it takes seconds);
- the quasi-static solver (:func:`slidernet.solver.simulate`, which has no
  tau_ratio: the same number on every row of a scene), median over the
  repeats.

Everything runs in this process, pinned to one core (``--core``), after
each solver has run once on the scene (compiling or loading its kernels);
the times are ``time.process_time`` around ``run`` alone. The slip rates
differ between the three (inertia changes the avalanches), so each is per
its own count. ``--quick``: fewer steps (a smoke run, noisy numbers).
"""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import time
from collections.abc import Callable

import numpy as np

from slidernet.config import load_config
from slidernet.solver import Scene, simulate
from slidernet.solver.inertia import InertialSolver
from slidernet.validation.dynamics import Dynamics

Ntilde = 1e-7
TAU_RATIOS = (1e-4, 1e-3, 1e-2, 1e-1)
# Steps of each scene: (inertial and quasi-static runs, reference runs). At sigma_theta / Ntilde = 10 the
# pair makes ~50 slips per tau_th, the chain of 4 ~170 and the chain of 16 ~750 (tau_ratio = 1e-4).
SCENES = {
    "pair": ({"kind": "two_slider", "Ntilde": Ntilde}, 2000, 4),
    "chain-4": ({"kind": "chain", "n": 4, "Ntilde": Ntilde}, 500, 2),
    "chain-16": ({"kind": "chain", "n": 16, "Ntilde": Ntilde}, 100, 1),
}


def make_scene(network: dict, steps: int) -> Scene:
    return Scene.from_config(load_config({
        "steps": steps, "record": "log", "network": network,
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 10 * Ntilde}}))


def cpu_per_slip(run: Callable[[], dict]) -> tuple[float, int]:
    """(CPU seconds per start of motion, starts) of one call of ``run``."""
    t0 = time.process_time()
    out = run()
    cpu = time.process_time() - t0
    n = int(out["n"][-1])
    return cpu / max(n, 1), n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--core", type=int, default=1, help="the core to pin to (default 1)")
    parser.add_argument("--repeat", type=int, default=5, help="runs of the compiled solvers (median)")
    parser.add_argument("--quick", action="store_true", help="a tenth of the steps: a smoke run")
    parser.add_argument("--csv", help="also write the rows here")
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {args.core})
    seed = np.random.SeedSequence(0)
    rows = []
    print("| scene | tau_ratio | inertial us/slip | slips | reference ms/slip | slips | quasi-static us/slip "
          "| slips | reference / inertial |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, (network, steps, ref_steps) in SCENES.items():
        steps = max(steps // 10, ref_steps) if args.quick else steps
        sc = make_scene(network, steps)
        simulate(make_scene(network, 1), seed)  # compile or load the kernels
        qs = [cpu_per_slip(lambda sc=sc: simulate(sc, seed)) for _ in range(args.repeat)]
        qs_cpu, qs_n = statistics.median(c for c, _ in qs), qs[0][1]
        for tau in TAU_RATIOS:
            solver = InertialSolver(sc, tau)
            solver.run(seed, steps=1)
            runs = [cpu_per_slip(lambda solver=solver: solver.run(seed)) for _ in range(args.repeat)]
            cpu, n = statistics.median(c for c, _ in runs), runs[0][1]
            dyn = Dynamics(sc, tau)
            ref_cpu, ref_n = cpu_per_slip(lambda dyn=dyn, k=ref_steps: dyn.run(seed, steps=k))
            row = {"scene": name, "tau_ratio": tau, "inertial_us": 1e6 * cpu, "inertial_slips": n,
                   "reference_ms": 1e3 * ref_cpu, "reference_slips": ref_n, "quasi_static_us": 1e6 * qs_cpu,
                   "quasi_static_slips": qs_n, "ratio": ref_cpu / cpu}
            rows.append(row)
            print(f"| {name} | {tau:g} | {row['inertial_us']:.2f} | {n} | {row['reference_ms']:.1f} | {ref_n} "
                  f"| {row['quasi_static_us']:.3f} | {qs_n} | {row['ratio']:.0f} |", flush=True)
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)


if __name__ == "__main__":
    main()
