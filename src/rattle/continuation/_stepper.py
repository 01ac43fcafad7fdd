"""Pseudo-arclength continuation of R(q, p) = 0 in its parameter p.

The parameter is whatever the problem makes it: the forcing frequency Ω of a frequency response,
the forcing scale λ of a start homotopy, … The stepper knows only its range [p_min, p_max], the
open ``domain`` in which the problem may be evaluated, and the ``symbol`` its messages use.

Keller's method on any :class:`~rattle.continuation.ContinuationProblem`, in scaled variables
y = (q / L, p / p_s) (see ``_problem`` and ``_corrector``):

* predictor (a ``predictor`` object, see ``_predictor``): by default along the unit tangent t,
  y_pred = y_i + Δs t;
* corrector: Newton on the bordered system  R(y) = 0,  d·(y − y_pred) = 0 (d the predictor's
  direction: t for the default);
* step control: Δs is scaled by the ratio of the target to the actual number of Newton
  iterations and by the ratio of the target to the actual turn of the tangent (angle between
  successive tangents); a step whose corrector fails, or whose tangent turns by more than the
  allowed angle, is rejected and retried with half the step, down to the minimum step;
* with a ``monitor`` (test functions whose zeros are the special points, see ``_monitor``) a
  step that leaves a test function unresolved — a hidden pair of zeros, a model that could
  reach zero, a kink near zero, too large a move — is rejected and retried with half the step
  (down to ``resolution``), and the next step is bounded by how fast the test functions move,
  so that every zero is bracketed by two consecutive points: no bifurcation is stepped over.

The stepper yields one accepted point per :meth:`ContinuationStepper.step`; the run ends when the
branch leaves the parameter range (the last point is placed exactly on the bound), when an
optional ``stop`` test fires, or with a :class:`~rattle.errors.Status` saying where and why.

``stations`` p_1, p_2, … (in the order the branch reaches them) are parameters at which a point is
placed exactly: a predicted step that passes the next station is cut there (the predictor's step
shortened in proportion), or a corrected step that passes it is cut on its chord, and the point
is solved at p = p_k by Newton from there; a solve that fails rejects the step (halved as any
other). A station on
the range's far end ends the run there. So
a ladder (a regularisation width ε_0 > ε_1 > … followed in log ε) reports its rungs at the
scheduled values whatever steps the step control took between them.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .._typing import FloatArray
from ..errors import Status
from ._corrector import ArclengthCorrector, Corrected
from ._monitor import Monitor, MonitorReading, check_segment
from ._newton import solve_fixed
from ._options import ContinuationOptions, NewtonOptions
from ._predictor import AbstractPredictor, Tangent
from ._problem import ContinuationProblem


@dataclass(frozen=True, slots=True)
class BranchPoint:
    """An accepted solution: unknowns ``q``, parameter ``p``, Newton ``iterations``, scaled
    ``residual``, unit ``tangent`` (scaled variables), the ``step`` that reached it and the
    monitor's ``reading`` there (None without a monitor)."""

    q: FloatArray
    p: float
    iterations: int
    residual: float
    tangent: FloatArray
    step: float
    reading: MonitorReading | None = None

    @property
    def omega(self) -> float:
        """``p`` under the name rattle's frequency responses read it by (their parameter is Ω)."""
        return self.p


@dataclass(slots=True)
class ContinuationStepper:
    """Step-by-step pseudo-arclength continuation (the low-level API).

    ``problem`` any :class:`~rattle.continuation.ContinuationProblem` (harmonic balance, shooting,
    a homotopy), ``q0`` a solution (or good guess) at the parameter ``p0``; ``p_range`` the
    parameter's range (min < max, inside ``domain``). Without ``tangent`` the start must be one
    end of ``p_range`` and the branch is followed into the range; with ``tangent`` (a direction
    in scaled variables, e.g. the critical eigenvector at a branch point) the start may be
    anywhere in the range and the branch is followed along that direction.
    ``stop(point) -> str | None`` may end the run (status ``STOPPED``) with the returned reason.
    ``monitor(q, p, dq/ds, dp/ds)`` returns the test functions whose zeros are the special
    points (see ``_monitor``); with it no zero is stepped over. ``predictor`` a
    :class:`~rattle.continuation.AbstractPredictor` (default :class:`~rattle.continuation.Tangent`).

    ``domain`` the open interval of parameters at which the problem may be evaluated (the
    corrector rejects an iterate outside it); the default, p > 0, suits a frequency, a forcing
    scale or a width; a homotopy parameter that may take any sign passes (−inf, inf).
    ``symbol`` names the parameter in messages (default ``"Ω"``: most of rattle's branches are
    frequency responses); ``speed``, when given, writes a value of the parameter in them instead
    (an engine case's crankshaft rpm: ``speed(p)`` → ``"1086 rpm"``). ``stations``: parameters at
    which a point is placed exactly (module docstring), in the order the branch reaches them; each
    inside ``p_range``.
    """

    problem: ContinuationProblem
    q0: FloatArray
    p0: float
    p_range: tuple[float, float]
    options: ContinuationOptions = field(default_factory=ContinuationOptions)
    newton: NewtonOptions = field(default_factory=NewtonOptions)
    tangent: FloatArray | None = None
    stop: Callable[[BranchPoint], str | None] | None = None
    monitor: Monitor | None = None
    predictor: AbstractPredictor = field(default_factory=Tangent)
    domain: tuple[float, float] = (0.0, math.inf)
    symbol: str = "Ω"
    speed: Callable[[float], str] | None = None
    stations: tuple[float, ...] = ()
    status: Status | None = None
    message: str = ""
    points: list[BranchPoint] = field(default_factory=list)
    rejected: int = 0  # trial steps rejected, for any reason
    monitor_rejected: int = 0  # of which by the test-function monitor
    corrector: ArclengthCorrector = field(init=False, repr=False)
    _y: FloatArray = field(init=False, repr=False)
    _t: FloatArray = field(init=False, repr=False)
    _y_prev: FloatArray | None = field(init=False, repr=False, default=None)
    _ds: float = field(init=False, repr=False)
    _start_time: float = field(init=False, repr=False)
    _direction: float = field(init=False, repr=False)
    _reading: MonitorReading | None = field(init=False, repr=False, default=None)

    def __post_init__(self) -> None:
        lo, hi = self.p_range
        d_lo, d_hi = self.domain
        if not d_lo < d_hi:
            raise ValueError(f"`domain` must be an interval (min < max), got {self.domain!r}")
        if not (math.isfinite(lo) and math.isfinite(hi) and d_lo < lo < hi < d_hi):
            raise ValueError(
                f"`p_range` must satisfy {d_lo:g} < min < max < {d_hi:g} (inside `domain`), got {self.p_range!r}"
            )
        if self.tangent is not None:
            if not lo <= self.p0 <= hi:
                raise ValueError(f"`p0` must lie in `p_range` {self.p_range}, got {self.p0}")
            self._direction = 0.0
        elif self.p0 == lo:
            self._direction = 1.0
        elif self.p0 == hi:
            self._direction = -1.0
        else:
            raise ValueError(f"`p0` must be one end of `p_range` {self.p_range}, got {self.p0}")
        if not isinstance(self.predictor, AbstractPredictor):
            raise TypeError(
                f"`predictor` must be a predictor object (rattle.continuation.Tangent(), Secant()), got {self.predictor!r}"
            )
        self.stations = tuple(float(x) for x in self.stations)
        if any(not lo <= x <= hi for x in self.stations):
            raise ValueError(f"`stations` must lie in `p_range` {self.p_range}, got {self.stations!r}")
        self._start_time = time.perf_counter()
        self.corrector = ArclengthCorrector(self.problem, self.newton, domain=self.domain)
        self._ds = self.options.initial_step

    def _finish(self, status: Status, message: str = "") -> None:
        self.status = status
        self.message = message or status.message

    def _read(self, y: FloatArray, t: FloatArray) -> MonitorReading | None:
        """The monitor's reading at scaled point y with unit scaled tangent t (None: no monitor)."""
        if self.monitor is None:
            return None
        q, p = self.corrector.unscale(y)
        d = t * self.corrector.scale
        return self.monitor(q, p, d[:-1], float(d[-1]))

    # --- public ----------------------------------------------------------------------------
    def start(self) -> BranchPoint | None:
        """Converge the first point at ``p0`` and compute its tangent.

        A start given with a ``tangent`` that already solves R = 0 (e.g. a located branch point,
        where ∂R/∂q is singular and a Newton step would be ill-posed) is taken as it is.
        """
        if self.tangent is not None:
            r0 = float(np.max(np.abs(self.problem.residual(self.q0, self.p0)))) / self.problem.force_scale
            if r0 <= self.newton.residual_tol:
                self._t = np.asarray(self.tangent, dtype=float) / np.linalg.norm(self.tangent)
                self._y = self.corrector.to_scaled(np.asarray(self.q0, dtype=float), self.p0)
                self._reading = self._read(self._y, self._t)
                pt = BranchPoint(np.array(self.q0, dtype=float), self.p0, 0, r0, self._t.copy(), 0.0, self._reading)
                self.points.append(pt)
                return pt
        res = solve_fixed(self.problem, self.q0, self.p0, self.newton)
        if not res.converged:
            self._finish(
                Status.START_FAILED,
                f"Newton did not converge at {self._at(self.p0)} ({res.message}, scaled residual {res.residual:.3g})",
            )
            return None
        R, Rq, Rp = self.problem.residual_jacobian(res.q, self.p0)
        if self.tangent is not None:
            reference = np.asarray(self.tangent, dtype=float) / np.linalg.norm(self.tangent)
            t0: FloatArray | None = reference
        else:
            reference = np.zeros(self.problem.size + 1)
            reference[-1] = self._direction
            t0 = self.corrector.tangent(Rq, Rp, reference)
        if t0 is None:
            self._finish(Status.START_FAILED, f"singular Jacobian at the start {self._at(self.p0)}")
            return None
        self._t = t0
        self._y = self.corrector.to_scaled(res.q, self.p0)
        self._reading = self._read(self._y, self._t)
        pt = BranchPoint(res.q, self.p0, res.iterations, res.residual, self._t.copy(), 0.0, self._reading)
        self.points.append(pt)
        return pt

    def step(self) -> BranchPoint | None:
        """Advance by one accepted point; None once the run has ended (see ``status``)."""
        if self.status is not None:
            return None
        if not self.points:
            return self.start()
        opts = self.options
        corr_ = self.corrector
        if len(self.points) >= opts.max_points:
            self._finish(Status.MAX_STEPS, f"{Status.MAX_STEPS.message} ({opts.max_points} points, last {self._at(self.points[-1].p)})")
            return None
        if opts.max_time is not None and time.perf_counter() - self._start_time > opts.max_time:
            self._finish(Status.MAX_TIME, f"{Status.MAX_TIME.message} ({opts.max_time} s, last {self._at(self.points[-1].p)})")
            return None
        lo, hi = self.p_range
        turns: list[float] = []  # the turns of the trials rejected in a row for turning too much
        ds_first = self._ds  # the step tried first (before any halving)
        kink = False
        while True:
            ds = self._ds
            y_pred, normal = self.predictor.predict(self._y, self._t, ds, self._y_prev)
            cut = self._cut_at_station(y_pred, ds) if self.stations else None
            corr = corr_.correct(y_pred, normal) if cut is None else self._solve_on_station(cut)
            if cut is None and corr is not None and self.stations:  # the corrector passed the station
                cut = self._cut_at_station(corr.y, None)
                corr = corr if cut is None else self._solve_on_station(cut)
            t_new = None if corr is None else corr_.tangent(corr.Rq, corr.Rp, self._t)
            at_floor = ds <= opts.min_step * 1.0000001
            if corr is not None and t_new is not None:
                turn = math.acos(min(1.0, float(t_new @ self._t)))
                # A kink of the branch (a contact switching on or off: the tangent jumps there) turns
                # the tangent by the same angle however short the step; on a smooth branch the turn
                # shrinks with the step. A turn that two halvings of the step in a row each left at
                # more than 3/4 of itself is a kink: taken in one step (the monitor below still
                # checks the segment: no zero of a test function is stepped over).
                kink = turn > opts.max_turn and len(turns) >= 2 and turn >= 0.75 * turns[-1] \
                    and turns[-1] >= 0.75 * turns[-2]
                if turn <= opts.max_turn or at_floor or kink:
                    reading = self._read(corr.y, t_new)
                    if reading is None or self._reading is None:
                        verdict = None
                        break
                    length = float(np.linalg.norm(corr.y - self._y))
                    verdict = check_segment(
                        self._reading, reading, length, tolerance=opts.monitor_tolerance,
                        max_change=opts.max_change, resolved=ds <= opts.resolution or at_floor,
                    )
                    if verdict.accept:
                        break
                    self.monitor_rejected += 1
            self.rejected += 1
            if corr is not None and t_new is not None and turn > opts.max_turn:
                turns.append(turn)
            else:
                turns.clear()
            if at_floor:
                _, p = corr_.unscale(self._y)
                self._finish(
                    Status.STEP_TOO_SMALL,
                    f"{Status.STEP_TOO_SMALL.message}: Newton failed to converge beyond {self._at(p)} "
                    f"with step {ds:.3g} (after {len(self.points)} points)",
                )
                return None
            self._ds = max(opts.min_step, 0.5 * ds)
        q, p = corr_.unscale(corr.y)
        at_station = bool(self.stations) and abs(p - self.stations[0]) <= 1e-13 * max(1.0, abs(self.stations[0]))
        if at_station:  # on the station (to round-off of the scaling): exactly there
            p, self.stations = self.stations[0], self.stations[1:]
        # Leaving the range: place the last point exactly on the bound and end.
        if p > hi or p < lo:
            bound = hi if p > hi else lo
            _, p_prev = corr_.unscale(self._y)
            frac = (bound - p_prev) / (p - p_prev)
            y_guess = self._y + frac * (corr.y - self._y)
            end = solve_fixed(self.problem, corr_.unscale(y_guess)[0], bound, self.newton)
            start_side = self._direction != 0.0 and (bound == lo) == (self._direction > 0)
            status = Status.RETURNED if start_side else Status.SUCCESS
            if end.converged:
                R, Rq, Rp = self.problem.residual_jacobian(end.q, bound)
                t_end = corr_.tangent(Rq, Rp, self._t)
                t_end = t_new if t_end is None else t_end
                pt = BranchPoint(end.q, bound, end.iterations, end.residual, t_end, ds * frac,
                                 self._read(corr_.to_scaled(end.q, bound), t_end))
            else:  # keep the point just outside rather than nothing
                pt = BranchPoint(q, p, corr.iterations, corr.residual, t_new, ds, reading)
            self.points.append(pt)
            self._finish(status)
            return pt
        pt = BranchPoint(q, p, corr.iterations, corr.residual, t_new, ds, reading)
        self.points.append(pt)
        self._y_prev = self._y
        self._y, self._t, self._reading = corr.y, t_new, reading
        # Step control from the iteration count and the tangent's turn.
        f_it = opts.target_iterations / max(corr.iterations, 1)
        f_turn = opts.target_turn / max(turn, 1e-12)
        if kink:  # the turn was the kink's, not the branch's curvature: go on with the step tried first
            ds, f_turn = ds_first, 2.0
        factor = min(max(min(f_it, f_turn), 0.5), 2.0)
        if verdict is not None:
            factor = min(factor, max(verdict.factor, 0.25))
        self._ds = min(opts.max_step, max(opts.min_step, ds * factor))
        if at_station and p == (hi if self._direction > 0 else lo if self._direction < 0 else math.nan):
            self._finish(Status.SUCCESS)  # a station on the far end: the run ends there
            return pt
        if self.stop is not None:
            reason = self.stop(pt)
            if reason:
                self._finish(Status.STOPPED, reason)
        return pt

    def _at(self, p: float) -> str:
        """A value of the parameter in a message: ``Ω = 1.2345`` (``symbol``), or ``speed(p)``."""
        return self.speed(float(p)) if self.speed is not None else f"{self.symbol} = {float(p):.6g}"

    def _cut_at_station(self, y_next: FloatArray, ds: float | None) -> FloatArray | None:
        """None, or when the step from the last point to ``y_next`` (the prediction with step
        ``ds``, or the corrected point with ``ds`` None) passes the next station p_k: the guess
        there, the predictor's step (or the chord) shortened in proportion."""
        corr_ = self.corrector
        p_prev, p = corr_.unscale(self._y)[1], corr_.unscale(y_next)[1]
        target = self.stations[0]
        if not (p_prev < target <= p or p <= target < p_prev):
            return None
        frac = (target - p_prev) / (p - p_prev)
        if ds is None:
            return self._y + frac * (y_next - self._y)
        return self.predictor.predict(self._y, self._t, ds * frac, self._y_prev)[0]

    def _solve_on_station(self, y_cut: FloatArray) -> Corrected | None:
        """Newton at the next station p_k (the problem's own step, :func:`solve_fixed`) from the
        cut prediction, with the Jacobians there; None when it does not converge."""
        corr_, target = self.corrector, self.stations[0]
        res = solve_fixed(self.problem, corr_.unscale(y_cut)[0], target, self.newton)
        if not res.converged:
            return None
        _, Rq, Rp = self.problem.residual_jacobian(res.q, target)
        return Corrected(corr_.to_scaled(res.q, target), res.iterations, res.residual, Rq, Rp)

    def run(self) -> list[BranchPoint]:
        """Step until the run ends; returns all accepted points."""
        while self.step() is not None:
            pass
        return self.points

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self._start_time


__all__ = ["BranchPoint", "ContinuationStepper"]
