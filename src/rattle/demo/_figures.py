"""The paper's figures (Figures 4–7 and the mean operating point) for ``rattle demo``.

Each function draws one figure from result objects and returns ``(figure, axes)``, ``axes`` a
:class:`rattle.plotting.PlotAxes` (panel name → matplotlib Axes, with a primary one); the numbers
(level differences, stage intervals) come from :mod:`rattle.demo._report`, which holds no
plotting. The building blocks (branch colours, special-point markers, sweep styles) are those
of :mod:`rattle.plotting`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..plotting import (
    PlotAxes, amplitude_spectrum, branch_colors, branch_label, draw_branches, draw_regions, draw_special_points,
    frequency_response_plot, place_legend, true_runs, unwrap,
)

if TYPE_CHECKING:  # pragma: no cover
    from ._report import LevelDifference
    from ..results import FrequencyResponse, PeriodicOrbit, SweepResult

__all__ = [
    "linear_vs_nonlinear_plot", "hbm_vs_simulation_plot", "point_plot", "mean_operating_point_plot",
    "simulated_window",
]

#: Highest frequency of the spectrum panel of :func:`point_plot`, in multiples of Ω.
SPECTRUM_ORDERS = 4
_SIM_STYLE = {"color": "black", "ms": 3.0, "ls": "none", "marker": "o", "zorder": 5}


# --------------------------------------------------------------------------------------------
# Figure 4: linear vs non-linear, and the level difference in the 0.6–0.8 band
# --------------------------------------------------------------------------------------------
def linear_vs_nonlinear_plot(
    frf: "FrequencyResponse", level: "LevelDifference", fig: Any = None, *, title: str | None = None
) -> tuple[Any, PlotAxes]:
    """Non-linear rms of δ along every branch against the linear system (top), and the level
    difference ΔL = 20 log10(p2p δ''_non-linear / p2p δ''_linear) over ``level.band`` (bottom).

    Parameters
    ----------
    frf : FrequencyResponse
    level : LevelDifference
        From :func:`rattle.demo.level_difference`.
    fig : matplotlib.figure.Figure, optional
        An empty figure (default a new 10 × 8 in one).
    title : str, optional
        Figure title.

    Returns
    -------
    (figure, PlotAxes)
        Panels ``response`` (the primary) and ``level``.
    """
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(10, 8.2), layout="constrained")
    ax_r, ax_l = fig.subplots(2, 1, height_ratios=(1.35, 1.0))
    lo, hi = level.band
    frequency_response_plot(frf, ax=ax_r, special_points=False, regions=False, legend="none",
                            title="δ rms vs Ω: non-linear (harmonic balance, all branches) and linear")
    ax_r.axvspan(lo, hi, color="tab:red", alpha=0.08, lw=0, zorder=0, label=f"band {lo:g} < Ω < {hi:g} (below)")
    ax_r.legend(fontsize=8, loc="upper right", framealpha=0.9)

    colors = branch_colors(frf)
    labelled: set[tuple[int, bool]] = set()
    # Pieces of consecutive rows with one stability; a gap in the row numbers is where a branch
    # left the band (e.g. the upper branch beyond Ω = 0.8 before it folds back).
    rows, st = level.rows, level.stable
    cut = np.flatnonzero((np.diff(rows) != 1) | (st[1:] != st[:-1]) | (level.branch[1:] != level.branch[:-1])) + 1
    for i0, i1 in zip(np.concatenate(([0], cut)), np.concatenate((cut, [rows.size]))):
        flag, b = bool(st[i0]), int(level.branch[i0])
        j1 = i1 + 1 if i1 < rows.size and rows[i1] == rows[i1 - 1] + 1 else i1  # join to the next piece
        key = (b, flag)
        lab = None if key in labelled else f"acceleration p2p, branch {b} {'stable' if flag else 'unstable'}"
        labelled.add(key)
        ax_l.plot(level.omega[i0:j1], level.db[i0:j1], "-" if flag else "--", color=colors.get(b, "tab:blue"),
                  lw=1.6 if flag else 1.0, label=lab)
    ax_l.plot(level.omega[level.stable], level.db_displacement[level.stable], ".", color="0.55", ms=2.5,
              label="for comparison: displacement rms about the mean (stable)")
    ax_l.axhline(20.0, color="tab:red", ls=":", lw=1.2, label="paper: \"at least 20 dB\"")
    for value, where, text, xy, ha in (
        (level.db_max, level.omega_at_max, "max", (6, 9), "left"), (level.db_min, level.omega_at_min, "min", (-10, 0), "right"),
    ):
        ax_l.plot([where], [value], "o", color="black", ms=6, mfc="white", mew=1.4, zorder=6)
        ax_l.annotate(f"{text} {value:.1f} dB at Ω = {where:.3f}", (where, value), xytext=xy,
                      textcoords="offset points", ha=ha, va="bottom" if text == "max" else "center", fontsize=9,
                      bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85})
    ax_l.set_xlim(lo, hi)
    ymin = min(float(np.min(level.db)), float(np.min(level.db_displacement))) - 2.0
    ax_l.set_ylim(ymin, max(22.0, float(np.max(level.db)) + 2.0))
    ax_l.set_xlabel("forcing frequency Ω (rad/s)")
    ax_l.set_ylabel("ΔL = 20 log10(non-linear / linear) (dB)")
    ax_l.set_title(
        f"Level difference over {lo:g} < Ω < {hi:g}: peak-to-peak acceleration δ'' (∝ sound pressure) of the "
        f"non-linear solution vs the linear system\nstable solutions {level.db_min:.1f} … {level.db_max:.1f} dB "
        "(the lower values on the lower branch, where the response is multi-valued)", fontsize=10)
    ax_l.grid(True, alpha=0.3)
    place_legend(ax_l, "inside")
    fig.suptitle(title if title is not None else "Figure 4 — linear vs non-linear frequency response")
    return fig, PlotAxes({"response": ax_r, "level": ax_l})


# --------------------------------------------------------------------------------------------
# Figure 5: harmonic balance vs the time-domain sweep
# --------------------------------------------------------------------------------------------
#: Marker styles of the sweep points over a frequency response (colours apart from the branches').
SWEEP_STYLES: dict[str, dict[str, Any]] = {
    "up": {"marker": "^", "mfc": "none", "mec": "black", "ms": 4.6, "mew": 0.9, "label": "sweep up (Ω increasing)"},
    "down": {"marker": "v", "mfc": "darkcyan", "mec": "darkcyan", "ms": 3.6, "mew": 0.6,
             "label": "sweep down (Ω decreasing)"},
}


def _draw_sweep_points(sweep: "SweepResult", ax: Any) -> None:
    """Sweep points as markers, and the period of every point that is not period 1 as a strip of
    ticks along the bottom of the axes (up sweep lower, down sweep above it), coloured by period."""
    from matplotlib.transforms import blended_transform_factory

    from ..plotting import PERIOD_COLORS, period_label

    direction = np.asarray(sweep.direction).astype(str)
    period = np.asarray(sweep.period, dtype=int)
    for name, style in SWEEP_STYLES.items():
        m = direction == name
        if np.any(m):
            ax.plot(sweep.omega[m], sweep.rms[m], ls="none", zorder=2.5, **style)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo - 0.12 * (hi - lo), hi)
    strip = blended_transform_factory(ax.transData, ax.transAxes)
    labelled: set[int] = set()
    for k, name in enumerate(SWEEP_STYLES):
        for p in sorted(set(period[direction == name].tolist()) - {1}):
            m = (direction == name) & (period == p)
            ax.plot(sweep.omega[m], np.full(int(np.sum(m)), 0.025 + 0.035 * k), "|", ms=7, mew=1.4,
                    color=PERIOD_COLORS.get(p, "tab:gray"), transform=strip, ls="none", zorder=4,
                    label=f"sweep {period_label(p)} (ticks at the bottom: up, then down)" if p not in labelled else None)
            labelled.add(p)
    for k, name in enumerate(SWEEP_STYLES):
        if np.any((direction == name) & (period != 1)):
            ax.text(0.003, 0.025 + 0.035 * k, name, transform=ax.transAxes, fontsize=7, va="center", ha="left",
                    color="0.3")


def hbm_vs_simulation_plot(
    frf: "FrequencyResponse", sweep: "SweepResult", ax: Any = None, *, title: str | None = None
) -> tuple[Any, PlotAxes]:
    """The frequency response (every branch, stable solid, unstable dashed, special points and
    regions) with the up (▲) and down (▼) sweep points over it; each jump of the sweep is drawn
    as an arrow and annotated with its Ω and the nearest HB fold.

    Returns
    -------
    (figure, PlotAxes)
        One panel ``response`` (the given ``ax`` when there is one).
    """
    import matplotlib.pyplot as plt

    ax = unwrap(ax)
    if ax is None:
        fig, ax = plt.subplots(figsize=(12, 6), layout="constrained")
    else:
        fig = ax.figure
    frequency_response_plot(frf, ax=ax, linear=False, legend="none", title="")
    _draw_sweep_points(sweep, ax)
    folds = [sp for sp in frf.special_points if sp.kind == "fold" and int(frf.period[sp.index]) == 1]
    for j in sweep.jumps():
        near = min(folds, key=lambda s: abs(s.omega - j.omega)) if folds else None
        color = SWEEP_STYLES.get(j.direction, SWEEP_STYLES["up"])["mec"]
        ax.annotate("", (j.omega_after, j.rms_after), xytext=(j.omega_before, j.rms_before),
                    arrowprops={"arrowstyle": "-|>", "color": color, "lw": 1.6, "mutation_scale": 14}, zorder=7)
        text = f"{j.direction} sweep: jump {j.kind}\nΩ = {j.omega_before:.3f} → {j.omega_after:.3f}"
        if near is not None:
            text += f"\nHB fold at Ω = {near.omega:.4f}"
        right = j.direction == "up"
        ax.annotate(text, (j.omega, 0.5 * (j.rms_before + j.rms_after)), xytext=(14 if right else -14, 0),
                    textcoords="offset points", ha="left" if right else "right", va="center", fontsize=8.5,
                    color=color, bbox={"boxstyle": "round,pad=0.25", "fc": "white", "ec": color, "alpha": 0.9},
                    zorder=8)
    n = int(np.sum(np.asarray(sweep.direction) == "up"))
    ax.set_title(title if title is not None else  # two lines: one would run past the figure's left edge
                 f"Figure 5 — harmonic balance (lines; H = {frf.settings.get('harmonics', frf.harmonics)})\n"
                 f"vs the time-domain sweep up and down ({n} frequencies each way)")
    ax.set_ylabel("δ rms (rad)")
    place_legend(ax, "outside")
    return fig, PlotAxes.single(ax)


# --------------------------------------------------------------------------------------------
# Figures 6 and 7: time histories at one frequency
# --------------------------------------------------------------------------------------------
def simulated_window(
    orbit: "PeriodicOrbit", periods: int, samples: int = 256
) -> dict[str, Any] | None:
    """The simulated steady state over ``periods`` forcing periods from a forcing-period start,
    repeated when it is periodic, and shifted by the whole number k of forcing periods that best
    matches the HB orbit of the same period (a 1/p sub-harmonic has p copies, shifted by one
    forcing period each: the same motion).

    Returns
    -------
    dict or None
        ``t``, ``delta``, ``velocity`` (arrays), ``shift`` k and ``period`` p (0: none found);
        None without a simulation.
    """
    sim = orbit.simulation
    traj = None if sim is None else getattr(sim, "trajectory", None)
    if traj is None:
        return None
    Tf = 2.0 * math.pi / orbit.omega
    p = int(orbit.simulated_period or 0)
    t = np.linspace(0.0, periods * Tf, samples * periods + 1)
    start = math.ceil(traj.t0 / Tf - 1e-9) * Tf

    def sample(k: int) -> tuple[np.ndarray, Any]:
        if p >= 1:
            local = start + np.mod(t + k * Tf, p * Tf)
            local = np.where(local > traj.t1, local - p * Tf, local)
            tt = t
        else:
            tt = t[start + t <= traj.t1]
            local = start + tt
        return tt, traj.sample(np.clip(local, traj.t0, traj.t1))

    refs = [i for i, s in enumerate(orbit.solutions) if s.period == p and p >= 2]
    best_k, best = 0, math.inf
    if refs:
        ref = orbit.time_history(refs[0], samples=samples, periods=periods)["delta"]
        for k in range(p):
            _tt, s = sample(k)
            err = float(np.max(np.abs(np.asarray(s.delta) - ref)))
            if err < best:
                best_k, best = k, err
    tt, s = sample(best_k)
    return {"t": tt, "delta": np.asarray(s.delta), "velocity": np.asarray(s.velocity), "shift": best_k,
            "period": p, "error": best}


def _sim_text(p: int) -> str:
    return f"period {p}" if p else "no period ≤ 8 (quasi-periodic or chaotic)"


def point_plot(
    orbit: "PeriodicOrbit",
    fig: Any = None,
    *,
    name: str = "",
    periods: int = 4,
    spectrum: bool = True,
    samples: int = 256,
    note: str = "",
    title: str | None = None,
) -> tuple[Any, PlotAxes]:
    """Time history at one forcing frequency: the simulated steady state (black dots) against
    every HB orbit there (stable solid, unstable dashed): δ(t) over ``periods`` forcing periods,
    the phase portrait (δ, δ') with the simulation's stroboscopic points (t = k·2π/Ω: p points
    for period p, a closed curve for quasi-periodic motion) and, with ``spectrum``, the
    amplitude spectrum of δ in multiples of Ω (half-order lines for a period-2 motion).

    Parameters
    ----------
    orbit : PeriodicOrbit
    fig : matplotlib.figure.Figure, optional
        An empty figure (default a new 12 × 8 in one).
    name : str
        The point's name ("A", "B") for the title.
    periods : int, default 4
        Forcing periods in the time history.
    spectrum : bool, default True
        Draw the spectrum panel.
    samples : int, default 256
        Samples per forcing period.
    note : str
        A second title line (e.g. what the paper said).
    title : str, optional
        Replaces the default title (which says what the simulation shows).

    Returns
    -------
    (figure, PlotAxes)
        Panels ``delta`` (the primary), ``phase`` and (with ``spectrum``) ``spectrum``.
    """
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(12, 8), layout="constrained")
    gs = fig.add_gridspec(2, 2 if spectrum else 1, height_ratios=(1.0, 1.25))
    ax_d = fig.add_subplot(gs[0, :])
    ax_p = fig.add_subplot(gs[1, 0])
    axes: dict[str, Any] = {"delta": ax_d, "phase": ax_p}
    ax_s = fig.add_subplot(gs[1, 1]) if spectrum else None
    if ax_s is not None:
        axes["spectrum"] = ax_s
    Tf = 2.0 * math.pi / orbit.omega
    colors = {1: "tab:blue", 2: "tab:orange", 3: "tab:green", 4: "tab:purple"}
    n_sol = len(orbit.solutions)
    for i, sol in enumerate(orbit.solutions):
        color = colors.get(sol.period, "tab:gray")
        style = "-" if sol.stable else "--"
        lw = 2.0 if sol.stable else 1.4
        label = (f"HB period {sol.period}, {'stable' if sol.stable else 'unstable'} "
                 f"(rms {sol.rms:.4f} rad, |μ|max {float(np.max(np.abs(sol.multipliers))):.3f})")
        h = orbit.time_history(i, samples=samples, periods=periods)
        ax_d.plot(h["t"], h["delta"], style, color=color, lw=lw, label=label, zorder=3)
        one = orbit.time_history(i, samples=samples)
        ax_p.plot(one["delta"], one["velocity"], style, color=color, lw=lw, zorder=3)
        if ax_s is not None:
            f = np.arange(sol.harmonics + 1) / sol.period
            amp = sol.amplitudes()
            keep = (f <= SPECTRUM_ORDERS + 1e-9) & (amp > 1e-7)
            offset = (i - (n_sol - 1) / 2) * 0.05
            ax_s.vlines(f[keep] + offset, 1e-7, amp[keep], color=color, lw=1.8, linestyles=style)
            ax_s.plot(f[keep] + offset, amp[keep], "o", color=color, ms=4.5, mfc=color if sol.stable else "white",
                      label=f"HB period {sol.period} ({'stable' if sol.stable else 'unstable'})")

    win = simulated_window(orbit, periods, samples)
    p = 0
    if win is not None:
        p = int(win["period"])
        step = max(1, samples // 32)
        lab = f"exact simulation: {_sim_text(p)}" + (f" (shifted {win['shift']}·2π/Ω)" if win["shift"] else "")
        ax_d.plot(win["t"][::step], win["delta"][::step], label=lab, **_SIM_STYLE)
        ax_p.plot(win["delta"][::step], win["velocity"][::step], **{**_SIM_STYLE, "ms": 2.2})
        strobe = np.arange(0, win["t"].size, samples)
        ax_p.plot(win["delta"][strobe], win["velocity"][strobe], "*", color="crimson", ms=13, mec="black", mew=0.6,
                  ls="none", zorder=7, label=f"simulation at t = k·2π/Ω ({len(set(np.round(win['delta'][strobe], 6)))} distinct points)")
        if ax_s is not None and p >= 1:
            one = win["delta"][: samples * p]  # one full period, endpoint excluded
            f, amp = amplitude_spectrum(one, p, SPECTRUM_ORDERS)
            keep = amp > 1e-7
            ax_s.plot(f[keep], amp[keep], "o", mfc="none", mec="black", ms=9, mew=1.2, ls="none",
                      label=f"simulation ({_sim_text(p)})")

    breakpoints = np.asarray(orbit.model.elastic.stages.breakpoints, dtype=float)
    for k, bp in enumerate(breakpoints):
        ax_d.axhline(bp, color="0.45", ls=":", lw=1.0, label="stage boundaries ±b" if k == 0 else None)
        ax_p.axvline(bp, color="0.45", ls=":", lw=1.0)
    for m in range(1, periods):
        ax_d.axvline(m * Tf, color="0.82", lw=0.8, zorder=0)
    ax_d.set_xlim(0.0, periods * Tf)
    ax_d.set_xlabel(f"time t (s); grey lines every forcing period 2π/Ω = {Tf:.3f} s")
    ax_d.set_ylabel("δ (rad)")
    ax_d.set_title(f"δ(t) over {periods} forcing periods", fontsize=10)
    ax_d.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax_p.set_xlabel("δ (rad)")
    ax_p.set_ylabel("δ' (rad/s)")
    ax_p.set_title("phase portrait (one period of each orbit)", fontsize=10)
    if ax_p.get_legend_handles_labels()[0]:  # below the portrait, not over the trajectory
        ax_p.legend(fontsize=7.5, loc="upper center", bbox_to_anchor=(0.5, -0.13), framealpha=0.85)
    if ax_s is not None:
        ymax = max([float(np.max(s.amplitudes())) for s in orbit.solutions] + [1e-6])
        ax_s.set_yscale("log")
        # every marker drawn inside (the smallest drawn amplitude, not a fixed 10⁻⁴ of the largest)
        drawn = [float(np.min(y[y > 0])) for line in ax_s.get_lines()
                 if (y := np.asarray(line.get_ydata(), dtype=float)).size and np.any(y > 0)]
        ax_s.set_ylim(max(1e-8, min([ymax * 1e-4, *drawn]) / 2.5), ymax * 4.0)
        ax_s.set_xlim(-0.2, SPECTRUM_ORDERS + 0.2)
        ax_s.set_xticks(np.arange(0, SPECTRUM_ORDERS + 0.01, 0.5))
        ax_s.set_xlabel("frequency / Ω")
        ax_s.set_ylabel("amplitude of δ (rad)")
        if any(s.period == 2 for s in orbit.solutions) or p == 2:
            for k in range(SPECTRUM_ORDERS):
                ax_s.axvspan(k + 0.5 - 0.08, k + 0.5 + 0.08, color="tab:orange", alpha=0.10, lw=0, zorder=0)
            ax_s.set_title("spectrum of δ; shaded: half orders (k + ½)Ω", fontsize=10)
        else:
            ax_s.set_title("amplitude spectrum of δ", fontsize=10)
        ax_s.legend(fontsize=7.5, loc="upper right", framealpha=0.85)
    for ax in axes.values():
        ax.grid(True, alpha=0.3)
    if title is None:
        head = f"Point {name}, " if name else ""
        title = f"{head}Ω = {orbit.omega:g} rad/s: the exact simulation settles on {_sim_text(p)}"
        if p >= 2:
            title += f" (a 1/{p} sub-harmonic)"
        if note:
            title += "\n" + note
    fig.suptitle(title)
    return fig, PlotAxes(axes)


# --------------------------------------------------------------------------------------------
# The mean operating point
# --------------------------------------------------------------------------------------------
def _stage_decoration(ax: Any, model: Any, *, labels: bool) -> None:
    """Stage boundaries (dotted), the soft stage shaded, and each stage named at the right edge."""
    from matplotlib.transforms import blended_transform_factory

    st = model.elastic.stages
    bps = np.asarray(st.breakpoints, dtype=float)
    for k, bp in enumerate(bps):
        ax.axhline(bp, color="black", ls=":", lw=1.3, zorder=2,
                   label=("stage boundaries " + ", ".join(f"{v:+.4f}" for v in bps) + " rad")
                   if labels and k == 0 else None)
    y0, y1 = ax.get_ylim()
    edges = np.concatenate(([-np.inf], bps, [np.inf]))
    right = blended_transform_factory(ax.transAxes, ax.transData)
    slopes = np.asarray(st.slopes, dtype=float)
    # A clutch (soft middle stage between two unit-slope ones): the paper's first and second stage.
    clutch = slopes.size == 3 and slopes[1] < min(slopes[0], slopes[2])
    for j, slope in enumerate(slopes):
        a, b = max(edges[j], y0), min(edges[j + 1], y1)
        if b - a < 0.06 * (y1 - y0):
            continue
        if slope < 1.0:
            ax.axhspan(a, b, color="tab:cyan", alpha=0.06, lw=0, zorder=0)
        name = (("first stage" if j == 1 else "second stage") + f" (slope {slope:g})") if clutch else f"slope {slope:g}"
        ax.text(0.995, 0.5 * (a + b), name, transform=right, ha="right", va="center", fontsize=8.5, color="0.25",
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "0.8", "alpha": 0.9}, zorder=6)
    ax.set_ylim(y0, y1)


def mean_operating_point_plot(
    frf: "FrequencyResponse", fig: Any = None, *, title: str | None = None
) -> tuple[Any, PlotAxes]:
    """The mean operating point δ_m along every branch vs Ω (top; stable solid, unstable dashed,
    special points, the static equilibrium and the stage boundary it crosses), and below it the
    range of δ (min … max) of the stable solutions against all stage boundaries (±b for a
    clutch): where the motion crosses them while its mean moves between the stages.

    Returns
    -------
    (figure, PlotAxes)
        Panels ``mean`` (the primary) and ``range``.
    """
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(11.5, 8), layout="constrained")
    ax, ax_r = fig.subplots(2, 1, sharex=True, height_ratios=(1.5, 1.0))
    model = frf.model
    colors = draw_branches(frf, ax, "mean")
    draw_special_points(frf, ax, "mean")
    draw_regions(frf, ax, "mean", [r for r in frf.regions if r.kind == "subharmonic"], colors, labels=False)
    static = model.static_equilibrium()
    ax.axhline(static, color="0.3", ls="-.", lw=1.0, label=f"static equilibrium δ = {static:.4f} rad")
    bps = np.asarray(model.elastic.stages.breakpoints, dtype=float)
    lo_y = float(np.min(frf.mean))
    hi_y = max(float(np.max(frf.mean)), static)
    near = bps[(bps > lo_y - 0.5 * (hi_y - lo_y)) & (bps < hi_y + 0.5 * (hi_y - lo_y))]
    if near.size:
        lo_y, hi_y = min(lo_y, float(near.min())), max(hi_y, float(near.max()))
    pad = 0.08 * (hi_y - lo_y)
    ax.set_ylim(lo_y - pad, hi_y + 2.5 * pad)
    _stage_decoration(ax, model, labels=True)
    ax.set_ylabel("mean δ_m (rad)")
    ax.grid(True, alpha=0.3)
    ax.set_title("mean δ_m along every branch (zoomed; stage boundaries outside the range are in the panel below)",
                 fontsize=10)
    place_legend(ax, "outside")

    first = min(colors)
    for b, color in colors.items():
        sel = np.flatnonzero(frf.branch == b)
        for i0, i1 in true_runs(np.asarray(frf.stable[sel], dtype=bool)):
            rows = sel[i0:i1]  # a stable stretch runs monotonically in Ω (folds end it)
            if rows.size >= 2 and b == first:  # one shade only: overlapping shades mix into a colour no legend names
                ax_r.fill_between(frf.omega[rows], frf.delta_min[rows], frf.delta_max[rows], color=color,
                                  alpha=0.18, lw=0, zorder=1)
            elif rows.size >= 2:  # another branch's range: its edges, in its colour
                for edge in (frf.delta_min[rows], frf.delta_max[rows]):
                    ax_r.plot(frf.omega[rows], edge, "-", color=color, lw=0.9, alpha=0.9, zorder=2)
        st = np.asarray(frf.stable[sel], dtype=bool)
        ax_r.plot(frf.omega[sel], np.where(st, frf.mean[sel], np.nan), "-", color=color, lw=1.2, zorder=3,
                  label=f"{'δ_m and ' if b == first else 'δ_m and edges of the '}range of δ, {branch_label(frf, b)} "
                        f"(stable{', shaded' if b == first else ''})")
    lo_r = min(float(np.min(frf.delta_min[frf.stable])), float(bps.min()) if bps.size else 0.0)
    hi_r = max(float(np.max(frf.delta_max[frf.stable])), float(bps.max()) if bps.size else 0.0)
    pad = 0.05 * (hi_r - lo_r)
    ax_r.set_ylim(lo_r - pad, hi_r + pad)
    _stage_decoration(ax_r, model, labels=False)
    ax_r.set_xlabel("forcing frequency Ω (rad/s)")
    ax_r.set_ylabel("δ min … max (rad)")
    ax_r.grid(True, alpha=0.3)
    ax_r.set_title("range of δ of the stable solutions (shaded) against the stage boundaries", fontsize=10)
    place_legend(ax_r, "outside")
    fig.suptitle(title if title is not None else
                 "Mean operating point: at rest on the second stage; under the pulsating torque δ_m moves into the "
                 "first stage")
    return fig, PlotAxes({"mean": ax, "range": ax_r})
