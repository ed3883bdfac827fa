"""Where the 2D kernel spends its time, instruction by instruction: perf samples mapped onto numba's machine code.

    python benchmarks/profile_kernel.py [--network irregular|triangular] [--n 10000] [--steps 60]
                                        [--seconds 12] [--top 30] [--core 1]

``perf`` cannot name the functions that numba compiles at run time, and the
2D kernel is one function anyway (every helper is inlined into
``run_plane``). This script therefore runs one realization in a child
process, which writes the address and the bytes of ``run_plane``'s machine
code to a temporary folder before it starts the timed part; the parent
samples the child with ``perf record -e cpu-clock`` (a software clock: no
hardware counters are needed), disassembles the bytes with ``objdump``, and
counts the samples at each instruction.

It prints the share of the samples inside the kernel, the busiest symbols
outside it, and the ``--top`` instructions with the three before each. A
sample lands on the instruction that waits, so a load that misses the cache
shows as the instruction after it (or the first that uses its value): read
the context, not only the instruction. Numbers are shares of the samples
inside the kernel.

The network is the one of ``bench_vs_c.py``'s rows 8 and 9 (irregular, network
seed 0, Ntilde = sigma_theta = 1e-7, thresholds N(0.6, 0.01) above mu_d = 0.5)
or its triangular lattice (``--n`` is then the side L). Needs Linux, ``perf``
(with ``kernel.perf_event_paranoid`` <= 2 for a process of one's own) and
``objdump``.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
_CODE_BYTES = 200_000  # more than run_plane's machine code (about 30 kB)


def child(network: str, n: int, steps: int, warm: int, folder: Path) -> None:
    """Build the realization, write the kernel's address and code, signal, then run to the end."""
    import ctypes

    import numpy as np

    sys.path.insert(0, str(HERE))
    import bench_vs_c as bench

    from slidernet import kernels
    from slidernet.config import load_config
    from slidernet.solver import Realization, Scene

    def config(size: int, n_steps: int) -> dict:
        if network == "irregular":
            return bench._irregular_config(size, n_steps)
        return bench._lattice_config(size, n_steps)

    Realization(Scene.from_config(load_config(config(16 if network == "irregular" else 4, 2))),
                np.random.SeedSequence(0)).advance()
    real = Realization(Scene.from_config(load_config(config(n, steps))), np.random.SeedSequence(1))
    real.advance(warm)
    (_, cres), = list(kernels.run_plane.overloads.items())
    address = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
    (folder / "code.bin").write_bytes(ctypes.string_at(address, _CODE_BYTES))
    (folder / "ready.json").write_text(json.dumps({"pid": os.getpid(), "address": address}))
    t0 = time.perf_counter()
    n0 = real.n
    real.advance()
    (folder / "done.json").write_text(json.dumps({"slips": real.n - n0, "seconds": time.perf_counter() - t0}))


def _instructions(code: Path) -> list[tuple[int, str]]:
    out = subprocess.run(["objdump", "-D", "-b", "binary", "-m", "i386:x86-64", str(code)],
                         capture_output=True, text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        m = re.match(r"\s+([0-9a-f]+):\s+((?:[0-9a-f]{2} )+)\s*(.*)", line)
        if m and m.group(3).strip():
            rows.append((int(m.group(1), 16), " ".join(m.group(3).split())))
    return rows


def report(samples: list[str], address: int, rows: list[tuple[int, str]], top: int) -> None:
    inside: collections.Counter[int] = collections.Counter()
    outside: collections.Counter[str] = collections.Counter()
    for line in samples:
        parts = line.split()
        if not parts:
            continue
        offset = int(parts[0], 16) - address
        if 0 <= offset < _CODE_BYTES:
            inside[offset] += 1
        else:
            outside[" ".join(parts[1:])[:60] or "[unknown]"] += 1
    total = sum(inside.values()) + sum(outside.values())
    n_in = sum(inside.values())
    print(f"{total} samples, {100 * n_in / max(total, 1):.1f} % inside run_plane")
    print("outside: " + ", ".join(f"{name} {100 * c / total:.1f} %" for name, c in outside.most_common(6)))
    where = {off: k for k, (off, _) in enumerate(rows)}
    print("\n| offset | share | cumulative | instruction | the three before it |\n|---|---|---|---|---|")
    cum = 0
    for offset, count in inside.most_common(top):
        cum += count
        k = where.get(offset)
        ins = rows[k][1] if k is not None else "?"
        before = " ; ".join(r[1] for r in rows[max(k - 3, 0):k]) if k else "?"
        print(f"| {offset:#x} | {100 * count / n_in:.2f} % | {100 * cum / n_in:.1f} % | `{ins}` | `{before}` |")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--network", choices=("irregular", "triangular"), default="irregular")
    parser.add_argument("--n", type=int, default=10_000, help="nodes (irregular) or side L (triangular)")
    parser.add_argument("--steps", type=int, default=60, help="thermal steps (must outlast --seconds)")
    parser.add_argument("--warm", type=int, default=2, help="steps run before sampling starts (default 2)")
    parser.add_argument("--seconds", type=float, default=12.0, help="seconds of sampling (default 12)")
    parser.add_argument("--top", type=int, default=30, help="instructions listed (default 30)")
    parser.add_argument("--core", type=int, default=1, help="the core of the child (default 1)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.network, args.n, args.steps, args.warm, Path(args.child))
        return 0
    missing = [tool for tool in ("perf", "objdump") if shutil.which(tool) is None]
    if missing:
        print(f"profile_kernel.py needs {' and '.join(missing)}: not found on PATH.", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="slidernet-profile-") as tmp:
        folder = Path(tmp)
        cmd = [sys.executable, str(Path(__file__).resolve()), "--network", args.network, "--n", str(args.n),
               "--steps", str(args.steps), "--warm", str(args.warm), "--child", tmp]
        if shutil.which("taskset"):
            cmd = ["taskset", "-c", str(args.core), *cmd]
        proc = subprocess.Popen(cmd)
        ready = folder / "ready.json"
        while not ready.exists():  # the child writes it once its code is compiled and the run is set up
            if proc.poll() is not None:
                print(f"the child exited with {proc.returncode} before the run started", file=sys.stderr)
                return 1
            time.sleep(0.2)
        info = json.loads(ready.read_text())
        data = folder / "perf.data"
        rec = subprocess.run(["perf", "record", "-q", "-e", "cpu-clock", "-F", "4000", "-p", str(info["pid"]),
                              "-o", str(data), "--", "sleep", str(args.seconds)], capture_output=True, text=True)
        finished = (folder / "done.json").exists()
        proc.wait()
        if rec.returncode != 0:
            print(f"perf record failed: {rec.stderr.strip()[-500:]}", file=sys.stderr)
            return 1
        if finished:
            print("warning: the run ended before the sampling did; raise --steps", file=sys.stderr)
        samples = subprocess.run(["perf", "script", "-i", str(data), "-F", "ip,sym"], capture_output=True,
                                 text=True).stdout.splitlines()
        done = json.loads((folder / "done.json").read_text())
        print(f"{args.network} {args.n}: {done['slips'] / done['seconds'] / 1e6:.2f} M slips/s over the run "
              f"after step {args.warm} (sampled for {args.seconds:g} s; load average {os.getloadavg()[0]:.2f})")
        report(samples, info["address"], _instructions(folder / "code.bin"), args.top)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
