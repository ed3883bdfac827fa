"""The machine's memory latency against the working set: why a network's kernel slows down as it grows.

    python benchmarks/memory_latency.py [--sizes-mb 0.125 0.5 2 4 8 32 400] [--loads 5000000] [--core 1]

For each working-set size it times, on one pinned core, two kinds of
random 8-byte loads over an array of that size:

* *dependent*: each load's address is the value of the previous one (a
  random cyclic permutation), so the processor waits for every load in turn.
  This is the latency a chain of cache misses pays: a driving event at a
  random node reads the node, then its row of K, then its neighbours;
* *independent*: the addresses are known in advance, so the processor keeps
  many loads in flight; the time per load is the memory's throughput for
  random reads.

A 2D irregular network's kernel state is about 420 bytes per node (K's
blocks, one per entry, forces, thermal loads, thresholds, heap and tree
entries; the performance guide), so a network of N nodes works on roughly
420 N bytes: 4.2 MB at 1e4 nodes, 420 MB at 1e6. Reading a row of the table against those sizes tells how far from
the cache each network runs on this machine. The numbers depend on the
machine and on what else shares its last-level cache; the script prints the
load average with them.
"""

from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np


@numba.njit(cache=False)
def _chase(nxt: np.ndarray, loads: int) -> int:
    j = 0
    for _ in range(loads):
        j = nxt[j]
    return j


@numba.njit(cache=False)
def _gather(values: np.ndarray, idx: np.ndarray) -> float:
    total = 0.0
    for k in range(idx.size):
        total += values[idx[k]]
    return total


def measure(size_mb: float, loads: int, rng: np.random.Generator) -> tuple[float, float]:
    """(dependent, independent) nanoseconds per random 8-byte load over ``size_mb`` megabytes."""
    n = max(2, int(size_mb * 1e6 / 8))
    perm = rng.permutation(n)
    nxt = np.empty(n, np.int64)
    nxt[perm] = np.roll(perm, 1)  # one cycle through every slot: no short loop stays in cache
    _chase(nxt, 1000)
    t0 = time.perf_counter()
    _chase(nxt, loads)
    dependent = (time.perf_counter() - t0) / loads * 1e9
    values = np.ones(n)
    idx = rng.integers(0, n, loads)
    _gather(values, idx[:1000])
    t0 = time.perf_counter()
    _gather(values, idx)
    independent = (time.perf_counter() - t0) / loads * 1e9
    return dependent, independent


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes-mb", type=float, nargs="+", default=[0.125, 0.5, 2, 4, 8, 32, 400],
                        help="working-set sizes in MB (default: 0.125 0.5 2 4 8 32 400)")
    parser.add_argument("--loads", type=int, default=5_000_000, help="timed loads per size (default 5e6)")
    parser.add_argument("--core", type=int, default=1, help="the core to pin to (default 1; -1: no pinning)")
    args = parser.parse_args(argv)
    if args.core >= 0 and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {args.core})
    rng = np.random.default_rng(0)
    print("| working set | dependent loads (latency) | independent loads (throughput) |")
    print("|---|---|---|")
    for size in args.sizes_mb:
        dep, ind = measure(size, args.loads, rng)
        print(f"| {size:g} MB | {dep:.1f} ns | {ind:.1f} ns |", flush=True)
    print(f"\nload average {os.getloadavg()[0]:.2f}; core {args.core}; {args.loads:,} loads per size")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
