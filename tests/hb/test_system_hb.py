"""Harmonic balance of a System with n coordinates and m clearance elements (one core; the single
equation is n = m = 1): the single-equation numbers unchanged, Jacobians against differences,
linear systems against the exact steady state, a free two-inertia chain against the Model."""

from __future__ import annotations

import numpy as np
import pytest

import rattle
from rattle.hb import HarmonicBalance, HBOptions, solve_harmonic_balance
from rattle.model import Backlash, Clutch, Excitation, Linear, Model, ReducedElement, System


class _Holder:
    """Anything with a ``system()`` method is a model for the harmonic balance."""

    def __init__(self, system: System) -> None:
        self._system = system

    def system(self) -> System:
        return self._system


def _grounded_chain(laws=(Clutch(alpha=0.25, b=0.1), Backlash(b=0.05)), forcing=True) -> System:
    """θ'' of three inertias M = diag(1, 2, 1.5): links ground–1 (k 2, c 0.03), 1–2 (k 0.5,
    c 0.02), 3–ground (k 0.3, c 0.05); element 1 (K_e 1.5) on θ1 − θ2, element 2 (K_e 1.0) on
    θ2 − θ3; torques T_m + two harmonics with phases on inertias 1 and 3."""
    M = np.array([1.0, 2.0, 1.5])
    links = [((0, None), 2.0, 0.03), ((0, 1), 0.5, 0.02), ((2, None), 0.3, 0.05)]
    Kt, Ct = np.zeros((3, 3)), np.zeros((3, 3))
    for (i, j), k, c in links:
        w = np.zeros(3)
        w[i] = 1.0
        if j is not None:
            w[j] = -1.0
        Kt += k * np.outer(w, w)
        Ct += c * np.outer(w, w)
    elements = []
    for name, (i, j), Ke, law in (("clutch", (0, 1), 1.5, laws[0]), ("gear", (1, 2), 1.0, laws[1])):
        w = np.zeros(3)
        w[i], w[j] = 1.0, -1.0
        elements.append(ReducedElement(name, w, w * Ke / M, law))
    Tm = np.array([0.04, 0.0, -0.01])
    amp = np.array([[0.03, 0.0, 0.01], [0.008, 0.0, 0.004]]) if forcing else np.zeros((2, 3))
    phase = np.array([[0.3, 0.0, -1.1], [0.9, 0.0, 0.2]])
    return System(
        damping=Ct / M[:, None], stiffness=Kt / M[:, None], elements=tuple(elements),
        mean=Tm / M, cos=amp * np.cos(phase) / M, sin=-amp * np.sin(phase) / M,
        coordinates=("theta1", "theta2", "theta3"), angles=np.eye(3), free=False,
    )


def _central(hb, q, omega, h=1e-7):
    n = q.size
    J = np.empty((n, n))
    for i in range(n):
        e = np.zeros(n)
        e[i] = h
        J[:, i] = (hb.residual(q + e, omega) - hb.residual(q - e, omega)) / (2 * h)
    dw = (hb.residual(q, omega + h) - hb.residual(q, omega - h)) / (2 * h)
    return J, dw


# --- (a) the single equation is unchanged ------------------------------------------------------
# Numbers of the pre-System single-equation code (rattle 0c2c1e1, HarmonicBalance of the reference
# case, H = 4, N = 32) at q_j = 0.05 + 0.12 sin(1.7 j + 0.3) / (1 + j), Ω = 0.83.
_R_BEFORE = [-0.01296037283217149, -0.04385234519620505, -0.04493852568137057, -0.13680237303208406,
             -0.7069076360758718, -0.023099869090246167, -0.07497253044949632, -0.2503074915824285,
             -0.6705489440056791]
_RW_BEFORE = [0.0, -0.17048110651894613, -0.18778357084894143, -0.3939529725624392, -1.7800820049341184,
              -0.10764714308448353, -0.2347461437870194, -0.6707433776567251, -1.6857193078866115]
_RQ_ROWS_BEFORE = {
    0: [0.390625, 0.12712562078453532, 0.09228631121658307, 0.050236536416425885, 0.016572815184059706,
        0.038563135466513423, 0.061663741727293, 0.061213396736743704, 0.04001031518405971],
    2: [0.18457262243316613, 0.1773621572009612, -2.34840218481594, 0.12807636231776195, 0.09543585538140366,
        0.02265026127023028, 0.12301031518405972, 0.04821617624794, 0.04582991396529591],
    6: [0.123327483454586, 0.09977653220325713, -0.042989684815940295, -0.028910094685086846,
        -0.07749756948929008, 0.07688908436810943, -2.3815478151840597, 0.12617487925130869, 0.08913676705176247],
}


def test_single_equation_residual_and_jacobians_are_unchanged():
    model = rattle.reference_case()
    hb = HarmonicBalance(model, HBOptions(harmonics=4, samples=32))
    assert (hb.n_coordinates, hb.n_elements, hb.size) == (1, 1, 9)
    j = np.arange(hb.size)
    q = 0.05 + 0.12 * np.sin(1.7 * j + 0.3) / (1 + j)
    R, Rq, Rw = hb.residual_jacobian(q, 0.83)
    assert R.shape == Rw.shape == (9,) and Rq.shape == (9, 9)
    np.testing.assert_allclose(R, _R_BEFORE, rtol=1e-14, atol=1e-16)
    np.testing.assert_allclose(Rw, _RW_BEFORE, rtol=1e-14, atol=1e-16)
    for row, values in _RQ_ROWS_BEFORE.items():
        np.testing.assert_allclose(Rq[row], values, rtol=1e-14, atol=1e-16)
    np.testing.assert_array_equal(hb.residual(q, 0.83), R)
    # The closed forms of the scalar equation: ∇²q + c∇q + k Γ* f(Γq) − F, with explicit Γ, Γ*.
    basis, w = hb.basis, 0.83
    D = basis.derivative_matrix(w)
    I_S, I_N = np.eye(hb.size), np.eye(basis.samples)
    Gamma = np.stack([basis.synthesize(I_S[i]) for i in range(hb.size)], axis=1)
    Gamma_star = np.stack([basis.analyze(I_N[i]) for i in range(basis.samples)], axis=1)
    delta = Gamma @ q
    R_closed = D @ D @ q + model.c * D @ q + model.k * Gamma_star @ model.elastic.force(delta) - hb.forcing
    J_closed = D @ D + model.c * D + model.k * Gamma_star @ np.diag(model.elastic.stiffness(delta)) @ Gamma
    np.testing.assert_allclose(R, R_closed, rtol=0, atol=1e-14)
    np.testing.assert_allclose(Rq, J_closed, rtol=0, atol=1e-14)
    np.testing.assert_allclose(hb.stiffness_samples(q), model.k * model.elastic.stiffness(delta), rtol=0, atol=0)
    assert hb.length_scale == model.length_scale() and hb.force_scale == model.force_scale()


# --- (b) three coordinates, two elements: Jacobians ----------------------------------------------
@pytest.mark.parametrize("period", [1, 2])
def test_chain_jacobians_match_central_differences(rng, period):
    system = _grounded_chain()
    hb = HarmonicBalance(_Holder(system), HBOptions(harmonics=6, samples=64), period=period)
    assert (hb.n_coordinates, hb.n_elements, hb.size) == (3, 2, 39)
    for _ in range(2):
        q = hb.linear_solution(0.9) + 0.05 * rng.standard_normal(hb.size)
        omega = rng.uniform(0.4, 2.0)
        R, Rq, Rw = hb.residual_jacobian(q, omega)
        np.testing.assert_array_equal(R, hb.residual(q, omega))
        Jn, dwn = _central(hb, q, omega)
        # Piecewise linear in q: the difference is exact up to eps·|R|/h unless a sample crosses a
        # breakpoint within ±h (improbable at random states).
        np.testing.assert_allclose(Rq, Jn, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(Rw, dwn, rtol=1e-6, atol=1e-7)


def test_chain_series_forcing_and_stiffness_samples(rng):
    system = _grounded_chain()
    H = 6
    hb = HarmonicBalance(_Holder(system), HBOptions(harmonics=H, samples=64), period=2)
    q = 0.1 * rng.standard_normal(hb.size)
    Q = hb.coordinate_series(q)
    assert Q.shape == (3, 2 * H + 1)
    np.testing.assert_array_equal(hb.element_series(q), system.element_rows @ Q)
    d = hb.element_samples(q)
    assert d.shape == (2, 64)
    np.testing.assert_allclose(d, hb.basis.synthesize(system.element_rows @ Q), atol=1e-15)
    np.testing.assert_allclose(hb.coordinate_samples(q).T @ system.element_rows.T, d.T, atol=1e-15)
    # Forcing: F_0 at a_0, harmonic h of Ω at harmonic 2h of ω (period 2): cos part F_ch, sin part F_sh.
    F = hb.forcing.reshape(3, 2 * H + 1)
    np.testing.assert_array_equal(F[:, 0], system.mean)
    for h in (1, 2):
        np.testing.assert_array_equal(F[:, 2 * h], system.cos[h - 1])
        np.testing.assert_array_equal(F[:, H + 2 * h], system.sin[h - 1])
    assert np.count_nonzero(F[:, [1, 3, 5, 6, H + 1, H + 3, H + 5, H + 6]]) == 0
    # Tangent stiffness K + Σ f_e'(δ_e) b_e a_eᵀ along the orbit, against the elements' laws.
    g = hb.element_slopes(q)
    Kt = hb.tangent_stiffness_samples(q)
    assert g.shape == (2, 64) and Kt.shape == (64, 3, 3)
    j = 17
    expected = system.stiffness + sum(e.law.stiffness(d[k, j]) * np.outer(e.b, e.a) for k, e in enumerate(system.elements))
    np.testing.assert_allclose(Kt[j], expected, rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="`stiffness_samples` is the n = 1 form"):
        hb.stiffness_samples(q)
    # Batched Γ* diag(g) Γ equals one at a time.
    Jb = hb.force_jacobian_from_stiffness(g)
    np.testing.assert_array_equal(Jb[1], hb.force_jacobian_from_stiffness(g[1]))
    # The linear matrix is the residual's linear part.
    L = hb.linear_matrix(1.3)
    no_elements = HarmonicBalance(_Holder(System(
        damping=system.damping, stiffness=system.stiffness, elements=(), mean=system.mean, cos=system.cos,
        sin=system.sin, coordinates=system.coordinates, angles=system.angles)), HBOptions(harmonics=H, samples=64), period=2)
    np.testing.assert_allclose(L @ q - hb.forcing, no_elements.residual(q, 1.3), rtol=0, atol=1e-14)


# --- (c) a linear system: Newton equals the exact steady state -----------------------------------
@pytest.mark.parametrize("omega", [0.35, 1.1, 2.4])
def test_linear_chain_equals_exact_steady_state(omega):
    system = _grounded_chain(laws=(Linear(), Linear()))
    H = 5
    hb = HarmonicBalance(_Holder(system), HBOptions(harmonics=H))
    Keff = system.stiffness + sum(np.outer(e.b, e.a) for e in system.elements)
    expected = np.zeros((3, 2 * H + 1))
    expected[:, 0] = np.linalg.solve(Keff, system.mean)
    for h in (1, 2):
        Z = Keff - (h * omega) ** 2 * np.eye(3) + 1j * h * omega * system.damping
        X = np.linalg.solve(Z, system.cos[h - 1] - 1j * system.sin[h - 1])  # x = Re(X e^{ihΩt})
        expected[:, h], expected[:, H + h] = X.real, -X.imag
    res = solve_harmonic_balance(hb, np.zeros(hb.size), omega)
    assert res.converged and res.iterations <= 2
    scale = np.max(np.abs(expected))
    np.testing.assert_allclose(res.q, expected.ravel(), rtol=0, atol=1e-12 * scale)
    # The closed-form linear solution about the static equilibrium is the same for linear laws.
    np.testing.assert_allclose(hb.linear_solution(omega), expected.ravel(), rtol=0, atol=1e-12 * scale)


def test_linear_solution_uses_the_stage_of_the_static_equilibrium():
    system = _grounded_chain()
    hb = HarmonicBalance(_Holder(system), HBOptions(harmonics=4))
    xs = system.static_equilibrium()
    stages = system.stages_of(xs)
    q = hb.linear_solution(0.7)
    Q = q.reshape(3, 9)
    np.testing.assert_allclose(Q[:, 0], xs)
    Ks, w = system.stage_stiffness(stages), 0.7
    X = np.linalg.solve(Ks - w**2 * np.eye(3) + 1j * w * system.damping, system.cos[0] - 1j * system.sin[0])
    np.testing.assert_allclose(Q[:, 1] - 1j * Q[:, 5], X, rtol=1e-13, atol=1e-16)


# --- (d) a free two-inertia chain in its relative coordinate is the single equation -------------
@pytest.mark.parametrize("law", [Clutch(alpha=0.25, b=0.17), Backlash(b=0.1)])
def test_free_two_inertia_chain_equals_the_single_equation(rng, law):
    I1, I2, C, K = 0.7, 1.9, 0.05, 1.3
    Fm, amps, phases = 0.05, (0.03, 0.01), (0.2, -0.6)
    model = Model(inertia=I1 * I2 / (I1 + I2), damping=C, stiffness=K, elastic=law,
                  excitation=Excitation(mean=Fm, amplitudes=amps, phases=phases))
    # Torques: balanced means T1m = −T2m = Fm/(1/I1 + 1/I2), harmonics T1p = I1·F_p on inertia 1
    # only; the relative coordinate sees T1/I1 − T2/I2 = F(t).
    inv = 1 / I1 + 1 / I2
    T1m = Fm / inv
    T2m = -T1m
    T1p = [(I1 * a * np.cos(p), -I1 * a * np.sin(p)) for a, p in zip(amps, phases)]
    cos = np.array([[c / I1] for c, _ in T1p])
    sin = np.array([[s / I1] for _, s in T1p])
    chain = System(
        damping=np.array([[C * inv]]), stiffness=np.array([[0.0]]),
        elements=(ReducedElement("clutch", np.array([1.0]), np.array([K * inv]), law),),
        mean=np.array([T1m / I1 - T2m / I2]), cos=cos, sin=sin,
        coordinates=("theta1-theta2",), angles=np.array([[1.0], [0.0]]), free=True,
    )
    opts = HBOptions(harmonics=8, samples=64)
    a, b = HarmonicBalance(model, opts), HarmonicBalance(_Holder(chain), opts)
    assert a.size == b.size == 17
    np.testing.assert_allclose(b.forcing, a.forcing, rtol=1e-15, atol=1e-17)
    for _ in range(3):
        q = a.linear_solution(0.9) + 0.05 * rng.standard_normal(a.size)
        omega = rng.uniform(0.3, 2.5)
        for x, y in zip(a.residual_jacobian(q, omega), b.residual_jacobian(q, omega)):
            np.testing.assert_allclose(y, x, rtol=1e-13, atol=1e-15)


def test_period_and_harmonics_are_checked_for_a_chain():
    holder = _Holder(_grounded_chain())
    with pytest.raises(ValueError, match=r"`harmonics` must be >= 6"):
        HarmonicBalance(holder, HBOptions(harmonics=5), period=3)
    with pytest.raises(ValueError, match=r"`period` must be an integer >= 1"):
        HarmonicBalance(holder, HBOptions(harmonics=8), period=0)


# --- condensation onto the element deflections ---------------------------------------------------
def test_condensed_newton_step_equals_the_full_step(rng):
    system = _grounded_chain()
    full = HarmonicBalance(_Holder(system), HBOptions(harmonics=6, samples=64))
    cond = HarmonicBalance(_Holder(system), HBOptions(harmonics=6, samples=64, condense=True))
    for _ in range(3):
        q = full.linear_solution(0.9) + 0.05 * rng.standard_normal(full.size)
        omega = rng.uniform(0.4, 2.0)
        R1, d1 = full.newton_step(q, omega)
        R2, d2 = cond.newton_step(q, omega)
        np.testing.assert_array_equal(R1, R2)
        _, Rq, _ = full.residual_jacobian(q, omega)
        np.testing.assert_allclose(Rq @ d2, -R1, rtol=0, atol=1e-12 * np.max(np.abs(R1)))
        np.testing.assert_allclose(d2, d1, rtol=0, atol=1e-12 * np.max(np.abs(d1)))
    a = solve_harmonic_balance(full, full.linear_solution(1.6), 1.6)
    b = solve_harmonic_balance(cond, cond.linear_solution(1.6), 1.6)
    assert a.converged and b.converged
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-13)


def test_condensation_falls_back_to_the_full_step_without_linear_stiffness(rng):
    # Without links the linear stiffness K is singular (held only by the elements): full step.
    s = _grounded_chain()
    bare = System(damping=s.damping, stiffness=np.zeros((3, 3)), elements=s.elements, mean=0 * s.mean, cos=s.cos,
                  sin=s.sin, coordinates=s.coordinates, angles=s.angles)
    full = HarmonicBalance(_Holder(bare), HBOptions(harmonics=4))
    cond = HarmonicBalance(_Holder(bare), HBOptions(harmonics=4, condense=True))
    q = 0.05 * rng.standard_normal(full.size)
    assert cond._dynamic_receptance(1.0) is None
    R1, d1 = full.newton_step(q, 1.0)
    R2, d2 = cond.newton_step(q, 1.0)
    assert (d1 is None and d2 is None) or np.array_equal(d1, d2)


def test_condense_must_be_a_bool():
    with pytest.raises(TypeError, match="`condense` must be true or false"):
        HBOptions(condense=1)


def test_static_forcing_and_resize_work_per_coordinate(rng):
    system = _grounded_chain()
    hb = HarmonicBalance(_Holder(system), HBOptions(harmonics=4))
    st = hb.static_forcing().reshape(3, 9)
    np.testing.assert_array_equal(st[:, 0], system.mean)
    assert np.count_nonzero(st[:, 1:]) == 0
    q = rng.standard_normal(hb.size)
    q2 = hb.resize(q, 8, factor=2).reshape(3, 17)
    Q = q.reshape(3, 9)
    np.testing.assert_array_equal(q2[:, 0], Q[:, 0])
    np.testing.assert_array_equal(q2[:, [2, 4, 6, 8]], Q[:, 1:5])
    np.testing.assert_array_equal(q2[:, [10, 12, 14, 16]], Q[:, 5:9])
