"""Truncated real Fourier basis, real DFT synthesis/analysis and the derivative operator.

A solution of base frequency ω is stored as q = [a_0, a_1 … a_H, b_1 … b_H] (length 2H + 1):

    δ(t) = a_0 + Σ_{k=1}^{H} (a_k cos kωt + b_k sin kωt).

Samples are taken at t_j = j T / N, j = 0 … N − 1, T = 2π/ω.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._typing import ComplexArray, FloatArray


@dataclass(frozen=True, slots=True)
class FourierBasis:
    """H harmonics sampled at N points per period (N ≥ 2H + 1)."""

    harmonics: int
    samples: int
    k: FloatArray = field(init=False, repr=False, compare=False)  # (H,) harmonic orders 1 … H

    def __post_init__(self) -> None:
        if self.samples < 2 * self.harmonics + 1:
            raise ValueError("samples must be >= 2*harmonics + 1")
        object.__setattr__(self, "k", np.arange(1, self.harmonics + 1, dtype=float))

    @property
    def size(self) -> int:
        """Number of real unknowns 2H + 1."""
        return 2 * self.harmonics + 1

    # --- conversions ---------------------------------------------------------------------
    def to_complex(self, q: FloatArray) -> ComplexArray:
        """One-sided complex coefficients Q_k, k = 0 … H (δ = Σ_{k=-H}^{H} Q_k e^{ikωt}); ``q``
        may hold several series as rows (..., 2H+1)."""
        H = self.harmonics
        c = np.empty(q.shape[:-1] + (H + 1,), dtype=complex)
        c[..., 0] = q[..., 0]
        c[..., 1:] = 0.5 * (q[..., 1 : H + 1] - 1j * q[..., H + 1 :])
        return c

    def from_complex(self, c: ComplexArray) -> FloatArray:
        """Inverse of :meth:`to_complex` (c of length H + 1, or rows (..., H + 1))."""
        H = self.harmonics
        q = np.empty(c.shape[:-1] + (2 * H + 1,))
        q[..., 0] = c[..., 0].real
        np.multiply(c[..., 1 : H + 1].real, 2.0, out=q[..., 1 : H + 1])
        np.multiply(c[..., 1 : H + 1].imag, -2.0, out=q[..., H + 1 :])
        return q

    def synthesize(self, q: FloatArray) -> FloatArray:
        """Samples δ(t_j), j = 0 … N − 1, of the series q (inverse real FFT); rows (..., 2H+1)
        give rows of samples (..., N)."""
        N = self.samples
        spec = np.zeros(q.shape[:-1] + (N // 2 + 1,), dtype=complex)
        spec[..., : self.harmonics + 1] = N * self.to_complex(q)
        return np.fft.irfft(spec, n=N, axis=-1)

    def analyze(self, x: FloatArray) -> FloatArray:
        """Coefficients q of the samples x (length N, or rows (..., N)), truncated to H
        harmonics (real FFT)."""
        spec = np.fft.rfft(x, axis=-1)[..., : self.harmonics + 1] / self.samples
        return self.from_complex(spec)

    def spectrum(self, x: FloatArray, orders: int) -> ComplexArray:
        """Complex coefficients X_m, m = 0 … ``orders``, of the samples x (x = Σ X_m e^{imωt})."""
        return np.fft.rfft(x)[: orders + 1] / self.samples

    def derivative(self, q: FloatArray, omega: float) -> FloatArray:
        """Coefficients of dδ/dt: cos part k ω b_k, sin part −k ω a_k."""
        H = self.harmonics
        kw = self.k * omega
        out = np.empty_like(q)
        out[0] = 0.0
        out[1 : H + 1] = kw * q[H + 1 :]
        out[H + 1 :] = -kw * q[1 : H + 1]
        return out

    def derivative_matrix(self, omega: float) -> FloatArray:
        """The matrix ∇(ω) with ∇ q = coefficients of dδ/dt, shape (2H+1, 2H+1)."""
        H = self.harmonics
        D = np.zeros((2 * H + 1, 2 * H + 1))
        idx = np.arange(1, H + 1)
        D[idx, idx + H] = self.k * omega
        D[idx + H, idx] = -self.k * omega
        return D

    def times(self, period: float) -> FloatArray:
        """Sample times t_j = j T / N over one solution period T."""
        return np.arange(self.samples) * (period / self.samples)

    def evaluate(self, q: FloatArray, omega: float, t: FloatArray, derivative: int = 0) -> FloatArray:
        """δ (or its ``derivative``-th time derivative) of the series at arbitrary times ``t``."""
        H = self.harmonics
        t = np.asarray(t, dtype=float)
        phase = np.multiply.outer(t, self.k * omega)
        a, b = q[1 : H + 1], q[H + 1 :]
        kw = self.k * omega
        if derivative == 0:
            return q[0] + np.cos(phase) @ a + np.sin(phase) @ b
        # d^m/dt^m of a cos + b sin: rotate by m quarter turns and scale by (kω)^m.
        m = derivative % 4
        scale = kw**derivative
        c, s = np.cos(phase), np.sin(phase)
        if m == 1:
            return c @ (scale * b) - s @ (scale * a)
        if m == 2:
            return -(c @ (scale * a)) - s @ (scale * b)
        if m == 3:
            return -(c @ (scale * b)) + s @ (scale * a)
        return c @ (scale * a) + s @ (scale * b)

    def galerkin_matrix_indices(self) -> tuple[np.ndarray, np.ndarray]:
        """Index grids k − j and k + j (k = 0 … H rows, j = 1 … H columns) for the Jacobian."""
        H = self.harmonics
        kk = np.arange(H + 1)[:, None]
        jj = np.arange(1, H + 1)[None, :]
        return kk - jj, kk + jj


def resize_harmonics(q: FloatArray, harmonics: int, factor: int = 1) -> FloatArray:
    """Coefficients ``q`` (last axis 2H + 1) rewritten with ``harmonics`` harmonics of the base
    frequency ω/``factor``: harmonic k of ω becomes harmonic factor·k; harmonics that do not fit
    are dropped, the others are zero. ``factor = 1`` pads or truncates; ``factor = n`` writes a
    solution in the basis of period n."""
    q = np.asarray(q, dtype=float)
    H0 = (q.shape[-1] - 1) // 2
    out = np.zeros(q.shape[:-1] + (2 * harmonics + 1,))
    out[..., 0] = q[..., 0]
    k = np.arange(1, H0 + 1)
    keep = factor * k <= harmonics
    out[..., factor * k[keep]] = q[..., 1 : H0 + 1][..., keep]
    out[..., harmonics + factor * k[keep]] = q[..., H0 + 1 :][..., keep]
    return out


__all__ = ["FourierBasis", "resize_harmonics"]
