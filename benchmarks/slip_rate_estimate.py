"""The estimate of slips per tau_th of slidernet.solver.budget against the study's measured rates.

``python benchmarks/slip_rate_estimate.py`` (a few seconds; no run, only scenes): for each row of the table
of docs/guides/aging-networks.md as of commit a921f70 (the earlier grid of ``examples/aging_networks.py``:
"slips/tau_th", the rate of rearrangements measured over 16 realizations of the horizontal evolution, 300 to
1e4 tau_th, network seed 0), :func:`slidernet.solver.budget.slips_per_tau` from the
same configuration (``examples/aging_networks.toml`` with the row's network, sigma_mu and sigma_theta), and
the ratio estimate / measured. It exits with status 1, naming the scenes, when any ratio is outside
[1/2, 2] (``FACTOR``). The slow-run warning (:func:`slidernet.solver.budget.warn_if_slow`), the ensembles
guide ("Before a run") and the performance guide quote these ratios as the estimate's error.
"""

from __future__ import annotations

import sys
from pathlib import Path

from slidernet.config import load_config, read_toml
from slidernet.solver import Scene, budget

#: (kind, N, sigma_mu / (mean - mu_d), sigma_theta / Ntilde, measured slips per tau_th), from the table.
MEASURED = [
    ("chain", 2, 0.1, 1, 2.887), ("chain", 2, 0.3, 1, 2.884), ("chain", 3, 0.1, 1, 5.775),
    ("chain", 4, 0.1, 1, 8.139), ("chain", 8, 0.1, 1, 11.94), ("chain", 16, 0.1, 1, 12.36),
    ("chain", 16, 0.3, 1, 12.58), ("chain", 2, 0.1, 10, 53.16), ("chain", 4, 0.1, 10, 197.6),
    ("chain", 8, 0.1, 10, 577.6), ("chain", 16, 0.1, 10, 1276.0), ("irregular", 16, 0.1, 1, 277.8),
    ("irregular", 64, 0.1, 1, 1530.0), ("irregular", 256, 0.1, 1, 6422.0), ("irregular", 1024, 0.1, 1, 24670.0),
    ("irregular", 4096, 0.1, 1, 81520.0), ("irregular", 16, 0.1, 10, 3244.0), ("irregular", 64, 0.1, 10, 22690.0),
]

#: The largest factor between the estimate and the measured rate, either way.
FACTOR = 2.0


def main() -> int:
    base = read_toml(Path(__file__).resolve().parents[1] / "examples" / "aging_networks.toml")
    outside = []
    print(f"{'network':>10} {'N':>5} {'ratio':>5} {'sig/Nt':>6} {'measured':>10} {'estimate':>10} {'est/meas':>8}")
    for kind, n, ratio, sig, measured in MEASURED:
        raw = dict(base, realizations=1, steps=10_000, observables=["n"], mu_eff_at="auto")
        raw["network"] = {"kind": kind, "n": n, "Ntilde": 1e-7} | ({"seed": 0} if kind == "irregular" else {})
        raw["friction"] = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.1 * ratio}}
        raw["driver"] = {"name": "gaussian_steps", "sigma_theta": sig * 1e-7}
        cfg = load_config(raw)
        estimate = budget.slips_per_tau(cfg, Scene.from_config(cfg))
        print(f"{kind:>10} {n:5d} {ratio:5.1f} {sig:6g} {measured:10.4g} {estimate:10.4g} "
              f"{estimate / measured:8.2f}")
        if not 1 / FACTOR <= estimate / measured <= FACTOR:
            outside.append(f"{kind} {n} at sigma_theta / Ntilde = {sig:g} ({estimate / measured:.2f}x)")
    if outside:
        print(f"FAIL: the estimate is outside a factor {FACTOR:g} of the measured rate for {len(outside)} of "
              f"{len(MEASURED)} scenes: " + "; ".join(outside))
        return 1
    print(f"OK: the estimate is within a factor {FACTOR:g} of the measured rate for all {len(MEASURED)} scenes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
