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


def _jacobian_gather_tables(H: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Index and sign tables with J[r, c] = s1 V[i1] + s2 V[i2], V = [Re G_m, Im G_m], m = −2H … 2H.

    From the complex product rule (g δ)_k = Σ_j G_{k−j} Q_j in the real basis:
    row a_0: G0, ½(Gr_{−j} + Gr_j), ½(Gi_{−j} − Gi_j); row cos k: 2Gr_k, Gr_{k−j} + Gr_{k+j},
    Gi_{k−j} − Gi_{k+j}; row sin k: −2Gi_k, −(Gi_{k−j} + Gi_{k+j}), Gr_{k−j} − Gr_{k+j}.
    """
    n = 2 * H + 1
    off = 2 * H
    im = 4 * H + 1  # start of the imaginary parts in V
    i1 = np.zeros((n, n), dtype=np.intp)
    i2 = np.zeros((n, n), dtype=np.intp)
    s1 = np.zeros((n, n))
    s2 = np.zeros((n, n))
    k = np.arange(1, H + 1)
    K, J = np.meshgrid(k, k, indexing="ij")
    a = slice(1, H + 1)
    b = slice(H + 1, n)
    # row a_0
    i1[0, 0], s1[0, 0] = off, 1.0
    i1[0, a], s1[0, a], i2[0, a], s2[0, a] = off - k, 0.5, off + k, 0.5
    i1[0, b], s1[0, b], i2[0, b], s2[0, b] = im + off - k, 0.5, im + off + k, -0.5
    # rows cos k
    i1[a, 0], s1[a, 0] = off + k, 2.0
    i1[a, a], s1[a, a], i2[a, a], s2[a, a] = off + K - J, 1.0, off + K + J, 1.0
    i1[a, b], s1[a, b], i2[a, b], s2[a, b] = im + off + K - J, 1.0, im + off + K + J, -1.0
    # rows sin k
    i1[b, 0], s1[b, 0] = im + off + k, -2.0
    i1[b, a], s1[b, a], i2[b, a], s2[b, a] = im + off + K - J, -1.0, im + off + K + J, -1.0
    i1[b, b], s1[b, b], i2[b, b], s2[b, b] = off + K - J, 1.0, off + K + J, -1.0
    return i1, s1, i2, s2


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
        self._gather = _jacobian_gather_tables(H)
        self._diag = np.arange(1, H + 1)
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
        return self._jacobian_from_spectrum(np.fft.rfft(g))

    def _jacobian_from_spectrum(self, spec: np.ndarray) -> FloatArray:
        H = self.basis.harmonics
        G = spec[: 2 * H + 1] / self.basis.samples
        V = np.concatenate((G.real[:0:-1], G.real, -G.imag[:0:-1], G.imag))  # Re, Im of G_m, m = −2H … 2H
        i1, s1, i2, s2 = self._gather
        return s1 * V[i1] + s2 * V[i2]

    # --- residual and Jacobians ------------------------------------------------------------
    def residual(self, q: FloatArray, omega: float) -> FloatArray:
        """R(q, Ω), shape (2H+1,)."""
        w = self.base_frequency(omega)
        return self._linear_part(q, w) + self.nonlinear_force(q) - self.forcing

    def residual_jacobian(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R, ∂R/∂q (2H+1, 2H+1) and ∂R/∂Ω (2H+1,) in one AFT pass."""
        w = self.base_frequency(omega)
        basis = self.basis
        H = basis.harmonics
        delta = basis.synthesize(q)
        f, g = self._force_samples(delta)
        spec = np.fft.rfft(np.stack((f, g)), axis=1)  # one FFT call for force and stiffness
        R = self._linear_part(q, w) + self._kstiff * basis.from_complex(spec[0, : H + 1] / basis.samples) - self.forcing
        Rq = self._jacobian_from_spectrum(spec[1])
        Rq *= self._kstiff
        # Add the linear (inertia, damping) blocks on their diagonals.
        i = self._diag
        kw = basis.k * w
        Rq[i, i] -= kw**2
        Rq[i + H, i + H] -= kw**2
        Rq[i, i + H] += self._c * kw
        Rq[i + H, i] -= self._c * kw
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
