"""The equations of motion of a 2D network, compiled: only the moving nodes are integrated.

The model, its rules and its units are those of the reference integrator
(:mod:`slidernet.validation.dynamics`): node i has mass N_i, and while it
moves, in the local time s = (t - t0) / tau_dyn,

    N_i d^2u_i/ds^2 = F_i - mu_d N_i v_i / |v_i|,    F = -K u + theta g + f_ext,

with v_i = du_i/ds, and Coulomb friction along -F_i / |F_i| at the instant
of a start (v_i = 0). A stuck node has v_i = 0 exactly while |F_i| <= mu_s,i
N_i and starts along F_i when |F_i| reaches mu_s,i N_i; a moving node whose
speed |v_i| falls to ``STOP_SPEED`` stops there (v_i set to 0), gets the next
threshold of the realization's stream, and sticks, or starts again at once if
|F_i| is above it (a new rearrangement). One rearrangement is counted per
start of motion. Units are the kernels': u in Ntilde l0, theta and forces
over Ntilde as in :mod:`slidernet.kernels.plane` (F = a + g theta with
a = f_ext - K u - g theta(0)), v in Ntilde l0 per tau_dyn.

How it is integrated
--------------------
**Phases.** Between two events the set M of moving nodes is fixed. The nodes of M are integrated together, by
Dormand-Prince 5(4) with adaptive steps (:func:`dp_step`: error per step below ``atol + rtol |y_i|`` in every
component of u and v of node i, |y_i| the largest of them, with ``atol = 1e-2 rtol`` Ntilde l0 as the reference's;
step at most ``max_step`` tau_dyn). Their right-hand side reads K only through the sparse rows of M (``K_MM``,
gathered once per phase). A stuck node is exactly fixed: its force changes only through the moving nodes'
displacements and theta, F_j(s) = F_j(0) - sum_{i in M} K_ji du_i(s) + g_j dtheta/ds s, so only the stuck
neighbours W of M (rows ``K_WM``) are evaluated at each step; every other stuck node is driven by theta alone, and
its first crossing is the root of a quadratic in theta (:func:`slidernet.kernels.plane.critical_thetas`, kept per
node in ``crit`` and recomputed only when the node's force offset a_j changes), which bounds the phase. When
nothing moves, the next start is the first such crossing, in closed form.

**Events.** A moving node stops when SS - |v_i| rises through 0 (SS = ``STOP_SPEED``); a stuck neighbour starts
when max_W (|F_j| - mu_s,j N_j) rises through 0; the phase ends at the end of the thermal step. A sign change
between the ends of an accepted step brackets the event, and its time is found by the Illinois (safeguarded secant)
method, each evaluation being the Dormand-Prince step from the step's start to the trial time: the state at the
event is a full step of the scheme, not an interpolant, and the root is located to 1e-14 of the phase's time or to
a zero event value.

**The traps.** (1) The stop: v_i / |v_i| is singular at v_i = 0 and the motion chatters about it without a sign
change, so the stop is at |v_i| = SS (the reference's rule: ~SS / 0.1 tau_dyn and SS^2 / 0.2 Ntilde l0 early). (2)
A node that starts has |v_i| < SS: it is armed for a stop once its speed has been above SS at the end of a step.
(3) A speed that dips below SS and rises again within one step (a node pushed on by a neighbour): where d|v_i|/ds
goes from < 0 to > 0 across a step, its minimum is located and, if below SS, the stop is found before it. (4) Until
a node is armed, friction acts along -sigma_i, the direction of F_i at its start, not along -v_i / |v_i|: below SS
that direction is stiff (rate mu_d / |v_i|), and a node whose mu_s lies a hair above mu_d (mu_s - mu_d = 7e-4 on a
4 x 4 lattice at ratio 0.3) crept for ever at |v_i| ~ 1e-11 on the stability limit of the explicit steps, its v_i
20 degrees off F_i. The first step after a start is ``H_START``. (5) Restarts and simultaneous starts: after every
event the candidates (the stopped node, the stuck neighbours of M) above their thresholds start, the largest |F_j|
/ (mu_s,j N_j) first, as the reference's ``_start_overloaded``; each restart is a phase of its own (no step of zero
length).

**Energy.** Each moving node also integrates its path length, int |v_i| ds,
and the work of the thermal load on it, int (theta - theta(0)) g_i . v_i ds;
E = (1/2) u.K u - u.f_ext changes by the exact quadratic form of each phase's
displacements. Per avalanche, work = dE + sum_i mu_d N_i path_i + the kinetic
energy (1/2) N_i |v_i|^2 <= (1/2) N_i SS^2 dropped at each stop.

**Cost.** 180 to 200 steps per slip at rtol = 1e-10, ~0.35 us each (benchmarks/inertia_2d_speed.py): ~60 %
in the half-oscillation at h ~ 0.013 tau_dyn, the rest near the ends of a slip, where the steps grow in
proportion to the time since the start and shrink with the time to the stop (the friction's part across v_i
is stiff, rate mu_d / |v_i|). DOP853 takes half the steps with twice the stages (scipy's, measured). The
helpers called at each step are inlined: a call passing the net, run, motion and work tuples flattens their
~40 arrays into hundreds of arguments.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from slidernet.kernels.heap import replace_threshold
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.plane import block_of, critical_thetas

# A moving node stops when its speed |v_i| falls to this, in Ntilde l0 per tau_dyn: the reference
# integrator's rule and value (slidernet.validation.event_loop.STOP_SPEED; tests/test_inertia_2d.py checks
# that the two are equal).
STOP_SPEED = 1e-6

# A node that slides this long (tau_dyn) without stopping slides for ever (the reference's MAX_SLIP_DURATION).
MAX_SLIP_DURATION = 1000.0

# The first step of a phase in which a node starts from rest, tau_dyn: the controller grows it from there.
H_START = 1e-6

# Return codes of run_inertia_2d: done; the threshold buffer is empty (refill it and call again); the slip or
# avalanche buffer is full (empty it and call again); a node slid MAX_SLIP_DURATION (ints[RUNAWAY_NODE]).
DONE, NEED_MU, NEED_OUT, RUNAWAY = 0, 1, 2, 3
# What ended a phase: nothing (its end), a moving node's stop, a stuck node's start.
EV_NONE, EV_STOP, EV_START = 0, 1, 2

# Slots of the float scalars (``floats``): the time t (tau_th); the clock, time spent in motion (tau_dyn); the
# largest speed set to zero at a stop; the last step (tau_dyn, the next phase's first guess); the running
# avalanche's start (tau_th), work of the thermal load, dissipation sum mu_d N_i path_i, change of the elastic
# energy and kinetic energy dropped at the stops.
T, CLOCK, STOP_MAX, H, AV_START, AV_WORK, AV_DISS, AV_DE, AV_KE, N_FLOATS = range(10)
# Slots of the integer scalars (``ints``): the thermal step q being run; the stage (0: the relaxation at t = 0;
# 1: at t = q, its record then its segment; 2: inside the segment q -> q + 1); the rearrangements n; the starts
# while another node moved; the next record; the read position in the threshold buffer; the rows written to
# the slip and avalanche buffers; the number of moving nodes; 1 once the overloads at t = 0 were started; the
# running avalanche's starts; the runaway node; the accepted steps of the scheme.
(Q, STAGE, N, OVERLAPPING, NEXT_OUT, POS, N_SLIPS, N_AV, N_MOVING, INIT, AV_STARTS, RUNAWAY_NODE, STEPS,
 N_INTS) = range(14)

# Columns of the integrated state of a moving node.
DUX, DUY, VX, VY, PATH, WORK = 0, 1, 2, 3, 4, 5
N_COMP = 6

# Dormand-Prince 5(4): the nodes c, the stages' weights (row 6: the 5th-order solution b, whose derivative is
# the first stage of the next step) and the error weights b - b_hat.
_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1 / 5, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3 / 40, 9 / 40, 0.0, 0.0, 0.0, 0.0],
    [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0, 0.0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0, 0.0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0.0],
    [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
])
_E = np.array([71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])


class Motion(NamedTuple):
    """The per-node state of the integration (N rows each; 2-vectors as (N, 2))."""

    u: np.ndarray  # (N, 2) displacements, Ntilde l0
    v: np.ndarray  # (N, 2) velocities, Ntilde l0 per tau_dyn (0 for a stuck node)
    a: np.ndarray  # (N, 2) force offsets: F = a + g theta
    sigma: np.ndarray  # (N, 2) the unit direction of F_i at the node's start
    mu: np.ndarray  # (N,) thresholds mu_s
    lim: np.ndarray  # (N,) mu_s N_i
    crit: np.ndarray  # (N, 2) the stable range [theta_dn, theta_up] of a stuck node's a_j
    moving: np.ndarray  # (N,) int8
    armed: np.ndarray  # (N,) int8: the speed has been above STOP_SPEED since the start
    start_t: np.ndarray  # (N,) tau_th, of the current slip
    start_clock: np.ndarray  # (N,) tau_dyn
    start_u: np.ndarray  # (N, 2)
    path: np.ndarray  # (N,) path length of the current slip, Ntilde l0
    mark: np.ndarray  # (N,) int64: local index in M of a moving node, -1 otherwise
    wmark: np.ndarray  # (N,) int64: local index in W of a watched stuck node, -1 otherwise
    best: np.ndarray  # (3,) the running mu_max, its holder and n_records (kernels.heap.replace_threshold)
    first: np.ndarray  # (N, 2) or (0, 2): the dynamic tilt test's watch, as kernels.inertia.Motion's
    times: np.ndarray  # (2,) or (0,)


class Work(NamedTuple):
    """Scratch arrays of a phase (sized for N nodes and nnz blocks)."""

    M: np.ndarray  # (N,) int64 moving nodes
    W: np.ndarray  # (N,) int64 stuck neighbours of M
    mptr: np.ndarray  # (N + 1,) int64: rows of K_MM
    mcol: np.ndarray  # (nnz,) int64: local column in M
    mblk: np.ndarray  # (nnz,) int64: row of K_table
    wptr: np.ndarray  # (N + 1,) int64: rows of K_WM
    wcol: np.ndarray  # (nnz,) int64
    wblk: np.ndarray  # (nnz,) int64
    F0: np.ndarray  # (N, 2) forces at the phase's start of the nodes of M
    FW: np.ndarray  # (N, 2) ... and of W
    Y: np.ndarray  # (N, 6) the state of M at the last accepted step
    Yt: np.ndarray  # (N, 6) a trial step
    Ks: np.ndarray  # (7, N, 6) the stages
    cand: np.ndarray  # (N,) int64 candidates of an overload
    over: np.ndarray  # (N,) their |F| / lim


@kernel_jit()
def node_crit(net, mo, j):
    """Recompute the stable range in theta of node j from its a_j (an undriven node: the whole line)."""
    gx = net.g[j, 0]
    gy = net.g[j, 1]
    if gx == 0.0 and gy == 0.0:
        mo.crit[j, 0] = -math.inf
        mo.crit[j, 1] = math.inf
    else:
        dn, up = critical_thetas(mo.a[j, 0], mo.a[j, 1], gx, gy, mo.lim[j])
        mo.crit[j, 0] = dn
        mo.crit[j, 1] = up


@kernel_jit(forceinline=True)
def _norm(x, y):
    """|(x, y)|: no need of libm's hypot and its guard against overflow (~20 ns a call, a sixth of a step)."""
    return math.sqrt(x * x + y * y)


@kernel_jit(forceinline=True)
def pushed(Kt, ptr, col, blk, row, Y, fx, fy):
    """(fx, fy) less sum_p K_table[blk[p]] du_col[p] over the entries p of a gathered row (K_MM or K_WM): the
    force on a node from the displacements Y[:, DUX:DUY + 1] of the moving nodes since the phase's start."""
    for p in range(ptr[row], ptr[row + 1]):
        c = col[p]
        b = blk[p]
        fx -= Kt[b, 0, 0] * Y[c, DUX] + Kt[b, 0, 1] * Y[c, DUY]
        fy -= Kt[b, 1, 0] * Y[c, DUX] + Kt[b, 1, 1] * Y[c, DUY]
    return fx, fy


@kernel_jit(forceinline=True)
def rhs(net, run, mo, wk, m, theta0, r, s, Y, out):
    """out = dY/ds of the moving nodes (Y: (m, 6) local state), theta = theta0 + r s."""
    mu_d = run.mu_d
    Kt = net.K_table
    th = theta0 + r * s
    for k in range(m):
        i = wk.M[k]
        fx, fy = pushed(Kt, wk.mptr, wk.mcol, wk.mblk, k, Y, wk.F0[k, 0] + net.g[i, 0] * (r * s),
                        wk.F0[k, 1] + net.g[i, 1] * (r * s))
        vx = Y[k, VX]
        vy = Y[k, VY]
        sp = _norm(vx, vy)
        if mo.armed[i] and sp > 0.0:
            dx = vx / sp
            dy = vy / sp
        else:
            dx = mo.sigma[i, 0]
            dy = mo.sigma[i, 1]
        Ni = net.normal_load[i]
        out[k, DUX] = vx
        out[k, DUY] = vy
        out[k, VX] = fx / Ni - mu_d * dx
        out[k, VY] = fy / Ni - mu_d * dy
        out[k, PATH] = sp
        out[k, WORK] = th * (net.g[i, 0] * vx + net.g[i, 1] * vy)


@kernel_jit(forceinline=True)
def dp_step(net, run, mo, wk, m, theta0, r, s, h):
    """One Dormand-Prince step of size h from (s, wk.Y), with wk.Ks[0] = f(s, Y): the result in wk.Yt, its
    derivative in wk.Ks[6], and the error norm returned (<= 1: within the tolerance)."""
    Y = wk.Y
    Yt = wk.Yt
    Ks = wk.Ks
    for st in range(1, 7):
        for k in range(m):
            for c in range(N_COMP):
                acc = 0.0
                for j in range(st):
                    acc += _A[st, j] * Ks[j, k, c]
                Yt[k, c] = Y[k, c] + h * acc
        rhs(net, run, mo, wk, m, theta0, r, s + _C[st] * h, Yt, Ks[st])
    err = 0.0
    for k in range(m):
        # A node's error is measured against the size of its own state (displacement and velocity alike):
        # near a stop its velocity is small, but an error of rtol times its displacement moves it by no more.
        size = 0.0
        for c in range(PATH):
            size = max(size, abs(Y[k, c]), abs(Yt[k, c]))
        scale = run.atol + run.rtol * size
        for c in range(PATH):  # the motion's components; path and work follow it
            e = 0.0
            for j in range(7):
                e += _E[j] * Ks[j, k, c]
            err = max(err, abs(h * e) / scale)
    return err


@kernel_jit(forceinline=True)
def watched_excess(net, mo, wk, nw, r, s, Y):
    """max over W of |F_j(s)| - mu_s,j N_j, and the node that reaches it (-1 if W is empty)."""
    Kt = net.K_table
    best = -math.inf
    arg = -1
    for w in range(nw):
        j = wk.W[w]
        fx, fy = pushed(Kt, wk.wptr, wk.wcol, wk.wblk, w, Y, wk.FW[w, 0] + net.g[j, 0] * (r * s),
                        wk.FW[w, 1] + net.g[j, 1] * (r * s))
        e = _norm(fx, fy) - mo.lim[j]
        if e > best:
            best = e
            arg = j
    return best, arg


@kernel_jit()
def _event_value(net, mo, wk, nw, kind, k, r, s):
    """The value of an event function on the trial state wk.Yt at local time s, rising through 0 at the event:
    kind EV_STOP: STOP_SPEED - |v_k|; EV_START: the watched excess; 3: d|v_k|/ds (a speed's minimum)."""
    Yt = wk.Yt
    if kind == EV_STOP:
        return STOP_SPEED - _norm(Yt[k, VX], Yt[k, VY])
    if kind == EV_START:
        e, _ = watched_excess(net, mo, wk, nw, r, s, Yt)
        return e
    return _speed_slope(Yt, wk.Ks[6], k)


@kernel_jit()
def locate(net, run, mo, wk, m, nw, theta0, r, s, kind, k, lo, flo, hi, fhi):
    """The first step size h in (lo, hi] where the event (kind, k) is >= 0, from flo < 0 <= fhi, by the
    Illinois method on full Dormand-Prince steps from (s, wk.Y). Leaves the step of that size in wk.Yt."""
    side = 0
    for _ in range(200):
        if hi - lo <= 1e-14 * (s + hi):
            break
        x = hi - fhi * (hi - lo) / (fhi - flo)
        if not (lo < x < hi):
            x = 0.5 * (lo + hi)
        dp_step(net, run, mo, wk, m, theta0, r, s, x)
        fx = _event_value(net, mo, wk, nw, kind, k, r, s + x)
        if fx >= 0.0:
            hi = x
            fhi = fx
            if side == 1:
                flo *= 0.5
            side = 1
        else:
            lo = x
            flo = fx
            if side == -1:
                fhi *= 0.5
            side = -1
        if fx == 0.0:
            break
    dp_step(net, run, mo, wk, m, theta0, r, s, hi)
    return hi


@kernel_jit(forceinline=True)
def _speed_slope(Y, D, k):
    """d|v_k|/ds from the state Y and its derivative D (0 at v_k = 0)."""
    sp = _norm(Y[k, VX], Y[k, VY])
    return (Y[k, VX] * D[k, VX] + Y[k, VY] * D[k, VY]) / sp if sp > 0.0 else 0.0


@kernel_jit()
def gather(net, mo, wk, theta0, m):
    """The phase's operators: the rows K_MM of the moving nodes, their stuck neighbours W and the rows K_WM,
    and the forces of M and W at its start (theta = theta0). Returns the size of W."""
    nw = 0
    e = 0
    for k in range(m):
        i = wk.M[k]
        wk.mptr[k] = e
        for p in range(net.indptr[i], net.indptr[i + 1]):
            j = net.indices[p]
            if mo.moving[j]:
                wk.mcol[e] = mo.mark[j]
                wk.mblk[e] = block_of(net, p)
                e += 1
            elif mo.wmark[j] < 0:
                mo.wmark[j] = nw
                wk.W[nw] = j
                nw += 1
        wk.F0[k, 0] = mo.a[i, 0] + net.g[i, 0] * theta0
        wk.F0[k, 1] = mo.a[i, 1] + net.g[i, 1] * theta0
    wk.mptr[m] = e
    e = 0
    for w in range(nw):
        j = wk.W[w]
        wk.wptr[w] = e
        for p in range(net.indptr[j], net.indptr[j + 1]):
            c = net.indices[p]
            if mo.moving[c]:
                wk.wcol[e] = mo.mark[c]
                wk.wblk[e] = block_of(net, p)
                e += 1
        wk.FW[w, 0] = mo.a[j, 0] + net.g[j, 0] * theta0
        wk.FW[w, 1] = mo.a[j, 1] + net.g[j, 1] * theta0
    wk.wptr[nw] = e
    return nw


@kernel_jit()
def driven_crossing(mo, theta, r):
    """The first stuck, unwatched node whose |F_j| reaches its threshold as theta moves from ``theta`` at
    rate r (any unit of time): (wait in that unit, node), or (inf, -1). Its stable range ``crit`` is exact for
    such a node (its a_j is fixed)."""
    if r == 0.0:
        return math.inf, -1
    # Rising theta leaves the range at theta_up, falling at theta_dn: both as a minimum of side * crit.
    col = 1 if r > 0.0 else 0
    side = 1.0 if r > 0.0 else -1.0
    best = math.inf
    arg = -1
    for j in range(mo.moving.size):
        if mo.moving[j] == 0 and mo.wmark[j] < 0 and side * mo.crit[j, col] < best:
            best = side * mo.crit[j, col]
            arg = j
    if arg < 0:
        return math.inf, -1
    return max((side * best - theta) / r, 0.0), arg


@kernel_jit()
def _wait_of(net, mo, j, theta, rate):
    """The time until |a_j + g_j (theta + rate x)| = mu_s,j N_j, the root x >= 0 of a x^2 + 2 b x + c = 0 in the
    form without cancellation (the reference's ``_next_start``)."""
    fx = mo.a[j, 0] + net.g[j, 0] * theta
    fy = mo.a[j, 1] + net.g[j, 1] * theta
    dx = net.g[j, 0] * rate
    dy = net.g[j, 1] * rate
    qa = dx * dx + dy * dy
    qb = fx * dx + fy * dy
    qc = fx * fx + fy * fy - mo.lim[j] * mo.lim[j]
    if qc >= 0.0:
        return 0.0
    root = math.sqrt(max(qb * qb - qa * qc, 0.0))
    return -qc / (qb + root) if qb >= 0.0 else (root - qb) / qa


@kernel_jit()
def phase(net, run, mo, wk, floats, ints, theta0, theta_ref, r, s_max):
    """Integrate the moving nodes from s = 0 (theta = theta0, rising at r per tau_dyn) to the first event or
    s_max, and commit the motion (u, v, a, crit, the path lengths and the avalanche's energies).

    Returns (s1, event, node, nw): the time elapsed in tau_dyn, EV_STOP (node: the one that stopped),
    EV_START (node: the stuck node that reached its threshold) or EV_NONE, and the size of W (wk.W).
    """
    m = ints[N_MOVING]
    nw = gather(net, mo, wk, theta0, m)
    s_c, c_node = driven_crossing(mo, theta0, r)
    s_end = min(s_max, s_c)
    Y = wk.Y
    for k in range(m):
        i = wk.M[k]
        for c in range(N_COMP):
            Y[k, c] = 0.0
        Y[k, VX] = mo.v[i, 0]
        Y[k, VY] = mo.v[i, 1]
    th0 = theta0 - theta_ref
    rhs(net, run, mo, wk, m, th0, r, 0.0, Y, wk.Ks[0])
    e_old = -math.inf
    if nw > 0:
        e_old, _ = watched_excess(net, mo, wk, nw, r, 0.0, Y)
    s = 0.0
    h = min(floats[H], run.max_step)
    for k in range(m):
        if Y[k, VX] == 0.0 and Y[k, VY] == 0.0:
            h = min(h, H_START)
    event = EV_NONE
    node = -1
    while s < s_end:
        last = h >= s_end - s
        if last:
            h = s_end - s
        err = dp_step(net, run, mo, wk, m, th0, r, s, h)
        if err > 1.0 and h > 1e-14 * (1.0 + s):
            h *= max(0.2, 0.9 * err ** -0.2)
            continue
        # Accepted: look for the events between s and s + h. wk.Yt holds the step of size `held`: a located
        # event leaves another one there, and the step of size h is taken again where it is needed.
        best = math.inf
        kind = EV_NONE
        arg = -1
        held = h
        for k in range(m):
            i = wk.M[k]
            if mo.armed[i] == 0:
                continue
            held = _hold(net, run, mo, wk, m, th0, r, s, h, held)
            f_old = STOP_SPEED - _norm(Y[k, VX], Y[k, VY])
            f_new = STOP_SPEED - _norm(wk.Yt[k, VX], wk.Yt[k, VY])
            hi = -1.0
            if f_new >= 0.0:
                hi = h
            elif _speed_slope(Y, wk.Ks[0], k) < 0.0 < _speed_slope(wk.Yt, wk.Ks[6], k):
                # The speed has a minimum inside the step: is it below STOP_SPEED?
                held = locate(net, run, mo, wk, m, nw, th0, r, s, 3, k, 0.0, _speed_slope(Y, wk.Ks[0], k), h,
                              _speed_slope(wk.Yt, wk.Ks[6], k))
                f_min = STOP_SPEED - _norm(wk.Yt[k, VX], wk.Yt[k, VY])
                if f_min >= 0.0:
                    hi = held
                    f_new = f_min
            if hi > 0.0 and f_old < 0.0:
                held = locate(net, run, mo, wk, m, nw, th0, r, s, EV_STOP, k, 0.0, f_old, hi, f_new)
                if held < best:
                    best = held
                    kind = EV_STOP
                    arg = i
        e_new = -math.inf
        if nw > 0:
            held = _hold(net, run, mo, wk, m, th0, r, s, h, held)
            e_new, _ = watched_excess(net, mo, wk, nw, r, s + h, wk.Yt)
            if e_old <= 0.0 <= e_new:
                if e_old == 0.0:
                    root = 0.0
                else:
                    held = locate(net, run, mo, wk, m, nw, th0, r, s, EV_START, 0, 0.0, e_old, h, e_new)
                    root = held
                if root < best:
                    best = root
                    kind = EV_START
        if kind != EV_NONE:
            _hold(net, run, mo, wk, m, th0, r, s, best, held)
            if kind == EV_START:
                _, arg = watched_excess(net, mo, wk, nw, r, s + best, wk.Yt)
            s += best
            _copy(wk.Yt, Y, m)
            event = kind
            node = arg
            ints[STEPS] += 1
            break
        _hold(net, run, mo, wk, m, th0, r, s, h, held)
        s = s_end if last else s + h
        _copy(wk.Yt, Y, m)
        _copy(wk.Ks[6], wk.Ks[0], m)
        e_old = e_new
        ints[STEPS] += 1
        for k in range(m):
            i = wk.M[k]
            if mo.armed[i] == 0 and _norm(Y[k, VX], Y[k, VY]) >= STOP_SPEED:
                mo.armed[i] = 1
        if not last:
            factor = 5.0 if err == 0.0 else min(5.0, max(0.2, 0.9 * err ** -0.2))
            h = min(h * factor, run.max_step)
            floats[H] = h
    if event == EV_NONE and s_c <= s_max:
        event = EV_START
        node = c_node
    _commit(net, run, mo, wk, floats, m, nw, theta_ref)
    floats[CLOCK] += s
    return s, event, node, nw


@kernel_jit(forceinline=True)
def _hold(net, run, mo, wk, m, th0, r, s, h, held):
    """Make wk.Yt the step of size h from s (it holds the step of size ``held``); returns h."""
    if held != h:
        dp_step(net, run, mo, wk, m, th0, r, s, h)
    return h


@kernel_jit(forceinline=True)
def _copy(src, dst, m):
    for k in range(m):
        for c in range(N_COMP):
            dst[k, c] = src[k, c]


@kernel_jit()
def _commit(net, run, mo, wk, floats, m, nw, theta_ref):
    """Move the nodes of M by their displacements wk.Y: u, v, the path lengths, the avalanche's energies,
    the force offsets a of their rows of K and the stable ranges of the stuck neighbours."""
    Y = wk.Y
    Kt = net.K_table
    dE = 0.0
    for k in range(m):
        i = wk.M[k]
        dux = Y[k, DUX]
        duy = Y[k, DUY]
        # E = u.K u / 2 - u.f_ext, and f_ext - K u = a + g theta(0): dE = -du.(a + g theta(0)) + du.K du / 2.
        kx, ky = pushed(Kt, wk.mptr, wk.mcol, wk.mblk, k, Y, 0.0, 0.0)  # -(K_MM du)_i
        dE += (-0.5 * (dux * kx + duy * ky) - dux * (mo.a[i, 0] + net.g[i, 0] * theta_ref)
               - duy * (mo.a[i, 1] + net.g[i, 1] * theta_ref))
        floats[AV_WORK] += Y[k, WORK]
        floats[AV_DISS] += run.mu_d * net.normal_load[i] * Y[k, PATH]
        mo.path[i] += Y[k, PATH]
        mo.u[i, 0] += dux
        mo.u[i, 1] += duy
        mo.v[i, 0] = Y[k, VX]
        mo.v[i, 1] = Y[k, VY]
    floats[AV_DE] += dE
    for k in range(m):
        i = wk.M[k]
        dux = Y[k, DUX]
        duy = Y[k, DUY]
        for p in range(net.indptr[i], net.indptr[i + 1]):
            j = net.indices[p]
            b = block_of(net, p)
            # K is symmetric with symmetric blocks: K_ji = K_ij, the stored block.
            mo.a[j, 0] -= Kt[b, 0, 0] * dux + Kt[b, 0, 1] * duy
            mo.a[j, 1] -= Kt[b, 1, 0] * dux + Kt[b, 1, 1] * duy
    for w in range(nw):
        j = wk.W[w]
        mo.wmark[j] = -1
        node_crit(net, mo, j)


@kernel_jit()
def start(net, mo, wk, floats, ints, i, theta):
    """Node i starts moving along F_i = a_i + g_i theta: one rearrangement."""
    if ints[N_MOVING] > 0:
        ints[OVERLAPPING] += 1
    else:
        floats[AV_START] = floats[T]
        for f in range(AV_WORK, AV_KE + 1):
            floats[f] = 0.0
        ints[AV_STARTS] = 0
    ints[AV_STARTS] += 1
    ints[N] += 1
    fx = mo.a[i, 0] + net.g[i, 0] * theta
    fy = mo.a[i, 1] + net.g[i, 1] * theta
    norm = math.hypot(fx, fy)
    mo.sigma[i, 0] = fx / norm
    mo.sigma[i, 1] = fy / norm
    mo.v[i, 0] = 0.0
    mo.v[i, 1] = 0.0
    mo.moving[i] = 1
    mo.armed[i] = 0
    mo.mark[i] = ints[N_MOVING]
    wk.M[ints[N_MOVING]] = i
    ints[N_MOVING] += 1
    mo.start_t[i] = floats[T]
    mo.start_clock[i] = floats[CLOCK]
    mo.start_u[i, 0] = mo.u[i, 0]
    mo.start_u[i, 1] = mo.u[i, 1]
    mo.path[i] = 0.0
    if mo.first.shape[0] > 0 and math.isnan(mo.first[i, 0]):
        mo.first[i, 0], mo.first[i, 1] = floats[T], norm
    if mo.times.size and math.isnan(mo.times[0]) and ints[N_MOVING] == mo.mu.size:
        mo.times[0] = floats[T]


@kernel_jit()
def start_overloaded(net, mo, wk, floats, ints, nc, theta):
    """Start every stuck candidate wk.cand[:nc] above its threshold, the largest |F_j| / (mu_s,j N_j) first."""
    for c in range(nc):
        j = wk.cand[c]
        if mo.moving[j]:
            wk.over[c] = 0.0
        else:
            wk.over[c] = math.hypot(mo.a[j, 0] + net.g[j, 0] * theta, mo.a[j, 1] + net.g[j, 1] * theta) / mo.lim[j]
    while True:
        best = 1.0
        arg = -1
        for c in range(nc):
            if wk.over[c] > best:
                best = wk.over[c]
                arg = c
        if arg < 0:
            return
        wk.over[arg] = 0.0
        start(net, mo, wk, floats, ints, wk.cand[arg], theta)


@kernel_jit()
def start_overloaded_all(net, mo, wk, floats, ints, theta):
    """:func:`start_overloaded` over the stuck nodes outside their stable range ``crit`` at theta."""
    nc = 0
    for j in range(mo.moving.size):
        if mo.moving[j] == 0 and not (mo.crit[j, 0] <= theta <= mo.crit[j, 1]):
            wk.cand[nc] = j
            nc += 1
    start_overloaded(net, mo, wk, floats, ints, nc, theta)


@kernel_jit()
def after_phase(net, run, mo, wk, out, floats, ints, mu_buf, event, node, nw, theta):
    """Apply the event that ended a phase (floats[T] and u already at its time), then start the overloaded."""
    nc = 0
    if event == EV_STOP:
        i = node
        sp = math.hypot(mo.v[i, 0], mo.v[i, 1])
        floats[STOP_MAX] = max(floats[STOP_MAX], sp)
        floats[AV_KE] += 0.5 * net.normal_load[i] * sp * sp
        mo.v[i, 0] = 0.0
        mo.v[i, 1] = 0.0
        mo.moving[i] = 0
        mo.armed[i] = 0
        # Out of the list of moving nodes: the last one takes its place.
        last = ints[N_MOVING] - 1
        k = mo.mark[i]
        wk.M[k] = wk.M[last]
        mo.mark[wk.M[k]] = k
        mo.mark[i] = -1
        ints[N_MOVING] = last
        r = ints[N_SLIPS]
        out.slip_f[r, 0] = mo.start_t[i]
        out.slip_f[r, 1] = floats[T]
        out.slip_f[r, 2] = (floats[CLOCK] - mo.start_clock[i]) * run.tau
        out.slip_f[r, 3] = mo.u[i, 0] - mo.start_u[i, 0]
        out.slip_f[r, 4] = mo.u[i, 1] - mo.start_u[i, 1]
        out.slip_f[r, 5] = mo.path[i]
        out.slip_node[r] = i
        ints[N_SLIPS] = r + 1
        # A new place on the substrate: a new threshold.
        replace_threshold(mo.mu, i, mu_buf[ints[POS]], mo.best)
        ints[POS] += 1
        mo.lim[i] = mo.mu[i] * net.normal_load[i]
        node_crit(net, mo, i)
        wk.cand[0] = i
        nc = 1
    elif event == EV_START:
        start(net, mo, wk, floats, ints, node, theta)
    for w in range(nw):
        wk.cand[nc] = wk.W[w]
        nc += 1
    start_overloaded(net, mo, wk, floats, ints, nc, theta)
    if ints[N_MOVING] == 0:
        a = ints[N_AV]
        out.av_f[a, 0] = floats[AV_START]
        out.av_f[a, 1] = floats[T]
        for f in range(4):  # work, dissipation, dE, dropped kinetic energy
            out.av_f[a, 2 + f] = floats[AV_WORK + f]
        out.av_n[a] = ints[AV_STARTS]
        ints[N_AV] = a + 1


@kernel_jit()
def _room(out, ints, mu_buf):
    """NEED_MU or NEED_OUT where the next phase could not record its stop, else DONE."""
    if ints[POS] >= mu_buf.size:
        return NEED_MU
    if ints[N_SLIPS] >= out.slip_node.size or ints[N_AV] >= out.av_n.size:
        return NEED_OUT
    return DONE


@kernel_jit()
def _runaway(mo, wk, floats, ints):
    """RUNAWAY, with the node in ints[RUNAWAY_NODE], if a moving node has slid MAX_SLIP_DURATION tau_dyn."""
    for k in range(ints[N_MOVING]):
        if floats[CLOCK] - mo.start_clock[wk.M[k]] >= MAX_SLIP_DURATION:
            ints[RUNAWAY_NODE] = wk.M[k]
            return RUNAWAY
    return DONE


@kernel_jit()
def _next_step(floats, ints, q):
    """The segment q -> q + 1 is over: t = q + 1, whose record comes next."""
    floats[T] = float(q + 1)
    ints[Q] = q + 1
    ints[STAGE] = 1


@kernel_jit()
def run_inertia_2d(thetas, out_steps, net, mo, wk, out, run, floats, ints, mu_buf):
    """Run one realization from where ``floats`` and ``ints`` say to the end of ``run.steps`` thermal steps,
    or to the first full buffer (NEED_MU, NEED_OUT) or a runaway (RUNAWAY); call again after a refill.

    The loop is the reference's (``EventLoop.run`` and ``_segment``): the overloads at t = 0 relaxed with
    theta frozen, then per thermal step the record at t = q and the segment q -> q + 1 with theta linear,
    phase by phase while something moves, from start to start in closed form while nothing does.
    """
    theta_ref = thetas[0]
    tau = run.tau
    while True:
        stage = ints[STAGE]
        if stage == 0:
            if ints[INIT] == 0:
                start_overloaded_all(net, mo, wk, floats, ints, theta_ref)
                ints[INIT] = 1
            if ints[N_MOVING] == 0:
                ints[STAGE] = 1
                continue
            code = _room(out, ints, mu_buf)
            if code == DONE:
                _, event, node, nw = phase(net, run, mo, wk, floats, ints, theta_ref, theta_ref, 0.0,
                                           MAX_SLIP_DURATION)
                after_phase(net, run, mo, wk, out, floats, ints, mu_buf, event, node, nw, theta_ref)
                code = _runaway(mo, wk, floats, ints)
            if code != DONE:
                return code
            continue
        q = ints[Q]
        if stage == 1:
            k = ints[NEXT_OUT]
            if k < out_steps.size and out_steps[k] == q:
                out.n[k] = ints[N]
                xg = 0.0
                mu_max = -math.inf
                for i in range(mo.mu.size):
                    xg += net.w[i] * mo.u[i, 0]
                    mu_max = max(mu_max, mo.mu[i])
                out.mu_max[k] = mu_max
                out.x_G[k] = xg
                ints[NEXT_OUT] = k + 1
            if q == run.steps:
                return DONE
            ints[STAGE] = 2
            continue
        theta_a = thetas[q]
        rate = thetas[q + 1] - theta_a  # per tau_th
        t = floats[T]
        theta = theta_a + rate * (t - q)
        if ints[N_MOVING] > 0:
            code = _room(out, ints, mu_buf)
            if code != DONE:
                return code
            left = (q + 1 - t) / tau
            s1, event, node, nw = phase(net, run, mo, wk, floats, ints, theta, theta_ref, rate * tau,
                                        min(left, MAX_SLIP_DURATION))
            if event == EV_NONE and s1 >= left:
                _next_step(floats, ints, q)
                continue
            floats[T] = t + tau * s1
            after_phase(net, run, mo, wk, out, floats, ints, mu_buf, event, node, nw,
                        theta_a + rate * (floats[T] - q))
            code = _runaway(mo, wk, floats, ints)
            if code != DONE:
                return code
        else:
            # Nothing moves: theta drives F through g, and the next start is a root in closed form,
            # inclusive at the end of the segment (the solver's eq. `critique`).
            wait, j = driven_crossing(mo, theta, rate)
            if j >= 0:
                wait = _wait_of(net, mo, j, theta, rate)
            if j < 0 or t + wait > q + 1:
                _next_step(floats, ints, q)
                continue
            floats[T] = t + wait
            theta = theta_a + rate * (floats[T] - q)
            if mo.times.size:
                mo.times[1] = floats[T]
            start(net, mo, wk, floats, ints, j, theta)
            start_overloaded_all(net, mo, wk, floats, ints, theta)
