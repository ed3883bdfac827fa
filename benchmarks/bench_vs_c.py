"""slidernet against two plain-C yardsticks in the same run: one Markdown table of same-run ratios.

    python benchmarks/bench_vs_c.py [--anchors DIR] [--quick] [--repeat 3] [--sizes L ...] [--core 1]
                                    [--csv PATH] [--no-delaunay] [--paper]
                                    [--rows {pair,workers,lattices,irregular} ...]
                                    [--irregular-nodes N ...]

The yardsticks are plain C programs that solve the same model the
straightforward way, on one core: ``twoslider_loop.c`` (the paper's two
sliders), ``lattice.c`` (a triangular lattice with free boundaries) and
``network.c`` (any 2D network read from a file). They
are not part of slidernet and do not ship with it: point ``--anchors`` (or
the environment variable ``SLIDERNET_ANCHORS``) at the folder that holds
them. The script builds them with ``cc -O3 -march=native`` in a temporary
folder. Without the folder or without a C compiler it says so in one line
and prints slidernet's figures alone, the ratio column reading
"skipped (no anchors)" or "skipped (no C compiler)".

Absolute rates move by tens of percent from one machine or minute to the
next; a ratio measured in the same minute on the same core does not. Every
slidernet workload therefore runs in a fresh Python process pinned to one
core (``--core``, ``os.sched_setaffinity``), and the C run of the same
workload follows it on the same core. Each process's peak resident memory
and CPU time come from ``os.wait4``, so they are that process's own. In
every slidernet process the compiled kernels are first loaded (numba's disk
cache) on a tiny scene, untimed.

The rows (rates in millions of rearrangements, i.e. slips, per second):

1. two sliders at the paper's setting: mu_d 0.5, Gaussian thresholds
   (0.6, 0.01), Ntilde 1e-7, sigma_theta 1e-6 (``gaussian_steps``),
   10 realizations x 100 000 steps, the drawing of the thresholds and of
   theta included, against ``twoslider_loop 0.5 0.6 0.01 1e-7 1e-6 100000
   10 1 0`` (10 realizations, seed 1; its last line gives the mean n and
   the mean mu_max at the last step);
2. the same with the virtual tilt test before every rearrangement
   (observable ``mu_eff``): slidernet alone, no C counterpart;
3. 20 realizations of row 1's scene with 10 times its steps (1e6; about
   9 s on one worker) through ``slidernet.run`` with 2 worker processes
   (``execution.workers = 2``) against 1: the speed-up, with the same total
   n checked (not pinned: it uses two cores);
4. triangular 32 x 32, Ntilde = sigma_theta = 1e-7, 2000 steps, kernel
   alone, against ``lattice 32 32 1e-7 1e-7 2000 1``;
5. triangular L x L for each L of ``--sizes`` (default 1000), 20 steps: the
   rate with the setup included and of the kernel alone, the setup seconds
   (slidernet: building the scene, then the realization: theta(t), the
   thresholds, forces and heaps) and the peak resident memory of the
   process, against ``lattice L L 1e-7 1e-7 20 1``;
6. the rate at the largest L over the rate at 32 x 32 (about 1e3 nodes),
   slidernet's and the C yardstick's;
7. slidernet alone: an irregular (Delaunay) network with as many nodes as
   the largest lattice, 2 steps (every node is driven: about 20 N slips a
   step), its kernel rate against the triangular one of row 5, its setup and
   peak memory (``--no-delaunay`` leaves it out: about 45 s at 1e6);
8. irregular networks of 1e4 nodes (400 steps) and 1e6 nodes (6 steps),
   Ntilde = sigma_theta = 1e-7, network seed 0, kernel alone, against
   ``network FILE 1e-7 1e-7 steps 1`` on the same network: the child writes
   slidernet's own network (positions, springs) to FILE in network.c's text
   format before it runs (``--no-irregular-c`` leaves these rows out;
   network.c is optional in ``--anchors``; ``--irregular-nodes 1000000``
   runs the largest alone);
9. the irregular rate at 1e6 nodes over the rate at 1e4, slidernet's and
   network.c's;
10. with ``--paper``: ``slidernet paper`` (full preset, all cores), wall time
   and the peak resident memory of its largest process (about 2 minutes).

The target column holds the performance issue's targets (for a ratio,
slidernet / C). Two columns show that both sides simulate the same thing: the slips (total
rearrangements) and the mean mu (the mean of the final thresholds mu_s over
the nodes; for two sliders, the mean over realizations of mu_max at the last
step). The random streams differ, so the counts agree statistically, not to
the bit: with 20 steps of a large lattice the work depends on the 20 draws
of theta and differs by tens of percent between seeds.

Rows 1 to 5 run ``--repeat`` times (default 3), slidernet and C alternating,
and report the median of each figure with the ratio of each run: one run of
a second or two moves by several per cent on a shared machine.

``--quick`` is a smoke run (10 000 steps for two sliders, 200 steps at
32 x 32, ``--sizes 100``): its ratios are noisy. ``--csv PATH`` writes one
line per row, with the numbers unformatted. ``--rows`` runs some groups of
rows alone: ``pair`` (1 and 2), ``workers`` (3), ``lattices`` (4 to 7),
``irregular`` (8 and 9).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

# The paper's two sliders; the lattice yardstick has mu_d = 0.5 and thresholds N(0.6, 0.01) built in.
PAIR = {"mu_d": 0.5, "mean": 0.6, "std": 0.01, "Ntilde": 1e-7, "sigma_theta": 1e-6}
LATTICE = {"Ntilde": 1e-7, "sigma_theta": 1e-7}
SMALL = 32  # the ~1e3-node lattice of rows 4 and 6
# Rows 8 and 9: (nodes, thermal steps) of the irregular networks against network.c; about 8e7 and
# 7e7 slips (every node is driven: about 20 N slips a step at sigma_theta / Ntilde = 1).
IRREGULAR = ((10_000, 400), (1_000_000, 6))
IRREGULAR_Q = ((1_000, 100), (10_000, 10))
# --rows: groups of rows that can run alone.
ROW_GROUPS = ("pair", "workers", "lattices", "irregular")


# ---------------------------------------------------------------------------
# slidernet's workloads; each runs in a child process (``--child NAME JSON``) and returns a dict


def _friction() -> dict[str, Any]:
    return {"mu_d": PAIR["mu_d"], "static": {"name": "gaussian", "mean": PAIR["mean"], "std": PAIR["std"]}}


def _pair_config(steps: int, realizations: int = 1, tilt: bool = False) -> dict[str, Any]:
    return {
        "seed": 1, "steps": steps, "realizations": realizations,
        "observables": ["n", "mu_max", "x_G"] + (["mu_eff"] if tilt else []),
        "network": {"kind": "two_slider", "Ntilde": PAIR["Ntilde"]},
        "friction": _friction(),
        "driver": {"name": "gaussian_steps", "sigma_theta": PAIR["sigma_theta"]},
    }


def _lattice_config(size: int, steps: int, kind: str = "triangular") -> dict[str, Any]:
    network = {"kind": "triangular", "shape": [size, size]} if kind == "triangular" else \
        {"kind": "irregular", "n": size * size}
    return {
        "steps": steps, "record": "log",
        "network": {**network, "Ntilde": LATTICE["Ntilde"]},
        "friction": _friction(),
        "driver": {"name": "gaussian_steps", "sigma_theta": LATTICE["sigma_theta"]},
    }


def _irregular_config(n: int, steps: int) -> dict[str, Any]:
    return {
        "seed": 1, "realizations": 1, "steps": steps, "record": [0, steps],
        "network": {"kind": "irregular", "n": n, "seed": 0, "Ntilde": LATTICE["Ntilde"]},
        "friction": _friction(),
        "driver": {"name": "gaussian_steps", "sigma_theta": LATTICE["sigma_theta"]},
    }


def _rss_GB() -> float:
    """Resident memory of this process now (Linux), in GB; nan elsewhere."""
    try:
        match = re.search(r"^VmRSS:\s+(\d+) kB", Path("/proc/self/status").read_text(), re.MULTILINE)
    except OSError:
        return math.nan
    return int(match.group(1)) * 1024 / 1e9 if match else math.nan


def child_pair(steps: int, realizations: int, tilt: bool) -> dict[str, Any]:
    """Rows 1 and 2: ``realizations`` realizations one after the other, draws included, scene not."""
    import numpy as np

    from slidernet.config import load_config
    from slidernet.solver import Realization, Scene

    Realization(Scene.from_config(load_config(_pair_config(10, tilt=tilt))), np.random.SeedSequence(0)).advance()
    scene = Scene.from_config(load_config(_pair_config(steps, realizations, tilt)))
    if int(scene.out_steps[-1]) != steps:
        raise RuntimeError(f"the last record is at step {scene.out_steps[-1]}, not {steps}")
    seeds = np.random.SeedSequence(1).spawn(realizations)  # as slidernet.run with seed = 1
    n = 0
    mu_max = 0.0
    t0 = time.perf_counter()
    for ss in seeds:
        real = Realization(scene, ss).advance()
        n += real.n
        mu_max += float(real.out["mu_max"][-1])
    seconds = time.perf_counter() - t0
    return {"slips": n, "seconds": seconds, "rate": n / seconds, "mean_mu": mu_max / realizations}


def child_workers(steps: int, realizations: int, workers: int) -> dict[str, Any]:
    """Row 3: ``slidernet.run`` on 1 worker, then on ``workers``; wall and CPU seconds of each."""
    import slidernet

    slidernet.run(_pair_config(10, 2), workers=1)  # load the kernels here; forked workers inherit them
    out: dict[str, Any] = {}
    for w in (1, workers):
        cfg = _pair_config(steps, realizations)
        cfg["execution"] = {"workers": w}
        c0, t0 = _cpu_seconds(), time.perf_counter()
        ds = slidernet.run(cfg)
        wall, cpu = time.perf_counter() - t0, _cpu_seconds() - c0
        n = int(ds["n"].isel(t=-1).sum())
        out[str(w)] = {"slips": n, "seconds": wall, "rate": n / wall, "cpu_share": cpu / (wall * w)}
    return out


def _cpu_seconds() -> float:
    """CPU seconds of this process and of its children that have ended."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def child_lattice(size: int, steps: int, kind: str = "triangular") -> dict[str, Any]:
    """Rows 4 and 5: one realization of a size x size lattice (or size^2 nodes); setup and kernel timed apart."""
    import numpy as np

    from slidernet.config import load_config
    from slidernet.solver import Realization, Scene

    Realization(Scene.from_config(load_config(_lattice_config(4, 2, kind))), np.random.SeedSequence(0)).advance()
    cfg = load_config(_lattice_config(size, steps, kind))
    rss0 = _rss_GB()
    t0 = time.perf_counter()
    scene = Scene.from_config(cfg)
    t1 = time.perf_counter()
    real = Realization(scene, np.random.SeedSequence(1))
    t2 = time.perf_counter()
    rss1 = _rss_GB()
    real.advance()
    t3 = time.perf_counter()
    mu = real.thresholds
    return {"slips": real.n, "scene_s": t1 - t0, "realization_s": t2 - t1, "setup": t2 - t0,
            "kernel_s": t3 - t2, "rate": real.n / (t3 - t2), "rate_with_setup": real.n / (t3 - t0),
            "mean_mu": float(mu.mean()), "mu_max": float(mu.max()),
            "rss_before_setup_GB": rss0, "rss_after_setup_GB": rss1}


def child_irregular(n: int, steps: int, file: str) -> dict[str, Any]:
    """Rows 8 and 9: one realization of an irregular network of n nodes, also written to ``file`` for network.c.

    The file (untimed, before the realization; written by the first repeat)
    holds the network's node positions (l0) and springs in network.c's text
    format, so that both programs solve the same network.
    """
    import numpy as np

    from slidernet.config import load_config
    from slidernet.solver import Realization, Scene

    Realization(Scene.from_config(load_config(_irregular_config(16, 2))), np.random.SeedSequence(0)).advance()
    t0 = time.perf_counter()
    scene = Scene.from_config(load_config(_irregular_config(n, steps)))
    t1 = time.perf_counter()
    net = scene.network
    # The same network at every repeat (network seed 0): written once, read by every C run.
    if not os.path.exists(file):
        with open(file, "w") as fh:
            fh.write(f"{net.n_nodes} {net.n_edges}\n")
            np.savetxt(fh, net.positions, fmt="%.17g")
            np.savetxt(fh, net.edges, fmt="%d")
    t2 = time.perf_counter()
    real = Realization(scene, np.random.SeedSequence(1))
    t3 = time.perf_counter()
    real.advance()
    t4 = time.perf_counter()
    mu = real.thresholds
    return {"slips": real.n, "setup": (t1 - t0) + (t3 - t2), "kernel_s": t4 - t3, "rate": real.n / (t4 - t3),
            "mean_mu": float(mu.mean()), "mu_max": float(mu.max())}


CHILDREN = {"pair": child_pair, "workers": child_workers, "lattice": child_lattice, "irregular": child_irregular}


# ---------------------------------------------------------------------------
# processes


def _spawn(cmd: list[str], core: int | None) -> tuple[str, dict[str, float]]:
    """Run ``cmd`` (pinned to ``core`` unless None); its stdout, and its wall s, CPU s and peak RSS (GB)."""
    # A child inherits the CPU affinity of this process: pin this one while it starts the child.
    allowed = os.sched_getaffinity(0) if core is not None else None
    with tempfile.TemporaryFile("w+") as err:
        if core is not None:
            os.sched_setaffinity(0, {core})
        try:
            t0 = time.perf_counter()
            proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=err, text=True)
        finally:
            if allowed is not None:
                os.sched_setaffinity(0, allowed)
        assert proc.stdout is not None
        out = proc.stdout.read()
        _, status, usage = os.wait4(proc.pid, 0)  # this child's own rusage, not the largest child's so far
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        proc.stdout.close()
        if proc.returncode != 0:
            err.seek(0)
            raise RuntimeError(f"{' '.join(cmd)} exited with {proc.returncode}:\n{err.read()[-3000:]}")
    # ru_maxrss is in kB on Linux
    return out, {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "peak_GB": usage.ru_maxrss * 1024 / 1e9}


def run_child(name: str, params: dict[str, Any], core: int | None) -> dict[str, Any]:
    """A slidernet workload in a fresh Python process; adds its peak RSS (GB) and CPU share."""
    out, usage = _spawn([sys.executable, str(Path(__file__).resolve()), "--child", name, json.dumps(params)],
                        core)
    res = json.loads(out.strip().splitlines()[-1])
    res["peak_GB"] = usage["peak_GB"]
    res["cpu_share"] = usage["cpu"] / usage["wall"]
    return res


def build_anchors(folder: Path | None, tmp: Path) -> tuple[dict[str, Path], str]:
    """Compile the C yardsticks into ``tmp``; returns their paths, or {} and why they are skipped."""
    if folder is None:
        return {}, "skipped (no anchors)"
    sources = {name: folder / f"{name}.c" for name in ("twoslider_loop", "lattice")}
    missing = [str(p) for p in sources.values() if not p.is_file()]
    if missing:
        return {}, f"skipped (no anchors: {', '.join(missing)} not found)"
    cc = next((c for c in ("cc", "gcc", "clang") if shutil.which(c)), None)
    if cc is None:
        return {}, "skipped (no C compiler)"
    # network.c is newer than the other two: a folder without it still gives rows 1 to 7.
    if (folder / "network.c").is_file():
        sources["network"] = folder / "network.c"
    built = {}
    for name, src in sources.items():
        cmd = [cc, "-O3", "-march=native", "-o", str(tmp / name), str(src), "-lm"]
        proc = subprocess.run(cmd, check=False, capture_output=True, text=True)
        if proc.returncode != 0:
            return {}, f"skipped (C build failed: {' '.join(cmd)}: {proc.stderr.strip()[:200]})"
        built[name] = tmp / name
    return built, ""


def c_pair(exe: Path, steps: int, realizations: int, core: int | None) -> dict[str, Any]:
    p = PAIR
    out, usage = _spawn([str(exe), str(p["mu_d"]), str(p["mean"]), str(p["std"]), str(p["Ntilde"]),
                         str(p["sigma_theta"]), str(steps), str(realizations), "1", "0"], core)
    # one line per checkpoint: q mean_n mean_mu_max mean_xG^2 (unused) (unused) mean_n^2
    q, mean_n, mean_mu_max = out.strip().splitlines()[-1].split()[:3]
    if int(q) != steps:
        raise RuntimeError(f"unexpected last line of twoslider_loop: {out.strip().splitlines()[-1]!r}")
    slips = round(float(mean_n) * realizations)
    return {"slips": slips, "seconds": usage["wall"], "rate": slips / usage["wall"],
            "mean_mu": float(mean_mu_max), "peak_GB": usage["peak_GB"], "cpu_share": usage["cpu"] / usage["wall"]}


def c_lattice(exe: Path, size: int, steps: int, core: int | None) -> dict[str, Any]:
    out, usage = _spawn([str(exe), str(size), str(size), str(LATTICE["Ntilde"]), str(LATTICE["sigma_theta"]),
                         str(steps), "1"], core)
    num = r"([0-9.eE+-]+|nan|inf)"
    m = re.search(rf"slips {num} setup {num} s total {num} s rate {num} slips/s \(run only {num}\) "
                  rf"mean_mu {num} mu_max {num}", out)
    if m is None:
        raise RuntimeError(f"unexpected output of the lattice yardstick: {out!r}")
    slips, setup, total, _rate, _run_only, mean_mu, mu_max = (float(x) for x in m.groups())
    # Rates from the seconds it prints (3 decimals), not from its 3-digit rates.
    return {"slips": int(slips), "setup": setup, "kernel_s": total - setup, "rate": slips / (total - setup),
            "rate_with_setup": slips / total, "mean_mu": mean_mu, "mu_max": mu_max,
            "peak_GB": usage["peak_GB"], "cpu_share": usage["cpu"] / usage["wall"]}


def c_network(exe: Path, file: str, steps: int, core: int | None) -> dict[str, Any]:
    out, usage = _spawn([str(exe), file, str(LATTICE["Ntilde"]), str(LATTICE["sigma_theta"]), str(steps), "1"],
                        core)
    num = r"([0-9.eE+-]+|nan|inf)"
    m = re.search(rf"slips {num} read {num} s setup {num} s total {num} s rate {num} slips/s \(run only {num}\) "
                  rf"mean_mu {num} mu_max {num}", out)
    if m is None:
        raise RuntimeError(f"unexpected output of the network yardstick: {out!r}")
    slips, _read, setup, total, _rate, _run_only, mean_mu, mu_max = (float(x) for x in m.groups())
    return {"slips": int(slips), "setup": setup, "kernel_s": total - setup, "rate": slips / (total - setup),
            "mean_mu": mean_mu, "mu_max": mu_max, "peak_GB": usage["peak_GB"],
            "cpu_share": usage["cpu"] / usage["wall"]}


def _median(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Each numeric field's median over repeated runs (other fields from the first run)."""
    out = dict(runs[0])
    for key, value in runs[0].items():
        if isinstance(value, int | float) and not isinstance(value, bool):
            out[key] = statistics.median(r[key] for r in runs)
    return out


def repeated(n: int, ours: Callable[[], dict[str, Any]], theirs: Callable[[], dict[str, Any]] | None
             ) -> tuple[dict[str, Any], dict[str, Any] | None, list[float], list[float]]:
    """Run slidernet's workload and then C's ``n`` times, alternating, so both see the same minutes.

    Returns the median of each side's figures, and each side's rate run by run.
    """
    a, b = [], []
    for _ in range(n):
        a.append(ours())
        if theirs is not None:
            b.append(theirs())
    return _median(a), (_median(b) if b else None), [r["rate"] for r in a], [r["rate"] for r in b]


def _spread(ours: list[float], theirs: list[float]) -> str:
    """' (median of n; runs: ...)' with the per-run ratios (or rates, in M/s, without C)."""
    if len(ours) < 2:
        return ""
    if theirs:
        runs = ", ".join(f"{x / y:.2f}" for x, y in zip(ours, theirs, strict=True))
        return f" (median of {len(ours)}; ratio by run {runs})"
    return f" (median of {len(ours)}; by run " + ", ".join(f"{x / 1e6:.1f}" for x in ours) + ")"


# ---------------------------------------------------------------------------
# the table


def _fmt(x: Any, unit: str) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if unit == "M/s":
        return f"{x / 1e6:.2f} M/s"
    if unit == "s":
        return f"{x:.2f} s"
    if unit == "GB":
        return f"{x:.2f} GB"
    if unit == "x":
        return f"{x:.2f} x"
    return f"{x:.3g}"


def _pair_str(a: Any, b: Any, fmt: str) -> str:
    if a is None:
        return ""
    return format(a, fmt) + " / " + (format(b, fmt) if b is not None else "-")


class Table:
    COLUMNS = ("workload", "slidernet", "C", "slidernet / C", "target", "slips: slidernet / C",
               "mean mu: slidernet / C")

    def __init__(self, why_no_c: str) -> None:
        self.why = why_no_c
        self.rows: list[dict[str, Any]] = []

    def add(self, workload: str, unit: str, ours: float, theirs: float | None = None, *, target: str = "",
            ratio: float | str | None = None, c_applies: bool = True, slips: tuple[Any, Any] = (None, None),
            mu: tuple[Any, Any] = (None, None), ours_text: str | None = None) -> None:
        """One row; the ratio is ours / theirs unless given; ``c_applies`` False: no C counterpart."""
        if ratio is None and c_applies:
            ratio = ours / theirs if theirs is not None else self.why
        elif ratio is None:
            ratio = "no C counterpart"
        row = {"workload": workload, "unit": unit, "slidernet": ours, "C": theirs, "ratio": ratio,
               "target": target, "slips_slidernet": slips[0], "slips_C": slips[1], "mean_mu_slidernet": mu[0],
               "mean_mu_C": mu[1], "_ours_text": ours_text}
        self.rows.append(row)
        print(f"  {workload}: " + " | ".join(self._cells(row)[1:]), flush=True)

    def _cells(self, r: dict[str, Any]) -> list[str]:
        ratio = r["ratio"]
        ratio = f"{ratio:.2f}" if isinstance(ratio, float) else ratio
        c = _fmt(r["C"], r["unit"]) if r["C"] is not None else "-"
        return [r["workload"], r["_ours_text"] or _fmt(r["slidernet"], r["unit"]), c, ratio, r["target"],
                _pair_str(r["slips_slidernet"], r["slips_C"], ".4g"), _pair_str(r["mean_mu_slidernet"],
                                                                               r["mean_mu_C"], ".5f")]

    def markdown(self) -> str:
        lines = ["| " + " | ".join(self.COLUMNS) + " |", "|" + "---|" * len(self.COLUMNS)]
        lines += ["| " + " | ".join(self._cells(r)) + " |" for r in self.rows]
        return "\n".join(lines)

    def write_csv(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        fields = [k for k in self.rows[0] if not k.startswith("_")]
        with path.open("w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
            w.writeheader()
            w.writerows(self.rows)


# ---------------------------------------------------------------------------


def _pick_core(core: int) -> int | None:
    if not hasattr(os, "sched_setaffinity"):
        print("no os.sched_setaffinity here: the runs are not pinned to one core")
        return None
    allowed = sorted(os.sched_getaffinity(0))
    if core in allowed:
        return core
    print(f"core {core} is not available to this process (allowed: {allowed}); using core {allowed[-1]}")
    return allowed[-1]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--anchors", type=Path, default=os.environ.get("SLIDERNET_ANCHORS") or None,
                    help="folder with twoslider_loop.c, lattice.c and network.c (default: $SLIDERNET_ANCHORS)")
    ap.add_argument("--quick", action="store_true", help="short runs, a smoke test: noisy ratios")
    ap.add_argument("--sizes", type=int, nargs="+", default=None,
                    help="L of the large L x L lattices (default 1000; --quick: 100)")
    ap.add_argument("--core", type=int, default=1, help="the core of the one-core runs (default 1)")
    ap.add_argument("--csv", type=Path, default=None, help="also write the rows to this CSV file")
    ap.add_argument("--no-delaunay", action="store_true",
                    help="leave out the irregular (Delaunay) network as large as the largest lattice")
    ap.add_argument("--no-irregular-c", action="store_true",
                    help="leave out rows 8 and 9, the irregular networks against network.c (minutes at 1e6 nodes)")
    ap.add_argument("--irregular-nodes", type=int, nargs="+", choices=[n for n, _ in IRREGULAR], default=None,
                    help="run rows 8 and 9 at these sizes only (default: all of them; ignored with --quick)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="runs of rows 1 to 5, alternating slidernet and C, reported as medians (default 3)")
    ap.add_argument("--paper", action="store_true",
                    help="also time `slidernet paper` (full preset, all cores; minutes)")
    ap.add_argument("--rows", nargs="+", choices=ROW_GROUPS, default=list(ROW_GROUPS),
                    help="the groups of rows to run: pair (rows 1 and 2), workers (3), lattices (4 to 7), "
                         "irregular (8 and 9); default all")
    ap.add_argument("--child", nargs=2, metavar=("NAME", "JSON"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        name, params = args.child
        print(json.dumps(CHILDREN[name](**json.loads(params))), flush=True)
        return 0

    q = args.quick
    rows = set(args.rows)
    pair_steps, small_steps, big_steps = (10_000, 200, 20) if q else (100_000, 2000, 20)
    # Row 3 runs 10 times row 1's steps: at 1e5 steps its 20 realizations took 0.9 s on one
    # worker, where the pool's fixed cost (about 40 ms) and the last realization's tail
    # (one of 20) set the ratio more than the parallel work does.
    ens_steps = 10 * pair_steps
    sizes = sorted(args.sizes or ([100] if q else [1000]))
    realizations, ens_realizations = 10, 20
    core = _pick_core(args.core)
    t_start = time.perf_counter()
    print(f"slidernet vs C, one core = core {core}; load average {os.getloadavg()[0]:.2f}", flush=True)

    with tempfile.TemporaryDirectory(prefix="slidernet-vs-c-") as tmp:
        exe, why = build_anchors(args.anchors, Path(tmp))
        if why == "skipped (no anchors)":
            print("C yardsticks: skipped (no anchors): pass --anchors DIR or set SLIDERNET_ANCHORS", flush=True)
        elif why:
            print(f"C yardsticks: {why}", flush=True)
        table = Table(why)
        shares: list[float] = []

        n = max(1, args.repeat)

        if "pair" in rows:
            # 1. two sliders, one core
            ours, theirs, r_ours, r_theirs = repeated(
                n, lambda: run_child("pair", {"steps": pair_steps, "realizations": realizations, "tilt": False},
                                     core),
                (lambda: c_pair(exe["twoslider_loop"], pair_steps, realizations, core)) if exe else None)
            shares += [ours["cpu_share"]] + ([theirs["cpu_share"]] if theirs else [])
            table.add(f"two sliders, {realizations} x {pair_steps:,} steps, one core", "M/s", ours["rate"],
                      theirs and theirs["rate"], target=">= 1.2",
                      slips=(ours["slips"], theirs and theirs["slips"]),
                      mu=(ours["mean_mu"], theirs and theirs["mean_mu"]),
                      ours_text=f"{ours['rate'] / 1e6:.2f} M/s{_spread(r_ours, r_theirs)}")

            # 2. with the tilt test
            tilt, _, r_tilt, _ = repeated(
                n, lambda: run_child("pair", {"steps": pair_steps, "realizations": realizations, "tilt": True},
                                     core),
                None)
            shares.append(tilt["cpu_share"])
            table.add("two sliders + tilt test (mu_eff), one core", "M/s", tilt["rate"], c_applies=False,
                      target=">= 20 M/s", slips=(tilt["slips"], None),
                      mu=(tilt["mean_mu"], None), ours_text=f"{tilt['rate'] / 1e6:.2f} M/s{_spread(r_tilt, [])}")

        if "workers" in rows:
            # 3. 2 workers against 1 (slidernet.run, execution.workers); a speed-up per run, its median
            runs = []
            for _ in range(n):
                ens = run_child("workers", {"steps": ens_steps, "realizations": ens_realizations, "workers": 2},
                                None)
                one, two = ens["1"], ens["2"]
                if one["slips"] != two["slips"]:
                    raise AssertionError(f"slidernet.run: {one['slips']} slips on 1 worker, {two['slips']} on 2")
                runs.append({"rate": two["rate"] / one["rate"], "one": one["rate"], "two": two["rate"],
                             "share_one": one["cpu_share"], "share_two": two["cpu_share"], "slips": two["slips"]})
            ens = _median(runs)
            by_run = ", ".join(f"{r['rate']:.2f}" for r in runs)
            table.add(f"two sliders, {ens_realizations} x {ens_steps:,} steps, slidernet.run on 2 workers / 1",
                      "x", ens["rate"], ratio="no C counterpart", target=">= 1.9",
                      ours_text=f"{ens['rate']:.2f} x ({ens['two'] / 1e6:.1f} / {ens['one'] / 1e6:.1f} M/s; "
                                f"CPU share {ens['share_two']:.2f} / {ens['share_one']:.2f}"
                                + (f"; median of {n}, by run {by_run})" if n > 1 else ")"),
                      slips=(ens["slips"], None))

        if "lattices" in rows:
            # 4. the small lattice
            small, c_small, r_small, r_c_small = repeated(
                n, lambda: run_child("lattice", {"size": SMALL, "steps": small_steps}, core),
                (lambda: c_lattice(exe["lattice"], SMALL, small_steps, core)) if exe else None)
            shares += [small["cpu_share"]] + ([c_small["cpu_share"]] if c_small else [])
            table.add(f"triangular {SMALL} x {SMALL}, {small_steps} steps, kernel alone", "M/s", small["rate"],
                      c_small and c_small["rate"], target=">= 1.2",
                      slips=(small["slips"], c_small and c_small["slips"]),
                      mu=(small["mean_mu"], c_small and c_small["mean_mu"]),
                      ours_text=f"{small['rate'] / 1e6:.2f} M/s{_spread(r_small, r_c_small)}")

            # 5. the large lattices
            large: dict[int, tuple[dict[str, Any], dict[str, Any] | None]] = {}
            for L in sizes:
                big, c_big, _, _ = repeated(
                    n, lambda L=L: run_child("lattice", {"size": L, "steps": big_steps}, core),
                    (lambda L=L: c_lattice(exe["lattice"], L, big_steps, core)) if exe else None)
                shares += [big["cpu_share"]] + ([c_big["cpu_share"]] if c_big else [])
                large[L] = (big, c_big)
                label = f"triangular {L} x {L}, {big_steps} steps"
                check = {"slips": (big["slips"], c_big and c_big["slips"]),
                         "mu": (big["mean_mu"], c_big and c_big["mean_mu"])}
                table.add(f"{label}, setup included", "M/s", big["rate_with_setup"],
                          c_big and c_big["rate_with_setup"], target=">= 1.0" if L == 1000 else "", **check)
                table.add(f"{label}, kernel alone", "M/s", big["rate"], c_big and c_big["rate"],
                          target=">= 1.2" if L == 1000 else "")
                table.add(f"{label}, setup", "s", big["setup"], c_big and c_big["setup"],
                          target="<= 0.5 s" if L == 1000 else "",
                          ours_text=f"{big['setup']:.2f} s (scene {big['scene_s']:.2f} + realization "
                                    f"{big['realization_s']:.2f})")
                table.add(f"{label}, peak resident memory", "GB", big["peak_GB"], c_big and c_big["peak_GB"],
                          target="<= 0.6 GB" if L == 1000 else "",
                          ours_text=f"{big['peak_GB']:.2f} GB ({big['rss_before_setup_GB']:.2f} before setup)")

            # 6. largest lattice against the small one
            L = sizes[-1]
            big, c_big = large[L]
            for key, what in (("rate", "kernel alone"), ("rate_with_setup", "setup included")):
                ours_r = big[key] / small[key]
                theirs_r = c_big[key] / c_small[key] if c_big and c_small else None
                table.add(f"rate at {L} x {L} / at {SMALL} x {SMALL}, {what}", "x", ours_r, theirs_r,
                          target=">= 0.5" if key == "rate" and L == 1000 else "")

            # 7. an irregular network of the largest size (every node driven: ~20 N slips a step)
            if not args.no_delaunay:
                irr = run_child("lattice", {"size": L, "steps": 2, "kind": "irregular"}, core)
                shares.append(irr["cpu_share"])
                table.add(f"irregular (Delaunay) {L * L:,} nodes, 2 steps, kernel alone", "M/s", irr["rate"],
                          ratio="no C counterpart", target="<= 1.5 x" if L == 1000 else "",
                          ours_text=f"{irr['rate'] / 1e6:.2f} M/s ({big['rate'] / irr['rate']:.2f} x slower than "
                                    f"triangular; setup {irr['setup']:.2f} s, peak {irr['peak_GB']:.2f} GB)",
                          slips=(irr["slips"], None), mu=(irr["mean_mu"], None))

        # 8. irregular networks against network.c, the same network (written by slidernet), kernel alone
        if "irregular" in rows and not args.no_irregular_c:
            irr_rates: dict[int, tuple[float, float | None]] = {}
            sizes_c = IRREGULAR_Q if q else [(m, s) for m, s in IRREGULAR
                                             if args.irregular_nodes is None or m in args.irregular_nodes]
            for nodes, steps in sizes_c:
                file = str(Path(tmp) / f"irregular_{nodes}.txt")
                ours_i, theirs_i, r_i, r_c_i = repeated(
                    n, lambda nodes=nodes, steps=steps, file=file: run_child(
                        "irregular", {"n": nodes, "steps": steps, "file": file}, core),
                    (lambda steps=steps, file=file: c_network(exe["network"], file, steps, core))
                    if "network" in exe else None)
                shares += [ours_i["cpu_share"]] + ([theirs_i["cpu_share"]] if theirs_i else [])
                irr_rates[nodes] = (ours_i["rate"], theirs_i and theirs_i["rate"])
                table.add(f"irregular {nodes:,} nodes, {steps} steps, kernel alone (vs network.c)", "M/s",
                          ours_i["rate"], theirs_i and theirs_i["rate"], target=">= 2.5",
                          ratio=None if "network" in exe or not exe else "skipped (no network.c)",
                          slips=(ours_i["slips"], theirs_i and theirs_i["slips"]),
                          mu=(ours_i["mean_mu"], theirs_i and theirs_i["mean_mu"]),
                          ours_text=f"{ours_i['rate'] / 1e6:.2f} M/s{_spread(r_i, r_c_i)}")
            # 9. the rate's fall with size
            by_size = sorted(irr_rates.items())
            (n_lo, (o_lo, c_lo)), (n_hi, (o_hi, c_hi)) = by_size[0], by_size[-1]
            if n_hi != n_lo:
                table.add(f"irregular: rate at {n_hi:,} / at {n_lo:,} nodes, kernel alone", "x", o_hi / o_lo,
                          c_hi / c_lo if c_hi and c_lo else None, target=">= 0.5")

    if args.paper:
        out = Path(tempfile.mkdtemp(prefix="slidernet-paper-"))
        try:
            _, usage = _spawn([sys.executable, "-m", "slidernet.cli", "paper", "--out", str(out), "--no-progress"],
                              None)
        finally:
            shutil.rmtree(out, ignore_errors=True)
        table.add("slidernet paper, full preset, all cores", "s", usage["wall"], ratio="no C counterpart",
                  target="<= 90 s, <= 1.2 GB",
                  ours_text=f"{usage['wall']:.0f} s, peak {usage['peak_GB']:.2f} GB (largest process)")

    wall = time.perf_counter() - t_start
    print()
    print(table.markdown())
    print()
    pinned = ""
    if shares:  # row 3 alone runs nothing pinned
        low = " (below 0.95: another process took the core, the rates are low for that reason)" \
            if min(shares) < 0.95 else ""
        pinned = f"; CPU share of the pinned runs {min(shares):.2f} - {max(shares):.2f}{low}"
    print(f"wall time {wall:.0f} s; load average {os.getloadavg()[0]:.2f}{pinned}")
    if args.csv is not None:
        table.write_csv(args.csv)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
