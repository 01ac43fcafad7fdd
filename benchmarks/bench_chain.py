"""Benchmark: a three-inertia driveline's frequency response by harmonic balance vs a solve_ivp sweep.

Run:  python benchmarks/bench_chain.py  [--frequencies 6] [--repeat 3] [--harmonics 32]

Side by side, in one run, on ``examples/driveline_three_inertia.toml`` (flywheel, four-stage
clutch damper, gearbox input, gear mesh with backlash, vehicle side; free chain, two engine
harmonics) over its analysis range Ω = 0.75 … 2.3:

* HBM: ``rattle.frequency_response`` (``--harmonics`` harmonics, arc-length continuation through
  every fold, exact Floquet stability of the 4 × 4 monodromy with Neimark–Sacker detection, the
  measures of both elements at every point; best of ``--repeat`` runs);
* the classic alternative: scipy ``solve_ivp`` (RK45, rtol 1e-8, atol 1e-10) on the same
  reduced equations x'' + C x' + K x + Σ b f(a·x) = F(t), a stepped sweep with the state
  carried from one frequency to the next, 150 forcing periods to settle and 20 recorded at each
  frequency. ``--frequencies`` equally spaced frequencies are timed and the mean time per
  frequency is scaled to the 200-up + 200-down sweep ``rattle sweep --direction both`` runs.

Accuracy: where the simulation settles on a period-1 orbit, every element's rms is compared with
the HB branch's stable solution nearest in rms at that frequency.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import rattle
from rattle.io import load_config

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "driveline_three_inertia.toml"


def simulate_frequency(system, omega, z0, settle=150, record=20):
    """RK45 at one frequency: (final state, rms of every element over ``record`` periods, period-1 residual)."""
    n = system.n
    A = system.element_rows

    def rhs(t, z):
        x, v = z[:n], z[n:]
        acc = system.forcing(t, omega) - system.damping @ v - system.restoring(x)
        return np.concatenate((v, acc))

    T = 2 * np.pi / omega
    sol = solve_ivp(rhs, (0.0, settle * T), z0, method="RK45", rtol=1e-8, atol=1e-10)
    z_settled = sol.y[:, -1]
    t_rec = settle * T + np.linspace(0.0, record * T, record * 256 + 1)
    sol2 = solve_ivp(rhs, (t_rec[0], t_rec[-1]), z_settled, method="RK45", rtol=1e-8, atol=1e-10, t_eval=t_rec)
    d = A @ sol2.y[:n]  # element deflections (m, samples)
    rms = np.sqrt(np.mean(d[:, :-1] ** 2, axis=1))
    return sol2.y[:, -1], rms, float(np.max(np.abs(sol2.y[:, -257] - sol2.y[:, -1])))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frequencies", type=int, default=6, help="frequencies simulated and timed (default 6)")
    parser.add_argument("--repeat", type=int, default=3, help="HBM runs, best time reported (default 3)")
    parser.add_argument("--harmonics", type=int, default=32, help="HB harmonics (default 32)")
    args = parser.parse_args(argv)

    cfg = load_config(EXAMPLE)
    model = cfg.model
    system = model.system()
    lo, hi = cfg.analysis.omega
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        frf = rattle.frequency_response(model, omega=(lo, hi), harmonics=args.harmonics)
        times.append(time.perf_counter() - t0)
    t_hb = min(times)
    kinds = [s.kind for s in frf.special_points]
    print(f"driveline: {model.n_inertias} inertias (free, n = {system.n} coordinates), elements "
          f"{', '.join(model.element_names)}, Ω = {lo} … {hi}")
    print(f"HBM  (H = {args.harmonics}): {len(frf)} points, {kinds.count('fold')} folds, "
          f"{kinds.count('period_doubling')} period doublings, {kinds.count('neimark_sacker')} Neimark–Sacker; "
          f"best of {args.repeat}: {t_hb:.2f} s  (timings of the best-or-last run: "
          + ", ".join(f"{k} {v:.2f} s" for k, v in frf.timings.items()) + ")")

    omegas = np.linspace(lo, hi, args.frequencies)
    z = np.zeros(2 * system.n)
    z[: system.n] = system.static_equilibrium()
    worst = 0.0
    t0 = time.perf_counter()
    rows = []
    for w in omegas:
        z, rms, p1 = simulate_frequency(system, float(w), z)
        rows.append((w, rms, p1))
    t_sim = time.perf_counter() - t0
    per = t_sim / len(omegas)
    print(f"solve_ivp sweep: {len(omegas)} frequencies in {t_sim:.1f} s ({per:.2f} s each) "
          f"→ 400 frequencies (200 up + 200 down) ≈ {400 * per:.0f} s")
    print(f"ratio (400-frequency sweep / whole HB frequency response with stability): {400 * per / t_hb:.0f}×")
    names = model.element_names
    for w, rms, p1 in rows:
        near = np.nonzero(np.abs(frf.omega - w) < 0.02 * (hi - lo))[0]
        near = near[frf.stable[near]]
        if p1 > 1e-4 * float(np.max(rms)) or near.size == 0:
            print(f"  Ω = {w:.4f}: simulation not period 1 (residual {p1:.1e}) or no stable HB point near; skipped")
            continue
        errs = []
        for e, name in enumerate(names):
            col = frf.element(name)["rms"]
            hb = np.interp(w, frf.omega[near], col[near]) if np.all(np.diff(frf.omega[near]) > 0) else col[near][np.argmin(np.abs(col[near] - rms[e]))]
            errs.append(abs(hb / rms[e] - 1.0))
        worst = max(worst, max(errs))
        print(f"  Ω = {w:.4f}: rms " + ", ".join(f"{n} {r:.6g} (HB rel. diff {x:.1e})" for n, r, x in zip(names, rms, errs)))
    print(f"worst relative rms difference HB vs simulation (period-1 points): {worst:.1e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
