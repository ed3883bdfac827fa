"""Loading a configuration: from a TOML file or a dict to a validated :class:`Config` with its plugins built.

Every check happens here, before any work: unknown keys first
(:func:`unknown_keys`, which needs nothing but the models' field names, so
a typo is reported before numba, scipy or a plugin is imported), then the
files and modules of ``plugins`` imported (so that what they register can
be named), structure and ranges through pydantic, plugin names and parameters by
building the plugins, and the checks that need them built (an incline
steeper than every threshold, a driver too short for the run). Pydantic's errors are rewritten as one
:class:`~slidernet.errors.ConfigError` that names each field and the
reason.
"""

from __future__ import annotations

import copy
import math
import sys
import typing
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel, ValidationError

from slidernet._paths import absolute_path, not_utf8
from slidernet._validation import did_you_mean
from slidernet.config.base import NOT_INT64, NOT_INTEGER, NOT_REAL, NOT_SEED
from slidernet.config.run import Config
from slidernet.errors import ConfigError
from slidernet.plugins.loader import absolute_entry, import_plugins, plugin_sources

if TYPE_CHECKING:
    from slidernet.model.network import Network

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def _describe(err: Mapping[str, Any]) -> str:
    # Drop pydantic's internal names of union members and validators from the path.
    loc = ".".join(
        str(p) for p in err["loc"] if not (str(p).startswith("function-") or "[" in str(p))
    )
    kind = err["type"]
    ctx = err.get("ctx") or {}
    got = err.get("input")
    if kind == "missing":
        return f"The {loc!r} field is required."
    if kind == "extra_forbidden":
        parent, _, key = loc.rpartition(".")
        model = _model_at(parent.split(".") if parent else [])
        return _unknown_key(key, parent, model.model_fields if model is not None else ())
    bounds = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<",
              "less_than_equal": "<="}
    if kind in bounds:
        limit = next(iter(ctx.values()))
        return f"The {loc!r} field must be {bounds[kind]} {limit}. Got {got!r} instead."
    if kind == "finite_number":
        return f"The {loc!r} field must be a finite number. Got {got!r} instead."
    # The rules of config/base.py: never a string or a boolean (slidernet._validation), int64, a seed's 128 bits.
    if kind in (NOT_INTEGER, NOT_REAL, NOT_INT64, NOT_SEED):
        return f"The {loc!r} field {err['msg']}. Got {got!r} instead."
    if kind == "value_error":
        msg = str(ctx.get("error", err["msg"]))
        return f"The {loc!r} field: {msg}." if loc else f"Invalid combination: {msg}."
    return f"The {loc!r} field: {err['msg']}. Got {got!r} instead."


def _unknown_key(key: str, parent: str, known: Iterable[str]) -> str:
    where = f" in [{parent}]" if parent else ""
    nearest = did_you_mean(key, known)
    return f"Unknown key {key!r}{where}; {nearest}" if nearest else f"Unknown key {key!r}{where}."


def _table_model(annotation: Any) -> type[BaseModel] | None:
    """The one model a field holds (``X`` or ``X | None``); None for a value, or a union of several models."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    models = [a for a in typing.get_args(annotation) if isinstance(a, type) and issubclass(a, BaseModel)]
    return models[0] if len(models) == 1 else None


def _model_at(path: Sequence[str]) -> type[BaseModel] | None:
    """The model of the table at the dotted ``path`` of a configuration (``[]``: :class:`Config`), or None."""
    model: type[BaseModel] | None = Config
    for key in path:
        field = model.model_fields.get(key) if model is not None else None
        model = _table_model(field.annotation) if field is not None else None
    return model


def unknown_keys(source: Mapping[str, Any], path: Sequence[str] = ()) -> list[str]:
    """The unknown keys of a raw configuration, one line each, naming the table and the nearest known key.

    It reads only the models' field names: a configuration with a typo is
    refused before anything heavy is imported or any plugin is loaded. A
    table whose model takes any key (a plugin's parameters) or that is not
    a table is left to the validation.

    >>> for line in unknown_keys({"realisations": 2, "network": {"kind": "chain", "Ntide": 1e-7}}):
    ...     print(line)
    Unknown key 'realisations'; did you mean 'realizations'?
    Unknown key 'Ntide' in [network]; did you mean 'Ntilde'?
    """
    model = _model_at(path)
    if model is None or model.model_config.get("extra") != "forbid":
        return []
    lines = []
    for key, value in source.items():
        field = model.model_fields.get(key)
        if field is None:
            lines.append(_unknown_key(str(key), ".".join(path), model.model_fields))
        elif isinstance(value, Mapping) and _table_model(field.annotation) is not None:
            lines += unknown_keys(value, (*path, key))
    return lines


def check_keys(source: Mapping[str, Any]) -> None:
    """Refuse a raw configuration with an unknown key (:func:`unknown_keys`), naming each and its nearest.

    Raises
    ------
    ConfigError
        Listing every unknown key, before anything else is checked.
    """
    unknown = unknown_keys(source)
    if unknown:
        raise _invalid(unknown)


def read_toml(path: str | Path) -> dict[str, Any]:
    """A configuration file as a dict, not validated; relative file paths made absolute against the file's folder.

    Files named in a config file (a graph, a temperature series, measured
    thresholds, the ``.py`` files of ``plugins``) are found next to that
    file. Their paths are made absolute (:func:`anchored`), so that a worker
    that starts elsewhere (Dask) reads the same files.
    """
    path = Path(path)
    where = f"The configuration file {str(path)!r}"
    if path.is_dir():
        raise ConfigError(f"{where} is a folder, not a file.")
    try:
        with path.open("rb") as fh:
            source = tomllib.load(fh)
    except FileNotFoundError:
        raise ConfigError(f"{where} does not exist.") from None
    except OSError as exc:  # no permission, a device, ...: the reason in the system's words
        raise ConfigError(f"{where} cannot be read: {exc.strerror or exc}.") from None
    except UnicodeDecodeError as exc:  # TOML is UTF-8 (a file saved as Latin-1 or UTF-16 fails here)
        line = exc.object[: exc.start].count(b"\n") + 1
        raise ConfigError(
            f"{where} is not UTF-8 text, as TOML must be: byte 0x{exc.object[exc.start]:02x} on line {line} "
            f"cannot be decoded. Save it as UTF-8."
        ) from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{where} is not valid TOML: {exc}") from None
    return anchored(source, path.parent)


def anchored(source: Mapping[str, Any], base: str | Path) -> dict[str, Any]:
    """A copy of a raw configuration whose file paths are absolute, a relative one taken against ``base``.

    The data files of :func:`_path_tables` and the ``.py`` files of
    ``plugins``; anything else (a value that is not a path) is left to the
    validation, which names it. Every path a run hands to its workers is
    then absolute, resolved in the process that read the configuration.

    Raises
    ------
    ConfigError
        If a path, once anchored, is not UTF-8 text (a folder named with a
        byte that is not UTF-8, :func:`slidernet._paths.not_utf8`): a
        configuration and the result that records it are text. Naming the
        field.

    >>> anchored({"plugins": ["laws.py", "my_package.laws"], "network": {"kind": "graph", "path": "g.txt"}},
    ...          "/home/me")
    {'plugins': ['/home/me/laws.py', 'my_package.laws'], 'network': {'kind': 'graph', 'path': '/home/me/g.txt'}}
    """
    source = copy.deepcopy(dict(source))
    for name, table in _path_tables(source).items():
        table["path"] = _text_path(absolute_path(table["path"], base), f"{name}.path")
    plugins = source.get("plugins")
    if isinstance(plugins, list):  # anything else is refused, by name, when it is validated
        source["plugins"] = [_text_path(absolute_entry(e, base), "plugins") if isinstance(e, str) else e
                             for e in plugins]
    return source


def _text_path(path: str, field: str) -> str:
    """``path``, refused (naming ``field``) if it is not UTF-8 text."""
    why = not_utf8(path)
    if why is not None:
        raise ConfigError(f"The {field!r} field: {path!r} {why}, and a configuration and its result name their "
                          "files in text. Rename the folder, or move the file.")
    return path


def _path_tables(source: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The tables of a raw or dumped configuration that name a file under ``path``, by their dotted name.

    The one list of the places a configuration names a data file: a graph
    (``network``), a temperature series (``driver``), measured thresholds
    (``friction.static``).
    """
    friction = source.get("friction")
    tables = {"network": source.get("network"), "driver": source.get("driver"),
              "friction.static": friction.get("static") if isinstance(friction, Mapping) else None}
    return {name: table for name, table in tables.items()
            if isinstance(table, dict) and isinstance(table.get("path"), str)}


def input_files(cfg: Config) -> dict[str, str]:
    """Every file a run of ``cfg`` reads, by what names it: its data files and plugin files.

    Parameters
    ----------
    cfg : Config
        A validated configuration.

    Returns
    -------
    dict of str to str
        ``"network.path"``, ``"driver.path"``, ``"friction.static.path"``
        (where given), ``"network.path (node file)"`` (the companion node
        file of an edge list), ``"plugins[i]"`` for each entry of
        ``plugins`` that is a ``.py`` file or a module of the user's, and
        ``"plugins[i] imports NAME"`` for each module outside the
        environment that entry brings in
        (:func:`slidernet.plugins.loader.plugin_sources`), each file listed
        once, to its path. A plugin installed in the environment's
        site-packages is not listed: its version is the user's to keep.
    """
    dumped = cfg.model_dump(mode="json")
    files = {f"{name}.path": table["path"] for name, table in _path_tables(dumped).items()}
    if cfg.network.kind == "graph" and cfg.network.path is not None:
        from slidernet.model.builders import graph_files

        nodes = graph_files(cfg.network.path).get("nodes")
        if nodes is not None:
            files["network.path (node file)"] = str(nodes)
    for i, entry in enumerate(cfg.plugins or ()):
        own, imports = plugin_sources(entry)
        if own is not None:
            files[f"plugins[{i}]"] = own
        for name, path in imports.items():
            if path not in files.values():  # a helper two plugins share is listed once, under the first
                files[f"plugins[{i}] imports {name}"] = path
    return files


def load_config(source: Config | Mapping[str, Any] | str | Path) -> Config:
    """Validate a configuration and build its plugins.

    The files and modules listed under ``plugins`` are imported first, in
    order (once per process), so that the distributions and drivers they
    register are known when the configuration names them.

    Parameters
    ----------
    source : Config, mapping, or path
        A :class:`Config`, a dict with the keys of docs/model.md section 5, or the
        path of a TOML file with those keys. A relative file path (under
        ``plugins``, or a data file's ``path``) is relative to the TOML file,
        or for a dict or a Config to the current directory; it is stored
        absolute (:func:`anchored`).

    Returns
    -------
    Config
        The validated configuration, with its plugins already built.

    Raises
    ------
    ConfigError
        On any invalid field, or a ``plugins`` entry that cannot be imported;
        the message names the field and the reason.
    """
    if isinstance(source, (str, Path)):
        source = read_toml(source)
    if isinstance(source, Config):
        dumped = source.model_dump(mode="json")
        if anchored(dumped, Path.cwd()) != dumped:  # built with a relative path: validated again, anchored
            source = dumped
    if isinstance(source, Config):
        import_plugins(source.plugins or ())
        cfg = source
    else:
        if not isinstance(source, Mapping):
            raise ConfigError(f"A configuration must be a dict, a Config or a path; got {type(source).__name__}.")
        # Absolute in the stored configuration: workers that start in another folder find the same files.
        source = anchored(source, Path.cwd())
        check_keys(source)
        _import_listed_plugins(source)
        try:
            cfg = Config.model_validate(dict(source))
        except ValidationError as exc:
            # dict.fromkeys: a union reports one error per member, often alike.
            raise _invalid(dict.fromkeys(_describe(e) for e in exc.errors())) from None
    cfg.distribution()
    _check_incline_holds(cfg)
    driver = cfg.driver_plugin()
    # An optional hook: a driver that cannot cover the run (a recorded series
    # too short) says so now, before any work.
    check = getattr(driver, "check_steps", None)
    if check is not None:
        try:
            check(cfg.steps)
        except ConfigError as exc:
            raise ConfigError(f"The 'driver' field: {exc}") from None
    return cfg


def _invalid(lines: Iterable[str]) -> ConfigError:
    return ConfigError("Invalid configuration:\n" + "\n".join(f"  - {m}" for m in lines))


def _import_listed_plugins(source: Mapping[str, Any]) -> None:
    """Import the ``plugins`` of a raw configuration (their paths absolute) before it is validated.

    Before validation, because the validators already look plugin names up
    (whether the driver takes ``sigma_theta``, for ``[units]``). A value that
    is not a list of strings is left to the validation, which names it.
    """
    plugins = source.get("plugins")
    if isinstance(plugins, list) and all(isinstance(e, str) and e for e in plugins):
        import_plugins(plugins)


def _check_incline_holds(cfg: Config) -> None:
    """Refuse an incline steeper than every threshold: tan(incline) >= mu_s for every slider.

    Such a network can never rest: every slider is unstable on its own from
    t = 0 on. The law's upper end is taken after its truncation at mu_d.
    """
    incline = cfg.network.incline
    if not incline:
        return
    hi = cfg.distribution().support()[1]
    slope = math.tan(math.radians(incline))
    if hi <= slope:
        raise ConfigError(
            f"The 'network.incline' field: tan({incline!r} degrees) = {slope!r} is at or above every static "
            f"threshold (the law {cfg.friction.static.name!r} of 'friction.static' ends at mu_s = {hi!r}), so no "
            f"slider can rest on it. Use a smaller angle."
        )


def build_network(cfg: Config) -> Network:
    """The network of the configured scene (its own seed: the geometry is quenched)."""
    return cfg.network.build()
