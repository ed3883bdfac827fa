"""How far from unit length the direction of a 2D driving slip is, and why it is kept so.

At a driving event the 2D kernels slip node i along F_i / (mu_s,i N_i): the
force at the critical theta divided by the threshold, which |F_i| equals up
to the rounding of eq. `critique`'s root (``kernels.plane.critical_thetas``).
This script draws states as the kernels meet them (a stable force f, |f| <
mu N, at a dilation theta_0 of size sigma_theta/Ntilde, so a = f - g
theta_0), computes both critical thetas as the kernels do, and reports the
largest | |F(theta_c)| / (mu N) - 1 |, which is the relative error of the
slip's length and of the force at which the node slips.

    python benchmarks/driving_slip_direction.py [--samples 20000] [--seed 0]
"""

from __future__ import annotations

import argparse

import numpy as np

from slidernet.kernels.plane import critical_thetas


def deviation(ratio: float, samples: int, rng: np.random.Generator) -> float:
    """The largest | |a + g theta_c| / lim - 1 | over random states at sigma_theta / Ntilde = ``ratio``."""
    worst = 0.0
    for _ in range(samples):
        g = rng.normal(size=2)
        lim = rng.uniform(0.5, 0.7)
        f = rng.normal(size=2)
        f *= lim * rng.uniform(0.0, 1.0) / np.linalg.norm(f)
        a = f - g * (rng.normal() * ratio)
        for theta_c in critical_thetas(a[0], a[1], g[0], g[1], lim):
            F = a + g * theta_c
            worst = max(worst, abs(np.hypot(F[0], F[1]) / lim - 1.0))
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=20_000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    print("sigma_theta/Ntilde   max | |F(theta_c)| / (mu_s N) - 1 |")
    for ratio in (1.0, 10.0, 1e2, 1e4, 1e6, 1e8):
        print(f"{ratio:<20g} {deviation(ratio, args.samples, rng):.2e}")


if __name__ == "__main__":
    main()
