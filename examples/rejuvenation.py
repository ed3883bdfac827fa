"""Does thermal cycling rejuvenate contacts? Contact strengthening against renewal by slips
========================================================================================

In the model every slip renews its slider's contact (a fresh threshold);
with ``[friction.strengthening]`` a contact also strengthens with its age a,
mu_s,i = mu_s,i^0 + beta ln(1 + a / tau_c). Thermal cycling makes sliders
slip, so it may keep contacts young and cap the strengthening. This study
measures, against t, the effective friction mu_eff (the network tilt test at
every recorded time, ``mu_eff_at = "records"``, the same estimator at every
size), the strongest threshold mu_max and the mean contact age
``contact_age``:

* **Systems**: the pair (a chain of 2), free chains of 4 and 16 (driven at
  their ends), irregular networks of 64 and 256 sliders (network seed 0,
  one geometry: errors are over realizations on that geometry).
* **Strengthening**: none, and the logarithmic law with beta = 0.005 and
  0.02, tau_c = 1e-3 tau_th.
* **Cycling**: sigma_theta / Ntilde = 0 (the ``constant`` driver: no slip
  at all, pure strengthening), 0.1, 1 and 10 (``gaussian_steps``).
* mu_d = 0.5, Gaussian mu_s of mean 0.6 and std 0.01, Ntilde = 1e-7; 16
  realizations to 1e3 tau_th (the irregular networks at sigma_theta / Ntilde
  = 10 to 1e2 tau_th: see ``Preset.short``), 4 recorded times per decade,
  seed 1 (common random numbers: realization r of every point has the same
  seed).

The ages' tail: the 90th and 99th percentiles and the largest contact age
at every recorded time, read from the histogram ``contact_age_count``
(pooled over realizations: no error over realizations) as the bin that
holds each (:func:`slidernet.analysis.observables.binned_quantile`).

A positive control: every point also runs ``[tilt] inject = {c = 0.002,
t0 = 1, select = 1}`` (docs/model.md, "Injected aging"), the points at
beta = 0 again with ``select = 0.1``, and reports mu_eff's recovery of
that known rise of the thresholds: (paired slope with injection - without)
/ (slope of the shift c ln(1 + t / t0)), both by ``log_trend`` over the
fit window (:func:`slidernet.analysis.trend.injection_recovery`, the
definition of ``examples/aging_recovery.py``).

Per point it reports mu_eff, mu_max and the mean contact age at t = 0, 1, 10,
100 and 1000 (mean +- standard error over realizations), the slope of mu_eff
per decade of t over 10 <= t <= t_end (:func:`slidernet.analysis.trend.log_trend`,
per-realization fits) and the slips per node per tau_th, r_node. Two
reference numbers make the answers readable: the strengthening of a contact
as old as the run, beta ln(1 + t_end / tau_c), and the strengthening of a
contact of the measured mean age, beta ln(1 + <a> / tau_c); and the product
<a> r_node, which is 1 for contacts renewed at random at the rate r_node
(a Poisson renewal; its mean backward recurrence time is 1 / r_node).

Writes ``rejuvenation.json``, ``rejuvenation_tables.md`` (the guide's tables,
made from that JSON) and ``rejuvenation.png`` into ``--out``::

    python examples/rejuvenation.py --out rejuvenation_out --workers 2   # the full preset
    python examples/rejuvenation.py --out rejuvenation_out --quick       # seconds; CI runs it

``--resume`` continues an interrupted run (every sweep is resumable). Units:
time in tau_th, friction coefficients dimensionless.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import slidernet
from slidernet.analysis.observables import binned_quantile
from slidernet.analysis.trend import injection_recovery, log_trend, mean_sem
from slidernet.config import InjectConfig
from slidernet.ensemble.sweep import sweep
from slidernet.io import atomic_output, save_figure, write_json

JSON_NAME = "rejuvenation.json"
PNG_NAME = "rejuvenation.png"
TABLES_NAME = "rejuvenation_tables.md"
LN10 = math.log(10.0)
NTILDE = 1e-7
TAU_C = 1e-3  # tau_th
REPORT_TIMES = (0, 1, 10, 100, 1000)
# The injected aging of the positive control: c ln 10 = 46e-4 per decade, about the pair's own rate without
# strengthening (37-38e-4 per decade at sigma_theta / Ntilde = 1 over 1-1e3 tau_th on both pages, 42-74e-4 over
# 10-1e3 here).
INJECT_C = 0.002
AGE_QUANTILES = {"q90": 0.9, "q99": 0.99, "max": 1.0}


@dataclasses.dataclass(frozen=True)
class Preset:
    """The study's grid and its duration."""

    realizations: int
    steps: int
    per_decade: int
    systems: tuple[tuple[str, int], ...]  # (kind, N): "pair" is a chain of 2
    betas: tuple[float, ...]  # 0: no strengthening (the table left out)
    cycling: tuple[float, ...]  # sigma_theta / Ntilde; 0: the constant driver
    t_fit: float  # the slopes are fitted over t_fit <= t <= t_end
    # (kind, sigma_theta / Ntilde) run to short_steps instead of steps: the irregular networks at the largest
    # amplitude, whose slips (~6e2 per node per tau_th at 256 sliders, 15.8 M per realization per 100 tau_th)
    # would take most of the budget, and whose contact ages settle within 1e-2 tau_th.
    short: tuple[tuple[str, float], ...] = ()
    short_steps: int = 100
    # The injections ([tilt] inject, select): every point runs with the first (every contact raised: its plain
    # outputs are those of a run without it, to the bit); the others run again at select_betas only.
    selects: tuple[float, ...] = (1.0,)
    select_betas: tuple[float, ...] = ()

    def steps_for(self, kind: str, cycling: float) -> int:
        """The duration of the runs of one system at one amplitude, in tau_th."""
        return self.short_steps if (kind, cycling) in self.short else self.steps


PRESETS = {
    "full": Preset(realizations=16, steps=1000, per_decade=4,
                   systems=(("pair", 2), ("chain", 4), ("chain", 16), ("irregular", 64), ("irregular", 256)),
                   betas=(0.0, 0.005, 0.02), cycling=(0.0, 0.1, 1.0, 10.0), t_fit=10.0,
                   short=(("irregular", 10.0),), selects=(1.0, 0.1), select_betas=(0.0,)),
    "quick": Preset(realizations=4, steps=30, per_decade=4, systems=(("pair", 2), ("chain", 4), ("irregular", 16)),
                    betas=(0.0, 0.02), cycling=(0.0, 1.0), t_fit=3.0, selects=(1.0, 0.1), select_betas=(0.0,)),
}


def driver(cycling: float) -> dict[str, Any]:
    """The [driver] table of sigma_theta / Ntilde = ``cycling`` (0: theta stands still)."""
    if cycling == 0.0:
        return {"name": "constant", "theta0": 0.0}
    return {"name": "gaussian_steps", "sigma_theta": cycling * NTILDE}


def point_config(kind: str, N: int, beta: float, preset: Preset, select: float = 1.0) -> dict[str, Any]:
    """The configuration of one system at one beta and one injection, as a plain dict (the sweep adds the
    driver)."""
    network: dict[str, Any] = {"kind": "chain" if kind == "pair" else kind, "n": N, "Ntilde": NTILDE}
    if kind == "irregular":
        network["seed"] = 0
    friction: dict[str, Any] = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
    if beta > 0.0:
        friction["strengthening"] = {"law": "log", "beta": beta, "tau_c": TAU_C}
    return {"seed": 1, "realizations": preset.realizations, "steps": preset.steps, "record": "log",
            "log_points_per_decade": preset.per_decade, "mu_eff_at": "records",
            "observables": ["n", "mu_max", "mu_eff", "mu_eff_realization", "contact_age"],
            "network": network, "friction": friction, "driver": driver(preset.cycling[0]),
            "tilt": {"inject": {"c": INJECT_C, "t0": 1.0, "select": select}}}


def _estimate(values: np.ndarray) -> dict[str, float]:
    """Mean and standard error over realizations, and how many had a finite value."""
    mean, sem, count = mean_sem(values)
    return {"mean": mean, "sem": sem, "count": count}


def _at(values: xr.DataArray, t: float) -> dict[str, float] | None:
    """:func:`_estimate` at recorded time t (None if t is not recorded)."""
    return _estimate(values.sel(t=t).values) if t in values["t"].values else None


def age_quantiles(ds: xr.Dataset) -> dict[str, Any]:
    """The 90th and 99th percentiles and the largest of the contact ages at every recorded time, as bounds.

    ``contact_age_count`` is summed over realizations: these are quantiles
    of the pooled (realization, node) ages, read from the histogram by
    :func:`slidernet.analysis.observables.binned_quantile` as the bin that
    holds them, [lo, hi) with 4 bins per decade; every age at t is at most
    t, so hi is clipped to t. The largest age is known exactly only where
    t is a bin edge (t = 1, 10, 100, 1000) and some contact never slipped:
    it is then t, and that bin holds exactly those contacts.
    """
    count = ds["contact_age_count"].transpose("t", "contact_age_bin").values
    lower, upper = ds["contact_age_bin"].values, ds["contact_age_upper"].values
    t = ds["t"].values.astype(float)
    out: dict[str, Any] = {"t": t.tolist()}
    for name, q in AGE_QUANTILES.items():
        lo, hi = binned_quantile(count, lower, upper, q)
        out[name] = [[float(a), float(min(b, tk))] for a, b, tk in zip(lo, hi, t, strict=True)]
    # The bin [t, ...) where t is an edge: the contacts of age exactly t, those that never slipped.
    at_edge = np.isin(t, lower) & (t > 0)
    k = np.searchsorted(lower, t, side="right") - 1
    never = count[np.arange(t.size), k]
    out["max_exact"] = [bool(e and n > 0) for e, n in zip(at_edge, never, strict=True)]
    out["never_slipped_share"] = [float(n / c.sum()) if e else None
                                  for e, n, c in zip(at_edge, never, count, strict=True)]
    return out


def _shift(t: xr.DataArray, inject: InjectConfig) -> xr.DataArray:
    """The injected shift c ln(1 + t / t0) at the recorded times, as one realization."""
    return xr.DataArray(inject.c * np.log1p(t.values / inject.t0)[None, :], dims=("realization", "t"),
                        coords={"t": t.values})


def recovery(ds: xr.Dataset, inject: InjectConfig, N: int, t_min: float) -> dict[str, Any]:
    """mu_eff's recovery of the injection over t_min <= t <= t_end: against the per-contact and the mean shift.

    recovery = (slope with injection - slope without, paired per
    realization) / (the slope of the injected shift c ln(1 + t / t0),
    fitted by :func:`log_trend` over the same window): the definition of
    ``examples/aging_recovery.py``. One geometry per size: every
    realization is independent (no groups).
    """
    share = inject.raised(N) / N  # the mean shift over the network, per unit of the per-contact shift
    rate = float(log_trend(_shift(ds["t"], inject), t_min=t_min)["slope"][0])
    slopes = [log_trend(ds[v].transpose("realization", "t"), t_min=t_min)["slope"].values
              for v in ("mu_eff_realization", "mu_eff_injected_realization")]
    out: dict[str, Any] = {"select": inject.select, "c": inject.c, "raised": inject.raised(N), "share": share,
                           "rate_per_decade": LN10 * rate,
                           "plain_slope_per_decade": LN10 * float(np.nanmean(slopes[0]))}
    for norm, r in (("contact", rate), ("mean", share * rate)):
        rec = injection_recovery(*slopes, r)
        out[norm] = {"recovery": rec.recovery, "sem": rec.recovery_sem, "dof": rec.dof, "pairs": rec.pairs,
                     "response_per_decade": LN10 * rec.response,
                     "response_sem_per_decade": LN10 * rec.response_sem}
    return out


def reduce_point(kind: str, N: int, beta: float, cycling: float, ds: xr.Dataset, preset: Preset,
                 config: dict[str, Any]) -> dict[str, Any]:
    """Every number of one point."""
    q = ds["mu_eff_realization"].transpose("realization", "t")
    age = ds["contact_age"].transpose("realization", "t")
    t_end = float(ds["t"].values[-1])
    trend = log_trend(q, t_min=preset.t_fit)
    slope_q = LN10 * trend["slope"].values
    r_node = ds["n"].isel(t=-1).values / (N * t_end)  # slips per node per tau_th, per realization
    age_end = age.isel(t=-1).values
    # The ages of every (realization, node) at t_end, binned on the fixed edges (4 per decade): the share in
    # the bin that holds t_end (for t_end = 1e2 or 1e3, an edge, exactly the contacts that never slipped) and
    # the bin that holds the median age.
    count = ds["contact_age_count"].isel(t=-1).values
    lower, upper = ds["contact_age_bin"].values, ds["contact_age_upper"].values
    last = int(np.searchsorted(lower, t_end, side="right")) - 1
    median = int(np.searchsorted(np.cumsum(count), 0.5 * count.sum()))
    point = {
        "kind": kind, "N": N, "beta": beta, "tau_c": TAU_C, "cycling": cycling,
        "share_in_t_end_bin": float(count[last] / count.sum()), "t_end_bin": [float(lower[last]),
                                                                               float(upper[last])],
        "median_age_bin": [float(lower[median]), float(upper[median])],
        "realizations": int(ds.sizes["realization"]), "t_end": t_end,
        "times": {f"{t:g}": {"mu_eff": _at(q, t), "mu_max": _at(ds["mu_max"], t), "contact_age": _at(age, t)}
                  for t in sorted({*(t for t in REPORT_TIMES if t < t_end), t_end})},
        "mu_eff_slope_per_decade": _estimate(slope_q),
        "mu_max_slope_per_decade": _estimate(LN10 * log_trend(ds["mu_max"], t_min=preset.t_fit)["slope"].values),
        "r_node": _estimate(r_node),
        "contact_age_end": _estimate(age_end),
        # <a> r_node per realization: 1 for contacts renewed at random (a Poisson renewal) at the rate r_node.
        "age_times_rate": _estimate(age_end * r_node) if (r_node > 0).all() else None,
        # What strengthening would add to a contact as old as the run, and to one of the mean age measured.
        "strength_run_age": beta * math.log1p(t_end / TAU_C),
        "strength_mean_age": beta * math.log1p(float(np.mean(age_end)) / TAU_C),
        # The strengthening rate per decade of a contact that never slips, for t >> tau_c: beta ln 10.
        "strength_slope_per_decade": beta * LN10,
        "age_quantiles": age_quantiles(ds),
        "recovery": {f"{preset.selects[0]:g}": recovery(ds, InjectConfig(**config["tilt"]["inject"]), N,
                                                        preset.t_fit)},
        "curves": {"t": ds["t"].values.tolist(),
                   "mu_eff": q.mean("realization").values.tolist(),
                   "contact_age": age.mean("realization").values.tolist()},
        "config": config,
    }
    return point


def run_system(kind: str, N: int, beta: float, preset: Preset, workers: int | None, scheduler: str | None,
               out: Path | None, resume: bool,
               select: float = 1.0) -> list[tuple[float, xr.Dataset, dict[str, Any]]]:
    """One system at one beta and one injection over every cycling amplitude: one sweep of the [driver] table
    per duration."""
    runs = []
    for steps in sorted({preset.steps_for(kind, c) for c in preset.cycling}, reverse=True):
        cyclings = [c for c in preset.cycling if preset.steps_for(kind, c) == steps]
        cfg = point_config(kind, N, beta, preset, select)
        cfg["steps"] = steps
        where = None if out is None else (out / "sweeps" / f"{kind}_{N}" / f"beta_{beta:g}" / f"select_{select:g}"
                                          / f"steps_{steps}")
        result = sweep(cfg, {"driver": [driver(c) for c in cyclings]}, workers=workers, scheduler=scheduler,
                       out=where, resume=resume and where is not None and (where / "sweep.json").exists(),
                       overwrite=not resume, progress=None)
        ds = result.to_dataset() if isinstance(result, xr.DataTree) else result
        configs = json.loads(ds.attrs["configs"])
        dim = ds["mu_max"].dims[0]
        runs += [(c, ds.isel({dim: i}).drop_vars(dim, errors="ignore"), configs[i])
                 for i, c in enumerate(cyclings)]
    return sorted(runs, key=lambda run: preset.cycling.index(run[0]))


def _pm(e: dict[str, float] | None, scale: float = 1.0, digits: int = 4) -> str:
    if e is None:
        return "–"
    return f"{e['mean'] * scale:.{digits}f} ± {e['sem'] * scale:.{digits}f}"


def _recovery(rec: dict[str, Any]) -> dict[str, float]:
    """A recovery in the form :func:`_pm` reads."""
    return {"mean": rec["recovery"], "sem": rec["sem"]}


def _bin(edges: list[float]) -> str:
    return f"[{edges[0]:.2g}, {edges[1]:.2g})"


def tables(data: dict[str, Any]) -> str:
    """The guide's tables, from the JSON."""
    lines = ["| system | β | σ_θ/Ñ | t_end | μ_eff(0) | μ_eff(1) | μ_eff(t_end) | slope (1e−4/decade) "
             "| β ln10 (1e−4) | ⟨a⟩(t_end) (τ_th) | median a (τ_th) | ages in t_end's bin (never slipped) "
             "| r_node (1/τ_th) | ⟨a⟩ r_node | β ln(1+⟨a⟩/τ_c) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in data["points"]:
        t_end = f"{p['t_end']:g}"
        name = "pair" if p["kind"] == "pair" else f"{p['kind']} {p['N']}"
        ar = p["age_times_rate"]
        lines.append(
            f"| {name} | {p['beta']:g} | {p['cycling']:g} | {t_end} | {_pm(p['times']['0']['mu_eff'])} "
            f"| {_pm(p['times']['1']['mu_eff'])} | {_pm(p['times'][t_end]['mu_eff'])} "
            f"| {_pm(p['mu_eff_slope_per_decade'], 1e4, 1)} | {p['strength_slope_per_decade'] * 1e4:.1f} "
            f"| {_pm(p['contact_age_end'], 1.0, 3)} | {_bin(p['median_age_bin'])} "
            f"| {p['share_in_t_end_bin']:.3f} | {_pm(p['r_node'], 1.0, 3)} "
            f"| {'–' if ar is None else _pm(ar, 1.0, 2)} | {p['strength_mean_age']:.4f} |")
    return "\n".join(lines) + "\n"


def _name(p: dict[str, Any]) -> str:
    return "pair" if p["kind"] == "pair" else f"{p['kind']} {p['N']}"


def _age_bound(edges: list[float], exact: bool) -> str:
    """A quantile's bin [lo, hi) as "lo–hi" (hi clipped to t: then a closed bound), or "= t" where exact."""
    lo, hi = edges
    return f"= {lo:.3g}" if exact or lo == hi else f"{lo:.2g}–{hi:.2g}"


def age_table(data: dict[str, Any]) -> str:
    """The ages' tail: the bins of the 90th and 99th percentiles and of the largest age at t = 1, 10, 100 and
    t_end, from the JSON."""
    times = sorted({t for p in data["points"] for t in (1.0, 10.0, 100.0, p["t_end"])})
    head = " | ".join(f"{name} at t = {t:g}" for t in times for name in ("90th", "99th", "max"))
    lines = [f"| system | β | σ_θ/Ñ | {head} |", "|---|---|---|" + "---|" * (3 * len(times))]
    for p in data["points"]:
        a = p["age_quantiles"]
        cells = []
        for t in times:
            if t not in a["t"]:
                cells += ["–"] * 3
                continue
            i = a["t"].index(t)
            cells += [_age_bound(a["q90"][i], False), _age_bound(a["q99"][i], False),
                      _age_bound(a["max"][i], a["max_exact"][i])]
        lines.append(f"| {_name(p)} | {p['beta']:g} | {p['cycling']:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def recovery_table(data: dict[str, Any]) -> str:
    """mu_eff's recovery of the injected aging, from the JSON: select 1 at every point, and the other
    selections where they ran (against the per-contact shift and the mean shift over the network)."""
    selects = data["inject"]["selects"]
    others = " | ".join(f"recovery, select {q:g}: per contact | mean shift (share)" for q in selects[1:])
    lines = ["| system | β | σ_θ/Ñ | t_end | slope of μ_eff, plain (1e−4/decade) | response, select 1 "
             f"(1e−4/decade) | recovery, select 1 | {others} |",
             "|---|---|---|---|---|---|---|" + "---|---|" * (len(selects) - 1)]
    for p in data["points"]:
        first = p["recovery"][f"{selects[0]:g}"]
        c = first["contact"]
        cells = [f"{first['plain_slope_per_decade'] * 1e4:+.1f}",
                 f"{c['response_per_decade'] * 1e4:+.1f} ± {c['response_sem_per_decade'] * 1e4:.1f}",
                 _pm(_recovery(c), 1.0, 2)]
        for q in selects[1:]:
            rec = p["recovery"].get(f"{q:g}")
            cells += (["–", "–"] if rec is None else
                      [_pm(_recovery(rec["contact"]), 1.0, 2), f"{_pm(_recovery(rec['mean']), 1.0, 2)} "
                                                              f"({rec['share']:.3g})"])
        lines.append(f"| {_name(p)} | {p['beta']:g} | {p['cycling']:g} | {p['t_end']:g} | " + " | ".join(cells)
                     + " |")
    return "\n".join(lines) + "\n"


def all_tables(data: dict[str, Any]) -> str:
    """Every table of the guide, from the JSON: the full table, the ages' tail and the recovery."""
    return (f"### Full table\n\n{tables(data)}\n### The ages' tail\n\n{age_table(data)}\n"
            f"### Recovery of the injected aging\n\n{recovery_table(data)}")


def plot(data: dict[str, Any], path: Path) -> Path:
    """mu_eff(t), the mean contact age and the 99th percentile of the ages against t: a column per beta, a line
    per system and amplitude."""
    betas = sorted({p["beta"] for p in data["points"]})
    fig = Figure(figsize=(5.0 * len(betas), 10.5), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(3, len(betas), squeeze=False)
    cyclings = sorted({p["cycling"] for p in data["points"]})
    styles = dict(zip(cyclings, ["-", "--", "-.", ":"], strict=False))
    systems = list(dict.fromkeys((p["kind"], p["N"]) for p in data["points"]))
    colors = {system: f"C{i}" for i, system in enumerate(systems)}  # a colour per system, a style per amplitude
    for col, beta in enumerate(betas):
        top, bottom, tail = axes[0, col], axes[1, col], axes[2, col]
        for p in (p for p in data["points"] if p["beta"] == beta):
            t = np.asarray(p["curves"]["t"], dtype=float)
            keep = t > 0
            label = f"{'pair' if p['kind'] == 'pair' else p['kind'] + ' ' + str(p['N'])}, σ_θ/Ñ = {p['cycling']:g}"
            style = {"ls": styles[p["cycling"]], "color": colors[(p["kind"], p["N"])], "lw": 1}
            top.plot(t[keep], np.asarray(p["curves"]["mu_eff"])[keep], label=label, **style)
            bottom.plot(t[keep], np.asarray(p["curves"]["contact_age"])[keep], **style)
            # The upper edge of the bin that holds the 99th percentile (clipped to t): a bound from above.
            tail.plot(t[keep], np.asarray(p["age_quantiles"]["q99"])[keep, 1], **style)
        top.set(xscale="log", title=f"β = {beta:g}" + (" (no strengthening)" if beta == 0 else ""),
                ylabel="μ_eff (network tilt test)")
        bottom.set(xscale="log", yscale="log", ylabel="mean contact age (τ_th)")
        tail.set(xscale="log", yscale="log", xlabel="t (τ_th)")
        tail.set_ylabel("99th percentile of the ages: its bin's upper edge (τ_th)", fontsize=8)
    axes[0, -1].legend(fontsize=6, ncol=2)
    return save_figure(fig, path)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("rejuvenation_out"),
                        help="output folder (default rejuvenation_out)")
    parser.add_argument("--quick", action="store_true", help="a small grid, short runs (seconds); "
                        "the same as --preset quick")
    parser.add_argument("--preset", choices=sorted(PRESETS), default="full", help="full (the study) or quick")
    parser.add_argument("--workers", type=int, default=None, help="worker processes per sweep point")
    parser.add_argument("--scheduler", default=None,
                        help="a Dask scheduler address, e.g. tcp://host:8786: realizations run on that cluster")
    parser.add_argument("--resume", action="store_true",
                        help="continue the sweeps of an interrupted run in --out (points already done are kept)")
    args = parser.parse_args(argv)

    name = "quick" if args.quick else args.preset
    preset = PRESETS[name]
    start = time.perf_counter()
    points = []
    for kind, N in preset.systems:
        for beta in preset.betas:
            t0 = time.perf_counter()
            for cycling, ds, config in run_system(kind, N, beta, preset, args.workers, args.scheduler, args.out,
                                                  args.resume):
                p = reduce_point(kind, N, beta, cycling, ds, preset, config)
                points.append(p)
                end = p["times"][f"{p['t_end']:g}"]
                print(f"{kind} {N} beta={beta:g} sigma/Ntilde={cycling:g}: mu_eff "
                      f"{_pm(p['times']['0']['mu_eff'])} -> {_pm(end['mu_eff'])}, "
                      f"age {_pm(p['contact_age_end'], 1.0, 3)}, recovery "
                      f"{_pm(_recovery(p['recovery'][f'{preset.selects[0]:g}']['contact']), 1.0, 2)}", flush=True)
            # The same runs again under the other injections (the plain outputs are the same to the bit).
            for select in preset.selects[1:] if beta in preset.select_betas else ():
                by_cycling = {(p["kind"], p["N"], p["beta"], p["cycling"]): p for p in points}
                for cycling, ds, config in run_system(kind, N, beta, preset, args.workers, args.scheduler,
                                                      args.out, args.resume, select):
                    rec = recovery(ds, InjectConfig(**config["tilt"]["inject"]), N, preset.t_fit)
                    by_cycling[(kind, N, beta, cycling)]["recovery"][f"{select:g}"] = rec
            print(f"{kind} {N} beta={beta:g}: {time.perf_counter() - t0:.1f} s", flush=True)
    data = {
        "question": "does thermal cycling cap the age of contacts, and with it the aging that contact "
                    "strengthening gives mu_eff?",
        "preset": name,
        "estimator": "network tilt test at every recorded time (mu_eff_at = 'records'); trends: log_trend, "
                     f"per-realization slopes against ln t for t >= {preset.t_fit:g}; errors from independent "
                     "realizations (one network geometry per irregular size)",
        "inject": {"c": INJECT_C, "t0": 1.0, "selects": list(preset.selects),
                   "recovery": "(paired slope of mu_eff with injection - without) / (slope of the injected "
                               f"shift), both by log_trend over {preset.t_fit:g} <= t <= t_end"},
        "age_quantiles": "bins of the pooled (realization, node) ages that hold the 90th and 99th percentiles "
                         "and the largest (binned_quantile on contact_age_count), the upper edge clipped to t",
        "preset_settings": dataclasses.asdict(preset),
        "points": points,
        "slidernet_version": slidernet.__version__,
    }
    data["wall_time_s"] = time.perf_counter() - start
    print(write_json(data, args.out / JSON_NAME))
    with atomic_output(args.out / TABLES_NAME) as tmp:
        tmp.write_text(all_tables(data))
    print(args.out / TABLES_NAME)
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
