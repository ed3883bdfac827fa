"""CPU per slip of the compiled inertial solver of 2D networks, against the reference integrator and the
quasi-static solver, on the study's irregular networks.

For each size N (irregular networks, network seed 0; mu_d = 0.5, Gaussian mu_s of mean 0.6 and std 0.01,
Ntilde = 1e-7, gaussian_steps with sigma_theta = ``--sigma`` Ntilde), on one core:

* ``inertia``: :class:`slidernet.solver.inertia_2d.Inertia2D` at tau_dyn / tau_th = ``--tau`` (default
  1e-4), ``--realizations`` runs of ``--steps`` thermal steps; the median over runs of CPU seconds / slips,
  and the scheme's accepted steps per slip;
* ``reference``: :class:`slidernet.validation.dynamics.Dynamics` (scipy, defaults) on the first of those
  runs, for N <= ``--ref-max`` (it costs ~14 ms per slip at 16 nodes and grows with N: dense operators);
* ``quasi-static``: :func:`slidernet.solver.simulate` (the default straight-line slips) on the same scene
  run for ``--qs-steps`` thermal steps, so that its per-call cost does not count; CPU / rearrangements.

Then the growth with tau_dyn / tau_th: the inertial solver at N = ``--tau-size`` for tau in ``--taus``.
CPU is ``time.process_time`` of this process, pinned to ``--core`` where the OS allows. The kernels are
compiled (or loaded) before any timing.

Run from the repository root::

    python benchmarks/inertia_2d_speed.py                      # about 2 min
    python benchmarks/inertia_2d_speed.py --sizes 16 64 --ref-max 16 --realizations 3
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from slidernet.config import load_config
from slidernet.solver import Scene, simulate
from slidernet.solver.inertia_2d import Inertia2D
from slidernet.validation.dynamics import Dynamics

NTILDE = 1e-7


def scene(n: int, sigma: float, steps: int) -> Scene:
    return Scene.from_config(load_config({
        "steps": steps, "record": "log", "network": {"kind": "irregular", "n": n, "seed": 0, "Ntilde": NTILDE},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "gaussian_steps", "sigma_theta": sigma * NTILDE}}))


def cpu(fn):
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def inertia_cost(sc: Scene, tau: float, realizations: int) -> dict:
    solver = Inertia2D(sc, tau_ratio=tau)
    per_slip, steps, slips = [], [], []
    for r in range(realizations):
        seconds, out = cpu(lambda r=r: solver.run(np.random.SeedSequence(r)))
        n = max(int(out["n"][-1]), 1)
        per_slip.append(seconds / n)
        steps.append(out["steps"] / n)
        slips.append(n)
    return {"us_per_slip": 1e6 * float(np.median(per_slip)), "steps_per_slip": float(np.median(steps)),
            "slips": int(np.median(slips))}


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[16, 64, 256, 1024])
    p.add_argument("--sigma", type=float, default=0.3, help="sigma_theta / Ntilde")
    p.add_argument("--steps", type=int, default=1)
    p.add_argument("--qs-steps", type=int, default=200)
    p.add_argument("--tau", type=float, default=1e-4)
    p.add_argument("--realizations", type=int, default=5)
    p.add_argument("--ref-max", type=int, default=64)
    p.add_argument("--tau-size", type=int, default=64)
    p.add_argument("--taus", type=float, nargs="+", default=[1e-4, 1e-3, 1e-2, 1e-1])
    p.add_argument("--core", type=int, default=0)
    p.add_argument("--json", default=None, help="also write the numbers to this file")
    args = p.parse_args(argv)
    if hasattr(os, "sched_setaffinity"):
        try:
            os.sched_setaffinity(0, {args.core})
        except OSError:
            pass
    # Compile (or load) the kernels before any timing.
    Inertia2D(scene(16, args.sigma, 1), tau_ratio=args.tau).run(np.random.SeedSequence(0))
    simulate(scene(16, args.sigma, 2), np.random.SeedSequence(0))
    rows = []
    print(f"irregular networks, sigma_theta = {args.sigma} Ntilde, tau_dyn/tau_th = {args.tau:g}; CPU per slip")
    print(f"{'N':>6} {'slips':>7} {'inertia us':>11} {'steps/slip':>10} {'reference us':>13} {'ratio':>7} "
          f"{'quasi-static us':>16}")
    for n in args.sizes:
        sc = scene(n, args.sigma, args.steps)
        row = {"N": n, **inertia_cost(sc, args.tau, args.realizations)}
        if n <= args.ref_max:
            seconds, out = cpu(lambda sc=sc: Dynamics(sc, tau_ratio=args.tau).run(np.random.SeedSequence(0)))
            row["reference_us_per_slip"] = 1e6 * seconds / max(int(out["n"][-1]), 1)
        qs = scene(n, args.sigma, args.qs_steps)
        seconds, out = cpu(lambda qs=qs: simulate(qs, np.random.SeedSequence(0)))
        row["quasi_static_us_per_slip"] = 1e6 * seconds / max(int(out["n"][-1]), 1)
        ref = row.get("reference_us_per_slip", float("nan"))
        print(f"{n:>6} {row['slips']:>7} {row['us_per_slip']:>11.1f} {row['steps_per_slip']:>10.1f} "
              f"{ref:>13.0f} {ref / row['us_per_slip']:>7.0f} {row['quasi_static_us_per_slip']:>16.3f}")
        rows.append(row)
    print(f"\ngrowth with tau_dyn/tau_th at N = {args.tau_size}")
    taus = []
    for tau in args.taus:
        row = {"tau": tau, **inertia_cost(scene(args.tau_size, args.sigma, args.steps), tau, args.realizations)}
        print(f"  tau {tau:>7g}: {row['us_per_slip']:8.1f} us/slip, {row['steps_per_slip']:6.1f} steps/slip, "
              f"{row['slips']} slips")
        taus.append(row)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump({"args": vars(args), "sizes": rows, "taus": taus}, f, indent=1)


if __name__ == "__main__":
    main()
