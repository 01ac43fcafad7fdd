"""frequency_response(): harmonic balance + arc-length continuation + stability + measures."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, replace
from typing import Any, Literal

import numpy as np

from .. import _limits, _validate
from .._typing import FloatArray
from ..continuation import BranchPoint, ContinuationOptions, ContinuationStepper, ForcingHomotopy
from ..errors import ConvergenceError, Status
from ..hb import HarmonicBalance, HBOptions, NewtonOptions, solve_harmonic_balance
from ..model import Model, check_analysable_model
from ..results import FrequencyResponse, SpeedText
from ..stability import stability_method
from ._assemble import assemble
from ._exact_branch import ShootingOptions
from ._nonsmooth import discontinuous_response
from ._regularisation import RegularisationOptions
from ._stretches import AdaptiveHarmonics, follow_branch
from ._sweep_check import SweepCheck, missed_branches
from ._settings import DEFAULT_HARMONICS, RunSettings, StabilityMethod, resolve_hb

logger = logging.getLogger("rattle")


def check_range(omega: object, name: str = "omega") -> tuple[float, float]:
    """Validate a frequency-range argument (min, max) in rad/s; messages name ``name``
    (:func:`rattle._validate.check_range`: two finite numbers, 0 < min < max)."""
    return _validate.check_range(omega, name)


def start_solution(
    hb: HarmonicBalance, omega: float, newton: NewtonOptions, *, continuation: ContinuationOptions | None = None,
) -> tuple[FloatArray, str]:
    """A converged solution at Ω from the linear solution about the static equilibrium.

    If Newton fails from there, the solution is reached by continuation in the scale λ of the
    forcing's harmonics (the *start homotopy*):

        R(q; Ω, λ) = R(q, Ω) + (1 − λ)(F − F_0) = 0,   λ from 0 to 1,

    F the forcing coefficients, F_0 their means alone (:meth:`~rattle.hb.HarmonicBalance.static_forcing`):
    at λ = 0 the static equilibrium, at λ = 1 the orbit sought. The branch is followed from
    λ = 0 by :class:`~rattle.continuation.ContinuationStepper` on
    :class:`~rattle.continuation.ForcingHomotopy` (pseudo-arclength in (q / L, λ), through every
    fold in λ, common inside a bent resonance), and its last point is placed on λ = 1 by Newton
    at the full forcing: the orbit the homotopy's branch connects to the static equilibrium.
    The stepper's step control and budgets are ``continuation`` (those of the frequency
    response being started; default ``ContinuationOptions()``; λ has scale 1). Raises
    :class:`~rattle.errors.ConvergenceError` when the branch does not reach λ = 1.
    """
    q_lin = hb.linear_solution(omega)
    res = solve_harmonic_balance(hb, q_lin, omega, newton)
    if res.converged:
        return res.q, "linear solution + Newton"
    static = hb.static_forcing()
    n = hb.size // hb.basis.size  # coordinates; every block's a_0 is its mean
    q = q_lin.copy()
    q.reshape(n, -1)[:, 1:] = 0.0  # the guess at λ = 0: the means of the linear solution
    homotopy = ForcingHomotopy(hb, omega, hb.forcing - static)
    # Positional, as every stepper of a frequency response is built (tests spy on the signature);
    # λ may take any value on the way (the residual is defined for all).
    options = ContinuationOptions() if continuation is None else continuation
    stepper = ContinuationStepper(homotopy, q, 0.0, (0.0, 1.0), options, newton, domain=(-np.inf, np.inf), symbol="λ")
    points = stepper.run()
    if stepper.status is Status.SUCCESS and points[-1].p == 1.0:
        # The branch turned back in λ (a fold of the amplitude response) where dλ/ds changed sign.
        dlam = np.array([pt.tangent[-1] for pt in points])
        folds = bool(np.any(dlam[1:] * dlam[:-1] < 0.0))
        return points[-1].q, ("amplitude continuation (through folds in the amplitude)" if folds
                              else "amplitude homotopy")
    reached = max((pt.p for pt in points), default=0.0)
    raise ConvergenceError(
        f"no periodic solution found at Ω = {omega:g}: Newton from the linear solution failed "
        f"({res.message}, scaled residual {res.residual:.3g}) and the amplitude homotopy, followed by "
        f"arclength through folds from the static equilibrium, reached no more than {reached:.3g} of "
        f"the forcing ({stepper.message}); with {hb.basis.harmonics} harmonics the truncated problem may "
        "have no solution there (a slow orbit through the stages needs many harmonics): give more "
        "harmonics or start the range higher"
    )


@_validate.numerical_failures
def frequency_response(
    model: Model,
    omega: tuple[float, float] = (0.1, 3.0),
    harmonics: int = DEFAULT_HARMONICS,
    *,
    options: ShootingOptions | RegularisationOptions | None = None,
    samples: int | None = None,
    hb: HBOptions | None = None,
    period: int = 1,
    start: Literal["low", "high", "both"] = "low",
    adaptive: AdaptiveHarmonics | None = AdaptiveHarmonics(),
    check: SweepCheck | None = SweepCheck(),
    stability: StabilityMethod = "monodromy",
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    subharmonics: bool = False,
    max_period: int = 4,
    sweep: object | None = None,
    seeds: Sequence[tuple[float, int, FloatArray]] = (),
    throw: bool = True,
    callback: Callable[[BranchPoint], None] | None = None,
    confirm_tori: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> FrequencyResponse:
    """Non-linear frequency response of ``model`` over ``omega`` = (Ω_min, Ω_max) rad/s, for
    every law.

    The method follows from the law. A continuous law (the model's ``discontinuous`` false):
    harmonic balance, below. A law with torque jumps or friction (a
    single-equation :class:`~rattle.model.System`, a :class:`~rattle.model.System` with its elements' whole laws, or a
    :class:`~rattle.model.Chain` with friction or jumps on an element, solved on its
    ``friction_system()``): ``options`` chooses the method (SPEC §8) — None or a
    :class:`~rattle.analysis.ShootingOptions`, exact shooting continuation on the event-driven
    period map (the default: every row an exact orbit, special points located); a
    :class:`~rattle.analysis.RegularisationOptions`, the regularised harmonic balance with every
    row checked by exact shooting (its ``harmonics`` and ε). The result's ``check`` holds the
    exact-check columns; ``omega``, ``options``, ``continuation``, ``newton``, ``subharmonics``
    (the period-2 branches born at the period doublings, rows of their own ``branch`` and
    ``period``), ``throw`` and ``progress`` apply; the harmonic-balance arguments (``harmonics``,
    ``samples``, ``hb``, ``period``, ``start``, ``adaptive``, ``check``, ``stability``,
    ``max_period``, ``sweep``, ``seeds``, ``callback``, ``confirm_tori``) must be left at their
    defaults. ``progress(done, total)``: called with the share (‰) of the range reached (the CLI
    draws a bar; the library draws nothing).

    With ``subharmonics=True`` every period-doubling point found is followed onto the branch
    of doubled period (branch switching), recursively up to solutions of period
    ``max_period``; all branches are returned together (columns ``branch`` and ``period``).
    Branches that no period doubling reaches (isolated sub-harmonics) are started from seeds:
    ``seeds`` = [(Ω, n, (δ, δ') at t = 0), …] given by the user, and the period-n motions
    (n ≥ 2) of a time-domain ``sweep`` (a SweepResult) that no computed branch explains; each
    orbit is closed by exact shooting and followed both ways in Ω.

    Harmonic balance with ``harmonics`` harmonics of the solution's base frequency Ω/``period``
    (AFT with ``samples`` time samples per period, default :func:`~rattle.hb.default_samples`;
    or both at once as ``hb=HBOptions(harmonics=…, samples=…)``, not together with a
    ``harmonics``/``samples`` that disagrees with it),
    followed from the linear solution at the ``start`` end of the range by pseudo-arclength
    continuation through every fold. Floquet multipliers for every point (``stability``:
    ``"monodromy"`` the exact monodromy of the piecewise-linear linearisation about the HB
    orbit, or ``"hill"`` Hill's method), stability changes labelled.

    ``harmonics`` is the starting H: with ``adaptive`` (default :class:`AdaptiveHarmonics`) H is
    doubled on a stretch where its truncation error estimate exceeds the tolerance or where the
    corrector fails even at the smallest step, and lowered again where the estimate allows; the
    column ``harmonics`` (``extra_columns``) gives H per row. ``adaptive=None`` keeps H fixed.

    ``check`` (default :class:`SweepCheck`): an exact up/down sweep over the range (16
    frequencies each way); every period-1 motion it settles on that no stable computed stretch
    explains (Ω and rms within 1 %) is continued as a branch of its own (``check=None`` skips it;
    ``settings["sweep_check"]`` records what it saw).

    Coverage: a branch that turns back and leaves the range at the side it started from, or
    that ends early, does not cover the range; the branch through the other end is then
    followed too (``start="both"`` always follows both and keeps the second where it is another
    branch). What no branch covers is listed in ``settings["uncovered"]`` ([[Ω_lo, Ω_hi], …]) and
    the status is ``UNCOVERED``: ``throw=True`` raises ConvergenceError with the points computed
    in ``.partial``; ``throw=False`` returns them with the status.

    ``confirm_tori`` (default True): every ``torus`` region (an unstable stretch between two
    Neimark–Sacker points; only chains have them) is confirmed by one simulation from the
    perturbed unstable orbit in its middle (:func:`rattle.analysis._tori.confirm_tori`): its
    label says what the motion settles on, ``detail["simulated_periods"]`` the period (0:
    quasi-periodic). About 1–1.5 s per region.

    Every sub-problem (the 2H re-location of special points, period-doubling branches, seeded
    branches) gets the same HBOptions (its sample count scaled with its harmonic count, see
    ``rattle.analysis._settings``), NewtonOptions, ContinuationOptions and stability method;
    ``result.settings["branches"]`` records what each branch actually used.
    """
    _limits.check_callback(progress, "progress")
    if getattr(model, "discontinuous", False):  # a law with jumps or friction: exact shooting or regularised HB
        refuse_hb_arguments((
            ("harmonics", harmonics, DEFAULT_HARMONICS), ("samples", samples, None), ("hb", hb, None),
            ("period", period, 1), ("start", start, "low"), ("adaptive", adaptive, AdaptiveHarmonics()),
            ("check", check, SweepCheck()), ("stability", stability, "monodromy"), ("max_period", max_period, 4),
            ("sweep", sweep, None), ("seeds", tuple(seeds), ()), ("callback", callback, None),
            ("confirm_tori", confirm_tori, True)),
            "choose its method with `options`: ShootingOptions() (exact shooting continuation, the default) or "
            "RegularisationOptions(harmonics=…, regularisation=…)")
        return discontinuous_response(model, omega, options, continuation=continuation, newton=newton,
                                      subharmonics=_validate.check_bool(subharmonics, "subharmonics"),
                                      throw=_validate.check_bool(throw, "throw"), progress=progress)
    if options is not None:
        raise TypeError(f"`options` chooses the method of a law with jumps or friction; this law is continuous "
                        f"(solved by harmonic balance: `harmonics`, `hb`, …), so leave `options` None, got {options!r}")
    # Argument checks: the rules of rattle._limits / rattle._validate, shared with the file.
    check_analysable_model(model)
    lo, hi = _limits.check_frequency_range(model, *check_range(omega))
    _validate.check_choice(start, "start", ("low", "high", "both"))
    _validate.check_instance(adaptive, "adaptive", AdaptiveHarmonics, "an AdaptiveHarmonics (or None: H fixed)")
    _validate.check_instance(check, "check", SweepCheck, "a SweepCheck (or None: no sweep check)")
    stability = stability_method(stability)  # a name becomes its method object (rattle.stability)
    period = _limits.check_period(period)
    subharmonics = _validate.check_bool(subharmonics, "subharmonics")
    max_period = _limits.check_period(max_period, "max_period")
    throw = _validate.check_bool(throw, "throw")
    # The largest sub-problem: a period-P branch (P = max_period, or up to 8 for the sweep's and
    # the seeds' motions) carries P·H harmonics, and its special points are re-located with 2P·H.
    largest = 1 if not subharmonics else (_limits.MAX_PERIOD if (sweep is not None or len(seeds)) else max_period)
    _limits.check_hb_settings(harmonics, samples, hb, period=largest)
    _validate.check_instance(continuation, "continuation", ContinuationOptions, "a ContinuationOptions")
    _validate.check_instance(newton, "newton", NewtonOptions, "a NewtonOptions")
    _limits.check_callback(callback)
    run = RunSettings.make(resolve_hb(harmonics, samples, hb), newton, continuation, stability)
    # a chain's coordinates share the effective harmonics of one problem (n·p·H ≤ 512)
    _limits.check_harmonics(run.hb.harmonics, "harmonics" if hb is None else "hb.harmonics", period=period,
                            coordinates=model.system().n)
    confirm_tori = _validate.check_bool(confirm_tori, "confirm_tori")
    if progress is not None:  # the share of the range reached, as the exact shooting continuation reports it
        callback = _reporting(progress, lo, hi, callback)
    result = _frequency_response(
        model, (lo, hi), run, period=period, start=start, subharmonics=subharmonics, max_period=max_period,
        sweep=sweep, seeds=seeds, throw=throw, callback=callback, adaptive=adaptive, check=check,
    )
    if confirm_tori and any(r.kind == "torus" for r in result.regions):
        from ._tori import confirm_tori as _confirm  # time domain: only when there is a torus

        t0 = time.perf_counter()
        result = replace(result, regions=_confirm(result), timings={
            **result.timings, "torus_simulations": time.perf_counter() - t0})
    return result


def refuse_hb_arguments(arguments: Sequence[tuple[str, object, object]], method: str) -> None:
    """TypeError naming every (name, value, default) of ``arguments`` not left at its default
    (:func:`_same`): they set the harmonic balance of a continuous law, and a law with jumps or
    friction is solved otherwise (``method`` says how to choose it). The one rule of
    :func:`frequency_response` and :func:`~rattle.analysis.periodic_orbit`."""
    given = [name for name, value, default in arguments if not _same(value, default)]
    if given:
        raise TypeError(
            f"{', '.join(f'`{k}`' for k in given)} must be left at the default for a law with jumps or friction "
            f"(they set the harmonic balance of a continuous law); {method}")


def _same(value: object, default: object) -> bool:
    """``value`` is ``default`` (equal, of the same type: 32 and 32.0 differ from what a user meant
    only in type, and an option object equal to the default's is the default)."""
    try:
        return type(value) is type(default) and bool(value == default)
    except (TypeError, ValueError):  # an array or an object that does not compare
        return False


def _reporting(progress: Callable[[int, int], None], lo: float, hi: float,
               callback: Callable[[BranchPoint], None] | None) -> Callable[[BranchPoint], None]:
    """A ``callback`` that also calls ``progress(done, 1000)`` with the share (‰) of [lo, hi]
    reached by the points so far."""
    reached = [0]

    def report(point: BranchPoint) -> None:
        done = int(1000 * min(max((point.omega - lo) / (hi - lo), 0.0), 1.0))
        if done > reached[0]:
            reached[0] = done
            progress(done, 1000)
        if callback is not None:
            callback(point)

    return report


def _frequency_response(
    model: Model,
    omega_range: tuple[float, float],
    run: RunSettings,
    *,
    period: int = 1,
    start: Literal["low", "high", "both"] = "low",
    subharmonics: bool = False,
    max_period: int = 4,
    sweep: object | None = None,
    seeds: Sequence[tuple[float, int, FloatArray]] = (),
    throw: bool = True,
    callback: Callable[[BranchPoint], None] | None = None,
    adaptive: AdaptiveHarmonics | None = None,
    check: SweepCheck | None = None,
) -> FrequencyResponse:
    """frequency_response() after its arguments are checked: every option comes in ``run``."""
    lo, hi = omega_range
    harmonics = run.hb.harmonics
    t_start = time.perf_counter()
    first_end = "high" if start == "high" else "low"
    primary, status, message = _branch_from_end(model, run, first_end, omega_range, period=period, adaptive=adaptive,
                                                callback=callback, branch_id=0)
    branches = [primary]
    covered = [_extent(primary)]
    other_end = "low" if first_end == "high" else "high"
    budget_spent = status in (Status.MAX_STEPS, Status.MAX_TIME)  # the user's limit: not spent again
    if start == "both" or (_uncovered(omega_range, covered) and not budget_spent):
        second, status2, message2 = _branch_from_end(model, run, other_end, omega_range, period=period,
                                                     adaptive=adaptive, callback=callback, branch_id=1)
        same = (len(primary) and len(second) and _reaches(primary, other_end, omega_range)
                and _reaches(second, first_end, omega_range))
        if len(second) and not same:  # another branch (the one through the other end)
            branches.append(second)
            covered.append(_extent(second))
            message = f"{message}; from the {other_end} end: {message2}"
    uncovered = _uncovered(omega_range, covered)
    if uncovered:
        # A range not covered is never success: a branch that returned (or a later one that was
        # complete) leaves the status UNCOVERED; a failure keeps its own status and reason.
        if status.success:
            status = Status.UNCOVERED
        message = f"{message}; not covered by any branch: {SpeedText.of(model).spans(uncovered, 6)}"
    elif not status.success or status is Status.RETURNED:
        status = Status.SUCCESS  # the branches through the two ends cover the range together
    t_cont = time.perf_counter()
    checked: dict[str, Any] | None = None
    if check is not None and period == 1 and status.success and any(len(b) for b in branches):
        # attractors a run-up or run-down settles on that no branch explains: continued as branches
        known = FrequencyResponse.concatenate(branches)
        try:
            missed, checked = missed_branches(known, omega_range, run, check, first_branch=len(branches))
        except (ValueError, ConvergenceError) as exc:  # a model the simulation refuses (its time step)
            missed, checked = [], {"skipped": str(exc)}
        branches += missed
        checked["time"] = time.perf_counter() - t_cont
    if uncovered and any(b.settings.get("end_status") == Status.STEP_TOO_SMALL.name for b in branches):
        # Where the corrector fails even at the smallest step, the truncated problem usually has
        # no solution there: an orbit through stiff stages (a gear mesh stiffer than the rest of
        # the chain) needs more harmonics than the range's low end can be resolved with.
        if adaptive is None:
            message += (f"; with {harmonics} harmonics the truncated problem may have no solution beyond this "
                        f"point (impacts on a stiff stage need many harmonics): give more harmonics "
                        f"(e.g. {min(2 * harmonics, _limits.MAX_HARMONICS)}), let them adapt (the default) "
                        "or start the range elsewhere")
        else:
            top = max(int(s["harmonics"]) for b in branches for s in b.settings.get("stretches", [])) \
                if any(b.settings.get("stretches") for b in branches) else harmonics
            message += (f"; the corrector failed even at the smallest step with up to {top} harmonics: the "
                        "truncated problem may have no solution there (impacts on a stiff stage need many "
                        "harmonics, a chaotic motion has no periodic branch to follow): give a larger "
                        "`max_harmonics` (AdaptiveHarmonics), or start the range elsewhere")
    logger.info("continuation: %d points, %s (%s)", sum(len(b) for b in branches), status.name, message)
    settings = {
        "omega": [lo, hi], **run.record(), "period": period, "start": start,
        "start_solution": primary.settings.get("start_solution"),
        "rejected_steps": sum(int(b.settings.get("rejected_steps", 0)) for b in branches),
        "rejected_by_monitor": sum(int(b.settings.get("rejected_by_monitor", 0)) for b in branches),
        "origin": f"continuation from the {first_end} end of the range",
        "uncovered": [[a, b] for a, b in uncovered],
        "adaptive_harmonics": None if adaptive is None else asdict(adaptive),
        "sweep_check": checked,
    }
    result = FrequencyResponse.concatenate(branches, status=status, message=message, settings=settings,
                                           timings={**primary.timings, "continuation": t_cont - t_start})
    if subharmonics and status.success:
        if isinstance(max_period, bool) or not isinstance(max_period, int) or max_period < 1:
            raise ValueError(f"`max_period` must be an integer >= 1, got {max_period!r}")
        from ._branches import period_doubling_branches

        t_sub = time.perf_counter()
        from ._branches import seed_from_state, seeded_branches, sweep_seeds

        extra: list[FrequencyResponse] = []
        for primary_b in branches:
            extra += period_doubling_branches(primary_b, (lo, hi), max_period=max_period, run=run,
                                              first_branch=len(branches) + len(extra))
        seed_list = []
        for k, seed in enumerate(seeds):
            try:
                w_s, n_s, x_s = float(seed[0]), int(seed[1]), np.asarray(seed[2], dtype=float).reshape(2)
            except (TypeError, ValueError, IndexError):
                raise ValueError(f"`seeds[{k}]` must be (omega, period, (delta, velocity)), got {seed!r}") from None
            if not (lo <= w_s <= hi) or not 1 <= n_s <= 8:
                raise ValueError(f"`seeds[{k}]`: omega must lie in {(lo, hi)} and period in 1…8, got {seed!r}")
            q_s = seed_from_state(model, w_s, x_s, n_s, n_s * harmonics, hb=run.for_harmonics(n_s * harmonics))
            if q_s is not None:
                seed_list.append((w_s, n_s, q_s))
        known = FrequencyResponse.concatenate([result, *extra])  # the branches found so far
        if sweep is not None:
            seed_list += sweep_seeds(known, sweep, harmonics_per_period=harmonics, run=run)
        if seed_list:
            extra += seeded_branches(known, seed_list, (lo, hi), run=run, first_branch=len(branches) + len(extra))
        timings = dict(result.timings)
        timings["subharmonics"] = time.perf_counter() - t_sub
        settings = dict(result.settings, subharmonics=True, max_period=max_period,
                        branches=[*(_branch_record(b) for b in branches), *(_branch_record(b) for b in extra)])
        result = FrequencyResponse.concatenate([result, *extra], settings=settings, timings=timings)
    else:
        result = replace(result, settings=dict(result.settings, subharmonics=False,
                                               branches=[_branch_record(b) for b in branches]))
    if len(result):
        from ._regimes import confirm_with_sweep, label_regions

        regions = label_regions(result)
        if sweep is not None:  # what the simulation saw there goes into the labels
            regions = confirm_with_sweep(regions, sweep)
        result = replace(result, regions=regions)
    if throw and not status.success:
        raise ConvergenceError(f"frequency response incomplete: {message}", partial=result)
    return result


def _branch_from_end(model: Model, run: RunSettings, end: str, omega_range: tuple[float, float], *, period: int,
                     adaptive: AdaptiveHarmonics | None, callback: Callable[[BranchPoint], None] | None,
                     branch_id: int) -> tuple[FrequencyResponse, Status, str]:
    """The branch through the start solution at the ``end`` ("low"/"high") of the range, followed
    into it (H per stretch with ``adaptive``), assembled with its stability, special points and
    the column ``harmonics``: (result, status, message). RETURNED when it leaves the range at
    the side it started from; an empty result (START_FAILED) when no start solution is found."""
    lo, hi = omega_range
    omega0 = lo if end == "low" else hi
    hb = HarmonicBalance(model, run.hb, period=period)
    try:
        q0, how = start_solution(hb, omega0, run.newton, continuation=run.continuation)
    except ConvergenceError as exc:
        empty = assemble(model, hb, [], stability=run.stability, newton=run.newton, status=Status.START_FAILED,
                         message=str(exc), branch_id=branch_id,
                         settings={"start_solution": "failed", "end_status": Status.START_FAILED.name})
        return empty, Status.START_FAILED, str(exc)
    stretches = follow_branch(model, run, q0, omega0, omega_range, period=period, adaptive=adaptive,
                              callback=callback)
    last = stretches[-1].stepper
    status = last.status or Status.START_FAILED
    points = [pt for st in stretches for pt in st.points]
    if status is Status.SUCCESS and points and points[-1].p == omega0 and len(points) > 1:
        status = Status.RETURNED  # a restarted stretch (tangent start) cannot tell: the branch can
    message = Status.RETURNED.message if status is Status.RETURNED else last.message
    parts = []
    for st in stretches:
        if not st.points:
            continue
        part = assemble(model, st.hb, st.points, stability=run.stability, newton=run.newton, branch_id=branch_id,  # type: ignore[arg-type]
                        status=status, message=message, settings={})
        parts.append(part)
    rejected = sum(st.stepper.rejected for st in stretches)
    by_monitor = sum(st.stepper.monitor_rejected for st in stretches)
    settings = {"start_solution": how, "rejected_steps": rejected, "rejected_by_monitor": by_monitor,
                "end_status": status.name, **run.record(),
                "stretches": [{"harmonics": st.hb.basis.harmonics, "points": len(st.points),  # type: ignore[attr-defined]
                               "omega": [st.points[0].p, st.points[-1].p] if st.points else None,
                               "ended": st.ended or status.name.lower()} for st in stretches],
                "origin": f"continuation from the {end} end of the range"}
    if not parts:
        empty = assemble(model, hb, [], stability=run.stability, newton=run.newton, status=status, message=message,
                         branch_id=branch_id, settings=settings)
        return empty, status, message
    branch = FrequencyResponse.concatenate(parts, status=status, message=message, settings=settings)
    return branch, status, message


def _extent(branch: FrequencyResponse) -> tuple[float, float] | None:
    """The Ω interval a connected branch covers (None when empty)."""
    return (float(branch.omega.min()), float(branch.omega.max())) if len(branch) else None


def _reaches(branch: FrequencyResponse, end: str, omega_range: tuple[float, float]) -> bool:
    lo, hi = omega_range
    ext = _extent(branch)
    tol = 1e-9 * hi
    return ext is not None and (ext[0] <= lo + tol if end == "low" else ext[1] >= hi - tol)


def _uncovered(omega_range: tuple[float, float], covered: Sequence[tuple[float, float] | None]) -> list[tuple[float, float]]:
    """The parts of ``omega_range`` outside every interval of ``covered`` (to 1e-9 relative)."""
    lo, hi = omega_range
    tol = 1e-9 * hi
    gaps = [(lo, hi)]
    for iv in covered:
        if iv is None:
            continue
        a, b = iv
        nxt = []
        for g0, g1 in gaps:
            if b < g0 - tol or a > g1 + tol:
                nxt.append((g0, g1))
                continue
            if a > g0 + tol:
                nxt.append((g0, a))
            if b < g1 - tol:
                nxt.append((b, g1))
        gaps = nxt
    return [(a, b) for a, b in gaps if b - a > tol]


def _branch_record(branch: FrequencyResponse) -> dict:
    """The settings one branch was computed with (``assemble``'s ``settings``), tagged with its id."""
    b = int(branch.branch[0]) if len(branch) else 0
    keep = ("harmonics", "samples", "samples_given", "stability", "newton", "continuation", "origin", "stretches",
            "end_status")
    return {"branch": b, "period": int(branch.period[0]) if len(branch) else None,
            **{k: branch.settings[k] for k in keep if k in branch.settings}}


__all__ = ["frequency_response", "start_solution", "assemble"]
