"""Nanoseconds a threshold draw: compiled draws against numpy's batched path, one process.

    python benchmarks/bench_draws.py [--draws 4000000] [--repeats 5]

For each built-in law with compiled draws (slidernet.kernels.draws), at the
paper's mu_d = 0.5, it times three ways of getting the same accepted values:

* ``compiled``: ``draws.fill_truncated``, one value at a time (what
  :class:`~slidernet.plugins.distributions.TruncatedStream` does for these laws);
* ``batched``: the plugin's ``sample(rng, RAW_CHUNK)`` and the truncation of
  ``TruncatedBelow.accepted``, chunk after chunk (what it does for plugins);
* ``numpy only``: numpy's batched draws with no truncation, for scale.

Prints the median over ``--repeats`` of the time per accepted value, and checks
that the compiled and batched values are the same bits.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from slidernet.kernels import draws
from slidernet.plugins.distributions import RAW_CHUNK, Exponential, Gaussian, TruncatedBelow, Uniform, Weibull

LAWS = {
    "gaussian (0.6, 0.01)": Gaussian(0.6, 0.01),
    "uniform (0.5, 0.7)": Uniform(0.5, 0.7),
    "weibull (2, 0.1, loc 0.5)": Weibull(2.0, 0.1, loc=0.5),
    "exponential (0.1, loc 0.5)": Exponential(0.1, loc=0.5),
}


def _median_ns(run, size: int, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) / size * 1e9


def measure(name: str, dist: object, size: int, repeats: int) -> tuple[float, float, float, bool]:
    """(compiled, batched, numpy only) in ns a draw, and whether compiled and batched agree to the bit."""
    law = TruncatedBelow(dist, 0.5, name)
    code = law.compiled_law()
    out = np.empty(size)
    draws.fill_truncated(np.random.default_rng(0), out[:10], *code, 0.5)  # load the compiled code, untimed

    def compiled() -> None:
        draws.fill_truncated(np.random.default_rng(1), out, *code, 0.5)

    def batched() -> np.ndarray:
        rng, parts, have = np.random.default_rng(1), [], 0
        while have < size:
            parts.append(law.accepted(rng, RAW_CHUNK))
            have += parts[-1].size
        return np.concatenate(parts)[:size]

    def numpy_only() -> None:
        dist.sample(np.random.default_rng(1), size)

    times = [_median_ns(f, size, repeats) for f in (compiled, batched, numpy_only)]
    return times[0], times[1], times[2], bool(np.array_equal(out, batched()))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=4_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    size = args.draws // RAW_CHUNK * RAW_CHUNK
    print(f"{size} accepted draws a run, median of {args.repeats} runs, ns a draw")
    print(f"{'law':28s} {'compiled':>9s} {'batched':>9s} {'numpy only':>11s}  same bits")
    for name, dist in LAWS.items():
        compiled, batched, raw, same = measure(name, dist, size, args.repeats)
        print(f"{name:28s} {compiled:9.2f} {batched:9.2f} {raw:11.2f}  {same}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
