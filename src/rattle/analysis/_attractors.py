"""A search for the attractors that a frequency response's branches do not explain.

Continuation from the linear solution, with branch switching at period doublings, finds every
solution connected to the primary branch. It misses what is not connected: isolated branches of
period 1 (isolas), sub-harmonics born elsewhere (a saddle-node pair of period 3, say), and
non-periodic (quasi-periodic, chaotic) attractors. This module looks for them by exact
simulation (:func:`~rattle.analysis.steady_state`) on a frequency grid, and continues every new
periodic attractor as a branch of its own (:func:`~rattle.analysis._branches.branch_from_seed`:
followed both ways in Ω, an isola closed once).

Where the simulations start (the budget, :class:`AttractorSearch`):

1. **From unstable orbits.** (a) Wherever no stable solution is known: on every run of grid
   frequencies where no branch has a stable solution, the simulation starts from the unstable
   orbit there (its section state, nudged by ``nudge`` of the orbit's half peak-to-peak) and
   then walks through the run carrying its state from one frequency to the next, like a time
   sweep, restarting from an unstable orbit where a new branch has made the previous one
   stable. What it settles on decides the grid frequency: a periodic attractor (continued as a
   branch unless known) or a non-periodic one (period 0, SPEC §7). (b) From the middle of
   every unstable stretch of every branch, nudged both ways off the orbit: where its unstable
   manifold leads (usually the known destination of a jump; sometimes an attractor no branch
   reaches).
2. **A modest multi-start per frequency band.** The range is cut into ``bands`` equal bands;
   at the middle grid frequency of each, ``starts`` initial states are simulated: points on
   rings around the static equilibrium whose radii are fixed multiples (½, 1, 2, 3…) of the
   largest half peak-to-peak of the solutions known there, at angles spread by the golden
   ratio, velocities scaled by Ω (deterministic: the same starts on every engine).

3. **Starts in harmonic balance: isolas and sub-harmonics.** A sub-harmonic of order 1/n is
   an orbit with strong content at Ω/n, born in a saddle-node pair (not by period doubling)
   wherever Ω/n meets a resonance of the bent backbone; a period-1 isola is a closed branch of
   orbits (say, impacting on one side) beside the primary one. Their basins may be small, but
   their harmonic-balance equations have solutions whatever the basins: at ``hb_points`` frequencies spread over the
   grid, for each n in
   ``hb_periods``, Newton (period n, n·H harmonics) starts from the stable period-1 orbit
   there plus a component A cos(Ωt/n + φ) in the first element's deflection (A = the
   length scale × ¼, ½, 1, φ = 0, π/2, π, 3π/2), first with 8 harmonics per forcing period, then
   polished with the run's. A converged solution that is truly of period n (n ≥ 2: its
   harmonics that are not multiples of n carry ≥ 1e-3 of its dynamic content) and that no known
   solution explains is checked by exact shooting (the orbit must close on the exact flow,
   within ``match``) and continued as a branch, stable or not — its stable stretches are
   attractors whatever their basins.

A simulated periodic attractor of period n is *explained* when a stable known solution of
period n at the same Ω passes through its section state (scaled max-norm, ``match``, on the
scales of :func:`~rattle.timeint.state_scale`); a non-periodic one is recorded at its
grid frequency. Every unexplained periodic attractor is continued (at most ``max_branches``
new branches per response), and its branch's solutions join the grid.

What it may still miss, stated: a sub-harmonic branch whose whole existence interval lies
between two of the ``hb_points`` frequencies (with the default 24, narrower than
(Ω_max − Ω_min)/24) and whose basin none of the simulations reaches; a period not in ``hb_periods`` reached by no
simulation; a period above ``max_period`` (8 at most: the simulation's period detection); a
period-1 isola no simulation reaches; a non-periodic attractor
coexisting with stable periodic ones outside the multi-start frequencies, and anything beyond
``max_periods`` forcing periods of transient (reported as period 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..hb import HarmonicBalance
from ..results import FrequencyResponse
from ..timeint import SystemTrajectory
from ..timeint import state_scale
from ._branches import branch_from_seed, is_shorter_period
from ._grid import GridSolution, section_states, solutions_on_grid
from ._settings import RunSettings
from ._steady import SteadyStateOptions, make_integrator, steady_state

_GOLDEN = 0.5 * (1.0 + math.sqrt(5.0))
#: Harmonics per forcing period of the harmonic-balance starts before they are polished.
_START_HARMONICS = 8
#: Ring radii of the multi-start, as multiples of the largest known half peak-to-peak.
_RADII = (0.5, 1.0, 2.0, 3.0, 1.5, 4.0, 0.25, 2.5)


@dataclass(frozen=True)
class AttractorSearch:
    """Budget of the attractor search (module docstring).

    Parameters
    ----------
    bands : int
        Frequency bands of the multi-start (default 8; 0 switches the multi-start off).
    starts : int
        Initial states simulated per band (default 4).
    from_unstable : bool
        Simulate from the unstable orbits wherever no stable solution is known (default True).
    max_branches : int
        New branches continued per frequency response at most (default 16; a random multi-stage
        case needed 11). What is found beyond is counted (``not_continued``) and said.
    max_period : int
        Largest period a simulation detects (default 8).
    max_periods : int
        Forcing periods a simulation may take to settle before it counts as non-periodic
        (default 600).
    match : float
        Scaled distance under which a simulated orbit is a known solution (default 1e-3; HB
        truncation errors are ~1e-6, distinct coexisting orbits differ by O(1)).
    nudge : float
        Start offset from an unstable orbit, relative to its half peak-to-peak (default 1e-2).
    hb_periods : tuple of int
        Periods of the harmonic-balance starts (default (1, 2, 3): period-1 isolas and
        sub-harmonics of order 1/2 and 1/3; empty switches them off).
    hb_points : int
        Grid frequencies (equally spread) of the harmonic-balance sub-harmonic starts
        (default 24; 0 switches them off).
    """

    bands: int = 8
    starts: int = 4
    from_unstable: bool = True
    max_branches: int = 16
    max_period: int = 8
    max_periods: int = 600
    match: float = 1e-3
    nudge: float = 1e-2
    hb_periods: tuple[int, ...] = (1, 2, 3)
    hb_points: int = 24

    def __post_init__(self) -> None:
        for name in ("bands", "starts", "max_branches", "max_period", "max_periods", "hb_points"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise ValueError(f"`{name}` must be an integer >= 0, got {value!r}")
        if not 1 <= self.max_period <= 8:
            raise ValueError(f"`max_period` must be in 1 … 8, got {self.max_period!r}")
        periods = tuple(self.hb_periods)
        if any(isinstance(p, bool) or not isinstance(p, (int, np.integer)) or not 1 <= p <= 8 for p in periods):
            raise ValueError(f"`hb_periods` must be periods in 1 … 8, got {self.hb_periods!r}")
        object.__setattr__(self, "hb_periods", tuple(int(p) for p in periods))
        for name in ("match", "nudge"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"`{name}` must be a number > 0, got {value!r}")

    def steady_options(self) -> SteadyStateOptions:
        return SteadyStateOptions(max_periods=self.max_periods, max_period_multiple=self.max_period,
                                  record_periods=20)


@dataclass(frozen=True)
class SimulatedAttractor:
    """An attractor seen by simulation at grid frequency ``omega`` (index ``index``) that no
    branch accounts for: a non-periodic one (``period`` 0), or a periodic one whose branch could
    not be continued (the branch budget was spent, or harmonic balance did not converge to it).
    Its first element's measures (over the recorded window for period 0), its regime, and
    whether some element impacts — a map counts it like any other attractor there. ``state``: the
    settled state at a whole forcing period (t ≡ 0 mod 2π/Ω; None where it was not kept), from
    which the orbit door solves a periodic one exactly."""

    index: int
    omega: float
    period: int
    rms: float
    rms_ac: float
    regime: str
    impacts: bool
    origin: str
    state: np.ndarray | None = field(default=None, repr=False, compare=False)


#: Former name of :class:`SimulatedAttractor` (the non-periodic ones have period 0).
NonPeriodic = SimulatedAttractor


@dataclass
class Census:
    """Everything known on the grid after the search: the solutions of every branch (old and
    new), the attractors seen only by simulation (non-periodic ones, and periodic ones no branch
    accounts for), the new branches, and a log of what was found."""

    solutions: list[GridSolution]
    simulated: list[SimulatedAttractor] = field(default_factory=list)
    branches: list[FrequencyResponse] = field(default_factory=list)
    found: list[dict[str, Any]] = field(default_factory=list)
    counts: dict[str, int] = field(default_factory=dict)


def _impacts(state: Any) -> bool:
    """Whether some element of a simulated motion crosses one of its breakpoints."""
    return any(r != "no_impact" for r in state.regimes())


def _section_state(state: Any) -> np.ndarray | None:
    """A periodic motion's ``state0`` (on the section, a point of its orbit); None for period 0."""
    z = getattr(state, "state0", None)
    if int(state.period) == 0 or z is None:
        return None
    z = np.array(z, dtype=float)
    return z if np.all(np.isfinite(z)) else None


def _coefficients(model: Any, state: Any, hb: HarmonicBalance) -> FloatArray:
    """HB coefficients (coordinate-major) of a settled periodic motion's exact trajectory."""
    return trajectory_coefficients(state.trajectory, state.period * 2.0 * math.pi / state.omega, hb)


def trajectory_coefficients(traj: Any, period: float, hb: HarmonicBalance) -> FloatArray:
    """HB coefficients (coordinate-major) of the exact periodic trajectory ``traj`` of period
    ``period`` (s), sampled on ``hb``'s grid: every coordinate of a chain, δ of the single equation."""
    t = hb.basis.times(period)
    if isinstance(traj, SystemTrajectory):
        x = traj.sample(t).x  # (N, n)
        return hb.basis.analyze(np.asarray(x).T).reshape(-1)
    return hb.basis.analyze(np.asarray(traj.sample(t).delta))


class _Search:
    def __init__(self, frf: FrequencyResponse, grid: FloatArray, run: RunSettings, options: AttractorSearch,
                 solutions: list[GridSolution]) -> None:
        self.frf = frf
        self.model = frf.model
        self.system = self.model.system() if hasattr(self.model, "system") else self.model
        self.grid = np.asarray(grid, dtype=float)
        self.run = run
        self.opts = options
        self.steady = options.steady_options()
        self.integ = make_integrator(self.model)
        self.census = Census(solutions=list(solutions))
        self.counts = {"simulations": 0, "periods": 0, "hb_starts": 0, "unexplained": 0, "branches": 0,
                       "not_continued": 0, "nonperiodic": 0}
        self.next_branch = int(np.max(frf.branch)) + 1 if len(frf) else 1
        self.range = (float(self.grid[0]), float(self.grid[-1]))
        self.by_index: dict[int, list[GridSolution]] = {}
        for s in self.census.solutions:
            self.by_index.setdefault(s.index, []).append(s)

    # --- what is known ------------------------------------------------------------------
    def stable_at(self, j: int) -> list[GridSolution]:
        return [s for s in self.by_index.get(j, []) if s.stable]

    def scale(self, j: int) -> FloatArray:
        return state_scale(self.system, float(self.grid[j]))

    def passes(self, j: int, n: int, point: FloatArray, stable_only: bool) -> bool:
        """Whether a known solution of period n at grid index j (a stable one, with
        ``stable_only``) passes through the section point ``point`` (scaled distance < match)."""
        sc = self.scale(j)
        for s in self.by_index.get(j, []):
            if s.period != n or (stable_only and not s.stable):
                continue
            d = np.max(np.abs(s.section - np.asarray(point, dtype=float)[None, :]) / sc[None, :], axis=1)
            if float(np.min(d)) < self.opts.match:
                return True
        return False

    def explained(self, j: int, state: Any) -> bool:
        """Whether a stable known solution is the simulated periodic motion ``state``."""
        return self.passes(j, int(state.period), state.cycle[0], stable_only=True)

    # --- simulation ---------------------------------------------------------------------
    def simulate(self, j: int, x0: FloatArray, origin: str) -> Any:
        w = float(self.grid[j])
        state = steady_state(self.model, w, x0, options=self.steady, integrator=self.integ)
        self.counts["simulations"] += 1
        self.counts["periods"] += int(state.periods)
        if state.period == 0:
            self.record(j, state, origin)
            self.counts["nonperiodic"] += 1
        elif not self.explained(j, state):
            self.counts["unexplained"] += 1
            self.add_branch(j, state, origin)
            if not self.explained(j, state):  # no branch accounts for it: it still counts here
                self.record(j, state, origin)
        return state

    def record(self, j: int, state: Any, origin: str) -> None:
        self.census.simulated.append(SimulatedAttractor(
            j, float(self.grid[j]), int(state.period), float(state.rms), float(state.rms_ac), str(state.regimes()[0]),
            _impacts(state), origin, _section_state(state)))

    def add_branch(self, j: int, state: Any, origin: str) -> None:
        n = int(state.period)
        H = n * self.run.hb.harmonics
        hb = HarmonicBalance(self.model, self.run.for_harmonics(H), period=n)
        q = _coefficients(self.model, state, hb)
        if is_shorter_period(q, len(self.system.coordinates), n):
            # the simulation's period detection said n, its spectrum says a divisor of n
            self.census.found.append({"omega": float(self.grid[j]), "period": n, "origin": origin, "branch": None,
                                      "rms": float(state.rms), "note": "a shorter period's orbit: not continued"})
            return
        record = self.add_branch_from(j, n, q, H, origin, float(state.rms))
        if record.get("branch") is not None and not self.explained(j, state):
            # The branch does not pass through the simulated orbit (HB with these harmonics
            # converged elsewhere): keep the record honest.
            record["note"] = "continued branch does not pass through the simulated orbit"

    def add_branch_from(self, j: int, n: int, q: FloatArray, H: int, origin: str, rms: float) -> dict[str, Any]:
        """Continue the period-n branch through the coefficients q (H harmonics of Ω/n) at grid
        index j; its solutions join the grid. Returns the record of :attr:`Census.found`."""
        w = float(self.grid[j])
        record: dict[str, Any] = {"omega": w, "period": n, "origin": origin, "branch": None, "rms": rms}
        self.census.found.append(record)
        if self.counts["branches"] >= self.opts.max_branches:
            record["note"] = "branch budget spent: not continued"
            self.counts["not_continued"] += 1
            return record
        branch = branch_from_seed(self.model, w, q, n, self.range, H, run=self.run, branch_id=self.next_branch)
        if branch is None or len(branch) < 2:
            record["note"] = "the seed did not converge in harmonic balance"
            return record
        branch = replace(branch, settings=dict(branch.settings, branches=[{"branch": self.next_branch,
                                                                           "harmonics": H, "period": n}]))
        self.next_branch += 1
        self.counts["branches"] += 1
        record["branch"] = int(branch.branch[0])
        self.census.branches.append(branch)
        for s in solutions_on_grid(branch, self.grid, self.run):
            self.census.solutions.append(s)
            self.by_index.setdefault(s.index, []).append(s)
        if math.isnan(rms):
            mine = [s for s in self.by_index.get(j, []) if s.branch == record["branch"]]
            if mine:
                record["rms"] = float(mine[0].rms)
        return record

    # --- 1. from unstable orbits ----------------------------------------------------------
    def start_near(self, j: int) -> FloatArray | None:
        """A state next to the unstable orbit at grid index j (the primary branch's, else any)."""
        sols = sorted(self.by_index.get(j, []), key=lambda s: (s.branch, -s.rms))
        if not sols:
            return None
        s = sols[0]
        x = np.array(s.section[0], dtype=float)
        n = x.size // 2
        amp = max(0.5 * s.p2p, 1e-3 * float(self.system.length_scale()))
        x[:n] += self.opts.nudge * amp
        return x

    def unstable_runs(self) -> None:
        j = 0
        N = self.grid.size
        state = None
        while j < N:
            if self.stable_at(j):
                state = None
                j += 1
                continue
            # a non-periodic motion is carried on; otherwise start next to the unstable orbit here
            # (None: no solution known at all, steady_state starts from rest at equilibrium)
            carried = state is not None and state.period == 0
            x0 = np.asarray(state.final_state) if carried else self.start_near(j)
            state = self.simulate(j, x0, "carried from the previous frequency" if carried else "unstable orbit")
            j += 1

    def unstable_stretches(self) -> None:
        """From the middle of every unstable stretch of every branch (grid frequencies where the
        branch's solution is unstable, in a run), both ways off the orbit: where the unstable
        orbit's manifold leads is an attractor — usually a known one (the jump's destination),
        sometimes one no branch reaches."""
        runs: dict[tuple[int, int], list[GridSolution]] = {}
        for s in self.census.solutions:
            if not s.stable and s.converged:
                runs.setdefault((s.branch, s.period), []).append(s)
        for (branch, _), sols in sorted(runs.items()):
            sols = sorted(sols, key=lambda s: (s.index, s.rms))
            stretch: list[GridSolution] = []
            for s in sols + [None]:  # type: ignore[list-item]
                if s is not None and (not stretch or s.index <= stretch[-1].index + 1):
                    stretch.append(s)
                    continue
                if stretch:
                    mid = stretch[len(stretch) // 2]
                    # a non-periodic attractor already seen there: its basin is where this
                    # orbit's manifold most likely leads, and it costs max_periods to see again
                    chaotic = any(p.index == mid.index and p.period == 0 for p in self.census.simulated)
                    for sign in (() if chaotic else (1.0, -1.0)):
                        x = np.array(mid.section[0], dtype=float)
                        n = x.size // 2
                        x[:n] += sign * self.opts.nudge * max(0.5 * mid.p2p, 1e-3 * float(self.system.length_scale()))
                        self.simulate(mid.index, x, f"off the unstable orbit of branch {branch}")
                stretch = [s] if s is not None else []

    # --- 3. sub-harmonic starts in harmonic balance ---------------------------------------------
    def band_indices(self) -> list[int]:
        N, B = self.grid.size, self.opts.bands
        edges = np.linspace(0, N, B + 1)
        return [int(min(N - 1, (edges[b] + edges[b + 1]) // 2)) for b in range(B)]

    def closes_exactly(self, w: float, x0: FloatArray, period: int) -> bool:
        """Whether exact shooting from x0 closes a period-``period`` orbit through x0 (within
        ``match``, scaled): the harmonic-balance solution is a true orbit."""
        from ..timeint import shoot_periodic_orbit, shoot_system_orbit

        if self.model is self.system or not hasattr(self.model, "elastic"):
            orbit = shoot_system_orbit(self.system, w, x0, period=period)
        else:
            orbit = shoot_periodic_orbit(self.model, w, x0, period=period, integrator=self.integ)
        if not orbit.converged:
            return False
        sc = state_scale(self.system, w)
        return float(np.max(np.abs(np.asarray(orbit.state0) - x0) / sc)) < self.opts.match

    def hb_subharmonics(self) -> None:
        """Section 3 of the module docstring. The starts are solved first with
        :data:`_START_HARMONICS` harmonics per forcing period (n·8 for period n: 16–25 times
        cheaper than n·H, and enough to tell which solution a start leads to); each distinct
        solution is then polished with the run's n·H harmonics and checked."""
        from ..continuation import solve_fixed
        from ..hb import resize_harmonics

        if not self.opts.hb_periods or self.opts.hb_points == 0:
            return
        H = self.run.hb.harmonics
        Hc = min(H, _START_HARMONICS)
        n_coord = len(self.system.coordinates)
        row = np.asarray(self.system.element_rows[0], dtype=float)
        direction = row / float(row @ row)  # x along it moves the first element's δ by 1
        L = float(self.system.length_scale())
        newton = replace(self.run.newton, max_iterations=max(self.run.newton.max_iterations, 25))
        coarse: dict[int, HarmonicBalance] = {}
        fine: dict[int, HarmonicBalance] = {}
        N, P = self.grid.size, self.opts.hb_points
        for j in sorted({int(min(N - 1, (k + 0.5) * N // P)) for k in range(P)}):
            w = float(self.grid[j])
            base = [s for s in self.by_index.get(j, []) if s.period == 1]
            if not base:
                continue
            s1 = max(base, key=lambda s: (s.stable, s.rms))
            H1 = (np.asarray(s1.q).size // n_coord - 1) // 2
            sc = self.scale(j)
            for n in self.opts.hb_periods:
                if n not in coarse:
                    coarse[n] = HarmonicBalance(self.model, self.run.for_harmonics(n * Hc), period=n)
                    fine[n] = HarmonicBalance(self.model, self.run.for_harmonics(n * H), period=n)
                Hs = n * Hc
                q_base = resize_harmonics(np.asarray(s1.q).reshape(n_coord, 2 * H1 + 1), Hs, factor=n)
                seen: list[FloatArray] = []
                for amp in (0.25 * L, 0.5 * L, 1.0 * L):
                    for phase in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi):
                        q0 = q_base.copy()
                        q0[:, 1] += amp * math.cos(phase) * direction
                        q0[:, Hs + 1] -= amp * math.sin(phase) * direction
                        self.counts["hb_starts"] += 1
                        res = solve_fixed(coarse[n], q0.reshape(-1), w, newton)
                        if not res.converged:
                            continue
                        sec = section_states(res.q, n_coord, w, n)[0]
                        if any(float(np.max(np.abs(sec - x) / sc)) < 1e-2 for x in seen):
                            continue  # a start that led to a solution already examined here
                        seen.append(sec)
                        self.examine(j, n, resize_harmonics(res.q.reshape(n_coord, -1), n * H).reshape(-1),
                                     fine[n], newton)

    def examine(self, j: int, n: int, q0: FloatArray, hb: HarmonicBalance, newton: Any) -> None:
        """Polish a harmonic-balance start's solution with the run's harmonics; continue it as a
        branch if it is truly of period n, unknown, and an orbit of the exact flow."""
        from ..continuation import solve_fixed

        w = float(self.grid[j])
        n_coord = len(self.system.coordinates)
        res = solve_fixed(hb, q0, w, newton)
        if not res.converged:
            return
        Hn = hb.basis.harmonics
        if float(np.linalg.norm(res.q.reshape(n_coord, -1)[:, 1:])) == 0.0 or is_shorter_period(res.q, n_coord, n):
            return  # a solution of a shorter period written with period n
        sec = section_states(res.q, n_coord, w, n)
        if self.passes(j, n, sec[0], stable_only=False):
            return
        if not self.closes_exactly(w, sec[0], n):
            self.census.found.append({"omega": w, "period": n, "origin": "harmonic-balance start", "branch": None,
                                      "rms": float("nan"), "note": "not an orbit of the exact flow: not continued"})
            return
        self.counts["unexplained"] += 1
        self.add_branch_from(j, n, res.q, Hn, "harmonic-balance start", float("nan"))


    # --- 2. multi-start ---------------------------------------------------------------------
    def rest(self, w: float) -> FloatArray:
        """The coordinates (n,) of the static equilibrium at Ω = w: the rings' centre."""
        return np.asarray(self.system.static_equilibrium(w), dtype=float)

    def multistart(self) -> None:
        B, K = self.opts.bands, self.opts.starts
        if B == 0 or K == 0:
            return
        for b, j in enumerate(self.band_indices()):
            w = float(self.grid[j])
            x_eq = self.rest(w)
            n = x_eq.size
            known = self.by_index.get(j, [])
            amp = max([0.5 * s.p2p for s in known], default=0.0)
            amp = max(amp, float(self.system.length_scale()))
            for k in range(K):
                angle = 2.0 * math.pi * ((k + b * K) * _GOLDEN % 1.0)
                r = _RADII[k % len(_RADII)] * amp
                x0 = np.concatenate((x_eq, np.zeros(n)))
                # the first element's direction carries the offset (a free chain: the relative
                # coordinates; a grounded chain: every coordinate alike)
                x0[:n] += r * math.cos(angle)
                x0[n:] += r * w * math.sin(angle)
                self.simulate(j, x0, f"multi-start {k + 1}/{K} of band {b + 1}/{B}")


def find_attractors(frf: FrequencyResponse, grid: FloatArray, run: RunSettings,
                    options: AttractorSearch | None = None,
                    solutions: list[GridSolution] | None = None) -> Census:
    """The attractors on ``grid`` that the branches of ``frf`` do not explain (module
    docstring), with every branch's solutions on the grid (``solutions``: those of ``frf``'s
    branches if already computed)."""
    options = options or AttractorSearch()
    if solutions is None:
        solutions = solutions_on_grid(frf, grid, run)
    return run_search(_Search(frf, grid, run, options, solutions), options)


def run_search(search: _Search, options: AttractorSearch) -> Census:
    """The stages of the search (module docstring) in order, and its census."""
    if options.from_unstable:
        search.unstable_runs()
        search.unstable_stretches()
    search.hb_subharmonics()
    search.multistart()
    search.census.counts = dict(search.counts)
    return search.census


__all__ = ["AttractorSearch", "Census", "SimulatedAttractor", "NonPeriodic", "find_attractors"]
