"""Measured data beside computed: a measured run-up against the harmonic balance and the
time-domain sweeps (``rattle compare --measured``).

A :class:`MeasuredRun` holds measured points: the forcing frequency Ω (rad/s) of each, the
crankshaft speed n (rpm) when the model has an engine (Ω = q_0 · 2π/60 · n, q_0 the model's
``speed_order``), and one or both of the quantities of :data:`MEASURED_QUANTITIES`:

- ``acc_p2p``: peak-to-peak of δ'' of the first clearance element (max δ'' − min δ'' over the
  steady motion), in the run's units (rad/s² in SI, dimensionless otherwise) — the SPEC column;
- ``spl_db``: sound pressure level at the receiver, L = 20 log10(p_rms / 20 µPa) dB (SPEC §6).

:func:`compare_measured` evaluates the computed values at every measured Ω:

- **HB** (``hb``): the largest value over the *stable segments* of the frequency response. A
  stable segment is a pair of consecutive points i, i+1 of one branch (continuation order) that
  are both stable; where Ω_i ≤ Ω ≤ Ω_{i+1} (either order) its value is the linear interpolation
  y_i + (Ω − Ω_i)(y_{i+1} − y_i)/(Ω_{i+1} − Ω_i). Every branch counts (a stable period-2 branch
  too); the HB value is the largest of the segments that cover Ω — the largest stable response
  the harmonic balance predicts there. None covers Ω (no stable solution computed there, or a
  segment across a stability change, which is left out): NaN.
- **sweep up / sweep down** (``sweep_up``, ``sweep_down``): the sweep points of that direction
  sorted by Ω, interpolated linearly in Ω (a jump between two grid frequencies is thus
  interpolated across). Outside the sweep's span, or a direction that was not run: NaN.
- **differences**: ``acc_p2p`` relative, (computed − measured)/measured; ``spl_db`` in dB,
  computed − measured. NaN where the computed value is NaN.

``spl_db`` of a sweep: the sweep's own ``spl_db`` column when its result carries one
(``SweepResult.columns()``); a sweep without it gives NaN there (the comparison of sound pressure
is then against the harmonic balance only) and :attr:`MeasuredComparison.missing` says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._typing import FloatArray
from .._validate import check_vector
from ._frequency_response import FrequencyResponse
from ._sweep import SweepResult

__all__ = ["MEASURED_QUANTITIES", "MeasuredRun", "MeasuredComparison", "compare_measured", "hb_largest_stable"]

#: Measured quantities that can be compared, in file order.
MEASURED_QUANTITIES: tuple[str, ...] = ("acc_p2p", "spl_db")
#: The computed curves each measured value is compared with, in file order.
COMPUTED: tuple[str, ...] = ("hb", "sweep_up", "sweep_down")
#: How each quantity's difference is formed, and the column suffix: relative or in dB.
DIFFERENCE_KIND: dict[str, str] = {"acc_p2p": "rel", "spl_db": "diff"}
#: Relative slack on the ends of a segment or a sweep span (round-off of rpm → Ω).
_END_SLACK = 1e-9
#: Measured points evaluated at once against the segments (bounds the (points × segments) work array).
_CHUNK = 512


@dataclass(frozen=True, slots=True, eq=False)
class MeasuredRun:
    """Measured points of a run-up (or run-down), in the order measured.

    Attributes
    ----------
    omega : numpy.ndarray
        Forcing frequency Ω of each point (rad/s), finite and > 0, strictly monotonic.
    values : dict
        Quantity (``acc_p2p`` and/or ``spl_db``) → measured values, one per point.
    speed_rpm : numpy.ndarray or None
        Crankshaft speed of each point (rpm) when the model has an engine, else None.
    source : str
        Where the points come from (the file name), for messages and the plot's legend.
    lines : tuple of int
        The line of the file each point was read from (empty when not read from a file).
    """

    omega: FloatArray
    values: dict[str, FloatArray]
    speed_rpm: FloatArray | None = None
    source: str = "measured"
    lines: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        omega = check_vector(self.omega, "omega")
        if omega.size == 0:
            raise ValueError("`omega` must hold at least one measured point, got none")
        if np.any(omega <= 0):
            raise ValueError(f"`omega` must be > 0 rad/s, got {omega[omega <= 0][0]!r}")
        if omega.size > 1:
            d = np.diff(omega)
            if not (np.all(d > 0) or np.all(d < 0)):
                raise ValueError("`omega` must be strictly monotonic (a run-up or a run-down, each speed once)")
        object.__setattr__(self, "omega", omega)
        if not isinstance(self.values, dict) or not self.values:
            raise ValueError(f"`values` must map at least one of {', '.join(MEASURED_QUANTITIES)} to measured "
                             "values, got none")
        values = {}
        for q in MEASURED_QUANTITIES:  # file order
            if q not in self.values:
                continue
            v = check_vector(self.values[q], f"values[{q!r}]")
            if v.size != omega.size:
                raise ValueError(f"`values[{q!r}]` must have one value per point ({omega.size}), got {v.size}")
            if q == "acc_p2p" and np.any(v <= 0):
                raise ValueError(f"`values['acc_p2p']` must be > 0 (a peak-to-peak value), got {v[v <= 0][0]!r}")
            values[q] = v
        unknown = sorted(set(self.values) - set(MEASURED_QUANTITIES))
        if unknown:
            raise ValueError(f"`values` may hold only {', '.join(MEASURED_QUANTITIES)}, got {unknown[0]!r}")
        object.__setattr__(self, "values", values)
        if self.speed_rpm is not None:
            rpm = check_vector(self.speed_rpm, "speed_rpm")
            if rpm.size != omega.size:
                raise ValueError(f"`speed_rpm` must have one value per point ({omega.size}), got {rpm.size}")
            object.__setattr__(self, "speed_rpm", rpm)
        object.__setattr__(self, "lines", tuple(int(n) for n in self.lines))

    def __len__(self) -> int:
        return int(self.omega.size)

    @property
    def quantities(self) -> tuple[str, ...]:
        """The measured quantities, in :data:`MEASURED_QUANTITIES` order."""
        return tuple(self.values)

    def __repr__(self) -> str:
        span = (f"{self.speed_rpm.min():.5g} … {self.speed_rpm.max():.5g} rpm" if self.speed_rpm is not None
                else f"Ω = {self.omega.min():.5g} … {self.omega.max():.5g} rad/s")
        return f"MeasuredRun({len(self)} points, {span}, {', '.join(self.quantities)}; {self.source})"


def _segment_values(omega: FloatArray, y: FloatArray, stable: np.ndarray, w: FloatArray) -> FloatArray:
    """Largest linear interpolation at each ``w`` over the stable segments of one branch
    (rows in continuation order); -inf where none covers it."""
    ok = stable[:-1] & stable[1:] & np.isfinite(y[:-1]) & np.isfinite(y[1:])
    w0, w1, y0, y1 = omega[:-1][ok], omega[1:][ok], y[:-1][ok], y[1:][ok]
    out = np.full(w.shape, -np.inf)
    if w0.size == 0:
        return out
    lo, hi = np.minimum(w0, w1), np.maximum(w0, w1)
    slack = _END_SLACK * np.maximum(np.abs(lo), np.abs(hi))
    dw = w1 - w0
    for k in range(0, w.size, _CHUNK):
        x = w[k:k + _CHUNK, None]
        inside = (x >= lo - slack) & (x <= hi + slack)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(dw != 0, (x - w0) / np.where(dw != 0, dw, 1.0), 0.0)
        val = y0 + np.clip(t, 0.0, 1.0) * (y1 - y0)
        out[k:k + _CHUNK] = np.max(np.where(inside, val, -np.inf), axis=1)
    return out


def hb_largest_stable(frf: FrequencyResponse, quantity: str, omega: Any) -> FloatArray:
    """The largest stable value of ``quantity`` that ``frf`` gives at each ``omega`` (rad/s),
    interpolated along its stable segments (rule in the module docstring); NaN where no stable
    segment covers a frequency."""
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    y_all = _frf_column(frf, quantity)
    best = np.full(w.shape, -np.inf)
    for b in np.unique(frf.branch):
        sel = np.flatnonzero(frf.branch == b)
        if sel.size < 2:
            continue
        best = np.maximum(best, _segment_values(np.asarray(frf.omega, dtype=float)[sel], y_all[sel],
                                                np.asarray(frf.stable, dtype=bool)[sel], w))
    return np.where(np.isfinite(best), best, np.nan)


def _frf_column(frf: FrequencyResponse, quantity: str) -> FloatArray:
    if quantity == "acc_p2p":
        return np.asarray(frf.acc_p2p, dtype=float)
    cols = getattr(frf, "extra_columns", {}) or {}
    if quantity not in cols:
        raise ValueError(f"the frequency response carries no `{quantity}` column; give it the sound paths first "
                         "(frf.with_sound(paths))")
    return np.asarray(cols[quantity], dtype=float)


def _sweep_column(part: SweepResult, quantity: str) -> FloatArray | None:
    """The sweep's values of ``quantity``, or None when its result has no such column.

    ``spl_db`` is taken from ``SweepResult.columns()``: a sweep with its sound pressure
    (:meth:`SweepResult.with_sound`) carries it, a sweep of a model without paths does not."""
    if quantity == "acc_p2p":
        return np.asarray(part.acc_p2p, dtype=float)
    col = part.columns().get(quantity)
    return None if col is None else np.asarray(col, dtype=float)


def _sweep_values(sweep: SweepResult, direction: str, quantity: str, w: FloatArray) -> FloatArray | None:
    """Linear interpolation in Ω of one direction's points (sorted by Ω) at ``w``; NaN outside
    its span; None when the sweep carries no ``quantity``."""
    if direction not in sweep.directions:
        return np.full(w.shape, np.nan)
    part = sweep.select(direction)
    y = _sweep_column(part, quantity)
    if y is None:
        return None
    om = np.asarray(part.omega, dtype=float)
    keep = np.isfinite(y)
    om, y = om[keep], y[keep]
    if om.size == 0:
        return np.full(w.shape, np.nan)
    order = np.argsort(om, kind="stable")
    om, y = om[order], y[order]
    lo, hi = om[0], om[-1]
    slack = _END_SLACK * hi
    out = np.interp(w, om, y)
    return np.where((w >= lo - slack) & (w <= hi + slack), out, np.nan)


def _difference(quantity: str, computed: FloatArray, measured: FloatArray) -> FloatArray:
    if DIFFERENCE_KIND[quantity] == "rel":
        return (computed - measured) / measured
    return computed - measured


@dataclass(frozen=True, slots=True, eq=False)
class MeasuredComparison:
    """Measured points with the computed values at each of them (:func:`compare_measured`).

    Attributes
    ----------
    measured : MeasuredRun
    computed : dict
        ``(quantity, curve)`` → values at the measured points, curve one of :data:`COMPUTED`
        (``hb``, ``sweep_up``, ``sweep_down``); NaN where there is no computed value.
    frf : FrequencyResponse
        The frequency response compared with (with ``spl_db`` when sound is compared).
    sweep : SweepResult
        The sweeps compared with.
    missing : dict
        ``(quantity, curve)`` → why that curve has no values at all (e.g. a sweep without
        sound pressure).
    """

    measured: MeasuredRun
    computed: dict[tuple[str, str], FloatArray]
    frf: FrequencyResponse
    sweep: SweepResult
    missing: dict[tuple[str, str], str] = field(default_factory=dict)

    @property
    def speed_order(self) -> float | None:
        return getattr(self.frf.model, "speed_order", None)

    def difference(self, quantity: str, curve: str) -> FloatArray:
        """(computed − measured)/measured for ``acc_p2p``, computed − measured (dB) for ``spl_db``."""
        return _difference(quantity, self.computed[(quantity, curve)], self.measured.values[quantity])

    def column_names(self) -> list[str]:
        """``measured.csv`` header: ``speed_rpm`` (with an engine), ``omega``, then per measured
        quantity Q: ``Q`` (measured), ``Q_hb``, ``Q_sweep_up``, ``Q_sweep_down`` and the
        differences ``Q_rel_hb`` … (``acc_p2p``, relative) or ``Q_diff_hb`` … (``spl_db``, dB)."""
        names = (["speed_rpm"] if self.speed_order is not None else []) + ["omega"]
        for q in self.measured.quantities:
            names += [q, *(f"{q}_{c}" for c in COMPUTED), *(f"{q}_{DIFFERENCE_KIND[q]}_{c}" for c in COMPUTED)]
        return names

    def columns(self) -> dict[str, FloatArray]:
        """The columns of ``measured.csv`` (:meth:`column_names`), one row per measured point."""
        m = self.measured
        cols: dict[str, FloatArray] = {}
        if self.speed_order is not None:
            cols["speed_rpm"] = (m.speed_rpm if m.speed_rpm is not None
                                 else m.omega * (60.0 / (2.0 * math.pi * float(self.speed_order))))
        cols["omega"] = m.omega
        for q in m.quantities:
            cols[q] = m.values[q]
            for c in COMPUTED:
                cols[f"{q}_{c}"] = self.computed[(q, c)]
            for c in COMPUTED:
                cols[f"{q}_{DIFFERENCE_KIND[q]}_{c}"] = self.difference(q, c)
        return cols

    def largest_differences(self, quantity: str) -> dict[str, tuple[float, int]]:
        """Curve → (difference of largest magnitude, its point index), for curves with values."""
        out = {}
        for c in COMPUTED:
            d = self.difference(quantity, c)
            if np.any(np.isfinite(d)):
                i = int(np.nanargmax(np.abs(d)))
                out[c] = (float(d[i]), i)
        return out

    def summary(self) -> str:
        """One line per measured quantity: the largest difference of each computed curve and where."""
        m = self.measured
        rpm = self.columns().get("speed_rpm")

        def where(i: int) -> str:
            return f"{rpm[i]:.5g} rpm" if rpm is not None else f"Ω = {m.omega[i]:.5g}"

        lines = []
        for q in m.quantities:
            parts = []
            for c, (d, i) in self.largest_differences(q).items():
                text = f"{100.0 * d:+.1f} %" if DIFFERENCE_KIND[q] == "rel" else f"{d:+.2f} dB"
                parts.append(f"{c.replace('_', ' ')} {text} at {where(i)}")
            for c in COMPUTED:
                if (q, c) in self.missing:
                    parts.append(f"{c.replace('_', ' ')}: none ({self.missing[(q, c)]})")
                    continue
                gaps = int(np.sum(~np.isfinite(self.computed[(q, c)])))
                if gaps:
                    why = "no stable solution computed" if c == "hb" else "outside the sweep"
                    parts.append(f"{c.replace('_', ' ')}: {why} at {gaps} point(s)")
            lines.append(f"measured {q} ({len(m)} points, {m.source}): largest difference "
                         + ("; ".join(parts) if parts else "none (no computed value at any measured point)"))
        return "\n".join(lines)

    def to_csv(self, path: str | Path) -> Path:
        """Write ``measured.csv`` (:meth:`column_names`) to ``path`` atomically (``nan`` where there
        is no computed value)."""
        from ..files import write_csv

        write_csv(path, self.columns(), self.column_names())
        return Path(path)


def compare_measured(measured: MeasuredRun, frf: FrequencyResponse, sweep: SweepResult) -> MeasuredComparison:
    """The computed values at every measured point (rules in the module docstring).

    Parameters
    ----------
    measured : MeasuredRun
    frf : FrequencyResponse
        With ``spl_db`` (:meth:`FrequencyResponse.with_sound`) when ``spl_db`` was measured.
    sweep : SweepResult
        The up and/or down sweeps.

    Returns
    -------
    MeasuredComparison

    Raises
    ------
    TypeError, ValueError
        Arguments of the wrong type; ``spl_db`` measured but the frequency response has none.
    """
    if not isinstance(measured, MeasuredRun):
        raise TypeError(f"`measured` must be a MeasuredRun, got {type(measured).__name__}")
    if not isinstance(frf, FrequencyResponse):
        raise TypeError(f"`frf` must be a FrequencyResponse, got {type(frf).__name__}")
    if not isinstance(sweep, SweepResult):
        raise TypeError(f"`sweep` must be a SweepResult, got {type(sweep).__name__}")
    w = measured.omega
    computed: dict[tuple[str, str], FloatArray] = {}
    missing: dict[tuple[str, str], str] = {}
    for q in measured.quantities:
        computed[(q, "hb")] = hb_largest_stable(frf, q, w)
        for d in ("up", "down"):
            values = _sweep_values(sweep, d, q, w)
            if values is None:
                missing[(q, f"sweep_{d}")] = f"the sweep result carries no {q}"
                values = np.full(w.shape, np.nan)
            elif d not in sweep.directions:
                missing[(q, f"sweep_{d}")] = f"no {d} sweep"
            computed[(q, f"sweep_{d}")] = values
    return MeasuredComparison(measured=measured, computed=computed, frf=frf, sweep=sweep, missing=missing)
