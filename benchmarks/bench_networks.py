"""Slips per second against network size, triangular lattices with free boundaries.

    python benchmarks/bench_networks.py [--sizes 10 32 100 316 1000] [--slips 2000000]

For each L x L lattice (N = L^2 nodes) at sigma_theta / Ntilde = 1, runs thermal
steps until at least ``--slips`` slips are done and prints the slip rate of the
kernel alone and with the setup (building the network, K and the heaps)
included, and the peak resident memory of the process.
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from slidernet.config import load_config
from slidernet.solver import Realization, Scene


def bench(L: int, slips: int) -> None:
    cfg = load_config({
        "steps": 1_000_000, "record": [0],
        "network": {"kind": "triangular", "shape": [L, L], "Ntilde": 1e-7},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7},
    })
    t0 = time.perf_counter()
    r = Realization(Scene.from_config(cfg), np.random.SeedSequence(1))
    t1 = time.perf_counter()
    q = 0
    while r.n < slips:
        q += 1
        r.advance(q)
    t2 = time.perf_counter()
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
    print(f"N = {L * L:>9d}  slips {r.n:>10d} in {q:>6d} steps  kernel {r.n / (t2 - t1) / 1e6:6.2f} M/s  "
          f"with setup {r.n / (t2 - t0) / 1e6:6.2f} M/s  (setup {t1 - t0:5.2f} s)  peak RSS {rss:5.2f} GB")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10, 32, 100, 316, 1000])
    ap.add_argument("--slips", type=int, default=2_000_000)
    args = ap.parse_args()
    bench(10, 10_000)  # load the compiled kernels before timing
    for L in args.sizes:
        bench(L, args.slips)


if __name__ == "__main__":
    main()
