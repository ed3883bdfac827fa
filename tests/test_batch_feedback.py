"""Feedback that fits a batch job: nearest spellings, errors before heavy imports, progress lines, the compile
notice's measured time, the scheduler's timeout as said."""

from __future__ import annotations

import io
import json
import re
import subprocess
import sys

import pytest

from slidernet import ConfigError, UnknownPluginError
from slidernet.config import load_config
from slidernet.ensemble.progress import Progress
from tests.conftest import make_config

# ---------------------------------------------------------------------------
# nearest spellings


@pytest.mark.parametrize(("key", "match"), [
    pytest.param("realisations", r"Unknown key 'realisations'; did you mean 'realizations'\?$", id="top-level"),
    pytest.param("network.Ntide", r"Unknown key 'Ntide' in \[network\]; did you mean 'Ntilde'\?$", id="network"),
    pytest.param("friction.mud", r"Unknown key 'mud' in \[friction\]; did you mean 'mu_d'\?$", id="friction"),
    pytest.param("solver.max_avalance", r"Unknown key 'max_avalance' in \[solver\]; did you mean "
                                        r"'max_avalanche'\?$", id="solver"),
    pytest.param("execution.worker", r"Unknown key 'worker' in \[execution\]; did you mean 'workers'\?$",
                 id="execution"),
    pytest.param("bogus", r"Unknown key 'bogus'\.$", id="nothing-near"),
])
def test_an_unknown_key_names_the_nearest_spelling(key, match):
    with pytest.raises(ConfigError, match=match):
        load_config(make_config(**{key: 1}))


def test_every_unknown_key_is_listed():
    cfg = make_config(**{"realisations": 2, "network.Ntide": 1e-7})
    with pytest.raises(ConfigError) as info:
        load_config(cfg)
    assert sorted(str(info.value).splitlines()[1:]) == [
        "  - Unknown key 'Ntide' in [network]; did you mean 'Ntilde'?",
        "  - Unknown key 'realisations'; did you mean 'realizations'?"]


@pytest.mark.parametrize(("key", "name", "nearest"), [
    pytest.param("friction.static.name", "gausian", "gaussian", id="distribution"),
    pytest.param("driver.name", "gaussian_step", "gaussian_steps", id="driver"),
])
def test_an_unknown_plugin_name_names_the_nearest(key, name, nearest, clean_registries):
    with pytest.raises(UnknownPluginError, match=rf"Unknown \w+ '{name}'; did you mean '{nearest}'\? Available: "):
        load_config(make_config(**{key: name}))


# ---------------------------------------------------------------------------
# errors in a configuration before the heavy imports

HEAVY = ("numba", "xarray", "distributed", "scipy", "matplotlib", "dask")

# Runs `slidernet run` on a configuration in this process, then prints which heavy modules it had imported.
_RUN_AND_LIST = """
import json, sys
from slidernet.cli import main
status = main(["run", sys.argv[1], "--out", sys.argv[2]])
print(json.dumps({"status": status, "imported": [m for m in sys.argv[3:] if m in sys.modules]}))
"""


PAIR_TOML = """\
seed = 1
{top}
[network]
kind = "two_slider"
{network}
[friction]
mu_d = 0.5
static = {{name = "gaussian", mean = 0.6, std = 0.01}}
[driver]
name = "gaussian_steps"
sigma_theta = 1e-6
"""


@pytest.mark.parametrize(("top", "network"), [
    pytest.param("realisations = 2\nsteps = 10", "Ntilde = 1e-7", id="unknown-key"),
    pytest.param("realizations = 2\nsteps = 10", "Ntide = 1e-7", id="unknown-key-in-table"),
    pytest.param("realizations = 2\nsteps = 0", "Ntilde = 1e-7", id="out-of-range"),
])
def test_a_bad_configuration_is_refused_before_the_heavy_imports(tmp_path, top, network):
    config = tmp_path / "bad.toml"
    config.write_text(PAIR_TOML.format(top=top, network=network))
    proc = subprocess.run([sys.executable, "-c", _RUN_AND_LIST, str(config), str(tmp_path / "out"), *HEAVY],
                          capture_output=True, text=True, timeout=120)
    assert json.loads(proc.stdout) == {"status": 2, "imported": []}, proc.stderr
    assert proc.stderr.startswith("slidernet: error: Invalid configuration:")
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------------------
# a scheduler that does not answer


def test_an_unanswering_scheduler_is_given_the_timeout_the_message_states(monkeypatch):
    import socket

    import distributed

    import slidernet
    from slidernet.ensemble import runner
    from slidernet.errors import SchedulerError

    with socket.socket() as s:  # a local port nobody listens on once this socket is closed
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    given, compiled = [], []
    real = distributed.Client

    def client(address, **kwargs):
        given.append(kwargs.get("timeout"))
        return real(address, **kwargs)

    monkeypatch.setattr(distributed, "Client", client)
    monkeypatch.setattr(runner, "compile_kernels", lambda *a, **k: compiled.append(a))
    address = f"tcp://127.0.0.1:{port}"
    with pytest.raises(SchedulerError, match=rf"^Cannot reach the Dask scheduler at '{address}' within 0\.5 s "
                                             r"\(execution\.scheduler_timeout\): "):
        slidernet.run(make_config(realizations=2, steps=10), scheduler=address, scheduler_timeout=0.5)
    assert given == [0.5]
    assert compiled == []  # connected before the kernels compile: the wait is the one stated


# ---------------------------------------------------------------------------
# progress lines


class _Clock:
    """A clock the test moves: the lines and the estimate's check read it, never the wall time."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _progress(progress=None, stream=None, **options):
    clock, stream = _Clock(), stream if stream is not None else io.StringIO()
    return Progress(4, progress, "realizations", stream=stream, clock=clock, background=False, **options), clock


@pytest.mark.parametrize("progress", [None, True], ids=["none", "true"])
def test_without_a_terminal_progress_is_a_line_at_each_interval(progress):
    bar, clock = _progress(progress)  # a StringIO is not a terminal
    clock.now += 29.0
    bar.update(1, slips=290_000)
    assert bar.stream.getvalue() == ""  # not yet 30 s
    clock.now += 1.0
    bar.tick()
    clock.now += 10.0
    bar.tick()  # 10 s after the line: none
    assert bar.stream.getvalue().splitlines() == [
        "slidernet: realizations 1/4 done (25%), 9.67e+03 slips/s, 30 s elapsed, about 1.5 min left"]


def test_the_interval_is_the_number_given_and_a_last_line_says_where_it_ended():
    bar, clock = _progress(5.0, stream=_Terminal())  # a number: lines even on a terminal
    clock.now += 5.0
    bar.tick()
    bar.update(4, slips=100)
    bar.close()
    assert bar.stream.getvalue().splitlines() == [
        "slidernet: realizations 0/4 done (0%), 5 s elapsed, time left unknown until one finishes",
        "slidernet: realizations 4/4 done (100%), 20 slips/s, 5 s elapsed"]


@pytest.mark.parametrize(("progress", "stream"), [
    pytest.param(False, io.StringIO(), id="off"),
    pytest.param(None, _Terminal(), id="terminal-bar"),
    pytest.param(True, _Terminal(), id="terminal-bar-asked"),
])
def test_no_lines_when_off_or_on_a_terminal(progress, stream):
    bar, clock = _progress(progress, stream=stream)
    clock.now += 100.0
    bar.update(1, slips=10)
    bar.close()
    assert "slidernet: realizations" not in stream.getvalue()


@pytest.mark.parametrize(("done", "at", "said"), [
    pytest.param(1, 70.0, "slidernet: this run is 7.0x slower than estimated (1 of 4 realizations done after "
                          "1.2 min; the estimate was 40 s for all of them).", id="one-done"),
    pytest.param(0, 100.0, "slidernet: this run is at least 10.0x slower than estimated (0 of 4 realizations "
                           "done after 1.7 min; the estimate was 40 s for all of them).", id="none-done"),
])
def test_a_run_behind_its_estimate_says_so_once(done, at, said):
    def behind_lines(progress):
        """The 'slower' lines of a run of 4 realizations (10 s each by the estimate) ticked at ``at`` and later."""
        bar, clock = _progress(progress, estimate=40.0, parallel=1)
        bar.update(done)
        clock.now += at
        bar.tick()
        bar.tick()
        clock.now += 100.0
        bar.tick()
        return [line for line in bar.stream.getvalue().splitlines() if "slower" in line]

    assert behind_lines(False) == []  # progress=False says nothing
    lines = behind_lines(3600.0)
    assert len(lines) == 1 and lines[0].startswith(said)


@pytest.mark.parametrize(("done", "at"), [
    pytest.param(1, 19.0, id="within-2x"),
    pytest.param(0, 59.0, id="too-early-to-judge"),
])
def test_a_run_near_its_estimate_says_nothing(done, at):
    bar, clock = _progress(3600.0, estimate=40.0, parallel=1)
    clock.now -= 100.0  # the check starts after BEHIND_AFTER seconds
    bar.start = clock.now
    bar.update(done)
    clock.now += at
    bar.tick()
    assert "slower" not in bar.stream.getvalue()


def test_a_run_with_its_stderr_in_a_file_writes_progress_lines(tmp_path):
    config = tmp_path / "pair.toml"
    config.write_text(PAIR_TOML.format(top="realizations = 2\nsteps = 20", network="Ntilde = 1e-7"))
    log = tmp_path / "log.txt"
    with log.open("w") as err:
        proc = subprocess.run([sys.executable, "-m", "slidernet", "run", str(config), "--out",
                               str(tmp_path / "out")], stderr=err, stdout=subprocess.PIPE, text=True, timeout=300)
    lines = log.read_text().splitlines()
    assert proc.returncode == 0, lines
    assert re.fullmatch(r"slidernet: realizations 2/2 done \(100%\), \S+ slips/s, \d+ s elapsed", lines[-1]), lines
    assert "it/s" not in log.read_text() and "\r" not in log.read_text()  # no bar in a file


# ---------------------------------------------------------------------------
# the compile notice from the time measured on this machine


@pytest.fixture
def empty_cache(tmp_path, monkeypatch):
    """A kernel cache of its own, empty: no compile time is known."""
    from slidernet.solver import compile as compile_module

    monkeypatch.setattr(compile_module, "cache_dir", lambda: str(tmp_path / "cache"))
    return tmp_path / "cache"


class _Compiles:
    """A realization whose advance() is numba compiling (the event it fires on a cache miss), or not."""

    compiles = True

    def __init__(self, *args) -> None:
        pass

    def advance(self) -> None:
        from numba.core import event

        if self.compiles:
            with event.trigger_event("numba:compile"):
                pass


def test_the_notice_says_the_time_the_last_compile_took_here(empty_cache, monkeypatch):
    from slidernet.solver import compile as compile_module
    from slidernet.solver.scene import Scene

    cfg = load_config(make_config(realizations=1, steps=10))
    scene = Scene.from_config(cfg)
    assert "how long is not known yet on this machine (it is measured this time)" in compile_module.compile_notice(
        scene)
    ticks = iter([100.0, 224.4, 300.0, 301.0])  # each compile's start and end, on the clock the recording reads
    monkeypatch.setattr(compile_module, "Realization", _Compiles)
    monkeypatch.setattr(compile_module, "_clock", lambda: next(ticks))
    notices = []
    assert compile_module.compile_kernels(cfg, notice=notices.append)
    assert len(notices) == 1 and "not known yet" in notices[0]
    assert json.loads((empty_cache / "compile_seconds.json").read_text()) == {compile_module.family(scene): 124.4}
    assert "about 124 s the last time on this machine; later runs load" in compile_module.compile_notice(scene)
    monkeypatch.setattr(_Compiles, "compiles", False)  # loaded from the cache: nothing measured, nothing said
    assert not compile_module.compile_kernels(cfg, notice=notices.append)
    assert len(notices) == 1 and compile_module.compile_times() == {compile_module.family(scene): 124.4}


@pytest.mark.parametrize("content", [
    pytest.param("{not json", id="not-json"),
    pytest.param('["pair"]', id="not-a-table"),
    pytest.param('{"pair": "fast", "1D network": -1}', id="not-seconds"),
])
def test_an_unreadable_record_of_compile_times_counts_as_none(empty_cache, content):
    from slidernet.solver.compile import compile_times

    empty_cache.mkdir()
    (empty_cache / "compile_seconds.json").write_text(content)
    assert compile_times() == {}


def test_a_run_gives_its_progress_the_slow_run_estimate_and_the_slips(monkeypatch):
    import slidernet
    from slidernet.ensemble import runner

    made = []

    class Recorded(Progress):
        def __init__(self, *args, **kwargs) -> None:
            super().__init__(*args, **kwargs, background=False)
            made.append(self)

    estimates = []
    check_run = runner.budget.check_run

    def recorded_check(*args, **kwargs):
        estimates.append(check_run(*args, **kwargs))
        return estimates[-1]

    monkeypatch.setattr(runner, "Progress", Recorded)
    monkeypatch.setattr(runner.budget, "check_run", recorded_check)
    ds = slidernet.run(make_config(realizations=2, steps=50), progress=3600.0, workers=1)
    (bar,) = made
    assert bar.estimate == estimates[0] > 0 and bar.parallel == 1
    assert bar.slips == int(ds["n"].isel(t=-1).sum()) > 0


def test_a_sweep_of_a_configuration_with_a_typo_is_refused_before_the_heavy_imports(tmp_path):
    config = tmp_path / "bad.toml"
    config.write_text(PAIR_TOML.format(top="realisations = 2\nsteps = 10", network="Ntilde = 1e-7"))
    sweep = '["sweep", sys.argv[1], "--set", "driver.sigma_theta=1e-7,1e-6", "--out", sys.argv[2]]'
    code = _RUN_AND_LIST.replace('["run", sys.argv[1], "--out", sys.argv[2]]', sweep)
    proc = subprocess.run([sys.executable, "-c", code, str(config), str(tmp_path / "out"), *HEAVY],
                          capture_output=True, text=True, timeout=120)
    assert json.loads(proc.stdout) == {"status": 2, "imported": []}, proc.stderr
    assert "Unknown key 'realisations'; did you mean 'realizations'?" in proc.stderr
