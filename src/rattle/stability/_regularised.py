"""Floquet multipliers of a regularised harmonic-balance orbit (preload, friction).

**One coordinate.** The regularised equation δ'' + c δ' + g_ε(δ, δ') = F(t) (:class:`~rattle.hb.RegularisedBalance`)
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

**A chain** with friction on its elements (:class:`~rattle.hb.RegularisedSystemBalance`;
x ∈ ℝⁿ, δ_e = a_e·x, the element's column b_e):

    x'' + C x' + K x + Σ_e b_e g_ε,e(δ_e, δ_e') = F(t)

is linearised the same way, with y = (Δx, Δx') (2n):

    A(t) = [[0, I], [−(K + Σ_e b_e a_eᵀ ∂g_e/∂δ), −(C + Σ_e b_e a_eᵀ ∂g_e/∂δ')]],

and the same exponential midpoint rule (2n × 2n exponentials,
:func:`regularised_system_monodromy`). This is the HB orbit's own stability: it reads only the HB
series, not the exact flow. Where a stick phase appears or vanishes along a branch (a grazing-
sliding point), the exact multipliers jump; the regularised ones pass through the change over a
range of Ω that narrows with ε.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._typing import ComplexArray, FloatArray
from ..hb import RegularisedBalance, RegularisedSystemBalance
from ..timeint import monodromy_multipliers


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
            E = np.concatenate((E, np.eye(E.shape[1])[None]))
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
    return monodromy_multipliers(regularised_monodromy(problem, q, omega, steps))


def regularised_system_monodromy(problem: RegularisedSystemBalance, q: FloatArray, omega: float,
                                 steps: int | None = None) -> FloatArray:
    """M (2n, 2n) of the regularised chain's orbit with coefficients ``q`` (n·(2H+1),) at forcing
    frequency ``omega`` over its period p·2π/Ω: the ordered product of exp(A(t_{j+½}) Δt) (module
    docstring), ``steps`` N (default the AFT samples)."""
    if not isinstance(problem, RegularisedSystemBalance):
        raise TypeError(f"`problem` must be a rattle.hb.RegularisedSystemBalance, got {problem!r}")
    N = problem.basis.samples if steps is None else int(steps)
    if N < 8:
        raise ValueError(f"`steps` must be >= 8, got {steps!r}")
    system = problem.system
    n, m = system.n, system.m
    w = omega / problem.period
    dt = 2.0 * np.pi / w / N
    t = (np.arange(N) + 0.5) * dt  # the step midpoints
    E = problem.element_series(np.asarray(q, dtype=float))  # (m, 2H+1)
    rows = system.element_rows.reshape(m, n)
    cols = system.element_columns.reshape(n, m)
    Kt = np.broadcast_to(np.asarray(system.stiffness, dtype=float), (N, n, n)).copy()
    Ct = np.broadcast_to(np.asarray(system.damping, dtype=float), (N, n, n)).copy()
    for e, (law, (ed, ev)) in enumerate(zip(problem.fsys.laws, problem.element_widths)):
        d = problem.basis.evaluate(E[e], w, t)
        v = problem.basis.evaluate(E[e], w, t, derivative=1)
        _, g_d, g_v = law.regularised(d, v, float(ed), float(ev))
        W = np.outer(cols[:, e], rows[e])  # b_e a_eᵀ
        Kt += g_d[:, None, None] * W
        Ct += g_v[:, None, None] * W
    A = np.zeros((N, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:, :n] = -Kt
    A[:, n:, n:] = -Ct
    return _ordered_product(scipy.linalg.expm(A * dt))


def regularised_system_multipliers(problem: RegularisedSystemBalance, q: FloatArray, omega: float,
                                   steps: int | None = None) -> ComplexArray:
    """The 2n Floquet multipliers of :func:`regularised_system_monodromy`, largest modulus first."""
    return monodromy_multipliers(regularised_system_monodromy(problem, q, omega, steps))


__all__ = ["regularised_monodromy", "regularised_multipliers", "regularised_system_monodromy",
           "regularised_system_multipliers"]
