"""Stability from Floquet multipliers and the type of a change of stability.

With n coordinates the monodromy has 2n multipliers (real, or complex-conjugate pairs). An orbit
loses (or regains) stability when one of them leaves (enters) the unit circle: a real multiplier
through +1 (fold), a real one through −1 (period doubling), or a complex pair μ = r e^{±iθ}
through r = 1 (Neimark–Sacker: a torus is born whose second frequency is θ/2π times the orbit's
base frequency ω, :func:`torus_ratio`). With one coordinate det M = e^{−cT} < 1 and the last
never happens.
"""

from __future__ import annotations

import numpy as np

from .._typing import ComplexArray

#: Multipliers are on the unit circle within this distance when stability is decided; the
#: HB orbit's multipliers carry errors of this order only at extreme harmonic truncation.
UNIT_CIRCLE_TOL = 1e-9

#: A multiplier is complex (one of a conjugate pair) when |Im μ| exceeds this times max(1, |μ|):
#: real multipliers come out of the 2×2 closed form and of LAPACK with Im μ = 0 exactly, or
#: ~1e-16 from a general solver.
COMPLEX_TOL = 1e-8


def is_stable(multipliers: ComplexArray) -> bool:
    """All multipliers strictly inside the unit circle."""
    return bool(np.max(np.abs(multipliers)) < 1.0 - UNIT_CIRCLE_TOL)


def _is_complex(mu: complex) -> bool:
    return abs(mu.imag) > COMPLEX_TOL * max(1.0, abs(mu))


def _critical(before: ComplexArray, after: ComplexArray) -> complex:
    """The multiplier that crossed: the largest-modulus one of the unstable side."""
    before, after = np.asarray(before), np.asarray(after)
    unstable = after if np.max(np.abs(after)) >= np.max(np.abs(before)) else before
    return complex(unstable[np.argmax(np.abs(unstable))])


def classify_loss(before: ComplexArray, after: ComplexArray) -> str:
    """Name the bifurcation between two consecutive points of different stability.

    The arguments are the 2n multipliers at either point. The critical multiplier is the
    largest-modulus one at the unstable side: it left (or re-entered) the unit circle through
    +1 (``fold``), through −1 (``period_doubling``) or as a complex pair (``neimark_sacker``).
    """
    mu = _critical(before, after)
    if _is_complex(mu):
        return "neimark_sacker"
    return "fold" if mu.real > 0 else "period_doubling"


def torus_ratio(multipliers: ComplexArray) -> float:
    """θ/2π ∈ [0, 0.5] of the complex pair μ = r e^{±iθ} nearest the unit circle.

    At a Neimark–Sacker point this is the critical frequency ratio of the torus: the new
    frequency is θ/2π times the orbit's base frequency ω (defined modulo 1 and up to sign, so
    reported in [0, 0.5]). NaN when no multiplier is complex. ``multipliers`` (..., 2n) gives
    an array of shape (...).
    """
    mu = np.asarray(multipliers, dtype=complex)
    cplx = np.abs(mu.imag) > COMPLEX_TOL * np.maximum(1.0, np.abs(mu))
    dist = np.where(cplx, np.abs(np.abs(mu) - 1.0), np.inf)
    k = np.argmin(dist, axis=-1)
    pick = np.take_along_axis(mu, k[..., None], axis=-1)[..., 0]
    ratio = np.abs(np.angle(pick)) / (2 * np.pi)
    ratio = np.where(np.any(cplx, axis=-1), ratio, np.nan)
    return float(ratio) if ratio.ndim == 0 else ratio


def critical_distance(multipliers: ComplexArray) -> float:
    """Distance of the nearest multiplier to where it would change the stability: |μ − 1| or
    |μ + 1| for every multiplier, and ||μ| − 1| for a complex one (n ≥ 2 only can reach it)."""
    mu = np.asarray(multipliers, dtype=complex)
    d = np.minimum(np.abs(mu - 1.0), np.abs(mu + 1.0))
    if mu.shape[-1] > 2:
        cplx = np.abs(mu.imag) > COMPLEX_TOL * np.maximum(1.0, np.abs(mu))
        d = np.where(cplx, np.minimum(d, np.abs(np.abs(mu) - 1.0)), d)
    dmin = float(np.min(d))
    return dmin if np.isfinite(dmin) else float("inf")


__all__ = ["is_stable", "classify_loss", "torus_ratio", "critical_distance", "UNIT_CIRCLE_TOL", "COMPLEX_TOL"]
