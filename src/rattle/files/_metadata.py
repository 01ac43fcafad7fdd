"""Run metadata (``frf.json``): configuration, versions, settings, timings, environment.

Everything is converted to plain JSON: numpy scalars and arrays become numbers and lists,
paths and dates strings, enums their value, dataclasses and objects with ``to_dict()`` dicts.
Non-finite floats (nan, inf) become ``null``, so the file stays strict JSON that any reader
accepts.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import enum
import importlib.metadata
import json
import math
import os
import platform
import sys
from collections.abc import Mapping
from pathlib import PurePath
from typing import Any

import numpy as np

from ._atomic import atomic_write_text

__all__ = ["rattle_version", "environment", "to_jsonable", "metadata_document", "write_metadata"]


def rattle_version() -> str:
    """The installed rattle version (``rattle.__version__``)."""
    from .._release import version

    return version()


def _package_version(name: str) -> str | None:
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


def environment() -> dict[str, Any]:
    """Python, numpy and scipy versions and the platform string of this process."""
    return {
        "python": sys.version.split()[0],
        "implementation": platform.python_implementation(),
        "numpy": np.__version__,
        "scipy": _package_version("scipy"),
        "matplotlib": _package_version("matplotlib"),
        "platform": platform.platform(),
    }


def to_jsonable(obj: Any) -> Any:
    """Convert ``obj`` recursively into values that :func:`json.dumps` accepts in strict mode.

    Parameters
    ----------
    obj : object
        Mappings, sequences, numpy scalars/arrays, numbers, strings, paths, enums, dates,
        dataclasses or objects with a ``to_dict()`` method. Anything else becomes its ``repr``,
        so that provenance never costs a finished computation.

    Returns
    -------
    object
        Built from dict, list, str, int, float (finite), bool and None only.
    """
    if obj is None or isinstance(obj, (bool, str, int)):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return to_jsonable(obj.item())
    if isinstance(obj, complex):
        return [to_jsonable(obj.real), to_jsonable(obj.imag)]
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, (set, frozenset)):
        return [to_jsonable(v) for v in sorted(obj, key=repr)]
    if isinstance(obj, PurePath):
        return os.fspath(obj)
    if isinstance(obj, enum.Enum):
        return to_jsonable(obj.value)
    if isinstance(obj, (_dt.datetime, _dt.date, _dt.time)):
        return obj.isoformat()
    if isinstance(obj, _dt.timedelta):
        return obj.total_seconds()
    to_dict = getattr(obj, "to_dict", None)
    if callable(to_dict):
        return to_jsonable(to_dict())
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {
            f.name: to_jsonable(getattr(obj, f.name))
            for f in dataclasses.fields(obj)
            if not f.name.startswith("_")
        }
    return repr(obj)


def metadata_document(**sections: Any) -> dict[str, Any]:
    """The metadata dict: ``version``, ``created`` (UTC, ISO 8601), the given sections, ``environment``.

    Parameters
    ----------
    **sections
        Named sections, e.g. ``config=``, ``settings=``, ``timings=``, ``status=``. A section
        named ``version``, ``created`` or ``environment`` replaces the default one.

    Returns
    -------
    dict
        JSON-ready (see :func:`to_jsonable`).
    """
    doc: dict[str, Any] = {
        "version": rattle_version(),
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }
    doc.update(sections)
    doc.setdefault("environment", environment())
    return to_jsonable(doc)


def write_metadata(path: str | os.PathLike[str], **sections: Any) -> dict[str, Any]:
    """Write :func:`metadata_document` of ``sections`` to ``path`` as indented JSON, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Target file (e.g. ``OUT/frf.json``); its directory must exist.
    **sections
        As in :func:`metadata_document`.

    Returns
    -------
    dict
        The document written.
    """
    doc = metadata_document(**sections)
    atomic_write_text(path, json.dumps(doc, indent=2, allow_nan=False) + "\n")
    return doc
