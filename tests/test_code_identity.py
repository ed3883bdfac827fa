"""The run's identity covers the code that computes: a digest of the slidernet package's own sources.

The version string alone let a killed run resume under other code: a second
install of version 0.1.0 whose Gaussian law's mean was shifted by 0.05
resumed with exit 0, and 7 of 8 realizations differed from the
uninterrupted run. Anyone with an editable install who pulls new code can
hit this.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import slidernet
from slidernet._version import code_digest, folder_digest
from slidernet.ensemble import runner
from slidernet.ensemble.sweep import sweep
from slidernet.errors import CheckpointError
from tests.test_output_folders import CHAIN8, _stopped_after, _toml

PACKAGE = Path(slidernet.__file__).parent
CHAIN = {**CHAIN8, "steps": 400}


def test_the_digest_covers_every_source_file_of_the_package(tmp_path):
    copy = tmp_path / "slidernet"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    assert folder_digest(copy) == code_digest()
    # A file deep in the package, and a new file: each changes it; a compiled file does not.
    law = copy / "plugins" / "distributions" / "unbounded.py"
    law.write_text(law.read_text() + "\n# an edit\n")
    edited = folder_digest(copy)
    assert edited != code_digest()
    (copy / "analysis" / "theory" / "new.py").write_text("")
    added = folder_digest(copy)
    assert added not in (edited, code_digest())
    (copy / "kernels" / "stale.pyc").write_bytes(b"\0")
    assert folder_digest(copy) == added


def test_a_run_records_the_digest_of_its_code(tmp_path):
    _stopped_after(CHAIN, tmp_path, 2)
    stored = json.loads((tmp_path / "checkpoint" / "run.json").read_text())
    assert stored["slidernet_code"] == code_digest()
    with slidernet.run(CHAIN, out=tmp_path, resume=True) as ds:
        assert ds.attrs["slidernet_code"] == code_digest()


def test_a_run_killed_under_other_code_of_the_same_version_is_not_resumed(tmp_path):
    # The case, as a user meets it: the run is killed, the code changes under the same version
    # (a shifted Gaussian law), the resume is refused before any work.
    out = tmp_path / "out"
    _stopped_after(CHAIN, out, 3)
    before = sorted(p.name for p in (out / "checkpoint").iterdir())
    root = tmp_path / "other-install"
    shutil.copytree(PACKAGE, root / "slidernet", ignore=shutil.ignore_patterns("__pycache__"))
    law = root / "slidernet" / "plugins" / "distributions" / "unbounded.py"
    text = law.read_text()
    shifted = text.replace('self.mean = check_scalar(mean, "mean", "gaussian")',
                           'self.mean = check_scalar(mean, "mean", "gaussian") + 0.05')
    assert shifted != text
    law.write_text(shifted)
    code = ("import sys\nimport slidernet\nassert slidernet.__file__.startswith(sys.argv[2]), slidernet.__file__\n"
            "from slidernet.cli import main\n"
            "sys.exit(main(['run', sys.argv[1], '--out', sys.argv[3], '--resume', '--no-progress']))\n")
    toml = tmp_path / "chain.toml"
    toml.write_text(_toml(CHAIN))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(root)
    proc = subprocess.run([sys.executable, "-c", code, str(toml), str(root), str(out)], env=env, cwd=root,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert ("Cannot resume: the checkpoint was computed by other code than this "
            f"(slidernet {slidernet.__version__} both times, but the digest of its sources is ") in proc.stderr
    assert sorted(p.name for p in (out / "checkpoint").iterdir()) == before


def test_a_finished_sweep_point_of_other_code_is_not_read_back(tmp_path, monkeypatch):
    # A finished point is read back on resume (runner.run_in): it must have been computed by this code.
    base = {**CHAIN, "realizations": 2, "steps": 50}
    grid = {"driver.sigma_theta": [1e-7, 1e-6]}

    def killed_at_point_1(cfg, *args, on_realization=None, **kwargs):
        if cfg.driver.sigma_theta == 1e-6:
            raise KeyboardInterrupt
        return real_run(cfg, *args, on_realization=on_realization, **kwargs)

    real_run = runner.run
    with monkeypatch.context() as patched:
        patched.setattr(runner, "run", killed_at_point_1)
        with pytest.raises(KeyboardInterrupt, match="1 of 2 sweep points are done"):
            sweep(base, grid, out=tmp_path, workers=1)
    monkeypatch.setattr(runner, "code_digest", lambda: "0" * 40, raising=False)
    with pytest.raises(CheckpointError, match=r"points/0/result\.nc' was computed by other code than this "
                                              rf"\(slidernet {re.escape(slidernet.__version__)} both times"):
        sweep(base, grid, out=tmp_path, resume=True, workers=1)
