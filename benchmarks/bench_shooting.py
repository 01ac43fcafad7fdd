"""Benchmark: ``rattle frf`` on the discontinuous laws by exact shooting continuation (the default)
against ``rattle frf`` on the smooth reference clutch, side by side in one run (issue 25).

Run:  python benchmarks/bench_shooting.py  [--repeat 3] [--hb]

Each row is the CPU time (user + system, the whole process: interpreter, imports, computation,
files) of ``python -m rattle frf CASE -o TMP`` as a subprocess, best of ``--repeat`` runs, and its
ratio to the reference clutch's (``examples/reference_clutch.toml``) measured in the same run. The
cases:

- ``preload``: the torque-converter preload law (K = I = 1, C = 0.05, T_p = 0.03,
  F = 0.05 + 0.03 cos Ωt) over Ω 0.3–2 at default settings;
- ``preload + stage friction``: a preload with a clearance (T_p = 0.02 past b = 0.05, slope 1)
  and Coulomb friction per stage (0.004, 0.001, 0.004), the same forcing, Ω 0.3–2;
- the examples with discontinuous laws, over their own ranges.

With ``--hb`` the same preload cases by the regularised harmonic balance (``method = "hb"``) too:
the method that was the default before. Target: the two preload cases at most 3× the reference.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

PRELOAD = """\
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "preload"
preload = 0.03
{extra}
[excitation]
mean = 0.05
amplitudes = [0.03]

[analysis]
omega = [0.3, 2.0]
{method}"""

FRICTION = 'clearance = 0.05\nfriction = [0.004, 0.001, 0.004]\n'


def cpu_of(args: list[str], cwd: Path) -> float:
    """CPU seconds (user + system) of one subprocess run."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.run([sys.executable, "-m", "rattle", *args], cwd=cwd, env=env, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode not in (0, 1):
        raise SystemExit(f"rattle {' '.join(args)} failed:\n{proc.stderr}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--hb", action="store_true", help="also the regularised harmonic balance on the preload cases")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cases: list[tuple[str, Path]] = [("reference clutch (smooth, HB)", EXAMPLES / "reference_clutch.toml")]
        for name, extra in (("preload, Ω 0.3–2", ""), ("preload + stage friction, Ω 0.3–2", FRICTION)):
            path = work / f"{len(cases)}.toml"
            path.write_text(PRELOAD.format(extra=extra, method=""))
            cases.append((name, path))
            if args.hb:
                path = work / f"{len(cases)}-hb.toml"
                path.write_text(PRELOAD.format(extra=extra, method='method = "hb"\n'))
                cases.append((name + " — regularised HB", path))
        for name in ("torque_converter_preload.toml", "clutch_friction.toml", "chain_lockup_clutch.toml",
                     "chain_clutch_friction.toml"):
            cases.append((name, EXAMPLES / name))
        best: dict[str, float] = {}
        for _ in range(args.repeat):  # alternating: the load of the machine falls on every case alike
            for k, (name, path) in enumerate(cases):
                t = cpu_of(["frf", str(path), "-o", str(work / f"out{k}")], work)
                best[name] = min(best.get(name, float("inf")), t)
        ref = best[cases[0][0]]
        print(f"{'case':48s} {'CPU s':>8s} {'× reference':>12s}")
        for name, _ in cases:
            print(f"{name:48s} {best[name]:8.2f} {best[name] / ref:12.2f}")


if __name__ == "__main__":
    main()
