"""The ``rattle`` command line (SPEC §3): a thin layer over the library.

Exit status: 0 success, 2 bad input (configuration, options, output path), 1 a numerical
failure that could not be recovered, 128 + the signal number when interrupted (130 SIGINT,
143 SIGTERM, 129 SIGHUP). Errors are one line on stderr, ``rattle: error: …``; warnings of the
numerics (numpy's RuntimeWarning …) one line each, ``rattle: warning: …``, never raw.

A front door that answers at once: this module imports click, numpy and the configuration
reader only; the solver (scipy) is imported when a command runs, matplotlib when a figure is
drawn. Every input is validated before that, and nothing is created in the output directory
until there is something to write.

Interrupted runs leave nothing wrong: every command writes its files into a staging folder inside
the output directory and moves them into place together at the end
(:class:`rattle.io.OutputSet`); SIGTERM and SIGHUP are turned into the same clean exit path as
Ctrl-C (an exception, so that every ``finally`` removes its temporary files and stops its worker
processes).
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import math
import os
import signal
import sys
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from ..errors import ConfigError, ConvergenceError, RattleError

if TYPE_CHECKING:  # annotations only: the numpy-based layers are imported when a command runs
    from ..io import AnalysisSettings
    from ..model import Model


def _io() -> Any:
    """``rattle.io`` (numpy, the model and the configuration reader), imported on first use so
    that ``--help``, ``--version`` and options click refuses need none of it."""
    from .. import io

    return io

__all__ = ["cli", "main", "EXIT_OK", "EXIT_NUMERICAL", "EXIT_BAD_INPUT", "DEFAULT_OUTPUT"]

EXIT_OK = 0
EXIT_NUMERICAL = 1
EXIT_BAD_INPUT = 2
#: Output directory when ``-o`` is not given.
DEFAULT_OUTPUT = "rattle-out"

_NoArgsIsHelpError: Any = getattr(click.exceptions, "NoArgsIsHelpError", ())

logger = logging.getLogger("rattle")

#: The files each command writes (its output set: staged and moved into place together; a file
#: of the set that a run does not produce is removed, so no old one stays beside new data).
FRF_FILES = ("frf.csv", "frf.json", "frf.png")
SWEEP_FILES = ("sweep.csv", "sweep.json", "sweep.png")
ORBIT_FILES = ("orbit.csv", "orbit.json", "orbit.png")
COMPARE_FILES = ("frf.csv", "sweep.csv", "compare.json", "compare.png")
#: Longest file name a command writes plus its staging folder and temporary suffix (bytes): the
#: room ``--output`` must leave below the file system's path limit.
_PATH_ROOM = 128


def _error(message: str) -> None:
    click.echo(f"rattle: error: {message}", err=True)


def _warning(message: str) -> None:
    click.echo(f"rattle: warning: {message}", err=True)


# --------------------------------------------------------------------------------------------
# Signals and warnings
# --------------------------------------------------------------------------------------------
class Interrupted(KeyboardInterrupt):
    """SIGTERM or SIGHUP received: raised in the main thread like Ctrl-C's KeyboardInterrupt, so
    that the same ``finally`` blocks remove temporary files and stop worker processes."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


class _Stopped(Exception):
    """An interruption carried through click's main loop (which would turn KeyboardInterrupt into
    a generic "Aborted!")."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _raise_interrupted(signum: int, _frame: object) -> None:
    raise Interrupted(signum)


@contextlib.contextmanager
def _signals_as_exceptions() -> Iterator[None]:
    """SIGTERM and SIGHUP raise :class:`Interrupted` for the body (main thread only; the previous
    handlers come back afterwards, which matters when the CLI runs inside another program)."""
    installed: dict[int, Any] = {}
    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is None:
            continue
        try:
            installed[sig] = signal.signal(sig, _raise_interrupted)
        except ValueError:  # not the main thread: leave the signals alone
            break
    try:
        yield
    finally:
        for sig, old in installed.items():
            with contextlib.suppress(ValueError, TypeError):
                signal.signal(sig, old)


def _signal_name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:  # pragma: no cover
        return f"signal {signum}"


#: Warning lines shown per run; the rest are counted and summarised in one line.
MAX_WARNINGS = 8


@contextlib.contextmanager
def _warnings_as_lines() -> Iterator[None]:
    """Every warning raised during the body reaches the user as one ``rattle: warning: …`` line:
    rattle's own warnings (their message names the key in backticks) as they are; others (numpy's
    "overflow encountered in …") with where they arose (the rattle module and line), what kind
    they are, and what they mean for the run. Each distinct warning once; at most
    ``MAX_WARNINGS`` lines."""
    seen: set[tuple[Any, ...]] = set()
    hidden = 0

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int,
             file: Any = None, line: str | None = None) -> None:
        nonlocal hidden
        key = (category, str(message), filename, lineno)
        if key in seen:
            return
        seen.add(key)
        if len(seen) > MAX_WARNINGS:
            hidden += 1
            return
        text = " ".join(str(message).split())
        if "`" in text:  # one of ours: already says what and why
            _warning(text)
            return
        where = _where(filename, lineno)
        _warning(f"{text} ({category.__name__} at {where}); the run went on, but check the results "
                 "at the frequencies where this happened")

    with warnings.catch_warnings():
        warnings.showwarning = show
        try:
            yield
        finally:
            if hidden:
                _warning(f"{hidden} further warning(s) not shown")


def _where(filename: str, lineno: int) -> str:
    """``rattle/measures.py:141`` for a file of the package; the file name otherwise."""
    parts = Path(filename).parts
    if "rattle" in parts:
        i = len(parts) - 1 - parts[::-1].index("rattle")
        return "/".join(parts[i:]) + f":{lineno}"
    return f"{Path(filename).name}:{lineno}"


def _set_verbose(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    """``-v``: the library's progress (logger ``rattle``, INFO) on stderr as ``rattle: …`` lines."""
    if not value or ctx.resilient_parsing:
        return
    if not any(h.get_name() == "rattle-cli" for h in logger.handlers):
        handler = logging.StreamHandler(sys.stderr)
        handler.set_name("rattle-cli")
        handler.setFormatter(logging.Formatter("rattle: %(message)s"))
        logger.addHandler(handler)
    logger.setLevel(logging.INFO)


def _reset_verbose() -> None:
    for handler in [h for h in logger.handlers if h.get_name() == "rattle-cli"]:
        logger.removeHandler(handler)
    logger.setLevel(logging.NOTSET)


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
            with _signals_as_exceptions(), _warnings_as_lines():
                return self._invoke(args, prog_name, complete_var, **extra)
        except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM/SIGHUP raised as Interrupted
            signum = exc.signum if isinstance(exc, Interrupted) else int(signal.SIGINT)
            _error(f"interrupted by {_signal_name(signum)}; temporary files were removed and no output "
                   "set was left half-written")
            return 128 + signum
        finally:
            _reset_verbose()

    def invoke(self, ctx: click.Context) -> Any:
        # click turns KeyboardInterrupt into Abort (and prints a blank line); keep the signal
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            raise _Stopped(exc.signum if isinstance(exc, Interrupted) else int(signal.SIGINT)) from None

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
            _error(exc.format_message() + hint)
            return int(exc.exit_code)
        except click.ClickException as exc:
            _error(exc.format_message())
            return int(exc.exit_code)
        except click.Abort as exc:
            cause = exc.__cause__ or exc.__context__
            if isinstance(cause, KeyboardInterrupt):  # Ctrl-C while click itself was parsing
                raise Interrupted(cause.signum if isinstance(cause, Interrupted) else int(signal.SIGINT)) from None
            _error("aborted")
            return EXIT_NUMERICAL
        except ConfigError as exc:
            _error(str(exc))
            return EXIT_BAD_INPUT
        except ConvergenceError as exc:
            _error(f"numerical failure: {exc}")
            return EXIT_NUMERICAL
        except RattleError as exc:
            _error(str(exc))
            return EXIT_NUMERICAL
        except ArithmeticError as exc:  # OverflowError, FloatingPointError, ZeroDivisionError
            _error(f"numerical failure: {_one_line(exc)} ({type(exc).__name__}); the model's numbers are "
                   "probably too large or too small for double precision — check their scale")
            return EXIT_NUMERICAL
        except MemoryError:
            _error("numerical failure: out of memory; lower --harmonics, --points or the frequency range")
            return EXIT_NUMERICAL
        except (ValueError, TypeError) as exc:
            if type(exc).__name__ == "LinAlgError":  # numpy.linalg's, without importing numpy here
                _error(f"numerical failure: {_one_line(exc)} (a singular or non-finite linear system)")
                return EXIT_NUMERICAL
            # The library validates its arguments with ValueError/TypeError naming the argument
            # (a combination the CLI's own checks did not anticipate): bad input, not a crash.
            if "`" not in str(exc):
                raise  # not one of our validation messages: a bug, keep the traceback
            _error(str(exc))
            return EXIT_BAD_INPUT
        return rv if isinstance(rv, int) else EXIT_OK


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _print_version(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    if value and not ctx.resilient_parsing:
        from .. import __version__  # the package metadata only, not the numerics

        click.echo(f"rattle {__version__}")
        ctx.exit(EXIT_OK)


def _common_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--version`` and ``-v/--verbose``, on the group and on every command."""
    f = click.option("-v", "--verbose", is_flag=True, expose_value=False, callback=_set_verbose,
                     help="Report progress on stderr.")(f)
    return click.option("--version", is_flag=True, expose_value=False, is_eager=True, callback=_print_version,
                        help="Show the version and exit.")(f)


@click.group(name="rattle", cls=RattleGroup, context_settings={"help_option_names": ["-h", "--help"]})
@_common_options
def cli() -> None:
    """Non-linear frequency response of drivetrain rattle (harmonic balance + continuation).

    Exit status: 0 success, 2 bad input, 1 numerical failure, 130/143 interrupted.
    """


def _output_path(_ctx: click.Context, _param: click.Parameter, value: str) -> Path:
    """``-o``: a non-blank path (``-o ""`` is refused: it would silently mean the current folder)."""
    if not value.strip():
        raise ConfigError(
            f"`--output` must name a folder, got {value!r}; give e.g. -o rattle-out (or -o . for the current folder)"
        )
    return Path(value)


_output_option = click.option(
    "-o", "--output", "output", type=str, default=DEFAULT_OUTPUT, callback=_output_path, metavar="DIR",
    show_default=True, help="Directory for the output files (created if needed).",
)


# --------------------------------------------------------------------------------------------
# Input checks (all before any computation)
# --------------------------------------------------------------------------------------------
def override_analysis(base: AnalysisSettings, model: Model | None = None, **options: Any) -> AnalysisSettings:
    """``base`` with the command-line options that were given (not None) replacing its fields.

    Parameters
    ----------
    base : AnalysisSettings
        Settings from the configuration file.
    model : Model, optional
        When given, the harmonic count is checked against its excitation harmonics.
    **options
        ``harmonics``, ``omega_min``, ``omega_max``; None means "not given".

    Returns
    -------
    AnalysisSettings

    Raises
    ------
    ConfigError
        If the combination breaks a rule; the message names the option (``--omega-min``) or the
        file key (``analysis.omega[1]``) each value came from.
    """
    given = {name: value for name, value in options.items() if value is not None}
    names = {"omega_min": "analysis.omega[0]", "omega_max": "analysis.omega[1]", "harmonics": "analysis.harmonics"}
    names.update({name: "--" + name.replace("_", "-") for name in given})
    try:
        analysis = dataclasses.replace(base, **given)
    except (ValueError, TypeError) as exc:
        raise ConfigError(_io().rename_keys(str(exc), names)) from exc
    if model is not None:
        _io().check_harmonics(model, analysis.harmonics, names["harmonics"])
        if "omega_min" in given or "omega_max" in given:  # the file's own range was checked on loading
            from .. import _limits

            with _as_bad_input():
                _limits.check_frequency_range(model, analysis.omega_min, analysis.omega_max,
                                              (names["omega_min"], names["omega_max"]))
    return analysis


#: File-system types that hold no files a user can keep (kernel interfaces, device nodes):
#: ``-o`` there is refused before computing (as root the permission check would pass).
VIRTUAL_FILESYSTEMS = frozenset({
    "proc", "sysfs", "devtmpfs", "devpts", "cgroup", "cgroup2", "debugfs", "tracefs", "securityfs", "pstore",
    "bpf", "configfs", "fusectl", "mqueue", "binfmt_misc", "autofs", "efivarfs", "selinuxfs", "hugetlbfs",
    "rpc_pipefs", "nsfs", "nfsd",
})
#: Path prefixes that are virtual on every Linux system (also when /proc/self/mountinfo is unreadable).
_VIRTUAL_ROOTS = ("/proc", "/sys", "/dev")
_REAL_UNDER_VIRTUAL = ("/dev/shm",)  # an ordinary tmpfs below /dev


def _mount_type(path: str) -> str | None:
    """The file-system type of the mount holding ``path`` (an absolute, resolved path), from
    /proc/self/mountinfo; None where that is unavailable."""
    try:
        with open("/proc/self/mountinfo", encoding="utf-8", errors="replace") as fh:
            lines = fh.read().splitlines()
    except OSError:
        return None
    best, fstype = "", None
    for line in lines:
        left, _, right = line.partition(" - ")
        fields = left.split()
        if len(fields) < 5 or not right:
            continue
        mount = fields[4].replace("\\040", " ").replace("\\011", "\t").replace("\\134", "\\")
        inside = path == mount or path.startswith(mount.rstrip("/") + "/")
        if inside and len(mount) >= len(best):
            best, fstype = mount, right.split()[0]
    return fstype


def _limit(path: Path, name: str, default: int) -> int:
    try:
        value = os.pathconf(path, name)
    except (OSError, ValueError, AttributeError):
        return default
    return value if value and value > 0 else default


def check_output_dir(output: Path) -> None:
    """Refuse an output path that cannot become a writable directory, without creating anything.

    The rules, in order: not blank (checked when the option is read); no name component longer
    than the file system allows (``PC_NAME_MAX``, usually 255 bytes) and the whole path short
    enough to hold the staging folder and file names below ``PC_PATH_MAX``; no broken symbolic
    link on the way; an existing ``output`` is a directory; the nearest existing ancestor is a
    directory we may write in; not on a virtual file system (/proc, /sys, /dev, cgroup …).

    Raises
    ------
    ConfigError
        Naming ``--output``, the value and the rule broken.
    """
    shown = str(output)
    if len(shown) > 80:
        shown = shown[:60] + "…" + shown[-15:]
    absolute = Path(os.path.abspath(output))

    def as_given(p: Path) -> str:  # a path on the way, spelled as the user wrote --output
        if not output.is_absolute():
            with contextlib.suppress(ValueError):
                return str(p.relative_to(Path(os.path.abspath("."))))
        return str(p)

    # Walk down from the root: every name must fit the file system, the existing part must be
    # directories (no file, no broken link on the way), the rest is created by the run. os.path's
    # predicates are used because they answer False instead of raising on a too-long name.
    ancestor = Path(absolute.anchor or "/")
    existing = True
    name_max = _limit(ancestor, "PC_NAME_MAX", 255)
    for part in absolute.parts[1:]:
        size = len(os.fsencode(part))
        if size > name_max:
            part_shown = part if len(part) <= 40 else part[:30] + "…"
            raise ConfigError(
                f"`--output` has a folder name of {size} bytes ({part_shown!r}), more than the {name_max} "
                "this file system allows; use a shorter name"
            )
        if not existing:
            continue
        candidate = ancestor / part
        if os.path.isdir(candidate):
            ancestor = candidate
            name_max = _limit(ancestor, "PC_NAME_MAX", name_max)
        elif os.path.lexists(candidate):
            if os.path.islink(candidate) and not os.path.exists(candidate):
                raise ConfigError(
                    f"`--output` {shown!r}: {as_given(candidate)!r} is a broken symbolic link; remove it or choose "
                    "another path"
                )
            if candidate == absolute:
                raise ConfigError(
                    f"`--output` must be a directory, got {shown!r}, which is an existing file; choose another path"
                )
            raise ConfigError(
                f"`--output` {shown!r} cannot be created because {as_given(candidate)!r} is a file, "
                "not a directory; choose another path"
            )
        else:
            existing = False
    path_max = _limit(ancestor, "PC_PATH_MAX", 4096)
    size = len(os.fsencode(str(absolute)))
    if size + _PATH_ROOM > path_max:
        raise ConfigError(
            f"`--output` is a path of {size} bytes; with the file names below it, it must stay under the "
            f"{path_max} bytes this file system allows (at most {path_max - _PATH_ROOM}); use a shorter path"
        )
    resolved = os.path.realpath(ancestor)
    virtual_root = any(resolved == r or resolved.startswith(r + "/") for r in _VIRTUAL_ROOTS) and not any(
        resolved == r or resolved.startswith(r + "/") for r in _REAL_UNDER_VIRTUAL)
    fstype = _mount_type(resolved) if sys.platform.startswith("linux") else None
    if virtual_root or fstype in VIRTUAL_FILESYSTEMS:
        kind = f"a {fstype} file system" if fstype in VIRTUAL_FILESYSTEMS else "a virtual file system"
        raise ConfigError(
            f"`--output` {shown!r} lies on {kind} ({resolved}), which cannot hold output files; "
            "choose a folder on a disk"
        )
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ConfigError(
            f"`--output` {shown!r}: no permission to write in {str(ancestor)!r}; "
            "choose a writable directory"
        )


def precheck(config: Path | None, output: Path, *, harmonics: int | None = None, points: int | None = None,
             workers: int | None = None) -> None:
    """The checks that need neither numpy nor the model, first, so that a refusal answers at once:
    the configuration file is an existing regular file within the size limit (from ``stat``), the
    options' bounds (``rattle._limits``), the output folder."""
    if config is not None:
        from ..io._read import check_input_file  # no numpy

        check_input_file(config)
    if harmonics is not None:
        from .. import _limits

        with _as_bad_input():
            _limits.check_harmonics(harmonics, "--harmonics")
    if points is not None:
        check_points(points)
    if workers is not None:
        check_workers(workers)
    check_output_dir(output)


# --------------------------------------------------------------------------------------------
# Running and writing
# --------------------------------------------------------------------------------------------
def _save_figure(draw: Callable[[], tuple[Any, Any]], path: Path) -> bool:
    """Call ``draw()`` (returns (figure, axes)) and save the figure atomically as PNG; False
    without matplotlib."""
    try:
        import matplotlib
    except ImportError:
        _warning(f"matplotlib is not installed, so {path.name} was not written (pip install matplotlib)")
        return False
    matplotlib.use("Agg")  # never open a window from the command line
    import matplotlib.pyplot as plt

    fig, _ax = draw()
    try:
        with _io().atomic_path(path) as tmp:
            fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=150)
    finally:
        plt.close(fig)
    return True


def _save_plot(result: Any, path: Path) -> bool:
    """Draw ``result`` with its ``.plot()`` and save it atomically as PNG; False without matplotlib."""
    return _save_figure(result.plot, path)


Writer = Callable[[Path], Any]


def write_set(output: Path, names: Sequence[str], steps: Sequence[tuple[str, Writer]]) -> list[str]:
    """Write one output set: each ``(name, writer)`` writes ``name`` into a staging folder inside
    ``output``, then all are moved into place together (:class:`rattle.io.OutputSet`); return
    the names written.

    ``names`` is the command's whole set: a file of it that this run does not write (a writer
    returning False, e.g. no matplotlib) is removed from ``output`` at the move, so that an old
    file never sits beside new ones. Any exception (KeyboardInterrupt, a numerical error while
    drawing) leaves ``output`` as it was: the staging folder is removed, and so are the folders
    the run created.
    """
    try:
        with _io().OutputSet(output, names) as staged:
            logger.info("staging %s in %s", ", ".join(n for n, _ in steps), staged.staging)
            for name, writer in steps:
                logger.info("writing %s", name)
                writer(staged.path(name))
            written = staged.commit()
    except OSError as exc:
        where = f"{exc.filename}" if exc.filename else str(output)
        raise click.ClickException(f"cannot write {where}: {exc.strerror or exc}") from exc
    logger.info("moved %s into %s", ", ".join(written), output)
    return written


def _frf_steps(result: Any, sections: dict[str, Any], t_start: float) -> list[tuple[str, Writer]]:
    """Writers of ``frf.csv``, ``frf.json`` and ``frf.png`` (the data first, the figure last)."""
    meta = dict(result.metadata())
    timings = dict(meta.pop("timings", None) or {})

    def write_json(path: Path) -> None:
        _io().write_metadata(path, **{**meta, **sections,
                                "timings": {**timings, "cli_wall_time": time.perf_counter() - t_start}})

    return [("frf.csv", result.to_csv), ("frf.json", write_json), ("frf.png", lambda path: _save_plot(result, path))]


def _write_frf(result: Any, output: Path, sections: dict[str, Any], t_start: float,
               names: Sequence[str] = FRF_FILES) -> list[str]:
    """Write ``frf.csv``, ``frf.json`` and ``frf.png`` into ``output`` as one set (``names``: the
    command's whole set, see :func:`write_set`); return the names written."""
    return write_set(output, names, _frf_steps(result, sections, t_start))


def _compute_frf(
    model: Model, analysis: AnalysisSettings, output: Path, sections: dict[str, Any], t_start: float,
    *, subharmonics: bool = False, names: Sequence[str] = FRF_FILES,
) -> Any:
    """The frequency response; on a numerical failure the points computed before it are
    written (frf.csv, frf.json, frf.png, as the command's whole set ``names``: files of an
    earlier run that the partial set does not replace are removed) and the error re-raised
    naming the files."""
    from ..analysis import frequency_response  # only now: all input has been validated

    extra = {"subharmonics": True} if subharmonics else {}
    logger.info("computing the frequency response over %g … %g rad/s with %d harmonics",
                analysis.omega_min, analysis.omega_max, analysis.harmonics)
    try:
        return frequency_response(model, omega=analysis.omega, harmonics=analysis.harmonics, throw=True, **extra)
    except (ConvergenceError, ArithmeticError) as exc:
        partial = getattr(exc, "partial", None)
        if partial is None or not len(partial):
            raise
        reason = str(exc) if isinstance(exc, ConvergenceError) else f"{_one_line(exc)} ({type(exc).__name__})"
        try:
            written = _write_frf(partial, output, sections, t_start, names)
        except click.ClickException as write_error:
            raise ConvergenceError(
                f"{reason}; the points computed before the failure could not be saved: "
                f"{write_error.format_message()}",
                partial=partial,
            ) from exc
        click.echo(partial.summary())
        raise ConvergenceError(
            f"{reason}; the points computed before the failure were written to "
            f"{', '.join(str(output / name) for name in written)}",
            partial=partial,
        ) from exc


def run_frf(
    model: Model, analysis: AnalysisSettings, output: Path, sections: dict[str, Any], *, subharmonics: bool = False
) -> None:
    """Compute the frequency response, write the three files and print the summary.

    Parameters
    ----------
    model : Model
    analysis : AnalysisSettings
        Frequency range and harmonics.
    output : pathlib.Path
        Output directory (checked with :func:`check_output_dir` beforehand).
    sections : dict
        Extra metadata sections for ``frf.json`` (``config``, ``command``, …).
    subharmonics : bool, default False
        Also follow the period-doubled branches (every branch goes into the files).

    Raises
    ------
    ConvergenceError
        When the continuation failed; the points computed before the failure are written first
        when the error carries them in ``.partial``.
    """
    t_start = time.perf_counter()
    result = _compute_frf(model, analysis, output, sections, t_start, subharmonics=subharmonics)
    written = _write_frf(result, output, sections, t_start)
    click.echo(result.summary())
    click.echo(f"wrote {', '.join(written)} to {output}")


# --------------------------------------------------------------------------------------------
# Commands
# --------------------------------------------------------------------------------------------
@cli.command("frf", short_help="Frequency response of the model in a configuration file.")
@_common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--harmonics", type=int, default=None, metavar="H",
              help="Harmonics kept in the harmonic balance (>= 1); overrides analysis.harmonics.")
@click.option("--omega-min", type=float, default=None, metavar="X",
              help="Lower forcing frequency in rad/s (> 0); overrides analysis.omega[0].")
@click.option("--omega-max", type=float, default=None, metavar="Y",
              help="Upper forcing frequency in rad/s (> omega-min); overrides analysis.omega[1].")
@click.option("--subharmonics", is_flag=True, default=False,
              help="Also follow the sub-harmonic (period-doubled) branches born at every period-doubling "
                   "point; all branches go into frf.csv (columns branch, period) and frf.png.")
def frf_command(
    config: Path, output: Path, harmonics: int | None, omega_min: float | None, omega_max: float | None,
    subharmonics: bool,
) -> None:
    """Frequency response of the model in CONFIG: frf.csv, frf.png, frf.json in OUTPUT.

    With --subharmonics every period-doubling point found on the primary branch starts a
    period-2 branch (and so on, up to period 4); each branch has its colour in frf.png.
    """
    precheck(config, output, harmonics=harmonics)
    run_config = _io().load_config(config)
    analysis = override_analysis(
        run_config.analysis, run_config.model, harmonics=harmonics, omega_min=omega_min, omega_max=omega_max
    )
    options = {"harmonics": harmonics, "omega_min": omega_min, "omega_max": omega_max,
               "subharmonics": True if subharmonics else None}
    run_frf(
        run_config.model, analysis, output,
        {
            "command": "frf",
            "config_file": os.fspath(config),
            "config": run_config.source,
            "options": {k: v for k, v in options.items() if v is not None},
            "analysis": analysis.to_dict(),
        },
        subharmonics=subharmonics,
    )


# --------------------------------------------------------------------------------------------
# Time-domain commands: sweep, orbit, compare
# --------------------------------------------------------------------------------------------
#: Largest period (multiple of the forcing period) that ``rattle orbit --period`` accepts.
MAX_PERIOD = 8
_DIRECTIONS = ("up", "down", "both")

_harmonics_option = click.option(
    "--harmonics", type=int, default=None, metavar="H",
    help="Harmonics kept in the harmonic balance (>= 1); overrides analysis.harmonics.",
)
_omega_min_option = click.option(
    "--omega-min", type=float, default=None, metavar="X",
    help="Lower forcing frequency in rad/s (> 0); overrides analysis.omega[0].",
)
_omega_max_option = click.option(
    "--omega-max", type=float, default=None, metavar="Y",
    help="Upper forcing frequency in rad/s (> omega-min); overrides analysis.omega[1].",
)
_quiet_option = click.option(
    "-q", "--quiet", is_flag=True,
    help="No progress bar (there is none anyway when stderr is not a terminal).",
)


@contextlib.contextmanager
def _as_bad_input() -> Iterator[None]:
    """The library's argument checks (ValueError/TypeError naming the argument) as ConfigError."""
    try:
        yield
    except (ValueError, TypeError) as exc:
        if isinstance(exc, ConfigError):
            raise
        raise ConfigError(str(exc)) from exc


def check_points(points: int) -> int:
    """``--points`` N: an integer 2 … ``rattle._limits.MAX_SWEEP_POINTS`` (the library's rule)."""
    if points < 2:
        raise ConfigError(
            f"`--points` must be an integer >= 2 (frequencies per sweep direction), got {points}; use e.g. 200"
        )
    from .. import _limits

    with _as_bad_input():
        return _limits.check_points(points, "--points")


def check_workers(workers: int) -> int:
    """``--workers``: an integer 1 … ``rattle._limits.MAX_WORKERS`` (2 runs the up and down sweeps at once)."""
    if workers < 1:
        raise ConfigError(f"`--workers` must be an integer >= 1, got {workers}; use 1 (serial) or 2")
    from .. import _limits

    with _as_bad_input():
        return _limits.check_workers(workers, "--workers")


def check_omega(omega: float, option: str = "--omega", model: Model | None = None) -> float:
    """A forcing frequency given on the command line: finite and > 0 rad/s, and with ``model``
    within the library's bounds relative to its stiffest stage (``rattle._limits``)."""
    if not (math.isfinite(omega) and omega > 0.0):
        raise ConfigError(f"`{option}` must be a finite forcing frequency > 0 rad/s, got {omega!r}; use e.g. 0.8")
    if model is not None:
        from .. import _limits

        with _as_bad_input():
            _limits.check_frequency(model, omega, option)
    return omega


def check_period(period: int, harmonics: int, forced: int) -> int:
    """``--period`` N: an integer 1 … 8 that the harmonic balance can hold with ``harmonics``."""
    if not 1 <= period <= MAX_PERIOD:
        raise ConfigError(
            f"`--period` must be an integer 1 … {MAX_PERIOD} (multiple of the forcing period), got {period}; "
            "use 1 for the primary response, n for a 1/n sub-harmonic"
        )
    if harmonics < forced * period:
        raise ConfigError(
            f"`--harmonics` must be >= {forced * period} to hold the excitation's harmonic {forced} at "
            f"`--period` {period}, got {harmonics}; raise `--harmonics`"
        )
    return period


def parse_at(text: str | None, omega_min: float, omega_max: float) -> list[float] | None:
    """``--at W1,W2,…``: comma-separated frequencies within the analysis range (rad/s)."""
    if text is None:
        return None
    parts = [p.strip() for p in text.split(",")]
    if not parts or any(not p for p in parts):
        raise ConfigError(f"`--at` must be a comma-separated list of frequencies such as 0.8,1.4, got {text!r}")
    values = []
    for part in parts:
        try:
            value = float(part)
        except ValueError:
            raise ConfigError(f"`--at` must hold numbers (rad/s), got {part!r} in {text!r}") from None
        if not (math.isfinite(value) and omega_min <= value <= omega_max):
            raise ConfigError(
                f"`--at` frequencies must be finite and within the analysis range {omega_min:g} … "
                f"{omega_max:g} rad/s, got {part!r}; choose frequencies inside the range or widen it"
            )
        values.append(value)
    return values


class _ProgressBar:
    """``callback(done, total)`` drawing a tqdm bar on stderr; a no-op when stderr is not a
    terminal, with ``--quiet``, or without tqdm. The library never draws one itself."""

    def __init__(self, description: str, enabled: bool) -> None:
        self.description = description
        self.enabled = enabled and sys.stderr.isatty()
        self._bar: Any = None

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self._bar is None:
            try:
                from tqdm import tqdm
            except ImportError:  # pragma: no cover - tqdm is a dependency
                self.enabled = False
                return
            self._bar = tqdm(total=total, desc=self.description, unit="Ω", file=sys.stderr, leave=False,
                             dynamic_ncols=True)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def _metadata_writer(meta: dict[str, Any], sections: dict[str, Any], t_start: float) -> Any:
    def write(path: Path) -> None:
        doc = dict(meta)
        timings = dict(doc.pop("timings", None) or {})
        timings["cli_wall_time"] = time.perf_counter() - t_start
        _io().write_metadata(path, **{**doc, **sections, "timings": timings})

    return write


def _sections(command: str, config: Path, run_config: Any, analysis: AnalysisSettings, options: dict[str, Any]) -> dict[str, Any]:
    return {
        "command": command,
        "config_file": os.fspath(config),
        "config": run_config.source,
        "options": {k: v for k, v in options.items() if v is not None},
        "analysis": analysis.to_dict(),
    }


@cli.command("sweep", short_help="Time-domain frequency sweep (steady state at each frequency).")
@_common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--direction", type=click.Choice(_DIRECTIONS), default=None,
              help="Required: sweep up (run-up), down (run-down) or both, the state carried from each "
                   "frequency to the next.")
@click.option("--points", type=int, default=200, show_default=True, metavar="N",
              help="Equally spaced frequencies per direction (>= 2).")
@click.option("--workers", type=int, default=1, show_default=True, metavar="W",
              help="Processes: 2 runs the up and down sweeps of --direction both at once.")
@_omega_min_option
@_omega_max_option
@_quiet_option
def sweep_command(
    config: Path, output: Path, direction: str | None, points: int, workers: int,
    omega_min: float | None, omega_max: float | None, quiet: bool,
) -> None:
    """Time-domain frequency sweep of the model in CONFIG: sweep.csv, sweep.png, sweep.json in OUTPUT.

    At N equally spaced frequencies the motion is simulated exactly until it settles (period
    1 … 8 of the forcing period, or 0 when none is found), the state carried from one frequency
    to the next as in a run-up or run-down.
    """
    if direction is None:  # checked here: click's own message for a missing choice spans lines
        raise ConfigError("`--direction` is required: give --direction up, down or both")
    precheck(config, output, points=points, workers=workers)
    run_config = _io().load_config(config)
    analysis = override_analysis(run_config.analysis, run_config.model, omega_min=omega_min, omega_max=omega_max)
    t_start = time.perf_counter()
    from ..analysis import time_sweep  # only now: all input has been validated

    bar = _ProgressBar(f"sweep {direction}", enabled=not quiet)
    try:
        result = time_sweep(run_config.model, omega=analysis.omega, points=points, direction=direction,
                            workers=workers, callback=bar)
    finally:
        bar.close()
    sections = _sections("sweep", config, run_config, analysis, {
        "direction": direction, "points": points, "workers": workers,
        "omega_min": omega_min, "omega_max": omega_max,
    })
    written = write_set(output, SWEEP_FILES, [
        ("sweep.csv", result.to_csv),
        ("sweep.json", _metadata_writer(result.metadata(), sections, t_start)),
        ("sweep.png", lambda path: _save_plot(result, path)),
    ])
    click.echo(result.summary())
    click.echo(f"wrote {', '.join(written)} to {output}")


@cli.command("orbit", short_help="Every periodic orbit at one forcing frequency, against the simulation.")
@_common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--omega", "omega", type=float, required=True, metavar="W",
              help="Forcing frequency in rad/s (finite, > 0).")
@click.option("--period", type=int, default=1, show_default=True, metavar="N",
              help=f"Period of the orbit as a multiple of the forcing period, 1 … {MAX_PERIOD} (N: a 1/N sub-harmonic).")
@_harmonics_option
@_omega_min_option
@_omega_max_option
def orbit_command(
    config: Path, output: Path, omega: float, period: int, harmonics: int | None,
    omega_min: float | None, omega_max: float | None,
) -> None:
    """Periodic orbits at the forcing frequency W for the model in CONFIG: orbit.csv, orbit.png,
    orbit.json in OUTPUT.

    Every coexisting harmonic-balance solution at W is found (the primary branch is followed over
    the analysis range, widened to include W; sub-harmonics are seeded from a simulation) and its
    stability computed. orbit.csv holds t, delta, velocity, acceleration over one period of the
    selected solution: the stable one closest in rms to the simulated steady state (preferring
    the requested period); orbit.json lists them all.
    """
    check_omega(omega)
    precheck(config, output, harmonics=harmonics)
    run_config = _io().load_config(config)
    analysis = override_analysis(
        run_config.analysis, run_config.model, harmonics=harmonics, omega_min=omega_min, omega_max=omega_max
    )
    check_omega(omega, model=run_config.model)
    check_period(period, analysis.harmonics, len(run_config.model.excitation.amplitudes))
    t_start = time.perf_counter()
    from ..analysis import periodic_orbit  # only now: all input has been validated

    result = periodic_orbit(run_config.model, omega, period=period, harmonics=analysis.harmonics,
                            search_range=analysis.omega)
    sections = _sections("orbit", config, run_config, analysis, {
        "omega": omega, "period": period, "harmonics": harmonics,
        "omega_min": omega_min, "omega_max": omega_max,
    })
    written = write_set(output, ORBIT_FILES, [
        ("orbit.csv", result.to_csv),
        ("orbit.json", _metadata_writer(result.metadata(), sections, t_start)),
        ("orbit.png", lambda path: _save_plot(result, path)),
    ])
    click.echo(result.summary())
    click.echo(f"wrote {', '.join(written)} to {output}")


@cli.command("compare", short_help="Frequency response and time-domain sweep together.")
@_common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--points", type=int, default=200, show_default=True, metavar="N",
              help="Equally spaced frequencies per sweep direction (>= 2).")
@click.option("--at", "at", type=str, default=None, metavar="W1,W2,...",
              help="Frequencies (rad/s) for the time-history panels; default: picked automatically "
                   "(one in the multi-valued region, one where the sweep is not period 1).")
@click.option("--workers", type=int, default=1, show_default=True, metavar="W",
              help="Processes for the sweep: 2 runs the up and down sweeps at once.")
@_harmonics_option
@_omega_min_option
@_omega_max_option
@_quiet_option
def compare_command(
    config: Path, output: Path, points: int, at: str | None, workers: int, harmonics: int | None,
    omega_min: float | None, omega_max: float | None, quiet: bool,
) -> None:
    """Frequency response against the up/down time-domain sweep for the model in CONFIG:
    compare.png, frf.csv, sweep.csv, compare.json in OUTPUT."""
    precheck(config, output, harmonics=harmonics, points=points, workers=workers)
    run_config = _io().load_config(config)
    analysis = override_analysis(
        run_config.analysis, run_config.model, harmonics=harmonics, omega_min=omega_min, omega_max=omega_max
    )
    at_values = parse_at(at, analysis.omega_min, analysis.omega_max)
    t_start = time.perf_counter()
    from ..analysis import compare  # only now: all input has been validated

    bar = _ProgressBar("sweep up+down", enabled=not quiet)
    try:
        result = compare(run_config.model, omega=analysis.omega, harmonics=analysis.harmonics, points=points,
                         at=at_values, workers=workers, callback=bar)
    finally:
        bar.close()
    sections = _sections("compare", config, run_config, analysis, {
        "points": points, "at": at_values, "workers": workers, "harmonics": harmonics,
        "omega_min": omega_min, "omega_max": omega_max,
    })
    written = write_set(output, COMPARE_FILES, [
        ("frf.csv", result.frf.to_csv),
        ("sweep.csv", result.sweep.to_csv),
        ("compare.json", _metadata_writer(result.metadata(), sections, t_start)),
        ("compare.png", lambda path: _save_plot(result, path)),
    ])
    click.echo(result.summary())
    click.echo(f"wrote {', '.join(written)} to {output}")


# --------------------------------------------------------------------------------------------
# rattle demo: the paper's reference case end to end
# --------------------------------------------------------------------------------------------
#: The demo's frequency range (rad/s), harmonics and sweep frequencies per direction.
DEMO_OMEGA = (0.1, 3.0)
DEMO_HARMONICS = 32
DEMO_POINTS = 200
#: Processes for the demo's sweep: the up and down sweeps run at once.
DEMO_WORKERS = 2
#: The paper's points A (Figure 6) and B (Figure 7), rad/s.
DEMO_POINT_A = 0.44
DEMO_POINT_B = 1.41
#: Files of the demo's figures, by report key.
DEMO_FIGURES = {
    "frf": "frf.png",
    "fig4": "fig4_linear_vs_nonlinear.png",
    "fig5": "fig5_hbm_vs_simulation.png",
    "fig6": "fig6_point_A.png",
    "fig7": "fig7_point_B.png",
    "mean": "fig_mean_operating_point.png",
}
DEMO_REPORT = "report.md"
#: Every file of the demo: its output set.
DEMO_FILES = ("frf.csv", "sweep.csv", "frf.json", *DEMO_FIGURES.values(), DEMO_REPORT)


def _draw_demo_figure(key: str, frf: Any, sweep: Any, orbits: dict[str, Any], level: Any) -> Callable[[], Any]:
    """The drawing function of one demo figure (imports the plotting layer lazily)."""

    def draw() -> Any:
        from ..plotting import (
            frequency_response_plot, hbm_vs_simulation_plot, linear_vs_nonlinear_plot, mean_operating_point_plot,
            point_plot,
        )

        if key == "frf":
            return frequency_response_plot(frf)
        if key == "fig4":
            return linear_vs_nonlinear_plot(frf, level)
        if key == "fig5":
            return hbm_vs_simulation_plot(frf, sweep)
        if key == "fig6":
            orbit = orbits["A"]
            p = orbit.simulated_period
            note = ("(the paper reported quasi-periodic motion at A; the exact simulation and the harmonic balance "
                    f"agree on period {p})") if p and p > 1 else "(the paper reported quasi-periodic motion at A)"
            return point_plot(orbit, name="A", note=note)
        if key == "fig7":
            return point_plot(orbits["B"], name="B",
                              note="(the paper: a sub-harmonic peak near Ω = 1.4, HB and simulation match exactly)")
        return mean_operating_point_plot(frf)

    return draw


@cli.command("demo", short_help="The paper's reference case end to end, with its figures and a report.")
@_common_options
@_output_option
@click.option("-q", "--quiet", is_flag=True,
              help="No progress bar (there is none anyway when stderr is not a terminal).")
def demo_command(output: Path, quiet: bool) -> None:
    """The paper's reference case end to end: clutch α = 0.25, b = 10°, ζ = 0.025, F_m = 0.05,
    F_p1 = 0.03 over Ω = 0.1 … 3.0 rad/s with 32 harmonics.

    Computes the frequency response with its sub-harmonic branches, a time-domain sweep up and
    down (200 frequencies each way) and the orbits at the paper's points A (Ω = 0.44) and B
    (Ω = 1.41), and writes into OUTPUT: frf.csv, frf.json, frf.png, sweep.csv, the paper's
    figures (fig4_linear_vs_nonlinear.png, fig5_hbm_vs_simulation.png, fig6_point_A.png,
    fig7_point_B.png, fig_mean_operating_point.png) and report.md, which collects them with
    the computed numbers.
    """
    precheck(None, output)
    from ..model import reference_case

    t_start = time.perf_counter()
    model = reference_case()
    analysis = _io().AnalysisSettings(omega_min=DEMO_OMEGA[0], omega_max=DEMO_OMEGA[1], harmonics=DEMO_HARMONICS)
    click.echo(
        "rattle demo: the paper's reference case — clutch alpha = 0.25, b = 10 deg, zeta = 0.025, "
        f"F_m = 0.05, F_p1 = 0.03; Omega = {analysis.omega_min} … {analysis.omega_max} rad/s, "
        f"H = {analysis.harmonics}, sub-harmonic branches on; sweep up and down, {DEMO_POINTS} points each"
    )
    sections: dict[str, Any] = {
        "command": "demo", "config": _io().model_to_toml_dict(model, analysis), "analysis": analysis.to_dict(),
        "options": {"subharmonics": True, "points": DEMO_POINTS, "workers": DEMO_WORKERS},
    }
    timings: dict[str, float] = {}

    # --- computation ---------------------------------------------------------------------------
    t0 = time.perf_counter()
    frf = _compute_frf(model, analysis, output, sections, t_start, subharmonics=True, names=DEMO_FILES)
    timings["frf"] = time.perf_counter() - t0

    from ..analysis import confirm_with_sweep, periodic_orbit, time_sweep
    from ..report import level_difference

    t0 = time.perf_counter()
    bar = _ProgressBar("sweep up+down", enabled=not quiet)
    try:
        sweep = time_sweep(model, omega=analysis.omega, points=DEMO_POINTS, direction="both",
                           workers=DEMO_WORKERS, callback=bar)
    finally:
        bar.close()
    timings["sweep"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    orbits = {
        name: periodic_orbit(model, w, period=2, harmonics=analysis.harmonics, frf=frf)
        for name, w in (("A", DEMO_POINT_A), ("B", DEMO_POINT_B))
    }
    timings["orbits"] = time.perf_counter() - t0
    regions = confirm_with_sweep(frf.regions, sweep)
    level = level_difference(frf)

    # --- output: data first, then the figures, then the report --------------------------------
    meta = dict(frf.metadata())
    frf_timings = dict(meta.pop("timings", None) or {})
    demo_section = {
        "regions_confirmed_by_sweep": [g.to_dict() for g in regions],
        "sweep": sweep.metadata(),
        "orbits": {name: {"omega": o.omega, **o.metadata()} for name, o in orbits.items()},
        "level_difference": {
            "quantity": "20 log10(acc_p2p non-linear / acc_p2p linear), stable solutions",
            "band": list(level.band), "db_min": level.db_min, "omega_at_min": level.omega_at_min,
            "db_max": level.db_max, "omega_at_max": level.omega_at_max,
            "single_valued": list(level.single_valued_range()),
        },
    }

    def write_json(path: Path) -> None:
        wall = {**frf_timings, **{f"demo_{k}": v for k, v in timings.items()},
                "cli_wall_time": time.perf_counter() - t_start}
        _io().write_metadata(path, **{**meta, **sections, "demo": demo_section, "timings": wall})

    from ..report import demo_report

    figures: dict[str, str] = {}

    def write_figure(key: str, path: Path) -> bool:
        done = _save_figure(_draw_demo_figure(key, frf, sweep, orbits, level), path)
        if done:
            figures[key] = path.name
        return done

    def write_report(path: Path) -> None:
        timings["figures"] = time.perf_counter() - t_figures
        timings["total"] = time.perf_counter() - t_start
        text = demo_report(frf, sweep, orbits=orbits, level=level, figures=figures, regions=regions,
                           timings=timings, data_files=["frf.csv", "frf.json", "sweep.csv"],
                           version=_io().rattle_version())
        _io().atomic_write_text(path, text)

    t_figures = time.perf_counter()
    written = write_set(output, DEMO_FILES, [
        ("frf.csv", frf.to_csv), ("sweep.csv", sweep.to_csv), ("frf.json", write_json),
        *[(name, lambda path, k=key: write_figure(k, path)) for key, name in DEMO_FIGURES.items()],
        (DEMO_REPORT, write_report),
    ])

    click.echo(frf.summary())
    click.echo(sweep.summary())
    for name, orbit in orbits.items():
        sim = orbit.simulated_period
        click.echo(f"point {name} (Omega = {orbit.omega:g}): simulation "
                   + (f"period {sim}" if sim else "no period <= 8")
                   + "; HB: " + ", ".join(f"P{s.period} {'stable' if s.stable else 'unstable'} rms {s.rms:.4g}"
                                         for s in orbit.solutions))
    click.echo("linear vs non-linear: " + level.summary())
    click.echo("time: " + ", ".join(f"{k} {v:.2f} s" for k, v in timings.items()))
    click.echo(f"wrote {len(written)} files to {output}: {', '.join(written)}")


def main(argv: Sequence[str] | None = None) -> None:
    """Console entry point ``rattle`` (and ``python -m rattle``); exits with status 0, 1 or 2.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; default ``sys.argv[1:]``.
    """
    cli.main(args=list(argv) if argv is not None else None, prog_name="rattle")


if __name__ == "__main__":  # pragma: no cover
    main()
