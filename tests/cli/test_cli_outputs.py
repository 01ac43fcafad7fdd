"""Output sets: every command's files are staged and moved into place together, so an
interrupted or failed run leaves the earlier set intact (never a mix); numerical failures exit 1
with one line and a consistent set; warnings reach the user as one line; -v and --version work
on every command."""

from __future__ import annotations

import json
import os
import sys
import types
import warnings
from pathlib import Path
from typing import Any

import pytest

from rattle.cli.output import FRF_FILES
from rattle.errors import ConvergenceError
from rattle.io import STAGING_PREFIX, OutputSet, read_csv, recover_staging
from _cli_helpers import invoke, write_config
from _fake_result import FakeResponse

OLD = {"frf.csv": "old csv\n", "frf.json": "{\"old\": true}\n", "frf.png": "old png"}


def _case_arguments(model: Any, analysis: Any, options: Any = None) -> dict[str, Any]:
    """``rattle.analysis.case_arguments`` of a continuous law (the fakes stand in for one)."""
    return {"omega": analysis.omega, "harmonics": analysis.harmonics, **(options or {})}


@pytest.fixture
def fake_solver(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    state: dict[str, Any] = {"raise": None, "result": FakeResponse(), "warn": None}

    def frequency_response(model: Any, omega: Any = None, harmonics: int = 32, *, throw: bool = True, **_: Any) -> Any:
        if state["warn"] is not None:
            for _i in range(3):  # the same warning three times: shown once
                warnings.warn_explicit(state["warn"], RuntimeWarning, "/x/src/rattle/measures.py", 141)
        if state["raise"] is not None:
            raise state["raise"]
        return state["result"]

    module = types.ModuleType("rattle.analysis")
    module.frequency_response = frequency_response  # type: ignore[attr-defined]
    module.case_arguments = _case_arguments  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "rattle.analysis", module)
    return state


def _old_set(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for name, text in OLD.items():
        (out / name).write_text(text)


def _no_leftovers(folder: Path) -> None:
    if folder.exists():
        hidden = [p.name for p in folder.iterdir() if p.name.startswith(".")]
        assert hidden == [], hidden  # no staging folder, no .tmp file


# --------------------------------------------------------------------------------------------
# OutputSet itself
# --------------------------------------------------------------------------------------------
def test_output_set_moves_every_file_in_and_leaves_other_files(tmp_path: Path) -> None:
    out = tmp_path / "out"
    _old_set(out)
    (out / "notes.txt").write_text("the user's own file")
    with OutputSet(out, FRF_FILES) as staged:
        for name in ("frf.csv", "frf.json"):
            staged.path(name).write_text("new " + name)
        assert staged.staging is not None and staged.staging.parent == out
        assert (out / "frf.csv").read_text() == OLD["frf.csv"]  # nothing moved before the commit
        written = staged.commit()
    assert written == ["frf.csv", "frf.json"]
    assert (out / "frf.csv").read_text() == "new frf.csv"
    assert not (out / "frf.png").exists()  # the old figure would not match the new data
    assert (out / "notes.txt").read_text() == "the user's own file"
    _no_leftovers(out)


def test_output_set_interrupted_before_the_commit_keeps_the_old_set(tmp_path: Path) -> None:
    out = tmp_path / "out"
    _old_set(out)
    with pytest.raises(KeyboardInterrupt):
        with OutputSet(out, FRF_FILES) as staged:
            staged.path("frf.csv").write_text("new")
            raise KeyboardInterrupt
    assert {p.name: p.read_text() for p in out.iterdir()} == OLD
    _no_leftovers(out)


def test_output_set_removes_the_folders_it_created_when_nothing_was_committed(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError):
        with OutputSet(tmp_path / "a" / "b" / "c", FRF_FILES) as staged:
            staged.path("frf.csv").write_text("new")
            raise RuntimeError("drawing failed")
    assert list(tmp_path.iterdir()) == []


def test_output_set_refuses_names_outside_the_set(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="plain file names"):
        OutputSet(tmp_path, ["../escape.csv"])
    with OutputSet(tmp_path, FRF_FILES) as staged, pytest.raises(ValueError, match="not part of this output set"):
        staged.path("sweep.csv")


def _dead_pid() -> int:
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os._exit(0)
    os.waitpid(pid, 0)
    return pid


def test_recovery_finishes_a_journalled_commit_and_drops_an_unfinished_one(tmp_path: Path) -> None:
    """A run killed outright (SIGKILL) in the middle of its renames is completed by the next one;
    one killed before its journal is dropped; a live run's folder is left alone."""
    out = tmp_path / "out"
    _old_set(out)
    dead = _dead_pid()
    done = out / f"{STAGING_PREFIX}{dead}-aaaa"
    done.mkdir()
    (done / "frf.json").write_text("new json")  # frf.csv was already moved in
    (out / "frf.csv").write_text("new csv")
    (done / ".commit.json").write_text(json.dumps({"moves": ["frf.csv", "frf.json"], "removals": ["frf.png"]}))
    unfinished = out / f"{STAGING_PREFIX}{dead}-bbbb"
    unfinished.mkdir()
    (unfinished / "frf.csv").write_text("half")
    live = out / f"{STAGING_PREFIX}{os.getppid()}-cccc"
    live.mkdir()
    assert sorted(recover_staging(out, FRF_FILES)) == sorted([done.name, unfinished.name])
    assert (out / "frf.csv").read_text() == "new csv" and (out / "frf.json").read_text() == "new json"
    assert not (out / "frf.png").exists()
    assert not done.exists() and not unfinished.exists() and live.exists()


# --------------------------------------------------------------------------------------------
# The commands: interrupted, failed, warned
# --------------------------------------------------------------------------------------------
def test_ctrl_c_while_drawing_leaves_the_old_set(tmp_path: Path, fake_solver: dict[str, Any]) -> None:
    pytest.importorskip("matplotlib")
    write_config(tmp_path)
    _old_set(tmp_path / "out")

    def interrupt() -> None:
        raise KeyboardInterrupt

    fake_solver["result"] = FakeResponse(on_plot=interrupt)
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 130
    assert result.stderr.strip().splitlines() == [
        "rattle: error: interrupted by SIGINT; temporary files were removed and no output set was left half-written"
    ]
    assert {p.name: p.read_text() for p in (tmp_path / "out").iterdir()} == OLD
    _no_leftovers(tmp_path / "out")


def test_ctrl_c_in_a_new_folder_leaves_no_folder(tmp_path: Path, fake_solver: dict[str, Any]) -> None:
    pytest.importorskip("matplotlib")
    write_config(tmp_path)

    def interrupt() -> None:
        raise KeyboardInterrupt

    fake_solver["result"] = FakeResponse(on_plot=interrupt)
    result = invoke(["frf", "case.toml", "-o", "new/deeper"], tmp_path)
    assert result.exit_code == 130
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml"]


@pytest.mark.parametrize("error", [OverflowError("(34, 'Numerical result out of range')"),
                                   FloatingPointError("overflow encountered in multiply"),
                                   ZeroDivisionError("float division by zero")],
                         ids=["overflow", "floating point", "zero division"])
def test_arithmetic_errors_are_a_numerical_failure(tmp_path: Path, fake_solver: dict[str, Any],
                                                   error: Exception) -> None:
    write_config(tmp_path)
    _old_set(tmp_path / "out")
    fake_solver["raise"] = error
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 1
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("rattle: error: numerical failure: ") and type(error).__name__ in line
    assert {p.name: p.read_text() for p in (tmp_path / "out").iterdir()} == OLD  # earlier set intact


def test_overflow_with_partial_points_writes_them_as_one_set(tmp_path: Path, fake_solver: dict[str, Any]) -> None:
    pytest.importorskip("matplotlib")
    write_config(tmp_path)
    _old_set(tmp_path / "out")
    error = OverflowError("overflow at Omega = 1.2")
    error.partial = FakeResponse(2)  # type: ignore[attr-defined]
    fake_solver["raise"] = error
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 1
    (line,) = result.stderr.strip().splitlines()
    assert "overflow at Omega = 1.2" in line and "written to" in line
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == list(FRF_FILES)
    assert len(read_csv(out / "frf.csv")["omega"]) == 2
    assert (out / "frf.png").read_bytes()[:4] == b"\x89PNG"  # the new figure, not the old one


def test_partial_set_without_a_figure_removes_the_old_figure(tmp_path: Path, fake_solver: dict[str, Any],
                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    write_config(tmp_path)
    _old_set(tmp_path / "out")
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # no matplotlib: no frf.png
    fake_solver["raise"] = ConvergenceError("step too small", partial=FakeResponse(2))
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 1
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["frf.csv", "frf.json"]


def test_numpy_warnings_become_one_line_each(tmp_path: Path, fake_solver: dict[str, Any],
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    write_config(tmp_path)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    fake_solver["warn"] = "overflow encountered in square"
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 0
    lines = result.stderr.strip().splitlines()
    numeric = [line for line in lines if "overflow" in line]
    assert numeric == [
        "rattle: warning: overflow encountered in square (RuntimeWarning); the run "
        "went on, but check the results at the frequencies where this happened"
    ]
    assert all(line.startswith("rattle: ") for line in lines)  # nothing raw


# --------------------------------------------------------------------------------------------
# -v and --version on every command
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", ["frf", "sweep", "orbit", "compare", "demo"])
def test_version_on_every_command(tmp_path: Path, command: str) -> None:
    result = invoke([command, "--version"], tmp_path)
    assert result.exit_code == 0 and result.stdout.startswith("rattle ")
    assert list(tmp_path.iterdir()) == []


def test_verbose_on_the_command(tmp_path: Path, fake_solver: dict[str, Any], monkeypatch: pytest.MonkeyPatch) -> None:
    write_config(tmp_path)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    result = invoke(["frf", "-v", "case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert "rattle: writing frf.csv" in result.stderr and "rattle: moved frf.csv, frf.json into out" in result.stderr
    result = invoke(["frf", "--verbose", "case.toml", "-o", "out", "--harmonics", "0"], tmp_path)
    assert result.exit_code == 2  # -v does not change the refusal


def test_verbose_does_not_leak_into_the_next_run(tmp_path: Path, fake_solver: dict[str, Any],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    write_config(tmp_path)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    invoke(["frf", "-v", "case.toml", "-o", "out"], tmp_path)
    result = invoke(["frf", "case.toml", "-o", "out"], tmp_path)
    assert "rattle: writing" not in result.stderr


def test_a_signal_during_the_move_waits_until_the_set_is_in_place(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """SIGINT arriving between two renames is held back: the whole new set is in place before
    the KeyboardInterrupt is raised."""
    import signal

    from rattle.files import _atomic

    out = tmp_path / "out"
    _old_set(out)
    real_replace = os.replace
    seen: list[str] = []

    def replace_then_signal(src: Any, dst: Any) -> None:
        real_replace(src, dst)
        seen.append(Path(dst).name)
        if len(seen) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # arrives in the middle of the move

    monkeypatch.setattr(_atomic.os, "replace", replace_then_signal)
    with pytest.raises(KeyboardInterrupt):
        with OutputSet(out, FRF_FILES) as staged:
            for name in FRF_FILES:
                staged.path(name).write_text("new " + name)
            staged.commit()
    assert seen == list(FRF_FILES)
    assert {p.name: p.read_text() for p in out.iterdir()} == {n: "new " + n for n in FRF_FILES}
