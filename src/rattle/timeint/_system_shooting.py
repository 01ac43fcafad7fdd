"""Periodic orbits of a :class:`~rattle.model.System` by shooting on the exact flow.

A periodic orbit of period T = p·2π/Ω is a fixed point of the exact period map
z0 ↦ φ(z0; 0 → T). Newton's method solves r(z0) = φ(z0) − z0 = 0 with the Jacobian M − I, M the
exact monodromy matrix (the product of the stage transition matrices exp(A_s τ): the laws are
continuous, so the saltation matrices are the identity). Newton does not care about stability,
so unstable orbits are found as readily as stable ones; the map is only piecewise smooth where
the orbit grazes a breakpoint, hence the step halving when the residual does not decrease.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from .._validate import check_omega, check_shooting
from ..errors import ConvergenceError
from ..model import System
from ._flow import (
    SystemIntegrator,
    SystemMeasures,
    SystemTrajectory,
    check_system_state,
)
from ._shooting import ShotOrbit, monodromy_multipliers

_MAX_HALVINGS = 12


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class SystemOrbit(ShotOrbit):
    """A periodic orbit of a System found by shooting, with its exact stability and measures.

    ``state0`` z = (x, x') at t = 0 (2n,); ``omega`` (rad/s); ``period`` p (T = p·2π/Ω);
    ``monodromy`` the (2n, 2n) matrix ∂z(T)/∂z(0); ``multipliers`` its eigenvalues, largest
    modulus first; ``converged``, ``iterations`` (Newton steps), ``residual`` (scaled
    ‖φ(z0) − z0‖∞, see :func:`shoot_system_orbit`), ``evaluations`` (period maps integrated);
    ``trajectory`` over [0, T]; ``measures`` every element's mean, rms, rms_ac, extremes and
    peak-to-peak values of δ and δ'' over one orbit period (exact to round-off).
    """

    evaluations: int
    trajectory: SystemTrajectory
    measures: SystemMeasures

    def crossed(self, element: int | str) -> FloatArray:
        """The breakpoints the orbit crosses for one element (index or name), sorted, unique."""
        names = tuple(e.name for e in self.trajectory.system.elements)
        i = names.index(element) if isinstance(element, str) else int(element)
        sel = self.trajectory.crossing_elements == i
        return np.unique(self.trajectory.crossing_breakpoints[sel])


def system_state_scale(system: System, omega: float) -> FloatArray:
    """Scales of x and x' for the shooting residual: the system's length scale L for every
    coordinate, L times the larger of Ω and the stiffest natural frequency for every velocity."""
    length = system.length_scale()
    nu = max(float(omega), system.stiffest_frequency())
    return np.concatenate((np.full(system.n, length), np.full(system.n, length * nu)))


def shoot_system_orbit(
    system: System,
    omega: float,
    z0: FloatArray,
    *,
    period: int = 1,
    tol: float = 1e-12,
    max_iterations: int = 50,
    integrator: SystemIntegrator | None = None,
) -> SystemOrbit:
    """Periodic orbit of a System through Newton shooting on the exact flow.

    Parameters
    ----------
    system
        The equations of motion.
    omega
        Forcing frequency Ω (rad/s), > 0.
    z0
        Initial guess of the state (x, x') at t = 0, shape (2n,).
    period
        The orbit's period as a multiple p of the forcing period (T = p·2π/Ω).
    tol
        Convergence threshold on the scaled residual max_i |φ_i(z0) − z0_i| / s_i, with s the
        scales of :func:`system_state_scale`.
    max_iterations
        Newton iteration budget.
    integrator
        The :class:`SystemIntegrator` to use (default: one with default settings).

    Returns
    -------
    SystemOrbit
        Check ``converged``: a failed solve is returned, not raised (the last iterate).
    """
    if not isinstance(system, System):
        raise TypeError(f"`system` must be a rattle.model.System, got {system!r}")
    omega = check_omega(omega)
    z = check_system_state(z0, system.n)
    check_shooting(period, tol, max_iterations)
    integ = SystemIntegrator(system) if integrator is None else integrator
    if not isinstance(integ, SystemIntegrator):
        raise TypeError(f"`integrator` must be a SystemIntegrator or None, got {integrator!r}")
    if integ.system is not system:
        raise ValueError("`integrator` was built for a different system than `system`")

    shot = _newton_system(integ, omega, z, int(period), float(tol), int(max_iterations),
                          system_state_scale(system, omega))
    traj = shot.trajectory
    return SystemOrbit(
        state0=shot.x, omega=omega, period=int(period), monodromy=traj.sensitivity,
        multipliers=monodromy_multipliers(traj.sensitivity),
        converged=shot.residual <= tol, iterations=shot.iterations, residual=shot.residual,
        evaluations=shot.evaluations, trajectory=traj, measures=traj.measures(),
    )


@dataclass(frozen=True, slots=True, eq=False)
class _SystemShot:
    """A Newton shooting solve of a System before measures: last iterate ``x``, its trajectory
    over one orbit period, scaled ``residual``, Newton ``iterations``, period maps ``evaluations``."""

    x: FloatArray
    trajectory: SystemTrajectory
    residual: float
    iterations: int
    evaluations: int

    def multipliers(self) -> ComplexArray:
        """Eigenvalues of the monodromy matrix, largest modulus first."""
        return monodromy_multipliers(self.trajectory.sensitivity)


def _newton_system(integ: SystemIntegrator | Any, omega: float, z0: FloatArray, period: int, tol: float,
                   max_iterations: int, scale: FloatArray, max_halvings: int = _MAX_HALVINGS) -> _SystemShot:
    """Newton's method on r(z0) = φ(z0; 0 → p·2π/Ω) − z0 with the exact monodromy, the period
    maps without records (:meth:`SystemIntegrator.advance`), the last iterate's trajectory
    recorded once (the core of :func:`shoot_system_orbit`, also used by ``steady_state``)."""
    T = period * 2.0 * math.pi / omega
    z = np.asarray(z0, dtype=float).copy()
    eye = np.eye(z.size)
    z1, M = integ.advance(z, 0.0, T, omega)
    evaluations = 1
    r = z1 - z
    res = float(np.max(np.abs(r / scale)))
    iterations = 0
    while res > tol and iterations < max_iterations:
        iterations += 1
        J = M - eye
        try:
            dz = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:  # a multiplier exactly 1 (fold): least-squares step
            dz = np.linalg.lstsq(J, -r, rcond=None)[0]
        step = 1.0
        for _ in range(max_halvings + 1):
            z_try = z + step * dz
            try:
                z1_try, M_try = integ.advance(z_try, 0.0, T, omega)
            except ConvergenceError:  # a trial state the flow cannot follow (an event budget): shorter step
                step *= 0.5
                continue
            evaluations += 1
            r_try = z1_try - z_try
            res_try = float(np.max(np.abs(r_try / scale)))
            if res_try < res:
                break
            step *= 0.5
        else:
            break  # no decrease along the Newton direction: give up (converged stays False)
        z, M, r, res = z_try, M_try, r_try, res_try
    traj = integ.propagate(z, 0.0, T, omega)
    evaluations += 1
    return _SystemShot(z, traj, res, iterations, evaluations)

__all__ = ["SystemOrbit", "shoot_system_orbit", "system_state_scale"]
