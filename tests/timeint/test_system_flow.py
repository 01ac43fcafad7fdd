"""Exact integration of a System (n coordinates, m clearance elements): against the single-equation
exact integrator, scipy's DOP853, closed forms and finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _systems import free_chain, free_pair, grounded_chain, rhs
from scipy.integrate import solve_ivp

import rattle
from rattle.model import Linear, ReducedElement, System
from rattle.timeint import ExactIntegrator, FlowOptions


def _state(system: System) -> np.ndarray:
    z = np.zeros(2 * system.n)
    z[: system.n] = system.static_equilibrium()
    return z


@pytest.mark.parametrize("omega", [0.3, 0.8, 1.6])
@pytest.mark.parametrize("case", ["reference", "backlash"])
def test_one_coordinate_system_equals_exact_integrator(case, omega):
    model = rattle.reference_case() if case == "reference" else rattle.backlash_case()
    T = 2 * math.pi / omega
    ref = ExactIntegrator(model).propagate([0.01, 0.0], 0.0, 20 * T, omega)
    traj = ExactIntegrator(model.system()).propagate([0.01, 0.0], 0.0, 20 * T, omega)
    scale = np.abs(ref.state1).max()
    np.testing.assert_allclose(traj.state1, ref.state1, rtol=0, atol=1e-11 * scale)
    np.testing.assert_allclose(traj.sensitivity, ref.sensitivity, rtol=0, atol=1e-11)  # a product of O(1) factors
    assert traj.crossing_times.size == ref.crossing_times.size > 0
    np.testing.assert_allclose(traj.crossing_times, ref.crossing_times, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(traj.crossing_breakpoints, ref.crossed_breakpoints)
    assert np.all(traj.crossing_elements == 0)
    t = np.linspace(0.0, 20 * T, 97)
    np.testing.assert_allclose(traj.sample(t).deflection[:, 0], ref.sample(t).delta, rtol=0, atol=1e-11 * scale)
    mine, theirs = traj.measures(), ref.measures()
    for key in ("mean", "rms", "rms_ac", "delta_min", "delta_max", "p2p", "acc_min", "acc_max", "acc_p2p"):
        assert getattr(mine, key)[0] == pytest.approx(getattr(theirs, key), rel=1e-11, abs=1e-13)


def test_grounded_three_inertia_chain_equals_dop853():
    system = grounded_chain()
    omega = 0.4
    T = 2 * math.pi / omega
    z0 = _state(system)
    traj = ExactIntegrator(system).propagate(z0, 0.0, 2 * T, omega)
    assert set(traj.crossing_elements.tolist()) == {0, 1}  # both elements switch
    t = np.linspace(0.0, 2 * T, 41)
    ref = solve_ivp(rhs(system, omega), (0.0, 2 * T), z0, method="DOP853", rtol=1e-12, atol=1e-14,
                    max_step=T / 50, dense_output=True)
    scale = np.abs(ref.y).max()
    np.testing.assert_allclose(traj.state1, ref.y[:, -1], rtol=0, atol=1e-8 * scale)
    s = traj.sample(t)
    np.testing.assert_allclose(np.concatenate((s.x, s.velocity), axis=1), ref.sol(t).T, rtol=0, atol=1e-8 * scale)
    # the acceleration from the closed form equals the equation of motion
    acc = system.forcing(t, omega) - s.velocity @ system.damping.T - system.restoring(s.x)
    np.testing.assert_allclose(s.acceleration, acc, rtol=0, atol=1e-12 * np.abs(acc).max())
    # every crossing puts the element exactly on a breakpoint of its law
    at = traj.deflections(traj.crossing_times, order=0)[0]
    hit = at[np.arange(traj.crossing_times.size), traj.crossing_elements]
    np.testing.assert_allclose(hit, traj.crossing_breakpoints, rtol=0, atol=1e-13)


def test_free_chain_with_defective_gap_stage_equals_dop853():
    """Inside the gear gap the free chain has an undamped rigid relative mode (a defective zero
    eigenvalue of the stage matrix, plus the mean torque: parabolas)."""
    system = free_chain()
    omega = 0.5
    T = 2 * math.pi / omega
    z0 = _state(system)
    traj = ExactIntegrator(system).propagate(z0, 0.0, 2 * T, omega)
    gaps = [i for i in range(traj.n_segments) if traj.stages[i, 1] == 1]
    assert gaps and set(traj.crossing_elements.tolist()) == {0, 1}
    assert np.abs(np.linalg.eigvals(traj.segments[gaps[0]].sol.A)).min() == pytest.approx(0.0, abs=1e-12)
    ref = solve_ivp(rhs(system, omega), (0.0, 2 * T), z0, method="DOP853", rtol=1e-13, atol=1e-15,
                    max_step=T / 200, dense_output=True)
    t = np.linspace(0.0, 2 * T, 41)
    s = traj.sample(t)
    scale = np.abs(ref.y).max()
    np.testing.assert_allclose(np.concatenate((s.x, s.velocity), axis=1), ref.sol(t).T, rtol=0, atol=1e-8 * scale)


@pytest.mark.parametrize("damping", [0.0, 0.04])
def test_free_pair_inside_the_gap_is_the_closed_form(damping):
    """Two free inertias inside a wide backlash gap: x'' + c x' = F0 + F1 cos Ωt exactly (a parabola
    when c = 0, a ramp with a decaying exponential when c > 0)."""
    system = free_pair(damping, mean=0.01)
    omega = 1.3
    c, F0, F1 = 1.5 * damping, float(system.mean[0]), float(system.cos[0, 0])
    x0, v0 = -0.2, 0.05
    t1 = 4.0
    traj = ExactIntegrator(system).propagate([x0, v0], 0.0, t1, omega)
    assert traj.crossing_times.size == 0
    t = np.linspace(0.0, t1, 33)
    if c == 0.0:
        x = x0 + v0 * t + 0.5 * F0 * t**2 + F1 * (1 - np.cos(omega * t)) / omega**2
        v = v0 + F0 * t + F1 * np.sin(omega * t) / omega
    else:
        X = F1 / (-(omega**2) + 1j * c * omega)  # harmonic part Re(X e^{iΩt})
        xp0, vp0 = X.real, (1j * omega * X).real
        # x = A + B e^{−ct} + (F0/c) t + Re(X e^{iΩt})
        B = -(v0 - vp0 - F0 / c) / c
        A = x0 - xp0 - B
        x = A + B * np.exp(-c * t) + F0 / c * t + (X * np.exp(1j * omega * t)).real
        v = -c * B * np.exp(-c * t) + F0 / c + (1j * omega * X * np.exp(1j * omega * t)).real
    s = traj.sample(t)
    np.testing.assert_allclose(s.x[:, 0], x, rtol=0, atol=1e-14 * 8)
    np.testing.assert_allclose(s.velocity[:, 0], v, rtol=0, atol=1e-14 * 8)
    # and it leaves the gap through the upper breakpoint when integrated further
    longer = ExactIntegrator(system).propagate([x0, v0], 0.0, 20.0, omega)
    assert longer.crossing_times.size >= 1 and longer.crossing_breakpoints[0] == 0.5


@pytest.mark.parametrize("which", ["grounded", "free", "single"])
def test_sensitivity_equals_central_differences(which):
    system = {"grounded": grounded_chain(), "free": free_chain(),
              "single": rattle.reference_case().system()}[which]
    omega = 0.8
    T = 2 * math.pi / omega
    z0 = _state(system) + 0.01
    integ = ExactIntegrator(system)
    traj = integ.propagate(z0, 0.0, T, omega)
    assert traj.crossing_times.size > 0
    h = 1e-6
    fd = np.empty_like(traj.sensitivity)
    for j in range(z0.size):
        dz = np.zeros_like(z0)
        dz[j] = h
        plus, minus = integ.propagate(z0 + dz, 0.0, T, omega), integ.propagate(z0 - dz, 0.0, T, omega)
        fd[:, j] = (plus.state1 - minus.state1) / (2 * h)
    np.testing.assert_allclose(traj.sensitivity, fd, rtol=0, atol=1e-6 * np.abs(fd).max())
    # advance (no record) gives the same state and sensitivity
    z1, M = integ.advance(z0, 0.0, T, omega)
    np.testing.assert_array_equal(z1, traj.state1)
    np.testing.assert_array_equal(M, traj.sensitivity)
    z1_only, none = integ.advance(z0, 0.0, T, omega, sensitivity=False)
    assert none is None
    np.testing.assert_array_equal(z1_only, traj.state1)


def test_composition_of_intervals():
    system = grounded_chain()
    omega = 1.0
    integ = ExactIntegrator(system)
    z0 = _state(system)
    whole = integ.propagate(z0, 0.0, 9.0, omega)
    first = integ.propagate(z0, 0.0, 4.0, omega)
    second = integ.propagate(first.state1, 4.0, 9.0, omega)
    np.testing.assert_allclose(second.state1, whole.state1, rtol=0, atol=1e-12)
    np.testing.assert_allclose(second.sensitivity @ first.sensitivity, whole.sensitivity, rtol=0, atol=1e-11)


def test_linear_system_without_crossings_over_many_periods():
    """A linear element (no breakpoint): one stage, long segments cut and continued, exact."""
    system = System(damping=np.array([[0.1]]), stiffness=np.zeros((1, 1)),
                    elements=(ReducedElement("lin", np.array([1.0]), np.array([4.0]), Linear()),),
                    mean=np.array([0.2]), cos=np.array([[0.3]]), sin=np.array([[0.1]]), coordinates=("x",),
                    angles=np.array([[1.0], [0.0]]), free=True)
    omega = 1.0
    t1 = 200 * 2 * math.pi
    traj = ExactIntegrator(system).propagate([0.0, 0.0], 0.0, t1, omega)
    X = (0.3 - 0.1j) / (4.0 - omega**2 + 0.1j * omega)  # steady state: the transient is gone
    assert traj.state1[0] == pytest.approx(0.05 + (X * np.exp(1j * omega * t1)).real, abs=1e-12)
    assert traj.crossing_times.size == 0


def test_resonant_undamped_stage_is_refused():
    system = System(damping=np.zeros((1, 1)), stiffness=np.zeros((1, 1)),
                    elements=(ReducedElement("lin", np.array([1.0]), np.array([4.0]), Linear()),),
                    mean=np.zeros(1), cos=np.array([[0.3]]), sin=np.zeros((1, 1)), coordinates=("x",),
                    angles=np.array([[1.0], [0.0]]), free=True)
    with pytest.raises(ValueError, match="resonance"):
        ExactIntegrator(system).propagate([0.0, 0.0], 0.0, 1.0, 2.0)


def test_input_checks_name_the_argument():
    system = grounded_chain()
    integ = ExactIntegrator(system)
    with pytest.raises(ValueError, match="`z0`.*shape \\(6,\\)"):
        integ.propagate([0.0, 0.0], 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="`z0`"):
        integ.propagate([0.0] * 5 + [math.nan], 0.0, 1.0, 1.0)
    with pytest.raises(TypeError, match="`z0`"):
        integ.propagate("zero", 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="`omega`"):
        integ.propagate(np.zeros(6), 0.0, 1.0, 0.0)
    with pytest.raises(ValueError, match="`t0` and `t1`"):
        integ.propagate(np.zeros(6), 1.0, 0.0, 1.0)
    with pytest.raises(TypeError, match="`system`"):
        ExactIntegrator(rattle.reference_case().elastic)
    with pytest.raises(ValueError, match="`samples_per_scale`"):
        ExactIntegrator(system, FlowOptions(samples_per_scale=2))
    traj = integ.propagate(np.zeros(6), 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="`t`"):
        traj.sample(2.0)


@pytest.mark.parametrize("excursion", [1e-9, -1e-9])
def test_tangential_touch_inside_a_grid_cell(excursion):
    """A parabola in the gap whose apex passes the breakpoint by 1e-9 (two crossings 2·sqrt(2e-9/g)
    apart, well inside one grid cell) or misses it by 1e-9 (none)."""
    system = free_pair(0.0, b=0.5, mean=-0.2, amp=0.0)
    g = -float(system.mean[0])  # constant deceleration in the gap
    v0 = 0.3
    x0 = 0.5 - v0**2 / (2 * g) + excursion
    traj = ExactIntegrator(system).propagate([x0, v0], 0.0, 2.0 * v0 / g, 1.0)
    if excursion > 0:
        apex, half = v0 / g, math.sqrt(2 * excursion / g)
        assert traj.crossing_directions.tolist() == [1, -1]
        np.testing.assert_allclose(traj.crossing_times, [apex - half, apex + half], rtol=0, atol=1e-9)
    else:
        assert traj.crossing_times.size == 0


@pytest.mark.parametrize("damping", [1.0, 2.0])
def test_critically_damped_stage_equals_exact_integrator(damping):
    """c = 1: the clutch's inner stage (k s = 0.25) is critically damped; c = 2: the outer ones.
    A double, defective eigenvalue: kept as a Taylor-summed block, exact."""
    from rattle.model import Clutch, Excitation, Model

    model = Model(inertia=1.0, damping=damping, stiffness=1.0, elastic=Clutch(alpha=0.25, b=0.1),
                  excitation=Excitation(mean=0.05, amplitudes=(0.5,)))
    omega = 0.7
    T = 2 * math.pi / omega
    ref = ExactIntegrator(model).propagate([0.0, 0.0], 0.0, 3 * T, omega)
    integ = ExactIntegrator(model.system())
    traj = integ.propagate([0.0, 0.0], 0.0, 3 * T, omega)
    assert traj.crossing_times.size == ref.crossing_times.size > 0
    np.testing.assert_allclose(traj.crossing_times, ref.crossing_times, rtol=0, atol=1e-11)
    np.testing.assert_allclose(traj.state1, ref.state1, rtol=0, atol=1e-13)
    np.testing.assert_allclose(traj.sensitivity, ref.sensitivity, rtol=0, atol=1e-12 * np.abs(ref.sensitivity).max())
    assert any(len(sol.clusters) and sol.method == "modal" for sol in integ.stages(omega)._cache.values())


def test_matrix_exponential_fallback_equals_block_modal_form(monkeypatch):
    """Every stage forced onto the scipy expm fallback gives the same trajectory."""
    import rattle.timeint._stage_flow as stage_flow

    system = free_chain()
    omega = 0.8
    T = 2 * math.pi / omega
    z0 = _state(system)
    modal = ExactIntegrator(system).propagate(z0, 0.0, T, omega)
    monkeypatch.setattr(stage_flow, "_MAX_CONDITION", 0.0)
    integ = ExactIntegrator(system)
    fallback = integ.propagate(z0, 0.0, T, omega)
    assert {sol.method for sol in integ.stages(omega)._cache.values()} == {"expm"}
    np.testing.assert_allclose(fallback.crossing_times, modal.crossing_times, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fallback.state1, modal.state1, rtol=0, atol=1e-13)
    np.testing.assert_allclose(fallback.sensitivity, modal.sensitivity, rtol=0, atol=1e-12)
    t = np.linspace(0.0, T, 9)
    np.testing.assert_allclose(fallback.sample(t).acceleration, modal.sample(t).acceleration, rtol=0, atol=1e-13)


@pytest.mark.parametrize("x0", [(0.0, 0.0), "b+", "b-", "-b0"])
def test_start_on_a_breakpoint_equals_exact_integrator(x0):
    model = rattle.reference_case()
    b = float(model.elastic.b)
    state = {"b+": (b, 0.01), "b-": (b, -0.01), "-b0": (-b, 0.0)}.get(x0, x0)
    omega = 1.0
    ref = ExactIntegrator(model).propagate(state, 0.5, 12.0, omega)
    traj = ExactIntegrator(model.system()).propagate(state, 0.5, 12.0, omega)
    np.testing.assert_array_equal(traj.stages[0], [ref.stage[0]])
    np.testing.assert_allclose(traj.state1, ref.state1, rtol=0, atol=1e-13)
    np.testing.assert_allclose(traj.crossing_times, ref.crossing_times, rtol=0, atol=1e-11)


@pytest.mark.parametrize("which", ["grounded", "free", "single"])
def test_omega_derivative_equals_central_differences(which):
    system = {"grounded": grounded_chain(), "free": free_chain(),
              "single": rattle.reference_case().system()}[which]
    omega, h = 0.8, 1e-6
    z0 = _state(system) + 0.01
    integ = ExactIntegrator(system)
    traj = integ.propagate(z0, 0.3, 9.0, omega)
    assert traj.crossing_times.size > 0
    fd = (integ.propagate(z0, 0.3, 9.0, omega + h).state1 - integ.propagate(z0, 0.3, 9.0, omega - h).state1) / (2 * h)
    np.testing.assert_allclose(traj.omega_derivative(), fd, rtol=0, atol=1e-8 * np.abs(fd).max())
    # the period map: Ωt held fixed (t1 = 2π/Ω)
    T = 2 * math.pi / omega
    traj = integ.propagate(z0, 0.0, T, omega)
    plus = integ.propagate(z0, 0.0, 2 * math.pi / (omega + h), omega + h).state1
    minus = integ.propagate(z0, 0.0, 2 * math.pi / (omega - h), omega - h).state1
    fd = (plus - minus) / (2 * h)
    np.testing.assert_allclose(traj.omega_derivative("phase"), fd, rtol=0, atol=1e-8 * np.abs(fd).max())
    with pytest.raises(ValueError, match="`fixed`"):
        traj.omega_derivative("both")
