"""A result depends on the configuration and the seed, never on ``solver.batch``.

``solver.batch`` only sets how many draws the kernels get per refill of their
buffers. The thresholds are the values of a
:class:`~slidernet.plugins.distributions.TruncatedStream` (fixed raw chunks of the
plugin, filtered at mu_d, surplus kept), so even where the truncation below
mu_d rejects many draws the values, and the results, are the same bits for
every batch size, 1 included.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import slidernet
from slidernet.config import load_config
from slidernet.errors import ConfigError, PluginError
from slidernet.plugins.distributions import RAW_CHUNK, Gaussian, TruncatedBelow, TruncatedStream
from slidernet.plugins.distributions import stream as threshold_stream
from slidernet.solver import Realization, Scene, realization_streams, simulate
from tests.conftest import make_config

MU_D = 0.5
BATCHES = (1, 7, 16, 65_536)

# Every built-in law with a large share of its mass at or below mu_d = 0.5
# (the rejected fraction in brackets), so that rejections happen in most
# batches of every size.
HEAVY = {
    "gaussian": {"mean": 0.55, "std": 0.1},  # 31 %
    "uniform": {"low": 0.3, "high": 0.7},  # 50 %
    "weibull": {"shape": 2.0, "scale": 0.15, "loc": 0.4},  # 36 %
    "lognormal": {"median": 0.1, "sigma": 0.5, "loc": 0.4},  # 50 %
    "exponential": {"scale": 0.05, "loc": 0.45},  # 63 %
    "pareto": {"alpha": 3.0, "scale": 0.05, "loc": 0.4},  # 87.5 %
    "scipy": {"dist": "gamma", "params": {"a": 2.0, "loc": 0.45, "scale": 0.05}},  # 26 %
    "empirical": {},  # 200 values uniform on (0.3, 0.8): 40 %, written by the fixture
}

# Two sliders with the appendix's tilt test before every rearrangement (pair
# kernel), a chain (csr kernel) and a small triangular lattice (vec kernel),
# both with the network tilt test at every record. sigma_theta / Ntilde = 3:
# tens of slips per step, so that batch = 1 refills at nearly every slip.
NETWORKS = {
    "pair": ({"kind": "two_slider"}, "pair"),
    "chain": ({"kind": "chain", "n": 4}, "csr"),
    "lattice": ({"kind": "triangular", "shape": [3, 3]}, "vec"),
}

QUICK = settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@pytest.fixture(scope="module")
def empirical_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("empirical") / "mu_s.txt"
    values = np.random.default_rng(2024).uniform(0.3, 0.8, 200)
    path.write_text("".join(f"{float(v)!r}\n" for v in values))
    return path


def law_spec(name: str, empirical_file: Path) -> dict[str, Any]:
    params = {"path": str(empirical_file)} if name == "empirical" else HEAVY[name]
    return {"name": name, **params}


def config(law: dict[str, Any], network: dict[str, Any], steps: int, batch: int) -> dict[str, Any]:
    return make_config(**{"steps": steps, "record": "all", "realizations": 1,
                          "observables": ["n", "mu_max", "x_G", "mu_eff"],
                          "network": {**network, "Ntilde": 1e-7}, "driver.sigma_theta": 3e-7,
                          "friction.static": law, "solver.batch": batch})


def assert_same_bits(a: dict[str, Any], b: dict[str, Any], where: str) -> None:
    assert set(a) == set(b), where
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=f"{where}: {key}", strict=True)


@pytest.mark.parametrize("net", list(NETWORKS), ids=list(NETWORKS))
@pytest.mark.parametrize("law", list(HEAVY), ids=list(HEAVY))
def test_every_batch_size_gives_the_same_bits(law: str, net: str, empirical_file: Path) -> None:
    # n, mu_max, x_G, mu_eff (f_sum, f_sq, f_count) and every other record, to the bit,
    # for batch = 1, 7, 16 and 65536; 3 seeds drawn by hypothesis per law and network.
    network, kernel = NETWORKS[net]
    steps = 12 if kernel == "vec" else 20
    scenes = {b: Scene.from_config(load_config(config(law_spec(law, empirical_file), network, steps, b)))
              for b in BATCHES}
    assert {s.kernel for s in scenes.values()} == {kernel}

    @QUICK
    @given(seed=st.integers(0, 2**32 - 1))
    def check(seed: int) -> None:
        ref = simulate(scenes[BATCHES[-1]], np.random.SeedSequence(seed))
        assert ref["n"][-1] > 16 and ref["f_count"].sum() > 0  # refills happen, mu_eff is sampled
        for b in BATCHES[:-1]:
            assert_same_bits(simulate(scenes[b], np.random.SeedSequence(seed)), ref, f"batch {b}")

    check()


def test_the_users_case_no_longer_depends_on_the_batch() -> None:
    # Reported: two sliders, gaussian std = 0.1 (mean 0.6, mu_d 0.5), seed 1, 200
    # steps: final n [8448, 8238] at batch 16 and [8425, 8279] at batch 65536.
    cfg = make_config(**{"steps": 200, "realizations": 2, "friction.static.std": 0.1, "execution.workers": 1})
    small = slidernet.run({**cfg, "solver": {"batch": 16}})
    large = slidernet.run({**cfg, "solver": {"batch": 65_536}})
    assert small["n"].values[:, -1].tolist() == large["n"].values[:, -1].tolist() == [8458, 8255]
    for name in ("n", "mu_max", "x_G", "mu_eff"):
        np.testing.assert_array_equal(small[name].values, large[name].values, err_msg=name, strict=True)


def test_the_documented_stream_order(empirical_file: Path) -> None:
    # Realization's docstring: thresholds and tilt thresholds are TruncatedStreams on
    # their Generators, the tilt uniforms plain random() on the first child of the tilt child,
    # the slide-hold-slide thresholds on the fourth child.
    law = law_spec("uniform", empirical_file)
    scene = Scene.from_config(load_config(config(law, {"kind": "two_slider"}, steps=5, batch=7)))
    ss = np.random.SeedSequence(12)
    real = Realization(scene, ss)
    rngs = realization_streams(ss)
    assert sorted(rngs) == ["driver", "shs", "thresholds", "tilt", "tilt_uniforms"]
    children = np.random.SeedSequence(12).spawn(4)
    uniforms = np.random.Generator(np.random.PCG64(np.random.SeedSequence(12, spawn_key=(2, 0))))
    assert uniforms.bit_generator.state == rngs["tilt_uniforms"].bit_generator.state
    for name, child in zip(("driver", "thresholds", "tilt", "shs"), children, strict=True):
        assert np.random.Generator(np.random.PCG64(child)).bit_generator.state == rngs[name].bit_generator.state
    thresholds = TruncatedStream(scene.distribution, rngs["thresholds"]).take(2 + 7)
    np.testing.assert_array_equal(np.concatenate([real.mu, real.buffers.mu]), thresholds, strict=True)
    np.testing.assert_array_equal(real.buffers.tilt_mu, TruncatedStream(scene.distribution, rngs["tilt"]).take(7),
                                  strict=True)
    np.testing.assert_array_equal(real.buffers.tilt_u, rngs["tilt_uniforms"].random(7), strict=True)


# -- the stream itself ------------------------------------------------------------------------------


class Recording:
    """A plugin that records the sizes it is asked for (and truncates below mu_d like a built-in)."""

    truncate_below_mu_d = True

    def __init__(self, low: float = 0.3) -> None:
        self.low = low
        self.sizes: list[int] = []

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        self.sizes.append(size)
        return rng.uniform(self.low, 0.7, size)

    def cdf(self, x):
        return np.clip((np.asarray(x, dtype=float) - self.low) / (0.7 - self.low), 0.0, 1.0)


@pytest.mark.parametrize("sizes", [[1] * 50, [7, 0, 3, 40], [50]], ids=["ones", "mixed", "one-call"])
def test_a_stream_is_the_filtered_raw_chunks_laid_end_to_end(sizes: list[int]) -> None:
    plugin = Recording()
    stream = TruncatedStream(TruncatedBelow(plugin, MU_D, "recording"), np.random.default_rng(3))
    got = np.concatenate([stream.take(k) for k in sizes])
    raw = np.random.default_rng(3).uniform(0.3, 0.7, RAW_CHUNK)
    kept = raw[raw > MU_D]
    np.testing.assert_array_equal(got, kept[:50], strict=True)
    np.testing.assert_array_equal(stream.surplus, kept[50:], strict=True)
    assert plugin.sizes == [RAW_CHUNK]  # the plugin is asked for a fixed size only


def test_a_stream_draws_nothing_before_it_is_read() -> None:
    rng = np.random.default_rng(4)
    state = rng.bit_generator.state
    stream = TruncatedStream(TruncatedBelow(Recording(), MU_D, "recording"), rng)
    assert stream.take(0).shape == (0,) and rng.bit_generator.state == state


def test_a_stream_crosses_chunk_boundaries_whatever_it_is_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    # Chunks of 8 raw draws, about 4 accepted each: requests span several chunks.
    monkeypatch.setattr(threshold_stream, "RAW_CHUNK", 8)  # read where TruncatedStream is
    law = TruncatedBelow(Recording(), MU_D, "recording")
    one = TruncatedStream(law, np.random.default_rng(5))
    mixed = TruncatedStream(law, np.random.default_rng(5))
    a = np.concatenate([one.take(1) for _ in range(300)])
    b = np.concatenate([mixed.take(k) for k in (17, 1, 0, 100, 182)])
    np.testing.assert_array_equal(a, b, strict=True)
    assert law.dist.sizes == [8] * len(law.dist.sizes)


def test_a_restored_surplus_continues_the_stream() -> None:
    law = TruncatedBelow(Gaussian(0.55, 0.1), MU_D, "gaussian")
    stream = TruncatedStream(law, np.random.default_rng(6))
    stream.take(1000)
    state, surplus = stream.rng.bit_generator.state, stream.surplus.copy()
    expected = stream.take(RAW_CHUNK)
    copy = TruncatedStream(law, np.random.default_rng(0))
    copy.rng.bit_generator.state = state
    copy.restore(surplus)
    np.testing.assert_array_equal(copy.take(RAW_CHUNK), expected, strict=True)


@pytest.mark.parametrize(("surplus", "match"), [
    (np.array([0.6, 0.5]), r"not finite and > mu_d = 0\.5"),
    (np.array([0.6, np.nan]), r"not finite"),
    (np.array([[0.6]]), r"1-D float64 array, not float64\(1, 1\)"),
    (np.array([1, 2]), r"1-D float64 array, not int64\(2,\)"),
], ids=["at-mu_d", "nan", "2d", "int"])
def test_a_bad_surplus_is_refused(surplus: np.ndarray, match: str) -> None:
    stream = TruncatedStream(TruncatedBelow(Gaussian(0.6, 0.1), MU_D, "gaussian"), np.random.default_rng(0))
    with pytest.raises(ValueError, match=match):
        stream.restore(surplus)


def test_a_negative_take_is_refused() -> None:
    stream = TruncatedStream(TruncatedBelow(Gaussian(0.6, 0.1), MU_D, "gaussian"), np.random.default_rng(0))
    with pytest.raises(ValueError, match=r"The 'size' parameter of TruncatedStream\.take must be >= 0\. "
                                         r"Got -1 instead\."):
        stream.take(-1)


class Liar(Recording):
    """Claims no mass at or below mu_d (its cdf), draws there anyway, and asks for no truncation."""

    truncate_below_mu_d = False

    def cdf(self, x):
        return np.clip((np.asarray(x, dtype=float) - MU_D) / 0.2, 0.0, 1.0)


def test_a_plugin_that_draws_at_or_below_mu_d_is_stopped_by_the_stream() -> None:
    stream = TruncatedStream(TruncatedBelow(Liar(), MU_D, "liar"), np.random.default_rng(0))
    with pytest.raises(PluginError, match=rf"The distribution 'liar' returned \d+ values at or below "
                                          rf"mu_d = 0\.5 from sample\(rng, {RAW_CHUNK}\)"):
        stream.take(1)


# -- batch = 1 and the pair kernel's recompute_forces ------------------------------------------------


@pytest.mark.parametrize(("batch", "ok"), [(1, True), (0, False), (-3, False)], ids=["one", "zero", "negative"])
def test_solver_batch_must_be_at_least_1(batch: int, ok: bool) -> None:
    cfg = make_config(**{"solver.batch": batch})
    if ok:
        assert load_config(cfg).solver.batch == batch
    else:
        with pytest.raises(ConfigError, match=rf"'solver\.batch' field must be >= 1\. Got {batch}"):
            load_config(cfg)


def test_recompute_forces_on_the_pair_kernel_has_nothing_to_reset() -> None:
    # The pair kernel forms F = theta - u at every use: no stored force, no drift.
    real = Realization(Scene.from_config(load_config(make_config(steps=30))), np.random.SeedSequence(2))
    real.advance(15)
    forces, n = real.forces(), real.n
    assert real.scene.kernel == "pair" and n > 0
    assert real.recompute_forces() == 0.0
    np.testing.assert_array_equal(real.forces(), forces, strict=True)
    real.advance()
    assert real.n > n


# -- the exactly integrated 2D slip refills often, so that a stop request is seen -------------------


def _exact_2d(**extra: Any) -> dict[str, Any]:
    return make_config(**{"network": {"kind": "irregular", "n": 16, "seed": 0, "Ntilde": 1e-7},
                          "driver.sigma_theta": 3e-7, "steps": 12, "solver.slip": "exact", **extra})


def test_an_exact_2d_scene_polls_a_stop_request_within_exact_slip_batch_slips() -> None:
    # A case of the configuration fuzz (a 4 x 4 lattice, slip = "exact", sigma_theta / Ntilde = 1e7): the
    # kernel returned to Python every 65 536 slips (solver.batch), each slip taking up to tenths of a second,
    # and one SIGTERM did not stop the run for minutes.
    from slidernet.solver.scene import EXACT_SLIP_BATCH

    scene = Scene.from_config(load_config(_exact_2d()))
    real = Realization(scene, np.random.SeedSequence(3))
    polls: list[int] = []

    def stop() -> bool:
        polls.append(real.n)
        return False

    real.advance(stop=stop)
    gaps = np.diff([0, *polls, real.n])
    assert scene.batch == EXACT_SLIP_BATCH == 32
    assert real.n > 10 * EXACT_SLIP_BATCH and gaps.max() <= EXACT_SLIP_BATCH
    # The straight slip keeps the batch the configuration asks for.
    assert Scene.from_config(load_config(_exact_2d(**{"solver.slip": "straight"}))).batch == 65_536


def test_the_exact_2d_cap_of_the_batch_changes_no_bit() -> None:
    a = simulate(Scene.from_config(load_config(_exact_2d())), np.random.SeedSequence(5))
    b = simulate(Scene.from_config(load_config(_exact_2d(**{"solver.batch": 7}))), np.random.SeedSequence(5))
    assert a.keys() == b.keys()
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], strict=True, err_msg=key)
