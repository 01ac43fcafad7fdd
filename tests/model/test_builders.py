"""Sub-system builders (rattle.model._builders): each against a hand calculation or an independent
computation in the physical coordinates (gear angles, line of action)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import rattle
from rattle.model import (
    Backlash,
    Link,
    Piecewise,
    Torque,
    clutch_damper,
    gear_pair,
    hub_spline,
    loose_gear,
)
from rattle.timeint import ExactIntegrator


# --------------------------------------------------------------------------------------------
# Clutch damper
# --------------------------------------------------------------------------------------------
def _damper_torque_by_hand(delta: float) -> float:
    """The data sheet of the test damper read directly: drive 10, 100, 1000 N m/rad ending at 0.05,
    0.15 rad; coast 20, 200 N m/rad ending at 0.03 rad; free play 0.02 rad (±0.01)."""
    if delta >= 0:
        stages = [(0.01, 0.05, 10.0), (0.05, 0.15, 100.0), (0.15, math.inf, 1000.0)]
        return sum(k * max(0.0, min(delta, hi) - lo) for lo, hi, k in stages)
    stages = [(0.01, 0.03, 20.0), (0.03, math.inf, 200.0)]
    return -sum(k * max(0.0, min(-delta, hi) - lo) for lo, hi, k in stages)


def test_damper_breakpoints_and_slopes_by_hand():
    e = clutch_damper(drive_stiffness=[10.0, 100.0, 1000.0], drive_angles=[0.05, 0.15],
                      coast_stiffness=[20.0, 200.0], coast_angles=[0.03], free_play=0.02, name="cd",
                      between=(1, 2))
    assert e.name == "cd" and e.between == (1, 2)
    assert e.stiffness == 1000.0  # the stiffest stage has slope 1
    assert isinstance(e.law, Piecewise)
    assert e.law.breakpoints == pytest.approx((-0.03, -0.01, 0.01, 0.05, 0.15), abs=1e-15)
    assert e.law.slopes == pytest.approx((0.2, 0.02, 0.0, 0.01, 0.1, 1.0), rel=1e-15)
    # the torque at a few angles: 60.4 N m at 0.2 rad = 10·0.04 + 100·0.1 + 1000·0.05; −4.4 at −0.05
    assert e.stiffness * float(e.law.force(0.2)) == pytest.approx(60.4, rel=1e-13)
    assert e.stiffness * float(e.law.force(-0.05)) == pytest.approx(-4.4, rel=1e-13)
    for d in np.linspace(-0.3, 0.3, 61):
        assert e.stiffness * float(e.law.force(d)) == pytest.approx(_damper_torque_by_hand(d), abs=1e-12)
    assert float(e.law.force(0.0)) == 0.0


def test_damper_without_free_play():
    # different first stages: a breakpoint at 0
    e = clutch_damper(drive_stiffness=[50.0, 500.0], drive_angles=[0.1], coast_stiffness=[25.0, 400.0],
                      coast_angles=[0.05])
    assert e.stiffness == 500.0
    assert e.law.breakpoints == pytest.approx((-0.05, 0.0, 0.1))
    assert e.law.slopes == pytest.approx((0.8, 0.05, 0.1, 1.0))
    assert e.stiffness * float(e.law.force(0.2)) == pytest.approx(50 * 0.1 + 500 * 0.1)
    assert e.stiffness * float(e.law.force(-0.1)) == pytest.approx(-(25 * 0.05 + 400 * 0.05))
    # equal first stages: one stage across zero (no breakpoint, so no "impact" at δ = 0)
    e = clutch_damper(drive_stiffness=[50.0, 500.0], drive_angles=[0.1], coast_stiffness=[50.0, 400.0],
                      coast_angles=[0.05])
    assert e.law.breakpoints == pytest.approx((-0.05, 0.1))
    assert e.law.slopes == pytest.approx((0.8, 0.1, 1.0))
    # one stage each side, with the reference clutch as a special case: Clutch(α, b) ≡ damper
    ref = rattle.Clutch(alpha=0.25, b=0.2)
    e = clutch_damper(drive_stiffness=[0.25, 1.0], drive_angles=[0.2], coast_stiffness=[0.25, 1.0],
                      coast_angles=[0.2])
    d = np.linspace(-1, 1, 401)
    np.testing.assert_allclose(e.stiffness * e.law.force(d), ref.force(d), atol=1e-15)


@pytest.mark.parametrize("kwargs, match", [
    ({"drive_angles": [0.05]}, r"`drive_angles` must have one entry fewer than `drive_stiffness`"),
    ({"drive_angles": [0.15, 0.05]}, r"`drive_angles` must be strictly increasing"),
    ({"drive_stiffness": [10.0, -1.0, 1000.0]}, r"`drive_stiffness\[1\]` must be > 0"),
    ({"coast_stiffness": [0.0, 200.0]}, r"`coast_stiffness\[0\]` must be > 0"),
    ({"coast_angles": [-0.03]}, r"`coast_angles\[0\]` must be > 0"),
    ({"free_play": 0.08}, r"`coast_angles\[0\]` must be > free_play/2"),
    ({"free_play": -0.01}, r"`free_play` must be >= 0"),
    ({"free_play": 5e-324}, r"`free_play` must be 0 \(none\) or at least 1e-12 rad"),
    ({"coast_stiffness": []}, r"`coast_stiffness` must hold at least one"),
])
def test_damper_refusals(kwargs, match):
    base = {"drive_stiffness": [10.0, 100.0, 1000.0], "drive_angles": [0.05, 0.15], "coast_stiffness": [20.0, 200.0],
                "coast_angles": [0.03]}
    with pytest.raises(ValueError, match=match):
        clutch_damper(**{**base, **kwargs})


_stage = st.floats(min_value=1.0, max_value=1e4)
_gap = st.floats(min_value=1e-3, max_value=0.1)


@settings(max_examples=60, deadline=None)
@given(kd=st.lists(_stage, min_size=1, max_size=4), kc=st.lists(_stage, min_size=1, max_size=4),
       gd=st.lists(_gap, min_size=3, max_size=3), gc=st.lists(_gap, min_size=3, max_size=3),
       play=st.one_of(st.just(0.0), st.floats(min_value=1e-12, max_value=0.05)))
def test_damper_law_invariants(kd, kc, gd, gc, play):
    """Any data sheet gives a continuous law with f(0) = 0, the torque of the stages by hand, and
    zero torque inside the free play."""
    ad = list(np.cumsum(gd[: len(kd) - 1]) + play / 2)
    ac = list(np.cumsum(gc[: len(kc) - 1]) + play / 2)
    e = clutch_damper(drive_stiffness=kd, drive_angles=ad, coast_stiffness=kc, coast_angles=ac, free_play=play)
    assert float(e.law.force(0.0)) == 0.0
    assert max(e.law.slopes) == 1.0 and min(e.law.slopes) >= 0.0

    def by_hand(d):
        k, a = (kd, ad) if d >= 0 else (kc, ac)
        edges = [play / 2, *a, math.inf]
        return math.copysign(sum(kj * max(0.0, min(abs(d), edges[j + 1]) - edges[j]) for j, kj in enumerate(k)), d)

    for d in np.linspace(-0.5, 0.5, 41):
        # absolute tolerance: round-off of the stage offsets, relative to the largest torque
        assert e.stiffness * float(e.law.force(d)) == pytest.approx(by_hand(d), abs=1e-9 * e.stiffness)
    for bp in e.law.breakpoints:  # continuous across every breakpoint
        lo, hi = float(e.law.force(np.nextafter(bp, -1.0))), float(e.law.force(bp))
        assert abs(hi - lo) <= 1e-12
    if play > 0:
        assert float(e.law.force(play / 2 * 0.999)) == 0.0 and float(e.law.force(-play / 2 * 0.999)) == 0.0


def test_hub_spline():
    e = hub_spline(backlash=math.radians(1.0), stiffness=8000.0, name="spline", between=(2, 3))
    assert isinstance(e.law, Backlash) and e.law.b == pytest.approx(math.radians(0.5))
    assert e.stiffness == 8000.0 and e.between == (2, 3)
    # engaged: 8000 N m/rad beyond the half play
    assert e.stiffness * float(e.law.force(math.radians(1.5))) == pytest.approx(8000.0 * math.radians(1.0))
    with pytest.raises(ValueError, match="`backlash` must be > 0"):
        hub_spline(backlash=0.0, stiffness=1.0)
    with pytest.raises(ValueError, match="`stiffness` must be > 0"):
        hub_spline(backlash=0.01, stiffness=-1.0)


# --------------------------------------------------------------------------------------------
# Gear pair: against the line-of-action equations in gear angles
# --------------------------------------------------------------------------------------------
R1, R2, J1, J2, KM, ZETA, BLOS = 0.03, 0.04, 5e-3, 6e-3, 2.0e8, 0.05, 60e-6


def _pair(**kw):
    return gear_pair(base_radii=[R1, R2], inertias=[J1, J2], mesh_stiffness=KM, mesh_damping_ratio=ZETA,
                     backlash=BLOS, **kw)


def test_gear_pair_reduction_numbers():
    g = _pair()
    assert g.ratio == pytest.approx(0.75)
    assert g.reflected_inertia == pytest.approx(J2 * 0.75**2)
    assert g.stiffness == pytest.approx(KM * R1**2)  # 1.8e5 N m/rad
    assert g.half_gap == pytest.approx(BLOS / (2 * R1))  # 1e-3 rad
    assert g.chain.free and g.chain.inertias == pytest.approx((J1, J2 * 0.5625))
    assert g.to_gear2(2.0) == pytest.approx(1.5) and g.line_of_action(1e-3) == pytest.approx(3e-5)


def test_gear_pair_linear_frequency_and_damping_in_line_of_action_coordinates():
    """The mesh mode computed in gear angles (M θ'' + K_θ θ = 0, K_θ = k_m [r1, −r2]ᵀ[r1, −r2]) has
    the frequency of the built chain, and the chain's mode the damping ratio ζ_m of the mode
    m_eq s'' + c_m s' + k_m s = 0 along the line of action."""
    g = _pair()
    M = np.diag([J1, J2])
    u = np.array([R1, -R2])
    lam = np.linalg.eigvals(np.linalg.solve(M, KM * np.outer(u, u)))
    w_direct = math.sqrt(max(lam.real))
    assert g.chain.natural_frequency == pytest.approx(w_direct, rel=1e-12)
    # the reduced chain: x'' + D x' + (b aᵀ) x = 0 (one relative coordinate)
    sysm = g.chain.system()
    B = sum(np.outer(e.b, e.a) for e in sysm.elements)
    A = np.block([[np.zeros((1, 1)), np.eye(1)], [-B, -sysm.damping]])
    ev = np.linalg.eigvals(A)
    zeta = -ev[0].real / abs(ev[0])
    assert zeta == pytest.approx(ZETA, rel=1e-12)
    assert abs(ev[0]) == pytest.approx(w_direct, rel=1e-12)


def _gear_angles_rhs(T1m, T1p, T2m, omega):
    """The two gears in their own angles: J1 θ1'' + r1 F = T1, J2 θ2'' − r2 F = T2, F = k_m g(s) + c_m s'."""
    m_eq = 1.0 / (R1**2 / J1 + R2**2 / J2)
    cm = 2 * ZETA * math.sqrt(KM * m_eq)
    half = BLOS / 2

    def rhs(t, y):
        th1, th2, w1, w2 = y
        s = R1 * th1 - R2 * th2
        sd = R1 * w1 - R2 * w2
        g = s - half if s > half else (s + half if s < -half else 0.0)
        F = KM * g + cm * sd
        return [w1, w2, (T1m + T1p * math.cos(omega * t) - R1 * F) / J1, (T2m + R2 * F) / J2]

    return rhs


def test_gear_pair_time_domain_equals_gear_angles():
    """An impacting motion of the built chain (exact integrator) equals the one of the two gears
    integrated in their own angles (scipy), mapped with s = r1 δ."""
    T1m, T1p = 30.0, 70.0
    T2m = -T1m * R2 / R1  # the gear-2 load in N m on gear 2's shaft, balancing
    g = _pair(torques=[Torque(inertia=1, mean=T1m, amplitudes=[T1p]), Torque(inertia=2, mean=T2m)])
    assert sum(t.mean for t in g.chain.torques) == pytest.approx(0.0, abs=1e-12)
    omega = 0.8 * g.chain.natural_frequency
    t1 = 6 * 2 * math.pi / omega
    delta0 = g.half_gap + 2e-4  # start in contact on the drive flank, at rest
    y0 = [delta0, 0.0, 0.0, 0.0]  # θ1 = δ0, θ2 = 0 (s = r1 δ0)
    sol = solve_ivp(_gear_angles_rhs(T1m, T1p, T2m, omega), (0.0, t1), y0, method="DOP853", rtol=1e-11,
                    atol=1e-14, max_step=t1 / 4000, dense_output=True)
    integ = ExactIntegrator(g.chain.system())
    z = np.array([delta0, 0.0])
    seen = set()
    for t in np.linspace(0.0, t1, 13)[1:]:
        z_prev_t = t - t1 / 12
        z, _ = integ.advance(z, z_prev_t, t, omega, sensitivity=False)
        th1, th2, w1, w2 = sol.sol(t)
        s, sd = R1 * th1 - R2 * th2, R1 * w1 - R2 * w2
        # abs: the two integrations agree to 5e-15 m and 5e-11 m/s (measured; scipy's DOP853 at
        # rtol 1e-11 with small steps across the impacts); 1e-12 m against the 60 µm gap
        assert g.line_of_action(z[0]) == pytest.approx(s, abs=1e-12)
        assert g.line_of_action(z[1]) == pytest.approx(sd, abs=1e-8)
        seen.add("drive" if s > BLOS / 2 else ("coast" if s < -BLOS / 2 else "free"))
    assert "free" in seen  # the motion did lose contact: the backlash was exercised


# --------------------------------------------------------------------------------------------
# Loose gear: against the gear's own equation with the imposed driving motion
# --------------------------------------------------------------------------------------------
def test_loose_gear_equals_imposed_motion():
    J, TD, A, omega, V = 2e-4, 0.05, 1500.0, 600.0, 150.0
    lg = loose_gear(base_radii=[R1, R2], inertia=J, mesh_stiffness=KM, mesh_damping_ratio=ZETA, backlash=BLOS,
                    drive_acceleration=[A], drag_torque=TD)
    assert not lg.chain.free and lg.chain.inertias == (J,)
    assert lg.stiffness == pytest.approx(KM * R2**2) and lg.half_gap == pytest.approx(BLOS / (2 * R2))
    assert lg.chain.natural_frequency == pytest.approx(math.sqrt(KM * R2**2 / J), rel=1e-12)
    cm = 2 * ZETA * math.sqrt(KM * J / R2**2)  # mesh damping of a gear against an imposed motion: m_eq = J/r2²
    half = BLOS / 2

    def th1(t):  # θ1'' = A cos Ωt, mean speed V
        return V * t - A / omega**2 * math.cos(omega * t), V + A / omega * math.sin(omega * t)

    def rhs(t, y):
        th2, w2 = y
        a1, v1 = th1(t)
        s, sd = R1 * a1 - R2 * th2, R1 * v1 - R2 * w2
        gs = s - half if s > half else (s + half if s < -half else 0.0)
        return [w2, (R2 * (KM * gs + cm * sd) - TD) / J]

    # start at rest relative to gear 1, in contact: δ0 = b + static deflection
    delta0 = lg.half_gap + TD / lg.stiffness
    a10, v10 = th1(0.0)
    y0 = [R1 / R2 * a10 - delta0, R1 / R2 * v10]
    t_end = 8 * 2 * math.pi / omega
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=1e-11, atol=1e-14, max_step=t_end / 8000,
                    dense_output=True)
    integ = ExactIntegrator(lg.chain.system())
    z = np.array([delta0, 0.0])
    lost = False
    ts = np.linspace(0.0, t_end, 41)
    for t0, t in itertools.pairwise(ts):
        z, _ = integ.advance(z, t0, t, omega, sensitivity=False)
        a1, _ = th1(t)
        delta = R1 / R2 * a1 - sol.sol(t)[0]
        # 1e-12 m along the line of action against the 100 µm gap (as above)
        assert z[0] == pytest.approx(delta, abs=1e-12 / R2)
        lost |= abs(z[0]) < lg.half_gap
    assert lost  # the loose gear rattles (leaves the drive flank)


def test_gear_builders_refuse_bad_input():
    with pytest.raises(ValueError, match=r"`base_radii\[1\]` must be > 0"):
        gear_pair(base_radii=[0.03, -0.04], inertias=[J1, J2], mesh_stiffness=KM, mesh_damping_ratio=ZETA,
                  backlash=BLOS)
    with pytest.raises(ValueError, match=r"`inertias\[0\]` must be > 0"):
        gear_pair(base_radii=[R1, R2], inertias=[0.0, J2], mesh_stiffness=KM, mesh_damping_ratio=ZETA,
                  backlash=BLOS)
    with pytest.raises(ValueError, match="`mesh_stiffness` must be > 0"):
        _pair_kw = {"base_radii": [R1, R2], "inertias": [J1, J2], "mesh_damping_ratio": ZETA, "backlash": BLOS}
        gear_pair(mesh_stiffness=0.0, **_pair_kw)
    with pytest.raises(ValueError, match="`links\\[0\\].between` must be"):
        _pair(links=[Link(between=(1, 2), stiffness=1.0)])
    with pytest.raises(ValueError, match="`drag_torque` must be >= 0"):
        loose_gear(base_radii=[R1, R2], inertia=1e-4, mesh_stiffness=KM, mesh_damping_ratio=ZETA, backlash=BLOS,
                   drive_acceleration=[1.0], drag_torque=-1.0)


def test_gear_pair_grounding_link_on_gear2_is_reflected():
    g = _pair(links=[Link(between=(2, 0), stiffness=100.0, damping=0.5)])
    link = g.chain.links[1]
    assert link.stiffness == pytest.approx(100.0 * 0.5625) and link.damping == pytest.approx(0.5 * 0.5625)
    assert not g.chain.free


def test_builders_are_exported():
    assert rattle.clutch_damper is clutch_damper and rattle.gear_pair is gear_pair
    assert rattle.hub_spline is hub_spline and rattle.loose_gear is loose_gear
