"""The reader of a file's model tables, as :meth:`Model.from_toml` and :meth:`Chain.from_toml` reach it.

The reader of the model tables (:func:`rattle.model._tables.model_tables`) builds models, chains
and their laws, so it imports them; they cannot import it back. It registers itself here when it
is loaded (``rattle.model`` loads it, so it is always registered once the package is imported),
and the classes' ``from_toml`` call :func:`read_tables`:

    read_tables(path) = reader(read_toml(path), path),

``read_toml`` the bounded TOML read of :mod:`rattle.files` (its errors for a missing, unreadable
or malformed file) and the reader's result the model tables of the file.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from ..files import read_toml

#: reader(data, source_name) -> the model tables of ``data`` (``source_name`` names the file in errors).
TableReader = Callable[[Mapping[str, Any], str], Any]

_READER: list[TableReader] = []


def register_reader(reader: TableReader) -> None:
    """Make ``reader`` the reader of the model tables (a later registration replaces it)."""
    if not callable(reader):
        raise TypeError(f"`reader` must be callable as reader(data, source_name), got {reader!r}")
    _READER[:] = [reader]


def read_tables(path: str | Path) -> Any:
    """The model tables of the TOML file at ``path``, read with the registered reader; a
    ``path`` that is not a path (None, a number …) is refused naming it (TypeError)."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"`path` must be the path of a TOML configuration file (a str or os.PathLike), got {path!r} "
                        f"({type(path).__name__})")
    data = read_toml(path)
    if not _READER:
        raise RuntimeError("no reader of the model tables is registered: import rattle.model "
                           "(it loads rattle.model._tables, which registers its reader)")
    return _READER[0](data, os.fsdecode(path))


__all__ = ["TableReader", "read_tables", "register_reader"]
