"""A reference integrator of the equations of motion (eq. `dynamics`), to measure the quasi-static error.

The solver (:mod:`slidernet.solver`) makes every slip instantaneous and lets
the slipping node move alone. Here the sliders have inertia: node i has mass
m_i = N_i m, and while it moves

    m_i d^2u_i/dt^2 = F_i(u, theta(t)) - mu_d N_i v_i / |v_i|,    F = -K u + theta g + f_ext,

with v_i = du_i/dt (a number in 1D, where v_i / |v_i| is its sign; a vector
in 2D, where Coulomb friction acts against the velocity) and theta(t) linear
between theta(t_q) and theta(t_q+1), the same driver values as the solver's.
A stuck node has v_i = 0 while |F_i| <= mu_s,i N_i and starts, along F_i,
when |F_i| reaches mu_s,i N_i, whatever the other nodes do: several nodes may
move at once. A moving node whose velocity returns to zero has reached a new
place on the substrate: its threshold is redrawn (the solver's order of
draws), and it sticks if |F_i| <= mu_s,i N_i, otherwise it starts again (a
new rearrangement, as in the solver's 1D rule). One rearrangement is counted
per start of motion.

The one time scale of the motion is tau_dyn = sqrt(m / k) for the reference
spring (k = 1 in the solver's units), and the one parameter is
``tau_ratio = tau_dyn / tau_th``. For the two sliders with theta frozen, a slip
is a half-oscillation of duration pi tau_dyn and length 2 (mu_s - mu_d) N / k
(eq. `displacement`): the solver's slip is the limit tau_ratio -> 0.

Units are the solver's: u in Ntilde l0, theta / Ntilde, forces in N, K in
k0 = N / (Ntilde l0), time in tau_th; during motion the integration runs in
the local time s = (t - t_0) / tau_dyn, in which the equation of node i reads
N_i d^2u_i/ds^2 = F_i - mu_d N_i v_i / |v_i| and every number is of order one.
In 2D, u, v, F and g are node-major vectors of length 2N (component c of
node i at 2 i + c) and K is the network's, in 2 x 2 blocks.

How it is integrated
--------------------
Between two events the set of moving nodes is fixed and theta is linear in
time. In 1D the signs of the velocities are fixed too, so the equations are
linear with a smooth right-hand side; in 2D the friction -mu_d N_i v_i/|v_i|
is the one nonlinear term, smooth while |v_i| > 0 (a node that starts has
v_i = 0 and its friction points against F_i, the direction it starts in).
Each such phase is one call of :func:`scipy.integrate.solve_ivp` with
terminal events: a moving node stops, or the largest |F_j| - mu_s,j N_j of
the stuck nodes rises to zero. A phase where nothing moves has u constant
and F_j linear in t, so its first threshold crossing is found in closed form
(the solver's eq. `critique`; in 2D the root of a quadratic), with no steps.

**The stop.** In 1D it is the root of v_i S_i (S_i the sign of the motion),
exact: the friction keeps its sign past the root, so the solution crosses it
cleanly. In 2D v_i / |v_i| is singular at the stop and the steps beyond it
chatter about v_i = 0 (a root of v_i . S_i is not reliably crossed), so a
node stops when its speed |v_i| falls to ``STOP_SPEED`` = 1e-6 Ntilde l0 per
tau_dyn, and v_i is then set to 0. Near a stop |F_i| < mu_d N_i and the node
decelerates at (mu_d N_i - |F_i|) / N_i ~ 0.1 per tau_dyn (a slip of the paper
peaks at ~0.1), so the stop comes ~1e-5 tau_dyn and ~STOP_SPEED^2 / 0.2 ~
5e-12 Ntilde l0 early: 2.5e-11 of a slip of length 0.2. The nodes that start
in a phase are watched by an event of their own (their speed rises through
STOP_SPEED first, which a falling event ignores). On the isolated slip of a
slider with an isotropic spring (tests/test_dynamics_2d.py) the length is
eq. `displacement`'s to 2e-8 and the duration pi tau_dyn less 3.4e-6 of it,
the early stop.

Cost: about 21 ms per slip at the defaults (DOP853, max_step = 0.05 tau_dyn,
~66 steps per slip), 15 ms with RK45, 7 ms at max_step = 0.2 and 4 ms at
max_step = inf, on the paper's two sliders and on a chain of 4 alike (577 and
160 slips, tau_ratio = 1e-4, one core): the time is scipy's, per step. In 2D,
on the study's irregular networks (benchmarks/aging_dynamics.py, defaults,
tau_ratio = 1e-4, one shared core), about 14 ms of CPU per slip at 16 and at
64 sliders (44,674 slips of 16 realizations to 10 tau_th, and 26,895 to
1 tau_th): those networks slip 279 times per tau_th at 16 sliders and 1,681
times in the first tau_th at 64. A dynamic tilt test of the 64-slider network
at t = 1 takes ~17 s of CPU (its final motion sets every slider moving).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import eigh

from slidernet.errors import AvalancheError, ConfigError, TiltTestError, param_error
from slidernet.plugins.distributions.stream import TruncatedStream
from slidernet.solver import Scene, horizontal_draws, realization_streams

METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")

# A node that slides this long (in tau_dyn) without its velocity ever returning
# to zero is sliding for ever: a single slip of the paper lasts pi tau_dyn.
MAX_SLIP_DURATION = 1000.0

# The dynamic tilt test (Dynamics.tilt_test). Its default ramp raises the load per unit
# normal load by 1e-5 per tau_dyn: 3e-5 during one slip of the paper (pi tau_dyn), against
# 0.1 for mu_s - mu_d and ~1e-3 for the aging effects measured with it.
TILT_RATE = 1e-5
# While something moves, the tilt test integrates in phases of at most this many tau_dyn
# (one period of the stiffest node of a chain, 2 pi / sqrt(2), is shorter), checking
# between them whether the network slides for good.
TILT_CHUNK = 2.0 * math.pi
# The tilt test gives up after this many starts of motion, or one avalanche this long in
# tau_dyn without the proof that the network slides (a ramp makes it slide well before).
TILT_MAX_STARTS = 100_000
TILT_MAX_AVALANCHE = 1e5

# atol = ATOL_SCALE * rtol, in Ntilde l0 (and Ntilde l0 per tau_dyn): a slip of
# the paper is 2 (mu_s - mu_d) ~ 0.2 Ntilde l0 long, its peak velocity ~ 0.1.
ATOL_SCALE = 1e-2

# 2D: a moving node stops when its speed |v_i| falls to this, in Ntilde l0 per tau_dyn (module
# docstring): a slip of the paper peaks at ~0.1 and decelerates at ~0.1 per tau_dyn, so the stop comes
# ~1e-5 tau_dyn and ~5e-12 Ntilde l0 early, and the integration's own error in v is ~1e-9.
STOP_SPEED = 1e-6


class ThresholdStream:
    """A realization's thresholds in the order the solver reads them.

    Parameters
    ----------
    initial : ndarray, shape (N,)
        The initial mu_s of the nodes.
    batches : iterator of ndarray
        The replacement draws, in batches of ``scene.batch``
        (:func:`slidernet.solver.horizontal_draws`); :meth:`next` reads them
        one by one.
    """

    def __init__(self, initial: np.ndarray, batches: Iterator[np.ndarray]) -> None:
        self.initial = initial
        self.batches = batches
        self.buf = np.empty(0)
        self.pos = 0

    def next(self) -> float:
        """The next replacement threshold."""
        if self.pos >= self.buf.size:
            self.buf = next(self.batches)
            self.pos = 0
        value = float(self.buf[self.pos])
        self.pos += 1
        return value


def realization_draws(scene: Scene, seed_seq: np.random.SeedSequence) -> tuple[np.ndarray, ThresholdStream]:
    """theta(t_q) / Ntilde, shape (steps + 1,), and the thresholds of one realization, as the solver draws them."""
    thetas, mu, batches = horizontal_draws(scene, realization_streams(seed_seq))
    return thetas, ThresholdStream(mu, batches)


class Dynamics:
    """Reference integrator of the equations of motion (eq. `dynamics`) on a 1D or 2D network.

    Constructing it validates and stores the settings; :meth:`run` integrates
    one realization, with the same theta(t_q) and the same stream of mu_s
    draws as :func:`slidernet.solver.simulate` on the same seed.

    Parameters
    ----------
    scene : Scene
        A scene of a network (``two_slider``, ``chain``, ``irregular``, a
        lattice or any :class:`~slidernet.model.network.Network`, 1D or 2D),
        with its f_ext, normal loads, thresholds law and driver. Dense
        operators: meant for tens of sliders (2N = 128 for 64 in 2D).
    tau_ratio : float
        tau_dyn / tau_th, > 0, with tau_dyn = sqrt(m / k) the period of the
        reference spring divided by 2 pi (masses m_i = N_i m).
    max_step : float
        Largest integration step during motion, in units of tau_dyn, > 0
        (``inf``: the step is set by ``rtol`` alone). Events are seen at the
        ends of steps only, so a velocity that dips to zero and comes back
        within one step (a node pushed on by a neighbour) is missed: on a
        chain of 4 (sigma_theta / Ntilde = 3, tau_ratio = 1e-4, seeds 0 and 1,
        10 steps) the slips at 0.2 and 1 tau_dyn departed from those at 0.01
        after 217 to 280 slips, those at 0.05 did not.
    rtol : float
        Relative tolerance of :func:`scipy.integrate.solve_ivp`, in
        [100 eps, 1); the absolute tolerance is ``1e-2 * rtol`` in Ntilde l0.
    method : str
        A :func:`scipy.integrate.solve_ivp` method (default ``"DOP853"``).

    Examples
    --------
    The paper's two sliders on a slow ramp of theta: the first slip is that of
    the weaker slider, 2 (mu_s - mu_d) Ntilde l0 long and pi tau_dyn in
    duration (eq. `displacement`), and the counts are the solver's.

    >>> from slidernet.config import load_config
    >>> from slidernet.solver import Realization, simulate
    >>> scene = Scene.from_config(load_config({
    ...     "steps": 2, "record": "all", "network": {"kind": "two_slider", "Ntilde": 1e-7},
    ...     "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...     "driver": {"name": "ramp", "rate": 1e-7}}))
    >>> out = Dynamics(scene, tau_ratio=1e-6).run(np.random.SeedSequence(0))
    >>> out["n"].tolist(), simulate(scene, np.random.SeedSequence(0))["n"].tolist()
    ([0, 3, 8], [0, 3, 8])
    >>> mu = Realization(scene, np.random.SeedSequence(0)).mu
    >>> slip = {key: value[0] for key, value in out["slips"].items()}
    >>> int(slip["node"]), int(np.argmin(mu))
    (1, 1)
    >>> print(f"{slip['du'] / (2 * (mu.min() - 0.5) * 1e-7):.4f}, {slip['duration'] / (np.pi * 1e-6):.4f}")
    1.0000, 1.0000
    """

    def __init__(self, scene: Scene, tau_ratio: float, max_step: float = 0.05, rtol: float = 1e-8,
                 method: str = "DOP853") -> None:
        owner = "Dynamics"
        if isinstance(tau_ratio, bool) or not isinstance(tau_ratio, (int, float)) or not (
                math.isfinite(tau_ratio) and tau_ratio > 0):
            raise param_error("tau_ratio", owner, "a finite number > 0", tau_ratio)
        if isinstance(max_step, bool) or not isinstance(max_step, (int, float)) or not max_step > 0:
            raise param_error("max_step", owner, "a number > 0 (inf: no limit)", max_step)
        floor = 100 * np.finfo(float).eps
        if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not floor <= rtol < 1:
            raise param_error("rtol", owner, f"a number in [{floor:.3g}, 1) (scipy's floor is 100 eps)", rtol)
        if method not in METHODS:
            raise param_error("method", owner, f"one of {', '.join(METHODS)}", method)
        net = scene.network
        self.scene = scene
        self.tau_ratio = float(tau_ratio)
        self.max_step = float(max_step)
        self.rtol = float(rtol)
        self.atol = ATOL_SCALE * self.rtol
        self.method = method
        self.dim = net.dim
        # Dense operators, node-major (component c of node i at i d + c): the networks
        # integrated here are small (N d <= ~128), and a dense sub-block product is the
        # cheapest right-hand side.
        self.K = net.stiffness_matrix().toarray()
        self.g = np.asarray(scene.operators.g, dtype=np.float64).reshape(-1)
        self.normal_load = net.normal_load.astype(np.float64)
        self.w = self.normal_load / self.normal_load.sum()
        self.f_ext = net.f_ext.astype(np.float64).reshape(-1)
        self._modes: tuple[np.ndarray, np.ndarray] | None = None  # the 1D tilt test's, built on first use
        self._compliance: np.ndarray | None = None  # the 2D tilt test's K^+, built on first use

    def run(self, seed_seq: np.random.SeedSequence, steps: int | None = None, *,
            states: bool = False) -> dict[str, np.ndarray]:
        """Integrate one realization through ``steps`` thermal steps (default: the scene's).

        Parameters
        ----------
        seed_seq : numpy.random.SeedSequence
            The realization's seed, as given to :func:`slidernet.solver.simulate`.
        steps : int, optional
            Thermal steps to run, 0 <= steps <= ``scene.steps``; theta(t_q) is
            drawn for the scene's steps either way (the same draws).
        states : bool
            Also return the state at the recorded times (below), e.g. for
            :meth:`tilt_test`. It changes no other output.

        Returns
        -------
        dict
            ``t`` (int64, tau_th), ``n`` (int64: rearrangements, one per
            start of motion), ``mu_max``, ``x_G`` (l0, the mass-weighted mean
            displacement along x), each of shape (T,), at the scene's recorded
            times up to ``steps``; ``overlapping`` (int64 scalar: starts while
            another node was moving); ``moving_at_end`` (int64 scalar: nodes
            still moving at t = steps); ``stop_speed`` (float, l0 per tau_dyn:
            the largest speed set to zero at a stop, in 2D ~STOP_SPEED Ntilde;
            in 1D the root finder's residual); ``slips``, a dict of arrays of
            shape (S,), one per slip that came to rest by t = ``steps``, in
            the order they ended: ``start`` and ``end`` (tau_th), ``duration``
            (tau_th, computed in the integrator's local time, so exact even
            where ``start`` is large), ``node`` (int64), ``du`` (l0; shape
            (S, 2) in 2D, the vector displacement).

            With ``states``, also, each of shape (T, N) in 1D and (T, N, 2)
            in 2D (``mu_s``: (T, N); ``theta``: (T,)): ``u``, the
            displacements from the reference positions (l0; u = 0 is every
            spring at rest at theta(0)); ``mu_s``, the thresholds; ``F``, the
            forces on the nodes (N: springs, dilation and f_ext); ``theta``,
            theta(t) - theta(0) (dimensionless). A node still moving at a
            recorded time (rare: the records fall between two thermal
            segments) is recorded where it is.
        """
        scene = self.scene
        steps = scene.steps if steps is None else steps
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or not 0 <= steps <= scene.steps:
            raise param_error("steps", "Dynamics.run", f"an integer in [0, {scene.steps}]", steps)
        thetas, draws = realization_draws(scene, seed_seq)
        return _Realization(self, thetas, draws).run(int(steps), bool(states))

    def tilt_test(self, u: np.ndarray, mu_s: np.ndarray, rng: np.random.Generator, *, theta: float = 0.0,
                  rate: float = TILT_RATE) -> dict[str, float]:
        """The dynamic tilt test: raise a uniform tilt on a state under the equations of motion until it slides.

        The tangential force f N_i along +x (a tilt by tan(alpha) = f; in 2D
        the direction of the quasi-static network tilt test) is added to every
        node and f rises from 0 at ``rate`` per tau_dyn, theta frozen; the
        nodes move by eq. `dynamics`, as in :meth:`run`: a node starts, along
        F_i, when |F_i| reaches mu_s,i N_i, and one whose velocity returns to
        zero gets a new threshold (from ``rng``) and sticks, or starts again
        if it is above it. While nothing moves, u is fixed and the next start
        is found in closed form (no steps).

        **Slides for good.** The network slides for good from the moment
        every node moves along +x, the mean load sum_i F_i / sum_i N_i
        exceeds mu_d, and the centre-of-mass velocity V = sum_i N_i v_i /
        sum_i N_i exceeds B_i for every node i, where B_i bounds |v_i - V|.
        This is a proof, not a rule of thumb: while every node moves forward
        the friction forces are mu_d N_i, so the rigid mode accelerates at
        sum_i F_i / sum_i N_i - mu_d > 0 (that sum only grows with f: the
        springs' forces sum to zero, f_ext and the dilation's are constant), while each other
        mode k of K phi = lambda M phi (M = diag(N_i)) is a free harmonic
        oscillator (the tilt and friction forces are proportional to N_i and
        drive the rigid mode alone); its velocity amplitude
        A_k = sqrt((phi_k . F)^2 / lambda_k + (phi_k . M v)^2) is conserved,
        and |v_i - V| <= B_i = sum_k |phi_k,i| A_k. So no velocity can
        return to zero, and the network never sticks again. It requires a
        connected network without springs to the ground (K has the single
        null vector (1, ..., 1)). The proof is checked after every event
        and every ``2 pi`` tau_dyn of motion.

        **In 2D** the friction -mu_d N_i v_i/|v_i| is not uniform unless
        every velocity has one direction, so the modes are coupled and their
        amplitudes are not conserved; the proof uses the internal energy
        instead. With V the centre-of-mass velocity, w_i = v_i - V and r the
        forces less their uniform part (r_i = F_i - N_i sum_j F_j / sum_j N_j:
        the springs' force about their equilibrium under the constant loads),
        E = (1/2) r . K^+ r + (1/2) sum_i N_i |w_i|^2. While every node
        slides, the tilt does no work on the w_i (sum_i N_i w_i = 0) and
        friction only removes energy from them (sum_i N_i w_i . v_i/|v_i| =
        sum_i N_i |v_i| - V . sum_i N_i v_i/|v_i| >= 0), so E never grows,
        and |w_i| <= B_i = sqrt(2 E (1/N_i - 1/sum_j N_j)) (the largest |w_i|
        at kinetic energy E with sum_j N_j w_j = 0). The load along x drives
        V_x at sum_i F_i,x / sum_i N_i - mu_d or more, which is > 0 and only
        grows with f. So once every node moves, that load exceeds mu_d and
        V_x > B_i for every i, |v_i| >= V_x - B_i > 0 for ever: the network
        never sticks again. It requires K^+ r to be the equilibrium, i.e. loads
        f_ext + theta g whose non-uniform part has no net torque (the dilation
        has none; a tilt or an incline is uniform per N_i).

        **mu_eff** is the load at the last moment the network was at rest
        (every node stuck) before it slid for good: the largest load the
        state held, where the quasi-static test's f is the load at which its
        final avalanche starts. The ramp raises f during each motion by
        ``rate`` times its duration, so the earlier avalanches (and
        redraws) come at slightly higher loads than under a static load:
        ``rate`` x (the longest motion) bounds that effect. mu_eff is not
        forced above mu_d: a collective motion that starts below mu_d and
        lasts while f ramps past it slides (``certified`` is above mu_d).

        Parameters
        ----------
        u : ndarray, shape (N,) in 1D, (N, 2) in 2D
            Displacements from the reference positions, in l0 (u = 0 is
            every spring at rest at theta(0); ``Dynamics.run(states=True)``
            returns them).
        mu_s : ndarray, shape (N,)
            Thresholds, each > mu_d. Not modified.
        rng : numpy.random.Generator
            The stream of the thresholds redrawn when a node stops: the
            scene's thresholds law truncated at mu_d, read through a
            :class:`~slidernet.plugins.distributions.stream.TruncatedStream`
            that owns it (nothing else should draw from it).
        theta : float
            theta - theta(0) of the state (dimensionless; ``run``'s
            ``theta``), frozen during the test.
        rate : float
            df/ds, per tau_dyn, finite and > 0 (default 1e-5).

        Returns
        -------
        dict
            Loads per unit normal load along x, each f + f_bar with f_bar =
            sum_i f_ext,i / sum_i N_i (f itself without f_ext), like the
            quasi-static test's: ``mu_eff``; ``first_start``, at the first
            start of motion; ``all_moving``, when every node first moved at
            once, above mu_d or not; ``certified``, when the proof above held
            (>= mu_eff; > mu_d). ``starts``: the starts of motion (int).

        Raises
        ------
        ConfigError
            A bad argument, or a network that has springs to the ground or (1D) is not connected,
            or (2D) loads with a net torque.
        TiltTestError
            More than 1e5 starts of motion, or one motion of 1e5 tau_dyn, without sliding for good.

        Examples
        --------
        Three unstressed sliders with the same threshold 0.6 all start at
        f = 0.6 and slide: mu_eff = mu_s, with no ramp effect (it is found
        in closed form while everything is at rest).

        >>> from slidernet.config import load_config
        >>> scene = Scene.from_config(load_config({
        ...     "steps": 1, "network": {"kind": "chain", "n": 3, "Ntilde": 1e-7},
        ...     "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        ...     "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}))
        >>> out = Dynamics(scene, tau_ratio=1e-4).tilt_test(np.zeros(3), np.full(3, 0.6),
        ...                                                 np.random.default_rng(0))
        >>> print(f"{out['mu_eff']:.12f} {out['first_start']:.12f} {out['all_moving']:.6f}")
        0.600000000000 0.600000000000 0.600000
        >>> bool(out["mu_eff"] <= out["certified"]), out["starts"]
        (True, 3)
        """
        owner = "Dynamics.tilt_test"
        N = self.normal_load.size
        mu_d = float(self.scene.mu_d)
        Ntilde = self.scene.network.Ntilde
        u = np.asarray(u, dtype=np.float64)
        mu_s = np.asarray(mu_s, dtype=np.float64)
        shape = (N,) if self.dim == 1 else (N, self.dim)
        if u.shape != shape or not np.isfinite(u).all():
            raise param_error("u", owner, f"a finite array of shape {shape}, in l0", u)
        if mu_s.shape != (N,) or not (np.isfinite(mu_s).all() and (mu_s > mu_d).all()):
            raise param_error("mu_s", owner, f"a finite array of shape ({N},) with every value > mu_d = {mu_d}",
                              mu_s)
        if not isinstance(rng, np.random.Generator):
            raise param_error("rng", owner, "a numpy.random.Generator", rng)
        if isinstance(theta, bool) or not isinstance(theta, (int, float)) or not math.isfinite(theta):
            raise param_error("theta", owner, "a finite number (theta - theta(0), dimensionless)", theta)
        if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not (math.isfinite(rate) and rate > 0):
            raise param_error("rate", owner, "a finite number > 0 (per tau_dyn)", rate)
        stream = TruncatedStream(self.scene.distribution, rng)

        def batches() -> Iterator[np.ndarray]:
            while True:
                yield stream.take(16)

        # theta(0) = 0 and theta = theta / Ntilde: forces() sees the state's theta - theta(0).
        real = _Realization(self, np.zeros(1), ThresholdStream(mu_s.copy(), batches()))
        real.u = u.reshape(-1) / Ntilde
        if self.dim == 1:
            self.modes()
        else:
            # The proof's elastic energy needs the loads' non-uniform part in the range of K:
            # no net torque (a spring's pair of forces has none, nor does a load uniform per N_i).
            F = real.forces(float(theta) / Ntilde).reshape(N, 2)
            r = (F - np.outer(self.normal_load, F.sum(axis=0) / self.normal_load.sum())).reshape(-1)
            if np.abs(self.K @ (self.compliance() @ r) - r).max() > 1e-9 * max(np.abs(r).max(), 1.0):
                raise ConfigError(
                    "The dynamic tilt test of a 2D network needs loads f_ext + theta g whose part not uniform "
                    "per unit normal load has no net torque: its proof of sliding rests on the elastic energy."
                )
        return real.tilt(float(theta) / Ntilde, float(rate))

    def compliance(self) -> np.ndarray:
        """K^+, the pseudo-inverse of K, for the 2D tilt test's proof of sliding.

        Returns
        -------
        ndarray, shape (N d, N d)
            In 1 / k0. (1/2) r . K^+ r is the elastic energy of a force r on
            the nodes that K can balance (r in the range of K).

        Raises
        ------
        ConfigError
            Springs to the ground (a translation that is not a null vector of K).
        """
        if self._compliance is None:
            K, d = self.K, self.dim
            scale = np.abs(K).max() if K.size else 1.0
            shift = np.zeros((K.shape[0], d))
            for c in range(d):
                shift[c::d, c] = 1.0
            if np.abs(K @ shift).max() > 1e-12 * scale:
                raise ConfigError(
                    "The dynamic tilt test needs a network without springs to the ground "
                    "(K with the translations as null vectors): its proof of sliding rests on the rigid mode."
                )
            self._compliance = np.linalg.pinv(K, rcond=1e-10, hermitian=True)
        return self._compliance

    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """The non-rigid modes of the network, for the tilt test's proof of sliding.

        Returns
        -------
        lam : ndarray, shape (N - 1,)
            The nonzero eigenvalues lambda_k of K phi = lambda M phi, M = diag(N_i),
            in k0 / N (per tau_dyn squared).
        phi : ndarray, shape (N, N - 1)
            Their eigenvectors, M-orthonormal (phi.T M phi = 1).
        """
        if self._modes is None:
            K, N = self.K, self.normal_load
            scale = np.abs(K).max() if K.size else 1.0
            lam, phi = eigh(K, np.diag(N))
            grounded = np.abs(K.sum(axis=1)).max() > 1e-12 * scale
            if grounded or (lam.size > 1 and lam[1] <= 1e-9 * scale / N.max()):
                raise ConfigError(
                    "The dynamic tilt test needs a connected network without springs to the ground "
                    "(K with the single null vector (1, ..., 1)): its proof of sliding rests on the rigid mode."
                )
            self._modes = (lam[1:], phi[:, 1:])
        return self._modes


def node_norms(x: np.ndarray, dim: int) -> np.ndarray:
    """|x_i| of node-major vectors x (shape (n dim,)), shape (n,): the absolute value in 1D."""
    return np.abs(x) if dim == 1 else np.hypot(x[0::2], x[1::2])


def node_dots(x: np.ndarray, y: np.ndarray, dim: int) -> np.ndarray:
    """x_i . y_i of node-major vectors (shape (n dim,)), shape (n,)."""
    return x * y if dim == 1 else x[0::2] * y[0::2] + x[1::2] * y[1::2]


def dofs(nodes: np.ndarray | int, dim: int) -> np.ndarray:
    """The node-major indices (i dim + c) of the components of ``nodes``."""
    return (np.atleast_1d(nodes)[:, None] * dim + np.arange(dim)).reshape(-1)


def _speed_event(columns: np.ndarray, dim: int) -> Callable[[float, np.ndarray], float]:
    """The terminal event min_i |v_i| - STOP_SPEED over the nodes whose velocities are ``y[columns]``, falling."""
    def stop(s: float, y: np.ndarray) -> float:
        return float(node_norms(y[columns], dim).min() - STOP_SPEED)

    stop.terminal = True
    stop.direction = -1.0
    return stop


class _Realization:
    """The state of one integrated realization and its event loop.

    Attributes: ``u`` (N d,) displacements in Ntilde l0, node-major; ``v``
    (N d,) velocities in Ntilde l0 per tau_dyn; ``moving`` (N,) bool;
    ``sigma`` (N d,) the unit direction of F_i when node i started: in 1D
    the sign of its motion; in 2D the direction of its friction while
    v_i = 0 (see the module's "How it is integrated"); ``t`` the time in
    tau_th; ``clock`` the time spent in motion, in tau_dyn (it also runs
    during the relaxation at t = 0, where theta is frozen).
    """

    def __init__(self, dyn: Dynamics, thetas: np.ndarray, draws: ThresholdStream) -> None:
        self.d = dyn
        self.thetas = thetas
        self.draws = draws
        N = dyn.normal_load.size
        nd = N * dyn.dim
        self.mu = draws.initial.copy()
        self.lim = self.mu * dyn.normal_load
        self.u = np.zeros(nd)
        self.v = np.zeros(nd)
        self.moving = np.zeros(N, bool)
        self.sigma = np.zeros(nd)
        self.t = 0.0
        self.clock = 0.0
        self.n = 0
        self.overlapping = 0
        self.stop_speed = 0.0  # the largest |v_i| set to zero at a stop, Ntilde l0 per tau_dyn
        self.start_t = np.zeros(N)
        self.start_clock = np.zeros(N)
        self.start_u = np.zeros(nd)
        self.slips: list[tuple[float, float, float, int, np.ndarray]] = []
        self.f = 0.0  # the tilt load per unit normal load, along x (tilt only)

    def forces(self, theta: float) -> np.ndarray:
        """F = -K u + (theta - theta(0)) g + f_ext + f N x, in N, shape (N d,); theta in units of Ntilde.

        u = 0 is every spring at rest at theta(0), as in the solver (a = -g theta(0)).
        f is the tilt load of :meth:`tilt`, along x, 0 (and left out) under the thermal drive.
        """
        d = self.d
        F = d.f_ext - d.K @ self.u + d.g * (theta - self.thetas[0])
        if self.f:
            F[0::d.dim] += self.f * d.normal_load
        return F

    def run(self, steps: int, states: bool = False) -> dict[str, np.ndarray]:
        d, thetas = self.d, self.thetas
        rec = d.scene.out_steps[d.scene.out_steps <= steps]
        out_n = np.zeros(rec.size, np.int64)
        out_mu_max = np.zeros(rec.size)
        out_xg = np.zeros(rec.size)
        N = d.normal_load.size
        shape = (N,) if d.dim == 1 else (N, d.dim)
        out_u = np.zeros((rec.size, *shape)) if states else None
        out_mu = np.zeros((rec.size, N)) if states else None
        out_F = np.zeros((rec.size, *shape)) if states else None
        # An f_ext above some thresholds is relaxed with theta frozen at
        # theta(0), before the t = 0 record, as the solver does.
        self._start_overloaded(thetas[0])
        while self.moving.any():
            s1, kind = self._move(thetas[0], np.zeros_like(d.g), MAX_SLIP_DURATION)
            self._after_move(s1, kind, thetas[0])
            self._check_runaway()
        k = 0
        for q in range(steps + 1):
            if k < rec.size and rec[k] == q:
                out_n[k] = self.n
                out_mu_max[k] = self.mu.max()
                out_xg[k] = d.w @ self.u[0::d.dim]
                if states:
                    # Every node is at rest here except those still moving at the step (moving_at_end).
                    out_u[k] = self.u.reshape(shape)
                    out_mu[k] = self.mu
                    out_F[k] = self.forces(thetas[q]).reshape(shape)
                k += 1
            if q == steps:
                break
            self._segment(q, thetas[q], thetas[q + 1])
        Ntilde = d.scene.network.Ntilde
        starts = np.array([slip[:4] for slip in self.slips], dtype=float).reshape(-1, 4)
        du = np.array([slip[4] for slip in self.slips], dtype=float).reshape(-1, d.dim)
        extra = {}
        if states:
            extra = {"u": out_u * Ntilde, "mu_s": out_mu, "F": out_F,
                     "theta": (thetas[rec] - thetas[0]) * Ntilde}
        return {
            "t": rec.astype(np.int64),
            "n": out_n,
            "mu_max": out_mu_max,
            "x_G": out_xg * Ntilde,
            "overlapping": np.int64(self.overlapping),
            "moving_at_end": np.int64(self.moving.sum()),
            "stop_speed": float(self.stop_speed * Ntilde),
            "slips": {
                "start": starts[:, 0].copy(),
                "end": starts[:, 1].copy(),
                "duration": starts[:, 2].copy(),
                "node": starts[:, 3].astype(np.int64),
                "du": (du[:, 0] if d.dim == 1 else du) * Ntilde,
            },
            **extra,
        }

    def _segment(self, q: int, theta_a: float, theta_b: float) -> None:
        """From t = q to t = q + 1, theta linear from ``theta_a`` to ``theta_b`` (units of Ntilde)."""
        rate = theta_b - theta_a  # per tau_th
        tau = self.d.tau_ratio
        while True:
            theta = theta_a + rate * (self.t - q)
            if self.moving.any():
                left = (q + 1 - self.t) / tau
                s1, kind = self._move(theta, self.d.g * (rate * tau), min(left, MAX_SLIP_DURATION))
                if kind is None and s1 >= left:
                    break
                self.t += tau * s1
                self._after_move(s1, kind, theta_a + rate * (self.t - q))
                self._check_runaway()
            else:
                # Nothing moves: theta drives F through g (eq. `critique`).
                wait, j = self._next_start(self.forces(theta), self.d.g * rate)
                # Inclusive at the end of the segment, as the solver's eq. `critique`.
                if j < 0 or self.t + wait > q + 1:
                    break
                self.t += wait
                theta = theta_a + rate * (self.t - q)
                self._start(j, self.forces(theta))
                self._start_overloaded(theta)
        self.t = float(q + 1)

    def _next_start(self, F: np.ndarray, drive: np.ndarray) -> tuple[float, int]:
        """Nothing moves: the first start under a linear drive, in closed form.

        u is constant, so F_j(x) = F_j + drive_j x, with x the time (or
        load) in whatever unit ``drive`` is per; the next start is the first
        root of |F_j(x)| = mu_s,j N_j over the driven nodes: linear in 1D,
        a quadratic in 2D. Returns the wait x >= 0 and the node; the node is
        -1 (and the wait inf) when nothing is driven.
        """
        dim = self.d.dim
        lim = self.lim
        if dim == 1:
            driven = np.flatnonzero(drive)
            if driven.size == 0:
                return math.inf, -1
            sgn = np.sign(drive[driven])
            wait = np.maximum((lim[driven] - sgn * F[driven]) / np.abs(drive[driven]), 0.0)
        else:
            a = node_dots(drive, drive, dim)
            driven = np.flatnonzero(a > 0.0)
            if driven.size == 0:
                return math.inf, -1
            a = a[driven]
            b = node_dots(F, drive, dim)[driven]
            c = node_dots(F, F, dim)[driven] - lim[driven] ** 2
            root = np.sqrt(np.maximum(b * b - a * c, 0.0))
            # The positive root of a x^2 + 2 b x + c = 0 (c < 0 below the threshold), in the form
            # without cancellation for either sign of b.
            with np.errstate(divide="ignore", invalid="ignore"):
                wait = np.where(b >= 0.0, -c / (b + root), (root - b) / a)
            wait = np.where(c >= 0.0, 0.0, wait)
        j = int(np.argmin(wait))
        return float(wait[j]), int(driven[j])

    def _start(self, i: int, F: np.ndarray) -> None:
        """Node i starts moving along its force F_i (``F``: every node's, shape (N d,)): one rearrangement."""
        if self.moving.any():
            self.overlapping += 1
        self.n += 1
        self.moving[i] = True
        k = dofs(i, self.d.dim)
        self.sigma[k] = F[k] / node_norms(F[k], self.d.dim)  # the sign of F_i in 1D
        self.v[k] = 0.0
        self.start_t[i] = self.t
        self.start_clock[i] = self.clock
        self.start_u[k] = self.u[k]

    def _start_overloaded(self, theta: float) -> None:
        """Start every stuck node above its threshold, the largest overload first."""
        while True:
            F = self.forces(theta)
            over = np.where(self.moving, 0.0, node_norms(F, self.d.dim) / self.lim)
            i = int(np.argmax(over))
            if over[i] <= 1.0:
                return
            self._start(i, F)

    def _move(self, theta0: float, drive: np.ndarray, s_max: float) -> tuple[float, str | None]:
        """Integrate the moving nodes from local time s = 0 to the first event or to ``s_max``.

        The forces at s = 0 are ``forces(theta0)``; during the phase they
        change, besides the springs, by ``drive`` s: ``drive`` (shape (N d,),
        N per tau_dyn) is g dtheta/ds when theta drives, f' N_i x when a tilt
        f(s) does (:meth:`tilt`). Updates u and v of the moving nodes and
        ``clock``; returns the time elapsed (tau_dyn) and the event,
        ``"stop"`` (in 1D v_i sigma_i fell to zero; in 2D |v_i| fell to
        STOP_SPEED), ``"start"`` or None.
        """
        d = self.d
        dim = d.dim
        M = np.flatnonzero(self.moving)
        Md = dofs(M, dim)
        Sd = dofs(np.flatnonzero(~self.moving), dim)
        m = Md.size
        F0 = self.forces(theta0)
        Nm = np.repeat(d.normal_load, dim)[Md]
        sig = self.sigma[Md]
        mu_d = d.scene.mu_d
        # y = (u_M - u_M(0), du_M/ds) obeys y' = A y + c s + b with friction along sigma; with
        # z = (y, s, 1) that is one product y' = B z, half the cost of three array operations.
        B = np.zeros((2 * m, 2 * m + 2))
        B[:m, m:2 * m] = np.eye(m)
        B[m:, :m] = -d.K[np.ix_(Md, Md)] / Nm[:, None]
        B[m:, 2 * m] = drive[Md] / Nm
        B[m:, 2 * m + 1] = (F0[Md] - mu_d * Nm * sig) / Nm
        z = np.zeros(2 * m + 2)
        z[-1] = 1.0

        if dim == 1:
            def rhs(s: float, y: np.ndarray) -> np.ndarray:
                z[:-2] = y
                z[-2] = s
                return B @ z
        else:
            def rhs(s: float, y: np.ndarray) -> np.ndarray:
                z[:-2] = y
                z[-2] = s
                out = B @ z
                # Friction along -v_i/|v_i| (per unit mass mu_d, as m_i = N_i m), not along -sigma_i:
                # B holds the part along sigma_i, this the difference. At v_i = 0 (a node starting) the
                # direction is sigma_i, the force's.
                v = y[m:]
                speed = np.repeat(node_norms(v, dim), dim)
                out[m:] -= mu_d * np.where(speed > 0.0, v / np.where(speed > 0.0, speed, 1.0) - sig, 0.0)
                return out

        if dim == 1:
            def stop(s: float, y: np.ndarray) -> float:
                # A node that starts at s = 0 has zero velocity there: a placeholder > 0 at s = 0 keeps
                # the root finder from stopping it at once when another node stops within the first step.
                if s == 0.0:
                    return 1.0
                return float((sig * y[m:]).min())

            stop.terminal = True
            stop.direction = -1.0
            events = [stop]
        else:
            # |v_i| falls to STOP_SPEED. The nodes that start at s = 0 rise through it first, which the
            # direction -1 ignores; watched apart, they cannot hide the fall of a node already moving.
            starting = node_norms(self.v[Md], dim) < STOP_SPEED
            events = []
            for group in (starting, ~starting):
                if group.any():
                    events.append(_speed_event(dofs(np.flatnonzero(group), dim) + m, dim))
        n_stop = len(events)
        if Sd.size:
            K_SM = d.K[np.ix_(Sd, Md)]
            F0_S = F0[Sd]
            g_S = drive[Sd]
            lim_S = self.lim[~self.moving]

            def start(s: float, y: np.ndarray) -> float:
                return float((node_norms(F0_S - K_SM @ y[:m] + g_S * s, dim) - lim_S).max())

            start.terminal = True
            start.direction = 1.0
            events.append(start)
        y0 = np.concatenate([np.zeros(m), self.v[Md]])
        sol = solve_ivp(rhs, (0.0, s_max), y0, method=d.method, rtol=d.rtol, atol=d.atol,
                        max_step=d.max_step, events=events)
        if sol.status == -1:  # pragma: no cover - the right-hand side is smooth between events
            raise RuntimeError(f"solve_ivp failed at t = {self.t} tau_th: {sol.message}")
        s1 = float(sol.t[-1])
        y1 = sol.y[:, -1]
        self.u[Md] += y1[:m]
        self.v[Md] = y1[m:]
        self.clock += s1
        kind = None
        if sol.status == 1:
            kind = "stop" if any(sol.t_events[e].size for e in range(n_stop)) else "start"
        return s1, kind

    def _after_move(self, s1: float, kind: str | None, theta: float) -> None:
        """Apply the event that ended a phase (``self.t`` and u already at its time)."""
        d = self.d
        dim = d.dim
        if kind == "stop":
            M = np.flatnonzero(self.moving)
            v_M = self.v[dofs(M, dim)]
            if dim == 1:
                i = int(M[np.argmin(self.sigma[M] * v_M)])
            else:
                i = int(M[np.argmin(np.abs(node_norms(v_M, dim) - STOP_SPEED))])
            k = dofs(i, dim)
            self.stop_speed = max(self.stop_speed, float(node_norms(self.v[k], dim)[0]))
            self.moving[i] = False
            self.v[k] = 0.0
            self.slips.append((self.start_t[i], self.t, (self.clock - self.start_clock[i]) * d.tau_ratio, i,
                               self.u[k] - self.start_u[k]))
            # A new place on the substrate: a new threshold.
            self.mu[i] = self.draws.next()
            self.lim[i] = self.mu[i] * d.normal_load[i]
        elif kind == "start":
            F = self.forces(theta)
            S = np.flatnonzero(~self.moving)
            j = int(S[np.argmax(node_norms(F, dim)[S] - self.lim[S])])
            self._start(j, F)
        # A stopped node above its new threshold starts again, and a node that
        # the event left above its threshold (a tie) starts too.
        self._start_overloaded(theta)

    def _check_runaway(self) -> None:
        """Under the thermal drive a node that never stops means a load friction cannot hold."""
        longest = self.clock - self.start_clock[self.moving]
        if longest.size and longest.max() >= MAX_SLIP_DURATION:
            i = int(np.flatnonzero(self.moving)[np.argmax(longest)])
            raise AvalancheError(
                f"Node {i} has been sliding for {MAX_SLIP_DURATION:g} tau_dyn without stopping "
                f"(t = {self.t!r} tau_th): a load f_ext that friction cannot hold makes the network slide "
                "for ever; lower f_ext."
            )

    def tilt(self, theta: float, rate: float) -> dict[str, float]:
        """The loop of :meth:`Dynamics.tilt_test`: theta frozen (units of Ntilde), f(s) = rate s along x."""
        d = self.d
        mu_d = float(d.scene.mu_d)
        N = d.normal_load
        drive = np.zeros_like(self.u)
        drive[0::d.dim] = rate * N  # dF_i/ds of the tilt, N per tau_dyn
        f_bar = float(d.f_ext[0::d.dim].sum() / N.sum())
        first = all_moving = math.nan
        # An overloaded state starts moving at f = 0: the network was never at rest.
        self._start_overloaded(theta)
        rest = f_bar if self.moving.any() else math.nan
        if self.moving.any():
            first = f_bar
        avalanche = 0.0  # tau_dyn of motion since the network was last at rest
        while True:
            if self.n > TILT_MAX_STARTS:
                raise TiltTestError(
                    f"The dynamic tilt test made {TILT_MAX_STARTS} starts of motion without sliding for good "
                    f"(load {self.f + f_bar!r})."
                )
            if not self.moving.any():
                # At rest: u is fixed and F grows by drive per tau_dyn, so the next start is exact.
                wait, j = self._next_start(self.forces(theta), drive)
                self.f += rate * wait
                rest = self.f + f_bar
                if math.isnan(first):
                    first = rest
                avalanche = 0.0
                self._start(j, self.forces(theta))
                self._start_overloaded(theta)
            else:
                s1, kind = self._move(theta, drive, TILT_CHUNK)
                self.f += rate * s1
                avalanche += s1
                self._after_move(s1, kind, theta)
            if math.isnan(all_moving) and self.moving.all():
                all_moving = self.f + f_bar
            if self._slides_for_good(theta, mu_d):
                return {"mu_eff": rest, "first_start": first, "all_moving": all_moving,
                        "certified": self.f + f_bar, "starts": int(self.n)}
            if avalanche > TILT_MAX_AVALANCHE:
                raise TiltTestError(
                    f"The dynamic tilt test has been moving for {TILT_MAX_AVALANCHE:g} tau_dyn without the proof "
                    f"that it slides for good (load {self.f + f_bar!r})."
                )

    def _slides_for_good(self, theta: float, mu_d: float) -> bool:
        """Every node moves, the mean load along x exceeds mu_d, and no node's velocity can return to zero.

        1D: the bound of each node's velocity about the centre of mass's from the conserved
        amplitudes of the modes; 2D: from the internal energy, which friction only lowers
        (:meth:`Dynamics.tilt_test`).
        """
        if not self.moving.all():
            return False
        d = self.d
        dim = d.dim
        N = d.normal_load
        F = self.forces(theta)
        if F[0::dim].sum() / N.sum() <= mu_d:
            return False
        if dim == 1:
            if (self.sigma < 0).any():
                return False
            lam, phi = d.modes()
            V = float(N @ self.v / N.sum())
            amplitude = np.sqrt((phi.T @ F) ** 2 / lam + (phi.T @ (N * self.v)) ** 2)
            bound = np.abs(phi) @ amplitude
            return bool((V > bound).all())
        v = self.v.reshape(-1, dim)
        V = N @ v / N.sum()
        # r = F less its uniform part N_i sum(F) / sum(N): the springs' force about their
        # equilibrium under the constant loads, so (1/2) r . K^+ r is the elastic energy above it.
        r = (F.reshape(-1, dim) - np.outer(N, F.reshape(-1, dim).sum(axis=0) / N.sum())).reshape(-1)
        energy = 0.5 * r @ (d.compliance() @ r) + 0.5 * N @ ((v - V) ** 2).sum(axis=1)
        bound = np.sqrt(2.0 * max(energy, 0.0) * (1.0 / N - 1.0 / N.sum()))
        return bool((V[0] > bound).all())
