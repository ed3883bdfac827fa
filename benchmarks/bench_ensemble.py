"""Ensembles: the speed-up from 1 to N local workers, and the per-realization overhead of Dask.

    python benchmarks/bench_ensemble.py [--realizations 16] [--steps 20000] [--tiny 200]

1. The paper's two sliders (sigma_theta/Ntilde = 10), R realizations of
   ``steps`` tau_th each: wall time of ``slidernet.run`` with 1 worker and with
   every core (``available_cores()``), the speed-up, and a check that both give
   the same bits.
2. Overhead: ``tiny`` realizations of 1 step each (the work is negligible),
   in this process, on local workers, and on a Dask ``LocalCluster`` with one
   worker process per core; the time per realization is the overhead of each
   backend (task submission, transport of the records, bookkeeping).

Numba's compiled kernels are loaded (from the on-disk cache) before timing.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import slidernet
from slidernet.ensemble.execution import available_cores

PAIR = {
    "seed": 1,
    "observables": ["n", "mu_max", "x_G"],
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}


def timed(**kwargs) -> tuple[float, object]:
    t0 = time.perf_counter()
    ds = slidernet.run(**kwargs)
    return time.perf_counter() - t0, ds


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--realizations", type=int, default=16)
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--tiny", type=int, default=200, help="realizations of the overhead test")
    args = p.parse_args(argv)
    cores = available_cores()
    slidernet.run({**PAIR, "steps": 10, "realizations": 1}, workers=1)  # load the kernels

    cfg = {**PAIR, "steps": args.steps, "realizations": args.realizations}
    t1, a = timed(config=cfg, workers=1)
    tn, b = timed(config=cfg, workers=cores)
    same = all(np.array_equal(a[k].values, b[k].values) for k in a.data_vars)
    slips = int(a["n"].values[:, -1].sum())
    print(f"two sliders, {args.realizations} realizations x {args.steps} tau_th, {slips:.3g} rearrangements")
    print(f"  1 worker : {t1:7.2f} s  {slips / t1 / 1e6:6.2f} M rearrangements/s")
    print(f"  {cores} workers: {tn:7.2f} s  {slips / tn / 1e6:6.2f} M rearrangements/s  "
          f"speed-up {t1 / tn:.2f}  same bits: {same}")

    tiny = {**PAIR, "steps": 1, "realizations": args.tiny}
    t_in, _ = timed(config=tiny, workers=1)
    t_pool, _ = timed(config=tiny, workers=cores)
    from distributed import LocalCluster

    with LocalCluster(n_workers=cores, threads_per_worker=1, processes=True, dashboard_address=None) as lc:
        slidernet.run({**tiny, "realizations": cores}, scheduler=lc.scheduler_address)  # warm the workers
        t_dask, _ = timed(config=tiny, scheduler=lc.scheduler_address)
    print(f"overhead per realization ({args.tiny} realizations of one step):")
    for name, t in (("in process", t_in), (f"{cores} local workers", t_pool), (f"Dask, {cores} workers", t_dask)):
        print(f"  {name:<18} {t / args.tiny * 1e3:7.2f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
