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
import json
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


# -- the faults of a cluster, a shared folder and a plugin that never returns ------------------------------------
def wait_for(predicate, what: str, timeout: float = 300.0) -> None:
    """Poll ``predicate`` every 20 ms until it holds (a hang guard of ``timeout`` s, never a synchronisation)."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise RuntimeError(f"gave up waiting for {what} after {timeout:g} s")
        time.sleep(0.02)


def one_line_error(err: str) -> str | None:
    """None if ``err`` is slidernet's one-line kind of failure (no traceback); else what is wrong with it."""
    if "Traceback" in err:
        return "a traceback: " + err.strip()[-600:]
    if not any(line.startswith("slidernet:") for line in err.splitlines()):
        return "no 'slidernet:' line: " + err.strip()[-600:]
    return None


def saved(out: Path) -> bool:
    """Whether the run in ``out`` has saved some work (a finished block or a realization in progress)."""
    folder = out / "checkpoint"
    return folder.is_dir() and any(p.name.startswith(("block-", "partial-")) for p in folder.iterdir())


class DaskCluster:
    """A scheduler and two single-threaded worker processes, started as a user would, with the ``dask`` command."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.file = folder / f"scheduler-{time.monotonic_ns()}.json"
        dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
        self.scheduler = subprocess.Popen([*dask, "--scheduler-file", str(self.file), "--port", "0",
                                           "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                          start_new_session=True)
        wait_for(lambda: self.file.exists() and self.file.stat().st_size > 0, "the scheduler's file", 60)
        self.address = json.loads(self.file.read_text())["address"]
        self.workers = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker",
                                          "--scheduler-file", str(self.file), "--nthreads", "1", "--no-dashboard"],
                                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                         start_new_session=True, cwd=folder)
                        for _ in range(2)]

    def worker_processes(self) -> list[int]:
        """The worker processes proper (each nanny's child), where the tasks run."""
        return sorted(c for w in self.workers for c in children(w.pid))

    def close(self) -> None:
        for proc in [*self.workers, self.scheduler]:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            proc.wait()


def start_on(config: Path, out: Path, scheduler: str, resume: bool) -> subprocess.Popen:
    args = [sys.executable, "-m", "slidernet", "run", str(config), "--out", str(out), "--scheduler", scheduler,
            "--no-progress", *(["--resume"] if resume else [])]
    return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def fault_dask_worker(folder: Path, config: Path, reference: Path) -> tuple[bool, str]:
    """Kill -9 one Dask worker once the run has saved work: Dask runs its tasks again; the same bits."""
    cluster = DaskCluster(folder)
    out = folder / "dask_worker"
    try:
        proc = start_on(config, out, cluster.address, resume=False)
        wait_for(lambda: saved(out) or proc.poll() is not None, "the run's first save")
        victims = cluster.worker_processes()
        if proc.poll() is not None or not victims:
            return False, f"the run ended (rc {proc.returncode}) before a worker could be killed"
        os.kill(victims[0], signal.SIGKILL)
        _, err = proc.communicate(timeout=600)
    finally:
        cluster.close()
    if proc.returncode != 0:
        return False, f"rc {proc.returncode}: {err.strip()[-600:]}"
    differs = same_bits(out / "result.nc", reference)
    return differs is None, differs or "a worker killed after the first save; the run finished, same bits"


def fault_dask_scheduler(folder: Path, config: Path, reference: Path) -> tuple[bool, str]:
    """Kill -9 the scheduler once the run has saved work: one line and exit 2; resumed on a new cluster."""
    cluster = DaskCluster(folder)
    out = folder / "dask_scheduler"
    try:
        proc = start_on(config, out, cluster.address, resume=False)
        wait_for(lambda: saved(out) or proc.poll() is not None, "the run's first save")
        if proc.poll() is not None:
            return False, f"the run ended (rc {proc.returncode}) before the scheduler could be killed"
        os.killpg(cluster.scheduler.pid, signal.SIGKILL)
        _, err = proc.communicate(timeout=600)
    finally:
        cluster.close()
    bad = one_line_error(err)
    if proc.returncode != 2 or bad or "--resume" not in err:
        return False, f"the scheduler's death gave rc {proc.returncode}: {bad or err.strip()[-600:]}"
    cluster = DaskCluster(folder)
    try:
        proc = start_on(config, out, cluster.address, resume=True)
        _, err = proc.communicate(timeout=600)
    finally:
        cluster.close()
    if proc.returncode != 0:
        return False, f"the resume on a new cluster gave rc {proc.returncode}: {err.strip()[-600:]}"
    differs = same_bits(out / "result.nc", reference)
    return differs is None, differs or "scheduler killed after the first save: one line, exit 2; resumed, same " \
                                       "bits"


def fault_shared_folder(folder: Path, config: Path, reference: Path) -> tuple[bool, str]:
    """A run and a sweep in one folder, both orders: the second is refused while the first works; nothing lost."""
    notes = []
    for first in ("sweep", "run"):
        out = folder / f"shared_{first}_first"
        sweep = [sys.executable, "-m", "slidernet", "sweep", str(config), "--set", "driver.sigma_theta=1e-6,2e-6",
                 "--out", str(out), "--workers", "2", "--no-progress"]
        run = [sys.executable, "-m", "slidernet", "run", str(config), "--out", str(out), "--workers", "2",
               "--no-progress"]
        a, b = (sweep, run) if first == "sweep" else (run, sweep)
        proc = subprocess.Popen(a, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        lock = out / ".slidernet.lock"
        wait_for(lambda lock=lock, proc=proc: lock.exists() or proc.poll() is not None, f"the {first}'s lock")
        second = subprocess.run(b, capture_output=True, text=True, timeout=600)
        _, err = proc.communicate(timeout=600)
        if proc.returncode != 0:
            return False, f"the {first} in the folder failed (rc {proc.returncode}): {err.strip()[-600:]}"
        if second.returncode != 2 or one_line_error(second.stderr) or "in use" not in second.stderr:
            return False, (f"the second job in the folder of a {first} gave rc {second.returncode}: "
                           f"{second.stderr.strip()[-600:]}")
        if first == "run":
            differs = same_bits(out / "result.nc", reference)
            if differs:
                return False, f"the run's result changed: {differs}"
        elif not (out / "sweep.json").exists():
            return False, "the sweep's sweep.json is gone"
        notes.append(f"{first} first: the other refused ({second.stderr.strip().splitlines()[-1][:80]}...)")
    return True, "; ".join(notes)


HANG_PLUGIN = """\"\"\"gaussian_steps, whose realizations never return once a file HANG is in the folder.

The checks before the run draw from the driver in the main process; the realizations run in the workers
(--workers 2, forked: they inherit MAIN, the process that imported this file first).
\"\"\"
import os
import time

import slidernet
from slidernet.plugins.drivers import GaussianSteps

MAIN = os.getpid()


class MaybeHanging(GaussianSteps):
    def thetas(self, rng, steps):
        if os.path.exists("HANG") and os.getpid() != MAIN:
            open(f"hanging-{os.getpid()}", "w").close()
            while True:
                time.sleep(3600)
        return super().thetas(rng, steps)


slidernet.register_driver("maybe_hanging", MaybeHanging)
"""


def fault_hanging_plugin(folder: Path, config: Path, group: bool) -> tuple[bool, str]:
    """A driver that never returns: one SIGTERM (to the main process, or to the group) stops the run within
    seconds, with one line and exit 143; resumed without the hang, the run gives the bits of a run that never
    hung."""
    work = folder / f"hang_{'group' if group else 'main'}"
    work.mkdir()
    (work / "hang_plugin.py").write_text(HANG_PLUGIN)
    text = config.read_text().replace('name = "gaussian_steps"', 'name = "maybe_hanging"')
    text = 'plugins = ["hang_plugin.py"]\n' + text.replace("[execution]", "[execution]\nstop_timeout = 5")
    (work / "hang.toml").write_text(text)

    def start_here(out: str, resume: bool = False) -> subprocess.Popen:
        args = [sys.executable, "-m", "slidernet", "run", "hang.toml", "--out", out, "--workers", "2",
                "--no-progress", *(["--resume"] if resume else [])]
        return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=work,
                                start_new_session=True)

    plain = start_here("plain")
    _, err = plain.communicate(timeout=600)
    if plain.returncode != 0:
        return False, f"the run without the hang failed (rc {plain.returncode}): {err.strip()[-600:]}"
    (work / "HANG").touch()
    proc = start_here("hung")
    wait_for(lambda: any(work.glob("hanging-*")) or proc.poll() is not None, "the plugin to hang")
    t0 = time.monotonic()
    (os.killpg if group else os.kill)(proc.pid, signal.SIGTERM)
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        return False, "one SIGTERM did not stop a run whose plugin never returns within 60 s"
    took = time.monotonic() - t0
    bad = one_line_error(err)
    if proc.returncode != 128 + signal.SIGTERM or bad:
        return False, f"SIGTERM gave rc {proc.returncode}: {bad or err.strip()[-600:]}"
    (work / "HANG").unlink()
    again = start_here("hung", resume=has_run(work / "hung"))
    _, err = again.communicate(timeout=600)
    if again.returncode != 0:
        return False, f"the resume failed (rc {again.returncode}): {err.strip()[-600:]}"
    differs = same_bits(work / "hung" / "result.nc", work / "plain" / "result.nc")
    return differs is None, differs or (f"stopped {took:.1f} s after one SIGTERM (to the "
                                        f"{'group' if group else 'main process'}), exit 143; resumed, same bits")


FAULTS = ("kills", "dask-worker", "dask-scheduler", "folder", "hang")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=24)
    parser.add_argument("--kills", type=int, default=3, help="at most this many kills per trial (default 3)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random delays and kill counts")
    parser.add_argument("--faults", default="kills", help="comma-separated, among " + ", ".join(FAULTS)
                        + " or 'all' (default: kills)")
    parser.add_argument("--fuzz", type=int, default=0, metavar="N",
                        help="also run N cases of the configuration fuzz (benchmarks/config_fuzz.py)")
    parser.add_argument("--keep", type=Path, help="work in this folder and keep it (default: a temporary one)")
    args = parser.parse_args()
    if not sys.platform.startswith("linux"):
        print("fault_injection.py reads /proc: Linux only.", file=sys.stderr)
        return 2
    faults = FAULTS if args.faults == "all" else tuple(f for f in args.faults.split(",") if f)
    unknown = sorted(set(faults) - set(FAULTS))
    if unknown:
        print(f"unknown faults {unknown}; among {', '.join(FAULTS)}", file=sys.stderr)
        return 2
    rng = random.Random(args.seed)
    failures = 0
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
        print(f"uninterrupted run: {span:.1f} s")
        if "kills" in faults:
            print(f"{args.trials} trials, up to {args.kills} kills each, seed {args.seed}")
            killed = {mode: 0 for mode in MODES}
            for k in range(args.trials):
                mode = MODES[k % len(MODES)]
                ok, what = trial(k, mode, rng, config, folder, reference, span, args.kills)
                failures += not ok
                killed[mode] += what.count(f"{mode} killed at ")
                print(f"{k:3d} {mode:7s} {'ok  ' if ok else 'FAIL'} {what}", flush=True)
            print("kills delivered: " + ", ".join(f"{n} of the {mode}" for mode, n in killed.items()))
        scenarios = {
            "dask-worker": lambda: [fault_dask_worker(folder, config, reference)],
            "dask-scheduler": lambda: [fault_dask_scheduler(folder, config, reference)],
            "folder": lambda: [fault_shared_folder(folder, config, reference)],
            "hang": lambda: [fault_hanging_plugin(folder, config, group=False),
                             fault_hanging_plugin(folder, config, group=True)],
        }
        for name in faults:
            for ok, what in scenarios[name]() if name != "kills" else []:
                failures += not ok
                print(f"{name:15s} {'ok  ' if ok else 'FAIL'} {what}", flush=True)
        if args.fuzz:
            import config_fuzz  # beside this script

            root = folder / "fuzz"
            root.mkdir()
            config_fuzz.warm(root, 1)
            done = config_fuzz.fuzz(args.fuzz, args.seed, 2, 60.0, 30.0, root)
            print(config_fuzz.summary(done))
            failures += sum(not c.ok for c in done)
        print(f"{failures} failure(s)")
        return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
