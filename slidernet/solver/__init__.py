"""The quasi-static, event-driven solver: from a validated configuration to the records of a realization.

- :mod:`~slidernet.solver.scene`: :class:`Scene`, everything derived once
  from a configuration (network, operators, the kernel picked for it);
- :mod:`~slidernet.solver.streams`: :class:`Streams`, the one owner of a
  realization's random side (its streams, the order in which its draws are
  read, the buffers and their refill);
- :mod:`~slidernet.solver.snapshot`: :class:`Snapshot`, a realization's
  whole state as plain data, and the checks its restore shares;
- :mod:`~slidernet.solver.backends`: one backend per kernel;
- :mod:`~slidernet.solver.realization`: :class:`Realization`, one
  realization's state, advanced by the compiled kernels.
- :mod:`~slidernet.solver.creep`: the creep observables of one realization
  (x_G per cycle, the reptation velocity, the creep events), reduced from its
  event catalogue.
- :mod:`~slidernet.solver.inject`: :func:`injected_thresholds`, the raised
  copy of the thresholds that the injected twin of a test reads
  (``[tilt] inject``).
"""

from slidernet.model.network import pair_tilt_applies
from slidernet.solver.inject import injected_thresholds
from slidernet.solver.realization import Realization, simulate
from slidernet.solver.scene import (
    EVENT_CHUNK,
    Scene,
    build_network,
    record_times,
    tilt_avalanche_cap,
)
from slidernet.solver.snapshot import Snapshot
from slidernet.solver.streams import Streams, draw_thetas, horizontal_draws, realization_streams

__all__ = ["EVENT_CHUNK", "Realization", "Scene", "Snapshot", "Streams", "build_network", "draw_thetas",
           "horizontal_draws", "injected_thresholds", "pair_tilt_applies", "realization_streams", "record_times",
           "simulate", "tilt_avalanche_cap"]
