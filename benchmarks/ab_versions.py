"""A/B of the kernels' speed: a git revision against the working tree, interleaved on one core.

    python benchmarks/ab_versions.py BASE [--rounds 3] [--core 1] [--networks "--sizes 32 316 --slips 3000000"]
                                          [--pair "--steps 30000 --workers 1"]

Checks BASE out into a temporary git worktree, then runs the working tree's
``bench_two_slider.py`` and ``bench_networks.py`` (they use only the public
API, so the same scripts drive both versions) alternately against BASE's
package and the working tree's (A B A B ...), each pinned to one core with
``taskset`` where it exists and with its own numba cache (compiled by an
untimed first run). Alternating within one command is what makes the
comparison fair on a machine whose speed drifts: both versions see the same
minutes. It prints each benchmark line of each round, then the median rate
of each line for A and B and their ratio B/A.
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
        if line.rstrip().endswith(":"):
            section = line.strip().rstrip(":")
        rates = [float(x) for x in _RATE.findall(line)]
        if rates:
            cells = line.split("|")
            label = cells[1].strip() if line.startswith("|") else re.split(r"\s{2,}|[0-9]", line.strip())[0]
            found[f"{section[:20]} {label}".strip()] = rates
    return found


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("base", help="the git revision to compare against (A)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--core", type=int, default=1)
    ap.add_argument("--pair", default="--steps 30000 --workers 1", help="arguments of bench_two_slider.py")
    ap.add_argument("--networks", default="--sizes 32 316 --slips 3000000", help="arguments of bench_networks.py")
    args = ap.parse_args(argv)
    with (tempfile.TemporaryDirectory(prefix="slidernet-ab-") as tmp,
          worktree(Path(tmp) / "base", args.base) as base):
        versions = {"A": base, "B": ROOT}
        runs = [("bench_two_slider.py", args.pair), ("bench_networks.py", args.networks)]
        results: dict[tuple[str, str, str], list[list[float]]] = {}
        for name, root in versions.items():  # compile each version's kernels into its own cache, untimed
            for script, a in runs:
                run_pinned(script, a, root, Path(tmp) / f"cache-{name}", args.core)
        for rnd in range(args.rounds):
            for script, a in runs:
                for name, root in versions.items():
                    out = run_pinned(script, a, root, Path(tmp) / f"cache-{name}", args.core)
                    print(f"--- round {rnd + 1}, {name}, {script}\n{out}", flush=True)
                    for label, rates in _rates(out).items():
                        results.setdefault((script, label, name), []).append(rates)
        print(f"\nMedian rates over {args.rounds} rounds (M/s), A = {args.base}, B = working tree:")
        for (script, label, name), values in sorted(results.items()):
            if name != "A" or (script, label, "B") not in results:
                continue
            a = [statistics.median(col) for col in zip(*values, strict=True)]
            b = [statistics.median(col) for col in zip(*results[(script, label, "B")], strict=True)]
            cells = "  ".join(f"{x:.3g} -> {y:.3g} ({y / x:.3f})" for x, y in zip(a, b, strict=True))
            print(f"{script:22s} {label[:40]:40s} {cells}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
