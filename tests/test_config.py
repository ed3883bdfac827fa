"""Configuration: bad input is refused before any work, with a message naming the field."""

from __future__ import annotations

import math
import re
import sys

import numpy as np
import pytest

import slidernet
from slidernet import ConfigError, UnknownPluginError
from slidernet.config import Config, load_config
from slidernet.plugins import distributions, drivers, registry
from tests.conftest import REFERENCE, make_config

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

# docs/model.md section 5, verbatim.
REFERENCE_TOML = """\
seed = 1
realizations = 200
steps = 10000                 # thermal steps of duration tau_th
record = "log"                # recorded times: "log"-spaced or "all"
observables = ["n", "mu_max", "x_G", "mu_eff"]

[network]
kind = "two_slider"           # the paper's reference configuration: a 2-node chain
Ntilde = 1e-7                 # N / (k l0)

[friction]
mu_d = 0.5

[friction.static]             # a registered distribution of mu_s
name = "gaussian"
mean = 0.6
std = 0.01                    # truncated below mu_d

[driver]                      # a registered temperature driver
name = "gaussian_steps"
sigma_theta = 1e-6
"""

# (dotted key, bad value, pattern the message must match). Each pattern names
# the field and says what is wrong.
BAD_VALUES = [
    ("network.Ntilde", -1e-7, r"'network\.Ntilde' field must be > 0"),
    ("network.Ntilde", math.nan, r"'network\.Ntilde' field must be a finite number"),
    ("network.Ntilde", 0.0, r"'network\.Ntilde' field must be > 0"),
    ("friction.mu_d", -0.5, r"'friction\.mu_d' field must be > 0"),
    ("friction.mu_d", math.nan, r"'friction\.mu_d' field must be a finite number"),
    ("driver.sigma_theta", -1e-6, r"'driver' field: The 'sigma_theta' parameter of gaussian_steps must be > 0"),
    ("driver.sigma_theta", math.nan,
     r"'sigma_theta' parameter of gaussian_steps must be finite and > 0\. Got nan"),
    ("friction.static.std", -0.01,
     r"'friction\.static' field: The 'std' parameter of gaussian must be > 0\. Got -0\.01"),
    ("friction.static.std", math.nan, r"'std' parameter of gaussian must be finite and > 0\. Got nan"),
    ("friction.static.mean", math.nan, r"'mean' parameter of gaussian must be finite\. Got nan"),
    ("friction.static.mean", 0.5, r"'mean' parameter of gaussian must be > mu_d = 0\.5\. Got 0\.5"),
    ("friction.static.mean", 0.4, r"'mean' parameter of gaussian must be > mu_d = 0\.5\. Got 0\.4"),
    ("realizations", 0, r"'realizations' field must be >= 1\. Got 0"),
    ("steps", 0, r"'steps' field must be >= 1\. Got 0"),
    ("steps", -5, r"'steps' field must be >= 1"),
    ("seed", -1, r"'seed' field must be >= 0"),
    ("solver.batch", 0, r"'solver\.batch' field must be >= 1"),
    ("solver.kernel", "gpu", r"'solver\.kernel' field: Input should be 'auto', 'pair', 'csr' or 'vec'"),
    ("observables", ["n", "energy"], r"'observables\.1' field: .*'mu_eff'"),
    ("foo", 1, r"Unknown key 'foo'\."),
    ("network.foo", 1, r"Unknown key 'foo' in \[network\]"),
    ("solver.foo", 1, r"Unknown key 'foo' in \[solver\]"),
    ("friction.foo", 1, r"Unknown key 'foo' in \[friction\]"),
    ("network.kind", "chain", r"'network' field: a chain network needs \['n'\]"),
    ("network.n", 3, r"'network' field: a two_slider network does not take \['n'\]"),
    ("record", [0, 5, 10001], r"'record' times must lie in \[0, steps = 10000\]"),
    ("friction.static.shape", 2.0, r"'friction\.static' field: the distribution 'gaussian' does not accept "
                                   r"\['shape'\]\. Its parameters are 'mean', 'std'\.$"),
    ("driver.period", 2.0, r"'driver' field: the driver 'gaussian_steps' does not accept \['period'\]\. "
                           r"Its parameters are 'sigma_theta'\.$"),
    ("friction.static.std", None, r"'friction\.static' field: the distribution 'gaussian' does not accept the "
                                  r"parameters given: it needs \['std'\]\. Its parameters are 'mean', 'std'\.$"),
]
BAD_IDS = [f"{key}={value!r}" for key, value, _ in BAD_VALUES]


@pytest.mark.parametrize(("key", "value", "match"), BAD_VALUES, ids=BAD_IDS)
def test_bad_values_are_refused_naming_the_field(key, value, match):
    cfg = make_config(**{key: value})
    if value is None:  # a removed key: the parameter is missing
        assert key.rsplit(".", 1)[-1] not in cfg["friction"]["static"]
    with pytest.raises(ConfigError, match=match):
        load_config(cfg)


@pytest.mark.parametrize(
    ("key", "name", "nearest", "available"),
    [("friction.static.name", "weibul", "; did you mean 'weibull'?",
      ", ".join(repr(n) for n in sorted(distributions.BUILTINS))),
     ("driver.name", "sine", ".", ", ".join(repr(n) for n in sorted(drivers.BUILTINS)))],
    ids=["distribution-near", "driver-none-near"],
)
def test_unknown_plugin_lists_the_available_ones(key, name, nearest, available, clean_registries):
    with pytest.raises(UnknownPluginError, match=rf"Unknown \w+ '{name}'{re.escape(nearest)} Available: "
                                                 rf"{re.escape(available)}\."):
        load_config(make_config(**{key: name}))


def test_missing_sections_are_all_reported_at_once():
    with pytest.raises(ConfigError) as info:
        load_config({"steps": 10})
    msg = str(info.value)
    for section in ("network", "friction", "driver"):
        assert f"The '{section}' field is required." in msg


def test_mu_eff_on_a_larger_network_uses_the_network_tilt_test():
    # The appendix's test before every rearrangement is for a pair; any other
    # network gets the network tilt test at the recorded times.
    cfg = make_config(network={"kind": "chain", "n": 5, "Ntilde": 1e-7})
    assert "mu_eff" in cfg["observables"]
    assert load_config(cfg).mu_eff_at == "auto"
    cfg["mu_eff_at"] = "rearrangements"
    with pytest.raises(ConfigError, match=r"'mu_eff_at = \"rearrangements\"' .* needs a 1D pair of sliders"):
        load_config(cfg)


def test_pair_kernel_needs_two_sliders():
    cfg = make_config(network={"kind": "chain", "n": 3, "Ntilde": 1e-7}, observables=["n"],
                      **{"solver.kernel": "pair"})
    with pytest.raises(ConfigError, match=r"'solver\.kernel' value 'pair' needs a 2-slider network"):
        load_config(cfg)


@pytest.mark.parametrize(
    ("table", "changes", "refused"),
    [("driver", {"driver.sigma": 1.0}, ["sigma"]),
     ("friction.static", {"friction.static.stdd": 0.02, "friction.static.std": None}, ["stdd"])],
    ids=["unknown-beside-a-good-one", "misspelt"],
)
def test_a_plugin_error_lists_only_the_refused_keys(table, changes, refused):
    # The keys that are right (sigma_theta, mean) are never among the refused ones.
    with pytest.raises(ConfigError) as info:
        load_config(make_config(**changes))
    listed = re.search(r"does not accept (\[.*?\])", str(info.value)).group(1)
    assert listed == str(refused), str(info.value)
    assert f"The '{table}' field" in str(info.value)


# --- observables that only networks record --------------------------------------------------

TRIANGULAR = {"kind": "triangular", "shape": [3, 3], "Ntilde": 1e-7}
CHAIN = {"kind": "chain", "n": 4, "Ntilde": 1e-7}
NETWORK_ONLY = ["y_G", "mu_mean", "mu_min", "avalanche_count", "node_slips", "mu_s"]


@pytest.mark.parametrize(
    ("network", "observables", "kernel"),
    [(TRIANGULAR, ["n", "mu_max", *NETWORK_ONLY], "auto"),
     (CHAIN, ["n", "mu_max", "node_slips", "mu_s", "mu_min"], "auto"),
     (REFERENCE["network"], ["n", "mu_max", "node_slips", "mu_s"], "csr")],
    ids=["lattice", "chain", "two-sliders-on-csr"],
)
def test_observables_of_the_readme_table_are_accepted_and_recorded(network, observables, kernel):
    cfg = load_config(make_config(steps=3, realizations=2, record="all", observables=observables, network=network,
                                  **{"solver.kernel": kernel}))
    assert cfg.observables == observables
    ds = slidernet.run(cfg, progress=False)
    n_nodes = 9 if network is TRIANGULAR else (4 if network is CHAIN else 2)
    for name in observables:
        assert name in ds, name
    assert ds["node_slips"].shape == (2, n_nodes)
    # mu_s holds every node's threshold at the end: its largest is mu_max there.
    np.testing.assert_array_equal(ds["mu_s"].max("node"), ds["mu_max"].isel(t=-1))


@pytest.mark.parametrize(
    ("network", "observables", "kernel", "match"),
    [(CHAIN, ["n", "y_G"], "auto", r"'y_G' observable .* needs a 2D network; this chain network is 1D"),
     (REFERENCE["network"], ["n", "y_G"], "csr", r"needs a 2D network; this two_slider network is 1D"),
     (REFERENCE["network"], ["n", "node_slips", "mu_s"], "auto",
      r"observables \['node_slips', 'mu_s'\] are recorded by the network kernels, .* 'pair' kernel; "
      r"set 'solver\.kernel = \"csr\"'"),
     (REFERENCE["network"], ["n", "avalanche_count"], "pair", r"\['avalanche_count'\] .* 'pair' kernel"),
     ({"kind": "chain", "n": 2, "Ntilde": 1e-7}, ["n", "mu_min"], "auto", r"\['mu_min'\] .* 'pair' kernel")],
    ids=["y_G-chain", "y_G-pair", "two-sliders-auto", "two-sliders-pair", "chain-of-two"],
)
def test_observables_a_network_cannot_record_are_refused(network, observables, kernel, match):
    with pytest.raises(ConfigError, match=match):
        load_config(make_config(observables=observables, network=network, **{"solver.kernel": kernel}))


def test_y_g_of_a_1d_graph_file_is_refused(tmp_path):
    path = tmp_path / "line.edgelist"
    path.write_text("0 1\n1 2\n", encoding="utf-8")
    (tmp_path / "line.nodes.csv").write_text("node,x\n0,0.0\n1,1.0\n2,2.0\n", encoding="utf-8")
    network = {"kind": "graph", "path": str(path), "Ntilde": 1e-7}
    load_config(make_config(observables=["n", "node_slips"], network=network))
    with pytest.raises(ConfigError, match=r"needs a 2D network; this graph network is 1D"):
        load_config(make_config(observables=["n", "y_G"], network=network))


def test_not_a_mapping_is_refused():
    with pytest.raises(ConfigError, match="must be a dict, a Config or a path; got list"):
        load_config([("steps", 10)])


class SpyDriver:
    """A driver that counts its uses: a refused config must never reach it."""

    built = 0
    calls = 0

    def __init__(self, sigma_theta: float) -> None:
        type(self).built += 1

    def thetas(self, rng, steps):  # pragma: no cover - must not run
        type(self).calls += 1
        return np.zeros(steps + 1)


@pytest.mark.parametrize(
    ("key", "value"),
    [("steps", 0), ("record", [0, 20]), ("friction.static.mean", 0.5), ("network.foo", 1)],
    ids=["steps", "record", "mean", "unknown-key"],
)
def test_refused_before_any_work(key, value, clean_registries):
    # run() validates everything before it draws a single theta.
    SpyDriver.built = SpyDriver.calls = 0
    registry.register_driver("spy", SpyDriver)
    cfg = make_config(**{"steps": 10, "realizations": 2, "driver.name": "spy", key: value})
    with pytest.raises(ConfigError):
        slidernet.run(cfg)
    assert SpyDriver.calls == 0
    # Sanity: the same config without the bad value does run the driver (in
    # this process, where the spy counts: one worker), once per realization (the probe that compiles
    # the kernels first runs a built-in driver in its place: slidernet.solver.compile), and once before,
    # from a generator of its own, for the scale of theta (slidernet.solver.budget.scales).
    good = make_config(steps=10, realizations=2, observables=["n"], **{"driver.name": "spy"})
    slidernet.run(good, workers=1)
    assert SpyDriver.calls == 1 + 2


def test_defaults_are_filled_in():
    cfg = load_config({k: v for k, v in REFERENCE.items() if k in ("steps", "network", "friction", "driver")})
    assert isinstance(cfg, Config)
    assert (cfg.seed, cfg.realizations, cfg.record) == (None, 1, "log")
    assert cfg.observables == ["n", "mu_max", "x_G"]
    assert (cfg.solver.kernel, cfg.network.kind) == ("auto", "two_slider")


# --------------------------------------------------------------------------
# Files and the reference configuration
# --------------------------------------------------------------------------


def test_reference_toml_loads_and_equals_the_dict(tmp_path):
    path = tmp_path / "paper.toml"
    path.write_text(REFERENCE_TOML)
    from_file = load_config(path)
    # Same fields (the built plugin objects are distinct instances).
    assert from_file.model_dump() == load_config(REFERENCE).model_dump()
    assert from_file.steps == 10000 and from_file.realizations == 200
    assert from_file.friction.static.params == {"mean": 0.6, "std": 0.01}
    assert load_config(str(path)).model_dump() == from_file.model_dump()  # a str path works too


def test_reference_toml_runs_with_fewer_steps(tmp_path):
    # The TOML of docs/model.md section 5, with steps 10000 -> 100 and
    # realizations 200 -> 3 by editing the parsed dict (to keep the test fast).
    path = tmp_path / "paper.toml"
    path.write_text(REFERENCE_TOML)
    with path.open("rb") as fh:
        cfg = tomllib.load(fh)
    cfg["steps"], cfg["realizations"] = 100, 3
    ds = slidernet.run(cfg)
    assert ds.sizes == {"realization": 3, "t": ds.sizes["t"]}
    assert int(ds["t"][-1]) == 100
    assert {"n", "mu_max", "x_G", "mu_eff"} <= set(ds.data_vars)
    assert ds.attrs["seed"] == "1"


def test_model_md_example_dict_runs_as_written():
    # docs/model.md section 5 as a dict, unchanged except steps 10000 -> 200 and
    # realizations 200 -> 4 (the full run takes minutes).
    cfg = make_config(steps=200, realizations=4)
    assert {k: v for k, v in cfg.items() if k not in ("steps", "realizations")} == {
        k: v for k, v in REFERENCE.items() if k not in ("steps", "realizations")
    }
    ds = slidernet.run(cfg)
    assert ds["n"].shape == (4, ds.sizes["t"])
    # Close to eq. `slope`: about 53.6 rearrangements per tau_th (loose: 10 %).
    assert 48 < float(ds["r_mean"]) < 59
    assert np.isfinite(ds["mu_eff"].values).all()


def test_missing_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(ConfigError, match=r"The configuration file '.*nope\.toml' does not exist"):
        load_config(missing)


def test_invalid_toml(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("steps = \n[network\n")
    with pytest.raises(ConfigError, match=r"The configuration file '.*bad\.toml' is not valid TOML"):
        load_config(path)


def test_toml_with_a_bad_value_names_the_field(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(REFERENCE_TOML.replace("mu_d = 0.5", "mu_d = -0.5"))
    with pytest.raises(ConfigError, match=r"'friction\.mu_d' field must be > 0"):
        load_config(path)


# One rule for every real parameter of a plugin (slidernet._validation.check_scalar): an int or a float,
# never a boolean, a string (even one that reads as a number) or an array. A law of mu_s and a driver
# answer alike: the library with a ConfigError, the command line with one line naming the field, exit 2.
# (id, table, its body in the TOML file, pattern of the message after the field's name)
NOT_REAL = [
    ("gaussian-std-text", "friction.static", 'name = "gaussian"\nmean = 0.6\nstd = "abc"',
     r"The 'std' parameter of gaussian must be a real number > 0\. Got 'abc' instead\."),
    ("gaussian-std-number-as-text", "friction.static", 'name = "gaussian"\nmean = 0.6\nstd = "0.1"',
     r"The 'std' parameter of gaussian must be a real number > 0\. Got '0\.1' instead\."),
    ("gaussian-std-array", "friction.static", 'name = "gaussian"\nmean = 0.6\nstd = [0.1]',
     r"The 'std' parameter of gaussian must be a real number > 0\. Got \[0\.1\] instead\."),
    ("gaussian-std-boolean", "friction.static", 'name = "gaussian"\nmean = 0.6\nstd = true',
     r"The 'std' parameter of gaussian must be a real number > 0\. Got True instead\."),
    ("gaussian-mean-text", "friction.static", 'name = "gaussian"\nmean = "0.6"\nstd = 0.01',
     r"The 'mean' parameter of gaussian must be a real number\. Got '0\.6' instead\."),
    ("weibull-shape-boolean", "friction.static", 'name = "weibull"\nshape = true\nscale = 0.15\nloc = 0.4',
     r"The 'shape' parameter of weibull must be a real number > 0\. Got True instead\."),
    ("uniform-low-text", "friction.static", 'name = "uniform"\nlow = "0.45"\nhigh = 0.65',
     r"The 'low' parameter of uniform must be a real number\. Got '0\.45' instead\."),
    ("empirical-column-float", "friction.static", 'name = "empirical"\npath = "mu_s.txt"\ncolumn = 1.5',
     r"The 'column' parameter of empirical must be a column index \(int\) or a header name \(str\)\."),
    ("scipy-param-text", "friction.static",
     'name = "scipy"\ndist = "gamma"\nparams = { a = "2", loc = 0.45, scale = 0.05 }',
     r"The 'params\.a' parameter of scipy must be a real number\. Got '2' instead\."),
    ("driver-sigma_theta-text", "driver", 'name = "gaussian_steps"\nsigma_theta = "1e-6"',
     r"The 'sigma_theta' parameter of gaussian_steps must be a real number > 0\. Got '1e-6' instead\."),
    ("driver-period-boolean", "driver", 'name = "sinusoidal"\namplitude = 1e-6\nperiod = true',
     r"The 'period' parameter of sinusoidal must be a real number > 0\. Got True instead\."),
]


def _toml_with(table: str, body: str) -> str:
    """REFERENCE_TOML, its ``[table]`` holding ``body`` instead."""
    pattern = rf"^\[{re.escape(table)}\][^\n]*\n.*?(?=^\[|\Z)"
    text, count = re.subn(pattern, lambda _: f"[{table}]\n{body}\n\n", REFERENCE_TOML, flags=re.M | re.S)
    assert count == 1
    return text.replace("steps = 10000", "steps = 10").replace("realizations = 200", "realizations = 1")


@pytest.mark.parametrize(("table", "body", "match"), [c[1:] for c in NOT_REAL], ids=[c[0] for c in NOT_REAL])
def test_a_parameter_that_is_not_a_real_number_is_one_line_naming_it(table, body, match, tmp_path, capsys):
    from slidernet.cli import main

    path = tmp_path / "bad.toml"
    path.write_text(_toml_with(table, body))
    with pytest.raises(ConfigError, match=rf"^The '{re.escape(table)}' field: {match}"):
        load_config(path)
    out = tmp_path / "out"
    status = main(["run", str(path), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert re.match(rf"slidernet: error: The '{re.escape(table)}' field: {match}", lines[0]), lines[0]
    assert not out.exists()


# The configuration's own numbers follow the plugins' rule (slidernet._validation.is_real, is_integral): a
# string or a boolean is refused by name, never read as the number it looks like. Issue 37: realizations =
# true ran one realization and steps = "200" ran 200 steps.
# (id, dotted key, value, the message's pattern)
NOT_A_NUMBER = [
    ("realizations-true", "realizations", True,
     r"The 'realizations' field must be an integer\. Got True instead\."),
    ("steps-text", "steps", "200", r"The 'steps' field must be an integer\. Got '200' instead\."),
    ("steps-fraction", "steps", 1.5, r"The 'steps' field must be an integer\. Got 1\.5 instead\."),
    ("seed-false", "seed", False, r"The 'seed' field must be an integer\. Got False instead\."),
    ("record-time-true", "record", [0, True], r"The 'record\.1' field must be an integer\. Got True instead\."),
    ("Ntilde-text", "network.Ntilde", "1e-7", r"The 'network\.Ntilde' field must be a real number\. Got '1e-7'"),
    ("mu_d-true", "friction.mu_d", True, r"The 'friction\.mu_d' field must be a real number\. Got True"),
    ("n-text", "network.n", "8", r"The 'network\.n' field must be an integer\. Got '8' instead\."),
    ("kappa-false", "network.kappa", False, r"The 'network\.kappa' field must be a real number\. Got False"),
    ("batch-true", "solver.batch", True, r"The 'solver\.batch' field must be an integer\. Got True instead\."),
    ("workers-text", "execution.workers", "2", r"The 'execution\.workers' field must be an integer\. Got '2'"),
    ("checkpoint_every-true", "execution.checkpoint_every", True,
     r"The 'execution\.checkpoint_every' field must be a real number\. Got True instead\."),
]


@pytest.mark.parametrize(("key", "value", "match"), [c[1:] for c in NOT_A_NUMBER],
                         ids=[c[0] for c in NOT_A_NUMBER])
def test_a_number_of_the_configuration_is_never_a_string_or_a_boolean(key, value, match):
    network = {"network.kind": "chain", "network.n": 4} if key.startswith("network.") else {}
    with pytest.raises(ConfigError, match=match):
        load_config(make_config(**{**network, key: value}))


@pytest.mark.parametrize(("key", "value", "expected"),
                         [("steps", 1e4, 10_000), ("realizations", 3.0, 3), ("seed", np.int64(7), 7),
                          ("network.Ntilde", np.float64(1e-7), 1e-7), ("solver.max_avalanche", 1e6, 1_000_000)],
                         ids=["steps-1e4", "realizations-3.0", "seed-numpy-int", "Ntilde-numpy",
                              "max_avalanche-1e6"])
def test_whole_floats_and_numpy_scalars_are_numbers(key, value, expected):
    cfg = load_config(make_config(**{key: value}))
    got = cfg
    for part in key.split("."):
        got = getattr(got, part)
    assert got == expected and type(got) is type(expected)


def test_a_configuration_file_that_is_not_utf8_is_one_line_naming_it(tmp_path, capsys):
    from slidernet.cli import main

    path = tmp_path / "latin1.toml"
    path.write_bytes("# Réglage de référence\n".encode("latin-1") + REFERENCE_TOML.encode())
    with pytest.raises(ConfigError, match=r"toml' is not UTF-8 text, as TOML must be: byte 0xe9 on line 1"):
        load_config(path)
    status = main(["run", str(path), "--out", str(tmp_path / "out"), "--no-progress"])
    err = capsys.readouterr().err
    assert status == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "out").exists()


def test_a_folder_given_as_the_configuration_is_named_as_a_folder(tmp_path):
    with pytest.raises(ConfigError, match=r"The configuration file '.*' is a folder, not a file\."):
        load_config(tmp_path)


# Issue 37: a Pareto law with alpha = 0.01 and mu_d = 1e308 printed raw numpy RuntimeWarning lines before the
# error or the result (which, for the second, held inf). Every threshold must stay below MU_S_MAX; the refusal
# is the only output, and no floating-point warning comes before it.
# (id, [friction] table, the message's pattern)
EXTREME_LAWS = [
    ("pareto-alpha-0.01", {"mu_d": 0.5, "static": {"name": "pareto", "alpha": 0.01, "scale": 0.1, "loc": 0.5}},
     r"the distribution 'pareto' \(above mu_d = 0\.5\) draws mu_s > 1e\+150 with probability 0\.0309; every "
     r"threshold must stay below 1e\+150"),
    ("mu_d-1e308-uniform", {"mu_d": 1e308, "static": {"name": "uniform", "low": 1e308, "high": 1.5e308}},
     r"the distribution 'uniform' \(above mu_d = 1e\+308\) draws mu_s > 1e\+150 with probability 1;"),
    ("mu_d-1e308-gaussian", {"mu_d": 1e308, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
     r"The 'mean' parameter of gaussian must be > mu_d = 1e\+308\. Got 0\.6 instead\."),
    ("mu_d-1e308-pareto", {"mu_d": 1e308, "static": {"name": "pareto", "alpha": 3.0, "scale": 0.1}},
     r"The 'loc' parameter of pareto must be such that P\(mu_s > mu_d = 1e\+308\) >= 0\.001 \(it is 0\)"),
    ("mu_d-1e308-weibull", {"mu_d": 1e308, "static": {"name": "weibull", "shape": 2.0, "scale": 0.1}},
     r"The 'loc' parameter of weibull must be such that P\(mu_s > mu_d = 1e\+308\) >= 0\.001"),
]


@pytest.mark.parametrize(("friction", "match"), [c[1:] for c in EXTREME_LAWS], ids=[c[0] for c in EXTREME_LAWS])
def test_extreme_laws_are_refused_without_floating_point_warnings(friction, match):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning would be raised here instead of the refusal
        with pytest.raises(ConfigError, match=rf"^The 'friction\.static' field: .*{match}"):
            load_config(make_config(friction=friction))


def test_a_law_just_inside_the_threshold_bound_is_accepted():
    # alpha = 0.2: P(mu_s > 1e150) = (1e150 / 0.1)^-0.2 = 1e-30, below 2^-53.
    cfg = load_config(make_config(friction={"mu_d": 0.5, "static": {"name": "pareto", "alpha": 0.2, "scale": 0.1,
                                                                    "loc": 0.5}}))
    assert cfg.distribution().sf(1e150) < 2.0**-53
