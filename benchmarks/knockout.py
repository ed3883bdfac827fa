"""What one part of the 2D kernel costs a slip, without hardware counters: do it twice, time the difference.

    python benchmarks/knockout.py [--n 10000] [--steps 40] [--rounds 6] [--core 1] [PATCH ...]

``perf`` on the development machine has only software events, so a profile
(``profile_kernel.py``) says which instructions wait, not what a whole part
of the work costs. Each patch in ``benchmarks/knockout/`` makes the kernel do
one part of its work a second time without changing a single slip: the
second result is kept from the compiler's dead-code elimination but never
used.

* ``roots_twice.diff``: eq. `critique`'s roots of every re-keyed node, twice;
* ``trees_both.diff``: every re-key keys both driving trees, the inactive
  one too (a turn of theta then finds its keys already set: the same tree).

The script checks HEAD out into a temporary git worktree (the base) and
once more per patch, with the patch applied; compiles each version's
kernels into its own numba cache (untimed); then runs ``bench_vs_c.py``'s
irregular child (``--n`` nodes, ``--steps`` thermal steps, the network of
its rows 8 and 9) for every version in each round, the order rotating from
round to round, pinned to ``--core``. It stops with an error if a version
makes a different number of slips: its patch changed the physics.

It prints each run, then per patch the median rate, the ratio to the base in
the same round (median and range), and the extra time a slip (median over
the rounds): the marginal cost of that part. Where the second copy overlaps
with the first on the processor, the difference is less than what the part
costs alone.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import statistics
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from ab_versions import run_pinned, worktree

HERE = Path(__file__).resolve().parent
PATCHES = HERE / "knockout"


def _rate(out: str) -> tuple[int, float]:
    """(slips, slips/s) from the child's last line, a JSON object."""
    row = json.loads(out.strip().splitlines()[-1])
    return int(row["slips"]), float(row["rate"])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("patches", nargs="*", type=Path, help="patches (default: all of benchmarks/knockout)")
    ap.add_argument("--n", type=int, default=10_000, help="nodes of the irregular network")
    ap.add_argument("--steps", type=int, default=40, help="thermal steps of each run")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--core", type=int, default=1)
    args = ap.parse_args(argv)
    patches = args.patches or sorted(PATCHES.glob("*.diff"))
    for patch in patches:
        if not patch.is_file():
            ap.error(f"no patch file {patch}")
    with tempfile.TemporaryDirectory(prefix="slidernet-knockout-") as tmp, contextlib.ExitStack() as trees:
        patch_of = {p.stem: p.resolve() for p in patches}
        versions = {name: trees.enter_context(worktree(Path(tmp) / name, "HEAD")) for name in ["base", *patch_of]}
        for name, patch in patch_of.items():
            subprocess.run(["git", "-C", str(versions[name]), "apply", str(patch)], check=True)

        def run(name: str, n: int, steps: int, file: str, core: int | None = args.core) -> tuple[int, float]:
            params = json.dumps({"n": n, "steps": steps, "file": str(Path(tmp) / file)})
            out = run_pinned("bench_vs_c.py", f"--child irregular '{params}'", versions[name],
                             Path(tmp) / f"cache-{name}", core)
            return _rate(out)

        # Compile, untimed, two versions at a time: each writes its own small network file. The timed runs
        # share one file (the child writes it, for network.c, only where it is missing).
        with ThreadPoolExecutor(max_workers=2) as pool:
            list(pool.map(lambda name: run(name, 1000, 2, f"warm-{name}.txt", None), versions))
        names = list(versions)
        rates: dict[str, list[float]] = {name: [] for name in names}
        for rnd in range(args.rounds):
            k = rnd % len(names)
            slips = {}
            for name in names[k:] + names[:k]:
                slips[name], rate = run(name, args.n, args.steps, f"net{args.n}.txt")
                rates[name].append(rate)
                print(f"round {rnd + 1}  {name:14s} {slips[name]} slips  {rate / 1e6:.3f} M/s", flush=True)
            if len(set(slips.values())) != 1:
                raise SystemExit(f"The versions made different numbers of slips: {slips}. A patch changed the "
                                 "physics, so its time is not the cost of a repeated part.")
        print(f"\n{args.n} irregular nodes, {args.steps} steps, {args.rounds} rounds on core {args.core}:")
        print("| version | median M slips/s | ratio to base, median (range) | extra ns a slip, median |")
        print("|---|---|---|---|")
        base = rates["base"]
        print(f"| base | {statistics.median(base) / 1e6:.3f} | | |")
        for name in names[1:]:
            ratio = [r / b for r, b in zip(rates[name], base, strict=True)]
            extra = [1e9 / r - 1e9 / b for r, b in zip(rates[name], base, strict=True)]
            print(f"| {name} | {statistics.median(rates[name]) / 1e6:.3f} | {statistics.median(ratio):.3f} "
                  f"({min(ratio):.3f} - {max(ratio):.3f}) | {statistics.median(extra):.0f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
