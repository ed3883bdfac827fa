"""The command's exit status, one rule for every subcommand (slidernet/cli.py's docstring), and its start-up.

- 2: something the user can change (the configuration, a file or a folder, the machine's memory), one line;
- 1: a bug of slidernet's, with Python's traceback and a line asking to report it;
- 128 + the signal: stopped by a signal, Ctrl-C included while the command starts (issue 37: a
  ``KeyboardInterrupt`` traceback), a closed output pipe (141).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from slidernet import cli
from slidernet.errors import SlowRunWarning
from tests.test_output_folders import SMALL  # a run of two sliders, 2 realizations of 50 steps

# Runs the command with a finder in front of Python's import system that sends SIGINT (or the signal named by
# SLIDERNET_TEST_SIGNAL) to this process when the module named by argv[1] is about to be imported: Ctrl-C at a
# known point of the start-up, on any machine.
CTRL_C_AT_IMPORT = textwrap.dedent("""\
    import importlib.abc, os, signal, sys
    SIGNAL = getattr(signal, os.environ.get("SLIDERNET_TEST_SIGNAL", "SIGINT"))

    # Python's own Ctrl-C handler, as in a terminal: a process started in the background by a shell without job
    # control (nohup, `cmd &` in a script, some CI runners) inherits SIGINT ignored, and would never see it.
    signal.signal(signal.SIGINT, signal.default_int_handler)

    class CtrlC(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path, target=None):
            if name == sys.argv[1]:
                os.kill(os.getpid(), SIGNAL)  # Python runs the handler (KeyboardInterrupt) at its next check
            return None

    sys.meta_path.insert(0, CtrlC())
    from slidernet.cli import main
    sys.exit(main(sys.argv[2:]))
""")


@pytest.mark.parametrize(("module", "command", "line"), [
    ("slidernet.model.units", ["units", "--material", "steel", "--size", "0.1m"],
     "slidernet: {what} while starting; nothing was done."),
    ("xarray", ["run", "CONFIG", "--out", "OUT", "--no-progress"],
     "slidernet: {what}; files already written are complete, nothing else was saved."),
], ids=["building-the-parser", "importing-the-runner"])
@pytest.mark.parametrize(("name", "what", "status"), [("SIGINT", "interrupted", 130),
                                                      ("SIGTERM", "terminated by SIGTERM", 143)],
                         ids=["ctrl-c", "sigterm"])
def test_a_signal_while_the_command_starts_is_one_line_and_its_status(tmp_path, module, command, line, name, what,
                                                                      status):
    # SIGTERM (a batch system's) ended the command with no word before a run had started.
    config = tmp_path / "small.toml"
    config.write_text(SMALL)
    args = [str(config) if a == "CONFIG" else str(tmp_path / "out") if a == "OUT" else a for a in command]
    proc = subprocess.run([sys.executable, "-c", CTRL_C_AT_IMPORT, module, *args], capture_output=True,
                          text=True, timeout=120, env={**os.environ, "SLIDERNET_TEST_SIGNAL": name})
    assert proc.returncode == status, proc.stderr
    assert proc.stderr.strip().splitlines() == [line.format(what=what)], proc.stderr
    assert not (tmp_path / "out").exists()


def test_an_output_pipe_closed_before_the_command_writes_exits_141(tmp_path):
    read, write = os.pipe()
    os.close(read)  # every write to the pipe now fails (EPIPE): no race with a reader
    try:
        proc = subprocess.run([sys.executable, "-m", "slidernet", "units", "--material", "steel",
                               "--size", "0.1m"], stdout=write, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write)
    assert proc.returncode == 141, proc.stderr
    assert proc.stderr == "slidernet: error: the output pipe was closed before everything was written.\n"


def _status_and_lines(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, list[str]]:
    status = cli.main(argv)
    return status, capsys.readouterr().err.strip().splitlines()


@pytest.mark.parametrize(("error", "line"), [
    (PermissionError(13, "Permission denied", "/data/run.toml"),
     "slidernet: error: '/data/run.toml': Permission denied"),
    (IsADirectoryError(21, "Is a directory", "/data/runs"), "slidernet: error: '/data/runs': Is a directory"),
    (OSError(28, "No space left on device"), "slidernet: error: No space left on device"),
    (MemoryError("Unable to allocate 7.28 TiB for an array with shape (1000000000000,) and data type float64"),
     "slidernet: error: out of memory (Unable to allocate 7.28 TiB for an array with shape (1000000000000,) "
     "and data type float64): the run needs more memory than this machine had free; run fewer workers or a "
     "smaller configuration."),
], ids=["no-permission", "a-folder", "disk-full", "out-of-memory"])
def test_a_file_or_memory_error_is_one_line_and_exit_2(monkeypatch, capsys, error, line):
    # Issue 37: file errors exited 1 (an OSError) or 2 (a ConfigError) depending on where they were found.
    def fail(args: object) -> int:
        raise error

    monkeypatch.setattr(cli, "_cmd_units", fail)
    assert _status_and_lines(capsys, ["units", "--size", "0.1m"]) == (2, [line])


def test_a_folder_given_as_the_configuration_exits_2(tmp_path, capsys):
    status, lines = _status_and_lines(capsys, ["run", str(tmp_path), "--out", str(tmp_path / "out")])
    assert (status, lines) == (2, [f"slidernet: error: The configuration file {str(tmp_path)!r} is a folder, "
                                   "not a file."])


def test_a_bug_shows_its_traceback_asks_to_report_it_and_exits_1(monkeypatch, capsys):
    def fail(args: object) -> int:
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(cli, "_cmd_units", fail)
    status, lines = _status_and_lines(capsys, ["units", "--size", "0.1m"])
    assert status == 1
    assert lines[0] == "Traceback (most recent call last):" and "ZeroDivisionError: a bug" in lines
    assert lines[-1] == ("slidernet: internal error: this is a bug of slidernet; please report it with the "
                         "lines above.")


def test_a_warning_of_slidernet_is_one_line(monkeypatch, capsys):
    import warnings

    def warn(args: object) -> int:
        warnings.warn("This run would take about 3 hours.", SlowRunWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(cli, "_cmd_units", warn)
    assert _status_and_lines(capsys, ["units", "--size", "0.1m"]) == (
        0, ["slidernet: warning: This run would take about 3 hours."])


def test_python_m_slidernet_is_the_same_command():
    proc = subprocess.run([sys.executable, "-m", "slidernet", "run", str(Path("no-such.toml")), "--out", "x"],
                          capture_output=True, text=True, timeout=120)
    assert (proc.returncode, proc.stderr) == (2, "slidernet: error: The configuration file 'no-such.toml' does "
                                                 "not exist.\n")
