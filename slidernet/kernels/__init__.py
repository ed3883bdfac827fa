"""Compiled event-driven kernels (numba), one per scene.

Units are the internal ones of :mod:`slidernet.model.network`: forces in N,
stiffnesses in k0 = N/(Ntilde l0), lengths in Ntilde l0, and theta enters as
theta/Ntilde. In these units the paper's spring has k = 1, so equation
`critique` reads theta_c = u + mu_min s and equation `displacement` reads
Delta u = 2 (mu_min - mu_d) s.

"Model only what a scene needs", and compile only what it runs:

* :func:`run_pair` (``pair.py``) -- the paper's two sliders: scalars only;
  :func:`run_pair_tilt` adds the appendix's tilt test before every
  rearrangement (observable ``mu_eff``);
* :func:`run_network` (``network.py``) -- any network, one driving loop
  compiled for each geometry: 1D (``chain.py``: scalar forces, CSR rows of
  K; :func:`run_chain`, and :func:`run_chain_tilt` for a 2-node chain with
  the appendix's test) and 2D (``plane.py``: vector forces, 2x2 blocks of
  K; :func:`run_plane`, straight-line slips, and :func:`run_plane_exact`);
* with contact strengthening (``strength.py``), :func:`run_chain_aging`,
  :func:`run_plane_aging` and :func:`run_plane_exact_aging`, compiled only
  for scenes that ask for it;
* ``tilt_net.py`` -- the network tilt test at the recorded times, compiled
  only where a scene asks for it (``tilt_test_network``, and
  ``tilt_test_network_exact`` for the exact 2D slip).

Each variant is compiled on its first use and cached on disk
(``jit.py``), so a chain without ``mu_eff`` never compiles a tilt test
and never a 2D function.

The network kernel finds the next driving event from two tournament trees
keyed by each driven node's critical theta (one per direction of theta),
and relaxes avalanches from an indexed heap keyed by overload (``heap.py``);
a slip updates only the slipped node and its neighbours, O(degree log N).

On a 2-node chain ``run_network`` performs the *same floating-point
operations* as ``run_pair``, so the two agree to the bit (tested). All
state lives in arrays (``state.py`` names them); a kernel returns at a clean
point when a buffer of random draws runs low, so that Python can refill it
with the plugin's ``sample`` in batches.
"""

from slidernet.kernels.chain import (
    init_chain_heaps,
    init_chain_heaps_aging,
    run_chain,
    run_chain_aging,
    run_chain_tilt,
)
from slidernet.kernels.pair import run_pair, run_pair_tilt
from slidernet.kernels.plane import (
    init_plane_heaps,
    init_plane_heaps_aging,
    run_plane,
    run_plane_aging,
    run_plane_exact,
    run_plane_exact_aging,
    stiffness_times,
)
from slidernet.kernels.state import (
    AGE_EDGES,
    AVALANCHE_LIMIT,
    DONE,
    N_AGE_BINS,
    N_AVALANCHE_BINS,
    NEED_EVENTS,
    NEED_MU,
    NEED_TILT,
    RECOMPUTE,
    SLID_AWAY,
    STATE,
    TILT_LIMIT,
    TILT_MAX_ITER,
    TILT_NEED_DRAWS,
    TILT_TOO_LONG,
    AgingNodes,
    Catalogue,
    Chain,
    Draws,
    Heaps,
    Nodes,
    Plane,
    Series,
    Settings,
    new_state,
)
from slidernet.kernels.tilt import tilt_status, tilt_test_pair

__all__ = [
    "AGE_EDGES",
    "AVALANCHE_LIMIT",
    "DONE",
    "NEED_EVENTS",
    "NEED_MU",
    "NEED_TILT",
    "N_AGE_BINS",
    "N_AVALANCHE_BINS",
    "RECOMPUTE",
    "SLID_AWAY",
    "STATE",
    "TILT_LIMIT",
    "TILT_MAX_ITER",
    "TILT_NEED_DRAWS",
    "TILT_TOO_LONG",
    "AgingNodes",
    "Catalogue",
    "Chain",
    "Draws",
    "Heaps",
    "Nodes",
    "Plane",
    "Series",
    "Settings",
    "init_chain_heaps",
    "init_chain_heaps_aging",
    "init_plane_heaps",
    "init_plane_heaps_aging",
    "new_state",
    "run_chain",
    "run_chain_aging",
    "run_chain_tilt",
    "run_pair",
    "run_pair_tilt",
    "run_plane",
    "run_plane_aging",
    "run_plane_exact",
    "run_plane_exact_aging",
    "stiffness_times",
    "tilt_status",
    "tilt_test_pair",
]
