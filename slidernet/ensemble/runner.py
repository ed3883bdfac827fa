"""``slidernet.run``: a configuration in, an xarray.Dataset out."""

from __future__ import annotations

import itertools
import json
import signal
import time
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from slidernet._paths import absolute_path
from slidernet._version import __version__, code_digest
from slidernet.analysis.observables import CHUNK, assemble, avalanche_bins
from slidernet.config import SCHEDULER_REQUIREMENT, Config, load_config
from slidernet.config.execution import scheduler_address_problem
from slidernet.config.loading import input_files
from slidernet.ensemble.execution import StopSignal, available_cores, connect, execute, scene_of
from slidernet.ensemble.progress import Progress, check_progress
from slidernet.ensemble.stream import write_result_stream
from slidernet.errors import (
    CheckpointError,
    ConfigError,
    OutputError,
    RunInterrupted,
    SchedulerError,
    SlidAwayWarning,
    SlidernetError,
    WorkerLostError,
    param_error,
)
from slidernet.io import read_result
from slidernet.io.checkpoint import read_arrays
from slidernet.io.netcdf import open_result
from slidernet.io.store import RunStore, changed_code, changed_inputs, file_digest
from slidernet.solver import budget
from slidernet.solver.compile import compile_kernels, terminal_notice


def resolve_seed(cfg: Config) -> Config:
    """A copy of ``cfg`` whose seed is set: fresh OS entropy when it was None."""
    if cfg.seed is not None:
        return cfg
    return _with_seed(cfg, int(np.random.SeedSequence().entropy))


def realization_seeds(seed: int, realizations: int) -> list[np.random.SeedSequence]:
    """``SeedSequence(seed).spawn(R)``: child r drives realization r, whatever the order of work."""
    return np.random.SeedSequence(seed).spawn(realizations)


def input_digests(cfg: Config) -> dict[str, dict[str, str]]:
    """Every file a run of ``cfg`` reads (``config.loading.input_files``): its ``path`` and ``sha256``."""
    return {what: {"path": path, "sha256": file_digest(path)} for what, path in input_files(cfg).items()}


def identity(requested: Config, resolved: Config) -> dict[str, Any]:
    """What a checkpoint must match to be resumed (``io.store.IDENTITY_KEYS``).

    The configuration without its execution table, the seed, the number of
    realizations, the slidernet version and the digest of its sources
    (:func:`slidernet._version.code_digest`), and the SHA-256 of every input
    file (a graph, a temperature series, measured thresholds, plugin files
    and the modules they bring in from outside the environment's
    site-packages).
    """
    config = requested.model_dump(mode="json", exclude={"execution"})
    return {"config": config, "seed": resolved.seed, "realizations": resolved.realizations,
            "slidernet_version": __version__, "slidernet_code": code_digest(), "inputs": input_digests(requested)}


#: What each value of a scene's ``tilt_at`` measures: the ``mu_eff_estimator`` attribute of a result.
MU_EFF_ESTIMATORS = {
    "rearrangements": "the appendix's virtual tilt test of the two sliders, made before every rearrangement "
                      "(and once at t = 0) and pooled over each bin (t_{k-1}, t_k]",
    "records": "the network tilt test (a uniform tilt raised on a copy of the network until it slides as a "
               "whole), made once per realization at each recorded time t",
}


def _attrs(cfg: Config, scene: Any, workers: int, scheduler: str | None,
           inputs: dict[str, dict[str, str]]) -> dict[str, str]:
    attrs = {
        "config": json.dumps(cfg.model_dump(mode="json", exclude={"execution"}), sort_keys=True),
        "inputs": json.dumps(inputs, sort_keys=True),
        "execution": json.dumps({"workers": workers, "scheduler": scheduler}),
        "slidernet_version": __version__,
        "slidernet_code": code_digest(),
        "seed": str(cfg.seed),
        "kernel": scene.kernel,
        "Conventions": "CF-1.8",
        "title": "slidernet result",
    }
    if scene.tilt_at is not None:
        # mu_eff_at = "auto" resolves per network: the result says which test it holds.
        attrs["mu_eff_at"] = scene.tilt_at
        attrs["mu_eff_estimator"] = mu_eff_estimator(scene)
    return attrs


def mu_eff_estimator(scene: Any) -> str:
    """What a scene's mu_eff measures, in words: :data:`MU_EFF_ESTIMATORS`, said of the dynamic state with
    ``[dynamics]``, or the dynamic tilt test's words with ``[dynamics] tilt_rate``."""
    words = MU_EFF_ESTIMATORS[scene.tilt_at]
    dyn = scene.dynamics
    if dyn is None:
        return words
    if dyn.tilt_rate is None:
        return words + ", on the state of the equations of motion ([dynamics]) as it stands"
    return (f"the dynamic tilt test (a uniform tilt ramped at {dyn.tilt_rate!r} per tau_dyn under the equations "
            "of motion, on a copy of the network, until it slides as a whole), made once per realization at "
            "each recorded time t")


def run(
    config: Config | Mapping[str, Any] | str | Path,
    progress: bool | float | None = False,
    on_realization: Callable[[int], None] | None = None,
    *,
    out: str | Path | None = None,
    resume: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    overwrite: bool = False,
    scheduler_timeout: float | None = None,
) -> xr.Dataset:
    """Simulate an ensemble of realizations and return the result dataset.

    Parameters
    ----------
    config : Config, dict or path
        The run configuration (docs/model.md section 5); a path is read as TOML.
    progress : bool, float or None
        Progress over realizations, all workers together: False nothing;
        True or None a bar on a terminal and a plain line on stderr every
        30 s elsewhere (a batch job's log: realizations done, slips per
        second, time left); a number of seconds, lines at that interval.
        Bar or lines, a run that falls twice behind the slow-run estimate
        says so once (:mod:`slidernet.ensemble.progress`).
    on_realization : callable, optional
        Called with the index of each realization once it is done (for
        callers that drive their own progress display).
    out : path, optional
        Output directory: the result goes to ``out/result.nc`` (written
        chunk by chunk, so memory does not grow with the number of
        realizations) and the run checkpoints its work under
        ``out/checkpoint/`` every ``execution.checkpoint_every`` seconds and
        on Ctrl-C. The returned dataset is then opened lazily from the file.
        A relative path is relative to the current directory of this
        process, never to a worker's. The run holds the folder's lock
        (``out/.slidernet.lock``) from before it writes anything until it
        ends, and never writes into a folder that holds a sweep or a paper
        reproduction.
    resume : bool
        Continue the interrupted run in ``out`` (same configuration; the
        execution table may differ). The result is the bits of an
        uninterrupted run.
    overwrite : bool
        Replace a finished ``out/result.nc``. Without it such a folder is
        refused before any work.
    scheduler_timeout : float, optional
        Seconds to wait for the Dask scheduler; overrides
        ``execution.scheduler_timeout`` (default 10).
    workers : int, optional
        Local worker processes; overrides ``execution.workers`` (default:
        every core).
    scheduler : str, optional
        Dask scheduler address (``"tcp://host:port"``); overrides
        ``execution.scheduler``.

    Returns
    -------
    xarray.Dataset
        Variables ``n``, ``mu_max``, ``x_G`` (realization, t) and ``mu_eff``
        (t) as requested, with ensemble means and standard errors; attributes
        ``config`` (the resolved configuration as JSON), ``slidernet_version``,
        ``slidernet_code`` (the digest of slidernet's sources), ``inputs``
        (every input file's path and SHA-256), ``seed``, ``kernel`` and
        ``execution``; with ``mu_eff``, also
        ``mu_eff_at`` (``"rearrangements"`` or ``"records"``, what
        ``mu_eff_at = "auto"`` resolved to) and ``mu_eff_estimator`` (the
        test in words).

    Raises
    ------
    SizeError
        Before any work, if the run's estimated memory exceeds the machine's
        (:mod:`slidernet.solver.budget`).
    PrecisionError
        Before any work, if float64 cannot resolve the scene's slips.
    RunInterrupted
        On Ctrl-C (SIGINT) or SIGTERM: the running realizations stop at
        their next clean point (those still running after
        ``execution.stop_timeout`` seconds are ended at their last save),
        and with ``out`` the finished ones and the state of the running ones
        are saved; its message says how to resume and its ``signum`` which
        signal stopped the run. A plugin's own KeyboardInterrupt is SIGINT.
    PluginError
        If a plugin's code raises (or calls ``sys.exit``), naming the plugin
        and its line; or if it returns values that break the contract. With
        ``out``, the message says what was saved.
    OutputError
        If ``out`` cannot be used as a folder, holds a sweep or a paper
        reproduction, or holds a finished result and ``overwrite`` is not
        set.
    FolderInUseError
        If another command works in ``out`` (it holds the folder's lock).
    SchedulerError
        If the Dask scheduler does not answer within
        ``execution.scheduler_timeout`` seconds, or goes away during the run
        (the message then says what was saved and how to resume).

    Warns
    -----
    SlowRunWarning
        Once, before any work, if the run would take more than an hour at
        the measured rates of the kernels (:mod:`slidernet.solver.budget`).

    Examples
    --------
    >>> ds = run({"seed": 1, "realizations": 2, "steps": 100,
    ...           "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...           "friction": {"mu_d": 0.5,
    ...                        "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
    >>> ds["n"].dims
    ('realization', 't')
    >>> bool((ds["mu_max"].diff("t") >= 0).all())
    True
    """
    check_progress(progress, "run")
    requested = load_config(config)
    cfg = resolve_seed(requested)
    ex = cfg.execution
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise param_error("workers", "run", "an integer >= 1", workers)
    problem = None if scheduler is None else scheduler_address_problem(scheduler)
    if problem is not None:
        refused = str(param_error("scheduler", "run", SCHEDULER_REQUIREMENT, scheduler))
        raise ConfigError(f"{refused[:-1]}: {problem}.")
    if scheduler_timeout is not None and (isinstance(scheduler_timeout, bool)
                                          or not isinstance(scheduler_timeout, (int, float))
                                          or not scheduler_timeout > 0):
        raise param_error("scheduler_timeout", "run", "a number of seconds > 0", scheduler_timeout)
    workers = workers or ex.workers or available_cores()
    scheduler = scheduler or ex.scheduler
    timeout = float(scheduler_timeout or ex.scheduler_timeout)
    R = cfg.realizations
    # Before the network is built (a network that cannot fit is refused before it is tried), then with
    # the scene: float64's precision and the time the run would take. A Dask worker runs one realization
    # at a time here, like one local worker.
    budget.check_memory(budget.memory_estimate(cfg, 1 if scheduler else workers, streamed=out is not None))
    config_json = json.dumps(cfg.model_dump(mode="json"), sort_keys=True)
    scene = scene_of(config_json)  # validates the scene before any file is touched; forked workers inherit it
    estimate = budget.check_run(cfg, scene, workers)
    run_identity = identity(requested, cfg)
    store = None
    if out is not None:
        # Absolute here, in this process: the workers' partial files are named from it, and a Dask worker
        # starts in its own working folder.
        out = Path(absolute_path(out, Path.cwd()))
        store = RunStore(out, run_identity, resume, overwrite=overwrite)
        seed = store.open()  # holds the folder's lock until store.close()
        if seed != cfg.seed:  # a resumed run whose config left the seed to fresh entropy
            cfg = _with_seed(cfg, seed)
            config_json = json.dumps(cfg.model_dump(mode="json"), sort_keys=True)
    try:
        done = store.done() if store is not None else {}
        records = _execute(cfg, config_json, store, done, progress, on_realization, workers, scheduler, timeout,
                           estimate)
        attrs = _attrs(cfg, scene, workers, scheduler, run_identity["inputs"])
        if store is None:
            ds = assemble((records.pop(r) for r in range(R)), scene.out_steps, list(cfg.observables), attrs)
        else:
            records = store.records(R)
            first = next(records)
            # The avalanche histogram's bins end where every realization's do: known before any is written.
            bins = _size_bins(store, R) if "avalanche_count" in first else None
            path = write_result_stream(itertools.chain([first], records), out / "result.nc", scene.out_steps, R,
                                       list(cfg.observables), attrs, bins)
            store.remove()
            ds = open_result(path)
    except RunInterrupted:
        raise
    except BaseException as exc:
        if store is None:
            raise
        if isinstance(exc, Exception):
            try:
                store.flush()  # the realizations that did finish are kept
            except OutputError:
                pass  # the disk refuses: the error that stopped the run says why
        if isinstance(exc, WorkerLostError):
            # The other workers were killed, and have ended: a save one of them was writing is only a
            # temporary file now, which would stay in the folder until the resume.
            store.remove_temporaries()
        store.abandon()  # a run that failed before saving anything leaves the folder as it found it
        if isinstance(exc, SlidernetError) and store.dir.exists():
            # What the failed run saved stays, and the line says where. A lost worker or scheduler, or a
            # full disk, is outside the run: --resume continues it. Any other error (a plugin's, an
            # avalanche past solver.max_avalanche) recurs on the same configuration, which a fix changes.
            outside = isinstance(exc, (WorkerLostError, OutputError, SchedulerError))
            raise type(exc)(f"{exc} {_saved_work(store, R, resumable=outside)}") from None
        raise
    finally:
        if store is not None:
            store.close()
    warn_if_all_slid_away(ds)
    return ds


def _size_bins(store: RunStore, R: int) -> int:
    """:func:`~slidernet.analysis.observables.avalanche_bins` over the store's R realizations, from their
    ``avalanche_count`` alone (the whole blocks, every checksum checked, are read as the result is written)."""
    rows: dict[Path, list[int]] = {}
    for r, (path, row) in sorted(store.done().items()):
        if r < R:
            rows.setdefault(path, []).append(row)
    return max(avalanche_bins(read_arrays(path, ["avalanche_count"])["avalanche_count"][taken])
               for path, taken in rows.items())


def all_slid_away(ds: xr.Dataset) -> str | None:
    """One line saying that every realization of ``ds`` slid away, or None if one did not."""
    if "slid_away_at" not in ds:
        return None
    at = ds["slid_away_at"].values
    if not np.isfinite(at).all():
        return None
    return (f"every realization ({at.size}) slid away, between t = {at.min():.6g} and {at.max():.6g} tau_th: "
            f"the load along x per unit normal load exceeds mu_d; the records after 'slid_away_at' hold the "
            f"state of the slide")


def warn_if_all_slid_away(ds: xr.Dataset) -> None:
    """Warn (:class:`~slidernet.errors.SlidAwayWarning`) if every realization of ``ds`` slid away."""
    line = all_slid_away(ds)
    if line is not None:
        warnings.warn(line[0].upper() + line[1:] + ".", SlidAwayWarning, stacklevel=3)


def _execute(cfg: Config, config_json: str, store: RunStore | None, done: Mapping[int, Any],
             progress: bool | float | None, on_realization: Callable[[int], None] | None, workers: int,
             scheduler: str | None, timeout: float, estimate: float | None = None) -> dict[int, dict]:
    """Run the realizations not ``done``; records kept in memory, or in ``store`` (flushed as they come).

    Ctrl-C and SIGTERM stop the run at a clean point of every running
    realization (see :class:`slidernet.ensemble.execution.StopSignal`): the work is
    saved in ``store`` and :class:`RunInterrupted` says how to resume.
    """
    ex = cfg.execution
    R = cfg.realizations
    pending = [r for r in range(R) if r not in done]
    # A partial file names its run: one of another run is never resumed (io.store.RunStore).
    meta = {} if store is None else {"run": store.digest}

    def args(r: int) -> tuple:
        partial = None if store is None else str(store.partial(r))
        return config_json, cfg.seed, r, partial, ex.checkpoint_every, meta

    # The scheduler first: one that does not answer is reported after the timeout it states, not after the
    # kernels are compiled too.
    client = connect(scheduler, timeout) if scheduler is not None and pending else None
    if pending:
        # In this process, before any worker starts: forked workers inherit the compiled kernels, and
        # the others load them from the cache instead of each compiling them again.
        try:
            compile_kernels(cfg, notice=terminal_notice(progress))
        except BaseException:
            if client is not None:
                client.close()
            raise
    records: dict[int, dict] = {}
    last_flush = time.monotonic()
    with StopSignal(ex.stop_timeout) as stop:
        results = execute(pending, args, workers, scheduler, stop=stop, scheduler_timeout=timeout, client=client)
        # The estimate is of the whole run: its share is the pending realizations'. A Dask worker runs one
        # realization at a time.
        bar = Progress(R, progress, "realizations", initial=R - len(pending),
                       estimate=None if estimate is None else estimate * len(pending) / R,
                       parallel=min(len(pending), 1 if scheduler else workers) or 1)
        try:
            try:
                for r, rec in results:
                    slips = int(rec["n"][-1]) if len(rec.get("n", ())) else 0  # the last record holds them all
                    if store is None:
                        records[r] = rec
                    else:
                        store.add(r, rec)
                        if time.monotonic() - last_flush >= ex.checkpoint_every or store.held >= CHUNK:
                            store.flush()
                            last_flush = time.monotonic()
                    bar.update(1, slips=slips)
                    if on_realization is not None:
                        on_realization(r)
            finally:
                bar.close()
                results.close()  # running realizations stop and save (within the grace) before the pool goes
        except KeyboardInterrupt:
            # A signal's KeyboardInterrupt (a second one, or the grace ran out), a hook's or a plugin's own
            # (a run in this process): the run stops as on Ctrl-C. One raised while the realizations saved
            # lands here too.
            stop.request(signal.SIGINT)
    # Outside the signals' handlers: saving what is finished is not cut by the end of the grace.
    if stop.requested:
        raise _interrupted(store, R, stop)
    if store is not None:
        store.flush()
    return records


def _interrupted(store: RunStore | None, R: int, stop: StopSignal) -> RunInterrupted:
    """Save what is finished; the exception that says what is saved and how to resume."""
    name = signal.Signals(stop.signum).name
    if store is None:
        return RunInterrupted(f"interrupted by {name}; nothing was saved (run with an output directory "
                              "to keep the work of an interrupted run).", stop.signum)
    ended = ""
    if stop.forced:
        # The workers that were ended are gone: a save one of them was writing is only a temporary file now.
        store.remove_temporaries()
        ended = (f" (the realizations still running after execution.stop_timeout = {stop.grace:g} s were ended"
                 if stop.expired else " (stopped at once by a second signal")
        ended += "; they resume from their last save)"
    store.flush()
    return RunInterrupted(f"interrupted by {name}{ended}: {_saved_work(store, R)}", stop.signum)


def _saved_work(store: RunStore, R: int, resumable: bool = True) -> str:
    """What the checkpoint folder holds, and the command that continues the run.

    ``resumable=False``: the run stopped on an error that the same configuration meets again; the line
    says that a fix outside the configuration and its files resumes, and that any other starts again.
    """
    saved = len(store.done(strict=False))
    running = store.partials()
    held = (f"{saved} of {R} realizations are finished"
            + (f" and {running} saved in progress" if running else "") + f" in {str(store.dir)!r}")
    command = f"`slidernet run CONFIG --out {str(store.dir.parent)!r} --resume`"
    if resumable:
        return f"{held}; continue with --resume on the same command, e.g. {command}."
    return (f"{held}: {command} continues them once the cause is fixed outside the configuration and its "
            "files; a changed configuration or plugin file is another run: start it with --overwrite.")


def run_in(config: Config | Mapping[str, Any] | str | Path, out: str | Path, *, resume: bool = False,
           overwrite: bool = False, on_realization: Callable[[int], None] | None = None,
           **execution: Any) -> xr.Dataset:
    """One run kept in its own folder, as a step of a larger job (a sweep point, a paper figure).

    With ``resume``, a finished run (``out/result.nc`` and no checkpoint) is
    read back, after checking that it was computed from this configuration,
    these input files and this code (version and digest of the sources); an
    interrupted one is resumed; a run not yet started starts. Without it the
    run starts, as :func:`run` does.

    Parameters
    ----------
    config : Config, dict or path
        The run's configuration (its seed set).
    out : path
        The run's folder.
    resume, overwrite : bool
        As in :func:`run`.
    on_realization : callable, optional
        Called with each realization's index once it is done (or found done).
    **execution
        ``workers``, ``scheduler``, ``scheduler_timeout`` of :func:`run`.

    Returns
    -------
    xarray.Dataset
        The result, loaded in memory (its file is closed).
    """
    cfg = load_config(config)
    out = Path(out)
    # The store keeps a run's checkpoint folder until its result.nc is written.
    unfinished = (out / "checkpoint").exists()
    if resume and not unfinished and (out / "result.nc").exists():
        ds = read_result(out / "result.nc")
        expected = json.loads(json.dumps(cfg.model_dump(mode="json", exclude={"execution"})))
        if json.loads(ds.attrs["config"]) != expected:
            raise CheckpointError(f"Cannot resume: {str(out / 'result.nc')!r} holds a run of another "
                                  "configuration than this one.")
        code = changed_code(ds.attrs, {"slidernet_version": __version__, "slidernet_code": code_digest()})
        if code:
            raise CheckpointError(f"Cannot resume: {str(out / 'result.nc')!r} {code}; it would not be "
                                  "bit-identical to what this code computes. Start again with --overwrite.")
        changed = changed_inputs(json.loads(ds.attrs.get("inputs", "{}")), input_digests(cfg))
        if changed:
            raise CheckpointError(f"Cannot resume: {str(out / 'result.nc')!r} was computed from other contents of "
                                  f"the input files than they hold now: {changed}. Start again with --overwrite.")
        for r in range(cfg.realizations):
            if on_realization is not None:
                on_realization(r)
        return ds
    ds = run(cfg, progress=False, on_realization=on_realization, out=out, resume=resume and unfinished,
             overwrite=overwrite, **execution)
    ds.load()
    ds.close()
    return ds


def _with_seed(cfg: Config, seed: int) -> Config:
    resolved = cfg.model_copy(update={"seed": seed})
    resolved._distribution = cfg._distribution
    resolved._driver = cfg._driver
    return resolved
