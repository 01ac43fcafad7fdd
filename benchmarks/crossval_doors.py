"""Every door at defaults: is every stable periodic motion an exact sweep lands on on ``rattle frf``'s stable branches?

Issue 24's cross-validation, run as a user would: random cases of every law kind (single-equation
backlash and multi-stage clutch, two-inertia chains, preload, preload with a clearance and stage
friction) are written as case files; ``rattle frf CASE`` runs at default settings and
``rattle sweep CASE --direction both`` (exact simulation, the state carried from frequency to
frequency, up and down) gives the motions a run-up and a run-down settle on. A settled period-1
row of the sweep is *explained* when a stable stretch of one ``frf`` branch of period 1 passes
through its Ω with every element's rms within ``--rtol`` (linear interpolation between the two
rows around Ω: both stable, or one stable and the other the located point where that stability ends). Sub-harmonic rows (period ≥ 2) are counted separately:
``frf`` at defaults reports sub-harmonic regions, not branches (``--subharmonics`` adds them).
Prints one line per case and the fraction explained, with the CPU time of both doors.

    python benchmarks/crossval_doors.py --cases 20 --seed 1
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

SINGLE = """\
[model]
inertia = 1.0
damping = {c}
stiffness = 1.0

[model.elastic]
{law}

[excitation]
mean = {mean}
amplitudes = [{amp}]

[analysis]
omega = [{w0}, {w1}]
"""

CHAIN = """\
[model]
inertias = [{i1}, {i2}]

[[model.links]]
between = [1, 2]
damping = {c}

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 1.0
type = "clutch"
alpha = {alpha}
b = {b}

[[excitation.torques]]
inertia = 1
mean = {mean}
amplitudes = [{amp}]

[[excitation.torques]]
inertia = 2
mean = -{mean}

[analysis]
omega = [{w0}, {w1}]
"""

KINDS = ("backlash", "clutch", "chain", "preload", "preload_friction")


def case_text(kind: str, rng: np.random.Generator) -> str:
    """A random case file of the given kind (parameters in the ranges of the examples)."""
    c = round(float(rng.uniform(0.03, 0.1)), 4)
    mean = round(float(rng.uniform(0.02, 0.08)), 4)
    amp = round(float(rng.uniform(0.01, 0.05)), 4)
    b = round(float(rng.uniform(0.05, 0.3)), 4)
    w0, w1 = 0.2, 2.5
    if kind == "backlash":
        return SINGLE.format(c=c, mean=mean, amp=amp, w0=w0, w1=w1, law=f'type = "backlash"\nb = {b}')
    if kind == "clutch":
        alpha = round(float(rng.uniform(0.0, 0.5)), 3)
        return SINGLE.format(c=c, mean=mean, amp=amp, w0=w0, w1=w1, law=f'type = "clutch"\nalpha = {alpha}\nb = {b}')
    if kind == "chain":
        alpha = round(float(rng.uniform(0.05, 0.5)), 3)
        return CHAIN.format(i1=round(float(rng.uniform(0.5, 3.0)), 3), i2=round(float(rng.uniform(0.5, 3.0)), 3),
                            c=c, alpha=alpha, b=b, mean=mean, amp=2 * amp, w0=w0, w1=w1)
    tp = round(float(rng.uniform(0.01, 0.05)), 4)
    law = f'type = "preload"\npreload = {tp}'
    if kind == "preload_friction":
        mu = [round(float(x), 4) for x in rng.uniform(0.0005, 0.005, 3)]
        law += f"\nclearance = {round(b / 3, 4)}\nfriction = [{mu[0]}, {mu[1]}, {mu[2]}]"
    return SINGLE.format(c=c, mean=mean, amp=amp, w0=0.3, w1=2.0, law=law)


def run(args: list[str], cwd: Path) -> tuple[int, float]:
    """Exit status and CPU seconds of one ``rattle`` command."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.run([sys.executable, "-m", "rattle", *args], cwd=cwd, env=env, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return proc.returncode, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def read(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def rms_columns(header: list[str]) -> list[str]:
    """``rms`` and every element's ``NAME_rms``."""
    return [h for h in header if h == "rms" or h.endswith("_rms")]


def explained(row: dict[str, str], frf: list[dict[str, str]], cols: list[str], rtol: float) -> bool:
    """Whether a stable period-1 stretch of one frf branch passes through the row's Ω with every rms within rtol."""
    w = float(row["omega"])
    want = np.array([float(row[c]) for c in cols])
    by_branch: dict[str, list[dict[str, str]]] = {}
    for r in frf:
        if r.get("period", "1") == "1":
            by_branch.setdefault(r["branch"], []).append(r)
    for rows in by_branch.values():
        for a, b in zip(rows, rows[1:]):
            # a stable stretch: both rows stable, or it ends at the row where its stability change is located
            ends = [r["stable"] == "true" or bool(r.get("bifurcation")) for r in (a, b)]
            if not all(ends) or "true" not in (a["stable"], b["stable"]):
                continue
            wa, wb = float(a["omega"]), float(b["omega"])
            if not min(wa, wb) <= w <= max(wa, wb):
                continue
            s = 0.0 if wa == wb else (w - wa) / (wb - wa)
            got = np.array([(1 - s) * float(a[c]) + s * float(b[c]) for c in cols])
            if np.all(np.abs(got - want) <= rtol * np.abs(want)):
                return True
    return False


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=20, help="cases in all (the kinds in turn)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--points", type=int, default=40, help="sweep frequencies per direction")
    ap.add_argument("--rtol", type=float, default=0.01)
    ap.add_argument("--keep", type=Path, help="keep the case files and outputs here")
    ap.add_argument("--kinds", default=",".join(KINDS),
                    help=f"comma-separated law kinds taken in turn (default: all, {','.join(KINDS)})")
    args = ap.parse_args()
    kinds = tuple(k.strip() for k in args.kinds.split(",") if k.strip())
    unknown = [k for k in kinds if k not in KINDS]
    if unknown or not kinds:
        ap.error(f"--kinds: unknown kind(s) {unknown or args.kinds!r}; choose from {', '.join(KINDS)}")
    rng = np.random.default_rng(args.seed)
    work = args.keep or Path(tempfile.mkdtemp(prefix="crossval-doors-"))
    work.mkdir(parents=True, exist_ok=True)
    total = {k: [0, 0, 0, 0.0, 0.0] for k in KINDS}  # rows, explained, sub-harmonic rows, frf CPU, sweep CPU
    print(f"{'case':24s} {'frf':>5s} {'P1 rows':>8s} {'explained':>9s} {'P≥2':>4s} {'frf s':>6s} {'sweep s':>7s}  missed Ω")
    for n in range(args.cases):
        kind = kinds[n % len(kinds)]
        name = f"{n:02d}-{kind}"
        path = work / f"{name}.toml"
        path.write_text(case_text(kind, rng))
        status, t_frf = run(["frf", str(path), "-o", str(work / f"{name}-frf")], work)
        s_status, t_sweep = run(["sweep", str(path), "--direction", "both", "--points", str(args.points),
                                 "-o", str(work / f"{name}-sweep")], work)
        frf_csv, sweep_csv = work / f"{name}-frf" / "frf.csv", work / f"{name}-sweep" / "sweep.csv"
        if not frf_csv.exists() or not sweep_csv.exists():
            print(f"{name:24s} frf exit {status}, sweep exit {s_status}: no output")
            continue
        frf, sweep = read(frf_csv), read(sweep_csv)
        cols = [c for c in rms_columns(list(sweep[0])) if c in frf[0]]
        p1 = [r for r in sweep if r["period"] == "1"]
        sub = [r for r in sweep if r["period"] not in ("1", "0", "-1")]
        missed = [float(r["omega"]) for r in p1 if not explained(r, frf, cols, args.rtol)]
        t = total[kind]
        t[0] += len(p1)
        t[1] += len(p1) - len(missed)
        t[2] += len(sub)
        t[3] += t_frf
        t[4] += t_sweep
        print(f"{name:24s} {status:5d} {len(p1):8d} {len(p1) - len(missed):9d} {len(sub):4d} {t_frf:6.1f} {t_sweep:7.1f}  "
              + " ".join(f"{w:.3f}" for w in sorted(set(missed))))
    print()
    rows = sum(t[0] for t in total.values())
    ok = sum(t[1] for t in total.values())
    for k, t in total.items():
        if t[0]:
            print(f"{k:18s} period-1 sweep rows {t[0]:5d}, on frf's stable branches {t[1]:5d} ({t[1] / t[0]:.1%}); "
                  f"sub-harmonic rows {t[2]}; CPU frf {t[3]:.1f} s, sweep {t[4]:.1f} s")
    if rows:
        print(f"all: {ok}/{rows} = {ok / rows:.1%} of the period-1 motions the sweeps settle on are on frf's stable "
              f"branches (rtol {args.rtol:g}); files in {work}")


if __name__ == "__main__":
    main()
