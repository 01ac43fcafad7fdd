"""One combination of a response map: its frequency response, every attractor, on the Ω grid.

:func:`compute_cell` is what an engine runs for every combination (a module-level function of
plain, picklable arguments, so that local processes and Dask workers run the very same code and
give the same bits). It

1. takes the combination's model (built and validated from its configuration tables, with
   :func:`rattle.io.config_from_dict`, once, before any work: :func:`rattle.maps.response_map`);
2. finds every branch on the grid and the attractors they miss
   (:func:`rattle.analysis.attractor_census`): for a smooth law the frequency response with
   sub-harmonic branch switching (harmonic balance), every branch solved again at the grid
   frequencies, and the attractor search; for a discontinuous law (a torque jump or friction) the
   exact shooting continuation of ``rattle frf`` with the period-2 branches born at its period
   doublings, every branch solved exactly at the grid frequencies, and the attractor search on
   the exact flow — a response that stops early keeps what it computed (status ``partial``);
3. summarises each grid frequency per SPEC §7 (:func:`summarise`) and the combination's
   intervals and special points;
4. with sound paths (``task["paths"]``), the largest sound pressure level over the stable
   periodic solutions at each grid frequency (:func:`sound_levels`; smooth laws: the levels come
   from the harmonic-balance series of the solutions).
"""

from __future__ import annotations

import time
import warnings
from typing import Any

import numpy as np

from ..analysis import AttractorSearch, Census, RunSettings, attractor_census, special_points
from ..errors import RattleError
from ..results import UNCOVERED_WARNING, coefficient_sound_pressure
from ._result import INTERVAL_KINDS, CellResult, grid_runs


def summarise(census: Census, grid: np.ndarray) -> dict[str, Any]:
    """The SPEC §7 columns on the grid, and the intervals of :data:`INTERVAL_KINDS`."""
    N = grid.size
    n_solutions = np.zeros(N, dtype=int)
    n_stable = np.zeros(N, dtype=int)
    rms_max = np.full(N, np.nan)
    rms_ac_max = np.full(N, np.nan)
    regime = np.full(N, "", dtype=object)
    periods: list[set[int]] = [set() for _ in range(N)]
    rattle = np.zeros(N, dtype=bool)
    for s in census.solutions:
        j = s.index
        if s.branch == 0 and s.period == 1:
            n_solutions[j] += 1
            n_stable[j] += int(s.stable)
        if not s.stable:
            continue
        periods[j].add(s.period)
        rattle[j] |= s.impacts
        if s.period == 1 and not (s.rms <= rms_max[j]):  # NaN compares False: the first one wins
            rms_max[j], rms_ac_max[j], regime[j] = s.rms, s.rms_ac, s.regime
    for a in census.simulated:  # attractors seen by simulation only (period 0: non-periodic)
        periods[a.index].add(a.period)
        rattle[a.index] |= a.impacts
        if a.period == 1 and not (a.rms <= rms_max[a.index]):
            rms_max[a.index], rms_ac_max[a.index], regime[a.index] = a.rms, a.rms_ac, a.regime
    periods_text = np.array([";".join(str(p) for p in sorted(ps)) for ps in periods], dtype=object)
    intervals = {
        "impact": grid_runs(rattle, grid),
        "rattle_free": grid_runs(~rattle, grid),
        "subharmonic": grid_runs(np.array([any(p >= 2 for p in ps) for ps in periods]), grid),
        "nonperiodic": grid_runs(np.array([0 in ps for ps in periods]), grid),
    }
    assert set(intervals) == set(INTERVAL_KINDS)
    return {
        "n_solutions": n_solutions, "n_stable": n_stable, "rms_max_stable": rms_max,
        "rms_ac_max_stable": rms_ac_max, "regime_max_stable": regime, "periods_stable": periods_text,
        "rattle": rattle, "intervals": intervals,
    }


def sound_levels(model: Any, census: Census, grid: np.ndarray, paths: tuple[Any, ...]) -> tuple[np.ndarray, str]:
    """``spl_max_stable_db`` on the grid: per grid frequency the largest sound pressure level at
    the receiver (:func:`rattle.results.coefficient_sound_pressure`, the paper's eq. 1 on
    each solution's own harmonics k Ω/period) over the stable periodic solutions of every branch
    there, NaN where there is none; and a note (empty, or the largest share of a source's
    mean-square acceleration outside a path table, when above UNCOVERED_WARNING: the level is then
    a lower bound). Attractors seen only by simulation (non-periodic, or periodic beyond the
    branch budget) have no harmonic-balance series and do not count."""
    spl = np.full(grid.size, np.nan)
    stable = [s for s in census.solutions if s.stable]
    uncovered = 0.0
    for size in sorted({s.q.size for s in stable}):  # one batch per harmonic count
        group = [s for s in stable if s.q.size == size]
        with warnings.catch_warnings():  # reported once, in the cell's message
            warnings.simplefilter("ignore")
            sp = coefficient_sound_pressure(model, np.array([s.q for s in group]), np.array([s.omega for s in group]),
                                            np.array([s.period for s in group]), paths)
        uncovered = max(uncovered, float(np.max(sp.uncovered, initial=0.0)))
        for s, level in zip(group, sp.spl_db):
            if not (level <= spl[s.index]):  # NaN compares False: the first one wins
                spl[s.index] = level
    note = "" if uncovered <= UNCOVERED_WARNING else (
        f"sound: up to {100 * uncovered:.3g} % of a source's mean-square acceleration lies outside a path table "
        "(transmitted as zero), so spl_max_stable_db is a lower bound there; extend the path tables")
    return spl, note


def compute_cell(task: dict[str, Any]) -> dict[str, Any]:
    """One combination (``task``: ``model`` — built from its configuration tables with the varied
    values set —, ``values`` by NAME, ``omega`` (lo, hi), ``omega_points``, ``run`` the RunSettings,
    ``max_period``, ``search`` the AttractorSearch, optionally ``paths`` the sound paths) →
    :meth:`CellResult.to_dict`.

    A combination whose frequency response fails numerically is not an error of the map: its
    cell says ``failed`` (or ``partial``) with the reason, and the map goes on."""
    t0 = time.perf_counter()
    lo, hi = (float(x) for x in task["omega"])
    grid = np.linspace(lo, hi, int(task["omega_points"]))
    run: RunSettings = task["run"]
    search: AttractorSearch = task["search"]
    values = dict(task["values"])
    model = task["model"]
    paths = tuple(task.get("paths") or ())
    try:
        found = attractor_census(model, grid, run, search, max_period=int(task["max_period"]))
    except RattleError as exc:  # nothing computed: the cell says why
        return _failed(values, grid, f"{type(exc).__name__}: {exc}", time.perf_counter() - t0, bool(paths))
    census, message, timings = found.census, found.message, dict(found.timings)
    t3 = time.perf_counter()
    summary = summarise(census, grid)
    if census.counts.get("not_continued"):
        message = "; ".join(x for x in (message, (
            f"attractor search: the branch budget ({search.max_branches}) was spent and "
            f"{census.counts['not_continued']} attractors found beyond it were not continued as branches (those seen "
            "by simulation still count where they were seen); raise AttractorSearch(max_branches=…)")) if x)
    if paths:
        summary["spl_max_stable_db"], note = sound_levels(model, census, grid, paths)
        message = "; ".join(x for x in (message, note) if x)
        timings["sound"] = time.perf_counter() - t3
    timings["total"] = time.perf_counter() - t0
    intervals = summary.pop("intervals")
    cell = CellResult(
        values=values, omega=grid, **summary, special_points=special_points(found.parts),
        intervals=intervals, attractors=census.found,
        search={**census.counts, "bands": search.bands, "starts": search.starts,
                "from_unstable": search.from_unstable, "max_branches": search.max_branches,
                "max_periods": search.max_periods, "branches_of_response": found.branches},
        status=found.status, message=message, timings=timings,
    )
    return cell.to_dict()


def _failed(values: dict[str, float], grid: np.ndarray, message: str, seconds: float,
            sound: bool = False) -> dict[str, Any]:
    N = grid.size
    cell = CellResult(
        values=values, omega=grid, n_solutions=np.zeros(N, dtype=int), n_stable=np.zeros(N, dtype=int),
        rms_max_stable=np.full(N, np.nan), rms_ac_max_stable=np.full(N, np.nan),
        regime_max_stable=np.full(N, "", dtype=object), periods_stable=np.full(N, "", dtype=object),
        rattle=np.zeros(N, dtype=bool), intervals={k: [] for k in INTERVAL_KINDS}, status="failed",
        message=message, timings={"total": seconds}, spl_max_stable_db=np.full(N, np.nan) if sound else None,
    )
    return cell.to_dict()


__all__ = ["compute_cell", "summarise", "sound_levels"]
