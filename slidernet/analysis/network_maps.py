"""Pictures of a network: a per-node field drawn over the nodes, its slip map and mu_s field.

A result of a network scene (kernel ``csr`` in 1D, ``vec`` in 2D) holds two
per-node variables, dims ``(realization, node)``:

* ``node_slips``: number of slips of each node over the whole run;
* ``mu_s``: static threshold of each node at the end (dimensionless).

:func:`slip_map` and :func:`mu_s_field` draw them over the network
(:func:`node_field`: a scatter of the nodes in 2D, a line against x in 1D);
:func:`save_network_pictures` writes both as PNG files. The standard panels
of a result, which show these maps under its time panels, are
:mod:`slidernet.analysis.plots`'.

Node positions are not stored in the result: the network is rebuilt from the
resolved configuration in its attributes (the geometry of an ``irregular``
network comes from its own ``network.seed``, so the rebuilt network is the
one that ran; a ``graph`` network needs its file to still be readable).

Figures are made with :class:`matplotlib.figure.Figure` and an Agg canvas,
never through pyplot's global state, so library calls neither open windows
nor leak figures; a caller who passes its own Axes keeps its figure.

Examples
--------
>>> from slidernet.model.network import chain
>>> from matplotlib.figure import Figure
>>> ax = Figure().subplots()
>>> line = node_field(ax, chain(4, Ntilde=1e-7), [3, 0, 1, 2], log=True, label="slips")
>>> line.get_ydata().mask.tolist()  # the zero count is masked: no log of 0
[False, True, False, False]
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PathCollection
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from slidernet.errors import ConfigError, ResultError
from slidernet.io import result_config, save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from slidernet.model.network import Network

__all__ = ["EDGE_LIMIT", "mu_s_field", "network_of", "node_field", "save_network_pictures", "slip_map"]

#: Springs are drawn only below this many edges: above it they would hide the
#: nodes at any figure size and cost more to draw than the nodes themselves.
EDGE_LIMIT = 20_000

#: Resolution of the PNG files of :func:`save_network_pictures`, in dots per inch.
DPI = 150

# Diameter of a node marker as a fraction of a short spring's length: with
# springs drawn, gaps between the markers must leave them visible.
_FILL_WITH_EDGES = 0.55
_FILL_WITHOUT_EDGES = 0.9
# Below this diameter (points) Agg would draw nothing visible for a node.
_MIN_DIAMETER_PT = 0.3
# Smaller markers are drawn as squares.
_ROUND_MIN_PT = 2.0


def node_field(
    ax: Axes,
    network: Network,
    values: Sequence[float] | np.ndarray,
    *,
    cmap: str = "viridis",
    log: bool = False,
    label: str = "",
    edges: bool = True,
) -> PathCollection | Line2D:
    """Draw a per-node scalar field of a network on ``ax``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw. In 2D its aspect is set to equal and a colorbar is
        added beside it (space taken from ``ax``).
    network : Network
        The network the values belong to; positions in l0, shape (N, d).
    values : array_like, shape (N,)
        One value per node, in node order (e.g. a row of ``ds["node_slips"]``).
    cmap : str
        Matplotlib colormap name (2D only).
    log : bool
        Logarithmic colour scale (2D) or y axis (1D), for slip counts that
        span decades. Values <= 0 (nodes that never slipped) have no
        logarithm: they are masked, drawn in light grey in 2D (the colormap's
        "bad" colour, noted in the colorbar label) and left out of the line in
        1D. If no value is > 0 the scale spans 1 to 10.
    label : str
        What the values are, with units: the colorbar label in 2D, the y
        label in 1D.
    edges : bool
        In 2D, draw the springs as thin grey segments under the nodes; they
        are left out when the network has ``EDGE_LIMIT`` springs or more.

    Returns
    -------
    matplotlib.collections.PathCollection or matplotlib.lines.Line2D
        In 2D the scatter of the nodes (the mappable of the colorbar; its
        ``get_array()`` holds the values, masked where ``log`` masked them).
        In 1D the line of value against node position, nodes sorted by x.

    Notes
    -----
    The scatter is rasterized (vector output of a million markers would be
    huge) and its markers are sized from a short spring's length and the
    axes' size in points, so a 1000 x 1000 lattice draws in seconds and a 6 x 6
    one still shows round nodes. A later resize of the figure does not
    resize the markers.
    """
    v = np.asarray(values, dtype=float)
    if v.shape != (network.n_nodes,):
        raise ConfigError(
            f"The values of a node field must have shape ({network.n_nodes},), one per node of the "
            f"network. Got shape {v.shape} instead."
        )
    shown = np.ma.masked_less_equal(v, 0.0) if log else np.ma.masked_invalid(v)
    if network.dim == 1:
        return _line_field(ax, network, shown, log=log, label=label)
    return _scatter_field(ax, network, shown, cmap=cmap, log=log, label=label, edges=edges)


def _line_field(ax: Axes, network: Network, shown: np.ma.MaskedArray, *, log: bool, label: str) -> Line2D:
    order = np.argsort(network.positions[:, 0], kind="stable")
    many = network.n_nodes > 200
    (line,) = ax.plot(network.positions[order, 0], shown[order], marker=None if many else "o",
                      markersize=3, linewidth=1.0)
    if log:
        ax.set_yscale("log")
        if shown.count() == 0:
            ax.set_ylim(1.0, 10.0)
    ax.set_xlabel("node position x ($l_0$)")
    ax.set_ylabel(label)
    return line


def _scatter_field(ax: Axes, network: Network, shown: np.ma.MaskedArray, *, cmap: str, log: bool,
                   label: str, edges: bool) -> PathCollection:
    pos = network.positions
    # A short spring rather than the median one, so that the close nodes of an
    # irregular network overlap less; every spring of a lattice has one length.
    spacing = float(np.quantile(network.lengths(), 0.25))
    draw_edges = edges and network.n_edges < EDGE_LIMIT
    if draw_edges:
        segments = pos[network.edges]  # (E, 2 ends, 2 coordinates)
        ax.add_collection(LineCollection(segments, colors="0.7", linewidths=0.5, zorder=1))
    norm = None
    if log:
        positive = shown.compressed()
        # LogNorm cannot autoscale on an all-masked array.
        if positive.size == 0:
            norm = LogNorm(1.0, 10.0)
        else:
            lo, hi = float(positive.min()), float(positive.max())
            norm = LogNorm(lo, hi if hi > lo else 10.0 * lo)
    pad = spacing
    ax.set_xlim(pos[:, 0].min() - pad, pos[:, 0].max() + pad)
    ax.set_ylim(pos[:, 1].min() - pad, pos[:, 1].max() + pad)
    ax.set_aspect("equal")
    fill = _FILL_WITH_EDGES if draw_edges else _FILL_WITHOUT_EDGES
    # Below a couple of points a circle and a square look alike, and squares draw
    # 1.5x faster (a 1000 x 1000 lattice); the colorbar will take ~20 % more width.
    marker = "o" if 0.8 * fill * spacing * _points_per_unit(ax) >= _ROUND_MIN_PT else "s"
    # NaN rather than a masked array: scatter re-masks non-finite values itself, and
    # reading a masked first element warns inside matplotlib.
    sc = ax.scatter(pos[:, 0], pos[:, 1], c=shown.filled(np.nan), cmap=_colormap(cmap), norm=norm, s=1.0,
                    marker=marker, linewidths=0, rasterized=True, plotnonfinite=True, zorder=2)
    ax.set_xlabel("x ($l_0$)")
    ax.set_ylabel("y ($l_0$)")
    n_masked = int(np.ma.count_masked(shown))
    if log and n_masked:
        label = f"{label}\n(grey: {n_masked} nodes at 0, no logarithm)"
    ax.figure.colorbar(sc, ax=ax, label=label)
    # Sized after the colorbar took its share of the axes.
    diameter = max(fill * spacing * _points_per_unit(ax), _MIN_DIAMETER_PT)
    sc.set_sizes([diameter**2])
    return sc


def _colormap(name: str) -> Any:
    from matplotlib import colormaps

    return colormaps[name].with_extremes(bad="0.85")


def _points_per_unit(ax: Axes) -> float:
    """Typographic points per l0 along both axes, once the equal aspect is applied."""
    ax.apply_aspect()
    box = ax.get_position()
    width_in, height_in = ax.figure.get_size_inches()
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    return min(box.width * width_in * 72.0 / abs(x1 - x0), box.height * height_in * 72.0 / abs(y1 - y0))


def network_of(ds: xr.Dataset) -> Network:
    """Rebuild the network of a result from the resolved configuration in its attributes.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`slidernet.run` (or read back with
        :func:`slidernet.io.read_result`).

    Returns
    -------
    Network
        The scene's network, positions in l0, shape (N, d).
    """
    from slidernet.config import load_config
    from slidernet.solver import build_network

    return build_network(load_config(result_config(ds)))


def _node_values(ds: xr.Dataset, name: str, what: str, realization: int) -> np.ndarray:
    """The row of a per-node variable for one realization, with the errors a user can act on."""
    if name not in ds.data_vars:
        raise ResultError(
            f"The dataset has no {name!r} variable: {what} need a network scene (kernel 'csr' or "
            f"'vec'); this result was made by kernel {ds.attrs.get('kernel', 'unknown')!r}."
        )
    R = ds.sizes["realization"]
    if isinstance(realization, (bool, np.bool_)) or not isinstance(realization, (int, np.integer)) \
            or not 0 <= realization < R:
        raise ConfigError(
            f"The 'realization' index must be an integer in [0, {R - 1}] (the result has {R} "
            f"realizations). Got {realization!r} instead."
        )
    return np.asarray(ds[name].isel(realization=int(realization)).values)


def geometry_words(cfg: dict[str, Any]) -> str:
    """The network of a resolved configuration (dict) in a few words: "square 6 x 6", "chain, n = 10"."""
    net = cfg.get("network", {})
    kind = net.get("kind", "?")
    if net.get("shape") is not None:
        return f"{kind} {' x '.join(str(s) for s in net['shape'])}"
    if kind == "graph":
        return f"graph {Path(str(net.get('path'))).name}"
    if kind == "two_slider":
        return "two sliders"
    return f"{kind}, n = {net.get('n')}"


def _scene_title(ds: xr.Dataset, realization: int) -> str:
    cfg = result_config(ds)
    return (f"{geometry_words(cfg)}, {cfg.get('steps')} steps of " r"$\tau_\mathrm{th}$, "
            f"realization {realization} of {ds.sizes['realization']}")


def _figure_size(net: Network) -> tuple[float, float]:
    """Figure size in inches that the network fills, once its equal-aspect axes and colorbar are placed."""
    width = 6.4
    if net.dim == 1:
        return width, 3.6
    extent = np.ptp(net.positions, axis=0) + 2.0 * float(np.median(net.lengths()))
    aspect = float(np.clip(extent[1] / extent[0], 0.3, 3.0))
    # Default subplot box (77.5 % x 77 % of the figure), of which the colorbar takes ~20 % of the width.
    axes_width = 0.775 * 0.8 * width
    return width, float(np.clip(axes_width * aspect / 0.77, 3.0, 9.0))


def _field_figure(ds: xr.Dataset, name: str, what: str, realization: int, ax: Axes | None,
                  network: Network | None, **field: Any) -> Figure:
    values = _node_values(ds, name, what, realization)
    net = network_of(ds) if network is None else network
    if net.n_nodes != values.size:
        raise ConfigError(
            f"The network has {net.n_nodes} nodes but the dataset's {name!r} has {values.size}; "
            "pass the network of this result (or none, to rebuild it)."
        )
    if ax is None:
        # Constrained layout moves the axes at draw time, after the 2D markers were
        # sized for them; only the 1D line can use it.
        fig = Figure(figsize=_figure_size(net), layout="constrained" if net.dim == 1 else None)
        FigureCanvasAgg(fig)
        ax = fig.subplots()
    node_field(ax, net, values, **field)
    ax.set_title(f"{field['label'].splitlines()[0]}\n{_scene_title(ds, int(realization))}", fontsize=10)
    return ax.figure


def slip_map(ds: xr.Dataset, realization: int = 0, ax: Axes | None = None, network: Network | None = None,
             *, log: bool = True) -> Figure:
    """Map of the number of slips of each node over the run.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of a network scene, with ``node_slips`` (dims realization, node).
    realization : int
        Index of the realization shown, in [0, R - 1].
    ax : matplotlib.axes.Axes, optional
        Where to draw; by default a new Agg figure.
    network : Network, optional
        The result's network, to skip rebuilding it from ``ds.attrs["config"]``.
    log : bool
        Logarithmic colour scale (default): counts span decades between the
        boundary, which the dilation drives directly, and the interior.
        Nodes that never slipped are drawn in light grey.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ResultError
        The dataset has no ``node_slips`` (e.g. the two-slider scene, kernel
        ``pair``).
    ConfigError
        ``realization`` is out of range, or ``network`` has another number of
        nodes.
    """
    return _field_figure(ds, "node_slips", "slip maps", realization, ax, network, cmap="magma", log=log,
                         label="slips per node over the run (count)")


def mu_s_field(ds: xr.Dataset, realization: int = 0, ax: Axes | None = None,
               network: Network | None = None) -> Figure:
    """Map of the static threshold mu_s of each node at the end of the run.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of a network scene, with ``mu_s`` (dims realization, node).
    realization : int
        Index of the realization shown, in [0, R - 1].
    ax : matplotlib.axes.Axes, optional
        Where to draw; by default a new Agg figure.
    network : Network, optional
        The result's network, to skip rebuilding it from ``ds.attrs["config"]``.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ResultError
        The dataset has no ``mu_s`` (e.g. the two-slider scene, kernel
        ``pair``).
    ConfigError
        ``realization`` is out of range, or ``network`` has another number of
        nodes.
    """
    return _field_figure(ds, "mu_s", "threshold maps", realization, ax, network, cmap="viridis",
                         label=r"static threshold $\mu_s$ at the end (dimensionless)")


def save_network_pictures(ds: xr.Dataset, out_dir: str | os.PathLike[str], *, dpi: int = DPI) -> dict[str, Path]:
    """Write ``slip_map.png`` and ``mu_s_field.png`` of realization 0 into ``out_dir``, atomically.

    Each picture is written to a temporary file in ``out_dir`` and renamed
    over its target, so an interrupted call never leaves a partial PNG.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of a network scene (``node_slips`` and ``mu_s``).
    out_dir : str or path-like
        Destination folder, created if missing.
    dpi : int
        Resolution in dots per inch.

    Returns
    -------
    dict of str to pathlib.Path
        ``{"slip_map": ..., "mu_s_field": ...}``.

    Raises
    ------
    ResultError, ConfigError
        As :func:`slip_map`, before any file is written.
    """
    # Both checks first, so a two-slider result leaves no file behind.
    _node_values(ds, "node_slips", "slip maps", 0)
    _node_values(ds, "mu_s", "threshold maps", 0)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    net = network_of(ds)
    paths = {}
    for name, draw in (("slip_map", slip_map), ("mu_s_field", mu_s_field)):
        fig = draw(ds, 0, network=net)
        paths[name] = save_figure(fig, out / f"{name}.png", dpi=dpi)
    return paths
