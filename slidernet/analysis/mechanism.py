"""The state of every node at the recorded times: which thresholds survive, and how loaded the nodes stand.

Why friction ages or weakens is a question about the nodes, not only about
the strongest threshold: are the thresholds that survive the thermal
cycling a selection of the fresh law (weak ones replaced, strong ones kept),
and how close to their thresholds do the nodes stand (prestress)?
:func:`node_states` follows realizations of a configuration and records,
at the times asked, every node's threshold mu_s and its load ratio
``|F_i| / (mu_s,i N_i)`` (1 at the threshold; every stable node has at most 1);
:func:`node_summary` reduces them to statistics whose standard errors come
from independent realizations: per-realization means, then their mean and
spread, never the nodes of one realization taken as independent (they are
not: a slip redraws one threshold and moves its neighbours' forces).

Realization r is driven by child r of the seed, as in :func:`slidernet.run`,
so these are the states of that run's realizations, to the bit.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from slidernet._validation import check_array
from slidernet.config import Config, load_config
from slidernet.errors import ConfigError
from slidernet.solver import Realization, Scene


def node_states(config: Config | Mapping[str, Any] | str | Path, times: Sequence[int] | np.ndarray, *,
                realizations: int | None = None) -> xr.Dataset:
    """Every node's threshold and load ratio at the thermal steps ``times``, for each realization.

    Parameters
    ----------
    config : Config, dict or path
        A run's configuration; its ``seed`` must be set (an int), so that
        the states are those of the run's realizations.
    times : sequence of int, shape (T,)
        Thermal steps, in tau_th, increasing, in [0, steps].
    realizations : int, optional
        The first ``realizations`` realizations (default: the config's).

    Returns
    -------
    xarray.Dataset
        ``mu_s`` (realization, t, node): the thresholds; ``load_ratio``
        (realization, t, node): ``|F_i| / (mu_s,i N_i)``, dimensionless;
        ``n`` (realization, t): slips so far. Attributes: the resolved
        ``config`` (JSON) and ``seed``.

    Raises
    ------
    ConfigError
        If the seed is not set, or ``times`` are not increasing steps of the run.

    Examples
    --------
    Two sliders at rest at t = 0 carry no spring force:

    >>> cfg = {"seed": 1, "realizations": 2, "steps": 10, "network": {"Ntilde": 1e-7},
    ...        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}
    >>> states = node_states(cfg, [0, 10])
    >>> dict(states.sizes)
    {'realization': 2, 't': 2, 'node': 2}
    >>> float(states["load_ratio"].sel(t=0).max())
    0.0
    """
    cfg = load_config(config)
    if cfg.seed is None:
        raise ConfigError("node_states needs a config with a 'seed' (an int): the states are those of the "
                          "run's realizations, child r of that seed for realization r.")
    t = check_array(times, "times", "node_states", ">= 0")
    if t.ndim != 1 or t.size == 0 or (np.diff(t) <= 0).any() or (t != np.round(t)).any() or t[-1] > cfg.steps:
        raise ConfigError(f"The 'times' parameter of node_states must be increasing whole thermal steps in "
                          f"[0, {cfg.steps}]. Got {np.asarray(times).tolist()!r} instead.")
    t = t.astype(np.int64)
    R = cfg.realizations if realizations is None else int(realizations)
    scene = Scene.from_config(cfg)
    N = scene.network.n_nodes
    load = scene.network.normal_load.astype(np.float64)
    mu_s = np.empty((R, t.size, N))
    ratio = np.empty((R, t.size, N))
    n = np.empty((R, t.size), np.int64)
    for r in range(R):
        real = Realization(scene, np.random.SeedSequence(cfg.seed, spawn_key=(r,)))
        for k, step in enumerate(t):
            real.advance(int(step))
            mu = real.thresholds
            force = np.linalg.norm(real.forces().reshape(N, -1), axis=1)
            mu_s[r, k] = mu
            ratio[r, k] = force / (mu * load)
            n[r, k] = real.n
    dims = ("realization", "t", "node")
    return xr.Dataset(
        {
            "mu_s": (dims, mu_s, {"long_name": "static threshold of each node", "units": "1"}),
            "load_ratio": (dims, ratio, {"long_name": "|F_i| / (mu_s,i N_i): 1 at the threshold", "units": "1"}),
            "n": (("realization", "t"), n, {"long_name": "cumulative number of slips", "units": "1"}),
        },
        coords={"realization": np.arange(R), "t": t, "node": np.arange(N)},
        attrs={"config": cfg.model_dump_json(), "seed": int(cfg.seed)},
    )


def node_summary(states: xr.Dataset, quantiles: Sequence[float] = (0.1, 0.5, 0.9),
                 law_mean: float | None = None) -> xr.Dataset:
    """Statistics of :func:`node_states` at each time, with standard errors from the realizations.

    For ``mu_s`` and ``load_ratio``: ``<name>_mean`` and ``<name>_sem`` (t,),
    the mean over realizations of each realization's mean over its nodes
    and its standard error (the spread of those means over sqrt(R));
    ``<name>_quantile`` (quantile, t), the quantiles of all nodes of all
    realizations pooled (a description, without error). With ``law_mean``,
    the mean of the fresh law of mu_s (``Distribution.mean_max(1)``),
    ``mu_s_shift_mean`` and ``mu_s_shift_sem`` (t,): how far the surviving
    thresholds stand above it (selection).

    Examples
    --------
    >>> s = xr.Dataset({"mu_s": (("realization", "t", "node"), [[[0.6, 0.8]], [[0.7, 0.7]]]),
    ...                 "load_ratio": (("realization", "t", "node"), [[[0.5, 1.0]], [[0.25, 0.25]]])},
    ...                coords={"t": [0]})
    >>> out = node_summary(s, law_mean=0.6)
    >>> round(float(out["mu_s_mean"][0]), 12), float(out["mu_s_sem"][0])
    (0.7, 0.0)
    >>> round(float(out["mu_s_shift_mean"][0]), 12)
    0.1
    >>> float(out["load_ratio_mean"][0]), float(out["load_ratio_sem"][0])
    (0.5, 0.25)
    """
    R = states.sizes["realization"]
    q = np.asarray(quantiles, dtype=np.float64)
    out: dict[str, Any] = {}
    for name in ("mu_s", "load_ratio"):
        per_r = states[name].mean("node")  # (realization, t): one independent value per realization
        out[f"{name}_mean"] = per_r.mean("realization")
        # Undefined with one realization: NaN, as every *_sem of a run.
        nan = out[f"{name}_mean"] * np.nan
        out[f"{name}_sem"] = per_r.std("realization", ddof=1) / np.sqrt(R) if R > 1 else nan
        out[f"{name}_quantile"] = states[name].quantile(q, dim=("realization", "node"))
    if law_mean is not None:
        shift = states["mu_s"].mean("node") - float(law_mean)
        out["mu_s_shift_mean"] = shift.mean("realization")
        out["mu_s_shift_sem"] = out["mu_s_sem"]
    ds = xr.Dataset(out)
    ds.attrs["realizations"] = R
    return ds
