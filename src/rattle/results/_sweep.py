"""Columnar result of a time-domain frequency sweep (``rattle sweep``)."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from .._typing import BoolArray, ComplexArray, FloatArray, IntArray
from ._columns import SWEEP_COLUMNS
from ._steady import METHOD_STATUS
from ..model import Model
from ._plotter import plot_with
from ._speed import SpeedText, round_to_grid, rpm_of_omega

#: Per-element columns of a chain's ``sweep.csv``: ``NAME_`` + each of these (the measures of
#: element NAME's deflection, as the SPEC columns are of the first element's).
SWEEP_ELEMENT_COLUMNS: tuple[str, ...] = ("mean", "rms", "rms_ac", "p2p", "acc_p2p")

#: ``SteadyStateOptions.record_periods`` when a result's settings do not say (its default).
_RECORD_PERIODS = 50

#: Sweep directions, in the order ``both`` runs them.
SWEEP_DIRECTIONS: tuple[str, ...] = ("up", "down")

#: ``method`` of a failed row: the steady state at its frequency raised numerical trouble.
SWEEP_FAILED = "failed"
#: ``period`` of a failed row (0 keeps its meaning: a motion with no period up to the limit).
FAILED_PERIOD = -1
#: Failed frequencies :attr:`SweepResult.message` lists per direction.
_LISTED = 10


class _JumpFields(NamedTuple):
    direction: str
    omega_before: float
    omega_after: float
    rms_before: float
    rms_after: float


class Jump(_JumpFields):
    """An abrupt change of the rms between two consecutive frequencies of one sweep direction:
    ``direction``, ``omega_before`` → ``omega_after`` (rad/s, in sweep order) and the rms on
    either side (rad). A named tuple: unpacks in that order. On a chain, ``element`` names the
    element whose rms it is ("" for the single equation; an attribute, not unpacked)."""

    element: str

    def __new__(cls, direction: str, omega_before: float, omega_after: float, rms_before: float,
                rms_after: float, element: str = "") -> "Jump":
        self = super().__new__(cls, direction, omega_before, omega_after, rms_before, rms_after)
        self.element = element
        return self

    @property
    def omega(self) -> float:
        """The jump frequency: midway between ``omega_before`` and ``omega_after``."""
        return 0.5 * (self.omega_before + self.omega_after)

    @property
    def kind(self) -> str:
        """``up`` when the rms jumps up, ``down`` when it drops."""
        return "up" if self.rms_after > self.rms_before else "down"


def _jump_steps(w: FloatArray, r: FloatArray, threshold: float) -> list[tuple[int, float]]:
    """The steps i (row i → i + 1) of one sweep direction that are jumps (see
    :meth:`SweepResult.jumps`), with their relative change."""
    c = np.diff(r)
    dw = np.diff(w)
    rel = np.abs(c) / np.maximum(np.maximum(np.abs(r[:-1]), np.abs(r[1:])), 1e-300)
    out = []
    for i in np.flatnonzero(rel > threshold).tolist():
        explained = False
        for j in (i - 1, i + 1):
            if 0 <= j < c.size and dw[j] != 0.0:
                trend = c[j] * dw[i] / dw[j]  # the neighbour's change, scaled to this step
                if trend * c[i] > 0.0 and abs(c[i]) <= 2.0 * abs(trend):
                    explained = True
                    break
        if not explained:
            out.append((i, float(rel[i])))
    return out


@dataclass(frozen=True, slots=True, eq=False)  # arrays: identity equality
class SweepResult:
    """Steady states along a stepped frequency sweep, one row per frequency, in sweep order
    (the up sweep first when both directions ran).

    Columns (numpy arrays of length P): SPEC §3 ``SWEEP_COLUMNS`` — ``direction`` (``up`` or
    ``down``), ``omega`` (rad/s), ``mean``, ``rms``, ``rms_ac``, ``p2p`` (rad), ``acc_p2p``
    (rad/s²), ``period`` (multiple of the forcing period, 0 when none up to the detection limit
    was found). Also ``regime`` (``no_impact``, ``single_sided``, ``double_sided`` as in SPEC §1:
    the breakpoints the row's steady motion crosses; written after ``period``), ``delta_min``,
    ``delta_max`` (rad), ``settled`` (bool), ``method``
    (``shooting``/``simulation``/``unsettled``; ``status`` the same as :class:`~rattle.errors.Status`
    values, as ``SteadyState.status``), ``periods`` and ``shooting_periods`` (forcing
    periods simulated and integrated by Newton shooting: the effort), ``state0`` (P, 2) the
    orbit's state on the Poincaré section, ``final_state`` (P, 2) the state carried to the next
    frequency, ``multipliers`` (P, 2) complex Floquet multipliers (NaN for period 0), and the
    provenance: ``model``, ``settings`` and ``timings`` (s).

    A chain (:class:`~rattle.model.Chain`): the SPEC columns measure its first clearance
    element; ``element_columns`` holds ``NAME_mean``, ``NAME_rms``, ``NAME_rms_ac``,
    ``NAME_p2p``, ``NAME_acc_p2p`` of every element NAME (:data:`SWEEP_ELEMENT_COLUMNS`),
    written after the SPEC columns; the states are z = (x, x') of its n coordinates ((P, 2n)),
    the multipliers (P, 2n).

    A discontinuous law (single-equation :class:`~rattle.model.System`: jumps and Coulomb friction on
    the single equation; :class:`~rattle.model.System` with its elements' whole laws: a chain with friction on its
    elements): the same columns, from its exact event-driven trajectories, and in
    ``extra_columns`` the fraction of each row's orbit (of its record for period 0) held stuck or
    locked — ``stick_fraction``, or ``NAME_stick_fraction`` per element of the chain.

    ``extra_columns``: columns written last, e.g. the stick fractions above or the sound pressure
    levels of :meth:`with_sound` (``spl_db``, ``spl_dba``, ``spl_linear_db``).

    A failed row — the steady state at its frequency raised numerical trouble (e.g. an exact
    event-driven flow that chatters into a lock beyond its event budget): ``omega`` and
    ``direction`` as given, every measure, state and multiplier NaN, ``period``
    :data:`FAILED_PERIOD` (−1), ``method`` ``"failed"``, ``settled`` False, no effort counted
    (``periods`` = ``shooting_periods`` = 0), and ``failure`` the reason (``""`` on every
    computed row). The sweep carried on from the last state computed. :attr:`complete` is False
    and :attr:`message` names the failed frequencies.
    """

    model: Model
    direction: np.ndarray
    omega: FloatArray
    mean: FloatArray
    rms: FloatArray
    rms_ac: FloatArray
    p2p: FloatArray
    acc_p2p: FloatArray
    period: IntArray
    delta_min: FloatArray
    delta_max: FloatArray
    settled: BoolArray
    method: np.ndarray
    periods: IntArray
    shooting_periods: IntArray
    state0: FloatArray
    final_state: FloatArray
    multipliers: ComplexArray
    settings: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    element_columns: dict[str, np.ndarray] = field(default_factory=dict)
    extra_columns: dict[str, np.ndarray] = field(default_factory=dict)
    failure: np.ndarray | None = None
    regime: np.ndarray | None = None
    #: The sound paths of :meth:`with_sound` (empty without): sweep.png draws the linear system's
    #: level through them on a dense Ω grid (closed form), not only at the rows' Ω.
    sound_paths: tuple[Any, ...] = ()

    def __post_init__(self) -> None:
        if self.failure is None:  # a sweep without failures: "" on every row
            object.__setattr__(self, "failure", np.full(int(np.size(self.omega)), "", dtype=object))
        if self.regime is None:  # not given by the sweep: from each row's extremes (frf.csv's rule)
            object.__setattr__(self, "regime", _regimes_from_extremes(self))

    # --- container protocol ----------------------------------------------------------------
    def __len__(self) -> int:
        return int(self.omega.size)

    def __getitem__(self, index: int) -> dict[str, Any]:
        """Row ``index`` as a dict of the SPEC columns."""
        return {name: getattr(self, name)[index] for name in SWEEP_COLUMNS}

    @property
    def status(self) -> np.ndarray:
        """How each row's steady state ended: an object array of :class:`~rattle.errors.Status`
        (``CONVERGED``, ``SETTLED`` or ``MAX_PERIODS``, as ``SteadyState.status``), read from
        ``method``; None on a failed row (no steady state: its reason in ``failure``)."""
        return np.array([METHOD_STATUS.get(str(m)) for m in self.method], dtype=object)

    @property
    def failed(self) -> BoolArray:
        """True on the rows whose steady state failed (``method`` ``"failed"``)."""
        return np.asarray(self.method) == SWEEP_FAILED

    @property
    def complete(self) -> bool:
        """True when every row was computed (no failed row)."""
        return not bool(np.any(self.failed))

    @property
    def message(self) -> str:
        """``""`` for a complete sweep; else one line naming the failed frequencies of each
        direction (the first :data:`_LISTED` of them) and the first row's reason (with how many
        other reasons there are: every row's is in ``failure``)."""
        if self.complete:
            return ""
        rows = np.flatnonzero(self.failed)
        reasons = list(dict.fromkeys(str(r) for r in self.failure[rows]))  # type: ignore[index]
        i = int(rows[0])
        text = (f"no steady state at {rows.size} of {len(self)} frequencies ({self._failed_text()}; recorded as "
                f"failed rows, the sweep carried on from the last state computed): at {self.direction[i]} "
                f"{SpeedText.of(self.model).at(self.omega[i], 6)}: {reasons[0]}")
        if len(reasons) > 1:
            text += f" (and {len(reasons) - 1} other reason{'s' if len(reasons) > 2 else ''} at other rows)"
        return text

    def _failed_text(self) -> str:
        """The failed frequencies by direction (the first :data:`_LISTED` of each)."""
        where = []
        for d in self.directions:
            w = self.omega[(self.direction == d) & self.failed]
            if w.size:
                more = f", … ({w.size} in all)" if w.size > _LISTED else ""
                where.append(f"{d} sweep {SpeedText.of(self.model).values(w[:_LISTED], 6)}{more}")
        return "; ".join(where)

    @property
    def directions(self) -> tuple[str, ...]:
        """The directions present, in sweep order."""
        return tuple(d for d in SWEEP_DIRECTIONS if np.any(self.direction == d))

    def select(self, direction: str) -> "SweepResult":
        """The rows of one ``direction`` (``up`` or ``down``) as a SweepResult."""
        if direction not in SWEEP_DIRECTIONS:
            raise ValueError(f"`direction` must be one of {', '.join(SWEEP_DIRECTIONS)}, got {direction!r}")
        rows = np.flatnonzero(self.direction == direction)
        values = {name: getattr(self, name)[rows] for name in _ROW_FIELDS}
        return SweepResult(model=self.model, settings=self.settings, timings=self.timings,
                           element_columns={k: v[rows] for k, v in self.element_columns.items()},
                           extra_columns={k: v[rows] for k, v in self.extra_columns.items()},
                           sound_paths=self.sound_paths, **values)

    def __repr__(self) -> str:
        parts = []
        for d in self.directions:
            m = self.direction == d
            counts = np.bincount(self.period[m & ~self.failed], minlength=1)
            per = ", ".join(f"{int(c)}×P{p}" for p, c in enumerate(counts) if c)
            failed = int(np.sum(m & self.failed))
            if failed:
                per += (", " if per else "") + f"{failed} failed"
            parts.append(f"{d}: {int(np.sum(m))} points ({per})")
        span = f"Ω = {self.omega.min():.4g}…{self.omega.max():.4g}" if len(self) else "empty"
        return f"SweepResult({span}; {'; '.join(parts)}; jumps at {self._jump_text()})"

    def _jump_text(self) -> str:
        jumps = self.jumps()
        if not jumps:
            return "none"
        return ", ".join(f"Ω ≈ {j.omega:.4g} ({j.direction} sweep, rms {j.kind})" for j in jumps)

    def columns(self) -> dict[str, np.ndarray]:
        """The SPEC columns in order and ``regime`` (of each row's steady motion, SPEC §1's
        vocabulary; empty on a failed row), as a dict of arrays; for a chain followed by the
        per-element columns (``NAME_mean`` … ``NAME_acc_p2p``), then ``speed_rpm`` with an engine,
        then the extra columns (``spl_db``, ``spl_dba``, ``spl_linear_db`` of :meth:`with_sound`)."""
        rpm = self.speed_rpm
        return {**{name: getattr(self, name) for name in SWEEP_COLUMNS}, "regime": self.regime,
                **self.element_columns,
                **({} if rpm is None else {"speed_rpm": rpm}), **self.extra_columns}

    @property
    def speed_rpm(self) -> FloatArray | None:
        """Crankshaft speed (rpm) of each row when the model has an engine (``Chain.speed_order``
        q_0): Ω · 60 / (2π q_0), rounded to a millionth of the grid's step
        (:func:`~rattle.results._speed.round_to_grid`: the speeds 400, 500, … of a grid the user
        gave in rpm, not 499.99999999999994); None otherwise."""
        order = getattr(self.model, "speed_order", None)
        if order is None:
            return None
        rpm = rpm_of_omega(np.asarray(self.omega, dtype=float), order)
        grid = self.settings.get("omega"), self.settings.get("points")
        if isinstance(grid[0], (list, tuple)) and len(grid[0]) == 2 and isinstance(grid[1], int):
            lo, hi = (float(rpm_of_omega(float(w), order)) for w in grid[0])
            rpm = round_to_grid(rpm, lo, hi, grid[1])  # the rpm grid's round values, not their round-off
        return rpm

    @property
    def element_names(self) -> tuple[str, ...]:
        """Names of the clearance elements whose columns this result carries (a chain's)."""
        return tuple(k[: -len("_rms_ac")] for k in self.element_columns if k.endswith("_rms_ac"))

    def element(self, name: str) -> dict[str, np.ndarray]:
        """The measures of element ``name`` (``mean``, ``rms``, ``rms_ac``, ``p2p``, ``acc_p2p``)."""
        if name not in self.element_names:
            raise KeyError(f"`name` must be one of the elements {list(self.element_names)}, got {name!r}")
        return {c: self.element_columns[f"{name}_{c}"] for c in SWEEP_ELEMENT_COLUMNS}

    def summary(self) -> str:
        """A few lines for the terminal: points per direction, periods found, jumps, effort."""
        lines = []
        speed = SpeedText.of(self.model)  # rpm with an engine, else Ω
        for d in self.directions:
            m = self.direction == d
            w = self.omega[m]
            ok = ~self.failed[m]
            counts = np.bincount(self.period[m][ok], minlength=1)
            per = ", ".join(f"period {p}: {int(c)}" for p, c in enumerate(counts) if c and p)
            if counts[0]:
                per += (", " if per else "") + f"not periodic (period 0): {int(counts[0])}"
            if not ok.all():
                per += (", " if per else "") + f"failed: {int(np.sum(~ok))}"
            line = f"{d} sweep: {int(np.sum(m))} frequencies over {speed.span(w.min(), w.max(), 4)} ({per})"
            if ok.any():
                i = int(np.flatnonzero(ok)[np.argmax(self.rms[m][ok])])
                line += f"; largest rms {self.rms[m][i]:.5g} rad at {speed.at(w[i])}"
            lines.append(line)
        jumps = self.jumps()
        if jumps:
            lines.append("jumps: " + "; ".join(
                f"{j.direction} sweep, {j.element + ' ' if j.element else ''}rms {j.kind} {j.rms_before:.4g} → "
                f"{j.rms_after:.4g} rad between "
                + (f"{speed.number(j.omega_before)} and {speed.at(j.omega_after)}" if speed.engine
                   else f"{speed.at(j.omega_before)} and {speed.number(j.omega_after)}")
                for j in jumps))
        else:
            lines.append("jumps: none")
        for key, col in self.extra_columns.items():  # a discontinuous law: the time held stuck or locked
            if not key.endswith("stick_fraction") or not len(col):
                continue
            what = "held (stuck or locked)" if key == "stick_fraction" else f"{key[: -len('_stick_fraction')]} held"
            col = np.where(self.failed, -np.inf, np.asarray(col, dtype=float))  # a failed row holds nothing
            i = int(np.argmax(col))
            if not col[i] > 0.0:
                lines.append(f"{what}: never")
                continue
            lines.append(f"{what}: {int(np.sum(col > 0))} of {col.size} rows, at most {100 * col[i]:.3g} % of the "
                         f"period at {speed.at(self.omega[i])} ({self.direction[i]} sweep)")
        lines.append(
            f"effort: {int(np.sum(self.periods))} forcing periods simulated, "
            f"{int(np.sum(self.shooting_periods))} in Newton shooting"
        )
        if self.timings:
            lines.append("time: " + ", ".join(f"{k} {v:.3g} s" for k, v in self.timings.items()))
        if not self.complete:
            lines.append(f"failed (no steady state): {self._failed_text()}")
        return "\n".join(lines)

    def jumps(self, threshold: float = 0.15) -> list[Jump]:
        """Abrupt rms changes between consecutive frequencies of each direction, of every element.

        Failed rows are left out: the step is then taken between the computed rows on either side.
        A step c_i = r_{i+1} − r_i from row i to i + 1 of one direction is a jump when

        * the rms changes by more than ``threshold`` times the larger of the two values, and
        * the trend does not explain it: for each neighbouring step j = i − 1 and i + 1 that
          exists, with the neighbour's change scaled to this step, t_j = c_j Δω_i/Δω_j, the change
          has the other sign or is more than twice as large (c_i t_j ≤ 0 or |c_i| > 2 |t_j|).

        A steep but smooth resonance flank or a coarsely sampled peak changes like its neighbours
        (its change is explained from at least one side); a jump at a fold is not explained from
        either side, also at the end of a steep flank (the branch it leaves was steepening toward
        its fold) or at the last row of the sweep.

        On a chain every element's rms is examined (a jump of the response may be large in one
        element and small in the first): each step is reported once, for the element whose rms
        changes most there relative to its size (``element``; "" for the single equation).

        Parameters
        ----------
        threshold : float
            Relative rms change (default 0.15).

        Returns
        -------
        list of Jump
            In sweep order; each unpacks as (direction, omega_before, omega_after, rms_before,
            rms_after); ``element`` names the element on a chain.
        """
        if not (isinstance(threshold, (int, float)) and not isinstance(threshold, bool) and threshold > 0):
            raise ValueError(f"`threshold` must be a number > 0, got {threshold!r}")
        series = [("", self.rms)] if not self.element_names else \
            [(name, self.element_columns[f"{name}_rms"]) for name in self.element_names]
        out: list[Jump] = []
        for d in self.directions:
            rows = np.flatnonzero((self.direction == d) & ~self.failed)
            if rows.size < 2:
                continue
            w = self.omega[rows]
            found: dict[int, tuple[float, str]] = {}
            for name, col in series:
                r = np.asarray(col, dtype=float)[rows]
                for i, rel in _jump_steps(w, r, float(threshold)):
                    if i not in found or rel > found[i][0]:
                        found[i] = (rel, name)
            for i in sorted(found):
                name = found[i][1]
                r = self.rms[rows] if not name else np.asarray(self.element_columns[f"{name}_rms"])[rows]
                out.append(Jump(d, float(w[i]), float(w[i + 1]), float(r[i]), float(r[i + 1]), name))
        return out

    def metadata(self) -> dict[str, Any]:
        """Settings, timings, effort, periods found (of the computed rows) and jumps, JSON-serialisable;
        with failed rows also ``complete`` (False), ``message`` and ``failures`` (per failed row:
        ``direction``, ``omega``, ``reason``)."""
        ok = ~self.failed
        meta: dict[str, Any] = {
            "settings": self.settings,
            "timings": self.timings,
            "points": len(self),
            "directions": list(self.directions),
            "periods_found": {str(int(p)): int(c) for p, c in zip(*np.unique(self.period[ok], return_counts=True))},
            "effort": {
                "simulated_periods": int(np.sum(self.periods)),
                "shooting_periods": int(np.sum(self.shooting_periods)),
            },
            "jumps": [
                {"direction": j.direction, "omega_before": j.omega_before, "omega_after": j.omega_after,
                 "rms_before": j.rms_before, "rms_after": j.rms_after, **({"element": j.element} if j.element else {})}
                for j in self.jumps()
            ],
        }
        if not self.complete:
            meta["complete"] = False
            meta["message"] = self.message
            meta["failures"] = [{"direction": str(self.direction[i]), "omega": float(self.omega[i]),
                                 "reason": str(self.failure[i])}  # type: ignore[index]
                                for i in np.flatnonzero(self.failed)]
        return meta

    def records(self) -> Iterator[tuple[Any, int]]:
        """The recorded motion of every row, again: (exact trajectory from t = 0, window in forcing
        periods) — the orbit from ``state0`` over its ``period`` forcing periods, or for a
        non-periodic row (period 0) the record of ``record_periods`` forcing periods the sweep
        measured (``settings["steady_state"]``). The integrator is deterministic, so these are the
        trajectories the sweep's measures were taken on. A failed row has none: (None, 0)."""
        from ..timeint import make_integrator

        integ = make_integrator(self.model)  # the one choice of the exact integrator by kind of system
        record = int(self.settings.get("steady_state", {}).get("record_periods", _RECORD_PERIODS))
        for w, p, x, m in zip(self.omega, self.period, self.state0, self.method):
            if m == SWEEP_FAILED:
                yield None, 0
                continue
            window = int(p) if p > 0 else record
            yield integ.propagate(x, 0.0, window * 2.0 * np.pi / float(w), float(w)), window

    def with_sound(self, paths: Any) -> "SweepResult":
        """A copy with the sound pressure at the receiver of every row's simulated motion through
        ``paths`` (:class:`rattle.model.SoundPath` objects; :func:`rattle.results.motion_sound_pressure`
        on :meth:`records`): ``spl_db`` (dB re 20 µPa), ``spl_dba`` (A-weighted, dB(A)) and
        ``spl_linear_db`` (the linear system at the same Ω, :func:`rattle.results.linear_sound_pressure`),
        as :meth:`FrequencyResponse.with_sound <rattle.results.FrequencyResponse.with_sound>` does.
        A periodic row's level is that of its orbit's Fourier series; a non-periodic row's is an
        estimate from its record (rectangular window); a failed row's NaN. One warning names the row with the largest
        share of a source's content outside a path table, when any exceeds
        :data:`~rattle.results.UNCOVERED_WARNING`."""
        from ._sound import _warn_uncovered, check_sound_paths, linear_sound_pressure, motion_sound_pressure

        paths_t = check_sound_paths(paths, self.model)
        P = len(self)
        spl, dba = np.full(P, np.nan), np.full(P, np.nan)
        worst = None
        for i, (traj, window) in enumerate(self.records()):
            if traj is None:  # a failed row
                continue
            plain, weighted = motion_sound_pressure(self.model, traj, float(self.omega[i]), window, paths_t,
                                                    a_weighting=(False, True), warn=False)
            spl[i], dba[i] = plain.spl_db[0], weighted.spl_db[0]
            if worst is None or np.max(plain.uncovered) > np.max(worst.uncovered):
                worst = plain
        linear = np.full(P, np.nan)
        if P:
            with warnings.catch_warnings():  # the linear reference's harmonics lie within the sweep's
                warnings.simplefilter("ignore")
                linear = linear_sound_pressure(self.model, self.omega, paths_t).spl_db
        if worst is not None:
            _warn_uncovered(worst)
        return replace(self, extra_columns={**self.extra_columns, "spl_db": spl, "spl_dba": dba,
                                            "spl_linear_db": linear}, sound_paths=tuple(paths_t))

    # --- output delegates ------------------------------------------------------------------
    def to_csv(self, path: str | Path) -> Path:
        """Write the SPEC columns to ``path`` atomically (see ``rattle.io``)."""
        from ..files import write_csv

        cols = self.columns()
        write_csv(path, cols, list(cols))
        return Path(path)

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """rms vs Ω of each direction; returns (figure, :class:`rattle.plotting.PlotAxes`). See
        :func:`rattle.plotting.sweep_plot`."""
        return plot_with("sweep_plot", self, ax=ax, **kwargs)


_ROW_FIELDS: tuple[str, ...] = (
    "direction", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "period", "delta_min", "delta_max",
    "settled", "method", "periods", "shooting_periods", "state0", "final_state", "multipliers", "failure", "regime",
)


def _regimes_from_extremes(result: SweepResult) -> np.ndarray:
    """``regime`` of every row from its extremes ``delta_min``, ``delta_max`` and the breakpoints
    of the model's (first) element, as frf.csv's (:func:`rattle.measures.regime_of_breakpoints`);
    ``""`` on a failed row and where the model has no breakpoints to read. A sweep computed by
    :func:`rattle.time_sweep` gives each row's regime from the breakpoints its trajectory crossed
    instead (the same for a continuous law; a discontinuous law's jump at δ = 0 counts on
    neither side)."""
    from ..measures import regime_of_breakpoints

    n = int(np.size(result.omega))
    out = np.full(n, "", dtype=object)
    model = result.model
    if getattr(model, "discontinuous", False):  # jumps or friction: the regimes come with the rows, if at all
        return out
    try:
        system = model if hasattr(model, "elements") and not hasattr(model, "system") else model.system()
        d = np.asarray(system.elements[0].breakpoints, dtype=float)
    except (AttributeError, IndexError, TypeError):
        return out
    lo, hi = np.asarray(result.delta_min, dtype=float), np.asarray(result.delta_max, dtype=float)
    ok = np.isfinite(lo) & np.isfinite(hi)
    if ok.any():
        out[ok] = regime_of_breakpoints(d, lo[ok], hi[ok])
    return out

__all__ = ["SweepResult", "Jump", "SWEEP_DIRECTIONS", "SWEEP_COLUMNS", "SWEEP_ELEMENT_COLUMNS", "SWEEP_FAILED",
           "FAILED_PERIOD"]
