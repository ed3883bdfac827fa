"""Readings of the appendix's virtual tilt test, side by side.

The appendix of Géminard & Bertin (2010) copies "the values of mu_s,1, mu_s,2
and of the force F_1->2" before each rearrangement and tilts the copy until
the pair slides. Two choices of that text change what the test measures, and
this module runs the paper's two sliders once per reading, on the same
horizontal evolution (the same seeds), so that they can be compared:

``"threshold"`` (slidernet's reading, :mod:`slidernet.kernels.tilt`)
    The state is copied at theta_c, just before the rearrangement: the
    weakest slider is exactly at its threshold, |F| = mu_min.
``"after"``
    The state is copied just after the rearrangement: F has dropped by
    2 (mu_min - mu_d) and the slipped slider holds its new threshold.
``"incline"``
    The copy at theta_c, on an exact incline: the normal load is
    N = m g cos(alpha) and the tangential one m g sin(alpha), while the
    spring force keeps its value in absolute units (m g, the normal load
    on the flat). At a given alpha the appendix's rules hold with every
    force divided by N, that is with f/N = tan(alpha) and F/N = F / cos(alpha):
    the spring force weighs more as the substrate tilts. Slider 1 starts at
    sin(alpha) - mu_s,1 cos(alpha) = F, slider 2 at
    sin(alpha) - mu_s,2 cos(alpha) = -F, whose roots are
    alpha_i = arctan(mu_s,i) -/+ arcsin(F / sqrt(1 + mu_s,i^2)).
``"incline_after"``
    Both changes at once.

The horizontal evolution is an independent, plain transcription of the
solver's rules for two sliders (eq. `critique`, eq. `displacement`, the
avalanche rule of docs/model.md): it reads the same random streams in the
same order as :class:`slidernet.solver.Realization`, so that its
``"threshold"`` reading reproduces ``slidernet.run``'s ``mu_eff``
(``tests/test_tilt_readings.py`` checks it). The tilt test of the first
two readings is the solver's own, :func:`slidernet.kernels.tilt.tilt_test_pair`.

Units are the kernels': theta and u in Ntilde, forces in N (the normal load
on the flat).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from slidernet.analysis.trend import log_trend
from slidernet.config import load_config
from slidernet.ensemble.runner import realization_seeds
from slidernet.errors import TiltTestError, param_error
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.state import DONE, NEED_MU, TILT_MAX_ITER
from slidernet.kernels.tilt import record_tilt, tilt_iterations, tilt_test_pair
from slidernet.solver import Realization, Scene

READINGS = ("threshold", "after", "incline", "incline_after")
_AFTER = {"threshold": False, "after": True, "incline": False, "incline_after": True}
_INCLINE = {"threshold": False, "after": False, "incline": True, "incline_after": True}
LN10 = math.log(10.0)
# The readings are those of the paper's appendix: its slip, 2 (mu_i - mu_d) (friction.overshoot = 1).
PAPER_SLIP = 2.0


@kernel_jit(forceinline=True)
def incline_onset(F, mu1, mu2):
    """The slider that starts first on an exact incline: (i, tan(alpha_i), cos(alpha_i)).

    Slider 1 starts at sin(alpha) - mu1 cos(alpha) = F, slider 2 at
    sin(alpha) - mu2 cos(alpha) = -F (ties: slider 1), F in units of the
    normal load on the flat.
    """
    a1 = math.atan(mu1) + math.asin(F / math.sqrt(1.0 + mu1 * mu1))
    a2 = math.atan(mu2) - math.asin(F / math.sqrt(1.0 + mu2 * mu2))
    if a1 <= a2:
        return 1, math.tan(a1), math.cos(a1)
    return 2, math.tan(a2), math.cos(a2)


@kernel_jit()
def tilt_test_incline(st, draws, F, mu1, mu2, mu_d):
    """The appendix's tilt test on an exact incline: tan(alpha_c), the tilt at which the pair slides.

    The iteration is the solver's (:func:`slidernet.kernels.tilt.tilt_iterations`)
    with the onset of :func:`incline_onset`: at the tilt alpha where a slider
    starts, the appendix's rules act on the forces per unit normal load,
    f / N = tan(alpha) and F / N = F / cos(alpha).

    Parameters
    ----------
    st : record of dtype STATE
        Its ``tilt_mu_pos`` and ``tilt_u_pos`` are the read positions in
        ``draws.tilt_mu`` and ``draws.tilt_u``; they advance only if the test
        ends.
    draws : Draws
        The redrawn thresholds and the uniforms of the creep branch.
    F : float
        The spring force on slider 2 in units of the normal load on the flat
        (m g); it keeps its absolute value as the substrate tilts.
    mu1, mu2 : float
        The thresholds.
    mu_d : float
        The dynamic coefficient.

    Returns
    -------
    float
        tan(alpha_c); -1.0 if the draw buffers ran out, -2.0 after
        ``TILT_MAX_ITER`` iterations.
    """
    return tilt_iterations(st, draws, F, mu1, mu2, mu_d, PAPER_SLIP, incline_onset)


@kernel_jit()
def _test(st, draws, F, mu1, mu2, mu_d, incline):
    if incline:
        return tilt_test_incline(st, draws, F, mu1, mu2, mu_d)
    return tilt_test_pair(st, draws, F, mu1, mu2, mu_d, PAPER_SLIP)


@kernel_jit()
def _sample(st, draws, F, mu1, mu2, mu_d, incline, k, out):
    """One test, its sample added to bin k of ``out``; returns a kernel status."""
    return record_tilt(_test(st, draws, F, mu1, mu2, mu_d, incline), out, k)


@kernel_jit()
def run_readings(thetas, bins, mu, state, draws, mu_d, after, incline, out):
    """Two sliders through ``thetas``, one tilt test per rearrangement (and one at t = 0).

    Parameters
    ----------
    thetas : ndarray, shape (steps + 1,)
        theta(t_q) / Ntilde.
    bins : ndarray of int64, shape (steps,)
        The output bin of the tests made during step q (theta from t_q to t_q+1);
        the test at t = 0 goes to bin 0.
    mu : ndarray, shape (2,)
        (mu_s,1, mu_s,2), updated in place.
    state : ndarray of dtype STATE, shape (1,)
        q, u, theta, started, pending, n_slips and the read positions.
    draws : Draws
        Thresholds, one per slip, and the tilt test's draws.
    mu_d : float
        The dynamic coefficient.
    after : bool
        Test the state just after each rearrangement instead of just before.
    incline : bool
        Use :func:`tilt_test_incline` instead of the appendix's linear test.
    out : Series
        ``out.f_sum``, ``f_sq``, ``f_count`` (shape (T,)): per bin, the sum of
        the samples, of their squares, and their number.

    Returns
    -------
    int
        A kernel status: ``DONE`` at the end of ``thetas``; ``NEED_MU`` or
        ``NEED_TILT`` when the thresholds or the tilt draws ran out (refill and
        call again: nothing was lost); ``TILT_LIMIT`` if a test did not end.
    """
    st = state[0]
    steps = thetas.size - 1
    if st.started == 0:
        code = _sample(st, draws, st.theta - st.u, mu[0], mu[1], mu_d, incline, 0, out)
        if code != DONE:
            return code
        st.started = 1
    while True:
        if st.pending:
            # An avalanche at fixed theta: the most overloaded slider slips (ties: lowest index).
            F = st.theta - st.u
            aF = abs(F)
            un0 = aF > mu[0]
            un1 = aF > mu[1]
            if un1 and (not un0 or aF / mu[1] > aF / mu[0]):
                i = 1
            elif un0:
                i = 0
            else:
                st.pending = 0
                continue
            du = 2.0 * (aF - mu_d) * (1.0 if F > 0.0 else -1.0)
            u_new = st.u + du if i == 1 else st.u - du
            theta_now = st.theta
            k = bins[st.q] if st.q < steps else bins[steps - 1]
        else:
            if st.q >= steps:
                return DONE
            a = thetas[st.q]
            b = thetas[st.q + 1]
            s = 1.0 if b > a else (-1.0 if b < a else 0.0)
            # The weakest slider yields when s (theta - u) reaches its threshold (eq. `critique`);
            # ties of the rounded theta_c go to the lowest index.
            i = 1 if mu[1] < mu[0] else 0
            tc = st.u + s * mu[i]
            if i == 1 and st.u + s * mu[0] == tc:
                i = 0
            if s * tc < s * st.theta:
                tc = st.theta  # rounding: already at the threshold
            if s == 0.0 or s * b < s * tc:
                st.q += 1
                st.theta = b
                continue
            F = tc - st.u
            du = 2.0 * (mu[i] - mu_d) * s
            u_new = st.u + du
            theta_now = tc
            k = bins[st.q]
        if st.mu_pos >= draws.mu.size:
            return NEED_MU
        new = draws.mu[st.mu_pos]
        if after:
            m0 = new if i == 0 else mu[0]
            m1 = new if i == 1 else mu[1]
            code = _sample(st, draws, theta_now - u_new, m0, m1, mu_d, incline, k, out)
        else:
            code = _sample(st, draws, F, mu[0], mu[1], mu_d, incline, k, out)
        if code != DONE:
            return code
        st.theta = theta_now
        st.u = u_new
        mu[i] = new
        st.mu_pos += 1
        st.n_slips += 1
        aF = abs(st.theta - st.u)
        st.pending = 1 if (aF > mu[0] or aF > mu[1]) else 0


def _bins(out_steps: np.ndarray, steps: int) -> np.ndarray:
    """Bin of the tests made during step q: the first recorded time at or after t_q+1."""
    return np.searchsorted(out_steps, np.arange(1, steps + 1), side="left").astype(np.int64)


def realization_readings(scene: Scene, seed_seq: np.random.SeedSequence, reading: str) -> dict[str, np.ndarray]:
    """One realization of the two sliders with one reading of the tilt test.

    The streams, draw buffers, initial state and output bins are those of
    :class:`slidernet.solver.Realization` with this seed; only the loop that
    advances them is this module's.

    Parameters
    ----------
    scene : Scene
        A two-slider scene with the tilt test (its driver, thresholds, mu_d
        and recorded times).
    seed_seq : numpy.random.SeedSequence
        The realization's seed: the same streams as ``slidernet.run``'s
        realization with this seed.
    reading : str
        One of :data:`READINGS`.

    Returns
    -------
    dict of str to ndarray
        ``f_sum``, ``f_sq``, ``f_count`` per recorded time (shape (T,)) and
        ``n``, the number of rearrangements at the end (shape ()).
    """
    if reading not in READINGS:
        raise param_error("reading", "realization_readings", f"one of {READINGS}", reading)
    real = Realization(scene, seed_seq)
    bins = _bins(scene.out_steps, scene.steps)
    while True:
        status = run_readings(real.thetas, bins, real.mu, real.state, real.buffers, float(scene.mu_d),
                              _AFTER[reading], _INCLINE[reading], real.series)
        if status == DONE:
            break
        if not real.refill(status):
            raise TiltTestError(f"A tilt test ({reading!r}) did not end within {TILT_MAX_ITER} iterations.")
    return {name: real.out[name] for name in ("f_sum", "f_sq", "f_count")} | {
        "n": np.int64(real.state["n_slips"][0])}


def readings(config: dict[str, Any], which: Sequence[str] = READINGS) -> xr.Dataset:
    """mu_eff(t) of a two-slider configuration under each reading of the tilt test.

    Parameters
    ----------
    config : dict
        A configuration of the paper's two sliders (as for ``slidernet.run``);
        its seed and realizations give the runs (realization r gets the r-th
        child of ``SeedSequence(seed)``, as in ``slidernet.run``).
    which : sequence of str
        The readings, from :data:`READINGS`.

    Returns
    -------
    xarray.Dataset
        Over (reading, t): ``mu_eff`` (the samples of the bin pooled over
        realizations, as ``slidernet.run``'s), ``mu_eff_sem`` (the standard
        error of the realizations' bin means, the honest spread), ``count``;
        over (reading, realization, t): ``mu_eff_realization``, each
        realization's own mean of its tests in the bin (NaN where it made
        none), from which trends get their errors
        (:func:`slidernet.analysis.trend.log_trend`); ``r_mean``, the measured
        rearrangements per tau_th (the first reading's n at the end over the
        duration, averaged over realizations).

    Examples
    --------
    >>> cfg = {"seed": 1, "realizations": 2, "steps": 50, "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.02}},
    ...        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}
    >>> ds = readings(cfg, ["threshold", "incline"])
    >>> ds["mu_eff"].dims, bool((ds["mu_eff"] > 0.5).all())
    (('reading', 't'), True)
    """
    bad = [w for w in which if w not in READINGS]
    if bad or not which:
        raise param_error("which", "readings", f"a non-empty list from {READINGS}", list(which))
    cfg = dict(config)
    cfg["observables"] = sorted(set(cfg.get("observables", ["n", "mu_max"])) | {"mu_eff"})
    model = load_config(cfg)
    scene = Scene.from_config(model)
    if model.network.kind != "two_slider":
        raise param_error("network.kind", "readings", "'two_slider'", cfg.get("network", {}).get("kind"))
    seeds = realization_seeds(model.seed, model.realizations)
    T = scene.out_steps.size
    mu_eff = np.full((len(which), T), np.nan)
    sem = np.full((len(which), T), np.nan)
    count = np.zeros((len(which), T), np.int64)
    # Each realization's own bin means: the time bins of one trajectory are correlated, so a trend's
    # error must come from per-realization values (independent), not from the pooled bins.
    per_real = np.full((len(which), len(seeds), T), np.nan)
    for w, reading in enumerate(which):
        runs = [realization_readings(scene, s, reading) for s in seeds]
        tot = sum(r["f_sum"] for r in runs)
        cnt = sum(r["f_count"] for r in runs)
        with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # bins with fewer than 2 realizations: NaN
            mu_eff[w] = tot / cnt
            means = np.array([r["f_sum"] / r["f_count"] for r in runs])  # NaN where a realization had no test
            sem[w] = np.nanstd(means, axis=0, ddof=1) / np.sqrt(np.isfinite(means).sum(axis=0))
        per_real[w] = means
        count[w] = cnt
        if w == 0:  # the horizontal evolution is the same under every reading
            n_end = np.array([float(r["n"]) for r in runs])
    t = scene.out_steps.astype(float)
    ds = xr.Dataset(
        {"mu_eff": (("reading", "t"), mu_eff, {"long_name": "tan(alpha_c), pooled over tests and realizations",
                                               "units": "1"}),
         "mu_eff_sem": (("reading", "t"), sem, {"long_name": "standard error over realizations", "units": "1"}),
         "count": (("reading", "t"), count, {"long_name": "tilt tests in the bin", "units": "1"}),
         "mu_eff_realization": (("reading", "realization", "t"), per_real,
                                {"long_name": "tan(alpha_c), mean of one realization's tests in the bin "
                                              "(NaN: no test)", "units": "1"})},
        coords={"reading": list(which), "realization": np.arange(len(seeds)), "t": ("t", t, {"units": "tau_th"})},
        attrs={"realizations": model.realizations, "seed": str(model.seed)},
    )
    ds["r_mean"] = ((), float(n_end.mean() / scene.steps), {"long_name": "rearrangements per tau_th",
                                                             "units": "1/tau_th"})
    return ds


# ---------------------------------------------------------------------------
# The study of the reproduction report: the paper's Fig. 5 under each reading

MU_S_MEAN = 0.6
CASES = tuple((mu_d, ratio) for mu_d in (0.5, 0.4) for ratio in (0.1, 0.2, 0.3))


def case_config(mu_d: float, ratio: float, steps: int, realizations: int, seed: int) -> dict[str, Any]:
    """The paper's Fig. 5 run at (mu_d, sigma_mu / (mean mu_s - mu_d)): Ntilde = 1e-7, sigma_theta = 1e-6."""
    return {
        "seed": int(seed), "realizations": int(realizations), "steps": int(steps), "record": "log",
        "log_points_per_decade": 10, "observables": ["n", "mu_max", "mu_eff"],
        "network": {"kind": "two_slider", "Ntilde": 1e-7},
        "friction": {"mu_d": float(mu_d),
                     "static": {"name": "gaussian", "mean": MU_S_MEAN, "std": float(ratio * (MU_S_MEAN - mu_d))}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
    }


def study(steps: int, realizations: int, seed: int = 300, cases: Sequence[tuple[float, float]] = CASES,
          which: Sequence[str] = READINGS, progress: bool = True) -> xr.Dataset:
    """:func:`readings` for every case: a dataset over (case, reading, t), with phi.

    phi = (mu_eff - mean mu_s) / sigma_mu, the paper's ordinate.
    ``mu_eff_realization`` has dims (case, reading, realization, t).

    Case k runs with seed ``seed + k``.
    """
    from tqdm.auto import tqdm

    runs = []
    for k, (mu_d, ratio) in enumerate(tqdm(cases, disable=not progress, desc="cases")):
        ds = readings(case_config(mu_d, ratio, steps, realizations, seed + k), which)
        sigma_mu = ratio * (MU_S_MEAN - mu_d)
        ds["phi"] = (ds["mu_eff"] - MU_S_MEAN) / sigma_mu
        ds["phi_sem"] = ds["mu_eff_sem"] / sigma_mu
        ds["rt"] = ds["r_mean"] * ds["t"]
        runs.append(ds.expand_dims(case=[k]))
    out = xr.concat(runs, dim="case")
    out = out.assign_coords(mu_d=("case", [c[0] for c in cases]), ratio=("case", [c[1] for c in cases]),
                            sigma_mu=("case", [c[1] * (MU_S_MEAN - c[0]) for c in cases]))
    out["mu_d"].attrs.update(long_name="dynamic friction coefficient mu_d")
    out["ratio"].attrs.update(long_name="sigma_mu / (mean mu_s - mu_d)")
    out["sigma_mu"].attrs.update(long_name="standard deviation of mu_s before truncation")
    out["phi"].attrs.update(long_name="(mu_eff - mean mu_s) / sigma_mu", units="1")
    out["rt"].attrs.update(long_name="<r> t, the typical number of rearrangements", units="1")
    out.attrs.update(steps=int(steps), realizations=int(realizations), seed=int(seed),
                     title="The appendix's tilt test under four readings (Fig. 5 of Geminard & Bertin 2010)")
    return out


def _log_slope(t: np.ndarray, y: np.ndarray, e: np.ndarray) -> tuple[float, float]:
    """Weighted least-squares slope of y against log10 t (per decade) and its standard error.

    The pooled fit of :func:`claims`: its standard error treats the time bins
    as independent points, which bins of the same trajectories are not.
    """
    ok = (t >= 1) & np.isfinite(y) & np.isfinite(e) & (e > 0)
    x = np.log10(t[ok])
    w = 1.0 / e[ok] ** 2
    A = np.vstack([np.ones_like(x), x]).T
    cov = np.linalg.inv(A.T @ (A * w[:, None]))
    beta = cov @ (A.T @ (w * y[ok]))
    return float(beta[1]), float(np.sqrt(cov[1, 1]))


CLAIMS_NOTES = {
    "slope_per_decade_realizations": (
        "per realization r: least-squares slope of its bin means mu_eff_realization against log10 t over "
        "1 <= t <= t_end (slidernet.analysis.trend.log_trend, times ln 10); _mean and _sem are their mean and "
        "std(ddof=1)/sqrt(R) over the R realizations fitted; _negative counts slopes < 0. Realizations are "
        "independent: this is the slope's error."),
    "slope_per_decade_pooled": (
        "weighted least-squares slope of the pooled mu_eff against log10 t (weights 1/mu_eff_sem^2). Its _sem "
        "treats the time bins of the same trajectories as independent and understates the error: not a "
        "significance."),
}


def claims(ds: xr.Dataset) -> dict[str, Any]:
    """The paper's claims on Fig. 5, measured under each reading.

    For every case and reading: mu_eff at t = 1 and at the last time, the
    relative change in per cent, and two slopes of mu_eff against log10 t,
    per decade:

    ``slope_per_decade_realizations_*``
        One least-squares slope per realization, from its own bin means
        (``mu_eff_realization``, :func:`slidernet.analysis.trend.log_trend`
        over 1 <= t <= t_end); their mean, standard error (spread / sqrt(R))
        and the number of negative slopes. Realizations are independent, so
        this standard error is the slope's.
    ``slope_per_decade_pooled``, ``slope_per_decade_pooled_sem``
        The weighted fit of the pooled ``mu_eff`` (weights from
        ``mu_eff_sem``). It weighs the late, precise bins most, so it is not
        the same quantity; its error treats the time bins of one trajectory
        as independent and understates the uncertainty.

    For every ratio: how well the two mu_d collapse, as the mean of
    (Delta phi)^2 / (sem_1^2 + sem_2^2) over the common range of <r> t
    (about 1 for a collapse within the errors).

    Parameters
    ----------
    ds : xarray.Dataset
        The output of :func:`study` (dims case, reading, realization, t).

    Returns
    -------
    dict
        ``cases`` (one dict per case and reading), ``collapse`` (one per ratio
        and reading) and ``notes`` (:data:`CLAIMS_NOTES`, what the slopes are).
    """
    res: dict[str, Any] = {"cases": [], "collapse": [], "notes": dict(CLAIMS_NOTES)}
    t = ds["t"].values
    first = int(np.searchsorted(t, 1.0))
    for k in range(ds.sizes["case"]):
        d = ds.isel(case=k)
        for reading in ds["reading"].values:
            r = d.sel(reading=reading)
            y, e = r["mu_eff"].values, r["mu_eff_sem"].values
            slope, slope_sem = _log_slope(t, y, e)
            # log_trend fits against ln t: d/d(log10 t) = ln 10 * d/d(ln t).
            tr = log_trend(r["mu_eff_realization"], t_min=1.0)
            per_decade = LN10 * tr["slope"].values
            res["cases"].append({
                "mu_d": float(d["mu_d"]), "ratio": float(d["ratio"]), "sigma_mu": float(d["sigma_mu"]),
                "reading": str(reading), "mu_eff_t1": float(y[first]), "mu_eff_t1_sem": float(e[first]),
                "mu_eff_end": float(y[-1]), "mu_eff_end_sem": float(e[-1]), "t_end": float(t[-1]),
                "change_percent": float(100 * (y[-1] - y[first]) / y[first]),
                "change_percent_sem": float(100 * np.hypot(e[-1], e[first]) / y[first]),
                "slope_per_decade_realizations_mean": LN10 * float(tr["slope_mean"]),
                "slope_per_decade_realizations_sem": LN10 * float(tr["slope_sem"]),
                "slope_per_decade_realizations_negative": int(np.sum(per_decade < 0)),
                "slope_realizations": int(tr["realizations"]),
                "slope_per_decade_realizations": [float(b) for b in per_decade],
                "slope_per_decade_pooled": slope, "slope_per_decade_pooled_sem": slope_sem,
                "phi_end": float(r["phi"].values[-1]),
            })
    for ratio in sorted(set(ds["ratio"].values.tolist())):
        ks = [k for k in range(ds.sizes["case"]) if float(ds["ratio"].values[k]) == ratio]
        if len(ks) != 2:
            continue
        a, b = ds.isel(case=ks[0]), ds.isel(case=ks[1])
        for reading in ds["reading"].values:
            ra, rb = a.sel(reading=reading), b.sel(reading=reading)
            xa, xb = ra["rt"].values, rb["rt"].values
            ok = (ra["t"].values >= 1) & (xa >= xb[ra["t"].values >= 1].min()) & (xa <= xb.max())
            ok &= np.isfinite(ra["phi"].values)
            lx = np.log(xb[rb["t"].values >= 1])
            yb = np.interp(np.log(xa[ok]), lx, rb["phi"].values[rb["t"].values >= 1])
            eb = np.interp(np.log(xa[ok]), lx, rb["phi_sem"].values[rb["t"].values >= 1])
            dphi = ra["phi"].values[ok] - yb
            chi2 = float(np.mean(dphi ** 2 / (ra["phi_sem"].values[ok] ** 2 + eb ** 2)))
            res["collapse"].append({"ratio": ratio, "reading": str(reading),
                                    "mu_d": [float(a["mu_d"]), float(b["mu_d"])],
                                    "mean_abs_dphi": float(np.mean(np.abs(dphi))), "chi2_per_point": chi2,
                                    "points": int(ok.sum())})
    return res


def plot_study(ds: xr.Dataset) -> Any:
    """One panel per reading: phi against <r> t for every case, bands of +- one standard error (a Figure)."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    which = [str(r) for r in ds["reading"].values]
    fig = Figure(figsize=(3.6 * len(which), 4.4), layout="constrained")
    axes = fig.subplots(1, len(which), sharey=True, squeeze=False)[0]
    ratios = sorted(set(ds["ratio"].values.tolist()))
    colors = dict(zip(ratios, ("tab:blue", "tab:orange", "tab:green", "tab:red"), strict=False))
    styles = {0.5: "-", 0.4: "--"}
    titles = {"threshold": "copied at $\\theta_c$ (slidernet)", "after": "copied after the slip",
              "incline": "exact incline, at $\\theta_c$", "incline_after": "exact incline, after the slip"}
    t = ds["t"].values
    pos = t >= 1
    for ax, reading in zip(axes, which, strict=True):
        for k in range(ds.sizes["case"]):
            d = ds.isel(case=k).sel(reading=reading)
            c = colors[float(d["ratio"])]
            x, y, e = d["rt"].values[pos], d["phi"].values[pos], d["phi_sem"].values[pos]
            ls = styles.get(round(float(d["mu_d"]), 3), ":")
            ax.plot(x, y, ls, color=c, lw=1.4)
            ax.fill_between(x, y - e, y + e, color=c, alpha=0.2, lw=0)
        ax.axhline(0.0, color="0.5", lw=0.7)
        ax.set_xscale("log")
        ax.set_title(titles.get(reading, reading), fontsize=10)
        ax.set_xlabel(r"$\langle r\rangle t$")
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel(r"$(\mu_s^\mathrm{eff} - \bar\mu_s)/\sigma_\mu$")
    handles = [Line2D([], [], color=colors[r], lw=3, label=rf"$\sigma_\mu/(\bar\mu_s-\mu_d)={r:g}$")
               for r in ratios]
    handles += [Line2D([], [], color="0.3", ls=ls, label=rf"$\mu_d={m:g}$") for m, ls in styles.items()]
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), fontsize=8)
    fig.suptitle(rf"The tilt test under four readings: $\bar\mu_s = {MU_S_MEAN}$, $\tilde N = 10^{{-7}}$, "
                 rf"$\sigma_\theta = 10^{{-6}}$, {ds.attrs['realizations']} realizations, bands $\pm$ s.e.",
                 fontsize=10)
    return fig


def main(argv: list[str] | None = None) -> int:
    """``python -m slidernet.validation.tilt_readings --out DIR``: the study, its figure and its claims."""
    import argparse
    import json
    from pathlib import Path

    from slidernet.io.netcdf import atomic_output, save_figure, write_netcdf

    p = argparse.ArgumentParser(prog="python -m slidernet.validation.tilt_readings",
                                description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True, help="folder for mueff_readings.nc, .png and .json")
    p.add_argument("--steps", type=int, default=100_000, help="thermal steps tau_th (default 1e5, the paper's)")
    p.add_argument("--realizations", type=int, default=20, help="realizations per case (default 20)")
    p.add_argument("--seed", type=int, default=300)
    p.add_argument("--no-progress", action="store_true")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ds = study(args.steps, args.realizations, args.seed, progress=not args.no_progress)
    write_netcdf(ds, out / "mueff_readings.nc")
    save_figure(plot_study(ds), out / "mueff_readings.png", dpi=120)
    with atomic_output(out / "mueff_readings.json") as tmp:
        tmp.write_text(json.dumps(claims(ds), indent=1))
    print(out / "mueff_readings.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
