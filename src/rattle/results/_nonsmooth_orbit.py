"""One periodic orbit of a discontinuous law (preload, friction) at one forcing frequency, with its
stick and lock phases.

The orbit of δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t) found by exact Newton shooting on the
event-driven flow (:func:`rattle.timeint.shoot_nonsmooth_orbit`), started from the regularised
harmonic balance's orbit (:mod:`rattle.analysis._nonsmooth_orbit`). Both are kept: the exact orbit
(the answer: rms, multipliers with the saltation matrices, the segments of slip, stick and lock)
and the HB series δ_HB(t) = a_0 + Σ_k a_k cos kΩt + b_k sin kΩt, so the regularisation's effect is
read on the whole period, not only on the rms.

``stick_intervals`` lists the held phases over one period [0, T], T = 2π/Ω: consecutive stick (or
lock) segments of the trajectory merged into (t_start, t_end, kind). A phase that runs through
t = T continues at t = 0 on the periodic orbit; it is listed as two intervals, one at each end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..model import System
from ..timeint import NonsmoothOrbit
from ._orbit import OrbitSolution, every_orbit_lines, every_orbit_records
from ._plotter import plot_with

#: The columns of :meth:`NonsmoothOrbitResult.to_csv`.
NONSMOOTH_ORBIT_COLUMNS = ("t", "delta", "velocity", "acceleration", "mode", "delta_hb")

#: The mode labels of the segment kinds 0, 1, 2 of a trajectory.
MODE_NAMES = ("slip", "stick", "lock")

#: How the exact orbit was reached (``NonsmoothOrbitResult.start``).
ORBIT_STARTS = ("hb", "x0", "settled", "")


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class NonsmoothOrbitResult:
    """The exact and regularised orbits at one forcing frequency (module docstring).

    ``system`` the equation; ``omega`` Ω (rad/s); ``orbit`` the exact
    :class:`~rattle.timeint.NonsmoothOrbit` (None when shooting failed; ``message`` says why);
    ``start`` how shooting was started: ``"hb"`` from the HB orbit's state at t = 0, ``"x0"`` from
    the state given, ``"settled"`` from the state reached after ``settle_periods`` periods of the
    exact flow from the HB state (the direct shooting had failed), ``""`` when none converged;
    ``coefficients`` q = [a_0, a_1 … a_H, b_1 … b_H] of δ_HB (nan when the HB failed);
    ``regularisation`` ε and ``harmonics`` H of the HB; ``hb_state`` (δ, δ') of the HB orbit at
    t = 0; ``hb_start`` how the HB was solved: ``"rest"`` (from rest, ε narrowed from 0.1),
    ``"exact"`` (from the exact orbit's spectrum, after the first failed), ``""`` failed;
    ``match`` the largest :attr:`hb_distance` for the two orbits to count as one
    (:attr:`matched`); ``periods`` p: the orbit repeats after p forcing periods (2: a sub-harmonic
    orbit; its HB series then holds harmonics of Ω/2, and "per period" means over p 2π/Ω)."""

    system: System
    omega: float
    orbit: NonsmoothOrbit | None
    message: str
    start: str
    coefficients: FloatArray
    regularisation: float
    harmonics: int
    hb_state: FloatArray
    hb_start: str = "rest"
    match: float = 0.1
    settle_periods: int = 100
    periods: int = 1
    #: Every orbit at Ω (:func:`rattle.analysis.exact_orbits_at`: exact, stable and unstable, of every
    #: period the census found; empty when not asked for) and the non-periodic attractors there.
    solutions: tuple[OrbitSolution, ...] = ()
    nonperiodic: tuple[Any, ...] = ()

    # --- the periods and the HB series ------------------------------------------------------
    @property
    def period(self) -> float:
        """T = p 2π/Ω (s): the orbit repeats after p = ``periods`` forcing periods."""
        return self.periods * 2.0 * math.pi / self.omega

    @property
    def converged(self) -> bool:
        """An exact orbit was found."""
        return self.orbit is not None

    def sample_hb(self, t: FloatArray | float, derivative: int = 0) -> FloatArray:
        """δ_HB (``derivative`` 0) or δ_HB' (1) at times ``t``: the regularised HB series."""
        if derivative not in (0, 1):
            raise ValueError(f"`derivative` must be 0 or 1, got {derivative!r}")
        q = self.coefficients
        H = self.harmonics
        t = np.asarray(t, dtype=float)
        kw = np.arange(1, H + 1) * (self.omega / self.periods)  # harmonics of the orbit's own frequency Ω/p
        ph = np.multiply.outer(t, kw)
        a, b = q[1 : H + 1], q[H + 1 :]
        if derivative == 0:
            return q[0] + np.cos(ph) @ a + np.sin(ph) @ b
        return np.cos(ph) @ (kw * b) - np.sin(ph) @ (kw * a)

    def sample(self, t: FloatArray | float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """δ, δ', δ'' of the exact orbit at times ``t`` (taken modulo T); nan without an orbit."""
        t = np.asarray(t, dtype=float)
        if self.orbit is None:
            nan = np.full(t.shape, math.nan)
            return nan, nan.copy(), nan.copy()
        T = self.period
        tt = np.where((t >= 0.0) & (t <= T), t, np.mod(t, T))
        return self.orbit.trajectory.sample(tt)

    # --- measures ---------------------------------------------------------------------------
    @property
    def rms(self) -> float:
        """rms of δ of the exact orbit (nan without one)."""
        return float(self.orbit.rms) if self.orbit is not None else math.nan

    @property
    def mean(self) -> float:
        """Mean of δ of the exact orbit (nan without one)."""
        return float(self.orbit.mean) if self.orbit is not None else math.nan

    @property
    def rms_hb(self) -> float:
        """rms of δ_HB: sqrt(a_0² + Σ (a_k² + b_k²)/2)."""
        q = self.coefficients
        return math.sqrt(float(q[0] ** 2 + 0.5 * np.sum(q[1:] ** 2)))

    @property
    def rms_error(self) -> float:
        """rms_hb / rms − 1: the regularisation's (and truncation's) effect on the rms (nan when the
        exact rms is 0 or missing: an orbit locked all period)."""
        rms = self.rms
        return self.rms_hb / rms - 1.0 if rms > 0.0 else math.nan

    @property
    def stable(self) -> bool | None:
        """Every exact Floquet multiplier inside the unit circle (None without an orbit)."""
        return bool(self.orbit.stable) if self.orbit is not None else None

    @property
    def multipliers(self) -> ComplexArray:
        """The exact Floquet multipliers, largest modulus first (a zero one per stick phase, both
        zero with a lock); nan without an orbit."""
        if self.orbit is None:
            return np.full(2, complex(math.nan, math.nan))
        return np.asarray(self.orbit.multipliers, dtype=complex)

    @property
    def stick_time(self) -> float:
        """Time per period spent sticking or locked (nan without an orbit)."""
        return float(self.orbit.trajectory.stick_time) if self.orbit is not None else math.nan

    @property
    def regime(self) -> str:
        """``no_impact``, ``single_sided`` or ``double_sided`` (``""`` without an orbit)."""
        return self.orbit.regime if self.orbit is not None else ""

    @property
    def stick_intervals(self) -> list[tuple[float, float, str]]:
        """The stick and lock phases over one period: (t_start, t_end, ``"stick"`` or ``"lock"``),
        consecutive segments of one kind merged, in time order (module docstring)."""
        if self.orbit is None:
            return []
        tr = self.orbit.trajectory
        out: list[tuple[float, float, str]] = []
        for ta, tb, kd in zip(tr.t_start.tolist(), tr.t_end.tolist(), tr.kind.tolist()):
            if kd == 0 or tb <= ta:
                continue
            name = MODE_NAMES[kd]
            if out and out[-1][2] == name and out[-1][1] == ta:
                out[-1] = (out[-1][0], tb, name)
            else:
                out.append((ta, tb, name))
        return out

    @property
    def hb_distance(self) -> float:
        """max over the period of |δ(t) − δ_HB(t)| relative to the peak-to-peak of δ_HB (at
        :meth:`sample_times`): how far the exact orbit lies from the regularised one (nan when
        either is missing)."""
        if self.orbit is None or not np.all(np.isfinite(self.coefficients)):
            return math.nan
        t = self.sample_times()
        hb = self.sample_hb(t)
        size = max(float(np.ptp(hb)), 1e-12 * self.system.length_scale())
        return float(np.max(np.abs(self.sample(t)[0] - hb))) / size

    @property
    def matched(self) -> bool:
        """The exact orbit is the HB orbit's (``hb_distance`` ≤ ``match``), as in
        :class:`NonsmoothCheck`: otherwise the shooting found another orbit and ``rms_error``
        compares two different orbits."""
        return bool(self.hb_distance <= self.match)

    # --- tables and plots -------------------------------------------------------------------
    def sample_times(self, points: int = 512) -> FloatArray:
        """``points`` + 1 equally spaced times over [0, T] together with every event time of the
        exact orbit (sorted, unique)."""
        if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or points < 2:
            raise ValueError(f"`points` must be an integer >= 2, got {points!r}")
        t = np.linspace(0.0, self.period, int(points) + 1)
        if self.orbit is not None:
            ev = self.orbit.trajectory.event_time
            t = np.concatenate((t, ev[(ev >= 0.0) & (ev <= self.period)]))
        return np.unique(t)

    def columns(self, points: int = 512) -> dict[str, Any]:
        """One period as columns :data:`NONSMOOTH_ORBIT_COLUMNS` at :meth:`sample_times`: t, δ,
        δ', δ'' of the exact orbit, ``mode`` of the segment (``slip``, ``stick`` or ``lock``; at a
        switching time the segment starting there) and δ_HB. Without an exact orbit the exact
        columns are nan and ``mode`` is empty."""
        t = self.sample_times(points)
        d, v, a = self.sample(t)
        if self.orbit is not None:
            tr = self.orbit.trajectory
            idx = np.clip(np.searchsorted(tr.t_start, t, side="right") - 1, 0, len(tr.t_start) - 1)
            mode = np.array([MODE_NAMES[k] for k in tr.kind[idx].tolist()], dtype=object)
        else:
            mode = np.full(t.size, "", dtype=object)
        return {"t": t, "delta": d, "velocity": v, "acceleration": a, "mode": mode, "delta_hb": self.sample_hb(t)}

    def summary(self) -> dict[str, Any]:
        """The scalars of the orbit as plain Python values (JSON-ready; nan stays nan, None for
        ``stable`` without an exact orbit): omega, period (s), periods (p), rms, mean, rms_hb, rms_error,
        hb_distance, matched, stable, mu1_abs, mu2_abs, stick_time, regime, start, hb_start,
        regularisation, harmonics, message, ``phases``: [[t_start, t_end, kind], …], ``orbits``: every
        orbit at Ω (:attr:`solutions`) and ``nonperiodic``: the non-periodic attractors there."""
        mu = np.abs(self.multipliers)
        return {
            "omega": self.omega, "period": self.period, "periods": self.periods, "rms": self.rms, "mean": self.mean, "rms_hb": self.rms_hb,
            "rms_error": self.rms_error, "hb_distance": self.hb_distance, "matched": self.matched,
            "stable": self.stable, "mu1_abs": float(mu[0]), "mu2_abs": float(mu[1]), "stick_time": self.stick_time,
            "regime": self.regime, "start": self.start, "hb_start": self.hb_start,
            "regularisation": self.regularisation, "harmonics": self.harmonics, "message": self.message,
            "phases": [[a, b, k] for a, b, k in self.stick_intervals],
            **every_orbit_records(self.solutions, self.nonperiodic),
        }

    def every_orbit_text(self) -> list[str]:
        """The terminal lines of every orbit found at Ω (:attr:`solutions`, :attr:`nonperiodic`)."""
        return every_orbit_lines(self.omega, self.solutions, self.nonperiodic)

    def to_csv(self, path: str | Path, points: int = 512) -> Path:
        """Write :meth:`columns` to ``path`` atomically; returns the path."""
        from ..files import write_csv

        write_csv(path, self.columns(points), list(NONSMOOTH_ORBIT_COLUMNS))
        return Path(path)

    def plot(self) -> tuple:
        """δ(t) exact and HB, δ'(t) and the phase portrait with the stick and lock phases shaded;
        returns (figure, PlotAxes). See :func:`rattle.plotting.nonsmooth_orbit_plot`."""
        return plot_with("nonsmooth_orbit_plot", self)

    def __repr__(self) -> str:
        if self.orbit is None:
            return f"NonsmoothOrbitResult(Ω = {self.omega:.6g}, no exact orbit: {self.message})"
        return (f"NonsmoothOrbitResult(Ω = {self.omega:.6g}, rms = {self.rms:.6g} rad (HB {self.rms_error:+.2e}), "
                f"{'stable' if self.stable else 'unstable'}, stick {self.stick_time:.4g} s in "
                f"{len(self.stick_intervals)} phases, {self.regime}, from {self.start})")


__all__ = ["MODE_NAMES", "NONSMOOTH_ORBIT_COLUMNS", "NonsmoothOrbitResult"]
