"""Benchmark: how fast the command line answers, and how fast a parallel sweep stops.

Run:  python benchmarks/bench_frontdoor.py  [--repeat 5] [--stops 3]

(a) Wall time of ``python -m rattle …`` as a subprocess (interpreter start included, as a user
    sees it), best of ``--repeat`` runs, for ``--help``, ``--version``, ``frf --help``,
    ``frf --version`` and refused inputs (bad option, out-of-bound option, bad configuration
    value, missing file, ``/dev/zero``, ``-o ""``, ``-o /proc/x``, a 300-character output
    name; issue 29: ``compare --measured`` refusals, ``compare --at`` with 101 values, two
    ``map --vary`` breakpoint ranges of 300 values whose late combinations are invalid), against
    the 0.5 s target. The bare interpreter (``python -c pass``) is shown for reference. Each row
    also says whether scipy, numba or matplotlib was imported (measured in a separate run with
    ``-X importtime``): they must not be for any of these.

(b) A parallel sweep (``sweep --direction both --workers 2``) is started; once both worker
    processes are computing, SIGINT is sent to the parent alone, and the time until the parent
    has exited and both workers are gone is measured (``--stops`` times; min, median, max),
    against the 1 s target. Then the same with SIGTERM.

(c) ``rattle frf`` on the reference case: the whole command's CPU against its computation's
    (``rattle.frequency_response`` in a warm process), target ≤ 2 — ``bench_command.py``'s table
    (``--ratio-repeat`` runs each; that script alone also compares with another tree).

The machine is shared: the best of several runs is the figure that measures the code, not the
load.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
TARGET = 0.5
STOP_TARGET = 1.0

CASE = """\
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "clutch"
alpha = 0.25
b = 0.174533

[excitation]
mean = 0.05
amplitudes = [0.03]

[analysis]
omega = [0.5, 0.8]
harmonics = 8
"""

ROWS: list[tuple[str, list[str]]] = [
    ("rattle --help", ["--help"]),
    ("rattle --version", ["--version"]),
    ("rattle frf --help", ["frf", "--help"]),
    ("rattle frf --version", ["frf", "--version"]),
    ("refused: frf --harmonics 0", ["frf", "case.toml", "--harmonics", "0"]),
    ("refused: frf --harmonics 10000", ["frf", "case.toml", "--harmonics", "10000"]),
    ("refused: inertia = -1 in the file", ["frf", "bad.toml"]),
    ("refused: missing file", ["frf", "missing.toml"]),
    ("refused: frf /dev/zero", ["frf", "/dev/zero"]),
    ("refused: frf -o ''", ["frf", "case.toml", "-o", ""]),
    ("refused: frf -o /proc/x", ["frf", "case.toml", "-o", "/proc/x"]),
    ("refused: frf -o <300 characters>", ["frf", "case.toml", "-o", "a" * 300]),
    ("refused: sweep --points 10^9", ["sweep", "case.toml", "--direction", "up", "--points", "1000000000"]),
    # issue 29: refusals that used to load the numerics or build every combination's model
    ("refused: compare --measured missing", ["compare", "case.toml", "--measured", "missing.csv"]),
    ("refused: compare --measured no rows", ["compare", "case.toml", "--measured", "header_only.csv"]),
    ("refused: compare --measured bad column", ["compare", "case.toml", "--measured", "bad_column.csv"]),
    ("refused: compare --measured bad cell", ["compare", "case.toml", "--measured", "bad_cell.csv"]),
    ("refused: compare --measured rpm, no engine", ["compare", "case.toml", "--measured", "rpm.csv"]),
    ("refused: compare --measured out of range", ["compare", "case.toml", "--measured", "outside.csv"]),
    ("refused: compare --at <101 values>", ["compare", "case.toml", "--at", ",".join(f"{0.5 + 0.003 * i:.3f}"
                                                                               for i in range(101))]),
    ("refused: map --vary 300 x 300, late bad", ["map", "piecewise.toml",
                                                 "--vary", "model.elastic.breakpoints.3=0.01:0.19:300",
                                                 "--vary", "model.elastic.breakpoints.4=0.3:0.18:300"]),
]

#: Files of the refusal rows, written into the working folder.
FILES = {
    "header_only.csv": "omega,acc_p2p\n",
    "bad_column.csv": "omega,acc_p2p,colour\n0.6,1.0,red\n",
    "bad_cell.csv": "omega,acc_p2p\n0.6,1.0\n0.7,fast\n",
    "rpm.csv": "speed_rpm,acc_p2p\n800,1.0\n900,1.1\n",
    "outside.csv": "omega,acc_p2p\n0.6,1.0\n5.0,1.1\n",
}


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    return env


def _time(argv: list[str], cwd: Path, repeat: int) -> tuple[float, int]:
    best, rc = float("inf"), 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        proc = subprocess.run(argv, cwd=cwd, env=_env(), capture_output=True, timeout=120)
        best = min(best, time.perf_counter() - t0)
        rc = proc.returncode
    return best, rc


def _heavy_imports(args: list[str], cwd: Path) -> str:
    proc = subprocess.run([sys.executable, "-X", "importtime", "-m", "rattle", *args], cwd=cwd, env=_env(),
                          capture_output=True, text=True, timeout=120)
    names = {m.group(1).split(".")[0] for m in re.finditer(r"\|\s+(?:\s*)([\w.]+)\s*$", proc.stderr, re.M)}
    heavy = sorted(names & {"scipy", "numba", "matplotlib"})
    return ", ".join(heavy) if heavy else "none"


def front_door(repeat: int) -> bool:
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        (cwd / "case.toml").write_text(CASE, encoding="utf-8")
        (cwd / "bad.toml").write_text(CASE.replace("inertia = 1.0", "inertia = -1.0"), encoding="utf-8")
        (cwd / "piecewise.toml").write_text(CASE.replace(
            'type = "clutch"\nalpha = 0.25\nb = 0.174533',
            'type = "piecewise"\nbreakpoints = [-0.3, -0.1, 0.05, 0.2]\nslopes = [1.0, 0.3, 0.05, 0.3, 1.0]'),
            encoding="utf-8")
        for name, text in FILES.items():
            (cwd / name).write_text(text, encoding="utf-8")
        before = sorted(p.name for p in cwd.iterdir())
        bare, _ = _time([sys.executable, "-c", "pass"], cwd, repeat)
        print(f"(a) front door: best of {repeat} runs of `python -m rattle …` (target {TARGET} s)\n")
        print(f"{'command':<44} {'exit':>4} {'wall s':>7}  {'target':<6} scipy/numba/matplotlib imported")
        print(f"{'python -c pass (the interpreter alone)':<44} {'0':>4} {bare:7.3f}")
        for label, args in ROWS:
            wall, rc = _time([sys.executable, "-m", "rattle", *args], cwd, repeat)
            heavy = _heavy_imports(args, cwd)
            good = wall < TARGET and heavy == "none" and (rc == 2 or not label.startswith("refused"))
            ok &= good
            print(f"{label:<44} {rc:>4} {wall:7.3f}  {'ok' if good else 'MISSED':<6} {heavy}")
        leftovers = sorted(p.name for p in cwd.iterdir())
        print(f"\nfiles written by the refusals: {sorted(set(leftovers) - set(before)) or 'none'}")
    return ok


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat", encoding="utf-8") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] not in ("Z", "X")
    except OSError:
        return False


def _one_stop(sig: signal.Signals) -> tuple[float, float, int]:
    """(parent exit time, all-workers-gone time, exit status) after ``sig`` to the parent alone."""
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        (cwd / "case.toml").write_text(CASE, encoding="utf-8")
        env = _env()
        env["PYTHONUNBUFFERED"] = "1"
        proc = subprocess.Popen(
            [sys.executable, "-m", "rattle", "-v", "sweep", "case.toml", "--direction", "both", "--points", "5000",
             "--workers", "2", "-q", "-o", "out"],
            cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True,
        )
        workers: list[int] = []
        assert proc.stderr is not None
        for line in proc.stderr:
            m = re.search(r"worker process (\d+) started", line)
            if m:
                workers.append(int(m.group(1)))
                if len(workers) == 2:
                    break
        threading.Thread(target=proc.stderr.read, daemon=True).start()
        time.sleep(0.5)  # both computing
        t0 = time.perf_counter()
        proc.send_signal(sig)
        rc = proc.wait(timeout=60)
        t_parent = time.perf_counter() - t0
        while any(_alive(p) for p in workers) and time.perf_counter() - t0 < 30:
            time.sleep(0.005)
        t_all = time.perf_counter() - t0
        for p in workers:
            if _alive(p):
                os.kill(p, signal.SIGKILL)
        return t_parent, t_all, rc


def sweep_stop(stops: int) -> bool:
    ok = True
    print(f"\n(b) parallel sweep (--workers 2): time to stop after a signal to the parent alone "
          f"(target {STOP_TARGET} s), {stops} runs\n")
    print(f"{'signal':<8} {'exit':>4} {'parent gone s (min/median/max)':>32} {'workers gone s (min/median/max)':>33}")
    for sig in (signal.SIGINT, signal.SIGTERM):
        runs = [_one_stop(sig) for _ in range(stops)]
        parent = [r[0] for r in runs]
        allgone = [r[1] for r in runs]
        rcs = sorted({r[2] for r in runs})
        good = max(allgone) < STOP_TARGET
        ok &= good
        fmt = lambda xs: f"{min(xs):.3f} / {statistics.median(xs):.3f} / {max(xs):.3f}"  # noqa: E731
        print(f"{sig.name:<8} {','.join(map(str, rcs)):>4} {fmt(parent):>32} {fmt(allgone):>33}  "
              f"{'ok' if good else 'MISSED'}")
    return ok


def command_ratio(repeat: int) -> bool:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import bench_command

    print(f"\n(c) rattle frf on the reference case: command / computation CPU (target ≤ {bench_command.TARGET:g}), "
          f"best (median) of {repeat} runs\n")
    return bench_command.report({"this tree": SRC}, bench_command.ROOT / "examples" / "reference_clutch.toml", repeat)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per command; the best counts")
    parser.add_argument("--stops", type=int, default=3, help="parallel sweeps stopped per signal")
    parser.add_argument("--ratio-repeat", type=int, default=3, help="runs of (c), the command/computation ratio")
    args = parser.parse_args()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores, load average {load:.2f}\n")
    ok = front_door(args.repeat)
    if sys.platform.startswith("linux"):
        ok &= sweep_stop(args.stops)
    ok &= command_ratio(args.ratio_repeat)
    print("\nall targets met" if ok else "\nsome targets missed (see MISSED; a loaded machine inflates the times)")


if __name__ == "__main__":
    main()
