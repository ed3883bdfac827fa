"""Aging of the strongest threshold in chains of 2, 4 and 8 sliders
================================================================

The model: sections 2 and 4 of :doc:`/model` (``docs/model.md``).

Each chain (free ends, kind ``chain``) is cycled in temperature with the
driver ``gaussian_steps``. The figure shows the ensemble mean of mu_max
against t (log axis) and the number of rearrangements n(t). For two sliders
only the weaker one ever slips, so mu_max is exactly the largest of the
n + 2 thresholds drawn so far: the exact law
(:func:`slidernet.analysis.theory.mu_max_moments` at the measured mean n(t)) is drawn
over the data. For every n the mean of the largest of n independent draws,
the state at t = 0, is marked on the left edge.

One parameter set (Gaussian mu_s of mean 0.6 and std 0.01, mu_d = 0.5,
Ntilde = 1e-7, sigma_theta = 1e-6; full preset 20 realizations of 1e4
tau_th, seed 1). It measures mu_max only, not the static friction (no tilt
test): with these parameters mu_max of the chains of 4 and 8 shows no trend
with log t (docs/guides/networks.md, "Aging in chains").

Writes ``chain_aging.png`` and ``chain_aging.nc`` into ``--out``::

    python examples/chain_aging.py --out chain_out           # about a minute
    python examples/chain_aging.py --out chain_out --quick   # seconds

Units: time in tau_th, friction coefficients dimensionless,
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
from slidernet.analysis import theory
from slidernet.io import save_figure, write_netcdf

MU_D = 0.5            # dynamic friction coefficient
MU_S_MEAN = 0.6       # mean of the gaussian p(mu_s), truncated below MU_D
MU_S_STD = 0.01
NTILDE = 1e-7         # N / (k l0)
SIZES = (2, 4, 8)

PNG_NAME = "chain_aging.png"
NC_NAME = "chain_aging.nc"


@dataclasses.dataclass(frozen=True)
class Preset:
    """Duration and ensemble size of one run.

    Attributes
    ----------
    steps : int
        Thermal steps per realization (duration in tau_th).
    realizations : int
        Independent realizations per chain.
    sigma_theta : float
        Standard deviation of the thermal dilation theta (dimensionless).
    """

    steps: int
    realizations: int
    sigma_theta: float


PRESETS = {
    # sigma_theta / Ntilde = 10: about 580 slips per tau_th for n = 8, 53 for n = 2.
    "full": Preset(steps=10_000, realizations=20, sigma_theta=1e-6),
    "quick": Preset(steps=1_000, realizations=8, sigma_theta=1e-6),
}


def make_config(n: int, preset: Preset, seed: int) -> dict[str, Any]:
    """The run configuration of a chain of ``n`` sliders.

    Parameters
    ----------
    n : int
        Number of sliders.
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
        "observables": ["n", "mu_max", "x_G"],
        "network": {"kind": "chain", "n": n, "Ntilde": NTILDE},
        "friction": {"mu_d": MU_D, "static": {"name": "gaussian", "mean": MU_S_MEAN, "std": MU_S_STD}},
        "driver": {"name": "gaussian_steps", "sigma_theta": preset.sigma_theta},
    }


def simulate(preset: Preset, seed: int, sizes: Sequence[int] = SIZES, log: bool = True) -> xr.Dataset:
    """Run one ensemble per chain size and gather the curves with the exact law.

    Parameters
    ----------
    preset : Preset
        Duration, ensemble size and sigma_theta.
    seed : int
        Seed of the realizations (the same for every size).
    sizes : sequence of int
        Numbers of sliders.
    log : bool
        Print one line per chain.

    Returns
    -------
    xarray.Dataset
        Dims ``(n_sliders, t)`` with t in tau_th: ``mu_max_mean``,
        ``mu_max_sem``, ``n_mean``, ``n_sem``; ``r_mean``, ``r_sem`` (slips per
        tau_th) and ``mu_max_t0`` (the mean of the largest of n_sliders
        draws) per size; ``mu_max_theory_mean`` and ``mu_max_theory_std`` (t):
        the exact law for two sliders at the measured mean n(t).
    """
    curves = []
    configs = {}
    for n in sizes:
        cfg = make_config(n, preset, seed)
        start = time.perf_counter()
        ds = slidernet.run(cfg, progress=False)
        if log:
            print(f"chain of {n}: r = {float(ds['r_mean']):.2f} +- {float(ds['r_sem']):.2f} slips/tau_th, "
                  f"<mu_max>(t = {preset.steps}) = {float(ds['mu_max_mean'].isel(t=-1)):.5f} "
                  f"[{time.perf_counter() - start:.1f} s, kernel {ds.attrs['kernel']}]", flush=True)
        configs[n] = json.loads(ds.attrs["config"])
        curves.append(ds[["mu_max_mean", "mu_max_sem", "n_mean", "n_sem", "r_mean", "r_sem"]])
    out = xr.concat(curves, dim=xr.DataArray(list(sizes), dims="n_sliders", name="n_sliders"),
                    coords="minimal", compat="override")

    dist = slidernet.load_config(make_config(2, preset, seed)).distribution()
    # The largest of n draws is mu_max_moments at n - 2 rearrangements.
    out["mu_max_t0"] = ("n_sliders", theory.mu_max_moments(dist, np.array(sizes) - 2)[0])
    if 2 in sizes:
        mean, std = theory.mu_max_moments(dist, out["n_mean"].sel(n_sliders=2).values)
        out["mu_max_theory_mean"] = ("t", mean)
        out["mu_max_theory_std"] = ("t", std)
    out["t"].attrs["units"] = "tau_th"
    out["r_mean"].attrs["units"] = "slips per tau_th"
    out.attrs = {"configs": json.dumps(configs), "slidernet_version": slidernet.__version__,
                 "seed": seed, "sigma_theta": preset.sigma_theta, "Ntilde": NTILDE}
    return out


def _sci(x: float) -> str:
    """``x`` as mathtext in scientific notation: 3e-07 -> ``3 \\times 10^{-7}``."""
    text = f"{x:.3g}"
    if "e" not in text:
        return text
    mantissa, exponent = text.split("e")
    power = f"10^{{{int(exponent)}}}"
    return power if mantissa == "1" else rf"{mantissa} \times {power}"


def plot(ds: xr.Dataset, path: Path) -> Path:
    """Draw <mu_max>(t) and n(t) for every chain, written atomically to ``path``."""
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax_mu, ax_n = fig.subplots(1, 2)
    shown = ds.sel(t=ds["t"] >= 1)   # log axis: leave t = 0 out
    t = shown["t"].values
    for i, n in enumerate(ds["n_sliders"].values):
        c = f"C{i}"
        one = shown.sel(n_sliders=n)
        ax_mu.errorbar(t, one["mu_max_mean"], yerr=one["mu_max_sem"], fmt="o", ms=3, color=c,
                       label=f"{n} sliders")
        # x in axes units: a mark on the left edge, whatever the time range.
        ax_mu.plot([0], [float(ds["mu_max_t0"].sel(n_sliders=n))], ">", color=c, ms=8, clip_on=False,
                   transform=ax_mu.get_yaxis_transform())
        ax_n.errorbar(t, one["n_mean"], yerr=one["n_sem"], fmt="o-", ms=3, color=c,
                      label=rf"{n} sliders, $\langle r\rangle$ = {float(one['r_mean']):.1f}")
    if "mu_max_theory_mean" in ds:
        mean, std = shown["mu_max_theory_mean"].values, shown["mu_max_theory_std"].values
        ax_mu.plot(t, mean, "k-", lw=1.2, label="2 sliders, exact: max of n + 2 draws")
        ax_mu.fill_between(t, mean - std, mean + std, color="k", alpha=0.1, lw=0,
                           label=r"exact law $\pm$ 1 std")
    ax_mu.set_xscale("log")
    ax_mu.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax_mu.set_ylabel(r"$\langle \mu_\mathrm{max} \rangle$  (dimensionless)")
    ax_mu.set_title(r"(a) strongest threshold; $\triangleright$ on the axis: mean max of n draws (t = 0)",
                    fontsize=9)
    ax_mu.legend(fontsize=8)
    ax_n.set_xscale("log")
    ax_n.set_yscale("log")
    ax_n.set_xlabel(r"$t$  [$\tau_\mathrm{th}$]")
    ax_n.set_ylabel(r"rearrangements $\langle n \rangle$")
    ax_n.set_title(rf"(b) $\sigma_\theta = {_sci(ds.attrs['sigma_theta'])}$, $\tilde N = {_sci(NTILDE)}$",
                   fontsize=9)
    ax_n.legend(fontsize=8)
    return save_figure(fig, path, dpi=130)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("chain_out"), help="output folder (default chain_out)")
    parser.add_argument("--quick", action="store_true", help="short runs (seconds)")
    parser.add_argument("--steps", type=int, help="thermal steps per realization (overrides the preset)")
    parser.add_argument("--realizations", type=int, help="realizations per chain (overrides the preset)")
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
