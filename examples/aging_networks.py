"""Does thermal cycling age the static friction of a network of sliders?
=====================================================================

The paper (Geminard & Bertin 2010) ends on an open question: in a 2D
irregular network of sliders, does the effective friction coefficient still
increase with time under thermal cycling? This study measures it, from the
base configuration ``examples/aging_networks.toml`` (mu_d = 0.5, gaussian
mu_s of mean 0.6, Ntilde = 1e-7, driver ``gaussian_steps``, record "log").

Estimator: ``mu_eff_at = "records"``, the network tilt test at every
recorded time, for every network, the pair included: the same estimator at
every size. mu_max (the strongest threshold) is reported beside it; it is
not mu_eff. Every trend is :func:`slidernet.analysis.trend.log_trend` of a
per-realization variable (``mu_eff_realization``, ``mu_max``, ``x_G**2``):
slopes against ln t fitted per realization, errors from their spread over
independent realizations. The mechanism (selection of strong thresholds,
prestress) comes from :func:`slidernet.analysis.mechanism.node_states` at
t = 0 and at the end, for a few sizes.

The grid of the full preset (16 realizations per point, seed 1, network
seed 0):

* chains (kind ``chain``; n = 2 runs on the pair kernel) of 2, 3, 4, 8, 16
  sliders x friction.static.std 0.01, 0.02, 0.03 (sigma_mu / (mean - mu_d)
  = 0.1, 0.2, 0.3) at sigma_theta / Ntilde = 1, 1e4 tau_th;
* the same chains at sigma_theta / Ntilde = 10, std 0.01, 1e4 tau_th;
* irregular 2D networks (kind ``irregular``) of 16 and 64 sliders x std
  0.01, 0.02, 0.03, 1e4 tau_th, and of 256 sliders, std 0.01, 3e3 tau_th,
  all at sigma_theta / Ntilde = 1;
* irregular 16 and 64 at sigma_theta / Ntilde = 10, std 0.01, 1e3 tau_th;
* irregular 1024, std 0.01, sigma_theta / Ntilde = 1, to 300 tau_th, 10
  recorded times per decade;
* a replica of the chains of 8 and 16 at std 0.01, sigma_theta / Ntilde = 1,
  1e4 tau_th, with seed 2 and 64 realizations (independent of the first);
* mechanism (node_states at t = 0 and at the end): chains of 2, 4, 16,
  irregular networks of 16 and 64.

Every point also records ``tilt_loads``: the load of the tilt test's first
slip, and the load at which one of its avalanches first set every slider in
motion, above mu_d or not, so that the answer does not rest on the tilt
test's sliding rule alone.

Cuts of the grid: 4096 sliders only in the ``large`` preset (8 realizations,
to 300 tau_th, 5 recorded times per decade: the tilt test's cost grows
fastest with size); std 0.02 and 0.03 not at 256 or 1024 sliders; sigma_theta / Ntilde =
10 only at std 0.01, only to 1e3 tau_th for the irregular networks and not
at 256 or above; 256 sliders only to 3e3 tau_th, 1024 to 300 tau_th.

Writes ``aging_networks.json`` (every number, with its parameters and the
configurations) and ``aging_networks.png`` into ``--out``::

    python examples/aging_networks.py --out aging_out --workers 2                 # the full preset
    python examples/aging_networks.py --out aging_out --quick                     # seconds
    python examples/aging_networks.py --out aging_large --preset large --workers 2  # 4096 sliders

Units: time in tau_th, friction coefficients dimensionless, x_G in l0.
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
from slidernet.analysis.mechanism import node_states, node_summary
from slidernet.analysis.trend import log_trend, mean_sem
from slidernet.ensemble.sweep import sweep
from slidernet.io import save_figure, write_json

try:
    BASE_TOML = Path(__file__).resolve().with_name("aging_networks.toml")
except NameError:  # sphinx-gallery defines no __file__; it runs the script from examples/
    BASE_TOML = Path("aging_networks.toml").resolve()
JSON_NAME = "aging_networks.json"
PNG_NAME = "aging_networks.png"
LN10 = math.log(10.0)


@dataclasses.dataclass(frozen=True)
class Group:
    """One sweep of the study: a network kind, a grid and a duration.

    Attributes
    ----------
    name : str
        Label of the group in the JSON output.
    kind : str
        Network kind: ``chain`` or ``irregular``.
    sizes : tuple of int
        Numbers of sliders (``network.n``).
    stds : tuple of float
        Values of ``friction.static.std``.
    sigma_ratio : float
        sigma_theta / Ntilde.
    steps : int
        Duration in tau_th.
    realizations : int, optional
        Realizations per point, when not the preset's.
    per_decade : int
        Recorded times per decade of t (``log_points_per_decade``): fewer
        tilt tests for the largest networks, where each costs most.
    seed : int, optional
        The ensemble's seed, when not the base configuration's (a replica
        with independent realizations).
    """

    name: str
    kind: str
    sizes: tuple[int, ...]
    stds: tuple[float, ...]
    sigma_ratio: float
    steps: int
    realizations: int | None = None
    per_decade: int = 20
    seed: int | None = None


@dataclasses.dataclass(frozen=True)
class Preset:
    """The whole study: its sweeps, ensemble size and the mechanism runs."""

    realizations: int
    groups: tuple[Group, ...]
    mechanism: tuple[tuple[str, int, int], ...]   # (kind, n, steps)


PRESETS = {
    "full": Preset(
        realizations=16,
        groups=(
            Group("chains", "chain", (2, 3, 4, 8, 16), (0.01, 0.02, 0.03), 1.0, 10_000),
            Group("chains_sigma10", "chain", (2, 3, 4, 8, 16), (0.01,), 10.0, 10_000),
            Group("irregular", "irregular", (16, 64), (0.01, 0.02, 0.03), 1.0, 10_000),
            Group("irregular_256", "irregular", (256,), (0.01,), 1.0, 3_000),
            Group("irregular_sigma10", "irregular", (16, 64), (0.01,), 10.0, 1_000),
            Group("irregular_1024", "irregular", (1024,), (0.01,), 1.0, 300, per_decade=10),
            # An independent replica (seed 2, 64 realizations) of the two chain
            # points that the first run found positive by about 3 standard errors.
            Group("chains_replica", "chain", (8, 16), (0.01,), 1.0, 10_000, realizations=64, seed=2),
        ),
        mechanism=(("chain", 2, 10_000), ("chain", 4, 10_000), ("chain", 16, 10_000),
                   ("irregular", 16, 10_000), ("irregular", 64, 10_000)),
    ),
    # Beyond the full preset's budget: 4096 sliders, 8 realizations, to 300 tau_th.
    "large": Preset(
        realizations=8,
        groups=(Group("irregular_4096", "irregular", (4096,), (0.01,), 1.0, 300, per_decade=5),),
        mechanism=(),
    ),
    "quick": Preset(
        realizations=4,
        groups=(
            Group("chains", "chain", (2, 4), (0.01, 0.02), 1.0, 300),
            Group("irregular", "irregular", (16,), (0.01,), 1.0, 100),
        ),
        mechanism=(("chain", 4, 300),),
    ),
}


def base_config(realizations: int) -> dict[str, Any]:
    """The study's base configuration (``aging_networks.toml``) as a plain dict."""
    cfg = slidernet.load_config(BASE_TOML).model_dump(mode="json")
    cfg["realizations"] = realizations
    return cfg


def group_config(group: Group, realizations: int) -> dict[str, Any]:
    """The base configuration of one sweep (kind, duration, sigma_theta)."""
    cfg = base_config(realizations if group.realizations is None else group.realizations)
    ntilde = cfg["network"]["Ntilde"]
    cfg["steps"] = group.steps
    cfg["log_points_per_decade"] = group.per_decade
    if group.seed is not None:
        cfg["seed"] = group.seed
    cfg["network"] = {"kind": group.kind, "n": group.sizes[0], "Ntilde": ntilde}
    if group.kind == "irregular":
        cfg["network"]["seed"] = 0
    cfg["driver"] = {**cfg["driver"], "sigma_theta": group.sigma_ratio * ntilde}
    return cfg


def _trend(values: xr.DataArray) -> dict[str, Any]:
    """log_trend of one per-realization variable, with its value at t = 0, as plain numbers."""
    tr = log_trend(values, t_min=1)
    t0_mean, t0_sem, t0_count = mean_sem(values.sel(t=0).values)
    return {
        "t0_mean": t0_mean, "t0_sem": t0_sem, "t0_realizations": t0_count,
        "start_mean": float(tr["start_mean"]), "start_sem": float(tr["start_sem"]),
        "t_start": tr.attrs["t_start"],
        "end_mean": float(tr["end_mean"]), "end_sem": float(tr["end_sem"]), "t_end": tr.attrs["t_end"],
        "slope_per_ln_t_mean": float(tr["slope_mean"]), "slope_per_ln_t_sem": float(tr["slope_sem"]),
        "slope_per_decade_mean": LN10 * float(tr["slope_mean"]),
        "slope_per_decade_sem": LN10 * float(tr["slope_sem"]),
        "realizations": int(tr["realizations"]),
    }


def _curve(values: xr.DataArray) -> dict[str, list[float]]:
    """Mean and standard error over realizations at every recorded time."""
    v = values.transpose("realization", "t").values
    count = np.isfinite(v).sum(axis=0)
    mean = np.nanmean(np.where(count > 0, v, 0.0), axis=0)
    std = np.nanstd(v, axis=0, ddof=1) if v.shape[0] > 1 else np.full(v.shape[1], np.nan)
    sem = std / np.sqrt(np.maximum(count, 1))
    return {"t": values["t"].values.tolist(), "mean": mean.tolist(), "sem": sem.tolist(), "count": count.tolist()}


def _below(values: xr.DataArray, mu_d: float) -> dict[str, Any]:
    """Per realization, the fraction of its tilt tests at t >= 1 whose collective motion began below mu_d.

    One fraction per realization, so that the mean's error comes from
    independent realizations.
    """
    v = values.sel(t=values["t"] >= 1).transpose("realization", "t").values
    tested = np.isfinite(v)
    frac = np.where(tested.any(axis=1), (tested & (v < mu_d)).sum(axis=1) / np.maximum(tested.sum(axis=1), 1),
                    np.nan)
    mean, sem, count = mean_sem(frac)
    return {"mean": mean, "sem": sem, "realizations": count}


def run_group(group: Group, realizations: int, workers: int | None, out: Path | None, resume: bool,
              log: bool = True, scheduler: str | None = None) -> list[dict[str, Any]]:
    """Run one sweep and reduce every point to its numbers."""
    cfg = group_config(group, realizations)
    grid: dict[str, list[Any]] = {"network.n": list(group.sizes), "friction.static.std": list(group.stds)}
    start = time.perf_counter()
    where = None if out is None else out / "sweeps" / group.name
    result = sweep(cfg, grid, workers=workers, scheduler=scheduler, out=where, resume=resume and where is not None
                   and (where / "sweep.json").exists(), overwrite=not resume, progress=None)
    ds = result.to_dataset() if isinstance(result, xr.DataTree) else result
    configs = json.loads(ds.attrs["configs"])
    elapsed = time.perf_counter() - start
    dims = ds["mu_max"].dims[:2]   # the sweep's dimensions, in the grid's order
    points = []
    for i, n in enumerate(group.sizes):
        for j, std in enumerate(group.stds):
            one = ds.isel({dims[0]: i, dims[1]: j})
            x2 = one["x_G"] ** 2
            point = {
                "group": group.name, "kind": group.kind, "n": n, "std": std,
                "std_over_gap": std / (0.6 - 0.5), "sigma_theta_over_Ntilde": group.sigma_ratio,
                "steps": group.steps, "realizations": cfg["realizations"], "seed": cfg["seed"],
                "r_mean": float(one["r_mean"]), "r_sem": float(one["r_sem"]),
                "mu_eff": _trend(one["mu_eff_realization"]),
                "mu_max": _trend(one["mu_max"]),
                "x_G2": _trend(x2),
                # What mu_eff rests on: the tilt test's first slip, and the load
                # at which one of its avalanches first set every slider moving.
                "tilt_first_slip": _trend(one["tilt_first_slip"]),
                "tilt_all_moving": _trend(one["tilt_all_moving"]),
                "all_moving_below_mu_d": _below(one["tilt_all_moving"], cfg["friction"]["mu_d"]),
                "curves": {"mu_eff": _curve(one["mu_eff_realization"]), "mu_max": _curve(one["mu_max"]),
                           "x_G2": _curve(x2), "tilt_all_moving": _curve(one["tilt_all_moving"])},
                "config": configs[i * len(group.stds) + j],
                "kernel": json.loads(ds.attrs["kernels"])[i * len(group.stds) + j]
                if "kernels" in ds.attrs else ds.attrs["kernel"],
            }
            points.append(point)
            if log:
                e = point["mu_eff"]
                print(f"{group.name} n={n} std={std}: mu_eff {e['t0_mean']:.4f} -> {e['end_mean']:.4f} "
                      f"(slope/decade {e['slope_per_decade_mean']:+.5f} +- {e['slope_per_decade_sem']:.5f}), "
                      f"all moving at {point['tilt_all_moving']['end_mean']:.4f}, "
                      f"r = {point['r_mean']:.1f}/tau_th", flush=True)
    if log:
        print(f"{group.name}: {elapsed:.1f} s", flush=True)
    return points


def mechanism(kind: str, n: int, steps: int, realizations: int, log: bool = True) -> dict[str, Any]:
    """Thresholds and load ratios of every node at t = 0 and t = steps (std 0.01, sigma_theta / Ntilde = 1)."""
    group = Group("mechanism", kind, (n,), (0.01,), 1.0, steps)
    cfg = group_config(group, realizations)
    law_mean = float(slidernet.load_config(cfg).distribution().mean_max(1))
    states = node_states(cfg, [0, steps])
    summary = node_summary(states, law_mean=law_mean)
    out: dict[str, Any] = {"kind": kind, "n": n, "steps": steps, "realizations": realizations,
                           "law_mean": law_mean, "config": cfg}
    for name in ("mu_s_shift", "load_ratio", "mu_s"):
        for label, k in (("t0", 0), ("end", 1)):
            out[f"{name}_{label}_mean"] = float(summary[f"{name}_mean"].isel(t=k))
            out[f"{name}_{label}_sem"] = float(summary[f"{name}_sem"].isel(t=k))
    # The change per realization, so that its error comes from independent realizations.
    shift = (states["mu_s"].isel(t=1) - states["mu_s"].isel(t=0)).mean("node").values
    ratio = (states["load_ratio"].isel(t=1) - states["load_ratio"].isel(t=0)).mean("node").values
    out["mu_s_change_mean"], out["mu_s_change_sem"], _ = mean_sem(shift)
    out["load_ratio_change_mean"], out["load_ratio_change_sem"], _ = mean_sem(ratio)
    if log:
        print(f"mechanism {kind} {n}: shift {out['mu_s_shift_t0_mean']:+.5f} -> "
              f"{out['mu_s_shift_end_mean']:+.5f}, "
              f"load ratio {out['load_ratio_t0_mean']:.4f} -> {out['load_ratio_end_mean']:.4f}", flush=True)
    return out


def plot(data: dict[str, Any], path: Path) -> Path:
    """mu_eff(t) per size, slopes and the x_G^2 prefactor against N, mechanism; written atomically to ``path``."""
    fig = Figure(figsize=(11, 8.5), layout="constrained")
    FigureCanvasAgg(fig)
    (ax_t, ax_s), (ax_x, ax_m) = fig.subplots(2, 2)
    # The replica (another seed) is drawn on its own in panel (b), not as a second curve.
    replica = [p for p in data["points"] if p["group"] == "chains_replica"]
    first = [p for p in data["points"] if p["group"] != "chains_replica"]
    base = [p for p in first if p["std"] == 0.01 and p["sigma_theta_over_Ntilde"] == 1.0]
    for c, p in enumerate(base):
        cur = p["curves"]["mu_eff"]
        t, m, s = np.array(cur["t"], float), np.array(cur["mean"]), np.array(cur["sem"])
        keep = t >= 1
        ax_t.errorbar(t[keep], m[keep], yerr=s[keep], fmt="o-" if p["kind"] == "chain" else "s--", ms=3,
                      color=f"C{c % 10}", label=f"{p['kind']} {p['n']}", lw=0.8)
        # t = 0 cannot sit on a log axis: its mean is marked on the left edge.
        ax_t.plot([0], [p["mu_eff"]["t0_mean"]], ">", color=f"C{c % 10}", ms=7, clip_on=False,
                  transform=ax_t.get_yaxis_transform())
    ax_t.axhline(data["parameters"]["mu_d"], color="k", lw=0.6, ls=":")
    ax_t.set_xscale("log")
    ax_t.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax_t.set_ylabel(r"$\mu_\mathrm{eff}$ (tilt test at recorded times)")
    ax_t.set_title(r"(a) $\sigma_\mu/(\bar\mu_s-\mu_d) = 0.1$, $\sigma_\theta/\tilde N = 1$; "
                   r"mean $\pm$ SE; $\triangleright$: t = 0", fontsize=9)
    ax_t.legend(fontsize=7, ncol=2)

    markers = {("chain", 1.0): "o", ("irregular", 1.0): "s", ("chain", 10.0): "^", ("irregular", 10.0): "D"}
    for (kind, ratio), mk in markers.items():
        for k, std in enumerate((0.01, 0.02, 0.03)):
            pts = [p for p in first if p["kind"] == kind and p["sigma_theta_over_Ntilde"] == ratio
                   and p["std"] == std]
            if not pts:
                continue
            n = np.array([p["n"] for p in pts], float)
            lab = f"{kind}, std {std}, " + rf"$\sigma_\theta/\tilde N$ = {ratio:g}"
            ax_s.errorbar(n * (1 + 0.04 * k), [p["mu_eff"]["slope_per_decade_mean"] for p in pts],
                          yerr=[p["mu_eff"]["slope_per_decade_sem"] for p in pts], fmt=mk + "-", ms=4,
                          color=f"C{k}", mfc="none" if ratio == 10.0 else None, label=lab, lw=0.8)
            if std == 0.01:
                ax_x.errorbar(n, [p["x_G2"]["slope_per_ln_t_mean"] for p in pts],
                              yerr=[p["x_G2"]["slope_per_ln_t_sem"] for p in pts], fmt=mk + "-", ms=4,
                              color="C0" if ratio == 1.0 else "C3",
                              label=f"{kind}, " + rf"$\sigma_\theta/\tilde N$ = {ratio:g}")
    if replica:
        ax_s.errorbar([p["n"] * 0.96 for p in replica], [p["mu_eff"]["slope_per_decade_mean"] for p in replica],
                      yerr=[p["mu_eff"]["slope_per_decade_sem"] for p in replica], fmt="*", ms=7, color="k",
                      label=f"chain, std 0.01, replica (seed {replica[0]['seed']}, "
                            f"{replica[0]['realizations']} realizations)")
    ax_s.axhline(0, color="k", lw=0.6)
    ax_s.set_xscale("log")
    ax_s.set_xlabel("number of sliders N")
    ax_s.set_ylabel(r"$d\mu_\mathrm{eff}/d\log_{10} t$ (per decade)")
    ax_s.set_title("(b) aging rate of the tilt-test friction", fontsize=9)
    ax_s.legend(fontsize=6)
    ax_x.set_xscale("log")
    ax_x.set_yscale("log")
    ax_x.set_xlabel("number of sliders N")
    ax_x.set_ylabel(r"$d\langle x_G^2\rangle/d\ln t$  [$l_0^2$]")
    ax_x.set_title(r"(c) diffusion prefactor of the centre of mass", fontsize=9)
    ax_x.legend(fontsize=7)

    mech = data["mechanism"]
    labels = [f"{m['kind'][:5]} {m['n']}" for m in mech]
    x = np.arange(len(mech))
    # Four markers per network, grouped about its tick; the limits keep a lone network in the middle
    # (with one network, the autoscaled axis spread the markers over the whole width).
    for k, (label, key) in enumerate((("t = 0", "t0"), ("end", "end"))):
        ax_m.errorbar(x - 0.15 + 0.1 * k, [m[f"mu_s_shift_{key}_mean"] for m in mech],
                      yerr=[m[f"mu_s_shift_{key}_sem"] for m in mech], fmt="o", color=f"C{k}",
                      label=r"$\langle\mu_s\rangle - $ law mean, " + label)
    ax_m.axhline(0, color="k", lw=0.6)
    ax_m.set_xticks(x, labels, fontsize=8)
    ax_m.set_xlim(-0.5, len(mech) - 0.5)
    ax_m.set_ylabel("threshold shift (selection)")
    ax_r = ax_m.twinx()
    for k, (label, key) in enumerate((("t = 0", "t0"), ("end", "end"))):
        ax_r.errorbar(x + 0.05 + 0.1 * k, [m[f"load_ratio_{key}_mean"] for m in mech],
                      yerr=[m[f"load_ratio_{key}_sem"] for m in mech], fmt="s", color=f"C{k + 2}",
                      label=r"load ratio $|F|/(\mu_s N)$, " + label)
    ax_r.set_ylabel("mean load ratio (prestress)")
    ax_m.set_title("(d) mechanism: circles selection (left), squares prestress (right)", fontsize=9)
    h1, l1 = ax_m.get_legend_handles_labels()
    h2, l2 = ax_r.get_legend_handles_labels()
    ax_m.legend(h1 + h2, l1 + l2, fontsize=6, loc="center right")
    return save_figure(fig, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("aging_out"), help="output folder (default aging_out)")
    parser.add_argument("--quick", action="store_true", help="a small grid, short runs (seconds); "
                        "the same as --preset quick")
    parser.add_argument("--preset", choices=sorted(PRESETS), default="full",
                        help="full (the study, about 9 min on 2 cores), quick, or large (4096 sliders, "
                             "beyond the full preset's budget)")
    parser.add_argument("--workers", type=int, default=None, help="worker processes per sweep point")
    parser.add_argument("--scheduler", default=None,
                        help="a Dask scheduler address, e.g. tcp://host:8786: realizations run on that cluster")
    parser.add_argument("--resume", action="store_true",
                        help="continue the sweeps of an interrupted run in --out (points already done are kept)")
    args = parser.parse_args(argv)

    name = "quick" if args.quick else args.preset
    preset = PRESETS[name]
    start = time.perf_counter()
    base = base_config(preset.realizations)
    points: list[dict[str, Any]] = []
    for group in preset.groups:
        points += run_group(group, preset.realizations, args.workers, args.out, args.resume,
                            scheduler=args.scheduler)
    mech = [mechanism(kind, n, steps, preset.realizations) for kind, n, steps in preset.mechanism]
    data = {
        "question": "does thermal cycling increase mu_eff with time in networks of sliders?",
        "preset": name,
        "estimator": "network tilt test at every recorded time (mu_eff_at = 'records'), same at every size; "
                     "trends: log_trend (per-realization slopes vs ln t, t >= 1; errors from their spread)",
        "parameters": {"mu_d": base["friction"]["mu_d"], "mu_s_mean": base["friction"]["static"]["mean"],
                       "Ntilde": base["network"]["Ntilde"], "seed": base["seed"],
                       "realizations": preset.realizations, "irregular_network_seed": 0},
        "base_config": base,
        "groups": [dataclasses.asdict(g) for g in preset.groups],
        "points": points,
        "mechanism": mech,
        "slidernet_version": slidernet.__version__,
        "wall_time_s": None,
    }
    data["wall_time_s"] = time.perf_counter() - start
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
