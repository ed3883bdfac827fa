"""The creep observables (observable ``creep``): x_G per cycle, the reptation velocity, the creep events.

The scene of issue 17: a chain of two sliders under a downhill load
f_ext = 0.3 N along +x, driven by a sinusoidal dilation. With constant
thresholds (mu_s = 0.6, mu_d = 0.5) every slip is exactly one reference slip
ell = 2 (mu_s - mu_d) Ntilde l0 = 2e-8 l0 (K_ii = k = 1 for both sliders),
so x_G advances by whole half-slips (w_i = 1/2) and, after a transient, by
the same number of them every cycle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import slidernet
from slidernet.config import load_config
from slidernet.ensemble.sweep import sweep
from slidernet.solver import Realization, Scene
from slidernet.solver import backends as backends_module
from slidernet.solver.creep import CreepSpec, creep_record

NTILDE = 1e-7
SLIP = 2 * (0.6 - 0.5) * NTILDE  # ell, in l0
CONSTANT = {"name": "constant", "value": 0.6}
GAUSSIAN = {"name": "gaussian", "mean": 0.6, "std": 0.01}


def creep_config(amplitude: float = 3e-7, period: float = 20, static: dict = CONSTANT, steps: int = 200,
                 realizations: int = 1, observables: tuple[str, ...] = ("n", "x_G", "creep"),
                 creep: dict | None = None, **top) -> dict:
    cfg = {"seed": 1, "realizations": realizations, "steps": steps, "record": "all",
           "observables": list(observables),
           "network": {"kind": "chain", "n": 2, "Ntilde": NTILDE, "f_ext": 0.3},
           "friction": {"mu_d": 0.5, "static": static},
           "driver": {"name": "sinusoidal", "amplitude": amplitude, "period": period},
           "creep": {"transient": 40.0} if creep is None else creep,
           "execution": {"workers": 1}, **top}
    return cfg


@pytest.fixture(scope="module")
def creeping():
    return slidernet.run(creep_config(observables=("n", "x_G", "creep", "events")))


def test_the_advance_per_cycle_is_whole_slips_and_periodic_after_the_transient(creeping):
    ds = creeping
    assert ds.sizes["cycle"] == 10
    np.testing.assert_array_equal(ds["cycle_end"].values, 20.0 * np.arange(1, 11))
    # Every slip is one reference slip exactly (driving slips at |F| = mu_s N).
    np.testing.assert_allclose(ds["event_dx"].values, SLIP, rtol=1e-14)
    half_slips = ds["dx_G_cycle"].values[0] / (SLIP / 2)
    np.testing.assert_allclose(half_slips, np.round(half_slips), rtol=0, atol=1e-9)
    steady = np.round(half_slips[2:])
    assert steady[0] > 0 and (steady == steady[0]).all()
    np.testing.assert_allclose(ds["dx_G_cycle"].values[0, 2:], steady[0] * SLIP / 2, rtol=1e-12)
    # The velocity over the whole cycles after t = 40: the advance per cycle, and its
    # spread over identical cycles is zero.
    v_cycle = float(ds["v_creep_cycle"][0])
    assert v_cycle == pytest.approx(steady[0] * SLIP / 2, rel=1e-12)
    assert float(ds["v_creep"][0]) == pytest.approx(v_cycle / 20, rel=1e-12)
    assert float(ds["v_creep_cycles_sem"][0]) < 1e-12 * float(ds["v_creep"][0])


def test_x_G_per_cycle_agrees_with_the_recorded_x_G(creeping):
    ds = creeping
    recorded = ds["x_G"].sel(t=ds["cycle_end"].values.astype(int)).values
    np.testing.assert_allclose(ds["x_G_cycle"].values, recorded, rtol=1e-12, atol=1e-20)
    np.testing.assert_allclose(ds["x_G_cycle"].diff("cycle").values, ds["dx_G_cycle"].values[:, 1:],
                               rtol=1e-9, atol=1e-20)


def test_every_slip_is_a_creep_event_here_and_the_events_add_up(creeping):
    # event_fraction 0.25: one slider's slip (x_G + ell / 2) is a creep event.
    ds = creeping
    count = int(ds["creep_event_count"][0])
    assert count == np.unique(ds["event_avalanche"].values).size
    times = ds["creep_event_time"].values[0, :count]
    assert (np.diff(times) > 0).all()
    np.testing.assert_allclose(np.nansum(ds["creep_event_dx_G"].values), float(ds["x_G"][0, -1]), rtol=1e-12)
    assert ds["creep_event_dx_G"].attrs["reference_slip"] == pytest.approx(SLIP, rel=1e-15)


def test_below_the_onset_nothing_moves():
    ds = slidernet.run(creep_config(amplitude=2e-8, period=10))
    assert float(ds["v_creep"][0]) == 0.0
    assert (ds["dx_G_cycle"].values == 0.0).all()
    assert int(ds["creep_event_count"][0]) == 0 and ds.sizes["creep_event"] == 0


def test_near_the_onset_random_thresholds_make_irregular_events():
    ds = slidernet.run(creep_config(amplitude=3.2e-8, period=10, static=GAUSSIAN, steps=600, realizations=3,
                                    creep={"transient": 100.0, "event_fraction": 0.25}))
    counts = ds["creep_event_count"].values
    assert counts.sum() > 20
    for r, c in enumerate(counts):
        t = ds["creep_event_time"].values[r]
        w = ds["creep_waiting_time"].values[r]
        assert np.isnan(t[c:]).all() and np.isnan(w[c:]).all() and not np.isnan(t[:c]).any()
        if c >= 2:
            assert np.isnan(w[0]) and (w[1:c] > 0).all()
            np.testing.assert_allclose(t[1:c] - t[:c - 1], w[1:c], rtol=1e-15)
            assert np.nansum(w) == pytest.approx(t[c - 1] - t[0], rel=1e-12)
    waits = ds["creep_waiting_time"].values
    waits = waits[~np.isnan(waits)]
    assert waits.std() > 0.1 * waits.mean()  # not a clock
    # The ensemble's velocity and its standard error over the realizations.
    v = ds["v_creep"].values
    assert float(ds["v_creep_mean"]) == pytest.approx(v.mean(), rel=1e-12)
    assert float(ds["v_creep_sem"]) == pytest.approx(v.std(ddof=1) / math.sqrt(v.size), rel=1e-9)


def test_without_a_period_the_velocity_is_the_end_point_rate():
    cfg = creep_config(static=GAUSSIAN, creep={"transient": 30.0},
                       driver={"name": "gaussian_steps", "sigma_theta": 3e-7})
    ds = slidernet.run(cfg)
    assert "cycle" not in ds.dims and "x_G_cycle" not in ds
    x = ds["x_G"].values[0]
    assert float(ds["v_creep"][0]) == pytest.approx((x[-1] - x[30]) / (200 - 30), rel=1e-9)
    assert np.isnan(float(ds["v_creep_cycle"][0])) and np.isnan(float(ds["v_creep_cycles_sem"][0]))


def test_the_result_file_holds_the_same_values(tmp_path):
    cfg = creep_config(amplitude=3.2e-8, period=10, static=GAUSSIAN, steps=300, realizations=3)
    in_memory = slidernet.run(cfg)
    on_disk = slidernet.run(cfg, out=tmp_path).load()
    assert set(in_memory.variables) == set(on_disk.variables)
    for name in in_memory.variables:
        assert in_memory[name].dtype == on_disk[name].dtype, name
        np.testing.assert_array_equal(in_memory[name].values, on_disk[name].values, err_msg=name)


def test_creep_changes_no_other_result():
    with_creep = slidernet.run(creep_config(static=GAUSSIAN))
    without = slidernet.run(creep_config(static=GAUSSIAN, observables=("n", "x_G"), creep={}) | {"creep": None})
    for name in without.data_vars:
        np.testing.assert_array_equal(with_creep[name].values, without[name].values, err_msg=name)
    assert "event" not in with_creep.dims  # the catalogue serves the creep observables only


def test_an_incomplete_catalogue_gives_nan(monkeypatch):
    monkeypatch.setattr(backends_module, "EVENT_CHUNK", 64)  # the cap is checked when a buffer is full
    with pytest.warns(RuntimeWarning, match=r"reached solver.max_events = 100"):
        ds = slidernet.run(creep_config(solver={"max_events": 100}))
    assert np.isnan(ds["v_creep"].values).all() and np.isnan(ds["x_G_cycle"].values).all()
    assert int(ds["creep_event_count"][0]) == 0


def test_the_two_slider_scene_runs_creep_on_the_csr_kernel():
    cfg = creep_config(network={"kind": "two_slider", "Ntilde": NTILDE})
    assert Scene.from_config(load_config(cfg)).kernel == "csr"


@pytest.mark.parametrize(("changes", "match"), [
    ({"creep": {"transient": 200.0}}, r"'creep.transient' value must be < steps = 200"),
    ({"creep": {"transient": -1.0}}, r"'creep.transient' field must be >= 0"),
    ({"creep": {"event_fraction": 0.0}}, r"'creep.event_fraction' field must be > 0"),
    ({"creep": {"transent": 1.0}}, r"Unknown key 'transent' in \[creep\]"),
    ({"observables": ["n", "x_G"]}, r"the \[creep\] table sets the observable 'creep', which is not asked for"),
    ({"solver": {"kernel": "pair"}, "network": {"kind": "two_slider", "Ntilde": NTILDE}},
     r"'creep' observable .* needs a network kernel"),
], ids=["transient-too-long", "transient-negative", "fraction-zero", "unknown-key", "not-asked", "pair-kernel"])
def test_bad_creep_settings_are_refused_naming_the_key(changes, match):
    with pytest.raises(slidernet.ConfigError, match=match):
        load_config(creep_config() | changes)


def test_creep_cannot_be_swept(tmp_path):
    with pytest.raises(slidernet.ConfigError, match=r"'creep' observable .* cannot be swept"):
        sweep(creep_config(), {"driver.amplitude": [3e-7, 5e-7]}, out=tmp_path)


def test_a_realization_without_creep_keeps_its_records():
    cfg = load_config(creep_config(observables=("n", "x_G", "events"), creep={}) | {"creep": None})
    res = Realization(Scene.from_config(cfg), np.random.SeedSequence(1)).advance().result()
    assert "events" in res and "v_creep" not in res


# -- the reduction of one catalogue, on made-up catalogues ---------------------------------------------------

@st.composite
def catalogues(draw):
    """A catalogue of avalanches in [0, steps): ids in order, several slips each, times non-decreasing.

    The kernels stamp the events of step q in [q, q + 1), so no stamp reaches ``steps``.
    """
    steps = draw(st.integers(10, 60))
    n_av = draw(st.integers(0, 30))
    times = sorted(draw(st.lists(st.floats(0, steps, exclude_max=True), min_size=n_av, max_size=n_av)))
    sizes = draw(st.lists(st.integers(1, 3), min_size=n_av, max_size=n_av))
    rows = [(t, a + 1, draw(st.integers(0, 2)), draw(st.sampled_from([-2.0, 1.0, 2.0, 3.0])))
            for a, (t, s) in enumerate(zip(times, sizes, strict=True)) for _ in range(s)]
    ev = {"time": np.array([r[0] for r in rows]), "avalanche": np.array([r[1] for r in rows], np.int64),
          "node": np.array([r[2] for r in rows], np.int64), "dx": np.array([r[3] for r in rows])}
    return ev, steps


@given(catalogues(), st.sampled_from([None, 3.0, 7.5]), st.floats(0, 9.0), st.floats(0.1, 2.0))
def test_the_reduction_keeps_its_invariants(catalogue, period, transient, fraction):
    ev, steps = catalogue
    w = np.full(3, 1 / 3)
    spec = CreepSpec(period=period, transient=transient, slip=2.0, threshold=fraction * 2.0, weights=w)
    rec = creep_record(ev, True, steps, spec)
    t, dx, wait = (rec["creep_events"][k] for k in ("time", "dx_G", "wait"))
    if t.size:
        assert np.isnan(wait[0]) and (wait[1:] >= 0).all()
        assert np.nansum(wait) == pytest.approx(t[-1] - t[0], abs=1e-9)
        assert (dx > spec.threshold).all()
    if period is not None:
        C = rec["dx_G_cycle"].size
        assert C == int(steps // period)
        inside = ev["time"] < C * period
        assert rec["dx_G_cycle"].sum() == pytest.approx((w[ev["node"]] * ev["dx"])[inside].sum(), abs=1e-9)
        np.testing.assert_allclose(rec["x_G_cycle"], np.cumsum(rec["dx_G_cycle"]))
    else:
        after = ev["time"] >= transient
        rate = (w[ev["node"]] * ev["dx"])[after].sum() / (steps - transient)
        assert float(rec["v_creep"]) == pytest.approx(rate, abs=1e-9)


def test_an_incomplete_catalogue_reduces_to_nan():
    spec = CreepSpec(period=5.0, transient=0.0, slip=1.0, threshold=0.5, weights=np.ones(1))
    ev = {"time": np.array([1.0]), "avalanche": np.array([1]), "node": np.array([0]), "dx": np.array([1.0])}
    rec = creep_record(ev, False, 20, spec)
    assert np.isnan(rec["v_creep"]) and np.isnan(rec["x_G_cycle"]).all() and rec["creep_events"]["time"].size == 0


def test_a_slip_at_a_cycle_end_falls_in_the_cycle_the_recorded_x_G_puts_it():
    """Two sliders at tan = 0.2, A = 0.617 Ntilde: slider 1 yields exactly at theta = 0, a cycle's end.

    U = mu_s - f = 2 D, and G stays congruent to theta modulo D, so the slips land on the samples
    theta(t_c) = 0 themselves. The kernels stamp a step's events in [q, q + 1): each cycle's advance
    from the catalogue is the difference of the recorded x_G, slip for slip.
    """
    steps = 800
    cfg = creep_config(amplitude=0.617 * NTILDE, steps=steps, observables=("n", "x_G", "creep", "events"),
                       record=list(range(0, steps + 1, 20)))
    cfg["network"] = {"kind": "chain", "n": 2, "Ntilde": NTILDE, "incline": math.degrees(math.atan(0.2))}
    ds = slidernet.run(cfg, progress=False)
    times = ds["event_time"].values
    assert (times == np.round(times)).any(), "no slip at a sample: the scene no longer tests the boundary"
    np.testing.assert_allclose(ds["dx_G_cycle"].values[0], np.diff(ds["x_G"].values[0]), rtol=1e-12, atol=0)
