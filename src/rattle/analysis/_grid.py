"""Every branch of a frequency response, solved again exactly at the frequencies of a grid.

A response map reports, at each frequency Ω_j of a fixed grid, every solution the branches of
a :class:`~rattle.results.FrequencyResponse` have there (several inside a fold), with its
stability and measures. Interpolating the continuation's rows would put an error of the order
of (step)² · curvature on the rms near a resonance peak, and stability would be guessed between
rows. Instead, wherever a segment between two consecutive rows of a branch crosses Ω_j, the
harmonic-balance equations R(q, Ω_j) = 0 of that branch (its own harmonic count and period)
are solved by Newton at the fixed Ω_j from the linear interpolation of the two rows, and the
Floquet multipliers and SPEC §1 measures are those of the solution — exactly what the branch
itself would report at Ω_j.

A segment crosses Ω_j when (Ω_j − Ω_i)(Ω_j − Ω_{i+1}) < 0, or Ω_j = Ω_i (each row is the start
of one segment; a branch's last row counts for its own value), so a grid frequency equal to a
row's is counted once. A Newton solution that lands farther from its guess than the segment is
long (it jumped to another sheet near a fold tip, where ∂R/∂q is nearly singular) is refused and
the grid point is taken from the nearer row instead (``converged`` False).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from ..continuation import solve_fixed
from ..hb import HarmonicBalance
from ..measures import system_measures_batch
from ..results import FrequencyResponse
from ..stability import UNIT_CIRCLE_TOL
from ._settings import RunSettings


@dataclass(frozen=True)
class GridSolution:
    """One solution of one branch at grid frequency ``omega`` (= grid[index]).

    ``rms`` … ``regime``: SPEC §1 measures of the first element; ``impacts``: some element's
    deflection crosses one of its breakpoints (regime other than ``no_impact``). ``section``
    (period, 2n): the state (x, x') at t = m·2π/Ω, m = 0 … period − 1 (the Poincaré section
    points of the orbit, to recognise a simulated attractor). ``q``: its HB coefficients
    (n·(2H+1), the branch's own H)."""

    index: int
    omega: float
    branch: int
    period: int
    stable: bool
    rms: float
    rms_ac: float
    p2p: float
    acc_p2p: float
    delta_min: float
    delta_max: float
    regime: str
    impacts: bool
    section: FloatArray
    q: FloatArray
    converged: bool = True


def section_states(q: FloatArray, coordinates: int, omega: float, period: int) -> FloatArray:
    """States (x, x') at t = m·2π/Ω, m = 0 … period − 1, of the series q (coordinate-major
    blocks [a_0, a_1 … a_H, b_1 … b_H] of base frequency Ω/period). Shape (period, 2n)."""
    Q = np.asarray(q, dtype=float).reshape(coordinates, -1)
    H = (Q.shape[1] - 1) // 2
    k = np.arange(1, H + 1)
    m = np.arange(period)
    phase = 2.0 * np.pi * np.outer(m, k) / period  # (period, H): k ω t at t = m T
    c, s = np.cos(phase), np.sin(phase)
    a, b = Q[:, 1 : H + 1], Q[:, H + 1 :]
    x = Q[:, 0][None, :] + c @ a.T + s @ b.T  # (period, n)
    w = omega / period
    v = (s @ (-a * k * w).T) + (c @ (b * k * w).T)
    return np.hstack([x, v])


def _branch_harmonics(frf: FrequencyResponse, rows: np.ndarray, coordinates: int) -> int:
    """A branch's own harmonic count (rows of a joined result are padded with zeros)."""
    b = int(frf.branch[rows[0]])
    for rec in frf.settings.get("branches", ()):
        if rec.get("branch") == b and rec.get("harmonics"):
            return int(rec["harmonics"])
    Q = frf.coefficients[rows].reshape(rows.size, coordinates, -1)
    H = frf.harmonics
    nz = np.nonzero(np.any(np.abs(Q[:, :, 1 : H + 1]) + np.abs(Q[:, :, H + 1 :]) > 0, axis=(0, 1)))[0]
    return int(nz.max()) + 1 if nz.size else 1


def _crossings(om: FloatArray, grid: FloatArray) -> list[tuple[int, int]]:
    """(segment i, grid index j) for every grid frequency a segment [row i, row i+1] crosses."""
    out = []
    for i in range(om.size - 1):
        a, b = om[i], om[i + 1]
        lo, hi = (a, b) if a <= b else (b, a)
        js = np.nonzero((grid >= lo) & (grid <= hi))[0]
        for j in js:
            w = grid[j]
            last = i == om.size - 2
            if (w - a) * (w - b) < 0 or w == a or (last and w == b):
                out.append((i, int(j)))
    return out


def solutions_on_grid(frf: FrequencyResponse, grid: FloatArray, run: RunSettings) -> list[GridSolution]:
    """Every solution of every branch of ``frf`` at the frequencies ``grid`` (see the module
    docstring), branch by branch, in grid order within a branch."""
    model = frf.model
    grid = np.asarray(grid, dtype=float)
    system = model.system() if hasattr(model, "system") else model
    n = len(system.coordinates)
    out: list[GridSolution] = []
    for b in np.unique(frf.branch):
        rows = np.nonzero(frf.branch == b)[0]
        if rows.size < 2:
            continue
        period = int(frf.period[rows[0]])
        H = _branch_harmonics(frf, rows, n)
        hb = HarmonicBalance(model, run.for_harmonics(H), period=period)
        L = 2 * H + 1
        Qall = frf.coefficients[rows].reshape(rows.size, n, -1)
        Hall = (Qall.shape[2] - 1) // 2
        keep = np.r_[0, 1 : H + 1, Hall + 1 : Hall + H + 1]
        Q = Qall[:, :, keep].reshape(rows.size, n * L)
        om = frf.omega[rows]
        found_q, found_w, found_ok = [], [], []
        found_j = []
        for i, j in _crossings(om, grid):
            w = float(grid[j])
            s = 0.0 if om[i + 1] == om[i] else (w - om[i]) / (om[i + 1] - om[i])
            guess = (1 - s) * Q[i] + s * Q[i + 1]
            res = solve_fixed(hb, guess, w, run.newton)
            seg = float(np.linalg.norm(Q[i + 1] - Q[i]))
            if res.converged and np.linalg.norm(res.q - guess) <= max(seg, 1e-12 * max(1.0, np.linalg.norm(guess))):
                found_q.append(res.q)
                found_ok.append(True)
            else:  # the nearer row stands for the point
                found_q.append(Q[i] if s < 0.5 else Q[i + 1])
                found_ok.append(False)
            found_w.append(w)
            found_j.append(j)
        if not found_q:
            continue
        Qg = np.array(found_q)
        Wg = np.array(found_w)
        mu = run.stability.multipliers(hb, Qg, Wg)
        stable = np.max(np.abs(mu), axis=1) < 1.0 - UNIT_CIRCLE_TOL
        per_element = system_measures_batch(model, Qg.reshape(len(found_q), n, L), Wg / period, Wg, hb.basis.samples)
        first = per_element[0]
        impacts = np.zeros(len(found_q), dtype=bool)
        for meas in per_element:
            impacts |= np.asarray(meas.regime) != "no_impact"
        for k in range(len(found_q)):
            out.append(GridSolution(
                index=found_j[k], omega=float(Wg[k]), branch=int(b), period=period, stable=bool(stable[k]),
                rms=float(first.rms[k]), rms_ac=float(first.rms_ac[k]), p2p=float(first.p2p[k]),
                acc_p2p=float(first.acc_p2p[k]), delta_min=float(first.delta_min[k]),
                delta_max=float(first.delta_max[k]), regime=str(first.regime[k]), impacts=bool(impacts[k]),
                section=section_states(Qg[k], n, float(Wg[k]), period), q=Qg[k], converged=found_ok[k],
            ))
    return out


__all__ = ["GridSolution", "solutions_on_grid", "section_states"]
