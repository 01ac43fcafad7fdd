"""A synthetic response map (shared by the map tests of the CLI, the plot and the report): cells
built directly from :class:`rattle.maps.CellResult`, no numerics, with impact bands that move
with the first parameter, a hole with no stable period-1 solution, a period-2 band and a
non-periodic band."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from rattle.maps import CellResult, Parameter, ResponseMap


def _runs(mask: np.ndarray, omega: np.ndarray) -> list[list[float]]:
    out, start = [], None
    for j, m in enumerate(mask):
        if m and start is None:
            start = j
        if start is not None and (not m or j == mask.size - 1):
            stop = j if m else j - 1
            out.append([float(omega[start]), float(omega[stop])])
            start = None
    return out


def synthetic_cell(values: dict[str, float], omega: np.ndarray, shift: float = 0.0) -> CellResult:
    n = omega.size
    impact = (omega > 0.6 + shift) & (omega < 1.4 + shift)
    no_stable = (omega > 0.9 + shift) & (omega < 1.0 + shift)
    sub = (omega > 1.6) & (omega < 1.9)
    nonperiodic = (omega > 2.2) & (omega < 2.35)
    rms = 0.2 + 0.1 * np.sin(omega) + shift
    rms = np.where(no_stable, np.nan, rms)
    periods = np.array(["1"] * n, dtype=object)
    periods[sub] = "1;2"
    periods[nonperiodic] = "0"
    periods[no_stable & ~nonperiodic] = "2"
    rattle = impact | nonperiodic
    regime = np.where(np.isnan(rms), "", np.where(impact, "double_sided", "no_impact")).astype(object)
    return CellResult(
        values=dict(values), omega=omega,
        n_solutions=np.where(impact, 3, 1).astype(int), n_stable=np.where(no_stable, 0, np.where(impact, 2, 1)),
        rms_max_stable=rms, rms_ac_max_stable=rms / 2, regime_max_stable=regime, periods_stable=periods,
        rattle=rattle,
        special_points=[{"kind": "fold", "omega": 0.75 + shift, "branch": 0, "period": 1, "rms": 0.3},
                        {"kind": "period_doubling", "omega": 1.62, "branch": 0, "period": 1, "rms": 0.25}],
        intervals={"impact": _runs(rattle, omega), "rattle_free": _runs(~rattle, omega),
                   "subharmonic": _runs(sub, omega), "nonperiodic": _runs(nonperiodic, omega)},
        attractors=[{"omega": 1.7, "period": 2, "origin": "simulation", "branch": 1}],
        search={"budget": {"simulations_per_band": 4, "bands": 6}, "simulations": 24, "seeds": 12,
                "branches_added": 1, "may_miss": "attractors with basins smaller than the seed spacing"},
        status="ok", timings={"frequency_response": 0.1, "grid": 0.01, "search": 0.2, "total": 0.31},
    )


def synthetic_map(names: Sequence[str] = ("alpha",), values: Sequence[Sequence[float]] = ((0.1, 0.2, 0.3),),
                  keys: Sequence[str] | None = None, points: int = 30) -> ResponseMap:
    omega = np.linspace(0.1, 3.0, points)
    keys = keys or [f"model.elastic.{n}" if n in ("alpha", "b") else n for n in names]
    params = tuple(Parameter(name=n, key=k, values=tuple(float(x) for x in v)) for n, k, v in zip(names, keys, values))
    cells = []
    for combo in itertools.product(*(p.values for p in params)):
        vals = {p.name: v for p, v in zip(params, combo)}
        cells.append(synthetic_cell(vals, omega, shift=float(combo[0])))
    return ResponseMap(parameters=params, omega=omega, cells=tuple(cells),
                       settings={"harmonics": 8, "omega_points": points, "engine": "serial"},
                       timings={"total": 1.0}, config={})
