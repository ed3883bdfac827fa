"""A fuzz of configurations: valid scenes mutated at random, each run by ``slidernet run``, none may crash or hang.

Each case starts from one of the base scenes below (every network kind, the
tilt test and its options, strengthening, overshoot, creep, events, files of
every format, a plugin file), applies 1 to 3 mutations and runs
``slidernet run CASE.toml --out DIR --no-progress --workers W`` in a fresh
process. A mutation sets a key (present or one of the documented options) to
a hostile value (mostly a number: 0, a negative, 2**63, 1e308, 5e-324,
NaN, inf; else a string, a boolean, a list, a table), multiplies a number
of the scene by 10^k (a wrong unit: k = +-1, 3, 7, 300), deletes a key, adds an unknown key, or damages
a data file (a row with a missing, extra or non-numeric field; a GraphML
string where a number belongs, a node without ``y``, a parallel edge).

A case passes when:

- it exits 0, its folder holds only ``result.nc``, and ``n``, ``mu_max``,
  ``x_G`` (and ``y_G``) are finite there; or
- it exits 2 with ``slidernet: error:`` lines and no traceback, and leaves no
  folder behind, or a checkpoint of the work it saved before the error,
  which its line names; or
- it runs past ``--case-timeout`` seconds having said it would be slow (a
  ``slidernet: warning:`` line) or with a slow-run estimate of at least a
  tenth of the timeout (:func:`slidernet.solver.budget.warn_if_slow`'s
  estimate is within a factor 2 on the study's scenes,
  ``benchmarks/slip_rate_estimate.py``, and may be further off elsewhere), and then one SIGTERM ends it, within
  ``--stop-timeout`` seconds, with exit 143 (128 + SIGTERM).

It fails on exit status 1 (slidernet's "internal error"), any Python
traceback, a result with a NaN or an inf where a run gives numbers, any
other status, a run that goes past its time without a warning or an
estimate that says so, a run that one SIGTERM does not stop, and a folder
left with something other than ``result.nc`` by a run that did not stop on
a signal.

Usage (from the repository root, slidernet installed)::

    python benchmarks/config_fuzz.py [--cases 400] [--seed 0] [--jobs 2] [--case-timeout 60] [--keep DIR]

Exit status 0 when every case passes, 1 otherwise. ``fault_injection.py
--fuzz N`` runs the same fuzz.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

# -- the base scenes ---------------------------------------------------------------------------------------------
_FRICTION = {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}}
_DRIVER = {"name": "gaussian_steps", "sigma_theta": 1e-7}


def _base(network: dict[str, Any], **top: Any) -> dict[str, Any]:
    # allow_implausible: the mutations reach every valid value, not only those of real materials (the
    # plausibility check itself is tests/test_plausibility.py's)
    cfg = {"seed": 1, "realizations": 2, "steps": 30, "observables": ["n", "mu_max", "x_G"],
           "network": {"Ntilde": 1e-7, **network}, "friction": copy.deepcopy(_FRICTION),
           "driver": copy.deepcopy(_DRIVER), "allow_implausible": True}
    cfg.update(top)
    return cfg


EDGES_CSV = "i,j,k\n0,1,2.0\n1,2,2.0\n2,3,2.0\n0,2,2.0\n1,3,2.0\n"
NODES_CSV = "node,x,y,normal_load\n0,0,0,1\n1,1,0,1\n2,0.5,0.9,1\n3,1.5,0.9,1\n"
GRAPHML = """<?xml version="1.0" encoding="UTF-8"?>
<graphml xmlns="http://graphml.graphdrawing.org/xmlns">
  <key id="x" for="node" attr.name="x" attr.type="double"/>
  <key id="y" for="node" attr.name="y" attr.type="double"/>
  <key id="k" for="edge" attr.name="k" attr.type="double"/>
  <graph edgedefault="undirected">
    <node id="0"><data key="x">0</data><data key="y">0</data></node>
    <node id="1"><data key="x">1</data><data key="y">0</data></node>
    <node id="2"><data key="x">0.5</data><data key="y">0.9</data></node>
    <node id="3"><data key="x">1.5</data><data key="y">0.9</data></node>
    <edge source="0" target="1"><data key="k">1.0</data></edge>
    <edge source="1" target="2"><data key="k">1.0</data></edge>
    <edge source="0" target="2"><data key="k">1.0</data></edge>
    <edge source="1" target="3"><data key="k">1.0</data></edge>
    <edge source="2" target="3"><data key="k">1.0</data></edge>
  </graph>
</graphml>
"""
SERIES_CSV = "hour,celsius\n" + "".join(f"{h},{15 + 6 * math.sin(h / 3.8):.2f}\n" for h in range(80))
MU_S_TXT = "".join(f"{0.6 + 0.05 * math.sin(7.3 * i):.3f}\n" for i in range(50))
PLUGIN_PY = '''"""A driver registered by a plugin file of the fuzz."""
import numpy as np
import slidernet


class Steps:
    def __init__(self, sigma_theta: float = 1e-7) -> None:
        if not sigma_theta > 0:
            raise slidernet.ConfigError(
                f"The 'sigma_theta' parameter of fuzz_steps must be > 0. Got {sigma_theta!r} instead.")
        self.sigma_theta = float(sigma_theta)

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        return self.sigma_theta * rng.standard_normal(steps + 1)


slidernet.register_driver("fuzz_steps", Steps)
'''
#: Data files every case folder gets (a mutation may damage its own copy).
FILES = {"net.csv": EDGES_CSV, "net.nodes.csv": NODES_CSV, "net.graphml": GRAPHML, "temps.csv": SERIES_CSV,
         "mu_s.txt": MU_S_TXT, "fuzz_plugin.py": PLUGIN_PY}

BASES: dict[str, dict[str, Any]] = {
    "pair": _base({"kind": "two_slider"}, observables=["n", "mu_max", "x_G", "mu_eff"]),
    "chain_tilt": _base({"kind": "chain", "n": 6}, observables=["n", "mu_max", "mu_eff"], mu_eff_at="records",
                        tilt={"min_slips": 2, "min_displacement": 0.5}),
    "irregular_aging": _base({"kind": "irregular", "n": 10, "seed": 2},
                             observables=["n", "mu_max", "mu_eff", "contact_age"],
                             friction={**copy.deepcopy(_FRICTION), "overshoot": 0.5,
                                       "strengthening": {"law": "log", "beta": 0.01, "tau_c": 1.0}}),
    "triangular_events": _base({"kind": "triangular", "shape": [4, 4]},
                               observables=["n", "mu_max", "x_G", "events"], solver={"slip": "exact"}),
    "square_creep": _base({"kind": "square", "shape": [3, 3], "f_ext": [0.2, 0.0]},
                          observables=["n", "x_G", "creep"], creep={"transient": 2}),
    "graph_csv": _base({"kind": "graph", "path": "net.csv", "k": 1.5}),
    "graph_graphml": _base({"kind": "graph", "path": "net.graphml"}, observables=["n", "mu_max", "mu_eff"]),
    "chain_series_empirical": _base(
        {"kind": "chain", "n": 4, "kappa": 1.0},
        friction={"mu_d": 0.5, "static": {"name": "empirical", "path": "mu_s.txt"}},
        driver={"name": "series", "path": "temps.csv", "kappa": 1e-8, "T0": 15.0, "tau_th": 1.0}),
    "plugin_incline": _base({"kind": "chain", "n": 5, "incline": 10.0}, plugins=["fuzz_plugin.py"],
                            driver={"name": "fuzz_steps", "sigma_theta": 1e-7}),
}

#: Options a mutation may set even where the base leaves them out: every documented key of every table.
OPTIONS = [
    "seed", "realizations", "steps", "record", "log_points_per_decade", "observables", "mu_eff_at", "plugins",
    "network.kind", "network.Ntilde", "network.n", "network.shape", "network.path", "network.seed", "network.k",
    "network.kappa", "network.normal_load", "network.f_ext", "network.incline",
    "friction.mu_d", "friction.overshoot", "friction.static.name", "friction.static.mean", "friction.static.std",
    "friction.strengthening.law", "friction.strengthening.beta", "friction.strengthening.tau_c",
    "friction.strengthening.exponent",
    "driver.name", "driver.sigma_theta", "driver.tau_c", "driver.amplitude", "driver.period", "driver.rate",
    "solver.kernel", "solver.max_avalanche", "solver.batch", "solver.recompute_every", "solver.slip",
    "solver.max_events",
    "execution.workers", "execution.scheduler", "execution.checkpoint_every", "execution.scheduler_timeout",
    "tilt.min_slips", "tilt.min_displacement", "creep.transient", "creep.event_fraction",
    "units.material", "units.size", "units.delta_T",
]

#: Numbers at the edges: zero, negatives, past int64, overflow and underflow, NaN, inf, and some that are valid.
NUMBERS: list[Any] = [
    0, 1, 2, -1, 3, 10, 1000, 20000, 2**31, 2**63, 2**64, 1e9, 1e19, 1e300, -1e300, 1e308, -1e308, 5e-324,
    1e-320, float("nan"), float("inf"), float("-inf"), 0.0, 0.5, 1.0, 0.999, 1e-7, 1e-6, 1e-3, 1e7,
]
#: Everything else a TOML value can be: strings (numbers written as strings, scheduler addresses, names),
#: booleans, lists and tables.
OTHERS: list[Any] = [
    "3", "0.5", "", "abc", "tcp://[::1", "tcp://host:notaport", "tcp://a b", "inproc://x", "ucx://h:1", True,
    False, [], [1, 2], [0.5, "a"], {}, {"a": 1}, ["n"], [4, 4], [1e308, 1e308], [2**63, 2], "log", "all",
    "records", "exact", "gaussian", "constant",
]

DAMAGE = {
    "net.csv": ["i,j,k\n0,1,2.0\n1,2\n2,3,2.0\n", "i,j,k\n0,1,2.0\n1,2,2.0,9\n", "i,j,k\n0,1,abc\n1,2,2.0\n",
                "i,j,k\n0,1,2.0\n0,1,2.0\n", "i,j,k\n0,9,2.0\n", "i,j,k\n0,1,1e308\n1,2,2\n", "i,j\n"],
    "net.nodes.csv": ["node,x,y,normal_load\n0,0,0,1\n1,1\n2,0.5,0.9,1\n3,1.5,0.9,1\n",
                      "node,x,y,normal_load\n0,0,0,1\n1,1e308,-1e308,1\n2,0.5,0.9,1\n3,1.5,0.9,1\n",
                      "node,x,y,normal_load\n0,0,0,x\n1,1,0,1\n2,0.5,0.9,1\n3,1.5,0.9,1\n"],
    "net.graphml": [GRAPHML.replace('<data key="k">1.0</data></edge>\n    <edge source="1" target="2">',
                                    '<data key="k">abc</data></edge>\n    <edge source="1" target="2">', 1),
                    GRAPHML.replace('<data key="y">0.9</data></node>\n    <node id="3">',
                                    '</node>\n    <node id="3">', 1),
                    GRAPHML.replace("</graph>", '<edge source="0" target="1"><data key="k">3.0</data></edge>\n'
                                                "  </graph>"),
                    GRAPHML.replace('attr.type="double"/>\n  <graph', 'attr.type="string"/>\n  <graph')
                           .replace('<data key="k">1.0</data>', '<data key="k">stiff</data>', 1),
                    GRAPHML[:300]],
    "temps.csv": ["hour,celsius\n0,15\n1\n2,16\n" + SERIES_CSV.split("\n", 4)[-1], "hour,celsius\n0,15,3\n",
                  "hour,celsius\n0,abc\n1,15\n"],
    "mu_s.txt": ["0.6\nabc\n0.7\n", "0.6 0.7\n0.8\n", "nan\n0.7\n", ""],
}


# -- TOML --------------------------------------------------------------------------------------------------------
def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def to_toml(cfg: dict[str, Any], prefix: str = "") -> str:
    """A configuration dict as TOML: scalars and lists first, then one [table] per nested dict."""
    lines = [f"{json.dumps(k)} = {_value(v)}" for k, v in cfg.items() if not isinstance(v, dict)]
    out = "\n".join(lines) + ("\n" if lines else "")
    for k, v in cfg.items():
        if isinstance(v, dict):
            name = f"{prefix}{json.dumps(k)}"
            out += f"\n[{name}]\n" + to_toml(v, name + ".")
    return out


# -- mutations ---------------------------------------------------------------------------------------------------
def _leaves(cfg: dict[str, Any], prefix: str = "") -> list[str]:
    out = []
    for k, v in cfg.items():
        out.append(prefix + k)
        if isinstance(v, dict):
            out += _leaves(v, prefix + k + ".")
    return out


def _get(cfg: dict[str, Any], dotted: str) -> Any:
    node: Any = cfg
    for key in dotted.split("."):
        node = node[key]
    return node


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _set(cfg: dict[str, Any], dotted: str, value: Any) -> None:
    *path, last = dotted.split(".")
    node = cfg
    for key in path:
        if not isinstance(node.get(key), dict):
            node[key] = {}
        node = node[key]
    node[last] = value


def _delete(cfg: dict[str, Any], dotted: str) -> None:
    *path, last = dotted.split(".")
    node = cfg
    for key in path:
        node = node[key]
    node.pop(last, None)


def mutate(cfg: dict[str, Any], files: dict[str, str], rng: random.Random) -> list[str]:
    """Apply one random mutation to ``cfg`` (or to one of ``files``), in place; what was done, in words."""
    what = rng.choices(["set", "option", "scale", "delete", "unknown", "file"], weights=[4, 5, 3, 1, 1, 2])[0]
    if what == "file":
        name = rng.choice(sorted(DAMAGE))
        files[name] = rng.choice(DAMAGE[name])
        return [f"damage {name}"]
    numeric = [key for key in _leaves(cfg) if _is_number(_get(cfg, key))]
    if what == "scale" and numeric:
        # A wrong unit or a typo in an exponent: a number of the scene times 10^k.
        key = rng.choice(numeric)
        k = rng.choice([-300, -7, -3, -1, 1, 3, 7, 300])
        value = _get(cfg, key) * 10.0**k
        _set(cfg, key, value)
        return [f"{key} = {_value(value)} (x 1e{k})"]
    if what == "delete":
        key = rng.choice(_leaves(cfg))
        _delete(cfg, key)
        return [f"delete {key}"]
    if what == "unknown":
        table = rng.choice(["", "network.", "friction.", "solver.", "driver.", "tilt.", "execution."])
        key = table + rng.choice(["relizations", "sigma", "n_steps", "foo", "mu-d"])
        _set(cfg, key, 1)
        return [f"unknown key {key}"]
    key = rng.choice(_leaves(cfg)) if what == "set" else rng.choice(OPTIONS)
    # Mostly numbers, so that many cases pass the type checks and reach the network, the kernels, the tilt
    # test and the files.
    value = rng.choice(NUMBERS) if rng.random() < 0.75 else rng.choice(OTHERS)
    _set(cfg, key, value)
    return [f"{key} = {_value(value)}"]


# -- one case ----------------------------------------------------------------------------------------------------
@dataclass
class Case:
    index: int
    base: str
    mutations: list[str]
    folder: Path
    status: str = ""
    ok: bool = False
    rc: int | None = None
    seconds: float = 0.0
    detail: str = ""
    extra: dict[str, Any] = field(default_factory=dict)


def make_case(index: int, rng: random.Random, root: Path) -> Case:
    base = rng.choice(sorted(BASES))
    cfg = copy.deepcopy(BASES[base])
    files = dict(FILES)
    done = []
    for _ in range(rng.choices([1, 2, 3], weights=[4, 2, 1])[0]):
        done += mutate(cfg, files, rng)
    folder = root / f"case{index:04d}"
    folder.mkdir(parents=True)
    for name, text in files.items():
        (folder / name).write_text(text)
    (folder / "case.toml").write_text(to_toml(cfg))
    return Case(index, base, done, folder)


def _estimate(case: Case) -> float | None:
    """The slow-run estimate of the case's run, in seconds on one worker (None if it cannot be had)."""
    code = ("import sys, warnings; warnings.simplefilter('ignore')\n"
            "from slidernet.config import load_config\nfrom slidernet.solver import Scene, budget\n"
            "cfg = load_config(sys.argv[1]); scene = Scene.from_config(cfg)\n"
            "print(budget.warn_if_slow(cfg, scene, 1))\n")
    try:
        done = subprocess.run([sys.executable, "-c", code, str(case.folder / "case.toml")], capture_output=True,
                              # A scene of 5e7 sliders took over 120 s to build beside other jobs (case 318).
                              text=True, timeout=600, cwd=case.folder)
        return float(done.stdout.strip().splitlines()[-1])
    except (subprocess.TimeoutExpired, ValueError, IndexError):
        return None


#: Variables of a result that are finite in every run that exits 0 (mu_eff may be NaN: a test that gave up).
FINITE = ("n", "mu_max", "x_G", "y_G")


def non_finite(path: Path) -> str | None:
    """The variables of :data:`FINITE` that hold a NaN or an inf in the result ``path``, in words (None: none)."""
    import numpy as np
    import xarray as xr

    with xr.open_dataset(path) as ds:
        bad = [f"{name} ({int((~np.isfinite(ds[name].values)).sum())} values)" for name in FINITE
               if name in ds and not np.isfinite(ds[name].values).all()]
    return "non-finite " + ", ".join(bad) if bad else None


def run_case(case: Case, workers: int, timeout: float, stop_timeout: float) -> Case:
    out = case.folder / "out"
    err_path = case.folder / "stderr.txt"
    args = [sys.executable, "-m", "slidernet", "run", "case.toml", "--out", "out", "--no-progress",
            "--workers", str(workers)]
    t0 = time.monotonic()
    with open(err_path, "w") as err, open(case.folder / "stdout.txt", "w") as std:
        proc = subprocess.Popen(args, cwd=case.folder, stdout=std, stderr=err, start_new_session=True)
        try:
            case.rc = proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            case.rc = None
    stderr = err_path.read_text(errors="replace")
    if case.rc is None:  # past its time: it must have said so, and one SIGTERM must stop it
        warned = "slidernet: warning:" in stderr
        proc.send_signal(signal.SIGTERM)
        try:
            rc = proc.wait(timeout=stop_timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            case.seconds = time.monotonic() - t0
            case.status, case.detail = "hang", f"one SIGTERM did not stop it within {stop_timeout:g} s"
            return case
        case.seconds = time.monotonic() - t0
        # After the stop: the estimate builds the scene again, which took minutes for 5e7 sliders, long enough
        # for the run to end on its own before its SIGTERM (case 318 of seed 0).
        estimate = None if warned else _estimate(case)
        stderr = err_path.read_text(errors="replace")
        expected = warned or (estimate is not None and estimate >= timeout / 10)
        if not expected:
            case.status = "slow, unannounced"
            case.detail = f"ran past {timeout:g} s; estimate {estimate!r} s, no warning"
        elif rc != 128 + signal.SIGTERM or "Traceback" in stderr:
            case.status, case.detail = "bad stop", f"SIGTERM gave rc {rc}: {stderr.strip()[-400:]}"
        else:
            case.status, case.ok = ("slow, warned" if warned else "slow, estimated"), True
            case.extra["estimate"] = estimate
        return case
    case.seconds = time.monotonic() - t0
    left = sorted(p.name for p in out.iterdir()) if out.is_dir() else []
    if case.rc == 0:
        case.ok = left == ["result.nc"]
        case.status = "ran" if case.ok else "ran, folder"
        case.detail = "" if case.ok else f"left in the folder: {left}"
        wrong = non_finite(out / "result.nc") if case.ok else None
        if wrong:
            case.ok, case.status, case.detail = False, "ran, non-finite", wrong
    elif case.rc == 2:
        lines = [line for line in stderr.splitlines() if line.strip()]
        first = next((i for i, line in enumerate(lines) if line.startswith("slidernet: error:")), None)
        # A run that fails after saving work keeps it (a resumable checkpoint) and its line says where.
        kept = left == ["checkpoint"] and (out / "checkpoint" / "run.json").exists() and "checkpoint" in stderr
        case.ok = first is not None and "Traceback" not in stderr and (not left or kept)
        case.status = "refused" if case.ok else "refused, badly"
        case.detail = (" ".join(lines[first:first + 2])[len("slidernet: error: "):] if first is not None
                       else stderr.strip()[-400:])
        if left and not kept:
            case.detail += f" (left in the folder: {left})"
    else:
        case.status = "crash" if case.rc == 1 else f"rc {case.rc}"
        case.detail = stderr.strip()[-600:]
    return case


def fuzz(cases: int, seed: int, jobs: int, timeout: float, stop_timeout: float, root: Path,
         workers: int = 1, only: set[int] | None = None) -> list[Case]:
    """Make and run ``cases`` cases in ``root``, ``jobs`` at a time; print one line per case as it ends.

    ``only``: run just the cases of these indices (every case is still made, so each is the case of the
    whole run of that seed)."""
    rng = random.Random(seed)
    made = [make_case(i, rng, root) for i in range(cases)]
    if only is not None:
        made = [case for case in made if case.index in only]
    done: list[Case] = []
    with ThreadPoolExecutor(jobs) as pool:
        for case in pool.map(lambda c: run_case(c, workers, timeout, stop_timeout), made):
            done.append(case)
            mark = "ok  " if case.ok else "FAIL"
            print(f"{case.index:4d} {mark} {case.status:17s} {case.seconds:6.1f} s  {case.base:22s} "
                  f"{'; '.join(case.mutations)}" + (f"\n          {case.detail}" if case.detail else ""),
                  flush=True)
    return done


def summary(done: list[Case]) -> str:
    counts: dict[str, int] = {}
    for case in done:
        counts[case.status] = counts.get(case.status, 0) + 1
    failed = sum(not c.ok for c in done)
    crashes = sum(c.rc == 1 for c in done)
    return (f"{len(done) - failed} of {len(done)} cases passed; exits of status 1: {crashes}; "
            + ", ".join(f"{n} {s}" for s, n in sorted(counts.items())))


def warm(root: Path, workers: int) -> None:
    """Run every base once, unmutated (fills the kernel cache; each base must run)."""
    for i, name in enumerate(sorted(BASES)):
        folder = root / f"base-{name}"
        folder.mkdir(parents=True)
        for fname, text in FILES.items():
            (folder / fname).write_text(text)
        (folder / "case.toml").write_text(to_toml(BASES[name]))
        case = run_case(Case(-1 - i, name, [], folder), workers, 900, 30)
        if case.status != "ran":
            raise SystemExit(f"the base scene {name!r} does not run: {case.status} {case.detail}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=400)
    parser.add_argument("--seed", type=int, default=0, help="seed of the mutations (default 0)")
    parser.add_argument("--jobs", type=int, default=2, help="cases run at once (default 2)")
    parser.add_argument("--workers", type=int, default=1, help="--workers of each run (default 1)")
    parser.add_argument("--case-timeout", type=float, default=60.0, help="seconds a case may run (default 60)")
    parser.add_argument("--stop-timeout", type=float, default=30.0,
                        help="seconds one SIGTERM has to stop a case past its time (default 30)")
    parser.add_argument("--keep", type=Path, help="work in this folder and keep it (default: a temporary one)")
    parser.add_argument("--only", type=int, nargs="+", metavar="INDEX",
                        help="run only these cases of the seed's --cases (a failed case again, say)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        root = args.keep or Path(tmp)
        root.mkdir(parents=True, exist_ok=True)
        t0 = time.monotonic()
        warm(root, args.workers)
        print(f"{len(BASES)} base scenes ran ({time.monotonic() - t0:.0f} s); {args.cases} cases, "
              f"seed {args.seed}, {args.jobs} at a time, {args.case_timeout:g} s each", flush=True)
        done = fuzz(args.cases, args.seed, args.jobs, args.case_timeout, args.stop_timeout, root, args.workers,
                    None if args.only is None else set(args.only))
        print(summary(done))
        print(f"{time.monotonic() - t0:.0f} s in all")
        return 0 if all(c.ok for c in done) else 1


if __name__ == "__main__":
    sys.exit(main())
