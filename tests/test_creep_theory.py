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
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.analysis import theory
from slidernet.errors import ConfigError, OrbitError

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


# Chains of 3 and more: the exact orbit (theory.chain_creep*) against the solver.
#
# The theory follows the forces slip by slip in rational arithmetic; the
# solver finds each slip from its priority queue in floating point. At a
# segment end two events tie and rounding decides, so every case below sits
# inside a segment: CHAIN_CASES are checked to lie at least 1e-3 from the
# nearest end (test_chain_cases_sit_inside_their_segments).
CHAIN_CASES = [(3, 0.55, 0.12), (3, 0.55, 0.22), (3, 0.55, 0.26), (3, 0.55, 0.281), (3, 0.55, 0.29),
               (3, 0.55, 0.35), (3, 0.55, 0.42), (3, 0.62, 0.22), (3, 0.9, 0.31), (3, 1.3, 0.26),
               (4, 0.55, 0.29), (4, 0.55, 0.42), (8, 0.55, 0.455)]
CHAIN_IDS = [f"n{n}-A{a}-f{f}" for n, a, f in CHAIN_CASES]


def _steady(n: int, A: float, f: float, cycles: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """The solver's x_G (l0) and slips per cycle over the last half of the run."""
    ds = _run(A, f, n=n, cycles=cycles)
    return tuple(np.diff(ds[name].values[0])[cycles // 2:] for name in ("x_G", "n"))


def _steady_dx(n: int, A: float, f: float, cycles: int = 12) -> np.ndarray:
    """The solver's x_G per cycle over the last half of the run, in l0."""
    return _steady(n, A, f, cycles)[0]


@pytest.mark.parametrize("n,A,f", CHAIN_CASES, ids=CHAIN_IDS)
def test_chain_cases_sit_inside_their_segments(n, A, f):
    ends = [s.lo for s in theory.chain_creep_segments(n, NTILDE, MU_S, MU_D, tan_alpha=(0.01, 0.49),
                                                      amplitude=A * NTILDE)]
    assert min(abs(np.asarray(ends[1:]) - f)) > 1e-3


@pytest.mark.parametrize("n,A,f", CHAIN_CASES, ids=CHAIN_IDS)
def test_chain_steady_creep_is_the_exact_orbit(n, A, f):
    slips, dx = theory.chain_creep(n, A * NTILDE, NTILDE, f, MU_S, MU_D)
    measured, n_rec = _steady(n, A, f)
    # The mean over the last 6 cycles: a whole number of periods for an orbit of period 1, 2 or 3.
    np.testing.assert_allclose(measured.mean(), float(dx), rtol=1e-9, atol=1e-22)
    assert n_rec.mean() == pytest.approx(float(slips), rel=1e-12)


def test_two_slider_chain_is_the_pair_closed_form():
    A = np.array([0.45, 0.55, 0.62, 0.9, 1.37])[:, None]
    f = np.array([0.07, 0.13, 0.21, 0.33, 0.47])[None, :]
    slips, dx = theory.chain_creep(2, A * NTILDE, NTILDE, f, MU_S, MU_D)
    m, dx_pair = theory.pair_creep(A * NTILDE, NTILDE, f, MU_S, MU_D)
    np.testing.assert_array_equal(slips, 2 * m)
    np.testing.assert_allclose(dx, dx_pair, rtol=1e-12)


@given(x=st.floats(0.0, 1.5))
@settings(max_examples=100, deadline=None)
def test_the_pair_segments_are_the_closed_form_staircase(x):
    """Along the angle, two sliders' segments end exactly at pair_creep_steps and carry its m."""
    steps = theory.pair_creep_steps(x * NTILDE, NTILDE, MU_S, MU_D)
    # A step on an end of the range would be a segment end or not by rounding.
    assume(np.all(abs(steps[:, None] - np.array([0.01, 0.49])) > 1e-9))
    segments = theory.chain_creep_segments(2, NTILDE, MU_S, MU_D, tan_alpha=(0.01, 0.49), amplitude=x * NTILDE)
    ends = np.array([b.lo for a, b in itertools.pairwise(segments) if a.slips != b.slips])
    np.testing.assert_allclose(ends, steps[(steps > 0.01) & (steps < 0.49)], atol=1e-12)
    for seg in segments:
        mid = 0.5 * (seg.lo + seg.hi)
        assert seg.dx_lo == seg.dx_hi == pytest.approx(float(theory.pair_creep(x * NTILDE, NTILDE, mid, MU_S,
                                                                                MU_D)[1]), rel=1e-12)


@pytest.mark.parametrize("n", [3, 4])
def test_segments_tile_the_range_and_hold_the_orbit(n):
    A = 0.55
    segments = theory.chain_creep_segments(n, NTILDE, MU_S, MU_D, tan_alpha=(0.01, 0.49), amplitude=A * NTILDE)
    assert segments[0].lo == pytest.approx(0.01) and segments[-1].hi == pytest.approx(0.49)
    for a, b in itertools.pairwise(segments):
        assert a.hi == b.lo
    rng = np.random.default_rng(17)
    for seg in segments:
        for w in rng.uniform(0.05, 0.95, 3):
            p = seg.lo + w * (seg.hi - seg.lo)
            slips, dx = theory.chain_creep(n, A * NTILDE, NTILDE, p, MU_S, MU_D)
            assert float(slips) == seg.slips
            assert float(dx) == pytest.approx(seg.dx_lo + w * (seg.dx_hi - seg.dx_lo), rel=1e-9, abs=1e-20)


@pytest.mark.parametrize("mu_s,mu_d", [(0.6, 0.5), (0.65, 0.52)], ids=["0.6-0.5", "0.65-0.52"])
def test_three_sliders_first_creeping_segment_is_the_derived_law(mu_s, mu_d):
    """The guide derives it: one end slips by D, the middle overshoots, the same end slips again.

    The middle slider's force at rest settles at c = 4 mu_d - 2 mu_s - f and each half cycle's three
    slips sum to 3 (mu_d - f) Ntilde: x_G advances 2 (mu_d - f) Ntilde per cycle.
    """
    A = 0.55
    creeping = [s for s in theory.chain_creep_segments(3, NTILDE, mu_s, mu_d, tan_alpha=(0.01, 0.45),
                                                       amplitude=A * NTILDE) if s.dx_lo > 0 or s.dx_hi > 0]
    first = creeping[0]
    assert first.slips == 6
    np.testing.assert_allclose([first.dx_lo, first.dx_hi], [2 * (mu_d - first.lo) * NTILDE,
                                                            2 * (mu_d - first.hi) * NTILDE], rtol=1e-12)
    # The derivation holds while c > mu_d (the middle's overshoot hands the end more than D / 2 over
    # threshold) and c + D > mu_s: f < 3 mu_d - 2 mu_s.
    assert first.hi <= 3 * mu_d - 2 * mu_s + 1e-12


@pytest.mark.parametrize("f", [0.22, 0.31])
def test_three_sliders_creep_starts_at_the_critical_amplitude(f):
    A_c = theory.chain_critical_amplitude(3, NTILDE, f, MU_S, MU_D, amplitude_max=1.5 * NTILDE) / NTILDE
    assert np.all(_steady_dx(3, A_c - 0.005, f) == 0)
    assert np.all(_steady_dx(3, A_c + 0.005, f) > 0)


@pytest.mark.parametrize("f", [0.07, 0.2, 0.33])
def test_two_slider_critical_amplitude_is_the_closed_form(f):
    from_rest, _ = theory.pair_critical_amplitude(NTILDE, f, MU_S, MU_D)
    got = theory.chain_critical_amplitude(2, NTILDE, f, MU_S, MU_D, amplitude_max=2 * NTILDE)
    assert got == pytest.approx(from_rest, rel=1e-12)


@pytest.mark.parametrize("kwargs,match", [
    ({"n_sliders": 1}, "'n_sliders' parameter of chain_creep_segments must be an integer >= 2. Got 1"),
    ({"amplitude": (0.0, 1e-7)}, "Exactly one of 'tan_alpha' and 'amplitude'"),
    ({"tan_alpha": (0.2, 0.1)}, "'tan_alpha' parameter of chain_creep_segments must be a range"),
    ({"tan_alpha": (0.2, 0.6)}, "'tan_alpha' parameter of chain_creep_segments must be in"),
], ids=["one-slider", "two-ranges", "reversed", "slides-away"])
def test_the_segments_refuse_bad_arguments(kwargs, match):
    args = {"n_sliders": 3, "tan_alpha": (0.1, 0.3), "amplitude": 0.55e-7} | kwargs
    n = args.pop("n_sliders")
    with pytest.raises(ConfigError, match=match):
        theory.chain_creep_segments(n, NTILDE, MU_S, MU_D, **args)


@pytest.mark.parametrize("mu_s,mu_d", [(0.6, 0.5), (0.65, 0.52), (0.58, 0.5)],
                         ids=["0.6-0.5", "0.65-0.52", "0.58-0.5"])
@pytest.mark.parametrize("w", [0.05, 0.35, 0.6, 0.95])
def test_three_sliders_closed_form_onset_is_the_exact_orbit(mu_s, mu_d, w):
    """three_slider_onset (derived by hand in the guide) against the exact orbit, across its window."""
    D = 2 * (mu_s - mu_d)
    lo, hi = max(mu_s - 2 * D, mu_d / 2 - D / 4), 3 * mu_d - 2 * mu_s
    f = lo + w * (hi - lo)
    A_c, A_next, dx = theory.three_slider_onset(NTILDE, f, mu_s, mu_d)
    got = theory.chain_critical_amplitude(3, NTILDE, f, mu_s, mu_d, amplitude_max=2 * NTILDE)
    assert got == pytest.approx(A_c, rel=1e-12)
    plateau = theory.chain_creep_segments(3, NTILDE, mu_s, mu_d, tan_alpha=f,
                                          amplitude=(0.5 * A_c, A_next + 0.5 * D * NTILDE))
    assert [s.slips for s in plateau[:2]] == [0, 6] and len(plateau) > 2  # the next plateau differs
    assert plateau[1].lo == pytest.approx(A_c, rel=1e-12) and plateau[1].hi == pytest.approx(A_next, rel=1e-12)
    assert plateau[1].dx_lo == plateau[1].dx_hi == pytest.approx(dx, rel=1e-12)


@pytest.mark.parametrize("f", [0.19, 0.31])
def test_three_slider_onset_refuses_angles_outside_its_window(f):
    with pytest.raises(ConfigError, match=r"'tan_alpha' parameter of three_slider_onset must be in \(0.2"):
        theory.three_slider_onset(NTILDE, f, MU_S, MU_D)


def test_three_sliders_on_the_plateau_in_the_solver():
    """Solver, constant thresholds: zero just below three_slider_onset's A_c, its velocity on the plateau."""
    f = 0.24
    A_c, A_next, dx = theory.three_slider_onset(NTILDE, f, MU_S, MU_D)
    assert np.all(_steady_dx(3, 0.99 * A_c / NTILDE, f) == 0)
    np.testing.assert_allclose(_steady_dx(3, 0.5 * (A_c + A_next) / NTILDE, f), dx, rtol=1e-9)


def test_three_sliders_settle_into_a_one_cycle_orbit():
    """The claim of the guide for three sliders at generic parameters: period 1 after at most one cycle.

    100 parameter sets drawn with seed 7 (A / Ntilde in [0, 2], mu_d in [0.2, 0.6], mu_s - mu_d in
    [0.01, 0.3], f / mu_d in [0.01, 0.99]). Random reals avoid exact ties, where longer periods occur
    (test_an_exact_tie_can_lengthen_the_period).
    """
    rng = np.random.default_rng(7)
    for A, mu_d, gap, w in rng.uniform([0.0, 0.2, 0.01, 0.01], [2.0, 0.6, 0.3, 0.99], size=(100, 4)):
        orbit = theory.chain_orbit(3, A * NTILDE, NTILDE, w * mu_d, mu_d + gap, mu_d, max_cycles=3)
        assert orbit.period == 1 and orbit.transient <= 1 and orbit.dx >= 0


def test_an_exact_tie_can_lengthen_the_period():
    """Parameters exact in binary make two events coincide: the orbit then repeats every 22 cycles.

    Found by hypothesis. A hair's breadth away in f the orbit has period 1 on either side, with other
    velocities: at a tie, floating-point rounding in the solver decides which orbit it follows.
    """
    args = (0.75 * NTILDE, NTILDE)
    tied = theory.chain_orbit(3, *args, 0.171875, 0.59375, 0.34375)
    assert (tied.period, tied.transient) == (22, 1)
    above = theory.chain_orbit(3, *args, 0.171875 + 1e-9, 0.59375, 0.34375)
    below = theory.chain_orbit(3, *args, 0.171875 - 1e-9, 0.59375, 0.34375)
    assert above.period == below.period == 1 and above.slips == 6 and below.slips == 8 and below.dx == 0


# Four sliders where the orbit does not repeat: the solver's advance per cycle wanders between 1.47 and
# 2.43 Ntilde over 200 cycles. Found by drawing random parameters.
APERIODIC = (4, 1.452947220624741, 0.12814064609379852, 0.48603783511332405, 0.3460029054034236)


def test_an_aperiodic_orbit_is_nan_with_a_warning_and_no_segment():
    n, A, f, mu_s, mu_d = APERIODIC
    with pytest.warns(RuntimeWarning, match=r"orbit of 4 sliders did not repeat within max_cycles = 40 at 1 of 2"):
        slips, dx = theory.chain_creep(n, [A * NTILDE, 0.5 * NTILDE], NTILDE, f, mu_s, mu_d, max_cycles=40)
    assert np.isnan(slips[0]) and np.isnan(dx[0]) and np.isfinite(dx[1])
    with pytest.raises(OrbitError, match=r"did not repeat within max_cycles = 40 cycles \(tan_alpha = 0.128"):
        theory.chain_creep_segments(n, NTILDE, mu_s, mu_d, tan_alpha=(f, f + 1e-3), amplitude=A * NTILDE,
                                    max_cycles=40)
