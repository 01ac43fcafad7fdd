"""Comparison: the frequency response, the time-domain sweep and detailed orbits at a few
frequencies, as :func:`rattle.compare` returns them."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..model import Model
from ._frequency_response import FrequencyResponse
from ._orbit import PeriodicOrbit
from ._sweep import SweepResult

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
        picks = ", ".join(f"{w:.4g} ({r})" for w, r in zip(self.at, self.reasons)) or "none"
        return (
            f"Comparison(Ω = {self.frf.omega.min():.4g}…{self.frf.omega.max():.4g}: {len(self.frf)} FRF points, "
            f"{len(self.sweep)} sweep points; orbits at {picks})"
        )

    def summary(self) -> str:
        """A few lines for the terminal."""
        lines = ["frequency response:", *("  " + s for s in self.frf.summary().splitlines())]
        lines += ["time-domain sweep:", *("  " + s for s in self.sweep.summary().splitlines())]
        for w, why, orbit, sims in zip(self.at, self.reasons, self.orbits, self.simulations):
            hb = ", ".join(
                f"P{s.period} rms {s.rms:.4g} {'stable' if s.stable else 'unstable'}" for s in orbit.solutions
            )
            sim = ", ".join(f"{d} sweep P{s.period} rms {s.rms:.4g}" for d, s in sims.items())
            lines.append(f"Ω = {w:.5g} ({why}): HB {hb or 'none'}; simulation {sim or 'none'}")
        return "\n".join(lines)

    def metadata(self) -> dict[str, Any]:
        """Settings, timings and the examined frequencies, JSON-serialisable."""
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
        from ..plotting import compare_plot

        return compare_plot(self, fig=fig, samples=samples, title=title)
