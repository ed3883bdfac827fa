"""Compiling: only what a scene runs, once per machine, one cache for the same sources wherever installed.

The cache tests run small kernels in fresh interpreters on copies of the
package (another path, new modification times: what ``pip install .`` and
then ``pip install -e .`` of the same sources look like to numba), each with
its own empty ``NUMBA_CACHE_DIR``. ``NUMBA_DEBUG_CACHE=1`` makes numba print
one line per cache file it saves ("data saved to ..."), i.e. per compile.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import slidernet
from slidernet.config import load_config
from slidernet.kernels.jit import on_first_compile
from slidernet.solver.compile import compile_kernels, compile_notice, kernel_parts, probe_config
from slidernet.solver.scene import Scene
from tests.conftest import make_config

PACKAGE = Path(slidernet.__file__).parent

# tilt_status(TILT_NEED_DRAWS) is NEED_TILT, a constant of state.py compiled into tilt.py's machine code.
STATUS = """
from slidernet.kernels import tilt_status, TILT_NEED_DRAWS
print(tilt_status(TILT_NEED_DRAWS))
"""


def _install_copy(where: Path) -> Path:
    """A copy of the package under ``where`` (the folder to put on PYTHONPATH)."""
    shutil.copytree(PACKAGE, where / "slidernet", ignore=shutil.ignore_patterns("__pycache__"))
    return where


def _python(code: str, root: Path, cache: Path, **env: str) -> subprocess.CompletedProcess:
    full = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    full.update(PYTHONPATH=str(root), NUMBA_CACHE_DIR=str(cache), NUMBA_DEBUG_CACHE="1", **env)
    # cwd: not the repository, whose slidernet/ would come first on sys.path.
    return subprocess.run([sys.executable, "-c", code], env=full, cwd=root, check=True, capture_output=True,
                          text=True)


def _saved(out: str, name: str) -> int:
    """Cache files of ``name`` numba saved (one per compile) according to NUMBA_DEBUG_CACHE's lines."""
    return sum(1 for line in out.splitlines() if "data saved to" in line and f".{name}-" in line)


def test_the_same_sources_share_one_cache_wherever_they_are_installed(tmp_path):
    cache = tmp_path / "cache"
    first = _python(STATUS, _install_copy(tmp_path / "site-packages"), cache)
    assert _saved(first.stdout, "tilt_status") == 1
    second = _python(STATUS, _install_copy(tmp_path / "editable"), cache)
    assert _saved(second.stdout, "tilt_status") == 0, second.stdout
    assert second.stdout.splitlines()[-1] == first.stdout.splitlines()[-1] == "2"


def test_an_edit_of_another_kernels_file_gets_new_machine_code(tmp_path):
    # numba's own cache checks a function against its own file only: this edit is in state.py, and
    # tilt_status lives in tilt.py.
    cache = tmp_path / "cache"
    root = _install_copy(tmp_path / "install")
    assert _python(STATUS, root, cache).stdout.splitlines()[-1] == "2"
    state = root / "slidernet" / "kernels" / "state.py"
    text = state.read_text()
    assert "NEED_TILT = 2" in text
    state.write_text(text.replace("NEED_TILT = 2", "NEED_TILT = 42"))
    edited = _python(STATUS, root, cache)
    assert _saved(edited.stdout, "tilt_status") == 1
    assert edited.stdout.splitlines()[-1] == "42"


def test_an_edit_outside_kernels_gets_new_machine_code(tmp_path):
    # The OU driver's compiled recursion lives in plugins/drivers.py: its own file is part of its stamp.
    code = ("import numpy as np\nfrom slidernet.plugins.drivers import _ar1_in_place\n"
            "y = np.ones(3)\n_ar1_in_place(y, 0.5)\nprint(y[-1])")
    cache = tmp_path / "cache"
    root = _install_copy(tmp_path / "install")
    assert _python(code, root, cache).stdout.splitlines()[-1] == "1.75"
    drivers = root / "slidernet" / "plugins" / "drivers.py"
    text = drivers.read_text()
    line = "y[q] += phi * y[q - 1]"
    assert line in text
    drivers.write_text(text.replace(line, "y[q] += 2.0 * phi * y[q - 1]"))
    edited = _python(code, root, cache)
    assert _saved(edited.stdout, "_ar1_in_place") == 1
    assert edited.stdout.splitlines()[-1] == "3.0"


def test_a_two_worker_run_compiles_its_kernel_once_and_says_so_once(tmp_path):
    code = ("import slidernet\nslidernet.run({'seed': 1, 'realizations': 4, 'steps': 50, 'network': "
            "{'kind': 'two_slider', 'Ntilde': 1e-7}, 'friction': {'mu_d': 0.5, 'static': {'name': 'gaussian', "
            "'mean': 0.6, 'std': 0.01}}, 'driver': {'name': 'gaussian_steps', 'sigma_theta': 1e-6}}, "
            "workers=2, progress=True)")
    out = _python(code, _install_copy(tmp_path / "install"), tmp_path / "cache")
    assert _saved(out.stdout, "run_pair") == 1, out.stdout
    notices = [line for line in out.stderr.splitlines() if "compiling the kernels" in line]
    assert len(notices) == 1, out.stderr
    assert "once per installation" in notices[0] and "pair" in notices[0]
    again = _python(code, tmp_path / "install", tmp_path / "cache")
    assert _saved(again.stdout, "run_pair") == 0
    assert "compiling the kernels" not in again.stderr


def test_a_chain_without_mu_eff_compiles_no_tilt_test_and_nothing_2d(tmp_path):
    code = ("import slidernet\nslidernet.run({'seed': 1, 'realizations': 1, 'steps': 20, 'network': "
            "{'kind': 'chain', 'n': 5, 'Ntilde': 1e-7}, 'friction': {'mu_d': 0.5, 'static': {'name': 'gaussian', "
            "'mean': 0.6, 'std': 0.01}}, 'driver': {'name': 'gaussian_steps', 'sigma_theta': 1e-6}}, workers=1)")
    out = _python(code, _install_copy(tmp_path / "install"), tmp_path / "cache")
    saved = [line for line in out.stdout.splitlines() if "data saved to" in line]
    assert any(".run_chain-" in line for line in saved)
    for absent in (".tilt_", "tilt_net", ".plane.", "plane.", ".pair.", "run_pair"):
        assert not any(absent in Path(line.split("data saved to")[-1].strip(" '")).name for line in saved), absent


# Scenes whose probe must compile every function the real (larger, longer) run calls.
SCENES = {
    "pair": {"observables": ["n", "mu_max"]},
    "pair-mu_eff": {"observables": ["n", "mu_max", "x_G", "mu_eff"]},
    "pair-csr-mu_eff": {"observables": ["n", "mu_max", "x_G", "mu_eff"], "solver": {"kernel": "csr"}},
    "chain-mu_eff": {"network": {"kind": "chain", "n": 12, "Ntilde": 1e-7},
                     "observables": ["n", "mu_max", "x_G", "mu_eff"]},
    "triangular-mu_eff-events": {"network": {"kind": "triangular", "shape": [6, 7], "Ntilde": 1e-7},
                                 "observables": ["n", "mu_max", "x_G", "mu_eff", "events"],
                                 "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}},
    "square-exact": {"network": {"kind": "square", "shape": [5, 5], "Ntilde": 1e-7}, "observables": ["n"],
                     "solver": {"slip": "exact"}, "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}},
    "irregular-mu_eff-ou": {"network": {"kind": "irregular", "n": 50, "seed": 2, "Ntilde": 1e-7},
                            "observables": ["n", "mu_max", "x_G", "mu_eff"],
                            "driver": {"name": "ornstein_uhlenbeck", "sigma_theta": 1e-7, "tau_c": 3.0}},
}


def _scene_config(changes: dict[str, Any]) -> dict[str, Any]:
    cfg = make_config(realizations=2, steps=30, **{k: v for k, v in changes.items() if k != "network"})
    if "network" in changes:
        cfg["network"] = changes["network"]
    return cfg


@pytest.mark.parametrize("changes", SCENES.values(), ids=SCENES.keys())
def test_the_probe_compiles_everything_the_run_calls(changes):
    cfg = load_config(_scene_config(changes))
    compile_kernels(cfg, notice=None)
    with on_first_compile(lambda: None) as compiled:
        slidernet.run(cfg, workers=1)
    assert not compiled.compiled


@pytest.mark.parametrize(("changes", "parts"), [
    ({"observables": ["n"]}, ["pair"]),
    ({"observables": ["n", "mu_max", "mu_eff"]}, ["pair", "pair tilt test"]),
    ({"network": {"kind": "chain", "n": 30, "Ntilde": 1e-7}, "observables": ["n"]}, ["1D network"]),
    ({"network": {"kind": "chain", "n": 30, "Ntilde": 1e-7}, "observables": ["n", "mu_eff"]},
     ["1D network", "network tilt test"]),
    ({"network": {"kind": "square", "shape": [3, 3], "Ntilde": 1e-7}, "solver": {"slip": "exact"},
      "observables": ["n"]}, ["2D network", "exact 2D slip"]),
], ids=["pair", "pair-mu_eff", "chain", "chain-mu_eff", "square-exact"])
def test_the_notice_names_what_is_compiled(changes, parts):
    scene = Scene.from_config(load_config(_scene_config(changes)))
    assert kernel_parts(scene) == parts
    line = compile_notice(scene)
    assert all(p in line for p in parts) and "once per installation" in line
    assert re.search(r"about \d+ s the last time on this machine|how long is not known yet on this machine", line)


def test_the_probe_is_small_and_keeps_the_kernel():
    big = load_config(_scene_config({"network": {"kind": "irregular", "n": 5000, "seed": 4, "Ntilde": 1e-7}}))
    probe = probe_config(big)
    assert probe.network.n == 32 and probe.network.seed == 4 and probe.steps == 2 and probe.realizations == 1
    assert probe.friction.static.name == big.friction.static.name == "gaussian"
    lattice = load_config(_scene_config({"network": {"kind": "triangular", "shape": [1, 900], "Ntilde": 1e-7}}))
    assert probe_config(lattice).network.shape == (1, 4)


def test_the_probe_drives_gently_whatever_the_runs_sigma_theta():
    # sigma_theta = 1 at Ntilde = 1e-7 (a unit slip: 1 K meant) made the probe's two steps of a 4 x 4 lattice
    # take ~1e8 slips in one kernel call, before the run's signal handling: one SIGTERM did not stop it for
    # 30 s (benchmarks/config_fuzz.py, case 284 of seed 0).
    # allow_implausible: the unit slip itself, which plausibility now refuses without it
    wild = load_config(_scene_config({"network": {"kind": "triangular", "shape": [4, 4], "Ntilde": 1e-7},
                                      "driver": {"name": "gaussian_steps", "sigma_theta": 1.0},
                                      "allow_implausible": True}))
    probe = probe_config(wild)
    thetas = probe.driver_plugin().thetas(np.random.default_rng(0), 2)
    assert np.abs(thetas).max() <= probe.network.Ntilde
    assert probe.driver.name == "gaussian_steps" and probe.network.shape == (4, 4)
    compile_kernels(wild, notice=None)  # two steps of a few slips (it ran for minutes)
    gentle = load_config(_scene_config({}))
    assert probe_config(gentle).network.Ntilde == gentle.network.Ntilde  # the usual case is left alone
