"""Writing and reading result files (netCDF), atomically, in one encoding.

A result is first written to a temporary file in the destination folder and
then renamed over the target, so an interrupted run never leaves a partial
``result.nc``.

Two writers make result files: :func:`write_netcdf` (a dataset in memory,
through xarray; or a :class:`xarray.DataTree`, one netCDF4 group per node,
for a sweep whose points differ in number of nodes) and
:func:`result_writer` (a file written piece by piece with netCDF4, for a
run streamed to disk chunk by chunk). Both store every variable, in every
group, as :func:`stored` and :func:`variable_encoding` say, so a file reads
back the same whichever wrote it (:func:`read_result`):

- dtypes are kept: float64 as float64, int64 counts as int64 (never narrowed:
  a run passes 2^31 slips), int8 as int8; a bool is stored as int8 with the
  attribute ``dtype = "bool"`` (xarray's convention: it reads back as bool);
  text as variable-length strings;
- a float variable has ``_FillValue = NaN``: NaN is a value of the results
  (``mu_eff`` where no test was pooled, a standard error of one realization,
  the creep events' padding) and reads back as NaN, and a part of the file
  never written (the padding of a row of creep events) reads NaN too; an
  integer or a string has no fill value;
- every variable with dimensions is chunked (:data:`CHUNKS`, at most
  :data:`MAX_CHUNK_BYTES` a chunk), a scalar is contiguous; nothing is
  compressed; ``event`` and ``creep_event`` are unlimited (:data:`UNLIMITED`:
  a streamed run learns their lengths only at its end);
- every chunk carries HDF5's Fletcher-32 checksum (``fletcher32``), which the
  library checks whenever the chunk is read; a scalar (contiguous: HDF5 has
  no checksum for it) carries the CRC-32 of its value's bytes in the
  attribute :data:`SCALAR_CRC` instead. :func:`read_result` reads every
  variable, so a flipped bit anywhere in the data is a
  :class:`~slidernet.errors.ResultError` naming the file and the variable,
  never a silent wrong value;
- attributes are text or numbers (:func:`check_attrs`), written as netCDF4
  writes them (a string as text, an int as int64, a float as float64); a
  coordinate that is not a dimension's is named in the ``coordinates``
  attribute of the variables it labels (CF, as xarray writes and reads it),
  so that it reads back as a coordinate.

The layout and the attributes of a result, for a user who reads one, are in
``docs/guides/file-formats.md``.
"""

from __future__ import annotations

import json
import math
import numbers
import os
import re
import shutil
import tempfile
import zlib
from collections.abc import Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from slidernet.errors import OutputError, ResultError, SlidernetError


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success rename it over ``path``.

    On any exception (Ctrl-C included) the temporary file is removed and
    ``path`` is left as it was. The file gets the usual permissions (mkstemp
    alone would leave it private to its owner).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


# The name of a temporary file of atomic_output: "." + the target's name + mkstemp's 8 random characters.
_TEMPORARY = re.compile(r"\.(?P<target>.+)\.[A-Za-z0-9_]{8}\.tmp")


def remove_temporaries(folder: str | Path) -> list[Path]:
    """Remove what :func:`atomic_output` (or a folder's removal) left in ``folder`` when its process was killed.

    A process that dies in the middle of a write cannot remove its temporary
    file. Call this only while no other process writes in ``folder``: the
    caller holds the folder's lock (:class:`slidernet.io.store.FolderLock`).

    Returns
    -------
    list of Path
        The files removed.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    removed = [p for p in folder.iterdir() if _TEMPORARY.fullmatch(p.name)]
    for p in removed:
        if p.is_dir():  # a checkpoint folder being removed (slidernet.io.store.RunStore.remove)
            shutil.rmtree(p, ignore_errors=True)
        else:
            p.unlink(missing_ok=True)
    return removed


def reason(exc: OSError) -> str:
    """The OS's words for an error, without the traceback's chain."""
    return exc.strerror or str(exc)


def _umask() -> int:
    # Reading the umask means setting it; put it straight back.
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: Storage chunk along the dimensions a result grows or is read along; any other
#: dimension is stored whole in each chunk. 1024 realizations is also the
#: reduction chunk of a streamed run (``analysis.observables.CHUNK``), so each of
#: its writes fills whole chunks; the event catalogue grows by 65536 slips a chunk.
CHUNKS: dict[str, int] = {"realization": 1024, "event": 1 << 16, "creep_event": 256}

#: Dimensions whose length a streamed run learns only at its end: unlimited in every result file.
UNLIMITED: tuple[str, ...] = ("event", "creep_event")

#: Largest chunk, in bytes: a quarter of netCDF's default chunk cache (64 MiB per
#: variable, ``netCDF4.get_chunk_cache()``). Without it a chunk of 1024
#: realizations of 1e5 recorded times would be 819 MB, read whole for one value.
MAX_CHUNK_BYTES = 16 * 2**20

#: The attribute of a scalar variable that holds the CRC-32 of its value (8 hex digits of the value's
#: little-endian bytes): HDF5 keeps no checksum for a contiguous variable. Written by both writers,
#: checked and removed by :func:`read_result`.
SCALAR_CRC = "crc32"


def variable_encoding(dims: Sequence[str], shape: Sequence[int], dtype: np.dtype) -> dict[str, Any]:
    """How one variable is stored: the one rule of both result writers.

    Parameters
    ----------
    dims : sequence of str
        The variable's dimensions.
    shape : sequence of int
        Their lengths in the file (a length along an unlimited dimension is
        not used).
    dtype : numpy.dtype
        The data's dtype (a bool is stored as int8: :func:`stored`).

    Returns
    -------
    dict
        xarray's encoding keys for the netCDF4 engine: ``dtype`` (where this
        rule sets it), ``_FillValue``, ``zlib``, ``fletcher32``,
        ``contiguous`` and ``chunksizes``. A dtype other than a number or
        text (dates, say) is left to xarray's own conventions, and refused by
        :func:`result_writer`.

    >>> variable_encoding(("realization", "t"), (3000, 41), np.dtype(np.int64))["chunksizes"]
    (1024, 41)
    >>> enc = variable_encoding(("t",), (41,), np.dtype(np.float64))
    >>> enc["dtype"], bool(np.isnan(enc["_FillValue"]))
    (dtype('float64'), True)
    """
    dtype = np.dtype(dtype)
    enc: dict[str, Any] = {"zlib": False, "fletcher32": False}
    if dtype.kind == "f":
        enc.update(dtype=dtype, _FillValue=dtype.type(np.nan))
    elif dtype.kind in "iu":
        enc.update(dtype=dtype, _FillValue=None)
    elif dtype.kind == "b":
        enc.update(dtype=np.dtype(np.int8), _FillValue=None)
    elif dtype.kind == "U":
        enc.update(dtype=str, _FillValue=None)
    if not dims:
        enc["contiguous"] = True
        return enc
    chunks = [CHUNKS[d] if d in UNLIMITED else max(1, min(CHUNKS.get(d, n), n))
              for d, n in zip(dims, shape, strict=True)]
    itemsize = dtype.itemsize if dtype.kind in "biuf" else 8  # text: one pointer per string
    while math.prod(chunks) * itemsize > MAX_CHUNK_BYTES and max(chunks) > 1:
        k = chunks.index(max(chunks))
        chunks[k] = (chunks[k] + 1) // 2
    # A checksum per chunk (4 bytes), checked by HDF5 at every read of the chunk.
    enc.update(contiguous=False, chunksizes=tuple(chunks), fletcher32=True)
    return enc


_ATTR_TYPES = (str, bytes, numbers.Number, np.ndarray, list, tuple)


def check_attrs(attrs: Mapping[str, Any], owner: str) -> None:
    """Refuse an attribute netCDF cannot store: text, numbers and arrays or lists of them only.

    A bool is refused too (netCDF has no bool attribute; xarray refuses
    numpy's and netCDF4 Python's), so that a file never gets a number where
    a flag was meant.

    Raises
    ------
    TypeError
        Naming the attribute, its owner and its value.
    """
    for key, value in attrs.items():
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, _ATTR_TYPES):
            raise TypeError(f"The attribute {key!r} of {owner} cannot be stored in netCDF: {value!r} is a "
                            f"{type(value).__name__}; give text or a number.")


def stored(name: str, dims: Sequence[str], data: Any, attrs: Mapping[str, Any],
           aux: Mapping[str, Sequence[str]]) -> tuple[Any, dict[str, Any]]:
    """A variable's data and attributes as both writers store them.

    Parameters
    ----------
    name : str
    dims : sequence of str
    data : array_like
        Returned as it is, except a bool array, returned as int8.
    attrs : mapping
        The variable's attributes (checked by :func:`check_attrs`).
    aux : mapping of str to sequence of str
        The result's coordinates that are not a dimension's, with their
        dimensions.

    Returns
    -------
    data : array_like
    attrs : dict
        With ``dtype = "bool"`` for a bool, ``coordinates``, the
        coordinates of ``aux`` that label this variable (those whose
        dimensions are all among its own; a coordinate lists none), and for
        a numeric scalar :data:`SCALAR_CRC`, its checksum (any such
        attribute given is replaced: it belongs to the value stored now).
    """
    attrs = dict(attrs)
    attrs.pop(SCALAR_CRC, None)
    check_attrs(attrs, f"the variable {name!r}")
    if not hasattr(data, "dtype"):
        data = np.asarray(data)
    if data.dtype == bool:
        data = np.asarray(data).astype(np.int8)
        attrs["dtype"] = "bool"
    if not dims and data.dtype.kind in "biuf":
        attrs[SCALAR_CRC] = _crc32(np.asarray(data))
    if name not in aux and name not in dims and "coordinates" not in attrs:
        labels = sorted(c for c, c_dims in aux.items() if set(c_dims) <= set(dims))
        if labels:
            attrs["coordinates"] = " ".join(labels)
    return data, attrs


def _crc32(value: np.ndarray) -> str:
    """The CRC-32 of a number's little-endian bytes, as 8 hex digits (:data:`SCALAR_CRC`)."""
    little = np.ascontiguousarray(value, dtype=value.dtype.newbyteorder("<"))
    return f"{zlib.crc32(little.tobytes()):08x}"


@contextmanager
def _netcdf_output(path: str | Path) -> Iterator[Path]:
    """:func:`atomic_output` for a netCDF file: a failed write is an :class:`OutputError` naming ``path``.

    netCDF reports a full disk or a file size limit as ``RuntimeError: NetCDF:
    HDF error``, naming neither the file nor the cause; the cause is found
    here from the limit and the free space (:func:`_why_not_written`).
    """
    path = Path(path)
    with atomic_output(path) as tmp:
        try:
            yield tmp
        except (RuntimeError, OSError) as exc:
            if isinstance(exc, SlidernetError) or not (type(exc) is RuntimeError or isinstance(exc, OSError)):
                raise  # an error of slidernet's own, or a plugin's: not the file's
            raise OutputError(f"Cannot write the result file {str(path)!r}: {_why_not_written(tmp, exc)}.") \
                from None


def _why_not_written(tmp: Path, exc: BaseException) -> str:
    """Why a write to ``tmp`` failed, in words: the size limit (ulimit -f), a full disk, or the library's."""
    said = (reason(exc) if isinstance(exc, OSError) else str(exc)) or type(exc).__name__
    try:
        import resource  # POSIX only

        size = tmp.stat().st_size
        soft = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
        stat = os.statvfs(tmp.parent)
    except (ImportError, OSError, AttributeError):
        return said
    # A write that crosses the limit stops at it; HDF5 writes at most a chunk (MAX_CHUNK_BYTES) at a time.
    if soft != resource.RLIM_INFINITY and size + MAX_CHUNK_BYTES >= soft:
        return f"the file reached this process's file size limit (ulimit -f: {soft} bytes) ({said})"
    if stat.f_bavail * stat.f_frsize < MAX_CHUNK_BYTES:
        return f"the disk is full ({said})"
    return said


def write_netcdf(result: xr.Dataset | xr.DataTree, path: str | Path) -> Path:
    """Write ``result`` to ``path`` atomically (temporary file, then rename), in the results' encoding.

    Every variable is stored as :func:`stored` and :func:`variable_encoding`
    say, whatever encoding ``result`` carries (a dataset read from a file
    carries that file's): a file written here reads back as one written by
    :func:`result_writer`. A :class:`xarray.DataTree` (a sweep whose points
    differ in number of nodes, :func:`slidernet.ensemble.sweep.sweep`) is
    written as netCDF4 groups, one per node of the tree, each group in
    this same encoding; a child's coordinates inherited from its parents
    are written once, in the parent's group (xarray's rule).

    Parameters
    ----------
    result : xarray.Dataset or xarray.DataTree
    path : path
        The file to write; missing folders are made.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    if isinstance(result, xr.DataTree):
        groups: dict[str, xr.Dataset] = {}
        encodings: dict[str, dict[str, dict[str, Any]]] = {}
        unlimited: dict[str, list[str]] = {}
        for node in result.subtree:
            owner = "the dataset" if node is result else f"the group {node.path!r}"
            groups[node.path], encodings[node.path] = _stored_dataset(node.to_dataset(inherit=False), owner)
            unlimited[node.path] = [d for d in UNLIMITED if d in groups[node.path].dims]
        tree = xr.DataTree.from_dict(groups)
        with _netcdf_output(path) as tmp:
            tree.to_netcdf(tmp, engine="netcdf4", encoding=encodings, unlimited_dims=unlimited)
        return Path(path)
    out, encoding = _stored_dataset(result, "the dataset")
    with _netcdf_output(path) as tmp:
        out.to_netcdf(tmp, engine="netcdf4", encoding=encoding,
                      unlimited_dims=[d for d in UNLIMITED if d in out.dims])
    return Path(path)


def _stored_dataset(ds: xr.Dataset, owner: str) -> tuple[xr.Dataset, dict[str, dict[str, Any]]]:
    """``ds`` as it is stored (:func:`stored`) and the encoding of each of its variables."""
    check_attrs(ds.attrs, owner)
    aux = {name: ds[name].dims for name in ds.coords if name not in ds.dims}
    variables: dict[str, xr.Variable] = {}
    encoding: dict[str, dict[str, Any]] = {}
    for name, var in ds.variables.items():
        data, attrs = stored(str(name), var.dims, var.values if var.dtype == bool else var.data, var.attrs, aux)
        variables[name] = xr.Variable(var.dims, data, attrs)
        encoding[name] = variable_encoding(var.dims, var.shape, variables[name].dtype)
    out = xr.Dataset({n: v for n, v in variables.items() if n not in ds.coords},
                     coords={n: v for n, v in variables.items() if n in ds.coords}, attrs=ds.attrs)
    return out, encoding


class ResultWriter:
    """An open result file, written variable by variable and piece by piece (netCDF4).

    Made by :func:`result_writer`, which writes it atomically. Each
    variable is created by its first :meth:`write`, stored as
    :func:`write_netcdf` stores it; its dimensions are created with the
    variable's first data (unlimited for :data:`UNLIMITED`), so a dimension
    must first come whole: write the coordinates first.
    """

    def __init__(self, nc: Any) -> None:
        self._nc = nc
        self._aux: dict[str, tuple[str, ...]] = {}  # coordinates that are not a dimension's
        self._labelled: set[str] = set()  # those named by some variable's 'coordinates'

    def size(self, dim: str) -> int:
        """The length of ``dim`` so far (0 before it exists)."""
        return len(self._nc.dimensions[dim]) if dim in self._nc.dimensions else 0

    def write(self, name: str, dims: str | Sequence[str], data: Any, attrs: Mapping[str, Any] | None = None, *,
              start: Mapping[str, int] | None = None, coordinate: bool = False) -> None:
        """Write ``data`` into the variable ``name``, created first if it is new.

        Parameters
        ----------
        name : str
        dims : str or sequence of str
            The variable's dimensions (a str for one).
        data : array_like
            Of one length per dimension; its place along each dimension starts
            at ``start[dim]`` (default 0), so that a piece can extend an
            unlimited dimension.
        attrs : mapping, optional
            The variable's attributes, used where it is created.
        start : mapping of str to int, optional
            Offsets along the dimensions; dimensions the variable does not
            have are ignored.
        coordinate : bool
            The variable is a coordinate: one that is not a dimension's
            (``name`` not in ``dims``) is named in the ``coordinates``
            attribute of the variables created after it that it labels.
        """
        dims = (dims,) if isinstance(dims, str) else tuple(dims)
        data = np.asarray(data)
        if name not in self._nc.variables:
            self._create(name, dims, data, attrs or {}, coordinate)
        var = self._nc.variables[name]
        start = start or {}
        if data.dtype == bool:
            data = data.astype(np.int8)
        at = tuple(slice(start.get(d, 0), start.get(d, 0) + n) for d, n in zip(dims, data.shape, strict=True))
        var[at if dims else ...] = data

    def _create(self, name: str, dims: tuple[str, ...], data: np.ndarray, attrs: Mapping[str, Any],
                coordinate: bool) -> None:
        if data.dtype.kind not in "biufU":
            raise TypeError(f"The variable {name!r} has dtype {data.dtype}, which a result file does not store "
                            "(numbers, bools and text only).")
        for d, n in zip(dims, data.shape, strict=True):
            if d not in self._nc.dimensions:
                self._nc.createDimension(d, None if d in UNLIMITED else n)
        data, attrs = stored(name, dims, data, attrs, self._aux)
        enc = variable_encoding(dims, [self.size(d) for d in dims], data.dtype)
        var = self._nc.createVariable(name, enc.get("dtype", data.dtype), dims, zlib=enc["zlib"],
                                      fletcher32=enc["fletcher32"], contiguous=enc["contiguous"],
                                      chunksizes=enc.get("chunksizes"), fill_value=enc["_FillValue"])
        for key, value in attrs.items():
            _set_attribute(var, key, value)
        self._labelled.update(attrs.get("coordinates", "").split())
        if coordinate and name not in dims:
            self._aux[name] = dims

    def set_attrs(self, attrs: Mapping[str, Any]) -> None:
        """Set the file's global attributes (checked by :func:`check_attrs`)."""
        check_attrs(attrs, "the dataset")
        for key, value in attrs.items():
            _set_attribute(self._nc, key, value)

    def _finish(self) -> None:
        # A coordinate that labels no variable is named in a global 'coordinates', as xarray writes it.
        unlabelled = sorted(set(self._aux) - self._labelled)
        if unlabelled:
            self._nc.setncattr("coordinates", " ".join(unlabelled))


def _set_attribute(obj: Any, key: str, value: Any) -> None:
    """Set one attribute as xarray's netCDF4 backend does: a list of strings as strings, anything else as given."""
    if isinstance(value, (list, tuple)) and value and all(isinstance(v, str) for v in value):
        obj.setncattr_string(key, value)
    else:
        obj.setncattr(key, value)


@contextmanager
def result_writer(path: str | Path) -> Iterator[ResultWriter]:
    """Write a result file piece by piece, atomically: a :class:`ResultWriter` on a temporary file.

    The file is renamed over ``path`` when the block ends, and removed
    instead on any exception (Ctrl-C included): ``path`` is never half
    written. A scalar is written whole by its first :meth:`ResultWriter.write`
    (its checksum, :data:`SCALAR_CRC`, is that value's).

    Raises
    ------
    OutputError
        If the file cannot be written (a full disk, the file size limit),
        naming it and the cause.

    Parameters
    ----------
    path : path
        The file to write; missing folders are made.

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "result.nc"
    >>> with result_writer(path) as out:
    ...     out.write("realization", "realization", np.arange(3), coordinate=True)
    ...     for r in range(3):
    ...         out.write("n", "realization", [10 * r], {"units": "1"}, start={"realization": r})
    >>> read_result(path)["n"].values.tolist()
    [0, 10, 20]
    """
    import netCDF4

    with _netcdf_output(path) as tmp, netCDF4.Dataset(tmp, "w", format="NETCDF4") as nc:
        writer = ResultWriter(nc)
        yield writer
        writer._finish()


def save_figure(fig, path: str | Path, **savefig_kwargs) -> Path:
    """Save a matplotlib figure to ``path`` atomically (temporary file, then rename)."""
    path = Path(path)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", **savefig_kwargs)
    return path


def read_result(path: str | Path) -> xr.Dataset | xr.DataTree:
    """Load a result file fully into memory, every checksum checked (the file is closed on return).

    Parameters
    ----------
    path : path
        A result file: of a run, of a sweep, or any file :func:`write_netcdf`
        or :func:`result_writer` wrote.

    Returns
    -------
    xarray.Dataset or xarray.DataTree
        What was written: a file without groups as a Dataset (every result
        of a run, a sweep whose points have the same number of nodes); a
        file with groups as a DataTree, its root the file's root group (a
        sweep whose points differ in number of nodes: the stacked variables
        at the root, each point's per-node variables in its group
        ``point_<i>``; :mod:`slidernet.ensemble.sweep`).

    Raises
    ------
    ResultError
        If the file is not a netCDF file, is truncated, or a variable's data
        fail their checksum (``fletcher32``, or :data:`SCALAR_CRC` for a
        scalar), naming the file and the variable. A file written before
        the checksums were (no ``fletcher32``) is read without them.
    """
    path = Path(path)
    groups = _checked_scalars(path)
    try:
        if groups:
            with xr.open_datatree(path, engine="netcdf4") as tree:
                for node in tree.subtree:
                    _load_each(node.dataset.variables, path, node.path)
                result = tree.load()
                for node in result.subtree:
                    _drop_crc(node.dataset.variables.values())
                return result
        with xr.open_dataset(path, engine="netcdf4") as ds:
            _load_each(ds.variables, path, "/")
            result = ds.load()
    except ResultError:
        raise
    except _DAMAGE as exc:
        raise _damaged(path, exc) from None
    _drop_crc(result.variables.values())
    return result


def open_result(path: str | Path) -> xr.Dataset:
    """Open a result file without groups lazily (``xarray.open_dataset``); its scalars' checksums checked.

    The chunks' checksums are checked by HDF5 as the data are read. Close
    the dataset (or use it in a ``with`` block) when done.
    """
    path = Path(path)
    _checked_scalars(path)
    ds = xr.open_dataset(path, engine="netcdf4")
    _drop_crc(ds.variables.values())
    return ds


def _load_each(variables: Mapping[Any, xr.Variable], path: Path, group: str) -> None:
    """Read every variable once, so that a checksum that fails names its variable."""
    for name, var in variables.items():
        try:
            var.load()
        except _DAMAGE as exc:
            where = f"{name!r}" if group == "/" else f"{name!r} of the group {group!r}"
            raise ResultError(
                f"The result file {str(path)!r} is damaged: the data of {where} cannot be read back intact "
                f"(a chunk fails its fletcher32 checksum, or the file is truncated: {exc})."
            ) from None


def _checked_scalars(path: Path) -> bool:
    """Check the :data:`SCALAR_CRC` of every scalar, in every group; return whether the file has groups."""
    import netCDF4

    try:
        with netCDF4.Dataset(path, "r") as nc:
            todo = [nc]
            while todo:
                group = todo.pop()
                todo.extend(group.groups.values())
                for name, var in group.variables.items():
                    if var.dimensions or SCALAR_CRC not in var.ncattrs():
                        continue
                    var.set_auto_maskandscale(False)
                    if _crc32(np.asarray(var[...])) != var.getncattr(SCALAR_CRC):
                        where = f"{name!r}" if group is nc else f"{name!r} of the group {group.path!r}"
                        raise ResultError(f"The result file {str(path)!r} is damaged: the value of {where} fails "
                                          f"its checksum ({SCALAR_CRC}).")
            return bool(nc.groups)
    except (FileNotFoundError, ResultError):
        raise
    except _DAMAGE as exc:
        raise _damaged(path, exc) from None


# What netCDF4 and xarray raise on a damaged file: HDF5 checks its metadata's checksums too, and a
# flipped bit there gave "AttributeError: NetCDF: Can't open HDF5 attribute" (found by flipping bits).
_DAMAGE = (OSError, RuntimeError, AttributeError, KeyError, ValueError, IndexError)


def _damaged(path: Path, exc: BaseException) -> ResultError:
    return ResultError(f"The result file {str(path)!r} cannot be read: it is not a netCDF file, or it is "
                       f"truncated or damaged ({exc}).")


def _drop_crc(variables: Iterable[xr.Variable]) -> None:
    """Remove :data:`SCALAR_CRC` from the attributes read back: it describes the file, not the value."""
    for var in variables:
        var.attrs.pop(SCALAR_CRC, None)


def result_config(ds: xr.Dataset | xr.DataTree) -> dict:
    """The resolved configuration stored in a result's attributes."""
    return json.loads(ds.attrs["config"])
