"""Writing and reading result files (netCDF), atomically.

A result is first written to a temporary file in the destination folder and
then renamed over the target, so an interrupted run never leaves a partial
``result.nc``.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import xarray as xr


def write_netcdf(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` atomically (temporary file, then rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def read_result(path: str | Path) -> xr.Dataset:
    """Load a result file fully into memory (the file is closed on return)."""
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()


def result_config(ds: xr.Dataset) -> dict:
    """The resolved configuration stored in a result's attributes."""
    return json.loads(ds.attrs["config"])
