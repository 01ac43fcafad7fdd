"""time_sweep(): a stepped frequency sweep in the time domain, as a rig run-up or run-down.

At N equally spaced forcing frequencies Ω_1 < … < Ω_N (up) or Ω_N > … > Ω_1 (down) the equation

    δ'' + c δ' + k f(δ) = F_m + Σ_n F_pn cos(n Ω t + φ_n)

is simulated to its steady state (:func:`rattle.analysis.steady_state`), each frequency starting
from the state the previous one ended in (on the Poincaré section, forcing phase 0), the first
from the static equilibrium at rest. Where several stable motions coexist the sweep therefore
follows the one it is on until it disappears, and jumps there: the up sweep of a softening
resonance drops near its upper fold, the down sweep jumps up near the lower fold.

The discontinuous laws sweep the same way on their event-driven exact integrators: the single
equation with torque jumps and Coulomb friction, δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t)
(single-equation :class:`~rattle.model.System`), and a chain with friction on its elements
(:class:`~rattle.model.System` with its elements' whole laws); their rows also carry the fraction of the orbit (or of
the record, period 0) held stuck or locked: ``stick_fraction`` (the single equation) or
``NAME_stick_fraction`` per element, as extra columns.
"""

from __future__ import annotations

import logging
import os
import pickle
import queue as queue_module
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from .._typing import FloatArray
from .. import _limits, _validate
from ..engines import die_with_parent, sigint_blocked, worker_signals
from ..errors import ConfigError, RattleError
from ..model import Model, System, check_analysable_model
from ..results import FAILED_PERIOD, SWEEP_ELEMENT_COLUMNS, SWEEP_FAILED, SpeedText, SweepResult
from ..timeint import FLOW_FAILURES
from ._steady import SteadyStateOptions, make_integrator, static_state, steady_state, stick_fraction

logger = logging.getLogger("rattle")

#: ``direction`` argument → the sweeps run, in order (the one registry of the names).
DIRECTIONS: dict[str, tuple[str, ...]] = {"up": ("up",), "down": ("down",), "both": ("up", "down")}

ProgressCallback = Callable[[int, int], None]


# ---------------------------------------------------------------------------------------------
# One direction: a pure function of picklable inputs (runs in a worker process when asked)
# ---------------------------------------------------------------------------------------------
_ROW_SCALARS = ("omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max")

def sweep_direction(
    model: Model, omegas: FloatArray, direction: str, options: SteadyStateOptions,
    report: Callable[[str], None] | None = None,
) -> dict[str, np.ndarray]:
    """Steady states at ``omegas`` (already in sweep order), the state carried from each
    frequency to the next, the first started at the static equilibrium at rest.

    Returns the sweep's rows as a dict of arrays (see :class:`~rattle.results.SweepResult`);
    ``report(direction)`` is called after each frequency.

    Numerical trouble at one frequency (``steady_state`` raising a
    :class:`~rattle.errors.RattleError` other than bad input, or for the discontinuous laws what
    their event-driven flow raises when it cannot be followed: :func:`_failures`) fails that row
    only: it is recorded as failed (measures and states NaN, ``period`` −1, ``method``
    ``"failed"``, ``failure`` the reason; a warning names Ω and the reason) and the sweep carries
    on from the last state computed (the failed frequency's is unknown) on a fresh integrator.
    """
    integ = make_integrator(model)
    x = static_state(model, float(omegas[0]) if len(omegas) else None)
    dim = x.size
    n = len(omegas)
    rows: dict[str, np.ndarray] = {name: np.empty(n) for name in _ROW_SCALARS}
    rows["period"] = np.empty(n, dtype=np.int64)
    rows["settled"] = np.empty(n, dtype=bool)
    rows["method"] = np.empty(n, dtype="<U10")
    rows["periods"] = np.empty(n, dtype=np.int64)
    rows["shooting_periods"] = np.empty(n, dtype=np.int64)
    rows["state0"] = np.empty((n, dim))
    rows["final_state"] = np.empty((n, dim))
    rows["multipliers"] = np.full((n, dim), np.nan + 0j)
    names = getattr(model, "element_names", None) or ()
    for name in names:
        for c in SWEEP_ELEMENT_COLUMNS:
            rows[f"{name}_{c}"] = np.empty(n)
        rows[f"{name}_regime"] = np.full(n, "", dtype=object)
    sticks = _stick_columns(model)
    for key in sticks:
        rows[key] = np.empty(n)
    rows["failure"] = np.full(n, "", dtype=object)
    rows["regime"] = np.full(n, "", dtype=object)
    failures = _failures(model)
    speed = SpeedText.of(model)  # an engine case's messages in rpm
    for i, w in enumerate(omegas):
        try:
            s = steady_state(model, float(w), x, options=options, integrator=integ)
        except failures as exc:
            if isinstance(exc, ConfigError):  # bad input fails the whole sweep, as before
                raise
            reason = _reason(exc)
            _fail_row(rows, i, float(w), reason)
            logger.warning("%s sweep %s: no steady state (%s); the row is recorded as failed and the sweep "
                           "carries on from the last state computed", direction, speed.at(float(w), 6), reason)
            integ = make_integrator(model)  # a fresh one: nothing of the failed run is carried on
            if report is not None:
                report(direction)
            continue
        for name in _ROW_SCALARS:
            rows[name][i] = getattr(s, name)
        rows["period"][i] = s.period
        rows["settled"][i] = s.settled
        rows["method"][i] = s.method
        rows["regime"][i] = s.regime
        rows["periods"][i] = s.periods
        rows["shooting_periods"][i] = s.shooting_periods
        rows["state0"][i] = s.state0
        rows["final_state"][i] = s.final_state
        if s.multipliers is not None:
            rows["multipliers"][i] = s.multipliers
        if names:
            em = s.element_measures
            for c in SWEEP_ELEMENT_COLUMNS:
                values = getattr(em, c)
                for k, nm in enumerate(names):
                    rows[f"{nm}_{c}"][i] = values[k]
            for nm, regime in zip(names, s.regimes()):
                rows[f"{nm}_regime"][i] = regime
        if sticks:
            held = np.atleast_1d(stick_fraction(s.trajectory))  # type: ignore[arg-type]
            for k, key in enumerate(sticks):
                rows[key][i] = held[k]
        x = s.final_state
        logger.debug("%s sweep %s: period %d (%s), rms %.6g", direction, speed.at(float(w), 6), s.period, s.method, s.rms)
        if report is not None:
            report(direction)
    rows["direction"] = np.full(n, direction, dtype="<U4")
    return rows


def _failures(model: object) -> tuple[type[BaseException], ...]:
    """The exceptions of ``steady_state`` that fail one row of a sweep instead of the sweep:
    rattle's own (:class:`~rattle.errors.RattleError`), and for the discontinuous laws also what
    their event-driven flow raises when it cannot be followed (:data:`FLOW_FAILURES`: a singular
    step, a loop of stuck elements, values beyond double precision)."""
    return FLOW_FAILURES if _discontinuous(model) else (RattleError,)


def _reason(exc: BaseException) -> str:
    """The failure on one line: rattle's message, another exception's with its type's name."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if isinstance(exc, RattleError) else f"{text} ({type(exc).__name__})"


def _fail_row(rows: dict[str, np.ndarray], i: int, omega: float, reason: str) -> None:
    """Row ``i`` (at ``omega``) as failed: every measure and state NaN, ``period``
    :data:`~rattle.results._sweep.FAILED_PERIOD` (−1), ``method`` ``"failed"``, not settled, no
    effort counted, ``failure`` the reason."""
    for key, col in rows.items():
        if key == "omega":
            col[i] = omega
        elif key == "failure":
            col[i] = reason
        elif key == "regime" or key.endswith("_regime"):
            col[i] = ""
        elif key == "period":
            col[i] = FAILED_PERIOD
        elif key == "method":
            col[i] = SWEEP_FAILED
        elif key == "settled":
            col[i] = False
        elif key in ("periods", "shooting_periods"):
            col[i] = 0
        else:
            col[i] = np.nan


def _discontinuous(model: object) -> bool:
    """A law with jumps or friction: the single equation's or a chain's (its whole laws)."""
    return isinstance(model, System) and model.discontinuous


def _stick_columns(model: object) -> tuple[str, ...]:
    """The stick-fraction columns of a discontinuous law's rows: ``stick_fraction`` for the single
    equation, ``NAME_stick_fraction`` per element of a chain with friction; none otherwise."""
    if not _discontinuous(model):
        return ()
    if model.is_single_equation:  # type: ignore[attr-defined]
        return ("stick_fraction",)
    return tuple(f"{nm}_stick_fraction" for nm in model.element_names)  # type: ignore[attr-defined]


class _Bounds:
    """The frequency bounds of a discontinuous law (:mod:`rattle._limits` reads ``system()``):
    the smooth System of a chain with friction; for the single equation its stiffest stage's
    natural frequency sqrt(k s_max) and damping rate c."""

    def __init__(self, model: System) -> None:
        self.model = model

    def system(self) -> Any:
        if not self.model.is_single_equation:
            return self.model.continuous()
        from types import SimpleNamespace

        ws = float(np.sqrt(self.model.k * float(np.max(self.model.law.stages.slopes))))
        return SimpleNamespace(stiffest_frequency=lambda: ws, damping=np.array([[self.model.c]]))


def _run_timed(model: Model, omegas: FloatArray, direction: str, options: SteadyStateOptions,
               report: Callable[[str], None] | None) -> tuple[dict[str, np.ndarray], float]:
    t0 = time.perf_counter()
    rows = sweep_direction(model, omegas, direction, options, report)
    return rows, time.perf_counter() - t0


# ---------------------------------------------------------------------------------------------
# Worker processes: one per direction, stopped with their parent on any signal
# ---------------------------------------------------------------------------------------------
#: How often (s) a worker checks that its parent is still alive, and the parent polls its workers.
_WATCH_INTERVAL = 0.2
#: Time (s) a worker gets to end after SIGTERM before it is killed.
_TERMINATE_GRACE = 1.0


def _worker_main(parent: int, messages: Any, model: Model, omegas: FloatArray, direction: str,
                 options: SteadyStateOptions) -> None:
    """A worker process: one direction, progress and the result sent back on ``messages``.

    SIGINT is ignored (a Ctrl-C reaches the whole process group; the parent decides and stops the
    workers), SIGTERM ends the process at once (the default action; a handler inherited from the
    parent is reset) — that is how the parent stops a worker.
    """
    worker_signals()  # SIGINT ignored (and unblocked: it was blocked while we started), SIGTERM ends us
    die_with_parent(parent, _WATCH_INTERVAL)
    try:
        result = _run_timed(model, omegas, direction, options, lambda d: messages.put(("progress", d, None)))
    except BaseException as exc:  # sent back whole when it pickles, else as text
        try:
            pickle.dumps(exc)
            payload: Any = exc
        except Exception:
            payload = RattleError(f"{type(exc).__name__}: {exc}")
        messages.put(("error", direction, payload))
        return
    messages.put(("done", direction, result))


def _stop_workers(processes: Sequence[Any]) -> None:
    """SIGTERM every live worker, wait up to ``_TERMINATE_GRACE`` s, SIGKILL what is left, reap all."""
    for p in processes:
        if p.is_alive():
            p.terminate()
    deadline = time.monotonic() + _TERMINATE_GRACE
    for p in processes:
        p.join(max(0.0, deadline - time.monotonic()))
    for p in processes:
        if p.is_alive():
            p.kill()
            p.join(1.0)


def _run_parallel(
    model: Model, grids: dict[str, FloatArray], options: SteadyStateOptions, workers: int,
    progress: Callable[[], None],
) -> dict[str, tuple[dict[str, np.ndarray], float]]:
    """The directions in ``workers`` processes; progress messages come back over a queue and
    are reported in this process as they arrive.

    The workers never outlive this call: whatever ends it — the results, a worker's error,
    KeyboardInterrupt (SIGINT), a SIGTERM turned into an exception by the command line, any other
    exception — they are terminated and reaped in ``finally``. The parent waits on the queue in
    short slices, so a signal is acted on within ``_WATCH_INTERVAL`` s. A parent killed outright
    (SIGKILL) is noticed by the workers themselves (:func:`rattle.engines.die_with_parent`).
    """
    import multiprocessing

    ctx = multiprocessing.get_context()
    messages = ctx.Queue()
    parent = os.getpid()
    directions = list(grids)
    processes: list[Any] = []  # every worker started, for the clean-up
    out: dict[str, tuple[dict[str, np.ndarray], float]] = {}
    try:
        # one process per direction (the frequencies of a direction depend on each other);
        # `workers` bounds how many run at once
        waiting = list(directions)
        running: dict[str, Any] = {}
        silent_polls = 0  # polls without a message while a worker has ended without a result
        while waiting or running:
            while waiting and len(running) < workers:
                d = waiting.pop(0)
                p = ctx.Process(target=_worker_main, name=f"rattle-sweep-{d}",
                                args=(parent, messages, model, grids[d], d, options), daemon=True)
                with sigint_blocked():  # a Ctrl-C while it starts is the parent's, not a traceback of it
                    p.start()
                processes.append(p)
                running[d] = p
                logger.info("%s sweep: worker process %d started", d, p.pid)
            try:
                kind, d, payload = messages.get(timeout=_WATCH_INTERVAL)
            except queue_module.Empty:
                ended = [d for d, p in running.items() if not p.is_alive()]
                silent_polls = silent_polls + 1 if ended else 0
                if silent_polls > 5:  # its last message would have arrived by now
                    d = ended[0]
                    raise RattleError(
                        f"the {d} sweep's worker process ended without a result "
                        f"(exit status {running[d].exitcode}); run with --workers 1 to see why"
                    ) from None
                continue
            silent_polls = 0
            if kind == "progress":
                progress()
            elif kind == "error":
                raise payload
            else:
                out[d] = payload
                running.pop(d).join(_TERMINATE_GRACE)
    finally:
        _stop_workers(processes)
        messages.close()
        messages.cancel_join_thread()
    return out


class _Progress:
    def __init__(self, total: int, callback: ProgressCallback | None) -> None:
        self.total, self.callback, self.count = total, callback, 0

    def __call__(self, *_: object) -> None:
        self.count += 1
        if self.callback is not None:
            self.callback(self.count, self.total)


@_validate.numerical_failures
def time_sweep(
    model: Model | Any,
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
    :func:`rattle.analysis.steady_state`), the state carried from each frequency to the next as in
    a rig run-up (``up``) or run-down (``down``). Each direction starts from the static
    equilibrium at rest; ``both`` runs the up sweep, then the down sweep.

    Parameters
    ----------
    model : Model, Chain or System (continuous, or with its whole laws: the single equation's or a chain's)
        The model; a chain is simulated on all its coordinates (state (x, x')), its rows measure
        the first clearance element and ``element_columns`` every element. A discontinuous law
        (jumps and Coulomb friction: single-equation :class:`~rattle.model.System`, or a chain with
        friction on its elements: :class:`~rattle.model.System` with its elements' whole laws) runs on its event-driven
        exact integrator; its rows also carry the stick fraction (``extra_columns``:
        ``stick_fraction``, or ``NAME_stick_fraction`` per element).
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
        ``sweep.csv`` columns, effort, states and provenance. A frequency whose steady state
        raised numerical trouble is a failed row (NaN measures, ``period`` −1, ``method``
        ``"failed"``, the reason in ``failure``; logged as a warning) and the sweep went on from
        the last state computed: ``complete`` is then False and ``message`` names them.
    """
    # Argument checks: the rules of rattle._limits / rattle._validate, shared with the file.
    if _discontinuous(model):
        lo, hi = _limits.check_frequency_range(_Bounds(model), *_validate.check_range(omega, "omega"), simulate=True)
    else:
        check_analysable_model(model)
        lo, hi = _limits.check_frequency_range(model, *_validate.check_range(omega, "omega"), simulate=True)
    points = _limits.check_points(points)
    if not isinstance(direction, str) or direction not in DIRECTIONS:
        raise ValueError(
            f"`direction` must be one of {', '.join(repr(d) for d in DIRECTIONS)}, got {direction!r}"
        )
    workers = _limits.check_workers(workers)
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
    names = getattr(model, "element_names", None) or ()
    element_columns = {f"{nm}_{c}": columns.pop(f"{nm}_{c}") for nm in names for c in (*SWEEP_ELEMENT_COLUMNS, "regime")}
    extra_columns = {key: columns.pop(key) for key in _stick_columns(model)}
    timings = {f"{d} sweep": runs[d][1] for d in DIRECTIONS[direction]}
    timings["total"] = t_total
    settings = {
        "omega": [lo, hi], "points": points, "direction": direction, "workers": n_proc,
        "steady_state": options.to_dict(),
    }
    logger.info("time sweep %s: %d frequencies in %.3g s", direction, points * len(grids), t_total)
    return SweepResult(model=model, settings=settings, timings=timings, element_columns=element_columns,
                       extra_columns=extra_columns, **columns)


__all__ = ["time_sweep", "sweep_direction", "DIRECTIONS"]
