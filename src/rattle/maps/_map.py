"""``response_map``: a frequency response with every attractor for every combination of the
varied parameters, on one Ω grid (SPEC §7).

The map is embarrassingly parallel over combinations: every combination is one task,
:func:`rattle.maps._cell.compute_cell` of plain arguments (its configuration tables with the
varied values set, the run's settings), run by an engine (:mod:`rattle.engines`: serial, local
processes — the default —, or a Dask cluster). Each finished combination is handed back at
once and, with a ``store``, written to disk atomically as it completes; a rerun with the same
arguments into the same store reads finished combinations back instead of recomputing them (a
combination is identified by a hash of everything that determines its result: its tables,
the grid, the settings and the rattle version). The assembled map is the same, bit for bit,
whichever engine ran it and however often it was interrupted.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict
from typing import Any

import numpy as np

from .._validate import check_int, check_range
from ..analysis import DEFAULT_HARMONICS, AttractorSearch, RunSettings, StabilityMethod, resolve_hb
from ..errors import ConfigError, RattleError
from ..files import WriteError
from ..continuation import ContinuationOptions, NewtonOptions
from ..hb import HBOptions
from ._cell import compute_cell
from ._result import CellResult, Parameter, ResponseMap

#: Default number of grid frequencies (SPEC §7).
DEFAULT_OMEGA_POINTS = 146

ProgressCallback = Callable[[int, int, int], None]


class StoreWarning(UserWarning):
    """Parts of a map's store were damaged or foreign and are computed again (one warning per run,
    naming them and what was wrong)."""


class CallbackError(RattleError, RuntimeError):
    """A callback handed to the library (``progress``) raised; the message names it. What was
    finished before is kept (a map's store holds every finished combination)."""


def _source_of(model: Any) -> tuple[Any, Any, tuple[Any, ...], Any]:
    """The model, the analysis settings, the sound paths and the resolved file (a RunConfig) of a
    Model/Chain, a Case or a RunConfig (None, (), None: none)."""
    from ..io import RunConfig

    config = model if isinstance(model, RunConfig) else getattr(model, "config", None)
    if config is not None:  # a Case (load_case) or a RunConfig: the resolved file
        return config.model, config.analysis, tuple(getattr(config, "paths", ()) or ()), config
    return model, None, (), None


def _discontinuous(model: Any) -> bool:
    """A law with a torque jump or friction (a System with its whole laws): solved by exact
    shooting (:func:`rattle.analysis.attractor_census`)."""
    from ..model import System

    return isinstance(model, System) and model.discontinuous


def _paths_fingerprint(paths: tuple[Any, ...]) -> list[dict[str, Any]]:
    """What a combination's sound levels depend on in its paths: each path's source and the
    SHA-256 of its table (frequencies, magnitudes, phases as float64 bytes) — a changed row
    changes the store's key."""
    import hashlib

    out = []
    for p in paths:
        table = np.concatenate([np.asarray(a, dtype="<f8") for a in (p.frequency_hz, p.magnitude, p.phase_deg)])
        out.append({"source": p.source, "rows": int(np.asarray(p.frequency_hz).size),
                    "table_sha256": hashlib.sha256(table.tobytes()).hexdigest()})
    return out


def _tables_of(model: Any, config: Any, lo: float, hi: float, harmonics: int) -> dict[str, Any]:
    """The configuration tables of ``model`` with the run's range and harmonics as its
    ``[analysis]``: every combination's model is then validated against the range it is run on
    (an engine's chain writes its speed order and the range in rad/s). A discontinuous law's
    tables come from its file (``config``, a RunConfig: the law's continuous part lives there)."""
    import dataclasses

    from ..io import AnalysisSettings, model_to_toml_dict

    if _discontinuous(model):
        if config is None:
            raise TypeError("`model`: a law with a torque jump or friction is mapped from its file: give its Case "
                            "(rattle.load_case(path)) or RunConfig (rattle.io.load_config(path)), or its `tables`")
        analysis = dataclasses.replace(config.analysis, omega_min=lo, omega_max=hi, harmonics=harmonics)
        return dataclasses.replace(config, analysis=analysis).to_dict()
    return model_to_toml_dict(model, AnalysisSettings(omega_min=lo, omega_max=hi, harmonics=harmonics))


def _version() -> str:
    from .._release import version

    return version()


def response_map(
    model: Any,
    vary: Mapping[str, Sequence[float]] | Sequence[Parameter] | Sequence[tuple[str, Sequence[float]]],
    omega: tuple[float, float] | None = None,
    omega_points: int = DEFAULT_OMEGA_POINTS,
    harmonics: int = DEFAULT_HARMONICS,
    *,
    samples: int | None = None,
    hb: HBOptions | None = None,
    stability: StabilityMethod = "monodromy",
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
    max_period: int = 4,
    search: AttractorSearch | None = None,
    engine: Any = None,
    workers: int | None = None,
    scheduler: Any = None,
    store: str | os.PathLike[str] | Any = None,
    progress: ProgressCallback | None = None,
    tables: Mapping[str, Any] | None = None,
    paths: Sequence[Any] | None = None,
) -> ResponseMap:
    """Response map of ``model`` over the varied parameters and the forcing frequency.

    For every combination of the values in ``vary`` (``{NAME: values}``; NAME a dotted key of
    the configuration — ``model.elastic.alpha``, ``excitation.amplitudes.1``,
    ``model.elements.clutch.b`` — or a short name ``alpha``, ``b``, ``damping``, ``mean``,
    ``amplitude``; see :mod:`rattle.maps._vary`): the frequency response over ``omega`` with
    sub-harmonic branches up to period ``max_period``, every branch solved exactly at
    ``omega_points`` equally spaced frequencies, and the attractor search of ``search``
    (:class:`~rattle.analysis._attractors.AttractorSearch`: simulations from unstable orbits
    wherever nothing stable is known and a multi-start per band; every new periodic attractor
    continued as a branch). Summarised per grid frequency as SPEC §7's ``map.csv`` columns.

    A law with a torque jump or friction (the single equation's System, or a chain with them: a
    System) is mapped on the exact flow (:func:`rattle.analysis.attractor_census`): the
    exact shooting continuation of ``rattle frf`` with its period-2 branches, every branch solved
    exactly on the grid, the search by exact simulation; give it as its Case or RunConfig (or
    with ``tables``). Its ``[analysis] method = "hb"`` and sound ``paths`` are refused
    (ConfigError).

    Every combination's model is built and validated first: a name that resolves to nothing,
    or a value the model refuses, raises :class:`~rattle.errors.ConfigError` before any work.

    Parameters
    ----------
    model : Model, Chain, or a Case (:func:`rattle.load_case`) or RunConfig
        The base model; a Case also gives the default range (its ``analysis.omega``) and harmonics.
    omega : (float, float), optional
        Frequency range (default: the case's, else (0.1, 3.0)).
    omega_points : int
        Grid frequencies (default 146).
    harmonics, samples, hb, stability, continuation, newton
        The run's settings, as :func:`rattle.frequency_response`; carried whole into every
        combination (and into the store's identity of a combination).
    engine : "serial", "processes", "dask" or an Engine, optional
        Default: local processes (serial for one combination); ``dask`` with a ``scheduler``.
    workers : int, optional
        Worker processes (default: the CPUs, at most one per combination).
    scheduler : str or distributed.Client, optional
        A Dask scheduler address: run on that cluster.
    store : path or MapStore, optional
        Where finished combinations are kept (``<store>/map.parts``): written as each finishes,
        read back by a rerun.
    progress : callable(done, total, resumed), optional
        Called once with the combinations read back, then after each finished combination.
    tables : dict, optional
        The configuration tables to vary (a parsed TOML file); default from ``model``.
    paths : sequence of SoundPath, optional
        Sound paths (SPEC §6): every cell then also has ``spl_max_stable_db``, the largest sound
        pressure level over the stable periodic solutions at each grid frequency. Default: a
        Case's or RunConfig's ``[[paths]]``, else none; ``()`` for none.

    Returns
    -------
    ResponseMap
    """
    from ..engines import make_engine
    from ._store import MapStore
    from ._vary import apply, build_all, combinations, parameters

    t_start = time.perf_counter()
    model, analysis, config_paths, config = _source_of(model)
    paths_t: tuple[Any, ...] = config_paths if paths is None else tuple(paths)
    if omega is None:
        omega = analysis.omega if analysis is not None else (0.1, 3.0)
    lo, hi = check_range(omega, "omega")
    omega_points = check_int("omega_points", omega_points, 2)
    if analysis is not None and harmonics is DEFAULT_HARMONICS and hb is None:
        harmonics = analysis.harmonics
    hb_opts = resolve_hb(harmonics, samples, hb)
    run = RunSettings.make(hb_opts, newton, continuation, stability)
    max_period = check_int("max_period", max_period, 1)
    if search is None:
        search = AttractorSearch()
    elif not isinstance(search, AttractorSearch):
        raise TypeError(f"`search` must be an AttractorSearch or None, got {search!r}")
    # the tables to vary: the caller's (a parsed file, validated with its own [analysis]), or
    # the model's with the run's range and harmonics
    base = dict(tables) if tables is not None else _tables_of(model, config, lo, hi, hb_opts.harmonics)
    params = parameters(base, vary)
    models = build_all(base, params)  # every combination's model, validated before any work
    orders = {getattr(m, "speed_order", None) for m in models}
    speed_order = orders.pop() if len(orders) == 1 else None  # rpm only when one order holds for all
    if any(_discontinuous(m) for m in models) and (base.get("analysis") or {}).get("method") == "hb":
        raise ConfigError(
            '`analysis.method` = "hb": a map solves a law with a torque jump or friction by exact shooting '
            '(the default method, "shooting": every branch row an exact orbit, as `rattle frf` computes it); '
            'remove `method = "hb"` from [analysis] (or set it to "shooting")')
    if paths_t and any(_discontinuous(m) for m in models):
        raise ConfigError(
            "`paths`: the sound levels of a map are not computed for a law with a torque jump or friction yet "
            "(they need the harmonic-balance series of every stable solution, and its branches are exact orbits); "
            "map it without paths (`paths=()`, or remove the [[paths]] tables) and take the levels of single "
            "orbits from `rattle frf`")
    if paths_t:  # every source must exist in every combination's model
        from ..results import check_sound_paths

        for m in models:
            check_sound_paths(paths_t, m)

    settings = {**run.record(), "omega": [lo, hi], "omega_points": omega_points, "max_period": max_period,
                "search": asdict(search)}
    version = _version()
    tasks: list[tuple[int, dict[str, Any]]] = []
    keys: list[str] = []
    names = [p.name for p in params]
    for flat, setting in enumerate(combinations(params)):
        values = {name: setting[p.key] for name, p in zip(names, params)}
        cell_tables = apply(base, setting)
        task = {"model": models[flat], "values": values, "omega": (lo, hi), "omega_points": omega_points,
                "run": run, "max_period": max_period, "search": search, "paths": paths_t}
        tasks.append((flat, task))
        # the store's identity of a combination: everything its result depends on (the paths'
        # tables only when there are paths: a map without keeps the keys it always had)
        fingerprint = {"tables": cell_tables, "values": values, "settings": settings, "version": version}
        if paths_t:
            fingerprint["paths"] = _paths_fingerprint(paths_t)
        keys.append(MapStore.key(fingerprint))

    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be a callable progress(done, total, resumed) or None, got {progress!r}")
    grid = np.linspace(lo, hi, omega_points)
    the_store = None
    if store is not None:
        the_store = store if isinstance(store, MapStore) else MapStore(store)
        the_store.check_folder()  # a file or a broken link where map.parts should be: refused
        the_store.clear_orphans()  # temporaries of a write killed in an earlier run
    results: dict[int, CellResult] = {}
    if the_store is not None:
        damaged: list[str] = []
        for (flat, task), key in zip(tasks, keys):
            data, damage = the_store.read(key)  # a special file in a part's place: refused
            if data is not None:
                try:
                    cell = CellResult.from_dict(data, resumed=True)
                    cell.check_against(task["values"], grid)
                except (ValueError, TypeError) as exc:
                    damage = str(exc)
                else:
                    results[flat] = cell
            if damage is not None:
                damaged.append(f"{key[:12]}…: {damage}")
        remaining = len(tasks) - len(results)
        if remaining:
            the_store.check_writable(remaining)  # read-only: refused before any work
        if damaged:
            shown = "; ".join(damaged[:3]) + (f"; and {len(damaged) - 3} more" if len(damaged) > 3 else "")
            warnings.warn(f"`map.parts` in {str(the_store.folder)!r}: {len(damaged)} damaged or foreign part(s) "
                          f"computed again ({shown})", StoreWarning, stacklevel=2)
    todo = [(flat, task) for flat, task in tasks if flat not in results]
    total = len(tasks)
    resumed = len(results)

    def report(done: int) -> None:
        if progress is None:
            return
        try:
            progress(done, total, resumed)
        except Exception as exc:
            raise CallbackError(
                f"`progress` raised {type(exc).__name__}: {exc}; the map stopped there ({done} of {total} "
                "combinations finished" + (", kept in map.parts" if the_store is not None else "") + ")"
            ) from exc

    report(resumed)

    def on_result(flat: int, data: dict[str, Any]) -> None:
        if the_store is not None:
            try:
                the_store.save(keys[flat], data)
            except WriteError as exc:
                raise type(exc)(f"{exc}; the {len(results)} combination(s) finished before are kept in "
                                f"{str(the_store.parts)!r}: make room and run again to resume",
                                code=exc.errno, filename=exc.filename) from None
        results[flat] = CellResult.from_dict(data)
        report(len(results))

    engine_used, workers_used = "none", 0  # everything read back: no engine ran
    if todo:
        if engine is None and scheduler is None and workers is None and len(todo) == 1:
            engine = "serial"
        runner = make_engine(engine, workers=workers, scheduler=scheduler)
        runner.run(compute_cell, todo, on_result)
        engine_used, workers_used = runner.name, runner.workers
    cells = tuple(results[flat] for flat in range(total))
    wall = time.perf_counter() - t_start
    computed = [c.timings.get("total", math.nan) for c in cells if not c.resumed]
    return ResponseMap(
        parameters=params, omega=grid, cells=cells,
        settings={**settings, "engine": engine_used, "workers": workers_used, "version": version},
        timings={"wall": wall, "combinations": float(np.nansum(computed)) if computed else 0.0,
                 "computed": len(computed), "resumed": resumed},
        config=base, speed_order=speed_order, paths=paths_t,
    )


__all__ = ["response_map", "DEFAULT_OMEGA_POINTS", "StoreWarning", "CallbackError"]
