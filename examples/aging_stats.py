"""The statistics of the aging study: windows, relative rates, geometries, slope(N), margins, one family
=====================================================================================================

The statistics of ``examples/aging_networks.py``: slopes in fit windows,
rates relative to the level above mu_d, variance components, one fit of
slope(N), equivalence to a margin declared before the run, the minimum
detectable effect, and one multiple-testing family. A helper module of
the aging study (docs/guides/aging-networks.md), imported by the study's
script; it runs nothing. Every slope is per decade of t; every error is
from independent units (realizations, or the means of network geometries,
:func:`slidernet.analysis.trend.grouped_mean_sem`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np
import xarray as xr
from scipy import stats

from slidernet.analysis.stats import (
    equivalence_test,
    fdr_family,
    meta_regression,
    minimum_detectable_effect,
    variance_components,
)
from slidernet.analysis.trend import grouped_mean_sem, log_trend, relative_rate

LN10 = math.log(10.0)

# The window in slips per node: aging by selection keeps the strongest of the thresholds each node has drawn,
# a function of its number of renewals, not of t. From 100 slips per node on, every system is compared at the
# same renewal history. The slips per node grow about linearly in t; from their values at 1e3 tau_th (the
# guide's table: 600 to 2100 for the pair and chains, 4000 to 11000 for lattices, 7000 to 25000 for irregular
# networks) the pair and the chains reach 100 at about 50 to 170 tau_th, lattices at 10 to 25, irregular
# networks at 4 to 14.
SLIPS_MIN = 100.0
# The fit windows: t_min (tau_th) and the least slips per node; each to the run's end. A window needs a decade.
WINDOWS = {"t>=1": (1.0, None), "t>=10": (10.0, None), "t>=100": (100.0, None), "t>=1e3": (1e3, None),
           f"s>={SLIPS_MIN:g}": (1.0, SLIPS_MIN)}
ESTIMATORS = {"mu_eff": "mu_eff_realization", "tilt_first_slip": "tilt_first_slip",
              "tilt_all_moving": "tilt_all_moving", "tilt_break_ratio": "tilt_break_ratio"}
# The family's correction: Benjamini-Yekutieli, which holds under any dependence. The slopes are dependent:
# windows of one series overlap and the estimators read the same tests (positively), but the sizes of one
# sweep share their ensemble seed (common random numbers of unknown sign) and the tests are two-sided, so the
# positive regression dependence (PRDS) that Benjamini-Hochberg needs is not assured. BH is reported beside it.
FAMILY_METHOD = "by"


def estimate(values: np.ndarray, geometry: np.ndarray) -> dict[str, Any]:
    """Mean, standard error (geometries' spread included), degrees of freedom and two-sided p of zero."""
    mean, sem, dof = grouped_mean_sem(values, geometry)
    p = float(2.0 * stats.t.sf(abs(mean / sem), dof)) if sem > 0 and dof > 0 else math.nan
    return {"mean": mean, "sem": sem, "dof": dof, "p": p}


def _absence(out: dict[str, Any], margin: float) -> dict[str, Any]:
    """An estimate with its minimum detectable effect (two-sided 5 %, power 0.8) and the two one-sided tests
    against +-``margin`` (where it has an error)."""
    if out["sem"] > 0 and out["dof"] > 0 and math.isfinite(out["mean"]):
        out["mde"] = minimum_detectable_effect(out["sem"], out["dof"])
        eq = equivalence_test(out["mean"], out["sem"], out["dof"], margin)
        out["equivalence"] = {"margin": margin, "p": eq.p, "equivalent": eq.equivalent, "ci90": list(eq.ci)}
    else:
        out["mde"] = math.nan
    return out


def slope_estimate(per_decade: np.ndarray, geometry: np.ndarray, margin: float) -> dict[str, Any]:
    """:func:`estimate` of per-realization slopes (per decade), with its MDE and equivalence to +-``margin``."""
    return _absence(estimate(per_decade, geometry), margin)


def trend(values: xr.DataArray, geometry: np.ndarray, margin: float,
          against: xr.DataArray | None = None) -> dict[str, Any]:
    """A per-realization variable: its value at t = 0, 1 and t_end, and its slope per decade of t (or of the
    abscissa ``against``) over t >= 1, each with its error from independent realizations (and geometries)."""
    tr = log_trend(values, t_min=1, against=against)
    v = values.transpose("realization", "t")
    return {"t0": estimate(v.sel(t=0).values, geometry), "t1": estimate(v.sel(t=1).values, geometry),
            "end": estimate(v.isel(t=-1).values, geometry), "t_end": float(v["t"].values[-1]),
            "slope_per_decade": slope_estimate(LN10 * tr["slope"].values, geometry, margin),
            "realizations": int(tr["realizations"]), "not_finite": int((~np.isfinite(v.values)).sum())}


def _components(per_decade: np.ndarray, geometry: np.ndarray) -> dict[str, Any]:
    """Between- and within-geometry variances of per-realization slopes, and each geometry's mean slope."""
    keys = np.unique(geometry)
    out: dict[str, Any] = {"per_geometry": [float(np.nanmean(per_decade[geometry == g]))
                                            if np.isfinite(per_decade[geometry == g]).any() else math.nan
                                            for g in keys]}
    counts = [int(np.isfinite(per_decade[geometry == g]).sum()) for g in keys]
    if sum(c > 0 for c in counts) < 2 or max(counts) < 2:
        return out | {"note": "one realization per geometry: no within spread"}
    vc = variance_components(per_decade, geometry)
    return out | {"between": vc.between, "within": vc.within, "icc": vc.icc, "between_ci": list(vc.between_ci),
                  "within_ci": list(vc.within_ci), "icc_ci": list(vc.icc_ci), "grand_mean": vc.grand_mean,
                  "grand_mean_sem": vc.grand_mean_sem, "groups": vc.groups, "values": vc.values,
                  "per_group": vc.per_group, "ms_between": vc.ms_between, "ms_within": vc.ms_within}


def windows(ds: xr.Dataset, geometry: np.ndarray, N: int, mu_d: float, several_geometries: bool,
            margin: float) -> dict[str, Any]:
    """Every estimator's slope in every fit window of :data:`WINDOWS` that the run covers by a decade.

    For ``mu_eff`` also its rate relative to its own level above mu_d
    (:func:`slidernet.analysis.trend.relative_rate`, floor mu_d: the
    relative rate of c in mu_eff = mu_d + c N^-1/2 at e = 1, of the excess
    at e < 1) and, over several geometries, the slopes' variance components.
    """
    t_end = float(ds["t"].values[-1])
    slips = ds["n"] / N
    out: dict[str, Any] = {}
    for name, var in ESTIMATORS.items():
        if var not in ds:
            continue
        out[name] = {}
        for label, (t_min, s_min) in WINDOWS.items():
            if t_end < 10 * t_min:
                continue
            where = None if s_min is None else (slips >= s_min)
            tr = log_trend(ds[var], t_min=t_min, where=where)
            per_decade = LN10 * tr["slope"].values
            records = np.isfinite(ds[var].sel(t=slice(t_min, None)).transpose("realization", "t").values)
            if where is not None:
                records &= where.sel(t=slice(t_min, None)).transpose("realization", "t").values
            w: dict[str, Any] = {"t_min": t_min, "slips_min": s_min, "t_start": tr.attrs["t_start"],
                                 "t_end": tr.attrs["t_end"], "realizations": int(tr["realizations"]),
                                 "records": float(records.sum(axis=1).mean()),
                                 "slope_per_decade": slope_estimate(per_decade, geometry, margin)}
            if name == "mu_eff" and int(tr["realizations"]) >= 2:
                rel = relative_rate(tr["slope"].values, tr["level"].values, geometry, floor=mu_d)
                w["relative"] = {"rate_per_decade": LN10 * rel.rate, "sem": LN10 * rel.sem, "dof": rel.dof,
                                 "ci95": [LN10 * c for c in rel.ci], "excess": rel.level_mean,
                                 "excess_sem": rel.level_sem, "c": math.sqrt(N) * rel.level_mean,
                                 "c_sem": math.sqrt(N) * rel.level_sem,
                                 "mde": minimum_detectable_effect(LN10 * rel.sem, rel.dof)
                                 if rel.sem > 0 and rel.dof > 0 else math.nan}
            if several_geometries:
                w["components"] = _components(per_decade, geometry)
            out[name][label] = w
    return out


def fits(points: list[dict[str, Any]], margin: float) -> list[dict[str, Any]]:
    """One random-effects fit of mu_eff's slope against N^-1/2 per parameter set, rule and condition, per window.

    Against N^-1/2, not ln N: at e = 1 mu_eff - mu_d falls as N^-1/2, so a
    slope that scales with the excess does too, and the intercept is then
    the slope of an infinite network, the question's answer; a fit in ln N
    has no limit to read. The networks of every kind (chains, irregular,
    triangular; not the pair, the control) enter one fit: what the line
    leaves over, kinds included, is the between-size variance tau^2.
    The fit takes the sizes as independent; those of one sweep share their
    ensemble seed (common random numbers), which the Knapp-Hartung error
    does not see.
    """
    sets: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for p in points:
        if p["kind"] != "pair" and p["mu_eff_at"] == "records":
            sets.setdefault((p["params"], p["rule"], p["condition"]), []).append(p)
    out = []
    for (params, rule, condition), pts in sets.items():
        for label in WINDOWS:
            rows = [(p["N"], p["windows"]["mu_eff"][label]["slope_per_decade"]) for p in pts
                    if label in p["windows"].get("mu_eff", {})]
            rows = [(n, s) for n, s in rows if s["sem"] > 0 and math.isfinite(s["mean"])]
            if len({n for n, _ in rows}) < 3:
                continue
            n = np.array([r[0] for r in rows], float)
            fit = meta_regression([s["mean"] for _, s in rows], [s["sem"] for _, s in rows], n**-0.5)
            coef = {}
            for i, name in enumerate(("infinite_N", "per_N^-1/2")):
                c = {"mean": float(fit.coef[i]), "sem": float(fit.coef_sem[i]), "dof": fit.dof,
                     "p": float(fit.coef_p[i])}
                coef[name] = _absence(c, margin) if name == "infinite_N" else c
            out.append({"params": params, "rule": rule, "condition": condition, "window": label,
                        "x": "N^-1/2", "sizes": [int(v) for v in n], "kinds": sorted({p["kind"] for p in pts}),
                        "coef": coef, "tau2": fit.tau2, "q": fit.q, "q_dof": fit.q_dof, "q_p": fit.q_p,
                        "i2": fit.i2, "method": f"{fit.method}, Knapp-Hartung t"})
    return out


def _slopes(points: list[dict[str, Any]], fitted: list[dict[str, Any]]) -> Iterable[tuple[str, dict[str, Any]]]:
    """Every slope the JSON and the tables report, named: (label, its estimate)."""
    for p in points:
        head = f"{p['group']}|{p['params']}|N={p['N']}"
        yield f"{head}|mu_max|t>=1", p["mu_max"]["slope_per_decade"]
        yield f"{head}|sqrtN_excess_vs_slips|t>=1", p["sqrtN_excess_vs_slips"]["slope_per_decade"]
        for name, per_window in p["windows"].items():
            for label, w in per_window.items():
                yield f"{head}|{name}|{label}", w["slope_per_decade"]
    for f in fitted:
        for name, c in f["coef"].items():
            yield f"fit|{f['params']}|{f['rule']}|{f['condition']}|{f['window']}|{name}", c


def family(points: list[dict[str, Any]], fitted: list[dict[str, Any]]) -> dict[str, Any]:
    """One multiple-testing family of every slope reported; each slope gets its q-values (``q_by``, ``q_bh``).

    The scaled slopes (sqrt(N) (mu_eff - mu_d), law units) and the relative
    rates test the same hypothesis as mu_eff's slope in the same window
    (one is zero if and only if the other is) and are not counted again.
    Also returned: the counts of the earlier family (mu_eff's slope over
    t >= 1 at every point, Benjamini-Hochberg), which the guide quotes.
    """
    members = [(label, s) for label, s in _slopes(points, fitted) if math.isfinite(s.get("p", math.nan))]
    out: dict[str, Any] = {}
    if members:
        p_values = {label: s["p"] for label, s in members}
        for method in ("bh", "by"):
            fam = fdr_family(p_values, method=method)
            for (_, s), q in zip(members, fam.q, strict=True):
                s[f"q_{method}"] = float(q)
            out[f"discoveries_{method}"] = list(fam.discoveries(0.05))
    out |= {"tests": len(members), "method": FAMILY_METHOD,
            "beyond_2_se": int(sum(abs(s["mean"]) > 2 * s["sem"] for _, s in members)),
            "expected_by_chance": float(sum(2 * stats.t.sf(2.0, s["dof"]) for _, s in members)),
            "untestable": sum(1 for _ in _slopes(points, fitted)) - len(members),
            "labels": [label for label, _ in members],
            "dependence": "windows of one series overlap and the estimators read the same tests (positive "
                          "dependence); the sizes of one sweep share their ensemble seed (dependence of unknown "
                          "sign); two-sided tests. PRDS, which Benjamini-Hochberg needs, is not assured: the "
                          "family's decision is Benjamini-Yekutieli's (any dependence), BH's beside it"}
    # The earlier family, kept for its counts: mu_eff's slope over t >= 1, Benjamini-Hochberg.
    old = [p["mu_eff"]["slope_per_decade"] for p in points if math.isfinite(p["mu_eff"]["slope_per_decade"]["p"])]
    ps = np.array([s["p"] for s in old])
    adjusted = stats.false_discovery_control(ps) if ps.size else ps
    return {"tests": len(old), "beyond_2_se": int(sum(abs(s["mean"]) > 2 * s["sem"] for s in old)),
            "expected_by_chance": float(sum(2 * stats.t.sf(2.0, s["dof"]) for s in old)),
            "significant_at_q_0.05": int((adjusted < 0.05).sum()),
            "method": "two-sided Student-t p-values of each slope (dof: realizations - 1, or geometries - 1); "
                      "Benjamini-Hochberg (scipy.stats.false_discovery_control)",
            "family": out}


# Tables.


def _cell(s: dict[str, Any], scale: float = 1e4) -> str:
    """A slope (scaled) with its error, dof, minimum detectable effect, equivalence mark and family q."""
    if not math.isfinite(s["mean"]):
        return "–"
    out = f"{s['mean'] * scale:+.1f} ± {s['sem'] * scale:.1f} ({s['dof']})"
    if math.isfinite(s.get("mde", math.nan)):
        out += f", MDE {s['mde'] * scale:.1f}"
    if s.get("equivalence", {}).get("equivalent"):
        out += " ≡"
    return out + (f", q {s['q_by']:.2g}" if "q_by" in s else "")


def tables(data: dict[str, Any], label: Any) -> list[str]:
    """The restated study's tables (Markdown lines), from the study's JSON; ``label`` names a point."""
    pts = data["points"]
    heads = list(WINDOWS)
    m = f"{data['windows']['margin_per_decade'] * 1e4:.1f}e-4"
    lines = ["### Slopes in fit windows (1e-4 per decade)", "",
             "Each cell: slope ± standard error (dof), minimum detectable effect (two-sided 5 %, power 0.8), "
             f"≡ where the two one-sided tests put it within ±{m} per decade (the margin declared in the script), "
             f"and its Benjamini-Yekutieli q in the family of every slope. Windows: t ≥ t_min to the run's end; "
             f"s ≥ {SLIPS_MIN:g}: slips per node ≥ {SLIPS_MIN:g}, t ≥ 1.", "",
             "| network | N | ratio, μ_d | rule | condition | estimator | " + " | ".join(heads) + " |",
             "|---|---|---|---|---|---|" + "---|" * len(heads)]
    for p in pts:
        for name, per_window in p["windows"].items():
            est = name if p["mu_eff_at"] == "records" or name != "mu_eff" else "μ_eff (appendix)"
            cells = [_cell(per_window[h]["slope_per_decade"]) if h in per_window else "" for h in heads]
            lines.append(f"| {label(p)} | {p['N']} | {p['ratio']:.1f}, {p['mu_d']:.1f} | {p['rule']} | "
                         f"{p['condition'] or 'standard'} | {est} | " + " | ".join(cells) + " |")
    lines += ["", "### μ_eff relative to its own level above μ_d (t ≥ 10)", "",
              "Relative rate: d(μ_eff − μ_d)/dlog10 t over ⟨μ_eff − μ_d⟩ (per decade), delta-method error, "
              "Fieller's 95 % interval; c = √N ⟨μ_eff − μ_d⟩ (at e = 1, μ_eff = μ_d + c N^−½).", "",
              "| network | N | ratio, μ_d | rule | condition | μ_eff − μ_d (1e-4) | c | relative rate (1e-2) "
              "| 95 % interval (1e-2) | MDE (1e-2) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for p in pts:
        w = p["windows"].get("mu_eff", {}).get("t>=10")
        if not w or "relative" not in w:
            continue
        r = w["relative"]
        lines.append(f"| {label(p)} | {p['N']} | {p['ratio']:.1f}, {p['mu_d']:.1f} | {p['rule']} | "
                     f"{p['condition'] or 'standard'} | {r['excess'] * 1e4:.1f} ± {r['excess_sem'] * 1e4:.1f} | "
                     f"{r['c']:.4f} ± {r['c_sem']:.4f} | {r['rate_per_decade'] * 1e2:+.2f} ± {r['sem'] * 1e2:.2f} "
                     f"({r['dof']}) | [{r['ci95'][0] * 1e2:.2f}, {r['ci95'][1] * 1e2:.2f}] | "
                     f"{r['mde'] * 1e2:.2f} |")
    lines += ["", "### Variance components of μ_eff's slope, between and within geometries (1e-8 per decade²)", "",
              "| network | N | ratio, μ_d | rule | condition | window | G × n | between [95 %] | within [95 %] "
              "| ICC [95 %] | per-geometry slopes (1e-4) |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in pts:
        for h, w in p["windows"].get("mu_eff", {}).items():
            c = w.get("components")
            if not c or h not in ("t>=1", "t>=10"):
                continue
            per = ", ".join(f"{v * 1e4:+.1f}" for v in c["per_geometry"])
            if "between" not in c:
                lines.append(f"| {label(p)} | {p['N']} | {p['ratio']:.1f}, {p['mu_d']:.1f} | {p['rule']} | "
                             f"{p['condition'] or 'standard'} | {h} | {len(c['per_geometry'])} × 1 | – | – | – | "
                             f"{per} |")
                continue
            b, wi = (1e8 * np.array([c[k], *c[f"{k}_ci"]]) for k in ("between", "within"))
            lines.append(
                f"| {label(p)} | {p['N']} | {p['ratio']:.1f}, {p['mu_d']:.1f} | {p['rule']} | "
                f"{p['condition'] or 'standard'} | {h} | {c['groups']} × {c['per_group']:.3g} | "
                f"{b[0]:.2f} [{b[1]:.2f}, {b[2]:.2f}] | {wi[0]:.2f} [{wi[1]:.2f}, {wi[2]:.2f}] | "
                f"{c['icc']:.2f} [{c['icc_ci'][0]:.2f}, {c['icc_ci'][1]:.2f}] | {per} |")
    lines += ["", "### One fit of slope(N) = a + b N^−½ per parameter set, rule and condition (networks, μ_eff)",
              "", "a: the slope of an infinite network (1e-4 per decade; MDE and ≡ as above); b: 1e-4 per decade "
              "per unit of N^−½; random effects (REML), Knapp-Hartung t.", "",
              "| ratio set | rule | condition | window | sizes | a | b | τ² (1e-8) | Q (dof), p |",
              "|---|---|---|---|---|---|---|---|---|"]
    for f in data["fits"]:
        a, b = f["coef"]["infinite_N"], f["coef"]["per_N^-1/2"]
        lines.append(f"| {f['params']} | {f['rule']} | {f['condition'] or 'standard'} | {f['window']} | "
                     f"{len(f['sizes'])} ({', '.join(f['kinds'])}) | {_cell(a)} | {_cell(b)} | "
                     f"{f['tau2'] * 1e8:.2f} | {f['q']:.1f} ({f['q_dof']}), {f['q_p']:.2g} |")
    fam = data["multiple_testing"]["family"]
    if fam.get("tests"):
        lines += ["", f"The family: {fam['tests']} slopes (every one above, μ_max's and the slopes against the "
                  f"slips per node of the first table; {fam['untestable']} without an error left out), "
                  f"{fam['beyond_2_se']} beyond 2 standard errors where {fam['expected_by_chance']:.1f} are "
                  f"expected by chance; {len(fam['discoveries_by'])} discoveries at a Benjamini-Yekutieli false "
                  f"discovery rate of 0.05 ({len(fam['discoveries_bh'])} under Benjamini-Hochberg). Dependence: "
                  f"{fam['dependence']}."]
        lines += [f"- {d}" for d in fam["discoveries_by"]]
    return [*lines, ""]
