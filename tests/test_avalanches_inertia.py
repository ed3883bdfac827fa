"""benchmarks/avalanches_inertia.py: the avalanche sizes of the quasi-static and inertial solvers on tiny scenes.

Exact facts only: the inertial avalanches' starts add up to the slips; on the pair at tau_dyn / tau_th =
1e-12, where tests/test_inertia.py shows slip-for-slip agreement with the quasi-static solver, the sizes are
the quasi-static ones avalanche for avalanche; the exponent's estimator recovers a known exponent.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from slidernet.ensemble.runner import realization_seeds


def _load_benchmark() -> ModuleType:
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "avalanches_inertia.py"
    spec = importlib.util.spec_from_file_location("slidernet_bench_avalanches_inertia", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


av = _load_benchmark()


@pytest.mark.parametrize("network", [{"kind": "irregular", "n": 16, "seed": 0}, {"kind": "chain", "n": 8}],
                         ids=["irregular-16", "chain-8"])
def test_starts_add_up_to_the_slips(network: dict) -> None:
    """Every start ends as one slip: the sizes of the finished avalanches and the unfinished motion's starts
    add up to the run's slips (irregular 16: 2D solver's ``starts``; chain of 8: 1D solver's ``slips``)."""
    sigma = 3.0 if network["kind"] == "chain" else 0.3  # a uniform chain is driven at its ends only
    sc = av.make_scene(0, sigma=sigma, ratio=0.3, steps=2, network=network)
    seed = realization_seeds(1, 1)[0]
    out = av.inertial_avalanches(sc, 1e-4, seed, skip=0.0)
    assert out["total_slips"] > 20
    assert out["total_starts"] == out["total_slips"]
    assert out["sizes"].sum() + out["unfinished"] == out["total_slips"]
    assert out["slips"] == out["total_slips"]  # skip = 0: every slip is in the window


def test_pair_sizes_are_the_quasi_static_ones_avalanche_for_avalanche() -> None:
    """The pair at tau_dyn / tau_th = 1e-12 (test_inertia's quasi-static limit): the same avalanches, the same
    sizes, in the same order; and no driving event merges into another's motion.

    Every avalanche of the pair is one slip (a slip relaxes the one spring, so the other slider's force falls
    too), so the fact checked is the grouping: 1226 driving events, 1226 motions from rest to rest.
    """
    sc = av.make_scene(0, sigma=10.0, ratio=0.1, steps=20, network={"kind": "two_slider"})
    seed = realization_seeds(3, 1)[0]
    qs = av.qs_avalanches(sc, seed, skip=0.0)
    inertial = av.inertial_avalanches(sc, 1e-12, seed, skip=0.0)
    assert qs["sizes"].size > 1000
    np.testing.assert_array_equal(inertial["sizes"], qs["sizes"])
    assert inertial["unfinished"] == 0 and inertial["gaps_below_tau_dyn"] == 0


def test_exponent_and_its_error_over_realizations() -> None:
    """Sizes drawn from S^-1.5 on [1, 1000]: the pooled MLE within 3 jackknife errors of 1.5, and the
    densities normalized (sum of P(S) times the bin widths is 1 in every realization)."""
    rng = np.random.default_rng(7)
    s = np.arange(1, 1001)
    p = s ** -1.5
    sizes = [rng.choice(s, 5000, p=p / p.sum()) for _ in range(6)]
    tau_s, sem = av.exponent(sizes, 1, 1000)
    assert 0 < sem < 0.05
    assert abs(tau_s - 1.5) < 3 * sem
    edges = av.log2_edges(1000)
    per = np.array([np.histogram(x, edges)[0] / x.size for x in sizes])
    assert per.sum(axis=1) == pytest.approx(1.0)
    density, density_sem = av.densities(sizes, edges)
    assert (density * np.diff(edges)).sum() == pytest.approx(1.0)
    assert density_sem.shape == density.shape


def test_a_realization_without_avalanches_has_no_density() -> None:
    """A realization in which no motion ended (the network moved to the end) is left out of P(S): the mean
    density over the others stays normalized, instead of falling to (non-empty) / (all) of it."""
    edges = av.log2_edges(8)
    sizes = [np.array([1, 1, 2, 5]), np.array([], dtype=np.int64), np.array([1, 3, 8])]
    density, density_sem = av.densities(sizes, edges)
    assert (density * np.diff(edges)).sum() == pytest.approx(1.0)
    assert np.isfinite(density_sem).all()
    assert np.isnan(av.densities([np.array([], dtype=np.int64)], edges)[0]).all()
