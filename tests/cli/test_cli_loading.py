"""rattle.cli.output.loading: the command line's imports and writing without the cyclic
collector, what they imported frozen after; elsewhere the body runs as it is."""

from __future__ import annotations

import gc
import sys
from pathlib import Path

import pytest

from rattle import _signals
from rattle.cli.output import loading


@pytest.fixture
def fresh_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    name = "rattle_loading_probe_module"
    (tmp_path / f"{name}.py").write_text("class A:\n    pass\n\nCYCLE = [A()]\nCYCLE.append(CYCLE)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield name
    sys.modules.pop(name, None)


@pytest.fixture
def collector() -> None:
    enabled = gc.isenabled()
    yield
    gc.unfreeze()  # nothing else freezes in the test process
    if enabled:
        gc.enable()


def test_an_import_in_the_command_line_runs_without_the_collector_and_is_frozen(
        fresh_module: str, collector: None, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_signals, "installed_at_start", lambda: True)
    gc.enable()
    frozen = gc.get_freeze_count()
    with loading():
        assert not gc.isenabled()
        __import__(fresh_module)
    assert gc.isenabled()
    assert gc.get_freeze_count() > frozen  # the module's objects: never searched for cycles again


def test_a_body_that_imports_nothing_freezes_nothing(collector: None, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_signals, "installed_at_start", lambda: True)
    gc.enable()
    frozen = gc.get_freeze_count()
    with loading():
        assert not gc.isenabled()
        garbage = [object() for _ in range(10)]
        garbage.append(garbage)
    assert gc.isenabled() and gc.get_freeze_count() == frozen


def test_the_collector_comes_back_when_the_body_raises(collector: None, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_signals, "installed_at_start", lambda: True)
    gc.enable()
    with pytest.raises(KeyboardInterrupt), loading():
        raise KeyboardInterrupt
    assert gc.isenabled()


def test_outside_the_command_line_the_body_runs_as_it_is(fresh_module: str, collector: None) -> None:
    assert not _signals.installed_at_start()
    gc.enable()
    frozen = gc.get_freeze_count()
    with loading():
        assert gc.isenabled()
        __import__(fresh_module)
    assert gc.get_freeze_count() == frozen


def test_a_collector_switched_off_stays_off(fresh_module: str, collector: None,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_signals, "installed_at_start", lambda: True)
    gc.disable()
    with loading():
        __import__(fresh_module)
    assert not gc.isenabled()


def test_an_interrupted_command_writes_no_output_set(tmp_path, monkeypatch) -> None:
    """A signal whose Interrupted some code swallowed (the command went on) still stops the output
    set: before it is opened, and at the last moment before it lands — nothing is left, not even
    the output folder (seen on a fresh install: a parallel sweep Ctrl-C'd twice ran to its end and
    left `out`)."""
    from rattle import _signals
    from rattle.cli import output

    monkeypatch.setattr(_signals._State, "first", None)
    out = tmp_path / "deep" / "out"

    def write(path):
        path.write_text("x", encoding="utf-8")
        _signals._State.first = 2  # the signal arrives while the set is being written, and is swallowed

    with pytest.raises(_signals.Interrupted):
        output.write_set(out, ["a.txt"], [("a.txt", write)])
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    with pytest.raises(_signals.Interrupted):  # received before: the set is never opened
        output.write_set(out, ["a.txt"], [("a.txt", lambda p: p.write_text("x", encoding="utf-8"))])
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    _signals._State.first = None
    assert output.write_set(out, ["a.txt"], [("a.txt", lambda p: p.write_text("x", encoding="utf-8"))]) == ["a.txt"]
    assert (out / "a.txt").read_text(encoding="utf-8") == "x"
