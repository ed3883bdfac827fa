"""The random streams of one realization, and the draws its horizontal evolution reads, in order."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from slidernet._validation import checked_output
from slidernet.plugins.distributions import TruncatedStream
from slidernet.solver.scene import Scene


def realization_streams(seed_seq: np.random.SeedSequence) -> dict[str, np.random.Generator]:
    """The independent random streams of one realization, in their documented order.

    ``seed_seq.spawn(3)`` gives, in order: the driver, the thresholds of the
    horizontal evolution, and the virtual tilt test's thresholds. The tilt
    test's uniforms, ``"tilt_uniforms"``, come from the first child of the
    tilt child (spawn key ``seed_seq.spawn_key + (2, 0)``): the tilt test reads
    thresholds and uniforms in proportions that depend on the state, so each
    kind needs a stream of its own for its values to be a function of the
    seed alone. The tilt test never touches the first two streams, so
    requesting ``mu_eff`` leaves n, mu_max and x_G unchanged to the bit. The
    same ``seed_seq`` always gives the same streams, even after it has been
    spawned from.

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
    children = pristine.spawn(3)
    streams = {name: np.random.Generator(np.random.PCG64(child))
               for name, child in zip(names, children, strict=True)}
    # Spawning from the tilt child leaves its own Generator (made above from its
    # entropy pool) as it always was: the tilt thresholds keep their stream.
    streams["tilt_uniforms"] = np.random.Generator(np.random.PCG64(children[2].spawn(1)[0]))
    return streams


def draw_thetas(scene: Scene, rng: np.random.Generator) -> np.ndarray:
    """theta(t_q) from the driver plugin, checked: shape (steps + 1,), finite."""
    thetas = checked_output(scene.driver.thetas(rng, scene.steps), (scene.steps + 1,), "driver",
                            scene.driver_name, f"thetas(rng, {scene.steps})")
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
