"""Signals sent to a running ``python -m rattle``: an interrupted run leaves the earlier output set
intact or the complete new one (never a mix, never a temporary file), and the worker processes of
a parallel sweep stop with their parent whatever signal it gets (no orphans).

Each test starts the command as a subprocess with a tiny, fast case, waits for a chosen ``-v``
progress line on stderr and sends the signal then. The times asserted are generous (the
benchmark ``benchmarks/bench_frontdoor.py`` measures the real figures).
"""

from __future__ import annotations

import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from _cases import clutch_toml  # tests/_cases.py (tests/ is on sys.path through its conftest)

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals and /proc as on Linux")

SRC = Path(__file__).resolve().parents[1] / "src"

FAST = clutch_toml((0.5, 0.8), 8)

OLD = {"frf.csv": "old csv\n", "frf.json": "{\"old\": true}\n", "frf.png": "old png"}
#: Longest wait for a progress line (the machine may be busy).
WAIT = 120.0


class Run:
    """``python -m rattle -v ARGS`` in ``cwd``, its stderr read line by line in a thread."""

    def __init__(self, args: list[str], cwd: Path, *, new_session: bool = False) -> None:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
        env["PYTHONUNBUFFERED"] = "1"
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "rattle", "-v", *args], cwd=cwd, env=env, text=True,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=new_session,
        )
        self.lines: queue.Queue[str | None] = queue.Queue()
        self.stderr: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stderr is not None
        for line in self.proc.stderr:
            self.lines.put(line.rstrip("\n"))
        self.lines.put(None)

    def wait_for(self, pattern: str) -> re.Match[str]:
        """Block until a stderr line matches ``pattern``; fail if the process ends first."""
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=1.0)
            except queue.Empty:
                continue
            if line is None:
                pytest.fail(f"the command ended before {pattern!r}: {self.stderr}")
            self.stderr.append(line)
            match = re.search(pattern, line)
            if match:
                return match
        pytest.fail(f"no line {pattern!r} within {WAIT} s: {self.stderr}")

    def finish(self, timeout: float = WAIT) -> int:
        rc = self.proc.wait(timeout=timeout)
        assert self.proc.stdout is not None
        self.proc.stdout.read()
        while True:
            try:
                line = self.lines.get(timeout=5.0)
            except queue.Empty:
                break
            if line is None:
                break
            self.stderr.append(line)
        return rc

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


@pytest.fixture
def case(tmp_path: Path) -> Path:
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    return tmp_path


def _set_state(out: Path) -> str:
    """"old" (the earlier set untouched) or "new" (the complete new set); fails on anything else."""
    names = sorted(p.name for p in out.iterdir())
    hidden = [n for n in names if n.startswith(".")]
    assert hidden == [], f"temporary files left behind: {hidden}"
    texts = {n: (out / n).read_bytes() for n in names}
    if names == sorted(OLD) and all(texts[n] == OLD[n].encode() for n in OLD):
        return "old"
    assert names == ["frf.csv", "frf.json", "frf.png"], names
    assert texts["frf.csv"].startswith(b"branch,") and texts["frf.png"][:4] == b"\x89PNG", "a mix of old and new files"
    assert b"old" not in texts["frf.json"][:20]
    return "new"


# --------------------------------------------------------------------------------------------
# Output sets under SIGINT / SIGTERM / SIGHUP
# --------------------------------------------------------------------------------------------
MOMENTS = [
    ("SIGINT", r"computing the frequency response"),
    ("SIGTERM", r"staging frf\.csv"),
    ("SIGINT", r"writing frf\.csv"),
    ("SIGTERM", r"writing frf\.png"),
]


@pytest.mark.parametrize(("signame", "moment"), MOMENTS, ids=[f"{s}-{m.split()[-1]}" for s, m in MOMENTS])
def test_signal_leaves_the_old_set_or_the_new_one(case: Path, signame: str, moment: str) -> None:
    out = case / "out"
    out.mkdir()
    for name, text in OLD.items():
        (out / name).write_text(text)
    run = Run(["frf", "case.toml", "-o", "out"], case)
    try:
        run.wait_for(moment)
        run.proc.send_signal(getattr(signal, signame))
        rc = run.finish()
    finally:
        run.kill()
    state = _set_state(out)
    signum = int(getattr(signal, signame))
    if rc == 128 + signum:
        assert run.stderr[-1] == (
            f"rattle: error: interrupted by {signame}; temporary files were removed and no output set was left "
            "half-written"
        )
        assert not any("Traceback" in line for line in run.stderr)
    else:  # the run had finished before the signal arrived
        assert rc == 0 and state == "new"
    if "computing" in moment or "staging" in moment:
        assert rc == 128 + signum and state == "old"


def test_sighup_in_a_new_folder_leaves_nothing(case: Path) -> None:
    run = Run(["frf", "case.toml", "-o", "fresh/out"], case)
    try:
        run.wait_for(r"writing frf\.json")
        run.proc.send_signal(signal.SIGHUP)
        rc = run.finish()
    finally:
        run.kill()
    if rc == 129:
        assert sorted(p.name for p in case.iterdir()) == ["case.toml"]
    else:
        assert rc == 0 and _set_state(case / "fresh" / "out") == "new"


# --------------------------------------------------------------------------------------------
# Parallel sweep: the workers stop with their parent
# --------------------------------------------------------------------------------------------
def _alive(pid: int) -> bool:
    """True while ``pid`` runs (a zombie waiting for a reaper has ended)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="utf-8") as fh:
            state = fh.read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


def _children(pid: int) -> list[int]:
    kids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", encoding="utf-8") as fh:
                ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        if ppid == pid:
            kids.append(int(entry))
    return kids


def _wait_gone(pids: list[int], timeout: float) -> list[int]:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        alive = [p for p in pids if _alive(p)]
        if not alive:
            return []
        time.sleep(0.05)
    return [p for p in pids if _alive(p)]


@pytest.fixture
def sweep_run(case: Path) -> Iterator[tuple[Run, list[int], Path]]:
    """A long parallel sweep (both directions, 2 workers), started; yields it and the worker pids."""
    run = Run(["sweep", "case.toml", "--direction", "both", "--points", "5000", "--workers", "2", "-q", "-o", "out"],
              case, new_session=True)
    workers: list[int] = []
    try:
        workers.append(int(run.wait_for(r"sweep: worker process (\d+) started").group(1)))
        workers.append(int(run.wait_for(r"sweep: worker process (\d+) started").group(1)))
        assert sorted(workers) == sorted(_children(run.proc.pid))  # the pids seen from /proc agree
        time.sleep(0.3)  # both are computing
        yield run, workers, case
    finally:
        run.kill()
        for pid in workers:  # never leave an orphan behind, even when the test fails
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)


@pytest.mark.parametrize("how", ["SIGTERM to the parent", "SIGINT to the parent", "SIGINT to the group",
                                 "SIGKILL to the parent"])
def test_sweep_workers_stop_with_their_parent(sweep_run: tuple[Run, list[int], Path], how: str) -> None:
    run, workers, case = sweep_run
    signame, _, target = how.split(" ", 2)
    sig = getattr(signal, signame)
    t0 = time.monotonic()
    if target == "the group":
        os.killpg(run.proc.pid, sig)
    else:
        run.proc.send_signal(sig)
    rc = run.proc.wait(timeout=30)
    stopped = time.monotonic() - t0
    left = _wait_gone(workers, 10.0)
    assert left == [], f"orphaned workers still running after {how}: {left}"
    if sig == signal.SIGKILL:
        assert rc == -signal.SIGKILL
        return
    run.finish()
    assert rc == 128 + int(sig), run.stderr
    assert stopped < 5.0, f"the sweep took {stopped:.2f} s to stop after {how}"
    assert run.stderr[-1].startswith(f"rattle: error: interrupted by {signame};")
    assert sorted(p.name for p in case.iterdir()) == ["case.toml"]  # no output folder was made


def test_worker_watchdog_without_prctl_ends_an_orphan(tmp_path: Path) -> None:
    """Where the kernel cannot kill a worker with its parent (no prctl), the worker's own watch
    thread notices the new parent and ends it."""
    script = tmp_path / "orphan.py"
    script.write_text(
        "import multiprocessing, os, sys, time\n"
        "from rattle.engines import _parent as ts\n"
        "def work(parent):\n"
        "    ts.sys.platform = 'not-linux'  # no prctl: only the watch thread\n"
        "    ts.die_with_parent(parent)\n"
        "    time.sleep(60)\n"
        "if __name__ == '__main__':\n"
        "    p = multiprocessing.Process(target=work, args=(os.getpid(),))\n"
        "    p.start()\n"
        "    print(p.pid, flush=True)\n"
        "    time.sleep(60)\n",
        encoding="utf-8",
    )
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True, env=env)
    worker = 0
    try:
        assert proc.stdout is not None
        worker = int(proc.stdout.readline())
        time.sleep(0.5)
        assert _alive(worker)
        proc.kill()
        proc.wait()
        assert _wait_gone([worker], 10.0) == []
    finally:
        proc.kill()
        if worker and _alive(worker):
            os.kill(worker, signal.SIGKILL)


# --------------------------------------------------------------------------------------------
# In-process: a worker's failure ends the sweep and leaves no process behind
# --------------------------------------------------------------------------------------------
@pytest.fixture
def forked(monkeypatch: pytest.MonkeyPatch) -> None:
    import multiprocessing

    if multiprocessing.get_start_method(allow_none=False) != "fork":
        pytest.skip("the patched worker reaches the child only with the fork start method")


@pytest.mark.usefixtures("forked")
@pytest.mark.parametrize("how", ["raises", "dies"])
def test_a_failing_worker_ends_the_sweep_without_leftovers(monkeypatch: pytest.MonkeyPatch, how: str) -> None:
    import multiprocessing

    from rattle import RattleError, reference_case, time_sweep
    from rattle.analysis import _time_sweep as ts

    real = ts._run_timed

    def broken(model, omegas, direction, options, report):  # type: ignore[no-untyped-def]
        if direction == "down":
            if how == "dies":
                os._exit(3)
            raise RattleError("the down sweep broke")
        return real(model, omegas, direction, options, report)

    monkeypatch.setattr(ts, "_run_timed", broken)
    message = "the down sweep broke" if how == "raises" else "down sweep's worker process ended without a result"
    with pytest.raises(RattleError, match=message):
        time_sweep(reference_case(), omega=(0.5, 0.6), points=3, direction="both", workers=2)
    assert multiprocessing.active_children() == []
