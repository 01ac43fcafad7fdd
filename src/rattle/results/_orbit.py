"""Periodic orbits at one forcing frequency: every harmonic-balance solution found there,
with its stability and measures, next to the simulated steady state."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._validate import check_history_size

from .._typing import ComplexArray, FloatArray
from ._columns import ORBIT_COLUMNS
from ._speed import SpeedText
from ..measures import acceleration_batch, element_accelerations, evaluate_batch
from ..model import Model
from ._plotter import plot_with

if TYPE_CHECKING:  # pragma: no cover
    from ._steady import SteadyState

#: Where a harmonic-balance solution came from (``OrbitSolution.source``).
ORBIT_SOURCES: tuple[str, ...] = ("continuation", "simulation", "subharmonic_branch")


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class OrbitSolution:
    """One harmonic-balance periodic solution at the forcing frequency ``omega`` (rad/s).

    Attributes
    ----------
    omega : float
        Forcing frequency Ω (rad/s).
    period : int
        The solution's least period as a multiple of the forcing period 2π/Ω (1 primary,
        n a 1/n sub-harmonic); its base frequency is ω = Ω / ``period``.
    coefficients : numpy.ndarray, shape (2H+1,)
        Fourier coefficients [a_0, a_1 … a_H, b_1 … b_H] of δ (rad) over the solution period.
    stable : bool
        All Floquet multipliers inside the unit circle.
    multipliers : numpy.ndarray, shape (2,), complex
        Floquet multipliers over one solution period, largest modulus first.
    mean, rms, rms_ac, p2p, delta_min, delta_max : float
        SPEC §1 measures of δ (rad).
    acc_p2p : float
        Peak-to-peak δ'' (rad/s²).
    regime : str
        ``no_impact``, ``single_sided`` or ``double_sided``.
    source : str
        ``"continuation"`` (the primary branch through Ω), ``"simulation"`` (Newton started
        from the simulated steady state) or ``"subharmonic_branch"`` (the branch of a
        simulation-seeded sub-harmonic followed in Ω back through Ω).
    iterations : int
        Newton iterations of the final polish at exactly Ω.
    residual : float
        Scaled harmonic-balance residual.
    simulated : bool
        A simulation (from the given initial state, or from next to an unstable orbit) settled
        on this orbit, whatever ``source`` first found it.
    elements : dict
        A chain's: element name → its measures (``mean``, ``rms``, ``rms_ac``, ``p2p``,
        ``acc_p2p``, ``delta_min``, ``delta_max``, ``regime``); the flat fields above are the
        first element's, and ``coefficients`` holds the n coordinate blocks (n·(2H+1),
        coordinate-major). Empty for the single equation.
    """

    omega: float
    period: int
    coefficients: FloatArray
    stable: bool
    multipliers: ComplexArray
    mean: float
    rms: float
    rms_ac: float
    p2p: float
    acc_p2p: float
    delta_min: float
    delta_max: float
    regime: str
    source: str
    iterations: int = 0
    residual: float = 0.0
    simulated: bool = False
    elements: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def harmonics(self) -> int:
        """H, the number of harmonics of the base frequency kept."""
        return (self.coefficients.size // self._blocks - 1) // 2

    @property
    def _blocks(self) -> int:
        """Coordinate blocks of ``coefficients`` (1 for the single equation)."""
        n = self.multipliers.size // 2
        return n if self.elements else 1

    @property
    def base_frequency(self) -> float:
        """ω = Ω / period (rad/s)."""
        return self.omega / self.period

    def amplitudes(self) -> FloatArray:
        """One-sided amplitudes |δ_k| = sqrt(a_k² + b_k²) of harmonics k = 0 … H of the base
        frequency (|a_0| for k = 0), shape (H+1,), rad."""
        H = self.harmonics
        q = self.coefficients[: 2 * H + 1]  # a chain: its first coordinate
        out = np.empty(H + 1)
        out[0] = abs(q[0])
        out[1:] = np.hypot(q[1 : H + 1], q[H + 1 :])
        return out

    def __repr__(self) -> str:
        return (
            f"OrbitSolution(Ω = {self.omega:.6g}, period {self.period}, rms = {self.rms:.6g} rad, "
            f"{'stable' if self.stable else 'unstable'}, |μ|max = {float(np.max(np.abs(self.multipliers))):.4g}, "
            f"{self.regime}, from {self.source}{', simulation lands here' if self.simulated else ''})"
        )


def solution_lines(solutions: "tuple[OrbitSolution, ...] | list[OrbitSolution]", selected: int | None = None) -> list[str]:
    """One terminal line per orbit at one frequency: its index, period, rms, p2p, stability (the
    largest |μ|), regime and what found it; ``*`` marks the ``selected`` one."""
    lines = []
    for i, s in enumerate(solutions):
        mark = "*" if i == selected else " "
        lines.append(
            f" {mark} [{i}] period {s.period}, rms {s.rms:.6g} rad, p2p {s.p2p:.5g} rad, "
            f"{'stable' if s.stable else 'unstable'} (|μ|max {float(np.max(np.abs(s.multipliers))):.4g}), "
            f"{s.regime}, from {s.source}{'; the simulation settles here' if s.simulated and s.source != 'simulation' else ''}"
        )
    return lines


def solution_record(s: OrbitSolution) -> dict[str, Any]:
    """One orbit's period, stability, source, measures and multipliers (JSON-serialisable)."""
    return {
        "period": s.period, "stable": s.stable, "source": s.source, "simulated": s.simulated,
        "mean": s.mean, "rms": s.rms, "rms_ac": s.rms_ac, "p2p": s.p2p, "acc_p2p": s.acc_p2p,
        "delta_min": s.delta_min, "delta_max": s.delta_max, "regime": s.regime,
        "multipliers": [[float(z.real), float(z.imag)] for z in s.multipliers],
        "residual": s.residual,
        **({"elements": s.elements} if s.elements else {}),
    }


def every_orbit_records(solutions: "tuple[OrbitSolution, ...]", nonperiodic: tuple[Any, ...]) -> dict[str, Any]:
    """The ``orbits`` (:func:`solution_record` of each) and ``nonperiodic`` (rms, rms_ac, regime,
    origin of each attractor with no period up to 8; ``period`` of a periodic one whose exact orbit
    was not found) of every orbit found at Ω, JSON-serialisable."""
    return {"orbits": [solution_record(o) for o in solutions],
            "nonperiodic": [{"rms": a.rms, "rms_ac": a.rms_ac, "regime": a.regime, "origin": a.origin,
                             **({"period": a.period} if a.period else {})} for a in nonperiodic]}


def every_orbit_lines(omega: float, solutions: "tuple[OrbitSolution, ...]", nonperiodic: tuple[Any, ...],
                      speed_rpm: float | None = None) -> list[str]:
    """The terminal lines of every orbit found at Ω (an exact orbit's census, each orbit exact) and
    of the non-periodic attractors the simulations settled on there; ``speed_rpm`` the crankshaft
    speed of an engine case (named first)."""
    if not solutions and not nonperiodic:
        return []
    where = f"Ω = {omega:.6g} rad/s" if speed_rpm is None else f"{speed_rpm:.5g} rpm (Ω = {omega:.6g} rad/s)"
    lines = [f"every orbit at {where} (exact, {len(solutions)} periodic"
             f"{f', {len(nonperiodic)} non-periodic attractor(s)' if nonperiodic else ''}):"]
    lines += solution_lines(solutions)
    lines += [f"     non-periodic attractor (no period ≤ 8): rms {a.rms:.6g} rad over the recorded window, {a.regime}"
              if not a.period else f"     period-{a.period} attractor (simulated; its exact orbit did not converge): "
              f"rms {a.rms:.6g} rad, {a.regime}" for a in nonperiodic]
    return lines


def _measures_of(simulation: Any) -> Any:
    """The object holding a SteadyState's measures (the state itself or its ``measures``)."""
    inner = getattr(simulation, "measures", None)
    if inner is not None and np.ndim(getattr(inner, "rms", None)) == 1:  # a chain's: per element
        return simulation  # (its flat fields are the first element's)
    return inner if inner is not None and hasattr(inner, "rms") else simulation


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class PeriodicOrbit:
    """Every harmonic-balance orbit found at one forcing frequency, and the simulated steady state.

    Returned by :func:`rattle.analysis.periodic_orbit`.

    Attributes
    ----------
    model : Model
    omega : float
        Forcing frequency Ω (rad/s).
    period : int
        The period that was asked for (multiple of 2π/Ω).
    harmonics : int
        Harmonics H of the harmonic balance.
    solutions : tuple of OrbitSolution
        Distinct HB solutions at Ω: those of the requested period first, then the others
        (e.g. the primary orbits when a sub-harmonic was asked for); within a period by
        decreasing rms.
    simulation : SteadyState or None
        The simulated steady state at Ω (None when ``simulate=False``).
    settings, timings : dict
        Provenance.

    Notes
    -----
    **Selection rule** (:attr:`selected`, used by :meth:`to_csv` and highlighted by
    :meth:`plot`): among the *stable* solutions — those of the requested period if there are
    any, else all stable ones — the one whose rms is closest to the simulated steady state's
    rms (the first of them without a simulation); if no solution is stable, the first solution.
    """

    model: Model
    omega: float
    period: int
    harmonics: int
    solutions: tuple[OrbitSolution, ...]
    simulation: "SteadyState | None" = None
    settings: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)

    # --- container protocol ----------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.solutions)

    def __getitem__(self, index: int) -> OrbitSolution:
        return self.solutions[index]

    def __iter__(self):  # type: ignore[no-untyped-def]
        return iter(self.solutions)

    def __repr__(self) -> str:
        sim = self.simulation
        sim_text = "not simulated" if sim is None else f"simulation period {getattr(sim, 'period', '?')}"
        return (
            f"PeriodicOrbit(Ω = {self.omega:.6g}, period {self.period}, H = {self.harmonics}, "
            f"{len(self)} solution(s): "
            + ", ".join(f"P{s.period} rms {s.rms:.4g} {'s' if s.stable else 'u'}" for s in self.solutions)
            + f"; {sim_text})"
        )

    # --- selection -------------------------------------------------------------------------
    @property
    def simulated_rms(self) -> float | None:
        """rms of δ (rad) of the simulated steady state, or None."""
        if self.simulation is None:
            return None
        rms = getattr(_measures_of(self.simulation), "rms", None)
        return None if rms is None or not math.isfinite(float(rms)) else float(rms)

    @property
    def simulated_period(self) -> int | None:
        """Period (multiple of 2π/Ω) the simulation settled on (0: none up to 8), or None."""
        if self.simulation is None:
            return None
        return int(getattr(self.simulation, "period", 0))

    @property
    def selected(self) -> int | None:
        """Index of the solution chosen by the selection rule (see the class notes); None if empty."""
        if not self.solutions:
            return None
        stable = [i for i, s in enumerate(self.solutions) if s.stable]
        if not stable:
            return 0
        same = [i for i in stable if self.solutions[i].period == self.period]
        pool = same or stable
        rms = self.simulated_rms
        if rms is None:
            return pool[0]
        return min(pool, key=lambda i: abs(self.solutions[i].rms - rms))

    def of_period(self, period: int) -> tuple[OrbitSolution, ...]:
        """The solutions whose least period is ``period``."""
        return tuple(s for s in self.solutions if s.period == period)

    # --- time histories --------------------------------------------------------------------
    def _index(self, solution: int | None) -> int:
        if not self.solutions:
            raise ValueError(f"no harmonic-balance solution was found at Ω = {self.omega:g}; nothing to evaluate")
        if solution is None:
            return int(self.selected)  # type: ignore[arg-type]
        if isinstance(solution, bool) or not isinstance(solution, (int, np.integer)):
            raise TypeError(f"`solution` must be an integer index or None, got {solution!r}")
        if not -len(self) <= solution < len(self):
            raise IndexError(f"`solution` must be in [0, {len(self)}), got {solution}")
        return int(solution) % len(self)

    def time_history(
        self, solution: int | None = None, samples: int = 256, periods: int | None = None
    ) -> dict[str, FloatArray]:
        """Time history of one HB solution from t = 0 (forcing phase as in the model).

        Parameters
        ----------
        solution : int, optional
            Index into :attr:`solutions`; default the :attr:`selected` one.
        samples : int, default 256
            Samples per forcing period 2π/Ω.
        periods : int, optional
            Forcing periods covered; default the solution's period (one full orbit).

        Returns
        -------
        dict of str to numpy.ndarray
            ``t`` (s), ``delta`` (rad), ``velocity`` (rad/s), ``acceleration`` (rad/s², from the
            equation of motion), each of length ``samples * periods + 1`` (both ends included).
            A chain: those of its first element, then ``NAME_delta`` and ``NAME_acceleration``
            of every element NAME.
        """
        i = self._index(solution)
        if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
            raise ValueError(f"`samples` must be an integer >= 2, got {samples!r}")
        sol = self.solutions[i]
        periods = sol.period if periods is None else periods
        if isinstance(periods, bool) or not isinstance(periods, (int, np.integer)) or periods < 1:
            raise ValueError(f"`periods` must be an integer >= 1, got {periods!r}")
        check_history_size(samples, periods, np.size(sol.coefficients) // 2)  # before allocating
        Tf = 2.0 * math.pi / self.omega
        t = np.linspace(0.0, periods * Tf, int(samples) * int(periods) + 1)
        w = np.array([sol.base_frequency])
        tt = t[None, :]
        if sol.elements:
            return self._chain_history(sol, t)
        Q = sol.coefficients[None, :]
        return {
            "t": t,
            "delta": evaluate_batch(Q, w, tt)[0],
            "velocity": evaluate_batch(Q, w, tt, derivative=1)[0],
            "acceleration": acceleration_batch(self.model, Q, w, np.array([self.omega]), tt)[0],
        }

    def _chain_history(self, sol: OrbitSolution, t: FloatArray) -> dict[str, FloatArray]:
        system = self.model.system()
        n = system.n
        Qx = sol.coefficients.reshape(n, -1)
        w = np.full(n, sol.base_frequency)
        tt = np.broadcast_to(t, (n, t.size))
        A = system.element_rows
        delta = A @ evaluate_batch(Qx, w, tt)
        velocity = A @ evaluate_batch(Qx, w, tt, derivative=1)
        acc = element_accelerations(system, Qx[None], w[:1], np.array([self.omega]), t[None, :])[0]
        out = {"t": t, "delta": delta[0], "velocity": velocity[0], "acceleration": acc[0]}
        for k, e in enumerate(system.elements):
            out[f"{e.name}_delta"] = delta[k]
            out[f"{e.name}_acceleration"] = acc[k]
        return out

    def simulated_history(self, samples: int = 256, periods: int | None = None) -> dict[str, FloatArray] | None:
        """The simulated steady state sampled like :meth:`time_history` (t from 0), or None.

        The window starts at the first whole forcing period of the recorded trajectory, so that
        t = 0 has the same forcing phase as the HB solutions; ``periods`` defaults to the
        simulation's period (or the requested one when the simulation found none), and is cut
        to the recorded length.
        """
        sim = self.simulation
        traj = None if sim is None else getattr(sim, "trajectory", None)
        if traj is None:
            return None
        Tf = 2.0 * math.pi / self.omega
        start = math.ceil(traj.t0 / Tf - 1e-9) * Tf
        available = int(math.floor((traj.t1 - start) / Tf + 1e-9))
        if available < 1:  # recorded window shorter than a forcing period: take what there is
            start, available = traj.t0, 0
        if periods is None:
            periods = self.simulated_period or self.period
        periods = max(1, min(int(periods), available)) if available else 1
        end = min(start + periods * Tf, traj.t1)
        n = int(samples) * periods + 1
        t = np.linspace(start, end, n)
        s = traj.sample(np.clip(t, traj.t0, traj.t1))  # round-off may put the ends just outside
        if hasattr(s, "deflection"):  # a chain: the first element, then every element's
            out = {"t": t - start, "delta": s.deflection[:, 0], "velocity": s.deflection_velocity[:, 0],
                   "acceleration": s.deflection_acceleration[:, 0]}
            for k, e in enumerate(traj.system.elements):
                out[f"{e.name}_delta"] = s.deflection[:, k]
                out[f"{e.name}_acceleration"] = s.deflection_acceleration[:, k]
            return out
        return {
            "t": t - start,
            "delta": np.asarray(s.delta),
            "velocity": np.asarray(s.velocity),
            "acceleration": np.asarray(s.acceleration),
        }

    # --- summaries -------------------------------------------------------------------------
    def summary(self) -> str:
        """A few lines for the terminal."""
        speed = SpeedText.of(self.model)
        at = (f"{speed.at(self.omega, 6)} (Ω = {self.omega:.6g} rad/s; H = {self.harmonics})" if speed.engine
              else f"Ω = {self.omega:.6g} rad/s (H = {self.harmonics})")
        lines = [f"{len(self)} harmonic-balance solution(s) at {at}:"]
        sel = self.selected
        lines += solution_lines(self.solutions, sel)
        if self.simulation is not None:
            p = self.simulated_period
            rms = self.simulated_rms
            what = f"period {p}" if p else "no period <= 8 (quasi-periodic or chaotic)"
            rms_text = f", rms {rms:.6g} rad" if rms is not None else ""
            settled = getattr(self.simulation, "settled", True)
            lines.append(f"simulation: {what}{rms_text}{'' if settled else ' (not settled)'}")
            for run in (self.settings.get("extra_simulations") or []) if isinstance(self.settings, dict) else []:
                p_run = int(run.get("period", 0))
                lines.append(
                    f"simulation from next to the unstable period-{run.get('from_period')} orbit (rms "
                    f"{float(run.get('from_rms', float('nan'))):.6g} rad): "
                    + (f"period {p_run}" if p_run else "no period <= 8")
                )
        if not self.of_period(self.period):
            lines.append(f"no harmonic-balance solution of period {self.period} was found at this frequency")
        if sel is not None:
            lines.append(f"* selected for orbit.csv: solution {sel}")
        return "\n".join(lines)

    def metadata(self) -> dict[str, Any]:
        """Settings, timings and every solution's period, stability, measures and multipliers
        (JSON-serialisable)."""
        sim = self.simulation
        sim_doc: dict[str, Any] | None = None
        if sim is not None:
            m = _measures_of(sim)
            sim_doc = {"period": self.simulated_period, "settled": bool(getattr(sim, "settled", True))}
            for name in ("mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max"):
                value = getattr(m, name, None)
                if value is not None:
                    sim_doc[name] = float(value)
        return {
            "omega": self.omega,
            "period": self.period,
            "harmonics": self.harmonics,
            "selected": self.selected,
            "solutions": [solution_record(s) for s in self.solutions],
            "simulation": sim_doc,
            "settings": self.settings,
            "timings": self.timings,
        }

    # --- output delegates ------------------------------------------------------------------
    def to_csv(self, path: str | Path, *, solution: int | None = None, samples: int = 256) -> Path:
        """Write one orbit to ``path`` atomically: the SPEC columns ``t, delta, velocity,
        acceleration`` over one full solution period (``samples`` per forcing period, both ends
        included), for ``solution`` (default the :attr:`selected` one). A chain: those of its
        first element, then ``NAME_delta``, ``NAME_acceleration`` of every element NAME."""
        from ..files import write_csv

        hist = self.time_history(solution, samples=samples)
        write_csv(path, hist, [*ORBIT_COLUMNS, *(k for k in hist if k not in ORBIT_COLUMNS)])
        return Path(path)

    def plot(
        self, fig: Any = None, *, samples: int = 256, periods: int | None = None, title: str | None = None,
        degrees: bool = False,
    ) -> tuple[Any, Any]:
        """δ(t), δ'(t), δ''(t), the phase portrait and the amplitude spectrum; returns
        (figure, :class:`rattle.plotting.PlotAxes`). See :func:`rattle.plotting.orbit_plot`."""
        return plot_with("orbit_plot", self, fig=fig, samples=samples, periods=periods, title=title, degrees=degrees)


__all__ = ["PeriodicOrbit", "OrbitSolution", "ORBIT_SOURCES"]
