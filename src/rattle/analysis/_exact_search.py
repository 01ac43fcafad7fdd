"""The attractor search on the exact flow of a law with jumps or friction, and the exact branches
solved at the frequencies of a grid: the parts of a map's census (:mod:`._census`) that a frequency
response with sub-harmonics runs too (:func:`subharmonic_attractors`).

* :func:`exact_solutions_on_grid`: every branch solved exactly at the grid frequencies (Newton on
  the period map R(z(0), Ω_j) = (φ_T(z(0); Ω_j) − z(0)) / s at the fixed Ω_j from the linear
  interpolation of the two rows around it);
* :func:`find_exact_attractors`: the simulations of :mod:`._attractors` on the exact flow, from
  unstable orbits and a multi-start, every new periodic attractor continued by exact shooting
  (:func:`~._exact_branch.branch_through`).

A branch becomes a response by ``build(branch, number, period)`` — the front end's own builder,
given by the caller (this module sits below the front ends: it imports none of them). The
responses of the two kinds are read through the small accessors below (``omega``, the first
element's ``rms``, ``stable``, ``period``, ``branch``, the special points), the attributes common
to :class:`~rattle.results.FrequencyResponse`, :class:`~rattle.results.NonsmoothCheck` and
:class:`~rattle.results.FrictionCheck`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .._threads import one_blas_thread
from .._typing import FloatArray
from ..continuation import NewtonOptions, solve_fixed
from ..errors import Status
from ..hb import HBOptions
from ..model import System
from ..results import FrequencyResponse, SteadyState
from ..timeint import FLOW_FAILURES, ShootingProblem, make_integrator
from ._attractors import AttractorSearch, Census, _Search, run_search
from ._exact_branch import ExactBranch, ExactRow, ShootingOptions, _row, branch_through
from ._grid import GridSolution, _crossings
from ._settings import RunSettings
from ._steady import static_state

#: ``build(branch, number, period)``: the response of an exact branch (a NonsmoothCheck or
#: FrictionCheck), as ``rattle frf`` builds it.
Build = Callable[[ExactBranch, int, int], Any]


def response_parts(response: Any) -> list[Any]:
    """The branches of a response, each a result of its own: a FrequencyResponse is one table
    (its ``branch`` column tells them apart); a Nonsmooth/FrictionCheck carries its other
    branches in ``branches``."""
    if isinstance(response, FrequencyResponse):
        return [response]
    return [response, *response.branches]


def first_rms(part: Any) -> FloatArray:
    """rms of the first element per row (P,): a chain's results hold one column per element."""
    rms = np.asarray(part.rms, dtype=float)
    return rms if rms.ndim == 1 else rms[:, 0]


def branch_count(response: Any) -> int:
    """How many branches ``response`` holds."""
    if isinstance(response, FrequencyResponse):
        return int(len(np.unique(response.branch)))
    return len(response_parts(response))


def special_points(parts: list[Any]) -> list[dict[str, Any]]:
    """The special points of the responses ``parts`` as records (kind, omega, branch, period,
    rms of the first element): a FrequencyResponse's ``special_points``, an exact branch's
    located ``labels``."""
    out = []
    for part in parts:
        if isinstance(part, FrequencyResponse):
            for sp in part.special_points:
                out.append({"kind": sp.kind, "omega": float(sp.omega), "branch": int(sp.branch),
                            "period": int(part.period[sp.index]), "rms": float(part.rms[sp.index])})
            continue
        labels = getattr(part, "labels", None)
        if labels is None:
            continue
        rms = first_rms(part)
        for i in np.flatnonzero(np.asarray(labels, dtype=object) != ""):
            out.append({"kind": str(labels[i]), "omega": float(part.omega[i]), "branch": int(part.branch),
                        "period": int(part.period), "rms": float(rms[i])})
    return out


def _orbit_state(system: System, row: ExactRow, period: int) -> SteadyState:
    """The exact orbit of ``row`` as a :class:`~rattle.results.SteadyState` (what a simulation
    that settled on it reports): its measures and regimes are then those of the attractors the
    search sees, computed by the same functions."""
    traj = row.trajectory
    t = np.arange(period) * (2.0 * math.pi / row.omega)
    measures, cycle = traj.measures(), traj.states(t)
    names = () if system.is_single_equation else system.element_names
    return SteadyState(omega=float(row.omega), period=int(period), status=Status.CONVERGED, periods=0,
                       shooting_periods=0, state0=row.q, final_state=row.q, cycle=cycle, poincare=cycle[:1],
                       trajectory=traj, measures=measures, multipliers=row.multipliers, residual=0.0,
                       element_names=names)


def exact_solutions_on_grid(system: System, parts: list[Any], grid: FloatArray, newton: NewtonOptions | None,
                            build: Build) -> list[GridSolution]:
    """Every solution of the exact branches ``parts`` (responses with ``omega``, ``states``,
    ``period``, ``branch``) at the frequencies ``grid``.

    Wherever the segment between two consecutive rows crosses Ω_j (the rule of
    :mod:`rattle.analysis._grid`), the periodic orbit of the branch's period p at Ω_j is the zero
    of the period map's scaled defect R(z(0), Ω_j) = (φ_{p 2π/Ω_j}(z(0)) − z(0)) / s, found by
    Newton (exact monodromy) from the linear interpolation of the two rows' states; its rms,
    multipliers and stability are those the branch's own rows would report (the same builder,
    ``build(branch, number, period)``: the response of an exact branch as ``rattle frf`` builds it).
    A Newton solution farther from its guess than the segment is long (scaled max-norm: it left
    the branch, near a fold or a grazing), or none, leaves the nearer row standing for the point
    (its own Ω and values, ``converged`` False)."""
    grid = np.asarray(grid, dtype=float)
    newton = newton or NewtonOptions()
    integ = make_integrator(system)
    out: list[GridSolution] = []
    with one_blas_thread():
        for part in parts:
            om = np.asarray(part.omega, dtype=float)
            states = getattr(part, "states", None)
            if om.size < 2 or states is None:
                continue
            period, number = int(part.period), int(part.branch)
            problem = ShootingProblem(system, period=period, integrator=integ)
            s = problem.length_scale
            rows: list[ExactRow] = []
            where: list[tuple[int, bool]] = []
            for i, j in _crossings(om, grid):
                a, c = np.asarray(states[i], dtype=float), np.asarray(states[i + 1], dtype=float)
                if not (np.all(np.isfinite(a)) and np.all(np.isfinite(c))):
                    continue
                w = float(grid[j])
                t = 0.0 if om[i + 1] == om[i] else (w - om[i]) / (om[i + 1] - om[i])
                guess = (1.0 - t) * a + t * c
                seg = max(float(np.max(np.abs((c - a) / s))), 1e-9)
                try:
                    res = solve_fixed(problem, guess, w, newton)
                    ok = res.converged and float(np.max(np.abs((res.q - guess) / s))) <= seg
                    near = i if t < 0.5 else i + 1
                    rows.append(_row(problem, res.q, w) if ok else _row(problem, np.asarray(states[near]), om[near]))
                except FLOW_FAILURES:
                    continue
                where.append((j, ok))
            if not rows:
                continue
            resp = build(ExactBranch(rows=rows), number, period)
            rms, stable = first_rms(resp), np.asarray(resp.stable, dtype=bool)
            for k, (row, (j, ok)) in enumerate(zip(rows, where)):
                st = _orbit_state(system, row, period)
                regimes = st.regimes()
                out.append(GridSolution(
                    index=j, omega=float(row.omega), branch=number, period=period, stable=bool(stable[k]),
                    rms=float(rms[k]), rms_ac=st.rms_ac, p2p=st.p2p, acc_p2p=st.acc_p2p, delta_min=st.delta_min,
                    delta_max=st.delta_max, regime=regimes[0], impacts=any(r != "no_impact" for r in regimes),
                    section=st.cycle, q=np.asarray(row.q, dtype=float), converged=ok))
    return out


# ---------------------------------------------------------------------------------------------
# The attractor search on the exact flow
# ---------------------------------------------------------------------------------------------
class _ExactSearch(_Search):
    """The attractor search of :mod:`rattle.analysis._attractors` on the exact flow of a
    discontinuous law: the simulations are the same (:func:`~rattle.analysis.steady_state` runs
    the event-driven integrators); an unexplained periodic attractor of period n is continued by
    exact shooting continuation through its orbit (:func:`~._exact_branch.branch_through`), its
    rows solved on the grid exactly (:func:`exact_solutions_on_grid`). The harmonic-balance
    starts (section 3 there) become simulations (:meth:`hb_subharmonics`); the period-2
    branches born at period doublings come with the response."""

    def __init__(self, system: System, response: Any, grid: FloatArray, run: RunSettings,
                 options: AttractorSearch, solutions: list[GridSolution], shooting: ShootingOptions,
                 build: Build, min_period: int = 1) -> None:
        self.min_period = min_period
        self.build = build
        self.frf = response
        self.model = self.system = system
        self.grid = np.asarray(grid, dtype=float)
        self.run = run
        self.opts = options
        self.shooting = shooting
        self.steady = options.steady_options()
        self.integ = make_integrator(system)
        self.census = Census(solutions=list(solutions))
        self.counts = {"simulations": 0, "periods": 0, "hb_starts": 0, "unexplained": 0, "branches": 0,
                       "not_continued": 0, "nonperiodic": 0}
        self.next_branch = 1 + max((int(p.branch) for p in response_parts(response)), default=0) \
            if response is not None else 1
        self.range = (float(self.grid[0]), float(self.grid[-1]))
        self.by_index: dict[int, list[GridSolution]] = {}
        for s in self.census.solutions:
            self.by_index.setdefault(s.index, []).append(s)

    def scale(self, j: int) -> FloatArray:
        """The scales of the state (x, x') at grid index j: L, and L times the larger of Ω and the
        stiffest natural frequency (the exact shooting's and the settling's)."""
        w = float(self.grid[j])
        n = self.rest(w).size
        return np.concatenate((np.full(n, float(self.system.length_scale())),
                               np.full(n, float(self.integ.velocity_scale(w)))))

    def rest(self, w: float) -> FloatArray:
        x = static_state(self.system, w)
        return np.asarray(x[: x.size // 2], dtype=float)

    def add_branch(self, j: int, state: Any, origin: str) -> None:
        n = int(state.period)
        w = float(self.grid[j])
        record: dict[str, Any] = {"omega": w, "period": n, "origin": origin, "branch": None, "rms": float(state.rms)}
        self.census.found.append(record)
        if n < self.min_period:
            record["note"] = f"period below {self.min_period}: not continued here"
            return
        if self.counts["branches"] >= self.opts.max_branches:
            record["note"] = "branch budget spent: not continued"
            self.counts["not_continued"] += 1
            return
        try:
            found = branch_through(self.system, np.asarray(state.state0, dtype=float), w, n, self.range, self.shooting,
                                   continuation=self.run.continuation, newton=self.run.newton, origin=origin)
        except FLOW_FAILURES as exc:
            record["note"] = f"the exact continuation failed ({exc})"
            return
        if len(found.rows) < 2:
            record["note"] = "the exact continuation through the simulated orbit did not go on"
            return
        part = self.build(found, self.next_branch, n)
        self.next_branch += 1
        self.counts["branches"] += 1
        record["branch"] = int(part.branch)
        self.census.branches.append(part)
        for s in exact_solutions_on_grid(self.system, [part], self.grid, self.run.newton, self.build):
            self.census.solutions.append(s)
            self.by_index.setdefault(s.index, []).append(s)
        if not self.explained(j, state):
            record["note"] = "continued branch does not pass through the simulated orbit"

    def hb_subharmonics(self) -> None:
        """The exact flow's counterpart of the harmonic-balance starts (section 3 of
        :mod:`._attractors`): at the same ``hb_points`` grid frequencies, exact simulations from
        the most energetic stable period-1 orbit there displaced in (x, x'/Ω) by A (cos φ, sin φ)
        along every coordinate, A = ½, 1 and 2 × max(the orbit's half peak-to-peak, the length
        scale), φ = 0, 2π/3, 4π/3 (deterministic): a sub-harmonic or an isola born in a
        saddle-node pair has a basin beside the primary orbit, which these reach where the bands'
        multi-start (one frequency per band) does not."""
        if not self.opts.hb_periods or self.opts.hb_points == 0:
            return
        N, P = self.grid.size, self.opts.hb_points
        L = float(self.system.length_scale())
        for j in sorted({int(min(N - 1, (k + 0.5) * N // P)) for k in range(P)}):
            w = float(self.grid[j])
            base = [s for s in self.by_index.get(j, []) if s.period == 1 and s.stable]
            if not base:
                continue
            s1 = max(base, key=lambda s: s.rms)
            x1 = np.asarray(s1.section[0], dtype=float)
            n = x1.size // 2
            amp = max(0.5 * s1.p2p, L)
            for r in (0.5, 1.0, 2.0):
                for phi in (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0):
                    x0 = x1.copy()
                    x0[:n] += r * amp * math.cos(phi)
                    x0[n:] += r * amp * w * math.sin(phi)
                    self.counts["hb_starts"] += 1
                    self.simulate(j, x0, f"sub-harmonic start at Ω = {w:.6g}")


def find_exact_attractors(system: System, response: Any, grid: FloatArray,
                          run: RunSettings, build: Build, options: AttractorSearch | None = None,
                          solutions: list[GridSolution] | None = None,
                          shooting: ShootingOptions | None = None, min_period: int = 1) -> Census:
    """The attractors on ``grid`` that the exact branches of ``response`` (a NonsmoothCheck or
    FrictionCheck of ``system``) do not explain, found by exact simulation and continued by
    exact shooting (:class:`_ExactSearch`; those of a period below ``min_period`` only recorded),
    with every branch's solutions on the grid."""
    options = options or AttractorSearch()
    if solutions is None:
        solutions = exact_solutions_on_grid(system, response_parts(response), grid, run.newton, build)
    search = _ExactSearch(system, response, grid, run, options, solutions, shooting or ShootingOptions(), build,
                          min_period)
    return run_search(search, options)


#: The attractor search of a frequency response with sub-harmonics on a law with jumps or friction
#: (:func:`subharmonic_attractors`): the map's budget (:class:`AttractorSearch`) but for its new
#: branches, at most 4 (the sweep check's, :class:`~._sweep_check.SweepCheck`), on
#: :data:`SUBHARMONIC_POINTS` equally spaced frequencies.
SUBHARMONIC_SEARCH = AttractorSearch(max_branches=4)
SUBHARMONIC_POINTS = 48


def subharmonic_attractors(system: System, response: Any, omega: tuple[float, float],
                           shooting: ShootingOptions, continuation: Any, newton: NewtonOptions | None, build: Build,
                           search: AttractorSearch = SUBHARMONIC_SEARCH,
                           points: int = SUBHARMONIC_POINTS) -> list[Any]:
    """The branches of period p ≥ 2 through the periodic attractors that exact simulations settle
    on over ``omega`` and that no branch of ``response`` (a NonsmoothCheck or FrictionCheck of
    ``system`` with its branches) accounts for: the map's attractor search
    (:func:`find_exact_attractors`) on ``points`` equally spaced frequencies with the budget
    ``search``, each such attractor of period p continued by exact shooting continuation over p
    forcing periods (:func:`~._exact_branch.branch_through`: both ways until it leaves the range,
    closes on itself or rejoins an orbit of a period dividing p). Numbered after the response's
    branches."""
    grid = np.linspace(float(omega[0]), float(omega[1]), points)
    run = RunSettings.make(HBOptions(), newton, continuation)
    census = find_exact_attractors(system, response, grid, run, build, search, shooting=shooting, min_period=2)
    return list(census.branches)


__all__ = ["Build", "SUBHARMONIC_POINTS", "SUBHARMONIC_SEARCH", "branch_count", "exact_solutions_on_grid",
           "find_exact_attractors", "first_rms", "response_parts", "special_points", "subharmonic_attractors"]
