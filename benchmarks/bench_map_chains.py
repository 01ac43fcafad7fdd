"""The example chains' map cells against exact references (as bench_map_reference.py does for
the reference clutch): every stable solution a cell reports at every ``--every``-th grid
frequency closes on the exact flow of the chain (Newton shooting, period, rms of the first
element to 1e-3, stability), and every distinct attractor of a dense census of ``--starts``
random initial states (all 2n coordinates) is one the cell reports, with ``rattle`` true wherever
one impacts (any element).

Run: ``python benchmarks/bench_map_chains.py [--points 40] [--every 4] [--starts 12]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_map_reference import check_model  # noqa: E402

import rattle  # noqa: E402
from rattle.analysis._settings import RunSettings  # noqa: E402
from rattle.hb import HBOptions  # noqa: E402

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=40)
    ap.add_argument("--every", type=int, default=4)
    ap.add_argument("--starts", type=int, default=12)
    args = ap.parse_args()
    rng = np.random.default_rng(5)
    misses: list[str] = []
    t0 = time.perf_counter()
    for name in ("chain_two_inertia.toml", "grounded_two_inertia.toml", "driveline_three_inertia.toml"):
        case = rattle.load_case(EXAMPLES / name)
        lo, hi = case.analysis.omega
        grid = np.linspace(lo, hi, args.points)
        run = RunSettings.make(HBOptions(harmonics=case.analysis.harmonics), None, None)
        t1 = time.perf_counter()
        t, m, census = check_model(case.model, grid, run, every=args.every, starts=args.starts, rtol=1e-3, rng=rng,
                                   label=name)
        misses += m
        print(f"{name}: {time.perf_counter() - t1:.0f} s, shot {t['shot']} worst rms {t['worst_rms']:.1e}, "
              f"stability mismatches {t['stab_bad']}, dense {t['dense']} missed {t['missed']} rattle_bad "
              f"{t['rattle_bad']}; search {census.counts}", flush=True)
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    for m in misses:
        print("  ", m)
    return 1 if misses else 0


if __name__ == "__main__":
    sys.exit(main())
