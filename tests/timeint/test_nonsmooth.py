"""Event-driven exact integration of one coordinate with preload jumps and Coulomb friction.

References: an independent mode-by-mode DOP853 integration (scipy ``solve_ivp``, rtol 1e-12,
terminal events on the switching surfaces, the stick's exit by ``brentq``); the exact integrator
of the continuous laws (T_p = r = 0); closed-form stick and lock exit times; central differences
of the flow (saltation-based monodromy); the energy balance with the exact friction work.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _filippov import single_reference as _reference  # tests/ is on sys.path through its conftest
from scipy.integrate import solve_ivp

from rattle.errors import ConvergenceError
from rattle.model import Clutch, Excitation, Linear, Model, Piecewise, reference_case
from rattle.model._discontinuous import (
    Friction,
    NonsmoothLaw,
    PiecewiseJump,
    Preload,
)
from rattle.model import System
from rattle.timeint import ExactIntegrator
from rattle.timeint import ExactIntegrator, FlowOptions, shoot_nonsmooth_orbit


# ---------------------------------------------------------------------------------------------
# Independent reference
# ---------------------------------------------------------------------------------------------

def _system(elastic, friction=None, c=0.05, mean=0.05, amps=(0.03,), phases=None) -> System:
    return System.single(damping=c, stiffness=1.0, law=NonsmoothLaw(elastic=elastic, friction=friction),
                           excitation=Excitation(mean=mean, amplitudes=amps, phases=phases))


def _random_cases(n: int):
    rng = np.random.default_rng(11)
    out = []
    for i in range(n):
        tp = rng.uniform(0.005, 0.03)
        b = [0.0, 0.1][i % 2]
        fr = None if i % 3 == 0 else Friction(levels=tuple(rng.uniform(0.0, 0.015, 3 if b else 2)))
        sysx = _system(Preload(preload=tp, clearance=b, slope=rng.uniform(0.5, 1.5)), fr, c=rng.uniform(0.02, 0.1),
                       mean=rng.uniform(-0.03, 0.05), amps=(rng.uniform(0.02, 0.08), rng.uniform(0.0, 0.02)),
                       phases=(rng.uniform(0, 6), rng.uniform(0, 6)))
        out.append((sysx, (rng.uniform(-0.15, 0.15), rng.uniform(-0.05, 0.05)), rng.uniform(0.4, 1.6)))
    return out


# ---------------------------------------------------------------------------------------------
# Trajectories
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("case", range(6))
def test_random_cases_match_solve_ivp(case: int) -> None:
    sysx, x0, w = _random_cases(6)[case]
    traj = ExactIntegrator(sysx).propagate(x0, 0.0, 30.0, w)
    x_ref, t_ref, y_ref = _reference(sysx, x0, 30.0, w)
    d, v, _ = traj.sample(t_ref)
    # DOP853 at rtol 1e-12 with event location: its own error is ~1e-11 over 30 s
    assert np.max(np.abs(d - y_ref[0])) < 1e-8
    assert np.max(np.abs(v - y_ref[1])) < 1e-8
    assert np.max(np.abs(traj.state1 - x_ref)) < 1e-8
    assert len(traj.event_time) > 0  # switching happened


def test_compiled_march_is_the_python_march() -> None:
    """The compiled event march (timeint._event_kernel) takes the Python march's steps: the same
    events, event times and segments, the same end state and sensitivity (to the last bit where
    numpy's complex matrix product sums by fused multiply-adds, as OpenBLAS' kernels on x86-64
    with FMA do; to round-off elsewhere), on random preload/clearance/friction laws with two
    harmonics, sticks, locks and reversals over several periods."""
    from rattle.timeint import _event_kernel

    if not _event_kernel.AVAILABLE:
        pytest.skip("numba is not installed")
    kinds = set()
    locking = _system(Preload(preload=0.1), Friction(levels=0.02), mean=0.02, amps=(0.15,))  # chatter into a lock
    for sysx, x0, w in _random_cases(12) + [(locking, (0.1, 0.0), 0.3)]:
        compiled, python = ExactIntegrator(sysx), ExactIntegrator(sysx)
        python._compiled = False
        a = compiled.propagate(x0, 0.0, 40.0, w)
        b = python.propagate(x0, 0.0, 40.0, w)
        assert compiled._compiled
        assert a.event_kind == b.event_kind
        kinds |= set(a.event_kind)
        np.testing.assert_array_equal(a.kind, b.kind)
        np.testing.assert_array_equal(a.stage, b.stage)
        np.testing.assert_array_equal(a.sign, b.sign)
        np.testing.assert_allclose(a.event_time, b.event_time, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(a.x_start, b.x_start, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(a.state1, b.state1, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(a.sensitivity, b.sensitivity, rtol=1e-8, atol=1e-10)
    assert {"crossing", "reversal", "stick", "unstick", "lock", "unlock"} <= kinds


def test_near_critical_damping_keeps_the_python_march() -> None:
    # a stage with its two real modes within 1 % of each other: no modal form, the Python march
    sysx = _system(Preload(preload=0.02), Friction(levels=0.005), c=2.0 * 1.00001)
    integ = ExactIntegrator(sysx)
    traj = integ.propagate((0.05, 0.0), 0.0, 20.0, 0.7)
    assert integ._compiled is False and len(traj.event_time) > 0


def test_stick_phases_match_solve_ivp() -> None:
    # Friction on the reference clutch at low frequency: the orbit sticks and reverses.
    sysx = System.from_model(reference_case(), friction=Friction(levels=(0.005, 0.02, 0.005)))
    traj = ExactIntegrator(sysx).propagate((0.1, 0.05), 0.0, 40.0, 0.4)
    assert {"stick", "unstick", "reversal", "crossing"} <= set(traj.event_kind)
    _, t_ref, y_ref = _reference(sysx, (0.1, 0.05), 40.0, 0.4)
    d, v, _ = traj.sample(t_ref)
    assert np.max(np.abs(d - y_ref[0])) < 1e-8 and np.max(np.abs(v - y_ref[1])) < 1e-8


@pytest.mark.parametrize("omega", [0.5, 1.3])
def test_zero_preload_and_friction_recover_the_exact_integrator(omega: float) -> None:
    m = reference_case()
    ref = ExactIntegrator(m).propagate((0.1, 0.05), 0.0, 50.0, omega)
    for sysx in (System.from_model(m), System.from_model(m, friction=Friction(levels=0.0))):
        traj = ExactIntegrator(sysx).propagate((0.1, 0.05), 0.0, 50.0, omega)
        assert np.array_equal(traj.state1, ref.state1)  # the same stage solutions and crossings
        np.testing.assert_allclose(traj.sensitivity, ref.sensitivity, rtol=0, atol=1e-13)
    # Preload(T_p = 0) is the linear law; T_p → 0 converges linearly to it
    lin = Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Linear(), excitation=m.excitation)
    ref = ExactIntegrator(lin).propagate((0.1, 0.05), 0.0, 50.0, omega)
    zero = ExactIntegrator(System.from_model(lin, elastic=Preload(preload=0.0)))
    assert np.max(np.abs(zero.propagate((0.1, 0.05), 0.0, 50.0, omega).state1 - ref.state1)) < 1e-14
    errs = [np.max(np.abs(ExactIntegrator(System.from_model(lin, elastic=Preload(preload=tp)))
                          .propagate((0.1, 0.05), 0.0, 50.0, omega).state1 - ref.state1)) for tp in (1e-6, 1e-7)]
    assert 5.0 < errs[0] / errs[1] < 20.0 and errs[0] < 1e-4
    # r → 0 likewise on the clutch (the reversals' saltations vanish with r)
    ref = ExactIntegrator(m).propagate((0.1, 0.05), 0.0, 50.0, omega)
    errs = [np.max(np.abs(ExactIntegrator(System.from_model(m, friction=Friction(levels=r)))
                          .propagate((0.1, 0.05), 0.0, 50.0, omega).state1 - ref.state1)) for r in (1e-6, 1e-7)]
    assert 5.0 < errs[0] / errs[1] < 20.0 and errs[0] < 1e-4


def test_stuck_mass_stays_exactly_stuck_inside_the_band() -> None:
    # linear law, friction r = 0.1 > |F − k δ0| = |0.02 cos Ωt + 0.01 − 0.02| for all t
    sysx = _system(Linear(), Friction(levels=0.1), mean=0.01, amps=(0.02,))
    traj = ExactIntegrator(sysx).propagate((0.02, 0.0), 0.0, 100.0, 0.7)
    assert traj.state1[0] == 0.02 and traj.state1[1] == 0.0
    assert traj.event_kind == () and traj.stick_time == 100.0
    d, v, a = traj.sample(np.linspace(0.0, 100.0, 501))
    assert np.all(d == 0.02) and np.all(v == 0.0) and np.all(a == 0.0)
    np.testing.assert_array_equal(traj.sensitivity, [[1.0, 0.0], [0.0, 0.0]])


def test_stick_ends_when_the_force_leaves_the_band() -> None:
    # F = 0.2 cos Ωt, δ0 = 0.15, r = 0.1: stuck at t = 0 (R = 0.05), slip starts when
    # 0.2 cos Ωt − 0.15 = −0.1 → cos Ωt = 1/4, downwards
    w = 0.9
    sysx = _system(Linear(), Friction(levels=0.1), mean=0.0, amps=(0.2,))
    traj = ExactIntegrator(sysx).propagate((0.15, 0.0), 0.0, 6.0, w)
    assert traj.event_kind[0] == "unstick"
    t_exit = math.acos(0.25) / w
    assert abs(traj.event_time[0] - t_exit) < 1e-14 * 10
    assert traj.sign[1] == -1 and traj.kind[0] == 1 and traj.kind[1] == 0


def test_preload_lock_and_release() -> None:
    # f = δ + 0.1 sgn δ, F = −0.2 sin Ωt: locked at (0, 0) while |F| ≤ 0.1, released downwards
    # (F < −0.1) at Ω t = π/6 exactly.
    w = 0.8
    sysx = _system(Preload(preload=0.1), None, mean=0.0, amps=(0.2,), phases=(math.pi / 2,))
    traj = ExactIntegrator(sysx).propagate((0.0, 0.0), 0.0, 3.0, w)
    assert traj.kind[0] == 2 and traj.event_kind[0] == "unlock"
    assert abs(traj.event_time[0] - math.pi / 6 / w) < 1e-14
    assert traj.stage[1] == 0  # below the jump
    d, v, _ = traj.sample(np.linspace(0.0, math.pi / 6 / w, 50))
    assert np.all(d == 0.0) and np.all(v == 0.0)


def test_chattering_approach_to_the_lock_with_friction_is_zeno_and_snaps() -> None:
    # |F| ≤ 0.03 < k T_p = 0.1: the spiral around (0, 0) loses a fixed fraction per crossing
    # (friction), accumulates in finite time and ends in the lock; afterwards δ ≡ 0.
    sysx = _system(Preload(preload=0.1), Friction(levels=0.01), mean=0.0, amps=(0.03,))
    traj = ExactIntegrator(sysx).propagate((0.05, 0.0), 0.0, 60.0, 0.8)
    assert "lock" in traj.event_kind and traj.event_kind[-1] == "lock"
    # |δ'| at the successive crossings of δ = 0 falls by a nearly fixed factor (Zeno), down to the
    # round-off level of the excursions δ'²/(2|a|) ~ 1e-13 L, where the lock is entered
    v = np.abs(traj.x_start[traj.x_start[:, 1] != 0.0, 1])
    assert np.all(v[1:] < v[:-1]) and v.size > 20
    assert v[-1] < 2e-7
    assert np.array_equal(traj.state1, [0.0, 0.0])
    np.testing.assert_array_equal(traj.sensitivity, np.zeros((2, 2)))  # all perturbations die


def test_chatter_without_snap_runs_out_of_budget() -> None:
    sysx = _system(Preload(preload=0.1), None, mean=0.0, amps=(0.03,))
    integ = ExactIntegrator(sysx, FlowOptions(lock_excursion=0.0, max_events=50))
    with pytest.raises(ConvergenceError, match="max_events"):
        integ.propagate((0.05, 0.0), 0.0, 200.0, 0.8)


# ---------------------------------------------------------------------------------------------
# Sensitivity, shooting, energy
# ---------------------------------------------------------------------------------------------
def _fd_sensitivity(integ, x0, T, w, h=1e-6):
    out = np.empty((2, 2))
    for i in range(2):
        e = np.zeros(2)
        e[i] = h
        out[:, i] = (integ.propagate(x0 + e, 0.0, T, w).state1 - integ.propagate(x0 - e, 0.0, T, w).state1) / (2 * h)
    return out


@pytest.mark.parametrize("case", ["jump", "jump_clearance_friction", "stage_friction", "stick"])
def test_monodromy_matches_finite_differences(case: str) -> None:
    m = reference_case()
    sysx, x0, w = {
        "jump": (System.from_model(m, elastic=Preload(preload=0.02)), (0.13, 0.05), 0.8),
        "jump_clearance_friction": (System.from_model(m, elastic=Preload(preload=0.02, clearance=0.1),
                                                               friction=Friction(levels=0.005)), (0.13, 0.05), 0.8),
        "stage_friction": (System.from_model(m, friction=Friction(levels=(0.005, 0.02, 0.005))),
                           (0.1, 0.05), 1.5),
        "stick": (System.from_model(m, friction=Friction(levels=(0.005, 0.02, 0.005))), (0.1, 0.05), 0.4),
    }[case]
    integ = ExactIntegrator(sysx)
    T = 2 * math.pi / w * (2 if case == "stick" else 1)
    traj = integ.propagate(np.array(x0), 0.0, T, w)
    kinds = set(traj.event_kind)
    assert {"crossing"} <= kinds and (case != "stick" or "stick" in kinds)
    fd = _fd_sensitivity(integ, np.array(x0), T, w)
    # h = 1e-6: truncation ~1e-10, round-off of the flow (~1e-15) / h ~ 1e-9
    np.testing.assert_allclose(traj.sensitivity, fd, rtol=0, atol=2e-8 * max(1.0, np.abs(fd).max()))
    # the saltation matrices matter: the bare product of the stage transition matrices is wrong
    bare = np.eye(2)
    for i in np.flatnonzero(traj.kind == 0):
        mode = 3 * int(traj.stage[i]) + int(traj.sign[i]) + 1
        bare = np.reshape(traj.solutions.transition_scalar(mode, traj.t_end[i] - traj.t_start[i]), (2, 2)) @ bare
    assert np.abs(bare - fd).max() > 1e-3 * np.abs(fd).max()


def test_shooting_stick_slip_orbit_has_a_zero_multiplier() -> None:
    sysx = System.from_model(reference_case(), friction=Friction(levels=0.01))
    orbit = shoot_nonsmooth_orbit(sysx, 0.4, (0.1, 0.05))
    assert orbit.converged and orbit.stable
    assert "stick" in orbit.trajectory.event_kind
    # stick removes velocity perturbations: rank-1 monodromy, one multiplier exactly 0
    assert abs(np.linalg.det(orbit.monodromy)) < 1e-15
    assert np.abs(orbit.multipliers[1]) < 1e-14
    fd = _fd_sensitivity(ExactIntegrator(sysx), orbit.state0, 2 * math.pi / 0.4, 0.4)
    np.testing.assert_allclose(orbit.monodromy, fd, atol=1e-8)
    np.testing.assert_allclose(np.abs(orbit.multipliers[0]), np.abs(np.linalg.eigvals(fd)).max(), atol=1e-8)


def test_shooting_preload_orbit_is_periodic_with_exact_multipliers() -> None:
    sysx = System.from_model(reference_case(), elastic=Preload(preload=0.02))
    orbit = shoot_nonsmooth_orbit(sysx, 0.8, (0.1, 0.05))
    assert orbit.converged
    T = 2 * math.pi / 0.8
    again = ExactIntegrator(sysx).propagate(orbit.state0, 0.0, T, 0.8)
    assert np.max(np.abs(again.state1 - orbit.state0)) < 1e-12
    # det M = exp(−c T) · Π (a⁺/a⁻ of the v-reversals) = exp(−cT) here (no friction): a saltation
    # matrix of a δ-jump crossing has determinant 1
    assert abs(np.linalg.det(orbit.monodromy) - math.exp(-0.05 * T)) < 1e-12
    fd = _fd_sensitivity(ExactIntegrator(sysx), orbit.state0, T, 0.8)
    np.testing.assert_allclose(orbit.monodromy, fd, atol=1e-8)


def test_energy_balance_with_friction_work() -> None:
    # E(t1) − E(t0) = ∫ F δ' dt − c ∫ δ'² dt − k ∫ r(δ) |δ'| dt, E = δ'²/2 + k V(δ): the friction
    # work from the segments' displacements (exact), the rest by Gauss–Legendre quadrature.
    sysx = _system(Preload(preload=0.02, clearance=0.1), Friction(levels=(0.02, 0.03, 0.02)), mean=0.02,
                   amps=(0.06, 0.01))
    w = 0.3
    traj = ExactIntegrator(sysx).propagate((0.12, -0.03), 0.0, 40.0, w)
    assert {"stick", "crossing", "reversal"} <= set(traj.event_kind)
    power_in = traj.integrate(lambda t, d, v, a: sysx.excitation(t, w) * v)
    viscous = sysx.c * traj.integrate(lambda t, d, v, a: v * v)
    friction = traj.friction_dissipation()
    dE = traj.energy(traj.state1) - traj.energy(traj.state0)
    assert friction > 0.0
    assert abs(dE - (power_in - viscous - friction)) < 1e-12 * max(power_in, 1.0)
    # over a periodic orbit: friction work = input − viscous work, and = k ∫ r |δ'| dt by quadrature
    orbit = shoot_nonsmooth_orbit(sysx, w, traj.state1)
    assert orbit.converged
    o = orbit.trajectory
    W_f = o.friction_dissipation()
    W_in = o.integrate(lambda t, d, v, a: sysx.excitation(t, w) * v)
    W_c = sysx.c * o.integrate(lambda t, d, v, a: v * v)
    assert abs(W_f - (W_in - W_c)) < 1e-12
    W_q = o.integrate(lambda t, d, v, a: sysx.law.friction_level(d) * np.abs(v))
    assert abs(W_f - W_q) < 1e-12


# ---------------------------------------------------------------------------------------------
# Laws
# ---------------------------------------------------------------------------------------------
def test_preload_is_the_clutch_limit() -> None:
    # the clutch α δ (|δ| ≤ b), δ − (1 − α) b sgn δ outside, with α b = T_p fixed and b → 0
    tp = 0.05
    x = np.array([-0.3, -0.01, 0.01, 0.3])
    pre = Preload(preload=tp).force(x)
    np.testing.assert_allclose(pre, x + tp * np.sign(x), rtol=0, atol=1e-15)
    for b in (1e-3, 1e-5):
        alpha = tp / b
        clutch = PiecewiseJump(breakpoints=(-b, b), slopes=(1.0, alpha, 1.0), jumps=(0.0, 0.0)).force(x)
        assert np.max(np.abs(clutch - pre)) <= 1.01 * b  # (α − 1) b = T_p − b
    np.testing.assert_allclose(Preload(preload=0.1, clearance=0.2, slope=2.0).force(np.array([-0.3, 0.1, 0.3])),
                               [-0.3, 0.0, 0.3])
    law = NonsmoothLaw(elastic=Clutch(alpha=0.25, b=0.17), friction=Friction(levels=(0.0, 0.02, 0.0)))
    np.testing.assert_array_equal(law.friction_levels, [0.0, 0.02, 0.0])
    assert law.stages.jumps.tolist() == [0.0, 0.0]


def test_regularised_law_tends_to_the_discontinuous_one() -> None:
    law = NonsmoothLaw(elastic=Preload(preload=0.05, clearance=0.1), friction=Friction(levels=(0.01, 0.02, 0.01)))
    d = np.array([-0.3, -0.05, 0.05, 0.25])
    v = np.array([0.2, -0.1, 0.3, -0.4])
    g = law.regularised(d, v, 1e-6, 1e-6)[0]
    exact = law.force(d) + law.friction_level(d) * np.sign(v)
    np.testing.assert_allclose(g, exact, atol=1e-12)
    # partials against central differences at a finite width
    h = 1e-7
    g1 = law.regularised(d + h, v, 0.05, 0.05)[0]
    g0 = law.regularised(d - h, v, 0.05, 0.05)[0]
    np.testing.assert_allclose(law.regularised(d, v, 0.05, 0.05)[1], (g1 - g0) / (2 * h), atol=1e-7)
    g1 = law.regularised(d, v + h, 0.05, 0.05)[0]
    g0 = law.regularised(d, v - h, 0.05, 0.05)[0]
    np.testing.assert_allclose(law.regularised(d, v, 0.05, 0.05)[2], (g1 - g0) / (2 * h), atol=1e-7)


def test_invalid_laws_are_refused() -> None:
    with pytest.raises(ValueError, match="`preload`"):
        Preload(preload=-0.1)
    with pytest.raises(ValueError, match="`clearance`"):
        Preload(preload=0.1, clearance=-1.0)
    with pytest.raises(ValueError, match="`jumps\\[0\\]`"):
        PiecewiseJump(breakpoints=(0.0,), slopes=(1.0, 1.0), jumps=(-0.1,))
    with pytest.raises(ValueError, match="`jumps`"):
        PiecewiseJump(breakpoints=(0.0,), slopes=(1.0, 1.0), jumps=(0.1, 0.2))
    with pytest.raises(ValueError, match="`levels\\[1\\]`"):
        Friction(levels=(0.1, -0.1))
    with pytest.raises(ValueError, match="one per stage"):
        NonsmoothLaw(elastic=Piecewise(breakpoints=(-0.1, 0.1), slopes=(1.0, 0.2, 1.0)), friction=Friction(levels=(0.1, 0.2)))
    with pytest.raises(TypeError, match="`law`"):
        System.single(damping=0.1, stiffness=1.0, law=Linear(), excitation=Excitation(mean=0.0, amplitudes=(0.1,)))
    with pytest.raises(ValueError, match="`lock_excursion`"):
        FlowOptions(lock_excursion=-1.0)


# ---------------------------------------------------------------------------------------------
# Filippov consistency on random cases with sticks and locks
# ---------------------------------------------------------------------------------------------
def _check_filippov(traj, sysx, omega: float) -> None:
    st, r, k = sysx.law.stages, sysx.law.friction_levels, sysx.k
    edges = np.concatenate(([-np.inf], st.breakpoints, [np.inf]))
    tol = 1e-12
    for i in range(len(traj.t_start)):
        ta, tb = traj.t_start[i], traj.t_end[i]
        if tb <= ta:
            continue
        t = ta + (tb - ta) * np.linspace(0.02, 0.98, 25)
        d, v, _ = traj.sample(t)
        F = sysx.excitation(t, omega)
        j = int(traj.stage[i])
        if traj.kind[i] == 0:  # slip: inside its stage, moving in the direction its friction assumes
            assert np.all(d >= edges[j] - tol) and np.all(d <= edges[j + 1] + tol)
            if r[j] > 0:
                assert traj.sign[i] != 0 and np.all(traj.sign[i] * v >= -tol)
        elif traj.kind[i] == 1:  # stick: friction holds the torque
            R = F - k * (st.slopes[j] * d + st.offsets[j])
            assert np.all(np.abs(R) <= k * r[j] + tol)
        else:  # lock at breakpoint j: F within the band of the four one-sided fields
            dj = st.breakpoints[j]
            lo = k * (st.slopes[j] * dj + st.offsets[j] - r[j])
            hi = k * (st.slopes[j + 1] * dj + st.offsets[j + 1] + r[j + 1])
            assert np.all((F >= lo - tol) & (F <= hi + tol)) and np.all(d == dj)


@pytest.mark.parametrize("seed", range(8))
def test_random_trajectories_are_filippov_consistent(seed: int) -> None:
    # forcing amplitudes of the order of the preload: slips, sticks, Zeno locks and releases
    # (seeds 6 and 7 lock) — every segment is checked against its mode's conditions
    rng = np.random.default_rng(100 + seed)
    b = [0.0, 0.05][seed % 2]
    tp = rng.uniform(0.05, 0.3)
    sysx = _system(Preload(preload=tp, clearance=b), Friction(levels=tuple(rng.uniform(0.0, 0.4 * tp, 3 if b else 2))),
                   c=rng.uniform(0.02, 0.1), mean=rng.uniform(-0.3, 0.3) * tp, amps=(rng.uniform(0.6, 1.8) * tp,),
                   phases=(rng.uniform(0, 6),))
    w = rng.uniform(0.3, 1.5)
    traj = ExactIntegrator(sysx).propagate((rng.uniform(-0.2, 0.2), rng.uniform(-0.1, 0.1)), 0.0, 40.0, w)
    _check_filippov(traj, sysx, w)
    assert len(traj.event_time) > 2
    if seed >= 6:
        assert "lock" in traj.event_kind


def test_orbit_with_a_lock_phase_is_superstable() -> None:
    # preload 0.1 with friction 0.02, F = 0.02 + 0.15 cos 0.3t: the chatter after each release
    # accumulates (Zeno) into the lock; the lock erases every perturbation
    w = 0.3
    sysx = _system(Preload(preload=0.1), Friction(levels=0.02), mean=0.02, amps=(0.15,))
    integ = ExactIntegrator(sysx)
    x = np.array([0.1, 0.0])
    for _ in range(5):
        x = integ.propagate(x, 0.0, 2 * math.pi / w, w).state1
    orbit = shoot_nonsmooth_orbit(sysx, w, x, integrator=integ)
    tr = orbit.trajectory
    assert orbit.converged and {"lock", "unlock"} <= set(tr.event_kind)
    np.testing.assert_array_equal(orbit.multipliers, [0.0, 0.0])
    fd = _fd_sensitivity(integ, orbit.state0, 2 * math.pi / w, w)
    np.testing.assert_array_equal(fd, np.zeros((2, 2)))
    # released where F leaves the band [k (−T_p − r), k (T_p + r)] = [−0.12, 0.12]
    t_un = tr.event_time[list(tr.event_kind).index("unlock")]
    assert abs(abs(float(sysx.excitation(t_un, w))) - 0.12) < 1e-15
    _check_filippov(tr, sysx, w)


def test_stiff_first_stage_clutch_tends_to_the_preload_orbit() -> None:
    # the clutch characteristic with first-stage slope α over ±b, (α − 1) b = T_p (outer stages
    # s δ ± T_p exactly), integrated by the continuous exact integrator: as b → 0 its periodic
    # orbit tends to the preload's, the error falling like b² (the multipliers agree)
    from rattle.timeint import shoot_periodic_orbit

    tp, w = 0.05, 1.2
    exc = Excitation(mean=0.01, amplitudes=(0.3,), phases=(0.3,))
    sysx = System.single(damping=0.05, stiffness=1.0, law=NonsmoothLaw(elastic=Preload(preload=tp)), excitation=exc)
    ref = shoot_nonsmooth_orbit(sysx, w, (0.3, 0.0))
    ref = shoot_nonsmooth_orbit(sysx, w, ref.state0)
    assert ref.converged
    errs = []
    for b in (1e-2, 1e-3):
        law = Piecewise(breakpoints=(-b, b), slopes=(1.0, tp / b + 1.0, 1.0))
        m = Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=law, excitation=exc)
        orbit = shoot_periodic_orbit(m, w, ref.state0)
        assert orbit.converged
        errs.append(abs(orbit.rms - ref.rms) / ref.rms)
        np.testing.assert_allclose(np.abs(orbit.multipliers), np.abs(ref.multipliers), atol=10 * b**2)
    assert errs[0] < 1e-5 and 50.0 < errs[0] / errs[1] < 200.0


@pytest.mark.parametrize("omega", [0.5, 1.3])
def test_orbit_measures_match_the_exact_integrator_without_jumps(omega: float) -> None:
    from rattle.timeint import shoot_periodic_orbit

    m = reference_case()
    orbit = shoot_nonsmooth_orbit(System.from_model(m), omega, (0.1, 0.05))
    ref = shoot_periodic_orbit(m, omega, orbit.state0)
    d_lo, d_hi, a_lo, a_hi = orbit.trajectory.extremes()
    got = np.array([orbit.mean, orbit.rms, d_lo, d_hi, a_lo, a_hi])
    want = np.array([ref.mean, ref.rms, ref.delta_min, ref.delta_max, ref.acc_min, ref.acc_max])
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-14)
    assert orbit.regime == ref.regime


def test_extremes_include_the_one_sided_accelerations_at_a_jump() -> None:
    sysx = System.from_model(reference_case(), elastic=Preload(preload=0.02), friction=Friction(levels=0.01))
    orbit = shoot_nonsmooth_orbit(sysx, 0.8, (0.1, 0.05))
    tr = orbit.trajectory
    d_lo, d_hi, a_lo, a_hi = tr.extremes()
    _, _, a = tr.sample(np.linspace(0.0, tr.t1, 20001))
    d, _, _ = tr.sample(np.linspace(0.0, tr.t1, 20001))
    assert d_lo <= d.min() and d_hi >= d.max() and d_hi - d.max() < 1e-6 and d.min() - d_lo < 1e-6
    assert a_lo <= a.min() and a_hi >= a.max()
    assert orbit.regime == "single_sided" and tr.crossed_breakpoints.tolist() == [0.0]


def test_fourier_coefficients_of_an_orbit() -> None:
    # against a 2^16-point FFT of the exact samples (aliasing of the k⁻³ tail below 1e-15) and
    # Parseval: the rms of the series tends to the orbit's rms (tail beyond H = 64 ~ 1e-9)
    sysx = System.from_model(reference_case(), elastic=Preload(preload=0.02), friction=Friction(levels=0.01))
    orbit = shoot_nonsmooth_orbit(sysx, 0.8, (0.1, 0.05))
    tr = orbit.trajectory
    H = 64
    q = tr.fourier(H)
    N = 2**16
    d = tr.sample(np.arange(N) * tr.t1 / N)[0]
    c = np.fft.rfft(d) / N
    np.testing.assert_allclose(q, np.concatenate(([c[0].real], 2 * c[1 : H + 1].real, -2 * c[1 : H + 1].imag)),
                               rtol=0, atol=1e-14)
    assert abs(math.sqrt(q[0] ** 2 + 0.5 * np.sum(q[1:] ** 2)) - orbit.rms) < 1e-8 * orbit.rms
