"""Every field of the configuration follows the one rule of its kind (issue 43, points 6 and 9).

A number is never a string or a boolean, a whole number fits int64 (a seed: 128 bits, the size of the
entropy of a fresh run), and a Dask scheduler's address is one a Client can reach a remote scheduler at.
The walk below reads every field of every table from the models themselves, so that a field added
later cannot escape the rule.
"""

from __future__ import annotations

import types
import typing
from collections.abc import Iterator
from typing import Any

import pytest
from pydantic import BaseModel, BeforeValidator, ValidationError

from slidernet import ConfigError
from slidernet.config import Config, ExecutionConfig, load_config
from tests.conftest import make_config

# The pydantic error types of the rules (config/base.py), which load_config words by field.
RULE_ERRORS = {"not_integer", "not_real", "not_int64", "not_seed"}


def _models(model: type[BaseModel], seen: set[type[BaseModel]] | None = None) -> Iterator[type[BaseModel]]:
    """``model`` and every table model its fields hold, recursively."""
    seen = set() if seen is None else seen
    if model in seen:
        return
    seen.add(model)
    yield model
    for field in model.model_fields.values():
        for leaf in _leaves(field.annotation, []):
            if isinstance(leaf[0], type) and issubclass(leaf[0], BaseModel):
                yield from _models(leaf[0], seen)


def _leaves(annotation: Any, metadata: list[Any]) -> Iterator[tuple[Any, list[Any], str]]:
    """(type, its Annotated metadata, container) for every leaf of a field's annotation; container is
    "" (a scalar), "list" or "tuple" (the leaf is an element of one)."""
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is typing.Annotated:
        yield from _leaves(args[0], [*metadata, *annotation.__metadata__])
    elif origin in (typing.Union, types.UnionType):
        for arg in args:
            yield from _leaves(arg, [])
    elif origin in (list, tuple):
        for arg in args:
            if arg is not Ellipsis:
                for leaf, meta, _ in _leaves(arg, []):
                    yield leaf, meta, origin.__name__
    else:
        yield annotation, metadata, ""


def _rule(metadata: list[Any]) -> str | None:
    """The name of the rule's validator among a leaf's metadata (``_integer``, ``_real``, ``_seed``)."""
    for item in metadata:
        if isinstance(item, BeforeValidator):
            return item.func.__name__
        for inner in getattr(item, "metadata", ()):
            if isinstance(inner, BeforeValidator):  # pragma: no cover - pydantic keeps them flat
                return inner.func.__name__
    return None


def _numeric_fields() -> list[tuple[type[BaseModel], str, str, str]]:
    """(model, field, kind, container) of every numeric leaf of every table; kind is the rule's validator
    (``_integer``, ``_real``, ``_seed``), or ``bare int`` / ``bare float`` for a leaf without one."""
    found = []
    for model in _models(Config):
        for name, field in model.model_fields.items():
            for leaf, meta, container in _leaves(field.annotation, list(field.metadata)):
                if leaf in (int, float):
                    entry = (model, name, _rule(meta) or f"bare {leaf.__name__}", container)
                    if entry not in found:  # the two whole numbers of a lattice's shape
                        found.append(entry)
    return found


NUMERIC = _numeric_fields()
NUMERIC_IDS = [f"{model.__name__}.{name}{'[]' if container else ''}" for model, name, _, container in NUMERIC]
WHOLE = [(f, i) for f, i in zip(NUMERIC, NUMERIC_IDS, strict=True) if f[2] in ("_integer", "_seed", "bare int")]


def test_the_walk_finds_the_fields_of_every_table():
    tables = {model.__name__ for model, *_ in NUMERIC}
    assert {"Config", "NetworkConfig", "FrictionConfig", "StrengtheningConfig", "SolverConfig",
            "ExecutionConfig", "TiltConfig", "CreepConfig", "UnitsConfig"} <= tables
    assert len(NUMERIC) >= 30


@pytest.mark.parametrize(("model", "name", "kind", "container"), NUMERIC, ids=NUMERIC_IDS)
def test_every_numeric_field_carries_the_rule_of_its_kind(model, name, kind, container):
    # A bare int or float (or one under pydantic's own Field only) is read in pydantic's lax mode: "0.5"
    # and true pass as numbers.
    assert kind in ("_integer", "_real", "_seed"), f"{model.__name__}.{name} is a {kind}"


def _wrapped(value: Any, container: str) -> Any:
    return [value, value] if container else value


def _errors_at(model: type[BaseModel], name: str, value: Any) -> list[dict[str, Any]]:
    with pytest.raises(ValidationError) as info:
        model.model_validate({name: value})
    return [e for e in info.value.errors() if e["loc"] and e["loc"][0] == name]


@pytest.mark.parametrize("bad", ["1", True, False], ids=["text", "true", "false"])
@pytest.mark.parametrize(("model", "name", "kind", "container"), NUMERIC, ids=NUMERIC_IDS)
def test_every_numeric_field_refuses_a_string_and_a_boolean(model, name, kind, container, bad):
    errors = _errors_at(model, name, _wrapped(bad, container))
    assert {e["type"] for e in errors} & RULE_ERRORS, errors


@pytest.mark.parametrize(("model", "name", "kind", "container"), [f for f, _ in WHOLE], ids=[i for _, i in WHOLE])
def test_every_integer_field_refuses_what_int64_cannot_hold(model, name, kind, container):
    # A seed goes to numpy's SeedSequence, whose entropy is 128 bits (a fresh run's seed is one): its bound.
    too_big = 2**128 if kind == "_seed" else 2**63
    for value in (too_big, float(too_big), 1e300):
        errors = _errors_at(model, name, _wrapped(value, container))
        assert {e["type"] for e in errors} & RULE_ERRORS, (value, errors)


# The cases of the issue, through load_config: one line naming the field. (id, dotted key, value, pattern)
LOOSE = [
    ("overshoot-text", "friction.overshoot", "0.5",
     r"'friction\.overshoot' field must be a real number\. Got '0\.5'"),
    ("overshoot-true", "friction.overshoot", True,
     r"'friction\.overshoot' field must be a real number\. Got True"),
    ("beta-text", "friction.strengthening", {"beta": "0.01", "tau_c": 1.0},
     r"'friction\.strengthening\.beta' field must be a real number\. Got '0\.01'"),
    ("tau_c-true", "friction.strengthening", {"beta": 0.01, "tau_c": True},
     r"'friction\.strengthening\.tau_c' field must be a real number\. Got True"),
    ("exponent-text", "friction.strengthening", {"law": "power", "beta": 0.01, "tau_c": 1.0, "exponent": "0.5"},
     r"'friction\.strengthening\.exponent' field must be a real number\. Got '0\.5'"),
    ("min_slips-text", "tilt.min_slips", "3", r"'tilt\.min_slips' field must be an integer\. Got '3'"),
    ("min_displacement-text", "tilt.min_displacement", "2",
     r"'tilt\.min_displacement' field must be a real number\. Got '2'"),
    ("max_avalanche-2^63", "solver.max_avalanche", 2**63,
     r"^Invalid configuration:\n  - The 'solver\.max_avalanche' field must be an integer within int64 "
     r"\(-2\^63 to 2\^63 - 1\)\. Got 9223372036854775808 instead\.$"),
    ("batch-1e19", "solver.batch", 1e19, r"'solver\.batch' field must be an integer within int64.* Got 1e\+19"),
    ("recompute_every-1e300", "solver.recompute_every", 1e300, r"'solver\.recompute_every' field must be an "
                                                              r"integer within int64"),
    ("steps-1e300", "steps", 1e300, r"'steps' field must be an integer within int64"),
    ("seed-2^128", "seed", 2**128, r"'seed' field must be an integer in \[0, 2\^128\)"),
]


@pytest.mark.parametrize(("key", "value", "match"), [c[1:] for c in LOOSE], ids=[c[0] for c in LOOSE])
def test_the_loose_options_of_the_issue_are_refused_naming_the_field(key, value, match):
    changes = {"mu_eff_at": "records", key: value} if key.startswith(("tilt", "friction.str")) else {key: value}
    with pytest.raises(ConfigError, match=match):
        load_config(make_config(**changes))


def test_a_seed_of_128_bits_is_accepted():
    assert load_config(make_config(seed=2**128 - 1)).seed == 2**128 - 1


# Addresses the validator passed but a Dask Client refuses or cannot use (issue 43, point 6).
BAD_SCHEDULERS = [
    ("unclosed-bracket", "tcp://[::1", r"ipv6"),
    ("port-not-a-number", "tcp://host:notaport", r"port"),
    ("space-in-host", "tcp://a b", r"port"),
    ("space-in-host-with-port", "tcp://a b:8786", r"host"),
    ("no-port", "tcp://host", r"port"),
    ("port-zero", "tcp://host:0", r"port"),
    ("port-too-large", "tcp://host:99999", r"port"),
    ("no-host", "tcp://:8786", r"host"),
    ("inproc-malformed", "inproc://x", r"inproc"),
    ("inproc-another-process", "inproc://127.0.0.1/1/1", r"inproc.*does not match"),
    ("unknown-scheme", "udp://host:8786", r"udp"),
    ("not-an-address", "", r"address"),
]


@pytest.mark.parametrize(("address", "match"), [c[1:] for c in BAD_SCHEDULERS],
                         ids=[c[0] for c in BAD_SCHEDULERS])
def test_a_scheduler_address_a_client_cannot_use_is_refused_naming_the_field(address, match):
    with pytest.raises(ConfigError, match=rf"^Invalid configuration:\n  - The 'execution\.scheduler' field: "
                                          rf".*{match}") as info:
        load_config(make_config(**{"execution.scheduler": address}))
    assert len(str(info.value).splitlines()) == 2


def test_ucx_is_refused_where_its_backend_is_not_installed():
    from distributed.comm import registry

    try:
        registry.get_backend("ucx").get_connector()
    except Exception:  # distributed's stub: UCX-Py was removed, distributed-ucxx replaces it
        pass
    else:  # pragma: no cover - a machine with distributed-ucxx
        pytest.skip("a UCX backend is installed here")
    with pytest.raises(ConfigError, match=r"'execution\.scheduler' field: .*'ucx'"):
        load_config(make_config(**{"execution.scheduler": "ucx://host:8786"}))


def test_tls_is_refused_without_the_dask_tls_configuration():
    import dask

    with dask.config.set({"distributed.comm.tls.ca-file": None, "distributed.comm.tls.client.cert": None}), \
            pytest.raises(ConfigError, match=r"'execution\.scheduler' field: .*TLS"):
        load_config(make_config(**{"execution.scheduler": "tls://host:8786"}))


@pytest.mark.parametrize("address", ["tcp://host:8786", "tcp://10.0.0.1:8786", "tcp://[::1]:8786",
                                     "host.example.org:8786", "ws://host:8786"])
def test_a_scheduler_address_a_client_accepts_is_accepted(address):
    assert ExecutionConfig(scheduler=address).scheduler == address


def test_an_inproc_address_of_this_process_is_accepted():
    # A LocalCluster(processes=False) started from Python: its scheduler lives in this process.
    from distributed.comm.inproc import new_address

    address = new_address()
    assert ExecutionConfig(scheduler=address).scheduler == address


def test_a_dask_worker_checks_the_address_alone():
    # A worker reads the configuration again to run a realization but makes no Client: what depends on the
    # process that makes one (Dask's TLS settings, here none) is not its to check; the address still is.
    import distributed

    from slidernet.config.execution import scheduler_address_problem

    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        in_worker = client.submit(scheduler_address_problem, "tls://host:8786").result()
        malformed = client.submit(scheduler_address_problem, "tcp://host").result()
    assert scheduler_address_problem("tls://host:8786") is not None  # here, where a Client would be made
    assert in_worker is None
    assert malformed == "missing port number in address 'host'"
