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

from .._typing import ComplexArray, FloatArray
from ..hb import RegularisedBalance


def _shifted(q: FloatArray, H: int, phase: float) -> FloatArray:
    """Coefficients of δ(t + τ) from those of δ(t), ``phase`` = ω τ."""
    k = np.arange(1, H + 1) * phase
    c, s = np.cos(k), np.sin(k)
    a, b = q[1 : H + 1], q[H + 1 :]
    out = np.empty_like(q)
    out[0] = q[0]
    out[1 : H + 1] = a * c + b * s
    out[H + 1 :] = b * c - a * s
    return out


def _expm_companion(a: FloatArray, b: FloatArray, tau: float) -> FloatArray:
    """exp(A τ) (N, 2, 2) of A = [[0, 1], [a, b]] in closed form: with s = b/2 and
    q² = s² + a, exp(Aτ) = e^{sτ} [cosh(qτ) I + (sinh(qτ)/q) (A − s I)] (q → 0: sinh(qτ)/q → τ)."""
    s = 0.5 * b
    q = np.sqrt((s * s + a).astype(complex))
    qt = q * tau
    ch = np.cosh(qt).real
    small = np.abs(qt) < 1e-6
    shq = np.where(small, tau * (1.0 + qt * qt / 6.0), np.sinh(qt) / np.where(small, 1.0, q)).real
    e = np.exp(s * tau)
    out = np.empty(a.shape + (2, 2))
    out[:, 0, 0] = e * (ch - s * shq)
    out[:, 0, 1] = e * shq
    out[:, 1, 0] = e * a * shq
    out[:, 1, 1] = e * (ch + s * shq)
    return out


def _ordered_product(E: FloatArray) -> FloatArray:
    """E[N−1] ⋯ E[1] E[0] by pairwise products (log₂ N batched steps)."""
    while E.shape[0] > 1:
        if E.shape[0] % 2:
            E = np.concatenate((E, np.eye(2)[None]))
        E = E[1::2] @ E[0::2]
    return E[0]


def regularised_monodromy(problem: RegularisedBalance, q: FloatArray, omega: float,
                          steps: int | None = None) -> FloatArray:
    """M (2, 2) of the regularised orbit with coefficients ``q`` at forcing frequency ``omega``
    over its period p·2π/Ω (module docstring); ``steps`` N (default the AFT samples)."""
    N = problem.basis.samples if steps is None else int(steps)
    if N < 8:
        raise ValueError(f"`steps` must be >= 8, got {steps!r}")
    w = omega / problem.period
    H = problem.basis.harmonics
    dt = 2.0 * np.pi / w / N
    qm = _shifted(np.asarray(q, dtype=float), H, 0.5 * w * dt)  # samples at the step midpoints
    if N == problem.basis.samples:
        d = problem.basis.synthesize(qm)
        v = problem.basis.synthesize(w * (problem.basis.derivative_matrix(1.0) @ qm))
    else:
        t = np.arange(N) * dt
        d = problem.basis.evaluate(qm, w, t)
        v = problem.basis.evaluate(qm, w, t, derivative=1)
    _, g_d, g_v = problem.force.regularised(d, v, *problem.widths)
    return _ordered_product(_expm_companion(-g_d, -(problem.c + g_v), dt))


def regularised_multipliers(problem: RegularisedBalance, q: FloatArray, omega: float,
                            steps: int | None = None) -> ComplexArray:
    """The Floquet multipliers of :func:`regularised_monodromy`, largest modulus first."""
    mu = np.linalg.eigvals(regularised_monodromy(problem, q, omega, steps)).astype(complex)
    return mu[np.argsort(-np.abs(mu), kind="stable")]


__all__ = ["regularised_monodromy", "regularised_multipliers"]
