"""The ``[execution]`` table: where and how the realizations run, which never changes a result.

Local worker processes or a Dask cluster, and how often a run saves its
work. A scheduler's address is checked by :func:`scheduler_address_problem`
(:func:`is_scheduler_address`), the one check, which the runner uses too.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, field_validator

from slidernet.config.base import Integer, PositiveReal, _Strict, unit


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
        None, description="Local processes that run the realizations (None: every core this process may use).",
        json_schema_extra=unit("1"))
    scheduler: str | None = Field(
        None, description="Address of a Dask scheduler, 'tcp://host:port' (any address a Dask Client can reach "
                          "a remote scheduler at: scheduler_address_problem); when given, the realizations run "
                          "on that cluster and 'workers' is ignored.")
    checkpoint_every: PositiveReal = Field(
        60.0, description="Seconds between two saves of the work of a run that has an output directory.",
        json_schema_extra=unit("s"))
    scheduler_timeout: PositiveReal = Field(
        10.0, description="Seconds to wait for the Dask scheduler to answer before giving up.",
        json_schema_extra=unit("s"))
    stop_timeout: PositiveReal = Field(
        10.0, description="Seconds the running realizations get, after Ctrl-C or SIGTERM (or an error), to reach "
                          "a clean point and save; those still running then (a plugin that never returns) are "
                          "ended at their last save.", json_schema_extra=unit("s"))

    @field_validator("scheduler")
    @classmethod
    def _scheduler_address(cls, value: str | None) -> str | None:
        if value is not None:
            problem = scheduler_address_problem(value)
            if problem is not None:
                raise ValueError(f"must be {SCHEDULER_REQUIREMENT}; got {value!r}: {problem}")
        return value


SCHEDULER_REQUIREMENT = "the address of a Dask scheduler that a Client can reach, such as 'tcp://host:8786'"


def scheduler_address_problem(value: object) -> str | None:
    """Why a :class:`distributed.Client` cannot reach a remote scheduler at ``value``; None if it can try.

    The address is read as distributed reads it (``distributed.comm.addressing``: ``parse_address``, then
    ``parse_host_port``; no scheme means tcp, as ``Client("host:8786")``), and refused where a Client
    would refuse it before connecting (a bracket left open, a port that is not a number) or could never
    connect: no host, a host with a space, a port outside 1-65535, an ``inproc://`` address that is not
    one of this very process (a ``LocalCluster(processes=False)`` started from Python has one), a
    protocol this installation of distributed cannot connect over (``ucx://`` without the package
    distributed-ucxx), ``tls://`` without Dask's TLS settings, or an unencrypted protocol where Dask's
    configuration requires encryption. These last depend on the process that makes the Client: a Dask
    worker, which reads the configuration again to run a realization but makes no Client, checks the
    address alone. Whether a scheduler answers is known only by asking it
    (``execution.scheduler_timeout``).

    >>> scheduler_address_problem("tcp://10.0.0.1:8786") is None
    True
    >>> scheduler_address_problem("tcp://host")
    "missing port number in address 'host'"
    """
    if not isinstance(value, str) or not value.strip():
        return "not an address"
    # distributed is imported only here, where an address is given: it takes a third of a second.
    from distributed.comm import registry
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(value)
    except ValueError as exc:
        return str(exc)
    try:
        backend = registry.get_backend(scheme)
    except ValueError:
        return f"distributed knows no protocol {scheme!r} (it knows {', '.join(sorted(registry.backends))})"
    client_side = not _in_dask_worker()
    if scheme == "inproc":
        if not client_side:
            return None
        try:
            backend.get_address_host(location)  # distributed's own check: this host, this process
        except ValueError as exc:
            return (f"an inproc:// address reaches only a scheduler inside this very process, as "
                    f"inproc://<ip>/<pid>/<n> ({str(exc) or 'not of that form'}); a cluster is reached over "
                    f"tcp://, tls://, ws:// or wss://")
        return None
    try:
        host, port = parse_host_port(location)
    except ValueError as exc:
        reason = str(exc)
        return reason if "address" in reason else f"the port {location.rpartition(':')[2]!r} is not a number"
    if not host or any(c.isspace() for c in host):
        return f"{host!r} is not a host name or an IP address"
    if not 1 <= port <= 65535:
        return f"the port {port} is not in 1-65535"
    if not client_side:
        return None
    try:
        connector = backend.get_connector()
    except Exception:  # the backend's own failure: distributed 2026 keeps 'ucx' as a stub that cannot connect
        return (f"this installation of distributed cannot connect over {scheme!r}"
                + (" (UCX needs the package distributed-ucxx)" if scheme == "ucx" else ""))
    # Only the TCP connectors declare whether they encrypt (and enforce require-encryption): the others pass.
    return _security_problem(scheme, getattr(connector, "encrypted", True))


def _in_dask_worker() -> bool:
    """Whether this code runs in a task of a Dask worker (which makes no Client of its own)."""
    from distributed import get_worker

    try:
        get_worker()
    except ValueError:
        return False
    return True


def _security_problem(scheme: str, encrypted: bool) -> str | None:
    """What Dask's configuration (its TLS settings, ``distributed.comm.require-encryption``) forbids of a
    Client connecting over ``scheme``; None if nothing."""
    from distributed import Security

    try:
        security = Security()
        context = security.get_connection_args("client").get("ssl_context")
    except Exception as exc:  # a certificate file named in the configuration that cannot be read
        return f"Dask's TLS settings cannot be used: {str(exc).splitlines()[0] if str(exc) else exc!r}"
    if security.require_encryption and not encrypted:
        return (f"Dask's configuration requires encryption (distributed.comm.require-encryption) and {scheme}:// "
                f"is not encrypted")
    if scheme == "tls" and context is None:
        return ("a tls:// address needs Dask's TLS settings (distributed.comm.tls.ca-file and "
                "distributed.comm.tls.client.cert, .key in the Dask configuration), and none are set")
    return None


def is_scheduler_address(value: object) -> bool:
    """Whether a Dask Client can try to reach a scheduler at ``value`` (:func:`scheduler_address_problem`)."""
    return scheduler_address_problem(value) is None
