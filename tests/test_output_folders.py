"""Output folders and command-line failures behave as users expect.

- A run that fails before any work is done leaves the folder as it found it.
- A finished result is never replaced silently; ``--overwrite`` replaces it.
- Bad paths, an unreachable scheduler and a closed pipe give one line, a
  non-zero exit and no traceback.
- Progress bars appear only on a terminal, and never with ``--no-progress``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import slidernet
from slidernet.cli import main
from slidernet.errors import OutputError, PluginError

SMALL = """\
seed = 1
realizations = 2
steps = 50
[network]
kind = "two_slider"
Ntilde = 1e-7
[friction]
mu_d = 0.5
[friction.static]
name = "gaussian"
mean = 0.6
std = 0.01
[driver]
name = "gaussian_steps"
sigma_theta = 1e-6
"""


@pytest.fixture
def config(tmp_path) -> Path:
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    return path


def _tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*")) if folder.exists() else []


def _one_line_error(capsys, status: int, expected_status: int = 2) -> str:
    err = capsys.readouterr().err
    assert status == expected_status, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


class _Broken:
    """A distribution plugin that fails on its first draw (after the config is valid)."""

    def sample(self, rng, size):
        raise PluginError("broken on purpose")

    # All of its mass between mu_d = 0.5 and 1 (a law above 1e150 is refused as the config is loaded).
    def cdf(self, x):
        return 1.0 - self.sf(x)

    def sf(self, x):
        return (np.asarray(x, dtype=float) < 1.0) * 1.0


@pytest.mark.parametrize("existing", [False, True], ids=["new-folder", "folder-with-files"])
def test_a_run_that_fails_before_any_work_leaves_the_folder_as_found(tmp_path, existing, monkeypatch):
    from slidernet.plugins import registry

    monkeypatch.setitem(registry.distributions._runtime, "broken_for_test", _Broken)
    out = tmp_path / "out"
    if existing:
        out.mkdir()
        (out / "notes.txt").write_text("mine")
    before = _tree(out)
    cfg = {**_dict(SMALL), "friction": {"mu_d": 0.5, "static": {"name": "broken_for_test"}}}
    with pytest.raises(PluginError, match="broken on purpose"):
        slidernet.run(cfg, out=out, workers=1)
    assert _tree(out) == before
    assert out.exists() == existing


def _dict(text: str) -> dict:
    from slidernet.config import tomllib

    return tomllib.loads(text)


def test_an_unreachable_scheduler_is_one_line_and_leaves_no_folder(tmp_path, config, capsys):
    out = tmp_path / "out"
    status = main(["run", str(config), "--out", str(out), "--scheduler", "tcp://127.0.0.1:1",
                   "--scheduler-timeout", "0.5", "--no-progress"])
    line = _one_line_error(capsys, status)
    assert "Cannot reach the Dask scheduler at 'tcp://127.0.0.1:1' within 0.5 s" in line
    assert not out.exists()


def test_a_finished_result_is_refused_then_replaced_with_overwrite(tmp_path, config, capsys):
    out = tmp_path / "out"
    assert main(["run", str(config), "--out", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    first = (out / "result.nc").read_bytes()
    other = tmp_path / "other.toml"
    other.write_text(SMALL.replace("seed = 1", "seed = 2"))
    line = _one_line_error(capsys, main(["run", str(other), "--out", str(out), "--no-progress"]))
    assert "holds a finished result" in line and "--overwrite" in line
    assert (out / "result.nc").read_bytes() == first and not (out / "checkpoint").exists()
    assert main(["run", str(other), "--out", str(out), "--no-progress", "--overwrite"]) == 0
    with slidernet.run(_dict(SMALL.replace("seed = 1", "seed = 2"))) as expected:
        got = slidernet.io.read_result(out / "result.nc")
        assert got.attrs["seed"] == "2"
        assert (got["n"].values == expected["n"].values).all()
    line = _one_line_error(capsys, main(["run", str(other), "--out", str(out), "--resume", "--no-progress"]))
    assert "Nothing to resume" in line and "finished" in line


def test_overwrite_from_python_and_its_refusal(tmp_path):
    cfg = _dict(SMALL)
    slidernet.run(cfg, out=tmp_path).close()
    with pytest.raises(OutputError, match="not replaced silently"):
        slidernet.run(cfg, out=tmp_path)
    slidernet.run(cfg, out=tmp_path, overwrite=True).close()


@pytest.mark.parametrize("kind", ["file", "under-a-file", "unwritable"])
def test_bad_output_paths_are_one_line(tmp_path, config, capsys, kind):
    afile = tmp_path / "afile"
    afile.write_text("x")
    out = {"file": afile, "under-a-file": afile / "sub", "unwritable": tmp_path / "ro" / "out"}[kind]
    if kind == "unwritable":
        if os.geteuid() == 0:
            out = Path("/proc/slidernet-test/out")  # root may write anywhere but in /proc
        else:
            (tmp_path / "ro").mkdir(mode=0o500)
    line = _one_line_error(capsys, main(["run", str(config), "--out", str(out), "--no-progress"]))
    assert str(out) in line or str(afile) in line or "/proc/slidernet-test" in line
    assert afile.read_text() == "x"


def test_a_closed_pipe_is_one_line():
    proc = subprocess.run(f"{sys.executable} -m slidernet.cli units --material steel --size 0.1 --delta-T 0.01 "
                          "| head -c 1 > /dev/null", shell=True, capture_output=True, text=True,
                          executable="/bin/bash")
    # The pipe is closed after one byte; slidernet may or may not have been writing then.
    assert "Traceback" not in proc.stderr
    assert proc.stderr.count("\n") <= 1
    assert proc.stderr in ("", "slidernet: error: the output pipe was closed before everything was written.\n")


def test_progress_only_on_a_terminal(tmp_path, config):
    """stderr is a pipe here: no bar unless asked; --no-progress never shows one."""
    for flags in ([], ["--no-progress"]):
        out = tmp_path / f"out{len(flags)}"
        proc = subprocess.run([sys.executable, "-m", "slidernet.cli", "run", str(config), "--out", str(out),
                               *flags], capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
        assert "realizations" not in proc.stderr and "it/s" not in proc.stderr
        assert json.loads(slidernet.io.read_result(out / "result.nc").attrs["config"])["seed"] == 1


def test_cli_messages_use_the_cli_spelling(tmp_path, config, capsys):
    """An interrupted run refused without --resume: the message names the flag, not the Python keyword."""
    out = tmp_path / "out"

    def interrupt(r: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        slidernet.run(config, out=out, workers=1, on_realization=interrupt)
    line = _one_line_error(capsys, main(["run", str(config), "--out", str(out), "--no-progress"]))
    assert "holds an interrupted run" in line and "--resume" in line and "--overwrite" in line
    assert "resume=True" not in line


def test_a_block_renamed_on_a_name_collision_is_still_read(tmp_path):
    # Two blocks with the same first realization and size: the second is written under a suffixed
    # name, after its realizations' partial files were deleted. That name used to be invisible to the
    # block pattern, so its records were lost.
    import numpy as np

    from slidernet.io.store import RunStore

    store = RunStore(tmp_path, {"config": {}, "seed": 1, "realizations": 3, "slidernet_version": "x"},
                     resume=False)
    store.open()

    def record(r: int) -> dict:
        return {"n": np.array([r, r + 1], np.int64), "events": {"node": np.arange(r, dtype=np.int64)}}

    for batch in ([0, 1], [0, 2]):
        for r in batch:
            store.add(r, record(r))
        store.flush()
    assert sorted(p.name for p in store.dir.glob("block-*")) == ["block-000000000-2-1.npz",
                                                                 "block-000000000-2.npz"]
    assert sorted(store.done()) == [0, 1, 2]
    records = list(store.records(3))
    for r, rec in enumerate(records):
        assert rec["n"].tolist() == [r, r + 1] and rec["events"]["node"].tolist() == list(range(r))
