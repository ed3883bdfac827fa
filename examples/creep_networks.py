"""Creep of networks of sliders under a constant tangential force: steady or logarithmic?
======================================================================================

The paper (Geminard & Bertin 2010) announces a study of 2D irregular networks
in which "the creep motion induced by a constant tangential force" will be
considered. This study measures it from the base configuration
``examples/creep_networks.toml``: the aging study's conventions (mu_d = 0.5,
gaussian mu_s of mean 0.6 and std 0.01, Ntilde = 1e-7, driver
``gaussian_steps`` with sigma_theta / Ntilde = 1, record "log", seed 1, 16
realizations) plus the same force f_ext = 0.3 N along +x on every slider,
f_ext / mu_d = 0.6, so that no network slides as a whole.

Two questions, at every size:

* the creep velocity v of the centre of mass, the mean velocity over the last
  decade [T/10, T], against the number of sliders N;
* does the creep slow down with time? :func:`slidernet.analysis.trend.creep_law`
  compares each realization's mean velocity over [T/100, T/10] and [T/10, T]:
  steady creep (x_G proportional to t) predicts a ratio 1, logarithmic creep
  (x_G proportional to ln t) about 0.1 (computed from the recorded times used).

and, a part of its own, the early transient below 1 tau_th that the
recorded times (whole thermal steps) cannot resolve:

* x_G(t) at t = 0, 0.01, 0.03, 0.1, 0.3, 1, 3, 10 and 30 tau_th, read
  exactly from the event catalogue (observable ``events``: every slip with
  the time of its driving event, fractional within the thermal step, and its
  displacement): x_G(t) is the sum of w_i dx over the slips with time < t,
  w_i = N_i / sum_j N_j (the relaxation at t = 0, if any, belongs to
  x_G(0), as in the records), checked against the recorded x_G at every
  integer t;
* the mean velocity over [0, 1], [1, 10] and [10, 100] tau_th, each set
  against the late velocity of the same network (the first question's, over
  [T/10, T]) by a per-realization contrast: the transient runs use the same
  seed and configuration, so realization r of both is one trajectory, the
  transient run a prefix of the long one;
* within the first thermal step, the advance x_G(s) - x_G(0) at s = 0.01 to
  0.3 set against the mean advance x_G(q + s) - x_G(q) over the steps q of
  [10, 100], whose sliders are prestressed.

Every error is a standard error over the independent realizations.

The grid of the full preset (16 realizations per point, seed 1, network seed 0):

* free-end chains (kind ``chain``; n = 2 runs on the pair kernel) of 2, 4, 8
  and 16 sliders, to T = 1e4 tau_th;
* irregular 2D networks (kind ``irregular``: random points joined by their
  Delaunay triangulation) of 16 sliders to 1e4 tau_th, 64 to 3e3 and 256 to
  1e3 tau_th (the cost grows like the slips, about 11 000 per tau_th at 256);
* the transient: chains of 2, 4 and 16 and irregular networks of 16 and 64
  to 100 tau_th with the event catalogue (3.7 million slips at 64).

Writes ``creep_networks.json`` (every number, with its parameters and the
configurations) and ``creep_networks.png`` into ``--out``, and each part's
runs under ``--out/sweeps/`` and ``--out/transient/``; ``--resume`` continues
an interrupted study there (finished runs are read back), and ``--parts``
runs some of the parts only (names of the size groups, and ``transient``)::

    python examples/creep_networks.py --out creep_net_out --workers 2   # ~5 min on 2 cores
    python examples/creep_networks.py --out creep_net_out --quick       # seconds
    python examples/creep_networks.py --out creep_net_out --workers 2 --parts transient

Units: lengths in l0, time in tau_th, forces in N (f_ext shares the friction
coefficients' scale), theta dimensionless; Ntilde = N / (k l0).
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import slidernet
from slidernet.analysis.trend import creep_law, mean_sem
from slidernet.ensemble.runner import run_in
from slidernet.ensemble.sweep import sweep
from slidernet.io import save_figure, write_json

try:
    BASE_TOML = Path(__file__).resolve().with_name("creep_networks.toml")
except NameError:  # sphinx-gallery defines no __file__; it runs the script from examples/
    BASE_TOML = Path("creep_networks.toml").resolve()
JSON_NAME = "creep_networks.json"
PNG_NAME = "creep_networks.png"
Z = 2.0          # the verdicts' threshold, in standard errors
TRANSIENT_TIMES = (0.0, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0)   # tau_th: x_G from the catalogue
TRANSIENT_WINDOWS = ((0.0, 1.0), (1.0, 10.0), (10.0, 100.0))            # tau_th: mean velocities


@dataclasses.dataclass(frozen=True)
class Group:
    """One sweep of the study: a network kind, its sizes and one duration.

    Attributes
    ----------
    name : str
        Label of the group in the JSON output.
    kind : str
        Network kind: ``chain`` or ``irregular`` (network seed 0).
    sizes : tuple of int
        Numbers of sliders (``network.n``).
    steps : int
        Duration T in tau_th.
    """

    name: str
    kind: str
    sizes: tuple[int, ...]
    steps: int


@dataclasses.dataclass(frozen=True)
class Transient:
    """The transient part: networks run with the event catalogue, to ``steps``.

    Attributes
    ----------
    networks : tuple of (str, int)
        (kind, number of sliders) of each network; each is also a point of a
        size group of the preset, whose late velocity it is set against.
    steps : int
        Duration in tau_th, at least the end of the last of ``TRANSIENT_WINDOWS``.
    """

    networks: tuple[tuple[str, int], ...]
    steps: int


@dataclasses.dataclass(frozen=True)
class Preset:
    """The whole study: its sweeps, its transient part and the number of realizations per point."""

    realizations: int
    groups: tuple[Group, ...]
    transient: Transient


PRESETS = {
    # ~600 core-seconds, three quarters of them the irregular networks of 64 and 256 sliders.
    "full": Preset(
        realizations=16,
        groups=(
            Group("chains", "chain", (2, 4, 8, 16), 10_000),
            Group("irregular_16", "irregular", (16,), 10_000),
            Group("irregular_64", "irregular", (64,), 3_000),
            Group("irregular_256", "irregular", (256,), 1_000),
        ),
        # 12 s of wall time, 7 s of CPU on 2 busy cores (2026-11-27), 0.86 GB resident at the peak: the
        # catalogue of irregular 64 holds 3.7 million slips.
        transient=Transient((("chain", 2), ("chain", 4), ("chain", 16), ("irregular", 16), ("irregular", 64)),
                            100),
    ),
    # A second or two of runs once the kernels are compiled.
    "quick": Preset(
        realizations=8,
        groups=(
            Group("chains", "chain", (2, 4), 1_000),
            Group("irregular_16", "irregular", (16,), 300),
        ),
        transient=Transient((("chain", 2), ("chain", 4), ("irregular", 16)), 100),
    ),
}


def base_config(realizations: int) -> dict[str, Any]:
    """The study's base configuration (``creep_networks.toml``) as a plain dict."""
    cfg = slidernet.load_config(BASE_TOML).model_dump(mode="json")
    cfg["realizations"] = realizations
    return cfg


def group_config(group: Group, realizations: int) -> dict[str, Any]:
    """The base configuration of one sweep: its kind (network seed 0 if irregular) and duration."""
    cfg = base_config(realizations)
    net = cfg["network"]
    cfg["steps"] = group.steps
    cfg["network"] = {"kind": group.kind, "n": group.sizes[0], "Ntilde": net["Ntilde"], "f_ext": net["f_ext"]}
    if group.kind == "irregular":
        cfg["network"]["seed"] = 0
    return cfg


def _velocity_curve(x_G: xr.DataArray, per_decade: int = 4) -> dict[str, list[float]]:
    """Mean velocity of the ensemble over successive log-spaced windows from t = 1 to the end.

    Window edges: the recorded times nearest to ``per_decade`` points per decade;
    each window's velocity (x(b) - x(a)) / (b - a) per realization, then mean and
    standard error over the realizations. ``t`` is the window's geometric middle.
    """
    x = x_G.transpose("realization", "t")
    t = x["t"].values.astype(np.float64)
    positive = t[t >= 1]
    wanted = np.logspace(0, math.log10(positive[-1]), max(2, round(per_decade * math.log10(positive[-1])) + 1))
    edges = np.unique(positive[np.abs(np.log(positive)[None, :] - np.log(wanted)[:, None]).argmin(axis=1)])
    idx = np.searchsorted(t, edges)
    v = np.diff(x.values[:, idx], axis=1) / np.diff(edges)
    stats = [mean_sem(v[:, k]) for k in range(v.shape[1])]
    return {"t": np.sqrt(edges[:-1] * edges[1:]).tolist(), "t_from": edges[:-1].tolist(),
            "t_to": edges[1:].tolist(), "v_mean": [m for m, _, _ in stats], "v_sem": [s for _, s, _ in stats]}


def reduce_point(one: xr.Dataset, n: int) -> dict[str, Any]:
    """Every number of one point (one network, R realizations) from its result."""
    law = creep_law(one["x_G"], factor=10.0, z=Z)
    t2, t3 = law.attrs["t2"], law.attrs["t3"]
    x, slips = one["x_G"], one["n"]
    # The whole-run mean velocity x_G(T) / T, per realization.
    v_run = mean_sem((x.sel(t=t3) - x.sel(t=0)).values / t3)
    # One slip of one slider by delta moves x_G by delta / N: N v / r is the mean displacement along
    # x of the slider that slips, per slip (l0), measured over the last decade per realization.
    dx = (x.sel(t=t3) - x.sel(t=t2)).values
    dn = (slips.sel(t=t3) - slips.sel(t=t2)).values.astype(np.float64)
    step = mean_sem(np.where(dn > 0, n * dx / np.maximum(dn, 1), np.nan))
    r_last = mean_sem(dn / (t3 - t2))
    return {
        "v_last_decade_mean": float(law["v_late_mean"]), "v_last_decade_sem": float(law["v_late_sem"]),
        # Per realization (NaN: not finite): the transient part pairs its windows with these.
        "v_last_decade": law["v_late"].values.tolist(),
        "v_previous_decade_mean": float(law["v_early_mean"]), "v_previous_decade_sem": float(law["v_early_sem"]),
        "v_run_mean": v_run[0], "v_run_sem": v_run[1],
        "windows": [law.attrs["t1"], t2, t3],
        "ratio_mean": float(law["ratio"]), "ratio_sem": float(law["ratio_sem"]),
        "ratio_steady": float(law["ratio_steady"]), "ratio_log": float(law["ratio_log"]),
        "steady_gap_mean": float(law["steady_gap_mean"]), "steady_gap_sem": float(law["steady_gap_sem"]),
        "log_gap_mean": float(law["log_gap_mean"]), "log_gap_sem": float(law["log_gap_sem"]),
        "steady_consistent": bool(law["steady_consistent"]), "log_consistent": bool(law["log_consistent"]),
        "early_resolved": bool(law["early_resolved"]), "verdict": law.attrs["verdict"],
        "r_mean": float(one["r_mean"]), "r_sem": float(one["r_sem"]),
        "r_last_decade_mean": r_last[0], "r_last_decade_sem": r_last[1],
        "slips_per_slider_per_tau_th": float(one["r_mean"]) / n,
        "step_per_slip_mean": step[0], "step_per_slip_sem": step[1],
        "realizations": int(law["realizations"]),
        "velocity_curve": _velocity_curve(x),
    }


def run_group(group: Group, realizations: int, workers: int | None, out: Path, resume: bool = False,
              log: bool = True) -> list[dict[str, Any]]:
    """Run one sweep over the sizes of a group in ``out/sweeps/<name>`` (resumed, or read back where it has
    finished, with ``resume``) and reduce every point to its numbers."""
    cfg = group_config(group, realizations)
    start = time.perf_counter()
    where = out / "sweeps" / group.name
    result = sweep(cfg, {"network.n": list(group.sizes)}, workers=workers, progress=None, out=where,
                   resume=resume and (where / "sweep.json").exists(), overwrite=not resume)
    ds = result.to_dataset() if isinstance(result, xr.DataTree) else result
    configs = json.loads(ds.attrs["configs"])
    elapsed = time.perf_counter() - start
    dim = ds["x_G"].dims[0]   # the sweep's dimension
    points = []
    for i, n in enumerate(group.sizes):
        point = {"group": group.name, "kind": group.kind, "n": n, "steps": group.steps,
                 "f_ext": cfg["network"]["f_ext"], "sigma_theta": cfg["driver"]["sigma_theta"],
                 **reduce_point(ds.isel({dim: i}), n), "config": configs[i]}
        points.append(point)
        if log:
            print(f"{group.kind} {n:4d} (T = {group.steps}): v = {point['v_last_decade_mean']:.3e} "
                  f"+- {point['v_last_decade_sem']:.1e} l0/tau_th, ratio {point['ratio_mean']:.3f} "
                  f"+- {point['ratio_sem']:.3f} (log {point['ratio_log']:.3f}) -> {point['verdict']}; "
                  f"r = {point['r_mean']:.1f}/tau_th", flush=True)
    if log:
        print(f"{group.name}: {elapsed:.1f} s", flush=True)
    return points


def transient_config(kind: str, n: int, steps: int, realizations: int) -> dict[str, Any]:
    """One network of the transient part: its size group's configuration (the same seed, network seed 0),
    run to ``steps`` with the event catalogue and a record at every integer t."""
    cfg = group_config(Group("transient", kind, (n,), steps), realizations)
    cfg["record"] = "all"   # every integer t: the catalogue's x_G is checked against each record
    cfg["observables"] = [*cfg["observables"], "events"]
    return cfg


def catalogue_x_G(time: np.ndarray, dx_G: np.ndarray, t: np.ndarray) -> np.ndarray:
    """x_G at any times, exactly, from one realization's event catalogue.

    Parameters
    ----------
    time : ndarray, shape (S,)
        The time of each slip, in tau_th, in the catalogue's order (non-decreasing).
    dx_G : ndarray, shape (S,)
        Its advance of x_G along x, w_i dx (w_i = N_i / sum_j N_j), in l0.
    t : ndarray, shape (T,)
        Times, in tau_th, >= 0.

    Returns
    -------
    ndarray, shape (T,)
        x_G(t) in l0: the sum of the advances of the slips with time < t, and
        at t = 0 of those at time 0 (the relaxation of a load above some
        thresholds, which the record at t = 0 holds).

    Examples
    --------
    >>> catalogue_x_G(np.array([0.0, 0.5, 1.0]), np.array([1.0, 2.0, 4.0]), np.array([0.0, 0.5, 0.6, 1.0, 2.0]))
    array([1., 1., 3., 3., 7.])
    """
    total = np.concatenate([[0.0], np.cumsum(dx_G)])
    # The kernels stamp a slip of step q with q plus its fraction of the step, in [q, q + 1), and write the
    # record at q before step q: it holds the slips with time < q, and the one at 0 the relaxation at 0.
    # Summed one slip after the other, in the catalogue's order, as the kernels sum x_G.
    count = np.where(t > 0, np.searchsorted(time, t, side="left"), np.searchsorted(time, 0.0, side="right"))
    return total[count]


def _contrast(values: np.ndarray, reference: np.ndarray) -> dict[str, Any]:
    """Per-realization contrast values - reference, shape (R,): its mean, standard error and whether it is
    within ``Z`` standard errors of 0 (the two share their realizations, whose covariance it keeps)."""
    gap, sem, _ = mean_sem(values - reference)
    return {"gap_mean": gap, "gap_sem": sem, "consistent": bool(abs(gap) <= Z * sem)}


def reduce_transient(ds: xr.Dataset, weights: np.ndarray, late: dict[str, Any] | None) -> dict[str, Any]:
    """Every number of one network of the transient part, from its result with the event catalogue.

    Parameters
    ----------
    ds : xarray.Dataset
        A run with the observables ``x_G`` and ``events``, recorded at every
        integer t, to at least the end of the last of ``TRANSIENT_WINDOWS``.
    weights : ndarray, shape (N,)
        w_i = N_i / sum_j N_j: one slip of node i by dx moves x_G by w_i dx.
    late : dict or None
        The network's point of the size part (:func:`reduce_point`), whose
        per-realization velocities over the last decade the windows are set
        against; None: no such point was run.

    Returns
    -------
    dict
        ``x_G_mean``, ``x_G_sem`` (l0) at ``times`` (``TRANSIENT_TIMES``, tau_th);
        ``windows``, one dict per window of ``TRANSIENT_WINDOWS``: the mean
        velocity (l0/tau_th), the slips per tau_th and, with ``late``, the
        contrast with the late velocity (``late_gap_mean``, ``late_gap_sem``,
        ``late_consistent``); ``late`` and ``reaches_late_from`` (the start,
        tau_th, of the first window from which every window is consistent
        with the late velocity; None where the last is not); ``in_step``: the
        advance x_G(q + s) - x_G(q) at the fractions s < 1 of ``times``, in
        the first step (q = 0) and averaged over the steps of the last window,
        with their contrast; ``catalogue_check``: the catalogue's x_G against
        the recorded one at every integer t.
    """
    times = np.array(TRANSIENT_TIMES)
    edges = np.array(TRANSIENT_WINDOWS)                        # (W, 2)
    fractions = times[(times > 0) & (times < 1)]               # within a thermal step
    steps_late = np.arange(int(edges[-1, 0]), int(edges[-1, 1]))   # the steps q of the last window
    t_rec = ds["t"].values.astype(np.float64)
    x_rec = ds["x_G"].transpose("realization", "t").values
    complete = ds["events_complete"].values.astype(bool)
    R = x_rec.shape[0]
    bounds = np.searchsorted(ds["event_realization"].values, np.arange(R + 1))   # realization 0, then 1, ...
    columns = {name: ds[f"event_{name}"].values for name in ("time", "node", "dx")}
    x = np.full((R, times.size), np.nan)
    v = np.full((R, len(edges)), np.nan)
    slips = np.full((R, len(edges)), np.nan)
    first_step = np.full((R, fractions.size), np.nan)
    late_steps = np.full((R, fractions.size), np.nan)
    diff = np.full(x_rec.shape, np.nan)
    for r in np.flatnonzero(complete):   # x_G cannot be read from a catalogue that stopped
        rows = {name: col[bounds[r]:bounds[r + 1]] for name, col in columns.items()}
        at = functools.partial(catalogue_x_G, rows["time"], weights[rows["node"]] * rows["dx"])
        x[r] = at(times)
        x_edges = at(edges.ravel()).reshape(edges.shape)
        v[r] = (x_edges[:, 1] - x_edges[:, 0]) / (edges[:, 1] - edges[:, 0])
        slips[r] = np.diff(np.searchsorted(rows["time"], edges, side="left"), axis=1)[:, 0] / np.diff(edges)[:, 0]
        first_step[r] = at(fractions) - at(np.zeros(1))
        late_steps[r] = (at(steps_late[:, None] + fractions) - at(steps_late.astype(np.float64))[:, None]).mean(0)
        diff[r] = at(t_rec) - x_rec[r]
    # To the bit only where Ntilde is a power of 2: the catalogue stores dx = du Ntilde (l0), rounded, while
    # the kernel sums w_i du in units of Ntilde l0 and scales by Ntilde once (docs/guides/creep.md).
    scale = np.abs(x_rec).max(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        relative = np.abs(diff) / scale
    check = {"compared": int(np.isfinite(diff).sum()), "bitwise_equal": int((diff == 0).sum()),
             "max_abs_diff": float(np.nanmax(np.abs(diff))) if complete.any() else None,
             "max_rel_diff": float(np.nanmax(np.where(scale > 0, relative, 0.0))) if complete.any() else None}
    late_v = None if late is None else np.asarray(late["v_last_decade"], dtype=np.float64)
    windows = []
    for k, (a, b) in enumerate(TRANSIENT_WINDOWS):
        mean, sem, count = mean_sem(v[:, k])
        rate, rate_sem, _ = mean_sem(slips[:, k])
        w: dict[str, Any] = {"t_from": a, "t_to": b, "v_mean": mean, "v_sem": sem, "realizations": count,
                             "slips_per_tau_th_mean": rate, "slips_per_tau_th_sem": rate_sem}
        if late_v is not None:
            w |= {f"late_{key}": value for key, value in _contrast(v[:, k], late_v).items()}
        windows.append(w)
    reaches = None
    for w in reversed(windows):
        if not w.get("late_consistent", False):
            break
        reaches = w["t_from"]
    stats = [mean_sem(x[:, k]) for k in range(times.size)]
    in_step = {"fractions": fractions.tolist(), "late_steps": [int(steps_late[0]), int(steps_late[-1])],
               "first_step_mean": [], "first_step_sem": [], "late_steps_mean": [], "late_steps_sem": [],
               "gap_mean": [], "gap_sem": [], "consistent": []}
    for k in range(fractions.size):
        for name, values in (("first_step", first_step[:, k]), ("late_steps", late_steps[:, k])):
            mean, sem, _ = mean_sem(values)
            in_step[f"{name}_mean"].append(mean)
            in_step[f"{name}_sem"].append(sem)
        for key, value in _contrast(first_step[:, k], late_steps[:, k]).items():
            in_step[key].append(value)
    return {
        "realizations": R, "times": times.tolist(),
        "x_G_mean": [m for m, _, _ in stats], "x_G_sem": [e for _, e, _ in stats],
        "windows": windows,
        "late": None if late is None else {"group": late["group"], "t_from": late["windows"][1],
                                           "t_to": late["windows"][2], "v_mean": late["v_last_decade_mean"],
                                           "v_sem": late["v_last_decade_sem"]},
        "reaches_late_from": reaches,
        "in_step": in_step,
        "catalogue_check": check,
    }


def run_transient(transient: Transient, realizations: int, points: list[dict[str, Any]], workers: int | None,
                  out: Path, resume: bool = False, log: bool = True) -> dict[str, Any]:
    """Run every network of the transient part in ``out/transient/<kind>_<n>`` (resumed, or read back where
    it has finished, with ``resume``) and reduce each, against its point of ``points`` where there is one."""
    late_of = {(p["kind"], p["n"]): p for p in points}
    networks = []
    for kind, n in transient.networks:
        start = time.perf_counter()
        cfg = transient_config(kind, n, transient.steps, realizations)
        ds = run_in(cfg, out / "transient" / f"{kind}_{n}", resume=resume, overwrite=not resume, workers=workers)
        net = slidernet.load_config(cfg).network.build()
        entry = {"kind": kind, "n": n, "steps": transient.steps,
                 "slips": int(ds.sizes["event"]),
                 **reduce_transient(ds, net.normal_load / net.normal_load.sum(), late_of.get((kind, n))),
                 "config": json.loads(ds.attrs["config"])}
        del ds   # its catalogue (0.15 GB at 64 sliders) goes before the next network's is read
        networks.append(entry)
        if log:
            v = "; ".join(f"[{w['t_from']:g}, {w['t_to']:g}] {w['v_mean']:.3e} +- {w['v_sem']:.1e}"
                          for w in entry["windows"])
            print(f"transient {kind} {n:4d}: v {v} l0/tau_th; late value from t = {entry['reaches_late_from']}; "
                  f"{time.perf_counter() - start:.1f} s", flush=True)
    return {"steps": transient.steps, "times": list(TRANSIENT_TIMES),
            "windows": [list(w) for w in TRANSIENT_WINDOWS], "networks": networks}


def _transient_panel(ax: Axes, transient: dict[str, Any] | None) -> None:
    """Panel (d): the mean velocity since t = 0, x_G(t) / t, over each window, and within a later step, each
    over the late velocity."""
    ax.set_xscale("log")
    ax.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax.set_ylabel(r"velocity / late velocity")
    ax.set_title(r"(d) the transient, from the event catalogue: $x_G(t)/t$ (points), windows (bars), a step"
                 "\n" r"of $[10, 100]$ (dashes); over the late velocity ($[T/10, T]$; else $[10, 100]$: *); "
                 r"mean $\pm$ SE", fontsize=9)
    if transient is None:
        ax.text(0.5, 0.5, "not run", transform=ax.transAxes, ha="center")
        return
    ax.axhline(1.0, color="k", lw=1, ls="--")
    markers = {"chain": "o", "irregular": "s"}
    for i, net in enumerate(transient["networks"]):
        color = f"C{i}"
        late = net["late"]
        ref = late["v_mean"] if late is not None else net["windows"][-1]["v_mean"]
        t = np.array(net["times"][1:])   # x_G(0) / 0 is not defined
        ax.errorbar(t, np.array(net["x_G_mean"][1:]) / (t * ref), yerr=np.array(net["x_G_sem"][1:]) / (t * ref),
                    fmt=markers[net["kind"]] + ":", ms=3, lw=0.8, capsize=2, color=color,
                    label=f"{net['kind']} {net['n']}" + ("" if late is not None else " *"))
        # A step of the last window, its advance x_G(q + s) - x_G(q) over s: what the first step is set against.
        step = net["in_step"]
        s = np.array(step["fractions"])
        ax.plot(s, np.array(step["late_steps_mean"]) / (s * ref), "--", lw=1, color=color)
        for w in net["windows"]:
            # A bar over each window (from 0.005 for the first: t = 0 is off a log axis), its error at the middle.
            a, b = max(w["t_from"], 0.005), w["t_to"]
            ax.hlines(w["v_mean"] / ref, a, b, color=color, lw=2.5, alpha=0.7)
            # Each network's error bar a little to the right of the previous one's, to keep them apart.
            ax.errorbar(math.sqrt(a * b) * 1.12**i, w["v_mean"] / ref, yerr=w["v_sem"] / ref, color=color,
                        capsize=3)
    ax.legend(fontsize=7, ncol=2)


def figure(data: dict[str, Any]) -> Figure:
    """The study's figure: (a) v against N, (b) the velocity ratio against N with both laws, (c) v(t), and
    (d) the transient below 1 tau_th (not run: a panel that says so)."""
    fig = Figure(figsize=(13, 8.4), layout="constrained")
    FigureCanvasAgg(fig)
    (ax_v, ax_r), (ax_t, ax_d) = fig.subplots(2, 2)
    styles = {"chain": ("o", "C0", "free-end chain"), "irregular": ("s", "C3", "irregular 2D (Delaunay)")}
    for kind, (mk, color, label) in styles.items():
        pts = sorted((p for p in data["points"] if p["kind"] == kind), key=lambda p: p["n"])
        if not pts:
            continue
        n = np.array([p["n"] for p in pts], float)
        ax_v.errorbar(n, [p["v_last_decade_mean"] for p in pts], yerr=[p["v_last_decade_sem"] for p in pts],
                      fmt=mk + "-", color=color, capsize=3, label=label)
        ax_r.errorbar(n, [p["ratio_mean"] for p in pts], yerr=[p["ratio_sem"] for p in pts],
                      fmt=mk, color=color, capsize=3, label=label)
        # Each point's own log prediction (from its recorded times): a short bar at the point.
        ax_r.plot(n, [p["ratio_log"] for p in pts], "_", color=color, ms=14, mew=2)
        for p in pts:
            cur = p["velocity_curve"]
            ax_t.errorbar(cur["t"], cur["v_mean"], yerr=cur["v_sem"], fmt=mk + "-", ms=3, lw=0.8,
                          color=color, alpha=0.35 + 0.65 * p["n"] / max(q["n"] for q in pts),
                          label=f"{kind} {p['n']}")
    ax_v.set_xscale("log", base=2)
    ax_v.set_yscale("log")
    ax_v.set_xlabel("number of sliders N")
    ax_v.set_ylabel(r"creep velocity $v$ over $[T/10, T]$  [$l_0/\tau_\mathrm{th}$]")
    ax_v.set_title(rf"(a) $f_\mathrm{{ext}}/\mu_d = {data['parameters']['f_ext_over_mu_d']:g}$, "
                   r"$\sigma_\theta/\tilde N = 1$; mean $\pm$ SE", fontsize=9)
    ax_r.axhline(1.0, color="k", lw=1, ls="--", label="steady creep ($x_G \\propto t$): 1")
    ax_r.axhline(0.1, color="0.5", lw=1, ls=":", label=r"logarithmic ($x_G \propto \ln t$): 0.1"
                 "\n(bars: each point's, from its times)")
    ax_r.set_xscale("log", base=2)
    ax_r.set_ylim(0, 1.6)
    ax_r.set_xlabel("number of sliders N")
    ax_r.set_ylabel(r"$\langle v\rangle_{[T/10,\,T]} / \langle v\rangle_{[T/100,\,T/10]}$")
    ax_r.set_title("(b) does the creep slow down? ratio of the mean velocities", fontsize=9)
    ax_t.set_xscale("log")
    ax_t.set_yscale("log")
    ax_t.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax_t.set_ylabel(r"mean velocity over log windows  [$l_0/\tau_\mathrm{th}$]")
    ax_t.set_title("(c) velocity against time (4 windows per decade)", fontsize=9)
    if data["points"]:   # the size part run: the legends have entries
        ax_v.legend(fontsize=8)
        ax_r.legend(fontsize=7, loc="lower left")
        ax_t.legend(fontsize=6, ncol=2)
    _transient_panel(ax_d, data.get("transient"))
    return fig


def plot(data: dict[str, Any], path: Path) -> Path:
    """The study's :func:`figure`, written atomically to ``path``."""
    return save_figure(figure(data), path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("creep_net_out"),
                        help="output folder (default creep_net_out)")
    parser.add_argument("--quick", action="store_true", help="small networks, short runs (seconds)")
    parser.add_argument("--workers", type=int, default=None, help="worker processes per sweep point")
    parser.add_argument("--resume", action="store_true",
                        help="continue an interrupted study in --out (finished runs are read back)")
    parser.add_argument("--parts", nargs="+", metavar="PART", default=None,
                        help="run only these parts: size groups by name (full: chains irregular_16 irregular_64 "
                             "irregular_256) and/or 'transient' (default: every part)")
    args = parser.parse_args(argv)

    name = "quick" if args.quick else "full"
    preset = PRESETS[name]
    known = [g.name for g in preset.groups] + ["transient"]
    parts = known if args.parts is None else args.parts
    if unknown := sorted(set(parts) - set(known)):
        parser.error(f"unknown parts {unknown} of the {name} preset; its parts are {known}")
    start = time.perf_counter()
    base = base_config(preset.realizations)
    groups = [g for g in preset.groups if g.name in parts]
    points: list[dict[str, Any]] = []
    for group in groups:
        points += run_group(group, preset.realizations, args.workers, args.out, args.resume)
    transient = None
    if "transient" in parts:
        start_transient = time.perf_counter()
        transient = run_transient(preset.transient, preset.realizations, points, args.workers, args.out,
                                  args.resume)
        print(f"transient: {time.perf_counter() - start_transient:.1f} s", flush=True)
    mu_d = base["friction"]["mu_d"]
    data = {
        "question": "creep under a constant tangential force: v against N at fixed f_ext / mu_d, "
                    "and does it slow down with time (logarithmic) or stay steady?",
        "preset": name,
        "estimators": {
            "v": "per-realization mean velocity (x_G(t3) - x_G(t2)) / (t3 - t2) over the last decade "
                 "[t2, t3] ~ [T/10, T] (recorded times nearest in ln t); mean and SE over realizations",
            "ratio": "creep_law: <v_late> / <v_early> over [T/100, T/10] and [T/10, T]; SE by the delta "
                     "method (spread of per-realization linearised terms)",
            "verdicts": f"a law is consistent when the mean of v_late - ratio_law v_early is within {Z:g} SE "
                        "of 0 (per-realization contrasts)",
            "step_per_slip": "N (x_G(t3) - x_G(t2)) / (n(t3) - n(t2)) per realization: the mean displacement "
                             "along x of the slider that slips, in l0",
            "transient": "x_G(t) = sum of w_i dx over the catalogue's slips with time < t (w_i = N_i / sum N); "
                         "window velocities (x_G(b) - x_G(a)) / (b - a) per realization, mean and SE; set "
                         f"against the late velocity by the per-realization contrast v_window - v_late, "
                         f"consistent within {Z:g} SE; reaches_late_from: the first window from which every "
                         "window is consistent",
        },
        "parameters": {"mu_d": mu_d, "mu_s_mean": base["friction"]["static"]["mean"],
                       "mu_s_std": base["friction"]["static"]["std"], "Ntilde": base["network"]["Ntilde"],
                       "f_ext": base["network"]["f_ext"], "f_ext_over_mu_d": base["network"]["f_ext"] / mu_d,
                       "sigma_theta": base["driver"]["sigma_theta"],
                       "sigma_theta_over_Ntilde": base["driver"]["sigma_theta"] / base["network"]["Ntilde"],
                       "seed": base["seed"], "realizations": preset.realizations, "irregular_network_seed": 0,
                       "z": Z},
        "base_config": base,
        "groups": [dataclasses.asdict(g) for g in groups],
        "points": points,
        "transient": transient,
        "slidernet_version": slidernet.__version__,
        "wall_time_s": time.perf_counter() - start,
    }
    print(write_json(data, args.out / JSON_NAME))
    print(plot(data, args.out / PNG_NAME))
    print(f"done in {time.perf_counter() - start:.1f} s")
    return 0


# %%
# Running the example
# -------------------
#
# The command line: ``main`` parses the options above. The documentation's
# gallery runs this script with ``--quick`` and a temporary ``--out`` folder
# (``docs/_ext/slidernet_gallery.py``) and shows the PNG files it writes.

if __name__ == "__main__":
    status = main()
    if status:  # sphinx-gallery runs the script inside Sphinx: exit only on failure
        raise SystemExit(status)
