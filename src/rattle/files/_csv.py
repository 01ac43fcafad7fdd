"""CSV files in SPEC column order: a plain writer and a typed reader (no pandas needed).

Values are written so that reading them back gives the same numbers: floats with Python's
shortest round-trip ``repr`` (``0.1``, ``1e-05``, ``nan``, ``inf``), integers as integers,
booleans as ``true``/``false``, strings as they are (quoted only when they hold a comma, a
quote or a line break), and missing values (``None``) as empty fields.
"""

from __future__ import annotations

import csv
import enum
import io
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ._atomic import atomic_write_text

__all__ = ["format_csv", "write_csv", "read_csv"]

def _format_value(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):  # before int: bool is an int subclass
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, enum.Enum):
        return _format_value(value.value)
    if isinstance(value, str):
        return value
    raise TypeError(
        f"cannot write {value!r} ({type(value).__name__}) to CSV; "
        "columns must hold numbers, booleans, strings or None"
    )


def format_csv(columns: Mapping[str, Any], order: Sequence[str]) -> str:
    """Format ``columns`` as CSV text with the header in exactly ``order``.

    Parameters
    ----------
    columns : mapping of str to array-like
        One 1-D array-like per column, all of the same length.
    order : sequence of str
        Column names in output order; must name every key of ``columns`` exactly once.

    Returns
    -------
    str
        Header line and one line per row, each ending with ``"\\n"``.
    """
    order = list(order)
    if len(set(order)) != len(order):
        dupes = sorted({c for c in order if order.count(c) > 1})
        raise ValueError(f"`order` must name each column once, got duplicates {dupes!r}")
    missing = [c for c in order if c not in columns]
    extra = [c for c in columns if c not in order]
    if missing or extra:
        raise ValueError(
            f"`columns` must hold exactly the columns in `order` {order!r}; "
            f"missing {missing!r}, not in `order` {extra!r}"
        )
    data: dict[str, list[Any]] = {}
    for name in order:
        values = columns[name]
        if isinstance(values, np.ndarray):
            if values.ndim != 1:
                raise ValueError(f"column `{name}` must be one-dimensional, got shape {values.shape}")
            data[name] = values.tolist()  # numpy scalars -> Python bool/int/float/str
        elif isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
            raise TypeError(f"column `{name}` must be a 1-D array or list, got {values!r}")
        else:
            data[name] = list(values)
    lengths = {name: len(values) for name, values in data.items()}
    if len(set(lengths.values())) > 1:
        raise ValueError(f"all columns must have the same length, got lengths {lengths!r}")

    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(order)
    for row in zip(*(data[name] for name in order)):
        writer.writerow([_format_value(v) for v in row])
    return buf.getvalue()


def write_csv(path: str | os.PathLike[str], columns: Mapping[str, Any], order: Sequence[str]) -> None:
    """Write ``columns`` to ``path`` atomically, header in exactly ``order`` (see :func:`format_csv`).

    Parameters
    ----------
    path : str or os.PathLike
        Target file; its directory must exist.
    columns : mapping of str to array-like
        One 1-D array-like per column, all of the same length.
    order : sequence of str
        Column names in output order, e.g. :data:`rattle.results.FRF_COLUMNS`.
    """
    atomic_write_text(path, format_csv(columns, order))


def _parse_column(values: list[str]) -> np.ndarray:
    if not values:
        return np.array([], dtype=float)
    if all(v in ("true", "false") for v in values):
        return np.array([v == "true" for v in values], dtype=bool)
    try:
        return np.array([int(v) for v in values], dtype=np.int64)
    except ValueError:
        pass
    try:
        return np.array([float(v) for v in values], dtype=np.float64)
    except ValueError:
        pass
    return np.array(values, dtype=str)


def read_csv(path: str | os.PathLike[str]) -> dict[str, np.ndarray]:
    """Read a CSV file written by :func:`write_csv` into typed columns.

    Each column becomes a ``bool`` array if every value is ``true``/``false``, else ``int64`` if
    every value is an integer, else ``float64`` if every value is a number, else a ``str`` array
    (empty fields stay ``""``).

    Parameters
    ----------
    path : str or os.PathLike
        CSV file with a header line.

    Returns
    -------
    dict of str to numpy.ndarray
        Columns in file order, each of shape (n_rows,).
    """
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        raise ValueError(f"{os.fspath(path)!r} is empty; a CSV file needs at least a header line")
    header, body = rows[0], rows[1:]
    for lineno, row in enumerate(body, start=2):
        if len(row) != len(header):
            raise ValueError(
                f"{os.fspath(path)!r} line {lineno} has {len(row)} fields, the header has {len(header)}"
            )
    return {name: _parse_column([row[j] for row in body]) for j, name in enumerate(header)}

