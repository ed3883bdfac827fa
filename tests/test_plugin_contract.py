"""The plugin contract: every discovered plugin, slidernet.testing itself, and the registry's safety.

Every name in ``registry.distributions`` and ``registry.drivers`` (built-ins,
entry points of installed packages, run-time registrations) is run through
:func:`slidernet.testing.check_distribution` / :func:`check_driver` with the
parameters its factory advertises in ``example_params`` (and, for a
distribution, ``example_mu_d``, default 0.5), then through a short run. A
plugin without ``example_params`` is skipped, saying so.
"""

from __future__ import annotations

import random
import re
import sys
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

import slidernet
from slidernet import PluginError, UnknownPluginError
from slidernet.cli import main
from slidernet.config import load_config
from slidernet.plugins import distributions, drivers, registry
from slidernet.testing import (
    DEFAULT_MU_D,
    PluginContractError,
    check_distribution,
    check_driver,
    example_file,
    example_of,
)
from tests.conftest import FixedThetas, make_config
from tests.plugin_fixtures import FakeDist, NanDist, ShortDriver

TINY = {"steps": 10, "realizations": 1, "observables": ["n", "mu_max", "x_G"], "seed": 7}


def _example(reg: registry.Registry, name: str) -> tuple[object, dict]:
    factory = reg.get(name)
    params = example_of(factory)
    if params is None:
        pytest.skip(f"the {reg.kind} {name!r} ({getattr(factory, '__qualname__', factory)!r}) declares no "
                    f"'example_params', so the contract test cannot build it")
    return factory, params


# --------------------------------------------------------------------------
# Every discovered plugin
# --------------------------------------------------------------------------


@pytest.mark.parametrize("name", registry.distributions.names())
def test_distribution_follows_the_contract(name):
    factory, params = _example(registry.distributions, name)
    mu_d = float(getattr(factory, "example_mu_d", DEFAULT_MU_D))
    check_distribution(factory, params, mu_d=mu_d, name=name)
    # And through a configuration, the way a user meets it.
    ds = slidernet.run(make_config(**TINY, **{"friction.mu_d": mu_d, "friction.static": {"name": name, **params}}))
    assert (ds["mu_max"].values > mu_d).all()


@pytest.mark.parametrize("name", registry.drivers.names())
def test_driver_follows_the_contract(name):
    factory, params = _example(registry.drivers, name)
    check_driver(factory, params, name=name)
    ds = slidernet.run(make_config(**TINY, driver={"name": name, **params}))
    assert np.isfinite(ds["x_G"].values).all()


BUILTINS = [(registry.distributions, name) for name in distributions.BUILTINS] + [
    (registry.drivers, name) for name in drivers.BUILTINS]


@pytest.mark.parametrize(("reg", "name"), BUILTINS, ids=[name for _, name in BUILTINS])
def test_every_builtin_has_an_example_so_the_contract_test_never_skips_it(reg, name):
    # The file-reading built-ins (empirical, series) used to be skipped on every run.
    params = example_of(reg.get(name))
    assert params is not None
    if "path" in params:
        assert Path(params["path"]).is_file()
        assert Path(params["path"]).parent == Path(example_file("README.md")).parent


def test_the_shipped_example_files_are_what_their_note_says(tmp_path, monkeypatch):
    # slidernet/plugins/data/README.md holds the script that made them: rerun it and compare bytes.
    note = Path(example_file("README.md")).read_text(encoding="utf-8")
    script = re.search(r"```python\n(.*?)```", note, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    exec(compile(script, "slidernet/plugins/data/README.md", "exec"), {})
    for name in ("mu_s_example.txt", "temperature_example.csv"):
        assert (tmp_path / name).read_bytes() == Path(example_file(name)).read_bytes(), name


def test_the_shipped_examples_are_read_as_the_note_describes():
    # Comment lines skipped, every value kept (truncation below mu_d happens later).
    values = np.loadtxt(example_file("mu_s_example.txt"))
    assert values.size == 200
    law = distributions.Empirical(**example_of(distributions.Empirical))
    assert law.values.tolist() == sorted(values.tolist())
    # The header line skipped; 8 days of hourly samples cover 192 steps of tau_th = 1 h.
    series = drivers.Series(**example_of(drivers.Series))
    assert series.covered_steps == 192
    theta = series.thetas(np.random.default_rng(0), 24)
    np.testing.assert_allclose(theta / 1.2e-5 + 15.0, series.temperature[:25], rtol=0, atol=1e-9)


# --------------------------------------------------------------------------
# The checks catch what they promise to catch
# --------------------------------------------------------------------------


class GlobalNumpy(FakeDist):
    def sample(self, rng, size):
        return np.random.uniform(self.low, self.high, size)  # noqa: NPY002 - the error under test


class GlobalPython(FakeDist):
    def sample(self, rng, size):
        return np.array([random.uniform(self.low, self.high) for _ in range(size)])


class HiddenState(FakeDist):
    def __init__(self) -> None:
        super().__init__()
        self.own = np.random.default_rng(0)

    def sample(self, rng, size):
        return self.own.uniform(self.low, self.high, size)


class AsList(FakeDist):
    def sample(self, rng, size):
        return list(rng.uniform(self.low, self.high, size))


class Integers(FakeDist):
    def sample(self, rng, size):
        return rng.integers(0, 2, size)


class ScalarCdf(FakeDist):
    def cdf(self, x):
        return 0.5


class Decreasing(FakeDist):
    def cdf(self, x):
        return 1.0 - super().cdf(x)


class AboveOne(FakeDist):
    def cdf(self, x):
        return 2.0 * super().cdf(x)


class WrongCdf(FakeDist):
    def cdf(self, x):  # the cdf of [0.55, 0.75]: not what sample draws
        return np.clip((np.asarray(x, dtype=float) - 0.55) / 0.2, 0.0, 1.0)


class WrongSf(FakeDist):
    def sf(self, x):
        return self.cdf(x)


class Refuses(FakeDist):
    def check_mu_d(self, mu_d):
        raise slidernet.ConfigError("The 'low' parameter of refuses must be > mu_d.")


BROKEN_DISTRIBUTIONS = [
    (GlobalNumpy, r"sample\(rng, 1\) used numpy's global RNG"),
    (GlobalPython, r"sample\(rng, 1\) used Python's global 'random' module"),
    (HiddenState, r"sample\(rng, 4000\) gave different values for two Generators of the same seed"),
    (NanDist, r"sample\(rng, 1\) returned 1 NaN or inf values"),
    (AsList, r"sample\(rng, 1\) returned list, not a numpy array"),
    (Integers, r"sample\(rng, 1\) returned dtype int64; expected floats"),
    (ScalarCdf, r"cdf\(x\) on \d+ points returned shape \(\); expected \(\d+,\)"),
    (Decreasing, r"cdf\(x\) decreases, from 1\.0 at x = "),
    (AboveOne, r"cdf\(x\) left \[0, 1\] \(min 0\.0, max 2\.0\)"),
    (WrongCdf, r"the draws do not follow cdf\(x\): at x = .* \(allowed gap 0\.05\d* for 4000 draws\)"),
    (WrongSf, r"sf\(x\) is not 1 - cdf\(x\)"),
    (Refuses, r"check_mu_d\(0\.5\) refused these parameters: The 'low' parameter of refuses"),
]


@pytest.mark.parametrize(("cls", "match"), BROKEN_DISTRIBUTIONS, ids=[c.__name__ for c, _ in BROKEN_DISTRIBUTIONS])
def test_check_distribution_catches(cls, match):
    with pytest.raises(PluginContractError, match=rf"^'broken': {match}"):
        check_distribution(cls, mu_d=0.5, name="broken")


def test_check_distribution_refuses_a_law_without_mass_above_mu_d():
    with pytest.raises(PluginContractError, match=r"cannot be truncated below mu_d = 0\.5: The distribution "
                                                  r"'low' puts probability 1\.0 at or below mu_d"):
        check_distribution(FakeDist, {"low": 0.1, "high": 0.4}, mu_d=0.5, name="low")


def test_check_distribution_accepts_discrete_laws():
    class Atoms:
        """Three equally likely thresholds (a law with atoms: the cdf check must still hold)."""

        values = np.array([0.55, 0.6, 0.7])

        def sample(self, rng, size):
            return rng.choice(self.values, size)

        def cdf(self, x):
            return (np.asarray(x, dtype=float)[..., None] >= self.values).mean(axis=-1)

    check_distribution(Atoms(), mu_d=0.5)


def test_check_distribution_names_the_class_without_a_name():
    with pytest.raises(PluginContractError, match=r"^tests\.plugin_fixtures\.NanDist: sample"):
        check_distribution(NanDist)


def test_a_contract_error_is_an_assertion_error():
    assert issubclass(PluginContractError, AssertionError)
    assert issubclass(PluginContractError, slidernet.SlidernetError)


class NanDriver:
    def thetas(self, rng, steps):
        out = rng.standard_normal(steps + 1) * 1e-6
        out[-1] = np.nan
        return out


class GlobalDriver:
    def thetas(self, rng, steps):
        return np.random.standard_normal(steps + 1) * 1e-6  # noqa: NPY002 - the error under test


class HiddenDriver:
    def __init__(self) -> None:
        self.calls = 0

    def thetas(self, rng, steps):
        self.calls += 1
        return rng.standard_normal(steps + 1) * 1e-6 * self.calls


BROKEN_DRIVERS = [
    (ShortDriver, r"thetas\(rng, 1\) returned shape \(1,\); expected \(2,\)"),
    (NanDriver, r"thetas\(rng, 1\) returned 1 NaN or inf values \(first at index 1\)"),
    (GlobalDriver, r"thetas\(rng, 1\) used numpy's global RNG"),
    (HiddenDriver, r"thetas\(rng, 1\) gave different values for two Generators of the same seed"),
    (lambda: FixedThetas([0.0, 1e-6]), r"thetas\(rng, 2\) returned shape \(2,\); expected \(3,\)"),
]


@pytest.mark.parametrize(("factory", "match"), BROKEN_DRIVERS, ids=["short", "nan", "global", "hidden", "fixed"])
def test_check_driver_catches(factory, match):
    with pytest.raises(PluginContractError, match=rf"^'broken': {match}"):
        check_driver(factory, name="broken")


def test_check_driver_accepts_deterministic_drivers():
    check_driver(lambda: FixedThetas(np.linspace(0.0, 1e-6, 101)), steps=(100,))


def test_checks_take_factories_or_objects():
    built = FakeDist(0.5, 0.7)
    assert check_distribution(built) is built
    assert isinstance(check_distribution(FakeDist, {"low": 0.5, "high": 0.7}), FakeDist)
    with pytest.raises(TypeError, match="params are for a factory"):
        check_distribution(built, {"low": 0.5})


def test_example_params_must_be_a_dict():
    class Odd(FakeDist):
        example_params: ClassVar = [("low", 0.5)]

    with pytest.raises(PluginContractError, match="'example_params' must be a dict"):
        check_distribution(Odd)


# --------------------------------------------------------------------------
# The registry's safety
# --------------------------------------------------------------------------


@pytest.fixture
def fake_entry_points(monkeypatch, clean_registries):
    """Replace importlib.metadata discovery by a given list of entry points."""

    def install(*eps: EntryPoint) -> None:
        monkeypatch.setattr(registry, "entry_points", lambda group: [ep for ep in eps if ep.group == group])
        registry.distributions.clear_cache()
        registry.drivers.clear_cache()

    return install


def test_broken_entry_point_warns_naming_it_and_the_rest_still_works(fake_entry_points, capsys):
    fake_entry_points(
        EntryPoint(name="broken_law", value="no_such_package.laws:Law", group="slidernet.distributions"),
        EntryPoint(name="fake", value="tests.plugin_fixtures:FakeDist", group="slidernet.distributions"),
        EntryPoint(name="broken_driver", value="tests.plugin_fixtures:NoSuchDriver", group="slidernet.drivers"),
    )
    with pytest.warns(RuntimeWarning, match=r"The distribution plugin 'broken_law' \(no_such_package\.laws:Law\) "
                                            r"failed to load: ModuleNotFoundError"):
        with pytest.raises(UnknownPluginError, match=r"Unknown distribution 'broken_law'"):
            registry.distributions.get("broken_law")
    with pytest.warns(RuntimeWarning, match=r"driver plugin 'broken_driver' .* failed to load: AttributeError"):
        with pytest.raises(UnknownPluginError):
            registry.drivers.get("broken_driver")
    # The rest of both registries still works: built-ins and the good entry point.
    assert {"gaussian", "fake", "broken_law"} <= set(registry.distributions.names())
    assert registry.distributions.get("fake") is FakeDist
    ds = slidernet.run(make_config(**TINY, **{"friction.static": {"name": "fake"}}))
    assert ds["n"].shape == (1, ds.sizes["t"])
    # `slidernet plugins` lists the broken ones as such, and the others as usual.
    assert main(["plugins"]) == 0
    out = capsys.readouterr().out
    assert "broken_law" in out and "FAILED TO LOAD (no_such_package.laws:Law): ModuleNotFoundError" in out
    assert "FAILED TO LOAD (tests.plugin_fixtures:NoSuchDriver): AttributeError" in out
    assert "fake" in out and "A uniform p(mu_s) on [low, high], as a third-party package would ship it." in out


@pytest.mark.parametrize("kind", ["distribution", "driver"])
def test_plugin_returning_nan_is_stopped_naming_it(kind, clean_registries):
    if kind == "distribution":
        slidernet.register_distribution("nan_law", NanDist)
        cfg = make_config(**TINY, **{"friction.static": {"name": "nan_law"}})
        name = "nan_law"
    else:
        slidernet.register_driver("nan_driver", NanDriver)
        cfg = make_config(**TINY, driver={"name": "nan_driver"})
        name = "nan_driver"
    with pytest.raises(PluginError, match=rf"^The {kind} '{name}' returned NaN or inf values from "):
        slidernet.run(cfg)
    with pytest.raises(PluginContractError, match=rf"^'{name}': .* NaN or inf values"):
        (check_distribution if kind == "distribution" else check_driver)(
            registry.distributions.get(name) if kind == "distribution" else registry.drivers.get(name), name=name
        )


MODULE_PATHS = ["os:system", "pkg.mod:Class", "slidernet.plugins.distributions:Gaussian",
                "tests.plugin_fixtures:FakeDist", "this:s", "subprocess.run", "builtins:eval"]


@pytest.mark.parametrize("path", MODULE_PATHS)
@pytest.mark.parametrize("key", ["friction.static.name", "driver.name"])
def test_configs_never_import_code_by_module_path(path, key):
    had_this = "this" in sys.modules  # `import this` prints; it must not happen
    with pytest.raises(UnknownPluginError, match=r"^Unknown (distribution|driver) '" + path.replace(".", r"\.")
                       + r"'\. Available: "):
        load_config(make_config(**{key: path}))
    assert ("this" in sys.modules) == had_this


# --------------------------------------------------------------------------
# slidernet plugins
# --------------------------------------------------------------------------


def test_cli_plugins_lists_origin_and_summary(clean_registries, capsys):
    slidernet.register_distribution("mine", FakeDist)
    slidernet.register_driver("no_doc", lambda: FixedThetas([0.0, 0.0]))
    assert main(["plugins"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "distributions (slidernet.distributions):"
    row = {line.split()[0]: line for line in lines if line.startswith("  ")}
    assert row["gaussian"].split()[1] == "built-in"
    assert "Gaussian p(mu_s) of the paper" in row["gaussian"]
    assert row["mine"].split()[1:3] == ["run", "time"]
    assert row["mine"].endswith("A uniform p(mu_s) on [low, high], as a third-party package would ship it.")
    assert row["no_doc"].endswith("(no docstring)")
    assert row["gaussian_steps"].split()[1] == "built-in"


def test_cli_plugins_names_the_package_of_an_entry_point(monkeypatch, clean_registries, capsys):
    class Dist:  # what importlib.metadata gives an entry point of an installed package
        name, version = "slidernet-example", "1.2.3"

    ep = EntryPoint(name="example", value="tests.plugin_fixtures:FakeDist", group="slidernet.distributions")
    monkeypatch.setattr(registry, "entry_points", lambda group: [ep] if group == ep.group else [])
    monkeypatch.setattr(EntryPoint, "dist", Dist(), raising=False)
    registry.distributions.clear_cache()
    assert main(["plugins"]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("  example "))
    assert "slidernet-example 1.2.3" in row and row.endswith("as a third-party package would ship it.")
