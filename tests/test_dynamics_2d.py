"""The reference integrator of the equations of motion (validation.dynamics) on 2D networks.

Hand cases with closed forms (a single slider on an isotropic spring, equal unstressed sliders), the
quasi-static limit against the solver's exact 2D slip, and the 2D checks of the arguments. Every run is
deterministic (fixed seeds); each test states its tolerance and why.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from slidernet.config import load_config
from slidernet.errors import ConfigError
from slidernet.model.network import Network
from slidernet.solver import Scene, simulate
from slidernet.validation.dynamics import STOP_SPEED, Dynamics, realization_draws

Ntilde = 1e-7
MU_D = 0.5
FRICTION = {"mu_d": MU_D, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
SMALL_STEPS = {"name": "gaussian_steps", "sigma_theta": Ntilde}


def scene(steps: int, network: Network | None = None, net: dict[str, Any] | None = None,
          driver: dict[str, Any] | None = None, **extra: Any) -> Scene:
    """A scene with the paper's friction on a given 2D network (or network table), every step recorded."""
    cfg = {"steps": steps, "record": "all", "friction": FRICTION,
           "network": net or {"kind": "chain", "n": 2, "Ntilde": Ntilde},
           "driver": driver or SMALL_STEPS, **extra}
    return Scene.from_config(load_config(cfg), network=network)


def corner(angle: float, load: float = 0.3) -> Network:
    """Node 0 at the corner of an L, held by two unit springs along x and y: K_00 = 1 (isotropic).

    Nodes 1 and 2 carry a normal load of 1e6 (thresholds ~6e5 N: they never move), and node 0 an external
    force of ``load`` N along ``angle`` (radians), so its force turns as theta rises and it starts along
    whatever direction F_0 has then.
    """
    f_ext = np.zeros((3, 2))
    f_ext[0] = load * np.array([math.cos(angle), math.sin(angle)])
    return Network([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], [[0, 1], [0, 2]], Ntilde,
                   normal_load=[1.0, 1e6, 1e6], f_ext=f_ext)


ANGLES = [0.0, 0.7, math.pi / 2, 2.5, 4.0, 5.5]


@pytest.mark.parametrize("angle", ANGLES, ids=[f"angle-{a:.2f}" for a in ANGLES])
def test_single_slider_slips_along_its_force(angle: float) -> None:
    """A slider on an isotropic spring slips along F, by 2 (mu_s - mu_d) N / k in pi tau_dyn, any direction.

    theta rises by Ntilde per tau_th (the ramp) and tau_dyn / tau_th = 1e-9, so theta moves the force by
    ~3e-9 N during the slip: the slip is eq. `displacement`'s to that, and the stop comes ~1e-5 tau_dyn
    early (STOP_SPEED over the deceleration 0.1): tolerances 1e-6 relative on the length (measured
    2e-8), 1e-5 on the duration (measured -3.4e-6), 1e-6 rad on the direction, and |F_0| = mu_s N_0 at
    the start to 1e-12.
    """
    sc = scene(3, network=corner(angle), driver={"name": "ramp", "rate": Ntilde})
    seed = np.random.SeedSequence(4)
    tau = 1e-9
    out = Dynamics(sc, tau_ratio=tau).run(seed)
    thetas, draws = realization_draws(sc, seed)
    mu_s = draws.initial[0]
    slip = {key: value[0] for key, value in out["slips"].items()}
    assert slip["node"] == 0
    # The force on node 0 when it started: u = 0 before the first slip, theta linear within the step.
    q = int(slip["start"])
    theta = thetas[q] + (thetas[q + 1] - thetas[q]) * (slip["start"] - q) - thetas[0]
    F = sc.network.f_ext[0] + theta * sc.operators.g[0]
    assert np.hypot(*F) == pytest.approx(mu_s, rel=1e-12)
    du = slip["du"] / Ntilde
    length = 2.0 * (mu_s - MU_D)
    assert np.hypot(*du) == pytest.approx(length, rel=1e-6)
    assert abs(math.atan2(F[0] * du[1] - F[1] * du[0], F @ du)) < 1e-6
    # The stop comes STOP_SPEED / 0.1 = 1e-5 tau_dyn early (3.4e-6 of pi, measured): tolerance 1e-5.
    assert slip["duration"] / tau == pytest.approx(math.pi, rel=1e-5)
    assert out["stop_speed"] / Ntilde == pytest.approx(STOP_SPEED, rel=1e-6)  # the event's root


SQUARE = Network([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
                 Ntilde)


@pytest.mark.parametrize("rate", [1e-5, 1e-3], ids=["rate-1e-5", "rate-1e-3"])
def test_four_equal_unstressed_sliders_slide_at_mu_s(rate: float) -> None:
    """Four unstressed sliders of a 2D square with mu_s = 0.62 start together at f = 0.62 and slide.

    At rest the start is found in closed form (mu_eff = 0.62 to 1e-12, at either rate); the four reach
    the threshold at once, move along x as a rigid body (the springs stay at rest: no internal energy),
    and the 2D proof holds at the first check, 2 pi tau_dyn later.
    """
    sc = scene(1, network=SQUARE)
    out = Dynamics(sc, tau_ratio=1e-4).tilt_test(np.zeros((4, 2)), np.full(4, 0.62), np.random.default_rng(0),
                                                 rate=rate)
    assert out["mu_eff"] == pytest.approx(0.62, abs=1e-12)
    assert out["first_start"] == pytest.approx(0.62, abs=1e-12)
    assert out["all_moving"] == pytest.approx(0.62, abs=1e-12)
    assert 0.62 < out["certified"] <= 0.62 + 2 * np.pi * rate * (1 + 1e-9)
    assert out["starts"] == 4


# -- the quasi-static limit: the solver's exact 2D slip (solver.slip = "exact") ----------------------------

def irregular_8(steps: int, sigma: float, slip: str = "exact") -> Scene:
    """The study's irregular network of 8 (network seed 0), slip rule ``slip``, sigma_theta = sigma Ntilde."""
    return scene(steps, net={"kind": "irregular", "n": 8, "seed": 0, "Ntilde": Ntilde},
                 driver={"name": "gaussian_steps", "sigma_theta": sigma * Ntilde}, solver={"slip": slip},
                 observables=["n", "mu_max", "x_G"])


def test_isolated_slips_are_the_solvers_exact_slip() -> None:
    """Where no two nodes ever move at once, tau_dyn / tau_th -> 0 is the quasi-static run with exact slips.

    Irregular 8, sigma_theta / Ntilde = 0.3, 10 steps, seed 3: 127 slips, none overlapping. A node that
    moves alone under Coulomb friction along its velocity, its neighbours held, is the solver's exact 2D
    slip (kernels.plane.exact_slip), so n and the thresholds (mu_max) are the solver's at every step and
    x_G agrees to the slips' error: measured max |dx_G| / rms(x_G) = 1.3e-7; tolerance 1e-5.

    The default straight-line slip (kernels.plane.run_plane) is not that limit: K_ii of these nodes is
    anisotropic (eigenvalue ratios 1.3 to 5.5), so a slip curves and its length differs. Measured: x_G
    off by 0.12 rms, and n by one slip from step 9 on; asserted: off by more than 1e-2 rms.
    """
    sc = irregular_8(10, 0.3)
    out = Dynamics(sc, tau_ratio=1e-9).run(np.random.SeedSequence(3))
    ref = simulate(sc, np.random.SeedSequence(3))
    rms = np.sqrt(np.mean(ref["x_G"] ** 2))
    assert out["overlapping"] == 0
    assert np.array_equal(out["n"], ref["n"])
    assert np.array_equal(out["mu_max"], ref["mu_max"])
    assert np.abs(out["x_G"] - ref["x_G"]).max() < 1e-5 * rms
    straight = simulate(irregular_8(10, 0.3, "straight"), np.random.SeedSequence(3))
    assert np.abs(out["x_G"] - straight["x_G"]).max() > 1e-2 * rms


def test_overlapping_slips_depart_from_the_solver() -> None:
    """With slips that overlap, the quasi-static rule (one node at a time) is not the limit, as in 1D chains.

    Irregular 8, sigma_theta / Ntilde = 0.3, seed 1: 14 starts while another node moved by step 10, and
    the counts differ from the exact-slip run's from step 5 on (measured: 198 against 197).
    """
    sc = irregular_8(10, 0.3)
    out = Dynamics(sc, tau_ratio=1e-9).run(np.random.SeedSequence(1))
    ref = simulate(sc, np.random.SeedSequence(1))
    assert out["overlapping"] > 0
    assert np.array_equal(out["n"][:5], ref["n"][:5])
    assert not np.array_equal(out["n"], ref["n"])


# -- arguments -----------------------------------------------------------------------------------------------

def test_a_lattice_runs() -> None:
    """Any 2D network is accepted (a triangular lattice of 2 x 2), and its states have shape (T, N, 2)."""
    sc = scene(1, net={"kind": "triangular", "shape": [2, 2], "Ntilde": Ntilde})
    out = Dynamics(sc, tau_ratio=1e-3).run(np.random.SeedSequence(0), states=True)
    assert out["u"].shape == out["F"].shape == (2, 4, 2)
    assert out["mu_s"].shape == (2, 4)


TORQUE = np.array([[0.0, 0.0], [0.0, 0.1], [0.0, 0.0], [0.0, -0.1]])  # a couple on the square: no net force


@pytest.mark.parametrize(
    ("network", "u", "match"),
    [
        (SQUARE, np.zeros(4), r"'u' parameter of Dynamics\.tilt_test must be a finite array of shape \(4, 2\)"),
        (Network(SQUARE.positions, SQUARE.edges, Ntilde, f_ext=TORQUE), np.zeros((4, 2)),
         r"loads f_ext \+ theta g whose part not uniform per unit normal load has no net torque"),
    ],
    ids=["u-1d-shape", "f-ext-torque"],
)
def test_tilt_2d_bad_arguments(network: Network, u: np.ndarray, match: str) -> None:
    dyn = Dynamics(scene(1, network=network), tau_ratio=1e-4)
    with pytest.raises(ConfigError, match=match):
        dyn.tilt_test(u, np.full(4, 0.6), np.random.default_rng(0))
