"""How the command line answers SIGINT, SIGTERM and SIGHUP, from its first millisecond.

``rattle`` (the console script) and ``python -m rattle`` import this package before anything
else of theirs; its ``__init__`` calls :func:`install_at_start`, which, in that process alone
(:func:`is_command_line`: the interpreter's own command line says so), installs
:func:`handle` for the three signals before click, numpy or any other slow import. Imported as a
library (a notebook, pytest, a worker process) nothing is installed here.

What a signal does, by phase (exit status 128 + the signal's number, one line on stderr
``rattle: error: interrupted by SIGxxx; …``):

- *at start and after the command* (mode ``"exit"``): the line is written and the process ends
  at once — nothing has been created yet, or everything has been moved into place already;
- *while a command runs* (:func:`raising`, mode ``"raise"``): the first signal raises
  :class:`Interrupted` (a ``KeyboardInterrupt``) in the main thread, so that every ``finally``
  removes its temporary files and stops its worker processes; the command line prints the line;
- *a later signal* while that clean-up runs is noted and ignored (a Ctrl-C reaches the whole
  process group, a supervisor may follow SIGINT with SIGTERM): the first one decides the exit
  status, and the clean-up is not broken off half-way. Only a signal that comes more than
  :data:`FORCE_AFTER` seconds into the clean-up (a user pressing Ctrl-C again at a clean-up
  that hangs) ends the process at once.

Python swallows an exception raised while a finalizer runs (a ``__del__``, a weakref callback
of the garbage collector): the first signal's :class:`Interrupted` raised there is sent again a
moment later (:func:`_unraisable`, the ``sys.unraisablehook`` while a command runs), so that a
signal that came at that instant still ends the run.

A signal whose disposition was "ignore" when the process started (``nohup``: SIGHUP; a
background job of a non-interactive shell: SIGINT) stays ignored. A child forked before it set
its own handlers (a worker process) is not the command line: SIGINT is ignored there (its
parent decides), the other signals end it as their default action would.

Imported here: ``os``, ``sys``, ``time`` and the C module ``_signal`` — not ``signal``, whose enums
import ``enum``, ``functools`` and ``collections`` (10–20 ms on a busy machine, the very window
this module closes), nor ``contextlib`` or ``typing``.
"""

from __future__ import annotations

import _signal
import os
import sys
import time

TYPE_CHECKING = False
if TYPE_CHECKING:  # annotations only
    from types import FrameType, TracebackType
    from typing import Any

__all__ = ["FORCE_AFTER", "HANDLED", "Interrupted", "install_at_start", "is_command_line", "installed_at_start",
           "raising", "handle", "message", "mark_reported", "interrupted_by", "raise_received", "exit_now",
           "signal_name"]

#: The signals handled, number → name (those the platform has).
HANDLED: dict[int, str] = {getattr(_signal, name): name for name in ("SIGINT", "SIGTERM", "SIGHUP")
                           if hasattr(_signal, name)}
#: Seconds into the clean-up after which a further signal ends the process at once.
FORCE_AFTER = 2.0
#: Seconds after which a signal swallowed by a finalizer is sent again (:func:`_unraisable`).
_AGAIN_AFTER = 0.01

_SIGINT = getattr(_signal, "SIGINT", 2)
#: The module names ``python -m NAME`` runs the command line with.
_MODULES = ("rattle", "rattle.__main__", "rattle.cli", "rattle.cli.main")
#: The console scripts' names (pip's launchers on Windows add the suffixes).
_SCRIPTS = ("rattle", "rattle.exe", "rattle-script.py")
#: Interpreter options followed by a separate value.
_WITH_VALUE = ("-X", "-W", "--check-hash-based-pycs")


class Interrupted(KeyboardInterrupt):
    """A signal received while a command runs: raised in the main thread like Ctrl-C's
    ``KeyboardInterrupt``, so that the same ``finally`` blocks remove temporary files and stop
    worker processes. ``signum`` is the signal's number."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


class _State:
    owner: int | None = None        # the process that installed the handlers
    at_start = False                # installed by install_at_start (the command-line process)
    mode = "exit"                   # "exit" or "raise"
    first: int | None = None        # the first signal received
    first_at = 0.0                  # when (time.monotonic)
    reported = False                # the interruption's line is on stderr
    reporting = False               # report() is writing it now
    swallowed = False               # the first signal's Interrupted was swallowed by a finalizer
    arrivals: int | None = None     # read end of the wakeup pipe: signal numbers in arrival order
    hook: Any = sys.__unraisablehook__  # the unraisable hook :class:`raising` replaced
    excepthook: Any = sys.__excepthook__  # and the exception hook


def signal_name(signum: int) -> str:
    """``SIGINT`` for 2 (``signal 99`` for a number without a name)."""
    if signum in HANDLED:
        return HANDLED[signum]
    import signal  # the enum, for a signal this module does not handle

    try:
        return signal.Signals(signum).name
    except ValueError:  # pragma: no cover
        return f"signal {signum}"


def message(signum: int, *, forced: bool = False) -> str:
    """The interruption's error line without its ``rattle: error: `` prefix."""
    if forced:
        return (f"interrupted by {signal_name(signum)}; a further signal cut the clean-up short: a hidden staging "
                "folder may be left in the output folder (the next run there removes it)")
    return (f"interrupted by {signal_name(signum)}; temporary files were removed and no output set was left "
            "half-written")


def _write_line(text: str) -> None:
    """``rattle: error: text`` on stderr, written with one system call (safe inside a handler,
    whatever the stderr buffer was doing when the signal came)."""
    outer = _State.reporting
    _State.reporting = True  # a handler run nested in here (a pending signal) returns: one line
    try:
        try:
            sys.stderr.flush()
        except Exception:  # a write interrupted half-way ("reentrant call"), a closed stream
            pass
        try:
            os.write(2, f"rattle: error: {text}\n".encode("utf-8", "replace"))
        except OSError:  # pragma: no cover - stderr closed
            pass
        _State.reported = True
    finally:
        _State.reporting = outer


def exit_now(code: int) -> None:
    """End the process at once with ``code``: stdout and stderr flushed, no finalizers run (an
    object an interrupted library call left behind — a Dask client still connecting — would
    otherwise wait in its ``__del__``; what rattle created was removed in its ``finally``
    blocks). The command line's use only."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # a closed or broken stream: nothing more to say
            pass
    os._exit(code)


def handle(signum: int, _frame: FrameType | None) -> None:
    """The handler of the handled signals (module docstring)."""
    if os.getpid() != _State.owner:  # a forked child that has not set its own handlers yet
        if signum != _SIGINT:
            _signal.signal(signum, _signal.SIG_DFL)
            os.kill(os.getpid(), signum)
        return
    first = _State.first
    if first is None:
        signum = _first_arrived(signum)
        _State.first, _State.first_at = signum, time.monotonic()
        if _State.mode == "raise":
            raise Interrupted(signum)
        if not _State.reported:
            _write_line(message(signum))
        exit_now(128 + signum)
        return
    _first_arrived(signum)  # (empties the arrival pipe)
    if _State.swallowed and _State.mode == "raise":  # the first's Interrupted did not reach the command:
        _State.swallowed = False  # raise it now, whichever handled signal runs next (the first decides)
        raise Interrupted(first)
    # a later signal: the first one's clean-up runs (raise mode), or the command has ended
    if _State.reporting:  # the line is being written (this handler runs nested inside report()):
        return  # it is written once, and the command ends right after
    if _State.mode == "exit" or time.monotonic() - _State.first_at > FORCE_AFTER:
        if not _State.reported:
            _write_line(message(first, forced=_State.mode == "raise"))
        exit_now(128 + first)


def _first_arrived(signum: int) -> int:
    """The handled signal that arrived first among those whose handlers are pending, or ``signum``.

    Python runs the handlers of signals pending together in the order of their numbers, not of
    their arrival: SIGTERM followed 20 ms later by SIGINT, both arriving while the main thread is
    in one long C call (an fsync, a process start, a BLAS call), would run SIGINT's handler first
    and SIGINT would decide. The C-level handler writes each signal's number, as it arrives, to
    the wakeup pipe (:func:`_watch_arrivals`); its first handled number is the first signal."""
    fd = _State.arrivals
    if fd is None:
        return signum
    first = None
    while True:
        try:
            data = os.read(fd, 512)
        except (BlockingIOError, InterruptedError):
            break
        except OSError:  # pragma: no cover - closed
            break
        if not data:
            break
        if first is None:
            first = next((b for b in data if b in HANDLED), None)
    return signum if first is None else first


def _watch_arrivals() -> Any:
    """Have the signals' numbers written, in arrival order, to a non-blocking pipe read by
    :func:`_first_arrived` (``signal.set_wakeup_fd``, main thread only); returns what to pass to
    :func:`_unwatch_arrivals` (None where it could not be set: the arrival order is then the
    handlers' order)."""
    try:
        r, w = os.pipe()
    except OSError:  # pragma: no cover - no file descriptors left
        return None
    try:
        os.set_blocking(r, False)
        os.set_blocking(w, False)
        old = _signal.set_wakeup_fd(w, warn_on_full_buffer=False)
    except (ValueError, OSError, AttributeError):  # not the main thread, or no pipes here
        os.close(r)
        os.close(w)
        return None
    previous = (_State.arrivals, old, r, w)
    _State.arrivals = r
    return previous


def _unwatch_arrivals(token: Any) -> None:
    """Undo :func:`_watch_arrivals` (the wakeup fd and arrival pipe that were there before)."""
    if token is None:
        return
    arrivals, old, r, w = token
    try:
        _signal.set_wakeup_fd(old)
    except (ValueError, OSError):  # pragma: no cover
        pass
    _State.arrivals = arrivals
    for fd in (r, w):
        try:
            os.close(fd)
        except OSError:  # pragma: no cover
            pass


def _install() -> dict[int, Any]:
    """:func:`handle` for every handled signal not ignored; the handlers it replaced."""
    previous: dict[int, Any] = {}
    for sig in HANDLED:
        old = _signal.getsignal(sig)
        if old is None or (not callable(old) and old == _signal.SIG_IGN):  # set outside Python, or ignored (nohup)
            continue
        _signal.signal(sig, handle)
        previous[sig] = old
    _State.owner = os.getpid()
    return previous


def is_command_line(argv: list[str] | None = None) -> bool:
    """Whether this process is ``rattle …`` or ``python -m rattle …``, from the interpreter's own
    command line ``argv`` (default ``sys.orig_argv``), not from ``sys.argv`` (which a
    multiprocessing child inherits from its parent)."""
    if argv is None:
        argv = list(getattr(sys, "orig_argv", None) or [])
    args = argv[1:]
    i = 0
    while i < len(args):
        arg = args[i]
        if arg == "-m":
            return i + 1 < len(args) and args[i + 1] in _MODULES
        if arg.startswith("-m"):
            return arg[2:] in _MODULES
        if arg.startswith("-c") or arg == "-":
            return False
        if arg in _WITH_VALUE:
            i += 2
            continue
        if arg.startswith("-"):
            i += 1
            continue
        return os.path.basename(arg) in _SCRIPTS
    return False


def install_at_start() -> None:
    """Install the handlers (mode ``"exit"``) when this process is the command line; a no-op
    otherwise, and on a second call."""
    if _State.at_start or not is_command_line():
        return
    try:
        _install()
    except (ValueError, OSError):  # pragma: no cover - not the main thread
        return
    _State.at_start = True


def installed_at_start() -> bool:
    """Whether :func:`install_at_start` installed the handlers in this process (it is the
    command line)."""
    return _State.at_start and _State.owner == os.getpid()


def _unraisable(unraisable: Any) -> None:
    """``sys.unraisablehook`` while a command runs: the first signal's :class:`Interrupted`
    raised while a finalizer ran (a ``__del__``, a weakref callback the garbage collector
    called) is swallowed by Python ("Exception ignored in …") and the run would go on as if no
    signal had come; it is delivered again instead, to be raised in the code that runs next.
    Anything else goes to the hook that was there before."""
    exc = unraisable.exc_value
    if isinstance(exc, Interrupted) and _State.mode == "raise" and os.getpid() == _State.owner \
            and _State.first == exc.signum:
        # The next handled signal's handler raises it: this one sent again, or a second signal
        # that comes first — the first signal still decides the exit status. (Should it land in
        # a finalizer again, it comes back here.)
        _swallowed(exc.signum)
        return
    _State.hook(unraisable)


def _excepthook(kind: type[BaseException], value: BaseException, tb: TracebackType | None) -> None:
    """``sys.excepthook`` while a command runs: C code that prints an exception and goes on
    (``PyErr_Print``: an import that C code makes, e.g. while a compiled kernel is built) would
    print the first signal's :class:`Interrupted` as a traceback and swallow it — measured: a
    SIGHUP 800 ms into a fresh install's first sweep, the run then ended with status 0. It is
    delivered again instead, as from a finalizer (:func:`_unraisable`), and nothing is printed.
    Anything else goes to the hook that was there before."""
    if isinstance(value, Interrupted) and _State.mode == "raise" and os.getpid() == _State.owner \
            and _State.first == value.signum:
        _swallowed(value.signum)
        return
    _State.excepthook(kind, value, tb)


def _swallowed(signum: int) -> None:
    """The first signal's Interrupted did not reach the command: the next handled signal's handler
    raises it (``swallowed``), this one sent again from a thread a moment later (sent from here,
    its handler would run inside the code that swallowed it)."""
    _State.swallowed = True
    import threading

    threading.Thread(target=_send_again, args=(os.getpid(), signum), name="rattle-signal-again",
                     daemon=True).start()


def _send_again(pid: int, signum: int) -> None:
    time.sleep(_AGAIN_AFTER)
    os.kill(pid, signum)


class raising:  # noqa: N801 - used as a function: ``with raising():``
    """For the body, the first handled signal raises :class:`Interrupted` and later ones are
    noted (module docstring); afterwards the earlier handlers and mode come back (the command
    line may run inside another program). Outside the main thread the body runs unprotected.

    A class rather than a ``contextlib.contextmanager``: this module imports no ``contextlib``.
    """

    def __enter__(self) -> None:
        self._mode = _State.mode
        self._previous: dict[int, Any] = {}
        self._hook: Any = None
        self._arrivals: Any = None
        _State.first, _State.reported, _State.mode, _State.swallowed = None, False, "raise", False
        try:
            self._previous = _install()
        except ValueError:  # not the main thread: leave the signals alone
            _State.mode = self._mode
            return
        self._arrivals = _watch_arrivals()
        self._hook = sys.unraisablehook
        if self._hook is not _unraisable:
            _State.hook = self._hook
        sys.unraisablehook = _unraisable
        self._excepthook = sys.excepthook
        if self._excepthook is not _excepthook:
            _State.excepthook = self._excepthook
        sys.excepthook = _excepthook

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 tb: TracebackType | None) -> None:
        for sig, old in self._previous.items():
            try:
                _signal.signal(sig, old)
            except (ValueError, TypeError):  # pragma: no cover
                pass
        if self._hook is not None:
            sys.unraisablehook = self._hook
            sys.excepthook = self._excepthook
        _unwatch_arrivals(self._arrivals)
        _State.mode = self._mode


def report(signum: int) -> None:
    """Write the interruption's line for ``signum`` once, with the handled signals blocked while
    it is written and marked: a further signal then (the handlers back in exit mode) ends the
    process without writing it again, and cannot end it before it is written."""
    mask = None
    try:
        mask = _signal.pthread_sigmask(_signal.SIG_BLOCK, HANDLED)
    except (AttributeError, OSError, ValueError):  # pragma: no cover - no pthread_sigmask here
        pass
    try:
        if not _State.reported:
            # A signal that arrived just before the mask was set has its Python handler pending: it
            # may run inside the write below (at a flush); ``reporting`` tells it to return.
            _State.reporting = True
            try:  # through sys.stderr (what a caller capturing it sees)
                sys.stderr.write(f"rattle: error: {message(signum)}\n")
                sys.stderr.flush()
                _State.reported = True
            except Exception:  # a closed or broken stream
                _write_line(message(signum))
            finally:
                _State.reporting = False
    finally:
        if mask is not None:
            _signal.pthread_sigmask(_signal.SIG_SETMASK, mask)


def mark_reported() -> None:
    """The interruption's line has been written (a later signal does not write it again)."""
    _State.reported = True


def interrupted_by() -> int | None:
    """The first signal received during the last :func:`raising` body (None if none)."""
    return _State.first


def raise_received() -> None:
    """Raise the :class:`Interrupted` of a signal received whose Interrupted never reached the
    command (code that caught it and went on): the signal decides — at the command's end, and
    before an output set is opened or lands, so that an interrupted run writes nothing."""
    signum = _State.first
    if signum is not None:
        raise Interrupted(int(signum))
