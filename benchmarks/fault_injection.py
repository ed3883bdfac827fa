"""Fault injection: kill -9 a run at random moments, resume it, and check that nothing is lost, mixed or left.

Each trial starts ``slidernet run`` (2 local workers, checkpoints every
0.2 s) in a fresh folder and sends SIGKILL, after a random delay, to one of:

- ``parent``: the main process alone (its workers must die with it);
- ``worker``: one worker process (the run must say so in one line, exit 2,
  and stay resumable);
- ``group``: every process of the run at once (a machine failure, a batch
  scheduler's kill of the job).

Up to ``--kills`` kills per trial, each on the run resumed after the
previous one (``--resume``); then a last ``--resume`` runs to the end. The
delays are drawn uniformly between 0 and 1.2 times the time of an
uninterrupted run, so that kills land while the kernels load, while
realizations run and save, and while ``result.nc`` is written. A trial
passes when:

- the final result is the bits of an uninterrupted run (every variable);
- the folder holds only ``result.nc`` (no temporary file, no lock file, no
  checkpoint);
- every process any attempt started has ended (a zombie, ended but not yet
  reaped by its new parent, counts as ended).

Usage (from the repository root; Linux: reads ``/proc``)::

    python benchmarks/fault_injection.py [--trials 24] [--kills 3] [--seed 0] [--keep DIR]

Exit status 0 when every trial passes, 1 otherwise.
"""

from __future__ import annotations

import argparse
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CONFIG = """\
seed = 7
realizations = 10
steps = 20000
observables = ["n", "mu_max", "x_G"]
[network]
kind = "chain"
n = 8
Ntilde = 1e-7
[friction]
mu_d = 0.5
[friction.static]
name = "gaussian"
mean = 0.6
std = 0.01
[driver]
name = "gaussian_steps"
sigma_theta = 1e-6
[execution]
checkpoint_every = 0.2
"""
MODES = ("parent", "worker", "group")


def start(config: Path, out: Path, resume: bool) -> subprocess.Popen:
    args = [sys.executable, "-m", "slidernet", "run", str(config), "--out", str(out), "--workers", "2",
            "--no-progress", *(["--resume"] if resume else [])]
    return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def has_run(out: Path) -> bool:
    """Whether ``out`` holds a run to resume (its identity was saved)."""
    return (out / "checkpoint" / "run.json").exists()


def children(pid: int) -> set[int]:
    """The processes whose parent is ``pid`` (every thread's children), from /proc."""
    found: set[int] = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found.update(int(c) for c in (task / "children").read_text().split())
        except OSError:
            pass
    return found


def gone(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return True
    return state in ("Z", "X")


def watch(proc: subprocess.Popen, until: float, seen: set[int]) -> None:
    """Collect the run's processes every 10 ms until ``until`` (monotonic s) or its end."""
    while time.monotonic() < until and proc.poll() is None:
        seen.update(children(proc.pid))
        time.sleep(0.01)
    seen.update(children(proc.pid))


def same_bits(a_path: Path, b_path: Path) -> str | None:
    from slidernet.io import read_result

    a, b = read_result(a_path), read_result(b_path)
    if set(a.variables) != set(b.variables):
        return f"variables differ: {sorted(set(a.variables) ^ set(b.variables))}"
    for name in a.variables:
        if not np.array_equal(a[name].values, b[name].values, equal_nan=a[name].dtype.kind == "f"):
            return f"{name} differs"
    return None


def trial(k: int, mode: str, rng: random.Random, config: Path, folder: Path, reference: Path, span: float,
          kills: int) -> tuple[bool, str]:
    out = folder / f"trial{k:02d}"
    seen: set[int] = set()
    notes = []
    for _ in range(rng.randint(1, kills)):
        # As a user would: --resume where a run was saved; a run killed before it saved its identity
        # (while loading the kernels) is started again.
        proc = start(config, out, resume=has_run(out))
        seen.add(proc.pid)
        delay = rng.uniform(0.0, 1.2 * span)
        watch(proc, time.monotonic() + delay, seen)
        if proc.poll() is not None:  # finished (or failed) before the kill
            notes.append(f"ended before {delay:.2f} s (rc {proc.returncode})")
            if proc.returncode != 0:
                return False, "; ".join(notes) + f": {proc.stderr.read().strip()}"
            break
        hit = mode
        if mode == "group":
            os.killpg(proc.pid, signal.SIGKILL)
        else:
            workers = sorted(children(proc.pid)) if mode == "worker" else []
            if mode == "worker" and not workers:
                hit = "parent (no worker yet)"  # before the pool exists, the parent is all there is
            os.kill(workers[0] if workers else proc.pid, signal.SIGKILL)
        _, err = proc.communicate(timeout=600)
        notes.append(f"{hit} killed at {delay:.2f} s (rc {proc.returncode})")
        if hit == "worker" and proc.returncode not in (0, 2):
            return False, "; ".join(notes) + f": a killed worker gave rc {proc.returncode}: {err.strip()}"
        if hit == "worker" and proc.returncode == 2 and "A worker process was killed by SIGKILL" not in err:
            return False, "; ".join(notes) + f": a killed worker said: {err.strip()}"
        if (out / "result.nc").exists() and not (out / "checkpoint").exists():
            break  # the kill came after the run had finished
    if not ((out / "result.nc").exists() and not (out / "checkpoint").exists()):
        proc = start(config, out, resume=has_run(out))
        seen.add(proc.pid)
        watch(proc, float("inf"), seen)
        _, err = proc.communicate(timeout=600)
        if proc.returncode != 0:
            return False, "; ".join(notes) + f"; the last resume failed (rc {proc.returncode}): {err.strip()}"
    deadline = time.monotonic() + 10  # a hang guard: a process killed by a signal ends at once
    while time.monotonic() < deadline and not all(gone(p) for p in seen):
        time.sleep(0.05)
    left = sorted(p for p in seen if not gone(p))
    if left:
        for pid in left:
            os.kill(pid, signal.SIGKILL)
        return False, "; ".join(notes) + f"; orphan processes {left}"
    extra = sorted(p.name for p in out.iterdir() if p.name != "result.nc")
    if extra:
        return False, "; ".join(notes) + f"; left in the folder: {extra}"
    differs = same_bits(out / "result.nc", reference)
    if differs:
        return False, "; ".join(notes) + f"; {differs}"
    return True, "; ".join(notes) + f"; {len(seen)} processes, all ended"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=24)
    parser.add_argument("--kills", type=int, default=3, help="at most this many kills per trial (default 3)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random delays and kill counts")
    parser.add_argument("--keep", type=Path, help="work in this folder and keep it (default: a temporary one)")
    args = parser.parse_args()
    if not sys.platform.startswith("linux"):
        print("fault_injection.py reads /proc: Linux only.", file=sys.stderr)
        return 2
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        config = folder / "faults.toml"
        config.write_text(CONFIG)
        t0 = time.monotonic()
        proc = start(config, folder / "reference", resume=False)
        _, err = proc.communicate()
        if proc.returncode != 0:
            print(f"the reference run failed: {err}", file=sys.stderr)
            return 1
        span = time.monotonic() - t0
        reference = folder / "reference" / "result.nc"
        print(f"uninterrupted run: {span:.1f} s; {args.trials} trials, up to {args.kills} kills each, seed "
              f"{args.seed}")
        failures = 0
        killed = {mode: 0 for mode in MODES}
        for k in range(args.trials):
            mode = MODES[k % len(MODES)]
            ok, what = trial(k, mode, rng, config, folder, reference, span, args.kills)
            failures += not ok
            killed[mode] += what.count(f"{mode} killed at ")
            print(f"{k:3d} {mode:7s} {'ok  ' if ok else 'FAIL'} {what}", flush=True)
        print(f"{args.trials - failures} of {args.trials} trials passed; kills delivered: "
              + ", ".join(f"{n} of the {mode}" for mode, n in killed.items()))
        return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
