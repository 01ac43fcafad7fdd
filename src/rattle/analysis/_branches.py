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

import numpy as np

from .._typing import FloatArray
from ..continuation import BranchPoint, ContinuationOptions, ContinuationStepper
from ..errors import Status
from ..hb import HarmonicBalance, HBOptions, NewtonOptions, solve_harmonic_balance
from ..model import Model
from ..results import FrequencyResponse


def embed_period(q: FloatArray, harmonics: int, factor: int, harmonics_new: int) -> FloatArray:
    """Coefficients of a solution with H harmonics of ω written with base ω/``factor``:
    harmonic k of ω becomes harmonic factor·k (zeros elsewhere), in a basis of ``harmonics_new``."""
    out = np.zeros(2 * harmonics_new + 1)
    out[0] = q[0]
    k = np.arange(1, harmonics + 1)
    keep = factor * k <= harmonics_new
    out[factor * k[keep]] = q[1 : harmonics + 1][keep]
    out[harmonics_new + factor * k[keep]] = q[harmonics + 1 :][keep]
    return out


def odd_indices(harmonics: int) -> np.ndarray:
    """Indices of the cosine and sine coefficients of the odd harmonics in q."""
    k = np.arange(1, harmonics + 1, 2)
    return np.concatenate((k, harmonics + k))


def critical_mode(hb2: HarmonicBalance, q2: FloatArray, omega: float) -> FloatArray:
    """Null vector φ of the odd block of ∂R/∂q of the doubled-period problem at q2 (unit norm,
    zero outside the odd harmonics)."""
    _, Rq, _ = hb2.residual_jacobian(q2, omega)
    odd = odd_indices(hb2.basis.harmonics)
    _, _, vt = np.linalg.svd(Rq[np.ix_(odd, odd)])
    phi = np.zeros(hb2.size)
    phi[odd] = vt[-1]
    return phi / np.linalg.norm(phi)


def _odd_part(q: FloatArray, odd: np.ndarray) -> FloatArray:
    return q[odd]


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
) -> tuple[HarmonicBalance, ContinuationStepper]:
    """Follow the period-2p branch born at a period-doubling point of a period-p branch.

    ``q_pd`` (H = ``harmonics`` harmonics of Ω/p) is the located point at ``omega_pd``. The new
    branch uses ``harmonics_new`` harmonics of Ω/(2p) (default 2H: the same resolution in
    frequency). Returns the HB problem of period 2p and the finished stepper.
    """
    H2 = 2 * harmonics if harmonics_new is None else harmonics_new
    newton = newton or NewtonOptions()
    hb2 = HarmonicBalance(model, HBOptions(harmonics=H2), period=2 * period)
    q2 = embed_period(q_pd, harmonics, 2, H2)
    # Polish the embedding on the doubled-period problem (the even block is regular there).
    res = solve_harmonic_balance(hb2, q2, omega_pd, newton)
    if res.converged and np.max(np.abs(res.q[odd_indices(H2)])) < 1e-9 * max(1.0, np.max(np.abs(res.q))):
        q2 = res.q
    phi = critical_mode(hb2, q2, omega_pd)
    odd = odd_indices(H2)
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
            return f"the period-{2 * period} branch rejoined a period-{period} branch near Ω = {pt.omega:.6g}"
        return None

    stepper = ContinuationStepper(
        hb2, q2, omega_pd, omega_range, continuation or ContinuationOptions(), newton, tangent=tangent, stop=rejoined,
    )
    stepper.run()
    return hb2, stepper


__all__ = ["embed_period", "odd_indices", "critical_mode", "switch_period_doubling"]


def period_doubling_branches(
    primary: FrequencyResponse,
    omega_range: tuple[float, float],
    *,
    max_period: int = 4,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    first_branch: int = 1,
    stability_refine: bool = True,
) -> list[FrequencyResponse]:
    """All branches born by period doubling from ``primary`` (one branch), recursively up to
    solutions of period ``max_period``. A branch that rejoins its parent at another
    period-doubling point ends exactly there, and that point is not switched at again."""
    from ._frequency_response import assemble

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
            hb2, stepper = switch_period_doubling(
                model, q_pd, w_pd, H, period, omega_range, continuation=continuation, newton=newton,
            )
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
                        q_end = embed_period(parent.coefficients[o.index], H, 2, hb2.basis.harmonics)
                        last = points[-1]
                        points[-1] = BranchPoint(q_end, float(parent.omega[o.index]), 0, last.residual, last.tangent, last.step)
                        end_is_pd = True
            branch = assemble(
                model, hb2, points, branch_id=next_id, refine=stability_refine, newton=newton,
                branch_points=(True, end_is_pd), status=stepper.status, message=stepper.message,
            )
            next_id += 1
            out.append(branch)
            queue.append(branch)
    return out


__all__ += ["period_doubling_branches"]
