"""Does the network answer of "Aging in networks" survive inertia? The dynamics check with the compiled solver.

For the pair and irregular 2D networks at ratio sigma_mu / (mu_s - mu_d) =
0.3 (where the pair ages: mu_d = 0.5, Gaussian mu_s of mean 0.6 and std
0.03, Ntilde = 1e-7, gaussian_steps with sigma_theta / Ntilde = 1), each
system is run to T tau_th quasi-statically and with ``[dynamics] tau_ratio``
at each tau_dyn / tau_th asked, on the same seeds (the same theta(t_q) and
initial thresholds: common random numbers), and read at the recorded times
(5 per decade) by the network tilt test on the state as it stands:

- ``tilt_break_ratio``, the estimator that passes the positive control of
  ``examples/aging_recovery.py`` (the contacts' local ratio |F_i| / N_i as
  each breaks);
- ``mu_max``, the paper's strongest threshold, and ``mu_mean``, the mean
  threshold;
- ``mu_eff``, the test's sample (blind to aging from 16 sliders on: the
  positive control);
- the slip rate (slips per tau_th over the run).

Per realization, each variable's least-squares slope against ln t over
10 <= t <= T (:func:`slidernet.analysis.trend.log_trend`), times ln 10: per
decade. Irregular networks have several geometries (network seeds), each
with its own realizations: the geometries are the independent units
(:func:`slidernet.analysis.trend.grouped_mean_sem`); the pair's realizations
are. Besides each slope, the paired difference (dynamics minus quasi-static,
realization by realization on the same seed) and its standard error.

Run from the repository root::

    python benchmarks/aging_dynamics_power.py --out DIR [--workers 2]

Defaults: the pair (64 realizations), irregular 16 (4 geometries x 4
realizations) and 64 (4 geometries x 1), T = 1000 tau_th, tau_dyn / tau_th in
{1e-4, 1e-3, 1e-2, 1e-1} (64 sliders: 1e-4, 1e-1 and 1e-2, in that order; 256 sliders, 4
geometries x 1, only when asked by ``--sizes 256``, with ``--taus`` to choose). ``--quick`` runs the
pair and irregular 16 to 100 tau_th. The JSON (``aging_dynamics_power.json``)
and a Markdown table are written when every point is done; each point's
dataset is kept (``points/``), and a rerun reads the points already there.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

import slidernet
from slidernet.analysis.trend import grouped_mean_sem, log_trend

ESTIMATORS = ("tilt_break_ratio", "mu_max", "mu_mean", "mu_eff_realization")
LN10 = math.log(10.0)


def config(n: int, geometry: int, realizations: int, steps: int, tau: float | None) -> dict[str, Any]:
    """One point: the pair (n = 2, a chain) or an irregular network of n sliders, geometry ``geometry``."""
    network: dict[str, Any] = ({"kind": "chain", "n": 2, "Ntilde": 1e-7} if n == 2 else
                               {"kind": "irregular", "n": n, "Ntilde": 1e-7, "seed": geometry})
    cfg: dict[str, Any] = {
        "seed": 1 + geometry, "realizations": realizations, "steps": steps, "record": "log",
        "log_points_per_decade": 5, "network": network,
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.03}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7},
        "observables": ["n", "mu_max", "mu_mean", "mu_eff", "mu_eff_realization", "tilt_loads"],
        "mu_eff_at": "records"}
    if tau is not None:
        cfg["dynamics"] = {"tau_ratio": tau}
    elif n == 2:
        cfg["solver"] = {"kernel": "csr"}  # mu_mean: a network kernel's record (the same bits as the pair's)
    return cfg


def run_point(n: int, geometry: int, realizations: int, steps: int, tau: float | None, out: Path,
              workers: int | None) -> xr.Dataset:
    """The dataset of one point, run in its own folder under ``out`` (resumed or read back there)."""
    where = out / "points" / f"n{n}_g{geometry}_tau{'qs' if tau is None else f'{tau:g}'}"
    cfg = config(n, geometry, realizations, steps, tau)
    cfg["execution"] = {"workers": workers} if workers else {}
    if (where / "result.nc").exists():  # a point an earlier run finished
        return xr.load_dataset(where / "result.nc")
    # The run's own folder: checkpoints, and an interrupted point resumed.
    return slidernet.run(cfg, out=where, resume=where.exists(), progress=False)


def slopes(ds: xr.Dataset, t_min: float) -> dict[str, np.ndarray]:
    """Per realization: each estimator's slope per decade over t >= t_min, and the slip rate per tau_th."""
    out = {name: log_trend(ds[name], t_min=t_min)["slope"].values * LN10 for name in ESTIMATORS}
    out["slip_rate"] = ds["n"].isel(t=-1).values / float(ds["t"].values[-1])
    # The level: each estimator's mean over the records of the window, per realization.
    late = ds["t"] >= t_min
    for name in ("tilt_break_ratio", "mu_eff_realization"):
        out[name + "_level"] = ds[name].where(late).mean("t").values
    return out


def summary(values: np.ndarray, groups: np.ndarray) -> dict[str, float]:
    mean, sem, units = grouped_mean_sem(values, groups)
    return {"mean": mean, "sem": sem, "units": units}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--t-min", type=float, default=10.0)
    parser.add_argument("--sizes", type=int, nargs="+", default=None,
                        help="only these N (256: 4 geometries x 1 realization, not run by default)")
    parser.add_argument("--taus", type=float, nargs="+", default=None, help="only these tau_dyn / tau_th")
    args = parser.parse_args(argv)
    taus = (1e-4, 1e-3, 1e-2, 1e-1)
    # (n, geometries, realizations per geometry, steps, taus)
    systems = ([(2, 1, 16, 100, taus), (16, 2, 2, 100, taus)] if args.quick else
               [(2, 1, 64, 1000, taus), (16, 4, 4, 1000, taus), (64, 4, 1, 1000, (1e-4, 1e-1, 1e-2)),
                (256, 4, 1, 1000, (1e-4, 1e-1, 1e-3, 1e-2))])
    if args.sizes is None and not args.quick:
        systems = systems[:3]  # 256 sliders cost 10-60 min of CPU per realization and tau: asked by --sizes
    elif args.sizes is not None:
        systems = [s for s in systems if s[0] in args.sizes]
    if args.taus is not None:
        systems = [(*s[:4], tuple(t for t in s[4] if t in args.taus)) for s in systems]
    args.out.mkdir(parents=True, exist_ok=True)
    start = time.monotonic()
    results: list[dict[str, Any]] = []
    for n, geometries, R, steps, point_taus in systems:
        groups = np.repeat(np.arange(geometries), R) if geometries > 1 else np.arange(R)
        per_tau: dict[str, dict[str, np.ndarray]] = {}
        for tau in (None, *point_taus):
            parts = [slopes(run_point(n, g, R, steps, tau, args.out, args.workers), args.t_min)
                     for g in range(geometries)]
            per_tau["qs" if tau is None else f"{tau:g}"] = {k: np.concatenate([p[k] for p in parts])
                                                           for k in parts[0]}
            print(f"N = {n}, tau = {tau}: done at {time.monotonic() - start:.0f} s", flush=True)
        qs = per_tau["qs"]
        for key, values in per_tau.items():
            row: dict[str, Any] = {"n": n, "geometries": geometries, "realizations": R * geometries,
                                   "steps": steps, "tau_ratio": key}
            for name, v in values.items():
                row[name] = summary(v, groups)
                if key != "qs":
                    row[name + "_minus_qs"] = summary(v - qs[name], groups)
                    row[name + "_over_qs"] = summary(v / qs[name], groups)
            results.append(row)
    data = {"command": "python benchmarks/aging_dynamics_power.py " + " ".join(sys.argv[1:] if argv is None
                                                                                else argv),
            "t_min": args.t_min, "wall_time_s": time.monotonic() - start, "machine": platform.platform(),
            "slidernet": slidernet.__version__, "points": results}
    (args.out / "aging_dynamics_power.json").write_text(json.dumps(data, indent=1))
    (args.out / "aging_dynamics_power.md").write_text(table(data))
    print(table(data))
    return 0


def _pm(e: dict[str, float], scale: float) -> str:
    if scale == 1:
        return f"{e['mean']:.3f} ± {e['sem']:.3f}"
    return f"{e['mean'] * scale:+.1f} ± {e['sem'] * scale:.1f}"


def table(data: dict[str, Any]) -> str:
    """The page's table: slopes per decade (1e-4) of each estimator and the slip rate, with the paired
    differences from the quasi-static run."""
    lines = ["| N | τ_dyn/τ_th | tilt_break_ratio | Δ vs QS | mu_max | Δ vs QS | mu_mean | mu_eff "
             "| break ratio level, Δ vs QS (1e-4) | slips per τ_th | rate / QS |"]
    lines.append("|---" * 11 + "|")
    for p in data["points"]:
        dyn = p["tau_ratio"] != "qs"
        lines.append(
            f"| {p['n']} | {p['tau_ratio']} | {_pm(p['tilt_break_ratio'], 1e4)} | "
            f"{_pm(p['tilt_break_ratio_minus_qs'], 1e4) if dyn else ''} | {_pm(p['mu_max'], 1e4)} | "
            f"{_pm(p['mu_max_minus_qs'], 1e4) if dyn else ''} | {_pm(p['mu_mean'], 1e4)} | "
            f"{_pm(p['mu_eff_realization'], 1e4)} | {p['tilt_break_ratio_level']['mean']:.4f}"
            f"{', ' + _pm(p['tilt_break_ratio_level_minus_qs'], 1e4) if dyn else ''} | "
            f"{p['slip_rate']['mean']:.4g} ± {p['slip_rate']['sem']:.2g} | "
            f"{_pm(p['slip_rate_over_qs'], 1) if dyn else ''} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
