"""What the command line writes and prints: output sets written atomically through
:mod:`rattle.io`, figures saved as PNG, the metadata file, the progress bar, the
``rattle: error:``/``rattle: warning:`` lines and ``-v`` progress on stderr.

Nothing is computed here; the commands (:mod:`rattle.cli.commands`) hand in result objects
and writer functions.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import os
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from .. import _signals

if TYPE_CHECKING:  # annotations only: the numpy-based layers are imported when a command runs
    from ..io import AnalysisSettings

__all__ = [
    "FRF_FILES", "SWEEP_FILES", "ORBIT_FILES", "COMPARE_FILES", "Writer", "ProgressBar", "write_set", "save_figure",
    "save_plot", "write_png", "FIGURE_DPI", "frf_steps", "write_frf", "metadata_writer", "sections", "echo_written",
    "error", "warning",
    "one_line", "set_verbose", "reset_verbose", "logger", "MAP_FILES", "MapProgress", "map_csv_writer",
    "map_json_writer", "map_summary", "loading",
]

logger = logging.getLogger("rattle")

#: The files each command writes (its output set: staged and moved into place together; a file
#: of the set that a run does not produce is removed, so no old one stays beside new data).
#: The demo's set is :data:`rattle.demo.DEMO_FILES`.
FRF_FILES = ("frf.csv", "frf.json", "frf.png")
SWEEP_FILES = ("sweep.csv", "sweep.json", "sweep.png")
ORBIT_FILES = ("orbit.csv", "orbit.json", "orbit.png")
COMPARE_FILES = ("frf.csv", "sweep.csv", "compare.json", "compare.png", "measured.csv")
#: ``rattle map``: with two or more varied parameters also ``map_<NAME>.png`` for each one after
#: the first (:func:`rattle.plotting.map_plot_names`); ``map.md`` with ``--report``.
MAP_FILES = ("map.csv", "map.nc", "map.json", "map.png", "map.md")


def _io() -> Any:
    """``rattle.io`` (numpy, the model and the configuration reader), imported on first use so
    that ``--help``, ``--version`` and options click refuses need none of it."""
    with loading():
        from .. import io

    return io


@contextlib.contextmanager
def loading() -> Iterator[None]:
    """The body — an import of the numerics (numpy, scipy, numba) or of matplotlib, a figure
    drawn and the output set written — without the cyclic garbage collector, in the
    command-line process; and when it imported modules, what is alive then is frozen
    (``gc.freeze()``: kept for the rest of the run and never searched for cycles again).

    An import creates some 10⁵ objects that live as long as the process; the collector would
    search each of them at least once and find nothing (``rattle frf`` on the reference case,
    ``benchmarks/bench_command.py``: the collector's CPU 0.08 s in some 40 collections, 0.006 s
    with this). The computation itself runs with
    the collector on. Outside the command-line process (the CLI's functions called by another
    program, ``CliRunner``) and when the collector is off already, the body runs as it is."""
    if not (gc.isenabled() and _signals.installed_at_start()):
        yield
        return
    modules = len(sys.modules)
    gc.disable()
    try:
        yield
    finally:
        if len(sys.modules) != modules:
            gc.freeze()
        gc.enable()


# --------------------------------------------------------------------------------------------
# Lines on stderr
# --------------------------------------------------------------------------------------------
def error(message: str) -> None:
    """``rattle: error: message`` on stderr."""
    click.echo(f"rattle: error: {message}", err=True)


def warning(message: str) -> None:
    """``rattle: warning: message`` on stderr."""
    click.echo(f"rattle: warning: {message}", err=True)


def one_line(exc: BaseException) -> str:
    """The exception's message on one line (its type's name when it has none)."""
    return " ".join(str(exc).split()) or type(exc).__name__


def set_verbose(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    """``-v``: the library's progress (logger ``rattle``, INFO) on stderr as ``rattle: …`` lines."""
    if not value or ctx.resilient_parsing:
        return
    if not any(h.get_name() == "rattle-cli" for h in logger.handlers):
        handler = logging.StreamHandler(sys.stderr)
        handler.set_name("rattle-cli")
        handler.setFormatter(logging.Formatter("rattle: %(message)s"))
        logger.addHandler(handler)
    logger.setLevel(logging.INFO)


def reset_verbose() -> None:
    """Remove what :func:`set_verbose` installed (the CLI may run inside another program)."""
    for handler in [h for h in logger.handlers if h.get_name() == "rattle-cli"]:
        logger.removeHandler(handler)
    logger.setLevel(logging.NOTSET)


class ProgressBar:
    """``callback(done, total)`` drawing a tqdm bar on stderr, counting ``unit``s; a no-op when
    stderr is not a terminal, with ``--quiet``, or without tqdm. The library never draws one
    itself."""

    def __init__(self, description: str, enabled: bool, unit: str = "Ω") -> None:
        self.description = description
        self.unit = unit
        self.enabled = enabled and sys.stderr.isatty()
        self._bar: Any = None

    def __call__(self, done: int, total: int, resumed: int = 0) -> None:
        if not self.enabled:
            return
        if self._bar is None:
            try:
                from tqdm import tqdm
            except ImportError:  # pragma: no cover - tqdm is a dependency
                self.enabled = False
                return
            desc = f"{self.description} ({resumed} resumed)" if resumed else self.description
            self._bar = tqdm(total=total, initial=min(done, total), desc=desc, unit=self.unit, file=sys.stderr,
                             leave=False, dynamic_ncols=True)
            return
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


class MapProgress(ProgressBar):
    """``progress(done, total, resumed)`` of a response map: a bar of finished combinations;
    those read back from an earlier run are counted at once (the bar starts there, so that its
    rate and time left are those of the combinations computed now)."""

    def __init__(self, description: str, enabled: bool) -> None:
        super().__init__(description, enabled, unit="combination")


def echo_written(summary: str, written: Sequence[str], output: Path) -> None:
    """The result's summary and the files written, on stdout."""
    click.echo(summary)
    click.echo(f"wrote {', '.join(written)} to {output}")


# --------------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------------
def save_figure(draw: Callable[[], tuple[Any, Any]], path: Path) -> bool:
    """Call ``draw()`` (returns (figure, axes)) and save the figure atomically as PNG; False
    without matplotlib."""
    try:
        import matplotlib
    except ImportError:
        warning(f"matplotlib is not installed, so {path.name} was not written (pip install matplotlib)")
        return False
    matplotlib.use("Agg")  # never open a window from the command line
    import matplotlib.pyplot as plt

    fig, _ax = draw()
    try:
        with _io().atomic_path(path) as tmp:
            if path.suffix in (".png", ""):
                write_png(fig, tmp, FIGURE_DPI)
            else:
                fig.savefig(tmp, format=path.suffix.lstrip("."), dpi=FIGURE_DPI)
    finally:
        plt.close(fig)
    return True


#: The resolution of the command line's figures (dots per inch).
FIGURE_DPI = 150


def write_png(fig: Any, path: Any, dpi: float) -> None:
    """``fig.savefig(path, format="png", dpi=dpi)``, byte for byte, drawn once.

    ``savefig`` draws a figure with a layout engine (``layout="constrained"``) twice: once with
    the drawing switched off, to lay it out, and once on the canvas. Here the figure is drawn
    once on its Agg canvas at ``dpi`` (the layout runs in that draw, at that resolution, as in
    savefig's first pass) and the pixels are written as savefig writes them
    (``matplotlib.image.imsave``, the same metadata): the same file, 13 % less CPU for
    ``frf.png``. With savefig settings that change the picture (``savefig.bbox = "tight"``, a
    transparent or coloured background in a matplotlibrc) it is ``savefig`` itself.
    """
    import matplotlib
    import matplotlib.image
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    rc = matplotlib.rcParams
    if (rc["savefig.bbox"] not in (None, "standard") or rc["savefig.transparent"]
            or rc["savefig.facecolor"] != "auto" or rc["savefig.edgecolor"] != "auto"):
        fig.savefig(path, format="png", dpi=dpi)
        return
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    canvas.draw()
    matplotlib.image.imsave(path, canvas.buffer_rgba(), format="png", origin="upper", dpi=dpi)


def save_plot(result: Any, path: Path) -> bool:
    """Draw ``result`` with its ``.plot()`` and save it atomically as PNG; False without matplotlib."""
    return save_figure(result.plot, path)


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
    # a signal whose Interrupted some code swallowed (measured on a fresh install: a parallel sweep
    # Ctrl-C'd twice ran to its end and wrote its output folder): an interrupted run writes nothing
    _signals.raise_received()
    try:
        with loading(), _io().OutputSet(output, names) as staged:
            logger.info("staging %s in %s", ", ".join(n for n, _ in steps), staged.staging)
            for name, writer in steps:
                logger.info("writing %s", name)
                writer(staged.path(name))
            _signals.raise_received()  # the last moment before the set lands (the staging is then removed)
            written = staged.commit()
    except OSError as exc:  # no space, no permission, a member that cannot be replaced: exit 1, one line
        from ..files import WriteError, describe_os_error

        if isinstance(exc, WriteError):
            raise click.ClickException(f"{exc}; no file of the set was replaced") from exc
        where = f"{exc.filename}" if exc.filename else str(output)
        raise click.ClickException(f"cannot write {where}: {describe_os_error(exc)}; no file of the set was "
                                   "replaced") from exc
    logger.info("moved %s into %s", ", ".join(written), output)
    return written


def metadata_writer(meta: dict[str, Any], sections: dict[str, Any], t_start: float) -> Writer:
    """A writer of the ``.json`` metadata: the result's ``meta`` with the command's ``sections``
    and the command's wall time added to its timings."""

    def write(path: Path) -> None:
        doc = dict(meta)
        timings = dict(doc.pop("timings", None) or {})
        timings["cli_wall_time"] = time.perf_counter() - t_start
        _io().write_metadata(path, **{**doc, **sections, "timings": timings})

    return write


def sections(command: str, config: Path, run_config: Any, analysis: AnalysisSettings,
             options: dict[str, Any]) -> dict[str, Any]:
    """The metadata sections every command adds: the command, the configuration file and its
    text, the options given (None left out) and the analysis settings used."""
    return {
        "command": command,
        "config_file": os.fspath(config),
        "config": run_config.source,
        "options": {k: v for k, v in options.items() if v is not None},
        "analysis": analysis.to_dict(),
    }


def frf_steps(result: Any, sections: dict[str, Any], t_start: float, quantity: str = "rms") -> list[tuple[str, Writer]]:
    """Writers of ``frf.csv``, ``frf.json`` and ``frf.png`` (the data first, the figure last; the
    figure draws ``quantity``)."""
    def figure(path: Path) -> bool:
        if quantity == "rms":
            return save_plot(result, path)
        return save_figure(lambda: result.plot(quantity=quantity), path)

    return [("frf.csv", result.to_csv), ("frf.json", metadata_writer(result.metadata(), sections, t_start)),
            ("frf.png", figure)]


def write_frf(result: Any, output: Path, sections: dict[str, Any], t_start: float,
              names: Sequence[str] = FRF_FILES, quantity: str = "rms") -> list[str]:
    """Write ``frf.csv``, ``frf.json`` and ``frf.png`` into ``output`` as one set (``names``: the
    command's whole set, see :func:`write_set`); return the names written."""
    return write_set(output, names, frf_steps(result, sections, t_start, quantity))


# --------------------------------------------------------------------------------------------
# rattle map
# --------------------------------------------------------------------------------------------
def map_csv_writer(response_map: Any) -> Writer:
    """A writer of ``map.csv``: one row per (combination, grid frequency), the varied NAMEs then
    :data:`rattle.maps.MAP_COLUMNS`; ``rms_max_stable``/``rms_ac_max_stable`` empty where NaN."""

    def write(path: Path) -> None:
        response_map.to_csv(path)

    return write


def map_json_writer(response_map: Any, sections: dict[str, Any], t_start: float) -> Writer:
    """A writer of ``map.json``: the command's ``sections`` (config, options, analysis), the map's
    settings and timings, the varied parameters, and per combination its values, special
    points, intervals, attractors, search, status, timings and whether it was read back."""

    def write(path: Path) -> None:
        from ..maps import common_intervals

        combos = []
        for (index, values), cell in zip(response_map.combinations(), response_map.cells):
            combos.append({
                "index": list(index), "values": values, "status": cell.status, "message": cell.message,
                "special_points": cell.special_points, "intervals": cell.intervals, "attractors": cell.attractors,
                "search": cell.search, "timings": cell.timings, "resumed": cell.resumed,
            })
        timings = dict(response_map.timings)
        timings["cli_wall_time"] = time.perf_counter() - t_start
        _io().write_metadata(
            path, **sections, settings=response_map.settings, timings=timings,
            parameters=[{"name": p.name, "key": p.key, "values": list(p.values)} for p in response_map.parameters],
            omega=list(map(float, response_map.omega)), region=common_intervals(response_map), combinations=combos,
        )

    return write


def map_summary(response_map: Any) -> str:
    """What ``rattle map`` prints: the map's size, what was read back or failed, and the Ω
    intervals (an engine case: crankshaft speeds in rpm) rattle-free at every combination."""
    from ..maps import common_intervals, format_intervals

    cells = response_map.cells
    resumed = sum(1 for c in cells if c.resumed)
    failed = sum(1 for c in cells if c.status == "failed")
    partial = sum(1 for c in cells if c.status == "partial")
    sizes = " × ".join(f"{len(p.values)} {p.name}" for p in response_map.parameters)
    lines = [f"response map: {len(cells)} combinations ({sizes}) × {len(response_map.omega)} frequencies; "
             f"{len(cells) - resumed} computed, {resumed} read back, {partial} partial, {failed} failed"]
    from ..results import SpeedText

    speed = SpeedText(None if response_map.speed_order is None else float(response_map.speed_order))
    common = common_intervals(response_map)
    free = format_intervals(common["rattle_free_everywhere"], speed)
    what = "speeds" if speed.engine else "Ω"
    lines.append(f"{what} rattle-free at every combination: {free}{'' if free == 'none' else ' ' + speed.unit}")
    return "\n".join(lines)
