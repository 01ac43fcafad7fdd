"""Benchmark: exact monodromy of HB orbits (rattle.stability), single element and N-DOF chains.

Run:  python benchmarks/bench_floquet.py  [--repeat 7]

* n = 1: the reference case's frequency response at H = 32 (all its orbits) — time per orbit of
  the batched monodromy (``monodromy_batch``, all points at once, as the FRF post-processing
  does), and time per call of the continuation's ``FloquetMonitor`` (two orbits per call);
* n = 2, 3: hand-built grounded chains with two clearance elements, at H = 32, on orbits whose
  deflections cross breakpoints of both elements — time per orbit of the batched monodromy,
  and per call of the monitor-equivalent evaluation (two orbits, ψ_fold, ψ_pd, ψ_ns);
* ψ_ns for n = 3, 10, 30, 60 (``--neimark-sacker-only``): from the multipliers, as evaluated, against
  the determinant of the bialternate product it replaced (up to n = 30: n = 60 takes over a minute).

Figures are best-of-``--repeat`` CPU times (the machine is shared); run with OMP_NUM_THREADS=1.
Before/after for n = 1: ``--against <older tree>/src`` times the older package interleaved with
this one in the same process (e.g. ``git archive <commit> | tar -x -C /tmp/old``), on the same
orbits (``--orbits file.npz`` keeps them between runs).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import rattle
from rattle.stability import FloquetMonitor


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


def _before_package(src: str):
    """The package of an older tree (``src``/rattle) imported as ``rattle_before`` (its imports
    are relative), so that both versions are timed interleaved in one process."""
    import importlib
    import shutil
    import sys
    import tempfile

    tmp = tempfile.mkdtemp(prefix="bench_floquet_")
    shutil.copytree(Path(src) / "rattle", Path(tmp) / "rattle_before")
    sys.path.insert(0, tmp)
    return importlib.import_module("rattle_before")


def single_element(repeat: int, orbits: str | None, against: str | None) -> None:
    model = rattle.reference_case()
    if orbits and Path(orbits).exists():
        data = np.load(orbits)
        Q, Om = data["Q"], data["omega"]
    else:
        frf = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)
        Q, Om = np.asarray(frf.coefficients), np.asarray(frf.omega)
        if orbits:
            np.savez(orbits, Q=Q, omega=Om)
    packages = [("this tree", rattle)] + ([("before", _before_package(against))] if against else [])
    P = len(Om)
    d = np.zeros_like(Q[0])
    d[1] = 1.0
    idx = range(0, P, max(1, P // 50))
    timings: dict[str, dict[str, list[float]]] = {}
    setups = []
    for name, pkg in packages:
        m = pkg.reference_case()
        hb = pkg.hb.HarmonicBalance(m, pkg.hb.HBOptions(harmonics=32))
        st = m.elastic.stages
        X = hb.basis.synthesize(Q)
        mon = pkg.stability.FloquetMonitor(hb)
        batch = (lambda pkg=pkg, X=X, st=st, m=m: pkg.stability.monodromy_batch(Q, Om, X, st.breakpoints, m.k * st.slopes, m.c))

        def monitor_all(mon=mon):
            for i in idx:
                mon(Q[i], float(Om[i]), d, 0.0)

        setups.append((name, batch, monitor_all))
        timings[name] = {"batch": [], "monitor": []}
    for _ in range(repeat):  # interleaved: both versions see the same load
        for name, batch, monitor_all in setups:
            timings[name]["batch"].append(best(batch, 1) / P)
            timings[name]["monitor"].append(best(monitor_all, 1) / len(idx))
    for name, t in timings.items():
        print(f"n=1 (reference case, H=32, {P} orbits), {name:9s}: batched monodromy {1e6 * min(t['batch']):7.1f} us/orbit "
              f"(median {1e6 * np.median(t['batch']):6.1f}); FloquetMonitor call {1e6 * min(t['monitor']):7.1f} us "
              f"(median {1e6 * np.median(t['monitor']):6.1f})")


def neimark_sacker(repeat: int, sizes: tuple[int, ...] = (3, 10, 30, 60), determinant_up_to: int = 30) -> None:
    """ψ_ns = Π_{i<j}(μ_i μ_j − 1) of a (2n × 2n) monodromy as ``floquet_test_functions`` evaluates
    it (from the multipliers, O(n³)) against the LU determinant of the bialternate product
    det(M ⊙ M − I) it replaced (O(n⁶): k(k−1)/2 = 7140 rows for n = 60, 410 MB, over a minute),
    on monodromy-like matrices (spectral radius ~ 1), and their relative difference."""
    from rattle.stability import floquet_test_functions, second_compound

    rng = np.random.default_rng(0)
    for n in sizes:
        k = 2 * n
        M = rng.standard_normal((k, k)) * 0.9 / np.sqrt(k)
        t_new = best(lambda M=M: floquet_test_functions(M), repeat)
        line = f"n={n:3d} (2n = {k:3d}): floquet_test_functions (psi_ns from the multipliers) {1e3 * t_new:8.3f} ms"
        if n <= determinant_up_to:
            def det(M=M):
                B = second_compound(M)
                return np.linalg.det(B - np.eye(B.shape[-1]))

            t_old = best(det, max(1, repeat if n < 20 else 1))
            old = det()
            diff = abs(floquet_test_functions(M)[2] - old) / abs(old)
            line += f"; psi_ns = det(M ⊙ M − I) alone {1e3 * t_old:10.3f} ms; relative difference {diff:.1e}"
        print(line)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--single-only", action="store_true", help="only the n = 1 part")
    parser.add_argument("--against", help="src directory of an older tree (e.g. from `git archive`): its n = 1 "
                        "figures are timed interleaved with this tree's, in the same process")
    parser.add_argument("--orbits", help="a .npz file keeping the reference FRF's orbits (computed and saved "
                        "when absent), so that runs on two trees time the same orbits")
    parser.add_argument("--neimark-sacker-only", action="store_true", help="only the ψ_ns timings (n = 3 … 60)")
    args = parser.parse_args(argv)
    if args.neimark_sacker_only:
        neimark_sacker(args.repeat)
        return 0
    single_element(args.repeat, args.orbits, args.against)
    if not args.single_only:
        for n in (2, 3):
            n_dof(n, args.repeat)
        neimark_sacker(args.repeat)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
