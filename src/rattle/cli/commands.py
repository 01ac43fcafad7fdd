"""The commands of ``rattle``, one function each: ``frf``, ``sweep``, ``orbit``, ``compare`` and
``demo`` (which runs :mod:`rattle.demo`), with the options they share.

Each command checks its input (:mod:`rattle.cli.checks`), reads the configuration, imports the
numerics only then, calls one front end of the library and hands the result to
:mod:`rattle.cli.output`. The group that dispatches to them is :mod:`rattle.cli.app`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import math
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from ..errors import ConfigError, ConvergenceError
from .checks import (
    DIRECTIONS, MAX_PERIOD, check_hb_options, check_omega, check_omega_points, check_period, check_scheduler,
    orbit_omega, orbit_speed, output_path, override_analysis, parse_at, precheck, speed_options,
)
from ._quantity import MAP_QUANTITY, check_quantity, map_largest_line, quantity_option, with_largest
from .output import (
    COMPARE_FILES, FRF_FILES, MAP_FILES, ORBIT_FILES, SWEEP_FILES, MapProgress, ProgressBar, _io, echo_written, loading,
    logger,
    frf_steps, map_csv_writer, map_json_writer, map_summary, metadata_writer, one_line, save_figure, save_plot, sections,
    set_verbose, warning,
    write_frf, write_set,
)
from .pages import check_html, html_option, html_writer

if TYPE_CHECKING:  # annotations only: the numpy-based layers are imported when a command runs
    from ..io import AnalysisSettings
    from ..model import Model

__all__ = [
    "DEFAULT_OUTPUT", "COMMANDS", "common_options", "compute_frf", "run_frf", "run_nonsmooth_orbit",
    "run_friction_orbit", "run_discontinuous_compare",
    "frf_command", "sweep_command", "orbit_command", "compare_command", "map_command", "demo_command",
]

#: Output directory when ``-o`` is not given.
DEFAULT_OUTPUT = "rattle-out"
#: The output sets with the interactive page (``--html``); without it a page of an earlier run is removed.
FRF_PAGE_FILES = (*FRF_FILES, "frf.html")
COMPARE_PAGE_FILES = (*COMPARE_FILES, "compare.html")


# --------------------------------------------------------------------------------------------
# Options shared by the commands
# --------------------------------------------------------------------------------------------
def _print_version(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    if value and not ctx.resilient_parsing:
        from .. import __version__  # the package metadata only, not the numerics

        click.echo(f"rattle {__version__}")
        ctx.exit(0)


def common_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--version`` and ``-v/--verbose``, on the group and on every command."""
    f = click.option("-v", "--verbose", is_flag=True, expose_value=False, callback=set_verbose,
                     help="Report progress on stderr.")(f)
    return click.option("--version", is_flag=True, expose_value=False, is_eager=True, callback=_print_version,
                        help="Show the version and exit.")(f)


_output_option = click.option(
    "-o", "--output", "output", type=str, default=DEFAULT_OUTPUT, callback=output_path, metavar="DIR",
    show_default=True, help="Directory for the output files (created if needed).",
)
_harmonics_option = click.option(
    "--harmonics", type=int, default=None, metavar="H",
    help="Harmonics kept in the harmonic balance (>= 1); overrides analysis.harmonics.",
)
_omega_min_option = click.option(
    "--omega-min", type=float, default=None, metavar="X",
    help="Lower forcing frequency in rad/s (> 0); overrides analysis.omega.1 (the lower end).",
)
_omega_max_option = click.option(
    "--omega-max", type=float, default=None, metavar="Y",
    help="Upper forcing frequency in rad/s (> omega-min); overrides analysis.omega.2 (the upper end).",
)
_rpm_min_option = click.option(
    "--rpm-min", type=float, default=None, metavar="N1",
    help="Lower crankshaft speed in rpm, for a configuration with [engine]; instead of --omega-min.",
)
_rpm_max_option = click.option(
    "--rpm-max", type=float, default=None, metavar="N2",
    help="Upper crankshaft speed in rpm, for a configuration with [engine]; instead of --omega-max.",
)
_quiet_option = click.option(
    "-q", "--quiet", is_flag=True,
    help="No progress bar (there is none anyway when stderr is not a terminal).",
)


# --------------------------------------------------------------------------------------------
# rattle frf
# --------------------------------------------------------------------------------------------
def compute_frf(
    model: Model, analysis: AnalysisSettings, output: Path, sections: dict[str, Any], t_start: float,
    *, subharmonics: bool = False, names: Sequence[str] = FRF_FILES, start: str = "low",
    fixed_harmonics: bool = False,
) -> Any:
    """The frequency response; on a numerical failure the points computed before it are
    written (frf.csv, frf.json, frf.png, as the command's whole set ``names``: files of an
    earlier run that the partial set does not replace are removed) and the error re-raised
    naming the files."""
    with loading():  # only now: all input has been validated
        from ..analysis import case_arguments, frequency_response

    extra: dict[str, Any] = {"subharmonics": True} if subharmonics else {}
    if start != "low":
        extra["start"] = start
    if fixed_harmonics:
        extra["adaptive"] = None
    arguments = case_arguments(model, analysis, extra)  # the law's method: harmonics, or [analysis] method
    from ..results import SpeedText

    speed = SpeedText.of(model)
    logger.info("computing the frequency response over %s%s",
                speed.span(analysis.omega_min, analysis.omega_max, 6, unit=True)
                + (f" (Ω = {analysis.omega_min:g} … {analysis.omega_max:g} rad/s)" if speed.engine else ""),
                f" with {analysis.harmonics} harmonics" if "harmonics" in arguments else
                f" ({type(arguments['options']).__name__})" if "options" in arguments else "")
    bar = ProgressBar("frequency response", enabled=True, unit="‰")  # a bar of the range reached, on a terminal
    try:
        try:
            return frequency_response(model, throw=True, progress=bar, **arguments)
        finally:
            bar.close()
    except (ConvergenceError, ArithmeticError) as exc:
        partial = getattr(exc, "partial", None)
        if partial is None or not len(partial):
            raise
        reason = str(exc) if isinstance(exc, ConvergenceError) else f"{one_line(exc)} ({type(exc).__name__})"
        try:
            written = write_frf(partial, output, sections, t_start, names)
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
    model: Model, analysis: AnalysisSettings, output: Path, sections: dict[str, Any], *, subharmonics: bool = False,
    paths: Sequence[Any] = (), start: str = "low", fixed_harmonics: bool = False, html: bool = False,
    quantity: str = "rms",
) -> None:
    """Compute the frequency response, write the three files (and frf.html) and print the summary.

    Parameters
    ----------
    model : Model
    analysis : AnalysisSettings
        Frequency range and harmonics.
    output : pathlib.Path
        Output directory (checked with :func:`rattle.cli.checks.check_output_dir` beforehand).
    sections : dict
        Extra metadata sections for ``frf.json`` (``config``, ``command``, …).
    subharmonics : bool, default False
        Also follow the period-doubled branches (every branch goes into the files).
    paths : sequence of SoundPath, default ()
        The configuration's ``[[paths]]``: when given, frf.csv gets the column ``spl_db``.
    start : {"low", "high", "both"}, default "low"
        The end the branch is started from (``frequency_response(start=...)``).
    fixed_harmonics : bool, default False
        Keep H fixed (``frequency_response(adaptive=None)``).
    html : bool, default False
        Also write frf.html, the interactive page (:func:`rattle.plotting.frequency_response_html`).
    quantity : str, default "rms"
        What frf.png (and frf.html) draws and the summary's 'largest' line reports (``--quantity``).

    Raises
    ------
    ConvergenceError
        When the continuation failed; the points computed before the failure are written first
        when the error carries them in ``.partial``.
    """
    t_start = time.perf_counter()
    result = compute_frf(model, analysis, output, sections, t_start, subharmonics=subharmonics, start=start,
                         fixed_harmonics=fixed_harmonics, names=FRF_PAGE_FILES)
    if paths:  # SPEC §6: the sound pressure level at the receiver, per point
        result = result.with_sound(tuple(paths))
    steps = frf_steps(result, sections, t_start, quantity)
    if html:
        from ..plotting import frequency_response_html

        steps.append(("frf.html", html_writer(lambda: frequency_response_html(result, quantity=quantity))))
    written = write_set(output, FRF_PAGE_FILES, steps)
    echo_written(with_largest(result.summary(), quantity, result), written, output)


def _law_keys(run_config: Any) -> str:
    """The keys that make the configuration's law discontinuous, as the user wrote them."""
    if getattr(run_config, "chain_friction", False):  # a chain with friction or preloads on its elements
        system = run_config.model
        keys = [f"`model.elements.{e + 1}.{k}`" for e in range(system.m)
                for k, on in (("preload", bool(system.laws[e].stages.jumps.any())),
                              ("friction", bool(system.friction_levels(e).any()))) if on]
        return " and ".join(keys) or "`model.elements`"
    law = run_config.model.law
    keys = [f"`model.elastic.{k}`" for k, on in (("preload", bool(law.stages.jumps.any())),
                                                  ("friction", bool(law.friction_levels.any()))) if on]
    return " and ".join(keys) or "`model.elastic`"


@click.command("frf", short_help="Frequency response of the model in a configuration file.")
@common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@_harmonics_option
@_omega_min_option
@_omega_max_option
@_rpm_min_option
@_rpm_max_option
@click.option("--subharmonics", is_flag=True, default=False,
              help="Also follow the sub-harmonic (period-doubled) branches born at every period-doubling "
                   "point; all branches go into frf.csv (columns branch, period) and frf.png.")
@click.option("--start", type=click.Choice(["low", "high", "both"]), default="low", show_default=True,
              help="Where the branch is started: the low or the high end of the range (a branch that does not "
                   "cover the range is followed from the other end too), or both ends always.")
@click.option("--fixed-harmonics", is_flag=True, default=False,
              help="Keep H = --harmonics on the whole range (by default H is raised where the truncation "
                   "error or a failing corrector demands it, up to 128, and lowered again where it allows).")
@html_option
@quantity_option
def frf_command(
    config: Path, output: Path, harmonics: int | None, omega_min: float | None, omega_max: float | None,
    rpm_min: float | None, rpm_max: float | None, subharmonics: bool, start: str = "low",
    fixed_harmonics: bool = False, html: bool = False, quantity: str = "rms",
) -> None:
    """Frequency response of the model in CONFIG: frf.csv, frf.png, frf.json (and frf.html, an
    interactive page, with --html) in OUTPUT.

    With --subharmonics every period-doubling point found on the primary branch starts a
    period-2 branch (and so on, up to period 4); each branch has its colour in frf.png. On a
    discontinuous law, or a chain with friction or jumps on its elements, it follows the period-2
    branches born at the period doublings of the period-1 branch, every orbit shot exactly over
    two periods; --start and --fixed-harmonics are refused there.
    """
    precheck(config, output, harmonics=harmonics)
    check_html(html)
    run_config = _io().load_config(config)
    check_quantity(quantity, run_config, "frf")
    check_hb_options(run_config, start=start, fixed_harmonics=fixed_harmonics)
    w_min, w_max, labels = speed_options(run_config.model, omega_min, omega_max, rpm_min, rpm_max)
    analysis = override_analysis(
        run_config.analysis, run_config.bounds_model, labels=labels, harmonics=harmonics, omega_min=w_min,
        omega_max=w_max,
    )
    options = {"quantity": None if quantity == "rms" else quantity, "harmonics": harmonics, "omega_min": omega_min, "omega_max": omega_max,
               "rpm_min": rpm_min, "rpm_max": rpm_max, "subharmonics": True if subharmonics else None,
               "start": None if start == "low" else start, "fixed_harmonics": True if fixed_harmonics else None,
               "html": True if html else None}
    run_frf(run_config.model, analysis, output, sections("frf", config, run_config, analysis, options),
            subharmonics=subharmonics, paths=run_config.paths, start=start, fixed_harmonics=fixed_harmonics, html=html,
            quantity=quantity)


# --------------------------------------------------------------------------------------------
# Time-domain commands: sweep, orbit, compare
# --------------------------------------------------------------------------------------------
class _SweepWarnings(logging.Handler):
    """The library's warnings during a sweep (a frequency whose steady state failed) as
    ``rattle: warning: …`` lines, above the progress bar; attached only when ``-v`` does not
    already print its log."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = " ".join(record.getMessage().split())
            try:
                from tqdm import tqdm
            except ImportError:  # pragma: no cover - tqdm is a dependency
                warning(text)
                return
            with tqdm.external_write_mode(file=sys.stderr):  # the bar cleared, written, drawn again
                warning(text)
        except Exception:  # a warning that cannot be shown never stops the sweep
            self.handleError(record)


@contextlib.contextmanager
def _sweep_warnings() -> Iterator[None]:
    if any(h.get_name() == "rattle-cli" for h in logger.handlers):  # -v: printed already
        yield
        return
    handler = _SweepWarnings()
    logger.addHandler(handler)
    try:
        yield
    finally:
        logger.removeHandler(handler)


@click.command("sweep", short_help="Time-domain frequency sweep (steady state at each frequency).")
@common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--direction", type=click.Choice(DIRECTIONS), default=None,
              help="Required: sweep up (run-up), down (run-down) or both, the state carried from each "
                   "frequency to the next.")
@click.option("--points", type=int, default=200, show_default=True, metavar="N",
              help="Equally spaced frequencies per direction (>= 2).")
@click.option("--workers", type=int, default=1, show_default=True, metavar="W",
              help="Processes: 2 runs the up and down sweeps of --direction both at once.")
@_omega_min_option
@_omega_max_option
@_rpm_min_option
@_rpm_max_option
@_quiet_option
@quantity_option
def sweep_command(
    config: Path, output: Path, direction: str | None, points: int, workers: int,
    omega_min: float | None, omega_max: float | None, rpm_min: float | None, rpm_max: float | None, quiet: bool,
    quantity: str = "rms",
) -> None:
    """Time-domain frequency sweep of the model in CONFIG: sweep.csv, sweep.png, sweep.json in OUTPUT.

    At N equally spaced frequencies the motion is simulated exactly until it settles (period
    1 … 8 of the forcing period, or 0 when none is found), the state carried from one frequency
    to the next as in a run-up or run-down.

    A discontinuous law (a torque jump or friction), or a chain with friction on its elements, is
    simulated by its exact event-driven integrator (Filippov sticking, locks at jumps); sweep.csv
    then also has the fraction of each row's period held stuck or locked (stick_fraction, or
    NAME_stick_fraction per element).

    A frequency whose steady state fails numerically (e.g. an exact flow that chatters into a
    lock beyond its event budget) is written as a failed row (period -1, the measures nan) and
    the sweep carries on; the three files are still written, the failed frequencies and the
    reason are printed, and the command exits with status 1.
    """
    if direction is None:  # checked here: click's own message for a missing choice spans lines
        raise ConfigError("`--direction` is required: give --direction up, down or both")
    precheck(config, output, points=points, workers=workers)
    run_config = _io().load_config(config)
    check_quantity(quantity, run_config, "sweep")
    w_min, w_max, labels = speed_options(run_config.model, omega_min, omega_max, rpm_min, rpm_max)
    analysis = override_analysis(run_config.analysis, run_config.bounds_model, labels=labels, omega_min=w_min,
                                 omega_max=w_max)
    t_start = time.perf_counter()
    with loading():  # only now: all input has been validated
        from ..analysis import time_sweep

    bar = ProgressBar(f"sweep {direction}", enabled=not quiet)
    try:
        with _sweep_warnings():
            result = time_sweep(run_config.model, omega=analysis.omega, points=points, direction=direction,
                                workers=workers, callback=bar)
    finally:
        bar.close()
    if run_config.paths:  # SPEC §6: the sound pressure level of every row's simulated motion
        result = result.with_sound(run_config.paths)
    meta = sections("sweep", config, run_config, analysis, {
        "direction": direction, "points": points, "workers": workers,
        "omega_min": omega_min, "omega_max": omega_max, "rpm_min": rpm_min, "rpm_max": rpm_max,
        "quantity": None if quantity == "rms" else quantity,
    })
    written = write_set(output, SWEEP_FILES, [
        ("sweep.csv", result.to_csv),
        ("sweep.json", metadata_writer(result.metadata(), meta, t_start)),
        ("sweep.png", lambda path: save_figure(lambda: result.plot(quantity=quantity), path)),
    ])
    echo_written(with_largest(result.summary(), quantity, result), written, output)
    _raise_if_incomplete(result, written, output)


def _raise_if_incomplete(sweep: Any, written: Sequence[str], output: Path) -> None:
    """The exit-1 error after the set was written, when a frequency of the time-domain sweep
    ``sweep`` failed (its rows computed are written; the failed ones as in a partial frf)."""
    if not sweep.complete:
        raise ConvergenceError(
            f"sweep incomplete: {sweep.message}; all rows were written (the failed ones as period -1 and nan) to "
            f"{', '.join(str(output / name) for name in written)}",
            partial=sweep,
        )


@click.command("orbit", short_help="Every periodic orbit at one forcing frequency, against the simulation.")
@common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--omega", "omega", type=float, default=None, metavar="W",
              help="Forcing frequency in rad/s (finite, > 0). Give this or --rpm.")
@click.option("--rpm", "rpm", type=float, default=None, metavar="N",
              help="Crankshaft speed in rpm (finite, > 0), for a configuration with [engine]; instead of --omega.")
@click.option("--period", type=int, default=1, show_default=True, metavar="N",
              help=f"Period of the orbit as a multiple of the forcing period, 1 … {MAX_PERIOD} (N: a 1/N sub-harmonic).")
@_harmonics_option
@_omega_min_option
@_omega_max_option
@click.option("--single", is_flag=True, default=False,
              help="A discontinuous law: compute only the orbit asked for, not every orbit at W (the census of "
                   "the window W (1 ± 0.05) costs seconds).")
def orbit_command(
    config: Path, output: Path, omega: float | None, period: int, harmonics: int | None,
    omega_min: float | None, omega_max: float | None, rpm: float | None = None, single: bool = False,
) -> None:
    """Periodic orbits at the forcing frequency W for the model in CONFIG: orbit.csv, orbit.png,
    orbit.json in OUTPUT.

    The frequency is --omega W (rad/s) or, for a configuration with [engine], --rpm N (the
    crankshaft speed: W = order × 2π N/60); one of the two, not both.

    Every coexisting harmonic-balance solution at W is found (the primary branch is followed over
    the analysis range, widened to include W; sub-harmonics are seeded from a simulation) and its
    stability computed. orbit.csv holds t, delta, velocity, acceleration over one period of the
    selected solution: the stable one closest in rms to the simulated steady state (preferring
    the requested period); orbit.json lists them all. A chain: those of its first clearance
    element, then NAME_delta and NAME_acceleration of every element.

    A discontinuous law, or a chain with friction on its elements: the orbit at W alone (period 1,
    or 2 with --period 2: exit 1 where the motion has period 1), exact (event-driven shooting,
    sticking exact) and regularised harmonic balance side by side; orbit.csv holds t and per
    element NAME_delta, NAME_velocity, NAME_stuck, NAME_delta_hb for the chain. --period above 2
    and --omega-min/--omega-max are refused there. Beside it, every orbit at W is listed (stable
    and unstable, of any period, exact; and the non-periodic attractors): the exact branches over
    the window W (1 ± 0.05) solved at W and the attractors simulations settle on at W (orbit.json:
    "orbits", "nonperiodic"); --single skips that census.
    """
    orbit_speed(omega, rpm)
    precheck(config, output, harmonics=harmonics)
    run_config = _io().load_config(config)
    omega, option = orbit_omega(run_config.model, omega, rpm)  # --rpm: only with an engine
    speed = {} if rpm is None else {"rpm": rpm}
    if getattr(run_config, "chain_friction", False):
        run_friction_orbit(run_config, config, output, omega, period, harmonics, omega_min, omega_max, speed,
                           every=not single)
        return
    if run_config.discontinuous:
        run_nonsmooth_orbit(run_config, config, output, omega, period, harmonics, omega_min, omega_max, speed,
                            every=not single)
        return
    if single:
        raise ConfigError("`--single` applies to a discontinuous law (a torque jump or friction): the orbits of this "
                          "model are every harmonic-balance solution at --omega; leave it out")
    analysis = override_analysis(
        run_config.analysis, run_config.model, harmonics=harmonics, omega_min=omega_min, omega_max=omega_max
    )
    check_omega(omega, option, model=run_config.model)
    model = run_config.model
    forced = len(model.excitation.amplitudes) if getattr(model, "excitation", None) is not None \
        else int(model.forced_harmonics)
    check_period(period, analysis.harmonics, forced)
    t_start = time.perf_counter()
    with loading():  # only now: all input has been validated
        from ..analysis import periodic_orbit

    result = periodic_orbit(run_config.model, omega, period=period, harmonics=analysis.harmonics,
                            search_range=analysis.omega)
    meta = sections("orbit", config, run_config, analysis, {
        "omega": omega, **speed, "period": period, "harmonics": harmonics,
        "omega_min": omega_min, "omega_max": omega_max,
    })
    written = write_set(output, ORBIT_FILES, [
        ("orbit.csv", result.to_csv),
        ("orbit.json", metadata_writer(result.metadata(), meta, t_start)),
        ("orbit.png", lambda path: save_figure(lambda: result.plot(degrees=_angles_in_degrees(run_config.source)),
                                               path)),
    ])
    echo_written(result.summary(), written, output)


def _angles_in_degrees(source: Any) -> bool:
    """Whether the case file gave the angles of its law (or of a chain's elements) in degrees
    (``b_deg``, ``breakpoints_deg``, a damper's data sheet: :func:`rattle.maps.given_in_degrees`)."""
    from collections.abc import Mapping

    from ..maps import given_in_degrees

    model = source.get("model") if isinstance(source, Mapping) else None
    if not isinstance(model, Mapping):
        return False
    keys = [f"model.elastic.{f}" for f in ("b", "breakpoints", "gap", "clearance")]
    elements = model.get("elements")
    if isinstance(elements, list):
        keys += [f"model.elements.{i}.{f}" for i in range(1, len(elements) + 1)
                 for f in ("b", "breakpoints", "gap", "clearance")]
    return any(given_in_degrees(source, k) for k in keys)


def run_nonsmooth_orbit(run_config: Any, config: Path, output: Path, omega: float, period: int,
                        harmonics: int | None, omega_min: float | None, omega_max: float | None,
                        speed: dict[str, float] | None = None, *, every: bool = True) -> None:
    """``rattle orbit`` on a discontinuous law: :func:`rattle.analysis.nonsmooth_orbit` (the regularised
    HB orbit at Ω and the exact orbit shot from it, with its stick and lock phases), written as one
    set orbit.csv, orbit.json, orbit.png.

    ``--period`` 1 or 2 (2: the period-doubled orbit, found from the exact flow); ``--omega-min``/
    ``--omega-max`` (a search range of the smooth laws) are refused. Raises ConvergenceError (exit 1) after writing the set when the exact shooting failed.
    """
    analysis, options = _nonsmooth_orbit_settings(run_config, omega, period, harmonics, omega_min, omega_max)
    t_start = time.perf_counter()
    with loading():  # only now: all input has been validated
        from ..analysis import nonsmooth_orbit

    logger.info("computing the orbit of a discontinuous law at Ω = %g: regularised harmonic balance (H = %d, ε = %g) "
                "and exact shooting", omega, options.harmonics, options.regularisation)
    result = nonsmooth_orbit(run_config.model, omega, options, period=period, every=every)
    timings = {"nonsmooth_orbit": time.perf_counter() - t_start}
    ok = result.orbit is not None and bool(result.converged)
    meta = {
        "settings": {"method": "exact event-driven shooting started from the regularised harmonic balance "
                               "(rattle.analysis.nonsmooth_orbit)", "harmonics": result.harmonics,
                     "regularisation": options.regularisation, "match": options.match, "period": period},
        "status": "converged" if ok else "failed",
        "message": result.message or ("" if ok else "the exact shooting did not converge"),
        "orbit": result.summary(),
        "timings": timings,
    }
    written = _write_nonsmooth_orbit(result, meta, config, run_config, analysis, output, omega, harmonics, t_start,
                                     speed)
    lines = [f"orbit at Ω = {omega:.6g} (period {result.period:.6g} s): "
             + (f"exact rms {result.rms:.6g} rad, mean {result.mean:.6g} rad, {result.regime}, "
                f"{'stable' if result.stable else 'unstable'} (|μ| = {abs(result.multipliers[0]):.3g}, "
                f"{abs(result.multipliers[1]):.3g})" if ok else "no exact orbit")]
    if ok:
        held = sum(b - a for a, b, _ in result.stick_intervals)
        if math.isfinite(result.rms_hb):
            lines.append(f"regularised HB (H = {result.harmonics}, ε = {options.regularisation:g}): rms "
                         f"{result.rms_hb:.6g} (error {result.rms_error:.2g}); "
                         f"{'matched' if result.matched else 'NOT matched'}")
        if result.stick_intervals:
            lines.append(f"sticks or locks {len(result.stick_intervals)} time(s) per period, {held:.4g} s "
                         f"({held / result.period:.0%} of the period)")
    if result.message:
        lines.append(result.message)
    lines += result.every_orbit_text()
    echo_written("\n".join(lines), written, output)
    if not ok:
        raise _orbit_not_found(omega, result.message, written, output)


def _write_nonsmooth_orbit(result: Any, meta: dict[str, Any], config: Path, run_config: Any,
                           analysis: AnalysisSettings, output: Path, omega: float, harmonics: int | None,
                           t_start: float, speed: dict[str, float] | None = None) -> list[str]:
    """orbit.csv, orbit.json (``meta`` with the run's sections) and orbit.png of the orbit of a
    discontinuous law or a chain with friction, written as one set; the names written."""
    sections_ = sections("orbit", config, run_config, analysis, {"omega": omega, **(speed or {}),
                                                                 "harmonics": harmonics})
    return write_set(output, ORBIT_FILES, [
        ("orbit.csv", result.to_csv),
        ("orbit.json", metadata_writer(meta, sections_, t_start)),
        ("orbit.png", lambda path: save_plot(result, path)),
    ])


def _orbit_not_found(omega: float, message: str, written: list[str], output: Path) -> ConvergenceError:
    """The exit-1 error after the set of an orbit whose exact shooting failed was written."""
    return ConvergenceError(f"the exact orbit at `--omega` {omega:g} was not found ({message}); the "
                            f"regularised HB orbit was written to {', '.join(str(output / n) for n in written)}")


def _nonsmooth_orbit_settings(run_config: Any, omega: float, period: int, harmonics: int | None,
                              omega_min: float | None, omega_max: float | None) -> tuple[AnalysisSettings, Any]:
    """The checked settings of ``rattle orbit`` on a discontinuous law or a chain with friction:
    the options refused there (:func:`_nonsmooth_orbit_options`), ``--omega`` within the bounds,
    and the file's analysis with ``--harmonics`` as its RegularisationOptions."""
    _nonsmooth_orbit_options(run_config, period, omega_min, omega_max)
    analysis = override_analysis(run_config.analysis, run_config.bounds_model, harmonics=harmonics)
    check_omega(omega, model=run_config.bounds_model)
    from ..analysis import regularisation_options

    return analysis, regularisation_options(analysis)


def _nonsmooth_orbit_options(run_config: Any, period: int, omega_min: float | None, omega_max: float | None) -> None:
    """Exit 2 on the options the orbit of a discontinuous law (or of a chain with friction) does not
    take: ``--period`` other than 1, ``--omega-min``/``--omega-max``."""
    law = _law_keys(run_config)
    what = ("a chain with friction on its elements" if getattr(run_config, "chain_friction", False)
            else "a discontinuous law")
    if period > 2:
        raise ConfigError(f"`--period` {period}: the orbit of {what} ({law}) is computed for period 1 or 2; "
                          "use --period 2 for a period-doubled orbit")
    for option, value in (("--omega-min", omega_min), ("--omega-max", omega_max)):
        if value is not None:
            raise ConfigError(f"`{option}` is not used for {what} ({law}): its orbit is computed at --omega alone, "
                              "without following a branch; leave it out")


def run_friction_orbit(run_config: Any, config: Path, output: Path, omega: float, period: int,
                       harmonics: int | None, omega_min: float | None, omega_max: float | None,
                       speed: dict[str, float] | None = None, *, every: bool = True) -> None:
    """``rattle orbit`` on a chain with Coulomb friction on its elements:
    :func:`rattle.analysis.friction_orbit` (the chain's regularised HB orbit at Ω and the exact orbit
    shot from it, every element's stick phases), written as one set orbit.csv, orbit.json,
    orbit.png.

    ``period`` 1 or 2 (above 2, and ``--omega-min``/``--omega-max``, are refused: exit 2). Raises
    ConvergenceError (exit 1) after writing the set when the exact shooting failed, and before
    writing anything when no orbit of period 2 exists there.
    """
    analysis, options = _nonsmooth_orbit_settings(run_config, omega, period, harmonics, omega_min, omega_max)
    t_start = time.perf_counter()
    with loading():  # only now: all input has been validated
        from ..analysis import friction_orbit

    system = run_config.model
    from ..results import SpeedText

    logger.info("computing the orbit of a chain with friction at %s: regularised harmonic balance (H = %d, "
                "ε = %g) and exact shooting", SpeedText.of(system).at(omega, 6, unit=True), options.harmonics,
                options.regularisation)
    result = friction_orbit(system, omega, options, period=period, every=every)
    timings = {"friction_orbit": time.perf_counter() - t_start}
    elements = [{"name": name, "law": law.elastic.to_dict(), "friction": [float(r) for r in system.friction_levels(e)]}
                for e, (name, law) in enumerate(zip(system.element_names, system.laws))]
    meta = {
        "settings": {"method": "exact event-driven shooting of the chain (Filippov sticking, saltation monodromy) "
                               "started from its regularised harmonic balance (rattle.analysis.friction_orbit)",
                     "harmonics": options.harmonics, "regularisation": options.regularisation, "match": options.match,
                     "period": period, "held_limit": options.held, "held_harmonics": options.held_harmonics,
                     "limit_eps": options.limit_eps},
        "system": {"coordinates": int(system.n), "elements": elements},
        "status": "converged" if result.converged else "failed",
        "message": result.message or ("" if result.converged else "the exact shooting did not converge"),
        "orbit": result.metadata(),
        "timings": timings,
    }
    written = _write_nonsmooth_orbit(result, meta, config, run_config, analysis, output, omega, harmonics, t_start,
                                     speed)
    echo_written(result.summary(), written, output)
    if not result.converged:
        raise _orbit_not_found(omega, result.message, written, output)


@click.command("compare", short_help="Frequency response and time-domain sweep together.")
@common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--points", type=int, default=200, show_default=True, metavar="N",
              help="Equally spaced frequencies per sweep direction (>= 2).")
@click.option("--at", "at", type=str, default=None, metavar="W1,W2,...",
              help="Frequencies (rad/s) for the time-history panels; default: picked automatically "
                   "(one in the multi-valued region, one where the sweep is not period 1).")
@click.option("--workers", type=int, default=1, show_default=True, metavar="W",
              help="Processes for the sweep: 2 runs the up and down sweeps at once.")
@click.option("--measured", "measured", type=click.Path(path_type=Path), default=None, metavar="FILE.csv",
              help="A measured run-up (CSV: speed_rpm or omega, and acc_p2p and/or spl_db) to overlay and "
                   "table against the computed curves: measured.csv.")
@_harmonics_option
@_omega_min_option
@_omega_max_option
@_rpm_min_option
@_rpm_max_option
@_quiet_option
@html_option
@quantity_option
def compare_command(
    config: Path, output: Path, points: int, at: str | None, workers: int, measured: Path | None,
    harmonics: int | None, omega_min: float | None, omega_max: float | None, rpm_min: float | None,
    rpm_max: float | None, quiet: bool, html: bool = False, quantity: str = "rms",
) -> None:
    """Frequency response against the up/down time-domain sweep for the model in CONFIG:
    compare.png, frf.csv, sweep.csv, compare.json (and compare.html, an interactive page, with --html) in
    OUTPUT.

    With --measured FILE.csv the measured points are drawn over the computed curves of the same
    quantity and tabled against them in measured.csv (HB largest stable, sweep up, sweep down,
    differences).

    A discontinuous law, or a chain with friction or jumps on its elements: the regularised
    harmonic balance checked by exact shooting (whatever [analysis] method says) beside the exact
    up/down sweep, without time histories; --at and --measured are refused there.
    """
    precheck(config, output, harmonics=harmonics, points=points, workers=workers)
    check_html(html)
    parse_at(at)  # the list's form and size: no numpy (the range is checked once the file is read)
    measured_table = None
    if measured is not None:
        from ..files import check_input_file  # no numpy: refused at once

        try:
            check_input_file(measured, what="measured data file")
        except ConfigError as exc:
            raise ConfigError(f"`--measured`: {exc}") from None
        # every rule of the measured file that needs no configuration, before numpy is loaded
        measured_table = _io().parse_measured_csv(measured)
    run_config = _io().load_config(config)
    check_quantity(quantity, run_config, "compare")
    if run_config.discontinuous:
        for given, option in ((at, "--at"), (measured, "--measured")):
            if given is not None:
                raise ConfigError(
                    f"`{option}` is not supported for a discontinuous law ({_law_keys(run_config)}) yet: its comparison "
                    f"sets the response and the exact sweep side by side without time histories; leave {option} out")
    w_min, w_max, labels = speed_options(run_config.model, omega_min, omega_max, rpm_min, rpm_max)
    analysis = override_analysis(
        run_config.analysis, run_config.bounds_model, labels=labels, harmonics=harmonics, omega_min=w_min,
        omega_max=w_max,
    )
    if run_config.discontinuous:
        run_discontinuous_compare(run_config, config, analysis, output, points, workers, quiet, {
            "points": points, "workers": workers, "harmonics": harmonics, "omega_min": omega_min,
            "omega_max": omega_max, "rpm_min": rpm_min, "rpm_max": rpm_max, "html": True if html else None},
            html=html)
        return
    at_values = parse_at(at, analysis.omega_min, analysis.omega_max)
    measured_run = None if measured_table is None else _io().read_measured_csv(
        measured_table, speed_order=getattr(run_config.model, "speed_order", None),
        omega_range=(analysis.omega_min, analysis.omega_max), has_paths=bool(run_config.paths))
    t_start = time.perf_counter()
    with loading():  # only now: all input has been validated
        from ..analysis import compare

    bar = ProgressBar("sweep up+down", enabled=not quiet)
    try:
        with _sweep_warnings():
            result = compare(run_config.model, omega=analysis.omega, harmonics=analysis.harmonics, points=points,
                             at=at_values, workers=workers, callback=bar)
    finally:
        bar.close()
    meta = sections("compare", config, run_config, analysis, {
        "points": points, "at": at_values, "workers": workers, "harmonics": harmonics,
        "omega_min": omega_min, "omega_max": omega_max, "rpm_min": rpm_min, "rpm_max": rpm_max,
        "measured": None if measured is None else str(measured), "html": True if html else None,
        "quantity": None if quantity == "rms" else quantity,
    })
    frf = result.frf.with_sound(run_config.paths) if run_config.paths else result.frf
    sweep = result.sweep.with_sound(run_config.paths) if run_config.paths else result.sweep
    steps: list[tuple[str, Any]] = [
        ("frf.csv", frf.to_csv), ("sweep.csv", sweep.to_csv),
        ("compare.json", metadata_writer(result.metadata(), meta, t_start)),
    ]
    summary = with_largest(result.summary(), quantity, frf, sweep, where=("frequency response: ", "sweep: "))
    shown = result if quantity == "rms" else dataclasses.replace(result, frf=frf, sweep=sweep)  # spl_db: the paths'
    if measured_run is None:
        def draw() -> Any:
            from ..plotting import compare_plot  # matplotlib checked by save_figure first

            return compare_plot(shown, quantity=quantity)

        steps.append(("compare.png", lambda path: save_plot(result, path) if quantity == "rms" else save_figure(draw, path)))
    else:
        from ..results import compare_measured

        def draw_measured() -> Any:
            from ..plotting import compare_plot  # matplotlib checked by save_figure first

            return compare_plot(shown, measured=beside, quantity=quantity)

        beside = compare_measured(measured_run, frf, sweep)  # the sweeps with their sound pressure (paths)
        summary += "\n" + beside.summary()
        steps += [("compare.png", lambda path: save_figure(draw_measured, path)), ("measured.csv", beside.to_csv)]
    if html:
        from ..plotting import compare_html

        steps.append(("compare.html", html_writer(lambda: compare_html(result, summary=summary))))
    written = write_set(output, COMPARE_PAGE_FILES, steps)
    echo_written(summary, written, output)
    _raise_if_incomplete(result.sweep, written, output)


def run_discontinuous_compare(run_config: Any, config: Path, analysis: AnalysisSettings, output: Path, points: int,
                              workers: int, quiet: bool, options: dict[str, Any], *, html: bool = False) -> None:
    """``rattle compare`` on a discontinuous law, or a chain with friction on its elements:
    :func:`rattle.analysis.compare` with the file's ``[analysis]`` (harmonics, regularisation,
    refine) — the regularised harmonic balance checked by exact shooting against the exact up and
    down sweep, written as frf.csv (the response's columns), sweep.csv, compare.json, compare.png (and
    compare.html with ``html``)."""
    t_start = time.perf_counter()
    with loading():  # only now: all input has been validated
        from ..analysis import compare
    from ..analysis import regularisation_options

    reg = regularisation_options(analysis)
    logger.info("comparing the response of a discontinuous law (regularised harmonic balance, H = %d, ε = %g, checked "
                "by exact shooting) with its exact up and down sweep", reg.harmonics, reg.regularisation)
    bar = ProgressBar("sweep up+down", enabled=not quiet)
    try:
        with _sweep_warnings():
            result = compare(run_config.model, omega=analysis.omega, points=points, workers=workers, callback=bar,
                             regularisation=reg)
    finally:
        bar.close()
    meta = sections("compare", config, run_config, analysis, options)
    steps: list[tuple[str, Any]] = [
        ("frf.csv", result.frf.to_csv), ("sweep.csv", result.sweep.to_csv),
        ("compare.json", metadata_writer(result.metadata(), meta, t_start)),
        ("compare.png", lambda path: save_plot(result, path)),
    ]
    if html:
        from ..plotting import compare_html

        steps.append(("compare.html", html_writer(lambda: compare_html(result))))
    written = write_set(output, COMPARE_PAGE_FILES, steps)
    echo_written(result.summary(), written, output)
    _raise_if_incomplete(result.sweep, written, output)


# --------------------------------------------------------------------------------------------
# rattle map: a frequency response with every attractor for every combination of parameters
# --------------------------------------------------------------------------------------------
@click.command("map", short_help="Response map over design parameters and frequency (where rattle is avoided).")
@common_options
@click.argument("config", type=click.Path(path_type=Path))
@_output_option
@click.option("--vary", "vary", type=str, multiple=True, metavar="NAME=START:STOP:COUNT",
              help="A varied parameter: a short name (alpha, b, damping, mean, amplitude, preload, friction) or a "
                   "dotted key of the configuration (model.elastic.alpha, excitation.amplitudes.1, "
                   "model.elements.clutch.b, model.elastic.friction.2), "
                   "COUNT values from START to STOP, or NAME=v1,v2,v3. Repeat for more parameters.")
@click.option("--omega-points", "omega_points", type=int, default=146, show_default=True, metavar="N",
              help="Frequencies of the map's grid over the analysis range.")
@click.option("--workers", type=int, default=None, metavar="W",
              help="Local worker processes (default: the CPUs); 1 runs serially.")
@click.option("--scheduler", type=str, default=None, metavar="ADDRESS",
              help="Run on a Dask distributed cluster at ADDRESS (tcp://host:8786); needs rattle[dask].")
@_harmonics_option
@_omega_min_option
@_omega_max_option
@_rpm_min_option
@_rpm_max_option
@click.option("--report", is_flag=True, default=False,
              help="Also write map.md, the design summary (special points, rattle-free intervals, the search).")
@_quiet_option
@html_option
@quantity_option
def map_command(
    config: Path, output: Path, vary: tuple[str, ...], omega_points: int, workers: int | None,
    scheduler: str | None, harmonics: int | None, omega_min: float | None, omega_max: float | None,
    rpm_min: float | None, rpm_max: float | None, report: bool, quiet: bool, html: bool = False,
    quantity: str = "rms",
) -> None:
    """Response map of the model in CONFIG over the --vary parameters and the frequency: map.csv,
    map.nc, map.json, map.png (map.md with --report, map.html, an interactive page, with --html) in OUTPUT.

    For every combination of the varied values: the frequency response with its sub-harmonic
    branches, every branch solved on the grid of N frequencies, and a search for the attractors
    the branches miss. Every combination finished is kept in OUTPUT/map.parts: a rerun of the
    same command into the same folder reads them back instead of recomputing them.

    A discontinuous law, or a chain with friction or jumps on its elements: every branch by exact
    shooting continuation (as rattle frf at its defaults) and the search on the exact flow;
    [analysis] method = "hb" is refused there.
    """
    from ..maps import build_all, combinations, mark_degrees, parameters, parse_all

    parsed = parse_all(vary)  # first: a malformed --vary needs no file
    precheck(config, output, harmonics=harmonics, workers=workers)
    check_html(html)
    check_omega_points(omega_points)
    scheduler = check_scheduler(scheduler)
    run_config = _io().load_config(config)
    check_quantity(quantity, run_config, "map")
    w_min, w_max, labels = speed_options(run_config.model, omega_min, omega_max, rpm_min, rpm_max)
    analysis = override_analysis(
        run_config.analysis, run_config.bounds_model, labels=labels, harmonics=harmonics, omega_min=w_min,
        omega_max=w_max,
    )
    if run_config.discontinuous:  # a jump or friction: the file's tables (the law's continuous part is there)
        import dataclasses

        tables = dataclasses.replace(run_config, analysis=analysis).to_dict()
    else:
        tables = _io().model_to_toml_dict(run_config.model, analysis)
    params = mark_degrees(parameters(tables, parsed), run_config.source)  # angles given in degrees: shown so
    build_all(tables, params)  # every combination's model, before any work
    t_start = time.perf_counter()
    with loading():  # only now: all input has been validated
        from ..maps import response_map

    logger.info("response map: %d combinations × %d frequencies over %g … %g rad/s",
                len(list(combinations(params))), omega_points, analysis.omega_min, analysis.omega_max)
    bar = MapProgress("map", enabled=not quiet)
    try:
        result = response_map(run_config.model, params, omega=analysis.omega, omega_points=omega_points,
                              harmonics=analysis.harmonics, workers=workers, scheduler=scheduler, store=output,
                              progress=bar, tables=tables, paths=run_config.paths)
    finally:
        bar.close()
    from ..maps import map_report
    from ..plotting import map_plot_names, plot_map

    figures = map_plot_names(result)
    meta = sections("map", config, run_config, analysis, {
        "vary": list(vary), "omega_points": omega_points, "workers": workers, "scheduler": scheduler,
        "harmonics": harmonics, "omega_min": omega_min, "omega_max": omega_max, "rpm_min": rpm_min,
        "rpm_max": rpm_max, "report": True if report else None, "html": True if html else None,
        "quantity": None if quantity == "rms" else quantity,
    })

    steps: list[tuple[str, Any]] = [
        ("map.csv", map_csv_writer(result)),
        ("map.nc", result.to_netcdf),
        ("map.json", map_json_writer(result, meta, t_start)),
        *[(name, lambda path, y=name_y: save_figure(lambda: plot_map(result, y, quantity=MAP_QUANTITY[quantity]), path))
          for name, name_y in figures],
    ]
    if report:
        steps.append(("map.md", lambda path: _io().atomic_write_text(path, map_report(result))))
    if html:
        from ..plotting import map_html

        steps.append(("map.html", html_writer(lambda: map_html(result, summary=map_summary(result),
                                                                    quantity=MAP_QUANTITY[quantity]))))
    # the set: also every map_<NAME>.png of an earlier map in OUTPUT, so that none is left beside the new one
    earlier = sorted(p.name for p in output.glob("map_*.png")) if output.is_dir() else []
    names = tuple(dict.fromkeys([*MAP_FILES, "map.html", *(name for name, _ in figures[1:]), *earlier]))
    written = write_set(output, names, steps)
    failed = [c for c in result.cells if c.status == "failed"]
    echo_written(map_summary(result) + map_largest_line(result, quantity), written, output)
    if failed and len(failed) == len(result.cells):
        raise ConvergenceError(f"every combination failed; the first: {failed[0].message}; the files written say "
                               "which (status in map.json)")
    for c in failed[:5]:
        warning(f"combination {', '.join(f'{k} = {v:g}' for k, v in c.values.items())} failed: {c.message}")
    if len(failed) > 5:
        warning(f"{len(failed) - 5} further combinations failed (status in map.json)")


# --------------------------------------------------------------------------------------------
# rattle demo: the paper's reference case end to end (rattle.demo computes, this writes)
# --------------------------------------------------------------------------------------------
@click.command("demo", short_help="The paper's reference case end to end, with its figures and a report.")
@common_options
@_output_option
@_quiet_option
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
    with loading():  # only now: all input has been validated
        from .. import demo

    t_start = time.perf_counter()
    model, analysis = demo.demo_case()
    click.echo("rattle demo: " + demo.describe(analysis))
    meta_sections: dict[str, Any] = {
        "command": "demo", "config": _io().model_to_toml_dict(model, analysis), "analysis": analysis.to_dict(),
        "options": {"subharmonics": True, "points": demo.DEMO_POINTS, "workers": demo.DEMO_WORKERS},
    }

    # --- computation ---------------------------------------------------------------------------
    t0 = time.perf_counter()
    frf = compute_frf(model, analysis, output, meta_sections, t_start, subharmonics=True, names=demo.DEMO_FILES)
    timings: dict[str, float] = {"frf": time.perf_counter() - t0}
    bar = ProgressBar("sweep up+down", enabled=not quiet)

    def progress(done: int, total: int) -> None:  # the bar goes when the sweep is done, before the orbits
        bar(done, total)
        if done >= total:
            bar.close()

    try:
        run = demo.run_demo(frf, callback=progress)
    finally:
        bar.close()
    timings.update(run.timings)

    # --- output: data first, then the figures, then the report --------------------------------
    meta = dict(frf.metadata())
    frf_timings = dict(meta.pop("timings", None) or {})
    demo_section = run.metadata()

    def write_json(path: Path) -> None:
        wall = {**frf_timings, **{f"demo_{k}": v for k, v in timings.items()},
                "cli_wall_time": time.perf_counter() - t_start}
        _io().write_metadata(path, **{**meta, **meta_sections, "demo": demo_section, "timings": wall})

    figures: dict[str, str] = {}

    def write_figure(key: str, path: Path) -> bool:
        done = save_figure(lambda: run.figure(key), path)
        if done:
            figures[key] = path.name
        return done

    def write_report(path: Path) -> None:
        timings["figures"] = time.perf_counter() - t_figures
        timings["total"] = time.perf_counter() - t_start
        text = run.report(figures=figures, timings=timings, version=_io().rattle_version())
        _io().atomic_write_text(path, text)

    t_figures = time.perf_counter()
    written = write_set(output, demo.DEMO_FILES, [
        ("frf.csv", frf.to_csv), ("sweep.csv", run.sweep.to_csv), ("frf.json", write_json),
        *[(name, lambda path, k=key: write_figure(k, path)) for key, name in demo.DEMO_FIGURES.items()],
        (demo.DEMO_REPORT, write_report),
    ])

    click.echo(run.summary())
    click.echo("time: " + ", ".join(f"{k} {v:.2f} s" for k, v in timings.items()))
    click.echo(f"wrote {len(written)} files to {output}: {', '.join(written)}")


#: Every command of ``rattle``, in the order of the documentation.
COMMANDS = (frf_command, sweep_command, orbit_command, compare_command, map_command, demo_command)
