"""The design summary of a response map as markdown (``rattle map --report`` writes it as
``map.md``): the settings, the rattle-free region in the (parameter, Ω) plane, per combination
its special points and its impact, rattle-free, sub-harmonic and non-periodic Ω intervals, and
what the attractor search did and may have missed.

Intervals are grid-resolved: ``a – b`` is the first and the last grid frequency of a run of
grid frequencies, so the true boundary lies within one grid step outside it.

Units as the case was given: with an ``[engine]`` every speed is the crankshaft speed in rpm
(:class:`rattle.results.SpeedText`), else Ω in rad/s; a varied angle the case file gave in
degrees (:attr:`Parameter.degrees <rattle.maps.Parameter>`) is shown in degrees. ``map.csv``,
``map.nc`` and ``map.json`` keep Ω and rad.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from ..results import SpeedText
from ._result import INTERVAL_KINDS, CellResult, Parameter, ResponseMap, grid_runs

__all__ = ["map_report", "format_intervals", "common_intervals", "SEARCH_CAVEATS"]

#: What the attractor search may still miss (its stated limits).
SEARCH_CAVEATS = (
    "an attractor whose basin none of the multi-start initial states of its band reaches (small basins, "
    "bands where another attractor dominates)",
    "a sub-harmonic of period above the largest period the simulation detects",
    "a non-periodic attractor coexisting with stable periodic ones away from the multi-start frequencies",
    "a motion that has not settled within the simulation budget of forcing periods (reported as period 0)",
    "new branches beyond the branch budget per combination (found and listed, but not continued)",
)

_KIND_TITLES = {
    "impact": "impacts (rattle)",
    "rattle_free": "rattle-free",
    "subharmonic": "stable sub-harmonic (period ≥ 2)",
    "nonperiodic": "non-periodic attractor (period 0)",
}


def _g(x: float) -> str:
    return f"{x:.4g}"


def format_intervals(intervals: Iterable[Sequence[float]], speed: SpeedText | None = None) -> str:
    """``0.1 – 0.55, 1.2 – 3`` (a one-frequency run as that frequency); ``none`` when empty.
    With ``speed`` (Ω intervals of an engine case: :class:`rattle.results.SpeedText`) the
    values are written as it writes them: the crankshaft speed in rpm, to 5 digits."""
    parts = []
    show, digits = (float, 4) if speed is None or not speed.engine else (speed.value, 5)
    for lo, hi in intervals:
        a, b = f"{show(lo):.{digits}g}", f"{show(hi):.{digits}g}"
        parts.append(a if lo == hi else f"{a} – {b}")
    return ", ".join(parts) if parts else "none"


def _speed(response_map: ResponseMap) -> SpeedText:
    """Speeds of the report: rpm when the map's models have one engine order, else Ω."""
    return SpeedText(None if response_map.speed_order is None else float(response_map.speed_order))


def _axis(speed: SpeedText) -> str:
    """The frequency axis's name with its unit: ``Ω (rad/s)`` or ``speed (rpm)``."""
    return "speed (rpm)" if speed.engine else "Ω (rad/s)"


def _value(p: Parameter, value: float) -> str:
    """A parameter value as the case gave it (degrees for an angle given in degrees)."""
    return _g(p.shown(value))


def _header(p: Parameter) -> str:
    """A parameter's column name, with ``(deg)`` when shown in degrees."""
    return f"{p.name} (deg)" if p.degrees else p.name


def _computed(cells: Sequence[CellResult]) -> list[CellResult]:
    return [c for c in cells if c.status != "failed"]


def common_intervals(response_map: ResponseMap) -> dict[str, list[list[float]]]:
    """Ω intervals (grid-resolved) where ``rattle`` is false at every computed combination
    (``rattle_free_everywhere``) and where it is true at every one (``impact_everywhere``)."""
    cells = _computed(response_map.cells)
    omega = np.asarray(response_map.omega, dtype=float)
    if not cells:
        return {"rattle_free_everywhere": [], "impact_everywhere": []}
    rattle = np.array([np.asarray(c.rattle, bool) for c in cells])
    return {"rattle_free_everywhere": grid_runs(~rattle.any(axis=0), omega),
            "impact_everywhere": grid_runs(rattle.all(axis=0), omega)}


def _values_text(values: dict[str, float], params: Sequence[Parameter] = ()) -> str:
    by_name = {p.name: p for p in params}
    out = []
    for k, v in values.items():
        p = by_name.get(k)
        out.append(f"{k} = {_g(v)}" if p is None else f"{k} = {_value(p, v)}" + (" deg" if p.degrees else ""))
    return ", ".join(out)


def _table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(x).replace("|", "\\|") for x in row) + " |" for row in rows]
    return out


def _settings(response_map: ResponseMap) -> list[str]:
    omega = np.asarray(response_map.omega, dtype=float)
    cells = response_map.cells
    lines = ["## Settings", ""]
    speed = _speed(response_map)
    for p in response_map.parameters:
        vals = p.values
        unit = " deg" if p.degrees else ""
        span = f"{_value(p, vals[0])} … {_value(p, vals[-1])}{unit}" if len(vals) > 1 else _value(p, vals[0]) + unit
        listed = ", ".join(_value(p, v) for v in vals) if len(vals) <= 12 else f"{len(vals)} values"
        given = ", given in degrees; map.csv in rad" if p.degrees else ""
        lines.append(f"- varied `{p.name}` (`{p.key}`{given}): {span} ({len(vals)} value{'s' if len(vals) != 1 else ''}: "
                     f"{listed})")
    if omega.size and speed.engine:
        lines.append(f"- speed grid: {omega.size} crankshaft speeds, {speed.span(omega[0], omega[-1])} "
                     f"(Ω = {_g(omega[0])} … {_g(omega[-1])} rad/s, Ω = {speed.order:g} × crankshaft speed)")
    elif omega.size:
        lines.append(f"- Ω grid: {omega.size} frequencies, {_g(omega[0])} … {_g(omega[-1])} rad/s")
    for key, value in response_map.settings.items():
        if value is None or isinstance(value, dict) or key in ("omega", "omega_points"):
            continue  # the option tables are in map.json; the grid is said above
        lines.append(f"- {key}: {value}")
    status = {s: sum(1 for c in cells if c.status == s) for s in ("ok", "partial", "failed")}
    resumed = sum(1 for c in cells if c.resumed)
    lines.append(f"- combinations: {len(cells)} ({status['ok']} complete, {status['partial']} partial, "
                 f"{status['failed']} failed; {resumed} read back from an earlier run)")
    total = response_map.timings.get("total", response_map.timings.get("wall"))
    if isinstance(total, (int, float)) and math.isfinite(total):
        lines.append(f"- wall time: {total:.1f} s")
    return lines


def _region(response_map: ResponseMap) -> list[str]:
    params = response_map.parameters
    speed = _speed(response_map)
    axis, what = ("speed", "crankshaft speed intervals (rpm") if speed.engine else ("Ω", "Ω intervals (rad/s")
    lines = ["## Rattle-free region", "",
             f"Where no attractor found crosses a breakpoint (`rattle` false), in the (parameter, {axis}) plane: "
             f"for every combination, its rattle-free and impact {what}, grid-resolved: the "
             "first and last grid frequency of each run).", ""]
    rows = []
    for (_, values), c in zip(response_map.combinations(), response_map.cells):
        shown = [_value(p, values[p.name]) for p in params]
        if c.status == "failed":
            rows.append([*shown, "(failed)", "(failed)"])
            continue
        rows.append([*shown, format_intervals(c.intervals.get("rattle_free", []), speed),
                     format_intervals(c.intervals.get("impact", []), speed)])
    unit = " (rpm)" if speed.engine else ""
    lines += _table([*(_header(p) for p in params), f"rattle-free {axis}{unit}", f"impacts {axis}{unit}"], rows)
    common = common_intervals(response_map)
    free_everywhere = [_values_text(v, params) for (_, v), c in zip(response_map.combinations(), response_map.cells)
                       if c.status != "failed" and not np.asarray(c.rattle, bool).any()]
    lines += _by_frequency(response_map)
    free, impact = (format_intervals(common[k], speed) for k in ("rattle_free_everywhere", "impact_everywhere"))
    rpm = (lambda text: text) if not speed.engine else (lambda text: text if text == "none" else f"{text} rpm")
    lines += ["",
              f"- {axis} rattle-free at every combination: {rpm(free)}",
              f"- {axis} with impacts at every combination: {rpm(impact)}",
              f"- combinations rattle-free over the whole {axis} range: "
              + ("; ".join(free_everywhere) if free_everywhere else "none")]
    return lines


def _valuegrid_runs(mask: Sequence[bool], p: Parameter) -> str:
    """The values of ``p`` where ``mask`` holds, as runs of consecutive values (``0 – 0.1, 0.5``;
    in degrees when the case gave them so)."""
    shown = np.asarray([p.shown(v) for v in p.values], float)
    return format_intervals(grid_runs(np.asarray(mask, bool), shown))


def _by_frequency(response_map: ResponseMap) -> list[str]:
    """With one varied parameter: the same region read along Ω — for every run of grid
    frequencies over which the set of rattle-free values does not change, those values."""
    if len(response_map.parameters) != 1 or not response_map.cells:
        return []
    p = response_map.parameters[0]
    speed = _speed(response_map)
    omega = np.asarray(response_map.omega, dtype=float)
    ok = np.array([c.status != "failed" for c in response_map.cells])
    rattle = np.array([np.asarray(c.rattle, bool) for c in response_map.cells])
    free = (~rattle) & ok[:, None]
    rows = []
    j = 0
    while j < omega.size:
        k = j
        while k + 1 < omega.size and np.array_equal(free[:, k + 1], free[:, j]):
            k += 1
        band = format_intervals([[float(omega[j]), float(omega[k])]], speed)
        rows.append([band, _valuegrid_runs(free[:, j], p), _valuegrid_runs((~free[:, j]) & ok, p)])
        j = k + 1
    unit = " (deg)" if p.degrees else ""
    return ["", f"Read along {'the speed' if speed.engine else 'Ω'}: over each band of grid frequencies, the values "
            f"of `{p.name}`{unit} that are rattle-free there and those where some attractor impacts (runs of "
            "consecutive values).", "",
            *_table([_axis(speed), f"rattle-free {p.name}{unit}", f"impacts at {p.name}{unit}"], rows)]


def _cell_section(values: dict[str, float], c: CellResult, params: Sequence[Parameter] = (),
                  speed: SpeedText = SpeedText()) -> list[str]:
    lines = [f"### {_values_text(values, params)}", ""]
    if c.status != "ok":
        lines += [f"Status: **{c.status}** — {c.message or 'no reason given'}", ""]
    if c.status == "failed":
        return lines
    if c.special_points:
        lines += ["Special points, the primary branch (0) first, then each further branch:", ""]
        lines += _table(["kind", _axis(speed), "branch", "period", "rms (rad)"],
                        [[sp.get("kind", ""), speed.number(float(sp.get("omega", math.nan))), sp.get("branch", ""),
                          sp.get("period", ""), f"{float(sp.get('rms', math.nan)):.4g}"]
                         for sp in sorted(c.special_points, key=lambda s: (int(s.get("branch", 0) or 0),
                                                                           float(s.get("omega", 0.0)),
                                                                           str(s.get("kind", ""))))])
    else:
        lines.append("No special points (no fold, period doubling or Neimark–Sacker point in the range).")
    lines.append("")
    for kind in INTERVAL_KINDS:
        found_in = format_intervals(c.intervals.get(kind, []), speed)
        lines.append(f"- {_KIND_TITLES.get(kind, kind)}: {found_in}{' rpm' if speed.engine and found_in != 'none' else ''}")
    if c.attractors:
        found = []
        for a in c.attractors:
            text = f"period {a.get('period', '?')} at {speed.at(float(a.get('omega', math.nan)), 5 if speed.engine else 4)}"
            if a.get("origin"):
                text += f" (from {a['origin']})"
            if a.get("branch") is not None:
                text += f", continued as branch {a['branch']}"
            if a.get("note"):
                text += f" — {a['note']}"
            found.append(text)
        lines.append("- attractors the branches did not explain: " + "; ".join(found))
    else:
        lines.append("- attractors the branches did not explain: none found")
    if c.search:
        counts = ", ".join(f"{k} {v}" for k, v in c.search.items() if isinstance(v, (int, float))
                           and not isinstance(v, bool) and k not in _BUDGET_KEYS)
        if counts:
            lines.append(f"- search: {counts}")
    if c.timings.get("total") is not None:
        lines.append(f"- time: {c.timings['total']:.2f} s" + (" (read back)" if c.resumed else ""))
    lines.append("")
    return lines


_BUDGET_KEYS = ("bands", "starts", "from_unstable", "max_branches", "max_period", "max_periods")
_BUDGET_TEXT = {
    "bands": "frequency bands of the multi-start",
    "starts": "initial states simulated per band",
    "from_unstable": "simulations from the unstable orbits where no stable solution is known",
    "max_branches": "new branches continued per combination at most",
    "max_period": "largest period a simulation detects",
    "max_periods": "forcing periods a simulation may take to settle",
}


def _search(response_map: ResponseMap) -> list[str]:
    cells = _computed(response_map.cells)
    lines = ["## The attractor search", ""]
    if not cells:
        return lines + ["No combination was computed.", ""]
    budget = {k: cells[0].search[k] for k in _BUDGET_KEYS if k in cells[0].search}
    if budget:
        lines.append("Budget per combination:")
        lines.append("")
        lines += [f"- {_BUDGET_TEXT[k]}: {v}" for k, v in budget.items()]
        lines.append("")
    totals: dict[str, float] = {}
    for c in cells:
        for k, v in c.search.items():
            if k in _BUDGET_KEYS or isinstance(v, bool) or not isinstance(v, (int, float)):
                continue
            totals[k] = totals.get(k, 0) + v
    if totals:
        lines.append("Over the whole map: " + ", ".join(f"{k} {int(v) if float(v).is_integer() else v}"
                                                        for k, v in totals.items()) + ".")
        lines.append("")
    n_found = sum(len(c.attractors) for c in cells)
    n_cells = sum(1 for c in cells if c.attractors)
    lines.append(f"Attractors not explained by the branches: {n_found} at {n_cells} of {len(cells)} combinations "
                 "(listed per combination above).")
    lines += ["", "What it may still miss:", ""]
    lines += [f"- {text}" for text in SEARCH_CAVEATS]
    lines.append("")
    return lines


def map_report(response_map: ResponseMap) -> str:
    """The design summary of ``response_map`` as markdown (see the module docstring).

    Parameters
    ----------
    response_map : ResponseMap

    Returns
    -------
    str
        Sections: Settings, Rattle-free region, Combinations (one sub-section each), The
        attractor search.
    """
    lines = ["# Response map: design summary", ""]
    lines += _settings(response_map)
    lines.append("")
    lines += _region(response_map)
    lines += ["", "## Combinations", ""]
    for (_, values), c in zip(response_map.combinations(), response_map.cells):
        lines += _cell_section(values, c, response_map.parameters, _speed(response_map))
    lines += _search(response_map)
    return "\n".join(lines).rstrip() + "\n"
