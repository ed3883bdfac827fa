"""A/B of the quasi-static results: a git revision against the working tree, bit for bit.

    python benchmarks/ab_results.py BASE [--keep DIR]

Checks BASE out into a temporary git worktree (as ``ab_versions.py`` does),
then runs the same scenes through ``slidernet.run`` against BASE's package
(A) and the working tree's (B), each in its own Python process with its own
numba cache, writes each result with ``slidernet.io.write_netcdf`` and
compares the two files of each scene: the same variables, and for each its
dtype, dimensions and bytes (so NaN against NaN and -0.0 against +0.0 are
compared as stored), and every attribute but the version, the code's
identity and the execution settings. The scenes are those of the
quasi-static solver's paths: the pair (compiled pair kernel), a chain, a
triangular lattice and irregular 2D networks (straight-line and exact
slips, 64 and 10 000 nodes), each without and with the tilt tests of
``mu_eff`` (before every rearrangement for the pair, at the records for the
networks, with their loads), with the event catalogue and the contacts' ages
on the networks. It prints one line per scene and exits with 0 when every
scene is identical, 1 otherwise. ``--keep DIR`` keeps the files (``DIR/A``,
``DIR/B``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from ab_versions import ROOT, worktree

# Attributes that may differ between two versions without a change of results.
VOLATILE = {"slidernet_version", "slidernet_code", "execution"}
NETWORK_OBS = ["n", "mu_max", "x_G", "events", "contact_age"]
TILT_OBS = ["mu_eff", "tilt_loads", "mu_eff_realization"]


def _scene(network: dict[str, Any], steps: int, observables: list[str], **more: Any) -> dict[str, Any]:
    return {"seed": 45, "realizations": 3, "steps": steps, "observables": observables,
            "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
            "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7},
            "network": {"Ntilde": 1e-7, **network}, "execution": {"workers": 1}, **more}


PAIR = {"kind": "two_slider"}
CHAIN = {"kind": "chain", "n": 16}
TRIANGULAR = {"kind": "triangular", "shape": [8, 8]}
IRREGULAR = {"kind": "irregular", "n": 64, "seed": 3}
SCENES: dict[str, dict[str, Any]] = {
    "pair": _scene(PAIR, 3000, ["n", "mu_max", "x_G"]),
    "pair_tilt": _scene(PAIR, 3000, ["n", "mu_max", "x_G", "mu_eff", "n_records", "mu_eff_realization"]),
    "chain": _scene(CHAIN, 300, NETWORK_OBS),
    "chain_tilt": _scene(CHAIN, 300, NETWORK_OBS + TILT_OBS, mu_eff_at="records"),
    "triangular": _scene(TRIANGULAR, 100, NETWORK_OBS),
    "triangular_tilt": _scene(TRIANGULAR, 100, NETWORK_OBS + TILT_OBS, mu_eff_at="records"),
    "irregular": _scene(IRREGULAR, 100, NETWORK_OBS),
    "irregular_tilt": _scene(IRREGULAR, 100, NETWORK_OBS + TILT_OBS, mu_eff_at="records"),
    "irregular_exact": _scene(IRREGULAR, 40, NETWORK_OBS, solver={"slip": "exact"}),
    "irregular_exact_tilt": _scene(IRREGULAR, 40, NETWORK_OBS + TILT_OBS, solver={"slip": "exact"},
                                   mu_eff_at="records"),
    "irregular_1e4": _scene({"kind": "irregular", "n": 10_000, "seed": 0}, 20, ["n", "mu_max", "x_G"],
                            realizations=1),
}


def child(folder: Path) -> None:
    """Run every scene with the package on ``sys.path`` and write its result into ``folder``."""
    import slidernet
    from slidernet.io import write_netcdf

    folder.mkdir(parents=True, exist_ok=True)
    for name, cfg in SCENES.items():
        write_netcdf(slidernet.run(cfg), folder / f"{name}.nc")


def differences(a: Path, b: Path) -> list[str]:
    """What differs between two result files (variables bit for bit, attributes but ``VOLATILE``); [] if none."""
    from slidernet.io import read_result

    x, y = read_result(a), read_result(b)
    found = [f"variables only in one: {sorted(set(x.variables) ^ set(y.variables))}"] \
        if set(x.variables) != set(y.variables) else []
    for name in sorted(set(x.variables) & set(y.variables)):
        u, v = x[name], y[name]
        if u.dtype != v.dtype or u.dims != v.dims or u.shape != v.shape:
            found.append(f"{name}: {u.dtype}{u.dims}{u.shape} against {v.dtype}{v.dims}{v.shape}")
        elif u.dtype == object:
            if u.values.tolist() != v.values.tolist():
                found.append(f"{name}: values differ")
        elif u.values.tobytes() != v.values.tobytes():
            differ = np.count_nonzero(u.values.view(np.uint8).reshape(u.size, -1)
                                      != v.values.view(np.uint8).reshape(v.size, -1), axis=None)
            found.append(f"{name}: {differ} bytes of {u.values.nbytes} differ")
    for key in sorted((set(x.attrs) | set(y.attrs)) - VOLATILE):
        p, q = x.attrs.get(key), y.attrs.get(key)
        if key in ("config", "configs", "sweep") and p is not None and q is not None:
            p, q = json.loads(p), json.loads(q)
        if not np.array_equal(np.asarray(p, dtype=object), np.asarray(q, dtype=object)):
            found.append(f"attribute {key}: {p!r} against {q!r}")
    return found


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("base", nargs="?", help="the git revision to compare against (A)")
    ap.add_argument("--keep", type=Path, default=None, help="keep the result files in DIR/A and DIR/B")
    ap.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child is not None:
        child(args.child)
        return 0
    if args.base is None:
        ap.error("the git revision BASE is required")
    with (tempfile.TemporaryDirectory(prefix="slidernet-ab-results-") as tmp,
          worktree(Path(tmp) / "base", args.base) as base):
        out = args.keep if args.keep is not None else Path(tmp)
        for name, root in (("A", base), ("B", ROOT)):
            env = {**os.environ, "PYTHONPATH": str(root), "NUMBA_CACHE_DIR": str(Path(tmp) / f"cache-{name}")}
            subprocess.run([sys.executable, __file__, "--child", str(out / name)], env=env, check=True,
                           cwd=root)
        print(f"A = {args.base}, B = working tree ({ROOT}):")
        same = True
        for name in SCENES:
            found = differences(out / "A" / f"{name}.nc", out / "B" / f"{name}.nc")
            same = same and not found
            print(f"  {name:22s} " + ("identical" if not found else "DIFFERENT: " + "; ".join(found)))
    print("all identical" if same else "some scenes differ")
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
