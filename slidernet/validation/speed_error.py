"""Speed against error: what the event-driven solver buys, measured on the same realizations.

``slidernet bench speed-error [--quick] --out DIR`` (or :func:`speed_error`)
runs, on the same theta(t_q) and the same stream of mu_s draws, every way of
computing a scene that slidernet knows of, times it, and measures its error
against the exact event-driven solution:

=================  ============================================================
method             what changes
=================  ============================================================
event-driven       the solver (pair kernel, and the general CSR kernel): exact
fixed-step         a naive theta sweep that checks stability every dtheta
                   (:mod:`slidernet.validation.fixed_step`)
dynamics           the equations of motion with inertia and Coulomb friction
                   (:mod:`slidernet.validation.dynamics`), at several tau_dyn/tau_th
dynamics, chain    the same on a chain of 4 sliders, where several sliders can
                   move at once and the quasi-static rule itself is the error
2D slip            the straight-line slip against the exactly integrated one
                   (``solver.slip``), on a triangular lattice
=================  ============================================================

Errors, at the last recorded time and averaged over realizations r:

- ``error_n`` = mean_r |n - n_exact| / n_exact,
- ``error_mu_max`` = mean_r |mu_max - mu_max_exact| / mu_max_exact,
- ``error_x_G`` = mean_r |x_G - x_G_exact| / rms_r(x_G_exact) (x_G is a random
  walk about 0, so it is measured against its ensemble spread),
- ``error`` = the largest of the three.

``seconds`` is the wall time of the method on the whole ensemble of its scene
(compiled kernels loaded beforehand), so times compare within a scene: the
pair scene (event-driven, fixed-step, dynamics), the chain scene and the 2D
scene each have their own.
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from slidernet.config import load_config
from slidernet.ensemble.progress import Progress
from slidernet.io import atomic_output, save_figure
from slidernet.solver import Scene, horizontal_draws, realization_streams, simulate

PAIR = {
    "network": {"kind": "two_slider", "Ntilde": 1e-7},
    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
}


@dataclass(frozen=True)
class Preset:
    """Sizes of the comparison (``QUICK`` fits in under 3 minutes on one core)."""

    pair_steps: int
    pair_realizations: int
    dthetas: tuple[float, ...]  # fixed-step sub-steps, in units of Ntilde
    tau_ratios: tuple[float, ...]  # tau_dyn / tau_th of the dynamics
    chain_steps: int
    chain_realizations: int
    chain_tau_ratios: tuple[float, ...]
    lattice_side: int
    lattice_steps: int
    lattice_realizations: int
    # Largest integration steps of the dynamics, in tau_dyn. Two sliders
    # never have a velocity that dips to zero and comes back within a step
    # (only one moves at a time), so their steps are left to the adaptive
    # control; in a chain such a dip would be missed at larger steps
    # (measured in tests/test_dynamics.py), hence 0.05.
    pair_max_step: float = math.inf
    chain_max_step: float = 0.05


QUICK = Preset(pair_steps=20, pair_realizations=2, dthetas=(1.0, 0.1, 0.01, 1e-3, 1e-4),
               tau_ratios=(1e-3, 1e-4, 1e-5, 1e-6), chain_steps=3, chain_realizations=1,
               chain_tau_ratios=(1e-4, 1e-6), lattice_side=5, lattice_steps=20, lattice_realizations=2)
FULL = Preset(pair_steps=50, pair_realizations=4,
              dthetas=(1.0, 0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5),
              tau_ratios=(1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7), chain_steps=10, chain_realizations=2,
              chain_tau_ratios=(1e-3, 1e-4, 1e-5, 1e-6), lattice_side=6, lattice_steps=50, lattice_realizations=4)


@dataclass(frozen=True)
class Row:
    """One line of ``speed_error.csv``."""

    method: str
    setting: str
    seconds: float
    error: float
    error_n: float
    error_mu_max: float
    error_x_G: float
    scene: str


Final = dict[str, np.ndarray]  # "n", "mu_max", "x_G" at the last recorded time, shape (R,)


def errors(final: Final, exact: Final) -> dict[str, float]:
    """The three relative errors of ``final`` against ``exact`` and their maximum.

    Examples
    --------
    >>> exact = {"n": np.array([100, 200]), "mu_max": np.array([0.6, 0.6]), "x_G": np.array([1.0, -1.0])}
    >>> e = errors({"n": np.array([110, 200]), "mu_max": np.array([0.6, 0.6]), "x_G": np.array([1.0, -1.0])},
    ...            exact)
    >>> e["error_n"], e["error"]
    (0.05, 0.05)
    """
    n0 = exact["n"].astype(float)
    e_n = float(np.mean(np.abs(final["n"] - n0) / np.maximum(n0, 1.0)))
    e_mu = float(np.mean(np.abs(final["mu_max"] - exact["mu_max"]) / exact["mu_max"]))
    spread = float(np.sqrt(np.mean(exact["x_G"] ** 2)))
    e_x = float(np.mean(np.abs(final["x_G"] - exact["x_G"]))) / spread if spread > 0 else 0.0
    return {"error": max(e_n, e_mu, e_x), "error_n": e_n, "error_mu_max": e_mu, "error_x_G": e_x}


def _scene(cfg: dict[str, Any]) -> Scene:
    return Scene.from_config(load_config(cfg))


def _final(results: list[dict[str, np.ndarray]]) -> Final:
    return {key: np.array([r[key][-1] for r in results]) for key in ("n", "mu_max", "x_G")}


def _timed(fn: Callable[[], Final]) -> tuple[Final, float]:
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def fixed_step_final(scene: Scene, seeds: list[np.random.SeedSequence], dtheta: float) -> Final:
    """Final n, mu_max and x_G of the fixed-step theta sweep on the solver's realizations.

    Parameters
    ----------
    scene : Scene
        A two-slider scene.
    seeds : list of SeedSequence
        One per realization, as given to :func:`slidernet.solver.simulate`.
    dtheta : float
        Largest sub-step of theta, in units of Ntilde.
    """
    from slidernet.validation.fixed_step import AVALANCHE_LIMIT, OUT_OF_DRAWS, sweep_pair

    out: dict[str, list[float]] = {"n": [], "mu_max": [], "x_G": []}
    rec = scene.out_steps
    for ss in seeds:
        thetas, mu0, batches = horizontal_draws(scene, realization_streams(ss))
        draws = next(batches)
        while True:
            n, mu_max, xg = (np.zeros(rec.size, np.int64), np.zeros(rec.size), np.zeros(rec.size))
            status = sweep_pair(thetas, dtheta, rec, mu0.copy(), draws, scene.mu_d, scene.max_avalanche,
                                n, mu_max, xg)
            if status != OUT_OF_DRAWS:
                break
            draws = np.concatenate([draws, next(batches)])
        if status == AVALANCHE_LIMIT:
            raise RuntimeError(f"the fixed-step sweep at dtheta = {dtheta} did not relax")
        out["n"].append(n[-1])
        out["mu_max"].append(mu_max[-1])
        out["x_G"].append(xg[-1] * scene.network.Ntilde)
    return {key: np.array(v) for key, v in out.items()}


def _solver_final(scene: Scene, seeds: list[np.random.SeedSequence]) -> Final:
    return _final([simulate(scene, ss) for ss in seeds])


def _dynamics_final(scene: Scene, seeds: list[np.random.SeedSequence], tau_ratio: float,
                    max_step: float) -> Final:
    from slidernet.validation.dynamics import Dynamics

    dyn = Dynamics(scene, tau_ratio=tau_ratio, max_step=max_step)
    return _final([dyn.run(ss) for ss in seeds])


def _warm_up() -> None:
    """Load every compiled kernel once, so that no timing includes numba's cache loading."""
    from slidernet.validation.fixed_step import sweep_pair

    tiny = _scene({**PAIR, "steps": 2, "record": [0, 2]})
    ss = [np.random.SeedSequence(0)]
    _solver_final(tiny, ss)
    fixed_step_final(tiny, ss, 1.0)
    for kernel in ("csr",):
        _solver_final(_scene({**PAIR, "steps": 2, "record": [0, 2], "solver": {"kernel": kernel}}), ss)
    for slip in ("straight", "exact"):
        _solver_final(_scene(_lattice_cfg(3, 2, slip)), ss)
    del sweep_pair


def _lattice_cfg(side: int, steps: int, slip: str) -> dict[str, Any]:
    return {"network": {"kind": "triangular", "shape": [side, side], "Ntilde": 1e-7},
            "friction": PAIR["friction"], "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7},
            "steps": steps, "record": [0, steps], "solver": {"slip": slip}}


def _chain_cfg(steps: int) -> dict[str, Any]:
    return {**PAIR, "network": {"kind": "chain", "n": 4, "Ntilde": 1e-7},
            "driver": {"name": "gaussian_steps", "sigma_theta": 3e-7}, "steps": steps, "record": [0, steps],
            "solver": {"kernel": "csr"}}


def _step_label(max_step: float) -> str:
    return ", adaptive steps" if math.isinf(max_step) else f", steps <= {max_step:g} tau_dyn"


def rows(preset: Preset, progress: bool | float | None = None) -> list[Row]:
    """Run every method of the comparison and return one :class:`Row` per (method, setting)."""
    jobs: list[tuple[str, str, str, Callable[[], Final]]] = []
    pair_cfg = {**PAIR, "steps": preset.pair_steps, "record": [0, preset.pair_steps]}
    pair = _scene(pair_cfg)
    pair_csr = _scene({**pair_cfg, "solver": {"kernel": "csr"}})
    pair_seeds = np.random.SeedSequence(1).spawn(preset.pair_realizations)
    scene_pair = f"two sliders, sigma_theta/Ntilde = 10, {preset.pair_steps} tau_th x {preset.pair_realizations}"
    jobs.append(("event-driven", "pair kernel", scene_pair, lambda: _solver_final(pair, pair_seeds)))
    jobs.append(("event-driven", "csr kernel", scene_pair, lambda: _solver_final(pair_csr, pair_seeds)))
    for d in preset.dthetas:
        jobs.append(("fixed-step", f"dtheta = {d:g} Ntilde", scene_pair,
                     lambda d=d: fixed_step_final(pair, pair_seeds, d)))
    for eps in preset.tau_ratios:
        jobs.append(("dynamics", f"tau_dyn/tau_th = {eps:g}{_step_label(preset.pair_max_step)}", scene_pair,
                     lambda eps=eps: _dynamics_final(pair, pair_seeds, eps, preset.pair_max_step)))

    chain = _scene(_chain_cfg(preset.chain_steps))
    chain_seeds = np.random.SeedSequence(2).spawn(preset.chain_realizations)
    scene_chain = f"chain of 4, sigma_theta/Ntilde = 3, {preset.chain_steps} tau_th x {preset.chain_realizations}"
    jobs.append(("event-driven, chain", "csr kernel", scene_chain, lambda: _solver_final(chain, chain_seeds)))
    for eps in preset.chain_tau_ratios:
        jobs.append(("dynamics, chain", f"tau_dyn/tau_th = {eps:g}{_step_label(preset.chain_max_step)}",
                     scene_chain, lambda eps=eps: _dynamics_final(chain, chain_seeds, eps, preset.chain_max_step)))

    side, lsteps = preset.lattice_side, preset.lattice_steps
    exact2d = _scene(_lattice_cfg(side, lsteps, "exact"))
    straight2d = _scene(_lattice_cfg(side, lsteps, "straight"))
    lat_seeds = np.random.SeedSequence(3).spawn(preset.lattice_realizations)
    scene_2d = (f"triangular {side}x{side}, sigma_theta/Ntilde = 1, {lsteps} tau_th x "
                f"{preset.lattice_realizations}")
    jobs.append(("2D slip", "exact", scene_2d, lambda: _solver_final(exact2d, lat_seeds)))
    jobs.append(("2D slip", "straight line", scene_2d, lambda: _solver_final(straight2d, lat_seeds)))

    _warm_up()
    reference: dict[str, Final] = {}
    out = []
    with Progress(len(jobs), progress, "speed-error runs") as bar:
        for method, setting, scene_name, fn in jobs:
            bar.set_postfix_str(f"{method} {setting}")
            final, seconds = _timed(fn)
            if method.startswith("event-driven") or (method == "2D slip" and setting == "exact"):
                reference.setdefault(scene_name, final)
            out.append(Row(method, setting, seconds, **errors(final, reference[scene_name]), scene=scene_name))
            bar.update(1)
    return out


def write_csv(table: list[Row], path: str | Path) -> Path:
    """Write the rows to ``path`` atomically: columns method, setting, seconds, error, then the details."""
    names = [f.name for f in fields(Row)]
    with atomic_output(path) as tmp, open(tmp, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=names)
        writer.writeheader()
        for row in table:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in asdict(row).items()})
    return Path(path)


def plot(table: list[Row], path: str | Path) -> Path:
    """Error against seconds, log-log, one line per method, its settings in the order run.

    Exact methods (error 0) are drawn as markers on a floor one decade below
    the smallest error measured, labelled "exact".
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    nonzero = [r.error for r in table if r.error > 0]
    floor = 10.0 ** (math.floor(math.log10(min(nonzero))) - 1) if nonzero else 1e-16
    markers = "osD^v<>p"
    for j, method in enumerate(dict.fromkeys(r.method for r in table)):
        sel = [r for r in table if r.method == method]
        approx = [r for r in sel if r.error > 0]
        exact = [r for r in sel if r.error == 0]
        style = {"marker": markers[j % len(markers)], "color": f"C{j}"}
        if approx:
            ax.loglog([r.seconds for r in approx], [r.error for r in approx], label=method, **style)
        if exact:
            ax.loglog([r.seconds for r in exact], [floor] * len(exact), ls="none", mfc="none",
                      label=None if approx else method, **style)
    ax.axhline(floor, color="0.6", lw=0.8, ls=":")
    ax.annotate("exact (error 0)", (0.01, floor), xycoords=("axes fraction", "data"), xytext=(0, 4),
                textcoords="offset points", fontsize=8, color="0.4")
    ax.set_xlabel("wall time on its scene [s]")
    ax.set_ylabel("relative error at the end (largest of n, mu_max, x_G)")
    ax.set_title("speed against error, on the same realizations")
    ax.legend(fontsize=8)
    return save_figure(fig, path, dpi=120)


def speed_error(out_dir: str | Path, quick: bool = False, progress: bool | float | None = None) -> dict[str, Path]:
    """Run the comparison and write ``speed_error.csv`` and ``speed_error.png`` into ``out_dir``.

    Parameters
    ----------
    out_dir : path
        Output directory (created if needed).
    quick : bool
        The small preset (under 3 minutes) instead of the full one.
    progress : bool, float or None
        Progress over the runs, as in :func:`slidernet.run` (True or None:
        a bar on a terminal, a line every 30 s elsewhere).

    Returns
    -------
    dict of str to Path
        ``csv`` and ``png``.
    """
    out_dir = Path(out_dir)
    table = rows(QUICK if quick else FULL, progress=progress)
    return {"csv": write_csv(table, out_dir / "speed_error.csv"), "png": plot(table, out_dir / "speed_error.png")}
