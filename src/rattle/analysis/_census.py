"""The census of one response-map combination: every branch on the Ω grid and every attractor the
branches miss, for every law.

:func:`attractor_census` is what a map's cell computes (:func:`rattle.maps.response_map`):

* a smooth law (a :class:`~rattle.model.Model` or chain): the frequency response with its
  sub-harmonic branches (harmonic balance, :func:`~rattle.analysis.frequency_response`), every
  branch solved again by harmonic balance at the grid frequencies
  (:func:`~rattle.analysis._grid.solutions_on_grid`) and the attractor search
  (:func:`~rattle.analysis._attractors.find_attractors`);
* a discontinuous law (a torque jump or friction: single-equation :class:`~rattle.model.System`, or a
  chain with friction, :class:`~rattle.model.System` with its elements' whole laws): the exact shooting continuation
  that ``rattle frf`` runs at its defaults (:func:`~rattle.analysis.frequency_response` with
  :class:`~rattle.analysis.ShootingOptions`, the period-2 branches born at its period doublings
  too), every branch solved exactly at the grid frequencies (:func:`exact_solutions_on_grid`:
  Newton on the period map R(z(0), Ω_j) = (φ_T(z(0); Ω_j) − z(0)) / s at the fixed Ω_j from the
  linear interpolation of the two rows around it) and the attractor search on the exact flow
  (:func:`find_exact_attractors`: the same simulations, from unstable orbits and a multi-start,
  every new periodic attractor continued by exact shooting, :func:`~._exact_branch.branch_through`).

The responses of the two kinds are read through the small accessors below (``omega``, the first
element's ``rms``, ``stable``, ``period``, ``branch``, the special points), the attributes common
to :class:`~rattle.results.FrequencyResponse`, :class:`~rattle.results.NonsmoothCheck` and
:class:`~rattle.results.FrictionCheck` (the exact-check groups of a discontinuous law's response).
"""

from __future__ import annotations

import math
import time
import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._threads import one_blas_thread
from .._typing import FloatArray
from ..continuation import NewtonOptions, solve_fixed
from ..errors import Status
from ..model import System
from ..hb import FourierBasis, HBOptions
from ..results import FrequencyResponse, OrbitSolution, SteadyState
from ..timeint import FLOW_FAILURES, ShootingProblem, make_integrator
from ._attractors import AttractorSearch, Census, SimulatedAttractor, _Search, find_attractors, run_search
from ._exact_branch import ExactBranch, ExactRow, ShootingOptions, _row, branch_through
from ._grid import GridSolution, _crossings, solutions_on_grid
from ._settings import RunSettings
from ._steady import static_state


# ---------------------------------------------------------------------------------------------
# What the map reads of a response, whatever its type
# ---------------------------------------------------------------------------------------------
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


def _exact_part(system: System, branch: ExactBranch, number: int, period: int) -> Any:
    """The response of an exact branch (every row an exact orbit), as ``rattle frf`` builds it."""
    if not system.is_single_equation:
        from ._friction_response import exact_friction_response

        return exact_friction_response(system, branch, number=number, period=period)
    from ._nonsmooth import _exact_response

    return _exact_response(branch, number=number, period=period)


# ---------------------------------------------------------------------------------------------
# Exact branches at the grid frequencies
# ---------------------------------------------------------------------------------------------
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


def exact_solutions_on_grid(system: System, parts: list[Any], grid: FloatArray,
                            newton: NewtonOptions | None = None) -> list[GridSolution]:
    """Every solution of the exact branches ``parts`` (responses with ``omega``, ``states``,
    ``period``, ``branch``) at the frequencies ``grid``.

    Wherever the segment between two consecutive rows crosses Ω_j (the rule of
    :mod:`rattle.analysis._grid`), the periodic orbit of the branch's period p at Ω_j is the zero
    of the period map's scaled defect R(z(0), Ω_j) = (φ_{p 2π/Ω_j}(z(0)) − z(0)) / s, found by
    Newton (exact monodromy) from the linear interpolation of the two rows' states; its rms,
    multipliers and stability are those the branch's own rows would report (the same builder).
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
            resp = _exact_part(system, ExactBranch(rows=rows), number, period)
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
                 min_period: int = 1) -> None:
        self.min_period = min_period
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
        part = _exact_part(self.system, found, self.next_branch, n)
        self.next_branch += 1
        self.counts["branches"] += 1
        record["branch"] = int(part.branch)
        self.census.branches.append(part)
        for s in exact_solutions_on_grid(self.system, [part], self.grid, self.run.newton):
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
                          run: RunSettings, options: AttractorSearch | None = None,
                          solutions: list[GridSolution] | None = None,
                          shooting: ShootingOptions | None = None, min_period: int = 1) -> Census:
    """The attractors on ``grid`` that the exact branches of ``response`` (a NonsmoothCheck or
    FrictionCheck of ``system``) do not explain, found by exact simulation and continued by
    exact shooting (:class:`_ExactSearch`; those of a period below ``min_period`` only recorded),
    with every branch's solutions on the grid."""
    options = options or AttractorSearch()
    if solutions is None:
        solutions = exact_solutions_on_grid(system, response_parts(response), grid, run.newton)
    search = _ExactSearch(system, response, grid, run, options, solutions, shooting or ShootingOptions(), min_period)
    return run_search(search, options)


#: The attractor search of a frequency response with sub-harmonics on a law with jumps or friction
#: (:func:`subharmonic_attractors`): the map's budget (:class:`AttractorSearch`) but for its new
#: branches, at most 4 (the sweep check's, :class:`~._sweep_check.SweepCheck`), on
#: :data:`SUBHARMONIC_POINTS` equally spaced frequencies.
SUBHARMONIC_SEARCH = AttractorSearch(max_branches=4)
SUBHARMONIC_POINTS = 48


def subharmonic_attractors(system: System, response: Any, omega: tuple[float, float],
                           shooting: ShootingOptions, continuation: Any, newton: NewtonOptions | None,
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
    census = find_exact_attractors(system, response, grid, run, search, shooting=shooting, min_period=2)
    return list(census.branches)


# ---------------------------------------------------------------------------------------------
# One combination of a map
# ---------------------------------------------------------------------------------------------
@dataclass
class CellCensus:
    """What :func:`attractor_census` found for one combination: the ``response`` (the frequency
    response, or the exact branches of a discontinuous law), the ``census`` on the grid (every
    branch's solutions, the attractors seen by simulation, the new branches), the ``status``
    ("ok", or "partial" when the response stopped early, ``message`` says why) and the
    ``timings`` (s) of its stages."""

    response: Any
    census: Census
    status: str = "ok"
    message: str = ""
    timings: dict[str, float] = field(default_factory=dict)

    @property
    def branches(self) -> int:
        """How many branches the response holds (before the search's new ones)."""
        return branch_count(self.response)

    @property
    def parts(self) -> list[Any]:
        """Every branch's result: the response's and the search's new ones."""
        return [*response_parts(self.response), *self.census.branches]


def attractor_census(model: Any, grid: FloatArray, run: RunSettings, search: AttractorSearch | None = None, *,
                     max_period: int = 4) -> CellCensus:
    """Every branch on ``grid`` (equally spaced, its ends the range) and the attractors they miss,
    for the model of one map combination (module docstring): a smooth law by harmonic balance
    (sub-harmonic branches up to ``max_period``), a discontinuous law by exact shooting (the
    period-2 branches born at period doublings when ``max_period`` ≥ 2). A response that stops
    early keeps what it computed (status ``partial``); errors before any result raise
    (:class:`~rattle.errors.RattleError`)."""
    from ._frequency_response import _frequency_response
    from ._nonsmooth import nonsmooth_response

    grid = np.asarray(grid, dtype=float)
    search = search or AttractorSearch()
    lo, hi = float(grid[0]), float(grid[-1])
    t0 = time.perf_counter()
    discontinuous = isinstance(model, System) and model.discontinuous
    if discontinuous:
        response = nonsmooth_response(model, (lo, hi), ShootingOptions(), continuation=run.continuation,
                                      newton=run.newton, subharmonics=max_period >= 2, max_period=max_period,
                                      search=None)  # the search below is the fuller one, on the map's grid
    else:
        response = _frequency_response(model, (lo, hi), run, subharmonics=True, max_period=max_period, throw=False)
    status, message = ("ok", "") if response.status.success else ("partial", response.message)
    t1 = time.perf_counter()
    if discontinuous:
        solutions = exact_solutions_on_grid(model, response_parts(response), grid, run.newton)
    else:
        solutions = solutions_on_grid(response, grid, run)
    t2 = time.perf_counter()
    if discontinuous:
        census = find_exact_attractors(model, response, grid, run, search, solutions)
    else:
        census = find_attractors(response, grid, run, search, solutions)
    t3 = time.perf_counter()
    return CellCensus(response, census, status, message,
                      {"frequency_response": t1 - t0, "grid": t2 - t1, "search": t3 - t2})


# ---------------------------------------------------------------------------------------------
# Every exact orbit at one frequency (rattle orbit of a discontinuous law)
# ---------------------------------------------------------------------------------------------
#: Half-width of the window Ω (1 ± w) whose census gives the orbits at Ω, and its grid points (odd:
#: Ω is the middle one). The branches are followed over the window from both ends with the
#: sweep check (an exact up/down sweep over the frequencies where no computed orbit is stable),
#: and the attractor search simulates at every grid point: a coexisting orbit needs only to be
#: reached somewhere in the window.
ORBIT_WINDOW = 0.05
ORBIT_POINTS = 5
#: The search's budget at one frequency: its multi-start (8 starts) and the starts displaced from
#: the stable period-1 orbit (9) at Ω itself (one band, one point), the runs from the unstable
#: orbits over the window.
ORBIT_SEARCH = AttractorSearch(bands=1, starts=8, hb_points=1)
#: Harmonics of an exact orbit's Fourier series in an :class:`~rattle.results.OrbitSolution`.
ORBIT_HARMONICS = 64


@dataclass
class ExactOrbits:
    """Every orbit at one forcing frequency found by :func:`exact_orbits_at`: the periodic ones
    (``solutions``, each an exact orbit, stable and unstable, with the multipliers of its exact
    monodromy), the non-periodic attractors the simulations settled on (``nonperiodic``) and the
    census they come from (``census``)."""

    solutions: tuple[OrbitSolution, ...]
    nonperiodic: tuple[SimulatedAttractor, ...]
    census: CellCensus


def _orbit_solution(system: System, row: ExactRow, period: int, source: str) -> OrbitSolution:
    """An exact orbit as the orbit door's :class:`~rattle.results.OrbitSolution`: its measures
    (the trajectory's own quadrature), multipliers (exact monodromy with saltation matrices) and
    the Fourier series x_k(t) = a_0 + Σ a_h cos(hωt) + b_h sin(hωt), ω = Ω/period, h ≤
    :data:`ORBIT_HARMONICS`, of every coordinate sampled on the exact trajectory."""
    st = _orbit_state(system, row, period)
    n = row.q.size // 2
    H = ORBIT_HARMONICS
    basis = FourierBasis(H, 4 * (2 * H + 1))
    x = np.asarray(row.trajectory.states(basis.times(period * 2.0 * math.pi / row.omega)), dtype=float)[:, :n]
    regimes = st.regimes()
    elements = {}
    if not system.is_single_equation:
        elements = {name: {**st.element(name), "regime": regimes[e]} for e, name in enumerate(system.element_names)}
    coefficients = basis.analyze(x.T).reshape(-1) if elements else basis.analyze(x[:, 0])
    return OrbitSolution(omega=float(row.omega), period=int(period), coefficients=coefficients,
                         stable=bool(np.all(np.abs(row.multipliers) < 1.0)),
                         multipliers=np.asarray(row.multipliers, dtype=complex), mean=st.mean, rms=st.rms,
                         rms_ac=st.rms_ac, p2p=st.p2p, acc_p2p=st.acc_p2p, delta_min=st.delta_min,
                         delta_max=st.delta_max, regime=regimes[0], source=source, elements=elements)


def exact_orbits_at(system: System, omega: float, run: RunSettings | None = None, *,
                    window: float = ORBIT_WINDOW, points: int = ORBIT_POINTS,
                    search: AttractorSearch | None = None, max_period: int = 4) -> ExactOrbits:
    """Every periodic orbit at Ω = ``omega`` of a discontinuous law, and the non-periodic
    attractors there: the census (:func:`attractor_census`) of the window Ω (1 ± ``window``) on
    ``points`` equally spaced frequencies, Ω the middle one — the exact branches followed over the
    window (period 2 from its period doublings), solved at Ω by Newton on the period map, and the
    attractors the simulations settle on that no branch explains, continued by exact shooting.

    A periodic attractor that the simulations settled on and that no branch accounts for (the
    search's branch budget spent, or its continuation failed) is solved at Ω by Newton on the
    period map from its settled state (``source`` ``"simulation"``); one whose Newton fails stays
    in ``nonperiodic`` with its period, as the map lists it.

    Each orbit is solved once more at Ω for its row (exact trajectory and monodromy) and reduced
    to one copy: two orbits of the same period whose states at t = 0 (or at a whole forcing period
    later) agree to 1e-6 of the length scale are one. ``source`` says what found it first:
    ``"continuation"`` (a branch of the window's frequency response), ``"simulation"`` (a branch
    through an attractor the search simulated). Stable first, then by rms (largest first)."""
    if points < 3 or points % 2 == 0:
        raise ValueError(f"`points` must be odd and at least 3, got {points!r}")
    if not 0.0 < window < 1.0:
        raise ValueError(f"`window` must be in (0, 1), got {window!r}")
    run = run or RunSettings.make(HBOptions(), None, None)
    grid = omega * (1.0 + window * np.linspace(-1.0, 1.0, points))
    j = points // 2
    grid[j] = omega
    search = search or ORBIT_SEARCH
    cell = attractor_census(system, grid, run, search, max_period=max_period)
    first = cell.branches
    integ = make_integrator(system)
    L = float(system.length_scale())
    kept: list[tuple[OrbitSolution, FloatArray]] = []
    newton = NewtonOptions()

    def keep(q: FloatArray, period: int, source: str, solve: bool) -> bool:
        problem = ShootingProblem(system, period=period, integrator=integ)
        try:
            if solve:  # a simulated state: Newton on the period map to the exact orbit
                res = solve_fixed(problem, np.asarray(q, dtype=float), float(omega), newton)
                if not res.converged:
                    return False
                q = res.q
            row = _row(problem, q, float(omega))
            cycle = np.asarray(row.trajectory.states(np.arange(period) * (2.0 * math.pi / float(omega))), dtype=float)
            # an orbit of a shorter period d | p (Newton on the p-period map may land on one) is that orbit
            d = next((d for d in range(1, period) if period % d == 0
                      and float(np.max(np.abs(cycle[d] - cycle[0]))) <= 1e-6 * L), period)
            if d < period:
                period, cycle = d, cycle[:d]
                row = _row(ShootingProblem(system, period=d, integrator=integ), q, float(omega))
        except FLOW_FAILURES:
            return False
        if not any(k.period == period and np.min(np.max(np.abs(c - cycle[0]), axis=-1)) <= 1e-6 * L
                   for k, c in kept):
            kept.append((_orbit_solution(system, row, period, source), cycle))
        return True

    with one_blas_thread():
        for s in (s for s in cell.census.solutions if s.index == j and s.converged):
            keep(s.q, int(s.period), "continuation" if s.branch < first else "simulation", False)
        # periodic attractors the simulations settled on that no branch accounts for (the search's
        # budget spent, or its continuation failed): solved at Ω from the settled state
        unsolved = [a for a in cell.census.simulated if a.index == j and a.period > 0
                    and not (a.state is not None and keep(a.state, int(a.period), "simulation", True))]
    solutions = sorted((k for k, _ in kept), key=lambda o: (not o.stable, -o.rms))
    nonperiodic = tuple(a for a in cell.census.simulated if a.index == j and a.period == 0) + tuple(unsolved)
    return ExactOrbits(tuple(solutions), nonperiodic, cell)


def with_every_orbit(system: System, result: Any) -> Any:
    """``result`` (a NonsmoothOrbitResult or FrictionOrbitResult at Ω) with every orbit at Ω
    (:func:`exact_orbits_at`) in its ``solutions`` and ``nonperiodic``."""
    found = exact_orbits_at(system, float(result.omega))
    return dataclasses.replace(result, solutions=found.solutions, nonperiodic=found.nonperiodic)


__all__ = ["CellCensus", "ExactOrbits", "SUBHARMONIC_POINTS", "SUBHARMONIC_SEARCH", "subharmonic_attractors",
           "attractor_census", "exact_orbits_at", "with_every_orbit", "exact_solutions_on_grid", "find_exact_attractors", "special_points",
           "response_parts", "first_rms", "branch_count"]
