"""Layout of the kernels' state arrays and return codes.

A kernel's whole state lives in two arrays, ``ist`` (int64) and ``fst``
(float64), plus the per-node arrays, so that a kernel can stop at any clean
point and resume later (buffer refills, checkpoints).
"""

from __future__ import annotations

import os
from collections.abc import Callable

import numba
import numpy as np
import platformdirs
from numba import njit

try:
    from numba.core.cpu import CPUTargetOptions

    _NUMBA_HAS_NRT_FLAG = hasattr(CPUTargetOptions, "_nrt")
except ImportError:  # pragma: no cover - numba moved its internals
    _NUMBA_HAS_NRT_FLAG = False


def kernel_jit(**options) -> Callable:
    """``numba.njit`` for the kernels: compiled once, cached on disk, no reference counting.

    The kernels never allocate arrays; they only read and write the arrays
    they are given. With numba's reference counting (NRT) on, every call of
    a helper that takes arrays increments and decrements each array's count
    atomically: about 4.5 ns per array per call, measured with numba 0.68,
    which made the heap bookkeeping of a 2D slip several times slower than
    its arithmetic. ``_nrt=False`` compiles without it. It is a private
    numba flag, so a numba that refuses it gets the plain decorator.
    """
    if _NUMBA_HAS_NRT_FLAG:
        options["_nrt"] = False
    return cached_jit(**options)


def cache_dir() -> str:
    """Where numba keeps slidernet's compiled kernels.

    ``NUMBA_CACHE_DIR`` when the user set it, else ``numba`` in the per-user
    cache directory (``platformdirs.user_cache_dir("slidernet")``, e.g.
    ``~/.cache/slidernet/numba`` on Linux). Never inside the installed
    package: cache files left in ``site-packages/slidernet/`` by a
    ``pip install .`` outlive a ``pip uninstall`` and then shadow an editable
    install as an empty namespace package.
    """
    return os.environ.get("NUMBA_CACHE_DIR") or os.path.join(platformdirs.user_cache_dir("slidernet"), "numba")


def cached_jit(**options) -> Callable:
    """``numba.njit(cache=True, **options)`` with the cache in :func:`cache_dir`.

    numba picks a function's cache folder when the function is decorated,
    from ``numba.config.CACHE_DIR``; setting it only for the time of the
    decoration keeps every other package's numba cache where it was.
    """

    def decorate(func: Callable) -> Callable:
        saved = numba.config.CACHE_DIR
        numba.config.CACHE_DIR = cache_dir()
        try:
            return njit(cache=True, **options)(func)
        finally:
            numba.config.CACHE_DIR = saved

    return decorate

# Return codes.
DONE = 0
NEED_MU = 1  # the horizontal threshold buffer is empty
NEED_TILT = 2  # the tilt-test buffers ran out during a test (rolled back)
AVALANCHE_LIMIT = 3  # an avalanche exceeded max_slips
TILT_LIMIT = 4  # a tilt test exceeded its iteration cap
RECOMPUTE = 5  # time to recompute the forces from the displacements (drift control)
NEED_EVENTS = 6  # the event catalogue's buffer is full

# Integer state (ist) slots.
Q = 0  # next thermal step: the segment thetas[q] -> thetas[q+1]
N_SLIPS = 1  # cumulative rearrangements n
REC = 2  # index of the next record time
MU_POS = 3  # read position in the threshold buffer
TMU_POS = 4  # read position in the tilt-test threshold buffer
TU_POS = 5  # read position in the tilt-test uniform buffer
N_RECORDS = 6  # draws that exceeded the running mu_max
ARGMAX = 7  # node holding mu_max
ERR_NODE = 8  # node named by an error
AV_SLIPS = 9  # slips in the current avalanche
HEAP_SIZE = 10  # size of the unstable-node heap (pair: 1 while a slider is unstable)
N_EVENTS = 11  # driving events (= avalanches)
STARTED = 12  # 1 once the t = 0 record is written
UP_SIZE = 13  # size of the heap of upper critical thetas (driving with theta increasing)
DOWN_SIZE = 14  # size of the heap of lower critical thetas (theta decreasing)
SINCE_RECOMPUTE = 15  # slips since the forces were last recomputed from u
IN_AVALANCHE = 16  # 1 between a driving slip and the end of its avalanche
EV_POS = 17  # events written to the catalogue buffer
EV_ON = 18  # 1 while the event catalogue is recorded
N_IST = 19

N_AVALANCHE_BINS = 63  # avalanche sizes s are binned by floor(log2 s); 2**62 fits in int64

# Float state (fst) slots.
THETA = 0  # current theta / Ntilde
XG = 1  # centre-of-mass displacement / (Ntilde l0)
MU_MAX = 2  # largest threshold mu_s
U = 3  # run_pair only: the paper's u / Ntilde (spring length change)
YG = 4  # run_vec only: centre-of-mass displacement along y / (Ntilde l0)
EV_T = 5  # time of the current driving event, in tau_th (q + fraction of the segment)
N_FST = 6

TILT_MAX_ITER = 1_000_000




def empty_state() -> tuple[np.ndarray, np.ndarray]:
    """Fresh (ist, fst) arrays."""
    return np.zeros(N_IST, dtype=np.int64), np.zeros(N_FST, dtype=np.float64)


@kernel_jit()
def write_record(ist, fst, out_n, out_mu_max, out_xg, out_records):
    """Write the counters into record slot ``ist[REC]`` and advance it."""
    k = ist[REC]
    out_n[k] = ist[N_SLIPS]
    out_mu_max[k] = fst[MU_MAX]
    out_xg[k] = fst[XG]
    out_records[k] = ist[N_RECORDS]
    ist[REC] = k + 1
