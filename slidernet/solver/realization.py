"""The quasi-static, event-driven solver: from a validated config to raw records.

Data flow for one realization (see ARCHITECTURE.md)::

    SeedSequence child r --spawn(4)--> [driver, thresholds, tilt, shs]; tilt --spawn(1)--> [tilt_uniforms]
    driver.thetas(rng_driver, steps)      -> theta(t_q), q = 0..steps
    TruncatedStream(dist, rng_thresholds) -> initial mu_s, then one per slip, handed out in batches
    kernel (pair, csr or vec)             -> records at the recorded times

No time stepping: within each linear segment of theta the kernel jumps from
one rearrangement to the next by solving eq. `critique` exactly.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from slidernet import kernels
from slidernet.errors import AvalancheError, SnapshotError, TiltTestError
from slidernet.kernels.tilt_net import TILT_LOADS
from slidernet.plugins.distributions import TruncatedStream
from slidernet.solver.backends import backend_for
from slidernet.solver.creep import creep_record
from slidernet.solver.inject import injected_thresholds
from slidernet.solver.scene import Scene, tilt_avalanche_cap
from slidernet.solver.snapshot import Snapshot, check_fingerprint, digest, scene_fingerprint, take
from slidernet.solver.streams import Streams

# Series fields a scene does not record, as the kernels take them (0-length arrays, never written).
_NOTHING = {"mu_mean": np.empty(0), "mu_min": np.empty(0), "y_G": np.empty(0), "contact_age": np.empty(0),
            "contact_age_count": np.zeros((0, kernels.N_AGE_BINS), np.int64)}

# The attributes of a Realization that a snapshot carries, and those the constructor rebuilds (and why that
# is exact). A new attribute must join one of the two: snapshot() refuses a realization holding another.
_SAVED = {"state", "mu", "out", "streams", "backend", "_tilted"}
_REBUILT = {
    "scene": "passed to the constructor; its fingerprint is checked",
    "series": "the kernels' view of out: the same arrays, restored in place",
    "thetas": "redrawn by the constructor from the driver stream; its digest is checked",
    "_tilt_work": "scratch arrays of the network tilt test, reset by every test",
    "_shs_work": "scratch arrays of the slide-hold-slide pull, reset by every pull",
    "_dynamic_loads": "the loads of the last dynamic tilt test ([dynamics] tilt_rate), reset by every test",
}

#: A stop request, polled where a kernel returns to refill a buffer: True asks the realization to stop there.
StopCheck = Callable[[], bool]


class Realization:
    """One realization: its random streams, its state and its records.

    Constructing it draws theta(t_q) and the initial thresholds; work happens
    in :meth:`advance`. Between calls the state is fully relaxed (every node
    stable), which the property tests check through :meth:`forces`.

    Every value drawn is a function of ``seed_seq`` alone, never of
    ``solver.batch`` (which only sets how many values wait in the kernels'
    buffers) nor of where the kernels stop. The five streams of
    :func:`realization_streams` are read in this order:

    1. ``driver``: ``driver.thetas(rng, steps)``, once.
    2. ``thresholds``: a :class:`~slidernet.plugins.distributions.TruncatedStream`
       (``draws["thresholds"]``): the plugin's ``sample(rng, RAW_CHUNK)``
       called again and again with the fixed size ``RAW_CHUNK``, the values
       at or below mu_d dropped, the rest laid end to end (built-in laws with
       compiled draws, :mod:`slidernet.kernels.draws`, give the same values
       one at a time). The first N values are the initial thresholds (node
       order), then one value per slip, in the order of the slips.
    3. ``tilt``: another ``TruncatedStream`` (``draws["tilt"]``), the same way:
       the thresholds the tilt tests redraw, in the order the tests (one
       after the other) read them.
    4. ``tilt_uniforms``: ``rng.random()``, one value per creep branch of a
       tilt test (the uniform force of the appendix), in the order the tests
       read them.
    5. ``shs``: a third ``TruncatedStream`` (``draws["shs"]``): the
       thresholds the slide-hold-slide pulls redraw, one per slip but the
       last of each pull, in the order the pulls read them.

    The tilt test reads thresholds and uniforms in proportions that depend
    on the state, so each kind has its own stream; buffers of either may be
    topped up at any time without changing what the other reads.

    Parameters
    ----------
    scene : Scene
        The scene, shared by all realizations.
    seed_seq : numpy.random.SeedSequence
        This realization's own seed (a child of the run's seed).
    """

    def __init__(self, scene: Scene, seed_seq: np.random.SeedSequence) -> None:
        self.scene = scene
        # The random side has one owner: Generators, threshold streams, buffers and their refill rule.
        self.streams = Streams(scene, seed_seq)
        self.thetas, self.mu = self.streams.start()
        T = scene.out_steps.size
        self.out = {
            "n": np.zeros(T, np.int64),
            "mu_max": np.zeros(T),
            "x_G": np.zeros(T),
            "n_records": np.zeros(T, np.int64),
            "f_sum": np.zeros(T),
            "f_sq": np.zeros(T),
            "f_count": np.zeros(T, np.int64),
        }
        if scene.contact_age:
            self.out.update(contact_age=np.zeros(T), contact_age_count=np.zeros((T, kernels.N_AGE_BINS), np.int64))
        if scene.tilt_loads:
            self.out.update({name: np.full(T, np.nan) for name in TILT_LOADS})
        if scene.counts_capped:
            self.out["tilt_capped"] = np.zeros(T, np.int64)
        if scene.shs_stiffness is not None:
            # NaN where no pull was made: the recorded times after the network slid away.
            self.out.update(mu_shs=np.full(T, np.nan), shs_travel=np.full(T, np.nan))
        self.out.update(_more_tilt_records(scene, T))
        self._tilted = 0  # recorded times whose network tilt test (and slide-hold-slide pull) is done
        self._tilt_work: tuple[kernels.Heaps, np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
        self._dynamic_loads: dict[str, float] | None = None
        self._shs_work: tuple[kernels.Heaps, np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
        self.state = kernels.new_state()
        self.state["theta"] = self.thetas[0]
        self.state["u"] = self.thetas[0]  # the spring at rest at theta(0): u = theta(0)
        self.state["mu_max"] = self.mu.max()
        self.state["argmax"] = int(np.argmax(self.mu))
        # The kernel's own state; the backend is the only part that knows which kernel runs.
        self.backend = backend_for(scene, self)
        self.out.update(self.backend.records(T))
        # The kernels' view of the records: the same arrays, 0-length where the scene records nothing.
        self.series = kernels.Series(**{name: self.out[name] if name in self.out else _NOTHING[name]
                                        for name in kernels.Series._fields})

    @property
    def rngs(self) -> dict[str, np.random.Generator]:
        """The realization's Generators by name (``driver``, ``thresholds``, ``tilt``, ``tilt_uniforms``,
        ``shs``)."""
        return self.streams.rngs

    @property
    def draws(self) -> dict[str, TruncatedStream]:
        """The truncated threshold streams by name (``thresholds``, ``tilt``, ``shs``)."""
        return self.streams.truncated

    @property
    def buffers(self) -> kernels.Draws:
        """The draws waiting for the kernels (``mu``, ``tilt_mu``, ``tilt_u``, ``shs_mu``)."""
        return self.streams.buffers

    def recompute_forces(self) -> float:
        """Recompute a = -K u - g theta(0) + f_ext from the displacements (a sparse product with K).

        Incremental updates of ``a`` accumulate rounding; this resets it and
        rebuilds the heaps. The pair kernel keeps no force: it forms
        F = theta - u afresh at every use, so there is nothing to reset and
        no drift, and this returns 0.0 there.

        Returns
        -------
        float
            The largest change of a force, in N (the drift that had accumulated).
        """
        return self.backend.recompute(self)

    @property
    def step(self) -> int:
        """The number of thermal steps done so far."""
        return int(self.state["q"][0])

    @property
    def n(self) -> int:
        """Cumulative number of rearrangements."""
        return int(self.state["n_slips"][0])

    @property
    def thresholds(self) -> np.ndarray:
        """Current mu_s of every node, shape (N,)."""
        return self.mu.copy()

    @property
    def theta(self) -> float:
        """Current dilation theta (dimensionless)."""
        return float(self.state["theta"][0] * self.scene.network.Ntilde)

    @property
    def x_G(self) -> float:
        """Current centre-of-mass displacement, in l0."""
        return float(self.state["x_G"][0] * self.scene.network.Ntilde)

    def forces(self) -> np.ndarray:
        """Spring forces on every node, in units of N, shape (N,) in 1D or (N, 2) in 2D."""
        return self.backend.forces(self)

    def displacements(self) -> np.ndarray:
        """Displacements u of the nodes from their reference positions, in l0, shape (N, d)."""
        return self.scene.network.Ntilde * self.backend.displacements(self)

    def advance(self, to_step: int | None = None, *, stop: StopCheck | None = None) -> Realization:
        """Run the thermal steps up to ``to_step`` (default: the last one).

        With ``mu_eff_at = "records"`` the network tilt test is made on the
        state at every recorded time passed on the way, and with the
        observable ``mu_shs`` the slide-hold-slide pull (:meth:`shs_test`).

        Parameters
        ----------
        to_step : int, optional
            The step to reach, in [``step``, ``scene.steps``].
        stop : callable, optional
            Asked each time a kernel returns to refill a buffer (every
            ``solver.batch`` slips at most, and at every event-catalogue
            chunk): once it returns True, the realization stops there, at a
            clean point between two slips, possibly within a thermal step,
            and ``advance`` returns with ``step < to_step``. A
            :meth:`snapshot` taken then resumes to the same bits.
        """
        scene = self.scene
        if self.slid_away:
            return self  # the realization ended when it slid away
        to_step = scene.steps if to_step is None else int(to_step)
        if not self.step <= to_step <= scene.steps:
            raise ValueError(f"to_step must lie in [{self.step}, {scene.steps}]; got {to_step}")
        if scene.tilt_at == "records" or scene.shs_stiffness is not None:
            while self._tilted < scene.out_steps.size and scene.out_steps[self._tilted] <= to_step:
                if not self._run_kernel(int(scene.out_steps[self._tilted]), stop):
                    return self  # stopped before the recorded time: no tilt test of a state in between
                if self.slid_away:
                    return self  # no tilt test of a sliding network: mu_eff_count stays 0 from here on
                if scene.tilt_at == "records":
                    self._tilt_record(self._tilted)
                if scene.shs_stiffness is not None:
                    self._shs_record(self._tilted)
                self._tilted += 1
        self._run_kernel(to_step, stop)
        return self

    @property
    def slid_away(self) -> bool:
        """True once the network slid away (docs/model.md, 'Sliding away'): the realization is over."""
        return bool(self.state["slid_away"][0])

    def tilt_test(self, mu: np.ndarray | None = None, *, advance: bool = True) -> float:
        """One network tilt test on a copy of the current state: mu_eff, the load at which it slides.

        Raises the uniform tangential force f N_i along +x on every node until
        the whole network slides (see :mod:`slidernet.kernels.tilt_net` for the
        rule, which is the appendix's for a 1D pair) and returns the total
        tangential load per unit normal load at that moment, f plus the mean
        f_ext along x. The state is left as it was; the draws come from the
        realization's tilt stream. With ``[dynamics] tilt_rate`` the test is
        the dynamic one, the load ramped at that rate under the equations of
        motion (:mod:`slidernet.solver.inertia_tilt`).

        Parameters
        ----------
        mu : ndarray of float64, shape (N,), optional
            The thresholds to test, which the test overwrites (default: a
            copy of the realization's; :meth:`tested_thresholds`).
        advance : bool
            True: the tilt stream goes on after the draws this test read.
            False: it stays where it was, so that the next test reads the
            same draws (the injected twin of ``[tilt] inject``).
        """
        from slidernet.kernels import tilt_net

        scene = self.scene
        mu = self.mu.copy() if mu is None else mu
        st = self.state
        if scene.dynamics is not None and scene.dynamics.tilt_rate is not None:
            from slidernet.solver.inertia_tilt import dynamic_tilt

            f, self._dynamic_loads, p_mu = dynamic_tilt(self.backend, self, mu, scene.dynamics.tilt_rate)
            if advance:
                st["tilt_mu_pos"] = p_mu
            return f
        self._dynamic_loads = None
        o = scene.tilt_operators()
        N = scene.network.n_nodes
        (heaps, epoch, count, pos, loads), G = self._test_work("_tilt_work")
        pos[:] = 0
        pos[tilt_net.P_MU], pos[tilt_net.P_U] = st["tilt_mu_pos"][0], st["tilt_u_pos"][0]
        settings = scene.settings()
        cap = tilt_avalanche_cap(N)
        while True:
            buffers = self.buffers
            f = o.test(G, mu, o.f_ext, o.f_bar, o.net, settings, o.pair_rule, buffers.tilt_mu, buffers.tilt_u, pos,
                       cap, heaps, epoch, count, loads)
            status = kernels.tilt_status(f)
            if status == kernels.DONE:
                if advance:
                    st["tilt_mu_pos"], st["tilt_u_pos"] = pos[tilt_net.P_MU], pos[tilt_net.P_U]
                return float(f)
            if status != kernels.NEED_TILT:
                raise TiltTestError(self._tilt_stop_reason(pos, float(loads[tilt_net.L_F] + o.f_bar), cap))
            # The test stands where it ran out: longer buffers, and it goes on from there.
            pos[tilt_net.P_MU], pos[tilt_net.P_U] = self.streams.extend_tilt(
                st, (int(pos[tilt_net.P_MU]), int(pos[tilt_net.P_U])))

    def _test_work(self, name: str) -> tuple[tuple[kernels.Heaps, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
                                             np.ndarray]:
        """What a test on a copy of the state starts from: its scratch arrays (the attribute ``name``, made on
        first use: heaps, epoch, count, pos, loads) and the forces G, shape (N, 2), 1D padded with zeros."""
        from slidernet.kernels import tilt_net

        N = self.scene.network.n_nodes
        if getattr(self, name) is None:
            setattr(self, name, (kernels.Heaps.empty(2, N), np.zeros(N, np.int64), np.zeros(N, np.int64),
                                 np.zeros(tilt_net.N_POS, np.int64), np.zeros(tilt_net.N_LOADS)))
        F = self.forces().reshape(N, -1)
        G = np.zeros((N, 2))
        G[:, : F.shape[1]] = F
        return getattr(self, name), G

    def shs_test(self, mu: np.ndarray | None = None, *, advance: bool = True) -> tuple[float, float]:
        """One slide-hold-slide pull on a copy of the current state: mu_shs, and the stage's travel at the peak.

        A stage moving quasi-statically along +x pulls every node i through a
        spring of stiffness gamma N_i <k> (``[shs] stiffness`` = gamma, <k> the
        mean spring stiffness) until every node has slipped at least once; the
        sample is the peak of the stage force per unit normal load, plus the
        mean f_ext along x (docs/model.md, "Slide-hold-slide";
        :mod:`slidernet.kernels.tilt_net` for the rule). The state is left as it
        was; the draws come from the realization's ``shs`` stream.

        Parameters
        ----------
        mu : ndarray of float64, shape (N,), optional
            The thresholds the pull starts from, which it overwrites (default:
            a copy of the realization's, the contacts as the hold left them;
            :meth:`tested_thresholds`).
        advance : bool
            True: the ``shs`` stream goes on after the draws this pull read.
            False: it stays where it was, so that the next pull reads the same
            draws (the injected twin of ``[tilt] inject``).

        Returns
        -------
        mu_shs : float
            The peak load per unit normal load.
        travel : float
            The stage's travel X from the start of the pull to that peak, in l0.
        """
        from slidernet.kernels import tilt_net

        scene = self.scene
        o = scene.shs_operators()
        (heaps, epoch, count, pos, loads), G = self._test_work("_shs_work")
        mu = self.mu.copy() if mu is None else mu
        st = self.state
        pos[:] = 0
        pos[tilt_net.P_MU] = st["shs_mu_pos"][0]
        settings = scene.settings()
        while True:
            end = o.test(G, mu, o.f_ext, o.f_bar, o.net, settings, self.buffers.shs_mu, pos, heaps, epoch, count,
                         loads, o.pull)
            status = kernels.tilt_status(end)
            if status == kernels.DONE:
                if advance:
                    st["shs_mu_pos"] = pos[tilt_net.P_MU]
                return float(loads[tilt_net.L_PEAK]), float(loads[tilt_net.L_TRAVEL] * scene.network.Ntilde)
            if status != kernels.NEED_TILT:
                slips = int(pos[tilt_net.N_SLIPS])
                why = (f"it reached solver.max_avalanche = {scene.max_avalanche} slips in all. A genuinely long "
                       "pull needs a larger solver.max_avalanche." if pos[tilt_net.STOP] == tilt_net.STOP_SLIPS
                       else "a slip of the exactly integrated 2D motion (solver.slip = 'exact') did not come to "
                            "rest within its step budget.")
                raise TiltTestError(f"The slide-hold-slide pull did not renew every contact at step {self.step}: "
                                    f"after {slips} slips, " + why)
            # The pull stands where it ran out: a longer buffer, and it goes on from there.
            pos[tilt_net.P_MU] = self.streams.extend_shs(st, int(pos[tilt_net.P_MU]))

    def _tilt_stop_reason(self, pos: np.ndarray, load: float, cap: int) -> str:
        """The message of a network tilt test that gave up (``pos[STOP]`` of the kernel says why)."""
        from slidernet.kernels import tilt_net

        scene = self.scene
        slips = int(pos[tilt_net.N_SLIPS])
        head = (f"The network tilt test did not reach sliding at step {self.step}: after {slips} slips, at a load "
                f"per unit normal load of {load!r}, ")
        why = int(pos[tilt_net.STOP])
        if why == tilt_net.STOP_SLIPS:
            return head + (f"it reached solver.max_avalanche = {scene.max_avalanche} slips in all. A genuinely "
                           "long test needs a larger solver.max_avalanche.")
        if why == tilt_net.STOP_PART:
            return head + (f"one avalanche passed {cap} slips without setting every node in motion, with the load "
                           f"still at or below mu_d = {scene.mu_d!r}: a part of the network creeps on its own.")
        return head + ("a slip of the exactly integrated 2D motion (solver.slip = 'exact') did not come to rest "
                       "within its step budget.")

    def refill(self, status: int) -> bool:
        """Top up the draw buffer a kernel's ``status`` says ran out; False for any other status.

        The rule is the streams' (:meth:`Streams.refill
        <slidernet.solver.streams.Streams.refill>`): where the kernel
        stopped never changes which values it reads next.
        """
        return self.streams.refill(status, self.state)

    def tested_thresholds(self, k: int, injected: bool) -> np.ndarray:
        """A copy of the thresholds that a test at recorded time ``k`` reads, shape (N,).

        ``injected``: raised by ``[tilt] inject`` at t = ``scene.out_steps[k]``
        (:func:`~slidernet.solver.inject.injected_thresholds`); else the
        realization's own. The realization's thresholds are left as they are.
        """
        if not injected:
            return self.mu.copy()
        if self.scene.inject is None:
            raise ValueError("this scene injects nothing ([tilt] inject is not set)")
        return injected_thresholds(self.mu, self.backend.last_slip(self), float(self.scene.out_steps[k]),
                                   self.scene.inject)

    def _tilt_record(self, k: int) -> None:
        """The network tilt tests at recorded time ``k``: ``[tilt] repeats`` of them, each with its injected twin
        under ``[tilt] inject``."""
        plain, injected = [], []
        for _ in range(self.scene.tilt_repeats):
            if self.scene.inject is not None:
                # The twin first, leaving the stream where it was: the plain test then reads the same draws
                # and moves the stream on exactly as in a run without injection.
                try:
                    injected.append(self._one_tilt_test(self.tested_thresholds(k, True), advance=False))
                except TiltTestError as exc:
                    raise TiltTestError(f"The injected twin ([tilt] inject) of a test: {exc}") from None
            plain.append(self._one_tilt_test(self.tested_thresholds(k, False), advance=True))
        self._store_tilt_tests(k, plain, "")
        if injected:
            self._store_tilt_tests(k, injected, "_injected")

    def _one_tilt_test(self, mu: np.ndarray, advance: bool) -> tuple[float, bool, dict[str, float]]:
        """(sample, met the avalanche cap before the [tilt] rule, the loads of :data:`TILT_LOADS`) of one network
        tilt test on the thresholds ``mu``."""
        from slidernet.kernels.tilt_net import STOP, STOP_CAP

        f = self.tilt_test(mu, advance=advance)
        if self._dynamic_loads is not None:
            return f, False, self._dynamic_loads
        _, _, _, pos, loads = self._tilt_work
        return (f, self.scene.counts_capped and pos[STOP] == STOP_CAP,
                {name: float(loads[slot]) for name, slot in TILT_LOADS.items()})

    def _store_tilt_tests(self, k: int, tests: list[tuple[float, bool, dict[str, float]]], suffix: str) -> None:
        """Add the tests at recorded time ``k`` to the records named with ``suffix`` ("" or "_injected")."""
        out = self.out
        sampled = [f for f, capped, _ in tests if not capped]
        if self.scene.counts_capped:
            # The avalanche cap's samples, not the stricter rule's: counted, never pooled into mu_eff as the
            # rule's.
            out["tilt_capped" + suffix][k] += len(tests) - len(sampled)
        for f in sampled:
            out["f_sum" + suffix][k] += f
            out["f_sq" + suffix][k] += f * f
            out["f_count" + suffix][k] += 1
        if "mu_eff_spread" + suffix in out and len(sampled) > 1:
            out["mu_eff_spread" + suffix][k] = np.std(sampled, ddof=1)
        if self.scene.tilt_loads:
            for name in TILT_LOADS:
                out[name + suffix][k] = _mean_of_events([loads[name] for _, _, loads in tests])

    def _shs_record(self, k: int) -> None:
        """The slide-hold-slide pull at recorded time ``k``, after its injected twin under ``[tilt] inject``."""
        if self.scene.inject is not None:
            # The twin first, leaving the shs stream where it was, as the tilt test's twin does the tilt stream's.
            try:
                self.out["mu_shs_injected"][k], _ = self.shs_test(self.tested_thresholds(k, True), advance=False)
            except TiltTestError as exc:
                raise TiltTestError(f"The injected twin ([tilt] inject) of a pull: {exc}") from None
        self.out["mu_shs"][k], self.out["shs_travel"][k] = self.shs_test(self.tested_thresholds(k, False))

    def _run_kernel(self, to_step: int, stop: StopCheck | None) -> bool:
        """Run the kernel to ``to_step``; False if ``stop`` asked it to stop first (see :meth:`advance`)."""
        scene = self.scene
        # The kernel stops at the end of the array it is given.
        thetas = self.thetas[: to_step + 1]
        st = self.state
        while True:
            status = self.backend.run(self, thetas)
            if status == kernels.DONE:
                return True
            if status == kernels.SLID_AWAY:
                # The kernel has held the records left at the state of the slide; the realization
                # is over, at its last step for whoever advances it.
                st["q"] = scene.steps
                return True
            if self.refill(status):
                pass
            elif status == kernels.RECOMPUTE:
                self.recompute_forces()
            elif status == kernels.NEED_EVENTS:
                self.backend.flush_events(self)
            elif status == kernels.AVALANCHE_LIMIT:
                i = int(st["err_node"][0])
                force = np.round(np.atleast_1d(self.forces()[i]), 12).tolist()
                raise AvalancheError(
                    f"An avalanche did not end after {scene.max_avalanche} slips "
                    f"(solver.max_avalanche), or a slip did not come to rest, during step "
                    f"{self.step}: node {i} is unstable with F = {force} N, "
                    f"mu_s = {float(self.mu[i])!r}, theta = {self.theta!r}. "
                    + ("A load f_ext that friction cannot hold makes the network (or a floppy part of it, "
                       "such as a row of a square lattice) slide for ever: lower f_ext. "
                       if self.scene.network.f_ext.any() else "")
                    + "A genuinely long avalanche needs a larger solver.max_avalanche."
                )
            elif status == kernels.TILT_LIMIT:
                raise TiltTestError(
                    f"The tilt test did not reach sliding within {kernels.TILT_MAX_ITER} "
                    f"iterations at step {self.step}."
                )
            else:  # pragma: no cover - a new status code without a handler is a bug
                raise RuntimeError(f"unknown kernel status {status}")
            # Every return but DONE comes within solver.batch slips (a refill) or a catalogue chunk: a
            # loop that runs long, in one thermal step or not, sees the request here.
            if stop is not None and stop():
                return False

    def snapshot(self) -> Snapshot:
        """The whole state of the realization, as JSON values and named numeric arrays.

        Take it between two calls of :meth:`advance` (a clean point, even
        one where ``stop`` left it within a thermal step).
        :meth:`restore` on a realization built from the same scene and seed
        then gives the bits an uninterrupted run gives. The keys are listed
        in :mod:`slidernet.solver.snapshot`. The arrays are the
        realization's own, not copies: store them before advancing again.

        Raises
        ------
        RuntimeError
            If the realization holds an attribute that is neither saved nor
            rebuilt (a new piece of state this method does not know).
        """
        unknown = sorted(set(vars(self)) - _SAVED - set(_REBUILT))
        if unknown:
            raise RuntimeError(
                f"The realization holds {unknown} that Realization.snapshot neither saves nor rebuilds; add "
                "each to realization._SAVED (and save it) or to realization._REBUILT."
            )
        streams_header, streams_arrays = self.streams.snapshot()
        header = {"scene": scene_fingerprint(self.scene), "thetas": digest(self.thetas), **streams_header,
                  "tilted": int(self._tilted), "step": self.step, "n": self.n}
        arrays = {f"state/{name}": self.state[name][0] for name in kernels.STATE.names}
        arrays["mu"] = self.mu
        arrays.update(streams_arrays)
        arrays.update({f"out/{name}": values for name, values in self.out.items()})
        own = self.backend.snapshot(self)
        arrays.update({f"backend/{name}": np.asarray(values) for name, values in own.items()})
        return Snapshot(header, arrays)

    def restore(self, snapshot: Snapshot) -> None:
        """Overwrite the state with ``snapshot``, taken of a realization of the same scene and seed.

        Call it on a realization just constructed; :meth:`advance` then goes
        on from the snapshot's step.

        Raises
        ------
        SnapshotError
            If the snapshot was taken in another scene (its fingerprint), with
            other theta(t_q) (another seed or driver), or lacks or misshapes
            a piece of state; the message names which.
        """
        header, arrays = snapshot.header, snapshot.arrays
        check_fingerprint(header.get("scene"), self.scene)
        if header.get("thetas") != digest(self.thetas):
            raise SnapshotError(
                "was saved with other theta(t_q) for this seed: the driver (or its input file, or numpy) has "
                "changed, or this is another realization's seed"
            )
        if "tilted" not in header:
            raise SnapshotError("is inconsistent: its header has no 'tilted'")
        # In place: the kernels get arrays of exactly the layout and dtype they were compiled for.
        for name in kernels.STATE.names:
            self.state[name] = take(arrays, f"state/{name}", dtype=kernels.STATE[name], ndim=0)
        self.mu[...] = take(arrays, "mu", self.mu)
        saved_out = {key.removeprefix("out/") for key in arrays if key.startswith("out/")}
        if saved_out != set(self.out):
            raise SnapshotError(f"is inconsistent: its records are {sorted(saved_out)}, this scene's are "
                                f"{sorted(self.out)}")
        for name, target in self.out.items():
            target[...] = take(arrays, f"out/{name}", target)
        # After the state: the backend reads the catalogue's write position from it.
        own = {key.removeprefix("backend/"): a for key, a in arrays.items() if key.startswith("backend/")}
        self.backend.restore(self, own)
        self._tilted = int(header["tilted"])
        self.streams.restore(header, arrays)

    def events(self) -> dict[str, np.ndarray]:
        """The event catalogue so far: one row per slip, in the order of the slips.

        Returns
        -------
        dict of str to ndarray, each of shape (S,), S the number of catalogued slips
            ``time`` (tau_th: q plus the fraction of the thermal step at the
            driving event), ``node`` (int64), ``avalanche`` (int64: the number
            of driving events so far; 0 for the relaxation of an initial
            overload at t = 0), ``dx`` and ``dy`` (the node's displacement, in
            l0; ``dy`` is 0 in 1D).
        """
        return self.backend.events(self)

    def result(self) -> dict[str, np.ndarray]:
        """The records at ``scene.out_steps`` (x_G converted to l0).

        Returns
        -------
        dict of str to ndarray
            ``n``, ``n_records`` (int64), ``mu_max``, ``x_G`` (in l0) of shape
            (T,), the tilt-test sums ``f_sum``, ``f_sq``, ``f_count`` per
            record bin, shape (T,) (under a stricter sliding rule, ``tilt_capped``:
            the tests that met the avalanche cap first, which these leave out;
            with ``[tilt] repeats`` > 1, ``mu_eff_spread``; with ``[tilt] inject``,
            the same of the injected twins, named ``*_injected``), with the
            observable ``mu_shs`` its pull's peak and the stage's travel there (l0),
            ``mu_shs`` and ``shs_travel`` (NaN after the network slid away),
            and the scalar ``n_events``; where the
            scene can slide away (``scene.records_slide``), the scalar
            ``slid_away_at`` (tau_th; NaN if it did not); the backend's
            own (``backend.result``), and with the observable
            ``creep`` those of :func:`slidernet.solver.creep.creep_record`.
        """
        res = {k: v.copy() for k, v in self.out.items()}
        Ntilde = self.scene.network.Ntilde
        res["x_G"] *= Ntilde
        if "y_G" in res:
            res["y_G"] *= Ntilde
        res["n_events"] = np.int64(self.state["n_events"][0])
        if self.scene.inject is not None:  # what the *_injected records hold: (c, t0, select)
            inj = self.scene.inject
            res["inject"] = np.array([inj.c, inj.t0, inj.select], np.float64)
        if self.scene.records_slide:
            res["slid_away_at"] = np.float64(self.state["slid_away_at"][0] if self.slid_away else np.nan)
        res.update(self.backend.result(self))
        scene = self.scene
        if scene.creep is not None:
            res.update(creep_record(res["events"], res["events_complete"], scene.steps, scene.creep))
        if scene.catalogue and not scene.keep_events:
            # Kept for the creep observables only: the rows stay out of the records.
            del res["events"], res["events_complete"]
        return res


def _more_tilt_records(scene: Scene, T: int) -> dict[str, np.ndarray]:
    """The records of ``[tilt] repeats`` (``mu_eff_spread``) and of ``[tilt] inject`` (the injected twins' sums,
    and their loads and cap counts where the plain tests have them; ``mu_shs_injected`` where the pull runs),
    shape (T,) each."""
    out: dict[str, np.ndarray] = {}
    if scene.tilt_repeats > 1:
        out["mu_eff_spread"] = np.full(T, np.nan)
    if scene.inject is not None and scene.shs_stiffness is not None:
        out["mu_shs_injected"] = np.full(T, np.nan)
    if scene.inject is not None and scene.tilt_at == "records":
        out.update(f_sum_injected=np.zeros(T), f_sq_injected=np.zeros(T), f_count_injected=np.zeros(T, np.int64))
        if scene.tilt_loads:
            out.update({name + "_injected": np.full(T, np.nan) for name in TILT_LOADS})
        if scene.counts_capped:
            out["tilt_capped_injected"] = np.zeros(T, np.int64)
    return out


def _mean_of_events(loads: list[float]) -> float:
    """The mean of a record's loads over its tests where the event happened (NaN: in none); one test's load as
    it is."""
    seen = [x for x in loads if not np.isnan(x)]
    return math.fsum(seen) / len(seen) if seen else math.nan


def simulate(scene: Scene, seed_seq: np.random.SeedSequence) -> dict[str, np.ndarray]:
    """Run one whole realization; see :meth:`Realization.result` for the records."""
    return Realization(scene, seed_seq).advance().result()
