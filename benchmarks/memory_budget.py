"""Measure the memory a run takes, part by part, against the model of slidernet.solver.budget.

``python benchmarks/memory_budget.py`` (about 3 minutes; memory only, no timing): each figure is the growth
of the peak resident memory (``ru_maxrss``) of a fresh Python process between two sizes of one part of a
run, divided by the growth of that part, so that what does not grow with it (the interpreter, numpy,
numba, the compiled kernels: about 0.3 GB) cancels. Printed beside each: the constant of the model
(``slidernet.solver.budget``) that the refusal of a run too large for the machine is based on.

- the scene, per node, for each kind of network: the peak of building the network, K and g (the
  Delaunay triangulation of an irregular network, the sparse assembly), before any realization;
- the state of a realization, per node (its forces, displacements, thresholds, heaps), from the same
  processes: the growth of the peak from the scene alone to the scene and two realizations, per
  realization, where the build's peak does not hide it (the lattices);
- theta(t_q), per thermal step of a running realization (the driver draws the whole run at once);
- the records, per realization and recorded time (``record = "all"``), held in memory or with ``--out``;
- the bookkeeping of the ensemble, per realization (one recorded step), in memory and with ``--out``.
"""

from __future__ import annotations

import json
import subprocess
import sys

from slidernet.solver import budget

SCENE = r'''
import json, resource, sys, numpy as np
from slidernet.config import load_config
from slidernet.solver import Realization, Scene
kind, size = sys.argv[1], json.loads(sys.argv[2])
def config(size):
    net = {"kind": kind, "Ntilde": 1e-7, ("shape" if isinstance(size, list) else "n"): size}
    return {"seed": 1, "realizations": 1, "steps": 1, "network": net,
            "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
            "driver": {"name": "gaussian_steps", "sigma_theta": 1e-9}}
tiny = config([2, 2] if isinstance(size, list) else 4)
Realization(Scene.from_config(load_config(tiny)), np.random.SeedSequence(0)).advance(1)  # kernels loaded
scene = Scene.from_config(load_config(config(size)))
built = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
kept = [Realization(scene, np.random.SeedSequence(r)).advance(1) for r in range(2)]
both = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"N": scene.network.n_nodes, "built": built * 1024, "both": both * 1024}))
'''

RUN = r'''
import json, resource, sys, tempfile, slidernet
R, steps, record, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4] == "out"
def config(R, steps):
    return {"seed": 1, "realizations": R, "steps": steps, "record": record,
            "network": {"kind": "chain", "n": 4, "Ntilde": 1e-7},
            "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
            "driver": {"name": "gaussian_steps", "sigma_theta": 1e-9}}
slidernet.run(config(2, 2), workers=1)  # kernels loaded
with tempfile.TemporaryDirectory() as folder:
    ds = slidernet.run(config(R, steps), workers=1, out=folder + "/run" if out else None)
    ds.close()
print(json.dumps({"peak": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
'''


def _child(code: str, *args: object) -> dict:
    proc = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True, text=True)
    if proc.returncode:
        raise SystemExit(proc.stderr[-3000:])
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    print("part                                        measured    model (slidernet.solver.budget)")
    sizes = {"chain": (200_000, 2_000_000), "square": ([400, 500], [1000, 2000]),
             "triangular": ([400, 500], [1000, 2000]), "irregular": (100_000, 1_000_000)}
    for kind, (small, large) in sizes.items():
        a, b = _child(SCENE, kind, json.dumps(small)), _child(SCENE, kind, json.dumps(large))
        dn = b["N"] - a["N"]
        scene = (b["built"] - a["built"]) / dn
        print(f"scene, {kind:<10} per node               {scene:8.0f} B  {budget.SCENE_BYTES[kind]:8.0f} B",
              flush=True)
        realization = ((b["both"] - b["built"]) - (a["both"] - a["built"])) / (2 * dn)
        print(f"realization state, {kind:<10} per node   {realization:8.0f} B  {budget.STATE_BYTES:8.0f} B"
              + ("  (hidden under the build's peak)" if kind in ("chain", "irregular") else ""), flush=True)
    a, b = _child(RUN, 1, 1_000_000, "log", "memory"), _child(RUN, 1, 11_000_000, "log", "memory")
    print(f"theta(t_q), per thermal step                {(b['peak'] - a['peak']) / 1e7:8.1f} B  "
          f"{budget.THETA_BYTES:8.1f} B", flush=True)
    for where in ("memory", "out"):
        a, b = _child(RUN, 2, 200_000, "all", where), _child(RUN, 2, 2_000_000, "all", where)
        # theta(t_q) of the running realization grows with the steps too: taken off.
        per = (b["peak"] - a["peak"] - budget.THETA_BYTES * 1_800_000) / (2 * 1_800_000)
        print(f"records ({where:<6}), per realization x time  {per:8.0f} B  {budget.RECORD_BYTES:8.0f} B",
              flush=True)
    for where in ("memory", "out"):
        a, b = _child(RUN, 2_000, 1, "log", where), _child(RUN, 10_000, 1, "log", where)
        model = budget.REALIZATION_BYTES[where == "out"]
        print(f"bookkeeping ({where:<6}), per realization     {(b['peak'] - a['peak']) / 8_000:8.0f} B  "
              f"{model:8.0f} B", flush=True)


if __name__ == "__main__":
    main()
