"""Parameter sweeps: one configuration, a grid of values of some of its keys, one dataset.

``slidernet sweep CONFIG --set driver.sigma_theta=1e-7,3e-7,1e-6`` and
:func:`sweep` run every point of the product grid with :func:`slidernet.run`
and stack the points' datasets along one dimension per swept key.

Rules
-----
Seeds
    Every point runs with the configuration's seed, unchanged (common random
    numbers): realization r of every point is driven by the same child of the
    seed, so the differences between points are less noisy than the points
    themselves, and a point of a sweep is the plain run of its configuration,
    bit for bit. A seed of None is resolved once (fresh entropy) and shared by
    every point. ``seed`` cannot be swept; ``realizations`` gives
    independent samples, and cannot be swept either: every point has the
    same number.
Dimensions
    One per swept key, in the order given, named after the key's last
    component (``driver.sigma_theta`` -> ``sigma_theta``), or after the full
    dotted key when that name is taken: by another swept key with the same
    last component, or by a variable, coordinate or dimension of the result
    (``network.n`` and the variable ``n``). The coordinate holds the values
    in the order given: numbers, booleans or strings; list or table values
    (``network.shape``) are stored as their JSON text. Every per-point
    variable gains the sweep dimensions in front: ``n`` is
    ``(sigma_theta, realization, t)``, ``r_mean`` is ``(sigma_theta,)``.
Times
    The points are stacked along one time axis ``t``, never padded along
    it. The combined ``t`` is the
    recorded times of the point with the fewest ``steps``, and every other
    point's recorded times must begin with exactly those; its records after
    them are left out of the combined dataset (a point's ``mu_eff`` bins
    (t_{k-1}, t_k] stay its own; scalars such as ``r_mean`` are each point's
    own, over its full run). So ``steps`` can be swept with ``record =
    "all"``, with an explicit ``record`` list that holds every smaller
    ``steps`` value of the sweep, or with ``record = "log"`` over whole
    decades (100, 1000, ...: a log grid spreads its points over the whole
    run). Any other difference in the recorded times is refused before any
    work.
Layout
    Every point must have the same observables, and with ``mu_eff`` the same tilt test: the pair kernel's
    default, the appendix's test before every rearrangement, and the
    network test at the recorded times are two estimators, so a sweep that
    mixes them is refused (``mu_eff_at = "records"`` runs the network test
    in every scene). The event catalogue and the creep observables (whose lengths differ from run
    to run) cannot be swept. All of this, and the validity of every point's
    configuration, is checked before any work. The points' scenes may
    differ: in kernel (the ``pair`` kernel of two sliders beside the
    network kernels), dimension and number of nodes (a size sweep,
    ``network.n = 2, 4, 8``, or ``network.kind`` chain against irregular).
Absent variables
    A variable that only some points give (those of the network kernels,
    ``mu_mean``, ``mu_min``, ``avalanche_count``, ``node_slips``, ``mu_s``,
    beside the pair kernel; ``y_G`` of 2D beside 1D) is stacked all the same,
    NaN where a point lacks it, as :func:`xarray.concat` fills it: its
    dtype becomes float64 (an int64 count is exact below 2^53). A variable
    every point gives keeps its dtype and bits. Each point's
    ``avalanche_count`` ends at its own highest occupied bin; the sweep's
    ``avalanche_size`` is the widest point's, the others padded with empty
    bins (zeros, int64 kept where every point has the histogram).
Per-node variables
    Those along ``node`` (``node_slips``, ``mu_s``). Where every point's
    network has the same number of nodes they are stacked with the rest,
    and :func:`sweep` returns an :class:`xarray.Dataset`, exactly as when
    the points share their scene. Where the numbers of nodes differ it
    returns an :class:`xarray.DataTree`: its root is the dataset of every
    other variable, stacked, plus the coordinate ``sweep_point`` (the sweep
    dimensions: each point's index i in C order), and it has one child
    group per point, ``point_<i>``, that holds the point's per-node
    variables, ``(realization, node)`` (none for the pair kernel) and the
    attributes ``sweep_point`` (i), ``sweep_assignment`` (the point's keys
    and values, JSON), ``config`` (its resolved configuration) and
    ``kernel``. A group inherits the root's coordinates (``realization``).
    ``tree[f"point_{int(tree['sweep_point'].sel({'network.n': 8}))}"]``
    is the group of the point ``network.n = 8``.
Attributes
    As a run's (``config``, the base configuration with its seed resolved,
    ``slidernet_version``, ``slidernet_code``, ``seed``, ``kernel``, ``execution``: the last
    point's), plus ``sweep`` (the grid) and ``configs`` (every point's resolved configuration, C order). Where
    the points' kernels differ, ``kernel`` lists the distinct ones, comma
    separated, and ``kernels`` (JSON) gives each point's, in C order. A
    variable keeps the attributes every point gives it alike; one that
    differs between points (``inject_select`` where ``tilt.inject.select``
    is swept) is left out: each point's configuration holds its value.

With ``out``, point i (its grid position in C order: the last key varies
fastest) runs in ``out/points/<i>/`` with the runner's checkpoints there, and
the combined result is written atomically to ``out/result.nc`` (a
DataTree as netCDF4 groups, every group in the one result encoding;
:func:`slidernet.io.read_result` reads back a Dataset or a DataTree, what
was written).
``out/sweep.json`` holds the base configuration, the grid, the resolved
seed, and slidernet's version and code digest, so a killed sweep resumes
point by point (``resume=True``): finished points are read back, the
interrupted one continues from its checkpoints, the rest run; a sweep with
another configuration, grid or code is refused there. The sweep holds
``out/.slidernet.lock`` while it works (each point its point folder's), and
never works in a folder that holds a run or a paper reproduction
(:func:`slidernet.io.store.check_own_folder`).
"""

from __future__ import annotations

import copy
import itertools
import json
import re
import shutil
import signal
import sys
from collections.abc import Callable, Mapping, Sequence
from numbers import Number
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from slidernet._version import __version__, code_digest
from slidernet.analysis.observables import align_avalanche_sizes
from slidernet.config import Config, load_config, read_toml
from slidernet.ensemble import runner
from slidernet.ensemble.progress import Progress, check_progress
from slidernet.errors import CheckpointError, ConfigError, OutputError, RunInterrupted, SizeError
from slidernet.io import atomic_output, write_netcdf
from slidernet.io.store import locked_folder, read_identity_file
from slidernet.solver import Scene, budget, record_times

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["parse_grid", "parse_set", "sweep"]

_KEY = re.compile(r"[A-Za-z0-9_-]+(\.[A-Za-z0-9_-]+)*")
# Keys that a sweep refuses, with the reason.
_UNSWEEPABLE = {
    "seed": "every point runs with the configuration's seed (common random numbers); "
            "raise 'realizations' for more independent samples",
    "execution": "the [execution] table never changes a result; pass workers= or scheduler= instead",
    # Refused here, once and by its key, rather than as two points that cannot be stacked (issue 37).
    "realizations": "the points are stacked along one dimension of independent samples, which has one length; "
                    "set it once in the configuration",
}


# ---------------------------------------------------------------------------
# parsing --set


def parse_set(text: str) -> tuple[str, list[Any]]:
    """Parse one ``KEY=V1,V2,...`` assignment of ``slidernet sweep --set``.

    Each value is read as a TOML value (integers, floats, booleans, quoted
    strings, arrays such as ``[4, 4]``, inline tables); a value that is not
    TOML is read as a Python float if it is one (``.5``), else as a bare
    string (``chain``). Commas inside brackets, braces or quotes do not
    split values.

    Parameters
    ----------
    text : str
        ``KEY=V1,V2,...``; KEY is a dotted configuration key.

    Returns
    -------
    key : str
        The dotted key.
    values : list
        The values, in the order given.

    Raises
    ------
    ConfigError
        Without ``=``, with an empty key or value, a malformed key or value,
        or a value given twice.

    Examples
    --------
    >>> parse_set("driver.sigma_theta=1e-7,3e-7")
    ('driver.sigma_theta', [1e-07, 3e-07])
    >>> parse_set("network.shape=[2, 2],[4, 4]")
    ('network.shape', [[2, 2], [4, 4]])
    >>> parse_set("network.kind=chain,two_slider")
    ('network.kind', ['chain', 'two_slider'])
    """
    key, sep, rhs = text.partition("=")
    key = key.strip()
    if not sep:
        raise ConfigError(f"A sweep assignment reads KEY=V1,V2,...; {text!r} has no '='.")
    _check_key(key)
    items = _split_values(rhs, text)
    values = []
    for k, item in enumerate(items, start=1):
        if not item:
            raise ConfigError(f"The sweep assignment {text!r} has an empty value (value {k}).")
        values.append(_parse_value(item, text))
    _check_distinct(key, values)
    return key, values


def parse_grid(texts: Sequence[str]) -> dict[str, list[Any]]:
    """Parse several ``--set`` assignments into a grid for :func:`sweep`.

    Raises
    ------
    ConfigError
        If an assignment is malformed (see :func:`parse_set`) or a key is
        given twice.

    Examples
    --------
    >>> parse_grid(["driver.sigma_theta=1e-7,1e-6", "friction.mu_d=0.4,0.5"])
    {'driver.sigma_theta': [1e-07, 1e-06], 'friction.mu_d': [0.4, 0.5]}
    """
    grid: dict[str, list[Any]] = {}
    for text in texts:
        key, values = parse_set(text)
        if key in grid:
            raise ConfigError(f"The sweep key {key!r} is given twice; give all its values in one "
                              f"assignment: {key}=V1,V2,...")
        grid[key] = values
    return grid


def _split_values(rhs: str, text: str) -> list[str]:
    """The comma-separated items of ``rhs``, stripped; commas in brackets, braces or quotes kept."""
    items, depth, quote, start = [], 0, "", 0
    for i, ch in enumerate(rhs):
        if quote:
            if ch == quote:
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            items.append(rhs[start:i].strip())
            start = i + 1
    if quote or depth:
        raise ConfigError(f"The sweep assignment {text!r} has an unclosed quote or bracket.")
    items.append(rhs[start:].strip())
    return items


def _parse_value(item: str, text: str) -> Any:
    try:
        parsed = tomllib.loads(f"v = {item}")
    except tomllib.TOMLDecodeError:
        parsed = None
    if parsed is not None and list(parsed) == ["v"]:
        return parsed["v"]
    if item[0] in "\"'[{":
        raise ConfigError(f"The sweep assignment {text!r}: {item!r} is not a valid TOML value.")
    try:
        return float(item)
    except ValueError:
        return item


def _check_key(key: str) -> None:
    if not key:
        raise ConfigError("A sweep key is empty; it is a dotted configuration key such as 'driver.sigma_theta'.")
    if not _KEY.fullmatch(key):
        raise ConfigError(f"The sweep key {key!r} is not a dotted configuration key such as "
                          f"'driver.sigma_theta'.")
    head = key.split(".")[0]
    if head in _UNSWEEPABLE:
        raise ConfigError(f"The sweep key {key!r} cannot be swept: {_UNSWEEPABLE[head]}.")


def _check_distinct(key: str, values: Sequence[Any]) -> None:
    if not values:
        raise ConfigError(f"The sweep key {key!r} has no values.")
    for k, v in enumerate(values):
        # ==, so 1 and 1.0 (one value for pydantic) are refused too.
        if v in values[:k]:
            raise ConfigError(f"The sweep key {key!r} lists the value {v!r} twice.")


# ---------------------------------------------------------------------------
# the sweep


def sweep(
    config: Config | Mapping[str, Any] | str | Path,
    grid: Mapping[str, Sequence[Any]],
    *,
    progress: bool | float | None = False,
    on_realization: Callable[[int, int], None] | None = None,
    out: str | Path | None = None,
    resume: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    overwrite: bool = False,
    scheduler_timeout: float | None = None,
) -> xr.Dataset | xr.DataTree:
    """Run ``config`` at every point of the product ``grid`` and return one result.

    See the module docstring for the rules on seeds, dimension names,
    recorded times, layout, absent and per-node variables.

    Parameters
    ----------
    config : Config, dict or path
        The base configuration (docs/model.md section 5); a path is read as TOML
        (files it names are found next to it). It need not be valid by
        itself, but every point must be.
    grid : mapping of str to sequence
        Dotted key (``"driver.sigma_theta"``) -> the values it takes, in
        order. A value replaces the key's whole value; missing tables are
        created.
    progress : bool, float or None
        Progress over the realizations of every point, as in
        :func:`slidernet.run` (True or None: a bar on a terminal, a line
        every 30 s elsewhere).
    on_realization : callable, optional
        Called as ``on_realization(i, r)`` once realization r of point i is
        done, or found done on resume (i: the point's index in C order, as
        in ``out/points/<i>``). Points come in order; the realizations of a
        point, in the order they finish.
    out : str or Path, optional
        Output folder: ``out/sweep.json``, point i in ``out/points/<i>/``,
        the result written atomically to ``out/result.nc``. A folder that
        holds a sweep is refused unless ``resume`` or ``overwrite``; one
        that holds a run or a paper reproduction, whatever the flags. The
        sweep holds the folder's lock (``out/.slidernet.lock``) from before
        it writes anything until it ends, and each point its point's.
    resume : bool
        Continue the killed sweep in ``out``, point by point (same
        configuration and grid; the seed stored there).
    workers, scheduler, scheduler_timeout
        Passed to :func:`slidernet.run` for every point (where the
        realizations run; never changes a result).
    overwrite : bool
        Replace the sweep in ``out`` (finished or not) with this one.

    Returns
    -------
    xarray.Dataset or xarray.DataTree
        A Dataset where every point's network has the same number of
        nodes: the points' variables with the sweep dimensions in front,
        e.g. ``n`` (sigma_theta, realization, t) and ``r_mean``
        (sigma_theta,); attributes ``config`` (the base configuration as
        JSON, seed resolved), ``sweep`` (the grid as JSON), ``configs``
        (JSON list of every point's resolved configuration, in C order),
        ``slidernet_version``, ``slidernet_code``, ``seed``, ``kernel`` and
        ``execution`` (the runner's, of the last point). A DataTree where the numbers of
        nodes differ: that dataset without the per-node variables at its
        root, with the coordinate ``sweep_point``; point i's per-node
        variables, (realization, node), in its child ``point_<i>``.

    Raises
    ------
    ConfigError
        Before any work, naming the point and its keys, if a point's
        configuration is invalid or the points cannot be stacked.
    CheckpointError
        If ``out`` holds another sweep, or (on resume) none, or a sweep of
        another version or code of slidernet.
    OutputError
        If ``out`` is not a folder, or holds a run or a paper reproduction.
    FolderInUseError
        If another command works in ``out`` (it holds the folder's lock).
    RunInterrupted
        On Ctrl-C or SIGTERM, once the work done is saved (with ``out``);
        its message says how to resume.

    Examples
    --------
    >>> base = {"seed": 1, "realizations": 2, "steps": 50,
    ...         "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...         "friction": {"mu_d": 0.5,
    ...                      "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...         "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}
    >>> ds = sweep(base, {"driver.sigma_theta": [1e-7, 1e-6]})
    >>> ds["n"].dims, ds["r_mean"].dims
    (('sigma_theta', 'realization', 't'), ('sigma_theta',))
    >>> ds["sigma_theta"].values.tolist()
    [1e-07, 1e-06]
    >>> bool((ds["n"].sel(sigma_theta=1e-6) >= ds["n"].sel(sigma_theta=1e-7)).all())
    True

    Chains of 2, 4 and 8 sliders (the first runs on the pair kernel, which
    records no per-node variable):

    >>> chains = {**base, "network": {"kind": "chain", "n": 2, "Ntilde": 1e-7}}
    >>> tree = sweep(chains, {"network.n": [2, 4, 8]})
    >>> tree["n"].dims, list(tree.children)
    (('network.n', 'realization', 't'), ['point_0', 'point_1', 'point_2'])
    >>> tree["point_2"]["node_slips"].dims, tree["point_2"].sizes["node"]
    (('realization', 'node'), 8)
    >>> bool(tree["mu_min"].sel({"network.n": 2}).isnull().all())
    True
    """
    check_progress(progress, "sweep")
    grid = _checked_grid(grid)
    base = _base_dict(config)
    options = {"progress": progress, "on_realization": on_realization, "resume": resume, "workers": workers,
               "scheduler": scheduler, "overwrite": overwrite, "scheduler_timeout": scheduler_timeout}
    if out is None:
        return _sweep(base, grid, None, **options)
    # One process at a time in the folder, whatever it runs: a second sweep (or --overwrite) must not touch a
    # sweep still going, nor a run write its result.nc there; and a sweep keeps to a sweep's folders.
    with locked_folder(Path(out), "sweep"):
        return _sweep(base, grid, Path(out), **options)


def _sweep(base: dict[str, Any], grid: dict[str, list[Any]], folder: Path | None, *,
           progress: bool | float | None,
           on_realization: Callable[[int, int], None] | None, resume: bool, workers: int | None,
           scheduler: str | None, overwrite: bool, scheduler_timeout: float | None) -> xr.Dataset | xr.DataTree:
    """:func:`sweep` of a checked grid, in ``folder`` (whose lock the caller holds) or in memory."""
    identity = _identity(base, grid)
    seed = base.get("seed")
    keys = list(grid)
    shape = tuple(len(v) for v in grid.values())
    points = [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*grid.values())]
    # Every point's size before any file is touched (each point checks it again as it starts, with its
    # workers, and then its precision and time, which need its scene); the seed does not change a size.
    for i, assignment in enumerate(points):
        try:
            budget.check_memory(budget.memory_estimate(_point_config(base, assignment, i),
                                                       streamed=folder is not None))
        except SizeError as exc:
            raise SizeError(f"Sweep point {i} ({_describe(assignment)}): {exc}") from None
    if folder is not None:
        if overwrite and not resume:
            _clear_folder(folder)
        stored_seed = _check_folder(folder, identity, resume)
        seed = stored_seed if stored_seed is not None else seed
    if seed is None:
        # As runner.resolve_seed, once for the whole sweep: every point shares it.
        seed = int(np.random.SeedSequence().entropy)
    base = {**base, "seed": seed}
    cfgs = [_point_config(base, assignment, i) for i, assignment in enumerate(points)]
    t_common, n_nodes = _check_layout(cfgs, points)

    if folder is not None and not resume:
        with atomic_output(folder / _SWEEP_JSON) as tmp:
            tmp.write_text(json.dumps({**identity, "seed": seed}, indent=1))
    execution = {k: v for k, v in (("workers", workers), ("scheduler", scheduler),
                                   ("scheduler_timeout", scheduler_timeout)) if v is not None}
    R = cfgs[0].realizations
    bar = Progress(len(cfgs) * R, progress, "sweep realizations")
    results = []
    try:
        for i, cfg in enumerate(cfgs):
            bar.set_postfix_str(_describe(points[i]))
            done = _counter(bar, on_realization, i)
            where = None if folder is None else folder / "points" / str(i)
            results.append(_run_point(cfg, where, resume, done, execution))
    except KeyboardInterrupt as exc:
        signum = getattr(exc, "signum", signal.SIGINT)
        if folder is None:
            raise RunInterrupted(f"interrupted by {signal.Signals(signum).name}; nothing was saved (sweep "
                                 "with an output directory to keep the work of an interrupted sweep).",
                                 signum) from None
        raise RunInterrupted(
            f"interrupted by {signal.Signals(signum).name}: {len(results)} of {len(cfgs)} sweep points are done "
            f"in {str(folder / 'points')!r}, and the work of point {len(results)} is saved; continue with "
            f"--resume on the same command, e.g. "
            f"`slidernet sweep CONFIG --set ... --out {str(folder)!r} --resume`.",
            signum,
        ) from None
    finally:
        bar.close()

    split_nodes = len(set(n_nodes)) > 1
    ds, groups = _combine(results, keys, grid, shape, t_common, split_nodes)
    kernels = [r.attrs["kernel"] for r in results]
    ds.attrs = {
        "config": json.dumps(base, sort_keys=True),
        "sweep": json.dumps(grid),
        "configs": json.dumps([json.loads(r.attrs["config"]) for r in results]),
        "slidernet_version": __version__,
        "slidernet_code": code_digest(),
        "seed": str(seed),
        "kernel": ", ".join(dict.fromkeys(kernels)),
        "Conventions": "CF-1.8",
        "title": "slidernet sweep result",
    }
    if len(set(kernels)) > 1:
        ds.attrs["kernels"] = json.dumps(kernels)
    tilt_at = [r.attrs.get("mu_eff_at") for r in results]
    if any(tilt_at):
        # mu_eff_at = "auto" may resolve differently from point to point (the pair against a network).
        ds.attrs["mu_eff_at"] = ", ".join(dict.fromkeys(a for a in tilt_at if a))
        ds.attrs["mu_eff_estimator"] = "; ".join(dict.fromkeys(r.attrs["mu_eff_estimator"] for r in results
                                                               if "mu_eff_estimator" in r.attrs))
        if len(set(tilt_at)) > 1:
            ds.attrs["mu_eff_at_points"] = json.dumps(tilt_at)
    if "execution" in results[-1].attrs:
        ds.attrs["execution"] = results[-1].attrs["execution"]
    result: xr.Dataset | xr.DataTree = ds
    if split_nodes:
        for i, group in enumerate(groups):
            group.attrs = {"sweep_point": i, "sweep_assignment": json.dumps(points[i]),
                           "config": results[i].attrs["config"], "kernel": kernels[i],
                           **({"mu_eff_at": tilt_at[i]} if tilt_at[i] else {})}
        result = xr.DataTree.from_dict({"/": ds, **{f"point_{i}": g for i, g in enumerate(groups)}})
    if folder is not None:
        write_netcdf(result, folder / "result.nc")
    return result


_SWEEP_JSON = "sweep.json"


def _identity(base: dict[str, Any], grid: dict[str, list[Any]]) -> dict[str, Any]:
    """What a sweep folder must match to be resumed (JSON-normalized: tuples are lists)."""
    return json.loads(json.dumps({"config": base, "sweep": grid, "slidernet_version": __version__,
                                  "slidernet_code": code_digest()}))


def _clear_folder(folder: Path) -> None:
    """Remove what a sweep writes in ``folder`` (``overwrite``): its identity, points and result."""
    for name in (_SWEEP_JSON, "result.nc"):
        (folder / name).unlink(missing_ok=True)
    shutil.rmtree(folder / "points", ignore_errors=True)


def _check_folder(folder: Path, identity: dict[str, Any], resume: bool) -> int | None:
    """Refuse a folder that holds another sweep (or none, on resume); return the stored seed on resume."""
    path = folder / _SWEEP_JSON
    if not resume:
        if path.exists() and (folder / "result.nc").exists():
            raise OutputError(f"{str(folder)!r} holds a finished sweep; it is not replaced silently. Replace it "
                              "with --overwrite, or use another output directory.")
        if path.exists():
            raise CheckpointError(f"{str(folder)!r} holds an interrupted sweep. Continue it with --resume, "
                                  "replace it with --overwrite, or use another output directory.")
        return None
    if not path.exists():
        raise CheckpointError(f"Nothing to resume in {str(folder)!r}: it has no {_SWEEP_JSON}.")
    stored = read_identity_file(path, {"config": dict, "sweep": dict, "slidernet_version": str, "seed": int},
                                "a sweep")
    for what, name in (("config", "base configuration"), ("sweep", "grid"),
                       ("slidernet_version", "slidernet version"),
                       ("slidernet_code", "code of slidernet (the digest of its sources)")):
        if stored.get(what) != identity[what]:
            raise CheckpointError(
                f"Cannot resume: the {name} differs from that of the sweep in {str(folder)!r} "
                f"({json.dumps(stored.get(what))} there, {json.dumps(identity[what])} now). Resume with the "
                f"same configuration and grid, or use another output directory.")
    return int(stored["seed"])


def _run_point(cfg: Config, where: Path | None, resume: bool, done: Callable[[int], None],
               execution: dict[str, Any]) -> xr.Dataset:
    """One point: a plain run, or its run in ``where`` (resumed, or read back if it has finished)."""
    if where is None:
        return runner.run(cfg, progress=False, on_realization=done, **execution)
    return runner.run_in(cfg, where, resume=resume, on_realization=done, **execution)


def _counter(bar: Progress, on_realization: Callable[[int, int], None] | None, i: int) -> Callable[[int], None]:
    def done(r: int) -> None:
        bar.update(1)
        if on_realization is not None:
            on_realization(i, r)
    return done


def _plain(value: Any) -> Any:
    """``value`` as plain JSON-like Python: dicts, lists, str, int, float, bool, None."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    return value


def _checked_grid(grid: Mapping[str, Sequence[Any]]) -> dict[str, list[Any]]:
    if not isinstance(grid, Mapping) or not grid:
        raise ConfigError("A sweep needs at least one key with its values, e.g. "
                          "{'driver.sigma_theta': [1e-7, 1e-6]}.")
    checked: dict[str, list[Any]] = {}
    for key, values in grid.items():
        _check_key(key)
        if isinstance(values, (str, bytes, Mapping)) or not isinstance(values, (Sequence, np.ndarray)):
            raise ConfigError(f"The sweep key {key!r} must map to a sequence of values; got {values!r}.")
        values = [_plain(v) for v in values]
        _check_distinct(key, values)
        checked[key] = values
    for a, b in itertools.permutations(checked, 2):
        if b.startswith(a + "."):
            raise ConfigError(f"The sweep keys {a!r} and {b!r} overlap: the first replaces the table of "
                              f"the second.")
    return checked


def _base_dict(config: Config | Mapping[str, Any] | str | Path) -> dict[str, Any]:
    """The base configuration as a plain dict, as the user wrote it (defaults not filled in)."""
    if isinstance(config, Config):
        return _plain(config.model_dump(mode="json", exclude_unset=True))
    if isinstance(config, Mapping):
        return _plain(copy.deepcopy(dict(config)))
    if isinstance(config, (str, Path)):
        raw = read_toml(config)  # the base need not be valid, so it is read, not loaded
        return _plain(raw)
    raise ConfigError(f"A configuration must be a dict, a Config or a path; got {type(config).__name__}.")


def _describe(assignment: Mapping[str, Any]) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in assignment.items())


def _point_config(base: Mapping[str, Any], assignment: Mapping[str, Any], i: int) -> Config:
    data = copy.deepcopy(dict(base))
    for key, value in assignment.items():
        *parents, last = key.split(".")
        table = data
        for depth, part in enumerate(parents):
            table = table.setdefault(part, {})
            if not isinstance(table, dict):
                where = ".".join(parents[:depth + 1])
                raise ConfigError(f"Sweep point {i} ({_describe(assignment)}): the sweep key {key!r} "
                                  f"needs {where!r} to be a table; it is {table!r}.")
        table[last] = copy.deepcopy(value)
    try:
        return load_config(data)
    except ConfigError as exc:
        raise ConfigError(f"Sweep point {i} ({_describe(assignment)}): {exc}") from None


def _check_layout(cfgs: list[Config], points: list[dict[str, Any]]) -> tuple[np.ndarray, list[int]]:
    """Refuse points that cannot be stacked; return the shared recorded times and each point's number of nodes."""
    def refuse(i: int, j: int, why: str) -> ConfigError:
        return ConfigError(f"Sweep points {i} ({_describe(points[i])}) and {j} ({_describe(points[j])}) "
                           f"cannot be stacked: {why}")

    times = [record_times(c.steps, c.record, c.log_points_per_decade) for c in cfgs]
    shortest = min(range(len(cfgs)), key=lambda i: cfgs[i].steps)
    t_common = times[shortest]
    scenes: dict[str, tuple[str, int, str | None]] = {}
    layout: list[tuple[str, int, str | None]] = []
    for i, c in enumerate(cfgs):
        for name, what in (("events", "the event catalogue, whose length differs from run to run"),
                           ("creep", "creep events and cycles, whose numbers differ from run to run")):
            if name in c.observables:
                raise ConfigError(f"Sweep point {i} ({_describe(points[i])}): the {name!r} observable ({what}) "
                                  f"cannot be swept; run the points one by one with slidernet.run.")
        if not np.array_equal(times[i][:t_common.size], t_common):
            raise refuse(shortest, i, f"the points are stacked along t, so the recorded times of point {i} must "
                         f"begin with those of point {shortest} (the fewest steps); to sweep 'steps', record "
                         f"'all', an explicit list of times that holds every smaller 'steps', or 'log' with "
                         f"'steps' whole decades apart")
        if set(c.observables) != set(cfgs[0].observables):
            raise refuse(0, i, f"observables {sorted(cfgs[0].observables)} and {sorted(c.observables)}")
        # What decides the kernel, the nodes and the tilt test; the scene is built once per distinct one.
        what = json.dumps(c.model_dump(mode="json", include={"network", "solver", "observables", "mu_eff_at"}),
                          sort_keys=True)
        if what not in scenes:
            try:
                scene = Scene.from_config(c)
            except ConfigError as exc:
                raise ConfigError(f"Sweep point {i} ({_describe(points[i])}): {exc}") from None
            scenes[what] = (scene.kernel, scene.network.n_nodes, scene.tilt_at)
        layout.append(scenes[what])
        # Two tilt tests are two estimators: one variable mu_eff must hold one of them.
        if "mu_eff" in c.observables and layout[i][2] != layout[0][2]:
            raise refuse(0, i, f"'mu_eff' is measured at the {layout[0][2]} in point 0 (mu_eff_at = "
                         f"{layout[0][2]!r}) and at the {layout[i][2]} in point {i} (mu_eff_at = "
                         f"{layout[i][2]!r}), two different estimators; set mu_eff_at = \"records\" (the network "
                         f"tilt test, which every scene runs) in the configuration")
    return t_common, [n_nodes for _, n_nodes, _ in layout]


def _dim_names(keys: list[str], taken: set[str]) -> list[str]:
    last = [k.rsplit(".", 1)[-1] for k in keys]
    return [name if last.count(name) == 1 and name not in taken else key for key, name in zip(keys, last,
                                                                                                strict=True)]


def _coordinate(values: list[Any]) -> np.ndarray:
    """The values as a netCDF-friendly 1D array: numbers, booleans, strings, else JSON text."""
    if all(isinstance(v, bool) for v in values):
        return np.array(values, dtype=bool)
    if all(isinstance(v, Number) and not isinstance(v, bool) for v in values):
        return np.array(values)
    if all(isinstance(v, str) for v in values):
        return np.array(values, dtype=str)
    return np.array([json.dumps(v, sort_keys=True) for v in values], dtype=str)


def _common_attrs(attrs: list[dict[str, Any]]) -> dict[str, Any]:
    """The attributes of a variable that every point gives alike: one that differs between points (the
    injection's ``inject_c`` where ``tilt.inject.c`` is swept) is each point's own, in its configuration."""
    return {key: value for key, value in attrs[0].items()
            if all(key in a and np.array_equal(a[key], value) for a in attrs[1:])}


def _union(names: list[list[str]]) -> list[str]:
    """The names of every list, each once, in the order of first appearance."""
    return list(dict.fromkeys(n for group in names for n in group))


def _combine(results: list[xr.Dataset], keys: list[str], grid: Mapping[str, list[Any]], shape: tuple[int, ...],
             t_common: np.ndarray, split_nodes: bool) -> tuple[xr.Dataset, list[xr.Dataset]]:
    """Stack the points' datasets (C order) along the sweep dimensions.

    Returns the stacked dataset and, with ``split_nodes``, one dataset per
    point of its per-node variables, which the stacked one then leaves out
    (else an empty list).
    """
    results = [r.isel(t=slice(0, t_common.size)) if "t" in r.dims else r for r in results]
    # Each point's avalanche histogram ends at its own largest avalanche: empty bins up to the widest.
    results = align_avalanche_sizes(results)
    # Only whether a point has a variable may differ (_check_layout sees to the rest): a variable's dims or a
    # coordinate that differ between points is a bug, never padded.
    names = _union([[str(n) for n in r.data_vars] for r in results])
    for name in names:
        found = {r[name].dims for r in results if name in r.data_vars}
        if len(found) > 1:
            raise ConfigError(f"The sweep points give the variable {name!r} with dims {sorted(found)}; they "
                              f"cannot be stacked.")
    coords: dict[str, xr.DataArray] = {}
    for i, r in enumerate(results):
        for name, coord in r.coords.items():
            if name not in coords:
                coords[str(name)] = coord
            elif not coord.equals(coords[str(name)]):
                raise ConfigError(f"Sweep point {i} gave the coordinate {name!r} unlike an earlier point's; it "
                                  f"cannot be stacked.")
    per_node = [n for n in names if split_nodes and any(n in r and "node" in r[n].dims for r in results)]
    taken = set().union(*(set(r.variables) | set(r.dims) for r in results))
    dims = _dim_names(keys, taken)
    ds = xr.Dataset(coords={dim: (dim, _coordinate(grid[key]), {"long_name": f"swept configuration value {key!r}",
                                                                "sweep_key": key})
                            for dim, key in zip(dims, keys, strict=True)})
    ds = ds.assign_coords(coords)
    for name in names:
        if name in per_node:
            continue
        have = [r for r in results if name in r.data_vars]
        var = have[0][name]
        if len(have) == len(results):
            data = np.stack([r[name].values for r in results]).reshape(shape + var.shape)
        else:
            # As xarray.concat fills a variable some datasets lack: NaN, in a float array.
            data = np.full(shape + var.shape, np.nan, dtype=np.result_type(var.dtype, np.float64))
            flat = data.reshape((len(results), *var.shape))
            for i, r in enumerate(results):
                if name in r.data_vars:
                    flat[i] = r[name].values
        ds[name] = ((*dims, *var.dims), data, _common_attrs([r[name].attrs for r in have]))
    if not split_nodes:
        return ds, []
    if "sweep_point" not in taken | set(dims):
        ds.coords["sweep_point"] = (dims, np.arange(len(results), dtype=np.int64).reshape(shape), {
            "long_name": "index of the sweep point in C order; its per-node variables are in the group "
                         "point_<index>", "units": "1"})
    return ds, [xr.Dataset({n: r[n].variable for n in per_node if n in r.data_vars}) for r in results]
