"""periodic_orbit(): every coexisting HB orbit at one frequency, checked against exact shooting."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rattle.analysis import periodic_orbit
from rattle.analysis._orbit import _least_period, _reduce, _shift, default_search_range
from rattle.io import read_csv
from rattle.results import ORBIT_COLUMNS
from rattle.results import OrbitSolution, PeriodicOrbit
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit


@pytest.fixture(scope="module")
def orbit_08(reference_model, reference_frf) -> PeriodicOrbit:
    return periodic_orbit(reference_model, 0.8, frf=reference_frf)


@pytest.fixture(scope="module")
def orbit_141(reference_model, reference_frf) -> PeriodicOrbit:
    return periodic_orbit(reference_model, 1.41, period=2, frf=reference_frf)


def _shoot(model, omega: float, x0, period: int = 1):
    orbit = shoot_periodic_orbit(model, omega, x0, period=period)
    assert orbit.converged
    return orbit


# --------------------------------------------------------------------------------------------
# The reference case
# --------------------------------------------------------------------------------------------
def test_three_coexisting_period_1_orbits_at_0_8(reference_model, orbit_08: PeriodicOrbit) -> None:
    sols = orbit_08.solutions
    assert [s.period for s in sols] == [1, 1, 1]
    assert [s.stable for s in sols] == [True, False, True]
    # Exact shooting from each HB orbit's state at t = 0 (periodic orbits of the exact flow).
    for s, rms_ref in zip(sols, (0.36599, 0.26436, 0.16671)):
        h = orbit_08.time_history(sols.index(s), samples=64)
        exact = _shoot(reference_model, 0.8, (h["delta"][0], h["velocity"][0]))
        # rtol 1e-4: HB with H = 32 on the kinked law vs the exact orbit (same tolerance as the FRF).
        assert s.rms == pytest.approx(exact.rms, rel=1e-4)
        assert s.rms == pytest.approx(rms_ref, abs=1e-5)  # the brief's numbers, 5 digits
        assert s.stable == exact.stable
    assert orbit_08.simulated_period == 1
    assert orbit_08.selected == 2  # the simulation from rest settles on the small orbit
    assert orbit_08.simulated_rms == pytest.approx(0.16671, abs=1e-5)


def test_period_2_subharmonic_at_1_41(reference_model, orbit_141: PeriodicOrbit) -> None:
    sub = orbit_141.of_period(2)
    assert len(sub) == 1
    (s,) = sub
    assert s.stable and s.source == "simulation"
    assert s.rms == pytest.approx(0.160, abs=1e-3)
    # Exact period-2 orbit by shooting from a state on the simulated attractor.
    integ = ExactIntegrator(reference_model)
    Tf = 2 * math.pi / 1.41
    x = integ.propagate(np.zeros(2), 0.0, 300 * Tf, 1.41).state1
    exact = _shoot(reference_model, 1.41, x, period=2)
    assert exact.stable
    assert s.rms == pytest.approx(exact.rms, abs=1e-4)
    assert s.p2p == pytest.approx(exact.p2p, abs=1e-4)
    assert s.mean == pytest.approx(exact.mean, abs=1e-4)
    # The unstable primary orbit is there too, after the period-2 one.
    primary = orbit_141.of_period(1)
    assert len(primary) == 1 and not primary[0].stable
    assert orbit_141.solutions[0] is s and orbit_141.selected == 0
    assert orbit_141.simulated_period == 2


def test_subharmonic_multipliers_match_shooting(reference_model, orbit_141: PeriodicOrbit) -> None:
    (s,) = orbit_141.of_period(2)
    h = orbit_141.time_history(0, samples=64)
    exact = _shoot(reference_model, 1.41, (h["delta"][0], h["velocity"][0]), period=2)
    # moduli to 1e-3: the HB orbit differs from the exact one by its truncation error
    assert np.sort(np.abs(s.multipliers)) == pytest.approx(np.sort(np.abs(exact.multipliers)), abs=1e-3)


def test_without_simulation_only_the_primary_orbits(reference_model, reference_frf) -> None:
    orbit = periodic_orbit(reference_model, 1.41, period=2, frf=reference_frf, simulate=False)
    assert orbit.simulation is None
    assert [s.period for s in orbit.solutions] == [1]
    assert orbit.selected == 0  # none stable: the first
    assert "no harmonic-balance solution of period 2" in orbit.summary()


def test_own_continuation_matches_a_given_frf(reference_model, orbit_08: PeriodicOrbit) -> None:
    orbit = periodic_orbit(reference_model, 0.8, search_range=(0.5, 1.2), simulate=False)
    assert [s.rms for s in orbit.solutions] == pytest.approx([s.rms for s in orbit_08.solutions], rel=1e-9)
    assert orbit.settings["search_range"] == [0.5, 1.2]


def test_search_range_is_widened_to_include_omega(reference_model) -> None:
    orbit = periodic_orbit(reference_model, 2.0, search_range=(0.5, 1.0), harmonics=8, simulate=False)
    assert orbit.settings["search_range"] == [0.5, 2.0]
    assert len(orbit) == 1 and orbit[0].stable
    assert default_search_range(reference_model, 10.0) == (0.1, 15.0)


# --------------------------------------------------------------------------------------------
# Result object
# --------------------------------------------------------------------------------------------
def test_time_history_and_csv(tmp_path, orbit_141: PeriodicOrbit) -> None:
    h = orbit_141.time_history(samples=32)
    assert list(h) == list(ORBIT_COLUMNS)
    assert h["t"].shape == (2 * 32 + 1,)  # the selected orbit has period 2
    assert h["t"][-1] == pytest.approx(2 * 2 * math.pi / 1.41)
    assert h["delta"][0] == pytest.approx(h["delta"][-1], abs=1e-12)  # closed orbit
    path = orbit_141.to_csv(tmp_path / "orbit.csv", samples=16)
    cols = read_csv(path)
    assert list(cols) == list(ORBIT_COLUMNS)
    assert cols["t"].size == 33
    np.testing.assert_allclose(cols["delta"], orbit_141.time_history(samples=16)["delta"], rtol=0, atol=1e-15)
    with pytest.raises(IndexError, match="`solution`"):
        orbit_141.time_history(5)
    with pytest.raises(ValueError, match="`periods`"):
        orbit_141.time_history(0, periods=0)


def test_acceleration_is_from_the_equation(reference_model, orbit_08: PeriodicOrbit) -> None:
    h = orbit_08.time_history(1, samples=128)
    rhs = reference_model.excitation(h["t"], 0.8) - reference_model.c * h["velocity"] - reference_model.restoring(h["delta"])
    np.testing.assert_allclose(h["acceleration"], rhs, atol=1e-14)


def test_simulated_history_starts_at_forcing_phase_zero(orbit_141: PeriodicOrbit) -> None:
    sim = orbit_141.simulated_history(samples=64)
    hb = orbit_141.time_history(0, samples=64)
    # the HB sub-harmonic was seeded from this simulation: same phase, same curve
    assert np.max(np.abs(sim["delta"] - hb["delta"])) < 2e-4


def test_summary_metadata_repr(orbit_08: PeriodicOrbit) -> None:
    text = orbit_08.summary()
    assert "3 harmonic-balance solution(s)" in text and "* [2]" in text
    meta = orbit_08.metadata()
    assert meta["selected"] == 2 and len(meta["solutions"]) == 3
    assert meta["simulation"]["period"] == 1
    assert "PeriodicOrbit(Ω = 0.8" in repr(orbit_08)
    assert isinstance(orbit_08[0], OrbitSolution) and "stable" in repr(orbit_08[0])
    amps = orbit_08[0].amplitudes()
    assert amps.shape == (33,) and amps[0] == pytest.approx(abs(orbit_08[0].mean))


def test_selection_rule(orbit_08: PeriodicOrbit) -> None:
    import dataclasses

    # Without a simulation: the first stable solution of the requested period.
    assert dataclasses.replace(orbit_08, simulation=None).selected == 0
    # None stable: the first.
    unstable = tuple(dataclasses.replace(s, stable=False) for s in orbit_08.solutions)
    assert dataclasses.replace(orbit_08, solutions=unstable).selected == 0
    # No solution at all.
    empty = dataclasses.replace(orbit_08, solutions=())
    assert empty.selected is None
    with pytest.raises(ValueError, match="no harmonic-balance solution"):
        empty.time_history()


# --------------------------------------------------------------------------------------------
# Helpers and validation
# --------------------------------------------------------------------------------------------
def test_least_period_and_reduce(rng) -> None:
    H = 8
    q1 = rng.normal(size=2 * H + 1)  # base Ω
    # The same motion written with base Ω/2: harmonic k of Ω is harmonic 2k of Ω/2.
    q2 = np.zeros(4 * H + 1)
    q2[0] = q1[0]
    q2[2 : 2 * H + 1 : 2] = q1[1 : H + 1]
    q2[2 * H + 2 :: 2] = q1[H + 1 :]
    assert _least_period(q2, 2) == 1
    back = _reduce(q2, 2, 1)
    np.testing.assert_array_equal(back[: H + 1], q1[: H + 1])
    np.testing.assert_array_equal(back[2 * H + 1 : 3 * H + 1], q1[H + 1 :])
    q2[1] = 1e-3  # an odd harmonic of Ω/2: a true period-2 motion
    assert _least_period(q2, 2) == 2
    assert _least_period(q1, 1) == 1


def test_shift_is_a_time_shift(rng) -> None:
    from rattle.hb import FourierBasis

    basis = FourierBasis(6, 64)
    q = rng.normal(size=13)
    t = np.linspace(0, 2 * np.pi, 17)
    np.testing.assert_allclose(basis.evaluate(_shift(q, 0.25), 1.0, t), basis.evaluate(q, 1.0, t + 0.5 * np.pi), atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"omega": 0.0}, ValueError, "`omega` must be a finite forcing frequency > 0"),
        ({"omega": float("nan")}, ValueError, "`omega`"),
        ({"omega": float("inf")}, ValueError, "`omega`"),
        ({"omega": "fast"}, TypeError, "`omega`"),
        ({"omega": 1.0, "period": 9}, ValueError, r"`period` must be an integer 1 … 8"),
        ({"omega": 1.0, "period": 0}, ValueError, "`period`"),
        ({"omega": 1.0, "period": 2.0}, TypeError, "`period`"),
        ({"omega": 1.0, "harmonics": 0}, ValueError, "`harmonics`"),
        ({"omega": 1.0, "period": 4, "harmonics": 3}, ValueError, "`harmonics` must be >= 4"),
        ({"omega": 1.0, "search_range": (2.0, 1.0)}, ValueError, "`search_range`"),
        ({"omega": 1.0, "x0": (0.0,)}, ValueError, "`x0`"),
        ({"omega": 1.0, "simulate": "yes"}, TypeError, "`simulate`"),
        ({"omega": 1.0, "frf": object()}, TypeError, "`frf`"),
    ],
)
def test_validation(reference_model, kwargs, error, match) -> None:
    with pytest.raises(error, match=match):
        periodic_orbit(reference_model, **kwargs)


def test_unknown_keyword_raises(reference_model) -> None:
    with pytest.raises(TypeError):
        periodic_orbit(reference_model, 1.0, harmonic=4)  # type: ignore[call-arg]
