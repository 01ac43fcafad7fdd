"""A measured run-up read from CSV, strictly (``rattle compare CONFIG --measured FILE.csv``).

The file has a header line and one row per measured point; lines starting with ``#`` and blank
lines are skipped, spaces around fields are ignored, commas separate the fields and a point is
the decimal separator. Its columns, in any order:

- exactly one speed column: ``speed_rpm`` (crankshaft speed in rpm; needs a model with an engine,
  ``[engine]`` or ``model.speed_order`` q_0: Ω = q_0 · 2π/60 · rpm) or ``omega`` (forcing
  frequency in rad/s);
- one or both quantity columns: ``acc_p2p`` (peak-to-peak of δ'' of the first clearance element,
  in the run's units: rad/s² for an SI configuration) and ``spl_db`` (sound pressure level at the
  receiver, dB re 20 µPa; needs ``[[paths]]`` in the configuration).

Any other column is refused (a misspelt quantity must not be dropped in silence): keep only
these columns in the file given to rattle.

Refused, each with a :class:`~rattle.errors.ConfigError` naming the option (``--measured``),
the file, the line and column and the rule: a missing or unreadable file, a header that is not
comma-separated, an unknown or repeated column, no speed column or both, no quantity column,
``speed_rpm`` without an engine, ``spl_db`` without ``[[paths]]``, a row with the wrong number
of fields, a cell that is not a finite number, a speed ≤ 0, ``acc_p2p`` ≤ 0 (a peak-to-peak
value; the relative difference divides by it), speeds not strictly monotonic (increasing: a
run-up, or decreasing: a run-down), a speed outside the analysis range (refused rather than
skipped, so that every row of ``measured.csv`` is compared: widen the range with
``--rpm-min``/``--rpm-max`` or ``--omega-min``/``--omega-max``, or remove the rows), no rows, more
than :data:`MAX_MEASURED_ROWS` rows.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..files import csv_rows, read_bounded

__all__ = ["MEASURED_SPEED_COLUMNS", "MEASURED_VALUE_COLUMNS", "MAX_MEASURED_BYTES", "MAX_MEASURED_ROWS",
           "MeasuredTable", "parse_measured_csv", "read_measured_csv"]

#: Speed columns: exactly one of them.
MEASURED_SPEED_COLUMNS = ("speed_rpm", "omega")
#: Quantity columns: one or both (``rattle.results.MEASURED_QUANTITIES``).
MEASURED_VALUE_COLUMNS = ("acc_p2p", "spl_db")
#: Largest measured file read (bytes).
MAX_MEASURED_BYTES = 16 << 20
#: Most measured points: a run-up sampled every rpm over 10 000 rpm is 10⁴ points.
MAX_MEASURED_ROWS = 100_000
#: Relative slack on the analysis range (round-off of rpm → Ω).
_RANGE_SLACK = 1e-9

_UNITS = {"speed_rpm": "rpm", "omega": "rad/s"}


@dataclass(frozen=True)
class MeasuredTable:
    """A measured CSV file read and checked on its own (:func:`parse_measured_csv`): the rules
    that need no configuration. Plain Python lists; neither numpy nor the results are loaded.

    Attributes
    ----------
    name : str
        The file as given (for messages).
    speed : str
        The speed column: ``speed_rpm`` or ``omega``.
    quantities : tuple of str
        The measured quantity columns, in :data:`MEASURED_VALUE_COLUMNS` order.
    columns : dict
        Column name → its values (floats), one per row.
    lines : tuple of int
        The file's line of every row.
    header_line : int
        The line of the header.
    key : str
        The option's (or argument's) name in messages.
    """

    name: str
    speed: str
    quantities: tuple[str, ...]
    columns: dict[str, list[float]]
    lines: tuple[int, ...]
    header_line: int
    key: str = "--measured"

    def fail(self, message: str) -> ConfigError:
        return ConfigError(f"`{self.key}` ({self.name!r}) {message}")


def parse_measured_csv(file: str | os.PathLike[str], *, key: str = "--measured") -> MeasuredTable:
    """Read a measured CSV file and check every rule that needs no configuration (the file, its
    header, every cell, speeds > 0 and strictly monotonic, ``acc_p2p`` > 0, the row count).

    Imports neither numpy nor the results: the command line calls it before the configuration
    is read, so that a refused file answers at once. :func:`read_measured_csv` takes its result.

    Raises
    ------
    ConfigError
        Naming ``key``, the file, the line and column, the rule and the fix.
    """
    if isinstance(file, MeasuredTable):
        return file
    if not isinstance(file, (str, os.PathLike)):
        raise TypeError(f"`file` must be the path of a measured CSV file (str or os.PathLike), got {file!r} "
                        f"({type(file).__name__})")
    name = os.fspath(file)
    where = f"`{key}` ({name!r})"

    def fail(message: str) -> ConfigError:
        return ConfigError(f"{where} {message}")

    try:
        raw = read_bounded(file, MAX_MEASURED_BYTES, what="measured data file")
    except FileNotFoundError:
        raise fail("does not exist; give the path of the measured CSV file (relative to the working folder)") from None
    except IsADirectoryError:
        raise fail("is a directory; give the path of a measured CSV file") from None
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    except OSError as exc:
        raise fail(f"cannot be read: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise fail(f"is not UTF-8 text ({exc.reason} at byte {exc.start}); save it as UTF-8 CSV") from None
    try:
        rows = csv_rows(text)  # a field over 128 KiB or a NUL byte: refused naming the line
    except ConfigError as exc:
        raise fail(str(exc)) from None
    rows = [(n, row) for n, row in rows if any(row) and not row[0].startswith("#")]
    known = (*MEASURED_SPEED_COLUMNS, *MEASURED_VALUE_COLUMNS)
    if not rows:
        raise fail("is empty; it needs a header line such as speed_rpm,acc_p2p and one row per measured point")
    line, header = rows[0]
    header_line = line
    if len(header) == 1 and any(sep in header[0] for sep in ";\t"):
        raise fail(f"line {line}: the header {header[0]!r} is not comma-separated; separate the columns with "
                   "commas (and use a point as the decimal separator)")
    for k, col in enumerate(header, start=1):
        if col not in known:
            raise fail(f"line {line}, column {k}: column {col!r} is not known; the columns are one speed column "
                       f"({' or '.join(MEASURED_SPEED_COLUMNS)}) and one or both of {', '.join(MEASURED_VALUE_COLUMNS)}; "
                       "remove other columns or correct the spelling")
        if header.count(col) > 1:
            raise fail(f"line {line}: column {col!r} appears {header.count(col)} times; name each column once")
    speeds = [c for c in MEASURED_SPEED_COLUMNS if c in header]
    if not speeds:
        raise fail(f"line {line}: the header {','.join(header)!r} has no speed column; add speed_rpm (crankshaft "
                   "rpm, with an [engine]) or omega (forcing frequency in rad/s)")
    if len(speeds) > 1:
        raise fail(f"line {line}: the header has both speed_rpm and omega; keep one speed column")
    speed = speeds[0]
    quantities = [c for c in MEASURED_VALUE_COLUMNS if c in header]
    if not quantities:
        raise fail(f"line {line}: the header {','.join(header)!r} has no measured quantity; add acc_p2p "
                   "(peak-to-peak acceleration of δ'') and/or spl_db (sound pressure level)")
    if len(rows) == 1:
        raise fail("has a header but no rows; add one row per measured point")
    if len(rows) - 1 > MAX_MEASURED_ROWS:
        raise fail(f"has {len(rows) - 1} rows, more than the {MAX_MEASURED_ROWS} allowed; thin the run out")
    cols: dict[str, list[float]] = {c: [] for c in header}
    lines: list[int] = []
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise fail(f"line {line} has {len(row)} fields, the header has {len(header)}; give "
                       f"{', '.join(header)} on every line")
        for col, cell in zip(header, row):
            try:
                value = float(cell)
            except ValueError:
                raise fail(f"line {line}, column `{col}`: must be a number, got {cell!r}; write a decimal number "
                           "(no units, a point as the decimal separator)") from None
            if not math.isfinite(value):
                raise fail(f"line {line}, column `{col}`: must be a finite number, got {cell!r}; remove the row or "
                           "give its value")
            cols[col].append(value)
        lines.append(line)
    s = cols[speed]
    unit = _UNITS[speed]
    for i, v in enumerate(s):
        if v <= 0:
            raise fail(f"line {lines[i]}, column `{speed}`: must be > 0 {unit}, got {v!r}; remove the row")
    if len(s) > 1:
        rising = s[1] > s[0]
        for i in range(1, len(s)):
            if (s[i] <= s[i - 1]) if rising else (s[i] >= s[i - 1]):
                raise fail(f"line {lines[i]}, column `{speed}`: speeds must be strictly "
                           f"{'increasing' if rising else 'decreasing'} (a {'run-up' if rising else 'run-down'}, "
                           f"each speed once), got {s[i]!r} after {s[i - 1]!r} (line {lines[i - 1]}); sort the rows "
                           "and remove repeated speeds")
    if "acc_p2p" in cols:
        for i, v in enumerate(cols["acc_p2p"]):
            if v <= 0:
                raise fail(f"line {lines[i]}, column `acc_p2p`: must be > 0 (a peak-to-peak acceleration; the "
                           f"relative difference divides by it), got {v!r}; remove the row")
    return MeasuredTable(name=name, speed=speed, quantities=tuple(quantities), columns=cols, lines=tuple(lines),
                         header_line=header_line, key=key)


def read_measured_csv(
    file: str | os.PathLike[str] | MeasuredTable,
    *,
    speed_order: float | None = None,
    omega_range: tuple[float, float] | None = None,
    has_paths: bool = False,
    key: str = "--measured",
) -> Any:
    """Read a measured run-up into a :class:`rattle.results.MeasuredRun`.

    Parameters
    ----------
    file : str, os.PathLike or MeasuredTable
        The CSV file (module docstring), or what :func:`parse_measured_csv` read from it.
    speed_order : float, optional
        The model's engine order q_0 of Ω (``Chain.speed_order``); None: the model has no
        engine, and ``speed_rpm`` is refused.
    omega_range : (float, float), optional
        The analysis range (rad/s); every measured speed must lie in it.
    has_paths : bool, default False
        Whether the configuration has ``[[paths]]`` (else ``spl_db`` is refused).
    key : str, default "--measured"
        The option's name in messages (for a path; a MeasuredTable keeps its own).

    Raises
    ------
    ConfigError
        Whatever breaks a rule of the module docstring; the message names ``key``, the file, the
        line and column, the rule and the fix.
    """
    table = parse_measured_csv(file, key=key)
    fail, speed, line = table.fail, table.speed, table.header_line
    if speed == "speed_rpm" and speed_order is None:
        raise fail(f"line {line}, column `speed_rpm`: the configuration has no engine ([engine] or "
                   "model.speed_order), so crankshaft rpm cannot be turned into Ω; give the column omega (rad/s) "
                   "instead, or add an [engine]")
    if "spl_db" in table.quantities and not has_paths:
        raise fail(f"line {line}, column `spl_db`: the configuration has no [[paths]], so no sound pressure is "
                   "computed to compare with; add [[paths]] (docs/sound.md) or remove the column")
    s, lines, unit = table.columns[speed], table.lines, _UNITS[speed]
    factor = 1.0 if speed == "omega" else float(speed_order) * 2.0 * math.pi / 60.0  # type: ignore[arg-type]
    omega = [v * factor for v in s]
    if omega_range is not None:
        lo, hi = float(omega_range[0]), float(omega_range[1])
        for i, w in enumerate(omega):
            if not lo * (1 - _RANGE_SLACK) <= w <= hi * (1 + _RANGE_SLACK):
                shown = f"{lo / factor:.6g} … {hi / factor:.6g} {unit}"
                option = "--rpm-min/--rpm-max" if speed == "speed_rpm" else "--omega-min/--omega-max"
                raise fail(f"line {lines[i]}, column `{speed}`: {s[i]:.6g} {unit} lies outside the analysis range "
                           f"{shown}; widen the range ({option} or the configuration) or remove the rows outside it")
    from ..results import MeasuredRun  # only now: every rule is checked (numpy and the numerics behind it)

    try:
        return MeasuredRun(omega=omega, values={q: table.columns[q] for q in table.quantities},
                           speed_rpm=s if speed == "speed_rpm" else None, source=Path(table.name).name,
                           lines=tuple(lines))
    except (TypeError, ValueError) as exc:
        raise fail(f"is refused: {exc}") from None
