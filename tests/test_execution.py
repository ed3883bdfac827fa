"""Ensembles at scale: workers, a Dask cluster, checkpoints, resume, streamed results.

The contract tested here: the same configuration gives the same bits on one
worker, on N workers, on a Dask cluster, streamed to a file or kept in
memory, and after any number of kills and resumes.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import signal
import sys
import threading
import types

import netCDF4
import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.ensemble.execution import _lost_message
from slidernet.errors import CheckpointError, ConfigError
from slidernet.io import read_result, write_netcdf

PAIR = {
    "seed": 3, "realizations": 5, "steps": 400, "observables": ["n", "mu_max", "x_G", "mu_eff", "n_records"],
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}
LATTICE = {**PAIR, "steps": 30, "realizations": 3, "observables": ["n", "mu_max", "x_G", "mu_eff", "events"],
           "network": {"kind": "triangular", "shape": [4, 5], "Ntilde": 1e-7},
           "driver": {"name": "gaussian_steps", "sigma_theta": 2e-7}}
SCENES = {"pair": PAIR, "lattice": LATTICE}


def assert_same_bits(a: xr.Dataset, b: xr.Dataset) -> None:
    """Every data variable and coordinate equal to the bit (NaN where the other has NaN); same config."""
    assert set(a.variables) == set(b.variables)
    for name in a.variables:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        assert a[name].dtype == b[name].dtype, name
    assert json.loads(a.attrs["config"]) == json.loads(b.attrs["config"])


@pytest.fixture(scope="module", params=list(SCENES), ids=list(SCENES))
def reference(request):
    """One worker, in memory: the reference bits of each scene."""
    cfg = SCENES[request.param]
    return cfg, slidernet.run(cfg, workers=1)


def test_two_workers_give_the_same_bits(reference):
    cfg, ref = reference
    assert_same_bits(slidernet.run(cfg, workers=2), ref)


def test_streamed_file_is_the_in_memory_result(reference, tmp_path):
    cfg, ref = reference
    with slidernet.run(cfg, workers=2, out=tmp_path) as ds:
        assert_same_bits(ds.load(), ref)
    write_netcdf(ref, tmp_path / "memory.nc")
    assert_same_bits(read_result(tmp_path / "result.nc"), read_result(tmp_path / "memory.nc"))
    assert not (tmp_path / "checkpoint").exists()  # removed once result.nc is written


def test_dask_cluster_gives_the_same_bits(reference):
    distributed = pytest.importorskip("distributed")
    cfg, ref = reference
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc:
        assert_same_bits(slidernet.run(cfg, scheduler=lc.scheduler_address), ref)


def test_more_realizations_than_a_reduction_chunk(tmp_path):
    """2500 realizations (three chunks of the on-the-fly reduction): stored in chunks of 1024 realizations."""
    cfg = {**PAIR, "realizations": 2500, "steps": 20, "observables": ["n", "mu_max", "x_G"]}
    mem = slidernet.run(cfg, workers=2)
    with slidernet.run(cfg, workers=2, out=tmp_path) as ds:
        assert_same_bits(ds.load(), mem)
    x = mem["x_G"].values
    np.testing.assert_allclose(mem["x_G_mean"], x.mean(axis=0), rtol=1e-12, atol=1e-30)
    np.testing.assert_allclose(mem["x_G_sem"], x.std(axis=0, ddof=1) / 50, rtol=1e-10, atol=1e-30)
    with netCDF4.Dataset(tmp_path / "result.nc") as nc:
        assert nc["n"].chunking() == [1024, mem.sizes["t"]]


# Interrupts (Ctrl-C, SIGTERM, kill -9 inside running realizations) are tested in test_interrupts.py.


def test_resume_refuses_another_config(tmp_path):
    out = tmp_path / "out"
    store_dir = out / "checkpoint"
    with pytest.raises(KeyboardInterrupt):
        slidernet.run(PAIR, out=out, workers=1, on_realization=_interrupt_after(2))
    assert (store_dir / "run.json").exists()
    other = {**PAIR, "driver": {"name": "gaussian_steps", "sigma_theta": 2e-6}}
    with pytest.raises(CheckpointError, match=r"driver\.sigma_theta \(1e-06 in the checkpoint, 2e-06 now\)"):
        slidernet.run(other, out=out, resume=True)
    with pytest.raises(CheckpointError, match="realizations"):
        slidernet.run({**PAIR, "realizations": 9}, out=out, resume=True)
    # Another number of workers is not another run.
    with slidernet.run(PAIR, out=out, resume=True, workers=2) as ds:
        assert_same_bits(ds.load(), slidernet.run(PAIR, workers=1))


def _interrupt_after(k: int):
    def hook(r: int) -> None:
        hook.calls += 1
        if hook.calls == k:
            raise KeyboardInterrupt

    hook.calls = 0
    return hook


def test_interrupted_in_process_run_resumes_to_the_same_bits(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt, match="resume"):
        slidernet.run(PAIR, out=out, workers=1, on_realization=_interrupt_after(3))
    stored = json.loads((out / "checkpoint" / "run.json").read_text())
    assert stored["seed"] == 3 and stored["realizations"] == 5 and "execution" not in stored["config"]
    with slidernet.run(PAIR, out=out, resume=True, workers=1) as ds:
        assert_same_bits(ds.load(), slidernet.run(PAIR, workers=1))


def test_fresh_seed_is_kept_across_a_resume(tmp_path):
    cfg = {**PAIR, "seed": None}
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        slidernet.run(cfg, out=out, workers=1, on_realization=_interrupt_after(2))
    seed = json.loads((out / "checkpoint" / "run.json").read_text())["seed"]
    with slidernet.run(cfg, out=out, resume=True, workers=1) as ds:
        assert ds.attrs["seed"] == str(seed)
        assert_same_bits(ds.load(), slidernet.run({**cfg, "seed": seed}, workers=1))


def test_resume_without_a_checkpoint_is_refused(tmp_path):
    with pytest.raises(CheckpointError, match="Nothing to resume"):
        slidernet.run(PAIR, out=tmp_path, resume=True)


@pytest.mark.parametrize("workers", [0, -1, 1.5, True], ids=["zero", "negative", "float", "bool"])
def test_bad_workers_are_refused(workers):
    with pytest.raises(ConfigError, match="'workers' parameter of run must be an integer >= 1"):
        slidernet.run(PAIR, workers=workers)


# "localhost:8786" is accepted, as a Client reads it (tcp): tests/test_config_fields.py has the rule's cases.
@pytest.mark.parametrize("address", ["tcp://localhost", "http://x:1", "tcp://"], ids=["no-port", "http", "empty"])
def test_bad_scheduler_is_refused_before_any_work(address):
    with pytest.raises(ConfigError, match="scheduler"):
        slidernet.run({**PAIR, "execution": {"scheduler": address}})
    with pytest.raises(ConfigError, match="scheduler"):
        slidernet.run(PAIR, scheduler=address)


def test_a_bad_scheduler_argument_says_why():
    with pytest.raises(ConfigError, match=r"^The 'scheduler' parameter of run must be .* Got 'tcp://localhost' "
                                          r"instead: missing port number in address 'localhost'\.$"):
        slidernet.run(PAIR, scheduler="tcp://localhost")


def test_execution_is_not_part_of_the_recorded_config():
    ds = slidernet.run({**PAIR, "realizations": 2, "steps": 10, "execution": {"workers": 2}})
    assert "execution" not in json.loads(ds.attrs["config"])
    assert json.loads(ds.attrs["execution"]) == {"workers": 2, "scheduler": None}


def test_an_interrupted_run_does_not_stop_a_later_one():
    # The stop request belongs to its StopSignal: a module-wide flag left set by an interrupted
    # in-process run (a notebook's Ctrl-C) made later direct calls return nothing.
    from slidernet.ensemble.execution import StopSignal, execute, run_realization

    config_json = json.dumps({**PAIR, "seed": 3})
    with StopSignal() as stop:
        stop.request()
        assert list(execute([0, 1], lambda r: (config_json, 3, r, None, 60.0, None), stop=stop)) == []
    assert run_realization(config_json, 3, 0) is not None
    assert [r for r, _ in execute([0, 1], lambda r: (config_json, 3, r, None, 60.0, None))] == [0, 1]


def test_a_stop_is_seen_inside_a_long_thermal_step(tmp_path):
    # One thermal step of ~1e6 slips: the realization stops at the first buffer refill after the
    # request, within the step, saves there, and resumes to the uninterrupted bits. The request is
    # made by the stop callable itself on its third question (no clock involved).
    from slidernet.config import load_config
    from slidernet.ensemble.execution import run_realization
    from slidernet.io.checkpoint import checkpoint_info
    from slidernet.solver import Scene, simulate

    cfg = {**PAIR, "seed": 4, "steps": 2, "realizations": 1, "observables": ["n", "x_G"],
           "network": {"kind": "chain", "n": 4, "Ntilde": 1e-7}, "driver": {"name": "gaussian_steps",
                                                                         "sigma_theta": 2e-2}}
    cfg_json = json.dumps(cfg)
    asked = []

    def stop() -> bool:
        asked.append(1)
        return len(asked) >= 3

    partial = tmp_path / "partial.npz"
    assert run_realization(cfg_json, 4, 0, str(partial), 1e9, {}, stop=stop) is None
    info = checkpoint_info(partial)
    assert info["step"] == 0 and 0 < info["n"] < 1e6  # stopped inside the first step
    resumed = run_realization(cfg_json, 4, 0, str(partial), 1e9, {})
    scene = Scene.from_config(load_config(cfg))
    expected = simulate(scene, np.random.SeedSequence(4, spawn_key=(0,)))
    for key in ("n", "x_G", "mu_max"):
        np.testing.assert_array_equal(resumed[key], expected[key], strict=True)
    assert resumed["n"][-1] > 3 * scene.batch


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forks a process")
def test_a_killed_worker_is_named_by_its_signal_while_the_pool_collects_its_status():
    # benchmarks/fault_injection.py: a killed worker was now and then said to have "died abruptly": the
    # pool's thread had taken its exit status (waitpid) and not yet recorded it when the message was made.
    worker = multiprocessing.get_context("fork").Process(target=signal.pause)
    worker.start()
    os.kill(worker.pid, signal.SIGKILL)
    os.waitpid(worker.pid, 0)  # the pool's thread takes the status first ...
    record = threading.Timer(0.05, setattr, (worker._popen, "returncode", -signal.SIGKILL))
    record.start()  # ... and records it an instant later
    try:
        message = _lost_message(types.SimpleNamespace(_processes={worker.pid: worker}))
    finally:
        record.join()
    assert message.startswith("A worker process was killed by SIGKILL (by a user, a batch scheduler or the "
                              "out-of-memory killer) during the run")


@pytest.mark.parametrize("given", ["dict", "toml"])
def test_every_path_handed_to_the_tasks_is_absolute(tmp_path, monkeypatch, given):
    # With Dask and a relative --out, the workers wrote their partial files relative to their own working
    # folder: 37 stray files, and nothing in progress reached the user's folder. The same held for a
    # data file named relative to the configuration. Every path is made absolute in the parent.
    from slidernet.cli import main
    from slidernet.ensemble import runner
    from slidernet.plugins.contract import example_file

    (tmp_path / "configs").mkdir()
    (tmp_path / "configs" / "mu_s.txt").write_bytes(open(example_file("mu_s_example.txt"), "rb").read())
    monkeypatch.chdir(tmp_path)
    cfg = {**PAIR, "realizations": 2, "steps": 50}
    handed = []
    real_execute = runner.execute

    def spy(indices, args, *rest, **kwargs):
        handed.extend(args(r) for r in indices)
        return real_execute(indices, args, *rest, **kwargs)

    monkeypatch.setattr(runner, "execute", spy)
    if given == "dict":
        monkeypatch.chdir(tmp_path / "configs")
        cfg["friction"] = {"mu_d": 0.5, "static": {"name": "empirical", "path": "mu_s.txt"}}
        slidernet.run(cfg, out="out", workers=1).close()
        monkeypatch.chdir(tmp_path)
        out = tmp_path / "configs" / "out"
    else:
        toml = "\n".join(f"{k} = {json.dumps(v)}" for k, v in cfg.items() if not isinstance(v, dict)) + (
            '\n[network]\nkind = "two_slider"\nNtilde = 1e-7\n[friction]\nmu_d = 0.5\n[friction.static]\n'
            'name = "empirical"\npath = "mu_s.txt"\n[driver]\nname = "gaussian_steps"\nsigma_theta = 1e-6\n')
        (tmp_path / "configs" / "run.toml").write_text(toml)
        assert main(["run", "configs/run.toml", "--out", "out", "--workers", "1", "--no-progress"]) == 0
        out = tmp_path / "out"
    assert len(handed) == 2
    for config_json, _seed, r, partial, *_ in handed:
        assert partial == str(out / "checkpoint" / f"partial-{r:09d}.npz")
        assert json.loads(config_json)["friction"]["static"]["path"] == str(tmp_path / "configs" / "mu_s.txt")
    assert (out / "result.nc").exists()
