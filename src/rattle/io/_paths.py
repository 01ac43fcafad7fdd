"""``[[paths]]``: sound paths read from CSV tables, strictly (SPEC §6).

Each ``[[paths]]`` table has exactly two keys::

    [[paths]]
    source = "gear"          # an element name (its δ'') or "inertia:N" (its θ'', chains only)
    file = "gear_path.csv"   # relative to the configuration file's folder

The CSV file has a header line naming the three columns ``frequency_hz``, ``magnitude``
(Pa per rad/s²) and ``phase_deg`` (degrees), in any order, and one row per frequency; lines
starting with ``#`` and blank lines are skipped, spaces around fields are ignored. Refused, each
with a :class:`~rattle.errors.ConfigError` naming the key (``paths[0].file``), the line and the
rule: a missing or unreadable file, a missing, unknown or repeated column, a row with the wrong
number of fields, a value that is not a finite number, a magnitude below 0 or above 1e50 Pa per
rad/s², a phase beyond ±10⁶ degrees (:meth:`rattle.model.SoundPath.value_rule`), frequencies that are
not > 0 and strictly increasing, a table without rows; a source that names no element of the
model or an inertia out of range.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..files import csv_rows, read_bounded

__all__ = ["PATH_COLUMNS", "PATHS_KEYS", "MAX_PATH_BYTES", "read_path_csv", "paths_from_config", "with_paths"]

#: Columns of a path table, in the order of the SPEC.
PATH_COLUMNS = ("frequency_hz", "magnitude", "phase_deg")
#: Keys of a ``[[paths]]`` table.
PATHS_KEYS = ("source", "file")
#: Largest path table read (bytes): a measured FRF of a few thousand lines is ~100 kB.
MAX_PATH_BYTES = 16 << 20


def _fail(prefix: str, message: str) -> ConfigError:
    return ConfigError(f"{prefix}{message}")


def read_path_csv(file: str | os.PathLike[str], source: str, *, key: str = "file", prefix: str = "") -> Any:
    """Read one path table into a :class:`rattle.model.SoundPath`.

    Parameters
    ----------
    file : str or os.PathLike
        The CSV file (module docstring).
    source : str
        An element name or ``"inertia:N"`` (checked against a model by :func:`paths_from_config`
        or :func:`rattle.results.sound_pressure`).
    key : str, default "file"
        The name of the file in messages (``paths[0].file`` in a configuration).
    prefix : str, default ""
        Prepended to messages (the configuration file's name).

    Raises
    ------
    ConfigError
        Whatever breaks a rule of the module docstring; the message names ``key``, the line and
        the fix.
    """
    from ..model import SoundPath

    name = os.fspath(file)
    where = f"`{key}` ({name!r})"
    try:
        raw = read_bounded(file, MAX_PATH_BYTES, what="path table")
    except FileNotFoundError:
        raise _fail(prefix, f"{where} does not exist; give the path of the CSV table (relative paths start at the "
                            "configuration file's folder)") from None
    except IsADirectoryError:
        raise _fail(prefix, f"{where} is a directory; give the path of a CSV table") from None
    except ConfigError as exc:
        raise _fail(prefix, f"{where}: {exc}") from None
    except OSError as exc:
        raise _fail(prefix, f"{where} cannot be read: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise _fail(prefix, f"{where} is not UTF-8 text ({exc.reason} at byte {exc.start}); save it as UTF-8 CSV") from None
    try:
        rows = csv_rows(text)  # a field over 128 KiB or a NUL byte: refused naming the line
    except ConfigError as exc:
        raise _fail(prefix, f"{where} {exc}") from None
    rows = [(n, row) for n, row in rows if any(row) and not row[0].startswith("#")]
    if not rows:
        raise _fail(prefix, f"{where} is empty; it needs the header line {','.join(PATH_COLUMNS)} and one row per "
                            "frequency")
    line, header = rows[0]
    if len(header) == 1 and any(sep in header[0] for sep in ";\t"):
        raise _fail(prefix, f"{where} line {line}: the header {header[0]!r} is not comma-separated; separate the "
                            f"columns {', '.join(PATH_COLUMNS)} with commas (and use a point as the decimal separator)")
    for col in header:
        if col not in PATH_COLUMNS:
            raise _fail(prefix, f"{where} line {line}: column {col!r} is not known; the header must name exactly "
                                f"the columns {', '.join(PATH_COLUMNS)} (frequency in Hz, magnitude in Pa per "
                                "rad/s², phase in degrees)")
        if header.count(col) > 1:
            raise _fail(prefix, f"{where} line {line}: column {col!r} appears {header.count(col)} times; name each "
                                "column once")
    missing = [c for c in PATH_COLUMNS if c not in header]
    if missing:
        raise _fail(prefix, f"{where} line {line}: the header {','.join(header)!r} lacks the column(s) "
                            f"{', '.join(missing)}; the header must be {','.join(PATH_COLUMNS)}")
    if len(rows) == 1:
        raise _fail(prefix, f"{where} has a header but no rows; add one row per frequency")
    cols: dict[str, list[float]] = {c: [] for c in PATH_COLUMNS}
    lines = []
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise _fail(prefix, f"{where} line {line} has {len(row)} fields, the header has {len(header)}; give "
                                f"{', '.join(header)} on every line")
        for col, text_value in zip(header, row):
            try:
                value = float(text_value)
            except ValueError:
                raise _fail(prefix, f"{where} line {line}: `{col}` must be a number, got {text_value!r}; write a "
                                    "decimal number (no units, a point as the decimal separator)") from None
            if not math.isfinite(value):
                raise _fail(prefix, f"{where} line {line}: `{col}` must be a finite number, got {text_value!r}; "
                                    "remove the row or give its value")
            cols[col].append(value)
        lines.append(line)
    f, mag = cols["frequency_hz"], cols["magnitude"]
    for i, (fi, mi) in enumerate(zip(f, mag)):
        if fi <= 0:
            raise _fail(prefix, f"{where} line {lines[i]}: `frequency_hz` must be > 0 Hz, got {fi!r}; remove the row "
                                "(the mean, 0 Hz, carries no sound)")
        if i and fi <= f[i - 1]:
            raise _fail(prefix, f"{where} line {lines[i]}: `frequency_hz` must be strictly increasing, got {fi!r} after "
                                f"{f[i - 1]!r} (line {lines[i - 1]}); sort the rows and remove repeated frequencies")
        for column, value in (("magnitude", mi), ("phase_deg", cols["phase_deg"][i])):
            rule = SoundPath.value_rule(column, value)
            if rule is not None:
                raise _fail(prefix, f"{where} line {lines[i]}: {rule}")
    try:
        return SoundPath(source=source, frequency_hz=f, magnitude=mag, phase_deg=cols["phase_deg"],
                         name=Path(name).name)
    except (TypeError, ValueError) as exc:
        raise _fail(prefix, f"{where}: {exc}") from None


def paths_from_config(value: Any, model: Any, base_dir: str | os.PathLike[str], prefix: str = "") -> tuple[Any, ...]:
    """The ``[[paths]]`` array of tables as SoundPath objects, files relative to ``base_dir``,
    sources checked against ``model``."""
    from ..model import check_source

    if isinstance(value, Mapping) or not isinstance(value, list) or not all(isinstance(t, Mapping) for t in value):
        raise _fail(prefix, f"`paths` must be an array of tables, written [[paths]] with source = \"…\" and file = "
                            f"\"….csv\", got {type(value).__name__}")
    if not value:
        raise _fail(prefix, "`paths` must hold at least one [[paths]] table, got none")
    out = []
    for k, table in enumerate(value):
        where = f"paths[{k}]"
        for key in table:
            if key not in PATHS_KEYS:
                raise _fail(prefix, f"`{where}.{key}` is not a known key: [[paths]] allows only source and file; "
                                    "remove it or correct its spelling")
        for key in PATHS_KEYS:
            if key not in table:
                raise _fail(prefix, f"`{where}.{key}` is missing: every [[paths]] needs source (an element name or "
                                    "\"inertia:N\") and file (a CSV table); add e.g. "
                                    + ('source = "gear"' if key == "source" else 'file = "gear_path.csv"'))
            if not isinstance(table[key], str) or not table[key].strip():
                raise _fail(prefix, f"`{where}.{key}` must be a non-empty string, got {table[key]!r}; write e.g. "
                                    + ('source = "gear"' if key == "source" else 'file = "gear_path.csv"'))
        try:
            check_source(table["source"], model, f"{where}.source")
        except (TypeError, ValueError) as exc:
            raise _fail(prefix, f"{exc}") from None
        file = Path(base_dir) / table["file"]
        out.append(read_path_csv(file, table["source"], key=f"{where}.file", prefix=prefix))
    return tuple(out)


def with_paths(config: Any, value: Any, source_name: str) -> Any:
    """``config`` (a RunConfig read without its ``paths``) with the ``[[paths]]`` array read: files
    relative to the folder of ``source_name`` when it names a file, else to the working folder."""
    base = Path(source_name).parent if os.path.isfile(source_name) else Path.cwd()
    paths = paths_from_config(value, config.model, base, prefix=f"{source_name}: ")
    return dataclasses.replace(config, paths=paths, source={**config.source, "paths": [dict(t) for t in value]})
