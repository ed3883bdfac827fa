"""Sweeps whose points differ in kernel, dimension or number of nodes: the stacked root, the per-node groups,
the NaN of absent variables, the file, resuming, the command line."""

from __future__ import annotations

import copy
import json
from typing import Any

import netCDF4
import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.analysis.plots import plot_result
from slidernet.ensemble import runner
from slidernet.ensemble.sweep import sweep
from slidernet.errors import ResultError, RunInterrupted
from slidernet.io import read_result
from slidernet.io.netcdf import variable_encoding

CHAIN: dict[str, Any] = {
    "seed": 5,
    "realizations": 2,
    "steps": 40,
    "network": {"kind": "chain", "n": 2, "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}
SIZES = {"network.n": [2, 4, 8]}
PER_NODE = ("node_slips", "mu_s")
# In this process: worker processes would only add their start-up time to these tiny runs.
ONE = {"workers": 1}


def with_network(base: dict[str, Any], **network: Any) -> dict[str, Any]:
    cfg = copy.deepcopy(base)
    cfg["network"] = {**cfg["network"], **network}
    return cfg


@pytest.fixture(scope="module")
def sizes_out(tmp_path_factory) -> tuple[xr.DataTree, Any]:
    out = tmp_path_factory.mktemp("sizes")
    return sweep(CHAIN, SIZES, out=out, **ONE), out


def assert_point_is_the_plain_run(result: xr.Dataset | xr.DataTree, dim: str, value: Any,
                                  plain: xr.Dataset) -> None:
    """Point ``dim = value`` of ``result`` holds the plain run's bits: stacked where every point has the
    variable, the same values in float64 where another point lacks it, the per-node ones in the point's group."""
    root = result.to_dataset() if isinstance(result, xr.DataTree) else result
    point = root.sel({dim: value}, drop=True)
    if "avalanche_size" in plain.dims:
        # The sweep pads each point's avalanche histogram with empty bins to the widest point's.
        bins = plain.sizes["avalanche_size"]
        assert not point["avalanche_count"].isel(avalanche_size=slice(bins, None)).any()
        point = point.isel(avalanche_size=slice(0, bins))
    if isinstance(result, xr.DataTree):
        group = result[f"point_{int(root['sweep_point'].sel({dim: value}))}"]
        assert group.attrs["kernel"] == plain.attrs["kernel"]
        assert json.loads(group.attrs["config"]) == json.loads(plain.attrs["config"])
        assert set(group.data_vars) == {n for n in plain.data_vars if "node" in plain[n].dims}
        for name in group.data_vars:
            np.testing.assert_array_equal(group[name].values, plain[name].values, err_msg=name)
            assert group[name].dtype == plain[name].dtype, name
            assert group[name].dims == ("realization", "node")
    for name in plain.data_vars:
        if isinstance(result, xr.DataTree) and "node" in plain[name].dims:
            assert name not in root
            continue
        np.testing.assert_array_equal(point[name].values, plain[name].values, err_msg=name)
        if point[name].dtype != plain[name].dtype:  # filled with NaN at another point
            assert point[name].dtype == np.float64 and np.isnan(root[name].values).any(), name
    for name in set(point.data_vars) - set(plain.data_vars):  # absent from this point
        assert np.isnan(point[name].values).all(), name


# ---------------------------------------------------------------------------
# chains of 2, 4 and 8: the pair kernel beside the chain kernel


def test_a_size_sweep_is_a_tree_with_one_group_per_point(sizes_out):
    tree, _ = sizes_out
    assert isinstance(tree, xr.DataTree)
    assert list(tree.children) == ["point_0", "point_1", "point_2"]
    assert tree["n"].dims == ("network.n", "realization", "t")
    assert tree["r_mean"].dims == ("network.n",)
    assert tree["network.n"].values.tolist() == [2, 4, 8]
    assert tree["sweep_point"].dims == ("network.n",) and tree["sweep_point"].values.tolist() == [0, 1, 2]
    assert not any(name in tree.data_vars for name in PER_NODE)
    assert [tree[f"point_{i}"].sizes.get("node") for i in range(3)] == [None, 4, 8]
    assert [json.loads(tree[f"point_{i}"].attrs["sweep_assignment"]) for i in range(3)] == [
        {"network.n": 2}, {"network.n": 4}, {"network.n": 8}]
    assert [tree[f"point_{i}"].attrs["sweep_point"] for i in range(3)] == [0, 1, 2]
    assert tree.attrs["kernel"] == "pair, csr"
    assert json.loads(tree.attrs["kernels"]) == ["pair", "csr", "csr"]
    assert tree.attrs["seed"] == "5" and tree.attrs["slidernet_version"] == slidernet.__version__
    assert json.loads(tree.attrs["config"]) == CHAIN
    # A group sees the root's coordinates, as any DataTree child does.
    assert tree["point_2"]["node_slips"].coords["realization"].values.tolist() == [0, 1]


@pytest.mark.parametrize("n", SIZES["network.n"], ids=[f"n={n}" for n in SIZES["network.n"]])
def test_each_size_is_the_plain_run_of_its_config_to_the_bit(sizes_out, n):
    tree, _ = sizes_out
    assert_point_is_the_plain_run(tree, "network.n", n, slidernet.run(with_network(CHAIN, n=n), **ONE))


def test_network_variables_the_pair_kernel_lacks_are_nan_there(sizes_out):
    tree, _ = sizes_out
    for name in ("mu_mean", "mu_min", "avalanche_count"):
        assert tree[name].dtype == np.float64
        assert np.isnan(tree[name].sel({"network.n": 2})).all(), name
        assert not np.isnan(tree[name].sel({"network.n": [4, 8]})).any(), name
    # Every point gives these: dtype and bits kept.
    assert tree["n"].dtype == np.int64 and not np.isnan(tree["x_G"]).any()


def test_the_file_round_trips_in_the_one_encoding(sizes_out):
    tree, out = sizes_out
    back = read_result(out / "result.nc")
    assert isinstance(back, xr.DataTree)
    xr.testing.assert_identical(back, tree)
    assert back["point_1"]["node_slips"].dtype == np.int64
    with netCDF4.Dataset(out / "result.nc") as nc:
        assert list(nc.groups) == ["point_0", "point_1", "point_2"]
        var = nc.groups["point_2"]["node_slips"]
        assert var.chunking() == list(variable_encoding(var.dimensions, var.shape, var.dtype)["chunksizes"])
        assert json.loads(nc.getncattr("config")) == CHAIN and nc.getncattr("seed") == "5"
    # Each point's own run is kept beside it, a plain result.
    point = read_result(out / "points" / "2" / "result.nc")
    xr.testing.assert_identical(point["node_slips"].variable, tree["point_2"]["node_slips"].variable)


def test_a_killed_size_sweep_resumes_to_the_same_file(sizes_out, tmp_path, monkeypatch):
    _, finished = sizes_out
    real_run = runner.run
    calls: list[int] = []

    def killed_at_point_2(cfg, *args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real_run(cfg, *args, **kwargs)

    monkeypatch.setattr(runner, "run", killed_at_point_2)
    with pytest.raises(RunInterrupted, match=r"2 of 3 sweep points are done.*--resume"):
        sweep(CHAIN, SIZES, out=tmp_path, **ONE)
    assert not (tmp_path / "result.nc").exists()
    reruns: list[int] = []

    def counted(cfg, *args, **kwargs):
        reruns.append(cfg.network.n)
        return real_run(cfg, *args, **kwargs)

    monkeypatch.setattr(runner, "run", counted)
    resumed = sweep(CHAIN, SIZES, out=tmp_path, resume=True, **ONE)
    assert reruns == [8]  # the finished points are read back
    xr.testing.assert_identical(read_result(tmp_path / "result.nc"), read_result(finished / "result.nc"))
    xr.testing.assert_identical(resumed, read_result(finished / "result.nc"))


# ---------------------------------------------------------------------------
# other scenes


def test_a_2d_irregular_size_sweep():
    base = with_network(CHAIN, kind="irregular", n=16)
    tree = sweep(base, {"network.n": [16, 32]}, **ONE)
    assert isinstance(tree, xr.DataTree)
    assert tree.attrs["kernel"] == "vec" and "kernels" not in tree.attrs
    assert [tree[f"point_{i}"].sizes["node"] for i in range(2)] == [16, 32]
    assert tree["y_G"].dims == ("network.n", "realization", "t") and not np.isnan(tree["y_G"]).any()
    assert tree["avalanche_count"].dtype == np.int64  # every point gives it: no fill
    assert_point_is_the_plain_run(tree, "network.n", 32, slidernet.run(with_network(base, n=32), **ONE))


def test_chain_against_irregular_of_the_same_size_is_one_dataset():
    # The same number of nodes: the per-node variables are stacked; y_G, 2D only, is NaN for the chain.
    base = with_network(CHAIN, n=16)
    ds = sweep(base, {"network.kind": ["chain", "irregular"]}, **ONE)
    assert isinstance(ds, xr.Dataset)
    assert ds["node_slips"].dims == ("kind", "realization", "node") and ds["node_slips"].dtype == np.int64
    assert np.isnan(ds["y_G"].sel(kind="chain")).all() and not np.isnan(ds["y_G"].sel(kind="irregular")).any()
    assert ds.attrs["kernel"] == "csr, vec" and json.loads(ds.attrs["kernels"]) == ["csr", "vec"]
    for kind in ("chain", "irregular"):
        assert_point_is_the_plain_run(ds, "kind", kind, slidernet.run(with_network(base, kind=kind), **ONE))


def test_two_sliders_against_a_chain_by_network_table():
    # kind = "two_slider" takes no n: the whole [network] table is swept.
    networks = [{"kind": "two_slider", "Ntilde": 1e-7}, {"kind": "chain", "n": 4, "Ntilde": 1e-7}]
    tree = sweep(CHAIN, {"network": networks}, **ONE)
    assert isinstance(tree, xr.DataTree)
    assert tree["network"].values.tolist() == [json.dumps(v, sort_keys=True) for v in networks]
    assert dict(tree["point_0"].data_vars) == {} and tree["point_0"].attrs["kernel"] == "pair"
    assert tree["point_1"]["mu_s"].shape == (2, 4)
    for value, network in zip(tree["network"].values, networks, strict=True):
        plain = slidernet.run({**CHAIN, "network": network}, **ONE)
        assert_point_is_the_plain_run(tree, "network", value, plain)


def test_the_pair_and_csr_kernels_on_the_same_two_sliders_stack_with_nan():
    # Formerly refused ("their scenes differ"); the same 2 nodes, so one Dataset.
    ds = sweep(CHAIN, {"solver.kernel": ["auto", "csr"]}, **ONE)
    assert isinstance(ds, xr.Dataset)
    assert ds["node_slips"].dtype == np.float64 and ds["node_slips"].sizes["node"] == 2
    assert np.isnan(ds["node_slips"].sel(kernel="auto")).all()
    # Invariant 6: on two sliders the chain kernel makes the pair kernel's floating-point operations.
    np.testing.assert_array_equal(ds["n"].sel(kernel="auto").values, ds["n"].sel(kernel="csr").values)


def test_mu_eff_at_records_sweeps_sizes_with_the_pair_kernel():
    base = {**CHAIN, "observables": ["n", "mu_max", "x_G", "mu_eff"], "mu_eff_at": "records"}
    tree = sweep(base, {"network.n": [2, 4]}, **ONE)
    assert tree["mu_eff"].dims == ("network.n", "t")
    assert_point_is_the_plain_run(tree, "network.n", 2, slidernet.run(base, **ONE))


# ---------------------------------------------------------------------------
# command line


def test_cli_writes_the_tree_and_plots_it(tmp_path, capsys):
    from slidernet.cli import main

    config = tmp_path / "chain.toml"
    config.write_text('seed = 5\nrealizations = 2\nsteps = 40\n[network]\nkind = "chain"\nn = 2\nNtilde = 1e-7\n'
                      '[friction]\nmu_d = 0.5\n[friction.static]\nname = "gaussian"\nmean = 0.6\nstd = 0.01\n'
                      '[driver]\nname = "gaussian_steps"\nsigma_theta = 1e-6\n')
    argv = ["sweep", str(config), "--set", "network.n=2,4,8", "--out", str(tmp_path / "out"), "--workers", "1",
            "--no-progress"]
    assert main(argv) == 0
    assert capsys.readouterr().out.splitlines() == [
        f"wrote {tmp_path / 'out' / 'result.nc'} (3 network.n points; per-node variables in groups point_0 to "
        f"point_2)"]
    tree = read_result(tmp_path / "out" / "result.nc")
    assert isinstance(tree, xr.DataTree) and tree["point_1"].sizes["node"] == 4
    # slidernet plot draws the sweep from the tree's root; plot_result, one run's panels, refuses it.
    assert main(["plot", str(tmp_path / "out" / "result.nc"), "--out", str(tmp_path / "picture.png")]) == 0
    assert (tmp_path / "picture.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ResultError, match=r"holds a sweep whose points differ in number of nodes.*plot_sweep"):
        plot_result(tree)
