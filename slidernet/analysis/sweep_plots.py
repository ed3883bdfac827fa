"""Pictures of a sweep's result: each point against t, and the late-time value against the swept key.

:func:`plot_sweep` draws the result of :func:`slidernet.ensemble.sweep.sweep`
(``slidernet sweep``): one row per recorded observable (n, mu_max,
<x_G^2>, mu_eff, the contact age), its ensemble mean against t with one
curve per sweep point on the left, and its value at the last recorded time
against the swept key, with its standard error over the realizations, on the
right. :func:`plot` is what ``slidernet plot`` calls: a sweep's figure for a
sweep, :func:`slidernet.analysis.plots.plot_result`'s for one run.

The points of a sweep run with the same seed (common random numbers): their
fluctuations are correlated, so curves that wiggle together are not a
finding. The figure says so where the points share their seed
(:func:`shares_seeds`).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.colors import LogNorm, Normalize
from matplotlib.figure import Figure

from slidernet.analysis.network_maps import DPI
from slidernet.analysis.plots import (
    _check_format,
    _load,
    _summary,
    _words,
    non_default_options,
    plot_result,
    time_panels,
)
from slidernet.errors import ResultError
from slidernet.io import save_figure

__all__ = ["SHARED_SEEDS_NOTE", "plot", "plot_sweep", "shares_seeds", "swept_dims"]

#: The line of a sweep's title where its points share their seed.
SHARED_SEEDS_NOTE = "points share seeds (common random numbers): their fluctuations are correlated"


def swept_dims(ds: xr.Dataset) -> list[str]:
    """The sweep dimensions of a result, in the order of its variables' dims (those whose coordinate has the
    attribute ``sweep_key``, as :func:`slidernet.ensemble.sweep.sweep` writes them); empty for one run."""
    order = list(ds["n"].dims) if "n" in ds else list(ds.dims)
    return [str(d) for d in order if d in ds.coords and "sweep_key" in ds[d].attrs]


def shares_seeds(ds: xr.Dataset) -> bool:
    """Whether the points of a sweep ran with one seed (common random numbers), read from the resolved
    configurations of its points (the attribute ``configs``); False where it does not say."""
    try:
        configs = json.loads(ds.attrs.get("configs", "[]"))
    except ValueError:
        return False
    seeds = [c.get("seed") for c in configs if isinstance(c, dict)]
    return len(seeds) > 1 and None not in seeds and len(set(seeds)) == 1


def plot(result: xr.Dataset | xr.DataTree | str | os.PathLike[str], path: str | os.PathLike[str] | None = None,
         *, figure: Figure | None = None, dpi: int = DPI) -> Figure:
    """The figure of a result: :func:`plot_sweep` for a sweep, :func:`~slidernet.analysis.plots.plot_result`
    for one run (what ``slidernet plot`` draws). The parameters and errors are theirs."""
    read_from = None if isinstance(result, (xr.Dataset, xr.DataTree)) else str(result)
    data = _load(result, None)[0]  # read once: the figure's function gets the data
    root = data.to_dataset() if isinstance(data, xr.DataTree) else data
    draw = plot_sweep if swept_dims(root) else plot_result
    return draw(data, path, figure=figure, dpi=dpi, read_from=read_from)


def plot_sweep(result: xr.Dataset | xr.DataTree | str | os.PathLike[str],
               path: str | os.PathLike[str] | None = None, *, figure: Figure | None = None, dpi: int = DPI,
               read_from: str | None = None) -> Figure:
    r"""The panels of a sweep: each observable against t per point, and its late-time value per point.

    One row per observable the sweep recorded, among n, mu_max, <x_G^2>,
    mu_eff and the contact age. Left: the ensemble mean against t (tau_th; a
    logarithmic axis over t > 0), one curve per sweep point with a band of
    +- one standard error, coloured by the swept value (a colorbar, for
    one numeric swept key) or told apart by a legend. Right: the value at
    the last recorded time against the first swept key, +- one standard
    error over the realizations (mu_eff: pooled over the tilt tests), one
    curve per value of the other swept keys. The title gives the scene, the
    swept values, every option not at its default
    (:func:`~slidernet.analysis.plots.non_default_options`, the swept keys
    left out) and, where the points share their seed, that their
    fluctuations are correlated (:data:`SHARED_SEEDS_NOTE`).

    Parameters
    ----------
    result : xarray.Dataset, xarray.DataTree or path-like
        A result of :func:`slidernet.ensemble.sweep.sweep` (a DataTree: its
        root), or the path of its file (``OUT/result.nc`` of ``slidernet
        sweep``).
    path : path-like, optional
        Where to write the figure, atomically; its suffix picks the format.
        None: write nothing.
    figure : matplotlib.figure.Figure, optional
        An empty figure to draw in. Default: a new Agg figure, outside pyplot.
    dpi : int
        Resolution of a raster file, in dots per inch.
    read_from : str, optional
        The path of the file that ``result``, a dataset, was read from: the
        title and the errors name it.

    Returns
    -------
    matplotlib.figure.Figure
        Axes in pairs per row (against t, late time), then a colorbar's.

    Raises
    ------
    ResultError
        Before anything is drawn or written: the file is missing or not
        netCDF, or the dataset has no sweep dimension or no ``t``.
    ConfigError
        Before anything is drawn or written: ``path`` has a suffix
        matplotlib cannot write.

    Examples
    --------
    >>> from slidernet.ensemble.sweep import sweep
    >>> base = {"seed": 1, "realizations": 2, "steps": 50,
    ...         "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...         "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...         "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}
    >>> fig = plot_sweep(sweep(base, {"driver.sigma_theta": [1e-7, 1e-6]}))
    >>> [ax.get_title().split(",")[0] for ax in fig.axes[:2]]
    ['against t', 'at the last recorded time']
    >>> SHARED_SEEDS_NOTE in fig._suptitle.get_text()
    True
    """
    data, source, name = _load(result, read_from)
    ds = data.to_dataset() if isinstance(data, xr.DataTree) else data
    dims = swept_dims(ds)
    if not dims:
        raise ResultError(f"{source} has no dimension of swept values (a coordinate with the attribute "
                          "'sweep_key', as slidernet sweep writes it): plot one run with "
                          "slidernet.analysis.plots.plot_result.")
    if "t" not in ds.coords:
        raise ResultError(f"{source} is not a result of slidernet sweep: it has no time coordinate 't'.")
    if path is not None:
        _check_format(Path(path))
    panels = [p for p in time_panels(ds) if _mean_name(p[0]) in ds]

    fig = figure
    if fig is None:
        fig = Figure()
        FigureCanvasAgg(fig)
    fig.set_size_inches(12.0, 3.0 * max(len(panels), 1) + 1.6)
    fig.set_layout_engine("constrained")
    grid = fig.add_gridspec(max(len(panels), 1), 2, width_ratios=(1.4, 1.0))
    points = _points(ds, dims)
    colours, mappable = _colours(ds, dims, points)
    t = ds["t"].values
    log_t = bool((t > 0).any())
    shown = t > 0 if log_t else np.ones(t.shape, bool)
    left = []
    for row, (var, _, ylabel) in enumerate(panels):
        ax = fig.add_subplot(grid[row, 0], sharex=left[0] if left else None)
        left.append(ax)
        mean, sem = ds[_mean_name(var)], ds[_sem_name(var)] if _sem_name(var) in ds else None
        for (label, where), colour in zip(points, colours, strict=True):
            m = mean.isel(where).values.astype(float)
            ax.plot(t[shown], m[shown], "-", color=colour, lw=1.2, label=label)
            if sem is not None:
                s = sem.isel(where).values.astype(float)
                ax.fill_between(t[shown], (m - s)[shown], (m + s)[shown], color=colour, alpha=0.15, lw=0)
        if var == "n" and log_t and (mean.values[..., shown] > 0).any():
            ax.set_yscale("log")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3, which="both")
        if row == 0:
            ax.set_title(r"against t, one curve per sweep point (mean, band: $\pm$ s.e.)", fontsize=9)
            if mappable is None:
                ax.legend(fontsize=7, loc="best")
        _late_panel(fig.add_subplot(grid[row, 1]), ds, dims, var, ylabel, title=row == 0)
    if left:
        left[-1].set_xlabel(r"$t/\tau_\mathrm{th}$ (dimensionless time)")
        if log_t:
            left[0].set_xscale("log")
    if mappable is not None:
        fig.colorbar(mappable, ax=fig.axes, label=dims[0], fraction=0.02, aspect=50)
    fig.suptitle(_title(ds, dims, name or ds.attrs.get("title", "slidernet sweep result")), fontsize=10)
    if path is not None:
        save_figure(fig, path, dpi=dpi)
    return fig


def _mean_name(var: str) -> str:
    return "mu_eff" if var == "mu_eff" else f"{var}_mean"


def _sem_name(var: str) -> str:
    return f"{var}_sem"


def _label(ds: xr.Dataset, dims: list[str], where: dict[str, int]) -> str:
    return ", ".join(f"{d} = {_words(ds[d].values[where[d]].item())}" for d in dims if d in where)


def _points(ds: xr.Dataset, dims: list[str]) -> list[tuple[str, dict[str, int]]]:
    """Every sweep point, in C order: its label and its position along the sweep dimensions."""
    return [(_label(ds, dims, dict(zip(dims, idx, strict=True))), dict(zip(dims, idx, strict=True)))
            for idx in np.ndindex(*(ds.sizes[d] for d in dims))]


def _numeric(values: np.ndarray) -> bool:
    return values.dtype.kind in "iuf"


def _log_axis(values: np.ndarray) -> bool:
    """A logarithmic axis for positive values that span a decade or more."""
    return bool(_numeric(values) and (values > 0).all() and values.max() >= 10 * values.min())


def _colours(ds: xr.Dataset, dims: list[str],
             points: list[tuple[str, dict[str, int]]]) -> tuple[list, ScalarMappable | None]:
    """One colour per point: from a colour map of the value where one numeric key is swept (with its
    mappable, for a colorbar), else from the cycle of distinct colours (no mappable: a legend tells them)."""
    values = ds[dims[0]].values
    if len(dims) == 1 and _numeric(values) and values.size > 1:
        norm = (LogNorm if _log_axis(values) else Normalize)(vmin=float(values.min()), vmax=float(values.max()))
        mappable = ScalarMappable(norm=norm, cmap="viridis")
        return [mappable.to_rgba(float(v)) for v in values], mappable
    return [f"C{k % 10}" for k in range(len(points))], None


def _late_panel(ax, ds: xr.Dataset, dims: list[str], var: str, ylabel: str, title: bool) -> None:
    """The value at the last recorded time against the first swept key, +- one standard error; one curve per
    combination of the other swept keys."""
    x = ds[dims[0]].values
    position = x if _numeric(x) else np.arange(x.size)
    mean = ds[_mean_name(var)].isel(t=-1)
    sem = ds[_sem_name(var)].isel(t=-1) if _sem_name(var) in ds else None
    others = dims[1:]
    for k, idx in enumerate(np.ndindex(*(ds.sizes[d] for d in others))):
        where = dict(zip(others, idx, strict=True))
        m = mean.isel(where).transpose(dims[0]).values.astype(float)
        s = None if sem is None else sem.isel(where).transpose(dims[0]).values.astype(float)
        ax.errorbar(position, m, yerr=s if s is not None and np.isfinite(s).all() else None, fmt="o-",
                    color=f"C{k % 10}", ms=4, capsize=3, label=_label(ds, others, where) or None)
    if not _numeric(x):
        ax.set_xticks(position, [str(v) for v in x])
    elif _log_axis(x):
        ax.set_xscale("log")
    if others:
        ax.legend(fontsize=7, loc="best")
    ax.set_xlabel(dims[0])
    ax.set_ylabel(ylabel.split(" (")[0])
    ax.grid(alpha=0.3, which="both")
    if title:
        ax.set_title(f"at the last recorded time, t = {_words(ds['t'].values[-1].item())} "
                     r"$\tau_\mathrm{th}$ ($\pm$ s.e.)", fontsize=9)


def _title(ds: xr.Dataset, dims: list[str], heading: str) -> str:
    """The scene (point 0's, the swept keys marked), the swept values, the options, the shared seeds."""
    keys = [str(ds[d].attrs["sweep_key"]) for d in dims]
    lines = ["swept: " + "; ".join(f"{d} = {', '.join(_words(v.item()) for v in ds[d].values)}" for d in dims)]
    try:
        configs = json.loads(ds.attrs.get("configs", "[]"))
    except ValueError:
        configs = []
    if configs:
        from slidernet.config import load_config

        scene = json.loads(json.dumps(configs[0]))
        for key in keys:
            *parents, last = key.split(".")
            table = scene
            for part in parents:
                table = table.setdefault(part, {})
            table[last] = "(swept)"
        options = [(k, words) for k, words in non_default_options(load_config(configs[0]))
                   if not any(k == s or k.startswith(s + ".") or s.startswith(k + ".") for s in keys)]
        lines.insert(0, _summary(scene, ds, options))
    if shares_seeds(ds):
        lines.append(SHARED_SEEDS_NOTE)
    return f"{heading}: " + "\n".join(lines)
