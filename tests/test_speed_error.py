"""The speed-error comparison: the fixed-step sweep, the error metrics and the report."""

from __future__ import annotations

import csv
import dataclasses
import itertools

import numpy as np
import pytest

from slidernet.cli import main
from slidernet.solver import Realization, horizontal_draws, realization_streams
from slidernet.validation import speed_error as se


@pytest.fixture(scope="module")
def pair40():
    """The paper's two sliders (sigma_theta/Ntilde = 10), 40 tau_th, 8 realizations of seed 1."""
    scene = se._scene({**se.PAIR, "steps": 40, "record": [0, 40]})
    seeds = np.random.SeedSequence(1).spawn(8)
    return scene, seeds, se._solver_final(scene, seeds)


def test_horizontal_draws_are_the_solvers():
    scene = se._scene({**se.PAIR, "steps": 5, "solver": {"batch": 16}})
    ss = np.random.SeedSequence(7)
    thetas, mu, batches = horizontal_draws(scene, realization_streams(ss))
    r = Realization(scene, ss)
    np.testing.assert_array_equal(thetas, r.thetas)
    np.testing.assert_array_equal(mu, r.mu)
    np.testing.assert_array_equal(next(batches), r.buffers.mu)


def test_fixed_step_converges_to_the_exact_solution(pair40):
    """The errors fall with dtheta; at dtheta = 1e-5 Ntilde n and mu_max are exact.

    Measured (seed 1, 8 realizations, 40 tau_th): error_n = 0.80, 0.33, 0.046,
    5.7e-3, 5.0e-4, 0 for dtheta = 1 ... 1e-5 Ntilde; error_x_G 3.8e-5 at 1e-5.
    The bias of n is about dtheta / (2 (mean - mu_d)): each slip overshoots by
    dtheta / 2 on average.
    """
    scene, seeds, exact = pair40
    err = [se.errors(se.fixed_step_final(scene, seeds, d), exact) for d in (1.0, 0.1, 0.01, 1e-3, 1e-4)]
    e_n = [e["error_n"] for e in err]
    assert all(a > b for a, b in itertools.pairwise(e_n)), e_n
    for d, e in zip((0.01, 1e-3, 1e-4), err[2:], strict=True):  # bias within a factor 2 of dtheta / 0.2
        assert d / 0.4 < e["error_n"] < d / 0.1, (d, e)
    fine = se.fixed_step_final(scene, seeds, 1e-5)
    np.testing.assert_array_equal(fine["n"], exact["n"])
    np.testing.assert_array_equal(fine["mu_max"], exact["mu_max"])
    assert se.errors(fine, exact)["error_x_G"] < 1e-4


def test_fixed_step_refills_its_draws():
    """A draw buffer of 16 values is topped up by batches from the same stream: same result."""
    small = se._scene({**se.PAIR, "steps": 20, "record": [0, 20], "solver": {"batch": 16}})
    big = se._scene({**se.PAIR, "steps": 20, "record": [0, 20]})
    seeds = np.random.SeedSequence(3).spawn(2)
    a = se.fixed_step_final(small, seeds, 1e-3)
    b = se.fixed_step_final(big, seeds, 1e-3)
    assert (a["n"] > 16).all()
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])


def test_event_driven_kernels_have_zero_error(pair40):
    _scene, seeds, exact = pair40
    csr = se._scene({**se.PAIR, "steps": 40, "record": [0, 40], "solver": {"kernel": "csr"}})
    assert se.errors(se._solver_final(csr, seeds), exact)["error"] == 0.0


def test_errors_against_a_zero_reference():
    """x_G exactly 0 everywhere (no slip at all) gives no division by zero."""
    zero = {"n": np.array([0, 0]), "mu_max": np.array([0.6, 0.6]), "x_G": np.zeros(2)}
    assert se.errors(zero, zero) == {"error": 0.0, "error_n": 0.0, "error_mu_max": 0.0, "error_x_G": 0.0}


TINY = se.Preset(pair_steps=4, pair_realizations=2, dthetas=(1.0, 0.01), tau_ratios=(1e-2,), chain_steps=2,
                 chain_realizations=1, chain_tau_ratios=(1e-2,), lattice_side=3, lattice_steps=2,
                 lattice_realizations=1)


def test_cli_writes_the_csv_and_the_figure(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(se, "QUICK", TINY)
    assert main(["bench", "speed-error", "--quick", "--no-progress", "--out", str(tmp_path)]) == 0
    with open(tmp_path / "speed_error.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0])[:4] == ["method", "setting", "seconds", "error"]
    assert list(table[0]) == [f.name for f in dataclasses.fields(se.Row)]
    methods = {r["method"] for r in table}
    assert methods == {"event-driven", "fixed-step", "dynamics", "event-driven, chain", "dynamics, chain",
                       "2D slip"}
    assert len(table) == 2 + 2 + 1 + 1 + 1 + 2
    for r in table:
        assert float(r["seconds"]) > 0 and np.isfinite(float(r["error"])) and float(r["error"]) >= 0
    exact = [r for r in table if r["method"] == "event-driven" or r["setting"] == "exact"]
    assert all(float(r["error"]) == 0 for r in exact)
    assert (tmp_path / "speed_error.png").stat().st_size > 10_000
    assert "speed_error.csv" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["speed_error.csv", "speed_error.png"]
