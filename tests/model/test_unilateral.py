"""Unilateral contact: a stop on one side of a gap, nothing on the other (SPEC §8).

The law is continuous and piecewise linear (slopes (0, 1) or (1, 0)), so the exact flow is the
reference: the harmonic balance at default settings agrees with exact shooting from its own
state, on the single equation and on a chain (NLvib's two-DOF unilateral-spring example written
as a rattle chain). A model is refused, naming the rule, only where it has no static equilibrium
(the mean load pushes the element away from the stop) or none that is isolated (no mean load on
the free side).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rattle
from rattle.model import Chain, Element, Excitation, Link, Model, Piecewise, Torque, Unilateral
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit, shoot_system_orbit

from _cases import hb_chain_state0, hb_state0  # tests/ is on sys.path through its conftest


@pytest.mark.parametrize("side, gap", [("positive", 0.1), ("negative", 0.1), ("positive", 0.0)])
def test_the_law_is_the_one_sided_piecewise_law(side, gap):
    law = Unilateral(gap=gap, side=side)
    ref = Piecewise(breakpoints=(gap,), slopes=(0.0, 1.0)) if side == "positive" else \
        Piecewise(breakpoints=(-gap,), slopes=(1.0, 0.0))
    x = np.linspace(-0.5, 0.5, 101)
    np.testing.assert_allclose(law.force(x), ref.force(x), atol=1e-15)
    sign = 1.0 if side == "positive" else -1.0
    np.testing.assert_allclose(law.force(x), np.where(sign * x > gap, x - sign * gap, 0.0), atol=1e-15)
    assert law.force(0.0) == 0.0
    assert law.to_dict() == {"type": "unilateral", "gap": gap, "side": side}


@pytest.mark.parametrize("side, mean, match", [
    ("positive", -0.05, r"`excitation.mean` = -0.05: no static equilibrium"),
    ("negative", 0.05, r"`excitation.mean` = 0.05: no static equilibrium"),
    ("positive", 0.0, r"`excitation.mean` = 0: the law is flat .* the mean of the motion is not determined"),
])
def test_a_model_without_an_isolated_equilibrium_is_refused(side, mean, match):
    with pytest.raises(ValueError, match=match):
        Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Unilateral(gap=0.05, side=side),
              excitation=Excitation(mean=mean, amplitudes=(0.03,)))


def _toml(tmp_path, elastic: str, mean: float) -> str:
    path = tmp_path / "case.toml"
    path.write_text(f"[model]\ninertia = 1.0\ndamping = 0.05\nstiffness = 1.0\n\n[model.elastic]\n{elastic}\n\n"
                    f"[excitation]\nmean = {mean}\namplitudes = [0.03]\n")
    return str(path)


def test_the_configuration_takes_gap_in_degrees_and_the_side(tmp_path):
    model = Model.from_toml(_toml(tmp_path, 'type = "unilateral"\ngap_deg = 2.0\nside = "negative"', -0.05))
    assert model.elastic == Unilateral(gap=math.radians(2.0), side="negative")
    model = Model.from_toml(_toml(tmp_path, 'type = "unilateral"\ngap = 0.01', 0.05))
    assert model.elastic == Unilateral(gap=0.01, side="positive")


@pytest.mark.parametrize("elastic, mean, words", [
    ('type = "unilateral"\ngap = 0.01\nside = "left"', 0.05, ["`model.elastic.side` must be \"positive\" or \"negative\""]),
    ('type = "unilateral"\ngap = 0.01\nside = 1', 0.05, ["`model.elastic.side` must be a string"]),
    ('type = "unilateral"\ngap = -0.01', 0.05, ["`model.elastic.gap` must be >= 0"]),
    ('type = "unilateral"\ngap = 0.01', -0.05, ["`excitation.mean` = -0.05: no static equilibrium"]),
])
def test_the_configuration_refuses_naming_the_key(tmp_path, elastic, mean, words):
    with pytest.raises(rattle.ConfigError) as info:
        Model.from_toml(_toml(tmp_path, elastic, mean))
    for word in words:
        assert word in str(info.value)


@pytest.mark.slow
def test_the_single_equation_agrees_with_exact_shooting():
    """A stop 2° beyond the rest position, the mean load pressing toward it, the forcing strong
    enough to lift off and hit: the frequency response covers the range and every sampled row's
    rms is within 0.1 % of the exact orbit through its own state.

    H = 64: on the large-excursion branch near its fold (Ω ≈ 0.227, rms 2.4 rad, a brief hard
    contact per period) H = 32 is 0.28–0.36 % off the exact rms and needs 6,530 points; H = 64 is
    within 1.0e-4 with 2,255 (measured). Raising H where the truncation error demands it is the
    automatic-harmonics item of the attractor issue."""
    model = Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Unilateral(gap=math.radians(2.0)),
                  excitation=Excitation(mean=0.05, amplitudes=(0.03,)))
    frf = rattle.frequency_response(model, omega=(0.2, 3.0), harmonics=64)
    assert frf.status.name == "SUCCESS"
    assert {"single_sided", "no_impact"} <= set(frf.regime.tolist())  # it lifts off the stop somewhere
    integ = ExactIntegrator(model)
    rows = np.flatnonzero(frf.stable & (frf.period == 1))
    checked = 0
    for i in rows[:: max(1, rows.size // 25)]:
        orbit = shoot_periodic_orbit(model, frf.omega[i], hb_state0(frf, i), integrator=integ)
        assert orbit.converged
        assert abs(frf.rms[i] - orbit.rms) <= 1e-3 * orbit.rms, (frf.omega[i], frf.rms[i], orbit.rms)
        assert orbit.stable
        checked += 1
    assert checked >= 20


def _two_dof() -> Chain:
    """NLvib's two-DOF oscillator with a unilateral spring (gap 1) at the first mass, as a chain:
    masses 1, springs 1 to ground and between the masses, light damping, forcing on mass 1."""
    return Chain(
        inertias=(1.0, 1.0),
        links=(Link(between=(1, 0), stiffness=1.0, damping=0.02), Link(between=(1, 2), stiffness=1.0, damping=0.02)),
        elements=(Element(name="stop", between=(1, 0), stiffness=1.0, law=Unilateral(gap=0.1)),),
        torques=(Torque(inertia=1, mean=0.0, amplitudes=(0.1,), phases=(0.0,)),),
    )


def test_a_chain_with_a_unilateral_stop_agrees_with_exact_shooting():
    """Both doors of the exact check on every sampled stable row: the stop's rms within 0.1 % and
    the same stability; the stop is hit on some of them."""
    chain = _two_dof()
    frf = rattle.frequency_response(chain, omega=(0.9, 2.0))
    assert frf.status.name == "SUCCESS"
    system = chain.system()
    special = np.array([s.omega for s in frf.special_points])
    rows = np.flatnonzero(frf.period == 1)
    impacting = checked = 0
    for i in rows[:: max(1, rows.size // 16)]:
        w = float(frf.omega[i])
        if special.size and np.min(np.abs(special - w)) < 5e-3:
            continue
        orbit = shoot_system_orbit(system, w, hb_chain_state0(frf, i))
        assert orbit.converged
        exact = orbit.measures.element("stop")["rms"]
        assert frf.element("stop")["rms"][i] == pytest.approx(exact, rel=1e-3), w
        assert bool(frf.stable[i]) == orbit.stable, w
        impacting += bool(orbit.crossed("stop").size)
        checked += 1
    assert checked >= 10 and impacting >= 1
