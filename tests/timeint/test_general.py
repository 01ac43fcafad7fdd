"""The general (solve_ivp, event-restarted) integrator: the independent check of the exact one."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from rattle.errors import ConvergenceError
from rattle.model import Backlash, Excitation, Linear, Model, Piecewise, reference_case
from rattle.timeint import ExactIntegrator, GeneralSolution, integrate_general


def _model(elastic, *, damping=0.05, mean=0.05, amplitudes=(0.03,), phases=None):
    return Model(inertia=1.0, damping=damping, stiffness=1.0, elastic=elastic,
                 excitation=Excitation(mean=mean, amplitudes=amplitudes, phases=phases))


MODELS = {
    "reference clutch": reference_case(),
    "backlash (zero-slope stage)": _model(Backlash(b=0.1), mean=0.02, amplitudes=(0.05,)),
    "asymmetric 5-stage, 3 harmonics": _model(
        Piecewise(breakpoints=(-0.3, -0.1, 0.05, 0.2), slopes=(1.0, 0.3, 0.05, 0.3, 1.0)),
        mean=0.01, amplitudes=(0.05, 0.02, 0.01), phases=(0.0, 0.5, -1.0)),
}


@pytest.mark.parametrize("name", sorted(MODELS))
@pytest.mark.parametrize("omega", [0.3, 0.8, 1.41, 2.0])
def test_agrees_with_exact_integrator(name, omega):
    """Ten forcing periods from rest at the static equilibrium: same crossings, same states."""
    model = MODELS[name]
    T = 2 * math.pi / omega
    x0 = (model.static_equilibrium(), 0.0)
    exact = ExactIntegrator(model).propagate(x0, 0.0, 10 * T, omega)
    x1, sol = integrate_general(model, x0, 0.0, 10 * T, omega)
    assert isinstance(sol, GeneralSolution)
    # DOP853 at rtol 1e-10, atol 1e-12 over ~100 s: ~1e-10 per segment, plus the crossing
    # times located on the dense output (a 7th-order interpolant): a few 1e-9 in all.
    np.testing.assert_allclose(x1, exact.state1, rtol=0, atol=5e-9)
    np.testing.assert_array_equal(sol.stage, exact.stage)
    np.testing.assert_array_equal(sol.crossed_breakpoints, exact.crossed_breakpoints)
    # A crossing time is off by (error of δ) / |δ'| at the crossing; |δ'| ≳ 1e-3 here.
    np.testing.assert_allclose(sol.crossing_times, exact.crossing_times, rtol=0, atol=1e-6)
    t = np.linspace(0.0, 10 * T, 777)
    ref, got = exact.sample(t), sol.sample(t)
    np.testing.assert_allclose(got.delta, ref.delta, rtol=0, atol=5e-9)
    np.testing.assert_allclose(got.velocity, ref.velocity, rtol=0, atol=5e-9)
    np.testing.assert_allclose(got.acceleration, ref.acceleration, rtol=0, atol=5e-9)
    np.testing.assert_array_equal(got.stage, ref.stage)


def test_short_excursion_inside_one_step_is_not_missed():
    """Reference clutch from rest at Ω = 0.8: between t ≈ 23.004 and 23.174 δ dips 4.4e-4 rad
    below −b. DOP853 steps over it (its steps are longer than the excursion), so the crossing
    events alone miss it; the extremum events reveal it."""
    model = reference_case()
    omega = 0.8
    T = 2 * math.pi / omega
    x0 = (model.static_equilibrium(), 0.0)
    exact = ExactIntegrator(model).propagate(x0, 0.0, 10 * T, omega)
    dips = np.flatnonzero(exact.crossed_breakpoints < 0)
    assert dips.size == 2  # down through −b and back
    t_in, t_out = exact.crossing_times[dips]
    assert 0.1 < t_out - t_in < 0.25
    _, sol = integrate_general(model, x0, 0.0, 10 * T, omega)
    np.testing.assert_allclose(sol.crossing_times, exact.crossing_times, rtol=0, atol=1e-6)
    # The steps really are longer than the excursion (else this test would not test anything).
    seg = sol.segments[int(np.searchsorted(sol.t_start, t_in, side="right")) - 2]
    assert np.max(np.diff(seg.ts)) > t_out - t_in


def test_linear_law_closed_form_with_harmonics_and_phases():
    """f = δ: x(t) = p(t) + exp(A t)(x0 − p(0)), p = F_m/k + Σ Re[X_n e^{inΩt}]."""
    model = Model(inertia=1.0, damping=0.1, stiffness=2.0, elastic=Linear(),
                  excitation=Excitation(mean=0.3, amplitudes=(0.5, 0.2), phases=(0.7, -0.3)))
    omega, t1 = 1.3, 17.0
    X = [a * np.exp(1j * ph) / (model.k - (n * omega) ** 2 + 1j * model.c * n * omega)
         for n, a, ph in zip((1, 2), (0.5, 0.2), (0.7, -0.3))]

    def particular(t):
        z = [x * np.exp(1j * n * omega * t) for n, x in zip((1, 2), X)]
        return np.array([0.3 / model.k + sum(zz.real for zz in z),
                         sum((1j * n * omega * zz).real for n, zz in zip((1, 2), z))])

    x0 = np.array([0.4, -0.1])
    A = np.array([[0.0, 1.0], [-model.k, -model.c]])
    expected = particular(t1) + scipy.linalg.expm(A * t1) @ (x0 - particular(0.0))
    x1, sol = integrate_general(model, x0, 0.0, t1, omega)
    np.testing.assert_allclose(x1, expected, rtol=0, atol=1e-10)
    assert sol.n_segments == 1 and sol.crossing_times.size == 0


def test_crossing_time_of_free_flight():
    """Backlash, no forcing, no damping, from δ = 0 with velocity v: free flight through the gap
    reaches b at t = b / v exactly."""
    model = Model(inertia=1.0, damping=0.0, stiffness=1.0, elastic=Backlash(b=0.2),
                  excitation=Excitation(mean=0.0, amplitudes=(0.0,)))
    _, sol = integrate_general(model, (0.0, 0.5), 0.0, 0.5, 1.0)
    assert sol.crossing_times[0] == pytest.approx(0.2 / 0.5, abs=1e-12)


def test_rk45_at_1e8_is_less_accurate_than_exact():
    """The classic setting (RK45, rtol 1e-8) drifts by ~1e-7 over 20 periods: the exact
    integrator is the reference, not the other way round."""
    model = reference_case()
    omega = 0.8
    T = 2 * math.pi / omega
    x0 = (model.static_equilibrium(), 0.0)
    exact = ExactIntegrator(model).propagate(x0, 0.0, 20 * T, omega)
    tight, _ = integrate_general(model, x0, 0.0, 20 * T, omega, rtol=1e-12, atol=1e-14)
    loose, _ = integrate_general(model, x0, 0.0, 20 * T, omega, method="RK45", rtol=1e-8, atol=1e-10)
    err_tight = np.max(np.abs(tight - exact.state1))
    err_loose = np.max(np.abs(loose - exact.state1))
    assert err_tight < 1e-10
    assert err_loose > 10 * err_tight


def test_arguments_are_checked():
    model = reference_case()
    with pytest.raises(ValueError, match="`method` must be one of .*RK45"):
        integrate_general(model, (0.0, 0.0), 0.0, 1.0, 1.0, method="Euler")
    with pytest.raises(ValueError, match="t1 >= t0"):
        integrate_general(model, (0.0, 0.0), 1.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="`omega`"):
        integrate_general(model, (0.0, 0.0), 0.0, 1.0, 0.0)
    with pytest.raises(ValueError, match="`x0`"):
        integrate_general(model, (0.0, math.nan), 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="`rtol`"):
        integrate_general(model, (0.0, 0.0), 0.0, 1.0, 1.0, rtol=-1.0)
    with pytest.raises(TypeError):
        integrate_general(model, (0.0, 0.0), 0.0, 1.0, 1.0, tol=1e-3)  # unknown keyword
    with pytest.raises(ConvergenceError, match="max_segments"):
        integrate_general(model, (0.0, 0.0), 0.0, 100.0, 1.0, max_segments=2)


def test_zero_length_interval():
    x1, sol = integrate_general(reference_case(), (0.1, 0.2), 3.0, 3.0, 1.0)
    np.testing.assert_array_equal(x1, [0.1, 0.2])
    np.testing.assert_array_equal(sol(3.0), [0.1, 0.2])
