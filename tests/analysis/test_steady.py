"""Steady state by simulation: settling, period detection (1 … 8 or 0) and honest acceleration."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import trapezoid

from rattle.analysis import SteadyStateOptions, steady_state
from rattle.errors import Status
from rattle.model import Backlash, Excitation, Linear, Model, reference_case
from rattle.results import SteadyState
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit

PLAIN = SteadyStateOptions(accelerate=False)


def _rest(model: Model) -> tuple[float, float]:
    return (model.static_equilibrium(), 0.0)


def _rattling_backlash() -> Model:
    """A gear pair with a small mean load and a strong pulsation: period-3, period-4 and
    chaotic (period 0) motions."""
    return Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Backlash(b=0.17),
                 excitation=Excitation(mean=0.01, amplitudes=(0.1,)))


# --- linear law: closed form -------------------------------------------------------------------
@pytest.mark.parametrize("accelerate", [True, False])
def test_linear_law_settles_on_the_closed_form_orbit(accelerate):
    """f = δ, two harmonics with phases: δ = F_m/k + Σ Re[X_n e^{inΩt}], one period, multipliers
    exp(λ T)."""
    model = Model(inertia=1.0, damping=0.1, stiffness=2.0, elastic=Linear(),
                  excitation=Excitation(mean=0.3, amplitudes=(0.5, 0.2), phases=(0.7, -0.3)))
    omega = 1.2
    T = 2 * math.pi / omega
    X = np.array([a * np.exp(1j * ph) / (model.k - (n * omega) ** 2 + 1j * model.c * n * omega)
                  for n, a, ph in zip((1, 2), (0.5, 0.2), (0.7, -0.3))])
    s = steady_state(model, omega, (0.0, 0.0), options=SteadyStateOptions(accelerate=accelerate))
    assert isinstance(s, SteadyState)
    assert s.period == 1 and s.settled
    assert s.method == ("shooting" if accelerate else "simulation")
    assert s.status is (Status.CONVERGED if accelerate else Status.SETTLED) and s.status.success
    mean = 0.3 / model.k
    rms_ac = math.sqrt(0.5 * np.sum(np.abs(X) ** 2))
    # accelerated: the exact orbit (round-off); plain: within the settling tolerance 1e-8 · L.
    tol = 1e-12 if accelerate else 1e-8
    assert s.mean == pytest.approx(mean, abs=tol)
    assert s.rms_ac == pytest.approx(rms_ac, abs=tol)
    assert s.rms == pytest.approx(math.hypot(mean, rms_ac), abs=tol)
    x0 = np.array([mean + X.real.sum(), (1j * omega * np.array([1, 2]) * X).real.sum()])
    np.testing.assert_allclose(s.state0, x0, rtol=0, atol=tol)
    lam = np.roots([1.0, model.c, model.k])
    np.testing.assert_allclose(np.sort_complex(s.multipliers), np.sort_complex(np.exp(lam * T)), rtol=0, atol=1e-12)
    assert s.regime == "no_impact" and s.stable


# --- reference clutch ----------------------------------------------------------------------------
@pytest.mark.parametrize(("omega", "guess"), [(0.3, (0.18, -0.01)), (2.0, (0.17, 0.0))])
def test_reference_period_one_equals_the_shooting_orbit(omega, guess):
    model = reference_case()
    s = steady_state(model, omega, _rest(model))
    orbit = shoot_periodic_orbit(model, omega, guess)
    assert s.period == 1 and s.method == "shooting" and s.stable
    # Both are the exact orbit (Newton to 1e-12 of the scaled residual).
    assert s.rms == pytest.approx(orbit.rms, abs=1e-9)
    assert s.p2p == pytest.approx(orbit.p2p, abs=1e-9)
    assert s.acc_p2p == pytest.approx(orbit.acc_p2p, abs=1e-9)
    np.testing.assert_allclose(s.state0, orbit.state0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(s.final_state, s.state0)
    np.testing.assert_allclose(s.cycle, s.state0[None, :])
    # The acceleration is real: far fewer periods than the plain simulation needs.
    plain = steady_state(model, omega, _rest(model), options=PLAIN)
    assert s.periods + s.shooting_periods < plain.periods


def test_subharmonic_point_b_is_period_two():
    """Ω = 1.41 (the paper's point "B"): from rest the motion settles on the 1/2 sub-harmonic."""
    model = reference_case()
    s = steady_state(model, 1.41, _rest(model))
    assert s.period == 2 and s.stable
    assert s.cycle.shape == (2, 2)
    assert np.max(np.abs(s.cycle[1] - s.cycle[0])) > 1e-2  # a genuine period 2
    orbit = shoot_periodic_orbit(model, 1.41, s.state0, period=2)
    assert orbit.converged and orbit.iterations == 0
    assert s.rms == pytest.approx(orbit.rms, abs=1e-12)
    assert s.rms == pytest.approx(0.15907, abs=1e-5)
    T = 2 * math.pi / 1.41
    assert s.trajectory.t1 == pytest.approx(2 * T)


def test_point_a_is_not_period_one():
    """Ω = 0.44 (the paper's point "A"): the period-1 orbit has lost stability by period
    doubling (HB: 0.408 < Ω < 0.461, multiplier below −1); the motion is period 2."""
    model = reference_case()
    s = steady_state(model, 0.44, _rest(model))
    assert s.period == 2
    assert s.rms == pytest.approx(0.163571, abs=1e-5)
    p1 = shoot_periodic_orbit(model, 0.44, s.state0)  # the period-1 orbit nearby
    assert p1.converged and not p1.stable
    assert p1.multipliers[0].real < -1.0


@pytest.mark.parametrize("omega", [0.3, 0.44, 0.8, 1.41, 2.0])
def test_without_acceleration_the_answers_are_the_same(omega):
    model = reference_case()
    fast = steady_state(model, omega, _rest(model))
    slow = steady_state(model, omega, _rest(model), options=PLAIN)
    assert slow.method == "simulation" and slow.shooting_periods == 0
    assert fast.period == slow.period
    # The plain simulation stops within ‖P_i − P_{i−n}‖ ≤ 1e-8 (scaled), i.e. within
    # 1e-8 / (1 − |μ|) ≲ 2e-7 · L of the orbit.
    L = model.length_scale()
    assert fast.rms == pytest.approx(slow.rms, abs=2e-7 * L)
    assert fast.p2p == pytest.approx(slow.p2p, abs=1e-6 * L)
    np.testing.assert_allclose(np.abs(fast.multipliers), np.abs(slow.multipliers), rtol=1e-5)


def test_acceleration_follows_the_simulation_away_from_a_saddle():
    """Ω = 0.8 has three period-1 orbits (large stable, saddle, small stable). Started next to
    the saddle, the accelerated result is the attractor the plain simulation reaches."""
    model = reference_case()
    saddle = shoot_periodic_orbit(model, 0.8, (-0.25, 0.14))
    assert saddle.converged and not saddle.stable
    for push in (1e-3, -1e-3):
        x0 = saddle.state0 + push * np.real(np.linalg.eig(saddle.monodromy)[1][:, 0])
        fast = steady_state(model, 0.8, x0)
        slow = steady_state(model, 0.8, x0, options=PLAIN)
        assert fast.period == slow.period == 1
        assert fast.rms == pytest.approx(slow.rms, abs=1e-7)
        assert abs(fast.rms - saddle.rms) > 0.05


def test_started_on_an_orbit_the_minimal_period_is_found():
    """A period-1 orbit is also period 2 … 8: the smallest period is reported, at once."""
    model = reference_case()
    orbit = shoot_periodic_orbit(model, 2.0, (0.17, 0.0))
    for opts in (None, PLAIN):
        s = steady_state(model, 2.0, orbit.state0, options=opts)
        assert s.period == 1
        assert s.periods <= 3
    sub = shoot_periodic_orbit(model, 1.4, (0.18, 0.09), period=2)
    assert steady_state(model, 1.4, sub.state0).period == 2


def test_periods_three_and_four():
    model = _rattling_backlash()
    for omega, period in ((1.5, 3), (0.4, 4)):
        fast = steady_state(model, omega, _rest(model))
        slow = steady_state(model, omega, _rest(model), options=PLAIN)
        assert fast.period == slow.period == period
        assert fast.cycle.shape == (period, 2)
        assert fast.rms == pytest.approx(slow.rms, abs=1e-7)
        assert fast.trajectory.t1 == pytest.approx(period * 2 * math.pi / omega)


def test_chaotic_motion_is_period_zero():
    """Ω = 1.2: the Poincaré points never repeat (chaotic rattle); measures over the record."""
    model = _rattling_backlash()
    opts = SteadyStateOptions(max_periods=300, record_periods=40)
    s = steady_state(model, 1.2, _rest(model), options=opts)
    assert s.period == 0 and not s.settled and s.method == "unsettled"
    assert s.status is Status.MAX_PERIODS and not s.status.success
    assert s.multipliers is None and s.stable is None
    assert s.cycle.shape == (0, 2)
    assert s.periods == 300 + 40
    T = 2 * math.pi / 1.2
    assert s.trajectory.t1 == pytest.approx(40 * T)
    assert s.poincare.shape == (opts.section_points, 2)
    # Spread over the section: far from any cycle of period ≤ 8.
    for n in range(1, 9):
        assert np.max(np.abs(s.poincare[n:] - s.poincare[:-n])) > 1e-2
    np.testing.assert_allclose(s.final_state, s.poincare[-1])
    # The record is the exact trajectory: its measures are those of dense samples (trapezoidal
    # rule, h = T/1000 on a piecewise-smooth δ: error ~1e-9).
    t = np.linspace(0.0, 40 * T, 40001)
    dense = s.trajectory.sample(t)
    assert s.rms == pytest.approx(math.sqrt(trapezoid(dense.delta**2, t) / (40 * T)), rel=1e-8)
    assert s.delta_max >= dense.delta.max() - 1e-15


def test_budget_exhausted_is_period_zero():
    model = reference_case()
    s = steady_state(model, 2.0, _rest(model), options=SteadyStateOptions(max_periods=5, accelerate=False))
    assert s.period == 0 and s.residual > 1e-8


def test_integrator_is_reused_and_checked():
    model = reference_case()
    integ = ExactIntegrator(model)
    assert steady_state(model, 0.3, _rest(model), integrator=integ).period == 1
    with pytest.raises(ValueError, match="different model"):
        steady_state(reference_case().__class__(**{**{f.name: getattr(model, f.name) for f in dataclasses.fields(model)},
                                                   "damping": 0.1}), 0.3, (0.0, 0.0), integrator=integ)


def test_options_are_validated():
    with pytest.raises(ValueError, match="`tolerance`"):
        SteadyStateOptions(tolerance=-1.0)
    with pytest.raises(ValueError, match="`max_periods`"):
        SteadyStateOptions(max_periods=0)
    with pytest.raises(ValueError, match="`max_period_multiple`"):
        SteadyStateOptions(max_period_multiple=0)
    with pytest.raises(TypeError, match="`record_periods`"):
        SteadyStateOptions(record_periods=2.5)
    with pytest.raises(TypeError, match="`accelerate`"):
        SteadyStateOptions(accelerate="yes")
    with pytest.raises(TypeError):
        SteadyStateOptions(tol=1e-3)  # unknown keyword
    with pytest.raises(TypeError):
        SteadyStateOptions(1e-8)  # keyword-only
    opts = SteadyStateOptions()
    with pytest.raises(AttributeError):
        opts.tolerance = 1.0  # frozen
    assert dataclasses.replace(opts, max_periods=10).max_periods == 10
    assert opts.to_dict()["tolerance"] == 1e-8


def test_arguments_are_checked():
    model = reference_case()
    with pytest.raises(ValueError, match="`omega`"):
        steady_state(model, 0.0, (0.0, 0.0))
    with pytest.raises(ValueError, match="`x0`"):
        steady_state(model, 1.0, (0.0, 0.0, 0.0))
    with pytest.raises(TypeError, match="`options`"):
        steady_state(model, 1.0, (0.0, 0.0), options={"tolerance": 1e-6})
    with pytest.raises(TypeError):
        steady_state(model, 1.0, (0.0, 0.0), tolerance=1e-6)  # unknown keyword


def test_the_old_timeint_names_answer_with_a_deprecation_warning():
    """The steady state moved from ``rattle.timeint`` to ``rattle.analysis`` (its result to
    ``rattle.results``); the old names still answer, with a warning naming the new place."""
    import rattle.results
    import rattle.timeint

    for name, where in (("steady_state", "rattle.analysis"), ("SteadyStateOptions", "rattle.analysis"),
                        ("SteadyState", "rattle.results")):
        with pytest.warns(DeprecationWarning, match=f"`rattle.timeint.{name}` is deprecated; import it from {where}"):
            old = getattr(rattle.timeint, name)
        assert old is getattr(rattle.analysis if where == "rattle.analysis" else rattle.results, name)
        assert name not in rattle.timeint.__all__
    with pytest.raises(AttributeError, match="no attribute 'steady'"):
        rattle.timeint.steady  # noqa: B018
