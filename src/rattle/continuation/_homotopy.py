"""The forcing homotopy: a problem at a fixed parameter, continued in the scale of its forcing.

A problem whose residual is a response minus a forcing, R(q, p) = A(q, p) − F, has at a fixed
parameter p (in rattle: the forcing frequency Ω) the one-parameter family

    R(q; λ) = A(q, p) − F_0 − λ f = R(q, p) + (1 − λ) f,    F = F_0 + f,

with ∂R/∂q(q; λ) = ∂R/∂q(q, p) and ∂R/∂λ = −f: at λ = 1 the problem itself, at λ = 0 the
problem forced by F_0 alone (for harmonic balance, f = F − F_0 the forcing's harmonics and F_0
its means: λ = 0 is the static equilibrium). :class:`ForcingHomotopy` is that family as a
:class:`~rattle.continuation.ContinuationProblem` in the parameter λ, so that a solution at
λ = 1 that Newton cannot reach from a guess is reached by following the branch from λ = 0 with
:class:`~rattle.continuation.ContinuationStepper` (through any folds in λ), the last point
placed on λ = 1 by Newton at the full forcing.

:class:`WidthHomotopy` is the other family: a problem whose width w (a regularisation's ε, a
scale of some elements' steps) is continued in u = log w at a fixed p — the ladders of the
regularised harmonic balance towards its limit.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .._typing import FloatArray
from ._newton import newton_step
from ._problem import ContinuationProblem


class ForcingHomotopy:
    """R(q; λ) = R(q, p) + (1 − λ) f: ``problem`` at the fixed parameter ``p`` with the part
    ``forcing`` = f (shape (N,), units of R) of its forcing scaled by λ (module docstring).

    A :class:`~rattle.continuation.ContinuationProblem` in λ (dimensionless: ``parameter_scale``
    1) with ``problem``'s size, length scale and force scale. ``problem`` is not modified.
    """

    __slots__ = ("problem", "p", "forcing")

    def __init__(self, problem: ContinuationProblem, p: float, forcing: FloatArray) -> None:
        f = np.array(forcing, dtype=float)
        if f.shape != (problem.size,) or not np.all(np.isfinite(f)):
            raise ValueError(f"`forcing` must be {problem.size} finite numbers (the problem's size), got shape {f.shape}")
        self.problem = problem
        self.p = float(p)
        self.forcing = f

    @property
    def size(self) -> int:
        return self.problem.size

    @property
    def length_scale(self) -> float | FloatArray:
        return self.problem.length_scale

    @property
    def parameter_scale(self) -> float:
        return 1.0

    @property
    def force_scale(self) -> float:
        return self.problem.force_scale

    def residual(self, q: FloatArray, lam: float) -> FloatArray:
        """R(q; λ) = R(q, p) + (1 − λ) f, shape (N,)."""
        return self.problem.residual(q, self.p) + (1.0 - lam) * self.forcing  # a new array: R is not the problem's

    def residual_jacobian(self, q: FloatArray, lam: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R(q; λ), ∂R/∂q (N, N) and ∂R/∂λ = −f (N,)."""
        R, Rq, _ = self.problem.residual_jacobian(q, self.p)
        return R + (1.0 - lam) * self.forcing, Rq, -self.forcing


class WidthHomotopy:
    """R(q; u) = R_w(q, p) with w = e^u: a family of problems ``family(w)`` (a regularisation
    width ε, a scale s of some elements' widths), each at the fixed parameter ``p``, continued in
    u = log w (dimensionless: ``parameter_scale`` 1; any sign: the stepper's ``domain`` is
    (−inf, inf)). A ladder w_0 > w_1 > … is this branch followed down in u with the rungs as the
    stepper's ``stations``.

    ``family(w)`` returns the :class:`~rattle.continuation.ContinuationProblem` (in p) at width w,
    all of one size and scales (``family(e^{u_0})``'s are this problem's). ∂R/∂u is not known in
    closed form: the central difference (R_{w e^h} − R_{w e^{−h}}) / 2h with h = 1e-6 (the
    residual is smooth in w; its error O(h²) is far below Newton's tolerance on a tangent).
    """

    __slots__ = ("family", "p", "_first")

    #: The step in u of the central difference for ∂R/∂u.
    STEP = 1e-6

    def __init__(self, family: Callable[[float], ContinuationProblem], p: float, u0: float) -> None:
        self.family = family
        self.p = float(p)
        self._first = family(math.exp(u0))

    @property
    def size(self) -> int:
        return self._first.size

    @property
    def length_scale(self) -> float | FloatArray:
        return self._first.length_scale

    @property
    def parameter_scale(self) -> float:
        return 1.0

    @property
    def force_scale(self) -> float:
        return self._first.force_scale

    def residual(self, q: FloatArray, u: float) -> FloatArray:
        """R_w(q, p), w = e^u, shape (N,)."""
        return self.family(math.exp(u)).residual(q, self.p)

    def residual_jacobian(self, q: FloatArray, u: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R_w(q, p), ∂R/∂q (N, N) and ∂R/∂u (N,, the central difference)."""
        R, Rq, _ = self.family(math.exp(u)).residual_jacobian(q, self.p)
        h = self.STEP
        Ru = (self.family(math.exp(u + h)).residual(q, self.p) - self.family(math.exp(u - h)).residual(q, self.p)) / (2 * h)
        return R, Rq, Ru

    def newton_step(self, q: FloatArray, u: float) -> tuple[FloatArray, FloatArray | None]:
        """One Newton step of the problem at w = e^u (:func:`~rattle.continuation._newton.newton_step`:
        its own step when it has one, else the full solve)."""
        return newton_step(self.family(math.exp(u)), q, self.p)


__all__ = ["ForcingHomotopy", "WidthHomotopy"]
