"""Reading an input file with bounds: a regular file of at most a stated size, read in one go.

``rattle frf /dev/zero`` must not read without end, and ``rattle frf <fifo>`` must not wait for a
writer: the file's type and size are checked from ``stat`` before it is opened, and the read is
capped again (the file may grow between the check and the read).
"""

from __future__ import annotations

import csv
import io
import os
import re
import stat
import sys
from typing import Any

from ..errors import ConfigError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["MAX_CONFIG_BYTES", "MAX_TOML_DEPTH", "MAX_KEY_PARTS", "MAX_CSV_FIELD", "read_bounded", "check_input_file",
           "read_toml", "check_toml_bounds", "csv_rows"]

#: Largest configuration file read (bytes). A case file is a few hundred bytes; 1 MiB leaves
#: room for long comments and generated files while keeping a mistaken path harmless.
MAX_CONFIG_BYTES = 1 << 20

#: Deepest nesting of arrays and inline tables in a configuration file. A case file nests two
#: levels (``omega = [0.1, 3.0]``, an inline table in an array); tomllib recurses once per level
#: and runs out of stack (RecursionError) near 1 000 of them.
MAX_TOML_DEPTH = 32
#: Most parts of one dotted key (``model.elements.clutch.alpha`` has 4). tomllib's time grows with
#: the square of a key's parts: 4 000 of them take seconds, more take minutes.
MAX_KEY_PARTS = 64
#: Longest field of a CSV input (characters): Python's csv module refuses longer fields (its
#: ``field_size_limit``, 128 KiB); the message then names the file, the line and this rule.
MAX_CSV_FIELD = csv.field_size_limit()

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
        _check_no_nul(name, what)
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


def _check_no_nul(name: str | bytes, what: str) -> None:
    """A path with a NUL byte names no file (the system calls end the name there): refused."""
    if ("\x00" in name) if isinstance(name, str) else (b"\x00" in name):
        raise ConfigError(f"{what} {name!r} is not a valid path: it holds a NUL byte, which no file name "
                          "can contain; give the path of the file")


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
    _check_no_nul(name, what)
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
        text = read_bounded(path).decode("utf-8")
        check_toml_bounds(text, name)  # before tomllib: its recursion and its dotted keys are unbounded
        return tomllib.loads(text)
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
    except RecursionError:  # pragma: no cover - check_toml_bounds refuses what could cause it
        raise ConfigError(f"configuration file {name!r} nests too deeply to be read; at most {MAX_TOML_DEPTH} "
                          "levels of arrays and inline tables") from None
    except OSError as exc:
        raise ConfigError(f"cannot read configuration file {name!r}: {exc.strerror or exc}") from None


# --------------------------------------------------------------------------------------------
# Bounds of a TOML text, checked before it is parsed
# --------------------------------------------------------------------------------------------
#: What the scan of a TOML text looks at: strings and comments (skipped whole, so that brackets
#: and dots inside them do not count), and the characters that open or close a level, end a key
#: or a value, or join a dotted key.
_TOML_TOKEN = re.compile(
    r'"""(?:[^"\\]|\\[\s\S]|"(?!""))*""""{0,2}'    # multi-line basic string
    r"|'''[\s\S]*?''''{0,2}"                       # multi-line literal string
    r'|"(?:[^"\\\n]|\\.)*"'                        # basic string
    r"|'[^'\n]*'"                                  # literal string
    r"|#[^\n]*"                                    # comment
    r"|[\[\]{}=,.\n]"                              # structure
)


def check_toml_bounds(text: str, name: str = "configuration file") -> None:
    """Refuse a TOML text that nests arrays and inline tables deeper than :data:`MAX_TOML_DEPTH`
    or has a dotted key of more than :data:`MAX_KEY_PARTS` parts, before it is parsed (tomllib
    recurses once per level, and its time grows with the square of a key's parts).

    One pass over the text with strings and comments skipped; a text that is not TOML at all is
    left to the parser (which says where). It stops at the first excess, so a hostile file costs
    no more than the bytes up to it.

    Raises
    ------
    ConfigError
        Naming the file, the line, the rule and the fix.
    """
    depth = 0
    dots = 0  # dots since the last `=`, `,`, bracket or line end: the parts of one key, minus one
    for match in _TOML_TOKEN.finditer(text):
        token = match.group()
        if len(token) != 1:  # a string or a comment
            continue
        if token in "[{":
            depth += 1
            dots = 0
            if depth > MAX_TOML_DEPTH:
                line = text.count("\n", 0, match.start()) + 1
                raise ConfigError(
                    f"configuration file {name!r}, line {line}: arrays and inline tables nest more than "
                    f"{MAX_TOML_DEPTH} levels deep; a case file needs two or three, flatten the value"
                )
        elif token in "]}":
            depth = max(depth - 1, 0)
            dots = 0
        elif token == ".":
            dots += 1
            if dots >= MAX_KEY_PARTS:
                line = text.count("\n", 0, match.start()) + 1
                raise ConfigError(
                    f"configuration file {name!r}, line {line}: a dotted key has more than {MAX_KEY_PARTS} parts "
                    "(`a.b.c…`); the configuration's keys have at most five, use those of docs/configuration.md"
                )
        else:  # `=`, `,` or a line end
            dots = 0


# --------------------------------------------------------------------------------------------
# CSV records of an input table
# --------------------------------------------------------------------------------------------
def csv_rows(text: str) -> list[tuple[int, list[str]]]:
    """The records of the CSV ``text`` as (line number, stripped fields), refusing what the csv
    module cannot read (a field longer than :data:`MAX_CSV_FIELD` characters, a NUL byte) with a
    :class:`ConfigError` whose message starts ``line N:`` (the caller prepends the file).
    """
    reader = csv.reader(io.StringIO(text))
    rows: list[tuple[int, list[str]]] = []
    try:
        for row in reader:
            rows.append((reader.line_num, [f.strip() for f in row]))
    except csv.Error as exc:
        too_long = "field larger" in str(exc)
        rule = (f"a field may hold at most {MAX_CSV_FIELD} characters ({MAX_CSV_FIELD >> 10} KiB)" if too_long
                else "a CSV table is text with no NUL byte and closed quotes")
        raise ConfigError(f"line {max(reader.line_num, 1)}: not readable as CSV ({exc}): {rule}; correct the file "
                          "there") from None
    return rows
