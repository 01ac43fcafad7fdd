"""Refusals that need no numerics load none (issue 29): a refused ``--measured`` file, ``--at``
with too many frequencies, two ``--vary`` ranges whose late combinations break a rule. Each runs
the real entry point in a subprocess and reports which of numpy, scipy and numba it imported
(``sys.modules``), with the exit status and the one error line. No timing is asserted
(``benchmarks/bench_frontdoor.py`` measures the wall times)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from _cases import clutch_toml  # tests/_cases.py (tests/ is on sys.path through its conftest)

SRC = Path(__file__).resolve().parents[1] / "src"
FAST = clutch_toml((0.5, 0.8), 8)
PIECEWISE = FAST.replace('type = "clutch"\nalpha = 0.25\nb = 0.174533',
                         'type = "piecewise"\nbreakpoints = [-0.3, -0.1, 0.05, 0.2]\nslopes = [1.0, 0.3, 0.05, 0.3, 1.0]')

#: Runs ``rattle ARGS`` in this interpreter and prints the exit status and the heavy modules loaded.
_PROBE = (
    "import json, sys\n"
    "from rattle.cli.main import cli\n"
    "code = cli.main(args=sys.argv[1:], prog_name='rattle', standalone_mode=False)\n"
    "heavy = sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'scipy', 'numba', 'matplotlib'})\n"
    "print(json.dumps({'code': code, 'heavy': heavy}))\n"
)

FILES = {
    "header_only.csv": "omega,acc_p2p\n",
    "empty.csv": "",
    "bad_column.csv": "omega,acc_p2p,colour\n0.6,1.0,red\n",
    "bad_cell.csv": "omega,acc_p2p\n0.6,1.0\n0.7,fast\n",
    "not_monotonic.csv": "omega,acc_p2p\n0.6,1.0\n0.7,1.1\n0.65,1.2\n",
    "negative.csv": "omega,acc_p2p\n0.6,-1.0\n",
    "semicolons.csv": "omega;acc_p2p\n0.6;1.0\n",
    "rpm.csv": "speed_rpm,acc_p2p\n800,1.0\n900,1.1\n",
    "outside.csv": "omega,acc_p2p\n0.6,1.0\n5.0,1.1\n",
}

AT_101 = ",".join(f"{0.5 + 0.003 * i:.3f}" for i in range(101))
C = ["compare", "case.toml"]

# (id, arguments, fragment of the error line, modules allowed)
CASES = [
    ("measured missing", [*C, "--measured", "missing.csv"], "`--measured`", set()),
    ("measured header only", [*C, "--measured", "header_only.csv"], "has a header but no rows", set()),
    ("measured empty", [*C, "--measured", "empty.csv"], "`--measured`", set()),
    ("measured unknown column", [*C, "--measured", "bad_column.csv"], "column 'colour' is not known", set()),
    ("measured bad cell", [*C, "--measured", "bad_cell.csv"], "line 3, column `acc_p2p`: must be a number", set()),
    ("measured repeated speed", [*C, "--measured", "not_monotonic.csv"], "strictly increasing", set()),
    ("measured acc_p2p <= 0", [*C, "--measured", "negative.csv"], "`acc_p2p`: must be > 0", set()),
    ("measured semicolons", [*C, "--measured", "semicolons.csv"], "is not comma-separated", set()),
    ("at 101 values", [*C, "--at", AT_101], "`--at` must hold at most 100 frequencies, got 101", set()),
    ("at not a number", [*C, "--at", "0.6,fast"], "`--at` must hold numbers", set()),
    # these need the configuration (the model: numpy), never the solver
    ("measured rpm without an engine", [*C, "--measured", "rpm.csv"], "column `speed_rpm`: the configuration has no "
     "engine", {"numpy"}),
    ("measured outside the range", [*C, "--measured", "outside.csv"], "lies outside the analysis range", {"numpy"}),
    ("at outside the range", [*C, "--at", "0.6,5"], "within the analysis range", {"numpy"}),
    ("vary 300 x 300 late combinations", ["map", "piecewise.toml", "--vary", "model.elastic.breakpoints.3=0.01:0.19:300",
                                          "--vary", "model.elastic.breakpoints.4=0.3:0.18:300"],
     "model.elastic.breakpoints.3 = 0.19 with model.elastic.breakpoints.4 = 0.18: the model refuses this value: "
     "`model.elastic.breakpoints` must be strictly increasing", {"numpy"}),
    ("vary one bad value", ["map", "case.toml", "--vary", "alpha=0.2:1.5:3"], "alpha = 1.5 (`model.elastic.alpha`)",
     {"numpy"}),
]


@pytest.mark.parametrize(("args", "fragment", "allowed"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_refusal_loads_no_numerics(tmp_path: Path, args: list[str], fragment: str, allowed: set[str]) -> None:
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    (tmp_path / "piecewise.toml").write_text(PIECEWISE, encoding="utf-8")
    for name, text in FILES.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    before = sorted(os.listdir(tmp_path))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    proc = subprocess.run([sys.executable, "-c", _PROBE, *args, "-o", "out"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["code"] == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rattle: error: ") and fragment in lines[0], proc.stderr
    assert set(report["heavy"]) <= allowed, f"a refusal imported {report['heavy']}"
    assert sorted(os.listdir(tmp_path)) == before  # nothing written


def test_a_smooth_frf_loads_no_optimiser_and_no_ode_solver(tmp_path: Path) -> None:
    """``rattle frf`` on the single equation with a clearance computes everything itself (Brent's
    root finder of :mod:`rattle._brent` locates its special points): ``scipy.optimize`` and
    ``scipy.integrate`` (0.17 s of CPU at a command's start) are not imported."""
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    probe = _PROBE.replace("heavy = sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'scipy', 'numba', "
                           "'matplotlib'})", "heavy = sorted(m for m in sys.modules if m.startswith(('scipy.optimize', "
                           "'scipy.integrate')))")
    assert probe != _PROBE
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    proc = subprocess.run([sys.executable, "-c", probe, "frf", "case.toml", "-o", "out"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["code"] == 0, proc.stderr
    assert (tmp_path / "out" / "frf.csv").is_file() and "fold" in (tmp_path / "out" / "frf.json").read_text()
    assert report["heavy"] == []
