"""Benchmark: the frequency response of a chain with Coulomb friction, HB against exact shooting.

A grounded chain of 3 inertias (tests/test_friction_response.py's): a clutch with a soft first
stage over a backlash and friction levels per stage (0.02, 0.05, 0.02) between inertias 1 and 2,
a gear with backlash between 2 and 3; forcing 0.05 + 0.1 cos Ωt on inertia 1. The full branch
Ω = 0.2 … 2 ω_n by :func:`rattle.analysis.friction_response` (ε = 0.01) at H = 64 and 128:
rows, rows matched by the exact orbit, the fraction of matched rows whose HB rms (every element)
is within 0.5 % of the exact one at ε and after the ε-ladder (rows off by more than 0.5 % taken
down to ε = 1e-3; Richardson where linear), stability agreement (exact saltation monodromy of the
exact orbit vs that of one period of exact flow from the HB state), rows that stick, time.

Run:  OMP_NUM_THREADS=1 python benchmarks/bench_friction_chain.py [--harmonics 64 128] [--no-refine]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rattle.analysis import RegularisationOptions, friction_response
from rattle.model import Backlash, Chain, Clutch, Element, Friction, Link, Torque


def chain() -> Chain:
    return Chain(inertias=(1.0, 0.5, 2.0),
                 links=(Link(between=(1, 0), stiffness=0.5, damping=0.05), Link(between=(2, 3), damping=0.05),
                        Link(between=(3, 0), stiffness=1.0, damping=0.1)),
                 elements=(Element(name="clutch", between=(1, 2), stiffness=1.0, law=Clutch(alpha=0.2, b=0.1),
                                   friction=Friction(levels=(0.02, 0.05, 0.02))),
                           Element(name="gear", between=(2, 3), stiffness=3.0, law=Backlash(b=0.02))),
                 torques=(Torque(inertia=1, mean=0.05, amplitudes=(0.1,)),))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--harmonics", type=int, nargs="+", default=[64, 128])
    ap.add_argument("--no-refine", action="store_true")
    ap.add_argument("--lo", type=float, default=0.2)
    ap.add_argument("--hi", type=float, default=2.0)
    args = ap.parse_args()
    fs = chain().friction_system()
    wn = fs.frequency_scale()
    print(f"chain: 3 inertias, elements {fs.element_names}, ω_n = {wn:.4g} rad/s, Ω = {args.lo} … {args.hi} ω_n, ε = 0.01")
    for H in args.harmonics:
        opts = RegularisationOptions(harmonics=H, regularisation=0.01, refine=None if args.no_refine else 0.005,
                                     limit_harmonics=H)
        t0 = time.perf_counter()
        r = friction_response(fs, (args.lo * wn, args.hi * wn), opts)
        dt = time.perf_counter() - t0
        m = r.matched
        err = np.abs(r.element_rms_error[m]).max(axis=1)
        est = r.hb_error[m]
        agree = r.stable[m] == r.stable_hb[m]
        agree_lim = r.stable[m] == r.stable_hb_limit[m]
        sticks = np.nan_to_num(r.stick_fraction).max(axis=1) > 0
        print(f"H = {H}: {len(r)} rows, matched {int(m.sum())} ({m.mean():.1%}), status {r.status.name}, {dt:.1f} s "
              f"({dt / max(len(r), 1) * 1e3:.0f} ms/row)")
        print(f"  HB at ε = 0.01 within 0.5 %: {np.mean(err <= 0.005):.1%} of matched "
              f"(median {np.median(err):.2%}, max {np.max(err):.2%})")
        if r.limit_index.size:
            print(f"  refined {r.limit_index.size} rows (ε → {np.nanmin(r.limit_eps):g}); HB ε→0 estimate within 0.5 %: "
                  f"{np.mean(est <= 0.005):.1%} of matched (median {np.nanmedian(est):.2%}, max {np.nanmax(est):.2%})")
            print(f"  stability with the HB at its limit (refined rows) agrees on {int(agree_lim.sum())}/{int(m.sum())} "
                  f"({agree_lim.mean():.1%})")
        print(f"  stability agrees on {int(agree.sum())}/{int(m.sum())} matched rows ({agree.mean():.1%}); "
              f"unstable exact rows {int((~r.stable[m]).sum())}; sticking rows {int((sticks & m).sum())} "
              f"(Ω {r.omega[sticks & m].min() / wn:.3g} … {r.omega[sticks & m].max() / wn:.3g} ω_n)"
              if np.any(sticks & m) else f"  stability agrees on {int(agree.sum())}/{int(m.sum())}")
        bad = np.flatnonzero(m)[~agree]
        if bad.size:
            print("  disagreeing rows (Ω/ω_n, max|μ| exact, HB):",
                  ", ".join(f"{r.omega[i] / wn:.4f} {r.mu_abs[i]:.4f} {r.mu_hb_abs[i]:.4f}" for i in bad[:8]))
        un = np.flatnonzero(~m)
        if un.size:
            departed = np.isfinite(r.match_distance[un])
            print(f"  unmatched {un.size} rows: {int(departed.sum())} shot to another orbit (δ departs by more than "
                  f"`match`), {int((~departed).sum())} shooting failed; Ω/ω_n ranges:",
                  ", ".join(f"{a / wn:.3f}–{b / wn:.3f}" for a, b in _runs(r.omega, ~m)[:12]))


def _runs(omega: np.ndarray, sel: np.ndarray) -> list[tuple[float, float]]:
    idx = np.flatnonzero(sel)
    if idx.size == 0:
        return []
    parts = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    return [(float(omega[p].min()), float(omega[p].max())) for p in parts]


if __name__ == "__main__":
    main()
