"""One periodic orbit of a chain with Coulomb friction at one forcing frequency.

For x'' + C x' + K x + Σ_e b_e [f_e(δ_e) + r_e(δ_e) sgn δ_e'] = F(t)
(:class:`~rattle.model.System` with its elements' whole laws, n coordinates, m elements, δ_e = a_e · x) at Ω:

1. the regularised harmonic balance (:class:`~rattle.hb.RegularisedSystemBalance`, smooth steps
   of relative width ε, H harmonics) at Ω: started from the linearised chain's steady state at
   wide steps (ε = 0.1, else 0.3) and narrowed to the requested ε by homotopy, with the fallbacks
   of :func:`~rattle.analysis._friction_response.friction_response`'s start (damped Newton; the spectrum of the exact
   orbit reached by simulation);
2. the exact orbit: Newton shooting on the event-driven flow
   (:func:`~rattle.timeint.shoot_friction_orbit`: every element's sticking exact, Filippov; the
   2n multipliers with saltation matrices) from the HB orbit's state (x, x') at t = 0, or from
   ``x0`` when given. Where an element sticks (nearly) the whole period of the exact flow from
   the HB state, the exact orbits form a family (its stuck deflection is free within the friction
   band; M − I singular) and the member held at the HB's mean deflection is shot (``hold``) when
   the plain shooting does not converge on the HB's orbit. When that fails too, the exact flow is
   run for :data:`SETTLE_PERIODS` periods and the shooting restarted from where it arrived (the
   orbit the motion settles on, if it is stable; elements stuck a whole period there held where
   they stuck);
3. when the HB of step 1 fails and an exact orbit was found, the HB is solved at ε from the exact
   orbit's spectrum.

The result (:class:`~rattle.results.FrictionOrbitResult`) keeps both orbits per element: the exact
one is the answer (rms, mean, stick fraction and phases, multipliers), the HB series its
regularised approximation, and the HB orbit's own multipliers beside the exact ones: by the
options' ``stability``, ``"saltation"`` the non-smooth monodromy of one period of the exact flow
from its state, ``"regularised"`` the smooth monodromy of the regularised chain along the HB orbit
(:func:`~rattle.stability.regularised_system_multipliers`).

Cost: one HB ladder of n(2H + 1) unknowns (a dense Jacobian), one period of exact flow from the
HB state and one shooting of a few ms per Newton step (plus 100 periods of exact flow when
settling).
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from .._typing import FloatArray
from .._validate import as_float_array, check_omega
from ..errors import ConvergenceError, RattleError, Status
from ..hb import RegularisedSystemBalance
from ..model import System
from ..results import FrictionOrbitResult, HeldLimitRecord
from ..stability import regularised_system_multipliers
from ..timeint import FLOW_FAILURES, ExactIntegrator, FrictionOrbit, FrictionTrajectory, shoot_friction_orbit
from ._friction_response import (
    REPEAT_TOL,
    _departures,
    _hb_flow,
    _hb_multipliers,
    _hb_samples,
    _orbit_spectrum,
    _settled,
    _start,
    _stuck_elements,
    chain_options,
    friction_balance_factory,
    period_gap,
)
from ._held_limit import held_limit
from ._regularisation import RegularisationOptions

#: Periods of the exact flow run before shooting again when the shooting from the start fails.
SETTLE_PERIODS = 100
#: Equally spaced samples per period of the result (every event time is added).
ORBIT_POINTS = 512


def _check_x0(value: object, n: int) -> FloatArray:
    """``x0``: a finite state (x_1 … x_n, x'_1 … x'_n) of shape (2n,)."""
    z = as_float_array(value, "x0", f"a state (x, x') of {2 * n} numbers")
    if z.shape != (2 * n,) or not np.all(np.isfinite(z)):
        raise ValueError(f"`x0` must be a finite state (x_1 … x_n, x'_1 … x'_n) of shape ({2 * n},) for a chain "
                         f"of n = {n} coordinates, got {value!r}")
    return z.copy()


def _shoot(system: System, omega: float, z0: FloatArray, integ: ExactIntegrator,
           hold: dict[int, float] | None = None, period: int = 1) -> tuple[FrictionOrbit | None, str]:
    """The exact orbit of ``period`` forcing periods from ``z0`` (``hold`` the elements held), or
    (None, why)."""
    try:
        orbit = shoot_friction_orbit(system, omega, z0, period=period, integrator=integ, max_iterations=30,
                                     hold=hold or None)
    except FLOW_FAILURES as exc:  # e.g. the event budget of a chattering orbit, a loop of stuck elements
        return None, f"{type(exc).__name__}: {exc}"
    if not orbit.converged:
        return None, f"Newton shooting stopped after {orbit.iterations} steps at residual {orbit.residual:.3g}"
    if hold and not all(orbit.stick_fraction[e] >= 1.0 - 1e-9 for e in hold):
        return None, "an element held at its stuck deflection slipped on the orbit found"
    return orbit, ""


def _gap(orbit: FrictionOrbit, pb: RegularisedSystemBalance, E: FloatArray, omega: float, free: list[int]) -> float:
    """The largest departure of the exact δ_e(t) (``free`` elements) from the HB's (series rows
    ``E``) on 64 samples, relative to the HB δ_e's peak-to-peak."""
    t = np.arange(64) * (2.0 * math.pi / omega / 64)
    d_hb = _hb_samples(pb, E, omega, t)
    size = np.maximum(np.ptp(d_hb, axis=0), 1e-12 * max(float(np.max(np.abs(d_hb))), 1e-300))
    gap = _departures(orbit.trajectory, d_hb, t, size)
    return float(np.max(gap[free])) if free else 0.0


def friction_orbit(
    system: System,
    omega: float,
    options: RegularisationOptions | None = None,
    *,
    x0: FloatArray | None = None,
    period: int = 1,
    every: bool = True,
) -> FrictionOrbitResult:
    """The periodic orbit of the chain with friction ``system`` at forcing frequency ``omega``
    (module docstring), with the HB settings ``options``
    (:class:`~rattle.analysis.RegularisationOptions`: ``harmonics`` H, ``regularisation`` ε,
    ``match`` and ``stability``, how the HB orbit's own multipliers are found; the ladder settings
    are not used here. None: :func:`~rattle.analysis._friction_response.chain_options`). ``x0`` = (x, x') at
    t = 0 (2n numbers) starts the exact shooting instead of the HB orbit's state. ``period`` 2:
    the period-doubled orbit (:func:`_period_two`; raises ConvergenceError where the motion has
    period 1).

    A failed exact shooting is reported in the result (``converged`` False, ``message``); a failed
    HB leaves nan series. Raises :class:`~rattle.errors.ConvergenceError` when neither is found,
    TypeError/ValueError on bad arguments (``system`` not a System, ``omega`` not finite
    and > 0, ``options`` not a RegularisationOptions or with too few harmonics for the
    excitation, ``x0`` not a finite state of shape (2n,), ``period`` not 1 or 2).

    ``every`` (default True): the result also lists every orbit at Ω, stable and unstable, of
    every period, and the non-periodic attractors there (``solutions``, ``nonperiodic``:
    :func:`~rattle.analysis._census.exact_orbits_at`, the census of the window Ω (1 ± 0.05): a few
    seconds of exact continuation and simulation)."""
    if isinstance(period, bool) or not isinstance(period, (int, np.integer)) or period not in (1, 2):
        raise ValueError(f"`period` must be 1 or 2, got {period!r}")
    if not isinstance(every, bool):
        raise TypeError(f"`every` must be True or False, got {every!r}")
    if every:  # the orbit asked for, then every orbit at Ω beside it
        from ._census import with_every_orbit

        return with_every_orbit(system, friction_orbit(system, omega, options, x0=x0, period=period, every=False))
    if period == 2:
        return _period_two(system, omega, options, x0)
    if not (isinstance(system, System) and system.discontinuous):
        raise TypeError(f"`system` must be a rattle.model.System with its elements' whole laws "
                        f"(Chain.friction_system()), got {system!r}")
    omega = check_omega(omega)
    opts = chain_options(system) if options is None else options
    if not isinstance(opts, RegularisationOptions):
        raise TypeError(f"`options` must be a RegularisationOptions or None, got {opts!r}")
    n, m = system.n, system.m
    start_x = None if x0 is None else _check_x0(x0, n)
    H, eps = opts.harmonics, opts.regularisation
    make = friction_balance_factory(system)
    problem = make(eps, H)  # raises on too few harmonics for the excitation
    integ = ExactIntegrator(system)
    notes: list[str] = []

    # 1. the regularised HB at Ω
    q: FloatArray | None = None
    hb_start = ""
    try:
        q = _start(make, omega, eps, H, None)
        hb_start = "linear"
    except RattleError as exc:
        notes.append(f"the regularised HB failed ({exc})")
    E = problem.element_series(q) if q is not None else None
    z_hb = problem.state_at_zero(q, omega) if q is not None else None
    hb_flow = _hb_flow(integ, z_hb, omega) if z_hb is not None else None

    # 2. the exact orbit
    orbit: FrictionOrbit | None = None
    start, held_set = "", [] if E is None else _stuck_elements(hb_flow)
    held: dict[int, float] = {}
    if start_x is not None:
        orbit, why = _shoot(system, omega, start_x, integ)
        start = "x0"
        if orbit is None:
            notes.append(f"shooting from `x0` failed ({why})")
    elif z_hb is not None:
        if held_set:  # a family of orbits: the member held at the HB's mean deflection first
            assert E is not None
            hold = {e: float(E[e][0]) for e in held_set}
            free = [e for e in range(m) if e not in held_set]
            orbit, why = _shoot(system, omega, z_hb, integ, hold)
            if orbit is not None and _gap(orbit, problem, E, omega, free) <= opts.match:
                start, held = "held", hold
                names = ", ".join(system.element_names[e] for e in held_set)
                notes.append(f"{names} stuck the whole period, held at the HB's mean deflection")
            else:
                notes.append(f"shooting with {', '.join(system.element_names[e] for e in held_set)} held at the "
                             "HB's mean deflection " + (f"failed ({why})" if orbit is None else "missed the HB orbit"))
                orbit = None
        if orbit is None:
            orbit, why = _shoot(system, omega, z_hb, integ)
            start = "hb"
            if orbit is None:
                notes.append(f"shooting from the HB state failed ({why})")
    if orbit is None:
        origin = start_x if start_x is not None else (z_hb if z_hb is not None else None)
        where = "`x0`" if start_x is not None else ("the HB state" if z_hb is not None else "the linearised chain")
        if origin is None:
            origin = problem.state_at_zero(problem.linear_solution(omega), omega)
        settled = _settled(integ, origin, omega, SETTLE_PERIODS)
        if settled is None:
            notes.append(f"the exact flow from {where} could not be followed for {SETTLE_PERIODS} periods")
        else:
            orbit, why = _shoot(system, omega, settled, integ)
            if orbit is None:
                stuck = _stuck_elements(_hb_flow(integ, settled, omega))
                if stuck:
                    rows = system.element_rows.reshape(m, n)
                    hold = {e: float(rows[e] @ settled[:n]) for e in stuck}
                    orbit, why = _shoot(system, omega, settled, integ, hold)
                    if orbit is not None:
                        held = hold
            if orbit is not None:
                start = "settled"
                notes.append(f"settled for {SETTLE_PERIODS} periods from {where}, then shooting converged")
            else:
                start = ""
                notes.append(f"shooting after settling for {SETTLE_PERIODS} periods from {where} failed ({why})")

    # 3. the HB from the exact orbit's spectrum when the first failed
    if q is None and orbit is not None:
        try:
            q = _start_from(make, _orbit_spectrum(problem, orbit.trajectory, omega), omega, eps, H)
            hb_start = "exact"
            notes.append("the HB was solved from the exact orbit's spectrum")
        except RattleError as exc:
            notes.append(f"the HB from the exact orbit's spectrum failed too ({exc})")
        if q is not None:
            E = problem.element_series(q)
            hb_flow = _hb_flow(integ, problem.state_at_zero(q, omega), omega)
    if q is None and orbit is None:
        raise ConvergenceError(f"no periodic orbit at `omega` = {omega:g}: " + "; ".join(notes)
                               + "; try another `regularisation` or `harmonics`, or give `x0`")
    if orbit is None:
        notes.insert(0, f"no exact orbit at Ω = {omega:g}")
    record = _held(system, make, omega, opts, orbit, q, notes) if opts.held else None
    return _result(system, problem, omega, opts, orbit, q, E, hb_flow, start, hb_start, held, notes,
                   held_record=record)


def _held(system: System, make, omega: float, opts: RegularisationOptions,  # type: ignore[no-untyped-def]
          orbit: FrictionOrbit | None, q: FloatArray | None, notes: list[str]) -> HeldLimitRecord | None:
    """The HB with the steps of the elements the exact orbit holds part of the period (0 < stick
    fraction < 1) narrowed to their limit: the chain's ε first continued to ``limit_eps`` (if
    wider), then :func:`~rattle.analysis._held_limit.held_limit` at ``held_harmonics``. None
    without an exact and an HB orbit or a held element, or when the ladder fails (said in
    ``notes``)."""
    if orbit is None or q is None:
        return None
    elements = [e for e in range(system.m) if 0.0 < float(orbit.stick_fraction[e]) < 1.0]
    if not elements:
        return None
    t0 = time.perf_counter()
    H, eps = opts.harmonics, opts.regularisation
    try:
        if opts.limit_eps < eps:
            from ._regularisation import regularisation_limit

            q = regularisation_limit(make, omega, q, eps_start=eps, eps_min=opts.limit_eps, harmonics=H,
                                     max_harmonics=H, tail_tol=math.inf).last.q
            eps = opts.limit_eps
        hl = held_limit(make(eps, H), q, omega, elements, harmonics=opts.held_harmonics)
    except RattleError as exc:
        notes.append(f"the held elements' ladder failed ({exc})")
        return None
    return HeldLimitRecord(elements=tuple(system.element_names[e] for e in hl.elements), rms=hl.rms,
                           status=hl.status, scale=hl.scale, eps=float(eps), harmonics=hl.harmonics,
                           samples=int(hl.samples[-1]), change=hl.change, seconds=time.perf_counter() - t0)


def _period_two(system: System, omega: float, options: RegularisationOptions | None,
                x0: FloatArray | None) -> FrictionOrbitResult:
    """The period-2 orbit of the chain at ``omega``: the exact one first, then its regularised HB
    of period 2.

    1. The period-1 orbit (:func:`friction_orbit`, from ``x0`` or the HB state); where one of its
       multipliers lies beyond −1 the period-2 orbit next to it is shot from it pushed along that
       multiplier's eigenvector (:func:`~rattle.analysis._friction_subharmonics.period_two_orbit`);
    2. else the exact flow is run for 2 × :data:`SETTLE_PERIODS` forcing periods from ``x0`` (or
       the period-1 orbit's state, or rest) and shot over two periods from where it arrived;
    3. an orbit that repeats after one period is not one of period 2; the HB of period 2 (2H
       harmonics of Ω/2) is solved from the exact orbit's spectrum (nan when it falls back to
       period 1, as where friction sticks).

    Raises :class:`~rattle.errors.ConvergenceError` when no exact orbit of period 2 is found."""
    from ._friction_subharmonics import _period_two_start, period_two_orbit
    from ._period_two import beyond_minus_one

    one = friction_orbit(system, omega, options, x0=x0, every=False)  # validates every argument
    opts = chain_options(system) if options is None else options
    n = system.n
    integ = ExactIntegrator(system)
    notes: list[str] = []
    seed, start = None, ""
    if one.converged and beyond_minus_one(one.multipliers):
        seed = period_two_orbit(system, integ, omega, one.state0)
        start = "x0" if x0 is not None else "hb"
        if seed is None:
            notes.append("the period-1 orbit is unstable by a multiplier beyond −1, but no period-2 orbit was found "
                         "next to it")
    if seed is None:
        where = "`x0`" if x0 is not None else ("the period-1 orbit" if one.converged else "rest")
        origin = _check_x0(x0, n) if x0 is not None else (one.state0 if one.converged else np.zeros(2 * n))
        settled = _settled(integ, origin, omega, 2 * SETTLE_PERIODS)
        if settled is None:
            notes.append(f"the exact flow from {where} could not be followed for {2 * SETTLE_PERIODS} periods")
        else:
            orbit, why = _shoot(system, omega, settled, integ, period=2)
            if orbit is None:
                notes.append(f"the motion settled from {where} could not be shot over two periods ({why})")
            elif period_gap(orbit.trajectory, omega) <= REPEAT_TOL:
                notes.append(f"the motion settled from {where} repeats after one forcing period")
            else:
                seed, start = orbit, "settled"
    if seed is None:
        raise ConvergenceError(f"no periodic orbit of period 2 at `omega` = {omega:g}: " + "; ".join(notes)
                               + "; the orbit there is of period 1 (rattle orbit without --period), or, in the "
                               "library, give `x0` near a period-2 motion")
    H2 = 2 * opts.harmonics
    opts2 = dataclasses.replace(opts, harmonics=H2, limit_harmonics=max(opts.limit_harmonics, H2),
                                deep_harmonics=max(opts.deep_harmonics, H2))
    make2 = friction_balance_factory(system, period=2)
    problem = make2(opts.regularisation, H2)
    q = _period_two_start(make2, seed, omega, opts.regularisation, H2, None)
    E = hb_flow = None
    if q is None:
        notes.append("the regularised HB of period 2 has no orbit next to the exact one (it falls back to period 1): "
                     "only the exact orbit is given")
    else:
        E = problem.element_series(q)
        hb_flow = _hb_flow(integ, problem.state_at_zero(q, omega), omega, 2)
    return _result(system, problem, omega, opts2, seed, q, E, hb_flow, start, "exact" if q is not None else "", {},
                   notes, periods=2)


def _start_from(make, q0: FloatArray, omega: float, eps: float, H: int) -> FloatArray:  # type: ignore[no-untyped-def]
    """The HB at ε from the series ``q0`` (Newton at ε; raises RattleError)."""
    from ._regularisation import regularisation_limit

    return regularisation_limit(make, omega, q0, eps_start=eps, eps_min=eps, harmonics=H, max_harmonics=H,
                                tail_tol=math.inf).last.q


def _result(system: System, problem: RegularisedSystemBalance, omega: float, opts: RegularisationOptions, orbit: FrictionOrbit | None,
            q: FloatArray | None, E: FloatArray | None, hb_flow: FrictionTrajectory | None, start: str,
            hb_start: str, held: dict[int, float], notes: list[str], periods: int = 1,
            held_record: HeldLimitRecord | None = None) -> FrictionOrbitResult:
    """The result's samples and measures (:class:`~rattle.results.FrictionOrbitResult`) over the
    orbit's ``periods`` forcing periods (``problem``'s and ``opts``' H those of that period)."""
    n, m, H = system.n, system.m, opts.harmonics
    T = periods * 2.0 * math.pi / omega
    t = np.linspace(0.0, T, ORBIT_POINTS + 1)
    nan_m = np.full(m, math.nan)
    if orbit is not None:
        tr = orbit.trajectory
        ev = tr.event_times
        t = np.unique(np.concatenate((t, ev[(ev >= 0.0) & (ev <= T)])))
        delta, velocity, _ = tr.element_samples(t)
        stuck = np.asarray(tr.stuck, dtype=bool)[tr.segment_index(t)]
        intervals = tuple(tuple(tr.stick_intervals(e)) for e in range(m))
        rms, mean, frac = orbit.rms.copy(), orbit.mean.copy(), orbit.stick_fraction.copy()
        mult, state0 = np.asarray(orbit.multipliers, dtype=complex), orbit.state0.copy()
    else:
        delta, velocity = np.full((t.size, m), math.nan), np.full((t.size, m), math.nan)
        stuck = np.zeros((t.size, m), dtype=bool)
        intervals = tuple(() for _ in range(m))
        rms, mean, frac = nan_m.copy(), nan_m.copy(), nan_m.copy()
        mult, state0 = np.full(2 * n, complex(math.nan, math.nan)), np.full(2 * n, math.nan)
    if E is not None:
        coeff = np.asarray(E, dtype=float)
        rms_hb = np.sqrt(coeff[:, 0] ** 2 + 0.5 * np.sum(coeff[:, 1:] ** 2, axis=1))
    else:
        coeff, rms_hb = np.full((m, 2 * H + 1), math.nan), nan_m.copy()
    mult_hb = np.full(2 * n, complex(math.nan, math.nan))
    mu = None
    if q is not None and opts.stability == "regularised":
        try:
            mu = regularised_system_multipliers(problem, q, omega)
        except FLOW_FAILURES:
            mu = None
    elif q is not None:
        mu = _hb_multipliers(hb_flow)
    if mu is not None and np.all(np.isfinite(mu)):
        mult_hb = mu
    delta_hb = _hb_samples(problem, coeff, omega, t)
    rpm = system.speed_rpm(omega)
    return FrictionOrbitResult(
        omega=omega, speed_rpm=None if rpm is None else float(rpm), element_names=system.element_names,  # type: ignore[arg-type]
        t=t, delta=delta, velocity=velocity, stuck=stuck, stick_intervals=intervals, rms=rms, mean=mean,
        stick_fraction=frac, multipliers=mult, state0=state0, converged=orbit is not None,
        status=Status.CONVERGED if orbit is not None else Status.MAX_ITERATIONS, message="; ".join(notes),
        start=start, coefficients_hb=coeff, delta_hb=delta_hb, rms_hb=rms_hb, multipliers_hb=mult_hb,
        regularisation=float(opts.regularisation), harmonics=int(H), hb_start=hb_start, match=float(opts.match),
        held=tuple(system.element_names[e] for e in held), settle_periods=SETTLE_PERIODS, periods=periods,
        held_limit=held_record,
    )


__all__ = ["FrictionOrbitResult", "friction_orbit"]
