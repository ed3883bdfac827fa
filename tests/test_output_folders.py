"""Output folders and command-line failures behave as users expect.

- A run that fails before any work is done leaves the folder as it found it.
- A finished result is never replaced silently; ``--overwrite`` replaces it.
- Bad paths, an unreachable scheduler and a closed pipe give one line, a
  non-zero exit and no traceback.
- Progress bars appear only on a terminal (plain lines elsewhere), and never with ``--no-progress``.
"""

from __future__ import annotations

import hashlib
import importlib
import json
import os
import re
import secrets
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

import slidernet
from slidernet.cli import main
from slidernet.errors import (
    CheckpointError,
    CheckpointWarning,
    FolderInUseError,
    OutputError,
    PluginError,
    WorkerLostError,
)

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
    proc = subprocess.run(f"{sys.executable} -m slidernet.cli units --material steel --size 10cm --delta-T 10mK "
                          "| head -c 1 > /dev/null", shell=True, capture_output=True, text=True,
                          executable="/bin/bash")
    # The pipe is closed after one byte; slidernet may or may not have been writing then.
    assert "Traceback" not in proc.stderr
    assert proc.stderr.count("\n") <= 1
    assert proc.stderr in ("", "slidernet: error: the output pipe was closed before everything was written.\n")


@pytest.mark.parametrize(("flags", "lines"), [([], True), (["--no-progress"], False)],
                         ids=["lines", "no-progress"])
def test_progress_is_a_bar_only_on_a_terminal(tmp_path, config, flags, lines):
    """stderr is a pipe here: plain progress lines, never a bar; --no-progress shows nothing."""
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "slidernet.cli", "run", str(config), "--out", str(out),
                           *flags], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert ("slidernet: realizations" in proc.stderr) == lines and "it/s" not in proc.stderr
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

    store = RunStore(tmp_path, {"config": {}, "seed": 1, "realizations": 3, "slidernet_version": "x",
                                "slidernet_code": "y", "inputs": {}}, resume=False)
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


# ---------------------------------------------------------------------------
# A run's identity: every file of a checkpoint names its run; input files are part of the run.

# The chain of 8 (8 realizations), with fewer steps: checkpoint_every = 60 s, so that the finished
# realizations are written as one block when the run is stopped, whatever the speed of the machine.
CHAIN8 = {
    "seed": 1, "realizations": 8, "steps": 2000,
    "network": {"kind": "chain", "n": 8, "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
    "execution": {"workers": 1},
}


def _with(cfg: dict, **dotted) -> dict:
    """A deep copy of ``cfg`` with dotted keys set."""
    out = json.loads(json.dumps(cfg))
    for key, value in dotted.items():
        *parents, last = key.split(".")
        table = out
        for p in parents:
            table = table[p]
        table[last] = value
    return out


def _stopped_after(cfg: dict, out: Path, k: int) -> None:
    """Run ``cfg`` in ``out`` and stop it (as Ctrl-C does) once ``k`` realizations are finished."""
    finished = []

    def stop(r: int) -> None:
        finished.append(r)
        if len(finished) == k:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt, match=f"{k} of {cfg['realizations']} realizations are finished"):
        slidernet.run(cfg, out=out, on_realization=stop)


def _assert_same_bits(got, expected) -> None:
    assert set(got.variables) == set(expected.variables)
    for name in expected.variables:
        np.testing.assert_array_equal(got[name].values, expected[name].values, err_msg=name, strict=True)


@pytest.fixture(scope="module")
def chain8_reference():
    return slidernet.run(CHAIN8)


@pytest.mark.parametrize("overwrite", [False, True], ids=["plain", "overwrite"])
def test_blocks_of_another_run_are_never_read(tmp_path, overwrite):
    # The case: stop a run, delete run.json and the partial files, run another configuration in
    # the same folder. The finished block used to be taken as realizations 0-1 of the new run (exit 0,
    # old sigma_theta in the data, the new one in the attributes).
    out = tmp_path / "out"
    _stopped_after(CHAIN8, out, 2)
    (out / "checkpoint" / "run.json").unlink()
    for p in (out / "checkpoint").glob("partial-*"):
        p.unlink()
    other = _with(CHAIN8, **{"driver.sigma_theta": 2e-6})
    if not overwrite:
        with pytest.raises(CheckpointError, match=r"holds 1 checkpoint files \(e\.g\. 'block-000000000-2\.npz'\) "
                                                  r"but no run\.json.*--overwrite"):
            slidernet.run(other, out=out)
        assert [p.name for p in (out / "checkpoint").iterdir()] == ["block-000000000-2.npz"]
        return
    with slidernet.run(other, out=out, overwrite=True) as ds:
        _assert_same_bits(ds.load(), slidernet.run(other))


def test_a_block_of_another_run_is_refused_on_resume(tmp_path):
    # Every block carries its run's digest: a block copied in from another run's folder is never read.
    mine, theirs = tmp_path / "mine", tmp_path / "theirs"
    _stopped_after(CHAIN8, mine, 2)
    other = _with(CHAIN8, **{"driver.sigma_theta": 2e-6})
    _stopped_after(other, theirs, 3)
    foreign = mine / "checkpoint" / "block-000000005-3.npz"
    shutil.copy(theirs / "checkpoint" / "block-000000000-3.npz", foreign)
    with pytest.raises(CheckpointError, match=rf"{re.escape(str(foreign))!s}' belongs to another run"):
        slidernet.run(CHAIN8, out=mine, resume=True)


def _edge_list(folder: Path, k_last: float) -> Path:
    """A chain of 8 as an edge list with its node file; the last spring's stiffness ``k_last``."""
    (folder / "chain.nodes.csv").write_text("node,x\n" + "".join(f"{i},{float(i)}\n" for i in range(8)))
    edges = folder / "chain.txt"
    edges.write_text("".join(f"{i} {i + 1} k=1.0\n" for i in range(6)) + f"6 7 k={k_last}\n")
    return edges


def _law_file(folder: Path, high: float) -> Path:
    path = folder / "my_law.py"
    path.write_text("import numpy as np\nimport slidernet\n\n\nclass Flat:\n    def sample(self, rng, size):\n"
                    f"        return rng.uniform(0.55, {high}, size)\n\n    def cdf(self, x):\n"
                    f"        return np.clip((np.asarray(x) - 0.55) / ({high} - 0.55), 0.0, 1.0)\n\n\n"
                    "slidernet.register_distribution('flat_for_test', Flat)\n")
    return path


def _input_case(case: str, folder: Path) -> tuple[dict, Path, Callable[[], None]]:
    """A configuration that reads a file, the file, and an edit of it."""
    from slidernet.plugins.contract import example_file

    base = _with(CHAIN8, realizations=16, steps=150)
    if case == "graph":
        edges = _edge_list(folder, 1.0)
        cfg = _with(base, network={"kind": "graph", "path": str(edges), "Ntilde": 1e-7})
        return cfg, edges, lambda: _edge_list(folder, 1.5)  # one spring's k
    if case == "graph-nodes":
        edges = _edge_list(folder, 1.0)
        nodes = folder / "chain.nodes.csv"
        cfg = _with(base, network={"kind": "graph", "path": str(edges), "Ntilde": 1e-7})
        return cfg, nodes, lambda: nodes.write_text(nodes.read_text().replace("7,7.0", "7,7.5"))
    if case == "empirical":
        path = folder / "mu_s.txt"
        shutil.copy(example_file("mu_s_example.txt"), path)
        cfg = _with(base, **{"friction.static": {"name": "empirical", "path": str(path)}})
        return cfg, path, lambda: path.write_text(path.read_text() + "0.7\n")
    if case == "series":
        path = folder / "T.csv"
        shutil.copy(example_file("temperature_example.csv"), path)
        cfg = _with(base, steps=100, driver={"name": "series", "path": str(path), "kappa": 1.2e-5, "T0": 15.0,
                                             "tau_th": 1.0})
        return cfg, path, lambda: path.write_text(path.read_text().replace("\n0,10.30", "\n0,10.40"))
    if case.startswith("plugin-"):
        return _helper_case(case, folder, base)
    path = _law_file(folder, 0.65)
    cfg = _with(base, plugins=[str(path)], **{"friction.static": {"name": "flat_for_test"}})
    return cfg, path, lambda: _law_file(folder, 0.66)


def _helper_case(case: str, folder: Path, base: dict) -> tuple[dict, Path, Callable[[], None]]:
    """A plugin file whose law's upper end comes from a module beside it (or from a module that one imports).

    The module names are new to this process (a module imported once stays in ``sys.modules``); with
    ``-imported-before`` this process imports the helper before the plugin file is imported.
    """
    helper = f"helper_{secrets.token_hex(4)}"
    inner = f"{helper}_inner"
    (folder / f"{inner}.py").write_text("HIGH = 0.65\n")
    (folder / f"{helper}.py").write_text(f"from {inner} import HIGH\n" if case == "plugin-helper-of-helper"
                                         else "HIGH = 0.65\n")
    law = folder / "law_with_helper.py"
    law.write_text("import sys\nfrom pathlib import Path\n\nimport numpy as np\nimport slidernet\n\n"
                   "sys.path.insert(0, str(Path(__file__).parent))\n"
                   f"from {helper} import HIGH  # noqa: E402\n\n\n"
                   "class Flat:\n    def sample(self, rng, size):\n"
                   "        return rng.uniform(0.55, HIGH, size)\n\n"
                   "    def cdf(self, x):\n"
                   "        return np.clip((np.asarray(x) - 0.55) / (HIGH - 0.55), 0.0, 1.0)\n"
                   "\n\nslidernet.register_distribution('flat_helper_for_test', Flat)\n")
    if case == "plugin-helper-imported-before":
        sys.path.insert(0, str(folder))
        importlib.import_module(helper)
    cfg = _with(base, plugins=[str(law)], **{"friction.static": {"name": "flat_helper_for_test"}})
    edited = folder / f"{inner if case == 'plugin-helper-of-helper' else helper}.py"
    return cfg, edited, lambda: edited.write_text(edited.read_text().replace("0.65", "0.66"))


@pytest.mark.usefixtures("clean_registries")
@pytest.mark.parametrize("case", ["graph", "graph-nodes", "empirical", "series", "plugin", "plugin-helper",
                                  "plugin-helper-of-helper", "plugin-helper-imported-before"])
def test_an_input_file_changed_before_resume_is_refused(tmp_path, case, monkeypatch):
    # kind = "graph" from an edge list, 16 realizations: kill after a few, change one spring's k, resume.
    # The run used to go on (exit 0), realizations 0-8 with the old network and 9-15 with the new one.
    # A module that a plugin file imports (helper.py beside it) was not hashed: a changed helper was
    # resumed with exit 0, realizations half old law and half new.
    monkeypatch.setattr(sys, "path", list(sys.path))  # a plugin file may put its folder on it
    cfg, path, edit = _input_case(case, tmp_path)
    out = tmp_path / "out"
    _stopped_after(cfg, out, 9)
    edit()
    with pytest.raises(CheckpointError, match=rf"input file changed since the run started: "
                                              rf"'{re.escape(str(path))}'"):
        slidernet.run(cfg, out=out, resume=True)
    assert len(list((out / "checkpoint").glob("block-*"))) == 1  # nothing was touched


@pytest.mark.usefixtures("clean_registries")
def test_the_modules_a_plugin_file_brings_in_are_input_files_and_installed_ones_are_not(tmp_path, monkeypatch):
    from slidernet.config import load_config
    from slidernet.config.loading import input_files

    monkeypatch.setattr(sys, "path", list(sys.path))
    cfg, inner, _ = _input_case("plugin-helper-of-helper", tmp_path)
    helper = inner.with_name(inner.name.replace("_inner", ""))
    files = input_files(load_config(cfg))
    # numpy and slidernet, which the file imports too, are the environment's: not listed.
    assert files == {"plugins[0]": cfg["plugins"][0],
                     f"plugins[0] imports {helper.stem}": str(helper),
                     f"plugins[0] imports {inner.stem}": str(inner)}


def test_the_input_files_are_in_the_result_and_an_unchanged_one_resumes(tmp_path):
    cfg, path, _ = _input_case("graph", tmp_path)
    out = tmp_path / "out"
    _stopped_after(cfg, out, 9)
    with slidernet.run(cfg, out=out, resume=True) as ds:
        inputs = json.loads(ds.attrs["inputs"])
        _assert_same_bits(ds.load(), slidernet.run(cfg))
    assert sorted(inputs) == ["network.path", "network.path (node file)"]
    assert inputs["network.path"]["path"] == str(path)
    assert inputs["network.path"]["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()


DAMAGE = {
    "truncated": lambda data: data[: len(data) // 2],
    "emptied": lambda data: b"",
    "one-bit": lambda data: (data[: len(data) // 2] + bytes([data[len(data) // 2] ^ 0x10])
                             + data[len(data) // 2 + 1:]),
}


@pytest.mark.parametrize("damage", list(DAMAGE.values()), ids=list(DAMAGE))
def test_a_damaged_block_is_found_when_the_folder_is_opened_and_recomputed(tmp_path, chain8_reference, damage):
    # It gave a BadZipFile or EOFError traceback, and a flipped bit was only noticed after every
    # remaining realization had been computed.
    out = tmp_path / "out"
    _stopped_after(CHAIN8, out, 3)
    block = out / "checkpoint" / "block-000000000-3.npz"
    block.write_bytes(damage(block.read_bytes()))
    ran = []
    with pytest.warns(CheckpointWarning, match=rf"{re.escape(str(block))}.*truncated or corrupt.*It is removed; "
                                               r"its realizations are computed again"):
        ds = slidernet.run(CHAIN8, out=out, resume=True, on_realization=ran.append)
    assert sorted(ran) == list(range(8))  # the three lost realizations too
    with ds:
        _assert_same_bits(ds.load(), chain8_reference)


def test_a_damaged_partial_file_restarts_its_realization(tmp_path, chain8_reference):
    from slidernet.ensemble.execution import run_realization

    out = tmp_path / "out"
    _stopped_after(CHAIN8, out, 3)
    # Realization 3 saved in progress, as a running one is when its run stops, then damaged.
    digest = json.loads((out / "checkpoint" / "run.json").read_text())["digest"]
    asked = []
    partial = out / "checkpoint" / "partial-000000003.npz"
    config_json = json.dumps(CHAIN8)
    assert run_realization(config_json, 1, 3, str(partial), 60.0, {"run": digest},
                           stop=lambda: asked.append(1) or len(asked) > 3) is None
    partial.write_bytes(DAMAGE["one-bit"](partial.read_bytes()))
    with pytest.warns(CheckpointWarning, match=r"partial-000000003\.npz.*its realization starts again"):
        ds = slidernet.run(CHAIN8, out=out, resume=True)
    with ds:
        _assert_same_bits(ds.load(), chain8_reference)


@pytest.mark.parametrize("text", ["{}", "[]", "not json", "changed"], ids=["empty-object", "list", "text",
                                                                             "edited"])
def test_a_damaged_run_json_is_one_line(tmp_path, capsys, text):
    # {} and [] gave KeyError / TypeError / AttributeError tracebacks.
    config = tmp_path / "chain8.toml"
    config.write_text(_toml(CHAIN8))
    out = tmp_path / "out"
    _stopped_after(CHAIN8, out, 2)
    run_json = out / "checkpoint" / "run.json"
    if text == "changed":  # a flipped digit: the contents no longer match their digest
        text = run_json.read_text().replace('"seed": 1,', '"seed": 3,')
    run_json.write_text(text)
    line = _one_line_error(capsys, main(["run", str(config), "--out", str(out), "--resume", "--no-progress"]))
    assert str(run_json) in line and "--overwrite" in line


@pytest.mark.parametrize("command", ["run", "sweep", "paper"])
@pytest.mark.parametrize("kind", ["dangling-symlink", "symlink-loop", "symlink-to-a-file"])
def test_a_symbolic_link_that_is_no_folder_is_named_for_what_it_is(tmp_path, config, capsys, kind, command):
    # A dangling symbolic link or a loop as --out was called "a file".
    out = tmp_path / "link"
    target = {"dangling-symlink": tmp_path / "nowhere", "symlink-loop": out,
              "symlink-to-a-file": tmp_path / "afile"}[kind]
    (tmp_path / "afile").write_text("x")
    out.symlink_to(target)
    argv = {"run": ["run", str(config)], "sweep": ["sweep", str(config), "--set", "driver.sigma_theta=1e-6,2e-6"],
            "paper": ["paper"]}[command]
    line = _one_line_error(capsys, main([*argv, "--out", str(out), "--no-progress"]))
    expected = {"dangling-symlink": f"is a symbolic link to {str(target)!r}, which does not exist",
                "symlink-loop": "is a symbolic link in a loop of links, which never reaches a folder",
                "symlink-to-a-file": f"is a symbolic link to the file {str(target)!r}"}[kind]
    assert line == f"slidernet: error: The output directory {str(out)!r} {expected}; name a folder."
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "link", "small.toml"]
    assert not (tmp_path / "nowhere").exists()


def test_a_dangling_symbolic_link_inside_the_output_path_is_named(tmp_path, config, capsys):
    (tmp_path / "link").symlink_to(tmp_path / "nowhere")
    out = tmp_path / "link" / "out"
    line = _one_line_error(capsys, main(["run", str(config), "--out", str(out), "--no-progress"]))
    link, nowhere = str(tmp_path / "link"), str(tmp_path / "nowhere")
    assert line == (f"slidernet: error: The output directory {str(out)!r} cannot be made: {link!r} is a symbolic "
                    f"link to {nowhere!r}, which does not exist.")


# A name that is not UTF-8 text: the byte 0xff, as a shell hands it to Python (surrogateescape).
NOT_UTF8 = os.fsdecode(b"caf\xe9")


@pytest.mark.parametrize("command", ["run", "sweep", "paper"])
def test_an_output_folder_whose_name_is_not_utf8_is_refused_before_any_work(tmp_path, config, capsys,
                                                                           monkeypatch, command):
    # It failed after the whole run, in the netCDF library, with a UnicodeEncodeError traceback (exit 1).
    from slidernet.ensemble import runner
    from slidernet.paper import reproduction

    monkeypatch.setattr(runner, "compile_kernels", _no_work)
    monkeypatch.setattr(reproduction, "compile_kernels", _no_work)
    out = tmp_path / NOT_UTF8
    argv = {"run": ["run", str(config)], "sweep": ["sweep", str(config), "--set", "driver.sigma_theta=1e-6,2e-6"],
            "paper": ["paper"]}[command]
    line = _one_line_error(capsys, main([*argv, "--out", str(out), "--no-progress"]))
    assert line == (f"slidernet: error: The output directory {str(out)!r} is not UTF-8 text: its byte 0xe9 "
                    "cannot be decoded, and netCDF files are named in UTF-8. Rename it, or name another folder.")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml"]


def _no_work(*args, **kwargs):
    raise AssertionError("work started")


@pytest.mark.usefixtures("clean_registries")
@pytest.mark.parametrize("where", ["plugin", "data"])
def test_an_input_path_that_is_not_utf8_is_refused_before_any_work(tmp_path, capsys, where):
    # A plugin file in such a folder gave a UnicodeEncodeError traceback (exit 1). A configuration holds
    # text, its paths included: each is refused by its field, as the validation refuses the graph's.
    from slidernet.plugins.contract import example_file

    folder = tmp_path / NOT_UTF8
    folder.mkdir()
    config = folder / "small.toml"  # a TOML file is UTF-8 text: the name comes from the file's folder
    if where == "plugin":
        path = _law_file(folder, 0.65)
        config.write_text('plugins = ["my_law.py"]\n'
                          + SMALL.replace('name = "gaussian"\nmean = 0.6\nstd = 0.01', 'name = "flat_for_test"'))
        field = "'plugins' field"
    else:
        path = folder / "mu_s.txt"
        shutil.copy(example_file("mu_s_example.txt"), path)
        config.write_text(SMALL.replace('name = "gaussian"\nmean = 0.6\nstd = 0.01',
                                        'name = "empirical"\npath = "mu_s.txt"'))
        field = "'friction.static.path' field"
    out = tmp_path / "out"
    line = _one_line_error(capsys, main(["run", str(config), "--out", str(out), "--no-progress"]))
    assert line == (f"slidernet: error: The {field}: {str(path)!r} is not UTF-8 text: its byte 0xe9 cannot be "
                    "decoded, and a configuration and its result name their files in text. Rename the folder, or "
                    "move the file.")
    assert not out.exists()

def _toml(cfg: dict) -> str:
    """A configuration as TOML (tables of plain values)."""
    def value(v):
        return json.dumps(v)

    lines = [f"{k} = {value(v)}" for k, v in cfg.items() if not isinstance(v, dict)]
    for k, v in cfg.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f"{kk} = {value(vv)}" for kk, vv in v.items() if not isinstance(vv, dict)]
            for kk, vv in v.items():
                if isinstance(vv, dict):
                    lines.append(f"[{k}.{kk}]")
                    lines += [f"{kkk} = {value(vvv)}" for kkk, vvv in vv.items()]
    return "\n".join(lines) + "\n"


def test_resume_names_an_empty_checkpoint_folder(tmp_path):
    # "it has no checkpoint folder" was said of a folder that has one.
    (tmp_path / "checkpoint").mkdir()
    with pytest.raises(CheckpointError, match=r"Nothing to resume in .*: its checkpoint folder holds no run"):
        slidernet.run(CHAIN8, out=tmp_path, resume=True)


# ---------------------------------------------------------------------------
# The folder's lock: one run at a time in a folder.

_HOLD_LOCK = """\
import sys
from slidernet.io.store import FolderLock
FolderLock(sys.argv[1], "run").acquire()
print("locked", flush=True)
sys.stdin.read()
"""


def _hold_lock(folder: Path) -> subprocess.Popen:
    """Another process that holds ``folder``'s lock, as a run still going does, until it is killed."""
    holder = subprocess.Popen([sys.executable, "-c", _HOLD_LOCK, str(folder)], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline() == "locked\n"
    return holder


@pytest.fixture
def interrupted_and_locked(tmp_path) -> Iterator[tuple[Path, subprocess.Popen]]:
    """An interrupted run in ``tmp_path / "out"``, whose lock another process holds."""
    out = tmp_path / "out"
    _stopped_after(CHAIN8, out, 1)
    holder = _hold_lock(out)
    yield out, holder
    holder.kill()
    holder.wait()


@pytest.mark.parametrize("flags", [{"resume": True}, {}, {"overwrite": True}],
                         ids=["resume", "plain", "overwrite"])
def test_a_run_still_going_is_refused_whatever_the_flags(interrupted_and_locked, flags):
    # A --resume started while the same run was still going was accepted: all the work was done twice
    # and the first run then failed; without --resume it said "holds an interrupted run".
    out, holder = interrupted_and_locked
    before = _tree(out)
    with pytest.raises(FolderInUseError, match=rf"a slidernet run is still going there \(process {holder.pid} "
                                               r"holds its lock"):
        slidernet.run(CHAIN8, out=out, **flags)
    assert _tree(out) == before


def test_a_lock_dies_with_its_process(interrupted_and_locked, chain8_reference):
    out, holder = interrupted_and_locked
    holder.kill()  # kill -9: the operating system lets the lock go
    holder.wait()
    assert (out / ".slidernet.lock").exists()
    with slidernet.run(CHAIN8, out=out, resume=True) as ds:
        _assert_same_bits(ds.load(), chain8_reference)
    assert _tree(out) == ["result.nc"]  # the lock file goes with its run


# ---------------------------------------------------------------------------
# Faults while files are written: kill -9 during result.nc, a full disk (ulimit -f).

_KILLED_WHILE_WRITING_RESULT = """\
import os, signal, sys
from slidernet.io import netcdf

def write_then_die(self, *args, **kwargs):
    netcdf.ResultWriter.write.__wrapped__(self, *args, **kwargs)
    os.kill(os.getpid(), signal.SIGKILL)

write_then_die.__wrapped__ = netcdf.ResultWriter.write
netcdf.ResultWriter.write = write_then_die
from slidernet.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_kill_9_while_result_nc_is_written_leaves_nothing_behind_after_the_resume(tmp_path, chain8_reference):
    # The temporary .result.nc.*.tmp of a killed write stayed in the folder forever, even after a
    # successful resume.
    config = tmp_path / "chain8.toml"
    config.write_text(_toml(CHAIN8))
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-c", _KILLED_WHILE_WRITING_RESULT, "run", str(config),
                           "--out", str(out), "--no-progress"], capture_output=True, text=True)
    assert proc.returncode == -9, proc.stderr
    assert [p.name for p in out.glob(".result.nc.*.tmp")]  # what a kill -9 leaves
    assert main(["run", str(config), "--out", str(out), "--resume", "--no-progress"]) == 0
    assert _tree(out) == ["result.nc"]
    _assert_same_bits(slidernet.io.read_result(out / "result.nc"), chain8_reference)


def _limited_run(config: Path, out: Path, limit: int, *flags: str) -> subprocess.CompletedProcess:
    """The command line with a file size limit (``ulimit -f``) of ``limit`` bytes."""
    import resource

    def limit_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.run([sys.executable, "-m", "slidernet", "run", str(config), "--out", str(out),
                           "--no-progress", *flags], capture_output=True, text=True, preexec_fn=limit_files)


def test_a_file_size_limit_is_one_line_naming_the_file_and_the_run_resumes(tmp_path, chain8_reference):
    # A full disk while result.nc was written gave a netCDF RuntimeError traceback; during checkpoints,
    # "File too large" without the file's name.
    config = tmp_path / "chain8.toml"
    config.write_text(_toml(CHAIN8))
    sizes = tmp_path / "sizes"
    _stopped_after(CHAIN8, sizes, 8)  # every realization finished, in one block: the block's size
    block = (sizes / "checkpoint" / "block-000000000-8.npz").stat().st_size
    result = tmp_path / "result.nc"
    slidernet.io.write_netcdf(chain8_reference, result)
    assert 4 * 1024 < block < result.stat().st_size
    out = tmp_path / "out"
    # A limit below the block's size: the checkpoint cannot be written.
    proc = _limited_run(config, out, block // 2)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and proc.stderr.count("\n") == 1, proc.stderr
    assert f"Cannot write the checkpoint file '{out / 'checkpoint' / 'block-000000000-8.npz'}': File too large" \
        in proc.stderr
    assert not out.exists()  # nothing could be saved: the folder is left as it was found
    # A limit between the block's and the result's sizes: the result cannot be written, the checkpoint stays.
    proc = _limited_run(config, out, (block + result.stat().st_size) // 2)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and proc.stderr.count("\n") == 1, proc.stderr
    assert f"Cannot write the result file '{out / 'result.nc'}': the file reached this process's file size " \
           "limit (ulimit -f" in proc.stderr and "--resume" in proc.stderr
    assert _tree(out) == ["checkpoint", "checkpoint/block-000000000-8.npz", "checkpoint/run.json"]
    assert main(["run", str(config), "--out", str(out), "--resume", "--no-progress"]) == 0
    _assert_same_bits(slidernet.io.read_result(out / "result.nc"), chain8_reference)
    assert _tree(out) == ["result.nc"]


def test_a_lost_worker_leaves_no_temporary_file(tmp_path, monkeypatch, chain8_reference):
    # tests/test_interrupts.py now and then: when a worker died, the other was killed while it wrote a
    # partial file, and its temporary file stayed in the folder until the resume.
    from slidernet.ensemble import runner

    out = tmp_path / "out"
    _stopped_after(CHAIN8, out, 3)  # finished realizations saved: the folder stays resumable

    def lost(cfg, config_json, store, *args, **kwargs):
        (store.dir / ".partial-000000003.npz.2ja72z68.tmp").write_bytes(b"PK\x03\x04")  # a killed write
        raise WorkerLostError("A worker process was killed by SIGKILL during the run.")

    monkeypatch.setattr(runner, "_execute", lost)
    with pytest.raises(WorkerLostError, match=r"killed by SIGKILL during the run\. 3 of 8 realizations are "
                                              r"finished in .*--resume"):
        slidernet.run(CHAIN8, out=out, resume=True)
    assert not [name for name in _tree(out) if name.endswith(".tmp")]
    monkeypatch.undo()
    _assert_same_bits(slidernet.run(CHAIN8, out=out, resume=True), chain8_reference)
