"""Periodic orbits by shooting, as a continuation problem in the forcing frequency.

For a :class:`~rattle.model.System` with n coordinates, a periodic orbit of period
T = p·2π/Ω is a fixed point of the exact period map z(0) ↦ φ_T(z(0); Ω), z = (x, x'). With the
unknowns q = z(0) (2n numbers) and the parameter Ω the residual is the scaled defect

    R(q, Ω) = (φ_T(q; Ω) − q) / s,      s = (L, …, L, L ω_s, …, L ω_s),

L the system's length scale and ω_s its stiffest natural frequency (fixed scales, so R is smooth
in Ω), with the exact Jacobians

    ∂R/∂q = (M − I) / s,      ∂R/∂Ω = (∂φ_T/∂Ω at fixed phase) / s,

M the exact monodromy (product of the stage transition matrices exp(A_s τ)) and ∂φ_T/∂Ω from
:meth:`SystemTrajectory.omega_derivative` (``fixed="phase"``: T = p·2π/Ω moves with Ω). It
implements :class:`rattle.continuation.ContinuationProblem` structurally (this module does not
import the continuation layer above it): ``length_scale`` = s, ``parameter_scale`` = ω_s,
``force_scale`` = 1 (R is already scaled), and a cheap fixed-Ω :meth:`newton_step` on the
period map without records. At a fold det(M − I) = 0, so det ∂R/∂q is a fold test function.
"""

from __future__ import annotations

import math

import numpy as np

from .._typing import FloatArray
from ..model import System
from ._flow import SystemIntegrator


class ShootingProblem:
    """R(z(0), Ω) = (φ_T(z(0); Ω) − z(0)) / s of a :class:`~rattle.model.System` (module docstring).

    Parameters
    ----------
    system
        The equations of motion.
    period
        The orbit's period as a multiple p of the forcing period (T = p·2π/Ω), ≥ 1.
    integrator
        The :class:`SystemIntegrator` to use (default: one with default settings for ``system``).
    """

    def __init__(self, system: System, *, period: int = 1, integrator: SystemIntegrator | None = None) -> None:
        if not isinstance(system, System):
            raise TypeError(f"`system` must be a rattle.model.System, got {system!r}")
        if isinstance(period, bool) or not isinstance(period, (int, np.integer)) or period < 1:
            raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
        integ = SystemIntegrator(system) if integrator is None else integrator
        if not isinstance(integ, SystemIntegrator) or integ.system is not system:
            raise ValueError("`integrator` must be a SystemIntegrator built for `system` (or None)")
        self.system = system
        self.period = int(period)
        self.integrator = integ
        n = system.n
        self._omega_s = float(system.stiffest_frequency())
        L = float(system.length_scale())
        self._scale = np.concatenate((np.full(n, L), np.full(n, L * self._omega_s)))
        self._eye = np.eye(2 * n)

    # --- the ContinuationProblem protocol ------------------------------------------------------
    @property
    def size(self) -> int:
        """2n: the state (x, x') at t = 0."""
        return 2 * self.system.n

    @property
    def length_scale(self) -> FloatArray:
        """s (2n,): L for the coordinates, L ω_s for the velocities."""
        return self._scale

    @property
    def parameter_scale(self) -> float:
        """ω_s, the system's stiffest natural frequency (rad/s)."""
        return self._omega_s

    @property
    def force_scale(self) -> float:
        """1: the residual is already scaled by s."""
        return 1.0

    def orbit_period(self, omega: float) -> float:
        """T = p·2π/Ω (s)."""
        return self.period * 2.0 * math.pi / omega

    def residual(self, q: FloatArray, omega: float) -> FloatArray:
        """R(q, Ω) = (φ_T(q; Ω) − q) / s, shape (2n,)."""
        q = np.asarray(q, dtype=float)
        z1, _ = self.integrator.advance(q, 0.0, self.orbit_period(omega), omega, sensitivity=False)
        return (z1 - q) / self._scale

    def residual_jacobian(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R (2n,), ∂R/∂q = (M − I)/s (2n, 2n) and ∂R/∂Ω (2n,), exact (one recorded period map)."""
        q = np.asarray(q, dtype=float)
        traj = self.integrator.propagate(q, 0.0, self.orbit_period(omega), omega)
        s = self._scale
        R = (traj.state1 - q) / s
        Rq = (traj.sensitivity - self._eye) / s[:, None]
        Rw = traj.omega_derivative(fixed="phase") / s
        return R, Rq, Rw

    def newton_step(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray | None]:
        """R(q, Ω) and the Newton increment −(M − I)⁻¹ (φ_T(q) − q) (None if M − I is singular):
        the period map without records and without ∂/∂Ω."""
        q = np.asarray(q, dtype=float)
        z1, M = self.integrator.advance(q, 0.0, self.orbit_period(omega), omega)
        r = z1 - q
        try:
            dq = np.linalg.solve(M - self._eye, -r)
        except np.linalg.LinAlgError:
            return r / self._scale, None
        return r / self._scale, (dq if np.all(np.isfinite(dq)) else None)

    # --- for test functions -----------------------------------------------------------------------
    def monodromy(self, q: FloatArray, omega: float) -> FloatArray:
        """The exact monodromy M = ∂φ_T/∂z(0) (2n, 2n) of the period map from q."""
        _, M = self.integrator.advance(np.asarray(q, dtype=float), 0.0, self.orbit_period(omega), omega)
        return M


__all__ = ["ShootingProblem"]
