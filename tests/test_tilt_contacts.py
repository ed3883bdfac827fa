"""The contacts' own loads in the network tilt test (issue 44, item 3): ``tilt_contact_mean``,
``tilt_half_broken`` and ``tilt_break_ratio``.

A contact breaks at its node's first slip of the test; one still intact when the test ends breaks at the end
(under the sliding rule it is unstable there). The three readings: the mean load f + f_bar at which the contacts
broke, the load at which half of the normal load had broken, and the mean local ratio |F_i| / N_i under which
they broke (all weighted by N_i).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import slidernet
from slidernet import kernels
from slidernet.config import load_config
from slidernet.kernels.tilt_net import L_CONTACTS, L_FIRST, L_HALF, L_RATIO, N_LOADS, N_POS, TILT_LOADS
from slidernet.solver import Realization, Scene

from .conftest import make_config


def _tilt_loads(network: dict[str, Any], G: np.ndarray, mu: list[float], redraws: list[float],
                *, shs: bool = False) -> tuple[float, np.ndarray]:
    """The compiled network tilt test (or, with ``shs``, the slide-hold-slide pull) from forces G, shape (N, 2),
    and thresholds mu at mu_d = 0.5, e = 1: its sample and its ``loads``."""
    cfg = make_config(steps=4, network={"Ntilde": 1e-7, **network}, mu_eff_at="records",
                      observables=["n", "mu_eff", "mu_shs"] if shs else ["n", "mu_eff"],
                      friction={"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}})
    scene = Scene.from_config(load_config(cfg))
    N = scene.network.n_nodes
    o = scene.shs_operators() if shs else scene.tilt_operators()
    settings = kernels.Settings(mu_d=0.5, max_slips=10**6, recompute_every=0, slip_factor=2.0)
    loads = np.zeros(N_LOADS)
    work = (np.zeros(N_POS, np.int64),)
    args = (np.array(G, float), np.array(mu, float), o.f_ext, o.f_bar, o.net, settings)
    heaps, epoch, count = kernels.Heaps.empty(2, N), np.zeros(N, np.int64), np.zeros(N, np.int64)
    if shs:
        f = o.test(*args, np.asarray(redraws, float), *work, heaps, epoch, count, loads, o.pull)
    else:
        f = o.test(*args, o.pair_rule, np.asarray(redraws, float), np.full(4, 0.5), *work, 10**5, heaps, epoch,
                   count, loads)
    return float(f), loads


def test_two_sliders_break_at_their_own_thresholds_one_after_the_other():
    # Dyadic numbers, exact in float64. Springs at rest, mu = (0.5625, 0.75), k = 1, e = 1, redraw 0.875.
    # Slider 0 breaks at f = 0.5625 under a force of 0.5625 and slips by 0.125: slider 1 feels 0.125 + f and
    # breaks at f = 0.625 under 0.75, its threshold; its slip pushes slider 0 to 1.0 > 0.875: the sample, 0.625.
    f, loads = _tilt_loads({"kind": "chain", "n": 2}, np.zeros((2, 2)), [0.5625, 0.75], [0.875, 0.875])
    assert f == 0.625
    assert loads[L_FIRST] == 0.5625
    assert loads[L_HALF] == 0.5625  # one contact of two is half of the normal load
    assert loads[L_CONTACTS] == (0.5625 + 0.625) / 2
    assert loads[L_RATIO] == (0.5625 + 0.75) / 2  # both broke at their thresholds (driving slips)


def test_a_contact_intact_at_the_sample_breaks_there_under_its_force_then():
    # A free chain of 3, springs at rest, mu_s = 0.625 everywhere, redraws 0.9. At f = 0.625 slider 0 breaks
    # (force 0.625) and slips by 2 (0.125) / 1 = 0.25; slider 1 (K_11 = 2) then feels 0.875, breaks and slips
    # by 2 (0.875 - 0.5) / 2 = 0.375; slider 2 feels 0.375 + 0.625 = 1.0 > 0.625: every node in motion at
    # f > mu_d, the sample 0.625, with slider 2 unstable and never slipped: it breaks at 0.625 under 1.0.
    f, loads = _tilt_loads({"kind": "chain", "n": 3}, np.zeros((3, 2)), [0.625] * 3, [0.9, 0.9])
    assert f == 0.625
    assert loads[L_CONTACTS] == 0.625 and loads[L_HALF] == 0.625
    assert loads[L_RATIO] == pytest.approx((0.625 + 0.875 + 1.0) / 3, rel=0, abs=1e-15)


def test_a_pull_reads_no_contacts():
    _, loads = _tilt_loads({"kind": "chain", "n": 2}, np.zeros((2, 2)), [0.5625, 0.75], [0.875], shs=True)
    assert math.isnan(loads[L_CONTACTS]) and math.isnan(loads[L_HALF]) and math.isnan(loads[L_RATIO])


SCENES = {
    "pair": {"kind": "two_slider"},
    "chain-9": {"kind": "chain", "n": 9},
    "irregular-12": {"kind": "irregular", "n": 12},
    "triangular-3x4": {"kind": "triangular", "shape": [3, 4]},
    "graph-loads": "graph",  # a 2D graph whose nodes carry unequal normal loads: the weights N_i
}


def _graph(tmp_path: Path) -> dict[str, Any]:
    (tmp_path / "loads.edgelist").write_text("0 1\n1 2\n2 0\n2 3\n3 4\n4 2\n0 4\n", encoding="utf-8")
    (tmp_path / "loads.nodes.csv").write_text(
        "node,x,y,normal_load\n0,0,0,1.0\n1,1,0,2.0\n2,0.5,0.8,0.5\n3,1.5,1,1.5\n4,-0.5,1,1.0\n",
        encoding="utf-8")
    return {"kind": "graph", "path": str(tmp_path / "loads.edgelist")}


@pytest.mark.parametrize("overshoot", [1.0, 0.0], ids=["e1", "e0"])
@pytest.mark.parametrize("network", list(SCENES.values()), ids=list(SCENES))
def test_the_readings_lie_between_the_first_slip_and_the_sample_and_the_ratio_above_the_thresholds(network,
                                                                                                   overshoot,
                                                                                                   tmp_path):
    # f only rises in a test, so every contact breaks between the first slip and the sample; under the sliding
    # rule every contact breaks at or above its own threshold (a driving slip at it, a pushed or unstable node
    # above it), so the mean ratio is at least the N_i-weighted mean of the tested thresholds.
    network = _graph(tmp_path) if network == "graph" else network
    cfg = make_config(steps=200, record="all", network={**network, "Ntilde": 1e-7}, mu_eff_at="records",
                      observables=["n", "mu_eff", "mu_eff_realization", "tilt_loads"],
                      **{"driver.sigma_theta": 1e-6, "friction.overshoot": overshoot})
    real = Realization(Scene.from_config(load_config(cfg)), np.random.SeedSequence(11))
    w = real.scene.network.normal_load / real.scene.network.normal_load.sum()
    assert (np.ptp(w) > 0) == (network.get("kind") == "graph")  # the graph's weights are unequal
    out = real.out
    for k, t in enumerate(real.scene.out_steps):
        real.advance(int(t))
        floor = float(w @ real.tested_thresholds(k, False))
        sample = out["f_sum"][k]  # one test per record
        assert out["f_count"][k] == 1
        assert out["tilt_first_slip"][k] <= out["tilt_half_broken"][k] <= sample
        assert out["tilt_first_slip"][k] <= out["tilt_contact_mean"][k] <= sample
        assert out["tilt_break_ratio"][k] >= floor - 1e-12
    assert real.n > 50


def test_the_readings_are_in_the_dataset_with_their_twins_and_attributes():
    cfg = make_config(realizations=2, steps=30, record="log", log_points_per_decade=3,
                      network={"kind": "chain", "n": 5, "Ntilde": 1e-7}, mu_eff_at="records",
                      observables=["n", "mu_eff", "tilt_loads"], tilt={"inject": {"c": 0.01}},
                      **{"driver.sigma_theta": 1e-6})
    ds = slidernet.run(cfg)
    for name in TILT_LOADS:
        for var in (name, name + "_injected"):
            assert ds[var].dims == ("realization", "t") and np.isfinite(ds[var].values).all()
            assert ds[var].attrs["units"] == "1" and ds[var].attrs["long_name"]
        assert ds[name + "_injected"].attrs["inject_c"] == 0.01
