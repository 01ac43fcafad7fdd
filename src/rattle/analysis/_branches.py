"""Sub-harmonic branches: switching at period doubling and continuation from seeds.

A period-doubling point of a branch of period p (a Floquet multiplier at −1) is a pitchfork of
the same solutions written with period 2p: with base frequency Ω/(2p) the period-p orbit has
only even harmonics, and the HB Jacobian of the period-2p problem decouples into an even and
an odd block (the orbit's stiffness g(t) has only even harmonics, so g·δ couples odd with odd).
At the period-doubling point the odd block is singular; its null vector φ (the critical
Floquet mode, T-antiperiodic) is the tangent of the new branch. We start the period-2p
continuation at the located point along (φ, 0) and follow it until it rejoins a period-p branch
(its odd part shrinks to zero and changes sign: another period-doubling point) or leaves the
frequency range.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._typing import FloatArray
from ..continuation import BranchPoint, ContinuationOptions, ContinuationStepper
from ..errors import Status
from ..hb import HarmonicBalance, HBOptions, NewtonOptions, resize_harmonics, solve_harmonic_balance
from ..model import Model
from ..results import FrequencyResponse, SpeedText
from ..stability import FloquetMonitor
from ..timeint import ExactIntegrator
from ._assemble import assemble
from ._settings import RunSettings


def _run(run: RunSettings | None, harmonics: int, continuation: ContinuationOptions | None,
         newton: NewtonOptions | None) -> RunSettings:
    """``run``, or (old keyword style) one made of ``continuation``/``newton`` and default HB."""
    if run is not None:
        return run
    return RunSettings.make(HBOptions(harmonics=harmonics), newton, continuation)


def odd_indices(harmonics: int, coordinates: int = 1) -> np.ndarray:
    """Indices of the cosine and sine coefficients of the odd harmonics in q (every coordinate's
    block of 2H + 1, coordinate-major)."""
    k = np.arange(1, harmonics + 1, 2)
    one = np.concatenate((k, harmonics + k))
    return np.concatenate([one + i * (2 * harmonics + 1) for i in range(coordinates)])


def _coordinates(hb: HarmonicBalance) -> int:
    return hb.size // hb.basis.size


def _resize(q: FloatArray, coordinates: int, harmonics: int, factor: int = 1) -> FloatArray:
    """:func:`~rattle.hb.resize_harmonics` of every coordinate block of the flat ``q``."""
    return resize_harmonics(np.asarray(q).reshape(coordinates, -1), harmonics, factor).reshape(-1)


def critical_mode(hb2: HarmonicBalance, q2: FloatArray, omega: float) -> FloatArray:
    """Null vector φ of the odd block of ∂R/∂q of the doubled-period problem at q2 (unit norm,
    zero outside the odd harmonics)."""
    _, Rq, _ = hb2.residual_jacobian(q2, omega)
    odd = odd_indices(hb2.basis.harmonics, _coordinates(hb2))
    _, _, vt = np.linalg.svd(Rq[np.ix_(odd, odd)])
    phi = np.zeros(hb2.size)
    phi[odd] = vt[-1]
    return phi / np.linalg.norm(phi)


def _odd_part(q: FloatArray, odd: np.ndarray) -> FloatArray:
    return q[odd]


#: A period-n solution whose harmonics that are not multiples of n carry less than this fraction
#: of its dynamic part (the norm of every harmonic) is a solution of a shorter period written with
#: period n (the period-1 orbit repeated): not a period-n attractor.
SHORTER_PERIOD_RTOL = 1e-3


def sub_harmonic_fraction(q: FloatArray, coordinates: int, period: int) -> float:
    """‖harmonics k of Ω/n with n ∤ k‖ / ‖every harmonic k ≥ 1‖ of the period-n coefficients
    ``q`` (``coordinates`` rows of 2H + 1: mean, cosines, sines); 1 for a period-1 solution,
    0 for a motion without dynamic part."""
    if period <= 1:
        return 1.0
    Q = np.asarray(q, dtype=float).reshape(coordinates, -1)
    H = (Q.shape[1] - 1) // 2
    not_multiple = np.array([k % period != 0 for k in range(1, H + 1)])
    sub = np.concatenate(([False], not_multiple, not_multiple))
    dynamic = float(np.linalg.norm(Q[:, 1:]))
    return float(np.linalg.norm(Q[:, sub])) / dynamic if dynamic > 0.0 else 0.0


def is_shorter_period(q: FloatArray, coordinates: int, period: int) -> bool:
    """Whether period-``period`` coefficients are a solution of a shorter period (see
    :data:`SHORTER_PERIOD_RTOL`)."""
    return period > 1 and sub_harmonic_fraction(q, coordinates, period) < SHORTER_PERIOD_RTOL


def switch_period_doubling(
    model: Model,
    q_pd: FloatArray,
    omega_pd: float,
    harmonics: int,
    period: int,
    omega_range: tuple[float, float],
    *,
    harmonics_new: int | None = None,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    run: RunSettings | None = None,
) -> tuple[HarmonicBalance, ContinuationStepper]:
    """Follow the period-2p branch born at a period-doubling point of a period-p branch.

    ``q_pd`` (H = ``harmonics`` harmonics of Ω/p) is the located point at ``omega_pd``. The new
    branch uses ``harmonics_new`` harmonics of Ω/(2p) (default 2H: the same resolution in
    frequency), with the run's HBOptions scaled to that count (``run.for_harmonics``), its
    Newton and continuation options. Returns the HB problem of period 2p and the finished stepper.
    """
    H2 = 2 * harmonics if harmonics_new is None else harmonics_new
    speed_text = SpeedText.of(model)  # an engine case's messages in rpm
    run = _run(run, harmonics, continuation, newton)
    newton = run.newton
    hb2 = HarmonicBalance(model, run.for_harmonics(H2), period=2 * period)
    n = _coordinates(hb2)
    q2 = _resize(q_pd, n, H2, factor=2)
    odd = odd_indices(H2, n)
    # Polish the embedding on the doubled-period problem (the even block is regular there).
    res = solve_harmonic_balance(hb2, q2, omega_pd, newton)
    if res.converged and np.max(np.abs(res.q[odd])) < 1e-9 * max(1.0, np.max(np.abs(res.q))):
        q2 = res.q
    phi = critical_mode(hb2, q2, omega_pd)
    # Tangent in scaled variables: along φ, with no change in Ω.
    tangent = np.zeros(hb2.size + 1)
    tangent[:-1] = phi  # q / L scaling is uniform, so φ's direction is unchanged
    start_odd = phi[odd]
    state = {"prev": start_odd}

    def rejoined(pt: BranchPoint) -> str | None:
        o = _odd_part(pt.q, odd)
        prev = state["prev"]
        state["prev"] = o
        if float(o @ prev) < 0.0:
            return f"the period-{2 * period} branch rejoined a period-{period} branch near {speed_text.at(pt.omega, 6)}"
        return None

    stepper = ContinuationStepper(
        hb2, q2, omega_pd, omega_range, run.continuation, newton, tangent=tangent, stop=rejoined,
        monitor=FloquetMonitor(hb2), speed=speed_text.at if speed_text.engine else None,
    )
    stepper.run()
    return hb2, stepper


__all__ = ["odd_indices", "critical_mode", "switch_period_doubling", "sub_harmonic_fraction", "is_shorter_period",
           "SHORTER_PERIOD_RTOL"]


def period_doubling_branches(
    primary: FrequencyResponse,
    omega_range: tuple[float, float],
    *,
    max_period: int = 4,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    first_branch: int = 1,
    stability_refine: bool = True,
    run: RunSettings | None = None,
) -> list[FrequencyResponse]:
    """All branches born by period doubling from ``primary`` (one branch), recursively up to
    solutions of period ``max_period``. A branch that rejoins its parent at another
    period-doubling point ends exactly there, and that point is not switched at again.
    ``run`` (the parent run's settings) goes unchanged to every branch; each branch's
    ``settings`` records what it used."""
    run = _run(run, primary.harmonics, continuation, newton)
    model = primary.model
    out: list[FrequencyResponse] = []
    queue = [primary]
    next_id = first_branch
    while queue:
        parent = queue.pop(0)
        period = int(parent.period[0])
        if 2 * period > max_period:
            continue
        H = parent.harmonics
        done: set[int] = set()
        # Genuine period doublings of this branch: a multiplier at −1 (the birth point of a
        # switched branch is labelled period_doubling too, but its multiplier is +1 here).
        pds = [sp for sp in parent.special_points
               if sp.kind == "period_doubling" and sp.located and sp.multipliers[0].real < 0]
        for sp in pds:
            if sp.index in done:
                continue
            done.add(sp.index)
            q_pd = parent.coefficients[sp.index]
            w_pd = float(parent.omega[sp.index])
            hb2, stepper = switch_period_doubling(model, q_pd, w_pd, H, period, omega_range, run=run)
            points = list(stepper.points)
            end_is_pd = False
            if stepper.status is Status.STOPPED and len(points) > 2:
                # Replace the point past the rejoin by the parent's period-doubling point there.
                w_end = points[-1].omega
                others = [o for o in pds if o.index not in done]
                if others:
                    o = min(others, key=lambda o: abs(float(parent.omega[o.index]) - w_end))
                    if abs(float(parent.omega[o.index]) - w_end) < 1e-2 * (omega_range[1] - omega_range[0]):
                        done.add(o.index)
                        q_end = _resize(parent.coefficients[o.index], _coordinates(hb2), hb2.basis.harmonics, factor=2)
                        last = points[-1]
                        points[-1] = BranchPoint(q_end, float(parent.omega[o.index]), 0, last.residual, last.tangent, last.step)
                        end_is_pd = True
            branch = assemble(
                model, hb2, points, branch_id=next_id, refine=stability_refine, newton=run.newton,
                stability=run.stability, branch_points=(True, end_is_pd), status=stepper.status or Status.STOPPED,
                message=stepper.message,
                settings=run.record(hb2.options, period=2 * period,
                                    origin=f"period doubling of branch {int(parent.branch[0])} at Ω = {w_pd:.6g}"),
            )
            next_id += 1
            out.append(branch)
            queue.append(branch)
    return out


__all__ += ["period_doubling_branches"]


def branch_from_seed(
    model: Model,
    omega: float,
    q_seed: FloatArray,
    period: int,
    omega_range: tuple[float, float],
    harmonics: int,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    branch_id: int = 0,
    run: RunSettings | None = None,
) -> FrequencyResponse | None:
    """The branch of period ``period`` through a seed (coefficients with ``harmonics`` harmonics
    of Ω/period, e.g. from a simulated orbit) at ``omega``: Newton at that Ω, then continuation
    both ways in Ω, joined into one branch. An isola is closed once (the run stops when it comes
    back to the seed). None if the seed does not converge. ``run``: the run's settings (HB
    options scaled to ``harmonics``, Newton, continuation, stability method)."""
    run = _run(run, harmonics, continuation, newton)
    newton = run.newton
    speed_text = SpeedText.of(model)  # an engine case's messages in rpm
    hb_opts = run.for_harmonics(harmonics)
    hb = HarmonicBalance(model, hb_opts, period=period)
    res = solve_harmonic_balance(hb, q_seed, omega, newton)
    if not res.converged:
        return None
    n_coord = _coordinates(hb)
    if is_shorter_period(res.q, n_coord, period):
        return None  # the seed converged onto a shorter period's orbit written with this period
    not_multiple = np.array([k % period != 0 for k in range(1, harmonics + 1)])
    sub_mask = np.concatenate(([False], not_multiple, not_multiple))
    from ..continuation import ArclengthCorrector

    corrector = ArclengthCorrector(hb, newton)
    _, Rq, Rw = hb.residual_jacobian(res.q, omega)
    y_seed = corrector.to_scaled(res.q, omega)
    halves: list[list[BranchPoint]] = []
    statuses = []
    for sign in (1.0, -1.0):
        reference = np.zeros(hb.size + 1)
        reference[-1] = sign
        tangent = corrector.tangent(Rq, Rw, reference)
        if tangent is None:
            return None
        count: dict[str, Any] = {"n": 0}

        def back_at_seed(pt: BranchPoint) -> str | None:
            count["n"] += 1
            y = corrector.to_scaled(pt.q, pt.omega)
            if count["n"] > 5 and np.linalg.norm(y - y_seed) < 0.5 * max(pt.step, 1e-9):
                count["isola"] = True
                return "the branch closed on itself (an isola)"
            if period > 1:
                # At a period doubling the period-n branch meets the orbit of period n/2, which is
                # also a solution of the period-n balance: the sub-harmonic part (harmonics k with
                # n ∤ k) goes through zero there. Stop on it (not onto the shorter period's branch)
                # or where it changed sign between two points (past it, onto the branch's copy
                # shifted by a forcing period: the same orbits again).
                sub = pt.q.reshape(n_coord, -1)[:, sub_mask].ravel()
                prev, count["sub"] = count.get("sub"), sub
                count["past"] = prev is not None and float(sub @ prev) < 0.0
                if count["past"] or is_shorter_period(pt.q, n_coord, period):
                    return f"the period-{period} branch rejoined a shorter period's branch near {speed_text.at(pt.omega, 6)}"
            return None

        stepper = ContinuationStepper(hb, res.q, omega, omega_range, run.continuation, newton,
                                      tangent=tangent, stop=back_at_seed, monitor=FloquetMonitor(hb),
                                      speed=speed_text.at if speed_text.engine else None)
        stepper.run()
        # a point past the doubling is on the branch's shifted copy: the branch ends before it
        halves.append(stepper.points[:-1] if count.get("past") and len(stepper.points) > 2 else stepper.points)
        statuses.append(stepper)
        if count.get("isola"):
            break  # an isola: one way round covers it
    points = halves[0] if len(halves) == 1 else halves[1][::-1] + halves[0][1:]
    status = statuses[0].status or Status.STOPPED
    return assemble(model, hb, points, branch_id=branch_id, newton=newton, stability=run.stability, status=status,
                    message="; ".join(s.message for s in statuses),
                    settings=run.record(hb_opts, period=period, origin=f"seed at Ω = {omega:.6g}"))


def explained(frf: FrequencyResponse, period: int, omega: float, rms: float, rtol: float, *,
              stable_only: bool = True) -> bool:
    """Whether a stable stretch of a period-``period`` branch crosses Ω with that rms (with
    ``stable_only=False``: any stretch of it)."""
    for b in np.unique(frf.branch[frf.period == period]):
        rows = np.nonzero(frf.branch == b)[0]
        om, r = frf.omega[rows], frf.rms[rows]
        st = (frf.stable[rows] | (frf.bifurcation[rows] != "")) if stable_only else np.ones(rows.size, dtype=bool)
        lo, hi = om[:-1], om[1:]
        cross = ((lo - omega) * (hi - omega) <= 0) & st[:-1] & st[1:] & (lo != hi)
        for i in np.nonzero(cross)[0]:
            s = (omega - lo[i]) / (hi[i] - lo[i])
            if abs(((1 - s) * r[i] + s * r[i + 1]) / rms - 1) < rtol:
                return True
    return False


def sweep_seeds(frf: FrequencyResponse, sweep: object, *, harmonics_per_period: int | None = None,
                rtol: float = 1e-3, run: RunSettings | None = None) -> list[tuple[float, int, FloatArray]]:
    """Seeds (Ω, period n, coefficients) for the periodic motions of period n ≥ 2 that a time
    ``sweep`` (SweepResult) settled on and that no stable computed branch of period n explains
    (no stable stretch of that period crossing the sweep's Ω with an rms, interpolated there,
    within ``rtol``). The orbit is closed by exact shooting from the sweep's section state and
    analysed into n·H harmonics of Ω/n."""
    model = frf.model
    H = harmonics_per_period or int(frf.settings.get("harmonics", frf.harmonics))
    integ = ExactIntegrator(model)
    seeds: list[tuple[float, int, FloatArray]] = []
    omegas = np.asarray(sweep.omega)  # type: ignore[attr-defined]
    states = np.asarray(sweep.state0)  # type: ignore[attr-defined]
    step = float(np.min(np.diff(np.unique(omegas)))) if np.unique(omegas).size > 1 else 0.0
    for j, (w, n) in enumerate(zip(omegas, np.asarray(sweep.period))):  # type: ignore[attr-defined]
        n = int(n)
        if n < 2:
            continue
        rms = float(np.asarray(sweep.rms)[j])  # type: ignore[attr-defined]
        if explained(frf, n, float(w), rms, rtol):
            continue
        if any(abs(s[0] - w) <= step + 1e-12 and s[1] == n for s in seeds):
            continue  # one seed per stretch of unexplained motion
        q = seed_from_state(model, float(w), states[j], n, n * H, integrator=integ,
                            hb=None if run is None else run.for_harmonics(n * H))
        if q is not None:
            seeds.append((float(w), n, q))
    return seeds


def seed_from_state(model: Model, omega: float, x0: FloatArray, period: int, harmonics: int, *,
                    integrator: "ExactIntegrator | None" = None, hb: HBOptions | None = None) -> FloatArray | None:
    """HB coefficients (``harmonics`` of Ω/period) of the period-``period`` orbit through the
    state x0 = (δ, δ') at t = 0 (a forcing-phase-aligned section point): the orbit is closed by
    exact shooting and its samples analysed (on the sample grid of ``hb``, whose harmonic count
    must be ``harmonics``; default HBOptions). None if shooting does not converge."""
    from ..timeint import ExactIntegrator, shoot_periodic_orbit

    integ = ExactIntegrator(model) if integrator is None else integrator
    orbit = shoot_periodic_orbit(model, omega, np.asarray(x0, dtype=float), period=period, integrator=integ)
    if not orbit.converged:
        return None
    if hb is not None and hb.harmonics != harmonics:
        raise ValueError(f"`hb.harmonics` ({hb.harmonics}) must equal `harmonics` ({harmonics})")
    problem = HarmonicBalance(model, hb or HBOptions(harmonics=harmonics), period=period)
    T = period * 2 * np.pi / omega
    return problem.basis.analyze(np.asarray(orbit.trajectory.sample(problem.basis.times(T)).delta))


def seeded_branches(
    frf: FrequencyResponse,
    seeds: list[tuple[float, int, FloatArray]],
    omega_range: tuple[float, float],
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    first_branch: int,
    run: RunSettings | None = None,
) -> list[FrequencyResponse]:
    """Branches through ``seeds`` (Ω, period, coefficients), skipping a seed that a branch
    already found (including one from an earlier seed) explains."""
    out: list[FrequencyResponse] = []
    next_id = first_branch
    for w, n, q in seeds:
        known = FrequencyResponse.concatenate([frf, *out]) if out else frf
        rms = float(np.sqrt(q[0] ** 2 + 0.5 * np.sum(q[1:] ** 2)))
        if explained(known, n, w, rms, 1e-3):
            continue
        H = (q.size - 1) // 2
        branch = branch_from_seed(frf.model, w, q, n, omega_range, H, continuation=continuation, newton=newton,
                                  branch_id=next_id, run=run)
        if branch is not None and len(branch):
            out.append(branch)
            next_id += 1
    return out


__all__ += ["branch_from_seed", "sweep_seeds", "seed_from_state", "seeded_branches", "explained"]
