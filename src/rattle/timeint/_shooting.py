"""Periodic orbits of δ'' + c δ' + k f(δ) = F(t) by shooting on the exact flow.

A periodic orbit of period T = p·2π/Ω (p = 1 primary, p = n a 1/n sub-harmonic) is a fixed point
of the exact period map x0 ↦ φ(x0; 0 → T). Newton's method solves r(x0) = φ(x0) − x0 = 0 with the
Jacobian M − I, M = ∂φ/∂x0 the exact monodromy matrix (product of the stage transition matrices;
the saltation matrices of the crossings are the identity because f is continuous). Newton does
not care about stability, so unstable orbits are found as readily as stable ones. The map is only
piecewise smooth where the orbit grazes a breakpoint, hence the step halving when the residual
does not decrease.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._typing import ComplexArray, FloatArray
from .._validate import check_omega, check_shooting
from ..errors import RattleError
from ..model import Model
from ._exact import ExactIntegrator, Trajectory

_MAX_HALVINGS = 12



#: What an exact flow or its shooting raises when it cannot follow the motion (the event budget
#: of a chatter, a loop of stuck elements, a singular step; numpy's LinAlgError is a ValueError):
#: the callers then report the orbit or row as not found instead of stopping.
FLOW_FAILURES: tuple[type[Exception], ...] = (RattleError, ValueError, ArithmeticError)


def monodromy_multipliers(M: FloatArray) -> ComplexArray:
    """The Floquet multipliers: the eigenvalues of the monodromy matrix ``M``, largest modulus
    first (a stable sort: equal moduli keep the solver's order)."""
    mu = np.linalg.eigvals(M).astype(complex)
    return mu[np.argsort(-np.abs(mu), kind="stable")]


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class ShotOrbit:
    """What every Newton shooting on an exact flow returns (:class:`ShootingOrbit`,
    :class:`~rattle.timeint.SystemOrbit`, :class:`~rattle.timeint.NonsmoothOrbit` add their
    trajectory and measures): ``state0`` at t = 0, ``omega``, ``period`` p (T = p·2π/Ω),
    ``monodromy`` M = ∂x(T)/∂x(0), its ``multipliers`` (largest modulus first), ``converged``,
    ``iterations`` (Newton steps) and ``residual`` (the scaled ‖φ(x0) − x0‖∞)."""

    state0: FloatArray
    omega: float
    period: int
    monodromy: FloatArray
    multipliers: ComplexArray
    converged: bool
    iterations: int
    residual: float

    @property
    def stable(self) -> bool:
        """True when every Floquet multiplier lies inside the unit circle."""
        return bool(np.all(np.abs(self.multipliers) < 1.0))


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class ShootingOrbit(ShotOrbit):
    """A periodic orbit found by shooting, with its exact stability and response measures.

    ``state0`` (δ, δ') at t = 0 (rad, rad/s); ``omega`` the forcing frequency (rad/s); ``period``
    the orbit's period as a multiple p of the forcing period 2π/Ω; ``monodromy`` the 2×2 matrix M =
    ∂x(T)/∂x(0); ``multipliers`` its eigenvalues sorted by modulus, largest first (their product
    is det M = exp(−c T)); ``converged``, ``iterations`` (Newton steps) and ``residual`` (scaled
    ‖φ(x0) − x0‖∞, see :func:`shoot_periodic_orbit`); ``evaluations`` the number of period maps
    φ integrated (the work done); ``trajectory`` over [0, T]; and the measures
    of SPEC §1 over one orbit period (exact to round-off): ``mean``, ``rms``, ``rms_ac``,
    ``delta_min``, ``delta_max``, ``p2p``, ``acc_min``, ``acc_max``, ``acc_p2p``.
    """

    trajectory: Trajectory
    mean: float
    rms: float
    rms_ac: float
    delta_min: float
    delta_max: float
    p2p: float
    acc_min: float
    acc_max: float
    acc_p2p: float
    evaluations: int = 0

    @property
    def regime(self) -> str:
        """``no_impact``, ``single_sided`` or ``double_sided`` (SPEC §1), from the breakpoints
        the orbit crosses."""
        crossed = self.trajectory.crossed_breakpoints
        if crossed.size == 0:
            return "no_impact"
        if np.all(crossed > 0.0) or np.all(crossed < 0.0):
            return "single_sided"
        return "double_sided"


def _state_scale(model: Model, omega: float) -> FloatArray:
    """Scales of δ and δ' for the residual: the model's length scale L, and L times the fastest
    of the forcing frequency and the stiffest stage's natural frequency."""
    length = model.length_scale()
    stiffest = math.sqrt(model.k * float(np.max(model.elastic.stages.slopes)))
    return np.array([length, length * max(omega, stiffest)])


def shoot_periodic_orbit(
    model: Model,
    omega: float,
    x0: FloatArray | tuple[float, float],
    *,
    period: int = 1,
    tol: float = 1e-12,
    max_iterations: int = 50,
    integrator: ExactIntegrator | None = None,
) -> ShootingOrbit:
    """Periodic orbit of δ'' + c δ' + k f(δ) = F(t) through Newton shooting on the exact flow.

    Parameters
    ----------
    model
        The model.
    omega
        Forcing frequency Ω (rad/s), > 0.
    x0
        Initial guess of the state (δ, δ') at t = 0 (rad, rad/s), shape (2,).
    period
        The orbit's period as a multiple p of the forcing period (T = p·2π/Ω).
    tol
        Convergence threshold on the scaled residual max(|Δδ|/L, |Δδ'|/(L ν)) of
        φ(x0; 0 → T) − x0, with L = ``model.length_scale()`` and ν the larger of Ω and the
        stiffest stage's natural frequency.
    max_iterations
        Newton iteration budget.
    integrator
        The :class:`ExactIntegrator` to use (default: one with default settings).

    Returns
    -------
    ShootingOrbit
        Check ``converged``: a failed solve is returned, not raised (the last iterate).
    """
    if not isinstance(model, Model):
        raise TypeError(f"`model` must be a rattle Model, got {model!r}")
    omega = check_omega(omega)
    check_shooting(period, tol, max_iterations)
    integ = ExactIntegrator(model) if integrator is None else integrator
    if integ.model is not model and integ.model != model:
        raise ValueError("`integrator` was built for a different model than `model`")

    shot = _newton_shooting(integ, omega, x0, int(period), float(tol), int(max_iterations),
                            _state_scale(model, omega))
    return _orbit_from_shot(shot, omega, int(period), float(tol))


@dataclass(frozen=True, slots=True, eq=False)
class _Shot:
    """The outcome of a Newton shooting solve before measures: last iterate ``x``, its trajectory
    over one orbit period, scaled ``residual``, Newton ``iterations`` and period-map ``evaluations``."""

    x: FloatArray
    trajectory: Trajectory
    residual: float
    iterations: int
    evaluations: int

    def multipliers(self) -> ComplexArray:
        """Eigenvalues of the monodromy matrix, largest modulus first."""
        return monodromy_multipliers(self.trajectory.sensitivity)


def _newton_shooting(
    integ: ExactIntegrator, omega: float, x0: FloatArray | tuple[float, float], period: int, tol: float,
    max_iterations: int, scale: FloatArray, max_halvings: int = _MAX_HALVINGS,
) -> _Shot:
    """Newton's method on r(x0) = φ(x0; 0 → p·2π/Ω) − x0 with the exact monodromy (no measures:
    the cheap core of :func:`shoot_periodic_orbit`, also used by ``steady_state``)."""
    T = period * 2.0 * math.pi / omega
    x = np.asarray(x0, dtype=float).copy()
    traj = integ.propagate(x, 0.0, T, omega)
    evaluations = 1
    r = traj.state1 - x
    res = float(np.max(np.abs(r / scale)))
    iterations = 0
    while res > tol and iterations < max_iterations:
        iterations += 1
        J = traj.sensitivity - np.eye(2)
        try:
            dx = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:  # a multiplier exactly 1 (fold): least-squares step
            dx = np.linalg.lstsq(J, -r, rcond=None)[0]
        step = 1.0
        for _ in range(max_halvings + 1):
            x_try = x + step * dx
            traj_try = integ.propagate(x_try, 0.0, T, omega)
            evaluations += 1
            r_try = traj_try.state1 - x_try
            res_try = float(np.max(np.abs(r_try / scale)))
            if res_try < res:
                break
            step *= 0.5
        else:
            break  # no decrease along the Newton direction: give up (converged stays False)
        x, traj, r, res = x_try, traj_try, r_try, res_try
    return _Shot(x=x, trajectory=traj, residual=res, iterations=iterations, evaluations=evaluations)


def _orbit_from_shot(shot: _Shot, omega: float, period: int, tol: float) -> ShootingOrbit:
    """The :class:`ShootingOrbit` of a Newton solve: multipliers and exact measures."""
    traj = shot.trajectory
    meas = traj.measures()
    return ShootingOrbit(
        state0=shot.x, omega=omega, period=period, monodromy=traj.sensitivity,
        multipliers=shot.multipliers(), converged=shot.residual <= tol, iterations=shot.iterations,
        residual=shot.residual, trajectory=traj, mean=meas.mean, rms=meas.rms, rms_ac=meas.rms_ac,
        delta_min=meas.delta_min, delta_max=meas.delta_max, p2p=meas.p2p, acc_min=meas.acc_min,
        acc_max=meas.acc_max, acc_p2p=meas.acc_p2p, evaluations=shot.evaluations,
    )


__all__ = ["ShootingOrbit", "shoot_periodic_orbit"]
