"""Time-domain steady states and stepped sweeps of the discontinuous laws: ``steady_state`` and
``time_sweep`` on a :class:`System` (jumps, Coulomb friction) and on a
a :class:`System` with its elements' whole laws (a chain with friction on its elements), checked against independent
exact shooting (``shoot_nonsmooth_orbit`` / ``shoot_friction_orbit``)."""

from __future__ import annotations

import dataclasses

import math
import pickle

import numpy as np
import pytest

from rattle.analysis import SteadyStateOptions, steady_state, time_sweep
from rattle.analysis._steady import static_state, stick_fraction
from rattle.errors import Status
from rattle.model import (
    Chain, Clutch, Element, Excitation, Friction, Link, NonsmoothLaw, Preload, System, Torque,
)
from rattle.timeint import ExactIntegrator, shoot_friction_orbit, shoot_nonsmooth_orbit


def _preload(friction: float | None = 0.02) -> System:
    """The torque converter's preloaded spring (T_p = 0.03, c = 0.05, F = 0.05 + 0.03 cos Ωt),
    optionally with Coulomb friction r on both stages."""
    law = NonsmoothLaw(elastic=Preload(preload=0.03), friction=None if friction is None else Friction(levels=friction))
    return System.single(damping=0.05, stiffness=1.0, law=law, excitation=Excitation(mean=0.05, amplitudes=(0.03,)))


def _two_inertias():
    """Two inertias, the second grounded by a soft link; a clutch with friction on its idle stage."""
    return Chain(
        inertias=(1.0, 1.0),
        links=(Link(between=(2, 0), stiffness=0.1, damping=0.05), Link(between=(1, 2), damping=0.02)),
        elements=(Element(name="clutch", between=(1, 2), stiffness=1.0, law=Clutch(alpha=0.25, b=0.1),
                          friction=Friction(levels=(0.0, 0.03, 0.0))),),
        torques=(Torque(inertia=1, mean=0.05, amplitudes=(0.06,)),),
    ).friction_system()


def test_a_sticking_preload_with_friction_settles_on_the_exact_orbit():
    ns = _preload()
    omega = 0.5
    s = steady_state(ns, omega)
    assert s.period == 1 and s.status is Status.CONVERGED and s.stable
    held = stick_fraction(s.trajectory)
    assert 0.2 < held < 0.5  # it sticks about 31 % of the period
    assert np.min(np.abs(s.multipliers)) < 1e-12  # the stick phase: an exact zero multiplier
    # an independent shooting from rest lands on the same orbit
    orbit = shoot_nonsmooth_orbit(ns, omega, (0.0, 0.0))
    assert orbit.converged
    assert abs(orbit.rms - s.rms) <= 1e-9 and abs(orbit.mean - s.mean) <= 1e-9
    np.testing.assert_allclose(np.abs(s.multipliers), np.abs(orbit.multipliers), atol=1e-9)
    # the extremes against dense samples of the exact trajectory (δ'' one-sided at the switchings)
    t = np.linspace(0.0, 2 * math.pi / omega, 20001)
    d, _, a = s.trajectory.sample(t)
    assert s.delta_min <= d.min() + 1e-12 and s.delta_max >= d.max() - 1e-12
    assert s.p2p == pytest.approx(np.ptp(d), rel=1e-6)
    assert s.acc_p2p >= np.ptp(a) - 1e-12 and s.acc_p2p == pytest.approx(np.ptp(a), rel=1e-3)
    rms_ac = math.sqrt(np.trapezoid((d - s.mean) ** 2, t) / t[-1])
    assert s.rms_ac == pytest.approx(rms_ac, rel=1e-6)


def test_the_integrator_and_the_start_state_of_a_nonsmooth_system():
    ns = _preload(None)
    np.testing.assert_allclose(static_state(ns), [0.02, 0.0])  # δ + T_p = F_m on the drive side
    integ = ExactIntegrator(ns)
    a = steady_state(ns, 0.7, integrator=integ)
    b = steady_state(ns, 0.7, a.final_state, integrator=integ)
    assert a.settled and b.settled and abs(a.rms - b.rms) <= 1e-9
    with pytest.raises(ValueError, match="different system"):
        steady_state(ns, 0.7, integrator=ExactIntegrator(_preload(0.01)))
    with pytest.raises(TypeError, match="ExactIntegrator"):
        steady_state(ns, 0.7, integrator=object())


def test_a_chain_with_friction_settles_on_the_exact_orbit():
    fs = _two_inertias()
    omega = 0.6
    s = steady_state(fs, omega)
    assert s.period == 1 and s.status is Status.CONVERGED and s.stable
    assert s.element_names == ("clutch",)
    held = stick_fraction(s.trajectory)
    assert held.shape == (1,) and 0.3 < held[0] < 0.6  # the clutch sticks about 44 % of the period
    orbit = shoot_friction_orbit(fs, omega, static_state(fs, omega))  # from rest, independently
    assert orbit.converged
    assert abs(float(orbit.rms[0]) - s.rms) <= 1e-9
    assert abs(float(orbit.mean[0]) - s.mean) <= 1e-9
    np.testing.assert_allclose(held, orbit.stick_fraction, atol=1e-9)
    t = np.linspace(0.0, 2 * math.pi / omega, 8001)
    d, _, a = s.trajectory.element_samples(t)
    em = s.element_measures
    assert em.p2p[0] == pytest.approx(np.ptp(d[:, 0]), rel=1e-6)
    assert em.acc_p2p[0] >= np.ptp(a[:, 0]) - 1e-12 and em.acc_p2p[0] == pytest.approx(np.ptp(a[:, 0]), rel=1e-3)


def test_up_and_down_sweeps_of_a_preload_show_the_hysteresis_on_stable_exact_orbits():
    """The torque converter's resonance bends to lower frequency (folds near Ω = 1.0194 and
    1.0249): between them the run-up stays on the small motion and the run-down on the large one."""
    ns = _preload(None)
    seen = []
    sweep = time_sweep(ns, omega=(1.005, 1.045), points=9, direction="both", callback=lambda d, n: seen.append(d))
    assert seen[-1] == 18 and len(sweep) == 18
    up, down = sweep.select("up"), sweep.select("down")
    assert np.array_equal(up.omega, down.omega[::-1])
    gap = np.abs(up.rms - down.rms[::-1]) / np.maximum(up.rms, down.rms[::-1])
    assert np.max(gap) > 0.5  # the hysteresis: rms 0.07 (up) against 0.3 (down) near Ω = 1.02
    assert np.min(gap) < 1e-9  # outside it both find the same orbit
    assert any(j.direction == "up" and j.kind == "up" for j in sweep.jumps())  # the run-up jumps onto the peak
    assert "stick_fraction" in sweep.extra_columns and np.all(sweep.extra_columns["stick_fraction"] == 0.0)
    assert list(sweep.columns())[-1] == "stick_fraction"
    import matplotlib

    matplotlib.use("Agg")
    fig, axes = sweep.plot()  # never stuck or locked: no panel of zeros below (issue 27), the title says so
    assert list(axes) == ["response"] and "never stuck or locked" in axes.primary.get_title()
    matplotlib.pyplot.close(fig)
    held = dataclasses.replace(sweep, extra_columns={**sweep.extra_columns,
                                                     "stick_fraction": np.full(len(sweep), 0.05)})
    fig, axes = held.plot()  # held part of the period: the stick fractions below, scaled to them
    assert axes["stick"].get_ylabel() == "stick / period" and axes.primary is axes["response"]
    assert axes["stick"].get_ylim()[1] < 0.1
    matplotlib.pyplot.close(fig)
    for w, p, x, rms, settled in zip(sweep.omega, sweep.period, sweep.state0, sweep.rms, sweep.settled):
        assert settled
        orbit = shoot_nonsmooth_orbit(ns, float(w), x, period=int(p))
        assert orbit.converged and np.max(np.abs(orbit.multipliers)) < 1.0
        assert abs(orbit.rms - rms) <= 1e-9


def test_a_chain_sweep_has_per_element_columns_and_runs_in_two_processes():
    fs = _two_inertias()
    assert pickle.loads(pickle.dumps(fs)).element_names == ("clutch",)
    options = SteadyStateOptions(max_periods=300)
    serial = time_sweep(fs, omega=(0.55, 0.65), points=3, direction="both", options=options)
    parallel = time_sweep(fs, omega=(0.55, 0.65), points=3, direction="both", options=options, workers=2)
    assert serial.element_names == ("clutch",)
    cols = serial.columns()
    assert "clutch_rms" in cols and "clutch_stick_fraction" in cols
    np.testing.assert_array_equal(serial.rms, parallel.rms)
    np.testing.assert_array_equal(serial.extra_columns["clutch_stick_fraction"],
                                  parallel.extra_columns["clutch_stick_fraction"])
    assert np.all(serial.extra_columns["clutch_stick_fraction"] > 0.0)
    np.testing.assert_array_equal(serial.element_columns["clutch_rms"], serial.rms)
    assert serial.state0.shape == (6, 4) and serial.multipliers.shape == (6, 4)
    # the records are the trajectories the rows were measured on
    traj, window = next(iter(serial.records()))
    assert window == serial.period[0]
    assert np.allclose(traj.element_mean_and_rms()[1][0], serial.rms[0], rtol=1e-12)


def test_a_bad_range_of_a_discontinuous_law_is_refused():
    with pytest.raises(ValueError, match="omega"):
        time_sweep(_preload(), omega=(1e-6, 1.0), points=3)
    with pytest.raises(ValueError, match="omega"):
        time_sweep(_two_inertias(), omega=(0.5, 1e4), points=3)


def test_compare_sets_the_response_beside_the_exact_sweep():
    import json

    import matplotlib

    matplotlib.use("Agg")
    from rattle.analysis import RegularisationOptions, compare

    ns = _preload()
    reg = RegularisationOptions(harmonics=32, refine=None)
    result = compare(ns, omega=(0.6, 0.65), points=3, regularisation=reg)
    assert result.discontinuous and result.at == () and result.orbits == ()
    assert result.frf.harmonics == 32 and len(result.sweep) == 6
    ag = result.agreement()
    assert ag["rows"] == ag["compared"] == 6 and ag["largest"] < 1e-4 and ag["without"] == []
    meta = json.loads(json.dumps(result.metadata()))
    assert meta["frf"]["matched"] == len(result.frf) and meta["agreement"]["compared"] == 6
    assert "sweep against the response: 6 of 6" in result.summary()
    fig, axes = result.plot()
    assert axes["stick"] is not None and axes.primary is axes["frf"]
    with pytest.raises(ValueError, match="`at`"):
        compare(ns, omega=(0.6, 0.65), points=3, at=[0.62], regularisation=reg)
    with pytest.raises(ValueError, match="`harmonics`"):
        compare(ns, omega=(0.6, 0.65), points=3, harmonics=16)
    with pytest.raises(ValueError, match="`regularisation`"):
        from rattle import reference_case

        compare(reference_case(), points=3, regularisation=reg)


def test_regimes_of_the_discontinuous_steady_states_follow_their_orbits():
    """SteadyState.regimes() of a discontinuous law is its exact orbit's regime (a jump at δ = 0
    on neither side), per element for a chain, from the breakpoints the trajectory crossed."""
    ns = _preload()
    s = steady_state(ns, 0.5)
    orbit = shoot_nonsmooth_orbit(ns, 0.5, (0.0, 0.0))
    assert s.regimes() == (orbit.regime,) and s.regime == orbit.regime
    fs = _two_inertias()
    s = steady_state(fs, 0.6)
    crossed = s.trajectory.crossed_breakpoints(0)
    want = "no_impact" if crossed.size == 0 else (
        "single_sided" if np.all(crossed >= 0) or np.all(crossed <= 0) else "double_sided")
    assert s.regimes() == (want,)
    assert s.regime in ("no_impact", "single_sided", "double_sided")
