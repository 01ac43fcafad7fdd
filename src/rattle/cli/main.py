"""The ``rattle`` command line (SPEC §3): a thin layer over the library.

Exit status: 0 success, 2 bad input (configuration, options, output path), 1 a numerical
failure that could not be recovered. Errors are one line on stderr, ``rattle: error: …``.

Every input is validated before the solver is imported, and nothing is created in the output
directory until there is something to write; every file is written atomically.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import click

from ..errors import ConfigError, ConvergenceError, RattleError
from ..io import (
    AnalysisSettings,
    atomic_path,
    check_harmonics,
    atomic_write_text,
    load_config,
    model_to_toml_dict,
    rattle_version,
    rename_keys,
    write_metadata,
)
from ..model import Model

__all__ = ["cli", "main", "EXIT_OK", "EXIT_NUMERICAL", "EXIT_BAD_INPUT", "DEFAULT_OUTPUT"]

EXIT_OK = 0
EXIT_NUMERICAL = 1
EXIT_BAD_INPUT = 2
#: Output directory when ``-o`` is not given.
DEFAULT_OUTPUT = "rattle-out"

_NoArgsIsHelpError: Any = getattr(click.exceptions, "NoArgsIsHelpError", ())


def _error(message: str) -> None:
    click.echo(f"rattle: error: {message}", err=True)


def _warning(message: str) -> None:
    click.echo(f"rattle: warning: {message}", err=True)


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
            rv = super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
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
        except click.Abort:
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
        except (ValueError, TypeError) as exc:
            # The library validates its arguments with ValueError/TypeError naming the argument
            # (a combination the CLI's own checks did not anticipate): bad input, not a crash.
            if "`" not in str(exc):
                raise  # not one of our validation messages: a bug, keep the traceback
            _error(str(exc))
            return EXIT_BAD_INPUT
        return rv if isinstance(rv, int) else EXIT_OK


def _print_version(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    if value and not ctx.resilient_parsing:
        click.echo(f"rattle {rattle_version()}")
        ctx.exit(EXIT_OK)


@click.group(name="rattle", cls=RattleGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--version", is_flag=True, expose_value=False, is_eager=True, callback=_print_version,
              help="Show the version and exit.")
@click.option("-v", "--verbose", is_flag=True, help="Report progress on stderr.")
def cli(verbose: bool) -> None:
    """Non-linear frequency response of drivetrain rattle (harmonic balance + continuation).

    Exit status: 0 success, 2 bad input, 1 numerical failure.
    """
    if verbose:
        logger = logging.getLogger("rattle")
        if not any(h.get_name() == "rattle-cli" for h in logger.handlers):
            handler = logging.StreamHandler(sys.stderr)
            handler.set_name("rattle-cli")
            handler.setFormatter(logging.Formatter("rattle: %(message)s"))
            logger.addHandler(handler)
        logger.setLevel(logging.INFO)


_output_option = click.option(
    "-o", "--output", "output", type=click.Path(path_type=Path), default=DEFAULT_OUTPUT,
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
        raise ConfigError(rename_keys(str(exc), names)) from exc
    if model is not None:
        check_harmonics(model, analysis.harmonics, names["harmonics"])
    return analysis


def check_output_dir(output: Path) -> None:
    """Refuse an output path that cannot become a writable directory, without creating anything.

    Raises
    ------
    ConfigError
        If ``output`` is an existing file, lies below a file, or its nearest existing ancestor
        is not writable.
    """
    if output.exists() and not output.is_dir():
        raise ConfigError(
            f"`--output` must be a directory, got {str(output)!r}, which is an existing file; "
            "choose another path"
        )
    ancestor = output
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise ConfigError(
            f"`--output` {str(output)!r} cannot be created because {str(ancestor)!r} is a file, "
            "not a directory; choose another path"
        )
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ConfigError(
            f"`--output` {str(output)!r}: no permission to write in {str(ancestor)!r}; "
            "choose a writable directory"
        )


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
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=150)
    finally:
        plt.close(fig)
    return True


def _save_plot(result: Any, path: Path) -> bool:
    """Draw ``result`` with its ``.plot()`` and save it atomically as PNG; False without matplotlib."""
    return _save_figure(result.plot, path)


def _write_frf(result: Any, output: Path, sections: dict[str, Any], t_start: float) -> list[str]:
    """Write ``frf.csv``, ``frf.json`` and ``frf.png`` into ``output``; return the names written.

    The data files come first so that they exist even if drawing the figure fails.
    """
    written: list[str] = []
    try:
        output.mkdir(parents=True, exist_ok=True)
        result.to_csv(output / "frf.csv")
        written.append("frf.csv")
        meta = dict(result.metadata())
        timings = dict(meta.pop("timings", None) or {})
        timings["cli_wall_time"] = time.perf_counter() - t_start
        write_metadata(output / "frf.json", **{**meta, **sections, "timings": timings})
        written.append("frf.json")
        if _save_plot(result, output / "frf.png"):
            written.append("frf.png")
    except OSError as exc:
        where = f"{exc.filename}" if exc.filename else str(output)
        raise click.ClickException(f"cannot write {where}: {exc.strerror or exc}") from exc
    return written


def _compute_frf(
    model: Model, analysis: AnalysisSettings, output: Path, sections: dict[str, Any], t_start: float,
    *, subharmonics: bool = False,
) -> Any:
    """The frequency response; on a convergence failure the points computed before it are
    written (frf.csv, frf.json, frf.png) and the error re-raised naming the files."""
    from ..analysis import frequency_response  # only now: all input has been validated

    extra = {"subharmonics": True} if subharmonics else {}
    try:
        return frequency_response(model, omega=analysis.omega, harmonics=analysis.harmonics, throw=True, **extra)
    except ConvergenceError as exc:
        partial = getattr(exc, "partial", None)
        if partial is None:
            raise
        try:
            written = _write_frf(partial, output, sections, t_start)
        except click.ClickException as write_error:
            raise ConvergenceError(
                f"{exc}; the points computed before the failure could not be saved: "
                f"{write_error.format_message()}",
                partial=partial,
            ) from exc
        click.echo(partial.summary())
        raise ConvergenceError(
            f"{exc}; the points computed before the failure were written to "
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
    run_config = load_config(config)
    analysis = override_analysis(
        run_config.analysis, run_config.model, harmonics=harmonics, omega_min=omega_min, omega_max=omega_max
    )
    check_output_dir(output)
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


def check_points(points: int) -> int:
    """``--points`` N: an integer >= 2 (a sweep needs two frequencies)."""
    if points < 2:
        raise ConfigError(
            f"`--points` must be an integer >= 2 (frequencies per sweep direction), got {points}; use e.g. 200"
        )
    return points


def check_workers(workers: int) -> int:
    """``--workers``: an integer >= 1 (2 runs the up and down sweeps at once)."""
    if workers < 1:
        raise ConfigError(f"`--workers` must be an integer >= 1, got {workers}; use 1 (serial) or 2")
    return workers


def check_omega(omega: float, option: str = "--omega") -> float:
    """A forcing frequency given on the command line: finite and > 0 rad/s."""
    if not (math.isfinite(omega) and omega > 0.0):
        raise ConfigError(f"`{option}` must be a finite forcing frequency > 0 rad/s, got {omega!r}; use e.g. 0.8")
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


def _write_outputs(output: Path, steps: list[tuple[str, Any]]) -> list[str]:
    """Run each (file name, writer(path) -> bool | None) into ``output``; return the names written.

    Data files should come first so that they exist even if drawing a figure fails; a writer
    returning False wrote nothing (e.g. no matplotlib).
    """
    written: list[str] = []
    try:
        output.mkdir(parents=True, exist_ok=True)
        for name, writer in steps:
            if writer(output / name) is not False:
                written.append(name)
    except OSError as exc:
        where = f"{exc.filename}" if exc.filename else str(output)
        raise click.ClickException(f"cannot write {where}: {exc.strerror or exc}") from exc
    return written


def _metadata_writer(meta: dict[str, Any], sections: dict[str, Any], t_start: float) -> Any:
    def write(path: Path) -> None:
        doc = dict(meta)
        timings = dict(doc.pop("timings", None) or {})
        timings["cli_wall_time"] = time.perf_counter() - t_start
        write_metadata(path, **{**doc, **sections, "timings": timings})

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
    run_config = load_config(config)
    analysis = override_analysis(run_config.analysis, run_config.model, omega_min=omega_min, omega_max=omega_max)
    check_points(points)
    check_workers(workers)
    check_output_dir(output)
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
    written = _write_outputs(output, [
        ("sweep.csv", result.to_csv),
        ("sweep.json", _metadata_writer(result.metadata(), sections, t_start)),
        ("sweep.png", lambda path: _save_plot(result, path)),
    ])
    click.echo(result.summary())
    click.echo(f"wrote {', '.join(written)} to {output}")


@cli.command("orbit", short_help="Every periodic orbit at one forcing frequency, against the simulation.")
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
    run_config = load_config(config)
    analysis = override_analysis(
        run_config.analysis, run_config.model, harmonics=harmonics, omega_min=omega_min, omega_max=omega_max
    )
    check_omega(omega)
    check_period(period, analysis.harmonics, len(run_config.model.excitation.amplitudes))
    check_output_dir(output)
    t_start = time.perf_counter()
    from ..analysis import periodic_orbit  # only now: all input has been validated

    result = periodic_orbit(run_config.model, omega, period=period, harmonics=analysis.harmonics,
                            search_range=analysis.omega)
    sections = _sections("orbit", config, run_config, analysis, {
        "omega": omega, "period": period, "harmonics": harmonics,
        "omega_min": omega_min, "omega_max": omega_max,
    })
    written = _write_outputs(output, [
        ("orbit.csv", result.to_csv),
        ("orbit.json", _metadata_writer(result.metadata(), sections, t_start)),
        ("orbit.png", lambda path: _save_plot(result, path)),
    ])
    click.echo(result.summary())
    click.echo(f"wrote {', '.join(written)} to {output}")


@cli.command("compare", short_help="Frequency response and time-domain sweep together.")
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
    run_config = load_config(config)
    analysis = override_analysis(
        run_config.analysis, run_config.model, harmonics=harmonics, omega_min=omega_min, omega_max=omega_max
    )
    check_points(points)
    check_workers(workers)
    at_values = parse_at(at, analysis.omega_min, analysis.omega_max)
    check_output_dir(output)
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
    written = _write_outputs(output, [
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
    from ..model import reference_case

    check_output_dir(output)
    t_start = time.perf_counter()
    model = reference_case()
    analysis = AnalysisSettings(omega_min=DEMO_OMEGA[0], omega_max=DEMO_OMEGA[1], harmonics=DEMO_HARMONICS)
    click.echo(
        "rattle demo: the paper's reference case — clutch alpha = 0.25, b = 10 deg, zeta = 0.025, "
        f"F_m = 0.05, F_p1 = 0.03; Omega = {analysis.omega_min} … {analysis.omega_max} rad/s, "
        f"H = {analysis.harmonics}, sub-harmonic branches on; sweep up and down, {DEMO_POINTS} points each"
    )
    sections: dict[str, Any] = {
        "command": "demo", "config": model_to_toml_dict(model, analysis), "analysis": analysis.to_dict(),
        "options": {"subharmonics": True, "points": DEMO_POINTS, "workers": DEMO_WORKERS},
    }
    timings: dict[str, float] = {}

    # --- computation ---------------------------------------------------------------------------
    t0 = time.perf_counter()
    frf = _compute_frf(model, analysis, output, sections, t_start, subharmonics=True)
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
        write_metadata(path, **{**meta, **sections, "demo": demo_section, "timings": wall})

    written = _write_outputs(output, [("frf.csv", frf.to_csv), ("sweep.csv", sweep.to_csv), ("frf.json", write_json)])
    t0 = time.perf_counter()
    figures: dict[str, str] = {}
    for key, name in DEMO_FIGURES.items():
        done = _write_outputs(output, [(name, lambda path, k=key: _save_figure(
            _draw_demo_figure(k, frf, sweep, orbits, level), path))])
        if done:
            figures[key] = name
            written += done
    timings["figures"] = time.perf_counter() - t0
    timings["total"] = time.perf_counter() - t_start

    from ..report import demo_report

    text = demo_report(frf, sweep, orbits=orbits, level=level, figures=figures, regions=regions, timings=timings,
                       data_files=["frf.csv", "frf.json", "sweep.csv"], version=rattle_version())
    written += _write_outputs(output, [(DEMO_REPORT, lambda path: atomic_write_text(path, text))])

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
