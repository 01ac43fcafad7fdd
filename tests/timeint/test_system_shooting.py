"""Shooting periodic orbits of a System with the exact monodromy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _systems import free_chain, grounded_chain

import rattle
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit, shoot_system_orbit


def _rest(system):
    z = np.zeros(2 * system.n)
    z[: system.n] = system.static_equilibrium()
    return z


@pytest.mark.parametrize("omega", [0.8, 1.6])
def test_one_coordinate_orbit_equals_single_equation_shooting(omega):
    model = rattle.reference_case()
    ref = shoot_periodic_orbit(model, omega, [0.05, 0.0])
    orbit = shoot_system_orbit(model.system(), omega, [0.05, 0.0])
    assert ref.converged and orbit.converged
    np.testing.assert_allclose(orbit.state0, ref.state0, rtol=0, atol=1e-9 * np.abs(ref.state0).max())
    np.testing.assert_allclose(orbit.multipliers, ref.multipliers, rtol=0, atol=1e-9)
    np.testing.assert_allclose(orbit.monodromy, ref.monodromy, rtol=0, atol=1e-9)
    assert orbit.stable == ref.stable
    meas = orbit.measures
    assert meas.names == ("delta",)
    for key in ("mean", "rms", "rms_ac", "delta_min", "delta_max", "p2p", "acc_min", "acc_max", "acc_p2p"):
        assert getattr(meas, key)[0] == pytest.approx(getattr(ref, key), rel=1e-9, abs=1e-12)
    assert meas.element("delta")["rms"] == meas.rms[0]


@pytest.mark.parametrize("make, omega", [(grounded_chain, 0.4), (grounded_chain, 1.0), (free_chain, 1.0)])
def test_chain_orbit_is_periodic_and_its_multipliers_are_those_of_the_fd_monodromy(make, omega):
    system = make()
    orbit = shoot_system_orbit(system, omega, _rest(system))
    assert orbit.converged and orbit.residual <= 1e-12
    T = 2 * math.pi / omega
    integ = ExactIntegrator(system)
    z1 = integ.propagate(orbit.state0, 0.0, T, omega).state1
    np.testing.assert_allclose(z1, orbit.state0, rtol=0, atol=1e-12 * max(1.0, np.abs(orbit.state0).max()))
    assert orbit.trajectory.crossing_times.size > 0
    # finite-difference monodromy
    h = 1e-6
    fd = np.empty((2 * system.n, 2 * system.n))
    for j in range(2 * system.n):
        dz = np.zeros(2 * system.n)
        dz[j] = h
        fd[:, j] = (integ.propagate(orbit.state0 + dz, 0.0, T, omega).state1
                    - integ.propagate(orbit.state0 - dz, 0.0, T, omega).state1) / (2 * h)
    np.testing.assert_allclose(orbit.monodromy, fd, rtol=0, atol=1e-6 * np.abs(fd).max())
    lam = np.linalg.eigvals(fd)
    for mu in orbit.multipliers:
        assert np.min(np.abs(lam - mu)) <= 1e-5
    # Liouville: det M = exp(−tr C · T) (the element forces do not change the trace)
    assert np.prod(orbit.multipliers).real == pytest.approx(math.exp(-np.trace(system.damping) * T), rel=1e-9)
    # measures: one entry per element, consistent
    meas = orbit.measures
    assert meas.rms.shape == (system.m,)
    np.testing.assert_allclose(meas.p2p, meas.delta_max - meas.delta_min)
    assert np.all(meas.rms >= np.abs(meas.mean)) and np.all(meas.rms_ac <= meas.rms + 1e-15)
    np.testing.assert_allclose(meas.rms_ac**2, meas.rms**2 - meas.mean**2, rtol=1e-10, atol=1e-15)
    t = np.linspace(0.0, T, 2001)
    d = orbit.trajectory.sample(t).deflection
    assert np.all(d.min(axis=0) >= meas.delta_min - 1e-14) and np.all(d.max(axis=0) <= meas.delta_max + 1e-14)
    np.testing.assert_allclose(d.max(axis=0), meas.delta_max, rtol=0, atol=1e-5 * meas.p2p.max())
    for e in range(system.m):
        assert orbit.crossed(e).size == len(set(orbit.crossed(e).tolist()))


def test_sub_harmonic_period_and_argument_checks():
    system = grounded_chain()
    one = shoot_system_orbit(system, 1.0, _rest(system))
    orbit = shoot_system_orbit(system, 1.0, one.state0 + 1e-4, period=2)  # the primary orbit, twice
    assert orbit.period == 2 and orbit.converged
    np.testing.assert_allclose(orbit.state0, one.state0, rtol=0, atol=1e-10)
    squares = one.multipliers**2
    for mu in orbit.multipliers:
        assert np.min(np.abs(squares - mu)) <= 1e-8
    assert orbit.trajectory.t1 == pytest.approx(4 * math.pi)
    with pytest.raises(ValueError, match="`period`"):
        shoot_system_orbit(system, 1.0, _rest(system), period=0)
    with pytest.raises(ValueError, match="`z0`"):
        shoot_system_orbit(system, 1.0, np.zeros(4))
    with pytest.raises(ValueError, match="`omega`"):
        shoot_system_orbit(system, -1.0, _rest(system))
    with pytest.raises(ValueError, match="`tol`"):
        shoot_system_orbit(system, 1.0, _rest(system), tol=0.0)
    with pytest.raises(ValueError, match="`integrator`"):
        shoot_system_orbit(system, 1.0, _rest(system), integrator=ExactIntegrator(free_chain()))
    with pytest.raises(TypeError, match="`system`"):
        shoot_system_orbit(rattle.reference_case(), 1.0, [0.0, 0.0])


def test_linear_system_without_elements_is_its_frequency_response():
    from rattle.model import System

    C = np.array([[0.1, 0.0], [0.0, 0.2]])
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    F0, F1 = np.array([0.1, 0.0]), np.array([0.1, 0.05j])  # F1: cos + i(−sin) amplitudes
    system = System(damping=C, stiffness=K, elements=(), mean=F0, cos=F1.real[None], sin=-F1.imag[None],
                    coordinates=("a", "b"), angles=np.eye(2), free=False)
    omega = 1.1
    orbit = shoot_system_orbit(system, omega, np.zeros(4))
    X = np.linalg.solve(K - omega**2 * np.eye(2) + 1j * omega * C, F1)
    x0 = np.linalg.solve(K, F0) + X.real
    v0 = (1j * omega * X).real
    assert orbit.converged and orbit.iterations == 1  # linear: one Newton step
    np.testing.assert_allclose(orbit.state0, np.concatenate((x0, v0)), rtol=0, atol=1e-13)
    assert orbit.measures.rms.shape == (0,)
