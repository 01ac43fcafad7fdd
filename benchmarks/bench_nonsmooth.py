"""Benchmark: the exact event-driven orbit of a discontinuous law (preload, Coulomb friction) and what
the harmonic balance's regularisation does to it.

Run:  OMP_NUM_THREADS=1 python benchmarks/bench_nonsmooth.py

For each case (δ'' + c δ' + k [f(δ) + r sgn δ'] = F_m + F_p cos(Ωt + 0.3), f = δ + T_p sgn δ):

* the exact periodic orbit by shooting (``shoot_nonsmooth_orbit``): its rms, multipliers, stick
  time, events and the time to find it;
* the regularised harmonic balance (``RegularisedBalance`` with this law's ``regularised``)
  followed from ε = 0.1 down to 1e-3 by ``regularisation_limit``, started from the exact orbit's
  spectrum: the relative rms error of each rung against the exact orbit, and of the Richardson
  extrapolation.

Figures are wall-clock times on a shared machine.
"""

from __future__ import annotations

import math
import time

import numpy as np

from rattle.analysis._regularisation import regularisation_limit
from rattle.hb import HBOptions
from rattle.hb._regularised import RegularisedBalance
from rattle.model import Excitation
from rattle.model._discontinuous import Friction, NonsmoothLaw, Preload
from rattle.model import System
from rattle.timeint import ExactIntegrator, shoot_nonsmooth_orbit

C, FM, FP, PHASE = 0.05, 0.01, 0.3, 0.3
CASES = [  # (T_p, r, Ω)
    (0.05, 0.02, 0.5),
    (0.05, 0.1, 0.5),
    (0.2, 0.05, 0.6),
    (0.2, 0.0, 0.6),
    (0.2, 0.0, 1.2),
]


def main() -> None:
    for tp, r, w in CASES:
        law = NonsmoothLaw(elastic=Preload(preload=tp), friction=Friction(levels=r))
        sysx = System.single(damping=C, stiffness=1.0, law=law,
                               excitation=Excitation(mean=FM, amplitudes=(FP,), phases=(PHASE,)))
        integ = ExactIntegrator(sysx)
        T = 2 * math.pi / w
        x = np.array([0.3, 0.0])
        for _ in range(60):  # settle
            x = integ.propagate(x, 0.0, T, w).state1
        t0 = time.perf_counter()
        orbit = shoot_nonsmooth_orbit(sysx, w, x, integrator=integ)
        t_shoot = time.perf_counter() - t0
        tr = orbit.trajectory
        events = {k: tr.event_kind.count(k) for k in sorted(set(tr.event_kind))}
        print(f"T_p = {tp}, r = {r}, Ω = {w}: exact rms = {orbit.rms:.10f}, |μ| = "
              f"{np.array2string(np.abs(orbit.multipliers), precision=4)}, stick/lock time = {tr.stick_time:.3f}, "
              f"events {events}, shooting {t_shoot * 1e3:.1f} ms ({orbit.iterations} Newton steps)")

        q0 = tr.fourier(32)

        def problem(eps: float, harmonics: int, sysx: System = sysx) -> RegularisedBalance:
            return RegularisedBalance(C, sysx, FM, (FP,), (PHASE,), regularisation=eps, length_scale=0.3,
                                      frequency_scale=1.0, options=HBOptions(harmonics=harmonics))

        t0 = time.perf_counter()
        try:
            lim = regularisation_limit(problem, w, q0, eps_start=0.1, eps_min=1e-3)
        except Exception as exc:  # noqa: BLE001 - a benchmark reports and goes on
            print(f"    regularised HB: {exc}")
            continue
        t_hb = time.perf_counter() - t0
        for s in lim.steps:
            print(f"    ε = {s.eps:<9.4g} H = {s.harmonics:<4d} rms = {s.rms:.8f}  error {(s.rms - orbit.rms) / orbit.rms:+.2e}")
        print(f"    Richardson rms = {lim.extrapolated_rms:.8f}  error "
              f"{(lim.extrapolated_rms - orbit.rms) / orbit.rms:+.2e}   (ladder {t_hb:.1f} s)")


if __name__ == "__main__":
    main()
