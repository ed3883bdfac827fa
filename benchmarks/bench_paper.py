"""Wall time and peak memory of reproducing the paper's figures (``slidernet.paper.reproduction.reproduce``).

    python benchmarks/bench_paper.py [--full] [--out DIR] [--csv PATH]

Runs ``reproduce(out, quick=True)`` (the ``--quick`` preset, under a minute)
and, with ``--full``, then ``reproduce(out, quick=False)`` (the full preset,
about ten minutes), each in a fresh Python process started by this script,
as ``slidernet paper --out DIR [--quick]`` would run. Numba's compiled
kernels come from its on-disk cache (run anything once after installing to
fill it), and loading them counts in the reproduction's time.

For each preset it prints and writes to ``--csv`` (one row per preset):

- ``import_s``: importing ``slidernet.paper.reproduction`` in the fresh process;
- ``reproduce_s``: the ``reproduce`` call (simulations, netCDF files, figures);
- ``process_s``: the whole process, interpreter start included (what
  ``time slidernet paper`` reports);
- ``cpu_s``: user + system CPU seconds of the process (all its threads), and
  ``cpu_share`` = cpu_s / process_s, the number of cores it kept busy on
  average. The simulations run on one core, but library threads (numpy's
  BLAS, for one) can push the share above 1, so a share below 1 says that
  other processes took the core, while a share above 1 does not rule it out;
- ``peak_rss_MB``: the process's peak resident memory (``ru_maxrss`` from
  ``wait4``), interpreter and imports included;
- the simulation and output seconds of each figure, from the ``summary.json``
  that ``reproduce`` writes.

Output goes to ``DIR/quick`` and ``DIR/full`` (default: a temporary folder,
removed at the end).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

# Run in the fresh process: times the import and the reproduce call, prints them as JSON on the last line.
CHILD = """
import json, sys, time
t0 = time.perf_counter()
from slidernet.paper.reproduction import reproduce
t1 = time.perf_counter()
reproduce(sys.argv[1], quick=sys.argv[2] == "quick", progress=False)
t2 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "reproduce_s": t2 - t1}))
"""

FIGURES = ["fig1_aging", "fig2_diffusion", "fig3_rearrangements", "fig4_mueff"]


def bench(preset: str, out: Path) -> dict[str, Any]:
    """Reproduce the figures with ``preset`` ("quick" or "full") in a fresh process; returns the row."""
    t0 = time.perf_counter()
    with subprocess.Popen([sys.executable, "-c", CHILD, str(out), preset], stdout=subprocess.PIPE,
                          text=True) as proc:
        stdout = proc.stdout.read() if proc.stdout is not None else ""  # until the child closes it
        # wait4 gives this child's own resource usage (RUSAGE_CHILDREN would be the maximum over all children).
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here: Popen must not wait for it again
    process_s = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"reproduce({out}, quick={preset == 'quick'}) exited with status {proc.returncode}")
    timings = json.loads(stdout.strip().splitlines()[-1])
    wall = json.loads((out / "summary.json").read_text())["wall_time_s"]
    cpu_s = usage.ru_utime + usage.ru_stime
    row = {"preset": preset, **timings, "process_s": process_s, "cpu_s": cpu_s, "cpu_share": cpu_s / process_s,
           "peak_rss_MB": usage.ru_maxrss / 1024}  # ru_maxrss is in kB on Linux
    for fig in FIGURES:
        row[f"{fig}_simulation_s"] = wall[fig]["simulation_s"]
        row[f"{fig}_output_s"] = wall[fig]["output_s"]
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="also time the full preset (about ten minutes)")
    ap.add_argument("--out", type=Path, default=None, help="keep the figures in DIR/quick and DIR/full")
    ap.add_argument("--csv", type=Path, default=None, help="write one row per preset to this file")
    args = ap.parse_args(argv)
    presets = ["quick", "full"] if args.full else ["quick"]
    with tempfile.TemporaryDirectory() as tmp:
        root = args.out if args.out is not None else Path(tmp)
        rows = []
        print(f"load average {os.getloadavg()[0]:.2f}")
        print("| preset | reproduce | import | whole process | CPU share | peak RSS |")
        print("|---|---|---|---|---|---|")
        for preset in presets:
            r = bench(preset, root / preset)
            rows.append(r)
            print(f"| {preset} | {r['reproduce_s']:.1f} s | {r['import_s']:.1f} s | {r['process_s']:.1f} s | "
                  f"{r['cpu_share']:.2f} | {r['peak_rss_MB']:.0f} MB |", flush=True)
        for r in rows:
            parts = ", ".join(f"{fig} {r[f'{fig}_simulation_s']:.1f} + {r[f'{fig}_output_s']:.1f} s"
                              for fig in FIGURES)
            print(f"{r['preset']}: simulation + output per figure: {parts}")
        print(f"load average {os.getloadavg()[0]:.2f}")
    if args.csv is not None:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
