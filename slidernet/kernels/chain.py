"""The geometry of 1D networks: scalar forces, CSR rows of K.

The force on node i is F_i = a_i + g_i theta, with a = -K u - g theta(0)
(+ f_ext) updated incrementally on the CSR row of the slipped node. A node
is stable while |F_i| <= mu_s,i N_i, i.e. while theta lies between its two
critical values theta_dn,i <= theta <= theta_up,i (eq. `critique` for node i);
these only change when the node or a neighbour slips.

These are the pieces of :func:`slidernet.kernels.network.run_network` that
depend on the dimension; the driving loop itself is shared with 2D
networks (:mod:`slidernet.kernels.plane`). On a 2-node chain they perform
the same floating-point operations as :func:`slidernet.kernels.pair.run_pair`.
"""

from __future__ import annotations

from slidernet.kernels.heap import heap_set, set_critical
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.network import init_heaps, no_tilt, run_network, tree_event
from slidernet.kernels.state import UNSTABLE, nonneg
from slidernet.kernels.strength import refresh_all_nodes, strengthened_event
from slidernet.kernels.tilt import tilt_sample


@kernel_jit(forceinline=True)
def update_node(net, nodes, heaps, j, theta):
    """Re-key node j in the three heaps after its force or threshold changed."""
    a = nodes.a
    g = net.g
    F = abs(a[j] + g[j] * theta)
    # With unit loads (the default) the load array stays out of the cache; mu * 1.0 is mu exactly.
    lim = nodes.mu[j] if net.unit_load else nodes.mu[j] * net.normal_load[j]
    # Most updated nodes are stable and out of the heap: skip the call then.
    if F > lim or heaps.slot[j, UNSTABLE] >= 0:
        heap_set(heaps, UNSTABLE, j, F / lim, F > lim)
    if g[j] != 0.0:
        dn, up = critical_roots(net, nodes, j)
        set_critical(heaps, j, dn, up)


@kernel_jit(forceinline=True)
def critical_roots(net, nodes, j):
    """(theta_dn, theta_up) of a driven node j: the two roots of |a_j + g_j theta| = mu_s,j N_j."""
    a = nodes.a[j]
    gj = net.g[j]
    lim = nodes.mu[j] if net.unit_load else nodes.mu[j] * net.normal_load[j]
    if gj > 0.0:
        return (-lim - a) / gj, (lim - a) / gj
    return (lim - a) / gj, (-lim - a) / gj


@kernel_jit(forceinline=True)
def slip_displacement(net, nodes, settings, i, theta, driving, s):
    """The slip of node i alone: (True, du, 0.0).

    Delta u_i = (1 + e) (|F_i| - mu_d N_i) sign(F_i) / K_ii, e = friction.overshoot
    (``settings.slip_factor`` = 1 + e; e = 1: the undamped half-oscillation of eq. `displacement`).
    A driving slip (``driving``, theta moving with sign s) starts exactly at
    the threshold, |F_i| = mu_s,i N_i, with the sign of g_i s.
    """
    if driving:
        absF = nodes.mu[i] * net.normal_load[i]
        F = absF if net.g[i] * s > 0.0 else -absF
    else:
        F = nodes.a[i] + net.g[i] * theta
        absF = abs(F)
    sgn = 1.0 if F > 0.0 else -1.0
    return True, settings.slip_factor * (absF - settings.mu_d * net.normal_load[i]) * sgn / net.K_diag[i], 0.0


@kernel_jit(forceinline=True)
def move_node(net, st, nodes, heaps, i, dux, duy, theta):
    """Displace node i by dux: the centre of mass, and the force offsets on the CSR row of K, each
    node of the row re-keyed (:func:`update_node`) as soon as its force is moved."""
    nodes.u[i] += dux
    st.x_G += dux * net.w[i]
    # nonneg: the row's bounds, its entries and their nodes are indices >= 0, and numba's wrap-around
    # of a negative index goes away (run_chain's sign tests, sar $63: 35 -> 27). Interleaved runs on
    # core 0, a chain of 1000 nodes (2026-11-26, slips and x_G unchanged): -6 to +21 %, median of
    # 9 rounds +9 %.
    for p in range(nonneg(net.indptr[i]), nonneg(net.indptr[i + 1])):
        q = nonneg(p)  # the compiler does not carry lo >= 0 over to p
        j = nonneg(net.indices[q])
        nodes.a[j] -= net.K_data[q] * dux
        update_node(net, nodes, heaps, j, theta)



@kernel_jit(forceinline=True)
def pair_tilt(net, st, nodes, draws, out, settings):
    """The appendix's tilt test on a 2-node chain, its sample added to the output bin ``st.next_out``.

    The spring force on node 1, F_{1->2}, is what the test reads.
    """
    F = nodes.a[1] + net.g[1] * st.theta
    return tilt_sample(st, draws, out, st.next_out, F, nodes.mu[0], nodes.mu[1], settings.mu_d,
                       settings.slip_factor)


@kernel_jit()
def run_chain(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings):
    """:func:`slidernet.kernels.network.run_network` on a 1D network (``net`` a Chain)."""
    return run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings,
                       update_node, critical_roots, slip_displacement, move_node, no_tilt, tree_event)


@kernel_jit()
def run_chain_aging(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings):
    """:func:`run_chain` with contact strengthening (``nodes`` an AgingNodes; see :mod:`.strength`)."""
    return run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings,
                       update_node, critical_roots, slip_displacement, move_node, no_tilt,
                       strengthened_event)


@kernel_jit()
def run_chain_tilt(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings):
    """:func:`run_chain` with the appendix's tilt test before every rearrangement (a 2-node chain)."""
    return run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings,
                       update_node, critical_roots, slip_displacement, move_node, pair_tilt, tree_event)


@kernel_jit()
def init_chain_heaps(net, state, nodes, heaps, t):
    """:func:`slidernet.kernels.network.init_heaps` on a 1D network (t, the state's time, is not read)."""
    init_heaps(net, state, nodes, heaps, update_node)


@kernel_jit()
def init_chain_heaps_aging(net, state, nodes, heaps, t):
    """:func:`init_chain_heaps` with contact strengthening: every threshold first brought up to time t (tau_th)."""
    refresh_all_nodes(nodes, t)
    init_heaps(net, state, nodes, heaps, update_node)
