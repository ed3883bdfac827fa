"""A plugin's own errors are the plugin's (issue 43, items 6 and 8).

A plugin that raised was reported as "internal error: this is a bug of
slidernet" (exit 1, a traceback), one that called ``sys.exit(5)`` ended
the command with status 5 and no word. Now every call of a plugin's code
(its factory, its methods, in this process and in a worker) turns what it
raises into a :class:`~slidernet.errors.PluginError` naming the plugin,
where it comes from, the call and the plugin's own line (exit 2, one line);
its KeyboardInterrupt stops the run as Ctrl-C does.
"""

from __future__ import annotations

import pickle
import re
import signal
from pathlib import Path

import numpy as np
import pytest

import slidernet
from slidernet.cli import main
from slidernet.config import load_config
from slidernet.errors import PluginError, RunInterrupted
from slidernet.plugins import registry
from slidernet.plugins.distributions import Gaussian
from tests import plugin_fixtures
from tests.plugin_fixtures import FakeDist

SOURCE = re.escape(str(Path(plugin_fixtures.__file__).resolve()))
LINE = r"\(line \d+ of plugin_fixtures\.py\)\."


def _config(static: str = "fake", driver: str = "gaussian_steps") -> dict:
    return {"seed": 3, "realizations": 2, "steps": 50, "observables": ["n", "mu_max"],
            "network": {"kind": "two_slider", "Ntilde": 1e-7},
            "friction": {"mu_d": 0.5, "static": {"name": static}},
            "driver": {"name": driver, "sigma_theta": 1e-6}}


@pytest.fixture
def faulty(clean_registries: None) -> None:
    for name, factory in [("fake", FakeDist), ("raising", plugin_fixtures.Raising),
                          ("exiting", plugin_fixtures.Exiting), ("interrupting", plugin_fixtures.Interrupting),
                          ("broken_factory", plugin_fixtures.BrokenFactory)]:
        registry.register_distribution(name, factory)
    registry.register_driver("raising_driver", plugin_fixtures.RaisingDriver)


def test_a_factory_that_raises_is_the_plugins_error(faulty):
    with pytest.raises(PluginError, match=rf"^The distribution 'broken_factory' \({SOURCE}\) failed in its "
                                          r"factory, BrokenFactory\(\): ValueError: cannot make a law on "
                                          rf"\[0\.55, 0\.65\] {LINE}$"):
        load_config(_config("broken_factory")).distribution()


def test_a_driver_that_raises_is_the_plugins_error_before_the_run(faulty, tmp_path):
    # The driver is sampled before the run, to check float64's precision and the run's length.
    with pytest.raises(PluginError, match=rf"^The driver 'raising_driver' \({SOURCE}\) failed in thetas\(\): "
                                          rf"KeyError: 'sigma' {LINE}$"):
        slidernet.run(_config(driver="raising_driver"), out=tmp_path / "out")
    assert not (tmp_path / "out").exists()  # refused before any file


@pytest.mark.parametrize("workers", [1, 2], ids=["in-process", "two-workers"])
def test_a_method_that_raises_during_the_run_is_the_plugins_error(faulty, workers):
    # In a worker, the error crosses to the parent pickled: its class and message arrive whole.
    with pytest.raises(PluginError, match=rf"^The distribution 'raising' \({SOURCE}\) failed in sample\(\): "
                                          rf"ZeroDivisionError: float division by zero {LINE}$"):
        slidernet.run(_config("raising"), workers=workers)


@pytest.mark.parametrize("workers", [1, 2], ids=["in-process", "two-workers"])
def test_a_plugins_sys_exit_is_its_error(faulty, workers):
    with pytest.raises(PluginError, match=r"^The distribution 'exiting' \(.*\) called sys\.exit\(5\) in "
                                          r"sample\(\): a plugin may not end the process; raise an exception "
                                          r"instead\.$"):
        slidernet.run(_config("exiting"), workers=workers)


@pytest.mark.parametrize("workers", [1, 2], ids=["in-process", "two-workers"])
def test_a_plugins_keyboard_interrupt_stops_the_run_as_ctrl_c(faulty, tmp_path, workers):
    with pytest.raises(RunInterrupted, match="interrupted by SIGINT: 0 of 2 realizations are finished") as info:
        slidernet.run(_config("interrupting"), out=tmp_path / "out", workers=workers)
    assert info.value.signum == signal.SIGINT


def test_the_command_says_a_plugins_error_in_one_line_and_exits_2(faulty, tmp_path, capsys):
    config = tmp_path / "run.toml"
    config.write_text('seed = 3\nrealizations = 2\nsteps = 50\n[network]\nkind = "two_slider"\nNtilde = 1e-7\n'
                      '[friction]\nmu_d = 0.5\nstatic = { name = "raising" }\n'
                      '[driver]\nname = "gaussian_steps"\nsigma_theta = 1e-6\n')
    assert main(["run", str(config), "--out", str(tmp_path / "out"), "--no-progress", "--workers", "1"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and re.fullmatch(rf"slidernet: error: The distribution 'raising' \({SOURCE}\) failed in "
                                          rf"sample\(\): ZeroDivisionError: float division by zero {LINE}", err[0])
    assert not (tmp_path / "out").exists()  # nothing was saved: the folder is left as it was found


def test_a_guarded_plugin_is_still_the_plugin(faulty):
    dist = load_config(_config("fake")).distribution().dist
    assert isinstance(dist, FakeDist) and repr(dist) == repr(dist._plugin)
    again = pickle.loads(pickle.dumps(dist))
    draws = again.sample(np.random.default_rng(0), 3)
    np.testing.assert_array_equal(draws, FakeDist().sample(np.random.default_rng(0), 3))
    assert not hasattr(dist, "sf")  # an optional method the plugin lacks stays absent


def test_a_built_in_is_called_as_it_is():
    # An error of a built-in is a bug of slidernet: it keeps its traceback (exit 1).
    cfg = {**_config(), "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}}
    assert type(load_config(cfg).distribution().dist) is Gaussian


@pytest.mark.parametrize("code", [3, "bye"], ids=["status", "message"])
def test_a_plugin_file_that_exits_while_imported_is_the_plugins_error(tmp_path, capsys, code):
    # Such a file ended the command with its own status and no word (a SystemExit passed the loader).
    plugin = tmp_path / "quits.py"
    plugin.write_text(f"import sys\nsys.exit({code!r})\n")
    config = tmp_path / "run.toml"
    config.write_text('plugins = ["quits.py"]\n[network]\nkind = "two_slider"\nNtilde = 1e-7\n[friction]\n'
                      'mu_d = 0.5\n[friction.static]\nname = "gaussian"\nmean = 0.6\nstd = 0.01\n[driver]\n'
                      'name = "gaussian_steps"\nsigma_theta = 1e-6\n')
    assert main(["run", str(config), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("slidernet: error: ") and err.count("\n") == 1
    assert f"it called sys.exit({code!r}) while being imported" in err
    assert not (tmp_path / "out").exists()
