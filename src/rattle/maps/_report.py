"""The design summary of a response map as markdown (``rattle map --report`` writes it as
``map.md``): the settings, the rattle-free region in the (parameter, Ω) plane, per combination
its special points and its impact, rattle-free, sub-harmonic and non-periodic Ω intervals, and
what the attractor search did and may have missed.

Intervals are grid-resolved: ``a – b`` is the first and the last grid frequency of a run of
grid frequencies, so the true boundary lies within one grid step outside it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from ._result import INTERVAL_KINDS, CellResult, ResponseMap, grid_runs

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


def format_intervals(intervals: Iterable[Sequence[float]]) -> str:
    """``0.1 – 0.55, 1.2 – 3`` (a one-frequency run as that frequency); ``none`` when empty."""
    parts = []
    for lo, hi in intervals:
        parts.append(_g(lo) if lo == hi else f"{_g(lo)} – {_g(hi)}")
    return ", ".join(parts) if parts else "none"


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


def _values_text(values: dict[str, float]) -> str:
    return ", ".join(f"{k} = {_g(v)}" for k, v in values.items())


def _table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(x).replace("|", "\\|") for x in row) + " |" for row in rows]
    return out


def _settings(response_map: ResponseMap) -> list[str]:
    omega = np.asarray(response_map.omega, dtype=float)
    cells = response_map.cells
    lines = ["## Settings", ""]
    for p in response_map.parameters:
        vals = p.values
        span = f"{_g(vals[0])} … {_g(vals[-1])}" if len(vals) > 1 else _g(vals[0])
        listed = ", ".join(_g(v) for v in vals) if len(vals) <= 12 else f"{len(vals)} values"
        lines.append(f"- varied `{p.name}` (`{p.key}`): {span} ({len(vals)} value{'s' if len(vals) != 1 else ''}: "
                     f"{listed})")
    if omega.size:
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
    names = list(response_map.names)
    lines = ["## Rattle-free region", "",
             "Where no attractor found crosses a breakpoint (`rattle` false), in the (parameter, Ω) plane: "
             "for every combination, its rattle-free and impact Ω intervals (rad/s, grid-resolved: the "
             "first and last grid frequency of each run).", ""]
    rows = []
    for (_, values), c in zip(response_map.combinations(), response_map.cells):
        if c.status == "failed":
            rows.append([*(_g(values[n]) for n in names), "(failed)", "(failed)"])
            continue
        rows.append([*(_g(values[n]) for n in names), format_intervals(c.intervals.get("rattle_free", [])),
                     format_intervals(c.intervals.get("impact", []))])
    lines += _table([*names, "rattle-free Ω", "impacts Ω"], rows)
    common = common_intervals(response_map)
    free_everywhere = [_values_text(v) for (_, v), c in zip(response_map.combinations(), response_map.cells)
                       if c.status != "failed" and not np.asarray(c.rattle, bool).any()]
    lines += _by_frequency(response_map)
    lines += ["",
              f"- Ω rattle-free at every combination: {format_intervals(common['rattle_free_everywhere'])}",
              f"- Ω with impacts at every combination: {format_intervals(common['impact_everywhere'])}",
              "- combinations rattle-free over the whole Ω range: "
              + ("; ".join(free_everywhere) if free_everywhere else "none")]
    return lines


def _valuegrid_runs(mask: Sequence[bool], values: Sequence[float]) -> str:
    """The parameter values where ``mask`` holds, as runs of consecutive values (``0 – 0.1, 0.5``)."""
    return format_intervals(grid_runs(np.asarray(mask, bool), np.asarray(values, float)))


def _by_frequency(response_map: ResponseMap) -> list[str]:
    """With one varied parameter: the same region read along Ω — for every run of grid
    frequencies over which the set of rattle-free values does not change, those values."""
    if len(response_map.parameters) != 1 or not response_map.cells:
        return []
    p = response_map.parameters[0]
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
        band = format_intervals([[float(omega[j]), float(omega[k])]])
        rows.append([band, _valuegrid_runs(free[:, j], p.values), _valuegrid_runs((~free[:, j]) & ok, p.values)])
        j = k + 1
    return ["", f"Read along Ω: over each band of grid frequencies, the values of `{p.name}` that are rattle-free "
            "there and those where some attractor impacts (runs of consecutive values).", "",
            *_table(["Ω (rad/s)", f"rattle-free {p.name}", f"impacts at {p.name}"], rows)]


def _cell_section(values: dict[str, float], c: CellResult) -> list[str]:
    lines = [f"### {_values_text(values)}", ""]
    if c.status != "ok":
        lines += [f"Status: **{c.status}** — {c.message or 'no reason given'}", ""]
    if c.status == "failed":
        return lines
    if c.special_points:
        lines += ["Special points, the primary branch (0) first, then each further branch:", ""]
        lines += _table(["kind", "Ω (rad/s)", "branch", "period", "rms (rad)"],
                        [[sp.get("kind", ""), f"{float(sp.get('omega', math.nan)):.5g}", sp.get("branch", ""),
                          sp.get("period", ""), f"{float(sp.get('rms', math.nan)):.4g}"]
                         for sp in sorted(c.special_points, key=lambda s: (int(s.get("branch", 0) or 0),
                                                                           float(s.get("omega", 0.0)),
                                                                           str(s.get("kind", ""))))])
    else:
        lines.append("No special points (no fold, period doubling or Neimark–Sacker point in the range).")
    lines.append("")
    for kind in INTERVAL_KINDS:
        lines.append(f"- {_KIND_TITLES.get(kind, kind)}: {format_intervals(c.intervals.get(kind, []))}")
    if c.attractors:
        found = []
        for a in c.attractors:
            text = f"period {a.get('period', '?')} at Ω = {_g(float(a.get('omega', math.nan)))}"
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
        lines += _cell_section(values, c)
    lines += _search(response_map)
    return "\n".join(lines).rstrip() + "\n"
