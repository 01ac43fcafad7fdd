"""Random cross-validation of the special points of the frequency response against exact shooting.

For N random continuous piecewise-linear cases (backlash, clutch, asymmetric multi-stage laws;
clearances 0.05–1 rad; damping 0.02–0.12; mean load and up to three harmonics with random
phases) the folds and period doublings of the period-1 branch found by
``rattle.frequency_response(model, omega=(0.2, 2.5))`` at default settings (H = 32) are compared
with the exact reference of ``tests/_exact_branch.py`` (pseudo-arclength continuation of the
shooting problem on the exact piecewise-linear flow, steps ≤ 2e-3, hidden-pair guard, Brent
location to 1e-11). A point is found when an HB point of the same kind lies within 1e-4 in Ω;
an HB point with no exact counterpart within 1e-4 is spurious.

Run:  python benchmarks/bench_bifurcations.py [--cases 40] [--seed 2026] [--verbose]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import rattle  # noqa: E402
from _exact_branch import accepted_cases, diagnose, hb_special_points, match  # noqa: E402

TOL = 1e-4


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=40, help="accepted random cases (default 40)")
    ap.add_argument("--seed", type=int, default=2026, help="seed of the case generator (default 2026)")
    ap.add_argument("--verbose", action="store_true", help="print the HB rows around every miss")
    args = ap.parse_args(argv)

    t0 = time.perf_counter()
    cases, rejected = accepted_cases(args.seed, args.cases)
    t_gen = time.perf_counter() - t0
    found = total = spurious = 0
    errors: list[float] = []
    hb_counts: list[int] = []
    t_hb = t_ref = 0.0
    failed_cases = 0
    print(f"{'case':>4} {'law':<10} {'exact':>5} {'HB':>4} {'found':>5} {'spur':>4} {'worst dΩ':>9} "
          f"{'HB s':>6} {'ref s':>6}  missed / spurious")
    for acc in cases:
        t = time.perf_counter()
        frf = rattle.frequency_response(acc.case.model, omega=acc.case.omega, throw=False)
        dt = time.perf_counter() - t
        t_hb += dt
        t_ref += acc.reference.seconds
        hb = hb_special_points(frf)
        m = match(acc.reference.special, hb, TOL)
        found += len(m.pairs)
        total += len(acc.reference.special)
        spurious += len(m.spurious)
        errors += m.errors
        hb_counts.append(len(hb))
        if m.missed or m.spurious:
            failed_cases += 1
        worst = max(m.errors) if m.errors else float("nan")
        note = "; ".join([f"MISSED {k} {w:.6f}" for k, w in m.missed] + [f"SPURIOUS {k} {w:.6f}" for k, w in m.spurious])
        print(f"{acc.index:>4} {acc.case.label.split()[0]:<10} {len(acc.reference.special):>5} {len(hb):>4} "
              f"{len(m.pairs):>5} {len(m.spurious):>4} {worst:>9.2e} {dt:>6.2f} {acc.reference.seconds:>6.2f}  {note}")
        if args.verbose and (m.missed or m.spurious):
            print("      " + acc.case.label)
            for p in m.missed + m.spurious:
                print(diagnose(frf, p, acc.reference.special))
    err = np.asarray(errors)
    print()
    print(f"seed {args.seed}: {len(cases)} cases accepted, {len(rejected)} rejected "
          f"({time.perf_counter() - t0:.0f} s in all; case generation with references {t_gen:.0f} s)")
    for i, label, why in rejected:
        print(f"  rejected #{i}: {why}  [{label}]")
    print(f"special points found / total exact : {found} / {total}")
    print(f"spurious HB special points         : {spurious}")
    print(f"cases with a miss or a spurious    : {failed_cases} / {len(cases)}")
    if err.size:
        print(f"located |ΔΩ| worst / median        : {err.max():.2e} / {np.median(err):.2e}")
    print(f"HB special points per case         : min {min(hb_counts, default=0)}, median "
          f"{np.median(hb_counts) if hb_counts else 0:.0f}, max {max(hb_counts, default=0)}")
    print(f"time HB (defaults) / exact ref.    : {t_hb:.1f} s / {t_ref:.1f} s "
          f"(per case {t_hb / max(len(cases), 1):.2f} s / {t_ref / max(len(cases), 1):.2f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
