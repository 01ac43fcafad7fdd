"""Reading an input file with bounds: a regular file of at most a stated size, read in one go.

``rattle frf /dev/zero`` must not read without end, and ``rattle frf <fifo>`` must not wait for a
writer: the file's type and size are checked from ``stat`` before it is opened, and the read is
capped again (the file may grow between the check and the read).
"""

from __future__ import annotations

import os
import stat
import sys
from typing import Any

from ..errors import ConfigError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["MAX_CONFIG_BYTES", "read_bounded", "check_input_file", "read_toml"]

#: Largest configuration file read (bytes). A case file is a few hundred bytes; 1 MiB leaves
#: room for long comments and generated files while keeping a mistaken path harmless.
MAX_CONFIG_BYTES = 1 << 20

_KINDS = {
    stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device", stat.S_IFIFO: "a named pipe (FIFO)",
    stat.S_IFSOCK: "a socket",
}


def check_input_file(path: str | os.PathLike[str], limit: int = MAX_CONFIG_BYTES,
                     what: str = "configuration file") -> os.stat_result:
    """Refuse ``path`` unless it is an existing regular file of at most ``limit`` bytes, from
    ``stat`` alone (no read, no numpy): the command line calls it before anything heavy.

    Raises
    ------
    ConfigError
        Missing, a directory, not a regular file, too large, or not accessible; the message says
        which and the fix.
    """
    name = os.fspath(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise ConfigError(
            f"{what} {name!r} does not exist; check the path (relative paths start at {os.getcwd()!r})"
        ) from None
    except OSError as exc:
        raise ConfigError(f"cannot read {what} {name!r}: {exc.strerror or exc}") from None
    except ValueError as exc:  # an embedded NUL byte
        raise ConfigError(f"{what} {name!r} is not a valid path ({exc}); give the path of a .toml file") from None
    if stat.S_ISDIR(st.st_mode):
        raise ConfigError(f"{what} {name!r} is a directory; give the path of a .toml file")
    _check_kind_and_size(name, st, limit, what)
    return st


def _check_kind_and_size(name: str, st: os.stat_result, limit: int, what: str) -> None:
    if not stat.S_ISREG(st.st_mode):
        kind = _KINDS.get(stat.S_IFMT(st.st_mode), "not a regular file")
        raise ConfigError(f"{what} {name!r} is {kind}, not a regular file; give the path of a .toml file")
    if st.st_size > limit:
        raise ConfigError(
            f"{what} {name!r} has {st.st_size} bytes, more than the limit of {limit} bytes ({limit >> 10} KiB); "
            "give the path of a .toml case file"
        )


def read_bounded(path: str | os.PathLike[str], limit: int = MAX_CONFIG_BYTES, what: str = "configuration file") -> bytes:
    """The bytes of the regular file ``path``, refusing anything else or anything over ``limit``.

    Raises
    ------
    FileNotFoundError, IsADirectoryError, OSError
        As ``open`` would (the caller words them).
    ConfigError
        If ``path`` is not a regular file (device, pipe, socket) or holds more than ``limit`` bytes.
    """
    name = os.fspath(path)
    st = os.stat(path)
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(21, "Is a directory", name)
    _check_kind_and_size(name, st, limit, what)
    # O_NONBLOCK: should the path have become a FIFO since the stat, opening it does not wait
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    with os.fdopen(fd, "rb") as fh:
        _check_kind_and_size(name, os.fstat(fd), limit, what)  # what was opened is what was checked
        data = fh.read(limit + 1)
    if len(data) > limit:
        raise ConfigError(
            f"{what} {name!r} holds more than the limit of {limit} bytes ({limit >> 10} KiB); "
            "give the path of a .toml case file"
        )
    return data


def read_toml(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The tables of the TOML configuration file ``path`` (as ``tomllib`` parses them), read with
    :func:`read_bounded`: a regular file of at most :data:`MAX_CONFIG_BYTES`, UTF-8 text.

    Raises
    ------
    ConfigError
        If the file cannot be read or is not TOML; the message names the file and says the fix.
    """
    name = os.fspath(path)
    try:
        # a regular file of at most MAX_CONFIG_BYTES, checked before reading (not /dev/zero, not a FIFO)
        return tomllib.loads(read_bounded(path).decode("utf-8"))
    except FileNotFoundError:
        raise ConfigError(
            f"configuration file {name!r} does not exist; check the path "
            f"(relative paths start at {os.getcwd()!r})"
        ) from None
    except IsADirectoryError:
        raise ConfigError(f"configuration file {name!r} is a directory; give the path of a .toml file") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"configuration file {name!r} is not UTF-8 text ({exc.reason} at byte {exc.start}); "
            "save it with UTF-8 encoding"
        ) from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{name} is not valid TOML: {exc}; correct the syntax there") from None
    except OSError as exc:
        raise ConfigError(f"cannot read configuration file {name!r}: {exc.strerror or exc}") from None
