"""Staging recovery reads its journal as untrusted data: crafted or damaged journals (path
traversal, absolute paths, symlinks staged or in place, hidden names, names outside the output
set, special files, huge lists, non-JSON) must not move or delete anything outside the output
set, and must never block."""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import pytest

from rattle.io import STAGING_PREFIX, OutputSet, RecoveryWarning, recover_staging

SET = ("frf.csv", "frf.json", "frf.png")


def _dead_pid() -> int:
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os._exit(0)
    os.waitpid(pid, 0)
    return pid


def _world(tmp_path: Path) -> tuple[Path, Path, dict[Path, str]]:
    """An output folder with an earlier set and a user's file, and files beside and above it."""
    out = tmp_path / "case" / "out"
    out.mkdir(parents=True)
    files = {
        tmp_path / "case" / "victim.txt": "beside the output folder",
        tmp_path / "secret.txt": "above it",
        out / "case.toml": "the user's configuration in the output folder",
        out / "frf.csv": "old csv",
        out / "frf.png": "old png",
    }
    for path, text in files.items():
        path.write_text(text)
    staging = out / f"{STAGING_PREFIX}{_dead_pid()}-x"
    staging.mkdir()
    return out, staging, files


def _journal(staging: Path, plan: object) -> None:
    (staging / ".commit.json").write_text(json.dumps(plan))


def _untouched(files: dict[Path, str], *, except_: tuple[str, ...] = ()) -> None:
    for path, text in files.items():
        if path.name in except_:
            continue
        assert path.is_file() and not path.is_symlink(), path
        assert path.read_text() == text, path


@pytest.mark.parametrize("name", [
    "../victim.txt", "../../secret.txt", "..", ".", "", "sub/frf.csv", "/etc/passwd", None, 3,
    ".commit.json", "frf.csv\x00x", "case.toml",
])
def test_a_removal_not_of_the_set_is_refused_and_left_alone(tmp_path: Path, name: object) -> None:
    out, staging, files = _world(tmp_path)
    absolute = str(tmp_path / "secret.txt")
    _journal(staging, {"moves": [], "removals": [name, absolute]})
    with pytest.warns(RecoveryWarning, match="refused"):
        assert recover_staging(out, SET) == [staging.name]
    _untouched(files)
    assert not staging.exists()


def test_moves_only_take_regular_files_staged_inside_the_folder(tmp_path: Path) -> None:
    """A staged symlink (to a file outside) is not moved in; a plain staged file is; a target that
    is a symlink is replaced as a link, its target untouched."""
    out, staging, files = _world(tmp_path)
    (staging / "frf.json").symlink_to(tmp_path / "secret.txt")
    (staging / "frf.csv").write_text("new csv")
    (out / "frf.png").unlink()
    (out / "frf.png").symlink_to(tmp_path / "case" / "victim.txt")
    (staging / "frf.png").write_text("new png")
    _journal(staging, {"moves": ["frf.csv", "frf.json", "frf.png", "../victim.txt"], "removals": []})
    with pytest.warns(RecoveryWarning) as record:
        recover_staging(out, SET)
    text = " ".join(str(w.message) for w in record)
    assert "'frf.json'" in text and "'../victim.txt'" in text
    assert (out / "frf.csv").read_text() == "new csv"
    assert not (out / "frf.json").exists()
    assert not (out / "frf.png").is_symlink() and (out / "frf.png").read_text() == "new png"
    _untouched(files, except_=("frf.csv", "frf.png"))


def test_a_removal_that_is_a_symlink_removes_the_link_only(tmp_path: Path) -> None:
    out, staging, files = _world(tmp_path)
    (out / "frf.json").symlink_to(tmp_path / "secret.txt")
    _journal(staging, {"moves": [], "removals": ["frf.json"]})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        recover_staging(out, SET)
    assert not os.path.lexists(out / "frf.json")
    _untouched(files)


def test_a_folder_in_place_of_a_member_is_refused(tmp_path: Path) -> None:
    out, staging, files = _world(tmp_path)
    (out / "frf.json").mkdir()
    (out / "frf.json" / "keep").write_text("inside")
    _journal(staging, {"moves": [], "removals": ["frf.json"]})
    with pytest.warns(RecoveryWarning):
        recover_staging(out, SET)
    assert (out / "frf.json" / "keep").read_text() == "inside"
    _untouched(files)


@pytest.mark.parametrize("content", [
    "not json", "[1, 2]", '{"moves": "frf.csv", "removals": []}', '{"moves": [], "removals": {"a": 1}}',
    json.dumps({"moves": [], "removals": ["frf.csv"] * 20_001}), "[" * 100_000, "\udcff",
])
def test_a_damaged_or_huge_journal_does_nothing(tmp_path: Path, content: str) -> None:
    out, staging, files = _world(tmp_path)
    (staging / ".commit.json").write_bytes(content.encode("utf-8", "surrogateescape"))
    with pytest.warns(RecoveryWarning):
        recover_staging(out, SET)
    _untouched(files)


def test_a_journal_that_is_a_fifo_or_a_symlink_is_not_read(tmp_path: Path) -> None:
    out, staging, files = _world(tmp_path)
    os.mkfifo(staging / ".commit.json")  # a blocking open would hang here
    with pytest.warns(RecoveryWarning):
        recover_staging(out, SET)
    _untouched(files)
    out2, staging2, files2 = _world(tmp_path / "b")
    forged = tmp_path / "forged.json"
    forged.write_text(json.dumps({"moves": [], "removals": ["frf.csv"]}))
    (staging2 / ".commit.json").symlink_to(forged)
    with pytest.warns(RecoveryWarning):
        recover_staging(out2, SET)
    _untouched(files2)


def test_a_staging_folder_that_is_a_symlink_is_not_followed(tmp_path: Path) -> None:
    out, staging, files = _world(tmp_path)
    staging.rmdir()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "frf.csv").write_text("elsewhere")
    (elsewhere / ".commit.json").write_text(json.dumps({"moves": ["frf.csv"], "removals": ["frf.png"]}))
    staging.symlink_to(elsewhere)
    assert recover_staging(out, SET) == []
    _untouched(files)
    assert (elsewhere / "frf.csv").read_text() == "elsewhere"


def test_the_next_run_in_the_folder_touches_nothing_outside(tmp_path: Path) -> None:
    """The reported attack end to end: the next output set opened in ``out`` recovers the forged
    folder and deletes nothing beside it."""
    out, staging, files = _world(tmp_path)
    _journal(staging, {"moves": [], "removals": ["../victim.txt"]})
    with pytest.warns(RecoveryWarning), OutputSet(out, SET) as staged:
        staged.path("frf.csv").write_text("new csv")
        staged.commit()
    assert (out / "frf.csv").read_text() == "new csv"
    _untouched(files, except_=("frf.csv", "frf.png"))
    assert not (out / "frf.png").exists()  # a member of the set this run did not write: removed
