"""Where realizations run: in this process, in local worker processes, or on a Dask cluster.

Each realization is a task: ``run_realization(config_json, seed, r, ...)``
builds (once per process) the scene of the configuration, drives realization
r with child r of the run's seed (``SeedSequence(seed, spawn_key=(r,))``, the
same as ``SeedSequence(seed).spawn(R)[r]``) and returns its records. Nothing
else decides a result, so the backend, the number of workers and the order in
which tasks finish never change the bits.

While it runs, a task with a ``partial`` path saves its realization there
every ``every`` seconds (and on Ctrl-C), so a killed run resumes inside a
long realization rather than at its start.

Backends
--------
- ``workers = 1``: in this process.
- ``workers = N``: a :class:`concurrent.futures.ProcessPoolExecutor` of N
  processes, forked where the platform can (the workers then inherit the
  compiled kernels and plugins registered at run time), spawned elsewhere.
- ``scheduler = "tcp://host:port"``: a :class:`distributed.Client` on that
  scheduler. The workers need slidernet (and any plugin) installed, and the
  files named in the config (and the output directory, for checkpoints inside
  a realization) at the same paths.
"""

from __future__ import annotations

import functools
import json
import multiprocessing
import os
import signal
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from pathlib import Path
from typing import Any

import numpy as np

Record = dict[str, Any]


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS, Windows
        return os.cpu_count() or 1


def realization_seed(seed: int, r: int) -> np.random.SeedSequence:
    """Child ``r`` of ``SeedSequence(seed)``, without spawning the ``r`` before it.

    Examples
    --------
    >>> a = realization_seed(1, 3).generate_state(2)
    >>> b = np.random.SeedSequence(1).spawn(5)[3].generate_state(2)
    >>> bool((a == b).all())
    True
    """
    return np.random.SeedSequence(seed, spawn_key=(r,))


@functools.lru_cache(maxsize=4)
def scene_of(config_json: str):
    """The scene of a configuration, built once per process (a large network is costly to build)."""
    from slidernet.config import load_config
    from slidernet.solver import Scene

    return Scene.from_config(load_config(json.loads(config_json)))


class _DeferredInterrupt:
    """Hold Ctrl-C (SIGINT) until the realization is at a clean point between two steps.

    A KeyboardInterrupt raised inside :meth:`Realization.advance` would leave
    the state between a kernel's return and Python's handling of it (a refill,
    a flushed event chunk): saving that would not resume to the same bits.
    Only the main thread of a process can hold signals; elsewhere (a Dask
    worker thread) this does nothing.
    """

    def __init__(self) -> None:
        self.pending = False
        self._previous = None

    def __enter__(self) -> _DeferredInterrupt:
        try:
            self._previous = signal.signal(signal.SIGINT, self._hold)
        except ValueError:  # not the main thread
            self._previous = None
        return self

    def _hold(self, signum, frame) -> None:
        self.pending = True

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)


def _advance_with_checkpoints(real, partial: Path, every: float, meta: dict[str, Any]) -> None:
    """Advance ``real`` to its end, saving it to ``partial`` every ``every`` seconds and on Ctrl-C."""
    from slidernet.checkpoint import save_realization

    steps = real.scene.steps
    chunk = 1
    # Chunks of at most a tenth of the interval, and half a second: a
    # checkpoint or a Ctrl-C is never served much later than asked, and the
    # Python overhead per chunk stays negligible.
    target = min(0.1 * every, 0.5)
    last = time.monotonic()
    with _DeferredInterrupt() as sigint:
        while real.step < steps:
            t0 = time.monotonic()
            real.advance(min(real.step + chunk, steps))
            took = time.monotonic() - t0
            chunk = max(1, min(2 * chunk, int(chunk * target / took) if took > 0 else 2 * chunk))
            if sigint.pending:
                if real.step < steps:
                    save_realization(real, partial, meta)
                raise KeyboardInterrupt
            if real.step < steps and time.monotonic() - last >= every:
                save_realization(real, partial, meta)
                last = time.monotonic()


def run_realization(config_json: str, seed: int, r: int, partial: str | None = None,
                    every: float = 60.0, meta: dict[str, Any] | None = None) -> Record:
    """Run realization ``r`` of a configuration and return its records (the task of every backend).

    Parameters
    ----------
    config_json : str
        The resolved configuration (seed included), as JSON.
    seed : int
        The run's seed.
    r : int
        Index of the realization.
    partial : str, optional
        Where to save the running realization (and to resume it from, if the
        file exists); None: no checkpoints inside the realization.
    every : float
        Seconds between two saves.
    meta : dict, optional
        What identifies the run, stored in and checked against ``partial``.

    Returns
    -------
    dict
        :meth:`slidernet.solver.Realization.result`.
    """
    from slidernet.solver import Realization

    scene = scene_of(config_json)
    ss = realization_seed(seed, r)
    if partial is None:
        return Realization(scene, ss).advance().result()
    path = Path(partial)
    meta = {**(meta or {}), "realization": r}
    if path.exists():
        from slidernet.checkpoint import load_realization

        real = load_realization(scene, ss, path, expect_meta=meta)
    else:
        real = Realization(scene, ss)
    _advance_with_checkpoints(real, path, every, meta)
    return real.result()


Task = Callable[[int], tuple]  # r -> the arguments of run_realization


def _task(*args: Any) -> tuple[Record, list[tuple[type[Warning], str]]]:
    """:func:`run_realization` in a worker, with the warnings it raised, for the caller to re-raise."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        record = run_realization(*args)
    return record, [(w.category, str(w.message)) for w in caught]


def _reraise(result: tuple[Record, list[tuple[type[Warning], str]]]) -> Record:
    record, caught = result
    for category, message in caught:
        warnings.warn(message, category, stacklevel=2)
    return record


def _in_process(indices: Sequence[int], args: Task) -> Iterator[tuple[int, Record]]:
    for r in indices:
        yield r, run_realization(*args(r))


def _window(workers: int) -> int:
    """Tasks in flight at once: enough to keep every worker busy, few enough to bound memory."""
    return 4 * workers


def _local_pool(indices: Sequence[int], args: Task, workers: int) -> Iterator[tuple[int, Record]]:
    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
    todo = iter(indices)
    with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context(method)) as pool:
        running: dict[Any, int] = {}
        try:
            for r in todo:
                running[pool.submit(_task, *args(r))] = r
                if len(running) >= _window(workers):
                    break
            while running:
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for fut in done:
                    r = running.pop(fut)
                    yield r, _reraise(fut.result())
                    nxt = next(todo, None)
                    if nxt is not None:
                        running[pool.submit(_task, *args(nxt))] = nxt
        except BaseException:
            for fut in running:
                fut.cancel()
            raise


def _dask(indices: Sequence[int], args: Task, scheduler: str) -> Iterator[tuple[int, Record]]:
    from distributed import Client, as_completed

    with Client(scheduler) as client:
        workers = max(1, sum(client.nthreads().values()))
        todo = iter(indices)
        keys: dict[str, int] = {}
        queue = as_completed()
        try:
            for r in todo:
                fut = client.submit(_task, *args(r), pure=False)
                keys[fut.key] = r
                queue.add(fut)
                if len(keys) >= _window(workers):
                    break
            for fut in queue:
                r = keys.pop(fut.key)
                result = _reraise(fut.result())
                fut.release()
                yield r, result
                nxt = next(todo, None)
                if nxt is not None:
                    new = client.submit(_task, *args(nxt), pure=False)
                    keys[new.key] = nxt
                    queue.add(new)
        except BaseException:
            queue.clear()
            raise


def execute(indices: Sequence[int], args: Task, workers: int = 1,
            scheduler: str | None = None) -> Iterator[tuple[int, Record]]:
    """Run the realizations ``indices``; yield ``(r, records)`` as they finish (in any order).

    Parameters
    ----------
    indices : sequence of int
        Realizations to run.
    args : callable
        ``args(r)`` gives the arguments of :func:`run_realization` for r.
    workers : int
        Local worker processes (1: in this process).
    scheduler : str, optional
        Address of a Dask scheduler; when given, ``workers`` is ignored.
    """
    if scheduler is not None:
        return _dask(indices, args, scheduler)
    if workers <= 1 or len(indices) <= 1:
        return _in_process(indices, args)
    return _local_pool(indices, args, min(workers, len(indices)))
