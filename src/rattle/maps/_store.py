"""The resumable store of a map: one JSON file per finished combination.

``OUT/map.parts/<key>.json`` holds one combination's result (:meth:`CellResult.to_dict`), written
atomically (a temporary file renamed over the target) as soon as the combination is done. A run
killed outright therefore loses at most the combinations in flight, and a rerun of the same
command reads the finished ones back instead of computing them again.

The key is the SHA-256 of a canonical JSON of everything the combination's result depends on
(the configuration tables with the varied values applied, the varied values, the analysis
settings, the rattle version; see :meth:`MapStore.key`): another command, configuration or
rattle version never reuses a part. Floats are written by ``json`` as their ``repr``: they read
back bit for bit.

A part that cannot be read (truncated, not JSON, another key inside: it should not happen, the
writes are atomic) is treated as missing: the combination is computed again and the file
replaced. Nothing here raises on a bad part.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import re
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from .._release import version as rattle_version
from ..files import atomic_write_text

logger = logging.getLogger("rattle")

__all__ = ["MapStore", "PARTS_FOLDER", "STORE_FORMAT", "canonical_json"]

#: The folder of the parts inside the map's output folder.
PARTS_FOLDER = "map.parts"
#: Version of the part files' layout (part of every key: a new layout never reads an old part).
STORE_FORMAT = 1

_KEY = re.compile(r"^[0-9a-f]{64}$")


def _plain(value: Any, where: str = "fingerprint") -> Any:
    """``value`` as plain JSON data: mappings with str keys, lists, str, int, float, bool, None.

    numpy scalars and arrays, tuples and paths are converted; anything else is refused (a key must
    not depend on an object's ``repr``).
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"{where}: keys must be strings, got {k!r}")
            out[k] = _plain(v, f"{where}.{k}")
        return out
    if isinstance(value, (list, tuple)):
        return [_plain(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    tolist = getattr(value, "tolist", None)  # numpy scalars and arrays
    if callable(tolist):
        return _plain(tolist(), where)
    raise TypeError(f"{where}: {type(value).__name__} {value!r} has no canonical JSON form; "
                    "use numbers, strings, booleans, lists and dicts")


def canonical_json(data: Any) -> str:
    """One text for equal data: sorted keys, no spaces, ASCII, floats as ``repr`` (NaN, ±Infinity
    allowed), integral floats kept apart from ints (``1.0`` ≠ ``1``)."""
    return json.dumps(_plain(data), sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=True)


class MapStore:
    """The finished combinations of a map in ``folder/map.parts``.

    Parameters
    ----------
    folder : str or os.PathLike
        The map's output folder (created with the parts folder on the first :meth:`save`).

    Examples
    --------
    >>> store = MapStore(out)                                   # doctest: +SKIP
    >>> key = store.key({"config": tables, "values": {"alpha": 0.1}, "settings": settings})  # doctest: +SKIP
    >>> result = store.load(key) or compute(...)                # doctest: +SKIP
    >>> store.save(key, result)                                  # doctest: +SKIP
    """

    def __init__(self, folder: str | os.PathLike[str]) -> None:
        self.folder = Path(folder)
        self.parts = self.folder / PARTS_FOLDER

    def __repr__(self) -> str:
        return f"MapStore({str(self.folder)!r})"

    # -- keys -----------------------------------------------------------------------------------
    @staticmethod
    def key(task_fingerprint: Mapping[str, Any]) -> str:
        """SHA-256 (hex) of the canonical JSON of ``task_fingerprint`` with the rattle version and
        the store format added: everything one combination's result depends on (configuration
        tables, varied values, settings). Equal fingerprints give equal keys; any difference —
        a value, a setting, ``1`` for ``1.0`` — a different key."""
        if not isinstance(task_fingerprint, Mapping):
            raise TypeError(f"`task_fingerprint` must be a dict, got {type(task_fingerprint).__name__}")
        doc = {"task": task_fingerprint, "rattle": rattle_version(), "store_format": STORE_FORMAT}
        return hashlib.sha256(canonical_json(doc).encode("ascii")).hexdigest()

    def path(self, key: str) -> Path:
        """The part file of ``key``."""
        if not isinstance(key, str) or not _KEY.match(key):
            raise ValueError(f"`key` must be a key from MapStore.key (64 hex digits), got {key!r}")
        return self.parts / f"{key}.json"

    # -- parts ----------------------------------------------------------------------------------
    def save(self, key: str, result: Mapping[str, Any], fingerprint: Mapping[str, Any] | None = None) -> Path:
        """Write ``result`` (a JSON-ready dict, e.g. ``CellResult.to_dict()``) as the part of
        ``key``, atomically; ``fingerprint`` (optional) is stored beside it for inspection.
        Returns the part's path."""
        target = self.path(key)
        if not isinstance(result, Mapping):
            raise TypeError(f"`result` must be a dict, got {type(result).__name__}")
        doc: dict[str, Any] = {"store_format": STORE_FORMAT, "key": key, "result": result}
        if fingerprint is not None:
            doc["fingerprint"] = fingerprint
        text = json.dumps(doc, allow_nan=True, separators=(",", ":")) + "\n"
        self.parts.mkdir(parents=True, exist_ok=True)
        atomic_write_text(target, text)
        return target

    def load(self, key: str) -> dict[str, Any] | None:
        """The saved result of ``key``, or None when there is none or the part cannot be read
        (a bad part is logged and treated as missing: it will be computed again)."""
        target = self.path(key)
        try:
            text = target.read_text(encoding="utf-8")
        except FileNotFoundError:
            return None
        except (OSError, UnicodeDecodeError) as exc:
            logger.warning("map part %s cannot be read (%s); computing it again", target, exc)
            return None
        try:
            doc = json.loads(text)
            ok = (isinstance(doc, dict) and doc.get("key") == key and doc.get("store_format") == STORE_FORMAT
                  and isinstance(doc.get("result"), dict))
        except (ValueError, RecursionError):
            ok = False
        if not ok:
            logger.warning("map part %s is damaged or belongs to another key; computing it again", target)
            return None
        return doc["result"]

    def finished(self) -> set[str]:
        """The keys with a part file (not opened: :meth:`load` checks each)."""
        try:
            names = [p.name for p in self.parts.iterdir()]
        except (FileNotFoundError, NotADirectoryError):
            return set()
        return {n[:-5] for n in names if n.endswith(".json") and _KEY.match(n[:-5])}

    def discard(self, key: str) -> None:
        """Remove the part of ``key`` (if any)."""
        with contextlib.suppress(FileNotFoundError):
            self.path(key).unlink()

    def clear_orphans(self, min_age: float = 60.0) -> list[str]:
        """Remove the temporary files a killed write left in the parts folder (a run killed by
        SIGKILL cannot remove its own) and return their names. Only temporaries not modified for
        ``min_age`` seconds are touched: a part is written in milliseconds, so an older one has
        no writer left, and a run writing into the same folder at this moment keeps its own."""
        removed: list[str] = []
        try:
            entries = list(self.parts.iterdir())
        except (FileNotFoundError, NotADirectoryError):
            return removed
        now = time.time()
        for entry in entries:
            name = entry.name
            if not (name.startswith(".") and ".tmp" in name):
                continue
            with contextlib.suppress(OSError):
                if entry.is_file() and now - entry.stat().st_mtime >= min_age:
                    entry.unlink()
                    removed.append(name)
        return sorted(removed)

    def clear_stale(self, keep: Iterable[str]) -> list[str]:
        """Remove the parts whose key is not in ``keep`` (another configuration's, an older
        version's) and temporary files left by a killed write; return the names removed.
        Call it only when no other run writes into the same folder."""
        keep = set(keep)
        removed: list[str] = []
        try:
            entries = list(self.parts.iterdir())
        except (FileNotFoundError, NotADirectoryError):
            return removed
        for entry in entries:
            name = entry.name
            stale_part = name.endswith(".json") and _KEY.match(name[:-5]) and name[:-5] not in keep
            temporary = name.startswith(".") and ".tmp" in name
            if (stale_part or temporary) and entry.is_file():
                with contextlib.suppress(OSError):
                    entry.unlink()
                    removed.append(name)
        return sorted(removed)

