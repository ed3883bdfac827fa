"""The reference integrator of the equations of motion (validation.dynamics) against closed forms and the solver.

Every run is deterministic (fixed seeds); each test states its tolerance and why.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from slidernet.config import load_config
from slidernet.errors import AvalancheError, ConfigError
from slidernet.model.network import chain
from slidernet.solver import Realization, Scene, simulate
from slidernet.validation.dynamics import Dynamics, realization_draws

Ntilde = 1e-7
MU_D = 0.5
FRICTION = {"mu_d": MU_D, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}


def scene(steps: int, network: dict[str, Any] | None = None, driver: dict[str, Any] | None = None,
          **extra: Any) -> Scene:
    """A scene with the paper's friction (mu_d = 0.5, mu_s ~ N(0.6, 0.01^2)), every step recorded."""
    cfg = {"steps": steps, "record": "all", "friction": FRICTION,
           "network": network or {"kind": "two_slider", "Ntilde": Ntilde},
           "driver": driver or {"name": "gaussian_steps", "sigma_theta": 1e-6}, **extra}
    return Scene.from_config(load_config(cfg))


def exact_slip(A: float, K: float, N: float, gamma: float) -> tuple[float, float]:
    """Length (Ntilde l0) and duration (tau_dyn) of one slip of a node alone, its neighbours fixed.

    Along its direction of motion the node obeys N u'' = A N - K u + gamma s
    (s in tau_dyn, A N = |F| - mu_d N at the start, gamma the rate at which
    theta raises its force): u = (A N / K)(1 - cos w s) + (gamma / K)(s - sin(w s) / w)
    with w = sqrt(K / N), and u' = 0 again at w s = 2 (pi - atan(A N w / gamma)).
    For gamma -> 0 it is eq. `displacement`: 2 A N / K in pi / w.
    """
    w = np.sqrt(K / N)
    ws = 2.0 * (np.pi - np.arctan2(A * N * w, gamma))
    return A * N / K * (1.0 - np.cos(ws)) + gamma / K * (ws / w - np.sin(ws) / w), ws / w


# -- 1. a single slip against the closed form ------------------------------------------------------

RAMP = {"name": "ramp", "rate": Ntilde}  # theta / Ntilde rises by 1 per tau_th: the first slip is at t ~ 0.6


@pytest.mark.parametrize(
    ("tau_ratio", "net", "tol"),
    [
        # theta rises by pi tau_ratio ~ 3e-7 Ntilde during the slip: the paper's frozen-theta values
        # 2 (mu_s - mu_d) and pi hold to ~ pi tau_ratio / (2 (mu_s - mu_d)) ~ 2e-6 relative
        # (measured: 1.8e-6 on the length, 7.3e-7 on the duration); tolerance 1e-5.
        (1e-7, None, 1e-5),
        # theta moves by 0.03 Ntilde during the slip, which is 19 % longer and lasts 7 % longer than
        # the paper's: against exact_slip, to the integrator's rtol = 1e-8 (measured: 4e-16 relative).
        (1e-2, None, 1e-8),
        # Heavier sliders, stiffer spring: masses N_i m, so the slip lasts pi sqrt(N_i / K_ii) tau_dyn
        # and is 2 (mu_s - mu_d) N_i / K_ii long (plus 1.5 % from the moving theta). Against exact_slip,
        # tolerance rtol = 1e-8 (measured: 7e-16).
        (1e-3, chain(2, Ntilde=Ntilde, k=2.0, normal_load=3.0), 1e-8),
    ],
    ids=["paper-frozen-theta", "drifting-theta", "loads-3-stiffness-2"],
)
def test_single_slip_closed_form(tau_ratio: float, net, tol: float) -> None:
    sc = scene(1, driver=RAMP)
    if net is not None:
        sc = Scene.from_config(load_config({"steps": 1, "record": "all", "friction": FRICTION,
                                            "network": {"kind": "chain", "n": 2, "Ntilde": Ntilde},
                                            "driver": RAMP}), network=net)
    seed = 3
    out = Dynamics(sc, tau_ratio=tau_ratio).run(np.random.SeedSequence(seed))
    mu = Realization(sc, np.random.SeedSequence(seed)).mu
    slips = out["slips"]
    first = int(np.argmin(slips["start"]))
    i = int(slips["node"][first])
    assert i == int(np.argmin(mu))  # equal loads and |g_i|: the weaker slider goes first
    N_i = sc.network.normal_load[i]
    K_ii = sc.network.stiffness_matrix().diagonal()[i]
    g_i = abs(sc.network.thermal_load()[i])
    # A rising theta pushes node 1 forward (g_1 > 0) and node 0 backward.
    assert np.sign(slips["du"][first]) == np.sign(sc.network.thermal_load()[i])
    du, duration = abs(slips["du"][first]) / Ntilde, slips["duration"][first] / tau_ratio
    if tau_ratio == 1e-7:
        expected = (2 * (mu[i] - MU_D) * N_i / K_ii, np.pi * np.sqrt(N_i / K_ii))
    else:
        expected = exact_slip(mu[i] - MU_D, K_ii, N_i, gamma=g_i * 1.0 * tau_ratio)
    assert du == pytest.approx(expected[0], rel=tol)
    assert duration == pytest.approx(expected[1], rel=tol)


# -- 2. the same realizations as the solver -----------------------------------------------------------


def test_draws_are_the_solvers() -> None:
    """theta(t_q), the initial thresholds and the replacement draws, across a batch boundary, to the bit."""
    sc = scene(20, solver={"batch": 16})
    thetas, stream = realization_draws(sc, np.random.SeedSequence(5))
    real = Realization(sc, np.random.SeedSequence(5))
    assert np.array_equal(thetas, real.thetas)
    assert np.array_equal(stream.initial, real.mu)
    # The solver's next batch comes from the same stream, after mu_buf (its _refill).
    second = real.draws["thresholds"].take(sc.batch)
    assert np.array_equal([stream.next() for _ in range(2 * sc.batch)], np.concatenate([real.buffers.mu, second]))


@pytest.fixture(scope="module")
def paper() -> Scene:
    """The paper's two sliders (Ntilde = 1e-7, mu_d = 0.5, mu_s ~ N(0.6, 0.01^2), sigma_theta = 1e-6), 10 steps."""
    return scene(10, observables=["n", "mu_max", "x_G", "events"])


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1], ids=["seed0", "seed1"])
def test_small_tau_ratio_is_the_solver(paper: Scene, seed: int) -> None:
    """At tau_dyn / tau_th = 1e-9, the solver's n and mu_max at every recorded time, and its x_G.

    Each slip overshoots by pi tau_ratio |dtheta/dt| ~ 6e-8 Ntilde l0 (theta moves during it), so the
    overshoots of a thermal step shift its events by ~50 * 6e-8, far from changing a count. x_G: measured
    max |dx_G| / rms(x_G) = 9.5e-7 (seed 0, 452 slips) and 1.1e-6 (seed 1, 608 slips); tolerance 1e-5.
    """
    ref = simulate(paper, np.random.SeedSequence(seed))
    out = Dynamics(paper, tau_ratio=1e-9, max_step=np.inf).run(np.random.SeedSequence(seed))
    assert np.array_equal(out["t"], paper.out_steps)
    assert np.array_equal(out["n"], ref["n"])
    assert np.array_equal(out["mu_max"], ref["mu_max"])
    rms = np.sqrt(np.mean(ref["x_G"] ** 2))
    assert np.abs(out["x_G"] - ref["x_G"]).max() < 1e-5 * rms
    assert out["overlapping"] == 0  # two sliders with mu_s < 3 mu_d: one moves at a time


@pytest.mark.slow
def test_x_G_error_is_the_overshoot_linear_in_tau_ratio(paper: Scene) -> None:
    """x_G - x_G(solver) is, to first order in tau_ratio, the sum of the slips' overshoots.

    A slip of slider i while theta moves at |dtheta/dt| (units of Ntilde per tau_th) is longer than
    eq. `displacement` by pi tau_ratio |dtheta/dt| Ntilde l0 along its motion (exact_slip to first
    order), and moves x_G by half of that; later slips keep their lengths, so the shifts add up. Seed 2,
    where n agrees up to tau_ratio = 1e-6: measured residual / prediction = 4.8e-4, 6.2e-5, 1.5e-4 at
    tau_ratio = 1e-8, 1e-7, 1e-6; tolerance 2e-3. The error itself, 5.2e-6 to 5.2e-4 of rms(x_G), shrinks
    tenfold per decade of tau_ratio.
    """
    seed = 2
    ref = simulate(paper, np.random.SeedSequence(seed))
    thetas = Realization(paper, np.random.SeedSequence(seed)).thetas
    ev = ref["events"]
    q = np.maximum(np.ceil(ev["time"]).astype(np.int64) - 1, 0)  # a slip at time q + f lies in step q
    rate = np.abs(np.diff(thetas))[q]
    rms = np.sqrt(np.mean(ref["x_G"] ** 2))
    errors = []
    for tau_ratio in (1e-8, 1e-7, 1e-6):
        out = Dynamics(paper, tau_ratio=tau_ratio, max_step=np.inf).run(np.random.SeedSequence(seed))
        assert np.array_equal(out["n"], ref["n"])
        overshoot = 0.5 * np.sign(ev["dx"]) * np.pi * tau_ratio * rate * Ntilde
        predicted = np.array([overshoot[ev["time"] <= t].sum() for t in out["t"]])
        error = out["x_G"] - ref["x_G"]
        assert np.abs(error - predicted).max() < 2e-3 * np.abs(predicted).max()
        errors.append(np.abs(error).max() / rms)
    assert errors[0] < errors[1] / 5 < errors[2] / 25


# -- 3. a chain, where several sliders move at once ------------------------------------------------------


@pytest.mark.parametrize("tau_ratio", [1e-4, 1e-6], ids=["tau-1e-4", "tau-1e-6"])
def test_chain_slips_overlap_and_n_differs(tau_ratio: float) -> None:
    """A chain of 4, sigma_theta / Ntilde = 1, 10 steps, seed 0: the quasi-static rule is not the limit.

    The slip of a node loads its neighbours continuously, so a neighbour that the solver would slip next
    in the avalanche reaches its threshold while the first node still moves, however small tau_ratio is.
    Measured: the solver makes 50 slips; the dynamics 45, 8 of them starting while another node moved,
    at tau_ratio = 1e-4 and 1e-6 alike (default max_step = 0.05 tau_dyn).
    """
    sc = scene(10, network={"kind": "chain", "n": 4, "Ntilde": Ntilde},
               driver={"name": "gaussian_steps", "sigma_theta": 1e-7})
    ref = simulate(sc, np.random.SeedSequence(0))
    out = Dynamics(sc, tau_ratio=tau_ratio).run(np.random.SeedSequence(0))
    assert out["overlapping"] > 0
    assert out["n"][-1] != ref["n"][-1]
    # Every start is one rearrangement; the slips that came to rest are at most that many.
    assert out["slips"]["node"].size == out["n"][-1] - out["moving_at_end"]


# -- initial overload, runaway, validation ---------------------------------------------------------------


def test_initial_overload_relaxes_as_in_the_solver() -> None:
    """f_ext = 0.65 N on the first of 3 sliders: one slip at t = 0, theta frozen, as the solver's.

    Its neighbour ends at 0.15 below its threshold, so the slip is alone and of length
    2 (0.65 - 0.5) N / k; x_G to rtol-level (measured 4e-16 relative; tolerance 1e-8).
    """
    net = chain(3, Ntilde=Ntilde, f_ext=[0.65, 0.0, 0.0])
    sc = Scene.from_config(load_config({"steps": 2, "record": "all", "friction": FRICTION,
                                        "network": {"kind": "chain", "n": 3, "Ntilde": Ntilde},
                                        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}),
                           network=net)
    ref = simulate(sc, np.random.SeedSequence(0))
    out = Dynamics(sc, tau_ratio=1e-3).run(np.random.SeedSequence(0))
    assert out["n"][0] == ref["n"][0] == 1
    assert out["x_G"][0] == pytest.approx(2 * 0.15 * Ntilde / 3, rel=1e-8)
    assert out["x_G"][0] == pytest.approx(ref["x_G"][0], rel=1e-8)


def test_load_beyond_friction_slides_for_ever() -> None:
    net = chain(2, Ntilde=Ntilde, f_ext=0.7)
    sc = Scene.from_config(load_config({"steps": 1, "friction": FRICTION,
                                        "network": {"kind": "two_slider", "Ntilde": Ntilde},
                                        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}),
                           network=net)
    with pytest.raises(AvalancheError, match="sliding for 1000 tau_dyn without stopping"):
        Dynamics(sc, tau_ratio=1e-3, max_step=np.inf).run(np.random.SeedSequence(0))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"tau_ratio": 0.0}, r"'tau_ratio' parameter of Dynamics must be a finite number > 0\. Got 0\.0"),
        ({"tau_ratio": float("nan")}, r"'tau_ratio' .* Got nan"),
        ({"tau_ratio": 1e-3, "max_step": -0.1}, r"'max_step' parameter of Dynamics must be a number > 0"),
        ({"tau_ratio": 1e-3, "rtol": 0.0}, r"'rtol' parameter of Dynamics must be a number in \[2\.22e-14, 1\)"),
        ({"tau_ratio": 1e-3, "rtol": 1.0}, r"'rtol' .* Got 1\.0"),
        ({"tau_ratio": 1e-3, "method": "Euler"}, r"'method' parameter of Dynamics must be one of RK23"),
    ],
    ids=["tau-zero", "tau-nan", "max-step-negative", "rtol-zero", "rtol-one", "method-unknown"],
)
def test_bad_settings(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        Dynamics(scene(1), **kwargs)


def test_bad_steps() -> None:
    with pytest.raises(ConfigError, match=r"'steps' parameter of Dynamics\.run must be an integer in \[0, 1\]"):
        Dynamics(scene(1), tau_ratio=1e-3).run(np.random.SeedSequence(0), steps=2)


# -- 4. the state at the recorded times, and the dynamic tilt test ---------------------------------------------

CHAIN_4 = {"kind": "chain", "n": 4, "Ntilde": Ntilde}
SMALL_STEPS = {"name": "gaussian_steps", "sigma_theta": 1e-7}


def test_states_add_the_state_and_change_nothing() -> None:
    """run(states=True) gives the same outputs to the bit, plus u, mu_s, F and theta consistent with them.

    At t = 0 nothing has moved (no f_ext): u = 0, F = 0, theta = 0 and mu_s the initial thresholds. At every
    record F = -K u / Ntilde + g theta / Ntilde (units: u in l0, F in N) to rounding (1e-12 relative), and
    mu_max is the largest mu_s.
    """
    sc = scene(5, network=CHAIN_4, driver=SMALL_STEPS)
    dyn = Dynamics(sc, tau_ratio=1e-4)
    plain = dyn.run(np.random.SeedSequence(0))
    out = dyn.run(np.random.SeedSequence(0), states=True)
    for key in ("t", "n", "mu_max", "x_G", "overlapping", "moving_at_end"):
        assert np.array_equal(out[key], plain[key])
    for key in plain["slips"]:
        assert np.array_equal(out["slips"][key], plain["slips"][key])
    T, N = out["t"].size, 4
    assert out["u"].shape == out["mu_s"].shape == out["F"].shape == (T, N) and out["theta"].shape == (T,)
    assert np.array_equal(out["mu_s"][0], Realization(sc, np.random.SeedSequence(0)).mu)
    assert not out["u"][0].any() and not out["F"][0].any() and out["theta"][0] == 0.0
    assert np.array_equal(out["mu_s"].max(axis=1), out["mu_max"])
    K = sc.network.stiffness_matrix().toarray()
    g = np.asarray(sc.operators.g)
    expected = (-out["u"] @ K.T + out["theta"][:, None] * g) / Ntilde
    assert np.abs(out["F"] - expected).max() < 1e-12 * np.abs(out["F"]).max()
    assert np.allclose(out["x_G"], out["u"].mean(axis=1), rtol=1e-12, atol=0)


@pytest.mark.parametrize("net", [{"kind": "two_slider", "Ntilde": Ntilde},
                                 {"kind": "chain", "n": 3, "Ntilde": Ntilde}, CHAIN_4],
                         ids=["pair", "chain-3", "chain-4"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_tilt_of_the_fresh_state_is_the_quasi_static_one(net: dict[str, Any], seed: int) -> None:
    """From u = 0 both tests slide in their first avalanche, which starts at f = min mu_s.

    With no spring force the first node starts at f = min mu_s, found in closed form while everything is
    at rest (no ramp effect), and its slip sets the others in motion with f > mu_d in both tests (for the
    pair and these seeds: measured, the quasi-static mu_eff is min mu_s). So mu_eff and the first start
    are min mu_s in both, to rounding (measured: equal to the bit; tolerance 1e-12). The ramp (1e-5 per
    tau_dyn) shows only in the loads reached during the motion: every node moves within 2 tau_dyn of the
    first start (measured: all_moving - min mu_s = 0.9e-5 to 1.9e-5; bound 2e-4), and sliding is proved
    after one or two checks, 2 pi tau_dyn apart (measured: certified - mu_eff = 6.8e-5 to 8.2e-5; bound 1e-3).
    """
    sc = scene(1, network=net, driver=SMALL_STEPS)
    real = Realization(sc, np.random.SeedSequence(seed))
    mu_min = real.mu.min()
    out = Dynamics(sc, tau_ratio=1e-4).tilt_test(np.zeros(real.mu.size), real.mu, np.random.default_rng(seed))
    assert out["mu_eff"] == pytest.approx(real.tilt_test(), abs=1e-12)
    assert out["mu_eff"] == pytest.approx(mu_min, abs=1e-12)
    assert out["first_start"] == pytest.approx(mu_min, abs=1e-12)
    assert mu_min <= out["all_moving"] < mu_min + 2e-4
    assert out["mu_eff"] < out["certified"] < out["mu_eff"] + 1e-3
    assert out["starts"] == real.mu.size


@pytest.mark.parametrize("rate", [1e-5, 1e-3], ids=["rate-1e-5", "rate-1e-3"])
def test_equal_thresholds_slide_at_mu_s(rate: float) -> None:
    """Four unstressed sliders with mu_s = 0.62: all reach it at f = 0.62, whatever the ramp.

    The start is found in closed form at rest, so mu_eff = 0.62 to rounding (tolerance 1e-12) at either
    rate; every node then moves at once (the ties at the threshold start at s = 0) and the chain, loaded
    0.12 above mu_d, slides as a rigid body: no internal mode is excited, so the proof holds at the first
    check, 2 pi tau_dyn later, and the certified load is 0.62 + 2 pi rate (measured to 1e-15; bound
    0.62 + 2 pi rate (1 + 1e-9)).
    """
    sc = scene(1, network=CHAIN_4, driver=SMALL_STEPS)
    out = Dynamics(sc, tau_ratio=1e-4).tilt_test(np.zeros(4), np.full(4, 0.62), np.random.default_rng(0),
                                                 rate=rate)
    assert out["mu_eff"] == pytest.approx(0.62, abs=1e-12)
    assert out["first_start"] == pytest.approx(0.62, abs=1e-12)
    assert out["all_moving"] == pytest.approx(0.62, abs=1e-12)
    assert 0.62 < out["certified"] <= 0.62 + 2 * np.pi * rate * (1 + 1e-9)
    assert out["starts"] == 4


def test_tilt_of_cycled_states_never_slides_at_or_below_mu_d() -> None:
    """States of a chain of 4 after 3 steps of cycling (prestressed: the first start comes early).

    Sliding is proved only with the mean load above mu_d, so certified > mu_d always; the loads are
    ordered first_start <= mu_eff <= certified and first_start <= all_moving <= certified; and a
    state that is tested twice from the same Generator seed gives the same loads (no hidden RNG).
    """
    sc = scene(3, network=CHAIN_4, driver=SMALL_STEPS)
    dyn = Dynamics(sc, tau_ratio=1e-4)
    out = dyn.run(np.random.SeedSequence(1), states=True)
    early = []
    for k in range(out["t"].size):
        args = (out["u"][k], out["mu_s"][k], np.random.default_rng(k))
        res = dyn.tilt_test(*args, theta=float(out["theta"][k]))
        assert res["certified"] > MU_D
        assert res["first_start"] <= res["mu_eff"] <= res["certified"]
        assert res["first_start"] <= res["all_moving"] <= res["certified"]
        early.append(res["first_start"] < MU_D)
        again = dyn.tilt_test(out["u"][k], out["mu_s"][k], np.random.default_rng(k), theta=float(out["theta"][k]))
        assert again == res
    assert any(early)  # the cycled states are prestressed


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"u": np.zeros(3)}, r"'u' parameter of Dynamics\.tilt_test must be a finite array of shape \(4,\)"),
        ({"u": np.full(4, np.nan)}, r"'u' parameter .* finite array"),
        ({"mu_s": np.full(4, 0.5)}, r"'mu_s' parameter of Dynamics\.tilt_test .* every value > mu_d = 0\.5"),
        ({"rng": np.random.SeedSequence(0)}, r"'rng' parameter of Dynamics\.tilt_test must be a numpy\.random"),
        ({"rate": 0.0}, r"'rate' parameter of Dynamics\.tilt_test must be a finite number > 0 \(per tau_dyn\)"),
        ({"rate": float("inf")}, r"'rate' .* Got inf"),
        ({"theta": float("nan")}, r"'theta' parameter of Dynamics\.tilt_test must be a finite number"),
    ],
    ids=["u-shape", "u-nan", "mu-at-mu-d", "rng-seedsequence", "rate-zero", "rate-inf", "theta-nan"],
)
def test_tilt_bad_arguments(kwargs: dict[str, Any], match: str) -> None:
    args = {"u": np.zeros(4), "mu_s": np.full(4, 0.6), "rng": np.random.default_rng(0), **kwargs}
    dyn = Dynamics(scene(1, network=CHAIN_4, driver=SMALL_STEPS), tau_ratio=1e-4)
    with pytest.raises(ConfigError, match=match):
        dyn.tilt_test(args.pop("u"), args.pop("mu_s"), args.pop("rng"), **args)

