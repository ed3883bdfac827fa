"""Unit tests of the slip equations (paper section II.C) and of the compiled kernels.

Internal units (kernels.py docstring): forces in N, k = 1, lengths and theta in
units of Ntilde (l0), so eq. `critique` reads theta_c = u + mu_min s and eq.
`displacement` reads Delta u = 2 (mu_min - mu_d) s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import slidernet
from slidernet import AvalancheError, kernels
from slidernet.plugins.distributions import Gaussian, TruncatedBelow
from slidernet.solver import Realization, realization_streams, simulate
from tests.conftest import make_config, realization_of, scene_of

MU_D = 0.5


# --------------------------------------------------------------------------
# Direct calls of run_pair on hand-built states
# --------------------------------------------------------------------------


class PairState:
    """A hand-built two-slider state and the buffers run_pair needs."""

    def __init__(self, u: float, theta: float, mu: tuple[float, float], out_steps=(0, 1)):
        self.state = kernels.new_state()
        self.st = self.state[0]
        self.st["u"] = u
        self.st["theta"] = theta
        self.st["mu_max"] = max(mu)
        self.mu = np.array(mu, dtype=float)
        self.out_steps = np.asarray(out_steps, dtype=np.int64)
        T = self.out_steps.size
        nothing = np.empty(0)
        self.out = kernels.Series(n=np.zeros(T, np.int64), mu_max=np.zeros(T), x_G=np.zeros(T),
                                  n_records=np.zeros(T, np.int64), mu_mean=nothing, mu_min=nothing, y_G=nothing,
                                  f_sum=np.zeros(T), f_sq=np.zeros(T), f_count=np.zeros(T, np.int64),
                                  contact_age=nothing,
                                  contact_age_count=np.zeros((0, kernels.N_AGE_BINS), np.int64))

    def run(self, thetas, mu_buf, mu_d: float = MU_D, slip_factor: float = 2.0) -> int:
        draws = kernels.Draws(np.asarray(mu_buf, dtype=float), np.empty(0), np.empty(0))
        settings = kernels.Settings(mu_d=mu_d, max_slips=1000, recompute_every=0, slip_factor=slip_factor)
        return kernels.run_pair(np.asarray(thetas, dtype=float), self.out_steps, self.mu, self.state, draws,
                                self.out, settings)

    @property
    def n(self) -> int:
        return int(self.st["n_slips"])


# (mu_s,1, mu_s,2) with slider 1 or slider 2 the weaker one.
WEAK1 = (0.58, 0.62)
WEAK2 = (0.62, 0.58)


@pytest.mark.parametrize("s", [1.0, -1.0], ids=["dilating", "contracting"])
@pytest.mark.parametrize("mu", [WEAK1, WEAK2], ids=["slider1-weaker", "slider2-weaker"])
def test_single_slip_follows_eq_displacement(mu, s):
    u0 = 0.25
    i = 1 if mu[0] < mu[1] else 2  # the paper's slider label of the weakest
    mu_min = min(mu)
    theta_c = u0 + mu_min * s
    st = PairState(u=u0, theta=u0, mu=mu)
    # theta ends 0.05 past theta_c: after the slip the next theta_c is
    # u0 + 2 (mu_min - mu_d) s + 0.6 s, well beyond the end, so exactly one slip.
    status = st.run([u0, theta_c + 0.05 * s], mu_buf=[0.6])
    assert status == kernels.DONE
    assert st.n == 1
    assert st.st["u"] == pytest.approx(u0 + 2 * (mu_min - MU_D) * s, abs=1e-14)
    # eq. `displacmt-G`: half the slip, sign (-1)^i s.
    assert st.st["x_G"] == pytest.approx((-1) ** i * (mu_min - MU_D) * s, abs=1e-14)
    # Only the weakest threshold is redrawn (it takes the first buffer value).
    expected = list(mu)
    expected[i - 1] = 0.6
    assert st.mu.tolist() == expected
    assert st.st["mu_max"] == max(expected)
    assert st.st["n_events"] == 1


@pytest.mark.parametrize("s", [1.0, -1.0], ids=["dilating", "contracting"])
@pytest.mark.parametrize("mu", [WEAK1, WEAK2], ids=["slider1-weaker", "slider2-weaker"])
def test_rearrangement_happens_at_theta_c(mu, s):
    u0 = -0.3
    theta0 = u0 + 0.1 * s  # a loaded but stable spring
    theta_c = u0 + min(mu) * s  # eq. `critique`
    # With an empty threshold buffer the kernel stops right at the event,
    # before the slip, which exposes the theta it found.
    st = PairState(u=u0, theta=theta0, mu=mu)
    assert st.run([theta0, theta_c + 0.05 * s], mu_buf=[]) == kernels.NEED_MU
    assert st.st["theta"] == theta_c
    assert st.n == 0
    # Resuming from that clean point completes the slip.
    assert st.run([theta0, theta_c + 0.05 * s], mu_buf=[0.6]) == kernels.DONE
    assert st.n == 1


@pytest.mark.parametrize("s", [1.0, -1.0], ids=["dilating", "contracting"])
def test_theta_c_is_the_exact_threshold(s):
    u0 = 0.1
    theta_c = u0 + min(WEAK1) * s
    # Reaching theta_c exactly triggers the rearrangement (paper: theta_c <= theta(t_q+1)) ...
    st = PairState(u=u0, theta=u0, mu=WEAK1)
    st.run([u0, theta_c], mu_buf=[0.6])
    assert st.n == 1
    # ... one ulp short of it does not.
    st = PairState(u=u0, theta=u0, mu=WEAK1)
    st.run([u0, math.nextafter(theta_c, u0)], mu_buf=[0.6])
    assert st.n == 0
    assert st.st["u"] == u0


def test_no_rearrangement_while_theta_is_constant():
    # s = 0: no event, even for a spring loaded just below the threshold.
    st = PairState(u=0.0, theta=0.579, mu=WEAK1)
    assert st.run([0.579, 0.579, 0.579], mu_buf=[0.6]) == kernels.DONE
    assert st.n == 0


def test_avalanche_slips_the_most_overloaded_until_stable():
    # mu_min = 1.9 > 3 mu_d = 1.5: after the first slip |F| = mu_min - 2 mu_d
    # = 0.9 exceeds the fresh threshold 0.55, so the same slider slips again
    # with |F| (not its threshold) in eq. `displacement`: F -> F - 2(|F| - mu_d).
    st = PairState(u=0.0, theta=0.0, mu=(1.9, 2.5))
    st.run([0.0, 1.95], mu_buf=[0.55, 0.7], mu_d=MU_D)
    assert st.n == 2
    assert st.st["n_events"] == 1
    F = 1.9 - 2 * (1.9 - MU_D)  # = -0.9 after the driving slip
    F = F - 2 * (abs(F) - MU_D) * np.sign(F)  # = 0.1 after the avalanche slip
    # theta ended at 1.95 (past 1.9): F grew by 0.05 after the avalanche.
    assert 1.95 - st.st["u"] == pytest.approx(F + 0.05, abs=1e-12)
    assert st.mu.tolist() == [0.7, 2.5]


# --------------------------------------------------------------------------
# The same through a Realization driven by a registered driver
# --------------------------------------------------------------------------


@pytest.mark.parametrize("s", [1.0, -1.0], ids=["dilating", "contracting"])
@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_realization_single_slip(fixed_driver, s, seed):
    ntilde = 1e-7
    # std = 1e-4: mu_min lies within 0.6 +- 0.0006 and the second theta_c
    # near (2 * 0.1 + 0.6) Ntilde, so theta: 0 -> 0.7 Ntilde gives exactly one slip.
    cfg = make_config(steps=1, record="all", observables=["n", "mu_max", "x_G"],
                      driver=fixed_driver([0.0, 0.7 * ntilde * s]),
                      **{"friction.static.std": 1e-4})
    real = realization_of(cfg, seed)
    mu0 = real.thresholds
    i = int(np.argmin(mu0)) + 1  # the paper's label of the weakest slider
    # The documented stream order: 2 initial draws, then batches of scene.batch.
    rngs = realization_streams(np.random.SeedSequence(seed))
    dist = real.scene.distribution
    np.testing.assert_array_equal(dist.sample(rngs["thresholds"], 2), mu0)
    first_redraw = dist.sample(rngs["thresholds"], real.scene.batch)[0]

    real.advance()
    res = real.result()
    assert res["n"].tolist() == [0, 1]
    mu_min = mu0.min()
    assert real.x_G == pytest.approx((-1) ** i * (mu_min - MU_D) * ntilde * s, rel=1e-12)
    assert res["x_G"][-1] == real.x_G
    assert real.state["u"][0] * ntilde == pytest.approx(2 * (mu_min - MU_D) * ntilde * s, rel=1e-12)
    after = real.thresholds
    assert after[2 - i] == mu0[2 - i]  # the stronger one is untouched
    assert after[i - 1] == first_redraw
    # The spring force is the one left by the slip, 2 mu_d - mu_min, plus the
    # remaining drive 0.7 - mu_min (in units of N).
    F2 = real.forces()[1]
    assert F2 == pytest.approx(s * ((2 * MU_D - mu_min) + (0.7 - mu_min)), abs=1e-9)


# --------------------------------------------------------------------------
# The virtual tilt test
# --------------------------------------------------------------------------


def tilt_reference(F, mu1, mu2, mu_d, tmu, tu):
    """docs/model.md section 1, "The virtual tilt test", steps 1-3, written from the text.

    Returns (f, draws of thresholds used, uniforms used); raises IndexError
    when the buffers run out.
    """
    j = k = 0
    for _ in range(100_000):
        # Step 1.
        f1, f2 = mu1 + F, mu2 - F
        i, f = (1, f1) if f1 <= f2 else (2, f2)
        # Step 2: eq. `stab`.
        if f >= mu_d + 0.5 * (-1) ** i * (mu1 - mu2):
            if f > mu_d:
                return f, j, k
            mu1, mu2 = tmu[j], tmu[j + 1]
            j += 2
            lo, hi = f - mu1, mu2 - f
            F = lo + (hi - lo) * tu[k]
            k += 1
        else:
            # Step 3.
            mu_i = mu1 if i == 1 else mu2
            F = F - 2 * (-1) ** i * (mu_i - mu_d)
            if i == 1:
                mu1 = tmu[j]
            else:
                mu2 = tmu[j]
            j += 1
    raise AssertionError("reference tilt test did not end")


def run_tilt(F, mu1, mu2, mu_d, tmu, tu):
    st = kernels.new_state()[0]
    f = kernels.tilt_test_pair(st, kernels.Draws(np.empty(0), np.asarray(tmu, float), np.asarray(tu, float)),
                               F, mu1, mu2, mu_d, 2.0)
    return f, int(st["tilt_mu_pos"]), int(st["tilt_u_pos"])


def test_tilt_immediate_sliding():
    # f1 = 0.6 < f2 = 0.7: slider 1 first; eq. `stab`: 0.6 >= 0.5 + 0.05 and 0.6 > mu_d.
    assert run_tilt(0.0, 0.6, 0.7, 0.5, [], []) == (0.6, 0, 0)


def test_tilt_one_rearrangement_then_sliding():
    # f1 = 0.6 < f2 = 0.9 but 0.6 < 0.5 + 0.15: slider 1 rearranges alone,
    # F -> 0 + 2 (0.6 - 0.5) = 0.2 and mu_s,1 -> 0.7. Then f1 = 0.9, f2 = 0.7:
    # slider 2 at f = 0.7 >= 0.5 + 0.5 (0.7 - 0.9) = 0.4 and > mu_d: sliding.
    f, used_mu, used_u = run_tilt(0.0, 0.6, 0.9, 0.5, [0.7, 9.9], [])
    assert f == pytest.approx(0.7, abs=1e-15)
    assert (used_mu, used_u) == (1, 0)


def test_tilt_creep_then_sliding():
    # mu = (0.8, 0.6), F = -0.35: f1 = 0.45 < f2 = 0.95, eq. `stab` holds
    # (0.45 >= 0.5 - 0.1) but f <= mu_d: creep. New thresholds (0.7, 0.65),
    # F uniform in [0.45 - 0.7, 0.65 - 0.45] = [-0.25, 0.2] at 0.25 -> -0.1375.
    # Then f1 = 0.5625 < f2 = 0.7875 and 0.5625 >= 0.5 - 0.025 > mu_d: sliding.
    f, used_mu, used_u = run_tilt(-0.35, 0.8, 0.6, 0.5, [0.7, 0.65, 9.9], [0.25, 0.9])
    assert f == pytest.approx(0.5625, abs=1e-15)
    assert (used_mu, used_u) == (2, 1)


def test_tilt_slider2_rearranges():
    # Mirror of the single-rearrangement case: F = +0.0 with mu = (0.9, 0.6),
    # slider 2 first (f2 = 0.6), 0.6 < 0.5 + 0.5 (0.9 - 0.6): it rearranges,
    # F -> 0 - 2 (0.6 - 0.5) = -0.2, mu_s,2 -> 0.7; then f1 = 0.7 < f2 = 0.9,
    # 0.7 >= 0.5 - 0.1: sliding at 0.7.
    f, used_mu, _ = run_tilt(0.0, 0.9, 0.6, 0.5, [0.7], [])
    assert f == pytest.approx(0.7, abs=1e-15)
    assert used_mu == 1


def test_tilt_out_of_draws_rolls_back():
    # Needs one threshold draw and none is there: -1, read positions untouched.
    st = kernels.new_state()[0]
    st["tilt_mu_pos"] = 3
    st["tilt_u_pos"] = 2
    draws = kernels.Draws(np.empty(0), np.full(3, 0.7), np.full(2, 0.5))
    f = kernels.tilt_test_pair(st, draws, 0.0, 0.6, 0.9, 0.5, 2.0)
    assert f == -1.0
    assert (st["tilt_mu_pos"], st["tilt_u_pos"]) == (3, 2)


def test_tilt_iteration_cap():
    # Thresholds exactly at mu_d and F redrawn at the centre give f = mu_d
    # forever (creep without end): the kernel gives up with -2.
    m = kernels.TILT_MAX_ITER
    draws = kernels.Draws(np.empty(0), np.full(2 * m + 2, 0.5), np.full(m + 1, 0.5))
    f = kernels.tilt_test_pair(kernels.new_state()[0], draws, 0.0, 0.5, 0.5, 0.5, 2.0)
    assert f == -2.0


def test_tilt_matches_reference_on_random_inputs():
    # 3000 random stable states (|F| <= mu_min) with widely spread thresholds
    # so that all three branches occur; seed 2024.
    rng = np.random.default_rng(2024)
    branches = {"creep": 0, "single": 0, "immediate": 0}
    for _ in range(3000):
        mu_d = rng.uniform(0.1, 0.6)
        dist = TruncatedBelow(Gaussian(mu_d + rng.uniform(0.02, 0.4), rng.uniform(0.01, 0.3)), mu_d, "g")
        mu1, mu2 = dist.sample(rng, 2)
        F = rng.uniform(-1, 1) * min(mu1, mu2)
        tmu = dist.sample(rng, 400)
        tu = rng.random(200)
        ref = tilt_reference(F, mu1, mu2, mu_d, tmu, tu)
        got = run_tilt(F, mu1, mu2, mu_d, tmu, tu)
        assert got[0] == pytest.approx(ref[0], rel=1e-12, abs=1e-12), (F, mu1, mu2, mu_d)
        assert got[1:] == ref[1:]
        branches["creep" if ref[2] else ("single" if ref[1] else "immediate")] += 1
    # Each branch must have been exercised for the comparison to mean anything.
    assert min(branches.values()) >= 50, branches


# --------------------------------------------------------------------------
# pair kernel vs csr kernel on the two-slider scene
# --------------------------------------------------------------------------

AGREEMENT_CASES = {
    "reference": {},
    "avalanches": {"friction.mu_d": 0.1, "friction.static.mean": 0.6, "friction.static.std": 0.2},
    "record-all": {"record": "all", "steps": 200},
}


@pytest.mark.parametrize("tilt", [False, True], ids=["no-mu_eff", "mu_eff"])
@pytest.mark.parametrize("case", list(AGREEMENT_CASES), ids=list(AGREEMENT_CASES))
def test_pair_and_csr_kernels_agree_to_the_bit(case, tilt):
    obs = ["n", "mu_max", "x_G"] + (["mu_eff"] if tilt else [])
    # batch = 64: many buffer refills, so that the resumption paths are exercised too.
    changes = {"steps": 400, "observables": obs, "solver.batch": 64, **AGREEMENT_CASES[case]}
    pair = scene_of(make_config(**changes, **{"solver.kernel": "pair"}))
    csr = scene_of(make_config(**changes, **{"solver.kernel": "csr"}))
    assert (pair.kernel, csr.kernel) == ("pair", "csr")
    avalanche_slips = 0
    for seed in (11, 12, 13):
        a = simulate(pair, np.random.SeedSequence(seed))
        b = simulate(csr, np.random.SeedSequence(seed))
        for key in ("n", "mu_max", "x_G", "n_records", "f_sum", "f_count", "n_events"):
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)
        assert a["n"][-1] > 1000
        if tilt:
            assert a["f_count"].sum() > a["n"][-1]  # the tilt test did run
        avalanche_slips += int(a["n"][-1] - a["n_events"])
    # The avalanche case must contain avalanches; the others cannot (mu_min < 3 mu_d).
    assert (avalanche_slips > 0) == (case == "avalanches")


@pytest.mark.parametrize("kernel", ["pair", "csr"])
@pytest.mark.parametrize("case", ["reference", "avalanches"])
def test_one_tilt_test_per_rearrangement(kernel, case):
    # docs/model.md: mu_eff pools one tilt test per rearrangement (plus one on the
    # initial state, bin t = 0). batch = 16 forces a refill every 16 slips.
    changes = {"steps": 100, "observables": ["n", "mu_eff"], "solver.batch": 16,
               "solver.kernel": kernel, **AGREEMENT_CASES[case]}
    res = simulate(scene_of(make_config(**changes)), np.random.SeedSequence(3))
    assert res["f_count"].sum() == res["n"][-1] + 1


@pytest.mark.parametrize("kernel", ["pair", "csr"])
def test_avalanche_limit_is_reported(kernel):
    # solver.max_avalanche = 1 allows one slip after the driving one; with
    # mu_min > 3 mu_d common (mu_d = 0.1) a longer avalanche comes soon (seed 1).
    cfg = make_config(steps=200, realizations=1, observables=["n"],
                      **{**AGREEMENT_CASES["avalanches"], "solver.max_avalanche": 1, "solver.kernel": kernel})
    with pytest.raises(AvalancheError, match=r"did not end after 1 slips \(solver\.max_avalanche\).* during step "
                                             r"\d+: node [01] is unstable"):
        slidernet.run(cfg)


# --------------------------------------------------------------------------
# The paper's algorithm (section III.A), in plain Python, against the kernel
# --------------------------------------------------------------------------


def paper_algorithm(thetas, mu_init, next_batch, mu_d):
    """Section III.A of the paper, fed with the kernel's thetas (units of Ntilde).

    ``mu_init`` are the two initial thresholds; ``next_batch()`` gives the
    following draws in batches (the solver's documented order). Returns n,
    mu_max and x_G (units of Ntilde l0) after every step.
    """
    mu = [float(mu_init[0]), float(mu_init[1])]
    draws, pos = next_batch(), 0
    u = thetas[0]  # the spring at rest at theta(0)
    x_G = 0.0
    n = 0
    out_n, out_max, out_x = [0], [max(mu)], [0.0]
    for q in range(len(thetas) - 1):
        a, b = thetas[q], thetas[q + 1]
        s = 1.0 if b > a else (-1.0 if b < a else 0.0)
        while s != 0.0:
            i = 0 if mu[0] <= mu[1] else 1  # index of the weakest (0: slider 1)
            mu_min = mu[i]
            theta_c = u + mu_min * s  # eq. `critique`
            # Keep rearranging while theta_c lies within [theta(t_q), theta(t_q+1)].
            if not s * (b - theta_c) >= 0.0:
                break
            u = u + 2.0 * (mu_min - mu_d) * s  # eq. `displacement`
            x_G += (-1) ** (i + 1) * (mu_min - mu_d) * s  # eq. `displacmt-G`
            if pos == len(draws):
                draws, pos = next_batch(), 0
            mu[i] = draws[pos]  # only the weakest is redrawn
            pos += 1
            n += 1
        out_n.append(n)
        out_max.append(max(mu))
        out_x.append(x_G)
    return np.array(out_n), np.array(out_max), np.array(out_x)


@pytest.mark.parametrize("seed", [5, 6])
def test_kernel_matches_the_papers_algorithm(seed):
    # Reference parameters (no avalanche possible); batch = 64 so that the
    # threshold buffer is refilled many times during the 500 steps.
    cfg = make_config(steps=500, record="all", observables=["n", "mu_max", "x_G"],
                      **{"solver.batch": 64})
    scene = scene_of(cfg)
    got = simulate(scene, np.random.SeedSequence(seed))
    # The same draws: driver stream -> thetas; thresholds stream -> 2 initial
    # values, then batches of scene.batch from the truncated distribution.
    rngs = realization_streams(np.random.SeedSequence(seed))
    thetas = scene.driver.thetas(rngs["driver"], scene.steps) / scene.network.Ntilde
    dist, rng = scene.distribution, rngs["thresholds"]
    init = dist.sample(rng, 2)
    ref_n, ref_max, ref_x = paper_algorithm(thetas, init, lambda: dist.sample(rng, scene.batch), MU_D)
    assert ref_n[-1] > 20_000
    np.testing.assert_array_equal(got["n"], ref_n)
    np.testing.assert_array_equal(got["mu_max"], ref_max)
    # Same operations in the same order: x_G agrees to rounding (in fact to the bit).
    np.testing.assert_allclose(got["x_G"], ref_x * scene.network.Ntilde, rtol=1e-12, atol=1e-18)


def test_realization_draws_follow_the_documented_streams():
    # The reference loop above relies on this order: thresholds stream gives
    # the 2 initial values and then the first batch.
    cfg = make_config(steps=10, **{"solver.batch": 32})
    real = realization_of(cfg, 9)
    assert isinstance(real, Realization)
    rngs = realization_streams(np.random.SeedSequence(9))
    dist = real.scene.distribution
    np.testing.assert_array_equal(real.thetas,
                                  real.scene.driver.thetas(rngs["driver"], 10) / real.scene.network.Ntilde)
    np.testing.assert_array_equal(real.mu, dist.sample(rngs["thresholds"], 2))
    np.testing.assert_array_equal(real.buffers.mu, dist.sample(rngs["thresholds"], 32))


@pytest.mark.parametrize("index", [3, (3,), (1, 3)], ids=["row", "tuple-1d", "tuple-2d"])
def test_prefetch_compiles_and_changes_no_value(index):
    # A hint only: the values read after it are those before it, and an index past the end is harmless.
    from numba import njit

    from slidernet.kernels.memory import prefetch

    arr = np.arange(12.0).reshape(2, 6) if len(np.atleast_1d(index)) == 2 else np.arange(6.0)

    @njit
    def touch(a, i):
        prefetch(a, i)
        return a.sum()

    assert touch(arr, index) == arr.sum()
    if isinstance(index, int):
        assert touch(arr, 10_000) == arr.sum()
    np.testing.assert_array_equal(arr, np.arange(arr.size, dtype=float).reshape(arr.shape))
