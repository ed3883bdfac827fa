"""Compiled draws of the built-in threshold laws, truncated below mu_d.

numba compiles the methods of ``numpy.random.Generator`` to the same code
numpy runs, so drawing one value at a time here gives the same bits, from
the same Generator (whose state advances in place), as the plugin's batched
``sample`` followed by the truncation of
:class:`~slidernet.plugins.distributions.TruncatedStream`: the accepted
values are the same sequence. The cost is what differs: for the Gaussian,
4.3 ns a draw against 15.1 ns through numpy's batched call, the filter and
the concatenation (``python benchmarks/bench_draws.py``, one core,
2026-11-24; the other laws gain less).

Only the laws whose single draws are numpy's batched draws to the bit are
here (``tests/test_draws.py`` checks each): Gaussian, uniform, Weibull and
exponential. The lognormal and Pareto laws pass their draws through
``numpy.exp``, which differs from the scalar ``exp`` in the last bit, so
they keep the batched path, as plugins do.
"""

from __future__ import annotations

from slidernet.kernels.jit import kernel_jit

# Law codes: x = the law's transformation of one Generator draw, with parameters (a, b, c).
GAUSSIAN = 1  # x = standard_normal() * a + b  (a = std, b = mean), as numpy's x *= std; x += mean
UNIFORM = 2  # x = uniform(a, b)  (a = low, b = high)
WEIBULL = 3  # x = a + b * weibull(c)  (a = loc, b = scale, c = shape)
EXPONENTIAL = 4  # x = a + b * standard_exponential()  (a = loc, b = scale)


@kernel_jit(forceinline=True)
def draw(rng, law, a, b, c):
    """One draw of law ``law`` from the Generator ``rng``."""
    if law == GAUSSIAN:
        return rng.standard_normal() * a + b
    if law == UNIFORM:
        return rng.uniform(a, b)
    if law == WEIBULL:
        return a + b * rng.weibull(c)
    return a + b * rng.standard_exponential()


@kernel_jit()
def fill_truncated(rng, out, law, a, b, c, lower):
    """Fill ``out`` (float64, shape (k,)) with the next k draws of the law that are > ``lower``.

    Returns the number of raw draws made (accepted and rejected).
    """
    raw = 0
    for k in range(out.size):
        x = draw(rng, law, a, b, c)
        raw += 1
        while not x > lower:
            x = draw(rng, law, a, b, c)
            raw += 1
        out[k] = x
    return raw
