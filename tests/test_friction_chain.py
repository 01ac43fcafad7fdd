"""Exact event-driven integration of chains with Coulomb friction on their elements
(rattle.timeint.ExactIntegrator): checked against the single equation's own exact integrator,
the smooth chain's exact integrator, an independent scipy event integration of the Filippov
system, and finite differences of the period map (the saltation monodromy)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _filippov import chain_reference as _reference  # tests/ is on sys.path through its conftest

from rattle.model import (
    Backlash, Chain, Clutch, Element, Excitation, Friction, Link, NonsmoothLaw, System, Torque,
)
from rattle.model._system import single_equation_system
from rattle.timeint import (
    ExactIntegrator, shoot_friction_orbit, shoot_nonsmooth_orbit,
)


def _single(levels, law=None):
    law = Backlash(b=0.05) if law is None else law
    sys1 = single_equation_system(0.05, 1.0, law, 0.01, (0.3,), (0.3,))
    ns = System.single(damping=0.05, stiffness=1.0, law=NonsmoothLaw(elastic=law, friction=Friction(levels=levels)),
                         excitation=Excitation(mean=0.01, amplitudes=(0.3,), phases=(0.3,)))
    return sys1.with_friction((levels,)), ns


def _chain(levels=((0.02, 0.06, 0.02), None), torque=0.25, grounded=True):
    links = [Link(between=(2, 3), stiffness=0.6, damping=0.03)]
    if grounded:
        links.append(Link(between=(3, 0), stiffness=0.4, damping=0.04))
    return Chain(
        inertias=(1.0, 0.5, 2.0),
        links=tuple(links),
        elements=(
            Element(name="clutch", between=(1, 2), stiffness=1.5, law=Clutch(alpha=0.2, b=0.05),
                    friction=None if levels[0] is None else Friction(levels=levels[0])),
            Element(name="gear", between=(2, 3), stiffness=2.0, law=Backlash(b=0.02),
                    friction=None if levels[1] is None else Friction(levels=levels[1])),
        ),
        torques=(Torque(inertia=1, mean=0.0 if not grounded else 0.02, amplitudes=(torque,), phases=(0.0,)),
                 *(() if grounded else (Torque(inertia=3, mean=0.0),))),
    )


@pytest.mark.parametrize("levels,omega", [((0.02, 0.005, 0.02), 0.35), ((0.1, 0.05, 0.1), 0.3),
                                          ((0.1, 0.05, 0.1), 0.5), ((0.3,), 0.8), ((0.3,), 1.5)])
def test_single_equation_agrees_with_its_own_exact_integrator(levels, omega):
    """n = m = 1: the chain integrator and the single equation's (different code: scalar stage
    solutions, its own stick logic) give the same state and sensitivity after 5 periods, sticks
    included (rows with stick time > 0)."""
    fs, ns = _single(levels)
    z0 = np.array([0.02, 0.1])
    T = 2 * math.pi / omega
    a = ExactIntegrator(ns).propagate(z0, 0.0, 5 * T, omega)
    b = ExactIntegrator(fs).propagate(z0, 0.0, 5 * T, omega)
    assert np.allclose(b.state1, a.state1, rtol=0, atol=1e-12)
    assert np.allclose(b.sensitivity, a.sensitivity, rtol=0, atol=1e-10 * max(1.0, np.abs(a.sensitivity).max()))
    if levels[0] >= 0.1:
        assert b.stick_time()[0] > 0.0
    o1 = shoot_nonsmooth_orbit(ns, omega, z0)
    o2 = shoot_friction_orbit(fs, omega, z0)
    if levels[0] < 0.3:  # r = 0.3 holds the element for whole periods: a continuum of orbits
        assert o1.converged and o2.converged
        assert o2.rms[0] == pytest.approx(o1.rms, rel=1e-9)
        assert np.allclose(np.abs(o2.multipliers), np.abs(o1.multipliers), atol=1e-8)


@pytest.mark.parametrize("grounded", [True, False])
def test_without_friction_it_is_the_smooth_chain(grounded):
    ch = _chain(levels=(None, None), grounded=grounded)
    sysm = ch.system()
    fs = sysm.with_friction((None, None))
    omega = 0.7
    z0 = np.linspace(0.01, 0.05, 2 * sysm.n)
    T = 2 * math.pi / omega
    a = ExactIntegrator(sysm).propagate(z0, 0.0, 3 * T, omega)
    b = ExactIntegrator(fs).propagate(z0, 0.0, 3 * T, omega)
    assert np.allclose(b.state1, a.state1, rtol=0, atol=1e-12)
    assert np.allclose(b.sensitivity, a.sensitivity, rtol=0, atol=1e-9)



@pytest.mark.parametrize("levels,omega", [((0.03, None), 0.45), ((0.03, 0.01), 0.9), ((0.06, 0.02), 0.3)])
def test_chain_agrees_with_an_independent_event_integration(levels, omega):
    """A 3-inertia chain, friction on one or both elements (constant levels), sticking included:
    the exact integrator's state after two periods against scipy's DOP853 event integration of
    the same Filippov system (rtol 1e-12: agreement to 1e-9 of the state's scale)."""
    ch = _chain(levels=levels)
    fs = ch.friction_system()
    z0 = np.array([0.02, -0.01, 0.0, 0.05, 0.0, -0.02])
    T = 2 * math.pi / omega
    exact = ExactIntegrator(fs).propagate(z0, 0.0, 2 * T, omega)
    ref = _reference(fs, z0, 2 * T, omega)
    scale = np.abs(exact.state1).max()
    assert np.abs(exact.state1 - ref).max() <= 1e-9 * scale  # measured 1e-12 … 1.5e-11
    kinds = set(exact.event_kinds.tolist())
    assert 1 in kinds or 2 in kinds  # a stick or a reversal happened: the friction logic was exercised


@pytest.mark.parametrize("levels,omega", [((0.03, 0.01), 0.45), ((0.06, 0.02), 0.3), ((0.02, 0.06, 0.02), None)])
def test_sensitivity_is_the_derivative_of_the_flow(levels, omega):
    """∂z(T)/∂z(0) with stage transitions and saltation matrices against central differences of
    the flow (across sticks, releases, reversals and crossings)."""
    if omega is None:
        levels, omega = ((0.02, 0.06, 0.02), (0.01,)), 0.6
    ch = _chain(levels=levels)
    fs = ch.friction_system()
    integ = ExactIntegrator(fs)
    z0 = np.array([0.02, -0.01, 0.0, 0.05, 0.0, -0.02])
    T = 2 * math.pi / omega
    traj = integ.propagate(z0, 0.0, 2 * T, omega)
    assert traj.event_times.size > 3
    h = 1e-7
    J = np.empty((6, 6))
    for i in range(6):
        dz = np.zeros(6)
        dz[i] = h
        J[:, i] = (integ.advance(z0 + dz, 0.0, 2 * T, omega)[0] - integ.advance(z0 - dz, 0.0, 2 * T, omega)[0]) / (2 * h)
    assert np.abs(J - traj.sensitivity).max() <= 1e-5 * max(1.0, np.abs(J).max())


def test_shooting_on_a_chain_finds_a_periodic_orbit_with_its_multipliers():
    ch = _chain(levels=((0.02, 0.06, 0.02), None))
    fs = ch.friction_system()
    omega = 0.5
    orbit = shoot_friction_orbit(fs, omega, np.zeros(6))
    assert orbit.converged
    z1 = ExactIntegrator(fs).propagate(orbit.state0, 0.0, 2 * math.pi / omega, omega).state1
    assert np.allclose(z1, orbit.state0, atol=1e-9 * np.abs(orbit.state0).max())
    mu = np.linalg.eigvals(orbit.monodromy)
    assert np.allclose(np.sort(np.abs(mu)), np.sort(np.abs(orbit.multipliers)))
    assert orbit.rms.shape == (2,) and np.all(orbit.rms > 0)
    # the element's exact rms by Gauss quadrature against dense trapezoid samples
    t = np.linspace(0.0, 2 * math.pi / omega, 20001)
    d, _, _ = orbit.trajectory.element_samples(t)
    rms = np.sqrt(np.trapezoid(d**2, t, axis=0) / t[-1])
    assert np.allclose(orbit.rms, rms, rtol=1e-6)


def test_sticking_is_reported_and_holds_the_torque_band():
    """At low Ω with strong friction the clutch sticks: during a stick its deflection is constant
    and its velocity zero."""
    ch = _chain(levels=((0.08,), None), torque=0.12)
    fs = ch.friction_system()
    omega = 0.25
    orbit = shoot_friction_orbit(fs, omega, np.zeros(6))
    assert orbit.converged
    assert 0.0 < orbit.stick_fraction[0] < 1.0
    for a, b in orbit.trajectory.stick_intervals(0):
        t = np.linspace(a, b, 7)[1:-1]
        d, v, _ = orbit.trajectory.element_samples(t)
        assert np.ptp(d[:, 0]) <= 1e-12 * max(1.0, abs(d[0, 0]))
        assert np.abs(v[:, 0]).max() <= 1e-12


def test_friction_on_elements_is_validated():
    with pytest.raises(ValueError, match="levels"):
        Element(name="c", between=(1, 2), stiffness=1.0, law=Backlash(b=0.1), friction=Friction(levels=(0.1, 0.2)))
    with pytest.raises(TypeError, match="friction"):
        Element(name="c", between=(1, 2), stiffness=1.0, law=Backlash(b=0.1), friction=0.1)
    ch = _chain()
    assert ch.has_friction
    with pytest.raises(ValueError, match="friction"):
        ch.system()
    assert ExactIntegrator(ch).system.discontinuous  # the one flow takes its reduced form


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_random_chains_agree_with_the_independent_event_integration(seed):
    """Random 3-inertia chains (grounded or free; clutch and gear laws, stiffnesses, inertias,
    damping, constant friction levels on one or both elements, forcing and Ω drawn): the exact
    state after two periods against the scipy event integration."""
    rng = np.random.default_rng(seed)
    grounded = bool(rng.integers(2))
    links = [Link(between=(2, 3), stiffness=float(rng.uniform(0.2, 1.0)), damping=float(rng.uniform(0.01, 0.05)))]
    if grounded:
        links.append(Link(between=(3, 0), stiffness=float(rng.uniform(0.1, 0.6)), damping=float(rng.uniform(0.01, 0.05))))
    r1 = float(rng.uniform(0.005, 0.08))
    r2 = float(rng.uniform(0.005, 0.04)) if rng.integers(2) else None
    ch = Chain(
        inertias=tuple(float(v) for v in rng.uniform(0.4, 2.5, 3)),
        links=tuple(links),
        elements=(
            Element(name="clutch", between=(1, 2), stiffness=float(rng.uniform(0.8, 2.5)),
                    law=Clutch(alpha=float(rng.uniform(0.05, 0.5)), b=float(rng.uniform(0.01, 0.1))),
                    friction=Friction(levels=r1)),
            Element(name="gear", between=(2, 3), stiffness=float(rng.uniform(1.0, 3.0)),
                    law=Backlash(b=float(rng.uniform(0.005, 0.05))), friction=None if r2 is None else Friction(levels=r2)),
        ),
        torques=(Torque(inertia=1, mean=float(rng.uniform(0.0, 0.05)) if grounded else 0.0,
                        amplitudes=(float(rng.uniform(0.05, 0.4)),), phases=(float(rng.uniform(0, 6.28)),)),),
    )
    fs = ch.friction_system()
    omega = float(rng.uniform(0.2, 1.5)) * fs.frequency_scale() / 2
    z0 = np.concatenate((rng.normal(0.0, 0.03, fs.n), rng.normal(0.0, 0.03, fs.n)))
    T = 2 * math.pi / omega
    exact = ExactIntegrator(fs).propagate(z0, 0.0, 2 * T, omega)
    ref = _reference(fs, z0, 2 * T, omega)
    assert np.abs(exact.state1 - ref).max() <= 1e-9 * max(np.abs(exact.state1).max(), 1e-3)


def test_a_case_file_with_friction_on_an_element_reads_as_that_chain():
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "chain_clutch_friction.toml"
    ch = Chain.from_toml(path)
    assert isinstance(ch, Chain) and ch.has_friction
    fs = ch.friction_system()
    assert any(np.any(fs.friction_levels(e) > 0) for e in range(fs.m))


def test_a_fully_stuck_element_gives_a_family_of_orbits_held_by_its_deflection():
    """Friction strong enough to hold the clutch the whole period: every stuck deflection within
    the band carries a periodic orbit (a multiplier 1). ``hold`` picks the member: converged, the
    clutch constant at the held value, and two holds give two different orbits."""
    ch = _chain(levels=((0.3,), None), torque=0.1)
    fs = ch.friction_system()
    omega = 1.2
    orbits = []
    for d in (0.02, 0.06):
        o = shoot_friction_orbit(fs, omega, np.zeros(6), hold={0: d})
        assert o.converged and o.stick_fraction[0] == pytest.approx(1.0)
        t = np.linspace(0.0, 2 * math.pi / omega, 9)
        dd, vv, _ = o.trajectory.element_samples(t)
        assert np.allclose(dd[:, 0], d, rtol=0, atol=1e-12) and np.abs(vv[:, 0]).max() <= 1e-12
        assert np.min(np.abs(np.abs(o.multipliers) - 1.0)) <= 1e-9  # the family's neutral direction
        orbits.append(o)
    assert not np.allclose(orbits[0].state0, orbits[1].state0)
    # a start in the stick removes a δ_e' perturbation (the entry saltation S = I − b aᵀ/(a·b) on
    # the velocities: the slip along b that a relative velocity starts is undone at once)
    b = fs.continuous().element_columns[:, 0]
    assert np.allclose(orbits[0].monodromy[:, 3:] @ b, 0.0, atol=1e-12)
