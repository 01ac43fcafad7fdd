"""Root finding shared by every path of the exact flow: Newton's method safeguarded by bisection on
a bracket, one root at a time (the crossing search's hot loop, Python floats) or many at once
(extrema of a trajectory's measures, numpy); the event grid's chunks (:func:`grid_chunk`), a
crossing inside one grid cell, grazing-safe (:func:`resolve_cell`), and the polish of a crossing
where the field jumps (:func:`polish_crossing`)."""

from __future__ import annotations

import math
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


_EPS = float(np.finfo(float).eps)


def grid_chunk(start: float, end: float, step: float, cells: int) -> FloatArray:
    """The grid points of the next at most ``cells`` cells of width ``step`` from ``start`` (the
    event grid is scanned a chunk at a time), the last one placed exactly on ``end`` when the
    chunk reaches it."""
    n = max(1, min(cells, math.ceil((end - start) / step)))
    pts = start + step * np.arange(n + 1)
    if n < cells or pts[-1] >= end:
        pts[-1] = end
    return pts


def resolve_cell(
    state: Callable[[float], tuple[float, float, float]], lo: float, hi: float, tau_a: float, tau_b: float,
    d_a: float, d_b: float, v_a: float, v_b: float, at_start: bool, d_floor: float, v_floor: float,
) -> tuple[float, int] | None:
    """The exit of a deflection δ(τ) from its stage [lo, hi) inside the grid cell [tau_a, tau_b],
    if any: (τ, direction +1 up / −1 down); None when δ stays inside or only grazes a breakpoint
    (an excursion beyond it of at most ``d_floor``, its round-off floor).

    ``state(τ)`` = (δ, δ', δ''); d_a, d_b, v_a, v_b the grid values of δ and δ' at the cell's
    ends. An extremum of δ inside the cell (δ' changes sign) is located first (Newton on δ' to
    ``v_floor``), so a trajectory touching a breakpoint tangentially inside a cell is not
    missed; the crossing is then bracketed on the side of the extremum where δ passes the bound
    and located by Newton on δ − bound to its round-off floor. ``at_start``: the cell starts at
    the segment's start, which is inside the stage by construction whatever round-off says.
    """
    tol = 4.0 * _EPS * tau_b + 1e-300
    end_up, end_down = d_b >= hi, d_b < lo
    if v_a != 0.0 and (v_a > 0.0) != (v_b > 0.0):

        def velocity_and_acceleration(tau: float) -> tuple[float, float]:
            _, v, a = state(tau)
            return v, a

        tau_e = tau_b if v_b == 0.0 else bracketed_newton(
            velocity_and_acceleration, tau_a, tau_b, v_a, v_b, tol, v_floor)
        d_e = state(tau_e)[0]
        if v_a > 0.0:  # a maximum: beyond hi, cross before it; else maybe down after it
            if d_e - hi > d_floor or end_up:
                up, a_, b_, d_a_, d_b_ = True, tau_a, tau_e, d_a, d_e
            elif end_down:
                up, a_, b_, d_a_, d_b_ = False, tau_e, tau_b, d_e, d_b
            else:
                return None
        else:  # a minimum
            if lo - d_e > d_floor or end_down:
                up, a_, b_, d_a_, d_b_ = False, tau_a, tau_e, d_a, d_e
            elif end_up:
                up, a_, b_, d_a_, d_b_ = True, tau_e, tau_b, d_e, d_b
            else:
                return None
    elif end_up or end_down:
        up, a_, b_, d_a_, d_b_ = end_up, tau_a, tau_b, d_a, d_b
    else:
        return None
    bound = hi if up else lo
    fa, fb = d_a_ - bound, d_b_ - bound
    if (fa >= 0.0) if up else (fa < 0.0):
        if not (at_start and a_ == 0.0):
            return a_, (1 if up else -1)  # round-off at a graze: the crossing is at the bracket's start
        fa = -1e-300 if up else 1e-300  # the segment start is inside by construction

    def gap(tau: float) -> tuple[float, float]:
        d, v, _ = state(tau)
        return d - bound, v

    return bracketed_newton(gap, a_, b_, fa, fb, tol, d_floor), (1 if up else -1)


def polish_crossing(state: Callable[[float], tuple[float, float, float]], bound: float, tau: float,
                    tau_max: float) -> float | None:
    """The crossing time ``tau`` of δ(τ) = ``bound`` where the field jumps (a jump of the law, a
    change of friction level), polished by up to three Newton steps on δ(τ) − bound to the last
    bit: an error dτ there becomes an error (a⁺ − a⁻) dτ of δ'. ``state(τ)`` = (δ, δ', δ'');
    the polished time, or None when it leaves (0, ``tau_max``] or moves by more than a relative
    1e-6 of ``tau`` (then ``tau`` stands)."""
    tp = tau
    for _ in range(3):
        dd, vv, _ = state(tp)
        if vv == 0.0:
            break
        dt = (dd - bound) / vv
        tp -= dt
        if abs(dt) <= 2.0 * _EPS * abs(tp):
            break
    if 0.0 < tp <= tau_max and abs(tp - tau) <= 1e-6 * max(tau, 1e-300) + 1e-12:
        return tp
    return None


__all__ = ["bracketed_newton", "grid_chunk", "polish_crossing", "resolve_cell", "vector_bracketed_newton"]
