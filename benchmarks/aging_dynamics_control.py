"""The positive control of the dynamics check: does tilt_break_ratio see an aging injected under inertia?

Irregular networks of 16 (``--n``: another size; 4 geometries x 2 realizations, 300 tau_th, the aging study's
parameters at ratio 0.3) with ``[dynamics] tau_ratio`` 1e-3 and 1e-1 and ``[tilt] inject`` c = 0.01 (every
contact, t0 = 1): the recovery is the paired slope difference (injected twin minus plain) over t >= 10 divided
by the injected rate, with its standard error over the geometries.

    python benchmarks/aging_dynamics_control.py    # about 1 min on 2 cores
    python benchmarks/aging_dynamics_control.py --n 64 --workers 1    # the same at 64 sliders
"""
import argparse
import time

import numpy as np
import xarray as xr

import slidernet
from slidernet.analysis.trend import grouped_mean_sem, log_trend

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--n", type=int, default=16, help="sliders of the irregular networks")
parser.add_argument("--workers", type=int, default=2)
args = parser.parse_args()
c, t0, T = 0.01, 1.0, 300
t_start = time.monotonic()
for tau in (1e-3, 1e-1):
    diffs, groups = [], []
    for g in range(4):
        cfg = {"seed": 1 + g, "realizations": 2, "steps": T, "record": "log", "log_points_per_decade": 5,
               "network": {"kind": "irregular", "n": args.n, "Ntilde": 1e-7, "seed": g},
               "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.03}},
               "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7},
               "observables": ["n", "mu_eff", "tilt_loads"], "mu_eff_at": "records",
               "tilt": {"inject": {"c": c, "t0": t0, "select": 1.0}},
               "dynamics": {"tau_ratio": tau}, "execution": {"workers": args.workers}}
        ds = slidernet.run(cfg, progress=False)
        p = log_trend(ds["tilt_break_ratio"], t_min=10)["slope"].values
        i = log_trend(ds["tilt_break_ratio_injected"], t_min=10)["slope"].values
        diffs += list(i - p)
        groups += [g] * len(p)
    t = ds["t"].values
    shift = xr.DataArray(c * np.log1p(t / t0)[None, :], dims=("realization", "t"), coords={"t": t})
    rate = float(log_trend(shift, t_min=10)["slope"][0])
    m, s, u = grouped_mean_sem(np.array(diffs) / rate, np.array(groups))
    print(f"N {args.n}, tau {tau:g}: recovery {m:.2f} +- {s:.2f} (dof {u}), "
          f"{time.monotonic() - t_start:.0f} s", flush=True)
