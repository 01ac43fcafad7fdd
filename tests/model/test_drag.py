"""Drag torque by speed ([drag], SPEC §6): the mean torques follow D(rpm) along the continuation.

Checked against independent forms: at every Ω the drag model must be exactly the constant-mean
chain whose drag is D(Ω) (harmonic-balance residual, exact flow, static equilibrium, linear
response), a constant table must reproduce the constant-mean model bit for bit, and the
Ω-derivatives the continuation and the shooting use must match finite differences.
"""

from __future__ import annotations

import math
import re
import tomllib

import numpy as np
import pytest

import rattle
from rattle.errors import ConfigError
from rattle.hb import HarmonicBalance, HBOptions
from rattle.io import config_from_dict, model_to_toml_dict
from rattle.model import Chain, Drag, Element, Link, Torque
from rattle.timeint import ExactIntegrator

BASE = """
[model]
units = "SI"
inertias = [0.15, 0.01]
[[model.links]]
between = [1, 2]
damping = 0.15
[[model.elements]]
name = "damper"
between = [1, 2]
stiffness = 1720.0
type = "clutch"
alpha = 0.05
b_deg = 4.0
[engine]
inertia = 1
speed_rpm = [600.0, 1300.0]
orders = [2.0, 4.0]
amplitudes = [60.0, 10.0]
[analysis]
harmonics = 8
"""
DRAG = "[drag]\ninertia = 2\nspeed_rpm = [600.0, 900.0, 1500.0]\ntorque = [3.0, 5.0, 8.0]\n"
RPM_PER_OMEGA = 60.0 / (2.0 * math.pi * 2.0)  # base order 2


def _config(text: str):
    return config_from_dict(tomllib.loads(text))


def _drag_chain():
    return _config(BASE + DRAG).model


def _constant_chain(drag_chain: Chain, omega: float) -> Chain:
    """The same chain with the drag frozen at its value at Ω: an ordinary pair of mean torques."""
    D = float(drag_chain.drag.at_rpm(omega * RPM_PER_OMEGA))
    torques = [*drag_chain.torques, Torque(inertia=1, mean=D), Torque(inertia=2, mean=-D)]
    return Chain(inertias=drag_chain.inertias, links=drag_chain.links, elements=drag_chain.elements,
                 torques=tuple(torques), speed_order=drag_chain.speed_order)


def test_drag_table_is_interpolated_linearly_and_constant_outside() -> None:
    d = Drag(inertia=2, speed_rpm=(600.0, 900.0, 1500.0), torque=(3.0, 5.0, 8.0), balance=1)
    assert d.at_rpm(750.0) == pytest.approx(4.0, rel=1e-15)
    assert d.at_rpm(1200.0) == pytest.approx(6.5, rel=1e-15)
    assert d.at_rpm(100.0) == 3.0 and d.at_rpm(5000.0) == 8.0
    load = _drag_chain().system().load
    assert load.nodes == pytest.approx(np.array([600.0, 900.0, 1500.0]) / RPM_PER_OMEGA, rel=1e-15)
    w = 750.0 / RPM_PER_OMEGA
    assert load.slope(w) == pytest.approx(2.0 / 300.0 * RPM_PER_OMEGA, rel=1e-12)
    assert load.slope(10.0) == 0.0 and load.slope(1e4) == 0.0
    # u = D M⁻¹ (e_1 − e_2) for the relative coordinate θ1 − θ2: 1/I1 + 1/I2
    assert load.direction == pytest.approx([1 / 0.15 + 1 / 0.01], rel=1e-15)


@pytest.mark.parametrize("rpm", [650.0, 900.0, 1234.5])
def test_at_each_speed_the_drag_model_is_the_constant_mean_chain(rpm: float) -> None:
    chain = _drag_chain()
    w = rpm / RPM_PER_OMEGA
    const = _constant_chain(chain, w)
    s, c = chain.system(), const.system()
    assert np.array_equal(s.mean_at(w), c.mean) or s.mean_at(w) == pytest.approx(c.mean, rel=1e-15)
    assert s.static_equilibrium(w) == pytest.approx(c.static_equilibrium(), rel=1e-13)
    # the harmonic-balance residual and Jacobian at Ω
    hb, hc = HarmonicBalance(chain, HBOptions(harmonics=8)), HarmonicBalance(const, HBOptions(harmonics=8))
    q = np.random.default_rng(3).normal(size=hb.size) * 0.02
    Rs, Jqs, _ = hb.residual_jacobian(q, w)
    Rc, Jqc, _ = hc.residual_jacobian(q, w)
    assert np.max(np.abs(Rs - Rc)) <= 1e-12 * np.max(np.abs(Rc))
    assert np.array_equal(Jqs, Jqc)
    assert np.max(np.abs(hb.residual(q, w) - Rc)) <= 1e-12 * np.max(np.abs(Rc))
    # the exact flow over two forcing periods from the same state
    z0 = np.array([0.01, 3.0])
    T = 2 * (2 * math.pi / w)
    ts = ExactIntegrator(s).propagate(z0, 0.0, T, w)
    tc = ExactIntegrator(c).propagate(z0, 0.0, T, w)
    assert ts.state1 == pytest.approx(tc.state1, rel=1e-10, abs=1e-13)
    # the linear response's mean
    lin_s = rattle.linear_frequency_response(chain, np.array([w]))
    lin_c = rattle.linear_frequency_response(const, np.array([w]))
    assert lin_s.mean == pytest.approx(lin_c.mean, rel=1e-13)


def test_a_constant_drag_table_reproduces_the_constant_mean_model_bit_for_bit() -> None:
    with_drag = _config(BASE + "[drag]\ninertia = 2\nspeed_rpm = [1000.0]\ntorque = [5.0]\n").model
    plain = _config(BASE + "[[excitation.torques]]\ninertia = 1\nmean = 5.0\n[[excitation.torques]]\n"
                    "inertia = 2\nmean = -5.0\n").model
    omega = (700.0 / RPM_PER_OMEGA, 1000.0 / RPM_PER_OMEGA)
    a = rattle.frequency_response(with_drag, omega=omega, harmonics=8)
    b = rattle.frequency_response(plain, omega=omega, harmonics=8)
    assert np.array_equal(a.omega, b.omega) and np.array_equal(a.rms, b.rms)
    assert [(p.kind, p.omega) for p in a.special_points] == [(p.kind, p.omega) for p in b.special_points]


@pytest.mark.parametrize("rpm", [700.0, 900.0, 1100.0, 2000.0])
def test_hb_omega_derivative_matches_finite_differences(rpm: float) -> None:
    hb = HarmonicBalance(_drag_chain(), HBOptions(harmonics=8))
    q = np.random.default_rng(5).normal(size=hb.size) * 0.02
    w = rpm / RPM_PER_OMEGA + (1e-3 if rpm == 900.0 else 0.0)  # just right of a node
    _, _, Rw = hb.residual_jacobian(q, w)
    h = 1e-7 * w
    fd = (hb.residual(q, w + h) - hb.residual(q, w - h)) / (2 * h)
    assert np.max(np.abs(fd - Rw)) <= 1e-7 * np.max(np.abs(Rw))
    assert Rw[0] != HarmonicBalance(_constant_chain(_drag_chain(), w), HBOptions(harmonics=8)).residual_jacobian(q, w)[2][0] \
        or rpm == 2000.0  # the drag's slope is in it (none beyond the table)


def test_exact_flow_omega_derivative_carries_the_drag_slope() -> None:
    system = _drag_chain().system()
    integ = ExactIntegrator(system)
    w, z0 = 750.0 / RPM_PER_OMEGA, np.array([0.02, 1.0])
    T = 2 * math.pi / w * 1.5
    s = integ.propagate(z0, 0.0, T, w).omega_derivative(fixed="time")
    h = 1e-6 * w
    fd = (integ.propagate(z0, 0.0, T, w + h).state1 - integ.propagate(z0, 0.0, T, w - h).state1) / (2 * h)
    assert s == pytest.approx(fd, rel=1e-5, abs=1e-9 * np.max(np.abs(fd)))


def test_hb_with_drag_agrees_with_exact_shooting() -> None:
    """Stable periodic solutions of the continuation against Newton shooting on the exact flow at
    the same Ω (the drag D(Ω) at each): rms within the H = 24 truncation of this clutch (measured
    3.4e-6 relative at H = 24, 3.7e-7 at H = 48: the error is the truncation's, it falls with H)."""
    chain = _drag_chain()
    frf = rattle.frequency_response(chain, omega=(650.0 / RPM_PER_OMEGA, 1000.0 / RPM_PER_OMEGA), harmonics=24)
    picks = np.flatnonzero(frf.stable)[:: max(1, int(np.sum(frf.stable)) // 4)]
    assert picks.size >= 3
    system = chain.system()
    for i in picks:
        w = float(frf.omega[i])
        hb = HarmonicBalance(chain, HBOptions(harmonics=24))
        x = hb.coordinate_samples(frf.coefficients[i])[:, 0]
        v = np.array([np.sum(frf.coefficients[i][25:] * np.arange(1, 25)) * w])  # x'(0) = Σ k ω b_k
        orbit = rattle.timeint.shoot_system_orbit(system, w, np.concatenate((x, v)))
        assert orbit.converged
        exact = float(orbit.measures.rms[0])
        assert abs(frf.rms[i] - exact) <= 2e-5 * exact, (w, frf.rms[i], exact)
        assert orbit.stable


def test_free_chain_drag_is_delivered_by_the_engine() -> None:
    chain = _drag_chain()
    assert chain.drag.balance == 1  # [engine] inertia = 1
    # T_m(Ω) = D e_1 − D e_2: balanced at every speed
    with pytest.raises(ValueError, match="`drag.balance` is missing"):
        Chain(inertias=(1.0, 1.0), links=(Link(between=(1, 2), damping=0.1),),
              elements=(Element(name="e", between=(1, 2), stiffness=1.0, law=rattle.Backlash(b=0.1)),),
              speed_order=2.0, drag=Drag(inertia=2, speed_rpm=(100.0,), torque=(1.0,)))
    with pytest.raises(ValueError, match="speed_order"):
        Chain(inertias=(1.0, 1.0), links=(Link(between=(1, 0), stiffness=1.0, damping=0.1),),
              elements=(Element(name="e", between=(1, 2), stiffness=1.0, law=rattle.Backlash(b=0.1)),),
              drag=Drag(inertia=2, speed_rpm=(100.0,), torque=(1.0,)))


def test_round_trip_keeps_the_drag() -> None:
    cfg = _config(BASE + DRAG)
    chain = cfg.model
    again = config_from_dict(model_to_toml_dict(chain, cfg.analysis)).model
    assert again.drag == chain.drag and again.speed_order == chain.speed_order
    assert np.array_equal(again.system().load.nodes, chain.system().load.nodes)


@pytest.mark.parametrize("table, key", [
    ("[drag]\ninertia = 2\nspeed_rpm = [600.0, 500.0]\ntorque = [1.0, 2.0]\n", "drag.speed_rpm"),
    ("[drag]\ninertia = 2\nspeed_rpm = [600.0, 600.0]\ntorque = [1.0, 2.0]\n", "drag.speed_rpm"),
    ("[drag]\ninertia = 2\nspeed_rpm = [600.0, 900.0]\ntorque = [1.0]\n", "drag.torque"),
    ("[drag]\ninertia = 2\nspeed_rpm = [600.0]\ntorque = [-1.0]\n", "drag.torque.1"),
    ("[drag]\ninertia = 3\nspeed_rpm = [600.0]\ntorque = [1.0]\n", "drag.inertia"),
    ("[drag]\ninertia = 2\nspeed_rpm = [600.0]\ntorque = [1.0]\nbalance = 2\n", "drag.balance"),
    ("[drag]\ninertia = 2\nspeed_rpm = [0.0]\ntorque = [1.0]\n", "drag.speed_rpm.1"),
    ("[drag]\ninertia = 2\nspeed = [600.0]\ntorque = [1.0]\n", "drag"),
])
def test_bad_drag_tables_are_refused_naming_the_key(table: str, key: str) -> None:
    with pytest.raises(ConfigError, match=re.escape(f"`{key}")):
        _config(BASE + table)


def test_drag_needs_an_engine_order_and_a_chain() -> None:
    no_engine = BASE.replace("[engine]\ninertia = 1\nspeed_rpm = [600.0, 1300.0]\norders = [2.0, 4.0]\n"
                             "amplitudes = [60.0, 10.0]\n",
                             "[[excitation.torques]]\ninertia = 1\namplitudes = [60.0]\n")
    no_engine = no_engine.replace("harmonics = 8\n", "harmonics = 8\nomega = [100.0, 200.0]\n")
    _config(no_engine)  # valid without the drag
    with pytest.raises(ConfigError, match="`drag` is tabulated over the crankshaft speed"):
        _config(no_engine + DRAG)
    single = ('[model]\ninertia = 1.0\ndamping = 0.05\nstiffness = 1.0\n[model.elastic]\ntype = "backlash"\nb = 0.1\n'
              '[excitation]\nmean = 0.0\namplitudes = [0.1]\n' + DRAG)
    with pytest.raises(ConfigError, match="`drag` needs a chain of inertias"):
        _config(single)


@pytest.mark.parametrize("command", [["frf"], ["sweep", "--direction", "up"], ["compare"],
                                     ["map", "--vary", "alpha=0.05,0.1"]])
def test_cli_refuses_an_unsorted_drag_table_with_exit_2_writing_nothing(tmp_path, command) -> None:
    from click.testing import CliRunner

    from rattle.cli.main import cli

    case = tmp_path / "case.toml"
    case.write_text(BASE + "[drag]\ninertia = 2\nspeed_rpm = [900.0, 600.0]\ntorque = [1.0, 2.0]\n", encoding="utf-8")
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, [command[0], str(case), *command[1:], "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert "drag.speed_rpm" in result.output + str(getattr(result, "stderr", ""))
    assert not out.exists()


def _random_drag_chain(seed: int, free: bool) -> Chain:
    """A random three-inertia chain with two clearance elements and a three-point drag table on
    inertia 3; free chains get the drag delivered by inertia 1 (the engine), grounded ones hold it."""
    rng = np.random.default_rng(seed)
    inertias = tuple(rng.uniform(0.5, 1.5, 3))
    links = [Link(between=(1, 2), damping=rng.uniform(0.03, 0.06)), Link(between=(2, 3), damping=rng.uniform(0.03, 0.06))]
    if not free:
        links.append(Link(between=(1, 0), stiffness=rng.uniform(0.2, 0.4), damping=rng.uniform(0.02, 0.04)))
    elements = (Element(name="e1", between=(1, 2), stiffness=rng.uniform(1.0, 2.0),
                        law=rattle.Clutch(alpha=rng.uniform(0.2, 0.4), b=rng.uniform(0.1, 0.2))),
                Element(name="e2", between=(2, 3), stiffness=rng.uniform(1.0, 2.0), law=rattle.Backlash(b=rng.uniform(0.05, 0.1))))
    d = rng.uniform(0.02, 0.05, 3).cumsum()
    drag = Drag(inertia=3, speed_rpm=(10.0, 20.0, 30.0), torque=tuple(d), balance=1 if free else None)
    torques = (Torque(inertia=1, amplitudes=(rng.uniform(0.03, 0.06),)),)
    return Chain(inertias=inertias, links=tuple(links), elements=elements, torques=torques,
                 speed_order=60.0 / (2.0 * math.pi * 20.0), drag=drag)  # rpm = 20 Ω: the table spans Ω 0.5 … 1.5


@pytest.mark.slow
@pytest.mark.parametrize("seed, free", [(1, True), (2, False), (3, True)])
def test_random_chains_with_drag_agree_with_exact_shooting(seed: int, free: bool) -> None:
    """Random three-inertia chains whose drag changes along the branch: every 4th stable point of the
    continuation is an orbit of the exact flow with the drag of its Ω (Newton shooting from the HB
    state: same orbit, element rms within the H = 24 truncation — measured 8.0e-6, 4.9e-7, 1.2e-5
    relative on seeds 1, 2, 3 — and the same stability)."""
    from rattle.timeint import shoot_system_orbit

    chain = _random_drag_chain(seed, free)
    system = chain.system()
    assert system.load is not None and np.any(system.load.direction)
    frf = rattle.frequency_response(chain, omega=(0.6, 1.4), harmonics=24, confirm_tori=False)
    n, S = system.n, 2 * 24 + 1
    checked = 0
    for i in np.flatnonzero(frf.stable)[::4][:8]:
        w = float(frf.omega[i])
        Q = frf.coefficients[i].reshape(n, S)
        z0 = np.concatenate((Q[:, 0] + Q[:, 1:25].sum(axis=1), (Q[:, 25:] * np.arange(1, 25)).sum(axis=1) * w))
        orbit = shoot_system_orbit(system, w, z0)
        assert orbit.converged
        assert np.max(np.abs(orbit.state0 - z0)) <= 1e-2 * chain.length_scale()
        for name in chain.element_names:
            assert frf.element(name)["rms"][i] == pytest.approx(orbit.measures.element(name)["rms"], rel=1e-4), (name, w)
        assert orbit.stable
        checked += 1
    assert checked >= 4
