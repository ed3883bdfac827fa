"""One lock per output folder, whatever writes into it: a run, a sweep, a resume, the paper, a plot.

A run used to lock ``DIR/checkpoint/.slidernet.lock`` and a sweep
``DIR/.slidernet.lock``: a run started in the folder of a sweep still going
was not refused, and whichever ended last replaced the other's
``result.nc``. Every command now takes ``DIR/.slidernet.lock`` before it
writes anything, and a run never writes into a sweep's folder (nor a sweep
into a run's), finished or not, even with ``--overwrite``.

The tests hold a folder from inside a command still going: its
``on_realization`` callback runs in the parent process while the command
holds its lock, so nothing races the clock.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import pytest

import slidernet
from slidernet.cli import main
from slidernet.ensemble.sweep import sweep
from slidernet.errors import FolderInUseError, OutputError
from slidernet.io.store import FolderLock
from slidernet.paper.reproduction import reproduce

BASE: dict[str, Any] = {
    "seed": 1, "realizations": 2, "steps": 50,
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}
GRID = {"driver.sigma_theta": [1e-6, 2e-6]}
ONE = {"workers": 1}


def _tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*")) if folder.exists() else []


def _in_use(what: str) -> str:
    """The start of the refusal of a folder whose lock a ``what`` of this process holds."""
    return rf"is in use: a slidernet {what} is still going there \(process {os.getpid()} holds its lock"


FLAGS = pytest.mark.parametrize("flags", [{}, {"overwrite": True}, {"resume": True}],
                                ids=["plain", "overwrite", "resume"])


@FLAGS
def test_a_run_is_refused_while_a_sweep_works_in_its_folder(tmp_path, flags):
    # The case: `slidernet sweep ... --out D &` then `slidernet run base.toml --out D`.
    out = tmp_path / "D"
    refused = []

    def run_inside(i: int, r: int) -> None:
        if not refused:  # once, while the sweep's first point runs
            with pytest.raises(FolderInUseError, match=_in_use("sweep")):
                slidernet.run(BASE, out=out, **flags, **ONE)
            refused.append(_tree(out))

    sweep(BASE, GRID, out=out, on_realization=run_inside, **ONE)
    assert refused
    assert "checkpoint" not in refused[0]  # the run wrote nothing
    assert [p for p in _tree(out) if "/" not in p] == ["points", "result.nc", "sweep.json"]


@FLAGS
def test_a_sweep_is_refused_while_a_run_works_in_its_folder(tmp_path, flags):
    out = tmp_path / "D"
    refused = []

    def sweep_inside(r: int) -> None:
        if not refused:
            with pytest.raises(FolderInUseError, match=_in_use("run")):
                sweep(BASE, GRID, out=out, **flags, **ONE)
            refused.append(_tree(out))

    slidernet.run(BASE, out=out, on_realization=sweep_inside, **ONE).close()
    assert refused
    assert not {"sweep.json", "points"} & set(refused[0])
    assert _tree(out) == ["result.nc"]  # the lock file went with the run


@pytest.mark.parametrize("overwrite", [False, True], ids=["plain", "overwrite"])
def test_a_run_never_writes_into_a_sweeps_folder(tmp_path, overwrite):
    # A run's --overwrite replaces a run: it used to put a run's result.nc beside a sweep's sweep.json and
    # points/, and a run without it called the sweep's result "a finished result".
    sweep(BASE, GRID, out=tmp_path, **ONE)
    before = {p: (tmp_path / p).stat().st_mtime_ns for p in _tree(tmp_path)}
    with pytest.raises(OutputError, match=rf"^{re.escape(repr(str(tmp_path)))} holds a sweep \(sweep\.json, "
                                          r"points\): a run does not write there, even with --overwrite, which "
                                          r"replaces only a run's own files\. Use another output directory\.$"):
        slidernet.run(BASE, out=tmp_path, overwrite=overwrite, **ONE)
    assert {p: (tmp_path / p).stat().st_mtime_ns for p in _tree(tmp_path)} == before


@pytest.mark.parametrize("state", ["finished", "interrupted"])
@pytest.mark.parametrize("overwrite", [False, True], ids=["plain", "overwrite"])
def test_a_sweep_never_writes_into_a_runs_folder(tmp_path, overwrite, state):
    # A sweep in the folder of a finished run replaced its result.nc at its end, without --overwrite.
    if state == "finished":
        slidernet.run(BASE, out=tmp_path, **ONE).close()
        found = "result.nc"
    else:
        with pytest.raises(KeyboardInterrupt):
            slidernet.run(BASE, out=tmp_path, on_realization=_interrupt, **ONE)
        found = "checkpoint"
    before = {p: (tmp_path / p).stat().st_mtime_ns for p in _tree(tmp_path)}
    with pytest.raises(OutputError, match=rf"holds a run \({found}\): a sweep does not write there, even with "
                                          r"--overwrite"):
        sweep(BASE, GRID, out=tmp_path, overwrite=overwrite, **ONE)
    assert {p: (tmp_path / p).stat().st_mtime_ns for p in _tree(tmp_path)} == before


def _interrupt(r: int) -> None:
    raise KeyboardInterrupt


def test_a_resumed_run_and_a_resumed_sweep_keep_to_their_own_folders(tmp_path):
    (tmp_path / "run").mkdir()
    sweep(BASE, GRID, out=tmp_path / "sweep", **ONE)
    with pytest.raises(OutputError, match="holds a sweep"):
        slidernet.run(BASE, out=tmp_path / "sweep", resume=True, **ONE)
    slidernet.run(BASE, out=tmp_path / "run", **ONE).close()
    with pytest.raises(OutputError, match="holds a run"):
        sweep(BASE, GRID, out=tmp_path / "run", resume=True, **ONE)


def test_the_paper_takes_its_folders_lock_and_keeps_to_its_own_folders(tmp_path):
    with FolderLock(tmp_path, "run"):
        with pytest.raises(FolderInUseError, match=_in_use("run")):
            reproduce(tmp_path, progress=False)
    assert _tree(tmp_path) == []
    slidernet.run(BASE, out=tmp_path, **ONE).close()
    with pytest.raises(OutputError, match=r"holds a run \(result\.nc\): a paper reproduction does not write "
                                          r"there"):
        reproduce(tmp_path, progress=False, overwrite=True)
    assert _tree(tmp_path) == ["result.nc"]


def test_a_run_is_refused_in_a_folder_a_paper_reproduction_holds(tmp_path):
    (tmp_path / "runs").mkdir()  # what an interrupted reproduction leaves
    with pytest.raises(OutputError, match=r"holds a paper reproduction \(runs\): a run does not write there"):
        slidernet.run(BASE, out=tmp_path, **ONE)
    with FolderLock(tmp_path, "paper reproduction"):
        with pytest.raises(FolderInUseError, match=_in_use("paper reproduction")):
            slidernet.run(BASE, out=tmp_path, overwrite=True, **ONE)
    assert _tree(tmp_path) == ["runs"]


@pytest.fixture
def finished(tmp_path) -> Path:
    out = tmp_path / "D"
    slidernet.run(BASE, out=out, **ONE).close()
    return out


def test_plot_is_refused_while_a_run_holds_the_folder(finished, capsys):
    with FolderLock(finished, "run"):
        status = main(["plot", str(finished / "result.nc")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert re.search(_in_use("run"), err), err
    assert _tree(finished) == ["result.nc"]


def test_plot_holds_the_folder_it_writes_into(finished, tmp_path):
    # While the picture is written, no run may start there; the lock file goes with the plot.
    pictures = tmp_path / "pictures"
    pictures.mkdir()
    seen = []

    def savefig(self, fname, **kwargs):
        with pytest.raises(FolderInUseError, match=_in_use("plot")):
            slidernet.run(BASE, out=pictures, **ONE)
        seen.append(sorted(os.listdir(pictures)))
        Path(fname).write_bytes(b"picture")

    with pytest.MonkeyPatch.context() as patch:
        from matplotlib.figure import Figure

        patch.setattr(Figure, "savefig", savefig)
        assert main(["plot", str(finished / "result.nc"), "--out", str(pictures / "n.png")]) == 0
    assert seen and ".slidernet.lock" in seen[0]
    assert sorted(os.listdir(pictures)) == ["n.png"]


def test_a_lock_file_of_a_killed_command_is_taken_over(finished):
    # The lock of a process that ended (kill -9 leaves its file) is no lock: the next command takes it.
    (finished / ".slidernet.lock").write_text("123456789 sweep\n")
    slidernet.run(BASE, out=finished, overwrite=True, **ONE).close()
    assert _tree(finished) == ["result.nc"]



def test_a_finished_run_leaves_no_lock_file_from_the_moment_its_checkpoint_goes(tmp_path, monkeypatch):
    # The result is opened after the checkpoint is removed and before the lock is let go: a kill -9 there
    # (seen in benchmarks/fault_injection.py) left the lock file beside result.nc for good.
    from slidernet.ensemble import runner

    seen: list[list[str]] = []
    opened = runner.open_result

    def open_result(path):
        seen.append(sorted(os.listdir(path.parent)))
        return opened(path)

    monkeypatch.setattr(runner, "open_result", open_result)
    slidernet.run(BASE, out=tmp_path / "out", **ONE).close()
    assert seen == [["result.nc"]]
