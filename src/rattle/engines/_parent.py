"""A worker process that ends when its parent ends, however the parent ends (SIGKILL included)."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

__all__ = ["die_with_parent"]

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
