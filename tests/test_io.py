"""Result files: atomic netCDF writing, lossless reading, provenance attributes."""

from __future__ import annotations

import json

import netCDF4
import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.errors import ResultError
from slidernet.io import read_result, result_config, write_netcdf
from slidernet.io.netcdf import SCALAR_CRC
from tests.conftest import make_config


@pytest.fixture(scope="module")
def result() -> xr.Dataset:
    # Every variable kind: per realization, ensemble statistics, scalars, mu_eff.
    cfg = make_config(steps=50, realizations=3,
                      observables=["n", "mu_max", "x_G", "mu_eff", "n_records"])
    return slidernet.run(cfg)


def test_round_trip_is_identical(result, tmp_path):
    path = write_netcdf(result, tmp_path / "result.nc")
    assert path == tmp_path / "result.nc"
    back = read_result(path)
    xr.testing.assert_identical(back, result)
    assert back["n"].dtype == result["n"].dtype  # int64 stays int64
    # read_result closes the file: it can be removed at once.
    path.unlink()
    assert back["mu_max"].values.size > 0  # still usable: loaded in memory


def test_write_creates_missing_folders_and_overwrites(result, tmp_path):
    path = tmp_path / "a" / "b" / "result.nc"
    write_netcdf(result.isel(realization=[0]), path)
    write_netcdf(result, path)
    assert read_result(path).sizes["realization"] == 3
    assert sorted(p.name for p in path.parent.iterdir()) == ["result.nc"]


def test_attributes_hold_the_provenance(result, tmp_path):
    back = read_result(write_netcdf(result, tmp_path / "result.nc"))
    config = json.loads(back.attrs["config"])
    assert config == result_config(back)
    assert config["seed"] == 1 and back.attrs["seed"] == "1"
    assert config["steps"] == 50
    assert config["friction"]["static"] == {"name": "gaussian", "mean": 0.6, "std": 0.01}
    assert back.attrs["slidernet_version"] == slidernet.__version__
    # The stored config runs again to the same result.
    xr.testing.assert_identical(slidernet.run(config), result)


def test_unset_seed_is_resolved_and_stored(tmp_path):
    cfg = make_config(steps=20, realizations=2, observables=["n"], seed=None)
    assert "seed" not in cfg
    ds = read_result(write_netcdf(slidernet.run(cfg), tmp_path / "result.nc"))
    seed = json.loads(ds.attrs["config"])["seed"]
    assert isinstance(seed, int) and seed >= 0
    assert ds.attrs["seed"] == str(seed)
    # The stored seed reproduces the run.
    again = slidernet.run({**cfg, "seed": seed})
    xr.testing.assert_equal(again["n"], ds["n"])


def test_failed_write_leaves_nothing(result, tmp_path, monkeypatch):
    def fail(self, *args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", fail)
    with pytest.raises(OSError, match="disk full"):
        write_netcdf(result, tmp_path / "result.nc")
    assert list(tmp_path.iterdir()) == []


def test_failed_write_keeps_the_previous_result(result, tmp_path, monkeypatch):
    # An interrupted overwrite must not damage the result already there.
    path = write_netcdf(result, tmp_path / "result.nc")
    before = path.read_bytes()

    def interrupted(self, target, *args, **kwargs):
        with open(target, "wb") as fh:
            fh.write(b"partial")
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_netcdf(result, path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["result.nc"]


def _checksummed(path) -> dict[str, bool]:
    """Per variable: whether the file holds a checksum of its data (fletcher32 chunks, or a scalar's crc32)."""
    with netCDF4.Dataset(path) as nc:
        return {name: bool(var.filters()["fletcher32"]) if var.dimensions else SCALAR_CRC in var.ncattrs()
                for name, var in nc.variables.items()}


@pytest.mark.parametrize("writer", ["write_netcdf", "streamed"])
def test_every_variable_of_a_result_file_carries_a_checksum(result, tmp_path, writer):
    if writer == "write_netcdf":
        path = write_netcdf(result, tmp_path / "result.nc")
    else:
        cfg = make_config(steps=50, realizations=3, observables=["n", "mu_max", "x_G", "mu_eff", "n_records"])
        slidernet.run(cfg, out=tmp_path, workers=1).close()
        path = tmp_path / "result.nc"
    checked = _checksummed(path)
    assert set(checked) == set(result.variables) and all(checked.values()), checked
    assert {"r_mean", "r_sem"} <= {name for name, var in result.variables.items() if not var.dims}


@pytest.mark.parametrize("name", ["n", "mu_max_mean", "r_mean"], ids=["per-realization", "mean", "scalar"])
def test_a_flipped_bit_in_a_result_file_is_an_error_naming_the_variable(result, tmp_path, name):
    # result.nc carried no checksum: a flipped bit in its data read (and plotted) silently.
    path = write_netcdf(result, tmp_path / "result.nc")
    raw = np.ascontiguousarray(result[name].values, dtype=result[name].dtype.newbyteorder("<")).tobytes()
    data = bytearray(path.read_bytes())
    assert data.count(raw) == 1
    data[data.find(raw) + len(raw) // 2] ^= 0x04
    path.write_bytes(bytes(data))
    with pytest.raises(ResultError, match=rf"result file '{path}' is damaged: the (data|value) of '{name}'"):
        read_result(path)


def test_a_truncated_result_file_is_an_error_naming_it(result, tmp_path):
    path = write_netcdf(result, tmp_path / "result.nc")
    path.write_bytes(path.read_bytes()[:5000])
    with pytest.raises(ResultError, match=rf"result file '{path}' cannot be read: .*truncated or damaged"):
        read_result(path)
