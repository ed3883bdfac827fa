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

How it is integrated: :mod:`slidernet.validation.event_loop` (phases
between events, each one call of :func:`scipy.integrate.solve_ivp`; the
closed form while nothing moves; the stop in 1D and in 2D).

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
from collections.abc import Iterator

import numpy as np
from scipy.linalg import eigh

from slidernet.errors import ConfigError, param_error
from slidernet.plugins.distributions.stream import TruncatedStream
from slidernet.solver import Scene
from slidernet.validation.event_loop import (
    MAX_SLIP_DURATION,
    STOP_SPEED,
    TILT_CHUNK,
    TILT_MAX_AVALANCHE,
    TILT_MAX_STARTS,
    EventLoop,
    ThresholdStream,
    dofs,
    node_dots,
    node_norms,
    realization_draws,
)

# The names of the integration (event_loop) are importable from here too, as before the split.
__all__ = ["ATOL_SCALE", "MAX_SLIP_DURATION", "METHODS", "STOP_SPEED", "TILT_CHUNK", "TILT_MAX_AVALANCHE",
           "TILT_MAX_STARTS", "TILT_RATE", "Dynamics", "ThresholdStream", "dofs", "node_dots", "node_norms",
           "realization_draws"]

METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")

# The dynamic tilt test (Dynamics.tilt_test). Its default ramp raises the load per unit
# normal load by 1e-5 per tau_dyn: 3e-5 during one slip of the paper (pi tau_dyn), against
# 0.1 for mu_s - mu_d and ~1e-3 for the aging effects measured with it.
TILT_RATE = 1e-5

# atol = ATOL_SCALE * rtol, in Ntilde l0 (and Ntilde l0 per tau_dyn): a slip of
# the paper is 2 (mu_s - mu_d) ~ 0.2 Ntilde l0 long, its peak velocity ~ 0.1.
ATOL_SCALE = 1e-2


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
        return EventLoop(self, thetas, draws).run(int(steps), bool(states))

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
        real = EventLoop(self, np.zeros(1), ThresholdStream(mu_s.copy(), batches()))
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
