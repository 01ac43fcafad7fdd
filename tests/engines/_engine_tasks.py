"""Module-level task functions for the engine tests (picklable: workers import this module)."""

from __future__ import annotations

import math
import os
import signal
import time
import uuid
from pathlib import Path

import numpy as np


def _claim(marker: str) -> bool:
    """True for the one caller that creates ``marker`` first."""
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return False
    os.close(fd)
    return True


def compute(payload: dict) -> dict:
    """A small deterministic computation of ``payload["x"]``; hooks for the tests:

    ``sleep`` seconds first; ``calls`` a folder where each call leaves a file; ``kill_marker``: the
    first call to create that file kills its own process (SIGKILL); ``always_kill``: every call
    does; ``fail``: raise ValueError.
    """
    if payload.get("calls"):
        Path(payload["calls"], f"{payload['name']}.{os.getpid()}.{uuid.uuid4().hex[:8]}").touch()
    if payload.get("sleep"):
        time.sleep(payload["sleep"])
    if payload.get("always_kill") or (payload.get("kill_marker") and _claim(payload["kill_marker"])):
        os.kill(os.getpid(), signal.SIGKILL)
    if payload.get("fail"):
        raise ValueError(f"payload {payload['name']} is marked to fail")
    x = float(payload["x"])
    a = np.array([[2.0 + x, 1.0 / 3.0, 0.1], [0.7, 1.0 + x * x, math.pi / 7], [0.2, 0.3, 3.0 - x]])
    eig = np.sort(np.linalg.eigvals(a).real)
    solve = np.linalg.solve(a, np.array([1.0, math.e, x]))
    return {
        "name": payload["name"],
        "x": x,
        "sin": math.sin(x) / 3.0,
        "eig": [float(v) for v in eig],
        "solve": [float(v) for v in solve],
        "sum": float(np.cumsum(np.linspace(0.0, x, 101) ** 1.5)[-1]),
        "pid": os.getpid(),
        "omp": os.environ.get("OMP_NUM_THREADS"),
    }


def comparable(result: dict) -> dict:
    """``result`` without what legitimately differs between runs (the process, its environment)."""
    return {k: v for k, v in result.items() if k not in ("pid", "omp")}


def make_tasks(n: int, **extra: object) -> list[tuple[str, dict]]:
    return [(f"t{i}", {"name": f"t{i}", "x": 0.1 + 0.37 * i, **extra}) for i in range(n)]
