"""Progress of a long job: tqdm's bar on a terminal, plain lines in a batch job's log.

A bar redraws one line with carriage returns: in a file it is either
nothing (tqdm's rule, off when stderr is not a terminal) or a mess. A batch
job whose stderr goes to a log file gets instead one line every
:data:`INTERVAL` seconds of wall time, each complete::

    slidernet: realizations 3/10 done (30%), 1.24e+05 slips/s, 2.1 min elapsed, about 4.9 min left

and a run given the slow-run estimate (:func:`slidernet.solver.budget.check_run`)
says once, bar or lines, when it falls :data:`BEHIND` times behind it.

The ``progress`` argument of :func:`slidernet.run`, :func:`slidernet.ensemble.sweep.sweep`
and :func:`slidernet.paper.reproduce`, one rule:

- ``False``: nothing;
- ``True`` or ``None``: a bar where stderr is a terminal, lines every :data:`INTERVAL` s where it is
  not (a script that asks for progress in a batch job gets lines, not a bar's carriage returns);
- a number of seconds > 0: lines at that interval, terminal or not.

A background thread writes the lines (the work runs in the caller's
thread, which waits for realizations that may take hours); tests drive
:meth:`Progress.tick` themselves with a clock of their own.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import TextIO

from tqdm.auto import tqdm

from slidernet.errors import param_error

# Held while a line is written. A local pool forks its workers while the thread of the lines may be writing:
# a child forked then would inherit the stream's lock held, and hang at its first write to stderr. Holding
# this lock across every fork of the process keeps the fork out of a write.
_WRITING = threading.Lock()
if hasattr(os, "register_at_fork"):  # POSIX
    os.register_at_fork(before=_WRITING.acquire, after_in_parent=_WRITING.release,
                        after_in_child=_WRITING.release)

#: Seconds of wall time between two progress lines (``progress=None`` without a terminal).
INTERVAL = 30.0
#: How many times slower than the slow-run estimate a run must be to say so.
BEHIND = 2.0
#: Seconds before a run may say it is behind its estimate: a short run's start (imports, workers starting)
#: is no measure of its rate.
BEHIND_AFTER = 60.0

def check_progress(progress: object, owner: str) -> None:
    """Refuse a ``progress`` argument that is not ``True``, ``False``, ``None`` or a number of seconds > 0."""
    if progress is None or isinstance(progress, bool):
        return
    if not isinstance(progress, (int, float)) or not (progress > 0 and math.isfinite(progress)):
        raise param_error("progress", owner, "True, False, None or a number of seconds > 0", progress)


def shows_lines(progress: bool | float | None, stream: TextIO | None = None) -> bool:
    """True if ``progress`` is given as plain lines on ``stream`` (default: stderr)."""
    if progress is None or progress is True:
        return not (stream or sys.stderr).isatty()
    return progress is not False


class Progress:
    """A bar, plain lines or nothing, over ``total`` units of work; the interface of the tqdm bar it replaces.

    Parameters
    ----------
    total : float
        The work in all: realizations, or for ``unit=None`` an estimate in
        any unit (the paper's figures), given as a percentage.
    progress : bool, float or None
        The rule of the module's docstring.
    desc : str
        What is counted, the line's first word(s).
    initial : float
        Work already done (a resumed run's finished realizations).
    unit : str or None
        The unit of ``total`` named in a line (``"realizations"``); None:
        percentages only.
    estimate : float, optional
        The slow-run estimate of the remaining work, in seconds; None: none
        is checked.
    parallel : int
        The realizations that run at once (the estimate's workers): the
        first ones are due after ``estimate x parallel / remaining``.
    stream : file, optional
        Where it writes (default: stderr).
    clock : callable
        Seconds, monotonic (default :func:`time.monotonic`): a test gives
        its own.
    background : bool
        Start the thread that writes the lines (and checks the estimate);
        False: the caller calls :meth:`tick`.
    """

    def __init__(self, total: float, progress: bool | float | None, desc: str, *, initial: float = 0,
                 unit: str | None = "realizations", estimate: float | None = None, parallel: int = 1,
                 stream: TextIO | None = None, clock: Callable[[], float] = time.monotonic,
                 background: bool = True) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.total, self.done, self.initial = total, initial, initial
        self.desc, self.unit, self.postfix = desc, unit, ""
        self.estimate, self.parallel = estimate, max(1, int(parallel))
        self.slips = 0
        self.clock = clock
        self.start = self.last = clock()
        self.said_behind = False
        self.written: float | None = None  # the work done when the last line was written
        self.shown = progress is not False
        self.lines = progress is not False and shows_lines(progress, self.stream)
        self.interval = INTERVAL if progress is None or isinstance(progress, bool) else float(progress)
        self.bar = None
        if progress is not False and not self.lines:
            self.bar = tqdm(total=total, initial=initial, desc=desc, file=self.stream,
                            bar_format=None if unit else "{desc}: {percentage:3.0f}%|{bar}| "
                                                         "[{elapsed}<{remaining}{postfix}]")
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        if background and progress is not False:
            self._thread = threading.Thread(target=self._beat, name="slidernet-progress", daemon=True)
            self._thread.start()

    # -- the tqdm interface ------------------------------------------------------------------------------

    def update(self, n: float = 1, slips: int = 0) -> None:
        """``n`` more units done, ``slips`` rearrangements in them (for the rate of slips)."""
        with self._lock:
            self.done += n
            self.slips += slips
            if self.bar is not None:
                self.bar.update(n)
        self.tick()

    def set_postfix_str(self, text: str) -> None:
        """What runs now (a sweep's point, a figure's run), at the end of the bar or of the next line."""
        with self._lock:
            self.postfix = text
            if self.bar is not None:
                self.bar.set_postfix_str(text)

    def close(self) -> None:
        """Stop the thread; a last line says where the work ended, a bar is closed."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        with self._lock:
            if self.bar is not None:
                self.bar.close()
                self.bar = None
            elif self.lines and self.done != self.written:  # where it ended, unless the last line said it
                self._write(self.line())
            self.lines = False

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- lines -------------------------------------------------------------------------------------------

    def tick(self) -> None:
        """Write a line if :attr:`interval` seconds passed since the last; say once if the run is behind."""
        with self._lock:
            now = self.clock()
            behind = self.behind_line()
            if behind is not None:
                self.said_behind = True
                self._write(behind)
            if self.lines and now - self.last >= self.interval:
                self.last, self.written = now, self.done
                self._write(self.line())

    def line(self) -> str:
        """The progress line now: done of total, slips per second, time elapsed and left."""
        elapsed = self.clock() - self.start
        share = self.done / self.total if self.total else 1.0
        if self.unit:
            head = f"{self.desc} {self.done:g}/{self.total:g} done ({share:.0%})"
        else:
            head = f"{self.desc} {share:.0%} done"
        parts = [head]
        if self.slips and elapsed > 0:
            parts.append(f"{self.slips / elapsed:.3g} slips/s")
        parts.append(f"{duration(elapsed)} elapsed")
        new = self.done - self.initial
        if new > 0 and self.done < self.total:
            parts.append(f"about {duration(elapsed * (self.total - self.done) / new)} left")
        elif self.done < self.total:
            parts.append("time left unknown until one finishes")
        return "slidernet: " + ", ".join(parts) + (f" [{self.postfix}]" if self.postfix else "")

    def behind_line(self) -> str | None:
        """The one line that says the run is :data:`BEHIND` times slower than its estimate, or None."""
        if not self.shown or self.estimate is None or self.said_behind or self.estimate <= 0:
            return None
        elapsed = self.clock() - self.start
        if elapsed < BEHIND_AFTER:
            return None
        remaining = self.total - self.initial
        new = self.done - self.initial
        if new > 0:
            # At this pace the run would take elapsed * remaining / new in all, against the estimate.
            ratio, bound = elapsed * remaining / (new * self.estimate), ""
        else:
            # Not one realization finished: the first ones were due after the estimate's share of one of them.
            ratio, bound = elapsed / (self.estimate * min(self.parallel, remaining) / remaining), "at least "
        if ratio < BEHIND:
            return None
        return (f"slidernet: this run is {bound}{ratio:.1f}x slower than estimated ({new:g} of {remaining:g} "
                f"{self.unit or 'units'} done after {duration(elapsed)}; the estimate was "
                f"{duration(self.estimate)} for all of them). A value far from its physical scale (sigma_theta "
                f"or Ntilde in the wrong unit) makes far more slips than a real material does; Ctrl-C stops it, "
                f"and with --out saves its work.")

    def _write(self, line: str) -> None:
        with _WRITING:
            if self.bar is not None:
                self.bar.write(line, file=self.stream)
            else:
                print(line, file=self.stream, flush=True)

    def _beat(self) -> None:
        # Often enough for the estimate's check; the lines keep their own interval.
        while not self._stop.wait(min(self.interval, 5.0)):
            self.tick()


def duration(seconds: float) -> str:
    """A duration in the unit a person reads: s, min, h or days.

    >>> duration(42.0), duration(294.0), duration(7200.0), duration(3 * 86400.0)
    ('42 s', '4.9 min', '2 h', '3 days')
    """
    if seconds < 60:
        return f"{seconds:.0f} s"
    for unit, scale in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= scale:
            return f"{seconds / scale:.2g} {unit}"
    raise AssertionError  # pragma: no cover
