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

Every error is a standard error over the independent realizations.

The grid of the full preset (16 realizations per point, seed 1, network seed 0):

* free-end chains (kind ``chain``; n = 2 runs on the pair kernel) of 2, 4, 8
  and 16 sliders, to T = 1e4 tau_th;
* irregular 2D networks (kind ``irregular``: random points joined by their
  Delaunay triangulation) of 16 sliders to 1e4 tau_th, 64 to 3e3 and 256 to
  1e3 tau_th (the cost grows like the slips, about 11 000 per tau_th at 256).

Writes ``creep_networks.json`` (every number, with its parameters and the
configurations) and ``creep_networks.png`` into ``--out``::

    python examples/creep_networks.py --out creep_net_out --workers 2   # ~5 min on 2 cores
    python examples/creep_networks.py --out creep_net_out --quick       # seconds

Units: lengths in l0, time in tau_th, forces in N (f_ext shares the friction
coefficients' scale), theta dimensionless; Ntilde = N / (k l0).
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
from slidernet.analysis.trend import creep_law, mean_sem
from slidernet.ensemble.sweep import sweep
from slidernet.io import save_figure, write_json

try:
    BASE_TOML = Path(__file__).resolve().with_name("creep_networks.toml")
except NameError:  # sphinx-gallery defines no __file__; it runs the script from examples/
    BASE_TOML = Path("creep_networks.toml").resolve()
JSON_NAME = "creep_networks.json"
PNG_NAME = "creep_networks.png"
Z = 2.0          # the verdicts' threshold, in standard errors


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
class Preset:
    """The whole study: its sweeps and the number of realizations per point."""

    realizations: int
    groups: tuple[Group, ...]


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
    ),
    # A second or two of runs once the kernels are compiled.
    "quick": Preset(
        realizations=8,
        groups=(
            Group("chains", "chain", (2, 4), 1_000),
            Group("irregular_16", "irregular", (16,), 300),
        ),
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


def run_group(group: Group, realizations: int, workers: int | None, log: bool = True) -> list[dict[str, Any]]:
    """Run one sweep over the sizes of a group and reduce every point to its numbers."""
    cfg = group_config(group, realizations)
    start = time.perf_counter()
    result = sweep(cfg, {"network.n": list(group.sizes)}, workers=workers, progress=None)
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


def plot(data: dict[str, Any], path: Path) -> Path:
    """v against N, the velocity ratio against N with both laws, and v(t); written atomically to ``path``."""
    fig = Figure(figsize=(13, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax_v, ax_r, ax_t = fig.subplots(1, 3)
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
    ax_v.legend(fontsize=8)
    ax_r.axhline(1.0, color="k", lw=1, ls="--", label="steady creep ($x_G \\propto t$): 1")
    ax_r.axhline(0.1, color="0.5", lw=1, ls=":", label=r"logarithmic ($x_G \propto \ln t$): 0.1"
                 "\n(bars: each point's, from its times)")
    ax_r.set_xscale("log", base=2)
    ax_r.set_ylim(0, 1.6)
    ax_r.set_xlabel("number of sliders N")
    ax_r.set_ylabel(r"$\langle v\rangle_{[T/10,\,T]} / \langle v\rangle_{[T/100,\,T/10]}$")
    ax_r.set_title("(b) does the creep slow down? ratio of the mean velocities", fontsize=9)
    ax_r.legend(fontsize=7, loc="lower left")
    ax_t.set_xscale("log")
    ax_t.set_yscale("log")
    ax_t.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax_t.set_ylabel(r"mean velocity over log windows  [$l_0/\tau_\mathrm{th}$]")
    ax_t.set_title("(c) velocity against time (4 windows per decade)", fontsize=9)
    ax_t.legend(fontsize=6, ncol=2)
    return save_figure(fig, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("creep_net_out"),
                        help="output folder (default creep_net_out)")
    parser.add_argument("--quick", action="store_true", help="small networks, short runs (seconds)")
    parser.add_argument("--workers", type=int, default=None, help="worker processes per sweep point")
    args = parser.parse_args(argv)

    name = "quick" if args.quick else "full"
    preset = PRESETS[name]
    start = time.perf_counter()
    base = base_config(preset.realizations)
    points: list[dict[str, Any]] = []
    for group in preset.groups:
        points += run_group(group, preset.realizations, args.workers)
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
        },
        "parameters": {"mu_d": mu_d, "mu_s_mean": base["friction"]["static"]["mean"],
                       "mu_s_std": base["friction"]["static"]["std"], "Ntilde": base["network"]["Ntilde"],
                       "f_ext": base["network"]["f_ext"], "f_ext_over_mu_d": base["network"]["f_ext"] / mu_d,
                       "sigma_theta": base["driver"]["sigma_theta"],
                       "sigma_theta_over_Ntilde": base["driver"]["sigma_theta"] / base["network"]["Ntilde"],
                       "seed": base["seed"], "realizations": preset.realizations, "irregular_network_seed": 0,
                       "z": Z},
        "base_config": base,
        "groups": [dataclasses.asdict(g) for g in preset.groups],
        "points": points,
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
