"""Stability from Floquet multipliers and the type of a change of stability."""

from __future__ import annotations

import numpy as np

from .._typing import ComplexArray

#: Multipliers are on the unit circle within this distance when stability is decided; the
#: HB orbit's multipliers carry errors of this order only at extreme harmonic truncation.
UNIT_CIRCLE_TOL = 1e-9


def is_stable(multipliers: ComplexArray) -> bool:
    """All multipliers strictly inside the unit circle."""
    return bool(np.max(np.abs(multipliers)) < 1.0 - UNIT_CIRCLE_TOL)


def classify_loss(before: ComplexArray, after: ComplexArray) -> str:
    """Name the bifurcation between two consecutive points of different stability.

    The critical multiplier is the largest-modulus one at the unstable side: it left (or
    re-entered) the unit circle through +1 (``fold``), through −1 (``period_doubling``) or as
    a complex pair (``neimark_sacker``).
    """
    unstable = after if np.max(np.abs(after)) >= np.max(np.abs(before)) else before
    mu = unstable[np.argmax(np.abs(unstable))]
    # A complex pair has |Im μ| well away from 0; real multipliers come out of the 2×2 eigen-
    # problem with Im μ = 0 exactly, or ~1e-16 from a general solver.
    if abs(mu.imag) > 1e-8 * max(1.0, abs(mu)):
        return "neimark_sacker"
    return "fold" if mu.real > 0 else "period_doubling"


__all__ = ["is_stable", "classify_loss", "UNIT_CIRCLE_TOL"]
