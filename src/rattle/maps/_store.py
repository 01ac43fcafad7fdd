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

A part that cannot be read (truncated, not JSON, another key inside, a symbolic link, too large:
it should not happen, the writes are atomic) is treated as missing: the combination is computed
again and the file replaced (:meth:`MapStore.read` says what was wrong, for the one warning line
of the run). What cannot be replaced is refused before any work, with a
:class:`~rattle.errors.ConfigError` naming the path (:meth:`MapStore.check_folder`,
:meth:`MapStore.read`, :meth:`MapStore.check_writable`): a folder, a named pipe or another special
file in the place of a part (never opened: a FIFO would block), ``map.parts`` that is a file or a
broken symbolic link, a read-only ``map.parts`` when combinations remain to be computed. A part
that cannot be written (no space, no permission) raises :class:`rattle.files.WriteError`.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import logging
import os
import re
import stat
import tempfile
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from .._release import version as rattle_version
from ..errors import ConfigError
from ..files import WriteError, atomic_write_text, describe_os_error

logger = logging.getLogger("rattle")

__all__ = ["MapStore", "PARTS_FOLDER", "STORE_FORMAT", "canonical_json"]

#: The folder of the parts inside the map's output folder.
PARTS_FOLDER = "map.parts"
#: Version of the part files' layout (part of every key: a new layout never reads an old part).
STORE_FORMAT = 1

#: Largest part read (bytes): a combination on 10 000 grid frequencies is ~2 MB.
MAX_PART_BYTES = 64 << 20

_KEY = re.compile(r"^[0-9a-f]{64}$")

_SPECIAL = {stat.S_IFDIR: "a folder", stat.S_IFIFO: "a named pipe (FIFO)", stat.S_IFSOCK: "a socket",
            stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device"}


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
        try:
            self.parts.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise WriteError(f"cannot create the map's parts folder {str(self.parts)!r}: {describe_os_error(exc)}",
                             code=exc.errno, filename=str(self.parts)) from None
        atomic_write_text(target, text)
        return target

    def check_folder(self) -> None:
        """Refuse (ConfigError) a ``map.parts`` that is not a folder: a file, a special file, a
        broken symbolic link (a symbolic link to a folder is followed)."""
        try:
            st = os.stat(self.parts)
        except FileNotFoundError:
            if os.path.islink(self.parts):
                raise ConfigError(
                    f"the map's parts folder {str(self.parts)!r} is a broken symbolic link (to "
                    f"{os.readlink(self.parts)!r}); remove it, or point it at a folder"
                ) from None
            return
        except OSError as exc:
            raise ConfigError(f"the map's parts folder {str(self.parts)!r} cannot be examined: "
                              f"{describe_os_error(exc)}; give another -o folder") from None
        if not stat.S_ISDIR(st.st_mode):
            kind = _SPECIAL.get(stat.S_IFMT(st.st_mode), "a file")
            raise ConfigError(
                f"the map's parts folder {str(self.parts)!r} is {kind}, not a folder: a map keeps its finished "
                "combinations there; move it away, or give another -o folder"
            )

    def check_writable(self, remaining: int) -> None:
        """Refuse (ConfigError) a parts folder in which the ``remaining`` combinations could not be
        stored (read-only, no permission), by creating and removing a temporary file there — before
        any work. Creates the folder when it does not exist."""
        try:
            self.parts.mkdir(parents=True, exist_ok=True)
            fd, name = tempfile.mkstemp(dir=self.parts, prefix=".probe.", suffix=".tmp")
            os.close(fd)
            os.unlink(name)
        except OSError as exc:
            code = exc.errno
            if code in (errno.EROFS, errno.EACCES, errno.EPERM):
                raise ConfigError(
                    f"the map's parts folder {str(self.parts)!r} is not writable ({describe_os_error(exc)}) and "
                    f"{remaining} combination(s) remain to be computed there; make it writable, or give another "
                    "-o folder"
                ) from None
            raise WriteError(f"cannot write into the map's parts folder {str(self.parts)!r}: {describe_os_error(exc)}",
                             code=code, filename=str(self.parts)) from None

    def read(self, key: str) -> tuple[dict[str, Any] | None, str | None]:
        """The saved result of ``key`` and what is wrong with its part: ``(result, None)``;
        ``(None, None)`` when there is none; ``(None, reason)`` when the part is damaged or foreign
        (to be computed again and replaced). Never blocks: the part is examined with ``lstat`` and
        opened without following a symbolic link, without waiting for a writer.

        Raises
        ------
        ConfigError
            A folder, a named pipe or another special file in the part's place (it cannot be
            replaced by the part computed again).
        """
        target = self.path(key)
        try:
            st = os.lstat(target)
        except FileNotFoundError:
            return None, None
        except OSError as exc:
            return None, f"cannot be examined ({describe_os_error(exc)})"
        if stat.S_ISLNK(st.st_mode):
            return None, "is a symbolic link, not a part rattle wrote"
        if not stat.S_ISREG(st.st_mode):
            kind = _SPECIAL.get(stat.S_IFMT(st.st_mode), "not a file")
            raise ConfigError(
                f"map part {str(target)!r} is {kind}, not a file: it cannot be read or replaced; remove it (a map "
                "part is a JSON file rattle writes), then run again"
            )
        if st.st_size > MAX_PART_BYTES:
            return None, f"has {st.st_size} bytes, more than a part can hold ({MAX_PART_BYTES} bytes)"
        flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
        try:
            fd = os.open(target, flags)
            try:
                if not stat.S_ISREG(os.fstat(fd).st_mode):  # replaced since the lstat
                    return None, "is not a file"
                with os.fdopen(os.dup(fd), "rb") as fh:
                    raw = fh.read(MAX_PART_BYTES + 1)
            finally:
                os.close(fd)
        except FileNotFoundError:
            return None, None
        except OSError as exc:
            return None, f"cannot be read ({describe_os_error(exc)})"
        if len(raw) > MAX_PART_BYTES:
            return None, f"holds more than {MAX_PART_BYTES} bytes"
        try:
            doc = json.loads(raw.decode("utf-8"))
        except UnicodeDecodeError:
            return None, "is not UTF-8 text"
        except (ValueError, RecursionError):
            return None, "is not complete JSON (truncated or overwritten)"
        if not isinstance(doc, dict):
            return None, f"holds a JSON {type(doc).__name__}, not a part"
        if doc.get("store_format") != STORE_FORMAT:
            return None, f"has store format {doc.get('store_format')!r}, not {STORE_FORMAT}"
        if doc.get("key") != key:
            return None, "belongs to another combination (its key differs from its name)"
        if not isinstance(doc.get("result"), dict):
            return None, "has no result table"
        return doc["result"], None

    def load(self, key: str) -> dict[str, Any] | None:
        """The saved result of ``key``, or None when there is none or the part cannot be read
        (a bad part is logged and treated as missing: it will be computed again). See :meth:`read`."""
        result, damage = self.read(key)
        if damage is not None:
            logger.warning("map part %s %s; computing it again", self.path(key), damage)
        return result

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

