"""Periodic orbits by Newton shooting on the exact flow, for every kind of system.

A periodic orbit of period T = p·2π/Ω (p = 1 primary, p = n a 1/n sub-harmonic) is a fixed point
of the exact period map x0 ↦ φ(x0; 0 → T). Newton's method solves r(x0) = φ(x0) − x0 = 0 with the
Jacobian M − I, M = ∂φ/∂x0 the exact monodromy matrix: the product of the stage transition
matrices exp(A τ) and, for the discontinuous laws, the saltation matrices of their switchings
(the identity across a breakpoint of a continuous law). Newton does not care about stability, so
unstable orbits are found as readily as stable ones. The map is only piecewise smooth where the
orbit grazes a breakpoint, hence the step halving when the residual does not decrease.

The loop is :meth:`ShootingProblem.solve <rattle.timeint.ShootingProblem.solve>` (one for every
system); the residual is scaled by :func:`~rattle.timeint.state_scale`, (L, L ν) with ν the larger
of Ω and the stiffest natural frequency. The shooters here check their arguments, call it and
dress the result with the orbit's measures:

- :func:`shoot_periodic_orbit` — the single equation δ'' + c δ' + k f(δ) = F(t) (a Model);
- :func:`shoot_system_orbit` — a System x'' + C x' + K x + Σ b_e f_e(a_e·x) = F(t);
- :func:`shoot_nonsmooth_orbit` — the single equation with jumps and Coulomb friction;
- :func:`shoot_friction_orbit` — a chain with jumps and Coulomb friction on its elements.

A failed solve is returned with ``converged`` False (the last iterate), not raised.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from .._validate import check_omega, check_shooting, check_state
from ..model import Model, System
from ._flow import SystemMeasures, SystemTrajectory, check_system_state
from ._friction_chain import FrictionTrajectory
from ._nonsmooth import NonsmoothTrajectory
from ._shooting_problem import (
    FLOW_FAILURES, ShootingProblem, Shot, built_for, make_integrator, monodromy_multipliers, state_scale,
)
from ._trajectory import Trajectory
from ._exact_flow import ExactIntegrator

_MAX_HALVINGS = 12


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class ShotOrbit:
    """What every Newton shooting on an exact flow returns (:class:`ShootingOrbit`,
    :class:`SystemOrbit`, :class:`NonsmoothOrbit`, :class:`FrictionOrbit` add their trajectory
    and measures): ``state0`` at t = 0, ``omega``, ``period`` p (T = p·2π/Ω), ``monodromy``
    M = ∂x(T)/∂x(0), its ``multipliers`` (largest modulus first), ``converged``, ``iterations``
    (Newton steps) and ``residual`` (the scaled ‖φ(x0) − x0‖∞)."""

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


def _orbit_fields(shot: Shot, omega: float, period: int, tol: float) -> dict[str, Any]:
    """The :class:`ShotOrbit` fields of a Newton solve."""
    M = shot.trajectory.sensitivity
    return dict(state0=shot.x, omega=omega, period=int(period), monodromy=M, multipliers=monodromy_multipliers(M),
                converged=shot.residual <= tol, iterations=shot.iterations, residual=shot.residual)


def _regime(crossed: FloatArray, strict: bool = True) -> str:
    """``no_impact``, ``single_sided`` or ``double_sided`` (SPEC §1) from the breakpoints crossed
    (``strict`` False: a breakpoint at δ = 0 is on neither side)."""
    if crossed.size == 0:
        return "no_impact"
    one_side = (np.all(crossed > 0.0) or np.all(crossed < 0.0)) if strict else \
        (np.all(crossed >= 0.0) or np.all(crossed <= 0.0))
    if one_side:
        return "single_sided"
    return "double_sided"


def _solve(system: Any, integ: Any, omega: float, x: FloatArray, period: int, tol: float, max_iterations: int,
           max_halvings: int = _MAX_HALVINGS, **kw: Any) -> Shot:
    problem = ShootingProblem(system, period=int(period), integrator=integ)
    return problem.solve(x, omega, tol=float(tol), max_iterations=int(max_iterations), max_halvings=max_halvings,
                         scale=problem.state_scale(omega), **kw)


# ---------------------------------------------------------------------------------------------
# The single equation
# ---------------------------------------------------------------------------------------------
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
        return _regime(self.trajectory.crossed_breakpoints)


def _state_scale(model: Model, omega: float) -> FloatArray:
    """Scales of δ and δ' for the residual (:func:`~rattle.timeint.state_scale` of the model)."""
    return state_scale(model, omega)


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
    if not built_for(integ, model):
        raise ValueError("`integrator` was built for a different model than `model`")
    shot = _solve(model, integ, omega, check_state(x0), period, tol, max_iterations)
    return _orbit_from_shot(shot, omega, int(period), float(tol))


def _orbit_from_shot(shot: Shot, omega: float, period: int, tol: float) -> ShootingOrbit:
    """The :class:`ShootingOrbit` of a Newton solve: multipliers and exact measures."""
    meas = shot.trajectory.measures()
    return ShootingOrbit(
        **_orbit_fields(shot, omega, period, tol), trajectory=shot.trajectory, mean=meas.mean, rms=meas.rms,
        rms_ac=meas.rms_ac, delta_min=meas.delta_min, delta_max=meas.delta_max, p2p=meas.p2p, acc_min=meas.acc_min,
        acc_max=meas.acc_max, acc_p2p=meas.acc_p2p, evaluations=shot.evaluations,
    )


# ---------------------------------------------------------------------------------------------
# A System
# ---------------------------------------------------------------------------------------------
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
    """Scales of x and x' for the shooting residual (:func:`~rattle.timeint.state_scale`)."""
    return state_scale(system, omega)


def shoot_system_orbit(
    system: System,
    omega: float,
    z0: FloatArray,
    *,
    period: int = 1,
    tol: float = 1e-12,
    max_iterations: int = 50,
    integrator: ExactIntegrator | None = None,
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
        scales of :func:`~rattle.timeint.state_scale`.
    max_iterations
        Newton iteration budget.
    integrator
        The :class:`ExactIntegrator` to use (default: one with default settings).

    Returns
    -------
    SystemOrbit
        Check ``converged``: a failed solve is returned, not raised (the last iterate).
    """
    if not isinstance(system, System) or system.discontinuous:
        raise TypeError(f"`system` must be a rattle.model.System with continuous laws, got {system!r}")
    omega = check_omega(omega)
    z = check_system_state(z0, system.n)
    check_shooting(period, tol, max_iterations)
    integ = ExactIntegrator(system) if integrator is None else integrator
    if not isinstance(integ, ExactIntegrator):
        raise TypeError(f"`integrator` must be an ExactIntegrator or None, got {integrator!r}")
    if integ.system is not system:
        raise ValueError("`integrator` was built for a different system than `system`")
    shot = _solve(system, integ, omega, z, period, tol, max_iterations)
    return SystemOrbit(**_orbit_fields(shot, omega, period, tol), evaluations=shot.evaluations,
                       trajectory=shot.trajectory, measures=shot.trajectory.measures())


# ---------------------------------------------------------------------------------------------
# The discontinuous laws
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class NonsmoothOrbit(ShotOrbit):
    """A periodic orbit of the discontinuous equation found by Newton shooting on the exact period
    map: ``state0`` (δ, δ') at t = 0, ``omega``, ``period`` p (T = p 2π/Ω), ``monodromy`` M (with
    the saltation matrices), ``multipliers`` (eigenvalues of M, largest modulus first),
    ``converged``, ``iterations``, ``residual`` (scaled ‖φ(x0) − x0‖∞), ``trajectory`` over one
    period, ``mean`` and ``rms`` of δ."""

    trajectory: NonsmoothTrajectory
    mean: float
    rms: float

    @property
    def regime(self) -> str:
        """``no_impact``, ``single_sided`` or ``double_sided`` from the breakpoints crossed or
        locked on (a jump at δ = 0 is on neither side: crossing only it is ``single_sided``)."""
        return _regime(self.trajectory.crossed_breakpoints, strict=False)


def shoot_nonsmooth_orbit(system: System, omega: float, x0: FloatArray | tuple[float, float], *,
                          period: int = 1, tol: float = 1e-12, max_iterations: int = 50,
                          integrator: ExactIntegrator | None = None) -> NonsmoothOrbit:
    """Periodic orbit of δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t) by Newton shooting: r(x0) =
    φ(x0; 0 → T) − x0 = 0 with the Jacobian M − I, M the exact monodromy (stage transition and
    saltation matrices). The residual is scaled by (L, L ν) (:func:`~rattle.timeint.state_scale`).
    A failed solve is returned with ``converged`` False."""
    if not (isinstance(system, System) and system.is_single_equation):
        raise TypeError(f"`system` must be the single equation's System (System.single), got {system!r}")
    omega = check_omega(omega)
    check_shooting(period, tol, max_iterations)
    integ = ExactIntegrator(system) if integrator is None else integrator
    if not built_for(integ, system):
        raise ValueError("`integrator` was built for a different system than `system`")
    if integ.system is not system:  # an equal system: the problem checks identity
        system = integ.system
    shot = _solve(system, integ, omega, check_state(x0), period, tol, max_iterations)
    mean, rms = shot.trajectory.mean_and_rms()
    return NonsmoothOrbit(**_orbit_fields(shot, omega, period, tol), trajectory=shot.trajectory, mean=mean, rms=rms)


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FrictionOrbit(ShotOrbit):
    """A periodic orbit of a chain with friction by Newton shooting on the exact period map:
    ``state0`` z(0) (2n,), ``monodromy`` (with saltation matrices), ``multipliers``,
    ``trajectory`` over one period, every element's ``mean`` and ``rms`` (m,) and
    ``stick_fraction`` (m,: the fraction of the period it sticks)."""

    trajectory: FrictionTrajectory
    mean: FloatArray
    rms: FloatArray
    stick_fraction: FloatArray


def shoot_friction_orbit(system: System, omega: float, z0: FloatArray, *, period: int = 1,
                         tol: float = 1e-12, max_iterations: int = 50,
                         integrator: ExactIntegrator | None = None,
                         hold: dict[int, float] | None = None) -> FrictionOrbit:
    """Periodic orbit of the chain with friction by Newton shooting: r(z0) = φ(z0; 0 → T) − z0 = 0
    with the Jacobian M − I (M the exact monodromy with saltation matrices), steps halved until
    the scaled residual decreases. Scales: L for positions, L max(Ω, ω_n) for velocities. A
    failed solve is returned with ``converged`` False.

    ``hold`` {element: deflection}: elements that stick the whole period. Their orbits form a
    family (the stuck deflection is free within the friction band; a multiplier 1, M − I
    singular); the one whose held deflection is the given one is found, by Gauss–Newton on the
    shooting equations with a_e·x0 = d_e added. The start is moved onto the holds: δ_e = d_e and
    δ_e' = 0."""
    if not (isinstance(system, System) and system.discontinuous and not system.is_single_equation):
        raise TypeError(f"`system` must be a rattle System with its elements' whole laws "
                        f"(Chain.friction_system(), System.with_friction), got {system!r}")
    omega = check_omega(omega)
    check_shooting(period, tol, max_iterations)
    integ = ExactIntegrator(system) if integrator is None else integrator
    if not isinstance(integ, ExactIntegrator) or integ.system is not system:
        raise ValueError("`integrator` was built for a different system than `system`")
    z = check_system_state(z0, system.n).copy()
    n = system.n
    rows = None
    if hold:
        held = {int(e): float(d) for e, d in hold.items()}
        for e, d in held.items():
            if not 0 <= e < system.m:
                raise ValueError(f"`hold` names element {e}; the system has elements 0 … {system.m - 1}")
            a = integ.A[e]
            z[:n] += a * ((d - float(a @ z[:n])) / float(a @ a))
            z[n:] -= a * (float(a @ z[n:]) / float(a @ a))
        rows = (np.array([integ.A[e] for e in held]), np.array(list(held.values())))
    shot = _solve(system, integ, omega, z, period, tol, max_iterations, max_halvings=30, hold=rows)
    traj = shot.trajectory
    mean, rms = traj.element_mean_and_rms()
    T = period * 2.0 * math.pi / omega
    return FrictionOrbit(**_orbit_fields(shot, omega, period, tol), trajectory=traj, mean=mean, rms=rms,
                         stick_fraction=traj.stick_time() / T)


__all__ = ["ShotOrbit", "ShootingOrbit", "shoot_periodic_orbit", "SystemOrbit", "shoot_system_orbit",
           "NonsmoothOrbit", "shoot_nonsmooth_orbit", "FrictionOrbit", "shoot_friction_orbit", "FLOW_FAILURES",
           "monodromy_multipliers", "system_state_scale", "make_integrator"]
