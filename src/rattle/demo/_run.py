"""The paper's reference case end to end (``rattle demo``): its settings, the computation, the
figures by key and the numbers for the report.

No files and no printing here: :func:`run_demo` returns a :class:`PaperDemo` that holds every
result; the command line writes them (as one output set) and prints :meth:`PaperDemo.summary`.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..analysis import confirm_with_sweep, frequency_response, periodic_orbit, time_sweep
from ..io import AnalysisSettings
from ..model import Model, reference_case
from ..results import FrequencyResponse, PeriodicOrbit, Region, SweepResult
from ._report import LevelDifference, demo_report, level_difference

__all__ = [
    "DEMO_OMEGA", "DEMO_HARMONICS", "DEMO_POINTS", "DEMO_WORKERS", "DEMO_POINT_A", "DEMO_POINT_B",
    "DEMO_FIGURES", "DEMO_REPORT", "DEMO_DATA", "DEMO_FILES", "demo_case", "describe", "demo_frequency_response",
    "PaperDemo", "run_demo",
]

#: The demo's frequency range (rad/s), harmonics and sweep frequencies per direction.
DEMO_OMEGA = (0.1, 3.0)
DEMO_HARMONICS = 32
DEMO_POINTS = 200
#: Processes for the demo's sweep: the up and down sweeps run at once.
DEMO_WORKERS = 2
#: The paper's points A (Figure 6) and B (Figure 7), rad/s.
DEMO_POINT_A = 0.44
DEMO_POINT_B = 1.41
#: Files of the demo's figures, by report key.
DEMO_FIGURES = {
    "frf": "frf.png",
    "fig4": "fig4_linear_vs_nonlinear.png",
    "fig5": "fig5_hbm_vs_simulation.png",
    "fig6": "fig6_point_A.png",
    "fig7": "fig7_point_B.png",
    "mean": "fig_mean_operating_point.png",
}
DEMO_REPORT = "report.md"
#: The data files of the demo, in the order the report lists them.
DEMO_DATA = ("frf.csv", "frf.json", "sweep.csv")
#: Every file of the demo: its output set.
DEMO_FILES = ("frf.csv", "sweep.csv", "frf.json", *DEMO_FIGURES.values(), DEMO_REPORT)


def demo_case() -> tuple[Model, AnalysisSettings]:
    """The paper's reference case and the demo's analysis settings (range, harmonics)."""
    return reference_case(), AnalysisSettings(omega_min=DEMO_OMEGA[0], omega_max=DEMO_OMEGA[1],
                                              harmonics=DEMO_HARMONICS)


def describe(analysis: AnalysisSettings) -> str:
    """One line saying what the demo computes."""
    return (
        "the paper's reference case — clutch alpha = 0.25, b = 10 deg, zeta = 0.025, "
        f"F_m = 0.05, F_p1 = 0.03; Omega = {analysis.omega_min} … {analysis.omega_max} rad/s, "
        f"H = {analysis.harmonics}, sub-harmonic branches on; sweep up and down, {DEMO_POINTS} points each"
    )


def demo_frequency_response(model: Model, analysis: AnalysisSettings) -> FrequencyResponse:
    """The demo's frequency response: every branch (sub-harmonic ones too); raises on failure."""
    return frequency_response(model, omega=analysis.omega, harmonics=analysis.harmonics, throw=True,
                              subharmonics=True)


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class PaperDemo:
    """Everything ``rattle demo`` computed.

    Attributes
    ----------
    model : Model
        The reference case.
    analysis : AnalysisSettings
        Range and harmonics of the frequency response.
    frf : FrequencyResponse
        Every branch, sub-harmonic ones included.
    sweep : SweepResult
        The up and down time-domain sweeps.
    orbits : dict
        ``{"A": PeriodicOrbit at DEMO_POINT_A, "B": PeriodicOrbit at DEMO_POINT_B}``.
    regions : tuple of Region
        ``frf.regions`` confirmed by the sweep.
    level : LevelDifference
        Linear vs non-linear level difference in the paper's band.
    timings : dict
        Wall times (s) of the ``sweep`` and the ``orbits`` (and of the ``frf`` when
        :func:`run_demo` computed it).
    """

    model: Model
    analysis: AnalysisSettings
    frf: FrequencyResponse
    sweep: SweepResult
    orbits: dict[str, PeriodicOrbit]
    regions: tuple[Region, ...]
    level: LevelDifference
    timings: dict[str, float] = field(default_factory=dict)

    def metadata(self) -> dict[str, Any]:
        """The ``demo`` section of ``frf.json``: confirmed regions, sweep, orbits, level difference."""
        level = self.level
        return {
            "regions_confirmed_by_sweep": [g.to_dict() for g in self.regions],
            "sweep": self.sweep.metadata(),
            "orbits": {name: {"omega": o.omega, **o.metadata()} for name, o in self.orbits.items()},
            "level_difference": {
                "quantity": "20 log10(acc_p2p non-linear / acc_p2p linear), stable solutions",
                "band": list(level.band), "db_min": level.db_min, "omega_at_min": level.omega_at_min,
                "db_max": level.db_max, "omega_at_max": level.omega_at_max,
                "single_valued": list(level.single_valued_range()),
            },
        }

    def summary(self) -> str:
        """A few lines for the terminal: the frequency response, the sweep, points A and B, the
        level difference."""
        lines = [self.frf.summary(), self.sweep.summary()]
        for name, orbit in self.orbits.items():
            sim = orbit.simulated_period
            lines.append(f"point {name} (Omega = {orbit.omega:g}): simulation "
                         + (f"period {sim}" if sim else "no period <= 8")
                         + "; HB: " + ", ".join(f"P{s.period} {'stable' if s.stable else 'unstable'} rms {s.rms:.4g}"
                                                for s in orbit.solutions))
        lines.append("linear vs non-linear: " + self.level.summary())
        return "\n".join(lines)

    def figure(self, key: str) -> tuple[Any, Any]:
        """Draw the figure ``key`` of :data:`DEMO_FIGURES`; returns (figure, axes)."""
        from ..plotting import frequency_response_plot
        from ._figures import hbm_vs_simulation_plot, linear_vs_nonlinear_plot, mean_operating_point_plot, point_plot

        if key not in DEMO_FIGURES:
            raise ValueError(f"`key` must be one of {sorted(DEMO_FIGURES)}, got {key!r}")
        if key == "frf":
            return frequency_response_plot(self.frf)
        if key == "fig4":
            return linear_vs_nonlinear_plot(self.frf, self.level)
        if key == "fig5":
            return hbm_vs_simulation_plot(self.frf, self.sweep)
        if key == "fig6":
            orbit = self.orbits["A"]
            p = orbit.simulated_period
            note = ("(the paper reported quasi-periodic motion at A; the exact simulation and the harmonic balance "
                    f"agree on period {p})") if p and p > 1 else "(the paper reported quasi-periodic motion at A)"
            return point_plot(orbit, name="A", note=note)
        if key == "fig7":
            return point_plot(self.orbits["B"], name="B",
                              note="(the paper: a sub-harmonic peak near Ω = 1.4, HB and simulation match exactly)")
        return mean_operating_point_plot(self.frf)

    def report(self, *, figures: Mapping[str, str], timings: Mapping[str, float] | None = None,
               data_files: Sequence[str] = DEMO_DATA, version: str = "") -> str:
        """The markdown report (:func:`rattle.demo.demo_report`) for the figures written."""
        return demo_report(self.frf, self.sweep, orbits=self.orbits, level=self.level, figures=figures,
                           regions=self.regions, timings=timings, data_files=list(data_files), version=version)


def run_demo(
    frf: FrequencyResponse | None = None,
    *,
    callback: Callable[[int, int], None] | None = None,
) -> PaperDemo:
    """Compute the paper's reference case end to end: the frequency response (unless given),
    the up and down sweeps, the orbits at points A and B, the regions confirmed by the sweep
    and the level difference.

    Parameters
    ----------
    frf : FrequencyResponse, optional
        The demo's frequency response when already computed (:func:`demo_frequency_response`).
    callback : callable, optional
        ``callback(done, total)`` after each sweep frequency (for a progress bar).

    Returns
    -------
    PaperDemo
    """
    model, analysis = demo_case()
    timings: dict[str, float] = {}
    if frf is None:
        t0 = time.perf_counter()
        frf = demo_frequency_response(model, analysis)
        timings["frf"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    sweep = time_sweep(model, omega=analysis.omega, points=DEMO_POINTS, direction="both", workers=DEMO_WORKERS,
                       callback=callback)
    timings["sweep"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    orbits = {
        name: periodic_orbit(model, w, period=2, harmonics=analysis.harmonics, frf=frf)
        for name, w in (("A", DEMO_POINT_A), ("B", DEMO_POINT_B))
    }
    timings["orbits"] = time.perf_counter() - t0
    return PaperDemo(
        model=model, analysis=analysis, frf=frf, sweep=sweep, orbits=orbits,
        regions=tuple(confirm_with_sweep(frf.regions, sweep)), level=level_difference(frf), timings=timings,
    )
