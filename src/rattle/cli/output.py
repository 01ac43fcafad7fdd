"""What the command line writes and prints: output sets written atomically through
:mod:`rattle.io`, figures saved as PNG, the metadata file, the progress bar, the
``rattle: error:``/``rattle: warning:`` lines and ``-v`` progress on stderr.

Nothing is computed here; the commands (:mod:`rattle.cli.commands`) hand in result objects
and writer functions.
"""

from __future__ import annotations

import logging
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

if TYPE_CHECKING:  # annotations only: the numpy-based layers are imported when a command runs
    from ..io import AnalysisSettings

__all__ = [
    "FRF_FILES", "SWEEP_FILES", "ORBIT_FILES", "COMPARE_FILES", "Writer", "ProgressBar", "write_set", "save_figure",
    "save_plot", "write_png", "FIGURE_DPI", "frf_steps", "write_frf", "metadata_writer", "sections", "echo_written",
    "error", "warning",
    "one_line", "set_verbose", "reset_verbose", "logger", "MAP_FILES", "MapProgress", "map_csv_writer",
    "map_json_writer", "map_summary", "nonsmooth_metadata", "nonsmooth_summary", "friction_metadata",
    "friction_summary",
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
    from .. import io

    return io


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
    try:
        with _io().OutputSet(output, names) as staged:
            logger.info("staging %s in %s", ", ".join(n for n, _ in steps), staged.staging)
            for name, writer in steps:
                logger.info("writing %s", name)
                writer(staged.path(name))
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


def frf_steps(result: Any, sections: dict[str, Any], t_start: float) -> list[tuple[str, Writer]]:
    """Writers of ``frf.csv``, ``frf.json`` and ``frf.png`` (the data first, the figure last)."""
    return [("frf.csv", result.to_csv), ("frf.json", metadata_writer(result.metadata(), sections, t_start)),
            ("frf.png", lambda path: save_plot(result, path))]


def write_frf(result: Any, output: Path, sections: dict[str, Any], t_start: float,
              names: Sequence[str] = FRF_FILES) -> list[str]:
    """Write ``frf.csv``, ``frf.json`` and ``frf.png`` into ``output`` as one set (``names``: the
    command's whole set, see :func:`write_set`); return the names written."""
    return write_set(output, names, frf_steps(result, sections, t_start))


# --------------------------------------------------------------------------------------------
# rattle frf on a discontinuous law (preload, friction)
# --------------------------------------------------------------------------------------------
def _shooting_settings(options: Any, chain: bool) -> dict[str, Any]:
    """The ``frf.json`` settings of an exact shooting continuation (``options``, a ShootingOptions)."""
    return {
        "method": "exact shooting continuation: pseudo-arclength in (z(0), Ω) on the exact event-driven period map"
                  + (" of the chain" if chain else "") + " (Filippov sticking and locking, saltation monodromy), "
                  "special points located on the branch (rattle.analysis.nonsmooth_response)",
        "settle_periods": options.settle_periods, "hops": list(options.hops), "locate": options.locate,
    }


def _is_shooting(options: Any) -> bool:
    return type(options).__name__ == "ShootingOptions"


def nonsmooth_metadata(result: Any, system: Any, options: Any, timings: dict[str, float]) -> dict[str, Any]:
    """The ``frf.json`` sections of a :class:`rattle.results.NonsmoothResponse`: the settings of the
    regularised harmonic balance (``options``, a ``RegularisationOptions``), the equation solved,
    status and message, the rows (all, matched by exact shooting, sticking), the largest and median
    |rms_error| over the matched rows, the stability changes and ``timings``."""
    import numpy as np

    matched = np.asarray(result.matched, dtype=bool)
    err = np.abs(np.asarray(result.rms_error, dtype=float)[matched])
    err = err[np.isfinite(err)]
    stick = np.asarray(result.stick_time, dtype=float)
    labels = result.bifurcation
    return {
        "settings": _shooting_settings(options, False) if _is_shooting(options) else {
            "method": "regularised harmonic balance continued over Ω, every point checked by exact event-driven "
                      "shooting (rattle.analysis.nonsmooth_response)",
            "harmonics": options.harmonics, "regularisation": options.regularisation, "match": options.match,
            "limit": options.limit, "refine": getattr(options, "refine", None), "limit_eps": options.limit_eps,
            "limit_harmonics": options.limit_harmonics,
        },
        "system": {"damping": system.damping, "stiffness": system.stiffness, "law": system.law.to_dict(),
                   "excitation": system.excitation.to_dict()},
        "status": result.status.name.lower(),
        "message": result.message or result.status.message,
        "points": len(result),
        "matched": int(np.count_nonzero(matched)),
        "sticking": int(np.count_nonzero(matched & (np.nan_to_num(stick) > 0))),
        "unstable": int(np.count_nonzero(~np.asarray(result.stable, dtype=bool))),
        "rms_error_max": float(np.max(err)) if err.size else None,
        "rms_error_median": float(np.median(err)) if err.size else None,
        "refined": int(np.size(result.limit_index)),
        "hb_error_max": _largest(getattr(result, "hb_error", None), matched),
        "bifurcations": [{"kind": str(labels[i]), "index": int(i), "omega": float(result.omega[i])}
                         for i in range(len(result)) if labels[i]],
        "branches": [_branch_metadata(b) for b in result.branches],
        "timings": dict(timings),
    }


def _branch_metadata(branch: Any) -> dict[str, Any]:
    """One sub-harmonic branch (a discontinuous law's or a chain's) in ``frf.json``: its number, period, where
    it was born, how its continuation ended, its rows (all, matched, stable), its Ω range, the
    HB's largest |rms_error| over the matched rows and its stability changes."""
    import numpy as np

    matched = np.asarray(branch.matched, dtype=bool)
    labels = branch.bifurcation
    return {
        "branch": int(branch.branch), "period": int(branch.period), "origin": branch.origin,
        "followed": branch.followed,
        "status": branch.status.name.lower(), "message": branch.message or branch.status.message,
        "points": len(branch), "matched": int(np.count_nonzero(matched)),
        "stable": int(np.count_nonzero(matched & np.asarray(branch.stable, dtype=bool))),
        "omega_min": float(np.min(branch.omega)), "omega_max": float(np.max(branch.omega)),
        "rms_error_max": _largest(branch.rms_error, matched),
        "bifurcations": [{"kind": str(labels[i]), "index": int(i), "omega": float(branch.omega[i])}
                         for i in range(len(branch)) if labels[i]],
    }


def _stable_spans(branch: Any) -> str:
    """The Ω ranges of a branch's consecutive matched stable rows, as text (the runs its plot
    shades, :func:`rattle.plotting.held_runs`)."""
    import numpy as np

    from ..plotting import held_runs

    ok = np.asarray(branch.matched, dtype=bool) & np.asarray(branch.stable, dtype=bool)
    runs = held_runs(np.asarray(branch.omega, dtype=float), ok)
    return ", ".join(f"{a:.5g} … {b:.5g}" for a, b in runs) if runs else "nowhere"


def _largest(values: Any, rows: Any) -> float | None:
    """max |values| over ``rows`` (finite ones), None when there is none."""
    import numpy as np

    if values is None:
        return None
    v = np.abs(np.asarray(values, dtype=float)[rows])
    v = v[np.isfinite(v)]
    return float(np.max(v)) if v.size else None


def _branch_lines(result: Any, subharmonics: bool) -> list[str]:
    """The summary's lines on the sub-harmonic branches of ``result`` (a discontinuous law's or a
    chain's), or on the period doublings that started none (``subharmonics``: whether they were
    asked for)."""
    import numpy as np

    lines = []
    for b in result.branches:
        m = np.asarray(b.matched, dtype=bool)
        worst = _largest(b.rms_error, m)
        how = (f"{int(np.count_nonzero(m))} matched by exact shooting over {b.period} periods"
               if b.followed == "harmonic balance" else "every row an exact orbit (exact shooting continuation)")
        lines.append(f"branch {b.branch} (period {b.period}, {b.origin}): {len(b)} points over Ω = "
                     f"{np.min(b.omega):.5g} … {np.max(b.omega):.5g}, {how}; stable over Ω = {_stable_spans(b)}"
                     + (f"; HB rms error at most {worst:.2g}" if worst is not None else ""))
    if "period_doubling" in set(result.bifurcation.tolist()) and not result.branches:
        lines.append("no period-2 orbit was found next to the period doubling(s)" if subharmonics else
                     "period doubling found: run with --subharmonics for the period-2 branches born there")
    return lines


def nonsmooth_summary(result: Any, options: Any, subharmonics: bool = False) -> str:
    """What ``rattle frf`` prints for a discontinuous law (``subharmonics``: whether the
    sub-harmonic branches were asked for)."""
    import numpy as np

    n = len(result)
    matched = np.asarray(result.matched, dtype=bool)
    unstable = int(np.count_nonzero(~np.asarray(result.stable, dtype=bool)))
    how = (f"(exact shooting continuation: every row an exact orbit); {unstable} unstable" if _is_shooting(options)
           else f"(regularised harmonic balance, H = {options.harmonics}, ε = {options.regularisation:g}); "
                f"{int(np.count_nonzero(matched))} matched by exact shooting, {unstable} unstable")
    lines = [
        f"{n} points over Ω = {np.min(result.omega):.4g} … {np.max(result.omega):.4g} {how}" if n else "no points",
        f"status: {result.status.name.lower()} — {result.message or result.status.message}",
    ]
    err = np.abs(np.asarray(result.rms_error, dtype=float)[matched])
    err = err[np.isfinite(err)]
    if err.size or matched.any():
        if err.size:
            lines.append(f"rms of the HB against the exact orbit: median error {np.median(err):.2g}, largest "
                         f"{np.max(err):.2g} (at Ω = "
                         f"{result.omega[matched][np.nanargmax(np.abs(result.rms_error[matched]))]:.5g})")
        refined = int(np.size(result.limit_index))
        best = _largest(getattr(result, "hb_error", None), matched)
        if refined and best is not None:
            lines.append(f"regularisation continued towards its limit at {refined} row(s) (those off by more than "
                         f"{options.refine:g} and any asked for): largest error at the smallest ε {best:.2g}")
        stick = np.nan_to_num(np.asarray(result.stick_time, dtype=float)[matched])
        if np.any(stick > 0):
            period = 2.0 * np.pi / np.asarray(result.omega, dtype=float)[matched]
            lines.append(f"sticks at {int(np.count_nonzero(stick > 0))} of the matched points (at most "
                         f"{np.max(stick / period):.0%} of the period)")
        i = int(np.nanargmax(np.where(matched, result.rms, np.nan)))
        lines.append(f"largest exact rms {result.rms[i]:.5g} rad at Ω = {result.omega[i]:.5g} ({result.regime[i]})")
    labels = result.bifurcation
    if getattr(result, "labels", None) is not None:  # located on the exact branch
        changes = [f"{labels[i]} at Ω = {result.omega[i]:.7g}" for i in range(n) if labels[i]]
        head = "special points (located; grazing: a crossing or a stick phase appears or vanishes): "
    else:
        changes = [f"{labels[i]} before Ω = {result.omega[i]:.5g}" for i in range(n) if labels[i]]
        head = "bifurcations (between rows; grazing: a crossing or a stick phase appears or vanishes): "
    if changes:
        lines.append(head + ", ".join(changes))
    lines.extend(_branch_lines(result, subharmonics))
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# rattle frf on a chain with Coulomb friction on its elements
# --------------------------------------------------------------------------------------------
def friction_metadata(result: Any, system: Any, options: Any, timings: dict[str, float]) -> dict[str, Any]:
    """The ``frf.json`` sections of a :class:`rattle.results.FrictionResponse` (a chain with Coulomb
    friction on its elements): the settings of the regularised harmonic balance (``options``, a
    ``RegularisationOptions``), the elements (law, friction level per stage relative to the
    element's stiffness, the matched rows where it sticks), status and message, the rows, and the
    response's own counts and measured HB error (:meth:`FrictionResponse.metadata`: matched,
    within_0_5_percent, within_0_5_percent_moving, within_0_5_percent_moving_estimate, held_rows,
    max_rms_error, median_rms_error,
    stability_agrees, unstable_rows, sticking_rows, refined_rows, refined_max_error), and
    ``timings``."""
    import numpy as np

    own = {k: v for k, v in result.metadata().items() if k not in ("method", "regularisation", "harmonics",
                                                                      "status", "message")}
    matched = np.asarray(result.matched, dtype=bool)
    stick = np.nan_to_num(np.asarray(result.stick_fraction, dtype=float).reshape(len(result), -1))
    elements = [{"name": name, "law": law.elastic.to_dict(),
                 "friction": [float(r) for r in system.friction_levels(e)],
                 "sticking_rows": int(np.count_nonzero(matched & (stick[:, e] > 0)))}
                for e, (name, law) in enumerate(zip(system.element_names, system.laws))]
    return {
        "settings": _shooting_settings(options, True) if _is_shooting(options) else {
            "method": "regularised harmonic balance of the chain continued over Ω, every point checked by exact "
                      "event-driven shooting with Filippov sticking and saltation monodromy "
                      "(rattle.analysis.nonsmooth_response)",
            "harmonics": options.harmonics, "regularisation": options.regularisation, "match": options.match,
            "limit": options.limit, "refine": getattr(options, "refine", None), "limit_eps": options.limit_eps,
            "limit_harmonics": options.limit_harmonics, "held": options.held,
            "held_harmonics": options.held_harmonics,
        },
        "system": {"coordinates": int(system.n), "elements": elements},
        "status": result.status.name.lower(),
        "message": result.message or result.status.message,
        "points": len(result),
        **own,
        "branches": [_branch_metadata(b) for b in result.branches],
        "timings": dict(timings),
    }


def friction_summary(result: Any, options: Any, subharmonics: bool = False) -> str:
    """What ``rattle frf`` prints for a chain with friction on its elements: the response's summary
    (:meth:`FrictionResponse.summary`), the continuation's status, every element's largest exact
    rms, and the sub-harmonic branches (``subharmonics``: whether they were asked for)."""
    import numpy as np

    lines = [result.summary(), f"status: {result.status.name.lower()} — {result.message or result.status.message}"]
    matched = np.asarray(result.matched, dtype=bool)
    rms = np.asarray(result.rms, dtype=float).reshape(len(result), -1)
    for e, name in enumerate(result.element_names):
        col = np.where(matched, rms[:, e], np.nan)
        if np.any(np.isfinite(col)):
            j = int(np.nanargmax(col))
            lines.append(f"{name}: largest exact rms {col[j]:.5g} rad at Ω = {result.omega[j]:.5g}")
    lines.extend(_branch_lines(result, subharmonics))
    return "\n".join(lines)


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
    intervals rattle-free at every combination."""
    from ..maps import common_intervals, format_intervals

    cells = response_map.cells
    resumed = sum(1 for c in cells if c.resumed)
    failed = sum(1 for c in cells if c.status == "failed")
    partial = sum(1 for c in cells if c.status == "partial")
    sizes = " × ".join(f"{len(p.values)} {p.name}" for p in response_map.parameters)
    lines = [f"response map: {len(cells)} combinations ({sizes}) × {len(response_map.omega)} frequencies; "
             f"{len(cells) - resumed} computed, {resumed} read back, {partial} partial, {failed} failed"]
    common = common_intervals(response_map)
    free = format_intervals(common["rattle_free_everywhere"])
    lines.append(f"Ω rattle-free at every combination: {free}{'' if free == 'none' else ' rad/s'}")
    return "\n".join(lines)
