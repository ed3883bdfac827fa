"""Network pictures: per-node fields read back from the figures, errors, atomic PNG files."""

from __future__ import annotations

import io
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure

import slidernet
from slidernet.analysis.plots import (
    EDGE_LIMIT,
    mu_s_field,
    network_of,
    node_field,
    save_network_pictures,
    slip_map,
)
from slidernet.config import load_config
from slidernet.errors import ConfigError, ResultError
from slidernet.io import read_result, write_netcdf
from slidernet.model.builders import triangular
from slidernet.model.network import chain

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _config(network: dict[str, Any], sigma_theta: float = 1e-7, realizations: int = 2) -> dict[str, Any]:
    """A small scene shaped like examples/lattice.toml."""
    return {
        "seed": 3,
        "realizations": realizations,
        "steps": 20,
        "observables": ["n", "mu_max", "x_G"],
        "network": {**network, "Ntilde": 1e-7},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "gaussian_steps", "sigma_theta": sigma_theta},
    }


@pytest.fixture(scope="module")
def lattice_ds():
    return slidernet.run(load_config(_config({"kind": "triangular", "shape": [6, 6]})))


@pytest.fixture(scope="module")
def chain_ds():
    return slidernet.run(load_config(_config({"kind": "chain", "n": 10}, sigma_theta=1e-6)))


@pytest.fixture(scope="module")
def pair_ds():
    return slidernet.run(load_config(_config({"kind": "two_slider"}, sigma_theta=1e-6, realizations=1)))


def _scatter(fig: Figure) -> PathCollection:
    (sc,) = [c for c in fig.axes[0].collections if isinstance(c, PathCollection)]
    return sc


def _render(fig: Figure) -> None:
    """Draw the figure fully, as saving would (catches norms that only fail at draw time)."""
    fig.savefig(io.BytesIO(), format="png", dpi=40)


# --------------------------------------------------------------------------
# Fields read back from the figures
# --------------------------------------------------------------------------


def test_slip_map_colours_are_the_realizations_counts(lattice_ds):
    fig = slip_map(lattice_ds, realization=1)
    counts = lattice_ds["node_slips"].isel(realization=1).values
    shown = _scatter(fig).get_array()
    assert shown.shape == (36,)
    # Log scale: only the zero counts are masked.
    np.testing.assert_array_equal(np.ma.getmaskarray(shown), counts == 0)
    np.testing.assert_array_equal(np.ma.filled(shown, 0), counts)
    assert not np.array_equal(counts, lattice_ds["node_slips"].isel(realization=0).values)
    title = fig.axes[0].get_title()
    assert "triangular 6 x 6" in title and "20 steps" in title and "realization 1 of 2" in title
    _render(fig)
    plt.close(fig)


def test_slip_map_linear_scale(lattice_ds):
    fig = slip_map(lattice_ds, log=False)
    np.testing.assert_array_equal(_scatter(fig).get_array(), lattice_ds["node_slips"].isel(realization=0).values)
    plt.close(fig)


def test_mu_s_field_colours_are_the_final_thresholds(lattice_ds):
    fig = mu_s_field(lattice_ds, realization=0)
    mu = lattice_ds["mu_s"].isel(realization=0).values
    np.testing.assert_array_equal(_scatter(fig).get_array(), mu)
    assert (mu > 0.5).all()
    assert "mu_s" in fig.axes[1].get_ylabel()  # the colorbar
    _render(fig)
    plt.close(fig)


def test_lattice_draws_nodes_at_their_positions_with_springs(lattice_ds):
    net = network_of(lattice_ds)
    assert net.dim == 2 and net.n_nodes == lattice_ds.sizes["node"]
    fig = slip_map(lattice_ds, network=net)
    np.testing.assert_array_equal(_scatter(fig).get_offsets(), net.positions)
    springs = [c for c in fig.axes[0].collections if not isinstance(c, PathCollection)]
    assert len(springs) == 1 and len(springs[0].get_segments()) == net.n_edges
    assert fig.axes[0].get_aspect() == 1.0
    plt.close(fig)


def test_chain_is_a_line_of_value_against_position(chain_ds):
    fig = slip_map(chain_ds, realization=1)
    (line,) = fig.axes[0].lines
    counts = chain_ds["node_slips"].isel(realization=1).values
    np.testing.assert_array_equal(line.get_xdata(), np.arange(10.0))
    np.testing.assert_array_equal(np.ma.filled(line.get_ydata(), 0), counts)
    assert fig.axes[0].get_yscale() == "log"
    assert "chain, n = 10" in fig.axes[0].get_title()
    _render(fig)
    fig = mu_s_field(chain_ds, realization=0)
    np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), chain_ds["mu_s"].isel(realization=0).values)
    plt.close(fig)


def test_drawing_on_a_given_axes_and_a_result_read_back(lattice_ds, tmp_path):
    ds = read_result(write_netcdf(lattice_ds, tmp_path / "result.nc"))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    assert slip_map(ds, ax=axes[0]) is fig
    assert mu_s_field(ds, ax=axes[1]) is fig
    np.testing.assert_array_equal(_scatter(fig).get_array().filled(0), lattice_ds["node_slips"][0].values)
    plt.close(fig)


# --------------------------------------------------------------------------
# Log scale and zero counts
# --------------------------------------------------------------------------


def _axes() -> Any:
    fig = Figure()
    FigureCanvasAgg(fig)
    return fig.subplots()


@pytest.mark.parametrize("values", [[0, 5, 0, 120, 3, 0], [0, 0, 0, 0, 0, 0], [7, 7, 7, 7, 7, 7]])
def test_log_scale_masks_zero_counts_in_2d(values):
    ax = _axes()
    net = triangular((2, 3), Ntilde=1e-7)
    sc = node_field(ax, net, values, log=True, label="slips")
    v = np.asarray(values)
    np.testing.assert_array_equal(np.ma.getmaskarray(sc.get_array()), v == 0)
    assert len(sc.get_offsets()) == 6  # masked nodes are still drawn, in grey
    label = ax.figure.axes[1].get_ylabel()
    assert (f"grey: {int((v == 0).sum())} nodes at 0" in label) == bool((v == 0).any())
    _render(ax.figure)


@pytest.mark.parametrize("values", [[0, 5, 0, 2], [0, 0, 0, 0]])
def test_log_scale_masks_zero_counts_in_1d(values):
    ax = _axes()
    line = node_field(ax, chain(4, Ntilde=1e-7), values, log=True, label="slips")
    np.testing.assert_array_equal(np.ma.getmaskarray(line.get_ydata()), np.asarray(values) == 0)
    _render(ax.figure)


def test_springs_are_left_out_of_large_networks():
    rows = int(np.sqrt(EDGE_LIMIT / 3)) + 2
    net = triangular((rows, rows), Ntilde=1e-7)
    assert net.n_edges >= EDGE_LIMIT
    ax = _axes()
    node_field(ax, net, np.ones(net.n_nodes))
    assert [type(c) for c in ax.collections] == [PathCollection]


def test_values_of_the_wrong_shape_are_refused():
    with pytest.raises(ConfigError, match=r"must have shape \(4,\), one per node.*Got shape \(3,\)"):
        node_field(_axes(), chain(4, Ntilde=1e-7), [1.0, 2.0, 3.0])


# --------------------------------------------------------------------------
# Errors
# --------------------------------------------------------------------------


@pytest.mark.parametrize("draw, name", [(slip_map, "node_slips"), (mu_s_field, "mu_s")])
def test_two_slider_result_has_no_per_node_fields(pair_ds, draw, name):
    assert pair_ds.attrs["kernel"] == "pair"
    with pytest.raises(ValueError, match=rf"no '{name}' variable: .* network scene \(kernel 'csr' or 'vec'\); "
                                         r"this result was made by kernel 'pair'\."):
        draw(pair_ds)


def test_two_slider_result_writes_no_picture(pair_ds, tmp_path):
    with pytest.raises(ResultError, match="no 'node_slips' variable"):
        save_network_pictures(pair_ds, tmp_path / "pics")
    assert not (tmp_path / "pics").exists()


@pytest.mark.parametrize("realization", [2, -1, True, 0.5])
def test_realization_out_of_range(lattice_ds, realization):
    with pytest.raises(ConfigError, match=r"'realization' index must be an integer in \[0, 1\] \(the result has 2 "
                                          r"realizations\)\. Got"):
        slip_map(lattice_ds, realization=realization)


def test_network_of_another_size_is_refused(lattice_ds):
    with pytest.raises(ConfigError, match=r"network has 10 nodes but the dataset's 'mu_s' has 36"):
        mu_s_field(lattice_ds, network=chain(10, Ntilde=1e-7))


# --------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------


def test_save_network_pictures_writes_png_atomically(lattice_ds, tmp_path):
    out = tmp_path / "new" / "dir"
    paths = save_network_pictures(lattice_ds, out)
    assert paths == {"slip_map": out / "slip_map.png", "mu_s_field": out / "mu_s_field.png"}
    for path in paths.values():
        assert path.read_bytes()[:8] == PNG_MAGIC
    # Again over the existing files: replaced, and no temporary file left behind.
    (out / "slip_map.png").write_bytes(b"stale")
    save_network_pictures(lattice_ds, out)
    assert sorted(p.name for p in out.iterdir()) == ["mu_s_field.png", "slip_map.png"]
    assert (out / "slip_map.png").read_bytes()[:8] == PNG_MAGIC


def test_save_network_pictures_of_a_chain(chain_ds, tmp_path):
    paths = save_network_pictures(chain_ds, tmp_path)
    assert all(p.read_bytes()[:8] == PNG_MAGIC for p in paths.values())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mu_s_field.png", "slip_map.png"]
