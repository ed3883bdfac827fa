"""The network kernel: one driving loop for 1D and 2D networks.

:func:`run_network` advances any network through theta(t_q): it relaxes
avalanches largest overload first, then jumps theta to the next node's
critical value (eq. `critique`) or to the end of the thermal step. What
depends on the dimension -- the force's norm, the roots of eq. `critique`,
the slip, how a slip moves the forces -- comes in as five functions of the
geometry, from :mod:`slidernet.kernels.chain` (1D: scalar forces, CSR rows
of K) or :mod:`slidernet.kernels.plane` (2D: vector forces, 2 x 2 blocks):

* ``update_node(net, nodes, heaps, j, theta)``: re-key node j in the heap and trees;
* ``critical_roots(net, nodes, j)``: theta_dn and theta_up of a driven node;
* ``slip_displacement(net, nodes, settings, i, theta, driving, s)``: the
  slip of node i alone, ``(ok, du_x, du_y)``;
* ``move_node(net, st, nodes, heaps, i, du_x, du_y, theta)``:
  apply it to u, to the centre of mass and to the force offsets of the row
  of K, re-keying each node of the row as its force moves;
* ``tilt(net, st, nodes, draws, out, settings)``: the appendix's tilt test
  before a rearrangement (a 1D pair, :func:`slidernet.kernels.chain.pair_tilt`)
  or nothing (:func:`no_tilt`);
* ``driving_event(st, net, nodes, heaps, thetas, s, critical_roots)``: the
  next driving event, the top of the driving tree (:func:`tree_event`) or,
  with contact strengthening, the lazy exact search of
  :func:`slidernet.kernels.strength.strengthened_event`; the variants with
  strengthening (``run_chain_aging``, ``run_plane_aging``, ...) pass it and
  run on a :class:`~slidernet.kernels.state.AgingNodes`, for which
  :func:`slip_node` brings the thresholds of the slipped node's row up to
  date before it moves them (``strength.renew_contact``, compiled per type),
  so that no other kernel carries a line of it.

Only the functions that take other functions are inlined into the kernel
by numba (``inline="always"``: :func:`run_network`, :func:`slip_node`,
:func:`init_heaps`, :func:`turn`): a function passed as an argument of a
compiled call would become an address in the machine code, which numba
cannot cache. Each geometry's kernel (:func:`~slidernet.kernels.chain.run_chain`,
:func:`~slidernet.kernels.plane.run_plane` and their variants) passes them
its own functions, resolved when it is compiled, so each kernel runs as if
the loop had been written for it alone. Every other helper is compiled once
as a function of its own and inlined by LLVM (``forceinline=True``):
inlining every helper in numba's IR, as before, made compiling 3 to 7 times
slower for the same speed (docs/guides/performance.md, "Compiling").
"""

from __future__ import annotations

from slidernet.kernels.heap import (
    avalanche_done,
    buffers_low,
    close_t0,
    end_step,
    heap_clear,
    log_event,
    next_driving_event,
    open_driving_event,
    open_initial_relaxation,
    open_recomputed_avalanche,
    redraw_threshold,
    theta_direction,
    tree_set,
    write_ages,
    write_output,
)
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.state import AVALANCHE_LIMIT, DONE, DOWN, RECOMPUTE, SLID_AWAY, UNSTABLE, UP, nonneg
from slidernet.kernels.strength import refresh_at_record, renew_contact


@kernel_jit(inline="always")
def init_heaps(net, state, nodes, heaps, update_node):
    """(Re)build the unstable heap and the driving trees from scratch, O(N log N) at most."""
    st = state[0]
    heap_clear(heaps)
    for j in range(nodes.mu.size):
        update_node(net, nodes, heaps, j, st.theta)


@kernel_jit(inline="always")
def slip_node(net, st, nodes, heaps, draws, catalogue, settings, i, driving, s, update_node, slip_displacement,
              move_node):
    """Node i slips alone; its threshold is redrawn and it and its neighbours are re-keyed.

    Returns False if the slip did not come to rest (the exact 2D slip's step budget).
    """
    theta = st.theta
    ok, dux, duy = slip_displacement(net, nodes, settings, i, theta, driving, s)
    if not ok:
        return False
    log_event(st, catalogue, i, dux, duy)
    if nodes.last_slip.size:  # contact_age: the slip's time is its driving event's (0-length: not recorded)
        nodes.last_slip[i] = st.event_time
    # The new threshold first, so that one pass over the row both moves the forces and re-keys the
    # nodes (each node's key reads only its own force and threshold: the same keys, in the same order,
    # as moving every force first).
    redraw_threshold(st, i, nodes.mu, draws.mu, nodes.node_slips)
    renew_contact(st, net, nodes, i)  # strengthening only (an AgingNodes); nothing otherwise
    move_node(net, st, nodes, heaps, i, dux, duy, theta)
    return True


@kernel_jit(forceinline=True)
def every_node_moving(st, nodes, i):
    """Count node i among the nodes the current avalanche has set in motion; True once that is all of them.

    The avalanche's id is ``st.n_events`` (0: the relaxation at t = 0);
    ``nodes.moving`` stamps each node with the last avalanche it slipped in,
    so the count costs O(1) per slip and nothing between avalanches.
    """
    av = st.n_events
    if st.moving_id != av:
        st.moving_id = av
        st.n_moving = 0
    if nodes.moving[i] != av:
        nodes.moving[i] = av
        st.n_moving += 1
    return st.n_moving == nodes.mu.size


@kernel_jit(forceinline=True)
def record(st, nodes, out, t):
    """Write the state into the next output slot; t is the time of that state, in tau_th.

    The contact ages are written only where the scene records them (``out.contact_age`` not 0-length);
    with strengthening every threshold is first brought up to time t.
    """
    refresh_at_record(st, nodes, t)
    if out.contact_age.size:
        write_ages(t, nodes.last_slip, out, st.next_out)
    write_output(st, nodes.mu, out)


@kernel_jit(forceinline=True)
def slide_away(st, nodes, out, out_steps):
    """The network slides away: record when, and hold the state of that moment in the records left
    (contact ages included: their time is the slide's)."""
    st.slid_away = 1
    st.slid_away_at = st.event_time
    while st.next_out < out_steps.size:
        record(st, nodes, out, st.slid_away_at)
    return SLID_AWAY


@kernel_jit(inline="always")
def turn(net, nodes, heaps, s, critical_roots):
    """Make the driving tree of theta's direction s the active one, up to date.

    When theta turns, the nodes re-keyed since the last turn get their key in
    the tree that becomes active (their key in the other one is up to date:
    it was the active tree). O(stale nodes log N), once per turn, instead of
    a second update at every slip.
    """
    if s == 0.0:
        return  # theta stands still: no driving event in this step
    want = UP if s > 0.0 else DOWN
    if heaps.active[0] == want:
        return
    heaps.active[0] = want
    for k in range(heaps.n_stale[0]):
        j = nonneg(heaps.stale_nodes[k])
        heaps.stale[j] = 0
        dn, up = critical_roots(net, nodes, j)
        if want == UP:
            tree_set(heaps, UP, j, -up)
        else:
            tree_set(heaps, DOWN, j, dn)
    heaps.n_stale[0] = 0


@kernel_jit(forceinline=True)
def no_tilt(net, st, nodes, draws, out, settings):
    """The ``tilt`` of a kernel without the appendix's test before every rearrangement: nothing, DONE."""
    return DONE


@kernel_jit(inline="always")
def tree_event(st, net, nodes, heaps, thetas, s, critical_roots):
    """The ``driving_event`` of thresholds that do not age: the top of the active driving tree
    (:func:`~slidernet.kernels.heap.next_driving_event`)."""
    return next_driving_event(st, heaps, thetas, s)


@kernel_jit(inline="always")
def run_network(thetas, out_steps, net, state, nodes, heaps, draws, catalogue, out, settings, update_node,
                critical_roots, slip_displacement, move_node, tilt, driving_event):
    """Advance a network through ``thetas`` (units of Ntilde); returns a status code.

    Parameters
    ----------
    thetas : ndarray, shape (steps + 1,)
        theta(t_q) / Ntilde; the run stops at the end of the array.
    out_steps : ndarray of int64, shape (T,)
        The steps at which the state is written to ``out``.
    net : Chain or Plane
        The network's operators; their type picks the geometry.
    state : ndarray of dtype STATE, shape (1,)
        The realization's scalars.
    nodes : Nodes
        The per-node state.
    heaps : Heaps
        The unstable heap and the driving trees, built by :func:`init_heaps`.
    draws : Draws
        Thresholds to hand out, one per slip (and the tilt test's draws).
    catalogue : Catalogue
        The event catalogue's buffer (0 rows when it is off).
    out : Series
        The output series.
    settings : Settings
        mu_d, max_slips, recompute_every, slide_away.

    Returns ``DONE`` at the end of ``thetas``, ``NEED_MU``, ``NEED_TILT`` or
    ``NEED_EVENTS`` when a buffer runs low, ``RECOMPUTE`` every
    ``recompute_every`` slips (0: never) so that the caller recomputes the
    forces from the displacements and rebuilds the heaps, and
    ``AVALANCHE_LIMIT`` (node in ``err_node``). An unstable initial state (a
    large f_ext) is relaxed first, as part of t = 0.

    With ``settings.slide_away`` (the mean load along x exceeds mu_d) an
    avalanche that sets every node in motion, or that exceeds ``max_slips``
    slips (a part sliding alone), is the network sliding away: the kernel
    sets ``slid_away`` and ``slid_away_at`` (the avalanche's event time),
    writes the state of that moment into every output step left, and
    returns ``SLID_AWAY``; the realization is over.
    """
    st = state[0]
    steps = thetas.size - 1
    open_initial_relaxation(st, heaps)
    open_recomputed_avalanche(st, heaps, thetas)
    while True:
        while heaps.size[UNSTABLE] > 0:
            i = nonneg(heaps.node[UNSTABLE, 0])
            st.av_slips += 1
            if st.av_slips > settings.max_slips:
                if settings.slide_away:
                    return slide_away(st, nodes, out, out_steps)
                st.err_node = i
                return AVALANCHE_LIMIT
            # The buffer check comes first: a kernel that returns after the
            # tilt sample would take it again on re-entry.
            status = buffers_low(st, draws, catalogue)
            if status == DONE:
                status = tilt(net, st, nodes, draws, out, settings)
            if status != DONE:
                st.av_slips -= 1
                return status
            if not slip_node(net, st, nodes, heaps, draws, catalogue, settings, i, False, 0.0, update_node,
                             slip_displacement, move_node):
                st.err_node = i
                return AVALANCHE_LIMIT
            if settings.slide_away and every_node_moving(st, nodes, i):
                return slide_away(st, nodes, out, out_steps)
        avalanche_done(st, nodes.avalanche_count)
        if st.started == 0:
            # The tilt test before each rearrangement needs f_ext = 0, so
            # there was no initial relaxation: this is the state at t = 0.
            status = tilt(net, st, nodes, draws, out, settings)
            if status != DONE:
                return status
        if close_t0(st, out_steps):
            record(st, nodes, out, 0.0)
        if settings.recompute_every > 0 and st.since_recompute >= settings.recompute_every:
            return RECOMPUTE
        if st.q >= steps:
            return DONE
        s = theta_direction(st, thetas)
        turn(net, nodes, heaps, s, critical_roots)
        best, thc = driving_event(st, net, nodes, heaps, thetas, s, critical_roots)
        if best >= 0:
            best = nonneg(best)
            st.theta = thc
            status = buffers_low(st, draws, catalogue)
            if status == DONE:
                status = tilt(net, st, nodes, draws, out, settings)
            if status != DONE:
                return status
            open_driving_event(st, thetas, thc)
            if not slip_node(net, st, nodes, heaps, draws, catalogue, settings, best, True, s, update_node,
                             slip_displacement, move_node):
                st.err_node = best
                return AVALANCHE_LIMIT
            if settings.slide_away and every_node_moving(st, nodes, best):
                return slide_away(st, nodes, out, out_steps)
            continue
        if end_step(st, thetas, out_steps):
            record(st, nodes, out, float(st.q))
