"""Plot of a comparison: the frequency response with the time-domain sweep over it, and time
histories (HB orbits vs simulation) at a few frequencies."""

from __future__ import annotations

import math
import string
from typing import TYPE_CHECKING, Any

import numpy as np

from ._axes import PlotAxes, fit_ylim, separate_texts
from ._frf import frequency_response_plot
from ._orbit import window_periods
from ._sweep import DIRECTION_STYLES, sweep_plot

if TYPE_CHECKING:  # pragma: no cover
    from ..results import Comparison, MeasuredComparison

#: Labels of the measured-data panels (``compare_plot(..., measured=...)``).
MEASURED_LABELS: dict[str, str] = {
    "acc_p2p": "δ'' peak-to-peak (rad/s²)", "spl_db": "sound pressure level (dB re 20 µPa)",
}


def _steady_history(
    state: Any, omega: float, periods: int, samples: int, shift: int = 0, element: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """(t, δ(t + shift·2π/Ω)) of a SteadyState over ``periods`` forcing periods from t = 0 (its
    trajectory starts at forcing phase 0; a periodic one is repeated, a non-periodic one cut);
    a chain's: the deflection of element ``element``."""
    traj = state.trajectory
    Tf = 2.0 * math.pi / omega
    t = np.linspace(0.0, periods * Tf, samples * periods + 1)
    span = traj.t1 - traj.t0
    if state.period >= 1:
        local = np.mod(t + shift * Tf, state.period * Tf)
    else:
        t = t[t <= span]
        local = t
    local = np.clip(traj.t0 + local, traj.t0, traj.t1)
    s = traj.sample(local)
    if hasattr(s, "deflection"):
        return t, np.asarray(s.deflection[:, element])
    return t, np.asarray(s.delta)


def _align(t: np.ndarray, x: np.ndarray, state: Any, orbit: Any, omega: float, samples: int) -> tuple[np.ndarray, int]:
    """Shift a period-p simulation by the whole number k of forcing periods (0 ≤ k < p) that
    best matches an HB orbit of the same period (a 1/p sub-harmonic has p copies shifted by a
    forcing period: all the same motion). Returns the shifted δ samples and k."""
    p = int(state.period)
    refs = [i for i, s in enumerate(orbit.solutions) if s.period == p]
    if p < 2 or not refs:
        return x, 0
    n_per = int(round(t[-1] * omega / (2.0 * math.pi)))
    ref = orbit.time_history(refs[0], samples=samples, periods=n_per)["delta"]
    if ref.size != x.size:
        return x, 0
    best_k, best = 0, np.inf
    for k in range(p):
        t_k, x_k = _steady_history(state, omega, n_per, samples, shift=k)
        err = float(np.max(np.abs(x_k - ref)))
        if err < best:
            best_k, best, best_x = k, err, x_k
    return best_x, best_k


def compare_plot(
    comparison: "Comparison",
    fig: Any = None,
    *,
    samples: int = 256,
    title: str | None = None,
    measured: "MeasuredComparison | None" = None,
    quantity: str = "rms",
) -> tuple[Any, PlotAxes]:
    """Draw the frequency response (stable solid, unstable dashed) with the up (▲) and down (▼)
    sweep points over it, the examined frequencies marked (a), (b), …, and below it one panel
    per examined frequency: δ(t) of every HB orbit there (solid stable, dashed unstable) and the
    steady states the up and down sweeps reach there (▲/▼ markers).

    Parameters
    ----------
    comparison : Comparison
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into (default: a new 13 × 9 in figure).
    samples : int, default 256
        Samples per forcing period of the time histories.
    title : str, optional
        Figure title (default none: the axes titles say what is shown).
    measured : MeasuredComparison, optional
        Measured points (:func:`rattle.results.compare_measured`): below the frequency-response
        panels, one panel per measured quantity Q (``acc_p2p``, ``spl_db``) with the frequency
        response of Q (stable solid, unstable dashed), the up (▲) and down (▼) sweep points of Q
        (when the sweep carries Q) and the measured points (black ●, joined), over engine rpm
        when the model has an engine.
    quantity : str, default "rms"
        What the frequency-response panels draw (HB lines and sweep points): ``rms``, ``rms_ac``,
        ``p2p``, ``acc_p2p`` (a chain: of each element), or ``spl_db`` (frf and sweep with sound
        paths: the level at the receiver in the first panel, a chain's other elements keep their
        rms). The time histories are δ(t) whatever the quantity. A discontinuous law's
        comparison draws rms only.

    Returns
    -------
    (figure, PlotAxes)
        Panels ``frf`` (the top axes, the primary) and ``history_a``, ``history_b``, … (one per
        examined frequency, lettered as in the figure); the alias ``histories`` is the list of
        the history panels; with ``measured`` also ``measured_Q`` per measured quantity Q. A chain: one frequency-response panel and one row of time
        histories per clearance element NAME (``NAME_frf``, ``NAME_history_a``, …; the primary
        is the first element's ``NAME_frf``); the aliases ``frf`` and ``histories`` are the
        first element's, ``frf_panels`` (list) and ``element_histories`` (element name → list
        of panels) all of them.
    """
    import matplotlib.pyplot as plt

    from ._frf import LABEL_ROOM, _draw_panel, speed_axis
    from ._sweep import _draw_sweep

    if getattr(comparison, "discontinuous", False):
        if measured is not None:
            raise ValueError("`measured` is not supported for a discontinuous law's comparison")
        if quantity != "rms":
            raise ValueError(f"`quantity` {quantity!r}: a discontinuous law's comparison draws the exact rms only")
        return _discontinuous_plot(comparison, fig, title)
    from ._frf import QUANTITY_LABELS

    if quantity not in ("rms", "rms_ac", "p2p", "acc_p2p", "spl_db"):
        raise ValueError(f"`quantity` must be one of rms, rms_ac, p2p, acc_p2p, spl_db, got {quantity!r}")
    frf, sweep = comparison.frf, comparison.sweep
    names = tuple(getattr(sweep, "element_names", ()) or ())
    m = max(1, len(names))
    n = len(comparison.at)
    quantities = tuple(measured.measured.quantities) if measured is not None else ()
    q = len(quantities)
    if fig is None:
        fig = plt.figure(figsize=(13, ((9 if n else 6) if m == 1 else 2.6 + 3.4 * m * (2 if n else 1)) + 3.6 * q),
                         layout="constrained")
    if n:
        gs = fig.add_gridspec(2 * m + q, n, height_ratios=(1.5,) * m + (1.2,) * q + (1.0,) * m)
        frf_axes = [fig.add_subplot(gs[k, :]) for k in range(m)]
        measured_axes = [fig.add_subplot(gs[m + k, :]) for k in range(q)]
        rows = [[fig.add_subplot(gs[m + q + k, j]) for j in range(n)] for k in range(m)]
    else:
        gs = fig.add_gridspec(m + q, 1)
        frf_axes = [fig.add_subplot(gs[k, 0]) for k in range(m)]
        measured_axes = [fig.add_subplot(gs[m + k, 0]) for k in range(q)]
        rows = [[] for _ in range(m)]
    ax_frf = frf_axes[0]
    for measured_q, ax_q in zip(quantities, measured_axes):
        _draw_measured(measured, measured_q, ax_q)  # type: ignore[arg-type]

    if not names:
        frequency_response_plot(frf, ax=ax_frf, quantity=quantity, linear=False, title="")
        sweep_plot(sweep, ax=ax_frf, quantity=quantity, lines=False, title="")
    else:
        for k, (name, ax_k) in enumerate(zip(names, frf_axes)):
            if k == 0 and quantity == "spl_db":  # the level at the receiver (the whole chain's)
                frequency_response_plot(frf, ax=ax_k, quantity=quantity, linear=False, title="", legend="none")
                sweep_plot(sweep, ax=ax_k, quantity=quantity, lines=False, title="")
                continue
            q_k = "rms" if quantity == "spl_db" else quantity
            _draw_panel(frf, ax_k, f"{name}_{q_k}", q_k, False, True, frf.regions, "none", element=k,
                        label=f"{name}: ")
            _draw_sweep(sweep, ax_k, np.asarray(sweep.element_columns[f"{name}_{q_k}"], dtype=float), True, False,
                        legend=False)
            ax_k.set_ylabel(f"{name}: {QUANTITY_LABELS[q_k]}")
    letters = string.ascii_lowercase
    sx = speed_axis(frf)[0]  # crankshaft rpm with an engine
    for ax_k in [*frf_axes, *measured_axes]:
        for j, w in enumerate(comparison.at):
            ax_k.axvline(w * sx, color="0.35", lw=0.9, ls="-.", zorder=0)
            lo_x, hi_x = ax_k.get_xlim()
            right = w * sx > lo_x + 0.93 * (hi_x - lo_x)  # near the right edge: the letter left of its line
            letter = ax_k.annotate(f"({letters[j % 26]})", (w * sx, 1.0), xycoords=("data", "axes fraction"),
                                   xytext=(-3 if right else 3, -3), textcoords="offset points", fontsize=10,
                                   fontweight="bold", ha="right" if right else "left", va="top")
            letter.rattle_move = 0  # stays; the band labels move out of its way
    ax_frf.set_title(
        f"Harmonic balance (H = {frf.harmonics}, lines) against the time-domain sweep "
        f"({int(np.sum(sweep.direction == 'up'))} frequencies per direction, markers)"
        + (f" — element {names[0]}" if names else ""), fontsize=10.5)
    for k, name in enumerate(names[1:], start=1):
        frf_axes[k].set_title(f"element {name}", fontsize=10)
    for ax_k in frf_axes:  # every sweep point inside the axes, room for the band labels
        fit_ylim(ax_k, room=LABEL_ROOM)
    # the legend beside the panel, never over the data
    ax_frf.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, framealpha=0.9)

    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for e in range(m):
        key = f"{names[e]}_delta" if names else "delta"
        for j, (ax, w, why, orbit, sims) in enumerate(
            zip(rows[e], comparison.at, comparison.reasons, comparison.orbits, comparison.simulations)
        ):
            n_win = window_periods([s.period for s in orbit.solutions] + [s.period for s in sims.values()])
            Tf = 2.0 * math.pi / w
            for i, sol in enumerate(orbit.solutions):
                h = orbit.time_history(i, samples=samples, periods=n_win)
                rms = sol.elements[names[e]]["rms"] if names else sol.rms
                ax.plot(h["t"], h[key], "-" if sol.stable else "--", color=colors[i % len(colors)],
                        lw=1.8 if sol.stable else 1.2,
                        label=f"HB P{sol.period} {'stable' if sol.stable else 'unstable'} (rms {rms:.3g})")
            step = max(1, samples // 24)
            for d, state in sims.items():
                marker, color, _ = DIRECTION_STYLES.get(d, ("o", "black", d))
                t, x = _steady_history(state, w, n_win, samples)
                x, k = _align(t, x, state, orbit, w, samples)
                if e:
                    t, x = _steady_history(state, w, n_win, samples, shift=k, element=e)
                per = f"P{state.period}" if state.period else "no period ≤ 8"
                moved = f", shifted {k}·2π/Ω" if k else ""
                rms = float(state.element_measures.rms[e]) if names else state.rms
                ax.plot(t[::step], x[::step], marker, color=color, mec="black", mew=0.4, ms=5, ls="none",
                        label=f"{d} sweep: {per} (rms {rms:.3g}{moved})", zorder=5)
            for mm in range(1, n_win):
                ax.axvline(mm * Tf, color="0.85", lw=0.8, zorder=0)
            ax.set_xlim(0.0, n_win * Tf)
            if e == 0:
                rpm = f" ({w * sx:.5g} rpm)" if sx != 1.0 else ""
                ax.set_title(f"({letters[j % 26]}) Ω = {w:.4g} rad/s{rpm}: {why}", fontsize=10)
            ax.set_xlabel("time t (s)")
            if j == 0:
                ax.set_ylabel(f"{names[e]}: δ (rad)" if names else "δ (rad)")
            ax.grid(True, alpha=0.3)
            fit_ylim(ax, room=0.35)  # room for the legend above the curves
            ax.legend(fontsize=7, loc="upper center", ncols=2, framealpha=0.85)
    if title is not None:
        fig.suptitle(title)
    separate_texts(fig, [*frf_axes, *measured_axes])
    tags = [f"history_{letters[j]}" if j < 26 else f"history_{j}" for j in range(n)]
    extra = {f"measured_{measured_q}": ax_q for measured_q, ax_q in zip(quantities, measured_axes)}
    if not names:
        return fig, PlotAxes({"frf": ax_frf, **extra, **dict(zip(tags, rows[0]))}, aliases={"histories": rows[0]})
    panels: dict[str, Any] = {f"{name}_frf": ax_k for name, ax_k in zip(names, frf_axes)}
    panels.update(extra)
    for name, row in zip(names, rows):
        panels.update({f"{name}_{tag}": ax for tag, ax in zip(tags, row)})
    aliases = {"frf": ax_frf, "histories": rows[0], "frf_panels": frf_axes,
               "element_histories": dict(zip(names, rows))}
    return fig, PlotAxes(panels, aliases=aliases)


def _discontinuous_plot(comparison: "Comparison", fig: Any, title: str | None) -> tuple[Any, PlotAxes]:
    """A discontinuous law's comparison: per element (the single equation: δ) the response's exact
    rms (solid where stable, dotted where not; rows not matched left out), the regularised HB's
    dashed, and the up (▲) and down (▼) sweep points over them; below, the stick fraction of the
    response's rows (line) and of the sweep's (markers)."""
    import matplotlib.pyplot as plt

    from ._axes import stick_ylim
    from ._sweep import _draw_sweep

    frf, sweep = comparison.frf.check, comparison.sweep  # the exact-check group: HB and exact side by side
    names = tuple(getattr(frf, "element_names", ()) or ())
    m = max(1, len(names))
    if fig is None:
        fig = plt.figure(figsize=(10, 3.2 + 3.4 * m), layout="constrained")
    gs = fig.add_gridspec(m + 1, 1, height_ratios=(3.0,) * m + (1.2,))
    axes = [fig.add_subplot(gs[k, 0]) for k in range(m)]
    ax_s = fig.add_subplot(gs[m, 0], sharex=axes[0])
    w = np.asarray(frf.omega, dtype=float)
    matched = np.asarray(frf.matched, dtype=bool)
    stable = np.asarray(frf.stable, dtype=bool)
    rms = np.asarray(frf.rms, dtype=float).reshape(len(w), -1)
    rms_hb = np.asarray(frf.rms_hb, dtype=float).reshape(len(w), -1)
    if names:
        held = np.asarray(frf.stick_fraction, dtype=float).reshape(len(w), -1)
        sweep_held = [sweep.extra_columns.get(f"{nm}_stick_fraction") for nm in names]
    else:
        held = (np.asarray(frf.stick_time, dtype=float) * w / (2.0 * math.pi)).reshape(-1, 1)
        sweep_held = [sweep.extra_columns.get("stick_fraction")]
    for k, ax in enumerate(axes):
        ax.plot(w, rms_hb[:, k], "--", color="0.55", lw=0.9,
                label=f"regularised HB (H = {frf.harmonics}, ε = {frf.regularisation:g})")
        ax.plot(w, np.where(matched & stable, rms[:, k], np.nan), "-", color="tab:green", lw=1.6,
                label="exact orbit, stable")
        if np.any(matched & ~stable):
            ax.plot(w, np.where(matched & ~stable, rms[:, k], np.nan), ":", color="tab:green", lw=1.3,
                    label="exact orbit, unstable")
        y = np.asarray(sweep.element_columns[f"{names[k]}_rms"] if names else sweep.rms, dtype=float)
        _draw_sweep(sweep, ax, y, True, False, legend=False)
        ax.set_ylabel(f"{names[k]}: δ rms (rad)" if names else "δ rms (rad)")
        ax.set_xlabel("")
        fit_ylim(ax)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, framealpha=0.9)
        if k:
            ax.set_title(f"element {names[k]}", fontsize=10)
    ag = comparison.agreement()
    text = (f"sweep against response: {ag['compared']} of {ag['rows']} settled period-1 rows compared, median "
            f"relative rms difference {ag['median']:.2g}" if ag["compared"] else
            f"sweep against response: none of {ag['rows']} settled period-1 rows on a stable matched stretch")
    axes[0].set_title(
        "Response (exact orbits, regularised HB) against the exact sweep "
        f"({int(np.sum(sweep.direction == 'up'))} Ω per direction)"
        + (f" — element {names[0]}" if names else "") + f"\n{text}", fontsize=10)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    direction = np.asarray(sweep.direction).astype(str)
    for k in range(m):
        c = colours[k % len(colours)]
        label = f"{names[k]}: " if names else ""
        ax_s.plot(w, np.where(matched, held[:, k], np.nan), "-", color=c, lw=1.2, label=f"{label}response")
        if sweep_held[k] is not None:
            for d in ("up", "down"):
                sel = direction == d
                if np.any(sel):
                    marker, _, _ = DIRECTION_STYLES[d]
                    ax_s.plot(np.asarray(sweep.omega)[sel], np.asarray(sweep_held[k])[sel], marker, color=c, ms=4,
                              ls="none", label=f"{label}sweep {d}")
    stick_ylim(ax_s, [np.where(matched, held[:, k], np.nan) for k in range(m)]
               + [v for v in sweep_held if v is not None])
    ax_s.set_ylabel("stick / period")
    ax_s.set_xlabel("Ω (rad/s)")
    ax_s.grid(True, alpha=0.3)
    ax_s.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    if title is not None:
        fig.suptitle(title)
    if names:
        panels = {f"{name}_frf": ax for name, ax in zip(names, axes)}
        panels["stick"] = ax_s
        return fig, PlotAxes(panels, aliases={"frf": axes[0], "histories": [], "frf_panels": axes})
    return fig, PlotAxes({"frf": axes[0], "stick": ax_s}, aliases={"histories": []})


def _draw_measured(measured: "MeasuredComparison", quantity: str, ax: Any) -> None:
    """One measured-data panel: the frequency response of ``quantity`` (stable solid, unstable
    dashed), the sweep points of it (when the sweep carries it) and the measured points."""
    from ._frf import draw_branches, speed_axis
    from ._sweep import _draw_sweep

    frf, sweep = measured.frf, measured.sweep
    sx, xlabel = speed_axis(frf)
    draw_branches(frf, ax, quantity, lw=1.3)
    y_sweep = sweep.columns().get(quantity)
    if y_sweep is not None:
        _draw_sweep(sweep, ax, np.asarray(y_sweep, dtype=float), False, False, legend=False)
    run = measured.measured
    ax.plot(run.omega * sx, run.values[quantity], "o-", color="black", mfc="black", ms=4.5, lw=1.0,
            label="measured" if run.source == "measured" else f"measured ({run.source})", zorder=6)
    names = tuple(getattr(frf, "element_names", ()) or ())
    label = MEASURED_LABELS.get(quantity, quantity)
    ax.set_ylabel(f"{names[0]}: {label}" if names and quantity == "acc_p2p" else label)
    ax.set_xlabel(xlabel)
    gaps = [c.replace("_", " ") for (qq, c) in measured.missing if qq == quantity]
    ax.set_title(f"measured {quantity} against the computed" + (f" (no {', '.join(gaps)})" if gaps else ""),
                 fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best", framealpha=0.9)


__all__ = ["compare_plot", "MEASURED_LABELS"]
