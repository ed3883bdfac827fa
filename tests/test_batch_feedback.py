"""Feedback that fits a batch job: nearest spellings, errors before heavy imports, progress lines, the compile
notice's measured time, the scheduler's timeout as said."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from slidernet import ConfigError, UnknownPluginError
from slidernet.config import load_config
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
