"""Random map cells against exact references: other clearances than the reference clutch.

Each random case (tests/_exact_branch.random_case: a backlash, a clutch or an asymmetric
multi-stage law, clearances 0.05–1 rad, damping 0.02–0.12, up to three harmonics with random
phases, random inertia scale) is one map cell — frequency response with sub-harmonic branches,
branches solved on the Ω grid, the attractor search — checked as in bench_map_reference.py:
every stable solution the cell reports at every ``--every``-th grid frequency closes on the exact
flow (period, rms to 1e-3, stability), and every distinct attractor of a dense census
(``--starts`` random initial states simulated exactly) is one the cell reports, with ``rattle``
true wherever one impacts.

Run: ``python benchmarks/bench_map_random.py [--cases 8] [--seed 7] [--points 60]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from bench_map_reference import check_model  # noqa: E402
from _exact_branch import random_case  # noqa: E402

from rattle.analysis._settings import RunSettings  # noqa: E402
from rattle.hb import HBOptions  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=8)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--points", type=int, default=60)
    ap.add_argument("--every", type=int, default=4)
    ap.add_argument("--starts", type=int, default=16)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    dense_rng = np.random.default_rng(args.seed + 1)
    run = RunSettings.make(HBOptions(harmonics=32), None, None)
    totals: dict = {}
    misses: list[str] = []
    t0 = time.perf_counter()
    for i in range(args.cases):
        case = random_case(rng)
        grid = np.linspace(case.omega[0], case.omega[1], args.points)
        t1 = time.perf_counter()
        try:
            t, m, census = check_model(case.model, grid, run, every=args.every, starts=args.starts, rtol=1e-3,
                                       rng=dense_rng, label=f"#{i}")
        except Exception as exc:  # a failure of the cell is a finding, not a crash of the benchmark
            misses.append(f"#{i} [{case.label}]: {type(exc).__name__}: {exc}")
            print(f"#{i} {case.label}: FAILED {type(exc).__name__}: {exc}", flush=True)
            continue
        for k, v in t.items():
            totals[k] = max(totals.get(k, 0.0), v) if k == "worst_rms" else totals.get(k, 0) + v
        misses += [f"{x} [{case.label}]" for x in m]
        print(f"#{i} {case.label}: {time.perf_counter() - t1:.0f} s, worst rms {t['worst_rms']:.1e}, "
              f"dense {t['dense']} missed {t['missed']} rattle_bad {t['rattle_bad']}; found "
              f"{[(round(f['omega'], 3), f['period']) for f in census.found]}", flush=True)
    print(f"\ntotals: {totals}  ({time.perf_counter() - t0:.0f} s)")
    for m in misses:
        print("  ", m)
    return 1 if misses else 0


if __name__ == "__main__":
    sys.exit(main())
