"""The README's API example must run as written (a new user copies it first)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import xarray as xr

import slidernet
from slidernet.analysis import theory
from tests.test_statistics import rule_rate

README = Path(__file__).resolve().parents[1] / "README.md"


def _api_example() -> str:
    text = README.read_text(encoding="utf-8")
    section = text.split("## The API in 20 lines", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_api_example_is_at_most_20_lines():
    assert len(_api_example().strip().splitlines()) <= 20


def test_api_example_runs_as_written_and_its_claims_hold(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # it writes result.nc in the working directory
    ns: dict = {}
    exec(compile(_api_example(), "README.md", "exec"), ns)
    ds = ns["ds"]
    assert ds["n"].dims == ("realization", "t")
    k = int(np.flatnonzero(ds["t"].values == 10_000)[0])
    # It prints what its comments say, from the dataset it made.
    printed = [float(x) for x in capsys.readouterr().out.split()[:3]]
    r, mu_max, mu_eff = float(ds["r_mean"]), float(ds["mu_max_mean"][k]), float(ds["mu_eff"][k])
    assert printed == [r, mu_max, mu_eff]

    # "eq. slope: 53.6", and <r> is the two-slider rule's: its expectation from
    # the rule written in test_statistics, with its own draws (seed 2010, 20 x
    # 10000 steps), within 3 combined standard errors (about 0.5 %).
    assert round(float(theory.mean_rearrangements(1e-6, 1e-7, 0.5, 0.6)), 1) == 53.6
    expected, expected_sem = rule_rate(10.0, 20, 10_000, seed=2010)
    assert abs(r - expected) <= 3 * np.hypot(float(ds["r_sem"]), expected_sem), (r, expected)

    # The aged threshold is the exact mean of the max of n + 2 draws that the
    # example computes, within 3 standard errors of the printed mean.
    assert abs(mu_max - ns["mean"][k]) <= 3 * float(ds["mu_max_sem"][k])
    assert ns["mean"][k] > 0.6 + 4 * 0.01  # aged: far above the mean threshold

    # The README's results: (mu_eff - mean mu_s) / sigma_mu stays negative at
    # every time, and goes from -2.9 at t = 1 to -4.0 at t = 1e5 (values given to
    # 0.1: half a unit of rounding, plus 3 standard errors, allowed).
    z = (ds["mu_eff"].values - 0.6) / 0.01
    z_sem = ds["mu_eff_sem"].values / 0.01
    assert (z + 3 * z_sem < 0).all()
    at_1 = int(np.flatnonzero(ds["t"].values == 1)[0])
    assert abs(z[at_1] - (-2.9)) <= 0.05 + 3 * z_sem[at_1]
    assert -4.05 - 3 * z_sem[k] <= z[k] <= -2.85 + 3 * z_sem[k]

    # "resolved config, version and seed in ds.attrs", written to result.nc.
    back = xr.open_dataset(tmp_path / "result.nc")
    try:
        np.testing.assert_array_equal(back["n"].values, ds["n"].values)
        assert json.loads(back.attrs["config"])["seed"] == 1 == int(back.attrs["seed"])
        assert back.attrs["slidernet_version"] == slidernet.__version__
    finally:
        back.close()


def test_plugin_example_runs_as_written(clean_registries):
    text = README.read_text(encoding="utf-8").split("**Your own plugin.**", 1)[1]
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    exec(compile(code, "README.md", "exec"), {})
    from slidernet.plugins import registry

    assert registry.distributions.origin("my_uniform") == "run time"
