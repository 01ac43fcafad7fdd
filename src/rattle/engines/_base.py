"""What every engine shares: the :class:`Engine` protocol, the errors, and the checks of a task list."""

from __future__ import annotations

import os
import pickle
from collections.abc import Callable, Hashable, Sequence
from typing import Any, Protocol, runtime_checkable

from ..errors import RattleError

#: ``on_result(key, result)``: called in the calling thread as each task completes.
ResultCallback = Callable[[Any, Any], None]
#: ``progress(done, total)``: called in the calling thread after each ``on_result``.
ProgressCallback = Callable[[int, int], None]
#: A task: its key (hashable, unique in a run, shown in messages) and its payload (picklable).
Task = tuple[Hashable, Any]


class EngineError(RattleError, RuntimeError):
    """An engine could not complete a run: a worker was lost more often than retries allow, a
    worker could not start, or a cluster could not be reached (CLI exit status 1).

    ``key`` is the task concerned (None when no single task is).
    """

    def __init__(self, message: str, key: Any = None) -> None:
        super().__init__(message)
        self.key = key


class TaskError(EngineError):
    """A task raised an exception (in a worker or in this process).

    The message names the task key and the exception; ``exception`` is the original exception
    (also the ``__cause__``), ``worker_traceback`` the traceback text from the worker ("" when
    the task ran in this process).
    """

    def __init__(self, key: Any, exception: BaseException, worker_traceback: str = "") -> None:
        text = str(exception).strip() or "(no message)"
        super().__init__(f"task `{key}` raised {type(exception).__name__}: {text}", key)
        self.exception = exception
        self.worker_traceback = worker_traceback


@runtime_checkable
class Engine(Protocol):
    """Runs a module-level function over independent tasks; results are handed back one by one.

    ``run(fn, tasks, on_result, progress=None)`` calls ``fn(payload)`` for every ``(key, payload)``
    of ``tasks`` (somewhere: this process, worker processes, a cluster) and calls
    ``on_result(key, result)`` in the calling thread as soon as each result is back, in completion
    order; ``progress(done, total)`` after each. It returns when every task is done, and raises
    :class:`TaskError` (the first task that raised; every worker stopped) or
    :class:`EngineError`. ``fn`` must be picklable (a module-level function) for every engine
    but ``serial``; the payloads and results must be picklable.
    """

    name: str
    workers: int

    def run(self, fn: Callable[[Any], Any], tasks: Sequence[Task], on_result: ResultCallback,
            progress: ProgressCallback | None = None) -> None: ...


def cpu_count() -> int:
    """CPUs this process may use (the affinity mask where the platform has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - macOS, Windows
        return max(1, os.cpu_count() or 1)


def check_workers(workers: object, name: str = "workers") -> int | None:
    """None (the engine's default) or an integer ≥ 1."""
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"`{name}` must be an integer >= 1 (or None for the default), got {workers!r}")
    return int(workers)


def check_run(fn: object, tasks: object, on_result: object, progress: object, *, pickled: bool) -> list[Task]:
    """The arguments of :meth:`Engine.run` checked; the tasks as a list of (key, payload) pairs."""
    if not callable(fn):
        raise TypeError(f"`fn` must be callable, got {fn!r}")
    if pickled:
        try:
            pickle.dumps(fn)
        except Exception as exc:
            raise TypeError(
                f"`fn` must be picklable (a function defined at module level, not a lambda or a local "
                f"function) to run in worker processes, got {fn!r} ({exc})"
            ) from None
    if not callable(on_result):
        raise TypeError(f"`on_result` must be callable as on_result(key, result), got {on_result!r}")
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be callable as progress(done, total), got {progress!r}")
    try:
        out = [(key, payload) for key, payload in tasks]  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise TypeError("`tasks` must be a sequence of (key, payload) pairs") from None
    seen: set[Any] = set()
    for key, _ in out:
        try:
            if key in seen:
                raise ValueError(f"task keys must be unique, `{key}` appears twice")
        except TypeError:
            raise TypeError(f"task keys must be hashable, got {key!r}") from None
        seen.add(key)
    return out
