"""A new user's first contact, timed cold: an empty kernel cache, then the same run again warm.

    python benchmarks/cold_start.py [--package-root PATH] [--rows NAME ...] [--csv PATH]

Each row runs ``python -m slidernet ...`` in a fresh process with its own
empty numba cache (``NUMBA_CACHE_DIR`` in a temporary folder), and then once
more on the cache the first run filled. The CPU seconds are the whole
process tree's (the run and its worker processes: ``os.wait4``'s usage,
which includes the children the run waited for); the wall time is beside
them. The rows:

- ``import``: ``python -c "import slidernet"`` and ``python -m slidernet --help``
  (no kernel; the best of 3 runs);
- ``pair``: the getting-started run (the paper's reference case with 20
  realizations, 1e4 steps, observables n, mu_max, x_G, mu_eff: two sliders
  with the appendix's tilt test), 2 workers;
- ``chain``: a chain of 8 with mu_eff (the network tilt test at the recorded
  times), 4 realizations x 200 steps, 2 workers;
- ``lattice``: a triangular 8 x 8 lattice with mu_eff, 4 realizations x 50
  steps, 2 workers;
- ``moved``: the chain row again on the cache the chain row filled, but with
  the package copied to another folder (new paths and modification times:
  what ``pip install .`` then ``pip install -e .`` of the same sources does).
  It should compile nothing.

``--package-root`` runs another checkout of slidernet (its parent folder of
``slidernet/``, put first on ``PYTHONPATH``): the same script gives the table
before and after a change. Without it, the package this script imports.
Quoted figures in docs/guides/performance.md come from this script on the
idle 2-core dev machine.
"""

from __future__ import annotations

import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHAIN = """seed = 1
realizations = 4
steps = 200
record = "log"
observables = ["n", "mu_max", "x_G", "mu_eff"]
[network]
kind = "chain"
n = 8
Ntilde = 1e-7
[friction]
mu_d = 0.5
[friction.static]
name = "gaussian"
mean = 0.6
std = 0.01
[driver]
name = "gaussian_steps"
sigma_theta = 1e-7
"""
LATTICE = CHAIN.replace("steps = 200", "steps = 50").replace(
    'kind = "chain"\nn = 8', 'kind = "triangular"\nshape = [8, 8]')
PAIR = CHAIN.replace("realizations = 4", "realizations = 20").replace("steps = 200", "steps = 10000").replace(
    'kind = "chain"\nn = 8', 'kind = "two_slider"').replace("sigma_theta = 1e-7", "sigma_theta = 1e-6")

ROWS = ("import", "pair", "chain", "lattice", "moved")


def timed(cmd: list[str], env: dict[str, str], cwd: Path) -> tuple[float, float]:
    """(CPU s of the process tree, wall s) of ``cmd``; raises if it fails."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    err = proc.stderr.read().decode() if proc.stderr else ""
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{err}")
    return usage.ru_utime + usage.ru_stime, wall


def run_row(name: str, root: Path, work: Path) -> list[tuple[str, float, float]]:
    env = {**os.environ, "PYTHONPATH": str(root)}
    py = sys.executable
    if name == "import":
        out = []
        for label, args in (("import slidernet", ["-c", "import slidernet"]),
                            ("slidernet --help", ["-m", "slidernet", "--help"])):
            best = min((timed([py, *args], env, work) for _ in range(3)), key=lambda t: t[1])
            out.append((label, *best))
        return out
    config = {"pair": PAIR, "chain": CHAIN, "lattice": LATTICE, "moved": CHAIN}[name]
    path = work / f"{name}.toml"
    path.write_text(config)
    cache = work / ("cache-chain" if name == "moved" else f"cache-{name}")
    if name == "moved":
        if not cache.exists():
            raise SystemExit("the 'moved' row needs the 'chain' row first (it reuses its cache)")
        copy = work / "moved-install"
        shutil.copytree(root / "slidernet", copy / "slidernet", ignore=shutil.ignore_patterns("__pycache__"))
        env["PYTHONPATH"] = str(copy)
    env["NUMBA_CACHE_DIR"] = str(cache)
    cmd = [py, "-m", "slidernet", "run", str(path), "--workers", "2", "--no-progress", "--overwrite",
           "--out", str(work / f"out-{name}")]
    rows = []
    for label in (("same sources, another install",) if name == "moved" else ("cold", "warm")):
        rows.append((f"{name}: {label}", *timed(cmd, env, work)))
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--package-root", type=Path, default=None,
                        help="the folder holding the slidernet package to time (default: the one imported here)")
    parser.add_argument("--rows", nargs="+", choices=ROWS, default=list(ROWS))
    parser.add_argument("--csv", type=Path, default=None, help="also write the rows here")
    args = parser.parse_args(argv)
    if args.package_root is None:
        import slidernet

        root = Path(slidernet.__file__).resolve().parent.parent
    else:
        root = args.package_root.resolve()
    if "moved" in args.rows and "chain" not in args.rows:
        raise SystemExit("--rows moved needs chain too")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"slidernet at {root}; {os.cpu_count()} cores, load average {load:.2f}")
    print("| what | CPU s (process tree) | wall s |\n|---|---|---|")
    results = []
    with tempfile.TemporaryDirectory(prefix="slidernet-cold-") as tmp:
        for name in ROWS:
            if name not in args.rows:
                continue
            for label, cpu, wall in run_row(name, root, Path(tmp)):
                print(f"| {label} | {cpu:.1f} | {wall:.1f} |", flush=True)
                results.append((label, cpu, wall))
    if args.csv is not None:
        with args.csv.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["what", "cpu_s", "wall_s"])
            w.writerows(results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
