"""The configuration reference as Markdown tables, generated from the models (``docs/configuration-reference.md``).

Every key of every table of a configuration, with its type, default, unit,
constraint and meaning, read from the pydantic models of
:mod:`slidernet.config` (a field's ``description``, its bounds, and the unit
in its ``json_schema_extra``), and the parameters of the built-in
distributions and drivers, read from their factories' signatures, their
numpydoc ``Parameters`` and their ``param_units``. The file is committed, so
that it reads as tables on GitHub; ``tests/test_reference.py`` fails when it
is out of date. To write it again::

    python -m slidernet.config.reference --write

>>> text = markdown_reference()
>>> "| `dynamics.rtol` | float | 1e-10 | 1 | in [1e-14, 0.001] |" in text
True
"""

from __future__ import annotations

import argparse
import inspect
import re
import sys
import types
import typing
from pathlib import Path
from typing import Annotated, Any, Literal

import annotated_types
from pydantic import BaseModel
from pydantic.fields import FieldInfo

from slidernet.config import base
from slidernet.config.plugins import PluginSpec
from slidernet.config.run import Config

#: Where the reference is committed, relative to the repository root.
REFERENCE_PATH = Path("docs") / "configuration-reference.md"
#: The command that writes it again.
COMMAND = "python -m slidernet.config.reference --write"

_HEADER = f"""# Configuration reference: every key

<!-- Generated from the models of slidernet.config by `{COMMAND}`; do not edit. -->

Every key of a configuration file, table by table, generated from the
pydantic models that validate it (`slidernet/config/reference.py`; a test
fails when this page is out of date: `{COMMAND}` writes it again). What the
tables mean and how they work together is in [the configuration
guide](configuration.md); the reference case is `examples/paper.toml`.

**Type**: `int` is a whole number within int64 (a float without a fractional
part, `1e4`, is taken), `float` a real number; never a string or a boolean.
A real number is finite unless its constraint says `inf allowed`. **Default**:
*required* must be given; *unset* is the key left out, which the description
says the meaning of. **Unit**: `1` is dimensionless; `tau_th` the thermal
time, `l0` the slider's size, `N` the normal load, `k0 = N / (Ntilde l0)` the
paper's spring, `ell` the reference slip of the description, `tau_dyn` the
time of a slip with inertia.
"""


def _extra(field: FieldInfo, key: str) -> str:
    """The ``unit`` or ``constraint`` of a field (:func:`slidernet.config.base.unit`); "" without one."""
    extra = field.json_schema_extra
    return str(extra.get(key, "")) if isinstance(extra, dict) else ""


def _interval(bounds: dict[str, float]) -> str:
    """'> 0', '>= 1', 'in [1e-14, 0.001]' from the tightest bounds found."""
    low = max(((v, k) for k, v in bounds.items() if k in ("gt", "ge")), default=None)
    high = min(((v, k) for k, v in bounds.items() if k in ("lt", "le")), default=None)
    if low and high:
        return f"in {'(' if low[1] == 'gt' else '['}{low[0]:g}, {high[0]:g}{')' if high[1] == 'lt' else ']'}"
    if low:
        return f"{'>' if low[1] == 'gt' else '>='} {low[0]:g}"
    if high:
        return f"{'<' if high[1] == 'lt' else '<='} {high[0]:g}"
    return ""


def _flat(metadata: list[Any]) -> list[Any]:
    """The metadata of an annotation with every ``Field(...)`` in it opened (``Annotated`` nests them)."""
    return [leaf for item in metadata
            for leaf in (_flat(item.metadata) if isinstance(item, FieldInfo) else [item])]


def _constraint(metadata: list[Any], kind: str) -> list[str]:
    """The constraints the metadata of one annotation states, in words."""
    bounds: dict[str, float] = {}
    found = []
    finite = False
    for item in _flat(metadata):
        if isinstance(item, (annotated_types.Gt, annotated_types.Ge)):
            name = type(item).__name__.lower()
            bounds[name] = max(bounds.get(name, -float("inf")), getattr(item, name))
        elif isinstance(item, (annotated_types.Lt, annotated_types.Le)):
            name = type(item).__name__.lower()
            bounds[name] = min(bounds.get(name, float("inf")), getattr(item, name))
        elif isinstance(item, annotated_types.MinLen):
            found.append("not empty" if item.min_length == 1 else f"at least {item.min_length} long")
        elif getattr(item, "allow_inf_nan", None) is False:
            finite = True
        elif getattr(item, "func", None) is base._seed:
            found.append("< 2^128")
    interval = _interval(bounds)
    if kind == "float" and not finite:
        found.append("inf allowed")
    return ([interval] if interval else []) + found


def _describe(annotation: Any, metadata: list[Any] = ()) -> tuple[str, list[str]]:
    """(type in words, constraints) of an annotation and the metadata pydantic took out of it."""
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is Annotated:
        return _describe(args[0], [*args[1:], *metadata])
    if origin in (typing.Union, types.UnionType):
        kinds, constraints = [], []
        for arg in args:
            if arg is type(None):
                continue
            kind, found = _describe(arg)
            kinds.append(kind)
            constraints += [c for c in found if c not in constraints]
        return " or ".join(kinds), constraints
    if origin is Literal:
        return " \\| ".join(f'`"{a}"`' if isinstance(a, str) else f"`{a}`" for a in args), []
    if origin is list:
        kind, found = _describe(args[0])
        return f"list of {kind}", [f"each {c}" for c in found]
    if origin is tuple:
        kinds = [_describe(arg) for arg in args]
        found = kinds[0][1]
        return f"[{', '.join(k for k, _ in kinds)}]", [f"each {c}" for c in found]
    if inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        return "table", []
    kind = {int: "int", float: "float", str: "string", bool: "bool"}.get(annotation, str(annotation))
    return kind, _constraint(list(metadata), kind)


def _value(value: Any) -> str:
    """A default as TOML writes it."""
    if isinstance(value, str):
        return f'`"{value}"`'
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"
    if isinstance(value, float):
        return f"{value:g}" if float(f"{value:g}") == value else repr(value)
    if isinstance(value, int):  # a round large count as TOML can write it: 1e8
        short = f"{value:g}".replace("e+0", "e").replace("e+", "e")
        return short if value >= 10**6 and float(short) == value else str(value)
    if isinstance(value, (list, tuple)):
        return "`[" + ", ".join(f'"{v}"' if isinstance(v, str) else str(v) for v in value) + "]`"
    if isinstance(value, BaseModel):
        return "its defaults"
    return str(value)


def _default(field: FieldInfo) -> str:
    if field.is_required():
        return "*required*"
    value = field.default_factory() if field.default_factory is not None else field.default
    return "*unset*" if value is None else _value(value)


def _cell(text: str) -> str:
    """One table cell: one line, its bars escaped, and its "<" outside code (``<k>`` would read as an HTML tag)."""
    parts = " ".join(text.split()).replace("|", "\\|").split("`")
    return "`".join(part if i % 2 else part.replace("<", "\\<") for i, part in enumerate(parts))


_COLUMNS = "| Key | Type | Default | Unit | Constraint | Description |\n|---|---|---|---|---|---|\n"


def _model_rows(model: type[BaseModel], prefix: str) -> tuple[str, list[tuple[str, type[BaseModel]]]]:
    """The table of one model's keys, and its keys that are tables of their own (dotted name, model)."""
    rows, nested = [], []
    for name, field in model.model_fields.items():
        key = f"{prefix}{name}"
        kind, constraints = _describe(field.annotation, list(field.metadata))
        constraints += [_extra(field, "constraint")] if _extra(field, "constraint") else []
        sub = _models(field.annotation)
        if sub and sub[0] is PluginSpec:
            kind = f"table, [a plugin](#{_anchor(_plugins_title(key))})"
        elif sub:
            nested.append((key, sub[0]))
            kind = f"table [`[{key}]`](#{_anchor(key)})"
        rows.append(f"| `{key}` | {kind} | {_default(field)} | {_extra(field, 'unit') or '—'} | "
                    f"{_cell(', '.join(constraints)) or '—'} | {_cell(field.description or '')} |")
    return _COLUMNS + "\n".join(rows) + "\n", nested


def _models(annotation: Any) -> list[type[BaseModel]]:
    if inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in typing.get_args(annotation) for m in _models(arg)]


def _anchor(key: str) -> str:
    """The anchor GitHub and MyST give the heading ``## `[key]```: lower case, punctuation dropped."""
    return re.sub(r"[^\w\- ]", "", key.lower()).replace(" ", "-")


def _parameters(factory: Any) -> dict[str, tuple[str, str]]:
    """{name: (type, description)} from the numpydoc ``Parameters`` section of a factory's docstring."""
    doc = inspect.getdoc(factory) or ""
    section = re.search(r"^Parameters\n-+\n(.*?)(?:^\S[^\n]*\n-+\n|\Z)", doc, re.S | re.M)
    found: dict[str, tuple[str, str]] = {}
    if section is None:
        return found
    for head, body in re.findall(r"^(\S[^\n]*)\n((?:[ \t]+[^\n]*\n?|\n(?=[ \t]))*)", section.group(1), re.M):
        names, _, kind = head.partition(" : ")
        for name in names.split(","):
            found[name.strip()] = (kind.replace(", optional", "").strip(), _cell(body.replace("``", "`")))
    return found


def _plugin_table(factory: Any, prefix: str) -> str:
    """The table of a built-in plugin's parameters (its factory's signature, docstring and param_units)."""
    documented = _parameters(factory)
    param_units = getattr(factory, "param_units", {})
    rows = []
    for name, param in inspect.signature(factory).parameters.items():
        kind, description = documented.get(name, ("", ""))
        default = "*required*" if param.default is param.empty else (
            "*unset*" if param.default is None else _value(param.default))
        rows.append(f"| `{prefix}{name}` | {_cell(kind)} | {default} | {param_units.get(name, '—')} | "
                    f"{description} |")
    return "| Key | Type | Default | Unit | Description |\n|---|---|---|---|---|\n" + "\n".join(rows) + "\n"


def _plugins_title(table: str) -> str:
    return f"Built-in {'driver' if table == 'driver' else 'distribution'}s of `[{table}]`"


def _plugins_section(kind: str, table: str, builtins: dict[str, Any]) -> list[str]:
    parts = [f"## {_plugins_title(table)}\n",
             f"`[{table}]` takes `name` and the parameters of that {kind}'s factory: those of the built-ins "
             f"are below (constraints in the description). `slidernet plugins` lists every registered name, "
             f"those of plugins included.\n"]
    for name, factory in builtins.items():
        parts += [f"### `{name}` ({kind})\n", _cell(_summary(factory)) + "\n", _plugin_table(factory, f"{table}.")]
    return parts


def _summary(factory: Any) -> str:
    """The first paragraph of a docstring, its reST literals (````x````) as Markdown's."""
    return (inspect.getdoc(factory) or "").split("\n\n")[0].replace("``", "`")


def markdown_reference() -> str:
    """The configuration reference: one Markdown table per table of a configuration, then the plugins'.

    Returns
    -------
    str
        The text of ``docs/configuration-reference.md``.
    """
    from slidernet.plugins.distributions import BUILTINS as DISTRIBUTIONS
    from slidernet.plugins.drivers import BUILTINS as DRIVERS

    parts = [_HEADER]
    todo: list[tuple[str, type[BaseModel]]] = [("", Config)]
    while todo:
        key, model = todo.pop(0)
        if model is PluginSpec:
            continue  # its keys are the plugin's: below
        title = "The run (top level)" if not key else f"`[{key}]`"
        table, nested = _model_rows(model, f"{key}." if key else "")
        parts += [f"## {title}\n", _cell(_summary(model)) + "\n", table]
        todo = nested + todo  # each table's own tables right after it
    parts += _plugins_section("distribution", "friction.static", DISTRIBUTIONS)
    parts += _plugins_section("driver", "driver", DRIVERS)
    return "\n".join(parts)


def main(argv: list[str] | None = None) -> int:
    """Print the reference, or with ``--write`` write it to ``docs/configuration-reference.md`` of ``--root``."""
    parser = argparse.ArgumentParser(prog="python -m slidernet.config.reference",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--write", action="store_true", help=f"write {REFERENCE_PATH} instead of printing it")
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parents[2],
                        help="the repository's root (default: the one this module is in)")
    args = parser.parse_args(argv)
    text = markdown_reference()
    if args.write:
        (args.root / REFERENCE_PATH).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
