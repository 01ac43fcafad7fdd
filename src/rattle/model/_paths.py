"""Sound paths: a measured (or computed) linear transfer from a rattle source to a receiver.

A :class:`SoundPath` carries one frequency response function H(f) = p / q'' (Pa per rad/s²) from
a source's torsional acceleration q'' to the sound pressure p at the receiver, as a table of
frequency (Hz), magnitude and phase (degrees) — the path terms (p/q'')_ij of the paper's eq. (1).

Between table rows H is interpolated linearly in magnitude and linearly in the *unwrapped*
phase (so a phase that runs through ±180° between two rows is not interpolated the long way
round). Outside the table's frequency range the transmission is taken as zero — nothing is
extrapolated — and :func:`rattle.results.sound_pressure` reports how much of the source's
content fell outside (and warns).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._limits import MAX_MAGNITUDE
from .._typing import FloatArray
from .._validate import check_vector

__all__ = ["SoundPath", "parse_source", "check_source", "MAX_PATH_MAGNITUDE", "MAX_PHASE_DEG", "path_value_rule"]

_INERTIA = re.compile(r"inertia:([0-9]+)")

#: Largest number of rows of a path table.
MAX_PATH_ROWS = 1_000_000
#: Largest |H| (Pa per rad/s²) of a path table: the magnitude bound of every physical number
#: (``rattle._limits.MAX_MAGNITUDE``), so that the pressure's harmonics, their squares and the
#: level in dB stay finite (1e300 wrote ``inf`` into ``spl_db``).
MAX_PATH_MAGNITUDE = MAX_MAGNITUDE
#: Largest |phase| (degrees) of a path table: an unwrapped phase of a measured transfer runs
#: through a few thousand turns at most (a 10 ms delay is 36 000° at 10 kHz); beyond 10⁶° (2 778
#: turns) the phase is not known to a degree in double precision any more, let alone 1e300.
MAX_PHASE_DEG = 1e6


def path_value_rule(column: str, value: float, at: str = "") -> str | None:
    """Why ``value`` (finite) is refused in ``column`` of a path table (``magnitude`` ≥ 0 and
    ≤ :data:`MAX_PATH_MAGNITUDE`; ``phase_deg`` within ±:data:`MAX_PHASE_DEG`), or None; ``at``
    follows the value shown (`` at row 3``)."""
    if column == "magnitude":
        if value < 0:
            return (f"`magnitude` must be >= 0 (a modulus, Pa per rad/s²; put the sign in `phase_deg`, +180), "
                    f"got {value!r}{at}")
        if value > MAX_PATH_MAGNITUDE:
            return (f"`magnitude` must be <= {MAX_PATH_MAGNITUDE:g} Pa per rad/s² (a physical transfer from "
                    f"torsional acceleration to sound pressure; a larger one makes the sound pressure level "
                    f"overflow to inf), got {value!r}{at}; check the column's unit")
    if column == "phase_deg" and abs(value) > MAX_PHASE_DEG:
        return (f"`phase_deg` must lie within ±{MAX_PHASE_DEG:g} degrees (an unwrapped phase of a few thousand "
                f"turns at most; beyond, double precision does not hold it to a degree), got {value!r}{at}; give the "
                "phase in degrees, wrapped or unwrapped")
    return None


def parse_source(source: str, name: str = "source") -> tuple[str, int | str]:
    """``("inertia", N)`` for ``"inertia:N"`` (1-based), else ``("element", name)``."""
    if not isinstance(source, str) or not source:
        raise TypeError(f"`{name}` must be an element name or \"inertia:N\", got {source!r}")
    m = _INERTIA.fullmatch(source.strip())
    if m:
        return "inertia", int(m.group(1))
    if source.startswith("inertia"):
        raise ValueError(f"`{name}` {source!r} must be \"inertia:N\" with N a whole inertia number (from 1), "
                         "e.g. \"inertia:2\"")
    return "element", source


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class SoundPath:
    """A path from a rattle source to the receiver: H(f) = p / q'' tabulated at ``frequency_hz``.

    Parameters
    ----------
    source : str
        An element name (its deflection acceleration δ''; the single-equation model's element is
        ``"delta"``) or ``"inertia:N"`` (the absolute angular acceleration θ''_N of inertia N,
        numbered from 1; chains only).
    frequency_hz : sequence of float, shape (R,)
        Frequencies (Hz), finite, > 0, strictly increasing; R ≥ 1.
    magnitude : sequence of float, shape (R,)
        |H| (Pa per rad/s²), finite, 0 … :data:`MAX_PATH_MAGNITUDE` (1e50).
    phase_deg : sequence of float, shape (R,)
        arg H (degrees), finite, within ±:data:`MAX_PHASE_DEG` (10⁶); unwrapped before
        interpolation.
    name : str, optional
        A label for messages (e.g. the CSV file it was read from).

    Notes
    -----
    ``response(f)`` interpolates linearly in |H| and in the unwrapped phase; outside
    [frequency_hz[0], frequency_hz[-1]] it is 0 (no extrapolation; see :meth:`covers`). A table
    of one row is a single frequency: only that frequency is transmitted.
    """

    source: str
    frequency_hz: FloatArray
    magnitude: FloatArray
    phase_deg: FloatArray
    name: str = ""

    def __post_init__(self) -> None:
        parse_source(self.source)
        if not isinstance(self.name, str):
            raise TypeError(f"`name` must be a string, got {self.name!r}")
        f = check_vector(self.frequency_hz, "frequency_hz")
        mag = check_vector(self.magnitude, "magnitude")
        ph = check_vector(self.phase_deg, "phase_deg")
        if f.size == 0:
            raise ValueError("`frequency_hz` must hold at least one frequency, got none")
        if f.size > MAX_PATH_ROWS:
            raise ValueError(f"`frequency_hz` must hold at most {MAX_PATH_ROWS} rows, got {f.size}")
        if mag.size != f.size or ph.size != f.size:
            raise ValueError(f"`magnitude` and `phase_deg` must have one entry per frequency ({f.size}), "
                             f"got {mag.size} and {ph.size}")
        if f[0] <= 0:
            raise ValueError(f"`frequency_hz` must be > 0 Hz, got {f[0]!r} at row 0")
        steps = np.flatnonzero(np.diff(f) <= 0)
        if steps.size:
            i = int(steps[0])
            raise ValueError(f"`frequency_hz` must be strictly increasing, got {f[i]!r} then {f[i + 1]!r} "
                             f"at rows {i} and {i + 1}; sort the table and remove repeated frequencies")
        for column, values in (("magnitude", mag), ("phase_deg", ph)):
            limit = MAX_PATH_MAGNITUDE if column == "magnitude" else MAX_PHASE_DEG
            bad = np.flatnonzero((values < 0) | (values > limit)) if column == "magnitude" \
                else np.flatnonzero(np.abs(values) > limit)
            if bad.size:
                row = int(bad[0])
                raise ValueError(path_value_rule(column, float(values[row]), f" at row {row}"))
        object.__setattr__(self, "source", self.source.strip())
        object.__setattr__(self, "frequency_hz", f)
        object.__setattr__(self, "magnitude", mag)
        object.__setattr__(self, "phase_deg", ph)

    @staticmethod
    def value_rule(column: str, value: float, at: str = "") -> str | None:
        """Why the finite ``value`` is refused in ``column`` (``magnitude``, ``phase_deg``) of a
        path table, or None (:func:`path_value_rule`: the readers of path files use it per line)."""
        return path_value_rule(column, value, at)

    @property
    def kind(self) -> str:
        """``"element"`` or ``"inertia"``."""
        return parse_source(self.source)[0]

    @property
    def target(self) -> int | str:
        """The element name, or the inertia number (from 1)."""
        return parse_source(self.source)[1]

    @property
    def frequency_range(self) -> tuple[float, float]:
        """(lowest, highest) tabulated frequency in Hz."""
        return float(self.frequency_hz[0]), float(self.frequency_hz[-1])

    def covers(self, f_hz: FloatArray | float) -> np.ndarray:
        """True where ``f_hz`` lies within the table's range (boolean array of f_hz's shape)."""
        f = np.asarray(f_hz, dtype=float)
        lo, hi = self.frequency_range
        return (f >= lo) & (f <= hi)

    def response(self, f_hz: FloatArray | float) -> np.ndarray | complex:
        """H(f) (Pa per rad/s², complex) at frequencies ``f_hz`` (Hz, any shape): |H| and the
        unwrapped phase interpolated linearly between rows; 0 outside the table's range."""
        f = np.asarray(f_hz, dtype=float)
        mag = np.interp(f, self.frequency_hz, self.magnitude)
        ph = np.interp(f, self.frequency_hz, np.unwrap(self.phase_deg, period=360.0))
        out = np.where(self.covers(f), mag * np.exp(1j * np.deg2rad(ph)), 0.0 + 0.0j)
        return complex(out) if out.ndim == 0 else out

    def __repr__(self) -> str:
        lo, hi = self.frequency_range
        label = f", {self.name!r}" if self.name else ""
        return f"SoundPath({self.source!r}{label}, {self.frequency_hz.size} rows, {lo:g} … {hi:g} Hz)"

    def to_dict(self) -> dict[str, object]:
        """Source, name, row count and frequency range (for run metadata)."""
        return {"source": self.source, "name": self.name, "rows": int(self.frequency_hz.size),
                "frequency_range_hz": list(self.frequency_range)}


def check_source(source: str, model: Any, name: str = "source") -> None:
    """Refuse a source that names no element of ``model`` or an inertia out of range."""
    kind, target = parse_source(source, name)
    system = model.system()
    if kind == "element":
        names = [e.name for e in system.elements]
        if target not in names:
            raise ValueError(f"`{name}` must name an element of the model ({', '.join(map(repr, names))}) or be "
                             f"\"inertia:N\", got {source!r}")
        return
    if not hasattr(model, "inertias"):
        raise ValueError(
            f"`{name}` {source!r}: the single-equation model knows only the effective inertia, not I1 and I2, "
            "so an inertia's absolute acceleration is not defined; use the element \"delta\", or write the model "
            "as a two-inertia chain ([model] inertias = [I1, I2], SPEC §5)")
    n_inertias = system.angles.shape[0]
    if not 1 <= int(target) <= n_inertias:
        raise ValueError(f"`{name}` {source!r} must name an inertia 1 … {n_inertias}, got inertia {target}")
