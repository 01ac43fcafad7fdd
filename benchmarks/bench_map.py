"""Benchmark: the reference clutch's response map — serial, 2 local processes, Dask LocalCluster.

The map of the issue: the reference case (SPEC §1) over α = 0 … 0.5 (11 values) × Ω 0.1 … 3.0
(146 grid frequencies), every attractor (sub-harmonic branches, the attractor search), 32
harmonics. Measured side by side in one run:

- serial (one process, the caller's);
- local processes, ``--workers`` (default 2): the default engine, start-up included;
- Dask: a ``LocalCluster`` of ``--workers`` single-threaded worker processes, already running
  (as ``--scheduler ADDRESS`` meets it; its start-up is printed apart), with rattle's worker
  settings (:data:`rattle.engines.WORKER_CONFIG`; ``--dask-defaults``: Dask's own).

Prints wall times, the speed-ups over serial, Dask against local processes, and whether the
three maps are identical bit for bit (every cell's JSON but its timings).

Run:  ``python benchmarks/bench_map.py [--workers 2] [--alphas 11] [--no-dask]``
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def _cells(result) -> list[str]:
    return [json.dumps({k: v for k, v in c.to_dict().items() if k != "timings"}) for c in result.cells]


def _loads(name: str, result) -> None:
    t = [c.timings.get("total", 0.0) for c in result.cells]
    print(f"    {name}: Σ cell time {sum(t):.1f} s, longest {max(t):.1f} s; per cell "
          + " ".join(f"{x:.1f}" for x in t), flush=True)


def main() -> None:
    import rattle
    from rattle.maps import response_map

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--alphas", type=int, default=11)
    ap.add_argument("--points", type=int, default=146)
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--skip-serial", action="store_true")
    ap.add_argument("--dask-defaults", action="store_true",
                    help="start the LocalCluster with Dask's default worker settings instead of rattle's "
                         "(rattle.engines.WORKER_CONFIG: no statistical profiler, no MALLOC_TRIM_THRESHOLD_)")
    args = ap.parse_args()
    model = rattle.reference_case()
    vary = {"alpha": np.linspace(0.0, 0.5, args.alphas)}
    kw = dict(omega=(0.1, 3.0), omega_points=args.points, harmonics=32)
    # warm the numba cache and the imports in this process (as a second run would be)
    response_map(model, {"alpha": [0.25]}, omega=(0.5, 0.6), omega_points=3, harmonics=8, engine="serial")

    runs: dict[str, tuple[float, list[str]]] = {}
    if not args.skip_serial:
        t0 = time.perf_counter()
        r = response_map(model, vary, engine="serial", **kw)
        runs["serial"] = (time.perf_counter() - t0, _cells(r))
        print(f"serial               {runs['serial'][0]:7.1f} s", flush=True)
        _loads("serial", r)
    t0 = time.perf_counter()
    r = response_map(model, vary, engine="processes", workers=args.workers, **kw)
    runs["processes"] = (time.perf_counter() - t0, _cells(r))
    print(f"processes ({args.workers} workers) {runs['processes'][0]:7.1f} s  (worker start-up included)", flush=True)
    _loads("processes", r)
    if not args.no_dask:
        import dask
        from distributed import Client, LocalCluster

        from rattle.engines import local_cluster

        t0 = time.perf_counter()
        if args.dask_defaults:  # Dask's own worker settings (profiler on, MALLOC_TRIM_THRESHOLD_ set)
            with dask.config.set({}):
                cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
        else:  # rattle's worker settings (rattle.engines.WORKER_CONFIG)
            cluster = local_cluster(args.workers)
        client = Client(cluster)
        t_start = time.perf_counter() - t0
        try:
            t0 = time.perf_counter()
            r = response_map(model, vary, engine="dask", scheduler=client, **kw)
            runs["dask"] = (time.perf_counter() - t0, _cells(r))
            _loads("dask", r)
        finally:
            client.close()
            cluster.close()
        print(f"dask LocalCluster ({args.workers}) {runs['dask'][0]:7.1f} s  (cluster start-up {t_start:.1f} s apart)",
              flush=True)
    print()
    if "serial" in runs:
        for name in ("processes", "dask"):
            if name in runs:
                print(f"speed-up {name} over serial: {runs['serial'][0] / runs[name][0]:.2f}×")
    if "dask" in runs:
        print(f"dask / processes wall: {runs['dask'][0] / runs['processes'][0]:.2f}")
    ref = runs.get("serial", runs["processes"])[1]
    for name, (_, cells) in runs.items():
        print(f"{name:10s} identical to {'serial' if 'serial' in runs else 'processes'}: {cells == ref}")


if __name__ == "__main__":
    main()
