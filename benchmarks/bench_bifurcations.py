"""Random cross-validation of the special points of the frequency response against exact shooting.

For N random continuous piecewise-linear cases (backlash, clutch, asymmetric multi-stage laws;
clearances 0.05–1 rad; damping 0.02–0.12; mean load and up to three harmonics with random
phases) the folds and period doublings of the period-1 branch found by
``rattle.frequency_response(model, omega=(0.2, 2.5))`` at default settings (H = 32) are compared
with the exact reference of ``tests/_exact_branch.py`` (pseudo-arclength continuation of the
shooting problem on the exact piecewise-linear flow, steps ≤ 2e-3, hidden-pair guard, Brent
location to 1e-11). A point is found when an HB point of the same kind lies within 1e-4 in Ω;
an HB point with no exact counterpart within 1e-4 is spurious.

Times are process (CPU) seconds, the figure that means something on a shared machine; with
``--references FILE`` (written by ``--save-references``) the reference times are those saved.

Run:  python benchmarks/bench_bifurcations.py [--cases 40] [--seed 2026] [--verbose]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import rattle  # noqa: E402
from _exact_branch import Accepted, diagnose, hb_special_points, iter_cases, match  # noqa: E402

TOL = 1e-4


def _saved_cases(path: str, seed: int, family: str):
    """Accepted cases rebuilt from the generator, with the exact points read from ``path``."""
    from _exact_branch import FAMILIES, ExactBranch

    saved = {}
    with open(path) as fh:
        for line in fh:
            rec = json.loads(line)
            if rec["seed"] == seed and rec.get("family", "mixed") == family:
                saved[rec["index"]] = rec
    rng = np.random.default_rng(seed)
    for i in range(max(saved, default=-1) + 1):
        case = FAMILIES[family](rng)
        if i in saved:
            rec = saved[i]
            assert rec["label"] == case.label, (rec["label"], case.label)
            ref = ExactBranch(special=[tuple(p) for p in rec["special"]], points=np.empty((0, 5)),
                              states=[np.asarray(x) for x in rec.get("states", [])] or None,
                              seconds=rec["seconds"], cpu=rec.get("cpu", rec["seconds"]))
            yield Accepted(case, ref, i)
        else:
            yield (i, case.label, "rejected when the references were saved")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=40, help="accepted random cases (default 40)")
    ap.add_argument("--seed", type=int, default=2026, help="seed of the case generator (default 2026)")
    ap.add_argument("--family", choices=("mixed", "gear"), default="mixed",
                    help="case family: mixed (backlash, clutch, asymmetric multi-stage, 1-3 harmonics; default) or "
                         "gear (near examples/gear_backlash.toml, narrow period-doubling bubbles)")
    ap.add_argument("--max-steps", type=int, default=200_000,
                    help="step budget of one exact reference; a longer branch rejects the case (default 200000)")
    ap.add_argument("--save-references", metavar="FILE",
                    help="write every accepted case's exact special points to FILE (JSON lines)")
    ap.add_argument("--references", metavar="FILE",
                    help="take the exact special points from FILE (written by --save-references with the same "
                         "seed) instead of recomputing them: compares another version's HB with the same reference")
    ap.add_argument("--verbose", action="store_true", help="print the HB rows around every miss")
    args = ap.parse_args(argv)

    t0 = time.perf_counter()
    found = total = spurious = 0
    errors: list[float] = []
    hb_counts: list[int] = []
    t_hb = t_ref = 0.0
    failed_cases = 0
    cases: list[Accepted] = []
    rejected: list[tuple[int, str, str]] = []
    print(f"{'case':>4} {'law':<10} {'exact':>5} {'HB':>4} {'found':>5} {'spur':>4} {'worst dΩ':>9} "
          f"{'HB cpu':>6} {'ref cpu':>7}  missed / spurious", flush=True)
    if args.references:
        stream = _saved_cases(args.references, args.seed, args.family)
    else:
        stream = iter_cases(args.seed, family=args.family, max_steps=args.max_steps)
    save = open(args.save_references, "w") if args.save_references else None
    while len(cases) < args.cases and len(cases) + len(rejected) < 4 * args.cases + 10:
        acc = next(stream)
        if not isinstance(acc, Accepted):
            rejected.append(acc)
            print(f"{acc[0]:>4} rejected: {acc[2]}", flush=True)
            continue
        cases.append(acc)
        if save is not None:
            save.write(json.dumps({"seed": args.seed, "family": args.family, "index": acc.index,
                                   "label": acc.case.label,
                                   "special": acc.reference.special, "seconds": acc.reference.seconds,
                                   "cpu": acc.reference.cpu,
                                   "states": [list(map(float, x)) for x in acc.reference.states]}) + "\n")
            save.flush()
        t = time.process_time()
        frf = rattle.frequency_response(acc.case.model, omega=acc.case.omega, throw=False)
        dt = time.process_time() - t
        t_hb += dt
        t_ref += acc.reference.cpu
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
        status = getattr(frf, "status", None)
        bad_status = status is not None and not getattr(status, "success", True)
        note = "; ".join(([f"HB status {status.name}"] if bad_status else [])
                         + [f"MISSED {k} {w:.6f}" for k, w in m.missed]
                         + [f"SPURIOUS {k} {w:.6f}" for k, w in m.spurious])
        print(f"{acc.index:>4} {acc.case.label.split()[0]:<10} {len(acc.reference.special):>5} {len(hb):>4} "
              f"{len(m.pairs):>5} {len(m.spurious):>4} {worst:>9.2e} {dt:>6.2f} {acc.reference.cpu:>7.2f}  {note}",
              flush=True)
        if args.verbose and (m.missed or m.spurious):
            print("      " + acc.case.label)
            for p in m.missed + m.spurious:
                print(diagnose(frf, p, acc.reference.special, acc.reference.states))
    err = np.asarray(errors)
    print()
    print(f"family {args.family}, seed {args.seed}: {len(cases)} cases accepted, {len(rejected)} rejected "
          f"({time.perf_counter() - t0:.0f} s in all)")
    for i, label, why in rejected:
        print(f"  rejected #{i}: {why}  [{label}]")
    print(f"special points found / total exact : {found} / {total}")
    print(f"spurious HB special points         : {spurious}")
    print(f"cases with a miss or a spurious    : {failed_cases} / {len(cases)}")
    if err.size:
        print(f"located |ΔΩ| worst / median        : {err.max():.2e} / {np.median(err):.2e}")
    print(f"HB special points per case         : min {min(hb_counts, default=0)}, median "
          f"{np.median(hb_counts) if hb_counts else 0:.0f}, max {max(hb_counts, default=0)}")
    print(f"CPU time HB (defaults) / exact ref.: {t_hb:.1f} s / {t_ref:.1f} s "
          f"(per case {t_hb / max(len(cases), 1):.2f} s / {t_ref / max(len(cases), 1):.2f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
