"""The network tilt test's caps and the sliding rule of [tilt] (issue 43, point 5).

``[tilt] min_slips = 20000`` or ``1e9``, and ``min_displacement = 1e300``, on 6 sliders gave the sample
of the avalanche cap (rule 4 of kernels/tilt_net.py: an avalanche of max(100 N, 1e5) slips is a part
sliding alone), identical for all three, labelled as the rule asked for. A rule the caps cannot reach is
refused before the run, naming both numbers; a test that still meets the cap before the rule is counted
in ``tilt_capped`` and left out of mu_eff.
"""

from __future__ import annotations

import numpy as np
import pytest

import slidernet
from slidernet.ensemble import runner
from slidernet.errors import ConfigError
from slidernet.io import read_result
from slidernet.solver import realization

from .conftest import make_config

SIX = {"kind": "chain", "n": 6, "Ntilde": 1e-7}


def _config(tilt: dict, **changes: object) -> dict:
    return make_config(**{"realizations": 2, "steps": 10, "record": "all", "network": SIX,
                          "observables": ["n", "mu_eff", "mu_eff_realization"], "mu_eff_at": "records",
                          "tilt": tilt, **changes})


@pytest.fixture
def no_work(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("the run started before its tilt rule was checked")

    monkeypatch.setattr(runner, "compile_kernels", refuse)


UNREACHABLE = [
    pytest.param({"min_slips": 20_000}, {}, r"asks each of the 6 sliders to slip min_slips = 20000 times in one "
                 r"avalanche: at least 6 x 19999 \+ 1 = 119995 slips, more than the 100000 slips after which the "
                 r"network tilt test takes a part of the network to slide on its own \(max\(100 N, 1e5\)\)",
                 id="min_slips-20000"),
    pytest.param({"min_slips": 1e9}, {}, r"asks .* min_slips = 1000000000 .* more than the 100000 slips",
                 id="min_slips-1e9"),
    pytest.param({"min_displacement": 1e300}, {}, r"asks the centre of mass to move by min_displacement = 1e\+300 "
                 r"mean slip lengths in one avalanche: about 6e\+300 slips .* more than the 100000 slips",
                 id="min_displacement-1e300"),
    pytest.param({"min_slips": 100}, {"solver": {"max_avalanche": 300}},
                 r"asks .* at least 6 x 99 \+ 1 = 595 slips, more than solver\.max_avalanche = 300",
                 id="max_avalanche"),
]


@pytest.mark.parametrize(("tilt", "changes", "match"), UNREACHABLE)
def test_a_rule_the_caps_cannot_reach_is_refused_before_the_run_naming_both(no_work, tilt, changes, match):
    with pytest.raises(ConfigError, match=r"^The \[tilt\] table " + match) as refused:
        slidernet.run(_config(tilt, **changes))
    assert "\n" not in str(refused.value)


def test_a_rule_within_the_caps_runs():
    ds = slidernet.run(_config({"min_slips": 2}))
    assert int(ds["tilt_capped"].sum()) == 0
    assert int(ds["mu_eff_count"].sum()) == 2 * 11


def test_a_test_that_meets_the_cap_first_is_counted_and_left_out_of_mu_eff(monkeypatch):
    # A cap of 20 slips per avalanche (rule 4) meets the rule of 3 slips per node (at least 13 slips) in most
    # tests before the rule (measured: 37 of 44; a cap of 40 in none): those are counted, not sampled.
    monkeypatch.setattr(realization, "tilt_avalanche_cap", lambda n_nodes: 20)
    ds = slidernet.run(_config({"min_slips": 3}, realizations=4), workers=1)
    capped, count = ds["tilt_capped"].values, ds["mu_eff_count"].values
    assert ds["tilt_capped"].dims == ("t",) and capped.dtype == np.int64
    assert capped.sum() > 0 and count.sum() > 0
    np.testing.assert_array_equal(capped + count, 4)  # every test is one or the other
    full = np.isnan(ds["mu_eff_realization"].values)
    assert full.sum() >= (capped == 4).sum() * 4
    assert np.isnan(ds["mu_eff"].values[capped == 4]).all()
    assert ds["tilt_capped"].attrs["units"] == "1" and "cap" in ds["tilt_capped"].attrs["long_name"]


def test_the_default_rule_has_no_count_and_keeps_its_samples(monkeypatch):
    # Rule 4 is part of the default rule (a part sliding alone above mu_d, the rows of a square lattice): its
    # samples are mu_eff's, and the result has no tilt_capped.
    monkeypatch.setattr(realization, "tilt_avalanche_cap", lambda n_nodes: 40)
    ds = slidernet.run(_config({"min_slips": 1}), workers=1)
    assert "tilt_capped" not in ds
    assert int(ds["mu_eff_count"].sum()) == 2 * 11


def test_the_count_is_written_and_read_back(tmp_path, monkeypatch):
    monkeypatch.setattr(realization, "tilt_avalanche_cap", lambda n_nodes: 20)
    ds = slidernet.run(_config({"min_slips": 3}), out=tmp_path / "out", workers=1)
    back = read_result(tmp_path / "out" / "result.nc")
    assert ds["tilt_capped"].values.sum() > 0
    np.testing.assert_array_equal(back["tilt_capped"].values, ds["tilt_capped"].values)
    assert back["tilt_capped"].dtype == np.int64
