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

For a :class:`~rattle.model.System` of n ≥ 2 coordinates (q coordinate-major, n blocks of
2H + 1) the same problem reads

    (λ² I + λ (2 I_n ⊗ ∇ + C ⊗ I) + J) Y = 0,
    J = I_n ⊗ ∇² + C ⊗ ∇ + K ⊗ I + Σ_e (b_e a_eᵀ) ⊗ Γ* diag(f_e'(δ_e(t_j))) Γ,

J the HB Jacobian ∂R/∂q, built here from the System and the element stiffness samples (the
check does not depend on how the HB problem assembles or condenses its own). 2n exponents are
physical; they are chosen by eigenvector centroid (|centroid| smallest first), skipping every
candidate that is a copy λ + i m ω (m ≠ 0) of one already taken. A real exponent is a real
multiplier e^{λT}; one whose phase |Im λ| T lies within ``REAL_PHASE_TOL`` of π stands for a real
negative multiplier −e^{Re λ T} (its conjugate is its copy shifted by −iω; truncation moves Im λ
off ω/2 and would otherwise turn a period doubling into a complex pair); any other brings its
complex conjugate (a pair, two slots).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._typing import ComplexArray, FloatArray
from ..hb import FourierBasis, HarmonicBalance
from ..model import System

#: Phase distance (rad) of Im λ T from 0 or π under which a Hill exponent (n ≥ 2) is taken as a
#: real multiplier: Hill's truncation error in Im λ T is ~1e-3 at H = 16–32 for a stiffness
#: that jumps in time.
REAL_PHASE_TOL = 0.02


def _system_of(hb: HarmonicBalance) -> System:
    system = getattr(hb, "system", None)
    return system if system is not None else hb.model.system()


def _synthesis(basis: FourierBasis) -> tuple[FloatArray, FloatArray]:
    """Γ (N, 2H+1) synthesis and Γ* (2H+1, N) analysis matrices of the real basis."""
    H, N = basis.harmonics, basis.samples
    ph = np.outer(2 * np.pi * np.arange(N) / N, basis.k)
    G = np.concatenate([np.ones((N, 1)), np.cos(ph), np.sin(ph)], axis=1)
    Gs = G.T * (2.0 / N)
    Gs[0] = 1.0 / N
    return G, Gs


def system_hill_matrices(system: System, basis: FourierBasis, X: FloatArray, w: float) -> tuple[FloatArray, FloatArray]:
    """The HB Jacobian J = ∂R/∂q and the λ-coefficient D = 2 I_n ⊗ ∇ + C ⊗ I, both
    (n(2H+1), n(2H+1)) coordinate-major, of the orbit with coordinate series ``X`` (n, 2H+1)
    at base frequency ``w`` (module docstring)."""
    X = np.asarray(X, dtype=float).reshape(system.n, basis.size)
    n, N = system.n, basis.size
    G, Gs = _synthesis(basis)
    nabla = basis.derivative_matrix(w)
    eye = np.eye(N)
    J = np.kron(np.eye(n), nabla @ nabla) + np.kron(system.damping, nabla) + np.kron(system.stiffness, eye)
    deltas = system.element_rows @ X  # (m, 2H+1)
    for e, el in enumerate(system.elements):
        d = G @ deltas[e]
        g = el.slopes[np.searchsorted(el.breakpoints, d, side="right")]
        J += np.kron(np.outer(el.b, el.a), Gs @ (g[:, None] * G))
    D = 2.0 * np.kron(np.eye(n), nabla) + np.kron(system.damping, eye)
    return J, D


def _centroids(vec: ComplexArray, n: int, H: int) -> FloatArray:
    """Σ k |Y_k|² / Σ |Y_k|² of eigenvectors (columns of ``vec``, first n(2H+1) rows the
    displacement part, coordinate-major), summed over the coordinates."""
    Y = vec[: n * (2 * H + 1)].reshape(n, 2 * H + 1, -1)
    a, b = Y[:, 1 : H + 1], Y[:, H + 1 :]
    # Complex harmonic amplitudes of e^{ikωt}: k > 0 ↔ (a − i b)/2, k < 0 ↔ (a + i b)/2.
    w_pos = np.abs(0.5 * (a - 1j * b)) ** 2
    w_neg = np.abs(0.5 * (a + 1j * b)) ** 2
    k = np.arange(1, H + 1)[None, :, None]
    total = np.sum(np.abs(Y[:, 0]) ** 2, axis=0) + np.sum(w_pos + w_neg, axis=(0, 1))
    return np.sum(k * (w_pos - w_neg), axis=(0, 1)) / total


def system_hill_exponents(system: System, basis: FourierBasis, X: FloatArray, w: float) -> ComplexArray:
    """The 2n physical Floquet exponents λ of the orbit ``X`` (n, 2H+1) of base frequency ``w``
    (module docstring: eigenvector-centroid selection, copies skipped, conjugates paired),
    Im λ in (−ω/2, ω/2]."""
    n, H = system.n, basis.harmonics
    J, D = system_hill_matrices(system, basis, X, w)
    size = J.shape[0]
    A = np.zeros((2 * size, 2 * size))
    A[:size, size:] = np.eye(size)
    A[size:, :size] = -J
    A[size:, size:] = -D
    lam, vec = scipy.linalg.eig(A, check_finite=False)
    centroid = _centroids(vec, n, H)
    T = 2 * np.pi / w
    # Fold every exponent into the fundamental strip Im λ ∈ (−ω/2, ω/2].
    shift = np.round(lam.imag / w)
    folded = lam - 1j * w * shift
    chosen: list[complex] = []

    def is_copy(z: complex) -> bool:
        """z is an exponent already chosen (or its conjugate) or, within Hill's truncation
        error, a copy λ + i m ω (m ≠ 0) of one (for a negative real multiplier, stored with
        Im λ = ω/2, any m: its truncated conjugate folds to either side of ω/2)."""
        for c in chosen:
            if abs(z - c) <= 1e-9 * max(w, abs(c)):
                return True
            d = (z - c) / (1j * w)
            m = round(d.real)
            if (m != 0 or c.imag == 0.5 * w) and abs(z.real - c.real) <= 1e-3 * max(w, abs(c.real)) and abs(d.real - m) < 0.01:
                return True
        return False

    for i in np.argsort(np.abs(centroid), kind="stable"):
        if len(chosen) >= 2 * n:
            break
        z = complex(folded[i])
        if is_copy(z):
            continue
        phase = abs(z.imag) * T
        if z.imag == 0.0:  # a real multiplier e^{λT} > 0
            chosen.append(z)
        elif abs(phase - np.pi) <= REAL_PHASE_TOL or len(chosen) == 2 * n - 1:
            # a real multiplier −e^{Re λ T} (Im λ = ω/2; its conjugate is the copy shifted by −iω)
            chosen.append(complex(z.real, 0.5 * w))
        else:
            chosen.extend([z, z.conjugate()])
    return np.array(chosen[: 2 * n])


def system_hill_multipliers(system: System, basis: FourierBasis, X: FloatArray, w: float) -> ComplexArray:
    """exp(λ T), T = 2π/w, of :func:`system_hill_exponents`, largest modulus first; real
    multipliers exactly real."""
    lam = system_hill_exponents(system, basis, X, w)
    T = 2 * np.pi / w
    with np.errstate(over="ignore", under="ignore"):
        mu = np.exp(lam.real * T) * np.exp(1j * lam.imag * T)
    real = (lam.imag == 0.0) | (lam.imag == 0.5 * w)
    mu = np.where(real, np.where(lam.imag == 0.0, 1.0, -1.0) * np.exp(lam.real * T), mu)
    return mu[np.argsort(-np.abs(mu), kind="stable")]


def hill_exponents(hb: HarmonicBalance, q: FloatArray, omega: float) -> ComplexArray:
    """The 2n physical Floquet exponents λ of the HB orbit q at forcing frequency Ω (n = 1: the
    single-DOF selection below; n ≥ 2: :func:`system_hill_exponents`)."""
    system = _system_of(hb)
    if system.n > 1:
        return system_hill_exponents(system, hb.basis, q.reshape(system.n, -1), hb.base_frequency(omega))
    H = hb.basis.harmonics
    n = hb.size
    w = hb.base_frequency(omega)
    _, Rq, _ = hb.residual_jacobian(q, omega)
    c = float(system.damping[0, 0])
    D1 = 2.0 * hb.basis.derivative_matrix(w) + c * np.eye(n)
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
    return np.array([lam1, -c - lam1])


def hill_multipliers(hb: HarmonicBalance, q: FloatArray, omega: float) -> ComplexArray:
    """Floquet multipliers exp(λ T_p), T_p = p 2π/Ω, from :func:`hill_exponents`, largest first
    (n ≥ 2: :func:`system_hill_multipliers`).

    The monodromy of the single-DOF equation is a real 2×2 matrix with det M = e^{−cT}, so its
    multipliers are either a complex-conjugate pair on the circle |μ| = e^{−cT/2} or two real
    numbers with product e^{−cT}. Hill's exponent carries a truncation error in both parts, which
    would otherwise make a real multiplier come out slightly complex (and a period doubling be
    named a Neimark–Sacker bifurcation). The pair is therefore projected onto the nearer of the
    two admissible structures: with λ_1 = a + i b, the distance to the circle is |a + c/2| T and
    the distance to the real axis is that of bT from the nearest multiple of π; the nearer one wins
    (real: μ_1 = ±e^{aT}, μ_2 = e^{−cT}/μ_1; circle: μ = e^{−cT/2} e^{±ibT}).
    """
    system = _system_of(hb)
    if system.n > 1:
        return system_hill_multipliers(system, hb.basis, q.reshape(system.n, -1), hb.base_frequency(omega))
    lam = hill_exponents(hb, q, omega)
    period = 2 * np.pi / hb.base_frequency(omega)
    c = float(system.damping[0, 0])
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


__all__ = [
    "hill_exponents", "hill_multipliers", "system_hill_matrices", "system_hill_exponents", "system_hill_multipliers",
    "REAL_PHASE_TOL",
]
