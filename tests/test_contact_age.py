"""The observable contact_age: the time since each node last slipped, exact, on every kernel."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import slidernet
from slidernet import kernels
from slidernet.analysis.observables import binned_quantile
from slidernet.config import load_config
from slidernet.errors import ConfigError
from slidernet.solver import Realization, Scene

from .conftest import make_config

# Powers of two: theta / Ntilde = q / 2 exactly, so the slips' times are exact binary fractions.
NT = 2.0 ** -23

NETWORKS = {
    "two_slider": {"kind": "two_slider"},
    "chain": {"kind": "chain", "n": 5},
    "square": {"kind": "square", "shape": [3, 3]},
    "triangular": {"kind": "triangular", "shape": [3, 4]},
    "irregular": {"kind": "irregular", "n": 12},
}


def _config(network: dict[str, Any], **changes: Any) -> dict[str, Any]:
    return make_config(**{"realizations": 2, "steps": 40, "record": "all",
                          "observables": ["n", "contact_age"], "network": {**network, "Ntilde": 1e-7},
                          **changes})


def _graph(tmp_path: Path) -> dict[str, Any]:
    path = tmp_path / "line.edgelist"
    path.write_text("0 1\n1 2\n2 3\n", encoding="utf-8")
    (tmp_path / "line.nodes.csv").write_text("node,x\n0,0.0\n1,1.0\n2,2.0\n3,3.0\n", encoding="utf-8")
    return {"kind": "graph", "path": str(path)}


@pytest.mark.parametrize("kind", [*NETWORKS, "graph"], ids=[*NETWORKS, "graph"])
def test_a_node_that_never_slips_has_age_t_exactly(kind: str, tmp_path: Path) -> None:
    # sigma_theta / Ntilde = 1e-6: no force comes near a threshold, no node ever slips.
    network = _graph(tmp_path) if kind == "graph" else NETWORKS[kind]
    # allow_implausible: a drive this weak is far below real materials' (the point: no slip at all)
    ds = slidernet.run(_config(network, **{"driver.sigma_theta": 1e-13, "allow_implausible": True}))
    assert int(ds["n"].max()) == 0
    t = ds["t"].values.astype(float)
    np.testing.assert_array_equal(ds["contact_age"].values, np.broadcast_to(t, ds["contact_age"].shape))
    np.testing.assert_array_equal(ds["contact_age_mean"].values, t)
    np.testing.assert_array_equal(ds["contact_age_sem"].values, np.zeros_like(t))
    # Every node of every realization in the bin of t (bin 0 at t = 0).
    count = ds["contact_age_count"]
    nodes = int(count.isel(t=0).sum())
    assert nodes == 2 * len(ds["node_slips"].node) if "node_slips" in ds else nodes > 0
    expected = np.zeros(count.shape, np.int64)
    expected[np.arange(t.size), np.searchsorted(kernels.AGE_EDGES, t, side="right")] = nodes
    np.testing.assert_array_equal(count.values, expected)


def test_two_sliders_by_hand() -> None:
    """theta / Ntilde = q / 2 (a ramp), mu_s = 0.75 and mu_d = 0.5 for every draw: both sliders reach their
    threshold together, slider 0 makes every slip (ties go to the lowest index), at theta / Ntilde = 0.75,
    1.25, 1.75, ... (each slip adds 0.5 to the spring's length), i.e. at t = 1.5, 2.5, 3.5, ... Slider 1
    never slips. At the record t >= 2 the ages are 0.5 and t, their mean (t + 0.5) / 2; at t = 0 and 1, t."""
    cfg = make_config(**{"realizations": 1, "steps": 10, "record": "all", "observables": ["n", "contact_age"],
                         "network": {"kind": "two_slider", "Ntilde": NT},
                         "friction": {"mu_d": 0.5, "static": {"name": "constant", "value": 0.75}},
                         "driver": {"name": "ramp", "rate": NT / 2}})
    ds = slidernet.run(cfg)
    t = np.arange(11.0)
    np.testing.assert_array_equal(ds["n"].values[0], np.maximum(t - 1, 0).astype(np.int64))
    np.testing.assert_array_equal(ds["contact_age"].values[0], np.where(t >= 2, (t + 0.5) / 2, t))
    # The ages 0.5 and t, binned: 0.5 lies in [10**-0.5, 1), bin 4 * 6 - 2 + 1 = 23.
    bins = np.searchsorted(kernels.AGE_EDGES, [0.5, 10.0], side="right")
    assert bins[0] == 23 and kernels.AGE_EDGES[22] <= 0.5 < kernels.AGE_EDGES[23]
    assert ds["contact_age_count"].values[-1, bins[0]] == 1 and ds["contact_age_count"].values[-1, bins[1]] == 1
    assert ds["contact_age_bin"].values[bins[0]] <= 0.5 < ds["contact_age_upper"].values[bins[0]]


def _ages_from_catalogue(ds: Any, n_nodes: int) -> np.ndarray:
    """Each realization's mean age at each record, from the event catalogue alone: the last slip of each node
    with time < t (the slips of step q have times in [q, q + 1)), summed in node order as the kernel does."""
    t = ds["t"].values.astype(float)
    ages = np.empty((ds.sizes["realization"], t.size))
    for r in range(ages.shape[0]):
        mine = ds["event_realization"].values == r
        time, node = ds["event_time"].values[mine], ds["event_node"].values[mine]
        for k, tk in enumerate(t):
            last = np.zeros(n_nodes)
            before = time < tk
            last[node[before]] = time[before]  # in slip order: the last write of each node wins
            total = 0.0
            for value in last:
                total += value
            ages[r, k] = tk - total / n_nodes
    return ages


@pytest.mark.parametrize("network", [{"kind": "chain", "n": 8}, {"kind": "triangular", "shape": [3, 3]}],
                         ids=["chain8", "triangular3x3"])
def test_contact_age_is_the_event_catalogue_s_to_the_bit(network: dict[str, Any]) -> None:
    ds = slidernet.run(_config(network, **{"observables": ["n", "contact_age", "events"], "steps": 30,
                                           "realizations": 3}))
    assert int(ds["n"].values[:, -1].min()) > 100  # every realization slipped many times
    n_nodes = int(np.prod(network.get("shape", [network.get("n", 0)])))
    np.testing.assert_array_equal(ds["contact_age"].values, _ages_from_catalogue(ds, n_nodes))
    # Ages are not rounded to steps: slips inside a step leave fractional ages.
    assert not np.all(ds["contact_age"].values == np.round(ds["contact_age"].values))


def test_the_tilt_test_leaves_the_ages_unchanged() -> None:
    cfg = _config({"kind": "chain", "n": 6}, steps=30)
    plain = slidernet.run(cfg)
    tilted = slidernet.run({**cfg, "observables": ["n", "contact_age", "mu_eff"]})
    assert int(tilted["mu_eff_count"].sum()) > 0
    np.testing.assert_array_equal(plain["contact_age"].values, tilted["contact_age"].values)
    np.testing.assert_array_equal(plain["contact_age_count"].values, tilted["contact_age_count"].values)


def test_the_mean_and_sem_are_over_realizations() -> None:
    ds = slidernet.run(_config({"kind": "chain", "n": 6}, realizations=4, steps=30))
    ages = ds["contact_age"].values
    np.testing.assert_allclose(ds["contact_age_mean"].values, ages.mean(axis=0), rtol=1e-13)
    np.testing.assert_allclose(ds["contact_age_sem"].values, ages.std(axis=0, ddof=1) / 2.0,
                               rtol=1e-10, atol=1e-15)
    assert ds["contact_age_count"].dims == ("t", "contact_age_bin")
    assert (ds["contact_age_count"].sum("contact_age_bin") == 4 * 6).all()


def test_a_scene_without_contact_age_keeps_no_last_slip() -> None:
    scene = Scene.from_config(load_config(_config({"kind": "chain", "n": 6}, observables=["n"])))
    assert not scene.contact_age
    real = Realization(scene, np.random.SeedSequence(1))
    assert real.backend.nodes.last_slip.size == 0 and real.series.contact_age.size == 0


def test_a_snapshot_from_before_last_slip_restores_where_it_is_not_kept() -> None:
    """A checkpoint written before ``nodes/last_slip`` existed resumes a scene that does not keep it; a scene
    that keeps it refuses such a snapshot by the array's name."""
    from slidernet.errors import SnapshotError
    from slidernet.solver.snapshot import Snapshot

    def old_snapshot(observables: list[str]) -> tuple[Scene, Snapshot, Realization]:
        scene = Scene.from_config(load_config(_config({"kind": "chain", "n": 6}, observables=observables)))
        real = Realization(scene, np.random.SeedSequence(1))
        real.advance(3)
        snap = real.snapshot()
        arrays = {k: v for k, v in snap.arrays.items() if k != "backend/nodes/last_slip"}
        return scene, Snapshot(snap.header, arrays), real

    scene, snap, real = old_snapshot(["n"])
    again = Realization(scene, np.random.SeedSequence(1))
    again.restore(snap)
    real.advance(6)
    again.advance(6)
    assert np.array_equal(again.backend.nodes.u, real.backend.nodes.u)
    scene, snap, _ = old_snapshot(["n", "contact_age"])
    with pytest.raises(SnapshotError, match="last_slip"):
        Realization(scene, np.random.SeedSequence(1)).restore(snap)


def test_two_sliders_with_contact_age_run_on_the_network_kernel_and_the_pair_kernel_refuses_it() -> None:
    cfg = _config(NETWORKS["two_slider"])
    assert Scene.from_config(load_config(cfg)).kernel == "csr"
    with pytest.raises(ConfigError, match=r"'contact_age' observable .* needs a network kernel"):
        load_config({**cfg, "solver": {"kernel": "pair"}})


# The fixed age bins of contact_age_count: [0, 1e-6), 4 per decade to 1e9, [1e9, inf).
_EDGES = np.concatenate([[0.0], kernels.AGE_EDGES, [np.inf]])


@settings(max_examples=60, deadline=None)
@given(ages=st.lists(st.floats(0.0, 1e4, allow_subnormal=False), min_size=1, max_size=60),
       q=st.sampled_from([0.0, 0.1, 0.5, 0.9, 0.99, 1.0]) | st.floats(0.0, 1.0))
def test_binned_quantile_holds_numpy_s_quantile(ages: list[float], q: float) -> None:
    # The histogram of known ages on the fixed bins, and the exact quantile of the ages themselves.
    counts, _ = np.histogram(ages, bins=_EDGES)
    lo, hi = binned_quantile(counts, _EDGES[:-1], _EDGES[1:], q)
    exact = np.quantile(ages, q, method="inverted_cdf")
    assert lo <= exact < hi
    # The same bin as the exact value's, not merely one that holds it.
    assert lo == _EDGES[np.searchsorted(_EDGES, exact, side="right") - 1]


def test_binned_quantile_of_a_run_s_histogram_per_time() -> None:
    # 4 realizations x 6 nodes of a chain: every age at t is at most t, so the bin of the largest starts at
    # or below t; at t = 0 every age is 0, in the first bin [0, 1e-6).
    ds = slidernet.run(load_config(_config({"kind": "chain", "n": 6}, realizations=4)))
    count = ds["contact_age_count"]
    lo, hi = binned_quantile(count.values, ds["contact_age_bin"].values, ds["contact_age_upper"].values, 1.0)
    assert lo.shape == ds["t"].shape
    t = ds["t"].values
    assert (lo <= t).all() and (lo[0], hi[0]) == (0.0, 1e-6)
    # q = 0.5 never lies above q = 1.
    lo_half, _ = binned_quantile(count.values, ds["contact_age_bin"].values, ds["contact_age_upper"].values, 0.5)
    assert (lo_half <= lo).all()


def test_binned_quantile_of_an_empty_histogram_is_nan() -> None:
    lo, hi = binned_quantile([[0, 0], [1, 0]], [0.0, 1.0], [1.0, 2.0], 0.9)
    np.testing.assert_array_equal(lo, [np.nan, 0.0])
    np.testing.assert_array_equal(hi, [np.nan, 1.0])


@pytest.mark.parametrize(("q", "match"), [(1.5, r"'q' parameter of binned_quantile must be in \[0, 1\]"),
                                          (-0.1, r"must be in \[0, 1\]. Got -0.1"),
                                          (float("nan"), "'q' parameter of binned_quantile")],
                         ids=["above_1", "below_0", "nan"])
def test_binned_quantile_refuses_q_outside_0_1(q: float, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        binned_quantile([1, 2], [0.0, 1.0], [1.0, 2.0], q)


def test_binned_quantile_refuses_edges_that_do_not_fit_the_counts() -> None:
    with pytest.raises(ConfigError, match=r"binned_quantile needs counts of shape \(..., B\)"):
        binned_quantile([1, 2, 3], [0.0, 1.0], [1.0, 2.0], 0.5)
