"""Atomic file writes: write a temporary file next to the target, then rename it over the target.

A reader (or a crashed run) therefore sees either the old file or the complete new one, never a
half-written file. The temporary file lives in the target's directory because a rename is only
atomic within one file system; it is removed when the write fails.
"""

from __future__ import annotations

import contextlib
import functools
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text"]


@functools.cache
def _default_file_mode() -> int:
    # mkstemp creates files with mode 0o600; outputs should get the usual 0o666 & ~umask.
    # os.umask can only be read by setting it, so read it once and restore it at once.
    umask = os.umask(0o022)
    os.umask(umask)
    return 0o666 & ~umask


def _fsync(path: Path) -> None:
    with open(path, "rb") as fh:
        os.fsync(fh.fileno())


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path in the target's directory; rename it over ``path`` on success.

    The temporary name keeps the target's suffix (``.frf.png.<random>.tmp.png``) so that writers
    that infer the format from the suffix (``Figure.savefig``) still work. If the ``with`` body
    raises, the temporary file is deleted and the target is left untouched.

    Parameters
    ----------
    path : str or os.PathLike
        Final location. Its directory must exist.

    Yields
    ------
    pathlib.Path
        Where to write the content (an existing, empty file).

    Examples
    --------
    >>> with atomic_path(out / "frf.png") as tmp:  # doctest: +SKIP
    ...     fig.savefig(tmp, format="png")
    """
    target = Path(path)
    fd, name = tempfile.mkstemp(
        dir=target.parent, prefix=f".{target.name}.", suffix=f".tmp{target.suffix}"
    )
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        if not tmp.is_file():
            raise FileNotFoundError(f"the temporary file {str(tmp)!r} for {str(target)!r} vanished")
        _fsync(tmp)
        # Keep the mode of a file being replaced; give new files the ordinary umask mode.
        mode = target.stat().st_mode & 0o7777 if target.is_file() else _default_file_mode()
        os.chmod(tmp, mode)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (all or nothing).

    Parameters
    ----------
    path : str or os.PathLike
        Target file; its directory must exist.
    data : bytes
        Complete file content.
    """
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise TypeError(f"`data` must be bytes, got {type(data).__name__}; encode text first or use atomic_write_text")
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)


def atomic_write_text(path: str | os.PathLike[str], text: str, *, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically, encoded with ``encoding`` and without newline translation.

    Parameters
    ----------
    path : str or os.PathLike
        Target file; its directory must exist.
    text : str
        Complete file content.
    encoding : str, default "utf-8"
        Text encoding.
    """
    if not isinstance(text, str):
        raise TypeError(f"`text` must be a str, got {type(text).__name__}; use atomic_write_bytes for bytes")
    atomic_write_bytes(path, text.encode(encoding))
