"""Aging of mu_max in the three extreme-value classes (two sliders)
================================================================

The model: sections 1 and 4 of :doc:`/model` (``docs/model.md``).

In the two-slider system only the weaker slider ever slips, so after n
rearrangements mu_max is exactly the largest of the n + 2 thresholds drawn
so far, whatever p(mu_s). How it grows with time therefore depends on the
extreme-value class of p(mu_s). One law of each class, all with support
starting at a = 0.55 > mu_d = 0.5 (so no truncation is needed):

* ``uniform`` on [0.55, 0.65] -- Weibull class (the class of laws bounded
  above, whose limit law is the reversed Weibull; not the ``weibull`` law,
  which is in the Gumbel class): mu_max saturates at the upper end,
  E[z] = m / (m + 1);
* ``exponential``, 0.55 + Exp(0.05) -- Gumbel class: E[z] = H_m ~ ln m;
* ``pareto``, 0.5 + 0.05 Pareto(alpha = 3) -- Frechet class:
  E[z] ~ Gamma(2/3) m^(1/3) - 1, a power law.

with z = (mu_max - a) / s, s each law's scale (0.1, 0.05, 0.05), so that
the three share axes. The figure shows the ensemble mean of z against t,
with the exact law -- the mean of the largest of n + 2 draws
(:meth:`slidernet.plugins.distributions.TruncatedBelow.mean_max`) at each
realization's measured n(t), averaged over the realizations, and (dotted)
at the measured mean n(t) -- and the deviation of the data from the first in
standard errors.

Writes ``extreme_value_classes.png`` and ``extreme_value_classes.nc`` into
``--out``::

    python examples/extreme_value_classes.py --out evc_out           # about 15 s
    python examples/extreme_value_classes.py --out evc_out --quick   # a few seconds

Units: time in tau_th, friction coefficients dimensionless, z dimensionless,
Ntilde = N / (k l0), theta dimensionless.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import slidernet
from slidernet.io import save_figure, write_netcdf

MU_D = 0.5      # dynamic friction coefficient
NTILDE = 1e-7   # N / (k l0)

PNG_NAME = "extreme_value_classes.png"
NC_NAME = "extreme_value_classes.nc"


@dataclasses.dataclass(frozen=True)
class Law:
    """One p(mu_s) and its normalization z = (mu_max - origin) / scale.

    Attributes
    ----------
    name : str
        Registered distribution name.
    params : dict
        Its parameters (the ``friction.static`` table without ``name``).
    origin : float
        Lower end of the support (dimensionless).
    scale : float
        Scale of the law (dimensionless).
    label : str
        Legend text, with the extreme-value class.
    """

    name: str
    params: dict[str, Any]
    origin: float
    scale: float
    label: str


LAWS = (
    Law("uniform", {"low": 0.55, "high": 0.65}, 0.55, 0.10, "uniform [0.55, 0.65]: Weibull class"),
    Law("exponential", {"scale": 0.05, "loc": 0.55}, 0.55, 0.05, "0.55 + Exp(0.05): Gumbel class"),
    Law("pareto", {"alpha": 3.0, "scale": 0.05, "loc": 0.5}, 0.55, 0.05,
        r"0.5 + 0.05 Pareto($\alpha$ = 3): Fréchet class"),
)


@dataclasses.dataclass(frozen=True)
class Preset:
    """Duration and ensemble size of one run.

    Attributes
    ----------
    steps : int
        Thermal steps per realization (duration in tau_th).
    realizations : int
        Independent realizations per law.
    sigma_theta : float
        Standard deviation of the thermal dilation theta (dimensionless).
    """

    steps: int
    realizations: int
    sigma_theta: float


PRESETS = {
    # sigma_theta / Ntilde = 10: about 50 to 100 rearrangements per tau_th.
    "full": Preset(steps=10_000, realizations=100, sigma_theta=1e-6),
    "quick": Preset(steps=300, realizations=40, sigma_theta=1e-6),
}


def make_config(law: Law, preset: Preset, seed: int) -> dict[str, Any]:
    """The two-slider run configuration of one law.

    Parameters
    ----------
    law : Law
        The distribution of mu_s.
    preset : Preset
        Duration, ensemble size and sigma_theta.
    seed : int
        Seed of the realizations.

    Returns
    -------
    dict
        A configuration for :func:`slidernet.run`.
    """
    return {
        "seed": seed,
        "realizations": preset.realizations,
        "steps": preset.steps,
        "record": "log",
        "observables": ["n", "mu_max"],
        "network": {"kind": "two_slider", "Ntilde": NTILDE},
        "friction": {"mu_d": MU_D, "static": {"name": law.name, **law.params}},
        "driver": {"name": "gaussian_steps", "sigma_theta": preset.sigma_theta},
    }


def simulate(preset: Preset, seed: int, laws: Sequence[Law] = LAWS, log: bool = True) -> xr.Dataset:
    """Run one ensemble per law and compare with the exact law of the maximum.

    Parameters
    ----------
    preset : Preset
        Duration, ensemble size and sigma_theta.
    seed : int
        Seed of the realizations (the same for every law).
    laws : sequence of Law
        The distributions.
    log : bool
        Print one line per law.

    Returns
    -------
    xarray.Dataset
        Dims ``(law, t)``, t in tau_th: ``z_mean``, ``z_sem`` (the normalized
        mu_max), ``z_exact`` (the exact mean of the max of n + 2 draws at
        each realization's own n(t), averaged over realizations),
        ``z_exact_at_mean_n`` (the same at the measured mean n(t)),
        ``mu_max_mean``, ``mu_max_sem``, ``n_mean``, ``n_sem``; ``origin``,
        ``scale`` and ``r_mean`` (rearrangements per tau_th) per law.
    """
    curves = []
    configs = {}
    for law in laws:
        cfg = make_config(law, preset, seed)
        start = time.perf_counter()
        ds = slidernet.run(cfg, progress=False)
        dist = slidernet.load_config(cfg).distribution()
        # The exact conditional mean given each realization's own n, averaged
        # over the realizations: what <mu_max>(t) estimates. The law at the
        # mean n(t) is larger by the Jensen gap (mean_max is concave in n),
        # which matters only while n(t) still varies much between realizations.
        exact = dist.mean_max(ds["n"].values + 2.0).mean(axis=0)
        at_mean_n = dist.mean_max(ds["n_mean"].values + 2.0)
        one = xr.Dataset({
            "z_mean": (ds["mu_max_mean"] - law.origin) / law.scale,
            "z_sem": ds["mu_max_sem"] / law.scale,
            "z_exact": ("t", (exact - law.origin) / law.scale),
            "z_exact_at_mean_n": ("t", (at_mean_n - law.origin) / law.scale),
            "mu_max_mean": ds["mu_max_mean"], "mu_max_sem": ds["mu_max_sem"],
            "n_mean": ds["n_mean"], "n_sem": ds["n_sem"], "r_mean": ds["r_mean"],
            "origin": law.origin, "scale": law.scale,
        })
        curves.append(one)
        configs[law.name] = json.loads(ds.attrs["config"])
        if log:
            late = one.isel(t=-1)
            print(f"{law.name:12s} r = {float(ds['r_mean']):6.1f}/tau_th, n(t = {preset.steps}) = "
                  f"{float(late['n_mean']):9.0f}: z = {float(late['z_mean']):.4f} +- {float(late['z_sem']):.4f}, "
                  f"exact {float(late['z_exact']):.4f}  [{time.perf_counter() - start:.1f} s]", flush=True)
    out = xr.concat(curves, dim=xr.DataArray([law.name for law in laws], dims="law", name="law"),
                    coords="minimal", compat="override")
    out["t"].attrs["units"] = "tau_th"
    out["r_mean"].attrs["units"] = "rearrangements per tau_th"
    out["z_mean"].attrs["long_name"] = "(mu_max - origin) / scale, ensemble mean"
    out["z_exact"].attrs["long_name"] = "mean max of n + 2 draws, averaged over the measured n(t), normalized"
    out["z_exact_at_mean_n"].attrs["long_name"] = "mean max of n + 2 draws at the measured mean n(t), normalized"
    out.attrs = {"configs": json.dumps(configs), "slidernet_version": slidernet.__version__,
                 "seed": seed, "sigma_theta": preset.sigma_theta, "Ntilde": NTILDE, "mu_d": MU_D}
    return out


def plot(ds: xr.Dataset, path: Path, laws: Sequence[Law] = LAWS) -> Path:
    """Draw z(t) against the exact law, and the deviation in standard errors; written atomically."""
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax_z, ax_dev = fig.subplots(1, 2, width_ratios=[2, 1])
    shown = ds.sel(t=ds["t"] >= 1)  # log axis: leave t = 0 out
    t = shown["t"].values
    labels = {law.name: law.label for law in laws}
    for i, name in enumerate(shown["law"].values):
        one = shown.sel(law=name)
        c = f"C{i}"
        ax_z.errorbar(t, one["z_mean"], yerr=one["z_sem"], fmt="o", ms=3, color=c, label=labels.get(name, name))
        ax_z.plot(t, one["z_exact"], "-", color=c, lw=1.2)
        ax_z.plot(t, one["z_exact_at_mean_n"], ":", color=c, lw=1.0)
        sem = np.where(one["z_sem"] > 0, one["z_sem"], np.nan)
        ax_dev.plot(t, (one["z_mean"] - one["z_exact"]) / sem, "o-", ms=3, color=c, lw=0.8)
    ax_z.plot([], [], "k-", lw=1.2, label="exact: mean max of n + 2 draws, averaged over the measured n(t)")
    ax_z.plot([], [], "k:", lw=1.0, label="the same at the mean n(t)")
    ax_z.set_xscale("log")
    ax_z.set_yscale("log")
    ax_z.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax_z.set_ylabel(r"$(\langle\mu_\mathrm{max}\rangle - a)/s$")
    ax_z.set_title(rf"(a) two sliders, $\mu_d$ = {ds.attrs['mu_d']}, "
                   rf"$\sigma_\theta/\tilde N$ = {ds.attrs['sigma_theta'] / ds.attrs['Ntilde']:.0f}", fontsize=9)
    ax_z.legend(fontsize=8)
    for y in (-2, 2):
        ax_dev.axhline(y, color="0.6", lw=0.8, ls="--")
    ax_dev.axhline(0, color="k", lw=0.8)
    ax_dev.set_xscale("log")
    ax_dev.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax_dev.set_ylabel("(data - exact) / standard error")
    ax_dev.set_title("(b) deviation from the exact law", fontsize=9)
    return save_figure(fig, path, dpi=130)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("evc_out"), help="output folder (default evc_out)")
    parser.add_argument("--quick", action="store_true", help="short runs (a few seconds)")
    parser.add_argument("--steps", type=int, help="thermal steps per realization (overrides the preset)")
    parser.add_argument("--realizations", type=int, help="realizations per law (overrides the preset)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the realizations (default 1)")
    args = parser.parse_args(argv)

    preset = PRESETS["quick" if args.quick else "full"]
    overrides = {k: getattr(args, k) for k in ("steps", "realizations") if getattr(args, k) is not None}
    preset = dataclasses.replace(preset, **overrides)

    start = time.perf_counter()
    ds = simulate(preset, args.seed)
    print(write_netcdf(ds, args.out / NC_NAME))
    print(plot(ds, args.out / PNG_NAME))
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
