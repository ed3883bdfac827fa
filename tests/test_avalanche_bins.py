"""The avalanche histogram of a result: its bins end at the highest occupied one, however the result was made."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.analysis.observables import align_avalanche_sizes, avalanche_bins
from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.ensemble.sweep import sweep
from slidernet.io import read_result
from slidernet.solver import Realization, Scene

CHAIN = {"seed": 2, "realizations": 3, "steps": 20, "network": {"kind": "chain", "n": 8, "Ntilde": 1e-7},
         "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
         "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}


def kernel_counts(cfg: dict) -> np.ndarray:
    """Each realization's avalanche counts as the kernel records them, every bin: (R, 63)."""
    scene = Scene.from_config(load_config(cfg))
    return np.stack([Realization(scene, ss).advance().result()["avalanche_count"]
                     for ss in realization_seeds(cfg["seed"], cfg["realizations"])])


def assert_trimmed(ds: xr.Dataset, full: np.ndarray) -> None:
    """Bins 1, 2, 4, ... up to the highest occupied one in any realization; the bins left out were empty."""
    counts, sizes = ds["avalanche_count"].values, ds["avalanche_size"].values
    assert counts.dtype == np.int64 and sizes.dtype == np.int64
    assert sizes.tolist() == [2**k for k in range(sizes.size)]
    assert counts[..., -1].any()
    np.testing.assert_array_equal(counts, full[:, :sizes.size])
    assert not full[:, sizes.size:].any()


@pytest.fixture(scope="module")
def full() -> np.ndarray:
    return kernel_counts(CHAIN)


def test_the_histogram_of_a_run_ends_at_its_highest_occupied_bin(full):
    assert full.shape[1] == 63 and full[:, -1].sum() == 0  # the kernel's bins run to 2^62
    assert_trimmed(slidernet.run(CHAIN), full)


def test_a_streamed_run_has_the_same_bins(full, tmp_path):
    ds = slidernet.run(CHAIN, out=tmp_path)
    assert_trimmed(ds, full)
    xr.testing.assert_identical(ds["avalanche_count"], slidernet.run(CHAIN)["avalanche_count"])


def test_a_sweep_pads_its_points_with_empty_bins(tmp_path):
    grid = {"driver.sigma_theta": [1e-8, 1e-6]}
    ds = sweep(CHAIN, grid, out=tmp_path)
    points = [read_result(tmp_path / "points" / str(i) / "result.nc") for i in range(2)]
    widths = [p.sizes["avalanche_size"] for p in points]
    assert widths == [1, 4]  # 1e-8: no avalanche at all, one empty bin
    assert ds["avalanche_count"].dtype == np.int64 and ds.sizes["avalanche_size"] == widths[1]
    for i, p in enumerate(points):
        np.testing.assert_array_equal(ds["avalanche_count"].values[i, :, :widths[i]], p["avalanche_count"].values)
        assert not ds["avalanche_count"].values[i, :, widths[i]:].any()


def test_results_aligned_on_their_sizes_concatenate_with_int_counts(full):
    small = slidernet.run({**CHAIN, "driver": {"name": "gaussian_steps", "sigma_theta": 1e-8}})
    large = slidernet.run(CHAIN)
    assert small.sizes["avalanche_size"] < large.sizes["avalanche_size"]
    a, b = align_avalanche_sizes([small, large])
    assert a["avalanche_size"].equals(large["avalanche_size"]) and a["avalanche_count"].dtype == np.int64
    merged = xr.concat([a, b.assign_coords(realization=b["realization"] + 3)], dim="realization",
                       data_vars="minimal", coords="minimal", compat="override")
    assert merged["avalanche_count"].dtype == np.int64
    np.testing.assert_array_equal(merged["avalanche_count"].values[3:], large["avalanche_count"].values)


@pytest.mark.parametrize(("counts", "bins"), [([[0, 0, 0]], 1), ([[1, 0, 0], [0, 2, 0]], 2), ([[0, 0, 5]], 3)],
                         ids=["none", "two", "last"])
def test_avalanche_bins_counts_from_the_first_to_the_highest_occupied(counts, bins):
    assert avalanche_bins(np.array(counts)) == bins
