"""One periodic orbit of a discontinuous law (preload, friction) at one forcing frequency.

For δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t) (single-equation :class:`~rattle.model.System`) at Ω:

1. the regularised harmonic balance (:class:`~rattle.hb.RegularisedBalance`, smooth steps of
   relative width ε, H harmonics) is solved at Ω from rest where the steps are wide (ε = 0.1) and
   narrowed to the requested ε by the homotopy of
   :func:`~rattle.analysis._regularisation.regularisation_limit` — the start of
   :func:`rattle.frequency_response` (a law with jumps or friction), at one Ω;
2. the exact orbit: Newton shooting on the event-driven flow
   (:func:`~rattle.timeint.shoot_nonsmooth_orbit`: crossings, sticking and locking exact, the
   monodromy with saltation matrices) from the HB orbit's state (δ, δ') at t = 0, or from ``x0``
   when given. When that fails (no convergence, or the integrator gives up), the exact flow is run
   for 100 periods from the same state and the shooting restarted from where it arrived (the
   orbit the motion settles on, if it is stable);
3. when the ladder of step 1 fails (Newton stalls while ε narrows), the exact orbit is found by
   settling from ``x0`` or from rest, and the HB is solved at ε from the exact orbit's spectrum
   (:meth:`~rattle.timeint.NonsmoothTrajectory.fourier`).

The result (:class:`~rattle.results.NonsmoothOrbitResult`) keeps both orbits: the exact one is the
answer (rms, multipliers, stick and lock phases), the HB series is its regularised approximation.

Cost: one ladder of HB solves (2H + 1 unknowns) and one shooting of a few ms (plus 100 periods of
the exact flow when settling).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .._typing import FloatArray
from .._validate import check_omega, check_state
from ..errors import ConvergenceError
from ..hb import RegularisedBalance
from ..model import System
from ..results import FrictionOrbitResult, NonsmoothOrbitResult
from ..timeint import FLOW_FAILURES, ExactIntegrator, NonsmoothOrbit, shoot_nonsmooth_orbit
from ._nonsmooth import RegularisationOptions, balance_factory
from ._regularisation import regularisation_limit

#: Periods of the exact flow run from the HB state before shooting again when the direct shooting fails.
SETTLE_PERIODS = 100


def _hb_orbit(make: Callable[[float, int], RegularisedBalance], omega: float, q0: FloatArray, eps_start: float,
              opts: RegularisationOptions) -> tuple[FloatArray, FloatArray]:
    """The HB coefficients at ``omega`` (the ladder from ``eps_start`` down to ``opts.regularisation``
    started at ``q0``) and the HB orbit's state (δ, δ') at t = 0; raises ConvergenceError."""
    problem = make(opts.regularisation, opts.harmonics)
    q = regularisation_limit(make, omega, q0, eps_start=eps_start, eps_min=opts.regularisation,
                             harmonics=opts.harmonics, max_harmonics=opts.harmonics, tail_tol=math.inf).last.q
    d0, v0 = (float(a[0]) for a in problem.samples(q, omega))
    return q, np.array([d0, v0])


def _shoot(system: System, omega: float, x0: FloatArray, integ: ExactIntegrator, period: int = 1,
           max_iterations: int = 30) -> tuple[NonsmoothOrbit | None, str]:
    """The exact orbit of ``period`` forcing periods from ``x0``, or (None, why)."""
    try:
        orbit = shoot_nonsmooth_orbit(system, omega, x0, period=period, integrator=integ,
                                      max_iterations=max_iterations)
    except FLOW_FAILURES as exc:  # e.g. the event budget of a chattering orbit
        return None, f"{type(exc).__name__}: {exc}"
    if not orbit.converged:
        return None, f"Newton shooting stopped after {orbit.iterations} steps at residual {orbit.residual:.3g}"
    return orbit, ""


def _settle_and_shoot(system: System, omega: float, x0: FloatArray, integ: ExactIntegrator,
                      period: int = 1, max_iterations: int = 30) -> tuple[NonsmoothOrbit | None, str]:
    """The exact flow run for :data:`SETTLE_PERIODS` orbit periods (× ``period`` forcing periods)
    from ``x0``, then shot over ``period`` forcing periods; or (None, why)."""
    try:
        settled = integ.propagate(x0, 0.0, SETTLE_PERIODS * period * 2.0 * math.pi / omega, omega).state1
    except FLOW_FAILURES as exc:
        return None, f"{type(exc).__name__}: {exc}"
    return _shoot(system, omega, settled, integ, period, max_iterations)


def nonsmooth_orbit(
    system: System,
    omega: float,
    options: RegularisationOptions | None = None,
    *,
    x0: FloatArray | tuple[float, float] | None = None,
    period: int = 1,
    every: bool = True,
) -> NonsmoothOrbitResult | FrictionOrbitResult:
    """The periodic orbit at forcing frequency ``omega`` (module docstring), with the HB settings
    ``options`` (:class:`RegularisationOptions`: ``harmonics``, ``regularisation`` and ``match``;
    the ladder settings are not used here). ``x0`` = (δ, δ') at t = 0 starts the exact shooting
    instead of the HB orbit's state.

    When the HB ladder from rest fails, the exact orbit is sought by settling from ``x0`` (or from
    rest) and the HB is then solved from the exact orbit's spectrum (``hb_start`` ``"exact"``).
    A failed exact shooting is reported in the result (``orbit`` None, ``message``); a failed HB
    leaves nan coefficients. Raises :class:`~rattle.errors.ConvergenceError` when neither is found.

    ``period`` 2 asks for a sub-harmonic orbit of period 2 (:func:`_period_two`; a chain's likewise
    in :func:`~rattle.analysis._friction_orbit.friction_orbit`): found from the exact flow, its HB of
    period 2 solved from its spectrum.

    A chain with friction on its elements (:class:`~rattle.model.System` with its elements' whole laws) goes to
    :func:`~rattle.analysis._friction_orbit.friction_orbit` (a :class:`FrictionOrbitResult`;
    ``x0`` then the chain's state (x, x'), 2n values).

    ``every`` (default True): the result also lists every orbit at Ω, stable and unstable, of
    every period, and the non-periodic attractors there (``solutions``, ``nonperiodic``:
    :func:`~rattle.analysis._census.exact_orbits_at`, the census of the window Ω (1 ± 0.05): a few
    seconds of exact continuation and simulation); ``every=False`` computes the one orbit only.
    """
    if isinstance(period, bool) or not isinstance(period, (int, np.integer)) or period not in (1, 2):
        raise ValueError(f"`period` must be 1 or 2 (a period-2 sub-harmonic orbit), got {period!r}")
    if not isinstance(every, bool):
        raise TypeError(f"`every` must be True or False, got {every!r}")
    if isinstance(system, System) and system.discontinuous and not system.is_single_equation:
        from ._friction_orbit import friction_orbit

        return friction_orbit(system, omega, options, x0=x0, period=period, every=every)
    if every and isinstance(system, System) and system.is_single_equation:  # the orbit asked for, then every orbit at Ω beside it
        from ._census import with_every_orbit

        return with_every_orbit(system, nonsmooth_orbit(system, omega, options, x0=x0, period=period, every=False))
    if not (isinstance(system, System) and system.is_single_equation):
        raise TypeError(f"`system` must be a System with its whole laws: the single equation's (System.single) or a chain's ("
                        f"friction on its elements; rattle.model), got {system!r}")
    omega = check_omega(omega)
    opts = RegularisationOptions() if options is None else options
    if not isinstance(opts, RegularisationOptions):
        raise TypeError(f"`options` must be a RegularisationOptions, got {opts!r}")
    start_x = None if x0 is None else check_state(x0)
    if period == 2:
        return _period_two(system, omega, opts, start_x)
    H, eps = opts.harmonics, opts.regularisation
    make = balance_factory(system)
    integ = ExactIntegrator(system)
    notes: list[str] = []
    q: FloatArray | None = None
    hb_state = np.full(2, math.nan)
    hb_start = ""
    try:  # the start of nonsmooth_response: wide steps (ε = 0.1) from rest, narrowed to ε
        q, hb_state = _hb_orbit(make, omega, np.zeros(2 * H + 1), max(0.1, eps), opts)
        hb_start = "rest"
    except ConvergenceError as exc:
        notes.append(f"the regularised HB from rest failed ({exc})")
    first = start_x if start_x is not None else (hb_state if q is not None else None)
    first_name = "`x0`" if start_x is not None else "the HB state"
    orbit, start, why = None, "", ""
    if first is not None:
        orbit, why = _shoot(system, omega, first, integ)
        start = "x0" if start_x is not None else "hb"
    if orbit is None:
        origin = first if first is not None else np.zeros(2)
        orbit, why_settled = _settle_and_shoot(system, omega, origin, integ)
        where = first_name if first is not None else "rest"
        if orbit is not None:
            start = "settled"
            if first is not None:
                notes.append(f"shooting from {first_name} failed ({why})")
            notes.append(f"settled for {SETTLE_PERIODS} periods from {where}, then shooting converged")
        else:
            start = ""
            if first is not None:
                notes.append(f"shooting from {first_name} failed ({why})")
            notes.append(f"shooting after settling for {SETTLE_PERIODS} periods from {where} failed ({why_settled})")
    if q is None and orbit is not None:  # the HB started on the exact orbit's spectrum, at ε directly
        try:
            q, hb_state = _hb_orbit(make, omega, orbit.trajectory.fourier(H), eps, opts)
            hb_start = "exact"
            notes.append("the HB was solved from the exact orbit's spectrum")
        except ConvergenceError as exc:
            notes.append(f"the HB from the exact orbit's spectrum failed too ({exc})")
    if q is None and orbit is None:
        raise ConvergenceError(f"no periodic orbit at `omega` = {omega:g}: " + "; ".join(notes)
                               + "; try another `regularisation` or `harmonics`, or give `x0`")
    if orbit is None:
        notes.insert(0, f"no exact orbit at Ω = {omega:g}")
    coefficients = np.asarray(q, dtype=float) if q is not None else np.full(2 * H + 1, math.nan)
    return NonsmoothOrbitResult(system=system, omega=omega, orbit=orbit, message="; ".join(notes), start=start,
                                coefficients=coefficients, regularisation=float(eps), harmonics=int(H),
                                hb_state=hb_state, hb_start=hb_start, match=float(opts.match),
                                settle_periods=SETTLE_PERIODS)


def _period_two(system: System, omega: float, opts: RegularisationOptions,
                x0: FloatArray | None) -> NonsmoothOrbitResult:
    """The period-2 orbit at ``omega``: the exact one first, then its regularised HB of period 2.

    1. The period-1 orbit (as :func:`nonsmooth_orbit`, from ``x0`` or the HB state); where one of
       its multipliers lies beyond −1 the period-2 orbit next to it is shot from it pushed along
       that multiplier's eigenvector (:func:`~rattle.analysis._nonsmooth._period_two_orbit`);
    2. else the exact flow is run for :data:`SETTLE_PERIODS` × 2 forcing periods from ``x0`` (or
       rest) and shot over two periods from where it arrived;
    3. an orbit that repeats after one period is not one of period 2; the HB of period 2 (2H
       harmonics of Ω/2) is solved from the exact orbit's spectrum
       (:func:`~rattle.analysis._nonsmooth._period_two_start`; nan when it falls back to period 1,
       as where friction sticks).

    Raises :class:`~rattle.errors.ConvergenceError` when no exact orbit of period 2 is found."""
    from ._nonsmooth import _period_two_orbit, _period_two_start, _repeats_early
    from ._period_two import beyond_minus_one

    integ = ExactIntegrator(system)
    notes: list[str] = []
    one = nonsmooth_orbit(system, omega, opts, x0=x0, every=False)
    seed, start = None, ""
    if one.orbit is not None:
        if beyond_minus_one(one.orbit.multipliers):
            seed = _period_two_orbit(system, integ, omega, one.orbit.state0)
            start = "hb" if seed is not None else ""
            if seed is None:
                notes.append("the period-1 orbit is unstable by a multiplier beyond −1, but no period-2 orbit was "
                             "found next to it")
    if seed is None:
        where = "`x0`" if x0 is not None else "rest"
        seed, why = _settle_and_shoot(system, omega, x0 if x0 is not None else np.zeros(2), integ, period=2,
                                      max_iterations=40)
        if seed is None:
            notes.append(f"the motion settled from {where} could not be shot over two periods ({why})")
        elif _repeats_early(seed):
            notes.append(f"the motion settled from {where} repeats after one forcing period")
            seed = None
        start = "settled" if seed is not None else ""
    if seed is None:
        raise ConvergenceError(f"no periodic orbit of period 2 at `omega` = {omega:g}: " + "; ".join(notes)
                               + "; the orbit there is of period 1 (rattle orbit without --period), or, in the "
                               "library, give `x0` near a period-2 motion")
    H2 = 2 * opts.harmonics
    make2 = balance_factory(system, period=2)
    q = _period_two_start(make2, seed, omega, opts.regularisation, H2, None)
    hb_state = np.full(2, math.nan)
    if q is None:
        notes.append("the regularised HB of period 2 has no orbit next to the exact one (it falls back to "
                     "period 1): only the exact orbit is given")
        q = np.full(2 * H2 + 1, math.nan)
    else:
        hb_state = np.array([float(a[0]) for a in make2(opts.regularisation, H2).samples(q, omega)])
    return NonsmoothOrbitResult(system=system, omega=omega, orbit=seed, message="; ".join(notes), start=start,
                                coefficients=np.asarray(q, dtype=float), regularisation=float(opts.regularisation),
                                harmonics=int(H2), hb_state=hb_state, hb_start="exact" if np.isfinite(q[0]) else "",
                                match=float(opts.match), settle_periods=SETTLE_PERIODS, periods=2)


__all__ = ["NonsmoothOrbitResult", "nonsmooth_orbit"]
