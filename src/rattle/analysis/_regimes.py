"""Named regions of a frequency response: super-harmonic resonances, sub-harmonic motion, and
the intervals where no computed periodic solution is stable.

* super-harmonic resonance: a local maximum of rms_ac on the primary (period-1) branch below
  the primary resonance; its order k ≈ ω_r / Ω, with ω_r the primary resonance frequency at low
  amplitude, taken at the primary branch's lower fold (the jump-up frequency) when it has one,
  else at the rms_ac maximum;
* sub-harmonic (period p > 1): an Ω interval where a period-p branch is stable;
* no stable periodic solution: an Ω interval where none of the computed branches is stable —
  the motion there is quasi-periodic, chaotic or periodic of a period not computed; a time
  sweep decides (:func:`confirm_with_sweep`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from scipy.signal import find_peaks

from ..results import FrequencyResponse, Region


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    return list(zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]))


def stable_intervals(frf: FrequencyResponse, branch: int) -> list[tuple[float, float]]:
    """Ω intervals covered by stable stretches of one branch; a stretch extends to the special
    points that bound it (a located bifurcation row has a multiplier on the circle and is
    flagged unstable, but it is where the stability ends, not a gap)."""
    sel = np.nonzero(frf.branch == branch)[0]
    om, st = frf.omega[sel], frf.stable[sel]
    special = frf.bifurcation[sel] != ""
    out = []
    for a, b in _runs(st):
        a = a - 1 if a > 0 and special[a - 1] else a
        b = b + 1 if b < sel.size and special[b] else b
        out.append((float(om[a:b].min()), float(om[a:b].max())))
    return out


def _union(intervals: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[list[float]] = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1]:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return [(a, b) for a, b in out]


def superharmonic_resonances(frf: FrequencyResponse, branch: int = 0, prominence: float = 0.01) -> list[Region]:
    """Local rms_ac maxima of a period-1 branch below its primary resonance (prominence as a
    fraction of the branch's rms_ac range), with the order k ≈ ω_r / Ω."""
    sel = np.nonzero(frf.branch == branch)[0]
    if sel.size < 3 or int(frf.period[sel[0]]) != 1:
        return []
    om, ac = frf.omega[sel], frf.rms_ac[sel]
    i_peak = int(np.argmax(ac))
    folds = [s.omega for s in frf.special_points if s.branch == branch and s.kind == "fold" and s.omega < om[i_peak]]
    omega_r = max(folds) if folds else float(om[i_peak])
    low = np.nonzero(om < 0.6 * omega_r)[0]
    if low.size < 3:
        return []
    peaks, props = find_peaks(ac[low], prominence=prominence * float(np.ptp(ac)))
    out = []
    for p, prom in zip(peaks, props["prominences"]):
        w = float(om[low[p]])
        k = int(round(omega_r / w))
        if k < 2:
            continue
        out.append(Region("superharmonic", w, w, f"1/{k} super-harmonic", {"order": k, "omega_r": omega_r, "rms_ac": float(ac[low[p]]), "prominence": float(prom)}))
    return out


def label_regions(frf: FrequencyResponse, min_gap: float = 1e-4) -> tuple[Region, ...]:
    """All regions of a (possibly multi-branch) frequency response, sorted by Ω.

    A gap between stable stretches narrower than ``min_gap`` × (Ω range) is not reported as a
    region without a stable solution: branches meet at located points (accurate to ~1e-6 in Ω),
    and such slivers are where two stretches join, not a physical interval."""
    regions: list[Region] = []
    for b in np.unique(frf.branch):
        period = int(frf.period[frf.branch == b][0])
        if period == 1:
            regions += superharmonic_resonances(frf, int(b))
        else:
            for lo, hi in _union(stable_intervals(frf, int(b))):
                regions.append(Region("subharmonic", lo, hi, f"period {period} (1/{period} sub-harmonic)", {"period": period, "branch": int(b)}))
    covered = _union([iv for b in np.unique(frf.branch) for iv in stable_intervals(frf, int(b))])
    lo_all, hi_all = float(frf.omega.min()), float(frf.omega.max())
    edge = lo_all
    for a, b in covered + [(hi_all, hi_all)]:
        if a - edge > min_gap * (hi_all - lo_all):
            regions.append(Region("no_stable_periodic", edge, a, "no stable periodic solution (quasi-periodic or chaotic?)", {}))
        edge = max(edge, b)
    return tuple(sorted(regions, key=lambda r: (r.omega_min, r.kind)))


def confirm_with_sweep(regions: tuple[Region, ...], sweep: Any) -> tuple[Region, ...]:
    """Add to each region the periods a time-domain ``sweep`` (SweepResult) saw inside it; a
    ``no_stable_periodic`` region is relabelled quasi-periodic/chaotic when the simulation found
    no period ≤ 8 (period 0) there, or by the period it did find."""
    out = []
    for r in regions:
        inside = (sweep.omega >= r.omega_min) & (sweep.omega <= r.omega_max)
        periods = sorted(set(int(p) for p in sweep.period[inside]))
        detail = dict(r.detail, sweep_periods=periods)
        label = r.label
        if r.kind == "no_stable_periodic" and periods:
            if periods == [0]:
                label = "quasi-periodic or chaotic (no period ≤ 8 in the simulation)"
            else:
                label = "no stable computed orbit; simulation: period " + ", ".join(str(p) if p else "none ≤ 8" for p in periods)
        out.append(replace(r, label=label, detail=detail))
    return tuple(out)


__all__ = ["Region", "label_regions", "superharmonic_resonances", "stable_intervals", "confirm_with_sweep"]
