"""Compiled kernel of the single-element monodromy (numba), the n = m = 1 case of ``_floquet``.

For one coordinate and one element, :func:`monodromies` does per orbit what the array code of
``_floquet`` does for many orbits at once — the crossings of every breakpoint bracketed by the
sign changes of the samples, refined by Newton on the Fourier series (safeguarded by Illinois
regula falsi and bisection where Newton leaves its bracket), the segments' stages read at their
mid-points, the product of the closed-form stage transitions exp(A τ) of
:func:`rattle.model._stage_matrix.transition_scalar` compiled — in scalar loops. On the one
or two orbits of a continuation step the array code spends its time in numpy's per-call cost
(some hundred calls on arrays of a few elements); compiled, one orbit costs a few microseconds
beyond its samples. The results agree with the array code to round-off (tests/stability).

``AVAILABLE`` is False when numba cannot be imported; ``_floquet`` then keeps the array code.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit, numba  # numba is a dependency; the array code stays the fallback (and the reference)

from ..model import stage_constants, transition_scalar

AVAILABLE = numba is not None

_EPS64 = 64 * np.finfo(float).eps


def _series(a0, a, b, w, t):
    """δ(t), δ'(t) of the series a0 + Σ a_k cos kωt + b_k sin kωt."""
    d = 0.0
    v = 0.0
    for k in range(a.size):
        kw = (k + 1) * w
        ph = kw * t
        c = math.cos(ph)
        s = math.sin(ph)
        d += c * a[k] + s * b[k]
        v += c * (kw * b[k]) - s * (kw * a[k])
    return a0 + d, v


def _refine(a0, a, b, w, lvl, fa, fb, ta, tb, t, tol):
    """The crossing of level ``lvl`` in the bracket [ta, tb] (f = δ − lvl is fa, fb at its ends)
    from the interpolated guess t: Newton, and where it does not converge inside the bracket,
    Newton safeguarded by Illinois regula falsi and bisection (as ``_floquet._crossings``)."""
    t_fast = t
    for _ in range(4):
        f, fp = _series(a0, a, b, w, t_fast)
        step = (f - lvl) / fp
        t_fast = t_fast - step
        if math.isfinite(t_fast) and abs(step) <= tol and t_fast >= ta and t_fast <= tb:
            return t_fast
    fa_val, fb_val = fa, fb
    side = 0
    for _ in range(60):
        f, fp = _series(a0, a, b, w, t)
        f = f - lvl
        left = (f > 0) == (fa > 0)
        t0 = t
        if left and side == -1:
            fb_val = 0.5 * fb_val
        if not left and side == 1:
            fa_val = 0.5 * fa_val
        if left:
            ta = t0
            fa_val = f
            side = -1
        else:
            tb = t0
            fb_val = f
            side = 1
        t_new = t0 - f / fp
        t_rf = ta - fa_val * (tb - ta) / (fb_val - fa_val)
        if not math.isfinite(t_new) or t_new < ta or t_new > tb:
            if not math.isfinite(t_rf) or t_rf < ta or t_rf > tb:
                t_new = 0.5 * (ta + tb)
            else:
                t_new = t_rf
        exact = f == 0.0
        if exact:
            t_new = t0
        t = t_new
        if not (abs(t_new - t0) > tol and not exact and tb - ta > tol):
            break
    return t


def _next_change(x, lvl, start):
    """The first j ≥ ``start`` where the periodic samples x change side of ``lvl`` between x_j
    and x_{j+1} (x_N = x_0), else N: a plain loop the compiler keeps tight (the crossings are
    few, the samples many)."""
    N = x.size
    for j in range(start, N - 1):
        if (x[j] > lvl) != (x[j + 1] > lvl):
            return j
    if start <= N - 1 and (x[N - 1] > lvl) != (x[0] > lvl):
        return N - 1
    return N


def _monodromies(Q, omega, samples, bp, kappa, sigma, under, wd, gamma, lam1, lam2, M, counts):
    """Fill M (P, 2, 2) and counts (P, k) for the orbits Q (P, 2H+1) with samples (P, N); the
    stages' exp(A τ) from their constants (:func:`rattle.model._stage_matrix.stage_constants`)."""
    P, N = samples.shape
    H = (Q.shape[1] - 1) // 2
    k = bp.size
    times = np.empty(max(1, 4 * k * 16))
    for p in range(P):
        a0 = Q[p, 0]
        a = Q[p, 1 : H + 1]
        b = Q[p, H + 1 :]
        w = omega[p]
        x = samples[p]
        T = 2 * np.pi / w
        dt = T / N
        tol = _EPS64 * T
        n = 0
        for i in range(k):
            lvl = bp[i]
            c_i = 0
            j = _next_change(x, lvl, 0)
            while j < N:
                fa = x[j] - lvl
                fb = x[(j + 1) % N] - lvl
                ta = j * dt
                tb = ta + dt
                t = ta + dt * fa / (fa - fb)
                t = _refine(a0, a, b, w, lvl, fa, fb, ta, tb, t, tol)
                if n == times.size:
                    grown = np.empty(2 * n)
                    grown[:n] = times[:n]
                    times = grown
                times[n] = t % T
                n += 1
                c_i += 1
                j = _next_change(x, lvl, j + 1)
            counts[p, i] = c_i
        order = np.argsort(times[:n], kind="mergesort")
        m00, m01, m10, m11 = 1.0, 0.0, 0.0, 1.0
        start = 0.0
        for g in range(n + 1):
            end = times[order[g]] if g < n else T
            tau = end - start
            mid = 0.5 * (start + end)
            start = end
            d_mid, _ = _series(a0, a, b, w, mid)
            stage = 0
            if d_mid != d_mid:  # NaN sorts last (np.searchsorted)
                stage = k
            else:
                while stage < k and bp[stage] <= d_mid:
                    stage += 1
            f00, f01, f10, f11 = _transition(sigma, under[stage], wd[stage], gamma[stage], lam1[stage],
                                             lam2[stage], kappa[stage], tau)
            m00, m01, m10, m11 = (f00 * m00 + f01 * m10, f00 * m01 + f01 * m11,
                                  f10 * m00 + f11 * m10, f10 * m01 + f11 * m11)
        M[p, 0, 0] = m00
        M[p, 0, 1] = m01
        M[p, 1, 0] = m10
        M[p, 1, 1] = m11


if AVAILABLE:
    _jit = njit  # rattle._jit: the one compile setting
    _transition = _jit(transition_scalar)  # the one closed form of exp(A τ), compiled
    _series = _jit(_series)
    _refine = _jit(_refine)
    _next_change = _jit(_next_change)
    _monodromies = _jit(_monodromies)
else:  # pragma: no cover - the array code is taken then
    _transition = transition_scalar


#: Stage constants of the laws met, keyed by (stage stiffnesses, damping).
_CONSTANTS: dict = {}


def monodromies(
    Q: np.ndarray, omega: np.ndarray, samples: np.ndarray, breakpoints: np.ndarray, stiffness: np.ndarray,
    damping: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Monodromies (P, 2, 2) and crossings per breakpoint (P, k) of single-element orbits: ``Q``
    (P, 2H+1) series, ``omega`` (P,) base frequencies, ``samples`` (P, N), ``breakpoints`` (k,)
    sorted, ``stiffness`` (k+1,) the stage stiffnesses, ``damping`` c (see
    :func:`~rattle.stability.monodromy_and_crossings_batch`)."""
    Q = np.ascontiguousarray(Q, dtype=float)
    stiffness = np.ascontiguousarray(stiffness, dtype=float)
    key = (stiffness.tobytes(), float(damping))
    const = _CONSTANTS.get(key)
    if const is None:  # a dozen numpy calls: once per law, not once per orbit
        if len(_CONSTANTS) > 64:
            _CONSTANTS.clear()
        const = _CONSTANTS[key] = stage_constants(stiffness, damping)
    P = Q.shape[0]
    M = np.empty((P, 2, 2))
    counts = np.zeros((P, breakpoints.size), dtype=np.intp)
    _monodromies(Q, np.ascontiguousarray(omega, dtype=float), np.ascontiguousarray(samples, dtype=float),
                 np.ascontiguousarray(breakpoints, dtype=float), const.kappa, const.sigma, const.under, const.wd,
                 const.gamma, const.lam1, const.lam2, M, counts)
    return M, counts


__all__ = ["AVAILABLE", "monodromies"]
