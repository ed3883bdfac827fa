"""Avalanches with inertia: size distributions under thermal cycling, quasi-static against inertial.

For one irregular network (``--n`` nodes, network seed 0; mu_d = 0.5, Gaussian mu_s of mean 0.6 and std
``--ratio`` (0.6 - 0.5), Ntilde = 1e-7, gaussian_steps with sigma_theta = ``--sigma`` Ntilde; the aging
study's parameters) and ``--realizations`` R realizations (the children of ``SeedSequence(--seed)``, as
``slidernet.run`` gives them), this runs the quasi-static solver (:func:`slidernet.solver.simulate`, the
event catalogue) and the compiled inertial solver (:class:`slidernet.solver.inertia_2d.Inertia2D`, or
:class:`slidernet.solver.inertia.InertialSolver` for a 1D scene) at each tau_dyn / tau_th of ``--taus``,
on the same seeds (the same theta(t_q) and the same stream of thresholds), over ``--steps`` thermal steps,
and keeps the avalanches that start at t >= ``--skip`` tau_th (the first loading is left out).

What an avalanche is, in each solver:

* quasi-static: the slips set off by one driving event (the event catalogue's ``avalanche``); its size S is
  its number of slips;
* inertial: one motion from rest to rest (a start with nothing moving to the next moment nothing moves);
  its size S is its number of starts, each of which ends as one slip (so the sizes add up to the slips).

The two are not the same grouping. A driving event that comes while the network moves joins the running
inertial avalanche, so one inertial avalanche can hold several driving events (``events_per_avalanche``:
the quasi-static run's driving events over the inertial avalanches, in the same window, on the same
theta(t)); the reverse cannot happen, as the kernels end an avalanche only where nothing moves and nothing
is over its threshold (a node that stops on a redrawn threshold below its force restarts within the same
avalanche); ``gaps_below_tau_dyn`` counts the avalanches that start less than tau_dyn after the previous
one's end, the nearest thing to a split.

Written, per solver (``qs`` and each tau): the log2-binned density P(S) (per unit S, normalized per
realization), its mean and standard error over realizations (the realizations are the independent samples,
not the avalanches of one trajectory); the exponent tau_S of P(S) ~ S^-tau_S, the discrete power law's
maximum-likelihood estimate on the pooled sizes in [``--fit-min``, ``--fit-max``], with its jackknife
standard error over realizations; the mean and largest size; the fraction of avalanches of size >= N (the
system-spanning ones); the slip rate (slips per tau_th in the window); the fraction of the window in
motion; and, for a run still moving at its end, the starts of that unfinished motion. An inertial run that
has not ended within ``--limit`` seconds of wall time (each run is a child process, one at a time) is
recorded as not finished, and the other realizations at that tau are not started.

Run from the repository root (one process at a time)::

    python benchmarks/avalanches_inertia.py --json avalanches.json --figure avalanches.png
    python benchmarks/avalanches_inertia.py --quick     # a smoke run (32 nodes, tau 1e-4 and 1e-1), ~20 s

Time: see docs/guides/avalanches.md for the run there and the time it took.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import os
import platform
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.solver import Scene, simulate

NTILDE = 1e-7
MU_D = 0.5
MU_S = 0.6
MIN_CURVE = 100  # avalanches below which the figure names a solver without drawing its P(S)


def make_scene(n: int, sigma: float, ratio: float, steps: int, network: dict | None = None,
               solver: dict | None = None) -> Scene:
    """The aging study's scene: an irregular network of n (network seed 0) unless ``network`` is given.

    sigma is sigma_theta / Ntilde, ratio is std(mu_s) / (mean(mu_s) - mu_d); ``solver``: the ``[solver]``
    table (default: the default straight-line slip).
    """
    net = dict(network or {"kind": "irregular", "n": n, "seed": 0}, Ntilde=NTILDE)
    return Scene.from_config(load_config({
        "steps": steps, "record": "log", "observables": ["n", "events"], "network": net,
        "friction": {"mu_d": MU_D, "static": {"name": "gaussian", "mean": MU_S, "std": ratio * (MU_S - MU_D)}},
        "driver": {"name": "gaussian_steps", "sigma_theta": sigma * NTILDE}, "solver": solver or {}}))


def qs_avalanches(scene: Scene, seed_seq: np.random.SeedSequence, skip: float) -> dict[str, Any]:
    """The quasi-static run's avalanches that start at t >= skip (tau_th).

    Returns
    -------
    dict
        ``sizes`` (int64, shape (A,): slips per driving event), ``slips`` (in the window), ``window``
        (tau_th), ``events`` (A: the driving events in the window), ``moving`` (0.0: a quasi-static slip takes
        no time).
    """
    ev = simulate(scene, seed_seq)["events"]
    keep = ev["avalanche"] >= 1  # 0: the relaxation of an initial overload, not a driving event
    aval, time_ = ev["avalanche"][keep], ev["time"][keep]
    sizes = np.bincount(aval)
    first = np.full(sizes.size, np.inf)
    np.minimum.at(first, aval, time_)
    chosen = (sizes > 0) & (first >= skip)
    sizes = sizes[chosen].astype(np.int64)
    return {"sizes": sizes, "slips": int(sizes.sum()), "window": float(scene.steps - skip),
            "events": int(sizes.size), "moving": 0.0}


def inertial_avalanches(scene: Scene, tau: float, seed_seq: np.random.SeedSequence, skip: float) -> dict[str, Any]:
    """The inertial run's avalanches (motions from rest to rest) that start at t >= skip (tau_th).

    Returns
    -------
    dict
        ``sizes`` (int64, shape (A,): starts per avalanche), ``duration`` (tau_th, shape (A,)), ``slips``
        (slips that start in the window), ``window`` (tau_th), ``moving`` (the fraction of the window in
        motion, the unfinished motion at the end included), ``unfinished`` (the starts of a motion still
        running at the end: a lower bound on its size; 0 if at rest), ``gaps_below_tau_dyn`` (avalanches
        that start less than tau_dyn after the previous one ended), ``total_slips``, ``total_starts``
        (over the whole run: they are equal where the run ends at rest).
    """
    if scene.network.dim == 1:
        from slidernet.solver.inertia import InertialSolver
        out = InertialSolver(scene, tau).run(seed_seq)
        ends = out["avalanches"]["slips"]
        starts = np.diff(np.concatenate([[0], ends]))
    else:
        from slidernet.solver.inertia_2d import Inertia2D
        out = Inertia2D(scene, tau).run(seed_seq)
        starts = out["avalanches"]["starts"]
    av = out["avalanches"]
    total = int(out["n"][-1])
    unfinished = total - int(starts.sum())
    chosen = av["start"] >= skip
    last_end = av["end"][-1] if av["end"].size else 0.0
    moving = float(np.sum(av["end"][chosen] - av["start"][chosen]))
    if unfinished:
        moving += scene.steps - max(last_end, skip)
    gap = (av["start"][1:] - av["end"][:-1])[chosen[1:]]  # from the previous avalanche's end
    return {"sizes": starts[chosen].astype(np.int64), "duration": (av["end"] - av["start"])[chosen],
            "slips": int(np.sum(out["slips"]["start"] >= skip)), "window": float(scene.steps - skip),
            "moving": moving / (scene.steps - skip), "unfinished": unfinished,
            "gaps_below_tau_dyn": int(np.sum(gap < tau)), "total_slips": total,
            "total_starts": int(starts.sum()) + unfinished}


def log2_edges(largest: int) -> np.ndarray:
    """Bin edges 1, 2, 4, ... up to the first power of 2 above ``largest`` (bins [s, 2s), as
    ``avalanche_count``)."""
    return 2.0 ** np.arange(0, max(1, math.ceil(math.log2(largest + 1))) + 1)


def densities(sizes: Sequence[np.ndarray], edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P(S) per unit S in each bin, per realization (each normalized to its own avalanches), and its mean and
    standard error over the realizations that have avalanches (one without any has no P(S); counting it as
    zero would lower the density); shape (B,) each (NaN error with fewer than two such realizations)."""
    width = np.diff(edges)
    per = np.array([np.histogram(s, edges)[0] / s.size / width for s in sizes if s.size]).reshape(-1, width.size)
    if not len(per):
        return np.full(width.size, np.nan), np.full(width.size, np.nan)
    sem = per.std(axis=0, ddof=1) / math.sqrt(len(per)) if len(per) > 1 else np.full(width.size, np.nan)
    return per.mean(axis=0), sem


def power_law_mle(sizes: np.ndarray, s_min: int, s_max: int) -> float:
    """The exponent tau_S of the discrete power law P(S) = S^-tau_S / Z on the integers [s_min, s_max],
    by maximum likelihood on the sizes in that range (NaN with fewer than 10 of them).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> s = np.arange(1, 1001)
    >>> p = s ** -1.5
    >>> round(power_law_mle(rng.choice(s, 200_000, p=p / p.sum()), 1, 1000), 2)
    1.5
    """
    x = sizes[(sizes >= s_min) & (sizes <= s_max)]
    if x.size < 10:
        return math.nan
    mean_log = np.log(x).mean()
    log_s = np.log(np.arange(s_min, s_max + 1, dtype=np.float64))

    def nll(tau: float) -> float:
        return tau * mean_log + float(np.logaddexp.reduce(-tau * log_s))

    return float(minimize_scalar(nll, bounds=(0.0, 6.0), method="bounded", options={"xatol": 1e-6}).x)


def exponent(sizes: Sequence[np.ndarray], s_min: int, s_max: int) -> tuple[float, float]:
    """The MLE on the sizes of all realizations pooled, and its jackknife standard error over realizations
    (each left out in turn; NaN with fewer than 2)."""
    pooled = power_law_mle(np.concatenate(sizes), s_min, s_max)
    R = len(sizes)
    if R < 2:
        return pooled, math.nan
    leave = np.array([power_law_mle(np.concatenate([s for j, s in enumerate(sizes) if j != i]), s_min, s_max)
                      for i in range(R)])
    return pooled, float(math.sqrt((R - 1) / R * np.sum((leave - leave.mean()) ** 2)))


def mean_sem(values: Sequence[float]) -> tuple[float, float]:
    v = np.asarray(values, dtype=np.float64)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else math.nan


def summarize(runs: list[dict[str, Any]], n_nodes: int, edges: np.ndarray, fit: tuple[int, int]) -> dict[str, Any]:
    """The statistics over realizations of one solver's runs (each a dict of :func:`qs_avalanches` or
    :func:`inertial_avalanches`)."""
    sizes = [r["sizes"] for r in runs]
    density, density_sem = densities(sizes, edges)
    tau_s, tau_s_sem = exponent(sizes, *fit)
    per = {
        "mean_size": [float(s.mean()) if s.size else math.nan for s in sizes],
        "largest_size": [int(s.max()) if s.size else 0 for s in sizes],
        "spanning_fraction": [float(np.mean(s >= n_nodes)) if s.size else math.nan for s in sizes],
        "slip_rate": [r["slips"] / r["window"] for r in runs],
        "avalanche_rate": [s.size / r["window"] for s, r in zip(sizes, runs, strict=True)],
        "moving_fraction": [r["moving"] for r in runs],
    }
    out: dict[str, Any] = {"realizations": len(runs), "avalanches": int(sum(s.size for s in sizes)),
                           "density": density.tolist(), "density_sem": density_sem.tolist(),
                           "tau_S": tau_s, "tau_S_sem": tau_s_sem}
    for key, values in per.items():
        out[key], out[key + "_sem"] = mean_sem(values)
    out["largest_size_max"] = int(max(per["largest_size"]))
    if "unfinished" in runs[0]:
        out["unfinished"] = [r["unfinished"] for r in runs]
        out["gaps_below_tau_dyn"] = int(sum(r["gaps_below_tau_dyn"] for r in runs))
        out["starts_equal_slips"] = all(r["total_starts"] == r["total_slips"] for r in runs)
    return out


def _child(conn, scene: Scene, tau: float, seed_seq: np.random.SeedSequence, skip: float) -> None:
    conn.send(inertial_avalanches(scene, tau, seed_seq, skip))
    conn.close()


def inertial_with_limit(scene: Scene, tau: float, seed_seq: np.random.SeedSequence, skip: float,
                        limit: float) -> tuple[dict[str, Any] | None, float]:
    """:func:`inertial_avalanches` in a child process, stopped after ``limit`` seconds of wall time: its
    result (None if stopped) and the seconds it took."""
    ctx = mp.get_context("spawn")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(child, scene, tau, seed_seq, skip))
    t0 = time.perf_counter()
    proc.start()
    child.close()
    result = parent.recv() if parent.poll(limit) else None
    proc.join(1.0 if result is None else None)
    if proc.is_alive():
        proc.terminate()
        proc.join()
    return result, time.perf_counter() - t0


def study(args: argparse.Namespace) -> dict[str, Any]:
    """Every run of the study and its summary (the JSON written)."""
    scene = make_scene(args.n, args.sigma, args.ratio, args.steps)
    n_nodes = scene.network.n_nodes
    seeds = realization_seeds(args.seed, args.realizations)
    t0 = time.perf_counter()
    qs = [qs_avalanches(scene, s, args.skip) for s in seeds]
    qs_seconds = time.perf_counter() - t0
    results: dict[str, list[dict[str, Any]]] = {}
    seconds: dict[str, list[float]] = {}
    not_finished: dict[str, list[int]] = {}
    for tau in args.taus:
        key = f"{tau:g}"
        results[key], seconds[key], not_finished[key] = [], [], []
        for r, s in enumerate(seeds):
            res, sec = inertial_with_limit(scene, tau, s, args.skip, args.limit)
            seconds[key].append(sec)
            done = f"{sec:.1f} s" if res else f"not finished in {args.limit:g} s"
            print(f"tau {key} realization {r}: {done}", flush=True)
            if res is None:
                not_finished[key].append(r)
                break
            results[key].append(res)
    largest = max([int(r["sizes"].max()) for rs in [qs, *results.values()] for r in rs if r["sizes"].size] + [1])
    edges = log2_edges(largest)
    fit = (args.fit_min, args.fit_max)
    summary: dict[str, Any] = {"qs": summarize(qs, n_nodes, edges, fit)}
    qs_events = np.array([r["events"] for r in qs], dtype=np.float64)
    for key, runs in results.items():
        if not runs:
            summary[key] = {"realizations": 0}
            continue
        summary[key] = summarize(runs, n_nodes, edges, fit)
        # Driving events (the quasi-static run's, same theta(t), same window) per inertial avalanche.
        # NaN where no avalanche ended in the window (the network moved to the end).
        ratio = [q / r["sizes"].size if r["sizes"].size else math.nan
                 for q, r in zip(qs_events, runs, strict=False)]
        summary[key]["events_per_avalanche"], summary[key]["events_per_avalanche_sem"] = mean_sem(ratio)
    for key in results:
        summary[key]["seconds"] = seconds[key]
        summary[key]["not_finished"] = not_finished[key]
    summary["qs"]["seconds"] = qs_seconds
    return {"settings": {k: v for k, v in vars(args).items() if k not in ("json", "figure")},
            "n_nodes": n_nodes, "edges": edges.tolist(), "fit_range": list(fit), "summary": summary,
            "machine": {"cpus": os.cpu_count(), "load_average": os.getloadavg(),
                        "python": platform.python_version()}}


def figure(data: dict[str, Any], path: str) -> None:
    """P(S) of each solver, log-log, with its standard error, and the fitted range marked."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    edges = np.asarray(data["edges"])
    centre = np.sqrt(edges[:-1] * edges[1:])
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for key, s in data["summary"].items():
        label = "quasi-static" if key == "qs" else f"inertial, $\\tau_{{dyn}}/\\tau_{{th}}$ = {key}"
        if s.get("avalanches", 0) < MIN_CURVE:
            # A handful of ended motions is no distribution: named in the legend, not drawn.
            ax.plot([], [], " ", label=f"{label}: {s.get('avalanches', 0)} avalanches ended, not drawn")
            continue
        d, e = np.asarray(s["density"]), np.asarray(s["density_sem"])
        keep = d > 0
        label += f" ($\\tau_S$ = {s['tau_S']:.2f} ± {s['tau_S_sem']:.2f})"
        e = np.nan_to_num(e[keep])
        # The lower bar clipped above zero: a log axis cannot show a bar that reaches it.
        ax.errorbar(centre[keep], d[keep], yerr=[np.minimum(e, 0.9 * d[keep]), e], marker="o", ms=3, capsize=2,
                    label=label)
    ax.axvspan(*data["fit_range"], color="0.9", zorder=0)
    ax.axvline(data["n_nodes"], color="0.5", ls=":", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("avalanche size S (slips; inertial: starts from rest to rest)")
    ax.set_ylabel("P(S)")
    ax.set_title(f"irregular network of {data['n_nodes']}, {data['settings']['realizations']} realizations",
                 fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=1024, help="nodes of the irregular network")
    p.add_argument("--sigma", type=float, default=1.0, help="sigma_theta / Ntilde")
    p.add_argument("--ratio", type=float, default=0.3, help="std(mu_s) / (mean(mu_s) - mu_d)")
    p.add_argument("--steps", type=int, default=20, help="thermal steps (tau_th) per run")
    p.add_argument("--skip", type=float, default=2.0,
                   help="avalanches starting before this time (tau_th) are left out")
    p.add_argument("--realizations", type=int, default=4)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--taus", type=float, nargs="+", default=[1e-4, 1e-3, 1e-2, 1e-1])
    p.add_argument("--fit-min", type=int, default=2)
    p.add_argument("--fit-max", type=int, default=64)
    p.add_argument("--limit", type=float, default=120.0, help="wall seconds per inertial run")
    p.add_argument("--quick", action="store_true", help="a smoke run: 32 nodes, 4 steps, 2 realizations")
    p.add_argument("--json", default=None)
    p.add_argument("--figure", default=None)
    args = p.parse_args(argv)
    if args.quick:
        args.n, args.steps, args.skip, args.realizations, args.fit_max, args.limit = 32, 4, 1.0, 2, 16, 60.0
        args.sigma, args.taus = 0.3, [1e-4, 1e-1]
    t0 = time.perf_counter()
    data = study(args)
    data["wall_seconds"] = time.perf_counter() - t0
    for key, s in data["summary"].items():
        if not s.get("realizations"):
            print(f"{key:>6}: no run finished")
            continue
        print(f"{key:>6}: R={s['realizations']} A={s['avalanches']} tau_S={s['tau_S']:.3f}±{s['tau_S_sem']:.3f} "
              f"<S>={s['mean_size']:.3g}±{s['mean_size_sem']:.2g} S_max={s['largest_size_max']} "
              f"spanning={s['spanning_fraction']:.3g} slips/tau_th={s['slip_rate']:.4g}±{s['slip_rate_sem']:.2g} "
              f"moving={s['moving_fraction']:.3g}"
              + (f" events/aval={s['events_per_avalanche']:.3g} unfinished={s['unfinished']}"
                 if key != "qs" else ""))
    print(f"wall {data['wall_seconds']:.0f} s")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(data, f, indent=1, default=float)
    if args.figure:
        figure(data, args.figure)


if __name__ == "__main__":
    main()
