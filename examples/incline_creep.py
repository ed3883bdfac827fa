"""Thermal creep on an incline: reptation, its plateaus, the critical amplitude and intermittency
==============================================================================================

Chains of sliders rest on an incline (``network.incline``, downhill along
+x) and the springs dilate with a sinusoidal temperature cycle (driver
``sinusoidal``, period 20 tau_th). Each cycle pushes the downhill end forward
on expansion and pulls the uphill end forward on contraction: the chain
reptates downhill (Blanc, Pugnaloni & Géminard, Phys. Rev. E 84, 061303,
2011). Four panels, each from the runs named in its title:

(a) the reptation velocity (x_G per cycle, in units of D Ntilde l0 =
    2 (mu_s - mu_d) Ntilde l0, the length of one slip of an end slider: not a
    count of slips) against tan(incline) for chains of 2, 3, 4 and 8
    with constant thresholds (``constant``), with the exact orbit of each
    chain (:func:`slidernet.analysis.theory.chain_creep_segments`): a
    staircase for two sliders, straight segments whose slopes change sign
    for three and more;
(b) the velocity against the amplitude of theta at tan(incline) = 0.22, with
    constant thresholds (the exact staircases and critical amplitudes of
    chains of 2 and 3,
    :func:`~slidernet.analysis.theory.chain_critical_amplitude`) and with
    Gaussian thresholds, where creep goes on below them, irregularly;
(c) an irregular (Delaunay) network with Gaussian thresholds just above the
    amplitude where its creep stops, and further up: the waiting times
    between creep events (the ``creep`` observable: avalanches that advance
    x_G by more than half the advance of one slip of one node), tested
    against an exponential law (Kolmogorov-Smirnov with the fitted mean
    accounted for, seed stated);
(d) the same velocity against amplitude for a 2D irregular (Delaunay)
    network on the incline.

Writes ``incline_creep.png`` and ``incline_creep.json`` (every plotted
number, with the configuration it came from) into ``--out``::

    python examples/incline_creep.py --out creep_out           # about a minute
    python examples/incline_creep.py --out creep_out --quick   # seconds

Units: time in tau_th, x_G in l0, theta dimensionless, Ntilde = N / (k l0).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from scipy import stats

import slidernet
from slidernet.analysis import theory
from slidernet.io import atomic_output, save_figure

MU_S = 0.6            # the constant threshold (and the Gaussian's mean)
MU_D = 0.5
SIGMA_MU = 0.01       # the Gaussian thresholds' spread
NTILDE = 1e-7
PERIOD = 20           # tau_th per temperature cycle: a multiple of 4, the sampled sine reaches +-A
SLIP = 2 * (MU_S - MU_D) * NTILDE  # one slip of an end slider, in l0
# tan(incline) of panel (b): inside a segment of the chain of 3's exact orbit. At 0.2 two events tie
# for every amplitude (f = D), and the solver's rounding decides the orbit.
TAN_B = 0.22
TAN_NET = 0.2         # tan(incline) of panels (c) and (d), the irregular network
# (A / Ntilde, share of the preset's wait_cycles) of panel (c): near where the network stops creeping, and above
# (where events are frequent, fewer cycles keep the event catalogue below solver.max_events).
WAIT_RUNS = ((0.06, 1.0), (0.13, 0.2))
PNG_NAME = "incline_creep.png"
JSON_NAME = "incline_creep.json"


@dataclasses.dataclass(frozen=True)
class Preset:
    """Sizes of the runs.

    Attributes
    ----------
    cycles : int
        Temperature cycles per run; the velocity is measured over the second half.
    angles : int
        Values of tan(incline) in panel (a).
    amplitudes : int
        Values of A / Ntilde in panels (b) and (d).
    realizations : int
        Realizations of the Gaussian runs.
    wait_cycles : int
        Cycles of the waiting-time run of panel (c).
    nodes : int
        Nodes of the irregular network of panel (d).
    """

    cycles: int
    angles: int
    amplitudes: int
    realizations: int
    wait_cycles: int
    nodes: int


PRESETS = {
    "full": Preset(cycles=40, angles=49, amplitudes=25, realizations=8, wait_cycles=100_000, nodes=100),
    "quick": Preset(cycles=16, angles=13, amplitudes=9, realizations=3, wait_cycles=20_000, nodes=36),
}


def make_config(network: dict[str, Any], angle: float, amplitude: float, cycles: int, *, gaussian: bool,
                realizations: int = 1, seed: int = 1) -> dict[str, Any]:
    """A run on the incline: ``angle`` in degrees, theta's amplitude ``amplitude`` (dimensionless)."""
    steps = PERIOD * cycles
    static = ({"name": "gaussian", "mean": MU_S, "std": SIGMA_MU} if gaussian
              else {"name": "constant", "value": MU_S})
    return {
        "seed": seed, "realizations": realizations, "steps": steps,
        "record": list(range(0, steps + 1, PERIOD)), "observables": ["n", "x_G", "creep"],
        "creep": {"transient": PERIOD * (cycles // 2)},
        "network": {**network, "Ntilde": NTILDE, "incline": float(angle)},
        "friction": {"mu_d": MU_D, "static": static},
        "driver": {"name": "sinusoidal", "amplitude": float(amplitude), "period": PERIOD},
    }


def velocity(ds: Any) -> tuple[float, float]:
    """x_G per cycle over the second half of the run, in units of SLIP: the mean over realizations and its s.e.

    The ``creep`` observable's ``v_creep_cycle``, summed slip by slip from the event catalogue over
    the whole cycles after the transient (half the run).
    """
    v = ds["v_creep_cycle"].values / SLIP
    sem = float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else 0.0
    return float(v.mean()), sem


def _degrees(tan_alpha: float) -> float:
    return math.degrees(math.atan(tan_alpha))


def _segments(n: int, **range_and_value: Any) -> list[dict[str, float]]:
    """The exact orbit's segments: ends in tan(alpha) or in A / Ntilde, x_G per cycle in units of SLIP."""
    segs = theory.chain_creep_segments(n, NTILDE, MU_S, MU_D, **range_and_value)
    unit = NTILDE if isinstance(range_and_value.get("amplitude"), tuple) else 1.0
    return [{"lo": s.lo / unit, "hi": s.hi / unit, "v_lo": s.dx_lo / SLIP, "v_hi": s.dx_hi / SLIP,
             "slips": s.slips, "period": s.period} for s in segs]


def panel_a(p: Preset) -> dict[str, Any]:
    # The grid is offset by 0.001 from round values: the segments of the exact orbit end at round
    # values (0.05, 0.2, 0.275, ...), where two events tie and rounding decides.
    tans = np.linspace(0.011, 0.491, p.angles)
    A = 0.55
    out: dict[str, Any] = {"A_over_Ntilde": A, "tan_alpha": tans.tolist(), "v": {}, "theory": {},
                           "theory_at_points": {}}
    for n in (2, 3, 4, 8):
        out["v"][str(n)] = [velocity(slidernet.run(make_config({"kind": "chain", "n": n}, _degrees(t),
                                                               A * NTILDE, p.cycles, gaussian=False),
                                                   progress=False))[0] for t in tans]
        out["theory"][str(n)] = _segments(n, tan_alpha=(0.01, 0.49), amplitude=A * NTILDE)
        out["theory_at_points"][str(n)] = (theory.chain_creep(n, A * NTILDE, NTILDE, tans, MU_S, MU_D)[1]
                                           / SLIP).tolist()
    return out


def _amplitude_sweep(network: dict[str, Any], p: Preset, amps: np.ndarray, gaussian: bool, seed: int,
                     tan_alpha: float) -> tuple[list[float], list[float]]:
    vs, es = [], []
    for k, a in enumerate(amps):
        cfg = make_config(network, _degrees(tan_alpha), a * NTILDE, p.cycles, gaussian=gaussian,
                          realizations=p.realizations if gaussian else 1, seed=seed + k)
        v, e = velocity(slidernet.run(cfg, progress=False))
        vs.append(v)
        es.append(e)
    return vs, es


def panel_b(p: Preset) -> dict[str, Any]:
    amps = np.linspace(0.2, 0.7, p.amplitudes)
    _, any_state = theory.pair_critical_amplitude(NTILDE, TAN_B, MU_S, MU_D)
    out: dict[str, Any] = {"A_over_Ntilde": amps.tolist(), "A_c_any_state_2": any_state / NTILDE, "runs": {},
                           "A_c": {}, "theory": {}}
    for n in (2, 3):
        for gaussian in (False, True):
            key = f"{n}-{'gaussian' if gaussian else 'constant'}"
            v, e = _amplitude_sweep({"kind": "chain", "n": n}, p, amps, gaussian, seed=100 * n, tan_alpha=TAN_B)
            out["runs"][key] = {"v": v, "sem": e}
        out["A_c"][str(n)] = theory.chain_critical_amplitude(n, NTILDE, TAN_B, MU_S, MU_D,
                                                             amplitude_max=amps[-1] * NTILDE) / NTILDE
        out["theory"][str(n)] = _segments(n, tan_alpha=TAN_B, amplitude=(amps[0] * NTILDE, amps[-1] * NTILDE))
    return out


def panel_c(p: Preset, seed: int = 8) -> dict[str, Any]:
    """Creep events of an irregular network with Gaussian thresholds, near where its creep stops, and above.

    The events and their waiting times are the ``creep`` observable's
    (``creep_waiting_time``): avalanches that advance x_G by more than half
    the advance of one slip of one node (``event_fraction`` = 0.5 / nodes).
    The waits (tau_th) are tested against an exponential law of the same
    mean with a Kolmogorov-Smirnov test whose p-value accounts for the
    fitted mean (``scipy.stats.goodness_of_fit``, Monte Carlo, seeded).
    """
    out: dict[str, Any] = {"nodes": p.nodes, "seed": seed, "runs": {}}
    for A, share in WAIT_RUNS:
        cycles = int(share * p.wait_cycles)
        net = {"kind": "irregular", "n": p.nodes, "seed": 3}
        cfg = make_config(net, _degrees(TAN_NET), A * NTILDE, cycles, gaussian=True, seed=seed)
        cfg["observables"] = ["n", "x_G", "creep"]
        cfg["creep"] = {"event_fraction": 0.5 / p.nodes}
        ds = slidernet.run(cfg, progress=False)
        waits = ds["creep_waiting_time"].values[0]
        waits = waits[np.isfinite(waits)]
        run: dict[str, Any] = {"cycles": cycles, "events": int(ds["creep_event_count"].values[0]),
                               "waits": waits.tolist(),
                               "mean_wait": float(waits.mean()) if waits.size else float("nan"),
                               "ks_statistic": float("nan"), "ks_pvalue": float("nan")}
        if waits.size > 5:
            gof = stats.goodness_of_fit(stats.expon, waits, known_params={"loc": 0.0}, statistic="ks",
                                        n_mc_samples=2000, rng=np.random.default_rng(seed))
            run["ks_statistic"], run["ks_pvalue"] = float(gof.statistic), float(gof.pvalue)
        out["runs"][f"{A:g}"] = run
    return out


def panel_d(p: Preset) -> dict[str, Any]:
    amps = np.linspace(0.02, 0.7, p.amplitudes)
    net = {"kind": "irregular", "n": p.nodes, "seed": 3}
    v, e = _amplitude_sweep(net, p, amps, gaussian=True, seed=900, tan_alpha=TAN_NET)
    return {"A_over_Ntilde": amps.tolist(), "nodes": p.nodes, "v": v, "sem": e}


def _plot_segments(axis: Any, segments: list[dict[str, float]], colour: str, label: str | None) -> None:
    """One straight line per segment, broken where the orbit changes."""
    xs: list[float] = []
    ys: list[float] = []
    for seg in segments:
        xs += [seg["lo"], seg["hi"], math.nan]
        ys += [seg["v_lo"], seg["v_hi"], math.nan]
    axis.plot(xs, ys, "-", color=colour, lw=1, label=label)


def plot(data: dict[str, Any], path: Path) -> Path:
    fig = Figure(figsize=(12, 9), layout="constrained")
    FigureCanvasAgg(fig)
    (ax, bx), (cx, dx) = fig.subplots(2, 2)
    a = data["a"]
    for n, c in zip(("2", "3", "4", "8"), ("C0", "C1", "C2", "C3"), strict=True):
        ax.plot(a["tan_alpha"], a["v"][n], "o", ms=4, mfc="none", color=c, label=f"chain of {n}")
    for n, c in zip(("2", "3", "4", "8"), ("C0", "C1", "C2", "C3"), strict=True):
        _plot_segments(ax, a["theory"][n], c, label="exact orbit (chain_creep_segments)" if n == "2" else None)
    ax.set_xlabel(r"$\tan\alpha$ (downhill load per unit normal load)")
    ax.set_ylabel(r"$x_G$ per cycle, in units of $D\tilde N l_0$")
    ax.set_title(rf"(a) constant $\mu_s = {MU_S}$, $\mu_d = {MU_D}$, $A = {a['A_over_Ntilde']}\,\tilde N$",
                 fontsize=10)
    ax.legend(fontsize=8)
    b = data["b"]
    styles = {"2-constant": ("C0", "o"), "3-constant": ("C1", "o"), "2-gaussian": ("C0", "s"),
              "3-gaussian": ("C1", "s")}
    for key, run in b["runs"].items():
        c, m = styles[key]
        bx.errorbar(b["A_over_Ntilde"], run["v"], yerr=run["sem"], fmt=m, ms=4, mfc="none", color=c,
                    capsize=2, label=key.replace("-", " sliders, ").replace("gaussian",
                                                                           rf"Gaussian $\sigma_\mu={SIGMA_MU}$"))
    for n, c in (("2", "C0"), ("3", "C1")):
        _plot_segments(bx, b["theory"][n], c, label=f"exact orbit, {n} sliders")
        bx.axvline(b["A_c"][n], color=c, ls="--", lw=1, label=rf"$A_c$ from rest, {n} sliders")
    bx.axvline(b["A_c_any_state_2"], color="0.4", ls=":", lw=1,
               label=r"$(\mu_d - \tan\alpha)\tilde N$ (2 sliders, any state)")
    bx.set_xlabel(r"$A/\tilde N$ (amplitude of $\theta$)")
    bx.set_ylabel(r"$x_G$ per cycle, in units of $D\tilde N l_0$")
    bx.set_title(rf"(b) $\tan\alpha = {TAN_B}$", fontsize=10)
    bx.legend(fontsize=7)
    c = data["c"]
    for (A, run), colour in zip(c["runs"].items(), ("C4", "C5"), strict=False):
        waits = np.sort(np.asarray(run["waits"]))
        if not waits.size:
            continue
        surv = 1.0 - np.arange(waits.size) / waits.size
        cx.semilogy(waits, surv, ".", ms=3, color=colour,
                    label=rf"$A = {A}\,\tilde N$: {run['events']} events, KS p = {run['ks_pvalue']:.2g}")
        cx.semilogy(waits, np.exp(-waits / run["mean_wait"]), "-", color=colour, lw=1)
    cx.set_ylim(1e-3, 1.5)
    cx.set_xscale("log")
    cx.set_xlabel(r"waiting time between creep events ($\tau_\mathrm{th}$)")
    cx.set_ylabel("P(wait > w); lines: exponential of the same mean")
    cx.set_title(rf"(c) irregular network, {c['nodes']} nodes, Gaussian, $\tan\alpha = {TAN_NET}$ "
                 f"(seed {c['seed']})", fontsize=10)
    cx.legend(fontsize=8)
    d = data["d"]
    dx.errorbar(d["A_over_Ntilde"], d["v"], yerr=d["sem"], fmt="s", ms=4, mfc="none", color="C4", capsize=2)
    dx.set_xlabel(r"$A/\tilde N$")
    dx.set_ylabel(r"$x_G$ per cycle, in units of $D\tilde N l_0$")
    dx.set_title(rf"(d) irregular network, {d['nodes']} nodes, Gaussian, $\tan\alpha = {TAN_NET}$", fontsize=10)
    for axis in (ax, bx, dx):
        axis.grid(alpha=0.3)
    return save_figure(fig, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="folder for the figure and its data")
    parser.add_argument("--quick", action="store_true", help="short runs (seconds)")
    args = parser.parse_args(argv)
    preset = PRESETS["quick" if args.quick else "full"]
    start = time.perf_counter()
    data = {"preset": dataclasses.asdict(preset), "a": panel_a(preset), "b": panel_b(preset),
            "c": panel_c(preset), "d": panel_d(preset)}
    args.out.mkdir(parents=True, exist_ok=True)
    with atomic_output(args.out / JSON_NAME) as tmp:
        tmp.write_text(json.dumps(data, indent=1))
    print(args.out / JSON_NAME)
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
