"""What ``[tilt] inject`` costs: CPU seconds of the injected twin against the plain network tilt test it pairs.

    python benchmarks/inject_cost.py [--sizes 64 256 1024] [--realizations 6] [--tests 3] [--age 100]
                                     [--c 0.01] [--select 1.0]

For irregular networks of ``--sizes`` nodes (network seed 0; mu_d = 0.5,
Gaussian mu_s of mean 0.6 and std 0.03, Ntilde = 1e-7, gaussian_steps at
sigma_theta / Ntilde = 1), ``--realizations`` realizations (children of
``SeedSequence(1)``) are aged ``--age`` thermal steps; on each state,
``--tests`` times in a row, the injected twin (``Realization.tilt_test`` on
``Realization.tested_thresholds(k, True)``, the stream left where it was) and
then the plain test on the same draws are timed with ``time.process_time``
(CPU seconds, so that other processes on the machine count less), as a run
with ``inject`` makes them at a recorded time. It prints the mean CPU
seconds of each and the ratio twin / plain (of the sums over all tests, and
the median of the per-test ratios). With ``inject`` a record makes both, so
the tilt tests of such a run cost 1 + that ratio times the plain ones'.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from slidernet.config import load_config
from slidernet.solver import Realization, Scene


def scene(n: int, age: int, inject: dict[str, float]) -> Scene:
    """An irregular network of ``n`` nodes recording mu_eff at ``age``, with the injection."""
    return Scene.from_config(load_config({
        "seed": 1, "steps": age, "record": [age], "observables": ["n", "mu_eff"], "mu_eff_at": "records",
        "network": {"kind": "irregular", "n": n, "Ntilde": 1e-7, "seed": 0},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.03}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}, "tilt": {"inject": inject}}))


def timed(sc: Scene, realizations: int, tests: int) -> tuple[np.ndarray, np.ndarray]:
    """CPU seconds of the plain tests and of their twins, in the order they were made."""
    plain, twin = [], []
    k = sc.out_steps.size - 1
    for r in range(realizations):
        real = Realization(sc, np.random.SeedSequence(1, spawn_key=(r,)))
        real.advance(int(sc.out_steps[k]) - 1)  # the state the record at out_steps[k] would test, its step aside
        for _ in range(tests):
            t0 = time.process_time()
            real.tilt_test(real.tested_thresholds(k, True), advance=False)
            twin.append(time.process_time() - t0)
            t0 = time.process_time()
            real.tilt_test()
            plain.append(time.process_time() - t0)
    return np.array(plain), np.array(twin)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 256, 1024])
    parser.add_argument("--realizations", type=int, default=6)
    parser.add_argument("--tests", type=int, default=3)
    parser.add_argument("--age", type=int, default=100)
    parser.add_argument("--c", type=float, default=0.01)
    parser.add_argument("--select", type=float, default=1.0)
    args = parser.parse_args(argv)
    inject = {"c": args.c, "select": args.select}
    timed(scene(16, 2, inject), 1, 1)  # compile, untimed
    print("| irregular N | tests | CPU s per plain test | CPU s per twin | twin / plain (sums) "
          "| median per test |")
    print("|---|---|---|---|---|---|")
    for n in args.sizes:
        plain, twin = timed(scene(n, args.age, inject), args.realizations, args.tests)
        print(f"| {n} | {plain.size} | {plain.mean():.3g} | {twin.mean():.3g} | {twin.sum() / plain.sum():.2f} | "
              f"{np.median(twin / plain):.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
