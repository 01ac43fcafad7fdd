"""Shared helpers of the command-line tests: a valid configuration, running the CLI in a
folder, and the check for refused input (exit 2, one line naming the key or option)."""

from __future__ import annotations

import os
from pathlib import Path

from click.testing import CliRunner, Result

from rattle.cli.main import cli
from _cases import clutch_toml  # tests/_cases.py (tests/ is on sys.path through its conftest)

VALID = clutch_toml((0.1, 3.0), 32)

PNG = b"\x89PNG\r\n\x1a\n"


def runner() -> CliRunner:
    try:  # click < 8.2 mixes stderr into stdout unless told not to
        return CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        return CliRunner()


def invoke(args: list[str], cwd: Path) -> Result:
    """Run ``rattle ARGS`` with ``cwd`` as the working folder."""
    old = Path.cwd()
    os.chdir(cwd)
    try:
        return runner().invoke(cli, args, catch_exceptions=False)
    finally:
        os.chdir(old)


def write_config(tmp_path: Path, text: str = VALID) -> Path:
    path = tmp_path / "case.toml"
    path.write_text(text, encoding="utf-8")
    return path


def assert_bad_input(result: Result, *fragments: str) -> None:
    """Exit 2 with one ``rattle: error:`` line on stderr containing every fragment, no stdout."""
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr  # one clear line
    assert lines[0].startswith("rattle: error: ")
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    assert result.stdout == ""
