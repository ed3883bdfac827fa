"""Seconds per network tilt test against network size, irregular networks and triangular lattices, one core.

    python benchmarks/tilt_cost.py [--sizes 100 1000 10000] [--lattices 10 32] [--realizations 8]
                                   [--tests 2] [--age 3] [--seed 1] [--core 0] [--max-avalanche S]
                                   [--overshoot E] [--min-slips M] [--min-displacement X] [--shs GAMMA]
                                   [--csv PATH] [--quick]

The network tilt test (:meth:`slidernet.solver.Realization.tilt_test`, kernel
:mod:`slidernet.kernels.tilt_net`; the observable ``mu_eff`` makes one at
every recorded time) raises a uniform tangential force on every node until
the whole network slides. This script measures what one test costs as the
network grows.

For each irregular (Delaunay) network of ``--sizes`` nodes (network seed 0)
and each triangular ``L x L`` lattice of ``--lattices``, at Ntilde = 1e-7,
mu_d = 0.5, Gaussian mu_s (mean 0.6, std 0.01) and the ``gaussian_steps``
driver with sigma_theta = 1e-7 (sigma_theta / Ntilde = 1), it builds one
scene and ``--realizations`` independent realizations (child r of
``SeedSequence(--seed)``, as ``slidernet.run`` seeds them). Each realization
is advanced to step 1, then one thermal step at a time to step ``--age``
(each of these steps timed: the kernel time of one thermal step), then
``--tests`` tilt tests are made on its state, each timed with
``time.perf_counter`` around ``real.tilt_test()``. The test works on a copy of
the state, so the tests of a realization test the same state with different
draws of the tilt stream.

Every figure is first averaged within a realization (its tests, its thermal
steps), then given as the mean over realizations +- its standard error
(``slidernet.analysis.trend.mean_sem``): the realizations are independent,
the tests of one realization are not (same state). The figures:

* seconds per test, as a user pays it: the call includes the refills of a
  test that ran out of tilt draws (the threshold buffer starts at
  ``solver.batch`` values and doubles; a test that runs out goes on where
  it stood, ``Streams.extend_tilt``; before commit f52d954 it started again
  from its beginning, and the first test of a realization paid for growing
  the buffers);
* the same per node (microseconds);
* slips per test: the thresholds the test drew from the tilt stream
  (one per slip, read from the public ``Realization.buffers`` and
  ``Realization.state["tilt_mu_pos"]``), plus the slip that sets the network
  sliding, which draws none; per node as well;
* the slip rate of the tests (slips / seconds, per realization), apart for
  the tests that did not refill the draw buffers and for those that did
  (before f52d954 they ran again from the start at least once; the slips
  counted are those of the run that slid), with the share of tests that
  refilled. The scenes record no ``mu_eff``, so a realization's tilt
  buffers start empty and its first test refills at its first slip, then
  again each time it outgrows them;
* the seconds of one thermal step of the same realizations and the ratio
  test / step (per realization, then averaged);
* mu_eff, the test's result, for reference.

Before the table, a line per size gives the fewest, the median and the
most slips per test over the realizations (each a realization's mean), the
largest ratio of the most to the fewest slips among the tests of one
realization, the scene's setup time, the largest tilt draw buffers of a realization after
its tests (``Realization.buffers``: thresholds and uniforms), the process's
peak resident memory so far and the CPU share of the tests (CPU over wall
seconds; below 1 where another process took the core).

Below the table: for each kind of network with two sizes or more, the
exponents alpha of cost ~ N^alpha (seconds per test and slips per test),
between consecutive sizes (error propagated from the two standard errors)
and from a weighted least-squares fit of log cost against log N (error from
the standard errors alone, with the fit's chi^2 per degree of freedom).

The process is pinned to one core (``--core``, default 0) with
``os.sched_setaffinity``; the compiled kernels are loaded on tiny scenes
first, untimed. A test that does not reach sliding (``TiltTestError``, after
``solver.max_avalanche`` slips: 1e8 by default, ``--max-avalanche`` changes
it) is counted and timed, and left out of the means: where one is, the
means are those of the tests that slid, below the mean of all (the test left
out cost at least ``solver.max_avalanche`` slips). ``--quick`` is a smoke
run of a few seconds (irregular 100 and 1000 nodes, lattice 10 x 10, 4
realizations of one test each, age 2). ``--csv PATH`` writes one line per
size with the numbers unformatted.

The sliding rule and the slip rule are those of the configuration keys:
``--overshoot E`` is ``friction.overshoot`` (default: the paper's e = 1),
``--min-slips M`` and ``--min-displacement X`` are ``[tilt] min_slips`` and
``min_displacement`` (defaults 1 and 0, the rule of every earlier result).
A stricter rule costs more slips per test; run the script once per rule to
compare (the rule is printed in the first line). A configuration with a
``[tilt]`` table must ask for ``mu_eff``, so with ``--min-slips`` or
``--min-displacement`` the scenes record ``mu_eff`` at t = 0: one untimed
test of the fresh state, which also fills part of the tilt draw buffers.

``--shs GAMMA`` times the slide-hold-slide pull instead
(:meth:`slidernet.solver.Realization.shs_test`, the observable ``mu_shs``
with ``[shs] stiffness = GAMMA``): the same body as the tilt test, pulled
through springs until every node has slipped. Its scenes record ``mu_shs``
at t = 0 (one untimed pull) and run to ``--age`` + 1 steps, so that no
timed thermal step holds a pull; its slips are counted from the ``shs``
draws as the test's are from the tilt draws, and its result, ``mu_shs``,
stands in the column of mu_eff.
"""

from __future__ import annotations

import argparse
import csv
import itertools
import math
import os
import resource
import time
from pathlib import Path
from typing import Any

import numpy as np

from slidernet.analysis.trend import mean_sem
from slidernet.config import load_config
from slidernet.errors import TiltTestError
from slidernet.solver import Realization, Scene

FRICTION = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
NTILDE = 1e-7
SIGMA_THETA = 1e-7

#: Per-realization figures averaged over realizations, in table order: (key, CSV/label name).
FIGURES = ("test_s", "test_us_per_node", "slips", "slips_per_node", "rate_plain", "rate_refilled", "refilled",
           "step_s", "test_per_step", "mu_eff")


def network_table(kind: str, size: int) -> dict[str, Any]:
    """The ``[network]`` table of an irregular network of ``size`` nodes or a triangular ``size x size`` lattice.

    Parameters
    ----------
    kind : {"irregular", "triangular"}
        The network's kind.
    size : int
        Nodes (irregular) or the lattice's side L (triangular).

    Returns
    -------
    dict
        The table, with Ntilde; irregular networks use network seed 0.
    """
    if kind == "irregular":
        return {"kind": "irregular", "n": size, "seed": 0, "Ntilde": NTILDE}
    return {"kind": "triangular", "shape": [size, size], "Ntilde": NTILDE}


def run_config(network: dict[str, Any], age: int, max_avalanche: int | None,
               rule: dict[str, float] | None = None) -> dict[str, Any]:
    """The configuration of the scene: ``age`` thermal steps, no observable that makes tilt tests itself.

    Parameters
    ----------
    network : dict
        The ``[network]`` table (:func:`network_table`).
    age : int
        Thermal steps of the realizations.
    max_avalanche : int or None
        ``solver.max_avalanche`` (also the tilt test's cap on slips); None: the default.
    rule : dict, optional
        ``overshoot``, ``min_slips``, ``min_displacement`` (any of them; None
        values left out): ``friction.overshoot`` and the ``[tilt]`` table;
        ``shs``: the slide-hold-slide pull's stiffness (its observable, and
        ``age`` + 1 steps).

    Returns
    -------
    dict
        A configuration for :func:`slidernet.config.load_config`.
    """
    cfg: dict[str, Any] = {
        "steps": age, "record": [0, age], "observables": ["n"],
        "network": network, "friction": FRICTION,
        "driver": {"name": "gaussian_steps", "sigma_theta": SIGMA_THETA},
    }
    if max_avalanche is not None:
        cfg["solver"] = {"max_avalanche": max_avalanche}
    rule = {k: v for k, v in (rule or {}).items() if v is not None}
    if "shs" in rule:
        # A pull at t = 0 only (untimed); the last recorded time, always one, after the timed steps.
        cfg.update(observables=["n", "mu_shs"], shs={"stiffness": rule.pop("shs")}, steps=age + 1, record=[0])
    if "overshoot" in rule:
        cfg["friction"] = FRICTION | {"overshoot": rule.pop("overshoot")}
    if rule:
        # The [tilt] table is refused without mu_eff, whose rule it sets: the scene then records mu_eff at
        # t = 0 only, one untimed test of the fresh state before the timed ones.
        cfg["tilt"] = rule
        cfg["observables"] = ["n", "mu_eff"]
        cfg["record"] = [0]
    return cfg


def warm_up() -> None:
    """Load the compiled kernels (thermal steps, tilt test, pull) on tiny scenes of both kinds, untimed."""
    for network in (network_table("irregular", 16), network_table("triangular", 4)):
        real = Realization(Scene.from_config(load_config(run_config(network, 2, None, {"shs": 1.0}))),
                           np.random.SeedSequence(0))
        real.advance(2)
        real.tilt_test()
        real.shs_test()


def _tilt_read(real: Realization, shs: bool = False) -> tuple[np.ndarray, int]:
    """The tilt (or shs) stream's threshold buffer and the read position in it (public attributes)."""
    name = "shs_mu" if shs else "tilt_mu"
    return getattr(real.buffers, name), int(real.state[f"{name}_pos"][0])


def timed_test(real: Realization, shs: bool = False) -> dict[str, Any]:
    """One tilt test of ``real``'s state, timed (with ``shs``, one slide-hold-slide pull).

    Parameters
    ----------
    real : Realization
        The realization; its state is left as it was.
    shs : bool
        Time :meth:`Realization.shs_test` instead; its ``mu_shs`` is returned as ``mu_eff``.

    Returns
    -------
    dict
        ``seconds`` (wall), ``cpu`` (process CPU seconds), ``mu_eff`` (NaN if
        the test did not reach sliding), ``slips`` (0 then), ``slid`` and
        ``refilled`` (the test ran out of tilt draws at least once; always
        True for a test that did not slide).

    Notes
    -----
    The slips are the thresholds read from the tilt stream, plus one. The
    test reads one per slip except the slip that sets the network sliding,
    and its read position advances only when it returns a sample; a test
    that ran out of draws got a new buffer (from the test's first draw on,
    then new draws), read from 0.
    """
    buf0, pos0 = _tilt_read(real, shs)
    c0, t0 = time.process_time(), time.perf_counter()
    try:
        mu_eff = real.shs_test()[0] if shs else real.tilt_test()
    except TiltTestError:
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
        return {"seconds": seconds, "cpu": cpu, "mu_eff": math.nan, "slips": 0, "slid": False, "refilled": True}
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    buf1, pos1 = _tilt_read(real, shs)
    refilled = buf1 is not buf0  # a refill gives a new buffer, read from 0
    read = pos1 if refilled else pos1 - pos0
    return {"seconds": seconds, "cpu": cpu, "mu_eff": mu_eff, "slips": read + 1, "slid": True,
            "refilled": refilled}


def _rate(done: list[dict[str, Any]]) -> float:
    """Slips per second over the tests ``done`` (NaN without any)."""
    return sum(d["slips"] for d in done) / sum(d["seconds"] for d in done) if done else math.nan


def measure(kind: str, size: int, realizations: int, tests: int, age: int, seed: int,
            max_avalanche: int | None, rule: dict[str, float] | None = None) -> dict[str, Any]:
    """Tilt tests and thermal steps of ``realizations`` realizations of one network.

    Parameters
    ----------
    kind : {"irregular", "triangular"}
        The network's kind.
    size : int
        Nodes (irregular) or the lattice's side (triangular).
    realizations : int
        Independent realizations (children of ``SeedSequence(seed)``).
    tests : int
        Tilt tests per realization, all of the state at step ``age``.
    age : int
        Thermal steps before the tests (at least 2: steps 2 to ``age`` are timed).
    seed : int
        The root seed.
    max_avalanche : int or None
        ``solver.max_avalanche``; None: the default.
    rule : dict, optional
        The slip and sliding rules (:func:`run_config`); None: the defaults.

    Returns
    -------
    dict
        ``N``, ``per_realization`` (a dict of arrays, one value per
        realization, NaN where no test of it slid), ``within`` (the largest
        ratio of the most to the fewest slips among the tests of one
        realization; 0 with fewer than two tests), ``failed`` (tests that did
        not reach sliding) and ``failed_s`` (their seconds), ``tests``,
        ``cpu_share`` (CPU over wall seconds of all the tests), ``setup_s``
        (building the scene), ``buffer_MB`` (the largest tilt draw buffers of
        a realization after its tests) and ``peak_GB`` (the process's peak
        resident memory so far).
    """
    t0 = time.perf_counter()
    scene = Scene.from_config(load_config(run_config(network_table(kind, size), age, max_avalanche, rule)))
    setup = time.perf_counter() - t0
    N = scene.network.n_nodes
    per: dict[str, list[float]] = {k: [] for k in FIGURES}
    failed, failed_s, wall, cpu, buffer_MB, within = 0, 0.0, 0.0, 0.0, 0.0, 0.0
    for ss in np.random.SeedSequence(seed).spawn(realizations):
        real = Realization(scene, ss)
        real.advance(1)
        steps = []
        for q in range(2, age + 1):
            t1 = time.perf_counter()
            real.advance(q)
            steps.append(time.perf_counter() - t1)
        done = [timed_test(real, (rule or {}).get("shs") is not None) for _ in range(tests)]
        wall += sum(d["seconds"] for d in done)
        cpu += sum(d["cpu"] for d in done)
        slid = [d for d in done if d["slid"]]
        failed += len(done) - len(slid)
        failed_s += sum(d["seconds"] for d in done if not d["slid"])
        if len(slid) > 1:
            within = max(within, max(d["slips"] for d in slid) / min(d["slips"] for d in slid))
        b = real.buffers
        buffer_MB = max(buffer_MB, (b.tilt_mu.nbytes + b.tilt_u.nbytes) / 1e6)
        step_s = float(np.mean(steps))
        test_s, slips, mu_eff = (float(np.mean([d[k] for d in slid])) if slid else math.nan
                                 for k in ("seconds", "slips", "mu_eff"))
        values = {"test_s": test_s, "test_us_per_node": test_s / N * 1e6, "slips": slips,
                  "slips_per_node": slips / N, "rate_plain": _rate([d for d in slid if not d["refilled"]]),
                  "rate_refilled": _rate([d for d in slid if d["refilled"]]),
                  "refilled": float(np.mean([d["refilled"] for d in slid])) if slid else math.nan,
                  "step_s": step_s, "test_per_step": test_s / step_s, "mu_eff": mu_eff}
        for k in FIGURES:
            per[k].append(values[k])
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6  # kB on Linux
    return {"kind": kind, "size": size, "N": N, "realizations": realizations, "tests": tests,
            "per_realization": {k: np.array(v) for k, v in per.items()}, "within": within, "failed": failed,
            "failed_s": failed_s, "cpu_share": cpu / wall if wall > 0 else math.nan, "setup_s": setup,
            "buffer_MB": buffer_MB, "peak_GB": peak}


def summary(row: dict[str, Any]) -> dict[str, float]:
    """Mean and standard error over realizations of every figure of a :func:`measure` row.

    Parameters
    ----------
    row : dict
        A row of :func:`measure`.

    Returns
    -------
    dict
        ``<figure>``, ``<figure>_sem`` and ``<figure>_n`` (the realizations
        with a value: for the rates, those with such a test) for each figure,
        and ``n_used``: the realizations with a test that slid.
    """
    out: dict[str, float] = {}
    for k in FIGURES:
        out[k], out[f"{k}_sem"], out[f"{k}_n"] = mean_sem(row["per_realization"][k])
    out["n_used"] = out["test_s_n"]
    return out


def exponent_between(n1: int, m1: float, s1: float, n2: int, m2: float, s2: float) -> tuple[float, float]:
    """alpha of m ~ N^alpha between two sizes, and its error propagated from the two standard errors.

    Parameters
    ----------
    n1, n2 : int
        The sizes.
    m1, s1, m2, s2 : float
        The means and their standard errors at ``n1`` and ``n2``.

    Returns
    -------
    alpha, error : float
    """
    span = math.log(n2 / n1)
    return math.log(m2 / m1) / span, math.hypot(s1 / m1, s2 / m2) / span


def exponent_fit(N: np.ndarray, m: np.ndarray, s: np.ndarray) -> tuple[float, float, float]:
    """Weighted least-squares slope of log m against log N.

    Parameters
    ----------
    N, m, s : ndarray
        Sizes, means and standard errors (at least two sizes; all finite).

    Returns
    -------
    alpha, error, chi2_dof : float
        The slope, its error from the standard errors alone (not scaled by
        the fit's residuals) and the fit's chi^2 per degree of freedom (NaN
        with two sizes).
    """
    x, y, sy = np.log(N), np.log(m), s / m
    w = 1.0 / sy**2
    xm = np.sum(w * x) / np.sum(w)
    sxx = np.sum(w * (x - xm) ** 2)
    alpha = float(np.sum(w * (x - xm) * y) / sxx)
    b = np.sum(w * (y - alpha * x)) / np.sum(w)
    dof = x.size - 2
    chi2 = float(np.sum(w * (y - alpha * x - b) ** 2) / dof) if dof > 0 else math.nan
    return alpha, float(1.0 / math.sqrt(sxx)), chi2


def _pm(m: float, s: float) -> str:
    """``m ± s`` with two significant digits of ``s`` (``(m ± s)eK`` for large or small values)."""
    if math.isnan(m):
        return "-"
    if math.isnan(s) or s <= 0:
        return f"{m:.3g}"
    k = math.floor(math.log10(abs(m))) if m != 0 else 0
    scale = k if abs(k) >= 4 else 0
    m, s = m / 10.0**scale, s / 10.0**scale
    decimals = 1 - math.floor(math.log10(s))
    if decimals < 0:
        m, s, decimals = round(m, decimals), round(s, decimals), 0
    text = f"{m:.{decimals}f} ± {s:.{decimals}f}"
    return f"({text})e{scale}" if scale else text


def _share(m: float, s: float) -> str:
    """A share in [0, 1], as ``m ± s`` or with two decimals where every realization gave the same."""
    return f"{m:.2f}" if not math.isnan(m) and (math.isnan(s) or s == 0) else _pm(m, s)


def _label(row: dict[str, Any]) -> str:
    return "irregular" if row["kind"] == "irregular" else f"triangular {row['size']} x {row['size']}"


COLUMNS = ("network", "N", "realizations x tests", "s per test", "µs per test per node", "slips per test",
           "slips per test per node", "M slips/s: tests without a refill", "M slips/s: tests with a refill",
           "tests with a refill", "s per thermal step", "test / thermal step", "mu_eff", "did not slide")


def _rates(s: dict[str, float], key: str, realizations: int) -> str:
    """A rate in M slips/s, with the realizations it rests on where some had no such test."""
    text = _pm(s[key] / 1e6, s[f"{key}_sem"] / 1e6)
    n = s[f"{key}_n"]
    return text if n in (0, realizations) else f"{text} ({n} of {realizations})"


def markdown(rows: list[dict[str, Any]]) -> str:
    """The Markdown table of the rows, every figure as mean ± standard error over realizations.

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`measure`.

    Returns
    -------
    str
    """
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for row in rows:
        s = summary(row)
        cells = [
            _label(row), f"{row['N']:,}", f"{row['realizations']} x {row['tests']}",
            _pm(s["test_s"], s["test_s_sem"]), _pm(s["test_us_per_node"], s["test_us_per_node_sem"]),
            _pm(s["slips"], s["slips_sem"]), _pm(s["slips_per_node"], s["slips_per_node_sem"]),
            _rates(s, "rate_plain", row["realizations"]), _rates(s, "rate_refilled", row["realizations"]),
            _share(s["refilled"], s["refilled_sem"]), _pm(s["step_s"], s["step_s_sem"]),
            _pm(s["test_per_step"], s["test_per_step_sem"]), _pm(s["mu_eff"], s["mu_eff_sem"]),
            f"{row['failed']} ({row['failed_s']:.0f} s)" if row["failed"] else "0",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def exponents(rows: list[dict[str, Any]]) -> list[str]:
    """Lines giving alpha of cost ~ N^alpha for each kind of network with two sizes or more.

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`measure`.

    Returns
    -------
    list of str
    """
    lines = []
    for kind in ("irregular", "triangular"):
        got = sorted(((r["N"], summary(r)) for r in rows if r["kind"] == kind), key=lambda t: t[0])
        got = [(n, s) for n, s in got if s["n_used"] >= 2 and s["test_s"] > 0]
        if len(got) < 2:
            continue
        for key, what in (("test_s", "seconds per test"), ("slips", "slips per test")):
            steps = ", ".join(
                "{:,} to {:,}: {:.2f} ± {:.2f}".format(a[0], b[0], *exponent_between(
                    a[0], a[1][key], a[1][f"{key}_sem"], b[0], b[1][key], b[1][f"{key}_sem"]))
                for a, b in itertools.pairwise(got))
            alpha, err, chi2 = exponent_fit(np.array([n for n, _ in got], dtype=float),
                                            np.array([s[key] for _, s in got]),
                                            np.array([s[f"{key}_sem"] for _, s in got]))
            fit = f"fit over all {len(got)} sizes: {alpha:.2f} ± {err:.2f}" + (
                f" (chi^2/dof {chi2:.1f})" if not math.isnan(chi2) else "")
            lines.append(f"{kind}, {what} ~ N^alpha: between sizes {steps}; {fit}")
    return lines


def write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    """One line per size: the run's settings and every figure's mean and standard error, unformatted.

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`measure`.
    path : Path
        The CSV file (its folder is made if needed).
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    keys = ("kind", "size", "N", "realizations", "tests", "failed", "failed_s", "cpu_share", "setup_s",
            "buffer_MB", "peak_GB", "within")
    lines = [{**{k: r[k] for k in keys}, "slips_min": np.nanmin(r["per_realization"]["slips"], initial=np.inf),
              "slips_median": np.nanmedian(r["per_realization"]["slips"]),
              "slips_max": np.nanmax(r["per_realization"]["slips"], initial=-np.inf), **summary(r)} for r in rows]
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(lines[0]))
        w.writeheader()
        w.writerows(lines)


def _pick_core(core: int) -> int | None:
    if not hasattr(os, "sched_setaffinity"):
        print("no os.sched_setaffinity here: the process is not pinned to one core")
        return None
    allowed = sorted(os.sched_getaffinity(0))
    if core not in allowed:
        print(f"core {core} is not available to this process (allowed: {allowed}); using core {allowed[-1]}")
        core = allowed[-1]
    os.sched_setaffinity(0, {core})
    return core


def _spread(row: dict[str, Any]) -> str:
    """The fewest, median and most slips per test over the realizations, and the spread within one."""
    v = row["per_realization"]["slips"]
    v = v[np.isfinite(v)]
    if v.size == 0:
        return "none slid"
    text = f"{v.min():.3g}, median {np.median(v):.3g}, most {v.max():.3g}"
    return text + (f"; within one, at most {row['within']:.2f} x" if row["within"] else "")


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print its table; returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=None,
                    help="nodes of the irregular networks (default 100 1000 10000; --quick: 100 1000)")
    ap.add_argument("--lattices", type=int, nargs="*", default=None,
                    help="sides L of the triangular L x L lattices (default 10 32; --quick: 10)")
    ap.add_argument("--realizations", type=int, default=None,
                    help="independent realizations per size (default 8; --quick: 4)")
    ap.add_argument("--tests", type=int, default=None, help="tilt tests per realization (default 2; --quick: 1)")
    ap.add_argument("--age", type=int, default=None,
                    help="thermal steps before the tests, at least 2 (default 3; --quick: 2)")
    ap.add_argument("--seed", type=int, default=1, help="root seed of the realizations (default 1)")
    ap.add_argument("--core", type=int, default=0, help="the core the process is pinned to (default 0)")
    ap.add_argument("--max-avalanche", type=int, default=None,
                    help="solver.max_avalanche, the tilt test's cap on slips (default: the config's, 1e8)")
    ap.add_argument("--overshoot", type=float, default=None, help="friction.overshoot e in [0, 1] (default 1)")
    ap.add_argument("--min-slips", type=int, default=None, help="[tilt] min_slips (default 1)")
    ap.add_argument("--min-displacement", type=float, default=None, help="[tilt] min_displacement (default 0)")
    ap.add_argument("--shs", type=float, default=None, metavar="GAMMA",
                    help="time the slide-hold-slide pull with [shs] stiffness = GAMMA instead of the tilt test")
    ap.add_argument("--csv", type=Path, default=None, help="also write the rows to this CSV file")
    ap.add_argument("--quick", action="store_true", help="a smoke run of a few seconds")
    args = ap.parse_args(argv)
    q = args.quick
    sizes = sorted(args.sizes if args.sizes is not None else ([100, 1000] if q else [100, 1000, 10_000]))
    lattices = sorted(args.lattices if args.lattices is not None else ([10] if q else [10, 32]))
    tests = args.tests or (1 if q else 2)
    realizations = args.realizations or (4 if q else 8)
    age = args.age or (2 if q else 3)
    if age < 2 or tests < 1 or realizations < 1:
        ap.error("--age must be at least 2, --tests and --realizations at least 1")

    rule = {"overshoot": args.overshoot, "min_slips": args.min_slips, "min_displacement": args.min_displacement,
            "shs": args.shs}
    load_config(run_config(network_table("irregular", 16), 2, None, rule))  # a bad rule: one line, before work
    core = _pick_core(args.core)
    t_start = time.perf_counter()
    named = ", ".join(f"{k} = {v:g}" for k, v in rule.items() if v is not None) or "the defaults"
    what = "slide-hold-slide pull" if args.shs is not None else "network tilt test"
    print(f"{what}, cost per test; rule: {named}; one core = core {core}; load average "
          f"{os.getloadavg()[0]:.2f}", flush=True)
    warm_up()
    rows = []
    for kind, size in [("irregular", n) for n in sizes] + [("triangular", L) for L in lattices]:
        row = measure(kind, size, realizations, tests, age, args.seed, args.max_avalanche, rule)
        rows.append(row)
        s = summary(row)
        print(f"  {_label(row)}, N = {row['N']:,}: {_pm(s['test_s'], s['test_s_sem'])} s per test, "
              f"{_pm(s['slips'], s['slips_sem'])} slips (by realization: fewest {_spread(row)}); did not slide: "
              f"{row['failed']}; setup "
              f"{row['setup_s']:.2f} s; tilt draw buffers up to {row['buffer_MB']:.0f} MB; peak resident "
              f"{row['peak_GB']:.2f} GB; CPU share {row['cpu_share']:.2f}", flush=True)

    wall = time.perf_counter() - t_start
    print()
    print(markdown(rows))
    print()
    for line in exponents(rows):
        print(line)
    shares = [r["cpu_share"] for r in rows if not math.isnan(r["cpu_share"])]
    low = " (below 0.95: another process took the core)" if shares and min(shares) < 0.95 else ""
    print(f"wall time {wall:.0f} s; load average {os.getloadavg()[0]:.2f}; CPU share of the tests "
          f"{min(shares):.2f} - {max(shares):.2f}{low}")
    if args.csv is not None:
        write_csv(rows, args.csv)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
