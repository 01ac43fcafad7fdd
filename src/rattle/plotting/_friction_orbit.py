"""Plot of one periodic orbit of a chain with Coulomb friction.

:func:`friction_orbit_plot`. One panel per element, stacked over one period: δ_e(t) of the exact
orbit (solid) and of the regularised harmonic balance (dashed), every stick phase of the element
(friction holds it, δ_e' ≡ 0) shaded in :data:`~rattle.plotting._nonsmooth.STICK_COLOUR`, one span
per phase.
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
    fig, axes = plt.subplots(m, 1, figsize=(9, 1.0 + 2.4 * m), sharex=True, squeeze=False)
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
        ax.legend(fontsize="x-small", loc="upper right")
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
    fig.tight_layout()
    return fig, PlotAxes(panels)


__all__ = ["friction_orbit_plot"]
