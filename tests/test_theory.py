"""Tests of slidernet.analysis.theory: exact identities, Monte Carlo checks, validation."""

from __future__ import annotations

import math
import re
from fractions import Fraction

import numpy as np
import pytest
from scipy import integrate, special, stats

from slidernet.analysis.theory import (
    harmonic,
    mean_rearrangements,
    mean_records,
    msd,
    mu_max_cdf,
    mu_max_leading,
    mu_max_moments,
)
from slidernet.errors import ConfigError
from slidernet.plugins.distributions import Gaussian, TruncatedBelow

MU_D = 0.5
MU_S_MEAN = 0.6


class CdfOnlyGaussian:
    """A plugin with ``sample`` and ``cdf`` only: no ``sf``, no ``lower``."""

    truncate_below_mu_d = True  # its tail reaches below mu_d: conditioned by slidernet

    def __init__(self, mean: float, std: float) -> None:
        self.mean = mean
        self.std = std

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        return self.mean + self.std * rng.standard_normal(size)

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        return special.ndtr((np.asarray(x, dtype=float) - self.mean) / self.std)


def truncated(std: float, plugin: type = Gaussian) -> TruncatedBelow:
    return TruncatedBelow(plugin(MU_S_MEAN, std), lower=MU_D, name="gaussian")


NARROW = truncated(0.01)  # the paper's p(mu_s): truncation 10 sigma below the mean
HEAVY = truncated(0.1)  # truncation 1 sigma below the mean: 16 % of the mass removed


def reference_moments(dist: TruncatedBelow, n: float, sigma: float) -> tuple[float, float]:
    """Mean and std of the max of n + 2 draws by adaptive quadrature.

    Independent of mu_max_moments' range finding and fixed rule: integrates
    P(max > x) from the support's lower end to 20 sigma above the mean.
    """
    m = n + 2.0

    def survival(x: float) -> float:
        sf = float(dist.sf(x))
        return 1.0 if sf >= 1.0 else -math.expm1(m * math.log1p(-sf))

    lo, hi = dist.lower, MU_S_MEAN + 20 * sigma
    # Breakpoints around the bulk of the maximum help quad find the Gumbel peak.
    peak = MU_S_MEAN + sigma * math.sqrt(2 * math.log(m))
    points = [p for p in (peak - 2 * sigma, peak, peak + 2 * sigma) if lo < p < hi]
    opts = {"points": points, "limit": 500, "epsabs": 1e-14 * sigma, "epsrel": 1e-12}
    first = integrate.quad(survival, lo, hi, **opts)[0]
    second = integrate.quad(lambda x: 2 * (x - lo) * survival(x), lo, hi, **opts)[0]
    return lo + first, math.sqrt(second - first**2)


def two_slider_thresholds(dist, n_max: int, rows: int, seed: int, record_at: set[int]):
    """Run the threshold dynamics of the two-slider model for ``rows`` realizations.

    Each rearrangement redraws the weaker of the two thresholds (docs/model.md,
    section 1). Returns, for each n in ``record_at``, mu_max and the number
    of times the strongest slider changed.
    """
    rng = np.random.default_rng(seed)
    mu = np.stack([dist.sample(rng, rows), dist.sample(rng, rows)], axis=1)
    rows_idx = np.arange(rows)
    strongest = mu.argmax(axis=1)
    exchanges = np.zeros(rows, dtype=int)
    out = {}
    for n in range(n_max + 1):
        if n in record_at:
            out[n] = (mu.max(axis=1), exchanges.copy())
        if n == n_max:
            break
        mu[rows_idx, mu.argmin(axis=1)] = dist.sample(rng, rows)
        new_strongest = mu.argmax(axis=1)
        exchanges += new_strongest != strongest
        strongest = new_strongest
    return out


# ---------------------------------------------------------------------------
# mean_rearrangements


def test_mean_rearrangements_paper_value():
    r = mean_rearrangements(1e-6, Ntilde=1e-7, mu_d=MU_D, mu_s_mean=MU_S_MEAN)
    # (1e-6 - 0.5e-7) / (sqrt(pi) * 0.1 * 1e-7) = 9.5 / sqrt(pi) * 10
    assert float(r) == pytest.approx(95 / math.sqrt(math.pi), rel=1e-12)
    assert float(r) == pytest.approx(53.6, abs=0.01)


def test_mean_rearrangements_without_offset_and_vectorised():
    sigma = np.array([[1e-7, 1e-6], [5e-6, 1e-5]])
    plain = mean_rearrangements(sigma, 1e-7, MU_D, MU_S_MEAN, offset=False)
    shifted = mean_rearrangements(sigma, 1e-7, MU_D, MU_S_MEAN)
    assert plain.shape == shifted.shape == (2, 2)
    np.testing.assert_allclose(plain, sigma / (math.sqrt(math.pi) * 0.1 * 1e-7), rtol=1e-12)
    # The offset is the same number of rearrangements, mu_d / (sqrt(pi) (mu_s - mu_d)).
    np.testing.assert_allclose(plain - shifted, 0.5 / (math.sqrt(math.pi) * 0.1), rtol=1e-9)


# ---------------------------------------------------------------------------
# mu_max_cdf


@pytest.mark.parametrize("dist", [NARROW, HEAVY, CdfOnlyGaussian(0.6, 0.01)], ids=["narrow", "heavy", "cdf-only"])
def test_mu_max_cdf_no_rearrangement_is_f_squared(dist):
    mu = np.linspace(0.45, 0.9, 50)
    np.testing.assert_allclose(mu_max_cdf(dist, mu, 0), dist.cdf(mu) ** 2, rtol=1e-12, atol=1e-300)


def test_mu_max_cdf_broadcasts():
    out = mu_max_cdf(NARROW, np.array([0.6, 0.62, 0.64]), np.array([[0], [10], [1000]]))
    assert out.shape == (3, 3)
    # More rearrangements can only raise mu_max.
    assert (np.diff(out, axis=0) <= 0).all()
    np.testing.assert_allclose(out[1], NARROW.cdf([0.6, 0.62, 0.64]) ** 12, rtol=1e-12)


def test_mu_max_cdf_far_tail_uses_sf():
    # At sf = 1e-20 the cdf is 1 to double precision, so only the sf path can see
    # 1 - F^m ~ m * sf = 1e-11 for n = 1e9.
    n = 1e9
    z = -special.ndtri(1e-20)
    p = float(mu_max_cdf(NARROW, MU_S_MEAN + 0.01 * z, n))
    assert 1.0 - p == pytest.approx((n + 2) * 1e-20, rel=1e-4)


# ---------------------------------------------------------------------------
# mu_max_moments: exact values and quadrature accuracy


@pytest.mark.parametrize(
    ("n", "mean_z", "var_z"),
    [
        (0, 1 / math.sqrt(math.pi), 1 - 1 / math.pi),
        (1, 1.5 / math.sqrt(math.pi), 1 + math.sqrt(3) / (2 * math.pi) - 9 / (4 * math.pi)),
    ],
    ids=["max-of-2", "max-of-3"],
)
def test_mu_max_moments_closed_forms(n, mean_z, var_z):
    # Closed forms of the max of 2 and 3 standard normals; the truncation of
    # NARROW, 10 sigma below the mean, changes them by ~1e-23.
    mean, std = mu_max_moments(NARROW, n)
    assert float(mean) == pytest.approx(MU_S_MEAN + 0.01 * mean_z, abs=1e-13)
    assert float(std) == pytest.approx(0.01 * math.sqrt(var_z), abs=1e-12)


@pytest.mark.parametrize("n", [0, 10, 1e3, 1e6, 1e9], ids=lambda n: f"n={n:g}")
@pytest.mark.parametrize(("dist", "sigma"), [(NARROW, 0.01), (HEAVY, 0.1)], ids=["narrow", "heavy"])
def test_mu_max_moments_match_adaptive_quadrature(dist, sigma, n):
    # Requirement: error of (mean - median) well below 1e-3 sigma. The median
    # F^-1(2^(-1/m)) is exact, so this is a bound on the mean; we ask 1e-9 sigma.
    mean, std = mu_max_moments(dist, n)
    ref_mean, ref_std = reference_moments(dist, n, sigma)
    assert abs(float(mean) - ref_mean) < 1e-9 * sigma
    assert abs(float(std) - ref_std) < 1e-9 * sigma


def test_mu_max_moments_cdf_only_plugin_matches_sf():
    # Without sf, 1 - F below ~1e-16 rounds to 0; that must stay negligible.
    n = np.array([0, 10, 1e3, 1e6, 1e9])
    for sigma in (0.01, 0.1):
        with_sf = mu_max_moments(truncated(sigma), n)
        raw = mu_max_moments(truncated(sigma, CdfOnlyGaussian), n)
        np.testing.assert_allclose(raw[0], with_sf[0], rtol=0, atol=1e-6 * sigma)
        np.testing.assert_allclose(raw[1], with_sf[1], rtol=0, atol=1e-6 * sigma)
    # A bare plugin (no lower support): the range is found by bracketing alone.
    bare = mu_max_moments(CdfOnlyGaussian(0.6, 0.01), n)
    np.testing.assert_allclose(bare[0], mu_max_moments(NARROW, n)[0], rtol=0, atol=1e-8)


class CdfOnlyUniform:
    """Uniform on [0.55, 0.65] with only a cdf: bounded support, no ``lower``."""

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        return np.clip((np.asarray(x, dtype=float) - 0.55) / 0.1, 0.0, 1.0)


@pytest.mark.parametrize("n", [0, 10, 1e6], ids=lambda n: f"n={n:g}")
def test_mu_max_moments_uniform_plugin_closed_form(n):
    # Max of m uniforms on [a, a + w]: mean a + w m/(m+1), var w^2 m/((m+1)^2 (m+2)).
    m = n + 2
    mean, std = mu_max_moments(CdfOnlyUniform(), n)
    assert float(mean) == pytest.approx(0.55 + 0.1 * m / (m + 1), abs=1e-12)
    assert float(std) == pytest.approx(0.1 * math.sqrt(m / ((m + 1) ** 2 * (m + 2))), rel=1e-6)


def test_mu_max_moments_median_gap():
    # mean - median of the max of m Gaussians, with the exact median
    # mu + sigma * isf(1 - 2^(-1/m)), tends to the Gumbel value
    # (gamma + ln ln 2) / sqrt(2 ln m) sigma only slowly; check that it is
    # positive and shrinks with n, and agrees with the quadrature reference.
    n = np.array([1e3, 1e6, 1e9])
    mean, _ = mu_max_moments(NARROW, n)
    median = MU_S_MEAN - 0.01 * special.ndtri(-np.expm1(-math.log(2) / (n + 2)))
    gap = (mean - median) / 0.01
    assert (gap > 0).all() and (np.diff(gap) < 0).all()
    ref = np.array([reference_moments(NARROW, k, 0.01)[0] for k in n])
    np.testing.assert_allclose(mean - median, ref - median, rtol=0, atol=1e-11)


def test_mu_max_moments_shape_and_monotonicity():
    # Its speed (~0.03 s for 100 values of n) is not asserted: a test never races the machine.
    n = np.unique(np.round(np.logspace(0, 9, 100)))
    mean, std = mu_max_moments(NARROW, n)
    assert mean.shape == std.shape == n.shape
    assert (np.diff(mean) > 0).all() and (np.diff(std) < 0).all()
    grid_mean, grid_std = mu_max_moments(HEAVY, np.array([[0, 5, 5], [1e9, 0, 5]]))
    assert grid_mean.shape == (2, 3)
    assert grid_mean[0, 1] == grid_mean[0, 2] == grid_mean[1, 2]
    assert grid_std[0, 0] == grid_std[1, 1]
    assert mu_max_moments(NARROW, [])[0].shape == (0,)


# ---------------------------------------------------------------------------
# Monte Carlo of the two-slider threshold dynamics


@pytest.mark.parametrize(("dist", "sigma"), [(NARROW, 0.01), (HEAVY, 0.1)], ids=["narrow", "heavy"])
def test_mu_max_monte_carlo(dist, sigma):
    # Seed 20240601, 20000 realizations, n in {0, 10, 1000}. Tolerance: 4
    # standard errors -- std/sqrt(R) for the mean and std/sqrt(2(R-1)) for
    # the std (near-Gaussian approximation, adequate for these max laws) --
    # plus a Kolmogorov-Smirnov test against mu_max_cdf at the 1e-3 level.
    rows, checkpoints = 20000, {0, 10, 1000}
    samples = two_slider_thresholds(dist, 1000, rows, seed=20240601, record_at=checkpoints)
    for n in sorted(checkpoints):
        mu_max = samples[n][0]
        mean, std = mu_max_moments(dist, n)
        assert abs(mu_max.mean() - mean) < 4 * std / math.sqrt(rows), n
        assert abs(mu_max.std(ddof=1) - std) < 4 * std / math.sqrt(2 * (rows - 1)), n
        ks = stats.kstest(mu_max, lambda x, n=n: mu_max_cdf(dist, x, n))
        assert ks.pvalue > 1e-3, n


def test_mean_records_monte_carlo():
    # Seed 7, 20000 realizations: the mean number of exchanges of the
    # strongest slider after n rearrangements, within 4 standard errors.
    rows, checkpoints = 20000, {0, 1, 5, 200}
    samples = two_slider_thresholds(NARROW, 200, rows, seed=7, record_at=checkpoints)
    assert (samples[0][1] == 0).all()
    for n in sorted(checkpoints - {0}):
        exchanges = samples[n][1]
        se = exchanges.std(ddof=1) / math.sqrt(rows)
        assert abs(exchanges.mean() - float(mean_records(n))) < 4 * se, n


# ---------------------------------------------------------------------------
# mu_max_leading and msd


def test_mu_max_leading_values():
    out = mu_max_leading(MU_S_MEAN, 0.01, [0, 1, 0.5, 1e4])
    np.testing.assert_allclose(out[:3], MU_S_MEAN, rtol=0, atol=0)
    assert out[3] == pytest.approx(MU_S_MEAN + 0.01 * math.sqrt(2 * math.log(1e4)), rel=1e-14)


def test_mu_max_leading_overestimates_by_04_to_05_sigma():
    # docs/model.md section 4: for n = 1e3..1e6 eq. mumaxth overestimates the exact
    # mean maximum by 0.4-0.5 sigma_mu. We measure (leading - exact mean) /
    # sigma_mu on 31 log-spaced n: it falls monotonically from 0.475 (n = 1e3)
    # to 0.394 (n = 1e6), i.e. the statement holds to its one significant digit
    # (0.39 rounds to 0.4); we assert 0.39 < excess < 0.48.
    n = np.logspace(3, 6, 31)
    mean, _ = mu_max_moments(NARROW, n)
    excess = (mu_max_leading(MU_S_MEAN, 0.01, n) - mean) / 0.01
    assert (np.diff(excess) < 0).all()
    assert excess[0] == pytest.approx(0.475, abs=0.001)
    assert excess[-1] == pytest.approx(0.394, abs=0.001)
    assert ((excess > 0.39) & (excess < 0.48)).all()


def test_msd():
    out = msd(np.array([[1e-6], [1e-5]]), np.array([0, 1, math.e, 1e6]))
    assert out.shape == (2, 4)
    np.testing.assert_array_equal(out[:, :2], 0.0)
    np.testing.assert_allclose(out[:, 2], [1e-12, 1e-10], rtol=1e-14)
    np.testing.assert_allclose(out[0, 3], 1e-12 * math.log(1e6), rtol=1e-14)


# ---------------------------------------------------------------------------
# harmonic numbers and records


def test_harmonic_small_values_exact():
    expected = [float(sum(Fraction(1, k) for k in range(1, n + 1))) for n in range(0, 40)]
    assert harmonic(np.arange(40)).tolist() == expected
    assert harmonic(3).tolist() == 11 / 6


@pytest.mark.parametrize("n", [1024, 1025, 5000, 10**6], ids=lambda n: f"n={n}")
def test_harmonic_large_values(n):
    # Across the table boundary (1024) the digamma branch must agree with the sum.
    expected = math.fsum(1.0 / k for k in range(1, n + 1))
    assert float(harmonic(n)) == pytest.approx(expected, rel=1e-14)


def test_harmonic_asymptotic_and_noninteger():
    n = 1e9
    assert float(harmonic(n)) == pytest.approx(
        math.log(n) + np.euler_gamma + 1 / (2 * n) - 1 / (12 * n**2), rel=1e-15
    )
    # H_{1/2} = 2 - 2 ln 2.
    assert float(harmonic(0.5)) == pytest.approx(2 - 2 * math.log(2), rel=1e-14)


def test_mean_records_exact():
    assert float(mean_records(0)) == 0.0
    assert float(mean_records(1)) == pytest.approx(1 / 3, rel=1e-15)
    n = np.array([[2, 10], [100, 10**6]])
    out = mean_records(n)
    assert out.shape == (2, 2)
    expected = [[math.fsum(1 / k for k in range(3, int(v) + 3)) for v in row] for row in n]
    np.testing.assert_allclose(out, expected, rtol=1e-13)
    # Leading order: H_{n+2} - 3/2 = ln n - (3/2 - gamma) + O(1/n).
    big = float(mean_records(1e9))
    assert big - math.log(1e9) == pytest.approx(np.euler_gamma - 1.5, abs=1e-8)


# ---------------------------------------------------------------------------
# validation


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: mean_rearrangements(1e-6, -1.0, MU_D, MU_S_MEAN),
            "The 'Ntilde' parameter of mean_rearrangements must be > 0. Got -1.0 instead.",
        ),
        (
            lambda: mean_rearrangements(1e-6, 0, MU_D, MU_S_MEAN),
            "The 'Ntilde' parameter of mean_rearrangements must be > 0. Got 0.0 instead.",
        ),
        (
            lambda: mean_rearrangements([1e-6, float("nan")], 1e-7, MU_D, MU_S_MEAN),
            "The 'sigma_theta' parameter of mean_rearrangements must be finite and > 0. Got nan instead.",
        ),
        (
            lambda: mean_rearrangements(float("inf"), 1e-7, MU_D, MU_S_MEAN),
            "The 'sigma_theta' parameter of mean_rearrangements must be finite and > 0. Got inf instead.",
        ),
        (
            lambda: mean_rearrangements(1e-6, 1e-7, MU_D, 0.5),
            "The 'mu_s_mean' parameter of mean_rearrangements must be > mu_d = 0.5. Got 0.5 instead.",
        ),
        (
            lambda: mean_rearrangements(1e-6, 1e-7, float("nan"), 0.6),
            "The 'mu_d' parameter of mean_rearrangements must be finite. Got nan instead.",
        ),
        (lambda: mu_max_cdf(NARROW, 0.6, -1), "The 'n' parameter of mu_max_cdf must be >= 0. Got -1.0 instead."),
        (
            lambda: mu_max_moments(NARROW, [3, -2]),
            "The 'n' parameter of mu_max_moments must be >= 0. Got -2.0 instead.",
        ),
        (
            lambda: mu_max_moments(NARROW, float("inf")),
            "The 'n' parameter of mu_max_moments must be finite and >= 0. Got inf instead.",
        ),
        (
            lambda: mu_max_moments(object(), 3),
            "The 'dist' parameter of mu_max_moments must be a distribution with a cdf",
        ),
        (
            lambda: mu_max_leading(MU_S_MEAN, float("nan"), 10),
            "The 'sigma_mu' parameter of mu_max_leading must be finite and > 0. Got nan instead.",
        ),
        (lambda: msd(-1e-6, 10), "The 'sigma_theta' parameter of msd must be > 0. Got -1e-06 instead."),
        (
            lambda: harmonic(float("nan")),
            "The 'n' parameter of harmonic must be finite and >= 0. Got nan instead.",
        ),
        (lambda: mean_records(-3), "The 'n' parameter of mean_records must be >= 0. Got -3.0 instead."),
    ],
    ids=[
        "Ntilde-negative",
        "Ntilde-zero",
        "sigma_theta-nan",
        "sigma_theta-inf",
        "mu_s_mean-not-above-mu_d",
        "mu_d-nan",
        "cdf-negative-n",
        "moments-negative-n",
        "moments-inf-n",
        "moments-no-cdf",
        "leading-nan-sigma",
        "msd-negative-sigma",
        "harmonic-nan",
        "records-negative",
    ],
)
def test_bad_inputs_raise_config_error(call, message):
    with pytest.raises(ConfigError, match="^" + re.escape(message)):
        call()


def test_config_error_is_a_value_error():
    with pytest.raises(ValueError, match="Ntilde"):
        mean_rearrangements(1e-6, -1.0, MU_D, MU_S_MEAN)


def test_mu_max_moments_in_chunks_gives_the_bits_of_one_batch(monkeypatch):
    # The paper's 50 500 values of n in one batch took 2.8 GB; chunks must not change a bit.
    # Seed 0: 700 values of n spread over 0 to 5e7, three chunks of 256 against one batch.
    from slidernet.analysis.theory import extremes as th
    law = TruncatedBelow(Gaussian(0.6, 0.01), lower=0.5, name="gaussian")
    n = np.round(np.exp(np.random.default_rng(0).uniform(0.0, np.log(5e7), 700)))
    chunked = th.mu_max_moments(law, n)
    monkeypatch.setattr(th, "_CHUNK", 10**9)
    whole = th.mu_max_moments(law, n)
    for got, expected in zip(chunked, whole, strict=True):
        np.testing.assert_array_equal(got, expected)
