"""One encoding for every result file: a run written from memory (write_netcdf) and a run streamed to disk
(result_writer, through write_result_stream) give the same file layout and read back the same.

Before the two writers shared slidernet.io.netcdf.variable_encoding, they differed: write_netcdf stored every
variable contiguous, with fixed dimensions and _FillValue = NaN on every float; the stream chunked every
variable, made 'event' and 'creep_event' unlimited, set no _FillValue but on the creep events, and wrote no
'coordinates' attribute, so that 'cycle_end' read back as a data variable instead of a coordinate.
"""

from __future__ import annotations

import json
import warnings

import netCDF4
import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.io import read_result, result_writer, write_netcdf
from slidernet.io.netcdf import CHUNKS, MAX_CHUNK_BYTES, variable_encoding


def _config(network: dict, observables: list[str], driver: dict | None = None) -> dict:
    return {"seed": 3, "realizations": 3, "steps": 30, "record": "all", "observables": observables,
            "network": {"Ntilde": 1e-7, **network},
            "friction": {"mu_d": 0.5, "static": {"name": "uniform", "low": 0.55, "high": 0.65}},
            "driver": driver or {"name": "gaussian_steps", "sigma_theta": 1e-6},
            "execution": {"workers": 1}}


RUNS = {
    # The pair kernel with the appendix's tilt test: NaN in mu_eff where no test was pooled.
    "pair": _config({"kind": "two_slider"}, ["n", "mu_max", "x_G", "mu_eff", "n_records"]),
    # A chain on an incline: the event catalogue (unlimited), int8 flags, int64 counts, slid_away_at.
    "chain": _config({"kind": "chain", "n": 4, "incline": 5.0},
                     ["n", "mu_max", "x_G", "mu_eff", "events", "mu_min", "node_slips"]),
    # A lattice with the creep observables: the coordinate cycle_end, creep events padded with NaN.
    "creep": _config({"kind": "triangular", "shape": [3, 3]}, ["n", "x_G", "creep", "events", "y_G"],
                     {"name": "sinusoidal", "amplitude": 1e-6, "period": 10, "noise_std": 1e-7}),
}


def layout(path, group: str | None = None) -> dict:
    """What a file stores, read with netCDF4 (no decoding): dimensions, and per variable its dtype on disk,
    dimensions, fill value, chunking, filters and attributes; the global attributes (of ``group``, a group's
    name, else of the root group)."""
    with netCDF4.Dataset(path) as root:
        nc = root if group is None else root.groups[group]
        out = {"dims": {d: (len(v), v.isunlimited()) for d, v in nc.dimensions.items()},
               "attrs": {k: (type(v).__name__, v) for k, v in nc.__dict__.items()}}
        for name, var in nc.variables.items():
            attrs = {k: (type(v).__name__, v) for k, v in var.__dict__.items() if k != "_FillValue"}
            fill = var.__dict__.get("_FillValue")
            out[name] = {"dtype": str(var.dtype), "dims": var.dimensions, "chunking": var.chunking(),
                         "filters": {k: v for k, v in (var.filters() or {}).items() if v}, "attrs": attrs,
                         "fill": None if fill is None else ("nan" if np.isnan(fill) else fill)}
    return out


def assert_same_result(a: xr.Dataset, b: xr.Dataset) -> None:
    """The same variables and coordinates, dtypes, bits (NaN where the other has NaN) and attributes."""
    assert set(a.variables) == set(b.variables)
    assert set(a.coords) == set(b.coords)
    for name in a.variables:
        assert a[name].dtype == b[name].dtype, name
        assert a[name].dims == b[name].dims, name
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        assert a[name].attrs == b[name].attrs, name
    assert a.attrs.keys() == b.attrs.keys()


@pytest.mark.parametrize("case", list(RUNS))
def test_a_run_in_memory_and_streamed_gives_the_same_file(case, tmp_path):
    cfg = RUNS[case]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a chain on an incline may warn that it slid away
        memory = slidernet.run(cfg)
        write_netcdf(memory, tmp_path / "memory.nc")
        slidernet.run(cfg, out=tmp_path / "out").close()
    streamed = tmp_path / "out" / "result.nc"
    a, b = layout(tmp_path / "memory.nc"), layout(streamed)
    volatile = {"execution", "slidernet_version"}
    a["attrs"] = {k: v for k, v in a["attrs"].items() if k not in volatile}
    b["attrs"] = {k: v for k, v in b["attrs"].items() if k not in volatile}
    assert a.keys() == b.keys()
    for key in a:
        assert a[key] == b[key], key
    back = read_result(tmp_path / "memory.nc")
    assert_same_result(back, read_result(streamed))
    assert_same_result(back, memory)  # and both are the dataset in memory
    assert json.loads(back.attrs["config"]) == json.loads(memory.attrs["config"])
    if case == "creep":
        assert "cycle_end" in read_result(streamed).coords
        assert np.isnan(back["creep_event_time"].values).any()  # the padding


def _dataset() -> xr.Dataset:
    """Every kind of variable a result file may hold, including the ones no run makes today."""
    R, T = 3, 4
    counts = np.arange(R * T, dtype=np.int64).reshape(R, T) + 2**31 - 5  # past int32
    x = np.linspace(0.0, 1.0, R * T).reshape(R, T)
    x[1, 2] = np.nan
    return xr.Dataset(
        {"n": (("realization", "t"), counts, {"long_name": "count", "units": "1"}),
         "x": (("realization", "t"), x, {"units": "l0", "scale": 0.5}),
         "flag": ("realization", np.array([True, False, True]), {"long_name": "a flag"}),
         "label": ("realization", np.array(["a", "bb", "ccc"]), {"long_name": "text"}),
         "event_time": ("event", np.array([0.5, 1.5, np.nan, 2.5])),
         "rate": ((), np.float64(np.nan), {"long_name": "undefined with one realization"})},
        coords={"realization": ("realization", np.arange(R, dtype=np.int64)),
                "t": ("t", np.arange(T, dtype=np.int64), {"units": "tau_th"}),
                "t_end": ("t", np.arange(T, dtype=np.float64) + 0.5, {"units": "tau_th"})},
        attrs={"config": json.dumps({"seed": 1}), "seed": "1", "count": 7, "ratio": 0.25,
               "names": ["one", "two"]},
    )


def test_the_piecewise_writer_stores_any_variable_as_write_netcdf_does(tmp_path):
    ds = _dataset()
    write_netcdf(ds, tmp_path / "memory.nc")
    with result_writer(tmp_path / "pieces.nc") as out:
        for name in ("realization", "t", "t_end"):
            out.write(name, ds[name].dims, ds[name].values, ds[name].attrs, coordinate=True)
        for r in range(ds.sizes["realization"]):  # one realization at a time, as a stream does
            for name in ("n", "x", "flag", "label"):
                out.write(name, ds[name].dims, ds[name].values[r:r + 1], ds[name].attrs, start={"realization": r})
        for k in range(0, 4, 2):  # the unlimited dimension grows piece by piece
            out.write("event_time", "event", ds["event_time"].values[k:k + 2], start={"event": out.size("event")})
        out.write("rate", (), ds["rate"].values, ds["rate"].attrs)
        out.set_attrs(ds.attrs)
    assert layout(tmp_path / "memory.nc") == layout(tmp_path / "pieces.nc")
    back = read_result(tmp_path / "pieces.nc")
    xr.testing.assert_identical(back, ds)
    assert back["flag"].dtype == bool and back["n"].dtype == np.int64 and back["label"].dtype.kind in "UO"
    assert int(back["n"].max()) == 2**31 + 6
    with netCDF4.Dataset(tmp_path / "pieces.nc") as nc:
        assert nc["flag"].dtype == np.int8 and nc["flag"].getncattr("dtype") == "bool"
        assert nc["x"].getncattr("coordinates") == "t_end" and "coordinates" not in nc["flag"].ncattrs()
        assert nc.dimensions["event"].isunlimited()


def test_a_dataset_s_own_encoding_does_not_change_the_file(tmp_path):
    # A dataset read back from a file carries that file's encoding; write_netcdf stores it by the one rule.
    ds = _dataset()
    first = write_netcdf(ds, tmp_path / "first.nc")
    again = read_result(first)
    again["x"].encoding.update(zlib=True, complevel=4, chunksizes=(1, 1))
    write_netcdf(again, tmp_path / "again.nc")
    assert layout(first) == layout(tmp_path / "again.nc")


def test_chunks_stay_below_the_cap():
    enc = variable_encoding(("realization", "t"), (5000, 100_001), np.dtype(np.float64))
    rows, cols = enc["chunksizes"]
    assert rows == CHUNKS["realization"] and rows * cols * 8 <= MAX_CHUNK_BYTES
    assert variable_encoding(("realization", "t"), (2, 41), np.dtype(np.int64))["chunksizes"] == (2, 41)
    assert variable_encoding(("event",), (5,), np.dtype(np.float64))["chunksizes"] == (CHUNKS["event"],)
    assert variable_encoding((), (), np.dtype(np.float64))["contiguous"] is True


@pytest.mark.parametrize("value", [True, None, {"a": 1}], ids=["bool", "none", "dict"])
def test_both_writers_refuse_an_attribute_netcdf_cannot_hold(value, tmp_path):
    ds = xr.Dataset({"x": ("t", np.zeros(2))}, attrs={"odd": value})
    with pytest.raises(TypeError, match="The attribute 'odd' of the dataset cannot be stored in netCDF"):
        write_netcdf(ds, tmp_path / "a.nc")
    with pytest.raises(TypeError, match="The attribute 'odd' of the dataset cannot be stored in netCDF"):
        with result_writer(tmp_path / "b.nc") as out:
            out.write("x", "t", np.zeros(2))
            out.set_attrs(ds.attrs)
    assert list(tmp_path.iterdir()) == []


def test_an_interrupted_piecewise_write_leaves_the_previous_file(tmp_path):
    path = write_netcdf(_dataset(), tmp_path / "result.nc")
    before = path.read_bytes()
    with pytest.raises(KeyboardInterrupt):
        with result_writer(path) as out:
            out.write("realization", "realization", np.arange(5), coordinate=True)
            raise KeyboardInterrupt
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["result.nc"]


def test_every_group_of_a_tree_is_stored_as_a_dataset_is(tmp_path):
    # A sweep over network size writes a DataTree: every group in the one encoding, inherited coordinates once.
    ds = _dataset()
    root = ds.drop_vars(["flag", "label"])
    child = xr.Dataset({"flag": ds["flag"].variable, "label": ds["label"].variable,
                        "node_slips": (("realization", "node"), np.arange(12, dtype=np.int64).reshape(3, 4)),
                        "mu_s": (("realization", "node"), np.full((3, 4), np.nan), {"units": "1"})},
                        attrs={"sweep_point": 1, "config": json.dumps({"seed": 1})})
    tree = xr.DataTree.from_dict({"/": root, "point_1": child})
    write_netcdf(tree, tmp_path / "tree.nc")
    write_netcdf(root, tmp_path / "root.nc")
    write_netcdf(child.assign_coords(realization=ds["realization"]), tmp_path / "child.nc")
    assert layout(tmp_path / "tree.nc") == layout(tmp_path / "root.nc")
    in_group, alone = layout(tmp_path / "tree.nc", "point_1"), layout(tmp_path / "child.nc")
    assert "realization" not in in_group and in_group["dims"] == {"node": (4, False)}  # inherited, stored once
    for name in child.data_vars:
        assert in_group[name] == alone[name], name
    assert in_group["attrs"] == alone["attrs"]
    back = read_result(tmp_path / "tree.nc")
    assert isinstance(back, xr.DataTree)
    xr.testing.assert_identical(back, tree)
    assert back["point_1"]["flag"].dtype == bool and back["point_1"]["node_slips"].dtype == np.int64
    assert isinstance(read_result(tmp_path / "root.nc"), xr.Dataset)  # a file without groups: a Dataset


def test_a_group_s_attribute_is_checked_by_its_name(tmp_path):
    tree = xr.DataTree.from_dict({"/": xr.Dataset(attrs={"seed": "1"}),
                                  "point_0": xr.Dataset(attrs={"odd": True})})
    with pytest.raises(TypeError, match="The attribute 'odd' of the group '/point_0' cannot be stored"):
        write_netcdf(tree, tmp_path / "tree.nc")
    assert list(tmp_path.iterdir()) == []
