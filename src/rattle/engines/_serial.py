"""The serial engine: a plain loop in this process."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ._base import ProgressCallback, ResultCallback, Task, TaskError, check_run


class SerialEngine:
    """Runs the tasks one after the other in this process (``workers`` is 1).

    A task that raises ends the run with :class:`~rattle.engines.TaskError` naming its key
    (the original exception as its cause); KeyboardInterrupt passes through unchanged.
    """

    name = "serial"

    def __init__(self) -> None:
        self.workers = 1

    def __repr__(self) -> str:
        return "SerialEngine()"

    def run(self, fn: Callable[[Any], Any], tasks: Sequence[Task], on_result: ResultCallback,
            progress: ProgressCallback | None = None) -> None:
        items = check_run(fn, tasks, on_result, progress, pickled=False)
        total = len(items)
        for done, (key, payload) in enumerate(items, start=1):
            try:
                result = fn(payload)
            except Exception as exc:
                raise TaskError(key, exc) from exc
            on_result(key, result)
            if progress is not None:
                progress(done, total)
