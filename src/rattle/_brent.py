"""Brent's bracketing root finder for a scalar function (root helper of every layer).

Find x in [a, b] with f(x) = 0, given f(a) f(b) ≤ 0. Each step keeps the bracket [x, x_c] (x the
best estimate, |f(x)| ≤ |f(x_c)|) and tries, in order of preference,

* inverse quadratic interpolation through (x_p, f_p), (x, f), (x_c, f_c) when the previous point
  x_p is not the bracket's other end:  s = −f (f_c d_c − f_p d_p) / (d_c d_p (f_c − f_p)),
  with the divided differences d_p = (f_p − f)/(x_p − x), d_c = (f_c − f)/(x_c − x);
* the secant through (x_p, f_p), (x, f) otherwise:  s = −f (x − x_p)/(f − f_p);

and accepts the step only when it is short, 2|s| < min(|s_prev|, 3|m| − δ) with m = (x_c − x)/2,
bisecting (s = m) otherwise — so the bracket shrinks at least as fast as bisection every second
step and superlinearly near a simple root (R. P. Brent, *Algorithms for Minimization without
Derivatives*, 1973, ch. 4). It stops when |m| < δ = (xtol + rtol |x|)/2 or f(x) = 0; a step
shorter than δ is lengthened to δ towards the other end.

These are the step rules of ``scipy.optimize.brentq``, so the iterates are the same numbers; it is
written here (a few lines) so that locating a special point does not import ``scipy.optimize``
(0.15 s of every command's start), and so that a caller who has already evaluated f at the two
ends gives those values instead of paying for them again (a corrector solve each, when f is a
test function along a branch).
"""

from __future__ import annotations

from collections.abc import Callable

#: rtol's floor: 4 ε, below which the stopping test cannot be met in floating point.
MIN_RTOL = 4.0 * 2.220446049250313e-16


class BracketError(ValueError):
    """f(a) and f(b) have the same strict sign: [a, b] brackets no root."""


class NoConvergence(RuntimeError):
    """``maxiter`` steps did not shrink the bracket below the tolerance."""


def brent_root(f: Callable[[float], float], a: float, b: float, *, xtol: float = 2e-12,
               rtol: float = MIN_RTOL, maxiter: int = 100, fa: float | None = None,
               fb: float | None = None) -> float:
    """The root of ``f`` in [a, b] to |error| ≤ xtol + rtol |x| (see the module's docstring).

    ``fa``, ``fb``: f(a) and f(b) when the caller has them (not evaluated again). Raises
    :class:`BracketError` when f(a) f(b) > 0 and :class:`NoConvergence` after ``maxiter``
    steps."""
    if not xtol > 0:
        raise ValueError(f"`xtol` must be > 0, got {xtol!r}")
    if not rtol >= MIN_RTOL:
        raise ValueError(f"`rtol` must be >= 4 eps ({MIN_RTOL!r}), got {rtol!r}")
    x_prev, x = float(a), float(b)
    f_prev = float(f(x_prev)) if fa is None else float(fa)
    fx = float(f(x)) if fb is None else float(fb)
    if f_prev * fx > 0:
        raise BracketError(f"f(a) = {f_prev!r} and f(b) = {fx!r} have the same sign: no root bracketed")
    if f_prev == 0:
        return x_prev
    if fx == 0:
        return x
    x_c = f_c = 0.0
    step_prev = step = 0.0
    for _ in range(maxiter):
        if f_prev * fx < 0:  # the root lies between the last two points: the bracket restarts there
            x_c, f_c = x_prev, f_prev
            step_prev = step = x - x_prev
        if abs(f_c) < abs(fx):  # keep the best estimate in x
            x_prev, x, x_c = x, x_c, x
            f_prev, fx, f_c = fx, f_c, fx
        tol = (xtol + rtol * abs(x)) / 2
        half = (x_c - x) / 2
        if fx == 0 or abs(half) < tol:
            return x
        if abs(step_prev) > tol and abs(fx) < abs(f_prev):
            if x_prev == x_c:  # two distinct points only: the secant
                trial = -fx * (x - x_prev) / (fx - f_prev)
            else:  # inverse quadratic interpolation
                d_prev = (f_prev - fx) / (x_prev - x)
                d_c = (f_c - fx) / (x_c - x)
                trial = -fx * (f_c * d_c - f_prev * d_prev) / (d_c * d_prev * (f_c - f_prev))
            if 2 * abs(trial) < min(abs(step_prev), 3 * abs(half) - tol):
                step_prev, step = step, trial
            else:
                step_prev = step = half
        else:
            step_prev = step = half
        x_prev, f_prev = x, fx
        x = x + (step if abs(step) > tol else (tol if half > 0 else -tol))
        fx = float(f(x))
    raise NoConvergence(f"no convergence in {maxiter} steps: the bracket around {x!r} is still wider "
                        f"than {2 * (xtol + rtol * abs(x))!r}")


__all__ = ["BracketError", "MIN_RTOL", "NoConvergence", "brent_root"]
