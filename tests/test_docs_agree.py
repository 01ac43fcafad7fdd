"""docs/cli.md's table "Which command solves which law, and how" agrees with the commands.

The table is parsed from the page: every row (a kind of law and an ``[analysis] method``) is run
through every command on a small case of that kind (a narrow range, 8 harmonics, two sweep
points, a two-frequency map of one combination), and each cell is checked against what the
command did — ``refused``: exit status 2 with one ``rattle: error:`` line; otherwise exit status
0 and, where the cell names a method the command reports in its summary, that method and not the
other one. A row added to the table without a case here fails, and so does a cell whose
wording this test does not know.
"""

from __future__ import annotations

import itertools
import re
import sys
from pathlib import Path

import pytest

from cli._cli_helpers import invoke  # tests/cli/_cli_helpers.py

ROOT = Path(__file__).resolve().parents[1]
TABLE_HEADING = "## Which command solves which law, and how"
COMMANDS = ("frf", "sweep", "orbit", "compare", "map")

_SINGLE = """
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0
[model.elastic]
{law}
[excitation]
mean = 0.05
amplitudes = [0.03]
[analysis]
omega = [0.5, 0.55]
harmonics = 8
{analysis}
"""

_CHAIN = """
[model]
inertias = [2.0, 2.0]
[[model.links]]
between = [1, 2]
damping = 0.05
[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 1.0
{law}
[[excitation.torques]]
inertia = 1
mean = 0.05
amplitudes = [0.06]
[[excitation.torques]]
inertia = 2
mean = -0.05
[analysis]
omega = [0.5, 0.55]
harmonics = 8
{analysis}
"""

_CLUTCH = 'type = "clutch"\nalpha = 0.25\nb = 0.174533'
# The law of each row, by the start of its first cell. refine = 0 (and a chain's ladder kept at
# H = 8) keeps the regularised HB to its first pass: seconds, not minutes.
_CASES = {
    "continuous, one equation": [(_SINGLE, _CLUTCH, "")],
    "continuous, a chain": [(_CHAIN, _CLUTCH, "")],
    "continuous, either form": [(_SINGLE, _CLUTCH, ""), (_CHAIN, _CLUTCH, "")],
    "a torque jump": [(_SINGLE, 'type = "preload"\npreload = 0.03', "refine = 0")],
    "friction": [(_SINGLE, _CLUTCH + "\nfriction = 0.01", "refine = 0")],
    "a chain with friction or a jump": [(_CHAIN, _CLUTCH + "\nfriction = 0.002", "refine = 0\nlimit_harmonics = 8"),
                                        # a lock-up clutch, damped more: the map's search settles in 1 s, not 4
                                        (_CHAIN.replace("damping = 0.05", "damping = 0.2"),
                                         'type = "preload"\npreload = 0.03', "refine = 0\nlimit_harmonics = 8")],
}

# What a cell's method looks like in the command's summary (stdout), and what it must not say.
_REPORTS = {
    "HB": (r"\(H = \d+ harmonics", r"exact shooting continuation|regularised|ε = "),
    "exact shooting": (r"exact shooting continuation", r"regularised|ε = "),
    "regularised HB + exact check": (r"regularised|ε = ", r"exact shooting continuation"),
}
_KNOWN = ("HB", "exact integration", "HB + simulation", "HB + exact integration", "HB + attractor search",
          "exact shooting", "exact flow", "regularised HB + exact check", "regularised HB + exact check, exact flow",
          "regularised HB + exact check, every exact orbit",
          "exact shooting + search on the exact flow", "refused")


def _table() -> list[dict[str, str]]:
    text = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    assert TABLE_HEADING in text, f"docs/cli.md has no section {TABLE_HEADING!r}"
    body = text.split(TABLE_HEADING, 1)[1].split("\n## ", 1)[0]
    lines = [line for line in body.splitlines() if line.startswith("|")]
    cells = [[c.strip() for c in line.strip().strip("|").split("|")] for line in lines]
    header, rows = cells[0], [r for r in cells[2:]]
    assert header[:2] == ["law", "`method`"] and header[2:] == [f"`rattle {c}`" for c in COMMANDS], header
    return [dict(zip(["law", "method", *COMMANDS], row, strict=True)) for row in rows]


def _row_id(row: dict[str, str]) -> str:
    return f"{row['law'].split(' (')[0]} / {row['method']}"


def _cases(row: dict[str, str]) -> list[str]:
    """The case files of a row: each of its law's forms with each method the row names."""
    variants = next((v for start, v in _CASES.items() if row["law"].startswith(start)), None)
    assert variants, f"docs/cli.md's law table has a row {row['law']!r} this test has no case for"
    methods = re.findall(r'`"(\w+)"`', row["method"])
    assert bool(methods) == (row["method"] != "not given"), f"the method cell {row['method']!r}"
    lines = [f'method = "{m}"\n' for m in methods] or [""]
    return [template.format(law=law, analysis=line + analysis)
            for template, law, analysis in variants for line in lines]


_ROWS = _table()


def test_the_table_has_every_kind_of_law():
    kinds = {next(s for s in _CASES if row["law"].startswith(s)) for row in _ROWS}
    assert kinds == set(_CASES), f"rows missing for {set(_CASES) - kinds}"
    methods = {(row["law"], row["method"]) for row in _ROWS}
    assert len(methods) == len(_ROWS), "a law and method appear twice"


@pytest.mark.parametrize("row", _ROWS, ids=_row_id)
def test_every_command_does_what_the_table_says(row, tmp_path, monkeypatch):
    # Run as without matplotlib (the commands then write their sets without the figures, with a
    # warning): the figures are three quarters of the time here and are tested on their own.
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    args = {
        "frf": [],
        "sweep": ["--direction", "up", "--points", "2", "-q"],
        "orbit": ["--omega", "0.5"],
        "compare": ["--points", "2", "-q"],
        "map": ["--omega-points", "2", "--workers", "1", "-q"],  # + one combination: the case's damping
    }
    for (n, text), command in itertools.product(enumerate(_cases(row)), COMMANDS):
        config = tmp_path / f"case{n}.toml"
        config.write_text(text, encoding="utf-8")
        cell = row[command]
        assert cell in _KNOWN, f"docs/cli.md: {_row_id(row)}, `rattle {command}`: unknown cell {cell!r}"
        vary = ["--vary", "damping=" + re.findall(r"^damping = (\S+)", text, flags=re.M)[0]] if command == "map" else []
        result = invoke([command, str(config), *args[command], *vary, "-o", str(tmp_path / f"{command}{n}")], tmp_path)
        where = (f"docs/cli.md says `rattle {command}` on {_row_id(row)}: {cell!r}; got exit {result.exit_code} "
                 f"on {config.name}:\n{text}")
        if cell == "refused":
            assert result.exit_code == 2, f"{where}\n{result.stdout}{result.stderr}"
            assert result.stderr.startswith("rattle: error: ") and result.stderr.count("\n") == 1, result.stderr
            assert "`" in result.stderr, f"the refusal names no key: {result.stderr}"
            continue
        assert result.exit_code == 0, f"{where}\n{result.stderr}"
        if cell.endswith("every exact orbit"):  # the census of the orbits at Ω beside the one asked for
            assert "every orbit at Ω = 0.5 rad/s (exact" in result.stdout, f"{where}; summary:\n{result.stdout}"
        for method, (says, never) in _REPORTS.items():
            if cell.split(",")[0] == method:  # the map's summary names no method
                assert re.search(says, result.stdout) and not re.search(never, result.stdout), (
                    f"{where}; summary:\n{result.stdout}")
