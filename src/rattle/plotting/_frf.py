"""Plot of a frequency response: a measure vs Ω along every branch, stable solid, unstable
dashed, special points marked by type, the named regions shaded and labelled."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ._axes import PlotAxes, fit_ylim, separate_texts, speed_axis, unwrap

if TYPE_CHECKING:  # pragma: no cover
    from ..results import FrequencyResponse, Region

#: Marker, colour and legend text of each kind of special point.
SPECIAL_POINT_STYLES: dict[str, tuple[str, str, str]] = {
    "fold": ("o", "tab:red", "fold ○"),
    "period_doubling": ("s", "tab:purple", "period doubling □"),
    "neimark_sacker": ("D", "tab:green", "Neimark–Sacker ◇"),
}
_MARKERS = {kind: (m, c) for kind, (m, c, _) in SPECIAL_POINT_STYLES.items()}  # kept for older callers
#: The response measures that can be drawn, with their axis labels.
QUANTITY_LABELS: dict[str, str] = {
    "mean": "δ mean δ_m (rad)", "rms": "δ rms (rad)", "rms_ac": "δ rms about the mean (rad)",
    "p2p": "δ peak-to-peak (rad)", "acc_p2p": "δ'' peak-to-peak (rad/s²)",
    "delta_min": "δ min (rad)", "delta_max": "δ max (rad)",
    "spl_db": "sound pressure level (dB re 20 µPa)",
}
_LEGEND_PLACES = ("outside", "inside", "none")
#: A sub-harmonic branch narrower than this fraction of the Ω range is drawn over the markers and named.
SHORT_BRANCH = 0.04
#: Room above the data (a fraction of its span) for the band labels at the top of a panel.
LABEL_ROOM = 0.12
#: Face colour of a ``no_stable_periodic`` band (hatched).
NO_STABLE_COLOR = "0.6"
#: How each kind of interval without a stable computed orbit is drawn: (hatch, edge colour,
#: legend text, short text on the band). Only ``no_stable_periodic`` (sub-harmonics computed
#: and a simulation found no period ≤ 8) says "no stable periodic solution".
UNSTABLE_REGION_STYLES: dict[str, tuple[str, str, str, str]] = {
    "unstable_period_doubling": ("\\\\", "tab:purple",
                                 "period 1 unstable (period doubling):\nperiod 2 likely, not computed", "period 2\nlikely"),
    "unstable_not_computed": ("..", "0.5", "no stable period-1 orbit;\nsub-harmonics not computed", "P1\nunstable"),
    "no_stable_computed": ("xx", "0.5", "no stable orbit computed\n(sub-harmonics included)", "none\nstable"),
    "no_stable_periodic": ("//", NO_STABLE_COLOR, "no stable periodic solution", "no stable\nperiodic"),
}
#: (band colour, label colour) of the stable sub-harmonic bands, by period.
SUBHARMONIC_COLORS: dict[int, tuple[str, str]] = {
    2: ("#f5c342", "#8a6100"), 3: ("#9ad39a", "#2e6b2e"), 4: ("#c9a3e0", "#5b2d7a"),
}


#: An element's column suffix for each drawable quantity (SPEC §5: NAME_min, NAME_max).
_ELEMENT_SUFFIX = {"delta_min": "min", "delta_max": "max"}


def column(frf: "FrequencyResponse", quantity: str) -> np.ndarray:
    """The values of ``quantity``: a SPEC column (``rms``) or an element's (``clutch_rms``)."""
    cols = {**(getattr(frf, "element_columns", {}) or {}), **(getattr(frf, "extra_columns", {}) or {})}
    if quantity in cols:
        return np.asarray(cols[quantity], dtype=float)
    return np.asarray(getattr(frf, quantity), dtype=float)


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs of consecutive True values, stop exclusive."""
    edges = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    return list(zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]))


def branch_colors(frf: "FrequencyResponse") -> dict[int, str]:
    """Colour of each branch (matplotlib's default cycle, in branch order)."""
    import matplotlib.pyplot as plt

    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    return {int(b): cycle[n % len(cycle)] for n, b in enumerate(np.unique(frf.branch))}


def branch_label(frf: "FrequencyResponse", branch: int) -> str:
    """``branch b`` with ``(period p)`` for a sub-harmonic branch."""
    period = int(frf.period[frf.branch == branch][0])
    return f"branch {branch}" + (f" (period {period})" if period > 1 else "")


def _harmonics_text(frf: "FrequencyResponse") -> str:
    """``H = 32``, or ``H = 32–128`` where H adapted along the branches (the rows' ``harmonics``)."""
    text = getattr(frf, "harmonics_text", None)
    if callable(text):
        return f"H = {text()}"
    h = frf.settings.get("harmonics", frf.harmonics) if isinstance(frf.settings, dict) else frf.harmonics
    return f"H = {h}"


def draw_uncovered(frf: "FrequencyResponse", ax: Any) -> None:
    """Shade the parts of the range no branch covers (``frf.uncovered``), labelled ``not covered``."""
    gaps = getattr(frf, "uncovered", None) or []
    scale = speed_axis(frf)[0]
    for k, (a, b) in enumerate(gaps):
        ax.axvspan(a * scale, b * scale, color="0.85", zorder=0, label="not covered (no branch found)" if k == 0 else None)


def draw_branches(
    frf: "FrequencyResponse", ax: Any, quantity: str, *, labels: bool = True, lw: float = 1.5,
    name_short: bool = False,
) -> dict[int, str]:
    """Every branch of ``frf`` in its colour, stable solid and unstable dashed; returns the colours.

    A sub-harmonic branch narrower than :data:`SHORT_BRANCH` of the Ω range is drawn thicker and
    above the special points' markers (which would hide it), and with ``name_short`` named beside
    it (an annotation below, in its colour)."""
    y_all = column(frf, quantity)
    colors = branch_colors(frf)
    x_all = np.asarray(frf.omega, dtype=float) * speed_axis(frf)[0]
    width = float(np.ptp(x_all)) if x_all.size else 0.0
    for b, color in colors.items():
        sel = np.nonzero(frf.branch == b)[0]
        om, y, st = x_all[sel], y_all[sel], np.asarray(frf.stable[sel], dtype=bool)
        base = branch_label(frf, b)
        short = b != min(colors) and om.size > 1 and float(np.ptp(om)) < SHORT_BRANCH * width
        if short and name_short:  # a short branch: named beside it (its markers would hide it)
            mid = int(np.argmin(np.abs(om - 0.5 * (om.min() + om.max()))))
            note = ax.annotate(base, (om[mid], y[mid]), xytext=(0, -26), textcoords="offset points", ha="center",
                               va="top", fontsize=7.5, color=color, zorder=7,
                               arrowprops={"arrowstyle": "-", "color": color, "lw": 0.8, "shrinkA": 0, "shrinkB": 2})
            note.rattle_move = -1
        for flag, style in ((True, "-"), (False, "--")):
            first = True
            for i0, i1 in true_runs(st == flag):
                # Extend each run by one point so that solid and dashed pieces join.
                j1 = min(i1 + 1, sel.size)
                lab = None
                if labels and first:
                    lab = f"{base}, {'stable' if flag else 'unstable'}"
                    first = False
                ax.plot(om[i0:j1], y[i0:j1], style, color=color, lw=(1.8 if short else 1.0) * (lw if flag else 0.8 * lw),
                        label=lab, zorder=(6 if short else 3) if flag else (6 if short else 2))
    return colors


def draw_special_points(frf: "FrequencyResponse", ax: Any, quantity: str, *, labels: bool = True) -> None:
    """Special points (stability changes) marked by type: fold ○, period doubling □, Neimark–Sacker ◇.

    The first row of a period-doubled branch (where it is born) is a period-doubling row too, so
    each period-doubling point shows on both the parent and the new branch (at the same place).
    """
    y_all = column(frf, quantity)
    rows: dict[str, list[int]] = {}
    for sp in frf.special_points:
        rows.setdefault(sp.kind, []).append(int(sp.index))
    for kind, idx in rows.items():
        marker, color, text = SPECIAL_POINT_STYLES.get(kind, ("X", "black", kind.replace("_", " ")))
        ax.plot(np.asarray(frf.omega, dtype=float)[idx] * speed_axis(frf)[0], y_all[idx], marker, color=color, ms=6.5, mfc="none", mew=1.5, ls="none",
                label=text if labels else None, zorder=5)


def _resonance_rows(frf: "FrequencyResponse", omega: float) -> int | None:
    """Row of a period-1 branch at ``omega`` (a super-harmonic peak is a row's Ω); None if none."""
    p1 = np.nonzero(frf.period == 1)[0]
    if p1.size == 0:
        return None
    d = np.abs(frf.omega[p1] - omega)
    return int(p1[int(np.argmin(d))])


def draw_regions(
    frf: "FrequencyResponse",
    ax: Any,
    quantity: str,
    regions: Sequence["Region"],
    colors: dict[int, str],
    *,
    labels: bool = True,
) -> None:
    """Shade and label the named regions.

    ``subharmonic``: a light band (a colour per period), labelled "period p" at the top of the
    axes; an interval without a stable computed orbit: a hatched band whose hatch and legend
    say what is known (:data:`UNSTABLE_REGION_STYLES`; "no stable periodic solution" only for
    ``no_stable_periodic``); ``superharmonic``: a small "1/k" label just above the resonance peak.
    """
    from matplotlib.transforms import blended_transform_factory

    top = blended_transform_factory(ax.transData, ax.transAxes)
    y_all = column(frf, quantity)
    sx = speed_axis(frf)[0]  # x in rpm with an engine
    seen: set[str] = set()
    peaks: list[tuple[int, str]] = []
    for r in regions:
        if r.kind == "subharmonic":
            period = int(r.detail.get("period", 2))
            band, text_color = SUBHARMONIC_COLORS.get(period, ("#bbbbbb", "0.25"))
            key = f"sub{period}"
            ax.axvspan(sx * r.omega_min, sx * r.omega_max, color=band, alpha=0.22, lw=0, zorder=0,
                       label=f"period {period} stable (1/{period} sub-harmonic)" if labels and key not in seen else None)
            seen.add(key)
            joined = _joined_bands(regions, period)  # bands of one period that touch: one label
            if r is not next(g[0] for g in joined if r in g):
                continue
            group = next(g for g in joined if r in g)
            x_mid = 0.5 * sx * (min(g.omega_min for g in group) + max(g.omega_max for g in group))
            _band_label(ax, x_mid, 0.985, f"period {period}", top,
                        fontsize=8, color=text_color, fontweight="bold")
        elif r.kind in UNSTABLE_REGION_STYLES:
            hatch, edge, legend_text, short = UNSTABLE_REGION_STYLES[r.kind]
            sim = [int(p) for p in r.detail.get("sweep_periods", []) or []]
            if sim and r.kind != "no_stable_periodic":  # what the simulation saw replaces the guess
                seen_text = ", ".join(f"period {p}" if p else "no period ≤ 8" for p in sim)
                legend_text = legend_text.split(":")[0].split(";")[0] + f":\nsimulation: {seen_text}"
            ax.axvspan(sx * r.omega_min, sx * r.omega_max, facecolor="none", edgecolor=edge, hatch=hatch, lw=0,
                       zorder=0, label=legend_text if labels and legend_text not in seen else None)
            seen.add(legend_text)
            if r.kind == "unstable_period_doubling":
                short = f"period {2 * int(r.detail.get('period', 1))}\nlikely"
            if sim and r.kind != "no_stable_periodic":
                short = "sim: " + ",".join(f"P{p}" if p else "none" for p in sim)
            _band_label(ax, 0.5 * sx * (r.omega_min + r.omega_max), 0.985, short, top, fontsize=7, color="0.25")
        elif r.kind == "torus":
            sim = r.detail.get("simulated_periods")
            text = ("quasi-periodic (Neimark–Sacker)" if sim is None else
                    "Neimark–Sacker interval, simulation: " + ", ".join(f"period {p}" if p else "quasi-periodic" for p in sim))
            ax.axvspan(sx * r.omega_min, sx * r.omega_max, facecolor="tab:green", alpha=0.12, edgecolor="tab:green", lw=0.8,
                       zorder=0, label=text if labels and text not in seen else None)
            seen.add(text)
            short = "torus" if sim is None else ("sim: " + ",".join(f"P{p}" if p else "QP" for p in sim))
            _band_label(ax, 0.5 * sx * (r.omega_min + r.omega_max), 0.985, short, top, fontsize=7, color="tab:green")
        elif r.kind == "superharmonic":
            i = _resonance_rows(frf, r.omega_min)
            if i is not None:
                order = r.detail.get("order")
                peaks.append((i, f"1/{order}" if order else r.label))
    # "1/k" labels above the peaks; neighbours closer than 3 % of the Ω axis are staggered upwards
    # so that the labels do not overlap.
    lo, hi = ax.get_xlim()
    level, last = 0, -np.inf
    for i, text in sorted(peaks, key=lambda p: frf.omega[p[0]]):
        w = float(frf.omega[i]) * sx
        level = level + 1 if w - last < 0.03 * (hi - lo) else 0
        last = w
        label = ax.annotate(text, (w, y_all[i]), xytext=(0, 9 + 11 * (level % 3)), textcoords="offset points",
                            ha="center", va="bottom", fontsize=8, color="0.15", zorder=6,
                            arrowprops={"arrowstyle": "-", "color": "0.4", "lw": 0.6, "shrinkA": 0, "shrinkB": 1})
        label.rattle_move = 1  # moved up, away from its peak, when it overlaps another label


def _joined_bands(regions: Sequence["Region"], period: int) -> list[list["Region"]]:
    """The ``subharmonic`` regions of ``period`` in groups whose Ω intervals touch or overlap."""
    bands = sorted((r for r in regions if r.kind == "subharmonic" and int(r.detail.get("period", 2)) == period),
                   key=lambda r: r.omega_min)
    groups: list[list[Any]] = []
    for r in bands:
        if groups and r.omega_min <= max(g.omega_max for g in groups[-1]) * (1.0 + 1e-9):
            groups[-1].append(r)
        else:
            groups.append([r])
    return groups


def _band_label(ax: Any, x: float, y: float, text: str, transform: Any, **style: Any) -> Any:
    """A band's label at ``x`` (data) and ``y`` (axes fraction), hanging from there; an annotation
    with an offset in points, so that :func:`rattle.plotting.separate_texts` can move it down out of
    another's way."""
    label = ax.annotate(text, (x, y), xycoords=transform, xytext=(0, 0), textcoords="offset points", ha="center",
                        va="top", bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85},
                        zorder=6, annotation_clip=False, **style)
    label.rattle_move = -1
    return label


def place_legend(ax: Any, legend: str, fontsize: float = 8) -> Any:
    """``outside``: to the right of the axes; ``inside``: best place; ``none``: no legend."""
    if legend == "none":
        return None
    if legend == "outside":
        return ax.legend(fontsize=fontsize, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                         framealpha=0.9)
    return ax.legend(fontsize=fontsize, loc="best", framealpha=0.9)


def frequency_response_plot(
    frf: "FrequencyResponse",
    ax: Any = None,
    *,
    quantity: str = "rms",
    linear: bool = True,
    special_points: bool = True,
    regions: "bool | Sequence[Region]" = True,
    legend: str = "outside",
    title: str | None = None,
) -> tuple[Any, PlotAxes]:
    """Draw ``quantity`` (a SPEC column, default rms) vs Ω along every branch.

    Each branch has its colour (its period in the legend), stable stretches solid and unstable
    ones dashed. Special points are marked by type (fold ○, period doubling □, Neimark–Sacker
    ◇). The regions are shaded: a stable sub-harmonic as a light band labelled "period p", an
    interval without a stable computed orbit as a hatched band (hatch and legend say what is
    known: a period doubling with sub-harmonics not computed, none stable with sub-harmonics
    computed, no periodic motion in the simulation either), and each super-harmonic
    resonance gets a small "1/k" label at its peak. The linear system's response (f = δ) is
    overlaid in grey.

    Parameters
    ----------
    frf : FrequencyResponse
    ax : matplotlib.axes.Axes or PlotAxes, optional
        Axes to draw into (default: a new 9.5 × 5 in figure; a :class:`PlotAxes`: its primary).
    quantity : str, default "rms"
        One of ``mean``, ``rms``, ``rms_ac``, ``p2p``, ``acc_p2p``, ``delta_min``, ``delta_max``, or
        ``spl_db`` (a response with sound paths: the level at the receiver, one panel).
    linear : bool, default True
        Overlay the linear system (drawn only for ``mean``, ``rms`` and ``rms_ac``).
    special_points : bool, default True
        Mark the special points.
    regions : bool or sequence of Region, default True
        Shade ``frf.regions`` (True), none (False), or the given regions (e.g. those returned by
        :func:`rattle.analysis.confirm_with_sweep`).
    legend : {"outside", "inside", "none"}, default "outside"
        Where the legend goes.
    title : str, optional
        Axes title (default names H).

    Returns
    -------
    (figure, PlotAxes)
        One panel ``response`` (the given ``ax`` when there is one). A chain drawn without
        ``ax``: one panel per clearance element, keyed by its name, sharing Ω; the primary is
        the first element's. A law with jumps or friction (``frf.check`` set): the panels of its
        exact-check group — :func:`nonsmooth_response_plot` (one equation: ``rms``, ``stick``)
        or :func:`friction_response_plot` (a chain: per element, and the stick fractions); the
        options above apply to the harmonic-balance plot only and must be left at their defaults.
    """
    import matplotlib.pyplot as plt

    if getattr(frf, "check", None) is not None:  # the panels follow from the columns the result has
        if ax is not None or (quantity, linear, special_points, regions, legend, title) != (
                "rms", True, True, True, "outside", None):
            raise TypeError("`ax`, `quantity`, `linear`, `special_points`, `regions`, `legend` and `title` apply to "
                            "the harmonic-balance plot; a law with jumps or friction draws its exact-check panels: "
                            "leave them at their defaults")
        from ._friction import friction_response_plot
        from ._nonsmooth import nonsmooth_response_plot

        draw = friction_response_plot if hasattr(frf.check, "element_names") else nonsmooth_response_plot
        return draw(frf.check)
    ax = unwrap(ax)
    if quantity not in QUANTITY_LABELS:
        raise ValueError(f"`quantity` must be a numeric SPEC column ({', '.join(QUANTITY_LABELS)}), got {quantity!r}")
    if legend not in _LEGEND_PLACES:
        raise ValueError(f"`legend` must be one of {', '.join(_LEGEND_PLACES)}, got {legend!r}")
    if isinstance(regions, bool):
        shown: Sequence[Any] = frf.regions if regions else ()
    else:
        shown = tuple(regions)
    names = tuple(getattr(frf, "element_names", ()) or ())
    sound = ax is None and "spl_db" in (getattr(frf, "extra_columns", {}) or {})  # [[paths]]: an SPL panel below
    if quantity == "spl_db":  # the level at the receiver: one panel, the whole chain's
        if "spl_db" not in (getattr(frf, "extra_columns", {}) or {}):
            raise ValueError("`quantity` \"spl_db\" needs a response with sound paths (frf.with_sound(paths)); "
                             "this one has no spl_db column")
        names, sound = (), False
    if names and ax is None:  # a chain: one panel per element, sharing Ω
        fig, axes = plt.subplots(len(names) + sound, 1, figsize=(9.5, 2.2 + 2.6 * (len(names) + sound)), sharex=True,
                                 layout="constrained", squeeze=False)
        for k, (name, ax_k) in enumerate(zip(names, axes[:, 0])):
            key = f"{name}_{_ELEMENT_SUFFIX.get(quantity, quantity)}"
            _draw_panel(frf, ax_k, key, quantity, linear, special_points, shown, legend if k == 0 else "none",
                        element=k, label=f"{name}: ")
            first = title if title is not None else f"Non-linear frequency response ({_harmonics_text(frf)})"
            ax_k.set_title(f"{first} — element {name}" if k == 0 else f"element {name}", fontsize=10)
            if k < len(names) - 1 or sound:
                ax_k.set_xlabel("")
        if sound:
            _draw_sound_panel(frf, axes[-1, 0], special_points)
        separate_texts(fig, axes[:, 0])
        if sound:
            return fig, PlotAxes([*zip(names, axes[:-1, 0]), ("spl_db", axes[-1, 0])])
        return fig, PlotAxes(zip(names, axes[:, 0]))
    own = ax is None  # a figure of its own: its labels are separated here (else by the caller)
    if ax is None and sound:
        fig, (ax, ax_spl) = plt.subplots(2, 1, figsize=(9.5, 7.6), sharex=True, layout="constrained")
    elif ax is None:
        fig, ax = plt.subplots(figsize=(9.5, 5), layout="constrained")
    else:
        fig = ax.figure
    _draw_panel(frf, ax, quantity, quantity, linear, special_points, shown, legend)
    ax.set_title(title if title is not None else f"Non-linear frequency response ({_harmonics_text(frf)})")
    if sound:
        ax.set_xlabel("")
        _draw_sound_panel(frf, ax_spl, special_points)
        separate_texts(fig, (ax, ax_spl))
        return fig, PlotAxes([("response", ax), ("spl_db", ax_spl)])
    if own:
        separate_texts(fig, (ax,))
    return fig, PlotAxes.single(ax)


def _draw_sound_panel(frf: "FrequencyResponse", ax: Any, special_points: bool) -> None:
    """The sound pressure level ``spl_db`` at the receiver (``frf.with_sound(paths)``) along every branch."""
    draw_branches(frf, ax, "spl_db", labels=False)
    if special_points:
        draw_special_points(frf, ax, "spl_db", labels=False)
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="tab:blue", lw=1.5, label="non-linear, stable (branch colours as above)"),
               Line2D([], [], color="tab:blue", ls="--", lw=1.2, label="non-linear, unstable")]
    handles += draw_linear_spl(frf, ax)
    ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
              framealpha=0.9)
    fit_ylim(ax)
    ax.set_xlabel(speed_axis(frf)[1])
    ax.set_ylabel("sound pressure level (dB re 20 µPa)")
    ax.set_title("sound pressure at the receiver (paths summed harmonic by harmonic)", fontsize=10)
    ax.grid(True, alpha=0.3)


#: Frequencies of the linear system's level drawn over the range (closed form: cheap, and a
#: lightly damped resonance's peak needs them).
LINEAR_SPL_POINTS = 2000


def draw_linear_spl(frf: Any, ax: Any) -> list[Any]:
    """The linear system's level through the sound paths of a response or a sweep (its
    ``sound_paths``): on :data:`LINEAR_SPL_POINTS` frequencies over the range
    (:func:`rattle.results.linear_sound_pressure`, closed form), so that its resonance peak is
    resolved; at the rows' Ω (``spl_linear_db``, marked) when the paths are not known. Returns
    the line drawn (for a legend), or nothing."""
    import warnings

    sx = speed_axis(frf)[0]
    paths = getattr(frf, "sound_paths", ())
    omega = np.asarray(frf.omega, dtype=float)
    if paths and omega.size:
        from ..results import linear_sound_pressure

        dense = np.linspace(float(omega.min()), float(omega.max()), LINEAR_SPL_POINTS)
        with warnings.catch_warnings():  # warned about once, by with_sound
            warnings.simplefilter("ignore")
            level = linear_sound_pressure(frf.model, dense, paths).spl_db
        return ax.plot(dense * sx, level, color="0.55", lw=1.0, label="linear system (f = δ)", zorder=1)
    linear = frf.extra_columns.get("spl_linear_db")
    if linear is None:
        return []
    order = np.argsort(omega, kind="stable")  # one curve in Ω order, marked where computed
    return ax.plot(omega[order] * sx, np.asarray(linear)[order], color="0.55", lw=1.0, marker=".", ms=2.5,
                   label="linear system (f = δ), at the rows' Ω", zorder=1)


def _draw_panel(frf: "FrequencyResponse", ax: Any, key: str, quantity: str, linear: bool, special_points: bool,
                shown: Sequence[Any], legend: str, *, element: int = 0, label: str = "") -> None:
    """One frequency-response panel: column ``key`` (``quantity`` of element ``element``)."""
    colors = draw_branches(frf, ax, key, name_short=special_points)
    draw_uncovered(frf, ax)
    if special_points:
        draw_special_points(frf, ax, key)
    if linear and quantity == "spl_db" and "spl_linear_db" in frf.extra_columns:
        draw_linear_spl(frf, ax)
    if linear and quantity in ("mean", "rms", "rms_ac"):
        lin = frf.linear_response() if element == 0 else frf.linear_response(element=element)
        ax.plot(lin.omega * speed_axis(frf)[0], getattr(lin, quantity), color="0.55", lw=1.0, label="linear system (f = δ)", zorder=1)
    if shown:
        draw_regions(frf, ax, key, shown, colors)
    ax.set_xlabel(speed_axis(frf)[1])
    ax.set_ylabel(QUANTITY_LABELS[quantity] if not label else QUANTITY_LABELS[quantity].replace("δ", label.strip(": ").split()[-1] + " δ", 1))
    ax.grid(True, alpha=0.3)
    fit_ylim(ax, room=LABEL_ROOM if shown else 0.0)  # every point, room for the band labels at the top
    place_legend(ax, legend)


__all__ = [
    "frequency_response_plot", "column", "speed_axis", "draw_branches", "draw_special_points", "draw_regions", "place_legend",
    "draw_uncovered",
    "branch_colors", "branch_label", "true_runs", "SPECIAL_POINT_STYLES", "QUANTITY_LABELS",
]
