"""Benchmark: the whole reference-case frequency response by harmonic balance vs a time-domain sweep.

Run:  python benchmarks/bench_frf.py  [--frequencies 8] [--repeat 5]
      python benchmarks/bench_frf.py  --against /path/to/other/tree  [--rounds 5]

``--against PATH`` times this tree against another checkout of rattle (``PATH/src``) on the
reference case's whole frequency response (H = 32, stability, measures): the two trees run in
child processes taken alternately (A B A B …, ``--rounds`` of each, OMP_NUM_THREADS=1), each
child timing its runs in CPU time (``time.process_time``, so that other load on a shared machine
counts less) after a warm-up run; the best of each tree, the ratio and the largest difference of
the special points (Ω of each located point, in order) are printed.

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
import json
import os
import subprocess
import sys
import time
from pathlib import Path

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


def child(runs: int) -> int:
    """One child of ``--against``: warm-up, then ``runs`` timed runs; one JSON line on stdout."""
    model = rattle.reference_case()
    rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)  # warm-up (imports, caches)
    cpu, wall, frf = [], [], None
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        frf = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - t0)
    print(json.dumps({
        "file": rattle.__file__, "cpu": cpu, "wall": wall, "points": len(frf),
        "special": [[p.kind, p.omega] for p in frf.special_points],
        "rms": [float(frf.rms.min()), float(frf.rms.max())],
    }))
    return 0


def against(other: str, rounds: int, runs: int) -> int:
    """Time this tree (``src`` next to ``benchmarks``) and ``other`` alternately (see the docstring)."""
    here = Path(__file__).resolve().parents[1]
    trees = {"this": here, "other": Path(other).resolve()}
    for name, tree in trees.items():
        if not (tree / "src" / "rattle" / "__init__.py").is_file():
            raise SystemExit(f"`--against`: no rattle package under {tree / 'src'} ({name} tree)")
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    out: dict[str, list[dict]] = {name: [] for name in trees}
    for r in range(rounds):
        for name in (("this", "other") if r % 2 == 0 else ("other", "this")):
            proc = subprocess.run(
                [sys.executable, __file__, "--child", str(runs)], env=dict(env, PYTHONPATH=str(trees[name] / "src")),
                capture_output=True, text=True, check=False,
            )
            if proc.returncode:
                raise SystemExit(f"{name} tree failed:\n{proc.stderr[-2000:]}")
            out[name].append(json.loads(proc.stdout.strip().splitlines()[-1]))
    best = {name: min(min(o["cpu"]) for o in runs_) for name, runs_ in out.items()}
    med = {name: float(np.median([c for o in runs_ for c in o["cpu"]])) for name, runs_ in out.items()}
    print(f"reference case frequency response (H = 32, stability + measures), CPU time per run, "
          f"{rounds} alternating rounds × {runs} runs per tree, OMP_NUM_THREADS=1")
    for name in trees:
        o = out[name][-1]
        print(f"  {name:5s} {trees[name]}: best {best[name] * 1e3:7.1f} ms, median {med[name] * 1e3:7.1f} ms, "
              f"{o['points']} points, {len(o['special'])} special points  ({o['file']})")
    print(f"  ratio other / this: best {best['other'] / best['this']:.2f} x, median {med['other'] / med['this']:.2f} x")
    a, b = out["this"][-1]["special"], out["other"][-1]["special"]
    if [k for k, _ in a] == [k for k, _ in b]:
        diff = max((abs(x - y) for (_, x), (_, y) in zip(a, b)), default=0.0)
        print(f"  special points: same kinds in the same order, largest |ΔΩ| = {diff:.2e}")
    else:
        print(f"  special points DIFFER: this {a}\n                         other {b}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frequencies", type=int, default=8, help="frequencies simulated and timed (default 8)")
    parser.add_argument("--repeat", type=int, default=5, help="HBM runs, best time reported (default 5)")
    parser.add_argument("--against", metavar="PATH", help="time this tree against the rattle checkout at PATH")
    parser.add_argument("--rounds", type=int, default=5, help="--against: alternating rounds per tree (default 5)")
    parser.add_argument("--runs", type=int, default=2, help="--against: timed runs per child (default 2)")
    parser.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child is not None:
        return child(args.child)
    if args.against is not None:
        return against(args.against, args.rounds, args.runs)

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
