"""Root finding shared by the exact integrators: Newton's method safeguarded by bisection on a
bracket, one root at a time (the crossing search's hot loop, Python floats) or many at once
(extrema of a trajectory's measures, numpy)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._typing import FloatArray, IntArray


def bracketed_newton(
    fun: Callable[[float], tuple[float, float]], a: float, b: float, fa: float, fb: float, tol: float,
    ftol: float = 0.0,
) -> float:
    """Root of ``fun`` in [a, b] (fa·fb ≤ 0) by Newton's method safeguarded by bisection
    (Numerical Recipes' rtsafe); ``fun(x)`` returns (f, f'). Stops when the step is below ``tol``
    or |f| ≤ ``ftol`` (the round-off floor of f)."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if fa > 0.0:  # orient so that f(lo) < 0 < f(hi)
        lo, hi = b, a
    else:
        lo, hi = a, b
    # regula falsi start (good for a transversal crossing); the midpoint where the two ends agree
    # (a bracket of two equal round-off values: no secant)
    x = 0.5 * (a + b) if fb == fa else a - fa * (b - a) / (fb - fa)
    dx_old = dx = abs(b - a)
    for _ in range(200):
        f, df = fun(x)
        if abs(f) <= ftol:
            return x
        if f < 0.0:
            lo = x
        else:
            hi = x
        if ((x - hi) * df - f) * ((x - lo) * df - f) > 0.0 or abs(2.0 * f) > abs(dx_old * df):
            dx_old, dx = dx, 0.5 * (hi - lo)  # Newton leaves the bracket or converges slowly
            x = lo + dx
        else:
            dx_old, dx = dx, f / df
            x -= dx
        if abs(dx) <= tol:
            return x
    return x


def vector_bracketed_newton(
    fun: Callable[[FloatArray, IntArray], tuple[FloatArray, FloatArray]],
    a: FloatArray, b: FloatArray, fa: FloatArray, fb: FloatArray, tol: FloatArray,
) -> FloatArray:
    """Roots of ``fun`` in the brackets [a_i, b_i] (fa·fb ≤ 0), all at once: Newton steps, with a
    bisection wherever the step leaves the bracket. ``fun(x, idx)`` evaluates the roots ``idx``."""
    lo = np.where(fa > 0.0, b, a)
    hi = np.where(fa > 0.0, a, b)
    x = np.where(fa == fb, a, a - fa * (b - a) / np.where(fa == fb, 1.0, fb - fa))
    active = np.ones(a.shape, dtype=bool)
    for _ in range(200):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        f, df = fun(x[idx], idx)
        neg = f < 0.0
        lo[idx] = np.where(neg, x[idx], lo[idx])
        hi[idx] = np.where(neg, hi[idx], x[idx])
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = x[idx] - f / df
        # Closed bracket: a converged Newton step may land on the end just updated (round-off).
        inside = np.isfinite(newton) & ((newton - lo[idx]) * (newton - hi[idx]) <= 0.0)
        x_new = np.where(inside, newton, 0.5 * (lo[idx] + hi[idx]))
        done = (f == 0.0) | (np.abs(x_new - x[idx]) <= tol[idx]) | (np.abs(hi[idx] - lo[idx]) <= tol[idx])
        x[idx] = np.where(f == 0.0, x[idx], x_new)
        active[idx[done]] = False
    return x


__all__ = ["bracketed_newton", "vector_bracketed_newton"]
