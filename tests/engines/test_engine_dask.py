"""The Dask engine on a LocalCluster of 2 single-threaded worker processes: the serial results bit
for bit, a worker killed mid-run (the map still complete and identical), a failing task named, an
unreachable scheduler refused naming ``--scheduler``."""

from __future__ import annotations

import socket

import pytest
from _engine_tasks import comparable, compute, make_tasks

from rattle.engines import EngineError, SerialEngine, TaskError, make_engine
from rattle.errors import ConfigError

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        yield cluster


@pytest.fixture(scope="module")
def client(cluster):
    with distributed.Client(cluster, set_as_default=False) as client:
        yield client


def _run(engine, tasks) -> dict:
    """The results without pid and environment (checked here: one BLAS thread in every worker)."""
    results: dict = {}
    ticks = []

    def on_result(key, result):
        assert key not in results
        results[key] = result

    engine.run(compute, tasks, on_result, progress=lambda done, total: ticks.append((done, total)))
    assert ticks == [(i, len(tasks)) for i in range(1, len(tasks) + 1)]
    if engine.name == "dask":
        assert {r["omp"] for r in results.values()} == {"1"}
    return {k: comparable(v) for k, v in results.items()}


def _serial(tasks) -> dict:
    return _run(SerialEngine(), [(k, {kk: vv for kk, vv in p.items() if kk != "kill_marker"}) for k, p in tasks])


def test_dask_gives_the_serial_results_bit_for_bit(client) -> None:
    tasks = make_tasks(6, sleep=0.05)
    engine = make_engine("dask", scheduler=client)
    assert engine.name == "dask"
    assert _run(engine, tasks) == _serial(tasks)
    assert engine.workers == 2
    assert client.status == "running"  # a client passed in is not closed


def test_dask_by_address_and_a_worker_killed_mid_run(cluster, tmp_path) -> None:
    tasks = make_tasks(6, sleep=0.2)
    tasks[3][1]["kill_marker"] = str(tmp_path / "killed-once")
    engine = make_engine(scheduler=cluster.scheduler_address)  # engine None + scheduler: dask
    assert engine.name == "dask"
    assert _run(engine, tasks) == _serial(tasks)
    assert (tmp_path / "killed-once").exists()  # a worker did die mid-task


def test_dask_task_that_raises_is_named(client) -> None:
    tasks = make_tasks(4, sleep=0.1)
    tasks[2][1]["fail"] = True
    with pytest.raises(TaskError, match=r"task `t2` raised ValueError: payload t2 is marked to fail") as info:
        make_engine("dask", scheduler=client).run(compute, tasks, lambda k, r: None)
    assert info.value.key == "t2" and isinstance(info.value, EngineError)
    assert not [k for k in client.who_has() if str(k).startswith("rattle-")]  # nothing left on the cluster


def test_unreachable_scheduler_is_refused_naming_the_option() -> None:
    with socket.socket() as s:  # a free port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    engine = make_engine("dask", scheduler=f"tcp://127.0.0.1:{port}")
    engine.timeout = 1.0
    with pytest.raises(ConfigError, match=r"`--scheduler` 'tcp://127.0.0.1:\d+': no Dask scheduler answered within 1 s"):
        engine.run(compute, make_tasks(1), lambda k, r: None)
    with pytest.raises(ValueError, match="`workers`"):
        make_engine("dask", scheduler="tcp://127.0.0.1:1", workers=2)
