"""The paper-reproduction driver, on a tiny preset (a few seconds)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.io import read_result
from slidernet.paper.reproduction import FULL, QUICK, Preset, _config, reproduce

TINY = Preset(
    name="tiny",
    fig12_sigmas=(1e-7, 1e-6),
    fig12_steps=200,
    fig12_realizations=3,
    fig3a_steps=50,
    fig3a_realizations=3,
    fig3a_points=11,
    fig3b_sigmas=(1e-7, 1e-6, 1e-5),
    fig3b_steps=50,
    fig3b_realizations=2,
    fig4_steps=200,
    fig4_realizations=3,
)

EXPECTED = {
    "fig1_aging.nc": ["n", "n_mean", "mu_max", "mu_max_mean", "mu_max_sem", "r_mean", "mu_max_exact",
                      "mu_max_leading"],
    "fig2_diffusion.nc": ["n", "n_mean", "x_G", "x_G2_mean", "x_G2_sem", "r_mean", "x_G2_law", "records_law"],
    "fig3_rearrangements.nc": ["n", "n_mean", "n_sem", "r_mean", "r_sem", "r_slope", "r_plain"],
    "fig4_mueff.nc": ["mu_eff", "mu_eff_sem", "mu_eff_count", "n_mean", "r_mean", "phi", "mu_max_exact_phi"],
}


@pytest.fixture(scope="module")
def tiny_output(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper")
    return out, reproduce(out, progress=False, _preset=TINY)


def test_writes_all_figures_and_data(tiny_output):
    out, files = tiny_output
    names = {"fig1_aging", "fig2_diffusion", "fig3_rearrangements", "fig4_mueff"}
    expected = {f"{n}.png" for n in names} | {f"{n}.nc" for n in names} | {"summary.json"}
    assert set(files) == expected
    for name, path in files.items():
        assert path == out / name
        assert path.is_file() and path.stat().st_size > 0
    for name in names:
        assert (out / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_data_files_hold_finite_expected_variables(tiny_output, name):
    out, _ = tiny_output
    ds = read_result(out / name)
    for var in EXPECTED[name]:
        assert var in ds, f"{name} lacks {var}"
        assert "units" in ds[var].attrs, f"{name}:{var} has no units"
        values = np.asarray(ds[var].values, dtype=float)
        assert values.size > 0
        if var in ("mu_eff", "mu_eff_sem", "phi"):
            # A bin without any rearrangement is NaN by contract; the rest must be finite.
            assert np.isfinite(values).any(), f"{name}:{var} is all NaN"
            assert not np.isinf(values).any()
        else:
            assert np.isfinite(values).all(), f"{name}:{var} has non-finite values"
    configs = json.loads(ds.attrs["configs"])
    assert configs, "no configurations stored"
    for cfg in configs.values():
        slidernet.load_config(cfg)  # every stored configuration is a valid, runnable one


def test_data_match_the_preset(tiny_output):
    out, _ = tiny_output
    fig1 = read_result(out / "fig1_aging.nc")
    assert fig1["sigma_theta"].values.tolist() == list(TINY.fig12_sigmas)
    assert fig1.sizes["realization"] == TINY.fig12_realizations
    assert int(fig1["t"].values[-1]) == TINY.fig12_steps
    assert (fig1["mu_max"].diff("t") >= 0).all()
    fig3 = read_result(out / "fig3_rearrangements.nc")
    assert fig3.sizes["sigma_theta"] == len(TINY.fig3b_sigmas)
    assert (fig3["r_mean"] > 0).all()
    fig4 = read_result(out / "fig4_mueff.nc")
    assert fig4.sizes["case"] == len(TINY.fig4_mu_ds) * len(TINY.fig4_ratios)
    np.testing.assert_allclose(fig4["sigma_mu"], fig4["ratio"] * (0.6 - fig4["mu_d"]))
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["wall_time_s"]) >= {"fig1_aging", "fig2_diffusion", "fig3_rearrangements", "fig4_mueff",
                                           "total_s"}
    assert summary["preset"]["name"] == "tiny"


def test_progress_callback_does_not_change_the_result():
    # The paper's progress bar hooks into slidernet.run; the dataset must not depend on it.
    cfg = _config(1e-6, 50, 3, seed=7, observables=("n", "mu_max", "x_G", "mu_eff"), points_per_decade=5)
    calls = []
    mine = slidernet.run(cfg, on_realization=calls.append)
    assert sorted(calls) == [0, 1, 2]  # in the order the workers finish
    xr.testing.assert_identical(mine, slidernet.run(cfg))


def test_presets_use_the_captions_parameters():
    for p in (FULL, QUICK):
        assert min(p.fig12_sigmas) == pytest.approx(1e-7) and max(p.fig12_sigmas) == pytest.approx(1e-5)
        assert min(p.fig3b_sigmas) == pytest.approx(1e-7) and max(p.fig3b_sigmas) == pytest.approx(1e-5)
        assert len(p.fig3b_sigmas) >= 8
        assert p.fig4_sigma_theta == 1e-6
        assert set(p.fig4_mu_ds) == {0.5, 0.4} and set(p.fig4_ratios) == {0.1, 0.2, 0.3}


def test_an_interrupted_reproduction_resumes_to_the_same_figures(tmp_path, tiny_output, monkeypatch):
    import signal

    from slidernet.ensemble import runner
    from slidernet.errors import CheckpointError, OutputError, RunInterrupted
    from slidernet.paper import reproduction as paper

    real_run_in = paper.run_in
    calls = []

    def stopped_at_the_third_run(*args, **kwargs):
        calls.append(args[1])
        if len(calls) == 3:  # figures 1 and 2 are done; panel 3a is running
            raise RunInterrupted("stopped", signal.SIGTERM)
        return real_run_in(*args, **kwargs)

    out = tmp_path / "paper"
    monkeypatch.setattr(paper, "run_in", stopped_at_the_third_run)
    with pytest.raises(RunInterrupted, match=r"slidernet paper --out .* --resume") as info:
        reproduce(out, progress=False, _preset=TINY)
    assert info.value.signum == signal.SIGTERM
    with pytest.raises(OutputError, match="interrupted reproduction"):
        reproduce(out, progress=False, _preset=TINY)
    monkeypatch.setattr(paper, "run_in", real_run_in)
    real_run = runner.run
    computed = []

    def counted(cfg, *args, **kwargs):
        computed.append(kwargs["out"].name)
        return real_run(cfg, *args, **kwargs)

    monkeypatch.setattr(runner, "run", counted)
    reproduce(out, progress=False, resume=True, _preset=TINY)
    assert not set(computed) & {p.name for p in calls[:2]}  # the finished runs are read back
    assert calls[2].name in computed
    reference, _ = tiny_output
    for name in EXPECTED:
        a, b = read_result(out / name), read_result(reference / name)
        for var in a.data_vars:
            np.testing.assert_array_equal(a[var].values, b[var].values, err_msg=f"{name}:{var}")
    assert not (out / "runs").exists()
    with pytest.raises(CheckpointError, match="finished"):
        reproduce(out, progress=False, resume=True, _preset=TINY)
