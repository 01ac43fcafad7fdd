"""A real response map killed with SIGKILL mid-run, then resumed: finished combinations are read
back (not recomputed, their files untouched), no worker survives its parent, and the resumed map
is identical to one computed without interruption."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import psutil
import pytest

import rattle
from rattle.maps import AttractorSearch, response_map
from rattle.maps._store import MapStore

ALPHAS = [0.2, 0.25, 0.3, 0.35, 0.4, 0.45]
KW = dict(omega=(0.3, 1.5), omega_points=9, harmonics=10, search=AttractorSearch(bands=1, starts=2))

DRIVER = textwrap.dedent("""
    import sys
    import rattle
    from rattle.maps import AttractorSearch, response_map
    if __name__ == "__main__":
        response_map(rattle.reference_case(), {{"alpha": {alphas}}}, omega=(0.3, 1.5), omega_points=9, harmonics=10,
                     search=AttractorSearch(bands=1, starts=2), engine="processes", workers=2, store=sys.argv[1],
                     progress=lambda d, t, r: print("progress", d, t, r, flush=True))
        print("done", flush=True)
""")


def _cells(result) -> list[str]:
    return [json.dumps({k: v for k, v in c.to_dict().items() if k != "timings"}) for c in result.cells]


def _running(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


@pytest.mark.slow
def test_sigkill_mid_map_then_resume(tmp_path):
    store = tmp_path / "out"
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER.format(alphas=ALPHAS))
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, str(driver), str(store)], stdout=subprocess.PIPE, text=True, env=env)
    parts = store / "map.parts"
    workers: set[int] = set()
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline:
            try:
                workers |= {c.pid for c in psutil.Process(proc.pid).children(recursive=True)}
            except psutil.NoSuchProcess:
                break
            if len(MapStore(store).finished()) >= 2:  # finished parts, not a write in flight
                break
            time.sleep(0.05)
        assert proc.poll() is None, "the map finished before it could be killed: make its cells slower"
        workers |= {c.pid for c in psutil.Process(proc.pid).children(recursive=True)}
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.stdout.close()
    finished = {f"{k}.json": (parts / f"{k}.json").stat().st_mtime_ns for k in MapStore(store).finished()}
    assert 2 <= len(finished) < len(ALPHAS)
    # no worker outlives its killed parent
    t_end = time.monotonic() + 10
    alive = workers
    while alive and time.monotonic() < t_end:
        alive = {pid for pid in alive if _running(pid)}
        time.sleep(0.1)
    assert not alive, f"worker processes {alive} outlived the killed map"
    # resume (serial, in this process): the finished combinations are read back, not recomputed
    seen = []
    resumed = response_map(rattle.reference_case(), {"alpha": ALPHAS}, engine="serial", store=store,
                           progress=lambda d, t, r: seen.append(r), **KW)
    assert seen[0] == len(finished)
    assert sum(c.resumed for c in resumed.cells) == len(finished)
    for name, mtime in finished.items():
        assert (parts / name).stat().st_mtime_ns == mtime
    fresh = response_map(rattle.reference_case(), {"alpha": ALPHAS}, engine="serial", **KW)
    assert _cells(resumed) == _cells(fresh)
    assert np.array_equal(resumed.dataset["rattle"].values, fresh.dataset["rattle"].values)
