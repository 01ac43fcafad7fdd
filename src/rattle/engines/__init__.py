"""Engines: run a module-level function over many independent tasks, each result handed back to
the caller (in the calling thread) as soon as it is done.

- ``serial``: a plain loop in this process;
- ``processes`` (the default of a map): local worker processes, started fresh (``spawn``) with one
  BLAS thread each; a worker lost mid-task has its task retried on a fresh worker;
- ``dask``: a Dask distributed cluster (an address, a client, or a LocalCluster started for the run).

Every engine gives the same results, bit for bit (the same function on the same payload with one
BLAS thread); only the order in which they arrive differs — ordering them is the caller's job.

Layer: low level, no numerics; imports nothing from rattle but :mod:`rattle.errors`.

Examples
--------
>>> engine = make_engine("processes", workers=2)  # doctest: +SKIP
>>> engine.run(compute, [("a", 1), ("b", 2)], lambda key, result: save(key, result))  # doctest: +SKIP
"""

from __future__ import annotations

from typing import Any

from ._base import (
    Engine,
    EngineError,
    ProgressCallback,
    ResultCallback,
    Task,
    TaskError,
    cpu_count,
)
from ._parent import die_with_parent, sigint_blocked, worker_signals
from ._processes import MAX_RETRIES, WORKER_ENVIRONMENT, ProcessEngine
from ._serial import SerialEngine

__all__ = [
    "Engine", "EngineError", "TaskError", "SerialEngine", "ProcessEngine", "DaskEngine", "make_engine",
    "ENGINES", "die_with_parent", "sigint_blocked", "worker_signals", "cpu_count", "MAX_RETRIES", "WORKER_ENVIRONMENT", "ResultCallback",
    "ProgressCallback", "Task", "local_cluster", "WORKER_CONFIG", "check_scheduler_address",
]

#: The engine names :func:`make_engine` knows.
ENGINES: tuple[str, ...] = ("serial", "processes", "dask")


def __getattr__(name: str) -> Any:
    if name in ("DaskEngine", "local_cluster", "WORKER_CONFIG", "check_scheduler_address"):  # keep `import rattle.engines` minimal
        from . import _dask

        return getattr(_dask, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def make_engine(engine: str | Engine | None = None, *, workers: int | None = None,
                scheduler: Any = None) -> Engine:
    """The engine asked for.

    Parameters
    ----------
    engine : {"serial", "processes", "dask"} or Engine, optional
        An engine object is returned as it is (then ``workers`` and ``scheduler`` must be None).
        None: ``dask`` when a ``scheduler`` is given, ``serial`` when ``workers == 1``, else
        ``processes``.
    workers : int, optional
        Worker processes (``processes``: default the CPUs, capped at the task count; ``dask``:
        the LocalCluster started when no scheduler is given). ``serial`` accepts only 1.
    scheduler : str, distributed.Client or cluster, optional
        ``dask`` only: the scheduler address (``tcp://host:8786``), a client or a cluster.

    Raises
    ------
    ValueError, TypeError
        An unknown engine or an argument that does not fit it.
    ConfigError
        ``dask`` without Dask distributed installed (names ``--scheduler``).
    """
    if engine is not None and not isinstance(engine, str):
        if not isinstance(engine, Engine):
            raise TypeError(
                f"`engine` must be one of {', '.join(repr(e) for e in ENGINES)}, an Engine object "
                f"(with `name`, `workers` and `run`) or None, got {engine!r}"
            )
        if workers is not None or scheduler is not None:
            raise ValueError("`workers` and `scheduler` configure a named engine; "
                             f"with an engine object ({engine!r}) leave them out")
        return engine
    if engine is None:
        engine = "dask" if scheduler is not None else ("serial" if workers == 1 else "processes")
    if engine not in ENGINES:
        raise ValueError(f"`engine` must be one of {', '.join(repr(e) for e in ENGINES)}, got {engine!r}")
    if scheduler is not None and engine != "dask":
        raise ValueError(f"`scheduler` ({scheduler!r}) is for the 'dask' engine, not {engine!r}")
    if engine == "serial":
        if workers not in (None, 1):
            raise ValueError(f"the 'serial' engine runs one task at a time: `workers` must be 1 or None, got {workers!r}")
        return SerialEngine()
    if engine == "processes":
        return ProcessEngine(workers)
    from ._dask import DaskEngine

    return DaskEngine(scheduler, workers)
