"""Periodic orbits by shooting, as a continuation problem in the forcing frequency.

For any of rattle's equations of motion — a smooth :class:`~rattle.model.System`, the single
equation with a discontinuous law (:class:`~rattle.model.NonsmoothSystem`) or a chain with
torque jumps and Coulomb friction on its elements (:class:`~rattle.model.FrictionSystem`) — a
periodic orbit of period T = p·2π/Ω is a fixed point of the exact period map
z(0) ↦ φ_T(z(0); Ω), z = (x, x'). With the unknowns q = z(0) (2n numbers) and the parameter Ω
the residual is the scaled defect

    R(q, Ω) = (φ_T(q; Ω) − q) / s,      s = (L, …, L, L ω_s, …, L ω_s),

L the system's length scale and ω_s its stiffest natural frequency (fixed scales, so R is smooth
in Ω wherever the period map is), with the Jacobians

    ∂R/∂q = (M − I) / s,      ∂R/∂Ω = (∂φ_T/∂Ω at fixed phase) / s,

M the exact monodromy: the product of the stage (or mode) transition matrices exp(A_s τ) and,
for the discontinuous laws, the saltation matrices of the crossings of a jump and of the stick,
slip and lock transitions (:mod:`._friction_chain`). ∂φ_T/∂Ω is exact for a smooth System
(:meth:`SystemTrajectory.omega_derivative`, ``fixed="phase"``: T = p·2π/Ω moves with Ω); for the
discontinuous laws it is the forward difference (φ_T(q; Ω + h) − φ_T(q; Ω)) / h with
h = √ε_mach · Ω, relative error O(h) ≈ 1e-8 — it enters only the corrector's Jacobian and the
tangent, so the branch points (R = 0) are exact whatever its error, and Newton's rate is
unchanged to that order.

It implements :class:`rattle.continuation.ContinuationProblem` structurally (this module does not
import the continuation layer above it): ``length_scale`` = s, ``parameter_scale`` = ω_s,
``force_scale`` = 1 (R is already scaled), and a cheap fixed-Ω :meth:`newton_step` on the
period map without records. At a fold det(M − I) = 0, so det ∂R/∂q is a fold test function.
The period map is defined wherever the flow can be followed; where it cannot (an event budget,
a grazing the integrator refuses) :meth:`residual` raises :class:`~rattle.errors.ConvergenceError`
and :meth:`residual_jacobian` of a discontinuous law returns nan, which the corrector treats as a
failed step.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..model import FrictionSystem, NonsmoothSystem, System
from ._flow import SystemIntegrator
from ._friction_chain import FrictionIntegrator
from ._nonsmooth import NonsmoothIntegrator
from ._shooting import FLOW_FAILURES

#: Relative step of the forward difference in Ω of a discontinuous law's period map.
OMEGA_STEP = math.sqrt(np.finfo(float).eps)

#: Scaled distance within which a discontinuous law's ∂φ_T/∂Ω is taken again (:meth:`ShootingProblem._omega_derivative`).
REUSE_DISTANCE = 1e-4

Shootable = System | NonsmoothSystem | FrictionSystem


def _default_integrator(system: Shootable) -> Any:
    if isinstance(system, System):
        return SystemIntegrator(system)
    if isinstance(system, NonsmoothSystem):
        return NonsmoothIntegrator(system)
    return FrictionIntegrator(system)


def _scales(system: Shootable) -> tuple[int, float, float]:
    """n, L and ω_s of ``system``."""
    if isinstance(system, System):
        return system.n, float(system.length_scale()), float(system.stiffest_frequency())
    if isinstance(system, NonsmoothSystem):
        s = system.law.stages.slopes
        return 1, float(system.length_scale()), math.sqrt(system.k * float(np.max(s)))
    return system.n, float(system.length_scale()), float(system.frequency_scale())


class ShootingProblem:
    """R(z(0), Ω) = (φ_T(z(0); Ω) − z(0)) / s of any of rattle's systems (module docstring).

    Parameters
    ----------
    system
        The equations of motion: a :class:`~rattle.model.System`, a
        :class:`~rattle.model.NonsmoothSystem` or a :class:`~rattle.model.FrictionSystem`.
    period
        The orbit's period as a multiple p of the forcing period (T = p·2π/Ω), ≥ 1.
    integrator
        The exact integrator to use, built for ``system`` (default: the system's own with default
        settings: :class:`SystemIntegrator`, :class:`NonsmoothIntegrator` or
        :class:`FrictionIntegrator`).
    """

    def __init__(self, system: Shootable, *, period: int = 1, integrator: Any = None) -> None:
        if not isinstance(system, (System, NonsmoothSystem, FrictionSystem)):
            raise TypeError(f"`system` must be a rattle.model.System, NonsmoothSystem or FrictionSystem, got {system!r}")
        if isinstance(period, bool) or not isinstance(period, (int, np.integer)) or period < 1:
            raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
        integ = _default_integrator(system) if integrator is None else integrator
        kind = SystemIntegrator if isinstance(system, System) else (
            NonsmoothIntegrator if isinstance(system, NonsmoothSystem) else FrictionIntegrator)
        own = getattr(integ, "fsys", None) if isinstance(integ, FrictionIntegrator) else getattr(integ, "system", None)
        if not isinstance(integ, kind) or own is not system:
            raise ValueError("`integrator` must be an exact integrator built for `system` (or None)")
        self.system = system
        self.period = int(period)
        self.integrator = integ
        self._smooth = isinstance(system, System)
        n, L, omega_s = _scales(system)
        self.n = n
        self._omega_s = omega_s
        self._scale = np.concatenate((np.full(n, L), np.full(n, L * omega_s)))
        self._eye = np.eye(2 * n)
        self._last_zw: tuple[FloatArray, float, FloatArray] | None = None

    # --- the ContinuationProblem protocol ------------------------------------------------------
    @property
    def size(self) -> int:
        """2n: the state (x, x') at t = 0."""
        return 2 * self.n

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

    def period_map(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray]:
        """φ_T(q; Ω) (2n,) and the exact monodromy M = ∂φ_T/∂q (2n, 2n), without records."""
        q = np.asarray(q, dtype=float)
        T = self.orbit_period(omega)
        if isinstance(self.integrator, NonsmoothIntegrator):
            traj = self.integrator.propagate(q, 0.0, T, omega)
            return traj.state1, traj.sensitivity
        return self.integrator.advance(q, 0.0, T, omega)

    def residual(self, q: FloatArray, omega: float) -> FloatArray:
        """R(q, Ω) = (φ_T(q; Ω) − q) / s, shape (2n,)."""
        q = np.asarray(q, dtype=float)
        if self._smooth:
            z1, _ = self.integrator.advance(q, 0.0, self.orbit_period(omega), omega, sensitivity=False)
        else:
            try:
                z1, _ = self.period_map(q, omega)
            except FLOW_FAILURES:  # the flow cannot be followed from q: no residual
                return np.full(2 * self.n, np.nan)
        return (z1 - q) / self._scale

    def residual_jacobian(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R (2n,), ∂R/∂q = (M − I)/s (2n, 2n) and ∂R/∂Ω (2n,) (module docstring)."""
        q = np.asarray(q, dtype=float)
        s = self._scale
        if self._smooth:
            traj = self.integrator.propagate(q, 0.0, self.orbit_period(omega), omega)
            z1, M = traj.state1, traj.sensitivity
            zw = traj.omega_derivative(fixed="phase")
        else:
            try:
                z1, M = self.period_map(q, omega)
                zw = self._omega_derivative(q, omega, z1)
            except FLOW_FAILURES:  # the flow cannot be followed from q: no residual (a failed corrector step)
                nan = np.full(2 * self.n, np.nan)
                return nan, np.full((2 * self.n, 2 * self.n), np.nan), nan
        return (z1 - q) / s, (M - self._eye) / s[:, None], zw / s

    def _omega_derivative(self, q: FloatArray, omega: float, z1: FloatArray) -> FloatArray:
        """∂φ_T/∂Ω by the forward difference (module docstring); within :data:`REUSE_DISTANCE` (scaled,
        in q and in Ω) of the point where it was last taken, that value again: a corrector's
        iterations move the point by less, and the column enters only the Jacobian (the chord
        method in Ω: the residual, hence every branch point, stays exact)."""
        last = self._last_zw
        if last is not None:
            q0, w0, zw0 = last
            if abs(omega - w0) <= REUSE_DISTANCE * self._omega_s and \
                    float(np.max(np.abs(q - q0) / self._scale)) <= REUSE_DISTANCE:
                return zw0
        h = OMEGA_STEP * omega
        zh, _ = self.period_map(q, omega + h)
        zw = (zh - z1) / h
        self._last_zw = (q.copy(), float(omega), zw)
        return zw

    def newton_step(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray | None]:
        """R(q, Ω) and the Newton increment −(M − I)⁻¹ (φ_T(q) − q) (None if M − I is singular):
        the period map without records and without ∂/∂Ω."""
        q = np.asarray(q, dtype=float)
        try:
            z1, M = self.period_map(q, omega)
        except FLOW_FAILURES:
            if self._smooth:
                raise
            return np.full(2 * self.n, np.nan), None
        r = z1 - q
        try:
            dq = np.linalg.solve(M - self._eye, -r)
        except np.linalg.LinAlgError:
            return r / self._scale, None
        return r / self._scale, (dq if np.all(np.isfinite(dq)) else None)

    # --- for test functions -----------------------------------------------------------------------
    def monodromy(self, q: FloatArray, omega: float) -> FloatArray:
        """The exact monodromy M = ∂φ_T/∂z(0) (2n, 2n) of the period map from q."""
        return self.period_map(q, omega)[1]


__all__ = ["ShootingProblem"]
