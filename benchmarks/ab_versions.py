"""A/B of the kernels' speed: a git revision against the working tree, interleaved on one core.

    python benchmarks/ab_versions.py BASE [--rounds 3] [--core 1] [--networks "--sizes 32 316 --slips 3000000"]
                                          [--pair "--steps 30000 --workers 1"]
                                          [--vs-c "--rows irregular --irregular-nodes 1000000 --repeat 1
                                                   --anchors DIR"]

Checks BASE out into a temporary git worktree, then runs the working tree's
``bench_two_slider.py`` and ``bench_networks.py`` (they use only the public
API, so the same scripts drive both versions), and with ``--vs-c ARGS`` also
``bench_vs_c.py ARGS``, alternately against BASE's package and the working
tree's, each pinned to one core with ``taskset`` where it exists and with
its own numba cache (compiled by an untimed first run; ``bench_vs_c.py``'s
with ``--quick`` added). The order turns every round (A B, B A, A B, ...),
so that neither version always runs second. Alternating within one command
is what makes the comparison fair on a machine whose speed drifts: both
versions see the same minutes. It prints the load average at the start and
the end, each benchmark line of each round, then for each line the median
rate of A and of B, their ratio B/A and the range of the ratios of the
rounds (each round's B over the same round's A). A row of ``bench_vs_c.py``
with a ratio slidernet / C (the C yardstick runs beside each version, in the
same round) also gets that ratio's median and range for A and for B.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
# A rate: "45.7 M rearrangements/s" (bench_two_slider) or a table cell "4.59 M" (bench_networks).
_RATE = re.compile(r"([0-9.]+) M\b")
# bench_vs_c.py prints each row as it is measured ("  workload: 2.64 M/s | 1.35 M/s | ...") and again in its
# closing Markdown table: only the table's row is read.
_ECHO = re.compile(r"^\s+\S.*: .* \| ")


def run_pinned(script: str, args: str, package_root: Path, cache: Path, core: int | None) -> str:
    """stdout of ``benchmarks/SCRIPT ARGS`` run against the package at ``package_root``, with its own numba cache,
    pinned to ``core`` where ``taskset`` exists (``knockout.py`` uses it too)."""
    env = {**os.environ, "PYTHONPATH": str(package_root), "NUMBA_CACHE_DIR": str(cache)}
    cmd = [sys.executable, str(HERE / script), *shlex.split(args)]
    if core is not None and shutil.which("taskset"):
        cmd = ["taskset", "-c", str(core), *cmd]
    return subprocess.run(cmd, env=env, check=True, capture_output=True, text=True, cwd=package_root).stdout


@contextlib.contextmanager
def worktree(path: Path, rev: str) -> Iterator[Path]:
    """A detached git worktree of revision ``rev`` at ``path``, removed on exit (``knockout.py`` uses it too)."""
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(path), rev],
                   check=True, capture_output=True)
    try:
        yield path
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(path)],
                       check=False, capture_output=True)


def _rates(text: str) -> dict[str, list[float]]:
    """Rates (M/s) of each output line that has any, keyed by its section (the last line ending with ':')
    and its label (the text before its first number, or a table row's first cell)."""
    found: dict[str, list[float]] = {}
    section = ""
    for line in text.splitlines():
        if _ECHO.match(line):
            continue
        if line.rstrip().endswith(":"):
            section = line.strip().rstrip(":")
        rates = [float(x) for x in _RATE.findall(line)]
        if rates:
            cells = line.split("|")
            label = cells[1].strip() if line.startswith("|") else re.split(r"\s{2,}|[0-9]", line.strip())[0]
            found[f"{section[:20]} {label}".strip()] = rates
    return found


def _c_ratios(text: str) -> dict[str, float]:
    """slidernet / C of each row of bench_vs_c.py's table that has one (its fourth column, computed from the
    unrounded rates), keyed by the row's workload."""
    found = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.split("|")]
        if line.startswith("|") and len(cells) > 4 and re.fullmatch(r"[0-9.]+", cells[4]):
            found[cells[1]] = float(cells[4])
    return found


def _range(values: list[float]) -> str:
    return f"{min(values):.3f}-{max(values):.3f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("base", help="the git revision to compare against (A)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--core", type=int, default=1)
    ap.add_argument("--pair", default="--steps 30000 --workers 1", help="arguments of bench_two_slider.py")
    ap.add_argument("--networks", default="--sizes 32 316 --slips 3000000", help="arguments of bench_networks.py")
    ap.add_argument("--vs-c", default=None, help="arguments of bench_vs_c.py (default: it is not run)")
    args = ap.parse_args(argv)
    print(f"load average at the start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}", flush=True)
    with (tempfile.TemporaryDirectory(prefix="slidernet-ab-") as tmp,
          worktree(Path(tmp) / "base", args.base) as base):
        versions = {"A": base, "B": ROOT}
        runs = [("bench_two_slider.py", args.pair), ("bench_networks.py", args.networks)]
        if args.vs_c is not None:
            runs.append(("bench_vs_c.py", args.vs_c))
        # (script, label, version) -> the rates of that line, one list per round
        results: dict[tuple[str, str, str], list[list[float]]] = {}
        c_ratios: dict[tuple[str, str], list[float]] = {}  # (label, version) -> slidernet / C, one per round
        for name, root in versions.items():  # compile each version's kernels into its own cache, untimed
            for script, a in runs:
                warm = f"{a} --quick" if script == "bench_vs_c.py" else a
                run_pinned(script, warm, root, Path(tmp) / f"cache-{name}", args.core)
        for rnd in range(args.rounds):
            order = list(versions.items())[:: 1 if rnd % 2 == 0 else -1]
            for script, a in runs:
                for name, root in order:
                    out = run_pinned(script, a, root, Path(tmp) / f"cache-{name}", args.core)
                    print(f"--- round {rnd + 1}, {name}, {script}\n{out}", flush=True)
                    for label, rates in _rates(out).items():
                        results.setdefault((script, label, name), []).append(rates)
                    for label, ratio in _c_ratios(out).items():
                        c_ratios.setdefault((label, name), []).append(ratio)
        print(f"\nMedian rates over {args.rounds} rounds (M/s), A = {args.base}, B = working tree: "
              "A -> B (B/A; range of the rounds' B/A)")
        for (script, label, name), a_runs in sorted(results.items()):
            b_runs = results.get((script, label, "B"))
            if name != "A" or b_runs is None or len(b_runs) != len(a_runs):
                continue
            cells = []
            for col_a, col_b in zip(zip(*a_runs, strict=True), zip(*b_runs, strict=True), strict=True):
                x, y = statistics.median(col_a), statistics.median(col_b)
                paired = [v / u for u, v in zip(col_a, col_b, strict=True)]
                cells.append(f"{x:.3g} -> {y:.3g} ({y / x:.3f}; {_range(paired)})")
            print(f"{script:22s} {label[:40]:40s} {'  '.join(cells)}")
            if script == "bench_vs_c.py" and (label, "A") in c_ratios and (label, "B") in c_ratios:
                print(f"{'':22s} {'slidernet / C, median (range)':40s} " + "  ".join(
                    f"{v} {statistics.median(r):.2f} ({min(r):.2f}-{max(r):.2f})"
                    for v in "AB" for r in [c_ratios[(label, v)]]))
    print(f"load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
