"""The serial and local-processes engines: the same results, a lost worker's task retried, a failing
task stopping everything, no worker outliving its parent (SIGKILL included), a killed run resumed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil
import pytest
from _engine_tasks import comparable, compute, make_tasks

from rattle.engines import (
    EngineError,
    ProcessEngine,
    SerialEngine,
    TaskError,
    make_engine,
)
from rattle.errors import RattleError
from rattle.maps._store import MapStore

HERE = Path(__file__).resolve().parent


def _children() -> set[int]:
    """This process's descendants but multiprocessing's resource tracker (started with the first
    spawned process, it lives as long as this process: not a worker)."""
    out = set()
    for p in psutil.Process().children(recursive=True):
        try:
            if "resource_tracker" not in " ".join(p.cmdline()):
                out.add(p.pid)
        except psutil.NoSuchProcess:
            pass
    return out


def _gone(pids: set[int], timeout: float = 5.0) -> set[int]:
    """The pids of ``pids`` still running (not ended, not a zombie) after waiting up to ``timeout``."""
    deadline = time.monotonic() + timeout
    while True:
        alive = set()
        for pid in pids:
            try:
                if psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                    alive.add(pid)
            except psutil.NoSuchProcess:
                pass
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.05)


def _run(engine, tasks) -> tuple[dict, list[str], list[tuple[int, int]]]:
    results: dict = {}
    order: list[str] = []
    ticks: list[tuple[int, int]] = []

    def on_result(key, result):
        assert key not in results
        results[key] = result
        order.append(key)

    engine.run(compute, tasks, on_result, progress=lambda done, total: ticks.append((done, total)))
    return results, order, ticks


@pytest.fixture(scope="module")
def serial_results() -> dict:
    results, _, _ = _run(SerialEngine(), make_tasks(6))
    return {k: comparable(v) for k, v in results.items()}


def test_make_engine_names_and_refusals() -> None:
    assert make_engine("serial").name == "serial"
    assert make_engine(workers=1).name == "serial"
    e = make_engine(workers=3)
    assert (e.name, e.workers) == ("processes", 3)
    assert make_engine(e) is e
    with pytest.raises(ValueError, match="`engine`"):
        make_engine("threads")
    with pytest.raises(ValueError, match="`workers`"):
        make_engine("processes", workers=0)
    with pytest.raises(ValueError, match="`scheduler`"):
        make_engine("processes", scheduler="tcp://127.0.0.1:1")
    with pytest.raises(ValueError, match="`workers`"):
        make_engine("serial", workers=2)
    with pytest.raises(TypeError, match="picklable"):
        ProcessEngine(2).run(lambda p: p, [("a", 1)], lambda k, r: None)
    with pytest.raises(TypeError, match="task `b`: its payload cannot be sent"):
        ProcessEngine(1).run(compute, [("a", {"name": "a", "x": 1.0}), ("b", lambda: 0)], lambda k, r: None)
    with pytest.raises(ValueError, match="unique"):
        SerialEngine().run(compute, [("a", {}), ("a", {})], lambda k, r: None)


def test_processes_give_the_serial_results_bit_for_bit(serial_results) -> None:
    before = _children()
    env_before = os.environ.get("OMP_NUM_THREADS")
    engine = ProcessEngine(2)
    results, order, ticks = _run(engine, make_tasks(6, sleep=0.1))
    assert {k: comparable(v) for k, v in results.items()} == serial_results
    assert sorted(order) == sorted(serial_results)
    assert ticks == [(i, 6) for i in range(1, 7)]
    assert {r["omp"] for r in results.values()} == {"1"}  # one BLAS thread in every worker
    assert len({r["pid"] for r in results.values()}) == 2 and os.getpid() not in {r["pid"] for r in results.values()}
    assert os.environ.get("OMP_NUM_THREADS") == env_before  # the parent's environment is left as it was
    assert engine.last_run["workers_started"] == 2 and engine.last_run["tasks_lost"] == 0
    assert _children() - before == set()


def test_worker_count_is_capped_at_the_task_count() -> None:
    engine = ProcessEngine(4)
    results, _, _ = _run(engine, make_tasks(1))
    assert list(results) == ["t0"] and engine.last_run["workers_started"] == 1
    engine.run(compute, [], lambda k, r: None)  # nothing to do: nothing started
    assert engine.last_run["workers_started"] == 0


def test_a_killed_worker_has_its_task_retried(tmp_path, serial_results) -> None:
    before = _children()
    tasks = make_tasks(6, sleep=0.1)
    tasks[2][1]["kill_marker"] = str(tmp_path / "killed-once")
    engine = ProcessEngine(2)
    results, _, _ = _run(engine, tasks)
    assert (tmp_path / "killed-once").exists()  # it did die once
    assert {k: comparable(v) for k, v in results.items()} == serial_results
    assert engine.last_run["tasks_lost"] == 1 and engine.last_run["workers_started"] == 3
    assert _children() - before == set()


def test_a_task_that_always_kills_its_worker_fails_the_run_naming_it() -> None:
    before = _children()
    tasks = make_tasks(3)
    tasks[1][1]["always_kill"] = True
    with pytest.raises(EngineError, match=r"task `t1` was lost 2 times.*signal 9 \(SIGKILL\)") as info:
        ProcessEngine(2, max_retries=1).run(compute, tasks, lambda k, r: None)
    assert info.value.key == "t1" and isinstance(info.value, RattleError)
    assert _children() - before == set()


@pytest.mark.parametrize("engine", [SerialEngine(), ProcessEngine(2)], ids=["serial", "processes"])
def test_a_task_that_raises_stops_every_worker_and_names_its_key(engine) -> None:
    before = _children()
    tasks = make_tasks(6, sleep=0.2)
    tasks[1][1]["fail"] = True
    t0 = time.monotonic()
    with pytest.raises(TaskError, match=r"task `t1` raised ValueError: payload t1 is marked to fail") as info:
        engine.run(compute, tasks, lambda k, r: None)
    assert info.value.key == "t1" and isinstance(info.value.exception, ValueError)
    assert isinstance(info.value.__cause__, ValueError)
    assert time.monotonic() - t0 < 30  # not waiting for the other tasks' end (generous: a loaded machine)
    assert _children() - before == set()


def test_an_interrupt_in_the_parent_stops_and_reaps_every_worker() -> None:
    before = _children()
    seen = []

    def on_result(key, result):
        seen.append(key)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        ProcessEngine(2).run(compute, make_tasks(6, sleep=0.2), on_result)
    assert len(seen) == 1
    assert _children() - before == set()


def test_ctrl_c_while_waiting_on_busy_workers_stops_them_at_once(tmp_path) -> None:
    before = _children()
    stop = threading.Event()

    def interrupt_when_both_run() -> None:  # SIGINT once both workers are inside a task
        while not stop.is_set():
            if len(list(tmp_path.iterdir())) >= 2:
                os.kill(os.getpid(), signal.SIGINT)
                return
            time.sleep(0.02)

    watcher = threading.Thread(target=interrupt_when_both_run, daemon=True)
    t0 = time.monotonic()
    watcher.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            ProcessEngine(2).run(compute, make_tasks(4, sleep=60, calls=str(tmp_path)), lambda k, r: None)
    finally:
        stop.set()
        watcher.join()
    assert time.monotonic() - t0 < 30  # not waiting for the 60 s tasks
    assert _children() - before == set()


def test_sigkill_of_the_parent_leaves_no_worker_and_a_rerun_resumes(tmp_path, serial_results) -> None:
    out, calls = tmp_path / "out", tmp_path / "calls"
    calls.mkdir()
    n = 8
    # the first 3 tasks are quick, the others slow: killed then, the workers are mid-task for
    # 30 s more, unless they die with their parent
    argv = [sys.executable, str(HERE / "_engine_driver.py"), str(out), str(n), "0.3", "30", str(calls)]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")])}
    driver = subprocess.Popen(argv, stdout=subprocess.PIPE, text=True, env=env)
    try:
        saved = 0
        for line in driver.stdout:  # wait until a few results are saved
            saved += line.startswith("saved")
            if saved >= 3:
                break
        workers = {p.pid for p in psutil.Process(driver.pid).children(recursive=True)}
        assert workers
        driver.send_signal(signal.SIGKILL)
        driver.wait(10)
    finally:
        if driver.poll() is None:  # pragma: no cover - the test failed before the kill
            driver.kill()
            driver.wait()
        driver.stdout.close()
    assert _gone(workers) == set(), "worker processes outlived their parent"
    store = MapStore(out)
    finished = store.finished()
    assert len(finished) == 3  # the kill came mid-run
    calls_before = {p.name.split(".")[0] for p in calls.iterdir()}
    done_before = {store.load(k)["name"] for k in finished}
    counts_before = {name: sum(1 for p in calls.iterdir() if p.name.startswith(name + ".")) for name in done_before}

    argv[5] = "0.3"  # the rerun is quick
    rerun = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=120)
    assert rerun.returncode == 0, rerun.stderr
    assert rerun.stdout.count("saved") == n - len(finished)  # only what was missing was computed
    counts_after = {name: sum(1 for p in calls.iterdir() if p.name.startswith(name + ".")) for name in done_before}
    assert counts_after == counts_before  # finished tasks were not run again
    assert calls_before <= {p.name.split(".")[0] for p in calls.iterdir()}
    results = {r["name"]: comparable(r) for r in (store.load(k) for k in store.finished())}
    full, _, _ = _run(SerialEngine(), make_tasks(n))
    assert results == {k: comparable(v) for k, v in full.items()}
