"""From per-realization records to the result dataset (docs/model.md section 3).

Per realization (dims ``realization, t``): ``n``, ``mu_max``, ``x_G`` and
``n_records``. Ensemble statistics (dim ``t``): ``<name>_mean`` and
``<name>_sem`` (standard error of the mean over realizations), ``x_G2_mean``
(the mean square displacement) and ``mu_eff`` from the virtual tilt test.

mu_eff(t_k) pools every tilt test made at the rearrangements of the bin
(t_{k-1}, t_k] over all realizations (the appendix's average). The bin of
t = 0 holds one test per realization, made on the initial state, so that
mu_eff(0) is the value of a fresh system. A bin without any rearrangement
gives NaN, with ``mu_eff_count = 0``. Its standard error treats the
realizations as independent clusters of correlated samples: the tests of
one realization (the rearrangements of a bin, or the ``[tilt] repeats``
tests of one state) are never counted as independent. ``mu_eff_injected``,
the injected twins of ``[tilt] inject``, is pooled by the same rule.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from slidernet._validation import check_scalar
from slidernet.errors import ConfigError, param_error
from slidernet.kernels.state import AGE_EDGES
from slidernet.kernels.tilt_net import TILT_LOADS

ATTRS = {
    "n": {"long_name": "cumulative number of rearrangements (slips)", "units": "1"},
    "mu_max": {"long_name": "largest static threshold mu_s in the network", "units": "1"},
    "x_G": {"long_name": "centre-of-mass displacement along x since t = 0", "units": "l0"},
    "n_records": {"long_name": "number of drawn thresholds that exceeded the running mu_max",
                  "units": "1"},
    "mu_eff": {"long_name": "effective static friction coefficient from the virtual tilt test",
               "units": "1"},
    "tilt_first_slip": {"long_name": "load per unit normal load along x, f + f_bar, at the first slip of the "
                                     "network tilt test at t (the mean over its [tilt] repeats)", "units": "1"},
    "tilt_all_moving": {"long_name": "load f + f_bar at which an avalanche of the tilt test at t first set every "
                                     "node in motion at once, above mu_d or not (the mean over the [tilt] repeats "
                                     "in which one did; NaN: none did)", "units": "1"},
    "tilt_contact_mean": {"long_name": "mean over the contacts, weighted by their normal loads N_i, of the load "
                                       "f + f_bar at which each contact first broke in the network tilt test at t "
                                       "(its node's first slip; a contact intact at the test's sample at that "
                                       "sample) (the mean over its [tilt] repeats)", "units": "1"},
    "tilt_half_broken": {"long_name": "load f + f_bar at which the contacts broken in the network tilt test at t "
                                      "first held half of the normal load (the mean over its [tilt] repeats)",
                         "units": "1"},
    "tilt_break_ratio": {"long_name": "mean over the contacts, weighted by their normal loads N_i, of the local "
                                      "ratio |F_i| / N_i of the force on each contact to its normal load at the "
                                      "moment it first broke in the network tilt test at t (a contact intact at "
                                      "the test's sample: its ratio then) (the mean over its [tilt] repeats)",
                         "units": "1"},
    "mu_eff_spread": {"long_name": "standard deviation (ddof = 1) of the realization's [tilt] repeats network "
                                   "tilt tests at t (NaN: fewer than 2 sampled)", "units": "1"},
    "contact_age": {"long_name": "mean over the nodes of the time since each node last slipped in the horizontal "
                                 "evolution (since t = 0 for a node that has not slipped)", "units": "tau_th"},
    "mu_eff_realization": {"long_name": "mean of the realization's own tilt tests in the bin (t_{k-1}, t_k] "
                                        "(NaN: none)", "units": "1"},
    "mu_shs": {"long_name": "static friction from the slide-hold-slide pull at t: peak of the stage force per "
                            "unit normal load, plus f_bar, until every contact was renewed (NaN: no pull, the "
                            "network had slid away)", "units": "1"},
    "shs_travel": {"long_name": "travel of the slide-hold-slide stage from the start of its pull at t to the peak "
                                "of mu_shs", "units": "l0"},
    "tilt_capped": {"long_name": "number of network tilt tests at t, over the realizations, that met the "
                                "avalanche cap (a part of the network sliding alone) before the sliding rule of "
                                "[tilt]: left out of mu_eff and mu_eff_count", "units": "1"},
}

#: The pairing every injected variable rests on, in its attributes with the injection's c, t0 and select.
PAIRING = ("each test at t is made twice, on the same state with the same draws of its stream (tilt; shs for the "
           "slide-hold-slide pull): as it is "
           "(the plain variable) and on a copy whose thresholds mu_s are raised by "
           "inject_c ln(1 + t / inject_t0), those of the ceil(inject_select N) oldest contacts (all with "
           "inject_select = 1); a contact that slips in the test draws a fresh threshold without the rise")


def _injected_attrs(name: str, inject: np.ndarray) -> dict[str, str | float]:
    """The attributes of the injected twin of ``name``: its plain meaning, the injection and the pairing."""
    c, t0, select = (float(x) for x in inject)
    return {**ATTRS[name], "long_name": f"injected twin ([tilt] inject) of: {ATTRS[name]['long_name']}",
            "inject_c": c, "inject_t0": t0, "inject_select": select, "pairing": PAIRING}


Record = dict[str, np.ndarray]
Variables = dict[str, tuple[tuple[str, ...], np.ndarray, dict[str, str]]]

CHUNK = 1024
"""Realizations per reduction chunk. Fixed, so that the ensemble statistics are
summed in the same order whatever the number of workers or checkpoints."""


def _network_variables(ds: Variables, records: list[Record], first_realization: int,
                       size_bins: int | None) -> None:
    """Variables that only network kernels record (docs/model.md: networks add their own); the avalanche
    counts in their first ``size_bins`` bins (None: every bin)."""
    first = records[0]
    per_t = {
        "y_G": ("centre-of-mass displacement along y since t = 0", "l0"),
        "mu_mean": ("mean static threshold over the nodes", "1"),
        "mu_min": ("weakest static threshold in the network", "1"),
    }
    for name, (long_name, units) in per_t.items():
        if name in first:
            ds[name] = (("realization", "t"), np.stack([r[name] for r in records]),
                        {"long_name": long_name, "units": units})
    if "avalanche_count" in first:
        counts = np.stack([r["avalanche_count"] for r in records])[:, :size_bins]
        ds["avalanche_count"] = (("realization", "avalanche_size"), counts, {
            "long_name": "number of avalanches (driving slip + triggered slips) per size bin "
                         "[s, 2 s), s = avalanche_size", "units": "1"})
    if "node_slips" in first:
        ds["node_slips"] = (("realization", "node"), np.stack([r["node_slips"] for r in records]),
                            {"long_name": "number of slips of each node", "units": "1"})
        ds["mu_s"] = (("realization", "node"), np.stack([r["mu_s"] for r in records]),
                      {"long_name": "static threshold of each node at the end", "units": "1"})
    if "events" in first:
        _event_catalogue(ds, records, first_realization)


EVENT_ATTRS = {
    "time": ("time of the slip (q + fraction of the thermal step at its driving event)", "tau_th"),
    "node": ("node that slipped", "1"),
    "avalanche": ("avalanche id: driving events so far in the realization (0: initial relaxation)", "1"),
    "dx": ("displacement of the node along x", "l0"),
    "dy": ("displacement of the node along y", "l0"),
}


def _event_catalogue(ds: Variables, records: list[Record], first_realization: int) -> None:
    """The slips of every realization, one after the other, along dim ``event``."""
    events = [r["events"] for r in records]
    sizes = [e["node"].size for e in events]
    ds["event_realization"] = ("event", np.repeat(np.arange(len(records)) + first_realization, sizes),
                               {"long_name": "realization of the slip", "units": "1"})
    two_d = "y_G" in records[0]
    for name, (long_name, units) in EVENT_ATTRS.items():
        if name == "dy" and not two_d:
            continue
        ds[f"event_{name}"] = ("event", np.concatenate([e[name] for e in events]),
                               {"long_name": long_name, "units": units})
    ds["events_complete"] = ("realization", np.array([int(r["events_complete"]) for r in records], np.int8),
                             {"long_name": "1 if every slip is in the catalogue (solver.max_events not reached)",
                              "units": "1"})


CREEP_EVENT_ATTRS = {
    "time": ("time of the creep event (its avalanche's driving event)", "tau_th"),
    "dx_G": ("advance of x_G along +x over the creep event's avalanche", "l0"),
    "wait": ("waiting time since the previous creep event (NaN for the first)", "tau_th"),
}
CREEP_VARIABLES = {
    "x_G_cycle": ("cycle", "x_G at the end of the cycle", "l0"),
    "dx_G_cycle": ("cycle", "advance of x_G over the cycle", "l0"),
    "v_creep": ((), "reptation velocity: mean rate of x_G after creep.transient", "l0/tau_th"),
    "v_creep_cycle": ((), "reptation velocity per cycle: mean advance of x_G per whole cycle after "
                          "creep.transient (NaN without a periodic driver)", "l0"),
    "v_creep_cycles_sem": ((), "standard error of v_creep from the spread of the advances of its cycles "
                               "(NaN without 2 whole cycles after creep.transient)", "l0/tau_th"),
}


def _padded(rows: list[np.ndarray], width: int) -> np.ndarray:
    """Ragged rows as one array (len(rows), width), padded with NaN."""
    out = np.full((len(rows), width), np.nan)
    for b, row in enumerate(rows):
        out[b, : row.size] = row
    return out


def _creep_variables(ds: Variables, records: list[Record]) -> None:
    """The creep observables (:mod:`slidernet.solver.creep`): per cycle, the velocity, the creep events."""
    for name, (dim, long_name, units) in CREEP_VARIABLES.items():
        if name in records[0]:
            ds[name] = (("realization", *((dim,) if dim else ())), np.stack([r[name] for r in records]),
                        {"long_name": long_name, "units": units})
    events = [r["creep_events"] for r in records]
    counts = np.array([e["time"].size for e in events], np.int64)
    ds["creep_event_count"] = ("realization", counts, {"long_name": "number of creep events", "units": "1"})
    width = int(counts.max())
    # The scene's constants (the same in every record): the reference slip and the events' threshold.
    constants = {"reference_slip": float(records[0]["creep_slip"]),
                 "event_threshold": float(records[0]["creep_threshold"])}
    for name, (long_name, units) in CREEP_EVENT_ATTRS.items():
        var = "creep_waiting_time" if name == "wait" else f"creep_event_{name}"
        ds[var] = (("realization", "creep_event"), _padded([e[name] for e in events], width),
                   {"long_name": long_name + "; NaN past creep_event_count", "units": units, **constants})


def realization_variables(records: list[Record], observables: list[str], first_realization: int = 0,
                          size_bins: int | None = None) -> Variables:
    """The per-realization variables of consecutive realizations, stacked.

    Parameters
    ----------
    records : list of dict
        Realizations ``first_realization, first_realization + 1, ...``, as
        returned by :func:`slidernet.solver.simulate`.
    observables : list of str
        The requested observables.
    first_realization : int
        Index of ``records[0]``.
    size_bins : int, optional
        The avalanche size bins to keep (:func:`avalanche_bins` over every
        realization of the result); None: every bin of the kernel's.

    Returns
    -------
    dict
        name -> (dims, data, attrs), dims starting with ``realization`` (or
        ``event`` for the event catalogue).
    """
    out: Variables = {}
    for name in ("n", "mu_max", "x_G", "n_records", "contact_age"):
        if name in observables:
            out[name] = (("realization", "t"), np.stack([r[name] for r in records]), ATTRS[name])
    inject = records[0].get("inject")
    for suffix in ("", "_injected") if inject is not None else ("",):
        attrs = (lambda name: ATTRS[name]) if not suffix else (lambda name: _injected_attrs(name, inject))
        if "mu_eff_realization" in observables and "f_count" + suffix in records[0]:
            # Each realization's own mean of its tilt tests in the bin: independent across realizations,
            # so trends and errors of mu_eff can come from the spread of realizations, not of time bins.
            count = np.stack([r["f_count" + suffix] for r in records]).astype(np.float64)
            with np.errstate(invalid="ignore", divide="ignore"):
                value = np.stack([r["f_sum" + suffix] for r in records]) / np.where(count > 0, count, np.nan)
            out[f"mu_eff{suffix}_realization"] = (("realization", "t"), value, attrs("mu_eff_realization"))
        for name in (*TILT_LOADS, "mu_shs", "shs_travel"):
            if name + suffix in records[0]:
                out[name + suffix] = (("realization", "t"), np.stack([r[name + suffix] for r in records]),
                                      attrs(name))
    if "mu_eff_spread" in records[0]:
        out["mu_eff_spread"] = (("realization", "t"), np.stack([r["mu_eff_spread"] for r in records]),
                                ATTRS["mu_eff_spread"])
    _network_variables(out, records, first_realization, size_bins)
    if "creep_events" in records[0]:
        _creep_variables(out, records)
    if "slid_away_at" in records[0]:  # a scene that can slide away (docs/model.md, 'Sliding away')
        out["slid_away_at"] = ("realization", np.array([r["slid_away_at"] for r in records], np.float64), {
            "long_name": "time at which the network slid away (NaN: it did not); the records after it "
                         "hold the state of that moment", "units": "tau_th"})
    return out


def pad_creep_events(parts: list[Variables]) -> None:
    """Pad the creep events of consecutive chunks of :func:`realization_variables` to one width, in place."""
    names = [name for name, (dims, _, _) in parts[0].items() if "creep_event" in dims]
    if not names:
        return
    width = max(p[names[0]][1].shape[1] for p in parts)
    for p in parts:
        for name in names:
            dims, data, attrs = p[name]
            p[name] = (dims, np.pad(data, ((0, 0), (0, width - data.shape[1])), constant_values=np.nan), attrs)


def _undefined_sem(shape: tuple[int, ...]) -> np.ndarray:
    return np.full(shape, np.nan)


class EnsembleStats:
    """Ensemble statistics reduced on the fly, chunk by chunk, in realization order.

    Memory does not grow with the number of realizations. Feed
    :meth:`add` consecutive chunks of :data:`CHUNK` realizations (the last one
    may be shorter), always cut at the same places, so that the sums are the
    same bits however the realizations were computed. Means are chunk sums
    added in order; variances combine per-chunk two-pass moments (Chan et
    al.'s pairwise update), which loses no digits to cancellation.

    Parameters
    ----------
    observables : list of str
        The requested observables.
    steps : int
        The last recorded time, for the rate ``r = n(steps) / steps``.
    """

    MOMENTS = ("n", "mu_max", "x_G", "n_records", "contact_age", "mu_shs")
    #: Of those, the ones an injected twin of ``[tilt] inject`` has, named ``<name>_injected`` in the records.
    INJECTED_MOMENTS = ("mu_shs",)

    def __init__(self, observables: list[str], steps: int) -> None:
        self.observables = list(observables)
        self.steps = steps
        self.R = 0
        self._moments: dict[str, tuple[np.ndarray, np.ndarray]] = {}  # name -> (mean, M2)
        self._f: dict[str, dict[str, np.ndarray]] = {}  # "" or "_injected" -> the pooled sums of the tilt tests
        self._age_count: np.ndarray | None = None  # (T, bins) int64: the nodes' ages, summed over realizations
        # "" or "_injected" -> (T,) int64: the tilt tests that met the cap first, summed
        self._capped: dict[str, np.ndarray] = {}
        self._inject: np.ndarray | None = None  # the injection's (c, t0, select), where [tilt] inject is set

    def _merge(self, name: str, x: np.ndarray) -> None:
        """Fold the chunk ``x`` (B, ...) into the running (mean, M2) of ``name``."""
        B = x.shape[0]
        m_b = x.sum(axis=0) / B
        m2_b = ((x - m_b) ** 2).sum(axis=0)
        if name not in self._moments:
            self._moments[name] = (m_b, m2_b)
            return
        mean, m2 = self._moments[name]
        n_a = self.R
        n = n_a + B
        delta = m_b - mean
        self._moments[name] = (mean + delta * (B / n), m2 + m2_b + delta**2 * (n_a * B / n))

    def add(self, records: list[Record]) -> None:
        """Fold the next chunk of consecutive realizations in."""
        for name in self.MOMENTS:
            if name in self.observables:
                x = np.stack([r[name] for r in records]).astype(float)
                self._merge(name, x)
                if name == "x_G":
                    self._merge("x_G2", x**2)
            if name in self.INJECTED_MOMENTS and name + "_injected" in records[0]:
                self._merge(name + "_injected", np.stack([r[name + "_injected"] for r in records]).astype(float))
        if "n" in self.observables and self.steps > 0:
            self._merge("r", np.array([[r["n"][-1] / self.steps] for r in records]))
        if "contact_age" in self.observables:
            counts = np.stack([r["contact_age_count"] for r in records]).sum(axis=0)
            self._age_count = counts if self._age_count is None else self._age_count + counts
        for name in ("v_creep", "v_creep_cycle"):
            if name in records[0]:
                self._merge(name, np.array([[r[name]] for r in records], dtype=np.float64))
        self._inject = records[0].get("inject")
        for suffix in ("", "_injected"):
            if "tilt_capped" + suffix in records[0]:
                capped = np.stack([r["tilt_capped" + suffix] for r in records]).sum(axis=0)
                self._capped[suffix] = capped + self._capped.get(suffix, 0)
            if "mu_eff" in self.observables and "f_sum" + suffix in records[0]:
                self._pool(suffix, np.stack([r["f_sum" + suffix] for r in records]),
                           np.stack([r["f_count" + suffix] for r in records]).astype(float))
        self.R += len(records)

    def _pool(self, suffix: str, fsum: np.ndarray, count: np.ndarray) -> None:
        """Fold a chunk's tilt-test sums (B, T) and counts (B, T) into the pooled sums of ``suffix``."""
        if suffix not in self._f:
            # Shift for the sums of squares: the first chunk's pooled value,
            # close to the final one, so that no digits cancel.
            with np.errstate(invalid="ignore", divide="ignore"):
                shift = fsum.sum(axis=0) / count.sum(axis=0)
            self._f[suffix] = {"shift": np.nan_to_num(shift), "f": 0.0, "c": 0.0, "gg": 0.0, "gc": 0.0, "cc": 0.0}
        f = self._f[suffix]
        g = fsum - f["shift"] * count
        f["f"] = f["f"] + fsum.sum(axis=0)
        f["c"] = f["c"] + count.sum(axis=0)
        f["gg"] = f["gg"] + (g * g).sum(axis=0)
        f["gc"] = f["gc"] + (g * count).sum(axis=0)
        f["cc"] = f["cc"] + (count * count).sum(axis=0)

    def _mean_sem(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        mean, m2 = self._moments[name]
        if self.R < 2:  # undefined with a single realization
            return mean, _undefined_sem(np.shape(mean))
        return mean, np.sqrt(m2 / (self.R - 1)) / np.sqrt(self.R)

    def finish(self) -> Variables:
        """The statistics: ``<name>_mean``, ``<name>_sem``, ``x_G2_*``, ``r_*``, ``mu_eff*``."""
        out: Variables = {}
        for name in self.MOMENTS:
            if name not in self.observables:
                continue
            units = ATTRS[name]["units"]
            mean, sem = self._mean_sem(name)
            out[f"{name}_mean"] = ("t", mean, {"long_name": f"ensemble mean of {name}", "units": units})
            out[f"{name}_sem"] = ("t", sem, {"long_name": f"standard error of {name}_mean", "units": units})
            if name == "x_G":
                mean, sem = self._mean_sem("x_G2")
                out["x_G2_mean"] = ("t", mean, {"long_name": "mean square displacement <x_G^2>", "units": "l0^2"})
                out["x_G2_sem"] = ("t", sem, {"long_name": "standard error of x_G2_mean", "units": "l0^2"})
            if name + "_injected" in self._moments:
                twin = f"{name}_injected"
                extra = {**_injected_attrs(name, self._inject), "long_name": f"ensemble mean of {twin}"}
                mean, sem = self._mean_sem(twin)
                out[f"{twin}_mean"] = ("t", mean, extra)
                out[f"{twin}_sem"] = ("t", sem, {**extra, "long_name": f"standard error of {twin}_mean"})
        if self._age_count is not None:
            out["contact_age_count"] = (("t", "contact_age_bin"), self._age_count, {
                "long_name": "number of (realization, node) pairs whose contact age at t lies in the bin "
                             "[contact_age_bin, contact_age_upper)", "units": "1"})
        if "r" in self._moments:
            mean, sem = self._mean_sem("r")
            out["r_mean"] = ((), mean[0], {"long_name": "mean rearrangements per tau_th", "units": "1"})
            out["r_sem"] = ((), sem[0], {"long_name": "standard error of r_mean", "units": "1"})
        for name in ("v_creep", "v_creep_cycle"):
            if name in self._moments:
                mean, sem = self._mean_sem(name)
                units = CREEP_VARIABLES[name][2]
                out[f"{name}_mean"] = ((), mean[0], {"long_name": f"ensemble mean of {name}", "units": units})
                out[f"{name}_sem"] = ((), sem[0], {"long_name": f"standard error of {name}_mean over the "
                                                                f"realizations", "units": units})
        for suffix, f in self._f.items():
            R = self.R
            total = f["c"]
            with np.errstate(invalid="ignore", divide="ignore"):
                mu_eff = f["f"] / total
                # Ratio estimator, realizations as independent clusters:
                # sum_r (f_r - mu_eff c_r)^2, expanded about the shift.
                d = mu_eff - f["shift"]
                resid2 = np.maximum(f["gg"] - 2 * d * f["gc"] + d * d * f["cc"], 0.0)
                sem = np.sqrt(resid2 / (R * (R - 1))) / (total / R) if R > 1 else _undefined_sem(total.shape)
            name = "mu_eff" + suffix
            extra = _injected_attrs("mu_eff", self._inject) if suffix else {}
            out[name] = ("t", mu_eff, {**ATTRS["mu_eff"], **extra})
            out[name + "_sem"] = ("t", np.where(total > 0, sem, np.nan),
                                  {**extra, "long_name": f"standard error of {name}, from the spread of the "
                                                         "realizations' tests", "units": "1"})
            out[name + "_count"] = ("t", total.astype(np.int64), {
                **extra, "long_name": f"number of tilt tests pooled into {name}", "units": "1"})
        for suffix, capped in self._capped.items():
            extra = _injected_attrs("tilt_capped", self._inject) if suffix else ATTRS["tilt_capped"]
            out["tilt_capped" + suffix] = ("t", capped.astype(np.int64), extra)
        return out


def chunks(records: Iterable[Record], size: int = CHUNK) -> Iterator[list[Record]]:
    """Consecutive lists of ``size`` records (the last one shorter)."""
    chunk: list[Record] = []
    for rec in records:
        chunk.append(rec)
        if len(chunk) == size:
            yield chunk
            chunk = []
    if chunk:
        yield chunk


def coordinates(t: np.ndarray, R: int, first: Record, size_bins: int | None = None) -> dict[str, tuple]:
    """The coordinates of the result: ``realization``, ``t``, for networks ``avalanche_size`` (its first
    ``size_bins`` bins; None: every bin of the kernel's), and with a periodic driver and the observable
    ``creep`` ``cycle`` and ``cycle_end``."""
    coords: dict[str, tuple] = {
        "realization": ("realization", np.arange(R, dtype=np.int64)),
        "t": ("t", np.asarray(t, dtype=np.int64), {"long_name": "time", "units": "tau_th"}),
    }
    if "avalanche_count" in first:
        bins = first["avalanche_count"].size if size_bins is None else size_bins
        coords["avalanche_size"] = ("avalanche_size", 2 ** np.arange(bins, dtype=np.int64), {
            "long_name": "smallest avalanche size (slips) of the bin [s, 2 s); the bins end at the highest "
                         "occupied in any realization", "units": "1"})
    if "contact_age_count" in first:
        # Fixed edges (kernels.AGE_EDGES), the same for every run: histograms of runs and sweeps stack.
        edges = np.concatenate([[0.0], AGE_EDGES, [np.inf]])
        coords["contact_age_bin"] = ("contact_age_bin", edges[:-1], {
            "long_name": "lower edge of the contact-age bin (4 per decade from 1e-6)", "units": "tau_th"})
        coords["contact_age_upper"] = ("contact_age_bin", edges[1:], {
            "long_name": "upper edge of the contact-age bin (excluded)", "units": "tau_th"})
    if "cycle_end" in first:
        C = first["cycle_end"].size
        coords["cycle"] = ("cycle", np.arange(1, C + 1, dtype=np.int64),
                           {"long_name": "cycle of the periodic driver (cycle c ends at t = c period)",
                            "units": "1"})
        coords["cycle_end"] = ("cycle", np.asarray(first["cycle_end"], dtype=np.float64),
                               {"long_name": "end of the cycle, c period", "units": "tau_th"})
    return coords


def assemble(
    records: Iterable[Record],
    t: np.ndarray,
    observables: list[str],
    attrs: dict[str, str | int | float],
) -> xr.Dataset:
    """Stack the realizations' records into the result dataset, in memory.

    Parameters
    ----------
    records : iterable of dict
        One dict per realization, in realization order, as returned by
        :func:`slidernet.solver.simulate`.
    t : ndarray of int, shape (T,)
        Recorded times in tau_th.
    observables : list of str
        The requested observables; ``mu_eff`` adds the tilt-test variables.
    attrs : dict
        Global attributes (resolved config, version, seed).

    Returns
    -------
    xarray.Dataset
        Coordinates ``realization`` and ``t``; see the module docstring.
        :func:`slidernet.ensemble.stream.write_result_stream` writes the same variables,
        chunk by chunk, to a file.
    """
    stats = EnsembleStats(observables, int(t[-1]))
    parts: list[Variables] = []
    R = 0
    first: Record | None = None
    for chunk in chunks(records):
        first = first or chunk[0]
        parts.append(realization_variables(chunk, observables, R))
        stats.add(chunk)
        R += len(chunk)
    if first is None:
        raise ValueError("assemble needs at least one realization")
    pad_creep_events(parts)
    data = {name: (dims, np.concatenate([p[name][1] for p in parts]), a)
            for name, (dims, _, a) in parts[0].items()}
    size_bins = None
    if "avalanche_count" in data:
        dims, counts, a = data["avalanche_count"]
        size_bins = avalanche_bins(counts)
        data["avalanche_count"] = (dims, counts[:, :size_bins], a)
    ds = xr.Dataset(data, coords=coordinates(t, R, first, size_bins), attrs=dict(attrs))
    for name, var in stats.finish().items():
        ds[name] = var
    return ds


def avalanche_bins(counts: ArrayLike) -> int:
    """The avalanche size bins a result keeps: from the first, sizes [1, 2), to the highest occupied one.

    The kernels count avalanches in 63 bins [2^k, 2^(k+1)) (up to 2^62
    slips, what int64 holds); a result keeps those up to the highest bin
    that any realization occupies, so that its ``avalanche_size`` ends near
    its largest avalanche. Every bin below stays, empty or not.

    Parameters
    ----------
    counts : array_like, shape (..., B)
        Counts (or whether any) per bin, along the last axis, e.g. the
        kernels' ``avalanche_count`` of every realization, (R, 63).

    Returns
    -------
    int
        The number of bins to keep, in [1, B]: 1 where nothing is counted,
        so that the dimension and its integer dtype stay.

    Examples
    --------
    >>> avalanche_bins([[3, 1, 0, 0], [2, 0, 0, 0]])
    2
    """
    counts = np.asarray(counts)
    occupied = np.flatnonzero(counts.reshape(-1, counts.shape[-1]).any(axis=0))
    return int(occupied[-1]) + 1 if occupied.size else 1


def align_avalanche_sizes(datasets: Iterable[xr.Dataset]) -> list[xr.Dataset]:
    """Results with the same ``avalanche_size``: each padded with empty bins to the widest, to concatenate them.

    Each result's histogram ends at its own highest occupied bin
    (:func:`avalanche_bins`), so the results of two runs differ in their
    ``avalanche_size`` where their largest avalanches do; pad them before
    :func:`xarray.concat`, which would otherwise fill the missing bins with
    NaN (and make the counts float). ``xr.concat(..., join="outer",
    fill_value={"avalanche_count": 0})`` does the same.

    Parameters
    ----------
    datasets : iterable of xarray.Dataset
        Results; those without ``avalanche_size`` (two sliders on the pair
        kernel) are returned as they are.

    Returns
    -------
    list of xarray.Dataset
        The same results, ``avalanche_count`` padded with zeros (its dtype
        kept) to the widest ``avalanche_size``.

    Examples
    --------
    >>> a = xr.Dataset({"avalanche_count": (("realization", "avalanche_size"), [[4, 1]])},
    ...                coords={"avalanche_size": [1, 2]})
    >>> b = a.isel(avalanche_size=[0])
    >>> align_avalanche_sizes([a, b])[1]["avalanche_count"].values.tolist()
    [[4, 0]]
    """
    datasets = list(datasets)
    widths = [ds.sizes.get("avalanche_size", 0) for ds in datasets]
    if not any(widths):
        return datasets
    sizes = datasets[int(np.argmax(widths))]["avalanche_size"]
    return [ds.reindex(avalanche_size=sizes, fill_value={"avalanche_count": 0}) if 0 < w < sizes.size else ds
            for ds, w in zip(datasets, widths, strict=True)]


def binned_quantile(counts: ArrayLike, lower: ArrayLike, upper: ArrayLike,
                    q: float) -> tuple[np.ndarray, np.ndarray]:
    """The bin that holds the q-quantile of values known only through their histogram.

    The q-quantile is read as the order statistic of rank j = ceil(q n) of
    the n counted values (the inverse of the empirical distribution
    function, NumPy's ``method="inverted_cdf"``; q = 0 the smallest value, q
    = 1 the largest): it lies in the first bin k where the cumulative count
    reaches q n. The histogram bounds it, and no more: ``lower[k] <=
    quantile < upper[k]`` exactly, wherever the values lie inside their
    bins. For ``contact_age_count`` (values in [``contact_age_bin``,
    ``contact_age_upper``), 4 bins per decade) that is a factor 10^(1/4) =
    1.78 of resolution; every age at t is also <= t.

    Parameters
    ----------
    counts : array_like of int, shape (..., B)
        The counts of B bins along the last axis (e.g. ``contact_age_count``,
        shape (T, B), pooled over realizations and nodes).
    lower, upper : array_like, shape (B,)
        The bins' edges: bin b holds the values in [lower[b], upper[b]);
        increasing, each bin above the previous one.
    q : float
        The quantile, in [0, 1].

    Returns
    -------
    lo, hi : ndarray, shape (...)
        The edges of the bin that holds the quantile; NaN where nothing is
        counted.

    Raises
    ------
    ConfigError
        If ``q`` is not a real number in [0, 1], or the shapes do not match.

    Examples
    --------
    Ten ages in bins [0, 1), [1, 10), [10, 100): the 90th percentile, the
    9th smallest age, lies in [1, 10), the largest in [10, 100).

    >>> counts, lower, upper = [2, 7, 1], [0.0, 1.0, 10.0], [1.0, 10.0, 100.0]
    >>> binned_quantile(counts, lower, upper, 0.9), binned_quantile(counts, lower, upper, 1.0)
    ((array(1.), array(10.)), (array(10.), array(100.)))
    """
    owner = "binned_quantile"
    q = check_scalar(q, "q", owner)
    if not 0.0 <= q <= 1.0:
        raise param_error("q", owner, "in [0, 1]", q)
    counts = np.asarray(counts)
    lower, upper = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)
    if lower.shape != upper.shape or lower.ndim != 1 or counts.shape[-1:] != lower.shape:
        raise ConfigError(f"{owner} needs counts of shape (..., B) and edges of shape (B,); got "
                          f"{counts.shape}, {lower.shape} and {upper.shape}.")
    cumulative = np.cumsum(counts, axis=-1)
    total = cumulative[..., -1]
    # The first bin whose cumulative count reaches max(q n, 1): rank ceil(q n), at least the first value.
    # q n in float64, as NumPy's inverted_cdf computes it, so that the two agree on every value.
    rank = np.maximum(q * total, 1)
    k = np.minimum((cumulative < rank[..., None]).sum(axis=-1), lower.size - 1)
    empty = total == 0
    return np.where(empty, np.nan, lower[k]), np.where(empty, np.nan, upper[k])
