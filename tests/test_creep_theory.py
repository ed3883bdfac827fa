"""Thermal creep of two sliders on an incline with constant thresholds: theory.pair_creep* against the solver.

The solver and the theory share nothing: the solver finds each slip from
eq. `critique` event by event, the theory maps the spring's compression from
one turning point of theta to the next in closed form. With constant
thresholds both are exact, so they must agree to rounding.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.analysis import theory
from slidernet.errors import ConfigError

MU_S, MU_D, NTILDE = 0.6, 0.5, 1e-7
D = 2 * (MU_S - MU_D)
PERIOD = 20  # a multiple of 4: the sampled sine reaches +-A exactly
CYCLES = 8


def _run(amplitude: float, f: float, n: int = 2, cycles: int = CYCLES, phase: float = 0.0):
    steps = PERIOD * cycles
    cfg = {"seed": 1, "realizations": 1, "steps": steps, "record": list(range(0, steps + 1, PERIOD)),
           "observables": ["n", "x_G"],
           "network": {"kind": "chain", "n": n, "Ntilde": NTILDE, "f_ext": float(f)},
           "friction": {"mu_d": MU_D, "static": {"name": "constant", "value": MU_S}},
           "driver": {"name": "sinusoidal", "amplitude": amplitude * NTILDE, "period": PERIOD, "phase": phase}}
    return slidernet.run(cfg, progress=False)


# (A / Ntilde, tan alpha): below the critical amplitude, on each of the first plateaus, and far up.
CASES = [(0.45, 0.1), (0.55, 0.1), (0.55, 0.3), (0.62, 0.25), (0.9, 0.45), (1.37, 0.2)]


@pytest.mark.parametrize("A,f", CASES, ids=[f"A{a}-f{f}" for a, f in CASES])
def test_steady_creep_per_cycle_is_the_closed_form(A, f):
    ds = _run(A, f)
    dx = np.diff(ds["x_G"].values[0])
    m, dx_theory = theory.pair_creep(A * NTILDE, NTILDE, f, MU_S, MU_D)
    # From the second cycle on the motion is periodic (the first holds the first rise).
    np.testing.assert_allclose(dx[1:], float(dx_theory), rtol=1e-9, atol=1e-22)
    assert (np.diff(ds["n"].values[0])[1:] == 2 * int(m)).all()


@pytest.mark.parametrize("A,f", CASES, ids=[f"A{a}-f{f}" for a, f in CASES])
def test_the_slips_of_every_stretch_are_the_map(A, f):
    """Stretch by stretch, the transient included: the solver's slips between turning points are the map's."""
    steps = PERIOD * CYCLES
    # theta is 0 at t = 0 and turns at t = P/4 + j P/2 (+A, -A, +A, ...).
    turns = [0, *range(PERIOD // 4, steps, PERIOD // 2)]
    cfg = {"seed": 1, "realizations": 1, "steps": steps, "record": turns, "observables": ["n"],
           "network": {"kind": "chain", "n": 2, "Ntilde": NTILDE, "f_ext": float(f)},
           "friction": {"mu_d": MU_D, "static": {"name": "constant", "value": MU_S}},
           "driver": {"name": "sinusoidal", "amplitude": A * NTILDE, "period": PERIOD}}
    n = slidernet.run(cfg, progress=False)["n"].sel(t=turns).values[0]
    turning = np.concatenate([[0.0], np.tile([A, -A], len(turns))[: len(turns) - 1]])
    np.testing.assert_array_equal(np.diff(n), theory.pair_creep_slips(turning, f, MU_S, MU_D))


def test_no_creep_below_the_critical_amplitude_from_rest():
    f = 0.2
    from_rest, _ = theory.pair_critical_amplitude(NTILDE, f, MU_S, MU_D)
    below = _run(0.999 * from_rest / NTILDE, f)
    above = _run(1.001 * from_rest / NTILDE, f)
    assert (below["n"].values == 0).all() and (below["x_G"].values == 0).all()
    assert np.diff(above["x_G"].values[0])[-1] > 0


@given(big=st.floats(1.0, 3.0), small=st.floats(0.0, 0.999), f=st.floats(0.05, 0.45))
@settings(max_examples=200, deadline=None)
def test_creep_cannot_last_below_the_amplitude_for_any_state(big, small, f):
    """Whatever state a large cycle leaves, a cycle of amplitude below (mu_d - f) Ntilde stops the creep."""
    _, any_state = theory.pair_critical_amplitude(NTILDE, f, MU_S, MU_D)
    a = small * any_state / NTILDE
    turning = np.concatenate([[0.0], np.tile([big, -big], 3), np.tile([a, -a], 6)])
    slips = theory.pair_creep_slips(turning, f, MU_S, MU_D)
    assert slips[-8:].sum() == 0


def test_between_the_two_amplitudes_creep_depends_on_the_state():
    """Above (mu_d - f) Ntilde some states keep creeping, where rest does not.

    Every slip is D, so G = theta - (u_2 - u_1) stays congruent to theta modulo D: from rest a cycle
    about theta = 0 always meets the same states. A cycle about another mean (theta0) meets others.
    """
    f = 0.1
    from_rest, any_state = theory.pair_critical_amplitude(NTILDE, f, MU_S, MU_D)
    a = 0.5 * (from_rest + any_state) / NTILDE
    rest = theory.pair_creep_slips(np.concatenate([[0.0], np.tile([a, -a], 6)]), f, MU_S, MU_D)
    assert rest.sum() == 0
    lasting = [theory.pair_creep_slips(np.concatenate([[0.0], [1.0, -1.0], c + np.tile([a, -a], 6)]),
                                       f, MU_S, MU_D)[-6:].sum() > 0
               for c in np.linspace(0.0, D, 41)]
    assert any(lasting) and not all(lasting)


def test_the_staircase_steps_where_the_closed_form_says():
    A = 0.55
    steps = theory.pair_creep_steps(A * NTILDE, NTILDE, MU_S, MU_D)
    np.testing.assert_allclose(steps, [0.05, 0.25, 0.45])
    for lo, hi in itertools.pairwise(steps):
        m_lo, _ = theory.pair_creep(A * NTILDE, NTILDE, lo + 1e-9, MU_S, MU_D)
        m_hi, _ = theory.pair_creep(A * NTILDE, NTILDE, hi - 1e-9, MU_S, MU_D)
        assert m_lo == m_hi  # a plateau
        assert theory.pair_creep(A * NTILDE, NTILDE, hi + 1e-9, MU_S, MU_D)[0] == m_hi + 2


@pytest.mark.parametrize("f,match", [(0.0, "'tan_alpha' parameter of pair_creep must be in"),
                                     (0.5, "'tan_alpha' parameter of pair_creep must be in")],
                         ids=["flat", "slides-away"])
def test_the_theory_refuses_angles_outside_its_range(f, match):
    with pytest.raises(ConfigError, match=match):
        theory.pair_creep(1e-7, NTILDE, f, MU_S, MU_D)
