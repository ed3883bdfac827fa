"""The ensemble's result file, written chunk by chunk as realizations come in.

A run with an output directory streams its realizations to ``result.nc``:
memory does not grow with the number of realizations. The reduction is
here (it needs :mod:`slidernet.analysis.observables`, a stage above
:mod:`slidernet.io`); the file itself, its encoding and its atomic write are
:func:`slidernet.io.result_writer`'s, the same as :func:`slidernet.io.write_netcdf`'s.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np

from slidernet.io import result_writer


def write_result_stream(records: Iterable[dict], path: str | Path, t: np.ndarray, R: int,
                        observables: list[str], attrs: dict[str, str], size_bins: int | None = None) -> Path:
    """Write a result to netCDF chunk by chunk, atomically; memory does not grow with R.

    The same variables, bits and encoding as :func:`slidernet.analysis.observables.assemble`
    followed by :func:`~slidernet.io.write_netcdf`: the per-realization variables go to the
    file one chunk of :data:`slidernet.analysis.observables.CHUNK` realizations at a
    time, the ensemble statistics are reduced on the fly in the same chunks.

    Parameters
    ----------
    records : iterable of dict
        The R realizations' records, in realization order.
    path : path
        The netCDF file to write.
    t : ndarray of int, shape (T,)
        Recorded times, in tau_th.
    R : int
        Number of realizations.
    observables : list of str
        The requested observables.
    attrs : dict
        Global attributes.
    size_bins : int, optional
        The avalanche size bins to keep, :func:`slidernet.analysis.observables.avalanche_bins`
        over every realization (assemble finds them itself; here the first chunk is
        written before the last is read). Required where the records count avalanches.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        If the records count avalanches and ``size_bins`` is not given, or
        there are not R of them.
    """
    from slidernet.analysis.observables import EnsembleStats, chunks, coordinates, realization_variables

    path = Path(path)
    with result_writer(path) as out:
        stats = EnsembleStats(observables, int(t[-1]))
        r0 = 0
        for chunk in chunks(records):
            if r0 == 0:  # the coordinates come whole, and first: they make the dimensions
                if "avalanche_count" in chunk[0] and size_bins is None:
                    raise ValueError("write_result_stream needs size_bins for records that count avalanches")
                for name, (dim, data, *rest) in coordinates(t, R, chunk[0], size_bins).items():
                    out.write(name, dim, data, rest[0] if rest else {}, coordinate=True)
            # This chunk's slips go on where the previous chunk's ended; rows of creep
            # events shorter than the longest so far read NaN, as assemble pads them.
            start = {"realization": r0, "event": out.size("event")}
            for name, (dims, data, var_attrs) in realization_variables(chunk, observables, r0, size_bins).items():
                out.write(name, dims, data, var_attrs, start=start)
            stats.add(chunk)
            r0 += len(chunk)
        if r0 != R:
            raise ValueError(f"write_result_stream got {r0} realizations, expected {R}")
        for name, (dims, data, var_attrs) in stats.finish().items():
            out.write(name, dims, data, var_attrs)
        out.set_attrs(attrs)
    return path
