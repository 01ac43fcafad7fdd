"""Periodic orbits by shooting, as a continuation problem in the forcing frequency.

For any of rattle's equations of motion — the single equation (a :class:`~rattle.model.Model`), a
smooth :class:`~rattle.model.System`, the single equation with a discontinuous law
(the single equation's :class:`~rattle.model.System`, :meth:`~rattle.model.System.single`) or a chain with
torque jumps and Coulomb friction on its elements (a :class:`~rattle.model.System` with their whole laws) — a
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
discontinuous laws (and a Model) it is the forward difference (φ_T(q; Ω + h) − φ_T(q; Ω)) / h with
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

:meth:`ShootingProblem.solve` is rattle's one Newton loop on the period map at fixed Ω: every
shooter (:mod:`._shooting`), the settling loop's acceleration and the exact branches' start
call it. From q_0, with r_i = φ_T(q_i) − q_i and the increment Δq_i = −(M_i − I)⁻¹ r_i,

    q_{i+1} = q_i + 2^{−h} Δq_i,   h = 0, 1, … the first with ‖r_{i+1}/s‖∞ < ‖r_i/s‖∞,

until ‖r_i/s‖∞ ≤ tol (and, when asked, ‖Δq_i/s‖∞ ≤ step_tol: then q_i + Δq_i is returned). The
map is only piecewise smooth where an orbit grazes a breakpoint, hence the halving; a trial
state the flow cannot follow (:data:`FLOW_FAILURES`) counts as no decrease. Held elements (a
family of orbits, M − I singular) add the rows a_e·x(0) = d_e and the step becomes the
least-squares (Gauss–Newton) one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..errors import RattleError
from ..model import Chain, Model, System
from . import _flow, _friction_chain, _nonsmooth  # noqa: F401  (the paths register themselves)
from ._exact_flow import ExactIntegrator
from ._integrator import _ScalarFlow

#: What an exact flow or its shooting raises when it cannot follow the motion (the event budget
#: of a chatter, a loop of stuck elements, a singular step; numpy's LinAlgError is a ValueError):
#: the callers then report the orbit or row as not found instead of stopping.
FLOW_FAILURES: tuple[type[Exception], ...] = (RattleError, ValueError, ArithmeticError)

#: Relative step of the forward difference in Ω of a discontinuous law's period map.
OMEGA_STEP = math.sqrt(np.finfo(float).eps)

#: Scaled distance within which a discontinuous law's ∂φ_T/∂Ω is taken again (:meth:`ShootingProblem._omega_derivative`).
REUSE_DISTANCE = 1e-4

Shootable = Model | System

def monodromy_multipliers(M: FloatArray) -> ComplexArray:
    """The Floquet multipliers: the eigenvalues of the monodromy matrix ``M``, largest modulus
    first (a stable sort: equal moduli keep the solver's order)."""
    mu = np.linalg.eigvals(M).astype(complex)
    return mu[np.argsort(-np.abs(mu), kind="stable")]


def make_integrator(system: Shootable | Chain) -> ExactIntegrator:
    """The exact flow of ``system`` with default settings, ``ExactIntegrator(system)`` (a Chain:
    of its System; reuse it across calls to share its cache)."""
    return ExactIntegrator(system)


def built_for(integrator: object, system: Shootable) -> bool:
    """True when ``integrator`` is an exact flow built for ``system``."""
    return isinstance(integrator, ExactIntegrator) and integrator.built_for(system)


def _scales(system: Shootable) -> tuple[int, float, float]:
    """n, L and ω_s of ``system``."""
    if isinstance(system, Model) or (isinstance(system, System) and system.is_single_equation):
        s = system.elastic.stages.slopes if isinstance(system, Model) else system.law.stages.slopes
        return 1, float(system.length_scale()), math.sqrt(system.k * float(np.max(s)))
    if isinstance(system, System):
        return system.n, float(system.length_scale()), float(system.stiffest_frequency())
    raise TypeError(f"`system` must be a rattle Model or System, got {system!r}")


def state_scale(system: Shootable, omega: float) -> FloatArray:
    """Scales of x and x' of a shooting residual at forcing frequency Ω: the system's length scale
    L for every coordinate, L ν for every velocity, ν the larger of Ω and the stiffest natural
    frequency ω_s (shape (2n,))."""
    n, L, omega_s = _scales(system)
    return np.concatenate((np.full(n, L), np.full(n, L * max(float(omega), omega_s))))


@dataclass(frozen=True, slots=True, eq=False)
class Shot:
    """The outcome of :meth:`ShootingProblem.solve`: the last iterate ``x`` = z(0), its
    ``trajectory`` over one orbit period (its ``sensitivity`` the monodromy M), the scaled
    ``residual`` ‖(φ_T(x) − x)/s‖∞, the Newton ``iterations``, the period maps integrated
    (``evaluations``, the work done) and whether the solve ``converged`` (residual, and step when
    asked, within the tolerances)."""

    x: FloatArray
    trajectory: Any
    residual: float
    iterations: int
    evaluations: int
    converged: bool = False

    def multipliers(self) -> ComplexArray:
        """Eigenvalues of the monodromy matrix, largest modulus first."""
        return monodromy_multipliers(self.trajectory.sensitivity)


class ShootingProblem:
    """R(z(0), Ω) = (φ_T(z(0); Ω) − z(0)) / s of any of rattle's systems (module docstring).

    Parameters
    ----------
    system
        The equations of motion: a :class:`~rattle.model.Model` (the single equation), a
        :class:`~rattle.model.System` (continuous laws, or with its elements' whole laws: a chain's
        or the single equation's).
    period
        The orbit's period as a multiple p of the forcing period (T = p·2π/Ω), ≥ 1.
    integrator
        The exact integrator to use, built for ``system`` (default: :func:`make_integrator`).
    """

    def __init__(self, system: Shootable, *, period: int = 1, integrator: Any = None) -> None:
        if not isinstance(system, (Model, System)):
            raise TypeError(f"`system` must be a rattle Model or System, got {system!r}")
        if isinstance(period, bool) or not isinstance(period, (int, np.integer)) or period < 1:
            raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
        integ = make_integrator(system) if integrator is None else integrator
        if not built_for(integ, system):
            raise ValueError("`integrator` must be an exact integrator built for `system` (or None)")
        self.system = system
        self.period = int(period)
        self.integrator = integ
        self._smooth = isinstance(system, System) and not system.discontinuous
        # the flows whose record costs next to nothing: their Newton iterates are recorded as they go
        self._records = isinstance(integ, _ScalarFlow)
        n, L, omega_s = _scales(system)
        self.n = n
        self._L = L
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

    def state_scale(self, omega: float) -> FloatArray:
        """:func:`state_scale` of the system at Ω: (L, L ν), ν = max(Ω, ω_s) (2n,)."""
        return np.concatenate((np.full(self.n, self._L), np.full(self.n, self._L * max(float(omega), self._omega_s))))

    def orbit_period(self, omega: float) -> float:
        """T = p·2π/Ω (s)."""
        return self.period * 2.0 * math.pi / omega

    def period_map(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray]:
        """φ_T(q; Ω) (2n,) and the exact monodromy M = ∂φ_T/∂q (2n, 2n), without records."""
        z1, M = self.integrator.advance(np.asarray(q, dtype=float), 0.0, self.orbit_period(omega), omega)
        return z1, M

    def _evaluate(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, Any]:
        """φ_T(q), M and the trajectory when the flow records cheaply (else None)."""
        if self._records:
            traj = self.integrator.propagate(q, 0.0, self.orbit_period(omega), omega)
            return traj.state1, traj.sensitivity, traj
        z1, M = self.period_map(q, omega)
        return z1, M, None

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

    # --- Newton on the period map at fixed Ω --------------------------------------------------------
    def solve(self, q0: FloatArray, omega: float, *, tol: float, max_iterations: int, max_halvings: int,
              scale: FloatArray | None = None, step_tol: float | None = None, least_squares: bool = True,
              hold: tuple[FloatArray, FloatArray] | None = None, record: bool = True,
              max_evaluations: int | None = None) -> Shot:
        """Newton's method on φ_T(q) − q = 0 at fixed Ω with the exact monodromy, the step halved
        (at most ``max_halvings`` times) until the scaled residual decreases (module docstring);
        the last iterate is returned with its trajectory over one orbit period, converged or not
        (``residual`` ≤ ``tol``). ``scale`` the residual's scales s (default :attr:`length_scale`);
        ``step_tol`` also asks ‖Δq/s‖∞ ≤ step_tol and returns q + Δq; ``least_squares`` takes the
        least-squares step where M − I is singular (else the solve stops there); ``hold`` = (A, d)
        adds the rows A x(0) = d (scaled by L), the step then by least squares; ``record`` False
        leaves the trajectory None when it was not recorded on the way; ``max_evaluations`` caps the
        period maps integrated (spent: the solve stops, not converged). A failure of the flow from
        ``q0`` itself is raised (:data:`FLOW_FAILURES`)."""
        s = self._scale if scale is None else np.asarray(scale, dtype=float)
        n = self.n
        rows = target = None
        if hold is not None:
            rows, target = (np.atleast_2d(np.asarray(hold[0], dtype=float)), np.asarray(hold[1], dtype=float))
            rows = np.hstack((rows, np.zeros_like(rows)))

        def defect(q: FloatArray) -> tuple[FloatArray, FloatArray, Any, float]:
            z1, M, traj = self._evaluate(q, omega)
            r = z1 - q
            res = float(np.max(np.abs(r / s)))
            if rows is not None:
                res = max(res, float(np.max(np.abs((rows @ q - target) / s[0]))))
            return r, M, traj, res

        def increment(q: FloatArray, r: FloatArray, M: FloatArray) -> FloatArray | None:
            if rows is not None:  # Gauss–Newton on [(φ − q)/s; (A x − d)/L]
                J = np.vstack(((M - self._eye) / s[:, None], rows / s[0]))
                return np.linalg.lstsq(J, -np.concatenate((r / s, (rows @ q - target) / s[0])), rcond=None)[0]
            try:
                return np.linalg.solve(M - self._eye, -r)
            except np.linalg.LinAlgError:  # a multiplier exactly 1 (fold)
                return np.linalg.lstsq(M - self._eye, -r, rcond=None)[0] if least_squares else None

        q = np.array(q0, dtype=float)
        r, M, traj, res = defect(q)
        evaluations, iterations, converged = 1, 0, False
        while iterations <= max_iterations:
            dq = increment(q, r, M) if (step_tol is not None or res > tol) else None
            if res <= tol and (step_tol is None or (dq is not None and float(np.max(np.abs(dq / s))) <= step_tol)):
                converged = True
                if step_tol is not None:
                    q, traj = q + dq, None
                break
            if iterations == max_iterations or dq is None or not np.all(np.isfinite(dq)):
                break
            iterations += 1
            step = 1.0
            spent = False
            for _ in range(max_halvings + 1):
                if max_evaluations is not None and evaluations >= max_evaluations:
                    spent = True
                    break
                trial = q + step * dq
                try:
                    out = defect(trial)
                except FLOW_FAILURES:  # a trial state the flow cannot follow: a shorter step
                    step *= 0.5
                    continue
                evaluations += 1
                if out[3] < res:
                    break
                step *= 0.5
            else:
                break  # no decrease along the Newton direction: give up (not converged)
            if spent:
                break  # the budget of period maps is spent (not converged)
            q = trial
            r, M, traj, res = out
        if traj is None and record:
            traj = self.integrator.propagate(q, 0.0, self.orbit_period(omega), omega)
            evaluations += 1
        return Shot(q, traj, res, iterations, evaluations, converged)

    # --- for test functions -----------------------------------------------------------------------
    def monodromy(self, q: FloatArray, omega: float) -> FloatArray:
        """The exact monodromy M = ∂φ_T/∂z(0) (2n, 2n) of the period map from q."""
        return self.period_map(q, omega)[1]


__all__ = ["ShootingProblem", "Shot", "FLOW_FAILURES", "monodromy_multipliers", "state_scale", "make_integrator",
           "built_for"]
