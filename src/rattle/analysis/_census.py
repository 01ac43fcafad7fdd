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
  too), every branch solved exactly at the grid frequencies (:func:`~._exact_search.exact_solutions_on_grid`:
  Newton on the period map R(z(0), Ω_j) = (φ_T(z(0); Ω_j) − z(0)) / s at the fixed Ω_j from the
  linear interpolation of the two rows around it) and the attractor search on the exact flow
  (:func:`~._exact_search.find_exact_attractors`: the same simulations, from unstable orbits and a multi-start,
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
from ..model import System
from ..hb import FourierBasis, HBOptions
from ..results import OrbitSolution
from ..timeint import FLOW_FAILURES, ShootingProblem, make_integrator
from ._attractors import AttractorSearch, Census, SimulatedAttractor, find_attractors
from ._exact_branch import ExactBranch, ExactRow, ShootingOptions, _row
from ._exact_search import (
    _orbit_state,
    branch_count,
    exact_solutions_on_grid,
    find_exact_attractors,
    response_parts,
)
from ._grid import solutions_on_grid
from ._settings import RunSettings


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
    def build(branch: ExactBranch, number: int, period: int) -> Any:
        return _exact_part(model, branch, number, period)

    if discontinuous:
        solutions = exact_solutions_on_grid(model, response_parts(response), grid, run.newton, build)
    else:
        solutions = solutions_on_grid(response, grid, run)
    t2 = time.perf_counter()
    if discontinuous:
        census = find_exact_attractors(model, response, grid, run, build, search, solutions)
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


__all__ = ["CellCensus", "ExactOrbits", "attractor_census", "exact_orbits_at", "with_every_orbit"]
