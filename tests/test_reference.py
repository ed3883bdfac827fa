"""The configuration reference, ``docs/configuration-reference.md``: generated from the models, committed, and
never out of date (issue 46, point 3)."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

from slidernet.config import reference
from slidernet.plugins.distributions import BUILTINS as DISTRIBUTIONS
from slidernet.plugins.drivers import BUILTINS as DRIVERS
from tests.test_docs import config_models

ROOT = Path(__file__).resolve().parents[1]
COMMITTED = ROOT / reference.REFERENCE_PATH


def test_the_committed_reference_is_up_to_date():
    assert COMMITTED.read_text(encoding="utf-8") == reference.markdown_reference(), (
        f"{reference.REFERENCE_PATH} is out of date with the models of slidernet.config; write it again with "
        f"`{reference.COMMAND}` and commit it")


def _numeric(annotation: object) -> bool:
    return "int" in str(annotation) or "float" in str(annotation)


def test_every_numeric_key_has_its_unit():
    # One place for a unit: the field's json_schema_extra (slidernet.config.base.unit), which the table reads.
    bare = sorted(f"{cls.__name__}.{name}" for cls in config_models() for name, field in cls.model_fields.items()
                  if _numeric(field.annotation) and name != "seed" and not reference._extra(field, "unit"))
    assert not bare, f"numeric fields without json_schema_extra=unit(...): {bare}"


@pytest.mark.parametrize("factory", [*DISTRIBUTIONS.values(), *DRIVERS.values()],
                         ids=[*(f"distribution-{n}" for n in DISTRIBUTIONS), *(f"driver-{n}" for n in DRIVERS)])
def test_every_builtin_parameter_has_its_unit_and_its_description(factory):
    params = set(inspect.signature(factory).parameters)
    assert set(factory.param_units) == params
    assert set(reference._parameters(factory)) == params


def test_every_table_has_its_section_and_the_guide_links_it():
    text = COMMITTED.read_text(encoding="utf-8")
    sections = re.findall(r"^## `\[([\w.]+)\]`$", text, re.M)
    assert {"network", "friction", "friction.strengthening", "units", "solver", "tilt", "tilt.inject", "shs",
            "creep", "dynamics", "execution"} <= set(sections)
    guide = (ROOT / "docs" / "configuration.md").read_text(encoding="utf-8")
    missing = [key for key in sections if f"configuration-reference.md#{reference._anchor(key)})" not in guide]
    assert not missing, f"docs/configuration.md links no section of the reference for {missing}"


@pytest.mark.parametrize(("key", "row"), [
    ("steps", "| `steps` | int | *required* | tau_th | >= 1 |"),
    ("dynamics.rtol", "| `dynamics.rtol` | float | 1e-10 | 1 | in [1e-14, 0.001] |"),
    ("friction.overshoot", "| `friction.overshoot` | float | *unset* | 1 | in [0, 1] |"),
    ("execution.stop_timeout", "| `execution.stop_timeout` | float | 10 | s | > 0, inf allowed |"),
    ("network.incline", "| `network.incline` | float | *unset* | degree | in [0, 90) |"),
    ("seed", "| `seed` | int | *unset* | — | >= 0, \\< 2^128 |"),
    ("solver.max_avalanche", "| `solver.max_avalanche` | int | 1e8 | slips | >= 1 |"),
    ("driver.tau_c", "| `driver.tau_c` | float | *required* | tau_th | Correlation time, in units of tau_th; > 0. "
                     "|"),
], ids=lambda v: v if "|" not in v else "")
def test_rows_read_as_the_models_say(key, row):
    assert row in reference.markdown_reference()


def test_write_puts_the_file_where_the_test_reads_it(tmp_path, capsys):
    (tmp_path / "docs").mkdir()
    assert reference.main(["--write", "--root", str(tmp_path)]) == 0
    assert (tmp_path / reference.REFERENCE_PATH).read_text(encoding="utf-8") == reference.markdown_reference()
    assert reference.main([]) == 0
    assert capsys.readouterr().out == reference.markdown_reference()
