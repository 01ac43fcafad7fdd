"""A worker process that ends when its parent ends, however the parent ends (SIGKILL included),
and whose start-up no Ctrl-C can interrupt (the parent decides and stops its workers)."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator

__all__ = ["die_with_parent", "sigint_blocked", "worker_signals"]

#: How often (s) the watcher thread checks that the parent is still there.
WATCH_INTERVAL = 0.2


def die_with_parent(parent: int, interval: float = WATCH_INTERVAL) -> None:
    """Make this process end when the process ``parent`` ends, however it ends (SIGKILL included).

    Linux: ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` asks the kernel to kill us with our parent (with
    the parent *thread* that started us: start workers from a thread that outlives them). Every
    platform: a daemon thread that sees ``os.getppid()`` change (we were re-parented, so the
    parent is gone) and ends the process at once. Call it first thing in the worker.
    """
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover - no prctl: the thread below is enough
            pass

    def watch() -> None:
        while True:
            if os.getppid() != parent:
                os._exit(1)
            time.sleep(interval)

    if os.getppid() != parent:  # the parent died before we got here
        os._exit(1)
    threading.Thread(target=watch, name="rattle-parent-watch", daemon=True).start()


@contextlib.contextmanager
def sigint_blocked() -> Iterator[None]:
    """SIGINT blocked in this thread while a worker process is started (``process.start()``): the
    new process inherits the mask through fork and exec, so a Ctrl-C to the process group while
    its interpreter starts and unpickles its task stays pending there (no KeyboardInterrupt
    traceback from the start-up) until :func:`worker_signals` sets SIGINT to be ignored and
    unblocks it (the pending one is discarded). In the parent the signal stays pending too, and
    its handler runs as soon as the start returns."""
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - POSIX only
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def worker_signals() -> None:
    """A worker's signal dispositions, first thing in the worker: SIGINT ignored (a Ctrl-C reaches
    the whole process group; the parent decides and stops the workers) and unblocked (it was
    blocked by :func:`sigint_blocked` while the worker started), SIGTERM and SIGHUP end the
    process at once (default actions; handlers inherited from the parent are reset) — that is
    how the parent stops a worker."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
