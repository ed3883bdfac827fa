"""Does the network answer of "Aging in networks" survive the full equations of motion?

For the pair and free chains of 3 and 4 sliders at the study's base parameters
(mu_d = 0.5, Gaussian mu_s of mean 0.6 and std 0.01, ratio sigma_mu / (mu_s -
mu_d) = 0.1, Ntilde = 1e-7, gaussian_steps with sigma_theta / Ntilde = 1,
seed 1), R realizations are run to T tau_th, and mu_eff is measured at the
recorded times (log, 2 per decade: 0, 1, 3, 10, 32, 100, ...) three ways:

(i)   ``qs``: the quasi-static solver's own run (``slidernet.run``,
      ``mu_eff_realization``): quasi-static evolution, quasi-static tilt test;
(ii)  ``qs_tilt``: the quasi-static network tilt test
      (:func:`slidernet.kernels.tilt_net.tilt_test_network`, the kernel of
      ``Realization.tilt_test``) applied to the state of the full equations of
      motion (:class:`slidernet.validation.dynamics.Dynamics`, ``states=True``);
(iii) ``dyn_tilt``: the dynamic tilt test (``Dynamics.tilt_test``) applied to
      that same state; its loads at the first start of motion, when every
      slider first moved at once, and when sliding for good was proved are
      reported too.

Realization r uses ``realization_seeds(seed, R)[r]``, as ``slidernet.run``
does, so (i) and the dynamics share theta(t_q) and the initial thresholds. The
tilt tests on the dynamics' states draw their redrawn thresholds from streams
of their own, ``SeedSequence(seed, spawn_key=(r, 3 or 4, k))`` for record k
(keys (r, 0..2) are the realization's; (r, 3, k) the dynamic test's, (r, 4, k)
the quasi-static one's; (r, 5, k) its uniforms).

Statistics as in docs/guides/aging-networks.md: mean +- standard error over
realizations at t = 0, 1 and T; slope per decade from per-realization
least-squares slopes against ln t over 1 <= t <= T
(:func:`slidernet.analysis.trend.log_trend`), times ln 10.

Run from the repository root::

    PYTHONPATH=$PWD python benchmarks/aging_dynamics.py --realizations 16 --steps 30 --out aging_dynamics.json

(about 5 min on one core; T = 100 takes about three times longer). With ``--geometry irregular`` the
sizes are the study's irregular 2D networks (network seed 0, the base point's geometry 0), integrated
in 2D::

    PYTHONPATH=$PWD python benchmarks/aging_dynamics.py --geometry irregular --sizes 16 --steps 10 \
        --out aging_dynamics_2d_16.json

They cost far more: ~280 slips per tau_th at 16 sliders and ~14 ms of CPU each, so 16 realizations
to 30 tau_th take ~30 CPU-minutes at 16 sliders and several CPU-hours at 64. The JSON is written
after every realization with those done so far (``realizations_done``), so a run cut short keeps
them; ``--from-json`` prints its tables. ``--first``/``--stop`` run a range of the R realizations (same
seeds and streams as in the whole run) and ``--merge`` joins such runs into one, so the two cores of a
laptop can share a long run::

    PYTHONPATH=$PWD python benchmarks/aging_dynamics.py --geometry irregular --sizes 64 --realizations 16 \
        --steps 30 --first 0 --stop 8 --out part_a.json &
    PYTHONPATH=$PWD python benchmarks/aging_dynamics.py --geometry irregular --sizes 64 --realizations 16 \
        --steps 30 --first 8 --stop 16 --out part_b.json
    python benchmarks/aging_dynamics.py --merge part_a.json part_b.json --out aging_dynamics_2d_64.json

The merged statistics are those of the whole run (tested on chains of 3: every value the same).

``--rate-check R`` instead tests the states of the first R realizations at ten times and a tenth of
the ramp rate, the effect of the rate on the dynamic tilt test (``--rate-check 4 --sizes 3 4``: about 2 min).
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
import warnings
from typing import Any

import numpy as np
import xarray as xr

import slidernet
from slidernet import kernels
from slidernet.analysis.trend import log_trend, mean_sem
from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.errors import TiltTestError
from slidernet.kernels.tilt_net import N_LOADS, N_POS, N_SLIPS
from slidernet.plugins.distributions.stream import TruncatedStream
from slidernet.solver import Scene
from slidernet.solver.scene import tilt_avalanche_cap
from slidernet.validation.dynamics import TILT_RATE, Dynamics

NTILDE = 1e-7
MU_D = 0.5
# Spawn-key slots of the tilt tests' streams (after the realization's own 0, 1, 2).
KEY_DYN, KEY_QS, KEY_QS_U = 3, 4, 5


def config(n: int, steps: int, realizations: int, seed: int, geometry: str = "chain",
           network_seed: int = 0) -> dict[str, Any]:
    """The study's base point (examples/aging_networks.toml) for a chain of n (the pair kernel for n = 2)
    or, with ``geometry = "irregular"``, the study's irregular 2D network of n sliders built from
    ``network_seed`` (examples/aging_networks.py: geometry 0 of the base point has seed 1, network seed 0)."""
    network: dict[str, Any] = {"kind": "two_slider", "Ntilde": NTILDE}
    if geometry == "irregular":
        network = {"kind": "irregular", "n": n, "seed": network_seed, "Ntilde": NTILDE}
    elif n != 2:
        network = {"kind": "chain", "n": n, "Ntilde": NTILDE}
    return {
        "seed": seed, "realizations": realizations, "steps": steps, "record": "log", "log_points_per_decade": 2,
        "mu_eff_at": "records",
        "observables": ["n", "mu_max", "x_G", "mu_eff", "mu_eff_realization", "tilt_loads"],
        "friction": {"mu_d": MU_D, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "gaussian_steps", "sigma_theta": NTILDE},
        "network": network,
    }


def qs_tilt(scene: Scene, F: np.ndarray, mu_s: np.ndarray, seed: int, key: tuple[int, ...]) -> float:
    """The quasi-static network tilt test (Realization.tilt_test's kernel and rule) on a given state.

    F: forces on the nodes before the tilt, shape (N,) in 1D or (N, 2) in 2D, in N; mu_s: thresholds,
    shape (N,). Redrawn
    thresholds come from ``TruncatedStream(scene's law, SeedSequence(seed, spawn_key=key + (KEY_QS,)))``
    and the pair rule's uniforms from ``key + (KEY_QS_U,)`` (keys rearranged below as (r, slot, k)).
    """
    N = mu_s.size
    o = scene.tilt_operators()
    r, k = key
    size = 256
    while True:
        # Fresh streams on every try: the values are prefix-consistent, so a longer buffer only adds values.
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(r, KEY_QS, k)))
        stream = TruncatedStream(scene.distribution, rng)
        uniforms = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(r, KEY_QS_U, k))).random(size)
        G = np.zeros((N, 2))
        G[:, :F.size // N] = F.reshape(N, -1)
        pos = np.zeros(N_POS, np.int64)
        loads = np.zeros(N_LOADS)
        f = o.test(G, mu_s.copy(), o.f_ext, o.f_bar, o.net, scene.settings(), o.pair_rule,
                   stream.take(size), uniforms, pos, tilt_avalanche_cap(N), kernels.Heaps.empty(2, N),
                   np.zeros(N, np.int64), np.zeros(N, np.int64), loads)
        status = kernels.tilt_status(f)
        if status == kernels.DONE:
            return float(f)
        if status != kernels.NEED_TILT:
            raise TiltTestError(f"quasi-static tilt test gave up after {int(pos[N_SLIPS])} slips")
        size *= 4


def summary(values: np.ndarray, t: np.ndarray, T: int) -> dict[str, Any]:
    """Mean +- SE over realizations at t = 0, 1, 3, 10, 30 and T (those recorded), and the slope per
    decade (log_trend over 1 <= t <= T, when it has two times or more) with its SE.

    values: shape (R, len(t)).
    """
    def at(time: int) -> tuple[float, float]:
        return mean_sem(values[:, int(np.flatnonzero(t == time)[0])])[:2]

    out: dict[str, Any] = {f"t{time}": at(time) for time in (0, 1, 3, 10, 30, T) if time in t}
    out["slope_per_decade"] = (math.nan, math.nan)
    out["realizations_fitted"] = 0
    if np.sum(t >= 1) >= 2:
        trend = log_trend(xr.DataArray(values, dims=("realization", "t"), coords={"t": t.astype(float)}))
        ln10 = math.log(10.0)
        out["slope_per_decade"] = (float(trend["slope_mean"]) * ln10, float(trend["slope_sem"]) * ln10)
        out["realizations_fitted"] = int(trend["realizations"])
    out["values"] = values.tolist()
    return out


def measure(n: int, args: argparse.Namespace, done: list[dict[str, Any]] | None = None) -> dict[str, Any]:
    """The three-way comparison at size n, on realizations ``args.first`` to ``args.stop`` of R (all by
    default). After each realization the JSON is written with the realizations done so far (the sizes in
    ``done`` first), so a run cut short keeps them."""
    R, T, seed = args.realizations, args.steps, args.seed
    rows = list(range(args.first, min(args.stop or R, R)))
    cfg = config(n, T, R, seed, args.geometry, args.network_seed)
    clock = time.perf_counter()
    ds = slidernet.run(cfg)
    qs_seconds = time.perf_counter() - clock
    t = ds["t"].values.astype(np.int64)

    def by_realization(name: str) -> np.ndarray:
        return ds[name].transpose("realization", ...).values[rows]

    arrays = {"qs": by_realization("mu_eff_realization"), "qs_first_slip": by_realization("tilt_first_slip"),
              "qs_all_moving": by_realization("tilt_all_moving")}
    qs_slips = by_realization("n")[:, -1]

    scene = Scene.from_config(load_config(cfg))
    dyn = Dynamics(scene, tau_ratio=args.tau_ratio, max_step=args.max_step)
    seeds = realization_seeds(seed, R)
    keys = ("qs_tilt", "dyn_tilt", "dyn_first_start", "dyn_all_moving", "dyn_certified", "dyn_starts")
    vals = {key: np.full((len(rows), t.size), np.nan) for key in keys}
    slips = np.zeros(len(rows), np.int64)
    clock = time.perf_counter()
    dyn_seconds = tilt_seconds = 0.0
    for i, r in enumerate(rows):
        c0 = time.perf_counter()
        out = dyn.run(seeds[r], states=True)
        c1 = time.perf_counter()
        dyn_seconds += c1 - c0
        assert np.array_equal(out["t"], t)
        slips[i] = out["n"][-1]
        for k in range(t.size):
            # A node still moving at a record (rare: records fall between thermal segments) is tested
            # where it is, at rest.
            vals["qs_tilt"][i, k] = qs_tilt(scene, out["F"][k], out["mu_s"][k], seed, (r, k))
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(r, KEY_DYN, k)))
            res = dyn.tilt_test(out["u"][k], out["mu_s"][k], rng, theta=float(out["theta"][k]), rate=args.rate)
            vals["dyn_tilt"][i, k] = res["mu_eff"]
            vals["dyn_first_start"][i, k] = res["first_start"]
            vals["dyn_all_moving"][i, k] = res["all_moving"]
            vals["dyn_certified"][i, k] = res["certified"]
            vals["dyn_starts"][i, k] = res["starts"]
        tilt_seconds += time.perf_counter() - c1
        if args.progress:
            elapsed = time.perf_counter() - clock
            print(f"  n={n} r={r} slips={slips[i]} {elapsed:.1f} s", file=sys.stderr, flush=True)
        with warnings.catch_warnings():
            # One realization has no standard error yet (NaN, said by numpy); the JSON keeps its values.
            warnings.simplefilter("ignore", RuntimeWarning)
            part = reduce(n, args, t, {**{key: v[:i + 1] for key, v in arrays.items()},
                                       **{key: v[:i + 1] for key, v in vals.items()}},
                          slips[:i + 1], qs_slips[:i + 1], rows[:i + 1],
                          {"qs_run": qs_seconds, "dynamics": dyn_seconds, "tilt_tests": tilt_seconds})
        if i < len(rows) - 1:
            write(args, [*(done or []), part], time.perf_counter() - args.start)
    return part


def reduce(n: int, args: argparse.Namespace, t: np.ndarray, values: dict[str, np.ndarray], slips: np.ndarray,
           qs_slips: np.ndarray, realizations: list[int], seconds: dict[str, float]) -> dict[str, Any]:
    """The statistics of the given realizations: ``values`` maps each estimator to its values, shape
    (len(realizations), len(t)), realization by realization ((i) paired with the dynamics' same realization);
    ``slips`` and ``qs_slips`` are each realization's slips to T under the dynamics and in (i)."""
    T = args.steps
    result: dict[str, Any] = {
        "n": n, "geometry": args.geometry, "t": t.tolist(), "realizations_done": len(realizations),
        "realizations": list(realizations), "seconds": seconds,
        "dynamics_slips": slips.tolist(), "qs_slips": qs_slips.tolist(),
        "dynamics_slips_per_tau_th": float(slips.mean() / T),
        "qs_slips_per_tau_th": float(qs_slips.mean() / T),
    }
    for key, v in values.items():
        result[key] = summary(v, t, T)
    # The certified load exceeds mu_eff by the ramp during the final motion; the largest excess over all tests.
    result["max_certified_minus_mu_eff"] = float(np.nanmax(values["dyn_certified"] - values["dyn_tilt"]))
    result["dyn_tilt_below_mu_d"] = int(np.sum(values["dyn_tilt"] <= MU_D))
    result["dyn_all_moving_below_mu_d"] = int(np.sum(values["dyn_all_moving"] < MU_D))
    result["compare"] = compare(result)
    return result


def merge(paths: list[str], args: argparse.Namespace) -> dict[str, Any]:
    """One document from runs of the same study on disjoint realizations (``--first``/``--stop``): per size,
    the realizations in their order, the statistics recomputed over all of them, the seconds summed."""
    docs = []
    for path in paths:
        with open(path) as fh:
            docs.append(json.load(fh))
    same = ("realizations", "steps", "seed", "geometry", "network_seed", "tau_ratio", "max_step", "rate")
    for doc in docs[1:]:
        for key in same:
            if doc["parameters"][key] != docs[0]["parameters"][key]:
                raise SystemExit(f"cannot merge: the '{key}' parameter differs ({doc['parameters'][key]!r} "
                                 f"against {docs[0]['parameters'][key]!r})")
    for key in same:
        setattr(args, key, docs[0]["parameters"][key])
    results = []
    for n in dict.fromkeys(res["n"] for doc in docs for res in doc["results"]):
        parts = sorted((res for doc in docs for res in doc["results"] if res["n"] == n),
                       key=lambda res: res["realizations"][0])
        rows = [r for res in parts for r in res["realizations"]]
        if len(set(rows)) != len(rows):
            raise SystemExit(f"cannot merge: size {n} has realizations run twice")
        keys = [key for key in parts[0] if isinstance(parts[0][key], dict) and "values" in parts[0][key]]
        values = {key: np.concatenate([np.array(res[key]["values"]) for res in parts]) for key in keys}
        seconds = {key: sum(res["seconds"][key] for res in parts) for key in parts[0]["seconds"]}
        results.append(reduce(n, args, np.array(parts[0]["t"]), values,
                              np.concatenate([res["dynamics_slips"] for res in parts]),
                              np.concatenate([res["qs_slips"] for res in parts]), rows, seconds))
    return {**docs[0], "command": " ".join(sys.argv), "merged_from": paths,
            "wall_seconds": max(doc["wall_seconds"] for doc in docs), "results": results}


def rate_check(n: int, args: argparse.Namespace) -> dict[str, Any]:
    """The ramp-rate effect: the dynamics' states of the first R realizations tested at rate x 10 and rate / 10.

    Each state is tested three times from the same redraw stream (spawn key (r, 3, k)); the differences
    of mu_eff, all_moving and certified against the test at ``rate``: each realization's mean over its
    records, then mean +- SE over the R realizations, and the largest |difference| of any test.
    """
    cfg = config(n, args.steps, args.realizations, args.seed, args.geometry, args.network_seed)
    dyn = Dynamics(Scene.from_config(load_config(cfg)), tau_ratio=args.tau_ratio, max_step=args.max_step)
    seeds = realization_seeds(args.seed, args.realizations)
    rates = (10 * args.rate, args.rate, args.rate / 10)
    rows = []
    for r in range(args.rate_check):
        out = dyn.run(seeds[r], states=True)
        per_record = []
        for k in range(out["t"].size):
            row = []
            for rate in rates:
                rng = np.random.default_rng(np.random.SeedSequence(args.seed, spawn_key=(r, KEY_DYN, k)))
                res = dyn.tilt_test(out["u"][k], out["mu_s"][k], rng, theta=float(out["theta"][k]), rate=rate)
                row.append([res["mu_eff"], res["all_moving"], res["certified"]])
            per_record.append(row)
        rows.append(per_record)
    a = np.array(rows)  # (realization, record, rate, load)
    result: dict[str, Any] = {"n": n, "rates": rates, "tests": int(a.shape[0] * a.shape[1]), "values": a.tolist()}
    for j, load in enumerate(("mu_eff", "all_moving", "certified")):
        for i, label in ((0, "x10"), (2, "/10")):
            d = a[:, :, i, j] - a[:, :, 1, j]
            # The records of one realization are not independent: average within it first.
            mean, sem, _ = mean_sem(d.mean(axis=1))
            result[f"{load} {label}"] = (mean, sem, float(np.abs(d).max()))
    return result


def compare(res: dict[str, Any]) -> dict[str, Any]:
    """Paired comparisons on the same realizations, and what the dynamic tilt test's motion did.

    Differences of two estimators, realization by realization: at each recorded time, and averaged over
    the times t >= 1 within each realization first (the times of one realization are not independent),
    then mean +- standard error over realizations. Counts over the tests at t >= 1: collective motions
    (every node moving at once) that stopped before the network slid (all_moving < mu_eff, as f only
    rises), split by their load against mu_d.
    """
    t = np.array(res["t"])
    late = t >= 1
    v = {key: np.array(res[key]["values"]) for key in ("qs", "qs_tilt", "dyn_tilt", "dyn_all_moving")}
    out: dict[str, Any] = {}
    for a, b in (("dyn_tilt", "qs_tilt"), ("dyn_tilt", "qs"), ("qs_tilt", "qs")):
        diff = v[a] - v[b]
        R = diff.shape[0]
        per_t = {int(time): (float(diff[:, k].mean()), float(diff[:, k].std(ddof=1) / math.sqrt(R)))
                 for k, time in enumerate(t)}
        pooled = diff[:, late].mean(axis=1)
        out[f"{a}-{b}"] = {"per_t": per_t,
                           "mean_t_ge_1": (float(pooled.mean()), float(pooled.std(ddof=1) / math.sqrt(R)))}
    mu_eff, moving = v["dyn_tilt"][:, late], v["dyn_all_moving"][:, late]
    stopped = moving < mu_eff
    out["tests_t_ge_1"] = int(mu_eff.size)
    out["collective_stopped_below_mu_d"] = int(np.sum(stopped & (moving < MU_D)))
    out["collective_stopped_above_mu_d"] = int(np.sum(stopped & (moving >= MU_D)))
    out["collective_first_in_final_motion"] = int(np.sum(~stopped))
    out["min_dyn_mu_eff"] = float(np.min(v["dyn_tilt"]))
    return out


def fmt(pair: tuple[float, float], digits: int = 4) -> str:
    return f"{pair[0]:.{digits}f} ± {pair[1]:.{digits}f}"


def table(results: list[dict[str, Any]], T: int) -> str:
    times = [time for time in (0, 1, 3, 10, 30, T) if f"t{time}" in results[0]["qs"]]
    times = sorted(set(times))
    rows = ["| N | estimator | " + " | ".join(f"μ_eff({time})" for time in times) + " | dμ_eff/dlog10 t (1e−4) |",
            "|---|---|" + "---|" * len(times) + "---|"]
    names = {"qs": "(i) QS run", "qs_tilt": "(ii) QS tilt on dyn. state", "dyn_tilt": "(iii) dynamic tilt",
             "dyn_first_start": "(iii) first start", "dyn_all_moving": "(iii) all moving",
             "dyn_certified": "(iii) certified", "qs_first_slip": "(i) first slip",
             "qs_all_moving": "(i) all moving"}
    for res in results:
        for key, name in names.items():
            s = res[key]
            slope = s["slope_per_decade"]
            cells = " | ".join(fmt(s[f"t{time}"]) for time in times)
            rows.append(f"| {res['n']} | {name} | {cells} | {slope[0] * 1e4:+.1f} ± {slope[1] * 1e4:.1f} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--realizations", type=int, default=16)
    parser.add_argument("--steps", type=int, default=100, help="T, in tau_th")
    parser.add_argument("--tau-ratio", type=float, default=1e-4, help="tau_dyn / tau_th")
    parser.add_argument("--max-step", type=float, default=0.05, help="Dynamics' max_step, tau_dyn")
    parser.add_argument("--rate", type=float, default=TILT_RATE, help="dynamic tilt ramp, per tau_dyn")
    parser.add_argument("--sizes", type=int, nargs="+", default=[2, 3, 4])
    parser.add_argument("--geometry", choices=("chain", "irregular"), default="chain",
                        help="chains (1D; the pair for size 2) or the study's irregular 2D networks")
    parser.add_argument("--network-seed", type=int, default=0, help="the irregular network's seed")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", default="aging_dynamics.json")
    parser.add_argument("--progress", action="store_true")
    parser.add_argument("--from-json", metavar="PATH", help="print the tables of a saved run again; no run")
    parser.add_argument("--first", type=int, default=0, help="run realizations first to stop - 1 of R only")
    parser.add_argument("--stop", type=int, default=0, help="(0: R) see --first")
    parser.add_argument("--merge", metavar="PATH", nargs="+",
                        help="merge runs on disjoint realizations into --out and print the tables; no run")
    parser.add_argument("--rate-check", type=int, default=0, metavar="R",
                        help="instead of the study: test the states of R realizations at rate x 10 and / 10")
    args = parser.parse_args(argv)
    if args.rate_check:
        start = time.perf_counter()
        checks = [rate_check(n, args) for n in args.sizes]
        with open(args.out, "w") as fh:
            json.dump({"parameters": vars(args), "command": " ".join(sys.argv), "results": checks,
                       "wall_seconds": time.perf_counter() - start}, fh, indent=1)
        print("| N | load | rate x 10 − rate | rate / 10 − rate | tests |")
        print("|---|---|---|---|---|")
        for c in checks:
            for load in ("mu_eff", "all_moving", "certified"):
                up, down = c[f"{load} x10"], c[f"{load} /10"]
                print(f"| {c['n']} | {load} | {up[0]:+.1e} ± {up[1]:.1e} (max {up[2]:.1e}) "
                      f"| {down[0]:+.1e} ± {down[1]:.1e} (max {down[2]:.1e}) | {c['tests']} |")
        print(f"wall {time.perf_counter() - start:.1f} s")
        return
    if args.merge:
        doc = merge(args.merge, args)
        with open(args.out, "w") as fh:
            json.dump(doc, fh, indent=1)
        report(doc)
        return
    if args.from_json:
        with open(args.from_json) as fh:
            doc = json.load(fh)
        for res in doc["results"]:
            res["compare"] = compare(res)
        report(doc)
        return
    start = args.start = time.perf_counter()
    results: list[dict[str, Any]] = []
    for n in args.sizes:
        results.append(measure(n, args, results))
        wall = time.perf_counter() - start
        doc = write(args, results, wall)
    report(doc)


def write(args: argparse.Namespace, results: list[dict[str, Any]], wall: float) -> dict[str, Any]:
    """Write the JSON of the sizes done so far (after each size: a long run keeps what it has)."""
    doc = {"parameters": {**vars(args), "mu_d": MU_D, "mu_s_mean": 0.6, "mu_s_std": 0.01, "Ntilde": NTILDE,
                          "sigma_theta": NTILDE, "record": "log", "log_points_per_decade": 2},
           "command": " ".join(sys.argv), "wall_seconds": wall, "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
           "python": platform.python_version(), "slidernet": slidernet.__version__, "results": results}
    with open(args.out, "w") as fh:
        json.dump(doc, fh, indent=1)
    return doc


def report(doc: dict[str, Any]) -> None:
    """Print the markdown tables of a run's JSON."""
    results = doc["results"]
    print(table(results, doc["parameters"]["steps"]))
    print()
    print("| N | (iii) − (ii) | (iii) − (i) | (ii) − (i) | collective motions that stopped, below / above μ_d "
          "| first collective motion in the final one | min (iii) |")
    print("|---|---|---|---|---|---|---|")
    for res in results:
        c = res["compare"]
        pairs = " | ".join(fmt(c[key]["mean_t_ge_1"]) for key in ("dyn_tilt-qs_tilt", "dyn_tilt-qs", "qs_tilt-qs"))
        stopped = f"{c['collective_stopped_below_mu_d']} / {c['collective_stopped_above_mu_d']}"
        print(f"| {res['n']} | {pairs} | {stopped} "
              f"| {c['collective_first_in_final_motion']} of {c['tests_t_ge_1']} | {c['min_dyn_mu_eff']:.4f} |")
    print()
    for res in results:
        print(f"N={res['n']}: slips/tau_th dynamics {res['dynamics_slips_per_tau_th']:.3g}, "
              f"QS {res['qs_slips_per_tau_th']:.3g}; "
              f"max(certified - mu_eff) {res['max_certified_minus_mu_eff']:.2e}; "
              f"dyn mu_eff <= mu_d in {res['dyn_tilt_below_mu_d']} tests; all moving below mu_d in "
              f"{res['dyn_all_moving_below_mu_d']}; seconds {res['seconds']}")
    print(f"wall {doc['wall_seconds']:.1f} s, {doc['date']}")


if __name__ == "__main__":
    main()
