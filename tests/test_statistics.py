"""Statistical tests against MODEL.md section 4. Every test states its seed and tolerance.

Seeds are fixed, so each test is deterministic; the tolerances are chosen so
that they would hold for most seeds too (they are not tuned to one draw).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

import slidernet
from slidernet.theory import mean_rearrangements, mean_records, mu_max_cdf
from tests.conftest import make_config, scene_of

NTILDE = 1e-7
MU_D = 0.5
MU_S_MEAN = 0.6

# Relative deviation of the simulated <r> from eq. `slope`, measured once with
# 40 realizations of 200000 / 100000 / 40000 steps (seed 12345, reference
# mu_d = 0.5, mu_s = 0.6 +- 0.01, Ntilde = 1e-7):
#   sigma_theta/Ntilde =  2: -2.68 % (standard error 0.03 %)
#   sigma_theta/Ntilde = 10: -0.83 % (standard error 0.04 %)
#   sigma_theta/Ntilde = 50: -0.23 % (standard error 0.07 %)
# The formula is phenomenological: it slightly overestimates <r>, less so at
# large amplitude. The test allows twice the measured deviation plus 3
# standard errors of its own (shorter) run.
MEASURED_SLOPE_DEVIATION = {2: 0.0268, 10: 0.0083, 50: 0.0023}


@pytest.mark.parametrize("ratio", [2, 10, 50], ids=["2", "10", "50"])
def test_mean_rearrangements_follow_eq_slope(ratio):
    # Seed 7, 10 realizations x 20000 steps: relative standard error ~0.25 %.
    cfg = make_config(seed=7, realizations=10, steps=20_000, observables=["n"],
                      **{"driver.sigma_theta": ratio * NTILDE})
    ds = slidernet.run(cfg)
    r, sem = float(ds["r_mean"]), float(ds["r_sem"])
    predicted = float(mean_rearrangements(ratio * NTILDE, NTILDE, MU_D, MU_S_MEAN))
    tolerance = 2 * MEASURED_SLOPE_DEVIATION[ratio] * predicted + 3 * sem
    assert abs(r - predicted) <= tolerance, (r, sem, predicted)
    # The run is precise enough for the tolerance to mean something.
    assert 3 * sem < 0.01 * predicted


# sigma_mu / (mu_s_mean - mu_d): 0.1 (the paper's, truncation irrelevant)
# and 1.0 (truncation one sigma below the mean removes 16 % of p(mu_s)).
TRUNCATION = {"narrow": 0.01, "truncated": 0.1}
# steps and sigma_theta/Ntilde: a few rearrangements (n ~ 8, n = 0 included),
# where the exponent n + 2 matters most, and a long run (n ~ 1500).
DURATION = {"short": (1, 2.0), "long": (30, 10.0)}


@pytest.mark.parametrize("duration", list(DURATION), ids=list(DURATION))
@pytest.mark.parametrize("truncation", list(TRUNCATION), ids=list(TRUNCATION))
def test_mu_max_is_the_maximum_of_n_plus_2_draws(truncation, duration):
    # P(mu_max <= mu | n) = F(mu)^(n + 2), F the truncated CDF; so by the
    # probability integral transform U = F(mu_max)^(n + 2) is Uniform(0, 1).
    # Seed 2010, 400 realizations; Kolmogorov-Smirnov p > 1e-3.
    steps, ratio = DURATION[duration]
    cfg = make_config(seed=2010, realizations=400, steps=steps, observables=["n", "mu_max"],
                      **{"friction.static.std": TRUNCATION[truncation],
                         "driver.sigma_theta": ratio * NTILDE})
    ds = slidernet.run(cfg)
    dist = scene_of(cfg).distribution
    n = ds["n"].values[:, -1]
    mu_max = ds["mu_max"].values[:, -1]
    U = mu_max_cdf(dist, mu_max, n)
    np.testing.assert_allclose(U, dist.cdf(mu_max) ** (n + 2), rtol=1e-9)
    result = stats.kstest(U, "uniform")
    assert result.pvalue > 1e-3, result


@pytest.mark.parametrize("duration", list(DURATION), ids=list(DURATION))
@pytest.mark.parametrize("truncation", list(TRUNCATION), ids=list(TRUNCATION))
def test_strongest_slider_changes_are_records(truncation, duration):
    # n_records counts the draws that beat every earlier one. After n
    # rearrangements (n + 2 draws) its mean is H_{n+2} - H_2. Each realization
    # is compared with the expectation at its own n; the mean difference must
    # lie within 4 standard errors of 0. Seed 2011, 400 realizations.
    steps, ratio = DURATION[duration]
    cfg = make_config(seed=2011, realizations=400, steps=steps, observables=["n", "n_records"],
                      **{"friction.static.std": TRUNCATION[truncation],
                         "driver.sigma_theta": ratio * NTILDE})
    ds = slidernet.run(cfg)
    n = ds["n"].values[:, -1]
    diff = ds["n_records"].values[:, -1] - mean_records(n)
    sem = diff.std(ddof=1) / np.sqrt(diff.size)
    assert abs(diff.mean()) <= 4 * sem, (diff.mean(), sem)
    # The expected counts are not trivially small (H_{n+2} - 3/2 ~ 1.3 or ~6).
    assert mean_records(n).mean() > 1.0
