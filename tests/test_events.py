"""The event catalogue (observable ``events``): one row per slip, consistent with the records."""

from __future__ import annotations

import numpy as np
import pytest

import slidernet
from slidernet.config import load_config
from slidernet.model.builders import triangular
from slidernet.model.network import Network, chain
from slidernet.solver import Realization, Scene
from slidernet.solver import backends as backends_module

from .conftest import make_config

NETWORKS = {
    "chain": {"kind": "chain", "n": 6},
    "triangular": {"kind": "triangular", "shape": [4, 5]},
    "two_slider": {"kind": "two_slider"},
}


def events_config(net: dict, steps: int = 40, events: bool = True, **changes) -> dict:
    obs = ["n", "mu_max", "x_G"] + (["events"] if events else [])
    return make_config(**{"seed": 3, "realizations": 2, "steps": steps, "record": "all", "observables": obs,
                          "network": {**net, "Ntilde": 1e-7}, "driver.sigma_theta": 3e-7, **changes})


def catalogued_displacements(ev: dict, shape: tuple[int, ...]) -> np.ndarray:
    """Per-node sums of the catalogue's slips, shape (N, d) like ``Realization.displacements()``."""
    u = np.zeros((shape[0], 2))
    np.add.at(u, ev["node"], np.column_stack([ev["dx"], ev["dy"]]))
    return u[:, : shape[1]]


@pytest.fixture
def small_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    # Many returns of the kernel to Python per run: exercises the buffer hand-over.
    monkeypatch.setattr(backends_module, "EVENT_CHUNK", 64)


@pytest.mark.parametrize("net", list(NETWORKS.values()), ids=list(NETWORKS))
def test_the_catalogue_adds_up_to_the_records(net, small_chunks):
    cfg = load_config(events_config(net))
    r = Realization(Scene.from_config(cfg), np.random.SeedSequence(5)).advance()
    res, ev = r.result(), r.events()
    assert ev["node"].size == res["n"][-1] > 64 * 3
    # Each slip counted once per node, and the slips of a node add up to its
    # displacement in the final state (the u that the forces are recomputed from).
    np.testing.assert_array_equal(np.bincount(ev["node"], minlength=r.mu.size), res["node_slips"])
    u = r.displacements()
    np.testing.assert_allclose(catalogued_displacements(ev, u.shape), u, rtol=1e-12, atol=1e-18)
    # Time runs forward; avalanche ids count the driving events.
    assert (np.diff(ev["time"]) >= 0).all() and ev["time"][0] >= 0 and ev["time"][-1] <= cfg.steps
    assert (np.diff(ev["avalanche"]) >= 0).all()
    assert np.unique(ev["avalanche"]).size == res["n_events"]
    # The slips up to each recorded time are those with time <= t.
    t = r.scene.out_steps
    np.testing.assert_array_equal(np.searchsorted(ev["time"], t, side="right"), res["n"])


@pytest.mark.parametrize("net", list(NETWORKS.values()), ids=list(NETWORKS))
def test_the_catalogue_changes_no_result(net):
    with_ev = slidernet.run(events_config(net))
    without = slidernet.run(events_config(net, events=False))
    for name in ("n", "mu_max", "x_G"):
        np.testing.assert_array_equal(with_ev[name].values, without[name].values, err_msg=name)
    assert "event" not in without.dims
    assert with_ev.sizes["event"] == int(with_ev["n"].isel(t=-1).sum())
    assert with_ev["events_complete"].values.tolist() == [1, 1]


def test_a_two_slider_catalogue_runs_on_the_csr_kernel():
    assert Scene.from_config(load_config(events_config(NETWORKS["two_slider"]))).kernel == "csr"
    cfg = events_config(NETWORKS["two_slider"], **{"solver.kernel": "pair"})
    with pytest.raises(slidernet.ConfigError, match=r"'events' observable .* needs a network kernel"):
        load_config(cfg)


def test_max_events_stops_the_catalogue_not_the_run(small_chunks):
    base = events_config(NETWORKS["triangular"], **{"solver.max_events": 100})
    with pytest.warns(RuntimeWarning, match=r"reached solver.max_events = 100 events at step \d+"):
        capped = slidernet.run(base)
    full = slidernet.run(events_config(NETWORKS["triangular"]))
    np.testing.assert_array_equal(capped["n"].values, full["n"].values)
    assert capped["events_complete"].values.tolist() == [0, 0]
    assert capped.sizes["event"] == 200
    first = full["event_node"].where(full["event_realization"] == 0, drop=True).values[:100]
    np.testing.assert_array_equal(capped["event_node"].values[:100], first)


def test_the_catalogue_is_written_to_netcdf(tmp_path):
    from slidernet.io import read_result, write_netcdf

    ds = slidernet.run(events_config(NETWORKS["triangular"], steps=10))
    path = write_netcdf(ds, tmp_path / "result.nc")
    back = read_result(path)
    for name in ("event_time", "event_node", "event_avalanche", "event_dx", "event_dy", "event_realization"):
        np.testing.assert_array_equal(back[name].values, ds[name].values, err_msg=name)
    assert back["event_dx"].attrs["units"] == "l0"


# --- x_G -------------------------------------------------------------------


def loaded(net: dict) -> Network:
    """The network of ``net`` with unequal normal loads (1 to 2.5 N), so that x_G is not the plain mean of u."""
    if net["kind"] == "triangular":
        return triangular(net["shape"], Ntilde=1e-7, normal_load=np.linspace(1.0, 2.5, np.prod(net["shape"])))
    n = net.get("n", 2)
    return chain(n, Ntilde=1e-7, normal_load=np.linspace(1.0, 2.5, n))


@pytest.mark.parametrize("net", list(NETWORKS.values()), ids=list(NETWORKS))
def test_x_G_is_the_load_weighted_mean_of_the_catalogued_displacements(net, small_chunks):
    # The kernel adds the same du to the catalogue, to u and to x_G. x_G must
    # be the load-weighted mean of the displacements at every recorded time:
    # rebuilt here from the catalogue's slips up to t and the network's loads,
    # and at the end from the displacements of the final state.
    network = loaded(net)
    scene = Scene.from_config(load_config(events_config(net)), network)
    r = Realization(scene, np.random.SeedSequence(5)).advance()
    res, ev = r.result(), r.events()
    weight = network.normal_load / network.normal_load.sum()
    upto = np.searchsorted(ev["time"], scene.out_steps, side="right")
    x_G = np.concatenate([[0.0], np.cumsum(weight[ev["node"]] * ev["dx"])])[upto]
    np.testing.assert_allclose(res["x_G"], x_G, rtol=1e-9, atol=1e-18)
    u = r.displacements()
    assert res["x_G"][-1] == pytest.approx(weight @ u[:, 0], rel=1e-9, abs=1e-18)
    if u.shape[1] == 2:
        assert res["y_G"][-1] == pytest.approx(weight @ u[:, 1], rel=1e-9, abs=1e-18)
    # The loads matter here: the plain mean of the displacements is another number.
    assert abs(u[:, 0].mean() - res["x_G"][-1]) > 1e-3 * abs(res["x_G"][-1]) > 0


# --- avalanche_count ------------------------------------------------------


def catalogue_avalanche_count(ev: dict, bins: int) -> np.ndarray:
    """``avalanche_count`` rebuilt from the catalogue: slips per avalanche id, binned by floor(log2 size).

    Id 0 is the relaxation at t = 0 (its slips alone), id k > 0 the k-th
    driving event (its driving slip and the slips it set off).
    """
    _, sizes = np.unique(ev["avalanche"], return_counts=True)
    _, exponent = np.frexp(sizes)  # size = m 2**e with 0.5 <= m < 1: floor(log2 size) = e - 1, exactly
    return np.bincount(exponent - 1, minlength=bins)


# A chain for the csr kernel, a triangular lattice for the vec kernel.
KERNEL_NETWORKS = {
    "csr": {"kind": "chain", "n": 20},
    "vec": {"kind": "triangular", "shape": [6, 6]},
}
DEFAULT_BATCH = 1 << 16  # solver.batch's default


def with_f_ext(net: dict, fx: np.ndarray) -> Network:
    """The network of ``net`` (a chain or a triangular lattice) with the force ``fx[i]`` along x on node i."""
    if net["kind"] == "chain":
        return chain(net["n"], Ntilde=1e-7, f_ext=fx)
    return triangular(net["shape"], Ntilde=1e-7, f_ext=np.column_stack([fx, np.zeros_like(fx)]))


def halves_pushed_together(net: dict) -> Network:
    """0.7 N along +x on the left half of the chain or of each row of the lattice, along -x on the right half.

    0.7 N is above every threshold (0.6 +- 0.01): every slider is overloaded
    at t = 0, and the relaxation takes tens to hundreds of slips. The forces
    cancel: a uniform f_ext above mu_d would make the network slide for ever.
    """
    n, cols = (net["n"], net["n"]) if net["kind"] == "chain" else (np.prod(net["shape"]), net["shape"][1])
    return with_f_ext(net, np.where(np.arange(n) % cols < cols // 2, 0.7, -0.7))


@pytest.mark.parametrize("batch", [16, DEFAULT_BATCH], ids=["batch16", "default_batch"])
@pytest.mark.parametrize("overload", [True, False], ids=["overload_at_t0", "driven_only"])
@pytest.mark.parametrize("kernel", list(KERNEL_NETWORKS))
def test_avalanche_count_is_the_catalogue_binned(kernel, overload, batch):
    net = KERNEL_NETWORKS[kernel]
    cfg = load_config(events_config(net, **{"solver.batch": batch}))
    scene = Scene.from_config(cfg, halves_pushed_together(net) if overload else None)
    assert scene.kernel == kernel
    r = Realization(scene, np.random.SeedSequence(5)).advance()
    res, ev = r.result(), r.events()
    relaxation = int((ev["avalanche"] == 0).sum())
    if overload:
        # The kernel returns for thresholds every `batch` slips: at batch 16 the
        # relaxation spans several refills, each a re-entry before t = 0.
        assert relaxation > 3 * 16
        assert res["n"][0] == relaxation
    else:
        assert relaxation == 0
    assert res["n_events"] > 100
    expected = catalogue_avalanche_count(ev, res["avalanche_count"].size)
    np.testing.assert_array_equal(res["avalanche_count"], expected)
    assert res["avalanche_count"].sum() == res["n_events"] + (relaxation > 0)


@pytest.mark.parametrize("kernel", list(KERNEL_NETWORKS))
def test_one_overloaded_slider_is_an_avalanche_of_one_slip(kernel):
    # 0.7 N on one interior slider: it slips once, to 2 mu_d - 0.7 = 0.3 N, and
    # its neighbours take less than their thresholds. There is no driving
    # slip, so the relaxation's size is 1: bin 0.
    net = KERNEL_NETWORKS[kernel]
    n = net.get("n") or int(np.prod(net["shape"]))
    node = n // 2 + 3
    scene = Scene.from_config(load_config(events_config(net)), with_f_ext(net, 0.7 * (np.arange(n) == node)))
    r = Realization(scene, np.random.SeedSequence(5))
    r.advance(0)
    res = r.result()
    assert r.n == 1 and res["n_events"] == 0
    assert r.events()["node"].tolist() == [node]
    assert res["avalanche_count"].tolist() == [1] + [0] * (res["avalanche_count"].size - 1)


def test_a_small_max_events_caps_the_catalogue_at_the_real_chunk_size():
    # At the real buffer size (EVENT_CHUNK = 65536 rows, not the 64 the other tests patch in), a cap
    # below the buffer was never applied, and past it the kernel asked for a flush at every slip for
    # ever: this run (a chain of 8, 3000 tau_th, 1.4 s uncapped) hung.
    cfg = make_config(**{"seed": 1, "realizations": 2, "steps": 3000, "observables": ["n", "events"],
                         "network": {"kind": "chain", "n": 8, "Ntilde": 1e-7}, "driver.sigma_theta": 1e-6,
                         "solver.max_events": 100})
    with pytest.warns(RuntimeWarning, match=r"solver.max_events = 100 events") as caught:
        r = Realization(Scene.from_config(load_config(cfg)), np.random.SeedSequence(5)).advance()
    assert sum("max_events" in str(w.message) for w in caught) == 1  # warned once
    res = r.result()
    assert res["n"][-1] > 1000  # the physics went on past the cap
    assert res["events"]["node"].size == 100 and res["events_complete"] is False
    np.testing.assert_array_equal(res["events"]["time"], r.events()["time"])
    with pytest.warns(RuntimeWarning, match=r"solver.max_events = 100 events"):
        ds = slidernet.run(cfg)
    assert (ds["events_complete"].values == 0).all()


@pytest.mark.parametrize("cap", [1, 64, 65_537], ids=["one", "below-chunk", "past-chunk"])
def test_the_cap_is_exact_whatever_its_relation_to_the_buffer(cap):
    cfg = load_config(events_config({"kind": "chain", "n": 6}, steps=2000, events=True,
                                    **{"solver.max_events": cap, "driver.sigma_theta": 3e-6}))
    with pytest.warns(RuntimeWarning, match=rf"solver.max_events = {cap} events"):
        r = Realization(Scene.from_config(cfg), np.random.SeedSequence(2)).advance()
    res = r.result()
    assert res["n"][-1] > cap
    assert res["events"]["node"].size == cap and res["events_complete"] is False


@pytest.mark.parametrize("net", [NETWORKS["chain"], NETWORKS["triangular"]], ids=["chain", "triangular"])
def test_a_node_that_a_recomputation_finds_unstable_opens_its_own_avalanche(net):
    # Resetting the forces from u can find a node a rounding error over its threshold (exact ties occur
    # with constant thresholds and periodic drivers). Here u is nudged so that the reset puts the most
    # loaded node 1e-12 over its threshold. Its slips used to run under the previous avalanche's id and
    # time, outside the avalanche counts.
    cfg = load_config(events_config(net, steps=40))
    r = Realization(Scene.from_config(cfg), np.random.SeedSequence(5)).advance(20)
    before = r.result()
    N = r.mu.size
    F = r.forces().reshape(N, -1)
    j = int(np.argmax(np.linalg.norm(F, axis=1) / r.mu))
    d = F.shape[1]
    K_jj = r.scene.K.toarray()[d * j: d * j + d, d * j: d * j + d]
    c = 1.0 - r.mu[j] * (1.0 + 1e-12) / np.linalg.norm(F[j])
    u = r.backend.nodes.u.reshape(N, d)
    u[j] += np.linalg.solve(K_jj, c * F[j])  # then F_j = (1 - c) F_j: |F_j| = mu_j (1 + 1e-12)
    r.recompute_forces()
    assert np.linalg.norm(r.forces().reshape(N, -1)[j]) > r.mu[j]
    r.advance()
    res, ev = r.result(), r.events()
    k = before["events"]["node"].size
    assert ev["node"][k] == j  # the next slip is that node's ...
    assert ev["avalanche"][k] == before["n_events"] + 1  # ... in an avalanche of its own ...
    assert ev["time"][k] == 20.0  # ... at the current theta: the start of step 20
    assert np.unique(ev["avalanche"]).size == res["n_events"] == res["avalanche_count"].sum()
