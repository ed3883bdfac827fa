"""Where realizations run: in this process, in local worker processes, or on a Dask cluster.

Each realization is a task: ``run_realization(config_json, seed, r, ...)``
builds (once per process) the scene of the configuration, drives realization
r with child r of the run's seed (``SeedSequence(seed, spawn_key=(r,))``, the
same as ``SeedSequence(seed).spawn(R)[r]``) and returns its records. Nothing
else decides a result, so the backend, the number of workers and the order in
which tasks finish never change the bits.

While it runs, a task with a ``partial`` path saves its realization there
every ``every`` seconds (and on Ctrl-C), so a killed run resumes inside a
long realization rather than at its start. A stopping run gives its running
tasks :attr:`StopSignal.grace` seconds (``execution.stop_timeout``) to do so;
those still running then (a plugin that never returns) are ended at their
last save.

Backends
--------
- ``workers = 1``: in this process.
- ``workers = N``: a :class:`concurrent.futures.ProcessPoolExecutor` of N
  processes, forked where the platform can (the workers then inherit the
  compiled kernels and plugins registered at run time), spawned elsewhere.
  A worker dies with its parent (:func:`_die_with_parent`): a parent killed
  by kill -9 leaves no worker behind. A worker that dies stops the run with
  :class:`~slidernet.errors.WorkerLostError`; the other workers are ended
  at once, and what was saved stays resumable.
- ``scheduler = "tcp://host:port"``: a :class:`distributed.Client` on that
  scheduler. The workers need slidernet (and any plugin) installed, and the
  files named in the config (and the output directory, for checkpoints inside
  a realization) at the same paths.
"""

from __future__ import annotations

import asyncio
import ctypes
import functools
import json
import logging
import math
import multiprocessing
import multiprocessing.connection
import os
import signal
import sys
import threading
import time
import uuid
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

import numpy as np

from slidernet.config.execution import ExecutionConfig
from slidernet.errors import SchedulerError, SlidernetError, WorkerLostError

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


# A pool worker's stop flag: the multiprocessing.Event its parent sets, handed over by the pool's
# initializer (an Event crosses to another process only by inheritance, never as a task's argument).
# It lives and dies with the worker process, which serves one pool of one run; in the parent, and in
# any process that is not such a worker, it stays None.
_WORKER_STOP: Any = None


@functools.lru_cache(maxsize=4)
def _compiled(config_json: str) -> None:
    """The scene's kernels in a Dask worker, compiled once per process and once per machine: the first
    worker of a machine holds the cache's lock and compiles, the others wait and load from the cache."""
    from slidernet.config import load_config
    from slidernet.solver.compile import compile_kernels

    compile_kernels(load_config(json.loads(config_json)), notice=None)


class StopSignal:
    """Ctrl-C (SIGINT) and SIGTERM during a run, as a context manager.

    The first signal only asks: every running realization stops at its next
    clean point, between two chunks of thermal steps (at most about half a
    second of work) or, within a step, at the next refill of a draw buffer
    (every ``solver.batch`` slips at most), saves its state, and no queued
    realization starts. Realizations that have not stopped ``grace``
    seconds later (a plugin that never returns, a save that takes longer)
    are ended: the main thread is sent the signal again, which raises
    KeyboardInterrupt there, wherever it is (inside a plugin's Python code
    too), and the backend ends the workers. A second signal does the same
    at once. Every file is written atomically, so the folder still holds
    the last saved state of each realization. Outside the main thread
    (where Python cannot catch signals) this does nothing.

    The request belongs to this object: the realizations of its run read it
    (:meth:`is_set`, passed down to :func:`run_realization`), and nothing of
    it outlives the run, so a later run, or a direct call of
    :func:`run_realization`, is never stopped by an earlier one.

    Parameters
    ----------
    grace : float, optional
        Seconds between the first signal and the end of the realizations
        that have not stopped by then (default: that of
        ``execution.stop_timeout``).

    Attributes
    ----------
    signum : int or None
        The first signal received (``signal.SIGINT`` or ``signal.SIGTERM``).
    forced : bool
        True once the run was stopped at once (a second signal, or the grace
        ran out): the realizations still running were ended at their last save.
    expired : bool
        True if the grace ran out before every running realization had stopped.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self, grace: float | None = None) -> None:
        self.grace = float(ExecutionConfig.model_fields["stop_timeout"].default if grace is None else grace)
        self.signum: int | None = None
        self.forced = False
        self.expired = False
        self._previous: dict[int, Any] = {}
        self._timer: threading.Timer | None = None
        self._closing = False

    @property
    def requested(self) -> bool:
        """True once a signal asked the run to stop."""
        return self.signum is not None

    def is_set(self) -> bool:
        """The same as :attr:`requested`, as the callable a realization polls."""
        return self.signum is not None

    def request(self, signum: int = signal.SIGINT) -> None:
        """Ask the run to stop, as the first signal does (hooks and tests call it directly)."""
        if self.signum is None:
            self.signum = int(signum)

    def _handle(self, signum: int, frame: Any) -> None:
        if self.signum is not None:
            if self._closing:  # the run is over: nothing is left to stop
                return
            self.forced = True
            raise KeyboardInterrupt
        self.request(signum)
        # The main thread may be inside a plugin that never returns: only a signal reaches it there.
        self._timer = threading.Timer(self.grace, self._expire)
        self._timer.daemon = True
        self._timer.start()
        # Said at once: saving can take a moment, and the user should know a second Ctrl-C is heard.
        print(f"slidernet: {signal.Signals(signum).name} received: the running realizations stop at their next "
              f"clean point and are saved (those still running after {self.grace:g} s, execution.stop_timeout, "
              "are ended at their last save); send it again to stop at once.", file=sys.stderr, flush=True)

    def _expire(self) -> None:
        """The grace ran out: the first signal again, to the main thread, whose handler now stops at once."""
        if self._closing or self.signum is None:
            return
        self.expired = True
        main = threading.main_thread().ident
        if hasattr(signal, "pthread_kill") and main is not None:
            # A real signal: it also wakes a main thread blocked in a system call (a plugin's sleep).
            signal.pthread_kill(main, self.signum)
        else:  # pragma: no cover - Windows
            import _thread

            _thread.interrupt_main(self.signum)

    def __enter__(self) -> StopSignal:
        if threading.current_thread() is threading.main_thread():
            for sig in self.SIGNALS:
                self._previous[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc: Any) -> None:
        self._closing = True
        if self._timer is not None:
            self._timer.cancel()
            self._timer.join()  # a signal it was sending meets this object's handler, which lets it go
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()


Stop = Callable[[], bool] | str | None  # how a task learns that its run is stopping: see run_realization

# Seconds between two questions to a Dask Event inside a realization: each is a round trip to the scheduler.
_DASK_POLL = 0.2


def _stop_checker(stop: Stop) -> Callable[[], bool]:
    """``stop`` as a callable: itself, a Dask Event by name (asked at most every _DASK_POLL s), or never."""
    if stop is None:
        return lambda: False
    if callable(stop):
        return stop
    from distributed import Event

    event = Event(stop)
    last, answer = -math.inf, False

    def asked() -> bool:
        nonlocal last, answer
        now = time.monotonic()
        if not answer and now - last >= _DASK_POLL:
            last, answer = now, event.is_set()
        return answer

    return asked


def _advance_with_checkpoints(real, partial: Path | None, every: float, meta: dict[str, Any],
                              stopped: Callable[[], bool]) -> bool:
    """Advance ``real`` to its end, saving it to ``partial`` every ``every`` seconds.

    Returns False if the run was stopped first (``stopped()`` became true):
    the realization is then saved (when it has a ``partial`` path) at the
    clean point where it stopped.
    """
    from slidernet.io.checkpoint import save_realization

    steps = real.scene.steps
    chunk = 1
    # Chunks of at most a tenth of the interval, and half a second: a
    # checkpoint or a stop is never served much later than asked, and the
    # Python overhead per chunk stays negligible.
    target = min(0.1 * every, 0.5)
    last = time.monotonic()
    while real.step < steps:
        if stopped():
            if partial is not None:
                save_realization(real, partial, meta)
            return False
        t0 = time.monotonic()
        # The stop is also asked inside the chunk, wherever the kernel returns to refill a buffer: a
        # step that runs long (or an endless loop) is stopped within solver.batch slips.
        real.advance(min(real.step + chunk, steps), stop=stopped)
        took = time.monotonic() - t0
        chunk = max(1, min(2 * chunk, int(chunk * target / took) if took > 0 else 2 * chunk))
        if partial is not None and real.step < steps and time.monotonic() - last >= every:
            save_realization(real, partial, meta)
            last = time.monotonic()
    return True


def run_realization(config_json: str, seed: int, r: int, partial: str | None = None,
                    every: float = 60.0, meta: dict[str, Any] | None = None,
                    stop: Stop = None) -> Record | None:
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
    stop : callable, str or None
        What asks the run to stop: a callable polled between chunks of steps
        and at every buffer refill inside them (:meth:`StopSignal.is_set`,
        a pool worker's flag), the name of a Dask Event, or None (nothing
        stops it).

    Returns
    -------
    dict or None
        :meth:`slidernet.solver.Realization.result`; None if the run was
        asked to stop before the realization ended (its state is then saved
        in ``partial``, if given) or before it started.
    """
    from slidernet.solver import Realization

    stopped = _stop_checker(stop)
    if stopped():  # a queued realization does not start once the run is stopping
        return None
    scene = scene_of(config_json)
    ss = realization_seed(seed, r)
    path = None if partial is None else Path(partial)
    meta = {**(meta or {}), "realization": r}
    if path is not None and path.exists():
        from slidernet.io.checkpoint import load_realization

        real = load_realization(scene, ss, path, expect_meta=meta)
    else:
        real = Realization(scene, ss)
    if not _advance_with_checkpoints(real, path, every, meta, stopped):
        return None
    return real.result()


Task = Callable[[int], tuple]  # r -> the arguments of run_realization


TaskResult = tuple[Record | None, list[tuple[type[Warning], str]], bool]


def _task(*args: Any) -> TaskResult:
    """:func:`run_realization` in a worker: its records, the warnings it raised (for the caller to re-raise),
    and whether a plugin raised KeyboardInterrupt in it.

    Without a Dask Event's name among ``args``, the stop is the pool worker's flag. A worker ignores
    the signals, so a KeyboardInterrupt there is a plugin's own: the caller stops the run as on Ctrl-C
    (the realization keeps its last save).
    """
    stop = args[6] if len(args) > 6 else (None if _WORKER_STOP is None else _WORKER_STOP.is_set)
    if len(args) > 6:
        _compiled(args[0])  # a Dask worker: a local pool's workers are forked from a parent that compiled
    record, interrupted = None, False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            record = run_realization(*args[:6], stop=stop)
        except KeyboardInterrupt:
            interrupted = True
    return record, [(w.category, str(w.message)) for w in caught], interrupted


def _reraise(result: TaskResult, stop: StopSignal) -> Record | None:
    """The records of a task's result; its warnings raised here; a plugin's KeyboardInterrupt asks ``stop``."""
    record, caught, interrupted = result
    for category, message in caught:
        warnings.warn(message, category, stacklevel=2)
    if interrupted:
        stop.request(signal.SIGINT)
    return record


def _in_process(indices: Sequence[int], args: Task, stop: StopSignal) -> Iterator[tuple[int, Record]]:
    for r in indices:
        if stop.requested:
            return
        record = run_realization(*args(r), stop=stop.is_set)
        if record is not None:
            yield r, record


def _window(workers: int) -> int:
    """Tasks in flight at once: enough to keep every worker busy, few enough to bound memory."""
    return 4 * workers


# How often the parent looks at the signal flag while it waits for results, in s.
_POLL = 0.1


def _init_worker(flag: Any, parent: int) -> None:
    """Initializer of a pool worker: the parent's flag is its stop flag; signals are the parent's; it dies
    with its parent (process id ``parent``)."""
    global _WORKER_STOP
    _WORKER_STOP = flag
    # Ctrl-C reaches every process of the terminal's group, and a batch
    # scheduler may send SIGTERM to every process of a job. The parent alone
    # decides, through the flag, so that each running realization stops at a
    # clean point and saves; a worker killed by the signal would lose its work.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    _die_with_parent(parent)


# Linux's prctl option that sends this process a signal when its parent dies (<linux/prctl.h>).
_PR_SET_PDEATHSIG = 1
# Seconds between two looks at the parent process, where the OS cannot send a signal on its death.
_PARENT_POLL = 1.0


def _die_with_parent(parent: int) -> None:
    """End this worker process when its parent process ends, however the parent ends (kill -9 included).

    A pool worker waits for its next task on a pipe whose writing end it
    inherited itself, so it never sees the parent go: without this, a parent
    killed by kill -9 left its workers waiting forever (about 220 MB each).
    On Linux the kernel sends SIGKILL to the worker when its parent dies
    (``prctl(PR_SET_PDEATHSIG)``, through ctypes): at once, even while the
    worker runs a compiled kernel that holds the GIL. Elsewhere a daemon
    thread looks at ``os.getppid()`` every :data:`_PARENT_POLL` s and ends
    the process when the parent has changed. Either way the worker's files
    are consistent: every file is written atomically.
    """
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        except (OSError, AttributeError):
            armed = False
        if armed:
            if os.getppid() != parent:  # the parent died before the signal was armed
                os._exit(1)
            return

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(_PARENT_POLL)
        os._exit(1)

    threading.Thread(target=watch, name="slidernet-parent-watch", daemon=True).start()


def _terminate(pool: ProcessPoolExecutor) -> None:
    """Kill the pool's workers now (a second Ctrl-C, a worker lost) and wait until they have ended.

    SIGKILL, since the workers ignore SIGTERM (see :func:`_init_worker`).
    Their last saves are complete files; a save they were writing is left
    under a temporary name, which the caller may remove once this returns:
    no worker writes any more.
    """
    processes = list((getattr(pool, "_processes", None) or {}).values())
    kill = getattr(pool, "kill_workers", None)  # Python >= 3.14
    if kill is not None:
        kill()
    else:
        for proc in processes:
            proc.kill()
    for proc in processes:
        proc.join()  # at once: SIGKILL cannot be caught


class _Deadline:
    """The end of the grace a stopping run gives its running realizations (:attr:`StopSignal.grace` s)."""

    def __init__(self, grace: float) -> None:
        self.grace = grace
        self.since: float | None = None

    def start(self) -> bool:
        """Start the grace, once; True the first time (the caller then tells the tasks to stop)."""
        if self.since is not None:
            return False
        self.since = time.monotonic()
        return True

    @property
    def passed(self) -> bool:
        return self.since is not None and time.monotonic() - self.since > self.grace


def _local_pool(indices: Sequence[int], args: Task, workers: int,
                stop: StopSignal) -> Iterator[tuple[int, Record]]:
    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
    ctx = multiprocessing.get_context(method)
    flag = ctx.Event()
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_init_worker,
                               initargs=(flag, os.getpid()))
    todo = iter(indices)
    running: dict[Future, int] = {}
    deadline = _Deadline(stop.grace)

    def submit_next() -> bool:
        r = next(todo, None)
        if r is None:
            return False
        running[pool.submit(_task, *args(r))] = r
        return True

    def stopping() -> None:
        # Queued tasks see the flag as they start and return at once. None is cancelled here: Python 3.11's
        # pool thread sets an exception on every pending future when the pool breaks (our kill), and a
        # cancelled one raised InvalidStateError in that thread, a traceback after a second signal.
        if deadline.start():
            flag.set()

    forced = False
    try:
        while len(running) < _window(workers) and submit_next():
            pass
        while running:
            if stop.requested:
                stopping()
            if deadline.passed:  # tasks that never return (a plugin's endless loop): ended below
                forced = stop.expired = True
                break
            done, _ = wait(running, timeout=_POLL, return_when=FIRST_COMPLETED)
            for fut in done:
                r = running.pop(fut)
                try:
                    result = fut.result()
                except BrokenProcessPool:
                    running.clear()
                    raise WorkerLostError(_lost_message(pool)) from None
                record = _reraise(result, stop)
                if record is not None:
                    yield r, record
                if not stop.requested:
                    submit_next()
    except (KeyboardInterrupt, WorkerLostError):
        # A second Ctrl-C; or a worker died, and the pool can no longer send a task or a stop to the
        # others (they ignore SIGTERM): end them now. Their last saves are complete files.
        forced = True
        raise
    finally:
        # On any way out (an error, the caller stopping early, a second
        # Ctrl-C) running realizations are told to stop and save, and get
        # the grace to do so.
        stopping()
        try:
            # Short waits, not one long join: a signal that the OS hands to
            # another thread reaches Python's handler only when the main
            # thread wakes up.
            while running and not forced:
                if deadline.passed:
                    forced = stop.expired = True
                    break
                _, pending = wait(running, timeout=_POLL)
                if not pending:
                    break
        except KeyboardInterrupt:  # a second Ctrl-C while the workers save
            forced = True
            raise
        finally:
            if forced:
                stop.forced = True
                _terminate(pool)
            # The pool's thread, which has seen the killed workers, ends on its own (a forced stop) or once
            # the last task has returned.
            pool.shutdown(wait=True)


# Seconds to wait for the exit status of a worker known to have died (a hang guard: it comes at once).
_STATUS_WAIT = 5.0


def _exit_codes(pool: ProcessPoolExecutor) -> list[int]:
    """The exit statuses of the workers of ``pool`` that have ended (negative: the signal that ended it).

    The pool's own thread collects a dead worker's status (``waitpid``) at the
    moment the pool breaks: when it takes it between our look and its own
    bookkeeping, ``exitcode`` reads None for an instant although the worker
    is gone. A worker whose end the OS has signalled (its sentinel is ready)
    is therefore waited for until its status is known.
    """
    processes = list((getattr(pool, "_processes", None) or {}).values())
    try:
        ended = set(multiprocessing.connection.wait([p.sentinel for p in processes], timeout=0))
    except (ValueError, OSError):  # a process already closed by the pool
        return [p.exitcode for p in processes if p.exitcode is not None]
    deadline = time.monotonic() + _STATUS_WAIT
    codes = []
    for p in processes:
        if p.sentinel not in ended:
            continue
        while p.exitcode is None and time.monotonic() < deadline:
            time.sleep(0.01)
        if p.exitcode is not None:
            codes.append(p.exitcode)
    return codes


def _lost_message(pool: ProcessPoolExecutor) -> str:
    """One line: a worker of ``pool`` died, and how, where its exit status is known."""
    codes = _exit_codes(pool)
    signals = sorted({-c for c in codes if c is not None and c < 0})
    how = "died abruptly" if not signals else "was killed by " + ", ".join(signal.Signals(s).name for s in signals)
    if signal.SIGKILL in signals:
        how += " (by a user, a batch scheduler or the out-of-memory killer)"
    return f"A worker process {how} during the run; the other workers were stopped."


class _QuietLostScheduler(logging.Filter):
    """Drops what distributed's client logs when its scheduler has gone away: the run says it, in one line.

    That is the line "Failed to reconnect to scheduler ..." and, after it, the tracebacks of the
    client's own closing coroutines, cancelled (``asyncio.CancelledError``). Every other record passes.
    """

    def __init__(self) -> None:
        super().__init__()
        self.lost = False

    def filter(self, record: logging.LogRecord) -> bool:
        if record.getMessage().startswith("Failed to reconnect to scheduler"):
            self.lost = True
            return False
        cancelled = record.exc_info is not None and record.exc_info[0] is not None \
            and issubclass(record.exc_info[0], asyncio.CancelledError)
        return not (self.lost and cancelled)


def connect(scheduler: str, timeout: float) -> Any:
    """A ``distributed.Client`` of ``scheduler``, connected within ``timeout`` s (the client's own timeout:
    2.0 s of wall time for 2 to a local port nobody listens on), or :class:`SchedulerError` in one line.

    A run connects before it compiles its kernels: a compile (minutes from a cold cache on a loaded
    machine) never lengthens the wait the message states.
    """
    from distributed import Client

    try:
        return Client(scheduler, timeout=timeout)
    except Exception as exc:
        raise SchedulerError(
            f"Cannot reach the Dask scheduler at {scheduler!r} within {timeout:g} s "
            f"(execution.scheduler_timeout): {_first_line(exc)}."
        ) from None


def _dask(indices: Sequence[int], args: Task, scheduler: str, stop: StopSignal,
          timeout: float, client: Any = None) -> Iterator[tuple[int, Record]]:
    quiet = _QuietLostScheduler()
    log = logging.getLogger("distributed.client")
    log.addFilter(quiet)
    try:
        if client is None:
            client = connect(scheduler, timeout)
        with client:
            try:
                yield from _dask_tasks(client, indices, args, scheduler, stop)
            except SchedulerError:
                quiet.lost = True  # before the client closes: its closing, cut off, logs tracebacks
                raise
    finally:
        log.removeFilter(quiet)


def _first_line(exc: BaseException) -> str:
    return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def _dask_tasks(client: Any, indices: Sequence[int], args: Task, scheduler: str,
                stop: StopSignal) -> Iterator[tuple[int, Record]]:
    """The realizations on the cluster of ``client``; a scheduler that goes away is a SchedulerError."""
    from concurrent.futures import CancelledError

    from distributed import Event
    from distributed import wait as dask_wait
    from distributed.comm.core import CommClosedError

    workers = max(1, sum(client.nthreads().values()))
    name = f"slidernet-stop-{uuid.uuid4().hex}"
    event = Event(name, client=client)
    todo = iter(indices)
    running: dict[Any, int] = {}
    deadline = _Deadline(stop.grace)
    lost = at_once = False

    def submit_next() -> bool:
        r = next(todo, None)
        if r is None:
            return False
        running[client.submit(_task, *args(r), name, pure=False)] = r
        return True

    def stopping() -> None:
        if deadline.start():
            event.set()  # queued tasks see it as they start and return at once

    def waited(return_when: str) -> list[Any]:
        try:
            return list(dask_wait(list(running), timeout=_POLL, return_when=return_when).done)
        except TimeoutError:  # the wait's own timeout (a lost connection is another OSError)
            return []

    try:
        while len(running) < _window(workers) and submit_next():
            pass
        while running:
            if stop.requested:
                stopping()
            if deadline.passed:
                break
            for fut in waited("FIRST_COMPLETED"):
                r = running.pop(fut)
                record = _reraise(fut.result(), stop)
                fut.release()
                if record is not None:
                    yield r, record
                if not stop.requested:
                    submit_next()
    except (OSError, CancelledError, asyncio.CancelledError) as exc:
        # A task's own error passes (slidernet's errors, anything raised while the scheduler answers);
        # a closed connection, a connection that cannot be made again, the futures that a client cut
        # off from its scheduler cancels: the scheduler went away.
        if isinstance(exc, SlidernetError) or (client.status == "running" and not isinstance(
                exc, (CommClosedError, CancelledError, asyncio.CancelledError))):
            raise
        lost = True
        cut = isinstance(exc, (CommClosedError, CancelledError, asyncio.CancelledError))
        raise SchedulerError(f"The Dask scheduler at {scheduler!r} went away during the run "
                             f"({'the connection to it was lost' if cut else _first_line(exc)}).") from None
    except KeyboardInterrupt:  # a second Ctrl-C, or the grace ran out (StopSignal)
        at_once = True
        raise
    finally:
        # Running tasks save and return; short waits keep the main thread awake for a second signal.
        # With no scheduler there is nobody left to tell.
        try:
            if not (lost or at_once):
                stopping()
                while running and not deadline.passed:
                    if len(waited("ALL_COMPLETED")) == len(running):
                        running.clear()
        except KeyboardInterrupt:  # a second Ctrl-C: the tasks still running are left below
            pass
        except (OSError, CancelledError, asyncio.CancelledError):
            lost = True  # the error that brought us here says what happened
        if running and not lost:
            # A task that never returns (a plugin's endless loop) holds a thread of its worker, which no
            # one can end from here: its future is cancelled, and the run ends without it.
            stop.forced = True
            stop.expired = stop.expired or deadline.passed
            try:
                client.cancel(list(running))
            except (OSError, CancelledError, asyncio.CancelledError):
                pass


def execute(indices: Sequence[int], args: Task, workers: int = 1, scheduler: str | None = None,
            stop: StopSignal | None = None, scheduler_timeout: float = 10.0,
            client: Any = None) -> Iterator[tuple[int, Record]]:
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
    stop : StopSignal, optional
        Once it is requested no realization starts, and the running ones
        stop at a clean point, save, and are not yielded; the iteration then
        ends. Those still running ``stop.grace`` seconds later (a plugin that
        never returns) are ended: a local worker is killed, a Dask task's
        future cancelled, and ``stop.forced`` set. The same grace bounds the
        wait for the running realizations when the iteration ends early (an
        error, the caller closing it). None: never requested.
    scheduler_timeout : float
        Seconds to wait for the Dask scheduler before raising
        :class:`~slidernet.errors.SchedulerError`, which is also raised when
        the scheduler goes away during the run.
    client : distributed.Client, optional
        A client of ``scheduler`` already connected (:func:`connect`); the
        iteration closes it when it ends. None: it connects when the
        iteration starts.
    """
    stop = StopSignal() if stop is None else stop
    if scheduler is not None:
        return _dask(indices, args, scheduler, stop, scheduler_timeout, client)
    if workers <= 1 or len(indices) <= 1:
        return _in_process(indices, args, stop)
    return _local_pool(indices, args, min(workers, len(indices)), stop)
