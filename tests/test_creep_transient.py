"""The transient part of examples/creep_networks.py: x_G read from the event catalogue below 1 tau_th.

The catalogue's x_G is checked against the recorded x_G at integer times (to
the bit where Ntilde is a power of 2, and to rounding at the study's
Ntilde = 1e-7), and the --quick preset's transient numbers and panel are
checked on one run of the preset, resumed after its transient part.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest
import xarray as xr

import slidernet
from tests.test_examples import assert_png, load_example


@pytest.fixture(scope="module")
def study() -> ModuleType:
    return load_example("creep_networks")


def catalogue_and_records(study: ModuleType, kind: str, n: int, ntilde: float) -> tuple[np.ndarray, xr.Dataset]:
    """A short run of the transient's configuration (2 realizations, 20 tau_th, sigma_theta = Ntilde):
    the catalogue's x_G at every recorded time, shape (R, T), and the run's result."""
    cfg = study.transient_config(kind, n, 20, 2)
    cfg["network"]["Ntilde"] = ntilde
    cfg["driver"]["sigma_theta"] = ntilde   # sigma_theta / Ntilde = 1, as in the study
    ds = slidernet.run(cfg)
    assert ds["events_complete"].values.all()
    net = slidernet.load_config(cfg).network.build()
    w = net.normal_load / net.normal_load.sum()
    t = ds["t"].values.astype(np.float64)
    owner = ds["event_realization"].values
    time, node, dx = (ds[f"event_{name}"].values for name in ("time", "node", "dx"))
    x = np.stack([study.catalogue_x_G(time[owner == r], w[node[owner == r]] * dx[owner == r], t)
                  for r in range(ds.sizes["realization"])])
    return x, ds


@pytest.mark.parametrize("kind, n", [("chain", 2), ("chain", 4)], ids=["chain-2", "chain-4"])
def test_catalogue_x_G_is_the_recorded_x_G_to_the_bit_where_Ntilde_is_a_power_of_2(study, kind, n):
    # Scaling by 2**-23 is exact, so the catalogue's dx = du Ntilde loses nothing and the slips, summed in
    # the kernel's order, give the kernel's x_G bit for bit at every integer t.
    x, ds = catalogue_and_records(study, kind, n, 2.0**-23)
    assert ds["event_time"].size > 20   # slips in every realization, not an empty check
    np.testing.assert_array_equal(x, ds["x_G"].transpose("realization", "t").values)


@pytest.mark.parametrize("kind, n", [("chain", 4)], ids=["chain-4"])
def test_catalogue_x_G_agrees_with_the_records_to_rounding_at_Ntilde_1e_7(study, kind, n):
    # dx = du * 1e-7 is rounded once per slip: a few ulps of the largest |x_G| (measured: up to 2e-15 relative).
    x, ds = catalogue_and_records(study, kind, n, 1e-7)
    recorded = ds["x_G"].transpose("realization", "t").values
    scale = np.abs(recorded).max(axis=1, keepdims=True)
    assert (scale > 0).all()
    assert (np.abs(x - recorded) <= 1e-13 * scale).all()


@pytest.mark.parametrize(
    "t, expected",
    [(0.0, 1.0), (0.5, 1.0), (0.6, 3.0), (1.0, 3.0), (1.5, 7.0)],
    ids=["t0-holds-the-relaxation", "slip-at-t-not-yet", "after-a-slip", "record-before-its-step", "after-all"],
)
def test_catalogue_x_G_counts_the_slips_before_t(study, t, expected):
    # A relaxation at 0, a slip at 0.5 and one at the start of step 1 (time 1.0, after the record at 1).
    time, dx = np.array([0.0, 0.5, 1.0]), np.array([1.0, 2.0, 4.0])
    assert study.catalogue_x_G(time, dx, np.array([t])).tolist() == [expected]


@pytest.fixture(scope="module")
def quick(study, tmp_path_factory) -> tuple[dict[str, Any], dict[str, Any], Path]:
    """The --quick preset run in two steps: its transient part alone, then the whole, resumed in the same
    folder (the transient runs read back); the two JSON summaries and the folder."""
    out = tmp_path_factory.mktemp("creep_quick")
    assert study.main(["--quick", "--out", str(out), "--parts", "transient"]) == 0
    alone = json.loads((out / study.JSON_NAME).read_text())
    assert study.main(["--quick", "--out", str(out), "--resume"]) == 0
    return alone, json.loads((out / study.JSON_NAME).read_text()), out


QUICK_NETWORKS = [("chain", 2), ("chain", 4), ("irregular", 16)]


@pytest.mark.parametrize("kind, n", QUICK_NETWORKS, ids=[f"{k}-{n}" for k, n in QUICK_NETWORKS])
def test_quick_transient_numbers_are_finite_with_errors(study, quick, kind, n):
    alone, data, _ = quick
    preset = study.PRESETS["quick"]
    assert [(net["kind"], net["n"]) for net in data["transient"]["networks"]] == list(preset.transient.networks)
    net = next(x for x in data["transient"]["networks"] if (x["kind"], x["n"]) == (kind, n))
    assert net["realizations"] == preset.realizations and net["times"] == list(study.TRANSIENT_TIMES)
    for mean, sem, t in zip(net["x_G_mean"], net["x_G_sem"], net["times"], strict=True):
        assert math.isfinite(mean) and math.isfinite(sem)
        if t >= 1:   # every realization has slipped by then: a spread
            assert mean > 0 and sem > 0
    for w in net["windows"]:
        # Downhill at every window, with an error; set against the late velocity of the size part.
        assert w["v_mean"] > 0 and 0 < w["v_sem"] < w["v_mean"] and w["slips_per_tau_th_mean"] > 0
        assert math.isfinite(w["late_gap_mean"]) and w["late_gap_sem"] > 0
    assert net["late"]["v_mean"] > 0 and net["late"]["t_to"] == next(
        p["steps"] for p in data["points"] if (p["kind"], p["n"]) == (kind, n))
    assert net["reaches_late_from"] in (None, 0.0, 1.0, 10.0)
    step = net["in_step"]
    assert all(math.isfinite(v) for v in step["first_step_mean"] + step["late_steps_mean"] + step["gap_sem"])
    check = net["catalogue_check"]
    assert check["compared"] == preset.realizations * (preset.transient.steps + 1)
    assert check["max_rel_diff"] < 1e-12
    # Read back on --resume, the transient runs give the numbers they gave alone; only the late contrast is new.
    first = next(x for x in alone["transient"]["networks"] if (x["kind"], x["n"]) == (kind, n))
    assert first["late"] is None and "late_gap_mean" not in first["windows"][0]
    assert first["x_G_mean"] == net["x_G_mean"] and first["catalogue_check"] == check


def test_quick_figure_has_the_transient_panel(study, quick):
    alone, data, out = quick
    assert_png(out / study.PNG_NAME)
    assert not alone["points"]   # the transient part alone: no size part
    for summary in (data, alone, {**data, "transient": None}):
        axes = study.figure(summary).axes
        assert len(axes) == 4
        panel = axes[3]
        assert panel.get_title().startswith("(d) the transient")
        if summary["transient"] is None:
            assert [t.get_text() for t in panel.texts] == ["not run"]
        else:
            labels = panel.get_legend_handles_labels()[1]
            assert len(labels) == len(summary["transient"]["networks"])
