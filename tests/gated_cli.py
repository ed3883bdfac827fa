"""The ``slidernet`` command with one more threshold law, ``gated``, for the interrupt tests.

``gated`` draws mu_s uniformly in [low, high] (above mu_d: nothing is
truncated). When the environment names a gate folder
(``SLIDERNET_TEST_GATE``), a process that has drawn more than
``SLIDERNET_TEST_GATE_AFTER`` thresholds stops in ``sample``: it creates
``waiting-<pid>-<thread>`` in the folder and waits until the file ``open``
exists there (once per process and thread: a Dask worker runs realizations
in threads). A test thereby holds a run at a known point, with
every running realization part-way through and checkpointed, while it sends
a signal or kills the run: it never races the machine's speed. Without the
variable the law is a plain uniform, so a run's bits do not depend on the
gate. A gate that never opens is a plugin that never returns.

With ``SLIDERNET_TEST_GATE_FAULT`` set, a process at the gate does not wait:
it raises the plugin's fault instead, ``raise`` (a ValueError), ``exit``
(``sys.exit(5)``) or ``interrupt`` (KeyboardInterrupt).

Usage: ``python tests/gated_cli.py run CONFIG --out DIR ...`` (the
arguments of ``slidernet``).
"""

from __future__ import annotations

import os
import sys
import threading
import time
from pathlib import Path
from typing import ClassVar

import numpy as np

import slidernet
from slidernet.cli import main


class Gated:
    """Uniform p(mu_s) on [low, high] with a gate in ``sample`` (see the module docstring)."""

    drawn: ClassVar[dict[tuple[int, int], int]] = {}
    passed: ClassVar[set[tuple[int, int]]] = set()

    def __init__(self, low: float = 0.55, high: float = 0.65) -> None:
        self.low = float(low)
        self.high = float(high)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        gate = os.environ.get("SLIDERNET_TEST_GATE")
        who = (os.getpid(), threading.get_ident())
        if gate and who not in Gated.passed:
            Gated.drawn[who] = Gated.drawn.get(who, 0) + size
            if Gated.drawn[who] > int(os.environ["SLIDERNET_TEST_GATE_AFTER"]):
                Path(gate, f"waiting-{who[0]}-{who[1]}").touch()
                fault = os.environ.get("SLIDERNET_TEST_GATE_FAULT")
                if fault == "raise":
                    raise ValueError("the gate's fault")
                if fault == "exit":
                    sys.exit(5)
                if fault == "interrupt":
                    raise KeyboardInterrupt
                while not Path(gate, "open").exists():
                    time.sleep(0.01)
                Gated.passed.add(who)
        return rng.uniform(self.low, self.high, size)

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        return np.clip((np.asarray(x, dtype=float) - self.low) / (self.high - self.low), 0.0, 1.0)


if __name__ == "__main__":
    slidernet.register_distribution("gated", Gated)
    sys.exit(main(sys.argv[1:]))
