"""Is the slide-hold-slide peak reached before its pull ends? The pull continued past its end, on held states.

    python benchmarks/shs_peak.py [--networks 2 16 64 256] [--realizations 16] [--times 0 100]
                                  [--more 3] [--std 0.01] [--stiffness 1.0] [--overshoot 1.0] [--seed 1]

The observable ``mu_shs`` is the peak of the stage force per unit normal load
over a pull that ends when every node has slipped once since it began
(docs/model.md, "Slide-hold-slide"). This script pulls on: for each state it
makes that pull, then ``--more`` pulls after it, each going on from where the
last stood (the stage's travel and the pull springs' stretch kept: the
forces of the end folded into the next start) until every node has slipped
once more, and reports how often and by how much the stage load of the
continued pull exceeds the recorded peak.

Scenes: irregular networks (network seed 0; 2 nodes: the pair, a chain of 2)
of ``--networks`` nodes, Ñ = 1e-7, mu_d = 0.5, Gaussian mu_s of mean 0.6 and
``--std``, the ``gaussian_steps`` driver with sigma_theta / Ñ = 1, and
``--realizations`` realizations (child r of SeedSequence(``--seed``)), each
held (cycled) to every time of ``--times`` (tau_th). The pulls' thresholds
come from a stream of the script's own (``SeedSequence([seed, r])``), not
the realization's ``shs`` stream: the measurement is of the rule, not of a
run's records. Every figure is a mean over realizations with its standard
error.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

import numpy as np

from slidernet import kernels
from slidernet.analysis.trend import mean_sem
from slidernet.config import load_config
from slidernet.kernels.tilt_net import L_F, L_PEAK, L_SHIFT, N_LOADS, N_POS, N_SLIPS, P_MU
from slidernet.plugins.distributions import TruncatedStream
from slidernet.solver import Realization, Scene


def scene_of(nodes: int, std: float, stiffness: float, overshoot: float, steps: int) -> Scene:
    """The scene of an irregular network of ``nodes`` (a chain of two for 2), recording ``mu_shs``."""
    network = {"kind": "chain", "n": 2} if nodes == 2 else {"kind": "irregular", "n": nodes, "seed": 0}
    cfg = {"seed": 0, "steps": steps, "record": [0], "observables": ["n", "mu_shs"],
           "network": {**network, "Ntilde": 1e-7}, "shs": {"stiffness": stiffness},
           "friction": {"mu_d": 0.5, "overshoot": overshoot,
                        "static": {"name": "gaussian", "mean": 0.6, "std": std}},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}
    return Scene.from_config(load_config(cfg))


def continued_pulls(real: Realization, draws: np.ndarray, more: int) -> dict[str, Any]:
    """The pull of ``real``'s state and ``more`` pulls after it, each until every node has slipped once more.

    Returns
    -------
    dict
        ``peak`` (mu_shs: the first pull's), ``later`` (the largest stage load, plus f_bar, of each later
        pull, shape (more,)), ``slips`` (the first pull's slips per node).
    """
    scene = real.scene
    o = scene.shs_operators()
    N = scene.network.n_nodes
    F = real.forces().reshape(N, -1)
    G = np.zeros((N, 2))
    G[:, : F.shape[1]] = F
    mu = real.mu.copy()
    heaps, epoch, count = kernels.Heaps.empty(2, N), np.zeros(N, np.int64), np.zeros(N, np.int64)
    pos, loads = np.zeros(N_POS, np.int64), np.zeros(N_LOADS)
    settings = scene.settings()
    offset = 0.0  # the stage's load at the end of the pulls so far, without f_bar
    peaks, slips = [], 0
    for k in range(more + 1):
        p_mu = int(pos[P_MU])
        pos[:] = 0
        pos[P_MU] = p_mu
        end = o.test(G, mu, o.f_ext, o.f_bar, o.net, settings, draws, pos, heaps, epoch, count, loads, o.pull)
        if kernels.tilt_status(end) != kernels.DONE:
            raise RuntimeError(f"pull {k} did not end (code {end}): more draws or a larger max_avalanche")
        peaks.append(loads[L_PEAK] + offset)
        slips = slips or int(pos[N_SLIPS])
        # Go on from here: the stage's travel f / pull becomes the next pull's origin, its load a force on G.
        offset += loads[L_F] - o.pull * loads[L_SHIFT]
        G[:, 0] += loads[L_F] * o.net.normal_load
    return {"peak": peaks[0], "later": np.array(peaks[1:]), "slips": slips / N}


def measure(nodes: int, realizations: int, times: list[int], more: int, std: float, stiffness: float,
            overshoot: float, seed: int) -> list[dict[str, Any]]:
    """One row per recorded time: per realization, the peak, whether and by how much later pulls exceed it."""
    scene = scene_of(nodes, std, stiffness, overshoot, max(max(times), 1))
    per: dict[int, dict[str, list[float]]] = {t: {"peak": [], "above1": [], "above": [], "excess": [],
                                                   "slips": []} for t in times}
    for r, child in enumerate(np.random.SeedSequence(seed).spawn(realizations)):
        real = Realization(scene, child)
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, r])))
        for t in sorted(times):
            real.advance(t)
            draws = TruncatedStream(scene.distribution, rng).take(200 * nodes * (more + 1) + 10_000)
            got = continued_pulls(real, draws, more)
            later = got["later"]
            row = per[t]
            row["peak"].append(got["peak"])
            row["above1"].append(float(later[:1].max() > got["peak"]) if more else math.nan)
            row["above"].append(float(later.max() > got["peak"]) if more else math.nan)
            row["excess"].append(max(later.max() - got["peak"], 0.0) if more else math.nan)
            row["slips"].append(got["slips"])
    return [{"nodes": nodes, "t": t, **{k: mean_sem(np.array(v))[:2] for k, v in per[t].items()}} for t in times]


def _pm(m: float, s: float, digits: int = 4) -> str:
    return f"{m:.{digits}f} ± {s:.{digits}f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--networks", type=int, nargs="*", default=[2, 16, 64, 256], help="nodes (2: the pair)")
    ap.add_argument("--realizations", type=int, default=16)
    ap.add_argument("--times", type=int, nargs="*", default=[0, 100], help="hold times, tau_th")
    ap.add_argument("--more", type=int, default=3, help="pulls after the first, each renewing every node once")
    ap.add_argument("--std", type=float, default=0.01, help="std of the Gaussian mu_s (mean 0.6, mu_d 0.5)")
    ap.add_argument("--stiffness", type=float, default=1.0, help="[shs] stiffness gamma")
    ap.add_argument("--overshoot", type=float, default=1.0, help="friction.overshoot e")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    print(f"std {args.std}, stiffness {args.stiffness}, overshoot {args.overshoot}, {args.realizations} "
          f"realizations, {args.more} more pulls; mean ± standard error over realizations")
    print("| N | t | mu_shs | slips per node | later pull above: next one | any of them | mean excess |")
    print("|---|---|---|---|---|---|---|")
    for nodes in args.networks:
        for row in measure(nodes, args.realizations, args.times, args.more, args.std, args.stiffness,
                           args.overshoot, args.seed):
            print(f"| {row['nodes']} | {row['t']} | {_pm(*row['peak'])} | {_pm(*row['slips'], 1)} | "
                  f"{_pm(*row['above1'], 2)} | {_pm(*row['above'], 2)} | {_pm(*row['excess'])} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
