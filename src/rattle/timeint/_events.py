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
from ._roots import bracketed_newton, grid_chunk, resolve_cell, vector_bracketed_newton
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
        taus = grid_chunk(tau_a, tau_end, step, chunk)
        n = taus.size - 1
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
    (τ, direction); None when δ_e stays inside or only grazes a breakpoint (:func:`resolve_cell`
    on δ_e, its round-off floor raised by that of the bounds)."""

    def state(tau: float) -> tuple[float, float, float]:
        return seg.element_point(tau, e)

    d_floor, v_floor = seg.element_floors(e)
    d_floor += 8.0 * _EPS * max(abs(lo) if math.isfinite(lo) else 0.0, abs(hi) if math.isfinite(hi) else 0.0)
    return resolve_cell(state, lo, hi, tau_a, tau_b, d_a, d_b, v_a, v_b, at_start, d_floor, v_floor)


__all__ = ["first_exit", "bracketed_newton", "vector_bracketed_newton"]
