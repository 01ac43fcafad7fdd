"""Plots of a discontinuous law (preload, friction): the frequency response and one orbit.

:func:`nonsmooth_response_plot`. Top panel: the rms of δ of the exact orbits (solid where stable,
dashed where unstable, points the exact shooting did not match left out) and the regularised
harmonic balance's rms (thin grey), with the labelled changes of stability, and the Ω-ranges where
the exact orbit sticks or locks for part of the period shaded; bottom panel: the fraction of the
period the exact orbit sticks (or locks), where the friction holds the clutch, filled in the same
colour. Sub-harmonic branches (``response.branches``) are drawn in their own colours in both
panels (their stick fraction over their own period).

:func:`nonsmooth_orbit_plot`. One period of one orbit: δ(t) exact with the HB's δ(t) dashed and the
breakpoints (where the law jumps or its friction changes) as horizontal lines; δ'(t); the phase
portrait (δ, δ'), with every other orbit found at Ω (``result.solutions``, the exact census: its
Fourier series over its own period, solid stable, dashed unstable, named by period, stability and
rms in the legend). Every stick phase (friction holds, δ' ≡ 0) is shaded in :data:`STICK_COLOUR`,
every lock phase (held at a jump of the preload) in :data:`LOCK_COLOUR`, one span per phase. One
legend below the panels, where it hides no data.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..results import held_runs
from ._axes import PlotAxes
from ._axes import stick_ylim

if TYPE_CHECKING:  # pragma: no cover
    from ..results import NonsmoothOrbitResult, NonsmoothCheck

#: Colours of the sub-harmonic branches, in order (the period-1 branch is tab:blue).
_BRANCH_COLOURS = ("tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")

_MARKERS = {"fold": "o", "period_doubling": "s", "neimark_sacker": "D", "grazing": "^", "grazing_sliding": "v"}

#: Shading of the stick phases (friction holds the clutch) and of the lock phases (held at a jump).
STICK_COLOUR = "tab:green"
LOCK_COLOUR = "tab:orange"
_SHADE_ALPHA = 0.25


def nonsmooth_response_plot(response: NonsmoothCheck) -> tuple[Any, PlotAxes]:
    """Draw ``response`` (module docstring); returns (figure, PlotAxes with panels ``rms`` and
    ``stick``)."""
    import matplotlib.pyplot as plt

    fig, (ax, ax_s) = plt.subplots(2, 1, figsize=(9.5, 6), sharex=True, gridspec_kw={"height_ratios": (3, 1)},
                                   layout="constrained")
    w = response.omega
    if np.any(np.isfinite(response.rms_hb)):  # none when followed by exact shooting
        ax.plot(w, response.rms_hb, "-", color="0.6", lw=0.8,
                label=f"regularised HB (ε = {response.regularisation:g}, H = {response.harmonics})")
    matched = response.matched
    for stable, style, text in ((True, "-", "exact orbit, stable"), (False, "--", "exact orbit, unstable")):
        y = np.where(matched & (response.stable == stable), response.rms, np.nan)
        ax.plot(w, y, style, color="tab:blue", lw=1.4, label=text)
    labels = response.bifurcation
    for kind, marker in _MARKERS.items():
        sel = labels == kind
        if np.any(sel):
            ax.plot(w[sel], response.rms[sel], marker, color="tab:red", ms=5, ls="none", label=kind.replace("_", " "))
    for k, br in enumerate(response.branches):  # the sub-harmonic branches, each in its colour
        colour = _BRANCH_COLOURS[k % len(_BRANCH_COLOURS)]
        ax.plot(br.omega, br.rms_hb, "-", color="0.6", lw=0.8, zorder=1)
        for stable, style in ((True, "-"), (False, "--")):
            y = np.where(br.matched & (br.stable == stable), br.rms, np.nan)
            ax.plot(br.omega, y, style, color=colour, lw=1.6, zorder=3,
                    label=f"branch {br.branch}: period {br.period}, exact" if stable else None)
        fr = np.where(br.matched, br.stick_time / (br.period * 2.0 * np.pi / br.omega), np.nan)
        ax_s.plot(br.omega, fr, "-", color=colour, lw=1.0)
    held = matched & (np.nan_to_num(response.stick_time) > 0.0)
    for i, (a, b) in enumerate(held_runs(w, held)):
        ax.axvspan(a, b, color=STICK_COLOUR, alpha=0.12, lw=0, label="exact orbit sticks or locks" if i == 0 else None)
    ax.set_ylabel("δ rms (rad)")
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.3)
    ax.set_title(f"Exact orbits (shooting) and the regularised harmonic balance (ε = {response.regularisation:g}, "
                 f"H = {response.harmonics})", fontsize=10)
    T = 2.0 * np.pi / w
    frac = np.where(matched, response.stick_time / T, np.nan)
    ax_s.plot(w, frac, "-", color=STICK_COLOUR, lw=1.2)
    ax_s.fill_between(w, 0.0, frac, where=np.isfinite(frac), color=STICK_COLOUR, alpha=_SHADE_ALPHA, lw=0)
    stick_ylim(ax_s, [frac, *(np.where(br.matched, br.stick_time / (br.period * 2.0 * np.pi / br.omega), np.nan)
                              for br in response.branches)])
    if not np.any(np.nan_to_num(frac) > 0.0) and not any(
            np.any(np.nan_to_num(br.stick_time) > 0.0) for br in response.branches):  # say so, not a row of zeros
        ax_s.text(0.5, 0.5, "the exact orbit is never stuck or locked on this range", transform=ax_s.transAxes,
                  ha="center", va="center", fontsize=9, color="0.3")
    ax_s.set_ylabel("stick / period")
    ax_s.set_xlabel("Ω (rad/s)")
    ax_s.grid(alpha=0.3)
    return fig, PlotAxes({"rms": ax, "stick": ax_s})


def nonsmooth_orbit_plot(result: NonsmoothOrbitResult, points: int = 1024) -> tuple[Any, PlotAxes]:
    """Draw one period of ``result`` (module docstring) at ``points`` times plus every event;
    returns (figure, PlotAxes with panels ``delta`` (the primary), ``velocity`` and ``phase``).
    In ``delta`` and ``velocity`` each stick or lock phase is one shaded span (``ax.patches``)."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(11, 6.6), layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(3, 2))
    ax_d = fig.add_subplot(grid[0, 0])
    ax_v = fig.add_subplot(grid[1, 0], sharex=ax_d)
    ax_p = fig.add_subplot(grid[:, 1])
    T = result.period
    t = result.sample_times(points)
    d_hb, v_hb = result.sample_hb(t), result.sample_hb(t, derivative=1)
    hb_label = f"regularised HB (ε = {result.regularisation:g}, H = {result.harmonics})"
    if result.orbit is not None:
        d, v, _ = result.sample(t)
        ax_d.plot(t, d, "-", color="tab:blue", lw=1.4, label="exact orbit")
        ax_v.plot(t, v, "-", color="tab:blue", lw=1.4)
        ax_p.plot(d, v, "-", color="tab:blue", lw=1.4, label="exact orbit")
    ax_d.plot(t, d_hb, "--", color="0.35", lw=1.0, label=hb_label)
    ax_v.plot(t, v_hb, "--", color="0.35", lw=1.0)
    ax_p.plot(d_hb, v_hb, "--", color="0.35", lw=1.0, label=hb_label)
    seen: set[str] = set()
    for ta, tb, kind in result.stick_intervals:
        colour = STICK_COLOUR if kind == "stick" else LOCK_COLOUR
        label = None if kind in seen else ("stick (friction holds)" if kind == "stick" else "lock (held at a jump)")
        seen.add(kind)
        ax_d.axvspan(ta, tb, color=colour, alpha=_SHADE_ALPHA, lw=0, label=label)
        ax_v.axvspan(ta, tb, color=colour, alpha=_SHADE_ALPHA, lw=0)
        held = float(result.sample(np.array([0.5 * (ta + tb)]))[0][0])
        ax_p.plot([held], [0.0], "o", color=colour, ms=7, label=label)
    _draw_every_orbit(result, ax_p)
    law = result.system.law
    bp = law.stages.breakpoints
    jumps, levels = law.stages.jumps, law.friction_levels
    for i, b in enumerate(bp.tolist()):
        what = "jump" if jumps[i] > 0 else ("friction changes" if levels[i] != levels[i + 1] else "breakpoint")
        ax_d.axhline(b, color="0.2", ls=":", lw=0.9, label=f"{what} at δ = {b:g}")
        ax_p.axvline(b, color="0.2", ls=":", lw=0.9)
    ax_d.set_ylabel("δ (rad)")
    ax_v.set_ylabel("δ' (rad/s)")
    ax_v.set_xlabel("t (s)")
    ax_d.set_xlim(0.0, T)
    ax_p.set_xlabel("δ (rad)")
    ax_p.set_ylabel("δ' (rad/s)")
    title = f"Ω = {result.omega:.6g} rad/s" + (f", period {result.periods} (sub-harmonic)" if result.periods > 1 else "")
    if result.orbit is not None:
        title += (f": rms {result.rms:.4g} rad (HB {result.rms_error:+.1e}), "
                  f"{'stable' if result.stable else 'unstable'}, held {result.stick_time:.3g} of {T:.3g} s")
    else:
        title += ": no exact orbit (HB only)"
    n_every = len(getattr(result, "solutions", ()) or ())
    if n_every > 1:
        ax_p.set_title(f"phase portrait: every orbit at Ω ({n_every} periodic)", fontsize=10)
    fig.suptitle(title, fontsize="medium")
    for a in (ax_d, ax_v, ax_p):
        a.grid(alpha=0.3)
    # one legend below the panels, where it hides no data: the curves of δ(t), then every orbit
    # of the phase portrait (each named by its period and stability)
    handles, labels = ax_d.get_legend_handles_labels()
    for h, text in zip(*ax_p.get_legend_handles_labels()):
        if text not in labels:
            handles.append(h)
            labels.append(text)
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize="small", frameon=False)
    return fig, PlotAxes({"delta": ax_d, "velocity": ax_v, "phase": ax_p})


#: Colours of the other orbits at Ω in the phase portrait (the exact orbit asked for is tab:blue).
_ORBIT_COLOURS = ("tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan", "tab:orange",
                  "tab:gray")


def _draw_every_orbit(result: Any, ax_p: Any, samples: int = 512) -> None:
    """Every orbit found at Ω (``result.solutions``: the exact census, each with the Fourier series
    of its δ over its own period p·2π/Ω) as a closed curve of the phase portrait (δ, δ'), solid
    where stable and dashed where unstable, named in the legend by its index, period, stability
    (largest |μ|) and rms — the orbit asked for among them (drawn thick above)."""
    from ..measures import evaluate_batch

    for i, sol in enumerate(getattr(result, "solutions", ()) or ()):
        if sol.elements:  # a chain's series hold its coordinates: drawn by its own plot
            continue
        t = np.linspace(0.0, sol.period * 2.0 * np.pi / sol.omega, samples * sol.period + 1)[None, :]
        q, w = np.asarray(sol.coefficients, dtype=float)[None, :], np.array([sol.base_frequency])
        d, v = evaluate_batch(q, w, t)[0], evaluate_batch(q, w, t, derivative=1)[0]
        mu = float(np.max(np.abs(sol.multipliers)))
        text = (f"orbit [{i}] at Ω: period {sol.period}, {'stable' if sol.stable else 'unstable'} (|μ|max {mu:.3g}), "
                f"rms {sol.rms:.4g} rad")
        asked = getattr(result, "orbit", None) is not None and sol.period == result.periods and \
            abs(sol.rms - result.rms) <= 1e-6 * max(abs(result.rms), 1e-300)
        if asked:  # the exact orbit drawn above: named, not drawn twice
            ax_p.plot([], [], "-", color="tab:blue", lw=1.4, label=f"{text}: the exact orbit above")
            continue
        ax_p.plot(d, v, "-" if sol.stable else "--", color=_ORBIT_COLOURS[i % len(_ORBIT_COLOURS)], lw=1.0,
                  zorder=1, label=text)


__all__ = ["LOCK_COLOUR", "STICK_COLOUR", "nonsmooth_orbit_plot", "nonsmooth_response_plot"]
