"""Benchmark: BLAS/OpenMP threads on rattle's small dense problems, measured both ways.

Run:  python benchmarks/bench_threads.py  [--repeat 3] [--harmonics 32]

The reference case's whole frequency response (Ω = 0.1 … 3.0) with Hill's method (an eigenvalue
problem of size 2(2H + 1) per point) and with the default monodromy, and the command
``rattle frf`` on the same case, each in a child process with its BLAS thread count fixed by
``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` and ``MKL_NUM_THREADS`` = 1 and = the number of cores
(the library's default on this machine), taken alternately. CPU (user + system of the child,
every thread counted) and wall time, best and median of ``--repeat``; the same rows in both (Ω,
stability), checked.

Why it matters: the matrices are small (2H + 1 = 65 … 257 rows), and a BLAS thread pool spends
more time handing work to its threads and spinning while waiting for it than it saves; on a
shared machine the spinning threads take the cores from the other processes. The command line
(``rattle …``) and its worker processes therefore run with one BLAS thread unless the
environment says otherwise (``rattle.cli.app.single_threaded_blas``, ``rattle.engines``' worker
environment).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

_CHILD = r"""
import hashlib, json, sys
import numpy as np
import rattle
method, harmonics = sys.argv[1], int(sys.argv[2])
frf = rattle.frequency_response(rattle.reference_case(), omega=(0.1, 3.0), harmonics=harmonics, stability=method)
digest = hashlib.sha1(np.ascontiguousarray(frf.omega).tobytes() + np.asarray(frf.stable).tobytes()).hexdigest()
print(json.dumps({"points": int(len(frf.omega)), "digest": digest}))
"""


def _env(threads: int | None) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src")
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # as installed: bytecode written once
    for var in VARS:
        env.pop(var, None)
        if threads is not None:
            env[var] = str(threads)
    return env


def _run(argv: list[str], threads: int | None) -> tuple[float, float, str]:
    """(CPU s of the child and every thread, wall s, stdout) of one run."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, env=_env(threads), stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    out = proc.stdout.read() if proc.stdout else ""
    _pid, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if proc.stdout:
        proc.stdout.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"failed: {' '.join(argv)}")
    return usage.ru_utime + usage.ru_stime, wall, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--harmonics", type=int, default=32)
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"python {sys.version.split()[0]}, {cores} cores, load average {load:.2f}; reference case, "
          f"H = {args.harmonics}; best (median) of {args.repeat}, s\n")
    with tempfile.TemporaryDirectory() as tmp:
        jobs = {
            "frequency_response, Hill": [sys.executable, "-c", _CHILD, "hill", str(args.harmonics)],
            "frequency_response, monodromy": [sys.executable, "-c", _CHILD, "monodromy", str(args.harmonics)],
            "rattle frf (command)": [sys.executable, "-m", "rattle", "frf", str(ROOT / "examples" / "reference_clutch.toml"),
                                     "--harmonics", str(args.harmonics), "-o", str(Path(tmp) / "out")],
        }
        print(f"{'':32} {'threads':>7} {'CPU':>15} {'wall':>15}  same rows")
        for label, argv in jobs.items():
            _run(argv, 1)  # warm-up: bytecode and numba's cache written
            runs: dict[int, list[tuple[float, float, str]]] = {1: [], cores: []}
            for _ in range(args.repeat):
                for n in runs:
                    runs[n].append(_run(argv, n))
            outs = {r[2].strip() for rs in runs.values() for r in rs} if "command" not in label else set()
            same = "yes" if len(outs) <= 1 else "NO"
            for n, rs in runs.items():
                cpu, wall = [r[0] for r in rs], [r[1] for r in rs]
                print(f"{label:32} {n:>7} {min(cpu):7.2f} ({statistics.median(cpu):5.2f}) "
                      f"{min(wall):7.2f} ({statistics.median(wall):5.2f})  {same if n == 1 else ''}")
                label = ""


if __name__ == "__main__":
    main()
