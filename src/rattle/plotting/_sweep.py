"""Plot of a time-domain frequency sweep: a response measure vs Ω, up and down sweeps apart."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._axes import PlotAxes, fit_ylim, separate_texts, speed_axis, stick_ylim, unwrap
from ._frf import draw_linear_spl

if TYPE_CHECKING:  # pragma: no cover
    from ..results import SweepResult

#: Marker, colour and legend text of each sweep direction.
DIRECTION_STYLES: dict[str, tuple[str, str, str]] = {
    "up": ("^", "tab:blue", "sweep up (Ω increasing)"),
    "down": ("v", "tab:orange", "sweep down (Ω decreasing)"),
}
#: Ring colours of the points whose period is not 1 (period 0: none up to 8 found).
PERIOD_COLORS: dict[int, str] = {
    0: "black", 2: "tab:red", 3: "tab:green", 4: "tab:purple", 5: "tab:brown",
    6: "tab:pink", 7: "tab:olive", 8: "tab:cyan",
}
_QUANTITIES = {
    "mean": "δ mean (rad)", "rms": "δ rms (rad)", "rms_ac": "δ rms about the mean (rad)",
    "p2p": "δ peak-to-peak (rad)", "acc_p2p": "δ'' peak-to-peak (rad/s²)",
    "spl_db": "sound pressure level (dB re 20 µPa)",
}


def _column(sweep: "SweepResult", quantity: str) -> np.ndarray:
    """The values of ``quantity``: a SPEC column or an extra one (``spl_db``)."""
    extra = getattr(sweep, "extra_columns", {}) or {}
    return np.asarray(extra[quantity] if quantity in extra else getattr(sweep, quantity), dtype=float)


def _runs(values: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of runs of equal consecutive values, stop exclusive."""
    if values.size == 0:
        return []
    cut = np.nonzero(values[1:] != values[:-1])[0] + 1
    starts = np.concatenate(([0], cut))
    stops = np.concatenate((cut, [values.size]))
    return list(zip(starts.tolist(), stops.tolist()))


def period_label(period: int) -> str:
    """Legend text of a period: ``period n``, or ``no period ≤ 8`` for 0."""
    return "no period ≤ 8 (quasi-periodic or chaotic)" if int(period) == 0 else f"period {int(period)}"


def sweep_plot(
    sweep: "SweepResult",
    ax: Any = None,
    *,
    quantity: str = "rms",
    annotate: bool = True,
    lines: bool = True,
    title: str | None = None,
) -> tuple[Any, PlotAxes]:
    """Draw ``quantity`` (default rms of δ) vs Ω for each sweep direction; returns (figure, PlotAxes).

    The up sweep is drawn with ▲ markers, the down sweep with ▼ markers, each in its colour and
    joined in sweep order, so that the jumps at the ends of a multi-valued region show as
    vertical steps at different Ω. Points whose motion has a period other than 1 are ringed in
    a colour per period, and each run of them is labelled with its period ("P2"); period 0
    (no period up to 8: quasi-periodic or chaotic) is ringed in black and labelled "P0". A failed
    row (no steady state, period −1, NaN measures) has no point: its line breaks there and a
    dotted grey vertical line marks its Ω.

    Parameters
    ----------
    sweep : SweepResult
        Columns ``direction``, ``omega``, the measures and ``period``.
    ax : matplotlib.axes.Axes or PlotAxes, optional
        Axes to draw into (default: a new 8 × 5 in figure; a :class:`PlotAxes`: its primary).
    quantity : str, default "rms"
        One of ``mean``, ``rms``, ``rms_ac``, ``p2p``, ``acc_p2p``, or ``spl_db`` (a sweep with
        sound paths: the level at the receiver, one panel).
    annotate : bool, default True
        Label each run of period ≠ 1 points with its period.
    lines : bool, default True
        Join the points of each direction (False: markers only, e.g. over a frequency response).
    title : str, optional
        Axes title.

    Returns
    -------
    (figure, PlotAxes)
        One panel ``response`` (the given ``ax`` when there is one). A chain's sweep
        (per-element columns) drawn without ``ax``: one panel per clearance element
        (``quantity`` of its deflection), keyed by its name, sharing Ω; the primary is the
        first element's. A discontinuous law's sweep (``stick_fraction`` columns) drawn without
        ``ax``: below them a panel ``stick``, the fraction of each row's period held stuck or
        locked per direction (and element).
    """
    import matplotlib.pyplot as plt

    ax = unwrap(ax)
    if quantity not in _QUANTITIES:
        raise ValueError(f"`quantity` must be one of {sorted(_QUANTITIES)}, got {quantity!r}")
    names = tuple(getattr(sweep, "element_names", ()) or ())
    extra = getattr(sweep, "extra_columns", {}) or {}
    sound = ax is None and "spl_db" in extra  # [[paths]]: an SPL panel below
    if quantity == "spl_db":  # the level at the receiver: one panel, the whole chain's
        if "spl_db" not in extra:
            raise ValueError("`quantity` \"spl_db\" needs a sweep with sound paths (sweep.with_sound(paths)); this one "
                             "has no spl_db column")
        names, sound = (), False
    # a discontinuous law: the stick fractions in a panel below
    sticks = [k for k in extra if k.endswith("stick_fraction")] if ax is None else []
    # a stick panel only where something sticks or locks (a pure preload that never locks: none)
    held = [k for k in sticks if np.any(np.nan_to_num(np.asarray(extra[k], dtype=float)) > 0.0)]
    if sticks and not held and title is None:
        title = "Time-domain frequency sweep (steady state at each Ω)\nnever stuck or locked at any Ω"
    sticks = held
    if sticks:
        fig, axes = plt.subplots(max(1, len(names)) + 1, 1, figsize=(8, 3.0 + 3.0 * max(1, len(names))), sharex=True,
                                 layout="constrained", squeeze=False,
                                 height_ratios=(3.0,) * max(1, len(names)) + (1.3,))
        ax_s = axes[-1, 0]
        for k, ax_k in enumerate(axes[:-1, 0]):
            y = sweep.element_columns[f"{names[k]}_{quantity}"] if names else _column(sweep, quantity)
            _draw_sweep(sweep, ax_k, np.asarray(y, dtype=float), annotate, lines, legend=k == 0)
            ax_k.set_ylabel(f"{names[k]}: {_QUANTITIES[quantity]}" if names else _QUANTITIES[quantity])
            first = title if title is not None else "Time-domain frequency sweep (steady state at each Ω)"
            ax_k.set_title(first + (f" — element {names[k]}" if names and k == 0 else "") if k == 0
                           else f"element {names[k]}", fontsize=10 if names else None)
            ax_k.set_xlabel("")
        _draw_stick_panel(sweep, ax_s, sticks, lines)
        separate_texts(fig, axes[:, 0])
        tags = [*(names or ("response",)), "stick"]
        return fig, PlotAxes(zip(tags, axes[:, 0]))
    if names and ax is None:  # a chain: one panel per element, sharing Ω
        fig, axes = plt.subplots(len(names) + sound, 1, figsize=(8, 1.5 + 3.0 * (len(names) + sound)), sharex=True,
                                 layout="constrained", squeeze=False)
        for k, (name, ax_k) in enumerate(zip(names, axes[:, 0])):
            first = title if title is not None else "Time-domain frequency sweep (steady state at each Ω)"
            _draw_sweep(sweep, ax_k, np.asarray(sweep.element_columns[f"{name}_{quantity}"], dtype=float),
                        annotate, lines, legend=k == 0)
            ax_k.set_ylabel(f"{name}: {_QUANTITIES[quantity]}")
            ax_k.set_title(f"{first} — element {name}" if k == 0 else f"element {name}", fontsize=10)
            if k < len(names) - 1 or sound:
                ax_k.set_xlabel("")
        if sound:
            _draw_sound_panel(sweep, axes[-1, 0], annotate, lines)
        separate_texts(fig, axes[:, 0])
        if sound:
            return fig, PlotAxes([*zip(names, axes[:-1, 0]), ("spl_db", axes[-1, 0])])
        return fig, PlotAxes(zip(names, axes[:, 0]))
    own = ax is None  # a figure of its own: its labels are separated here (else by the caller)
    if ax is None and sound:
        fig, (ax, ax_spl) = plt.subplots(2, 1, figsize=(8, 7.6), sharex=True, layout="constrained")
    elif ax is None:
        fig, ax = plt.subplots(figsize=(8, 5), layout="constrained")
    else:
        fig = ax.figure
    _draw_sweep(sweep, ax, _column(sweep, quantity), annotate, lines, legend=True)
    ax.set_ylabel(_QUANTITIES[quantity])
    ax.set_title(title if title is not None else "Time-domain frequency sweep (steady state at each Ω)")
    if sound:
        ax.set_xlabel("")
        _draw_sound_panel(sweep, ax_spl, annotate, lines)
        separate_texts(fig, (ax, ax_spl))
        return fig, PlotAxes([("response", ax), ("spl_db", ax_spl)])
    if own:
        separate_texts(fig, (ax,))
    return fig, PlotAxes.single(ax)


def _draw_sound_panel(sweep: "SweepResult", ax: Any, annotate: bool, lines: bool) -> None:
    """The sound pressure level ``spl_db`` at the receiver of every row's simulated motion
    (``sweep.with_sound(paths)``) per direction, the linear system's level in grey."""

    _draw_sweep(sweep, ax, np.asarray(sweep.extra_columns["spl_db"], dtype=float), annotate, lines, legend=False)
    if draw_linear_spl(sweep, ax):  # the linear system, on a dense grid (closed form)
        ax.legend(fontsize=8, loc="best", framealpha=0.9)
        fit_ylim(ax, room=0.08)  # every point of it inside too (the sweep's limits were set before it)
    ax.set_ylabel("sound pressure level (dB re 20 µPa)")
    ax.set_title("sound pressure at the receiver (paths summed harmonic by harmonic)", fontsize=10)


def _draw_stick_panel(sweep: "SweepResult", ax: Any, keys: list[str], lines: bool) -> None:
    """The fraction of each row's period held stuck or locked (a discontinuous law's sweep), per
    direction and element."""

    sx, xlabel = speed_axis(sweep)
    omega = np.asarray(sweep.omega, dtype=float) * sx
    direction = np.asarray(sweep.direction).astype(str)
    for j, key in enumerate(keys):
        y = np.asarray(sweep.extra_columns[key], dtype=float)
        who = "" if key == "stick_fraction" else f"{key[: -len('_stick_fraction')]}: "
        for d in ("up", "down"):
            sel = np.nonzero(direction == d)[0]
            if not sel.size:
                continue
            marker, color, _ = DIRECTION_STYLES[d]
            if lines:
                ax.plot(omega[sel], y[sel], "-", color=color, lw=0.8, alpha=0.6)
            ax.plot(omega[sel], y[sel], marker, color=color, ms=4, ls="none", alpha=1.0 if j == 0 else 0.6,
                    label=f"{who}sweep {d}")
    stick_ylim(ax, [np.asarray(sweep.extra_columns[k], dtype=float) for k in keys])
    ax.set_ylabel("stick / period")
    ax.set_xlabel(xlabel)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, ncol=1)


def _draw_sweep(sweep: "SweepResult", ax: Any, y_all: np.ndarray, annotate: bool, lines: bool, legend: bool) -> None:
    """One sweep panel: ``y_all`` vs Ω per direction, period rings and labels."""
    direction = np.asarray(sweep.direction).astype(str)

    sx, xlabel = speed_axis(sweep)  # crankshaft rpm with an engine
    omega = np.asarray(sweep.omega, dtype=float) * sx
    period = np.asarray(sweep.period, dtype=int)
    names = [d for d in ("up", "down") if np.any(direction == d)] + sorted(set(direction) - {"up", "down"})
    for name in names:  # the sweeps first, so that they lead the legend
        marker, color, label = DIRECTION_STYLES.get(name, ("o", "tab:gray", f"sweep {name}"))
        sel = np.nonzero(direction == name)[0]
        if lines:
            ax.plot(omega[sel], y_all[sel], "-", color=color, lw=0.9, alpha=0.7)
        ax.plot(omega[sel], y_all[sel], marker, color=color, ms=4.5, ls="none", label=label)
    for p in sorted(set(period.tolist()) - {1}):  # then a ring colour per period other than 1
        if p < 0:  # a failed row (no steady state): nothing to ring
            continue
        m = period == p
        ax.plot(omega[m], y_all[m], "o", ms=10, mfc="none", mec=PERIOD_COLORS.get(p, "tab:gray"), mew=1.4,
                ls="none", label=period_label(p))
    if annotate:
        for name in names:
            sel = np.nonzero(direction == name)[0]
            om, y, per = omega[sel], y_all[sel], period[sel]
            up = name != "down"
            for i0, i1 in _runs(per):
                if per[i0] == 1 or per[i0] < 0:
                    continue
                j = (i0 + i1 - 1) // 2
                label = ax.annotate(
                    f"P{int(per[i0])}", (om[j], y[j]), xytext=(0, 9 if up else -9),
                    textcoords="offset points", ha="center", va="bottom" if up else "top",
                    fontsize=8, color=PERIOD_COLORS.get(int(per[i0]), "tab:gray"), fontweight="bold",
                )
                label.rattle_move = 1 if up else -1  # away from its points when it overlaps another label
    failed = np.flatnonzero(period < 0)  # failed rows (NaN measures: no point drawn): a dotted line at Ω
    for k, i in enumerate(failed):
        ax.axvline(omega[i], color="0.5", ls=":", lw=0.9, zorder=0,
                   label="no steady state (failed)" if k == 0 else None)
    ax.set_xlabel(xlabel)
    ax.grid(True, alpha=0.3)
    fit_ylim(ax, room=0.06)  # every point inside, a little room for the period labels
    if legend:
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


__all__ = ["sweep_plot", "period_label", "stick_ylim", "DIRECTION_STYLES", "PERIOD_COLORS"]
