"""The reference clutch's response map against exact references, cell by cell.

For α = 0 … 0.5 (11 values) × Ω on the map's grid (0.1 … 3.0, 146 points), the map's cells
(:func:`rattle.maps._cell.compute_cell`'s pipeline: frequency response with sub-harmonic
branches, branches solved on the grid, attractor search) are checked two ways:

1. **Exact shooting of every stable solution the map reports** on a sample of grid frequencies
   (every ``--every``-th): Newton shooting on the exact piecewise-linear flow from the HB
   solution's section state must converge to an orbit of the same period whose rms agrees with
   the map's to ``--rtol`` (default 1e-3, the issue's 0.1 %) and whose stability (exact
   monodromy) agrees.
2. **A dense, independent attractor census** at the same frequencies: ``--starts`` initial
   states (a fixed random sample over a box of ±4 times the largest orbit's half amplitude
   around the equilibrium, velocities ±4 Ω times that) simulated to their steady state
   (exact integration, up to 1500 forcing periods); every distinct stable attractor found
   (period, rms) must be one the map reports at that frequency (a stable solution of that
   period whose rms agrees to 1e-3; a non-periodic one: ``0`` in ``periods_stable``), and
   ``rattle`` must be true wherever an attractor found impacts.

Prints one line per α and the totals: cells checked, disagreements (with where), and the
attractors the dense census found that the map missed.

Run: ``python benchmarks/bench_map_reference.py [--every 5] [--starts 24]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time

import numpy as np

import rattle
from rattle.analysis._attractors import AttractorSearch, find_attractors
from rattle.analysis._frequency_response import _frequency_response
from rattle.analysis._grid import solutions_on_grid
from rattle.analysis._settings import RunSettings
from rattle.analysis._steady import SteadyStateOptions, make_integrator, steady_state
from rattle.hb import HBOptions
from rattle.maps._cell import summarise
from rattle.model import Clutch
from rattle.timeint import shoot_periodic_orbit
from rattle.timeint import shoot_system_orbit


def cell(model, grid, run):
    frf = _frequency_response(model, (grid[0], grid[-1]), run, subharmonics=True, max_period=4, throw=False)
    sols = solutions_on_grid(frf, grid, run)
    census = find_attractors(frf, grid, run, AttractorSearch(), sols)
    return census, summarise(census, grid)


def check_model(model, grid, run, *, every: int, starts: int, rtol: float, rng, label: str,
                dense_opts=None) -> tuple[dict, list[str], object]:
    """One map cell of ``model`` checked against exact shooting and a dense census (module
    docstring); returns the counts, the disagreements and the census."""
    dense_opts = dense_opts or SteadyStateOptions(max_periods=1500)
    totals = {"shot": 0, "rms_bad": 0, "stab_bad": 0, "period_bad": 0, "dense": 0, "missed": 0, "rattle_bad": 0,
              "worst_rms": 0.0}
    misses: list[str] = []
    census, summary = cell(model, grid, run)
    integ = make_integrator(model)
    system = model.system()
    single = hasattr(model, "elastic")

    def shoot(w, x0, period):
        if single:
            return shoot_periodic_orbit(model, w, x0, period=period, integrator=integ)
        return shoot_system_orbit(system, w, x0, period=period, integrator=integ)

    for j in range(0, grid.size, every):
        w = float(grid[j])
        stable = [s for s in census.solutions if s.index == j and s.stable]
        for s in stable:
            orbit = shoot(w, s.section[0], s.period)
            totals["shot"] += 1
            if not orbit.converged:
                totals["period_bad"] += 1
                misses.append(f"{label} Ω={w:.3f}: shooting from the period-{s.period} HB orbit failed")
                continue
            rms = float(orbit.rms) if single else float(orbit.measures.rms[0])
            err = abs(rms / s.rms - 1.0)
            totals["worst_rms"] = max(totals["worst_rms"], err)
            if err > rtol:
                totals["rms_bad"] += 1
                misses.append(f"{label} Ω={w:.3f}: rms {s.rms:.6g} vs exact {rms:.6g}")
            if bool(orbit.stable) != s.stable:
                totals["stab_bad"] += 1
                misses.append(f"{label} Ω={w:.3f}: stability differs (period {s.period})")
        amp = max([0.5 * s.p2p for s in census.solutions if s.index == j] + [float(system.length_scale())])
        x_eq = np.asarray(system.static_equilibrium(), dtype=float)
        n = x_eq.size
        seen: list[tuple[int, float, bool]] = []
        for _ in range(starts):
            x0 = np.concatenate((x_eq + rng.uniform(-4, 4, n) * amp, rng.uniform(-4, 4, n) * amp * w))
            st = steady_state(model, w, x0, options=dense_opts, integrator=integ)
            key = (int(st.period), round(float(st.rms), 4), any(r != "no_impact" for r in st.regimes()))
            if key not in seen:
                seen.append(key)
        periods = set(int(p) for p in str(summary["periods_stable"][j]).split(";") if p != "")
        known = [(s.period, s.rms) for s in stable]
        for period, rms, impacts in seen:
            totals["dense"] += 1
            if period == 0:
                ok = 0 in periods
            else:  # the same orbit: a stable solution of that period with that rms
                ok = any(p == period and abs(r / rms - 1) < 1e-3 for p, r in known)
            if not ok:
                totals["missed"] += 1
                misses.append(f"{label} Ω={w:.3f}: dense census found period {period} rms {rms:.4g} "
                              f"impacts {impacts} (map: periods {sorted(periods)}, "
                              f"rms {[round(r, 4) for _, r in known]})")
            if impacts and not summary["rattle"][j]:
                totals["rattle_bad"] += 1
                misses.append(f"{label} Ω={w:.3f}: an impacting attractor, map says rattle false")
    return totals, misses, census


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--every", type=int, default=5)
    ap.add_argument("--starts", type=int, default=24)
    ap.add_argument("--rtol", type=float, default=1e-3)
    ap.add_argument("--alphas", type=int, default=11)
    args = ap.parse_args()
    base = rattle.reference_case()
    grid = np.linspace(0.1, 3.0, 146)
    run = RunSettings.make(HBOptions(harmonics=32), None, None)
    rng = np.random.default_rng(20261130)
    totals: dict = {}
    misses: list[str] = []
    t0 = time.perf_counter()
    for alpha in np.linspace(0.0, 0.5, args.alphas):
        model = dataclasses.replace(base, elastic=Clutch(alpha=float(alpha), b=base.elastic.b))
        t, m, census = check_model(model, grid, run, every=args.every, starts=args.starts, rtol=args.rtol, rng=rng,
                                   label=f"α={alpha:.2f}")
        for k, v in t.items():
            totals[k] = max(totals.get(k, 0.0), v) if k == "worst_rms" else totals.get(k, 0) + v
        misses += m
        print(f"α = {alpha:.2f}: worst rms error {t['worst_rms']:.2e}; search {census.counts}; found "
              f"{[(round(f['omega'], 3), f['period']) for f in census.found]}", flush=True)
    print(f"\ntotals: {totals}  ({time.perf_counter() - t0:.0f} s)")
    for m in misses:
        print("  ", m)
    bad = totals["rms_bad"] or totals["stab_bad"] or totals["missed"] or totals["rattle_bad"] or totals["period_bad"]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
