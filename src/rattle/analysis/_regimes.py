"""Named regions of a frequency response: super-harmonic resonances, sub-harmonic motion, and
the intervals where no computed periodic solution is stable.

* super-harmonic resonance: a local maximum of rms_ac on the primary (period-1) branch below
  the primary resonance; its order k ≈ ω_r / Ω, with ω_r the primary resonance frequency at low
  amplitude, taken at the primary branch's lower fold (the jump-up frequency) when it has one,
  else at the rms_ac maximum;
* sub-harmonic (period p > 1): an Ω interval where a period-p branch is stable;
* an Ω interval where none of the computed branches is stable, labelled by what is known
  (:data:`UNSTABLE_KINDS`): bounded by a period doubling with sub-harmonics not computed (a
  stable sub-harmonic is likely), sub-harmonics not computed otherwise, sub-harmonics computed
  and none stable; only when a time sweep then finds no period ≤ 8 there too is it "no stable
  periodic solution" (:func:`confirm_with_sweep`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

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


def _union(intervals: list[tuple[float, float]], tol: float = 0.0) -> list[tuple[float, float]]:
    """Union of intervals; two closer than ``tol`` are joined."""
    out: list[list[float]] = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1] + tol:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return [(a, b) for a, b in out]


def prominent_peaks(x: np.ndarray, prominence: float) -> tuple[np.ndarray, np.ndarray]:
    """The local maxima of ``x`` whose prominence is at least ``prominence``, and those
    prominences: ``scipy.signal.find_peaks(x, prominence=prominence)``'s peaks and
    ``["prominences"]``, the same integers and floats (the same comparisons in the same order;
    tests/analysis checks them against scipy) without importing scipy.signal, which costs
    0.35 s of CPU (scipy.stats with it) in every ``rattle frf``.

    A maximum is one sample, or a plateau of equal samples (its middle one, rounded down), with a
    smaller sample on each side; its prominence is its height above the higher of the lowest
    samples on each side before a higher one (or the end).
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    if x.ndim != 1:
        raise ValueError("`x` must be one-dimensional")
    v = x.tolist()  # Python floats: the same IEEE comparisons and subtraction, no per-item numpy cost
    n = len(v)
    peaks: list[int] = []
    i = 1
    while i < n - 1:
        if v[i - 1] < v[i]:
            ahead = i + 1
            while ahead < n - 1 and v[ahead] == v[i]:
                ahead += 1
            if v[ahead] < v[i]:
                peaks.append((i + ahead - 1) // 2)
                i = ahead
        i += 1
    keep: list[int] = []
    proms: list[float] = []
    for peak in peaks:
        top = v[peak]
        left_min = top
        j = peak
        while j >= 0 and v[j] <= top:
            if v[j] < left_min:
                left_min = v[j]
            j -= 1
        right_min = top
        j = peak
        while j <= n - 1 and v[j] <= top:
            if v[j] < right_min:
                right_min = v[j]
            j += 1
        prom = top - max(left_min, right_min)
        if prom >= prominence:
            keep.append(peak)
            proms.append(prom)
    return np.asarray(keep, dtype=np.intp), np.asarray(proms, dtype=np.float64)


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
    peaks, proms = prominent_peaks(ac[low], prominence * float(np.ptp(ac)))
    out = []
    for p, prom in zip(peaks, proms):
        w = float(om[low[p]])
        k = int(round(omega_r / w))
        if k < 2:
            continue
        out.append(Region("superharmonic", w, w, f"1/{k} super-harmonic", {"order": k, "omega_r": omega_r, "rms_ac": float(ac[low[p]]), "prominence": float(prom)}))
    return out


#: Region kinds for an interval where no computed periodic solution is stable, from the least
#: to the most that is known (see :func:`label_regions` and :func:`confirm_with_sweep`).
UNSTABLE_KINDS: tuple[str, ...] = (
    "unstable_period_doubling",  # sub-harmonics not computed; a period doubling bounds the interval
    "unstable_not_computed",     # sub-harmonics not computed; no period doubling there
    "no_stable_computed",        # sub-harmonics computed (up to max_period), none stable there
    "no_stable_periodic",        # … and a time sweep found no period ≤ 8 there either
)

_PERIOD_DOUBLING_TEXT = "period-{p} unstable (period doubling): stable period-{q} motion likely — run with --subharmonics (subharmonics=True)"


def _gap_region(frf: FrequencyResponse, a: float, b: float, tol: float) -> Region:
    """The region of an interval [a, b] where none of the computed branches is stable, labelled
    by what is known: whether sub-harmonic branches were computed, and what bounds it."""
    inside = [sp for sp in frf.special_points if a - tol <= float(frf.omega[sp.index]) <= b + tol]
    kinds = sorted({sp.kind for sp in inside})
    # Genuine period doublings (a multiplier at −1 on the branch; not the birth row of a
    # switched branch, whose multiplier there is +1).
    pds = [sp for sp in inside if sp.kind == "period_doubling" and sp.multipliers[0].real < 0]
    periods_there = sorted({int(frf.period[sp.index]) for sp in pds})
    computed = bool(frf.settings.get("subharmonics", False)) if isinstance(frf.settings, dict) else False
    detail: dict[str, Any] = {"subharmonics_computed": computed, "bounded_by": kinds}
    if computed:
        max_period = int(frf.settings.get("max_period", int(np.max(frf.period))))
        detail["max_period"] = max_period
        found = sorted({int(p) for p in np.unique(frf.period)})
        return Region(
            "no_stable_computed", a, b,
            f"no stable orbit of period ≤ {max_period} computed (branches of period {', '.join(map(str, found))} "
            "unstable or absent here) — a time sweep tells what the motion is",
            detail,
        )
    if pds:
        p = periods_there[0]
        detail["period"] = p
        return Region("unstable_period_doubling", a, b, _PERIOD_DOUBLING_TEXT.format(p=p, q=2 * p), detail)
    if "neimark_sacker" in kinds:
        what = "period-1 unstable (Neimark–Sacker): quasi-periodic motion likely"
    else:
        what = "no stable period-1 solution"
    return Region(
        "unstable_not_computed", a, b,
        f"{what}; sub-harmonics not computed — run with --subharmonics (subharmonics=True) or a time sweep",
        detail,
    )


def torus_regions(frf: FrequencyResponse) -> list[Region]:
    """The stretches of each branch between two Neimark–Sacker points where it is unstable:
    there a complex pair of multipliers is outside the unit circle, and the motion near the
    orbit is quasi-periodic (a torus, for a supercritical Neimark–Sacker bifurcation) — kind
    ``torus``, whatever other branch may be stable at the same Ω. ``detail``: the branch and
    the torus frequency ratios θ/2π at both ends."""
    out: list[Region] = []
    for b in np.unique(frf.branch):
        sel = np.nonzero(frf.branch == b)[0]
        ns = [sp for sp in frf.special_points if sp.branch == int(b) and sp.kind == "neimark_sacker"]
        for sp0, sp1 in zip(ns[:-1], ns[1:]):
            i0, i1 = int(sp0.index), int(sp1.index)
            inner = [i for i in sel if i0 < i < i1]
            if not inner or np.any(frf.stable[inner]):
                continue
            # Between them only this pair (no other stability change on the stretch).
            if any(sp.branch == int(b) and i0 < sp.index < i1 for sp in frf.special_points):
                continue
            lo, hi = sorted((float(frf.omega[i0]), float(frf.omega[i1])))
            ratios = [sp0.torus_ratio, sp1.torus_ratio]
            period = int(frf.period[i0])
            text = (f"period-{period} unstable between Neimark–Sacker points: quasi-periodic motion likely "
                    f"(torus frequency ratio ≈ {np.nanmean([r for r in ratios if r is not None]):.3g})")
            out.append(Region("torus", lo, hi, text, {"branch": int(b), "period": period, "torus_ratio": ratios,
                                                     "rows": [i0, i1]}))
    return out


def label_regions(frf: FrequencyResponse, min_gap: float = 1e-4) -> tuple[Region, ...]:
    """All regions of a (possibly multi-branch) frequency response, sorted by Ω.

    An interval where none of the computed branches is stable is never called "no stable
    periodic solution" here (that takes sub-harmonics computed *and* a simulation, see
    :func:`confirm_with_sweep`); its kind says what is known (:data:`UNSTABLE_KINDS`):
    ``unstable_period_doubling`` when sub-harmonics were not computed and a period doubling
    bounds it (a stable period-2p motion is likely), ``unstable_not_computed`` when they were not
    computed otherwise, ``no_stable_computed`` when they were and none is stable there.

    A gap between stable stretches narrower than ``min_gap`` × (Ω range) is not reported, and
    two stable stretches of one sub-harmonic branch that close are one region: branches meet at
    located points (accurate to ~1e-6 in Ω), and such slivers are where two stretches join, not
    a physical interval."""
    regions: list[Region] = []
    sliver = min_gap * float(np.ptp(frf.omega))
    for b in np.unique(frf.branch):
        period = int(frf.period[frf.branch == b][0])
        if period == 1:
            regions += superharmonic_resonances(frf, int(b))
        else:
            for lo, hi in _union(stable_intervals(frf, int(b)), sliver):
                regions.append(Region("subharmonic", lo, hi, f"period {period} (1/{period} sub-harmonic)", {"period": period, "branch": int(b)}))
    regions += torus_regions(frf)
    covered = _union([iv for b in np.unique(frf.branch) for iv in stable_intervals(frf, int(b))])
    lo_all, hi_all = float(frf.omega.min()), float(frf.omega.max())
    tol = 1e-6 * (hi_all - lo_all)
    # the parts of the range no branch covers are not "unstable": no branch is known there at all
    # (frf.uncovered, named in the summary and shaded in the plot)
    blank = [(float(x), float(y)) for x, y in (frf.settings.get("uncovered") or [])]
    edge = lo_all
    for a, b in covered + [(hi_all, hi_all)]:
        for x, y in _outside(edge, a, blank):
            if y - x > min_gap * (hi_all - lo_all):
                regions.append(_gap_region(frf, x, y, tol))
        edge = max(edge, b)
    return tuple(sorted(regions, key=lambda r: (r.omega_min, r.kind)))


def _outside(lo: float, hi: float, blanks: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The parts of (lo, hi) outside every interval of ``blanks``."""
    parts = [(lo, hi)]
    for x, y in blanks:
        parts = [piece for a, b in parts for piece in ((a, min(b, x)), (max(a, y), b)) if piece[1] > piece[0]]
    return parts


def _periods_text(periods: list[int]) -> str:
    return ", ".join(f"period {p}" if p else "no period ≤ 8" for p in periods)


def confirm_with_sweep(regions: tuple[Region, ...], sweep: Any) -> tuple[Region, ...]:
    """Add to each region the periods a time-domain ``sweep`` (SweepResult) saw inside it, and
    say them in the label of every interval without a stable computed orbit.

    Only an interval whose sub-harmonics were computed (``no_stable_computed``) and where the
    simulation found no period ≤ 8 (period 0) becomes ``no_stable_periodic``, "no stable
    periodic solution (quasi-periodic or chaotic)"; without sub-harmonics computed the label
    keeps saying so. A sweep frequency whose steady state failed (period −1) tells nothing about
    the attractors: it is left out of the periods and counted in ``detail["sweep_failed"]``."""
    out = []
    period = np.asarray(sweep.period)
    failed = period < 0  # a frequency whose steady state failed (period −1) saw nothing
    for r in regions:
        inside = (sweep.omega >= r.omega_min) & (sweep.omega <= r.omega_max)
        periods = sorted(set(int(p) for p in period[inside & ~failed]))
        detail = dict(r.detail, sweep_periods=periods)
        if np.any(inside & failed):
            detail["sweep_failed"] = int(np.sum(inside & failed))
        label, kind = r.label, r.kind
        if kind in UNSTABLE_KINDS and periods:
            if periods == [0] and kind in ("no_stable_computed", "no_stable_periodic"):
                kind = "no_stable_periodic"
                label = (f"no stable periodic solution: none of period ≤ {detail.get('max_period', '?')} computed "
                         "and the simulation finds no period ≤ 8 (quasi-periodic or chaotic)")
            elif kind == "unstable_period_doubling" and any(p > 1 for p in periods):
                label = (f"period-{detail.get('period', 1)} unstable (period doubling); simulation: "
                         f"{_periods_text(periods)} — run with --subharmonics (subharmonics=True) for the branches")
            else:
                label = f"{r.label.split(' — ')[0].split('; sub-harmonics')[0]}; simulation: {_periods_text(periods)}"
        out.append(replace(r, kind=kind, label=label, detail=detail))
    return tuple(out)


__all__ = ["torus_regions", "Region", "label_regions", "superharmonic_resonances", "stable_intervals", "confirm_with_sweep", "UNSTABLE_KINDS"]
