"""Feedback that fits a batch job: nearest spellings, errors before heavy imports, progress lines, the compile
notice's measured time, the scheduler's timeout as said."""

from __future__ import annotations

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
