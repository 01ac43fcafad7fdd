"""Reading an input file with bounds: a regular file of at most a stated size, read in one go.

``rattle frf /dev/zero`` must not read without end, and ``rattle frf <fifo>`` must not wait for a
writer: the file's type and size are checked from ``stat`` before it is opened, and the read is
capped again (the file may grow between the check and the read).
"""

from __future__ import annotations

import os
import stat

from ..errors import ConfigError

__all__ = ["MAX_CONFIG_BYTES", "read_bounded"]

#: Largest configuration file read (bytes). A case file is a few hundred bytes; 1 MiB leaves
#: room for long comments and generated files while keeping a mistaken path harmless.
MAX_CONFIG_BYTES = 1 << 20

_KINDS = {
    stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device", stat.S_IFIFO: "a named pipe (FIFO)",
    stat.S_IFSOCK: "a socket",
}


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
    if not stat.S_ISREG(st.st_mode):
        kind = _KINDS.get(stat.S_IFMT(st.st_mode), "not a regular file")
        raise ConfigError(f"{what} {name!r} is {kind}, not a regular file; give the path of a .toml file")
    if st.st_size > limit:
        raise ConfigError(
            f"{what} {name!r} has {st.st_size} bytes, more than the limit of {limit} bytes ({limit >> 10} KiB); "
            "give the path of a .toml case file"
        )
    with open(path, "rb") as fh:
        data = fh.read(limit + 1)
    if len(data) > limit:
        raise ConfigError(
            f"{what} {name!r} holds more than the limit of {limit} bytes ({limit >> 10} KiB); "
            "give the path of a .toml case file"
        )
    return data
