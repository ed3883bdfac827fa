"""Plugin registries: run-time registration, entry-point discovery, broken plugins."""

from __future__ import annotations

from importlib.metadata import EntryPoint

import numpy as np
import pytest

import slidernet
from slidernet import PluginError, UnknownPluginError
from slidernet.config import load_config
from slidernet.plugins import distributions, drivers, registry
from tests.conftest import FixedThetas, make_config
from tests.plugin_fixtures import FakeDist, NanDist, ShortDriver

SMALL = {"steps": 20, "realizations": 2, "observables": ["n", "mu_max", "x_G"]}


@pytest.fixture
def fake_entry_points(monkeypatch, clean_registries):
    """Replace importlib.metadata discovery by a given list of entry points."""

    def install(*eps: EntryPoint) -> None:
        def entry_points(group: str):
            return [ep for ep in eps if ep.group == group]

        monkeypatch.setattr(registry, "entry_points", entry_points)
        registry.distributions.clear_cache()
        registry.drivers.clear_cache()

    return install


def test_register_distribution_at_run_time(clean_registries):
    slidernet.register_distribution("uniform_test", FakeDist)
    assert "uniform_test" in registry.distributions.names()
    cfg = make_config(**SMALL, **{"friction.static": {"name": "uniform_test", "low": 0.52, "high": 0.7}})
    ds = slidernet.run(cfg)
    mu_max = ds["mu_max"].values
    assert ((mu_max > 0.52) & (mu_max < 0.7)).all()
    assert ds["n"].values[:, -1].min() > 0


def test_register_driver_at_run_time(clean_registries):
    # A driver that never moves: no rearrangement can happen.
    slidernet.register_driver("still", lambda: FixedThetas([0.0] * 21))
    ds = slidernet.run(make_config(**SMALL, driver={"name": "still"}))
    assert (ds["n"].values == 0).all()
    assert (ds["x_G"].values == 0).all()


def test_run_time_registration_overrides_builtins_and_is_undone(clean_registries):
    # clean_registries restores the registry afterwards (checked by the next test).
    slidernet.register_distribution("gaussian", FakeDist)
    cfg = load_config(make_config(**SMALL, **{"friction.static": {"name": "gaussian"}}))
    assert isinstance(cfg.distribution().dist, FakeDist)


def test_builtin_gaussian_is_back():
    cfg = load_config(make_config(**SMALL))
    assert type(cfg.distribution().dist).__name__ == "Gaussian"
    assert "gaussian" not in registry.distributions._runtime


@pytest.mark.parametrize(
    ("name", "factory", "match"),
    [("", FakeDist, "non-empty string"), (3, FakeDist, "non-empty string"),
     ("x", "not callable", "must be callable")],
    ids=["empty-name", "int-name", "not-callable"],
)
def test_register_refuses_bad_arguments(name, factory, match, clean_registries):
    with pytest.raises(TypeError, match=match):
        slidernet.register_distribution(name, factory)


def test_entry_point_discovery(fake_entry_points):
    fake_entry_points(EntryPoint(name="fake", value="tests.plugin_fixtures:FakeDist",
                                 group="slidernet.distributions"))
    assert registry.distributions.names() == sorted(["fake", *distributions.BUILTINS])
    assert registry.drivers.names() == sorted(drivers.BUILTINS)  # other group untouched
    assert registry.distributions.get("fake") is FakeDist
    ds = slidernet.run(make_config(**SMALL, **{"friction.static": {"name": "fake", "high": 0.6}}))
    assert (ds["mu_max"].values <= 0.6).all()


def test_entry_points_are_looked_up_lazily_once(monkeypatch, fake_entry_points):
    calls = []

    def entry_points(group: str):
        calls.append(group)
        return [EntryPoint(name="fake", value="tests.plugin_fixtures:FakeDist", group=group)]

    fake_entry_points()
    monkeypatch.setattr(registry, "entry_points", entry_points)
    assert calls == []
    registry.distributions.get("fake")
    registry.distributions.get("fake")
    registry.distributions.names()
    assert calls == ["slidernet.distributions"]


def test_broken_entry_point_warns_then_is_unknown(fake_entry_points):
    fake_entry_points(EntryPoint(name="broken", value="tests.no_such_module:Thing",
                                 group="slidernet.distributions"))
    cfg = make_config(**SMALL, **{"friction.static": {"name": "broken"}})
    with pytest.warns(RuntimeWarning, match=r"distribution plugin 'broken' \(tests\.no_such_module:Thing\) "
                                            r"failed to load: ModuleNotFoundError"):
        with pytest.raises(UnknownPluginError, match=r"Unknown distribution 'broken'\. Available: .*'gaussian'"):
            load_config(cfg)


def test_broken_entry_point_does_not_break_the_others(fake_entry_points):
    fake_entry_points(
        EntryPoint(name="broken", value="tests.plugin_fixtures:DoesNotExist", group="slidernet.drivers"),
        EntryPoint(name="fake", value="tests.plugin_fixtures:FakeDist", group="slidernet.distributions"),
    )
    assert load_config(make_config(**SMALL, **{"friction.static": {"name": "fake"}})).steps == 20
    with pytest.warns(RuntimeWarning, match="'broken'"), pytest.raises(UnknownPluginError):
        registry.drivers.get("broken")


def test_plugin_returning_nan_is_named(clean_registries):
    slidernet.register_distribution("nan_dist", NanDist)
    cfg = make_config(**SMALL, **{"friction.static": {"name": "nan_dist"}})
    load_config(cfg)  # the cdf is fine: the problem shows only when sampling
    with pytest.raises(PluginError, match=r"The distribution 'nan_dist' returned NaN or inf values"):
        slidernet.run(cfg)


def test_distribution_of_wrong_shape_is_named(clean_registries):
    class Scalar(NanDist):
        def sample(self, rng, size):
            return np.float64(0.6)

    slidernet.register_distribution("scalar", Scalar)
    # The solver asks a plugin for fixed raw chunks of RAW_CHUNK draws (batch-independent streams).
    from slidernet.plugins.distributions import RAW_CHUNK

    with pytest.raises(PluginError, match=rf"'scalar' returned shape \(\) from sample\(rng, {RAW_CHUNK}\); "
                                          rf"expected \({RAW_CHUNK},\)"):
        slidernet.run(make_config(**SMALL, **{"friction.static": {"name": "scalar"}}))


def test_driver_of_wrong_shape_is_named(clean_registries):
    slidernet.register_driver("short", ShortDriver)
    with pytest.raises(PluginError, match=r"The driver 'short' returned shape \(20,\) from thetas\(rng, 20\); "
                                          r"expected \(21,\)"):
        slidernet.run(make_config(**SMALL, driver={"name": "short"}))


def test_driver_returning_inf_is_named(clean_registries):
    slidernet.register_driver("inf", lambda: FixedThetas([0.0] * 20 + [np.inf]))
    with pytest.raises(PluginError, match=r"The driver 'inf' returned NaN or inf"):
        slidernet.run(make_config(**SMALL, driver={"name": "inf"}))


def test_distribution_without_mass_above_mu_d_is_refused(clean_registries):
    # A uniform law on [0.1, 0.4] puts nothing above mu_d = 0.5: refused at load time.
    slidernet.register_distribution("low", FakeDist)
    cfg = make_config(**SMALL, **{"friction.static": {"name": "low", "low": 0.1, "high": 0.4}})
    with pytest.raises(slidernet.ConfigError, match=r"'friction\.static' field: The distribution 'low' puts "
                                                    r"probability 1\.0 at or below mu_d = 0\.5"):
        load_config(cfg)
