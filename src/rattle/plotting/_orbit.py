"""Plot of the periodic orbits at one forcing frequency: time histories, phase portrait, spectrum."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ._axes import PlotAxes

if TYPE_CHECKING:  # pragma: no cover
    from ..results import PeriodicOrbit

#: Most forcing periods drawn (the least common multiple of the periods present, capped).
MAX_WINDOW = 8
#: Least number of forcing periods drawn when the simulation found no period.
NONPERIODIC_WINDOW = 4
#: Highest frequency of the spectrum panel, in multiples of Ω.
SPECTRUM_ORDERS = 6


def window_periods(periods: list[int]) -> int:
    """Forcing periods to draw so that every orbit closes: the lcm of ``periods`` (0s ignored),
    or their maximum when the lcm exceeds :data:`MAX_WINDOW`."""
    ps = [int(p) for p in periods if p and p > 0] or [1]
    lcm = 1
    for p in ps:
        lcm = lcm * p // math.gcd(lcm, p)
    return lcm if lcm <= MAX_WINDOW else max(ps)


def _solution_label(orbit: "PeriodicOrbit", i: int) -> str:
    s = orbit.solutions[i]
    text = f"HB {i}: period {s.period}, {'stable' if s.stable else 'unstable'}, rms {s.rms:.4g}"
    return text + (" (selected)" if i == orbit.selected else "")


def amplitude_spectrum(x: np.ndarray, periods: int, orders: int) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitudes of samples x (one window of ``periods`` forcing periods, endpoint
    excluded) at frequencies k Ω / periods up to ``orders`` Ω: (frequency / Ω, amplitude)."""
    n = x.size
    spec = np.fft.rfft(x) / n
    amp = np.abs(spec)
    amp[1:] *= 2.0
    kmax = min(orders * periods, amp.size - 1)
    k = np.arange(kmax + 1)
    return k / periods, amp[: kmax + 1]


def orbit_plot(
    orbit: "PeriodicOrbit",
    fig: Any = None,
    *,
    samples: int = 256,
    periods: int | None = None,
    title: str | None = None,
    degrees: bool = False,
) -> tuple[Any, PlotAxes]:
    """Draw the HB orbits at one frequency against the simulated steady state.

    Panels: δ(t), δ'(t) and δ''(t) over ``periods`` forcing periods (default: enough for every
    orbit shown to close, at least 4 when the simulation found no period), the phase portrait (δ, δ'), and the amplitude spectrum of δ at the
    harmonics of Ω/period (stems). HB solutions are drawn solid when stable and dashed when
    unstable, the selected one thicker; the simulation as black dots (time histories, phase
    portrait) and hollow circles (spectrum; a line over its whole recorded window when it found
    no period). Breakpoints of the elastic law are dotted lines.

    Parameters
    ----------
    orbit : PeriodicOrbit
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into (default: a new 12 × 8 in figure).
    samples : int, default 256
        Samples per forcing period of each curve.
    periods : int, optional
        Forcing periods drawn.
    title : str, optional
        Figure title (default names Ω and H; an engine case's crankshaft rpm first).
    degrees : bool, default False
        The case gave its angles in degrees: the δ panels and the phase portrait get a second
        axis in degrees (δ · 180/π) beside the one in rad.

    Returns
    -------
    (figure, PlotAxes)
        Panels ``delta`` (the primary), ``velocity``, ``acceleration``, ``phase`` and
        ``spectrum``. A chain: one pair of panels per clearance element NAME, δ and δ'' of its
        deflection (``NAME_delta``, ``NAME_acceleration``; the primary is the first element's
        δ), the phase portrait and the spectrum of the first element; ``delta``, ``velocity``
        and ``acceleration`` are aliases of the first element's panels.
    """
    import matplotlib.pyplot as plt

    system = orbit.model.system() if hasattr(orbit.model, "elements") else None
    if system is None:
        rows = [("delta", "δ (rad)"), ("velocity", "δ' (rad/s)"), ("acceleration", "δ'' (rad/s²)")]
        breakpoints_of = {"delta": np.asarray(orbit.model.elastic.stages.breakpoints, dtype=float)}
    else:
        rows = [r for e in system.elements for r in ((f"{e.name}_delta", f"{e.name}: δ (rad)"),
                                                      (f"{e.name}_acceleration", f"{e.name}: δ'' (rad/s²)"))]
        breakpoints_of = {f"{e.name}_delta": np.asarray(e.breakpoints, dtype=float) for e in system.elements}
    n_rows = max(3 if system is None else 2, len(rows))
    if fig is None:
        fig = plt.figure(figsize=(12, 8 if system is None else max(7.0, 2.2 * n_rows + 2.5)), layout="constrained")
    gs = fig.add_gridspec(n_rows, 2, width_ratios=(1.55, 1.0))
    ax_d = fig.add_subplot(gs[0, 0])
    hist_axes = {rows[0][0]: ax_d}
    for r, (key, _) in enumerate(rows[1:], start=1):
        hist_axes[key] = fig.add_subplot(gs[r, 0], sharex=ax_d)
    ax_p = fig.add_subplot(gs[0 : n_rows - 1, 1])
    ax_s = fig.add_subplot(gs[n_rows - 1, 1])
    aliases: dict[str, Any] = {}
    if system is not None:  # the first element's panels under the single-equation names too
        aliases = {"delta": hist_axes[rows[0][0]], "acceleration": hist_axes[rows[1][0]],
                   "velocity": hist_axes[rows[1][0]]}
    axes = PlotAxes({**hist_axes, "phase": ax_p, "spectrum": ax_s}, aliases=aliases)

    sim_period = orbit.simulated_period
    n_win = periods if periods is not None else window_periods(
        [s.period for s in orbit.solutions] + [orbit.period] + ([sim_period] if sim_period else [])
    )
    if periods is None and orbit.simulation is not None and not sim_period:
        n_win = max(n_win, NONPERIODIC_WINDOW)  # show that the simulated motion does not repeat
    Tf = 2.0 * math.pi / orbit.omega
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    selected = orbit.selected

    # --- HB solutions --------------------------------------------------------------------
    for i, sol in enumerate(orbit.solutions):
        h = orbit.time_history(i, samples=samples, periods=n_win)
        color = colors[i % len(colors)]
        style = "-" if sol.stable else "--"
        lw = 2.2 if i == selected else 1.3
        label = _solution_label(orbit, i)
        for key, ax in hist_axes.items():
            ax.plot(h["t"], h[key], style, color=color, lw=lw, label=label if ax is ax_d else None)
        one = orbit.time_history(i, samples=samples)  # one closed orbit for the phase portrait
        ax_p.plot(one["delta"], one["velocity"], style, color=color, lw=lw, label=label)
        if system is None:
            f = np.arange(sol.harmonics + 1) / sol.period
            amp = sol.amplitudes()
        else:  # the first element's deflection (exact for the truncated series)
            f, amp = amplitude_spectrum(one["delta"][:-1], sol.period, SPECTRUM_ORDERS)
        keep = f <= SPECTRUM_ORDERS + 1e-9
        f, amp = f[keep], amp[keep]
        offset = (i - (len(orbit.solutions) - 1) / 2) * 0.035  # side by side, not on top
        floor = 1e-7
        show = amp > floor
        ax_s.vlines(f[show] + offset, floor, amp[show], color=color, lw=1.6, linestyles=style)
        ax_s.plot(f[show] + offset, amp[show], "o", color=color, ms=4,
                  mfc=color if sol.stable else "white", label=f"HB {i} (period {sol.period})")

    # --- simulation --------------------------------------------------------------------------
    sim = orbit.simulated_history(samples=samples, periods=n_win)
    if sim is not None:
        p = sim_period
        sim_label = "simulation, " + (f"period {p}" if p else "no period ≤ 8")
        step = max(1, samples // 32)
        for key, ax in hist_axes.items():
            ax.plot(sim["t"][::step], sim[key][::step], "o", color="black", ms=2.6,
                    label=sim_label if ax is ax_d else None, zorder=5)
        ax_p.plot(sim["delta"][::step], sim["velocity"][::step], "o", color="black", ms=2.2,
                  label=sim_label, zorder=5)
        if p:
            n_sim = int(round(sim["t"][-1] / Tf))
            f, amp = amplitude_spectrum(sim["delta"][:-1], n_sim, SPECTRUM_ORDERS)
            show = amp > 1e-7 * max(float(np.max(amp)), 1e-300)
            ax_s.plot(f[show], amp[show], "o", mfc="none", mec="black", ms=7, mew=1.2, label=sim_label)
        else:  # not periodic: a continuous spectrum over the whole recorded window, as a line
            whole = orbit.simulated_history(samples=64, periods=10**6)
            if whole is not None:
                n_sim = max(1, int(round(whole["t"][-1] / Tf)))
                f, amp = amplitude_spectrum(whole["delta"][:-1], n_sim, SPECTRUM_ORDERS)
                ax_s.plot(f, np.maximum(amp, 1e-12), "-", color="black", lw=0.8,
                          label=f"{sim_label} ({n_sim} periods)")

    # --- decoration ----------------------------------------------------------------------------
    for key, breakpoints in breakpoints_of.items():
        for k, b in enumerate(breakpoints):
            hist_axes[key].axhline(b, color="0.5", ls=":", lw=0.9, label="breakpoints" if k == 0 and key == rows[0][0] else None)
            if key == rows[0][0]:
                ax_p.axvline(b, color="0.5", ls=":", lw=0.9, label="breakpoints" if k == 0 else None)
    for m in range(1, n_win):
        for ax in hist_axes.values():
            ax.axvline(m * Tf, color="0.8", lw=0.8, zorder=0)
    for key, ylabel in rows:
        hist_axes[key].set_ylabel(ylabel)
    last = hist_axes[rows[-1][0]]
    last.set_xlabel(f"time t (s); grey lines every forcing period 2π/Ω = {Tf:.4g} s")
    ax_d.set_xlim(0.0, n_win * Tf)
    for key, _ in rows[:-1]:
        plt.setp(hist_axes[key].get_xticklabels(), visible=False)
    ax_d.set_title("time histories", fontsize=10)
    who = "" if system is None else f"{system.elements[0].name}: "  # a chain: the first element's
    ax_p.set_xlabel(f"{who}δ (rad)")
    ax_p.set_ylabel(f"{who}δ' (rad/s)")
    ax_p.set_title("phase portrait" + ("" if system is None else f" of {system.elements[0].name}"), fontsize=10)
    ax_s.set_yscale("log")
    ax_s.set_xlabel("frequency / Ω")
    ax_s.set_ylabel(f"{who}amplitude of δ (rad)")
    ax_s.set_title("amplitude spectrum of δ" + ("" if system is None else f" ({system.elements[0].name})"),
                   fontsize=10)
    ax_s.set_xlim(-0.25, SPECTRUM_ORDERS + 0.25)
    ymax = max([float(np.max(s.amplitudes())) for s in orbit.solutions] + [1e-6]) if system is None else max(
        [float(np.max(np.abs(orbit.time_history(i, samples=64)["delta"]))) for i in range(len(orbit.solutions))]
        + [1e-6])
    # the legend sits above the stems: the top of the axis a decade per legend row over the largest
    n_entries = len(ax_s.get_legend_handles_labels()[1])
    ax_s.set_ylim(max(1e-7, ymax * 1e-6), ymax * 3.0 * 10.0 ** (1.0 + 0.9 * math.ceil(n_entries / 2)))
    from matplotlib.ticker import MaxNLocator

    ax_p.xaxis.set_major_locator(MaxNLocator(nbins=6))  # no crowded tick labels on a narrow panel
    if degrees:  # the case's unit beside rad
        for key, _ in rows:
            if key.endswith("delta"):
                hist_axes[key].secondary_yaxis("right", functions=(np.degrees, np.radians)).set_ylabel("(deg)")
        top = ax_p.secondary_xaxis("top", functions=(np.degrees, np.radians))
        top.set_xlabel("δ (deg)", fontsize=9)
        top.xaxis.set_major_locator(MaxNLocator(nbins=6))
    for ax in axes.values():
        ax.grid(True, alpha=0.3)
    # One legend for the curves (they are the same in every panel), above the panels where it
    # hides nothing; the spectrum keeps its own (its markers differ).
    handles, labels = ax_d.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(3, max(1, len(labels))), fontsize=8.5,
               frameon=False)
    ax_s.legend(fontsize=7, loc="upper center", ncol=2, framealpha=0.85)
    if title is None:
        order = getattr(orbit.model, "speed_order", None)
        where = (f"Ω = {orbit.omega:.5g} rad/s" if order is None
                 else f"{orbit.omega * 60.0 / (2.0 * math.pi * float(order)):.5g} rpm (Ω = {orbit.omega:.5g} rad/s)")
        title = f"Periodic orbits at {where} (H = {orbit.harmonics}, period {orbit.period} asked for)"
        if not orbit.solutions:
            title += ": no harmonic-balance solution found"
    fig.suptitle(title)
    return fig, axes


__all__ = ["orbit_plot", "window_periods", "amplitude_spectrum"]
