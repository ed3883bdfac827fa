"""The virtual tilt test of a whole network (docs/model.md section 1, generalized to N sliders), and the
slide-hold-slide pull, its variant.

On a copy of the state, a tangential force f N_i along +x (a tilt by tan(alpha)
= f) is added to every node and f is raised quasi-statically:

1. f rises to the smallest critical value at which some node reaches its
   threshold, |G_i + f N_i x| = mu_s,i N_i, with G_i the node's force before
   the tilt (springs, dilation and f_ext). Keys come from a min-heap, so the
   next critical f costs O(log N).
2. At fixed f, that node slips by the network's slip rule and the avalanche it
   triggers is relaxed, largest overload first (ties to the lowest index),
   exactly as on the horizontal substrate; each slip redraws the node's
   threshold from the tilt stream.
3. **The whole network is set in motion** when, during one avalanche, every
   node has slipped or is unstable. This is checked after each slip has moved
   force to its neighbours and before its threshold is redrawn (the slipped
   node counts as stable until then): for two sliders it is eq. `stab` (the
   other slider moves too).

   * If the total tangential load exceeds the total dynamic friction,
     f + f_bar > mu_d with f_bar = sum_i f_ext,i,x / sum_i N_i, the motion
     accelerates: the network slides, and the load per unit normal load at
     that moment, f + f_bar, is the sample of mu_eff (f itself, tan(alpha_c),
     when there is no f_ext).
     A stricter sliding rule (``settings.tilt_min_slips = m`` > 1, the
     ``[tilt]`` table's ``min_slips``; ``tilt_min_shift`` > 0, its
     ``min_displacement``) asks more of that avalanche before it counts:
     every node has slipped m times in it (or m - 1 times and is unstable,
     about to slip again), and its centre of mass has moved along +x by
     ``tilt_min_shift``. Until it has, the avalanche goes on and the sample
     is the load at the first slip where the rule is met. The motion itself
     does not depend on the rule, so a stricter rule never gives a lower
     sample on the same state and draws.
   * Otherwise the collective motion is damped (creep). For a 1D pair the
     appendix's rule is used: both thresholds are redrawn and the spring force
     is drawn uniformly between the two values that keep both sliders stable
     under f. For N > 2 (or in 2D) that stable set is a polytope with no
     natural uniform measure, so the damped motion is resolved by the slip
     rule itself: the avalanche goes on and the count of moving nodes starts
     again (the sliding rule's counts too).

4. **A part of the network slides on its own** when one avalanche at fixed f
   exceeds ``av_cap`` slips without having set every node in motion (counted
   from the avalanche's start, or from the last damped collective motion of
   rule 3, where both counts start again). In a
   rigid connected network a subset cannot slide for ever (the springs to the
   rest stretch), so this happens along floppy modes: each row of a
   ``square`` lattice (central springs only) slides along x independently.
   If f + f_bar > mu_d that is sliding, and f + f_bar is the sample
   (``pos[STOP] = STOP_CAP`` says so: under a stricter sliding rule it is the
   cap's sample, not the rule's); if not, the test gives up (``TILT_TOO_LONG``).

For a 1D pair without ``f_ext`` this performs the appendix's test: the same
sequence of critical forces, the same draws in the same order, and so the
same mu_eff (tested against :func:`slidernet.kernels.tilt.tilt_test_pair`).
One case differs, outside the paper's parameters: the appendix never lets a
slider slip backwards, while here a slider whose threshold drops below
mu_s,old - 2 mu_d after its slip does (it is unstable). With another slip
rule (``friction.overshoot`` e < 1) the pair's test is the appendix's with
that slip, as :func:`slidernet.kernels.tilt.tilt_test_pair` makes it.

**Slide-hold-slide** (:func:`shs_test_network`, docs/model.md "Slide-hold-slide") is the same body
with ``pull`` = gamma <k> > 0: a stage at X along +x is joined to every node i by a spring of stiffness
gamma N_i <k>, so node i feels G_i + gamma N_i <k> (X - u_i,x) x, u_i its displacement since the pull
began. That is the tilt f N_i above with f = gamma <k> X, on a network whose diagonal blocks K_ii hold
the pull spring gamma N_i <k> along x (the caller's ``net``): the critical f, the slips (with the local
stiffness pull spring included), the avalanches and the redraws are the tilt test's. Every slip relaxes
a pull spring, so every avalanche at fixed X ends: no rule 3 or 4. The stage force per unit normal load,
F / sum N = f - gamma <k> U (U = sum_i N_i u_i,x / sum N), rises with f between slips and drops at each
forward slip; its peak plus f_bar is the sample ``loads[L_PEAK]``, and the pull ends at the slip that
renews the last contact: every node has slipped at least once since it began.

Work arrays are the caller's: two :class:`~slidernet.kernels.state.Heaps`
over the N nodes (``Heaps.empty(2, N)``), ``epoch`` and ``count`` (N,) int64, so that a
test allocates nothing.
"""

from __future__ import annotations

import math

from slidernet.kernels.heap import heap_clear, heap_set
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.plane import slip_exact, slip_straight, spread
from slidernet.kernels.state import TILT_NEED_DRAWS, TILT_TOO_LONG

# Slots of the small integer array ``pos`` (shape (N_POS,)) shared with the caller.
P_MU = 0  # read position in the threshold buffer
P_U = 1  # read position in the uniform buffer
N_SLIPS = 2  # slips made by the test (out)
STAGE = 3  # 0: start a test; else where a test that ran out of draws resumes (R_REDRAW, R_CREEP)
STOP = 4  # why the test gave up (out): STOP_SLIPS, STOP_PART, STOP_SLIP_MOTION; STOP_CAP: a sample of rule 4
# The test's counters, kept here when it returns for draws so that it can resume where it stood.
S_NODE = 5  # the node whose threshold is to be redrawn
S_EP = 6  # the current avalanche (see ``epoch``)
S_MOVING = 7  # nodes in motion in the current avalanche: slipped at least once, or unstable (rule 3)
S_DONE = 8  # nodes that meet the sliding rule's tilt.min_slips (``_in_motion`` with m)
S_AV = 9  # slips of the current avalanche (rule 4)
S_RENEWED = 10  # slide-hold-slide: nodes that have slipped since the pull began
N_POS = 11

# Where a test that ran out of draws resumes (``pos[STAGE]``).
R_REDRAW = 1  # redraw the threshold of node pos[S_NODE], which has just slipped
R_CREEP = 2  # the appendix's creep rule (a 1D pair), which redraws both thresholds

# Why a test gave up (``pos[STOP]``, with the result ``TILT_TOO_LONG``).
STOP_SLIPS = 1  # settings.max_slips slips in all
STOP_PART = 2  # an avalanche passed av_cap slips with the load at or below mu_d (rule 4)
STOP_SLIP_MOTION = 3  # an exactly integrated slip did not come to rest within its step budget
# How a test that gave a sample ended, where it was not the sliding rule (``pos[STOP]``; 0 for the rule).
STOP_CAP = 4  # an avalanche passed av_cap slips above mu_d: a part slides alone (rule 4), the rule unmet

# Slots of the float array ``loads`` (shape (N_LOADS,)) the test fills, each a load per unit normal load
# along x, f + f_bar, like the sample; NaN where the event did not happen before the test ended.
L_FIRST = 0  # at the test's first slip (the first critical f)
L_MOVING = 1  # when an avalanche first set every node in motion at once, whatever its relation to mu_d
L_F = 2  # the tilt f reached so far: where a test resumes, and the load of a test that gave up
L_SHIFT = 3  # not a load: the current avalanche's displacement of the centre of mass along x, Ntilde l0
#              (slide-hold-slide: since the pull began)
L_PEAK = 4  # slide-hold-slide: the largest stage load so far, F / sum N + f_bar (the sample, mu_shs)
L_TRAVEL = 5  # slide-hold-slide: not a load: the stage's travel X at that peak, Ntilde l0
# The contacts' own loads (tilt test only). A contact breaks at its node's first slip of the test, at the load
# f + f_bar of that slip; a contact still intact when the test ends is taken to break at the end's load (under
# the sliding rule it is unstable there: exact; at the avalanche cap: a lower bound).
L_CONTACTS = 6  # sum of N_i times the load at which contact i broke, over the broken ones; at the end, the mean
#                 over contacts weighted by N_i (tilt_contact_mean)
L_BROKEN_N = 7  # not a load: sum of N_i over the broken contacts
L_TOTAL_N = 8  # not a load: sum of N_i over all contacts
L_HALF = 9  # the load at which the broken contacts first held half of the normal load (tilt_half_broken)
L_RATIO = 10  # sum over the broken contacts of the force |F_i| on each as it broke (springs, external, tilt); at
#               the end, divided by sum N_i: the mean of the local ratios |F_i| / N_i weighted by N_i
#               (tilt_break_ratio)
N_LOADS = 11

#: The records of the ``tilt_loads`` observable and the slot of ``loads`` each is read from: the mean over a
#: recorded time's [tilt] repeats of that load.
TILT_LOADS = {"tilt_first_slip": L_FIRST, "tilt_all_moving": L_MOVING, "tilt_contact_mean": L_CONTACTS,
              "tilt_half_broken": L_HALF, "tilt_break_ratio": L_RATIO}

# The test's two heaps.
_UNSTABLE = 0  # unstable nodes keyed by overload
_CRITICAL = 1  # nodes keyed by minus the tilt f at which they reach their threshold


@kernel_jit(forceinline=True)
def _critical_f(Gx, Gy, lim, n):
    """The f >= current at which |(Gx + f n, Gy)| reaches lim (the upper root)."""
    if Gy == 0.0:
        return (lim - Gx) / n
    r = lim * lim - Gy * Gy
    return (-Gx + math.sqrt(max(r, 0.0))) / n


@kernel_jit(forceinline=True)
def _key(j, f, G, mu, normal_load, heaps):
    """Re-key node j in both heaps at tilt f; returns True if it is unstable."""
    n = normal_load[j]
    lim = mu[j] * n
    Tx = G[j, 0] + f * n
    Ty = G[j, 1]
    T = math.sqrt(Tx * Tx + Ty * Ty)
    unstable = T > lim
    heap_set(heaps, _UNSTABLE, j, T / lim, unstable)
    heap_set(heaps, _CRITICAL, j, -_critical_f(G[j, 0], G[j, 1], lim, n), True)
    return unstable


@kernel_jit(inline="always")
def _displacement(net, settings, i, f, driving, G, mu, slip):
    """(ok, du_x, du_y): node i slips alone under its force plus the tilt f N_i along x, by the rule
    ``slip`` (:func:`~slidernet.kernels.plane.slip_straight` or :func:`~slidernet.kernels.plane.slip_exact`).

    A driving slip starts exactly at the threshold, as on the horizontal substrate.
    """
    n = net.normal_load[i]
    Tx = G[i, 0] + f * n
    Ty = G[i, 1]
    norm = math.sqrt(Tx * Tx + Ty * Ty)
    return slip(net, settings, i, Tx, Ty, norm, mu[i] * n if driving else norm)


@kernel_jit(forceinline=True)
def _pair_creep(f, G, mu, f_ext, normal_load, tilt_mu, tilt_u, p_mu, p_u, heaps):
    """The appendix's creep rule: both thresholds redrawn, the spring force on slider 2 uniform
    between the values that keep both sliders stable under f. Returns the new read positions."""
    mu[0] = tilt_mu[p_mu]
    mu[1] = tilt_mu[p_mu + 1]
    lo = f * normal_load[0] + f_ext[0, 0] - mu[0] * normal_load[0]
    hi = mu[1] * normal_load[1] - f * normal_load[1] - f_ext[1, 0]
    F = lo + (hi - lo) * tilt_u[p_u]
    G[0, 0] = f_ext[0, 0] - F
    G[1, 0] = f_ext[1, 0] + F
    # Both sliders are at rest: the next event is a critical f.
    for j in range(2):
        _key(j, f, G, mu, normal_load, heaps)
        heap_set(heaps, _UNSTABLE, j, 0.0, False)
    return p_mu + 2, p_u + 1


@kernel_jit(forceinline=True)
def _in_motion(c, m, unstable):
    """Whether a node that has slipped c times in the current avalanche counts as in motion under the rule of
    ``m`` slips: it has slipped m times, or m - 1 times and is unstable now (about to slip the m-th). With
    m = 1: it has slipped, or it is unstable."""
    return c >= m or (c == m - 1 and unstable)


@kernel_jit(forceinline=True)
def _stage_peak(loads, f, f_bar, pull, shift):
    """Slide-hold-slide: keep the stage's load f - pull U + f_bar (U = ``shift``) and its travel f / pull if it
    is the largest so far (the first value replaces the NaN of a new pull)."""
    load = f - pull * shift + f_bar
    if not load <= loads[L_PEAK]:
        loads[L_PEAK] = load
        loads[L_TRAVEL] = f / pull


@kernel_jit(forceinline=True)
def _break(loads, n, load, force):
    """Contact of normal load ``n`` breaks at ``load`` under the force ``force`` = |F_i|: add it to the sums, and
    note the load at which half of the normal load is first broken."""
    loads[L_CONTACTS] += n * load
    loads[L_RATIO] += force
    loads[L_BROKEN_N] += n
    # 2 x sum >= total: exact for unit loads (sums of 1.0), where half of an even N is reached exactly.
    if math.isnan(loads[L_HALF]) and 2.0 * loads[L_BROKEN_N] >= loads[L_TOTAL_N]:
        loads[L_HALF] = load


@kernel_jit(forceinline=True)
def _force(G, j, f, n):
    """|F_j|: the force on node j at tilt f, springs, external forces and the tilt f N_j along x."""
    Tx = G[j, 0] + f * n
    return math.sqrt(Tx * Tx + G[j, 1] * G[j, 1])


@kernel_jit(forceinline=True)
def _close_contacts(loads, load, G, f, normal_load, epoch):
    """At the test's sample ``load`` (tilt f): the contacts still intact (``epoch`` < 0) break there, under their
    forces now; ``L_CONTACTS`` and ``L_RATIO`` become means over the contacts weighted by N_i."""
    for j in range(epoch.size):
        if epoch[j] < 0:
            _break(loads, normal_load[j], load, _force(G, j, f, normal_load[j]))
    loads[L_CONTACTS] /= loads[L_TOTAL_N]
    loads[L_RATIO] /= loads[L_TOTAL_N]


@kernel_jit(inline="always")
def _tilt_test(G, mu, f_ext, f_bar, net, settings, pair_rule, tilt_mu, tilt_u, pos, av_cap, heaps, epoch, count,
               loads, slip, pull):
    """Raise a uniform tilt on a copy of a network until it slides as a whole (``pull`` = 0), or pull it through
    springs until every contact is renewed (slide-hold-slide, ``pull`` > 0).

    Parameters
    ----------
    G : ndarray, shape (N, 2)
        Forces on the nodes before the tilt, in units of N (overwritten: pass a
        copy). 1D networks pass their forces in column 0 and zeros in column 1.
    mu : ndarray, shape (N,)
        Thresholds mu_s (overwritten: pass a copy).
    f_ext : ndarray, shape (N, 2)
        The constant external forces included in G (used by the pair rule).
    f_bar : float
        sum_i f_ext,i,x / sum_i N_i: the external load per unit normal load along x.
    net : Plane
        Block-CSR rows of K (1D padded to 2 x 2 blocks) and the loads N_i; the
        tilt force on node i is f N_i along +x.
    settings : Settings
        mu_d, max_slips (give up after this many slips), slip_factor (the
        slip rule's 1 + e), and the sliding rule: one avalanche above mu_d in
        which every node has slipped at least ``tilt_min_slips`` times (or
        that many less one and is unstable) and the centre of mass has moved
        by ``tilt_min_shift`` along +x (Ntilde l0; 0: no such condition).
    pair_rule : bool
        Use the appendix's creep rule (a 1D pair of sliders).
    tilt_mu, tilt_u : ndarray
        Thresholds and uniforms of the tilt stream, read from ``pos[P_MU]``
        and ``pos[P_U]`` on.
    pos : ndarray of int64, shape (N_POS,)
        Read positions (slots ``P_MU``, ``P_U``), the slip count
        (``N_SLIPS``), why a test gave up or ended at the cap of rule 4
        (``STOP``: ``STOP_CAP`` with a sample, 0 with the sliding rule's),
        and the test's stage
        and counters: set ``pos[STAGE] = 0`` to start a test.
    av_cap : int
        Slips of one avalanche after which a part of the network is taken to
        slide on its own (rule 4).
    heaps : Heaps
        Two heaps over the N nodes (work array).
    epoch : ndarray of int64, shape (N,)
        Work array: the avalanche in which each node last slipped.
    count : ndarray of int64, shape (N,)
        Work array: how many times each node slipped in the avalanche
        ``epoch[j]`` (the sliding rule of ``settings.tilt_min_slips``).
    slip : compiled function
        The slip rule, ``slip(net, settings, i, Fx, Fy, norm, mag) -> (ok, du_x, du_y)``.
    pull : float
        0.0: the tilt test (a constant of its compiled variants, so that the
        pull's branches fold away there). > 0: the slide-hold-slide pull
        (:func:`shs_test_network`), ``pull`` = gamma <k>, with the pull
        springs gamma <k> N_i along x already in the diagonal blocks of
        ``net``: the whole pull is one count (``count`` holds each node's
        slips since it began, ``L_SHIFT`` the shift U of its centre of
        mass), the stage's load f - pull U + f_bar is kept at its peak
        (``L_PEAK``, the travel f / pull in ``L_TRAVEL``), and the pull ends
        at the slip that renews the last contact (no threshold drawn; f and U
        at the end left in ``L_F`` and ``L_SHIFT``), with
        none of rules 3 and 4 (``pair_rule`` and ``av_cap`` are not read;
        ``L_FIRST`` and ``L_MOVING`` stay NaN).
    loads : ndarray of float64, shape (N_LOADS,)
        Out: the load f + f_bar at the test's first slip (``L_FIRST``), and
        when an avalanche first set every node in motion at once, above mu_d
        or not (``L_MOVING``; NaN if none did: a part slid alone). They
        tell what the sample rests on: the onset of the first slip, the
        collective motion, and the rule that only motion above mu_d slides.
        ``L_F``: the tilt f reached so far. The contacts' own loads, each
        contact broken at its node's first slip of the test (those intact
        at the sample at the sample's load): their mean weighted by N_i
        (``L_CONTACTS``), the load at which the broken ones first held
        half of the normal load (``L_HALF``), and the mean weighted by N_i
        of the local ratio |F_i| / N_i under which each broke
        (``L_RATIO``); NaN with ``pull`` > 0.

    Returns
    -------
    float
        f + f_bar when the network slides (a mu_eff sample; with ``pull`` > 0,
        f >= 0 at the end of the pull, whose sample is ``loads[L_PEAK]``:
        a peak may have any sign and must not be read as a code); ``TILT_TOO_LONG``
        if the test gave up (``pos[STOP]`` says why); ``TILT_NEED_DRAWS`` if a
        buffer ran out. The test then stands where it stopped, in ``G``,
        ``mu``, ``heaps``, ``epoch``, ``loads`` and ``pos``: called again with
        these, and with buffers that hold the same values from ``pos[P_MU]``
        and ``pos[P_U]`` on and more after them, it goes on as if the buffers
        had been long enough (the same draws in the same order: the same
        sample).
    """
    N = mu.size
    normal_load = net.normal_load
    w = net.w
    m = settings.tilt_min_slips
    min_shift = settings.tilt_min_shift
    p_mu = pos[P_MU]
    p_u = pos[P_U]
    stage = pos[STAGE]
    if stage == 0:
        heap_clear(heaps)
        f = 0.0
        loads[L_FIRST] = math.nan
        loads[L_MOVING] = math.nan
        loads[L_PEAK] = math.nan
        loads[L_TRAVEL] = math.nan
        loads[L_HALF] = math.nan
        loads[L_CONTACTS] = 0.0 if pull == 0.0 else math.nan
        loads[L_RATIO] = 0.0 if pull == 0.0 else math.nan
        loads[L_BROKEN_N] = 0.0
        total = 0.0
        for j in range(N):
            _key(j, f, G, mu, normal_load, heaps)
            epoch[j] = -1
            total += normal_load[j]
        loads[L_TOTAL_N] = total
        # The pull is one count from its start: ep = 1 throughout (the tilt test's first avalanche is 1).
        ep = 1 if pull > 0.0 else 0
        slips = 0
        renewed = 0
        # moving: nodes in motion in the current avalanche (slipped, or unstable: before any slip, the
        # unstable ones); done: nodes that meet the sliding rule of m slips (the same as moving for m = 1).
        moving = heaps.size[_UNSTABLE]
        done = moving if m == 1 else 0
        shift = 0.0
        av_slips = 0
        i = -1
    else:
        f = loads[L_F]
        shift = loads[L_SHIFT]
        i = pos[S_NODE]
        ep = pos[S_EP]
        slips = pos[N_SLIPS]
        moving = pos[S_MOVING]
        done = pos[S_DONE]
        av_slips = pos[S_AV]
        # Read only by a pull: in the tilt test's variants renewed stays the constant 0, no register held for it.
        renewed = pos[S_RENEWED] if pull > 0.0 else 0
    pos[STOP] = 0
    while True:
        # What the last slip left to do, each step first checking that its draws are there:
        # redraw the slipped node's threshold, or apply the pair's creep rule (both thresholds).
        if stage == R_CREEP:
            if p_mu + 2 > tilt_mu.size or p_u + 1 > tilt_u.size:
                return _wait_for_draws(pos, loads, R_CREEP, p_mu, p_u, f, i, ep, slips, moving, done, av_slips,
                                       shift, renewed)
            # Both contacts are renewed: one that had not slipped (it was unstable, in motion) breaks here,
            # under its force before the creep. epoch = ep with count 0 marks it broken and counts as no slip
            # in this avalanche.
            for j in range(2):
                if epoch[j] < 0:
                    _break(loads, normal_load[j], f + f_bar, _force(G, j, f, normal_load[j]))
                    epoch[j] = ep
                    count[j] = 0
            p_mu, p_u = _pair_creep(f, G, mu, f_ext, normal_load, tilt_mu, tilt_u, p_mu, p_u, heaps)
        elif stage == R_REDRAW:
            if p_mu + 1 > tilt_mu.size:
                return _wait_for_draws(pos, loads, R_REDRAW, p_mu, p_u, f, i, ep, slips, moving, done, av_slips,
                                       shift, renewed)
            mu[i] = tilt_mu[p_mu]
            p_mu += 1
            now = _key(i, f, G, mu, normal_load, heaps)
            # The slipped node counted as stable until its new threshold: one slip short of m, it counts if
            # it is unstable now (it has slipped, so it is in motion already).
            if epoch[i] == ep and count[i] == m - 1 and now:
                done += 1
        driving = heaps.size[_UNSTABLE] == 0
        if driving:
            # Raise f to the next critical value; a new avalanche starts.
            fc = -heaps.key[_CRITICAL, 0]
            if fc > f:
                f = fc
            i = heaps.node[_CRITICAL, 0]
            if ep == 0:
                loads[L_FIRST] = f + f_bar
            if pull > 0.0:
                # The stage force has risen with f since the last slip, and this slip lowers it: a peak. The
                # pull is one count, its shift the centre of mass's since it began.
                _stage_peak(loads, f, f_bar, pull, shift)
            else:
                ep += 1
                moving = 0
                done = 0
                shift = 0.0
                av_slips = 0
        else:
            i = heaps.node[_UNSTABLE, 0]
        slips += 1
        av_slips += 1
        pos[N_SLIPS] = slips
        # loads[L_F] is written where the test returns (f changes only just above, at a driving slip).
        if slips > settings.max_slips:
            return _give_up(pos, loads, f, STOP_SLIPS)
        if pull == 0.0 and av_slips > av_cap:
            if f + f_bar > settings.mu_d:
                pos[STOP] = STOP_CAP  # a sample, not of the sliding rule: the caller decides what it is worth
                _close_contacts(loads, f + f_bar, G, f, normal_load, epoch)
                return _sample(pos, loads, f, p_mu, p_u, f + f_bar)
            return _give_up(pos, loads, f, STOP_PART)
        # Node i's count goes up by one; until its threshold is redrawn it counts as stable.
        c = count[i] if epoch[i] == ep else 0
        if pull > 0.0 and c == 0:
            renewed += 1
        if pull == 0.0 and epoch[i] < 0:
            _break(loads, normal_load[i], f + f_bar, _force(G, i, f, normal_load[i]))
        was = heaps.slot[i, _UNSTABLE] >= 0
        moving += int(_in_motion(c + 1, 1, False)) - int(_in_motion(c, 1, was))
        done += int(_in_motion(c + 1, m, False)) - int(_in_motion(c, m, was))
        epoch[i] = ep
        count[i] = c + 1
        ok, dux, duy = _displacement(net, settings, i, f, driving, G, mu, slip)
        if not ok:
            return _give_up(pos, loads, f, STOP_SLIP_MOTION)
        shift += w[i] * dux
        spread(net, G, i, dux, duy)
        for p in range(net.indptr[i], net.indptr[i + 1]):
            j = net.indices[p]
            if j == i:
                continue
            was = heaps.slot[j, _UNSTABLE] >= 0
            now = _key(j, f, G, mu, normal_load, heaps)
            cj = count[j] if epoch[j] == ep else 0
            if cj == 0:
                moving += int(now) - int(was)
            if cj == m - 1:
                done += int(now) - int(was)
        stage = R_REDRAW
        if pull > 0.0:
            # At a fixed stage a slip lowers its force, unless the node slipped backwards (2D, or a force
            # along -x): the peak is looked for after every slip too.
            _stage_peak(loads, f, f_bar, pull, shift)
            if renewed == N:
                # Every contact renewed: the slip that renews the last one draws no threshold, as in the tilt
                # test. The stage's load at the end is f - pull U + f_bar (U kept in L_SHIFT, f in L_F).
                loads[L_SHIFT] = shift
                return _sample(pos, loads, f, p_mu, p_u, f)
            continue
        if moving == N:
            # Every node is in motion at once (rule 3). Whether that motion is damped depends on the load
            # alone; the sliding rule (m slips, a displacement) only says when a motion above mu_d counts.
            if math.isnan(loads[L_MOVING]):
                loads[L_MOVING] = f + f_bar
            if f + f_bar > settings.mu_d:
                if done == N and (min_shift <= 0.0 or shift >= min_shift):
                    _close_contacts(loads, f + f_bar, G, f, normal_load, epoch)
                    return _sample(pos, loads, f, p_mu, p_u, f + f_bar)
                # Above mu_d, the rule not yet met: the avalanche goes on, its counts kept.
                continue
            if pair_rule:
                stage = R_CREEP
                continue
            # Damped collective motion: the avalanche goes on, counted afresh
            # from the node that is moving now.
            ep += 1
            epoch[i] = ep
            count[i] = 1
            shift = w[i] * dux
            # Rule 4 counts the slips since every node was last in motion: a long damped collective
            # motion in a large network is not a part sliding alone.
            av_slips = 0
            others = heaps.size[_UNSTABLE] - (1 if heaps.slot[i, _UNSTABLE] >= 0 else 0)
            moving = 1 + others
            done = int(_in_motion(1, m, False)) + (others if m == 1 else 0)


@kernel_jit(forceinline=True)
def _sample(pos, loads, f, p_mu, p_u, load):
    """End the test with a sample, the load f + f_bar: the read positions after its draws, and f."""
    loads[L_F] = f
    pos[P_MU] = p_mu
    pos[P_U] = p_u
    pos[STAGE] = 0
    return load


@kernel_jit(forceinline=True)
def _give_up(pos, loads, f, why):
    """End the test without a sample (``TILT_TOO_LONG``); ``why`` goes to ``pos[STOP]``, f to ``loads[L_F]``."""
    loads[L_F] = f
    pos[STOP] = why
    pos[STAGE] = 0
    return TILT_TOO_LONG


@kernel_jit(forceinline=True)
def _wait_for_draws(pos, loads, stage, p_mu, p_u, f, i, ep, slips, moving, done, av_slips, shift, renewed):
    """Keep where the test stands, to resume at ``stage`` once the buffers are longer."""
    pos[P_MU] = p_mu
    pos[P_U] = p_u
    pos[STAGE] = stage
    pos[S_NODE] = i
    pos[S_EP] = ep
    pos[N_SLIPS] = slips
    pos[S_MOVING] = moving
    pos[S_DONE] = done
    pos[S_AV] = av_slips
    pos[S_RENEWED] = renewed
    loads[L_F] = f
    loads[L_SHIFT] = shift
    return TILT_NEED_DRAWS


@kernel_jit()
def tilt_test_network(G, mu, f_ext, f_bar, net, settings, pair_rule, tilt_mu, tilt_u, pos, av_cap, heaps, epoch,
                      count, loads):
    """The network tilt test with straight-line slips (1D networks, and 2D with ``solver.slip = "straight"``):
    :func:`_tilt_test`, whose docstring gives the parameters."""
    return _tilt_test(G, mu, f_ext, f_bar, net, settings, pair_rule, tilt_mu, tilt_u, pos, av_cap, heaps, epoch,
                      count, loads, slip_straight, 0.0)


@kernel_jit()
def tilt_test_network_exact(G, mu, f_ext, f_bar, net, settings, pair_rule, tilt_mu, tilt_u, pos, av_cap, heaps,
                            epoch, count, loads):
    """The network tilt test with the exactly integrated 2D slip (``solver.slip = "exact"``)."""
    return _tilt_test(G, mu, f_ext, f_bar, net, settings, pair_rule, tilt_mu, tilt_u, pos, av_cap, heaps, epoch,
                      count, loads, slip_exact, 0.0)


@kernel_jit()
def shs_test_network(G, mu, f_ext, f_bar, net, settings, shs_mu, pos, heaps, epoch, count, loads, pull):
    """The slide-hold-slide pull with straight-line slips: :func:`_tilt_test` with ``pull`` = gamma <k> > 0 on
    ``net``, whose diagonal blocks hold the pull springs (``solver.scene.shs_operators``); thresholds redrawn
    from ``shs_mu``. Returns f >= 0 at the end of the pull (its sample is ``loads[L_PEAK]``), or a code."""
    return _tilt_test(G, mu, f_ext, f_bar, net, settings, False, shs_mu, shs_mu[:0], pos, 0, heaps, epoch, count,
                      loads, slip_straight, pull)


@kernel_jit()
def shs_test_network_exact(G, mu, f_ext, f_bar, net, settings, shs_mu, pos, heaps, epoch, count, loads, pull):
    """The slide-hold-slide pull with the exactly integrated 2D slip (``solver.slip = "exact"``)."""
    return _tilt_test(G, mu, f_ext, f_bar, net, settings, False, shs_mu, shs_mu[:0], pos, 0, heaps, epoch, count,
                      loads, slip_exact, pull)
