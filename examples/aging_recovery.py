"""Could the network tilt test have seen aging? A positive control at every size
=============================================================================

``examples/aging_networks.py`` asks whether mu_eff, the network tilt test,
rises with time in networks as it does for the pair. A "no" means something
only if the estimator could have said "yes". This study injects a known
aging into the tested copy of the state (``[tilt] inject``, docs/model.md,
"Injected aging"): at every recorded time t each test is made twice on the
same state with the same draws, as it is and with thresholds raised by
c ln(1 + t / tau_th), and the paired difference of the slopes says how much
of the injected rise each estimator passes:

    recovery = (slope with injection - slope without) / (slope of the shift),

paired per realization (common random numbers), slopes per decade of t over
a window (10 <= t <= 1e3 tau_th, the main one, and 1 <= t <= 1e3), its error
two-level over network geometries where there are several
(:func:`slidernet.analysis.trend.injection_recovery`).

* **Injections**: every contact (``select = 1``), or only the 10 % oldest
  (``select = 0.1``: aging by selection). c = 0.004, so that c ln 10 =
  92e-4 per decade, about the pair's own rate at ratio 0.3 (the aging page).
  Under ``select = 0.1`` the recovery is given against the per-contact shift
  (c) and against the mean shift over the network (q c, q = ceil(0.1 N) / N):
  a friction coefficient of the whole network, an average of its contacts'
  forces, sees at most the mean.
* **Estimators**: ``mu_eff`` (the load at which the network slides as a
  whole), ``tilt_first_slip`` (the load at the test's first slip),
  ``tilt_all_moving`` (the load once every node has slipped in it) and
  ``mu_shs`` (the peak force of the slide-hold-slide pull, stiffness 1,
  on the same state with the same injection), and three readings of the
  contacts as each breaks in the tilt test: ``tilt_contact_mean`` (the
  mean load at which the contacts break), ``tilt_half_broken`` (the load
  at which half of them have broken) and ``tilt_break_ratio`` (the mean
  local ratio ``|F_i| / N_i`` under which each breaks).
* **Systems**: ratio sigma_mu / (mean - mu_d) = 0.3 at mu_d = 0.5,
  sigma_theta / Ntilde = 1, to 1e3 tau_th, 10 recorded times per decade;
  the pair, free chains of 4 and 16, irregular networks of 16 and 64 (16
  geometries x 2 realizations), 256 (8 x 2) and 1024 (8 x 1), triangular
  lattices 4 x 4 to 32 x 32 (16 realizations); slip rules e = 1, 0.5, 0;
  for the rise of the oldest contacts, 64x the realizations for the pair
  and the chains (2 048) and 4x for the rest at e = 1.

Writes ``aging_recovery.json`` (every number with its configurations),
``aging_recovery_tables.md`` (the guide's table, from that JSON) and
``aging_recovery.png`` into ``--out``::

    python examples/aging_recovery.py --out recovery_out --workers 2   # the full preset
    python examples/aging_recovery.py --out recovery_out --quick       # seconds; CI runs it

``--resume`` continues an interrupted run. Units: time in tau_th, friction
coefficients dimensionless.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import slidernet
from slidernet.analysis.trend import grouped_mean_sem, injection_recovery, log_trend
from slidernet.config import InjectConfig
from slidernet.io import atomic_output, save_figure, write_json

try:
    HERE = Path(__file__).resolve().parent
except NameError:  # sphinx-gallery defines no __file__; it runs the script from examples/
    HERE = Path.cwd()
sys.path.insert(0, str(HERE))  # the systems, the configurations and the sweeps of the aging study
import aging_networks as study

JSON_NAME = "aging_recovery.json"
PNG_NAME = "aging_recovery.png"
TABLES_NAME = "aging_recovery_tables.md"
LN10 = math.log(10.0)
INJECT_C = 0.004  # c ln 10 = 92e-4 per decade, about the pair's own aging rate at ratio 0.3
SELECTS = (1.0, 0.1)
OVERSHOOTS = (1.0, 0.5, 0.0)
# Each estimator: its per-realization variable, without and with the injection.
ESTIMATORS = {"mu_eff": ("mu_eff_realization", "mu_eff_injected_realization"),
              "tilt_first_slip": ("tilt_first_slip", "tilt_first_slip_injected"),
              "tilt_all_moving": ("tilt_all_moving", "tilt_all_moving_injected"),
              "mu_shs": ("mu_shs", "mu_shs_injected"),
              "tilt_contact_mean": ("tilt_contact_mean", "tilt_contact_mean_injected"),
              "tilt_half_broken": ("tilt_half_broken", "tilt_half_broken_injected"),
              "tilt_break_ratio": ("tilt_break_ratio", "tilt_break_ratio_injected")}
WINDOWS = {"10-1e3": 10.0, "1-1e3": 1.0}  # t_min of each window; t_max: the run's end


def _systems(tag: str, inject: tuple[float, float], e: float) -> list[study.Group]:
    """The full preset's systems at one injection and one slip rule (ratio 0.3).

    The rise of the 10 % oldest contacts at the paper's slip (e = 1) gets 4x the realizations: its mean
    shift is a tenth of the uniform one, and the recovery's error with it (0.24-0.48 at 16 to 1024 irregular
    sliders with the base counts, up to 1.9 along chains, measured), too large to tell 0.5 from 1.
    """
    common = {"params": ("ratio0.3",), "overshoot": e, "inject": inject, "observables": ("mu_shs",)}
    x = 4 if (inject[1] < 1.0 and e == 1.0) else 1
    # The pair and the chains cost seconds: under the rise of the oldest contacts (2 of 16 along a chain of
    # 16: a mean shift an eighth of the uniform one) they get 64x the realizations at every e.
    x1d = 64 if inject[1] < 1.0 else 1
    return [study.Group(f"{tag}_pair", "pair", (2,), realizations=32 * x1d, **common),
            study.Group(f"{tag}_chains", "chain", (4, 16), realizations=32 * x1d, **common),
            study.Group(f"{tag}_irregular_small", "irregular", (16, 64), geometries=16, realizations=32 * x,
                        **common),
            study.Group(f"{tag}_irregular_256", "irregular", (256,), geometries=8, realizations=16 * x, **common),
            study.Group(f"{tag}_irregular_1024", "irregular", (1024,), geometries=8, realizations=8 * x, **common),
            study.Group(f"{tag}_lattices", "triangular", (4, 8, 16, 32), realizations=16 * x, **common)]


def _tag(select: float, e: float) -> str:
    return f"q{select:g}_e{e:g}"


PRESETS = {
    "full": study.Preset(
        realizations=32, steps=1000, per_decade=10, mechanism=(),
        groups=tuple(g for q in SELECTS for e in OVERSHOOTS for g in _systems(_tag(q, e), (INJECT_C, q), e))),
    "quick": study.Preset(
        realizations=4, steps=100, per_decade=5, mechanism=(),
        groups=tuple(g for q in SELECTS for g in (
            study.Group(f"{_tag(q, 1.0)}_pair", "pair", (2,), ("ratio0.3",), inject=(INJECT_C, q),
                        observables=("mu_shs",)),
            study.Group(f"{_tag(q, 1.0)}_irregular", "irregular", (16,), ("ratio0.3",), 2,
                        inject=(INJECT_C, q), observables=("mu_shs",))))),
}


def _shift(t: xr.DataArray, inject: InjectConfig) -> xr.DataArray:
    """The injected shift c ln(1 + t / t0) at the recorded times, as one realization."""
    return xr.DataArray(inject.c * np.log1p(t.values / inject.t0)[None, :], dims=("realization", "t"),
                        coords={"t": t.values})


def recover(ds: xr.Dataset, geometry: np.ndarray, inject: InjectConfig, N: int) -> dict[str, Any]:
    """Every estimator's recovery of the injection, per window: against the per-contact shift and the mean one.

    Parameters
    ----------
    ds : xarray.Dataset
        The realizations of one point (dims ``realization``, ``t``), with
        the variables of :data:`ESTIMATORS` and their injected twins.
    geometry : ndarray of int, shape (R,)
        Each realization's independent unit (its network geometry).
    inject : InjectConfig
        The injection the point ran with.
    N : int
        Number of sliders.
    """
    share = inject.raised(N) / N  # the mean shift over the network, per unit of the per-contact shift
    out: dict[str, Any] = {"raised": inject.raised(N), "share": share, "rate_per_decade": {}}
    for window, t_min in WINDOWS.items():
        # The shift's own slope over the window: full recovery (near c per unit ln t for t >> t0).
        rate = float(log_trend(_shift(ds["t"], inject), t_min=t_min)["slope"][0])
        out["rate_per_decade"][window] = LN10 * rate
        for name, (plain, injected) in ESTIMATORS.items():
            slopes = [log_trend(ds[v], t_min=t_min)["slope"].values for v in (plain, injected)]
            # The plain slope's mean and error by one rule, two-level over geometries like the recovery's.
            plain_mean, plain_sem, _ = grouped_mean_sem(slopes[0], geometry)
            for norm, r in (("contact", rate), ("mean", share * rate)):
                rec = injection_recovery(*slopes, r, geometry)
                out[f"{name}|{window}|{norm}"] = {
                    "recovery": rec.recovery, "sem": rec.recovery_sem, "dof": rec.dof, "pairs": rec.pairs,
                    "response_per_decade": LN10 * rec.response, "response_sem_per_decade": LN10 * rec.response_sem,
                    "plain_slope_per_decade": LN10 * plain_mean, "plain_slope_sem_per_decade": LN10 * plain_sem}
    return out


def _pm(rec: dict[str, Any]) -> str:
    return f"{rec['recovery']:.2f} ± {rec['sem']:.2f}"


def tables(data: dict[str, Any]) -> str:
    """The guide's recovery tables in Markdown, from ``aging_recovery.json``: one per injection, the main
    window (10-1e3 tau_th); mu_eff's recovery also in the window 1-1e3."""
    lines = []
    for select in SELECTS:
        norm = "contact" if select == 1.0 else "mean"
        lines += [f"### Injection into {'every contact' if select == 1.0 else 'the 10 % oldest contacts'} "
                  f"(select = {select:g}), recovery of the {'shift' if select == 1.0 else 'mean shift'}", "",
                  "| e | network | N | R (G) | μ_eff, 10–1e3 | μ_eff, 1–1e3 | first slip | all moving | μ_shs "
                  "| contact mean | half broken | break ratio | dμ_eff/dlog10 t, plain (1e-4) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for p in data["points"]:
            if p["select"] != select:
                continue
            r = p["recovery"]
            lines.append(
                f"| {p['overshoot']:g} | {study._label(p)} | {p['N']} | {p['realizations']} ({p['geometries']}) | "
                f"{_pm(r[f'mu_eff|10-1e3|{norm}'])} | {_pm(r[f'mu_eff|1-1e3|{norm}'])} | "
                f"{_pm(r[f'tilt_first_slip|10-1e3|{norm}'])} | {_pm(r[f'tilt_all_moving|10-1e3|{norm}'])} | "
                f"{_pm(r[f'mu_shs|10-1e3|{norm}'])} | {_pm(r[f'tilt_contact_mean|10-1e3|{norm}'])} | "
                f"{_pm(r[f'tilt_half_broken|10-1e3|{norm}'])} | {_pm(r[f'tilt_break_ratio|10-1e3|{norm}'])} | "
                f"{1e4 * r[f'mu_eff|10-1e3|{norm}']['plain_slope_per_decade']:+.1f} |")
        lines.append("")
    return "\n".join(lines)


def calibrated(results: dict[str, Any], data: dict[str, Any]) -> str:
    """``tilt_break_ratio``'s slopes in the aging study's systems (``examples/aging_networks.py``'s JSON,
    ``results``), each at ratio 0.3 beside its gain, the recovery of the uniform rise at e = 1 in this study's
    JSON (``data``), and the slope divided by it: a rate of the thresholds (1e-4 per decade of t). The
    quotient's error combines both relative errors (delta method; the two runs are independent)."""
    gain = {}
    for p in data["points"]:
        if p["select"] == 1.0 and p["overshoot"] == 1.0:
            r = p["recovery"]["tilt_break_ratio|10-1e3|contact"]
            gain[(p["kind"], p["N"])] = (r["recovery"], r["sem"])
    lines = ["| network | N | parameters | slope, t ≥ 10 | slope, t ≥ 100 | slope, ≥ 100 slips per node "
             "| gain (uniform rise, e = 1, ratio 0.3) | t ≥ 10 slope / gain |",
             "|---|---|---|---|---|---|---|---|"]
    for p in results["points"]:
        w = p["windows"].get("tilt_break_ratio")
        if p["mu_eff_at"] != "records" or not w or p["rule"] != "e = 1" or p["condition"]:
            continue

        def slope(label: str, w: dict[str, Any] = w) -> str:
            if label not in w:
                return "–"
            s = w[label]["slope_per_decade"]
            return f"{1e4 * s['mean']:+.1f} ± {1e4 * s['sem']:.1f}"

        g = gain.get((p["kind"], p["N"])) if p["params"] == "ratio0.3" else None
        quotient = "–"
        if g is not None:
            s = w["t>=10"]["slope_per_decade"]
            q = s["mean"] / g[0]
            sem = math.hypot(s["sem"] / g[0], q * g[1] / g[0])
            quotient = f"{1e4 * q:+.1f} ± {1e4 * sem:.1f}"
        lines.append(f"| {study._label(p)} | {p['N']} | {p['params']} | {slope('t>=10')} | {slope('t>=100')} | "
                     f"{slope('s>=100')} | {'–' if g is None else f'{g[0]:.2f} ± {g[1]:.2f}'} | {quotient} |")
    # The pair's plain slopes over the largest ensemble of this study (its plain variables are those of a run
    # without injection): the reference rate, with the error of its 2 048 realizations.
    pairs = [p for p in data["points"] if p["kind"] == "pair" and p["overshoot"] == 1.0]
    big = max(pairs, key=lambda p: p["realizations"], default=None)
    if big is not None:
        for name in ("tilt_break_ratio", "mu_eff"):
            for window, t_min in WINDOWS.items():
                r = big["recovery"][f"{name}|{window}|contact"]
                lines.append(f"\nThe pair's plain {name} over {big['realizations']} realizations (e = 1, "
                             f"ratio 0.3, {t_min:g} <= t <= 1e3): {1e4 * r['plain_slope_per_decade']:+.1f} ± "
                             f"{1e4 * r['plain_slope_sem_per_decade']:.1f} (1e-4 per decade)")
    return "\n".join(lines) + "\n"


def plot(data: dict[str, Any], path: Path) -> Path:
    """Recovery against N: one panel per estimator and injection, one line per slip rule and kind."""
    fig = Figure(figsize=(24, 6.5), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(SELECTS), len(ESTIMATORS), sharex=True, squeeze=False)
    for row, select in enumerate(SELECTS):
        norm = "contact" if select == 1.0 else "mean"
        for col, name in enumerate(ESTIMATORS):
            ax = axes[row][col]
            for e, color in zip(OVERSHOOTS, ("C0", "C1", "C2"), strict=True):
                for kind, marker in (("pair", "s"), ("chain", "^"), ("irregular", "o"), ("triangular", "D")):
                    pts = sorted((p for p in data["points"] if p["select"] == select and p["overshoot"] == e
                                  and p["kind"] == kind), key=lambda p: p["N"])
                    if not pts:
                        continue
                    rec = [p["recovery"][f"{name}|10-1e3|{norm}"] for p in pts]
                    ax.errorbar([p["N"] for p in pts], [r["recovery"] for r in rec], [r["sem"] for r in rec],
                                color=color, marker=marker, ms=4, capsize=2, lw=1,
                                label=f"e = {e:g}" if kind == "irregular" else None)
            ax.axhline(1.0, color="0.5", lw=0.8)
            ax.axhline(0.5, color="0.5", lw=0.8, ls=":")
            study._sizes_axis(ax, [p["N"] for p in data["points"]])
            ax.set_title(f"{name}, select = {select:g}", fontsize=9)
            ax.set_ylabel("recovery of the " + ("shift" if norm == "contact" else "mean shift"))
            if row == len(SELECTS) - 1:
                ax.set_xlabel("N (squares: pair, triangles: chains, circles: irregular, diamonds: lattices)",
                              fontsize=7)
    axes[0][0].legend(fontsize=7)
    return save_figure(fig, path, dpi=110)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("recovery_out"), help="output folder")
    parser.add_argument("--quick", action="store_true", help="the pair and 16 sliders, short runs (seconds)")
    parser.add_argument("--workers", type=int, default=None, help="worker processes per sweep point")
    parser.add_argument("--scheduler", default=None,
                        help="a Dask scheduler address, e.g. tcp://host:8786: realizations run on that cluster")
    parser.add_argument("--resume", action="store_true",
                        help="continue the sweeps of an interrupted run in --out (points already done are kept)")
    parser.add_argument("--calibrate", type=Path, default=None, metavar="STUDY_JSON",
                        help="print tilt_break_ratio's slopes in the aging study's JSON (aging_networks.json) "
                             "divided by their gains in --out's aging_recovery.json, and exit")
    args = parser.parse_args(argv)
    if args.calibrate is not None:
        try:
            results, data = (json.loads(path.read_text(encoding="utf-8")) for path in (args.calibrate,
                                                                                      args.out / JSON_NAME))
            table = calibrated(results, data)
        except (OSError, ValueError, KeyError, TypeError) as exc:
            # A wrong path or another file than the two studies' JSON: one line, the user's fault.
            print(f"aging_recovery: error: --calibrate needs examples/aging_networks.py's JSON and this study's "
                  f"{JSON_NAME} in --out: {type(exc).__name__}: {exc}", file=sys.stderr)
            return 2
        print(table, end="")
        return 0

    name = "quick" if args.quick else "full"
    preset = PRESETS[name]
    start = time.perf_counter()
    points: list[dict[str, Any]] = []
    for group in preset.groups:
        t0 = time.perf_counter()
        assert group.inject is not None
        inject = InjectConfig(c=group.inject[0], select=group.inject[1])
        for size, (ds, geometry, configs) in zip(group.sizes, study.run_sweeps(
                group, "ratio0.3", preset, args.workers, args.scheduler, args.out, args.resume), strict=True):
            N = study._n_nodes(group.kind, size)
            pt = {"group": group.name, "kind": group.kind, "size": size, "N": N, "overshoot": group.overshoot,
                  "select": inject.select, "c": inject.c, "realizations": int(ds.sizes["realization"]),
                  "geometries": group.geometries, "recovery": recover(ds, geometry, inject, N),
                  "configs": configs}
            points.append(pt)
            r = pt["recovery"]["mu_eff|10-1e3|contact"]
            print(f"{group.name} N={N}: mu_eff recovers {r['recovery']:.3f} +- {r['sem']:.3f} of the shift",
                  flush=True)
        print(f"{group.name}: {time.perf_counter() - t0:.1f} s", flush=True)
    data = {
        "question": "how much of a known rise of the thresholds does each estimator's slope recover?",
        "preset": name, "inject": {"c": INJECT_C, "t0": 1.0, "selects": list(SELECTS)},
        "windows": {w: [t, preset.steps] for w, t in WINDOWS.items()},
        "preset_settings": {"steps": preset.steps, "per_decade": preset.per_decade,
                            "groups": [dataclasses.asdict(g) for g in preset.groups]},
        "points": points, "slidernet_version": slidernet.__version__,
    }
    data["wall_time_s"] = time.perf_counter() - start
    print(write_json(data, args.out / JSON_NAME))
    with atomic_output(args.out / TABLES_NAME) as tmp:
        tmp.write_text(tables(data))
    print(args.out / TABLES_NAME)
    print(plot(data, args.out / PNG_NAME))
    print(f"done in {time.perf_counter() - start:.1f} s")
    return 0


# %%
# Running the example
# -------------------
#
# The command line: ``main`` parses the options above. The documentation's
# gallery runs this script with ``--quick`` and a temporary ``--out`` folder
# (``docs/_ext/slidernet_gallery.py``) and shows the PNG files it writes.

if __name__ == "__main__":
    status = main()
    if status:  # sphinx-gallery runs the script inside Sphinx: exit only on failure
        raise SystemExit(status)
