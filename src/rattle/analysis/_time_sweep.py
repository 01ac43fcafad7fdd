"""time_sweep(): a stepped frequency sweep in the time domain, as a rig run-up or run-down.

At N equally spaced forcing frequencies Ω_1 < … < Ω_N (up) or Ω_N > … > Ω_1 (down) the equation

    δ'' + c δ' + k f(δ) = F_m + Σ_n F_pn cos(n Ω t + φ_n)

is simulated to its steady state (:func:`rattle.timeint.steady_state`), each frequency starting
from the state the previous one ended in (on the Poincaré section, forcing phase 0), the first
from the static equilibrium at rest. Where several stable motions coexist the sweep therefore
follows the one it is on until it disappears, and jumps there: the up sweep of a softening
resonance drops near its upper fold, the down sweep jumps up near the lower fold.
"""

from __future__ import annotations

import logging
import queue as queue_module
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any

import numpy as np

from .._typing import FloatArray
from .._validate import check_int
from ..model import Model
from ..results._sweep import SweepResult
from ..timeint import ExactIntegrator, SteadyStateOptions, steady_state

from ._frequency_response import check_range

logger = logging.getLogger("rattle")

#: ``direction`` argument → the sweeps run, in order (the one registry of the names).
DIRECTIONS: dict[str, tuple[str, ...]] = {"up": ("up",), "down": ("down",), "both": ("up", "down")}

ProgressCallback = Callable[[int, int], None]


# ---------------------------------------------------------------------------------------------
# One direction: a pure function of picklable inputs (runs in a worker process when asked)
# ---------------------------------------------------------------------------------------------
_ROW_SCALARS = ("omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max")

_WORKER_QUEUE: Any = None  # progress queue of a worker process (set by its initializer)


def _init_worker(progress_queue: Any) -> None:
    global _WORKER_QUEUE
    _WORKER_QUEUE = progress_queue


def _report_to_queue(direction: str) -> None:
    if _WORKER_QUEUE is not None:
        _WORKER_QUEUE.put(direction)


def sweep_direction(
    model: Model, omegas: FloatArray, direction: str, options: SteadyStateOptions,
    report: Callable[[str], None] | None = None,
) -> dict[str, np.ndarray]:
    """Steady states at ``omegas`` (already in sweep order), the state carried from each
    frequency to the next, the first started at the static equilibrium at rest.

    Returns the sweep's rows as a dict of arrays (see :class:`~rattle.results.SweepResult`);
    ``report(direction)`` is called after each frequency.
    """
    integ = ExactIntegrator(model)
    x = np.array([model.static_equilibrium(), 0.0])
    n = len(omegas)
    rows: dict[str, np.ndarray] = {name: np.empty(n) for name in _ROW_SCALARS}
    rows["period"] = np.empty(n, dtype=np.int64)
    rows["settled"] = np.empty(n, dtype=bool)
    rows["method"] = np.empty(n, dtype="<U10")
    rows["periods"] = np.empty(n, dtype=np.int64)
    rows["shooting_periods"] = np.empty(n, dtype=np.int64)
    rows["state0"] = np.empty((n, 2))
    rows["final_state"] = np.empty((n, 2))
    rows["multipliers"] = np.full((n, 2), np.nan + 0j)
    for i, w in enumerate(omegas):
        s = steady_state(model, float(w), x, options=options, integrator=integ)
        for name in _ROW_SCALARS:
            rows[name][i] = getattr(s, name)
        rows["period"][i] = s.period
        rows["settled"][i] = s.settled
        rows["method"][i] = s.method
        rows["periods"][i] = s.periods
        rows["shooting_periods"][i] = s.shooting_periods
        rows["state0"][i] = s.state0
        rows["final_state"][i] = s.final_state
        if s.multipliers is not None:
            rows["multipliers"][i] = s.multipliers
        x = s.final_state
        logger.debug("%s sweep Ω = %.6g: period %d (%s), rms %.6g", direction, w, s.period, s.method, s.rms)
        if report is not None:
            report(direction)
    rows["direction"] = np.full(n, direction, dtype="<U4")
    return rows


def _run_timed(model: Model, omegas: FloatArray, direction: str, options: SteadyStateOptions,
               report: Callable[[str], None] | None) -> tuple[dict[str, np.ndarray], float]:
    t0 = time.perf_counter()
    rows = sweep_direction(model, omegas, direction, options, report)
    return rows, time.perf_counter() - t0


def _run_in_worker(model: Model, omegas: FloatArray, direction: str,
                   options: SteadyStateOptions) -> tuple[dict[str, np.ndarray], float]:
    return _run_timed(model, omegas, direction, options, _report_to_queue)


def _run_parallel(
    model: Model, grids: dict[str, FloatArray], options: SteadyStateOptions, workers: int,
    progress: Callable[[], None],
) -> dict[str, tuple[dict[str, np.ndarray], float]]:
    """The directions in ``workers`` processes; progress messages come back over a queue and
    are reported in this process as they arrive."""
    import multiprocessing

    ctx = multiprocessing.get_context()
    progress_queue = ctx.Queue()
    out: dict[str, tuple[dict[str, np.ndarray], float]] = {}
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_init_worker,
                             initargs=(progress_queue,)) as pool:
        futures: dict[Future, str] = {
            pool.submit(_run_in_worker, model, grid, d, options): d for d, grid in grids.items()
        }
        pending = set(futures)
        while pending:
            try:
                while True:  # drain what has arrived
                    progress_queue.get(timeout=0.05)
                    progress()
            except queue_module.Empty:
                pass
            done, pending = wait(pending, timeout=0.0, return_when=FIRST_COMPLETED)
            for fut in done:
                out[futures[fut]] = fut.result()  # re-raises a worker's exception here
        # the workers are done: every message is in the queue (or about to be flushed)
        expected = sum(len(g) for g in grids.values())
        while progress.count < expected:  # type: ignore[attr-defined]
            try:
                progress_queue.get(timeout=1.0)
            except queue_module.Empty:
                break
            progress()
    progress_queue.close()
    return out


class _Progress:
    def __init__(self, total: int, callback: ProgressCallback | None) -> None:
        self.total, self.callback, self.count = total, callback, 0

    def __call__(self, *_: object) -> None:
        self.count += 1
        if self.callback is not None:
            self.callback(self.count, self.total)


def time_sweep(
    model: Model,
    omega: Sequence[float] = (0.1, 3.0),
    points: int = 200,
    direction: str = "up",
    *,
    options: SteadyStateOptions | None = None,
    workers: int = 1,
    callback: ProgressCallback | None = None,
) -> SweepResult:
    """Stepped time-domain frequency sweep of ``model`` over ``omega`` = (Ω_min, Ω_max) rad/s.

    At ``points`` equally spaced frequencies the equation
    δ'' + c δ' + k f(δ) = F_m + Σ_n F_pn cos(n Ω t + φ_n) is simulated exactly until its
    steady state (period 1 … 8 of the forcing period, or 0 when none settles; see
    :func:`rattle.timeint.steady_state`), the state carried from each frequency to the next as in
    a rig run-up (``up``) or run-down (``down``). Each direction starts from the static
    equilibrium at rest; ``both`` runs the up sweep, then the down sweep.

    Parameters
    ----------
    model : Model
        The model.
    omega : (float, float)
        Frequency range (Ω_min, Ω_max) in rad/s, 0 < Ω_min < Ω_max.
    points : int
        Number of equally spaced frequencies per direction (≥ 2, default 200).
    direction : {"up", "down", "both"}
        Sweep direction.
    options : SteadyStateOptions, optional
        Settling tolerance, period budget and acceleration of every frequency.
    workers : int
        Processes (default 1: serial). With ``workers >= 2`` and ``direction="both"`` the up and
        down sweeps run concurrently in two processes (the frequencies of one direction depend on
        each other and stay serial); the results are identical to the serial run.
    callback : callable, optional
        ``callback(done, total)`` after every frequency, in the calling process (also with
        ``workers >= 2``: the workers send their progress back as they go); ``total`` counts the
        frequencies of all directions. For a progress bar.

    Returns
    -------
    SweepResult
        One row per frequency in sweep order (up rows first for ``both``), with the SPEC
        ``sweep.csv`` columns, effort, states and provenance.
    """
    if not isinstance(model, Model):
        raise TypeError(f"`model` must be a rattle Model, got {model!r}")
    lo, hi = check_range(omega)
    points = check_int("points", points, 2)
    if not isinstance(direction, str) or direction not in DIRECTIONS:
        raise ValueError(
            f"`direction` must be one of {', '.join(repr(d) for d in DIRECTIONS)}, got {direction!r}"
        )
    workers = check_int("workers", workers, 1)
    if options is None:
        options = SteadyStateOptions()
    elif not isinstance(options, SteadyStateOptions):
        raise TypeError(f"`options` must be a SteadyStateOptions, got {options!r}")
    if callback is not None and not callable(callback):
        raise TypeError(f"`callback` must be callable as callback(done, total), got {callback!r}")

    grid = np.linspace(lo, hi, points)
    grids = {d: (grid if d == "up" else grid[::-1].copy()) for d in DIRECTIONS[direction]}
    progress = _Progress(points * len(grids), callback)
    t_start = time.perf_counter()
    n_proc = min(workers, len(grids))
    if n_proc > 1:
        runs = _run_parallel(model, grids, options, n_proc, progress)
    else:
        runs = {d: _run_timed(model, g, d, options, progress) for d, g in grids.items()}
    t_total = time.perf_counter() - t_start

    ordered = [runs[d][0] for d in DIRECTIONS[direction]]
    columns = {name: np.concatenate([r[name] for r in ordered]) for name in ordered[0]}
    timings = {f"{d} sweep": runs[d][1] for d in DIRECTIONS[direction]}
    timings["total"] = t_total
    settings = {
        "omega": [lo, hi], "points": points, "direction": direction, "workers": n_proc,
        "steady_state": options.to_dict(),
    }
    logger.info("time sweep %s: %d frequencies in %.3g s", direction, points * len(grids), t_total)
    return SweepResult(model=model, settings=settings, timings=timings, **columns)


__all__ = ["time_sweep", "sweep_direction", "DIRECTIONS"]
