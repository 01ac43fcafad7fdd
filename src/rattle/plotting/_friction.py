"""Plot of the frequency response of a chain with Coulomb friction.

:func:`friction_response_plot`. Top panel: every element's rms of δ_e against Ω, one colour per
element: the exact orbits solid where stable, thin dotted where unstable (with × markers), the
regularised harmonic balance dashed; the stability changes labelled; the Ω-ranges where some
element of the exact orbit sticks for part of the period shaded. Bottom panel: each element's
stick fraction (the part of the period its friction holds it). The sub-harmonic branches
(``response.branches``) are drawn dash-dotted in each element's colour (stable thick, unstable
thin).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._axes import PlotAxes
from ._axes import stick_ylim
from ..results import held_runs
from ._nonsmooth import STICK_COLOUR

if TYPE_CHECKING:  # pragma: no cover
    from ..results import FrictionCheck

_MARKERS = {"fold": "o", "period_doubling": "s", "neimark_sacker": "D"}


def friction_response_plot(response: FrictionCheck) -> tuple[Any, PlotAxes]:
    """Draw ``response`` (module docstring); returns (figure, PlotAxes with panels ``rms`` (the
    primary) and ``stick``)."""
    import matplotlib.pyplot as plt

    fig, (ax, ax_s) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True, gridspec_kw={"height_ratios": (3, 1)},
                                   layout="constrained")
    w = response.omega
    matched = response.matched
    colours = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0", "C1", "C2", "C3"])
    labels = response.bifurcation
    for e, name in enumerate(response.element_names):
        c = colours[e % len(colours)]
        if np.any(np.isfinite(response.rms_hb[:, e])):  # none when followed by exact shooting
            ax.plot(w, response.rms_hb[:, e], "--", color=c, lw=0.9, alpha=0.8,
                    label=f"{name}: HB (ε = {response.regularisation:g}, H = {response.harmonics})")
        ax.plot(w, np.where(matched & response.stable, response.rms[:, e], np.nan), "-", color=c, lw=1.6,
                label=f"{name}: exact, stable")
        unst = matched & ~response.stable
        if np.any(unst):
            ax.plot(w, np.where(unst, response.rms[:, e], np.nan), ":", color=c, lw=1.2)
            ax.plot(w[unst], response.rms[unst, e], "x", color=c, ms=4, ls="none", label=f"{name}: exact, unstable")
        for kind, marker in _MARKERS.items():
            sel = labels == kind
            if np.any(sel):
                ax.plot(w[sel], response.rms[sel, e], marker, color="tab:red", ms=5, ls="none",
                        label=kind.replace("_", " ") if e == 0 else None)
        ax_s.plot(w, np.where(matched, response.stick_fraction[:, e], np.nan), "-", color=c, lw=1.2, label=name)
        for br in response.branches:  # the sub-harmonic branches: the element's colour, dash-dotted
            for ok, lw, kind in ((br.matched & br.stable, 2.2, "stable"), (br.matched & ~br.stable, 0.9, "unstable")):
                if np.any(ok):
                    ax.plot(br.omega, np.where(ok, br.rms[:, e], np.nan), "-.", color=c, lw=lw, alpha=0.75,
                            label=f"{name}: period {br.period}, branch {br.branch}, {kind}")
            ax_s.plot(br.omega, np.where(br.matched, br.stick_fraction[:, e], np.nan), "-.", color=c, lw=1.0)
    held = matched & (np.nan_to_num(response.stick_fraction).max(axis=1) > 0.0) if len(response) else matched
    for i, (a, b) in enumerate(held_runs(w, held)):
        ax.axvspan(a, b, color=STICK_COLOUR, alpha=0.12, lw=0, label="an element sticks" if i == 0 else None)
        ax_s.axvspan(a, b, color=STICK_COLOUR, alpha=0.12, lw=0)
    ax.set_ylabel("δ rms (rad)")
    ax.set_title(f"Exact orbits of the chain (shooting) and its regularised harmonic balance "
                 f"(ε = {response.regularisation:g}, H = {response.harmonics})", fontsize=10)
    ax.legend(fontsize="x-small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.3)
    stick_ylim(ax_s, [np.where(matched, response.stick_fraction[:, e], np.nan)
                      for e in range(len(response.element_names))]
               + [np.where(br.matched[:, None], br.stick_fraction, np.nan) for br in response.branches])
    ax_s.set_ylabel("stick / period")
    ax_s.set_xlabel("Ω (rad/s)")
    ax_s.legend(fontsize="x-small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax_s.grid(alpha=0.3)
    return fig, PlotAxes({"rms": ax, "stick": ax_s})


__all__ = ["friction_response_plot"]
