"""Compiled event-driven kernels (numba), one per scene.

Units are the internal ones of :mod:`slidernet.model.network`: forces in N,
stiffnesses in k0 = N/(Ntilde l0), lengths in Ntilde l0, and theta enters as
theta/Ntilde. In these units the paper's spring has k = 1, so equation
`critique` reads theta_c = u + mu_min s and equation `displacement` reads
Delta u = 2 (mu_min - mu_d) s.

"Model only what a scene needs":

* :func:`run_pair` (``pair.py``) -- the paper's two sliders: scalars only;
* :func:`run_csr` (``csr.py``) -- any 1D network: CSR neighbour lists;
* :func:`run_vec` (``vec.py``) -- any 2D network: 2x2 blocks of K, vector forces.

The network kernels find the next driving event from two indexed heaps
keyed by each driven node's critical theta (one per direction of theta),
and relax avalanches from a heap keyed by overload (``heap.py``); a slip
updates only the slipped node and its neighbours, O(degree log N).

On a 2-node chain ``run_csr`` performs the *same floating-point operations*
as ``run_pair``, so the two agree to the bit (tested). All state lives in
arrays (``state.py`` lists the slots); a kernel returns at a clean point
when a buffer of random draws runs low, so that Python can refill it with
the plugin's ``sample`` in batches.
"""

from slidernet.kernels.csr import init_csr_heaps, run_csr
from slidernet.kernels.pair import run_pair
from slidernet.kernels.state import *  # noqa: F403 - the slot and status constants
from slidernet.kernels.state import empty_state
from slidernet.kernels.tilt import tilt_test_pair
from slidernet.kernels.vec import init_vec_heaps, run_vec

__all__ = ["empty_state", "init_csr_heaps", "init_vec_heaps", "run_csr", "run_pair", "run_vec", "tilt_test_pair"]
