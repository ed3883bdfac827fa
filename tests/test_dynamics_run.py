"""``[dynamics]``: the inertial solver from a configuration, through slidernet.run and Realization.

The compiled kernels are checked against the reference integrator in
tests/test_inertia.py and tests/test_inertia_2d.py; here, that the run of a
configuration gives exactly what the standalone solvers give on the same
seeds, that the observables read from their logs count what they should,
and that a realization stopped, saved and resumed gives the same bits.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import slidernet
from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.errors import ConfigError
from slidernet.io.checkpoint import load_realization, save_realization
from slidernet.solver import Realization, Scene
from slidernet.solver.inertia import InertialSolver
from slidernet.solver.inertia_2d import Inertia2D
from slidernet.solver.inertia_backends import log2_bins
from slidernet.solver.streams import horizontal_draws, realization_streams

NETWORKS = {
    "pair": {"kind": "two_slider", "Ntilde": 1e-7},
    "chain6": {"kind": "chain", "n": 6, "Ntilde": 1e-7},
    "triangular3x3": {"kind": "triangular", "shape": [3, 3], "Ntilde": 1e-7},
    "irregular16": {"kind": "irregular", "n": 16, "Ntilde": 1e-7, "seed": 2},
}


def config(network: str, steps: int = 12, **more) -> dict:
    # Ratio sigma_mu / (mu_s - mu_d) = 0.3, the aging study's: thresholds a hair above mu_d are drawn.
    return {"seed": 5, "realizations": 2, "steps": steps, "record": "all", "network": NETWORKS[network],
            "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.03}},
            "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}, "dynamics": {"tau_ratio": 1e-3},
            "execution": {"workers": 1}, **more}


def standalone(scene: Scene, seed_seq: np.random.SeedSequence) -> dict:
    solver = InertialSolver(scene, 1e-3) if scene.network.dim == 1 else Inertia2D(scene, 1e-3)
    return solver.run(seed_seq)


@pytest.mark.parametrize("bad, match", [
    ({"solver": {"kernel": "csr"}}, "'solver.kernel' names a quasi-static kernel"),
    ({"solver": {"slip": "exact"}}, "'solver.slip' chooses the quasi-static 2D slip"),
    ({"friction": {"mu_d": 0.5, "overshoot": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.03}}},
     "'friction.overshoot' sets a quasi-static slip's length"),
    ({"observables": ["n", "creep"]}, "the 'creep' observable is not recorded with inertia"),
    ({"observables": ["n", "mu_shs"]}, "the 'mu_shs' observable is not recorded with inertia"),
    ({"observables": ["n", "mu_eff"], "mu_eff_at": "rearrangements"}, "needs the quasi-static pair kernel"),
    ({"dynamics": {"tau_ratio": 0.0}}, r"'dynamics.tau_ratio' field must be > 0"),
    ({"dynamics": {"tau_ratio": math.inf}}, r"'dynamics.tau_ratio'"),
    ({"dynamics": {"tau_ratio": 1e-3, "rtol": 0.1}}, r"'dynamics.rtol' field must be <= 0.001"),
    ({"dynamics": {"tau_ratio": 1e-3, "tau": 1}}, r"Unknown key 'tau' in \[dynamics\]"),
], ids=["kernel", "slip", "overshoot", "creep", "shs", "appendix-tilt", "tau-zero", "tau-inf", "rtol",
        "unknown-key"])
@pytest.mark.parametrize("network", ["pair", "chain6"])
def test_what_the_inertial_solver_does_not_model_is_refused(bad, match, network):
    with pytest.raises(ConfigError, match=match):
        load_config({**config(network), **bad})


def test_a_network_that_would_slide_away_is_refused():
    cfg = load_config({**config("chain6"), "network": {**NETWORKS["chain6"], "incline": 30.0}})
    with pytest.raises(ConfigError, match=r"must not exceed mu_d = 0\.5"):
        Scene.from_config(cfg)


@pytest.mark.parametrize("network", list(NETWORKS))
def test_a_run_gives_the_standalone_solvers_records_bit_for_bit(network):
    cfg = config(network, observables=["n", "mu_max", "x_G", "n_records", "events"])
    ds = slidernet.run(cfg, progress=False)
    scene = Scene.from_config(load_config(cfg))
    assert scene.kernel == ("inertia" if scene.network.dim == 1 else "inertia_2d")
    for r, ss in enumerate(realization_seeds(cfg["seed"], cfg["realizations"])):
        out = standalone(scene, ss)
        np.testing.assert_array_equal(ds["n"].values[r], out["n"])
        np.testing.assert_array_equal(ds["mu_max"].values[r], out["mu_max"])
        np.testing.assert_array_equal(ds["x_G"].values[r], out["x_G"])
        # Every slip logged once: the catalogue, the counts per node, the avalanches' sizes.
        nodes = out["slips"]["node"]
        assert int(ds["node_slips"].values[r].sum()) == nodes.size
        np.testing.assert_array_equal(ds["node_slips"].values[r],
                                      np.bincount(nodes, minlength=scene.network.n_nodes))
        av = out["avalanches"]
        sizes = av["starts"] if "starts" in av else np.diff(av["slips"], prepend=0)
        bins = ds.sizes["avalanche_size"]  # the result keeps the bins up to the highest occupied one
        np.testing.assert_array_equal(ds["avalanche_count"].values[r], log2_bins(sizes)[:bins])
        assert not log2_bins(sizes)[bins:].any()


@pytest.mark.parametrize("network", ["chain6", "irregular16"])
def test_n_records_counts_the_draws_above_the_running_mu_max(network):
    """A replay in Python of the quasi-static rule over the standalone solver's stops, in their order."""
    cfg = config(network, observables=["n", "n_records"])
    ds = slidernet.run(cfg, progress=False)
    scene = Scene.from_config(load_config(cfg))
    for r, ss in enumerate(realization_seeds(cfg["seed"], cfg["realizations"])):
        out = standalone(scene, ss)
        _, mu, batches = horizontal_draws(scene, realization_streams(ss))
        nodes = out["slips"]["node"]
        draws = np.concatenate([next(batches) for _ in range(nodes.size // scene.batch + 1)])
        count = 0
        for k, i in enumerate(nodes):
            count += draws[k] > mu.max()
            mu[i] = draws[k]
        assert count > 0
        assert int(ds["n_records"].values[r, -1]) == count


@pytest.mark.parametrize("network", ["pair", "triangular3x3"])
def test_a_realization_stopped_saved_and_resumed_gives_the_same_bits(network, tmp_path):
    cfg = load_config(config(network, observables=["n", "mu_max", "x_G", "mu_eff", "tilt_loads", "contact_age",
                                                    "events"], mu_eff_at="records", solver={"batch": 4}))
    scene = Scene.from_config(cfg)
    ss = realization_seeds(5, 1)[0]
    refills = 0

    def count() -> bool:  # asked at every refill of the 4 draws
        nonlocal refills
        refills += 1
        return False

    whole = Realization(scene, ss).advance(stop=count).result()
    real = Realization(scene, ss)
    calls = 0

    def stop() -> bool:  # half-way through the refills, within a thermal step or between two
        nonlocal calls
        calls += 1
        return calls == refills // 2

    real.advance(stop=stop)
    assert refills >= 10 and real.step < scene.steps
    path = save_realization(real, tmp_path / "r.npz", {"run": "test"})
    resumed = load_realization(scene, ss, path, expect_meta={"run": "test"}).advance().result()
    assert set(resumed) == set(whole)
    for name, value in whole.items():
        if isinstance(value, dict):
            for key in value:
                np.testing.assert_array_equal(resumed[name][key], value[key], err_msg=f"{name}.{key}")
        else:
            np.testing.assert_array_equal(resumed[name], value, err_msg=name)


def test_the_tilt_test_reads_the_dynamic_state_at_every_record():
    ds = slidernet.run(config("irregular16", steps=6, observables=["n", "mu_eff", "mu_eff_realization",
                                                                    "tilt_loads"], mu_eff_at="records"),
                       progress=False)
    assert (ds["mu_eff_count"].values == 2).all()
    ratio = ds["tilt_break_ratio"].values
    assert np.isfinite(ratio).all() and (ratio > 0.5).all()
    assert ds.attrs["kernel"] == "inertia_2d"
    assert "on the state of the equations of motion" in ds.attrs["mu_eff_estimator"]


def test_the_result_names_the_dynamic_tilt_test_where_it_ran():
    ds = slidernet.run(config("pair", steps=3, observables=["n", "mu_eff"], mu_eff_at="records",
                              dynamics={"tau_ratio": 1e-3, "tilt_rate": 1e-3}), progress=False)
    assert ds.attrs["mu_eff_estimator"].startswith(
        "the dynamic tilt test (a uniform tilt ramped at 0.001 per tau_dyn")
