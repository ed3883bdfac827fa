"""Seconds per node of building a scene (the network, K, g and the scene's checks), by kind of network.

The slow-run estimate (:func:`slidernet.solver.budget.warn_if_slow`) counts
this time beside the kernels' (``budget.SETUP_SECONDS``): a network of 5e7
sliders takes longer to build than to drive for a few steps. Each kind is
built at two sizes, in a fresh process each (the first build of a process
pays for the allocator's growth), and the figure is the larger size's time
per node, the median of ``--repeat`` builds.

Usage (from the repository root, slidernet installed)::

    python benchmarks/setup_cost.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

SIZES = {"chain": [{"n": 10**6}, {"n": 5 * 10**6}],
         "square": [{"shape": [1000, 1000]}, {"shape": [2000, 2500]}],
         "triangular": [{"shape": [1000, 1000]}, {"shape": [2000, 2500]}],
         "irregular": [{"n": 10**5}, {"n": 10**6}]}

ONE_BUILD = """
import json, sys, time, warnings
warnings.simplefilter("ignore")
from slidernet.config import load_config
from slidernet.solver import Scene
net = json.loads(sys.argv[1])
cfg = load_config({"seed": 1, "steps": 2, "network": {**net, "Ntilde": 1e-7},
                   "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
                   "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}})
t0 = time.perf_counter()
scene = Scene.from_config(cfg)
print(time.perf_counter() - t0, scene.network.n_nodes)
"""


def build_seconds(kind: str, size: dict) -> tuple[float, int]:
    out = subprocess.run([sys.executable, "-c", ONE_BUILD, json.dumps({"kind": kind, **size})], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[0]), int(out[1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    for kind, sizes in SIZES.items():
        row = []
        for size in sizes:
            runs = [build_seconds(kind, size) for _ in range(args.repeat)]
            seconds = statistics.median(s for s, _ in runs)
            row.append(f"{runs[0][1]:,} nodes: {seconds:.2f} s ({seconds / runs[0][1] * 1e6:.3f} us/node)")
        print(f"{kind:11s} " + "; ".join(row), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
