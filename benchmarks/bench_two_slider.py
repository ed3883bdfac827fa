"""Rearrangements per second of the two-slider case, at the paper's parameters.

    python benchmarks/bench_two_slider.py [--steps 100000] [--realizations 10]

Prints one line per method: the compiled pair kernel (with and without the
tilt test), the general CSR kernel on the same scene, and a plain-Python loop
of the same algorithm (eq. `critique` and eq. `displacement`) for reference.
Wall times include drawing the thresholds and the thetas (the whole
``simulate`` call), not numba's one-time compilation, which is cached on disk.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from slidernet.config import load_config
from slidernet.solver import Scene, simulate

PAPER = {
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}


def bench_kernel(kernel: str, steps: int, realizations: int, tilt: bool) -> tuple[int, float]:
    obs = ["n", "mu_max", "x_G"] + (["mu_eff"] if tilt else [])
    cfg = load_config({**PAPER, "steps": steps, "observables": obs, "solver": {"kernel": kernel}})
    scene = Scene.from_config(cfg)
    simulate(Scene.from_config(load_config({**PAPER, "steps": 10, "observables": obs,
                                            "solver": {"kernel": kernel}})),
             np.random.SeedSequence(0))  # load the compiled kernel before timing
    seeds = np.random.SeedSequence(1).spawn(realizations)
    t0 = time.perf_counter()
    n = sum(int(simulate(scene, ss)["n"][-1]) for ss in seeds)
    return n, time.perf_counter() - t0


def plain_python(steps: int, seed: int = 1) -> tuple[int, float]:
    """The paper's loop in plain Python (section III.A), one realization."""
    rng = np.random.default_rng(seed)
    Ntilde, mu_d, mean, std, sigma = 1e-7, 0.5, 0.6, 0.01, 1e-6
    thetas = sigma * rng.standard_normal(steps + 1)
    mus = [mean + std * rng.standard_normal(), mean + std * rng.standard_normal()]
    u, xg, n = thetas[0], 0.0, 0
    t0 = time.perf_counter()
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
    return n, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--realizations", type=int, default=10)
    args = ap.parse_args()
    print(f"two sliders, sigma_theta = 1e-6, Ntilde = 1e-7, {args.realizations} x {args.steps} steps")
    for kernel, tilt in [("pair", False), ("pair", True), ("csr", False)]:
        n, dt = bench_kernel(kernel, args.steps, args.realizations, tilt)
        label = f"{kernel} kernel" + (" + tilt test (mu_eff)" if tilt else "")
        print(f"{label:32s} {n / dt / 1e6:8.2f} M rearrangements/s  ({n} in {dt:.2f} s)")
    n, dt = plain_python(min(args.steps, 20_000))
    print(f"{'plain-Python loop':32s} {n / dt / 1e6:8.2f} M rearrangements/s  ({n} in {dt:.2f} s)")


if __name__ == "__main__":
    main()
