"""Comparison: the frequency response, the time-domain sweep and detailed orbits at a few
frequencies, as :func:`rattle.compare` returns them."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model import Model
from ._frequency_response import FrequencyResponse
from ._orbit import PeriodicOrbit
from ._sweep import SweepResult
from ._plotter import plot_with
from ._speed import SpeedText

if TYPE_CHECKING:  # annotations only
    from ._steady import SteadyState

__all__ = ["Comparison"]


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Comparison:
    """The frequency response, the time-domain sweep and detailed orbits at a few frequencies.

    Attributes
    ----------
    model : Model
    frf : FrequencyResponse
        Harmonic balance + continuation over the range.
    sweep : SweepResult
        The up and down time-domain sweeps over the same range.
    at : tuple of float
        The frequencies examined in detail (rad/s), increasing.
    reasons : tuple of str
        Why each frequency of ``at`` was chosen (``multi-valued``, ``sub-harmonic``,
        ``non-periodic``, ``resonance`` or ``requested``).
    orbits : tuple of PeriodicOrbit
        Every HB orbit at each frequency of ``at`` (its ``simulation`` started from the up
        sweep's state there).
    simulations : tuple of dict
        For each frequency of ``at``: direction (``up``/``down``) → the steady state that sweep
        reaches there (started from its state at the nearest grid frequency).
    settings, timings : dict
        Provenance.

    A discontinuous law (single-equation :class:`~rattle.model.System`, or a chain with friction:
    :class:`~rattle.model.System` with its elements' whole laws): ``frf`` is its :class:`NonsmoothCheck` or
    :class:`FrictionCheck` (exact rms per row, ``stable``, ``matched``), ``at``, ``orbits`` and
    ``simulations`` are empty, and :meth:`agreement` sets the sweep's settled period-1 rows against
    the response's exact rms.
    """

    model: Model
    frf: FrequencyResponse
    sweep: SweepResult
    at: tuple[float, ...]
    reasons: tuple[str, ...]
    orbits: tuple[PeriodicOrbit, ...]
    simulations: tuple[dict[str, SteadyState], ...]
    settings: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)

    def __repr__(self) -> str:
        if self.discontinuous:
            return (f"Comparison(Ω = {float(np.min(self.frf.omega)):.4g}…{float(np.max(self.frf.omega)):.4g}: "
                    f"{len(self.frf)} response rows, {len(self.sweep)} sweep points)")
        picks = ", ".join(f"{w:.4g} ({r})" for w, r in zip(self.at, self.reasons)) or "none"
        return (
            f"Comparison(Ω = {self.frf.omega.min():.4g}…{self.frf.omega.max():.4g}: {len(self.frf)} FRF points, "
            f"{len(self.sweep)} sweep points; orbits at {picks})"
        )

    @property
    def discontinuous(self) -> bool:
        """True when ``frf`` is the response of a discontinuous law (it carries an exact-check
        group, :class:`NonsmoothCheck` or :class:`FrictionCheck`, in ``check``)."""
        return self.frf.check is not None

    def agreement(self) -> dict[str, Any]:
        """The sweep's settled period-1 rows against the response's exact rms (first element of a
        chain) at the same Ω: for every such row, the stretches between consecutive response rows
        that are both stable and matched and bracket its Ω give an rms by linear interpolation;
        the one nearest the row's counts. Returns ``rows`` (settled period-1 rows), ``compared``
        (those with such a stretch), ``median`` and ``largest`` relative difference
        |rms_sweep − rms_response| / rms_sweep (None when none compared; they include the
        interpolation between the response's rows) and ``without`` (the Ω of the rows without)."""
        frf, sweep = self.frf.check, self.sweep
        w = np.asarray(frf.omega, dtype=float)
        r = np.asarray(frf.rms, dtype=float)
        r = r[:, 0] if r.ndim == 2 else r
        ok = np.asarray(frf.stable, dtype=bool) & np.asarray(frf.matched, dtype=bool) & np.isfinite(r)
        seg = np.flatnonzero(ok[:-1] & ok[1:] & (w[:-1] != w[1:])) if w.size > 1 else np.zeros(0, dtype=int)
        a, b = np.minimum(w[seg], w[seg + 1]), np.maximum(w[seg], w[seg + 1])
        errors, without = [], []
        rows = 0
        for om, rms, p, settled in zip(sweep.omega, sweep.rms, sweep.period, sweep.settled):
            if int(p) != 1 or not settled:
                continue
            rows += 1
            inside = seg[(a <= om) & (om <= b)]
            if inside.size == 0:
                without.append(float(om))
                continue
            cand = r[inside] + (r[inside + 1] - r[inside]) * (om - w[inside]) / (w[inside + 1] - w[inside])
            errors.append(float(np.min(np.abs(cand - rms))) / max(abs(float(rms)), 1e-300))
        err = np.asarray(errors)
        return {"rows": rows, "compared": int(err.size),
                "median": float(np.median(err)) if err.size else None,
                "largest": float(np.max(err)) if err.size else None, "without": without}

    @property
    def _speed(self) -> SpeedText:
        """Speeds in text: rpm with an engine, else Ω."""
        return SpeedText.of(self.sweep.model)

    def _frf_lines(self) -> list[str]:
        """A discontinuous law's response in a few lines."""
        frf = self.frf.check
        stable = np.asarray(frf.stable, dtype=bool) & np.asarray(frf.matched, dtype=bool)
        return [
            f"regularised harmonic balance (H = {frf.harmonics}, ε = {frf.regularisation:g}) checked by exact "
            f"shooting: {len(frf)} rows over {self._speed.span(float(np.min(frf.omega)), float(np.max(frf.omega)), 4)}, "
            f"{int(np.sum(frf.matched))} matched, {int(np.sum(stable))} matched and stable; "
            f"{frf.status.name.lower()}" + (f": {frf.message}" if frf.message else ""),
        ]

    def summary(self) -> str:
        """A few lines for the terminal."""
        if self.discontinuous:
            lines = ["frequency response:", *("  " + s for s in self._frf_lines())]
            lines += ["time-domain sweep:", *("  " + s for s in self.sweep.summary().splitlines())]
            ag = self.agreement()
            text = (f"median {ag['median']:.2g}, largest {ag['largest']:.2g}" if ag["compared"] else "none compared")
            lines.append(f"sweep against the response: {ag['compared']} of {ag['rows']} settled period-1 rows on a "
                         f"stable matched stretch of the response, relative rms difference {text}")
            if ag["without"]:
                lines.append("  rows without one at " + self._speed.values(sorted(set(ag["without"])), 4))
            return "\n".join(lines)
        lines = ["frequency response:", *("  " + s for s in self.frf.summary().splitlines())]
        lines += ["time-domain sweep:", *("  " + s for s in self.sweep.summary().splitlines())]
        for w, why, orbit, sims in zip(self.at, self.reasons, self.orbits, self.simulations):
            hb = ", ".join(
                f"P{s.period} rms {s.rms:.4g} {'stable' if s.stable else 'unstable'}" for s in orbit.solutions
            )
            sim = ", ".join(f"{d} sweep P{s.period} rms {s.rms:.4g}" for d, s in sims.items())
            lines.append(f"{self._speed.at(w)} ({why}): HB {hb or 'none'}; simulation {sim or 'none'}")
        return "\n".join(lines)

    def metadata(self) -> dict[str, Any]:
        """Settings, timings and the examined frequencies, JSON-serialisable (a discontinuous
        law: the response's counts and the :meth:`agreement` instead of the orbits)."""
        if self.discontinuous:
            frf = self.frf.check
            stable = np.asarray(frf.stable, dtype=bool) & np.asarray(frf.matched, dtype=bool)
            response = {"harmonics": frf.harmonics, "regularisation": frf.regularisation, "rows": len(frf),
                        "matched": int(np.sum(frf.matched)), "stable": int(np.sum(stable)),
                        "status": frf.status.name, "message": frf.message}
            ag = self.agreement()
            ag = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in ag.items()}
            return {"settings": self.settings, "timings": self.timings, "frf": response,
                    "sweep": self.sweep.metadata(), "agreement": ag, "orbits": []}
        return {
            "settings": self.settings,
            "timings": self.timings,
            "frf": self.frf.metadata(),
            "sweep": self.sweep.metadata(),
            "orbits": [
                {"omega": w, "reason": why, **orbit.metadata(),
                 "sweep_states": {d: {"period": s.period, "rms": s.rms} for d, s in sims.items()}}
                for w, why, orbit, sims in zip(self.at, self.reasons, self.orbits, self.simulations)
            ],
        }

    def to_csv(self, directory: str | Path) -> tuple[Path, Path]:
        """Write ``frf.csv`` and ``sweep.csv`` (SPEC columns) into ``directory`` atomically."""
        directory = Path(directory)
        return self.frf.to_csv(directory / "frf.csv"), self.sweep.to_csv(directory / "sweep.csv")

    def plot(self, fig: Any = None, *, samples: int = 256, title: str | None = None) -> tuple[Any, Any]:
        """The FRF with the sweep points over it, and a row of time histories; returns
        (figure, :class:`rattle.plotting.PlotAxes`). See :func:`rattle.plotting.compare_plot`."""
        return plot_with("compare_plot", self, fig=fig, samples=samples, title=title)
