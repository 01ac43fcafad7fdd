"""SI units and engine orders against the dimensionless reference case (issue 9, "Done means").

A two-inertia free clutch chain in SI whose dimensionless equivalent is the paper's reference
case (SPEC §1: K = I = 1, C = 0.05, α = 0.25, b = 10°, F_m = 0.05, F_p1 = 0.03) must give the
reference case's folds and period doublings at the rpm the scaling predicts and the same rms
(δ is an angle in rad in both forms).

Scaling: I = I1 I2 / (I1 + I2), ω_n = sqrt(K / I), C = 2ζ sqrt(K I); forces divided by ω_n²:
F_m = T_m/I1 + T_m/I2 = T_m / I = 0.05 ω_n² → T_m = 0.05 K; F_p1 = T_p1 / I1 = 0.03 ω_n² →
T_p1 = 0.03 I1 ω_n². Engine order q: Ω = q · 2π/60 · rpm, Ω = Ω̄ ω_n → rpm = Ω̄ ω_n · 60 / (2π q).
"""

import math
import tomllib

import numpy as np
import pytest
from pathlib import Path

import rattle
from rattle.io import config_from_dict
from rattle.model import base_order, engine_speed, firing_orders, forcing_frequency

I1, I2, K, ZETA, ORDER, H = 0.2, 0.05, 500.0, 0.025, 2.0, 16
I_RED = I1 * I2 / (I1 + I2)
W_N = math.sqrt(K / I_RED)
T_M = 0.05 * W_N**2 * I_RED
T_P1 = 0.03 * I1 * W_N**2


def _rpm(omega_bar):
    return omega_bar * W_N * 60.0 / (2.0 * math.pi * ORDER)


SI_CHAIN = f"""
[model]
units = "SI"
inertias = [{I1!r}, {I2!r}]

[[model.links]]
between = [1, 2]
damping = {2.0 * ZETA * math.sqrt(K * I_RED)!r}

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = {K!r}
type = "clutch"
alpha = 0.25
b_deg = 10.0

[engine]
inertia = 1
cylinders = 4
speed_rpm = [{_rpm(0.1)!r}, {_rpm(3.0)!r}]
mean_torque = {T_M!r}
orders = [{ORDER!r}]
amplitudes = [{T_P1!r}]

[[excitation.torques]]
inertia = 2
mean = {-T_M!r}

[analysis]
harmonics = {H}
"""


def test_hand_calculations_of_the_scaling():
    assert I_RED == pytest.approx(0.04, rel=1e-15)
    assert W_N == pytest.approx(math.sqrt(12500.0), rel=1e-15)
    assert T_M == pytest.approx(25.0, rel=1e-14)  # 0.05 K
    assert T_P1 == pytest.approx(75.0, rel=1e-14)  # 0.03 · 0.2 · 12500
    assert T_M / I1 + T_M / I2 == pytest.approx(0.05 * W_N**2, rel=1e-14)  # SPEC §1's F_m


def test_conversions_against_hand_calculations():
    assert math.radians(10.0) == pytest.approx(0.174533, abs=5e-7)
    # rpm ↔ Ω: order 2 at 3000 rpm is 100 Hz
    assert forcing_frequency(3000.0, 2.0) == pytest.approx(2.0 * math.pi * 100.0, rel=1e-15)
    assert engine_speed(2.0 * math.pi * 100.0, 2.0) == pytest.approx(3000.0, rel=1e-15)
    assert np.allclose(engine_speed(forcing_frequency(np.array([600.0, 800.0]), 1.5), 1.5), [600.0, 800.0], rtol=1e-15)
    # orders → base order and harmonic numbers
    assert base_order([2.0, 4.0]) == (2, (1, 2))
    assert base_order([0.5, 1.5, 2.0]) == (0.5, (1, 3, 4))
    assert base_order([1.5, 3.0, 4.5]) == (1.5, (1, 2, 3))
    assert base_order([2.0, 3.0]) == (1, (2, 3))
    with pytest.raises(ValueError, match="orders"):
        base_order([2.0, 2.0 * math.sqrt(2.0)])
    # firing orders: 4-stroke cylinders/2 · k, 2-stroke cylinders · k
    assert firing_orders(4) == (2.0, 4.0, 6.0)
    assert firing_orders(3, count=2) == (1.5, 3.0)
    assert firing_orders(6, strokes=2, count=1) == (6.0,)


def test_si_chain_is_the_reference_case_at_the_predicted_rpm():
    cfg = config_from_dict(tomllib.loads(SI_CHAIN), source_name="si.toml")
    assert cfg.model.speed_order == ORDER
    assert cfg.analysis.omega_min == pytest.approx(0.1 * W_N, rel=1e-14)
    assert cfg.analysis.omega_max == pytest.approx(3.0 * W_N, rel=1e-14)
    ref = rattle.frequency_response(rattle.reference_case(), omega=(0.1, 3.0), harmonics=H)
    si = rattle.frequency_response(cfg.model, omega=cfg.analysis.omega, harmonics=H)
    kinds_ref = [s.kind for s in ref.special_points]
    assert kinds_ref.count("fold") >= 2 and kinds_ref.count("period_doubling") >= 2
    assert [s.kind for s in si.special_points] == kinds_ref
    rpm = si.speed_rpm
    assert rpm is not None and ref.speed_rpm is None
    for a, b in zip(ref.special_points, si.special_points):
        assert b.located == a.located
        assert engine_speed(b.omega, ORDER) == pytest.approx(_rpm(a.omega), rel=1e-6), a.kind
        assert rpm[b.index] == pytest.approx(_rpm(ref.omega[a.index]), rel=1e-6), a.kind  # its row
        assert b.omega / W_N == pytest.approx(a.omega, rel=1e-6), a.kind
        assert si.rms[b.index] == pytest.approx(ref.rms[a.index], rel=1e-6)  # δ is an angle: same rms
        assert si.regime[b.index] == ref.regime[a.index]
    # the whole curve: the continuation is scale-invariant (steps in Ω/ω_n), so the SI run has
    # the same points, at the same Ω̄, with the same rms and stability (measured: rows agree to
    # 7e-9 relative, the Newton tolerance; the located special points to 1e-15)
    assert len(si) == len(ref)
    assert np.allclose(si.omega / W_N, ref.omega, rtol=1e-6, atol=0)
    assert np.allclose(si.rms, ref.rms, rtol=1e-6, atol=0)
    assert np.array_equal(si.stable, ref.stable)
    # speed_rpm column in frf.csv terms
    cols = si.columns()
    assert "speed_rpm" in cols and "speed_rpm" not in ref.columns()
    assert np.allclose(cols["speed_rpm"], si.omega * 60.0 / (2.0 * math.pi * ORDER), rtol=1e-15)


def test_an_engine_case_s_continuation_messages_give_the_speed_in_rpm():
    """The status message of an engine case's frequency response (the continuation's "last …",
    the ranges no branch covers) names crankshaft speeds in rpm, not Ω in rad/s (issue 27)."""
    import re

    from rattle.analysis import frequency_response
    from rattle.continuation import ContinuationOptions
    from rattle.io import load_config

    rc = load_config(Path(__file__).resolve().parents[1] / "examples" / "engine_clutch_si.toml")
    r = frequency_response(rc.model, rc.analysis.omega, harmonics=16, adaptive=None, throw=False,
                           continuation=ContinuationOptions(max_points=40))
    assert r.status.name == "MAX_STEPS"
    assert "Ω =" not in r.message, r.message
    last = float(re.search(r"last ([0-9.]+) rpm", r.message).group(1))
    assert last == pytest.approx(float(r.speed_rpm.max()), rel=1e-4)
    assert re.search(r"not covered by any branch: [0-9.]+ … 1500 rpm", r.message), r.message
    status = next(line for line in r.summary().splitlines() if line.startswith("status:"))
    assert "rpm" in status and "Ω =" not in status
