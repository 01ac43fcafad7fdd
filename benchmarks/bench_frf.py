"""Benchmark: the whole reference-case frequency response by harmonic balance vs a time-domain sweep.

Run:  python benchmarks/bench_frf.py  [--frequencies 8] [--repeat 5]

Side by side, in one run, on the paper's clutch (K = I = 1, C = 0.05, α = 0.25, b = 10°,
F_m = 0.05, F_p1 = 0.03) over Ω = 0.1 … 3.0:

* HBM: ``rattle.frequency_response`` with 32 harmonics, arc-length continuation, exact
  Floquet stability and all SPEC measures for every point (best of ``--repeat`` runs);
* the classic alternative: scipy ``solve_ivp`` (RK45, rtol 1e-8, atol 1e-10) stepped sweep,
  the state carried from one frequency to the next, 150 forcing periods to settle and 20
  recorded at each frequency. A full 200-up + 200-down sweep takes many minutes, so
  ``--frequencies`` equally spaced frequencies are timed (up sweep, state carried) and the
  mean time per frequency is scaled to 400 frequencies.

Accuracy: at each simulated frequency where the sweep settles on a period-1 orbit, its rms is
compared with the HB branch's stable solution at that frequency.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

import rattle
from rattle.hb import HarmonicBalance, HBOptions, solve_harmonic_balance


def simulate_frequency(model, omega, x0, settle=150, record=20):
    """Classic RK45 simulation at one frequency: returns (final state, rms over `record` periods, period-1 residual)."""
    c, k = model.c, model.k
    law, exc = model.elastic, model.excitation

    def rhs(t, x):
        return [x[1], exc(t, omega) - c * x[1] - k * law.force(x[0])]

    T = 2 * np.pi / omega
    sol = solve_ivp(rhs, (0.0, settle * T), x0, method="RK45", rtol=1e-8, atol=1e-10)
    x_settled = sol.y[:, -1]
    t_rec = settle * T + np.linspace(0.0, record * T, record * 256 + 1)
    sol2 = solve_ivp(rhs, (t_rec[0], t_rec[-1]), x_settled, method="RK45", rtol=1e-8, atol=1e-10, t_eval=t_rec)
    delta = sol2.y[0]
    # rms over whole periods by the trapezoidal rule (periodic integrand: spectrally accurate).
    rms = np.sqrt(np.mean(delta[:-1] ** 2))
    # Period-1 check: the state one period apart at the end of the record.
    return sol2.y[:, -1], rms, abs(delta[-257] - delta[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frequencies", type=int, default=8, help="frequencies simulated and timed (default 8)")
    parser.add_argument("--repeat", type=int, default=5, help="HBM runs, best time reported (default 5)")
    args = parser.parse_args(argv)

    model = rattle.reference_case()
    # --- HBM: the whole frequency response ------------------------------------------------
    rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)  # warm-up (imports, caches)
    t_hbm, frf = float("inf"), None
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        run = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)
        elapsed = time.perf_counter() - t0
        if elapsed < t_hbm:
            t_hbm, frf = elapsed, run

    # --- all branches: the primary plus the period-doubled ones (branch switching) ----------
    t_all, frf_all = float("inf"), None
    for _ in range(max(1, args.repeat // 2)):
        t0 = time.perf_counter()
        run = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32, subharmonics=True)
        elapsed = time.perf_counter() - t0
        if elapsed < t_all:
            t_all, frf_all = elapsed, run

    # --- time-domain sweep (subset, scaled) ------------------------------------------------
    omegas = np.linspace(0.1, 3.0, args.frequencies)
    x = np.array([model.static_equilibrium(), 0.0])
    sim_times, sim_rms = [], []
    for w in omegas:
        t0 = time.perf_counter()
        x, rms, per_res = simulate_frequency(model, w, x)
        sim_times.append(time.perf_counter() - t0)
        sim_rms.append((w, rms, per_res))
    t_one = float(np.mean(sim_times))
    t_sweep = 400 * t_one

    # --- accuracy: simulated rms vs the HB solution at the same frequency -----------------
    hb = HarmonicBalance(model, HBOptions(harmonics=32))
    errors = []
    for w, rms, per_res in sim_rms:
        if per_res > 1e-6:
            continue  # not period-1 at this frequency
        # HB solution at w: start from the nearest stable branch point.
        cand = np.nonzero(frf.stable)[0]
        i = cand[np.argmin(np.abs(frf.omega[cand] - w))]
        r = solve_harmonic_balance(hb, frf.coefficients[i], w)
        if r.converged:
            rms_hb = np.sqrt(r.q[0] ** 2 + 0.5 * np.sum(r.q[1:] ** 2))
            errors.append(abs(rms_hb / rms - 1))

    print(f"reference case, Ω = 0.1 … 3.0 — machine: {sys.platform}, numpy {np.__version__}")
    print(f"HBM frequency response (H = 32, {len(frf)} points, stability + measures): {t_hbm * 1e3:8.1f} ms  (best of {args.repeat})")
    print(f"  of which: " + ", ".join(f"{k} {v * 1e3:.0f} ms" for k, v in frf.timings.items()))
    branches = len(set(frf_all.branch.tolist()))
    print(f"HBM with sub-harmonics ({branches} branches, {len(frf_all)} points, all special points located): {t_all * 1e3:8.1f} ms")
    print(f"solve_ivp RK45 rtol 1e-8, one frequency (150 + 20 periods), mean of {len(omegas)}: {t_one * 1e3:8.1f} ms")
    print(f"solve_ivp sweep, 200 up + 200 down (scaled from {len(omegas)} frequencies): {t_sweep:8.1f} s")
    print(f"ratio  sweep / HBM frequency response : {t_sweep / t_hbm:8.0f} x")
    print(f"ratio  one simulated frequency / HBM  : {t_one / t_hbm:8.2f} x")
    if errors:
        print(f"accuracy: |rms_HB / rms_sim − 1| at {len(errors)} period-1 frequencies: max {max(errors):.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
