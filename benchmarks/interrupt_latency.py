"""How long Ctrl-C (SIGINT) and SIGTERM take to stop a run with long realizations, and what they save.

Starts ``slidernet run`` with 2 workers on realizations of about a minute or
more each (an 8 x 8 triangular lattice, 3e6 thermal steps), sends the signal
after ``--after`` seconds, and reports the exit status, the seconds from the
signal to the exit, and the realizations saved in progress (with the step
each reached). Resuming such a run to the bits of an uninterrupted one is
tested in tests/test_interrupts.py.

With ``--long-step`` every thermal step is itself long (a chain of 8 at
sigma_theta/Ntilde = 1e7: about 1e8 slips, a minute or more, per step), as a
realization stuck in a loop would be: the signal must still be served
within the step, at the next refill of a draw buffer.

    python benchmarks/interrupt_latency.py [--after 15] [--workers 2] [--long-step]
"""

from __future__ import annotations

import argparse
import json
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CONFIG = """\
seed = 1
realizations = 6
steps = 3000000
observables = ["n", "mu_max", "x_G"]
[network]
kind = "triangular"
shape = [8, 8]
Ntilde = 1e-7
[friction]
mu_d = 0.5
[friction.static]
name = "gaussian"
mean = 0.6
std = 0.01
[driver]
name = "gaussian_steps"
sigma_theta = 2e-7
[execution]
checkpoint_every = 60.0
"""


LONG_STEP = """\
# sigma_theta = 1 is a unit slip (1 K for alpha*DeltaT), far outside real materials: the point of this
# case, a step of minutes, is a stress test of the interrupt
allow_implausible = true
seed = 1
realizations = 4
steps = 3
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
sigma_theta = 1.0
[execution]
checkpoint_every = 60.0
"""


def measure(sig: signal.Signals, after: float, workers: int, folder: Path, config_text: str = CONFIG) -> dict:
    config = folder / "long.toml"
    config.write_text(config_text)
    out = folder / f"out-{sig.name}"
    proc = subprocess.Popen([sys.executable, "-m", "slidernet.cli", "run", str(config), "--out", str(out),
                             "--workers", str(workers), "--no-progress"], stderr=subprocess.PIPE, text=True)
    time.sleep(after)
    sent = time.monotonic()
    proc.send_signal(sig)
    _, err = proc.communicate()
    took = time.monotonic() - sent
    steps = []
    for f in sorted((out / "checkpoint").glob("partial-*.npz")):
        with np.load(f, allow_pickle=False) as z:
            header = json.loads(bytes(z["header"]).decode())
            steps.append((header["step"], header["n"]))
    return {"signal": sig.name, "exit_status": proc.returncode, "seconds_to_exit": round(took, 2),
            "saved_in_progress": len(steps), "steps_and_slips_reached": steps,
            "message": err.strip().splitlines()[-1]}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--after", type=float, default=15.0, help="seconds before the signal")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--long-step", action="store_true", help="every thermal step about 1e8 slips long")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for sig in (signal.SIGINT, signal.SIGTERM):
            print(json.dumps(measure(sig, args.after, args.workers, Path(tmp),
                                     LONG_STEP if args.long_step else CONFIG)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
