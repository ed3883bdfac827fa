"""The event loop of the reference integrator (:mod:`slidernet.validation.dynamics`), phase by phase.

:class:`EventLoop` holds the state of one realization under the equations
of motion (their units, rules and parameters are those of
:mod:`slidernet.validation.dynamics`) and integrates it from event to event,
under the thermal drive (:meth:`EventLoop.run`) or a rising tilt
(:meth:`EventLoop.tilt`, the loop of
:meth:`~slidernet.validation.dynamics.Dynamics.tilt_test`). Beside it: the
thresholds in the order the solver reads them (:class:`ThresholdStream`,
:func:`realization_draws`) and the node-major helpers of 2D.

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
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import Protocol

import numpy as np
from scipy.integrate import solve_ivp

from slidernet.errors import AvalancheError, TiltTestError
from slidernet.solver import Scene, horizontal_draws, realization_streams

# A node that slides this long (in tau_dyn) without its velocity ever returning
# to zero is sliding for ever: a single slip of the paper lasts pi tau_dyn.
MAX_SLIP_DURATION = 1000.0

# The dynamic tilt test (Dynamics.tilt_test, its loop EventLoop.tilt).
# While something moves, the tilt test integrates in phases of at most this many tau_dyn
# (one period of the stiffest node of a chain, 2 pi / sqrt(2), is shorter), checking
# between them whether the network slides for good.
TILT_CHUNK = 2.0 * math.pi
# The tilt test gives up after this many starts of motion, or one avalanche this long in
# tau_dyn without the proof that the network slides (a ramp makes it slide well before).
TILT_MAX_STARTS = 100_000
TILT_MAX_AVALANCHE = 1e5

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


class Integrator(Protocol):
    """What the event loop reads of its integrator, :class:`~slidernet.validation.dynamics.Dynamics`.

    Operators node-major (component c of node i at i d + c), in the units
    of the module :mod:`slidernet.validation.dynamics`.
    """

    scene: Scene
    tau_ratio: float
    max_step: float
    rtol: float
    atol: float
    method: str
    dim: int
    K: np.ndarray  # (N d, N d), dense
    g: np.ndarray  # (N d,)
    normal_load: np.ndarray  # (N,)
    w: np.ndarray  # (N,), normal_load / sum(normal_load)
    f_ext: np.ndarray  # (N d,)

    def modes(self) -> tuple[np.ndarray, np.ndarray]: ...

    def compliance(self) -> np.ndarray: ...


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


class EventLoop:
    """The state of one integrated realization and its event loop.

    Attributes: ``u`` (N d,) displacements in Ntilde l0, node-major; ``v``
    (N d,) velocities in Ntilde l0 per tau_dyn; ``moving`` (N,) bool;
    ``sigma`` (N d,) the unit direction of F_i when node i started: in 1D
    the sign of its motion; in 2D the direction of its friction while
    v_i = 0 (see the module's "How it is integrated"); ``t`` the time in
    tau_th; ``clock`` the time spent in motion, in tau_dyn (it also runs
    during the relaxation at t = 0, where theta is frozen).
    """

    def __init__(self, dyn: Integrator, thetas: np.ndarray, draws: ThresholdStream) -> None:
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
                # B holds the part along sigma_i, this the difference. Below STOP_SPEED (a node starting:
                # one that slows down to it stops there) the direction is sigma_i, the force's at the
                # start: there v_i / |v_i| is stiff (rate mu_d / |v_i|), and a node whose mu_s lies a hair
                # above mu_d crept for ever.
                v = y[m:]
                speed = np.repeat(node_norms(v, dim), dim)
                fast = speed >= STOP_SPEED
                out[m:] -= mu_d * np.where(fast, v / np.where(fast, speed, 1.0) - sig, 0.0)
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
        """The loop of :meth:`~slidernet.validation.dynamics.Dynamics.tilt_test`.

        theta is frozen (units of Ntilde) and the tilt f(s) = rate s along x.
        """
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
        (:meth:`~slidernet.validation.dynamics.Dynamics.tilt_test`).
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
