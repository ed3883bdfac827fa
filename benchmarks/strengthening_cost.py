"""What contact strengthening costs a run that uses it: slips per CPU second with and without it.

    python benchmarks/strengthening_cost.py [--steps 100] [--sigma 1 10] [--beta 0.02]

For a chain of 16, irregular networks of 64 and 256 and a 32 x 32
triangular lattice (mu_d = 0.5, Gaussian mu_s of mean 0.6 and std 0.01,
Ntilde = 1e-7, gaussian_steps at sigma_theta / Ntilde = each ``--sigma``,
seed 1, one realization on one core, only ``n`` recorded), each scene runs
without ``[friction.strengthening]`` and with the logarithmic law (``--beta``,
tau_c = 1e-3 tau_th), after an untimed run that compiles both. It prints the
slips, the CPU seconds of ``slidernet.run`` and the slips per second of each.
The two runs slip differently (strengthening changes the physics), so the
comparison is per slip. What the option costs scenes *without* it is
measured by ``benchmarks/ab_versions.py`` against a commit before it.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import slidernet

SCENES = {
    "chain 16": {"kind": "chain", "n": 16},
    "irregular 64": {"kind": "irregular", "n": 64, "seed": 0},
    "irregular 256": {"kind": "irregular", "n": 256, "seed": 0},
    "triangular 32 x 32": {"kind": "triangular", "shape": [32, 32]},
}


def config(network: dict[str, Any], sigma: float, steps: int, beta: float | None) -> dict[str, Any]:
    friction: dict[str, Any] = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
    if beta is not None:
        friction["strengthening"] = {"beta": beta, "tau_c": 1e-3}
    return {"seed": 1, "realizations": 1, "steps": steps, "record": [0, steps], "observables": ["n"],
            "network": {**network, "Ntilde": 1e-7}, "friction": friction,
            "driver": {"name": "gaussian_steps", "sigma_theta": sigma * 1e-7},
            "execution": {"workers": 1}}


def timed(cfg: dict[str, Any]) -> tuple[int, float]:
    """(slips, CPU seconds of slidernet.run) of one run."""
    t0 = time.process_time()
    ds = slidernet.run(cfg)
    return int(ds["n"].values[0, -1]), time.process_time() - t0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--steps", type=int, default=100)
    parser.add_argument("--sigma", type=float, nargs="+", default=[1.0, 10.0], help="sigma_theta / Ntilde")
    parser.add_argument("--beta", type=float, default=0.02)
    args = parser.parse_args(argv)
    for beta in (None, args.beta):  # compile both variants, untimed
        timed(config(SCENES["chain 16"], 1.0, 2, beta))
        timed(config(SCENES["irregular 64"], 1.0, 2, beta))
    print("| scene | sigma_theta/Ntilde | slips without | M slips/s | slips with | M slips/s | ratio |")
    print("|---|---|---|---|---|---|---|")
    for name, network in SCENES.items():
        for sigma in args.sigma:
            n0, s0 = timed(config(network, sigma, args.steps, None))
            n1, s1 = timed(config(network, sigma, args.steps, args.beta))
            r0, r1 = n0 / s0 / 1e6, n1 / s1 / 1e6
            print(f"| {name} | {sigma:g} | {n0} | {r0:.2f} | {n1} | {r1:.2f} | {r1 / r0:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
