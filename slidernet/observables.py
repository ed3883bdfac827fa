"""From per-realization records to the result dataset (MODEL.md section 3).

Per realization (dims ``realization, t``): ``n``, ``mu_max``, ``x_G`` and
``n_records``. Ensemble statistics (dim ``t``): ``<name>_mean`` and
``<name>_sem`` (standard error of the mean over realizations), ``x_G2_mean``
(the mean square displacement) and ``mu_eff`` from the virtual tilt test.

mu_eff(t_k) pools every tilt test made at the rearrangements of the bin
(t_{k-1}, t_k] over all realizations (the appendix's average). The bin of
t = 0 holds one test per realization, made on the initial state, so that
mu_eff(0) is the value of a fresh system. A bin without any rearrangement
gives NaN, with ``mu_eff_count = 0``. Its standard error treats the
realizations as independent clusters of correlated samples.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

ATTRS = {
    "n": {"long_name": "cumulative number of rearrangements (slips)", "units": "1"},
    "mu_max": {"long_name": "largest static threshold mu_s in the network", "units": "1"},
    "x_G": {"long_name": "centre-of-mass displacement along x since t = 0", "units": "l0"},
    "n_records": {"long_name": "number of drawn thresholds that exceeded the running mu_max",
                  "units": "1"},
    "mu_eff": {"long_name": "effective static friction coefficient from the virtual tilt test",
               "units": "1"},
}


def _sem(x: np.ndarray) -> np.ndarray:
    """Standard error over axis 0; NaN with a single realization (undefined)."""
    R = x.shape[0]
    if R < 2:
        return np.full(x.shape[1:], np.nan)
    return x.std(axis=0, ddof=1) / np.sqrt(R)


def _network_variables(ds: xr.Dataset, records: list[dict[str, np.ndarray]]) -> None:
    """Variables that only network kernels record (MODEL.md: networks add their own)."""
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
        counts = np.stack([r["avalanche_count"] for r in records])
        ds["avalanche_count"] = (("realization", "avalanche_size"), counts, {
            "long_name": "number of avalanches (driving slip + triggered slips) per size bin "
                         "[s, 2 s), s = avalanche_size", "units": "1"})
        ds.coords["avalanche_size"] = 2 ** np.arange(counts.shape[1], dtype=np.int64)
    if "node_slips" in first:
        ds["node_slips"] = (("realization", "node"), np.stack([r["node_slips"] for r in records]),
                            {"long_name": "number of slips of each node", "units": "1"})
        ds["mu_s"] = (("realization", "node"), np.stack([r["mu_s"] for r in records]),
                      {"long_name": "static threshold of each node at the end", "units": "1"})
    if "events" in first:
        _event_catalogue(ds, records)


EVENT_ATTRS = {
    "time": ("time of the slip (q + fraction of the thermal step at its driving event)", "tau_th"),
    "node": ("node that slipped", "1"),
    "avalanche": ("avalanche id: driving events so far in the realization (0: initial relaxation)", "1"),
    "dx": ("displacement of the node along x", "l0"),
    "dy": ("displacement of the node along y", "l0"),
}


def _event_catalogue(ds: xr.Dataset, records: list[dict[str, np.ndarray]]) -> None:
    """The slips of every realization, one after the other, along dim ``event``."""
    events = [r["events"] for r in records]
    sizes = [e["node"].size for e in events]
    ds["event_realization"] = ("event", np.repeat(np.arange(len(records)), sizes),
                               {"long_name": "realization of the slip", "units": "1"})
    two_d = "y_G" in ds
    for name, (long_name, units) in EVENT_ATTRS.items():
        if name == "dy" and not two_d:
            continue
        ds[f"event_{name}"] = ("event", np.concatenate([e[name] for e in events]),
                               {"long_name": long_name, "units": units})
    ds["events_complete"] = ("realization", np.array([int(r["events_complete"]) for r in records], np.int8),
                             {"long_name": "1 if every slip is in the catalogue (solver.max_events not reached)",
                              "units": "1"})


def assemble(
    records: list[dict[str, np.ndarray]],
    t: np.ndarray,
    observables: list[str],
    attrs: dict[str, str | int | float],
) -> xr.Dataset:
    """Stack the realizations' records into the result dataset.

    Parameters
    ----------
    records : list of dict
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
    """
    R = len(records)
    coords = {"realization": np.arange(R), "t": np.asarray(t, dtype=np.int64)}
    ds = xr.Dataset(coords=coords, attrs=dict(attrs))
    ds["t"].attrs.update(long_name="time", units="tau_th")
    for name in ("n", "mu_max", "x_G", "n_records"):
        if name not in observables:
            continue
        data = np.stack([r[name] for r in records])
        ds[name] = (("realization", "t"), data, ATTRS[name])
        ds[f"{name}_mean"] = ("t", data.mean(axis=0),
                              {"long_name": f"ensemble mean of {name}", "units": ATTRS[name]["units"]})
        ds[f"{name}_sem"] = ("t", _sem(data), {"long_name": f"standard error of {name}_mean",
                                               "units": ATTRS[name]["units"]})
        if name == "x_G":
            x2 = data**2
            ds["x_G2_mean"] = ("t", x2.mean(axis=0),
                               {"long_name": "mean square displacement <x_G^2>", "units": "l0^2"})
            ds["x_G2_sem"] = ("t", _sem(x2),
                              {"long_name": "standard error of x_G2_mean", "units": "l0^2"})
    _network_variables(ds, records)
    if "n" in observables and ds.sizes["t"] > 1:
        steps = int(t[-1])
        r = np.array([rec["n"][-1] / steps for rec in records])
        ds["r_mean"] = ((), r.mean(), {"long_name": "mean rearrangements per tau_th", "units": "1"})
        ds["r_sem"] = ((), _sem(r[:, None])[0], {"long_name": "standard error of r_mean", "units": "1"})
    if "mu_eff" in observables:
        fsum = np.stack([r["f_sum"] for r in records])
        count = np.stack([r["f_count"] for r in records]).astype(float)
        total = count.sum(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            mu_eff = fsum.sum(axis=0) / total
            # Ratio estimator: realizations are independent clusters.
            cbar = total / R
            resid = fsum - mu_eff[None, :] * count
            sem = np.sqrt((resid**2).sum(axis=0) / (R * (R - 1))) / cbar if R > 1 else np.nan * total
        ds["mu_eff"] = ("t", mu_eff, ATTRS["mu_eff"])
        ds["mu_eff_sem"] = ("t", np.where(total > 0, sem, np.nan),
                            {"long_name": "standard error of mu_eff", "units": "1"})
        ds["mu_eff_count"] = ("t", total.astype(np.int64),
                              {"long_name": "number of tilt tests pooled into mu_eff", "units": "1"})
    return ds
