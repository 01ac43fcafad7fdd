"""frequency_response(): harmonic balance + arc-length continuation + stability + measures."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Literal

import numpy as np

from .. import _limits, _validate
from .._typing import FloatArray
from ..continuation import ArclengthCorrector, BranchPoint, ContinuationOptions, ContinuationStepper
from ..continuation._detect import LocatedPoint, locate_on_segment
from ..errors import ConvergenceError, Status
from ..hb import HarmonicBalance, HBOptions, NewtonOptions, resize_harmonics, solve_harmonic_balance
from ..measures import Measures, system_measures_batch
from ..model import Model, check_analysable_model
from ..results import FrequencyResponse, SpecialPoint
from ..results._frequency_response import element_columns_from
from ..stability import FloquetMonitor, classify_loss, stability_method, torus_ratio
from ..stability._classify import UNIT_CIRCLE_TOL
from ._settings import DEFAULT_HARMONICS, RunSettings, StabilityMethod, resolve_hb, scaled_hb

logger = logging.getLogger("rattle")


def check_range(omega: object, name: str = "omega") -> tuple[float, float]:
    """Validate a frequency-range argument (min, max) in rad/s; messages name ``name``
    (:func:`rattle._validate.check_range`: two finite numbers, 0 < min < max)."""
    return _validate.check_range(omega, name)


def start_solution(hb: HarmonicBalance, omega: float, newton: NewtonOptions) -> tuple[FloatArray, str]:
    """A converged solution at Ω from the linear solution about the static equilibrium.

    If Newton fails from there, the dynamic forcing λ·(F − F_0) is raised from λ = 0 (the
    static solution) to 1: first in natural steps, each started from the previous solution;
    where that stalls (the solution turns back in λ: a fold of the amplitude response, common
    inside a bent resonance), by pseudo-arclength continuation in (q, λ), which follows the
    solution curve through such folds (:func:`_amplitude_continuation`).
    """
    q_lin = hb.linear_solution(omega)
    res = solve_harmonic_balance(hb, q_lin, omega, newton)
    if res.converged:
        return res.q, "linear solution + Newton"
    full = hb.forcing.copy()
    n = hb.size // hb.basis.size  # coordinates; every block's a_0 is its mean
    static = np.zeros_like(full)
    static.reshape(n, -1)[:, 0] = full.reshape(n, -1)[:, 0]
    q = q_lin.copy()
    q.reshape(n, -1)[:, 1:] = 0.0
    lam, dlam = 0.0, 0.1
    q_static = None
    try:
        while lam < 1.0 and dlam > 1e-4:
            trial = min(1.0, lam + dlam)
            hb.forcing = static + trial * (full - static)
            r = solve_harmonic_balance(hb, q, omega, newton)
            if r.converged:
                q, lam = r.q, trial
                if q_static is None:
                    q_static = (r.q, trial)
                dlam = min(0.5, 1.5 * dlam)
            else:
                dlam *= 0.5
    finally:
        hb.forcing = full
    if lam >= 1.0:
        return q, "amplitude homotopy"
    stalled = lam
    q_cont = _amplitude_continuation(hb, omega, q, lam, static, full, newton)
    if q_cont is not None:
        return q_cont, "amplitude continuation (through folds in the amplitude)"
    raise ConvergenceError(
        f"no periodic solution found at Ω = {omega:g}: Newton from the linear solution failed "
        f"({res.message}, scaled residual {res.residual:.3g}) and the amplitude homotopy stalled at "
        f"{stalled:.3g} of the forcing (also followed by arclength through folds); with "
        f"{hb.basis.harmonics} harmonics the truncated problem may have "
        "no solution there (a slow orbit through the stages needs many harmonics): give more "
        "harmonics or start the range higher"
    )


def _amplitude_continuation(
    hb: HarmonicBalance, omega: float, q0: FloatArray, lam0: float, static: FloatArray, full: FloatArray,
    newton: NewtonOptions, max_steps: int = 2000,
) -> FloatArray | None:
    """Pseudo-arclength continuation of R(q, Ω) with the forcing F_0 + λ (F − F_0), from the
    converged (q0, λ0) to λ = 1, through folds in λ; the solution at λ = 1 (Newton at the full
    forcing from the point interpolated where the curve crosses it), or None.

    Variables y = (q / L, λ); the corrector solves R = 0 with tᵀ(y − y_pred) = 0 on the
    bordered Jacobian [∂R/∂q L, −(F − F_0)]; the tangent is its null vector, oriented along the
    previous one (initially towards increasing λ).
    """
    L, Fs = hb.length_scale, hb.force_scale
    D = full - static
    size = hb.size

    def rj(y: FloatArray) -> tuple[FloatArray, FloatArray]:
        hb.forcing = static + y[-1] * D
        R, Rq, _ = hb.residual_jacobian(y[:-1] * L, omega)
        J = np.empty((size, size + 1))
        J[:, :size] = Rq * L
        J[:, size] = -D
        return R, J

    def tangent(J: FloatArray, ref: FloatArray) -> FloatArray | None:
        A = np.vstack((J, ref))
        rhs = np.zeros(size + 1)
        rhs[-1] = 1.0
        try:
            t = np.linalg.solve(A, rhs)
        except np.linalg.LinAlgError:
            return None
        return t / np.linalg.norm(t) if np.all(np.isfinite(t)) else None

    try:
        y = np.concatenate((q0 / L, [lam0]))
        _, J = rj(y)
        ref = np.zeros(size + 1)
        ref[-1] = 1.0
        t = tangent(J, ref)
        h = 0.05
        for _ in range(max_steps if t is not None else 0):
            yp = y + h * t
            ok = False
            yc = yp.copy()
            for _it in range(newton.max_iterations):
                R, J = rj(yc)
                A = np.vstack((J, t))
                rhs = np.concatenate((-R, [-float(t @ (yc - yp))]))
                try:
                    dy = np.linalg.solve(A, rhs)
                except np.linalg.LinAlgError:
                    break
                yc = yc + dy
                if not np.all(np.isfinite(yc)):
                    break
                if float(np.max(np.abs(R))) / Fs <= newton.residual_tol and float(np.max(np.abs(dy))) <= newton.step_tol:
                    ok = True
                    break
            if not ok or float(np.linalg.norm(yc - y)) > 2.0 * h:
                h *= 0.5
                if h < 1e-7:
                    return None
                continue
            if yc[-1] >= 1.0:  # crossed the full forcing: Newton there from the interpolated point
                s = (1.0 - y[-1]) / (yc[-1] - y[-1])
                q_guess = ((1.0 - s) * y[:-1] + s * yc[:-1]) * L
                hb.forcing = full
                r = solve_harmonic_balance(hb, q_guess, omega, newton)
                return r.q if r.converged else None
            _, J = rj(yc)
            t_new = tangent(J, t)
            if t_new is None:
                return None
            y, t = yc, t_new
            h = min(2.0 * h, 0.25)
        return None
    finally:
        hb.forcing = full


def monitor_of(hb: HarmonicBalance) -> FloquetMonitor:
    """The :class:`~rattle.stability.FloquetMonitor` of ``hb`` (one per problem: it caches the
    stage decompositions of a chain)."""
    mon = getattr(hb, "_floquet_monitor", None)
    if mon is None:
        mon = FloquetMonitor(hb)
        hb._floquet_monitor = mon  # type: ignore[attr-defined]
    return mon


def _test_function(kind: str, hb: HarmonicBalance, corrector: ArclengthCorrector):
    """ψ(q, Ω, corrected, d) whose sign change marks a ``kind`` point (see continuation._detect):
    det(M − I) (fold), det(M + I) (period doubling), det(M ⊙ M − I) (Neimark–Sacker), from the
    exact monodromy of the orbit (``FloquetMonitor.test_function``)."""
    psi = monitor_of(hb).test_function(kind)

    def test(q, w, corr, d):
        return psi(q, w)
    return test


def _locate_with(hb: HarmonicBalance, newton: NewtonOptions, kind: str, qa, wa, qb, wb) -> LocatedPoint | None:
    corrector = ArclengthCorrector(hb, newton)
    return locate_on_segment(corrector, qa, wa, qb, wb, _test_function(kind, hb, corrector))


def _refine(hb: HarmonicBalance, hb2: HarmonicBalance, newton: NewtonOptions, kind: str, qa, wa, qb, wb) -> LocatedPoint | None:
    """Locate the same special point with the doubled harmonic count hb2 (built with the run's
    HBOptions scaled to 2H: see ``_settings``): the end points are first corrected onto the 2H
    branch (in the plane normal to the secant)."""
    H2 = hb2.basis.harmonics
    corr2 = ArclengthCorrector(hb2, newton)
    ya = corr2.to_scaled(hb.resize(qa, H2), wa)
    yb = corr2.to_scaled(hb.resize(qb, H2), wb)
    d = (yb - ya) / np.linalg.norm(yb - ya)
    ca, cb = corr2.correct(ya, d), corr2.correct(yb, d)
    if ca is None or cb is None:
        return None
    qa2, wa2 = corr2.unscale(ca.y)
    qb2, wb2 = corr2.unscale(cb.y)
    return _locate_with(hb2, newton, kind, qa2, wa2, qb2, wb2)


def _vertex_stretch(Q: FloatArray, hb: HarmonicBalance, rows: range) -> int:
    """How many rows after the first of ``rows`` (a branch-point end, walking inwards) are
    still (nearly) of half the period: the vertex of the period-doubling pitchfork.

    There the doubled-period orbit's critical multiplier is the square of its parent's, ≈ +1,
    and sits on either side of the unit circle within the truncation error; the stability
    changes it shows there are the branch point itself (labelled at the end row), not folds.
    """
    count = 0
    for j in list(rows)[1:-1]:
        if not _is_period_halved(Q[j], hb):
            break
        count += 1
    return count


def _is_period_halved(q: FloatArray, hb: HarmonicBalance, rtol: float = 0.1) -> bool:
    """Whether a solution of even period p is (nearly) of period p/2: its odd harmonics carry
    less than ``rtol`` of the dynamic content. Near the pitchfork where a doubled-period branch
    meets its parent the odd part vanishes like sqrt(|Ω − Ω_pd|); the located +1 crossing there
    has ~1–2 % odd content on the reference case, a genuine fold of a period-2 branch ~95 %."""
    if hb.period % 2:
        return False
    H = hb.basis.harmonics
    k = np.arange(1, H + 1, 2)
    odd = np.concatenate((k, H + k))
    Q = np.asarray(q).reshape(-1, 2 * H + 1)  # one row per coordinate
    return float(np.linalg.norm(Q[:, odd])) <= rtol * max(float(np.linalg.norm(Q[:, 1:])), 1e-300)


def _locate_changes(
    hb: HarmonicBalance, newton: NewtonOptions, Q: FloatArray, Om: FloatArray, mu: np.ndarray, stable: np.ndarray,
    refine: bool,
) -> list[tuple[int, str, LocatedPoint | None, float | None]]:
    """For each change of stability between rows i−1 and i: (i, kind, located point or None,
    Ω located again with 2H harmonics or None). The 2H problem keeps ``hb.options``' sample
    ratio (``RunSettings.for_harmonics``)."""
    found = []
    hb2 = None
    for i in range(1, stable.size):
        if stable[i] == stable[i - 1]:
            continue
        kind = classify_loss(mu[i - 1], mu[i])
        loc = _locate_with(hb, newton, kind, Q[i - 1], Om[i - 1], Q[i], Om[i])
        if kind == "fold" and loc is not None and _is_period_halved(loc.q, hb):
            # +1 at a point that is really of half the period: the pitchfork where this branch
            # meets the branch it doubled from — that branch's period doubling, not a fold.
            kind = "period_doubling"
        omega2 = None
        if loc is not None and refine:
            if hb2 is None:
                hb_opts = hb.options if isinstance(hb.options, HBOptions) else HBOptions(harmonics=hb.basis.harmonics)
                hb2 = HarmonicBalance(hb.model, scaled_hb(hb_opts, 2 * hb.basis.harmonics), period=hb.period)
            loc2 = _refine(hb, hb2, newton, kind, Q[i - 1], Om[i - 1], Q[i], Om[i])
            omega2 = None if loc2 is None else loc2.omega
        found.append((i, kind, loc, omega2))
    return found


@_validate.numerical_failures
def frequency_response(
    model: Model,
    omega: tuple[float, float] = (0.1, 3.0),
    harmonics: int = DEFAULT_HARMONICS,
    *,
    samples: int | None = None,
    hb: HBOptions | None = None,
    period: int = 1,
    start: Literal["low", "high"] = "low",
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
) -> FrequencyResponse:
    """Non-linear frequency response of ``model`` over ``omega`` = (Ω_min, Ω_max) rad/s.

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

    If the run ends before the far end of the range, ``throw=True`` raises ConvergenceError
    with the points computed so far in ``.partial``; ``throw=False`` returns them with the status.

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
    # Argument checks: the rules of rattle._limits / rattle._validate, shared with the file.
    check_analysable_model(model)
    lo, hi = _limits.check_frequency_range(model, *check_range(omega))
    _validate.check_choice(start, "start", ("low", "high"))
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
    confirm_tori = _validate.check_bool(confirm_tori, "confirm_tori")
    result = _frequency_response(
        model, (lo, hi), run, period=period, start=start, subharmonics=subharmonics, max_period=max_period,
        sweep=sweep, seeds=seeds, throw=throw, callback=callback,
    )
    if confirm_tori and any(r.kind == "torus" for r in result.regions):
        from ._tori import confirm_tori as _confirm  # time domain: only when there is a torus

        t0 = time.perf_counter()
        result = replace(result, regions=_confirm(result), timings={
            **result.timings, "torus_simulations": time.perf_counter() - t0})
    return result


def _frequency_response(
    model: Model,
    omega_range: tuple[float, float],
    run: RunSettings,
    *,
    period: int = 1,
    start: Literal["low", "high"] = "low",
    subharmonics: bool = False,
    max_period: int = 4,
    sweep: object | None = None,
    seeds: Sequence[tuple[float, int, FloatArray]] = (),
    throw: bool = True,
    callback: Callable[[BranchPoint], None] | None = None,
) -> FrequencyResponse:
    """frequency_response() after its arguments are checked: every option comes in ``run``."""
    lo, hi = omega_range
    cont_opts, newton_opts, hb_opts, stability = run.continuation, run.newton, run.hb, run.stability
    harmonics = hb_opts.harmonics
    t_start = time.perf_counter()
    hb = HarmonicBalance(model, hb_opts, period=period)
    omega0 = lo if start == "low" else hi
    try:
        q0, how = start_solution(hb, omega0, newton_opts)
    except ConvergenceError:
        if throw:
            raise
        q0, how = hb.linear_solution(omega0), "failed"
    stepper = ContinuationStepper(hb, q0, omega0, (lo, hi), cont_opts, newton_opts, monitor=FloquetMonitor(hb))
    while (pt := stepper.step()) is not None:
        if callback is not None:
            callback(pt)
    t_cont = time.perf_counter()
    points = stepper.points
    status = stepper.status or Status.START_FAILED
    logger.info("continuation: %d points, %s (%s)", len(points), status.name, stepper.message)
    result = assemble(
        model, hb, points, stability=stability, newton=newton_opts, status=status, message=stepper.message,
        settings={
            "omega": [lo, hi], **run.record(), "period": period,
            "start": start, "start_solution": how, "rejected_steps": stepper.rejected,
            "rejected_by_monitor": stepper.monitor_rejected,
            "origin": f"continuation from the {start} end of the range",
        },
        timings={"continuation": t_cont - t_start},
    )
    if subharmonics and status.success:
        if isinstance(max_period, bool) or not isinstance(max_period, int) or max_period < 1:
            raise ValueError(f"`max_period` must be an integer >= 1, got {max_period!r}")
        from ._branches import period_doubling_branches

        t_sub = time.perf_counter()
        from ._branches import seed_from_state, seeded_branches, sweep_seeds

        extra = period_doubling_branches(result, (lo, hi), max_period=max_period, run=run)
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
            extra += seeded_branches(known, seed_list, (lo, hi), run=run, first_branch=1 + len(extra))
        timings = dict(result.timings)
        timings["subharmonics"] = time.perf_counter() - t_sub
        settings = dict(result.settings, subharmonics=True, max_period=max_period,
                        branches=[_branch_record(result), *(_branch_record(b) for b in extra)])
        result = FrequencyResponse.concatenate([result, *extra], settings=settings, timings=timings)
    else:
        result = replace(result, settings=dict(result.settings, subharmonics=False, branches=[_branch_record(result)]))
    if len(result):
        from ._regimes import confirm_with_sweep, label_regions

        regions = label_regions(result)
        if sweep is not None:  # what the simulation saw there goes into the labels
            regions = confirm_with_sweep(regions, sweep)
        result = replace(result, regions=regions)
    if throw and not status.success:
        raise ConvergenceError(f"frequency response incomplete: {stepper.message}", partial=result)
    return result


def _branch_record(branch: FrequencyResponse) -> dict:
    """The settings one branch was computed with (``assemble``'s ``settings``), tagged with its id."""
    b = int(branch.branch[0]) if len(branch) else 0
    keep = ("harmonics", "samples", "samples_given", "stability", "newton", "continuation", "origin")
    return {"branch": b, "period": int(branch.period[0]) if len(branch) else None,
            **{k: branch.settings[k] for k in keep if k in branch.settings}}


def _multipliers(model: Model, hb: HarmonicBalance, Q: FloatArray, Om: FloatArray, X: FloatArray, stability: StabilityMethod) -> np.ndarray:
    """Floquet multipliers (P, 2n), largest modulus first, of the orbits ``Q`` (P, n·(2H+1))."""
    return stability.multipliers(hb, Q, Om)  # a rattle.stability method object


def assemble(
    model: Model,
    hb: HarmonicBalance,
    points: list[BranchPoint],
    *,
    branch_id: int = 0,
    stability: StabilityMethod = "monodromy",
    locate: bool = True,
    refine: bool = True,
    branch_points: tuple[bool, bool] = (False, False),
    newton: NewtonOptions | None = None,
    status: Status = Status.SUCCESS,
    message: str = "",
    settings: dict | None = None,
    timings: dict | None = None,
) -> FrequencyResponse:
    """Stability, located special points, measures and labels for the points of one branch.

    Where stability changes between two points, the special point is located on the branch
    (``locate=True``; see ``continuation._detect``) and inserted between them as a row of its
    own, labelled with its type; its ``stable`` is false (a multiplier sits on the unit circle).
    Without ``locate`` (or if locating fails) the nearer of the two points is labelled.
    With ``refine`` the special point is located once more with 2H harmonics: its
    ``SpecialPoint.omega`` is that value and ``omega_error`` = |Ω(2H) − Ω(H)| estimates the
    truncation error of the row's Ω (the row itself stays the H-harmonic solution).
    ``branch_points`` (first, last) marks end rows that are period-doubling points of another
    branch (a branch born by period doubling): they are labelled so, and the change of
    stability through them (the multiplier −1 of the parent is +1 here) is not reported again.
    """
    t0 = time.perf_counter()
    newton = newton or NewtonOptions()
    P = len(points)
    n = hb.size
    Q = np.array([p.q for p in points]).reshape(P, n)
    Om = np.array([p.omega for p in points], dtype=float)
    its = np.array([p.iterations for p in points], dtype=int)
    res = np.array([p.residual for p in points], dtype=float)
    X = None  # (the monodromy synthesises what it needs)
    stability = stability_method(stability)  # assemble() is public: a name is still accepted
    mu = _multipliers(model, hb, Q, Om, X, stability)
    stable = np.max(np.abs(mu), axis=1) < 1.0 - UNIT_CIRCLE_TOL if P else np.zeros(0, dtype=bool)
    labels = np.full(P, "", dtype=object)
    # A branch-point end row takes the stability of its neighbour for the change detection.
    stable_for_changes = stable.copy()
    if P > 1 and branch_points[0]:
        labels[0] = "period_doubling"
        k = _vertex_stretch(Q, hb, range(P))
        stable_for_changes[: k + 1] = stable[min(k + 1, P - 1)]
    if P > 1 and branch_points[1]:
        labels[P - 1] = "period_doubling"
        k = _vertex_stretch(Q, hb, range(P - 1, -1, -1))
        stable_for_changes[P - 1 - k :] = stable[max(P - 2 - k, 0)]
    changes = _locate_changes(hb, newton, Q, Om, mu, stable_for_changes, refine) if locate and stability.locates else [
        (i, classify_loss(mu[i - 1], mu[i]), None, None) for i in range(1, P) if stable_for_changes[i] != stable_for_changes[i - 1]
    ]
    if P > 1 and branch_points[0]:
        stable[0] = False  # a multiplier on the unit circle
    if P > 1 and branch_points[1]:
        stable[P - 1] = False
    # Insert the located points (in reverse so that the indices stay valid).
    inserted = np.zeros(P, dtype=bool)
    refined: dict[int, float] = {}
    for i, kind, loc, omega2 in reversed(changes):
        if loc is None:
            j = i if abs(np.max(np.abs(mu[i])) - 1.0) <= abs(np.max(np.abs(mu[i - 1])) - 1.0) else i - 1
            labels[j] = kind
            continue
        Q = np.insert(Q, i, loc.q, axis=0)
        Om = np.insert(Om, i, loc.omega)
        its = np.insert(its, i, loc.iterations)
        res = np.insert(res, i, loc.residual)
        labels = np.insert(labels, i, kind)
        stable = np.insert(stable, i, False)
        inserted = np.insert(inserted, i, True)
        refined = {(k + 1 if k >= i else k): v for k, v in refined.items()}
        if omega2 is not None:
            refined[i] = omega2
    if inserted.any():
        mu_new = _multipliers(model, hb, Q[inserted], Om[inserted], None, stability)
        mu_full = np.empty((Q.shape[0], mu.shape[1]), dtype=complex)
        mu_full[~inserted] = mu
        mu_full[inserted] = mu_new
        mu = mu_full
    P = Q.shape[0]
    ends = {0} if P > 1 and branch_points[0] else set()
    if P > 1 and branch_points[1]:
        ends.add(P - 1)
    special = [
        SpecialPoint(
            str(labels[j]), j, float(refined.get(j, Om[j])), branch_id, mu[j].copy(), located=bool(inserted[j]) or j in ends,
            omega_error=abs(refined[j] - float(Om[j])) if j in refined else None,
            torus_ratio=torus_ratio(mu[j]) if labels[j] == "neimark_sacker" else None,
        )
        for j in range(P) if labels[j]
    ]
    t1 = time.perf_counter()
    n_coord = hb.size // hb.basis.size
    per_element = system_measures_batch(model, Q.reshape(P, n_coord, -1), Om / hb.period, Om, hb.basis.samples) if P else None
    meas = per_element[0] if per_element else None
    names = getattr(model, "element_names", None)
    element_cols = element_columns_from(names, per_element) if (names and per_element) else (
        element_columns_from(names, tuple(_empty_measures() for _ in names)) if names else {})
    t2 = time.perf_counter()
    empty = np.zeros(0)
    timings = dict(timings or {})
    timings.update({"stability": t1 - t0, "measures": t2 - t1})
    return FrequencyResponse(
        model=model,
        harmonics=hb.basis.harmonics,
        branch=np.full(P, branch_id, dtype=int),
        period=np.full(P, hb.period, dtype=int),
        omega=Om,
        mean=meas.mean if meas else empty,
        rms=meas.rms if meas else empty,
        rms_ac=meas.rms_ac if meas else empty,
        p2p=meas.p2p if meas else empty,
        acc_p2p=meas.acc_p2p if meas else empty,
        delta_min=meas.delta_min if meas else empty,
        delta_max=meas.delta_max if meas else empty,
        regime=meas.regime if meas else np.zeros(0, dtype=object),
        stable=stable,
        bifurcation=labels,
        iterations=its,
        residual=res,
        coefficients=Q,
        multipliers=mu,
        special_points=tuple(special),
        status=status,
        message=message or status.message,
        settings=dict(settings or {}),
        timings=timings,
        element_columns=element_cols,
    )


def _empty_measures() -> Measures:
    e = np.zeros(0)
    return Measures(e, e, e, e, e, e, e, np.zeros(0, dtype=object))


__all__ = ["frequency_response", "start_solution", "assemble"]
