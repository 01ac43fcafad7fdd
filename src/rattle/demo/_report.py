"""The numbers the paper quotes, computed from the results, and the markdown report of ``rattle demo``.

Everything here is pure: result objects in, numbers or text out. No matplotlib, no files (the
command line writes the report atomically; the figures are drawn by
:mod:`rattle.demo._figures` and only their file names come in here).

Sound pressure and acceleration
-------------------------------
The paper's Eq. (1) makes the sound pressure of a rattle source proportional to its torsional
acceleration δ'' (linear paths from the source to the listener). A level difference in sound
pressure between the non-linear and the linear system at one Ω is therefore

    ΔL = 20 log10( p2p δ''_non-linear / p2p δ''_linear )   dB,

with p2p δ''_linear from the closed-form harmonic response X_n = F_pn e^{iφ_n} / (k − (nΩ)² + i c nΩ)
of the linear system (f = δ): δ''(t) = Σ_n Re[−(nΩ)² X_n e^{inΩt}], so that for a single
harmonic p2p δ'' = 2 Ω² |X_1| (the general case is sampled).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..model import Model

__all__ = [
    "LevelDifference", "linear_acceleration_p2p", "level_difference", "stage_intervals", "demo_report",
    "PAPER_BAND",
]

#: The band where the paper quotes "at least 20 dB" between linear and non-linear (rad/s).
PAPER_BAND: tuple[float, float] = (0.6, 0.8)


# --------------------------------------------------------------------------------------------
# Linear vs non-linear level difference (Figure 4)
# --------------------------------------------------------------------------------------------
def linear_acceleration_p2p(model: Model, omega: FloatArray, samples: int = 256) -> FloatArray:
    """Peak-to-peak torsional acceleration δ'' (rad/s²) of the linear system (f = δ, same
    inertia, damping and excitation) in steady state at each forcing frequency ``omega``.

    Parameters
    ----------
    model : Model
        Only ``k``, ``c`` and the excitation are used (the elastic law is replaced by f = δ).
    omega : array_like, shape (M,)
        Forcing frequencies Ω (rad/s).
    samples : int, default 256
        Samples per forcing period when the excitation has more than one harmonic (with one the
        closed form 2 Ω² |X_1| is exact and used).

    Returns
    -------
    numpy.ndarray, shape (M,)
    """
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    exc = model.excitation
    orders = np.asarray(exc.orders, dtype=float)
    amps = np.asarray(exc.amplitudes, dtype=float)
    phases = np.asarray(exc.phases, dtype=float)
    nw = orders[None, :] * w[:, None]                                    # (M, N)
    X = amps * np.exp(1j * phases) / (model.k - nw**2 + 1j * model.c * nw)
    A = -(nw**2) * X                                                     # acceleration phasors
    if orders.size == 1:
        return 2.0 * np.abs(A[:, 0])
    theta = 2.0 * np.pi * np.arange(samples) / samples                   # Ω t over one period
    acc = np.real(A[:, :, None] * np.exp(1j * orders[None, :, None] * theta[None, None, :])).sum(axis=1)
    return acc.max(axis=1) - acc.min(axis=1)


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class LevelDifference:
    """Level difference ΔL = 20 log10(non-linear / linear) of the acceleration p2p over a band.

    One entry per frequency-response row inside ``band`` (every branch, stable or not).

    Attributes
    ----------
    band : (float, float)
        Ω interval (rad/s).
    rows : numpy.ndarray of int, shape (M,)
        The rows' indices in the frequency response (a gap marks where a branch left the band).
    omega, branch, period, stable : numpy.ndarray, shape (M,)
        The rows' Ω (rad/s), branch, period and stability.
    nonlinear, linear : numpy.ndarray, shape (M,)
        p2p δ'' of the non-linear solution and of the linear system at the same Ω (rad/s²).
    db : numpy.ndarray, shape (M,)
        20 log10(nonlinear / linear), dB.
    db_displacement : numpy.ndarray, shape (M,)
        For comparison, 20 log10 of the rms of δ about the mean (non-linear / linear), dB.
    """

    band: tuple[float, float]
    rows: np.ndarray
    omega: FloatArray
    branch: np.ndarray
    period: np.ndarray
    stable: np.ndarray
    nonlinear: FloatArray
    linear: FloatArray
    db: FloatArray
    db_displacement: FloatArray

    def _extreme(self, values: FloatArray, largest: bool) -> tuple[float, float]:
        m = self.stable if np.any(self.stable) else np.ones_like(self.stable, dtype=bool)
        idx = np.flatnonzero(m)
        if idx.size == 0:
            return math.nan, math.nan
        j = idx[int(np.argmax(values[idx]) if largest else np.argmin(values[idx]))]
        return float(values[j]), float(self.omega[j])

    @property
    def db_min(self) -> float:
        """Smallest ΔL over the stable solutions in the band (dB)."""
        return self._extreme(self.db, False)[0]

    @property
    def db_max(self) -> float:
        """Largest ΔL over the stable solutions in the band (dB)."""
        return self._extreme(self.db, True)[0]

    @property
    def omega_at_min(self) -> float:
        return self._extreme(self.db, False)[1]

    @property
    def omega_at_max(self) -> float:
        return self._extreme(self.db, True)[1]

    def single_valued_range(self) -> tuple[float, float, float, float]:
        """(Ω_lo, Ω_hi, ΔL_min, ΔL_max) over the stable rows below the lowest Ω of an unstable row
        in the band: where the response is still single-valued (the multi-valued part between
        the folds holds the unstable middle branch). NaNs when there is no such row.
        """
        unstable = self.omega[~self.stable]
        cut = float(unstable.min()) if unstable.size else math.inf
        m = self.stable & (self.omega < cut)
        if not np.any(m):
            return (math.nan,) * 4  # type: ignore[return-value]
        return (float(self.omega[m].min()), float(self.omega[m].max()), float(self.db[m].min()), float(self.db[m].max()))

    def summary(self) -> str:
        lo, hi = self.band
        text = (
            f"acceleration p2p, non-linear vs linear, over Ω = {lo:g} … {hi:g}: "
            f"{self.db_min:.1f} … {self.db_max:.1f} dB over the stable solutions "
            f"(min at Ω = {self.omega_at_min:.3f}, max at Ω = {self.omega_at_max:.3f})"
        )
        s_lo, s_hi, d_lo, d_hi = self.single_valued_range()
        if math.isfinite(s_lo):
            text += f"; {d_lo:.1f} … {d_hi:.1f} dB where single-valued (Ω = {s_lo:.3f} … {s_hi:.3f})"
        return text


def level_difference(frf: Any, band: tuple[float, float] = PAPER_BAND) -> LevelDifference:
    """ΔL = 20 log10(p2p δ''_non-linear / p2p δ''_linear) at every row of ``frf`` in ``band``.

    Parameters
    ----------
    frf : FrequencyResponse
        All branches are used (``stable`` tells them apart).
    band : (float, float), default (0.6, 0.8)
        Ω interval (rad/s), the paper's "0.6 < Ω < 0.8".

    Returns
    -------
    LevelDifference
    """
    lo, hi = (float(band[0]), float(band[1]))
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"`band` must be (lo, hi) with 0 < lo < hi rad/s, got {band!r}")
    m = (frf.omega >= lo) & (frf.omega <= hi)
    if not np.any(m):
        raise ValueError(f"`band` {lo:g} … {hi:g} rad/s holds no row of the frequency response "
                         f"(Ω = {frf.omega.min():g} … {frf.omega.max():g})")
    w = np.asarray(frf.omega[m], dtype=float)
    nl = np.asarray(frf.acc_p2p[m], dtype=float)
    lin = linear_acceleration_p2p(frf.model, w)
    lin_ac = frf.linear_response(w).rms_ac
    return LevelDifference(
        band=(lo, hi), rows=np.flatnonzero(m), omega=w, branch=np.asarray(frf.branch[m]), period=np.asarray(frf.period[m]),
        stable=np.asarray(frf.stable[m], dtype=bool), nonlinear=nl, linear=lin,
        db=20.0 * np.log10(nl / lin), db_displacement=20.0 * np.log10(np.asarray(frf.rms_ac[m]) / lin_ac),
    )


def _union(intervals: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[list[float]] = []
    for a, b in sorted(intervals):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def stage_intervals(frf: Any, threshold: float, *, below: bool = True) -> list[tuple[float, float]]:
    """Ω intervals where a stable solution has its mean δ_m below (or at/above) ``threshold``.

    Used for the mean operating point: with ``threshold`` = b, the intervals where the mean
    sits on the first stage (δ_m < b) rather than the second. A stable stretch extends to the
    special point that ends it (the located row has a multiplier on the unit circle and is
    flagged unstable, but the stability ends there, it is not a gap).
    """
    out = []
    for b in np.unique(frf.branch):
        sel = np.flatnonzero(frf.branch == b)
        mean = frf.mean[sel]
        ok = np.asarray(frf.stable[sel], dtype=bool) & ((mean < threshold) if below else (mean >= threshold))
        special = np.asarray(frf.bifurcation[sel]) != ""
        edges = np.diff(np.concatenate(([0], ok.astype(int), [0])))
        for i0, i1 in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            i0 = i0 - 1 if i0 > 0 and special[i0 - 1] else i0
            i1 = i1 + 1 if i1 < sel.size and special[i1] else i1
            om = frf.omega[sel[i0:i1]]
            out.append((float(om.min()), float(om.max())))
    return _union(out)


# --------------------------------------------------------------------------------------------
# The demo report
# --------------------------------------------------------------------------------------------
_KIND_TEXT = {"fold": "fold", "period_doubling": "period doubling", "neimark_sacker": "Neimark–Sacker"}


def _fmt_list(values: Sequence[float], digits: int = 4) -> str:
    return ", ".join(f"{v:.{digits}f}" for v in values) or "none"


def _special_by(frf: Any, kind: str, period: int | None = None) -> list[Any]:
    out = []
    seen: list[float] = []
    for sp in frf.special_points:
        if sp.kind != kind:
            continue
        if period is not None and int(frf.period[sp.index]) != period:
            continue
        if any(abs(sp.omega - w) < 1e-5 for w in seen):  # a branch-birth row repeats its parent's point
            continue
        seen.append(sp.omega)
        out.append(sp)
    return sorted(out, key=lambda s: s.omega)


def _fold_texts(frf: Any, regions: Sequence[Any]) -> list[str]:
    """Each fold's Ω with what it belongs to: a super-harmonic resonance (a ``1/k`` region within
    5 % in Ω), the primary resonance (the other period-1 folds), or a period-p branch."""
    supers = [g for g in regions if g.kind == "superharmonic"]
    out = []
    for sp in _special_by(frf, "fold"):
        p = int(frf.period[sp.index])
        if p > 1:
            what = f"period-{p} branch {sp.branch}"
        else:
            near = [g for g in supers if abs(g.omega_min - sp.omega) <= 0.05 * sp.omega]
            order = near[0].detail.get("order") if near else None
            what = f"1/{order} super-harmonic" if order else ("super-harmonic" if near else "primary resonance")
        out.append(f"{sp.omega:.4f} ({what})")
    return out


def _nearest_fold(frf: Any, omega: float) -> Any:
    folds = [sp for sp in frf.special_points if sp.kind == "fold" and int(frf.period[sp.index]) == 1]
    return min(folds, key=lambda s: abs(s.omega - omega)) if folds else None


def _orbit_line(orbit: Any) -> str:
    parts = []
    for s in orbit.solutions:
        mu = float(np.max(np.abs(s.multipliers)))
        parts.append(f"period {s.period} {'stable' if s.stable else 'unstable'} (rms {s.rms:.4f} rad, |μ|max {mu:.3f})")
    return "; ".join(parts)


def _sim_text(orbit: Any) -> str:
    p = orbit.simulated_period
    if p is None:
        return "not simulated"
    return f"period {p}" if p else "no period ≤ 8 (quasi-periodic or chaotic)"


def _half_order(orbit: Any) -> tuple[float, float] | None:
    """(|δ| at Ω/2, |δ| at Ω) of the stable period-2 orbit, or None."""
    for s in orbit.solutions:
        if s.period == 2 and s.stable:
            amp = s.amplitudes()
            return float(amp[1]), float(amp[2]) if amp.size > 2 else math.nan
    return None


def demo_report(
    frf: Any,
    sweep: Any,
    *,
    orbits: Mapping[str, Any],
    level: LevelDifference,
    figures: Mapping[str, str],
    data_files: Sequence[str] = (),
    regions: Sequence[Any] | None = None,
    timings: Mapping[str, float] | None = None,
    version: str = "",
) -> str:
    """The markdown report of ``rattle demo``: each figure (relative link) with one line of
    interpretation from the computed numbers, the special-point table and the regions.

    Parameters
    ----------
    frf : FrequencyResponse
        All branches (computed with ``subharmonics=True``).
    sweep : SweepResult
        The up and down time-domain sweeps.
    orbits : mapping
        ``{"A": PeriodicOrbit at Ω = 0.44, "B": PeriodicOrbit at Ω = 1.41}`` (either may be absent).
    level : LevelDifference
        From :func:`level_difference`.
    figures : mapping
        Figure key → file name, for the figures that were written: ``frf``,
        ``fig4``, ``fig5``, ``fig6``, ``fig7``, ``mean`` (missing keys are left out).
    data_files : sequence of str
        Other files written (listed at the end).
    regions : sequence of Region, optional
        The regions to list (default ``frf.regions``; pass those confirmed by the sweep).
    timings : mapping, optional
        Wall times in s: ``frf``, ``sweep``, ``orbits``, ``figures``, ``total``.
    version : str
        rattle's version, for the header.

    Returns
    -------
    str
        Markdown text ending with a newline.
    """
    timings = dict(timings or {})
    regions = tuple(frf.regions if regions is None else regions)
    model = frf.model
    el = model.elastic
    b = float(getattr(el, "b", float(np.max(np.abs(el.stages.breakpoints)))))
    H = frf.settings.get("harmonics", frf.harmonics) if isinstance(frf.settings, dict) else frf.harmonics
    L: list[str] = []
    add = L.append

    pds = _special_by(frf, "period_doubling")
    i_max = int(np.argmax(frf.rms))
    lin = frf.linear_response()
    j_lin = int(np.argmax(lin.rms))
    jumps = sweep.jumps()

    add("# rattle demo — the paper's reference case")
    add("")
    add(f"Clutch with two-stage stiffness: α = {getattr(el, 'alpha', float('nan')):g}, b = {b:.6f} rad "
        f"({math.degrees(b):.0f}°), ζ = {model.zeta:.3g}, F_m = {model.excitation.mean:g}, "
        f"F_p1 = {model.excitation.amplitudes[0]:g}; Ω = {frf.omega.min():g} … {frf.omega.max():g} rad/s, "
        f"H = {H} harmonics of Ω (2H of Ω/2 on the period-2 branches)" + (f"; rattle {version}." if version else "."))
    add("")
    t_parts = []
    for key, text in (("frf", "harmonic balance with continuation, stability and sub-harmonic branches"),
                      ("sweep", "time-domain sweep up and down"), ("orbits", "orbits at A and B"),
                      ("figures", "figures"), ("total", "total")):
        if key in timings:
            t_parts.append(f"{text} {timings[key]:.2f} s")
    if t_parts:
        add("Timings: " + "; ".join(t_parts) + ".")
        if "frf" in timings and "sweep" in timings:
            n_up = int(np.sum(sweep.direction == "up"))
            add(f"The harmonic balance gives {len(frf)} solution points on {len(np.unique(frf.branch))} branches, "
                f"unstable ones included, in {timings['frf']:.2f} s; the sweep gives {len(sweep)} stable steady "
                f"states ({n_up} frequencies each way) in {timings['sweep']:.2f} s.")
        add("")

    add("## Figures")
    add("")
    if "frf" in figures:
        add(f"### Frequency response, all branches — [{figures['frf']}]({figures['frf']})")
        add("")
        add(f"![frequency response]({figures['frf']})")
        add("")
        add(f"Largest rms {frf.rms[i_max]:.4f} rad at Ω = {frf.omega[i_max]:.4f} ({frf.regime[i_max].replace('_', '-')} "
            f"impacts). Folds at Ω = {', '.join(_fold_texts(frf, regions)) or 'none'}; period doubling at "
            f"Ω = {_fmt_list([s.omega for s in pds])}, each the birth of a period-2 branch "
            f"({len(np.unique(frf.branch))} branches in all).")
        add("")
    if "fig4" in figures:
        s_lo, s_hi, d_lo, d_hi = level.single_valued_range()
        add(f"### Figure 4 — linear vs non-linear — [{figures['fig4']}]({figures['fig4']})")
        add("")
        add(f"![linear vs non-linear]({figures['fig4']})")
        add("")
        add(f"Non-linear rms peaks at {frf.rms[i_max]:.3f} rad (Ω = {frf.omega[i_max]:.3f}), the linear system at "
            f"{lin.rms[j_lin]:.3f} rad (Ω = {lin.omega[j_lin]:.3f}). Compared quantity: p2p torsional acceleration δ'' "
            f"(sound pressure ∝ acceleration), non-linear HB solution vs the linear system's 2Ω²|X₁| at the same Ω: "
            f"over {level.band[0]:g} < Ω < {level.band[1]:g} the stable solutions are {level.db_min:.1f} … "
            f"{level.db_max:.1f} dB louder (max at Ω = {level.omega_at_max:.3f}, min at Ω = {level.omega_at_min:.3f} "
            f"on the lower stable branch where the response is multi-valued)"
            + (f"; {d_lo:.1f} … {d_hi:.1f} dB where it is single-valued (Ω = {s_lo:.3f} … {s_hi:.3f})" if math.isfinite(s_lo) else "")
            + f". The displacement rms about the mean differs by {np.min(level.db_displacement[level.stable]):.1f} … "
            f"{np.max(level.db_displacement[level.stable]):.1f} dB. The paper's \"at least 20 dB\" is not reached by the "
            f"exact solution: the difference is about {level.db_max:.0f} dB at most.")
        add("")
    if "fig5" in figures:
        add(f"### Figure 5 — harmonic balance vs time-domain sweep — [{figures['fig5']}]({figures['fig5']})")
        add("")
        add(f"![HBM vs simulation]({figures['fig5']})")
        add("")
        if jumps:
            texts = []
            for j in jumps:
                f = _nearest_fold(frf, j.omega)
                fold = f"; HB fold at Ω = {f.omega:.4f}" if f is not None else ""
                texts.append(f"{j.direction} sweep jumps {j.kind} ({j.rms_before:.3f} → {j.rms_after:.3f} rad) between "
                             f"Ω = {j.omega_before:.4f} and {j.omega_after:.4f}{fold}")
            add("The sweeps follow the stable HB solutions and jump at the folds: " + "; ".join(texts) + ".")
        else:
            add("The sweeps follow the stable HB solutions; no jump was detected.")
        sub = [g for g in regions if g.kind == "subharmonic"]
        per = [(g, g.detail.get("sweep_periods")) for g in sub]
        if per:
            add("")
            add("Where HB has a stable period-2 branch the sweep finds period 2 too: " + "; ".join(
                f"Ω = {g.omega_min:.4f} … {g.omega_max:.4f} (sweep periods there: "
                f"{', '.join(str(p) for p in (ps or [])) or 'not checked'})" for g, ps in per) + ".")
        add("")
    for key, name, what in (("fig6", "A", "Figure 6 — point A"), ("fig7", "B", "Figure 7 — point B")):
        orbit = orbits.get(name)
        if key not in figures or orbit is None:
            continue
        add(f"### {what}, Ω = {orbit.omega:g} — [{figures[key]}]({figures[key]})")
        add("")
        add(f"![point {name}]({figures[key]})")
        add("")
        sim = _sim_text(orbit)
        line = f"The exact simulation settles on {sim}"
        if orbit.simulated_rms is not None:
            line += f" (rms {orbit.simulated_rms:.4f} rad)"
        line += f"; harmonic balance: {_orbit_line(orbit)}."
        if name == "A":
            line += (" The paper called point A quasi-periodic; the exact solution is periodic with period "
                     f"{orbit.simulated_period}: a 1/{orbit.simulated_period} sub-harmonic, while the period-1 "
                     "orbit there is unstable." if orbit.simulated_period and orbit.simulated_period > 1 else
                     " The paper called point A quasi-periodic.")
        else:
            half = _half_order(orbit)
            if half is not None:
                line += (f" Its spectrum has the half-order harmonic Ω/2 (amplitude {half[0]:.4f} rad) next to "
                         f"Ω ({half[1]:.4f} rad): a 1/2 sub-harmonic, as the paper says (peak near Ω = 1.4).")
        add(line)
        add("")
    if "mean" in figures:
        below = stage_intervals(frf, b, below=True)
        above = stage_intervals(frf, b, below=False)
        i_min = int(np.argmin(np.where(frf.stable, frf.mean, np.inf)))
        static = model.static_equilibrium()
        add(f"### Mean operating point — [{figures['mean']}]({figures['mean']})")
        add("")
        add(f"![mean operating point]({figures['mean']})")
        add("")
        add(f"At rest the mean torque puts δ on the second stage (static δ = {static:.4f} rad > b = {b:.4f} rad); "
            f"under the pulsating torque the mean δ_m of the stable solutions drops into the first stage (δ_m < b) over "
            f"Ω = " + (", ".join(f"{a:.3f} … {c:.3f}" for a, c in below) or "nowhere")
            + f", down to {frf.mean[i_min]:.4f} rad at Ω = {frf.omega[i_min]:.3f}; stable solutions with δ_m on the "
            f"second stage (δ_m ≥ b): Ω = " + (", ".join(f"{a:.3f} … {c:.3f}" for a, c in above) or "none") + ".")
        add("")

    add("## Special points")
    add("")
    add("| type | branch | period | Ω (rad/s) | omega_error | located |")
    add("|---|---|---|---|---|---|")
    for sp in sorted(frf.special_points, key=lambda s: (s.branch, s.omega)):
        err = "—" if sp.omega_error is None else f"{sp.omega_error:.1e}"
        add(f"| {_KIND_TEXT.get(sp.kind, sp.kind)} | {sp.branch} | {int(frf.period[sp.index])} | {sp.omega:.5f} | "
            f"{err} | {'yes' if sp.located else 'no'} |")
    add("")
    add("omega_error = |Ω(2H) − Ω(H)|, the point located again with twice the harmonics (— : the birth row of a "
        "period-2 branch, the same point as its parent's period doubling).")
    add("")
    add("## Regions")
    add("")
    if regions:
        for g in regions:
            where = f"Ω = {g.omega_min:.4f}" if g.omega_min == g.omega_max else f"Ω = {g.omega_min:.4f} … {g.omega_max:.4f}"
            extra = ""
            if g.detail.get("sweep_periods"):
                extra = f" (sweep periods: {', '.join(str(p) for p in g.detail['sweep_periods'])})"
            add(f"- {g.kind}: {g.label}, {where}{extra}")
    else:
        add("- none")
    if data_files:
        add("")
        add("## Data")
        add("")
        for name in data_files:
            add(f"- [{name}]({name})")
    return "\n".join(L) + "\n"
