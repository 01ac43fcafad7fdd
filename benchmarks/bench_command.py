"""Benchmark: what ``rattle frf`` costs as a command against what its computation costs.

Run:  python benchmarks/bench_command.py  [--repeat 5] [--case examples/reference_clutch.toml]
      python benchmarks/bench_command.py  --against /path/to/other/tree   (that tree's src side by side)

In one run, for each tree (this one, and the one of ``--against`` when given), alternately so
that a change of load on a shared machine falls on both:

* **command**: the CPU time (user + system, the whole process and its children, from the kernel's
  accounting of the finished child) of ``python -m rattle frf CASE -o TMP`` — interpreter start,
  imports, numba's cached kernels, the frequency response, frf.csv, frf.json, frf.png and the
  interpreter's exit; after one discarded warm-up run (numba's cache written, files in the page
  cache);
* **computation**: the CPU time (``time.process_time``) of ``rattle.frequency_response`` on the same
  case in a process where it has run once already (imports done, kernels loaded): what the
  command computes, nothing else;
* both with the modules' bytecode written (``PYTHONDONTWRITEBYTECODE`` is dropped from the
  children's environment; the warm-up run writes ``__pycache__``), as after an installation;
* **ratio** = command / computation, from the best of ``--repeat`` runs of each (target ≤ 2), and
  the median ratio;
* **PNG**: the CPU time of drawing and writing ``frf.png`` as the command does
  (``rattle.cli.output.save_plot``) in a warm process, best of ``--repeat``;
* **phases**: where the command's CPU goes, best of ``--repeat`` runs of the command with its
  functions timed (a child that runs ``python -m rattle frf`` as the command line does, the
  process's ``sys.orig_argv`` saying so): up to the computation (interpreter, click, the
  configuration, the imports of numpy, scipy, numba and rattle), the computation in the command
  (numba's cached kernels loaded), the output set (frf.csv, frf.json, frf.png with matplotlib's
  import) and the exit; and the cyclic collector's share of it all; then one ``-X importtime``
  run (import of the numerics, of matplotlib).

The best of several runs is the figure that measures the code on a shared machine; the median is
printed beside it.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET = 2.0

#: Run in a child process with the tree's src first on the path: the computation's CPU time
#: (after one warm-up run) and the PNG's, printed as JSON.
_CHILD = r"""
import json, sys, tempfile, time
from pathlib import Path
import rattle
from rattle.io import load_config
case, repeat = sys.argv[1], int(sys.argv[2])
rc = load_config(case)
a = rc.analysis
def compute():
    return rattle.frequency_response(rc.model, omega=a.omega, harmonics=a.harmonics, throw=True)
frf = compute()  # warm-up: imports, numba's cached kernels
comp = []
for _ in range(repeat):
    t0 = time.process_time()
    frf = compute()
    comp.append(time.process_time() - t0)
png = []
try:
    from rattle.cli.output import save_plot
    with tempfile.TemporaryDirectory() as tmp:
        save_plot(frf, Path(tmp) / "w.png")  # warm-up: matplotlib imported, fonts loaded
        for k in range(repeat):
            t0 = time.process_time()
            save_plot(frf, Path(tmp) / f"frf{k}.png")
            png.append(time.process_time() - t0)
except ImportError:
    pass
print(json.dumps({"computation": comp, "png": png, "points": int(len(frf.omega))}))
"""


#: ``python -m rattle frf …`` in a child whose functions are timed: the CPU time when the
#: computation starts and ends, when the output set starts and ends, at exit, and the collector's.
_PHASES = r"""
import atexit, gc, importlib.abc, importlib.util, json, runpy, sys, time
out, args = sys.argv[1], sys.argv[2:]
marks, collector = {}, {"cpu": 0.0, "start": 0.0}
def timed(module, name, label):
    function = getattr(module, name)
    def wrapper(*a, **k):
        marks.setdefault(label + " start", time.process_time())
        try:
            return function(*a, **k)
        finally:
            marks[label + " end"] = time.process_time()
    setattr(module, name, wrapper)
class Hook(importlib.abc.MetaPathFinder):
    targets = {"rattle.analysis": ("frequency_response", "computation"), "rattle.cli.output": ("write_set", "output")}
    def find_spec(self, fullname, path, target=None):
        if fullname not in self.targets:
            return None
        sys.meta_path.remove(self)
        try:
            spec = importlib.util.find_spec(fullname)
        finally:
            sys.meta_path.insert(0, self)
        run = spec.loader.exec_module
        def exec_module(module):
            run(module)
            timed(module, *self.targets[fullname])
        spec.loader.exec_module = exec_module
        return spec
def on_collection(phase, info):
    if phase == "start":
        collector["start"] = time.process_time()
    else:
        collector["cpu"] += time.process_time() - collector["start"]
def report():
    marks["exit"] = time.process_time()
    marks["collector"] = collector["cpu"]
    with open(out, "w") as f:
        json.dump(marks, f)
sys.meta_path.insert(0, Hook())
gc.callbacks.append(on_collection)
atexit.register(report)
sys.orig_argv = [sys.executable, "-m", "rattle", *args]  # the command line, as rattle._signals reads it
sys.argv = ["rattle", *args]
runpy.run_module("rattle", run_name="__main__", alter_sys=True)
"""


def _env(src: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(src)
    # As installed (pip compiles the modules; an editable install writes them at the first
    # import): without this a shell with PYTHONDONTWRITEBYTECODE=1 compiles rattle's 200 modules
    # from source in every run, 0.3 s of CPU that no user pays.
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def command_cpu(src: Path, case: Path) -> float:
    """CPU seconds (user + system) of one ``python -m rattle frf case`` with ``src`` first on the path."""
    with tempfile.TemporaryDirectory() as tmp:
        proc = subprocess.Popen([sys.executable, "-m", "rattle", "frf", str(case), "-o", str(Path(tmp) / "out")],
                                env=_env(src), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _pid, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        err = proc.stderr.read().decode() if proc.stderr else ""
        if proc.stderr:
            proc.stderr.close()
        if proc.returncode != 0:
            raise SystemExit(f"rattle frf failed ({proc.returncode}) with {src}:\n{err}")
        return usage.ru_utime + usage.ru_stime


def computation_cpu(src: Path, case: Path, repeat: int) -> dict:
    out = subprocess.run([sys.executable, "-c", _CHILD, str(case), str(repeat)], env=_env(src), check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def phases(src: Path, case: Path) -> dict[str, float]:
    """CPU seconds of the command's phases in one timed run (:data:`_PHASES`): ``to computation``,
    ``computation``, ``output set``, ``exit`` (the rest, from the kernel's accounting of the
    finished child), their sum ``command``, and ``collector`` (the cyclic garbage collector's
    share of the whole)."""
    with tempfile.TemporaryDirectory() as tmp:
        marks_file = Path(tmp) / "marks.json"
        proc = subprocess.Popen([sys.executable, "-c", _PHASES, str(marks_file), "frf", str(case), "-o",
                                 str(Path(tmp) / "out")], env=_env(src), stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        _pid, status, usage = os.wait4(proc.pid, 0)
        if os.waitstatus_to_exitcode(status) != 0:
            raise SystemExit(f"the timed rattle frf failed with {src}")
        m = json.loads(marks_file.read_text())
    total = usage.ru_utime + usage.ru_stime
    return {"to computation": m["computation start"], "computation": m["computation end"] - m["computation start"],
            "output set": m["output end"] - m["output start"], "exit": total - m["exit"],
            "command": total, "collector": m["collector"]}


def import_costs(src: Path, case: Path) -> dict[str, float]:
    """Import time (s, wall, one ``-X importtime`` run of the command) of numpy, scipy, numba and
    matplotlib (each package's outermost imports, wherever the command imports them) and of
    rattle's own modules (their self time)."""
    with tempfile.TemporaryDirectory() as tmp:
        proc = subprocess.run([sys.executable, "-X", "importtime", "-m", "rattle", "frf", str(case), "-o",
                               str(Path(tmp) / "out")], env=_env(src), capture_output=True, text=True)
    rows = [(int(m.group(1)), int(m.group(2)), len(m.group(3)), m.group(4)) for m in
            re.finditer(r"^import time:\s+(\d+) \|\s+(\d+) \|( *)([\w.]+)\s*$", proc.stderr, re.M)]
    totals: dict[str, float] = {}
    stack: list[tuple[int, str]] = []  # the enclosing imports: a row's parent is printed after it
    for own, cumulative, indent, name in reversed(rows):
        while stack and stack[-1][0] >= indent:
            stack.pop()
        top = name.split(".")[0]
        if top == "rattle":
            totals["rattle (own modules)"] = totals.get("rattle (own modules)", 0.0) + own / 1e6
        elif top in ("numpy", "scipy", "numba", "matplotlib") and all(a.split(".")[0] != top for _, a in stack):
            totals[top] = totals.get(top, 0.0) + cumulative / 1e6
        stack.append((indent, name))
    return totals


def report(trees: dict[str, Path], case: Path, repeat: int) -> bool:
    """Measure and print the table for ``trees`` (label → src folder); True when the first tree
    meets the target."""
    for src in trees.values():
        command_cpu(src, case)  # warm-up: bytecode and numba's cache for this tree, the page cache
    commands: dict[str, list[float]] = {k: [] for k in trees}
    for _ in range(repeat):  # alternate the trees so that load changes fall on both
        for label, src in trees.items():
            commands[label].append(command_cpu(src, case))
    inproc = {label: computation_cpu(src, case, repeat) for label, src in trees.items()}
    ok = True
    print(f"{'tree':<40} {'command':>15} {'computation':>15} {'ratio':>13} {'frf.png':>15}  target")
    for n, label in enumerate(trees):
        cmd, comp, png = commands[label], inproc[label]["computation"], inproc[label]["png"]
        ratio = min(cmd) / min(comp)
        good = ratio <= TARGET
        ok &= good or n > 0
        fmt = lambda xs: f"{min(xs):6.3f} ({statistics.median(xs):5.3f})" if xs else "-"  # noqa: E731
        print(f"{label:<40} {fmt(cmd):>15} {fmt(comp):>15} {ratio:6.2f} "
              f"({statistics.median(cmd) / statistics.median(comp):4.2f}) {fmt(png):>15}  "
              f"{'ok' if good else 'MISSED'} (≤ {TARGET:g})")
    print(f"\nthe command's phases (CPU s, best of {repeat} timed runs; 'to computation': interpreter, click, the "
          "configuration, the imports of numpy, scipy, numba and rattle; 'output set': frf.csv, frf.json, frf.png "
          "with matplotlib's import; 'collector': the cyclic garbage collector's share of the command):")
    for label, src in trees.items():
        runs = [phases(src, case) for _ in range(repeat)]
        best = {key: min(run[key] for run in runs) for key in runs[0]}
        print(f"  {label:<38} " + ", ".join(f"{k} {v:.3f}" for k, v in best.items()))
    print("\nwhere the command's time goes (one -X importtime run, wall s: numpy, scipy, numba, matplotlib "
          "where the command first imports them, rattle's own modules; numba's kernels load at the first "
          "call, not here):")
    for label, src in trees.items():
        costs = import_costs(src, case)
        print(f"  {label:<38} " + ", ".join(f"{k} {v:.3f}" for k, v in sorted(costs.items(), key=lambda kv: -kv[1])))
    return ok


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs of each measurement; the best counts")
    parser.add_argument("--case", type=Path, default=ROOT / "examples" / "reference_clutch.toml")
    parser.add_argument("--against", type=Path, default=None, help="another checkout of rattle, timed beside this one")
    args = parser.parse_args()
    trees = {"this tree": ROOT / "src"}
    if args.against is not None:
        trees[f"against {args.against}"] = args.against.resolve() / "src"
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores, load average {load:.2f}; "
          f"case {args.case.name}; best (median) of {args.repeat} runs, CPU seconds\n")
    ok = report(trees, args.case, args.repeat)
    print("\nall targets met" if ok else "\ntarget missed (see MISSED; a loaded machine inflates both sides)")


if __name__ == "__main__":
    main()
