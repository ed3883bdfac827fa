"""Slide-hold-slide: the network pulled through springs from a stage, on a copy of the state (``mu_shs``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import slidernet
from slidernet import kernels
from slidernet.config import load_config
from slidernet.errors import ConfigError, TiltTestError
from slidernet.kernels.tilt_net import L_F, L_PEAK, L_SHIFT, L_TRAVEL, N_LOADS, N_POS, N_SLIPS, P_MU
from slidernet.model.network import Network, chain
from slidernet.solver import Realization, Scene
from slidernet.solver.scene import stiffness_matrix
from slidernet.solver.streams import realization_streams

FRICTION = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}


def config(network: dict[str, Any], *, observables: tuple[str, ...] = ("n", "mu_max", "x_G", "mu_shs"),
           shs: dict[str, Any] | None = None, **changes: Any) -> dict[str, Any]:
    cfg: dict[str, Any] = {"seed": 3, "realizations": 1, "steps": 12, "record": "all",
                           "observables": list(observables), "network": {"Ntilde": 1e-7, **network},
                           "friction": dict(FRICTION), "driver": {"name": "gaussian_steps", "sigma_theta": 3e-7},
                           **changes}
    if shs is not None:
        cfg["shs"] = shs
    return cfg


def scene_of(network: dict[str, Any], **kw: Any) -> Scene:
    return Scene.from_config(load_config(config(network, **kw)))


def pull(scene: Scene, G: np.ndarray, mu: np.ndarray, redraws: list[float] | np.ndarray, *, overshoot: float = 1.0,
         max_slips: int = 10**6) -> dict[str, Any]:
    """The compiled pull on the scene's pull springs, from forces G (N, 2) and thresholds mu; all it leaves."""
    o = scene.shs_operators()
    N = scene.network.n_nodes
    heaps, epoch, count = kernels.Heaps.empty(2, N), np.zeros(N, np.int64), np.zeros(N, np.int64)
    pos, loads = np.zeros(N_POS, np.int64), np.zeros(N_LOADS)
    G, mu = np.array(G, float), np.array(mu, float)
    settings_ = kernels.Settings(mu_d=0.5, max_slips=max_slips, recompute_every=0, slip_factor=1.0 + overshoot)
    end = o.test(G, mu, o.f_ext, o.f_bar, o.net, settings_, np.asarray(redraws, float), pos, heaps, epoch, count,
                 loads, o.pull)
    return {"end": end, "peak": loads[L_PEAK], "travel": loads[L_TRAVEL], "f": loads[L_F],
            "end_load": loads[L_F] - o.pull * loads[L_SHIFT] + o.f_bar, "drawn": int(pos[P_MU]),
            "slips": int(pos[N_SLIPS]), "epoch": epoch, "count": count, "G": G, "pull": o.pull, "f_bar": o.f_bar}


def tilt(scene: Scene, G: np.ndarray, mu: np.ndarray, redraws: list[float], overshoot: float = 1.0) -> float:
    """The network tilt test on the same state (its compiled kernel)."""
    o = scene.tilt_operators()
    N = scene.network.n_nodes
    settings_ = kernels.Settings(mu_d=0.5, max_slips=10**6, recompute_every=0, slip_factor=1.0 + overshoot)
    return o.test(np.array(G, float), np.array(mu, float), o.f_ext, o.f_bar, o.net, settings_, o.pair_rule,
                  np.asarray(redraws, float), np.full(4, 0.5), np.zeros(N_POS, np.int64), 10**5,
                  kernels.Heaps.empty(2, N), np.zeros(N, np.int64), np.zeros(N, np.int64), np.zeros(N_LOADS))


PAIR = {"kind": "chain", "n": 2}


# --- exact hand cases ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("overshoot", [1.0, 0.5, 0.0], ids=["e1", "e0.5", "e0"])
@pytest.mark.parametrize("stiffness", [0.25, 1.0, 4.0], ids=["soft", "unit", "stiff"])
def test_two_sliders_of_equal_thresholds_and_no_force_give_that_threshold_in_both_tests(stiffness, overshoot):
    # Springs at rest, mu_s = 0.625 on both: both reach the threshold at f = 0.625 (a tie: slider 0 slips first).
    # Tilt test: slider 0 slips by (1 + e)(0.625 - 0.5) / k and pushes slider 1 past its threshold: both in
    # motion at f > mu_d, the sample is 0.625. Pull: slider 0 slips by (1 + e)(0.125) / (k (1 + gamma)), which
    # lowers the stage force and pushes slider 1 by (1 + e)(0.125) / (1 + gamma) > 0 past its threshold: it
    # slips at the same stage position and renews the last contact. The peak is the stage force at the first
    # slip, f = 0.625, exactly, whatever the redraw (0.9: slider 0 stays stable).
    scene = scene_of(PAIR, shs={"stiffness": stiffness})
    G, mu = np.zeros((2, 2)), [0.625, 0.625]
    got = pull(scene, G, mu, [0.9, 0.9], overshoot=overshoot)
    assert got["peak"] == 0.625 == tilt(scene, G, mu, [0.9, 0.9], overshoot)
    assert got["travel"] == 0.625 / (stiffness * 1.0)  # X = f / (gamma <k>), <k> = 1
    assert (got["drawn"], got["slips"]) == (1, 2)  # the second slip renews the last contact: no draw


def test_a_pull_peaks_where_the_stronger_slider_slips_and_reads_more_than_the_tilt_test():
    # Dyadic numbers, exact in float64. mu = (0.5625, 0.75), mu_d = 0.5, k = gamma = 1, e = 1, redraw 0.875.
    # Pull (K_ii + pull spring = 2 along x): slider 0 slips at f = 0.5625 by 2 (0.0625) / 2 = 0.0625,
    # U = 0.0625 / 2 = 0.03125; the stage force drops to 0.53125; slider 1's force is 0.0625 + f, below 0.75
    # until f = 0.6875, where the stage force is 0.6875 - 0.03125 = 0.65625: the peak (slider 0, redrawn
    # 0.875 at a force of f - 0.125, would slip only at f = 1). Slider 1 then slips (by 0.25) and the pull ends:
    # U = 0.15625, the stage's load 0.6875 - 0.15625 = 0.53125.
    # Tilt test (K_ii = 1): slider 0 slips at 0.5625 by 0.125, slider 1 at 0.125 + f stays stable; at
    # f = 0.625 slider 1 slips by 0.5 and pushes slider 0 to 1.0 > 0.875: both in motion, the sample 0.625.
    scene = scene_of(PAIR)
    G, mu = np.zeros((2, 2)), [0.5625, 0.75]
    got = pull(scene, G, mu, [0.875])
    assert (got["peak"], got["travel"], got["f"], got["end_load"]) == (0.65625, 0.6875, 0.6875, 0.53125)
    assert (got["drawn"], got["slips"]) == (1, 2)
    assert tilt(scene, G, mu, [0.875]) == 0.625


def test_a_pull_that_peaks_at_its_first_slip_reads_the_tilt_test_s_first_slip():
    # The same sliders with mu = (0.5625, 0.625): slider 1 now slips at f = 0.625 - 0.0625 = 0.5625, the stage
    # force there is 0.5625 - 0.03125, below the first slip's 0.5625: the peak is the first onset.
    scene = scene_of(PAIR)
    got = pull(scene, np.zeros((2, 2)), [0.5625, 0.625], [0.875])
    assert got["peak"] == 0.5625 and got["travel"] == 0.5625


def test_a_stiff_pull_makes_the_sliders_independent():
    # gamma = 1e8: each node is held by its own pull spring, its slips move the network's springs by O(1/gamma).
    # A slip from mu_i drops the node's force by (1 + e)(mu_i - mu_d) and nothing else, so with every force at
    # 0 and unit loads the stage's load before the k-th slip (thresholds in increasing order) is
    # mu_(k) - (1 + e)/N sum_{j<k} (mu_(j) - mu_d). Thresholds 0.55, 0.6, 0.65, 0.7, 0.9, e = 1, N = 5:
    # 0.55; 0.6 - 0.4 (0.05) = 0.58; 0.65 - 0.4 (0.15) = 0.59; 0.7 - 0.4 (0.30) = 0.58; 0.9 - 0.4 (0.50) = 0.70.
    # The peak is at the last node's slip, 0.70 (redraws of 10: no node slips twice).
    scene = scene_of({"kind": "chain", "n": 5}, shs={"stiffness": 1e8})
    got = pull(scene, np.zeros((5, 2)), [0.55, 0.7, 0.6, 0.9, 0.65], np.full(10, 10.0))
    assert got["peak"] == pytest.approx(0.70, abs=1e-7)
    assert got["travel"] == pytest.approx(0.9 / 1e8, rel=1e-7)
    assert (got["drawn"], got["slips"]) == (4, 5)


@pytest.mark.parametrize("n", [3, 6])
def test_a_relaxed_chain_of_equal_thresholds_gives_that_threshold_in_both_tests(n):
    # As the tilt test's worked case (tests/test_creep_tilt.py): at f = 0.62 the first end slips along +x, and in
    # 1D a forward slip raises the force on its neighbours, so every node slips at that stage position; each
    # slip lowers the stage force: the peak is the first onset, 0.62, and so is mu_eff.
    r = Realization(scene_of({"kind": "chain", "n": n}, observables=("n", "mu_eff", "mu_shs")),
                    np.random.SeedSequence(2))
    np.testing.assert_array_equal(r.forces(), 0.0)
    r.mu[:] = 0.62
    assert r.shs_test()[0] == 0.62 == r.tilt_test()


# --- injected aging ([tilt] inject) on the pull -----------------------------------------------------------------


def _at_rest(network: dict[str, Any], observables: tuple[str, ...], **changes: Any) -> dict[str, Any]:
    """Every threshold (and redraw) 0.6, theta fixed at 0: no spring ever stretched, no slip in the hold."""
    return config(network, observables=observables, realizations=2, steps=100, record="log",
                  log_points_per_decade=2, friction={"mu_d": 0.5, "static": {"name": "constant", "value": 0.6}},
                  driver={"name": "constant", "theta0": 0.0}, **changes)


@pytest.mark.parametrize("stiffness", [0.25, 1.0, 4.0], ids=["soft", "unit", "stiff"])
@pytest.mark.parametrize("network", [{"kind": "two_slider"}, {"kind": "chain", "n": 2}, {"kind": "chain", "n": 5}],
                         ids=["pair-kernel", "chain-2", "chain-5"])
@pytest.mark.parametrize(("c", "t0"), [(0.01, 1.0), (0.3, 7.5)], ids=["c-0.01", "c-0.3-t0-7.5"])
def test_a_pull_of_raised_equal_thresholds_peaks_exactly_the_shift_higher_as_the_tilt_test(network, stiffness,
                                                                                          c, t0):
    # Equal thresholds on springs at rest: the pull peaks at its first slip, at the threshold itself (the hand
    # case above: the first slip pushes the next node past its threshold, and the stage force only drops
    # after it). Raised by s(t) = c ln(1 + t/t0), every threshold of the twin's copy is 0.6 + s, and its pull
    # peaks at 0.6 + s, to the bit; the redraws (0.6, young contacts) come after the peak. The tilt test's
    # twin reads the same, 0.6 + s: here the two estimators agree, with and without the injection.
    cfg = _at_rest(network, ("n", "mu_eff", "mu_shs"), mu_eff_at="records", shs={"stiffness": stiffness},
                   tilt={"inject": {"c": c, "t0": t0}})
    ds = slidernet.run(cfg)
    t = ds["t"].values
    assert t.tolist() == [0, 1, 3, 10, 32, 100] and int(ds["n"].max()) == 0
    raised = np.array([0.6 + c * math.log1p(float(time) / t0) for time in t])
    np.testing.assert_array_equal(ds["mu_shs"].values, np.full((2, t.size), 0.6))
    np.testing.assert_array_equal(ds["mu_shs_injected"].values, np.stack([raised, raised]))
    np.testing.assert_array_equal(ds["mu_shs_injected_mean"].values, raised)
    np.testing.assert_array_equal(ds["mu_shs_injected_sem"].values, np.zeros(t.size))
    np.testing.assert_array_equal(ds["mu_eff_injected"].values, raised)
    attrs = ds["mu_shs_injected"].attrs
    assert (attrs["inject_c"], attrs["inject_t0"], attrs["inject_select"]) == (c, t0, 1.0)
    assert "shs for the slide-hold-slide pull" in attrs["pairing"]
    assert ds["mu_shs_injected"].dims == ds["mu_shs"].dims == ("realization", "t")


def test_the_injection_applies_to_the_pull_alone_where_no_network_tilt_test_runs():
    # [tilt] inject with mu_shs and no mu_eff: the pull has its twin; no tilt test is made, none is recorded.
    cfg = _at_rest({"kind": "chain", "n": 3}, ("n", "mu_shs"), tilt={"inject": {"c": 0.02}})
    ds = slidernet.run(cfg)
    assert {name for name in ds.data_vars if "injected" in name} == {"mu_shs_injected", "mu_shs_injected_mean",
                                                                    "mu_shs_injected_sem"}
    raised = 0.6 + 0.02 * np.log1p(ds["t"].values.astype(float))
    np.testing.assert_allclose(ds["mu_shs_injected_mean"].values, raised, rtol=0, atol=1e-15)
    # The pair whose mu_eff is the appendix's test before every rearrangement: the pull's twin only.
    pair = slidernet.run(_at_rest({"kind": "two_slider"}, ("n", "mu_eff", "mu_shs"), tilt={"inject": {"c": 0.02}}))
    assert pair.attrs["kernel"] == "pair" and "mu_eff" in pair
    assert "mu_shs_injected" in pair and "mu_eff_injected" not in pair


def test_an_injection_with_neither_test_is_refused_naming_both():
    message = (r"'tilt\.inject' raises the thresholds of the copy that a test of static friction measures .* the "
               r"slide-hold-slide pull of 'mu_shs'\), and this run makes neither: \"mu_eff\" is not in "
               r"'observables'; add it, or add \"mu_shs\" to 'observables'")
    with pytest.raises(ConfigError, match=message):
        load_config(config({"kind": "chain", "n": 4}, observables=("n",), tilt={"inject": {"c": 0.01}}))


@pytest.mark.parametrize("select", [1.0, 0.5], ids=["select-1", "select-0.5"])
def test_the_pull_s_twin_reads_the_raised_copy_and_the_same_draws(select):
    # Run by hand: at every record the twin is the pull on tested_thresholds(k, True) from the shs stream's
    # position before the plain pull, and it leaves that position where it was.
    scene = scene_of({"kind": "irregular", "n": 12}, observables=("n", "mu_shs"), steps=20,
                     tilt={"inject": {"c": 0.03, "t0": 2.0, "select": select}})
    r = Realization(scene, np.random.SeedSequence(4))
    for k, t in enumerate(scene.out_steps):
        r._run_kernel(int(t), None)  # the state at t, before the record's tests (advance would make them)
        start = int(r.state["shs_mu_pos"][0])
        raised = r.tested_thresholds(k, True)
        shift = scene.inject.shift(float(t))
        assert np.count_nonzero(raised != r.mu) == (0 if shift == 0 else math.ceil(select * 12))
        G = np.zeros((12, 2))
        G[:, : scene.network.dim] = r.forces().reshape(12, -1)
        twin = pull(scene, G, raised, r.buffers.shs_mu[start:], max_slips=scene.max_avalanche)
        plain = pull(scene, G, r.mu, r.buffers.shs_mu[start:], max_slips=scene.max_avalanche)
        r.advance(int(t))
        assert r.out["mu_shs_injected"][k] == twin["peak"]
        assert r.out["mu_shs"][k] == plain["peak"]
        assert r.state["shs_mu_pos"][0] == start + plain["drawn"]
        assert twin["drawn"] > 0 and plain["drawn"] > 0


# --- the pull against its stated rule, by brute force --------------------------------------------------------


def reference_shs(net: Network, F: np.ndarray, mu: np.ndarray, mu_d: float, stiffness: float,
                  redraws: np.ndarray) -> dict[str, Any]:
    """Slide-hold-slide by brute force from its stated rule (straight slips): dense K, the displacements u of the
    pull kept, the stage force recomputed from them at every event; no heaps, no kernel.

    A stage at X is joined to node i by a spring gamma <k> N_i along x; the force on node i is
    F_i - sum_j K_ij u_j + gamma <k> N_i (X - u_i,x) x. X rises to the smallest value at which a node reaches
    its threshold; at fixed X the unstable nodes slip, largest overload first (ties to the lowest index), each
    by 2 (|F_i| - mu_d N_i) / k_eff along its force, k_eff = e^T (K_ii + gamma <k> N_i x x^T) e (|F_i| = mu_s N_i
    for the one that reaches it), and draws a new threshold; the pull ends at the slip after which every node
    has slipped, with no draw. The stage's load is gamma <k> (X - sum_i N_i u_i,x / sum N) + f_bar, its peak
    taken before every driving slip and after every slip.
    """
    N, d = net.n_nodes, net.dim
    K = np.zeros((N, N, 2, 2))
    K[:, :, :d, :d] = net.stiffness_matrix().toarray().reshape(N, d, N, d).transpose(0, 2, 1, 3)
    load = net.normal_load.astype(float)
    w = load / load.sum()
    f_bar = float(net.f_ext[:, 0].sum() / load.sum())
    pull_k = stiffness * float(np.mean(net.k))
    G0 = np.zeros((N, 2))
    G0[:, :d] = np.asarray(F, float).reshape(N, d)
    mu = np.array(mu, float)
    u = np.zeros((N, 2))
    X, used, peak, at, renewed = 0.0, 0, -math.inf, math.nan, set()

    def forces() -> np.ndarray:
        T = G0 - np.einsum("ijab,jb->ia", K, u)
        T[:, 0] += pull_k * load * (X - u[:, 0])
        return T

    def stage() -> float:
        return pull_k * (X - float(w @ u[:, 0])) + f_bar

    for _ in range(1_000_000):
        T = forces()
        lim = mu * load
        overload = np.hypot(T[:, 0], T[:, 1]) / lim
        driving = not (overload > 1.0).any()
        if driving:
            A = T.copy()
            A[:, 0] -= pull_k * load * X  # the forces at X = 0, u as it is
            critical = (-A[:, 0] + np.sqrt(np.maximum(lim**2 - A[:, 1] ** 2, 0.0))) / (pull_k * load)
            i = int(np.argmin(critical))
            X = max(X, float(critical[i]))
            if stage() > peak:
                peak, at = stage(), X
            T = forces()
        else:
            i = int(np.argmax(overload))
        e = T[i] / np.hypot(*T[i])
        K_ii = K[i, i] + np.diag([pull_k * load[i], 0.0])
        magnitude = lim[i] if driving else np.hypot(*T[i])
        u[i] += 2.0 * (magnitude - mu_d * load[i]) / (e @ K_ii @ e) * e
        renewed.add(i)
        if stage() > peak:
            peak, at = stage(), X
        if len(renewed) == N:
            return {"peak": peak, "travel": at, "drawn": used, "end_load": stage(), "X": X, "u": u,
                    "G": forces() - np.outer(pull_k * load * X, [1.0, 0.0])}
        mu[i] = redraws[used]
        used += 1
    raise AssertionError("the reference pull did not end")


REFERENCE_CASES = {
    "chain": ({"kind": "chain", "n": 7}, None, 2.0),
    # Uneven normal loads and an uphill load (f_bar = -0.1 / 1.2): the weights and f_bar of the stage's load.
    "chain-uphill": ({"kind": "chain", "n": 5},
                     chain(5, Ntilde=1e-7, normal_load=[1.0, 2.0, 0.5, 1.5, 1.0], f_ext=-0.1), 0.3),
    "triangular": ({"kind": "triangular", "shape": [4, 4]}, None, 1.0),
    "irregular": ({"kind": "irregular", "n": 24, "seed": 2}, None, 5.0),
}


@pytest.mark.parametrize("case", list(REFERENCE_CASES))
def test_every_pull_of_a_run_follows_the_stated_rule_and_keeps_its_books(case):
    # At every recorded time of a run (seed 3), the pull on the state there is the brute-force rule's on the
    # same forces, thresholds and shs draws: the same draws (one per slip but the last), the peak and the
    # stage's travel there, the stage's load at the end recomputed from the displacements, and the forces
    # the pull left on its copy (to 1e-9: sums in another order). The state itself is left as it was.
    network, built, stiffness = REFERENCE_CASES[case]
    scene = Scene.from_config(load_config(config(network, shs={"stiffness": stiffness})), network=built)
    r = Realization(scene, np.random.SeedSequence(3))
    Ntilde, slips = scene.network.Ntilde, 0
    for t in (0, 4, 12):
        r.advance(t)
        F, mu, u = r.forces().copy(), r.thresholds, r.displacements()
        start = int(r.state["shs_mu_pos"][0])
        ref = reference_shs(scene.network, F, mu, 0.5, stiffness, r.buffers.shs_mu[start:])
        G = np.zeros((mu.size, 2))
        G[:, : scene.network.dim] = F.reshape(mu.size, -1)
        got = pull(scene, G, mu, r.buffers.shs_mu[start:], max_slips=scene.max_avalanche)
        assert got["peak"] == pytest.approx(ref["peak"], rel=1e-9)
        assert got["travel"] == pytest.approx(ref["travel"], rel=1e-9)
        assert got["drawn"] == ref["drawn"]
        # The books: the stage's load kept as f - pull U + f_bar is the one from the displacements, and the
        # forces on the nodes add up to it (the network's springs sum to zero).
        assert got["end_load"] == pytest.approx(ref["end_load"], rel=1e-9, abs=1e-12)
        loads = scene.network.normal_load
        total = (got["G"][:, 0].sum() + got["f"] * loads.sum()) / loads.sum()
        assert total == pytest.approx(got["end_load"], rel=1e-9, abs=1e-12)
        np.testing.assert_allclose(got["G"], ref["G"], rtol=1e-9, atol=1e-10)
        # Every contact renewed: every node slipped in the pull's one count.
        assert (got["epoch"] == 1).all() and (got["count"] >= 1).all()
        # The realization's own pull: the same sample, its travel in l0, and nothing of the state touched.
        assert r.shs_test() == pytest.approx((got["peak"], got["travel"] * Ntilde), rel=1e-15)
        assert r.state["shs_mu_pos"][0] == start + ref["drawn"]
        np.testing.assert_array_equal(r.forces(), F)
        np.testing.assert_array_equal(r.thresholds, mu)
        np.testing.assert_array_equal(r.displacements(), u)
        slips += got["slips"]
    assert slips > 40  # the pulls made avalanches, not a slip per node


# --- the pull never reads less than the first onset ------------------------------------------------------------


@st.composite
def held_states(draw: Any) -> dict[str, Any]:
    kind = draw(st.sampled_from(["two_slider", "chain", "triangular", "irregular"]))
    network: dict[str, Any] = {"kind": kind}
    if kind == "chain":
        network["n"] = draw(st.integers(2, 8))
    elif kind == "triangular":
        network["shape"] = [draw(st.integers(2, 4)), draw(st.integers(2, 4))]
    elif kind == "irregular":
        network.update(n=draw(st.integers(6, 20)), seed=draw(st.integers(0, 3)))
    overshoot = draw(st.sampled_from([1.0, 0.5, 0.0]))
    cfg = config(network, observables=("n", "mu_eff", "tilt_loads", "mu_shs"), mu_eff_at="records",
                 shs={"stiffness": draw(st.floats(0.05, 20.0))}, steps=draw(st.integers(1, 6)),
                 seed=draw(st.integers(0, 2**32 - 1)))
    cfg["friction"]["overshoot"] = overshoot
    cfg["friction"]["static"]["std"] = draw(st.sampled_from([0.01, 0.03]))
    cfg["driver"]["sigma_theta"] = draw(st.sampled_from([1e-7, 3e-7, 1e-6]))
    return cfg


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cfg=held_states())
def test_the_pull_peaks_at_or_above_the_tilt_test_s_first_slip(cfg):
    # Before any slip both tests raise the same load f N_i on the same forces: the first critical f is the
    # same number, and the stage's load there is the pull's first candidate for its peak.
    run = slidernet.run(cfg)
    first, shs = run["tilt_first_slip"].values, run["mu_shs"].values
    assert np.isfinite(shs).all()
    assert (shs >= first).all(), (shs, first)


# --- the pull never touches the run ----------------------------------------------------------------------------


@pytest.mark.parametrize("network", [{"kind": "two_slider"}, {"kind": "chain", "n": 5},
                                     {"kind": "square", "shape": [3, 4]}],
                         ids=["pair-kernel", "chain", "square"])
def test_a_run_is_the_same_bits_with_and_without_mu_shs(network):
    observables = ("n", "mu_max", "x_G", "n_records", "mu_eff")
    cfg = config(network, observables=observables, realizations=3, steps=30)
    without = slidernet.run(cfg)
    with_shs = slidernet.run({**cfg, "observables": [*observables, "mu_shs"], "shs": {"stiffness": 2.0}})
    added = set(with_shs.data_vars) - set(without.data_vars)
    assert added == {"mu_shs", "shs_travel", "mu_shs_mean", "mu_shs_sem"}
    for name in without.data_vars:
        np.testing.assert_array_equal(without[name].values, with_shs[name].values, err_msg=name, strict=True)
    assert np.isfinite(with_shs["mu_shs"].values).all() and (with_shs["shs_travel"].values > 0).all()
    np.testing.assert_allclose(with_shs["mu_shs_mean"].values, with_shs["mu_shs"].mean("realization").values,
                               rtol=1e-14)


def test_the_pair_kernel_and_the_csr_kernel_pull_the_same_two_sliders():
    # Invariant 6: two sliders run the same bits on both kernels, and so do their pulls (the same forces).
    cfg = config({"kind": "two_slider"}, observables=("n", "x_G", "mu_shs"), realizations=2, steps=40)
    pair = slidernet.run(cfg)
    csr = slidernet.run({**cfg, "solver": {"kernel": "csr"}})
    assert (pair.attrs["kernel"], csr.attrs["kernel"]) == ("pair", "csr")
    for name in ("mu_shs", "shs_travel"):
        np.testing.assert_array_equal(pair[name].values, csr[name].values, err_msg=name, strict=True)


def test_the_shs_stream_is_the_fourth_child_and_leaves_the_others_as_they_were():
    ss = np.random.SeedSequence(12)
    rngs = realization_streams(ss)
    shs = np.random.Generator(np.random.PCG64(np.random.SeedSequence(12, spawn_key=(3,))))
    assert shs.bit_generator.state == rngs["shs"].bit_generator.state
    for k, name in enumerate(("driver", "thresholds", "tilt")):
        child = np.random.Generator(np.random.PCG64(np.random.SeedSequence(12, spawn_key=(k,))))
        assert child.bit_generator.state == rngs[name].bit_generator.state


@pytest.mark.parametrize("batch", [16, 64], ids=["batch-16", "batch-64"])
def test_a_pull_that_runs_out_of_draws_goes_on_where_it_stood(batch):
    # A pull of an 8 x 8 lattice draws hundreds of thresholds: with a batch of 16 or 64 it runs out several
    # times, and goes on from where it stood: the same peak, travel and draws as with long buffers.
    def scene(b: int) -> Scene:
        return scene_of({"kind": "triangular", "shape": [8, 8]}, steps=2, solver={"batch": b})

    seed = np.random.SeedSequence(5)
    ref = Realization(scene(10**7), seed).advance(1)
    start = int(ref.state["shs_mu_pos"][0])
    expected = ref.shs_test()
    used = int(ref.state["shs_mu_pos"][0]) - start
    assert used > 5 * batch
    r = Realization(scene(batch), seed).advance(1)
    assert r.shs_test() == expected
    assert r.buffers.shs_mu.size <= 2 * (used + batch)
    assert r.buffers.shs_mu[r.state["shs_mu_pos"][0]] == ref.buffers.shs_mu[start + used]
    np.testing.assert_array_equal(r.result()["mu_shs"][:2], ref.result()["mu_shs"][:2])


def test_a_realization_resumed_from_a_snapshot_pulls_the_same():
    scene = scene_of({"kind": "chain", "n": 6}, steps=20)
    whole = Realization(scene, np.random.SeedSequence(8)).advance().result()
    half = Realization(scene, np.random.SeedSequence(8)).advance(9)
    again = Realization(scene, np.random.SeedSequence(8))
    again.restore(half.snapshot())
    got = again.advance().result()
    for name in ("mu_shs", "shs_travel", "n", "x_G"):
        np.testing.assert_array_equal(got[name], whole[name], err_msg=name, strict=True)


def test_a_pull_stopped_by_max_avalanche_says_so():
    r = Realization(scene_of({"kind": "triangular", "shape": [8, 8]}, steps=2, solver={"max_avalanche": 20}),
                    np.random.SeedSequence(5))
    with pytest.raises(TiltTestError, match=r"The slide-hold-slide pull did not renew every contact at step 0: "
                                            r"after 21 slips, it reached solver\.max_avalanche = 20 slips in all"):
        r.shs_test()


def test_a_slid_away_network_records_no_pull():
    # f_ext above mu_d along +x on every node: the network slides away in the first step; the records after
    # that hold no pull (NaN), and the one at t = 0 has one.
    cfg = config({"kind": "chain", "n": 3, "f_ext": 0.58}, steps=5, **{"friction": {**FRICTION,
                 "static": {"name": "gaussian", "mean": 0.7, "std": 0.01}}})
    res = Realization(Scene.from_config(load_config(cfg)), np.random.SeedSequence(1)).advance().result()
    assert math.isfinite(res["slid_away_at"])
    assert np.isfinite(res["mu_shs"][0]) and np.isnan(res["mu_shs"][1:]).all()


# --- the configuration -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("shs", "observables", "match"),
    [({"stiffness": 0}, None, r"'shs\.stiffness' field must be > 0\.0\. Got 0 instead"),
     ({"stiffness": -1.0}, None, r"'shs\.stiffness' field must be > 0\.0\. Got -1\.0 instead"),
     ({"stiffness": math.nan}, None, r"'shs\.stiffness' field must be a finite number"),
     ({"stiffness": "1.0"}, None, r"'shs\.stiffness' field must be a real number\. Got '1\.0' instead"),
     ({"stiffness": True}, None, r"'shs\.stiffness' field must be a real number\. Got True instead"),
     ({"stifness": 1.0}, None, r"Unknown key 'stifness' in \[shs\]"),
     ({"stiffness": 2.0}, ("n", "x_G"), r"the \[shs\] table sets the slide-hold-slide pull of the observable "
                                        r"'mu_shs', which is not asked for; add \"mu_shs\" to 'observables'")],
    ids=["zero", "negative", "nan", "string", "bool", "unknown-key", "without-mu_shs"],
)
def test_a_bad_shs_table_is_refused_naming_the_key(shs, observables, match):
    kw = {} if observables is None else {"observables": observables}
    with pytest.raises(ConfigError, match=match):
        load_config(config({"kind": "chain", "n": 4}, shs=shs, **kw))


def test_pull_springs_float64_cannot_hold_are_refused_before_the_run():
    with pytest.raises(ConfigError, match=r"The 'shs\.stiffness' value 1e-320 gives pull springs gamma <k> N_i "
                                          r"from 1e-320 to 1e-320 k0 .* use a stiffness nearer 1\."):
        scene_of({"kind": "chain", "n": 4}, shs={"stiffness": 1e-320})


def test_the_default_stiffness_is_one_and_a_configuration_without_the_table_dumps_as_before():
    cfg = load_config(config({"kind": "chain", "n": 4}))
    assert cfg.shs is None and cfg.shs_settings().stiffness == 1.0
    assert "shs" not in cfg.model_dump()
    scene = Scene.from_config(cfg)
    assert scene.shs_operators().pull == 1.0  # gamma <k> with the chain's unit springs
    assert scene_of({"kind": "chain", "n": 4}, observables=("n",)).shs_stiffness is None


def test_the_pull_springs_sit_on_the_diagonal_blocks_only():
    # A lattice keeps its table of distinct blocks, the diagonal ones with their pull springs added once each.
    for network in ({"kind": "triangular", "shape": [5, 4], "normal_load": 2.0}, {"kind": "irregular", "n": 12}):
        scene = scene_of(network, shs={"stiffness": 3.0})
        plain, pulled = scene.tilt_operators().net, scene.shs_operators().net
        difference = (stiffness_matrix(pulled) - stiffness_matrix(plain)).toarray()
        expected = np.zeros_like(difference)
        N = scene.network.n_nodes
        expected[2 * np.arange(N), 2 * np.arange(N)] = 3.0 * np.mean(scene.network.k) * scene.network.normal_load
        np.testing.assert_allclose(difference, expected, rtol=1e-15, atol=0)
        if plain.block_per_entry:
            assert pulled.block_per_entry and pulled.K_table.shape == plain.K_table.shape
        else:  # a handful of distinct diagonal blocks (corners, edges, interior)
            assert plain.K_table.shape[0] < pulled.K_table.shape[0] <= plain.K_table.shape[0] + 8
