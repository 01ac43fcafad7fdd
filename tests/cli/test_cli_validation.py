"""Command line: bad input exits with status 2 before any computation and creates nothing;
a numerical failure exits with 1 and keeps what was computed; success writes three files."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import types
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rattle.cli.main import main
from rattle.errors import ConvergenceError
from rattle.io import read_csv
from rattle.results import FRF_COLUMNS
from _cli_helpers import VALID, assert_bad_input, invoke, write_config
from _fake_result import FakeResponse as _FakeResponse

SRC = Path(__file__).resolve().parents[2] / "src"


@pytest.fixture
def no_solver(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make importing the solver fail: bad input must be refused before it is imported."""
    monkeypatch.setitem(sys.modules, "rattle.analysis", None)


# --------------------------------------------------------------------------------------------
# Bad configuration: exit 2, key named on stderr, no output directory
# --------------------------------------------------------------------------------------------
BAD_CONFIGS = [
    ("unknown key", VALID.replace("damping = 0.05", "damping = 0.05\nmass = 2.0"), "`model.mass` is not a known key"),
    ("negative inertia", VALID.replace("inertia = 1.0", "inertia = -1.0"), "`model.inertia` must be > 0"),
    ("nan", VALID.replace("mean = 0.05", "mean = nan"), "`excitation.mean` must be a finite number"),
    ("string number", VALID.replace("b = 0.174533", 'b = "0.17"'), "`model.elastic.b` must be a number"),
    ("unknown type", VALID.replace('"clutch"', '"spring"'), "`model.elastic.type` must be one of"),
    ("foreign key", VALID.replace('"clutch"', '"backlash"'), '`model.elastic.alpha` does not belong to type = "backlash"'),
    ("breakpoints not increasing",
     VALID.replace('type = "clutch"\nalpha = 0.25\nb = 0.174533',
                   'type = "piecewise"\nbreakpoints = [0.2, 0.1]\nslopes = [1.0, 0.5, 1.0]'),
     "`model.elastic.breakpoints` must be strictly increasing"),
    ("slopes count", VALID.replace('type = "clutch"\nalpha = 0.25\nb = 0.174533',
                                   'type = "piecewise"\nbreakpoints = [0.1, 0.2]\nslopes = [1.0, 1.0]'),
     "`model.elastic.slopes` must have one more entry"),
    ("alpha out of range", VALID.replace("alpha = 0.25", "alpha = 1.5"), "`model.elastic.alpha`"),
    ("empty range", VALID.replace("omega = [0.1, 3.0]", "omega = [3.0, 3.0]"), "the frequency range is empty"),
    ("harmonics zero", VALID.replace("harmonics = 32", "harmonics = 0"), "`analysis.harmonics` must be an integer >= 1"),
    ("phases length", VALID.replace("amplitudes = [0.03]", "amplitudes = [0.03]\nphases = [0.0, 0.0]"), "`excitation.phases`"),
    ("invalid TOML", VALID.replace("inertia = 1.0", "inertia 1.0"), "is not valid TOML"),
]


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize(("text", "fragment"), [row[1:] for row in BAD_CONFIGS], ids=[row[0] for row in BAD_CONFIGS])
def test_bad_config_exits_2_and_creates_nothing(tmp_path: Path, text: str, fragment: str) -> None:
    write_config(tmp_path, text)
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert_bad_input(result, fragment, "case.toml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml"]


@pytest.mark.usefixtures("no_solver")
def test_missing_config_file(tmp_path: Path) -> None:
    result = invoke(["frf", "nope.toml"], tmp_path)
    assert_bad_input(result, "'nope.toml' does not exist")
    assert list(tmp_path.iterdir()) == []  # not even the default ./rattle-out


# --------------------------------------------------------------------------------------------
# Bad options: exit 2, the option named
# --------------------------------------------------------------------------------------------
BAD_OPTIONS = [
    ("harmonics zero", ["--harmonics", "0"], ["`--harmonics` must be an integer >= 1, got 0"]),
    ("harmonics negative", ["--harmonics", "-4"], ["`--harmonics`", "got -4"]),
    ("harmonics not an integer", ["--harmonics", "2.5"], ["'--harmonics'", "not a valid integer"]),
    ("omega-min zero", ["--omega-min", "0"], ["`--omega-min` must be > 0 rad/s"]),
    ("omega-min nan", ["--omega-min", "nan"], ["`--omega-min` must be finite"]),
    ("omega-max inf", ["--omega-max", "inf"], ["`--omega-max` must be finite"]),
    ("omega-min above omega-max", ["--omega-min", "2", "--omega-max", "1"],
     ["`--omega-min` must be < `--omega-max`", "`--omega-min` = 2.0", "`--omega-max` = 1.0", "empty"]),
    ("omega-min above the file's max", ["--omega-min", "5"],
     ["`--omega-min` must be < `analysis.omega.2`", "`analysis.omega.2` = 3.0"]),
    ("omega-max below the file's min", ["--omega-max", "0.05"], ["`analysis.omega.1` must be < `--omega-max`"]),
    ("omega-min not a number", ["--omega-min", "low"], ["'--omega-min'", "not a valid float"]),
    ("unknown option", ["--points", "10"], ["No such option", "--points", "rattle frf --help"]),
    ("missing option value", ["--harmonics"], ["'--harmonics' requires an argument"]),
]


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize(("options", "fragments"), [row[1:] for row in BAD_OPTIONS], ids=[row[0] for row in BAD_OPTIONS])
def test_bad_option_exits_2_and_creates_nothing(tmp_path: Path, options: list[str], fragments: list[str]) -> None:
    write_config(tmp_path)
    result = invoke(["frf", "case.toml", "-o", "out", *options], tmp_path)
    assert_bad_input(result, *fragments)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml"]


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["simulate"], ["No such command 'simulate'", "rattle --help"]),
        (["demo", "--harmonics", "3"], ["No such option", "--harmonics"]),
        (["frf"], ["Missing argument 'CONFIG'"]),
        (["frf", "case.toml", "extra.toml"], ["unexpected extra argument"]),
    ],
    ids=["unknown command", "demo has no --harmonics", "missing config", "extra argument"],
)
def test_usage_errors_exit_2(tmp_path: Path, args: list[str], fragments: list[str]) -> None:
    write_config(tmp_path)
    assert_bad_input(invoke(args, tmp_path), *fragments)


@pytest.mark.usefixtures("no_solver")
def test_output_path_that_is_a_file(tmp_path: Path) -> None:
    write_config(tmp_path)
    (tmp_path / "taken").write_text("keep me")
    result = invoke(["frf", "case.toml", "-o", "taken"], tmp_path)
    assert_bad_input(result, "`--output` must be a directory", "'taken'")
    result = invoke(["frf", "case.toml", "-o", "taken/sub"], tmp_path)
    assert_bad_input(result, "`--output` 'taken/sub' cannot be created because 'taken' is a file")
    result = invoke(["demo", "-o", "taken"], tmp_path)
    assert_bad_input(result, "`--output` must be a directory")
    assert (tmp_path / "taken").read_text() == "keep me"


def test_help_and_version_exit_0(tmp_path: Path) -> None:
    result = invoke(["--help"], tmp_path)
    assert result.exit_code == 0 and "frf" in result.stdout and "demo" in result.stdout
    result = invoke(["frf", "--help"], tmp_path)
    assert result.exit_code == 0
    for option in ("--output", "--harmonics", "--omega-min", "--omega-max"):
        assert option in result.stdout
    result = invoke(["--version"], tmp_path)
    assert result.exit_code == 0 and result.stdout.startswith("rattle ")


# --------------------------------------------------------------------------------------------
# The real entry points: python -m rattle and main()
# --------------------------------------------------------------------------------------------
def _python_m_rattle(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    return subprocess.run(
        [sys.executable, "-m", "rattle", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=120
    )


def test_python_m_rattle_bad_config(tmp_path: Path) -> None:
    write_config(tmp_path, VALID.replace("stiffness = 1.0", "stiffness = -1.0"))
    proc = _python_m_rattle(["frf", "case.toml", "-o", "out"], tmp_path)
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.strip().splitlines() == [
        "rattle: error: case.toml: `model.stiffness` must be > 0, got -1.0"
    ]
    assert not (tmp_path / "out").exists()


def test_python_m_rattle_bad_option(tmp_path: Path) -> None:
    write_config(tmp_path)
    proc = _python_m_rattle(["frf", "case.toml", "--harmonics", "0"], tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.startswith("rattle: error: `--harmonics`")
    assert not (tmp_path / "rattle-out").exists()
    proc = _python_m_rattle(["frf", "case.toml", "--no-such-option"], tmp_path)
    assert proc.returncode == 2
    assert "No such option" in proc.stderr
    assert not (tmp_path / "rattle-out").exists()


def test_main_exits_with_the_status(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as info:
        main(["frf", "missing.toml"])
    assert info.value.code == 2
    assert capsys.readouterr().err.startswith("rattle: error: configuration file 'missing.toml'")
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0


# --------------------------------------------------------------------------------------------
# Numerical failure and success, with a stand-in solver (the CLI's contract with the core)
# --------------------------------------------------------------------------------------------
def FakeResponse(n: int = 3) -> _FakeResponse:  # noqa: N802 - stands for the class
    """The shared stand-in, with numpy scalars in its settings (the metadata must still be JSON)."""
    return _FakeResponse(n, settings={"harmonics": np.int64(32)}, timings={"continuation": 0.5})


def _case_arguments(model: Any, analysis: Any, options: Any = None) -> dict[str, Any]:
    """``rattle.analysis.case_arguments`` of a continuous law (the fakes stand in for one)."""
    return {"omega": analysis.omega, "harmonics": analysis.harmonics, **(options or {})}


@pytest.fixture
def fake_solver(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """Replace rattle.analysis by a module whose frequency_response does what ``state`` says."""
    state: dict[str, Any] = {"calls": [], "raise": None, "result": FakeResponse()}

    def frequency_response(model: Any, omega: tuple[float, float] = (0.1, 3.0), harmonics: int = 32, *, throw: bool = True,
                           progress: Any = None) -> _FakeResponse:
        state["calls"].append({"model": model, "omega": omega, "harmonics": harmonics, "throw": throw})
        if state["raise"] is not None:
            raise state["raise"]
        return state["result"]

    module = types.ModuleType("rattle.analysis")
    module.frequency_response = frequency_response  # type: ignore[attr-defined]
    module.case_arguments = _case_arguments  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "rattle.analysis", module)
    return state


def test_frf_success_writes_three_files(tmp_path: Path, fake_solver: dict[str, Any]) -> None:
    pytest.importorskip("matplotlib")
    write_config(tmp_path)
    result = invoke(["frf", "case.toml", "-o", "out/nested", "--harmonics", "8", "--omega-max", "2.5"], tmp_path)
    assert result.exit_code == 0, result.stderr
    (call,) = fake_solver["calls"]
    assert call["omega"] == (0.1, 2.5) and call["harmonics"] == 8 and call["throw"] is True
    out = tmp_path / "out" / "nested"
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    assert list(read_csv(out / "frf.csv")) == list(FRF_COLUMNS)
    assert (out / "frf.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    meta = json.loads((out / "frf.json").read_text())
    assert meta["config"]["model"]["elastic"]["type"] == "clutch"
    assert meta["config_file"] == "case.toml"
    assert meta["options"] == {"harmonics": 8, "omega_max": 2.5}
    assert meta["analysis"] == {"omega": [0.1, 2.5], "harmonics": 8}
    assert meta["settings"] == {"harmonics": 32}
    assert meta["timings"]["continuation"] == 0.5 and meta["timings"]["cli_wall_time"] >= 0
    assert meta["version"] and meta["created"] and meta["environment"]["numpy"]
    assert "3 solution points (fake)" in result.stdout
    assert result.stderr == ""


def test_convergence_failure_without_partial_exits_1(tmp_path: Path, fake_solver: dict[str, Any]) -> None:
    write_config(tmp_path)
    fake_solver["raise"] = ConvergenceError("no periodic solution at the start of the range")
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 1
    assert result.stderr.strip() == (
        "rattle: error: numerical failure: no periodic solution at the start of the range"
    )
    assert not (tmp_path / "out").exists()


def test_convergence_failure_with_partial_writes_it_and_exits_1(tmp_path: Path, fake_solver: dict[str, Any]) -> None:
    pytest.importorskip("matplotlib")
    write_config(tmp_path)
    fake_solver["raise"] = ConvergenceError("step too small at Omega = 1.2", partial=FakeResponse(2))
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 1
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("rattle: error: numerical failure: step too small at Omega = 1.2; ")
    assert "written to" in line and "frf.csv" in line
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    assert len(read_csv(out / "frf.csv")["omega"]) == 2
    assert "2 solution points (fake)" in result.stdout


# --------------------------------------------------------------------------------------------
# End to end with the real solver (small and quick)
# --------------------------------------------------------------------------------------------
def test_frf_end_to_end_with_the_real_solver(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    write_config(tmp_path)
    result = invoke(["frf", "case.toml", "-o", "out", "--harmonics", "8", "--omega-min", "0.5", "--omega-max", "1.5"], tmp_path)
    assert result.exit_code == 0, result.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    frf = read_csv(out / "frf.csv")
    assert list(frf) == [*FRF_COLUMNS, "harmonics"]  # SPEC §3 + §8
    assert frf["omega"].min() == pytest.approx(0.5) and frf["omega"].max() == pytest.approx(1.5)
    assert frf["stable"].dtype == bool
    meta = json.loads((out / "frf.json").read_text())
    assert meta["analysis"] == {"omega": [0.5, 1.5], "harmonics": 8}


def test_harmonics_fewer_than_the_excitation_harmonics_are_refused(tmp_path: Path, no_solver: None) -> None:
    two = VALID.replace("amplitudes = [0.03]", "amplitudes = [0.03, 0.01]")
    write_config(tmp_path, two.replace("harmonics = 32", "harmonics = 1"))
    assert_bad_input(invoke(["frf", "case.toml", "-o", "out"], tmp_path), "`analysis.harmonics` must be >= 2")
    write_config(tmp_path, two)
    assert_bad_input(invoke(["frf", "case.toml", "-o", "out", "--harmonics", "1"], tmp_path), "`--harmonics` must be >= 2")
    assert not (tmp_path / "out").exists()


def test_library_argument_errors_are_bad_input(tmp_path: Path) -> None:
    """A combination only the library can judge (harmonics too few for --period) still exits 2
    with the library's message, not a traceback."""
    write_config(tmp_path)
    result = invoke(["orbit", "case.toml", "--omega", "0.8", "--period", "8", "--harmonics", "3", "-o", "out"], tmp_path)
    assert_bad_input(result, "`--harmonics` must be >= 8")
