"""Property tests (hypothesis): invariants that hold for every seed and parameter set."""

from __future__ import annotations

import numpy as np
import xarray as xr
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import slidernet
from slidernet import kernels
from slidernet.solver import Realization, simulate
from tests.conftest import make_config, realization_of, scene_of

# Property tests exercise the kernels many times: no deadline (the first
# example may include numba's cache loading), a few dozen examples each.
FAST = settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
# For the test that walks every slip in Python.
SLOW = settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])

seeds = st.integers(min_value=0, max_value=2**32 - 1)


@st.composite
def physics(draw, min_ratio: float = 0.5, max_ratio: float = 30.0, min_gap: float = 0.02):
    """Random friction and drive: mu_d, gaussian p(mu_s) with mean > mu_d, sigma_theta/Ntilde."""
    mu_d = draw(st.floats(0.05, 0.6))
    mean = mu_d + draw(st.floats(min_gap, 0.5))
    std = draw(st.floats(0.005, 0.3))
    ratio = draw(st.floats(min_ratio, max_ratio))
    ntilde = draw(st.sampled_from([1e-9, 1e-7, 1e-4]))
    return {
        "network.Ntilde": ntilde,
        "friction.mu_d": mu_d,
        "friction.static.mean": mean,
        "friction.static.std": std,
        "driver.sigma_theta": ratio * ntilde,
    }


networks = st.one_of(
    st.just({"kind": "two_slider"}),
    st.integers(2, 10).map(lambda n: {"kind": "chain", "n": n}),
)


def config(phys: dict, network: dict | None = None, **changes) -> dict:
    """The reference config with the drawn physics, a network and other changes."""
    cfg = make_config(**{"observables": ["n", "mu_max", "x_G"], **phys, **changes})
    if network is not None:
        cfg["network"] = {**network, "Ntilde": phys["network.Ntilde"]}
    return cfg


@FAST
@given(seed=seeds, phys=physics())
def test_mu_max_never_decreases_with_two_sliders(seed, phys):
    # Only the weakest threshold is ever redrawn (docs/model.md section 4).
    res = simulate(scene_of(config(phys, steps=60, record="all")), np.random.SeedSequence(seed))
    assert (np.diff(res["mu_max"]) >= 0).all()
    assert (np.diff(res["n_records"]) >= 0).all()


@FAST
@given(seed=seeds, phys=physics(), network=networks)
def test_every_node_is_stable_after_each_step(seed, phys, network):
    real = realization_of(config(phys, network, steps=15), seed)
    N = real.scene.network.normal_load
    for q in range(1, 16):
        real.advance(q)
        F = real.forces()
        limit = real.thresholds * N
        # 1e-12 relative: the threshold crossing and the final force are computed
        # by different float operations, so an exact tie may round either way.
        assert (np.abs(F) <= limit * (1 + 1e-12)).all(), (q, F, limit)
    assert real.step == 15


@FAST
@given(seed=seeds, phys=physics(min_ratio=2.0), n=st.integers(2, 10))
def test_spring_forces_sum_to_zero(seed, phys, n):
    # Newton's third law: every spring pulls its two ends oppositely, so the
    # network's forces sum to zero. The csr kernel updates forces incrementally;
    # rounding drift must stay ~1e-9 of mu. (A 2-chain runs the csr kernel here.)
    cfg = config(phys, {"kind": "chain", "n": n}, steps=15, **{"solver.kernel": "csr"})
    real = realization_of(cfg, seed)
    mu = phys["friction.static.mean"]
    for q in range(1, 16):
        real.advance(q)
        assert abs(real.forces().sum()) <= 1e-9 * mu
    assume(real.n > 0)  # without slips the check is empty: let hypothesis look elsewhere


def slip_by_slip(real: Realization):
    """Advance a two-slider realization one slip at a time.

    The kernel stops cleanly (NEED_MU) whenever its threshold buffer is empty,
    so feeding it one draw at a time exposes every single slip. Draws come in
    the order Realization.advance would use (the first buffer, then batches),
    so the end state equals the one of an uninterrupted run. Yields, after
    each slip, (thresholds before, thresholds after, u before, u after,
    x_G before, x_G after, new avalanche?) in internal units.
    """
    queue = list(real.buffers.mu)
    st = real.state[0]
    while True:
        if not queue:
            queue = list(real.draws["thresholds"].take(real.scene.batch))
        real.streams.buffers = real.buffers._replace(mu=np.array(queue[:1]))  # the buffers' owner
        st["mu_pos"] = 0
        before = (real.thresholds, float(st["u"]), float(st["x_G"]), int(st["n_events"]))
        status = real.backend.run(real, real.thetas)
        assert status == kernels.DONE or st["mu_pos"] == 1  # else no progress
        if st["mu_pos"] == 1:
            queue.pop(0)
            yield (before[0], real.thresholds, before[1], float(st["u"]), before[2], float(st["x_G"]),
                   int(st["n_events"]) > before[3])
        if status == kernels.DONE:
            return
        assert status == kernels.NEED_MU


@SLOW
@given(seed=seeds, phys=physics(max_ratio=10.0))
def test_x_G_moves_by_half_the_slip(seed, phys):
    # Python sees every slip here: sigma_theta/Ntilde <= 10 keeps that cheap.
    cfg = config(phys, steps=30)
    real = realization_of(cfg, seed)
    d_mu = phys["friction.mu_d"]
    half_signed = 0.0  # (sum of slider-2 slips - sum of slider-1 slips) / 2, on u
    n = changes = 0
    for mu0, mu1, u0, u1, x0, x1, driven in slip_by_slip(real):
        n += 1
        moved = np.flatnonzero(mu0 != mu1)
        assert moved.size == 1  # exactly one slider slips and is redrawn
        i = int(moved[0])
        assert mu0[i] <= mu0[1 - i]  # the weakest one
        du = u1 - u0
        tol = 1e-12 * (1 + abs(u0))  # u1 - u0 loses the digits of |u|
        if driven:
            # A driving event: eq. `displacement` with |F| = mu_min.
            np.testing.assert_allclose(abs(du), 2 * (mu0[i] - d_mu), rtol=1e-12, atol=tol)
        # eq. `displacmt-G`: slider 2 moves +du, slider 1 moves -du; G by half of it.
        sign = 1.0 if i == 1 else -1.0
        np.testing.assert_allclose(x1 - x0, sign * du / 2, rtol=1e-9, atol=tol)
        half_signed += sign * du / 2
        changes += int(np.argmax(mu1) != np.argmax(mu0))
    assert real.n == n
    np.testing.assert_allclose(real.state["x_G"][0], half_signed, rtol=1e-9, atol=1e-9)
    # Interrupting the kernel after every slip changes nothing: same bits as one run.
    ref = simulate(real.scene, np.random.SeedSequence(seed))
    assert ref["n"][-1] == n
    assert ref["x_G"][-1] == real.result()["x_G"][-1]
    assert ref["mu_max"][-1] == real.state["mu_max"][0]
    # Every change of the strongest slider is a record among the draws.
    assert ref["n_records"][-1] == changes


@FAST
@given(seed=seeds, phys=physics(min_ratio=1.5, max_ratio=3.0, min_gap=0.3))
def test_single_slip_steps_move_x_G_by_mu_minus_mu_d(seed, phys):
    # sigma_theta/Ntilde in [1.5, 3] and mu_s - mu_d >= 0.3: about 0.5 to 5
    # rearrangements per step (eq. `slope`), so many steps hold exactly one.
    real = realization_of(config(phys, steps=60), seed)
    ntilde = phys["network.Ntilde"]
    mu_d = phys["friction.mu_d"]
    thetas = real.thetas
    single = 0
    for q in range(1, 61):
        mu_before, n_before, x_before = real.thresholds, real.n, real.x_G
        events_before = int(real.state["n_events"][0])
        real.advance(q)
        if real.n - n_before == 1 and real.state["n_events"][0] - events_before == 1:
            i = int(np.argmin(mu_before))  # 0: slider 1
            s = np.sign(thetas[q] - thetas[q - 1])
            expected = (-1) ** (i + 1) * s * (mu_before[i] - mu_d) * ntilde
            # x_G is a running sum: its difference loses the digits of |x_G|.
            np.testing.assert_allclose(real.x_G - x_before, expected, rtol=1e-9,
                                       atol=1e-12 * (ntilde + abs(x_before)))
            single += 1
    assert single > 0


@settings(max_examples=20, deadline=None)
@given(seed=seeds, phys=physics(max_ratio=10.0))
def test_same_seed_same_bits_other_seed_differs(seed, phys):
    cfg = config(phys, steps=30, realizations=3, seed=seed, observables=["n", "mu_max", "x_G", "mu_eff"])
    a = slidernet.run(cfg)
    b = slidernet.run(cfg)
    xr.testing.assert_identical(a, b)
    other = slidernet.run({**cfg, "seed": (seed + 1) % 2**32})
    assert not np.array_equal(a["mu_max"].values, other["mu_max"].values)


@FAST
@given(seed=seeds, phys=physics(max_ratio=10.0), network=networks)
def test_mu_eff_does_not_change_the_horizontal_evolution(seed, phys, network):
    # The tilt test draws from its own stream and works on a copy.
    if network["kind"] == "chain" and network["n"] > 2:
        network = {"kind": "chain", "n": 2}  # mu_eff is defined for 2 sliders only
    plain = scene_of(config(phys, network, steps=40, **{"solver.batch": 16}))
    tilt = scene_of(config(phys, network, steps=40, observables=["n", "mu_max", "x_G", "mu_eff"],
                           **{"solver.batch": 16}))
    a = simulate(plain, np.random.SeedSequence(seed))
    b = simulate(tilt, np.random.SeedSequence(seed))
    for key in ("n", "mu_max", "x_G", "n_records", "n_events"):
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    assert b["f_count"].sum() > 0 and a["f_count"].sum() == 0


@FAST
@given(seed=seeds, ratio=st.floats(0.5, 30.0), network=networks)
def test_buffer_refills_do_not_change_the_horizontal_evolution(seed, ratio, network):
    # The kernel returns at clean points when its threshold buffer is empty
    # (ARCHITECTURE.md invariant 7), and the thresholds stream is the same
    # draws whatever solver.batch is, so batch = 16 (a refill every 16 slips)
    # must give the bits of the default batch. Here without rejections by the
    # truncation (mu_s = 0.6 +- 0.01, mu_d = 0.5: 10 sigma); every law under
    # heavy truncation is in tests/test_batch_independence.py.
    phys = {"network.Ntilde": 1e-7, "driver.sigma_theta": ratio * 1e-7}
    cfg = config(phys, network, steps=20)
    small = simulate(scene_of({**cfg, "solver": {"batch": 16}}), np.random.SeedSequence(seed))
    large = simulate(scene_of(cfg), np.random.SeedSequence(seed))
    for key in ("n", "mu_max", "x_G", "n_records", "n_events"):
        np.testing.assert_array_equal(small[key], large[key], err_msg=key)
