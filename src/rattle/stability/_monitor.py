"""Floquet test functions along a harmonic-balance branch, for the continuation's step control.

At a point (q, Ω) of the branch the exact monodromy M (2n × 2n) of the piecewise-linear
linearisation about the HB orbit (``_floquet``) gives the test functions

    ψ_fold = det(M − I) = Π (μ_k − 1),     ψ_pd = det(M + I) = Π (μ_k + 1),
    ψ_ns = det(M ⊙ M − I) = Π_{i<j} (μ_i μ_j − 1)    (n ≥ 2),

whose zeros are the folds (a multiplier at +1), the period doublings (a multiplier at −1) and
the Neimark–Sacker points (a complex pair on the unit circle; ψ_ns also vanishes at a neutral
saddle, a real pair with μ_i μ_j = 1, which the labelling tells apart). With one coordinate,
det M = e^{−cT} < 1 and no complex pair can reach the unit circle: only the first two are
monitored. All are polynomials in the entries of M, so they are smooth where M is — unlike the
multipliers themselves, which move with infinite speed where a complex pair meets the real axis —
and M is smooth in (q, Ω) except where the orbit grazes a breakpoint, which the crossing counts
per element and breakpoint (the reading's ``structure``) reveal.

Their derivative along the branch is the forward difference quotient (ψ(x + ε d) − ψ(x))/ε
along the unit tangent d, ε = 1e-7 in scaled arc length: the truncation error O(ε ψ'') is far
below what the step control needs, and the round-off ~1e-16/ε stays below 1e-8 of ψ. Where
the shifted point grazes (a different structure) the backward quotient is taken instead.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .._typing import FloatArray
from ..continuation import MonitorReading
from ..hb import HarmonicBalance
from .. import hb as fft  # its compiled rfft/irfft
from ..model import System
from ._classify import critical_distance
from ._floquet import (
    TEST_FUNCTIONS, element_monodromy_batch, floquet_test_functions, monodromy_and_crossings_batch,
    multipliers_from_monodromy,
)

#: Difference step in scaled arc length for the test functions' derivative.
EPSILON = 1e-7
#: Orbits whose monodromy a monitor remembers (readings, test functions); all are forgotten when full.
MEMO = 20000


def hb_system(hb: HarmonicBalance) -> System:
    """The :class:`~rattle.model.System` of a harmonic-balance problem (``hb.system`` when it has
    one, else its model's)."""
    system = getattr(hb, "system", None)
    return system if system is not None else hb.model.system()


class FloquetMonitor:
    """Test functions ψ_fold, ψ_pd (and ψ_ns for n ≥ 2) with slopes and crossing structure of
    ``hb``'s orbits.

    Callable as ``monitor(q, Ω, dq/ds, dΩ/ds)`` (see ``rattle.continuation._monitor``); the
    tangent is per unit scaled arc length, so ``EPSILON`` is a step in scaled variables. ``q``
    holds the n·(2H+1) coefficients coordinate-major.
    """

    def __init__(self, hb: HarmonicBalance) -> None:
        self.hb = hb
        self.system = hb_system(hb)
        system = self.system
        self.names = TEST_FUNCTIONS[:2] if system.n == 1 else TEST_FUNCTIONS
        self._cache: dict = {}
        self._buffers: dict = {}
        self._memo: dict = {}
        # The single element of the single equation: the closed-form path on q itself.
        self._single = system.n == 1 and system.m == 1 and float(system.element_rows[0, 0]) == 1.0
        if self._single:
            e = system.elements[0]
            self._breakpoints = np.ascontiguousarray(np.atleast_1d(np.asarray(e.breakpoints, dtype=float)))
            self._stiffness = np.array([system.stage_stiffness((j,))[0, 0] for j in range(len(e.slopes))])
            self._damping = float(system.damping[0, 0])
        self._rows = system.element_rows

    def monodromy_and_crossings(self, Q: FloatArray, Om: FloatArray) -> tuple[FloatArray, np.ndarray]:
        """Monodromies (P, 2n, 2n) and crossings (P, m, k_max) of the orbits ``Q`` (P, n·(2H+1))
        at forcing frequencies ``Om`` (P,) (arrays).

        The monitor remembers the monodromy of every point it has read (the first of a reading's
        two orbits, P = 2) and of every single orbit (a test function), by its exact (Ω, q), up
        to ``MEMO`` of them; one orbit or a batch (the multipliers of a branch's points, which
        were the readings' points) takes the remembered ones and computes the rest."""
        if Q.shape[0] == 2:  # a reading: the point and its neighbour along the tangent
            M, counts = self._compute(Q, Om)
            self._remember(Q[0], float(Om[0]), M[0], counts[0])
            return M, counts
        memo = self._memo
        found = [memo.get((float(w), q.tobytes())) for q, w in zip(Q, Om)]
        missing = [i for i, f in enumerate(found) if f is None]
        if not missing:
            return np.stack([f[0] for f in found]), np.stack([f[1] for f in found])
        if len(missing) == len(found):
            M, counts = self._compute(Q, Om)
        else:
            M_new, counts_new = self._compute(Q[missing], Om[missing])
            for j, i in enumerate(missing):
                found[i] = (M_new[j], counts_new[j])
            M, counts = np.stack([f[0] for f in found]), np.stack([f[1] for f in found])
        if Q.shape[0] == 1:
            self._remember(Q[0], float(Om[0]), M[0], counts[0])
        return M, counts

    def _remember(self, q: FloatArray, omega: float, M: FloatArray, counts: np.ndarray) -> None:
        """Keep the monodromy and crossings of the orbit (q, Ω) (all forgotten once ``MEMO`` are
        kept)."""
        if len(self._memo) >= MEMO:
            self._memo.clear()
        self._memo[(omega, q.tobytes())] = (M.copy(), counts.copy())

    def _compute(self, Q: FloatArray, Om: FloatArray) -> tuple[FloatArray, np.ndarray]:
        hb = self.hb
        w = Om / hb.period
        if self._single:
            M, counts = monodromy_and_crossings_batch(Q, w, self._samples(Q), self._breakpoints, self._stiffness,
                                                      self._damping)
            return M, counts[:, None, :]
        S = np.einsum("en,pnk->pek", self._rows, Q.reshape(Q.shape[0], self.system.n, -1))
        return element_monodromy_batch(self.system, S, w, hb.basis.synthesize(S), cache=self._cache)

    def _samples(self, Q: FloatArray) -> FloatArray:
        """``hb.basis.synthesize(Q)`` (P, N); for the one or two orbits of a reading into buffers
        kept between calls, by the inverse FFT without numpy.fft's wrapper (the array returned
        is overwritten by the next call)."""
        P = Q.shape[0]
        if P > 2:
            return self.hb.basis.synthesize(Q)
        basis = self.hb.basis
        H, N = basis.harmonics, basis.samples
        buffers = self._buffers.get(P)
        if buffers is None:
            buffers = self._buffers[P] = (np.zeros((P, N // 2 + 1), dtype=complex), np.empty((P, N)))
        spec, out = buffers
        re, im = spec.real, spec.imag
        np.multiply(Q[:, :1], N, out=re[:, :1])
        np.multiply(Q[:, 1 : H + 1], 0.5 * N, out=re[:, 1 : H + 1])
        np.multiply(Q[:, H + 1 :], -0.5 * N, out=im[:, 1 : H + 1])
        return fft.irfft(spec, out)

    def monodromy(self, q: FloatArray, omega: float) -> FloatArray:
        """The exact monodromy (2n, 2n) of the orbit q at forcing frequency Ω."""
        return self.monodromy_and_crossings(np.asarray(q, dtype=float)[None, :], np.array([float(omega)]))[0][0]

    def test_functions(self, q: FloatArray, omega: float) -> FloatArray:
        """The monitored ψ (fold, period doubling[, Neimark–Sacker for n ≥ 2]) at one point,
        in the order of ``names``."""
        return floquet_test_functions(self.monodromy(q, omega))

    def test_function(self, kind: str) -> Callable[[FloatArray, float], float]:
        """ψ_kind(q, Ω) for ``kind`` "fold" (det(M − I)), "period_doubling" (det(M + I)) or
        "neimark_sacker" (det(M ⊙ M − I); for n = 1 the 1 × 1 bialternate product is det M, so
        this is det M − 1, which never vanishes for damping c > 0): a scalar function whose zero
        between two branch points locates the special point (e.g. with
        ``continuation.locate_on_segment``)."""
        if kind not in TEST_FUNCTIONS:
            raise ValueError(f"`kind` must be one of {TEST_FUNCTIONS}, got {kind!r}")
        i = TEST_FUNCTIONS.index(kind)
        if i < 2 or self.system.n > 1:
            return lambda q, omega: float(self.test_functions(q, omega)[i])
        return lambda q, omega: float(np.linalg.det(self.monodromy(q, omega)) - 1.0)

    def _evaluate(self, Q: FloatArray, Om: FloatArray) -> tuple[FloatArray, np.ndarray, FloatArray]:
        M, counts = self.monodromy_and_crossings(Q, Om)
        return floquet_test_functions(M), counts, M

    def _structure(self, counts: np.ndarray) -> tuple[int, ...]:
        if self._single:
            return tuple(int(c) for c in counts[0])
        return tuple(int(c) for e, el in enumerate(self.system.elements) for c in counts[e, : len(el.breakpoints)])

    def __call__(self, q: FloatArray, omega: float, dq: FloatArray, domega: float) -> MonitorReading:
        eps = EPSILON
        if self._single:
            return self._single_reading(q, omega, dq, domega)
        psi, counts, M = self._evaluate(np.stack([q, q + eps * dq]), np.array([omega, omega + eps * domega]))
        here = self._structure(counts[0])
        if self._structure(counts[1]) == here:
            slopes = (psi[1] - psi[0]) / eps
        else:  # the forward point grazes: take the backward difference
            psi_b, counts_b, _ = self._evaluate((q - eps * dq)[None, :], np.array([omega - eps * domega]))
            if self._structure(counts_b[0]) == here:
                slopes = (psi[0] - psi_b[0]) / eps
            else:  # grazing within ±ε: no derivative; the stepper treats the point as a kink
                slopes = np.full(psi.shape[1], np.nan)
        distance = critical_distance(multipliers_from_monodromy(M[0])) if np.isfinite(M[0]).all() else math.inf
        return MonitorReading(psi[0], slopes, here, distance)

    def _single_reading(self, q: FloatArray, omega: float, dq: FloatArray, domega: float) -> MonitorReading:
        """:meth:`__call__` of the single equation: the same reading from 2 × 2 closed forms in
        Python floats (ψ, the multipliers' distance), as numpy's per-call cost dominates there."""
        eps = EPSILON
        Q = np.empty((2, q.size))
        Q[0] = q
        np.multiply(dq, eps, out=Q[1])
        Q[1] += q
        M, counts = self.monodromy_and_crossings(Q, np.array([omega, omega + eps * domega]))
        here = tuple(counts[0, 0].tolist())
        m = M.tolist()
        psi = _psi_2x2(m[0])
        if tuple(counts[1, 0].tolist()) == here:
            psi_f = _psi_2x2(m[1])
            slopes = ((psi_f[0] - psi[0]) / eps, (psi_f[1] - psi[1]) / eps)
        else:  # the forward point grazes: take the backward difference
            Mb, counts_b = self.monodromy_and_crossings((q - eps * dq)[None, :], np.array([omega - eps * domega]))
            if tuple(counts_b[0, 0].tolist()) == here:
                psi_b = _psi_2x2(Mb[0].tolist())
                slopes = ((psi[0] - psi_b[0]) / eps, (psi[1] - psi_b[1]) / eps)
            else:  # grazing within ±ε: no derivative; the stepper treats the point as a kink
                slopes = (math.nan, math.nan)
        return MonitorReading(np.array(psi), np.array(slopes), here, _distance_2x2(m[0]))


def _psi_2x2(m: list) -> tuple[float, float]:
    """det(M − I), det(M + I) of a 2 × 2 monodromy given as nested lists."""
    (a, b), (c, d) = m
    return (a - 1.0) * (d - 1.0) - b * c, (a + 1.0) * (d + 1.0) - b * c


def _distance_2x2(m: list) -> float:
    """:func:`~rattle.stability.critical_distance` of the multipliers of a 2 × 2 monodromy
    (nested lists), from the closed form of :func:`multipliers_from_monodromy`."""
    (a, b), (c, d) = m
    tr, det = a + d, a * d - b * c
    if not all(math.isfinite(v) for v in (a, b, c, d)):
        return math.inf
    disc = 0.25 * (tr * tr) - det
    root = math.sqrt(abs(disc))
    if disc >= 0:
        big = 0.5 * tr + math.copysign(root, tr)
        small = det / big if big != 0 else 0.0
        out = min(abs(big - 1.0), abs(big + 1.0), abs(small - 1.0), abs(small + 1.0))
    else:
        out = min(math.hypot(0.5 * tr - 1.0, root), math.hypot(0.5 * tr + 1.0, root))
    return out if math.isfinite(out) else math.inf

__all__ = ["FloquetMonitor", "EPSILON", "hb_system"]
