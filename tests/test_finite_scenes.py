"""Scenes float64 cannot hold are refused before the run, naming the field (issue 43, points 5 and 6).

A triangular lattice with k = 1e308, or graph coordinates of +-1e308, gave overflow warnings, NaN unit
vectors, n = 0 and exit 0 (the same k on a chain was refused): every stiffness, rest length, unit vector
and thermal load of the assembled operators must be finite, and the precision check sees NaN as the
worst case. A 2D network at sigma_theta / Ntilde >= 1e7 ended in a ZeroDivisionError of the kernel.
"""

from __future__ import annotations

import math
import warnings

import networkx as nx
import numpy as np
import pytest

import slidernet
from slidernet.config import load_config
from slidernet.errors import ConfigError, PrecisionError
from slidernet.kernels.plane import _CANCELLATION, critical_thetas
from slidernet.solver import Realization, Scene, budget

from .conftest import make_config

NT = 1e-7


def _config(network: dict, **changes: object) -> dict:
    cfg = make_config(**{"realizations": 1, "steps": 20, "observables": ["n", "mu_max", "x_G"],
                         "driver.sigma_theta": NT, **changes})
    cfg["network"] = {"Ntilde": NT, **network}
    return cfg


# (id, network, pattern naming the cause)
OVERFLOWS = [
    ("triangular-k-1e308", {"kind": "triangular", "shape": [3, 3], "k": 1e308},
     r"the stiffness matrix K .*'network\.k'"),
    ("square-k-1e308", {"kind": "square", "shape": [3, 3], "k": 1e308}, r"the stiffness matrix K .*'network\.k'"),
    ("irregular-k-1e308", {"kind": "irregular", "n": 10, "k": 1e308}, r"the stiffness matrix K .*'network\.k'"),
    ("chain-k-kappa-1e200", {"kind": "chain", "n": 4, "k": 1e200, "kappa": 1e200},
     r"the thermal load g .*'network\.k', 'network\.kappa'"),
    ("triangular-k-kappa-1e200", {"kind": "triangular", "shape": [3, 3], "k": 1e200, "kappa": 1e200},
     r"the thermal load g .*'network\.k', 'network\.kappa'"),
    ("normal-load-1e308", {"kind": "triangular", "shape": [3, 3], "normal_load": 1e308},
     r"the normal loads .*'network\.normal_load'"),
]


@pytest.mark.parametrize(("network", "match"), [c[1:] for c in OVERFLOWS], ids=[c[0] for c in OVERFLOWS])
def test_operators_that_overflow_are_refused_naming_the_field(network, match):
    cfg = load_config(_config(network))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no raw numpy overflow warning before the refusal
        with pytest.raises(ConfigError, match=rf"^This network's operators overflow float64: {match}"):
            Scene.from_config(cfg)


def test_graph_coordinates_that_overflow_are_refused_naming_the_file(tmp_path):
    G = nx.Graph()
    G.add_node(0, x=-1e308, y=0.0)
    G.add_node(1, x=1e308, y=0.0)
    G.add_node(2, x=0.0, y=1.0)
    G.add_edges_from([(0, 1), (1, 2), (0, 2)])
    path = tmp_path / "far.graphml"
    nx.write_graphml(G, path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ConfigError, match=r"far\.graphml.: The sliders 0 and 1, joined by a spring, lie too "
                                              r"far apart, beyond float64"):
            slidernet.run(_config({"kind": "graph", "path": str(path)}))


def test_the_precision_check_sees_nan_as_the_worst_case():
    cfg = load_config(_config({"kind": "chain", "n": 4}))
    scene = Scene.from_config(cfg)
    found = budget.scales(cfg, scene)
    nan_load = budget.Scales(**{**found.__dict__, "load": np.array([1.0, math.nan, 1.0, 1.0])})
    with pytest.raises(PrecisionError, match=r"the cause: 'network\.k' \(thermal loads g = k L kappa up to nan\)"):
        budget.check_precision(cfg, scene, nan_load)
    nan_gap = budget.Scales(**{**found.__dict__, "gap": math.nan})
    with pytest.raises(PrecisionError, match=r"the cause: 'friction\.static' with 'friction\.mu_d'"):
        budget.check_precision(cfg, scene, nan_gap)


# --- the 2D kernel at sigma_theta / Ntilde >= 1e7 ---------------------------------------------------------------


@pytest.mark.parametrize(("network", "sigma_theta"), [
    pytest.param({"kind": "irregular", "n": 10}, 1.0, id="irregular-sigma-1-Ntilde-1e-7"),
    pytest.param({"kind": "square", "shape": [3, 3]}, 10.0, id="square-sigma-10"),
    pytest.param({"kind": "triangular", "shape": [3, 3]}, 10.0, id="triangular-sigma-10"),
])
def test_2d_networks_at_huge_sigma_theta_over_ntilde_slip_without_a_traceback(network, sigma_theta):
    # The scenes: about 5e8 slips per driven node and step (a run of hours, which the SlowRunWarning
    # announces), so the realization is stopped after its first ~100 refills of 4096 draws, ~4e5 slips.
    # allow_implausible: the unit slip of issue 46 (sigma_theta in kelvin), run on purpose
    cfg = load_config(_config(network, steps=2, **{"driver.sigma_theta": sigma_theta, "solver.batch": 4096,
                                                   "allow_implausible": True}))
    real = Realization(Scene.from_config(cfg), np.random.SeedSequence(0))
    polls = iter(range(100))
    real.advance(stop=lambda: next(polls, None) is None)
    assert real.n > 100_000
    assert np.isfinite(real.forces()).all() and np.isfinite(real.thresholds).all()


@pytest.mark.parametrize("scale", [1.0, 1e4, 1e7, 1e8, 1e9])
def test_critical_thetas_stay_roots_when_the_force_dwarfs_the_threshold(scale):
    # |a| ~ scale, g ~ 1, lim ~ 0.6: the roots lie near -a/g, at theta ~ scale. The quadratic's
    # discriminant B^2 - A C cancels catastrophically there (its terms ~ scale^2, its value ~ lim^2):
    # the roots must still put |a + g theta| at lim, to the rounding of the terms (eps * scale), and below
    # the switch to Lagrange's identity (kernels.plane._CANCELLATION) to what the first form keeps.
    rng = np.random.default_rng(7)
    for _ in range(200):
        gx, gy = rng.normal(size=2)
        theta0 = scale * rng.normal()
        lim = 0.6
        # a force that passes within lim of the origin as theta moves: a = -g theta0 + a perpendicular offset
        off = 0.9 * lim * rng.uniform(-1.0, 1.0)
        norm = math.hypot(gx, gy)
        ax, ay = -gx * theta0 - gy / norm * off, -gy * theta0 + gx / norm * off
        dn, up = critical_thetas(ax, ay, gx, gy, lim)
        assert dn <= up
        for root in (dn, up):
            F = math.hypot(ax + gx * root, ay + gy * root)
            eps = np.finfo(float).eps
            assert abs(F - lim) <= _CANCELLATION * eps * lim + 8 * eps * (abs(ax) + abs(ay) + 1.0), (scale, F)
