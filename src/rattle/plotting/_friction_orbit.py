"""Plot of one periodic orbit of a chain with Coulomb friction.

:func:`friction_orbit_plot`. One panel per element, stacked over one period: δ_e(t) of the exact
orbit (solid) and of the regularised harmonic balance (dashed), every stick phase of the element
(friction holds it, δ_e' ≡ 0) shaded in :data:`~rattle.plotting._nonsmooth.STICK_COLOUR`, one span
per phase. One legend below the panels: the curves, then every orbit found at Ω (the exact census,
``result.solutions``: period, stability, largest |μ|, the first element's rms; a filled mark
stable, hollow unstable).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._axes import PlotAxes
from ._nonsmooth import STICK_COLOUR

if TYPE_CHECKING:  # pragma: no cover
    from ..results import FrictionOrbitResult

_SHADE_ALPHA = 0.25


def friction_orbit_plot(result: FrictionOrbitResult) -> tuple[Any, PlotAxes]:
    """Draw one period of ``result`` (module docstring); returns (figure, PlotAxes with one panel
    per element, named by the element, the first the primary). Each stick phase is one shaded span
    (``ax[name].patches``)."""
    import matplotlib.pyplot as plt

    m = result.m
    every = tuple(getattr(result, "solutions", ()) or ())
    fig, axes = plt.subplots(m, 1, figsize=(9, 1.6 + 2.4 * m + 0.18 * len(every)), sharex=True, squeeze=False,
                             layout="constrained")
    T = result.period
    hb_label = f"regularised HB (ε = {result.regularisation:g}, H = {result.harmonics})"
    panels: dict[str, Any] = {}
    for e, name in enumerate(result.element_names):
        ax = axes[e, 0]
        if result.converged:
            ax.plot(result.t, result.delta[:, e], "-", color="tab:blue", lw=1.4, label="exact orbit")
        if np.any(np.isfinite(result.delta_hb[:, e])):
            ax.plot(result.t, result.delta_hb[:, e], "--", color="0.35", lw=1.0, label=hb_label)
        for i, (ta, tb) in enumerate(result.stick_intervals[e]):
            ax.axvspan(ta, tb, color=STICK_COLOUR, alpha=_SHADE_ALPHA, lw=0,
                       label="stick (friction holds)" if i == 0 else None)
        text = name
        if result.converged:
            err = result.element_rms_error[e]
            text += (f": rms {result.rms[e]:.4g} rad ({f'HB {err:+.1e}' if np.isfinite(err) else 'no HB'}), "
                     f"sticks {result.stick_fraction[e]:.1%} of the period")
        ax.set_title(text, fontsize="small", loc="left")
        ax.set_ylabel(f"δ {name} (rad)")
        ax.grid(alpha=0.3)
        panels[name] = ax
    axes[-1, 0].set_xlabel("t (s)")
    axes[0, 0].set_xlim(0.0, T)
    title = f"Ω = {result.omega:.6g} rad/s"
    if result.speed_rpm is not None:
        title += f" ({result.speed_rpm:.5g} rpm)"
    if result.converged:
        title += (f": {'stable' if result.stable else 'unstable'} (max |μ| = {result.mu_abs:.3g}), period {T:.4g} s"
                  + ("" if result.periods == 1 else f" ({result.periods} forcing periods)"))
    else:
        title += ": no exact orbit (HB only)"
    fig.suptitle(title, fontsize="medium")
    # one legend below the panels (it hides no data): the curves, then every orbit found at Ω
    # (the exact census: index, period, stability, the first element's rms), listed
    handles, labels = axes[0, 0].get_legend_handles_labels()
    for a in axes[1:, 0]:
        for h, text in zip(*a.get_legend_handles_labels()):
            if text not in labels:
                handles.append(h)
                labels.append(text)
    from matplotlib.lines import Line2D

    for i, sol in enumerate(every):
        mu = float(np.max(np.abs(sol.multipliers)))
        # listed, not drawn (the panels show the orbit asked for): a filled mark stable, hollow unstable
        handles.append(Line2D([], [], ls="none", marker="o", ms=5, color="0.3", mfc="0.3" if sol.stable else "white"))
        labels.append(f"orbit [{i}] at Ω: period {sol.period}, {'stable' if sol.stable else 'unstable'} "
                      f"(|μ|max {mu:.3g}), {result.element_names[0]} rms {sol.rms:.4g} rad")
    fig.legend(handles, labels, loc="outside lower center", ncol=1 if every else 3, fontsize="x-small",
               frameon=False)
    return fig, PlotAxes(panels)


__all__ = ["friction_orbit_plot"]
