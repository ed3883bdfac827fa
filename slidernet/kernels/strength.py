"""Contact strengthening: a threshold that grows with the age of its contact, and its exact events.

With ``friction.strengthening`` the static threshold of node i is

    mu_s,i(t) = mu_s,i^0 + beta L(a_i(t) / tau_c),   a_i(t) = t - t_i,

where mu_s,i^0 is the threshold drawn at the node's last renewal (its last
slip, at time t_i; t_i = 0 for a node that has not slipped) and L is the
law: L(x) = ln(1 + x) (``exponent`` 0, the logarithmic law of Dieterich and
of Baumberger and Caroli) or L(x) = (1 + x)^p - 1 with 0 < p <= 1 (a power
law). Both are 0 at a = 0, increasing and concave: a renewed contact starts
at its drawn threshold.

How the event-driven solver stays exact
---------------------------------------
A node's threshold only grows between its slips, so time alone never makes
a node slip: an event still needs theta to move. Within thermal step q,
theta is linear in t, t(theta) = q + (theta - theta_q) / (theta_q+1 -
theta_q), so the node's gap h(theta) = mu_s,i(t(theta)) N_i - |F_i(theta)|
is concave (a concave threshold minus the norm of a force linear in theta):
once h < 0 it stays < 0 within the step, and the node's event is the one
root of h after the current theta.

The driving trees keep each node keyed by the roots of eq. `critique`
computed with ``nodes.mu``, the node's threshold at the last time it was
brought up to date, which is never above its threshold at any later time:
a key is a lower bound of the node's true event in theta's direction.
:func:`strengthened_event` takes the node at the top of the tree and solves
its true event in the step; if the node has none there, it is re-keyed past
the end of the step (its threshold there), and the next node is tried; the
first node whose exact event leads the tree is the event (a lazy search,
which solves only the nodes whose bound falls within the step). The root is
bracketed and found by the Illinois variant of regula falsi on the fixed
point theta = theta_c(mu_s,i(t(theta))) (eq. `critique`'s root with the
threshold at theta's time), to a bracket of at most 4 eps |theta| (4 to 8
ulp of theta); the slip then starts at the threshold of the bracket's end, |F_i| = mu_s,i N_i
to the rounding of eq. `critique`'s root, as without strengthening.

The nodes a slip moves are brought up to the avalanche's time first
(:func:`refresh_row`, by :func:`renew_contact` in the slip of
:func:`slidernet.kernels.network.slip_node`), so that every
stability test of an avalanche reads the threshold of that moment; at an
output step every node is (:func:`refresh_all`), so that mu_max, mu_mean,
mu_min and the network tilt test read the thresholds of the record's time.
All of it reads ``nodes.mu0`` and ``nodes.law``, which only an
:data:`~slidernet.kernels.state.AgingNodes` has: the kernels of scenes
without strengthening are compiled for :class:`~slidernet.kernels.state.Nodes`
and carry none of it.
"""

from __future__ import annotations

import math

from numba.extending import overload

from slidernet.kernels.heap import next_driving_event, set_critical
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.state import nonneg

# law = (beta, tau_c, exponent)
BETA = 0
TAU_C = 1
EXPONENT = 2

# Bracket iterations of one root before bisection alone finishes it (a bisection halves a float64
# bracket to 4 ulp in at most ~60 more).
ROOT_ITER = 200
EPS = 2.0**-52  # float64's machine epsilon: 4 EPS |theta| is 4 to 8 ulp of theta


@kernel_jit(forceinline=True)
def strengthening(law, age):
    """beta L(age / tau_c): what a contact of ``age`` tau_th adds to its drawn threshold (0 at age 0)."""
    x = max(age, 0.0) / law[TAU_C]
    p = law[EXPONENT]
    if p == 0.0:
        return law[BETA] * math.log1p(x)
    return law[BETA] * math.expm1(p * math.log1p(x))


@kernel_jit(forceinline=True)
def threshold_at(nodes, j, t):
    """mu_s,j at time t (tau_th): the drawn threshold plus the strengthening of its contact's age."""
    return nodes.mu0[j] + strengthening(nodes.law, t - nodes.last_slip[j])


@kernel_jit(forceinline=True)
def refresh_row(net, nodes, i, t):
    """Before node i's slip moves the forces of its row: its renewed contact starts at the threshold it has
    just drawn (age 0), and every node of the row has its threshold brought up to time t (tau_th), the
    avalanche's, so that its stability is tested against the threshold of that moment. ``net`` is a Chain
    or a Plane (both keep their rows in ``indptr`` and ``indices``)."""
    nodes.mu0[i] = nodes.mu[i]
    for p in range(nonneg(net.indptr[i]), nonneg(net.indptr[i + 1])):
        j = nonneg(net.indices[nonneg(p)])
        nodes.mu[j] = threshold_at(nodes, j, t)


@kernel_jit()
def refresh_all_nodes(nodes, t):
    """Bring every threshold up to time t (tau_th), O(N): when the heaps are rebuilt."""
    for j in range(nodes.mu.size):
        nodes.mu[j] = threshold_at(nodes, j, t)


@kernel_jit()
def refresh_all(st, nodes, t):
    """Bring every threshold up to time t, and mu_max and its holder with them, O(N): at output steps."""
    refresh_all_nodes(nodes, t)
    mu = nodes.mu
    best = 0
    for j in range(mu.size):
        if mu[j] > mu[best]:
            best = j
    st.mu_max = mu[best]
    st.argmax = best


def _aging(nodes) -> bool:
    """True if numba's type of ``nodes`` is an AgingNodes: the overloads below compile their work only then."""
    return "mu0" in getattr(nodes, "fields", ())


def refresh_at_record(st, nodes, t):
    """At an output step: :func:`refresh_all` where ``nodes`` is an AgingNodes, nothing for Nodes (compiled
    per type by numba, :func:`_refresh_at_record`: a kernel without strengthening carries no line of it)."""


@overload(refresh_at_record, jit_options={"cache": True})
def _refresh_at_record(st, nodes, t):
    if _aging(nodes):
        def impl(st, nodes, t):
            refresh_all(st, nodes, t)
        return impl

    def nothing(st, nodes, t):
        pass
    return nothing


def renew_contact(st, net, nodes, i):
    """Before node i's slip moves the forces of its row: :func:`refresh_row` at the avalanche's time
    (``st.event_time``) where ``nodes`` is an AgingNodes, nothing for Nodes (compiled per type, as
    :func:`refresh_at_record`)."""


@overload(renew_contact, jit_options={"cache": True})
def _renew_contact(st, net, nodes, i):
    if _aging(nodes):
        def impl(st, net, nodes, i):
            refresh_row(net, nodes, i, st.event_time)
        return impl

    def nothing(st, net, nodes, i):
        pass
    return nothing


@kernel_jit(inline="always")
def solve_event(st, net, nodes, j, thetas, s, critical_roots):
    """Set node j's threshold to its value at its exact event in step q, or at the end of the step if it
    has none there: on return ``nodes.mu[j]`` makes eq. `critique`'s root the event (or a point past the
    step)."""
    q = nonneg(st.q)
    theta_a = thetas[q]
    theta_b = thetas[q + 1]
    rate = theta_b - theta_a
    t0 = float(q)
    lo = st.theta
    hi = theta_b
    f_hi = _crossing_at(net, nodes, j, hi, theta_a, rate, t0, s, critical_roots)
    if f_hi > 0.0:
        return  # its threshold at the step's end is not reached within the step: no event in it
    f_lo = _crossing_at(net, nodes, j, lo, theta_a, rate, t0, s, critical_roots)
    if f_lo <= 0.0:
        return  # at its threshold already (rounding): the event is now
    side = 0
    for it in range(ROOT_ITER + 64):
        if abs(hi - lo) <= 4.0 * EPS * max(abs(hi), abs(lo)):
            break
        if it < ROOT_ITER:
            x = hi - f_hi * (hi - lo) / (f_hi - f_lo)  # regula falsi
            if not (min(lo, hi) < x < max(lo, hi)):
                x = 0.5 * (lo + hi)
        else:
            x = 0.5 * (lo + hi)
        f = _crossing_at(net, nodes, j, x, theta_a, rate, t0, s, critical_roots)
        if f > 0.0:
            lo, f_lo = x, f
            if side == -1:
                f_hi *= 0.5  # Illinois: the end kept twice in a row counts half
            side = -1
        else:
            hi, f_hi = x, f
            if side == 1:
                f_lo *= 0.5
            side = 1
    _crossing_at(net, nodes, j, hi, theta_a, rate, t0, s, critical_roots)


@kernel_jit(inline="always")
def _crossing_at(net, nodes, j, theta, theta_a, rate, t0, s, critical_roots):
    """phi(theta) = s (theta_c - theta), theta_c eq. `critique`'s root in theta's direction s with node j's
    threshold set to its value at t(theta) = t0 + (theta - theta_a) / rate: > 0 before the node's event,
    <= 0 from it on."""
    nodes.mu[j] = threshold_at(nodes, j, t0 + (theta - theta_a) / rate)
    dn, up = critical_roots(net, nodes, j)
    return s * ((up if s > 0.0 else dn) - theta)


@kernel_jit(inline="always")
def strengthened_event(st, net, nodes, heaps, thetas, s, critical_roots):
    """The next driving event of step q with strengthening: ``(node, theta_c)`` as :func:`next_driving_event`.

    The lazy search of this module's docstring: the tree's top is solved exactly and re-keyed until the
    node at the top is the one just solved.
    """
    last = -1
    while True:
        best, thc = next_driving_event(st, heaps, thetas, s)
        if best < 0 or best == last:
            return best, thc
        j = nonneg(best)
        solve_event(st, net, nodes, j, thetas, s, critical_roots)
        dn, up = critical_roots(net, nodes, j)
        set_critical(heaps, j, dn, up)
        last = best
