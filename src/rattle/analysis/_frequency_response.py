"""frequency_response(): harmonic balance + arc-length continuation + stability + measures."""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import asdict
from typing import Literal

import numpy as np

from .._typing import FloatArray
from ..continuation import BranchPoint, ContinuationOptions, ContinuationStepper
from ..errors import ConvergenceError, Status
from ..hb import HarmonicBalance, HBOptions, NewtonOptions, solve_harmonic_balance
from ..measures import measures_batch, synthesize_batch
from ..model import Model
from ..results import FrequencyResponse, SpecialPoint
from ..stability import classify_loss, hill_multipliers, monodromy_batch, multipliers_from_monodromy
from ..stability._classify import UNIT_CIRCLE_TOL

logger = logging.getLogger("rattle")

StabilityMethod = Literal["monodromy", "hill"]


def _check_range(omega: object) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in omega)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise ValueError(f"`omega` must be a pair (min, max) of frequencies in rad/s, got {omega!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"`omega` must be finite, got {omega!r}")
    if not 0 < lo < hi:
        raise ValueError(f"`omega` must satisfy 0 < min < max, got ({lo}, {hi})")
    return lo, hi


def start_solution(hb: HarmonicBalance, omega: float, newton: NewtonOptions) -> tuple[FloatArray, str]:
    """A converged solution at Ω from the linear solution about the static equilibrium.

    If Newton fails from there, the dynamic forcing is raised from zero to its value in
    steps (a homotopy in the amplitude), each step started from the previous solution.
    """
    q_lin = hb.linear_solution(omega)
    res = solve_harmonic_balance(hb, q_lin, omega, newton)
    if res.converged:
        return res.q, "linear solution + Newton"
    full = hb.forcing.copy()
    static = np.zeros_like(full)
    static[0] = full[0]
    q = q_lin.copy()
    q[1:] = 0.0
    lam, dlam = 0.0, 0.1
    try:
        while lam < 1.0 and dlam > 1e-4:
            trial = min(1.0, lam + dlam)
            hb.forcing = static + trial * (full - static)
            r = solve_harmonic_balance(hb, q, omega, newton)
            if r.converged:
                q, lam = r.q, trial
                dlam = min(0.5, 1.5 * dlam)
            else:
                dlam *= 0.5
    finally:
        hb.forcing = full
    if lam >= 1.0:
        return q, "amplitude homotopy"
    raise ConvergenceError(
        f"no periodic solution found at Ω = {omega:g}: Newton from the linear solution failed "
        f"({res.message}, scaled residual {res.residual:.3g}) and the amplitude homotopy stalled at "
        f"{lam:.3g} of the forcing"
    )


def _bifurcations(stable: np.ndarray, mu: np.ndarray, branch: np.ndarray, omega: FloatArray) -> tuple[np.ndarray, list[SpecialPoint]]:
    labels = np.full(stable.size, "", dtype=object)
    special: list[SpecialPoint] = []
    for i in range(1, stable.size):
        if branch[i] != branch[i - 1] or stable[i] == stable[i - 1]:
            continue
        kind = classify_loss(mu[i - 1], mu[i])
        # Label the one of the two points whose critical multiplier is closer to the circle.
        j = i if abs(np.max(np.abs(mu[i])) - 1.0) <= abs(np.max(np.abs(mu[i - 1])) - 1.0) else i - 1
        labels[j] = kind
        special.append(SpecialPoint(kind, j, float(omega[j]), int(branch[j]), mu[j].copy()))
    return labels, special


def frequency_response(
    model: Model,
    omega: tuple[float, float] = (0.1, 3.0),
    harmonics: int = 32,
    *,
    samples: int | None = None,
    period: int = 1,
    start: Literal["low", "high"] = "low",
    stability: StabilityMethod = "monodromy",
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    throw: bool = True,
    callback: Callable[[BranchPoint], None] | None = None,
) -> FrequencyResponse:
    """Non-linear frequency response of ``model`` over ``omega`` = (Ω_min, Ω_max) rad/s.

    Harmonic balance with ``harmonics`` harmonics of the solution's base frequency Ω/``period``
    (AFT with ``samples`` time samples per period, default :func:`~rattle.hb.default_samples`),
    followed from the linear solution at the ``start`` end of the range by pseudo-arclength
    continuation through every fold. Floquet multipliers for every point (``stability``:
    ``"monodromy"`` the exact monodromy of the piecewise-linear linearisation about the HB
    orbit, or ``"hill"`` Hill's method), stability changes labelled.

    If the run ends before the far end of the range, ``throw=True`` raises ConvergenceError
    with the points computed so far in ``.partial``; ``throw=False`` returns them with the status.
    """
    lo, hi = _check_range(omega)
    if start not in ("low", "high"):
        raise ValueError(f"`start` must be 'low' or 'high', got {start!r}")
    if stability not in ("monodromy", "hill"):
        raise ValueError(f"`stability` must be 'monodromy' or 'hill', got {stability!r}")
    if continuation is not None and not isinstance(continuation, ContinuationOptions):
        raise TypeError(f"`continuation` must be a ContinuationOptions, got {continuation!r}")
    if newton is not None and not isinstance(newton, NewtonOptions):
        raise TypeError(f"`newton` must be a NewtonOptions, got {newton!r}")
    cont_opts = continuation or ContinuationOptions()
    newton_opts = newton or NewtonOptions()
    hb_opts = HBOptions(harmonics=harmonics, samples=samples)
    t_start = time.perf_counter()
    hb = HarmonicBalance(model, hb_opts, period=period)
    omega0 = lo if start == "low" else hi
    try:
        q0, how = start_solution(hb, omega0, newton_opts)
    except ConvergenceError:
        if throw:
            raise
        q0, how = hb.linear_solution(omega0), "failed"
    stepper = ContinuationStepper(hb, q0, omega0, (lo, hi), cont_opts, newton_opts)
    while (pt := stepper.step()) is not None:
        if callback is not None:
            callback(pt)
    t_cont = time.perf_counter()
    points = stepper.points
    status = stepper.status or Status.START_FAILED
    logger.info("continuation: %d points, %s (%s)", len(points), status.name, stepper.message)
    result = assemble(
        model, hb, points, stability=stability, status=status, message=stepper.message,
        settings={
            "omega": [lo, hi], "harmonics": harmonics, "samples": hb.basis.samples, "period": period,
            "start": start, "start_solution": how, "stability": stability,
            "continuation": asdict(cont_opts), "newton": asdict(newton_opts),
            "rejected_steps": stepper.rejected,
        },
        timings={"continuation": t_cont - t_start},
    )
    if throw and not status.success:
        raise ConvergenceError(f"frequency response incomplete: {stepper.message}", partial=result)
    return result


def assemble(
    model: Model,
    hb: HarmonicBalance,
    points: list[BranchPoint],
    *,
    branch_id: int = 0,
    stability: StabilityMethod = "monodromy",
    status: Status = Status.SUCCESS,
    message: str = "",
    settings: dict | None = None,
    timings: dict | None = None,
) -> FrequencyResponse:
    """Stability, measures and labels for the points of one branch -> FrequencyResponse."""
    t0 = time.perf_counter()
    P = len(points)
    n = hb.size
    Q = np.array([p.q for p in points]).reshape(P, n)
    Om = np.array([p.omega for p in points], dtype=float)
    w = Om / hb.period
    X = synthesize_batch(Q, hb.basis.samples) if P else np.zeros((0, hb.basis.samples))
    if P == 0:
        mu = np.zeros((0, 2), dtype=complex)
    elif stability == "monodromy":
        st = model.elastic.stages
        mu = multipliers_from_monodromy(monodromy_batch(Q, w, X, st.breakpoints, model.k * st.slopes, model.c))
    else:
        mu = np.array([hill_multipliers(hb, q, om) for q, om in zip(Q, Om)]).reshape(P, 2)
    t1 = time.perf_counter()
    stable = np.max(np.abs(mu), axis=1) < 1.0 - UNIT_CIRCLE_TOL if P else np.zeros(0, dtype=bool)
    branch = np.full(P, branch_id, dtype=int)
    labels, special = _bifurcations(stable, mu, branch, Om)
    meas = measures_batch(model, Q, w, Om, X) if P else None
    t2 = time.perf_counter()
    empty = np.zeros(0)
    timings = dict(timings or {})
    timings.update({"stability": t1 - t0, "measures": t2 - t1})
    return FrequencyResponse(
        model=model,
        harmonics=hb.basis.harmonics,
        branch=branch,
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
        iterations=np.array([p.iterations for p in points], dtype=int),
        residual=np.array([p.residual for p in points], dtype=float),
        coefficients=Q,
        multipliers=mu,
        special_points=tuple(special),
        status=status,
        message=message or status.message,
        settings=dict(settings or {}),
        timings=timings,
    )


__all__ = ["frequency_response", "start_solution", "assemble"]
