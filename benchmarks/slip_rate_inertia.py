"""Why the equations of motion slip less often than the quasi-static solver: the rate against the slips' length.

For irregular 2D networks of N sliders (geometries 0..G-1, R realizations
each, the aging study's parameters: mu_d = 0.5, Gaussian mu_s of mean 0.6
and std 0.1 * ratio, Ntilde = 1e-7, gaussian_steps with sigma_theta / Ntilde
= 1), each run to T tau_th quasi-statically and with ``[dynamics] tau_ratio``
on the same seeds, reads from the event catalogue:

- the slip rate r (slips per tau_th, after the first tau_th);
- the mean length <|du|> of a slip, in Ntilde l0;
- their product, the sliding distance per tau_th that the drive makes the
  network cover, r <|du|>.

If inertia only changes how the relaxation is cut into slips (longer slips,
a node pushed on by its moving neighbours), r <|du|> stays what the
quasi-static solver gives while r falls: the check of that reading is the
ratio of the products, with standard errors over the geometries (the
independent units).

Run from the repository root (about 2 min on one core)::

    python benchmarks/slip_rate_inertia.py [--n 16] [--geometries 4] [--realizations 4] [--steps 30]
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

import numpy as np

import slidernet
from slidernet.analysis.trend import grouped_mean_sem

TAUS = (None, 1e-4, 1e-3, 1e-2, 1e-1)


def run(n: int, geometry: int, R: int, steps: int, ratio: float, tau: float | None) -> list[dict[str, float]]:
    """Per realization: the slip rate after t = 1, the mean slip length and their product."""
    cfg: dict[str, Any] = {
        "seed": 1 + geometry, "realizations": R, "steps": steps, "record": "all",
        "network": {"kind": "irregular", "n": n, "Ntilde": 1e-7, "seed": geometry},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.1 * ratio}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}, "observables": ["n", "events"],
        "execution": {"workers": 1}}
    if tau is not None:
        cfg["dynamics"] = {"tau_ratio": tau}
    ds = slidernet.run(cfg, progress=False)
    out = []
    which, time = ds["event_realization"].values, ds["event_time"].values
    dx = ds["event_dx"].values
    dy = ds["event_dy"].values if "event_dy" in ds else np.zeros_like(dx)
    for r in range(R):
        keep = (which == r) & (time >= 1.0)
        du = np.hypot(dx[keep], dy[keep]) / 1e-7
        rate = keep.sum() / (steps - 1.0)
        out.append({"rate": rate, "length": float(du.mean()), "distance": rate * float(du.mean())})
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=16)
    parser.add_argument("--geometries", type=int, default=4)
    parser.add_argument("--realizations", type=int, default=4)
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--ratios", type=float, nargs="+", default=[0.1, 0.3])
    args = parser.parse_args(argv)
    G, R = args.geometries, args.realizations
    groups = np.repeat(np.arange(G), R)
    print(f"irregular {args.n}, {G} geometries x {R} realizations, {args.steps} tau_th; errors over geometries")
    print("| ratio | τ_dyn/τ_th | slips per τ_th | ⟨abs du⟩ (Ñ l0) | distance per τ_th | rate / QS "
          "| distance / QS |")
    print("|---|---|---|---|---|---|---|")
    for ratio in args.ratios:
        qs = None
        for tau in TAUS:
            rows = [row for g in range(G) for row in run(args.n, g, R, args.steps, ratio, tau)]
            col = {k: np.array([row[k] for row in rows]) for k in rows[0]}
            if qs is None:
                qs = col
            cells = [grouped_mean_sem(col[k], groups) for k in ("rate", "length", "distance")]
            rel = [grouped_mean_sem(col[k] / qs[k], groups) for k in ("rate", "distance")]
            print(f"| {ratio:g} | {'QS' if tau is None else f'{tau:g}'} | "
                  + " | ".join(f"{m:.4g} ± {s:.2g}" for m, s, _ in cells + rel) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
