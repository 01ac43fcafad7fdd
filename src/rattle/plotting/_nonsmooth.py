"""Plot of the frequency response of a discontinuous law (preload, friction).

Top panel: the rms of δ of the exact orbits (solid where stable, dashed where unstable, points the
exact shooting did not match left out) and the regularised harmonic balance's rms (thin grey),
with the labelled changes of stability; bottom panel: the fraction of the period the exact orbit
sticks (or locks), where the friction holds the clutch.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._axes import PlotAxes

if TYPE_CHECKING:  # pragma: no cover
    from ..results import NonsmoothResponse

_MARKERS = {"fold": "o", "period_doubling": "s", "neimark_sacker": "D"}


def nonsmooth_response_plot(response: NonsmoothResponse) -> tuple[Any, PlotAxes]:
    """Draw ``response`` (module docstring); returns (figure, PlotAxes with panels ``rms`` and
    ``stick``)."""
    import matplotlib.pyplot as plt

    fig, (ax, ax_s) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, gridspec_kw={"height_ratios": (3, 1)})
    w = response.omega
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
    ax.set_ylabel("δ rms (rad)")
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    T = 2.0 * np.pi / w
    ax_s.plot(w, np.where(matched, response.stick_time / T, np.nan), "-", color="tab:green", lw=1.2)
    ax_s.set_ylim(-0.02, 1.02)
    ax_s.set_ylabel("stick / period")
    ax_s.set_xlabel("Ω (rad/s)")
    ax_s.grid(alpha=0.3)
    fig.tight_layout()
    return fig, PlotAxes({"rms": ax, "stick": ax_s})


__all__ = ["nonsmooth_response_plot"]
