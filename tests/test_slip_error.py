"""Facts that benchmarks/slip_error.py relies on (docs/model.md section 2, the 2D slip rule).

* The straight-line slip is exact where K_ii is isotropic, and along either
  eigen-axis of an anisotropic K_ii; the benchmark's reference integrator and
  ``slidernet.kernels.plane.exact_slip`` both reproduce it there.
* The reference integrator is converged and ends with the node stuck:
  |F_after| <= mu_d N, hence also <= |F_before|.
* Its run statistics are the ones ``slidernet.run`` reports.

Three regression tests keep the cases where the fixed-step ``exact_slip`` of
slidernet 0.1 did not stop, or stopped late and off the converged slip: a
strongly anisotropic block, a small overload, a square boundary block.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.kernels.plane import exact_slip

MU_D = 0.5  # kinetic friction mu_d N with N = 1, in N
REL = 1e-9  # agreement where the straight line is exact (both integrators reach ~1e-12 there)
STICK_TOL = 1e-6  # relative slack on |F_after| <= mu_d N (integration error of the stop)


def _load_benchmark() -> ModuleType:
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "slip_error.py"
    spec = importlib.util.spec_from_file_location("slidernet_bench_slip_error", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    # dataclasses resolve the module's annotations through sys.modules.
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


se = _load_benchmark()


def _straight(F: np.ndarray, k: np.ndarray) -> np.ndarray:
    return se.straight_slip(F[None, :], k[None, :, :], MU_D)[0]


def _reference(F: np.ndarray, k: np.ndarray, steps_per_period: int = 4000, c: float = 0.5) -> np.ndarray:
    dx, dy, steps = se.reference_slip(F[0], F[1], k[0, 0], k[0, 1], k[1, 1], MU_D, steps_per_period, c)
    assert steps > 0, "the reference did not stop"
    return np.array([dx, dy])


def _exact(F: np.ndarray, k: np.ndarray) -> tuple[np.ndarray, int]:
    dx, dy, steps = exact_slip(F[0], F[1], k[0, 0], k[0, 1], k[1, 1], MU_D)
    return np.array([dx, dy]), int(steps)


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def _block(lam_min: float, rho: float, phi: float) -> np.ndarray:
    """SPD block with eigenvalues lam_min, rho lam_min and its stiff axis at angle phi."""
    c, s = math.cos(phi), math.sin(phi)
    R = np.array([[c, -s], [s, c]])
    return R @ np.diag([rho * lam_min, lam_min]) @ R.T


@pytest.fixture(scope="module")
def triangular_blocks() -> tuple[np.ndarray, np.ndarray]:
    """K_ii of a 6 x 6 triangular lattice, split into (isotropic, anisotropic) blocks."""
    k = se.diagonal_blocks({"kind": "triangular", "shape": [6, 6]})
    rho = se.anisotropy(k)
    iso = rho <= 1.0 + se.ANISO_TOL
    assert iso.any() and (~iso).any()
    return k[iso], k[~iso]


@pytest.mark.parametrize("mu_s", [0.6, 0.9], ids=["mu_s=0.6", "mu_s=0.9"])
def test_straight_is_exact_for_isotropic_blocks(triangular_blocks, mu_s: float) -> None:
    iso, _ = triangular_blocks
    rng = np.random.Generator(np.random.PCG64(11))
    for k in iso[:6]:
        for ang in rng.uniform(0.0, 2.0 * math.pi, 4):
            F = mu_s * np.array([math.cos(ang), math.sin(ang)])
            straight = _straight(F, k)
            du, steps = _exact(F, k)
            assert steps > 0
            assert _rel(straight, du) < REL
            assert _rel(straight, _reference(F, k)) < REL


@settings(deadline=None, max_examples=30)
@given(lam=st.floats(0.5, 4.0), rho=st.floats(1.0, 8.0), phi=st.floats(0.0, math.pi),
       axis=st.sampled_from([0, 1]), sign=st.sampled_from([1.0, -1.0]), mu_s=st.floats(0.55, 1.2))
def test_straight_is_exact_along_eigen_axes(lam: float, rho: float, phi: float, axis: int, sign: float,
                                            mu_s: float) -> None:
    # Along an eigenvector K e is parallel to e: the motion never leaves the line.
    k = _block(lam, rho, phi)
    e = sign * np.linalg.eigh(k)[1][:, axis]
    F = mu_s * e
    straight = _straight(F, k)
    assert _rel(straight, _reference(F, k)) < REL
    du, steps = _exact(F, k)
    assert steps > 0
    assert _rel(straight, du) < REL


@pytest.mark.parametrize("mu_s", [0.6, 0.9], ids=["mu_s=0.6", "mu_s=0.9"])
def test_exact_slip_ends_stable_on_anisotropic_lattice_blocks(triangular_blocks, mu_s: float) -> None:
    # Boundary blocks of the triangular lattice (eigenvalue ratios 5/3 and 3). |F_after| <= |F_before|
    # is checked without slack (the margin is > 10 %), |F_after| <= mu_d N with STICK_TOL. Its
    # accuracy is another matter: see test_exact_slip_is_accurate_on_a_square_boundary_block.
    _, aniso = triangular_blocks
    blocks = np.unique(np.round(aniso, 12), axis=0)
    for k in blocks:
        for ang in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False) + 0.1:
            F = mu_s * np.array([math.cos(ang), math.sin(ang)])
            du, steps = _exact(F, k)
            assert steps > 0
            after = np.linalg.norm(F - k @ du)
            assert after <= np.linalg.norm(F)
            assert after <= MU_D * (1.0 + STICK_TOL)


@settings(deadline=None, max_examples=40)
@given(lam=st.floats(0.5, 4.0), rho=st.floats(1.0, 10.0), phi=st.floats(0.0, math.pi),
       ang=st.floats(0.0, 2.0 * math.pi), mu_s=st.floats(0.51, 1.4))
def test_reference_sticks_and_converges(lam: float, rho: float, phi: float, ang: float, mu_s: float) -> None:
    # mu_d N < |F| <= 3 mu_d N: a half-oscillation ends with |F_after| <= mu_d N < |F_before|.
    k = _block(lam, rho, phi)
    F = mu_s * np.array([math.cos(ang), math.sin(ang)])
    du = _reference(F, k)
    after = np.linalg.norm(F - k @ du)
    assert after <= MU_D * (1.0 + STICK_TOL)
    assert after <= np.linalg.norm(F)
    fine = _reference(F, k, steps_per_period=16000, c=0.125)
    assert _rel(du, fine) < 1e-7


def test_straight_error_vanishes_only_where_expected(triangular_blocks) -> None:
    # Off the eigen-axes of an anisotropic block the straight line is a real approximation.
    _, aniso = triangular_blocks
    k = aniso[0]
    _, vec = np.linalg.eigh(k)
    diagonal = (vec[:, 0] + vec[:, 1]) / math.sqrt(2.0)
    F = 0.6 * diagonal
    assert _rel(_straight(F, k), _reference(F, k)) > 1e-3


def test_run_statistics_match_slidernet_run() -> None:
    cfg = se.base_config({"kind": "triangular", "shape": [4, 4]}, steps=20, realizations=3)
    ds = slidernet.run(cfg, progress=False)
    case = se.RunCase("t", cfg["network"], 1.0, 20, 3)
    res = se.run_mode(case, "straight")
    assert not res.aborted and res.slips > 0
    stats = se.run_statistics([res.records[r] for r in sorted(res.records)], 20)
    assert stats["r_mean"] == pytest.approx(float(ds["r_mean"]), rel=1e-12)
    assert stats["mu_max_mean"] == pytest.approx(float(ds["mu_max_mean"][-1]), rel=1e-12)
    assert stats["x_G_rms"] == pytest.approx(math.sqrt(float(ds["x_G2_mean"][-1])), rel=1e-12)


def test_write_csv_is_atomic(tmp_path: Path) -> None:
    path = tmp_path / "sub" / "slip_error.csv"
    se.write_csv([("per_slip", "net", "case", "q", 0.25)], path)
    assert path.read_text().splitlines() == ["section,network,case,quantity,value", "per_slip,net,case,q,0.25"]
    assert [p.name for p in path.parent.iterdir()] == ["slip_error.csv"]


def test_exact_slip_stops_on_a_strongly_anisotropic_block() -> None:
    # K_ii of node 10 of the irregular network n = 200, seed 0 (eigenvalue ratio 9.6), F at threshold.
    k = np.array([[0.46237367, -0.51300285], [-0.51300285, 3.53762633]])
    F = np.array([0.394564657679, 0.431430884021])
    du, steps = _exact(F, k)
    assert steps > 0
    assert _rel(du, _reference(F, k)) < 1e-6


def test_exact_slip_small_overload_isotropic() -> None:
    k = 1.5 * np.eye(2)
    F = 0.51 * np.array([math.cos(1.0), math.sin(1.0)])
    du, steps = _exact(F, k)
    assert steps > 0
    assert _rel(du, _straight(F, k)) < REL


def test_exact_slip_is_accurate_on_a_square_boundary_block() -> None:
    k = np.diag([1.0, 2.0])
    a = math.radians(30.5)
    F = 0.6 * np.array([math.cos(a), math.sin(a)])
    du, steps = _exact(F, k)
    assert steps > 0
    assert _rel(du, _reference(F, k)) < 1e-6
