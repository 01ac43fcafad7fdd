"""A damaged, foreign or unreadable map store (issue 28, item 1): every damaged part is computed
again, with one warning line naming the damage; what cannot be replaced (a folder or a special
file in a part's place, ``map.parts`` that is a file or a broken link, a read-only store with
combinations left) is refused with exit status 2 naming the path, before any work, never
blocking on a FIFO.

The maps run in-process through click's CliRunner on the serial engine (``--workers 1``) with the
combination's computation replaced by a synthetic cell (tests/_fake_map.py): what is tested is
the store, not the numerics.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import signal
import socket
import stat
import subprocess
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

import rattle.maps._map as map_module
import rattle.maps._store as store_module
from _cases import clutch_toml  # type: ignore[import-not-found]
from _cli_helpers import invoke  # type: ignore[import-not-found]
from _fake_map import synthetic_cell  # type: ignore[import-not-found]

FAST_MAP = clutch_toml((0.5, 0.8), 8)

MAP = ["map", "case.toml", "--vary", "alpha=0.1:0.2:2", "--omega-points", "12", "--workers", "1", "-q", "-o", "out"]


@contextlib.contextmanager
def bounded(seconds: float) -> Iterator[None]:
    """Fail instead of hanging: SIGALRM after ``seconds`` raises in the test."""

    def expire(_signum: int, _frame: object) -> None:
        raise TimeoutError(f"no answer within {seconds} s: a hang")

    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@pytest.fixture
def fake_cells(monkeypatch: pytest.MonkeyPatch) -> list[dict]:
    """compute_cell replaced by a synthetic cell, the heat maps by a stub file (matplotlib is not
    what is tested, and costs a second a run); returns the list of the tasks computed."""
    import rattle.cli.commands as commands

    computed: list[dict] = []

    def figure(_draw, path: Path) -> bool:
        path.write_bytes(b"\x89PNG stub")
        return True

    monkeypatch.setattr(commands, "save_figure", figure)

    def compute(task: dict) -> dict:
        computed.append(task["values"])
        grid = np.linspace(*task["omega"], task["omega_points"])
        return synthetic_cell(task["values"], grid).to_dict()

    monkeypatch.setattr(map_module, "compute_cell", compute)
    return computed


@pytest.fixture
def first_run(tmp_path: Path, fake_cells: list[dict]) -> Path:
    (tmp_path / "case.toml").write_text(FAST_MAP, encoding="utf-8")
    with bounded(60):
        result = invoke(MAP, tmp_path)
    assert result.exit_code == 0, result.stderr
    fake_cells.clear()
    return tmp_path


def _parts(folder: Path) -> list[Path]:
    return sorted((folder / "out" / "map.parts").glob("*.json"))


def _edit(part: Path, change: Callable[[dict], None]) -> None:
    doc = json.loads(part.read_text())
    change(doc["result"])
    part.write_text(json.dumps(doc))


def _set(key: str, value: object) -> Callable[[dict], None]:
    def change(result: dict) -> None:
        result[key] = value

    return change


def _drop(key: str) -> Callable[[dict], None]:
    def change(result: dict) -> None:
        del result[key]

    return change


def _shorten(key: str) -> Callable[[dict], None]:
    def change(result: dict) -> None:
        result[key] = result[key][:-1]

    return change


def _first(key: str, value: object) -> Callable[[dict], None]:
    def change(result: dict) -> None:
        result[key][0] = value

    return change


def _clear(result: dict) -> None:
    result.clear()


def _values_text(result: dict) -> None:
    result["values"] = {"alpha": "a lot"}


def _values_other(result: dict) -> None:
    result["values"] = {"alpha": 0.15}


def _omega_shifted(result: dict) -> None:
    result["omega"] = [x * 1.001 for x in result["omega"]]


# (id, edit of the part's result table, a fragment of the warning)
RESULT_DAMAGE: list[tuple[str, Callable[[dict], None], str]] = [
    ("no omega", _drop("omega"), "`omega`"),
    ("no values", _drop("values"), "`values`"),
    ("no rattle", _drop("rattle"), "`rattle`"),
    ("no n_stable", _drop("n_stable"), "`n_stable`"),
    ("empty dict", _clear, "lacks"),
    ("omega shorter than the grid", _shorten("omega"), "`omega`"),
    ("rms shorter", _shorten("rms_max_stable"), "`rms_max_stable` has"),
    ("rattle shorter", _shorten("rattle"), "`rattle` has"),
    ("periods shorter", _shorten("periods_stable"), "`periods_stable` has"),
    ("values text", _values_text, "`values`"),
    ("values a list", _set("values", [0.1]), "`values`"),
    ("values of another combination", _values_other, "`values`"),
    ("omega text", _set("omega", "0.5 … 0.8"), "`omega` must be a list"),
    ("omega of text", _first("omega", "0.5"), "`omega` must hold numbers"),
    ("omega shifted", _omega_shifted, "not the map's grid"),
    ("omega null", _first("omega", None), "`omega`"),
    ("rms text", _first("rms_max_stable", "big"), "`rms_max_stable` must hold"),
    ("rms list", _set("rms_max_stable", {"a": 1}), "`rms_max_stable` must be a list"),
    ("n_solutions text", _first("n_solutions", "three"), "`n_solutions`"),
    ("n_solutions negative", _first("n_solutions", -1), "`n_solutions`"),
    ("n_solutions float", _first("n_solutions", 1.5), "`n_solutions`"),
    ("n_stable bool", _first("n_stable", True), "`n_stable`"),
    ("rattle number", _first("rattle", 1), "`rattle`"),
    ("regime number", _first("regime_max_stable", 3), "`regime_max_stable`"),
    ("periods number", _first("periods_stable", 1), "`periods_stable`"),
    ("timings text", _set("timings", "fast"), "`timings`"),
    ("timings of text", _set("timings", {"total": "fast"}), "`timings`"),
    ("intervals text", _set("intervals", "everywhere"), "`intervals`"),
    ("intervals of text", _set("intervals", {"impact": "0.5-0.6"}), "`intervals.impact`"),
    ("intervals of short pairs", _set("intervals", {"impact": [[0.5]]}), "`intervals.impact`"),
    ("intervals of text pairs", _set("intervals", {"impact": [["a", "b"]]}), "`intervals.impact`"),
    ("special points text", _set("special_points", "fold"), "`special_points`"),
    ("special points of numbers", _set("special_points", [1, 2]), "`special_points`"),
    ("attractors dict", _set("attractors", {}), "`attractors`"),
    ("search list", _set("search", []), "`search`"),
    ("status unknown", _set("status", "great"), "`status`"),
    ("status number", _set("status", 1), "`status`"),
    ("message number", _set("message", 7), "`message`"),
    ("spl text", _set("spl_max_stable_db", "loud"), "`spl_max_stable_db`"),
    ("spl shorter", _set("spl_max_stable_db", [1.0]), "`spl_max_stable_db`"),
]


def _rerun(folder: Path) -> tuple[object, list[str]]:
    with bounded(60):
        result = invoke(MAP, folder)
    warnings = [line for line in result.stderr.splitlines() if line.startswith("rattle: warning:")]
    return result, warnings


@pytest.mark.parametrize(("change", "fragment"), [c[1:] for c in RESULT_DAMAGE], ids=[c[0] for c in RESULT_DAMAGE])
def test_a_damaged_result_is_computed_again(first_run: Path, fake_cells: list[dict], change, fragment) -> None:
    part = _parts(first_run)[0]
    _edit(part, change)
    result, warnings = _rerun(first_run)
    assert result.exit_code == 0, result.stderr
    assert len(warnings) == 1 and "1 damaged or foreign part(s) computed again" in warnings[0], result.stderr
    assert fragment in warnings[0], warnings[0]
    assert len(fake_cells) == 1  # only the damaged one
    assert len(_parts(first_run)) == 2
    doc = json.loads(part.read_text())  # replaced by a whole part
    assert len(doc["result"]["omega"]) == 12
    # and a third run reads everything back, without a warning
    result, warnings = _rerun(first_run)
    assert result.exit_code == 0 and warnings == [] and len(fake_cells) == 1


def _truncate(part: Path) -> None:
    part.write_text(part.read_text()[:100])


def _empty(part: Path) -> None:
    part.write_text("")


def _binary(part: Path) -> None:
    part.write_bytes(b"\xff\xfe\x00\x01garbage")


def _not_object(part: Path) -> None:
    part.write_text("[1, 2, 3]")


def _other_key(part: Path) -> None:
    doc = json.loads(part.read_text())
    doc["key"] = "0" * 64
    part.write_text(json.dumps(doc))


def _format(part: Path) -> None:
    doc = json.loads(part.read_text())
    doc["store_format"] = 99
    part.write_text(json.dumps(doc))


def _no_result(part: Path) -> None:
    doc = json.loads(part.read_text())
    doc["result"] = "gone"
    part.write_text(json.dumps(doc))


def _deep(part: Path) -> None:
    part.write_text("[" * 5_000 + "]" * 5_000)


def _nan_json(part: Path) -> None:
    part.write_text(part.read_text().replace('"omega":[', '"omega":[NaN,', 1))


def _link_to_other(part: Path) -> None:
    other = _parts(part.parents[2])[1]
    part.unlink()
    os.symlink(other, part)


def _link_to_zero(part: Path) -> None:
    part.unlink()
    os.symlink("/dev/zero", part)


def _link_to_fifo(part: Path) -> None:
    fifo = part.parent.parent / "pipe"
    os.mkfifo(fifo)
    part.unlink()
    os.symlink(fifo, part)


def _dangling(part: Path) -> None:
    part.unlink()
    os.symlink(part.parent / "nowhere", part)


def _huge(part: Path) -> None:
    part.write_text(" " * 30_000 + part.read_text())  # over the (lowered) size bound


FILE_DAMAGE: list[tuple[str, Callable[[Path], None], str]] = [
    ("truncated", _truncate, "not complete JSON"),
    ("empty", _empty, "not complete JSON"),
    ("binary", _binary, "not UTF-8"),
    ("a JSON list", _not_object, "JSON list"),
    ("another key", _other_key, "another combination"),
    ("another format", _format, "store format 99"),
    ("no result table", _no_result, "no result table"),
    ("nested 5 000 deep", _deep, "not complete JSON"),
    ("NaN in omega", _nan_json, "`omega`"),
    ("symlink to another part", _link_to_other, "symbolic link"),
    ("symlink to /dev/zero", _link_to_zero, "symbolic link"),
    ("symlink to a FIFO", _link_to_fifo, "symbolic link"),
    ("dangling symlink", _dangling, "symbolic link"),
    ("over the size bound", _huge, "bytes"),
]


@pytest.mark.parametrize(("damage", "fragment"), [c[1:] for c in FILE_DAMAGE], ids=[c[0] for c in FILE_DAMAGE])
def test_a_damaged_part_file_is_computed_again(first_run: Path, fake_cells: list[dict], monkeypatch, damage,
                                               fragment) -> None:
    part = _parts(first_run)[0]
    monkeypatch.setattr(store_module, "MAX_PART_BYTES", part.stat().st_size + 20_000)
    damage(part)
    result, warnings = _rerun(first_run)
    assert result.exit_code == 0, result.stderr
    assert len(warnings) == 1 and fragment in warnings[0], result.stderr
    assert len(fake_cells) == 1
    assert not part.is_symlink() and part.is_file()  # a part of its own now
    assert json.loads(part.read_text())["result"]["values"] == {"alpha": 0.1}


def test_every_part_damaged_is_one_warning_line(first_run: Path, fake_cells: list[dict]) -> None:
    for part in _parts(first_run):
        part.write_text("x")
    result, warnings = _rerun(first_run)
    assert result.exit_code == 0 and len(warnings) == 1 and "2 damaged" in warnings[0]
    assert len(fake_cells) == 2


# --------------------------------------------------------------------------------------------
# What cannot be replaced: refused, exit 2, naming the path, before any work
# --------------------------------------------------------------------------------------------
def _part_dir(folder: Path) -> str:
    part = _parts(folder)[0]
    part.unlink()
    part.mkdir()
    return part.name


def _part_dir_full(folder: Path) -> str:
    part = _parts(folder)[0]
    part.unlink()
    part.mkdir()
    (part / "keep.txt").write_text("mine")
    return part.name


def _part_fifo(folder: Path) -> str:
    part = _parts(folder)[0]
    part.unlink()
    os.mkfifo(part)
    return part.name


def _part_socket(folder: Path) -> str:
    part = _parts(folder)[0]
    part.unlink()
    old = Path.cwd()
    os.chdir(part.parent)  # a socket path must be short
    try:
        sock = socket.socket(socket.AF_UNIX)
        sock.bind(part.name)
        sock.close()
    finally:
        os.chdir(old)
    return part.name


def _parts_file(folder: Path) -> str:
    parts = folder / "out" / "map.parts"
    for p in parts.iterdir():
        p.unlink()
    parts.rmdir()
    parts.write_text("not a folder")
    return "map.parts"


def _parts_fifo(folder: Path) -> str:
    parts = folder / "out" / "map.parts"
    for p in parts.iterdir():
        p.unlink()
    parts.rmdir()
    os.mkfifo(parts)
    return "map.parts"


def _parts_dangling(folder: Path) -> str:
    parts = folder / "out" / "map.parts"
    for p in parts.iterdir():
        p.unlink()
    parts.rmdir()
    os.symlink(folder / "gone", parts)
    return "broken symbolic link"


def _parts_link_to_file(folder: Path) -> str:
    parts = folder / "out" / "map.parts"
    for p in parts.iterdir():
        p.unlink()
    parts.rmdir()
    (folder / "afile").write_text("x")
    os.symlink(folder / "afile", parts)
    return "map.parts"


REFUSED: list[tuple[str, Callable[[Path], str], str]] = [
    ("a part that is an empty folder", _part_dir, "is a folder, not a file"),
    ("a part that is a folder with files", _part_dir_full, "is a folder, not a file"),
    ("a part that is a FIFO", _part_fifo, "named pipe"),
    ("a part that is a socket", _part_socket, "socket"),
    ("map.parts a file", _parts_file, "is a file, not a folder"),
    ("map.parts a FIFO", _parts_fifo, "named pipe"),
    ("map.parts a dangling symlink", _parts_dangling, "map.parts"),
    ("map.parts a symlink to a file", _parts_link_to_file, "not a folder"),
]


@pytest.mark.parametrize(("setup", "fragment"), [c[1:] for c in REFUSED], ids=[c[0] for c in REFUSED])
def test_what_cannot_be_replaced_is_refused(first_run: Path, fake_cells: list[dict], setup, fragment) -> None:
    name = setup(first_run)
    before = sorted(str(p.relative_to(first_run)) for p in first_run.rglob("*"))
    result, _ = _rerun(first_run)
    assert result.exit_code == 2, (result.exit_code, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rattle: error: "), result.stderr
    assert name in lines[0] and fragment in lines[0], lines[0]
    assert fake_cells == []  # before any work
    assert sorted(str(p.relative_to(first_run)) for p in first_run.rglob("*")) == before  # nothing written


def _read_only_parts(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Creating a file in map.parts fails with EROFS (elsewhere it works)."""
    real = tempfile.mkstemp
    parts = (folder / "out" / "map.parts").resolve()

    def mkstemp(*args, **kw):
        if Path(kw.get("dir", ".")).resolve() == parts:
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))
        return real(*args, **kw)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)


def test_a_read_only_store_with_a_part_missing_is_refused(first_run: Path, fake_cells: list[dict],
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """As root every folder is writable, so the file system's answer is simulated: the probe's
    temporary file cannot be created (EROFS)."""
    _parts(first_run)[0].unlink()

    _read_only_parts(first_run, monkeypatch)
    result, _ = _rerun(first_run)
    assert result.exit_code == 2, result.stderr
    line = result.stderr.strip()
    assert "map.parts" in line and "not writable" in line and "EROFS" in line and "1 combination" in line, line
    assert fake_cells == []


def test_a_read_only_store_that_is_complete_is_read(first_run: Path, fake_cells: list[dict],
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    _read_only_parts(first_run, monkeypatch)
    result, warnings = _rerun(first_run)
    assert result.exit_code == 0 and warnings == [] and fake_cells == []


def _can_mount() -> bool:
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        return False
    with tempfile.TemporaryDirectory() as d:
        ok = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", d], capture_output=True).returncode == 0
        if ok:
            subprocess.run(["umount", d], capture_output=True)
        return ok


@pytest.mark.skipif(not _can_mount(), reason="needs root and mount (a real read-only file system)")
def test_a_really_read_only_store_is_refused(first_run: Path, fake_cells: list[dict]) -> None:
    parts = first_run / "out" / "map.parts"
    saved = {p.name: p.read_bytes() for p in parts.iterdir()}
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(parts)], check=True)
    try:
        first = sorted(saved)[0]
        (parts / first).write_bytes(saved[first])  # one part there, one missing
        subprocess.run(["mount", "-o", "remount,ro", str(parts)], check=True)
        result, _ = _rerun(first_run)
        assert result.exit_code == 2, result.stderr
        assert "not writable" in result.stderr and "EROFS" in result.stderr and fake_cells == []
    finally:
        subprocess.run(["umount", str(parts)], check=True)


def test_a_fifo_part_is_never_opened(tmp_path: Path) -> None:
    """MapStore.read on a FIFO answers at once (a reader opening it would wait for a writer)."""
    store = store_module.MapStore(tmp_path)
    key = store.key({"x": 1})
    store.parts.mkdir(parents=True)
    os.mkfifo(store.path(key))
    with bounded(10), pytest.raises(Exception, match="named pipe"):
        store.read(key)
    assert stat.S_ISFIFO(os.lstat(store.path(key)).st_mode)  # left alone


def test_the_store_api_reads_what_it_wrote_and_names_damage(tmp_path: Path) -> None:
    store = store_module.MapStore(tmp_path)
    key = store.key({"x": 1})
    assert store.read(key) == (None, None)
    store.save(key, {"v": 1})
    assert store.read(key) == ({"v": 1}, None)
    store.path(key).write_text("{")
    data, damage = store.read(key)
    assert data is None and "JSON" in damage
