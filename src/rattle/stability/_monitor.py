"""Floquet test functions along a harmonic-balance branch, for the continuation's step control.

At a point (q, Ω) of the branch the exact monodromy M of the piecewise-linear linearisation
about the HB orbit (``_floquet``) gives the test functions

    ψ_fold = det(M − I) = Π (μ_k − 1),     ψ_pd = det(M + I) = Π (μ_k + 1),

whose zeros are the folds (a multiplier at +1) and the period doublings (a multiplier at −1).
(Neimark–Sacker needs two or more coordinates: with one, det M = e^{−cT} < 1 and no complex
pair can reach the unit circle.) Both are polynomials in the entries of M, so they are smooth
where M is — unlike the multipliers themselves, which move with infinite speed where a complex
pair meets the real axis — and M is smooth in (q, Ω) except where the orbit grazes a
breakpoint, which the crossing counts per breakpoint (the reading's ``structure``) reveal.

Their derivative along the branch is the forward difference quotient (ψ(x + ε d) − ψ(x))/ε
along the unit tangent d, ε = 1e-7 in scaled arc length: the truncation error O(ε ψ'') is far
below what the step control needs, and the round-off ~1e-16/ε stays below 1e-8 of ψ. Where
the shifted point grazes (a different structure) the backward quotient is taken instead.
"""

from __future__ import annotations

import math

import numpy as np

from .._typing import FloatArray
from ..continuation import MonitorReading
from ..hb import HarmonicBalance
from ._floquet import monodromy_and_crossings_batch, multipliers_from_monodromy

#: Difference step in scaled arc length for the test functions' derivative.
EPSILON = 1e-7


class FloquetMonitor:
    """Test functions ψ_fold, ψ_pd (with slopes and crossing structure) of ``hb``'s orbits.

    Callable as ``monitor(q, Ω, dq/ds, dΩ/ds)`` (see ``rattle.continuation._monitor``); the
    tangent is per unit scaled arc length, so ``EPSILON`` is a step in scaled variables.
    """

    def __init__(self, hb: HarmonicBalance) -> None:
        self.hb = hb
        st = hb.model.elastic.stages
        self._breakpoints = np.asarray(st.breakpoints, dtype=float)
        self._stiffness = hb.model.k * np.asarray(st.slopes, dtype=float)
        self._damping = hb.model.c

    def _evaluate(self, Q: FloatArray, Om: FloatArray) -> tuple[FloatArray, np.ndarray, FloatArray]:
        hb = self.hb
        X = hb.basis.synthesize(Q)
        M, counts = monodromy_and_crossings_batch(Q, Om / hb.period, X, self._breakpoints, self._stiffness, self._damping)
        n = M.shape[-1]
        eye = np.eye(n)
        with np.errstate(over="ignore", invalid="ignore"):
            psi = np.stack([np.linalg.det(M - eye), np.linalg.det(M + eye)], axis=-1)
        return psi, counts, M

    def __call__(self, q: FloatArray, omega: float, dq: FloatArray, domega: float) -> MonitorReading:
        eps = EPSILON
        psi, counts, M = self._evaluate(np.stack([q, q + eps * dq]), np.array([omega, omega + eps * domega]))
        here = tuple(int(c) for c in counts[0])
        if tuple(int(c) for c in counts[1]) == here:
            slopes = (psi[1] - psi[0]) / eps
        else:  # the forward point grazes: take the backward difference
            psi_b, counts_b, _ = self._evaluate((q - eps * dq)[None, :], np.array([omega - eps * domega]))
            if tuple(int(c) for c in counts_b[0]) == here:
                slopes = (psi[0] - psi_b[0]) / eps
            else:  # grazing within ±ε: no derivative; the stepper treats the point as a kink
                slopes = np.full(2, np.nan)
        if np.all(np.isfinite(M[0])):
            mu = multipliers_from_monodromy(M[0])
            distance = float(np.min(np.minimum(np.abs(mu - 1.0), np.abs(mu + 1.0))))
        else:
            distance = math.inf
        return MonitorReading(psi[0], slopes, here, distance)


__all__ = ["FloquetMonitor", "EPSILON"]
