"""Exact shooting continuation: the branch of periodic orbits of a discontinuous law, every row an
exact orbit.

For a law with torque jumps (a preload) or Coulomb friction, on the single equation
(single-equation :class:`~rattle.model.System`) or on a chain (:class:`~rattle.model.System` with its elements' whole laws),
the periodic orbits of period T = p·2π/Ω are the zeros of the scaled period-map defect

    R(z(0), Ω) = (φ_T(z(0); Ω) − z(0)) / s        (:class:`~rattle.timeint.ShootingProblem`),

φ_T the exact event-driven flow (crossings located to round-off, stick/slip/lock by Filippov) and
∂R/∂z(0) = (M − I)/s with M the exact monodromy (stage transition matrices and saltation
matrices). The branch is continued by pseudo-arclength in (z(0), Ω) on the one stepper
(:class:`~rattle.continuation.ContinuationStepper`): every row is an exact orbit, its rms, measures,
stick time and Floquet multipliers exact by construction (no regularisation, no truncation).

**Start.** At the first frequency the exact flow is simulated ``settle_periods`` forcing periods
from rest (transients decay) and the period map's fixed point is found by Newton from there;
where that fails, from ``settle_periods`` more.

**Grazing.** Where the orbit grazes a switching surface (a crossing of a jump or a stop at zero
speed, the start or end of a stick or lock phase) the period map is continuous but its derivative
blows up (the saltation matrix carries 1/v), and the corrector fails ever closer to the grazing
point: the stepper ends with its step at the floor. The branch then goes on along the orbits of
the other event structure: at Ω (1 ± h) next to the last point, h = ``hops`` in turn, the period
map's fixed point is sought by Newton from the last orbit (damped where plain Newton fails, within
:data:`HOP_EVALUATIONS` period maps); one that differs from it by at most
:data:`HOP_DISTANCE` (scaled state) and has another event structure is on the branch's other
side. The branch is continued from it away from the grazing (Ω increasing from Ω (1 + h),
decreasing from Ω (1 − h)); a continuation that stalls again within :data:`MIN_PIECE` points is
the wrong arm (the same side of the grazing), and the next candidate is tried. So a
discontinuity-induced fold (the two arms on one side of the grazing: the branch turns there) and
a persisting branch (the arms on either side) are both followed.

**Special points located.** Between two consecutive rows whose count of multipliers outside the
unit circle (|μ| > 1 + :data:`UNIT_TOL`) differs, the point where the critical multiplier's
modulus crosses 1 is located on the branch by Brent's method along the secant
(:func:`~rattle.continuation.locate_on_segment`, each trial point corrected onto the branch): to
``xtol`` in scaled arc length, far inside 1e-4 in Ω. It is labelled by how the multipliers left
the unit circle (:func:`~rattle.stability.classify_loss`: ``fold``, ``period_doubling``,
``neimark_sacker``) when they do so continuously, and by what happened to the event structure when
they jump there (a discontinuity-induced bifurcation): ``grazing_sliding`` where a stick or lock
phase appears or vanishes, ``grazing`` where a pair of crossings does.

**Coverage.** A branch followed from Ω_min that turns back and leaves the range at Ω_min, or ends
early, leaves the frequencies above it uncovered: the branch through Ω_max is then followed down
from there (a second branch) until it joins the first among the frequencies covered (its orbit
within :data:`JOIN_DISTANCE` of the first branch's there). Where it does not join, it is another
orbit — measured: a preload whose branch from Ω_min ended at a grazing where the branch from Ω_max,
another event structure (four crossings of the jump where the first had two), went on below the
first's top frequency and carried the stable motion a sweep settles on there — and it is followed
on (at most :data:`SEEDED_POINTS` points below the first's top).

**Where no computed orbit is stable.** A bounded, damped motion settles on some attractor at every
Ω; where no row of the branches is stable (nor unstable only by a period doubling, whose
period-2 orbit is the motion there), the one followed is not what a run-up shows (measured: a
preload whose only branch from Ω_min stayed on an unstable small orbit over Ω 1.04–1.65 while
sweeps settled on a stable one of 10–30× its rms). There an exact up/down sweep
(:class:`~rattle.analysis.SweepCheck`: ``check.points`` frequencies each way over the whole range,
spread over those intervals, the state carried) settles on the attractors, and every period-1
attractor no stable stretch explains (every element's rms within ``check.rtol``) is shot to its
exact orbit and followed both ways as a branch of its own until it leaves the range or joins rows
already computed (:func:`_missed_branches`, at most ``check.max_branches`` branches of at most
:data:`SEEDED_POINTS` points each way). Intervals narrower than :data:`MIN_GAP` of the range
are left (a stability change and its jump). Sub-harmonic and non-periodic attractors are not
continued here (``subharmonics=True``). On one coordinate (a flow of ~10 ms a frequency) the
sweep runs over the whole range, as for the smooth laws, so that a stable attractor beside a stable
computed one is found too (measured: a preload whose branch from Ω_min was unstable over its first
1.3 % of the range — too narrow an interval — while a run-up from rest settles at Ω_min on a
stable orbit of 1.26× its rms); on a chain only over those intervals.

**Arms a hop skipped.** Where the follower hops a grazing (or restarts past a stall) onto an arm
that goes on back beyond the hop with its own event structure, that stretch was never followed
(measured: a preload's stable arm, rms 0.0316, from the hop at Ω 0.3891 down to its fold at
0.3808, where a run-down settles): each such arm is followed back as a branch of its own until it
joins rows already computed, leaves the range, or stays unstable for :data:`ARM_UNSTABLE_POINTS`
points (:func:`_skipped_arms`).

**Windows of periodic motion.** On one coordinate, between two of the sweep check's frequencies
where the motion was not period 1 (non-periodic, sub-harmonic, failed), the sweep goes on at up to
:data:`REFINE_POINTS` frequencies inside the step, the state carried (:func:`_refined`): a window
of period-1 motion inside a chaotic stretch is often narrower than the check's spacing.

**A branch that closes on itself.** A piece whose points run on the rows of the branch's earlier
pieces (:data:`RETRACE_POINTS` in a row) ends the branch (:meth:`_Follower._retrace`): where
grazings follow one another closely, hopping each can lead back onto arms already followed. What
the branch leaves uncovered gets starts of its own, the gaps taken again after each start.

**The range's ends.** The check's first frequency each way starts from rest, the longest
transient: where it did not settle in ``check.max_periods`` it goes on to the default budget
(:func:`_from_rest`); and the unstable rows at Ω_min and Ω_max are probed as the middle rows of
unstable stretches are (:func:`_probed_branches`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..continuation import (
    ArclengthCorrector,
    BranchPoint,
    ContinuationOptions,
    ContinuationStepper,
    NewtonOptions,
    locate_on_segment,
    solve_fixed,
)
from .._limits import MAX_PERIOD
from .._threads import one_blas_thread
from ..errors import RattleError, Status
from ..model import System
from ..stability import classify_loss
from ..timeint import FLOW_FAILURES, ShootingProblem, monodromy_multipliers
from ._period_two import pushed_starts
from ._sweep_check import SweepCheck

#: |μ| up to 1 + UNIT_TOL counts as inside the unit circle: an element stuck the whole period
#: gives a neutral multiplier 1 (a family of orbits).
UNIT_TOL = 1e-8
#: A hop past a grazing lands on the branch's other side only within this scaled distance of the
#: last orbit (the state moves like the square root of the distance to the grazing).
HOP_DISTANCE = 0.05
#: ... and only to an orbit whose every element's rms is within this relative distance of the last
#: orbit's: across a grazing the orbit changes continuously (the new crossings or stick phases are
#: small), so a hop of h ≤ 1e-2 in Ω moves the rms by far less.
HOP_RMS = 0.05
#: The most period maps the damped Newton of one hop candidate integrates (measured on the examples
#: and the bench's preload cases: the hops that landed took at most 14, the ones that never landed
#: 176–308, half a second to 1.2 s a candidate on a chain).
HOP_EVALUATIONS = 64
#: A piece continued from a hop that stalls again within this many points is the wrong arm.
MIN_PIECE = 5
#: A piece whose last CRAWL_POINTS steps were all within CRAWL_FACTOR × the stepper's smallest
#: step is approaching a grazing (the corrector converges only ever closer to it): it ends there
#: and the grazing is hopped (module docstring).
CRAWL_POINTS = 4
CRAWL_FACTOR = 8.0
CRAWLING = "crawling towards a grazing"
#: A piece whose RETRACE_POINTS points in a row lie on rows of the branch's earlier pieces (within
#: :data:`JOIN_DISTANCE`) retraces an arm already followed: the branch closed on itself and ends.
RETRACE_POINTS = 3
CLOSED = "the branch closed on itself (it retraced an arm already followed)"
#: A hop's grazing point is sought this many points back along the arm hopped onto.
GRAZE_POINTS = 40
#: Unstable stretches probed for an attractor next to them (:func:`_probed_branches`), and the
#: push along the unstable eigenvector (scaled max-norm: a share of the length scale).
PROBES = 8
PROBE_PUSH = 0.05
#: The most arms a hop skipped followed as branches of their own (:func:`_skipped_arms`), and
#: how many unstable points in a row end one (the stable motion it carried has ended there).
MAX_ARMS = 4
ARM_UNSTABLE_POINTS = 20
#: Relative frequency steps to a restart past a stall that no hop passes (:meth:`_Follower._restart`).
RESTART_STEPS = (0.005, 0.02, 0.05)
#: A restart past a stall whose orbit's rms is within this relative distance of the stall's is the
#: same branch (followed back to the stall); a larger jump is another branch (:meth:`_Follower._restart`).
RESTART_RMS = 0.1
#: A branch followed from a restart onto another branch ends where its state comes within this
#: scaled distance of the orbit interpolated between two rows of the branch it started from.
JOIN_DISTANCE = 1e-2
#: The most points followed each way from an attractor the sweep found (module docstring).
SEEDED_POINTS = 200
#: Intervals without a stable row narrower than this share of the range are not swept.
MIN_GAP = 0.02
#: Frequencies the sweep check adds, a direction, inside its steps where a motion was not period 1
#: (:func:`_refined`): REFINE_BUDGET × its points in all, at most REFINE_POINTS a step (its spacing
#: there divided by up to REFINE_POINTS + 1); ~20 ms each on one coordinate.
REFINE_BUDGET = 3
REFINE_POINTS = 7
#: Multipliers that move by less than this across a located point left the unit circle
#: continuously (a smooth bifurcation); a larger jump is the event structure's.
CONTINUOUS_JUMP = 1e-3


@dataclass(frozen=True, slots=True)
class ShootingOptions:
    """Exact shooting continuation (SPEC §8 ``method = "shooting"``), the default method for laws
    with jumps or friction.

    ``settle_periods`` forcing periods of exact simulation before the first shooting at a start;
    ``hops`` the relative frequency offsets tried in turn past a grazing (module docstring);
    ``max_pieces`` the most pieces (grazings passed) per branch; ``locate`` the stability
    changes on the branch (module docstring); ``xtol`` the location's tolerance in scaled arc
    length; ``check`` the exact sweep over the frequencies where no computed orbit is stable (module
    docstring; None: none)."""

    settle_periods: int = 40
    hops: tuple[float, ...] = (1e-5, 1e-4, 1e-3, 1e-2)
    max_pieces: int = 64
    locate: bool = True
    xtol: float = 1e-10
    check: SweepCheck | None = SweepCheck()

    def __post_init__(self) -> None:
        if isinstance(self.settle_periods, bool) or not isinstance(self.settle_periods, int) or self.settle_periods < 0:
            raise ValueError(f"`settle_periods` must be an integer >= 0, got {self.settle_periods!r}")
        hops = tuple(self.hops)
        if not hops or not all(isinstance(h, (int, float)) and not isinstance(h, bool) and 0 < h < 0.5 for h in hops):
            raise ValueError(f"`hops` must be relative offsets in (0, 0.5), got {self.hops!r}")
        object.__setattr__(self, "hops", tuple(float(h) for h in hops))
        if isinstance(self.max_pieces, bool) or not isinstance(self.max_pieces, int) or self.max_pieces < 1:
            raise ValueError(f"`max_pieces` must be an integer >= 1, got {self.max_pieces!r}")
        if not isinstance(self.locate, bool):
            raise TypeError(f"`locate` must be True or False, got {self.locate!r}")
        if not (isinstance(self.xtol, (int, float)) and 0 < self.xtol < 1e-2):
            raise ValueError(f"`xtol` must be in (0, 0.01), got {self.xtol!r}")
        if self.check is not None and not isinstance(self.check, SweepCheck):
            raise TypeError(f"`check` must be a SweepCheck or None, got {self.check!r}")


@dataclass(slots=True)
class ExactRow:
    """One row of an exact branch: the state z(0) ``q``, ``omega``, the monodromy ``M`` and its
    ``multipliers`` (largest modulus first, computed once), its event ``structure``, the
    ``label`` of a special point located there ("" none) and the ``trajectory`` of one period."""

    q: FloatArray
    omega: float
    M: FloatArray
    multipliers: ComplexArray
    structure: tuple[int, ...]
    label: str = ""
    trajectory: Any = None

    @property
    def unstable_count(self) -> int:
        return int(np.sum(np.abs(self.multipliers) > 1.0 + UNIT_TOL))


@dataclass(slots=True)
class ExactBranch:
    """The rows of one continued exact branch (in continuation order), how it ended (``status``,
    ``message``), the ``pieces`` it was followed in (rows per piece: grazings passed between
    them), ``origin`` (where it was started), its ``period`` p (T = p 2π/Ω) and the ``bridges``: the Ω intervals between a stall
    and the hop past its grazing (the branch is continuous across them)."""

    rows: list[ExactRow] = field(default_factory=list)
    status: Status = Status.SUCCESS
    message: str = ""
    pieces: list[int] = field(default_factory=list)
    origin: str = ""
    bridges: list[tuple[float, float]] = field(default_factory=list)
    period: int = 1

    @property
    def omega(self) -> FloatArray:
        return np.array([r.omega for r in self.rows], dtype=float)


def _row(problem: ShootingProblem, q: FloatArray, omega: float) -> ExactRow:
    """The row of the orbit through (q, Ω): one recorded period of the exact flow (its monodromy,
    event structure and trajectory)."""
    q = np.asarray(q, dtype=float).copy()
    traj = problem.integrator.propagate(q, 0.0, problem.orbit_period(omega), omega)
    M = np.asarray(traj.sensitivity, dtype=float)
    return ExactRow(q, float(omega), M, monodromy_multipliers(M), traj.event_structure(), trajectory=traj)


def _row_rms(row: ExactRow) -> FloatArray:
    """Every element's rms over the row's recorded period (the trajectory's own quadrature)."""
    traj = row.trajectory
    if hasattr(traj, "element_mean_and_rms"):  # a chain's trajectory: one rms per element
        return np.atleast_1d(np.asarray(traj.element_mean_and_rms()[1], dtype=float))
    return np.atleast_1d(float(traj.mean_and_rms()[1]))


def start_state(problem: ShootingProblem, omega: float, options: ShootingOptions, newton: NewtonOptions,
                guess: FloatArray | None = None, continuation: ContinuationOptions | None = None,
                bounds: tuple[float, float] | None = None) -> FloatArray | None:
    """The exact periodic orbit's z(0) at ``omega``: :func:`settled_start` there, else from a
    neighbouring frequency Ω (1 ± δ), δ = 1 %, 3 %, 10 % (within ``bounds``), continued along its
    branch to ``omega`` (an unstable orbit that neither the settled flow nor Newton from the
    attractor reaches at ``omega`` is reached along the branch). None when none is found."""
    q = settled_start(problem, omega, options, newton, guess)
    if q is not None:
        return q
    lo, hi = bounds if bounds is not None else (0.0, math.inf)
    cont = continuation or ContinuationOptions()
    for delta in (0.01, 0.03, 0.1):
        for sign in (1.0, -1.0):
            w1 = omega * (1.0 + sign * delta)
            if not lo <= w1 <= hi:
                continue
            q1 = settled_start(problem, w1, options, newton, guess)
            if q1 is None:
                continue
            rng = (min(omega, w1), max(omega, w1))
            stepper = ContinuationStepper(problem, q1, w1, rng, options=cont, newton=newton)
            pts = stepper.run()
            if pts and stepper.status in (Status.SUCCESS, Status.RETURNED) and pts[-1].p == omega:
                return pts[-1].q
    return None


def settled_start(problem: ShootingProblem, omega: float, options: ShootingOptions, newton: NewtonOptions,
                  guess: FloatArray | None = None) -> FloatArray | None:
    """The exact periodic orbit's z(0) at ``omega`` (module docstring, start): from ``guess`` (else
    rest) settled ``settle_periods`` forcing periods by the exact flow, then Newton on the period
    map; where that fails, settled as long again. None when no orbit was found."""
    z = np.zeros(problem.size) if guess is None else np.asarray(guess, dtype=float).copy()
    T1 = 2.0 * math.pi / omega
    integ = problem.integrator
    for _ in range(START_TRIES):
        try:
            for _k in range(options.settle_periods):
                z = np.asarray(integ.propagate(z, 0.0, T1, omega).state1, dtype=float)
        except Exception:  # noqa: BLE001 - a flow that cannot be followed gives no start
            return None
        res = solve_fixed(problem, z, omega, newton)
        if res.converged:
            return res.q
        q = damped_newton(problem, z, omega, newton)
        if q is not None:
            return q
    return None


#: Settled starts tried (each ``settle_periods`` later than the last: another point of the attractor).
START_TRIES = 3


def damped_newton(problem: ShootingProblem, q: FloatArray, omega: float, newton: NewtonOptions,
                  iterations: int = 60, evaluations: int | None = None) -> FloatArray | None:
    """Newton on the period map at fixed Ω with the step halved until the scaled residual
    decreases (:meth:`ShootingProblem.solve`: an unstable orbit, which the settled flow does not
    approach, from a state of the attractor); None when it stalls or has integrated ``evaluations``
    period maps (None: no cap). Converged as :func:`~rattle.continuation.solve_fixed` (residual and
    step within the tolerances)."""
    try:
        shot = problem.solve(q, omega, tol=newton.residual_tol, step_tol=newton.step_tol, max_iterations=iterations,
                             max_halvings=29, least_squares=False, record=False, max_evaluations=evaluations)
    except FLOW_FAILURES:  # the flow cannot be followed from q
        return None
    return shot.x if shot.converged else None


def _tangent(problem: ShootingProblem, corrector: ArclengthCorrector, q: FloatArray, omega: float,
             direction: float) -> FloatArray | None:
    """The branch's unit tangent (scaled) at (q, Ω), oriented so that Ω moves by ``direction``."""
    R, Rq, Rp = problem.residual_jacobian(q, omega)
    if not np.all(np.isfinite(Rq)):
        return None
    reference = np.zeros(problem.size + 1)
    reference[-1] = direction
    return corrector.tangent(Rq, Rp, reference)


class _Follower:
    """Follows one exact branch in pieces (module docstring)."""

    def __init__(self, problem: ShootingProblem, omega: tuple[float, float], options: ShootingOptions,
                 continuation: ContinuationOptions, newton: NewtonOptions, progress: Any = None) -> None:
        self.problem = problem
        self.progress = progress
        self._reach = (math.inf, -math.inf)
        self.lo, self.hi = omega
        self.options = options
        self.continuation = continuation
        self.newton = newton
        self.corrector = ArclengthCorrector(problem, newton)
        #: the rows of the last piece's accepted points, made as they were accepted (their period
        #: was then the flow's last: no second integration, :meth:`_rows`)
        self._made: dict[tuple[float, bytes], ExactRow] = {}
        #: arms hopped onto that go on against the direction of travel beyond the grazing (the
        #: stretch a hop skipped): (z(0), Ω, direction) to follow as branches of their own
        self.arms: list[tuple[FloatArray, float, float]] = []

    def _rows(self, pts: list[BranchPoint]) -> list[ExactRow]:
        """The rows of the last piece's points ``pts`` (made when accepted, else now)."""
        made, self._made = self._made, {}
        rows = []
        for p in pts:
            row = made.get((p.p, p.q.tobytes()))
            rows.append(row if row is not None else _row(self.problem, p.q, p.p))
        return rows

    def _piece(self, q: FloatArray, w: float, direction: float,
               stop: Any = None) -> ContinuationStepper | None:
        lo, hi = self.lo, self.hi
        if w <= lo and direction < 0 or w >= hi and direction > 0:
            return None
        tangent = None
        if lo < w < hi:
            tangent = _tangent(self.problem, self.corrector, q, w, direction)
            if tangent is None:
                return None
        floor = CRAWL_FACTOR * self.continuation.min_step
        crawl = [0]
        made = self._made = {}

        def halt(pt: BranchPoint) -> str | None:
            made[(pt.p, pt.q.tobytes())] = _row(self.problem, pt.q, pt.p)
            crawl[0] = crawl[0] + 1 if pt.step <= floor else 0
            if self.progress is not None:
                self._report(pt.p)
            if crawl[0] >= CRAWL_POINTS:
                return CRAWLING
            return None if stop is None else stop(pt)

        stepper = ContinuationStepper(self.problem, q, w, (lo, hi), options=self.continuation, newton=self.newton,
                                      tangent=tangent, stop=halt)
        stepper.run()
        if stepper.status is Status.STOPPED and stepper.message == CRAWLING:
            stepper.status = Status.STEP_TOO_SMALL  # a grazing approached: hop it
            stepper.message = (f"{Status.STEP_TOO_SMALL.message}: the steps fell to the floor near "
                               f"Ω = {stepper.points[-1].p:.6g} (a grazing)")
        return stepper

    def _report(self, omega: float) -> None:
        """``progress(done, total)``: the share of the range reached so far, in thousandths."""
        a, b = min(self._reach[0], omega), max(self._reach[1], omega)
        self._reach = (a, b)
        self.progress(int(round(1000 * (b - a) / (self.hi - self.lo))), 1000)

    def _hops(self, last: BranchPoint, last_row: ExactRow,
              recent: float) -> list[tuple[FloatArray, float, float]]:
        """Candidates past a grazing: (z(0), Ω, direction) of nearby orbits of another structure;
        failing those, the nearest orbit of the same structure a step ahead in the direction of
        travel since the Ω ``recent`` a few points back (the steps fell to the floor where the
        branch still goes on: a natural step over)."""
        s = self.problem.length_scale
        structure = last_row.structure
        rms_last = _row_rms(last_row)
        out: list[tuple[FloatArray, float, float]] = []
        ahead: list[tuple[FloatArray, float, float]] = []
        travel = 1.0 if last.p >= recent else -1.0
        for h in self.options.hops:
            for d in (1.0, -1.0):
                w = last.p * (1.0 + d * h)
                if not self.lo <= w <= self.hi:
                    continue
                res = solve_fixed(self.problem, last.q, w, self.newton)
                q = res.q if res.converged else damped_newton(self.problem, last.q, w, self.newton,
                                                              evaluations=HOP_EVALUATIONS)
                if q is None or float(np.max(np.abs((q - last.q) / s))) > HOP_DISTANCE:
                    continue
                try:
                    row = _row(self.problem, q, w)
                except Exception:  # noqa: BLE001 - no orbit where the flow cannot be followed
                    continue
                # the orbit itself next to the last one, not only its state at t = 0: an orbit of
                # another branch can pass close to z(0) with a far larger motion (measured: a
                # preload with stage friction hopped from rms 0.128 onto a resonance orbit of 0.40)
                if not np.all(np.abs(_row_rms(row) - rms_last) <= HOP_RMS * np.abs(rms_last)):
                    continue
                if row.structure != structure:
                    out.append((q, w, d))
                elif d == travel and not ahead:
                    ahead.append((q, w, d))
            if out:
                break
        return out or ahead

    def follow(self, q0: FloatArray, w0: float, direction: float, stop: Any = None) -> ExactBranch:
        branch = ExactBranch()
        q, w, d = q0, w0, direction
        pending: list[tuple[FloatArray, float, float]] = []
        hopped = False
        while True:
            stepper = self._piece(q, w, d, self._retrace(branch, stop))
            pts = [] if stepper is None else stepper.points
            stalled = stepper is not None and stepper.status is Status.STEP_TOO_SMALL
            if pending and (not pts or stalled and len(pts) < MIN_PIECE):
                q, w, d = pending.pop(0)  # the wrong arm: try the next candidate
                continue
            if pts:
                rows = self._rows(pts)
                if branch.rows and rows and hopped:
                    graze = self._graze(pts[0], d, rows[0].structure)
                    if graze is not None:
                        rows.insert(0, graze)
                    rows[0].label = "grazing_sliding" if _held_changed(branch.rows[-1], rows[0]) else "grazing"
                branch.pieces.append(len(rows))
                branch.rows.extend(rows)
            if stepper is None:
                branch.status, branch.message = Status.START_FAILED, f"no exact branch could be continued from Ω = {w:.6g}"
                return branch
            branch.status, branch.message = stepper.status or Status.SUCCESS, stepper.message
            if not stalled or len(branch.pieces) >= self.options.max_pieces:
                return branch
            last = pts[-1]
            recent = pts[max(0, len(pts) - 8)].p
            candidates = self._hops(last, branch.rows[-1], recent)
            if not candidates:
                travel = 1.0 if last.p >= recent else -1.0
                restarted = self._restart(branch, last.p, travel, stop)
                if restarted is None:
                    branch.message += " (a grazing: no orbit of another event structure was found next to it)"
                    return branch
                candidates = [restarted]
                hopped = False
            else:
                hopped = True
                # the arms meet at the grazing between the stall and the hop: the branch is continuous there
                branch.bridges.append((min(last.p, candidates[0][1]), max(last.p, candidates[0][1])))
            q, w, d = candidates[0]
            pending = candidates[1:]

    def _retrace(self, branch: ExactBranch, stop: Any) -> Any:
        """The stop of the branch's next piece: the caller's ``stop``, and the branch closing on
        itself — :data:`RETRACE_POINTS` points in a row on the rows of a piece before the last one
        (measured: a preload with stage friction whose branch, hopping grazings in a snaking
        stretch of Ω 0.357–0.388, followed the same arms over and over until ``max_pieces``: 2000
        rows, 20 s, and the range above left uncovered)."""
        earlier = branch.rows[: len(branch.rows) - branch.pieces[-1]] if len(branch.pieces) >= 2 else []
        if not earlier:
            return stop
        on = [0]

        def halt(pt: BranchPoint) -> str | None:
            on[0] = on[0] + 1 if _joins(self.problem, pt, earlier, math.nan) else 0
            if on[0] >= RETRACE_POINTS:
                return CLOSED
            return None if stop is None else stop(pt)
        return halt

    def _graze(self, start: BranchPoint, direction: float, structure: tuple[int, ...]) -> ExactRow | None:
        """The grazing point a hop passed, on the arm hopped onto: that arm followed back (against
        ``direction``) from its first point while its event structure stays ``structure``; the last
        such point (the arm ends there, or its structure changes: the grazing, to the stepper's
        resolution). None when the arm cannot be followed back."""
        seen: list[BranchPoint] = []

        def same(pt: BranchPoint) -> str | None:
            if self._made[(pt.p, pt.q.tobytes())].structure != structure:  # the row made when accepted
                return "the structure changed"
            seen.append(pt)
            return "far enough" if len(seen) > GRAZE_POINTS else None

        stepper = self._piece(start.q, start.p, -direction, same)
        if stepper is not None and (len(seen) > GRAZE_POINTS or len(seen) >= 2 and stepper.status in (
                Status.SUCCESS, Status.RETURNED)):
            # the arm goes on back beyond the stall with its structure: not a grazing next to the
            # hop but a stretch of orbits the hop skipped (measured: a preload's stable arm from
            # Ω 0.3891 down past 0.387, where a run-down settles on it) — followed afterwards
            self.arms.append((start.q, start.p, -direction))
        if stepper is None or len(seen) < 2 or len(seen) > GRAZE_POINTS:
            return None
        return _row(self.problem, seen[-1].q, seen[-1].p)

    def _restart(self, branch: ExactBranch, w_stall: float, travel: float,
                 stop: Any) -> tuple[FloatArray, float, float] | None:
        """Past a stall with no orbit next to it: the exact start (settled, then shot) a step
        :data:`RESTART_STEPS` further in the direction of travel, where this branch has no rows yet;
        the stretch back to the stall is followed from there (a piece of its own). Returns the
        restart (z(0), Ω, direction) to go on from, or None."""
        covered = (min(r.omega for r in branch.rows), max(r.omega for r in branch.rows))
        for step in RESTART_STEPS:
            w = w_stall * (1.0 + travel * step)
            if not self.lo <= w <= self.hi or covered[0] <= w <= covered[1]:
                continue
            q = start_state(self.problem, w, self.options, self.newton, continuation=self.continuation,
                            bounds=(self.lo, self.hi))
            if q is None:
                continue
            if stop is not None and stop(BranchPoint(q, w, 0, 0.0, np.zeros(q.size + 1), 0.0)):
                return None

            def back(pt: BranchPoint, w_stall: float = w_stall) -> str | None:
                return "reached the stall" if (pt.p - w_stall) * travel <= 0 else None

            restart_rms = _row_rms(_row(self.problem, q, w))
            stall = branch.rows[-1]
            stall_rms = _row_rms(stall)
            if np.all(np.abs(restart_rms - stall_rms) <= RESTART_RMS * np.abs(stall_rms)):
                stepper = self._piece(q, w, -travel, back)
                if stepper is not None and stepper.message == "reached the stall":
                    # one step past the stall: the same orbit is within that step's arc length of
                    # the stall's; farther, the restart is on another orbit of a like rms that goes
                    # on beyond (measured: a preload's stable arm, rms 0.0316 beside the stall's
                    # unstable 0.0296, at a scaled distance of 0.38) — followed on afterwards
                    last = stepper.points[-1]
                    if float(np.max(np.abs(last.q - stall.q) / self.problem.length_scale)) > \
                            2.0 * self.continuation.max_step:
                        self.arms.append((last.q, last.p, -travel))
            else:
                # another branch (the stall's branch turned back at a grazing we could not pass, or
                # ended): followed back past the stall's frequency — over its own folds — until it
                # leaves the range or joins the rows of this branch, so none of it is skipped
                stepper = self._piece(q, w, -travel, lambda pt, rows=list(branch.rows): _joins(self.problem, pt, rows, w))
            if stepper is not None and stepper.points:
                rows = list(reversed(self._rows(stepper.points)))
                if rows:
                    branch.pieces.append(len(rows))
                    branch.rows.extend(rows)
            return q, w, travel
        return None

    def locate(self, branch: ExactBranch) -> None:
        """Insert the located special points between rows of different stability (module docstring)."""
        rows = branch.rows
        out: list[ExactRow] = []
        piece_end = np.cumsum(branch.pieces) if branch.pieces else np.array([len(rows)])
        s = self.problem.length_scale
        eye = np.eye(self.problem.size)
        sizes = list(branch.pieces) if branch.pieces else [len(rows)]
        piece_of = np.searchsorted(piece_end, np.arange(len(rows)), side="right")
        for i, row in enumerate(rows):
            if i and i not in piece_end:
                a = rows[i - 1]
                ca, cb = a.unstable_count, row.unstable_count
                if ca != cb:
                    k = min(ca, cb)

                    def test(q: FloatArray, p: float, corr: Any, dvec: Any, k: int = k) -> float:
                        M = corr.Rq * s[:, None] + eye
                        return float(np.sort(np.abs(np.linalg.eigvals(M)))[::-1][k]) - 1.0

                    pt = locate_on_segment(self.corrector, a.q, a.omega, row.q, row.omega, test,
                                           xtol=self.options.xtol)
                    if pt is not None:
                        located = _row(self.problem, pt.q, pt.p)
                        located.label = _label(a, row)
                        out.append(located)
                        sizes[int(piece_of[i])] += 1
            out.append(row)
        branch.rows = out
        if branch.pieces:
            branch.pieces = sizes


def _joins(problem: ShootingProblem, pt: BranchPoint, rows: list[ExactRow], w0: float) -> str | None:
    """"joined the branch" when the point's state is within :data:`JOIN_DISTANCE` (scaled) of the
    orbit interpolated between two consecutive ``rows`` around its Ω (never at the start ``w0``)."""
    if abs(pt.p - w0) <= 1e-9 * w0:
        return None
    s = problem.length_scale
    for a, c in zip(rows, rows[1:]):
        if min(a.omega, c.omega) <= pt.p <= max(a.omega, c.omega):
            t = 0.0 if a.omega == c.omega else (pt.p - a.omega) / (c.omega - a.omega)
            if float(np.max(np.abs(pt.q - ((1.0 - t) * a.q + t * c.q)) / s)) <= JOIN_DISTANCE:
                return "joined the branch"
    return None


def _held_changed(a: ExactRow, b: ExactRow) -> bool:
    """The number of stick or lock phases differs between the two rows' structures."""
    return a.structure[0::2] != b.structure[0::2]


def _label(a: ExactRow, b: ExactRow) -> str:
    """The name of the stability change between rows a and b (module docstring)."""
    mu_a, mu_b = a.multipliers, b.multipliers
    jump = float(np.max(np.abs(np.sort(np.abs(mu_a)) - np.sort(np.abs(mu_b)))))
    if a.structure != b.structure and jump > CONTINUOUS_JUMP:
        return "grazing_sliding" if _held_changed(a, b) else "grazing"
    return classify_loss(mu_a, mu_b)


def exact_branches(
    system: System,
    omega: tuple[float, float],
    options: ShootingOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    period: int = 1,
    progress: Any = None,
) -> list[ExactBranch]:
    """The branch of period ``period`` (1: period-1 orbits) over ``omega`` = (Ω_min, Ω_max) followed from Ω_min by exact shooting
    continuation, and, where it leaves frequencies above it uncovered, the branch through Ω_max
    followed down (module docstring). Every row an exact orbit; special points located and
    labelled. ``progress(done, total)``, if given, is called at every accepted point with the share
    of the range reached (in thousandths; the library draws nothing itself)."""
    opts = ShootingOptions() if options is None else options
    if not isinstance(opts, ShootingOptions):
        raise TypeError(f"`options` must be a ShootingOptions, got {opts!r}")
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be a callable progress(done, total) or None, got {progress!r}")
    with one_blas_thread():
        return _exact_branches(system, omega, opts, continuation, newton, period, progress)


def _exact_branches(system: System, omega: tuple[float, float], opts: ShootingOptions,
                    continuation: ContinuationOptions | None, newton: NewtonOptions | None,
                    period: int, progress: Any = None) -> list[ExactBranch]:
    lo, hi = omega
    problem = ShootingProblem(system, period=period)
    newton = newton or NewtonOptions()
    cont = continuation or ContinuationOptions()
    follower = _Follower(problem, (lo, hi), opts, cont, newton, progress)
    q0 = start_state(problem, lo, opts, newton, continuation=cont, bounds=(lo, hi))
    if q0 is None:
        return [ExactBranch(status=Status.START_FAILED, origin=f"Ω = {lo:.6g}",
                            message=f"no exact periodic orbit was found at Ω = {lo:.6g} (the flow settled "
                                    f"{2 * opts.settle_periods} periods, then Newton on the period map)")]
    first = follower.follow(q0, lo, 1.0)
    first.origin = f"Ω = {lo:.6g}"
    out = [first]
    top = float(first.omega.max()) if first.rows else lo
    if top < hi * (1.0 - 1e-9):
        q1 = start_state(problem, hi, opts, newton, continuation=cont, bounds=(lo, hi))
        if q1 is not None:
            below, known = [0], list(first.rows)

            def covered(pt: BranchPoint) -> str | None:
                """Below the frequencies the first branch reached: joined it, or a branch of its own
                (another orbit there: followed on, at most SEEDED_POINTS points)."""
                if pt.p >= top:
                    return None
                below[0] += 1
                if _joins(problem, pt, known, hi):
                    return "reached the frequencies already covered (joined the branch there)"
                if below[0] > SEEDED_POINTS:
                    return (f"the budget of {SEEDED_POINTS} points below the frequencies already covered was "
                            "spent (another orbit than the branch there)")
                return None

            second = follower.follow(q1, hi, -1.0, stop=covered)
            second.origin = f"Ω = {hi:.6g}"
            if second.rows:
                out.append(second)
    out.extend(_skipped_arms(follower, out))
    if opts.check is not None and period == 1 and any(b.rows for b in out):
        # one coordinate: the exact sweep costs ~10 ms a frequency, so it runs over the whole range
        # (as for the smooth laws: a stable attractor beside a stable computed one is found too);
        # a chain's flow costs 10–1000× that: only where no computed orbit is stable
        gaps = [(lo, hi)] if problem.size == 2 else _unstable_intervals(out, lo, hi)
        if gaps:
            out.extend(_missed_branches(follower, out, opts.check, gaps))
        if problem.size == 2:
            out.extend(_probed_branches(follower, out, opts.check))
    out.extend(_fill_gaps(follower, out, opts, newton, cont))
    if opts.locate:
        for b in out:
            follower.locate(b)
    _coverage(out, lo, hi)
    return out


def _joining(problem: ShootingProblem, known: list[ExactRow], w0: float, what: str) -> Any:
    """``also`` of :func:`_both_ways` for a branch started at ``w0`` beside the rows ``known``: a
    stop made afresh for each side, at the point budget (:data:`SEEDED_POINTS` a way) or where the
    branch joins those rows."""
    def joins() -> Any:
        seen = [0]

        def stop(pt: BranchPoint) -> str | None:
            seen[0] += 1
            if seen[0] > SEEDED_POINTS:
                return f"the budget of {SEEDED_POINTS} points a way of {what} was spent"
            return _joins(problem, pt, known, w0)
        return stop
    return joins


def _fill_gaps(follower: _Follower, found: list[ExactBranch], opts: ShootingOptions, newton: NewtonOptions,
               continuation: ContinuationOptions) -> list[ExactBranch]:
    """Branches through the frequencies no branch of ``found`` covers (:func:`_gaps`): an exact start
    in the middle of each (settled, then shot), followed both ways until it joins rows already
    computed or leaves the gap's neighbourhood (:data:`SEEDED_POINTS` points a way; at most
    :data:`MAX_ARMS` starts, the gaps taken again after each). Measured: a preload with stage friction whose seeded branches each
    spent their budget 1 % short of one another left Ω 0.988–1.0005 uncovered (exit 1)."""
    problem, out = follower.problem, []
    tried: list[float] = []
    for _ in range(MAX_ARMS):
        # the gaps left by what is computed so far: a start may cover a gap in part only
        # (measured: a start at Ω 0.400 in the gap 0.388–0.412 covered 0.3996–0.426)
        fresh = [(a, c) for a, c in _gaps([*found, *out], follower.lo, follower.hi) if 0.5 * (a + c) not in tried]
        if not fresh:
            break
        a, c = fresh[0]
        w = 0.5 * (a + c)
        tried.append(w)
        q = start_state(problem, w, opts, newton, continuation=continuation, bounds=(follower.lo, follower.hi))
        if q is None:
            continue
        joins = _joining(problem, [r for b in (*found, *out) for r in b.rows], w, "a branch started in a gap")
        branch = _both_ways(follower, [], q, w, f"a start in the uncovered Ω = {a:.6g} … {c:.6g}", locate=False,
                            also=joins)
        if len(branch.rows) >= 2:
            out.append(branch)
    return out


def _gaps(branches: list[ExactBranch], lo: float, hi: float) -> list[tuple[float, float]]:
    """The intervals of [lo, hi] that no piece of ``branches`` (nor a bridge over a grazing) spans."""
    spans: list[tuple[float, float]] = []
    for b in branches:
        k = 0
        for size in b.pieces or [len(b.rows)]:
            om = [r.omega for r in b.rows[k:k + size]]
            k += size
            if om:
                spans.append((min(om), max(om)))
        spans.extend(b.bridges)
    spans.sort()
    gaps, reach = [], lo
    for a, c in spans:
        if a > reach * (1.0 + 1e-9):
            gaps.append((reach, a))
        reach = max(reach, c)
    if reach < hi * (1.0 - 1e-9):
        gaps.append((reach, hi))
    return gaps


def _skipped_arms(follower: _Follower, found: list[ExactBranch]) -> list[ExactBranch]:
    """The arms the follower hopped onto that go on back beyond their hop (:attr:`_Follower.arms`),
    each followed back as a branch of its own until it leaves the range or joins rows already
    computed, or its last :data:`ARM_UNSTABLE_POINTS` points were all unstable (at most
    :data:`SEEDED_POINTS` points; at most :data:`MAX_ARMS` arms, arms found while following these
    included)."""
    out: list[ExactBranch] = []
    done = 0
    while follower.arms and done < MAX_ARMS:
        q, w, d = follower.arms.pop(0)
        done += 1
        known = [r for b in (*found, *out) for r in b.rows]
        seen, unstable = [0], [0]

        def stop(pt: BranchPoint, known: list[ExactRow] = known, w0: float = w) -> str | None:
            seen[0] += 1
            row = follower._made.get((pt.p, pt.q.tobytes()))
            unstable[0] = unstable[0] + 1 if row is not None and row.unstable_count else 0
            if seen[0] > SEEDED_POINTS:
                return f"the budget of {SEEDED_POINTS} points of an arm a hop skipped was spent"
            if unstable[0] > ARM_UNSTABLE_POINTS:
                return f"the arm a hop skipped stayed unstable for {ARM_UNSTABLE_POINTS} points"
            return _joins(follower.problem, pt, known, w0)

        branch = follower.follow(q, w, d, stop=stop)
        if len(branch.rows) >= 2:
            branch.origin = f"the arm a hop skipped at Ω = {w:.6g}"
            out.append(branch)
    follower.arms.clear()
    return out


def _accounted(row: ExactRow) -> bool:
    """The row is stable, or unstable only by multipliers below −1 (a period doubling: the motion
    there is the period-2 orbit born at it, ``subharmonics=True``, not a period-1 one missed)."""
    out = row.multipliers[np.abs(row.multipliers) > 1.0 + UNIT_TOL]
    return bool(np.all((np.abs(out.imag) <= 1e-9 * np.abs(out)) & (out.real < 0.0)))


def _unstable_intervals(branches: list[ExactBranch], lo: float, hi: float) -> list[tuple[float, float]]:
    """The Ω intervals of [lo, hi] (wider than :data:`MIN_GAP` of the range) where no stretch of
    two consecutive rows of any branch is stable or period-doubled (:func:`_accounted`)."""
    spans = sorted((min(a.omega, c.omega), max(a.omega, c.omega)) for b in branches
                   for a, c in zip(b.rows, b.rows[1:]) if _accounted(a) and _accounted(c))
    gaps: list[tuple[float, float]] = []
    reach = lo
    for a, c in spans:
        if a > reach:
            gaps.append((reach, a))
        reach = max(reach, c)
    if reach < hi:
        gaps.append((reach, hi))
    return [(a, c) for a, c in gaps if c - a > MIN_GAP * (hi - lo)]


def _explained(branches: list[ExactBranch], row: ExactRow, rms: FloatArray, rtol: float) -> bool:
    """Whether a stable stretch of one of ``branches`` passes through the row's Ω with every
    element's rms within ``rtol`` of ``rms`` (linear between the two rows around Ω)."""
    w = row.omega
    for b in branches:
        for a, c in zip(b.rows, b.rows[1:]):
            if a.unstable_count or c.unstable_count or not min(a.omega, c.omega) <= w <= max(a.omega, c.omega):
                continue
            t = 0.0 if a.omega == c.omega else (w - a.omega) / (c.omega - a.omega)
            est = (1.0 - t) * _row_rms(a) + t * _row_rms(c)
            if np.all(np.abs(est - rms) <= rtol * np.abs(rms)):
                return True
    return False


def _missed_branches(follower: _Follower, found: list[ExactBranch], check: SweepCheck,
                     gaps: list[tuple[float, float]]) -> list[ExactBranch]:
    """The branches through the period-1 attractors that an exact up/down sweep over ``gaps``
    settles on and ``found`` does not explain (module docstring)."""
    from ._steady import SteadyStateOptions
    from ._time_sweep import time_sweep

    problem = follower.problem
    width = follower.hi - follower.lo
    settle = SteadyStateOptions(max_periods=check.max_periods, max_period_multiple=1, record_periods=1)
    out: list[ExactBranch] = []
    for a, c in gaps:
        points = max(3, math.ceil(check.points * (c - a) / width))
        sweep = time_sweep(problem.system, omega=(a, c), points=points, direction="both", options=settle)
        settled = [(float(sweep.omega[j]), np.asarray(sweep.state0[j], dtype=float))
                   for j in range(len(sweep.omega)) if int(sweep.period[j]) == 1]
        if problem.size == 2:
            settled += _refined(problem, sweep, settle, REFINE_BUDGET * check.points)
            settled += _from_rest(problem, sweep)
        for w, state in settled:
            if len(out) >= check.max_branches:
                break
            _seed(follower, found, out, state, w, check, f"the attractor an exact sweep settled on at Ω = {w:.6g}")
    return out


def _from_rest(problem: ShootingProblem, sweep: Any) -> list[tuple[float, FloatArray]]:
    """The first frequency of each sweep direction starts from rest: its transient is the longest
    (measured: a random preload whose run-up from rest at Ω_min settles after 1424 periods on a
    stable orbit, μ = −0.96, that the check's 200 periods did not see). Where it did not settle, the
    simulation goes on from where it stopped up to the default budget of
    :class:`~rattle.analysis.SteadyStateOptions`. Returns (Ω, the orbit's state) where it settled
    on a period-1 orbit."""
    from ._steady import SteadyStateOptions, steady_state

    out: list[tuple[float, FloatArray]] = []
    budget = SteadyStateOptions().max_periods
    for d in sweep.directions:
        one = sweep.select(d)  # its first row started from rest
        spent = int(one.periods[0])
        if int(one.period[0]) != 0 or spent >= budget or not np.all(np.isfinite(one.final_state[0])):
            continue
        w = float(one.omega[0])
        more = SteadyStateOptions(max_periods=budget - spent, max_period_multiple=1, record_periods=1)
        try:
            s = steady_state(problem.system, w, x0=np.asarray(one.final_state[0], dtype=float), options=more,
                             integrator=problem.integrator)
        except RattleError:
            continue
        if s.period == 1:
            out.append((w, np.asarray(s.state0, dtype=float)))
    return out


def _refined(problem: ShootingProblem, sweep: Any, settle: Any, budget: int) -> list[tuple[float, FloatArray]]:
    """The period-1 motions the sweep settles on between two of its frequencies where one of the
    two did not settle on a period-1 orbit (non-periodic, sub-harmonic or failed): a window of
    periodic motion inside a chaotic or sub-harmonic region is often narrower than the sweep's
    spacing (measured: a preload with stage friction whose run-ups settle on a stable single-sided
    orbit, |μ| 0.993, over Ω ≈ 0.425–0.445 between non-periodic motions, missed at 16 frequencies a
    way over Ω 0.3–2). Inside each such step the sweep goes on at evenly spaced frequencies as a
    finer run-up or run-down would, the state carried from the step's first frequency: ``budget``
    frequencies a direction shared among its steps (at most :data:`REFINE_POINTS` a step). Returns
    (Ω, the orbit's state) of each that settled on a period-1 orbit."""
    from ._steady import steady_state

    out: list[tuple[float, FloatArray]] = []
    for d in sweep.directions:
        one = sweep.select(d)  # its rows in sweep order
        steps = [j for j in range(len(one) - 1)
                 if not (one.period[j] == 1 and one.period[j + 1] == 1) and np.all(np.isfinite(one.final_state[j]))]
        if not steps:
            continue
        inner = max(1, min(REFINE_POINTS, budget // len(steps)))
        for j in steps[: budget // inner]:
            x = np.asarray(one.final_state[j], dtype=float)
            w0, w1 = float(one.omega[j]), float(one.omega[j + 1])
            for i in range(1, inner + 1):
                w = w0 + (w1 - w0) * i / (inner + 1)
                try:
                    s = steady_state(problem.system, w, x0=x, options=settle, integrator=problem.integrator)
                except RattleError:  # the flow failed here: the finer sweep of this step ends
                    break
                x = np.asarray(s.final_state, dtype=float)
                if s.period == 1:
                    out.append((w, np.asarray(s.state0, dtype=float)))
    return out


def _probed_branches(follower: _Follower, found: list[ExactBranch], check: SweepCheck) -> list[ExactBranch]:
    """The period-1 attractors next to the unstable orbits of ``found``: on each stretch of rows
    unstable by a multiplier that is not a period doubling (:func:`_accounted`; the longest
    :data:`PROBES` stretches), the middle row's state pushed both ways along the eigenvector of its
    largest multiplier (:data:`PROBE_PUSH` of the length scale) and simulated until it settles;
    a period-1 attractor no stable stretch explains is continued as in :func:`_missed_branches`.
    An orbit unstable there leaves for an attractor next to it, wherever the sweep's frequencies
    fall (measured: preloads whose run-ups settled on orbits of 0.0299 and 0.051 rms beside
    unstable rows of |μ| 10 and 2.4, in windows narrower than the sweep's spacing)."""
    from ._steady import SteadyStateOptions, steady_state

    problem = follower.problem
    s = problem.length_scale
    settle = SteadyStateOptions(max_periods=check.max_periods, max_period_multiple=1, record_periods=1)
    stretches: list[list[ExactRow]] = []
    for b in found:
        run: list[ExactRow] = []
        for r in [*b.rows, None]:
            if r is not None and not _accounted(r):
                run.append(r)
            elif run:
                stretches.append(run)
                run = []
    stretches.sort(key=len, reverse=True)
    lo, hi = follower.lo, follower.hi
    # the middle rows of the longest stretches, and the rows at the range's ends of any: at an end
    # only what is already there is known (measured: a random preload whose run-down settles at
    # Ω_min on a stable orbit of rms 0.03103 next to the unstable 0.03111 the branch had there)
    rows = [run[len(run) // 2] for run in stretches[:PROBES]]
    rows += [r for run in stretches for r in (run[0], run[-1]) if min(abs(r.omega - lo), abs(r.omega - hi)) <= 1e-9 * hi]
    out: list[ExactBranch] = []
    for row in {id(r): r for r in rows}.values():
        mu, vecs = np.linalg.eig(row.M)
        v = np.real(vecs[:, int(np.argmax(np.abs(mu)))])
        size = float(np.max(np.abs(v / s)))
        if not size > 0.0:
            continue
        for sign in (1.0, -1.0):
            if len(out) >= check.max_branches:
                return out
            z0 = row.q + sign * PROBE_PUSH * v / size
            try:
                settled = steady_state(problem.system, row.omega, x0=z0, options=settle, integrator=problem.integrator)
            except RattleError:  # the push left the flow's reach: no attractor from there
                continue
            if settled.period != 1:
                continue
            _seed(follower, found, out, np.asarray(settled.state0, dtype=float), row.omega, check,
                  f"the attractor next to the unstable orbit at Ω = {row.omega:.6g}")
    return out


def _seed(follower: _Follower, found: list[ExactBranch], out: list[ExactBranch], state: FloatArray, w: float,
          check: SweepCheck, origin: str) -> None:
    """The branch through the orbit shot from a settled ``state`` at ``w``, followed both ways
    until it joins rows already computed (:data:`SEEDED_POINTS` points a way), appended to ``out``
    — unless the orbit is unstable or a stable stretch of ``found`` or ``out`` explains it."""
    problem = follower.problem
    res = solve_fixed(problem, state, w, follower.newton)
    if not res.converged:
        return
    row = _row(problem, res.q, w)
    if row.unstable_count or _explained([*found, *out], row, _row_rms(row), check.rtol):
        return
    joins = _joining(problem, [r for b in (*found, *out) for r in b.rows], w, "a branch found by the sweep")

    branch = _both_ways(follower, [], res.q, w, origin, locate=False, also=joins)
    if len(branch.rows) >= 2:
        out.append(branch)


def _coverage(branches: list[ExactBranch], lo: float, hi: float) -> None:
    """A primary branch that ended early (a stall, a piece that could not start past a grazing, or
    it turned back and left the range at Ω_min) while the branches together cover the range is a
    success: its status says so, its message keeps why it ended; else the uncovered frequencies are
    named in its message."""
    gaps = _gaps(branches, lo, hi)
    first = branches[0]
    ended_early = not first.status.success or first.status is Status.RETURNED  # turned back: the top not reached
    started = first.status is not Status.START_FAILED or len(first.rows) >= 2
    if not gaps and ended_early and started:
        first.message = f"{first.message}; the range is covered with the other branches"
        first.status = Status.SUCCESS
    elif gaps:
        first.message += "; not covered: " + ", ".join(f"Ω = {a:.6g} … {c:.6g}" for a, c in gaps)


#: A period-p orbit whose one-period map returns within this scaled distance is a period-1 orbit
#: run p times: the sub-harmonic branch rejoined a period-1 branch.
REJOIN_TOL = 1e-7
#: A period-2p seed counts (it is not the period-p orbit run twice) when its p-period map moves it
#: by more than this share of the orbit's peak-to-peak (scaled by the length scale L).
SEED_GAP = 1e-3
#: ... and when it lies within this share of the orbit's peak-to-peak of the period-p orbit (scaled
#: max-norm): the orbit born at the doubling, not another one Newton reached from a push (measured:
#: from a push at the end of a period-4 branch, an unrelated period-8 orbit with |μ| ≈ 500).
SEED_REACH = 0.5
#: The most branches :func:`subharmonic_branches` follows from period doublings in one call (the
#: map's branch budget, :class:`~rattle.analysis.AttractorSearch` ``max_branches``).
DOUBLING_BRANCHES = 16
#: Newton iterations of the shooting of a pushed start over 2p forcing periods.
SEED_ITERATIONS = 40


def doubled_orbit(half: ShootingProblem, omega: float, state: FloatArray, newton: NewtonOptions) -> FloatArray | None:
    """z(0) of an exact orbit of period 2p next to the exact orbit of period p = ``half.period``
    through ``state`` at ``omega``, one of whose multipliers lies near −1: the period-p orbit
    (Newton on its period map from ``state``) pushed along the eigenvector of its negative real
    multiplier nearest −1 (:func:`~._period_two.pushed_starts`: by 2 %, 10 % and 30 % of its
    largest coordinate peak-to-peak, either way) and shot over 2p forcing periods; the first
    converged orbit whose p-period defect R_p(z(0), Ω) = (φ_{p 2π/Ω}(z(0)) − z(0)) / s exceeds
    :data:`SEED_GAP` × (peak-to-peak / L) — not the period-p orbit run twice — and whose z(0) lies
    within :data:`SEED_REACH` × (peak-to-peak / L) of the period-p orbit's. None when none is."""
    q = damped_newton(half, np.asarray(state, dtype=float), omega, newton, iterations=30)
    if q is None:
        return None
    double = ShootingProblem(half.system, period=2 * half.period, integrator=half.integrator)
    try:
        row = _row(half, q, omega)
        n = half.size // 2
        x = np.asarray(row.trajectory.states(np.linspace(0.0, half.orbit_period(omega), 64 * half.period + 1)),
                       dtype=float)[:, :n]
    except FLOW_FAILURES:
        return None
    L = float(half.length_scale[0])
    size = max(float(np.max(np.ptp(x, axis=0))), 1e-12 * L)
    for z0 in pushed_starts(row.M, q, half.state_scale(omega), size, L):
        z2 = damped_newton(double, z0, omega, newton, iterations=SEED_ITERATIONS)
        if z2 is None:
            continue
        try:
            gap = float(np.max(np.abs(half.residual(z2, omega))))
        except FLOW_FAILURES:
            continue
        if gap > SEED_GAP * size / L and float(np.max(np.abs((z2 - q) / half.length_scale))) <= SEED_REACH * size / L:
            return z2
    return None


def subharmonic_branches(
    system: System,
    parents: list[Any],
    omega: tuple[float, float],
    options: ShootingOptions,
    continuation: ContinuationOptions | None,
    newton: NewtonOptions | None,
    build: Any,
    *,
    first: int = 1,
    max_period: int = MAX_PERIOD,
) -> list[Any]:
    """The branches of period 2p born at the period doublings located on the exact branches
    ``parents`` (responses with ``omega``, ``states``, ``bifurcation`` and ``period`` p), 2p ≤
    ``max_period``, recursively: each branch found is a parent too. At a doubling the exact
    period-2p orbit next to the row on either side of the located point (:func:`doubled_orbit`)
    is followed by exact shooting continuation over 2p forcing periods both ways
    (:func:`_both_ways`) until it rejoins an orbit of a period dividing 2p (:func:`_rejoin_stop`)
    or leaves the range. ``build(branch, number, period)`` makes each branch's response
    (numbered from ``first``); a doubling at an end of a branch of period 2p already found (its
    other end) starts none; at most :data:`DOUBLING_BRANCHES` branches."""
    lo, hi = omega
    newton = newton or NewtonOptions()
    cont = continuation or ContinuationOptions()
    out: list[Any] = []
    queue = [p for p in parents if 2 * int(p.period) <= max_period and p.states is not None]
    with one_blas_thread():
        integ = None
        while queue:
            parent = queue.pop(0)
            p = int(parent.period)
            if integ is None:
                integ = ShootingProblem(system).integrator
            half = ShootingProblem(system, period=p, integrator=integ)
            problem = ShootingProblem(system, period=2 * p, integrator=integ)
            shorter = [ShootingProblem(system, period=d, integrator=integ) for d in range(1, 2 * p) if 2 * p % d == 0]
            follower = _Follower(problem, (lo, hi), options, cont, newton)
            labels = np.asarray(parent.bifurcation, dtype=object)
            for i in np.flatnonzero(labels == "period_doubling"):
                if len(out) >= DOUBLING_BRANCHES:
                    break
                w_pd = float(parent.omega[i])
                if any(int(b.period) == 2 * p and abs(w_pd - float(b.omega[j])) <= 1e-3 * w_pd
                       for b in out if len(b.omega) for j in (0, -1)):
                    continue
                z2 = None
                for j in (i + 1, i - 1):
                    if 0 <= j < len(parent.omega) and np.all(np.isfinite(parent.states[j])):
                        z2 = doubled_orbit(half, float(parent.omega[j]), parent.states[j], newton)
                        if z2 is not None:
                            w0 = float(parent.omega[j])
                            break
                if z2 is None:
                    continue
                branch = _both_ways(follower, shorter, z2, w0,
                                    f"period doubling of branch {int(parent.branch)} at Ω = {w_pd:.6g}", options.locate)
                branch.period = 2 * p
                if len(branch.rows) >= 2:
                    part = build(branch, first + len(out), 2 * p)
                    out.append(part)
                    if 4 * p <= max_period:
                        queue.append(part)
    return out


def _rejoin_stop(shorter: list[ShootingProblem], period: int) -> Any:
    """The stop of one side of a branch of period p ≥ 2: it has rejoined an orbit of a period d
    dividing p (``shorter``: the period-d problems) when the d-period map's scaled defect falls
    below :data:`REJOIN_TOL`, or, for d = p/2, flips sign (past the period doubling the branch
    would go on along its own copy shifted by d forcing periods: a closed loop). The points found
    on an orbit of period d are kept in its ``shorter_points`` ((Ω, z(0) bytes)): they are no rows
    of the period-p branch."""
    prev: dict[int, FloatArray] = {}
    shorter_points: set[tuple[float, bytes]] = set()

    def rejoined(pt: BranchPoint) -> str | None:
        for k, once in enumerate(shorter):
            r = once.residual(pt.q, pt.p)
            if not np.all(np.isfinite(r)):
                continue
            # the sign flip marks a period doubling of the period-d orbit (d = p/2) only
            flipped = 2 * once.period == period and k in prev and float(r @ prev[k]) < 0.0
            prev[k] = r
            on_shorter = float(np.max(np.abs(r))) < REJOIN_TOL
            if on_shorter:  # an orbit of period d, not p: no row of this branch
                shorter_points.add((pt.p, pt.q.tobytes()))
            if flipped or on_shorter:
                return f"the period-{period} branch rejoined a period-{once.period} branch near Ω = {pt.p:.6g}"
        return None

    rejoined.shorter_points = shorter_points  # type: ignore[attr-defined]
    return rejoined


#: A branch followed from an orbit has closed on itself (an isola) when it crosses the orbit's
#: frequency again within this scaled distance of one of the orbit's section points (the
#: continuation's chords put the interpolated state off the branch by (step)² × curvature).
CLOSE_TOL = 1e-2
CLOSED = "the branch closed on itself (an isola)"
#: ... after it has left the start: moved this far in Ω (relative), or 0.1 (scaled) in state.
LEAVE_OMEGA = 1e-3


def _close_stop(problem: ShootingProblem, z0: FloatArray, w0: float, inner: Any) -> Any:
    """``inner`` (a stop or None), and the stop of a branch that comes back to its start: where
    it crosses Ω = ``w0`` again after leaving it, the state interpolated there lies within
    :data:`CLOSE_TOL` (scaled) of a section point z(m 2π/Ω), m = 0 … p − 1, of the orbit through
    ``z0`` (the same orbit, or it shifted by m forcing periods: the loop is traced from there on
    again)."""
    s = problem.length_scale
    T = 2.0 * math.pi / w0
    points = [np.asarray(z0, dtype=float)]
    try:
        for m in range(1, problem.period):
            points.append(np.asarray(problem.integrator.propagate(points[-1], (m - 1) * T, m * T, w0).state1,
                                     dtype=float))
    except Exception:  # noqa: BLE001 - the start itself is enough to recognise the loop
        pass
    state: dict[str, Any] = {"prev": None, "left": False}

    def closed(pt: BranchPoint) -> str | None:
        reason = None if inner is None else inner(pt)
        if reason:
            return reason
        prev, state["prev"] = state["prev"], pt
        if abs(pt.p - w0) > LEAVE_OMEGA * w0 or min(float(np.max(np.abs((pt.q - z) / s))) for z in points) > 0.1:
            state["left"] = True
        if prev is None or not state["left"] or (prev.p - w0) * (pt.p - w0) > 0.0:
            return None
        t = 0.0 if pt.p == prev.p else (w0 - prev.p) / (pt.p - prev.p)
        z = (1.0 - t) * prev.q + t * pt.q
        if min(float(np.max(np.abs((z - zm) / s))) for zm in points) <= CLOSE_TOL:
            return CLOSED
        return None

    return closed


def _both_ways(follower: _Follower, shorter: list[ShootingProblem], z0: FloatArray, w0: float, origin: str,
               locate: bool, close: bool = False, also: Any = None) -> ExactBranch:
    """The branch through the orbit z(0) = ``z0`` at ``w0`` followed down and up in Ω (each side
    stopped where it rejoins a shorter period, :func:`_rejoin_stop`; with ``close`` also where it
    comes back to its start, :func:`_close_stop`: an isola is then followed once, down from
    ``w0`` round to it; and where ``also()``, a stop made afresh for each side, says so), joined in
    order of the continuation (down reversed, then up; the pieces of both sides kept, the two
    through ``w0`` one piece); its special points located with ``locate``."""
    period = follower.problem.period
    marks: list[set[tuple[float, bytes]]] = []  # each side's points on an orbit of a shorter period

    def stop() -> Any:
        inner = _rejoin_stop(shorter, period) if shorter else None
        if inner is not None:
            marks.append(inner.shorter_points)
        inner = _close_stop(follower.problem, z0, w0, inner) if close else inner
        extra = also() if also is not None else None
        if inner is None or extra is None:
            return inner if extra is None else extra
        return lambda pt: inner(pt) or extra(pt)

    down = follower.follow(z0, w0, -1.0, stop=stop())
    if close and down.message == CLOSED:
        up = ExactBranch(rows=down.rows[:1], pieces=[1])
    else:
        up = follower.follow(z0, w0, 1.0, stop=stop())
    dropped = set().union(*marks)
    for side in (down, up):  # an end on an orbit of a shorter period is no row of this branch
        if len(side.rows) > 1 and (side.rows[-1].omega, side.rows[-1].q.tobytes()) in dropped:
            side.rows.pop()
            if side.pieces:
                side.pieces[-1] -= 1
    branch = ExactBranch(origin=origin, bridges=[*down.bridges, *up.bridges])
    branch.rows = list(reversed(down.rows[1:])) + up.rows
    sides = [*reversed(down.pieces or [len(down.rows)]), *(up.pieces or [len(up.rows)])]
    if down.rows and up.rows:
        mid = len(down.pieces or [0]) - 1  # the seed row is in both sides' first pieces: once, in one piece
        sides[mid:mid + 2] = [sides[mid] + sides[mid + 1] - 1]
    branch.pieces = [n for n in sides if n > 0]
    branch.status = Status.SUCCESS
    branch.message = "; ".join(m for m in (down.message, up.message) if m)
    if locate:
        follower.locate(branch)
    return branch


def branch_through(
    system: System,
    state: FloatArray,
    omega0: float,
    period: int,
    omega: tuple[float, float],
    options: ShootingOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    origin: str = "",
) -> ExactBranch:
    """The exact branch of period ``period`` (T = p 2π/Ω) through the orbit z(0) = ``state`` at
    ``omega0`` (an attractor found by simulation, say), followed both ways within ``omega`` =
    (Ω_min, Ω_max) by exact shooting continuation (module docstring: grazings hopped, special
    points located). A branch of period p ≥ 2 ends where it rejoins an orbit of a period d
    dividing p: the d-period map's defect R_d(z(0), Ω) = (φ_{d 2π/Ω}(z(0)) − z(0)) / s falls
    below :data:`REJOIN_TOL` (or flips sign, d = p/2); a branch that comes back to the orbit (an
    isola) is followed once round (:data:`CLOSE_TOL`)."""
    opts = ShootingOptions() if options is None else options
    if not isinstance(opts, ShootingOptions):
        raise TypeError(f"`options` must be a ShootingOptions, got {opts!r}")
    lo, hi = omega
    with one_blas_thread():
        problem = ShootingProblem(system, period=period)
        shorter = [ShootingProblem(system, period=d, integrator=problem.integrator)
                   for d in range(1, period) if period % d == 0]
        follower = _Follower(problem, (lo, hi), opts, continuation or ContinuationOptions(), newton or NewtonOptions())
        branch = _both_ways(follower, shorter, np.asarray(state, dtype=float), float(omega0), origin, opts.locate,
                            close=True)
        branch.period = int(period)
        return branch


__all__ = ["DOUBLING_BRANCHES", "ExactBranch", "ExactRow", "ShootingOptions", "branch_through", "doubled_orbit", "exact_branches",
           "start_state", "subharmonic_branches"]
