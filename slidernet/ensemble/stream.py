"""The ensemble's result file, written chunk by chunk as realizations come in.

A run with an output directory streams its realizations to ``result.nc``:
memory does not grow with the number of realizations, and the file is
written atomically (a temporary file, then a rename).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np

from slidernet.io import atomic_output


def write_result_stream(records: Iterable[dict], path: str | Path, t: np.ndarray, R: int,
                        observables: list[str], attrs: dict[str, str]) -> Path:
    """Write a result to netCDF chunk by chunk, atomically; memory does not grow with R.

    The same variables and bits as :func:`slidernet.analysis.observables.assemble`
    followed by :func:`write_netcdf`: the per-realization variables go to the
    file one chunk of :data:`slidernet.analysis.observables.CHUNK` realizations at a
    time (stored in chunks of that many realizations), the ensemble
    statistics are reduced on the fly in the same chunks.

    Parameters
    ----------
    records : iterable of dict
        The R realizations' records, in realization order.
    path : path
        The netCDF file to write.
    t : ndarray of int, shape (T,)
        Recorded times.
    R : int
        Number of realizations.
    observables : list of str
        The requested observables.
    attrs : dict
        Global attributes.
    """
    import netCDF4

    from slidernet.analysis.observables import CHUNK, EnsembleStats, chunks, coordinates, realization_variables

    def create(nc, name: str, dims: str | tuple[str, ...], data: np.ndarray, var_attrs: dict) -> netCDF4.Variable:
        dims = (dims,) if isinstance(dims, str) else tuple(dims)
        for i, d in enumerate(dims):  # dimensions without a coordinate (node)
            if d not in nc.dimensions:
                # The creep events are padded to the most of any realization, known only at the end.
                nc.createDimension(d, None if d == "creep_event" else data.shape[i])
        fixed = {"realization": min(CHUNK, R), "event": 1 << 16, "creep_event": 256}
        sizes = [fixed.get(d) or max(1, len(nc.dimensions[d])) for d in dims]
        # Rows of creep events shorter than the dimension read NaN, as assemble pads them.
        fill = np.nan if "creep_event" in dims else False
        var = nc.createVariable(name, data.dtype, dims, fill_value=fill, chunksizes=sizes or None,
                                contiguous=not dims)
        var.setncatts(var_attrs)
        return var

    path = Path(path)
    with atomic_output(path) as tmp, netCDF4.Dataset(tmp, "w", format="NETCDF4") as nc:
        stats = EnsembleStats(observables, int(t[-1]))
        r0 = 0
        for chunk in chunks(records):
            if r0 == 0:
                for name, (dim, data, *rest) in coordinates(t, R, chunk[0]).items():
                    if dim not in nc.dimensions:  # cycle_end shares the dimension cycle
                        nc.createDimension(dim, data.size)
                    create(nc, name, (dim,), data, rest[0] if rest else {})[:] = data
                if "events" in chunk[0]:
                    nc.createDimension("event", None)
            variables = realization_variables(chunk, observables, r0)
            offset = len(nc.dimensions["event"]) if "event" in nc.dimensions else 0
            for name, (dims, data, var_attrs) in variables.items():
                var = nc.variables[name] if name in nc.variables else create(nc, name, dims, data, var_attrs)
                if dims in ("event", ("event",)):
                    var[offset:offset + data.shape[0]] = data
                elif "creep_event" in dims:
                    var[r0:r0 + data.shape[0], :data.shape[1]] = data
                else:
                    var[r0:r0 + data.shape[0]] = data
            stats.add(chunk)
            r0 += len(chunk)
        if r0 != R:
            raise ValueError(f"write_result_stream got {r0} realizations, expected {R}")
        for name, (dims, data, var_attrs) in stats.finish().items():
            data = np.asarray(data)
            create(nc, name, dims, data, var_attrs)[...] = data
        nc.setncatts(attrs)
    return path
