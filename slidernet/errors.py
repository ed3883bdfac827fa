"""Exception classes of slidernet.

Every class subclasses a builtin so that ``except ValueError`` keeps working
for callers who do not know slidernet's own types.
"""

from __future__ import annotations


class SlidernetError(Exception):
    """Base class of every error raised by slidernet."""


class ConfigError(SlidernetError, ValueError):
    """A configuration value is invalid; raised before any work is done."""


class UnknownPluginError(ConfigError):
    """A distribution or driver name is not registered."""


class SizeError(ConfigError):
    """A run would need more memory than the machine has (its estimate, from the configuration, exceeds
    the machine's memory); raised before any work, with the estimate and the machine's memory."""


class PrecisionError(ConfigError):
    """float64 cannot resolve the slips of a scene: its forces are sums of terms so large that their
    rounding reaches the gap between the static and the dynamic thresholds; raised before any work,
    naming the parameter that makes the terms large (or the gap small)."""


class PluginError(SlidernetError, RuntimeError):
    """A plugin returned values that break the model's contract (NaN, mu_s <= mu_d, ...), or its own code raised
    (or called ``sys.exit``): the message names the plugin, where it comes from, the call, the exception and the
    plugin's line (:mod:`slidernet.plugins.guard`)."""


class AvalancheError(SlidernetError, RuntimeError):
    """An avalanche did not end within the allowed number of slips."""


class TiltTestError(SlidernetError, RuntimeError):
    """The virtual tilt test did not reach a sliding state within its iteration cap."""


class OrbitError(SlidernetError, RuntimeError):
    """An exact creep orbit of the theory did not repeat within its cycle cap: from four sliders on,
    some orbits are aperiodic."""


class CheckpointError(SlidernetError, ValueError):
    """A checkpoint file is unreadable, or belongs to another run or scene."""


class SnapshotError(SlidernetError, ValueError):
    """A snapshot of a realization does not fit the realization it is restored into: another scene,
    another seed, or missing or malformed state. The message is a predicate ("was written for another
    scene: ..."), so that a caller can prefix what it read the snapshot from."""


class ResultError(SlidernetError, ValueError):
    """A result file or dataset cannot be read, or lacks what is asked of it (not a run of slidernet,
    a sweep where one run is wanted, no per-node variables for a network picture)."""


class OutputError(SlidernetError, OSError):
    """An output path cannot be used (a file where a folder is wanted, no permission, no such parent),
    or it holds a finished result that would be replaced without ``overwrite``."""


class FolderInUseError(OutputError):
    """An output folder is locked by a command still going there (a run, a sweep, the paper, a plot)."""


class WorkerLostError(SlidernetError, RuntimeError):
    """A local worker process died abruptly (killed by a signal, e.g. by the out-of-memory killer) during a
    run; the work saved until then is kept, and the run can be resumed."""


class SchedulerError(SlidernetError, ConnectionError):
    """The Dask scheduler could not be reached within ``execution.scheduler_timeout``, or went away during the run
    (the work saved until then is kept, and the run can be resumed)."""


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT) or SIGTERM after saving its work; the message says how to resume.

    Parameters
    ----------
    message : str
        What was saved and how to resume.
    signum : int
        The signal that stopped the run (``signal.SIGINT`` or ``signal.SIGTERM``);
        the command line exits with 128 + signum, as a shell does.
    """

    def __init__(self, message: str = "", signum: int = 2) -> None:
        super().__init__(message)
        self.signum = int(signum)


class CheckpointWarning(UserWarning):
    """Something of a checkpoint folder was found damaged and is recomputed, or a folder cannot be locked."""


class SlidAwayWarning(UserWarning):
    """Every realization of a run slid away down its incline (its ``slid_away_at`` is finite)."""


class SlowRunWarning(UserWarning):
    """A run would take hours: its estimated slips, at a stated rate of slips per second, exceed the
    threshold of :mod:`slidernet.solver.budget`; raised once, before the run, with the estimate."""


def param_error(param: str, owner: str, requirement: str, got: object) -> ConfigError:
    """Build the standard message for a bad parameter value.

    >>> print(param_error("sigma_theta", "gaussian_steps", "> 0", -1e-06))
    The 'sigma_theta' parameter of gaussian_steps must be > 0. Got -1e-06 instead.
    """
    return ConfigError(
        f"The {param!r} parameter of {owner} must be {requirement}. Got {got!r} instead."
    )
