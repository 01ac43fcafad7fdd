"""Command line, time-domain commands: ``rattle sweep``, ``rattle orbit``, ``rattle compare``.

Bad input exits with status 2 before the solver is imported, names the option in backticks and
writes nothing; small real runs write the SPEC files with the SPEC columns.
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from rattle.cli.output import ProgressBar
from rattle.io import read_csv
from rattle.results import FRF_COLUMNS, ORBIT_COLUMNS, SWEEP_COLUMNS
from _cli_helpers import PNG, VALID, assert_bad_input, invoke



@pytest.fixture
def case(tmp_path: Path) -> Path:
    (tmp_path / "case.toml").write_text(VALID, encoding="utf-8")
    return tmp_path


@pytest.fixture
def no_solver(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make importing the solver fail: bad input must be refused before it is imported."""
    monkeypatch.setitem(sys.modules, "rattle.analysis", None)


# --------------------------------------------------------------------------------------------
# Bad input: exit 2, the option named, nothing written
# --------------------------------------------------------------------------------------------
BAD = [
    ("sweep no direction", ["sweep", "case.toml"], ["`--direction` is required", "up, down or both"]),
    ("sweep unknown direction", ["sweep", "case.toml", "--direction", "sideways"],
     ["'--direction'", "'sideways' is not one of 'up', 'down', 'both'"]),
    ("sweep one point", ["sweep", "case.toml", "--direction", "up", "--points", "1"],
     ["`--points` must be an integer >= 2", "got 1"]),
    ("sweep negative points", ["sweep", "case.toml", "--direction", "up", "--points", "-5"], ["`--points`", "got -5"]),
    ("sweep points not an integer", ["sweep", "case.toml", "--direction", "up", "--points", "2.5"],
     ["'--points'", "not a valid integer"]),
    ("sweep zero workers", ["sweep", "case.toml", "--direction", "both", "--workers", "0"], ["`--workers` must be"]),
    ("sweep empty range", ["sweep", "case.toml", "--direction", "up", "--omega-min", "2", "--omega-max", "1"],
     ["`--omega-min` must be < `--omega-max`"]),
    ("sweep has no --harmonics", ["sweep", "case.toml", "--direction", "up", "--harmonics", "8"],
     ["No such option", "--harmonics"]),
    ("orbit no omega", ["orbit", "case.toml"], ["`--omega` or `--rpm` is required"]),
    ("orbit omega and rpm", ["orbit", "case.toml", "--omega", "1", "--rpm", "800"], ["`--omega` and `--rpm` are both given"]),
    ("orbit rpm without an engine", ["orbit", "case.toml", "--rpm", "800"], ["`--rpm` 800 needs a model with an engine"]),
    ("orbit rpm negative", ["orbit", "case.toml", "--rpm", "-1"], ["`--rpm` must be a finite crankshaft speed > 0"]),
    ("orbit omega zero", ["orbit", "case.toml", "--omega", "0"], ["`--omega` must be a finite forcing frequency > 0"]),
    ("orbit omega negative", ["orbit", "case.toml", "--omega", "-1"], ["`--omega`", "got -1.0"]),
    ("orbit omega nan", ["orbit", "case.toml", "--omega", "nan"], ["`--omega`", "got nan"]),
    ("orbit omega inf", ["orbit", "case.toml", "--omega", "inf"], ["`--omega`", "got inf"]),
    ("orbit omega text", ["orbit", "case.toml", "--omega", "fast"], ["'--omega'", "not a valid float"]),
    ("orbit period 9", ["orbit", "case.toml", "--omega", "1", "--period", "9"], ["`--period` must be an integer 1 … 8", "got 9"]),
    ("orbit period 0", ["orbit", "case.toml", "--omega", "1", "--period", "0"], ["`--period`", "got 0"]),
    ("orbit period not an integer", ["orbit", "case.toml", "--omega", "1", "--period", "1.5"],
     ["'--period'", "not a valid integer"]),
    ("orbit harmonics too few for the period", ["orbit", "case.toml", "--omega", "1", "--period", "4", "--harmonics", "3"],
     ["`--harmonics` must be >= 4", "`--period` 4"]),
    ("orbit harmonics zero", ["orbit", "case.toml", "--omega", "1", "--harmonics", "0"], ["`--harmonics` must be an integer >= 1"]),
    ("compare one point", ["compare", "case.toml", "--points", "1"], ["`--points` must be an integer >= 2"]),
    ("compare at outside", ["compare", "case.toml", "--at", "0.8,5"], ["`--at` frequencies must be finite and within", "'5'"]),
    ("compare at text", ["compare", "case.toml", "--at", "0.8,fast"], ["`--at` must hold numbers", "'fast'"]),
    ("compare at empty item", ["compare", "case.toml", "--at", "0.8,,1.2"], ["`--at` must be a comma-separated list"]),
    ("compare at nan", ["compare", "case.toml", "--at", "nan"], ["`--at`", "'nan'"]),
]


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize(("args", "fragments"), [row[1:] for row in BAD], ids=[row[0] for row in BAD])
def test_bad_input_exits_2_and_writes_nothing(case: Path, args: list[str], fragments: list[str]) -> None:
    result = invoke([*args, "-o", "out"], case)
    assert_bad_input(result, *fragments)
    assert sorted(p.name for p in case.iterdir()) == ["case.toml"]


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize("command", [["sweep", "--direction", "up"], ["orbit", "--omega", "1"], ["compare"]])
def test_bad_config_exits_2(case: Path, command: list[str]) -> None:
    (case / "case.toml").write_text(VALID.replace("inertia = 1.0", "inertia = -1.0"), encoding="utf-8")
    result = invoke([command[0], "case.toml", *command[1:], "-o", "out"], case)
    assert_bad_input(result, "`model.inertia` must be > 0")
    assert not (case / "out").exists()


def test_help_lists_the_commands(case: Path) -> None:
    result = invoke(["--help"], case)
    assert result.exit_code == 0
    for command in ("frf", "sweep", "orbit", "compare", "demo"):
        assert command in result.stdout
    help_of = {c: invoke([c, "--help"], case).stdout for c in ("sweep", "orbit", "compare")}
    for option in ("--direction", "--points", "--workers", "--quiet", "--omega-min", "--omega-max", "--output"):
        assert option in help_of["sweep"]
    for option in ("--omega", "--period", "--harmonics"):
        assert option in help_of["orbit"]
    for option in ("--points", "--at", "--harmonics"):
        assert option in help_of["compare"]


# --------------------------------------------------------------------------------------------
# Small real runs
# --------------------------------------------------------------------------------------------
def test_sweep_end_to_end(case: Path) -> None:
    result = invoke(["sweep", "case.toml", "--direction", "both", "--points", "20",
                     "--omega-min", "0.6", "--omega-max", "1.6", "-o", "out"], case)
    assert result.exit_code == 0, result.stderr
    out = case / "out"
    assert sorted(p.name for p in out.iterdir()) == ["sweep.csv", "sweep.json", "sweep.png"]
    cols = read_csv(out / "sweep.csv")
    assert list(cols) == [*SWEEP_COLUMNS, "regime"]
    assert set(cols["regime"].tolist()) <= {"no_impact", "single_sided", "double_sided"}
    assert list(cols["direction"]) == ["up"] * 20 + ["down"] * 20
    np.testing.assert_allclose(cols["omega"][:20], np.linspace(0.6, 1.6, 20))
    np.testing.assert_allclose(cols["omega"][20:], np.linspace(1.6, 0.6, 20))
    assert set(cols["period"].tolist()) <= set(range(9)) and 2 in cols["period"]
    assert (out / "sweep.png").read_bytes()[:8] == PNG
    meta = json.loads((out / "sweep.json").read_text())
    assert meta["command"] == "sweep"
    assert meta["options"] == {"direction": "both", "points": 20, "workers": 1, "omega_min": 0.6, "omega_max": 1.6}
    assert meta["timings"]["cli_wall_time"] >= 0
    assert "up sweep: 20 frequencies" in result.stdout
    assert result.stderr == ""  # no progress bar when stderr is not a terminal


def test_orbit_end_to_end(case: Path) -> None:
    result = invoke(["orbit", "case.toml", "--omega", "1.41", "--period", "2", "--omega-min", "0.5",
                     "--omega-max", "2.0", "-o", "out"], case)
    assert result.exit_code == 0, result.stderr
    out = case / "out"
    assert sorted(p.name for p in out.iterdir()) == ["orbit.csv", "orbit.json", "orbit.png"]
    cols = read_csv(out / "orbit.csv")
    assert list(cols) == list(ORBIT_COLUMNS)
    # the selected orbit is the period-2 sub-harmonic: two forcing periods, closed
    assert cols["t"][-1] == pytest.approx(2 * 2 * np.pi / 1.41)
    assert cols["delta"][0] == pytest.approx(cols["delta"][-1], abs=1e-12)
    rms = np.sqrt(np.mean(cols["delta"][:-1] ** 2))
    assert rms == pytest.approx(0.15907, abs=1e-4)
    meta = json.loads((out / "orbit.json").read_text())
    assert meta["selected"] == 0 and meta["solutions"][0]["period"] == 2 and meta["solutions"][0]["stable"]
    assert meta["simulation"]["period"] == 2
    assert meta["options"] == {"omega": 1.41, "period": 2, "omega_min": 0.5, "omega_max": 2.0}
    assert (out / "orbit.png").read_bytes()[:8] == PNG
    assert "period 2, rms 0.15907" in result.stdout


def test_compare_end_to_end(case: Path) -> None:
    result = invoke(["compare", "case.toml", "--points", "20", "--harmonics", "16", "--omega-min", "0.6",
                     "--omega-max", "1.6", "-o", "out"], case)
    assert result.exit_code == 0, result.stderr
    out = case / "out"
    assert sorted(p.name for p in out.iterdir()) == ["compare.json", "compare.png", "frf.csv", "sweep.csv"]
    assert list(read_csv(out / "frf.csv")) == [*FRF_COLUMNS, "harmonics"]  # SPEC §3 + §8
    assert list(read_csv(out / "sweep.csv")) == [*SWEEP_COLUMNS, "regime"]
    assert (out / "compare.png").read_bytes()[:8] == PNG
    meta = json.loads((out / "compare.json").read_text())
    assert [o["reason"] for o in meta["orbits"]] == ["multi-valued", "sub-harmonic"]
    assert meta["command"] == "compare" and meta["analysis"] == {"omega": [0.6, 1.6], "harmonics": 16}


def test_compare_at(case: Path) -> None:
    result = invoke(["compare", "case.toml", "--points", "6", "--harmonics", "8", "--omega-min", "0.6",
                     "--omega-max", "1.6", "--at", "0.8, 1.41", "-o", "out"], case)
    assert result.exit_code == 0, result.stderr
    meta = json.loads((case / "out" / "compare.json").read_text())
    assert [o["omega"] for o in meta["orbits"]] == [0.8, 1.41]
    assert meta["options"]["at"] == [0.8, 1.41]


# --------------------------------------------------------------------------------------------
# Progress bar: only on a terminal, never with --quiet
# --------------------------------------------------------------------------------------------
class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_bar_draws_on_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("tqdm")
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    bar = ProgressBar("sweep both", enabled=True)
    for done in range(1, 5):
        bar(done, 4)
    assert bar._bar is not None and bar._bar.n == 4 and bar._bar.total == 4
    bar.close()
    assert "sweep both" in term.getvalue() and "/4" in term.getvalue()


def test_progress_bar_silent_when_quiet_or_not_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    bar = ProgressBar("sweep", enabled=False)  # --quiet
    bar(1, 2)
    bar.close()
    assert term.getvalue() == ""
    plain = io.StringIO()
    monkeypatch.setattr(sys, "stderr", plain)
    bar = ProgressBar("sweep", enabled=True)
    bar(1, 2)
    bar.close()
    assert plain.getvalue() == ""
