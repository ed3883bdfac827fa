"""Interrupts: Ctrl-C, SIGTERM and kill -9 in the middle of realizations, with one and two workers.

Every test holds the run at a gate (``tests/gated_cli.py``): each running
realization is part-way through and has saved a checkpoint when the test
acts, whatever the speed of the machine. The contract:

- SIGINT and SIGTERM stop the running realizations at their next clean
  point and save them; no queued realization starts; the exit status is
  130 or 143 and the message gives the resume command;
- a second Ctrl-C stops at once and still leaves a consistent folder;
- after any of these (and after kill -9) ``--resume`` gives the bits of an
  uninterrupted run.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from slidernet.ensemble.execution import scene_of
from slidernet.io import read_result

GATED_CLI = Path(__file__).with_name("gated_cli.py")

# Realizations of about 1e5 slips each (an 8 x 8 triangular lattice), the
# event catalogue and the network tilt test on; checkpoints at every chunk;
# threshold draws in small batches, so that the gate falls a few steps in.
LONG = """\
seed = 3
realizations = 4
steps = 60
observables = ["n", "mu_max", "x_G", "mu_eff", "events"]
[network]
kind = "triangular"
shape = [8, 8]
Ntilde = 1e-7
[friction]
mu_d = 0.5
[friction.static]
name = "gated"
[driver]
name = "gaussian_steps"
sigma_theta = 2e-7
[solver]
batch = 256
[execution]
checkpoint_every = 1e-9
"""
GATE_AFTER = 2 * 65_536  # thresholds drawn by a process before it waits: its third raw chunk, steps in


def _cli(*args: str, gate: Path | None = None, fault: str | None = None) -> subprocess.Popen:
    env = {k: v for k, v in os.environ.items() if not k.startswith("SLIDERNET_TEST_GATE")}
    if gate is not None:
        gate.mkdir(exist_ok=True)
        env.update(SLIDERNET_TEST_GATE=str(gate), SLIDERNET_TEST_GATE_AFTER=str(GATE_AFTER))
    if fault is not None:
        env.update(SLIDERNET_TEST_GATE_FAULT=fault)
    return subprocess.Popen([sys.executable, str(GATED_CLI), *args, "--no-progress"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)


def _finish(proc: subprocess.Popen, timeout: float = 300) -> tuple[int, str]:
    try:
        _, err = proc.communicate(timeout=timeout)  # a hang guard, not a speed requirement
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        raise
    return proc.returncode, err


def _wait_at_gate(gate: Path, proc: subprocess.Popen, processes: int) -> None:
    """Wait (on files) until ``processes`` processes of the run stand at the gate."""
    while len(list(gate.glob("waiting-*"))) < processes:
        if proc.poll() is not None:
            pytest.fail(f"the run ended before reaching the gate: {proc.communicate()}")
        time.sleep(0.02)


def _run_at_gate(config: Path, tmp_path: Path, workers: int) -> tuple[Path, Path, subprocess.Popen]:
    """Start ``slidernet run config`` in ``tmp_path/out`` with ``workers`` workers, and wait until each
    worker stands at the gate of ``tmp_path/gate``; the output folder, the gate and the process."""
    out, gate = tmp_path / "out", tmp_path / "gate"
    proc = _cli("run", str(config), "--out", str(out), "--workers", str(workers), gate=gate)
    _wait_at_gate(gate, proc, workers)
    return out, gate, proc


def _assert_same_bits(a_path: Path, b_path: Path) -> None:
    a, b = read_result(a_path), read_result(b_path)
    assert set(a.variables) == set(b.variables)
    for name in a.variables:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    assert json.loads(a.attrs["config"]) == json.loads(b.attrs["config"])


def _assert_consistent(checkpoint: Path) -> None:
    """Only complete files: every npz opens without pickle, no temporary file is left."""
    assert not [p.name for p in checkpoint.iterdir() if p.name.endswith(".tmp")]
    for f in checkpoint.glob("*.npz"):
        with np.load(f, allow_pickle=False) as z:
            [z[k] for k in z.files]


@pytest.fixture(scope="module")
def config(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("interrupts") / "long.toml"
    path.write_text(LONG)
    return path


@pytest.fixture(scope="module")
def stuck_config(config) -> Path:
    """The same run, with a short grace for realizations that do not stop (the execution table: the same run)."""
    path = config.with_name("stuck.toml")
    path.write_text(LONG + "stop_timeout = 0.5\n")
    return path


@pytest.fixture(scope="module")
def reference(config) -> Path:
    """The uninterrupted run (one worker, no gate)."""
    out = config.parent / "reference"
    rc, err = _finish(_cli("run", str(config), "--out", str(out), "--workers", "1"))
    assert rc == 0, err
    return out / "result.nc"


def _resume(config: Path, out: Path, workers: str = "2") -> None:
    rc, err = _finish(_cli("run", str(config), "--out", str(out), "--resume", "--workers", workers))
    assert rc == 0, err
    assert not (out / "checkpoint").exists()


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("workers", [1, 2], ids=["one-worker", "two-workers"])
def test_a_signal_saves_the_running_realizations_and_starts_no_other(tmp_path, config, reference, sig, status,
                                                                      workers):
    out, gate, proc = _run_at_gate(config, tmp_path, workers)
    if sig == signal.SIGINT:
        os.killpg(proc.pid, sig)  # Ctrl-C reaches every process of the terminal's group
    else:
        os.kill(proc.pid, sig)  # a batch scheduler's SIGTERM, to the main process
    (gate / "open").touch()
    rc, err = _finish(proc)
    assert rc == status, err
    assert f"interrupted by {sig.name}" in err and "--resume" in err
    assert f"0 of 4 realizations are finished and {workers} saved in progress" in err
    assert not (out / "result.nc").exists()
    checkpoint = out / "checkpoint"
    _assert_consistent(checkpoint)
    # The running realizations (the first ones handed out) are saved; the queued ones never started.
    assert sorted(p.name for p in checkpoint.glob("partial-*.npz")) == [
        f"partial-{r:09d}.npz" for r in range(workers)]
    for r in range(workers):
        with np.load(checkpoint / f"partial-{r:09d}.npz", allow_pickle=False) as z:
            assert json.loads(bytes(z["header"]).decode())["step"] > 0
    # Without --resume the interrupted run is refused, not overwritten.
    rc, err = _finish(_cli("run", str(config), "--out", str(out)))
    assert rc == 2 and "--resume" in err
    _resume(config, out)
    _assert_same_bits(out / "result.nc", reference)


@pytest.mark.slow
def test_a_second_ctrl_c_stops_at_once_and_leaves_a_consistent_folder(tmp_path, config, reference):
    out, _, proc = _run_at_gate(config, tmp_path, 2)
    os.killpg(proc.pid, signal.SIGINT)
    # Two signals sent at once would merge into one: wait until the first is taken, which slidernet says.
    first = proc.stderr.readline()
    assert "SIGINT received" in first and "again to stop at once" in first
    os.killpg(proc.pid, signal.SIGINT)  # the workers still stand at the gate: only the second signal ends them
    rc, err = _finish(proc)
    assert rc == 130, first + err
    _assert_consistent(out / "checkpoint")
    assert (out / "checkpoint" / "run.json").exists()
    _resume(config, out)
    _assert_same_bits(out / "result.nc", reference)


@pytest.mark.slow
@pytest.mark.parametrize("workers", [1, 2], ids=["one-worker", "two-workers"])
def test_resume_after_kill_9_gives_the_same_bits(tmp_path, config, reference, workers):
    out, _, proc = _run_at_gate(config, tmp_path, workers)
    assert len(list((out / "checkpoint").glob("partial-*.npz"))) == workers
    os.killpg(proc.pid, signal.SIGKILL)  # the whole session, as in a machine failure
    proc.wait()
    assert not (out / "result.nc").exists()
    _assert_consistent(out / "checkpoint")
    _resume(config, out)
    _assert_same_bits(out / "result.nc", reference)


def _gated_on_dask(monkeypatch, gate: Path) -> None:
    """The ``gated`` law registered in this process, whose Dask cluster runs its workers in threads."""
    import importlib.util

    from slidernet.plugins import registry

    spec = importlib.util.spec_from_file_location("gated_cli", GATED_CLI)
    gated = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gated)
    monkeypatch.setitem(registry.distributions._runtime, "gated", gated.Gated)
    # Scenes are cached per process: one built by an earlier test holds that test's law, whose gate its
    # threads (whose identities the cluster's new threads may reuse) have passed.
    scene_of.cache_clear()
    gate.mkdir()
    monkeypatch.setenv("SLIDERNET_TEST_GATE", str(gate))
    monkeypatch.setenv("SLIDERNET_TEST_GATE_AFTER", str(GATE_AFTER))


def _when_at_gate(gate: Path, processes: int, act) -> threading.Thread:
    """A thread that calls ``act()`` once ``processes`` realizations stand at the gate."""
    def wait_and_act() -> None:
        while len(list(gate.glob("waiting-*"))) < processes:
            time.sleep(0.02)
        act()

    thread = threading.Thread(target=wait_and_act, daemon=True)
    thread.start()
    return thread


@pytest.mark.slow
def test_ctrl_c_stops_a_run_on_a_dask_cluster(tmp_path, config, reference, monkeypatch):
    """The workers are threads of a Dask cluster: they learn of the stop through a Dask Event."""
    distributed = pytest.importorskip("distributed")
    import slidernet
    from slidernet.config import tomllib
    from slidernet.errors import RunInterrupted

    gate, out = tmp_path / "gate", tmp_path / "out"
    _gated_on_dask(monkeypatch, gate)
    cfg = tomllib.loads(LONG)

    def press_ctrl_c() -> None:
        os.kill(os.getpid(), signal.SIGINT)  # the run's handler takes it in the main thread
        (gate / "open").touch()

    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        presser = _when_at_gate(gate, 2, press_ctrl_c)
        with pytest.raises(RunInterrupted, match="0 of 4 realizations are finished and 2 saved in progress"):
            slidernet.run(cfg, out=out, scheduler=cluster.scheduler_address)
        presser.join()
    _assert_consistent(out / "checkpoint")
    assert sorted(p.name for p in (out / "checkpoint").glob("partial-*.npz")) == [
        f"partial-{r:09d}.npz" for r in range(2)]
    monkeypatch.delenv("SLIDERNET_TEST_GATE")
    slidernet.run(cfg, out=out, resume=True, workers=1).close()
    _assert_same_bits(out / "result.nc", reference)


@pytest.mark.slow
def test_ctrl_c_ends_a_plugin_that_never_returns_on_a_dask_cluster(tmp_path, config, reference, monkeypatch):
    # Issue 43, item 7, on Dask: a task that never returns holds a worker's thread, which nothing can end from
    # outside; after the grace its future is cancelled and the run ends, saved, within the test's hang guard.
    distributed = pytest.importorskip("distributed")
    import slidernet
    from slidernet.config import tomllib
    from slidernet.errors import RunInterrupted

    gate, out = tmp_path / "gate", tmp_path / "out"
    _gated_on_dask(monkeypatch, gate)
    cfg = tomllib.loads(LONG)
    cfg["execution"]["stop_timeout"] = 0.5
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        presser = _when_at_gate(gate, 2, lambda: os.kill(os.getpid(), signal.SIGINT))
        try:
            ended = (r"interrupted by SIGINT \(the realizations still running after execution\.stop_timeout = "
                     r"0\.5 s were ended; .*0 of 4 realizations are finished and 2 saved in progress")
            with pytest.raises(RunInterrupted, match=ended):
                slidernet.run(cfg, out=out, scheduler=cluster.scheduler_address)
            presser.join()
        finally:
            (gate / "open").touch()  # the cluster's threads end, and the cluster with them
    _assert_consistent(out / "checkpoint")
    monkeypatch.delenv("SLIDERNET_TEST_GATE")
    slidernet.run(cfg, out=out, resume=True, workers=1).close()
    _assert_same_bits(out / "result.nc", reference)


@pytest.mark.slow
def test_a_scheduler_killed_mid_run_is_one_line_and_the_run_resumes(tmp_path, config, reference, monkeypatch):
    # Issue 43, item 8: the scheduler killed mid-run gave "Timed out trying to connect..." after distributed's
    # own ERROR lines and two CancelledError tracebacks, and no word of what was saved. The scheduler and the
    # worker are processes of their own, as on a cluster, so that the scheduler can be killed with SIGKILL.
    pytest.importorskip("distributed")
    import logging

    import slidernet
    from slidernet.config import tomllib
    from slidernet.errors import SchedulerError

    gate, out = tmp_path / "gate", tmp_path / "out"
    _gated_on_dask(monkeypatch, gate)  # the law's name, for the configuration's checks in this process
    preload = tmp_path / "gated_law.py"  # the worker's law, registered as it starts
    preload.write_text(f"import sys\nsys.path.insert(0, {str(GATED_CLI.parent.parent)!r})\n"
                       "import slidernet\nfrom tests.gated_cli import Gated\n"
                       "slidernet.register_distribution('gated', Gated)\n")
    address = tmp_path / "scheduler.json"
    cluster = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
                                 "--no-dashboard", "--scheduler-file", str(address)], start_new_session=True,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    logged: list[logging.LogRecord] = []
    handler = logging.Handler(logging.ERROR)
    handler.emit = logged.append
    client_log = logging.getLogger("distributed.client")  # its own handler: it does not propagate
    try:
        while not address.exists():  # written once the scheduler listens
            assert cluster[0].poll() is None, "the scheduler did not start"
            time.sleep(0.05)
        cluster.append(subprocess.Popen([sys.executable, "-m", "dask", "worker", "--scheduler-file", str(address),
                                         "--nthreads", "2", "--no-nanny", "--no-dashboard", "--preload",
                                         str(preload)], start_new_session=True, stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL))
        killer = _when_at_gate(gate, 2, lambda: os.kill(cluster[0].pid, signal.SIGKILL))
        client_log.addHandler(handler)
        gone = (r"^The Dask scheduler at 'tcp://127\.0\.0\.1:\d+' went away during the run \(.*\)\. 0 of 4 "
                r"realizations are finished and 2 saved in progress in .*; continue with --resume")
        with pytest.raises(SchedulerError, match=gone):
            slidernet.run(tomllib.loads(LONG), out=out, scheduler=json.loads(address.read_text())["address"])
        killer.join()
    finally:
        client_log.removeHandler(handler)
        for proc in cluster:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert not logged, [r.getMessage() for r in logged]
    _assert_consistent(out / "checkpoint")
    monkeypatch.delenv("SLIDERNET_TEST_GATE")
    slidernet.run(tomllib.loads(LONG), out=out, resume=True, workers=1).close()
    _assert_same_bits(out / "result.nc", reference)


# One thermal step of about 1e6 slips per realization (sigma_theta/Ntilde = 2e5 on a chain of 4): a run
# whose every step takes long, as a stuck loop would.
LONG_STEP = """\
seed = 5
realizations = 2
steps = 2
observables = ["n", "mu_max", "x_G"]
[network]
kind = "chain"
n = 4
Ntilde = 1e-7
[friction]
mu_d = 0.5
[friction.static]
name = "gated"
[driver]
name = "gaussian_steps"
sigma_theta = 2e-2
[execution]
checkpoint_every = 1e-9
"""


@pytest.mark.slow
def test_sigterm_stops_a_realization_inside_a_long_thermal_step(tmp_path):
    # The stop is asked wherever the kernel returns to refill a buffer, not only between thermal
    # steps: the realization stops within the step it stands in at the gate, and resumes to the bits.
    # (Before, it ran to the end of the step: a step, or a loop, that never ended could not be stopped.)
    config = tmp_path / "long_step.toml"
    config.write_text(LONG_STEP)
    rc, err = _finish(_cli("run", str(config), "--out", str(tmp_path / "reference"), "--workers", "1"))
    assert rc == 0, err
    out, gate, proc = _run_at_gate(config, tmp_path, 1)
    os.kill(proc.pid, signal.SIGTERM)
    assert "SIGTERM received" in proc.stderr.readline()  # the stop is requested before the gate opens
    (gate / "open").touch()
    rc, err = _finish(proc)
    assert rc == 143, err
    for r in range(1):
        with np.load(out / "checkpoint" / f"partial-{r:09d}.npz", allow_pickle=False) as z:
            header = json.loads(bytes(z["header"]).decode())
        # The gate falls at the first refill of the threshold buffer (65536 slips in); the stop is served
        # at that refill, inside step 0.
        assert header["step"] == 0 and header["n"] == 65_536
    _resume(config, out)
    _assert_same_bits(out / "result.nc", tmp_path / "reference" / "result.nc")


def _gone(pid: int) -> bool:
    """True once process ``pid`` has ended (a zombie not yet reaped by its new parent has ended too)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return True
    return state in ("Z", "X")


def _workers_at(gate: Path) -> list[int]:
    return sorted({int(p.name.split("-")[1]) for p in gate.glob("waiting-*")})


def _wait_until_gone(pids: list[int]) -> list[int]:
    """The processes of ``pids`` still there after a hang guard of 60 s (death by a signal is immediate)."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not all(_gone(p) for p in pids):
        time.sleep(0.02)
    return [p for p in pids if not _gone(p)]


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_workers_die_with_their_parent(tmp_path, config, reference):
    # kill -9 of the parent of a 2-worker run left both workers waiting forever (about 220 MB each).
    out, gate, proc = _run_at_gate(config, tmp_path, 2)
    workers = _workers_at(gate)
    assert len(workers) == 2 and proc.pid not in workers
    os.kill(proc.pid, signal.SIGKILL)  # the parent alone
    proc.wait()
    left = _wait_until_gone(workers)
    for pid in left:  # do not leave them behind when the test fails
        os.kill(pid, signal.SIGKILL)
    assert not left, f"workers {left} outlived their parent"
    _assert_consistent(out / "checkpoint")
    _resume(config, out)
    _assert_same_bits(out / "result.nc", reference)
    assert sorted(p.name for p in out.iterdir()) == ["result.nc"]


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_killed_worker_is_one_line_and_the_run_resumes(tmp_path, config, reference):
    # kill -9 of one worker gave a BrokenProcessPool traceback and exit 1.
    out, gate, proc = _run_at_gate(config, tmp_path, 2)
    killed, other = _workers_at(gate)
    os.kill(killed, signal.SIGKILL)
    (gate / "open").touch()
    rc, err = _finish(proc)
    assert rc == 2 and "Traceback" not in err and err.count("\n") == 1, err
    assert "A worker process was killed by SIGKILL" in err and "0 of 4 realizations are finished and 2 saved " \
        "in progress" in err and "--resume" in err
    assert not _wait_until_gone([other]), "the other worker outlived the run"
    _assert_consistent(out / "checkpoint")
    _resume(config, out)
    _assert_same_bits(out / "result.nc", reference)


@pytest.mark.slow
def test_a_second_run_in_the_folder_of_a_run_still_going_is_refused(tmp_path, config, reference):
    # --resume of a run still going was accepted: every realization was computed twice and the first
    # run then failed. Without --resume the second run said "holds an interrupted run".
    out, gate, proc = _run_at_gate(config, tmp_path, 1)
    try:
        for flags in (["--resume"], [], ["--overwrite"]):
            rc, err = _finish(_cli("run", str(config), "--out", str(out), *flags))
            assert rc == 2 and err.count("\n") == 1, err
            assert f"a slidernet run is still going there (process {proc.pid} holds its lock" in err
    finally:
        (gate / "open").touch()  # the first run goes on to its end, whatever happened
    rc, err = _finish(proc)
    assert rc == 0, err
    _assert_same_bits(out / "result.nc", reference)
    assert sorted(p.name for p in out.iterdir()) == ["result.nc"]


# Issue 43, item 7: a plugin that never returns (the gate never opens) held a run for ever after one SIGTERM or
# SIGINT (10 min seen); a batch system sends one. A second signal ended it, with 2 workers after an
# InvalidStateError traceback from the pool's thread (a queued task's future cancelled by the first signal).
# The hang guard below is the test's only clock: the run must end on its own, after its 0.5 s of grace.
@pytest.mark.slow
@pytest.mark.parametrize("workers", [1, 2], ids=["one-worker", "two-workers"])
def test_one_sigterm_ends_a_plugin_that_never_returns(tmp_path, stuck_config, config, reference, workers):
    out, _, proc = _run_at_gate(stuck_config, tmp_path, workers)
    os.kill(proc.pid, signal.SIGTERM)  # the gate stays closed
    rc, err = _finish(proc, timeout=60)
    assert rc == 143 and "Traceback" not in err and err.count("\n") == 2, err
    assert "SIGTERM received" in err.splitlines()[0]
    assert err.splitlines()[1].startswith(
        "slidernet: interrupted by SIGTERM (the realizations still running after execution.stop_timeout = 0.5 s "
        f"were ended; they resume from their last save): 0 of 4 realizations are finished and {workers} saved in "
        "progress"), err
    _assert_consistent(out / "checkpoint")
    for r in range(workers):  # each at the save it made before the gate
        with np.load(out / "checkpoint" / f"partial-{r:09d}.npz", allow_pickle=False) as z:
            assert json.loads(bytes(z["header"]).decode())["step"] > 0
    _resume(config, out)
    _assert_same_bits(out / "result.nc", reference)


@pytest.mark.slow
def test_a_second_sigterm_while_a_plugin_never_returns_is_one_line(tmp_path, config):
    out, _, proc = _run_at_gate(config, tmp_path, 2)  # the default grace: the second signal ends the run
    os.kill(proc.pid, signal.SIGTERM)
    first = proc.stderr.readline()
    assert "SIGTERM received" in first
    os.kill(proc.pid, signal.SIGTERM)
    rc, err = _finish(proc, timeout=60)
    assert rc == 143 and "Traceback" not in err and err.count("\n") == 1, first + err
    assert err.startswith("slidernet: interrupted by SIGTERM (stopped at once by a second signal; they resume "
                          "from their last save): 0 of 4 realizations are finished and 2 saved in progress"), err
    _assert_consistent(out / "checkpoint")


# Issue 43, items 6 and 8: a plugin that raised was "internal error: this is a bug of slidernet" (exit 1), one
# that called sys.exit(5) ended the command with status 5 and no word, and a plugin's KeyboardInterrupt in a
# worker ended the other workers at once.
GATED_LINE = re.compile(r"line \d+ of gated_cli\.py")


@pytest.mark.slow
@pytest.mark.parametrize(("fault", "status", "line"), [
    ("raise", 2, "slidernet: error: The distribution 'gated' ({path}) failed in sample(): ValueError: the gate's "
                 "fault ({where}). 0 of 4 realizations are finished and {workers} saved in progress"),
    ("exit", 2, "slidernet: error: The distribution 'gated' ({path}) called sys.exit(5) in sample(): a plugin may "
                "not end the process; raise an exception instead. 0 of 4 realizations are finished and {workers} "
                "saved in progress"),
    ("interrupt", 130, "slidernet: interrupted by SIGINT: 0 of 4 realizations are finished and {workers} saved "
                       "in progress"),
], ids=["raises", "sys-exit", "keyboard-interrupt"])
@pytest.mark.parametrize("workers", [1, 2], ids=["one-worker", "two-workers"])
def test_a_plugins_fault_is_one_line_and_leaves_a_resumable_folder(tmp_path, config, reference, fault, status,
                                                                     line, workers):
    out = tmp_path / "out"
    proc = _cli("run", str(config), "--out", str(out), "--workers", str(workers), gate=tmp_path / "gate",
                fault=fault)
    rc, err = _finish(proc, timeout=120)
    assert rc == status and "Traceback" not in err and err.count("\n") == 1, err
    found = GATED_LINE.sub("WHERE", err)
    assert found.startswith(line.format(path=GATED_CLI.resolve(), where="WHERE", workers=workers)), err
    # A plugin's error recurs on the same configuration: the line says what a resume needs, and that a fixed
    # plugin file is another run; a KeyboardInterrupt is a stop, continued with --resume.
    resumes = ("continues them once the cause is fixed outside the configuration and its files; a changed "
               "configuration or plugin file is another run: start it with --overwrite." if status == 2
               else "; continue with --resume on the same command")
    assert "--resume" in err and resumes in err, err
    _assert_consistent(out / "checkpoint")
    assert len(list((out / "checkpoint").glob("partial-*.npz"))) == workers
    if fault == "interrupt" and workers == 2:  # as after Ctrl-C
        _resume(config, out)
        _assert_same_bits(out / "result.nc", reference)
