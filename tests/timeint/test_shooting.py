"""Periodic orbits by shooting on the exact flow: convergence, Floquet multipliers, measures."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import quad

from rattle.model import Excitation, Linear, Model, reference_case
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit

# Orbits of the reference clutch found by shooting from a grid of guesses (x0 rounded to 2
# decimals); at Ω = 0.8 three period-1 orbits coexist (the hysteresis window of the softening
# primary resonance is 0.754 < Ω < 0.874; at Ω = 0.7 the orbit is unique).
REFERENCE_ORBITS = {
    0.3: (0.18, -0.01),
    0.7: (0.40, 0.14),
    1.0: (0.10, 0.01),
    2.0: (0.17, 0.0),
}


def _check_orbit(model: Model, orbit) -> None:
    assert orbit.converged
    # tol = 1e-12 on the scaled residual; the flow itself is exact to ~1e-15.
    assert orbit.residual < 1e-11
    T = orbit.period * 2 * math.pi / orbit.omega
    again = ExactIntegrator(model).propagate(orbit.state0, 0.0, T, orbit.omega)
    # One more period returns to the start: residual (~1e-12 L) amplified by at most |μ| ≲ 2.
    np.testing.assert_allclose(again.state1, orbit.state0, rtol=0, atol=1e-11)
    # Liouville: μ1 μ2 = det M = exp(−c T) (trace A_j = −c on every stage).
    assert np.prod(orbit.multipliers).real == pytest.approx(math.exp(-model.c * T), rel=1e-10)
    assert abs(np.prod(orbit.multipliers).imag) < 1e-12
    np.testing.assert_allclose(np.abs(orbit.multipliers), np.sort(np.abs(orbit.multipliers))[::-1])


@pytest.mark.parametrize("omega", sorted(REFERENCE_ORBITS))
def test_reference_orbits_converge(omega):
    model = reference_case()
    orbit = shoot_periodic_orbit(model, omega, REFERENCE_ORBITS[omega])
    _check_orbit(model, orbit)
    assert orbit.stable
    assert orbit.iterations <= 10


def test_three_coexisting_orbits_at_0p8():
    """Large stable, unstable (saddle, real multipliers 1.64 and 0.41) and small stable orbits."""
    model = reference_case()
    guesses = [(0.43, 0.31), (-0.25, 0.14), (-0.05, 0.03)]
    orbits = [shoot_periodic_orbit(model, 0.8, g) for g in guesses]
    for orbit in orbits:
        _check_orbit(model, orbit)
    large, saddle, small = orbits
    assert large.stable and small.stable and not saddle.stable
    assert abs(saddle.multipliers[0]) > 1.0 > abs(saddle.multipliers[1])
    assert large.rms > saddle.rms > small.rms
    assert large.regime == "double_sided" and small.regime == "single_sided"
    # Regression values (exact flow; tolerance far above round-off, far below the orbit spacing).
    assert [o.rms for o in orbits] == pytest.approx([0.365991, 0.264359, 0.166710], abs=2e-6)


def test_linear_orbit_closed_form():
    """Linear law: the periodic orbit is F_m/k + Re[X e^{iΩt}], X = F/(k − Ω² + icΩ); its measures
    and multipliers exp(λT) are closed forms."""
    model = Model(inertia=1.0, damping=0.1, stiffness=2.0, elastic=Linear(),
                  excitation=Excitation(mean=0.3, amplitudes=(0.5,), phases=(0.7,)))
    omega = 1.2
    T = 2 * math.pi / omega
    X = 0.5 * np.exp(0.7j) / (model.k - omega**2 + 1j * model.c * omega)
    orbit = shoot_periodic_orbit(model, omega, (0.0, 0.0))
    assert orbit.converged and orbit.iterations <= 2  # the period map is affine: one Newton step
    np.testing.assert_allclose(orbit.state0, [0.3 / model.k + X.real, (1j * omega * X).real], rtol=0, atol=1e-13)
    np.testing.assert_allclose(orbit.monodromy, scipy.linalg.expm(np.array([[0, 1], [-model.k, -model.c]]) * T),
                               rtol=0, atol=1e-13)
    lam = np.roots([1.0, model.c, model.k])
    np.testing.assert_allclose(np.sort_complex(orbit.multipliers), np.sort_complex(np.exp(lam * T)), rtol=0, atol=1e-13)
    # Gauss–Legendre on analytic segments: the measures are exact to round-off.
    a = abs(X)
    assert orbit.mean == pytest.approx(0.3 / model.k, abs=1e-14)
    assert orbit.rms_ac == pytest.approx(a / math.sqrt(2), abs=1e-14)
    assert orbit.rms == pytest.approx(math.hypot(0.3 / model.k, a / math.sqrt(2)), abs=1e-14)
    assert orbit.p2p == pytest.approx(2 * a, abs=1e-14)
    assert orbit.acc_p2p == pytest.approx(2 * a * omega**2, abs=1e-14)
    assert orbit.regime == "no_impact"


def test_measures_against_adaptive_quadrature():
    """Reference clutch at Ω = 0.7 (double-sided impacts): the Gauss–Legendre integrals match
    scipy.quad over the segments, and the refined extremes bound dense samples from outside."""
    model = reference_case()
    orbit = shoot_periodic_orbit(model, 0.7, REFERENCE_ORBITS[0.7])
    traj = orbit.trajectory
    T = traj.t1
    f = lambda t: float(traj.sample(np.array([t])).delta[0])  # noqa: E731

    def integral(g):  # segment by segment: δ is analytic on each
        return sum(quad(g, a, b, epsabs=1e-15, epsrel=1e-13)[0] for a, b in zip(traj.t_start, traj.t_end))

    mean = integral(f) / T
    ms_ac = integral(lambda t: (f(t) - mean) ** 2) / T
    # quad reaches ~1e-14 on these smooth pieces; the Gauss–Legendre sums are exact to round-off.
    assert orbit.mean == pytest.approx(mean, abs=1e-13)
    assert orbit.rms_ac == pytest.approx(math.sqrt(ms_ac), abs=1e-13)
    assert orbit.rms == pytest.approx(math.sqrt(ms_ac + mean**2), abs=1e-13)
    dense = traj.sample(np.linspace(0.0, T, 20001))
    # Exact extremes lie outside the sampled range, by at most the sampling error
    # ~ (ΔT/2)² |δ''| / 2 ≈ 1e-8.
    for exact, sampled, sign in [
        (orbit.delta_max, dense.delta.max(), 1), (orbit.delta_min, dense.delta.min(), -1),
        (orbit.acc_max, dense.acceleration.max(), 1), (orbit.acc_min, dense.acceleration.min(), -1),
    ]:
        assert sign * (exact - sampled) >= -1e-15
        assert abs(exact - sampled) < 1e-7
    assert orbit.p2p == pytest.approx(orbit.delta_max - orbit.delta_min)
    assert orbit.acc_p2p == pytest.approx(orbit.acc_max - orbit.acc_min)


def test_subharmonic_period_two():
    """At Ω = 1.4 a stable 1/2 sub-harmonic exists (the Ω = 0.7 resonance seen at half the
    forcing frequency): a genuine period-2 orbit, not a period-1 orbit counted twice."""
    model = reference_case()
    orbit = shoot_periodic_orbit(model, 1.4, (0.18, 0.09), period=2)
    _check_orbit(model, orbit)
    after_one = ExactIntegrator(model).propagate(orbit.state0, 0.0, 2 * math.pi / 1.4, 1.4).state1
    assert np.max(np.abs(after_one - orbit.state0)) > 1e-2
    assert orbit.stable


def test_arguments_are_checked():
    model = reference_case()
    with pytest.raises(ValueError, match="`period`"):
        shoot_periodic_orbit(model, 1.0, (0.0, 0.0), period=0)
    with pytest.raises(ValueError, match="`omega`"):
        shoot_periodic_orbit(model, -1.0, (0.0, 0.0))
    with pytest.raises(TypeError):
        shoot_periodic_orbit(model, 1.0, (0.0, 0.0), tolerance=1e-3)  # unknown keyword


def test_failure_is_reported_not_raised():
    model = reference_case()
    orbit = shoot_periodic_orbit(model, 0.7, (0.8, -0.6), max_iterations=1)
    assert not orbit.converged
    assert orbit.residual > 1e-12
