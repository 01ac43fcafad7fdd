"""Harmonic balance of a chain with Coulomb friction on its elements, by regularisation.

The chain's equations with friction (:class:`~rattle.model.System` with its elements' whole laws), n coordinates and
m clearance elements,

    x'' + C x' + K x + Σ_e b_e g_e(δ_e, δ_e') = F(t),   δ_e = a_e · x,
    g_e(δ, δ') = f_e(δ) + r_e(δ) sgn(δ'),

have a force that jumps where a relative velocity δ_e' changes sign. As for the single equation
(:mod:`rattle.hb._regularised`) the harmonic balance solves the regularised equations, every
sign replaced by a smooth step (:meth:`~rattle.model.NonsmoothLaw.regularised`, g_ε,e relative
to the element stiffness, which b_e carries):

    sgn(δ') → tanh(δ' / ε_v),   steps of r_e at breakpoints → H_ε(δ − d_i) of width ε_δ,
    ε_δ = ε L,   ε_v = ε L ω_n,

L the system's length scale with friction (:meth:`System.length_scale`) and ω_n its
highest natural frequency (:meth:`System.frequency_scale`); both are fixed (the law
does not depend on Ω), so ε is the only knob. An element may have narrower steps of its own
(:meth:`RegularisedSystemBalance.with_element_scales`): element e's widths are then s_e ε_δ and
s_e ε_v (s_e = 1 by default), which resolves an element whose own motion is much smaller than L
(one held part of the period) without narrowing every element's steps.

The unknowns are those of :class:`~rattle.hb.HarmonicBalance`: q = vec(Q), Q (n, 2H+1)
coordinate-major, row i the real series [a_0, a_1 … a_H, b_1 … b_H] of x_i at base frequency
ω = Ω/p. With ℰ (N × (2H+1)) the synthesis at N samples per period, 𝒜 = ℰ⁺ the truncated
analysis and ∇(ω) = ω ∇(1) the derivative operator, the residual is

    R_i(q, Ω) = ∇² q_i + Σ_j C_ij ∇ q_j + Σ_j K_ij q_j
                + Σ_e b_e,i 𝒜 g_ε,e(ℰ (a_e·Q), ℰ ∇ (a_e·Q)) − F_i(Ω),

F_i the forcing coefficients (mean F_0 plus a speed-dependent load d(Ω) u at a_0, harmonic h of Ω
at harmonic h·p of ω). Its Jacobians, by AFT with a velocity-dependent force:

    ∂R/∂q = I ⊗ ∇² + C ⊗ ∇ + K ⊗ I + Σ_e (b_e a_eᵀ) ⊗ [𝒜 diag(∂g_e/∂δ) ℰ + 𝒜 diag(∂g_e/∂δ') ℰ ∇],
    ∂R/∂Ω = (1/p) [2ω ∇(1)² Q + C ∇(1) Q + Σ_e b_e 𝒜 diag(∂g_e/∂δ') ℰ ∇(1) (a_e·Q)] − d'(Ω) u,

the products 𝒜 diag(w) ℰ assembled from the spectra of the samples w by the harmonic balance's
product rule (:func:`~rattle.hb._residual.product_jacobians`, exact for N ≥ 4H + 1), one pair
per element; ∂R/∂q is dense, (n·S)² with S = 2H + 1.

The ε-problem's orbit differs from the discontinuous one by O(ε) in general (sticking becomes
creeping at a speed ~ε_v); it is solved along a decreasing sequence of ε and checked against the
exact event-driven orbit, for which :meth:`RegularisedSystemBalance.state_at_zero` gives the
start (x(0), x'(0)).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._typing import FloatArray
from ..model import System
from ._basis import FourierBasis, resize_harmonics
from ._options import HBOptions
from ._residual import (
    check_forced_harmonics,
    forcing_with_load,
    load_slope,
    product_jacobians,
    product_tables,
    system_forcing,
)

_gesv = scipy.linalg.lapack.dgesv

#: The most AFT samples :meth:`RegularisedSystemBalance.with_samples` takes (a few (m, N) arrays).
MAX_SAMPLES = 1 << 20


class RegularisedSystemBalance:
    """R(q, Ω) = 0 of the regularised chain with friction (module docstring), a
    :class:`~rattle.continuation.ContinuationProblem` in Ω.

    Parameters
    ----------
    fsys
        The chain's equations with friction (:class:`~rattle.model.System` with its elements' whole laws).
    regularisation
        ε > 0, the relative width of the smooth steps (ε_δ = ε L, ε_v = ε L ω_n).
    options
        The harmonics and samples (:class:`HBOptions`).
    period
        p: the solution's period is p forcing periods.
    """

    def __init__(self, fsys: System, *, regularisation: float, options: HBOptions | None = None,
                 period: int = 1) -> None:
        if not (isinstance(fsys, System) and fsys.discontinuous):
            raise TypeError(f"`fsys` must be a rattle.model.System with its elements' whole laws "
                            f"(Chain.friction_system() or System.with_friction), got {fsys!r}")
        eps = _check_regularisation(regularisation)
        if options is None:
            options = HBOptions()
        elif not isinstance(options, HBOptions):
            raise TypeError(f"`options` must be a rattle.hb.HBOptions or None, got {options!r}")
        if isinstance(period, bool) or not isinstance(period, (int, np.integer)) or period < 1:
            raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
        period = int(period)
        system = fsys.continuous()
        H = options.harmonics
        check_forced_harmonics(system, H, period)
        L, wn = float(fsys.length_scale()), float(fsys.frequency_scale())
        if not (np.isfinite(L) and L > 0 and np.isfinite(wn) and wn > 0):
            raise ValueError(f"`fsys` must have a finite length scale > 0 and natural frequency > 0, got "
                             f"L = {L!r}, ω_n = {wn!r}")
        self.fsys = fsys
        self.system = system
        self.options = options
        self.period = period
        self.eps = eps
        self._L, self._wn = L, wn
        self.basis = FourierBasis(H, options.n_samples)
        S = 2 * H + 1
        n, m = system.n, system.m
        self.n_coordinates, self.n_elements = n, m
        self._S = S
        self.forcing = system_forcing(system, H, period)
        self._load = system.load
        self._a0 = np.arange(n) * S
        self._force_scale = float(system.force_scale())
        self._C = np.asarray(system.damping, dtype=float)
        self._K = np.asarray(system.stiffness, dtype=float)
        self._A = system.element_rows.reshape(m, n)
        self._B = system.element_columns.reshape(n, m)
        W = np.einsum("ie,ej->eij", self._B, self._A)
        self._W_entries = [(int(e), int(i), int(j), float(W[e, i, j])) for e, i, j in zip(*np.nonzero(W))]
        self._laws = fsys.laws
        self._tables = product_tables(H, 2 * m)
        self._lin_pos, self._lin_vals = self._linear_pattern()
        self._scales = np.ones(m)

    def _linear_pattern(self) -> tuple[np.ndarray, FloatArray]:
        """The linear part's Jacobian I ⊗ ∇(ω)² + C ⊗ ∇(ω) + K ⊗ I = ω² L2 + ω L1 + L0 by its
        non-zero entries: flat positions in the (n·S, n·S) matrix and the values (3, ·) of L2, L1,
        L0 there (∇(1): a_k → −k on row b_k, b_k → k on row a_k)."""
        n, S, H = self.n_coordinates, self._S, self.basis.harmonics
        nS = n * S
        k = np.arange(1, H + 1, dtype=float)
        a, b = np.arange(1, H + 1), np.arange(H + 1, S)
        pos, vals = [], []

        def put(rows: np.ndarray, cols: np.ndarray, *v: float | FloatArray) -> None:
            pos.append(rows * nS + cols)
            vals.append(np.stack([np.broadcast_to(np.asarray(x, dtype=float), rows.shape) for x in v]))

        for i in range(n):  # I ⊗ ∇(1)²: −k² on the harmonic rows
            put(i * S + a, i * S + a, -(k**2), 0.0, 0.0)
            put(i * S + b, i * S + b, -(k**2), 0.0, 0.0)
        for i, j in zip(*np.nonzero(self._C)):  # C ⊗ ∇(1)
            put(i * S + a, j * S + b, 0.0, self._C[i, j] * k, 0.0)
            put(i * S + b, j * S + a, 0.0, -self._C[i, j] * k, 0.0)
        r = np.arange(S)
        for i, j in zip(*np.nonzero(self._K)):  # K ⊗ I
            put(i * S + r, j * S + r, 0.0, 0.0, self._K[i, j])
        flat = np.concatenate(pos)
        unique, inverse = np.unique(flat, return_inverse=True)
        V = np.concatenate(vals, axis=1)
        out = np.stack([np.bincount(inverse, weights=v, minlength=unique.size) for v in V])
        return unique, out

    # --- scales (ContinuationProblem) --------------------------------------------------------
    @property
    def size(self) -> int:
        """n·(2H+1) real unknowns."""
        return self.n_coordinates * self._S

    @property
    def length_scale(self) -> float:
        """L (rad): :meth:`System.length_scale`."""
        return self._L

    @property
    def parameter_scale(self) -> float:
        """ω_n (rad/s): :meth:`System.frequency_scale`."""
        return self._wn

    @property
    def force_scale(self) -> float:
        """The forcing's size per inertia (:meth:`System.force_scale`)."""
        return self._force_scale

    @property
    def regularisation(self) -> float:
        """ε."""
        return self.eps

    @property
    def widths(self) -> tuple[float, float]:
        """(ε_δ, ε_v): the widths of the smooth steps in δ (rad) and δ' (rad/s)."""
        return self.eps * self._L, self.eps * self._L * self._wn

    @property
    def element_scales(self) -> FloatArray:
        """s_e (m,): element e's steps have the widths s_e ε_δ and s_e ε_v (1 by default)."""
        return self._scales.copy()

    @property
    def element_widths(self) -> FloatArray:
        """(m, 2): every element's step widths (s_e ε_δ, s_e ε_v)."""
        ed, ev = self.widths
        return np.column_stack((self._scales * ed, self._scales * ev))

    def _copy(self) -> RegularisedSystemBalance:
        out = object.__new__(RegularisedSystemBalance)
        out.__dict__.update(self.__dict__)
        return out

    def with_regularisation(self, regularisation: float) -> RegularisedSystemBalance:
        """The same problem with another ε (shares the matrices)."""
        out = self._copy()
        out.eps = _check_regularisation(regularisation)
        return out

    def with_element_scales(self, scales: FloatArray) -> RegularisedSystemBalance:
        """The same problem with element e's steps s_e times as wide as the chain's (``scales``
        (m,), each finite and > 0; shares the matrices)."""
        s = np.asarray(scales, dtype=float)
        if s.shape != (self.n_elements,) or not np.all(np.isfinite(s)) or not np.all(s > 0):
            raise ValueError(f"`scales` must be {self.n_elements} finite numbers > 0 (one per element), got "
                             f"{np.asarray(scales)!r}")
        out = self._copy()
        out._scales = s.copy()
        return out

    def with_samples(self, samples: int) -> RegularisedSystemBalance:
        """The same problem with N = ``samples`` AFT samples per period (N ≥ 4H + 2; the residual
        and its Jacobian are computed by FFT, so N is bounded by memory only: 2^20 at most).
        Steps much narrower in time than T/N are not resolved by the samples (Newton stalls):
        narrow steps need more of them."""
        H = self.basis.harmonics
        if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) \
                or not 4 * H + 2 <= samples <= MAX_SAMPLES:
            raise ValueError(f"`samples` must be an integer in [4H + 2, {MAX_SAMPLES}] = [{4 * H + 2}, {MAX_SAMPLES}], "
                             f"got {samples!r}")
        out = self._copy()
        out.basis = FourierBasis(H, int(samples))
        return out

    def base_frequency(self, omega: float) -> float:
        """ω = Ω / p."""
        return omega / self.period

    # --- views ---------------------------------------------------------------------------------
    def coordinate_series(self, q: FloatArray) -> FloatArray:
        """Q (n, 2H+1): row i is the real series of coordinate x_i (a view of ``q``)."""
        return np.asarray(q).reshape(self.n_coordinates, self._S)

    def element_series(self, q: FloatArray) -> FloatArray:
        """The deflection series of every element, A Q, shape (m, 2H+1)."""
        return self._A @ self.coordinate_series(q)

    def element_samples(self, q: FloatArray) -> FloatArray:
        """δ_e(t_j) at the N sample times of the base period, shape (m, N)."""
        return self.basis.synthesize(self.element_series(q))

    def element_rms(self, q: FloatArray) -> FloatArray:
        """rms of every element's deflection over the period, √(a_0² + ½ Σ_h (a_h² + b_h²)), (m,)."""
        E = self.element_series(q)
        return np.sqrt(E[:, 0] ** 2 + 0.5 * np.sum(E[:, 1:] ** 2, axis=1))

    def state_at_zero(self, q: FloatArray, omega: float) -> FloatArray:
        """z(0) = (x(0), x'(0)) (2n,) of the orbit q at forcing frequency Ω: x(0) = a_0 + Σ a_h,
        x'(0) = Σ_h h ω b_h (ω = Ω/p); the start of the exact integration."""
        Q = self.coordinate_series(q)
        H = self.basis.harmonics
        w = self.base_frequency(omega)
        x0 = Q[:, 0] + Q[:, 1 : H + 1].sum(axis=1)
        v0 = Q[:, H + 1 :] @ (self.basis.k * w)
        return np.concatenate((x0, v0))

    def resize(self, q: FloatArray, harmonics: int, factor: int = 1) -> FloatArray:
        """:func:`~rattle.hb.resize_harmonics` of every coordinate's series of ``q`` (flat in, flat out)."""
        return resize_harmonics(self.coordinate_series(q), harmonics, factor).reshape(-1)

    def linear_solution(self, omega: float) -> FloatArray:
        """A start for Newton: the steady state of the system linearised about its static
        equilibrium x_s at Ω, friction left out (every element on the stage holding a_e·x_s,
        K_s = K + Σ_e s_e b_e a_eᵀ): X_h = (K_s − (hω)² I + i hω C)⁻¹ F_h, mean x_s."""
        system = self.system
        n, H, S = self.n_coordinates, self.basis.harmonics, self._S
        xs = system.static_equilibrium(omega)
        Ks = system.stage_stiffness(system.stages_of(xs))
        hw = self.basis.k * self.base_frequency(omega)
        F = self.forcing.reshape(n, S)
        Fc = F[:, 1 : H + 1] - 1j * F[:, H + 1 :]  # (n, H)
        Z = Ks[None] - (hw**2)[:, None, None] * np.eye(n) + 1j * hw[:, None, None] * self._C[None]
        X = np.linalg.solve(Z, Fc.T[:, :, None])[:, :, 0].T
        Q = np.zeros((n, S))
        Q[:, 0] = xs
        Q[:, 1 : H + 1] = X.real
        Q[:, H + 1 :] = -X.imag
        return Q.reshape(-1)

    # --- residual ------------------------------------------------------------------------------
    def _forcing_at(self, omega: float) -> FloatArray:
        """The forcing coefficients at Ω: :attr:`forcing` plus the load's d(Ω) u at the a_0 slots."""
        return forcing_with_load(self.forcing, self._load, self._a0, omega)

    def _derivative(self, X: FloatArray, w: float) -> FloatArray:
        """∇(ω) applied to every row of the series X (r, S)."""
        H = self.basis.harmonics
        kw = self.basis.k * w
        out = np.empty_like(X)
        out[:, 0] = 0.0
        np.multiply(kw, X[:, H + 1 :], out=out[:, 1 : H + 1])
        np.multiply(-kw, X[:, 1 : H + 1], out=out[:, H + 1 :])
        return out

    def _element_forces(self, q: FloatArray, omega: float) -> tuple[FloatArray, ...]:
        """Q, ∇Q, and the samples g_ε,e, ∂g/∂δ, ∂g/∂δ' (each (m, N)) along the orbit q."""
        Q = self.coordinate_series(np.asarray(q, dtype=float))
        w = self.base_frequency(omega)
        dQ = self._derivative(Q, w)
        m, N = self.n_elements, self.basis.samples
        samples = self.basis.synthesize(np.concatenate((self._A @ Q, self._A @ dQ)))  # (2m, N)
        g, gd, gv = np.empty((m, N)), np.empty((m, N)), np.empty((m, N))
        for e, (law, (ed, ev)) in enumerate(zip(self._laws, self.element_widths)):
            g[e], gd[e], gv[e] = law.regularised(samples[e], samples[m + e], float(ed), float(ev))
        return Q, dQ, g, gd, gv

    def samples(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray]:
        """δ_e(t_j) and δ_e'(t_j) (m, N) at the N samples of the solution period."""
        Q = self.coordinate_series(np.asarray(q, dtype=float))
        dQ = self._derivative(Q, self.base_frequency(omega))
        return self.basis.synthesize(self._A @ Q), self.basis.synthesize(self._A @ dQ)

    def _linear(self, Q: FloatArray, dQ: FloatArray, w: float) -> FloatArray:
        """(∇² + C ∇ + K) Q, shape (n, S)."""
        return self._derivative(dQ, w) + self._C @ dQ + self._K @ Q

    def residual(self, q: FloatArray, omega: float) -> FloatArray:
        """R(q, Ω), shape (n·(2H+1),)."""
        Q, dQ, g, _, _ = self._element_forces(q, omega)
        R = self._linear(Q, dQ, self.base_frequency(omega)) + self._B @ self.basis.analyze(g)
        return R.reshape(-1) - self._forcing_at(omega)

    def residual_jacobian(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R (n·S,), ∂R/∂q (n·S, n·S) and ∂R/∂Ω (n·S,) in one AFT pass (module docstring)."""
        w = self.base_frequency(omega)
        Q, dQ, g, gd, gv = self._element_forces(q, omega)
        n, m, S, H = self.n_coordinates, self.n_elements, self._S, self.basis.harmonics
        N = self.basis.samples
        spec = np.fft.rfft(np.concatenate((g, gd, gv)), axis=1)  # (3m, N/2+1)
        P = self.basis.from_complex(spec[:m, : H + 1] / N)  # 𝒜 g, (m, S)
        R = (self._linear(Q, dQ, w) + self._B @ P).reshape(-1) - self._forcing_at(omega)
        # Element blocks J_e = 𝒜 diag(∂g/∂δ) ℰ + 𝒜 diag(∂g/∂δ') ℰ ∇(ω).
        Jp = product_jacobians(spec[m:], N, self._tables)  # (2m, S, S)
        Jd, Jv = Jp[:m], Jp[m:]
        kw = self.basis.k * w
        Jd[:, :, H + 1 :] += Jv[:, :, 1 : H + 1] * kw  # (Jv ∇)[:, H+k] = kω Jv[:, k]
        Jd[:, :, 1 : H + 1] -= Jv[:, :, H + 1 :] * kw  # (Jv ∇)[:, k] = −kω Jv[:, H+k]
        J = np.zeros((n * S, n * S))
        J.reshape(-1)[self._lin_pos] = np.array([w * w, w, 1.0]) @ self._lin_vals
        J4 = J.reshape(n, S, n, S)
        for e, i, j, wij in self._W_entries:
            J4[i, :, j, :] += wij * Jd[e]
        # ∂R/∂Ω = (1/p) ∂R/∂ω.
        D1Q = self._derivative(Q, 1.0)
        vel1 = self.basis.synthesize(self._A @ D1Q)  # ℰ ∇(1) (a_e·Q), (m, N)
        Rw = self._derivative(D1Q, 2.0 * w) + self._C @ D1Q + self._B @ self.basis.analyze(gv * vel1)
        return R, J, load_slope(Rw.reshape(-1) / self.period, self._load, self._a0, omega)

    def newton_step(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray | None]:
        """R(q, Ω) and the Newton increment dq = −(∂R/∂q)⁻¹ R (None when ∂R/∂q is singular)."""
        R, J, _ = self.residual_jacobian(q, omega)
        _, _, dq, info = _gesv(J, -R)
        if info != 0 or not np.all(np.isfinite(dq)):
            return R, None
        return R, dq


def _check_regularisation(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not (np.isfinite(value) and value > 0):
        raise ValueError(f"`regularisation` (ε, the relative width of the smooth steps) must be a finite number "
                         f"> 0, got {value!r}; try 0.05 and decrease it along a sequence")
    return float(value)


__all__ = ["RegularisedSystemBalance"]
