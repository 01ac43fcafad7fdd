"""Benchmark: exact integration of a System (n coordinates, m clearance elements).

Run:  python benchmarks/bench_system_flow.py  [--repeat 5] [--periods 100]

Prints, best of ``--repeat`` runs, the time to integrate ``--periods`` forcing periods:

(a) n = 1: the paper's clutch (reference case) as a System (``ExactIntegrator(model.system())``:
    the stage-matrix path) next to ``ExactIntegrator(model)`` (the compiled scalar path: the event
    kernel's march, ``timeint/_event_kernel.py``) and that path's Python march (the reference,
    ``_compiled = False``), at Ω = 0.3, 0.8, 1.6, and the largest differences of their final states;
(b) n = 3: a grounded 3-inertia chain (M = diag(1, 2, 1.5), clutch between 1 and 2, gear
    backlash between 2 and 3, two forcing harmonics) and n = 2: the free version of that chain
    (relative coordinates; inside the gear gap an undamped rigid relative mode: a defective
    stage) — with the number of segments, and one solve_ivp run (DOP853, rtol 1e-12,
    atol 1e-14) over 5 periods for scale;
(c) shooting: ``shoot_system_orbit`` vs ``shoot_periodic_orbit`` (n = 1), and for the chain.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

import rattle
from rattle.model import Backlash, Chain, Clutch, Element, Link, Torque
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit, shoot_system_orbit


def best_of(repeat: int, fn):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def chain(free: bool):
    links = [Link(between=(1, 2), damping=0.05), Link(between=(2, 3), damping=0.0 if free else 0.04)]
    if not free:
        links += [Link(between=(1, 0), stiffness=0.5, damping=0.03), Link(between=(3, 0), stiffness=0.3, damping=0.02)]
    torques = [Torque(inertia=1, mean=0.05, amplitudes=(0.1, 0.04), phases=(0.3, -1.0))]
    if free:
        torques.append(Torque(inertia=3, mean=-0.05))
    return Chain(
        inertias=(1.0, 2.0, 1.5), links=tuple(links),
        elements=(Element(name="clutch", between=(1, 2), stiffness=1.0, law=Clutch(alpha=0.25, b=0.1)),
                  Element(name="gear", between=(2, 3), stiffness=2.0, law=Backlash(b=0.05))),
        torques=tuple(torques),
    ).system()


def rest(system):
    z = np.zeros(2 * system.n)
    z[: system.n] = system.static_equilibrium()
    return z


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--periods", type=int, default=100)
    args = ap.parse_args()
    P = args.periods

    print(f"(a) n = 1, reference case, {P} periods from (0.01, 0)")
    print("    Omega   scalar, compiled   scalar, Python march   stage-matrix path   Python/compiled   segments"
          "   max |dz| Python, stage-matrix")
    model = rattle.reference_case()
    system = model.system()
    for om in (0.3, 0.8, 1.6):
        T = 2 * math.pi / om
        ex, py, si = ExactIntegrator(model), ExactIntegrator(model), ExactIntegrator(system)
        py._compiled = False  # the scalar path's Python march (the reference)
        te, a = best_of(args.repeat, lambda: ex.propagate([0.01, 0.0], 0.0, P * T, om))
        tp, c = best_of(args.repeat, lambda: py.propagate([0.01, 0.0], 0.0, P * T, om))
        ts, b = best_of(args.repeat, lambda: si.propagate([0.01, 0.0], 0.0, P * T, om))
        dz_python, dz_stage = np.abs(a.state1 - c.state1).max(), np.abs(a.state1 - b.state1).max()
        print(f"    {om:5.2f}   {1e3 * te:13.1f} ms   {1e3 * tp:17.1f} ms   {1e3 * ts:14.1f} ms   {tp / te:15.1f}"
              f"   {b.n_segments:8d}   {dz_python:.1e}, {dz_stage:.1e}")

    print(f"\n(b) chains, {P} periods from the static equilibrium at rest")
    print("    system              Omega   stage-matrix path   segments   per segment   solve_ivp (5 periods)")
    for name, sysm in (("grounded n=3, m=2", chain(False)), ("free n=2, m=2", chain(True))):
        for om in (0.4, 1.0):
            T = 2 * math.pi / om
            si = ExactIntegrator(sysm)
            z0 = rest(sysm)
            ts, b = best_of(args.repeat, lambda: si.propagate(z0, 0.0, P * T, om))

            def ivp():
                def f(t, z):
                    n = sysm.n
                    return np.concatenate((z[n:], sysm.forcing(t, om) - sysm.damping @ z[n:] - sysm.restoring(z[:n])))
                return solve_ivp(f, (0.0, 5 * T), z0, method="DOP853", rtol=1e-12, atol=1e-14, max_step=T / 50)

            tr, _ = best_of(1, ivp)
            print(f"    {name:18s}  {om:5.2f}   {1e3 * ts:11.1f} ms   {b.n_segments:8d}"
                  f"   {1e6 * ts / b.n_segments:8.0f} us   {1e3 * tr:9.0f} ms")

    print("\n(c) shooting (tol 1e-12, measures included)")
    for om in (0.8, 1.6):
        t1, _ = best_of(args.repeat, lambda: shoot_periodic_orbit(model, om, [0.05, 0.0]))
        t2, o = best_of(args.repeat, lambda: shoot_system_orbit(system, om, [0.05, 0.0]))
        print(f"    n = 1, Omega = {om}: shoot_periodic_orbit {1e3 * t1:.1f} ms, shoot_system_orbit {1e3 * t2:.1f} ms"
              f" ({o.iterations} Newton steps)")
    for name, sysm in (("grounded n=3", chain(False)), ("free n=2", chain(True))):
        om = 1.0
        t2, o = best_of(args.repeat, lambda: shoot_system_orbit(sysm, om, rest(sysm)))
        print(f"    {name}, Omega = {om}: shoot_system_orbit {1e3 * t2:.1f} ms ({o.iterations} Newton steps, "
              f"converged {o.converged}, |multipliers| max {np.abs(o.multipliers).max():.4f})")


if __name__ == "__main__":
    main()
