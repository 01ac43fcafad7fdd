"""Crossings of the clearance elements' breakpoints on an exact segment, located to round-off.

On a segment every element e sits on one stage [lo_e, hi_e) of its law. The segment ends at the
first local time where any deflection δ_e = a_e·x leaves its stage. Crossings are bracketed on a
grid of ``samples_per_scale`` points per fastest time scale of the stage combination (highest
forcing harmonic, highest natural frequency, fastest decay) scanned in growing chunks, all
elements at once. Inside a grid cell, an extremum of δ_e (a sign change of δ_e') is refined
too, so that a trajectory touching a breakpoint tangentially inside a cell is not missed. Roots
are refined by Newton's method safeguarded by bisection. An excursion beyond a breakpoint below
round-off (an exact graze) does not switch the stage; the segment start is inside its stages by
construction (a crossing enters the new stage), whatever round-off says of δ there.
"""

from __future__ import annotations

import math

import numpy as np

from .._typing import FloatArray
from ._roots import bracketed_newton, vector_bracketed_newton
from ._stage_flow import Segment

_EPS = float(np.finfo(float).eps)
_FIRST_CHUNK = 48  # grid cells scanned at once for the first crossing; doubled up to _MAX_CHUNK
_MAX_CHUNK = 4096


def first_exit(
    seg: Segment, lo: FloatArray, hi: FloatArray, tau_end: float, step: float, samples_per_scale: int,
) -> tuple[float, int, int]:
    """First local time in (0, ``tau_end``] where an element leaves its stage on ``seg``:
    (τ, element, direction +1 up / −1 down); element −1 and τ = ``tau_end`` when none does.

    ``lo``, ``hi`` (m,) are the elements' stage bounds (±inf where open), ``step`` the grid step.
    """
    if tau_end <= 0.0 or not seg.sol.bounded:
        return tau_end, -1, 0
    if not (math.isfinite(step) and step > 0.0):
        step = max(tau_end, 1e-300) / samples_per_scale
    tau_a = 0.0
    chunk = _FIRST_CHUNK
    while tau_a < tau_end:
        n = max(1, min(chunk, math.ceil((tau_end - tau_a) / step)))
        taus = tau_a + step * np.arange(n + 1)
        if n < chunk or taus[-1] >= tau_end:
            taus[-1] = tau_end
        d, v = seg.scan(taus)
        D = d[1:]
        outside = (D >= hi) | (D < lo)  # (n, m)
        i_out = np.where(outside.any(axis=0), outside.argmax(axis=0), n)
        pos = v > 0.0
        change = pos[:-1] != pos[1:]
        cands: list[tuple[int, int]] = []
        i_out_l = i_out.tolist()
        if change.any():
            ci, ce = change.nonzero()
            for i, e in zip(ci.tolist(), ce.tolist()):
                if i >= i_out_l[e]:
                    continue
                d_a, d_b, v_a, v_b = float(d[i, e]), float(d[i + 1, e]), float(v[i, e]), float(v[i + 1, e])
                # An extremum inside a cell can only reach a breakpoint within the cell's possible
                # excursion (δ' passes through zero and |δ'| is at most about its end values;
                # factor 2 for safety): refine only those.
                excursion = 2.0 * float(taus[i + 1] - taus[i]) * max(abs(v_a), abs(v_b))
                if (max(d_a, d_b) + excursion < hi[e]) if v_a > 0.0 else (min(d_a, d_b) - excursion > lo[e]):
                    continue
                cands.append((i, e))
        for e, i in enumerate(i_out_l):
            if i < n:
                cands.append((i, e))
        if cands:
            cands.sort()
            best: tuple[float, int, int] | None = None
            cell = -1
            for i, e in cands:
                if best is not None and i != cell:
                    break
                cell = i
                hit = _resolve_cell(seg, e, float(lo[e]), float(hi[e]), float(taus[i]), float(taus[i + 1]),
                                    float(d[i, e]), float(d[i + 1, e]), float(v[i, e]), float(v[i + 1, e]),
                                    at_start=(i == 0 and tau_a == 0.0))
                if hit is not None and hit[0] < tau_end and (best is None or hit[0] < best[0]):
                    best = (hit[0], e, hit[1])
            if best is not None:
                return best
        tau_a = float(taus[-1])
        chunk = min(2 * chunk, _MAX_CHUNK)
    return tau_end, -1, 0


def _resolve_cell(
    seg: Segment, e: int, lo: float, hi: float, tau_a: float, tau_b: float,
    d_a: float, d_b: float, v_a: float, v_b: float, at_start: bool,
) -> tuple[float, int] | None:
    """The exit of element ``e`` from its stage inside the grid cell [tau_a, tau_b], if any:
    (τ, direction); None when δ_e stays inside or only grazes a breakpoint (an excursion beyond
    it below round-off)."""

    def state(tau: float) -> tuple[float, float, float]:
        return seg.element_point(tau, e)

    def velocity_and_acceleration(tau: float) -> tuple[float, float]:
        _, v, a = state(tau)
        return v, a

    d_floor, v_floor = seg.element_floors(e)
    d_floor += 8.0 * _EPS * max(abs(lo) if math.isfinite(lo) else 0.0, abs(hi) if math.isfinite(hi) else 0.0)
    tol = 4.0 * _EPS * tau_b + 1e-300
    end_up, end_down = d_b >= hi, d_b < lo
    if v_a != 0.0 and (v_a > 0.0) != (v_b > 0.0):
        tau_e = tau_b if v_b == 0.0 else bracketed_newton(
            velocity_and_acceleration, tau_a, tau_b, v_a, v_b, tol, v_floor)
        d_e = state(tau_e)[0]
        if v_a > 0.0:  # a maximum
            if d_e - hi > d_floor or end_up:
                up, a_, b_, d_a_, d_b_ = True, tau_a, tau_e, d_a, d_e
            elif end_down:
                up, a_, b_, d_a_, d_b_ = False, tau_e, tau_b, d_e, d_b
            else:
                return None
        else:  # a minimum
            if lo - d_e > d_floor or end_down:
                up, a_, b_, d_a_, d_b_ = False, tau_a, tau_e, d_a, d_e
            elif end_up:
                up, a_, b_, d_a_, d_b_ = True, tau_e, tau_b, d_e, d_b
            else:
                return None
    elif end_up or end_down:
        up, a_, b_, d_a_, d_b_ = end_up, tau_a, tau_b, d_a, d_b
    else:
        return None
    bound = hi if up else lo
    fa, fb = d_a_ - bound, d_b_ - bound
    tau_c = a_
    if (fa >= 0.0) if up else (fa < 0.0):
        if at_start and a_ == 0.0:
            fa = -1e-300 if up else 1e-300  # the segment start is inside by construction
        else:
            return tau_c, (1 if up else -1)  # round-off at a graze: the crossing is at the bracket's start

    def gap(tau: float) -> tuple[float, float]:
        d, v, _ = state(tau)
        return d - bound, v

    tau_c = bracketed_newton(gap, a_, b_, fa, fb, tol, d_floor)
    return tau_c, (1 if up else -1)


__all__ = ["first_exit", "bracketed_newton", "vector_bracketed_newton"]
