"""Injected aging (``[tilt] inject``) and several tilt tests per record (``[tilt] repeats``), issue 44.

``inject`` tests, beside each network tilt test at a recorded time, a twin on the same state with the
same draws whose thresholds are raised by c ln(1 + t / t0) (every contact, or the oldest share
``select``): a positive control of the estimator. ``repeats = K`` makes K independent tests per record.
Neither changes anything a run without them records.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.config import InjectConfig, load_config
from slidernet.ensemble.sweep import sweep
from slidernet.errors import ConfigError, SnapshotError
from slidernet.solver import Realization, Scene, injected_thresholds
from slidernet.solver.snapshot import check_fingerprint, scene_fingerprint

from .conftest import make_config

OBSERVED = ["n", "mu_max", "x_G", "mu_eff", "mu_eff_realization", "tilt_loads", "contact_age", "mu_shs"]

#: The plain variables of a run with the network tilt test, and their injected twins.
TWINS = {"mu_eff": "mu_eff_injected", "mu_eff_sem": "mu_eff_injected_sem", "mu_eff_count": "mu_eff_injected_count",
         "mu_eff_realization": "mu_eff_injected_realization", "tilt_first_slip": "tilt_first_slip_injected",
         "tilt_all_moving": "tilt_all_moving_injected", "tilt_capped": "tilt_capped_injected",
         "tilt_contact_mean": "tilt_contact_mean_injected", "tilt_half_broken": "tilt_half_broken_injected",
         "tilt_break_ratio": "tilt_break_ratio_injected",
         "mu_shs": "mu_shs_injected", "mu_shs_mean": "mu_shs_injected_mean", "mu_shs_sem": "mu_shs_injected_sem"}


def _graph(tmp_path: Path) -> dict[str, Any]:
    path = tmp_path / "star.edgelist"
    path.write_text("0 1\n0 2\n0 3\n3 4\n", encoding="utf-8")
    (tmp_path / "star.nodes.csv").write_text("node,x\n0,0.0\n1,-1.0\n2,1.0\n3,2.0\n4,3.0\n", encoding="utf-8")
    return {"kind": "graph", "path": str(path), "Ntilde": 1e-7}


# Every kind of network, each slip rule and sliding rule, and repeats: the scenes every guarantee is run on.
SCENES: dict[str, dict[str, Any]] = {
    "pair": {"network": {"kind": "two_slider", "Ntilde": 1e-7}},
    "chain-overshoot-0": {"network": {"kind": "chain", "n": 6, "Ntilde": 1e-7}, "friction.overshoot": 0.0},
    # The exactly integrated slip costs ~0.1 ms: a slower drive (200 slips per realization, not 35 000).
    "triangular-exact-slip": {"network": {"kind": "triangular", "shape": [3, 4], "Ntilde": 1e-7},
                              "solver.slip": "exact", "driver.sigma_theta": 3e-8},
    "irregular-min_slips-repeats": {"network": {"kind": "irregular", "n": 12, "Ntilde": 1e-7},
                                    "tilt": {"min_slips": 2, "repeats": 2}},
    "square-min_displacement": {"network": {"kind": "square", "shape": [3, 3], "Ntilde": 1e-7},
                                "tilt": {"min_displacement": 0.5}},
    "chain-strengthening": {"network": {"kind": "chain", "n": 5, "Ntilde": 1e-7},
                            "friction.strengthening": {"beta": 0.01, "tau_c": 1.0}},
    "graph": {},
}


def _scene_config(name: str, tmp_path: Path, **changes: Any) -> dict[str, Any]:
    scene = dict(SCENES[name])
    if name == "graph":
        scene["network"] = _graph(tmp_path)
    return make_config(**{"realizations": 2, "steps": 30, "record": "log", "log_points_per_decade": 4,
                          "observables": OBSERVED, "mu_eff_at": "records", "driver.sigma_theta": 1e-6,
                          **scene, **changes})


def _with_inject(cfg: dict[str, Any], **inject: float) -> dict[str, Any]:
    return {**cfg, "tilt": {**cfg.get("tilt", {}), "inject": inject}}


@pytest.mark.parametrize("select", [1.0, 0.3], ids=["select-1", "select-0.3"])
@pytest.mark.parametrize("scene", list(SCENES))
def test_c_0_changes_no_bit_and_its_twins_equal_the_plain_outputs(scene, select, tmp_path):
    plain = slidernet.run(_scene_config(scene, tmp_path))
    injected = slidernet.run(_with_inject(_scene_config(scene, tmp_path), c=0.0, select=select))
    for name in plain.data_vars:
        np.testing.assert_array_equal(injected[name].values, plain[name].values, err_msg=name)
    twins = [(p, i) for p, i in TWINS.items() if p in plain]
    assert len(twins) >= 9
    for p, i in twins:
        assert injected[i].dtype == plain[p].dtype, i
        np.testing.assert_array_equal(injected[i].values, plain[p].values, err_msg=i)


@pytest.mark.parametrize("select", [1.0, 0.3], ids=["select-1", "select-0.3"])
@pytest.mark.parametrize("scene", list(SCENES))
def test_an_injection_never_changes_the_run(scene, select, tmp_path):
    plain = slidernet.run(_scene_config(scene, tmp_path))
    injected = slidernet.run(_with_inject(_scene_config(scene, tmp_path), c=0.05, t0=2.0, select=select))
    # n, mu_max, x_G, the contact ages, the plain mu_eff and every other plain output: the same bits.
    for name in plain.data_vars:
        np.testing.assert_array_equal(injected[name].values, plain[name].values, err_msg=name)
    assert not np.array_equal(injected["tilt_first_slip_injected"].values[:, 1:],
                              plain["tilt_first_slip"].values[:, 1:])
    assert not np.array_equal(injected["mu_shs_injected"].values[:, 1:], plain["mu_shs"].values[:, 1:])


@pytest.mark.parametrize("scene", ["chain-overshoot-0", "irregular-min_slips-repeats"])
def test_twins_that_outgrow_the_draw_buffers_read_the_same_draws(scene, tmp_path):
    # With 7 draws per buffer the twins and the plain tests run out again and again: the buffers grow under
    # them (Streams.extend_tilt), and the results are those of the default batch, twins and all.
    cfg = _with_inject(_scene_config(scene, tmp_path), c=0.05, select=0.5)
    small = slidernet.run({**cfg, "solver": {"batch": 7}})
    default = slidernet.run(cfg)
    assert set(small.data_vars) == set(default.data_vars)
    for name in default.data_vars:
        np.testing.assert_array_equal(small[name].values, default[name].values, err_msg=name)
    plain = slidernet.run({**_scene_config(scene, tmp_path), "solver": {"batch": 7}})
    for name in plain.data_vars:
        np.testing.assert_array_equal(small[name].values, plain[name].values, err_msg=name)


def test_the_pair_runs_on_the_csr_kernel_for_the_ages_with_the_pair_kernels_bits(tmp_path):
    # select < 1 reads each contact's age: the two sliders then run on csr, whose bits are the pair kernel's
    # (ARCHITECTURE.md, invariant 6).
    cfg = _scene_config("pair", tmp_path, observables=["n", "mu_max", "x_G", "mu_eff", "mu_eff_realization"])
    plain = slidernet.run(cfg)
    injected = slidernet.run(_with_inject(cfg, c=0.05, select=0.5))
    assert (plain.attrs["kernel"], injected.attrs["kernel"]) == ("pair", "csr")
    assert slidernet.run(_with_inject(cfg, c=0.05)).attrs["kernel"] == "pair"
    for name in plain.data_vars:
        np.testing.assert_array_equal(injected[name].values, plain[name].values, err_msg=name)


# --------------------------------------------------------------------------
# Hand cases
# --------------------------------------------------------------------------

@pytest.mark.parametrize("network", [{"kind": "two_slider"}, {"kind": "chain", "n": 5}], ids=["pair", "chain-5"])
@pytest.mark.parametrize(("c", "t0"), [(0.01, 1.0), (0.3, 7.5)], ids=["c-0.01", "c-0.3-t0-7.5"])
def test_a_slider_at_rest_under_no_force_slides_at_its_threshold_raised_by_exactly_the_shift(network, c, t0):
    # Every threshold (and every redraw) is 0.6 and theta never moves: no spring is stretched, every test
    # slides at the first critical load, the threshold itself; the injected test at its raised threshold.
    cfg = make_config(realizations=2, steps=100, record="log", log_points_per_decade=2,
                      network={**network, "Ntilde": 1e-7}, observables=["n", "mu_eff", "mu_eff_realization"],
                      mu_eff_at="records", tilt={"inject": {"c": c, "t0": t0}},
                      friction={"mu_d": 0.5, "static": {"name": "constant", "value": 0.6}},
                      driver={"name": "constant", "theta0": 0.0})
    ds = slidernet.run(cfg)
    t = ds["t"].values
    assert t.tolist() == [0, 1, 3, 10, 32, 100] and int(ds["n"].max()) == 0
    raised = np.array([0.6 + c * math.log1p(float(time) / t0) for time in t])
    np.testing.assert_array_equal(ds["mu_eff"].values, np.full(t.size, 0.6))
    np.testing.assert_array_equal(ds["mu_eff_injected"].values, raised)
    np.testing.assert_array_equal(ds["mu_eff_injected_realization"].values, np.stack([raised, raised]))
    np.testing.assert_array_equal(ds["mu_eff_injected_count"].values, ds["mu_eff_count"].values)
    assert ds["mu_eff_injected"].attrs["inject_c"] == c and ds["mu_eff_injected"].attrs["inject_t0"] == t0
    assert ds["mu_eff_injected"].attrs["inject_select"] == 1.0
    assert "same draws" in ds["mu_eff_injected"].attrs["pairing"]


SELECTIONS = [
    # last slips, select -> the raised nodes: the oldest contacts (smallest last slip), ties to the lower index.
    pytest.param([3.0, 0.0, 1.5, 0.0, 3.0], 0.4, [1, 3], id="the-two-that-never-slipped"),
    pytest.param([3.0, 0.0, 1.5, 0.0, 3.0], 0.6, [1, 2, 3], id="then-the-next-oldest"),
    pytest.param([3.0, 0.0, 1.5, 0.0, 3.0], 0.8, [0, 1, 2, 3], id="a-tie-at-the-edge-goes-to-the-lower-index"),
    pytest.param([0.0, 0.0, 0.0, 0.0], 0.5, [0, 1], id="all-tied"),
    pytest.param([2.0, 1.0, 0.5, 0.25], 0.01, [3], id="at-least-one"),
    pytest.param([0.3] * 10, 0.3, [0, 1, 2], id="0.3-of-10-is-3"),
    pytest.param([2.0, 1.0], 1.0, [0, 1], id="select-1-raises-all"),
]


@pytest.mark.parametrize(("last_slip", "select", "raised"), SELECTIONS)
def test_the_oldest_contacts_are_raised_ties_to_the_lower_index(last_slip, select, raised):
    mu = np.linspace(0.55, 0.65, len(last_slip))
    inject = InjectConfig(c=0.02, t0=4.0, select=select)
    out = injected_thresholds(mu, np.array(last_slip), 12.0, inject)
    shift = 0.02 * math.log1p(12.0 / 4.0)
    expected = mu.copy()
    expected[raised] += shift
    np.testing.assert_array_equal(out, expected)
    assert mu.tolist() == np.linspace(0.55, 0.65, len(last_slip)).tolist()  # the state's own is untouched


def test_a_selection_without_the_ages_is_a_bug_not_a_silent_raise_of_every_contact():
    with pytest.raises(ValueError, match=r"select = 0\.5\) needs each node's last slip: got 0 times for 3"):
        injected_thresholds(np.full(3, 0.6), np.zeros(0), 1.0, InjectConfig(c=0.01, select=0.5))


@pytest.mark.parametrize("network", [{"kind": "chain", "n": 7}, {"kind": "triangular", "shape": [3, 3]}],
                         ids=["chain", "triangular"])
def test_the_realization_raises_the_contacts_its_ages_call_oldest(network):
    cfg = make_config(steps=40, record="all", network={**network, "Ntilde": 1e-7}, mu_eff_at="records",
                      observables=["n", "mu_eff", "contact_age"], tilt={"inject": {"c": 0.01, "select": 0.4}},
                      **{"driver.sigma_theta": 1e-6})
    real = Realization(Scene.from_config(load_config(cfg)), np.random.SeedSequence(3))
    N = real.mu.size
    mixed = 0
    for k, t in enumerate(real.scene.out_steps):
        real.advance(int(t))
        ages = float(t) - real.backend.last_slip(real)
        np.testing.assert_allclose(ages.mean(), real.out["contact_age"][k], rtol=0, atol=1e-12)
        order = sorted(range(N), key=lambda i: (-ages[i], i))  # oldest first, then the lower index
        expected = np.zeros(N, bool)
        expected[order[: math.ceil(0.4 * N)]] = True
        raised = real.tested_thresholds(k, True) != real.mu
        np.testing.assert_array_equal(raised, expected if t > 0 else np.zeros(N, bool))
        mixed += len(set(ages.round(9))) > 2
    assert mixed > 10  # states where age, not index, decides


@settings(max_examples=20)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 8), normal_load=st.floats(0.5, 2.0),
       c=st.floats(1e-4, 0.3), t0=st.floats(0.1, 30.0), overshoot=st.sampled_from([0.0, 0.5, 1.0]))
def test_the_first_slip_of_a_raised_1d_network_comes_exactly_the_shift_later(seed, n, normal_load, c, t0,
                                                                              overshoot):
    # In 1D the first slip's load is min_i (mu_s,i N_i - G_i) / N_i: with every threshold raised by s, s more.
    cfg = make_config(steps=12, record="all", network={"kind": "chain", "n": n, "Ntilde": 1e-7,
                                                      "normal_load": normal_load},
                      observables=["n", "mu_eff", "tilt_loads"], mu_eff_at="records",
                      tilt={"inject": {"c": c, "t0": t0}},
                      **{"driver.sigma_theta": 1e-6, "friction.overshoot": overshoot})
    real = Realization(Scene.from_config(load_config(cfg)), np.random.SeedSequence(seed)).advance()
    shift = np.array([real.scene.inject.shift(float(t)) for t in real.scene.out_steps])
    rise = real.out["tilt_first_slip_injected"] - real.out["tilt_first_slip"]
    np.testing.assert_allclose(rise, shift, rtol=0, atol=4e-15)
    assert real.n > 0


# --------------------------------------------------------------------------
# [tilt] repeats
# --------------------------------------------------------------------------

def _repeats_config(**tilt: Any) -> dict[str, Any]:
    return make_config(realizations=4, steps=30, record="log", log_points_per_decade=4,
                       network={"kind": "irregular", "n": 10, "Ntilde": 1e-7}, observables=OBSERVED,
                       mu_eff_at="records", **({"tilt": tilt} if tilt else {}), **{"driver.sigma_theta": 1e-6})


def test_one_repeat_is_the_run_without_the_key_to_the_bit():
    plain, once = slidernet.run(_repeats_config()), slidernet.run(_repeats_config(repeats=1))
    assert set(once.data_vars) == set(plain.data_vars) and "mu_eff_spread" not in once
    for name in plain.data_vars:
        np.testing.assert_array_equal(once[name].values, plain[name].values, err_msg=name)


def test_three_repeats_pool_three_tests_per_record_with_errors_from_the_realizations():
    plain, ds = slidernet.run(_repeats_config()), slidernet.run(_repeats_config(repeats=3))
    R = ds.sizes["realization"]
    np.testing.assert_array_equal(ds["mu_eff_count"].values, 3 * R)
    for name in ("n", "mu_max", "x_G", "contact_age"):
        np.testing.assert_array_equal(ds[name].values, plain[name].values, err_msg=name)
    # The first slip's load does not depend on the draws: the mean of three equal loads.
    np.testing.assert_allclose(ds["tilt_first_slip"].values, plain["tilt_first_slip"].values, rtol=0, atol=1e-15)
    # The standard error of mu_eff comes from the realizations' means, never from the R K tests as if
    # independent: with K tests in every realization it is std(mu_eff_realization) / sqrt(R).
    means = ds["mu_eff_realization"].values
    np.testing.assert_allclose(ds["mu_eff"].values, means.mean(axis=0), rtol=1e-14)
    np.testing.assert_allclose(ds["mu_eff_sem"].values, means.std(axis=0, ddof=1) / math.sqrt(R), rtol=1e-9)
    spread = ds["mu_eff_spread"]
    assert spread.dims == ("realization", "t") and "ddof = 1" in spread.attrs["long_name"]
    assert np.isfinite(spread.values).all() and (spread.values > 0).sum() > spread.size // 2


def test_the_repeats_are_today_s_test_and_the_next_ones_read_from_the_tilt_stream():
    # A run of K = 3 is, bit for bit, a run of K = 1 (today's code) that tests each record's state twice
    # more right after its own test, from the same stream.
    cfg = load_config(_repeats_config(repeats=3))
    three = Realization(Scene.from_config(cfg), np.random.SeedSequence(11))
    one = Realization(Scene.from_config(cfg.model_copy(update={"tilt": None})), np.random.SeedSequence(11))
    for k, t in enumerate(three.scene.out_steps):
        three.advance(int(t))
        one.advance(int(t))
        tests = [float(one.out["f_sum"][k]), one.tilt_test(), one.tilt_test()]
        total = 0.0
        for f in tests:
            total += f
        assert three.out["f_sum"][k] == total
        assert three.out["f_count"][k] == 3
        assert three.out["mu_eff_spread"][k] == np.std(tests, ddof=1)
        assert three.out["n"][k] == one.out["n"][k]


def test_each_repeat_has_its_injected_twin():
    ds = slidernet.run(_repeats_config(repeats=3, inject={"c": 0.0}))
    for plain, twin in TWINS.items():
        if plain in ds:
            np.testing.assert_array_equal(ds[twin].values, ds[plain].values, err_msg=twin)
    np.testing.assert_array_equal(ds["mu_eff_injected_count"].values, 3 * ds.sizes["realization"])


# --------------------------------------------------------------------------
# The configuration: validated, one line naming the key; dumps unchanged without the keys
# --------------------------------------------------------------------------

REFUSED = {
    "inject-without-mu_eff": ({"tilt": {"inject": {"c": 0.01}}, "observables": ["n"]},
                              r"'tilt\.inject' raises the thresholds .* this run makes neither: "
                              r"\"mu_eff\" is not in 'observables'; add it, or add \"mu_shs\""),
    "inject-with-the-appendix-test": ({"tilt": {"inject": {"c": 0.01}}},
                                      r"'tilt\.inject' .* the appendix's test of two sliders before every "
                                      r"rearrangement; set 'mu_eff_at = \"records\"', or add \"mu_shs\""),
    "repeats-without-mu_eff": ({"tilt": {"repeats": 2}, "observables": ["n"], "mu_eff_at": "records"},
                               r"'tilt\.repeats' = 2 asks for that many network tilt tests .* \"mu_eff\" is not "
                               r"in 'observables'; add it"),
    "repeats-with-the-appendix-test": ({"tilt": {"repeats": 2}},
                                       r"'tilt\.repeats' = 2 .* set 'mu_eff_at = \"records\"'"),
    "select-on-the-pair-kernel": ({"tilt": {"inject": {"c": 0.01, "select": 0.5}}, "mu_eff_at": "records",
                                   "solver.kernel": "pair"},
                                  r"'tilt\.inject' with select < 1 raises the oldest contacts, whose ages need a "
                                  r"network kernel; use 'solver\.kernel = \"auto\"'"),
    "c-negative": ({"tilt": {"inject": {"c": -0.01}}}, r"'tilt\.inject\.c' field must be >= 0"),
    "c-nan": ({"tilt": {"inject": {"c": float("nan")}}}, r"'tilt\.inject\.c' field must be a finite number"),
    "c-inf": ({"tilt": {"inject": {"c": float("inf")}}}, r"'tilt\.inject\.c' field must be a finite number"),
    "c-text": ({"tilt": {"inject": {"c": "0.01"}}},
               r"'tilt\.inject\.c' field must be a real number\. Got '0\.01'"),
    "c-true": ({"tilt": {"inject": {"c": True}}}, r"'tilt\.inject\.c' field must be a real number\. Got True"),
    "c-missing": ({"tilt": {"inject": {"t0": 1.0}}}, r"'tilt\.inject\.c' field is required"),
    "t0-zero": ({"tilt": {"inject": {"c": 0.01, "t0": 0.0}}}, r"'tilt\.inject\.t0' field must be > 0"),
    "select-zero": ({"tilt": {"inject": {"c": 0.01, "select": 0}}}, r"'tilt\.inject\.select' field must be > 0"),
    "select-above-1": ({"tilt": {"inject": {"c": 0.01, "select": 1.5}}},
                       r"'tilt\.inject\.select' field must be <= 1"),
    "inject-unknown-key": ({"tilt": {"inject": {"c": 0.01, "tau": 1.0}}},
                           r"Unknown key 'tau' in \[tilt\.inject\]"),
    "repeats-zero": ({"tilt": {"repeats": 0}}, r"'tilt\.repeats' field must be >= 1"),
    "repeats-text": ({"tilt": {"repeats": "3"}}, r"'tilt\.repeats' field must be an integer\. Got '3'"),
    "repeats-fraction": ({"tilt": {"repeats": 2.5}}, r"'tilt\.repeats' field must be an integer"),
}


@pytest.mark.parametrize(("changes", "message"), REFUSED.values(), ids=REFUSED.keys())
def test_bad_injections_and_repeats_are_refused_naming_the_key(changes, message):
    with pytest.raises(ConfigError, match=message) as refused:
        load_config(make_config(**changes))
    assert len(str(refused.value).splitlines()) == 2  # "Invalid configuration:" and the one reason


def test_a_tilt_table_without_the_new_keys_dumps_as_before():
    rule = {"min_slips": 2, "min_displacement": 0.0}
    for tilt in (rule, {**rule, "repeats": 1}):
        cfg = load_config(make_config(tilt=tilt, mu_eff_at="records"))
        assert cfg.model_dump(mode="json")["tilt"] == rule
    cfg = load_config(make_config(tilt={"repeats": 3, "inject": {"c": 0.01}}, mu_eff_at="records"))
    assert cfg.model_dump(mode="json")["tilt"] == {**rule, "min_slips": 1, "repeats": 3,
                                                    "inject": {"c": 0.01, "t0": 1.0, "select": 1.0}}


# --------------------------------------------------------------------------
# Checkpoints and sweeps
# --------------------------------------------------------------------------

def test_a_snapshot_resumes_to_the_same_bits_and_names_its_injection():
    cfg = load_config(_repeats_config(repeats=2, inject={"c": 0.02, "select": 0.5}))
    scene = Scene.from_config(cfg)
    whole = Realization(scene, np.random.SeedSequence(5)).advance().result()
    half = Realization(scene, np.random.SeedSequence(5)).advance(13)
    resumed = Realization(scene, np.random.SeedSequence(5))
    resumed.restore(half.snapshot())
    got = resumed.advance().result()
    for name, values in whole.items():
        np.testing.assert_array_equal(got[name], values, err_msg=name)
    other = Scene.from_config(load_config(_repeats_config(repeats=2, inject={"c": 0.03, "select": 0.5})))
    with pytest.raises(SnapshotError, match="inject"):
        check_fingerprint(scene_fingerprint(scene), other)


def test_a_sweep_keeps_the_attributes_its_points_share_and_leaves_out_the_swept_one():
    cfg = make_config(realizations=2, steps=10, network={"kind": "chain", "n": 4, "Ntilde": 1e-7},
                      observables=["n", "mu_eff"], mu_eff_at="records", tilt={"inject": {"c": 0.01}})
    ds = sweep(cfg, {"tilt.inject.select": [1.0, 0.5]})
    attrs = ds["mu_eff_injected"].attrs
    assert attrs["inject_c"] == 0.01 and "inject_select" not in attrs and "pairing" in attrs
