"""Frequency response of a chain with Coulomb friction: regularised HB, checked exactly row by row.

For the chain x'' + C x' + K x + Σ_e b_e [f_e(δ_e) + r_e(δ_e) sgn δ_e'] = F(t)
(:class:`~rattle.model.System` with its elements' whole laws, n coordinates, m elements, δ_e = a_e · x), as
:mod:`rattle.analysis._nonsmooth` does for the single equation:

1. the regularised harmonic balance (:class:`~rattle.hb.RegularisedSystemBalance`, steps of
   relative width ε, H harmonics) is continued over Ω by pseudo-arclength
   (:class:`~rattle.continuation.ContinuationStepper`) from a solution at Ω_min found by a
   homotopy in ε from wide steps (ε = 0.1, started from the linearised chain's steady state,
   :meth:`~rattle.hb.RegularisedSystemBalance.linear_solution`, by Newton, and by Newton with
   step halving where that wanders; last, from the spectrum of the exact orbit simulated and shot
   from the linear solution's state);
2. every continuation point is checked against the exact flow: Newton shooting on the
   event-driven integrator (:func:`~rattle.timeint.shoot_friction_orbit`: crossings and sticking
   exact (Filippov), the monodromy with saltation matrices) from the HB orbit's state at t = 0.
   The two are one orbit (``matched``) when the shooting converged and every element's δ_e(t)
   stays within ``match`` × (the HB δ_e's peak-to-peak) of the HB's on 64 samples of the period.
   Where the shooting fails, or an element sticks or locks part of the period (on the flow from
   the HB state or on the exact orbit) and that check fails, the row is checked at the limit of
   its regularisation: the HB is followed at fixed Ω down the ε ladder (:func:`_ladder`, the
   rungs kept for step 3), the exact flow is shot from the HB state at the ladder's end, and the
   two are one orbit when every δ_e(t) stays within ``match`` of that HB's, an element held part
   of the period measured on the chain's scale (the largest HB δ peak-to-peak): its regularised
   deflection is of the order of the steps' width (at a lock ε_δ artanh(τ/J), a few ε_δ where the
   exact δ_e is 0), so its own peak-to-peak is no scale to measure by. The exact orbit is then
   the limit ε → 0 of the HB's, unless the ladder left the row's branch (a fold in ε; Newton
   then finds another orbit on the way down): so the elements the exact orbit does not hold must
   also stay within :data:`LADDER_GUARD` × ``match`` of the HB orbit at the row's own ε.
   A row still unmatched after the whole branch is checked is shot again from the exact orbit of
   the nearest matched row on either side (a step away in Ω: near a fold the HB's error at ε can
   move its own state out of Newton's reach) and compared with its HB as above.
   The exact orbit gives the answer (every element's rms, mean, stick fraction; the 2n
   multipliers); the HB's own values stand beside them: its rms and its multipliers. Those are,
   by ``stability`` (:class:`~rattle.analysis.RegularisationOptions`), ``"saltation"``: the
   non-smooth monodromy (saltation matrices) of one period of the exact flow from the HB state
   (the exact orbit's when that flow cannot be followed), or ``"regularised"``: the smooth
   monodromy of the regularised chain linearised along the HB orbit
   (:func:`~rattle.stability.regularised_system_multipliers`; it reads the HB series only);
3. where a matched row's HB rms misses the exact one by more than ``refine`` on any element
   (relative), the regularisation is continued at that row towards its limit (ε down to
   ``limit_eps``, H up to ``limit_harmonics``, and on to ``deep_eps`` if asked;
   :func:`~rattle.analysis._regularisation.regularisation_limit`): the rms at the smallest ε and
   Richardson's ε → 0 value (where the last three rungs are linear in ε) are kept per element,
   and the HB orbit's multipliers are found again from the state of the smallest ε (the
   stability of the HB at its limit: at ε = 0.01 a sticking orbit's state is off by the
   regularisation, and so is the monodromy of the flow from it).

Cost: one continuation of n(2H + 1) unknowns (a dense Jacobian) plus two exact integrations of
a period (the shooting, a few ms per Newton step, and the HB orbit's monodromy) per point, and a
ladder per refined row. Where an element sticks the whole period the exact orbits form a family
(its stuck deflection is free within the friction band; a multiplier 1, counted as inside the
unit circle up to :data:`UNIT_TOL`) while the regularised HB picks one (its creep balance): the
shooting may end on another member, and the row is then left unmatched. A row checked at the
limit costs its ladder (a few Newton solves per rung; shared with step 3). Not resolved: grazing (a tangential touch of a breakpoint or of zero
relative velocity) and stuck sets closing a loop (the exact integrator's limits); such rows are
left unmatched.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from .._typing import FloatArray
from .._validate import check_range
from ..continuation import ContinuationOptions, ContinuationStepper, NewtonOptions
from ..errors import ConvergenceError, RattleError, Status
from ..hb import HBOptions, RegularisedSystemBalance
from ..model import System
from ..results import FrictionCheck
from ..stability import regularised_system_multipliers
from ..timeint import ExactIntegrator, FrictionOrbit, FrictionTrajectory, shoot_friction_orbit
from ..timeint import CROSSING, FLOW_FAILURES, LOCK, STICK, monodromy_multipliers
from ._exact_branch import ExactBranch, ShootingOptions, exact_branches
from ._held_limit import held_limit
from ._regularisation import (
    RegularisationLimit,
    RegularisationOptions,
    RegularisationStep,
    regularisation_limit,
)

#: ε when no options are given: a chain's velocity width ε L ω_n takes its highest natural
#: frequency, ~10× wider against an element's own twist rates than on the single equation; 0.001
#: meets 0.5 % at ε away from special points (measured in docs/nonsmooth.md).
CHAIN_REGULARISATION = 0.001
#: ε when no options are given and an element's law jumps (a preload): the jump's position step
#: ε L is then as narrow as the velocity step, and the continuation crawls (measured on the
#: benchmark chain with a lock-up clutch, 0.4 … 1 ω_n at H = 64: 2187 steps in 35 s at ε = 0.01,
#: 17554 steps in 269 s at 0.003, and at 0.001 the 20000-step budget ran out by 0.45 ω_n).
JUMP_CHAIN_REGULARISATION = 0.01


def chain_regularisation(system: System) -> float:
    """The default ε of a chain with friction or jumps on its elements:
    :data:`JUMP_CHAIN_REGULARISATION` when a law jumps, else :data:`CHAIN_REGULARISATION`."""
    return JUMP_CHAIN_REGULARISATION if system.has_jumps else CHAIN_REGULARISATION


def chain_options(system: System) -> RegularisationOptions:
    """The settings of a chain with friction or jumps when none are given: ε =
    :func:`chain_regularisation`, and the ladder keeping its H (``limit_harmonics`` = ``harmonics``):
    each doubling multiplies a dense Jacobian of n(2H + 1) unknowns, at n = 3 about 40 s a row at
    H = 256 against 2 s at H = 64 (measured in docs/nonsmooth.md), and the benchmark chains meet
    0.5 % away from special points with H fixed."""
    base = RegularisationOptions(regularisation=chain_regularisation(system))
    return dataclasses.replace(base, limit_harmonics=base.harmonics)


#: Samples per period on which the exact and the HB orbits are compared.
MATCH_SAMPLES = 64
#: |μ| up to 1 + UNIT_TOL counts as inside the unit circle: an element stuck the whole period
#: gives a neutral multiplier 1 (a family of orbits, its stuck deflection free within the band).
UNIT_TOL = 1e-8


def friction_balance_factory(system: System, period: int = 1) -> Callable[[float, int], RegularisedSystemBalance]:
    """``make(ε, H)``: the regularised HB of the chain ``system`` at relative width ε with H
    harmonics, of solution period ``period`` forcing periods (one problem built per H; another ε
    shares its matrices)."""
    built: dict[int, RegularisedSystemBalance] = {}

    def make(eps: float, H: int) -> RegularisedSystemBalance:
        pb = built.get(H)
        if pb is None:
            pb = built[H] = RegularisedSystemBalance(system, regularisation=eps, options=HBOptions(harmonics=H),
                                                     period=period)
        return pb if pb.eps == eps else pb.with_regularisation(eps)

    return make


def _hb_flow(integ: ExactIntegrator, z0: FloatArray, omega: float, period: int = 1) -> FrictionTrajectory | None:
    """``period`` forcing periods of the exact flow from the state ``z0`` at t = 0 (the HB orbit's,
    or a settled one); None when it cannot be followed (:data:`FLOW_FAILURES`)."""
    try:
        return integ.propagate(z0, 0.0, period * 2.0 * math.pi / omega, omega)
    except FLOW_FAILURES:
        return None


def _hb_multipliers(flow: FrictionTrajectory | None) -> np.ndarray | None:
    """The HB orbit's 2n multipliers, largest modulus first: the non-smooth monodromy (saltation
    matrices at every switching) of one period of the exact flow from its state (:func:`_hb_flow`);
    None without that flow."""
    if flow is None:
        return None
    mu = monodromy_multipliers(flow.sensitivity)
    return mu if np.all(np.isfinite(mu)) else None


#: An element stuck at least this fraction of one period of the exact flow from the HB state is
#: held at the HB's mean deflection when the plain shooting finds no matching orbit.
HOLD_FRACTION = 0.9


def _holds_part(flow: FrictionTrajectory | None, orbit: FrictionOrbit | None) -> bool:
    """Whether an element sticks or locks some of the period on ``flow`` (:func:`_hb_flow`) or on
    the converged exact ``orbit``."""
    trajs = [flow] + ([orbit.trajectory] if orbit is not None and orbit.converged else [])
    return any(tr is not None and bool(np.any(tr.stick_time() > 0.0)) for tr in trajs)


def _stuck_elements(flow: FrictionTrajectory | None) -> list[int]:
    """The elements that friction holds at least :data:`HOLD_FRACTION` of the period on ``flow``
    (:func:`_hb_flow`). Where an element sticks the whole period the exact periodic orbits form a
    family (its stuck deflection is free within the friction band; a multiplier 1). A lock at a
    jump of the law does not count: its deflection is the jump's, one orbit, no family."""
    if flow is None:
        return []
    frac = (flow.stick_time() - flow.lock_time()) / (flow.t1 - flow.t0)
    return [int(e) for e in np.flatnonzero(frac >= HOLD_FRACTION)]


def _held_elements(flow: FrictionTrajectory | None, E: FloatArray) -> dict[int, float]:
    """{element: the HB's mean deflection (row of the element series ``E``)} of the
    :func:`_stuck_elements` on ``flow``: the regularised HB picks one member of their family by
    its creep balance, and the exact orbit checked against it is the member with the same stuck
    deflection (:func:`~rattle.timeint.shoot_friction_orbit` ``hold``)."""
    return {e: float(E[e][0]) for e in _stuck_elements(flow)}


def _hb_samples(pb: RegularisedSystemBalance, E: FloatArray, omega: float, t: FloatArray) -> FloatArray:
    """δ_e(t) of the HB orbit with element series ``E`` (m, 2H+1) at forcing frequency Ω = ``omega``
    at the times ``t``, shape (t.size, m)."""
    w = pb.base_frequency(omega)
    return np.stack([pb.basis.evaluate(E[e], w, t) for e in range(E.shape[0])], axis=1)


def _departures(traj: FrictionTrajectory, d_hb: FloatArray, t: FloatArray, size: FloatArray) -> FloatArray:
    """Per element, the largest departure of the exact δ_e(t) on ``traj`` from the HB's samples
    ``d_hb`` at ``t``, relative to ``size`` (the HB δ_e's peak-to-peak), shape (m,)."""
    return np.max(np.abs(traj.element_samples(t)[0] - d_hb), axis=0) / size


def _gap_at_limit(make: Callable[[float, int], RegularisedSystemBalance], omega: float, last: RegularisationStep,
                  traj: FrictionTrajectory, t: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Per element, the largest departure of the exact δ_e(t) on ``traj`` from the HB's at the
    ladder's rung ``last`` (absolute), and that HB δ_e's peak-to-peak, (m,) each."""
    pb = make(last.eps, last.harmonics)
    E = pb.element_series(last.q)
    size = np.maximum(np.ptp(pb.basis.synthesize(E), axis=1), 1e-12 * pb.length_scale)
    return _departures(traj, _hb_samples(pb, E, omega, t), t, np.ones_like(size)), size


def _departure_at_limit(make: Callable[[float, int], RegularisedSystemBalance], omega: float, lad: RegularisationLimit,
                        traj: FrictionTrajectory, t: FloatArray, elements: list[int]) -> float:
    """The largest departure of the exact δ_e(t) (``elements``) from the HB's at the end of the ε
    ladder ``lad`` (:func:`_ladder`), relative to the HB δ_e's peak-to-peak."""
    gap, size = _gap_at_limit(make, omega, lad.last, traj, t)
    return float(np.max(gap[elements] / size[elements])) if elements else 0.0


def _match_at_limit(make: Callable[[float, int], RegularisedSystemBalance], system: System,
                    integ: ExactIntegrator, omega: float, lad: RegularisationLimit, t: FloatArray,
                    d_hb: FloatArray, size_hb: FloatArray, match: float) -> tuple[FrictionTrajectory, float] | None:
    """The exact orbit shot from the HB state at the end of the ε ladder ``lad`` and its departure
    from that HB orbit (:func:`_held_scale`); None when the shooting fails. The departure is inf
    when an element the exact orbit does not hold departs from the HB orbit at the row's own ε
    (samples ``d_hb`` at ``t``, peak-to-peak ``size_hb``) by more than :data:`LADDER_GUARD` ×
    ``match`` of that peak-to-peak: the ladder then left the row's branch (a fold in ε: the
    regularised orbit at ε has no limit there, and Newton found another orbit on the way down)."""
    last = lad.last
    pb = make(last.eps, last.harmonics)
    try:
        orbit = shoot_friction_orbit(system, omega, pb.state_at_zero(last.q, omega), period=pb.period,
                                     integrator=integ, max_iterations=30)
    except FLOW_FAILURES:
        return None
    if not orbit.converged:
        return None
    return orbit.trajectory, _distance_at_limit(make, omega, last, orbit.trajectory, t, d_hb, size_hb, match)


def _distance_at_limit(make: Callable[[float, int], RegularisedSystemBalance], omega: float, last: RegularisationStep,
                       traj: FrictionTrajectory, t: FloatArray, d_hb: FloatArray, size_hb: FloatArray,
                       match: float) -> float:
    """The departure of the exact orbit ``traj`` from the HB orbit at the ladder's rung ``last``
    (:func:`_held_scale`), or inf when an element the exact orbit does not hold departs from the
    HB orbit at the row's own ε (samples ``d_hb`` at ``t``, peak-to-peak ``size_hb``) by more than
    :data:`LADDER_GUARD` × ``match`` of that peak-to-peak (:func:`_match_at_limit`)."""
    moving = traj.stick_time() <= 0.0
    if np.any(_departures(traj, d_hb, t, size_hb)[moving] > LADDER_GUARD * match):
        return math.inf
    gap, size = _gap_at_limit(make, omega, last, traj, t)
    return float(np.max(gap / _held_scale(traj, size)))


#: The check at the limit rejects an exact orbit whose elements that move (not held) depart from
#: the HB orbit at the row's own ε by more than this many times `match` of its peak-to-peak.
#: Measured on the lock-up clutch chain (examples/chain_lockup_clutch.toml's chain, ε = 0.01,
#: H = 64, Ω = 2.2 … 3.3 rad/s): the gear of the true limits departs by 0.042 … 0.077 at ε (the
#: held clutch's regularised width moves it), that of orbits the ladder jumped to by 0.34 … 2.5.
LADDER_GUARD = 2.0


def _held_scale(traj: FrictionTrajectory, size: FloatArray) -> FloatArray:
    """The scale of each element's departure: its HB δ_e's peak-to-peak ``size``, or, for an
    element the exact orbit ``traj`` holds (stuck or locked) part of the period, the chain's largest
    one. A held element moves within the regularisation's width of its stuck deflection or jump
    (a lock's regularised deflection is ε_δ artanh(τ/J), a few ε_δ, where the exact one is 0): its
    own peak-to-peak is then of the order of the regularisation and no scale to measure by."""
    held = traj.stick_time() > 0.0
    return np.where(held, np.max(size), size)


def _damped_newton(pb: RegularisedSystemBalance, q: FloatArray, omega: float, iterations: int = 200) -> FloatArray | None:
    """Newton with the step halved until the scaled residual ‖R‖∞ / F_s falls (Armijo, factor
    1 − s/4); the solution, or None. The start's fallback where plain Newton from the linear
    solution wanders (an impacting backlash)."""
    Fs = pb.force_scale
    R, dq = pb.newton_step(q, omega)
    res = float(np.max(np.abs(R))) / Fs
    for _ in range(iterations):
        if res <= 1e-10:
            return q
        if dq is None:
            return None
        s = 1.0
        while True:
            q_try = q + s * dq
            R_try, dq_try = pb.newton_step(q_try, omega)
            res_try = float(np.max(np.abs(R_try))) / Fs
            if np.isfinite(res_try) and res_try < (1.0 - 0.25 * s) * res:
                break
            s *= 0.5
            if s < 1e-4:
                return None
        q, dq, res = q_try, dq_try, res_try
    return q if res <= 1e-10 else None


#: Forcing periods simulated from the linear solution before the exact shooting of the start's
#: fallback (the transient of a lightly damped chain).
SETTLE_PERIODS = 40


def _settled(integ: ExactIntegrator, z0: FloatArray, omega: float, periods: int) -> FloatArray | None:
    """The state after ``periods`` forcing periods of the exact flow from ``z0``; None when the
    flow cannot be followed (:data:`FLOW_FAILURES`) or leaves the finite numbers."""
    T = 2.0 * math.pi / omega
    z = np.asarray(z0, dtype=float)
    try:
        for _ in range(periods):
            z = integ.advance(z, 0.0, T, omega)[0]
    except FLOW_FAILURES:
        return None
    return z if np.all(np.isfinite(z)) else None


def _orbit_spectrum(pb: RegularisedSystemBalance, traj: FrictionTrajectory, omega: float) -> FloatArray:
    """The Fourier series (pb's H, the HB's unknowns q) of the coordinates along one solution
    period (pb's p forcing periods) of ``traj`` at forcing frequency ``omega``, from pb's N samples."""
    N = pb.basis.samples
    x = traj.sample(np.arange(N) * (pb.period * 2.0 * math.pi / omega / N))[0][:, : pb.n_coordinates]
    return pb.basis.analyze(x.T).reshape(-1)


def _exact_spectrum(pb: RegularisedSystemBalance, omega: float) -> FloatArray | None:
    """The start's last fallback: the Fourier series (pb's H) of the exact periodic orbit reached
    by simulating :data:`SETTLE_PERIODS` periods from the linear solution's state and shooting;
    None when that fails."""
    fs: System = pb.fsys
    integ = ExactIntegrator(fs)
    try:
        z = _settled(integ, pb.state_at_zero(pb.linear_solution(omega), omega), omega, SETTLE_PERIODS)
        if z is None:
            return None
        orbit = shoot_friction_orbit(fs, omega, z, integrator=integ, max_iterations=30)
    except FLOW_FAILURES:
        return None
    if not orbit.converged:
        return None
    return _orbit_spectrum(pb, orbit.trajectory, omega)


def _start(make: Callable[[float, int], RegularisedSystemBalance], omega: float, eps: float, H: int,
           newton: NewtonOptions | None) -> FloatArray:
    """The HB orbit at Ω_min and ε: from the linear solution at wide steps (ε = 0.1, else 0.3;
    plain Newton, else damped Newton), narrowed by homotopy in ε."""
    last: RattleError | None = None
    for wide in (0.1, 0.3):
        e0 = max(wide, eps)
        q0 = make(e0, H).linear_solution(omega)
        for attempt in range(2):
            try:
                return regularisation_limit(make, omega, q0, eps_start=e0, eps_min=eps, harmonics=H, max_harmonics=H,
                                            tail_tol=math.inf, newton=newton).last.q
            except RattleError as exc:
                last = exc
            if attempt == 0:
                q_damped = _damped_newton(make(e0, H), q0, omega)
                if q_damped is None:
                    break
                q0 = q_damped
    q_exact = _exact_spectrum(make(max(0.1, eps), H), omega)
    if q_exact is not None:  # the exact orbit's spectrum as the start, narrowed from wide steps
        try:
            return regularisation_limit(make, omega, q_exact, eps_start=max(0.1, eps), eps_min=eps, harmonics=H,
                                        max_harmonics=H, tail_tol=math.inf, newton=newton).last.q
        except RattleError as exc:
            last = exc
    raise ConvergenceError(f"no regularised orbit found at Ω_min = {omega:g} (ε from 0.3 down to {eps:g}, "
                           f"H = {H}): {last}; start `omega` elsewhere or raise `regularisation`")


def _ladder(make: Callable[[float, int], RegularisedSystemBalance], omega: float, q: FloatArray,
            opts: RegularisationOptions, off: bool) -> RegularisationLimit:
    """The ladder at one row (ε → ``limit_eps``, H ≤ ``limit_harmonics``), on to ``deep_eps``
    when the row is still ``off`` and the last rungs are not linear in ε."""
    eps, H = opts.regularisation, opts.harmonics
    lad = regularisation_limit(make, omega, q, eps_start=eps, eps_min=min(opts.limit_eps, eps), harmonics=H,
                               max_harmonics=max(opts.limit_harmonics, H))
    if off and opts.deep_eps is not None and not lad.linear and opts.deep_eps < lad.last.eps:
        last = lad.last
        try:
            more = regularisation_limit(make, omega, last.q, eps_start=last.eps, eps_min=float(opts.deep_eps),
                                        harmonics=last.harmonics,
                                        max_harmonics=max(opts.deep_harmonics, last.harmonics))
            lad = RegularisationLimit(omega=lad.omega, steps=lad.steps + more.steps[1:])
        except RattleError:
            pass
    return lad


def friction_response(
    system: System,
    omega: tuple[float, float],
    options: RegularisationOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
) -> FrictionCheck:
    """The period-1 branch of the chain with friction ``system`` over ``omega`` = (Ω_min, Ω_max),
    from Ω_min (module docstring), with the settings ``options`` (None: :func:`chain_options`)
    (:class:`~rattle.analysis.RegularisationOptions`: ``harmonics`` H, ``regularisation`` ε,
    ``match``, ``refine``, ``limit``, ``limit_eps``, ``limit_harmonics``, ``deep_eps``,
    ``deep_harmonics``, ``stability``: how the HB orbit's own multipliers are found, see the
    module docstring)."""
    if not (isinstance(system, System) and system.discontinuous):
        raise TypeError(f"`system` must be a rattle.model.System with its elements' whole laws "
                        f"(Chain.friction_system()), got {system!r}")
    if isinstance(options, ShootingOptions):
        return shooting_friction_response(system, omega, options, continuation=continuation, newton=newton)
    lo, hi = check_range(omega)
    opts = chain_options(system) if options is None else options
    if not isinstance(opts, RegularisationOptions):
        raise TypeError(f"`options` must be a RegularisationOptions, got {opts!r}")
    if continuation is not None and not isinstance(continuation, ContinuationOptions):
        raise TypeError(f"`continuation` must be a ContinuationOptions or None, got {continuation!r}")
    if newton is not None and not isinstance(newton, NewtonOptions):
        raise TypeError(f"`newton` must be a NewtonOptions or None, got {newton!r}")
    H, eps = opts.harmonics, opts.regularisation
    make = friction_balance_factory(system)
    problem = make(eps, H)  # raises on too few harmonics for the excitation
    start = _start(make, lo, eps, H, None)
    stepper = ContinuationStepper(problem, start, lo, (lo, hi), options=continuation or ContinuationOptions(),
                                  newton=newton or NewtonOptions())
    points = stepper.run()
    return check_branch(system, make, points, opts, ExactIntegrator(system),
                        status=stepper.status or Status.SUCCESS, message=stepper.message)


def shooting_friction_response(
    system: System,
    omega: tuple[float, float],
    options: ShootingOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> FrictionCheck:
    """The chain's period-1 branch over ``omega`` by exact shooting continuation
    (:func:`~rattle.analysis._exact_branch.exact_branches`: every row an exact orbit of the chain,
    the special points located and labelled; ``followed`` "exact shooting", the HB columns nan).
    A second branch followed down from Ω_max, where the first left frequencies uncovered, is the
    first of ``branches`` (the sub-harmonic ones: :func:`rattle.analysis._nonsmooth.shooting_response`)."""
    if not (isinstance(system, System) and system.discontinuous):
        raise TypeError(f"`system` must be a rattle.model.System with its elements' whole laws "
                        f"(Chain.friction_system()), got {system!r}")
    lo, hi = check_range(omega)
    opts = ShootingOptions() if options is None else options
    found = exact_branches(system, (lo, hi), opts, continuation=continuation, newton=newton, progress=progress)
    parts = [exact_friction_response(system, b, number=k) for k, b in enumerate(found)]
    return dataclasses.replace(parts[0], branches=tuple(parts[1:])) if len(parts) > 1 else parts[0]


def exact_friction_response(system: System, branch: ExactBranch, *, number: int,
                            period: int = 1) -> FrictionCheck:
    """The :class:`FrictionCheck` of an exact branch of the chain: every row an exact orbit."""
    n, m, P = system.n, system.m, len(branch.rows)
    rows = [exact_measures(r.trajectory, r.omega, period) for r in branch.rows]
    if rows:
        mean, rms, stick, states, pattern, mult = (np.array([r[k] for r in rows]) for k in range(6))
    else:
        mean = rms = stick = np.zeros((0, m))
        states, pattern, mult = np.zeros((0, 2 * n)), np.zeros((0, 2 * m), dtype=np.int64), np.zeros((0, 2 * n), complex)
    omegas = branch.omega
    rpm = system.speed_rpm(omegas)
    return FrictionCheck(
        omega=omegas, rpm=None if rpm is None else np.asarray(rpm, dtype=float), element_names=system.element_names,
        rms=rms, rms_hb=np.full((P, m), np.nan), mean=mean, stick_fraction=stick, matched=np.ones(P, dtype=bool),
        match_distance=np.full(P, np.nan), stable=np.abs(mult).max(axis=1) < 1.0 + UNIT_TOL if P else np.zeros(0, bool),
        stable_hb=np.zeros(P, dtype=bool), multipliers=mult, multipliers_hb=np.full((P, 2 * n), np.nan + 0j),
        status=branch.status, message=branch.message, regularisation=math.nan, harmonics=0,
        limit_index=np.zeros(0, dtype=int), limit_eps=np.zeros(0), limit_harmonics=np.zeros(0, dtype=int),
        limit_rms=np.zeros((0, m)), limit_richardson=np.zeros((0, m)), limit_linear=np.zeros(0, dtype=bool),
        limit_multipliers=np.zeros((0, 2 * n), dtype=complex), pattern=pattern, period=period, branch=number,
        origin=branch.origin, states=states, followed="exact shooting",
        labels=np.array([r.label for r in branch.rows], dtype=object))


def period_gap(traj: FrictionTrajectory, omega: float) -> float:
    """max_e max_t |δ_e(t + T) − δ_e(t)| / ptp(δ_e) over the first period of the trajectory
    ``traj`` of two forcing periods or more (T = 2π/Ω): 0 for a period-1 orbit run twice."""
    T = 2.0 * math.pi / omega
    t = np.arange(MATCH_SAMPLES) * (T / MATCH_SAMPLES)
    d0, d1 = traj.element_samples(t)[0], traj.element_samples(t + T)[0]
    size = np.maximum(np.ptp(np.concatenate((d0, d1)), axis=0), 1e-300)
    return float(np.max(np.max(np.abs(d1 - d0), axis=0) / size))


def exact_measures(traj: FrictionTrajectory, omega: float,
                   period: int) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, np.ndarray, np.ndarray]:
    """A row's values from the exact orbit ``traj`` of ``period`` forcing periods: every element's
    mean and rms, the fraction of the period it sticks, z(0), the switching pattern (stick or lock
    phases of each element, then its breakpoint crossings, per period) and the multipliers."""
    m = traj.stick_time().size
    mean, rms = traj.element_mean_and_rms()
    stick = traj.stick_time() / (period * 2.0 * math.pi / omega)
    pattern = np.empty(2 * m, dtype=np.int64)
    for e in range(m):
        mine = traj.event_elements == e
        pattern[e] = int(np.sum(mine & np.isin(traj.event_kinds, (STICK, LOCK))))
        pattern[m + e] = int(np.sum(mine & (traj.event_kinds == CROSSING)))
    return mean, rms, stick, np.asarray(traj.state0, dtype=float), pattern, monodromy_multipliers(traj.sensitivity)


#: An exact orbit shot over p > 1 forcing periods repeats after one when every δ_e comes back
#: within this share of its peak-to-peak (the shooting converges to 1e-12 of the length scale).
REPEAT_TOL = 1e-6


def check_branch(system: System, make: Callable[[float, int], RegularisedSystemBalance],
                 points: list, opts: RegularisationOptions, integ: ExactIntegrator, *,  # type: ignore[type-arg]
                 status: Status, message: str, branch: int = 0, origin: str = "") -> FrictionCheck:
    """The rows of a continued HB branch ``points`` (:class:`~rattle.continuation.ContinuationPoint`
    of ``make(ε, H)``'s problem, whose period p forcing periods is the orbits'), each checked by exact
    shooting over p periods and refined at its regularisation's limit (module docstring, steps 2
    and 3). A row of p > 1 whose exact orbit repeats after one forcing period is not matched."""
    H, eps, match, refine = opts.harmonics, opts.regularisation, opts.match, opts.refine
    problem = make(eps, H)
    p = problem.period
    n, m = system.n, system.m
    L = problem.length_scale
    P = len(points)
    rms_hb = np.empty((P, m))
    rms, mean, stick = (np.full((P, m), np.nan) for _ in range(3))
    states = np.full((P, 2 * n), np.nan)
    mult, mult_hb = np.full((P, 2 * n), np.nan + 0j), np.full((P, 2 * n), np.nan + 0j)
    matched, dist_all = np.zeros(P, dtype=bool), np.full(P, np.nan)
    pattern = np.full((P, 2 * m), -1, dtype=np.int64)
    ladders: dict[tuple[int, bool], RegularisationLimit | None] = {}  # (row, deep): the row's ladder
    checks: list[tuple[FloatArray, FloatArray, FloatArray]] = []  # per row: times, HB δ_e there, HB peak-to-peaks

    def _row_ladder(i: int, w: float, q: FloatArray, off: bool = False) -> RegularisationLimit | None:
        """Row i's ladder (:func:`_ladder`; None when it stalls), found once: the match at the
        limit and the refinement share it."""
        key = (i, bool(off and opts.deep_eps is not None))
        if key not in ladders:
            try:
                ladders[key] = _ladder(make, w, q, opts, off)
            except RattleError:
                ladders[key] = None
        return ladders[key]

    for i, pt in enumerate(points):
        w, q = float(pt.omega), pt.q
        rms_hb[i] = problem.element_rms(q)
        z0 = problem.state_at_zero(q, w)
        hb_flow = _hb_flow(integ, z0, w, p)
        mu_hb = _hb_multipliers(hb_flow) if opts.stability == "saltation" \
            else regularised_system_multipliers(problem, q, w)
        try:
            orbit = shoot_friction_orbit(system, w, z0, period=p, integrator=integ, max_iterations=30)
        except FLOW_FAILURES:
            orbit = None
        shot_failed = orbit is None or not orbit.converged
        t = np.arange(MATCH_SAMPLES * p) * (2.0 * math.pi / w / MATCH_SAMPLES)
        E = problem.element_series(q)
        d_hb = _hb_samples(problem, E, w, t)  # (64 p, m)
        size = np.maximum(np.ptp(problem.basis.synthesize(E), axis=1), 1e-12 * L)
        checks.append((t, d_hb, size))
        traj = None
        if orbit is not None and orbit.converged:  # one orbit: every δ_e(t) within `match` of the HB's
            traj = orbit.trajectory
            dist_all[i] = float(np.max(_departures(traj, d_hb, t, size)))
            matched[i] = dist_all[i] <= match
        if not matched[i]:  # an element stuck (nearly) the whole period: a family of exact orbits
            held = _held_elements(hb_flow, E)
            if held:
                try:
                    orbit = shoot_friction_orbit(system, w, z0, period=p, integrator=integ, max_iterations=30,
                                                 hold=held)
                except FLOW_FAILURES:
                    orbit = None
                if orbit is not None and orbit.converged and all(orbit.stick_fraction[e] >= 1.0 - 1e-9 for e in held):
                    free = [e for e in range(m) if e not in held]
                    traj = orbit.trajectory
                    gap = _departures(traj, d_hb, t, size)
                    dist_all[i] = float(np.max(gap[free])) if free else 0.0
                    matched[i] = dist_all[i] <= match
                    if not matched[i] and dist_all[i] <= 3.0 * match:
                        # the regularised stick creeps (~ε_v), and the held element's creep moves the
                        # others: compare again with the HB at its smallest ε
                        lad = _row_ladder(i, w, q)
                        dist_all[i] = math.inf if lad is None else _departure_at_limit(make, w, lad, traj, t, free)
                        matched[i] = dist_all[i] <= match
        if not matched[i] and (shot_failed or _holds_part(hb_flow, orbit)):
            # the shooting from the HB at ε failed (outside Newton's reach of the exact orbit: near
            # a fold or a period doubling the HB's error moves it), or an element sticks or locks
            # part of the period, which the HB at ε resolves only to its regularisation's width:
            # the exact orbit is the limit of the HB's as ε → 0 when the flow shot from the HB at
            # the ladder's end matches that HB orbit
            lad = _row_ladder(i, w, q)
            found = None if lad is None else _match_at_limit(make, system, integ, w, lad, t, d_hb, size, match)
            if found is not None:
                traj, dist_all[i] = found
                matched[i] = dist_all[i] <= match
        if matched[i] and traj is not None and p > 1 and period_gap(traj, w) <= REPEAT_TOL:
            matched[i] = False  # a period-1 orbit: the branch has rejoined the primary there
        if matched[i]:
            assert traj is not None
            mean[i], rms[i], stick[i], states[i], pattern[i], mult[i] = exact_measures(traj, w, p)
            if mu_hb is None:
                mu_hb = mult[i]
        if mu_hb is not None:
            mult_hb[i] = mu_hb
        if not matched[i]:
            mult[i] = mult_hb[i]
    sources = np.flatnonzero(matched)
    for i in np.flatnonzero(~matched).tolist():
        # shot again from the exact orbit of the nearest matched row on either side: near a fold
        # the HB's error at ε moves its state out of Newton's reach, while the neighbour's exact
        # state, a step away in Ω, is within it; the orbit found is compared with the HB as the
        # row's own shot would have been (at the end of its ladder where it has one)
        w = float(points[i].omega)
        t, d_hb, size = checks[i]
        before, after = sources[sources < i], sources[sources > i]
        for j in sorted([int(x) for x in (before[-1:].tolist() + after[:1].tolist())], key=lambda j: abs(j - i)):
            try:
                orbit = shoot_friction_orbit(system, w, states[j], period=p, integrator=integ, max_iterations=30)
            except FLOW_FAILURES:
                continue
            if not orbit.converged or (p > 1 and period_gap(orbit.trajectory, w) <= REPEAT_TOL):
                continue
            traj = orbit.trajectory
            lad = ladders.get((i, False))  # the row was checked at its limit: compared as there
            d = float(np.max(_departures(traj, d_hb, t, _held_scale(traj, size)))) if lad is None \
                else _distance_at_limit(make, w, lad.last, traj, t, d_hb, size, match)
            if d <= match:
                matched[i], dist_all[i] = True, d
                mean[i], rms[i], stick[i], states[i], pattern[i], mult[i] = exact_measures(traj, w, p)
                break
    stable = np.abs(mult).max(axis=1) < 1.0 + UNIT_TOL  # nan (nothing known) → False
    stable_hb = np.abs(mult_hb).max(axis=1) < 1.0 + UNIT_TOL
    with np.errstate(invalid="ignore", divide="ignore"):
        err = np.max(np.abs(rms_hb / rms - 1.0), axis=1)
    candidates = np.flatnonzero(matched)
    pick = candidates[np.unique(np.linspace(0, candidates.size - 1, min(int(opts.limit), candidates.size))
                                .round().astype(int))] if opts.limit > 0 and candidates.size else np.zeros(0, int)
    if refine is not None and candidates.size:
        pick = np.union1d(pick, candidates[err[candidates] > refine]).astype(int)
    lim_eps, lim_H, lim_rms, lim_rich, lim_lin, lim_mu = [], [], [], [], [], []
    for i in pick.tolist():
        try:
            lad = _row_ladder(i, float(points[i].omega), points[i].q, bool(refine is not None and err[i] > refine))
            if lad is None:
                raise ConvergenceError(f"the ladder stalled at Ω = {float(points[i].omega):g}")
            assert lad.last.element_rms is not None
            lim_eps.append(lad.last.eps)
            lim_H.append(lad.last.harmonics)
            lim_rms.append(lad.last.element_rms)
            lim_rich.append(lad.extrapolated_element_rms)
            lim_lin.append(lad.linear)
            w = float(points[i].omega)
            last = make(lad.last.eps, lad.last.harmonics)
            mu_lim = _hb_multipliers(_hb_flow(integ, last.state_at_zero(lad.last.q, w), w, p)) \
                if opts.stability == "saltation" else regularised_system_multipliers(last, lad.last.q, w)
            lim_mu.append(np.full(2 * n, np.nan + 0j) if mu_lim is None else mu_lim)
        except RattleError:  # the ladder stalled: the row keeps its ε
            lim_eps.append(math.nan)
            lim_H.append(0)
            lim_rms.append(np.full(m, np.nan))
            lim_rich.append(np.full(m, np.nan))
            lim_lin.append(False)
            lim_mu.append(np.full(2 * n, np.nan + 0j))
    held_idx, held_rms, held_status, held_scale = [], [], [], []
    if opts.held:
        part = (np.nan_to_num(stick) > 0) & (np.nan_to_num(stick) < 1.0)
        for i in np.flatnonzero(matched & part.any(axis=1)).tolist():
            w = float(points[i].omega)
            lad = _row_ladder(i, w, points[i].q)
            held_idx.append(i)
            try:
                if lad is None:
                    raise ConvergenceError(f"the ladder stalled at Ω = {w:g}")
                hl = held_limit(make(lad.last.eps, lad.last.harmonics), lad.last.q, w, np.flatnonzero(part[i]).tolist(),
                                harmonics=opts.held_harmonics)
                held_rms.append(hl.rms)
                held_status.append(hl.status)
                held_scale.append(hl.scale)
            except RattleError:
                held_rms.append(np.full(m, np.nan))
                held_status.append("failed")
                held_scale.append(math.nan)
    omegas = np.array([float(p.omega) for p in points])
    rpm = system.speed_rpm(omegas)
    return FrictionCheck(
        omega=omegas, rpm=None if rpm is None else np.asarray(rpm, dtype=float), element_names=system.element_names,
        rms=rms, rms_hb=rms_hb, mean=mean, stick_fraction=stick, matched=matched, match_distance=dist_all,
        stable=stable, stable_hb=stable_hb, multipliers=mult, multipliers_hb=mult_hb,
        status=status, message=message, regularisation=float(eps), harmonics=int(H),
        limit_index=np.asarray(pick, dtype=int), limit_eps=np.array(lim_eps, dtype=float),
        limit_harmonics=np.array(lim_H, dtype=int), limit_rms=np.array(lim_rms, dtype=float).reshape(-1, m),
        limit_richardson=np.array(lim_rich, dtype=float).reshape(-1, m),
        limit_linear=np.array(lim_lin, dtype=bool),
        limit_multipliers=np.array(lim_mu, dtype=complex).reshape(-1, 2 * n), pattern=pattern,
        period=p, branch=branch, origin=origin, states=states,
        held_index=np.array(held_idx, dtype=int), held_rms=np.array(held_rms, dtype=float).reshape(-1, m),
        held_status=np.array(held_status, dtype=object), held_scale=np.array(held_scale, dtype=float),
    )


__all__ = ["FrictionCheck", "check_branch", "exact_measures", "period_gap", "friction_balance_factory", "friction_response"]
