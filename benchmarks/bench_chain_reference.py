"""Accuracy on chains: harmonic balance against the exact N-DOF shooting reference.

Run:  python benchmarks/bench_chain_reference.py  [--harmonics 32] [--orbits 40]

For the chains of ``tests/test_chains.py`` (the reference clutch as a free two-inertia chain, a
grounded two-inertia system with a clutch element, the three-inertia free driveline with a
four-stage clutch damper and gear backlash) over whole frequency ranges:

* special points: ``rattle.frequency_response`` (H harmonics) against the exact reference of
  ``tests/_exact_branch.py`` (shooting continuation on the exact flow of ``rattle.timeint.ExactIntegrator``,
  every change of stability located by Brent to 1e-11, hidden-pair guard) — kinds in order and
  the worst |ΔΩ|;
* orbits: at up to ``--orbits`` points of each branch away from special points, the exact
  periodic orbit shot from the HB state — every element's rms (relative error) and the
  stability verdict;
* the stiff gear mesh (the driveline with its mesh 20 times stiffer than the clutch, Ω 0.2 … 2)
  at the front end's defaults (adaptive harmonics: H per row), orbits as above (issue 24: it
  failed at the default H = 32 before H was raised where the truncation demands it).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import rattle
from rattle.timeint import make_integrator, shoot_system_orbit

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import _exact_branch as xb  # noqa: E402
from _cases import hb_chain_state0 as _state  # noqa: E402
from test_chains import driveline, grounded_clutch, two_inertia  # noqa: E402

CASES = (
    ("two-inertia chain = reference clutch", lambda: two_inertia(3.0, 1.5), (0.1, 3.0)),
    ("grounded two-inertia, clutch element", grounded_clutch, (0.3, 2.0)),
    ("three-inertia driveline", driveline, (0.55, 1.0)),
    ("three-inertia driveline", driveline, (0.75, 2.3)),
)


def stiff_mesh() -> rattle.Chain:
    """The three-inertia driveline with its gear mesh 20 times stiffer than the clutch (issue 24:
    it failed at the default H = 32; the default run now raises H where the truncation demands)."""
    chain = driveline()
    clutch, gear = chain.elements
    return rattle.Chain(inertias=chain.inertias, links=chain.links, torques=chain.torques,
                        elements=(clutch, rattle.Element(name=gear.name, between=gear.between, stiffness=20.0,
                                                         law=gear.law)))


#: Cases run at the front end's defaults (adaptive harmonics), orbits only: the special points of
#: a run with dozens of them are not compared with the exact reference here.
DEFAULT_CASES = (("stiff gear mesh (K 20 against the clutch's 1)", stiff_mesh, (0.2, 2.0)),)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--harmonics", type=int, default=32)
    parser.add_argument("--orbits", type=int, default=40, help="orbits checked per case (default 40)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    for label, make, omega in CASES:
        model = make()
        t0 = time.perf_counter()
        frf = rattle.frequency_response(model, omega=omega, harmonics=args.harmonics, confirm_tori=False)
        t_hb = time.perf_counter() - t0
        t0 = time.perf_counter()
        ref = xb.exact_special_points(model, omega, x0=_state(frf, 0), max_step=1e-2, max_domega=5e-3)
        t_ref = time.perf_counter() - t0
        hb = [(s.kind, s.omega) for s in frf.special_points]
        same = [k for k, _ in hb] == [k for k, _ in ref.special]
        worst = max((abs(a[1] - b[1]) for a, b in zip(hb, ref.special)), default=0.0)
        kinds = [k for k, _ in hb]
        print(f"{label}, Ω = {omega[0]} … {omega[1]}: HB {len(hb)} special points "
              f"({kinds.count('fold')} fold, {kinds.count('period_doubling')} PD, {kinds.count('neimark_sacker')} NS) "
              f"in {t_hb:.1f} s; exact reference {len(ref.special)} in {t_ref:.0f} s; "
              f"kinds in order {'identical' if same else 'DIFFER'}; worst |ΔΩ| {worst:.1e}")
        if not same:
            print("   HB   ", [(k, round(w, 6)) for k, w in hb])
            print("   exact", [(k, round(w, 6)) for k, w in ref.special])
        _orbits(model, frf, args.orbits)
    for label, make, omega in DEFAULT_CASES:
        model = make()
        t0 = time.perf_counter()
        frf = rattle.frequency_response(model, omega=omega)
        H = np.asarray(frf.extra_columns["harmonics"])
        print(f"{label}, Ω = {omega[0]} … {omega[1]}, defaults: {frf.status.name.lower()}, {len(frf)} rows in "
              f"{time.perf_counter() - t0:.0f} s, uncovered {frf.uncovered}, H per row "
              f"{dict(zip(*(v.tolist() for v in np.unique(H, return_counts=True))))}, "
              f"{len(frf.special_points)} special points")
        _orbits(model, frf, args.orbits)
    return 0


def _orbits(model, frf, count: int) -> None:
    """Every element's rms and the stability of ``count`` rows against the exact orbit shot from
    the row's state (rows within 5e-3 of a special point skipped)."""
    system = model.system()
    special = np.array([s.omega for s in frf.special_points])
    integ = make_integrator(system)
    worst_rms, n, agree = 0.0, 0, 0
    for i in np.linspace(0, len(frf) - 1, count).astype(int):
        w = float(frf.omega[i])
        if special.size and np.min(np.abs(special - w)) < 5e-3:
            continue
        orbit = shoot_system_orbit(system, w, _state(frf, i), integrator=integ)
        if not orbit.converged:
            continue
        n += 1
        agree += bool(frf.stable[i]) == orbit.stable
        for name in model.element_names:
            worst_rms = max(worst_rms, abs(frf.element(name)["rms"][i] / orbit.measures.element(name)["rms"] - 1))
    print(f"   orbits: {n} exact orbits, stability agrees at {agree}/{n}, worst element rms relative error {worst_rms:.1e}")


if __name__ == "__main__":
    sys.exit(main())
