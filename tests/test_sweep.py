"""Parameter sweeps: parsing ``--set``, the grid, the stacking rules, bitwise equality with plain runs."""

from __future__ import annotations

import copy
import importlib
import json
import re
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.ensemble import runner
from slidernet.ensemble.sweep import _dim_names, parse_grid, parse_set, sweep
from slidernet.errors import CheckpointError, ConfigError, OutputError, RunInterrupted
from slidernet.io import read_result

# sys.modules' entry: ``slidernet.ensemble.sweep`` may name the function once the package exports it.
sweep_module = importlib.import_module("slidernet.ensemble.sweep")

BASE: dict[str, Any] = {
    "seed": 3,
    "realizations": 2,
    "steps": 50,
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}
GRID = {"driver.sigma_theta": [1e-6, 1e-7], "friction.mu_d": [0.5, 0.45]}
# In this process: worker processes would only add their start-up time to these tiny runs.
ONE = {"workers": 1}


def with_values(base: dict[str, Any], **dotted: Any) -> dict[str, Any]:
    """A deep copy of ``base`` with dotted keys set (``**{"friction.mu_d": 0.4}``)."""
    cfg = copy.deepcopy(base)
    for key, value in dotted.items():
        *parents, last = key.split(".")
        table = cfg
        for p in parents:
            table = table.setdefault(p, {})
        table[last] = value
    return cfg


@pytest.fixture(scope="module")
def grid_2x2() -> xr.Dataset:
    return sweep(BASE, GRID, **ONE)


# ---------------------------------------------------------------------------
# parse_set


@pytest.mark.parametrize(("text", "key", "values"), [
    ("driver.sigma_theta=1e-7,3e-7", "driver.sigma_theta", [1e-7, 3e-7]),
    ("steps=100, 1_000", "steps", [100, 1000]),
    ("network.kind=chain,two_slider", "network.kind", ["chain", "two_slider"]),
    ("network.shape=[2, 2],[4,4]", "network.shape", [[2, 2], [4, 4]]),
    ('driver.path="a,b.csv",c.csv', "driver.path", ["a,b.csv", "c.csv"]),
    ("solver.flag=true,false", "solver.flag", [True, False]),
    ("friction.mu_d=.4,0.5", "friction.mu_d", [0.4, 0.5]),
    ("friction.static={name = 'uniform', low = 0.5, high = 0.7}", "friction.static",
     [{"name": "uniform", "low": 0.5, "high": 0.7}]),
], ids=["floats", "ints-with-underscore", "bare-words", "arrays", "quoted-comma", "booleans",
        "python-float", "inline-table"])
def test_parse_set_reads_toml_values(text, key, values):
    assert parse_set(text) == (key, values)
    assert [type(v) for v in parse_set(text)[1]] == [type(v) for v in values]


@pytest.mark.parametrize(("text", "match"), [
    ("driver.sigma_theta", "has no '='"),
    ("driver.sigma_theta=", r"empty value \(value 1\)"),
    ("steps=10,,20", r"empty value \(value 2\)"),
    ("steps=10,", r"empty value \(value 2\)"),
    ("=1,2", "sweep key is empty"),
    ("driver..sigma_theta=1", "not a dotted configuration key"),
    ("network.shape=[2, 2", "unclosed quote or bracket"),
    ("network.kind='chain", "unclosed quote or bracket"),
    ("network.shape=[2 2]", "not a valid TOML value"),
    ("steps=10,20,10", "lists the value 10 twice"),
    ("friction.mu_d=0.5,5e-1", "lists the value 0.5 twice"),
    ("seed=1,2", "'seed' cannot be swept: .*realizations"),
    ("execution.workers=1,2", "'execution.workers' cannot be swept: .*workers="),
    # Once, by its key (issue 37: "Sweep points 0 (realizations=2) and 1 (realizations=3) cannot be stacked:
    # 2 and 3 realizations" named it thrice).
    ("realizations=2,3", r"^The sweep key 'realizations' cannot be swept: the points are stacked along one "
                         r"dimension of independent samples, which has one length; set it once in the "
                         r"configuration\.$"),
], ids=["no-equals", "no-value", "empty-middle", "trailing-comma", "no-key", "bad-key", "open-bracket",
        "open-quote", "bad-toml", "repeated-value", "repeated-float", "seed", "execution", "realizations"])
def test_parse_set_errors(text, match):
    with pytest.raises(ConfigError, match=match):
        parse_set(text)


def test_parse_grid_keeps_order_and_refuses_a_repeated_key():
    assert list(parse_grid(["steps=10,20", "driver.sigma_theta=1e-6"])) == ["steps", "driver.sigma_theta"]
    with pytest.raises(ConfigError, match="'steps' is given twice"):
        parse_grid(["steps=10,20", "friction.mu_d=0.4", "steps=30"])


# ---------------------------------------------------------------------------
# the grid


def test_grid_dims_coords_and_attributes(grid_2x2):
    ds = grid_2x2
    assert ds["n"].dims == ("sigma_theta", "mu_d", "realization", "t")
    assert ds["n_mean"].dims == ("sigma_theta", "mu_d", "t")
    assert ds["r_mean"].dims == ("sigma_theta", "mu_d")
    # In the order given, not sorted.
    assert ds["sigma_theta"].values.tolist() == [1e-6, 1e-7]
    assert ds["mu_d"].values.tolist() == [0.5, 0.45]
    assert ds["sigma_theta"].attrs["sweep_key"] == "driver.sigma_theta"
    assert ds.sizes["realization"] == BASE["realizations"]
    assert int(ds["t"][-1]) == BASE["steps"]
    assert json.loads(ds.attrs["sweep"]) == GRID
    assert json.loads(ds.attrs["config"]) == BASE
    assert ds.attrs["seed"] == "3" and ds.attrs["kernel"] == "pair"
    assert ds.attrs["slidernet_version"] == slidernet.__version__
    # C order: the last key varies fastest.
    configs = json.loads(ds.attrs["configs"])
    assert [(c["driver"]["sigma_theta"], c["friction"]["mu_d"]) for c in configs] == [
        (1e-6, 0.5), (1e-6, 0.45), (1e-7, 0.5), (1e-7, 0.45)]
    assert all(np.isfinite(ds[v].values).all() for v in ds.data_vars if v != "r_sem")


def test_each_point_is_the_plain_run_of_its_config_to_the_bit(grid_2x2):
    configs = json.loads(grid_2x2.attrs["configs"])
    for i, (sigma, mu_d) in enumerate([(s, m) for s in GRID["driver.sigma_theta"] for m in GRID["friction.mu_d"]]):
        plain = slidernet.run(with_values(BASE, **{"driver.sigma_theta": sigma, "friction.mu_d": mu_d}), **ONE)
        point = grid_2x2.sel(sigma_theta=sigma, mu_d=mu_d, drop=True)
        assert set(point.data_vars) == set(plain.data_vars)
        for name in plain.data_vars:
            np.testing.assert_array_equal(point[name].values, plain[name].values, err_msg=name)
            assert point[name].dtype == plain[name].dtype
        for name in plain.coords:
            xr.testing.assert_identical(point[name], plain[name])
        assert configs[i] == json.loads(plain.attrs["config"])


def test_a_fresh_seed_is_drawn_once_and_shared():
    ds = sweep(with_values(BASE, seed=None), {"friction.static.std": [0.01, 0.02]}, **ONE)
    seeds = {c["seed"] for c in json.loads(ds.attrs["configs"])}
    assert seeds == {int(ds.attrs["seed"])}
    plain = slidernet.run(with_values(BASE, seed=int(ds.attrs["seed"]), **{"friction.static.std": 0.02}), **ONE)
    np.testing.assert_array_equal(ds["n"].sel(std=0.02).values, plain["n"].values)


def test_progress_callback_sees_every_realization_of_every_point():
    calls: list[tuple[int, int]] = []
    grid = {"driver.sigma_theta": [1e-7, 1e-6]}
    ds = sweep(BASE, grid, progress=True, on_realization=lambda i, r: calls.append((i, r)), **ONE)
    assert calls == [(0, 0), (0, 1), (1, 0), (1, 1)]
    xr.testing.assert_identical(ds, sweep(BASE, grid, **ONE))


def test_steps_swept_are_cut_at_the_fewest_steps():
    base = with_values(BASE, record="all")
    ds = sweep(base, {"steps": [30, 20]}, **ONE)
    assert ds["t"].values.tolist() == list(range(21))
    for steps in (30, 20):
        plain = slidernet.run(with_values(base, steps=steps), **ONE)
        np.testing.assert_array_equal(ds["n"].sel(steps=steps).values, plain["n"].values[:, :21])
        # Scalars are each point's own, over its full run.
        assert float(ds["r_mean"].sel(steps=steps)) == float(plain["r_mean"])


def test_log_recording_sweeps_steps_over_whole_decades():
    ds = sweep(BASE, {"steps": [1000, 100]}, **ONE)
    plain = slidernet.run(with_values(BASE, steps=100), **ONE)
    np.testing.assert_array_equal(ds["t"].values, plain["t"].values)


def test_string_coordinates_and_a_taken_name(tmp_path):
    # 'n' is a variable of the result, so the dim of network.n is the full key.
    ds = sweep(with_values(BASE, network={"kind": "chain", "n": 3, "Ntilde": 1e-7}),
               {"network.n": [3], "solver.slip": ["straight", "exact"]}, **ONE)
    assert ds["n"].dims[:2] == ("network.n", "slip")
    assert ds["slip"].values.tolist() == ["straight", "exact"]


@pytest.mark.parametrize(("keys", "taken", "names"), [
    (["driver.sigma_theta", "friction.mu_d"], {"n", "t"}, ["sigma_theta", "mu_d"]),
    (["a.mean", "b.mean", "c.std"], set(), ["a.mean", "b.mean", "std"]),
    (["network.n"], {"n", "t"}, ["network.n"]),
], ids=["last-component", "shared-last-component", "taken-by-a-variable"])
def test_dim_names(keys, taken, names):
    assert _dim_names(keys, taken) == names


def test_a_config_file_and_a_base_invalid_alone(tmp_path):
    path = tmp_path / "base.toml"
    path.write_text('seed = 3\nrealizations = 2\nsteps = 50\n[network]\nkind = "two_slider"\nNtilde = 1e-7\n'
                    '[friction]\nmu_d = 0.5\n[friction.static]\nname = "gaussian"\nmean = 0.6\nstd = 0.01\n'
                    '[driver]\nname = "gaussian_steps"\n')
    ds = sweep(path, {"driver.sigma_theta": [1e-6]}, **ONE)
    plain = slidernet.run(BASE, **ONE)
    np.testing.assert_array_equal(ds["n"].values[0], plain["n"].values)


# ---------------------------------------------------------------------------
# refused before any work


@pytest.fixture
def no_work(monkeypatch):
    def fail(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("the runner was called")
    monkeypatch.setattr(runner, "run", fail)


@pytest.mark.parametrize(("base", "grid", "match"), [
    (BASE, {"driver.sigma_theta": [1e-6, -1e-6]},
     r"Sweep point 1 \(driver.sigma_theta=-1e-06\): .*'sigma_theta' parameter of gaussian_steps must be > 0"),
    (BASE, {"friction.mu_d": [0.5], "network.kind": ["two_slider", "triangle"]},
     r"(?s)Sweep point 1 \(friction.mu_d=0.5, network.kind='triangle'\): .*'network.kind'"),
    (BASE, {"steps": [50, 200]}, r"Sweep points 0 \(steps=50\) and 1 \(steps=200\) cannot be stacked: .*times"),
    (BASE, {"realizations": [2, 3]}, "'realizations' cannot be swept"),
    (BASE, {"observables": [["n"], ["n", "x_G"]]}, "observables"),
    (with_values(BASE, observables=["n", "mu_eff"], network={"kind": "chain", "n": 2, "Ntilde": 1e-7}),
     {"network.n": [2, 4]},
     r"'mu_eff' is measured at the rearrangements in point 0 .* at the records in point 1 "
     r".*mu_eff_at = \"records\""),
    (with_values(BASE, network={"kind": "chain", "n": 3, "Ntilde": 1e-7}), {"observables": [["n", "events"]]},
     "'events' observable"),
    (BASE, {"steps.x": [1, 2]}, r"'steps.x' needs 'steps' to be a table"),
    (BASE, {"driver": [{"name": "gaussian_steps", "sigma_theta": 1e-6}], "driver.sigma_theta": [1e-6]},
     "overlap"),
    (BASE, {"steps": 50}, "must map to a sequence"),
    (BASE, {}, "at least one key"),
], ids=["invalid-value", "invalid-last-point", "times-differ", "realizations", "observables", "tilt-tests",
        "events", "not-a-table", "overlapping-keys", "not-a-sequence", "empty"])
def test_refused_before_any_work(no_work, base, grid, match):
    with pytest.raises(ConfigError, match=match):
        sweep(base, grid, **ONE)


@pytest.mark.parametrize(("grid", "refused"), [
    ({"driver.sigma_theta": [1e-7, 1e-6], "driver.sigma": [1.0]}, ["sigma"]),
    ({"friction.static.std": [0.01, 0.02], "friction.static.stdd": [0.01]}, ["stdd"]),
], ids=["driver", "distribution"])
def test_a_bad_key_swept_beside_a_good_one_is_the_only_one_refused(no_work, grid, refused):
    # The message used to list every key of the plugin's table, the right one among them.
    with pytest.raises(ConfigError, match=r"^Sweep point 0 \(") as info:
        sweep(BASE, grid, **ONE)
    listed = re.search(r"does not accept (\[.*?\])", str(info.value)).group(1)
    assert listed == str(refused), str(info.value)


# ---------------------------------------------------------------------------
# output folder


def test_out_folder_holds_every_point_and_the_result(tmp_path):
    grid = {"driver.sigma_theta": [1e-7, 1e-6]}
    ds = sweep(BASE, grid, out=tmp_path, **ONE)
    assert json.loads((tmp_path / "sweep.json").read_text())["sweep"] == grid
    xr.testing.assert_identical(read_result(tmp_path / "result.nc"), ds)
    point = read_result(tmp_path / "points" / "1" / "result.nc")
    xr.testing.assert_identical(point["n"], ds["n"].sel(sigma_theta=1e-6, drop=True))
    xr.testing.assert_identical(ds, sweep(BASE, grid, **ONE).assign_attrs(execution=ds.attrs["execution"]))
    with pytest.raises(OutputError, match="holds a finished sweep; it is not replaced silently"):
        sweep(BASE, grid, out=tmp_path, **ONE)
    with pytest.raises(CheckpointError, match=r"the grid differs"):
        sweep(BASE, {"driver.sigma_theta": [1e-7, 3e-6]}, out=tmp_path, resume=True, **ONE)
    with pytest.raises(CheckpointError, match="Nothing to resume"):
        sweep(BASE, grid, out=tmp_path / "elsewhere", resume=True, **ONE)
    # --overwrite replaces a finished sweep with another one.
    other = {"driver.sigma_theta": [2e-7, 1e-6]}
    replaced = sweep(BASE, other, out=tmp_path, overwrite=True, **ONE)
    xr.testing.assert_identical(read_result(tmp_path / "result.nc"), replaced)
    assert replaced["sigma_theta"].values.tolist() == [2e-7, 1e-6]


def _killed_at_point(k: int) -> Callable[..., xr.Dataset]:
    """``runner.run`` that raises KeyboardInterrupt, as Ctrl-C would, when point ``k`` (from 0) starts."""
    real_run = runner.run
    calls: list[int] = []

    def run(cfg, *args, **kwargs):
        calls.append(1)
        if len(calls) == k + 1:
            raise KeyboardInterrupt
        return real_run(cfg, *args, **kwargs)

    return run


def test_a_killed_sweep_resumes_to_the_same_bits(tmp_path, monkeypatch):
    grid = {"driver.sigma_theta": [1e-7, 3e-7, 1e-6]}
    base = with_values(BASE, seed=None)  # the seed drawn at the start must be the one resumed with
    real_run = runner.run
    monkeypatch.setattr(runner, "run", _killed_at_point(2))
    with pytest.raises(RunInterrupted, match=r"2 of 3 sweep points are done.*--resume"):
        sweep(base, grid, out=tmp_path, **ONE)
    reruns: list[dict] = []

    def counted(cfg, *args, **kwargs):
        reruns.append(cfg.driver.params)
        return real_run(cfg, *args, **kwargs)

    monkeypatch.setattr(runner, "run", counted)
    seen: list[tuple[int, int]] = []
    resumed = sweep(base, grid, out=tmp_path, resume=True, on_realization=lambda i, r: seen.append((i, r)), **ONE)
    assert [p["sigma_theta"] for p in reruns] == [1e-6]  # the finished points are read back
    assert sorted(seen) == [(i, r) for i in range(3) for r in range(2)]
    seed = json.loads((tmp_path / "sweep.json").read_text())["seed"]
    assert resumed.attrs["seed"] == str(seed)
    fresh = sweep(with_values(BASE, seed=seed), grid, **ONE)
    for name in fresh.data_vars:
        np.testing.assert_array_equal(resumed[name].values, fresh[name].values, err_msg=name)


def test_the_paper_figure_3b_sweep_fills_its_progress_bar(tmp_path):
    # paper.reproduce drives one bar over every job; the sweep of panel b must add exactly its jobs' cost.
    from slidernet.paper.reproduction import _config, _Job, _Runner

    jobs = [_Job(f"sweep_sigma_theta={s:g}", _config(s, 50, 2, 201, observables=("n",))) for s in (1e-7, 1e-6)]
    bar_owner = _Runner(jobs, progress=True, runs=tmp_path, resume=False)
    ds = bar_owner.sweep(jobs, "driver.sigma_theta", "fig3b")
    assert bar_owner.bar.done == bar_owner.bar.total == sum(j.cost for j in jobs)
    assert ds["sigma_theta"].values.tolist() == [1e-7, 1e-6]
    bar_owner.close()


def test_cli_sweep_writes_one_dataset_with_the_swept_dims(tmp_path, capsys):
    from slidernet.cli import main

    config = tmp_path / "base.toml"
    config.write_text('seed = 1\nrealizations = 2\nsteps = 50\n[network]\nkind = "two_slider"\nNtilde = 1e-7\n'
                      '[friction]\nmu_d = 0.5\n[friction.static]\nname = "gaussian"\nmean = 0.6\nstd = 0.01\n'
                      '[driver]\nname = "gaussian_steps"\nsigma_theta = 1e-6\n')
    argv = ["sweep", str(config), "--set", "driver.sigma_theta=1e-7,1e-6", "--set", "friction.mu_d=0.45,0.5",
            "--out", str(tmp_path / "out"), "--workers", "1", "--no-progress"]
    assert main(argv) == 0
    assert "2 sigma_theta x 2 mu_d points" in capsys.readouterr().out
    ds = read_result(tmp_path / "out" / "result.nc")
    assert ds["n"].dims == ("sigma_theta", "mu_d", "realization", "t")
    assert main([*argv[:3], "driver.sigma_theta=1e-7", "--set", "driver.sigma_theta=2", *argv[6:]]) == 2
    assert "given twice" in capsys.readouterr().err


@pytest.mark.parametrize("text", ["[]", "{}"], ids=["list", "empty-object"])
def test_a_damaged_sweep_json_is_one_line(tmp_path, text):
    # sweep.json holding [] gave an AttributeError traceback.
    grid = {"driver.sigma_theta": [1e-7, 1e-6]}
    sweep(BASE, grid, out=tmp_path, **ONE)
    (tmp_path / "sweep.json").write_text(text)
    with pytest.raises(CheckpointError, match=r"sweep\.json' does not identify a sweep .*--overwrite"):
        sweep(BASE, grid, out=tmp_path, resume=True, **ONE)


def test_a_sweep_still_going_is_not_touched(tmp_path):
    # A second sweep in the folder of one still going (even with --overwrite) is refused before it
    # removes or writes anything.
    from slidernet.errors import FolderInUseError
    from slidernet.io.store import FolderLock

    grid = {"driver.sigma_theta": [1e-7, 1e-6]}
    sweep(BASE, grid, out=tmp_path, **ONE)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    with FolderLock(tmp_path, "sweep"):  # held as the sweep still going holds it
        for flags in ({"overwrite": True}, {"resume": True}):
            with pytest.raises(FolderInUseError, match="a slidernet sweep is still going there"):
                sweep(BASE, grid, out=tmp_path, **flags, **ONE)
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


def test_a_finished_point_computed_from_an_input_file_since_changed_is_refused(tmp_path, monkeypatch):
    # The finished points of a killed sweep are read back on resume: one computed from a data file that
    # has changed since would be stacked beside points computed from the new contents.
    from slidernet.plugins.contract import example_file

    data = tmp_path / "mu_s.txt"
    data.write_text(open(example_file("mu_s_example.txt")).read())
    base = with_values(BASE, **{"friction.static": {"name": "empirical", "path": str(data)}})
    grid = {"driver.sigma_theta": [1e-7, 1e-6]}
    with monkeypatch.context() as patched:
        patched.setattr(runner, "run", _killed_at_point(1))
        with pytest.raises(RunInterrupted, match="1 of 2 sweep points are done"):
            sweep(base, grid, out=tmp_path / "out", **ONE)
    data.write_text(data.read_text() + "0.7\n")
    with pytest.raises(CheckpointError, match=r"points/0/result\.nc' was computed from other contents of the "
                                              rf"input files than they hold now: '{re.escape(str(data))}'"):
        sweep(base, grid, out=tmp_path / "out", resume=True, **ONE)
