"""The start of a frequency response where Newton from the linear solution fails: the forcing
homotopy R(q; Ω, λ) = 0, λ from 0 to 1, runs on ContinuationStepper (no loop of its own)."""

from __future__ import annotations

import numpy as np
import pytest

from rattle.analysis import start_solution
from rattle.continuation import ContinuationStepper, ForcingHomotopy, NewtonOptions, solve_fixed
from rattle.errors import Status
from rattle.hb import HarmonicBalance, HBOptions
from rattle.model import reference_case


@pytest.fixture
def steppers(monkeypatch):
    """Every ContinuationStepper that runs, in order."""
    seen: list[ContinuationStepper] = []
    run = ContinuationStepper.run

    def spy(self):
        seen.append(self)
        return run(self)

    monkeypatch.setattr(ContinuationStepper, "run", spy)
    return seen


@pytest.mark.parametrize("omega, harmonics", [(0.9, 16), (0.1, 8)])
def test_a_hard_start_is_reached_by_the_stepper_and_solves_the_balance(steppers, omega, harmonics, rng):
    """At Ω = 0.9 (inside the bent resonance) and Ω = 0.1 with H = 8, Newton from the linear
    solution fails; the start comes from the stepper's homotopy branch, through its folds in λ,
    and is the harmonic-balance orbit at the full forcing: direct Newton from it, and from it
    perturbed by 1e-3 of the length scale, returns it to Newton tolerance."""
    hb = HarmonicBalance(reference_case(), HBOptions(harmonics=harmonics))
    newton = NewtonOptions()
    assert not solve_fixed(hb, hb.linear_solution(omega), omega, newton).converged  # a hard start
    q, how = start_solution(hb, omega, newton)
    assert how == "amplitude continuation (through folds in the amplitude)"
    assert len(steppers) == 1
    stepper = steppers[0]
    assert isinstance(stepper.problem, ForcingHomotopy) and stepper.problem.p == omega
    assert stepper.status is Status.SUCCESS and stepper.points[0].p == 0.0 and stepper.points[-1].p == 1.0
    assert np.array_equal(stepper.points[-1].q, q)  # the start is the stepper's last point
    assert max(pt.p for pt in stepper.points[:-1]) < 1.0  # reached along the branch, not jumped to
    L = hb.length_scale
    for guess in (q, q + 1e-3 * L * rng.standard_normal(q.size)):
        res = solve_fixed(hb, guess, omega, newton)
        assert res.converged
        # 1e-8: NewtonOptions().step_tol, in units of the length scale (a few steps of it)
        assert np.max(np.abs(res.q - q)) <= 1e-8 * L


def test_an_easy_start_runs_no_homotopy(steppers):
    hb = HarmonicBalance(reference_case(), HBOptions(harmonics=16))
    q, how = start_solution(hb, 2.0, NewtonOptions())
    assert how == "linear solution + Newton" and not steppers
    assert solve_fixed(hb, q, 2.0, NewtonOptions()).iterations == 1
