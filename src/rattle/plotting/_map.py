"""Heat map of a response map: the largest stable rms over (Ω, a varied parameter), impact
regimes hatched, the rattle-free region outlined, no stable period-1 solution in grey.

Every cell of the picture is one (parameter value, grid frequency) of the map, drawn with its
edges half-way to its neighbours (``pcolormesh``), so the hatching and the outline follow the
cells exactly: a hatched cell is one where some attractor found crosses a breakpoint
(``rattle`` true), the black outline encloses the cells where none does.

With two or more varied parameters one figure shows one parameter (``parameter``) on the y
axis and has one panel per combination of the others' values, in a grid, with one shared colour
scale; :func:`map_plot_names` gives the other figures the command line writes.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._axes import PlotAxes, unwrap

#: The response map type (:class:`rattle.maps.ResponseMap`): plotting reads its fields and does
#: not import the maps layer above it.
ResponseMap = Any

__all__ = ["plot_map", "map_plot_names", "NO_SOLUTION_COLOR", "RATTLE_HATCH", "RATTLE_COLOR", "MAP_QUANTITIES"]

#: Colour of the cells with no stable period-1 solution (``rms_max_stable`` NaN).
NO_SOLUTION_COLOR = "0.78"
#: Hatch of the cells where an attractor impacts (``rattle`` true).
RATTLE_HATCH = "////"
#: Colour of that hatching (visible on every colour of viridis and on the grey).
RATTLE_COLOR = "#d62728"
#: Most panels one figure draws (more: the first ones, and the figure says so).
MAX_PANELS = 36


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges half-way between the values, the outer ones mirrored (one value: ± 5 %, or ± 0.5)."""
    v = np.asarray(values, dtype=float)
    if v.size == 1:
        half = 0.05 * abs(v[0]) or 0.5
        return np.array([v[0] - half, v[0] + half])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate(([v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]))


def _outline(free: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> list[list[tuple[float, float]]]:
    """Segments between True and False cells of ``free`` (rows along y, columns along x); the
    map's border is the axes frame, not drawn again."""
    pad = np.pad(free, 1, mode="edge")
    segs: list[list[tuple[float, float]]] = []
    # vertical edges: between columns j-1 and j (padded indices j, j+1)
    diff_x = pad[1:-1, 1:] != pad[1:-1, :-1]  # shape (ny, nx+1)
    for i, j in zip(*np.nonzero(diff_x)):
        segs.append([(xe[j], ye[i]), (xe[j], ye[i + 1])])
    diff_y = pad[1:, 1:-1] != pad[:-1, 1:-1]  # shape (ny+1, nx)
    for i, j in zip(*np.nonzero(diff_y)):
        segs.append([(xe[j], ye[i]), (xe[j + 1], ye[i])])
    return segs


#: The last word of a varied key that makes it an angle (rad): the map's y axis then has degrees too.
ANGLE_KEYS = frozenset({"b", "breakpoints", "backlash", "clearance"})


def _is_angle(response_map: ResponseMap, name: str) -> bool:
    key = next((p.key for p in response_map.parameters if p.name == name), name)
    words = [w for w in key.split(".") if not w.isdigit()]
    return bool(words) and words[-1] in ANGLE_KEYS


#: Longest y label with the configuration key beside the NAME (a longer one is cut by the figure).
MAX_LABEL = 40


def _label(response_map: ResponseMap, name: str) -> str:
    """The y label: the parameter's NAME with its key (``alpha (model.elastic.alpha)``) when that
    is short, else the NAME alone — a dotted key without its leading ``model.`` and ``elements.``
    (the full key is in map.json) — with its unit where it is an angle."""
    key = next((p.key for p in response_map.parameters if p.name == name), name)
    degrees = any(p.name == name and getattr(p, "degrees", False) for p in response_map.parameters)
    unit = (" (deg)" if degrees else " (rad)") if _is_angle(response_map, name) else ""
    both = f"{name} ({key})" if key != name else name
    if len(both + unit) <= MAX_LABEL:
        return both + unit
    short = name
    for head in ("model.", "elements."):
        short = short[len(head):] if short.startswith(head) else short
    return short + unit


def _panels(response_map: ResponseMap, name: str) -> list[tuple[str, list[int]]]:
    """(title, cell indices along ``name`` in value order) for every combination of the others."""
    params = response_map.parameters
    axis = [p.name for p in params].index(name)
    others = [k for k in range(len(params)) if k != axis]
    shape = response_map.shape
    out = []
    for combo in np.ndindex(*[shape[k] for k in others]) if others else [()]:
        cells = []
        for i in range(shape[axis]):
            index = [0] * len(params)
            index[axis] = i
            for k, c in zip(others, combo):
                index[k] = c
            cells.append(int(np.ravel_multi_index(tuple(index), shape)))
        title = ", ".join(f"{params[k].name} = {params[k].shown(params[k].values[c]):.4g}"
                          + (" deg" if params[k].degrees else "") for k, c in zip(others, combo))
        out.append((title, cells))
    return out


def map_plot_names(response_map: ResponseMap) -> list[tuple[str, str]]:
    """(file name, parameter on the y axis) of the figures ``rattle map`` writes: ``map.png``
    with the first parameter, and with two or more varied ``map_<NAME>.png`` for each further
    parameter (its NAME with characters other than letters, digits, ``.``, ``-``, ``_`` as ``_``)."""
    names = [p.name for p in response_map.parameters]
    out = [("map.png", names[0])]
    for name in names[1:]:
        safe = "".join(c if c.isalnum() or c in "._-" else "_" for c in name)
        out.append((f"map_{safe}.png", name))
    return out


#: What a map's colour can show: quantity → (cell field, colour-bar label, legend text of an empty cell).
MAP_QUANTITIES: dict[str, tuple[str, str, str]] = {
    "rms": ("rms_max_stable", "largest stable period-1 rms of δ (rad)", "no stable period-1 solution"),
    "spl": ("spl_max_stable_db", "largest stable sound pressure level (dB re 20 µPa)", "no stable periodic solution"),
    "rms_ac": ("rms_ac_max_stable", "rms about the mean (rms_ac) of the\nlargest stable period-1 solution (rad)",
               "no stable period-1 solution"),
}


def _values(cell: Any, field: str, size: int) -> np.ndarray:
    """A cell's colour values (NaN throughout where it has none: a failed combination)."""
    v = getattr(cell, field, None)
    return np.full(size, np.nan) if v is None else np.asarray(v, dtype=float)


def plot_map(
    response_map: ResponseMap, parameter: str | None = None, ax: Any = None, *, title: str | None = None,
    quantity: str = "rms",
) -> tuple[Any, PlotAxes]:
    """Heat map of the largest stable rms (or sound pressure level) over Ω (x) and one varied
    parameter (y).

    Parameters
    ----------
    response_map : ResponseMap
    parameter : str, optional
        The NAME of the parameter on the y axis (default: the first varied one). With two or
        more varied parameters there is one panel per combination of the others' values (at
        most :data:`MAX_PANELS`), in a grid, titled with those values.
    ax : matplotlib.axes.Axes or PlotAxes, optional
        Axes to draw into (one varied parameter only; default: a new figure).
    title : str, optional
        Figure title.
    quantity : {"rms", "rms_ac", "spl"}, default "rms"
        The colour: ``rms_max_stable``, ``rms_ac_max_stable`` (the motion about the mean of that
        same solution: the rattle without the mean twist), or ``spl_max_stable_db`` (a map
        computed with sound paths: the largest level over the stable periodic solutions, dB re
        20 µPa).

    Returns
    -------
    (figure, PlotAxes)
        Panels ``map`` (one varied parameter) or ``map_1``, ``map_2``, … (one per combination of
        the others), and ``colorbar`` (the colour bar's axes); the primary is the first map panel.

    Notes
    -----
    Colour: ``rms_max_stable`` (rad), the largest rms over the stable period-1 solutions at that
    frequency (viridis, one scale over all panels). Grey: no stable period-1 solution there (the
    motion is sub-harmonic or non-periodic, ``periods_stable`` says which). Hatched: ``rattle``
    true (some attractor found impacts). Black outline: the boundary of the rattle-free cells.
    With ``quantity="spl"`` the colour is ``spl_max_stable_db`` (dB) and grey means no stable
    periodic solution of any period.
    """
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.patches import Patch, Rectangle
    from matplotlib.lines import Line2D

    if quantity not in MAP_QUANTITIES:
        raise ValueError(f"`quantity` must be one of {', '.join(map(repr, MAP_QUANTITIES))}, got {quantity!r}")
    if quantity == "spl" and not getattr(response_map, "has_sound", False):
        raise ValueError("`quantity` \"spl\" needs a map computed with sound paths (response_map(..., paths=...), "
                         "or [[paths]] in the configuration); this one has none")
    field, bar_label, empty_label = MAP_QUANTITIES[quantity]
    N = np.asarray(response_map.omega).size
    names = [p.name for p in response_map.parameters]
    if not names:
        raise ValueError("`response_map` varies no parameter; there is nothing to draw")
    if parameter is None:
        parameter = names[0]
    if parameter not in names:
        raise ValueError(f"`parameter` must be one of the varied NAMEs {names}, got {parameter!r}")
    panels = _panels(response_map, parameter)
    shown = panels[:MAX_PANELS]
    if ax is not None and len(shown) > 1:
        raise ValueError(f"`ax` draws one panel, but this map has {len(shown)} (one per combination of the other "
                         "parameters); leave `ax` out")
    varied = response_map.parameters[names.index(parameter)]
    degrees = bool(getattr(varied, "degrees", False))  # an angle the case gave in degrees: the y axis in degrees
    yvalues = np.degrees(np.asarray(varied.values, dtype=float)) if degrees else np.asarray(varied.values, dtype=float)
    rpm = getattr(response_map, "speed_rpm", None)  # an engine: the crankshaft speed on the x axis
    omega = np.asarray(response_map.omega if rpm is None else rpm, dtype=float)
    xe, ye = _edges(omega), _edges(yvalues)

    rms_all = np.concatenate([_values(c, field, N) for c in response_map.cells]) \
        if response_map.cells else np.array([np.nan])
    finite = rms_all[np.isfinite(rms_all)]
    vmin, vmax = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    if vmax <= vmin:
        vmax = vmin + (abs(vmin) * 1e-3 or 1e-3)
    norm = Normalize(vmin=vmin, vmax=vmax)
    cmap = plt.get_cmap("viridis").with_extremes(bad=NO_SOLUTION_COLOR)

    if ax is not None:
        axes_list = [unwrap(ax)]
        fig = axes_list[0].figure
        cax = None
    else:
        n = len(shown)
        ncols = 1 if n == 1 else min(n, 3 if n <= 9 else math.ceil(math.sqrt(n)))
        nrows = math.ceil(n / ncols)
        fig = plt.figure(figsize=(1.0 + 4.6 * ncols, 0.9 + 3.3 * nrows), layout="constrained")
        grid = fig.subplots(nrows, ncols, squeeze=False, sharex=True, sharey=True)
        axes_list = [grid[r][c] for r in range(nrows) for c in range(ncols)]
        for extra in axes_list[n:]:
            extra.set_visible(False)
        axes_list = axes_list[:n]
        cax = None

    mesh = None
    for a, (panel_title, cells) in zip(axes_list, shown):
        rms = np.array([_values(response_map.cells[k], field, N) for k in cells])
        rattle = np.array([np.asarray(response_map.cells[k].rattle, bool) for k in cells])
        mesh = a.pcolormesh(xe, ye, np.ma.masked_invalid(rms), cmap=cmap, norm=norm, shading="flat")
        for i in range(rattle.shape[0]):  # hatched runs of impacting cells, row by row
            row = rattle[i]
            j = 0
            while j < row.size:
                if row[j]:
                    k = j
                    while k + 1 < row.size and row[k + 1]:
                        k += 1
                    a.add_patch(Rectangle((xe[j], ye[i]), xe[k + 1] - xe[j], ye[i + 1] - ye[i], fill=False,
                                          hatch=RATTLE_HATCH, edgecolor=RATTLE_COLOR, linewidth=0))
                    j = k + 1
                else:
                    j += 1
        segs = _outline(~rattle, xe, ye)
        if segs:
            a.add_collection(LineCollection(segs, colors="black", linewidths=1.6))
        a.set_xlim(min(xe[0], xe[-1]), max(xe[0], xe[-1]))
        a.set_ylim(min(ye[0], ye[-1]), max(ye[0], ye[-1]))
        if panel_title:
            a.set_title(panel_title, fontsize=9)
    angle = _is_angle(response_map, parameter)
    for k, a in enumerate(axes_list):
        a.set_xlabel("Ω (rad/s)" if rpm is None else "engine speed (rpm)")
        a.set_ylabel(_label(response_map, parameter), fontsize=9)
        last_column = ax is not None or (k + 1) % ncols == 0 or k == len(axes_list) - 1
        if angle and last_column:
            # an angle: the other unit on the right as well (rad the files' unit, degrees a data sheet's)
            right = a.secondary_yaxis("right", functions=(np.radians, np.degrees) if degrees else (np.degrees, np.radians))
            right.set_ylabel("(rad)" if degrees else "(deg)", fontsize=9)
    if mesh is not None:
        cbar = fig.colorbar(mesh, ax=axes_list, shrink=0.9)
        cbar.set_label(bar_label)
        cax = cbar.ax
    handles = [
        Patch(facecolor="none", edgecolor=RATTLE_COLOR, hatch=RATTLE_HATCH, label="impacts (rattle)"),
        Line2D([], [], color="black", linewidth=1.6, label="rattle-free boundary"),
        Patch(facecolor=NO_SOLUTION_COLOR, edgecolor="0.5", label=empty_label),
    ]
    if ax is None:
        fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize=8, frameon=False)
    else:
        axes_list[0].legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.85)
    heading = title
    if heading is None and ax is None:
        shown_as = {"rms": "largest stable rms", "spl": "largest stable sound pressure level",
                    "rms_ac": "rms about the mean (of the largest stable solution)"}[quantity]
        heading = f"response map: {shown_as}, impacts hatched, rattle-free outlined"
        if len(heading) > 70:  # two lines: one would run past a one-panel figure's edges
            heading = heading.replace(", impacts", ",\nimpacts", 1)
        if len(panels) > len(shown):
            heading += f" (first {len(shown)} of {len(panels)} panels)"
    if heading:
        fig.suptitle(heading, fontsize=10)
    if len(axes_list) == 1:
        named: dict[str, Any] = {"map": axes_list[0]}
    else:
        named = {f"map_{i + 1}": a for i, a in enumerate(axes_list)}
    if cax is not None:
        named["colorbar"] = cax
    return fig, PlotAxes(named, primary=next(iter(named)))
