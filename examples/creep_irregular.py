"""Creep of an irregular network under a constant load and thermal cycling
=======================================================================

The model: section 2 of :doc:`/model` (``docs/model.md``).

An irregular network (``n`` random points joined by their Delaunay
triangulation, a fixed network seed) carries the same tangential force
``f_ext`` along +x on every slider, below mu_d, so that it never slides as a
whole. The temperature is redrawn every tau_th (driver ``gaussian_steps``);
each rearrangement then moves a slider a little, preferentially downhill, and
the centre of mass creeps. Two sweeps measure the creep velocity
v = d<x_G>/dt (in l0 per tau_th):

* (a) against f_ext at a fixed sigma_theta (the standard deviation of theta);
* (b) against sigma_theta at a fixed f_ext.

Writes ``creep_velocity.csv`` (columns ``sweep, f_ext, sigma_theta, v, v_sem,
r_mean``) and ``creep_velocity.png`` into ``--out``::

    python examples/creep_irregular.py --out creep_out           # a few minutes
    python examples/creep_irregular.py --out creep_out --quick   # seconds

Units: lengths in l0, time in tau_th, forces in N (so f_ext and the friction
coefficients share one scale), theta dimensionless; Ntilde = N / (k l0).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import NullFormatter

import slidernet
from slidernet.io import atomic_output, save_figure

MU_D = 0.5            # dynamic friction coefficient
MU_S_MEAN = 0.6       # mean of the gaussian p(mu_s), truncated below MU_D
MU_S_STD = 0.01
NTILDE = 1e-7         # N / (k l0)

CSV_NAME = "creep_velocity.csv"
PNG_NAME = "creep_velocity.png"
CSV_COLUMNS = ("sweep", "f_ext", "sigma_theta", "v", "v_sem", "r_mean")


@dataclasses.dataclass(frozen=True)
class Preset:
    """Sizes and sweep values of one run.

    Attributes
    ----------
    n : int
        Number of sliders of the irregular network.
    steps : int
        Thermal steps per realization (duration in tau_th).
    realizations : int
        Independent realizations per point (the standard errors come from them).
    f_over_mu_d : tuple of float
        Sweep (a): f_ext in units of mu_d N.
    sigma_a : float
        Sweep (a): sigma_theta in units of Ntilde.
    f_b_over_mu_d : float
        Sweep (b): f_ext in units of mu_d N.
    sigma_b : tuple of float
        Sweep (b): sigma_theta in units of Ntilde.
    """

    n: int
    steps: int
    realizations: int
    f_over_mu_d: tuple[float, ...]
    sigma_a: float
    f_b_over_mu_d: float
    sigma_b: tuple[float, ...]


PRESETS = {
    # About 2e8 slips at ~1e6 slips/s on one core: a few minutes.
    "full": Preset(n=200, steps=120, realizations=10,
                   f_over_mu_d=(0.0, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9), sigma_a=1.0,
                   f_b_over_mu_d=0.6, sigma_b=(0.3, 0.5, 1.0, 2.0, 3.0)),
    # Small enough for a smoke test, still far from noise at the largest load.
    "quick": Preset(n=60, steps=40, realizations=4,
                    f_over_mu_d=(0.0, 0.45, 0.9), sigma_a=1.0,
                    f_b_over_mu_d=0.6, sigma_b=(0.5, 1.0, 2.0)),
}


@dataclasses.dataclass(frozen=True)
class Point:
    """One measured point of a sweep.

    Attributes
    ----------
    sweep : str
        ``"f_ext"`` (sweep a) or ``"sigma_theta"`` (sweep b).
    f_ext : float
        External force on every slider along +x, in units of N.
    sigma_theta : float
        Standard deviation of theta (dimensionless).
    v, v_sem : float
        Creep velocity of the centre of mass along x and its standard error,
        in l0 / tau_th (fit over the second half of the run).
    r_mean : float
        Mean number of slips of the whole network per tau_th (whole run).
    v_first : float
        Slope over the first half, in l0 / tau_th (a check of steadiness).
    """

    sweep: str
    f_ext: float
    sigma_theta: float
    v: float
    v_sem: float
    r_mean: float
    v_first: float


def make_config(f_ext: float, sigma_theta: float, preset: Preset, seed: int,
                network_seed: int) -> dict[str, Any]:
    """The run configuration of one point.

    Parameters
    ----------
    f_ext : float
        Force along +x on every slider, in units of N.
    sigma_theta : float
        Standard deviation of the thermal dilation theta (dimensionless).
    preset : Preset
        Network size, duration and number of realizations.
    seed : int
        Seed of the realizations. Every point uses the same one (common random
        numbers), which makes differences between points less noisy.
    network_seed : int
        Seed of the quenched geometry: the same network for every point.

    Returns
    -------
    dict
        A configuration for :func:`slidernet.run`.
    """
    return {
        "seed": seed,
        "realizations": preset.realizations,
        "steps": preset.steps,
        "record": "all",
        "observables": ["n", "mu_max", "x_G"],
        "network": {"kind": "irregular", "n": preset.n, "seed": network_seed, "Ntilde": NTILDE,
                    "f_ext": f_ext},
        "friction": {"mu_d": MU_D, "static": {"name": "gaussian", "mean": MU_S_MEAN, "std": MU_S_STD}},
        "driver": {"name": "gaussian_steps", "sigma_theta": sigma_theta},
    }


def slope(ds: xr.Dataset, t_min: float, t_max: float) -> tuple[float, float]:
    """Least-squares slope of x_G(t) over ``t_min <= t <= t_max``.

    The slope of the ensemble mean equals the mean of the per-realization
    slopes (the fit is linear in the data), so the spread of the latter gives
    the standard error of the former.

    Parameters
    ----------
    ds : xarray.Dataset
        A result with ``x_G`` (realization, t), x_G in l0 and t in tau_th.
    t_min, t_max : float
        Fit window, in tau_th.

    Returns
    -------
    v, v_sem : float
        Slope of <x_G>(t) in l0 / tau_th and its standard error (NaN with a
        single realization).
    """
    x = ds["x_G"].sel(t=slice(t_min, t_max))
    t = x["t"].values.astype(float)
    per_realization = np.polyfit(t, x.values.T, 1)[0]
    count = per_realization.size
    sem = float(np.std(per_realization, ddof=1) / math.sqrt(count)) if count > 1 else math.nan
    return float(np.mean(per_realization)), sem


def measure(preset: Preset, seed: int, network_seed: int, log: bool = True) -> list[Point]:
    """Run both sweeps and measure the creep velocity at every point.

    Parameters
    ----------
    preset : Preset
        Sizes and sweep values.
    seed, network_seed : int
        Seeds of the realizations and of the network geometry.
    log : bool
        Print one line per point.

    Returns
    -------
    list of Point
        Sweep (a) first, then sweep (b).
    """
    wanted = [("f_ext", f * MU_D, preset.sigma_a * NTILDE) for f in preset.f_over_mu_d]
    wanted += [("sigma_theta", preset.f_b_over_mu_d * MU_D, s * NTILDE) for s in preset.sigma_b]
    done: dict[tuple[float, float], Point] = {}   # a point shared by both sweeps runs once
    points = []
    half = preset.steps / 2
    for sweep, f_ext, sigma in wanted:
        key = (f_ext, sigma)
        if key not in done:
            start = time.perf_counter()
            ds = slidernet.run(make_config(f_ext, sigma, preset, seed, network_seed), progress=False)
            v, v_sem = slope(ds, half, preset.steps)
            v_first, _ = slope(ds, 0, half)
            done[key] = Point(sweep, f_ext, sigma, v, v_sem, float(ds["r_mean"]), v_first)
            if log:
                print(f"f_ext = {f_ext:.4g} N, sigma_theta = {sigma:.3g}: v = {v:.4e} +- {v_sem:.1e} l0/tau_th "
                      f"(first half {v_first:.4e}), r = {done[key].r_mean:.1f} slips/tau_th "
                      f"[{time.perf_counter() - start:.1f} s]", flush=True)
        points.append(dataclasses.replace(done[key], sweep=sweep))
    return points


def write_csv(points: Sequence[Point], path: Path) -> Path:
    """Write the measured points to ``path`` atomically (temporary file, then rename).

    Columns: ``sweep``, ``f_ext`` (N), ``sigma_theta`` (dimensionless), ``v``
    and ``v_sem`` (l0 / tau_th), ``r_mean`` (slips per tau_th).
    """
    with atomic_output(path) as tmp, open(tmp, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(CSV_COLUMNS)
        for p in points:
            writer.writerow([p.sweep] + [repr(float(getattr(p, c))) for c in CSV_COLUMNS[1:]])
    return path


def read_csv(path: Path) -> list[dict[str, Any]]:
    """Read back a file written by :func:`write_csv` (numbers as floats)."""
    with open(path, newline="") as fh:
        return [{k: (v if k == "sweep" else float(v)) for k, v in row.items()} for row in csv.DictReader(fh)]


def plot(points: Sequence[Point], preset: Preset, path: Path) -> Path:
    """Draw both sweeps in a two-panel PNG, written atomically to ``path``.

    (a) v against f_ext / mu_d, with v / (sigma_theta l0 / tau_th) on the right
    axis. (b) v against sigma_theta / Ntilde on log axes, with two guides
    through the middle point: v proportional to sigma_theta, and v
    proportional to the measured slip rate <r> (a fixed mean displacement per
    slip).
    """
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax_a, ax_b = fig.subplots(1, 2)

    a = [p for p in points if p.sweep == "f_ext"]
    sigma_a = preset.sigma_a * NTILDE
    ax_a.errorbar([p.f_ext / MU_D for p in a], [p.v for p in a], yerr=[p.v_sem for p in a],
                  fmt="o-", capsize=3)
    ax_a.axhline(0, color="0.7", lw=0.8)
    ax_a.set_xlabel(r"$f_\mathrm{ext} / (\mu_d N)$")
    ax_a.set_ylabel(r"creep velocity $v$  [$l_0 / \tau_\mathrm{th}$]")
    ax_a.set_title(rf"(a) $\sigma_\theta = {preset.sigma_a:g}\,\tilde N$, {preset.n} sliders", fontsize=10)
    right = ax_a.secondary_yaxis("right", functions=(lambda v: v / sigma_a, lambda u: u * sigma_a))
    right.set_ylabel(r"$v / (\sigma_\theta\, l_0 / \tau_\mathrm{th})$")

    b = [p for p in points if p.sweep == "sigma_theta"]
    s = np.array([p.sigma_theta for p in b])
    v = np.array([p.v for p in b])
    r = np.array([p.r_mean for p in b])
    ax_b.errorbar(s / NTILDE, v, yerr=[p.v_sem for p in b], fmt="o", capsize=3, label="measured")
    mid = len(b) // 2
    ax_b.plot(s / NTILDE, v[mid] * s / s[mid], "--", color="0.5", label=r"$\propto \sigma_\theta$")
    ax_b.plot(s / NTILDE, v[mid] * r / r[mid], ":", color="C3",
              label=r"$\propto \langle r \rangle$ (measured slips per $\tau_\mathrm{th}$)")
    ax_b.set_xscale("log")
    ax_b.set_yscale("log")
    # Tick the measured amplitudes: log-axis minor labels would overlap.
    ax_b.set_xticks(s / NTILDE, [f"{x:g}" for x in s / NTILDE])
    ax_b.xaxis.set_minor_formatter(NullFormatter())
    ax_b.set_xlabel(r"$\sigma_\theta / \tilde N$")
    ax_b.set_ylabel(r"creep velocity $v$  [$l_0 / \tau_\mathrm{th}$]")
    ax_b.set_title(rf"(b) $f_\mathrm{{ext}} = {preset.f_b_over_mu_d:g}\,\mu_d N$", fontsize=10)
    ax_b.legend(fontsize=8)
    return save_figure(fig, path, dpi=130)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("creep_out"), help="output folder (default creep_out)")
    parser.add_argument("--quick", action="store_true", help="a small network and short runs (seconds)")
    parser.add_argument("--n", type=int, help="number of sliders (overrides the preset)")
    parser.add_argument("--steps", type=int, help="thermal steps per realization (overrides the preset)")
    parser.add_argument("--realizations", type=int, help="realizations per point (overrides the preset)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the realizations (default 1)")
    parser.add_argument("--network-seed", type=int, default=0, help="seed of the network geometry (default 0)")
    args = parser.parse_args(argv)

    preset = PRESETS["quick" if args.quick else "full"]
    overrides = {k: getattr(args, k) for k in ("n", "steps", "realizations") if getattr(args, k) is not None}
    preset = dataclasses.replace(preset, **overrides)

    start = time.perf_counter()
    points = measure(preset, args.seed, args.network_seed)
    print(write_csv(points, args.out / CSV_NAME))
    print(plot(points, preset, args.out / PNG_NAME))
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
