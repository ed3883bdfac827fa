"""The random side of one realization: its streams, the draws its evolution reads in order, and their owner.

:class:`Streams` owns the Generators, the truncated threshold streams, the
draw buffers the kernels read and the rule that refills them;
:func:`realization_streams` and :func:`horizontal_draws` are the two steps
of the documented order that the validation tools reuse on their own.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from slidernet._validation import checked_output
from slidernet.errors import SnapshotError
from slidernet.kernels import NEED_MU, NEED_TILT, Draws
from slidernet.plugins.distributions import TruncatedStream
from slidernet.solver.scene import Scene
from slidernet.solver.snapshot import take


def realization_streams(seed_seq: np.random.SeedSequence) -> dict[str, np.random.Generator]:
    """The independent random streams of one realization, in their documented order.

    ``seed_seq.spawn(4)`` gives, in order: the driver, the thresholds of the
    horizontal evolution, the virtual tilt test's thresholds, and the
    slide-hold-slide pull's thresholds (``"shs"``, spawn key
    ``seed_seq.spawn_key + (3,)``, added last: spawning one more child leaves
    the first three as they were). The tilt test's uniforms,
    ``"tilt_uniforms"``, come from the first child of the tilt child (spawn
    key ``seed_seq.spawn_key + (2, 0)``): the tilt test reads thresholds and
    uniforms in proportions that depend on the state, so each kind needs a
    stream of its own for its values to be a function of the seed alone.
    Neither test touches the first two streams, nor the other's, so
    requesting ``mu_eff`` or ``mu_shs`` leaves n, mu_max and x_G unchanged to
    the bit. The same ``seed_seq`` always gives the same streams, even after
    it has been spawned from.

    Examples
    --------
    >>> ss = np.random.SeedSequence(1)
    >>> a = realization_streams(ss)["driver"].random()
    >>> a == realization_streams(ss)["driver"].random()
    True
    """
    names = ("driver", "thresholds", "tilt")
    # spawn() is stateful: a second call on the same SeedSequence gives other
    # children. Spawning from a pristine copy makes a realization a function
    # of its seed alone, however often that seed is used (reruns, comparisons).
    pristine = np.random.SeedSequence(seed_seq.entropy, spawn_key=seed_seq.spawn_key,
                                      pool_size=seed_seq.pool_size)
    children = pristine.spawn(4)
    streams = {name: np.random.Generator(np.random.PCG64(child))
               for name, child in zip(names, children[:3], strict=True)}
    # Spawning from the tilt child leaves its own Generator (made above from its
    # entropy pool) as it always was: the tilt thresholds keep their stream.
    streams["tilt_uniforms"] = np.random.Generator(np.random.PCG64(children[2].spawn(1)[0]))
    streams["shs"] = np.random.Generator(np.random.PCG64(children[3]))
    return streams


def draw_thetas(scene: Scene, rng: np.random.Generator, steps: int | None = None) -> np.ndarray:
    """theta(t_q) from the driver plugin, checked: shape (steps + 1,), finite.

    ``steps`` defaults to the scene's; fewer draw a sample of the run's driver (``solver.budget``).
    """
    steps = scene.steps if steps is None else int(steps)
    thetas = checked_output(scene.driver.thetas(rng, steps), (steps + 1,), "driver",
                            scene.driver_name, f"thetas(rng, {steps})")
    return thetas


def horizontal_draws(scene: Scene, rngs: dict[str, np.random.Generator],
                     stream: TruncatedStream | None = None) -> tuple[np.ndarray, np.ndarray, Iterator[np.ndarray]]:
    """The draws of a realization's horizontal evolution, in the order the solver reads them.

    The thresholds are the values of one :class:`TruncatedStream` on the
    thresholds Generator: the N initial ones, then one per slip. The batches
    only cut that sequence into pieces; their size never changes a value.

    Parameters
    ----------
    scene : Scene
        The scene.
    rngs : dict of str to Generator
        The realization's streams (:func:`realization_streams`).
    stream : TruncatedStream, optional
        The thresholds stream to read (the realization's own); by default a
        new one on ``rngs["thresholds"]``, which must then be untouched.

    Returns
    -------
    thetas : ndarray, shape (steps + 1,)
        theta(t_q) / Ntilde.
    mu : ndarray, shape (N,)
        The initial thresholds mu_s.
    batches : iterator of ndarray, each of shape (scene.batch,)
        The replacement thresholds, used one per slip, in order. Methods
        outside the solver (:mod:`slidernet.validation.dynamics`,
        :mod:`slidernet.validation.speed_error`) read them to run the same realization.
    """
    thetas = draw_thetas(scene, rngs["driver"]) / scene.network.Ntilde
    if stream is None:
        stream = TruncatedStream(scene.distribution, rngs["thresholds"])
    # A copy: the kernels write the current thresholds in place.
    mu = stream.take(scene.network.n_nodes).copy()

    def batches() -> Iterator[np.ndarray]:
        while True:
            yield stream.take(scene.batch)

    return thetas, mu, batches()


def _refill(buf: np.ndarray, pos: int, draw: Callable[[int], np.ndarray], batch: int) -> np.ndarray:
    """``buf`` from ``pos`` on, topped up with a new batch when fewer than ``batch`` remain.

    Keeping the unread tail makes the stream of draws the same whatever
    point the kernel stopped at. A buffer that still holds a batch is left
    alone: refilling it anyway would make it grow without bound (the tilt
    test's uniforms are read only in its rare creep branch).
    """
    if buf.size - pos >= batch:
        return buf[pos:]
    return np.concatenate([buf[pos:], draw(batch)])


class Streams:
    """The random side of one realization: its Generators, threshold streams, draw buffers and refill rule.

    As numpy gives a ``BitGenerator`` its ``state``, this object owns every
    piece of randomness a realization holds, and :meth:`snapshot` /
    :meth:`restore` carry all of it:

    - ``rngs``: the five Generators of :func:`realization_streams`;
    - ``truncated``: the three :class:`TruncatedStream` of accepted thresholds,
      ``"thresholds"`` (the horizontal evolution), ``"tilt"`` (the tilt
      tests) and ``"shs"`` (the slide-hold-slide pulls), each with its surplus;
    - ``buffers``: the draws waiting for the kernels
      (:class:`slidernet.kernels.Draws`: ``mu``, ``tilt_mu``, ``tilt_u``,
      ``shs_mu``);
    - the refill rule (:meth:`refill`).

    The read positions in the buffers (``mu_pos``, ``tilt_mu_pos``,
    ``tilt_u_pos``, ``shs_mu_pos``) belong to the realization's state record, which the
    kernels advance; :meth:`refill` reads them and sets them back to 0.

    Constructing it draws nothing; :meth:`start` draws theta(t_q), the
    initial thresholds and the first buffers, in the documented order.

    Parameters
    ----------
    scene : Scene
        The scene (its distribution, ``batch``, and whether it makes tilt tests).
    seed_seq : numpy.random.SeedSequence
        The realization's seed.

    Examples
    --------
    >>> from slidernet.config import load_config
    >>> scene = Scene.from_config(load_config({"network": {"Ntilde": 1e-7}, "steps": 3,
    ...     "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...     "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}}))
    >>> streams = Streams(scene, np.random.SeedSequence(1))
    >>> thetas, mu = streams.start()
    >>> thetas.shape, mu.shape, streams.buffers.mu.shape == (scene.batch,)
    ((4,), (2,), True)
    """

    def __init__(self, scene: Scene, seed_seq: np.random.SeedSequence) -> None:
        self.scene = scene
        self.rngs = realization_streams(seed_seq)
        # One stream of accepted thresholds per Generator that draws them: its
        # surplus is state, and where the kernels stop to refill, or how much
        # they ask for, never changes a value.
        self.truncated = {name: TruncatedStream(scene.distribution, self.rngs[name])
                          for name in ("thresholds", "tilt", "shs")}
        self.buffers = Draws(np.empty(0), np.empty(0), np.empty(0))

    def start(self) -> tuple[np.ndarray, np.ndarray]:
        """Draw theta(t_q) / Ntilde, shape (steps + 1,), and the initial thresholds, shape (N,); fill the buffers.

        The order is the documented one: the driver's thetas, the N initial
        thresholds, a batch of thresholds, then (with tilt tests) a batch of
        tilt thresholds and a batch of uniforms, and (with slide-hold-slide)
        a batch of its thresholds.
        """
        scene = self.scene
        thetas, mu, _ = horizontal_draws(scene, self.rngs, self.truncated["thresholds"])
        batch = scene.batch
        mu_batch = self.truncated["thresholds"].take(batch)
        if scene.tilt_at is not None:
            tilt = (self.truncated["tilt"].take(batch), self.rngs["tilt_uniforms"].random(batch))
        else:
            tilt = (np.empty(0), np.empty(0))
        shs = self.truncated["shs"].take(batch) if scene.shs_stiffness is not None else np.empty(0)
        self.buffers = Draws(mu_batch, *tilt, shs)
        return thetas, mu

    def refill(self, status: int, state: np.ndarray) -> bool:
        """Top up the buffer a kernel's ``status`` says ran out; False for any other status.

        ``NEED_MU``: the thresholds get the next batch of their stream;
        ``NEED_TILT``: the tilt test's buffers (:meth:`refill_tilt`). The
        read positions in ``state`` (the realization's record) are set back
        to 0. Where the kernel stopped never changes which values it reads next.
        """
        if status == NEED_MU:
            draw = self.truncated["thresholds"].take
            fresh = _refill(self.buffers.mu, state["mu_pos"][0], draw, self.scene.batch)
            self.buffers = self.buffers._replace(mu=fresh)
            state["mu_pos"] = 0
            return True
        if status == NEED_TILT:
            self.refill_tilt(state)
            return True
        return False

    def refill_tilt(self, state: np.ndarray) -> None:
        """Top up the tilt test's buffers after a pair's tilt test ran out of one of them.

        The pair's test (inside its kernel) starts again from its first draw
        after a refill; a network's test goes on where it stood
        (:meth:`extend_tilt`). The thresholds come from the tilt stream, the
        uniforms from ``rngs["tilt_uniforms"]`` (``random()`` takes one 64-bit
        word per value, so how it is cut into calls changes nothing). Each
        kind is thus read in an order set by the seed alone, and this rule
        only decides how many values wait in the buffers: a buffer with fewer
        than ``batch`` unread draws gets a batch. If both still held a batch,
        one test needed more than that (a long creep): both grow, so that the
        retry gets further.
        """
        batch, st, buf = self.scene.batch, state[0], self.buffers
        unread = min(buf.tilt_mu.size - st["tilt_mu_pos"], buf.tilt_u.size - st["tilt_u_pos"])
        # Doubling when both held a batch keeps the retries logarithmic in the test's length.
        size = batch if unread < batch else 2 * max(buf.tilt_mu.size, buf.tilt_u.size)
        self.buffers = buf._replace(
            tilt_mu=_refill(buf.tilt_mu, st["tilt_mu_pos"], self.truncated["tilt"].take, size),
            tilt_u=_refill(buf.tilt_u, st["tilt_u_pos"], self.rngs["tilt_uniforms"].random, size),
        )
        state["tilt_mu_pos"] = 0
        state["tilt_u_pos"] = 0

    def extend_tilt(self, state: np.ndarray, reading: tuple[int, int]) -> tuple[int, int]:
        """Lengthen the tilt buffers under a network tilt test that ran out of draws; its new read positions.

        The test has read the buffers from the realization's positions
        (``state``'s ``tilt_mu_pos``, ``tilt_u_pos``) up to ``reading`` =
        (p_mu, p_u), and goes on from there
        (:func:`slidernet.kernels.tilt_net.tilt_test_network`). The values it
        has read stay in the buffers until it ends, so that a test stopped
        half-way is made again from the same draws. A buffer with fewer than
        ``batch`` values after its reading position gets as many new draws as
        it holds from the realization's position on, and at least a batch:
        doubling keeps the returns of a long test logarithmic in its length,
        and only the buffer that ran out grows (the uniforms are read by the
        pair's creep rule alone). Values read before the realization's
        position are dropped, both positions moving back with them.
        """
        p_mu, p_u = self._extend(state, (("tilt_mu", self.truncated["tilt"].take, reading[0]),
                                         ("tilt_u", self.rngs["tilt_uniforms"].random, reading[1])))
        return p_mu, p_u

    def extend_shs(self, state: np.ndarray, reading: int) -> int:
        """Lengthen the slide-hold-slide buffer under a pull that ran out of draws; its new read position.

        The rule of :meth:`extend_tilt`, for the one buffer the pull reads
        (``shs_mu``, from the ``shs`` stream; the realization's position
        ``shs_mu_pos``).
        """
        (p_mu,) = self._extend(state, (("shs_mu", self.truncated["shs"].take, reading),))
        return p_mu

    def _extend(self, state: np.ndarray, plan: tuple[tuple[str, Callable[[int], np.ndarray], int], ...]
                ) -> list[int]:
        """Each buffer of ``plan`` (name in :class:`Draws`, its stream, the test's reading position in it) with
        fewer than ``batch`` values after its reading grown as :meth:`extend_tilt` says; the new positions."""
        batch, st, buf = self.scene.batch, state[0], self.buffers
        grown = {}
        new_reading = []
        for name, stream, at in plan:
            key = f"{name}_pos"  # the realization's read position, a field of the state record
            values, start = getattr(buf, name), int(st[key])
            if values.size - at < batch:
                kept = values[start:]
                grown[name] = np.concatenate([kept, stream(max(batch, kept.size))])
                state[key] = 0
                at -= start
            new_reading.append(int(at))
        self.buffers = buf._replace(**grown)
        return new_reading

    def snapshot(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """The streams' state: JSON values (``rngs``: each Generator's ``bit_generator.state``) and arrays
        (``buffers/<name>``, float64 (k,); ``surplus/<name>``, float64 (k,), the threshold streams' surplus)."""
        header = {"rngs": {name: rng.bit_generator.state for name, rng in self.rngs.items()}}
        arrays = {f"buffers/{name}": values for name, values in self.buffers._asdict().items()}
        arrays.update({f"surplus/{name}": stream.surplus for name, stream in self.truncated.items()})
        return header, arrays

    def restore(self, header: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Overwrite the streams' state with a :meth:`snapshot` of the same realization.

        Raises
        ------
        SnapshotError
            If a Generator, a buffer or a surplus is missing or malformed.
        """
        rngs = header.get("rngs")
        if not isinstance(rngs, dict) or set(rngs) != set(self.rngs):
            raise SnapshotError(f"is inconsistent: its streams are {sorted(rngs or [])}, a realization's are "
                                f"{sorted(self.rngs)}")
        self.buffers = Draws(*(np.array(take(arrays, f"buffers/{name}", dtype=np.float64, ndim=1), order="C")
                               for name in Draws._fields))
        saved = {key.removeprefix("surplus/") for key in arrays if key.startswith("surplus/")}
        if saved != set(self.truncated):
            raise SnapshotError(f"is inconsistent: its threshold streams are {sorted(saved)}, a realization's are "
                                f"{sorted(self.truncated)}")
        for name, stream in self.truncated.items():
            try:
                stream.restore(take(arrays, f"surplus/{name}", dtype=np.float64, ndim=1))
            except ValueError as exc:
                raise SnapshotError(f"is inconsistent: {exc}") from None
        for name, rng in self.rngs.items():
            # In place: the threshold streams hold these very Generators.
            rng.bit_generator.state = rngs[name]
