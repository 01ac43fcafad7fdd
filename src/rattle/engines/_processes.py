"""The local-processes engine: a small pool of worker processes on this machine.

Why an own pool rather than ``concurrent.futures.ProcessPoolExecutor``
-----------------------------------------------------------------------
The executor marks the whole pool broken when one worker dies and fails every pending future; it
does not say which task killed the worker. Here each worker runs one task at a time over its own
pipe, so the parent always knows which task a lost worker held: that task alone is retried on a
fresh worker (at most ``max_retries`` times), the others carry on.

How it works
------------
- Workers are started with the ``spawn`` start method (a fresh interpreter: no ``fork`` of a
  process that has threads), with ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` and
  ``MKL_NUM_THREADS`` = 1 in their environment from the start (set in the parent's environment
  only for the instant of the start, then restored): one BLAS thread, so that a result is bit
  for bit the one a serial run with one BLAS thread gives, and N workers do not oversubscribe N
  cores.
- The parent sends ``(index, payload)`` to an idle worker, the worker answers ``("done", index,
  result)`` or ``("error", index, exception, traceback)``. The parent waits on every pipe and
  every process sentinel at once (in short slices, so that a signal is acted on at once) and
  calls ``on_result`` as each result arrives.
- A worker that ends without answering (killed, segfault, out of memory) has lost its task: the
  task goes back to the front of the queue and a fresh worker is started. After ``max_retries``
  losses of the same task the run ends with :class:`~rattle.engines.EngineError`.
- A task that raises ends the run: every worker is stopped and :class:`~rattle.engines.TaskError`
  (task key, exception) is raised in the parent.
- Whatever ends :meth:`ProcessEngine.run` — the last result, an error, KeyboardInterrupt, a
  SIGTERM turned into an exception — every worker is stopped and reaped in ``finally`` (no
  orphans, no zombies). A parent killed outright (SIGKILL) is noticed by the workers themselves
  (:func:`~rattle.engines.die_with_parent`).

Like every ``spawn`` pool, the calling script's ``__main__`` module is imported again in each
worker: guard a script's work with ``if __name__ == "__main__":``.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import multiprocessing.connection
import os
import pickle
import signal
import threading
import time
import traceback
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from multiprocessing.reduction import ForkingPickler
from typing import Any

from ._base import (
    EngineError,
    ProgressCallback,
    ResultCallback,
    Task,
    TaskError,
    check_run,
    check_workers,
    cpu_count,
)
from ._parent import die_with_parent, sigint_blocked, worker_signals

logger = logging.getLogger("rattle")

#: Set in every worker's environment before it starts (one BLAS/OpenMP thread per worker).
WORKER_ENVIRONMENT: dict[str, str] = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
#: How many times a task whose worker was lost is run again before the run fails.
MAX_RETRIES = 2
#: Longest wait (s) on the workers before the parent looks again (and notices a signal).
_POLL = 0.2
#: Time (s) a worker gets to end after being asked (and again after SIGTERM) before SIGKILL.
_GRACE = 1.0
#: The start methods allowed (no plain ``fork``: the parent may have threads).
START_METHODS = ("spawn", "forkserver")

_environ_lock = threading.Lock()


@contextlib.contextmanager
def _environment(env: dict[str, str]) -> Iterator[None]:
    """``env`` in ``os.environ`` for the body (a child started meanwhile inherits it), then restored."""
    with _environ_lock:
        saved = {k: os.environ.get(k) for k in env}
        os.environ.update(env)
        try:
            yield
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v


def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else a RuntimeError with its type and message."""
    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:
        return RuntimeError(f"{type(exc).__name__}: {exc}")


def _worker_main(parent: int, conn: Any, fn_bytes: bytes, env: dict[str, str]) -> None:
    """A worker: load ``fn``, then run one payload at a time until told to stop (None or EOF).

    SIGINT is ignored (a Ctrl-C reaches the whole process group; the parent decides and stops the
    workers), SIGTERM and SIGHUP end the process at once (default actions; handlers inherited
    from the parent are reset) — that is how the parent stops a worker.
    """
    worker_signals()
    die_with_parent(parent)
    os.environ.update(env)
    try:
        fn = pickle.loads(fn_bytes)
    except BaseException as exc:
        conn.send(("fatal", None, f"{type(exc).__name__}: {exc}", traceback.format_exc()))
        return
    conn.send(("ready", os.getpid(), time.time()))
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        index, payload = message
        try:
            result = fn(payload)
        except BaseException as exc:  # SystemExit too: reported, not a lost worker
            conn.send(("error", index, _portable(exc), traceback.format_exc()))
            continue
        try:
            conn.send(("done", index, result))
        except Exception as exc:  # the result does not pickle (nothing was written)
            error = TypeError(f"the task's result cannot be sent back to the parent process: {exc}")
            conn.send(("error", index, error, traceback.format_exc()))


def describe_exit(exitcode: int | None) -> str:
    """How a process ended, in words (``killed by signal 9 (SIGKILL)``, ``exited with status 1``)."""
    if exitcode is None:
        return "stopped answering"
    if exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = "unknown signal"
        return f"was killed by signal {-exitcode} ({name})"
    return f"exited with status {exitcode}"


@dataclass(eq=False)
class _Worker:
    process: Any
    conn: Any
    started: float
    current: int | None = None  # index of the task it holds
    ready: float | None = None  # when it reported ready (time.time() in the worker)
    dead: bool = False
    sentinel: int = -1  # the process's sentinel, once started

    @property
    def spawned(self) -> bool:
        return self.process.pid is not None


class ProcessEngine:
    """Runs the tasks in ``workers`` local worker processes (see the module docstring).

    Parameters
    ----------
    workers : int, optional
        Worker processes (default: the CPUs this process may use); never more than there are
        tasks.
    max_retries : int
        How often a task whose worker was lost (killed, crashed) is run again (default 2).
    start_method : {"spawn", "forkserver"}
        How workers are started (default ``spawn``).

    After a run, ``last_run`` holds what happened: ``workers_started``, ``tasks_lost``,
    ``startup`` (seconds from the start of the first worker to its being ready: interpreter
    start-up plus loading ``fn``'s module), ``wall`` (seconds of the whole run).
    """

    name = "processes"

    def __init__(self, workers: int | None = None, *, max_retries: int = MAX_RETRIES,
                 start_method: str = "spawn") -> None:
        requested = check_workers(workers)
        self.workers = requested if requested is not None else cpu_count()
        if isinstance(max_retries, bool) or not isinstance(max_retries, int) or max_retries < 0:
            raise ValueError(f"`max_retries` must be an integer >= 0, got {max_retries!r}")
        if start_method not in START_METHODS:
            raise ValueError(f"`start_method` must be one of {START_METHODS}, got {start_method!r}")
        self.max_retries = max_retries
        self.start_method = start_method
        self.last_run: dict[str, Any] = {}

    def __repr__(self) -> str:
        return f"ProcessEngine(workers={self.workers})"

    # -----------------------------------------------------------------------------------------
    def _start(self, ctx: Any, fn_bytes: bytes, everyone: list[_Worker]) -> _Worker:
        """A new worker, registered in ``everyone`` before it starts (an interrupt during the
        start still finds it for the clean-up)."""
        parent_end, child_end = ctx.Pipe(duplex=True)
        process = ctx.Process(target=_worker_main, name="rattle-worker", daemon=True,
                              args=(os.getpid(), child_end, fn_bytes, WORKER_ENVIRONMENT))
        w = _Worker(process, parent_end, time.time())
        everyone.append(w)
        try:
            with _environment(WORKER_ENVIRONMENT), sigint_blocked():
                process.start()
        finally:
            child_end.close()
        w.sentinel = process.sentinel
        self.last_run["workers_started"] += 1
        logger.debug("engine worker process %d started", process.pid)
        return w

    @staticmethod
    def _stop(workers: Sequence[_Worker]) -> None:
        """Ask every idle worker to end and SIGTERM the busy ones (a run ended early: their tasks
        are not wanted), SIGTERM what has not ended after ``_GRACE`` s, then SIGKILL; reap all."""
        for w in workers:
            if not w.spawned:  # interrupted before it started
                with contextlib.suppress(OSError):
                    w.conn.close()
        workers = [w for w in workers if w.spawned]
        for w in workers:
            if w.process.is_alive():
                if w.current is None:
                    with contextlib.suppress(OSError, ValueError):
                        w.conn.send(None)
                else:
                    w.process.terminate()
        for escalate in ("terminate", "kill"):  # after each grace period, a harder signal
            deadline = time.monotonic() + _GRACE
            for w in workers:
                w.process.join(max(0.0, deadline - time.monotonic()))
            for w in workers:
                if w.process.is_alive():
                    getattr(w.process, escalate)()
        for w in workers:
            w.process.join(5.0)
        for w in workers:
            with contextlib.suppress(OSError):
                w.conn.close()
            with contextlib.suppress(ValueError):
                w.process.close()

    # -----------------------------------------------------------------------------------------
    def run(self, fn: Callable[[Any], Any], tasks: Sequence[Task], on_result: ResultCallback,
            progress: ProgressCallback | None = None) -> None:
        items = check_run(fn, tasks, on_result, progress, pickled=True)
        total = len(items)
        t0 = time.time()
        self.last_run = {"workers_started": 0, "tasks_lost": 0, "startup": None, "wall": 0.0}
        if total == 0:
            return
        fn_bytes = pickle.dumps(fn)
        ctx = multiprocessing.get_context(self.start_method)
        size = min(self.workers, total)
        pending: deque[int] = deque(range(total))
        lost = [0] * total
        done = 0
        live: list[_Worker] = []
        everyone: list[_Worker] = []

        def deliver(w: _Worker, message: tuple[Any, ...]) -> None:
            nonlocal done
            kind = message[0]
            if kind == "ready":
                w.ready = message[2]
                if self.last_run["startup"] is None:
                    self.last_run["startup"] = max(0.0, message[2] - w.started)
            elif kind == "done":
                _, index, result = message
                w.current = None
                done += 1
                on_result(items[index][0], result)
                if progress is not None:
                    progress(done, total)
            elif kind == "error":
                _, index, exc, tb = message
                w.current = None
                raise TaskError(items[index][0], exc, tb) from exc
            elif kind == "fatal":
                raise EngineError(f"the worker processes cannot load `fn` {fn!r}: {message[2]}")

        def bury(w: _Worker) -> None:
            """``w`` has ended (or closed its pipe): read what it still sent, reap it, requeue its task."""
            with contextlib.suppress(EOFError, OSError):
                while w.current is not None and w.conn.poll():
                    deliver(w, w.conn.recv())
            w.process.join(_GRACE)
            if w.process.is_alive():  # closed its pipe but lingers: end it
                w.process.kill()
                w.process.join(5.0)
            w.dead = True
            live.remove(w)
            if w.current is None:
                return
            index, w.current = w.current, None
            key = items[index][0]
            lost[index] += 1
            self.last_run["tasks_lost"] += 1
            how = describe_exit(w.process.exitcode)
            if lost[index] > self.max_retries:
                raise EngineError(
                    f"task `{key}` was lost {lost[index]} times: its worker process {how} while running it "
                    f"(the last time); it is not retried more than `max_retries` = {self.max_retries} times. "
                    "A task that kills its process (a crash, out of memory) needs a fix or more memory; "
                    "run with the serial engine (--workers 1) to see the error",
                    key,
                )
            logger.warning("task `%s`: its worker process %s; running it again on a fresh worker (retry %d of %d)",
                           key, how, lost[index], self.max_retries)
            pending.appendleft(index)

        try:
            for _ in range(size):
                live.append(self._start(ctx, fn_bytes, everyone))
            while done < total:
                # fresh workers for requeued tasks, then work for every idle worker
                idle = sum(1 for w in live if w.current is None)
                while len(live) < size and len(pending) > idle:
                    live.append(self._start(ctx, fn_bytes, everyone))
                    idle += 1
                for w in live:
                    if w.current is None and pending:
                        index = pending.popleft()
                        try:
                            data = ForkingPickler.dumps((index, items[index][1]))
                        except Exception as exc:
                            raise TypeError(f"task `{items[index][0]}`: its payload cannot be sent to a worker "
                                            f"process (it must pickle): {exc}") from exc
                        try:
                            w.conn.send_bytes(data)
                        except (OSError, ValueError):  # its pipe broke: it is dying; bury() requeues
                            pass
                        w.current = index
                by_handle: dict[Any, _Worker] = {}
                for w in live:
                    by_handle[w.conn] = w
                    by_handle[w.sentinel] = w
                ready = multiprocessing.connection.wait(list(by_handle), timeout=_POLL)
                ended: list[_Worker] = []
                for handle in ready:  # pipes first (a worker may have answered, then died)
                    w = by_handle[handle]
                    if handle is not w.conn or w.dead or w in ended:
                        continue
                    try:
                        message = w.conn.recv()
                    except (EOFError, OSError):
                        ended.append(w)
                        continue
                    deliver(w, message)
                for handle in ready:
                    w = by_handle[handle]
                    if handle is w.sentinel and w not in ended:
                        ended.append(w)
                for w in ended:
                    bury(w)
        finally:
            self._stop(everyone)
            self.last_run["wall"] = time.time() - t0
