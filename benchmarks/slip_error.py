"""Error of the straight-line 2D slip against the integrated 2D slip (docs/model.md section 2).

    python benchmarks/slip_error.py [--quick] [--out DIR]

A slipping node i moves alone, as an undamped half-oscillation under Coulomb
friction with its local stiffness block K_ii (2 x 2, units of N / (Ntilde l0)).
``solver.slip = "straight"`` moves it along its force F by
Delta u = 2 (|F| - mu_d N) F / (|F| k_eff), k_eff = F^T K_ii F / |F|^2: exact
where K_ii is isotropic, an approximation where it is not. This script
measures that approximation in two ways.

Per slip
    For every node of an irregular network and of triangular and square
    lattices, and for force directions spread uniformly on the circle at
    threshold (|F| = mu_s N), the relative displacement error
    |Delta u_straight - Delta u_exact| / |Delta u_exact| and the error of the
    force left on the node, |K_ii (Delta u_straight - Delta u_exact)| / (mu_s N).
    "Exact" is ``slidernet.kernels.plane.integrate_slip``, the RK4 integration
    of the 2D motion behind ``solver.slip = "exact"``, whose step shrinks
    where the speed is small; the script checks its convergence (4x finer
    steps) and that the kernels' ``exact_slip`` is that integration.

Per run
    The same configuration and seeds with ``slip = "straight"`` and
    ``"exact"``: relative differences of r_mean, of the final mu_max_mean and
    of the rms x_G, with their statistical significance, and the wall time
    per slip of each mode (kernels only: compilation, scene building and
    result assembly excluded). Realizations that abort (a slip that does not
    stop raises :class:`~slidernet.errors.AvalancheError`) are counted and
    left out of the comparison.

Everything is written to ``DIR/slip_error.csv`` (long format: section,
network, case, quantity, value) and printed as markdown tables. Single
threaded; ``--quick`` runs smaller networks and runs (under a minute).
"""

from __future__ import annotations

import argparse
import csv
import itertools
import math
import os
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.errors import AvalancheError
from slidernet.kernels.plane import exact_slip, integrate_slip
from slidernet.solver import Realization, Scene

MU_D = 0.5
NORMAL_LOAD = 1.0
MU_S_CASES = (0.6, 0.9)
ANISO_TOL = 1e-9  # eigenvalue ratio above 1 + ANISO_TOL: anisotropic K_ii
RHO_BINS = (1.0, 1.0 + ANISO_TOL, 1.5, 2.0, 3.0, 5.0, math.inf)
NTILDE = 1e-7
SEED = 2024


# --------------------------------------------------------------------------- the reference slip


# The reference is slidernet's own exact integrator, run at the resolution asked
# for (its convergence is measured by reference_convergence below).
reference_slip = integrate_slip


@njit
def _batch_reference(F: np.ndarray, k: np.ndarray, fd: float, steps_per_period: int,
                     c: float) -> tuple[np.ndarray, np.ndarray]:
    m = F.shape[0]
    du = np.empty((m, 2))
    steps = np.empty(m, np.int64)
    for j in range(m):
        du[j, 0], du[j, 1], steps[j] = reference_slip(F[j, 0], F[j, 1], k[j, 0, 0], k[j, 0, 1],
                                                      k[j, 1, 1], fd, steps_per_period, c)
    return du, steps


@njit
def _batch_exact_slip(F: np.ndarray, k: np.ndarray, fd: float) -> tuple[np.ndarray, np.ndarray]:
    m = F.shape[0]
    du = np.empty((m, 2))
    steps = np.empty(m, np.int64)
    for j in range(m):
        du[j, 0], du[j, 1], steps[j] = exact_slip(F[j, 0], F[j, 1], k[j, 0, 0], k[j, 0, 1],
                                                  k[j, 1, 1], fd)
    return du, steps


def straight_slip(F: np.ndarray, k: np.ndarray, fd: float) -> np.ndarray:
    """The straight-line slip of ``slip_mode = 0``, vectorized.

    Parameters
    ----------
    F : ndarray, shape (m, 2)
        Forces at rest, in N.
    k : ndarray, shape (m, 2, 2)
        Blocks K_ii, in N per unit of u.
    fd : float
        Kinetic friction mu_d N, in N.

    Returns
    -------
    ndarray, shape (m, 2)
        Displacements, in units of u: 2 (|F| - fd) e / (e^T K e), e = F / |F|.
    """
    absF = np.hypot(F[:, 0], F[:, 1])
    e = F / absF[:, None]
    keff = np.einsum("mi,mij,mj->m", e, k, e)
    return (2.0 * (absF - fd) / keff)[:, None] * e


def reference_slips(F: np.ndarray, k: np.ndarray, fd: float, steps_per_period: int = 4000,
                    c: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """:func:`reference_slip` over arrays: F (m, 2) in N, k (m, 2, 2); returns (du (m, 2), steps (m,))."""
    return _batch_reference(np.ascontiguousarray(F, np.float64), np.ascontiguousarray(k, np.float64),
                            float(fd), int(steps_per_period), float(c))


def exact_slips(F: np.ndarray, k: np.ndarray, fd: float) -> tuple[np.ndarray, np.ndarray]:
    """``slidernet.kernels.plane.exact_slip`` over arrays; steps < 0 where it did not stop."""
    return _batch_exact_slip(np.ascontiguousarray(F, np.float64), np.ascontiguousarray(k, np.float64),
                             float(fd))


# ------------------------------------------------------------------------------ networks


def base_config(network: dict[str, Any], *, slip: str = "straight", steps: int = 10,
                sigma_over_ntilde: float = 1.0, realizations: int = 1) -> dict[str, Any]:
    """A run configuration on ``network`` (units: Ntilde = 1e-7, mu_d = 0.5, mu_s ~ N(0.6, 0.01))."""
    return {
        "seed": SEED, "realizations": realizations, "steps": steps, "record": "log",
        "network": {**network, "Ntilde": NTILDE},
        "friction": {"mu_d": MU_D, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "gaussian_steps", "sigma_theta": sigma_over_ntilde * NTILDE},
        "solver": {"slip": slip},
    }


def diagonal_blocks(network: dict[str, Any]) -> np.ndarray:
    """The blocks K_ii of every node, shape (N, 2, 2), in N / (Ntilde l0), as the kernel reads them."""
    scene = Scene.from_config(load_config(base_config(network)))
    ops = scene.operators
    return np.array(ops.K_table[ops.K_id[ops.diag]], dtype=np.float64)


def anisotropy(k: np.ndarray) -> np.ndarray:
    """Eigenvalue ratio lambda_max / lambda_min of each block of ``k`` (m, 2, 2); 1 when isotropic."""
    lam = np.linalg.eigvalsh(k)
    return lam[:, 1] / lam[:, 0]


def force_directions(n_dir: int, rng: np.random.Generator) -> np.ndarray:
    """``n_dir`` angles equally spaced on the circle with a random phase, in radians.

    Stratified rather than independent: the same coverage of the circle with
    fewer slips.
    """
    return (np.arange(n_dir) + rng.uniform()) * (2.0 * math.pi / n_dir)


# -------------------------------------------------------------------------------- per slip


@dataclass
class SlipSample:
    """Every (node, direction) slip of one network at one mu_s; arrays of shape (m,)."""

    rho: np.ndarray  # anisotropy of the node's K_ii
    du_rel: np.ndarray  # |du_straight - du_ref| / |du_ref|
    dF_rel: np.ndarray  # |K (du_straight - du_ref)| / (mu_s N)
    ref_steps: np.ndarray
    ref_F_after: np.ndarray  # |F - K du_ref| / (mu_d N): at most 1 once the node sticks
    straight_F_after: np.ndarray  # |F - K du_straight| / (mu_d N)
    exact_steps: np.ndarray  # exact_slip's step count, < 0 where it did not stop
    exact_dev: np.ndarray  # |du_exact_slip - du_ref| / |du_ref| (NaN where it did not stop)
    straight_vs_exact: np.ndarray  # |du_straight - du_exact_slip| / |du_exact_slip| (NaN likewise)


def per_slip(k_nodes: np.ndarray, mu_s: float, n_dir: int, rng: np.random.Generator) -> SlipSample:
    """Straight-line slips against the reference for every node of a network and ``n_dir`` directions.

    Parameters
    ----------
    k_nodes : ndarray, shape (N, 2, 2)
        The blocks K_ii, in N / (Ntilde l0).
    mu_s : float
        Threshold: every slip starts at |F| = mu_s N.
    n_dir : int
        Force directions per node.
    rng : numpy.random.Generator
        Draws the phase of the directions.

    Returns
    -------
    SlipSample
        One entry per (node, direction) slip, nodes in order.
    """
    fd = MU_D * NORMAL_LOAD
    angles = force_directions(n_dir, rng)
    N = k_nodes.shape[0]
    k = np.repeat(k_nodes, n_dir, axis=0)
    ang = np.tile(angles, N)
    F = mu_s * NORMAL_LOAD * np.column_stack([np.cos(ang), np.sin(ang)])
    du_s = straight_slip(F, k, fd)
    du_r, ref_steps = reference_slips(F, k, fd)
    du_e, exact_steps = exact_slips(F, k, fd)
    norm_r = np.hypot(du_r[:, 0], du_r[:, 1])
    diff = du_s - du_r
    dF = np.einsum("mij,mj->mi", k, diff)
    ok = exact_steps > 0
    norm_e = np.hypot(du_e[:, 0], du_e[:, 1])
    exact_dev = np.where(ok, np.hypot(*(du_e - du_r).T) / norm_r, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        straight_vs_exact = np.where(ok, np.hypot(*(du_s - du_e).T) / norm_e, np.nan)

    def f_after(du: np.ndarray) -> np.ndarray:
        G = F - np.einsum("mij,mj->mi", k, du)
        return np.hypot(G[:, 0], G[:, 1]) / fd

    return SlipSample(
        rho=np.repeat(anisotropy(k_nodes), n_dir),
        du_rel=np.hypot(diff[:, 0], diff[:, 1]) / norm_r,
        dF_rel=np.hypot(dF[:, 0], dF[:, 1]) / (mu_s * NORMAL_LOAD),
        ref_steps=ref_steps,
        ref_F_after=f_after(du_r),
        straight_F_after=f_after(du_s),
        exact_steps=exact_steps,
        exact_dev=exact_dev,
        straight_vs_exact=straight_vs_exact,
    )


def reference_convergence(k_nodes: np.ndarray, mu_s: float, n_pairs: int, rng: np.random.Generator) -> float:
    """Largest relative change of the reference slip with 4x smaller steps, over random slips.

    Parameters
    ----------
    k_nodes : ndarray, shape (N, 2, 2)
        The blocks to draw from.
    mu_s : float
        Threshold (|F| = mu_s N).
    n_pairs : int
        Random (node, direction) slips to check.
    rng : numpy.random.Generator
        Draws the nodes and directions.

    Returns
    -------
    float
        max |du - du_fine| / |du_fine| (1) between steps_per_period 4000, c = 0.5
        and steps_per_period 16000, c = 0.125.
    """
    fd = MU_D * NORMAL_LOAD
    k = k_nodes[rng.integers(0, k_nodes.shape[0], n_pairs)]
    ang = rng.uniform(0.0, 2.0 * math.pi, n_pairs)
    F = mu_s * NORMAL_LOAD * np.column_stack([np.cos(ang), np.sin(ang)])
    coarse, _ = reference_slips(F, k, fd, 4000, 0.5)
    fine, _ = reference_slips(F, k, fd, 16000, 0.125)
    return float((np.hypot(*(coarse - fine).T) / np.hypot(*fine.T)).max())


def _pct(x: np.ndarray) -> tuple[float, float, float]:
    x = x[np.isfinite(x)]
    if x.size == 0:
        return (math.nan,) * 3
    return float(np.median(x)), float(np.percentile(x, 95)), float(x.max())


# --------------------------------------------------------------------------------- per run


@dataclass
class RunCase:
    """One per-run comparison: a network, a driving amplitude and an ensemble."""

    label: str
    network: dict[str, Any]
    sigma_over_ntilde: float
    steps: int
    realizations: int


@dataclass
class ModeResult:
    """Outcome of one slip mode on one :class:`RunCase`."""

    records: dict[int, dict[str, np.ndarray]]  # realization -> records, completed ones only
    aborted: dict[int, tuple[int, int]]  # realization -> (steps done, slips done) before the abort
    seconds: float  # wall time of the completed realizations' kernels
    slips: int  # slips of the completed realizations


def run_mode(case: RunCase, slip: str) -> ModeResult:
    """Run every realization of ``case`` with ``solver.slip = slip``, timing the kernels only.

    Parameters
    ----------
    case : RunCase
        Network, driving and ensemble.
    slip : {"straight", "exact"}
        The slip mode.

    Returns
    -------
    ModeResult
        Records of the completed realizations, the aborted ones, and the wall
        time (s) and slip count of the completed ones.
    """
    cfg = load_config(base_config(case.network, slip=slip, steps=case.steps,
                                  sigma_over_ntilde=case.sigma_over_ntilde,
                                  realizations=case.realizations))
    scene = Scene.from_config(cfg)
    out = ModeResult({}, {}, 0.0, 0)
    for r, ss in enumerate(realization_seeds(SEED, case.realizations)):
        real = Realization(scene, ss)
        t0 = time.perf_counter()
        try:
            real.advance()
        except AvalancheError:
            out.aborted[r] = (real.step, real.n)
            continue
        out.seconds += time.perf_counter() - t0
        out.slips += real.n
        out.records[r] = real.result()
    return out


def run_statistics(records: Sequence[dict[str, np.ndarray]], steps: int) -> dict[str, float]:
    """r_mean, final mu_max_mean and rms x_G, with standard errors, as ``slidernet.run`` defines them.

    Parameters
    ----------
    records : sequence of dict
        Per-realization records (``Realization.result()``), recorded up to ``steps``.
    steps : int
        Number of thermal steps (tau_th).

    Returns
    -------
    dict of str to float
        ``r_mean`` (slips per tau_th), ``mu_max_mean`` (final), ``x_G_rms``
        (final, in l0) and their ``*_sem`` (NaN with a single realization).
    """
    r = np.array([rec["n"][-1] / steps for rec in records], dtype=np.float64)
    mu = np.array([rec["mu_max"][-1] for rec in records], dtype=np.float64)
    x2 = np.array([rec["x_G"][-1] ** 2 for rec in records], dtype=np.float64)
    R = len(records)

    def sem(a: np.ndarray) -> float:
        return float(a.std(ddof=1) / math.sqrt(R)) if R > 1 else math.nan

    rms = math.sqrt(x2.mean())
    return {
        "r_mean": float(r.mean()), "r_mean_sem": sem(r),
        "mu_max_mean": float(mu.mean()), "mu_max_mean_sem": sem(mu),
        "x_G_rms": rms, "x_G_rms_sem": sem(x2) / (2.0 * rms) if rms > 0 else math.nan,
    }


def paired_differences(straight: Sequence[dict[str, np.ndarray]], exact: Sequence[dict[str, np.ndarray]],
                       steps: int) -> dict[str, float]:
    """Per-realization relative differences (straight - exact) / exact of r and of the final mu_max.

    Both modes of one realization share its seed, hence theta(t) and the stream
    of thresholds: pairing them removes most of the realization-to-realization
    spread that dominates the ensemble standard errors.

    Parameters
    ----------
    straight, exact : sequence of dict
        Records of the same realizations, in the same order.
    steps : int
        Number of thermal steps (tau_th).

    Returns
    -------
    dict of str to float
        ``r_paired`` and ``mu_max_paired`` (mean relative difference, 1) and
        their ``*_sem`` (NaN with a single pair).
    """
    out: dict[str, float] = {}
    for name, get in (("r", lambda rec: rec["n"][-1] / steps), ("mu_max", lambda rec: rec["mu_max"][-1])):
        d = np.array([get(a) / get(b) - 1.0 for a, b in zip(straight, exact, strict=True)], dtype=np.float64)
        out[f"{name}_paired"] = float(d.mean())
        out[f"{name}_paired_sem"] = float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else math.nan
    return out


def warm_up() -> None:
    """Load or compile every kernel the measurements call, so that no timing includes it."""
    for slip in ("straight", "exact"):
        cfg = load_config(base_config({"kind": "triangular", "shape": [4, 4]}, slip=slip, steps=3))
        Realization(Scene.from_config(cfg), realization_seeds(SEED, 1)[0]).advance()
    k = np.array([[[2.0, 0.3], [0.3, 1.0]]])
    F = np.array([[0.6, 0.0]])
    reference_slips(F, k, MU_D)
    exact_slips(F, k, MU_D)


# ---------------------------------------------------------------------------------- output


def write_csv(rows: list[tuple[str, str, str, str, float]], path: Path) -> None:
    """Write the long-format rows atomically: a temporary file in the same folder, then os.replace."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["section", "network", "case", "quantity", "value"])
            for row in rows:
                w.writerow([*row[:4], repr(float(row[4]))])
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _g(x: float, digits: int = 2) -> str:
    if not math.isfinite(x):
        return "n/a"
    if x == 0.0:
        return "0"
    return f"{x:.{digits}g}" if abs(x) < 1e-3 or abs(x) >= 1e4 else f"{x:.{digits + 1}g}"


def _pc(x: float) -> str:
    """A fraction as a percentage."""
    if not math.isfinite(x):
        return "n/a"
    return "0" if x == 0.0 else f"{100.0 * x:.3g} %"


def main(argv: Sequence[str] | None = None) -> int:
    """Run both measurements, write ``DIR/slip_error.csv`` and print the markdown tables; returns 0."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small networks and runs (under a minute)")
    ap.add_argument("--out", type=Path, default=Path("slip_error_out"), help="output folder")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    rng = np.random.Generator(np.random.PCG64(SEED))
    rows: list[tuple[str, str, str, str, float]] = []
    if args.quick:
        networks = [("irregular n=200", {"kind": "irregular", "n": 200, "seed": 0}),
                    ("triangular 10x10", {"kind": "triangular", "shape": [10, 10]}),
                    ("square 10x10", {"kind": "square", "shape": [10, 10]})]
        n_dir, n_conv = 8, 50
        cases = [RunCase("triangular 6x6", {"kind": "triangular", "shape": [6, 6]}, 1.0, 10, 2),
                 RunCase("irregular n=100", {"kind": "irregular", "n": 100, "seed": 0}, 0.3, 10, 2)]
    else:
        networks = [("irregular n=500", {"kind": "irregular", "n": 500, "seed": 0}),
                    ("triangular 20x20", {"kind": "triangular", "shape": [20, 20]}),
                    ("square 20x20", {"kind": "square", "shape": [20, 20]})]
        n_dir, n_conv = 24, 300
        # sigma_theta / Ntilde = 3 gives ~6e3 (triangular 10x10) and ~2.4e4 (irregular n=200)
        # slips per step, at ~0.4 ms per exact slip: only a few steps of it fit the time budget.
        cases = [RunCase("triangular 10x10", {"kind": "triangular", "shape": [10, 10]}, 1.0, 50, 3),
                 RunCase("triangular 10x10", {"kind": "triangular", "shape": [10, 10]}, 3.0, 8, 2),
                 RunCase("irregular n=200", {"kind": "irregular", "n": 200, "seed": 0}, 0.3, 50, 4),
                 RunCase("irregular n=200", {"kind": "irregular", "n": 200, "seed": 0}, 1.0, 6, 2),
                 RunCase("irregular n=200", {"kind": "irregular", "n": 200, "seed": 0}, 3.0, 10, 2)]
    warm_up()

    # ---- per slip
    slip_lines = []
    rho_lines = []
    check_lines = []
    for label, net in networks:
        k_nodes = diagonal_blocks(net)
        rho_nodes = anisotropy(k_nodes)
        aniso_nodes = rho_nodes > 1.0 + ANISO_TOL
        frac_aniso = float(aniso_nodes.mean())
        rows += [("per_slip", label, "nodes", "n_nodes", float(k_nodes.shape[0])),
                 ("per_slip", label, "nodes", "frac_anisotropic", frac_aniso),
                 ("per_slip", label, "nodes", "rho_median", float(np.median(rho_nodes))),
                 ("per_slip", label, "nodes", "rho_max", float(rho_nodes.max()))]
        for mu_s in MU_S_CASES:
            t0 = time.perf_counter()
            smp = per_slip(k_nodes, mu_s, n_dir, rng)
            conv = reference_convergence(k_nodes, mu_s, n_conv, rng)
            elapsed = time.perf_counter() - t0
            aniso = smp.rho > 1.0 + ANISO_TOL
            case = f"mu_s={mu_s}"
            for subset, mask in (("all", np.ones_like(aniso)), ("anisotropic", aniso)):
                if not mask.any() or (subset == "anisotropic" and mask.all()):
                    continue  # an empty subset, or the same slips as "all"
                du = _pct(smp.du_rel[mask])
                dF = _pct(smp.dF_rel[mask])
                se = _pct(smp.straight_vs_exact[mask])
                for name, trio in (("du_rel", du), ("dF_rel", dF), ("du_rel_vs_exact_slip", se)):
                    for stat, v in zip(("median", "p95", "max"), trio, strict=True):
                        rows.append(("per_slip", label, f"{case},{subset}", f"{name}_{stat}", v))
                rows.append(("per_slip", label, f"{case},{subset}", "slips", float(mask.sum())))
                slip_lines.append(
                    f"| {label} | {mu_s} | {subset} | {int(mask.sum())} | "
                    f"{_pc(du[0])} / {_pc(du[1])} / {_pc(du[2])} | "
                    f"{_pc(dF[0])} / {_pc(dF[1])} / {_pc(dF[2])} |")
            iso = ~aniso
            ok = smp.exact_steps > 0
            fail = float((~ok).mean())
            dev = smp.exact_dev[ok]
            iso_floor_exact = float(np.nanmax(smp.straight_vs_exact[iso & ok])) if (iso & ok).any() else math.nan
            iso_floor_ref = float(smp.du_rel[iso].max()) if iso.any() else math.nan
            checks = {
                "exact_slip_fail_frac": fail,
                "exact_slip_fail_frac_isotropic": float((~ok[iso]).mean()) if iso.any() else math.nan,
                "exact_slip_dev_median": float(np.median(dev)) if dev.size else math.nan,
                "exact_slip_dev_p99": float(np.percentile(dev, 99)) if dev.size else math.nan,
                "exact_slip_dev_max": float(dev.max()) if dev.size else math.nan,
                "exact_slip_frac_dev_gt_1e-6": float((dev > 1e-6).mean()) if dev.size else math.nan,
                "isotropic_straight_vs_exact_slip_max": iso_floor_exact,
                "isotropic_straight_vs_ref_max": iso_floor_ref,
                "ref_fail_frac": float((smp.ref_steps < 0).mean()),
                "ref_convergence_max": conv,
                "ref_F_after_over_mu_d_max": float(smp.ref_F_after.max()),
                "straight_F_after_over_mu_d_max": float(smp.straight_F_after.max()),
                "straight_frac_F_after_gt_mu_d": float((smp.straight_F_after > 1.0 + 1e-9).mean()),
                "seconds": elapsed,
            }
            rows += [("check", label, case, q, v) for q, v in checks.items()]
            check_lines.append(
                f"| {label} | {mu_s} | {_pc(fail)} | {_g(checks['exact_slip_dev_median'])} / "
                f"{_g(checks['exact_slip_dev_p99'])} / {_g(checks['exact_slip_dev_max'])} | "
                f"{_g(iso_floor_exact)} | {_g(iso_floor_ref)} | {_g(conv)} | "
                f"{checks['ref_F_after_over_mu_d_max']:.6f} | {checks['straight_F_after_over_mu_d_max']:.3f} |")
            if label.startswith("irregular"):
                for lo, hi in itertools.pairwise(RHO_BINS[1:]):
                    m = (smp.rho > lo) & (smp.rho <= hi)
                    if not m.any():
                        continue
                    du = _pct(smp.du_rel[m])
                    hi_txt = "inf" if math.isinf(hi) else f"{hi:g}"
                    rows += [("per_slip_rho", label, f"{case},rho=({lo:.3g},{hi_txt}]", f"du_rel_{s}", v)
                             for s, v in zip(("median", "p95", "max"), du, strict=True)]
                    rows.append(("per_slip_rho", label, f"{case},rho=({lo:.3g},{hi_txt}]", "slips",
                                 float(m.sum())))
                    lo_txt = "1" if lo <= 1.0 + 2 * ANISO_TOL else f"{lo:g}"
                    rho_lines.append(f"| {mu_s} | ({lo_txt}, {hi_txt}] | {int(m.sum())} | "
                                     f"{_pc(du[0])} / {_pc(du[1])} / {_pc(du[2])} |")
        print(f"# per slip: {label} done ({time.perf_counter() - t_start:.0f} s)", file=sys.stderr, flush=True)

    # ---- per run
    run_lines = []
    time_lines = []
    for case in cases:
        res = {slip: run_mode(case, slip) for slip in ("straight", "exact")}
        both = sorted(set(res["straight"].records) & set(res["exact"].records))
        cname = f"sigma/Ntilde={case.sigma_over_ntilde:g},steps={case.steps}"
        for slip, mr in res.items():
            rows += [("per_run", case.label, cname, f"{slip}_completed", float(len(mr.records))),
                     ("per_run", case.label, cname, f"{slip}_aborted", float(len(mr.aborted))),
                     ("per_run", case.label, cname, f"{slip}_slips", float(mr.slips)),
                     ("per_run", case.label, cname, f"{slip}_us_per_slip",
                      1e6 * mr.seconds / mr.slips if mr.slips else math.nan)]
            for r, (q, n) in sorted(mr.aborted.items()):
                rows += [("per_run", case.label, cname, f"{slip}_abort_r{r}_step", float(q)),
                         ("per_run", case.label, cname, f"{slip}_abort_r{r}_slips", float(n))]
        cells = []
        if both:
            st = {slip: run_statistics([res[slip].records[r] for r in both], case.steps) for slip in res}
            for q in ("r_mean", "mu_max_mean", "x_G_rms"):
                a, b = st["straight"][q], st["exact"][q]
                rel = (a - b) / b if b != 0 else math.nan
                z = (a - b) / math.hypot(st["straight"][f"{q}_sem"], st["exact"][f"{q}_sem"])
                rows += [("per_run", case.label, cname, f"{q}_straight", a),
                         ("per_run", case.label, cname, f"{q}_exact", b),
                         ("per_run", case.label, cname, f"{q}_rel_diff", rel),
                         ("per_run", case.label, cname, f"{q}_z", z)]
                z_txt = f"{z:+.2g}" if math.isfinite(z) else "n/a"  # one realization: no standard error
                cells.append(f"{_g(a, 4)} / {_g(b, 4)} ({rel:+.2%}, z = {z_txt})")
            pd = paired_differences([res["straight"].records[r] for r in both],
                                    [res["exact"].records[r] for r in both], case.steps)
            rows += [("per_run", case.label, cname, q, v) for q, v in pd.items()]
            cells += [f"{pd[f'{q}_paired']:+.2%} ± {pd[f'{q}_paired_sem']:.2%}"
                      if math.isfinite(pd[f"{q}_paired_sem"]) else f"{pd[f'{q}_paired']:+.2%}"
                      for q in ("r", "mu_max")]
        else:
            cells = ["n/a"] * 5
        aborted = ", ".join(f"r{r}: step {q}, {n} slips" for r, (q, n) in sorted(res["exact"].aborted.items()))
        run_lines.append(
            f"| {case.label} | {case.sigma_over_ntilde:g} | {case.steps} | "
            f"{len(res['straight'].records)} / {len(res['exact'].records)} of {case.realizations} | "
            + " | ".join(cells) + f" | {aborted or '-'} |")
        us = {s: 1e6 * res[s].seconds / res[s].slips if res[s].slips else math.nan for s in res}
        time_lines.append(
            f"| {case.label} | {case.sigma_over_ntilde:g} | {res['straight'].slips} | {_g(us['straight'])} | "
            f"{res['exact'].slips} | {_g(us['exact'], 3)} | {us['exact'] / us['straight']:.0f} |")
        print(f"# per run: {case.label} sigma/Ntilde={case.sigma_over_ntilde:g} done "
              f"({time.perf_counter() - t_start:.0f} s)", file=sys.stderr, flush=True)

    total = time.perf_counter() - t_start
    rows.append(("meta", "", "quick" if args.quick else "full", "seconds", total))
    rows.append(("meta", "", "", "directions_per_node", float(n_dir)))
    path = args.out / "slip_error.csv"
    write_csv(rows, path)

    print(f"### Straight-line slip error per slip (|F| = mu_s N, mu_d = {MU_D}, N = 1; "
          f"{n_dir} force directions per node)\n")
    print("| network | mu_s | nodes | slips | rel. error of Δu: median / p95 / max "
          "| force error / (mu_s N): median / p95 / max |")
    print("|---|---|---|---|---|---|")
    print("\n".join(slip_lines))
    print("\nAnisotropic nodes (eigenvalue ratio of K_ii > 1 + 1e-9): "
          + ", ".join(f"{label} {_pc(v)}" for (_, label, c, q, v) in rows
                      if q == "frac_anisotropic") + ".")
    print("\n### Error against the anisotropy rho = lambda_max / lambda_min of K_ii "
          f"({networks[0][0]})\n")
    print("| mu_s | rho | slips | rel. error of Δu: median / p95 / max |")
    print("|---|---|---|---|")
    print("\n".join(rho_lines))
    print("\n### Checks: slidernet's exact_slip and the reference integrator\n")
    print("| network | mu_s | exact_slip does not stop | exact_slip vs reference (rel.): median / p99 / max "
          "| straight vs exact_slip, isotropic, max | straight vs reference, isotropic, max "
          "| reference, 4x finer steps, max change | max abs(F_after) / mu_d N, reference "
          "| same, straight |")
    print("|---|---|---|---|---|---|---|---|---|")
    print("\n".join(check_lines))
    print("\n### Whole runs: straight / exact (relative difference, z = difference / combined s.e.; "
          "paired: per-realization relative difference, same seed)\n")
    print("| network | σ_θ/Ñ | steps | realizations completed (straight / exact) | r_mean | final mu_max_mean "
          "| rms x_G (l0) | paired r: mean ± s.e. | paired final mu_max: mean ± s.e. "
          "| exact runs aborted (slip did not stop) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    print("\n".join(run_lines))
    print("\n### Wall time per slip (kernels only, completed realizations, one core)\n")
    print("| network | σ_θ/Ñ | slips (straight) | µs / slip (straight) | slips (exact) | µs / slip (exact) "
          "| ratio |")
    print("|---|---|---|---|---|---|---|")
    print("\n".join(time_lines))
    print(f"\nWrote {path} ({total:.0f} s).")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
