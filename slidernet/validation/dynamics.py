"""A reference integrator of the equations of motion (eq. `dynamics`), to measure the quasi-static error.

The solver (:mod:`slidernet.solver`) makes every slip instantaneous and lets
the slipping node move alone. Here the sliders have inertia: node i has mass
m_i = N_i m, and while it moves

    m_i d^2u_i/dt^2 = F_i(u, theta(t)) - mu_d N_i S(du_i/dt),    F = -K u + theta g + f_ext,

with theta(t) linear between theta(t_q) and theta(t_q+1), the same driver
values as the solver's. A stuck node has du_i/dt = 0 while |F_i| <= mu_s,i N_i
and starts, with the sign of F_i, when |F_i| reaches mu_s,i N_i, whatever the
other nodes do: several nodes may move at once. A moving node whose velocity
returns to zero has reached a new place on the substrate: its threshold is
redrawn, and it sticks if |F_i| <= mu_s,i N_i, otherwise it starts again (a
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
N_i d^2u_i/ds^2 = F_i - mu_d N_i S(du_i/ds) and every number is of order one.

How it is integrated
--------------------
Between two events the set of moving nodes and the signs of their velocities
are fixed and theta is linear in time, so the equations are linear with a
smooth right-hand side: each such phase is one call of
:func:`scipy.integrate.solve_ivp` with two terminal events, the smallest
velocity of a moving node (along its direction of motion) falling to zero,
and the largest |F_j| - mu_s,j N_j of the stuck nodes rising to zero. A phase
where nothing moves has u constant and F_j linear in t, so its first threshold
crossing is found in closed form (the solver's eq. `critique`), with no steps.

Cost: about 21 ms per slip at the defaults (DOP853, max_step = 0.05 tau_dyn,
~66 steps per slip), 15 ms with RK45, 7 ms at max_step = 0.2 and 4 ms at
max_step = inf, on the paper's two sliders and on a chain of 4 alike (577 and
160 slips, tau_ratio = 1e-4, one core): the time is scipy's, per step.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

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
    """Reference integrator of the equations of motion (eq. `dynamics`) on a 1D network.

    Constructing it validates and stores the settings; :meth:`run` integrates
    one realization, with the same theta(t_q) and the same stream of mu_s
    draws as :func:`slidernet.solver.simulate` on the same seed.

    Parameters
    ----------
    scene : Scene
        A scene of a 1D network (``two_slider``, ``chain`` or any 1D
        :class:`~slidernet.model.network.Network`), with its f_ext, normal loads,
        thresholds law and driver.
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
        if net.dim != 1:
            raise ConfigError(
                f"Dynamics integrates 1D networks only; the scene's network is {net.dim}D "
                f"({net!r}). Compare 2D networks through the solver's slip options (solver.slip)."
            )
        self.scene = scene
        self.tau_ratio = float(tau_ratio)
        self.max_step = float(max_step)
        self.rtol = float(rtol)
        self.atol = ATOL_SCALE * self.rtol
        self.method = method
        # Dense operators: the networks integrated here are small (N <= ~16),
        # and a dense sub-block product is the cheapest right-hand side.
        self.K = net.stiffness_matrix().toarray()
        self.g = np.asarray(scene.operators.g, dtype=np.float64)
        self.normal_load = net.normal_load.astype(np.float64)
        self.w = self.normal_load / self.normal_load.sum()
        self.f_ext = net.f_ext[:, 0].astype(np.float64)
        self._modes: tuple[np.ndarray, np.ndarray] | None = None  # the tilt test's, built on first use

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
            displacement), each of shape (T,), at the scene's recorded times
            up to ``steps``; ``overlapping`` (int64 scalar: starts while another
            node was moving); ``moving_at_end`` (int64 scalar: nodes still
            moving at t = steps); ``slips``, a dict of arrays of shape (S,),
            one per slip that came to rest by t = ``steps``, in the order they
            ended: ``start`` and ``end`` (tau_th), ``duration`` (tau_th,
            computed in the integrator's local time, so exact even where
            ``start`` is large), ``node`` (int64), ``du`` (l0).

            With ``states``, also, each of shape (T, N) except ``theta``:
            ``u``, the displacements from the reference positions (l0; u = 0
            is every spring at rest at theta(0)); ``mu_s``, the thresholds;
            ``F``, the forces on the nodes (N: springs, dilation and f_ext);
            ``theta``, shape (T,), theta(t) - theta(0) (dimensionless). A node
            still moving at a recorded time (rare: the records fall between
            two thermal segments) is recorded where it is.
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

        The tangential force f N_i along +x (a tilt by tan(alpha) = f) is
        added to every node and f rises from 0 at ``rate`` per tau_dyn,
        theta frozen; the nodes move by eq. `dynamics`, as in :meth:`run`: a
        node starts when |F_i| reaches mu_s,i N_i, and one whose velocity
        returns to zero gets a new threshold (from ``rng``) and sticks, or
        starts again if it is above it. While nothing moves, u is fixed and
        the next start is found in closed form (no steps).

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
        u : ndarray, shape (N,)
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
            A bad argument, or a network that is not connected or has springs to the ground.
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
        if u.shape != (N,) or not np.isfinite(u).all():
            raise param_error("u", owner, f"a finite array of shape ({N},), in l0", u)
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
        real.u = u / Ntilde
        return real.tilt(float(theta) / Ntilde, float(rate), self.modes())

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


class _Realization:
    """The state of one integrated realization and its event loop.

    Attributes: ``u`` (N,) displacements in Ntilde l0; ``v`` (N,) velocities
    in Ntilde l0 per tau_dyn; ``moving`` (N,) bool; ``sigma`` (N,) the sign of
    the motion of each moving node; ``t`` the time in tau_th; ``clock`` the
    time spent in motion, in tau_dyn (it also runs during the relaxation at
    t = 0, where theta is frozen).
    """

    def __init__(self, dyn: Dynamics, thetas: np.ndarray, draws: ThresholdStream) -> None:
        self.d = dyn
        self.thetas = thetas
        self.draws = draws
        N = dyn.normal_load.size
        self.mu = draws.initial.copy()
        self.lim = self.mu * dyn.normal_load
        self.u = np.zeros(N)
        self.v = np.zeros(N)
        self.moving = np.zeros(N, bool)
        self.sigma = np.zeros(N)
        self.t = 0.0
        self.clock = 0.0
        self.n = 0
        self.overlapping = 0
        self.start_t = np.zeros(N)
        self.start_clock = np.zeros(N)
        self.start_u = np.zeros(N)
        self.slips: list[tuple[float, float, float, int, float]] = []
        self.f = 0.0  # the tilt load per unit normal load (tilt only)

    def forces(self, theta: float) -> np.ndarray:
        """F = -K u + (theta - theta(0)) g + f_ext + f N, in N, shape (N,); theta in units of Ntilde.

        u = 0 is every spring at rest at theta(0), as in the solver (a = -g theta(0)).
        f is the tilt load of :meth:`tilt`, 0 (and left out) under the thermal drive.
        """
        d = self.d
        F = d.f_ext - d.K @ self.u + d.g * (theta - self.thetas[0])
        if self.f:
            F += self.f * d.normal_load
        return F

    def run(self, steps: int, states: bool = False) -> dict[str, np.ndarray]:
        d, thetas = self.d, self.thetas
        rec = d.scene.out_steps[d.scene.out_steps <= steps]
        out_n = np.zeros(rec.size, np.int64)
        out_mu_max = np.zeros(rec.size)
        out_xg = np.zeros(rec.size)
        N = d.normal_load.size
        out_u = np.zeros((rec.size, N)) if states else None
        out_mu = np.zeros((rec.size, N)) if states else None
        out_F = np.zeros((rec.size, N)) if states else None
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
                out_xg[k] = d.w @ self.u
                if states:
                    # Every node is at rest here except those still moving at the step (moving_at_end).
                    out_u[k] = self.u
                    out_mu[k] = self.mu
                    out_F[k] = self.forces(thetas[q])
                k += 1
            if q == steps:
                break
            self._segment(q, thetas[q], thetas[q + 1])
        Ntilde = d.scene.network.Ntilde
        slips = np.array(self.slips, dtype=float).reshape(-1, 5)
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
            "slips": {
                "start": slips[:, 0].copy(),
                "end": slips[:, 1].copy(),
                "duration": slips[:, 2].copy(),
                "node": slips[:, 3].astype(np.int64),
                "du": slips[:, 4] * Ntilde,
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
                wait, j, sign = self._next_start(self.forces(theta), self.d.g * rate)
                # Inclusive at the end of the segment, as the solver's eq. `critique`.
                if j < 0 or self.t + wait > q + 1:
                    break
                self.t += wait
                self._start(j, sign)
                self._start_overloaded(theta_a + rate * (self.t - q))
        self.t = float(q + 1)

    def _next_start(self, F: np.ndarray, drive: np.ndarray) -> tuple[float, int, float]:
        """Nothing moves: the first start under a linear drive, in closed form.

        u is constant, so F_j(x) = F_j + drive_j x, with x the time (or
        load) in whatever unit ``drive`` is per; the next start is the first
        root of |F_j(x)| = mu_s,j N_j over the driven nodes. Returns the wait
        x >= 0, the node and the sign of its force then; the node is -1 (and
        the wait inf) when nothing is driven.
        """
        driven = np.flatnonzero(drive)
        if driven.size == 0:
            return math.inf, -1, 0.0
        sgn = np.sign(drive[driven])
        wait = np.maximum((self.lim[driven] - sgn * F[driven]) / np.abs(drive[driven]), 0.0)
        j = int(np.argmin(wait))
        return wait[j], int(driven[j]), sgn[j]

    def _start(self, i: int, sign: float) -> None:
        """Node i starts moving with the sign ``sign``: one rearrangement."""
        if self.moving.any():
            self.overlapping += 1
        self.n += 1
        self.moving[i] = True
        self.sigma[i] = sign
        self.v[i] = 0.0
        self.start_t[i] = self.t
        self.start_clock[i] = self.clock
        self.start_u[i] = self.u[i]

    def _start_overloaded(self, theta: float) -> None:
        """Start every stuck node above its threshold, the largest overload first."""
        while True:
            F = self.forces(theta)
            over = np.where(self.moving, 0.0, np.abs(F) / self.lim)
            i = int(np.argmax(over))
            if over[i] <= 1.0:
                return
            self._start(i, 1.0 if F[i] > 0.0 else -1.0)

    def _move(self, theta0: float, drive: np.ndarray, s_max: float) -> tuple[float, str | None]:
        """Integrate the moving nodes from local time s = 0 to the first event or to ``s_max``.

        The forces at s = 0 are ``forces(theta0)``; during the phase they
        change, besides the springs, by ``drive`` s: ``drive`` (shape (N,),
        N per tau_dyn) is g dtheta/ds when theta drives, f' N_i when a tilt
        f(s) does (:meth:`tilt`). Updates u and v of the moving nodes and
        ``clock``; returns the time elapsed (tau_dyn) and the event,
        ``"stop"``, ``"start"`` or None.
        """
        d = self.d
        M = np.flatnonzero(self.moving)
        S = np.flatnonzero(~self.moving)
        m = M.size
        F0 = self.forces(theta0)
        Nm = d.normal_load[M]
        sig = self.sigma[M]
        # y = (u_M - u_M(0), du_M/ds) obeys y' = A y + c s + b; with z = (y, s, 1)
        # that is one product y' = B z, half the cost of three array operations.
        B = np.zeros((2 * m, 2 * m + 2))
        B[:m, m:2 * m] = np.eye(m)
        B[m:, :m] = -d.K[np.ix_(M, M)] / Nm[:, None]
        B[m:, 2 * m] = drive[M] / Nm
        B[m:, 2 * m + 1] = (F0[M] - d.scene.mu_d * Nm * sig) / Nm
        z = np.zeros(2 * m + 2)
        z[-1] = 1.0

        def rhs(s: float, y: np.ndarray) -> np.ndarray:
            z[:-2] = y
            z[-2] = s
            return B @ z

        def stop(s: float, y: np.ndarray) -> float:
            # A node that starts at s = 0 has zero velocity there: a placeholder > 0 at s = 0 keeps
            # the root finder from stopping it at once when another node stops within the first step.
            if s == 0.0:
                return 1.0
            return float((sig * y[m:]).min())

        stop.terminal = True
        stop.direction = -1.0
        events = [stop]
        if S.size:
            K_SM = d.K[np.ix_(S, M)]
            F0_S = F0[S]
            g_S = drive[S]
            lim_S = self.lim[S]

            def start(s: float, y: np.ndarray) -> float:
                return float((np.abs(F0_S - K_SM @ y[:m] + g_S * s) - lim_S).max())

            start.terminal = True
            start.direction = 1.0
            events.append(start)
        y0 = np.concatenate([np.zeros(m), self.v[M]])
        sol = solve_ivp(rhs, (0.0, s_max), y0, method=d.method, rtol=d.rtol, atol=d.atol,
                        max_step=d.max_step, events=events)
        if sol.status == -1:  # pragma: no cover - a linear right-hand side does not fail
            raise RuntimeError(f"solve_ivp failed at t = {self.t} tau_th: {sol.message}")
        s1 = float(sol.t[-1])
        y1 = sol.y[:, -1]
        self.u[M] += y1[:m]
        self.v[M] = y1[m:]
        self.clock += s1
        kind = None
        if sol.status == 1:
            kind = "stop" if sol.t_events[0].size else "start"
        return s1, kind

    def _after_move(self, s1: float, kind: str | None, theta: float) -> None:
        """Apply the event that ended a phase (``self.t`` and u already at its time)."""
        d = self.d
        if kind == "stop":
            M = np.flatnonzero(self.moving)
            i = int(M[np.argmin(self.sigma[M] * self.v[M])])
            self.moving[i] = False
            self.v[i] = 0.0
            self.slips.append((self.start_t[i], self.t, (self.clock - self.start_clock[i]) * d.tau_ratio, i,
                               self.u[i] - self.start_u[i]))
            # A new place on the substrate: a new threshold.
            self.mu[i] = self.draws.next()
            self.lim[i] = self.mu[i] * d.normal_load[i]
        elif kind == "start":
            F = self.forces(theta)
            S = np.flatnonzero(~self.moving)
            j = int(S[np.argmax(np.abs(F[S]) - self.lim[S])])
            self._start(j, 1.0 if F[j] > 0.0 else -1.0)
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

    def tilt(self, theta: float, rate: float, modes: tuple[np.ndarray, np.ndarray]) -> dict[str, float]:
        """The loop of :meth:`Dynamics.tilt_test`: theta frozen (units of Ntilde), f(s) = rate s."""
        d = self.d
        mu_d = float(d.scene.mu_d)
        N = d.normal_load
        drive = rate * N  # dF_i/ds of the tilt, N per tau_dyn
        f_bar = float(d.f_ext.sum() / N.sum())
        lam, phi = modes
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
                wait, j, _ = self._next_start(self.forces(theta), drive)
                self.f += rate * wait
                rest = self.f + f_bar
                if math.isnan(first):
                    first = rest
                avalanche = 0.0
                self._start(j, 1.0)
                self._start_overloaded(theta)
            else:
                s1, kind = self._move(theta, drive, TILT_CHUNK)
                self.f += rate * s1
                avalanche += s1
                self._after_move(s1, kind, theta)
            if math.isnan(all_moving) and self.moving.all():
                all_moving = self.f + f_bar
            if self._slides_for_good(theta, mu_d, lam, phi):
                return {"mu_eff": rest, "first_start": first, "all_moving": all_moving,
                        "certified": self.f + f_bar, "starts": int(self.n)}
            if avalanche > TILT_MAX_AVALANCHE:
                raise TiltTestError(
                    f"The dynamic tilt test has been moving for {TILT_MAX_AVALANCHE:g} tau_dyn without the proof "
                    f"that it slides for good (load {self.f + f_bar!r})."
                )

    def _slides_for_good(self, theta: float, mu_d: float, lam: np.ndarray, phi: np.ndarray) -> bool:
        """Every node moves forward, the rigid mode accelerates, and no node's velocity can return to zero."""
        if not self.moving.all() or (self.sigma < 0).any():
            return False
        N = self.d.normal_load
        F = self.forces(theta)
        if F.sum() / N.sum() <= mu_d:
            return False
        V = float(N @ self.v / N.sum())
        amplitude = np.sqrt((phi.T @ F) ** 2 / lam + (phi.T @ (N * self.v)) ** 2)
        bound = np.abs(phi) @ amplitude
        return bool((V > bound).all())
