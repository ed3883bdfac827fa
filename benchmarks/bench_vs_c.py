"""slidernet against plain-C yardsticks, in the same run: the performance table of the README.

    python benchmarks/bench_vs_c.py [--anchors DIR] [--quick] [--paper] [--core 1] [--csv PATH]

The yardsticks are two plain C programs that solve the same model the
straightforward way (a two-slider loop and a triangular-lattice solver).
They are not part of slidernet: point ``--anchors`` (or the environment
variable ``SLIDERNET_ANCHORS``) at the folder that holds
``twoslider_loop.c`` and ``lattice.c``. The script builds them with
``cc -O3 -march=native`` in a temporary folder. Without a compiler or
without the folder it says so and prints slidernet's figures alone, the
ratio column reading "skipped".

Every slidernet workload runs in a fresh child process pinned to one core
(``--core``), so that its peak resident memory (``ru_maxrss``) is its own,
and the C run of the same workload follows it on the same core: the ratio
is a same-minute ratio. The workloads (the targets of the performance issue):

1. two sliders at the paper's setting (mu_d 0.5, Gaussian thresholds 0.6 +-
   0.01, Ntilde 1e-7, sigma_theta 1e-6), 10 realizations, draws included;
2. the same with the tilt test before every rearrangement (mu_eff);
3. the same on 2 cores (2 spawned workers) against 1;
4. triangular 32 x 32, sigma_theta / Ntilde = 1, 2000 steps;
5. triangular 1000 x 1000, 20 steps: setup, kernel alone, both, peak memory;
6. the rate at 1e6 nodes over the rate at 1e3 (kernel alone);
7. an irregular (Delaunay) network of 1e6 nodes, 2 steps (every node is driven: about
   2e7 slips a step), against row 5;
8. with ``--paper``: ``slidernet paper`` (full preset, 2 cores), wall time
   and peak memory (about 2 minutes).

``--quick`` shortens every run (smoke test; the ratios are then noisy).
Rates are M rearrangements (slips) per second.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent

PAIR = {"mu_d": 0.5, "mean": 0.6, "std": 0.01, "Ntilde": 1e-7, "sigma_theta": 1e-6}


# ---------------------------------------------------------------------------
# the workloads, run in child processes


def _pair_config(steps: int, realizations: int, mu_eff: bool) -> Any:
    from slidernet.config import load_config

    return load_config({
        "steps": steps, "realizations": realizations,
        "observables": ["n", "mu_max", "x_G", "mu_eff"] if mu_eff else ["n", "mu_max", "x_G"],
        "network": {"Ntilde": PAIR["Ntilde"]},
        "driver": {"name": "gaussian_steps", "sigma_theta": PAIR["sigma_theta"]},
        "friction": {"mu_d": PAIR["mu_d"],
                     "static": {"name": "gaussian", "mean": PAIR["mean"], "std": PAIR["std"]}},
    })


def _simulate(args: tuple[Any, int]) -> int:
    from slidernet.solver import simulate

    scene, seed = args
    import numpy as np

    return int(simulate(scene, np.random.SeedSequence(seed))["n"][-1])


def child_pair(steps: int, realizations: int, mu_eff: bool, workers: int) -> dict[str, float]:
    """Rearrangements per second of ``realizations`` runs, on ``workers`` processes (draws included)."""
    import numpy as np

    from slidernet.solver import Realization, Scene, simulate

    scene = Scene.from_config(_pair_config(steps, realizations, mu_eff))
    Realization(scene, np.random.SeedSequence(0)).advance(2)  # load the compiled kernels, untimed
    jobs = [(scene, seed) for seed in range(1, realizations + 1)]
    if workers == 1:
        t0 = time.perf_counter()
        n = sum(int(simulate(scene, np.random.SeedSequence(s))["n"][-1]) for _, s in jobs)
        wall = time.perf_counter() - t0
    else:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
            list(pool.map(_simulate, [(scene, 0)] * workers))  # start, import, load kernels: untimed
            t0 = time.perf_counter()
            n = sum(pool.map(_simulate, jobs))
            wall = time.perf_counter() - t0
    return {"slips": n, "seconds": wall, "rate": n / wall / 1e6}


def child_network(kind: str, size: int, steps: int) -> dict[str, float]:
    """Setup (config to the first kernel call) and kernel time of one realization."""
    import numpy as np

    from slidernet.config import load_config
    from slidernet.solver import Realization, Scene

    network = ({"kind": "triangular", "shape": [size, size]} if kind == "triangular"
               else {"kind": "irregular", "n": size * size})
    cfg = load_config({
        "steps": steps, "record": "log", "network": {**network, "Ntilde": 1e-7},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    })
    t0 = time.perf_counter()
    real = Realization(Scene.from_config(cfg), np.random.SeedSequence(1))
    t1 = time.perf_counter()
    real.advance()
    t2 = time.perf_counter()
    return {"slips": real.n, "setup": t1 - t0, "kernel": t2 - t1,
            "rate": real.n / (t2 - t1) / 1e6, "rate_with_setup": real.n / (t2 - t0) / 1e6,
            "mean_mu": float(real.mu.mean())}


def _run_child(kind: str, params: dict[str, Any], core: int | None) -> dict[str, float]:
    """Run a workload in a fresh Python process; adds its peak resident memory (GB)."""
    code = (f"import json, sys; sys.path.insert(0, {str(HERE)!r}); import bench_vs_c as b; "
            f"print(json.dumps(b.child_{kind}(**{params!r})))")
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          preexec_fn=(lambda: os.sched_setaffinity(0, {core})) if core is not None else None)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    # ru_maxrss of the children is the largest so far: exact only when this child set it.
    out["peak_GB"] = peak / 1024**2 if peak > before else float("nan")
    return out


# ---------------------------------------------------------------------------
# the yardsticks


def build_anchors(folder: Path | None, tmp: Path) -> tuple[dict[str, Path], str]:
    """Compile the C yardsticks; returns their paths, or {} and why not."""
    if folder is None:
        return {}, "skipped (no anchors: --anchors or SLIDERNET_ANCHORS)"
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        return {}, "skipped (no C compiler)"
    built = {}
    for name in ("twoslider_loop", "lattice"):
        src = folder / f"{name}.c"
        if not src.exists():
            return {}, f"skipped ({src} not found)"
        subprocess.run([cc, "-O3", "-march=native", "-o", str(tmp / name), str(src), "-lm"], check=True)
        built[name] = tmp / name
    return built, ""


def _pinned(cmd: list[str], core: int | None) -> tuple[str, float]:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=True,
                          preexec_fn=(lambda: os.sched_setaffinity(0, {core})) if core is not None else None)
    return proc.stdout, time.perf_counter() - t0


def c_pair(exe: Path, steps: int, realizations: int, core: int | None) -> dict[str, float]:
    p = PAIR
    out, wall = _pinned([str(exe), str(p["mu_d"]), str(p["mean"]), str(p["std"]), str(p["Ntilde"]),
                         str(p["sigma_theta"]), str(steps), str(realizations), "1", "0"], core)
    mean_n = float(out.strip().splitlines()[-1].split()[1])  # last checkpoint: q mean_n ...
    return {"slips": mean_n * realizations, "seconds": wall, "rate": mean_n * realizations / wall / 1e6}


def c_lattice(exe: Path, size: int, steps: int, core: int | None) -> dict[str, float]:
    out, _ = _pinned([str(exe), str(size), str(size), "1e-7", "1e-7", str(steps), "1"], core)
    num = r"([0-9.e+-]+)"
    m = re.search(rf"slips {num} setup {num} s total {num} s rate {num} slips/s \(run only {num}\) "
                  rf"mean_mu {num}", out)
    if m is None:
        raise RuntimeError(f"unexpected output of the lattice yardstick: {out!r}")
    slips, setup, _total, rate, run_only, mean_mu = (float(x) for x in m.groups())
    return {"slips": slips, "setup": setup, "rate_with_setup": rate / 1e6, "rate": run_only / 1e6,
            "mean_mu": mean_mu}


# ---------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--anchors", type=Path, default=os.environ.get("SLIDERNET_ANCHORS"))
    ap.add_argument("--quick", action="store_true", help="short runs: a smoke test, noisy ratios")
    ap.add_argument("--paper", action="store_true", help="also time `slidernet paper` (full, 2 cores)")
    ap.add_argument("--core", type=int, default=1, help="the core of the one-core runs")
    ap.add_argument("--csv", type=Path, default=None)
    args = ap.parse_args(argv)
    core = args.core if hasattr(os, "sched_setaffinity") and args.core in os.sched_getaffinity(0) else None
    q = args.quick
    pair_steps, big, big_steps = (10_000, 100, 20) if q else (100_000, 1000, 20)
    rows: list[dict[str, Any]] = []

    def row(workload: str, ours: str, c: str, ratio: str, target: str, note: str = "") -> None:
        rows.append({"workload": workload, "slidernet": ours, "C": c, "ratio": ratio, "target": target,
                     "note": note})
        print(f"{workload}: slidernet {ours} | C {c} | ratio {ratio} (target {target}) {note}", flush=True)

    with tempfile.TemporaryDirectory(prefix="slidernet-vs-c-") as tmp:
        exe, why = build_anchors(args.anchors, Path(tmp))
        if why:
            print(f"C yardsticks: {why}", flush=True)

        def ratio(ours: float, theirs: dict[str, float] | None, key: str = "rate") -> str:
            return f"{ours / theirs[key]:.2f}" if theirs else why

        # 1-3: two sliders
        one = _run_child("pair", {"steps": pair_steps, "realizations": 10, "mu_eff": False, "workers": 1}, core)
        c1 = c_pair(exe["twoslider_loop"], pair_steps, 10, core) if exe else None
        row("two sliders, one core, draws included", f"{one['rate']:.1f} M/s",
            f"{c1['rate']:.1f} M/s" if c1 else "-", ratio(one["rate"], c1), ">= 1.2")
        tilt = _run_child("pair", {"steps": pair_steps // 10, "realizations": 10, "mu_eff": True, "workers": 1},
                          core)
        row("two sliders with the tilt test (mu_eff)", f"{tilt['rate']:.1f} M/s", "-", "-", ">= 20 M/s")
        two = _run_child("pair", {"steps": pair_steps, "realizations": 20, "mu_eff": False, "workers": 2}, None)
        row("two sliders, 2 cores / 1 core", f"{two['rate']:.1f} M/s", "-", f"{two['rate'] / one['rate']:.2f}",
            ">= 1.9")

        # 4-7: lattices
        small = _run_child("network", {"kind": "triangular", "size": 32, "steps": 200 if q else 2000}, core)
        cs = c_lattice(exe["lattice"], 32, 200 if q else 2000, core) if exe else None
        row("triangular 32 x 32, kernel", f"{small['rate']:.2f} M/s", f"{cs['rate']:.2f} M/s" if cs else "-",
            ratio(small["rate"], cs), ">= 1.2",
            f"{small['slips']:.3g} slips" + (f" (C {cs['slips']:.3g})" if cs else ""))
        large = _run_child("network", {"kind": "triangular", "size": big, "steps": big_steps}, core)
        cl = c_lattice(exe["lattice"], big, big_steps, core) if exe else None
        label = f"triangular {big} x {big}"
        row(f"{label}, setup included", f"{large['rate_with_setup']:.2f} M/s",
            f"{cl['rate_with_setup']:.2f} M/s" if cl else "-",
            ratio(large["rate_with_setup"], cl, "rate_with_setup"),
            ">= 1.0", f"{large['slips']:.3g} slips" + (f" (C {cl['slips']:.3g})" if cl else ""))
        row(f"{label}, kernel alone", f"{large['rate']:.2f} M/s", f"{cl['rate']:.2f} M/s" if cl else "-",
            ratio(large["rate"], cl), ">= 1.2")
        row(f"{label}, setup", f"{large['setup']:.2f} s", f"{cl['setup']:.2f} s" if cl else "-", "-", "<= 0.5 s")
        row(f"{label}, peak resident memory", f"{large['peak_GB']:.2f} GB", "-", "-", "<= 0.6 GB")
        row(f"kernel rate at {big * big:.0e} nodes / at 1e3", f"{large['rate'] / small['rate']:.2f}", "-", "-",
            ">= 0.5")
        # Every node of an irregular network is driven: a step makes about 20 N slips (a lattice's, about
        # 0.2 N at the boundary), so 2 steps are plenty of work.
        irr = _run_child("network", {"kind": "irregular", "size": big, "steps": 2}, core)
        row(f"irregular (Delaunay) {big * big:.0e} nodes, kernel", f"{irr['rate']:.2f} M/s", "-",
            f"{large['rate'] / irr['rate']:.2f} x slower than triangular", "<= 1.5 x",
            f"{irr['slips']:.3g} slips in 2 steps, setup {irr['setup']:.2f} s, peak {irr['peak_GB']:.2f} GB")

    if args.paper:
        out = Path(tempfile.mkdtemp(prefix="slidernet-paper-"))
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        t0 = time.perf_counter()
        subprocess.run(["slidernet", "paper", "--out", str(out), "--no-progress"], check=True,
                       capture_output=True)
        wall = time.perf_counter() - t0
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        shutil.rmtree(out, ignore_errors=True)
        row("slidernet paper, full preset, 2 cores", f"{wall:.0f} s",
            "-", "-", "<= 90 s, <= 1.2 GB",
            f"peak {peak / 1024**2:.2f} GB (largest process)" if peak > before else "")

    print("\n| workload | slidernet | C yardstick | ratio | target | note |\n|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['workload']} | {r['slidernet']} | {r['C']} | {r['ratio']} | {r['target']} | {r['note']} |")
    if args.csv:
        with args.csv.open("w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
