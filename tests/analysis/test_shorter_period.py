"""A sub-harmonic branch is a period-n attractor only where it is not a shorter period's orbit
written with period n: a seed that is the period-1 orbit repeated is no period-2 branch, and a
period-2 branch continued from a seed stops where it meets the period-1 branch (its period
doublings) instead of following the period-1 orbit on, or passing onto its own copy shifted by a
forcing period — so its special points are its own, each once (the map counted the primary's
fold again as a period-2/3 branch's)."""

from __future__ import annotations

import numpy as np
import pytest

import rattle
from rattle.analysis._branches import SHORTER_PERIOD_RTOL, branch_from_seed, is_shorter_period, sub_harmonic_fraction
from rattle.hb import resize_harmonics


@pytest.fixture(scope="module")
def reference():
    model = rattle.reference_case()
    return model, rattle.frequency_response(model, subharmonics=True)


def test_the_fraction_of_a_repeated_orbit_is_zero():
    q1 = np.random.default_rng(1).normal(size=(1, 2 * 8 + 1))
    q2 = resize_harmonics(q1, 16, factor=2)
    assert sub_harmonic_fraction(q2, 1, 2) == 0.0 and is_shorter_period(q2, 1, 2)
    assert sub_harmonic_fraction(q1, 1, 1) == 1.0 and not is_shorter_period(q1, 1, 1)


def test_a_seed_that_is_the_period_one_orbit_gives_no_period_two_branch(reference):
    model, frf = reference
    i = int(np.flatnonzero((frf.period == 1) & frf.stable)[100])
    H = frf.harmonics
    q2 = resize_harmonics(frf.coefficients[i][: 2 * H + 1].reshape(1, -1), 2 * H, factor=2).reshape(-1)
    assert branch_from_seed(model, float(frf.omega[i]), q2, 2, (0.1, 3.0), 2 * H) is None


def test_a_period_two_branch_from_a_seed_ends_at_its_period_doublings(reference):
    model, frf = reference
    pd = sorted(s.omega for s in frf.special_points if s.kind == "period_doubling" and s.branch == 0)
    lo, hi = next((a, b) for a, b in zip(pd, pd[1:]) if a > 1.0)  # the period-2 branch between 1.24 and 1.96
    rows = np.flatnonzero((frf.period == 2) & (frf.omega > lo) & (frf.omega < hi))
    i = int(rows[rows.size // 2])
    H = (frf.coefficients[i].size - 1) // 2
    branch = branch_from_seed(model, float(frf.omega[i]), frf.coefficients[i], 2, (0.1, 3.0), H)
    assert branch is not None
    assert lo - 1e-3 <= branch.omega.min() and branch.omega.max() <= hi + 1e-3
    fractions = np.array([sub_harmonic_fraction(q, 1, 2) for q in branch.coefficients])
    assert np.sum(fractions < SHORTER_PERIOD_RTOL) <= 2  # at most the two end rows, at the doublings
    folds = [round(s.omega, 4) for s in branch.special_points if s.kind == "fold"]
    assert len(folds) == 2 == len(set(folds)), folds  # each once: not the branch's shifted copy again
    assert all(lo - 1e-3 <= s.omega <= hi + 1e-3 for s in branch.special_points)
    primary_folds = [s.omega for s in frf.special_points if s.kind == "fold" and s.branch == 0]
    assert not any(abs(s.omega - f) < 1e-3 for s in branch.special_points for f in primary_folds)
