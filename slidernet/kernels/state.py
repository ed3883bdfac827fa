"""The kernels' state, named: one record of scalars and named groups of arrays.

A kernel's whole state lives in arrays it is given, so that it can stop at
any clean point and resume later (buffer refills, checkpoints):

* the scalars of a realization (counters, theta, x_G, ...) in one record of
  the structured dtype :data:`STATE` (a 1-element array, see
  :func:`new_state`; the kernels write its fields through ``state[0]``);
* the arrays in named tuples: :class:`Heaps`, :class:`Draws`,
  :class:`Series`, :class:`Catalogue`, :class:`Nodes` (:data:`AgingNodes`), and the network
  operators :class:`Chain` (1D) and :class:`Plane` (2D), with the run's
  constants in :class:`Settings`.

numba compiles a field of a record or of a named tuple to a load at a fixed
offset, as it does a slot of an array: the names cost nothing
(``benchmarks/ab_kernel_state.py`` measures it).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from slidernet.kernels.jit import kernel_jit


@kernel_jit(forceinline=True)
def nonneg(k):
    """The index k (0 <= k < 2**62) with its two top bits cleared: the same value, known to the compiler
    not to be negative, nor k plus a small offset (k + 1, the 8 entries of a tree's group).

    numba wraps a negative index around (k + size) unless it can prove k >= 0, which costs a compare, a
    select and a load of the array's size at every access with an index read from memory (a node, a
    slot, an offset); clearing the top bits is one AND, and the wrap-around code folds away. Only for
    indices that cannot be negative: a -1 (no slot, no leaf) would become a huge index, not the last
    entry. In run_plane's machine code, 121 of those sign tests (``sar $63``) became 33 and the code 7 %
    shorter (16 today, none on the path of a slip); at that first step, interleaved runs on one core
    (2026-11-26, slips and thresholds unchanged) gave +14 to +73 % (median of 4 rounds +18 %) on an
    irregular network of 1e4 nodes and +10 to +39 % on the 32 x 32 triangular lattice (performance guide).
    """
    return k & 0x3FFFFFFFFFFFFFFF


# Return codes.
DONE = 0
NEED_MU = 1  # the threshold buffer (Draws.mu) is empty
NEED_TILT = 2  # the tilt-test buffers ran out during a test (rolled back)
AVALANCHE_LIMIT = 3  # an avalanche exceeded max_slips
TILT_LIMIT = 4  # a tilt test exceeded its iteration cap
RECOMPUTE = 5  # time to recompute the forces from the displacements (drift control)
NEED_EVENTS = 6  # the event catalogue's buffer is full
SLID_AWAY = 7  # the network slid away (Settings.slide_away): the realization is over

TILT_MAX_ITER = 1_000_000

# What a tilt test (the pair's or the network's) returns where it gives no sample; a sample, the load
# at which the system slides, is > mu_d > 0. slidernet.kernels.tilt.tilt_status maps these to the codes above.
TILT_NEED_DRAWS = -1.0  # a draw buffer ran out (pair: positions left as they were; network: it resumes)
TILT_TOO_LONG = -2.0  # the test gave up: TILT_MAX_ITER iterations (pair), or why in pos[STOP] (network)
N_AVALANCHE_BINS = 63  # avalanche sizes s are binned by floor(log2 s); 2**62 fits in int64

#: The fixed bin edges of the contact ages (observable ``contact_age``), in tau_th: 4 bins per decade from
#: 1e-6 to 1e9, so that the histograms of every run, realization and sweep point stack. Bin 0 holds the
#: ages in [0, 1e-6) (a node that slipped within 1e-6 tau_th of the record), bin b >= 1 the ages in
#: [AGE_EDGES[b - 1], AGE_EDGES[b]), the last bin the ages from 1e9 on.
AGE_EDGES = 10.0 ** (np.arange(-24, 37) / 4.0)
N_AGE_BINS = AGE_EDGES.size + 1

#: The scalars of a realization, one record. Units are the kernels' (theta in
#: Ntilde, lengths in Ntilde l0, see :mod:`slidernet.kernels`).
STATE = np.dtype([
    # counters
    ("q", np.int64),  # next thermal step: the segment thetas[q] -> thetas[q + 1]
    ("n_slips", np.int64),  # cumulative rearrangements n
    ("n_records", np.int64),  # drawn thresholds that exceeded the running mu_max
    ("n_events", np.int64),  # driving events (= avalanches)
    ("next_out", np.int64),  # index of the next output step (out_steps) to write
    ("started", np.int64),  # 1 once t = 0 is closed (its initial relaxation done)
    # read positions in the draw buffers (Draws)
    ("mu_pos", np.int64),
    ("tilt_mu_pos", np.int64),
    ("tilt_u_pos", np.int64),
    ("shs_mu_pos", np.int64),  # read by the slide-hold-slide pull only (Python calls it; no kernel of the run)
    # avalanches
    ("av_slips", np.int64),  # slips of the current avalanche after its driving slip
    ("in_avalanche", np.int64),  # 1 between a driving slip and the end of its avalanche
    ("pending", np.int64),  # pair kernel: 1 while a slip has left a slider over its threshold
    ("since_recompute", np.int64),  # slips since the forces were last recomputed from u
    ("argmax", np.int64),  # node holding mu_max
    ("err_node", np.int64),  # node named by an error return
    # sliding away (network kernels, only with Settings.slide_away)
    ("moving_id", np.int64),  # the avalanche (id: n_events) whose moving nodes n_moving counts
    ("n_moving", np.int64),  # distinct nodes that have slipped in that avalanche
    ("slid_away", np.int64),  # 1 once the network slid away
    # the event catalogue
    ("ev_pos", np.int64),  # rows written to the catalogue's buffer
    ("ev_on", np.int64),  # 1 while the catalogue is recorded
    # physical scalars
    ("theta", np.float64),  # theta / Ntilde
    ("u", np.float64),  # pair kernel: the paper's u / Ntilde (the spring's length change)
    ("x_G", np.float64),  # centre-of-mass displacement along x / (Ntilde l0)
    ("y_G", np.float64),  # 2D kernel: the same along y
    ("mu_max", np.float64),  # largest threshold mu_s
    ("event_time", np.float64),  # time of the current driving event, tau_th (q + fraction of the step)
    ("slid_away_at", np.float64),  # event_time of the avalanche that slid away (set with slid_away)
])


def new_state() -> np.ndarray:
    """A zeroed state: a 1-element array of dtype :data:`STATE` (the kernels take the array)."""
    return np.zeros(1, dtype=STATE)


# A network kernel's heap (row of Heaps.node / Heaps.key) and its two driving trees (rows of
# Heaps.tkey / Heaps.twin).
UNSTABLE = 0  # unstable nodes keyed by their overload |F_i| / (mu_s,i N_i)
UP = 0  # driven nodes keyed by minus their upper critical theta (next event as theta rises)
DOWN = 1  # driven nodes keyed by their lower critical theta (next event as theta falls)

TREE_ARITY = 8  # children per node of a driving tree: 8 keys of float64 fill one 64-byte cache line
_TREE_PAD = np.iinfo(np.int32).max  # the winner of a padding entry (key -inf): never a node


class Heaps(NamedTuple):
    """Indexed binary heaps and tournament trees (see :mod:`slidernet.kernels.heap`) over N nodes.

    ``node[w, h]`` is the node in slot h of heap w and ``key[w, h]`` its key,
    so that sifting reads contiguous memory; ``slot[node, w]`` is its slot or
    -1, node-major so that the W slots of a node share a cache line;
    ``size[w]`` is the size of heap w.

    The driving events of a network kernel come from two tournament trees
    (rows ``UP`` and ``DOWN`` of ``tkey`` and ``twin``) over its L driven
    nodes, each the leaf ``leaf[node]`` (leaves in node order; where every
    node is driven ``leaf`` is empty and the leaf of node j is j). Each tree is
    stored level by level from the leaves (level l from ``toff[l]`` to
    ``toff[l + 1]``, padded to whole groups of ``TREE_ARITY`` entries with
    key -inf): entry c of level l + 1 holds the key and the node (``twin``)
    that lead the group c of level l, its entries ``TREE_ARITY c`` to
    ``TREE_ARITY c + TREE_ARITY - 1``; the last level is the root. Trees of
    heaps without driving events (the tilt test's) have no levels
    (``toff == [0]``).

    Of the two trees only the one theta is moving along, ``active[0]``, is
    kept up to date at every slip; a node re-keyed meanwhile is listed in
    ``stale_nodes[:n_stale[0]]`` (and marked in ``stale``), and the other
    tree is brought up to date for those nodes when theta turns
    (:func:`slidernet.kernels.network.turn`).
    """

    node: np.ndarray  # (W, N) int32
    key: np.ndarray  # (W, N) float64
    slot: np.ndarray  # (N, W) int32
    size: np.ndarray  # (W,) int64
    active: np.ndarray  # (1,) int64: the driving tree kept up to date (UP or DOWN)
    stale: np.ndarray  # (N,) uint8: 1 if the other driving tree's key of the node is out of date
    stale_nodes: np.ndarray  # (N,) int32: those nodes, in the order they were marked
    n_stale: np.ndarray  # (1,) int64: how many
    tkey: np.ndarray  # (2, T) float64: the driving trees' keys
    twin: np.ndarray  # (2, T) int32: the node holding each key (leaves: their own node)
    toff: np.ndarray  # (levels + 1,) int64: where each level starts; T at the end
    leaf: np.ndarray  # (N,) int32: each node's leaf, or -1 if not driven; (0,) if all are driven or no trees

    @classmethod
    def empty(cls, n_heaps: int, n_nodes: int, driven: np.ndarray | None = None) -> Heaps:
        """W = ``n_heaps`` empty heaps over ``n_nodes`` nodes, with driving trees over the nodes of the
        boolean mask ``driven`` (shape (N,)) if given; their keys are set by the kernels' init."""
        sizes = []
        leaf = np.zeros(0, np.int32)
        if driven is not None:
            driven = np.asarray(driven, bool)
            leaf = np.full(n_nodes, -1, np.int32)
            n = int(driven.sum())
            leaf[driven] = np.arange(n, dtype=np.int32)
            if n == n_nodes:
                leaf = np.zeros(0, np.int32)
            while n > 1:
                parents = -(-n // TREE_ARITY)
                sizes.append(parents * TREE_ARITY)
                n = parents
            if n == 1:
                sizes.append(1)
        toff = np.concatenate([[0], np.cumsum(sizes, dtype=np.int64)]).astype(np.int64)
        T = int(toff[-1])
        twin = np.full((2, T), _TREE_PAD, np.int32)
        if sizes:
            twin[:, :int(driven.sum())] = np.flatnonzero(driven).astype(np.int32)
        # Node indices and slots in int32 (N < 2**31): slot is read for every re-keyed node.
        return cls(np.zeros((n_heaps, n_nodes), np.int32), np.zeros((n_heaps, n_nodes)),
                   np.full((n_nodes, n_heaps), -1, np.int32), np.zeros(n_heaps, np.int64),
                   np.full(1, UP, np.int64), np.zeros(n_nodes, np.uint8), np.zeros(n_nodes, np.int32),
                   np.zeros(1, np.int64), np.full((2, T), -np.inf), twin, toff, leaf)


class Draws(NamedTuple):
    """The random draws waiting for the kernel, read from the positions ``*_pos`` of the state."""

    mu: np.ndarray  # thresholds mu_s handed out one per slip
    tilt_mu: np.ndarray  # thresholds redrawn by the appendix's tilt test
    tilt_u: np.ndarray  # uniforms in [0, 1) of the tilt test's creep branch
    # thresholds redrawn by the slide-hold-slide pull (observable mu_shs; 0-length without it)
    shs_mu: np.ndarray = np.empty(0)


class Series(NamedTuple):
    """What the kernels write at the output steps, one entry per step of ``out_steps``, shape (T,).

    A kernel leaves out what its scene has not (0-length arrays): the pair
    kernel ``mu_mean``, ``mu_min``, ``y_G``; the 1D kernel ``y_G``.
    """

    n: np.ndarray  # int64, cumulative rearrangements
    mu_max: np.ndarray
    x_G: np.ndarray  # Ntilde l0
    n_records: np.ndarray  # int64
    mu_mean: np.ndarray
    mu_min: np.ndarray
    y_G: np.ndarray  # Ntilde l0
    f_sum: np.ndarray  # the tilt test's samples in the bin ending at the step: sum,
    f_sq: np.ndarray  # sum of squares,
    f_count: np.ndarray  # and count (int64)
    # Observable contact_age (network kernels; 0-length elsewhere): each record's mean over the nodes of
    # the time since the node last slipped, in tau_th, shape (T,), and the nodes' ages binned by
    # AGE_EDGES, int64, shape (T, N_AGE_BINS).
    contact_age: np.ndarray
    contact_age_count: np.ndarray


class Catalogue(NamedTuple):
    """The event catalogue's buffer: one row per slip (see :func:`slidernet.kernels.heap.log_event`)."""

    ids: np.ndarray  # (rows, 2) int64: node, avalanche id
    values: np.ndarray  # (rows, 3) float64: time in tau_th, du_x, du_y in Ntilde l0


class Nodes(NamedTuple):
    """The per-node state of a network realization (N nodes, d = 1 or 2)."""

    a: np.ndarray  # (N,) or (N, 2): force offsets, F_i = a_i + g_i theta, in N
    u: np.ndarray  # (N,) or (N, 2): displacements, Ntilde l0
    mu: np.ndarray  # (N,): thresholds mu_s
    node_slips: np.ndarray  # (N,) int64: slips of each node
    avalanche_count: np.ndarray  # (N_AVALANCHE_BINS,) int64: avalanches by floor(log2 size)
    # (N,) int64, 0-length unless the scene can slide away: the avalanche (id) in which the node last
    # slipped; -1: none.
    moving: np.ndarray
    # Written only with Settings.slide_away.
    # (N,) float64, 0-length unless the scene records contact_age or its contacts strengthen: the event
    # time (tau_th) of the last slip of each node in the horizontal evolution; 0.0 for a node that has not
    # slipped since t = 0.
    last_slip: np.ndarray


#: :class:`Nodes` with contact strengthening (friction.strengthening), the type the ``*_aging`` kernels are
#: compiled for: ``mu0`` (N,) float64, the threshold mu_s,i^0 drawn at each node's last renewal, and
#: ``law`` (3,) float64, the law's constants (beta, tau_c in tau_th, exponent; exponent 0: the logarithmic
#: law). ``mu`` then holds each node's threshold at the time it was last brought up to date
#: (:mod:`slidernet.kernels.strength`). A type of its own, so that the kernels of every other scene pass
#: and unpack none of these arrays (two more arrays in Nodes cost the 2D kernel 2 %).
AgingNodes = NamedTuple("AgingNodes", [*Nodes.__annotations__.items(), ("mu0", np.ndarray), ("law", np.ndarray)])


class Chain(NamedTuple):
    """A 1D network's operators: the CSR rows of K and the loads."""

    indptr: np.ndarray  # (N + 1,) int64
    indices: np.ndarray  # (nnz,) int64
    K_data: np.ndarray  # (nnz,) entries of K, in k0
    K_diag: np.ndarray  # (N,) K_ii
    g: np.ndarray  # (N,) thermal load: dF_i / d(theta / Ntilde), in N
    normal_load: np.ndarray  # (N,) N_i, in N
    w: np.ndarray  # (N,) N_i / sum N: weights of the centre of mass
    unit_load: bool  # every N_i == 1 (the load array is then not read in the hot loop)


class Plane(NamedTuple):
    """A 2D network's operators: the block-CSR rows of K (2 x 2 blocks) and the loads.

    Block K_ij, the entry p of row i, is ``K_table[K_id[p]]``: a lattice
    stores each distinct block once (a few dozen of them, where one block per
    entry took 224 MB at a million nodes), any other network one per entry,
    ``K_id`` = 0, 1, ... (``block_per_entry``: the kernels then take block p
    directly, :func:`slidernet.kernels.plane.block_of`).
    """

    indptr: np.ndarray  # (N + 1,) int64
    indices: np.ndarray  # (nnzb,) int32: block columns, sorted
    K_id: np.ndarray  # (nnzb,) int32: row of K_table holding the block
    K_table: np.ndarray  # (B, 2, 2) the distinct blocks of K, in k0
    diag: np.ndarray  # (N,) int64: position of K_ii in the row (indices, K_id)
    g: np.ndarray  # (N, 2) thermal load
    normal_load: np.ndarray  # (N,)
    w: np.ndarray  # (N,)
    unit_load: bool  # every N_i == 1, so every w_i == 1/N: neither array is read in the hot loop
    block_per_entry: bool  # K_id == 0, 1, ..., nnzb - 1: the kernels then do not read K_id


class Settings(NamedTuple):
    """A run's constants. What a kernel does beyond them (the appendix's tilt test, the exact 2D slip) is
    its compiled variant's (``run_pair_tilt``, ``run_plane_exact``, ...), not a flag read at run time."""

    mu_d: float  # dynamic coefficient
    max_slips: int  # slips of one avalanche before AVALANCHE_LIMIT
    recompute_every: int  # slips between recomputations of the forces (0: never)
    # The mean load along x per unit normal load, sum_i f_ext,i,x / sum_i N_i, exceeds mu_d: an
    # avalanche that sets every node in motion is the network sliding away (network kernels). False:
    # the kernels keep no count of the moving nodes at all.
    slide_away: bool = False
    # A slip's length over (|F_i| - mu_d N_i) / K_ii: 1 + e, e = friction.overshoot (2.0: the paper's
    # undamped half-oscillation, eq. `displacement`; 1.0: the slip stops where |F_i| = mu_d N_i).
    slip_factor: float = 2.0
    # The network tilt test's sliding rule (tilt_net): one avalanche above mu_d in which every node has
    # slipped at least tilt_min_slips times and the centre of mass has moved along +x by at least
    # tilt_min_shift (in Ntilde l0; 0: no such condition).
    tilt_min_slips: int = 1
    tilt_min_shift: float = 0.0
