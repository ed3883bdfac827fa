"""The ``[execution]`` table: where and how the realizations run, which never changes a result.

Local worker processes or a Dask cluster, and how often a run saves its
work. A scheduler's address is checked by :func:`is_scheduler_address`, the
one check, which the runner uses too.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, field_validator

from slidernet.config.base import Integer, PositiveReal, _Strict

_SCHEDULER_SCHEMES = ("tcp", "tls", "inproc", "ucx", "ws", "wss")


class ExecutionConfig(_Strict):
    """Where and how the realizations run; never changes a result.

    ``workers`` local processes run the realizations (None: every core this
    process may use); ``scheduler`` (``"tcp://host:port"``) sends them to a
    Dask distributed cluster instead. ``checkpoint_every`` (seconds) is how
    often a run with an output directory saves its work, and
    ``scheduler_timeout`` (seconds) how long to wait for the scheduler to
    answer before giving up with a message, ``stop_timeout`` (seconds) how
    long a stopping run waits for its running realizations to save before
    it ends them. Realization r is
    always driven by child r of the seed and the ensemble is reduced in
    realization order, so the same config gives the same bits on 1 worker,
    N workers or a cluster; this table is kept out of the identity of a run
    (a run may resume with other workers).
    """

    workers: Annotated[Integer, Field(ge=1)] | None = Field(
        None, description="Local processes that run the realizations (None: every core this process may use).")
    scheduler: str | None = Field(
        None, description="Address of a Dask scheduler, 'tcp://host:port'; when given, the realizations run "
                          "on that cluster and 'workers' is ignored.")
    checkpoint_every: PositiveReal = Field(
        60.0, description="Seconds between two saves of the work of a run that has an output directory.")
    scheduler_timeout: PositiveReal = Field(
        10.0, description="Seconds to wait for the Dask scheduler to answer before giving up.")
    stop_timeout: PositiveReal = Field(
        10.0, description="Seconds the running realizations get, after Ctrl-C or SIGTERM (or an error), to reach "
                          "a clean point and save; those still running then (a plugin that never returns) are "
                          "ended at their last save.")

    @field_validator("scheduler")
    @classmethod
    def _scheduler_address(cls, value: str | None) -> str | None:
        if value is not None and not is_scheduler_address(value):
            raise ValueError(f"must be {SCHEDULER_REQUIREMENT}; got {value!r}")
        return value


SCHEDULER_REQUIREMENT = (f"a Dask scheduler address such as 'tcp://host:8786' (schemes: "
                         f"{', '.join(_SCHEDULER_SCHEMES)})")


def is_scheduler_address(value: object) -> bool:
    """Whether ``value`` reads as a Dask scheduler address ``scheme://host[:port]``."""
    if not isinstance(value, str):
        return False
    scheme, sep, rest = value.partition("://")
    return bool(sep) and scheme in _SCHEDULER_SCHEMES and bool(rest)
