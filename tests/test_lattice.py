"""Lattices without per-spring arrays: the stencil's K and g against the general assembly, to the bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from slidernet import kernels
from slidernet.config import load_config
from slidernet.model.builders import square, triangular
from slidernet.model.lattice import Lattice
from slidernet.model.network import Network
from slidernet.solver import Realization, Scene

BUILDERS = {"square": square, "triangular": triangular}
SHAPES = [(1, 2), (2, 1), (2, 2), (3, 5), (5, 3), (1, 7), (7, 1), (6, 9)]


def _general(lat: Lattice) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
    """K's rows and g from the general assembly over the lattice's listed springs."""
    return Network.stiffness_table(lat), Network.thermal_load(lat)


def _same_operators(lat: Lattice) -> None:
    (indptr, indices, K_id, table), g = _general(lat)
    s_indptr, s_indices, s_id, s_table = lat.stiffness_table()
    np.testing.assert_array_equal(s_indptr, indptr)
    np.testing.assert_array_equal(s_indices, indices)
    np.testing.assert_array_equal(s_table[s_id], table[K_id])  # every block, to the bit
    np.testing.assert_array_equal(lat.thermal_load(), g)


@pytest.mark.parametrize("kind", list(BUILDERS), ids=list(BUILDERS))
@pytest.mark.parametrize("shape", SHAPES, ids=[f"{r}x{c}" for r, c in SHAPES])
def test_stencil_equals_the_general_assembly_to_the_bit(kind, shape):
    _same_operators(BUILDERS[kind](shape, Ntilde=1e-7, k=1.3, kappa=0.7, rest_length=1.1))


@settings(max_examples=30)
@given(kind=st.sampled_from(list(BUILDERS)), rows=st.integers(1, 12), cols=st.integers(1, 12),
       k=st.floats(0.1, 10.0), kappa=st.floats(-2.0, 2.0))
def test_stencil_equals_the_general_assembly_for_any_shape(kind, rows, cols, k, kappa):
    if rows * cols < 2:
        return
    _same_operators(BUILDERS[kind]((rows, cols), Ntilde=1e-7, k=k, kappa=kappa))


@pytest.mark.parametrize("kind", list(BUILDERS), ids=list(BUILDERS))
def test_springs_are_the_nearest_neighbour_pairs_in_order(kind):
    # Independently of the stencil: every pair of nodes at distance 1, listed (i, j), i < j, sorted.
    lat = BUILDERS[kind]((5, 6), Ntilde=1e-7)
    X = lat.positions
    dist = np.linalg.norm(X[:, None, :] - X[None, :, :], axis=-1)
    i, j = np.nonzero(np.triu(np.isclose(dist, 1.0), k=1))
    np.testing.assert_array_equal(lat.edges, np.column_stack([i, j]))
    assert lat.n_edges == len(i)
    # Exact class vectors, within rounding of the positions' differences.
    d = X[lat.edges[:, 1]] - X[lat.edges[:, 0]]
    np.testing.assert_allclose(lat.unit_vectors(), d, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(lat.lengths(), 1.0)


def test_a_large_lattice_keeps_a_small_table_and_no_spring_arrays():
    lat = triangular((300, 200), Ntilde=1e-7)
    _indptr, indices, K_id, table = lat.stiffness_table()
    assert table.shape[0] <= 3 + 64  # 3 spring classes and the distinct diagonal blocks
    assert indices.dtype == np.int32 and K_id.dtype == np.int32
    assert "_springs" not in vars(lat)  # never listed
    assert lat.k.strides == (0,) and lat.kappa.strides == (0,)  # one number each, broadcast


def test_springs_given_one_by_one_take_the_general_assembly():
    E = triangular((4, 4), Ntilde=1e-7).n_edges
    k = np.linspace(0.5, 2.0, E)
    lat = triangular((4, 4), Ntilde=1e-7, k=k)
    assert not lat.uniform
    (_indptr, indices, K_id, table), g = _general(lat)
    got = lat.stiffness_table()
    assert got[3].shape[0] == indices.size  # one block per entry
    np.testing.assert_array_equal(got[3][got[2]], table[K_id])
    np.testing.assert_array_equal(lat.thermal_load(), g)


@pytest.mark.parametrize("kind", ["square", "triangular", "irregular"])
def test_the_forces_reset_multiplies_by_K(kind):
    network = {"kind": kind, "Ntilde": 1e-7, **({"n": 40} if kind == "irregular" else {"shape": [5, 7]})}
    cfg = load_config({"steps": 3, "network": network,
                       "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
                       "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}})
    scene = Scene.from_config(cfg)
    u = np.random.default_rng(1).normal(size=(scene.network.n_nodes, 2))
    out = np.empty_like(u)
    kernels.stiffness_times(scene.operators, u, out)
    np.testing.assert_allclose(out.reshape(-1), scene.network.stiffness_matrix() @ u.reshape(-1),
                               rtol=0, atol=1e-12)
    Realization(scene, np.random.SeedSequence(0)).advance()  # and the scene runs
