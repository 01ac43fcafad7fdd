"""The result of a response map: one :class:`CellResult` per combination, gathered in a
:class:`ResponseMap` (an xarray Dataset over the varied parameters × Ω, SPEC §7).

A *combination* is one value of every varied parameter; its *cell result* is what the frequency
response and the attractor search found there, evaluated on the map's Ω grid:

======================  =====================================================================
``n_solutions``         period-1 solutions of the primary branch at Ω (all)
``n_stable``            … of them stable
``rms_max_stable``      largest rms over the stable period-1 solutions at Ω (any branch; NaN if none)
``rms_ac_max_stable``   rms_ac of that solution
``regime_max_stable``   that solution's regime (``""`` if none)
``periods_stable``      the periods of every stable solution found at Ω, ``;``-joined (``1;2``),
                        with ``0`` for a non-periodic attractor
``rattle``              some attractor found at Ω crosses a breakpoint (impacts)
======================  =====================================================================

With sound paths (``[[paths]]``, SPEC §6) a cell also has the extension column

======================  =====================================================================
``spl_max_stable_db``   largest sound pressure level at the receiver (dB re 20 µPa) over the
                        stable periodic solutions found at Ω, any branch and period (NaN if none)
======================  =====================================================================

A cell result is exactly JSON-serialisable (:meth:`CellResult.to_dict` / :meth:`from_dict`
round-trip every float bit for bit): that is how a finished combination is stored and read
back when a map resumes.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import xarray as xr

#: Per-frequency columns of a cell (SPEC §7 ``map.csv`` after the varied parameters and ``omega``).
GRID_COLUMNS: tuple[str, ...] = (
    "n_solutions", "n_stable", "rms_max_stable", "rms_ac_max_stable", "regime_max_stable", "periods_stable",
    "rattle",
)
#: ``map.csv`` columns after the varied parameters' names.
MAP_COLUMNS: tuple[str, ...] = ("omega", *GRID_COLUMNS)
#: The extension column of a map with sound paths (written after the SPEC §7 columns).
SOUND_COLUMN = "spl_max_stable_db"
#: The interval kinds of a cell's design summary.
INTERVAL_KINDS: tuple[str, ...] = ("impact", "rattle_free", "subharmonic", "nonperiodic")


def grid_runs(mask: np.ndarray, grid: np.ndarray) -> list[list[float]]:
    """[first, last] grid frequency of every run of consecutive True in ``mask`` (the
    grid-resolved intervals of a cell)."""
    out: list[list[float]] = []
    j, n = 0, mask.size
    while j < n:
        if mask[j]:
            k = j
            while k + 1 < n and mask[k + 1]:
                k += 1
            out.append([float(grid[j]), float(grid[k])])
            j = k + 1
        else:
            j += 1
    return out


def _spl(cell: "CellResult", size: int) -> np.ndarray:
    """A cell's ``spl_max_stable_db``, NaN throughout when it has none (a failed combination)."""
    return np.full(size, np.nan) if cell.spl_max_stable_db is None else np.asarray(cell.spl_max_stable_db, dtype=float)


def _is_real(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _is_real_or_none(x: Any) -> bool:
    return x is None or _is_real(x)


def _is_count(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool) and 0 <= x < 1 << 31


def _is_str(x: Any) -> bool:
    return isinstance(x, str)


def _is_bool(x: Any) -> bool:
    return isinstance(x, bool)


_KIND_WORDS = {_is_real: "numbers", _is_real_or_none: "numbers or null", _is_count: "counts (integers >= 0)",
               _is_str: "strings", _is_bool: "true/false"}


def _column(data: dict[str, Any], name: str, ok: Any, size: int | None = None) -> list[Any]:
    """``data[name]`` as a list of ``size`` items (any size when None) each passing ``ok``."""
    col = data[name]
    if not isinstance(col, list):
        raise ValueError(f"a map part's `{name}` must be a list, got {type(col).__name__}")
    if size is not None and len(col) != size:
        raise ValueError(f"a map part's `{name}` has {len(col)} entries, `omega` {size}")
    if not all(ok(x) for x in col):
        bad = next(x for x in col if not ok(x))
        raise ValueError(f"a map part's `{name}` must hold {_KIND_WORDS[ok]}, got {bad!r}"[:300])
    return col


def _field(data: dict[str, Any], name: str, kind: type, default: Any) -> Any:
    value = data.get(name, default)
    if not isinstance(value, kind):
        raise ValueError(f"a map part's `{name}` must be a {kind.__name__}, got {type(value).__name__}")
    return value


def _float(x: Any) -> float | None:
    x = float(x)
    return None if math.isnan(x) else x


@dataclass(frozen=True)
class CellResult:
    """What one combination of the varied parameters gives on the map's Ω grid.

    Attributes
    ----------
    values : dict[str, float]
        The varied parameters' values, by their NAME.
    omega : ndarray (N,)
        The map's frequency grid.
    n_solutions, n_stable : ndarray of int (N,)
    rms_max_stable, rms_ac_max_stable : ndarray of float (N,), NaN where no stable period-1 solution
    regime_max_stable : ndarray of str (N,)
    periods_stable : ndarray of str (N,)
    rattle : ndarray of bool (N,)
    special_points : list of dict
        ``kind``, ``omega``, ``branch``, ``period``, ``rms`` of every labelled point of every branch.
    intervals : dict[str, list[[lo, hi]]]
        Ω intervals (grid-resolved: first and last grid frequency of a run) of every kind in
        :data:`INTERVAL_KINDS`: ``impact`` (rattle true), ``rattle_free`` (false), ``subharmonic``
        (a stable solution of period ≥ 2), ``nonperiodic`` (a non-periodic attractor, period 0).
    attractors : list of dict
        What the attractor search found that the branches did not explain (``omega``,
        ``period``, ``origin``, ``branch``: the id of the branch continued from it, or None).
    search : dict
        The search's budget and counts (simulations run, seeds, branches added).
    status : str
        ``"ok"``, or ``"partial"`` (the primary branch stopped early; ``message`` says why), or
        ``"failed"`` (nothing computed; ``message``).
    message : str
    timings : dict[str, float]
        Seconds per stage (``frequency_response``, ``grid``, ``search``, ``total``).
    resumed : bool
        Read back from a finished earlier run instead of computed.
    spl_max_stable_db : ndarray of float (N,), or None
        With sound paths: the largest sound pressure level (dB re 20 µPa) over the stable
        periodic solutions at Ω (NaN where none); None for a map without paths.
    """

    values: dict[str, float]
    omega: np.ndarray
    n_solutions: np.ndarray
    n_stable: np.ndarray
    rms_max_stable: np.ndarray
    rms_ac_max_stable: np.ndarray
    regime_max_stable: np.ndarray
    periods_stable: np.ndarray
    rattle: np.ndarray
    special_points: list[dict[str, Any]] = field(default_factory=list)
    intervals: dict[str, list[list[float]]] = field(default_factory=dict)
    attractors: list[dict[str, Any]] = field(default_factory=list)
    search: dict[str, Any] = field(default_factory=dict)
    status: str = "ok"
    message: str = ""
    timings: dict[str, float] = field(default_factory=dict)
    resumed: bool = False
    spl_max_stable_db: np.ndarray | None = None

    def columns(self) -> dict[str, np.ndarray]:
        """The per-frequency columns (``omega`` and :data:`GRID_COLUMNS`, then
        ``spl_max_stable_db`` with sound paths)."""
        sound = {} if self.spl_max_stable_db is None else {SOUND_COLUMN: self.spl_max_stable_db}
        return {"omega": self.omega, **{k: getattr(self, k) for k in GRID_COLUMNS}, **sound}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (floats exact: ``json`` writes ``repr``; NaN as null)."""
        sound = {} if self.spl_max_stable_db is None else {
            SOUND_COLUMN: [_float(x) for x in self.spl_max_stable_db]}
        return {
            "values": dict(self.values),
            "omega": [float(x) for x in self.omega],
            "n_solutions": [int(x) for x in self.n_solutions],
            "n_stable": [int(x) for x in self.n_stable],
            "rms_max_stable": [_float(x) for x in self.rms_max_stable],
            "rms_ac_max_stable": [_float(x) for x in self.rms_ac_max_stable],
            "regime_max_stable": [str(x) for x in self.regime_max_stable],
            "periods_stable": [str(x) for x in self.periods_stable],
            "rattle": [bool(x) for x in self.rattle],
            "special_points": self.special_points,
            "intervals": self.intervals,
            "attractors": self.attractors,
            "search": self.search,
            "status": self.status,
            "message": self.message,
            "timings": self.timings,
            **sound,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any], *, resumed: bool = False) -> "CellResult":
        """The inverse of :meth:`to_dict` (``resumed`` marks a result read back from disk).

        Every field is checked, since the dict may come from a damaged file: the grid columns
        present, lists of one length of the right kind (numbers, None for NaN, strings, booleans),
        the tables of the right shape.

        Raises
        ------
        ValueError
            Naming the first field that is missing or wrong (``a map part's `omega`: …``).
        """
        if not isinstance(data, dict):
            raise ValueError(f"a map part must be a JSON object, got {type(data).__name__}")
        nan = float("nan")
        missing = [k for k in ("values", *MAP_COLUMNS) if k not in data]
        if missing:
            raise ValueError(f"a map part lacks {', '.join(f'`{k}`' for k in missing)}")
        values = data["values"]
        if not isinstance(values, dict) or not all(isinstance(k, str) and _is_real(v) for k, v in values.items()):
            raise ValueError("a map part's `values` must map names to numbers")
        omega = _column(data, "omega", _is_real)
        size = len(omega)
        n_solutions = _column(data, "n_solutions", _is_count, size)
        n_stable = _column(data, "n_stable", _is_count, size)
        rms = _column(data, "rms_max_stable", _is_real_or_none, size)
        rms_ac = _column(data, "rms_ac_max_stable", _is_real_or_none, size)
        regime = _column(data, "regime_max_stable", _is_str, size)
        periods = _column(data, "periods_stable", _is_str, size)
        rattle = _column(data, "rattle", _is_bool, size)
        spl = data.get(SOUND_COLUMN)
        if spl is not None:
            spl = _column(data, SOUND_COLUMN, _is_real_or_none, size)
        special_points = _field(data, "special_points", list, [])
        attractors = _field(data, "attractors", list, [])
        if not all(isinstance(x, dict) for x in (*special_points, *attractors)):
            raise ValueError("a map part's `special_points` and `attractors` must be lists of tables")
        intervals = _field(data, "intervals", dict, {})
        for kind, runs in intervals.items():
            if not (isinstance(runs, list) and all(isinstance(iv, list) and len(iv) == 2 and all(map(_is_real, iv))
                                                   for iv in runs)):
                raise ValueError(f"a map part's `intervals.{kind}` must be a list of [first, last] numbers")
        timings = _field(data, "timings", dict, {})
        if not all(_is_real(v) for v in timings.values()):
            raise ValueError("a map part's `timings` must map stages to numbers of seconds")
        status = _field(data, "status", str, "ok")
        if status not in ("ok", "partial", "failed"):
            raise ValueError(f"a map part's `status` must be ok, partial or failed, got {status!r}")
        return cls(
            values={k: float(v) for k, v in values.items()},
            omega=np.asarray(omega, dtype=float),
            n_solutions=np.asarray(n_solutions, dtype=int),
            n_stable=np.asarray(n_stable, dtype=int),
            rms_max_stable=np.asarray([nan if x is None else x for x in rms], dtype=float),
            rms_ac_max_stable=np.asarray([nan if x is None else x for x in rms_ac], dtype=float),
            regime_max_stable=np.asarray(regime, dtype=object),
            periods_stable=np.asarray(periods, dtype=object),
            rattle=np.asarray(rattle, dtype=bool),
            special_points=list(special_points),
            intervals={k: [[float(a), float(b)] for a, b in v] for k, v in intervals.items()},
            attractors=list(attractors),
            search=dict(_field(data, "search", dict, {})),
            status=status,
            message=_field(data, "message", str, ""),
            timings={k: float(v) for k, v in timings.items()},
            resumed=resumed,
            spl_max_stable_db=None if spl is None else np.asarray([nan if x is None else x for x in spl], dtype=float),
        )

    def check_against(self, values: dict[str, float], omega: np.ndarray) -> None:
        """Raise ValueError unless this cell is of the combination ``values`` on the grid ``omega``
        (a part read back must be the one its key names: same values, same grid, bit for bit)."""
        if self.omega.shape != np.shape(omega):
            raise ValueError(f"a map part's `omega` has {self.omega.size} frequencies, the map's grid "
                             f"{np.size(omega)}")
        if self.omega.tobytes() != np.asarray(omega, dtype=float).tobytes():
            raise ValueError("a map part's `omega` is not the map's grid")
        if set(self.values) != set(values) or any(self.values[k] != float(v) for k, v in values.items()):
            raise ValueError(f"a map part's `values` {self.values} are not the combination's {values}")

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), allow_nan=False)


@dataclass(frozen=True)
class Parameter:
    """A varied parameter: its NAME (as given: a short name or a dotted key), the dotted key of
    the configuration it sets, and its values (in the configuration's base unit: angles in rad).

    ``degrees``: the angle was given in degrees in the case file (a ``KEY_deg`` key, or a damper's
    angles in degrees: :func:`rattle.maps.mark_degrees`); reports then show its values in
    degrees, value × 180/π (the files keep rad)."""

    name: str
    key: str
    values: tuple[float, ...]
    degrees: bool = False

    def shown(self, value: float) -> float:
        """``value`` as reports show it: in degrees when the case gave the angle in degrees."""
        return math.degrees(value) if self.degrees else float(value)

    @property
    def unit(self) -> str:
        """``"deg"`` when the reports show degrees, else ``""`` (the key's own unit)."""
        return "deg" if self.degrees else ""


@dataclass(frozen=True)
class ResponseMap:
    """A response map (SPEC §7): the cells of every combination of the varied ``parameters``
    (C order: the last parameter varies fastest), on the Ω grid ``omega``.

    ``dataset`` is the same content as an :class:`xarray.Dataset` with one dimension per varied
    parameter (named by its NAME) and ``omega``. ``paths``: the sound paths
    (:class:`rattle.model.SoundPath`) the map was computed with, if any (column
    ``spl_max_stable_db``).
    """

    parameters: tuple[Parameter, ...]
    omega: np.ndarray
    cells: tuple[CellResult, ...]
    settings: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    config: dict[str, Any] = field(default_factory=dict)
    speed_order: float | None = None
    paths: tuple[Any, ...] = ()

    @property
    def has_sound(self) -> bool:
        """Whether the map was computed with sound paths (``paths``): then ``map.csv`` and the
        dataset carry ``spl_max_stable_db``."""
        return bool(self.paths)

    @property
    def speed_rpm(self) -> np.ndarray | None:
        """The grid as crankshaft speed (rpm) when the model has an engine (``[engine]``: Ω is
        ``speed_order`` × the crankshaft speed), else None: rpm = Ω · 60 / (2π · order), rounded
        to a millionth of the grid's step (:func:`rattle.results.round_to_grid`)."""
        if self.speed_order is None:
            return None
        from ..results import round_to_grid, rpm_of_omega

        rpm = rpm_of_omega(np.asarray(self.omega, dtype=float), float(self.speed_order))
        # the grid is equally spaced: its rpm as round as the range given (800, not 799.9999999999999)
        return round_to_grid(rpm, float(rpm[0]), float(rpm[-1]), rpm.size) if rpm.size else rpm

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(p.values) for p in self.parameters)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    def cell(self, *index: int) -> CellResult:
        """The cell of the combination with these parameter indices."""
        return self.cells[int(np.ravel_multi_index(index, self.shape))]

    def combinations(self) -> list[tuple[tuple[int, ...], dict[str, float]]]:
        """(index, values by NAME) of every combination, in cell order."""
        out = []
        for flat in range(len(self.cells)):
            idx = tuple(int(i) for i in np.unravel_index(flat, self.shape))
            out.append((idx, {p.name: p.values[i] for p, i in zip(self.parameters, idx)}))
        return out

    @property
    def dataset(self) -> "xr.Dataset":
        """The map as an xarray Dataset: dims (NAME…, omega); data variables the
        :data:`GRID_COLUMNS`, plus per combination ``status`` and ``seconds``; attributes: the
        settings and the varied keys (JSON)."""
        import xarray as xr

        shape = self.shape + (self.omega.size,)
        dims = (*self.names, "omega")
        data: dict[str, Any] = {}
        for col in GRID_COLUMNS:
            stack = np.stack([np.asarray(getattr(c, col)) for c in self.cells]) if self.cells else np.empty((0,))
            if col in ("regime_max_stable", "periods_stable"):
                stack = stack.astype(str)
            data[col] = (dims, stack.reshape(shape))
        if self.has_sound:
            data[SOUND_COLUMN] = (dims, np.stack([_spl(c, self.omega.size) for c in self.cells]).reshape(shape))
        data["status"] = (self.names, np.asarray([c.status for c in self.cells], dtype=str).reshape(self.shape))
        data["seconds"] = (self.names, np.asarray([c.timings.get("total", np.nan) for c in self.cells],
                                                  dtype=float).reshape(self.shape))
        coords: dict[str, Any] = {p.name: np.asarray(p.values, dtype=float) for p in self.parameters}
        coords["omega"] = self.omega
        if self.speed_order is not None:
            coords["speed_rpm"] = ("omega", self.speed_rpm)
        attrs = {
            "title": "rattle response map",
            "varied_keys": json.dumps({p.name: p.key for p in self.parameters}),
            "settings": json.dumps(self.settings, default=str),
        }
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def rows(self) -> list[dict[str, Any]]:
        """``map.csv`` rows: per (combination, frequency) the varied values by NAME, then
        :data:`MAP_COLUMNS` (then ``speed_rpm`` when the model has an engine, then
        ``spl_max_stable_db`` with sound paths). A combination whose frequency response failed (status
        ``failed``) knows nothing: its grid columns are None (empty in the CSV), never a
        ``rattle`` = false it did not establish."""
        out = []
        rpm = self.speed_rpm
        for (_, values), c in zip(self.combinations(), self.cells):
            cols = c.columns()
            known = c.status != "failed"
            for j in range(self.omega.size):
                row = {**values, "omega": cols["omega"][j], **{k: (cols[k][j] if known else None) for k in GRID_COLUMNS}}
                if rpm is not None:
                    row["speed_rpm"] = float(rpm[j])
                if self.has_sound:
                    row[SOUND_COLUMN] = float(_spl(c, self.omega.size)[j]) if known else None
                out.append(row)
        return out

    @property
    def column_names(self) -> list[str]:
        """``map.csv`` header: the varied NAMEs, then :data:`MAP_COLUMNS`, then ``speed_rpm`` when
        the model has an engine, then ``spl_max_stable_db`` with sound paths."""
        return [*self.names, *MAP_COLUMNS, *(["speed_rpm"] if self.speed_order is not None else []),
                *([SOUND_COLUMN] if self.has_sound else [])]

    def columns(self) -> dict[str, list[Any]]:
        """``map.csv`` as columns of plain Python values (None where empty: NaN rms, and every
        grid column of a failed combination)."""
        out: dict[str, list[Any]] = {name: [] for name in self.column_names}
        for row in self.rows():
            for name in out:
                value = row[name]
                if hasattr(value, "item"):  # numpy scalar → Python
                    value = value.item()
                if isinstance(value, float) and math.isnan(value):
                    value = None
                out[name].append(value)
        return out

    def to_csv(self, path: Any) -> Any:
        """Write ``map.csv`` (SPEC §7) to ``path`` atomically; returns the path."""
        from pathlib import Path

        from ..files import write_csv

        write_csv(path, self.columns(), self.column_names)
        return Path(path)

    def to_netcdf(self, path: Any) -> Any:
        """Write :attr:`dataset` to ``path`` as NetCDF (version 3 through scipy: no extra
        dependency), atomically; returns the path."""
        from pathlib import Path

        from ..files import atomic_path

        with atomic_path(path) as tmp:
            self.dataset.to_netcdf(tmp, engine="scipy")
        return Path(path)

    def plot(self, parameter: str | None = None, **kwargs: Any) -> Any:
        """Heat map of the largest stable rms over (parameter, Ω), impacts hatched, the
        rattle-free region outlined; returns (figure, PlotAxes). See
        :func:`rattle.plotting.plot_map`."""
        from ..results import plot_with  # the plotting layer by name: maps do not import it

        return plot_with("plot_map", self, parameter=parameter, **kwargs)

    def rattle_free_region(self) -> list[dict[str, Any]]:
        """Per combination, its values and its rattle-free Ω intervals."""
        return [{"values": v, "rattle_free": c.intervals.get("rattle_free", [])}
                for (_, v), c in zip(self.combinations(), self.cells)]


__all__ = ["CellResult", "ResponseMap", "Parameter", "GRID_COLUMNS", "MAP_COLUMNS", "INTERVAL_KINDS", "grid_runs",
           "SOUND_COLUMN"]
