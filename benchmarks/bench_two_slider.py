"""Rearrangements per second of the two-slider case, at the paper's parameters, on one core and on all cores.

    python benchmarks/bench_two_slider.py [--steps 100000] [--realizations 10] [--workers N] [--csv PATH]

One core: one line per method, the compiled pair kernel (with and without the
tilt test), the general CSR kernel on the same scene, and a plain-Python loop
of the same algorithm (eq. `critique` and eq. `displacement`), measured in the
same run, then the ratio of each compiled rate to the plain-Python one.
Wall times include drawing the thresholds and the thetas (the whole
``simulate`` call), not numba's one-time compilation, which is cached on disk.

All cores: the same realizations (``SeedSequence(1).spawn(realizations)``),
dealt round-robin to ``--workers`` processes (default ``os.cpu_count()``,
start method ``spawn``). Each worker loads the cached kernels before any
timing; that warm-up (process start, imports, loading the kernels) is timed
on its own. The timed part runs from handing out the seeds to the last
result, so it includes the inter-process traffic. Same seeds give the same
bits, so the script checks that the total number of rearrangements equals
the one-core total.

Every timed line also gives the CPU share: CPU seconds of the timed
processes over (wall seconds x cores). Well below 1 means that other
processes took the cores during the measurement, and the rate is low for
that reason.

``--csv PATH`` writes one row per measurement: method, cores, rearrangements,
seconds (wall), rate (rearrangements/s), cpu_share; the worker warm-up is a
row with 0 rearrangements and an empty rate.
"""

from __future__ import annotations

import argparse
import csv
import math
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from slidernet.config import load_config
from slidernet.solver import Scene, simulate

PAPER = {
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}

# (kernel, tilt test): the compiled methods, in the order they are printed.
COMPILED = [("pair", False), ("pair", True), ("csr", False)]

# (rearrangements, wall seconds, CPU seconds)
Timing = tuple[int, float, float]


def _label(kernel: str, tilt: bool) -> str:
    return f"{kernel} kernel" + (" + tilt test (mu_eff)" if tilt else "")


def _scene(kernel: str, steps: int, tilt: bool) -> Scene:
    obs = ["n", "mu_max", "x_G"] + (["mu_eff"] if tilt else [])
    cfg = {**PAPER, "steps": steps, "observables": obs, "solver": {"kernel": kernel}}
    return Scene.from_config(load_config(cfg))


def load_kernels() -> float:
    """Run every compiled method for 10 steps, so that numba loads them from its cache; returns seconds."""
    t0 = time.perf_counter()
    for kernel, tilt in COMPILED:
        simulate(_scene(kernel, 10, tilt), np.random.SeedSequence(0))
    return time.perf_counter() - t0


def run_realizations(kernel: str, tilt: bool, steps: int, seeds: list[np.random.SeedSequence]) -> Timing:
    """Total rearrangements n of the given realizations, with the wall and CPU seconds they took.

    Building the scene is not timed.
    """
    scene = _scene(kernel, steps, tilt)
    t0, c0 = time.perf_counter(), time.process_time()
    n = sum(int(simulate(scene, ss)["n"][-1]) for ss in seeds)
    return n, time.perf_counter() - t0, time.process_time() - c0


def bench_kernel(kernel: str, steps: int, realizations: int, tilt: bool) -> Timing:
    """One core: all realizations in this process."""
    return run_realizations(kernel, tilt, steps, np.random.SeedSequence(1).spawn(realizations))


# Set in each worker by _worker_init: the barrier of the warm-up tasks and the seconds load_kernels took.
_WORKER: dict[str, Any] = {}


def _worker_init(barrier: Any) -> None:
    # A barrier reaches a worker only through process creation (initargs), not as a task argument.
    _WORKER["barrier"] = barrier
    _WORKER["load_s"] = load_kernels()


def _worker_ready() -> tuple[int, float]:
    # Each worker holds here until all are up, so every worker gets exactly one of these tasks.
    _WORKER["barrier"].wait(timeout=300)
    return os.getpid(), _WORKER["load_s"]


def bench_all_cores(steps: int, realizations: int,
                    workers: int) -> tuple[float, float, dict[tuple[str, bool], Timing]]:
    """All cores: the warm-up wall time (s), the slowest worker's kernel loading (s), and per method a Timing.

    The Timing's CPU seconds are summed over the workers.
    """
    ctx = multiprocessing.get_context("spawn")
    barrier = ctx.Barrier(workers)
    seeds = np.random.SeedSequence(1).spawn(realizations)
    chunks = [seeds[w::workers] for w in range(workers) if seeds[w::workers]]
    results = {}
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_init,
                             initargs=(barrier,)) as pool:
        ready = [f.result() for f in [pool.submit(_worker_ready) for _ in range(workers)]]
        warmup = time.perf_counter() - t0
        if len({pid for pid, _ in ready}) != workers:
            raise RuntimeError(f"expected {workers} distinct warm workers, got {ready}")
        for kernel, tilt in COMPILED:
            t1 = time.perf_counter()
            parts = [f.result() for f in [pool.submit(run_realizations, kernel, tilt, steps, chunk)
                                          for chunk in chunks]]
            wall = time.perf_counter() - t1
            results[(kernel, tilt)] = (sum(p[0] for p in parts), wall, sum(p[2] for p in parts))
    return warmup, max(s for _, s in ready), results


def plain_python(steps: int, seed: int = 1) -> Timing:
    """The paper's loop in plain Python (section III.A), one realization."""
    rng = np.random.default_rng(seed)
    Ntilde, mu_d, mean, std, sigma = 1e-7, 0.5, 0.6, 0.01, 1e-6
    thetas = sigma * rng.standard_normal(steps + 1)
    mus = [mean + std * rng.standard_normal(), mean + std * rng.standard_normal()]
    u, xg, n = thetas[0], 0.0, 0
    t0, c0 = time.perf_counter(), time.process_time()
    normal = rng.standard_normal
    for q in range(steps):
        a, b = thetas[q], thetas[q + 1]
        s = math.copysign(1.0, b - a)
        while True:
            i = 0 if mus[0] <= mus[1] else 1
            theta_c = u + mus[i] * Ntilde * s
            if s * (b - theta_c) < 0:
                break
            du = 2 * (mus[i] - mu_d) * Ntilde * s
            u += du
            xg += du / 2 if i == 1 else -du / 2
            mus[i] = mean + std * normal()
            n += 1
    return n, time.perf_counter() - t0, time.process_time() - c0


def _row(method: str, cores: int, t: Timing) -> dict[str, Any]:
    n, wall, cpu = t
    return {"method": method, "cores": cores, "rearrangements": n, "seconds": wall, "rate": n / wall,
            "cpu_share": cpu / (wall * cores)}


def _line(row: dict[str, Any]) -> str:
    return (f"{row['method']:40s} {row['rate'] / 1e6:8.2f} M rearrangements/s  "
            f"({row['rearrangements']} in {row['seconds']:.2f} s, CPU share {row['cpu_share']:.2f})")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--realizations", type=int, default=10)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="processes for the all-cores run")
    ap.add_argument("--csv", type=Path, default=None, help="write one row per measurement to this file")
    args = ap.parse_args(argv)
    rows: list[dict[str, Any]] = []

    print(f"two sliders, sigma_theta = 1e-6, Ntilde = 1e-7, {args.realizations} x {args.steps} steps; "
          f"load average {os.getloadavg()[0]:.2f}")
    print(f"loading the compiled kernels in this process: {load_kernels():.2f} s (not timed below)")
    print("one core:")
    one_core = {}
    for kernel, tilt in COMPILED:
        one_core[(kernel, tilt)] = row = _row(_label(kernel, tilt), 1, bench_kernel(kernel, args.steps,
                                                                                       args.realizations, tilt))
        rows.append(row)
        print(_line(row))
    py = _row("plain-Python loop", 1, plain_python(min(args.steps, 20_000)))
    rows.append(py)
    print(_line(py))
    for row in one_core.values():
        print(f"{row['method'] + ' / plain-Python loop':56s} {row['rate'] / py['rate']:6.1f} x")

    warmup, load, all_cores = bench_all_cores(args.steps, args.realizations, args.workers)
    print(f"{args.workers} cores ({args.workers} spawned processes, realizations dealt round-robin):")
    print(f"worker warm-up (start, imports, load kernels): {warmup:.2f} s wall, "
          f"of which loading the kernels {load:.2f} s (slowest worker); not timed below")
    rows.append({"method": "worker warm-up", "cores": args.workers, "rearrangements": 0, "seconds": warmup,
                 "rate": "", "cpu_share": ""})
    for (kernel, tilt), t in all_cores.items():
        row, one = _row(_label(kernel, tilt), args.workers, t), one_core[(kernel, tilt)]
        if row["rearrangements"] != one["rearrangements"]:
            raise AssertionError(f"{row['method']}: {row['rearrangements']} rearrangements on {args.workers} "
                                 f"cores, {one['rearrangements']} on one core, with the same seeds")
        rows.append(row)
        print(_line(row) + f"  speed-up {one['seconds'] / row['seconds']:.2f} x")
    print(f"same total n on one core and on {args.workers} cores, for every method; "
          f"load average {os.getloadavg()[0]:.2f}")

    if args.csv is not None:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
