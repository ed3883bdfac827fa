"""How the exact creep orbits of chains settle: periods, transients and orbits that never repeat.

    python benchmarks/creep_orbit_periods.py [--sliders 3 4] [--sets 300] [--max-cycles 200] [--seed 2026]

For each chain length, draws ``--sets`` parameter sets at random (seeded):
A / Ntilde uniform in [0, 2], mu_d in [0.2, 0.6], mu_s - mu_d in
[0.01, 0.3], tan(alpha) / mu_d in [0.01, 0.99], and follows the exact orbit
of :func:`slidernet.analysis.theory.chain_orbit` from rest. Prints how many
orbits repeated, with which periods (cycles) after which transients
(cycles), and how many did not repeat within ``--max-cycles``.
"""

from __future__ import annotations

import argparse
import collections
import time
from collections.abc import Sequence

import numpy as np

from slidernet.analysis import theory
from slidernet.errors import OrbitError

NTILDE = 1e-7  # the orbit depends on A / Ntilde only


def survey(n_sliders: int, sets: int, max_cycles: int, rng: np.random.Generator) -> str:
    periods: collections.Counter[int] = collections.Counter()
    transients: collections.Counter[int] = collections.Counter()
    aperiodic = 0
    start = time.perf_counter()
    for _ in range(sets):
        A, mu_d, gap, w = rng.uniform([0.0, 0.2, 0.01, 0.01], [2.0, 0.6, 0.3, 0.99])
        try:
            orbit = theory.chain_orbit(n_sliders, A * NTILDE, NTILDE, w * mu_d, mu_d + gap, mu_d,
                                       max_cycles=max_cycles)
        except OrbitError:
            aperiodic += 1
            continue
        periods[orbit.period] += 1
        transients[orbit.transient] += 1
    return (f"{n_sliders} sliders, {sets} sets, max_cycles = {max_cycles}: {aperiodic} did not repeat; "
            f"periods {dict(sorted(periods.items()))}; transients {dict(sorted(transients.items()))} "
            f"({time.perf_counter() - start:.0f} s)")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--sliders", type=int, nargs="+", default=[3, 4])
    parser.add_argument("--sets", type=int, default=300)
    parser.add_argument("--max-cycles", type=int, default=200)
    parser.add_argument("--seed", type=int, default=2026)
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    for n in args.sliders:
        print(survey(n, args.sets, args.max_cycles, rng), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
