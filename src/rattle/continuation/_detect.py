"""Locating special points between two consecutive branch points.

Between accepted points y_a and y_b (scaled variables) the branch is parametrised by the arc
length s along the secant d = (y_b − y_a)/|y_b − y_a|: each trial point y_a + s d is corrected
back onto the branch in the plane normal to d (the arc-length corrector, on any
:class:`~rattle.continuation.ContinuationProblem`), and a scalar test function ψ that changes
sign at the special point, supplied by the caller, is solved for s by Brent's method. For
periodic orbits with monodromy M (``rattle.stability``):

* fold: ψ = det(M − I) = 1 − tr M + det M (a multiplier at +1);
* period doubling: ψ = det(M + I) = 1 + tr M + det M (a multiplier at −1);
* Neimark–Sacker: ψ = det(M ⊙ M − I) (a complex pair on the unit circle).

Where M is a smooth function of the orbit (between crossing-structure changes) Brent's method
converges superlinearly. (The parameter component of the tangent is no good test when the
residual is only piecewise smooth — a harmonic-balance curve of a piecewise-linear law is a fine
polyline whose tangent jumps, at a fold it flips sign in a single kink.) At a fold the
parameter is stationary in s, so an error in s changes the located parameter only to second order.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._brent import brent_root
from .._typing import FloatArray
from ._corrector import ArclengthCorrector, Corrected


@dataclass(frozen=True, slots=True)
class LocatedPoint:
    """A located special point: unknowns ``q``, parameter ``p``, the test function's
    ``value`` there, corrector ``iterations`` and scaled ``residual``."""

    q: FloatArray
    p: float
    value: float
    iterations: int
    residual: float

    @property
    def omega(self) -> float:
        """``p`` under the name rattle's frequency responses read it by (their parameter is Ω)."""
        return self.p


def locate_on_segment(
    corrector: ArclengthCorrector,
    q_a: FloatArray,
    p_a: float,
    q_b: FloatArray,
    p_b: float,
    test: Callable[[FloatArray, float, Corrected, FloatArray], float],
    *,
    xtol: float = 1e-10,
    ends: tuple[float, float] | None = None,
) -> LocatedPoint | None:
    """Root of ``test(q, p, corrected, d)`` on the branch between two points (q_a, p_a) and
    (q_b, p_b), or None if the test function has no sign change there or a correction fails.

    ``ends``: the test function's values at the two points when the caller has them (points
    already on the branch, e.g. from the monitor's readings): the ends are then not corrected
    and evaluated again (two corrector solves fewer); otherwise each end is corrected in the
    plane normal to the secant and ψ evaluated there."""
    y_a = corrector.to_scaled(q_a, p_a)
    y_b = corrector.to_scaled(q_b, p_b)
    length = float(np.linalg.norm(y_b - y_a))
    if length == 0.0:
        return None
    d = (y_b - y_a) / length
    cache: dict[float, tuple[float, Corrected]] = {}

    def psi(s: float) -> float:
        corr = corrector.correct(y_a + s * d, d)
        if corr is None:
            raise _CorrectorFailed
        q, p = corrector.unscale(corr.y)
        val = float(test(q, p, corr, d))
        cache[s] = (val, corr)
        return val

    try:
        f0, f1 = (psi(0.0), psi(length)) if ends is None else (float(ends[0]), float(ends[1]))
        if not np.sign(f0) * np.sign(f1) < 0:
            return None
        s_star = brent_root(psi, 0.0, length, xtol=xtol * length, fa=f0, fb=f1)
    except _CorrectorFailed:
        return None
    val, corr = cache[s_star] if s_star in cache else (psi(s_star), cache[s_star][1])
    q, p = corrector.unscale(corr.y)
    return LocatedPoint(q, p, val, corr.iterations, corr.residual)


class _CorrectorFailed(Exception):
    pass


__all__ = ["LocatedPoint", "locate_on_segment"]
