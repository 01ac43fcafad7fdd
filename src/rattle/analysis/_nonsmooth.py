"""Frequency response of a discontinuous law (preload, friction): regularised HB, checked exactly.

For δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t) (single-equation :class:`~rattle.model.System`):

1. the regularised harmonic balance (:class:`~rattle.hb.RegularisedBalance`, smooth steps of
   relative width ε, H harmonics) is continued over Ω by pseudo-arclength
   (:class:`~rattle.continuation.ContinuationStepper`): folds are followed as on the smooth laws;
2. every continuation point is checked against the exact flow: Newton shooting on the
   event-driven integrator (:func:`~rattle.timeint.shoot_nonsmooth_orbit`: crossings, sticking and
   locking exact, the monodromy with saltation matrices) started from the HB orbit's state at
   t = 0. The exact orbit gives the rms and the multipliers that are reported as the answer; the
   HB's own values (rms, and the HB orbit's multipliers: the non-smooth monodromy, with saltation
   matrices, of one period of the exact flow from the HB state, or on request the smooth one of
   the regularised equation, :func:`~rattle.stability.regularised_multipliers`) are kept beside
   them, so the regularisation's effect is measured at every point (``rms_error``);
3. the two are one orbit (``matched``) when the shooting converged and the exact δ(t) stays
   within ``match`` × (the HB δ's peak-to-peak) of the HB's on 64 samples of the period. Where
   the shooting fails (outside Newton's reach of the exact orbit: near a fold or a grazing the
   HB's error at ε moves its state away), or δ sticks or locks part of the period (on the exact
   flow from the HB state or on the exact orbit) and that check fails, the row is checked at the
   limit of its regularisation: the HB is followed at fixed Ω down the ε ladder (ε → ``limit_eps``,
   H ≤ ``limit_harmonics``, :func:`~rattle.analysis._regularisation.regularisation_limit`; the
   rungs kept for step 4), the exact flow is shot from the HB state at the ladder's end, and the
   two are one orbit when the exact δ(t) stays within ``match`` of that HB's, relative to that
   HB δ's peak-to-peak, and no rung of the ladder moved δ(t) by more than
   :data:`LADDER_STEP_GUARD` of its peak-to-peak (a larger step is a jump to another orbit: at a
   fold in ε the regularised orbit has no limit). The exact orbit is then the limit ε → 0 of the HB's. With one coordinate
   the plain relative scale stays the right one at the limit: a held phase is a part of δ's own
   period (δ constant while stuck, at the jump's breakpoint while locked), the motion outside it
   sets the peak-to-peak, and the regularised δ there departs from the exact one by the steps'
   width ε_δ (and its creep), which the ladder shrinks; unlike an element of a chain held while
   the others move, its own peak-to-peak is no regularisation-sized scale. An orbit held the
   whole period (the exact orbits a family, δ free within the friction band) is not resolved
   this way. Rows matched by neither check are ``matched = False``: there the HB point has no
   exact counterpart nearby and only the HB values stand;

4. where a matched row's HB rms misses the exact one by more than ``refine`` (0.5 % by default),
   the regularisation is continued at that row towards its limit (ε down to ``limit_eps``, H up to
   ``limit_harmonics``; :func:`~rattle.analysis._regularisation.regularisation_limit`) and the
   HB's rms at the smallest ε is kept beside the exact one (``hb_error``): the HB's accuracy is
   then measured at its limit, row by row. A ladder one of whose rungs moved δ(t) by more than
   :data:`LADDER_STEP_GUARD` of its peak-to-peak left the row's orbit on its way down (a fold in
   ε): it gives no value, and the row keeps its error at ε.

With ``subharmonics`` the period-2 branches born at the period doublings follow
(:func:`nonsmooth_subharmonics`), each checked by the same steps over two forcing periods.

Cost: one continuation of 2H + 1 unknowns plus one exact shooting and one exact period (the HB
orbit's monodromy; a few ms) per point, and a ladder (0.5–2 s) per row checked at the limit or
refined, found once per row: a row checked at the limit and then refined shares it.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .._typing import FloatArray
from .._validate import check_range
from ..continuation import BranchPoint, ContinuationOptions, ContinuationStepper, NewtonOptions
from ..errors import ConvergenceError, RattleError, Status
from ..hb import HBOptions, RegularisedBalance
from ..model import Chain, System
from ..results import FrequencyResponse, FrictionCheck, NonsmoothCheck
from ..stability import regularised_multipliers
from ..timeint import (
    FLOW_FAILURES, ExactIntegrator, NonsmoothOrbit, NonsmoothTrajectory, monodromy_multipliers,
    shoot_nonsmooth_orbit,
)
from .._limits import MAX_PERIOD
from ._attractors import AttractorSearch
from ._exact_search import SUBHARMONIC_POINTS, SUBHARMONIC_SEARCH, subharmonic_attractors
from ._exact_branch import DOUBLING_BRANCHES, ExactBranch, ShootingOptions, exact_branches, subharmonic_branches
from ._friction_response import exact_friction_response, friction_response, shooting_friction_response
from ._friction_subharmonics import friction_subharmonics
from ._period_two import branches_at_doublings, follow_both_ways, follow_exactly, period_two_hb, pushed_starts
from ._regularisation import (
    RegularisationLimit,
    RegularisationOptions,
    regularisation_limit,
)


#: Samples of the period on which the exact δ(t) is compared with the HB's.
MATCH_SAMPLES = 64


def _rms(q: FloatArray, H: int) -> float:
    return math.sqrt(q[0] ** 2 + 0.5 * float(np.sum(q[1:] ** 2)))


def _hb_flow(integ: ExactIntegrator, state: tuple[float, float], omega: float,
             period: int = 1) -> NonsmoothTrajectory | None:
    """One period p 2π/Ω of the exact flow from ``state`` (the HB orbit's at t = 0); None when it
    cannot be followed (the event budget of a chattering flow)."""
    try:
        return integ.propagate(np.asarray(state, dtype=float), 0.0, period * 2.0 * math.pi / omega, omega)
    except FLOW_FAILURES:
        return None


def _hb_multipliers(problem: RegularisedBalance, flow: NonsmoothTrajectory | None, q: FloatArray,
                    omega: float, method: str) -> np.ndarray:
    """The Floquet multipliers of the HB orbit (2,), largest modulus first: ``"saltation"`` the
    non-smooth monodromy (stage matrices and saltation matrices at every switching) of one period
    of the exact flow from the HB orbit's state at t = 0 (``flow``, :func:`_hb_flow`);
    ``"regularised"`` the smooth monodromy of the regularised equation along the HB orbit
    (:func:`~rattle.stability.regularised_multipliers`). The first falls back to the second when
    the flow cannot be followed (the event budget)."""
    if method == "saltation" and flow is not None:
        try:
            mu = monodromy_multipliers(flow.sensitivity)
            if np.all(np.isfinite(mu)):
                return mu
        except (ValueError, ArithmeticError):
            pass
    return regularised_multipliers(problem, q, omega)


def _match_times(omega: float, period: int) -> FloatArray:
    """:data:`MATCH_SAMPLES` equally spaced times over the period p 2π/Ω."""
    return np.arange(MATCH_SAMPLES) * (period * 2.0 * math.pi / omega / MATCH_SAMPLES)


def _departure(problem: RegularisedBalance, q: FloatArray, omega: float, traj: NonsmoothTrajectory,
               scale: float) -> float:
    """The largest departure of the exact δ(t) on ``traj`` from the HB orbit ``q`` of ``problem``
    (period p = ``problem.period``) on :data:`MATCH_SAMPLES` samples of its period p 2π/Ω,
    relative to ``scale``."""
    p = problem.period
    t = _match_times(omega, p)
    return float(np.max(np.abs(traj.sample(t)[0] - problem.basis.evaluate(q, omega / p, t)))) / scale


#: An exact orbit shot over p forcing periods repeats after fewer when δ comes back within this
#: share of its peak-to-peak (the shooting converges to 1e-12 of the length scale).
REPEAT_TOL = 1e-7


def _repeats_early(orbit: NonsmoothOrbit) -> bool:
    """Whether the exact ``orbit`` of p forcing periods repeats after a divisor d < p of them (δ
    and δ' back within :data:`REPEAT_TOL` of its peak-to-peak): near the ends of a sub-harmonic
    branch, where the exact period doubling lies on the other side of the row, the shooting lands
    on the period-1 orbit run p times."""
    omega, period = orbit.omega, orbit.period
    T = 2.0 * math.pi / omega
    size = max(float(np.ptp(orbit.trajectory.sample(np.linspace(0.0, period * T, 64 * period + 1))[0])), 1e-300)
    for k in range(1, period):
        if period % k == 0:
            d, v = orbit.trajectory.sample(np.array([0.0, k * T]))[:2]
            if max(abs(float(d[1] - d[0])), abs(float(v[1] - v[0])) / omega) <= REPEAT_TOL * size:
                return True
    return False


def _holds(flow: NonsmoothTrajectory | None, orbit: NonsmoothOrbit | None) -> bool:
    """Whether δ sticks or locks some of the period on the exact ``flow`` from the HB state or on
    the converged exact ``orbit``."""
    trajs = [flow] + ([orbit.trajectory] if orbit is not None and orbit.converged else [])
    return any(tr is not None and tr.stick_time > 0.0 for tr in trajs)


def _match_at_limit(make: Callable[[float, int], RegularisedBalance], system: System,
                    integ: ExactIntegrator, omega: float, lad: RegularisationLimit,
                    L: float) -> tuple[NonsmoothOrbit, float] | None:
    """The exact orbit shot from the HB state at the end of the ε ladder ``lad`` (one that stayed
    on the row's orbit, :data:`LADDER_STEP_GUARD`) and its departure from that HB orbit, relative
    to that HB δ's peak-to-peak; None when the shooting fails."""
    last = lad.last
    pb = make(last.eps, last.harmonics)
    d0, v0 = (float(a[0]) for a in pb.samples(last.q, omega))
    try:
        orbit = shoot_nonsmooth_orbit(system, omega, (d0, v0), period=pb.period, integrator=integ, max_iterations=30)
    except FLOW_FAILURES:
        return None
    if not orbit.converged:
        return None
    size = max(float(np.ptp(pb.basis.synthesize(last.q))), 1e-12 * L)
    return orbit, _departure(pb, last.q, omega, orbit.trajectory, size)


#: The check at the limit trusts a ladder whose rungs each move δ(t) by at most this fraction of
#: its peak-to-peak. Following one orbit down in ε (each rung halves it), a rung moves δ(t) by
#: about half of what is left of the regularisation's error; a rung that jumps to another orbit
#: (a fold in ε: the regularised orbit at ε has no limit, Newton finds another on the way down)
#: moves it by the distance between the two orbits, of the order of the peak-to-peak.
LADDER_STEP_GUARD = 0.2


def _ladder_step(make: Callable[[float, int], RegularisedBalance], lad: RegularisationLimit, omega: float,
                 L: float) -> float:
    """The largest change of δ(t) between two successive rungs of ``lad`` on :data:`MATCH_SAMPLES`
    samples of the period, relative to the earlier rung's peak-to-peak."""
    p = make(lad.last.eps, lad.last.harmonics).period
    t = _match_times(omega, p)
    prev: FloatArray | None = None
    worst = 0.0
    for step in lad.steps:
        d = make(step.eps, step.harmonics).basis.evaluate(step.q, omega / p, t)
        if prev is not None:
            worst = max(worst, float(np.max(np.abs(d - prev))) / max(float(np.ptp(prev)), 1e-12 * L))
        prev = d
    return worst


def _deeper(make: Callable[[float, int], RegularisedBalance], lad: RegularisationLimit,
            opts: RegularisationOptions) -> RegularisationLimit:
    """``lad`` continued from its last rung down to ``opts.deep_eps`` with up to
    ``opts.deep_harmonics`` harmonics; ``lad`` itself when that stalls."""
    last = lad.last
    try:
        more = regularisation_limit(make, lad.omega, last.q, eps_start=last.eps, eps_min=float(opts.deep_eps),
                                    harmonics=last.harmonics, max_harmonics=max(opts.deep_harmonics, last.harmonics))
    except RattleError:
        return lad
    return RegularisationLimit(omega=lad.omega, steps=lad.steps + more.steps[1:])


def balance_factory(system: System, period: int = 1) -> Callable[[float, int], RegularisedBalance]:
    """``make(ε, H)``: the regularised HB of ``system`` at relative width ε with H harmonics of
    Ω/``period``, on the scales every front end uses (the law's length scale L, ω_n = √(k s_max))."""
    exc = system.excitation
    L = system.length_scale()
    wn = math.sqrt(system.k * float(np.max(system.law.stages.slopes)))

    def make(eps: float, H: int) -> RegularisedBalance:
        return RegularisedBalance(system.c, system, exc.mean, exc.amplitudes, exc.phases, regularisation=eps,
                                  length_scale=L, frequency_scale=wn, options=HBOptions(harmonics=H), period=period)

    return make


def nonsmooth_response(
    system: System,
    omega: tuple[float, float],
    options: ShootingOptions | RegularisationOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    subharmonics: bool = False,
    max_period: int = MAX_PERIOD,
    search: AttractorSearch | None = SUBHARMONIC_SEARCH,
    progress: Callable[[int, int], None] | None = None,
) -> NonsmoothCheck | FrictionCheck:
    """The exact-check group (:class:`~rattle.results.NonsmoothCheck`, a chain's
    :class:`~rattle.results.FrictionCheck`) of the period-1 branch over ``omega`` = (Ω_min, Ω_max),
    from Ω_min: the builder under :func:`rattle.frequency_response` (:func:`discontinuous_response`
    makes it a :class:`~rattle.results.FrequencyResponse`). The method follows from ``options``: None or a :class:`ShootingOptions`, exact shooting continuation (the default,
    :func:`shooting_response`: every row an exact orbit, special points located); a
    :class:`RegularisationOptions`, the regularised harmonic balance with every row checked by
    exact shooting (module docstring); with ``subharmonics`` also the
    period-2 branches born at its period doublings (:func:`nonsmooth_subharmonics`), in its
    ``branches`` (by exact shooting: the sub-harmonic branches of :func:`shooting_response`, up to
    ``max_period``, with the attractor search ``search``). A chain with friction (:class:`~rattle.model.System` with its elements' whole laws) goes to
    :func:`~rattle.analysis._friction_response.friction_response` (a :class:`FrictionCheck`),
    with ``subharmonics`` also to :func:`~rattle.analysis._friction_subharmonics.friction_subharmonics`."""
    if not isinstance(subharmonics, bool):
        raise TypeError(f"`subharmonics` must be True or False, got {subharmonics!r}")
    if options is None or isinstance(options, ShootingOptions):  # the default: exact shooting continuation
        return shooting_response(system, omega, options, continuation=continuation, newton=newton,
                                 subharmonics=subharmonics, max_period=max_period, search=search, progress=progress)
    if isinstance(system, System) and system.discontinuous and not system.is_single_equation:
        chain = friction_response(system, omega, options, continuation=continuation, newton=newton)
        if subharmonics:
            chain = dataclasses.replace(chain, branches=friction_subharmonics(
                system, chain, omega, options, continuation=continuation, newton=newton))
        return chain
    if not (isinstance(system, System) and system.is_single_equation):
        raise TypeError(f"`system` must be a System with its whole laws: the single equation's (System.single) or a chain's ("
                        f"friction, Chain.friction_system()), got {system!r}")
    lo, hi = check_range(omega)
    opts = RegularisationOptions() if options is None else options
    if not isinstance(opts, RegularisationOptions):
        raise TypeError(f"`options` must be a RegularisationOptions, got {opts!r}")
    harmonics, regularisation = opts.harmonics, opts.regularisation
    make = balance_factory(system)
    problem = make(regularisation, harmonics)
    # the start: solved where the steps are wide (ε = 0.1), then narrowed to ε by homotopy
    start = regularisation_limit(make, lo, np.zeros(problem.size), eps_start=max(0.1, regularisation),
                                 eps_min=regularisation, harmonics=harmonics, max_harmonics=harmonics,
                                 tail_tol=math.inf).last.q
    stepper = ContinuationStepper(problem, start, lo, (lo, hi),
                                  options=continuation or ContinuationOptions(),
                                  newton=newton or NewtonOptions())
    points = stepper.run()
    primary = _check_branch(system, make, opts, points, stepper.status or Status.SUCCESS, stepper.message)
    if subharmonics:
        branches = nonsmooth_subharmonics(system, primary, (lo, hi), opts, continuation=continuation, newton=newton)
        primary = dataclasses.replace(primary, branches=branches)
    return primary


def method_settings(options: ShootingOptions | RegularisationOptions, chain: bool) -> dict[str, Any]:
    """The ``frf.json`` settings of the method ``options`` (``chain``: a chain with friction or jumps
    on its elements): what was solved and how, and the options' values."""
    if isinstance(options, ShootingOptions):
        return {
            "method": "exact shooting continuation: pseudo-arclength in (z(0), Ω) on the exact event-driven period "
                      "map" + (" of the chain" if chain else "") + " (Filippov sticking and locking, saltation "
                      "monodromy), special points located on the branch (rattle.frequency_response)",
            "settle_periods": options.settle_periods, "hops": list(options.hops), "locate": options.locate,
        }
    out = {
        "method": ("regularised harmonic balance of the chain continued over Ω, every point checked by exact "
                   "event-driven shooting with Filippov sticking and saltation monodromy (rattle.frequency_response)")
        if chain else ("regularised harmonic balance continued over Ω, every point checked by exact event-driven "
                       "shooting (rattle.frequency_response)"),
        "harmonics": options.harmonics, "regularisation": options.regularisation, "match": options.match,
        "limit": options.limit, "refine": options.refine, "limit_eps": options.limit_eps,
        "limit_harmonics": options.limit_harmonics,
    }
    if chain:
        out.update(held=options.held, held_harmonics=options.held_harmonics)
    return out


def discontinuous_response(
    model: Any,
    omega: tuple[float, float],
    options: ShootingOptions | RegularisationOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    subharmonics: bool = False,
    throw: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> FrequencyResponse:
    """:func:`rattle.analysis.frequency_response` of a law with jumps or friction: the
    :class:`~rattle.results.FrequencyResponse` of :func:`nonsmooth_response` (its exact-check
    group in ``check``, every branch's rows, the method's settings and the time taken). A
    :class:`~rattle.model.Chain` is solved on its ``friction_system()``. With ``throw`` a run that
    did not cover the range raises :class:`~rattle.errors.ConvergenceError` with the result in
    ``.partial``."""
    system = model.friction_system() if isinstance(model, Chain) else model
    if options is not None and not isinstance(options, (ShootingOptions, RegularisationOptions)):
        raise TypeError(f"`options` must be None, a ShootingOptions (exact shooting continuation) or a "
                        f"RegularisationOptions (the regularised harmonic balance), got {options!r}")
    t0 = time.perf_counter()
    check = nonsmooth_response(system, omega, options, continuation=continuation, newton=newton,
                               subharmonics=subharmonics, progress=progress)
    chain = isinstance(system, System) and system.discontinuous and not system.is_single_equation
    opts = options if options is not None else ShootingOptions()
    settings = {**method_settings(opts, chain), "subharmonics": subharmonics}
    if subharmonics and isinstance(opts, ShootingOptions):
        settings.update(max_period=MAX_PERIOD, doubling_branches=DOUBLING_BRANCHES,
                        subharmonic_search=None if chain else {"points": SUBHARMONIC_POINTS,
                                                               **dataclasses.asdict(SUBHARMONIC_SEARCH)})
    result = FrequencyResponse.from_check(check, model=system, settings=settings,
                                          timings={"frequency_response": time.perf_counter() - t0})
    if throw and not result.status.success:
        raise ConvergenceError(f"frequency response incomplete: {result.message or result.status.message}",
                               partial=result)
    return result


def shooting_response(
    system: System,
    omega: tuple[float, float],
    options: ShootingOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    subharmonics: bool = False,
    max_period: int = MAX_PERIOD,
    search: AttractorSearch | None = SUBHARMONIC_SEARCH,
    progress: Callable[[int, int], None] | None = None,
) -> NonsmoothCheck | FrictionCheck:
    """The period-1 branch over ``omega`` by exact shooting continuation
    (:func:`~rattle.analysis._exact_branch.exact_branches`: every row an exact orbit, the special
    points located and labelled; ``followed`` "exact shooting", the HB columns nan). A second
    branch followed down from Ω_max, where the first left frequencies uncovered, is the first of
    ``branches``. With ``subharmonics`` the sub-harmonic branches follow (numbered on), every row
    an exact orbit of its period p with the multipliers of the p-period map: those born at the
    period doublings located on the period-1 branches, and recursively on theirs, up to period
    ``max_period`` (:func:`~rattle.analysis._exact_branch.subharmonic_branches`); then, with
    ``search`` (an :class:`AttractorSearch` budget; None: none; a chain has none), those through
    the periodic attractors of period 2 … ``max_period`` that exact simulations settle on and no
    branch accounts for (:func:`~rattle.analysis._exact_search.subharmonic_attractors`), with the
    branches born at their own period doublings. ``progress(done, total)``: called with the share of the range reached
    (the CLI draws a bar; the library draws nothing)."""
    lo, hi = check_range(omega)
    opts = ShootingOptions() if options is None else options
    primary: NonsmoothCheck | FrictionCheck
    if isinstance(system, System) and system.discontinuous and not system.is_single_equation:
        primary = shooting_friction_response(system, (lo, hi), opts, continuation=continuation, newton=newton,
                                             progress=progress)
        build = lambda b, k, p: exact_friction_response(system, b, number=k, period=p)  # noqa: E731
        search = None  # a chain's simulations take seconds each: its attractor search is the map's (rattle map)
    elif isinstance(system, System) and system.is_single_equation:
        found = exact_branches(system, (lo, hi), opts, continuation=continuation, newton=newton, progress=progress)
        parts = [_exact_response(b, number=k) for k, b in enumerate(found)]
        primary = dataclasses.replace(parts[0], branches=tuple(parts[1:])) if len(parts) > 1 else parts[0]
        build = lambda b, k, p: _exact_response(b, number=k, period=p)  # noqa: E731
    else:
        raise TypeError(f"`system` must be a System with its whole laws: the single equation's (System.single) or a chain's ("
                        f"friction, Chain.friction_system()), got {system!r}")
    if not subharmonics or not len(primary):
        return primary
    extra = list(primary.branches)
    extra += subharmonic_branches(system, [primary, *primary.branches], (lo, hi), opts, continuation, newton, build,
                                  first=len(extra) + 1, max_period=max_period)
    if search is not None:
        found = subharmonic_attractors(system, dataclasses.replace(primary, branches=tuple(extra)), (lo, hi), opts,
                                       continuation, newton, build, search)
        found = [b for b in found if int(b.period) <= max_period]
        extra += found
        extra += subharmonic_branches(system, found, (lo, hi), opts, continuation, newton, build,
                                      first=len(extra) + 1, max_period=max_period)
    return dataclasses.replace(primary, branches=tuple(extra))


def _exact_response(branch: ExactBranch, *, number: int, period: int = 1) -> NonsmoothCheck:
    """The :class:`NonsmoothCheck` of an exact branch: every row an exact orbit."""
    rows: dict[str, list] = {k: [] for k in _ROW_KEYS}
    nan2 = np.full(2, np.nan + 0j)
    for r in branch.rows:
        traj = r.trajectory
        mean, rms = traj.mean_and_rms()
        orbit = NonsmoothOrbit(state0=r.q, omega=r.omega, period=period, monodromy=r.M,
                               multipliers=r.multipliers, converged=True, iterations=0, residual=0.0,
                               trajectory=traj, mean=mean, rms=rms)
        rows["omega"].append(r.omega)
        rows["rms_hb"].append(math.nan)
        rows["mult_hb"].append(nan2)
        rows["matched"].append(True)
        _add_row(rows, orbit, nan2)
    return _response(rows, status=branch.status, message=branch.message, regularisation=math.nan, harmonics=0,
                     period=period, branch=number, origin=branch.origin, followed="exact shooting",
                     labels=np.array([r.label for r in branch.rows], dtype=object),
                     limit_index=np.zeros(0, dtype=int), limit_eps=np.zeros(0), limit_rms=np.zeros(0),
                     limit_richardson=np.zeros(0), limit_linear=np.zeros(0, dtype=bool))


_ROW_KEYS = ("omega", "rms_hb", "rms", "stable", "mult", "mult_hb", "stick", "matched", "mean", "p2p", "acc_p2p",
             "regime", "sticks", "crossings", "state")


def _add_row(rows: dict[str, list], orbit: NonsmoothOrbit | None, mu_hb: np.ndarray) -> None:
    """Append the exact ``orbit``'s measures to ``rows`` (its stability, switching pattern and
    state at t = 0), or, without one, nan and the HB orbit's multipliers ``mu_hb``."""
    if orbit is not None:
        d_lo, d_hi, a_lo, a_hi = orbit.trajectory.extremes()
        rows["rms"].append(orbit.rms)
        rows["mean"].append(orbit.mean)
        rows["p2p"].append(d_hi - d_lo)
        rows["acc_p2p"].append(a_hi - a_lo)
        rows["regime"].append(orbit.regime)
        rows["mult"].append(np.asarray(orbit.multipliers, dtype=complex)[:2])
        rows["stable"].append(bool(orbit.stable))
        rows["stick"].append(float(orbit.trajectory.stick_time))
        kinds = orbit.trajectory.event_kind  # the switching pattern: held phases and crossings per period
        rows["sticks"].append(sum(k in ("stick", "lock") for k in kinds))
        rows["crossings"].append(sum(k == "crossing" for k in kinds))
        rows["state"].append(np.asarray(orbit.state0, dtype=float))
        return
    rows["state"].append(np.full(2, np.nan))
    rows["sticks"].append(-1)
    rows["crossings"].append(-1)
    for key in ("rms", "mean", "p2p", "acc_p2p", "stick"):
        rows[key].append(math.nan)
    rows["regime"].append("")
    rows["mult"].append(mu_hb)
    rows["stable"].append(bool(np.all(np.abs(mu_hb) < 1.0)))


def _response(rows: dict[str, list], **fields: object) -> NonsmoothCheck:
    """The :class:`NonsmoothCheck` of the collected ``rows`` and the other ``fields``."""
    rms, mean = np.array(rows["rms"], dtype=float), np.array(rows["mean"], dtype=float)
    return NonsmoothCheck(
        omega=np.array(rows["omega"], dtype=float), rms_hb=np.array(rows["rms_hb"], dtype=float), mean=mean, rms=rms,
        rms_ac=np.sqrt(np.maximum(rms**2 - mean**2, 0.0)), p2p=np.array(rows["p2p"], dtype=float),
        acc_p2p=np.array(rows["acc_p2p"], dtype=float), regime=np.array(rows["regime"], dtype=object),
        stable=np.array(rows["stable"], dtype=bool), multipliers=np.array(rows["mult"], dtype=complex).reshape(-1, 2),
        multipliers_hb=np.array(rows["mult_hb"], dtype=complex).reshape(-1, 2),
        stick_time=np.array(rows["stick"], dtype=float), sticks=np.array(rows["sticks"], dtype=np.int64),
        crossings=np.array(rows["crossings"], dtype=np.int64), matched=np.array(rows["matched"], dtype=bool),
        states=np.array(rows["state"], dtype=float).reshape(-1, 2), **fields,  # type: ignore[arg-type]
    )


def _check_branch(system: System, make: Callable[[float, int], RegularisedBalance],
                  opts: RegularisationOptions, points: list[BranchPoint], status: Status, message: str, *,
                  branch: int = 0, origin: str = "") -> NonsmoothCheck:
    """Steps 2–4 of the module docstring on the continued ``points`` of one branch (of the period
    p of ``make``'s problems: the exact orbits are shot over p forcing periods)."""
    harmonics, regularisation, match = opts.harmonics, opts.regularisation, opts.match
    limit, limit_eps, limit_harmonics, refine = opts.limit, opts.limit_eps, opts.limit_harmonics, opts.refine
    if points:
        harmonics = points[0].q.size // 2
    problem = make(regularisation, harmonics)
    period = problem.period
    L = system.length_scale()
    integ = ExactIntegrator(system)
    rows: dict[str, list] = {k: [] for k in _ROW_KEYS}
    ladders: dict[int, RegularisationLimit | None] = {}  # row: its ladder (None: it stalled)

    def _row_ladder(i: int) -> RegularisationLimit | None:
        """Row i's ladder (ε → ``limit_eps``, H ≤ ``limit_harmonics``), found once: the match at
        the limit and the refinement share it. None when it stalls, or when one of its rungs moved
        δ(t) by more than :data:`LADDER_STEP_GUARD` of its peak-to-peak: it left the row's orbit
        (a fold in ε), and its end is another orbit's."""
        if i not in ladders:
            w = float(points[i].omega)
            try:
                lad = regularisation_limit(make, w, points[i].q, eps_start=regularisation,
                                           eps_min=min(limit_eps, regularisation), harmonics=harmonics,
                                           max_harmonics=max(limit_harmonics, harmonics))
                ladders[i] = None if _ladder_step(make, lad, w, L) > LADDER_STEP_GUARD else lad
            except RattleError:
                ladders[i] = None
        return ladders[i]

    for i, pt in enumerate(points):
        w, q = float(pt.omega), pt.q
        rms_hb = _rms(q, harmonics)
        d0, v0 = (float(a[0]) for a in problem.samples(q, w))
        flow = _hb_flow(integ, (d0, v0), w, period) if opts.stability == "saltation" else None
        mu_hb = _hb_multipliers(problem, flow, q, w, opts.stability)
        size = max(float(np.ptp(problem.basis.synthesize(q))), 1e-12 * L)
        orbit = None
        try:
            orbit = shoot_nonsmooth_orbit(system, w, (d0, v0), period=period, integrator=integ, max_iterations=30)
        except FLOW_FAILURES:  # e.g. the event budget of a chattering orbit
            orbit = None
        shot_failed = orbit is None or not orbit.converged
        ok = not shot_failed
        if ok:  # the same orbit: δ(t) of the two within `match` of the HB orbit's peak-to-peak
            ok = _departure(problem, q, w, orbit.trajectory, size) <= match
        if not ok:
            if flow is None and opts.stability != "saltation":
                flow = _hb_flow(integ, (d0, v0), w, period)
            if shot_failed or _holds(flow, orbit):
                # the shooting from the HB at ε failed (outside Newton's reach of the exact orbit), or
                # δ sticks or locks part of the period, which the HB at ε resolves only to the steps'
                # width: the exact orbit is the limit of the HB's as ε → 0 when the flow shot from
                # the HB at the ladder's end matches that HB orbit
                lad = _row_ladder(i)
                found = None if lad is None else _match_at_limit(make, system, integ, w, lad, L)
                if found is not None and found[1] <= match:
                    orbit, ok = found[0], True
        if ok and period > 1 and _repeats_early(orbit):
            ok = False  # the exact orbit there is of a lower period: no exact counterpart of this one
        rows["omega"].append(w)
        rows["rms_hb"].append(rms_hb)
        rows["mult_hb"].append(mu_hb)
        rows["matched"].append(ok)
        _add_row(rows, orbit if ok else None, mu_hb)
    rms = np.array(rows["rms"])
    rms_hb = np.array(rows["rms_hb"])
    matched = np.array(rows["matched"], dtype=bool)
    candidates = np.flatnonzero(matched)
    pick = candidates[np.unique(np.linspace(0, candidates.size - 1, min(int(limit), candidates.size)).round().astype(int))] \
        if limit > 0 and candidates.size else np.zeros(0, dtype=int)
    if refine is not None and candidates.size:  # and every row whose HB misses the exact rms by more than `refine`
        off = candidates[np.abs(rms_hb[candidates] / rms[candidates] - 1.0) > refine]
        pick = np.union1d(pick, off).astype(int)
    lim_eps, lim_rms, lim_rich, lim_lin = [], [], [], []
    for i in pick:
        try:
            lad = _row_ladder(int(i))
            if lad is None:
                raise ConvergenceError(f"the ladder at Ω = {float(points[i].omega):g} stalled or left the row's orbit")
            if refine is not None and opts.deep_eps is not None and matched[i] and not lad.linear \
                    and abs(lad.last.rms / rms[i] - 1.0) > refine and opts.deep_eps < lad.last.eps:
                lad = _deeper(make, lad, opts)  # not yet in the linear range and still off: narrower, more harmonics
                if _ladder_step(make, lad, float(points[i].omega), L) > LADDER_STEP_GUARD:
                    raise ConvergenceError(f"the deeper ladder at Ω = {float(points[i].omega):g} left the row's orbit")
            lim_eps.append(lad.last.eps)
            lim_rms.append(lad.last.rms)
            lim_rich.append(lad.extrapolated_rms)
            lim_lin.append(lad.linear)
        except RattleError:  # the ladder stalled, or jumped to another orbit (a fold in ε): the row keeps its ε
            lim_eps.append(math.nan)
            lim_rms.append(math.nan)
            lim_rich.append(math.nan)
            lim_lin.append(False)
    return _response(
        rows, status=status, message=message, regularisation=float(regularisation), harmonics=int(harmonics),
        period=int(period), branch=int(branch), origin=origin, limit_index=np.asarray(pick, dtype=int),
        limit_eps=np.array(lim_eps), limit_rms=np.array(lim_rms), limit_richardson=np.array(lim_rich),
        limit_linear=np.array(lim_lin, dtype=bool),
    )


def _period_two_orbit(system: System, integ: ExactIntegrator, omega: float,
                      state: FloatArray) -> NonsmoothOrbit | None:
    """An exact period-2 orbit next to the exact period-1 orbit through ``state`` at ``omega``, one
    of whose multipliers lies near −1: shot over two forcing periods from the period-1 state pushed
    along that multiplier's eigenvector (:func:`~._period_two.pushed_starts`: by 2 %, 10 % and 30 % of
    the orbit's peak-to-peak, either way); None when every shot converges back to the period-1
    orbit or fails."""
    try:
        one = shoot_nonsmooth_orbit(system, omega, state, integrator=integ, max_iterations=30)
    except FLOW_FAILURES:
        return None
    if not one.converged:
        return None
    L = system.length_scale()
    scale = np.array([L, integ.velocity_scale(omega)])
    T = 2.0 * math.pi / omega
    size = max(float(np.ptp(one.trajectory.sample(np.linspace(0.0, T, 65))[0])), 1e-12 * L)
    for z0 in pushed_starts(one.monodromy, one.state0, scale, size, L):
        try:
            two = shoot_nonsmooth_orbit(system, omega, z0, period=2, integrator=integ, max_iterations=40)
        except FLOW_FAILURES:
            continue
        if not two.converged:
            continue
        d = two.trajectory.sample(np.array([0.0, T]))[0]
        if abs(float(d[1] - d[0])) > 1e-3 * size:  # not the period-1 orbit run twice
            return two
    return None


def _period_two_start(make2: Callable[[float, int], RegularisedBalance], orbit: NonsmoothOrbit, omega: float,
                      eps: float, H2: int, newton: NewtonOptions | None) -> FloatArray | None:
    """The regularised period-2 HB orbit (H2 harmonics of Ω/2) at ε next to the exact period-2
    ``orbit``: Newton from the exact orbit's spectrum, else the homotopy in ε from wider steps; None
    when neither converges to an orbit of period 2 (:data:`ODD_SHARE`)."""
    pb = make2(eps, H2)
    N = pb.basis.samples
    t = np.arange(N) * (2.0 * 2.0 * math.pi / omega / N)
    return period_two_hb(make2, pb.basis.analyze(orbit.trajectory.sample(t)[0]), omega, eps, H2, newton)


def nonsmooth_subharmonics(
    system: System,
    primary: NonsmoothCheck,
    omega: tuple[float, float],
    options: RegularisationOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
) -> tuple[NonsmoothCheck, ...]:
    """The period-2 branches born at the period doublings of the period-1 branch ``primary``
    (:func:`nonsmooth_response` of ``system`` with the same ``options``) within ``omega``.

    At each period doubling (``primary.bifurcation``, between two matched rows) the exact
    period-1 orbit on the side where a multiplier lies beyond −1 (else on the other side) is
    pushed along that multiplier's eigenvector and shot over two forcing periods: the exact
    period-2 orbit found there seeds the regularised HB of period 2 (2H harmonics of Ω/2, the
    same resolution in time), which is continued both ways until it rejoins a period-1 branch
    (its odd harmonics vanish) or leaves the range. Every point is then checked as on the primary
    branch (steps 2–4 of the module docstring, the exact orbits shot over two forcing periods).
    Where the regularised HB at ε has no period-2 orbit next to the exact one (Newton from the
    exact orbit's spectrum falls back to the period-1 orbit: where friction sticks, the
    regularisation's creep moves the period doubling), the exact branch is followed by exact
    shooting alone over the primary's frequencies (``followed`` "exact shooting", no HB values).
    A period doubling that lies on a branch already found (its other end) starts none. A
    doubling where no exact period-2 orbit is found next to it starts none either; the
    returned branches are what was found, numbered 1, 2, … in order of Ω."""
    if not (isinstance(system, System) and system.is_single_equation):
        raise TypeError(f"`system` must be the single equation's System (System.single), got {system!r}")
    if not isinstance(primary, NonsmoothCheck):
        raise TypeError(f"`primary` must be the NonsmoothCheck of `system`, got {primary!r}")
    lo, hi = check_range(omega)
    opts = RegularisationOptions() if options is None else options
    if not isinstance(opts, RegularisationOptions):
        raise TypeError(f"`options` must be a RegularisationOptions, got {opts!r}")
    make2 = balance_factory(system, period=2)
    H2 = 2 * opts.harmonics
    integ = ExactIntegrator(system)

    def seed(i: int) -> NonsmoothOrbit | None:
        return _period_two_orbit(system, integ, float(primary.omega[i]), primary.states[i])

    def from_seed(w0: float, orbit: NonsmoothOrbit, number: int, origin: str) -> NonsmoothCheck | None:
        q2 = _period_two_start(make2, orbit, w0, opts.regularisation, H2, newton)
        if q2 is None:
            return None
        points, status, message = follow_both_ways(make2(opts.regularisation, H2), q2, w0, lo, hi, continuation,
                                                   newton)
        if not points:
            return None
        return _check_branch(system, make2, opts, points, status, message, branch=number, origin=origin)

    def exact(w0: float, orbit: NonsmoothOrbit, grid: FloatArray, number: int, origin: str) -> NonsmoothCheck:
        return _exact_branch(system, integ, orbit, w0, grid, opts, branch=number, origin=origin)

    return branches_at_doublings(primary, lo, hi, seed, from_seed, exact)


def _exact_branch(system: System, integ: ExactIntegrator, seed: NonsmoothOrbit, omega: float,
                  grid: FloatArray, opts: RegularisationOptions, *, branch: int, origin: str) -> NonsmoothCheck:
    """The exact period-2 branch through ``seed`` (at ``omega``) followed over the frequencies
    ``grid`` each way by Newton shooting over two periods from the orbit at the previous
    frequency (natural continuation), until the shooting fails, its orbit repeats after one
    period (the branch rejoined a period-1 branch) or the grid ends. Used where the regularised
    HB of period 2 has no orbit next to the exact one (e.g. where friction sticks: the
    regularisation's creep moves the period doubling); the rows carry no HB values (nan)."""
    def shoot(w: float, prev: NonsmoothOrbit) -> NonsmoothOrbit | str:
        try:
            orbit = shoot_nonsmooth_orbit(system, w, prev.state0, period=2, integrator=integ, max_iterations=40)
        except FLOW_FAILURES as exc:
            return f"the exact shooting failed at Ω = {w:.6g} ({exc})"
        if not orbit.converged:
            return f"the exact shooting did not converge at Ω = {w:.6g} (a fold or the end of the branch)"
        if _repeats_early(orbit):
            return (f"the shooting at Ω = {w:.6g} lands on an orbit of period 1 (the branch rejoined a period-1 "
                    "branch, or ends at a fold)")
        return orbit

    pairs, ends = follow_exactly(shoot, seed, omega, grid)
    rows: dict[str, list] = {k: [] for k in _ROW_KEYS}
    for w, orbit in pairs:
        rows["omega"].append(w)
        rows["rms_hb"].append(math.nan)
        rows["mult_hb"].append(np.full(2, np.nan + 0j))
        rows["matched"].append(True)
        _add_row(rows, orbit, np.full(2, np.nan + 0j))
    message = "followed by exact shooting alone (the regularised HB of period 2 has no orbit next to the exact one " \
              "there); " + "; ".join(ends)
    return _response(rows, status=Status.SUCCESS, message=message, regularisation=float(opts.regularisation),
                     harmonics=0, period=2, branch=branch, origin=origin, followed="exact shooting",
                     limit_index=np.zeros(0, dtype=int), limit_eps=np.zeros(0), limit_rms=np.zeros(0),
                     limit_richardson=np.zeros(0), limit_linear=np.zeros(0, dtype=bool))


__all__ = ["NonsmoothCheck", "RegularisationOptions", "ShootingOptions", "discontinuous_response", "method_settings",
           "nonsmooth_response", "nonsmooth_subharmonics", "shooting_response"]
