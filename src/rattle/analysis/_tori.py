"""Time-domain confirmation of the Neimark–Sacker intervals of a frequency response.

Between two Neimark–Sacker points a branch is unstable by a complex pair of Floquet multipliers
(a ``torus`` region, :func:`rattle.analysis._regimes.torus_regions`). What the motion does there
is a question for the simulation, not for the harmonic balance: for a supercritical bifurcation
it settles on an invariant torus (quasi-periodic motion: on the Poincaré section, a closed
invariant curve around the unstable orbit), but it may as well jump to another attractor (a
coexisting stable orbit, a locked period-n orbit on the torus, chaos).

:func:`confirm_tori` answers it with one simulation per region: at the branch row nearest the
middle of the interval the unstable orbit is closed by exact shooting (z*, its monodromy M),
the state is perturbed by 10⁻³ of the length scale along the unstable complex eigenvector and
simulated to its steady state (:func:`rattle.analysis.steady_state`, with a long recorded
window). The Poincaré points of an unsettled motion (period 0) are then examined
(:func:`section_curve`): projected on the plane of the unstable eigenvector pair about z*, a
torus shows as points that wind around z* in one sense with a steady angle step and lie on one
closed curve (radius a single-valued, continuous function of the angle); their mean angle step
/ 2π is the rotation number ρ of the section map, the torus' frequency ratio, to compare with
the ratio θ/2π of the critical multipliers at the Neimark–Sacker points.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..results import FrequencyResponse
from ..results import Region
from ..timeint import ShootingProblem, state_scale
from ._steady import SteadyStateOptions, make_integrator, steady_state

#: Settling options of the confirmation run: 600 periods to settle (the unstable orbit is left in
#: tens of periods), a long recorded window (the
#: Poincaré points examined for a closed curve).
CONFIRM_OPTIONS = SteadyStateOptions(max_periods=600, record_periods=200, section_points=200)
#: Perturbation of the unstable orbit, as a fraction of the model's length scale.
_KICK = 1e-3
#: Largest gap between angle-neighbours on a closed curve, relative to the set's diameter.
_CURVE_JUMP = 0.25


def _system_of(model: Any) -> Any:
    return model.system() if hasattr(model, "system") else None


def _state_at_zero(q: FloatArray, n: int, omega: float, period: int) -> FloatArray:
    """(x(0), x'(0)) of the coordinate-major series q (n blocks of 2H+1) of base Ω/period."""
    Q = np.asarray(q, dtype=float).reshape(n, -1)
    H = (Q.shape[1] - 1) // 2
    k = np.arange(1, H + 1)
    w = omega / period
    x = Q[:, 0] + Q[:, 1 : H + 1].sum(axis=1)
    v = (Q[:, H + 1 :] * (k * w)).sum(axis=1)
    return np.concatenate((x, v))


def section_curve(points: FloatArray, center: FloatArray, plane: FloatArray, period: int = 1) -> dict[str, Any]:
    """Whether Poincaré points lie on one closed curve winding around ``center``.

    ``points`` (N, d) in forcing-period order; ``plane`` (d, 2) the real basis of the unstable
    eigenvector pair; with ``period`` p > 1 every p-th point is taken (the section map φ^p of a
    period-p orbit). Returns ``rotation`` (mean angle step / 2π, in [0, ½]: the rotation number),
    ``winds`` (every angle step of the same sign: the angle parametrises the set),
    ``curve_jump`` (largest state-space distance between angle-neighbours, every component
    scaled by its spread, over the set's diameter: small when the points lie densely on one
    curve, of order 1 for a cloud), ``closed_curve`` (winds and curve_jump ≤ 0.25),
    ``min_distance`` (smallest distance between two points / median radius: 0 for a periodic
    orbit), ``points`` (N/p, the number examined).
    """
    P = np.asarray(points, dtype=float)[:: max(1, int(period))]
    coords = np.linalg.lstsq(plane, (P - center).T, rcond=None)[0]  # (2, N)
    theta = np.arctan2(coords[1], coords[0])
    radius = np.hypot(coords[0], coords[1])
    step = np.angle(np.exp(1j * np.diff(theta)))
    out: dict[str, Any] = {"points": int(P.shape[0])}
    if P.shape[0] < 8 or not np.all(radius > 0):
        return {**out, "rotation": float("nan"), "winds": False, "curve_jump": float("inf"),
                "closed_curve": False, "min_distance": 0.0}
    winds = bool(np.all(step > 0) or np.all(step < 0))
    mean_step = float(np.mean(step))
    rotation = abs(mean_step) / (2.0 * math.pi)
    # Neighbours in angle must be neighbours in the state space (a curve, not a cloud): the
    # largest gap between them, each component scaled by its spread, over the set's diameter.
    spread = np.ptp(P, axis=0)
    S = (P - center) / np.where(spread > 0, spread, 1.0)
    ring = S[np.argsort(theta)]
    gaps = np.linalg.norm(np.diff(np.vstack((ring, ring[:1])), axis=0), axis=1)
    diameter = float(np.max(np.linalg.norm(S[:, None, :] - S[None, :, :], axis=-1)))
    jump = float(np.max(gaps)) / diameter
    d = np.linalg.norm(P[:, None, :] - P[None, :, :], axis=-1)
    d[np.diag_indices_from(d)] = np.inf
    min_dist = float(np.min(d)) / float(np.median(np.linalg.norm(P - center, axis=1)))
    return {**out, "rotation": rotation, "winds": winds, "curve_jump": jump,
            "closed_curve": bool(winds and jump <= _CURVE_JUMP), "min_distance": min_dist}


def _middle_row(frf: FrequencyResponse, region: Region) -> int:
    i0, i1 = (int(i) for i in region.detail["rows"])
    b = int(region.detail.get("branch", frf.branch[i0]))
    rows = [i for i in range(min(i0, i1) + 1, max(i0, i1)) if int(frf.branch[i]) == b]
    if not rows:
        rows = [i0]
    mid = 0.5 * (region.omega_min + region.omega_max)
    return min(rows, key=lambda i: abs(float(frf.omega[i]) - mid))


def simulate_torus(frf: FrequencyResponse, region: Region, options: SteadyStateOptions | None = None) -> dict[str, Any]:
    """One simulation from the perturbed unstable orbit in the middle of a ``torus`` region
    (module docstring): what it settles on, as a dict (``omega``, ``period`` 0 … 8,
    ``method``, ``rms`` of the first element, ``orbit_rms`` of the unstable orbit, and for
    period 0 the :func:`section_curve` verdict with ``rotation``)."""
    model = frf.model
    opts = CONFIRM_OPTIONS if options is None else options
    row = _middle_row(frf, region)
    W = float(frf.omega[row])
    p = int(frf.period[row])
    system = None if type(model).__name__ == "Model" else _system_of(model)
    n = 1 if system is None else system.n
    z_hb = _state_at_zero(frf.coefficients[row], n, W, p)
    integ = make_integrator(model)
    target = model if system is None else integ.system
    scale = state_scale(target, W)
    shot = ShootingProblem(target, period=p, integrator=integ).solve(
        z_hb, W, tol=1e-12, max_iterations=20, max_halvings=12, scale=scale)
    converged = shot.residual <= 1e-10
    z_star = shot.x if converged else z_hb
    M = shot.trajectory.sensitivity
    mu, V = np.linalg.eig(M)
    k = int(np.argmax(np.where(np.abs(mu.imag) > 1e-12, np.abs(mu), -np.inf)))
    if np.abs(mu[k].imag) <= 1e-12:  # no complex pair: the most unstable direction, doubled
        k = int(np.argmax(np.abs(mu)))
        plane = np.column_stack((V[:, k].real, np.roll(V[:, k].real, 1)))
    else:
        plane = np.column_stack((V[:, k].real, V[:, k].imag))
    kick = plane[:, 0] / np.max(np.abs(plane[:, 0] / scale))  # unit scaled size
    start = z_star + _KICK * kick
    run = steady_state(model, W, start, options=opts, integrator=integ)
    out: dict[str, Any] = {
        "omega": W, "row": row, "period": int(run.period), "method": run.method, "rms": float(run.rms),
        "orbit_rms": float(frf.rms[row]), "orbit_shot": bool(converged),
        "orbit_multipliers": [[float(z.real), float(z.imag)] for z in sorted(mu, key=lambda z: -abs(z))[:2]],
    }
    if run.period == 0:
        curve = section_curve(run.poincare, z_star, plane, p)
        out.update({k_: v for k_, v in curve.items()})
    return out


def _verdict(sim: dict[str, Any]) -> str:
    W = sim["omega"]
    if sim["period"] == 0 and sim.get("closed_curve"):
        return (f"simulation at Ω = {W:.4g} from the unstable orbit: quasi-periodic (Poincaré points on a closed "
                f"curve, rotation number {sim['rotation']:.3g})")
    if sim["period"] == 0:
        return (f"simulation at Ω = {W:.4g} from the unstable orbit: no period ≤ 8 and the Poincaré points do not "
                "lie on a closed curve (chaotic, or a torus not yet reached)")
    return (f"simulation at Ω = {W:.4g} from the unstable orbit: settles on period-{sim['period']} motion "
            f"(rms {sim['rms']:.4g} rad; the unstable orbit's {sim['orbit_rms']:.4g}) — not quasi-periodic")


def confirm_tori(frf: FrequencyResponse, options: SteadyStateOptions | None = None) -> tuple[Region, ...]:
    """The regions of ``frf`` with every ``torus`` region confirmed by one simulation
    (:func:`simulate_torus`): ``detail["simulated_periods"]`` = [the period it settled on]
    (0: none ≤ 8), ``detail["simulation"]`` the whole record, and the label saying what the
    simulation found (quasi-periodic with its rotation number, or the period it jumped to)."""
    out = []
    done: list[tuple[float, float, dict[str, Any]]] = []
    for r in frf.regions:
        if r.kind != "torus" or "rows" not in r.detail or "simulated_periods" in r.detail:
            out.append(r)
            continue
        sim = simulate_torus(frf, r, options)
        done.append((r.omega_min, r.omega_max, sim))
        detail = dict(r.detail, simulated_periods=[sim["period"]], simulation=sim)
        head = r.label.split(": quasi-periodic motion likely")[0]
        ratios = [x for x in r.detail.get("torus_ratio", []) if x is not None]
        ratio = f" (torus frequency ratio at the Neimark–Sacker points ≈ {np.mean(ratios):.3g})" if ratios else ""
        out.append(replace(r, label=f"{head}{ratio}; {_verdict(sim)}", detail=detail))
    # An interval without a stable computed orbit that is such a torus stretch says what the
    # simulation found instead of "quasi-periodic motion likely".
    for k, r in enumerate(out):
        if r.kind == "unstable_not_computed" and "quasi-periodic motion likely" in r.label:
            for lo, hi, sim in done:
                if lo - 1e-9 <= r.omega_min and r.omega_max <= hi + 1e-9:
                    what = "quasi-periodic" if sim["period"] == 0 and sim.get("closed_curve") else (
                        f"period {sim['period']}" if sim["period"] else "no period ≤ 8, not on a closed curve")
                    out[k] = replace(r, label=r.label.replace(
                        "quasi-periodic motion likely", f"simulation from the unstable orbit: {what}"),
                        detail=dict(r.detail, simulated_periods=[sim["period"]]))
    return tuple(out)


__all__ = ["confirm_tori", "simulate_torus", "section_curve", "CONFIRM_OPTIONS"]
