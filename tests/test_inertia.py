"""The inertial solver of 1D networks (solver.inertia) against the reference integrator and the quasi-static
solver.

Every run is deterministic (fixed seeds); each test states its tolerance and why.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from slidernet.config import load_config
from slidernet.errors import AvalancheError, ConfigError
from slidernet.model.network import Network, chain
from slidernet.solver import Realization, Scene, simulate
from slidernet.solver.inertia import InertialSolver
from slidernet.validation.dynamics import Dynamics

Ntilde = 1e-7
MU_D = 0.5
FRICTION = {"mu_d": MU_D, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
PAIR = {"kind": "two_slider", "Ntilde": Ntilde}
CHAIN_4 = {"kind": "chain", "n": 4, "Ntilde": Ntilde}


def scene(steps: int, network: dict[str, Any] | None = None, sigma_theta: float = 1e-6, net=None,
          friction: dict[str, Any] | None = None, **extra: Any) -> Scene:
    """A scene with the paper's friction (mu_d = 0.5, mu_s ~ N(0.6, 0.01^2)) unless told, every step recorded."""
    cfg = {"steps": steps, "record": "all", "friction": friction or FRICTION, "network": network or PAIR,
           "driver": {"name": "gaussian_steps", "sigma_theta": sigma_theta}, **extra}
    return Scene.from_config(load_config(cfg), network=net) if net is not None else Scene.from_config(
        load_config(cfg))


def write_values(path: Path, values: list[float]) -> dict[str, Any]:
    """The ``empirical`` thresholds law on ``values`` (exact reprs, one a line)."""
    path.write_text("".join(f"{float(v)!r}\n" for v in values))
    return {"name": "empirical", "path": str(path)}


# -- 1. slip for slip against the reference integrator -------------------------------------------------------

# One tau_th of the pair and of a free chain of 4; seed 1 and sigma_theta / Ntilde = 10 (pair) or 3 (chain)
# give tens of slips, several nodes moving at once in the chain and, at tau_ratio = 1e-2, in the pair.
REFERENCE_CASES = {
    "pair-1e-4": (PAIR, 1e-6, 1e-4),
    "pair-1e-2": (PAIR, 1e-6, 1e-2),
    "chain4-1e-4": (CHAIN_4, 3e-7, 1e-4),
    "chain4-1e-2": (CHAIN_4, 1e-6, 1e-2),
}


@pytest.mark.parametrize(("network", "sigma_theta", "tau_ratio"), list(REFERENCE_CASES.values()),
                         ids=list(REFERENCE_CASES))
def test_slip_for_slip_as_the_reference(network: dict[str, Any], sigma_theta: float, tau_ratio: float) -> None:
    """The same slips, nodes in the same order, each displacement within 1e-8 of the slip's length.

    The reference integrates at rtol = 1e-8 with max_step = 0.05 tau_dyn; the inertial solver is exact to
    rounding between events. Measured (slips; starts while another node moved; largest |du - du_ref| over
    the shortest slip; largest |end - end_ref| in tau_th): pair 1e-4 (49; 0; 2.3e-14; 1.6e-15), pair 1e-2
    (38; 19; 1.2e-14; 4.4e-16), chain 1e-4 (47; 15; 1.2e-13; 3.4e-15), chain 1e-2 (46; 47; 8.0e-14;
    1.7e-15). Tolerances 1e-8 (du, the issue's), 1e-10 tau_th (times).
    """
    sc = scene(1, network, sigma_theta)
    out = InertialSolver(sc, tau_ratio).run(np.random.SeedSequence(1))
    ref = Dynamics(sc, tau_ratio).run(np.random.SeedSequence(1))
    slips, expected = out["slips"], ref["slips"]
    assert 20 <= expected["node"].size <= 120  # tens of slips: the case is exercised, the test fast
    np.testing.assert_array_equal(slips["node"], expected["node"])
    np.testing.assert_array_equal(out["n"], ref["n"])
    assert out["overlapping"] == ref["overlapping"]
    assert out["moving_at_end"] == ref["moving_at_end"]
    assert np.abs(slips["du"] - expected["du"]).max() <= 1e-8 * np.abs(expected["du"]).min()
    for key in ("start", "end"):
        np.testing.assert_allclose(slips[key], expected[key], rtol=0, atol=1e-10)
    np.testing.assert_allclose(slips["duration"], expected["duration"], rtol=1e-8)
    np.testing.assert_allclose(out["x_G"], ref["x_G"], rtol=0, atol=1e-8 * np.abs(ref["x_G"]).max())


def test_several_nodes_moved_at_once() -> None:
    """The cases above exercise the modes of a moving segment: the chain's overlap (control for the test above)."""
    out = InertialSolver(scene(1, CHAIN_4, 3e-7), 1e-4).run(np.random.SeedSequence(1))
    assert out["overlapping"] >= 5


# -- 2. energy balance of every avalanche ---------------------------------------------------------------------


ENERGY_CASES = {
    "pair-1e-4": (PAIR, 1e-6, 1e-4, None),
    "pair-1e-2": (PAIR, 1e-6, 1e-2, None),
    "chain4-1e-4": (CHAIN_4, 1e-6, 1e-4, None),
    "chain4-1e-2": (CHAIN_4, 1e-7, 1e-2, None),
    # Unequal masses and springs, and an external load: every term of the balance is exercised.
    "chain5-loads": ({"kind": "chain", "n": 5, "Ntilde": Ntilde}, 1e-6, 1e-3,
                     chain(5, Ntilde=Ntilde, k=1.5, normal_load=[1.0, 2.0, 0.5, 1.0, 3.0],
                           f_ext=[0.1, 0.0, -0.2, 0.05, 0.0])),
    "chain16-1e-3": ({"kind": "chain", "n": 16, "Ntilde": Ntilde}, 1e-6, 1e-3, None),
}


@pytest.mark.parametrize(("network", "sigma_theta", "tau_ratio", "net"), list(ENERGY_CASES.values()),
                         ids=list(ENERGY_CASES))
def test_energy_balance_of_every_avalanche(network: dict[str, Any], sigma_theta: float, tau_ratio: float,
                                           net) -> None:
    """Work of the loads = change of elastic energy + sum of mu_d N_i |du_i| over the avalanche's slips.

    An avalanche runs from rest to rest (every velocity zero, so no kinetic energy at either end). The
    work is the kernel's integral of (f_ext + (theta - theta(0)) g) . v over the motion, the elastic energy
    u.K u / 2 at both ends, the dissipation from the logged slips (each slip keeps its sign, so |du_i| is
    its path). Measured: each residual at most 1.3e-13 of the larger of its avalanche's dissipation and
    work, the largest 5.5e-13 of the run's largest dissipation; tolerance 1e-9.
    """
    sc = scene(10, network, sigma_theta, net=net)
    out = InertialSolver(sc, tau_ratio).run(np.random.SeedSequence(0))
    av, slips = out["avalanches"], out["slips"]
    N = sc.network.normal_load
    heat = MU_D * N[slips["node"]] * np.abs(slips["du"])
    first = np.concatenate([[0], av["slips"][:-1]])
    dissipated = np.array([heat[a:b].sum() for a, b in zip(first, av["slips"], strict=True)])
    assert av["start"].size >= 10 and (dissipated > 0).all()
    residual = av["work"] - (av["e1"] - av["e0"]) - dissipated
    assert np.abs(residual).max() <= 1e-9 * dissipated.max()
    assert (np.abs(residual) <= 1e-9 * np.maximum(dissipated, np.abs(av["work"]))).all()


# -- 3. tau_ratio -> 0: the quasi-static solver's events where its rule is the limit ------------------------------


def assert_quasi_static(sc: Scene, seed: int, tau_ratio: float = 1e-12) -> dict[str, Any]:
    """The quasi-static solver's events at tau_ratio -> 0: n and mu_max at every record, each slip's node.

    Each slip's length is the solver's to within the drive during it: theta moves by pi tau_ratio
    |dtheta/dt| Ntilde in a half-oscillation of a node with K_ii = N_i = 1 (test_dynamics's exact_slip
    to first order); tolerance 4 pi tau_ratio max |theta(t_q+1) - theta(t_q)| (measured: at most 1.7 of
    the single-slip value), and x_G to 1e-6 of its largest value.
    """
    ref = simulate(sc, np.random.SeedSequence(seed))
    out = InertialSolver(sc, tau_ratio).run(np.random.SeedSequence(seed))
    np.testing.assert_array_equal(out["n"], ref["n"])
    np.testing.assert_array_equal(out["mu_max"], ref["mu_max"])
    np.testing.assert_allclose(out["x_G"], ref["x_G"], rtol=0, atol=1e-6 * np.abs(ref["x_G"]).max())
    ev = ref["events"]
    np.testing.assert_array_equal(out["slips"]["node"], ev["node"])
    rate = np.abs(np.diff(Realization(sc, np.random.SeedSequence(seed)).thetas)).max()
    overshoot = np.abs(np.abs(out["slips"]["du"]) - np.abs(ev["dx"])) / (np.pi * tau_ratio * rate * Ntilde)
    assert overshoot.max() <= 4.0
    return out


def test_thresholds_next_to_mu_d(tmp_path: Path) -> None:
    """A quarter of the draws at mu_d + 1e-12: slips of 2e-12 Ntilde l0 that stop at |F| = mu_d - 1e-12.

    The half-oscillation's amplitude is the excess over mu_d, so the closed-form stop scales with it. The
    second slider is twice as heavy (N = 2), so that the two never reach their thresholds at the same
    instant: with equal loads, |F_0| = |F_1| and a threshold drawn by both is a tie, where the two rules
    part (test_tied_thresholds_part_the_rules).
    """
    law = write_values(tmp_path / "mu.txt", [MU_D + 1e-12, 0.55, 0.6, 0.65])
    net = chain(2, Ntilde=Ntilde, normal_load=[1.0, 2.0])
    sc = scene(20, {"kind": "chain", "n": 2, "Ntilde": Ntilde}, 1e-6, net=net,
               friction={"mu_d": MU_D, "static": law}, observables=["n", "mu_max", "x_G", "events"])
    out = assert_quasi_static(sc, 3)
    tiny = np.abs(out["slips"]["du"]) < 1e-9 * Ntilde
    assert tiny.sum() >= 100


def test_simultaneous_starts(tmp_path: Path) -> None:
    """Four tied overloads 0.75 on a chain of 17 (thresholds 0.625) start at once at t = 0 and stop together.

    The quasi-static solver slips them one by one, lowest index first; inertia starts them all (the largest
    overload first, ties by index: 3 starts while another moves), and as they are 4 apart their half-
    oscillations do not touch: the same slips, stopped (and redrawn) in index order.
    """
    law = write_values(tmp_path / "mu.txt", [0.625, 0.625])
    f_ext = np.zeros(17)
    f_ext[[2, 6, 10, 14]] = 0.75
    net = chain(17, Ntilde=Ntilde, f_ext=f_ext)
    sc = scene(2, {"kind": "chain", "n": 17, "Ntilde": Ntilde}, 1e-9, net=net,
               friction={"mu_d": MU_D, "static": law}, observables=["n", "mu_max", "x_G", "events"])
    out = assert_quasi_static(sc, 0)
    assert out["n"][0] == 4 and out["overlapping"] == 3
    assert out["slips"]["node"][:4].tolist() == [2, 6, 10, 14]


def test_restart_on_a_redrawn_threshold_below_the_force(tmp_path: Path) -> None:
    """mu_d = 0.1, thresholds 0.15 or 0.9: a slip from 0.9 leaves |F| = 0.7, and a redrawn 0.15 restarts it.

    The second slider is ten times heavier (N = 10: |F| <= 0.9 never reaches its 1.5 or 9), so the restarts
    are the first slider's alone, backward and forward, each a half-oscillation as the solver's 1D rule.
    """
    law = write_values(tmp_path / "mu.txt", [0.15, 0.9])
    net = chain(2, Ntilde=Ntilde, normal_load=[1.0, 10.0])
    sc = scene(20, {"kind": "chain", "n": 2, "Ntilde": Ntilde}, 1e-6, net=net,
               friction={"mu_d": 0.1, "static": law}, observables=["n", "mu_max", "x_G", "events"])
    out = assert_quasi_static(sc, 0)
    du = out["slips"]["du"]
    assert (np.sign(du[1:]) != np.sign(du[:-1])).sum() >= 10  # restarts, backward


def test_tied_thresholds_part_the_rules(tmp_path: Path) -> None:
    """Where the two rules part: two equal sliders with one threshold (0.6) reach it at the same instant.

    The quasi-static rule slips the lower index alone (node 0, 0.2 Ntilde l0; node 1 is relieved, stable).
    With inertia and a moving theta, node 1's force keeps rising at the drive's rate while node 0's motion
    relieves it only quadratically in time, so node 1 starts too (or, where rounding puts its force a hair
    below the threshold at the tie, not): measured on 20 steps, seed 0, the solver's 965 slips all of node 0;
    at tau_ratio = 1e-4, 1979 starts, 991 and 988, 1024 of them while the other moved, each slip 0.1026
    Ntilde l0 (the symmetric half-oscillation); at 1e-9, 1558 (965 and 593); at 1e-12, 1573 (965 and 608).
    The limit tau_ratio -> 0 of a tie is not the quasi-static rule's, and the floating point decides it.
    """
    law = write_values(tmp_path / "mu.txt", [0.6, 0.6])
    sc = scene(20, PAIR, 1e-6, friction={"mu_d": MU_D, "static": law}, observables=["n", "events"])
    ref = simulate(sc, np.random.SeedSequence(0))
    assert (ref["events"]["node"] == 0).all()
    out = InertialSolver(sc, 1e-9).run(np.random.SeedSequence(0))
    assert (out["slips"]["node"] == 1).sum() > 100 and out["overlapping"] > 100
    assert out["n"][-1] > 1.3 * ref["n"][-1]


# -- validation --------------------------------------------------------------------------------------------------


def test_load_beyond_friction_slides_for_ever() -> None:
    net = chain(2, Ntilde=Ntilde, f_ext=0.7)
    sc = scene(1, net=net, sigma_theta=1e-7)
    with pytest.raises(AvalancheError, match="sliding for 1000 tau_dyn without stopping"):
        InertialSolver(sc, 1e-3).run(np.random.SeedSequence(0))


@pytest.mark.parametrize(("tau_ratio", "match"), [
    (0.0, r"'tau_ratio' parameter of InertialSolver must be a finite number > 0\. Got 0\.0"),
    (float("inf"), r"'tau_ratio' .* Got inf"),
    (True, r"'tau_ratio' .* Got True"),
], ids=["zero", "inf", "bool"])
def test_bad_tau_ratio(tau_ratio: Any, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        InertialSolver(scene(1), tau_ratio)


def test_2d_refused() -> None:
    sc = scene(1, {"kind": "triangular", "shape": [2, 2], "Ntilde": Ntilde})
    with pytest.raises(ConfigError, match=r"1D networks only .* this one is 2D"):
        InertialSolver(sc, 1e-3)


def test_bad_steps() -> None:
    with pytest.raises(ConfigError, match=r"'steps' parameter of InertialSolver\.run must be an integer in \[0"):
        InertialSolver(scene(1), 1e-3).run(np.random.SeedSequence(0), steps=2)


# -- any 1D network, and the invariants of every scene ---------------------------------------------------------


def ring_with_chords(n: int, **overrides: Any):
    """A 1D network that is no chain: a ring of n sliders with two chords, so that a moving segment's K_MM is
    full (not tridiagonal) and the nodes have 2 to 4 springs."""
    edges = [[i, (i + 1) % n] for i in range(n)] + [[0, n // 2], [1, n // 2 + 2]]
    return Network(positions=np.arange(n, dtype=float), edges=np.array(edges), Ntilde=Ntilde, **overrides)


SIGMA_RING = 1e-7


def test_any_1d_network_slip_for_slip_as_the_reference() -> None:
    """A ring of 6 with chords, unequal masses: the same slips as the reference, as on the chain."""
    net = ring_with_chords(6, normal_load=[1.0, 1.5, 0.8, 1.2, 1.0, 2.0])
    sc = scene(1, {"kind": "chain", "n": 6, "Ntilde": Ntilde}, SIGMA_RING, net=net)
    out = InertialSolver(sc, 1e-3).run(np.random.SeedSequence(2))
    ref = Dynamics(sc, 1e-3).run(np.random.SeedSequence(2))
    slips, expected = out["slips"], ref["slips"]
    assert 20 <= expected["node"].size <= 150 and out["overlapping"] >= 5
    np.testing.assert_array_equal(slips["node"], expected["node"])
    assert np.abs(slips["du"] - expected["du"]).max() <= 1e-8 * np.abs(expected["du"]).min()


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(n=st.integers(2, 7), ring=st.booleans(), tau_exp=st.floats(-6.0, -1.0), seed=st.integers(0, 2**32 - 1),
       loads=st.lists(st.floats(0.5, 2.0), min_size=7, max_size=7), k=st.floats(0.5, 2.0))
def test_invariants_of_any_1d_scene(n: int, ring: bool, tau_exp: float, seed: int, loads: list[float],
                                    k: float) -> None:
    """For any small 1D network, tau_ratio and seed: one start per rearrangement (the slips that came to rest
    plus the nodes still moving), every slip moves its node along one sign by more than nothing, and every
    avalanche balances its energy to 1e-9 (Ntilde = 1e-7, sigma_theta / Ntilde = 3, 3 steps)."""
    overrides = {"normal_load": loads[:n], "k": k}
    net = ring_with_chords(n, **overrides) if ring and n >= 5 else chain(n, Ntilde=Ntilde, **overrides)
    sc = scene(3, {"kind": "chain", "n": n, "Ntilde": Ntilde}, 3e-7, net=net)
    out = InertialSolver(sc, 10.0 ** tau_exp).run(np.random.SeedSequence(seed))
    slips, av = out["slips"], out["avalanches"]
    assert out["n"][-1] == slips["node"].size + out["moving_at_end"]
    assert (slips["du"] != 0.0).all() and (slips["end"] >= slips["start"]).all()
    heat = MU_D * sc.network.normal_load[slips["node"]] * np.abs(slips["du"])
    first = np.concatenate([[0], av["slips"]])[:-1].astype(np.int64)
    dissipated = np.array([heat[a:b].sum() for a, b in zip(first, av["slips"], strict=True)])
    residual = av["work"] - (av["e1"] - av["e0"]) - dissipated
    assert (np.abs(residual) <= 1e-9 * np.maximum(dissipated, np.abs(av["work"]))).all()
