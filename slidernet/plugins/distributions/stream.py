"""The thresholds' stream: the draws of a :class:`TruncatedBelow` law in an order set by the seed alone.

The solver reads every mu_s through a :class:`TruncatedStream`, which asks
the plugin for a fixed number of draws at a time (:data:`RAW_CHUNK`) and
keeps the accepted ones it has not handed out yet, so that the values never
depend on ``solver.batch``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from slidernet.kernels import draws
from slidernet.plugins.distributions.law import TruncatedBelow

# Raw draws asked of a plugin at a time by TruncatedStream. Fixed, so that the
# accepted values never depend on solver.batch or on how many are asked for:
# 2**16 is the default batch, so at the default settings, without rejections,
# a refill costs one plugin call as before (a plugin's per-call overhead,
# e.g. scipy's rvs, stays amortised), and a chunk is 512 KiB of float64.
RAW_CHUNK = 1 << 16


class TruncatedStream:
    """The draws of a :class:`TruncatedBelow` law from one Generator, in an order set by the seed alone.

    The plugin is always called with the same number of draws,
    :data:`RAW_CHUNK`, whatever is asked for; the draws at or below ``lower``
    are dropped (:meth:`TruncatedBelow.accepted`), and the accepted draws
    that a call of :meth:`take` does not hand out are kept for the next one
    (the *surplus*). The values handed out by ``take(k1)``, ``take(k2)``, ...
    are therefore the filtered raw chunks laid end to end, a function of the
    Generator's initial state alone: asking one at a time or 65536 at a time
    gives the same bits. Its state is the Generator's state plus
    :attr:`surplus` (what :mod:`slidernet.io.checkpoint` saves).

    Nothing is drawn before the first :meth:`take`. For a plugin whose
    ``sample`` is prefix-consistent (``sample(rng, a)`` then ``sample(rng, b)``
    gives the first ``a + b`` values of ``sample(rng, a + b)``, as numpy's
    normal, uniform and exponential draws are) and no rejection, the values
    are those of plain successive ``sample`` calls.

    Parameters
    ----------
    dist : TruncatedBelow
        The law (its plugin, truncation point and checks).
    rng : numpy.random.Generator
        The stream it owns: nothing else may draw from it, or the order of
        the values would depend on who drew when.

    Examples
    --------
    >>> import numpy as np
    >>> from slidernet.plugins.distributions import Gaussian
    >>> law = TruncatedBelow(Gaussian(0.6, 0.1), lower=0.5, name="gaussian")
    >>> one = TruncatedStream(law, np.random.default_rng(1))
    >>> many = TruncatedStream(law, np.random.default_rng(1))
    >>> small = np.concatenate([one.take(1) for _ in range(100)])
    >>> bool((small == many.take(100)).all()), bool((small > 0.5).all())
    (True, True)
    >>> one.surplus.size == many.surplus.size
    True
    """

    def __init__(self, dist: TruncatedBelow, rng: np.random.Generator) -> None:
        self.dist = dist
        self.rng = rng
        self._surplus = np.empty(0)
        # A built-in law with compiled draws is drawn one value at a time: the same values, with
        # no surplus, about 4 times faster (slidernet.kernels.draws).
        self._compiled = dist.compiled_law() if isinstance(dist, TruncatedBelow) else None

    @property
    def surplus(self) -> np.ndarray:
        """The accepted draws not yet handed out, in order; float64, shape ``(k,)``, read-only."""
        view = self._surplus.view()
        view.flags.writeable = False
        return view

    def take(self, size: int) -> np.ndarray:
        """The next ``size`` accepted draws of the stream.

        Parameters
        ----------
        size : int
            Number of values, >= 0.

        Returns
        -------
        numpy.ndarray
            Values strictly above ``dist.lower`` (dimensionless, like mu_s),
            float64, shape ``(size,)``, C-contiguous; the stream never
            reads or writes them again.

        Raises
        ------
        ValueError
            If ``size`` is negative.
        PluginError
            As :meth:`TruncatedBelow.accepted`.
        """
        size = int(size)
        if size < 0:
            raise ValueError(f"The 'size' parameter of TruncatedStream.take must be >= 0. Got {size} instead.")
        if self._compiled is not None and not self._surplus.size:
            out = np.empty(size)
            draws.fill_truncated(self.rng, out, *self._compiled, self.dist.lower)
            return out
        parts = [self._surplus] if self._surplus.size else []
        have = self._surplus.size
        while have < size:
            fresh = self.dist.accepted(self.rng, RAW_CHUNK)
            parts.append(fresh)
            have += fresh.size
        pool = np.concatenate(parts) if len(parts) > 1 else (parts[0] if parts else self._surplus)
        # No copy: the caller's values and the surplus are disjoint parts of one buffer.
        out = pool[:size]
        self._surplus = pool[size:]
        return out

    def restore(self, surplus: ArrayLike) -> None:
        """Replace the surplus, e.g. with one saved by a checkpoint (the Generator's state is the caller's).

        Raises
        ------
        ValueError
            If ``surplus`` is not a 1-D float64 array of finite values above ``dist.lower``.
        """
        arr = np.asarray(surplus)
        if arr.dtype != np.float64 or arr.ndim != 1:
            raise ValueError(f"the surplus of a threshold stream must be a 1-D float64 array, "
                             f"not {arr.dtype}{arr.shape}")
        if arr.size and not (np.isfinite(arr).all() and arr.min() > self.dist.lower):
            raise ValueError(f"the surplus of a threshold stream holds values that are not finite "
                             f"and > mu_d = {self.dist.lower!r}")
        self._surplus = arr.copy()

    def __repr__(self) -> str:
        return f"TruncatedStream({self.dist!r}, surplus={self._surplus.size})"
