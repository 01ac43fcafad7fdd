"""The period-2 branches of a chain with friction or jumps on its elements, born at the period
doublings of its period-1 branch (:func:`friction_subharmonics`).

At a period doubling a real Floquet multiplier μ of the period-1 orbit passes through −1, and a
period-2 orbit branches off on the side where |μ| > 1 (supercritical) or the other
(subcritical). The branch is found in three steps, the single equation's recipe
(:func:`rattle.analysis.nonsmooth_subharmonics`) for the chain's 2n states:

1. **Exact seed.** The exact period-1 orbit at the row next to the doubling (its state z(0) from
   the primary branch, shot again for its monodromy M with saltation matrices) is pushed along
   the eigenvector v of M's negative real multiplier nearest −1, z = z(0) ± a v (a = 2 %, 10 %,
   30 % of the orbit's largest element peak-to-peak, in the scaled state), and shot over two
   forcing periods. An orbit that returns after one period (every δ_e(t + T) within 1e-3 of its
   peak-to-peak of δ_e(t)) is the period-1 orbit again and does not count.
2. **The regularised HB of period 2** (:class:`~rattle.hb.RegularisedSystemBalance` with p = 2,
   2H harmonics of Ω/2: the same resolution in time) is solved at ε from the seed's spectrum,
   else narrowed from 4ε or 10ε; it must carry odd harmonics (:data:`~._period_two.ODD_SHARE`).
   It is continued both ways until its odd harmonics vanish or change sign (it rejoined a
   period-1 branch) or the range ends (:func:`~._period_two.follow_both_ways`).
3. **Every row checked by exact shooting over two periods**, refined at its regularisation's
   limit where it misses (:func:`~._friction_response.check_branch`, as on the primary branch). A
   row whose exact orbit repeats after one period is not matched: near the ends of the branch
   the regularised and the exact period doublings sit apart.

Where the regularised HB has no period-2 orbit next to the exact seed (Newton falls back to the
period-1 orbit: where friction sticks, the regularisation's creep moves the period doubling), the
branch is followed by exact shooting alone (natural continuation over the primary's frequencies,
the step halved up to four times where the shooting fails), and says so (``followed`` =
"exact shooting"; the HB columns nan).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._typing import FloatArray
from .._validate import check_range
from ..continuation import ContinuationOptions, NewtonOptions
from ..errors import Status
from ..model import System
from ..results import FrictionCheck
from ..timeint import FLOW_FAILURES, ExactIntegrator, FrictionOrbit, shoot_friction_orbit
from ._friction_response import (
    REPEAT_TOL,
    UNIT_TOL,
    _orbit_spectrum,
    chain_options,
    check_branch,
    exact_measures,
    friction_balance_factory,
    period_gap,
)
from ._period_two import branches_at_doublings, follow_both_ways, follow_exactly, period_two_hb, pushed_starts
from ._regularisation import RegularisationOptions

#: A seed shot over two periods counts as a period-2 orbit when some δ_e(t + T) departs from
#: δ_e(t) by more than this share of its peak-to-peak (:func:`period_gap`).
SEED_GAP = 1e-3
#: Newton iterations of an exact shooting over two periods, from a seed's pushed start or from the
#: orbit at the neighbouring frequency of the exact branch: a start that converges does so in a
#: few (each iteration costs two periods of the exact flow, 30–50 ms on the test chains); one that
#: has not by then is given up (a fold: the step is halved; a seed: the next push is tried).
EXACT_ITERATIONS = 20


def period_two_orbit(system: System, integ: ExactIntegrator, omega: float,
                     state: FloatArray) -> FrictionOrbit | None:
    """An exact period-2 orbit next to the exact period-1 orbit through ``state`` at ``omega``,
    one of whose multipliers lies near −1 (module docstring, step 1); None when every shot
    returns to the period-1 orbit or fails."""
    try:
        one = shoot_friction_orbit(system, omega, state, integrator=integ, max_iterations=30)
    except FLOW_FAILURES:
        return None
    if not one.converged:
        return None
    n, L = system.n, system.length_scale()
    scale = np.concatenate((np.full(n, L), np.full(n, integ.velocity_scale(omega))))
    d = one.trajectory.element_samples(np.linspace(0.0, 2.0 * math.pi / omega, 65))[0]
    size = max(float(np.max(np.ptp(d, axis=0))), 1e-12 * L)
    for z0 in pushed_starts(one.trajectory.sensitivity, one.state0, scale, size, L):
        try:
            two = shoot_friction_orbit(system, omega, z0, period=2, integrator=integ, max_iterations=EXACT_ITERATIONS)
        except FLOW_FAILURES:
            continue
        if two.converged and period_gap(two.trajectory, omega) > SEED_GAP:
            return two
    return None


def _period_two_start(make2, orbit: FrictionOrbit, omega: float, eps: float, H2: int,  # type: ignore[no-untyped-def]
                      newton: NewtonOptions | None) -> FloatArray | None:
    """The regularised period-2 HB orbit (H2 harmonics of Ω/2) at ε next to the exact period-2
    ``orbit`` (module docstring, step 2); None when none carries odd harmonics."""
    pb = make2(eps, H2)
    return period_two_hb(make2, _orbit_spectrum(pb, orbit.trajectory, omega), omega, eps, H2, newton,
                         pb.n_coordinates)


def friction_subharmonics(
    system: System,
    primary: FrictionCheck,
    omega: tuple[float, float],
    options: RegularisationOptions | None = None,
    *,
    continuation: ContinuationOptions | None = None,
    newton: NewtonOptions | None = None,
) -> tuple[FrictionCheck, ...]:
    """The period-2 branches born at the period doublings of the chain's period-1 branch
    ``primary`` (:func:`~rattle.analysis._friction_response.friction_response` of ``system`` with
    the same ``options``; None: :func:`~rattle.analysis._friction_response.chain_options`) within
    ``omega`` (module docstring), numbered 1, 2, … in order of Ω. Where the regularised HB of
    period 2 has no orbit next to the exact seed, the exact branch is followed by exact shooting
    alone over the primary's frequencies (``followed`` "exact shooting", no HB values). A doubling
    that lies on a branch already found (its other end) starts none; one where no exact period-2
    orbit is found next to it starts none either."""
    if not (isinstance(system, System) and system.discontinuous):
        raise TypeError(f"`system` must be a rattle.model.System with its elements' whole laws "
                        f"(Chain.friction_system()), got {system!r}")
    if not isinstance(primary, FrictionCheck):
        raise TypeError(f"`primary` must be the FrictionCheck of `system`, got {primary!r}")
    lo, hi = check_range(omega)
    opts = chain_options(system) if options is None else options
    if not isinstance(opts, RegularisationOptions):
        raise TypeError(f"`options` must be a RegularisationOptions or None, got {opts!r}")
    H2 = 2 * opts.harmonics
    opts2 = dataclasses.replace(opts, harmonics=H2, limit_harmonics=max(opts.limit_harmonics, H2),
                                deep_harmonics=max(opts.deep_harmonics, H2))
    make2 = friction_balance_factory(system, period=2)
    integ = ExactIntegrator(system)
    states = primary.states

    def seed(i: int) -> FrictionOrbit | None:
        return None if states is None else period_two_orbit(system, integ, float(primary.omega[i]), states[i])

    def from_seed(w0: float, orbit: FrictionOrbit, number: int, origin: str) -> FrictionCheck | None:
        q2 = _period_two_start(make2, orbit, w0, opts.regularisation, H2, newton)
        if q2 is None:
            return None
        points, status, message = follow_both_ways(make2(opts.regularisation, H2), q2, w0, lo, hi, continuation,
                                                   newton)
        if not points:
            return None
        return check_branch(system, make2, points, opts2, integ, status=status, message=message, branch=number,
                            origin=origin)

    def exact(w0: float, orbit: FrictionOrbit, grid: FloatArray, number: int, origin: str) -> FrictionCheck:
        return _exact_branch(system, integ, orbit, w0, grid, opts, branch=number, origin=origin)

    return branches_at_doublings(primary, lo, hi, seed, from_seed, exact)


def _exact_branch(system: System, integ: ExactIntegrator, seed: FrictionOrbit, omega: float,
                  grid: FloatArray, opts: RegularisationOptions, *, branch: int, origin: str) -> FrictionCheck:
    """The exact period-2 branch through ``seed`` (at ``omega``) followed over the frequencies
    ``grid`` each way by Newton shooting over two periods from the orbit at the previous frequency
    (:func:`~._period_two.follow_exactly`), until the shooting fails, its orbit repeats after one
    period (the branch rejoined a period-1 branch) or the grid ends. Used where the regularised HB
    of period 2 has no orbit next to the exact one (where friction sticks, the regularisation's
    creep moves the period doubling); the rows carry no HB values (nan)."""
    def shoot(w: float, prev: FrictionOrbit) -> FrictionOrbit | str:
        try:
            orbit = shoot_friction_orbit(system, w, prev.state0, period=2, integrator=integ,
                                         max_iterations=EXACT_ITERATIONS)
        except FLOW_FAILURES as exc:
            return f"the exact shooting failed at Ω = {w:.6g} ({exc})"
        if not orbit.converged:
            return f"the exact shooting did not converge at Ω = {w:.6g} (a fold or the end of the branch)"
        if period_gap(orbit.trajectory, w) <= REPEAT_TOL:
            return (f"the shooting at Ω = {w:.6g} lands on an orbit of period 1 (the branch rejoined a period-1 "
                    "branch, or ends at a fold)")
        return orbit

    pairs, ends = follow_exactly(shoot, seed, omega, grid)
    n, m, P = system.n, system.m, len(pairs)
    rows = [exact_measures(orbit.trajectory, w, 2) for w, orbit in pairs]
    mean, rms, stick, states, pattern, mult = (np.array([r[k] for r in rows]) for k in range(6))
    nan_m, nan_mu = np.full((P, m), np.nan), np.full((P, 2 * n), np.nan + 0j)
    stable = np.abs(mult).max(axis=1) < 1.0 + UNIT_TOL
    omegas = np.array([w for w, _ in pairs])
    rpm = system.speed_rpm(omegas)
    message = "followed by exact shooting alone (the regularised HB of period 2 has no orbit next to the exact one " \
              "there); " + "; ".join(ends)
    return FrictionCheck(
        omega=omegas, rpm=None if rpm is None else np.asarray(rpm, dtype=float), element_names=system.element_names,
        rms=rms, rms_hb=nan_m, mean=mean, stick_fraction=stick, matched=np.ones(P, dtype=bool),
        match_distance=np.full(P, np.nan), stable=stable, stable_hb=np.zeros(P, dtype=bool), multipliers=mult,
        multipliers_hb=nan_mu, status=Status.SUCCESS, message=message, regularisation=float(opts.regularisation),
        harmonics=0, limit_index=np.zeros(0, dtype=int), limit_eps=np.zeros(0), limit_harmonics=np.zeros(0, dtype=int),
        limit_rms=np.zeros((0, m)), limit_richardson=np.zeros((0, m)), limit_linear=np.zeros(0, dtype=bool),
        limit_multipliers=np.zeros((0, 2 * n), dtype=complex), pattern=pattern, period=2, branch=branch,
        origin=origin, states=states, followed="exact shooting")


__all__ = ["friction_subharmonics", "period_two_orbit"]
