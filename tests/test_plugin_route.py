"""A law or driver of one's own, from a .py file or a module, used by `slidernet run` (issue #35).

The routes: the configuration's ``plugins`` key, ``--plugin`` on the
command line, a dotted module name; the errors that stop a run before any
work; importing twice; workers that import the file again; and the guide's
example as written.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from slidernet.cli import main
from slidernet.config import load_config
from slidernet.errors import ConfigError, UnknownPluginError
from slidernet.plugins import registry
from slidernet.plugins.loader import import_plugins, module_name

ROOT = Path(__file__).resolve().parents[1]
GUIDE = ROOT / "docs" / "guides" / "distributions-and-drivers.md"

#: A plugin file: a two-Gaussian mixture of mu_s, registered as "route_bimodal". Each import appends a
#: line to `imports.log` next to the file, so that a test can count how often the file ran.
LAWS = '''
import numpy as np
from pathlib import Path
from scipy.special import ndtr

import slidernet

with open(Path(__file__).with_name("imports.log"), "a") as log:
    log.write("imported\\n")


class RouteBimodal:
    """Two populations of thresholds (tests only)."""

    truncate_below_mu_d = True

    def __init__(self, mean1, mean2, std, weight=0.5):
        self.mean1, self.mean2, self.std, self.weight = mean1, mean2, std, weight

    def sample(self, rng, size):
        first = rng.random(size) < self.weight
        return np.where(first, self.mean1, self.mean2) + self.std * rng.standard_normal(size)

    def cdf(self, x):
        x = np.asarray(x, dtype=float)
        first, second = ndtr((x - self.mean1) / self.std), ndtr((x - self.mean2) / self.std)
        return self.weight * first + (1 - self.weight) * second


slidernet.register_distribution("route_bimodal", RouteBimodal)
'''

#: A tiny two-slider run on that law; `{plugins}` is replaced by a `plugins = [...]` line or nothing.
TOML = '''
{plugins}
seed = 3
realizations = {realizations}
steps = 200
observables = ["n", "mu_max"]

[network]
kind = "two_slider"
Ntilde = 1e-7

[friction]
mu_d = 0.5
static = {{ name = "route_bimodal", mean1 = 0.58, mean2 = 0.62, std = 0.005, weight = 0.7 }}

[driver]
name = "gaussian_steps"
sigma_theta = 1e-6
'''


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def _toml(path: Path, plugins: list[str] | None = None, realizations: int = 3) -> Path:
    line = "" if plugins is None else f"plugins = {json.dumps(plugins)}"
    return _write(path, TOML.format(plugins=line, realizations=realizations))


def _run(toml: Path, out: Path, *extra: str, workers: int = 1) -> xr.Dataset:
    status = main(["run", str(toml), "--out", str(out), "--workers", str(workers), "--no-progress", *extra])
    assert status == 0
    assert (out / "result.nc").is_file()
    return xr.load_dataset(out / "result.nc")


def _imports(folder: Path) -> int:
    log = folder / "imports.log"
    return len(log.read_text().splitlines()) if log.exists() else 0


@pytest.fixture
def forget_route_pkg():
    """Forget the test package ``route_pkg`` after the test, so that the next one imports its own."""
    yield
    for name in [name for name in sys.modules if name == "route_pkg" or name.startswith("route_pkg.")]:
        del sys.modules[name]


# ---------------------------------------------------------------------------
# the three routes


def test_a_file_in_plugins_is_found_next_to_the_toml_and_its_law_runs(tmp_path, monkeypatch, clean_registries):
    laws = _write(tmp_path / "study" / "laws" / "my_laws.py", LAWS)
    toml = _toml(tmp_path / "study" / "run.toml", plugins=["laws/my_laws.py"])
    monkeypatch.chdir(_write(tmp_path / "elsewhere" / "x", "").parent)  # relative to the TOML, not to here
    ds = _run(toml, tmp_path / "out")
    assert ds.sizes["realization"] == 3
    assert json.loads(ds.attrs["config"])["plugins"] == [str(laws)]
    assert json.loads(ds.attrs["config"])["friction"]["static"]["name"] == "route_bimodal"
    assert registry.distributions.origin("route_bimodal") == "run time"


def test_the_plugin_option_adds_a_file_relative_to_the_current_directory(tmp_path, monkeypatch, clean_registries):
    _write(tmp_path / "my_laws.py", LAWS)
    toml = _toml(tmp_path / "configs" / "run.toml")  # no plugins key
    monkeypatch.chdir(tmp_path)
    ds = _run(toml, tmp_path / "out", "--plugin", "my_laws.py")
    assert json.loads(ds.attrs["config"])["plugins"] == [str(tmp_path / "my_laws.py")]


def test_the_plugin_option_appends_to_the_listed_ones_once(tmp_path, monkeypatch, clean_registries):
    laws = _write(tmp_path / "my_laws.py", LAWS)
    toml = _toml(tmp_path / "run.toml", plugins=["my_laws.py"])
    monkeypatch.chdir(tmp_path)
    ds = _run(toml, tmp_path / "out", "--plugin", "my_laws.py", "--plugin", "json")
    assert json.loads(ds.attrs["config"])["plugins"] == [str(laws), "json"]


def test_a_dotted_module_name_is_imported_from_sys_path(tmp_path, monkeypatch, clean_registries, forget_route_pkg):
    _write(tmp_path / "route_pkg" / "__init__.py", "")
    _write(tmp_path / "route_pkg" / "laws.py", LAWS)
    monkeypatch.syspath_prepend(str(tmp_path))
    ds = _run(_toml(tmp_path / "run.toml", plugins=["route_pkg.laws"]), tmp_path / "out")
    assert json.loads(ds.attrs["config"])["plugins"] == ["route_pkg.laws"]
    assert _imports(tmp_path / "route_pkg") == 1


def test_the_sweep_takes_the_plugin_option(tmp_path, monkeypatch, clean_registries):
    _write(tmp_path / "my_laws.py", LAWS)
    toml = _toml(tmp_path / "run.toml", realizations=2)
    monkeypatch.chdir(tmp_path)
    status = main(["sweep", str(toml), "--set", "friction.static.weight=0.3,0.7", "--plugin", "my_laws.py",
                   "--out", str(tmp_path / "out"), "--workers", "1", "--no-progress"])
    assert status == 0
    with xr.open_dataset(tmp_path / "out" / "result.nc") as ds:
        assert ds.sizes["weight"] == 2
        assert json.loads(ds.attrs["config"])["plugins"] == [str(tmp_path / "my_laws.py")]


def test_slidernet_plugins_lists_what_a_file_registers(tmp_path, monkeypatch, capsys, clean_registries):
    _write(tmp_path / "my_laws.py", LAWS)
    monkeypatch.chdir(tmp_path)
    assert main(["plugins", "--plugin", "my_laws.py"]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines() if "route_bimodal" in line)
    assert re.search(r"route_bimodal +run time +Two populations of thresholds", line)


def test_two_forked_workers_import_the_file_and_give_the_same_bits(tmp_path, clean_registries):
    _write(tmp_path / "my_laws.py", LAWS)
    toml = _toml(tmp_path / "run.toml", plugins=["my_laws.py"], realizations=4)
    two = _run(toml, tmp_path / "two", workers=2)
    one = _run(toml, tmp_path / "one", workers=1)
    np.testing.assert_array_equal(two["n"].values, one["n"].values)
    np.testing.assert_array_equal(two["mu_max"].values, one["mu_max"].values)


def test_a_fresh_process_imports_the_file_from_the_config_alone(tmp_path, clean_registries):
    # What a spawned or Dask worker does: load the run's configuration, as JSON, in another folder.
    # (__class__: the object is the plugin wrapped so that its errors are named as its, plugins.guard.)
    laws = _write(tmp_path / "my_laws.py", LAWS)
    cfg = load_config(_toml(tmp_path / "run.toml", plugins=["my_laws.py"]))
    code = ("import json, sys; from slidernet.ensemble.execution import scene_of; "
            "scene = scene_of(sys.stdin.read()); print(scene.distribution.dist.__class__.__module__)")
    done = subprocess.run([sys.executable, "-c", code], input=json.dumps(cfg.model_dump(mode="json")),
                          capture_output=True, text=True, cwd=_write(tmp_path / "elsewhere" / "x", "").parent,
                          check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == module_name(laws)


def test_a_config_without_plugins_dumps_as_before(tmp_path, clean_registries):
    # The key is left out of the stored configuration when unset: earlier results and run.json still match.
    _write(tmp_path / "my_laws.py", LAWS)
    import_plugins([str(tmp_path / "my_laws.py")])
    cfg = load_config(_toml(tmp_path / "run.toml"))
    assert cfg.plugins is None
    assert "plugins" not in cfg.model_dump(mode="json")


# ---------------------------------------------------------------------------
# once per process


def test_importing_a_file_twice_runs_it_once(tmp_path, monkeypatch, clean_registries):
    laws = _write(tmp_path / "my_laws.py", LAWS)
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path)
    first = import_plugins([str(laws)])
    # The same file under another spelling, then through two loads of a configuration.
    again = import_plugins(["my_laws.py", str(tmp_path / "sub" / ".." / "my_laws.py")])
    toml = _toml(tmp_path / "run.toml", plugins=["my_laws.py"])
    load_config(toml)
    load_config(toml)
    assert _imports(tmp_path) == 1
    assert again == first * 2
    assert first[0].__name__ == module_name(laws) in sys.modules
    assert first[0].RouteBimodal.__module__ == module_name(laws)  # so that its objects pickle by reference


def test_a_file_that_failed_can_be_fixed_and_imported(tmp_path, clean_registries):
    laws = _write(tmp_path / "my_laws.py", "raise RuntimeError('no data yet')\n")
    with pytest.raises(ConfigError, match="RuntimeError: no data yet"):
        import_plugins([str(laws)])
    assert module_name(laws) not in sys.modules
    _write(laws, LAWS)
    import_plugins([str(laws)])
    assert "route_bimodal" in registry.distributions.names()


# ---------------------------------------------------------------------------
# errors, before any work


BROKEN = {
    "missing-file": ("nope.py", None,
                     r"The 'plugins' field: cannot import '.*nope\.py': No such file\. A path in a configuration "
                     r"file is relative to that file"),
    "syntax-error": ("broken.py", "def f(:\n    pass\n",
                     r"The 'plugins' field: cannot import '.*broken\.py': SyntaxError: .*line 1"),
    "raises": ("raises.py", "x = 1\nraise ValueError('mu_s table missing')\n",
               r"The 'plugins' field: cannot import '.*raises\.py': ValueError: mu_s table missing "
               r"\(line 2 of raises\.py\)\."),
    "missing-dependency": ("needs.py", "import no_such_dependency_of_a_plugin\n",
                           r"cannot import '.*needs\.py': ModuleNotFoundError: No module named "
                           r"'no_such_dependency_of_a_plugin' \(line 1 of needs\.py\)"),
    "module-not-found": ("no_such_package.laws", None,
                         r"The 'plugins' field: cannot import 'no_such_package\.laws': No module named "
                         r"'no_such_package'\. Install it, or put the folder that holds it on PYTHONPATH\."),
    "not-a-name": ("my laws", None,
                   r"cannot import 'my laws': it is neither the path of a Python file \(ending in \.py\) nor a "
                   r"dotted module name"),
    "a-folder": ("folder.py", "", r"cannot import '.*folder\.py': it is not a file\."),
}


@pytest.mark.parametrize(("entry", "source", "message"), BROKEN.values(), ids=BROKEN.keys())
def test_a_plugin_that_cannot_be_imported_stops_the_run_before_any_work(entry, source, message, tmp_path,
                                                                        capsys, clean_registries):
    if entry == "folder.py":
        (tmp_path / entry).mkdir()
    elif source is not None:
        _write(tmp_path / entry, source)
    _write(tmp_path / "ok.py", LAWS)
    toml = _toml(tmp_path / "run.toml", plugins=["ok.py", entry])
    with pytest.raises(ConfigError, match=message):
        load_config(toml)
    out = tmp_path / "out"
    assert main(["run", str(toml), "--out", str(out), "--workers", "1", "--no-progress"]) == 2
    assert re.search(message, capsys.readouterr().err)
    assert not out.exists()


def test_a_plugins_value_that_is_not_a_list_is_refused_by_name(tmp_path, clean_registries):
    _write(tmp_path / "run.toml", TOML.format(plugins='plugins = "my_laws.py"', realizations=1))
    with pytest.raises(ConfigError, match=r"The 'plugins' field: Input should be a valid list"):
        load_config(tmp_path / "run.toml")


@pytest.mark.parametrize(("key", "kind", "group", "register"), [
    ("friction.static", "distribution", "slidernet.distributions", "slidernet.register_distribution"),
    ("driver", "driver", "slidernet.drivers", "slidernet.register_driver"),
], ids=["distribution", "driver"])
def test_an_unknown_name_says_how_to_add_one(key, kind, group, register, tmp_path, clean_registries):
    text = TOML.format(plugins="", realizations=1)
    if key == "driver":
        text = text.replace('name = "gaussian_steps"', 'name = "my_telegraph"')
        _write(tmp_path / "my_laws.py", LAWS)
        text = 'plugins = ["my_laws.py"]\n' + text
    else:
        text = text.replace('"route_bimodal"', '"my_bimodal"')
    toml = _write(tmp_path / "run.toml", text)
    name = "my_telegraph" if key == "driver" else "my_bimodal"
    hint = (rf"Unknown {kind} '{name}'\. Available: .*\. To add one, install a package that declares it as an "
            rf"entry point of the group '{re.escape(group)}', list the Python file or module that registers it "
            rf"under plugins = \[\.\.\.\] in the configuration or with --plugin on the command line, or call "
            rf"{re.escape(register)}\(name, factory\) in Python\.$")
    with pytest.raises(UnknownPluginError, match=hint):
        load_config(toml)
    reg = registry.distributions if kind == "distribution" else registry.drivers
    with pytest.raises(UnknownPluginError, match=hint):
        reg.origin(name)


# ---------------------------------------------------------------------------
# the guide's example, as written


def _guide_blocks(language: str) -> list[str]:
    text = GUIDE.read_text(encoding="utf-8")
    section = text.split("## Your own law or driver from the command line", 1)[1]
    section = re.split(r"^## ", section, maxsplit=1, flags=re.M)[0]
    return re.findall(rf"```{language}\n(.*?)```", section, re.S)


def test_the_guides_example_runs_as_written(tmp_path, monkeypatch, capsys, clean_registries):
    (laws,), (toml,) = _guide_blocks("python"), _guide_blocks("toml")
    _write(tmp_path / "my_laws.py", laws)
    _write(tmp_path / "bimodal.toml", toml)
    monkeypatch.chdir(tmp_path)
    commands = [line.split("#")[0].split() for line in _guide_blocks("bash")[0].splitlines() if line.strip()]
    assert [c[:2] for c in commands] == [["slidernet", "plugins"], ["slidernet", "run"]]
    for command in commands:
        assert main([*command[1:], "--no-progress"] if command[1] == "run" else command[1:]) == 0
    assert re.search(r"my_bimodal +run time", capsys.readouterr().out)
    with xr.open_dataset(tmp_path / "bimodal_out" / "result.nc") as ds:
        assert json.loads(ds.attrs["config"])["plugins"] == [str(tmp_path / "my_laws.py")]
        assert float(ds["mu_max_mean"].isel(t=-1)) > 0.5
