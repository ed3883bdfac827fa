"""Does thermal cycling age the static friction of a network of sliders? With the controls a referee asks for
==========================================================================================================

The paper (Geminard & Bertin 2010) ends on an open question: in a 2D
irregular network of sliders, does the effective friction coefficient still
increase with time under thermal cycling? This study measures mu_eff, the
network tilt test at every recorded time (``mu_eff_at = "records"``, the
same estimator at every size, the pair included), and asks it where the
pair ages, with the controls that decide whether an answer is an artefact:

* **Parameter sets** (``PARAMS``): the base, sigma_mu / (mean - mu_d)
  = 0.1 at mu_d = 0.5, and two where the pair ages: ratio 0.3 at mu_d = 0.5,
  and ratio 0.1 at mu_d = 0.4 (mean 0.6, std 0.03 and 0.02), all at
  sigma_theta / Ntilde = 1, to 1e3 tau_th, 10 recorded times per decade;
  and ratio 0.2 at mu_d = 0.5 (std 0.02) for the runs to 1e4 tau_th.
* **Sizes and geometries**: the pair, free chains of 4 and 16 (driven at
  their ends), irregular (Delaunay) networks of 16, 64, 256 and 1024 sliders
  (driven everywhere: every node of an irregular network feels the
  dilation), each over 8 network geometries (network seeds 0-7) of 4
  realizations, and triangular lattices of 4 x 4 to 32 x 32 (driven at the
  boundary, as the chains). 32 realizations per point.
* **The slip rule**: ``friction.overshoot`` e = 0 and 0.5 beside the
  paper's 1, for the pair and irregular 16, 64, 256, at ratios 0.1 and 0.3.
* **The sliding rule**: the tilt test's stricter criteria, ``[tilt]
  min_slips = 2`` and ``min_displacement = 10`` (the centre of mass moved
  by 10 reference slips within the sliding avalanche), at e = 1 and e = 0,
  for the same sizes and ratios. At e = 1 the three rules are re-draws of
  the tilt test on the same states: each makes ``[tilt] repeats = 4`` tests
  per record (mu_eff_realization their mean, mu_eff_spread their spread).
* **The restated study** (issue 44, item 4): the pair, chains of 4 and 16
  and irregular 16, 64, 256 to 1e4 tau_th at ratios 0.3 and 0.2 (fewer
  realizations: 16 over 8 geometries); a second driving amplitude,
  sigma_theta / Ntilde = 10, at ratio 0.3 (the pair, chains, irregular 16
  to 256); the e < 1 scan extended to irregular 1024 (8 realizations over
  4 geometries), chains, lattices and mu_d = 0.4; the ``large`` preset's at
  4096 sliders.

Every trend is :func:`slidernet.analysis.trend.log_trend` of a per-realization
variable (slopes against ln t over 1 <= t <= t_end, or against the
logarithm of the slips per node); its error is from independent
realizations and, for the irregular networks, includes the spread between
geometries (:func:`slidernet.analysis.trend.grouped_mean_sem`: each
geometry's mean, then the spread of the means, G - 1 degrees of freedom).
The statistics (``aging_stats.py`` beside this script):

* every estimator (mu_eff, ``tilt_first_slip``, ``tilt_all_moving``,
  ``tilt_break_ratio``, the contacts' local ratio as each breaks; both
  estimators for the pair) in fit windows t >= 1, 10, 100 (and 1e3 in the
  runs to 1e4) to the run's end, and from 100 slips per node on;
* mu_eff's rate relative to its own level above mu_d
  (:func:`~slidernet.analysis.trend.relative_rate`): the relative rate of c
  in mu_eff = mu_d + c N^-1/2 at e = 1, of the excess at e < 1;
* variance components of the slopes, between and within geometries
  (:func:`~slidernet.analysis.stats.variance_components`), and each
  geometry's slope;
* one random-effects fit of slope(N) = a + b N^-1/2 per parameter set, rule
  and condition (:func:`~slidernet.analysis.stats.meta_regression`);
* beside every slope its minimum detectable effect and the two one-sided
  tests against the margin ``MARGIN_PER_DECADE`` declared
  before the run (a tenth of the pair's slope at ratio 0.3);
* one family of every slope reported, Benjamini-Yekutieli (any
  dependence; Benjamini-Hochberg beside it), and the earlier family's
  counts (mu_eff over t >= 1, Benjamini-Hochberg).

Scaled observables: sqrt(N) (mu_eff - mu_d), in which a network with an
excess over mu_d that falls as 1/sqrt(N) is flat by construction, and
(mu_eff - mu_s_mean) / sigma_mu, in units of the law's spread; against t and
against the slips per node. mu_eff(0), the fresh state, is set beside the
exact mean of the weakest of N thresholds
(:func:`slidernet.plugins.distributions.mean_min_quadrature`).

Writes ``aging_networks.json`` (every number with its parameters and
configurations), ``aging_networks_tables.md`` (the guide's tables, made from
that JSON by ``tables``) and ``aging_networks.png`` into ``--out``::

    python examples/aging_networks.py --out aging_out --workers 2                  # the full preset
    python examples/aging_networks.py --out aging_out --quick                      # seconds; CI runs it
    python examples/aging_networks.py --out aging_large --preset large --workers 2   # 4096 sliders
    python examples/aging_networks.py --out aging_large --preset large --scheduler tcp://host:8786

``--resume`` continues an interrupted run: every sweep is resumable and the
points already written are read back. Units: time in tau_th, friction
coefficients dimensionless.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import slidernet
from slidernet.analysis.mechanism import node_states, node_summary
from slidernet.analysis.observables import align_avalanche_sizes
from slidernet.analysis.trend import mean_sem
from slidernet.ensemble.sweep import sweep
from slidernet.io import atomic_output, save_figure, write_json
from slidernet.plugins.distributions import mean_min_quadrature

try:
    HERE = Path(__file__).resolve().parent
except NameError:  # sphinx-gallery defines no __file__; it runs the script from examples/
    HERE = Path.cwd()
BASE_TOML = HERE / "aging_networks.toml"
sys.path.insert(0, str(HERE))  # the study's statistics: windows, relative rates, components, fits, the family
import aging_stats  # noqa: E402
from aging_stats import estimate, trend  # noqa: E402

JSON_NAME = "aging_networks.json"
PNG_NAME = "aging_networks.png"
TABLES_NAME = "aging_networks_tables.md"  # the guide's tables, from the JSON
MU_S_MEAN = 0.6  # the law's mean before its truncation at mu_d, in every parameter set
# The margin of "no aging", declared before the restated study's run. At ratio 0.3 the pair's mu_eff rises by
# (94 +- 13)e-4 per decade (records' estimator, 32 realizations to 1e3 tau_th). A network whose slope is within
# a tenth of that, +-9.4e-4 per decade, ages at most a tenth as fast as the pair, in the estimator's own units:
# the pair's rate is known to 14 %, so a tenth of it lies 6.5 of the pair's standard errors below it; a test
# against it passes for an error below about half the margin, as most networks' are (0.2e-4 to 7.9e-4 per
# decade at ratio 0.3, 7 dof). Scaled variables take it in their units. The margin bounds the estimator's
# slope, not the thresholds' aging: divided by an estimator's recovery (examples/aging_recovery.py) it bounds
# the latter.
MARGIN_PER_DECADE = 0.1 * 94e-4  # in mu_eff (or a tilt load) per decade of t


@dataclasses.dataclass(frozen=True)
class Params:
    """A parameter set of the friction law: mu_d and the Gaussian's std (mean 0.6)."""

    mu_d: float
    std: float

    @property
    def ratio(self) -> float:
        """sigma_mu / (mean - mu_d)."""
        return round(self.std / (MU_S_MEAN - self.mu_d), 12)


# New sets go last: a set's ensemble seed is its place in this dict.
PARAMS = {"base": Params(0.5, 0.01), "ratio0.3": Params(0.5, 0.03), "mu_d0.4": Params(0.4, 0.02),
          "ratio0.2": Params(0.5, 0.02)}


@dataclasses.dataclass(frozen=True)
class Group:
    """Sweeps of one kind of network over its sizes, for some parameter sets and one slip and sliding rule.

    Attributes
    ----------
    name : str
        Label of the group in the JSON output.
    kind : str
        ``pair`` (a chain of 2, on the pair kernel), ``chain``, ``irregular``
        or ``triangular``.
    sizes : tuple of int
        Numbers of sliders; for ``triangular``, the side L of an L x L lattice.
    params : tuple of str
        Keys of :data:`PARAMS`.
    geometries : int
        Network seeds 0, 1, ... (``irregular``): each its own sweep, with its
        own ensemble seed, so that the geometries' realizations are independent.
    overshoot : float
        ``friction.overshoot`` e.
    tilt : tuple of (str, value) pairs
        The ``[tilt]`` table (empty: the rule of one slip per node).
    mu_eff_at : str
        ``records`` (the study's estimator), or ``rearrangements`` for the
        pair: the paper's own estimator, the appendix's test before every
        rearrangement, as a check of the study's on the pair.
    inject : (c, select) or None
        ``[tilt] inject``: a known aging c ln(1 + t / tau_th) of the tested
        copy's thresholds (all, or the ``select`` share of the oldest
        contacts), the positive control of ``examples/aging_recovery.py``.
    realizations : int or None
        Realizations per size, over all geometries (None: the preset's).
    observables : tuple of str
        Observables beside the base configuration's.
    repeats : int
        ``[tilt] repeats``: K independent tilt tests per record (mu_eff_realization
        their mean, mu_eff_spread their spread).
    amplitude : float
        sigma_theta / Ntilde of the driver.
    steps : int or None
        The run's duration in tau_th (None: the preset's).
    """

    name: str
    kind: str
    sizes: tuple[int, ...]
    params: tuple[str, ...] = ("base", "ratio0.3", "mu_d0.4")  # ratio0.2: only the long runs name it
    geometries: int = 1
    overshoot: float = 1.0
    tilt: tuple[tuple[str, float], ...] = ()
    mu_eff_at: str = "records"
    inject: tuple[float, float] | None = None
    realizations: int | None = None
    observables: tuple[str, ...] = ()
    repeats: int = 1
    amplitude: float = 1.0
    steps: int | None = None

    def rule(self) -> str:
        """The slip and sliding rule in words (the JSON's and the figure's label)."""
        parts = [f"e = {self.overshoot:g}"]
        parts += [f"{key} = {value:g}" for key, value in self.tilt]
        if self.repeats > 1:
            parts.append(f"K = {self.repeats} tests")
        if self.mu_eff_at != "records":
            parts.append("the appendix's test before every rearrangement")
        return ", ".join(parts)

    def condition(self) -> str:
        """The driving and the duration where they differ from the study's (empty: sigma_theta / Ntilde = 1,
        the preset's duration)."""
        parts = [] if self.amplitude == 1.0 else [f"σ_θ/Ñ = {self.amplitude:g}"]
        return ", ".join(parts + ([] if self.steps is None else [f"to {self.steps:g} τ_th"]))


@dataclasses.dataclass(frozen=True)
class Preset:
    """The whole study: its sweeps, its duration, and the mechanism runs."""

    realizations: int  # per point: divided among the geometries of an irregular size
    steps: int
    per_decade: int
    groups: tuple[Group, ...]
    mechanism: tuple[tuple[str, int], ...]  # (kind, N) at the base parameters


def _scan(sizes: tuple[int, ...], params: tuple[str, ...], geometries: int, repeats: int = 1) -> tuple[Group, ...]:
    """The slip-rule and sliding-rule scan: the pair and irregular networks of ``sizes``, every rule.

    At e = 1 the three sliding rules are re-draws of the tilt stream on the same states (the second reading's
    M3): they get ``repeats`` tests per record, the paper's rule included (its K = 1 reading is the study's
    main group), so that their differences are the rules', not one draw's."""
    out = []
    rules = [(0.0, ()), (0.5, ()), (1.0, (("min_slips", 2),)), (1.0, (("min_displacement", 10.0),)),
             (0.0, (("min_slips", 2),)), (0.0, (("min_displacement", 10.0),))]
    if repeats > 1:
        rules.insert(2, (1.0, ()))
    for e, tilt in rules:
        K = repeats if e == 1.0 else 1
        tag = f"e{e:g}" + "".join(f"_{key}{v:g}" for key, v in tilt) + (f"_K{K}" if K > 1 else "")
        out.append(Group(f"pair_{tag}", "pair", (2,), params, overshoot=e, tilt=tilt, repeats=K))
        out.append(Group(f"irregular_{tag}", "irregular", sizes, params, geometries, overshoot=e, tilt=tilt,
                         repeats=K))
    return tuple(out)


def _restated() -> tuple[Group, ...]:
    """The groups of the restated study (issue 44, item 4), beside the study's own; realizations sized so that
    the full preset keeps within an hour on two cores (estimates in the comments: wall time at 2 workers)."""
    long = {"params": ("ratio0.3", "ratio0.2"), "steps": 10_000}
    e_scan = [(e, {"overshoot": e}) for e in (0.0, 0.5)]
    return (
        # To 1e4 tau_th (8-10x a realization's cost, measured), N <= 256, where the pair ages (about 6 min).
        Group("pair_1e4", "pair", (2,), **long),
        Group("pair_appendix_1e4", "pair", (2,), mu_eff_at="rearrangements", **long),
        Group("chains_1e4", "chain", (4, 16), **long),
        Group("irregular_1e4", "irregular", (16, 64, 256), geometries=8, realizations=16, **long),
        # sigma_theta / Ntilde = 10 (8-20x the cost at 64 sliders, 30x at 256), at ratio 0.3 (about 4 min).
        Group("pair_amp10", "pair", (2,), ("ratio0.3",), amplitude=10.0),
        Group("chains_amp10", "chain", (4, 16), ("ratio0.3",), amplitude=10.0),
        Group("irregular_amp10", "irregular", (16, 64), ("ratio0.3",), 8, realizations=16, amplitude=10.0),
        Group("irregular_256_amp10", "irregular", (256,), ("ratio0.3",), 4, realizations=8, amplitude=10.0),
        # The e < 1 scan to 1024 sliders, along chains and lattices, and at mu_d = 0.4 (about 7 min; at 1024
        # sliders e = 0 costs 2.4x as much as e = 1).
        *(g for e, rule in e_scan for g in (
            Group(f"irregular_1024_e{e:g}", "irregular", (1024,), ("base", "ratio0.3"), 4, realizations=8,
                  **rule),
            Group(f"chains_e{e:g}", "chain", (4, 16), ("base", "ratio0.3"), **rule),
            Group(f"lattices_e{e:g}", "triangular", (4, 8, 16, 32), ("base", "ratio0.3"), realizations=16,
                  **rule),
            Group(f"pair_mu_d0.4_e{e:g}", "pair", (2,), ("mu_d0.4",), **rule),
            Group(f"irregular_mu_d0.4_e{e:g}", "irregular", (16, 64, 256), ("mu_d0.4",), 8, realizations=16,
                  **rule))),
    )


PRESETS = {
    "full": Preset(
        realizations=32, steps=1000, per_decade=10,
        groups=(
            Group("pair", "pair", (2,)),
            Group("pair_appendix", "pair", (2,), mu_eff_at="rearrangements"),
            Group("chains", "chain", (4, 16)),
            Group("irregular", "irregular", (16, 64, 256, 1024), geometries=8),
            Group("lattices", "triangular", (4, 8, 16, 32)),
            # K = 4 tests per record at e = 1 (+35 % of a run's cost at 256 sliders, +51 % under
            # min_displacement = 10, measured).
            *_scan((16, 64, 256), ("base", "ratio0.3"), 8, repeats=4),
            *_restated(),
        ),
        mechanism=(("pair", 2), ("chain", 16), ("irregular", 64)),
    ),
    # Beyond the full preset's budget: 4096 sliders, 8 geometries x 2 realizations to 300 tau_th, at the base
    # and at the control where the pair ages, with the pair at the same times, at e = 1, 0.5 and 0 (about
    # 2 h of CPU: 25 min at e = 1; e = 0 cost 2.4x as much as e = 1 at 1024 sliders, measured, e = 0.5 less).
    "large": Preset(
        realizations=16, steps=300, per_decade=5,
        groups=(Group("pair", "pair", (2,), ("base", "ratio0.3")),
                Group("irregular_4096", "irregular", (4096,), ("base", "ratio0.3"), geometries=8),
                *(Group(f"{name}_e{e:g}", kind, (n,), ("base", "ratio0.3"), geometries=g, overshoot=e)
                  for e in (0.0, 0.5) for name, kind, n, g in (("pair", "pair", 2, 1),
                                                               ("irregular_4096", "irregular", 4096, 8)))),
        mechanism=(),
    ),
    # The study's main systems again, for the estimators added after the full run (tilt_break_ratio, the
    # contacts' local ratio as each breaks: the one that passes the positive control of aging_recovery.py).
    "contacts": Preset(
        realizations=32, steps=1000, per_decade=10,
        groups=(Group("pair", "pair", (2,)), Group("chains", "chain", (4, 16)),
                Group("irregular", "irregular", (16, 64, 256, 1024), geometries=8),
                Group("lattices", "triangular", (4, 8, 16, 32))),
        mechanism=(),
    ),
    # To 1e3 tau_th, so that every time window exists; the restated study's kinds of group, each once.
    "quick": Preset(
        realizations=4, steps=1000, per_decade=5,
        groups=(
            Group("pair", "pair", (2,), ("base", "ratio0.3")),
            Group("pair_appendix", "pair", (2,), ("base",), mu_eff_at="rearrangements"),
            Group("chains", "chain", (4, 8), ("base", "ratio0.3")),
            Group("irregular", "irregular", (16,), ("base", "ratio0.3"), geometries=2),
            Group("lattices", "triangular", (4,), ("base",)),
            Group("irregular_e0", "irregular", (16,), ("base",), 2, overshoot=0.0),
            Group("irregular_e0_min_slips2", "irregular", (16,), ("base",), 2, overshoot=0.0,
                  tilt=(("min_slips", 2),)),
            Group("irregular_e1_K2", "irregular", (16,), ("base",), 2, repeats=2),
            Group("pair_1e4", "pair", (2,), ("ratio0.2",), steps=10_000),
            Group("chains_amp10", "chain", (4,), ("ratio0.3",), amplitude=10.0),
        ),
        mechanism=(("chain", 4),),
    ),
}


def _n_nodes(kind: str, size: int) -> int:
    return size * size if kind == "triangular" else size


def point_config(group: Group, params: str, size: int, geometry: int, preset: Preset) -> dict[str, Any]:
    """The configuration of one point (one size, one parameter set, one geometry) as a plain dict."""
    cfg = slidernet.load_config(BASE_TOML).model_dump(mode="json")
    p = PARAMS[params]
    ntilde = cfg["network"]["Ntilde"]
    # Independent ensembles: a seed per parameter set and per geometry (the sizes of one sweep share it).
    cfg["seed"] = 1 + 1000 * list(PARAMS).index(params) + geometry
    cfg["realizations"] = (group.realizations or preset.realizations) // group.geometries
    cfg["steps"] = group.steps or preset.steps
    cfg["log_points_per_decade"] = preset.per_decade
    network: dict[str, Any] = {"kind": "chain" if group.kind == "pair" else group.kind, "Ntilde": ntilde}
    if group.kind == "triangular":
        network["shape"] = [size, size]
    else:
        network["n"] = size
    if group.kind == "irregular":
        network["seed"] = geometry
    cfg["network"] = network
    cfg["friction"] = {"mu_d": p.mu_d, "static": {"name": "gaussian", "mean": MU_S_MEAN, "std": p.std}}
    if group.overshoot != 1.0:
        cfg["friction"]["overshoot"] = group.overshoot
    if group.tilt or group.repeats > 1:
        cfg["tilt"] = dict(group.tilt) | ({"repeats": group.repeats} if group.repeats > 1 else {})
    if group.inject is not None:
        c, select = group.inject
        cfg["tilt"] = {**cfg.get("tilt", {}), "inject": {"c": c, "t0": 1.0, "select": select}}
    cfg["observables"] = [*cfg["observables"], *(o for o in group.observables if o not in cfg["observables"])]
    if group.mu_eff_at != "records":
        cfg["mu_eff_at"] = group.mu_eff_at
        cfg["observables"] = [o for o in cfg["observables"] if o != "tilt_loads"]  # a network tilt test's
    cfg["driver"] = {**cfg["driver"], "sigma_theta": group.amplitude * ntilde}
    return cfg


def run_sweeps(group: Group, params: str, preset: Preset, workers: int | None, scheduler: str | None,
               out: Path | None, resume: bool) -> list[tuple[xr.Dataset, np.ndarray, list[dict[str, Any]]]]:
    """Every size of ``group`` at ``params``: its realizations over all geometries, the independent unit each
    belongs to (its geometry, or itself where there is one geometry), and the configurations."""
    key = "network.shape" if group.kind == "triangular" else "network.n"
    values: list[Any] = [[s, s] for s in group.sizes] if group.kind == "triangular" else list(group.sizes)
    per_size: list[list[xr.Dataset]] = [[] for _ in group.sizes]
    configs: list[list[dict[str, Any]]] = [[] for _ in group.sizes]
    for g in range(group.geometries):
        cfg = point_config(group, params, group.sizes[0], g, preset)
        where = None if out is None else out / "sweeps" / group.name / params / f"geometry_{g}"
        result = sweep(cfg, {key: values}, workers=workers, scheduler=scheduler, out=where,
                       resume=resume and where is not None and (where / "sweep.json").exists(),
                       overwrite=not resume, progress=None)
        ds = result.to_dataset() if isinstance(result, xr.DataTree) else result
        dim = ds["mu_max"].dims[0]
        point_configs = json.loads(ds.attrs["configs"])
        for i in range(len(group.sizes)):
            per_size[i].append(ds.isel({dim: i}).drop_vars(dim, errors="ignore"))
            configs[i].append(point_configs[i])
    merged = []
    for i in range(len(group.sizes)):
        # Each geometry's avalanche histogram ends at its own largest avalanche: padded with empty bins.
        parts = align_avalanche_sizes(per_size[i])
        R = parts[0].sizes["realization"]
        ds = xr.concat([p.assign_coords(realization=np.arange(R) + g * R) for g, p in enumerate(parts)],
                       dim="realization", data_vars="minimal", coords="minimal", compat="override")
        # One geometry: the realizations are the independent units; several: the geometries are.
        groups = np.repeat(np.arange(len(parts)), R) if len(parts) > 1 else np.arange(R)
        merged.append((ds, groups, configs[i]))
    return merged


def _curve(values: xr.DataArray) -> dict[str, list[float]]:
    """Mean and standard error over realizations at every recorded time (for the figure)."""
    v = values.transpose("realization", "t").values
    count = np.isfinite(v).sum(axis=0)
    # A time where no realization has a value (the appendix's estimator between rearrangements) is NaN.
    with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(v, axis=0)
        sem = np.nanstd(v, axis=0, ddof=1) / np.sqrt(np.maximum(count, 1))
    return {"t": values["t"].values.tolist(), "mean": mean.tolist(), "sem": sem.tolist()}


def reduce_point(group: Group, params: str, size: int, ds: xr.Dataset, geometry: np.ndarray,
                 configs: list[dict[str, Any]]) -> dict[str, Any]:
    """Every number of one point of the study."""
    p = PARAMS[params]
    N = _n_nodes(group.kind, size)
    law = slidernet.load_config(configs[0]).distribution()
    mu_s_mean = float(law.mean_max(1))  # the law's mean, conditioned on mu_s > mu_d
    q = ds["mu_eff_realization"]
    slips = (ds["n"] / N).where(ds["t"] >= 1)
    excess = math.sqrt(N) * (q - p.mu_d)  # the scaled excess over mu_d, flat for an excess ~ 1/sqrt(N)
    point = {
        "group": group.name, "kind": group.kind, "size": size, "N": N, "params": params,
        "mu_d": p.mu_d, "std": p.std, "ratio": p.ratio, "overshoot": group.overshoot,
        "tilt": dict(group.tilt), "rule": group.rule(), "geometries": group.geometries,
        "repeats": group.repeats, "amplitude": group.amplitude, "condition": group.condition(),
        "realizations": int(ds.sizes["realization"]), "seeds": sorted({c["seed"] for c in configs}),
        "mu_s_mean": mu_s_mean,
        "r_mean": mean_sem(ds["n"].isel(t=-1).values / float(ds["t"][-1]))[0],
        "slips_per_node_end": estimate(slips.isel(t=-1).values, geometry),
        "mu_eff": trend(q, geometry, MARGIN_PER_DECADE),
        # The margin in each variable's unit; the slips per node grow about as t, so per decade of them too.
        "sqrtN_excess": trend(excess, geometry, math.sqrt(N) * MARGIN_PER_DECADE),
        "sqrtN_excess_vs_slips": trend(excess, geometry, math.sqrt(N) * MARGIN_PER_DECADE, against=slips),
        "law_units": trend((q - mu_s_mean) / p.std, geometry, MARGIN_PER_DECADE / p.std),
        "mu_max": trend(ds["mu_max"], geometry, MARGIN_PER_DECADE),
        # Every estimator in every fit window; mu_eff's rate relative to its level, the variance components.
        "windows": aging_stats.windows(ds, geometry, N, p.mu_d, group.geometries > 1,
                                       MARGIN_PER_DECADE),
        "mu_eff_at": group.mu_eff_at,
        # The weakest link: with no prestress, the first node to yield is the weakest of N.
        "weakest_of_N": float(mean_min_quadrature(law, N)),
        "curves": {"mu_eff": _curve(q), "sqrtN_excess": _curve(excess),
                   "slips_per_node": _curve(ds["n"] / N)},
        "configs": configs,
    }
    if "tilt_first_slip" in ds:  # the network tilt test's loads at its first slip and first collective motion
        point["tilt_first_slip_end"] = estimate(ds["tilt_first_slip"].isel(t=-1).values, geometry)
        point["tilt_all_moving_end"] = estimate(ds["tilt_all_moving"].isel(t=-1).values, geometry)
        first0 = ds["tilt_first_slip"].sel(t=0).values
        point["tilt_first_slip_t0"] = estimate(first0, geometry)
        # The fresh state: the share of realizations whose first slip already set the network sliding.
        point["first_slip_slides_t0"] = float(np.mean(first0 == q.sel(t=0).values))
    if "mu_eff_spread" in ds:  # [tilt] repeats: the spread of one realization's K tests, at t_end
        point["mu_eff_spread_end"] = estimate(ds["mu_eff_spread"].isel(t=-1).values, geometry)
    return point


def mechanism(kind: str, N: int, preset: Preset) -> dict[str, Any]:
    """Thresholds and load ratios of every node at t = 0 and t_end, at the base parameters."""
    group = Group("mechanism", kind, (N,))
    cfg = point_config(group, "base", N, 0, preset)
    cfg["realizations"] = preset.realizations
    law_mean = float(slidernet.load_config(cfg).distribution().mean_max(1))
    states = node_states(cfg, [0, preset.steps])
    summary = node_summary(states, law_mean=law_mean)
    out: dict[str, Any] = {"kind": kind, "N": N, "steps": preset.steps, "realizations": preset.realizations,
                           "law_mean": law_mean}
    for name in ("mu_s_shift", "load_ratio"):
        for label, k in (("t0", 0), ("end", 1)):
            out[f"{name}_{label}_mean"] = float(summary[f"{name}_mean"].isel(t=k))
            out[f"{name}_{label}_sem"] = float(summary[f"{name}_sem"].isel(t=k))
    return out


def _pm(e: dict[str, Any], scale: float = 1.0, digits: int = 4) -> str:
    """``mean ± sem`` of an estimate, both multiplied by ``scale``."""
    if not math.isfinite(e["sem"]):
        return f"{e['mean'] * scale:.{digits}f}"
    return f"{e['mean'] * scale:.{digits}f} ± {e['sem'] * scale:.{digits}f}"


def _slope(e: dict[str, Any], scale: float, digits: int = 1) -> str:
    """A slope per decade, scaled, with its error, degrees of freedom and its Benjamini-Hochberg q if known."""
    out = f"{e['mean'] * scale:+.{digits}f} ± {e['sem'] * scale:.{digits}f} ({e['dof']})"
    return out + (f", q {e['q_bh']:.2f}" if "q_bh" in e else "")


def tables(data: dict[str, Any]) -> str:
    """Every table of the guide's page, in Markdown, from the study's numbers (``aging_networks.json``).

    Errors: one standard error from independent units (the realizations;
    for irregular networks, the geometries' means), their degrees of
    freedom in brackets; slopes per decade of t.
    """
    pts = data["points"]
    main = [p for p in pts if _main(p)]
    lines = ["### Every point, absolute units (1e-4 per decade)", "",
             "| network | N | σ_μ/(μ̄_s−μ_d), μ_d | estimator | R (G) | slips per node, t_end | μ_eff(0) "
             "| μ_eff(1) | μ_eff(t_end) | dμ_eff/dlog10 t (dof) | dμ_max/dlog10 t (dof) | NaN |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in main:
        e = p["mu_eff"]
        lines.append(
            f"| {_label(p)} | {p['N']} | {p['ratio']:.1f}, {p['mu_d']:.1f} | {p['mu_eff_at']} | "
            f"{p['realizations']} ({p['geometries']}) | {_pm(p['slips_per_node_end'], 1, 0)} | {_pm(e['t0'])} | "
            f"{_pm(e['t1'])} | {_pm(e['end'])} | {_slope(e['slope_per_decade'], 1e4)} | "
            f"{_slope(p['mu_max']['slope_per_decade'], 1e4)} | {e['not_finite']} |")
    lines += ["", "### Scaled units (records' estimator)", "",
              "| network | N | σ_μ/(μ̄_s−μ_d), μ_d | √N(μ_eff−μ_d), t = 1 | same, t_end | d/dlog10 t (1e-3) "
              "| d/dlog10(slips per node) (1e-3) | (μ_eff−μ̄_s)/σ_μ, t_end | d/dlog10 t (1e-2) |",
              "|---|---|---|---|---|---|---|---|---|"]
    for p in main:
        if p["mu_eff_at"] != "records":
            continue
        x, xs, lu = p["sqrtN_excess"], p["sqrtN_excess_vs_slips"], p["law_units"]
        lines.append(
            f"| {_label(p)} | {p['N']} | {p['ratio']:.1f}, {p['mu_d']:.1f} | {_pm(x['t1'])} | {_pm(x['end'])} | "
            f"{_slope(x['slope_per_decade'], 1e3)} | {_slope(xs['slope_per_decade'], 1e3)} | "
            f"{_pm(lu['end'], 1, 2)} | {_slope(lu['slope_per_decade'], 1e2)} |")
    lines += ["", "### The slip rule and the sliding rule (1e-4 per decade)", "",
              "| rule | network | N | σ_μ/(μ̄_s−μ_d) | μ_eff(1) | μ_eff(t_end) | dμ_eff/dlog10 t (dof) "
              "| d√N(μ_eff−μ_d)/dlog10 t (1e-3) | NaN | spread of the K tests, t_end |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for p in sorted((p for p in pts if p["mu_eff_at"] == "records" and p["params"] in ("base", "ratio0.3")
                     and not p["condition"] and (p["kind"] in ("pair", "irregular") and p["N"] <= 256)),
                    key=lambda p: (p["params"], p["N"], -p["overshoot"], sorted(p["tilt"].items()))):
        e = p["mu_eff"]
        lines.append(
            f"| {p['rule']} | {_label(p)} | {p['N']} | {p['ratio']:.1f} | {_pm(e['t1'])} | {_pm(e['end'])} | "
            f"{_slope(e['slope_per_decade'], 1e4)} | {_slope(p['sqrtN_excess']['slope_per_decade'], 1e3)} | "
            f"{e['not_finite']} | {_pm(p['mu_eff_spread_end']) if 'mu_eff_spread_end' in p else '–'} |")
    lines += ["", "### The fresh state: the weakest link, the first slip", "",
              "| network | N | σ_μ/(μ̄_s−μ_d), μ_d | μ_eff(0) | E[min of N draws] | first slip, t = 0 "
              "| share whose first slip slides, t = 0 | first slip, t_end | all in motion, t_end |",
              "|---|---|---|---|---|---|---|---|---|"]
    for p in main:
        if "tilt_first_slip_t0" not in p:
            continue
        lines.append(
            f"| {_label(p)} | {p['N']} | {p['ratio']:.1f}, {p['mu_d']:.1f} | {_pm(p['mu_eff']['t0'])} | "
            f"{p['weakest_of_N']:.4f} | {_pm(p['tilt_first_slip_t0'])} | {p['first_slip_slides_t0']:.0%} | "
            f"{_pm(p['tilt_first_slip_end'])} | {_pm(p['tilt_all_moving_end'])} |")
    fam = data["multiple_testing"]
    lines += ["", f"Multiple testing: {fam['tests']} slopes of μ_eff, {fam['beyond_2_se']} beyond 2 standard "
              f"errors, {fam['expected_by_chance']:.1f} expected by chance; "
              f"{fam['significant_at_q_0.05']} significant at a Benjamini-Hochberg false discovery rate of 0.05 "
              "(the earlier family; the restated study's is below).", ""]
    if data["mechanism"]:
        lines += ["### Mechanism (base parameters)", "",
                  "| network | N | R | ⟨μ_s⟩ − law mean, t = 0 | same, t_end | load ratio, t_end |",
                  "|---|---|---|---|---|---|"]
        for m in data["mechanism"]:
            lines.append(
                f"| {m['kind']} | {m['N']} | {m['realizations']} | "
                f"{m['mu_s_shift_t0_mean']:+.5f} ± {m['mu_s_shift_t0_sem']:.5f} | "
                f"{m['mu_s_shift_end_mean']:+.5f} ± {m['mu_s_shift_end_sem']:.5f} | "
                f"{m['load_ratio_end_mean']:.3f} ± {m['load_ratio_end_sem']:.3f} |")
        lines.append("")
    lines += aging_stats.tables(data, _label)
    return "\n".join(lines)


def _sizes_axis(ax: Any, sizes: Sequence[int]) -> None:
    """A log axis of numbers of sliders, ticked at the sizes drawn."""
    ax.set_xscale("log")
    ax.set_xticks(sorted(set(sizes)), [str(n) for n in sorted(set(sizes))])
    ax.minorticks_off()


def _main(pt: dict[str, Any]) -> bool:
    """Whether a point is of the study's main grid: the paper's rules, sigma_theta / Ntilde = 1, the preset's
    duration, one tilt test per record."""
    return pt["overshoot"] == 1.0 and not pt["tilt"] and not pt["condition"] and pt["repeats"] == 1


def _label(pt: dict[str, Any]) -> str:
    return {"pair": "pair", "chain": f"chain {pt['N']}", "irregular": f"irregular {pt['N']}",
            "triangular": f"triangular {pt['size']}x{pt['size']}"}[pt["kind"]]


def plot(data: dict[str, Any], path: Path) -> Path:
    """mu_eff(t), its scaled excess against the slips per node, slopes against N, and the two rule scans."""
    fig = Figure(figsize=(15, 9), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, 3)
    (ax_t, ax_s, ax_n), (ax_scaled, ax_e, ax_c) = axes
    pts = data["points"]
    main = [p for p in pts if _main(p) and p["mu_eff_at"] == "records"]
    base = [p for p in main if p["params"] == "base"]
    style = {"pair": "*-", "chain": "o-", "irregular": "s-", "triangular": "^--"}
    for c, p in enumerate(base):
        cur = p["curves"]
        t, m, s = (np.array(cur["mu_eff"][k], float) for k in ("t", "mean", "sem"))
        keep = t >= 1
        ax_t.errorbar(t[keep], m[keep], yerr=s[keep], fmt=style[p["kind"]], ms=3, lw=0.8, color=f"C{c % 10}",
                      label=_label(p))
        x = np.array(cur["slips_per_node"]["mean"])[keep]
        y, ys = (np.array(cur["sqrtN_excess"][k])[keep] for k in ("mean", "sem"))
        ax_s.errorbar(x, y, yerr=ys, fmt=style[p["kind"]], ms=3, lw=0.8, color=f"C{c % 10}", label=_label(p))
    ax_t.axhline(PARAMS["base"].mu_d, color="k", lw=0.6, ls=":")
    ax_t.set_xscale("log")
    ax_t.set_xlabel(r"$t$ [$\tau_\mathrm{th}$]")
    ax_t.set_ylabel(r"$\mu_\mathrm{eff}$")
    ax_t.set_title(r"(a) base: $\sigma_\mu/(\bar\mu_s-\mu_d) = 0.1$, $\mu_d = 0.5$; mean $\pm$ SE", fontsize=9)
    ax_t.legend(fontsize=6, ncol=2)
    ax_s.set_xscale("log")
    ax_s.set_xlabel("slips per node")
    ax_s.set_ylabel(r"$\sqrt{N}\,(\mu_\mathrm{eff} - \mu_d)$")
    ax_s.set_title("(b) the excess over $\\mu_d$ in units of $1/\\sqrt{N}$, base", fontsize=9)
    markers = {"pair": "*", "chain": "o", "irregular": "s", "triangular": "^"}
    for k, params in enumerate(PARAMS):
        for kind, mk in markers.items():
            sel = [p for p in main if p["params"] == params and p["kind"] == kind]
            if not sel:
                continue
            n = np.array([p["N"] for p in sel], float) * (1 + 0.05 * (k - 1))
            for ax, key in ((ax_n, "mu_eff"), (ax_scaled, "sqrtN_excess")):
                sl = [p[key]["slope_per_decade"] for p in sel]
                ax.errorbar(n, [s["mean"] for s in sl], yerr=[s["sem"] for s in sl], fmt=mk, ms=5, color=f"C{k}",
                            label=f"{kind}, {params}" if ax is ax_n else None, mfc="none" if kind != "irregular"
                            else None)
    for ax, unit in ((ax_n, r"$d\mu_\mathrm{eff}/d\log_{10}t$"),
                     (ax_scaled, r"$d[\sqrt{N}(\mu_\mathrm{eff}-\mu_d)]/d\log_{10}t$")):
        ax.axhline(0, color="k", lw=0.6)
        _sizes_axis(ax, [p["N"] for p in main])
        ax.set_xlabel("number of sliders N")
        ax.set_ylabel(unit + " (per decade)")
    ax_n.set_title("(c) aging rate of $\\mu_\\mathrm{eff}$, three parameter sets", fontsize=9)
    ax_n.legend(fontsize=6, ncol=2)
    ax_scaled.set_title("(d) the same, scaled by $\\sqrt{N}$", fontsize=9)
    for ax, pick, title in (
        (ax_e, lambda p: not p["tilt"], "(e) the slip's overshoot e: $\\mu_\\mathrm{eff}$ at $t_\\mathrm{end}$"),
        (ax_c, lambda p: True, "(f) sliding rules at e = 1 and e = 0: $\\mu_\\mathrm{eff}$ at $t_\\mathrm{end}$"),
    ):
        rules = sorted({p["rule"] for p in pts if pick(p) and (p["kind"] in ("pair", "irregular"))
                        and not p["condition"] and p["mu_eff_at"] == "records"
                        and (ax is ax_e or p["overshoot"] in (0.0, 1.0))})
        for k, rule in enumerate(rules):
            for j, params in enumerate(("base", "ratio0.3")):
                sel = sorted((p for p in pts if p["rule"] == rule and p["params"] == params and pick(p)
                              and p["kind"] in ("pair", "irregular") and not p["condition"]),
                             key=lambda p: p["N"])
                if not sel:
                    continue
                n = np.array([p["N"] for p in sel], float) * (1 + 0.04 * k)
                ax.errorbar(n, [p["mu_eff"]["end"]["mean"] for p in sel],
                            yerr=[p["mu_eff"]["end"]["sem"] for p in sel], fmt="o-" if j == 0 else "s--", ms=4,
                            lw=0.8, color=f"C{k}", label=f"{rule}, {params}")
        ax.axhline(0.5, color="k", lw=0.6, ls=":")
        _sizes_axis(ax, [p["N"] for p in pts if p["kind"] in ("pair", "irregular")])
        ax.set_xlabel("number of sliders N (pair and irregular)")
        ax.set_ylabel(r"$\mu_\mathrm{eff}(t_\mathrm{end})$")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=6)
    return save_figure(fig, path, dpi=110)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("aging_out"), help="output folder (default aging_out)")
    parser.add_argument("--quick", action="store_true", help="a small grid, short runs (seconds); "
                        "the same as --preset quick")
    parser.add_argument("--preset", choices=sorted(PRESETS), default="full",
                        help="full (the study), quick, or large (4096 sliders and the pair, base and ratio0.3, "
                             "300 tau_th)")
    parser.add_argument("--workers", type=int, default=None, help="worker processes per sweep point")
    parser.add_argument("--scheduler", default=None,
                        help="a Dask scheduler address, e.g. tcp://host:8786: realizations run on that cluster")
    parser.add_argument("--resume", action="store_true",
                        help="continue the sweeps of an interrupted run in --out (points already done are kept)")
    args = parser.parse_args(argv)

    name = "quick" if args.quick else args.preset
    preset = PRESETS[name]
    start = time.perf_counter()
    points: list[dict[str, Any]] = []
    for group in preset.groups:
        for params in group.params:
            t0 = time.perf_counter()
            for size, (ds, geometry, configs) in zip(group.sizes, run_sweeps(
                    group, params, preset, args.workers, args.scheduler, args.out, args.resume), strict=True):
                pt = reduce_point(group, params, size, ds, geometry, configs)
                points.append(pt)
                e, s = pt["mu_eff"], pt["mu_eff"]["slope_per_decade"]
                print(f"{group.name} {params} N={pt['N']}: mu_eff {e['t0']['mean']:.4f} -> "
                      f"{e['end']['mean']:.4f}, slope/decade {s['mean']:+.5f} +- {s['sem']:.5f} (dof {s['dof']})",
                      flush=True)
            print(f"{group.name} {params}: {time.perf_counter() - t0:.1f} s", flush=True)
    fits = aging_stats.fits(points, MARGIN_PER_DECADE)
    family = aging_stats.family(points, fits)
    mech = [mechanism(kind, N, preset) for kind, N in preset.mechanism]
    data = {
        "question": "does thermal cycling increase mu_eff with time in networks of sliders, where the pair ages?",
        "preset": name,
        "estimator": "network tilt test at every recorded time (mu_eff_at = 'records'), the same at every size; "
                     "trends: log_trend, per-realization slopes against ln t for t >= 1, and in the fit windows "
                     "of 'windows' (each point's 'windows'); errors from independent "
                     "realizations, and for irregular networks from the spread of the geometries' means",
        "parameters": {key: dataclasses.asdict(p) | {"ratio": p.ratio} for key, p in PARAMS.items()},
        "preset_settings": {"realizations": preset.realizations, "steps": preset.steps,
                            "per_decade": preset.per_decade, "sigma_theta_over_Ntilde": 1.0,  # unless a group's
                            "groups": [dataclasses.asdict(g) for g in preset.groups]},
        "windows": {"fit_windows": {k: {"t_min": t, "slips_min": m} for k, (t, m) in aging_stats.WINDOWS.items()},
                    "margin_per_decade": MARGIN_PER_DECADE, "slips_min": aging_stats.SLIPS_MIN},
        "multiple_testing": family,
        "fits": fits,
        "points": points,
        "mechanism": mech,
        "slidernet_version": slidernet.__version__,
    }
    data["wall_time_s"] = time.perf_counter() - start
    print(write_json(data, args.out / JSON_NAME))
    with atomic_output(args.out / TABLES_NAME) as tmp:
        tmp.write_text(tables(data))
    print(args.out / TABLES_NAME)
    print(plot(data, args.out / PNG_NAME))
    print(f"{family['beyond_2_se']} of {family['tests']} slopes beyond 2 standard errors "
          f"({family['expected_by_chance']:.1f} expected by chance); done in {time.perf_counter() - start:.1f} s")
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
