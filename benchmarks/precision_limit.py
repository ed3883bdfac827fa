"""Where float64 stops resolving a network's slips: the share of the gap that a force's rounding reaches.

``python benchmarks/precision_limit.py`` (about 3.5 minutes; the precision check bypassed): chains of 8
(Ntilde = 1, mu_d = 0.5, mu_s ~ gaussian(0.6, 0.01)) at sigma_theta / Ntilde = 2e12, 2e13, 2e14, so that
the rounding of a force, eps times its largest term (|g| |theta| / Ntilde), is about 0.3 %, 3 % and 28 % of
the gap (mu_s - mu_d) N_i that a slip works across. Each runs two thermal steps in a process of its own
for at most 100 s (such a run makes ~1e14 slips per tau_th: it never ends, what counts is whether it stops
in an avalanche that never ends, ``AvalancheError``, within ``solver.max_avalanche`` = 1e8 slips). The
refusal of :func:`slidernet.solver.budget.check_precision` at ``PRECISION_SHARE`` = 1/64 of the gap is
placed below the smallest share measured to stop.
"""

from __future__ import annotations

import subprocess
import sys

ONE = r'''
import sys, time, numpy as np
from slidernet.config import load_config
from slidernet.solver import Realization, Scene, budget
# allow_implausible: Ntilde = 1 and the sigma_theta of float64's limit lie far outside real materials
cfg = load_config({"seed": 1, "realizations": 1, "steps": 2, "allow_implausible": True,
                   "network": {"kind": "chain", "n": 8, "Ntilde": 1.0},
                   "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
                   "driver": {"name": "gaussian_steps", "sigma_theta": float(sys.argv[1])}})
scene = Scene.from_config(cfg)
s = budget.scales(cfg, scene)
terms = s.load.max() * s.theta + s.mu_s * s.normal_load.max()
share = np.finfo(float).eps * terms / (s.gap * s.normal_load.min())
print(f"rounding / gap = {share:.3g}", flush=True)
start = time.perf_counter()
try:
    Realization(scene, np.random.SeedSequence(0)).advance(2)
    print("finished", flush=True)
except Exception as e:
    print(f"{type(e).__name__} after {time.perf_counter() - start:.1f} s: {str(e)[:160]}", flush=True)
'''


def main() -> None:
    for sigma in (2e12, 2e13, 2e14):
        try:
            proc = subprocess.run([sys.executable, "-c", ONE, str(sigma)], capture_output=True, text=True,
                                  timeout=100)
            out = proc.stdout.strip() + proc.stderr.strip()[-300:]
        except subprocess.TimeoutExpired as stopped:
            out = (stopped.stdout or b"").decode().strip() + "; still running after 100 s, no AvalancheError"
        print(f"sigma_theta / Ntilde = {sigma:.0e}: " + out.replace("\n", "; "), flush=True)


if __name__ == "__main__":
    main()
