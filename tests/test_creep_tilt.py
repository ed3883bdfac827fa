"""A constant external force f_ext (creep) and the network tilt test."""

from __future__ import annotations

import numpy as np
import pytest

import slidernet
from slidernet import kernels
from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.errors import ConfigError
from slidernet.kernels.tilt_net import N_LOADS, N_POS, P_MU, P_U, tilt_test_network
from slidernet.model.builders import triangular
from slidernet.model.network import Network, chain
from slidernet.plugins.distributions import Gaussian, TruncatedBelow
from slidernet.solver import Realization, Scene

from .conftest import make_config

NET_OBS = ["n", "mu_max", "x_G"]


def chain_config(n: int = 2, sigma_ratio: float = 3.0, **changes) -> dict:
    return make_config(**{"steps": 30, "record": "all", "observables": NET_OBS,
                          "network": {"kind": "chain", "n": n, "Ntilde": 1e-7},
                          "driver.sigma_theta": sigma_ratio * 1e-7, **changes})


# --- the network tilt test reduces to the appendix's for two sliders -------


def _pair_work(N: int = 2):
    return kernels.Heaps.empty(2, N), np.zeros(N, np.int64), np.zeros(N_POS, np.int64)


def _settings(mu_d: float, max_slips: int) -> kernels.Settings:
    return kernels.Settings(mu_d=mu_d, max_slips=max_slips, recompute_every=0)


def network_tilt_on_pair(F, mu1, mu2, mu_d, tmu, tu):
    """tilt_test_network on a 2-node chain with spring force F on slider 2 (in N)."""
    ops = Scene.from_config(load_config(chain_config(2)), network=chain(2, Ntilde=1e-7)).tilt_operators()
    G = np.array([[-F, 0.0], [F, 0.0]])
    heaps, epoch, pos = _pair_work()
    f = tilt_test_network(G, np.array([mu1, mu2]), ops.f_ext, ops.f_bar, ops.net, _settings(mu_d, 10_000),
                          ops.pair_rule, np.asarray(tmu, float), np.asarray(tu, float), pos, 10_000, heaps, epoch,
                          np.zeros(2, np.int64), np.zeros(N_LOADS))
    return f, int(pos[P_MU]), int(pos[P_U])


def pair_tilt(F, mu1, mu2, mu_d, tmu, tu):
    st = kernels.new_state()[0]
    f = kernels.tilt_test_pair(st, kernels.Draws(np.empty(0), np.asarray(tmu, float), np.asarray(tu, float)),
                               F, mu1, mu2, mu_d, 2.0)
    return f, int(st["tilt_mu_pos"]), int(st["tilt_u_pos"])


@pytest.mark.parametrize(
    ("F", "mu1", "mu2", "tmu", "tu"),
    [(0.0, 0.6, 0.7, [], []), (0.0, 0.6, 0.9, [0.7, 9.9], []), (-0.35, 0.8, 0.6, [0.7, 0.65, 9.9], [0.25, 0.9]),
     (0.0, 0.9, 0.6, [0.7], [])],
    ids=["immediate", "single", "creep", "slider2"],
)
def test_network_tilt_equals_the_appendix_on_worked_cases(F, mu1, mu2, tmu, tu):
    # The worked cases of test_kernels.py, through the general N-node test.
    assert network_tilt_on_pair(F, mu1, mu2, 0.5, tmu, tu) == pytest.approx(pair_tilt(F, mu1, mu2, 0.5, tmu, tu),
                                                                            abs=1e-15)


def test_network_tilt_equals_the_appendix_on_random_states():
    # 2000 random stable pairs, all three branches of the appendix; seed 7.
    # Thresholds stay below 3 mu_d, where the appendix's slider never slips
    # backwards (the one case where the two rules part, documented in tilt_net).
    rng = np.random.default_rng(7)
    branches = {"creep": 0, "single": 0, "immediate": 0}
    for _ in range(2000):
        mu_d = rng.uniform(0.2, 0.6)
        dist = TruncatedBelow(Gaussian(mu_d + rng.uniform(0.02, 0.3), rng.uniform(0.01, 0.2)), mu_d, "g")
        draws = dist.sample(rng, 1000)
        draws = draws[draws < 3 * mu_d]
        mu1, mu2, tmu = draws[0], draws[1], draws[2:]
        F = rng.uniform(-1, 1) * min(mu1, mu2)
        tu = rng.random(200)
        ref = pair_tilt(F, mu1, mu2, mu_d, tmu, tu)
        got = network_tilt_on_pair(F, mu1, mu2, mu_d, tmu, tu)
        assert got[0] == pytest.approx(ref[0], rel=1e-12, abs=1e-12), (F, mu1, mu2, mu_d)
        assert got[1:] == ref[1:]
        branches["creep" if ref[2] else ("single" if ref[1] else "immediate")] += 1
    assert min(branches.values()) >= 50, branches


def test_network_tilt_out_of_draws_asks_for_more_and_rolls_back():
    ops = Scene.from_config(load_config(chain_config(2)), network=chain(2, Ntilde=1e-7)).tilt_operators()
    heaps, epoch, pos = _pair_work()
    pos[P_MU], pos[P_U] = 3, 1
    f = tilt_test_network(np.zeros((2, 2)), np.array([0.6, 0.9]), ops.f_ext, 0.0, ops.net, _settings(0.5, 100),
                          True, np.full(3, 0.7), np.full(1, 0.5), pos, 100, heaps, epoch, np.zeros(2, np.int64),
                          np.zeros(N_LOADS))
    assert f == -1.0
    assert (pos[P_MU], pos[P_U]) == (3, 1)


# --- mu_eff at the recorded times for any network --------------------------


def reference_network_tilt(net: Network, F: np.ndarray, mu: np.ndarray, mu_d: float,
                           redraws: np.ndarray) -> tuple[float, int, int]:
    """The network tilt test by brute force, from its stated rule (straight slips, N > 2): no heaps, no kernel.

    A load f N_i along +x is added to every node's force F_i and f raised to the
    smallest value at which a node reaches |F_i + f N_i x| = mu_i N_i. At fixed
    f, that node slips, then the unstable ones, largest |F|/(mu N) first (ties
    to the lowest index); a slip moves the node by 2 (|F| - mu_d N) / k_eff
    along F (|F| = mu N exactly for the first one), k_eff = e^T K_ii e, and
    redraws its threshold. The network slides when, after a slip, every node
    has slipped in this avalanche or is unstable, and f + f_bar > mu_d (f_bar =
    sum f_ext,x / sum N); if f + f_bar <= mu_d the count starts again from the
    slipping node. Returns (f + f_bar, thresholds redrawn, restarts of the count).

    Rounding aside (sums in another order), the kernel's answer: no part
    sliding on its own here (rule 4), so no floppy square lattices.
    """
    N, d = net.n_nodes, net.dim
    assert N > 2  # two sliders follow the appendix's creep rule instead
    K = np.zeros((N, N, 2, 2))
    K[:, :, :d, :d] = net.stiffness_matrix().toarray().reshape(N, d, N, d).transpose(0, 2, 1, 3)
    G = np.zeros((N, 2))
    G[:, :d] = np.asarray(F, float).reshape(N, d)
    mu = np.array(mu, float)
    load = net.normal_load.astype(float)
    f_bar = float(net.f_ext[:, 0].sum() / load.sum())
    f, used, restarts, moved = 0.0, 0, 0, set()
    for _ in range(1_000_000):
        T = G + np.outer(f * load, [1.0, 0.0])
        lim = mu * load
        overload = np.hypot(T[:, 0], T[:, 1]) / lim
        driving = not (overload > 1.0).any()
        if driving:
            critical = (-G[:, 0] + np.sqrt(np.maximum(lim**2 - G[:, 1] ** 2, 0.0))) / load
            i = int(np.argmin(critical))
            f = max(f, float(critical[i]))
            moved = set()
        else:
            i = int(np.argmax(overload))
        Ti = G[i] + [f * load[i], 0.0]
        e = Ti / np.hypot(*Ti)
        magnitude = lim[i] if driving else np.hypot(*Ti)
        du = 2.0 * (magnitude - mu_d * load[i]) / (e @ K[i, i] @ e) * e
        G -= K[:, i] @ du
        moved.add(i)
        T = G + np.outer(f * load, [1.0, 0.0])
        unstable = set(np.flatnonzero(np.hypot(T[:, 0], T[:, 1]) > mu * load).tolist())
        if len(moved | unstable) == N:
            if f + f_bar > mu_d:
                return f + f_bar, used, restarts
            moved = {i}
            restarts += 1
        mu[i] = redraws[used]
        used += 1
    raise AssertionError("the reference tilt test did not end")




@pytest.mark.parametrize(("f_ext", "seed", "damped"), [(0.0, 4, False), (-0.1, 6, True)], ids=["flat", "uphill"])
def test_mu_eff_on_a_lattice_at_every_recorded_time(f_ext, seed, damped):
    # Seeds 4 and 6, 2 realizations of a 4 x 5 triangular lattice: every recorded mu_eff
    # is the mean of the two realizations' tests, each the brute-force rule
    # above on the state at that time with the tilt stream's draws in order
    # (to 1e-9: the sums run in another order). Uphill (f_ext = -0.1 N along x,
    # f_bar = -0.1) the whole lattice also moves at f + f_bar <= mu_d: the
    # damped motion, whose count starts again, is exercised too (9 times with seed 6).
    cfg = make_config(**{"seed": seed, "realizations": 2, "steps": 20, "record": [5, 10],
                         "observables": [*NET_OBS, "mu_eff"],
                         "network": {"kind": "triangular", "shape": [4, 5], "Ntilde": 1e-7, "f_ext": f_ext},
                         "driver.sigma_theta": 3e-7})
    ds = slidernet.run(cfg, progress=False)
    assert ds.attrs["kernel"] == "vec"
    # One test per realization at t = 0, 5, 10 and 20.
    np.testing.assert_array_equal(ds["mu_eff_count"].values, [2, 2, 2, 2])
    scene = Scene.from_config(load_config(cfg))
    samples, restarts = [], 0
    for child in realization_seeds(seed, 2):
        r = Realization(scene, child)
        redraws, pos, row = r.buffers.tilt_mu.copy(), 0, []
        for t in ds["t"].values:
            r.advance(int(t))  # its own test at t leaves the state as it was
            f, used, again = reference_network_tilt(scene.network, r.forces(), r.thresholds, 0.5, redraws[pos:])
            pos += used
            restarts += again
            row.append(f)
        assert r.state["tilt_mu_pos"][0] == pos  # the same draws: one per slip but the last
        samples.append(row)
    np.testing.assert_allclose(ds["mu_eff"].values, np.mean(samples, axis=0), rtol=1e-9, atol=0)
    assert pos > 100  # the tests made avalanches, not single slips
    if damped:  # the uphill case exercises the damped branch (flat runs may too, as seed 4 does now)
        assert restarts > 0


def test_the_tilt_test_changes_nothing_but_the_tilt_stream():
    base = make_config(**{"steps": 25, "record": "all", "observables": NET_OBS,
                          "network": {"kind": "square", "shape": [4, 4], "Ntilde": 1e-7},
                          "driver.sigma_theta": 3e-7})
    tilted = {**base, "observables": [*NET_OBS, "mu_eff"], "mu_eff_at": "records"}
    a = Realization(Scene.from_config(load_config(base)), np.random.SeedSequence(9)).advance().result()
    b = Realization(Scene.from_config(load_config(tilted)), np.random.SeedSequence(9)).advance().result()
    for name in ("n", "mu_max", "x_G", "y_G", "node_slips"):
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    assert b["f_count"].sum() == 26


def test_a_tilt_test_leaves_the_state_as_it_was():
    cfg = load_config(chain_config(6, observables=[*NET_OBS, "mu_eff"]))
    r = Realization(Scene.from_config(cfg), np.random.SeedSequence(1)).advance(10)
    F, mu, u = r.forces().copy(), r.thresholds, r.displacements()
    start = r.state["tilt_mu_pos"][0]
    expected, used, _ = reference_network_tilt(r.scene.network, F, mu, cfg.friction.mu_d,
                                               r.buffers.tilt_mu[start:])
    f = r.tilt_test()
    assert f == pytest.approx(expected, rel=1e-9)
    assert r.state["tilt_mu_pos"][0] == start + used
    np.testing.assert_array_equal(r.forces(), F)
    np.testing.assert_array_equal(r.thresholds, mu)
    np.testing.assert_array_equal(r.displacements(), u)


@pytest.mark.parametrize("n", [3, 6])
def test_a_relaxed_chain_of_equal_thresholds_slides_at_that_threshold(n):
    # Worked case: springs at rest (t = 0) and every mu_s = 0.62. At f = 0.62 the
    # first end slips along +x; in 1D a slip along +x raises the force on both
    # neighbours, so each node, once unstable, stays so until it slips, and the
    # avalanche reaches every node at that f (no force gets near 2 mu_d + mu_s,
    # where a node would slip back). mu_eff is 0.62 exactly, whatever the redraws.
    cfg = load_config(chain_config(n, observables=[*NET_OBS, "mu_eff"]))
    r = Realization(Scene.from_config(cfg), np.random.SeedSequence(2))
    np.testing.assert_array_equal(r.forces(), 0.0)
    r.mu[:] = 0.62
    assert r.tilt_test() == 0.62
    assert reference_network_tilt(r.scene.network, r.forces(), r.thresholds, 0.5, r.buffers.tilt_mu)[0] == 0.62


def test_mu_eff_before_every_rearrangement_needs_a_pair():
    cfg = chain_config(5, observables=[*NET_OBS, "mu_eff"], mu_eff_at="rearrangements")
    with pytest.raises(ConfigError, match=r"needs a 1D pair of sliders .* use 'records'"):
        load_config(cfg)


def test_a_two_slider_pair_gets_the_appendix_test_by_default():
    scene = Scene.from_config(load_config(make_config(steps=10)))
    assert scene.tilt_at == "rearrangements"
    chain5 = Scene.from_config(load_config(chain_config(5, observables=[*NET_OBS, "mu_eff"])))
    assert chain5.tilt_at == "records"


# --- f_ext: validation ---------------------------------------------------


@pytest.mark.parametrize(
    ("value", "match"),
    [(np.nan, "must be finite"), ([[1.0, 2.0, 3.0]], r"shape \(1, 3\)"), (np.ones(5), r"shape \(5,\)")],
    ids=["nan", "three-components", "wrong-length"],
)
def test_bad_f_ext_is_refused(value, match):
    net = triangular((2, 2), Ntilde=1e-7)
    with pytest.raises(ConfigError, match=rf"'f_ext' parameter of Network .*{match}"):
        Network(net.positions, net.edges, Ntilde=1e-7, f_ext=value)


def test_a_vector_f_ext_on_a_chain_is_refused():
    with pytest.raises(ConfigError, match=r"network is 1D: 'f_ext' must be a number"):
        load_config(chain_config(4, **{"network.f_ext": [0.1, 0.2]}))


@pytest.mark.parametrize(("value", "expected"), [(0.2, [0.2, 0.0]), ([0.1, -0.3], [0.1, -0.3])],
                         ids=["number", "vector"])
def test_f_ext_shapes(value, expected):
    net = triangular((2, 3), Ntilde=1e-7)
    net2 = Network(net.positions, net.edges, Ntilde=1e-7, f_ext=value)
    np.testing.assert_array_equal(net2.f_ext, np.tile(expected, (6, 1)))


def test_f_ext_survives_a_graphml_round_trip(tmp_path):
    from slidernet.model.builders import from_graph, read_graph, write_graph

    net = triangular((3, 3), Ntilde=1e-7, f_ext=[0.05, -0.01])
    (path,) = write_graph(net, tmp_path / "net.graphml")
    back = from_graph(read_graph(path), Ntilde=1e-7)
    np.testing.assert_allclose(back.f_ext, net.f_ext)


# --- f_ext: mechanics ----------------------------------------------------


def test_an_f_ext_above_the_thresholds_is_relaxed_at_t0():
    # f_ext = 0.65 N on every other slider of a chain: sliders whose mu_s < 0.65 slip
    # at once; the initial record shows a stable state with those slips. The mean load,
    # 0.325, is below mu_d: above it, an avalanche that moves every node is the network
    # sliding away (tests/test_incline.py).
    cfg = chain_config(8, **{"friction.static.std": 0.05})
    f_ext = np.where(np.arange(8) % 2 == 0, 0.65, 0.0)
    scene = Scene.from_config(load_config(cfg), network=chain(8, Ntilde=1e-7, f_ext=f_ext))
    r = Realization(scene, np.random.SeedSequence(3))
    weak = int((r.thresholds[f_ext > 0] < 0.65).sum())
    assert weak > 0
    r.advance(0)
    assert r.n >= weak and not r.slid_away
    res = r.result()
    assert res["n"][0] == r.n
    assert (np.abs(r.forces()) <= r.thresholds * (1 + 1e-12)).all()
    # The external load is carried by the substrate: the net force is sum_i f_ext,i.
    assert r.forces().sum() == pytest.approx(4 * 0.65, rel=1e-12)


@pytest.mark.parametrize("kind", ["chain", "triangular"])
def test_thermal_cycling_makes_the_network_creep_downhill(kind):
    # Same seed, f_ext = 0 against f_ext = 0.05 N along +x; 200 tau_th; seed 12.
    net = {"kind": "chain", "n": 6} if kind == "chain" else {"kind": "triangular", "shape": [4, 4]}

    def drift(f_ext: float) -> float:
        cfg = make_config(**{"seed": 12, "realizations": 4, "steps": 200, "record": [0],
                             "observables": NET_OBS, "network": {**net, "Ntilde": 1e-7, "f_ext": f_ext},
                             "driver.sigma_theta": 3e-7})
        return float(slidernet.run(cfg, progress=False)["x_G_mean"].isel(t=-1))

    # Without load x_G wanders by ~ sigma_theta; with it, it creeps by many times that.
    assert drift(0.05) > 20 * 3e-7
    assert abs(drift(0.0)) < 5 * 3e-7


def test_a_damped_collective_motion_restarts_the_count_of_a_part_sliding_alone():
    # Rule 3 of the network tilt test: an avalanche of more than max(100 N, 1e5) slips that never set every
    # node in motion is a part sliding alone. After a damped collective motion (every node moving at
    # f + f_bar <= mu_d) the count of moving nodes starts again, and so must the count of slips: the slips
    # before the restart counted too, and an irregular network of 1024 sliders failed with TiltTestError
    # at its second recorded time (seed 1; found by examples/aging_networks.py).
    cfg = {"seed": 1, "realizations": 1, "steps": 3, "record": "all", "observables": ["n", "mu_eff"],
           "mu_eff_at": "records", "network": {"kind": "irregular", "n": 1024, "Ntilde": 1e-7},
           "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}
    r = Realization(Scene.from_config(load_config(cfg)), np.random.SeedSequence(1, spawn_key=(0,))).advance()
    samples = r.out["f_sum"] / r.out["f_count"]
    assert (r.out["f_count"] == 1).all() and (samples > 0.5).all()


def _lattice_tilt_scene(batch: int, **solver) -> Scene:
    cfg = {"seed": 3, "realizations": 1, "steps": 2, "record": "all", "observables": ["n", "mu_eff"],
           "network": {"kind": "triangular", "shape": [8, 8], "Ntilde": 1e-7},
           "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}, "solver": {"batch": batch, **solver}}
    return Scene.from_config(load_config(cfg))


@pytest.mark.parametrize("batch", [16, 100], ids=["batch-16", "batch-100"])
def test_a_network_tilt_test_that_runs_out_of_draws_goes_on_where_it_stood(batch: int) -> None:
    # A test of an 8 x 8 lattice takes hundreds of thresholds: with a batch of 16 or 100 it runs out several
    # times. It must go on from where it stood (not start again): the same sample and the same draws as
    # with buffers long enough, the threshold buffer grown to at most twice what the test read plus a
    # batch, and the uniforms (read only by a pair's creep rule) not grown at all.
    seed = np.random.SeedSequence(5)
    ref = Realization(_lattice_tilt_scene(10**7), seed)
    ref.advance(1)  # with a test at steps 0 and 1 (the records)
    ref_start = int(ref.state["tilt_mu_pos"][0])
    f_ref = ref.tilt_test()
    used = int(ref.state["tilt_mu_pos"][0]) - ref_start
    assert used > 5 * batch  # the case needs several refills

    r = Realization(_lattice_tilt_scene(batch), seed)
    r.advance(1)
    assert r.tilt_test() == f_ref
    buffers = r.streams.buffers
    assert buffers.tilt_mu.size <= 2 * (used + batch)
    assert buffers.tilt_u.size == batch
    # The next draw is the reference's next one.
    assert buffers.tilt_mu[r.state["tilt_mu_pos"][0]] == ref.streams.buffers.tilt_mu[ref_start + used]


def test_a_tilt_test_stopped_by_max_avalanche_says_so() -> None:
    # The test of an 8 x 8 lattice takes hundreds of slips; at solver.max_avalanche = 50 it gives up,
    # and the message names that limit, not the rule of a part sliding alone below mu_d.
    r = Realization(_lattice_tilt_scene(1000, max_avalanche=50), np.random.SeedSequence(5))
    with pytest.raises(slidernet.TiltTestError,
                       match=r"did not reach sliding at step 0: after 51 slips, at a load per unit normal load of "
                             r"0\.[0-9]+, it reached solver\.max_avalanche = 50 slips in all\. A genuinely long "
                             r"test needs a larger solver\.max_avalanche\."):
        r.tilt_test()
