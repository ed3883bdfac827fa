"""One phase of the motion of a 1D network with inertia, solved exactly: the modes, the events, their search.

The pieces of :mod:`slidernet.kernels.inertia` that solve a phase; the
units and the equations are that module's (u in Ntilde l0, theta in Ntilde,
forces in N, K in k0, local time s in tau_dyn).

**A phase** is a stretch of time in which the set M of moving nodes and
their signs do not change and theta is linear in s (inside one driver
step): theta = theta_0 + r s. Stuck nodes are exactly fixed, so with
y = u_M - u_M(0) the motion is the linear system

    N_M y'' = -K_MM y + b + c s,    b = F_M(0) - mu_d N_M sigma_M,    c = r g_M,

y(0) = 0, y'(0) = v_M(0). With the generalized modes of (K_MM, N_M),
K_MM phi_k = lambda_k N_M phi_k, phi_k^T N_M phi_k = 1 (from the symmetric
N^-1/2 K_MM N^-1/2 = Q diag(lambda) Q^T by Jacobi rotations, phi = N^-1/2 Q),
the modal amplitudes a = phi^T N_M y obey a_k'' = -lambda_k a_k + beta_k +
gamma_k s (beta = phi^T b, gamma = phi^T c), so that

    a_k(s) = a'_k(0) C1 + beta_k C2 + gamma_k C3,   a'_k = a'_k(0) C0 + beta_k C1 + gamma_k C2,

with C0 = cos(w s), C1 = sin(w s) / w, C2 = (1 - cos w s) / lambda,
C3 = (s - sin(w s) / w) / lambda, w = sqrt(lambda) (:func:`basis`; their
Taylor series near lambda s^2 = 0, a rigid mode included). Each C_{n+1} is
the integral of C_n from 0, which is how the work of the drive is integrated.

**Events** end a phase: a moving node's velocity returns to zero (the root
of sigma_i v_i(s), falling), a stuck node's |F_j(s)| reaches mu_s,j N_j
(rising), or the end of the driver step. A lone moving node (one mode) has
its stop in closed form: sigma v(s) = P cos(w s) + Q sin(w s) + R; a stuck
neighbour of a lone node that no drive pushes sees F_j = c + A cos(w s - phi),
whose start is in closed form too. A stuck node that no moving node touches
sees a force linear in s (closed form). The other stuck nodes are first
bounded over the phase (each modal amplitude is at most |P_k| + |R_k| s +
hypot(U_k, V_k)); only those that the bound cannot clear, and the stops of a
moving segment of several nodes, are watched (:func:`watch`): from each
sample the next is as far as every watched function surely keeps its sign,
from its value, its slope and a bound on its curvature (:func:`safe_step`),
but at least ``SAMPLE`` / w_max tau_dyn (well below the shortest period
2 pi / w_max); a function that the step could carry across zero is checked
on the interval for a sign change and, from its slopes at the ends, for an
extremum that dips through zero inside it (:func:`crossing`); the root is
then polished by a bracketed Newton iteration to a few ulps of s. Stuck
nodes never move; only their thresholds are watched. The modes of a moving
set are computed once and cached under its bit mask (:func:`modes`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from slidernet.kernels.jit import kernel_jit

# The helpers are inlined (forceinline=True): numba passes every array of a named tuple as arguments of
# its own (about 200 for Work), so that a call cost more than a lone slip's arithmetic. Inlining them took
# the pair from 1.1 to 0.38 us per slip and a chain of 4 from 3 to 1.5 (tau_ratio = 1e-4, sigma_theta /
# Ntilde = 10, a loaded 2-core host, 2026-11-28).

# The watch's sampling step, in 1 / w_max tau_dyn (w_max the highest modal frequency): 1/5 of a radian,
# 31 samples per shortest period; at most MAX_SAMPLE tau_dyn where every mode is (nearly) rigid.
SAMPLE = 0.2
MAX_SAMPLE = 0.2
# Below this lambda s^2 the basis functions are summed from their Taylor series (to the x^6 term: the
# first term left out is below 1e-16 of the sum).
TAYLOR = 0.25

EPS = 2.220446049250313e-16  # float64's machine epsilon

# What ended a phase.
NO_EVENT, STOP, START = range(3)


class Work(NamedTuple):
    """Scratch of one phase, sized for N nodes: ``M`` the moving nodes, ``W`` the watched stuck ones
    (``where`` maps a node to its place in M, -1 - its place in W, or N when in neither); ``Kmm`` (N, N)
    K_MM then its rotations, ``Q`` (N, N) the modes, ``KWM`` (N, N) the rows K_WM and ``kphi`` (N, N)
    their products K_WM phi_k with the modes; per mode ``lam``, ``ap0``, ``beta``, ``gamma``; per moving
    node ``rootN`` = sqrt(N_i), ``F0``, ``y``, ``yv``, ``ya``, ``yint``; per watched node ``FW``, ``dW``
    (its drive) and ``watch`` (1: sampled); ``ev`` (6, 2 N) the event functions of the search (values and
    slopes at two samples, curvature bounds, safe steps); the cache of the modes of recurring moving sets
    (:func:`modes`): ``cache_key`` (C,) bit masks (0: empty), ``cache_Q`` (C, N, N), ``cache_lam`` (C, N)."""

    M: np.ndarray
    W: np.ndarray
    where: np.ndarray
    Kmm: np.ndarray
    Q: np.ndarray
    KWM: np.ndarray
    kphi: np.ndarray
    lam: np.ndarray
    ap0: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray
    rootN: np.ndarray
    F0: np.ndarray
    y: np.ndarray
    yv: np.ndarray
    ya: np.ndarray
    yint: np.ndarray
    FW: np.ndarray
    dW: np.ndarray
    watch: np.ndarray
    ev: np.ndarray
    cache_key: np.ndarray
    cache_Q: np.ndarray
    cache_lam: np.ndarray




def new_work(n: int) -> Work:
    """Scratch for a network of ``n`` nodes, with a cache of modes of at most 16 MiB (none above 62 nodes)."""
    f = np.zeros
    C = 0
    if n <= 62:
        C = 1024
        while C > 16 and C * n * n * 8 > 1 << 24:
            C //= 2
    return Work(M=np.zeros(n, np.int64), W=np.zeros(n, np.int64), where=np.full(n, n, np.int64),
                Kmm=f((n, n)), Q=f((n, n)), KWM=f((n, n)), kphi=f((n, n)), lam=f(n), ap0=f(n), beta=f(n),
                gamma=f(n), rootN=f(n), F0=f(n), y=f(n), yv=f(n), ya=f(n), yint=f(n), FW=f(n), dW=f(n),
                watch=np.zeros(n, np.int64),
                ev=f((6, 2 * n)), cache_key=np.zeros(C, np.int64), cache_Q=f((C, n, n)), cache_lam=f((C, n)))


@kernel_jit(forceinline=True)
def basis(lam, s):
    """(C0, C1, C2, C3, C4) at s for a mode of eigenvalue ``lam`` (per tau_dyn^2): C0 = cos(w s) and each
    C_{n+1} the integral from 0 of C_n; Taylor series below lambda s^2 = TAYLOR (a rigid mode: 1, s, s^2 / 2, ...).
    """
    x = lam * s * s
    if abs(x) < TAYLOR:
        s2 = s * s
        c0 = 1.0 - x / 2.0 * (1.0 - x / 12.0 * (1.0 - x / 30.0 * (1.0 - x / 56.0 * (1.0 - x / 90.0 * (
            1.0 - x / 132.0)))))
        c1 = s * (1.0 - x / 6.0 * (1.0 - x / 20.0 * (1.0 - x / 42.0 * (1.0 - x / 72.0 * (1.0 - x / 110.0 * (
            1.0 - x / 156.0))))))
        c2 = s2 / 2.0 * (1.0 - x / 12.0 * (1.0 - x / 30.0 * (1.0 - x / 56.0 * (1.0 - x / 90.0 * (
            1.0 - x / 132.0 * (1.0 - x / 182.0))))))
        c3 = s2 * s / 6.0 * (1.0 - x / 20.0 * (1.0 - x / 42.0 * (1.0 - x / 72.0 * (1.0 - x / 110.0 * (
            1.0 - x / 156.0 * (1.0 - x / 210.0))))))
        c4 = s2 * s2 / 24.0 * (1.0 - x / 30.0 * (1.0 - x / 56.0 * (1.0 - x / 90.0 * (1.0 - x / 132.0 * (
            1.0 - x / 182.0 * (1.0 - x / 240.0))))))
        return c0, c1, c2, c3, c4
    w = math.sqrt(lam)
    ws = w * s
    sn = math.sin(ws)
    cs = math.cos(ws)
    if cs < 0.5:
        c2 = (1.0 - cs) / lam  # 1 - cos >= 1/2: no cancellation
    else:
        half = math.sin(0.5 * ws)
        c2 = 2.0 * half * half / lam  # (1 - cos) / lambda without cancellation
    c3 = (s - sn / w) / lam
    return cs, sn / w, c2, c3, (0.5 * s * s - c2) / lam


@kernel_jit(forceinline=True)
def force(net, f_ext, u, j, dtheta):
    """F_j = f_ext,j - (K u)_j + g_j (theta - theta(0)), in N (``dtheta`` = theta - theta(0), in Ntilde)."""
    F = f_ext[j] + net.g[j] * dtheta
    for p in range(net.indptr[j], net.indptr[j + 1]):
        F -= net.K_data[p] * u[net.indices[p]]
    return F



@kernel_jit(forceinline=True)
def rotate(X, p, q, c, s, m, columns):
    """Rotate columns p and q of X[:m, :m] (``columns``) or its rows p and q by the angle of (c, s):
    x_p, x_q -> c x_p - s x_q, s x_p + c x_q."""
    for k in range(m):
        if columns:
            xp = X[k, p]
            xq = X[k, q]
            X[k, p] = c * xp - s * xq
            X[k, q] = s * xp + c * xq
        else:
            xp = X[p, k]
            xq = X[q, k]
            X[p, k] = c * xp - s * xq
            X[q, k] = s * xp + c * xq


@kernel_jit()
def jacobi_eigh(A, V, lam, m):
    """The eigen-decomposition of the symmetric m x m block of A by cyclic Jacobi rotations.

    A is overwritten (diagonalized); on return V[:m, :m] holds the orthonormal eigenvectors in columns and
    lam[:m] the eigenvalues. Rotations continue until the off-diagonal part is below 1e-32 of the diagonal's
    (squared norms): eigenvalues and vectors to rounding.
    """
    for i in range(m):
        for k in range(m):
            V[i, k] = 0.0
        V[i, i] = 1.0
    for _sweep in range(100):
        off = 0.0
        diag = 0.0
        for p in range(m):
            diag += A[p, p] * A[p, p]
            for q in range(p + 1, m):
                off += A[p, q] * A[p, q]
        if off <= 1e-32 * diag or off == 0.0:
            break
        for p in range(m - 1):
            for q in range(p + 1, m):
                apq = A[p, q]
                if apq == 0.0:
                    continue
                th = (A[q, q] - A[p, p]) / (2.0 * apq)
                t = 1.0 / (abs(th) + math.sqrt(th * th + 1.0))
                if th < 0.0:
                    t = -t
                c = 1.0 / math.sqrt(t * t + 1.0)
                s = t * c
                rotate(A, p, q, c, s, m, True)
                rotate(A, p, q, c, s, m, False)
                rotate(V, p, q, c, s, m, True)
    for k in range(m):
        lam[k] = A[k, k]


@kernel_jit()
def modes(wk, m):
    """The modes (wk.Q, wk.lam) of the m x m matrix in wk.Kmm, through the cache of the moving sets.

    A moving set recurs (the ends of a chain, the same segment): its modes are kept under the bit mask of
    M (networks of at most 62 nodes) in a table of ``cache_key.size`` entries (open addressing, 4 probes,
    a miss overwrites the first probe). A hit copies what Jacobi computed from the same K_MM: the same
    numbers to the bit, so the cache changes no result.
    """
    C = wk.cache_key.size
    slot = -1
    if C > 0:
        key = 0
        for p in range(m):
            key |= 1 << wk.M[p]
        h = (key * -7046029254386353131) >> 17  # Fibonacci hashing, 2^64 / golden ratio
        for probe in range(4):
            c = (h + probe) & (C - 1)
            if wk.cache_key[c] == key:
                for p in range(m):
                    wk.lam[p] = wk.cache_lam[c, p]
                    for k in range(m):
                        wk.Q[p, k] = wk.cache_Q[c, p, k]
                return
            if wk.cache_key[c] == 0 and slot < 0:
                slot = c
        if slot < 0:
            slot = h & (C - 1)
        wk.cache_key[slot] = key
    jacobi_eigh(wk.Kmm, wk.Q, wk.lam, m)
    if slot >= 0:
        for p in range(m):
            wk.cache_lam[slot, p] = wk.lam[p]
            for k in range(m):
                wk.cache_Q[slot, p, k] = wk.Q[p, k]


@kernel_jit(forceinline=True)
def modal_state(wk, m, s, integral):
    """y, y' and y'' of the m moving nodes at s into wk.y, wk.yv, wk.ya (with ``integral``, also the integral
    of y from 0 to s into wk.yint, for the work of the drive)."""
    for p in range(m):
        wk.y[p] = 0.0
        wk.yv[p] = 0.0
        wk.ya[p] = 0.0
        wk.yint[p] = 0.0
    for k in range(m):
        lam = wk.lam[k]
        c0, c1, c2, c3, c4 = basis(lam, s)
        a = wk.ap0[k] * c1 + wk.beta[k] * c2 + wk.gamma[k] * c3
        av = wk.ap0[k] * c0 + wk.beta[k] * c1 + wk.gamma[k] * c2
        aa = -lam * wk.ap0[k] * c1 + wk.beta[k] * c0 + wk.gamma[k] * c1
        ai = wk.ap0[k] * c2 + wk.beta[k] * c3 + wk.gamma[k] * c4
        for p in range(m):
            phi = wk.Q[p, k] / wk.rootN[p]
            wk.y[p] += phi * a
            wk.yv[p] += phi * av
            wk.ya[p] += phi * aa
            if integral:
                wk.yint[p] += phi * ai


@kernel_jit(forceinline=True)
def event_value(wk, mo, m, e, s):
    """The event function e at s and its derivative: e < m, sigma v of moving node M[e] (a stop where it
    falls through 0); e >= m, |F_j| - mu_s,j N_j of watched node j = W[e - m] (a start where it rises
    through 0). One pass over the modes: F_j = F_j(0) + d_j s - sum_k (K_jM phi_k) a_k (wk.kphi)."""
    r = e - m
    x0 = 0.0
    x1 = 0.0
    for k in range(m):
        lam = wk.lam[k]
        c0, c1, c2, c3, _ = basis(lam, s)
        if e < m:
            phi = wk.Q[e, k] / wk.rootN[e]
            x0 += phi * (wk.ap0[k] * c0 + wk.beta[k] * c1 + wk.gamma[k] * c2)
            x1 += phi * (-lam * wk.ap0[k] * c1 + wk.beta[k] * c0 + wk.gamma[k] * c1)
        else:
            kphi = wk.kphi[r, k]
            x0 += kphi * (wk.ap0[k] * c1 + wk.beta[k] * c2 + wk.gamma[k] * c3)
            x1 += kphi * (wk.ap0[k] * c0 + wk.beta[k] * c1 + wk.gamma[k] * c2)
    if e < m:
        sg = mo.sig[wk.M[e]]
        return sg * x0, sg * x1
    F = wk.FW[r] + wk.dW[r] * s - x0
    dF = wk.dW[r] - x1
    j = wk.W[r]
    if F >= 0.0:
        return F - mo.lim[j], dF
    return -F - mo.lim[j], -dF


@kernel_jit(forceinline=True)
def root(wk, mo, m, e, lo, hi, f_lo, f_hi, df_hi):
    """The root of event function e in [lo, hi], where it changes sign (f(lo) = ``f_lo``; f and f' at hi are
    ``f_hi``, ``df_hi``, already known): bracketed Newton from hi, bisecting where a step would leave the
    bracket, to a few ulps of s."""
    x = hi
    for it in range(200):
        if hi - lo <= 4.0 * EPS * hi:
            break
        if it == 0:
            f, fp = f_hi, df_hi
        else:
            f, fp = event_value(wk, mo, m, e, x)
        if f == 0.0:
            return x
        if (f > 0.0) == (f_lo > 0.0):
            lo = x
            f_lo = f
        else:
            hi = x
        nx = x - f / fp if fp != 0.0 else 0.5 * (lo + hi)
        if not (lo < nx < hi):
            nx = 0.5 * (lo + hi)
        elif abs(nx - x) <= 2.0 * EPS * x:
            return nx  # Newton has converged to an ulp or two, from one side
        x = nx
    return hi


@kernel_jit(forceinline=True)
def crossing(wk, mo, m, e, a, b, fa, dfa, fb, dfb):
    """The first root of event function e in [a, b] in its direction (stops fall, starts rise), or -1.

    A sign change is bracketed at once. Without one, f'(a) and f'(b) that bracket an extremum toward zero
    (a minimum of a stop function, a maximum of a start function) are followed to it by bisection on f';
    if the extremum crosses, the root lies between a and it. Before that, the extremum is bounded from the
    two ends with the curvature bound B = wk.ev[4, e]: g = sgn f >= g(a) + g'(a) t - B t^2 / 2 and >=
    g(b) - g'(b) (L - t) - B (L - t)^2 / 2 (t = s - a, L = b - a); where the two bounds meet above zero,
    g never reaches it.
    """
    sgn = 1.0 if e < m else -1.0  # the function is on the side sgn f > 0 before its event
    if sgn * fa > 0.0 and sgn * fb <= 0.0:
        return root(wk, mo, m, e, a, b, fa, fb, dfb)
    if sgn * fa > 0.0 and sgn * dfa < 0.0 and sgn * dfb > 0.0:
        ga, da, gb, db = sgn * fa, sgn * dfa, sgn * fb, sgn * dfb
        L = b - a
        B = wk.ev[4, e]
        t = min(max((ga - gb + db * L + 0.5 * B * L * L) / (db - da + B * L), 0.0), L)
        if ga + da * t - 0.5 * B * t * t > 0.0:
            return -1.0
        lo, hi = a, b
        for _it in range(200):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            f, fp = event_value(wk, mo, m, e, mid)
            if sgn * f <= 0.0:
                return root(wk, mo, m, e, a, mid, fa, f, fp)
            if sgn * fp < 0.0:
                lo = mid
            else:
                hi = mid
    return -1.0


@kernel_jit(forceinline=True)
def lone_stop(wk, mo, s_max):
    """The stop of a lone moving node (mode 0), in closed form, or inf where it comes after ``s_max``.

    sigma v(s) = P cos(w s) + Q sin(w s) + R with P = sigma (v0 - gamma / lambda) / rootN, Q = sigma beta /
    (w rootN), R = sigma gamma / (lambda rootN): its first falling root is w s = phi + acos(-R / A), phi =
    atan2(Q, P), A = hypot(P, Q), taken modulo 2 pi to the first positive one; then a Newton step.
    """
    lam = wk.lam[0]
    if lam <= 0.0:
        return -1.0  # no spring: the sampled search
    w = math.sqrt(lam)
    sg = mo.sig[wk.M[0]]
    rn = wk.rootN[0]
    P = sg * (wk.ap0[0] - wk.gamma[0] / lam) / rn
    Q = sg * wk.beta[0] / (w * rn)
    R = sg * wk.gamma[0] / (lam * rn)
    A = math.hypot(P, Q)
    if A == 0.0 or R >= A:
        return math.inf
    ratio = -R / A
    if ratio < -1.0:
        ratio = -1.0
    x = math.atan2(Q, P) + math.acos(ratio)
    while x <= 0.0:
        x += 2.0 * math.pi
    while x - 2.0 * math.pi > 0.0:
        x -= 2.0 * math.pi
    s = x / w
    if s > s_max:
        return math.inf
    f, fp = event_value(wk, mo, 1, 0, s)
    if fp != 0.0:
        s -= f / fp
    return s


@kernel_jit(forceinline=True)
def event_values(wk, mo, m, nw, s, row):
    """Every event function and its derivative at s into wk.ev[row] and wk.ev[row + 1] (see event_value)."""
    modal_state(wk, m, s, False)
    for e in range(m):
        sg = mo.sig[wk.M[e]]
        wk.ev[row, e] = sg * wk.yv[e]
        wk.ev[row + 1, e] = sg * wk.ya[e]
    for r in range(nw):
        F = wk.FW[r] + wk.dW[r] * s
        dF = wk.dW[r]
        for p in range(m):
            F -= wk.KWM[r, p] * wk.y[p]
            dF -= wk.KWM[r, p] * wk.yv[p]
        if F >= 0.0:
            wk.ev[row, m + r] = F - mo.lim[wk.W[r]]
            wk.ev[row + 1, m + r] = dF
        else:
            wk.ev[row, m + r] = -F - mo.lim[wk.W[r]]
            wk.ev[row + 1, m + r] = -dF


@kernel_jit(forceinline=True)
def curvature_bounds(wk, m, nw, s_end):
    """Bounds on |f''| over [0, s_end] of each event function, into wk.ev[4].

    Mode k: a_k^(3) = (gamma - lambda a'0) cos(w s) - w beta sin(w s) and a_k^(2) = beta cos(w s) + (gamma -
    lambda a'0) sin(w s) / w, so |a_k^(3)| <= hypot(gamma - lambda a'0, w beta) and |a_k^(2)| <=
    min(hypot(beta, |gamma - lambda a'0| / w), |beta| + |gamma - lambda a'0| s_end) (|sin(w s) / w| <= s:
    rigid modes too). A stop's f = sigma_i v_i has f^(2) = sigma_i sum_k phi_ik a_k^(3); a start's
    F_j^(2) = -sum_k (K_jM phi_k) a_k^(2).
    """
    for e in range(m + nw):
        wk.ev[4, e] = 0.0
    for k in range(m):
        lam = wk.lam[k]
        w = math.sqrt(lam)
        g3 = wk.gamma[k] - lam * wk.ap0[k]
        jerk = math.hypot(g3, w * wk.beta[k])
        acc = abs(wk.beta[k]) + abs(g3) * s_end
        if w > 0.0:
            acc = min(acc, math.hypot(wk.beta[k], g3 / w))
        for p in range(m):
            wk.ev[4, p] += abs(wk.Q[p, k] / wk.rootN[p]) * jerk
        for r in range(nw):
            wk.ev[4, m + r] += abs(wk.kphi[r, k]) * acc


@kernel_jit(forceinline=True)
def safe_step(f, df, bound):
    """How far an event function with f > 0 before its event (slope ``df``, |f^(2)| <= ``bound``) surely
    stays > 0: the positive root of f + df h - bound h^2 / 2, in the form without cancellation (f = 0 rising,
    a node that starts now: 2 df / bound)."""
    if f < 0.0 or (f == 0.0 and df <= 0.0):
        return 0.0
    disc = math.sqrt(df * df + 2.0 * bound * f)
    if df < 0.0:
        return 2.0 * f / (disc - df)
    if bound > 0.0:
        return (df + disc) / bound
    return math.inf


@kernel_jit()
def watch(wk, mo, m, nw, s_end, w_max):
    """The first event in (0, s_end] among the stops of the moving nodes (unless the lone one's, in closed
    form) and the starts of the watched stuck nodes (wk.watch): (s, event) or (-1, -1).

    From each sample a the next is a + h: h is the shortest of the steps over which each function surely
    keeps its side (safe_step, from its value, its slope and a bound on its curvature), but at least
    SAMPLE / w_max; the functions that the step could carry across zero are checked on [a, a + h] for a
    sign change and for an extremum that dips through zero (crossing).
    """
    h_min = MAX_SAMPLE if w_max <= 0.0 else min(MAX_SAMPLE, SAMPLE / w_max)
    lone = m == 1 and wk.lam[0] > 0.0  # the lone node's stop is the closed form's
    curvature_bounds(wk, m, nw, s_end)
    event_values(wk, mo, m, nw, 0.0, 0)
    # A watched node at its threshold and rising starts now (as the reference's events do).
    for r in range(nw):
        if wk.watch[r] and wk.ev[0, m + r] == 0.0 and wk.ev[1, m + r] > 0.0:
            return 0.0, m + r
    a = 0.0
    while a < s_end:
        h = math.inf
        for e in range(m + nw):
            if (e < m and lone) or (e >= m and wk.watch[e - m] == 0):
                continue
            f = wk.ev[0, e]
            if e < m:
                he = safe_step(f, wk.ev[1, e], wk.ev[4, e])
            else:
                he = safe_step(-f, -abs(wk.ev[1, e]), wk.ev[4, e])
            wk.ev[5, e] = he
            h = min(h, he)
        h = max(h, h_min)
        b = a + h if h < s_end - a else s_end
        event_values(wk, mo, m, nw, b, 2)
        found = -1.0
        found_e = -1
        for e in range(m + nw):
            if (e < m and lone) or (e >= m and wk.watch[e - m] == 0) or wk.ev[5, e] >= b - a:
                continue
            if e < m and wk.ev[0, e] == 0.0:
                continue  # a node starting now: sigma v rises from 0
            x = crossing(wk, mo, m, e, a, b, wk.ev[0, e], wk.ev[1, e], wk.ev[2, e], wk.ev[3, e])
            if x >= 0.0 and (found < 0.0 or x < found):
                found = x
                found_e = e
        if found >= 0.0:
            return found, found_e
        for e in range(m + nw):
            wk.ev[0, e] = wk.ev[2, e]
            wk.ev[1, e] = wk.ev[3, e]
        a = b
    return -1.0, -1


@kernel_jit(forceinline=True)
def lone_start(wk, mo, r, const):
    """When watched node W[r] reaches its threshold while a lone node moves with no drive (closed form), or inf.

    F_j(s) = const + Pc cos(w s) + Qs sin(w s) = const + A cos(w s - phi), Pc = kphi beta / lambda,
    Qs = -kphi (a'0 - gamma / lambda) / w: it rises through +lim at w s = phi - acos((lim - const) / A) and
    falls through -lim at phi + acos((-lim - const) / A), modulo 2 pi; the earlier, then a Newton step.
    """
    lam = wk.lam[0]
    w = math.sqrt(lam)
    kphi = wk.kphi[r, 0]
    Pc = kphi * wk.beta[0] / lam
    Qs = -kphi * (wk.ap0[0] - wk.gamma[0] / lam) / w
    A = math.hypot(Pc, Qs)
    if A == 0.0:
        return math.inf
    phi = math.atan2(Qs, Pc)
    lim = mo.lim[wk.W[r]]
    two_pi = 2.0 * math.pi
    x = math.inf
    c = (lim - const) / A
    if c <= 1.0:
        xp = phi - math.acos(max(c, -1.0))
        x = min(x, xp - two_pi * math.floor(xp / two_pi))
    c = (-lim - const) / A
    if c >= -1.0:
        xm = phi + math.acos(min(c, 1.0))
        x = min(x, xm - two_pi * math.floor(xm / two_pi))
    if x == math.inf:
        return x
    s = x / w
    if s > 0.0:
        f, fp = event_value(wk, mo, 1, 1 + r, s)
        if fp != 0.0 and abs(f / fp) < 1e-6 * s:
            s -= f / fp
    return s


@kernel_jit(forceinline=True)
def phase(net, f_ext, mo, wk, mu_d, dtheta, rate, s_max):
    """One phase of motion from the current state, theta - theta(0) = ``dtheta`` + ``rate`` s (Ntilde; rate
    per tau_dyn), to the first event or to ``s_max`` tau_dyn.

    Moves the moving nodes (u, v) to the phase's end and returns (s1, what, node, work): what is NO_EVENT,
    STOP (``node`` stopped; its v is left for the caller to read) or START (a stuck node reached its
    threshold), and ``work`` the work of f_ext + (theta - theta(0)) g on the motion, in N Ntilde l0.
    """
    N = mo.u.size
    m = 0
    for i in range(N):
        if mo.moving[i]:
            wk.M[m] = i
            wk.where[i] = m
            m += 1
    # The stuck nodes that a moving node touches (watched), their rows K_WM, and K_MM.
    nw = 0
    for p in range(m):
        i = wk.M[p]
        for q in range(net.indptr[i], net.indptr[i + 1]):
            j = net.indices[q]
            if wk.where[j] == N:
                wk.where[j] = -1 - nw
                wk.W[nw] = j
                nw += 1
    for p in range(m):
        for q in range(m):
            wk.Kmm[p, q] = 0.0
    for r in range(nw):
        for p in range(m):
            wk.KWM[r, p] = 0.0
    for p in range(m):
        i = wk.M[p]
        for q in range(net.indptr[i], net.indptr[i + 1]):
            j = net.indices[q]
            k = wk.where[j]
            if k >= 0 and k < N:
                wk.Kmm[p, k] = net.K_data[q]
            elif k < 0:
                wk.KWM[-1 - k, p] = net.K_data[q]  # K is symmetric: K_jM_p = K_M_p j
    # The modes of N^-1/2 K_MM N^-1/2.
    for p in range(m):
        wk.rootN[p] = math.sqrt(net.normal_load[wk.M[p]])
    for p in range(m):
        for q in range(m):
            wk.Kmm[p, q] /= wk.rootN[p] * wk.rootN[q]
    if m == 1:
        wk.lam[0] = wk.Kmm[0, 0]
        wk.Q[0, 0] = 1.0
    else:
        modes(wk, m)
    w_max = 0.0
    for k in range(m):
        if wk.lam[k] < 0.0:
            wk.lam[k] = 0.0  # rounding of a rigid mode: K is positive semi-definite
        w_max = max(w_max, math.sqrt(wk.lam[k]))
    for p in range(m):
        i = wk.M[p]
        wk.F0[p] = force(net, f_ext, mo.u, i, dtheta)
    for k in range(m):
        a0 = 0.0
        be = 0.0
        ga = 0.0
        for p in range(m):
            i = wk.M[p]
            qpk = wk.Q[p, k]
            a0 += qpk * wk.rootN[p] * mo.v[i]
            be += qpk * (wk.F0[p] - mu_d * net.normal_load[i] * mo.sig[i]) / wk.rootN[p]
            ga += qpk * rate * net.g[i] / wk.rootN[p]
        wk.ap0[k] = a0
        wk.beta[k] = be
        wk.gamma[k] = ga
    s_end = s_max
    what = NO_EVENT
    node = -1
    # Stuck nodes no moving node touches: a force linear in s, a closed-form start (the reference's
    # _next_start); ties go to the lowest index, as numpy's argmin.
    if rate != 0.0:
        for j in range(N):
            if wk.where[j] != N or net.g[j] == 0.0:
                continue
            d = net.g[j] * rate
            F = force(net, f_ext, mo.u, j, dtheta)
            sj = (mo.lim[j] - F) / d if d > 0.0 else (mo.lim[j] + F) / -d
            sj = max(sj, 0.0)
            if sj < s_end:
                s_end = sj
                what = START
                node = j
    # A moving node a hair past its stop (v sigma < 0 after another node's event) stops now.
    for p in range(m):
        i = wk.M[p]
        if mo.v[i] * mo.sig[i] < 0.0:
            s_end = 0.0
            what = STOP
            node = i
            break
    if s_end > 0.0 and m == 1:
        s_stop = lone_stop(wk, mo, s_end)
        if s_stop >= 0.0 and s_stop < s_end:
            s_end = s_stop
            what = STOP
            node = wk.M[0]
    # The watched stuck nodes: bound |F_j| over [0, s_end]; sample only those the bound cannot clear.
    n_watch = 0
    if s_end > 0.0:
        for r in range(nw):
            j = wk.W[r]
            wk.FW[r] = force(net, f_ext, mo.u, j, dtheta)
            wk.dW[r] = net.g[j] * rate
            const = wk.FW[r]
            slope = wk.dW[r]
            swing = 0.0
            rigid = False
            for k in range(m):
                kphi = 0.0
                for p in range(m):
                    kphi += wk.KWM[r, p] * wk.Q[p, k] / wk.rootN[p]
                wk.kphi[r, k] = kphi
                if kphi == 0.0:
                    continue
                lam = wk.lam[k]
                if lam * s_end * s_end < TAYLOR:
                    rigid = True
                    continue
                # a_k = (beta + gamma s) / lambda - (beta / lambda) cos + (a'0 - gamma / lambda) sin / w
                const -= kphi * wk.beta[k] / lam
                slope -= kphi * wk.gamma[k] / lam
                swing += abs(kphi) * math.hypot(wk.beta[k] / lam,
                                                (wk.ap0[k] - wk.gamma[k] / lam) / math.sqrt(lam))
            bound = max(abs(const), abs(const + slope * s_end)) + swing
            wk.watch[r] = 1 if (rigid or bound >= mo.lim[j]) else 0
            if wk.watch[r] and m == 1 and slope == 0.0 and not rigid:
                # A lone slider that no drive pushes: F_j = const + A cos(w s - phi), a closed-form start.
                wk.watch[r] = 0
                s_j = lone_start(wk, mo, r, const)
                if s_j < s_end:
                    s_end = s_j
                    what = START
                    node = j
            n_watch += wk.watch[r]
    if s_end > 0.0 and (m > 1 or n_watch > 0 or wk.lam[0] <= 0.0):
        found, found_e = watch(wk, mo, m, nw, s_end, w_max)
        if found >= 0.0 and found < s_end:
            s_end = found
            if found_e < m:
                what = STOP
                node = wk.M[found_e]
            else:
                what = START
                node = wk.W[found_e - m]
    # Move to s_end; the work of the loads: sum_p (f_ext + dtheta g)_p y_p(s1) + r g_p (s1 y_p - int y_p).
    work = 0.0
    if s_end > 0.0:
        modal_state(wk, m, s_end, True)
        for p in range(m):
            work -= rate * net.g[wk.M[p]] * wk.yint[p]
            i = wk.M[p]
            work += (f_ext[i] + net.g[i] * (dtheta + rate * s_end)) * wk.y[p]
            mo.u[i] += wk.y[p]
            mo.v[i] = wk.yv[p]
    for p in range(m):
        wk.where[wk.M[p]] = N
    for r in range(nw):
        wk.where[wk.W[r]] = N
    return s_end, what, node, work
