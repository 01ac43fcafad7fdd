"""Benchmark: exact monodromy of HB orbits (rattle.stability), single element and N-DOF chains.

Run:  python benchmarks/bench_floquet.py  [--repeat 7]

* n = 1: the reference case's frequency response at H = 32 (all its orbits) — time per orbit of
  the batched monodromy (``monodromy_batch``, all points at once, as the FRF post-processing
  does), and time per call of the continuation's ``FloquetMonitor`` (two orbits per call);
* n = 2, 3: hand-built grounded chains with two clearance elements, at H = 32, on orbits whose
  deflections cross breakpoints of both elements — time per orbit of the batched monodromy,
  and per call of the monitor-equivalent evaluation (two orbits, ψ_fold, ψ_pd, ψ_ns).

Figures are best-of-``--repeat`` CPU times (the machine is shared); run with OMP_NUM_THREADS=1.
``--single-only`` runs only the n = 1 part (it also runs against an older tree, for before/after:
``PYTHONPATH=<old tree>/src python benchmarks/bench_floquet.py --single-only``).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import rattle
from rattle.hb import HarmonicBalance, HBOptions
from rattle.stability import FloquetMonitor, monodromy_batch


def chain(n: int):
    """Grounded chains of 2 and 3 inertias with a clutch and a gear backlash (and, n = 3, a linear
    element), as in tests/stability/test_system_floquet.py, and an orbit crossing both elements'
    breakpoints, padded to 32 harmonics."""
    from rattle.model import Backlash, Clutch, Linear, ReducedElement, System

    inertia = [1.0, 2.0] if n == 2 else [1.0, 1.5, 0.8]
    Minv = np.diag(1.0 / np.array(inertia))
    Kt = np.zeros((n, n))
    Ct = np.zeros((n, n))
    Kt[0, 0], Ct[0, 0] = 1.0, 0.05
    for i in range(n - 1):
        w = np.zeros(n)
        w[i], w[i + 1] = 1.0, -1.0
        Kt += 0.3 * np.outer(w, w)
        Ct += 0.02 * np.outer(w, w)
    laws = [("clutch", Clutch(alpha=0.25, b=0.15), 2.0), ("gear", Backlash(b=0.1), 1.5), ("spring", Linear(), 0.7)]
    elements = []
    for e in range(n):
        w = np.zeros(n)
        w[e] = 1.0
        if e + 1 < n:
            w[e + 1] = -1.0
        name, law, Ke = laws[e]
        elements.append(ReducedElement(name, w, Minv @ w * Ke, law))
    system = System(damping=Minv @ Ct, stiffness=Minv @ Kt, elements=tuple(elements), mean=np.zeros(n),
                    cos=np.zeros((1, n)), sin=np.zeros((1, n)), coordinates=tuple(f"x{i}" for i in range(n)),
                    angles=np.eye(n))
    H = 32
    X = np.zeros((n, 2 * H + 1))
    X[0, 0], X[0, 1], X[0, H + 2] = 0.05, 0.4, 0.1
    X[1, 0], X[1, H + 1], X[1, 3] = -0.02, 0.15, 0.05
    if n == 3:
        X[2, 1], X[2, H + 3] = -0.05, 0.03
    return system, X


def n_dof(n: int, repeat: int) -> None:
    from types import SimpleNamespace

    from rattle.hb import FourierBasis
    from rattle.stability import _floquet, element_monodromy_batch

    system, X = chain(n)
    H = 32
    basis = FourierBasis(H, 256)
    P = 200
    Om = np.linspace(0.5, 2.5, P)
    Q = np.repeat(X[None], P, axis=0)
    S = np.einsum("en,pnk->pek", system.element_rows, Q)
    samples = basis.synthesize(S)
    hb = SimpleNamespace(system=system, basis=basis, period=1, model=None)
    q = X.ravel()
    d = np.zeros_like(q)
    d[1] = 1.0
    limit = _floquet.EIG_CONDITION_LIMIT
    for route, lim in (("eigen", limit), ("expm", -1.0)):
        _floquet.EIG_CONDITION_LIMIT = lim
        t = best(lambda: element_monodromy_batch(system, S, Om, samples), repeat)
        mon = FloquetMonitor(hb)

        def calls():
            for w in Om[::10]:
                mon(q, float(w), d, 0.0)

        tm = best(calls, repeat)
        segs = element_monodromy_batch(system, S[:1], Om[:1], samples[:1])[1].sum()
        print(f"n={n} (H=32, {P} orbits, {segs} crossings/period, {route:5s}): batched monodromy "
              f"{1e6 * t / P:8.1f} us/orbit; FloquetMonitor call {1e6 * tm / len(Om[::10]):8.1f} us/call")
    _floquet.EIG_CONDITION_LIMIT = limit


def best(fn, repeat: int) -> float:
    """Best-of-``repeat`` CPU time of the process (less disturbed by other jobs than wall time
    on a shared machine; numpy's BLAS should run single-threaded: OMP_NUM_THREADS=1)."""
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return min(times)


def single_element(repeat: int, orbits: str | None) -> None:
    model = rattle.reference_case()
    if orbits and Path(orbits).exists():
        data = np.load(orbits)
        Q, Om = data["Q"], data["omega"]
    else:
        frf = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)
        Q, Om = np.asarray(frf.coefficients), np.asarray(frf.omega)
        if orbits:
            np.savez(orbits, Q=Q, omega=Om)
    hb = HarmonicBalance(model, HBOptions(harmonics=32))
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
    parser.add_argument("--single-only", action="store_true", help="only the n = 1 part")
    parser.add_argument("--orbits", help="a .npz file keeping the reference FRF's orbits (computed and saved "
                        "when absent), so that runs on two trees time the same orbits")
    args = parser.parse_args(argv)
    single_element(args.repeat, args.orbits)
    if not args.single_only:
        for n in (2, 3):
            n_dof(n, args.repeat)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
