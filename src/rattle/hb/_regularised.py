"""Harmonic balance of one coordinate with a discontinuous law, by regularisation.

A preload (a torque jump at δ = 0) and Coulomb friction (a torque jump at δ' = 0) make the
restoring force discontinuous:

    δ'' + c δ' + g(δ, δ') = F(t),   F(t) = F_m + Σ_n F_pn cos(nΩt + φ_n),

with g = k f(δ) + P s(δ) + r(δ) sgn(δ') (f the continuous piecewise-linear law, s the preload's
sign-like jumps, r ≥ 0 the friction level per unit inertia). A truncated Fourier series cannot
hold a jump of g(t) and Newton cannot differentiate one, so the harmonic balance solves the
regularised equation, each sign replaced by a smooth step of width ε:

    sgn(δ) → tanh(δ / ε_δ),   sgn(δ') → tanh(δ' / ε_v),   ε_δ = ε L,   ε_v = ε L ω_n,

L the length scale of the law and ω_n its natural frequency (fixed scales: g does not depend on
Ω). The law supplies g_ε and its partial derivatives (:class:`RegularisedForce`). The residual
and Jacobian are those of the AFT method with a velocity-dependent force: for the real series q
of δ (q = [a_0, a_1 … a_H, b_1 … b_H], base frequency ω = Ω/p),

    R(q, Ω) = (∇² + c ∇) q + 𝒜 g_ε(ℰ q, ℰ ∇ q) − F,
    ∂R/∂q = ∇² + c ∇ + 𝒜 diag(∂g/∂δ) ℰ + 𝒜 diag(∂g/∂δ') ℰ ∇,
    ∂R/∂Ω = (1/p) [(2∇ + c I) ∂∇/∂ω q + 𝒜 diag(∂g/∂δ') ℰ ∂∇/∂ω q],

with ℰ (N × (2H+1)) the synthesis at N samples per period, 𝒜 = ℰ⁺ the truncated analysis and
∇(ω) the derivative operator (:meth:`FourierBasis.derivative_matrix`; ∂∇/∂ω = ∇(1)). The
products 𝒜 diag(w) ℰ are assembled from the spectrum of the samples w by the product rule of the
harmonic balance's core (:func:`~rattle.hb._residual.product_jacobians`, O(N log N + H²)).

Regularisation changes the answer: the orbit of the ε-problem differs from the discontinuous
one by O(ε) in general (a smooth step of width ε shifts where the jump acts by a fraction of ε
and turns sticking into creeping at a speed ~ε_v). A :class:`RegularisedBalance` is therefore
solved along a decreasing sequence of ε (the previous solution starting the next; see
:func:`rattle.analysis.regularisation_limit`) and checked against the exact event-driven orbit.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from .._typing import FloatArray
from ._basis import FourierBasis
from ._options import HBOptions
from ._residual import product_jacobians, product_tables


@runtime_checkable
class RegularisedForce(Protocol):
    """A discontinuous restoring force per unit inertia g(δ, δ') and its regularisation."""

    def regularised(self, delta: FloatArray, velocity: FloatArray, width: float,
                    velocity_width: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """g_ε, ∂g_ε/∂δ and ∂g_ε/∂δ' at the samples (arrays of one shape), the signs replaced by
        tanh(δ/``width``) and tanh(δ'/``velocity_width``)."""
        ...


class RegularisedBalance:
    """R(q, Ω) = 0 of the regularised single equation (module docstring), a
    :class:`~rattle.continuation.ContinuationProblem` in Ω.

    Parameters
    ----------
    damping
        c, the viscous damping per unit inertia (> 0).
    force
        The law (:class:`RegularisedForce`).
    mean, amplitudes, phases
        F_m and F_pn, φ_n of the forcing, harmonics n = 1, 2, … of Ω.
    regularisation
        ε > 0, the relative width of the smooth steps.
    length_scale, frequency_scale
        L and ω_n: ε_δ = ε L, ε_v = ε L ω_n; also the scales of the unknowns and of Ω.
    options
        The harmonics and samples (:class:`HBOptions`).
    period
        p: the solution's period is p forcing periods.
    """

    def __init__(self, damping: float, force: RegularisedForce, mean: float, amplitudes: tuple[float, ...],
                 phases: tuple[float, ...] | None, *, regularisation: float, length_scale: float,
                 frequency_scale: float, options: HBOptions | None = None, period: int = 1) -> None:
        options = HBOptions() if options is None else options
        if not isinstance(force, RegularisedForce):
            raise TypeError(f"`force` must provide regularised(delta, velocity, width, velocity_width), got {force!r}")
        for name, v in (("damping", damping), ("regularisation", regularisation), ("length_scale", length_scale),
                        ("frequency_scale", frequency_scale)):
            if not (isinstance(v, (int, float)) and np.isfinite(v) and v > 0):
                raise ValueError(f"`{name}` must be a finite number > 0, got {v!r}")
        if isinstance(period, bool) or not isinstance(period, int) or period < 1:
            raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
        amps = tuple(float(a) for a in amplitudes)
        phs = tuple(float(p) for p in phases) if phases is not None else (0.0,) * len(amps)
        if len(phs) != len(amps):
            raise ValueError(f"`phases` must have one entry per amplitude ({len(amps)}), got {len(phs)}")
        if options.harmonics < len(amps) * period:
            raise ValueError(f"`harmonics` must be >= {len(amps) * period} to hold the forcing, got {options.harmonics}")
        self.c = float(damping)
        self.force = force
        self.period = period
        self.options = options
        self.eps = float(regularisation)
        self._L = float(length_scale)
        self._wn = float(frequency_scale)
        H, N = options.harmonics, options.n_samples
        self.basis = FourierBasis(H, N)
        S = 2 * H + 1
        F = np.zeros(S)
        F[0] = float(mean)
        for n, (a, ph) in enumerate(zip(amps, phs), start=1):
            F[n * period] += a * np.cos(ph)
            F[H + n * period] -= a * np.sin(ph)
        self.forcing = F
        self.amplitude_scale = abs(float(mean)) + sum(abs(a) for a in amps)
        self._D1 = self.basis.derivative_matrix(1.0)  # ∇(ω) = ω ∇(1)
        self._D1sq = -np.concatenate(([0.0], self.basis.k**2, self.basis.k**2))  # ∇(1)² = −diag(0, k², k²)
        self._tables = product_tables(H, 2)

    # --- scales (ContinuationProblem) --------------------------------------------------------
    @property
    def size(self) -> int:
        return self.basis.size

    @property
    def length_scale(self) -> float:
        return self._L

    @property
    def parameter_scale(self) -> float:
        return self._wn

    @property
    def force_scale(self) -> float:
        return max(self.amplitude_scale, 1e-300)

    @property
    def widths(self) -> tuple[float, float]:
        """(ε_δ, ε_v): the widths of the smooth steps in δ (rad) and δ' (rad/s)."""
        return self.eps * self._L, self.eps * self._L * self._wn

    def with_regularisation(self, regularisation: float) -> RegularisedBalance:
        """The same problem with another ε (shares the matrices)."""
        out = object.__new__(RegularisedBalance)
        out.__dict__.update(self.__dict__)
        if not (np.isfinite(regularisation) and regularisation > 0):
            raise ValueError(f"`regularisation` must be a finite number > 0, got {regularisation!r}")
        out.eps = float(regularisation)
        return out

    # --- residual ------------------------------------------------------------------------------
    def samples(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray]:
        """δ(t_j) and δ'(t_j) at the N samples of the solution period."""
        w = omega / self.period
        return self.basis.synthesize(q), self.basis.synthesize(w * (self._D1 @ q))

    def residual(self, q: FloatArray, omega: float) -> FloatArray:
        return self.residual_jacobian(q, omega, jacobian=False)[0]

    def residual_jacobian(self, q: FloatArray, omega: float, jacobian: bool = True):  # type: ignore[no-untyped-def]
        """R, ∂R/∂q and ∂R/∂Ω (module docstring)."""
        q = np.asarray(q, dtype=float)
        w = omega / self.period
        D = w * self._D1
        dq = D @ q
        delta, vel = self.basis.synthesize(np.stack((q, dq)))
        g, g_d, g_v = self.force.regularised(delta, vel, *self.widths)
        lin = D @ (dq + self.c * q)  # (∇² + c∇) q
        R = lin + self.basis.analyze(g) - self.forcing
        if not jacobian:
            return R, None, None
        # 𝒜 diag(w) ℰ from the spectrum of w (the product rule, O(N log N + H²); exact for N ≥ 4H + 1)
        Jd, Jv = product_jacobians(np.fft.rfft(np.stack((g_d, g_v)), axis=1), self.basis.samples, self._tables)
        # ∇(ω)² + c ∇(ω) + Jd + Jv ∇(ω); ∇ couples (cos k, sin k) only: Jv ∇ is Jv's columns swapped and scaled
        # (O(S²), where the dense products cost O(S³) and were most of a Newton step)
        H = self.basis.harmonics
        J = Jd + self.c * D
        J[np.diag_indices_from(J)] += (w * w) * self._D1sq
        kw = self.basis.k * w
        J[:, 1 : H + 1] -= Jv[:, H + 1 :] * kw
        J[:, H + 1 :] += Jv[:, 1 : H + 1] * kw
        d1q = self._D1 @ q
        Rw = (D @ d1q + self._D1 @ dq + self.c * d1q + self.basis.analyze(g_v * self.basis.synthesize(d1q))) / self.period
        return R, J, Rw

    def newton_step(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray | None]:
        R, J, _ = self.residual_jacobian(q, omega)
        try:
            dq = np.linalg.solve(J, -R)
        except np.linalg.LinAlgError:
            return R, None
        return R, (dq if np.all(np.isfinite(dq)) else None)


__all__ = ["RegularisedBalance", "RegularisedForce"]
