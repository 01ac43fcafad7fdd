"""exp(A τ) of one stage of the single equation in closed form: the one formula of rattle.

On a stage of slope s the linearised single equation δ'' + c δ' + κ δ = … (κ = k s ≥ 0) has
the state matrix A = [[0, 1], [−κ, −c]]. With σ = c/2 and D = σ² − κ its exponential is

    under-damped (D < 0), ω_d = √−D:
        exp(Aτ) = e^{−στ} [[cos ω_dτ + σ S, S], [−κ S, cos ω_dτ − σ S]],  S = sin(ω_dτ)/ω_d;
    critically and over-damped (D ≥ 0), γ = √D, eigenvalues λ₂ = −(σ + γ) ≤ λ₁ = −κ/(σ + γ) ≤ 0:
        Φ₁₂ = (e^{λ₁τ} − e^{λ₂τ})/(λ₁ − λ₂) = e^{λ₁τ} (−expm1(−2γτ))/(2γ)   (τ e^{λ₁τ} at γ = 0),
        exp(Aτ) = [[e^{λ₁τ} − λ₁ Φ₁₂, Φ₁₂], [−κ Φ₁₂, e^{λ₂τ} + λ₁ Φ₁₂]].

λ₁ is written without cancellation (a slow mode of a soft stage, κ ≪ σ²), and only
exponentials of non-positive arguments appear (κ ≥ 0), so an over-damped stage neither
overflows nor loses digits. Nothing else in rattle writes this matrix: the exact integrator of
the single equation (:mod:`rattle.timeint`) and the monodromy of the single-element
linearisation (:mod:`rattle.stability`) both evaluate it here — :func:`transition_entries` on
arrays, :func:`transition_scalar` the same lines in Python floats for the per-segment hot loops
(numpy's per-call cost exceeds the arithmetic on scalars). numpy only.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._typing import FloatArray

__all__ = ["StageConstants", "stage_constants", "transition_entries", "transition_scalar", "stage_transition"]


class StageConstants(NamedTuple):
    """The constants of exp(A τ) per stage (arrays broadcast like the stiffness given):
    ``sigma`` = c/2, ``under`` (D < 0), ``wd`` = √−D (0 unless under), ``gamma`` = √D (0 if
    under), ``lam1`` (slow) and ``lam2`` (fast) real eigenvalues (of an over- or critically damped
    stage), ``kappa`` the stiffness."""

    sigma: float
    under: np.ndarray
    wd: FloatArray
    gamma: FloatArray
    lam1: FloatArray
    lam2: FloatArray
    kappa: FloatArray


def stage_constants(stiffness: FloatArray | float, damping: float) -> StageConstants:
    """:class:`StageConstants` of the stages of stiffness κ = ``stiffness`` (≥ 0) and damping c."""
    kappa = np.asarray(stiffness, dtype=float)
    sigma = 0.5 * float(damping)
    disc = sigma * sigma - kappa
    under = disc < 0.0
    wd = np.sqrt(np.where(under, -disc, 0.0))
    gamma = np.sqrt(np.where(under, 0.0, disc))
    s_plus = sigma + gamma
    lam2 = -s_plus
    lam1 = np.where(s_plus > 0.0, -kappa / np.where(s_plus > 0.0, s_plus, 1.0), 0.0)
    return StageConstants(sigma, under, wd, gamma, lam1, lam2, kappa)


def transition_entries(const: StageConstants, tau: FloatArray | float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(Φ₁₁, Φ₁₂, Φ₂₁, Φ₂₂) of exp(A τ), elementwise over the stages of ``const`` and ``tau``
    (broadcast; the module docstring's formula)."""
    tau = np.asarray(tau, dtype=float)
    sigma = const.sigma
    kappa, under, wd, gamma, lam1 = const.kappa, const.under, const.wd, const.gamma, const.lam1
    every = bool(np.all(under))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        if every or np.any(under):  # under-damped
            e = np.exp(-sigma * tau)
            co = np.cos(wd * tau)
            s = np.sin(wd * tau) / np.where(wd > 0.0, wd, 1.0)
            es = e * s
            u11, u22 = e * (co + sigma * s), e * (co - sigma * s)
            if every:
                return u11, es, -kappa * es, u22
        # critically and over-damped: e^{λ₂τ} = e^{λ₁τ} e^{−2γτ} (λ₁ − λ₂ = 2γ)
        e1 = np.exp(lam1 * tau)
        m1 = np.expm1(-2.0 * gamma * tau)
        p12 = np.where(gamma > 0.0, e1 * -m1 / np.where(gamma > 0.0, 2.0 * gamma, 1.0), tau * e1)
        o11, o22 = e1 - lam1 * p12, e1 * (1.0 + m1) + lam1 * p12
        if not np.any(under):
            return o11, p12, -kappa * p12, o22
        f11 = np.where(under, u11, o11)
        f12 = np.where(under, es, p12)
        f21 = -kappa * f12
        f22 = np.where(under, u22, o22)
    return f11, f12, f21, f22


def transition_scalar(sigma: float, under: bool, wd: float, gamma: float, lam1: float, lam2: float, kappa: float,
                      tau: float) -> tuple[float, float, float, float]:
    """(Φ₁₁, Φ₁₂, Φ₂₁, Φ₂₂) of one stage at one τ in Python floats: :func:`transition_entries`
    line for line (the constants of one stage of :func:`stage_constants`, as floats)."""
    if under:
        e = math.exp(-sigma * tau)
        co = math.cos(wd * tau)
        s = math.sin(wd * tau) / wd
        return e * (co + sigma * s), e * s, -kappa * e * s, e * (co - sigma * s)
    e1 = math.exp(lam1 * tau)
    m1 = math.expm1(-2.0 * gamma * tau)
    p12 = e1 * -m1 / (2.0 * gamma) if gamma > 0.0 else tau * e1
    return e1 - lam1 * p12, p12, -kappa * p12, e1 * (1.0 + m1) + lam1 * p12


def stage_transition(stiffness: FloatArray, damping: float, tau: FloatArray) -> FloatArray:
    """exp(A τ) for A = [[0, 1], [−κ, −c]], elementwise over κ = ``stiffness`` (≥ 0) and
    ``tau`` (broadcast): shape (..., 2, 2)."""
    kappa, tau = np.broadcast_arrays(np.asarray(stiffness, dtype=float), np.asarray(tau, dtype=float))
    f11, f12, f21, f22 = transition_entries(stage_constants(kappa, damping), tau)
    out = np.empty(kappa.shape + (2, 2))
    out[..., 0, 0] = f11
    out[..., 0, 1] = f12
    out[..., 1, 0] = f21
    out[..., 1, 1] = f22
    return out
