"""The built-in distributions of mu_s: validation, sampling, tails, the mean maximum and the exact law.

Every statistical test states its seed and tolerance. Seeds are fixed, so each
test is deterministic; the tolerances (KS p > 1e-3, 4 standard errors) would
hold for most seeds too.
"""

from __future__ import annotations

import inspect
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

import slidernet
from slidernet.analysis import theory
from slidernet.config import load_config
from slidernet.errors import ConfigError
from slidernet.plugins import registry
from slidernet.plugins.distributions import (
    BUILTINS,
    MIN_MASS,
    Distribution,
    Empirical,
    Exponential,
    Gaussian,
    Lognormal,
    Pareto,
    ScipyStats,
    TruncatedBelow,
    Uniform,
    Weibull,
    mean_max_quadrature,
)
from tests.conftest import make_config
from tests.test_examples import load_example

MU_D = 0.5
NTILDE = 1e-7
DATA_SEED = 3

# One law per case: (registered name, parameters). Most reach below mu_d = 0.5
# and are truncated there; the "-above" cases start above mu_d and are not.
# The empirical file (see ``data_file``) is filled in at run time.
CASES: dict[str, tuple[str, dict[str, Any]]] = {
    "gaussian": ("gaussian", {"mean": 0.6, "std": 0.1}),
    "uniform": ("uniform", {"low": 0.45, "high": 0.65}),
    "uniform-above": ("uniform", {"low": 0.55, "high": 0.65}),
    "weibull": ("weibull", {"shape": 2.0, "scale": 0.15, "loc": 0.4}),
    "lognormal": ("lognormal", {"median": 0.1, "sigma": 0.5, "loc": 0.45}),
    "exponential": ("exponential", {"scale": 0.05, "loc": 0.45}),
    "exponential-above": ("exponential", {"scale": 0.05, "loc": 0.55}),
    "pareto": ("pareto", {"alpha": 3.0, "scale": 0.03, "loc": 0.45}),
    "pareto-above": ("pareto", {"alpha": 3.0, "scale": 0.05, "loc": 0.5}),
    "empirical": ("empirical", {}),
    "scipy": ("scipy", {"dist": "gamma", "params": {"a": 2.0, "loc": 0.45, "scale": 0.05}}),
}
CONTINUOUS = [c for c in CASES if c != "empirical"]


@pytest.fixture(scope="module")
def data_file(tmp_path_factory) -> Path:
    """300 'measured' thresholds, rounded to 3 decimals (so with ties), 15-20 % of them <= mu_d."""
    rng = np.random.default_rng(DATA_SEED)
    values = np.round(0.45 + rng.gamma(2.0, 0.05, 300), 3)
    path = tmp_path_factory.mktemp("data") / "mu_s.txt"
    path.write_text("# measured static friction coefficients\nmu_s\n" + "\n".join(f"{v:.3f}" for v in values))
    return path


def spec_of(case: str, data_file: Path) -> dict[str, Any]:
    """The ``friction.static`` table of a case."""
    name, params = CASES[case]
    if name == "empirical":
        params = {"path": str(data_file)}
    return {"name": name, **params}


def raw_law(case: str, data_file: Path) -> Distribution:
    spec = spec_of(case, data_file)
    return BUILTINS[spec.pop("name")](**spec)


def used_law(case: str, data_file: Path) -> TruncatedBelow:
    """The law slidernet draws from: built through a config, truncated at mu_d."""
    return load_config(make_config(**{"friction.static": spec_of(case, data_file)})).distribution()


def randomized_pit(cdf, x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """U = F(x-) + V (F(x) - F(x-)), V ~ Uniform(0, 1): Uniform(0, 1) for any law, atoms included."""
    hi = np.asarray(cdf(x), dtype=float)
    lo = np.asarray(cdf(np.nextafter(x, -np.inf)), dtype=float)
    return lo + rng.random(x.shape) * (hi - lo)


# ---------------------------------------------------------------------------
# registry and configs


def test_builtins_are_registered():
    assert set(BUILTINS) == {"gaussian", "uniform", "constant", "weibull", "lognormal", "exponential", "pareto",
                             "empirical", "scipy"}
    for name, cls in BUILTINS.items():
        assert registry.distributions.get(name) is cls
        assert cls.name == name


def test_uniform_through_a_config():
    cfg = slidernet.load_config({
        "steps": 10, "network": {"Ntilde": 1e-7}, "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
        "friction": {"mu_d": 0.5, "static": {"name": "uniform", "low": 0.55, "high": 0.65}},
    })
    d = cfg.distribution()
    assert isinstance(d, TruncatedBelow) and isinstance(d.dist, Uniform)
    assert (d.dist.low, d.dist.high, d.lower, d.mass) == (0.55, 0.65, 0.5, 1.0)


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_every_builtin_loads_through_a_config(case, data_file):
    d = used_law(case, data_file)
    assert isinstance(d, TruncatedBelow)
    assert type(d.dist) is BUILTINS[CASES[case][0]]
    assert d.lower == MU_D
    truncated = d.dist.support()[0] < MU_D
    assert truncated == ("above" not in case), d.dist.support()
    assert (d.mass < 1.0) == truncated
    assert MIN_MASS <= d.mass <= 1.0


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_the_law_slidernet_draws_from_is_a_distribution(case, data_file):
    # The raw built-in and the law the solver draws from (the registry's
    # factory, truncated at mu_d by load_config) are one type, with one
    # mean_max(m): the mean of the max of m draws of that very law.
    raw, used = raw_law(case, data_file), used_law(case, data_file)
    assert isinstance(raw, Distribution) and isinstance(used, Distribution)
    assert list(inspect.signature(raw.mean_max).parameters) == ["m"]
    assert inspect.signature(used.mean_max) == inspect.signature(raw.mean_max)
    if "above" in case:
        # No truncation happens: the same law, so the same numbers, bit for bit.
        assert raw.support()[0] >= MU_D and used.support() == raw.support()
        np.testing.assert_array_equal(used.mean_max(M_VALUES), raw.mean_max(M_VALUES), strict=True)
    else:
        # Truncation happens: the raw law's maximum is smaller, since it also
        # counts the draws at or below mu_d.
        assert raw.support()[0] < MU_D and used.support()[0] == MU_D
        assert (raw.mean_max(M_VALUES[:3]) < used.mean_max(M_VALUES[:3])).all()
    np.testing.assert_array_equal(used.mean_max(M_VALUES), raw.mean_max_above(M_VALUES, MU_D), strict=True)


def test_mean_max_has_one_signature():
    # Every built-in and the truncated law: mean_max(self, m); the truncation
    # point goes to mean_max_above(self, m, lower) only.
    for cls in (*BUILTINS.values(), TruncatedBelow, Distribution):
        assert list(inspect.signature(cls.mean_max).parameters) == ["self", "m"], cls
        assert list(inspect.signature(cls.mean_max_above).parameters) == ["self", "m", "lower"], cls
    # A third-party plugin (sample and cdf only) becomes a Distribution too.
    assert isinstance(TruncatedBelow(CdfOnlyUniform(), MU_D, "cdf_only"), Distribution)


def test_truncated_law_support_and_check_mu_d():
    # The rest of the Distribution interface on the truncated law: its support
    # starts at mu_d, and check_mu_d lets the plugin name its own parameter.
    plugin = TruncatedBelow(CdfOnlyUniform(), MU_D, "cdf_only")
    assert plugin.support() == (MU_D, math.inf)  # the plugin does not give its upper end
    plugin.check_mu_d(0.6)
    with pytest.raises(ConfigError, match=r"'cdf_only', conditioned on mu_s > 0\.5, puts probability .* "
                                          r"above mu_d = 0\.6499; at least 0\.001 is needed"):
        plugin.check_mu_d(0.6499)
    gaussian = TruncatedBelow(Gaussian(0.6, 0.01), MU_D, "gaussian")
    assert gaussian.support() == (MU_D, math.inf)
    with pytest.raises(ConfigError, match=r"The 'mean' parameter of gaussian must be > mu_d = 0\.7"):
        gaussian.check_mu_d(0.7)


def test_scipy_through_a_toml_file(tmp_path):
    path = tmp_path / "run.toml"
    path.write_text(
        'steps = 10\n[network]\nNtilde = 1e-7\n[driver]\nname = "gaussian_steps"\nsigma_theta = 1e-6\n'
        '[friction]\nmu_d = 0.5\n[friction.static]\nname = "scipy"\ndist = "gamma"\n'
        'params = {a = 2, loc = 0.5, scale = 0.05}\n'
    )
    d = load_config(path).distribution()
    assert isinstance(d.dist, ScipyStats) and d.dist.dist == "gamma"
    assert float(d.cdf(0.6)) == pytest.approx(stats.gamma(2, loc=0.5, scale=0.05).cdf(0.6), rel=1e-14)


# ---------------------------------------------------------------------------
# parameter validation


VALIDATION = [
    # (id, class, parameters, message pattern)
    ("gaussian-std", Gaussian, {"mean": 0.6, "std": -1},
     r"The 'std' parameter of gaussian must be > 0\. Got -1\.0 instead\."),
    ("gaussian-mean", Gaussian, {"mean": math.nan, "std": 0.1},
     r"'mean' parameter of gaussian must be finite\."),
    ("uniform-order", Uniform, {"low": 0.6, "high": 0.6},
     r"The 'high' parameter of uniform must be > low = 0\.6\. Got 0\.6 instead\."),
    ("uniform-low", Uniform, {"low": math.nan, "high": 0.6},
     r"'low' parameter of uniform must be finite\. Got nan"),
    ("uniform-high", Uniform, {"low": 0.5, "high": math.inf},
     r"'high' parameter of uniform must be finite\. Got inf"),
    ("uniform-type", Uniform, {"low": "a", "high": 0.6},
     r"'low' parameter of uniform must be a real number\. Got 'a' instead\."),
    ("weibull-shape", Weibull, {"shape": 0, "scale": 0.1},
     r"'shape' parameter of weibull must be > 0\. Got 0\.0 instead\."),
    ("weibull-scale", Weibull, {"shape": 2, "scale": -0.1},
     r"'scale' parameter of weibull must be > 0\. Got -0\.1"),
    ("weibull-loc", Weibull, {"shape": 2, "scale": 0.1, "loc": math.inf},
     r"'loc' parameter of weibull must be finite\."),
    ("lognormal-median", Lognormal, {"median": 0, "sigma": 0.5},
     r"'median' parameter of lognormal must be > 0\. Got 0\.0 instead\."),
    ("lognormal-sigma", Lognormal, {"median": 0.1, "sigma": math.nan},
     r"'sigma' parameter of lognormal must be"),
    ("lognormal-loc", Lognormal, {"median": 0.1, "sigma": 0.5, "loc": math.nan},
     r"'loc' parameter of lognormal"),
    ("exponential-scale", Exponential, {"scale": 0.0, "loc": 0.5},
     r"'scale' parameter of exponential must be > 0\. Got 0\.0 instead\."),
    ("exponential-loc", Exponential, {"scale": 0.1, "loc": -math.inf},
     r"'loc' parameter of exponential must be finite\."),
    ("pareto-alpha", Pareto, {"alpha": -3, "scale": 0.05},
     r"'alpha' parameter of pareto must be > 0\. Got -3\.0 instead\."),
    ("pareto-scale", Pareto, {"alpha": 3, "scale": 0},
     r"'scale' parameter of pareto must be > 0\. Got 0\.0 instead\."),
    ("pareto-loc", Pareto, {"alpha": 3, "scale": 0.05, "loc": math.nan},
     r"'loc' parameter of pareto must be finite\."),
    ("scipy-discrete", ScipyStats, {"dist": "poisson", "params": {"mu": 1}},
     r"The 'dist' parameter of scipy must be the name of a continuous distribution of scipy\.stats "
     r"\(e\.g\. 'gamma'\)\. Got 'poisson' instead\."),
    ("scipy-module", ScipyStats, {"dist": "distributions"},
     r"'dist' parameter of scipy must be the name of a continuous"),
    ("scipy-class", ScipyStats, {"dist": "rv_continuous"},
     r"'dist' parameter of scipy .* Got 'rv_continuous'"),
    ("scipy-private", ScipyStats, {"dist": "_continuous_distns"},
     r"'dist' parameter of scipy"),
    ("scipy-unknown", ScipyStats, {"dist": "no_such_law"},
     r"Got 'no_such_law' instead"),
    ("scipy-not-a-string", ScipyStats, {"dist": 3},
     r"'dist' parameter of scipy .* Got 3 instead"),
    ("scipy-unknown-param", ScipyStats, {"dist": "gamma", "params": {"b": 2}},
     r"'params' parameter of scipy must be the parameters of scipy\.stats\.gamma \(a, loc, scale\)"
     r".*unexpected keyword"),
    ("scipy-missing-shape", ScipyStats, {"dist": "gamma", "params": {"loc": 0.5}},
     r"'params' parameter of scipy must be .*missing"),
    ("scipy-invalid-shape", ScipyStats, {"dist": "gamma", "params": {"a": -2}},
     r"'params' parameter of scipy must be valid values of the parameters of scipy\.stats\.gamma"),
    ("scipy-invalid-scale", ScipyStats, {"dist": "norm", "params": {"loc": 0.6, "scale": -1}},
     r"must be valid values"),
    ("scipy-nan", ScipyStats, {"dist": "norm", "params": {"loc": math.nan}},
     r"The 'params\.loc' parameter of scipy must be finite\. Got nan instead\."),
    ("scipy-string-value", ScipyStats, {"dist": "norm", "params": {"loc": "0.6"}},
     r"The 'params\.loc' parameter of scipy must be a real number\. Got '0\.6' instead\."),
    ("scipy-bool-value", ScipyStats, {"dist": "gamma", "params": {"a": True}},
     r"The 'params\.a' parameter of scipy must be a real number\. Got True instead\."),
    ("scipy-params-type", ScipyStats, {"dist": "norm", "params": [0.6, 0.1]},
     r"'params' parameter of scipy must be a table of named parameters"),
    ("empirical-type", Empirical, {"path": 3},
     r"'path' parameter of empirical must be the path of a file"),
    ("empirical-column-type", Empirical, {"path": "x", "column": 1.5},
     r"'column' parameter of empirical must be"),
    ("empirical-column-negative", Empirical, {"path": "x", "column": -1},
     r"'column' parameter of empirical must be >= 0"),
    ("empirical-delimiter", Empirical, {"path": "x", "delimiter": ";;"},
     r"'delimiter' parameter of empirical"),
]


@pytest.mark.parametrize(("cls", "params", "match"), [v[1:] for v in VALIDATION], ids=[v[0] for v in VALIDATION])
def test_parameters_are_validated(cls, params, match):
    with pytest.raises(ConfigError, match=match):
        cls(**params)


EMPIRICAL_FILES = [
    # (id, file text or None for a missing file, extra params, match)
    ("missing", None, {}, r"'path' parameter of empirical must be an existing file\. Got '.*nope\.txt' instead\."),
    ("not-a-number", "0.6\n0.7\nabc\n", {}, r"line 3: the value must be a number\. Got 'abc' instead\."),
    ("nan", "0.6\nnan\n0.7\n", {}, r"line 2: the value must be finite\. Got 'nan'"),
    ("inf", "mu\n0.6\n0.7\n-inf\n", {}, r"line 4: the value must be finite"),
    ("one-value", "# header comment\n0.6\n\n", {}, r"must be a file with at least 2 values \(it has 1\)"),
    ("empty", "", {}, r"at least 2 values \(it has 0\)"),
    ("two-columns", "a,0.6\nb,0.7\n", {}, r"line 1 has 2 fields; give 'column'"),
    ("no-such-name", "id,mu\na,0.6\nb,0.7\n", {"column": "mu_s"}, r"'column' parameter of empirical must be a "
     r"header name of .*\['id', 'mu'\]\. Got 'mu_s' instead"),
    ("no-such-index", "a,0.6\nb,0.7\n", {"column": 2}, r"line 1 has no column 2 \(only 2 fields\)"),
]


@pytest.mark.parametrize(("text", "params", "match"), [v[1:] for v in EMPIRICAL_FILES],
                         ids=[v[0] for v in EMPIRICAL_FILES])
def test_empirical_file_is_validated(tmp_path, text, params, match):
    path = tmp_path / "nope.txt"
    if text is not None:
        path.write_text(text)
    with pytest.raises(ConfigError, match=match):
        Empirical(path, **params)


def test_empirical_reads_csv_columns_by_name_and_index(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("id;mu_s;T\n# a comment\nA;0.61;20\n\nB;0.72;21\nC;0.43;22\n")
    by_name = Empirical(path, column="mu_s", delimiter=";")
    by_index = Empirical(path, column=1, delimiter=";")  # the header does not parse: skipped
    np.testing.assert_array_equal(by_name.values, [0.43, 0.61, 0.72])
    np.testing.assert_array_equal(by_index.values, by_name.values)
    assert Empirical(path, column=2, delimiter=";").values.tolist() == [20.0, 21.0, 22.0]


MU_D_REFUSALS = [
    ("uniform-below", {"name": "uniform", "low": 0.3, "high": 0.5},
     r"The 'friction\.static' field: The 'high' parameter of uniform must be such that the support reaches "
     r"above mu_d = 0\.5 \(it ends at 0\.5\)\. Got 0\.5"),
    ("uniform-thin", {"name": "uniform", "low": 0.0, "high": 0.5002}, r"'high' parameter of uniform must be such "
     r"that P\(mu_s > mu_d = 0\.5\) >= 0\.001 \(it is 0\.0004\)\. Got 0\.5002 instead"),
    ("weibull", {"name": "weibull", "shape": 2, "scale": 0.1}, r"'loc' parameter of weibull must be such that "
     r"P\(mu_s > mu_d = 0\.5\) >= 0\.001 \(it is 1\.39e-11\)\. Got 0\.0 instead"),
    ("lognormal", {"name": "lognormal", "median": 0.05, "sigma": 0.3}, r"'loc' parameter of lognormal"),
    ("exponential", {"name": "exponential", "scale": 0.01, "loc": 0.1}, r"'loc' parameter of exponential must be "
     r"such that P\(mu_s > mu_d = 0\.5\) >= 0\.001"),
    ("pareto", {"name": "pareto", "alpha": 3, "scale": 0.01}, r"'loc' parameter of pareto .* \(it is 8e-06\)"),
    ("scipy-support", {"name": "scipy", "dist": "uniform", "params": {"loc": 0.0, "scale": 0.4}}, r"'params' "
     r"parameter of scipy must be such that the support reaches above mu_d = 0\.5 \(it ends at 0\.4\)"),
    ("scipy-mass", {"name": "scipy", "dist": "gamma", "params": {"a": 2, "scale": 0.01}}, r"'params' parameter of "
     r"scipy must be such that P\(mu_s > mu_d = 0\.5\)"),
    ("gaussian", {"name": "gaussian", "mean": 0.5, "std": 0.1},
     r"'mean' parameter of gaussian must be > mu_d = 0\.5"),
]


@pytest.mark.parametrize(("spec", "match"), [v[1:] for v in MU_D_REFUSALS], ids=[v[0] for v in MU_D_REFUSALS])
def test_laws_with_too_little_mass_above_mu_d_are_refused(spec, match):
    with pytest.raises(ConfigError, match=match):
        load_config(make_config(**{"friction.static": spec}))


def test_empirical_needs_two_values_above_mu_d(tmp_path):
    path = tmp_path / "few.txt"
    path.write_text("0.3\n0.4\n0.45\n0.7\n")
    with pytest.raises(ConfigError, match=r"must name a file with at least 2 values > mu_d = 0\.5\. "
                                          r"Got '.*few\.txt' instead, with 1 of 4\."):
        load_config(make_config(**{"friction.static": {"name": "empirical", "path": str(path)}}))


def test_mean_max_validates_m():
    d = Exponential(0.05, 0.55)
    not_real = "a real number or an array of them, >= 1"
    cases = [(0, ">= 1", "0.0"), (0.5, ">= 1", "0.5"), (math.nan, "finite and >= 1", "nan"),
             ([3, math.inf], "finite and >= 1", "inf"), (True, not_real, "True"), ("2", not_real, "'2'")]
    for bad, requirement, shown in cases:
        with pytest.raises(ConfigError, match=rf"^The 'm' parameter of mean_max must be {re.escape(requirement)}"
                                              rf"\. Got {re.escape(shown)} instead\.$"):
            d.mean_max(bad)


# ---------------------------------------------------------------------------
# sampling against the cdf


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_samples_follow_the_cdf(case, data_file):
    # Seed 11, 20000 draws of the raw and of the truncated law, each against its
    # own cdf by a Kolmogorov-Smirnov test of the randomized probability
    # integral transform (exact for the empirical law's atoms too): p > 1e-3.
    rng = np.random.default_rng(11)
    for law in (raw_law(case, data_file), used_law(case, data_file)):
        x = law.sample(rng, 20_000)
        assert x.shape == (20_000,) and x.dtype == np.float64
        result = stats.kstest(randomized_pit(law.cdf, x, rng), "uniform")
        assert result.pvalue > 1e-3, (law, result)


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_sampling_uses_only_the_given_generator(case, data_file):
    law = used_law(case, data_file)
    np.random.seed(0)  # noqa: NPY002 -- the legacy global state must not matter
    a = law.sample(np.random.default_rng(5), 1000)
    np.random.seed(1)  # noqa: NPY002
    b = law.sample(np.random.default_rng(5), 1000)
    np.testing.assert_array_equal(a, b)


def test_gaussian_sampling_is_unchanged():
    # The paper's reproduction depends on these exact draws: mean + std * standard_normal.
    x = Gaussian(0.6, 0.01).sample(np.random.default_rng(2010), 5)
    z = np.random.default_rng(2010).standard_normal(5)
    np.testing.assert_array_equal(x, z * 0.01 + 0.6)


# ---------------------------------------------------------------------------
# cdf, sf and their inverses


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
@settings(max_examples=60, deadline=None)
@given(x=st.floats(min_value=-1.0, max_value=5.0))
def test_sf_plus_cdf_is_one(case, data_file, x):
    for law in (raw_law(case, data_file), used_law(case, data_file)):
        cdf, sf = float(law.cdf(x)), float(law.sf(x))
        assert 0.0 <= cdf <= 1.0 and 0.0 <= sf <= 1.0
        assert cdf + sf == pytest.approx(1.0, abs=2e-16)


# Far upper tail: sf ~ 1e-30 and below, where 1 - cdf is 0 in double precision.
SCIPY_REFERENCE = {
    "gaussian": (Gaussian(0.6, 0.01), stats.norm(0.6, 0.01)),
    "uniform": (Uniform(0.55, 0.65), stats.uniform(0.55, 0.1)),
    "weibull": (Weibull(2.0, 0.15, 0.4), stats.weibull_min(2.0, loc=0.4, scale=0.15)),
    "lognormal": (Lognormal(0.1, 0.5, 0.45), stats.lognorm(0.5, loc=0.45, scale=0.1)),
    "exponential": (Exponential(0.05, 0.45), stats.expon(loc=0.45, scale=0.05)),
    "pareto": (Pareto(3.0, 0.03, 0.45), stats.pareto(3.0, loc=0.45, scale=0.03)),
}


@pytest.mark.parametrize("case", list(SCIPY_REFERENCE), ids=list(SCIPY_REFERENCE))
def test_tails_and_inverses_match_scipy(case):
    law, ref = SCIPY_REFERENCE[case]
    q = np.array([0.9, 0.5, 0.1, 1e-3, 1e-10, 1e-30, 1e-100])
    if case == "uniform":  # bounded: near its end, x itself cannot resolve sf below ~1e-16
        q = q[:4]
    x = ref.isf(q)
    np.testing.assert_allclose(law.isf(q), x, rtol=1e-12)
    np.testing.assert_allclose(law.sf(x), q, rtol=1e-9)
    u = np.array([1e-12, 1e-3, 0.25, 0.5, 0.75])
    np.testing.assert_allclose(law.ppf(u), ref.ppf(u), rtol=1e-12)
    grid = np.linspace(*ref.ppf([1e-9, 1 - 1e-9]), 101)
    # Across the bulk, to rounding: x - loc loses digits near the lower end, whoever computes it.
    np.testing.assert_allclose(law.cdf(grid), ref.cdf(grid), rtol=1e-10, atol=1e-15)
    np.testing.assert_allclose(law.sf(grid), ref.sf(grid), rtol=1e-10, atol=1e-15)


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_support_is_strictly_above_mu_d_after_truncation(case, data_file):
    # Seed 12, 100000 draws.
    d = used_law(case, data_file)
    assert d.sample(np.random.default_rng(12), 100_000).min() > MU_D
    assert float(d.cdf(MU_D)) == 0.0 and float(d.sf(MU_D)) == 1.0
    assert float(d.cdf(MU_D - 0.1)) == 0.0
    assert float(d.ppf(0.0)) >= MU_D and float(d.isf(1.0)) >= MU_D
    if case != "empirical":  # continuous: no mass at mu_d itself
        assert float(d.cdf(np.nextafter(MU_D, 1.0))) < 1e-12


# ---------------------------------------------------------------------------
# the mean of the maximum

M_VALUES = np.array([1, 2, 3, 10, 1e3, 1e6, 1e9])
CLOSED_FORMS = {
    "uniform": Uniform(0.45, 0.65),
    "exponential": Exponential(0.05, 0.45),
    "pareto": Pareto(3.0, 0.03, 0.45),
    "pareto-heavy": Pareto(1.5, 0.03, 0.45),
}


@pytest.mark.parametrize("lower", [-math.inf, 0.4, 0.5], ids=["untruncated", "below-support", "truncated"])
@pytest.mark.parametrize("case", list(CLOSED_FORMS), ids=list(CLOSED_FORMS))
def test_closed_forms_match_the_generic_quadrature(case, lower):
    # The base class's mean_max_above is the tanh-sinh quadrature of the quantile
    # function; the closed forms must agree to 1e-12 relative up to m = 1e9.
    law = CLOSED_FORMS[case]
    closed = law.mean_max_above(M_VALUES, lower)
    generic = Distribution.mean_max_above(law, M_VALUES, lower)
    np.testing.assert_allclose(closed, generic, rtol=1e-12)


def test_closed_forms_known_values():
    uniform = TruncatedBelow(Uniform(0.45, 0.65), MU_D, "uniform")
    exponential = TruncatedBelow(Exponential(0.05, 0.45), MU_D, "exponential")
    assert float(uniform.mean_max(3)) == pytest.approx(0.5 + 0.15 * 3 / 4, rel=1e-15)
    assert float(exponential.mean_max(4)) == pytest.approx(0.5 + 0.05 * 25 / 12, rel=1e-15)
    # Pareto alpha = 2, m = 2: s Gamma(1/2) Gamma(3) / Gamma(5/2) = s 8/3.
    assert float(Pareto(2.0, 0.05, 0.5).mean_max(2)) == pytest.approx(0.5 + 0.05 * 8 / 3, rel=1e-14)
    assert float(Pareto(1.0, 0.05, 0.5).mean_max(2)) == math.inf
    assert Exponential(0.05).mean_max(np.array([[1, 2, 3], [4, 5, 6]])).shape == (2, 3)


def test_empirical_mean_max_is_exact(data_file):
    # Against a brute-force enumeration of all K^m equally likely resamples (m = 1, 2, 3).
    d = used_law("empirical", data_file)
    v = d.dist.values[d.dist.values > MU_D]
    grids = np.meshgrid(v, v, v, indexing="ij", sparse=True)
    brute = [v.mean(), np.maximum(*grids[:2]).mean(), np.maximum(np.maximum(grids[0], grids[1]), grids[2]).mean()]
    np.testing.assert_allclose(d.mean_max([1, 2, 3]), brute, rtol=1e-13)
    # Saturation: the max of many draws is the largest value.
    assert float(d.mean_max(1e9)) == pytest.approx(v.max(), rel=1e-15)


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_mean_max_matches_theory(case, data_file):
    # theory.mu_max_moments integrates the truncated cdf in x; mean_max uses a
    # closed form or the quadrature of the quantile function: two independent
    # routes, equal to 1e-9 relative. The empirical law's cdf has ~250 steps,
    # more than mu_max_moments has panels (128), so there its Gauss-Legendre
    # rule is only approximate (measured: 1.6e-4 relative); mean_max is exact
    # (test_empirical_mean_max_is_exact).
    d = used_law(case, data_file)
    n = np.array([0, 1, 10, 1e3, 1e6])
    rtol = 1e-3 if case == "empirical" else 1e-9
    np.testing.assert_allclose(d.mean_max(n + 2), theory.mu_max_moments(d, n)[0], rtol=rtol)


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_mean_max_matches_monte_carlo(case, data_file):
    # Seed 13, 4000 maxima of m draws for m = 1, 5, 50: within 4 standard errors.
    d = used_law(case, data_file)
    rng = np.random.default_rng(13)
    for m in (1, 5, 50):
        maxima = d.sample(rng, 4000 * m).reshape(4000, m).max(axis=1)
        sem = maxima.std(ddof=1) / math.sqrt(maxima.size)
        assert abs(maxima.mean() - float(d.mean_max(m))) < 4 * sem, (m, maxima.mean(), float(d.mean_max(m)), sem)


class CdfOnlyUniform:
    """A third-party plugin with sample and cdf only (no sf, isf nor mean_max)."""

    truncate_below_mu_d = True  # its support starts below mu_d: slidernet conditions it

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        return rng.uniform(0.45, 0.65, size)

    def cdf(self, x):
        return np.clip((np.asarray(x, dtype=float) - 0.45) / 0.2, 0.0, 1.0)


def test_mean_max_of_a_plugin_without_isf():
    # TruncatedBelow finds the quantiles by bisection on its sf.
    d = TruncatedBelow(CdfOnlyUniform(), MU_D, "cdf_only")
    np.testing.assert_allclose(d.mean_max(M_VALUES), Uniform(0.5, 0.65).mean_max(M_VALUES), rtol=1e-12)
    np.testing.assert_allclose(d.isf([1.0, 0.5, 0.0]), [0.5, 0.575, 0.65], rtol=1e-14)


def test_mean_max_quadrature_of_a_gaussian():
    # Closed forms for the max of 2 and 3 standard normals.
    d = Gaussian(0.6, 0.01)
    expected = [0.6 + 0.01 / math.sqrt(math.pi), 0.6 + 0.015 / math.sqrt(math.pi)]
    np.testing.assert_allclose(mean_max_quadrature(d, [2, 3]), expected, rtol=1e-14)
    np.testing.assert_allclose(d.mean_max([2, 3]), expected, rtol=1e-14)


def test_scipy_mean_max_of_a_law_without_mean():
    assert float(ScipyStats("pareto", {"b": 0.8, "loc": 0.5, "scale": 0.05}).mean_max(3)) == math.inf
    assert math.isnan(float(ScipyStats("cauchy", {"loc": 0.6, "scale": 0.01}).mean_max(3)))


# ---------------------------------------------------------------------------
# the paper's exact law, for every built-in

# Two sliders, sigma_theta = 10 Ntilde, 150 realizations x 100 tau_th (n ~ 2000-20000
# rearrangements each), plus a short run (2 tau_th, n ~ 10-400) where the exponent n + 2 matters most.
EXACT_LAW_SEEDS = {case: 3000 + i for i, case in enumerate(CASES)}


@pytest.mark.parametrize("steps", [2, 100], ids=["short", "long"])
@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_mu_max_is_the_maximum_of_n_plus_2_draws(case, steps, data_file):
    # P(mu_max <= mu | n) = F(mu)^(n + 2), F the truncated cdf, so the
    # (randomized, for the empirical law's atoms) probability integral
    # transform U = F(mu_max)^(n + 2) is Uniform(0, 1). Seeds 3000 + case
    # index (and 7 for V); Kolmogorov-Smirnov p > 1e-3.
    spec = spec_of(case, data_file)
    cfg = make_config(seed=EXACT_LAW_SEEDS[case], realizations=150, steps=steps, observables=["n", "mu_max"],
                      **{"friction.static": spec, "driver.sigma_theta": 10 * NTILDE, "solver": {"batch": 4096}})
    ds = slidernet.run(cfg, progress=False)
    dist = load_config(cfg).distribution()
    n = ds["n"].values[:, -1]
    mu_max = ds["mu_max"].values[:, -1]
    assert (mu_max > MU_D).all() and n.mean() > 5
    U = randomized_pit(lambda x: theory.mu_max_cdf(dist, x, n), mu_max, np.random.default_rng(7))
    np.testing.assert_allclose(theory.mu_max_cdf(dist, mu_max, n), dist.cdf(mu_max) ** (n + 2), rtol=1e-9)
    result = stats.kstest(U, "uniform")
    assert result.pvalue > 1e-3, result


# ---------------------------------------------------------------------------
# the example


def test_extreme_value_classes_example_quick(tmp_path, capsys):
    example = load_example("extreme_value_classes")
    with pytest.raises(SystemExit) as exc:
        example.main(["--help"])
    assert exc.value.code == 0
    assert "--quick" in capsys.readouterr().out
    assert example.main(["--quick", "--out", str(tmp_path)]) == 0
    png = tmp_path / example.PNG_NAME
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob(".*.tmp")), "a temporary file was left behind"
    ds = slidernet.io.read_result(tmp_path / example.NC_NAME)
    assert list(ds["law"].values) == ["uniform", "exponential", "pareto"]
    # Seed 1 (the example's default), 40 realizations x 300 tau_th: at every
    # recorded t >= 1 the mean normalized mu_max lies within 4 standard errors
    # of the exact law averaged over the measured n (uniform: its standard
    # error vanishes as mu_max saturates, so 1e-3 absolute is allowed too).
    shown = ds.sel(t=ds["t"] >= 1)
    dev = np.abs(shown["z_mean"] - shown["z_exact"])
    assert (dev <= 4 * shown["z_sem"] + 1e-3).all(), (dev / shown["z_sem"]).max("t").values
    # Evaluating the law at the mean n instead can only overestimate (concavity in n).
    assert (shown["z_exact_at_mean_n"] >= shown["z_exact"] - 1e-12).all()
    late = ds.isel(t=-1)
    # The three classes: bounded (uniform, z -> 1), logarithmic (exponential), power law (pareto).
    z = late["z_exact"].sel(law=["uniform", "exponential", "pareto"]).values
    assert z[0] < 1 < z[1] < z[2]


class BelowMuD:
    """A third-party plugin that reaches below mu_d without asking for truncation."""

    def __init__(self, lie: bool = False) -> None:
        self.lie = lie

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        return rng.uniform(0.45, 0.65, size)

    def cdf(self, x):
        # lie: a cdf that claims no mass at or below mu_d while the draws go there.
        low = 0.5 if self.lie else 0.45
        return np.clip((np.asarray(x, dtype=float) - low) / (0.65 - low), 0.0, 1.0)


def test_a_plugin_with_mass_at_or_below_mu_d_is_refused_before_any_work():
    with pytest.raises(ConfigError, match=r"'below' puts probability 0\.25 at or below mu_d = 0\.5, .*"
                                          r"'truncate_below_mu_d = True'"):
        TruncatedBelow(BelowMuD(), MU_D, "below")


def test_a_plugin_that_draws_at_or_below_mu_d_is_stopped_naming_it():
    d = TruncatedBelow(BelowMuD(lie=True), MU_D, "liar")
    with pytest.raises(slidernet.PluginError, match=r"The distribution 'liar' returned \d+ values at or below "
                                                    r"mu_d = 0\.5 from sample\(rng, 100\)"):
        d.sample(np.random.default_rng(0), 100)


def test_constant_thresholds_through_a_config():
    """The clean-friction law: every threshold, initial and redrawn, is the value; no draw is made."""
    cfg = {"seed": 1, "realizations": 2, "steps": 300, "observables": ["n", "mu_max"],
           "network": {"kind": "chain", "n": 4, "Ntilde": 1e-7},
           "friction": {"mu_d": 0.5, "static": {"name": "constant", "value": 0.6}},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}
    ds = slidernet.run(cfg, progress=False)
    assert (ds["n"].isel(t=-1) > 0).all()
    assert (ds["mu_max"] == 0.6).all()


@pytest.mark.parametrize("value", [0.5, 0.3], ids=["equal-to-mu_d", "below-mu_d"])
def test_a_constant_value_at_or_below_mu_d_is_refused(value):
    cfg = {"steps": 10, "network": {"kind": "two_slider", "Ntilde": 1e-7},
           "friction": {"mu_d": 0.5, "static": {"name": "constant",
                                                                                   "value": value}},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}
    msg = rf"The 'value' parameter of constant must be > mu_d = 0\.5\. Got {value}"
    with pytest.raises(ConfigError, match=msg):
        slidernet.load_config(cfg)
