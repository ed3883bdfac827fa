"""Compiled draws of the built-in laws (slidernet.kernels.draws) against the plugins' batched path."""

from __future__ import annotations

import numpy as np
import pytest

from slidernet.kernels import draws
from slidernet.plugins.distributions import (
    RAW_CHUNK,
    Exponential,
    Gaussian,
    Lognormal,
    Pareto,
    TruncatedBelow,
    TruncatedStream,
    Uniform,
    Weibull,
)

MU_D = 0.5
# Laws whose truncation at mu_d rejects a visible share of the draws (5 % to 50 %).
COMPILED = {
    "gaussian": Gaussian(0.55, 0.05),
    "uniform": Uniform(0.45, 0.7),
    "weibull": Weibull(2.0, 0.1, loc=0.45),
    "exponential": Exponential(0.1, loc=0.45),
}


@pytest.mark.parametrize("name", list(COMPILED), ids=list(COMPILED))
def test_compiled_draws_are_the_batched_draws_to_the_bit(name):
    # Seed 11: the first 3 * RAW_CHUNK raw draws through numpy's batched sample and the filter
    # of TruncatedBelow.accepted, against the compiled loop on a Generator in the same state.
    law = TruncatedBelow(COMPILED[name], MU_D, name)
    assert law.compiled_law() is not None
    batched_rng, compiled_rng = np.random.default_rng(11), np.random.default_rng(11)
    expected = np.concatenate([law.accepted(batched_rng, RAW_CHUNK) for _ in range(3)])
    got = np.empty(expected.size)
    raw = draws.fill_truncated(compiled_rng, got, *law.compiled_law(), MU_D)
    np.testing.assert_array_equal(got, expected, strict=True)
    assert 0.05 * raw < raw - expected.size  # the truncation was exercised
    # The Generator advanced in place, by exactly the raw draws made: the draws the batched
    # path made past the last accepted value are the only difference.
    assert raw <= 3 * RAW_CHUNK
    replay = np.random.default_rng(11)
    COMPILED[name].sample(replay, raw)
    assert compiled_rng.bit_generator.state == replay.bit_generator.state


@pytest.mark.parametrize("batch", [1, 7, RAW_CHUNK + 3], ids=["one", "seven", "past-a-chunk"])
def test_a_stream_of_a_compiled_law_hands_out_the_same_values_with_no_surplus(batch):
    law = TruncatedBelow(Gaussian(0.55, 0.05), MU_D, "gaussian")
    stream = TruncatedStream(law, np.random.default_rng(3))
    got = np.concatenate([stream.take(batch) for _ in range(3)])
    assert stream.surplus.size == 0
    batched = np.concatenate([law.accepted(np.random.default_rng(3), 4 * RAW_CHUNK)])
    np.testing.assert_array_equal(got, batched[: got.size], strict=True)


@pytest.mark.parametrize("dist", [Lognormal(0.1, 0.3, loc=0.45), Pareto(3.0, 0.1, loc=0.45)],
                         ids=["lognormal", "pareto"])
def test_laws_through_numpy_exp_keep_the_batched_path(dist):
    # numpy's vectorised exp differs from the scalar exp in the last bit: these stay batched.
    assert TruncatedBelow(dist, MU_D, dist.name).compiled_law() is None


def test_a_plugin_keeps_the_batched_path():
    class Plugin:
        truncate_below_mu_d = True

        def sample(self, rng, size):
            return 0.6 + 0.01 * rng.standard_normal(size)

        def cdf(self, x):
            return np.clip(np.asarray(x, float), 0.0, 1.0)

    assert TruncatedBelow(Plugin(), MU_D, "plugin").compiled_law() is None
