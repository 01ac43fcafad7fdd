"""Atomic file writes: write a temporary file next to the target, then rename it over the target.

A reader (or a crashed run) therefore sees either the old file or the complete new one, never a
half-written file. The temporary file lives in the target's directory because a rename is only
atomic within one file system; it is removed when the write fails (also on KeyboardInterrupt).

:class:`OutputSet` extends this to the several files of one run: staged in a hidden folder and
moved into place together, so that an interrupted run never leaves new and old files mixed.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import json
import os
import shutil
import signal
import stat
import tempfile
import threading
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ..errors import ConfigError, RattleError

__all__ = [
    "atomic_path", "atomic_write_bytes", "atomic_write_text", "OutputSet", "recover_staging", "RecoveryWarning",
    "STAGING_PREFIX", "WriteError", "describe_os_error",
]


class WriteError(RattleError, OSError):
    """A file or folder could not be written (no space, no permission, a folder where a file of
    the set should go …). An :class:`OSError` with ``errno`` and ``filename`` set, whose message
    is one line naming the path and the errno (``[Errno 28] No space left on device (ENOSPC)``);
    what was there before is left as it was. The command line exits with status 1 on it."""

    def __init__(self, message: str, *, code: int | None = None, filename: str | None = None) -> None:
        OSError.__init__(self, message)
        self.message = message
        self.errno = code  # type: ignore[assignment]
        self.strerror = os.strerror(code) if code is not None else None  # type: ignore[assignment]
        self.filename = filename

    def __str__(self) -> str:
        return self.message

    def __reduce__(self) -> Any:  # picklable across worker processes
        return (_make_write_error, (self.message, self.errno, self.filename))


#: OSError's own subclasses by errno: a WriteError is also the one ``open`` would have raised
#: (``except FileNotFoundError`` keeps working).
_ERRNO_CLASSES: dict[int, type[OSError]] = {
    errno.ENOENT: FileNotFoundError, errno.EISDIR: IsADirectoryError, errno.ENOTDIR: NotADirectoryError,
    errno.EACCES: PermissionError, errno.EPERM: PermissionError, errno.EEXIST: FileExistsError,
}


@functools.cache
def _write_error_class(code: int | None) -> type[WriteError]:
    base = _ERRNO_CLASSES.get(code) if code is not None else None
    if base is None:
        return WriteError
    return type(f"WriteError{base.__name__}", (WriteError, base), {"__module__": __name__})


def _make_write_error(message: str, code: int | None, filename: str | None) -> WriteError:
    """A :class:`WriteError` (of the errno's OSError subclass too)."""
    return _write_error_class(code)(message, code=code, filename=filename)


def describe_os_error(exc: OSError) -> str:
    """``[Errno 28] No space left on device (ENOSPC)``: the errno, its text and its symbol."""
    code = exc.errno
    if code is None:
        return str(exc)
    text = exc.strerror or os.strerror(code)
    return f"[Errno {code}] {text} ({errno.errorcode.get(code, '?')})"


def _write_error(exc: OSError, path: str | os.PathLike[str], what: str = "cannot write") -> WriteError:
    if isinstance(exc, WriteError):
        return exc
    where = os.fspath(exc.filename) if exc.filename and "tmp" not in os.fspath(exc.filename) else os.fspath(path)
    return _make_write_error(f"{what} {where!r}: {describe_os_error(exc)}", exc.errno, where)


def _check_path(path: str | os.PathLike[str], what: str = "`path`") -> Path:
    """``path`` as a Path, refusing one with a NUL byte (no system call can take it)."""
    try:
        target = Path(path)
    except TypeError:
        raise TypeError(f"{what} must be a str or os.PathLike, got {type(path).__name__} {path!r}") from None
    if "\x00" in os.fspath(target):
        raise ConfigError(f"{what} {os.fspath(target)!r} is not a valid path: it holds a NUL byte, which no file name "
                          "can contain; give another path")
    return target


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
    target = _check_path(path)
    parent = target.parent
    if not parent.is_dir():
        kind = "does not exist" if not os.path.lexists(parent) else "is not a folder"
        code = errno.ENOENT if not os.path.lexists(parent) else errno.ENOTDIR
        raise _make_write_error(f"cannot write {os.fspath(target)!r}: its folder {os.fspath(parent)!r} {kind} "
                                f"([Errno {code}] {os.strerror(code)} ({errno.errorcode[code]})); create the folder "
                                "first or give another path", code, os.fspath(target))
    if target.is_dir():
        raise _make_write_error(f"cannot write {os.fspath(target)!r}: a folder is there ([Errno {errno.EISDIR}] "
                                f"{os.strerror(errno.EISDIR)} (EISDIR)); give a file name", errno.EISDIR,
                                os.fspath(target))
    try:
        fd, name = tempfile.mkstemp(
            dir=parent, prefix=f".{target.name}.", suffix=f".tmp{target.suffix}"
        )
    except OSError as exc:
        raise _write_error(exc, target) from None
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
    except OSError as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise _write_error(exc, target) from exc
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


# --------------------------------------------------------------------------------------------
# A set of output files moved into place together
# --------------------------------------------------------------------------------------------
#: Name prefix of the hidden staging folders inside an output directory.
STAGING_PREFIX = ".rattle-staging-"
#: The commit journal inside a staging folder (written when every file of the set is complete).
_JOURNAL = ".commit.json"
#: Signals held back while a staged set is being moved into place.
_HELD_SIGNALS = tuple(
    sig for sig in (getattr(signal, n, None) for n in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT")) if sig is not None
)


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Hold SIGINT/SIGTERM/SIGHUP/SIGQUIT back for the body (a few system calls): a signal that
    arrives meanwhile is recorded and raised again, to the handler that was in place, when the
    body ends.

    The Python-level handlers are swapped rather than the signals blocked with
    ``pthread_sigmask``: a process-directed signal blocked in the main thread is delivered to
    another thread (a queue feeder, a progress monitor), and Python then runs its handler in the
    main thread all the same. Handlers can only be set in the main thread; elsewhere the body
    runs unprotected.
    """
    if threading.current_thread() is not threading.main_thread():  # pragma: no cover
        yield
        return
    pending: list[int] = []

    def hold(signum: int, _frame: object) -> None:
        pending.append(signum)

    previous: dict[int, Any] = {}
    for sig in _HELD_SIGNALS:
        handler = signal.getsignal(sig)
        if handler is None:  # set outside Python: leave it alone
            continue
        with contextlib.suppress(ValueError, OSError):
            signal.signal(sig, hold)
            previous[sig] = handler
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if pending:
            signal.raise_signal(pending[0])  # now: KeyboardInterrupt, the CLI's Interrupted, or the default


def _fsync_dir(path: Path) -> None:
    with contextlib.suppress(OSError):  # not every file system lets a directory be opened/synced
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _pid_alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    return True


def _move_in(directory: Path, staging: Path, moves: Sequence[str], removals: Sequence[str]) -> None:
    """The commit itself: stale files of the set removed, staged files renamed over their targets."""
    for name in removals:
        with contextlib.suppress(FileNotFoundError):
            (directory / name).unlink()
    for name in moves:
        src = staging / name
        if src.exists():  # absent only when a roll-forward repeats a partly done commit
            os.replace(src, directory / name)
    _fsync_dir(directory)


_KIND_NAMES = {stat.S_IFDIR: "a folder", stat.S_IFIFO: "a named pipe (FIFO)", stat.S_IFSOCK: "a socket",
               stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device"}


def _check_replaceable(target: Path) -> None:
    """Refuse (WriteError) a member of an output set whose place holds something that is neither
    a file nor a symbolic link (a rename over a folder fails; a special file is not ours)."""
    try:
        st = os.lstat(target)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise _write_error(exc, target) from None
    if stat.S_ISREG(st.st_mode) or stat.S_ISLNK(st.st_mode):
        return
    kind = _KIND_NAMES.get(stat.S_IFMT(st.st_mode), "not a file")
    code = errno.EISDIR if stat.S_ISDIR(st.st_mode) else errno.EEXIST
    raise _make_write_error(
        f"cannot write {os.fspath(target)!r}: {kind} is in the place of this output file ([Errno {code}] "
        f"{os.strerror(code)} ({errno.errorcode[code]})); move it away and run again", code, os.fspath(target))


def _move_in_or_back(directory: Path, staging: Path, moves: Sequence[str], removals: Sequence[str]) -> None:
    """:func:`_move_in` for a run's own commit, all or nothing against errors: each file replaced
    is first hard-linked into ``staging/.previous`` (a rename keeps the target present throughout),
    and when a rename or a removal fails the journal is removed and what was done is undone
    (raised as :class:`WriteError`). A SIGKILL in the middle leaves the journal: the next run rolls
    forward (:func:`recover_staging`)."""
    backup = staging / ".previous"
    done: list[tuple[str, str]] = []  # (name, "kept": the earlier file is in backup | "new" | "lost")
    try:
        backup.mkdir(exist_ok=True)
        for name in removals:
            target = directory / name
            if os.path.lexists(target):
                os.replace(target, backup / name)
                done.append((name, "kept"))
        for name in moves:
            target = directory / name
            state = "new"
            if os.path.lexists(target):
                try:
                    os.link(target, backup / name, follow_symlinks=False)
                    state = "kept"
                except OSError:  # a file system without hard links: this one cannot be undone
                    state = "lost"
            os.replace(staging / name, target)
            done.append((name, state))
        _fsync_dir(directory)
    except OSError as exc:
        with contextlib.suppress(OSError):
            (staging / _JOURNAL).unlink()  # first: a recovery must not roll this set forward
        _fsync_dir(staging)
        for name, state in reversed(done):
            with contextlib.suppress(OSError):
                if state == "kept":
                    os.replace(backup / name, directory / name)
                elif state == "new":
                    (directory / name).unlink()
        _fsync_dir(directory)
        raise _write_error(exc, directory / os.path.basename(os.fspath(exc.filename or directory))) from None


#: A journal larger than this, or listing more names than this, is not one this module wrote.
_JOURNAL_MAX_BYTES = 1 << 20
_JOURNAL_MAX_NAMES = 10_000


def _plain_name(name: object) -> bool:
    """A name that can only mean a file directly inside one folder: a non-empty str without
    separators, NUL or a leading dot (which also excludes ``.`` and ``..``), at most 255 bytes."""
    if not isinstance(name, str) or not name or name.startswith(".") or "\x00" in name:
        return False
    if "/" in name or os.sep in name or (os.altsep and os.altsep in name):
        return False
    try:
        return len(os.fsencode(name)) <= 255
    except UnicodeError:
        return False


def _read_journal(journal: Path) -> dict[str, Any] | None:
    """The journal's content, or None when it is not a regular file of a sane size holding a JSON
    object (opened without following a symlink and without blocking on a FIFO)."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(journal, flags)
    except OSError:
        return None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_size > _JOURNAL_MAX_BYTES:
            return None
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(_JOURNAL_MAX_BYTES + 1)
    except OSError:
        return None
    finally:
        os.close(fd)
    try:
        plan = json.loads(data.decode("utf-8"))
    except (UnicodeError, ValueError, RecursionError):
        return None
    return plan if isinstance(plan, dict) else None


def _journal_plan(directory: Path, staging: Path, plan: dict[str, Any],
                  names: frozenset[str] | None) -> tuple[list[str], list[str], list[str]]:
    """The moves and removals of a journal that recovery can prove are its own, and what it refused.

    A move is allowed for a plain name whose staged file is a regular file inside ``staging`` (not
    a symlink); a removal for a plain name that is a member of the output set ``names`` (with
    ``names`` None, the set is the journal's own moves) and, in ``directory``, a regular file or a
    symlink (unlinking a symlink never touches its target). Anything else — separators, ``..``,
    absolute paths, hidden names, folders, special files, names outside the set — is refused.
    """
    moves_in, removals_in = plan.get("moves"), plan.get("removals")
    refused: list[str] = []
    if not isinstance(moves_in, list) or not isinstance(removals_in, list) \
            or len(moves_in) + len(removals_in) > _JOURNAL_MAX_NAMES:
        return [], [], ["the journal's lists (not lists, or too long)"]
    moves: list[str] = []
    for name in moves_in:
        if _plain_name(name) and name not in moves:
            try:
                st = os.lstat(staging / name)
            except OSError:  # already moved by the run that was killed: nothing to do
                if (directory / name).is_file():
                    moves.append(name)
                    continue
                refused.append(repr(name))
                continue
            if stat.S_ISREG(st.st_mode):
                moves.append(name)
                continue
        refused.append(repr(name))
    own = names if names is not None else frozenset(moves)
    removals: list[str] = []
    for name in removals_in:
        if _plain_name(name) and name in own and name not in moves:
            try:
                st = os.lstat(directory / name)
            except FileNotFoundError:
                continue
            except OSError:
                refused.append(repr(name))
                continue
            if stat.S_ISREG(st.st_mode) or stat.S_ISLNK(st.st_mode):
                removals.append(name)
                continue
        refused.append(repr(name))
    return moves, removals, refused


def recover_staging(directory: str | os.PathLike[str], names: Sequence[str] | None = None) -> list[str]:
    """Finish or discard the staging folders that runs killed outright (SIGKILL, power loss) left
    in ``directory``; return the names of the folders handled.

    A folder whose journal exists had its set complete: its renames are finished (roll forward).
    A folder without a journal never got that far: it is removed (roll back; the earlier files are
    untouched). Folders of live processes (the pid is part of the name) are left alone.

    A journal is data read from disk, so recovery acts only on names it can prove are its own:
    files staged inside the staging folder (moved in) and members of the output set ``names``
    (removed; with ``names`` None only names the journal also moves). A name with a separator,
    ``..``, an absolute path, a hidden name, a symlink or special file staged, or a name outside
    the set is refused with a :class:`RecoveryWarning` and left alone; nothing outside
    ``directory`` is ever moved or deleted.

    Parameters
    ----------
    directory : str or os.PathLike
        The output directory.
    names : sequence of str, optional
        The output set of the run that recovers (its files may be removed as stale).
    """
    directory = Path(directory)
    own = None if names is None else frozenset(str(n) for n in names)
    handled: list[str] = []
    try:
        entries = list(directory.iterdir())
    except OSError:
        return handled
    for entry in entries:
        if not entry.name.startswith(STAGING_PREFIX) or entry.is_symlink() or not entry.is_dir():
            continue
        try:
            pid = int(entry.name[len(STAGING_PREFIX):].split("-", 1)[0])
        except ValueError:
            continue
        if pid == os.getpid() or _pid_alive(pid):
            continue
        journal = entry / _JOURNAL
        if os.path.lexists(journal):
            plan = _read_journal(journal)
            if plan is None:
                moves, removals, refused = [], [], ["the journal (not a JSON object of a sane size)"]
            else:
                moves, removals, refused = _journal_plan(directory, entry, plan, own)
            if refused:
                shown = ", ".join(refused[:5]) + (f" and {len(refused) - 5} more" if len(refused) > 5 else "")
                warnings.warn(f"recovering {entry}: refused {shown}: not a file of this output set; left alone",
                              RecoveryWarning, stacklevel=2)
            try:
                with _signals_held():
                    _move_in(directory, entry, moves, removals)
            except OSError as exc:
                warnings.warn(f"recovering {entry}: {exc}; the folder is left for the next run", RecoveryWarning,
                              stacklevel=2)
                continue
        shutil.rmtree(entry, ignore_errors=True)
        handled.append(entry.name)
    return handled


class RecoveryWarning(UserWarning):
    """A staging folder's journal named something that recovery cannot prove is its own."""


class OutputSet:
    """The output files of one run, written into a staging folder and moved into place together.

    How "together" works
    --------------------
    The output directory may hold other files (the user's configuration, another command's
    outputs), so it cannot be swapped for a new directory as a whole: ``rename(2)`` onto a
    non-empty directory fails, and exchanging directories would take the user's files away.
    Instead:

    1. every file is written into a hidden staging folder *inside* the output directory
       (``.rattle-staging-<pid>-<random>/``: the same file system, so the moves are renames);
    2. when all are complete (each flushed to disk), a journal listing the moves and removals is
       written into the staging folder — the commit point;
    3. with SIGINT, SIGTERM, SIGHUP and SIGQUIT held back (recorded, and raised again when the
       move is done), each staged file is renamed over its
       target (``os.replace``, atomic per file) and the files of the set that this run did not
       produce (e.g. ``frf.png`` without matplotlib) are removed, so that an old one cannot sit
       beside new data; then the staging folder is removed.

    Step 3 is a handful of system calls with the catchable signals held back, so an interrupted run
    (Ctrl-C, ``kill``) leaves either the earlier set untouched (interrupted before step 3; the
    staging folder is removed on the way out) or the complete new set. Only an uncatchable end in
    the middle of step 3 (SIGKILL, power loss) can leave a mix, and then the journal says how to
    finish: the next run in that directory completes the renames (:func:`recover_staging`).
    Files that are not part of the set are never touched.

    Parameters
    ----------
    directory : str or os.PathLike
        The output directory (created, with its parents, when the set is opened; the folders
        created are removed again if the run ends without committing).
    names : sequence of str
        Every file name this command can write: the set. Names only, no sub-folders.

    Examples
    --------
    >>> with OutputSet(out, ["frf.csv", "frf.json"]) as staged:  # doctest: +SKIP
    ...     result.to_csv(staged.path("frf.csv"))
    ...     write_metadata(staged.path("frf.json"), ...)
    ...     staged.commit()
    """

    def __init__(self, directory: str | os.PathLike[str], names: Sequence[str]) -> None:
        self.directory = _check_path(directory, "the output folder")
        self.names = tuple(names)
        for name in self.names:
            if not name or Path(name).name != name or name.startswith("."):
                raise ValueError(f"`names` must be plain file names, got {name!r}")
        self.staging: Path | None = None
        self.committed: list[str] = []
        self._created: list[Path] = []

    # -- context manager ------------------------------------------------------------------------
    def __enter__(self) -> OutputSet:
        missing = []
        d = self.directory
        while not d.exists() and d != d.parent:
            missing.append(d)
            d = d.parent
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            self._created = missing
            self.discard()
            raise _write_error(exc, self.directory, "cannot create the output folder") from None
        self._created = missing  # deepest first
        try:
            recover_staging(self.directory, self.names)
            self.staging = Path(tempfile.mkdtemp(dir=self.directory, prefix=f"{STAGING_PREFIX}{os.getpid()}-"))
        except OSError as exc:
            self.discard()
            raise _write_error(exc, self.directory, "cannot write into the output folder") from None
        except BaseException:
            self.discard()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.discard()

    def path(self, name: str) -> Path:
        """Where to write the file ``name`` of the set (inside the staging folder)."""
        if name not in self.names:
            raise ValueError(f"`name` {name!r} is not part of this output set {self.names}")
        if self.staging is None:
            raise RuntimeError("the output set is not open (use it in a `with` block)")
        return self.staging / name

    def commit(self) -> list[str]:
        """Move the staged files into place together (see the class docstring); return their names
        in the order of ``names``."""
        if self.staging is None:
            raise RuntimeError("the output set is not open (use it in a `with` block)")
        staging = self.staging
        moves = [n for n in self.names if (staging / n).is_file()]
        removals = [n for n in self.names if n not in moves]
        # Every member's place must take a file: a folder or a special file there would stop the
        # moves half-way. Checked before the commit point, so that nothing of the set lands.
        for name in self.names:
            _check_replaceable(self.directory / name)
        try:
            for name in moves:
                _fsync(staging / name)
            journal = staging / _JOURNAL
            with open(journal, "w", encoding="utf-8") as fh:
                json.dump({"directory": os.fspath(self.directory), "moves": moves, "removals": removals}, fh)
                fh.flush()
                os.fsync(fh.fileno())
            _fsync_dir(staging)
        except OSError as exc:  # no space for the journal: nothing has moved yet
            raise _write_error(exc, self.directory) from None
        with _signals_held():
            _move_in_or_back(self.directory, staging, moves, removals)
            shutil.rmtree(staging, ignore_errors=True)
            self.staging = None
        self._created = []
        self.committed = moves
        return moves

    def discard(self) -> None:
        """Remove the staging folder (and the folders this set created) unless committed; idempotent."""
        staging, self.staging = self.staging, None
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
        for d in self._created:  # deepest first; only if still empty
            with contextlib.suppress(OSError):
                d.rmdir()
        self._created = []
