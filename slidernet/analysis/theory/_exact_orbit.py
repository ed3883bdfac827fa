"""The exact creep orbit of a chain of sliders on an incline, followed slip by slip in rational arithmetic.

The machinery behind :mod:`~slidernet.analysis.theory.creep_chain`, its
only user: ``_Affine`` (the exact form a + b p), ``_Window`` (the interval of
p on which every comparison made so far comes out the same) and
``_chain_orbit`` (the orbit from rest until its cycle repeats). It shares
with :mod:`~slidernet.analysis.theory.creep_pair` the units and the solver's
slip rule below, and imports nothing from the rest of the theory.

Two sliders have a closed form
(:mod:`~slidernet.analysis.theory.creep_pair`); from three on, the interior
sliders slip with an overshoot -- an end slip hands D to its neighbour,
which can then sit above mu_s and slip by 2(|F| - mu_d) / 2, a length that
depends on f -- and the orbit has no short formula. It is still exact and
finite: with constant thresholds each slip is an affine map of the forces,
the choice of which slider slips next is a comparison of affine forms, and
a symmetric cycle of theta from rest settles into an exactly periodic
sequence of slips (after at most one cycle for three sliders; from four on
the transient can be long, and some orbits never repeat: chain_orbit's
docstring has the numbers). _chain_orbit follows that sequence in
rational arithmetic, with f and A / Ntilde affine in one parameter p, and
records every comparison it makes: the set of p where all of them go the
same way is an interval, on which the steady velocity is one affine
function of p. That is the derivation of the plateaus (of the slip
sequence) and of the values and ends of v on each, for any chain.

Units as for two sliders: forces in N, theta and lengths in Ntilde (k = 1).
The force on slider i is F_i = f + s_i - s_{i-1}, with s_e the tension of spring e
(between sliders e and e + 1); a rise of theta by d theta lengthens every
rest length and so lowers every tension by d theta; a slip of slider i by
du = 2 (|F_i| - mu_d) sign(F_i) / deg(i) (the solver's rule, K_ii =
deg(i) k) moves s_i by -du and s_{i-1} by +du.
"""

from __future__ import annotations

from fractions import Fraction

from slidernet.errors import OrbitError


class _Affine:
    """The exact affine form ``a + b p`` of one parameter p."""

    __slots__ = ("a", "b")

    def __init__(self, a: Fraction, b: Fraction = Fraction(0)) -> None:
        self.a, self.b = a, b

    def __add__(self, other: _Affine | Fraction) -> _Affine:
        if isinstance(other, _Affine):
            return _Affine(self.a + other.a, self.b + other.b)
        return _Affine(self.a + other, self.b)

    def __sub__(self, other: _Affine | Fraction) -> _Affine:
        if isinstance(other, _Affine):
            return _Affine(self.a - other.a, self.b - other.b)
        return _Affine(self.a - other, self.b)

    def __rsub__(self, other: Fraction) -> _Affine:
        return _Affine(other - self.a, -self.b)

    def __mul__(self, c: Fraction | int) -> _Affine:
        return _Affine(self.a * c, self.b * c)

    def key(self) -> tuple[Fraction, Fraction]:
        return self.a, self.b


class _Window:
    """The values of p around ``p0`` where every comparison made so far comes out the same.

    ``positive(e)`` answers e(p0) > 0 and narrows [lo, hi] to where e keeps
    that sign; a form that vanishes at p0 pins the window to p0 (a tie of
    two events: the orbit on either side differs).
    """

    def __init__(self, p0: Fraction, lo: Fraction, hi: Fraction) -> None:
        self.p0, self.lo, self.hi = p0, lo, hi

    def positive(self, e: _Affine) -> bool:
        value = e.a + e.b * self.p0
        if e.b != 0:
            root = -e.a / e.b
            if value == 0:
                self.lo = self.hi = self.p0
            elif (value > 0) == (e.b > 0):
                self.lo = max(self.lo, root)
            else:
                self.hi = min(self.hi, root)
        return value > 0


def _chain_orbit(n: int, f: _Affine, x: _Affine, mu_s: Fraction, mu_d: Fraction, window: _Window,
                 max_cycles: int) -> tuple[int, int, _Affine, int]:
    """Follow n sliders from rest under theta / Ntilde = 0 -> x -> -x -> 0 -> ... until the cycle repeats.

    Returns (period in cycles, slips per period, advance of x_G per period
    in Ntilde l0, cycles of transient), the last two valid across ``window``.
    """
    zero = _Affine(Fraction(0))
    s = [zero] * (n - 1)
    u = [zero] * n
    theta = zero
    deg = [1 if i in (0, n - 1) else 2 for i in range(n)]

    def force(i: int) -> _Affine:
        F = f
        if i < n - 1:
            F = F + s[i]
        if i > 0:
            F = F - s[i - 1]
        return F

    def slip(i: int, F: _Affine, sign: int) -> None:
        du = (F * sign - mu_d) * Fraction(2 * sign, deg[i])
        u[i] = u[i] + du
        if i < n - 1:
            s[i] = s[i] - du
        if i > 0:
            s[i - 1] = s[i - 1] + du

    def most_overloaded() -> tuple[int, _Affine, int] | None:
        # The solver's avalanche rule: the largest |F_i| / mu_s first, ties to the lowest index.
        best: tuple[int, _Affine, int] | None = None
        for i in range(n):
            F = force(i)
            sign = 1 if window.positive(F) else -1
            if window.positive(F * sign - mu_s) and (
                    best is None or window.positive(F * sign - best[1] * best[2])):
                best = (i, F, sign)
        return best

    def drive(target: _Affine) -> int:
        nonlocal theta, s
        d = 1 if window.positive(target - theta) else -1
        slips = 0
        while True:
            # Only the two ends feel theta: a rise pushes the last slider forward
            # and the first one back (an interior slider's two springs cancel).
            h_best: tuple[_Affine, int, int] | None = None
            for i, sign in ((0, -d), (n - 1, d)):
                F = force(i)
                h = (mu_s - F) if sign > 0 else (F + mu_s)
                if h_best is None or window.positive(h_best[0] - h):
                    h_best = (h, i, sign)
            assert h_best is not None
            h, i, sign = h_best
            if window.positive(h - (target - theta) * d):
                s = [e - (target - theta) for e in s]
                theta = target
                return slips
            s = [e - h * d for e in s]
            theta = theta + h * d
            slip(i, force(i), sign)
            slips += 1
            while (over := most_overloaded()) is not None:
                slip(*over)
                slips += 1

    seen: dict[tuple, int] = {}
    x_G: list[_Affine] = []
    slips_in: list[int] = []
    for cycle in range(max_cycles + 1):
        state = tuple(e.key() for e in s)
        centre = zero
        for ui in u:
            centre = centre + ui
        centre = centre * Fraction(1, n)
        if state in seen:
            first = seen[state]
            return cycle - first, sum(slips_in[first:]), centre - x_G[first], first
        seen[state] = cycle
        x_G.append(centre)
        slips_in.append(drive(x) + drive(zero - x) + drive(zero))
    at = window.p0
    raise OrbitError(f"The creep orbit of {n} sliders did not repeat within max_cycles = {max_cycles} cycles "
                     f"(tan_alpha = {float(f.a + f.b * at)!r}, A / Ntilde = {float(x.a + x.b * at)!r}): "
                     "it may be aperiodic, as some orbits of four sliders and more are; raise max_cycles to look "
                     "further.")

