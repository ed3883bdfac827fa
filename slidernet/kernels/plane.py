"""The geometry of 2D networks: vector forces, 2x2 blocks of K.

The force on node i is the 2-vector F_i = a_i + g_i theta (a = -K u - g
theta(0) + f_ext), and node i sticks while |F_i| <= mu_s,i N_i. Along a
linear segment of theta, |F_i(theta)|^2 = (mu_s,i N_i)^2 is a quadratic in
theta whose roots theta_dn,i <= theta <= theta_up,i bound the node's
stable range: they key the driving heaps.

A slip moves node i alone, the others fixed, as an undamped half-oscillation
under Coulomb friction with the local stiffness K_ii (a 2x2 block):

* ``solver.slip = "straight"`` (:func:`run_plane`): along F_i with the stiffness
  k = F^T K_ii F / |F|^2 of that line, Delta u_i = 2 (|F_i| - mu_d N_i) F_i / (|F_i| k).
  Exact when K_ii is isotropic (interior nodes of square and triangular
  lattices); an approximation otherwise.
* ``solver.slip = "exact"`` (:func:`run_plane_exact`): the 2D motion u'' = F_i - K_ii (u - u0) - mu_d N_i v/|v|
  is integrated (adaptive RK4, see :func:`exact_slip`) from rest until the
  node sticks. benchmarks/slip_error.py measures what the straight line costs.

These are the pieces of :func:`slidernet.kernels.network.run_network` that
depend on the dimension; the driving loop itself is shared with 1D networks
(:mod:`slidernet.kernels.chain`).
"""

from __future__ import annotations

import math

from slidernet.kernels.heap import heap_set, set_critical
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.memory import prefetch
from slidernet.kernels.network import init_heaps, no_tilt, run_network, tree_event
from slidernet.kernels.state import UNSTABLE, nonneg
from slidernet.kernels.strength import refresh_all_nodes, strengthened_event

_STEPS_PER_PERIOD = 4000
_MAX_PERIODS = 50


#: Where B^2 - A C of :func:`critical_thetas` cancels more than 2^20 of itself (B^2 above 2^20 A lim^2:
#: the force's projection on g above 1024 thresholds, |F| then off lim by up to ~1e-10 of it), its
#: discriminant is taken from Lagrange's identity instead. Below, the first form is kept: the 2D results,
#: the golden files among them, follow its bits (a last-bit change of one root reorders the events of a
#: run and changes it; their scenes stay below ~100 thresholds).
_CANCELLATION = 2.0**20


@kernel_jit()
def critical_thetas(ax, ay, gx, gy, lim):
    """Roots (theta_dn, theta_up) of |a + g theta| = lim, in the numerically stable form.

    The roots come from q = -B -+ sqrt(B^2 - A C) as q / A and C / q (no cancellation between B and the
    root), and the discriminant from Lagrange's identity where B^2 - A C would cancel (:data:`_CANCELLATION`):
    |a + g theta| stays at lim to the rounding of a (eps |a|) whatever |a| / lim is.
    """
    A = gx * gx + gy * gy
    B = ax * gx + ay * gy
    C = ax * ax + ay * ay - lim * lim
    if B * B <= _CANCELLATION * A * (lim * lim):
        disc = B * B - A * C
    else:
        # |a| >> lim: B^2 - A C cancels terms of size |a|^2 |g|^2 down to one of size lim^2 |g|^2, and
        # loses eps |a|^2 / lim^2 of it (all of it from |a| ~ 1e8 lim on, where theta_c put |F| at 0,
        # not at lim, and the slip divided by zero). Lagrange's identity gives the same number as
        # A lim^2 - (a x g)^2, whose terms are of its size.
        cross = ax * gy - ay * gx
        disc = A * (lim * lim) - cross * cross
    if disc < 0.0:
        disc = 0.0  # rounding at a tangency
    sq = math.sqrt(disc)
    if B >= 0.0:
        q = -B - sq
        if q == 0.0:
            return 0.0, 0.0
        r1 = q / A
        r2 = C / q
    else:
        q = -B + sq
        r1 = C / q
        r2 = q / A
    # At a tangency the two roots meet and rounding may swap them.
    return min(r1, r2), max(r1, r2)


@kernel_jit()
def exact_slip(Fx, Fy, kxx, kxy, kyy, fd):
    """The exact 2D slip of the kernels: :func:`integrate_slip` at its default resolution."""
    return integrate_slip(Fx, Fy, kxx, kxy, kyy, fd, _STEPS_PER_PERIOD, 0.5)


@kernel_jit()
def integrate_slip(Fx, Fy, kxx, kxy, kyy, fd, steps_per_period, c):
    """Displacement of a node sliding from rest under F - K x and friction fd (2D, unit mass).

    The motion x'' = F - K x - fd v/|v| (the other nodes fixed) is integrated
    by RK4 from rest until the node sticks: its speed vanishes where the
    elastic force G = F - K x is at most fd. The direction of the friction
    turns at the rate |G|/|v|, which is stiff where the speed is small, so
    the step is h = min(h_max, c |v| / (|G| + fd)) with h_max = (period of
    the stiffest mode) / ``steps_per_period`` (c, about the largest turn of
    the velocity per step in radians); the first instant, still along F, is taken
    from the short-time solution; the last stretch, once |G| < fd and the
    remaining speed is gone within h_max, is taken at constant deceleration.
    A fixed-step version of this integration (before 0.2) could creep instead
    of stopping where friction nearly balanced G, and the stretch of a
    small overload was amplified rounding: benchmarks/slip_error.py measured
    both.

    For an isotropic K_ii and |F| < 3 fd the node stops after one
    half-oscillation, 2 (|F| - fd)/k along F: the straight-line slip, to
    rounding. For |F| >= 3 fd the node does not stick at the first turning
    point: it starts again from rest there and slides back, and so on until
    it sticks, all as one slip (the straight and 1D slips split such a
    motion into separate rearrangements, each redrawing the threshold).

    Returns (dx, dy, steps); steps < 0 if the node had not stuck within the
    step budget (``_MAX_PERIODS`` periods of the softest mode, at most 5e7
    steps). benchmarks/slip_error.py checks convergence against
    ``steps_per_period = 16000, c = 0.125``.
    """
    root = math.sqrt(0.25 * (kxx - kyy) ** 2 + kxy * kxy)
    lam = 0.5 * (kxx + kyy) + root
    lam_soft = max(0.5 * (kxx + kyy) - root, 1e-12 * lam)
    h_max = 2.0 * math.pi / math.sqrt(lam) / steps_per_period
    # A soft direction slows the motion down: budget periods of the softest mode.
    budget = int(steps_per_period * _MAX_PERIODS * max(1.0, math.sqrt(lam / lam_soft)))
    budget = min(budget, 50_000_000)
    absF = math.hypot(Fx, Fy)
    a0 = absF - fd
    if a0 <= 0.0:
        return 0.0, 0.0, 0
    ex = Fx / absF
    ey = Fy / absF
    # Short-time motion along F; its error, O(lam a0 t^4), is below rounding at t0.
    t0 = 1e-3 * h_max
    x = 0.5 * a0 * t0 * t0 * ex
    y = 0.5 * a0 * t0 * t0 * ey
    vx = a0 * t0 * ex
    vy = a0 * t0 * ey
    for n in range(budget):
        sp = math.hypot(vx, vy)
        Gx = Fx - (kxx * x + kxy * y)
        Gy = Fy - (kxy * x + kyy * y)
        G = math.hypot(Gx, Gy)
        if sp == 0.0:
            return x, y, n + 1
        if G < fd and sp <= h_max * (fd - G):
            # Friction removes the remaining speed within one step: the rest
            # of the way at the current deceleration along v.
            dec = fd - (Gx * vx + Gy * vy) / sp
            d = 0.5 * sp * sp / dec
            return x + d * vx / sp, y + d * vy / sp, n + 1
        if G >= fd:
            dec = fd - (Gx * vx + Gy * vy) / sp
            if dec > 0.0 and sp <= h_max * dec:
                # A turning point (|F| >= 3 fd for an isotropic block): the node
                # comes to rest within one step where friction cannot hold it,
                # and starts again from rest along G. Without this the speed
                # cap on h would shrink the steps geometrically towards the turn.
                d = 0.5 * sp * sp / dec
                x += d * vx / sp
                y += d * vy / sp
                Gx = Fx - (kxx * x + kxy * y)
                Gy = Fy - (kxy * x + kyy * y)
                G = math.hypot(Gx, Gy)
                if G <= fd:
                    return x, y, n + 1
                a0 = G - fd
                x += 0.5 * a0 * t0 * t0 * Gx / G
                y += 0.5 * a0 * t0 * t0 * Gy / G
                vx = a0 * t0 * Gx / G
                vy = a0 * t0 * Gy / G
                continue
        h = min(h_max, c * sp / (G + fd))
        a1x, a1y = _acc(x, y, vx, vy, Fx, Fy, kxx, kxy, kyy, fd)
        k2x = vx + 0.5 * h * a1x
        k2y = vy + 0.5 * h * a1y
        a2x, a2y = _acc(x + 0.5 * h * vx, y + 0.5 * h * vy, k2x, k2y, Fx, Fy, kxx, kxy, kyy, fd)
        k3x = vx + 0.5 * h * a2x
        k3y = vy + 0.5 * h * a2y
        a3x, a3y = _acc(x + 0.5 * h * k2x, y + 0.5 * h * k2y, k3x, k3y, Fx, Fy, kxx, kxy, kyy, fd)
        k4x = vx + h * a3x
        k4y = vy + h * a3y
        a4x, a4y = _acc(x + h * k3x, y + h * k3y, k4x, k4y, Fx, Fy, kxx, kxy, kyy, fd)
        x += h / 6.0 * (vx + 2.0 * k2x + 2.0 * k3x + k4x)
        y += h / 6.0 * (vy + 2.0 * k2y + 2.0 * k3y + k4y)
        vx += h / 6.0 * (a1x + 2.0 * a2x + 2.0 * a3x + a4x)
        vy += h / 6.0 * (a1y + 2.0 * a2y + 2.0 * a3y + a4y)
    return x, y, -1


@kernel_jit(forceinline=True)
def _acc(x, y, vx, vy, Fx, Fy, kxx, kxy, kyy, fd):
    """Acceleration of the unit-mass node: elastic force F - K x minus kinetic friction along v."""
    Gx = Fx - (kxx * x + kxy * y)
    Gy = Fy - (kxy * x + kyy * y)
    v = math.hypot(vx, vy)
    if v > 0.0:
        return Gx - fd * vx / v, Gy - fd * vy / v
    G = math.hypot(Gx, Gy)
    if G > fd:  # at rest, the node starts along G if friction cannot hold it
        return Gx - fd * Gx / G, Gy - fd * Gy / G
    return 0.0, 0.0


@kernel_jit(forceinline=True)
def update_node(net, nodes, heaps, j, theta):
    """Re-key node j in the three heaps after its force or threshold changed."""
    a = nodes.a
    gx = net.g[j, 0]
    gy = net.g[j, 1]
    Fx = a[j, 0] + gx * theta
    Fy = a[j, 1] + gy * theta
    F2 = Fx * Fx + Fy * Fy  # forces are O(1) in these units: no overflow, hypot not needed
    # With unit loads (every lattice by default) the load array stays out of the cache.
    lim = nodes.mu[j] if net.unit_load else nodes.mu[j] * net.normal_load[j]
    # Most updated nodes are stable and out of the heap: skip the call (and the root) then.
    if F2 > lim * lim or heaps.slot[j, UNSTABLE] >= 0:
        F = math.sqrt(F2)
        heap_set(heaps, UNSTABLE, j, F / lim, F > lim)
    # Driven nodes (g_j != 0) are those of the `driven` mask; reading g, already
    # at hand, spares a cache line per neighbour.
    if gx != 0.0 or gy != 0.0:
        dn, up = critical_thetas(a[j, 0], a[j, 1], gx, gy, lim)
        set_critical(heaps, j, dn, up)


@kernel_jit(forceinline=True)
def critical_roots(net, nodes, j):
    """(theta_dn, theta_up) of a driven node j: the roots of |a_j + g_j theta| = mu_s,j N_j."""
    lim = nodes.mu[j] if net.unit_load else nodes.mu[j] * net.normal_load[j]
    return critical_thetas(nodes.a[j, 0], nodes.a[j, 1], net.g[j, 0], net.g[j, 1], lim)


@kernel_jit(forceinline=True)
def straight_slip(Fx, Fy, norm, mag, kxx, kxy, kyy, fd, sf):
    """The straight-line slip: sf (mag - fd) / k_eff along e = F / norm, k_eff = e^T K_ii e.

    ``sf`` = 1 + friction.overshoot: 2 for the undamped half-oscillation (eq. `displacement`).

    ``mag`` is the force magnitude the slip starts from (mu_s N exactly at a
    driving event, |F| in an avalanche) and ``norm`` what F is divided by:
    |F| as computed in an avalanche, and mu_s N at a driving event
    (:func:`slip_displacement`). There e has unit length only to the
    rounding of eq. `critique`'s root, which leaves |F(theta_c)| =
    mu_s N (1 + delta): the slip's length is off by the same relative
    delta, measured at most 5e-14, 7e-12, 2e-10, 2e-10, 4e-9 and 3e-7 at
    sigma_theta / Ntilde ~ 1, 10, 1e2, 1e4, 1e6 and 1e8 (``python
    benchmarks/driving_slip_direction.py``; before the discriminant of
    :func:`critical_thetas` switched to Lagrange's identity, 3e-6 at 1e4 and
    a zero force, then a division by zero, from ~1e7 on). It is kept so, not
    divided by the computed |F|: the node's force at the event is itself
    off its threshold by that delta (the root's rounding, which no
    normalization removes), and normalizing would change every 2D result in
    its last bits, the golden files included.
    """
    ex = Fx / norm
    ey = Fy / norm
    keff = kxx * ex * ex + 2.0 * kxy * ex * ey + kyy * ey * ey
    length = sf * (mag - fd) / keff
    return length * ex, length * ey


@kernel_jit(inline="always")
def _slip_displacement(net, nodes, settings, i, theta, driving, slip):
    """The slip of node i alone, the others fixed, by the rule ``slip`` (:func:`slip_straight` or
    :func:`slip_exact`): (ok, du_x, du_y).

    A driving slip (``driving``) starts exactly at the threshold,
    |F_i| = mu_s,i N_i, along the force computed at theta divided by that
    threshold (a direction of unit length to the rounding of theta_c: see
    :func:`straight_slip`).
    """
    Fx = nodes.a[i, 0] + net.g[i, 0] * theta
    Fy = nodes.a[i, 1] + net.g[i, 1] * theta
    if driving:
        # mu * 1.0 == mu exactly: with unit loads the load's cold cache line is not read.
        absF = nodes.mu[i] if net.unit_load else nodes.mu[i] * net.normal_load[i]
    else:
        absF = math.sqrt(Fx * Fx + Fy * Fy)
    return slip(net, settings, i, Fx, Fy, absF, absF)


@kernel_jit(forceinline=True)
def slip_displacement(net, nodes, settings, i, theta, driving, s):
    """The straight-line slip of node i (``solver.slip = "straight"``): (True, du_x, du_y)."""
    return _slip_displacement(net, nodes, settings, i, theta, driving, slip_straight)


@kernel_jit(forceinline=True)
def slip_displacement_exact(net, nodes, settings, i, theta, driving, s):
    """The exactly integrated slip of node i (``solver.slip = "exact"``): (ok, du_x, du_y)."""
    return _slip_displacement(net, nodes, settings, i, theta, driving, slip_exact)


@kernel_jit(forceinline=True)
def _diagonal_block(net, i):
    """The entries (kxx, kxy, kyy) of node i's diagonal block K_ii."""
    b = block_of(net, net.diag[i])
    K = net.K_table
    return K[b, 0, 0], K[b, 0, 1], K[b, 1, 1]


@kernel_jit(forceinline=True)
def slip_straight(net, settings, i, Fx, Fy, norm, mag):
    """(True, du_x, du_y): node i slides from rest under the force (Fx, Fy) along a straight line
    (:func:`straight_slip`, with ``norm`` and ``mag``), the others fixed. Used by the kernel and by
    the network tilt test."""
    fd = settings.mu_d if net.unit_load else settings.mu_d * net.normal_load[i]  # mu_d * 1.0 == mu_d
    kxx, kxy, kyy = _diagonal_block(net, i)
    dux, duy = straight_slip(Fx, Fy, norm, mag, kxx, kxy, kyy, fd, settings.slip_factor)
    return True, dux, duy


@kernel_jit(forceinline=True)
def slip_exact(net, settings, i, Fx, Fy, norm, mag):
    """(ok, du_x, du_y): node i slides from rest under the force (Fx, Fy) by the exact 2D motion
    (:func:`exact_slip`), the others fixed; ok is False if the motion did not come to rest within
    its step budget. ``norm`` and ``mag`` are not read (the signature is :func:`slip_straight`'s)."""
    fd = settings.mu_d if net.unit_load else settings.mu_d * net.normal_load[i]
    kxx, kxy, kyy = _diagonal_block(net, i)
    dux, duy, nsteps = exact_slip(Fx, Fy, kxx, kxy, kyy, fd)
    return nsteps >= 0, dux, duy


@kernel_jit(forceinline=True)
def block_of(net, p):
    """The row of ``net.K_table`` holding the block of entry p: p itself where every entry has its own.

    Skipping K_id there (any network but a lattice) spares a load that the
    block's own load would wait for, and K_id's cache lines (4 bytes per entry).
    """
    # p is an entry of K's rows (diag[i] included: the scene checks that every row holds K_ii) and K_id a
    # row of K_table: neither is ever negative.
    return nonneg(p) if net.block_per_entry else nonneg(net.K_id[nonneg(p)])


@kernel_jit(forceinline=True)
def _pushed(net, a, p, j, dux, duy):
    """a_j -= K_ji du_i for the entry p of row i (K is symmetric: K_ji = K_ij, the stored block)."""
    K = net.K_table
    b = block_of(net, p)
    a[j, 0] -= K[b, 0, 0] * dux + K[b, 0, 1] * duy
    a[j, 1] -= K[b, 1, 0] * dux + K[b, 1, 1] * duy


@kernel_jit(forceinline=True)
def spread(net, a, i, dux, duy):
    """The forces a_j of node i's neighbours (and its own) after it moved by (dux, duy): a -= K du."""
    for p in range(net.indptr[i], net.indptr[i + 1]):
        _pushed(net, a, p, net.indices[p], dux, duy)


@kernel_jit(forceinline=True)
def move_node(net, st, nodes, heaps, i, dux, duy, theta):
    """Displace node i by (dux, duy): the centre of mass, and the force offsets on the block row of K,
    each node of the row re-keyed (:func:`update_node`) as soon as its force is moved."""
    nodes.u[i, 0] += dux
    nodes.u[i, 1] += duy
    # With unit loads every weight is the same 1/N: w[0], in cache, has the bits of w[i].
    wi = net.w[0] if net.unit_load else net.w[i]
    st.x_G += dux * wi
    st.y_G += duy * wi
    lo = nonneg(net.indptr[i])
    hi = nonneg(net.indptr[i + 1])
    if heaps.leaf.size == 0:
        # Every node is driven (an irregular network): driving events land anywhere, and the
        # neighbours' lines are out of cache at large N. Ask for all of them first so that their
        # misses can overlap (+5.5 % in the median run at 1e6 nodes). A lattice's activity stays at
        # its driven boundary, in cache: nothing to gain there.
        r = heaps.active[0]
        for p in range(lo, hi):
            j = net.indices[nonneg(p)]
            prefetch(nodes.a, j)
            prefetch(net.g, j)
            prefetch(nodes.mu, j)
            prefetch(heaps.slot, j)
            prefetch(heaps.stale, j)
            prefetch(heaps.tkey, (r, j))
    for p in range(lo, hi):
        q = nonneg(p)  # lo >= 0, but the compiler does not carry that over to p
        j = nonneg(net.indices[q])
        _pushed(net, nodes.a, q, j, dux, duy)
        update_node(net, nodes, heaps, j, theta)



@kernel_jit()
def stiffness_times(net, u, out):
    """out = K u over the block rows of K (``out`` and ``u`` of shape (N, 2)): the forces' reset."""
    K = net.K_table
    for n in range(net.indptr.size - 1):
        sx = 0.0
        sy = 0.0
        for p in range(net.indptr[n], net.indptr[n + 1]):
            j = net.indices[p]
            b = block_of(net, p)
            sx += K[b, 0, 0] * u[j, 0] + K[b, 0, 1] * u[j, 1]
            sy += K[b, 1, 0] * u[j, 0] + K[b, 1, 1] * u[j, 1]
        out[n, 0] = sx
        out[n, 1] = sy


@kernel_jit()
def run_plane(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings):
    """:func:`slidernet.kernels.network.run_network` on a 2D network (``net`` a Plane), straight-line slips."""
    return run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings,
                       update_node, critical_roots, slip_displacement, move_node, no_tilt, tree_event)


@kernel_jit()
def run_plane_exact(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings):
    """:func:`run_plane` with the exactly integrated slip (``solver.slip = "exact"``)."""
    return run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings,
                       update_node, critical_roots, slip_displacement_exact, move_node, no_tilt, tree_event)


@kernel_jit()
def run_plane_aging(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings):
    """:func:`run_plane` with contact strengthening (``nodes`` an AgingNodes; see :mod:`.strength`)."""
    return run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings,
                       update_node, critical_roots, slip_displacement, move_node, no_tilt,
                       strengthened_event)


@kernel_jit()
def run_plane_exact_aging(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings):
    """:func:`run_plane_exact` with contact strengthening."""
    return run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings,
                       update_node, critical_roots, slip_displacement_exact, move_node, no_tilt,
                       strengthened_event)


@kernel_jit()
def init_plane_heaps(net, state, nodes, heaps, t):
    """:func:`slidernet.kernels.network.init_heaps` on a 2D network (t, the state's time, is not read)."""
    init_heaps(net, state, nodes, heaps, update_node)


@kernel_jit()
def init_plane_heaps_aging(net, state, nodes, heaps, t):
    """:func:`init_plane_heaps` with contact strengthening: every threshold first brought up to time t (tau_th)."""
    refresh_all_nodes(nodes, t)
    init_heaps(net, state, nodes, heaps, update_node)
