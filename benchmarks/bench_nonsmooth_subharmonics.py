"""Benchmark: sub-harmonic branches of the discontinuous laws, the period-2 HB against exact shooting.

Run:  OMP_NUM_THREADS=1 python benchmarks/bench_nonsmooth_subharmonics.py [EXAMPLE ...]

For each example (default: examples/torque_converter_preload.toml, examples/clutch_friction.toml and
the chain examples/chain_clutch_friction.toml, over their own ``[analysis]`` range, harmonics and
regularisation) the period-1 branch and then its period-2 branches
(:func:`rattle.analysis.nonsmooth_subharmonics`, or :func:`rattle.analysis.friction_subharmonics`
for a chain), side by side in one run:

- the time of the period-1 branch and of the sub-harmonic branches, and their ratio;
- per branch: how it was followed (the regularised HB, every row checked by exact shooting over
  two periods, or exact shooting alone), rows, matched rows, its Ω range, the stable stretches;
- on the HB-followed branches: the HB's rms against the exact orbit's on the matched rows (median,
  max, share within 0.5 %, at ε and at the HB's ε → 0 estimate), and away from the branch's own
  special points (rows more than 2.5 % in Ω from a labelled fold, period doubling or grazing);
  stability of the HB orbit (saltation monodromy of the exact flow from its state) against the
  exact orbit's.

Measured 2026-12-01 (one core, another job on the second; ``rattle frf --subharmonics`` gives the
same branches):

- torque_converter_preload.toml (Ω = 0.5 … 1.5, H = 64, ε = 0.01): period-1 branch 1903 rows in
  32.0 s, the two period-2 branches in 79.9 s (ratio 2.49). Branch 1 (0.5443 … 0.5606, 106 rows,
  94 matched): within 0.5 % on every matched row (max 0.32 %), stability 100 %. Branch 2
  (0.7458 … 0.8636, 405 rows, 402 matched, four special points of its own): 86.8 % within 0.5 %
  at ε, 95.8 % at the ε → 0 estimate, 100 % away from its special points (41 rows, max 1.6e-4),
  stability 95.3 % (100 % away).
- clutch_friction.toml (Ω = 0.3 … 1.2): period-1 branch 320 rows in 78.1 s, the two period-2
  branches in 4.0 s (ratio 0.05), both followed by exact shooting alone (their orbits stick; the
  regularised HB at ε = 0.01 has no period-2 orbit next to them): 0.4218 … 0.4333 (15 rows,
  stable over 0.4218 … 0.4286 and 0.4327 … 0.4333) and 0.4441 … 0.4464 (7 rows, unstable).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from rattle.analysis._friction_subharmonics import friction_subharmonics
from rattle.analysis._nonsmooth import nonsmooth_response, nonsmooth_subharmonics  # the builders under rattle.frequency_response
from rattle.analysis._case import regularisation_options
from rattle.io import load_config
from rattle.results import held_runs as _held_runs

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
DEFAULT = ("torque_converter_preload.toml", "clutch_friction.toml", "chain_clutch_friction.toml")


def _spans(omega: np.ndarray, ok: np.ndarray) -> str:
    runs = _held_runs(omega, ok)
    return ", ".join(f"{a:.4f} … {b:.4f}" for a, b in runs) if runs else "none"


def _report(br) -> None:  # type: ignore[no-untyped-def]
    m = br.matched
    print(f"  branch {br.branch} (period {br.period}, {br.followed}; {br.origin}): {len(br)} rows over "
          f"Ω = {br.omega.min():.4f} … {br.omega.max():.4f}, {int(m.sum())} matched; stable over "
          f"{_spans(br.omega, m & br.stable)}")
    if br.followed != "harmonic balance" or not m.any():
        return
    err = np.abs(br.rms_error[m])
    est = np.abs(br.hb_error[m])
    labels = br.omega[br.bifurcation != ""]
    w = br.omega[m]
    away = np.ones(w.size, dtype=bool) if labels.size == 0 else \
        np.min(np.abs(w[:, None] - labels[None, :]), axis=1) > 0.025 * w
    mu_hb = np.abs(br.multipliers_hb[m]).max(axis=1) < 1.0
    agree = mu_hb == br.stable[m]
    print(f"    HB rms against exact: at ε median {np.median(err):.2g}, max {err.max():.2g}, within 0.5 % "
          f"{100 * np.mean(err < 0.005):.1f} %; at the ε → 0 estimate within 0.5 % {100 * np.mean(est < 0.005):.1f} %")
    if away.any():
        print(f"    away from its {labels.size} special points ({int(away.sum())} rows): estimate within 0.5 % "
              f"{100 * np.mean(est[away] < 0.005):.1f} % (max {est[away].max():.2g}); stability agrees "
              f"{100 * np.mean(agree[away]):.1f} %")
    print(f"    stability of the HB orbit agrees with the exact on {100 * np.mean(agree):.1f} % of the matched rows")


def main() -> None:
    names = sys.argv[1:] or DEFAULT
    for name in names:
        path = Path(name) if Path(name).exists() else EXAMPLES / name
        cfg = load_config(path)
        opts = regularisation_options(cfg.analysis)
        t0 = time.perf_counter()
        primary = nonsmooth_response(cfg.model, cfg.analysis.omega, opts)
        t1 = time.perf_counter()
        follow = nonsmooth_subharmonics if cfg.model.is_single_equation else friction_subharmonics
        branches = follow(cfg.model, primary, cfg.analysis.omega, opts)
        t2 = time.perf_counter()
        print(f"{path.name}: Ω = {cfg.analysis.omega[0]:g} … {cfg.analysis.omega[1]:g}, H = {opts.harmonics}, "
              f"ε = {opts.regularisation:g}; period-1 branch {len(primary)} rows in {t1 - t0:.1f} s, "
              f"sub-harmonic branches {len(branches)} in {t2 - t1:.1f} s (ratio {(t2 - t1) / (t1 - t0):.2f})")
        for br in branches:
            _report(br)


if __name__ == "__main__":
    main()
