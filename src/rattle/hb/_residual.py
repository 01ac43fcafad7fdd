"""Harmonic-balance residual of the equation in δ, with its analytic Jacobians.

For a solution of period p·T (T = 2π/Ω, base frequency ω = Ω/p, p = 1 for the primary
response, p = n for a 1/n sub-harmonic) the Galerkin residual on q (see ``_basis``) is

    R(q, Ω) = ∇(ω)² q + c ∇(ω) q + k Γ*[f(Γ q)] − F,

with c = C/I, k = K/I, Γ the synthesis (samples of δ), Γ* the analysis (real FFT) and F the
coefficients of the excitation (its n-th harmonic sits at harmonic n·p of ω). The non-linear
force is evaluated by alternating frequency–time (AFT). Its Jacobian is

    ∂(Γ* f(Γq))/∂q = Γ* diag(∂f/∂δ(t_j)) Γ,

which we assemble exactly from the DFT coefficients G_m of the sampled stiffness g = ∂f/∂δ:
in complex form the product g·δ has coefficients Σ_j G_{k−j} Q_j, a Toeplitz + Hankel matrix
in the real basis (O(N log N + H²) instead of O(N H²)). Exact identity for N ≥ 4H + 1.
"""

from __future__ import annotations

import numpy as np

from .._typing import FloatArray
from ..model import Model
from ._basis import FourierBasis
from ._options import HBOptions


class HarmonicBalance:
    """The discretised problem R(q, Ω) = 0 for one model, harmonic count and period multiple."""

    def __init__(self, model: Model, options: HBOptions | None = None, *, period: int = 1) -> None:
        options = HBOptions() if options is None else options
        if isinstance(period, bool) or not isinstance(period, int) or period < 1:
            raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
        n_forced = len(model.excitation.amplitudes)
        if options.harmonics < n_forced * period:
            raise ValueError(
                f"`harmonics` must be >= {n_forced * period} to hold the excitation's harmonic "
                f"{n_forced} at period {period} (harmonic {n_forced}×{period} of the base "
                f"frequency), got {options.harmonics}"
            )
        self.model = model
        self.options = options
        self.period = period
        self.basis = FourierBasis(options.harmonics, options.n_samples)
        H = options.harmonics
        self._k2 = self.basis.k**2
        kmj, kpj = self.basis.galerkin_matrix_indices()
        self._idx_minus = kmj + 2 * H
        self._idx_plus = kpj + 2 * H
        self._rows = np.arange(H + 1)
        self.length_scale = model.length_scale()
        self.force_scale = model.force_scale()
        # Excitation coefficients: F_m at a_0, F_pn cos(nΩt + φ) at harmonic n·p.
        F = np.zeros(2 * H + 1)
        F[0] = model.excitation.mean
        for n, amp, phi in zip(model.excitation.orders, model.excitation.amplitudes, model.excitation.phases):  # type: ignore[arg-type]
            m = int(n) * period
            F[m] += amp * np.cos(phi)
            F[H + m] += -amp * np.sin(phi)
        self.forcing = F
        self._c = model.c
        self._kstiff = model.k
        self._st = model.elastic.stages

    @property
    def size(self) -> int:
        return self.basis.size

    def base_frequency(self, omega: float) -> float:
        """ω = Ω / p."""
        return omega / self.period

    # --- pieces ----------------------------------------------------------------------------
    def _linear_part(self, q: FloatArray, w: float) -> FloatArray:
        """∇² q + c ∇ q (inertia and damping), for base frequency w."""
        H = self.basis.harmonics
        a, b = q[1 : H + 1], q[H + 1 :]
        kw = self.basis.k * w
        out = np.empty_like(q)
        out[0] = 0.0
        out[1 : H + 1] = -(kw**2) * a + self._c * kw * b
        out[H + 1 :] = -(kw**2) * b - self._c * kw * a
        return out

    def _linear_part_dw(self, q: FloatArray, w: float) -> FloatArray:
        """∂/∂ω of :meth:`_linear_part`."""
        H = self.basis.harmonics
        a, b = q[1 : H + 1], q[H + 1 :]
        k = self.basis.k
        out = np.empty_like(q)
        out[0] = 0.0
        out[1 : H + 1] = -2.0 * self._k2 * w * a + self._c * k * b
        out[H + 1 :] = -2.0 * self._k2 * w * b - self._c * k * a
        return out

    def linear_matrix(self, omega: float) -> FloatArray:
        """Matrix of :meth:`_linear_part` at forcing frequency Ω, shape (2H+1, 2H+1)."""
        w = self.base_frequency(omega)
        H = self.basis.harmonics
        kw = self.basis.k * w
        D = np.zeros((2 * H + 1, 2 * H + 1))
        i = np.arange(1, H + 1)
        D[i, i] = -(kw**2)
        D[i + H, i + H] = -(kw**2)
        D[i, i + H] = self._c * kw
        D[i + H, i] = -self._c * kw
        return D

    def _force_samples(self, delta: FloatArray) -> tuple[FloatArray, FloatArray]:
        st = self._st
        j = np.searchsorted(st.breakpoints, delta, side="right")
        s = st.slopes[j]
        return s * delta + st.offsets[j], s

    def nonlinear_force(self, q: FloatArray) -> FloatArray:
        """k Γ* f(Γ q): coefficients of the restoring force by AFT."""
        f, _ = self._force_samples(self.basis.synthesize(q))
        return self._kstiff * self.basis.analyze(f)

    def force_jacobian_from_stiffness(self, g: FloatArray) -> FloatArray:
        """Γ* diag(g) Γ for stiffness samples g (length N), assembled from the DFT of g."""
        H = self.basis.harmonics
        G = np.fft.rfft(g)[: 2 * H + 1] / self.basis.samples
        Gfull = np.concatenate((np.conj(G[:0:-1]), G))  # m = −2H … 2H
        Gm = Gfull[self._idx_minus]  # G_{k−j}, (H+1, H)
        Gp = Gfull[self._idx_plus]  # G_{k+j}
        dA0 = G[: H + 1]  # ∂H_k/∂a_0
        dA = 0.5 * (Gm + Gp)  # ∂H_k/∂a_j
        dB = 0.5j * (Gp - Gm)  # ∂H_k/∂b_j
        J = np.empty((2 * H + 1, 2 * H + 1))
        J[0, 0] = dA0[0].real
        J[0, 1 : H + 1] = dA[0].real
        J[0, H + 1 :] = dB[0].real
        J[1 : H + 1, 0] = 2.0 * dA0[1:].real
        J[1 : H + 1, 1 : H + 1] = 2.0 * dA[1:].real
        J[1 : H + 1, H + 1 :] = 2.0 * dB[1:].real
        J[H + 1 :, 0] = -2.0 * dA0[1:].imag
        J[H + 1 :, 1 : H + 1] = -2.0 * dA[1:].imag
        J[H + 1 :, H + 1 :] = -2.0 * dB[1:].imag
        return J

    # --- residual and Jacobians ------------------------------------------------------------
    def residual(self, q: FloatArray, omega: float) -> FloatArray:
        """R(q, Ω), shape (2H+1,)."""
        w = self.base_frequency(omega)
        return self._linear_part(q, w) + self.nonlinear_force(q) - self.forcing

    def residual_jacobian(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R, ∂R/∂q (2H+1, 2H+1) and ∂R/∂Ω (2H+1,) in one AFT pass."""
        w = self.base_frequency(omega)
        delta = self.basis.synthesize(q)
        f, g = self._force_samples(delta)
        R = self._linear_part(q, w) + self._kstiff * self.basis.analyze(f) - self.forcing
        Rq = self.linear_matrix(omega)
        Rq += self._kstiff * self.force_jacobian_from_stiffness(g)
        Rw = self._linear_part_dw(q, w) / self.period
        return R, Rq, Rw

    def stiffness_samples(self, q: FloatArray) -> FloatArray:
        """k ∂f/∂δ at the N sample times of the orbit q."""
        return self._kstiff * self._force_samples(self.basis.synthesize(q))[1]

    def linear_solution(self, omega: float, stiffness_slope: float | None = None, center: float | None = None) -> FloatArray:
        """Closed-form solution of the equation linearised about a stage.

        With f ≈ s (δ − δ_c) + f(δ_c) on the stage holding δ_c (default: the static equilibrium),
        each excitation harmonic m of ω gives X_m = F_m / (k s − (mω)² + i c mω).
        """
        model = self.model
        dc = model.static_equilibrium() if center is None else center
        s = float(model.elastic.stiffness(dc)) if stiffness_slope is None else stiffness_slope
        H = self.basis.harmonics
        w = self.base_frequency(omega)
        q = np.zeros(2 * H + 1)
        q[0] = dc
        m = self.basis.k * w
        denom = model.k * s - m**2 + 1j * model.c * m
        Fc = self.forcing[1 : H + 1] - 1j * self.forcing[H + 1 :]
        X = Fc / denom
        q[1 : H + 1] = X.real
        q[H + 1 :] = -X.imag
        return q


__all__ = ["HarmonicBalance"]
