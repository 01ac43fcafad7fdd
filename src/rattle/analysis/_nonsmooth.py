"""Frequency response of a discontinuous law (preload, friction): regularised HB, checked exactly.

For δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t) (:class:`~rattle.model.NonsmoothSystem`):

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
   then measured at its limit, row by row.

Cost: one continuation of 2H + 1 unknowns plus one exact shooting and one exact period (the HB
orbit's monodromy; a few ms) per point, and a ladder (0.5–2 s) per row checked at the limit or
refined, found once per row: a row checked at the limit and then refined shares it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .._typing import FloatArray
from .._validate import check_range
from ..continuation import ContinuationOptions, ContinuationStepper, NewtonOptions
from ..errors import ConvergenceError, RattleError, Status
from ..hb import HBOptions, RegularisedBalance
from ..model import FrictionSystem, NonsmoothSystem
from ..results import FrictionResponse, NonsmoothResponse
from ..stability import regularised_multipliers
from ..timeint import NonsmoothIntegrator, NonsmoothOrbit, NonsmoothTrajectory, shoot_nonsmooth_orbit
from ..timeint._shooting import FLOW_FAILURES, monodromy_multipliers
from ._regularisation import (
    RegularisationLimit,
    RegularisationOptions,
    regularisation_limit,
)


#: Samples of the period on which the exact δ(t) is compared with the HB's.
MATCH_SAMPLES = 64


def _rms(q: FloatArray, H: int) -> float:
    return math.sqrt(q[0] ** 2 + 0.5 * float(np.sum(q[1:] ** 2)))


def _hb_flow(integ: NonsmoothIntegrator, state: tuple[float, float], omega: float) -> NonsmoothTrajectory | None:
    """One period of the exact flow from ``state`` (the HB orbit's at t = 0); None when it cannot
    be followed (the event budget of a chattering flow)."""
    try:
        return integ.propagate(np.asarray(state, dtype=float), 0.0, 2.0 * math.pi / omega, omega)
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


def _departure(problem: RegularisedBalance, q: FloatArray, omega: float, traj: NonsmoothTrajectory,
               scale: float) -> float:
    """The largest departure of the exact δ(t) on ``traj`` from the HB orbit ``q`` of ``problem``
    on :data:`MATCH_SAMPLES` samples of the period, relative to ``scale``."""
    t = np.arange(MATCH_SAMPLES) * (2.0 * math.pi / omega / MATCH_SAMPLES)
    return float(np.max(np.abs(traj.sample(t)[0] - problem.basis.evaluate(q, omega, t)))) / scale


def _holds(flow: NonsmoothTrajectory | None, orbit: NonsmoothOrbit | None) -> bool:
    """Whether δ sticks or locks some of the period on the exact ``flow`` from the HB state or on
    the converged exact ``orbit``."""
    trajs = [flow] + ([orbit.trajectory] if orbit is not None and orbit.converged else [])
    return any(tr is not None and tr.stick_time > 0.0 for tr in trajs)


def _match_at_limit(make: Callable[[float, int], RegularisedBalance], system: NonsmoothSystem,
                    integ: NonsmoothIntegrator, omega: float, lad: RegularisationLimit,
                    L: float) -> tuple[NonsmoothOrbit, float] | None:
    """The exact orbit shot from the HB state at the end of the ε ladder ``lad`` and its departure
    from that HB orbit, relative to that HB δ's peak-to-peak; None when the shooting fails."""
    last = lad.last
    pb = make(last.eps, last.harmonics)
    d0, v0 = (float(a[0]) for a in pb.samples(last.q, omega))
    try:
        orbit = shoot_nonsmooth_orbit(system, omega, (d0, v0), integrator=integ, max_iterations=30)
    except FLOW_FAILURES:
        return None
    if not orbit.converged:
        return None
    if _ladder_step(make, lad, omega, L) > LADDER_STEP_GUARD:
        return orbit, math.inf  # the ladder left the row's branch: its end is another orbit's
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
    t = np.arange(MATCH_SAMPLES) * (2.0 * math.pi / omega / MATCH_SAMPLES)
    prev: FloatArray | None = None
    worst = 0.0
    for step in lad.steps:
        d = make(step.eps, step.harmonics).basis.evaluate(step.q, omega, t)
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


def balance_factory(system: NonsmoothSystem) -> Callable[[float, int], RegularisedBalance]:
    """``make(ε, H)``: the regularised HB of ``system`` at relative width ε with H harmonics, on
    the scales every front end uses (the law's length scale L, ω_n = √(k s_max))."""
    exc = system.excitation
    L = system.length_scale()
    wn = math.sqrt(system.k * float(np.max(system.law.stages.slopes)))

    def make(eps: float, H: int) -> RegularisedBalance:
        return RegularisedBalance(system.c, system, exc.mean, exc.amplitudes, exc.phases, regularisation=eps,
                                  length_scale=L, frequency_scale=wn, options=HBOptions(harmonics=H))

    return make


def nonsmooth_response(
    system: NonsmoothSystem | FrictionSystem,
    omega: tuple[float, float],
    options: RegularisationOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
) -> NonsmoothResponse | FrictionResponse:
    """The period-1 branch over ``omega`` = (Ω_min, Ω_max), from Ω_min (module docstring), with
    the settings ``options`` (:class:`RegularisationOptions`). A chain with friction
    (:class:`~rattle.model.FrictionSystem`) goes to
    :func:`~rattle.analysis._friction_response.friction_response` (a :class:`FrictionResponse`)."""
    if isinstance(system, FrictionSystem):
        from ._friction_response import friction_response

        return friction_response(system, omega, options, continuation=continuation, newton=newton)
    if not isinstance(system, NonsmoothSystem):
        raise TypeError(f"`system` must be a NonsmoothSystem (one equation) or a FrictionSystem (a chain with "
                        f"friction, Chain.friction_system()), got {system!r}")
    lo, hi = check_range(omega)
    opts = RegularisationOptions() if options is None else options
    if not isinstance(opts, RegularisationOptions):
        raise TypeError(f"`options` must be a RegularisationOptions, got {opts!r}")
    harmonics, regularisation, match = opts.harmonics, opts.regularisation, opts.match
    limit, limit_eps, limit_harmonics, refine = opts.limit, opts.limit_eps, opts.limit_harmonics, opts.refine
    make = balance_factory(system)
    L = system.length_scale()
    problem = make(regularisation, harmonics)
    # the start: solved where the steps are wide (ε = 0.1), then narrowed to ε by homotopy
    start = regularisation_limit(make, lo, np.zeros(problem.size), eps_start=max(0.1, regularisation),
                                 eps_min=regularisation, harmonics=harmonics, max_harmonics=harmonics,
                                 tail_tol=math.inf).last.q
    stepper = ContinuationStepper(problem, start, lo, (lo, hi),
                                  options=continuation or ContinuationOptions(),
                                  newton=newton or NewtonOptions())
    points = stepper.run()
    integ = NonsmoothIntegrator(system)
    rows: dict[str, list] = {k: [] for k in ("omega", "rms_hb", "rms", "stable", "mult", "mult_hb", "stick", "matched",
                                             "mean", "p2p", "acc_p2p", "regime", "sticks", "crossings")}
    ladders: dict[int, RegularisationLimit | None] = {}  # row: its ladder (None: it stalled)

    def _row_ladder(i: int) -> RegularisationLimit | None:
        """Row i's ladder (ε → ``limit_eps``, H ≤ ``limit_harmonics``), found once: the match at
        the limit and the refinement share it."""
        if i not in ladders:
            try:
                ladders[i] = regularisation_limit(make, float(points[i].omega), points[i].q, eps_start=regularisation,
                                                  eps_min=min(limit_eps, regularisation), harmonics=harmonics,
                                                  max_harmonics=max(limit_harmonics, harmonics))
            except RattleError:
                ladders[i] = None
        return ladders[i]

    for i, pt in enumerate(points):
        w, q = float(pt.omega), pt.q
        rms_hb = _rms(q, harmonics)
        d0, v0 = (float(a[0]) for a in problem.samples(q, w))
        flow = _hb_flow(integ, (d0, v0), w) if opts.stability == "saltation" else None
        mu_hb = _hb_multipliers(problem, flow, q, w, opts.stability)
        size = max(float(np.ptp(problem.basis.synthesize(q))), 1e-12 * L)
        orbit = None
        try:
            orbit = shoot_nonsmooth_orbit(system, w, (d0, v0), integrator=integ, max_iterations=30)
        except FLOW_FAILURES:  # e.g. the event budget of a chattering orbit
            orbit = None
        shot_failed = orbit is None or not orbit.converged
        ok = not shot_failed
        if ok:  # the same orbit: δ(t) of the two within `match` of the HB orbit's peak-to-peak
            ok = _departure(problem, q, w, orbit.trajectory, size) <= match
        if not ok:
            if flow is None and opts.stability != "saltation":
                flow = _hb_flow(integ, (d0, v0), w)
            if shot_failed or _holds(flow, orbit):
                # the shooting from the HB at ε failed (outside Newton's reach of the exact orbit), or
                # δ sticks or locks part of the period, which the HB at ε resolves only to the steps'
                # width: the exact orbit is the limit of the HB's as ε → 0 when the flow shot from
                # the HB at the ladder's end matches that HB orbit
                lad = _row_ladder(i)
                found = None if lad is None else _match_at_limit(make, system, integ, w, lad, L)
                if found is not None and found[1] <= match:
                    orbit, ok = found[0], True
        rows["omega"].append(w)
        rows["rms_hb"].append(rms_hb)
        rows["mult_hb"].append(mu_hb)
        rows["matched"].append(ok)
        if ok:
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
        else:
            rows["sticks"].append(-1)
            rows["crossings"].append(-1)
            for key in ("rms", "mean", "p2p", "acc_p2p", "stick"):
                rows[key].append(math.nan)
            rows["regime"].append("")
            rows["mult"].append(mu_hb)
            rows["stable"].append(bool(np.all(np.abs(mu_hb) < 1.0)))
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
                raise ConvergenceError(f"the ladder stalled at Ω = {float(points[i].omega):g}")
            if refine is not None and opts.deep_eps is not None and matched[i] and not lad.linear \
                    and abs(lad.last.rms / rms[i] - 1.0) > refine and opts.deep_eps < lad.last.eps:
                lad = _deeper(make, lad, opts)  # not yet in the linear range and still off: narrower, more harmonics
            lim_eps.append(lad.last.eps)
            lim_rms.append(lad.last.rms)
            lim_rich.append(lad.extrapolated_rms)
            lim_lin.append(lad.linear)
        except RattleError:  # the ladder stalled: the row keeps its ε
            lim_eps.append(math.nan)
            lim_rms.append(math.nan)
            lim_rich.append(math.nan)
            lim_lin.append(False)
    mean = np.array(rows["mean"])
    return NonsmoothResponse(
        omega=np.array(rows["omega"]), rms_hb=rms_hb, mean=mean, rms=rms,
        rms_ac=np.sqrt(np.maximum(rms**2 - mean**2, 0.0)), p2p=np.array(rows["p2p"]),
        acc_p2p=np.array(rows["acc_p2p"]), regime=np.array(rows["regime"], dtype=object),
        stable=np.array(rows["stable"], dtype=bool), multipliers=np.array(rows["mult"]).reshape(-1, 2),
        multipliers_hb=np.array(rows["mult_hb"]).reshape(-1, 2), stick_time=np.array(rows["stick"]),
        sticks=np.array(rows["sticks"], dtype=np.int64), crossings=np.array(rows["crossings"], dtype=np.int64),
        matched=matched, status=stepper.status or Status.SUCCESS,
        message=stepper.message, regularisation=float(regularisation), harmonics=int(harmonics),
        limit_index=np.asarray(pick, dtype=int), limit_eps=np.array(lim_eps), limit_rms=np.array(lim_rms),
        limit_richardson=np.array(lim_rich), limit_linear=np.array(lim_lin, dtype=bool),
    )


__all__ = ["NonsmoothResponse", "RegularisationOptions", "nonsmooth_response"]
