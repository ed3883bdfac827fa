"""Inference for a study of trends (analysis.stats): variance components, a meta-regression of slopes against
size, equivalence tests, minimum detectable effects and a family of q-values, on cases worked by hand, on
invariants (hypothesis) and on simulated data with stated seeds and tolerances."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy import optimize, stats

from slidernet.analysis.stats import (
    equivalence_test,
    fdr_family,
    meta_regression,
    minimum_detectable_effect,
    variance_components,
)
from slidernet.analysis.trend import grouped_mean_sem
from slidernet.errors import ConfigError


def _coverage_tolerance(nominal: float, replicates: int) -> float:
    """Three standard errors of a coverage fraction."""
    return 3.0 * math.sqrt(nominal * (1.0 - nominal) / replicates)


# Variance components.


def test_variance_components_of_a_balanced_table_by_hand():
    # Geometries A: 1, 3; B: 4, 6; C: 7, 11. Means 2, 5, 9; grand mean 16/3. Within: SS = 2 + 2 + 8 = 12 on
    # 3 dof, MS 4. Between: var(means) = 37/3, MS = 2 x 37/3 = 74/3 on 2 dof. Components: within 4, between
    # (74/3 - 4) / 2 = 31/3, ICC 31/43; SE of the grand mean sqrt(37/3 / 3).
    out = variance_components([1, 3, 4, 6, 7, 11], ["A", "A", "B", "B", "C", "C"])
    assert (out.groups, out.values, out.per_group, out.balanced) == (3, 6, 2.0, True)
    assert (out.dof_between, out.dof_within) == (2, 3)
    assert out.ms_within == pytest.approx(4.0, rel=1e-12)
    assert out.ms_between == pytest.approx(74 / 3, rel=1e-12)
    assert (out.within, out.between, out.icc) == pytest.approx((4.0, 31 / 3, 31 / 43), rel=1e-12)
    assert (out.grand_mean, out.grand_mean_sem) == pytest.approx((16 / 3, math.sqrt(37 / 9)), rel=1e-12)
    # The exact intervals: chi-square for the within variance, Searle's F interval for the ICC.
    assert out.within_ci == pytest.approx((12 / stats.chi2.ppf(0.975, 3), 12 / stats.chi2.ppf(0.025, 3)))
    F = (74 / 3) / 4
    lo, hi = F / stats.f.ppf(0.975, 2, 3), F / stats.f.ppf(0.025, 2, 3)
    assert out.icc_ci == pytest.approx((max((lo - 1) / (lo + 1), 0.0), min((hi - 1) / (hi + 1), 1.0)))


def test_between_interval_is_the_chi_square_one_without_within_spread():
    # Every realization of a geometry alike: the modified large-sample interval of the between variance
    # becomes the exact chi-square interval of the geometries' means, (G - 1) S^2 / chi2.
    out = variance_components([1.0, 1.0, 2.0, 2.0, 4.0, 4.0, 7.0, 7.0], [0, 0, 1, 1, 2, 2, 3, 3])
    s2 = np.var([1.0, 2.0, 4.0, 7.0], ddof=1)
    assert out.within == 0.0 and out.between == pytest.approx(s2, rel=1e-12)
    assert out.between_ci == pytest.approx((3 * s2 / stats.chi2.ppf(0.975, 3), 3 * s2 / stats.chi2.ppf(0.025, 3)),
                                           rel=1e-12)
    assert out.within_ci == (0.0, 0.0) and out.icc_ci == (1.0, 1.0)


def test_the_components_plan_a_design():
    # The standard error a design of G geometries x n realizations would have: sqrt((between + within/n)/G);
    # for the design measured it is the two-level error of the data (the between part positive).
    rng = np.random.default_rng(31)
    groups = np.repeat(np.arange(8), 4)
    values = rng.normal(0.0, 1.0, 8)[groups] + rng.normal(0.0, 1.0, 32)
    out = variance_components(values, groups)
    assert out.between > 0
    assert out.sem(8, 4) == pytest.approx(grouped_mean_sem(values, groups)[1], rel=1e-12)
    assert out.sem(16, 4) == pytest.approx(math.sqrt((out.between + out.within / 4) / 16), rel=1e-12)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), G=st.integers(2, 6),
       sizes=st.lists(st.integers(1, 5), min_size=6, max_size=6), spread=st.floats(0.0, 10.0),
       scale=st.floats(1e-3, 1e3))
def test_variance_components_invariants(seed, G, sizes, spread, scale):
    # Any table (balanced or not): components >= 0, ICC in [0, 1], each estimate inside its interval; the
    # sums of squares add up (balanced); the grand mean's implied error is at least the two-level one.
    sizes = sizes[:G]
    assume(sum(sizes) > G)   # a within spread to estimate
    rng = np.random.default_rng(seed)
    groups = np.repeat(np.arange(G), sizes)
    values = scale * (spread * rng.standard_normal(G)[groups] + rng.standard_normal(groups.size))
    out = variance_components(values, groups)
    assert out.between >= 0 and out.within >= 0 and 0 <= out.icc <= 1
    for estimate, (lo, hi) in [(out.between, out.between_ci), (out.within, out.within_ci), (out.icc, out.icc_ci)]:
        assert lo <= estimate * (1 + 1e-12) and estimate <= hi * (1 + 1e-12)
    if out.balanced:
        total = (values.size - 1) * values.var(ddof=1)
        parts = out.dof_between * out.ms_between + out.dof_within * out.ms_within
        assert parts == pytest.approx(total, rel=1e-9)
    assert out.grand_mean_sem >= grouped_mean_sem(values, groups)[1] * (1 - 1e-12)


@pytest.mark.parametrize("sizes", [[4] * 8, [2, 3, 4, 5, 3, 4, 5, 6]], ids=["balanced", "unbalanced"])
def test_variance_component_intervals_cover(sizes):
    # Seed 32, 2000 tables of 8 geometries: between variance 1, within 2 (ICC 1/3). Each 95 % interval
    # covers the truth in a fraction within 3 standard errors (0.0146) of 0.95: exactly so for the within
    # variance and the balanced ICC, approximately for the between variance (modified large-sample) and
    # for the unbalanced ICC (Thomas & Hultquist).
    rng = np.random.default_rng(32)
    groups = np.repeat(np.arange(8), sizes)
    hits = np.zeros(3)
    for _ in range(2000):
        values = rng.normal(0.0, 1.0, 8)[groups] + rng.normal(0.0, math.sqrt(2.0), groups.size)
        out = variance_components(values, groups)
        hits += [out.between_ci[0] <= 1.0 <= out.between_ci[1], out.within_ci[0] <= 2.0 <= out.within_ci[1],
                 out.icc_ci[0] <= 1 / 3 <= out.icc_ci[1]]
    np.testing.assert_array_less(np.abs(hits / 2000 - 0.95), _coverage_tolerance(0.95, 2000))


@pytest.mark.parametrize(("values", "groups", "message"), [
    ([1.0, 2.0, 3.0], [0, 0, 0], r"variance_components needs two geometries or more with finite values; got 1"),
    ([1.0, 2.0, 3.0], [0, 1, 2], r"variance_components needs a geometry with two finite values or more"),
    ([1.0, 2.0, 3.0], [0, 1], r"variance_components needs values and groups of one shape \(R,\)"),
], ids=["one-geometry", "no-within", "shapes"])
def test_variance_components_refuse_what_they_cannot_estimate(values, groups, message):
    with pytest.raises(ConfigError, match=message):
        variance_components(values, groups)


# The slope against the size: a random-effects meta-regression.


def test_meta_regression_with_equal_errors_is_ordinary_least_squares():
    # Equal standard errors: the weights are equal, so the coefficients are the least-squares line's; with
    # the Knapp-Hartung t test their errors and p-values are the ordinary ones (scipy's linregress), on
    # K - 2 dof, whatever tau^2 is.
    x = np.log([2.0, 16.0, 64.0, 256.0, 1024.0])
    y = np.array([0.04, 0.01, 0.012, -0.003, 0.002])
    line = stats.linregress(x, y)
    for method in ("REML", "DL"):
        out = meta_regression(y, np.full(5, 0.002), x, method=method)
        assert out.coef == pytest.approx([line.intercept, line.slope], rel=1e-9)
        assert out.coef_sem == pytest.approx([line.intercept_stderr, line.stderr], rel=1e-9)
        assert out.coef_p[1] == pytest.approx(line.pvalue, rel=1e-9)
        assert out.dof == 3
        # tau^2 = RSS / (K - 2) - s^2 with equal errors, for both estimators.
        rss = float(np.sum((y - line.intercept - line.slope * x) ** 2))
        assert out.tau2 == pytest.approx(rss / 3 - 0.002**2, rel=1e-9)


def test_meta_regression_of_homogeneous_slopes_is_weighted_least_squares():
    # The slopes lie on the line within their errors (Q < K - 2): the DerSimonian-Laird tau^2 is 0 and the
    # fit is weighted least squares with weights 1/s^2; its z errors are those of (X'WX)^-1, numpy's
    # polyfit with w = 1/s and cov="unscaled".
    x = np.log([2.0, 16.0, 64.0, 256.0, 1024.0])
    s = np.array([0.01, 0.003, 0.002, 0.002, 0.001])
    y = 0.03 - 0.004 * x + s * np.array([0.3, -0.5, 0.2, 0.4, -0.1])
    coef, cov = np.polyfit(x, y, 1, w=1 / s, cov="unscaled")
    out = meta_regression(y, s, x, method="DL", test="z")
    assert out.q < 3 and out.tau2 == 0.0 and out.i2 == 0.0
    assert out.coef == pytest.approx(coef[::-1], rel=1e-9)
    assert out.coef_sem == pytest.approx(np.sqrt(np.diag(cov))[::-1], rel=1e-9)
    assert out.dof == math.inf
    np.testing.assert_allclose(out.fitted, coef[1] + coef[0] * x, rtol=1e-9)
    mean, sem = out.predict([0.0])
    assert (mean[0], sem[0]) == pytest.approx((coef[1], math.sqrt(cov[1, 1])), rel=1e-9)
    # Knapp-Hartung's t test is weighted least squares with the scale estimated from the residuals:
    # polyfit's cov=True, (X'WX)^-1 times chi^2 / (K - 2), on K - 2 dof.
    _, scaled = np.polyfit(x, y, 1, w=1 / s, cov=True)
    out = meta_regression(y, s, x, method="DL")
    assert out.coef_sem == pytest.approx(np.sqrt(np.diag(scaled))[::-1], rel=1e-9)
    assert out.dof == 3 and out.coef_sem[1] < math.sqrt(cov[0, 0])


def test_random_effects_mean_by_hand():
    # Intercept only, slopes 0, 2, 5 with errors 1, 1, 2: weights 1, 1, 1/4, weighted mean 13/9, Q = 50/9,
    # sum w - sum w^2 / sum w = 4/3, so tau^2_DL = (50/9 - 2) / (4/3) = 8/3; then weights 3/11, 3/11, 3/20
    # give the mean 95/51 with z error sqrt(220/153).
    out = meta_regression([0.0, 2.0, 5.0], [1.0, 1.0, 2.0], method="DL", test="z")
    assert out.q == pytest.approx(50 / 9, rel=1e-12)
    assert out.tau2 == pytest.approx(8 / 3, rel=1e-12)
    assert out.coef[0] == pytest.approx(95 / 51, rel=1e-12)
    assert out.coef_sem[0] == pytest.approx(math.sqrt(220 / 153), rel=1e-12)
    assert out.q_p == pytest.approx(stats.chi2.sf(50 / 9, 2), rel=1e-12)


def test_reml_maximizes_the_restricted_likelihood():
    # Against a direct maximization (scipy's bounded scalar minimizer) of the restricted log-likelihood,
    # written here from its definition: -2 l_R = sum ln v + ln det X'V^-1 X + r' V^-1 r, v = s^2 + tau^2.
    x = np.log([2.0, 4.0, 16.0, 64.0, 256.0, 1024.0])
    s = np.array([0.02, 0.01, 0.008, 0.004, 0.003, 0.002])
    y = np.array([0.05, 0.01, 0.03, 0.0, 0.012, -0.004])
    X = np.column_stack([np.ones_like(x), x])

    def minus_2l(tau2: float) -> float:
        w = 1 / (s**2 + tau2)
        beta = np.linalg.solve(X.T @ (w[:, None] * X), X.T @ (w * y))
        r = y - X @ beta
        return float(np.sum(np.log(s**2 + tau2)) + np.linalg.slogdet(X.T @ (w[:, None] * X))[1] + np.sum(w * r**2))

    best = optimize.minimize_scalar(minus_2l, bounds=(0.0, 1e-2), method="bounded", options={"xatol": 1e-14})
    out = meta_regression(y, s, x)
    assert out.tau2 > 0
    assert out.tau2 == pytest.approx(best.x, rel=1e-5)


def test_meta_regression_interval_covers_the_true_slope():
    # Seed 33, 1000 studies of 7 sizes: slopes a + b ln N with b = -0.002, between-size spread tau = 0.004,
    # errors 0.002 to 0.006. The REML fit's 95 % interval of b (Knapp-Hartung, 5 dof) covers b in a
    # fraction within 3 standard errors (0.0207) of 0.95.
    rng = np.random.default_rng(33)
    x = np.log([2.0, 4.0, 16.0, 64.0, 256.0, 1024.0, 4096.0])
    s = np.array([0.006, 0.005, 0.004, 0.003, 0.003, 0.002, 0.002])
    t95 = stats.t.ppf(0.975, 5)
    covered = 0
    for _ in range(1000):
        y = 0.01 - 0.002 * x + rng.normal(0.0, 0.004, 7) + rng.normal(0.0, s)
        out = meta_regression(y, s, x)
        covered += abs(out.coef[1] + 0.002) <= t95 * out.coef_sem[1]
    assert abs(covered / 1000 - 0.95) <= _coverage_tolerance(0.95, 1000)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"estimates": [1.0, 2.0], "sems": [1.0, 1.0], "x": [1.0, 2.0]}, r"needs more estimates \(2\) than coeff"),
    ({"estimates": [1.0, 2.0, 3.0], "sems": [1.0, 0.0, 1.0]}, r"'sems' parameter of meta_regression must be > 0"),
    ({"estimates": [1.0, 2.0, 3.0], "sems": [1.0, 1.0]}, r"needs estimates and sems of one shape \(K,\)"),
    ({"estimates": [1.0, 2.0, 3.0], "sems": [1.0, 1.0, 1.0], "method": "ML"}, r"'method' parameter of meta_reg"),
    ({"estimates": [1.0, 2.0, 3.0], "sems": [1.0, 1.0, 1.0], "x": [1.0, 1.0, 1.0]}, r"x takes a single value"),
], ids=["too-few", "zero-sem", "shapes", "method", "constant-x"])
def test_meta_regression_refuses_what_it_cannot_fit(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        meta_regression(**kwargs)


# Equivalence and minimum detectable effects.


def test_tost_on_a_known_case():
    # Normal errors (dof inf): estimate 0.1, SE 0.2, margin 0.5. One-sided p: P(Z > (0.1 + 0.5) / 0.2 = 3)
    # = 0.0013499 and P(Z < (0.1 - 0.5) / 0.2 = -2) = 0.0227501; the 90 % interval 0.1 +- 1.6448536 x 0.2
    # lies inside +-0.5: equivalent at alpha 0.05, not at alpha 0.02.
    out = equivalence_test(0.1, 0.2, math.inf, 0.5)
    assert (out.p_lower, out.p_upper) == pytest.approx((0.0013499, 0.0227501), abs=1e-7)
    assert out.p == out.p_upper and out.equivalent
    assert out.ci == pytest.approx((0.1 - 1.6448536 * 0.2, 0.1 + 1.6448536 * 0.2), abs=1e-7)
    assert out.margin == (-0.5, 0.5)
    assert not equivalence_test(0.1, 0.2, math.inf, 0.5, alpha=0.02).equivalent


@settings(max_examples=100, deadline=None)
@given(estimate=st.floats(-10, 10), sem=st.floats(1e-3, 10), dof=st.one_of(st.integers(1, 200), st.just(math.inf)),
       low=st.floats(-20, 0, exclude_max=True), width=st.floats(1e-3, 40), alpha=st.floats(0.001, 0.2))
def test_tost_is_equivalent_iff_the_interval_lies_within_the_margin(estimate, sem, dof, low, width, alpha):
    out = equivalence_test(estimate, sem, dof, (low, low + width), alpha=alpha)
    lo, hi = out.ci
    assume(min(abs(lo - low), abs(hi - low - width)) > 1e-9 * (1 + abs(low) + width))   # not on an edge
    assert out.equivalent == (low < lo and hi < low + width)
    assert out.p == max(out.p_lower, out.p_upper)


def test_tost_size_at_the_margin():
    # Seed 34, 2000 samples of 20 values of true mean 1 = the margin, spread 1: the TOST at alpha 0.05 calls
    # equivalence in a fraction within 3 standard errors (0.0146) of 0.05 (the lower test always rejects).
    rng = np.random.default_rng(34)
    hits = 0
    for _ in range(2000):
        v = rng.normal(1.0, 1.0, 20)
        hits += equivalence_test(v.mean(), v.std(ddof=1) / math.sqrt(20), 19, 1.0).equivalent
    assert abs(hits / 2000 - 0.05) <= _coverage_tolerance(0.05, 2000)


def test_minimum_detectable_effect_by_hand():
    # dof inf: (z_0.975 + z_0.8) SE = (1.959964 + 0.841621) SE.
    assert minimum_detectable_effect(0.1, math.inf) == pytest.approx(0.2801585, abs=1e-7)
    by_hand = stats.t.ppf(0.975, 9) + stats.t.ppf(0.8, 9)
    assert minimum_detectable_effect(1.0, 9) == pytest.approx(by_hand, rel=1e-12)


@pytest.mark.parametrize("dof", [3, 7, 30], ids=["3", "7", "30"])
def test_a_true_effect_of_the_mde_is_found_with_the_power(dof):
    # A true effect of the MDE (SE 1) makes the two-sided t test reject with probability 0.8 within 0.02
    # (noncentral t, exact).
    mde = minimum_detectable_effect(1.0, dof)
    crit = stats.t.ppf(0.975, dof)
    power = stats.nct.sf(crit, dof, mde) + stats.nct.cdf(-crit, dof, mde)
    assert abs(power - 0.8) < 0.02


@pytest.mark.parametrize(("call", "message"), [
    (lambda: equivalence_test(0.0, 0.0, 5, 1.0), r"'sem' parameter of equivalence_test must be > 0"),
    (lambda: equivalence_test(0.0, 1.0, 0, 1.0), r"'dof' parameter of equivalence_test must be > 0"),
    (lambda: equivalence_test(0.0, 1.0, 5, -1.0), r"'margin' parameter of equivalence_test must be > 0"),
    (lambda: equivalence_test(0.0, 1.0, 5, (1.0, -1.0)), r"'margin' parameter of equivalence_test must be a "
                                                            r"number > 0 or a pair low < high"),
    (lambda: equivalence_test(0.0, 1.0, 5, 1.0, alpha=0.6), r"'alpha' parameter of equivalence_test must be in "
                                                              r"\(0, 0.5\)"),
    (lambda: minimum_detectable_effect(1.0, 5, power=1.0), r"'power' parameter of minimum_detectable_effect must "
                                                             r"be in \(0, 1\)"),
], ids=["sem", "dof", "margin", "margin-pair", "alpha", "power"])
def test_equivalence_and_mde_refuse_bad_parameters(call, message):
    with pytest.raises(ConfigError, match=message):
        call()


# A family of q-values.

# Benjamini & Hochberg (1995), section 4: 15 p-values of a clinical trial; at 0.05 BH rejects the four smallest.
BH_1995 = [0.0001, 0.0004, 0.0019, 0.0095, 0.0201, 0.0278, 0.0298, 0.0344, 0.0459, 0.3240, 0.4262, 0.5719,
           0.6528, 0.7590, 1.000]


def test_benjamini_hochberg_on_the_textbook_example():
    labels = [f"slope {i}" for i in range(15)]
    family = fdr_family(dict(zip(labels[::-1], BH_1995[::-1], strict=True)))
    assert family.size == 15 and family.method == "bh"
    assert family.discoveries(0.05) == tuple(labels[:4])
    q = dict(zip(family.labels, family.q, strict=True))
    # By hand, q_(i) = min over j >= i of 15 p_(j) / j: the fourth 0.0095 x 15 / 4, the fifth 0.0201 x 3, the
    # sixth 0.0298 x 15 / 7 (the seventh's, smaller than its own 0.0278 x 15 / 6).
    hand = (0.035625, 0.0603, 0.0298 * 15 / 7)
    assert (q["slope 3"], q["slope 4"], q["slope 5"]) == pytest.approx(hand, rel=1e-12)
    assert q["slope 14"] == 1.0


def test_benjamini_yekutieli_is_bh_times_the_harmonic_sum():
    family = dict(zip(map(str, range(15)), BH_1995, strict=True))
    bh, by = fdr_family(family), fdr_family(family, method="by")
    c = sum(1 / i for i in range(1, 16))
    np.testing.assert_allclose(by.q, np.minimum(1.0, c * bh.q), rtol=1e-12)
    assert by.discoveries(0.05) == ("0", "1", "2")


@pytest.mark.parametrize(("p", "message"), [
    ({"a": 0.1, "b": math.nan}, r"fdr_family needs a p-value in \[0, 1\] for every member; 'b' has nan"),
    ({"a": 1.5}, r"fdr_family needs a p-value in \[0, 1\] for every member; 'a' has 1.5"),
    ({}, r"fdr_family needs a family of one p-value or more"),
], ids=["nan", "above-1", "empty"])
def test_fdr_family_refuses_a_member_without_a_p_value(p, message):
    with pytest.raises(ConfigError, match=message):
        fdr_family(p)


def test_fdr_family_refuses_an_unknown_method():
    with pytest.raises(ConfigError, match=r"'method' parameter of fdr_family must be 'bh' or 'by'"):
        fdr_family({"a": 0.1}, method="bonferroni")
