"""Pictures of a result: its standard panels, with the theory that applies.

:func:`plot_result` draws what a user looks at first (``slidernet plot``):
n, mu_max, <x_G^2> and mu_eff against t, with the paper's closed forms of
:mod:`slidernet.analysis.theory` where they apply (:func:`theory_overlays`),
and for a network its slip map and mu_s field, drawn by
:mod:`slidernet.analysis.network_maps` (whose names are importable from here
too: :func:`slip_map`, :func:`mu_s_field`, :func:`node_field`,
:func:`network_of`, :func:`save_network_pictures`).

Figures are made with :class:`matplotlib.figure.Figure` and an Agg canvas,
never through pyplot's global state, so library calls neither open windows
nor leak figures; a caller who passes its own figure keeps it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr
from matplotlib.backend_bases import FigureCanvasBase
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from pydantic import BaseModel

from slidernet.analysis import theory
from slidernet.analysis.network_maps import (
    DPI,
    EDGE_LIMIT,
    geometry_words,
    mu_s_field,
    network_of,
    node_field,
    save_network_pictures,
    slip_map,
)
from slidernet.errors import ConfigError, ResultError, SlidernetError
from slidernet.io import read_result, result_config, save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from slidernet.config import Config

__all__ = ["EDGE_LIMIT", "Overlay", "mu_s_field", "network_of", "node_field", "non_default_options", "plot_result",
           "save_network_pictures", "slip_map", "theory_overlays"]


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
#: The panel of the observable ``contact_age``, after :data:`TIME_PANELS` where the result records it.
CONTACT_AGE_PANEL = ("contact_age", "contact_age",
                     r"contact age ($\tau_\mathrm{th}$, mean over the nodes)")


def time_panels(ds: xr.Dataset) -> tuple[tuple[str, str, str], ...]:
    """The time panels of a result: :data:`TIME_PANELS`, and the contact age where it is recorded."""
    return TIME_PANELS + ((CONTACT_AGE_PANEL,) if "contact_age_mean" in ds else ())


# What the summary line of a figure already shows (the scene, its size and seed), or what never changes a
# result (execution) or only says what was recorded (observables, which the panels show).
_SHOWN = {"seed", "realizations", "steps", "observables", "execution", "units", "network.kind", "network.n",
          "network.shape", "network.path"}


def _words(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, BaseModel):
        value = value.model_dump(mode="json")
    return str(value)


def non_default_options(config: Config) -> list[tuple[str, str]]:
    """The options of a configuration that differ from their defaults, in a few words each.

    Read from the configuration's models (every field that has a default and
    another value), so that an option added later is named without a change
    here; the values without a default (``network.Ntilde``, ``friction.mu_d``,
    ``p(mu_s)``, the driver) and what a figure's summary line shows (the
    scene, its size and seed) are left out. A table that is absent by default
    (``[friction.strengthening]``, ``[dynamics]``) is named with its values.

    Parameters
    ----------
    config : Config
        A resolved configuration (e.g. of a result's ``config`` attribute).

    Returns
    -------
    list of (str, str)
        (dotted key, words), in the order of the models' fields, e.g.
        ``("friction.overshoot", "overshoot 0.5")``.

    Examples
    --------
    >>> from slidernet.config import load_config
    >>> cfg = load_config({"steps": 10, "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...                    "friction": {"mu_d": 0.5, "overshoot": 0.5,
    ...                                 "strengthening": {"beta": 0.02, "tau_c": 3.0},
    ...                                 "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...                    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
    >>> non_default_options(cfg)
    [('friction.overshoot', 'overshoot 0.5'), ('friction.strengthening', 'strengthening beta=0.02, tau_c=3')]
    """
    from slidernet.config.base import _Strict

    found: list[tuple[str, str]] = []

    def default(field: Any) -> Any:
        return field.get_default(call_default_factory=True)

    def table(model: BaseModel) -> str:
        """A table absent by default: its values that are required or not at their default."""
        fields = type(model).model_fields.items()
        return ", ".join(f"{name}={_words(getattr(model, name))}" for name, field in fields
                         if field.is_required() or getattr(model, name) != default(field))

    def walk(model: BaseModel, prefix: str) -> None:
        for name, field in type(model).model_fields.items():
            key, value = prefix + name, getattr(model, name)
            if key in _SHOWN:
                continue
            if field.is_required():
                if isinstance(value, _Strict):  # a table of options (network, friction), not a plugin's values
                    walk(value, key + ".")
                continue
            if value == default(field):
                continue
            if isinstance(value, _Strict) and isinstance(default(field), _Strict):
                walk(value, key + ".")
            elif isinstance(value, _Strict):
                found.append((key, f"{name} {table(value)}"))
            else:
                found.append((key, f"{name} {_words(value)}"))

    walk(config, "")
    return found


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


def _load(result: xr.Dataset | xr.DataTree | str | os.PathLike[str],
          read_from: str | None) -> tuple[xr.Dataset | xr.DataTree, str, str | None]:
    """A result given as data or as a path: (its data, how errors name it, the file's name for a title)."""
    if isinstance(result, (xr.Dataset, xr.DataTree)):
        if read_from is None:
            return result, "The dataset", None
        return result, f"The file {read_from!r}", Path(read_from).name
    file = Path(result)
    return _read(file), f"The file {str(file)!r}", file.name


def _check_result(ds: xr.Dataset | xr.DataTree, source: str) -> None:
    """Refuse a dataset that is not one run of slidernet (no n over (realization, t))."""
    if isinstance(ds, xr.DataTree):
        raise ResultError(
            f"{source} holds a sweep whose points differ in number of nodes (an xarray DataTree: the stacked "
            "variables at its root, each point's per-node variables in its group point_<i>), not one run. "
            "Plot it with slidernet.analysis.sweep_plots.plot_sweep (`slidernet plot` does), or one point: its "
            "own result, OUT/points/<i>/result.nc of `slidernet sweep --out OUT`."
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
            "(realization, t), as a sweep has. Plot a sweep's result with "
            f"slidernet.analysis.sweep_plots.plot_sweep, or one point: select it, e.g. ds.isel({extra[0]}=0), "
            "and pass that dataset to plot_result."
        )


def _check_format(path: Path) -> None:
    fmt = path.suffix.lstrip(".").lower()
    formats = FigureCanvasBase.get_supported_filetypes()
    if fmt and fmt not in formats:
        raise ConfigError(f"The picture's file {str(path)!r} has the suffix {path.suffix!r}, which matplotlib "
                          f"cannot write. Use one of: {', '.join('.' + f for f in sorted(formats))}.")


def _summary(cfg: dict[str, Any], ds: xr.Dataset, options: list[tuple[str, str]] = ()) -> str:
    """Two lines on the run: scene, size, seed; then the parameters of the model; a third with ``options``
    (:func:`non_default_options`) where there are any."""

    def plugin(spec: dict[str, Any]) -> str:
        params = ", ".join(f"{k} = {_words(v)}" for k, v in spec.items() if k != "name")
        return f"{spec.get('name')}({params})"

    return (f"{geometry_words(cfg)}, {ds.sizes['realization']} realizations of {cfg.get('steps')} "
            rf"$\tau_\mathrm{{th}}$, seed {ds.attrs.get('seed', cfg.get('seed'))}, "
            f"kernel {ds.attrs.get('kernel', '?')}\n"
            rf"$\tilde N$ = {_words(cfg['network']['Ntilde'])}, $\mu_d$ = {_words(cfg['friction']['mu_d'])}, "
            rf"$p(\mu_s)$ = {plugin(cfg['friction']['static'])}, driver {plugin(cfg['driver'])}"
            + ("\noptions not at their default: " + ", ".join(words for _, words in options) if options else ""))


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
                figure: Figure | None = None, dpi: int = DPI, read_from: str | None = None) -> Figure:
    r"""The standard panels of a result: what to look at before reading the numbers.

    Four panels against t (tau_th; a logarithmic axis over t > 0): the
    number of rearrangements n, the largest threshold mu_max, the mean
    square displacement <x_G^2> (each an ensemble mean with a band of
    +- one standard error over the realizations) and mu_eff of the virtual
    tilt test (pooled over the tests, with its standard error); a fifth,
    the contact age (mean over the nodes of the time since their last slip),
    where the result records it. The closed
    forms of :func:`theory_overlays` are drawn over them where they apply,
    and the legend says why one is not. A panel whose variable was not
    recorded says which observable to add. A network's result gets two more
    panels: its slip map (:func:`slip_map`) and mu_s field
    (:func:`mu_s_field`) of realization 0. The title gives the scene and
    the model's parameters, and names every option that is not at its
    default (:func:`non_default_options`).

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
    read_from : str, optional
        The path of the file that ``result``, a dataset, was read from: the
        title and the errors name it.

    Returns
    -------
    matplotlib.figure.Figure
        Its first axes are the time panels (n, mu_max, <x_G^2>, mu_eff, and
        the contact age where the result records it), in that order; a
        network's slip map and mu_s field follow (each with its colorbar in
        2D).

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

    ds, source, name = _load(result, read_from)
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
    panels = time_panels(ds)
    rows = (len(panels) + 1) // 2  # the time panels, two per row; the maps below them
    two_d = net is not None and net.dim == 2
    fig.set_size_inches(11.0, 3.4 * rows + (5.7 if two_d else (3.7 if maps else 0.7)))
    # The 2D maps size their markers for their axes when drawn: no layout engine may move them later.
    if two_d:
        grid = fig.add_gridspec(rows + 1, 2, height_ratios=(1.0,) * rows + (1.5,), left=0.08, right=0.95,
                                bottom=0.04, top=0.93, hspace=0.32, wspace=0.25)
    else:
        fig.set_layout_engine("constrained")
        grid = fig.add_gridspec(rows + maps, 2)
    t = ds["t"].values
    log_t = bool((t > 0).any())
    first = None
    for k, (var, observable, ylabel) in enumerate(panels):
        ax = fig.add_subplot(grid[k // 2, k % 2], sharex=first)
        first = first or ax
        _time_panel(ax, ds, var, observable, ylabel, panel_overlays.get(var, []), log_t)
        if k >= len(panels) - 2:
            ax.set_xlabel(r"$t/\tau_\mathrm{th}$ (dimensionless time)")
    if log_t:
        first.set_xscale("log")
    if maps:
        slip_map(ds, 0, ax=fig.add_subplot(grid[rows, 0]), network=net)
        mu_s_field(ds, 0, ax=fig.add_subplot(grid[rows, 1]), network=net)
    heading = name or ds.attrs.get("title", "slidernet result")
    options = non_default_options(cfg) if cfg is not None else []
    fig.suptitle(heading if cfg_dict is None else f"{heading}: {_summary(cfg_dict, ds, options)}", fontsize=10)
    if path is not None:
        save_figure(fig, path, dpi=dpi)
    return fig
