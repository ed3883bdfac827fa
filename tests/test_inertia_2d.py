"""The compiled inertial solver of 2D networks (solver.inertia_2d) against the reference integrator.

Slip for slip on the same streams (validation.dynamics.Dynamics at its defaults), the energy balance of every
avalanche, the closed form of an isolated slip on an isotropic spring, and the checks of the arguments. Every
run is deterministic (fixed seeds); each test states its tolerance and the measured value.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from slidernet.config import load_config
from slidernet.errors import AvalancheError, ConfigError
from slidernet.kernels import inertia_2d as kern
from slidernet.model.network import Network
from slidernet.solver import Scene
from slidernet.solver.inertia_2d import Inertia2D
from slidernet.validation.dynamics import STOP_SPEED, Dynamics, realization_draws

Ntilde = 1e-7
MU_D = 0.5
FRICTION = {"mu_d": MU_D, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}


def scene(net: dict[str, Any] | None = None, sigma: float = 0.2, steps: int = 1,
          network: Network | None = None) -> Scene:
    """One or a few thermal steps of sigma_theta = sigma Ntilde on a 2D network, every step recorded."""
    cfg = {"steps": steps, "record": "all", "friction": FRICTION,
           "network": dict(net or {"kind": "triangular", "shape": [2, 2]}, Ntilde=Ntilde),
           "driver": {"name": "gaussian_steps", "sigma_theta": sigma * Ntilde}}
    return Scene.from_config(load_config(cfg), network=network)


IRREGULAR = {"kind": "irregular", "n": 16, "seed": 0}
TRIANGULAR = {"kind": "triangular", "shape": [4, 4]}
# (network, sigma_theta / Ntilde, seed): tens of slips in one tau_th, some of them overlapping.
CASES = {"irregular-16": (IRREGULAR, 0.15, 0), "triangular-4x4": (TRIANGULAR, 0.5, 1)}
TAUS = [1e-4, 1e-2]


@pytest.fixture(scope="module", params=[(case, tau) for case in CASES for tau in TAUS],
                ids=[f"{case}-tau-{tau:g}" for case in CASES for tau in TAUS])
def pair(request: pytest.FixtureRequest) -> tuple[dict, dict]:
    """The compiled solver's run and the reference integrator's, on the same scene and seed."""
    case, tau = request.param
    net, sigma, seed = CASES[case]
    sc = scene(net, sigma)
    out = Inertia2D(sc, tau_ratio=tau).run(np.random.SeedSequence(seed))
    ref = Dynamics(sc, tau_ratio=tau).run(np.random.SeedSequence(seed))
    return out, ref


def test_stop_speed_is_the_references() -> None:
    assert kern.STOP_SPEED == STOP_SPEED


def test_slip_for_slip(pair: tuple[dict, dict]) -> None:
    """The same nodes slip in the same order, with the same displacements, counts and thresholds.

    22 to 61 slips per case, 3 to 33 of them starting while another node moved. Measured: displacements within
    5.6e-10 of each slip's length (the reference's own error at rtol = 1e-8 is ~3e-9 over 150 slips, against
    itself at 1e-12); tolerance 1e-8. Durations within 8.2e-8 relative (a stop at |v| = STOP_SPEED is
    ill-conditioned in time where the deceleration is small, not in place); tolerance 1e-6.
    """
    out, ref = pair
    a, b = out["slips"], ref["slips"]
    assert b["node"].size >= 20
    assert np.array_equal(a["node"], b["node"])
    length = np.hypot(*b["du"].T)
    assert np.abs(a["du"] - b["du"]).max(axis=1) / length == pytest.approx(0.0, abs=1e-8)
    assert a["duration"] / b["duration"] == pytest.approx(1.0, rel=1e-6)
    assert a["start"] == pytest.approx(b["start"], rel=0, abs=1e-9)
    assert np.array_equal(out["n"], ref["n"])
    assert np.array_equal(out["mu_max"], ref["mu_max"])
    assert out["x_G"] == pytest.approx(ref["x_G"], rel=0, abs=1e-8 * np.abs(b["du"]).max())
    assert (out["overlapping"], out["moving_at_end"]) == (ref["overlapping"], ref["moving_at_end"])
    assert out["stop_speed"] / Ntilde == pytest.approx(STOP_SPEED, rel=1e-6)


def test_energy_balance_of_every_avalanche(pair: tuple[dict, dict]) -> None:
    """Work of the thermal load = change of elastic energy + sum_i mu_d N_i (path length of u_i), per avalanche.

    The kinetic energy is zero at both ends but for the (1/2) N_i |v_i|^2 <= (1/2) N_i STOP_SPEED^2 Ntilde^2
    dropped at each stop (``dropped``, counted). Measured: 1.0e-11 relative to the dissipation; tolerance 1e-9.
    Every start belongs to one avalanche, and the paths are at least the displacements.
    """
    out, _ = pair
    av = out["avalanches"]
    assert av["start"].size > 0
    residual = av["work"] - av["dE"] - av["dissipation"] - av["dropped"]
    assert np.abs(residual) / av["dissipation"] == pytest.approx(0.0, abs=1e-9)
    # An avalanche still running at the end is not in the list.
    assert av["starts"].sum() == out["n"][-1] if out["moving_at_end"] == 0 else av["starts"].sum() < out["n"][-1]
    slips = out["slips"]
    assert (slips["path"] >= np.hypot(*slips["du"].T) * (1 - 1e-12)).all()


def corner(angle: float, load: float) -> Network:
    """Node 0 at the corner of an L, held by two unit springs along x and y (K_00 = 1, isotropic), with an
    external force of ``load`` N along ``angle``; nodes 1 and 2 carry 1e6 normal loads and never move."""
    f_ext = np.zeros((3, 2))
    f_ext[0] = load * np.array([math.cos(angle), math.sin(angle)])
    return Network([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], [[0, 1], [0, 2]], Ntilde,
                   normal_load=[1.0, 1e6, 1e6], f_ext=f_ext)


ANGLES = [0.0, 0.7, 2.5, 4.0]


@pytest.mark.parametrize("angle", ANGLES, ids=[f"angle-{a:.2f}" for a in ANGLES])
def test_isolated_slip_is_the_closed_form(angle: float) -> None:
    """A slider on an isotropic spring, overloaded at t = 0 (theta frozen): a half-oscillation along F.

    |F| = 0.65 N > mu_s: length 2 (|F| - mu_d N) / k = 0.3 Ntilde l0 along F, duration pi tau_dyn. The stop
    at |v| = STOP_SPEED comes STOP_SPEED / 0.15 tau_dyn early (deceleration mu_d - 0.35 at the stop), 2.1e-6
    of pi, and STOP_SPEED^2 / 0.3 = 3e-12 Ntilde l0 short. Measured: length -5.4e-11 relative (the scheme's
    rtol = 1e-10), direction within 5e-16 rad, duration pi (1 - 2.1e-6) to 2e-12; tolerances 1e-9, 1e-9 rad
    and 3e-7 about the early stop.
    """
    sc = scene(network=corner(angle, 0.65))
    tau = 1e-4
    out = Inertia2D(sc, tau_ratio=tau).run(np.random.SeedSequence(4))
    slip = {key: value[0] for key, value in out["slips"].items()}
    assert slip["node"] == 0 and slip["start"] == 0.0
    du = slip["du"] / Ntilde
    assert np.hypot(*du) == pytest.approx(2 * (0.65 - MU_D), rel=1e-9)
    assert abs(math.atan2(du[1], du[0]) - math.remainder(angle, 2 * math.pi)) < 1e-9
    early = STOP_SPEED / (MU_D - 0.35) / math.pi
    assert slip["duration"] / (tau * math.pi) == pytest.approx(1 - early, abs=3e-7)
    assert slip["path"] / Ntilde == pytest.approx(np.hypot(*du), rel=1e-12)


def _square(f_ext: np.ndarray) -> Network:
    """Four unit-load nodes on a unit square with one diagonal, forces ``f_ext`` (N)."""
    return Network([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
                   Ntilde, f_ext=f_ext)


HARD = {
    # |F| = 1.7 N >= 3 mu_d N: the slider comes to rest at the turning point (length 2.4) under |F - k du| =
    # 0.7 N, above its new threshold, and starts again at once (a new rearrangement) back along F, by 0.4.
    "restart": corner(0.7, 1.7),
    # Nodes 0 and 2 above their thresholds at t = 0 start together (the larger overload first), then the
    # drive's slips overlap them.
    "simultaneous": _square(np.array([[0.7, 0.1], [0.0, 0.0], [-0.5, 0.45], [0.0, 0.0]])),
}


@pytest.mark.parametrize("tau", TAUS, ids=[f"tau-{tau:g}" for tau in TAUS])
@pytest.mark.parametrize("case", list(HARD), ids=list(HARD))
def test_hard_cases_slip_for_slip(case: str, tau: float) -> None:
    """An immediate restart and simultaneous starts, against the reference integrator on the same streams.

    Measured: displacements within 4.1e-10 (restart) and 9.4e-11 (simultaneous) of the slips' lengths;
    tolerance 1e-8. The restart's two slips are the closed form's, 2.4 and 0.4 Ntilde l0 along +F and -F, to
    1e-9 relative.
    """
    sc = scene(network=HARD[case], sigma=0.2, steps=2)
    out = Inertia2D(sc, tau_ratio=tau).run(np.random.SeedSequence(0))
    ref = Dynamics(sc, tau_ratio=tau).run(np.random.SeedSequence(0))
    a, b = out["slips"], ref["slips"]
    assert np.array_equal(a["node"], b["node"]) and np.array_equal(out["n"], ref["n"])
    assert out["overlapping"] == ref["overlapping"]
    length = np.hypot(*b["du"].T)
    assert np.abs(a["du"] - b["du"]).max(axis=1) / length == pytest.approx(0.0, abs=1e-8)
    if case == "restart":
        assert a["start"][:2].tolist() == [0.0, 0.0] and a["node"][:2].tolist() == [0, 0]
        along = a["du"][:2] @ np.array([math.cos(0.7), math.sin(0.7)]) / Ntilde
        assert along == pytest.approx([2.4, -0.4], rel=1e-9)
    else:
        assert a["node"][:2].tolist() == [0, 2] and a["start"][:2].tolist() == [0.0, 0.0]


@pytest.mark.parametrize("seed", [0, 1, 2], ids=["seed-0", "seed-1", "seed-2"])
def test_counts_add_up(seed: int) -> None:
    """n counts the starts: every slip that ended, plus the nodes moving at the end; thresholds as the solver's.

    The initial thresholds are the realization's (realization_draws), and every slip's start precedes its end.
    """
    sc = scene(IRREGULAR, sigma=1.0, steps=2)
    out = Inertia2D(sc, tau_ratio=1e-3).run(np.random.SeedSequence(seed))
    slips = out["slips"]
    assert out["n"][-1] == slips["node"].size + out["moving_at_end"]
    assert (slips["end"] >= slips["start"]).all() and (np.diff(slips["end"]) >= 0).all()
    _, draws = realization_draws(sc, np.random.SeedSequence(seed))
    assert out["mu_max"][0] == draws.initial.max()


def test_refills_change_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    """The kernel returns whenever a buffer is full or empty and resumes where it was: thresholds in batches of
    2 (solver.batch) and slip and avalanche buffers of 3 rows give the run of the defaults, bit for bit."""
    cfg = {"steps": 2, "record": "all", "friction": FRICTION,
           "network": dict(IRREGULAR, Ntilde=Ntilde), "driver": {"name": "gaussian_steps", "sigma_theta": Ntilde}}
    out = Inertia2D(Scene.from_config(load_config(cfg)), tau_ratio=1e-3).run(np.random.SeedSequence(0))
    monkeypatch.setattr("slidernet.solver.inertia_2d.OUT_CHUNK", 3)
    small = Scene.from_config(load_config({**cfg, "solver": {"batch": 2}}))
    again = Inertia2D(small, tau_ratio=1e-3).run(np.random.SeedSequence(0))
    assert out["slips"]["node"].size > 100
    for key in ("n", "mu_max", "x_G"):
        assert np.array_equal(out[key], again[key])
    for part in ("slips", "avalanches"):
        for key, value in out[part].items():
            assert np.array_equal(value, again[part][key]), (part, key)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"tau_ratio": 0.0}, r"'tau_ratio' parameter of Inertia2D must be a finite number > 0\. Got 0\.0"),
        ({"tau_ratio": True}, r"'tau_ratio' parameter of Inertia2D must be a finite number > 0"),
        ({"tau_ratio": 1e-4, "rtol": 1e-2}, r"'rtol' parameter of Inertia2D must be a number in \[1e-14, 1e-3\]"),
        ({"tau_ratio": 1e-4, "max_step": math.inf}, r"'max_step' parameter of Inertia2D must be a finite number"),
    ],
    ids=["tau-zero", "tau-bool", "rtol-large", "max-step-inf"],
)
def test_bad_arguments(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        Inertia2D(scene(), **kwargs)


def test_a_load_friction_cannot_hold_is_refused() -> None:
    """Two sliders pushed together along x by 0.7 N each (above mu_s and mu_d) slide for ever: the run stops
    after MAX_SLIP_DURATION tau_dyn of motion with the reference's AvalancheError."""
    net = Network([[0.0, 0.0], [1.0, 0.0]], [[0, 1]], Ntilde, f_ext=np.array([[0.7, 0.0], [0.7, 0.0]]))
    with pytest.raises(AvalancheError, match=r"Node [01] has been sliding for 1000 tau_dyn without stopping"):
        Inertia2D(scene(network=net), tau_ratio=1e-4).run(np.random.SeedSequence(0))


def test_1d_scene_is_refused() -> None:
    sc = Scene.from_config(load_config({"steps": 1, "friction": FRICTION,
                                        "network": {"kind": "chain", "n": 3, "Ntilde": Ntilde},
                                        "driver": {"name": "gaussian_steps", "sigma_theta": Ntilde}}))
    with pytest.raises(ConfigError, match="Inertia2D runs 2D networks; this scene's network is 1D"):
        Inertia2D(sc, tau_ratio=1e-4)


def test_bad_steps() -> None:
    with pytest.raises(ConfigError, match=r"'steps' parameter of Inertia2D\.run must be an integer in \[0, 1\]"):
        Inertia2D(scene(), tau_ratio=1e-4).run(np.random.SeedSequence(0), steps=2)
