"""The stepper's parameter is generic (any sign, any meaning), and the forcing homotopy
R(q; λ) = R(q, p) + (1 − λ) f is a continuation problem in λ like any other."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rattle.continuation import (
    ContinuationOptions, ContinuationProblem, ContinuationStepper, ForcingHomotopy, NewtonOptions, solve_fixed,
)
from rattle.errors import Status
from rattle.hb import HarmonicBalance, HBOptions
from rattle.model import reference_case


class Circle:
    """R(q, p) = q² + p² − 1: the unit circle, a branch through negative and positive p."""

    size = 1
    length_scale = 1.0
    parameter_scale = 1.0
    force_scale = 1.0

    def residual(self, q, p):
        return np.array([q[0] ** 2 + p**2 - 1.0])

    def residual_jacobian(self, q, p):
        return self.residual(q, p), np.array([[2.0 * q[0]]]), np.array([2.0 * p])


def test_the_parameter_may_be_negative_and_is_named_as_the_caller_says():
    """From p = −0.9 over the top of the circle to p = 0.9: every point on the circle to Newton
    tolerance, the last one placed on the bound."""
    problem = Circle()
    assert isinstance(problem, ContinuationProblem)
    q0 = np.array([math.sqrt(1 - 0.81)])
    stepper = ContinuationStepper(problem, q0, -0.9, (-0.9, 0.9), ContinuationOptions(max_step=0.05),
                                  domain=(-np.inf, np.inf), symbol="μ")
    points = stepper.run()
    assert stepper.status is Status.SUCCESS
    assert points[0].p == -0.9 and points[-1].p == 0.9 and points[-1].omega == points[-1].p  # the read-only alias
    assert min(p.p for p in points) < 0.0 < max(p.p for p in points)
    for pt in points:
        # 1e-10: NewtonOptions().residual_tol (force scale 1)
        assert abs(pt.q[0] ** 2 + pt.p**2 - 1.0) <= 1e-10
        assert pt.q[0] > 0.0  # the upper half: no jump to the other branch
    with pytest.raises((AttributeError, TypeError)):  # frozen (TypeError: CPython's frozen slots dataclass)
        points[0].omega = 1.0  # type: ignore[misc]
    # The default domain is p > 0: a range reaching below it is refused, naming the argument.
    with pytest.raises(ValueError, match=r"`p_range` must satisfy 0 < min < max"):
        ContinuationStepper(problem, q0, -0.9, (-0.9, 0.9))
    # The stepper's messages name the parameter as it is told.
    failing = ContinuationStepper(problem, np.array([5.0]), 1.5, (1.5, 2.0), domain=(-np.inf, np.inf), symbol="μ")
    failing.run()
    assert failing.status is Status.START_FAILED and "μ = 1.5" in failing.message


def test_forcing_homotopy_jacobians_match_central_differences(rng):
    """∂R/∂q and ∂R/∂λ = −f of the homotopy against central differences at random (q, λ), and
    R(q; 1) = R(q, Ω), R(q; 0) the problem forced by F_0 alone."""
    hb = HarmonicBalance(reference_case(), HBOptions(harmonics=8))
    omega = 0.9
    f = hb.forcing - hb.static_forcing()
    problem = ForcingHomotopy(hb, omega, f)
    assert isinstance(problem, ContinuationProblem)
    assert problem.parameter_scale == 1.0 and problem.size == hb.size
    L = hb.length_scale
    for _ in range(3):
        q = rng.normal(scale=L, size=hb.size)
        lam = float(rng.uniform(-0.5, 1.5))
        R, Rq, Rl = problem.residual_jacobian(q, lam)
        np.testing.assert_array_equal(R, problem.residual(q, lam))
        h = 1e-6
        # rtol 1e-6: central differences of a piecewise-linear law's AFT forces (O(h²) away from kinks)
        np.testing.assert_allclose(Rl, (problem.residual(q, lam + h) - problem.residual(q, lam - h)) / (2 * h),
                                   rtol=0, atol=1e-9 * hb.force_scale)
        j = int(rng.integers(hb.size))
        e = np.zeros(hb.size)
        e[j] = h * L
        fd = (problem.residual(q + e, lam) - problem.residual(q - e, lam)) / (2 * h * L)
        np.testing.assert_allclose(Rq[:, j], fd, rtol=1e-6, atol=1e-6 * np.max(np.abs(Rq)))
    q = rng.normal(scale=L, size=hb.size)
    np.testing.assert_allclose(problem.residual(q, 1.0), hb.residual(q, omega), rtol=0, atol=1e-14 * hb.force_scale)
    np.testing.assert_allclose(problem.residual(q, 0.0), hb.residual(q, omega) + f, rtol=0, atol=1e-14 * hb.force_scale)
    with pytest.raises(ValueError, match="`forcing` must be"):
        ForcingHomotopy(hb, omega, f[:-1])


def test_the_homotopy_branch_is_continued_from_the_static_equilibrium_to_the_full_forcing():
    """On the stepper, λ from 0 to 1 at Ω = 0.9 inside the bent resonance: the branch turns back
    in λ (folds), and its last point, on λ = 1, solves the harmonic balance at the full forcing."""
    hb = HarmonicBalance(reference_case(), HBOptions(harmonics=16))
    omega = 0.9
    problem = ForcingHomotopy(hb, omega, hb.forcing - hb.static_forcing())
    q = hb.linear_solution(omega)
    q[1:] = 0.0
    stepper = ContinuationStepper(problem, q, 0.0, (0.0, 1.0), ContinuationOptions(max_step=0.5), NewtonOptions(),
                                  domain=(-np.inf, np.inf), symbol="λ")
    points = stepper.run()
    assert stepper.status is Status.SUCCESS and points[-1].p == 1.0
    dlam = np.array([pt.tangent[-1] for pt in points])
    assert np.sum(dlam[1:] * dlam[:-1] < 0) >= 2  # over a fold and back
    res = solve_fixed(hb, points[-1].q, omega, NewtonOptions())
    assert res.converged and res.iterations == 1
    # 1e-8: NewtonOptions().step_tol, in units of the length scale
    assert np.max(np.abs(res.q - points[-1].q)) <= 1e-8 * hb.length_scale
