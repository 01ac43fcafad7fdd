"""Sub-harmonic branches of any period (up to 8) of a law with a torque jump, by exact shooting
continuation (the default method): a period-3 attractor that no period doubling reaches, found
by the attractor search and continued as a branch of period 3; a period doubling of a period-2
branch, continued as a branch of period 4.

The case is the torque converter's preloaded spring (examples/torque_converter_preload.toml:
T_p = 0.03, K = I = 1, c = 0.05, F = 0.05 + 0.03 cos Ωt). Checked against the independent
Filippov reference of tests/_filippov.py (scipy DOP853, rtol 1e-12, the mode logic written out
again), which knows nothing of the shooting or the search.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _filippov import single_reference  # tests/ is on sys.path through its conftest

import rattle
from rattle.analysis._nonsmooth import nonsmooth_response
from rattle.model import Excitation, NonsmoothLaw, Preload, System
from rattle.timeint import ShootingProblem


def _torque_converter() -> System:
    return System.single(damping=0.05, stiffness=1.0, law=NonsmoothLaw(elastic=Preload(preload=0.03)),
                           excitation=Excitation(mean=0.05, amplitudes=(0.03,)))


def _reference_rms(system: System, z0: np.ndarray, omega: float, period: int) -> tuple[np.ndarray, float]:
    """The reference's state after ``period`` forcing periods from ``z0`` and the rms of δ over
    them (trapezoidal rule on steps of at most T/4000: error ~1e-9 relative here)."""
    T = 2.0 * math.pi / omega
    z1, ts, xs = single_reference(system, tuple(z0), period * T, omega, max_step=T / 4000)
    return z1, math.sqrt(float(np.trapezoid(xs[0] ** 2, ts)) / (period * T))


def _settled(system: System, z0: np.ndarray, omega: float, periods: int, steps: int | None = None) -> np.ndarray:
    """The reference's state after ``periods`` forcing periods from ``z0`` (``steps``: at least so
    many solver steps a period, for an orbit next to a grazing, whose velocity dip an unbounded
    step passes over)."""
    T = 2.0 * math.pi / omega
    return single_reference(system, tuple(z0), periods * T, omega, max_step=np.inf if steps is None else T / steps)[0]


@pytest.mark.slow
def test_a_stable_period_three_attractor_is_a_branch_of_the_response():
    """Over Ω = 0.86 … 0.93 the period-1 orbit is stable, and beside it (Ω ≈ 0.88 … 0.91) lies a
    stable period-3 attractor that no period doubling reaches (a saddle-node pair). With
    sub-harmonics the response has a branch of period 3 through it: the reference, started 5 % of
    the length scale off the branch's stable row nearest Ω = 0.9 and run 90 forcing periods,
    settles on that row's state (1e-7 L), its one-period map does not (period 3, not 1), and the
    rms of its orbit is the row's to 1e-6."""
    system = _torque_converter()
    frf = rattle.frequency_response(system, (0.86, 0.93), subharmonics=True)
    assert frf.status.success, frf.message
    threes = [p for p in frf.check.branches if p.period == 3]
    assert threes, [(p.branch, p.period) for p in frf.check.branches]
    (part,) = threes
    assert set(np.unique(frf.period[frf.branch == part.branch]).tolist()) == {3}
    stable = np.flatnonzero(part.stable)
    assert stable.size >= 10
    i = int(stable[np.argmin(np.abs(part.omega[stable] - 0.9))])
    w, z0 = float(part.omega[i]), np.asarray(part.states[i], dtype=float)
    assert abs(w - 0.9) < 5e-3
    assert np.max(np.abs(part.multipliers[i])) < 1.0
    L = system.length_scale()
    z = _settled(system, z0 + np.array([0.05 * L, 0.0]), w, 90)
    assert np.max(np.abs(z - z0) / np.array([L, L * max(w, 1.0)])) <= 1e-7
    one = _settled(system, z, w, 1)
    assert np.max(np.abs(one - z)) > 1e-2 * L  # period 3: not back after one forcing period
    z3, rms = _reference_rms(system, z, w, 3)
    assert np.max(np.abs(z3 - z)) <= 1e-7 * L
    assert abs(rms - float(part.rms[i])) <= 1e-6 * rms
    # the response's own table: the period-3 rows, with the branch's number and period
    rows = frf.branch == part.branch
    assert np.allclose(frf.rms[rows], part.rms) and np.all(frf.stable[rows] == part.stable)


def test_without_the_search_no_period_three_branch_is_found():
    """The period-3 branch comes from the attractor search: the period doublings alone (none on
    this range but one at its lower end) do not reach it."""
    res = nonsmooth_response(_torque_converter(), (0.87, 0.93), subharmonics=True, search=None)
    assert not [p for p in res.branches if p.period == 3]


@pytest.mark.slow
def test_a_period_doubling_of_a_period_two_branch_starts_a_period_four_branch():
    """Over Ω = 0.78 … 0.87 the period-1 orbit doubles its period at Ω ≈ 0.8636; the period-2
    branch born there doubles its own at Ω ≈ 0.7952, and the period-4 branch born there is
    followed too (max_period 4, no search). Its rows are exact period-4 orbits of the reference
    (back after four forcing periods to 1e-7 L, not after two; steps of T/2000 at most: the branch
    passes grazings), and its stable row nearest
    Ω = 0.7945 is the attractor the reference settles on from 1e-3 L off (rms to 1e-6)."""
    system = _torque_converter()
    res = nonsmooth_response(system, (0.78, 0.87), subharmonics=True, max_period=4, search=None)
    twos = [p for p in res.branches if p.period == 2]
    fours = [p for p in res.branches if p.period == 4]
    assert twos and fours
    assert any(f"period doubling of branch {p.branch}" in fours[0].origin for p in twos), fours[0].origin
    part = fours[0]
    L = system.length_scale()
    half = ShootingProblem(system, period=2)
    for i in np.unique(np.linspace(0, len(part.omega) - 1, 6).astype(int)):
        w, z0 = float(part.omega[i]), np.asarray(part.states[i], dtype=float)
        z1 = _settled(system, z0, w, 4, steps=2000)
        assert np.max(np.abs(z1 - z0)) <= 1e-7 * L * max(w, 1.0)
        assert np.max(np.abs(half.residual(z0, w))) > 1e-4  # not a period-2 orbit run twice
    stable = np.flatnonzero(part.stable)
    i = int(stable[np.argmin(np.abs(part.omega[stable] - 0.7945))])
    w, z0 = float(part.omega[i]), np.asarray(part.states[i], dtype=float)
    z = _settled(system, z0 + np.array([1e-3 * L, 0.0]), w, 160)
    assert np.max(np.abs(z - z0)) <= 1e-7 * L
    _, rms = _reference_rms(system, z0, w, 4)
    assert abs(rms - float(part.rms[i])) <= 1e-6 * rms
