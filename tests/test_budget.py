"""What a run will cost, checked before it starts (slidernet.solver.budget; issue 37).

- sizes that cannot fit (a chain of 2e9, a 1e5 x 1e5 lattice, an irregular network of 3e8, 1e12
  realizations, 1e15 steps recorded at every step) are refused with one line that gives the estimate and
  the machine's memory, before the network is built (they used to end in MemoryError tracebacks, the
  irregular one after 64 s);
- scenes whose forces float64 cannot resolve (sigma_theta / Ntilde = 1e15, k or kappa = 1e12, a normal load
  of 1e-300) are refused naming lost precision and the parameter, where the run used to stop with an
  avalanche-limit error that blamed max_avalanche, or ran for ever;
- a run that would take hours (mu_s - mu_d of 1e-10, sigma_theta / Ntilde = 1e5 for 1e6 steps) gets one
  SlowRunWarning before it starts, with the estimate.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import slidernet
from slidernet import cli
from slidernet.config import load_config
from slidernet.ensemble import runner
from slidernet.ensemble.sweep import sweep
from slidernet.errors import ConfigError, PrecisionError, SizeError, SlowRunWarning
from slidernet.solver import Scene, budget
from slidernet.solver.backends import BACKENDS

#: A machine's memory for the refusals, the same on every machine that runs the tests.
MACHINE = 64 * 10**9


def config(dotted: dict | None = None, **changes: object) -> dict:
    """A chain of 8 at the study's point (sigma_theta / Ntilde = 1), with ``changes`` (top-level keys) and
    ``dotted`` ("table.field" keys) on top."""
    raw: dict = {"seed": 1, "realizations": 2, "steps": 100,
                 "network": {"kind": "chain", "n": 8, "Ntilde": 1e-7},
                 "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
                 "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}
    raw.update(changes)
    for key, value in (dotted or {}).items():
        table, field = key.split(".")
        raw[table] = dict(raw[table], **{field: value})
    return raw


@pytest.fixture
def machine(monkeypatch: pytest.MonkeyPatch) -> None:
    """This machine has MACHINE bytes, and building a scene fails the test: the refusal comes before it."""
    monkeypatch.setattr(budget, "machine_memory", lambda: MACHINE)

    def no_scene(*args: object, **kwargs: object) -> None:
        raise AssertionError("the scene was built before the size was checked")

    monkeypatch.setattr(runner, "scene_of", no_scene)


TOO_LARGE = [
    pytest.param({"network": {"kind": "chain", "n": 2 * 10**9, "Ntilde": 1e-7}},
                 r"the network of 2,000,000,000 sliders.*'network\.n'", id="chain-n-2e9"),
    pytest.param({"network": {"kind": "square", "shape": [10**5, 10**5], "Ntilde": 1e-7}},
                 r"the network of 10,000,000,000 sliders.*'network\.shape'", id="square-1e5x1e5"),
    pytest.param({"network": {"kind": "irregular", "n": 3 * 10**8, "Ntilde": 1e-7}},
                 r"the network of 300,000,000 sliders.*'network\.n'", id="irregular-n-3e8"),
    pytest.param({"realizations": 10**12},
                 r"the bookkeeping of 1,000,000,000,000 realizations.*'realizations'",
                 id="realizations-1e12"),
    pytest.param({"steps": 10**15, "record": "all"},
                 r"2 realizations x 1,000,000,000,000,001 recorded times.*'record', 'steps'",
                 id="steps-1e15-record-all"),
    # Issue 43: solver.batch = 2^40 within int64 ended in a MemoryError traceback (8 TiB of draws).
    pytest.param({"solver": {"batch": 2**40}},
                 r"each drawing theta for all of its 100 steps.* and 1,099,511,627,776 draws of mu_s in its "
                 r"buffer.*'solver\.batch'", id="batch-2^40"),
]


@pytest.mark.parametrize(("changes", "match"), TOO_LARGE)
def test_sizes_that_cannot_fit_are_refused_before_any_work(machine: None, changes: dict, match: str) -> None:
    with pytest.raises(SizeError, match=r"This run needs about [\d.]+ [GTPE]B of memory, more than this machine's "
                                        r"64 GB: most of it for .*" + match) as refused:
        slidernet.run(config(**changes), workers=1, progress=False)
    assert "\n" not in str(refused.value)
    assert isinstance(refused.value, (ConfigError, ValueError))


def test_a_size_that_fits_is_not_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(budget, "machine_memory", lambda: MACHINE)
    ds = slidernet.run(config(), workers=1, progress=False)
    assert int(ds.sizes["realization"]) == 2


def test_the_command_refuses_a_size_with_one_line_and_exit_2(machine: None, tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "big.toml"
    path.write_text(
        'seed = 1\nrealizations = 2\nsteps = 10\n[network]\nkind = "chain"\nn = 2000000000\nNtilde = 1e-7\n'
        '[friction]\nmu_d = 0.5\n[friction.static]\nname = "gaussian"\nmean = 0.6\nstd = 0.01\n'
        '[driver]\nname = "gaussian_steps"\nsigma_theta = 1e-7\n')
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("slidernet: error: This run needs about ")
    assert "the network of 2,000,000,000 sliders" in err
    assert not (tmp_path / "out").exists()


def test_a_sweep_refuses_a_point_that_cannot_fit_before_any_point_runs(machine: None, tmp_path: Path,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a point ran before every point's size was checked")

    monkeypatch.setattr(runner, "run_in", no_run)
    with pytest.raises(SizeError, match=r"^Sweep point 1 \(network\.n=2000000000\): This run needs about .* the "
                                        r"network of 2,000,000,000 sliders"):
        sweep(config(), {"network.n": [8, 2 * 10**9]}, out=tmp_path / "sweep", workers=1, progress=False)
    assert not (tmp_path / "sweep" / "sweep.json").exists()


def test_memory_estimate_counts_the_draw_buffers() -> None:
    plain = budget.memory_estimate(load_config(config()))
    batch = budget.memory_estimate(load_config(config(solver={"batch": 2**20})))
    # The thresholds' buffer; a run with tilt tests holds two more (tilt thresholds, uniforms).
    assert batch.running - plain.running == budget.DRAW_BYTES * (2**20 - 2**16)
    tilted = budget.memory_estimate(load_config(config(solver={"batch": 2**20}, observables=["mu_eff"],
                                                       mu_eff_at="records")))
    assert tilted.running - batch.running == 2 * budget.DRAW_BYTES * 2**20


def test_memory_estimate_streams_records_with_an_output_folder() -> None:
    cfg = load_config(config(realizations=10_000, steps=1000, record="all"))
    held, streamed = budget.memory_estimate(cfg, 2), budget.memory_estimate(cfg, 2, streamed=True)
    assert held.records == budget.RECORD_BYTES * 10_000 * 1001
    assert streamed.records == budget.RECORD_BYTES * (budget.STREAMED + 2) * 1001
    assert held.ensemble == budget.REALIZATION_BYTES[False] * 10_000


def test_machine_memory_is_this_machines() -> None:
    memory = budget.machine_memory()
    assert memory is None or 10**8 < memory < 10**15


PRECISION = [
    pytest.param({"network.Ntilde": 1.0, "driver.sigma_theta": 1e15},
                 r"'driver' with 'network\.Ntilde'", id="sigma_theta-over-Ntilde-1e15"),
    pytest.param({"network.k": 1e12, "driver.sigma_theta": 1e-6}, r"'network\.k' \(thermal loads", id="k-1e12"),
    pytest.param({"network.kappa": 1e12, "driver.sigma_theta": 1e-6}, r"'network\.kappa' \(thermal loads",
                 id="kappa-1e12"),
    pytest.param({"network.normal_load": 1e-300}, r"'network\.normal_load' \(down to 1e-300",
                 id="normal-load-1e-300"),
]


@pytest.mark.parametrize(("changes", "cause"), PRECISION)
def test_scenes_float64_cannot_resolve_are_refused_naming_precision_and_the_parameter(
        monkeypatch: pytest.MonkeyPatch, changes: dict, cause: str) -> None:
    def no_realization(*args: object, **kwargs: object) -> None:
        raise AssertionError("a realization ran before the precision was checked")

    monkeypatch.setattr(runner, "compile_kernels", no_realization)
    raw = config(changes, allow_implausible=True)  # float64's limits lie far outside real materials
    with pytest.raises(PrecisionError, match=r"float64 cannot resolve .*Lost floating-point precision; the cause: "
                                             + cause) as refused:
        slidernet.run(raw, workers=1, progress=False)
    assert "max_avalanche" not in str(refused.value) and "\n" not in str(refused.value)


@pytest.mark.parametrize("changes", [
    pytest.param({}, id="paper-chain"),
    pytest.param({"network.Ntilde": 1.0, "driver.sigma_theta": 1e4}, id="sigma_theta-over-Ntilde-1e4"),
    pytest.param({"network.k": 1e3, "network.kappa": 1e3}, id="k-kappa-1e3"),
])
def test_scenes_within_float64_are_not_refused(changes: dict) -> None:
    cfg = load_config(config(changes, allow_implausible=True))  # Ntilde = 1: far outside real materials
    budget.check_precision(cfg, Scene.from_config(cfg))


SLOW = [
    pytest.param(config(**{"friction": {"mu_d": 0.5, "static": {"name": "uniform", "low": 0.5 + 1e-10,
                                                                 "high": 0.5 + 2e-10}}}), id="gap-1e-10"),
    pytest.param(config(steps=10**6, realizations=1, network={"kind": "two_slider", "Ntilde": 1e-7},
                        driver={"name": "gaussian_steps", "sigma_theta": 1e-2}), id="pair-sigma-1e5-1e6-steps"),
]


@pytest.mark.parametrize("raw", SLOW)
def test_a_run_that_would_take_hours_warns_once_before_it_starts(monkeypatch: pytest.MonkeyPatch,
                                                                 raw: dict) -> None:
    def stop(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the run started")

    monkeypatch.setattr(runner, "compile_kernels", stop)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(RuntimeError, match="the run started"):
            slidernet.run(raw, workers=1, progress=False)
    slow = [w for w in caught if issubclass(w.category, SlowRunWarning)]
    assert len(slow) == 1, [str(w.message) for w in caught]
    assert "hours" in str(slow[0].message) or "days" in str(slow[0].message)
    assert "slips per tau_th" in str(slow[0].message) and "slips/s" in str(slow[0].message)


def test_the_study_runs_without_a_warning() -> None:
    cfg = load_config(config(steps=10_000, realizations=16))
    scene = Scene.from_config(cfg)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SlowRunWarning)
        seconds = budget.warn_if_slow(cfg, scene, workers=2)
    assert seconds < 60


#: Scenes of the study's table (docs/guides/aging-networks.md; benchmarks/slip_rate_estimate.py has all 18):
#: (network, sigma_theta / Ntilde, measured slips per tau_th). The estimate was 1.96, 0.20, 0.09 and 0.59 of
#: these before it followed the band's loss and the front of relieved load.
STUDY_RATES = [({"kind": "chain", "n": 2}, 1.0, 2.887), ({"kind": "chain", "n": 8}, 10.0, 577.6),
               ({"kind": "chain", "n": 16}, 10.0, 1276.0),
               ({"kind": "irregular", "n": 256, "seed": 0}, 1.0, 6422.0)]


@pytest.mark.parametrize(("network", "sigma", "measured"), STUDY_RATES,
                         ids=["two-sliders-1", "chain-8-10", "chain-16-10", "irregular-256-1"])
def test_the_estimate_is_within_a_factor_2_of_the_measured_rate(network: dict, sigma: float,
                                                                 measured: float) -> None:
    cfg = load_config(config(network=network | {"Ntilde": 1e-7}, steps=10**4,
                             driver={"name": "gaussian_steps", "sigma_theta": sigma * 1e-7}))
    estimate = budget.slips_per_tau(cfg, Scene.from_config(cfg))
    assert 0.5 <= estimate / measured <= 2.0, estimate / measured


def test_the_ends_of_a_chain_load_its_middle_in_opposite_directions() -> None:
    # A chain of 3 at sigma_theta / Ntilde = 10: the fronts from its two ends cancel at node 1, so it slips
    # like two ends alone (the measured 5.775 is twice the two sliders' 2.887 at 1; here at 10).
    def rate(n: int) -> float:
        cfg = load_config(config(network={"kind": "chain", "n": n, "Ntilde": 1e-7}, steps=10**4,
                                 driver={"name": "gaussian_steps", "sigma_theta": 1e-6}))
        return budget.slips_per_tau(cfg, Scene.from_config(cfg))

    assert rate(3) == pytest.approx(2 * rate(2), rel=0.02)


def test_the_estimate_counts_the_time_to_build_a_large_network() -> None:
    # A chain of 5e7 sliders driven for 30 steps was estimated at 5e-5 s and ran for 80 s, building its
    # network (benchmarks/config_fuzz.py): the estimate now holds the build, SETUP_SECONDS per node.
    cfg = load_config(config(network={"kind": "chain", "n": 1000, "Ntilde": 1e-7}, steps=30))
    scene = Scene.from_config(cfg)
    slips = budget.slips_per_tau(cfg, scene) * cfg.steps * cfg.realizations
    drive = slips / BACKENDS[scene.kernel].slips_per_second
    seconds = budget.warn_if_slow(cfg, scene, workers=1)
    assert seconds == pytest.approx(drive + 1000 * budget.SETUP_SECONDS["chain"], rel=1e-12)
    assert 1000 * budget.SETUP_SECONDS["chain"] > drive
