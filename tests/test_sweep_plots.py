"""``slidernet plot`` on a sweep's result: curves per point against t, late-time values against the swept key."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.colorbar import Colorbar

from slidernet.analysis.sweep_plots import SHARED_SEEDS_NOTE, plot_sweep, shares_seeds
from slidernet.cli import main
from slidernet.errors import ResultError
from slidernet.io import read_result

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
SIGMAS = [1e-7, 3e-7, 1e-6]

BASE = """\
seed = 5
realizations = 3
steps = 30
observables = ["n", "mu_max", "x_G", "contact_age"]

[network]
kind = "two_slider"
Ntilde = 1e-7

[friction]
mu_d = 0.5
overshoot = 0.5
static = { name = "gaussian", mean = 0.6, std = 0.01 }

[driver]
name = "gaussian_steps"
sigma_theta = 1e-6
"""


@pytest.fixture(scope="module")
def swept(tmp_path_factory) -> Path:
    """The result file of a small sweep of sigma_theta, run by the command."""
    folder = tmp_path_factory.mktemp("sweep")
    (folder / "base.toml").write_text(BASE)
    out = folder / "out"
    assert main(["sweep", str(folder / "base.toml"), "--set",
                 "driver.sigma_theta=" + ",".join(map(str, SIGMAS)), "--out", str(out)]) == 0
    return out / "result.nc"


def test_a_sweep_plots_in_one_command(swept, capsys):
    capsys.readouterr()
    assert main(["plot", str(swept)]) == 0
    png = swept.with_suffix(".png")
    assert capsys.readouterr().out.strip() == f"wrote {png}"
    assert png.read_bytes()[:8] == PNG_MAGIC


def test_each_point_is_a_curve_coloured_by_its_swept_value(swept):
    ds = read_result(swept)
    fig = plot_sweep(ds)
    n_panel = fig.axes[0]
    assert n_panel.get_ylabel().startswith("$n$")
    lines = [ln for ln in n_panel.get_lines() if ln.get_label().startswith("sigma_theta")]
    assert len(lines) == len(SIGMAS)
    shown = ds["t"].values > 0
    for line, sigma in zip(lines, SIGMAS, strict=True):
        np.testing.assert_array_equal(line.get_ydata(), ds["n_mean"].sel(sigma_theta=sigma).values[shown])
    assert len({line.get_color() for line in lines}) == len(SIGMAS)
    colorbars = [ax for ax in fig.axes if isinstance(getattr(ax, "_colorbar", None), Colorbar)]
    assert [ax.get_ylabel() for ax in colorbars] == ["sigma_theta"]


def test_the_late_time_panel_is_the_last_value_against_the_swept_key_with_its_error(swept):
    ds = read_result(swept)
    fig = plot_sweep(ds)
    late = next(ax for ax in fig.axes if ax.get_title().startswith("at the last recorded time"))
    assert late.get_xlabel() == "sigma_theta"
    (bars,) = late.containers
    x, y = bars.lines[0].get_data()
    np.testing.assert_array_equal(x, SIGMAS)
    np.testing.assert_array_equal(y, ds["n_mean"].isel(t=-1).values)
    (segments,) = bars.lines[2]
    half = np.array([s[1, 1] - s[0, 1] for s in segments.get_segments()]) / 2
    np.testing.assert_allclose(half, ds["n_sem"].isel(t=-1).values)


def test_a_sweep_with_contact_age_gets_its_panel(swept):
    fig = plot_sweep(read_result(swept))
    assert any(ax.get_ylabel().startswith("contact age") for ax in fig.axes)


def test_the_title_names_the_sweep_and_the_options_not_at_their_default(swept):
    title = plot_sweep(read_result(swept))._suptitle.get_text()
    assert "sigma_theta = 1e-07, 3e-07, 1e-06" in title
    assert "overshoot 0.5" in title


def test_points_that_share_seeds_say_so(swept):
    ds = read_result(swept)
    assert shares_seeds(ds)
    assert SHARED_SEEDS_NOTE in plot_sweep(ds)._suptitle.get_text()
    # Points with seeds of their own (sweeps merged by hand, say) are independent: no note.
    configs = json.loads(ds.attrs["configs"])
    for k, c in enumerate(configs):
        c["seed"] = 100 + k
    ds.attrs["configs"] = json.dumps(configs)
    assert not shares_seeds(ds)
    assert SHARED_SEEDS_NOTE not in plot_sweep(ds)._suptitle.get_text()


def test_a_dataset_that_is_not_a_sweep_is_refused(swept):
    ds = read_result(swept).isel(sigma_theta=0)
    with pytest.raises(ResultError, match="no dimension of swept values"):
        plot_sweep(ds)


def test_one_run_still_plots_as_a_run(swept, tmp_path, capsys):
    one = read_result(swept).isel(sigma_theta=0, drop=True)
    path = tmp_path / "one.nc"
    one.to_netcdf(path)
    assert main(["plot", str(path)]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {path.with_suffix('.png')}"


def test_a_sweep_of_two_keys_draws_one_late_time_curve_per_value_of_the_second(swept):
    ds = read_result(swept)
    both = xr.concat([ds, ds.assign(n_mean=ds["n_mean"] + 1)], dim=xr.DataArray([0.4, 0.5], dims="mu_d"))
    both = both.transpose("sigma_theta", "mu_d", ...)
    both["mu_d"].attrs["sweep_key"] = "friction.mu_d"
    fig = plot_sweep(both)
    late = next(ax for ax in fig.axes if ax.get_title().startswith("at the last recorded time"))
    assert len(late.containers) == 2
    assert [t.get_text() for t in late.get_legend().get_texts()] == ["mu_d = 0.4", "mu_d = 0.5"]


def test_a_sweep_whose_points_differ_in_size_plots_from_its_root():
    from slidernet.analysis.sweep_plots import plot
    from slidernet.ensemble.sweep import sweep

    base = {"seed": 1, "realizations": 2, "steps": 10,
            "network": {"kind": "chain", "n": 2, "Ntilde": 1e-7},
            "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
            "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}
    tree = sweep(base, {"network.n": [2, 4]})
    assert isinstance(tree, xr.DataTree)
    title = plot(tree)._suptitle.get_text()
    assert "chain, n = (swept)" in title and "swept: network.n = 2, 4" in title
