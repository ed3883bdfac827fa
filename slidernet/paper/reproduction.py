"""Reproduce the four result figures of Géminard & Bertin (Phys. Rev. E 82, 056108, 2010).

:func:`reproduce` runs the two-slider model at the captions' parameters
(mu_d = 0.5, mean mu_s = 0.6, sigma_mu = 0.01, Ntilde = 1e-7, sigma_theta
from 1e-7 to 1e-5; docs/model.md section 1), overlays the closed forms of
:mod:`slidernet.analysis.theory` and writes, in ``out_dir``:

=========================  ====================================================
``fig1_aging.png/.nc``     mu_max vs t (the paper's Fig. 2, ``aging``)
``fig2_diffusion.png/.nc`` <x_G^2> / (sigma_theta l0)^2 vs t (Fig. 3, ``diffusion``)
``fig3_rearrangements``    (a) n vs t, (b) <r> vs sigma_theta (Fig. 4, ``rearrangement``)
``fig4_mueff.png/.nc``     (mu_eff - mean mu_s) / sigma_mu vs <r> t (Fig. 5, ``mueff``)
``summary.json``           wall time per figure, presets and measured <r>
=========================  ====================================================

The files are numbered from 1 but the paper's Fig. 1 is a sketch: file
``figK`` is the paper's Fig. K + 1 (the figures' titles give the paper's
numbers).

Each netCDF file carries the resolved configurations of its runs in the
attribute ``configs`` (JSON: run label -> configuration) and the theory
curves drawn on the figure as variables. Run it from the command line with
``python -m slidernet.paper OUT_DIR [--quick]``.

The simulations are those of :func:`slidernet.run` (same seeds, same
dataset), driven realization by realization so that a single progress bar
covers the whole reproduction. Panel b of figure 3 is one
:func:`slidernet.ensemble.sweep.sweep` over sigma_theta: every point runs with the
same seed (common random numbers).
"""

from __future__ import annotations

import argparse
import json
import shutil
import signal
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from slidernet._version import __version__
from slidernet.analysis import theory
from slidernet.config import load_config
from slidernet.ensemble.progress import Progress, check_progress
from slidernet.ensemble.runner import run_in
from slidernet.ensemble.sweep import sweep as run_sweep
from slidernet.errors import CheckpointError, OutputError, RunInterrupted
from slidernet.io import write_netcdf
from slidernet.io.store import locked_folder, reason
from slidernet.solver.compile import compile_kernels, terminal_notice

__all__ = ["FULL", "QUICK", "Preset", "reproduce"]

# The captions' reference parameters.
MU_D = 0.5
MU_S_MEAN = 0.6
SIGMA_MU = 0.01
NTILDE = 1e-7

PAPER = ('J.-C. Géminard & E. Bertin, "Aging of the frictional properties induced by temperature '
         'variations", Phys. Rev. E 82, 056108 (2010)')


@dataclass(frozen=True)
class Preset:
    """Run lengths and ensemble sizes of one reproduction.

    Field prefixes follow the file numbers (``figK`` is the paper's Fig. K + 1).
    ``fig12_*``: the runs shared by the aging and diffusion figures;
    ``fig3a_*``: n(t) on a linear time grid; ``fig3b_*``: the sweep of <r>
    over sigma_theta; ``fig4_*``: the tilt-test runs (the expensive ones).
    """

    name: str
    seed: int = 1
    fig12_sigmas: tuple[float, ...] = (1e-7, 3e-7, 1e-6, 3e-6, 1e-5)
    fig12_steps: int = 100_000
    fig12_realizations: int = 100
    fig12_points_per_decade: int = 20
    fig3a_sigma: float = 1e-6
    fig3a_steps: int = 10_000
    fig3a_realizations: int = 20
    fig3a_points: int = 101
    fig3b_sigmas: tuple[float, ...] = field(
        default_factory=lambda: tuple(float(s) for s in np.geomspace(1e-7, 1e-5, 9)))
    fig3b_steps: int = 10_000
    fig3b_realizations: int = 8
    fig4_sigma_theta: float = 1e-6
    fig4_mu_ds: tuple[float, ...] = (0.5, 0.4)
    fig4_ratios: tuple[float, ...] = (0.1, 0.2, 0.3)
    fig4_steps: int = 100_000
    fig4_realizations: int = 100
    fig4_points_per_decade: int = 10


FULL = Preset(name="full")
QUICK = Preset(name="quick", fig12_steps=10_000, fig12_realizations=20, fig3a_steps=2_000,
               fig3a_realizations=10, fig3b_steps=2_000, fig3b_realizations=4, fig4_steps=10_000,
               fig4_realizations=20)


# ---------------------------------------------------------------------------
# running


def _config(sigma_theta: float, steps: int, realizations: int, seed: int, *, mu_d: float = MU_D,
            sigma_mu: float = SIGMA_MU, observables: tuple[str, ...] = ("n", "mu_max", "x_G"),
            record: str | list[int] = "log", points_per_decade: int = 20) -> dict[str, Any]:
    return {
        "seed": int(seed),
        "realizations": int(realizations),
        "steps": int(steps),
        "record": record,
        "log_points_per_decade": int(points_per_decade),
        "observables": list(observables),
        "network": {"kind": "two_slider", "Ntilde": NTILDE},
        "friction": {"mu_d": float(mu_d),
                     "static": {"name": "gaussian", "mean": MU_S_MEAN, "std": float(sigma_mu)}},
        "driver": {"name": "gaussian_steps", "sigma_theta": float(sigma_theta)},
    }


# Cost model for the progress bar only, in units of one plain rearrangement
# (~30 M/s on the reference machine): a thermal step costs about 25 of them,
# and a rearrangement with the tilt test about 4 at mu_d = 0.5 and 1 at
# mu_d = 0.4 (benchmarks/bench_two_slider.py: ~10 M/s with the test).
_STEP_COST = 25.0
_TILT_COST = 4.0


def _cost_per_realization(cfg: dict[str, Any]) -> int:
    mu_d = cfg["friction"]["mu_d"]
    r = float(theory.mean_rearrangements(cfg["driver"]["sigma_theta"], NTILDE, mu_d, MU_S_MEAN))
    per_slip = _TILT_COST * (0.1 / (MU_S_MEAN - mu_d)) ** 2 if "mu_eff" in cfg["observables"] else 1.0
    # Integers, so that the bar's updates add up to its total exactly.
    return max(1, round(cfg["steps"] * (_STEP_COST + max(r, 0.5) * per_slip)))


@dataclass
class _Job:
    label: str
    config: dict[str, Any]

    @property
    def cost(self) -> int:
        return _cost_per_realization(self.config) * self.config["realizations"]


class _Runner:
    """Runs jobs under one progress bar whose total (estimated work) is known upfront.

    Each job runs in its own folder ``runs/<label>`` of the output directory,
    so that an interrupted reproduction resumes: finished runs are read back,
    the interrupted one continues to the same bits.
    """

    def __init__(self, jobs: list[_Job], progress: bool | float | None, runs: Path, resume: bool) -> None:
        # Every kernel of every figure first, with one line if they must be compiled: the bar would
        # otherwise stand still while they compile.
        compile_kernels([load_config(j.config) for j in jobs], notice=terminal_notice(progress))
        self.bar = Progress(sum(j.cost for j in jobs), progress, "paper figures", unit=None)
        self.runs = runs
        self.resume = resume

    def run(self, job: _Job) -> xr.Dataset:
        step = _cost_per_realization(job.config)
        self.bar.set_postfix_str(job.label)
        return run_in(job.config, self.runs / job.label, resume=self.resume,
                      on_realization=lambda _: self.bar.update(step))

    def sweep(self, jobs: list[_Job], key: str, label: str) -> xr.Dataset:
        """One sweep (:func:`~slidernet.ensemble.sweep.sweep`) over ``key``: point i is ``jobs[i]``."""
        values = [_get(j.config, key) for j in jobs]
        steps = [_cost_per_realization(j.config) for j in jobs]

        def done(i: int, _: int) -> None:
            self.bar.set_postfix_str(jobs[i].label)
            self.bar.update(steps[i])

        folder = self.runs / label
        return run_sweep(jobs[0].config, {key: values}, progress=False, on_realization=done, out=folder,
                         resume=self.resume and (folder / "sweep.json").exists())

    def close(self) -> None:
        self.bar.close()


def _get(config: dict[str, Any], key: str) -> Any:
    """The value of a dotted key of a config dict."""
    for part in key.split("."):
        config = config[part]
    return config


def _stack(runs: list[xr.Dataset], dim: str, coords: dict[str, Any]) -> xr.Dataset:
    """Concatenate same-shaped run datasets along a new dimension ``dim``."""
    ds = xr.concat([_no_attrs(r) for r in runs], dim=dim, combine_attrs="override")
    return ds.assign_coords({k: (dim, np.asarray(v)) for k, v in coords.items()})


def _no_attrs(ds: xr.Dataset) -> xr.Dataset:
    ds = ds.copy()
    ds.attrs = {}
    return ds


def _configs_attr(labels: list[str], runs: list[xr.Dataset]) -> str:
    return json.dumps({lab: json.loads(r.attrs["config"]) for lab, r in zip(labels, runs, strict=True)},
                      sort_keys=True)


def _file_attrs(title: str, labels: list[str], runs: list[xr.Dataset]) -> dict[str, str]:
    return {
        "title": title,
        "source": PAPER,
        "configs": _configs_attr(labels, runs),
        "slidernet_version": __version__,
        "Conventions": "CF-1.8",
    }


def _distribution(mu_d: float, sigma_mu: float) -> Any:
    return load_config(_config(1e-6, 1, 1, 0, mu_d=mu_d, sigma_mu=sigma_mu)).distribution()


# ---------------------------------------------------------------------------
# plotting helpers


def _figure(width: float = 7.0, height: float = 5.0, ncols: int = 1) -> Figure:
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    fig.subplots(1, ncols)
    return fig


def _colors(k: int, cmap: str = "plasma") -> list[Any]:
    from matplotlib import colormaps

    # The light end of a sequential map is hard to see on white (viridis at 0.85 is yellow): stop at 0.78.
    return [colormaps[cmap](x) for x in np.linspace(0.0, 0.78, k)] if k > 1 else [colormaps[cmap](0.0)]


def _sci(x: float) -> str:
    mant, exp = f"{x:.1e}".split("e")
    mant = mant.rstrip("0").rstrip(".")
    prefix = "" if mant == "1" else mant + r" \times "
    return prefix + f"10^{{{int(exp)}}}"


# ---------------------------------------------------------------------------
# figures 1 and 2: aging of mu_max and diffusion of the centre of mass


def _fig12_data(runs: list[xr.Dataset], labels: list[str], sigmas: tuple[float, ...]) -> xr.Dataset:
    ds = _stack(runs, "sigma_theta", {"sigma_theta": list(sigmas)})
    ds["sigma_theta"].attrs.update(long_name="standard deviation of the dilation theta", units="1")
    dist = _distribution(MU_D, SIGMA_MU)
    t = ds["t"].values.astype(float)
    n_mean = ds["n_mean"].values
    exact_mean, exact_std = theory.mu_max_moments(dist, n_mean)
    given_n, _ = theory.mu_max_moments(dist, ds["n"].values)
    r = ds["r_mean"].values[:, None]
    n_typ = r * t[None, :]
    s = ds["sigma_theta"].values[:, None]
    ds["mu_max_exact"] = (("sigma_theta", "t"), exact_mean, {
        "long_name": "exact mean of the max of n+2 draws at the measured mean n(t) (theory.mu_max_moments)",
        "units": "1"})
    ds["mu_max_exact_std"] = (("sigma_theta", "t"), exact_std, {
        "long_name": "exact std of the max of n+2 draws at the measured mean n(t)", "units": "1"})
    ds["mu_max_exact_given_n"] = (("sigma_theta", "t"), given_n.mean(axis=1), {
        "long_name": "ensemble mean of the exact E[mu_max | n] over the realizations' own n(t)",
        "units": "1"})
    ds["mu_max_leading"] = (("sigma_theta", "t"), theory.mu_max_leading(MU_S_MEAN, SIGMA_MU, n_typ), {
        "long_name": "eq. mumaxth: mean mu_s + sigma_mu sqrt(2 ln(<r> t)), <r> measured", "units": "1"})
    ds["x_G2_law"] = (("sigma_theta", "t"), theory.msd(s, n_typ), {
        "long_name": "order-of-magnitude law sigma_theta^2 l0^2 ln(<r> t), <r> measured", "units": "l0^2"})
    ds["records_law"] = (("sigma_theta", "t"), s**2 * theory.mean_records(n_mean), {
        "long_name": "sigma_theta^2 l0^2 times the exact mean number of records at n_mean(t)",
        "units": "l0^2"})
    ds["r_slope"] = ("sigma_theta", theory.mean_rearrangements(s[:, 0], NTILDE, MU_D, MU_S_MEAN), {
        "long_name": "eq. slope: (sigma_theta - mu_d Ntilde) / (sqrt(pi) (mu_s - mu_d) Ntilde)", "units": "1"})
    ds.attrs = _file_attrs("Figs. aging and diffusion of Géminard & Bertin (2010): two-slider runs",
                           labels, runs)
    return ds


def _plot_fig1(ds: xr.Dataset, path: Path) -> None:
    fig = _figure()
    ax = fig.axes[0]
    t = ds["t"].values
    pos = t > 0
    colors = _colors(ds.sizes["sigma_theta"])
    handles = []
    for i, c in enumerate(colors):
        d = ds.isel(sigma_theta=i)
        m, e = d["mu_max_mean"].values[pos], d["mu_max_sem"].values[pos]
        ax.fill_between(t[pos], m - e, m + e, color=c, alpha=0.3, lw=0)
        h, = ax.plot(t[pos], m, "o", ms=3, mfc="none", color=c,
                     label=rf"$\sigma_\theta = {_sci(float(d['sigma_theta']))}$, "
                           rf"$\langle r\rangle = {float(d['r_mean']):.3g}$")
        ax.plot(t[pos], d["mu_max_exact_given_n"].values[pos], "-", color=c, lw=1.2)
        ax.plot(t[pos], d["mu_max_leading"].values[pos], "--", color=c, lw=1.0)
        handles.append(h)
    handles += [
        Line2D([], [], color="0.3", ls="-", lw=1.2,
               label=r"exact: $E[\max$ of $n+2$ draws$\,|\,n]$, averaged over the realizations' own $n(t)$"),
        Line2D([], [], color="0.3", ls="--", lw=1.0,
               label=r"eq. (mumaxth): $\bar\mu_s + \sigma_\mu\sqrt{2\ln(\langle r\rangle t/\tau_{th})}$"),
    ]
    ax.set_xscale("log")
    ax.set_xlabel(r"$t/\tau_\mathrm{th}$ (dimensionless time)")
    ax.set_ylabel(r"$\mu_\mathrm{max}$ (dimensionless friction coefficient)")
    ax.set_title(r"Paper Fig. 2 (aging): $\mu_\mathrm{max}$ vs $t/\tau_\mathrm{th}$" + "\n"
                 rf"$\mu_d={MU_D}$, $\bar\mu_s={MU_S_MEAN}$, $\sigma_\mu={SIGMA_MU}$, $\tilde N=10^{{-7}}$, "
                 rf"{ds.sizes['realization']} realizations (band: $\pm$ sem)", fontsize=10)
    ax.legend(handles=handles, fontsize=8, loc="lower right")
    ax.grid(alpha=0.3, which="both")
    fig.savefig(path, dpi=130)


def _plot_fig2(ds: xr.Dataset, path: Path) -> None:
    fig = _figure(height=6.0)
    ax = fig.axes[0]
    t = ds["t"].values
    pos = t > 0
    colors = _colors(ds.sizes["sigma_theta"])
    handles = []
    for i, c in enumerate(colors):
        d = ds.isel(sigma_theta=i)
        s2 = float(d["sigma_theta"]) ** 2
        m, e = d["x_G2_mean"].values[pos] / s2, d["x_G2_sem"].values[pos] / s2
        ax.fill_between(t[pos], m - e, m + e, color=c, alpha=0.3, lw=0)
        h, = ax.plot(t[pos], m, "o", ms=3, mfc="none", color=c,
                     label=rf"$\sigma_\theta = {_sci(float(d['sigma_theta']))}$")
        ax.plot(t[pos], d["x_G2_law"].values[pos] / s2, "--", color=c, lw=1.0)
        ax.plot(t[pos], d["records_law"].values[pos] / s2, ":", color=c, lw=1.2)
        handles.append(h)
    handles += [
        Line2D([], [], color="0.3", ls="--", lw=1.0, label=r"law: $\ln(\langle r\rangle t/\tau_\mathrm{th})$"),
        Line2D([], [], color="0.3", ls=":", lw=1.2,
               label=r"exact mean number of records $H_{\bar n+2}-3/2$"),
    ]
    ax.set_xscale("log")
    ax.set_xlabel(r"$t/\tau_\mathrm{th}$ (dimensionless time)")
    ax.set_ylabel(r"$\langle x_G^2\rangle / (\sigma_\theta^2 l_0^2)$ (dimensionless)")
    ax.set_title(r"Paper Fig. 3 (diffusion): $\langle x_G^2\rangle/\sigma_\theta^2 l_0^2$ vs $t/\tau_\mathrm{th}$"
                 "\n" rf"$\mu_d={MU_D}$, $\bar\mu_s={MU_S_MEAN}$, $\sigma_\mu={SIGMA_MU}$, $\tilde N=10^{{-7}}$, "
                 rf"{ds.sizes['realization']} realizations (band: $\pm$ sem)", fontsize=10)
    ax.legend(handles=handles, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    ax.grid(alpha=0.3, which="both")
    fig.savefig(path, dpi=130)


# ---------------------------------------------------------------------------
# figure 3: rearrangements


def _fig3_data(run_a: xr.Dataset, sweep: xr.Dataset, labels: list[str]) -> xr.Dataset:
    """Panel a's run and panel b's sweep over sigma_theta; ``labels``: panel a's, then each sweep point's."""
    a = run_a.rename({"t": "t_a", "realization": "realization_a", "r_mean": "r_mean_a", "r_sem": "r_sem_a"})
    a = _no_attrs(a)
    a["t_a"].attrs.update(long_name="time (panel a, linear grid)", units="tau_th")
    s = sweep["sigma_theta"].values.astype(float)
    b = xr.Dataset(coords={"sigma_theta": ("sigma_theta", s, {
        "long_name": "standard deviation of the dilation theta (panel b sweep)", "units": "1"})})
    b["r_mean"] = ("sigma_theta", sweep["r_mean"].values,
                   {"long_name": "measured mean rearrangements per tau_th", "units": "1"})
    b["r_sem"] = ("sigma_theta", sweep["r_sem"].values,
                  {"long_name": "standard error of r_mean", "units": "1"})
    b["r_slope"] = ("sigma_theta", theory.mean_rearrangements(s, NTILDE, MU_D, MU_S_MEAN), {
        "long_name": "eq. slope (with offset mu_d Ntilde)", "units": "1"})
    b["r_plain"] = ("sigma_theta", theory.mean_rearrangements(s, NTILDE, MU_D, MU_S_MEAN, offset=False), {
        "long_name": "plain estimate sigma_theta / (sqrt(pi) (mu_s - mu_d) Ntilde)", "units": "1"})
    ds = xr.merge([a, b])
    ds["r_slope_a"] = ((), float(theory.mean_rearrangements(float(json.loads(run_a.attrs["config"])["driver"][
        "sigma_theta"]), NTILDE, MU_D, MU_S_MEAN)), {"long_name": "eq. slope at panel a's sigma_theta",
                                                      "units": "1"})
    ds.attrs = _file_attrs("Fig. rearrangement of Géminard & Bertin (2010): (a) n(t), (b) <r>(sigma_theta)",
                           labels[:1], [run_a])
    configs = json.loads(ds.attrs["configs"])
    configs.update(zip(labels[1:], json.loads(sweep.attrs["configs"]), strict=True))
    ds.attrs["configs"] = json.dumps(configs, sort_keys=True)
    return ds


def _plot_fig3(ds: xr.Dataset, sigma_a: float, path: Path) -> None:
    fig = _figure(width=12.0, height=5.0, ncols=2)
    ax, bx = fig.axes
    t = ds["t_a"].values
    n = ds["n"].values
    show = min(5, n.shape[0])
    for k in range(show):
        ax.plot(t, n[k], lw=0.8, color="0.6", label="single realizations" if k == 0 else None)
    m, e = ds["n_mean"].values, ds["n_sem"].values
    ax.fill_between(t, m - e, m + e, color="C0", alpha=0.3, lw=0)
    ax.plot(t, m, color="C0", lw=2, label=rf"ensemble mean ({n.shape[0]} realizations, band $\pm$ sem)")
    r_slope = float(ds["r_slope_a"])
    ax.plot(t, r_slope * t, "k--", lw=1,
            label=rf"eq. (slope): $n = \langle r\rangle t/\tau_\mathrm{{th}}$, $\langle r\rangle = {r_slope:.3g}$")
    ax.set_xlabel(r"$t/\tau_\mathrm{th}$ (dimensionless time)")
    ax.set_ylabel(r"$n$ (number of rearrangements)")
    ax.set_title(rf"(a) $n$ vs $t$, $\sigma_\theta = {_sci(sigma_a)}$; measured "
                 rf"$\langle r\rangle = {float(ds['r_mean_a']):.3g} \pm {float(ds['r_sem_a']):.1g}$", fontsize=10)
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)

    s = ds["sigma_theta"].values
    rel = float(np.max(ds["r_sem"].values / ds["r_mean"].values))
    # Small markers, capped bars drawn over them: at these sems the bars would hide under 6-point markers.
    bx.errorbar(s, ds["r_mean"].values, yerr=ds["r_sem"].values, fmt="o", ms=3, color="C0", mfc="none",
                capsize=4, elinewidth=1.2, zorder=3,
                label=rf"simulation (mean $\pm$ sem; sem $\leq$ {100 * rel:.2g} % of the mean)")
    grid = np.geomspace(s.min() / 1.2, s.max() * 1.2, 200)
    grid_off = grid[grid > 1.05 * MU_D * NTILDE]
    bx.plot(grid_off, theory.mean_rearrangements(grid_off, NTILDE, MU_D, MU_S_MEAN), "k-", lw=1,
            label=r"eq. (slope): $\frac{\sigma_\theta - \mu_d\tilde N}{\sqrt{\pi}(\bar\mu_s-\mu_d)\tilde N}$")
    bx.plot(grid, theory.mean_rearrangements(grid, NTILDE, MU_D, MU_S_MEAN, offset=False), "r--", lw=1,
            label=r"plain estimate $\frac{\sigma_\theta}{\sqrt{\pi}(\bar\mu_s-\mu_d)\tilde N}$")
    bx.axvline(2 * MU_D * NTILDE, color="0.5", ls=":", lw=1,
               label=r"$\sigma_\theta = 2\mu_d\tilde N$ (eq. slope fails below)")
    bx.set_xscale("log")
    bx.set_yscale("log")
    bx.set_xlabel(r"$\sigma_\theta$ (std of the dilation, dimensionless)")
    bx.set_ylabel(r"$\langle r\rangle$ (rearrangements per $\tau_\mathrm{th}$)")
    bx.set_title(r"(b) $\langle r\rangle$ vs $\sigma_\theta$", fontsize=10)
    bx.legend(fontsize=8, loc="upper left")
    bx.grid(alpha=0.3, which="both")
    fig.suptitle(r"Paper Fig. 4 (rearrangement): "
                 rf"$\mu_d={MU_D}$, $\bar\mu_s={MU_S_MEAN}$, $\sigma_\mu={SIGMA_MU}$, $\tilde N=10^{{-7}}$",
                 fontsize=11)
    fig.savefig(path, dpi=130)


# ---------------------------------------------------------------------------
# figure 4: effective friction from the virtual tilt test


def _fig4_cases(p: Preset) -> list[tuple[float, float, float]]:
    """(mu_d, ratio, sigma_mu) for every run of the effective-friction figure."""
    return [(mu_d, ratio, ratio * (MU_S_MEAN - mu_d)) for mu_d in p.fig4_mu_ds for ratio in p.fig4_ratios]


def _fig4_data(runs: list[xr.Dataset], labels: list[str], cases: list[tuple[float, float, float]]) -> xr.Dataset:
    mu_d = [c[0] for c in cases]
    ratio = [c[1] for c in cases]
    sigma_mu = [c[2] for c in cases]
    ds = _stack(runs, "case", {"mu_d": mu_d, "ratio": ratio, "sigma_mu": sigma_mu,
                               "case": np.arange(len(cases))})
    ds["mu_d"].attrs.update(long_name="dynamic friction coefficient", units="1")
    ds["ratio"].attrs.update(long_name="sigma_mu / (mean mu_s - mu_d)", units="1")
    ds["sigma_mu"].attrs.update(long_name="standard deviation of mu_s (before truncation)", units="1")
    ds = ds.assign_coords(label=("case", [f"mu_d={md:g}, sigma_mu/(mean mu_s - mu_d)={r:g}, sigma_mu={sm:.3g}"
                                          for md, r, sm in cases]))
    ds["case"].attrs.update(long_name="run index: one (mu_d, ratio) pair per case",
                            description="each case is one run of the tilt test; its mu_d, ratio, sigma_mu and "
                                        "label are the coordinates along case")
    ds["label"].attrs.update(long_name="what the case is")
    t = ds["t"].values.astype(float)
    sm = ds["sigma_mu"].values[:, None]
    ds["rt"] = (("case", "t"), ds["r_mean"].values[:, None] * t[None, :],
                {"long_name": "typical number of rearrangements <r> t / tau_th (<r> measured)", "units": "1"})
    ds["phi"] = (("case", "t"), (ds["mu_eff"].values - MU_S_MEAN) / sm,
                 {"long_name": "(mu_eff - mean mu_s) / sigma_mu", "units": "1"})
    ds["phi_sem"] = (("case", "t"), ds["mu_eff_sem"].values / sm,
                     {"long_name": "standard error of phi", "units": "1"})
    exact = np.empty((len(cases), t.size))
    for k, (md, _, s) in enumerate(cases):
        exact[k] = theory.mu_max_moments(_distribution(md, s), ds["n_mean"].values[k])[0]
    ds["mu_max_exact"] = (("case", "t"), exact, {
        "long_name": "exact mean of the max of n+2 draws at the measured mean n(t)", "units": "1"})
    ds["mu_max_exact_phi"] = (("case", "t"), (exact - MU_S_MEAN) / sm,
                              {"long_name": "(mu_max_exact - mean mu_s) / sigma_mu", "units": "1"})
    ds.attrs = _file_attrs("Fig. mueff of Géminard & Bertin (2010): effective friction from the tilt test",
                           labels, runs)
    return ds


def _plot_fig4(ds: xr.Dataset, sigma_theta: float, path: Path) -> None:
    fig = _figure(width=7.5, height=6.5)
    ax = fig.axes[0]
    ratios = sorted(set(ds["ratio"].values.tolist()))
    colors = dict(zip(ratios, _colors(len(ratios), "plasma"), strict=True))
    mu_ds = sorted(set(ds["mu_d"].values.tolist()), reverse=True)
    pos = ds["t"].values > 0
    handles = []
    theory_drawn: set[float] = set()
    for k in range(ds.sizes["case"]):
        d = ds.isel(case=k)
        c = colors[float(d["ratio"])]
        x = d["rt"].values[pos]
        y, e = d["phi"].values[pos], d["phi_sem"].values[pos]
        ok = np.isfinite(y)
        main = float(d["mu_d"]) == mu_ds[0]
        if main:
            ax.fill_between(x[ok], (y - e)[ok], (y + e)[ok], color=c, alpha=0.25, lw=0)
            ax.plot(x[ok], y[ok], "-", color=c, lw=1.5)
        else:
            ax.errorbar(x[ok], y[ok], yerr=e[ok], fmt="s", ms=4, mfc="none", color=c, capsize=2, elinewidth=0.9)
        if float(d["ratio"]) not in theory_drawn:
            theory_drawn.add(float(d["ratio"]))
            ax.plot(x, d["mu_max_exact_phi"].values[pos], ":", color=c, lw=1.3)
    for rr in ratios:
        handles.append(Line2D([], [], color=colors[rr], lw=4,
                              label=rf"$\sigma_\mu/(\bar\mu_s-\mu_d) = {rr:g}$"))
    handles.append(Line2D([], [], color="0.3", ls="-", lw=1.5,
                          label=rf"lines: $\mu_d = {mu_ds[0]:g}$ (band $\pm$ sem)"))
    if len(mu_ds) > 1:
        handles.append(Line2D([], [], color="0.3", ls="none", marker="s", mfc="none",
                              label=rf"open squares: $\mu_d = {mu_ds[1]:g}$ (bars $\pm$ sem)"))
    handles.append(Line2D([], [], color="0.3", ls=":", lw=1.3,
                          label=r"$(\mu_\mathrm{max} - \bar\mu_s)/\sigma_\mu$, exact mean (reference)"))
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel(r"$\langle r\rangle t/\tau_\mathrm{th}$ (typical number of rearrangements)")
    ax.set_ylabel(r"$(\mu_s^\mathrm{eff} - \bar\mu_s)/\sigma_\mu$ (dimensionless)")
    ax.set_title(r"Paper Fig. 5 (mueff): effective static friction from the virtual tilt test" + "\n"
                 rf"$\bar\mu_s={MU_S_MEAN}$, $\tilde N=10^{{-7}}$, $\sigma_\theta={_sci(sigma_theta)}$, "
                 rf"{ds.sizes['realization']} realizations; $t=0$ not shown", fontsize=10)
    ax.legend(handles=handles, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    ax.grid(alpha=0.3, which="both")
    fig.savefig(path, dpi=130)


# ---------------------------------------------------------------------------
# driver


def reproduce(out_dir: str | Path, quick: bool = False, progress: bool | float | None = True, *,
              resume: bool = False, overwrite: bool = False, _preset: Preset | None = None) -> dict[str, Path]:
    """Reproduce the paper's four result figures (its Figs. 2 to 5), with their data, in ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created if missing). The reproduction holds its lock
        (``out_dir/.slidernet.lock``) from before it writes anything until
        it ends, and never works in a folder that holds a run or a sweep.
    quick : bool
        Use the :data:`QUICK` preset (10 s of wall time on an idle 2-core
        machine) instead of :data:`FULL` (102 s; 183 s of CPU).
    progress : bool, float or None
        Progress over all the runs (estimated work, known upfront), as in
        :func:`slidernet.run`: True or None a bar on a terminal and a line
        every 30 s elsewhere (a batch job's log); a number of seconds,
        lines that far apart.
    resume : bool
        Continue the interrupted reproduction in ``out_dir``: finished runs
        are read back from ``out_dir/runs``, the interrupted one resumes.
    overwrite : bool
        Replace a reproduction (finished or interrupted) in ``out_dir``.
    _preset : Preset, optional
        Internal: replaces the preset chosen by ``quick`` (tests use a tiny one).

    Returns
    -------
    dict of str to Path
        File name -> path of every file written: ``fig1_aging.png``,
        ``fig1_aging.nc``, ``fig2_diffusion.png``, ``fig2_diffusion.nc``,
        ``fig3_rearrangements.png``, ``fig3_rearrangements.nc``,
        ``fig4_mueff.png``, ``fig4_mueff.nc`` and ``summary.json``.

    Raises
    ------
    OutputError
        If ``out_dir`` is not a folder, holds a run or a sweep, or holds a
        reproduction and neither ``resume`` nor ``overwrite`` is set.
    FolderInUseError
        If another command works in ``out_dir`` (it holds the folder's lock).
    """
    check_progress(progress, "reproduce")
    p = _preset if _preset is not None else (QUICK if quick else FULL)
    with locked_folder(Path(out_dir), "paper reproduction") as out:
        return _reproduce(out, p, bool(quick) if _preset is None else None, progress, resume, overwrite)


def _reproduce(out: Path, p: Preset, quick: bool | None, progress: bool | float | None, resume: bool,
               overwrite: bool) -> dict[str, Path]:
    """:func:`reproduce` with preset ``p`` in ``out``, whose lock the caller holds (``quick`` None: own ``p``)."""
    start = time.perf_counter()
    runs = _prepare(out, resume, overwrite)

    obs12 = ("n", "mu_max", "x_G")
    jobs12 = [_Job(f"sigma_theta={s:g}", _config(s, p.fig12_steps, p.fig12_realizations, p.seed + i,
                                                  observables=obs12, points_per_decade=p.fig12_points_per_decade))
              for i, s in enumerate(p.fig12_sigmas)]
    t_lin = sorted({round(x) for x in np.linspace(0, p.fig3a_steps, p.fig3a_points)})
    job3a = _Job(f"panel_a_sigma_theta={p.fig3a_sigma:g}",
                 _config(p.fig3a_sigma, p.fig3a_steps, p.fig3a_realizations, p.seed + 100, observables=("n",),
                         record=t_lin))
    # One sweep: every sigma_theta runs with the same seed (common random numbers, slidernet.ensemble.sweep).
    jobs3b = [_Job(f"sweep_sigma_theta={s:.4g}", _config(s, p.fig3b_steps, p.fig3b_realizations, p.seed + 200,
                                                         observables=("n",)))
              for s in p.fig3b_sigmas]
    cases = _fig4_cases(p)
    jobs4 = [_Job(f"mu_d={md:g}_ratio={rr:g}",
                  _config(p.fig4_sigma_theta, p.fig4_steps, p.fig4_realizations, p.seed + 300 + k, mu_d=md,
                          sigma_mu=sm, observables=("n", "mu_max", "mu_eff"),
                          points_per_decade=p.fig4_points_per_decade))
              for k, (md, rr, sm) in enumerate(cases)]

    runner = _Runner([*jobs12, job3a, *jobs3b, *jobs4], progress, runs, resume)
    files: dict[str, Path] = {}
    wall: dict[str, dict[str, float]] = {}
    try:
        # Figures 1 and 2 share their runs.
        t0 = time.perf_counter()
        runs12 = [runner.run(j) for j in jobs12]
        ds12 = _fig12_data(runs12, [j.label for j in jobs12], p.fig12_sigmas)
        t_sim12 = time.perf_counter() - t0
        t0 = time.perf_counter()
        fig1_vars = ["x_G", "x_G_mean", "x_G_sem", "x_G2_mean", "x_G2_sem", "x_G2_law", "records_law"]
        files["fig1_aging.nc"] = write_netcdf(ds12.drop_vars(fig1_vars), out / "fig1_aging.nc")
        _plot_fig1(ds12, out / "fig1_aging.png")
        files["fig1_aging.png"] = out / "fig1_aging.png"
        wall["fig1_aging"] = {"simulation_s": t_sim12, "output_s": time.perf_counter() - t0,
                              "note": "simulations shared with fig2 (counted here)"}
        t0 = time.perf_counter()
        files["fig2_diffusion.nc"] = write_netcdf(ds12.drop_vars(["mu_max", "mu_max_mean", "mu_max_sem",
                                                                  "mu_max_exact", "mu_max_exact_std",
                                                                  "mu_max_exact_given_n", "mu_max_leading"]),
                                                  out / "fig2_diffusion.nc")
        _plot_fig2(ds12, out / "fig2_diffusion.png")
        files["fig2_diffusion.png"] = out / "fig2_diffusion.png"
        wall["fig2_diffusion"] = {"simulation_s": 0.0, "output_s": time.perf_counter() - t0}

        t0 = time.perf_counter()
        run3a = runner.run(job3a)
        sweep3b = runner.sweep(jobs3b, "driver.sigma_theta", "fig3b_sweep")
        ds3 = _fig3_data(run3a, sweep3b, [job3a.label] + [j.label for j in jobs3b])
        t_sim3 = time.perf_counter() - t0
        t0 = time.perf_counter()
        files["fig3_rearrangements.nc"] = write_netcdf(ds3, out / "fig3_rearrangements.nc")
        _plot_fig3(ds3, p.fig3a_sigma, out / "fig3_rearrangements.png")
        files["fig3_rearrangements.png"] = out / "fig3_rearrangements.png"
        wall["fig3_rearrangements"] = {"simulation_s": t_sim3, "output_s": time.perf_counter() - t0}

        t0 = time.perf_counter()
        runs4 = [runner.run(j) for j in jobs4]
        ds4 = _fig4_data(runs4, [j.label for j in jobs4], cases)
        t_sim4 = time.perf_counter() - t0
        t0 = time.perf_counter()
        files["fig4_mueff.nc"] = write_netcdf(ds4, out / "fig4_mueff.nc")
        _plot_fig4(ds4, p.fig4_sigma_theta, out / "fig4_mueff.png")
        files["fig4_mueff.png"] = out / "fig4_mueff.png"
        wall["fig4_mueff"] = {"simulation_s": t_sim4, "output_s": time.perf_counter() - t0}
    except RunInterrupted as exc:
        flags = " --quick" if quick else ""
        raise RunInterrupted(
            f"interrupted by {signal.Signals(exc.signum).name}: the runs done and the saved work of the "
            f"running one are in {str(runs)!r}; continue with "
            f"`slidernet paper --out {str(out)!r}{flags} --resume`.",
            exc.signum,
        ) from None
    finally:
        runner.close()

    for w in wall.values():
        w["total_s"] = w["simulation_s"] + w["output_s"]
    summary = {
        "paper": PAPER,
        "preset": asdict(p),
        "quick": quick,
        "reference_parameters": {"mu_d": MU_D, "mu_s_mean": MU_S_MEAN, "sigma_mu": SIGMA_MU, "Ntilde": NTILDE},
        "wall_time_s": {**wall, "total_s": time.perf_counter() - start},
        "measured_r_mean": {
            "fig1_fig2": {j.label: float(r["r_mean"]) for j, r in zip(jobs12, runs12, strict=True)},
            "fig3b": {j.label: float(r) for j, r in zip(jobs3b, sweep3b["r_mean"].values, strict=True)},
            "fig4": {j.label: float(r["r_mean"]) for j, r in zip(jobs4, runs4, strict=True)},
        },
        "slidernet_version": __version__,
        "files": sorted([*files, "summary.json"]),
    }
    summary_path = out / "summary.json"
    tmp = summary_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(summary, indent=2, default=_json_default) + "\n")
    tmp.replace(summary_path)
    files["summary.json"] = summary_path
    shutil.rmtree(runs, ignore_errors=True)  # the figures' files hold the data; resume is over
    return files


def _prepare(out: Path, resume: bool, overwrite: bool) -> Path:
    """Check the output folder (its lock held) and make ``out/runs``; return that folder of the runs."""
    runs = out / "runs"
    finished = (out / "summary.json").exists() and not runs.exists()
    if overwrite and not resume:
        shutil.rmtree(runs, ignore_errors=True)
        (out / "summary.json").unlink(missing_ok=True)
    elif resume and finished:
        raise CheckpointError(f"Nothing to resume in {str(out)!r}: its reproduction is finished "
                              "(summary.json is there). Use --overwrite to make it again.")
    elif not resume and (finished or runs.exists()):
        state = "a finished reproduction" if finished else "an interrupted reproduction"
        raise OutputError(f"{str(out)!r} holds {state}; it is not replaced silently. Continue an "
                          "interrupted one with --resume, replace it with --overwrite, or use another folder.")
    try:
        runs.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"Cannot create the output directory {str(out)!r}: {reason(exc)}.") from None
    return runs


def _json_default(obj: Any) -> Any:
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def main(argv: list[str] | None = None) -> int:
    """``python -m slidernet.paper OUT_DIR [--quick] [--no-progress]``."""
    parser = argparse.ArgumentParser(prog="python -m slidernet.paper", description=__doc__.splitlines()[0])
    parser.add_argument("out_dir", type=Path)
    parser.add_argument("--quick", action="store_true", help="short runs (10 s on an idle 2-core machine)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    args = parser.parse_args(argv)
    files = reproduce(args.out_dir, quick=args.quick, progress=False if args.no_progress else None)
    for name in sorted(files):
        print(files[name])
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())

