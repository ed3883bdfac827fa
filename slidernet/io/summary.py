"""Summaries as JSON: the plain numbers a study writes beside its figures."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from slidernet.io.netcdf import atomic_output


def _json_ready(value: Any) -> Any:
    """``value`` with every non-finite float as None (JSON has no NaN), containers walked."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    return value


def write_json(data: dict[str, Any], path: str | Path) -> Path:
    """Write ``data`` as indented JSON, atomically, with NaN and infinities as null.

    The file appears whole or not at all (:func:`slidernet.io.atomic_output`):
    an interrupted study never leaves half a summary. Strict JSON readers
    refuse NaN, so a number that could not be measured is written as null.

    Parameters
    ----------
    data : dict
        Plain Python values (numbers, strings, lists, dicts, None).
    path : str or pathlib.Path
        The file to write; its folder is created if need be.

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> out = write_json({"slope": float("nan"), "values": [1.0, 2.5]}, folder / "s.json")
    >>> json.loads(out.read_text())
    {'slope': None, 'values': [1.0, 2.5]}
    """
    path = Path(path)
    with atomic_output(path) as tmp:
        tmp.write_text(json.dumps(_json_ready(data), indent=1, allow_nan=False))
    return path
