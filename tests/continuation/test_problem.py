"""One continuation core for every problem: the ContinuationProblem protocol, Newton at a fixed
parameter, predictor objects, and a shooting problem continued by the same stepper as harmonic
balance (a fold of the reference case, shooting against harmonic balance)."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle.continuation import (
    ContinuationOptions, ContinuationProblem, ContinuationStepper, Natural, NewtonOptions, Secant, Tangent,
    locate_on_segment, predictor, solve_fixed,
)
from rattle.errors import Status
from rattle.hb import HarmonicBalance, HBOptions
from rattle.model import Excitation, Linear, Model
from rattle.timeint import ShootingProblem

SRC = Path(rattle.__file__).resolve().parent


def test_the_continuation_layer_knows_no_problem():
    """rattle.continuation imports none of the layers that define problems (Fourier series,
    flows, models) nor the stability layer above it: only the package's shared helpers (Brent's
    root finder among them; ``_lazy.import_held`` for the compiled monitor scan loaded on first use, ``_jit`` its compile setting)."""
    allowed = {"rattle._typing", "rattle.errors", "rattle._limits", "rattle._validate", "rattle._brent", "rattle._lazy",
               "rattle._jit"}
    for path in sorted((SRC / "continuation").glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level:
                target = "rattle." + (node.module or "") if node.level == 2 else "rattle.continuation"
                assert node.level == 1 or target in allowed, f"{path.name} imports {target}"
            elif isinstance(node, ast.Import):
                assert not any(a.name.startswith("rattle") for a in node.names), path.name


def test_both_problems_implement_the_protocol(reference_model):
    hb = HarmonicBalance(reference_model, HBOptions(harmonics=4))
    shooting = ShootingProblem(reference_model.system())
    for problem in (hb, shooting):
        assert isinstance(problem, ContinuationProblem)
    assert hb.parameter_scale == reference_model.natural_frequency
    assert shooting.length_scale.shape == (2,) and shooting.force_scale == 1.0


def test_shooting_jacobians_against_central_differences(reference_model, rng):
    problem = ShootingProblem(reference_model.system())
    h = 1e-7
    for _ in range(3):
        z = rng.uniform(-0.3, 0.3, 2)
        w = rng.uniform(0.5, 1.5)
        R, Rq, Rw = problem.residual_jacobian(z, w)
        np.testing.assert_allclose(R, problem.residual(z, w), rtol=0, atol=1e-14)
        fd_q = np.column_stack([(problem.residual(z + h * e, w) - problem.residual(z - h * e, w)) / (2 * h)
                                for e in np.eye(2)])
        fd_w = (problem.residual(z, w + h) - problem.residual(z, w - h)) / (2 * h)
        # central differences of an exact flow: truncation O(h²), round-off ~1e-16/h ~ 1e-9
        np.testing.assert_allclose(Rq, fd_q, rtol=0, atol=1e-6 * max(1.0, np.abs(Rq).max()))
        np.testing.assert_allclose(Rw, fd_w, rtol=0, atol=1e-6 * max(1.0, np.abs(Rw).max()))


def test_solve_fixed_is_the_old_harmonic_balance_solve(reference_model):
    from rattle.hb import NewtonOptions as OldOptions
    from rattle.hb import solve_harmonic_balance

    assert OldOptions is NewtonOptions and solve_harmonic_balance is solve_fixed
    hb = HarmonicBalance(reference_model, HBOptions(harmonics=8))
    res = solve_fixed(hb, hb.linear_solution(2.0), 2.0)
    assert res.converged and res.status is Status.CONVERGED and res.residual <= 1e-10
    bad = solve_fixed(hb, hb.linear_solution(2.0), 2.0, NewtonOptions(max_iterations=1, residual_tol=1e-15))
    assert not bad.converged and bad.status is Status.MAX_ITERATIONS and bad.message == Status.MAX_ITERATIONS.message


def test_predictor_objects_and_names():
    assert isinstance(predictor("secant"), Secant) and isinstance(predictor(Tangent()), Tangent)
    with pytest.raises(ValueError, match=r"`predictor` must be a predictor \('tangent', 'secant'"):
        predictor("euler")
    model = Model(inertia=2.0, damping=0.1, stiffness=2.0, elastic=Linear(), excitation=Excitation(mean=0.1, amplitudes=(0.03,)))
    hb = HarmonicBalance(model, HBOptions(harmonics=2))
    with pytest.raises(TypeError, match="`predictor` must be a predictor object"):
        ContinuationStepper(hb, hb.linear_solution(0.2), 0.2, (0.2, 2.0), predictor="secant")  # type: ignore[arg-type]


@pytest.mark.parametrize("method", [Tangent(), Secant(), Natural()])
def test_the_predictors_follow_the_linear_branch(method):
    model = Model(inertia=2.0, damping=0.1, stiffness=2.0, elastic=Linear(), excitation=Excitation(mean=0.1, amplitudes=(0.03,)))
    hb = HarmonicBalance(model, HBOptions(harmonics=2))
    stepper = ContinuationStepper(hb, hb.linear_solution(0.2), 0.2, (0.2, 2.0), predictor=method)
    points = stepper.run()
    assert stepper.status is Status.SUCCESS and points[-1].omega == 2.0
    for p in points:  # HB is exact for a linear law: every point is the linear solution
        np.testing.assert_allclose(p.q, hb.linear_solution(p.omega), rtol=0, atol=1e-9)


class _Arctan:
    """R(q, p) = arctan(q − p): one root q = p; plain Newton from |q − p| > 1.3917 overshoots and
    diverges (the classic example), Newton with backtracking converges from anywhere."""

    size, length_scale, parameter_scale, force_scale = 1, 1.0, 1.0, 1.0

    def residual(self, q, p):  # type: ignore[no-untyped-def]
        return np.arctan(q - p)

    def residual_jacobian(self, q, p):  # type: ignore[no-untyped-def]
        with np.errstate(over="ignore"):  # the diverging full step goes to ±inf
            d = 1.0 / (1.0 + (q - p) ** 2)
        return np.arctan(q - p), d.reshape(1, 1), -d


def test_the_damped_newton_converges_where_the_full_step_diverges():
    pb = _Arctan()
    plain = solve_fixed(pb, np.array([2.0]), 0.5, NewtonOptions(max_iterations=40))  # 1.5 from the root
    assert not plain.converged
    damped = solve_fixed(pb, np.array([2.0]), 0.5, NewtonOptions(max_iterations=40, damped=True))
    assert damped.converged and abs(damped.q[0] - 0.5) < 1e-10
    near = solve_fixed(pb, np.array([0.6]), 0.5, NewtonOptions(damped=True))  # the full step where it descends
    assert near.converged and near.iterations == solve_fixed(pb, np.array([0.6]), 0.5).iterations
    with pytest.raises(TypeError, match="damped"):
        NewtonOptions(damped=1)  # type: ignore[arg-type]


def test_the_natural_predictor_keeps_q_and_the_damped_corrector_follows_from_afar():
    """A natural step moves the parameter only (its plane: p fixed); along R = arctan(q − p) the
    stepper with steps of 2 in p — each guess 2 from the root, where plain Newton diverges — reaches
    the far end on every point's root, with the damped corrector."""
    y, t = np.array([1.0, 2.0]), np.array([0.6, -0.8])
    pred, d = Natural().predict(y, t, 0.5, None)
    np.testing.assert_array_equal(pred, [1.0, 1.5])
    np.testing.assert_array_equal(d, [0.0, -1.0])
    pb = _Arctan()
    opts = ContinuationOptions(initial_step=2.0, min_step=2.0, max_step=2.0)
    plain = ContinuationStepper(pb, np.array([0.0]), 0.0, (0.0, 10.0), opts, NewtonOptions(max_iterations=40),
                                predictor=Natural(), domain=(-np.inf, np.inf), stations=(2.0, 4.0, 6.0, 8.0, 10.0))
    plain.run()
    assert plain.status is Status.STEP_TOO_SMALL
    stepper = ContinuationStepper(pb, np.array([0.0]), 0.0, (0.0, 10.0), opts,
                                  NewtonOptions(max_iterations=40, damped=True), predictor=Natural(),
                                  domain=(-np.inf, np.inf), stations=(2.0, 4.0, 6.0, 8.0, 10.0))
    points = stepper.run()
    assert stepper.status is Status.SUCCESS and [p.p for p in points] == [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
    for p in points:
        assert abs(p.q[0] - p.p) < 1e-9


def test_shooting_problem_through_the_stepper_finds_the_hb_fold(reference_model, reference_frf):
    """The exact shooting problem, continued by the same stepper and located by the same locator
    (test function det ∂R/∂q = det(M − I)/Π s), reproduces the upper fold of the bent primary
    resonance that harmonic balance (H = 32) locates at Ω ≈ 0.8744."""
    fold = [s for s in reference_frf.special_points if s.kind == "fold" and 0.85 < s.omega < 0.9]
    assert len(fold) == 1
    fold = fold[0]
    # Start on the same branch below the fold: the last row before it with Ω ≤ 0.86.
    rows = [i for i in range(fold.index) if reference_frf.omega[i] <= 0.86]
    i0 = rows[-1]
    w0 = float(reference_frf.omega[i0])
    h = reference_frf.time_history(i0, samples=8)
    problem = ShootingProblem(reference_model.system())
    start = solve_fixed(problem, np.array([h["delta"][0], h["velocity"][0]]), w0)
    assert start.converged
    stepper = ContinuationStepper(problem, start.q, w0, (w0, 0.9), ContinuationOptions(max_step=0.05))
    points = stepper.run()
    assert stepper.status is Status.RETURNED  # over the fold and back below the start
    psi = [np.linalg.det(problem.monodromy(p.q, p.omega) - np.eye(2)) for p in points]
    changes = [j for j in range(1, len(points)) if np.sign(psi[j]) != np.sign(psi[j - 1])]
    assert len(changes) == 1
    j = changes[0]
    loc = locate_on_segment(stepper.corrector, points[j - 1].q, points[j - 1].omega, points[j].q, points[j].omega,
                            lambda q, w, corrected, d: float(np.linalg.det(corrected.Rq)))
    assert loc is not None
    # 1e-4: the HB truncation error of the special points (tests/test_chains.py); here ~1e-7
    assert abs(loc.omega - fold.omega) <= 1e-4
    assert max(p.omega for p in points) == pytest.approx(loc.omega, abs=1e-3)  # the turning point
