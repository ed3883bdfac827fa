"""Slips per second against network size, triangular lattices with free boundaries.

    python benchmarks/bench_networks.py [--sizes 10 32 100 316 1000] [--slips 10000000] [--out DIR]

For each L x L lattice (N = L^2 nodes) at sigma_theta / Ntilde = 1, runs
thermal steps until at least ``--slips`` slips are done, on one core, and
prints the slip rate of the kernel alone and with the setup included
(building the network, K, g, the thresholds, theta(t) and the heaps), the
setup time, the peak resident memory of the process so far (the largest
lattice comes last, so its row is its own peak) and the memory per node:
the peak resident memory during that lattice's setup and run minus the
resident memory just before its setup, divided by N (bytes/node; Linux only:
the peak is reset through /proc/self/clear_refs and read from VmHWM). At
small N that figure is dominated by per-run arrays that do not grow with N
(theta(t) over the run's steps, buffers), so the script also prints the
marginal memory per node between the two largest lattices. Before each
baseline the script collects garbage and calls glibc's ``malloc_trim``, so
that each row measures the same way whatever ran before it. With ``--out`` it
also writes ``network_scaling.csv`` and ``network_scaling.png`` (the scaling
curve).
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import ctypes
import gc
import math
import re
import resource
import time
from pathlib import Path

import numpy as np

from slidernet.config import load_config
from slidernet.io import atomic_output, save_figure
from slidernet.solver import Realization, Scene


def _status_kB(field: str) -> int:
    """A memory field of /proc/self/status (VmRSS, VmHWM), in kB."""
    match = re.search(rf"^{field}:\s+(\d+) kB", Path("/proc/self/status").read_text(), re.MULTILINE)
    if match is None:
        raise OSError(f"no {field} in /proc/self/status")
    return int(match.group(1))


def _reset_peak_rss() -> int | None:
    """Reset the process's peak RSS (VmHWM) to its current RSS; returns that RSS in kB, None where unsupported."""
    gc.collect()
    # Hand the heap's free memory back to the OS (glibc), so that what the previous lattice freed is not
    # reused unseen by this one: each row then measures the same way whatever ran before it.
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return _status_kB("VmRSS")
    except OSError:
        return None


def bench(L: int, slips: int) -> dict[str, float]:
    """One lattice: returns N, slips, kernel rate, rate with setup (slips/s), setup (s), peak RSS (GB), bytes/node.

    ``peak_kB`` and ``baseline_kB`` (kB) are the peak RSS during this lattice and the RSS before its setup.
    """
    baseline = _reset_peak_rss()
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
        q = min(q + max(1, q // 4), cfg.steps)  # few returns to Python, few slips past the target
        r.advance(q)
    t2 = time.perf_counter()
    # ru_maxrss is in kB on Linux.
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
    peak = _status_kB("VmHWM") if baseline is not None else math.nan
    base = baseline if baseline is not None else math.nan
    return {"N": L * L, "slips": r.n, "steps": q, "kernel": r.n / (t2 - t1), "with_setup": r.n / (t2 - t0),
            "setup": t1 - t0, "rss_GB": rss, "peak_kB": peak, "baseline_kB": base,
            "bytes_per_node": (peak - base) * 1024 / (L * L)}


def plot(rows: list[dict[str, float]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    N = [r["N"] for r in rows]
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.semilogx(N, [r["kernel"] / 1e6 for r in rows], "o-", label="kernel")
    ax.semilogx(N, [r["with_setup"] / 1e6 for r in rows], "s--", label="setup included")
    ax.set_ylim(0, None)
    ax.set_xlabel("sliders N (triangular L x L)")
    ax.set_ylabel("slips per second (millions)")
    ax.set_title(f"one core, {rows[-1]['slips']:.1e} slips per run", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10, 32, 100, 316, 1000])
    ap.add_argument("--slips", type=int, default=10_000_000)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    bench(10, 10_000)  # load the compiled kernels before timing
    rows = []
    print("| N | slips | kernel slips/s | with setup | setup | peak RSS | memory/node |")
    print("|---|---|---|---|---|---|---|")
    for L in args.sizes:
        r = bench(L, args.slips)
        rows.append(r)
        print(f"| {r['N']:,} | {r['slips']:.2e} | {r['kernel'] / 1e6:.2f} M | {r['with_setup'] / 1e6:.2f} M | "
              f"{r['setup']:.2f} s | {r['rss_GB']:.2f} GB | {r['bytes_per_node']:,.0f} B |", flush=True)
    if len(rows) > 1:
        a, b = sorted(rows, key=lambda r: r["N"])[-2:]
        grown_kB = (b["peak_kB"] - b["baseline_kB"]) - (a["peak_kB"] - a["baseline_kB"])
        marginal = grown_kB * 1024 / (b["N"] - a["N"])
        print(f"marginal memory per node between N = {a['N']:,} and N = {b['N']:,}: {marginal:,.0f} bytes/node")
    by_n = {r["N"]: r for r in rows}
    if 1_000_000 in by_n and 1024 in by_n:
        print(f"rate at 1e3 / rate at 1e6: kernel {by_n[1024]['kernel'] / by_n[1_000_000]['kernel']:.2f}, "
              f"setup included {by_n[1024]['with_setup'] / by_n[1_000_000]['with_setup']:.2f}")
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        with atomic_output(args.out / "network_scaling.csv") as tmp, open(tmp, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        plot(rows, args.out / "network_scaling.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
