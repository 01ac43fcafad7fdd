"""Steady state of δ'' + c δ' + k f(δ) = F(t) — or of a chain's System, x'' + C x' + K x +
Σ b_e f_e(a_e·x) = F(t) — by simulation, with period detection (1 … 8).

An analysis on top of :mod:`rattle.timeint`: it runs the exact integrators and Newton shooting
there and returns a :class:`~rattle.results.SteadyState` (whose ``status`` tells how it ended).

One settling loop serves every system, on its exact flow (:class:`ExactIntegrator`, which picks
its path by the system: :func:`make_integrator`): the single equation with state (δ, δ') on the
fast scalar path, a chain with state z = (x, x') of its n coordinates (the scaled norm below then
takes every coordinate by the System's length scale and every velocity by that times ν,
:func:`~rattle.timeint.state_scale`), the discontinuous laws likewise; shooting is :meth:`ShootingProblem.solve` on the same exact
flows.

The state is integrated exactly (:class:`ExactIntegrator`) one forcing period T = 2π/Ω at a time,
from t = 0 to T (F is T-periodic, so every period starts at forcing phase 0). The states at the
period ends form the Poincaré sequence P_0 = x0, P_1, P_2, … of the stroboscopic map
P_{i+1} = φ(P_i; 0 → T). Distances are measured in the scaled max-norm

    ‖P_i − P_j‖ = max(|Δδ| / L, |Δδ'| / (L ν)),

L the model's length scale and ν the larger of Ω and the stiffest stage's natural frequency (the
scaling of :func:`shoot_periodic_orbit`), and d_n(i) = ‖P_i − P_{i−n}‖.

Plain settling
    The motion has settled on a period-n cycle (n·T-periodic) when d_n(k) ≤ ``tolerance`` for the
    n + 1 latest k (every point of the cycle repeats), for the smallest such n ≤
    ``max_period_multiple``. A cycle of period n is also one of period 2n; the smallest n is
    taken, and n is refused while d_m (m a proper divisor of n) still shrinks — a period-m orbit
    approached along a multiplier near −1 satisfies d_2m ≪ d_m long before d_m ≤ tolerance.

Acceleration (``accelerate=True``)
    Near a stable orbit with multiplier μ the sequence approaches it only like |μ|^i: with
    |μ| = 0.95, some 400 periods from 0.1 to 1e-8. Once the sequence contracts towards a period-n
    cycle (d_n small and shrinking, smallest such n), Newton shooting with period n (exact
    monodromy, :func:`shoot_periodic_orbit`) polishes the orbit X* from the current state. It is
    accepted only when

    1. Newton converged (scaled residual ≤ ``shooting_tolerance``), and the orbit is stable
       (every Floquet multiplier inside the unit circle);
    2. it is the attractor being approached: the current section point P_i is within
       ``capture_distance`` of X* (of one of the cycle's section points), and the simulation
       behaves as the linearisation about X* predicts: after n more periods
       ‖(P_{i+n} − X*) − M (P_i − X*)‖ ≤ 0.1 ‖P_i − X*‖ (M the monodromy matrix).

    Inside that linear neighbourhood of a stable orbit the simulation converges to X*, so the
    accelerated result is the attractor of the plain simulation, located exactly. Otherwise the
    simulation simply goes on (a rejected orbit is retried with growing waits).

Nothing settled within ``max_periods`` periods: period 0 (quasi-periodic, chaotic, or a period
above ``max_period_multiple``), with the measures over ``record_periods`` further periods.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _limits
from .._typing import FloatArray
from .._validate import check_int, check_positive, check_state, numerical_failures
from ..errors import Status
from ..errors import ConvergenceError
from ..model import Chain, Model, System, check_analysable_model
from ..results import STEADY_METHODS as METHODS, SteadyState
from ..timeint import (
    ExactIntegrator, ExactMeasures, ExactTrajectory, FrictionTrajectory, NonsmoothTrajectory, ShootingProblem, Shot,
    SystemMeasures, built_for, check_system_state, make_integrator,
)

_TWO_PI = 2.0 * math.pi
_LINEAR_CHECK = 0.1  # relative mismatch allowed between the simulation and the linearisation
_ROUNDOFF = 1e-12  # scaled distance treated as round-off in the linear check
_SAME_POINT = 1e-6  # scaled distance under which φ^m(X*) = X*: the period is m, not n
_MAX_WAIT = 128  # longest wait (forcing periods) between two acceleration attempts
# Step halvings per Newton iteration: an attempt from too far away should fail cheaply (the
# simulation goes on and a later attempt starts closer).
_MAX_HALVINGS = 3

@dataclass(frozen=True, slots=True, kw_only=True)
class SteadyStateOptions:
    """Budget and tolerances of :func:`steady_state` (frozen; derive variants with
    ``dataclasses.replace``).

    Parameters
    ----------
    tolerance : float
        Settling tolerance on the scaled Poincaré distance d_n = ‖P_i − P_{i−n}‖ (see the
        module docstring; δ scaled by the model's length scale L, δ' by L ν). Default 1e-8.
    max_periods : int
        Bound on the forcing periods simulated while settling (default 1500).
    max_period_multiple : int
        Largest period detected, as a multiple of the forcing period (default 8, SPEC §1).
    record_periods : int
        Forcing periods over which the measures of an unsettled motion (period 0) are taken
        (default 50).
    accelerate : bool
        Polish by Newton shooting once the simulation contracts towards a cycle, accepting the
        orbit only when it is stable and is the attractor being approached (default True).
        False: plain simulation only (slower, same answers to within the tolerance).
    capture_distance : float
        Scaled distance from a polished orbit within which the simulation is checked against the
        orbit's linearisation (default 1e-2).
    trigger_distance : float
        Scaled d_n below which (and shrinking) a shooting attempt with period n is made
        (default 0.1).
    shooting_tolerance : float
        Newton tolerance on the scaled shooting residual (default 1e-12).
    shooting_iterations : int
        Newton iteration budget per shooting attempt (default 10; Newton converges in 2–5
        iterations from a state that is close enough).
    section_points : int
        Latest Poincaré points kept in the result (default 32).
    """

    tolerance: float = 1e-8
    max_periods: int = 1500
    max_period_multiple: int = 8
    record_periods: int = 50
    accelerate: bool = True
    capture_distance: float = 1e-2
    trigger_distance: float = 0.1
    shooting_tolerance: float = 1e-12
    shooting_iterations: int = 10
    section_points: int = 32

    def __post_init__(self) -> None:
        for name in ("tolerance", "capture_distance", "trigger_distance", "shooting_tolerance"):
            object.__setattr__(self, name, check_positive(getattr(self, name), name))
        for name, low in (("max_periods", 1), ("max_period_multiple", 1), ("record_periods", 1),
                          ("shooting_iterations", 0), ("section_points", 1)):
            object.__setattr__(self, name, check_int(name, getattr(self, name), low))
        # Upper bounds (rattle._limits): an exactly integrated forcing period costs ~0.5 ms on the
        # reference case, so max_periods = 100 000 is ~1 min per frequency already.
        _limits.check_period(self.max_period_multiple, "max_period_multiple")
        for name, high, why in (
            ("max_periods", _limits.MAX_SETTLING_PERIODS,
             "each forcing period is integrated exactly (~0.5 ms), so this is ~1 min per frequency; use e.g. 1500"),
            ("record_periods", _limits.MAX_RECORD_PERIODS, "the measures of an unsettled motion need tens; use e.g. 50"),
            ("section_points", _limits.MAX_RECORD_PERIODS, "the Poincaré points kept; use e.g. 32"),
            ("shooting_iterations", _limits.MAX_NEWTON_ITERATIONS, "Newton converges in 2–5 iterations; use e.g. 10"),
        ):
            if getattr(self, name) > high:
                raise ValueError(f"`{name}` must be <= {high}, got {getattr(self, name)}: {why}")
        if not isinstance(self.accelerate, (bool, np.bool_)):
            raise TypeError(f"`accelerate` must be True or False, got {self.accelerate!r}")
        object.__setattr__(self, "accelerate", bool(self.accelerate))
        if self.tolerance >= 1.0:
            raise ValueError(f"`tolerance` must be < 1 (a scaled distance), got {self.tolerance!r}")

    def to_dict(self) -> dict[str, object]:
        """The options as a JSON-serialisable dict."""
        return {name: getattr(self, name) for name in self.__dataclass_fields__}


# ---------------------------------------------------------------------------------------------
# The flow being settled: the exact integrator of any system, state z = (x, x')
# ---------------------------------------------------------------------------------------------
class _Failed:
    """A shooting solve whose flow could not be followed (an event budget exceeded): never
    accepted (residual ∞)."""

    residual = math.inf
    iterations = 0

    def __init__(self, x: FloatArray, evaluations: int = 1) -> None:
        self.x, self.evaluations = x, evaluations


class _Flow:
    """The exact flow of ``system`` on its integrator (:func:`make_integrator`): the period map
    without records, Newton shooting (:meth:`ShootingProblem.solve`), the recorded trajectory,
    its section states and its measures. States z = (x, x') (2n,; (δ, δ') for the single
    equations), scaled by :func:`~rattle.timeint.state_scale`, (L, L ν), as the shooting scales
    its residual; a discontinuous law's period map carries the saltation matrices (a stick or
    lock phase contributes an exact zero multiplier), so the acceptance tests of the
    acceleration hold unchanged."""

    def __init__(self, system: Model | System, integ: Any, omega: float) -> None:
        self.system, self.integ, self.omega = system, integ, omega
        # one ShootingProblem per period multiple; the first gives the scales
        self._problems: dict[int, ShootingProblem] = {1: ShootingProblem(system, period=1, integrator=integ)}
        self.scale = self._problems[1].state_scale(omega)
        self.dim = self.scale.size

    def advance(self, x: FloatArray, T: float) -> FloatArray:
        return self.integ.advance(x, 0.0, T, self.omega, sensitivity=False)[0]

    def shoot(self, x: FloatArray, n: int, tol: float, iterations: int) -> Shot | _Failed:
        problem = self._problems.get(n)
        if problem is None:
            problem = self._problems[n] = ShootingProblem(self.system, period=n, integrator=self.integ)
        try:
            return problem.solve(x, self.omega, tol=tol, max_iterations=iterations, max_halvings=_MAX_HALVINGS,
                                 scale=self.scale)
        except ConvergenceError:  # a state the event-driven flow cannot follow: no orbit
            return _Failed(np.asarray(x, dtype=float).copy())

    def propagate(self, x: FloatArray, T: float) -> Any:
        return self.integ.propagate(x, 0.0, T, self.omega)

    @staticmethod
    def section(traj: ExactTrajectory, t: FloatArray) -> FloatArray:
        """The states z(t) (len(t), 2n) on a trajectory of any of the integrators."""
        return traj.states(np.asarray(t, dtype=float))

    @staticmethod
    def measures(traj: ExactTrajectory) -> ExactMeasures | SystemMeasures:
        return traj.measures()


def stick_fraction(traj: NonsmoothTrajectory | FrictionTrajectory) -> float | FloatArray:
    """The fraction of the trajectory's time held (stuck by friction or locked at a jump): a
    number for the single equation, one per element (m,) for a chain with friction."""
    T = traj.t1 - traj.t0
    if isinstance(traj, FrictionTrajectory):
        return traj.stick_time() / T
    return float(traj.stick_time / T)


def _proper_divisors(n: int) -> list[int]:
    return [m for m in range(1, n) if n % m == 0]


@dataclass(slots=True)
class _Candidate:
    """A stable orbit found by shooting, waiting for the simulation to come close."""

    shot: Shot
    period: int
    cycle: FloatArray  # (n, dim) unscaled section points
    created: int


class _Settler:
    """The settling loop of :func:`steady_state` (one call)."""

    def __init__(self, flow: _Flow, omega: float, x0: FloatArray, opts: SteadyStateOptions,
                 names: tuple[str, ...]) -> None:
        self.flow, self.omega, self.opts, self.names = flow, omega, opts, names
        self.T = _TWO_PI / omega
        self.scale = flow.scale
        n_max = opts.max_periods
        self.N = opts.max_period_multiple
        dim = flow.dim
        self.X = np.empty((n_max + 1, dim))  # section states
        self.P = np.empty((n_max + 1, dim))  # scaled
        self.d = np.full((n_max + 1, self.N + 1), np.inf)  # d[i, n] = ‖P_i − P_{i−n}‖
        self.X[0] = x0
        self.P[0] = x0 / self.scale
        self.i = 0
        self.shooting_periods = 0
        # acceleration state
        self.candidate: _Candidate | None = None
        self.pending: tuple[int, FloatArray, Shot, int] | None = None
        self.next_attempt = 1
        self.failures = 0

    # --- helpers --------------------------------------------------------------------------
    def norm(self, dx: FloatArray) -> float:
        return float(np.max(np.abs(dx / self.scale)))

    def step(self) -> None:
        i = self.i + 1
        self.X[i] = x = self.flow.advance(self.X[i - 1], self.T)
        p = self.P[i]
        np.divide(x, self.scale, out=p)
        n = min(self.N, i)
        # d[i, m] = ‖P_i − P_{i−m}‖ for m = n … 1 from the rows i − n … i − 1 (array methods: the
        # loop's cost per period is numpy's per call, ~1 µs less than np.max's dispatch)
        self.d[i, n:0:-1] = np.abs(self.P[i - n : i] - p).max(axis=1)
        self.i = i

    def shoot(self, x: FloatArray, n: int) -> Shot:
        opts = self.opts
        shot = self.flow.shoot(x, n, opts.shooting_tolerance, opts.shooting_iterations)
        self.shooting_periods += shot.evaluations * n
        return shot

    def cycle_points(self, shot: Shot, n: int) -> FloatArray:
        if n == 1:
            return shot.x[None, :].copy()
        return self.flow.section(shot.trajectory, np.arange(n) * self.T)

    # --- plain detection --------------------------------------------------------------------
    def plain_period(self) -> int:
        i, d, tol = self.i, self.d, self.opts.tolerance
        for n in range(1, self.N + 1):
            if i < 2 * n:
                break
            if not (d[i, n] <= tol and np.all(d[i - n : i, n] <= tol)):
                continue
            if all(d[i, m] > 1e3 * tol and d[i, m] > 0.99 * d[i - n, m] for m in _proper_divisors(n)):
                return n
        return 0

    # --- acceleration ------------------------------------------------------------------------
    def trigger(self) -> int:
        i, d = self.i, self.d
        for n in range(1, min(self.N, i) + 1):
            if d[i, n] <= self.opts.trigger_distance and (i < 2 * n or d[i, n] < d[i - n, n]):
                return n
        return 0

    def stable_orbit(self, x: FloatArray, n: int) -> tuple[Shot, int] | None:
        """Newton shooting with period n from x; the orbit (with its minimal period) if it
        converged and is stable, else None."""
        shot = self.shoot(x, n)
        if not shot.residual <= self.opts.shooting_tolerance:
            return None
        if not np.all(np.abs(shot.multipliers()) < 1.0):
            return None
        for m in _proper_divisors(n):
            if self.norm(self.flow.section(shot.trajectory, np.array([m * self.T]))[0] - shot.x) <= _SAME_POINT:
                lower = self.shoot(shot.x, m)
                if lower.residual <= self.opts.shooting_tolerance and np.all(np.abs(lower.multipliers()) < 1.0):
                    return lower, m
        return shot, n

    def fail(self) -> None:
        self.candidate = None
        self.pending = None
        self.failures += 1
        self.next_attempt = self.i + min(2 ** (self.failures + 1), _MAX_WAIT)

    def accelerate(self) -> SteadyState | None:
        i = self.i
        if self.pending is not None:
            i0, e0, shot, n = self.pending
            if i < i0 + n:
                return None
            e1 = self.X[i] - shot.x
            mismatch = self.norm(e1 - shot.trajectory.sensitivity @ e0)
            if mismatch <= _LINEAR_CHECK * self.norm(e0) + _ROUNDOFF:
                return self.from_shot(shot, n)
            self.fail()
            return None
        if self.candidate is None:
            if i < self.next_attempt:
                return None
            n = self.trigger()
            if n == 0:
                return None
            found = self.stable_orbit(self.X[i], n)
            if found is None:
                self.fail()
                return None
            shot, n = found
            self.candidate = _Candidate(shot, n, self.cycle_points(shot, n), i)
        cand = self.candidate
        dist = np.abs((cand.cycle - self.X[i]) / self.scale).max(axis=1)
        k = int(np.argmin(dist))
        if dist[k] > self.opts.capture_distance:
            if i - cand.created > max(64, 8 * cand.period):
                self.candidate = None  # not approached: look again later
            return None
        shot = cand.shot
        if k != 0:  # the simulation is at another phase of the cycle: re-base the orbit there
            shot = self.shoot(cand.cycle[k], cand.period)
            if not shot.residual <= self.opts.shooting_tolerance:
                self.fail()
                return None
        e0 = self.X[i] - shot.x
        if self.norm(e0) <= self.opts.tolerance:
            return self.from_shot(shot, cand.period)
        self.pending = (i, e0, shot, cand.period)
        return None

    # --- results ----------------------------------------------------------------------------
    def poincare(self) -> FloatArray:
        k = self.opts.section_points
        return self.X[max(0, self.i + 1 - k) : self.i + 1].copy()

    def from_shot(self, shot: Shot, n: int) -> SteadyState:
        traj = shot.trajectory
        return SteadyState(
            omega=self.omega, period=n, status=Status.CONVERGED, periods=self.i,
            shooting_periods=self.shooting_periods, state0=shot.x.copy(), final_state=shot.x.copy(),
            cycle=self.cycle_points(shot, n), poincare=self.poincare(), trajectory=traj,
            measures=self.flow.measures(traj), multipliers=shot.multipliers(), residual=shot.residual,
            element_names=self.names,
        )

    def from_simulation(self, n: int) -> SteadyState:
        i = self.i
        x = self.X[i].copy()
        traj = self.flow.propagate(x, n * self.T)
        mult = np.linalg.eigvals(traj.sensitivity).astype(complex)
        mult = mult[np.argsort(-np.abs(mult), kind="stable")]
        cycle = x[None, :] if n == 1 else self.flow.section(traj, np.arange(n) * self.T)
        return SteadyState(
            omega=self.omega, period=n, status=Status.SETTLED, periods=i + n,
            shooting_periods=self.shooting_periods, state0=x, final_state=traj.state1.copy(),
            cycle=cycle, poincare=self.poincare(), trajectory=traj, measures=self.flow.measures(traj),
            multipliers=mult, residual=float(np.max(self.d[i - n : i + 1, n])), element_names=self.names,
        )

    def unsettled(self) -> SteadyState:
        i, rec = self.i, self.opts.record_periods
        x = self.X[i].copy()
        traj = self.flow.propagate(x, rec * self.T)
        section = self.flow.section(traj, np.arange(rec + 1) * self.T)[-self.opts.section_points :]
        return SteadyState(
            omega=self.omega, period=0, status=Status.MAX_PERIODS, periods=i + rec,
            shooting_periods=self.shooting_periods, state0=x, final_state=traj.state1.copy(),
            cycle=np.empty((0, self.flow.dim)), poincare=section, trajectory=traj, measures=self.flow.measures(traj),
            multipliers=None, residual=float(np.min(self.d[i, 1:])), element_names=self.names,
        )

    def run(self) -> SteadyState:
        opts = self.opts
        while self.i < opts.max_periods:
            self.step()
            n = self.plain_period()
            if n:
                if opts.accelerate:
                    found = self.stable_orbit(self.X[self.i], n)
                    if found is not None and self.norm(self.X[self.i] - found[0].x) <= opts.capture_distance:
                        return self.from_shot(*found)
                return self.from_simulation(n)
            if opts.accelerate:
                result = self.accelerate()
                if result is not None:
                    return result
        return self.unsettled()


def _nonsmooth_rest(system: System) -> float:
    """δ_s of the law at rest, k f(δ_s) = F_m with f's jumps (friction aside): on a stage with
    positive slope, or at a breakpoint whose jump spans F_m/k (the lock band without friction)."""
    st = system.law.stages
    target = system.excitation.mean / system.k
    edges = np.concatenate(([-np.inf], st.breakpoints, [np.inf]))
    for j, (s, e) in enumerate(zip(st.slopes, st.offsets)):
        lo, hi = edges[j], edges[j + 1]
        if j > 0 and st.slopes[j - 1] * lo + st.offsets[j - 1] <= target <= s * lo + e:
            return float(lo)  # held at the breakpoint by its jump
        if s > 0:
            x = (target - e) / s
            if lo <= x <= hi:
                return float(x)
        elif abs(target - e) <= 1e-15 * max(1.0, abs(target)):
            return float(0.5 * (lo + hi)) if np.isfinite(lo + hi) else float(lo if np.isfinite(lo) else hi)
    return 0.0


def static_state(model: Model | Chain | System,
                 omega: float | None = None) -> FloatArray:
    """The static equilibrium at rest as a state: (δ_s, 0) for the single equation, (x_s, 0)
    (2n,) for a chain or System (under the mean torques at ``omega`` when they depend on it).
    The single equation's :class:`~rattle.model.System` (:meth:`~rattle.model.System.single`):
    k f(δ_s) = F_m with the law's jumps (at a
    breakpoint whose jump spans F_m/k, δ_s is the breakpoint); a
    :class:`~rattle.model.System` with its elements' whole laws: the equilibrium of its smooth System."""
    if isinstance(model, Model):
        return np.array([model.static_equilibrium(), 0.0])
    if isinstance(model, System) and model.is_single_equation:
        return np.array([_nonsmooth_rest(model), 0.0])
    if isinstance(model, System):
        model = model.continuous()
    system = model.system() if isinstance(model, Chain) else model
    return np.concatenate((system.static_equilibrium(omega), np.zeros(system.n)))


def _checked_integrator(integrator: object, system: Model | System) -> Any:
    """``integrator``, or :func:`make_integrator` of ``system`` when None: refused (TypeError)
    when not an exact flow (:class:`ExactIntegrator`), (ValueError) when built for another
    system."""
    integ = make_integrator(system) if integrator is None else integrator
    if not built_for(integ, system):
        if not isinstance(integ, ExactIntegrator):
            raise TypeError(f"`integrator` must be an ExactIntegrator built for the {type(system).__name__}, "
                            f"got {integrator!r}")
        raise ValueError(f"`integrator` was built for a different {'model' if isinstance(system, Model) else 'system'} "
                         "than `model`")
    return integ


@numerical_failures
def steady_state(
    model: Model | Chain | System,
    omega: float,
    x0: FloatArray | tuple[float, float] | None = None,
    *,
    options: SteadyStateOptions | None = None,
    integrator: ExactIntegrator | None = None,
) -> SteadyState:
    """Steady motion reached from ``x0`` at the forcing frequency ``omega``, and its period.

    Simulates exactly, one forcing period at a time, until the Poincaré sequence (the states at
    t = m·2π/Ω) repeats with a period n·2π/Ω, n = 1 … ``max_period_multiple`` (smallest n), to the
    scaled ``tolerance``; with ``accelerate`` the settling is shortened by Newton shooting,
    accepting only the stable orbit the simulation is seen to converge to (module docstring).

    Every system runs on its exact flow (:class:`ExactIntegrator`): the single equation
    δ'' + c δ' + k f(δ) = F(t) (a :class:`~rattle.model.Model`) with state (δ, δ') on the scalar
    path; a :class:`~rattle.model.Chain` (or a bare :class:`~rattle.model.System`) with state
    z = (x, x') of its n coordinates, with the measures of every clearance element (the flat
    fields: the first).

    The discontinuous laws run on the event-driven paths of the same flow, the same loop on top:
    δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t) (the single equation's :class:`~rattle.model.System`: jumps
    and Coulomb friction, Filippov sticking, locks at jumps), state (δ, δ'), scaled by (L, L ν);
    a chain with friction x'' + C x' + K x + Σ_e b_e [f_e(δ_e) + r_e(δ_e) sgn δ_e'] = F(t) (a
    :class:`~rattle.model.System` with its elements' whole laws), state (x, x'), with the measures of every element. Their shooting
    uses the exact monodromy with the saltation matrices (a stick or lock phase gives an exact
    zero multiplier, a stable direction); the measures come from the exact trajectories, the
    extremes of δ'' with their one-sided values at the switchings.

    Parameters
    ----------
    model : Model, Chain or System (continuous laws, or its whole laws: the single equation's or a chain's)
        The equations of motion.
    omega : float
        Forcing frequency Ω (rad/s), > 0.
    x0 : array_like, shape (2,) or (2n,), optional
        Initial state at t = 0 (forcing phase 0): (δ, δ') (rad, rad/s), or (x_1 … x_n, x'_1 …
        x'_n) for a chain; default the static equilibrium at rest.
    options : SteadyStateOptions, optional
        Tolerances and budget (default ``SteadyStateOptions()``).
    integrator : ExactIntegrator, optional
        The exact integrator of ``model`` (:func:`make_integrator`; reuse one across calls to
        share its cache).

    Returns
    -------
    SteadyState
        Period (0 when nothing settled within ``max_periods``), orbit, measures, multipliers and
        the final state to carry to the next frequency.
    """
    opts = SteadyStateOptions() if options is None else options
    if not isinstance(opts, SteadyStateOptions):
        raise TypeError(f"`options` must be a SteadyStateOptions, got {options!r}")
    if isinstance(model, System):
        from .._validate import check_omega

        omega = check_omega(omega)
        system: Model | System = model
    else:
        check_analysable_model(model)
        omega = _limits.check_frequency(model, omega)
        system = model if isinstance(model, Model) else model.system()
    if isinstance(system, Model) or system.is_single_equation:
        x = check_state(x0) if x0 is not None else static_state(system)
        names: tuple[str, ...] = ()
    else:
        n = system.n
        x = check_system_state(x0, n, "x0") if x0 is not None else static_state(system, omega)
        names = system.element_names
    flow = _Flow(system, _checked_integrator(integrator, system), omega)
    return _Settler(flow, omega, x.copy(), opts, names).run()


__all__ = ["SteadyStateOptions", "SteadyState", "steady_state", "METHODS", "static_state", "make_integrator",
           "stick_fraction"]
