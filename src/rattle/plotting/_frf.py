"""Plot of a frequency response: rms vs Ω, stable solid, unstable dashed."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from ..results import FrequencyResponse

_MARKERS = {"fold": ("o", "tab:red"), "period_doubling": ("s", "tab:purple"), "neimark_sacker": ("D", "tab:green")}


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs of consecutive True values, stop exclusive."""
    edges = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    return list(zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]))


def frequency_response_plot(
    frf: "FrequencyResponse",
    ax: Any = None,
    *,
    quantity: str = "rms",
    linear: bool = True,
    title: str | None = None,
) -> tuple[Any, Any]:
    """Draw ``quantity`` (a SPEC column, default rms) vs Ω; returns (figure, axes).

    Stable stretches solid, unstable dashed (each branch its colour), stability changes marked
    by type, and the linear system's response (f = δ) overlaid in grey.
    """
    import matplotlib.pyplot as plt

    if quantity not in ("mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max"):
        raise ValueError(f"`quantity` must be a numeric SPEC column, got {quantity!r}")
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 5), layout="constrained")
    else:
        fig = ax.figure
    y_all = getattr(frf, quantity)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for n, b in enumerate(np.unique(frf.branch)):
        sel = np.nonzero(frf.branch == b)[0]
        om, y, st = frf.omega[sel], y_all[sel], frf.stable[sel]
        color = colors[n % len(colors)]
        period = int(frf.period[sel[0]])
        label_base = f"branch {b}" + (f" (period {period})" if period > 1 else "")
        first = {True: True, False: True}
        for flag, style in ((True, "-"), (False, "--")):
            for i0, i1 in _runs(st == flag):
                # Extend each run by one point so that solid and dashed pieces join.
                j1 = min(i1 + 1, sel.size)
                lab = None
                if first[flag]:
                    lab = f"{label_base}, {'stable' if flag else 'unstable'}"
                    first[flag] = False
                ax.plot(om[i0:j1], y[i0:j1], style, color=color, lw=1.4 if flag else 1.1, label=lab)
    for kind, (marker, color) in _MARKERS.items():
        idx = np.nonzero(frf.bifurcation == kind)[0]
        if idx.size:
            ax.plot(frf.omega[idx], y_all[idx], marker, color=color, ms=6, mfc="none", mew=1.5, ls="none", label=kind.replace("_", " "))
    if linear and quantity in ("mean", "rms", "rms_ac"):
        lin = frf.linear_response()
        ax.plot(lin.omega, getattr(lin, quantity), color="0.55", lw=1.0, label="linear system (f = δ)")
    ax.set_xlabel("forcing frequency Ω (rad/s)")
    ax.set_ylabel({"rms": "δ rms (rad)"}.get(quantity, f"{quantity}"))
    ax.set_title(title if title is not None else f"Non-linear frequency response (H = {frf.harmonics})")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return fig, ax


__all__ = ["frequency_response_plot"]
