"""Floquet multipliers of a regularised harmonic-balance orbit (preload, friction).

The regularised equation δ'' + c δ' + g_ε(δ, δ') = F(t) (:class:`~rattle.hb.RegularisedBalance`)
is smooth, so a perturbation y = (Δδ, Δδ') of its periodic orbit obeys the linear periodic system

    y' = A(t) y,   A(t) = [[0, 1], [−∂g_ε/∂δ, −(c + ∂g_ε/∂δ')]],

evaluated along the HB orbit. Its monodromy over the period T is the ordered product of the
exact exponentials of A frozen at the midpoints of N equal steps (the exponential midpoint rule,
second order in T/N):

    M ≈ exp(A(t_{N−½}) Δt) ⋯ exp(A(t_½) Δt),   Δt = T/N.

N must resolve the smooth steps in time: a step of width ε_v in δ' is crossed in ~ε_v/|δ''|;
by default N is the problem's AFT sample count. The multipliers of the regularised orbit tend to
those of the discontinuous one (saltation matrices at the switchings, a zero multiplier for each
stick phase) as ε → 0; the exact ones are :func:`rattle.timeint.shoot_nonsmooth_orbit`'s.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._typing import ComplexArray, FloatArray
from ..hb import RegularisedBalance


def regularised_monodromy(problem: RegularisedBalance, q: FloatArray, omega: float,
                          steps: int | None = None) -> FloatArray:
    """M (2, 2) of the regularised orbit with coefficients ``q`` at forcing frequency ``omega``
    over its period p·2π/Ω (module docstring); ``steps`` N (default the AFT samples)."""
    N = problem.basis.samples if steps is None else int(steps)
    if N < 8:
        raise ValueError(f"`steps` must be >= 8, got {steps!r}")
    w = omega / problem.period
    T = 2.0 * np.pi / w
    dt = T / N
    t = (np.arange(N) + 0.5) * dt
    d = problem.basis.evaluate(q, w, t)
    v = problem.basis.evaluate(q, w, t, derivative=1)
    _, g_d, g_v = problem.force.regularised(d, v, *problem.widths)
    A = np.zeros((N, 2, 2))
    A[:, 0, 1] = 1.0
    A[:, 1, 0] = -g_d
    A[:, 1, 1] = -(problem.c + g_v)
    E = scipy.linalg.expm(A * dt)
    M = np.eye(2)
    for k in range(N):
        M = E[k] @ M
    return M


def regularised_multipliers(problem: RegularisedBalance, q: FloatArray, omega: float,
                            steps: int | None = None) -> ComplexArray:
    """The Floquet multipliers of :func:`regularised_monodromy`, largest modulus first."""
    mu = np.linalg.eigvals(regularised_monodromy(problem, q, omega, steps)).astype(complex)
    return mu[np.argsort(-np.abs(mu), kind="stable")]


__all__ = ["regularised_monodromy", "regularised_multipliers"]
