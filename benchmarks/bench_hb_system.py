"""Benchmark: harmonic balance of a System with n coordinates — residual + Jacobian, and a Newton
step full vs condensed onto the element deflections (``HBOptions(condense=True)``).

Run:  python benchmarks/bench_hb_system.py  [--harmonics 32] [--repeat 7]

Grounded chains of n inertias (n = 1 is the single equation of the reference case, run through
``Model.system()``): inertias 1 … n, a spring-damper to ground at both ends and between
neighbours, clutch and backlash elements on the first ⌈n/3⌉ neighbour pairs (m ≤ n), two forcing
harmonics. Times are CPU times of this thread (best of ``--repeat``), so that other load on the
machine inflates them less. Prints per n: the time of ``residual_jacobian``, of a full Newton step
(assembly + LU of the n·S × n·S Jacobian) and of a condensed step (LU of m·S × m·S), and the
largest difference between the two steps.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import rattle
from rattle.hb import HarmonicBalance, HBOptions
from rattle.model import Backlash, Clutch, ReducedElement, System


class _Holder:
    def __init__(self, system: System) -> None:
        self._system = system

    def system(self) -> System:
        return self._system


def grounded_chain(n: int) -> System:
    M = np.linspace(1.0, 2.0, n)
    Kt, Ct = np.zeros((n, n)), np.zeros((n, n))

    def link(i, j, k, c):
        w = np.zeros(n)
        w[i] = 1.0
        if j is not None:
            w[j] = -1.0
        Kt[:] += k * np.outer(w, w)
        Ct[:] += c * np.outer(w, w)

    link(0, None, 1.0, 0.03)
    link(n - 1, None, 0.4, 0.03)
    for i in range(n - 1):
        link(i, i + 1, 0.6, 0.02)
    elements = []
    for e in range(max(1, -(-n // 3))):
        if n == 1:
            break
        i = e % (n - 1)
        w = np.zeros(n)
        w[i], w[i + 1] = 1.0, -1.0
        law = Clutch(alpha=0.25, b=0.1) if e % 2 == 0 else Backlash(b=0.05)
        elements.append(ReducedElement(f"e{e}", w, w * 1.5 / M, law))
    amp = np.zeros((2, n))
    amp[0, 0], amp[1, 0], amp[0, -1] = 0.03, 0.01, 0.01
    mean = np.zeros(n)
    mean[0], mean[-1] = 0.04, -0.01
    return System(damping=Ct / M[:, None], stiffness=Kt / M[:, None], elements=tuple(elements), mean=mean / M,
                  cos=amp * np.cos(0.3) / M, sin=-amp * np.sin(0.3) / M,
                  coordinates=tuple(f"x{i}" for i in range(n)), angles=np.eye(n))


def best_time(f, repeat: int) -> float:
    f()
    best = float("inf")
    for _ in range(repeat):
        number = 20
        t0 = time.thread_time()
        for _ in range(number):
            f()
        best = min(best, (time.thread_time() - t0) / number)
    return best


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--harmonics", type=int, default=32)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args(argv)
    H = args.harmonics
    print(f"harmonic balance of a System, H = {H} — {sys.platform}, numpy {np.__version__}; CPU µs per call")
    print(f"{'n':>3} {'m':>3} {'unknowns':>9} {'residual_jacobian':>18} {'full step':>10} {'condensed':>10} {'max|Δdq|':>9}")
    rng = np.random.default_rng(1)
    for n in (1, 2, 3, 6):
        model = rattle.reference_case() if n == 1 else _Holder(grounded_chain(n))
        full = HarmonicBalance(model, HBOptions(harmonics=H))
        cond = HarmonicBalance(model, HBOptions(harmonics=H, condense=True))
        q = full.linear_solution(0.8) + 0.02 * rng.standard_normal(full.size)
        t_rj = best_time(lambda: full.residual_jacobian(q, 0.8), args.repeat)
        t_full = best_time(lambda: full.newton_step(q, 0.8), args.repeat)
        t_cond = best_time(lambda: cond.newton_step(q, 0.8), args.repeat)
        d = np.max(np.abs(full.newton_step(q, 0.8)[1] - cond.newton_step(q, 0.8)[1]))
        m = full.n_elements
        note = "" if m < n else "  (m = n: condensation not used)"
        print(f"{n:>3} {m:>3} {full.size:>9} {t_rj * 1e6:>18.1f} {t_full * 1e6:>10.1f} {t_cond * 1e6:>10.1f} {d:>9.1e}{note}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
