"""Smoke tests of the example scripts: they run, write their files, and show their physics."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path
from types import ModuleType

import pytest

from slidernet.io import read_result

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def load_example(name: str) -> ModuleType:
    """Import ``examples/<name>.py`` from its path (examples/ is not a package)."""
    spec = importlib.util.spec_from_file_location(f"slidernet_example_{name}", EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    # dataclasses look their module up in sys.modules while the class is built.
    sys.modules[spec.name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[spec.name]
        raise
    return module


def assert_png(path: Path) -> None:
    assert path.is_file(), path
    assert path.read_bytes()[:8] == PNG_MAGIC, path


def run_quick_study(name: str, out: Path) -> tuple[ModuleType, dict]:
    """Run a study's --quick preset into ``out``: its module and its JSON summary, once the figure
    is there and no temporary file is left behind."""
    study = load_example(name)
    assert study.main(["--quick", "--out", str(out)]) == 0
    assert_png(out / f"{name}.png")
    assert not list(out.glob(".*.tmp")), "a temporary file was left behind"
    return study, json.loads((out / f"{name}.json").read_text())


@pytest.mark.parametrize(
    "name",
    ["creep_irregular", "chain_aging", "aging_networks", "aging_recovery", "creep_networks", "rejuvenation"],
    ids=str)
def test_help_names_the_options(name, capsys):
    module = load_example(name)
    with pytest.raises(SystemExit) as exc:
        module.main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "--quick" in out and "--out" in out


def test_creep_irregular_quick(tmp_path):
    # The --quick preset: 60 sliders, 4 realizations x 40 tau_th, seed 1, network seed 0 (~8 s).
    creep = load_example("creep_irregular")
    assert creep.main(["--quick", "--out", str(tmp_path)]) == 0
    assert_png(tmp_path / "creep_velocity.png")
    assert not list(tmp_path.glob(".*.tmp")), "a temporary file was left behind"

    rows = creep.read_csv(tmp_path / "creep_velocity.csv")
    assert list(rows[0]) == list(creep.CSV_COLUMNS)
    preset = creep.PRESETS["quick"]
    assert len(rows) == len(preset.f_over_mu_d) + len(preset.sigma_b)
    assert all(math.isfinite(r["v"]) and r["v_sem"] > 0 and r["r_mean"] > 0 for r in rows)

    by_f = sorted((r for r in rows if r["sweep"] == "f_ext"), key=lambda r: r["f_ext"])
    rest, loaded = by_f[0], by_f[-1]
    assert rest["f_ext"] == 0.0
    # Downhill creep under the largest load (0.9 mu_d): well above zero and
    # above the unloaded drift, by more than 5 combined standard errors.
    # Measured with these seeds: 6.3e-7 +- 0.6e-7 against -1e-10 +- 3e-10 l0/tau_th.
    margin = 5 * math.hypot(loaded["v_sem"], rest["v_sem"])
    assert loaded["v"] > 5 * loaded["v_sem"]
    assert loaded["v"] - rest["v"] > margin
    # Without load the centre of mass does not creep: |v| within 4 standard errors.
    assert abs(rest["v"]) < 4 * rest["v_sem"]

    # More thermal agitation, more slips and faster creep at a fixed load.
    by_sigma = sorted((r for r in rows if r["sweep"] == "sigma_theta"), key=lambda r: r["sigma_theta"])
    assert [r["r_mean"] for r in by_sigma] == sorted(r["r_mean"] for r in by_sigma)
    assert by_sigma[-1]["v"] - by_sigma[0]["v"] > 5 * math.hypot(by_sigma[-1]["v_sem"], by_sigma[0]["v_sem"])


def test_chain_aging_quick(tmp_path):
    # The --quick preset: 8 realizations x 1000 tau_th, sigma_theta = 1e-6, seed 1 (~3 s).
    aging = load_example("chain_aging")
    assert aging.main(["--quick", "--out", str(tmp_path)]) == 0
    assert_png(tmp_path / "chain_aging.png")
    ds = read_result(tmp_path / "chain_aging.nc")
    assert ds["n_sliders"].values.tolist() == [2, 4, 8]
    assert int(ds["t"].values[-1]) == aging.PRESETS["quick"].steps

    # Two sliders: <mu_max>(t) follows the exact law of the max of n + 2 draws
    # at the measured n(t), within 4 standard errors plus 1e-4 (the exact law
    # is taken at the mean n, not averaged over n) at every recorded time.
    pair = ds.sel(n_sliders=2)
    gap = abs(pair["mu_max_mean"] - ds["mu_max_theory_mean"])
    assert (gap <= 4 * pair["mu_max_sem"] + 1e-4).all(), float(gap.max())
    # And it ages: up by more than 2 sigma_mu = 0.02 from t = 0 to t = 1000.
    assert float(pair["mu_max_mean"].isel(t=-1) - pair["mu_max_mean"].isel(t=0)) > 0.02
    # Longer chains need more slips per tau_th to follow the dilation.
    r = ds["r_mean"].values
    assert r[0] < r[1] < r[2]


def test_incline_creep_quick(tmp_path):
    """The --quick preset (seeds fixed in the script): every chain follows its exact orbit; no creep below A_c."""
    import numpy as np

    example = load_example("incline_creep")
    assert example.main(["--quick", "--out", str(tmp_path)]) == 0
    assert_png(tmp_path / "incline_creep.png")
    assert not list(tmp_path.glob(".*.tmp")), "a temporary file was left behind"
    data = json.loads((tmp_path / "incline_creep.json").read_text())
    a = data["a"]
    for n in ("2", "3", "4", "8"):
        # The grid avoids the segments' ends, where rounding decides: the solver is the exact orbit.
        ends = np.array([s["lo"] for s in a["theory"][n][1:]])
        assert min(np.min(abs(ends - t)) for t in a["tan_alpha"]) > 5e-4
        np.testing.assert_allclose(a["v"][n], a["theory_at_points"][n], rtol=1e-9, atol=1e-9)
    b = data["b"]
    for n in ("2", "3"):
        v = np.asarray(b["runs"][f"{n}-constant"]["v"])
        below = np.asarray(b["A_over_Ntilde"]) < b["A_c"][n]
        assert below.any() and (~below).any()
        assert (v[below] == 0).all() and (v[~below] > 0).all()


def test_aging_recovery_quick(tmp_path):
    """The positive control's --quick preset (the pair and irregular 16, both injections; ~10 s): every
    estimator's recovery with an error, and the one recovery that is exact."""
    study, data = run_quick_study("aging_recovery", tmp_path)
    assert len(data["points"]) == sum(len(g.sizes) for g in study.PRESETS["quick"].groups)
    for p in data["points"]:
        assert p["configs"][0]["tilt"]["inject"] == {"c": study.INJECT_C, "t0": 1.0, "select": p["select"]}
        rec = p["recovery"]
        assert rec["raised"] == math.ceil(p["select"] * p["N"])
        for name in study.ESTIMATORS:
            for window in study.WINDOWS:
                for norm in ("contact", "mean"):
                    r = rec[f"{name}|{window}|{norm}"]
                    assert math.isfinite(r["recovery"]) and r["sem"] >= 0
                    assert r["pairs"] == p["realizations"]
                    assert r["dof"] == (p["geometries"] - 1 if p["kind"] == "irregular" else p["realizations"] - 1)
        # Against the mean shift, the recovery is 1/q times that against the per-contact shift.
        assert math.isclose(rec["mu_eff|10-1e3|mean"]["recovery"] * rec["share"],
                            rec["mu_eff|10-1e3|contact"]["recovery"], rel_tol=1e-12)
    (pair,) = [p for p in data["points"] if p["kind"] == "pair" and p["select"] == 1.0]
    # Along a chain the first slip of the tilt test is at the load min_i (mu_s,i - f_i / N_i): every threshold
    # raised by one shift raises it by that shift, test by test, so its recovery is 1 up to rounding.
    for window in study.WINDOWS:
        r = pair["recovery"][f"tilt_first_slip|{window}|contact"]
        assert r["recovery"] == pytest.approx(1.0, abs=1e-9) and r["sem"] < 1e-9


@pytest.mark.parametrize("case", ["missing-study", "not-json", "no-recovery-json", "other-json"])
def test_aging_recovery_calibrate_refuses_wrong_files_in_one_line(tmp_path, capsys, case):
    study = load_example("aging_recovery")
    out, given = tmp_path / "out", tmp_path / "study.json"
    out.mkdir()
    if case != "no-recovery-json":
        (out / study.JSON_NAME).write_text(json.dumps({"points": []}), encoding="utf-8")
    if case == "not-json":
        given.write_text("not json", encoding="utf-8")
    elif case in ("no-recovery-json", "other-json"):
        given.write_text(json.dumps({"points": [{"kind": "pair"}]}), encoding="utf-8")
    assert study.main(["--out", str(out), "--calibrate", str(given)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("aging_recovery: error: --calibrate needs") and err.count("\n") == 1

def test_aging_networks_quick(tmp_path):
    """The --quick preset (pair, chains 4 and 8, irregular 16 over 2 geometries, triangular 4 x 4, the overshoot,
    a stricter sliding rule, K = 2 tests, a run to 1e4, sigma_theta / Ntilde = 10; 4 realizations to 1e3 tau_th;
    ~20 s): numbers with errors from independent units, and the restated study's statistics."""
    study, data = run_quick_study("aging_networks", tmp_path)
    preset = study.PRESETS["quick"]
    assert len(data["points"]) == sum(len(g.sizes) * len(g.params) for g in preset.groups)
    for p in data["points"]:
        assert all(c["mu_eff_at"] == p["mu_eff_at"] for c in p["configs"])
        assert p["realizations"] == preset.realizations
        slope = p["mu_eff"]["slope_per_decade"]
        # Errors from independent units: the geometries of an irregular network, else the realizations.
        assert slope["dof"] == (p["geometries"] - 1 if p["kind"] == "irregular" else preset.realizations - 1)
        assert slope["sem"] > 0 and math.isfinite(slope["mean"]) and 0 <= slope["p"] <= 1
        assert p["mu_eff"]["t_end"] == p["configs"][0]["steps"] in (preset.steps, 10_000)
        # The records' estimator has a value at every time; the appendix's only where a rearrangement was.
        if p["mu_eff_at"] == "records":
            assert p["mu_eff"]["not_finite"] == 0
        else:
            assert p["mu_eff"]["not_finite"] < p["realizations"] * len(p["curves"]["mu_eff"]["t"])
        # The tilt test gives a friction above mu_d, below the strongest threshold; its first slip comes
        # first and the collective motion before the sliding (per test, so for the means too).
        end = p["mu_eff"]["end"]["mean"]
        assert p["mu_d"] < end < p["mu_max"]["end"]["mean"]
        if p["mu_eff_at"] == "records":
            assert p["tilt_first_slip_end"]["mean"] <= p["tilt_all_moving_end"]["mean"] <= end
        # The weakest of N thresholds lies below the law's mean, and the more so the larger N.
        assert p["weakest_of_N"] < p["mu_s_mean"]
        assert math.isclose(p["sqrtN_excess"]["end"]["mean"], math.sqrt(p["N"]) * (end - p["mu_d"]), rel_tol=1e-9)
    points = {(p["group"], p["params"], p["N"]): p for p in data["points"]}
    # Slips that stop at mu_d (e = 0) leave a higher mu_eff than the paper's slip (measured: 0.560 against
    # 0.511, errors below 0.003).
    assert points[("irregular_e0", "base", 16)]["mu_eff"]["end"]["mean"] > \
        points[("irregular", "base", 16)]["mu_eff"]["end"]["mean"] + 0.02
    family = data["multiple_testing"]
    assert family["tests"] == len(data["points"]) and 0 <= family["beyond_2_se"] <= family["tests"]
    check_aging_statistics(study, data)
    (mech,) = data["mechanism"]
    # At rest at t = 0 no spring is stretched: load ratio 0; thermal cycling loads the nodes.
    assert mech["load_ratio_t0_mean"] == 0.0
    assert mech["load_ratio_end_mean"] > 0.1


def check_aging_statistics(study, data):
    """The restated aging study's statistics (issue 44, item 4) in the --quick JSON: windows, relative rates,
    variance components, the fits of slope(N), the new groups, and one family holding every slope reported."""
    import numpy as np

    stats = study.aging_stats
    points = data["points"]
    reported = []
    for p in points:
        reported += [p["mu_max"]["slope_per_decade"], p["sqrtN_excess_vs_slips"]["slope_per_decade"]]
        records = p["mu_eff_at"] == "records"
        estimators = set(study.aging_stats.ESTIMATORS) if records else {"mu_eff"}
        assert set(p["windows"]) == estimators
        for name, per_window in p["windows"].items():
            # Every window the run covers by a decade; the later the start, the fewer the records fitted.
            assert [w for w in stats.WINDOWS if w in per_window] == [
                w for w, (t_min, _) in stats.WINDOWS.items() if p["mu_eff"]["t_end"] >= 10 * t_min]
            counts = [per_window[w]["records"] for w in ("t>=100", "t>=10", "t>=1")]
            assert counts == sorted(counts) and (p["mu_eff_at"] != "records" or counts[0] < counts[1] < counts[2])
            for label, w in per_window.items():
                s = w["slope_per_decade"]
                reported.append(s)
                if label.startswith("t") and not (p["mu_eff_at"] != "records" or name == "tilt_all_moving"):
                    assert math.isfinite(s["mean"]) and s["sem"] > 0 and s["mde"] > 2 * s["sem"]
                    eq = s["equivalence"]
                    assert eq["margin"] == study.MARGIN_PER_DECADE
                    assert eq["equivalent"] == (-eq["margin"] < eq["ci90"][0] and eq["ci90"][1] < eq["margin"])
        for w in p["windows"]["mu_eff"].values():
            r = w.get("relative")
            if r is None or w["realizations"] != p["realizations"]:
                continue
            # The relative rate is the slope over the excess above mu_d, and c = sqrt(N) times that excess.
            assert math.isclose(r["rate_per_decade"] * r["excess"], w["slope_per_decade"]["mean"], rel_tol=1e-9)
            assert math.isclose(r["c"], math.sqrt(p["N"]) * r["excess"], rel_tol=1e-12)
            c = w.get("components")
            assert (c is not None) == (p["geometries"] > 1)
            if c is not None and "between" in c:
                # The components add up: between + within / n is the variance of the geometries' slopes,
                # unless the between-geometry estimate was negative and set to 0; their mean is the slope.
                spread = float(np.var(c["per_geometry"], ddof=1))
                if c["between"] > 0:
                    assert math.isclose(c["between"] + c["within"] / c["per_group"], spread, rel_tol=1e-9)
                    assert math.isclose(c["grand_mean_sem"], w["slope_per_decade"]["sem"], rel_tol=1e-9)
                else:
                    assert spread <= c["within"] / c["per_group"] * (1 + 1e-9)
                assert math.isclose(c["grand_mean"], w["slope_per_decade"]["mean"], rel_tol=1e-9)
                assert len(c["per_geometry"]) == p["geometries"]
    by_group = {p["group"]: p for p in points}
    long, amp, k2 = by_group["pair_1e4"], by_group["chains_amp10"], by_group["irregular_e1_K2"]
    assert long["mu_eff"]["t_end"] == 10_000 and "t>=1e3" in long["windows"]["mu_eff"]
    assert long["params"] == "ratio0.2" and long["configs"][0]["friction"]["static"]["std"] == 0.02
    driver = amp["configs"][0]["driver"]
    assert driver["sigma_theta"] == 10 * amp["configs"][0]["network"]["Ntilde"] and amp["condition"]
    assert k2["configs"][0]["tilt"]["repeats"] == 2 and k2["mu_eff_spread_end"]["mean"] > 0
    # One fit of slope(N) per parameter set and rule where three sizes or more of networks were run.
    fits = {(f["params"], f["rule"], f["window"]): f for f in data["fits"]}
    fit = fits[("base", "e = 1", "t>=1")]
    assert len(set(fit["sizes"])) >= 3 and fit["coef"]["infinite_N"]["mde"] > 0
    for f in data["fits"]:
        reported += list(f["coef"].values())
    # The family holds every slope reported, each with its q-values, and nothing else.
    fam = data["multiple_testing"]["family"]
    assert fam["tests"] + fam["untestable"] == len(reported) and len(set(fam["labels"])) == fam["tests"]
    for s in reported:
        assert ("q_by" in s) == math.isfinite(s["p"])
        if "q_by" in s:
            assert s["p"] <= s["q_bh"] <= s["q_by"] <= 1
    assert fam["method"] == "by" and "PRDS" in fam["dependence"]


def test_creep_networks_quick(tmp_path):
    """The --quick preset (chains of 2 and 4 to 1e3 tau_th, irregular 16 to 300; 8 realizations, seed 1;
    a few seconds): every point creeps downhill, steadily, with its numbers and errors."""
    study, data = run_quick_study("creep_networks", tmp_path)
    preset = study.PRESETS["quick"]
    assert [(p["kind"], p["n"]) for p in data["points"]] == [(g.kind, n) for g in preset.groups for n in g.sizes]
    assert data["parameters"]["f_ext_over_mu_d"] == 0.6
    for p in data["points"]:
        assert p["config"]["network"]["f_ext"] == 0.3 and p["realizations"] == preset.realizations
        t1, t2, t3 = p["windows"]
        assert t1 < t2 < t3 == p["steps"]
        # Downhill creep, resolved: measured 4.4e-8 +- 0.05e-8 (chain 2) to 1.2e-7 +- 0.02e-7 (irregular 16).
        assert p["v_last_decade_mean"] > 10 * p["v_last_decade_sem"] > 0
        assert p["r_mean"] > 0 and p["step_per_slip_mean"] > 0
        # The log law's ratio from the recorded times: near 1/10 for decade windows.
        assert 0.08 < p["ratio_log"] < 0.12
        # Measured ratios 0.95 +- 0.02 to 0.95 +- 0.05: logarithmic creep is rejected by more than 10 SE.
        assert not p["log_consistent"] and p["verdict"] == "steady: logarithmic creep rejected"
        assert abs(p["log_gap_mean"]) > 10 * p["log_gap_sem"]


def test_rejuvenation_quick(tmp_path):
    """The --quick preset (pair, chain 4, irregular 16; beta 0 and 0.02; sigma_theta / Ntilde 0 and 1; 4
    realizations to 30 tau_th, seed 1; ~10 s): strengthening seen where nothing slips, capped where slips renew."""
    study, data = run_quick_study("rejuvenation", tmp_path)
    preset = study.PRESETS["quick"]
    assert len(data["points"]) == len(preset.systems) * len(preset.betas) * len(preset.cycling)
    text = (tmp_path / "rejuvenation_tables.md").read_text()
    # Three tables (full, the ages' tail, the recovery), each a heading, a blank line, two header lines and a
    # row per point.
    assert text.count("\n| ") == 3 * (len(data["points"]) + 2) - 3 and text.count("### ") == 3
    for p in data["points"]:
        assert p["realizations"] == preset.realizations and p["t_end"] == preset.steps
        times = p["times"]
        t_end = f"{p['t_end']:g}"
        age = p["contact_age_end"]
        if p["cycling"] == 0.0:
            # Nothing slips: every contact is as old as the run, and mu_eff rises by exactly what the law
            # adds to every threshold (measured: 0.2061 at beta = 0.02, t = 30), or not at all.
            assert (age["mean"], age["sem"], p["r_node"]["mean"]) == (p["t_end"], 0.0, 0.0)
            rise = times[t_end]["mu_eff"]["mean"] - times["0"]["mu_eff"]["mean"]
            assert math.isclose(rise, p["beta"] * math.log1p(p["t_end"] / p["tau_c"]), rel_tol=1e-9, abs_tol=1e-12)
        else:
            # Slips renew contacts: the mean age stays below the run's duration, and without strengthening
            # cycling lowers mu_eff from its fresh value (measured 0.590 -> 0.570 to 0.583 -> 0.512).
            assert 0.0 < age["mean"] < p["t_end"] and p["r_node"]["mean"] > 0
            if p["beta"] == 0.0:
                assert times[t_end]["mu_eff"]["mean"] < times["0"]["mu_eff"]["mean"]
        # The ages' tail, read from the pooled histogram as bins at every recorded time: ordered, and never
        # above t; the largest is exact (t) only at a bin edge where some contact never slipped.
        ages = p["age_quantiles"]
        assert ages["t"] == p["curves"]["t"]
        for i, t in enumerate(ages["t"]):
            q90, q99, top = ages["q90"][i], ages["q99"][i], ages["max"][i]
            assert q90[0] <= q99[0] <= top[0] <= top[1] <= t and all(lo <= hi for lo, hi in (q90, q99))
            assert ages["max_exact"][i] == (t in (1.0, 10.0) and ages["never_slipped_share"][i] > 0)
        # The injected aging: every point runs select = 1; select = 0.1 at the preset's select_betas only.
        assert set(p["recovery"]) == ({"1", "0.1"} if p["beta"] in preset.select_betas else {"1"})
        for key, rec in p["recovery"].items():
            assert rec["select"] == float(key) and rec["c"] == study.INJECT_C
            assert rec["contact"]["pairs"] == preset.realizations
            assert rec["raised"] == (p["N"] if key == "1" else math.ceil(0.1 * p["N"]))
        if p["cycling"] == 0.0:
            # Nothing slips, the springs stand at rest: the tilt test slides at the weakest threshold, which
            # the injection raises by exactly the shift: recovery 1 with no spread (measured to 4e-15).
            rec = p["recovery"]["1"]["contact"]
            assert math.isclose(rec["recovery"], 1.0, abs_tol=1e-9) and rec["sem"] < 1e-9
            # Every contact as old as the run: the largest age is t_end's bin, and at t = 10 exactly 10.
            i = ages["t"].index(10.0)
            assert ages["max_exact"][i] and ages["never_slipped_share"][i] == 1.0
    # Cycling caps the ages' tail: in the cycled irregular network 99 % of the contacts are younger than the
    # run, by more than a bin (measured: 99th percentile in [5.6, 10) at t = 30, no contact that never slipped
    # at t = 10).
    cycled = next(p for p in data["points"] if (p["kind"], p["beta"], p["cycling"]) == ("irregular", 0.0, 1.0))
    ages = cycled["age_quantiles"]
    assert ages["q99"][-1][1] < 0.5 * cycled["t_end"] and ages["never_slipped_share"][ages["t"].index(10.0)] == 0.0
    # Cycling caps the strengthening: with beta = 0.02 the cycled irregular network ends far below the
    # uncycled one (measured 0.512 against 0.790).
    end = {(p["kind"], p["N"], p["beta"], p["cycling"]): p["times"][f"{p['t_end']:g}"]["mu_eff"]["mean"]
           for p in data["points"]}
    assert end[("irregular", 16, 0.02, 1.0)] < end[("irregular", 16, 0.02, 0.0)] - 0.1
