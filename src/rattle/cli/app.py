"""The ``rattle`` command group (SPEC §3): the argument parser, the dispatch to the commands
(:mod:`rattle.cli.commands`), and the one place where failures become exit statuses and
``rattle: error:`` lines.

Exit status: 0 success, 2 bad input (configuration, options, output path), 1 a numerical
failure that could not be recovered, 128 + the signal number when interrupted (130 SIGINT,
143 SIGTERM, 129 SIGHUP). Errors are one line on stderr, ``rattle: error: …``; warnings of the
numerics (numpy's RuntimeWarning …) one line each, ``rattle: warning: …``, never raw.

A front door that answers at once: the command line imports click, and numpy and the
configuration reader when a command reads its file; the solver (scipy) is imported when a command runs, matplotlib when a figure is
drawn. Every input is validated before that, and nothing is created in the output directory
until there is something to write.

Interrupted runs leave nothing wrong: every command writes its files into a staging folder inside
the output directory and moves them into place together at the end
(:class:`rattle.io.OutputSet`); while a command runs, SIGINT, SIGTERM and SIGHUP raise
:class:`Interrupted` (an exception, so that every ``finally`` removes its temporary files and
stops its worker processes), and a further signal during that clean-up does not break it off
(:mod:`rattle._signals`, which also answers the signals from the process's first millisecond,
before click or numpy are imported).
"""

from __future__ import annotations

import contextlib
import gc
import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from typing import Any

import click

from .. import _signals
from .._signals import Interrupted
from ..errors import ConfigError, ConvergenceError, RattleError
from .commands import COMMANDS, common_options
from .output import error, one_line, reset_verbose, warning

__all__ = ["cli", "main", "EXIT_OK", "EXIT_NUMERICAL", "EXIT_BAD_INPUT", "Interrupted", "RattleGroup"]

EXIT_OK = 0
EXIT_NUMERICAL = 1
EXIT_BAD_INPUT = 2

_NoArgsIsHelpError: Any = getattr(click.exceptions, "NoArgsIsHelpError", ())
_SIGINT = 2  # signal.SIGINT on every platform


# --------------------------------------------------------------------------------------------
# Signals and warnings
# --------------------------------------------------------------------------------------------
class _Stopped(Exception):
    """An interruption carried through click's main loop (which would turn KeyboardInterrupt into
    a generic "Aborted!")."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


#: Warning lines shown per run; the rest are counted and summarised in one line.
MAX_WARNINGS = 8


@contextlib.contextmanager
def _warnings_as_lines() -> Iterator[None]:
    """Every warning raised during the body reaches the user as one ``rattle: warning: …`` line:
    rattle's own warnings (UserWarning, or a message naming a key in backticks) as they are; others
    (numpy's "overflow encountered in …") with what kind they are and what they mean for the run —
    never with the file and line they arose at. Each distinct warning once; at most
    ``MAX_WARNINGS`` lines."""
    seen: set[tuple[Any, ...]] = set()
    hidden = 0

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int,
             file: Any = None, line: str | None = None) -> None:
        nonlocal hidden
        key = (category, " ".join(str(message).split()))
        if key in seen:
            return
        seen.add(key)
        if len(seen) > MAX_WARNINGS:
            hidden += 1
            return
        text = " ".join(str(message).split())
        if "`" in text or issubclass(category, UserWarning):  # one of ours: already says what and why
            warning(text)
            return
        # never the file and line it arose at: an internal location says nothing to the user
        warning(f"{text} ({category.__name__}); the run went on, but check the results "
                 "at the frequencies where this happened")

    with warnings.catch_warnings():
        warnings.showwarning = show
        try:
            yield
        finally:
            if hidden:
                warning(f"{hidden} further warning(s) not shown")


class RattleGroup(click.Group):
    """A click group that turns every failure into one ``rattle: error: …`` line and an exit status.

    Works the same under ``main()`` (console script, ``python -m rattle``) and under
    ``click.testing.CliRunner``, both of which call :meth:`main`.
    """

    def main(  # type: ignore[override]
        self,
        args: Sequence[str] | None = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        **extra: Any,
    ) -> Any:
        code = self._run(args, prog_name, complete_var, **extra)
        if standalone_mode:
            sys.exit(code)
        return code

    def _run(self, args: Sequence[str] | None, prog_name: str | None, complete_var: str | None, **extra: Any) -> int:
        try:
            try:
                with _signals.raising(), _warnings_as_lines():
                    code = self._invoke(args, prog_name, complete_var, **extra)
                    _signals.raise_received()  # a signal whose Interrupted never reached the command
                    return code
            finally:
                reset_verbose()
        except KeyboardInterrupt as exc:  # a signal while the command ran (a later one is noted only)
            signum = exc.signum if isinstance(exc, Interrupted) else int(_signals.interrupted_by() or _SIGINT)
            _signals.report(signum)  # once, whatever a further signal does meanwhile
            return 128 + signum
        except Exception:
            # The interruption raised inside code that turns it into another error: a C extension's
            # module initialisation interrupted while it was being imported ("ImportError:
            # initialization failed"), a library that wraps what it catches. The signal decides.
            signum = _signals.interrupted_by()
            if signum is None:
                raise
            _signals.report(int(signum))
            return 128 + int(signum)

    def invoke(self, ctx: click.Context) -> Any:
        # click turns KeyboardInterrupt into Abort (and prints a blank line); keep the signal
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            raise _Stopped(exc.signum if isinstance(exc, Interrupted) else _SIGINT) from None

    def _invoke(self, args: Sequence[str] | None, prog_name: str | None, complete_var: str | None,
                **extra: Any) -> int:
        try:
            rv = super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except _Stopped as exc:
            raise Interrupted(exc.signum) from None
        except _NoArgsIsHelpError as exc:  # bare `rattle`: show the help, as click does
            exc.show()
            return int(exc.exit_code)
        except click.UsageError as exc:
            hint = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
            error(exc.format_message() + hint)
            return int(exc.exit_code)
        except click.ClickException as exc:
            error(exc.format_message())
            return int(exc.exit_code)
        except click.Abort as exc:
            cause = exc.__cause__ or exc.__context__
            if isinstance(cause, KeyboardInterrupt):  # Ctrl-C while click itself was parsing
                raise Interrupted(cause.signum if isinstance(cause, Interrupted) else _SIGINT) from None
            error("aborted")
            return EXIT_NUMERICAL
        except ConfigError as exc:
            error(str(exc))
            return EXIT_BAD_INPUT
        except ConvergenceError as exc:
            error(f"numerical failure: {exc}")
            return EXIT_NUMERICAL
        except RattleError as exc:
            error(str(exc))
            return EXIT_NUMERICAL
        except ArithmeticError as exc:  # OverflowError, FloatingPointError, ZeroDivisionError
            error(f"numerical failure: {one_line(exc)} ({type(exc).__name__}); the model's numbers are "
                   "probably too large or too small for double precision — check their scale")
            return EXIT_NUMERICAL
        except MemoryError:
            error("numerical failure: out of memory; lower --harmonics, --points or the frequency range")
            return EXIT_NUMERICAL
        except (ValueError, TypeError) as exc:
            if type(exc).__name__ == "LinAlgError":  # numpy.linalg's, without importing numpy here
                error(f"numerical failure: {one_line(exc)} (a singular or non-finite linear system)")
                return EXIT_NUMERICAL
            if isinstance(exc, ValueError) and "embedded null byte" in str(exc):  # click's os.stat of a path
                error("a path argument contains a NUL byte (\\x00), which no file name can hold; check how the "
                      "command line was built")
                return EXIT_BAD_INPUT
            # The library validates its arguments with ValueError/TypeError naming the argument
            # (a combination the CLI's own checks did not anticipate): bad input, not a crash.
            if "`" not in str(exc):
                raise  # not one of our validation messages: a bug, keep the traceback
            error(str(exc))
            return EXIT_BAD_INPUT
        return rv if isinstance(rv, int) else EXIT_OK



@click.group(name="rattle", cls=RattleGroup, context_settings={"help_option_names": ["-h", "--help"]})
@common_options
def cli() -> None:
    """Non-linear frequency response of drivetrain rattle (harmonic balance + continuation).

    Exit status: 0 success, 2 bad input, 1 numerical failure, 130/143 interrupted.
    """


for _command in COMMANDS:
    cli.add_command(_command)


#: The environment variables that set the BLAS/OpenMP thread pools (numpy's and scipy's OpenBLAS,
#: MKL, OpenMP), read once when the library loads.
BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded_blas() -> bool:
    """One BLAS/OpenMP thread for the command-line process and the processes it starts (called by
    :func:`main` there only), unless the environment already chooses (any of
    :data:`BLAS_THREAD_VARIABLES` set: all left as they are) or numpy is loaded already (too late
    to matter; the environment is left alone).

    rattle's dense problems are small (2(2H + 1) rows: 130 at H = 32): a thread pool hands them
    out and spins waiting for them for longer than they take. Measured (benchmarks/bench_threads.py,
    2 cores): the reference FRF with Hill's method at H = 32 takes 7.4 s CPU with one thread and
    43 s with two (59 s wall); ``rattle frf`` on the reference case 2.06 s against 2.20 s.
    Returns whether it set them."""
    if "numpy" in sys.modules or any(var in os.environ for var in BLAS_THREAD_VARIABLES):
        return False
    os.environ.update(dict.fromkeys(BLAS_THREAD_VARIABLES, "1"))
    return True


#: The young generation's threshold of the command-line process (Python's default: 700).
GC_THRESHOLD0 = 10_000


def _collect_rarely() -> None:
    """The cyclic garbage collector of the command-line process, tuned for a short run that
    imports much (numpy, scipy, numba, matplotlib: some 10⁶ long-lived objects) and allocates
    few cycles: a young collection every 10,000 allocations instead of 700, so that the imports
    do not pay some 400 collections and three full ones (0.3 s of CPU in ``rattle frf``, 0.1 s
    with this). Cycles are still collected. Called by :func:`main` in the command-line process
    only: a program that imports rattle keeps its own settings."""
    threshold0, threshold1, threshold2 = gc.get_threshold()
    if threshold0:  # 0: the collector was switched off on purpose; leave it so
        gc.set_threshold(max(threshold0, GC_THRESHOLD0), threshold1, threshold2)


def main(argv: Sequence[str] | None = None) -> None:
    """Console entry point ``rattle`` (and ``python -m rattle``); exits with status 0, 1 or 2.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; default ``sys.argv[1:]``.

    In the command-line process (``rattle``, ``python -m rattle``: :mod:`rattle._signals`
    installed its handlers at start), an interrupted run ends at once after its line: the
    finalizers of what an interrupted library call left behind are not waited for (a Dask
    client still connecting to a scheduler that never answered waits 20 s in its ``__del__``);
    rattle's own temporary files and worker processes are gone already (its ``finally`` blocks).
    """
    command_line = _signals.installed_at_start()  # not main() called inside another program
    if command_line:
        single_threaded_blas()
        _collect_rarely()
    code = cli.main(args=list(argv) if argv is not None else None, prog_name="rattle", standalone_mode=False)
    if command_line:
        # Everything alive now lives until the process ends: the interpreter's exit need not
        # search it for garbage cycles (0.45 s of CPU after `rattle frf` with numba, scipy and
        # matplotlib loaded, 0.04 s with this). Finalizers, atexit and the streams' flush run as
        # before.
        gc.freeze()
    if code >= 128 and _signals.interrupted_by() is not None and _signals.installed_at_start():
        _signals.exit_now(code)
    sys.exit(code)
