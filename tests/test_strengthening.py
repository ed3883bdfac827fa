"""friction.strengthening: thresholds that grow with the age of their contact, resolved exactly.

The hand cases: a stuck contact ages exactly as the law; beta = 0 gives the bits of a run without the
option; two sliders under a ramp slip when the weaker of their strengthened thresholds is reached (the
time solved here by scipy's brentq); a chain and a 2D network follow, event for event, an independent
search written here (scipy's brentq on every node, every step; no driving trees, no lazy bounds).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from scipy.optimize import brentq

import slidernet
from slidernet.config import load_config
from slidernet.errors import ConfigError
from slidernet.solver import Realization, Scene
from slidernet.validation.dynamics import realization_draws

from .conftest import make_config

LOG = {"beta": 0.005, "tau_c": 1e-3}
POWER = {"law": "power", "beta": 0.002, "tau_c": 1e-2, "exponent": 0.3}
LAWS = {"log": LOG, "power": POWER}


def law(spec: dict[str, Any], age: np.ndarray | float) -> np.ndarray | float:
    """beta L(age / tau_c), written from the configuration reference."""
    x = np.asarray(age, dtype=float) / spec["tau_c"]
    if spec.get("law", "log") == "log":
        return spec["beta"] * np.log1p(x)
    return spec["beta"] * ((1.0 + x) ** spec["exponent"] - 1.0)


def _config(network: dict[str, Any], strengthening: dict[str, Any] | None, **changes: Any) -> dict[str, Any]:
    return make_config(**{"realizations": 2, "steps": 30, "record": "all",
                          "observables": ["n", "mu_max", "x_G", "contact_age"],
                          "network": {**network, "Ntilde": 1e-7}, "friction.strengthening": strengthening,
                          **changes})


NETWORKS = {
    "two_slider": {"kind": "two_slider"},
    "chain": {"kind": "chain", "n": 6},
    "triangular": {"kind": "triangular", "shape": [4, 4]},
    "irregular": {"kind": "irregular", "n": 16},
}


@pytest.mark.parametrize("kind", NETWORKS, ids=list(NETWORKS))
@pytest.mark.parametrize("name", LAWS, ids=list(LAWS))
def test_a_stuck_contact_ages_exactly_as_the_law(kind: str, name: str) -> None:
    # theta stands still: nothing slips, every threshold is its draw plus the law of t.
    cfg = _config(NETWORKS[kind], LAWS[name], record=[0, 1, 3, 10, 30],
                  driver={"name": "constant", "theta0": 0.0})
    cfg["observables"] = ["n", "mu_max", "contact_age"]
    ds = slidernet.run(cfg)
    assert int(ds["n"].max()) == 0
    t = ds["t"].values.astype(float)
    np.testing.assert_array_equal(ds["contact_age"].values, np.broadcast_to(t, ds["contact_age"].shape))
    grown = ds["mu_max"].values - ds["mu_max"].values[:, :1]
    np.testing.assert_allclose(grown, np.broadcast_to(law(LAWS[name], t), grown.shape), rtol=1e-12, atol=1e-15)
    if "mu_mean" in ds:
        np.testing.assert_allclose(ds["mu_mean"].values - ds["mu_mean"].values[:, :1], grown, atol=1e-14)


@pytest.mark.parametrize(
    ("kind", "changes"),
    [("two_slider", {}), ("chain", {}), ("chain", {"friction.overshoot": 0.3}), ("triangular", {}),
     ("irregular", {}), ("irregular", {"solver.slip": "exact"}),
     ("irregular", {"observables": ["n", "mu_max", "x_G", "mu_eff"], "mu_eff_at": "records", "record": "log"})],
    ids=["pair-on-csr", "chain", "chain-overshoot", "triangular", "irregular", "irregular-exact-slip",
         "irregular-mu_eff"],
)
def test_beta_zero_gives_the_bits_without_the_option(kind: str, changes: dict[str, Any]) -> None:
    # The strengthened search runs (a two-slider scene goes to the csr kernel in both) and adds 0.0.
    base = {**changes, "solver.kernel": "csr" if kind == "two_slider" else "auto"}
    off = slidernet.run(_config(NETWORKS[kind], None, **base))
    on = slidernet.run(_config(NETWORKS[kind], {"beta": 0.0, "tau_c": 1e-3}, **base))
    assert int(off["n"].max()) > 0
    for name in off.data_vars:
        np.testing.assert_array_equal(on[name].values, off[name].values, err_msg=name)


def test_two_sliders_slip_when_the_weaker_strengthened_threshold_is_reached() -> None:
    rate = 0.02  # theta / Ntilde per tau_th: the force reaches mu_s ~ 0.6 after ~30 tau_th of strengthening
    cfg = _config(NETWORKS["two_slider"], LOG, steps=60, record=[0, 60],
                  driver={"name": "ramp", "rate": rate * 1e-7}, observables=["n", "events"])
    scene = Scene.from_config(load_config(cfg))
    real = Realization(scene, np.random.SeedSequence(3))
    mu0 = real.mu.copy()
    g = abs(float(scene.operators.g[0]))
    real.advance()
    events = real.events()
    assert events["time"].size > 0
    # Before the first slip the spring's force is g theta(t) on both, and each threshold mu0_i + law(t).
    first = min(brentq(lambda t, m=m: g * rate * t - (m + law(LOG, t)), 0.0, 60.0, xtol=1e-14, rtol=1e-15)
                for m in mu0)
    weaker = int(np.argmin([brentq(lambda t, m=m: g * rate * t - (m + law(LOG, t)), 0.0, 60.0) for m in mu0]))
    assert events["node"][0] == weaker
    assert events["time"][0] == pytest.approx(first, rel=1e-12)
    # Without strengthening it would have slipped at mu0 / (g rate): strengthening delayed it.
    assert first > mu0.min() / (g * rate) + 1.0


def reference_events(scene: Scene, seed: int, spec: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An independent event search: every node's first threshold crossing in each step by brentq.

    Straight-line slips of (1 + e)(|F| - mu_d N) / k_eff along F (k_eff = e^T K_ii e; 1D: K_ii), avalanches
    largest overload first (ties to the lowest node), thresholds from the solver's stream in its order.
    Returns the slipping nodes, their times (tau_th) and the final displacements.
    """
    thetas, stream = realization_draws(scene, np.random.SeedSequence(seed))
    net = scene.network
    N, d = net.n_nodes, net.dim
    K = scene.K.toarray()
    g = np.asarray(scene.operators.g, dtype=float).reshape(N, d)
    load = np.asarray(net.normal_load, dtype=float)
    mu0 = stream.initial.copy()
    last = np.zeros(N)
    u = np.zeros((N, d))
    sf = scene.slip_factor

    def force(theta: float) -> np.ndarray:
        return -(K @ u.ravel()).reshape(N, d) + g * (theta - thetas[0])

    def limit(j: int, t: float) -> float:
        return (mu0[j] + law(spec, t - last[j])) * load[j]

    def slip(j: int, t: float, theta: float) -> None:
        F = force(theta)[j]
        norm = float(np.linalg.norm(F))
        e = F / norm
        block = K[j * d:(j + 1) * d, j * d:(j + 1) * d]
        u[j] += sf * (norm - scene.mu_d * load[j]) / float(e @ block @ e) * e
        last[j] = t
        mu0[j] = stream.next()
        nodes.append(j)
        times.append(t)

    def gap(t: float, j: int, q: int) -> float:
        """mu_s,j(t) N_j - |F_j(theta(t))| in step q, theta linear in t."""
        theta = thetas[q] + (thetas[q + 1] - thetas[q]) * (t - q)
        return limit(j, t) - float(np.linalg.norm(force(theta)[j]))

    nodes: list[int] = []
    times: list[float] = []
    for q in range(scene.steps):
        t0 = float(q)
        while thetas[q] != thetas[q + 1]:
            found = [(brentq(gap, t0, q + 1.0, args=(j, q), xtol=1e-15, rtol=1e-15), j)
                     for j in range(N) if gap(q + 1.0, j, q) < 0.0 and gap(t0, j, q) > 0.0]
            if not found:
                break
            t0, j = min(found)
            theta = thetas[q] + (thetas[q + 1] - thetas[q]) * (t0 - q)
            slip(j, t0, theta)
            while True:
                over = [float(np.linalg.norm(force(theta)[i])) / limit(i, t0) for i in range(N)]
                i = int(np.argmax(over))
                if over[i] <= 1.0:
                    break
                slip(i, t0, theta)
    return np.array(nodes), np.array(times), u


# sigma_theta / Ntilde = 1. The two searches round differently in the last bits, and on the irregular
# network (17 slips per node per tau_th) such differences grow by a factor ~10 every ~100 slips, with or
# without strengthening (beta = 0 alike): 3 steps (739 and 856 slips) keep them below 1e-12.
@pytest.mark.parametrize(("kind", "steps"), [("chain", 30), ("irregular", 3)], ids=["chain-of-6", "irregular-16"])
@pytest.mark.parametrize("name", LAWS, ids=list(LAWS))
def test_the_kernel_follows_an_independent_event_search(kind: str, steps: int, name: str) -> None:
    spec = LAWS[name]
    cfg = _config(NETWORKS[kind], spec, steps=steps, observables=["n", "events"], record=[0, steps],
                  **{"driver.sigma_theta": 1e-7})
    scene = Scene.from_config(load_config(cfg))
    real = Realization(scene, np.random.SeedSequence(11)).advance()
    got = real.events()
    nodes, times, u = reference_events(scene, 11, spec)
    assert nodes.size > 200  # renewals and strengthening both at work
    np.testing.assert_array_equal(got["node"], nodes)
    np.testing.assert_allclose(got["time"], times, rtol=1e-9, atol=1e-12)
    # Sums of hundreds of slips of ~0.2 Ntilde l0, their last-bit differences grown as the times' are.
    np.testing.assert_allclose(real.displacements() / scene.network.Ntilde, u, rtol=0.0, atol=1e-7)


def test_strengthening_changes_the_run_and_resumes_to_the_same_bits() -> None:
    cfg = _config(NETWORKS["irregular"], LOG, steps=40)
    scene = Scene.from_config(load_config(cfg))
    whole = Realization(scene, np.random.SeedSequence(5)).advance()
    half = Realization(scene, np.random.SeedSequence(5)).advance(17)
    again = Realization(scene, np.random.SeedSequence(5))
    again.restore(half.snapshot())
    again.advance()
    np.testing.assert_array_equal(again.thresholds, whole.thresholds)
    np.testing.assert_array_equal(again.displacements(), whole.displacements())
    for name, values in whole.out.items():
        np.testing.assert_array_equal(again.out[name], values, err_msg=name)
    plain = Realization(Scene.from_config(load_config(_config(NETWORKS["irregular"], None, steps=40))),
                        np.random.SeedSequence(5)).advance()
    assert not np.array_equal(plain.out["n"], whole.out["n"])


@pytest.mark.parametrize(
    ("table", "changes", "match"),
    [({"beta": -0.01, "tau_c": 1e-3}, {}, r"friction\.strengthening\.beta"),
     ({"beta": 0.01, "tau_c": 0.0}, {}, r"friction\.strengthening\.tau_c"),
     ({"beta": 0.01}, {}, r"friction\.strengthening\.tau_c"),
     ({"beta": math.inf, "tau_c": 1.0}, {}, r"friction\.strengthening\.beta"),
     ({"law": "power", "beta": 0.01, "tau_c": 1.0}, {}, "needs an 'exponent'"),
     ({"law": "power", "beta": 0.01, "tau_c": 1.0, "exponent": 1.5}, {}, r"friction\.strengthening\.exponent"),
     ({"beta": 0.01, "tau_c": 1.0, "exponent": 0.5}, {}, "the 'log' law has none"),
     ({"law": "linear", "beta": 0.01, "tau_c": 1.0}, {}, r"friction\.strengthening\.law"),
     ({"beta": 0.01, "tau_c": 1.0}, {"mu_eff_at": "rearrangements", "observables": ["n", "mu_eff"]},
      "thresholds that do not age"),
     ({"beta": 0.01, "tau_c": 1.0}, {"solver.kernel": "pair"}, "needs a network kernel")],
    ids=["beta<0", "tau_c=0", "no-tau_c", "beta-inf", "power-no-exponent", "exponent>1", "log-exponent",
         "unknown-law", "appendix-test", "pair-kernel"],
)
def test_bad_strengthening_is_refused_by_name(table: dict[str, Any], changes: dict[str, Any], match: str) -> None:
    cfg = make_config(**{"steps": 10, "friction.strengthening": table, **changes})
    with pytest.raises(ConfigError, match=match):
        load_config(cfg)


def test_a_pair_with_strengthening_measures_mu_eff_at_the_records() -> None:
    cfg = make_config(**{"realizations": 2, "steps": 10, "friction.strengthening": LOG})
    resolved = load_config(cfg)
    scene = Scene.from_config(resolved)
    assert (scene.kernel, scene.tilt_at) == ("csr", "records")


# Issue 43: tau_c = 5e-324 made a / tau_c overflow to inf: mu_max = inf, exit 0. A law whose growth over the
# run leaves float64, or passes the bound on every threshold (config.plugins.MU_S_MAX), is refused by name.
@pytest.mark.parametrize(
    ("table", "grows"),
    [({"beta": 0.01, "tau_c": 5e-324}, "inf"),
     ({"law": "power", "beta": 1.0, "tau_c": 1e-200, "exponent": 1.0}, r"1e\+201"),
     ({"beta": 1e300, "tau_c": 1.0}, r"2\.4e\+300")],
    ids=["log-tau_c-5e-324", "power-beyond-1e150", "beta-1e300"])
def test_a_law_that_overflows_over_the_run_is_refused_by_name(table: dict[str, Any], grows: str) -> None:
    cfg = make_config(**{"steps": 10, "friction.strengthening": table})
    with pytest.raises(ConfigError, match=r"'friction\.strengthening' .*over the run's 10 steps .*grows by "
                                          rf"beta L\(steps / tau_c\) = {grows}.*1e\+150"):
        load_config(cfg)


def test_a_tiny_tau_c_within_float64_runs_with_finite_thresholds() -> None:
    # allow_implausible: tau_c = 1e-300 tau_th is far below any real aging cutoff (float64's limit is the point)
    cfg = _config(NETWORKS["chain"], {"beta": 0.01, "tau_c": 1e-300}, steps=5, realizations=1,
                  allow_implausible=True)
    ds = slidernet.run(cfg)
    assert np.isfinite(ds["mu_max"].values).all()
    assert float(ds["mu_max"].max()) < 0.6 + 0.01 * math.log1p(5 / 1e-300) + 0.1
