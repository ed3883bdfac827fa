"""Pictures of a result: its standard panels, and the per-node fields of a network.

:func:`plot_result` draws what a user looks at first (``slidernet plot``):
n, mu_max, <x_G^2> and mu_eff against t, with the paper's closed forms of
:mod:`slidernet.analysis.theory` where they apply (:func:`theory_overlays`),
and for a network its slip map and mu_s field.

A result of a network scene (kernel ``csr`` in 1D, ``vec`` in 2D) holds two
per-node variables, dims ``(realization, node)``:

* ``node_slips``: number of slips of each node over the whole run;
* ``mu_s``: static threshold of each node at the end (dimensionless).

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
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr
from matplotlib.backend_bases import FigureCanvasBase
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PathCollection
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from slidernet.analysis import theory
from slidernet.errors import ConfigError, ResultError, SlidernetError
from slidernet.io import read_result, result_config, save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from slidernet.config import Config
    from slidernet.model.network import Network

__all__ = ["EDGE_LIMIT", "Overlay", "mu_s_field", "network_of", "node_field", "plot_result",
           "save_network_pictures", "slip_map", "theory_overlays"]

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


def _geometry(cfg: dict[str, Any]) -> str:
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
    return (f"{_geometry(cfg)}, {cfg.get('steps')} steps of " r"$\tau_\mathrm{th}$, "
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


# ---------------------------------------------------------------------------
# the standard panels of a result


@dataclass(frozen=True)
class Overlay:
    """One closed form of :func:`theory_overlays`: its values at the recorded times, or why there are none.

    Attributes
    ----------
    name : str
        Short name, e.g. ``"eq. (slope)"``.
    label : str
        Legend text when drawn (matplotlib mathtext).
    values : numpy.ndarray or None
        The prediction at every recorded time, shape (T,), in the units of
        the variable it is drawn over; None where the law does not apply.
    reason : str
        Why ``values`` is None; empty otherwise.
    """

    name: str
    label: str
    values: np.ndarray | None = None
    reason: str = ""

    @property
    def legend(self) -> str:
        """The legend entry: the label, or the name and why it is not drawn."""
        return self.label if self.values is not None else f"{self.name}: not drawn ({self.reason})"


def theory_overlays(ds: xr.Dataset, config: Config | None = None) -> dict[str, Overlay]:
    r"""The paper's closed forms for a result, at its recorded times.

    The laws of :mod:`slidernet.analysis.theory` describe the paper's two
    sliders; for any other network every overlay is None. Where they apply:

    ``"n"``
        eq. ``slope``, n = <r> t with <r> from
        :func:`~slidernet.analysis.theory.mean_rearrangements` (Ntilde,
        sigma_theta, mu_d and the mean of p(mu_s) as the model draws it,
        i.e. conditioned on mu_s > mu_d); needs the ``gaussian_steps``
        driver, and <r> > 0 (sigma_theta > mu_d Ntilde).
    ``"mu_max_exact"``
        the exact mean of the largest of n + 2 draws at the measured mean
        n(t) (:func:`~slidernet.analysis.theory.mu_max_moments`), for any law.
    ``"mu_max_leading"``
        eq. ``mumaxth``, mean mu_s + sigma_mu sqrt(2 ln(<r> t)) with <r>
        measured (``r_mean``); a Gaussian p(mu_s) only.
    ``"x_G2"``
        the order-of-magnitude law sigma_theta^2 l0^2 ln(<r> t)
        (:func:`~slidernet.analysis.theory.msd`), <r> measured; needs the
        ``gaussian_steps`` driver.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`slidernet.run`: ``t``, ``n_mean`` and ``r_mean``,
        and the resolved configuration in ``ds.attrs["config"]``.
    config : Config, optional
        The result's configuration, to skip rebuilding it from the attributes.

    Returns
    -------
    dict of str to Overlay
        Keys ``"n"``, ``"mu_max_exact"``, ``"mu_max_leading"``, ``"x_G2"``;
        values of shape (T,) in the units of n, mu_max and <x_G^2> (l0^2).

    Examples
    --------
    >>> import slidernet
    >>> ds = slidernet.run({"seed": 1, "realizations": 2, "steps": 100,
    ...                     "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...                     "friction": {"mu_d": 0.5,
    ...                                  "static": {"name": "uniform", "low": 0.55, "high": 0.65}},
    ...                     "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
    >>> overlays = theory_overlays(ds)
    >>> overlays["mu_max_exact"].values.shape == ds["t"].shape
    True
    >>> overlays["mu_max_leading"].legend
    'eq. (mumaxth): not drawn (Gaussian p(mu_s) only)'
    """
    from slidernet.config import load_config

    cfg = config if config is not None else load_config(result_config(ds))
    t = ds["t"].values.astype(float)
    r_measured = float(ds["r_mean"]) if "r_mean" in ds else None
    static = cfg.friction.static
    overlays = {
        "n": Overlay("eq. (slope)", ""),
        "mu_max_exact": Overlay("exact mean of the max of n + 2 draws",
                                r"exact: $E[\max$ of $n+2$ draws$]$ at the measured $\bar n(t)$"),
        "mu_max_leading": Overlay("eq. (mumaxth)", r"eq. (mumaxth): $\bar\mu_s + \sigma_\mu"
                                                   r"\sqrt{2\ln(\langle r\rangle t/\tau_\mathrm{th})}$, "
                                                   r"$\langle r\rangle$ measured"),
        "x_G2": Overlay("law of <x_G^2>", r"law: $\sigma_\theta^2 l_0^2\ln(\langle r\rangle t/\tau_\mathrm{th})$,"
                                          " order of magnitude"),
    }

    def skip(key: str, reason: str) -> None:
        overlays[key] = Overlay(overlays[key].name, overlays[key].label, None, reason)

    def draw(key: str, values: np.ndarray, label: str | None = None) -> None:
        o = overlays[key]
        overlays[key] = Overlay(o.name, label or o.label, np.broadcast_to(values, t.shape).astype(float))

    if not cfg.network.is_two_slider():
        for key in overlays:
            skip(key, "two sliders only")
        return overlays
    gaussian_steps = cfg.driver.name == "gaussian_steps"
    sigma_theta = float(cfg.driver.params["sigma_theta"]) if gaussian_steps else None
    mu_d = cfg.friction.mu_d
    dist = cfg.distribution()

    paper_slip = cfg.friction.slip_factor() == 2.0  # the laws of n and x_G rest on the paper's slip length
    if not gaussian_steps:
        skip("n", "gaussian_steps driver only")
    elif not paper_slip:
        skip("n", "the paper's slip only (friction.overshoot = 1)")
    else:
        try:
            r_slope = float(theory.mean_rearrangements(sigma_theta, cfg.network.Ntilde, mu_d,
                                                       float(dist.mean_max(1))))
        except SlidernetError as exc:
            skip("n", str(exc))
        else:
            if r_slope > 0:
                draw("n", r_slope * t, r"eq. (slope): $n = \langle r\rangle t/\tau_\mathrm{th}$, "
                                       rf"$\langle r\rangle = {r_slope:.3g}$")
            else:
                skip("n", rf"$\langle r\rangle = {r_slope:.3g} \leq 0$: $\sigma_\theta \leq \mu_d\tilde N$")

    if "n_mean" in ds:
        try:
            draw("mu_max_exact", theory.mu_max_moments(dist, ds["n_mean"].values)[0])
        except SlidernetError as exc:
            skip("mu_max_exact", str(exc))
    else:
        skip("mu_max_exact", "needs n")

    n_typical = None if r_measured is None else r_measured * t
    if static.name != "gaussian":
        skip("mu_max_leading", "Gaussian p(mu_s) only")
    elif n_typical is None:
        skip("mu_max_leading", "needs n")
    else:
        draw("mu_max_leading", theory.mu_max_leading(float(static.params["mean"]), float(static.params["std"]),
                                                     n_typical))

    if not gaussian_steps:
        skip("x_G2", "gaussian_steps driver only")
    elif not paper_slip:
        skip("x_G2", "the paper's slip only (friction.overshoot = 1)")
    elif n_typical is None:
        skip("x_G2", "needs n")
    else:
        draw("x_G2", theory.msd(sigma_theta, n_typical))
    return overlays


#: The time panels of :func:`plot_result`, in their order on the grid: the
#: variable drawn (``<name>_mean`` and ``<name>_sem`` of the result), the
#: observable that records it, and the y label.
TIME_PANELS = (
    ("n", "n", r"$n$ (rearrangements since $t = 0$)"),
    ("mu_max", "mu_max", r"$\mu_\mathrm{max}$ (largest threshold $\mu_s$)"),
    ("x_G2", "x_G", r"$\langle x_G^2\rangle$ ($l_0^2$)"),
    ("mu_eff", "mu_eff", r"$\mu_\mathrm{eff}$ (virtual tilt test)"),
)


def _read(path: Path) -> xr.Dataset | xr.DataTree:
    """A result file read into memory, or a ResultError that names the file and what is wrong."""
    if not path.exists():
        raise ResultError(f"The result file {str(path)!r} does not exist.")
    if not path.is_file():
        raise ResultError(f"The result file {str(path)!r} is not a file (a result is the result.nc of "
                          "`slidernet run`).")
    try:
        return read_result(path)
    except (OSError, ValueError) as exc:
        raise ResultError(f"The file {str(path)!r} is not a readable netCDF file: "
                          f"{getattr(exc, 'strerror', None) or exc}.") from None


def _check_result(ds: xr.Dataset | xr.DataTree, source: str) -> None:
    """Refuse a dataset that is not one run of slidernet (no n over (realization, t))."""
    if isinstance(ds, xr.DataTree):
        raise ResultError(
            f"{source} holds a sweep whose points differ in number of nodes (an xarray DataTree: the stacked "
            "variables at its root, each point's per-node variables in its group point_<i>), not one run. "
            "Plot one point: its own result, OUT/points/<i>/result.nc of `slidernet sweep --out OUT`."
        )
    missing = [name for name, there in (("t", "t" in ds.coords), ("n", "n" in ds.data_vars),
                                        ("n_mean", "n_mean" in ds.data_vars)) if not there]
    if missing:
        has = ", ".join(sorted(map(str, ds.variables))) or "nothing"
        raise ResultError(
            f"{source} is not a result of slidernet run: it has no {' and no '.join(map(repr, missing))} "
            f"(the time t in tau_th, the rearrangements n over (realization, t) and their ensemble mean). "
            f"It holds: {has}."
        )
    if ds["n"].dims != ("realization", "t"):
        extra = [d for d in ds["n"].dims if d not in ("realization", "t")]
        raise ResultError(
            f"{source} holds more than one run: its 'n' has dims {ds['n'].dims}, with {extra} besides "
            "(realization, t), as a sweep has. Plot one point: select it, e.g. ds.isel("
            f"{extra[0]}=0), and pass that dataset to slidernet.analysis.plots.plot_result."
        )


def _check_format(path: Path) -> None:
    fmt = path.suffix.lstrip(".").lower()
    formats = FigureCanvasBase.get_supported_filetypes()
    if fmt and fmt not in formats:
        raise ConfigError(f"The picture's file {str(path)!r} has the suffix {path.suffix!r}, which matplotlib "
                          f"cannot write. Use one of: {', '.join('.' + f for f in sorted(formats))}.")


def _summary(cfg: dict[str, Any], ds: xr.Dataset) -> str:
    """Two lines on the run: scene, size, seed; then the parameters of the model."""

    def plugin(spec: dict[str, Any]) -> str:
        params = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                           for k, v in spec.items() if k != "name")
        return f"{spec.get('name')}({params})"

    return (f"{_geometry(cfg)}, {ds.sizes['realization']} realizations of {cfg.get('steps')} "
            rf"$\tau_\mathrm{{th}}$, seed {ds.attrs.get('seed', cfg.get('seed'))}, "
            f"kernel {ds.attrs.get('kernel', '?')}\n"
            rf"$\tilde N$ = {cfg['network']['Ntilde']:g}, $\mu_d$ = {cfg['friction']['mu_d']:g}, "
            rf"$p(\mu_s)$ = {plugin(cfg['friction']['static'])}, driver {plugin(cfg['driver'])}")


def _time_panel(ax: Axes, ds: xr.Dataset, name: str, observable: str, ylabel: str,
                overlays: list[Overlay], log_t: bool) -> None:
    """Ensemble mean +- one standard error of ``name`` against t, with its overlays; a note if absent."""
    if f"{name}_mean" not in ds and name not in ds:
        ax.set_axis_off()
        ax.text(0.5, 0.5, f"{ylabel}\nnot recorded in this result:\nadd \"{observable}\" to 'observables'",
                transform=ax.transAxes, ha="center", va="center", fontsize=9, color="0.4")
        return
    t = ds["t"].values
    shown = t > 0 if log_t else np.ones(t.shape, bool)
    mean = ds[f"{name}_mean" if f"{name}_mean" in ds else name].values.astype(float)
    sem_name = f"{name}_sem"
    sem = ds[sem_name].values.astype(float) if sem_name in ds else np.full(mean.shape, np.nan)
    R = ds.sizes["realization"]
    pooled = name == "mu_eff"  # one pooled ratio over every tilt test, not a mean of realizations
    what = "pooled over the tilt tests" if pooled else f"mean over {R} realization{'s' * (R > 1)}"
    band = r" $\pm$ s.e." if np.isfinite(sem[shown]).any() else ""
    ok = shown & np.isfinite(mean)
    ax.fill_between(t[ok], (mean - sem)[ok], (mean + sem)[ok], color="C0", alpha=0.3, lw=0)
    ax.plot(t[ok], mean[ok], "-", marker="o" if ok.sum() <= 200 else None, ms=2.5, color="C0",
            label=what + band)
    for o in overlays:
        if o.values is None:
            ax.plot([], [], ls="none", label=o.legend)
        else:
            ax.plot(t[shown], o.values[shown], "--" if "eq." in o.name or "law" in o.name else "-",
                    color="k", lw=1.0, label=o.legend)
    if pooled and log_t and t[0] == 0 and np.isfinite(mean[0]):
        ax.axhline(mean[0], color="0.5", ls=":", lw=1.0,
                   label=rf"$t = 0$ (fresh system): $\mu_\mathrm{{eff}}$ = {mean[0]:.4g}")
    if name == "n" and log_t and (mean[ok] > 0).any():
        ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="best")


def plot_result(result: xr.Dataset | str | os.PathLike[str], path: str | os.PathLike[str] | None = None, *,
                figure: Figure | None = None, dpi: int = DPI) -> Figure:
    r"""The standard panels of a result: what to look at before reading the numbers.

    Four panels against t (tau_th; a logarithmic axis over t > 0): the
    number of rearrangements n, the largest threshold mu_max, the mean
    square displacement <x_G^2> (each an ensemble mean with a band of
    +- one standard error over the realizations) and mu_eff of the virtual
    tilt test (pooled over the tests, with its standard error). The closed
    forms of :func:`theory_overlays` are drawn over them where they apply,
    and the legend says why one is not. A panel whose variable was not
    recorded says which observable to add. A network's result gets two more
    panels: its slip map (:func:`slip_map`) and mu_s field
    (:func:`mu_s_field`) of realization 0.

    Parameters
    ----------
    result : xarray.Dataset or path-like
        A result of :func:`slidernet.run`, or the path of a result file
        (``result.nc`` of ``slidernet run``).
    path : path-like, optional
        Where to write the figure, atomically (a temporary file, then a
        rename); its suffix picks the format (``.png``, ``.pdf``, ``.svg``,
        ...). None: write nothing.
    figure : matplotlib.figure.Figure, optional
        An empty figure to draw in (e.g. ``pyplot.figure()``, to show it in
        a window); its size and layout are set here. Default: a new Agg
        figure, outside pyplot.
    dpi : int
        Resolution of a raster file, in dots per inch.

    Returns
    -------
    matplotlib.figure.Figure
        Its first four axes are the time panels (n, mu_max, <x_G^2>, mu_eff),
        in that order; a network's slip map and mu_s field follow (each with
        its colorbar in 2D).

    Raises
    ------
    ResultError
        Before anything is drawn or written: the file is missing or not
        netCDF; the dataset has no ``t``, ``n`` or ``n_mean`` (not a result
        of ``slidernet run``) or holds several runs (a sweep: a Dataset with
        the sweep dimensions, or a DataTree whose points differ in number
        of nodes).
    ConfigError
        Before anything is drawn or written: ``path`` has a suffix
        matplotlib cannot write.

    Examples
    --------
    >>> import slidernet
    >>> ds = slidernet.run({"seed": 1, "realizations": 2, "steps": 100,
    ...                     "observables": ["n", "mu_max", "x_G", "mu_eff"],
    ...                     "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...                     "friction": {"mu_d": 0.5,
    ...                                  "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...                     "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
    >>> fig = plot_result(ds)
    >>> [ax.get_ylabel().split(" (")[0] for ax in fig.axes]
    ['$n$', '$\\mu_\\mathrm{max}$', '$\\langle x_G^2\\rangle$', '$\\mu_\\mathrm{eff}$']
    >>> fig.axes[1].get_legend().get_texts()[1].get_text().startswith("exact")
    True
    """
    from slidernet.config import build_network, load_config

    if isinstance(result, (xr.Dataset, xr.DataTree)):
        ds, source, name = result, "The dataset", None
    else:
        file = Path(result)
        ds, source, name = _read(file), f"The file {str(file)!r}", file.name
    _check_result(ds, source)
    if path is not None:
        _check_format(Path(path))
    cfg_dict = result_config(ds) if "config" in ds.attrs else None
    cfg = load_config(cfg_dict) if cfg_dict is not None else None
    if cfg is None:
        overlays = {key: Overlay(key, "", None, "no configuration in the result") for key in
                    ("n", "mu_max_exact", "mu_max_leading", "x_G2")}
    else:
        overlays = theory_overlays(ds, cfg)
    panel_overlays = {"n": [overlays["n"]], "mu_max": [overlays["mu_max_exact"], overlays["mu_max_leading"]],
                      "x_G2": [overlays["x_G2"]], "mu_eff": []}
    maps = cfg is not None and "node_slips" in ds and "mu_s" in ds
    net = build_network(cfg) if maps else None

    fig = figure
    if fig is None:
        fig = Figure()
        FigureCanvasAgg(fig)
    two_d = net is not None and net.dim == 2
    fig.set_size_inches(11.0, 12.5 if two_d else (10.5 if maps else 7.5))
    # The 2D maps size their markers for their axes when drawn: no layout engine may move them later.
    if two_d:
        grid = fig.add_gridspec(3, 2, height_ratios=(1.0, 1.0, 1.5), left=0.08, right=0.95, bottom=0.04,
                                top=0.93, hspace=0.32, wspace=0.25)
    else:
        fig.set_layout_engine("constrained")
        grid = fig.add_gridspec(3 if maps else 2, 2)
    t = ds["t"].values
    log_t = bool((t > 0).any())
    first = None
    for k, (var, observable, ylabel) in enumerate(TIME_PANELS):
        ax = fig.add_subplot(grid[k // 2, k % 2], sharex=first)
        first = first or ax
        _time_panel(ax, ds, var, observable, ylabel, panel_overlays[var], log_t)
        if k >= 2:
            ax.set_xlabel(r"$t/\tau_\mathrm{th}$ (dimensionless time)")
    if log_t:
        first.set_xscale("log")
    if maps:
        slip_map(ds, 0, ax=fig.add_subplot(grid[2, 0]), network=net)
        mu_s_field(ds, 0, ax=fig.add_subplot(grid[2, 1]), network=net)
    heading = name or ds.attrs.get("title", "slidernet result")
    fig.suptitle(heading if cfg_dict is None else f"{heading}: {_summary(cfg_dict, ds)}", fontsize=10)
    if path is not None:
        save_figure(fig, path, dpi=dpi)
    return fig
