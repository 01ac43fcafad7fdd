"""Floquet exponents by Hill's method on the harmonic-balance Jacobian.

A perturbation y(t) = e^{λt} Σ_k Y_k e^{ikωt} of the orbit satisfies the quadratic eigenproblem

    (λ² I + λ (2∇ + c I) + ∂R/∂q) Y = 0,

with ∇ the derivative operator of the real Fourier basis and ∂R/∂q the HB Jacobian. Its
2(2H+1) eigenvalues approximate the true exponents λ_r shifted by i m ω, m = −H … H; only two
(one per state) are physical. The usual rule (smallest |Im λ|) fails when the physical exponent
itself has |Im λ| near ω/2 (period doubling) and when truncated copies cross over. We select
instead by the eigenvector (Lazarus & Thomas 2010; Guillot et al. 2020): the eigenvector of the
copy shifted by m ω is the physical one shifted by m harmonics, so the physical copies are
those whose harmonic energy |Y_k|² is centred on k = 0 — we take the 2 eigenvalues whose
eigenvector centroid Σ k |Y_k|² / Σ |Y_k|² is closest to zero. Taking the two best centroids
is still fragile: a real multiplier's exponent and its conjugate are copies of each other
(at period doubling both sit at centroid ±½). For the single-DOF equation we therefore take
only the best-centred exponent λ_1 and obtain the other from Liouville's formula: every stage
matrix has trace −c, so λ_1 + λ_2 = −c (mod iω) and μ_2 = e^{−cT} / μ_1 exactly.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._typing import ComplexArray, FloatArray
from ..hb import HarmonicBalance


def hill_exponents(hb: HarmonicBalance, q: FloatArray, omega: float) -> ComplexArray:
    """The two physical Floquet exponents λ of the HB orbit q at forcing frequency Ω."""
    H = hb.basis.harmonics
    n = hb.size
    w = hb.base_frequency(omega)
    _, Rq, _ = hb.residual_jacobian(q, omega)
    D1 = 2.0 * hb.basis.derivative_matrix(w) + hb.model.c * np.eye(n)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -Rq
    A[n:, n:] = -D1
    lam, vec = scipy.linalg.eig(A, check_finite=False)
    Y = vec[:n]
    a, b = Y[1 : H + 1], Y[H + 1 :]
    # Complex harmonic amplitudes of e^{ikωt}: k > 0 ↔ (a − i b)/2, k < 0 ↔ (a + i b)/2.
    w_pos = np.abs(0.5 * (a - 1j * b)) ** 2
    w_neg = np.abs(0.5 * (a + 1j * b)) ** 2
    k = np.arange(1, H + 1)[:, None]
    total = np.abs(Y[0]) ** 2 + np.sum(w_pos + w_neg, axis=0)
    centroid = np.sum(k * (w_pos - w_neg), axis=0) / total
    lam1 = lam[int(np.argmin(np.abs(centroid)))]
    return np.array([lam1, -hb.model.c - lam1])


def hill_multipliers(hb: HarmonicBalance, q: FloatArray, omega: float) -> ComplexArray:
    """Floquet multipliers exp(λ T_p), T_p = p 2π/Ω, from :func:`hill_exponents`, largest first.

    The monodromy of the single-DOF equation is a real 2×2 matrix with det M = e^{−cT}, so its
    multipliers are either a complex-conjugate pair on the circle |μ| = e^{−cT/2} or two real
    numbers with product e^{−cT}. Hill's exponent carries a truncation error in both parts, which
    would otherwise make a real multiplier come out slightly complex (and a period doubling be
    named a Neimark–Sacker bifurcation). The pair is therefore projected onto the nearer of the
    two admissible structures: with λ_1 = a + i b, the distance to the circle is |a + c/2| T and
    the distance to the real axis is that of bT from the nearest multiple of π; the nearer one wins
    (real: μ_1 = ±e^{aT}, μ_2 = e^{−cT}/μ_1; circle: μ = e^{−cT/2} e^{±ibT}).
    """
    lam = hill_exponents(hb, q, omega)
    period = 2 * np.pi / hb.base_frequency(omega)
    c = hb.model.c
    a, b = float(lam[0].real), float(lam[0].imag)
    to_circle = abs(a + 0.5 * c) * period
    phase = b * period
    k = round(phase / np.pi)
    to_axis = abs(phase - k * np.pi)
    with np.errstate(over="ignore", under="ignore"):
        if to_axis <= to_circle:
            mu1 = np.exp(a * period) * (-1.0 if k % 2 else 1.0)
            mu2 = np.exp(-c * period) / mu1 if mu1 != 0.0 else 0.0
            mu = np.array([mu1, mu2], dtype=complex)
        else:
            r = np.exp(-0.5 * c * period)
            mu = np.array([r * np.exp(1j * phase), r * np.exp(-1j * phase)])
    return mu[np.argsort(-np.abs(mu), kind="stable")]


__all__ = ["hill_exponents", "hill_multipliers"]
