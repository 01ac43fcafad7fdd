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
"""

from __future__ import annotations

import numpy as np

from .._typing import FloatArray
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


__all__ = ["ForcingHomotopy"]
