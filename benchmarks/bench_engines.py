"""Benchmark: the map engines' overhead — serial, local processes, Dask LocalCluster — side by side.

Run:  python benchmarks/bench_engines.py  [--tasks 22] [--seconds 0.5] [--workers 2] [--repeat 1] [--sleep]
                                          [--no-dask]

(a) Start-up of one worker process: spawn → ready (a fresh interpreter that has loaded the task
    function), importing ``rattle.maps._cell`` there (numpy, scipy, numba, the analysis), and the
    first small frequency response in a fresh worker against the second (numba's cached kernels
    loaded / compiled on first use).
(b) ``--tasks`` CPU-bound tasks of ``--seconds`` each (a pure-Python loop calibrated here, so the
    work is the same in every engine) on ``--workers`` workers: wall time, speed-up over serial,
    and the overhead against the ideal ceil(tasks / workers) × seconds (best of ``--repeat``
    rounds, the engines interleaved in each round). Dask twice: a LocalCluster
    started and closed by the run (what ``engine="dask"`` without a scheduler does) and one that
    is already running (what ``--scheduler ADDRESS`` meets); ``concurrent.futures``'
    ProcessPoolExecutor as a reference. Every engine's results are checked equal to the serial ones.
    With ``--sleep`` the tasks sleep instead of computing: the engines' own overhead, free of the
    CPU contention of a loaded machine (the speed-up then is what idle cores would give).
(c) The dispatch cost per task: 200 empty tasks.

The machine's other load shows in the figures: run it on a quiet machine for clean numbers.
"""

from __future__ import annotations

import argparse
import importlib
import math
import time


def busy(payload: dict) -> dict:
    """CPU-bound work: ``payload["n"]`` iterations of a pure-Python recurrence (after sleeping
    ``payload["sleep"]`` seconds, if given)."""
    if payload.get("sleep"):
        time.sleep(payload["sleep"])
    x, n = float(payload["i"]) * 1e-3 + 0.5, int(payload["n"])
    acc = 0.0
    for k in range(n):
        x = 3.7 * x * (1.0 - x)
        acc += x
    return {"i": payload["i"], "acc": acc / n, "x": x}


def load(name: str) -> float:
    """Seconds to import ``name`` (in a fresh worker: the full import)."""
    t0 = time.perf_counter()
    importlib.import_module(name)
    return time.perf_counter() - t0


def warm(payload: dict) -> dict:
    """Seconds of a first and a second small frequency response of the reference case."""
    out = {}
    t0 = time.perf_counter()
    from rattle import frequency_response
    from rattle.model import reference_case

    out["import"] = time.perf_counter() - t0
    model = reference_case()
    for name in ("first", "second"):
        t0 = time.perf_counter()
        frequency_response(model, omega=(0.5, 0.9), harmonics=8)
        out[name] = time.perf_counter() - t0
    return out


def calibrate(seconds: float) -> int:
    n = 200_000
    while True:
        t0 = time.perf_counter()
        busy({"i": 0, "n": n})
        dt = time.perf_counter() - t0
        if dt > 0.2:
            return max(1, int(n * seconds / dt))
        n *= 2


def timed(engine, fn, tasks) -> tuple[float, dict]:
    results: dict = {}
    t0 = time.perf_counter()
    engine.run(fn, tasks, lambda k, r: results.__setitem__(k, r))
    return time.perf_counter() - t0, results


def executor(workers: int, fn, tasks) -> tuple[float, dict]:
    """The same tasks on concurrent.futures.ProcessPoolExecutor (spawn): the reference pool the
    processes engine was measured against (it cannot tell which task a lost worker held)."""
    import concurrent.futures as cf
    import multiprocessing

    results: dict = {}
    t0 = time.perf_counter()
    with cf.ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = {pool.submit(fn, payload): key for key, payload in tasks}
        for f in cf.as_completed(futures):
            results[futures[f]] = f.result()
    return time.perf_counter() - t0, results


def dask_running(workers: int, fn, tasks) -> tuple[float, dict]:
    """The tasks on a LocalCluster started (and its workers up) before the clock starts."""
    import distributed

    from rattle.engines._dask import DaskEngine

    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster, set_as_default=False) as client:
            client.wait_for_workers(workers)
            client.run(lambda: None)
            return timed(DaskEngine(client), fn, tasks)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tasks", type=int, default=22)
    ap.add_argument("--seconds", type=float, default=0.5)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--sleep", action="store_true", help="tasks sleep instead of computing")
    ap.add_argument("--no-dask", action="store_true")
    args = ap.parse_args()

    from rattle.engines import ProcessEngine, SerialEngine
    from rattle.engines._dask import DaskEngine, dask_available

    use_dask = dask_available() and not args.no_dask

    print("(a) worker start-up (one worker process, spawn)")
    e = ProcessEngine(1)
    out: dict = {}
    e.run(load, [("import", "rattle.maps._cell")], lambda k, r: out.__setitem__(k, r))
    print(f"    spawn -> ready (interpreter + task module)  {e.last_run['startup']:.3f} s")
    print(f"    import rattle.maps._cell in the worker       {out['import']:.3f} s")
    e.run(warm, [("warm", {})], lambda k, r: out.__setitem__(k, r))
    w = out["warm"]
    print(f"    frequency_response H=8: first {w['first']:.3f} s, second {w['second']:.3f} s "
          f"(first-use cost {w['first'] - w['second']:.3f} s)")
    print(f"    whole run of that one task (spawn, import, 2 FRFs, stop)  {e.last_run['wall']:.3f} s")

    if args.sleep:
        n_iter, kind = 1, "sleeping"
        tasks = [(f"t{i}", {"i": i, "n": 1, "sleep": args.seconds}) for i in range(args.tasks)]
    else:
        n_iter, kind = calibrate(args.seconds), "CPU-bound"
        tasks = [(f"t{i}", {"i": i, "n": n_iter}) for i in range(args.tasks)]
    ideal = math.ceil(args.tasks / args.workers) * args.seconds
    print(f"\n(b) {args.tasks} {kind} tasks of ~{args.seconds:g} s on {args.workers} workers "
          f"(ideal {ideal:.2f} s; {n_iter} iterations each)")
    engines = [("serial", lambda: timed(SerialEngine(), busy, tasks), "")]
    pe = ProcessEngine(args.workers)
    engines.append((f"processes ({args.workers})", lambda: timed(pe, busy, tasks), "worker start-up included"))
    engines.append((f"ProcessPoolExecutor ({args.workers})", lambda: executor(args.workers, busy, tasks),
                    "reference: concurrent.futures, spawn"))
    if use_dask:
        engines.append((f"dask, new LocalCluster ({args.workers})",
                        lambda: timed(DaskEngine(None, args.workers), busy, tasks), "cluster start + stop included"))
        engines.append((f"dask, running cluster ({args.workers})", lambda: dask_running(args.workers, busy, tasks),
                        "cluster started before"))
    best = {name: math.inf for name, _, _ in engines}
    ref = None
    for _ in range(args.repeat):
        for name, run, _ in engines:
            t, res = run()
            if ref is None:
                ref = res
            assert res == ref, f"{name}: results differ from serial"
            best[name] = min(best[name], t)
    t_serial = best["serial"]
    t_proc = best[f"processes ({args.workers})"]
    rows = [(name, best[name], note) for name, _, note in engines]
    print(f"    {'engine':34s} {'wall s':>8s} {'speed-up':>9s} {'overhead s':>11s}")
    for name, t, note in rows:
        over = t - (ideal if name != "serial" else args.tasks * args.seconds)
        rel = f"; {t / t_proc:.2f}x local processes" if name.startswith("dask") else ""
        print(f"    {name:34s} {t:8.2f} {t_serial / t:8.2f}x {over:11.2f}  {note}{rel}")
    print("    (every engine's results equal the serial ones)")

    n_tiny = 200
    tiny = [(f"u{i}", {"i": i, "n": 1}) for i in range(n_tiny)]
    print(f"\n(c) dispatch cost: {n_tiny} empty tasks on {args.workers} workers (start-up excluded)")
    t, _ = timed(pe, busy, tiny)
    t_start = pe.last_run["startup"] or 0.0
    print(f"    processes: {1e3 * (t - t_start) / n_tiny:.2f} ms per task "
          f"({t:.2f} s in all, of which ~{t_start:.2f} s worker start-up)")
    if use_dask:
        import distributed

        with distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, \
                distributed.Client(cluster, set_as_default=False) as client:
            client.wait_for_workers(args.workers)
            t, _ = timed(DaskEngine(client), busy, tiny)
        print(f"    dask (running cluster): {1e3 * t / n_tiny:.2f} ms per task ({t:.2f} s in all)")


if __name__ == "__main__":
    main()
