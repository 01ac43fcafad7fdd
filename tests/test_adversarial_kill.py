"""A run killed at any moment (SIGKILL included) leaves the earlier output set or the new one,
never a mix (issue 28, item 2), and no process behind it. ``rattle frf`` and ``rattle compare``
(with two sweep workers) are killed at several points in time; afterwards the folder holds the
old set whole, or the new set whole, or a staging folder whose journal completes the new set
(what the next run in the folder does first: :func:`rattle.files.recover_staging`).
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from rattle.files import STAGING_PREFIX, recover_staging
from _cases import clutch_toml  # type: ignore[import-not-found]

SRC = Path(__file__).resolve().parents[1] / "src"
FAST = clutch_toml((0.5, 0.8), 8)
SETS = {
    "frf": (["frf", "case.toml", "-o", "out"], ("frf.csv", "frf.json", "frf.png")),
    "compare": (["compare", "case.toml", "-o", "out", "--points", "6", "--workers", "2", "-q"],
                ("frf.csv", "sweep.csv", "compare.json", "compare.png", "measured.csv")),
}


def _state(out: Path, names: tuple[str, ...]) -> dict[str, str | None]:
    return {n: hashlib.sha256((out / n).read_bytes()).hexdigest() if (out / n).is_file() else None for n in names}


def _tagged(tag: str) -> list[int]:
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if tag.encode() in (entry / "environ").read_bytes():
                pids.append(int(entry.name))
        except OSError:
            continue
    return pids


@pytest.mark.skipif(sys.platform != "linux", reason="/proc")
@pytest.mark.parametrize("delay", [0.6, 1.6, 2.8])
@pytest.mark.parametrize("command", list(SETS))
def test_a_killed_run_leaves_one_whole_set(tmp_path: Path, command: str, delay: float) -> None:
    args, names = SETS[command]
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    for n in names:  # the earlier set
        (out / n).write_bytes(f"old {n}".encode())
    old = _state(out, names)
    tag = f"RATTLE_KILL_TEST={uuid.uuid4().hex}"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(SRC), os.environ.get("PYTHONPATH")])))
    env[tag.split("=")[0]] = tag.split("=")[1]
    proc = subprocess.Popen([sys.executable, "-m", "rattle", *args], cwd=tmp_path, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(delay)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=60)
    # no process of the run is left (workers die with their parent)
    deadline = time.monotonic() + 30
    while _tagged(tag) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _tagged(tag) == []
    now = _state(out, names)
    staging = [p for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)]
    if now != old:  # something moved: it must be the whole new set, or a journal that completes it
        recover_staging(out, names)
        now = _state(out, names)
        assert all(now[n] != old[n] for n in names if now[n] is not None), now
        assert all(v is None or not (out / n).read_bytes().startswith(b"old ") for n, v in now.items())
    else:
        recover_staging(out, names)  # a staging folder without a journal is removed
        assert _state(out, names) == old
    assert not [p for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)], staging
