"""Harmonic balance of a chain with Coulomb friction on its elements, by regularisation.

:class:`RegularisedSystemBalance` is checked against
- central finite differences of its own residual (∂R/∂q and ∂R/∂Ω, chains of 2 and 3 inertias,
  grounded and free, friction levels per stage, with the chain's step widths and with one
  element's own narrower steps);
- :class:`HarmonicBalance` of the same chain without friction (the regularised law of a continuous
  law without friction is the law itself: residual and Jacobians equal to round-off, a speed-dependent
  drag included);
- :class:`RegularisedBalance` of the equivalent single equation (same widths);
- an independent integration (scipy LSODA, rtol 1e-10, the regularised equations written out here
  from their formula) of a 2-coordinate chain run from the linear solution to its steady state.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rattle.continuation import solve_fixed
from rattle.hb import (
    HarmonicBalance,
    HBOptions,
    RegularisedBalance,
    RegularisedSystemBalance,
)
from rattle.model import (
    Backlash, Chain, Clutch, Drag, Element, Excitation, Friction, Linear, Link, NonsmoothLaw, System, Torque,
)
from rattle.model._system import single_equation_system

CLUTCH_R = (0.01, 0.03, 0.01)


def _chain(kind: str, friction: bool = True, damping: float = 0.05) -> Chain:
    """g2: grounded, 2 inertias (n = 2); f2: free, 2 inertias (n = 1); f3: free, 3 inertias (n = 2);
    g3: grounded, 3 inertias (n = 3); f3drag: f3 with a speed-dependent drag."""
    def fr(*r: float) -> Friction | None:
        return Friction(levels=r) if friction else None

    c = damping
    clutch = {"name": "clutch", "stiffness": 1.0, "law": Clutch(alpha=0.2, b=0.1), "friction": fr(*CLUTCH_R)}
    if kind == "g2":
        return Chain(inertias=(1.0, 0.5),
                     links=(Link(between=(1, 0), damping=0.04), Link(between=(1, 2), stiffness=2.0, damping=0.03)),
                     elements=(Element(between=(1, 0), **clutch),
                               Element(name="gear", between=(1, 2), stiffness=0.5, law=Backlash(b=0.05),
                                       friction=fr(0.02))),
                     torques=(Torque(inertia=1, mean=0.02, amplitudes=(0.3, 0.05), phases=(0.2, 1.0)),))
    if kind == "f2":
        return Chain(inertias=(1.0, 0.5), links=(Link(between=(1, 2), damping=c),),
                     elements=(Element(between=(1, 2), **clutch),),
                     torques=(Torque(inertia=1, mean=0.05, amplitudes=(0.3,), phases=(0.4,)),
                              Torque(inertia=2, mean=-0.05)))
    if kind in ("f3", "f3drag"):
        drag = Drag(inertia=3, speed_rpm=(5.0, 15.0, 40.0), torque=(0.01, 0.03, 0.02), balance=1) \
            if kind == "f3drag" else None
        return Chain(inertias=(1.0, 0.5, 2.0),
                     links=(Link(between=(1, 2), damping=c), Link(between=(2, 3), stiffness=3.0, damping=c)),
                     elements=(Element(between=(1, 2), **clutch),
                               Element(name="gear", between=(2, 3), stiffness=2.0, law=Backlash(b=0.05),
                                       friction=fr(0.0, 0.01, 0.02))),
                     torques=(Torque(inertia=1, mean=0.05, amplitudes=(0.3, 0.1)), Torque(inertia=3, mean=-0.05)),
                     speed_order=1.0 if drag else None, drag=drag)
    assert kind == "g3"
    return Chain(inertias=(1.0, 0.5, 2.0),
                 links=(Link(between=(1, 2), damping=c), Link(between=(2, 3), stiffness=3.0, damping=c),
                        Link(between=(3, 0), stiffness=1.0, damping=0.1)),
                 elements=(Element(between=(1, 2), **clutch),
                           Element(name="gear", between=(2, 3), stiffness=2.0, law=Backlash(b=0.05), friction=fr(0.02)),
                           Element(name="mount", between=(1, 0), stiffness=0.5, law=Linear(), friction=fr(0.01))),
                 torques=(Torque(inertia=1, mean=0.05, amplitudes=(0.3, 0.1)),))


def _random_q(pb: RegularisedSystemBalance, omega: float, seed: int = 1) -> np.ndarray:
    """The linear solution plus a random series with decaying harmonics, amplitudes ~ L."""
    H, n = pb.basis.harmonics, pb.n_coordinates
    decay = np.concatenate(([1.0], 1.0 / np.arange(1, H + 1) ** 2, 1.0 / np.arange(1, H + 1) ** 2))
    noise = np.random.default_rng(seed).normal(size=(n, 2 * H + 1)) * decay * 0.3 * pb.length_scale
    return pb.linear_solution(omega) + noise.reshape(-1)


def _ladder(pb: RegularisedSystemBalance, omega: float) -> np.ndarray:
    """Newton from the linear solution along ε = 0.2, 0.1, … down to the problem's ε."""
    q = pb.linear_solution(omega)
    for eps in [e for e in (0.2, 0.1, 0.05, 0.02) if e > pb.eps] + [pb.eps]:
        res = solve_fixed(pb.with_regularisation(eps), q, omega)
        assert res.converged, (eps, res)
        q = res.q
    return q


@pytest.mark.parametrize("scaled", [False, True])
@pytest.mark.parametrize("kind", ["g2", "f2", "f3", "g3"])
def test_jacobians_match_finite_differences(kind: str, scaled: bool) -> None:
    """``scaled``: the first element (the clutch, with friction) with steps 0.3 times the chain's
    (:meth:`RegularisedSystemBalance.with_element_scales`), the others the chain's."""
    fs = _chain(kind).friction_system()
    assert fs.has_friction
    pb = RegularisedSystemBalance(fs, regularisation=0.05, options=HBOptions(harmonics=8))
    if scaled:
        pb = pb.with_element_scales(np.r_[0.3, np.ones(fs.m - 1)])
    w = 0.7 * pb.parameter_scale
    q = _random_q(pb, w)
    R, J, Rw = pb.residual_jacobian(q, w)
    np.testing.assert_array_equal(R, pb.residual(q, w))
    h = 1e-6 * pb.length_scale
    fd = np.empty_like(J)
    for j in range(pb.size):
        e = np.zeros(pb.size)
        e[j] = h
        fd[:, j] = (pb.residual(q + e, w) - pb.residual(q - e, w)) / (2 * h)
    assert np.max(np.abs(fd - J)) <= 1e-7 * np.max(np.abs(J))  # measured ≤ 1e-11
    hw = 1e-6 * w
    fdw = (pb.residual(q, w + hw) - pb.residual(q, w - hw)) / (2 * hw)
    assert np.max(np.abs(fdw - Rw)) <= 1e-7 * np.max(np.abs(Rw))  # measured ≤ 1e-10
    # The friction's velocity term is in both: without it the Jacobian is off by far more.
    frictionless = RegularisedSystemBalance(_chain(kind, friction=False).friction_system(), regularisation=0.05,
                                            options=HBOptions(harmonics=8))
    assert np.max(np.abs(frictionless.residual_jacobian(q, w)[1] - J)) > 1e-3 * np.max(np.abs(J))


@pytest.mark.parametrize("kind", ["g2", "f3", "g3", "f3drag"])
def test_without_friction_it_is_the_smooth_harmonic_balance(kind: str) -> None:
    chain = _chain(kind, friction=False)
    system = chain.system()
    fs = system.with_friction((0.0,) * system.m)  # friction levels 0 given explicitly
    opts = HBOptions(harmonics=8, samples=128)
    pb = RegularisedSystemBalance(fs, regularisation=0.01, options=opts)
    hb = HarmonicBalance(chain, opts)
    assert pb.size == hb.size and pb.force_scale == hb.force_scale
    w = 1.4 if kind == "f3drag" else 0.7 * pb.parameter_scale  # inside the drag table (rpm 5 … 40)
    q = _random_q(pb, w, seed=3)
    R, J, Rw = pb.residual_jacobian(q, w)
    R0, J0, Rw0 = hb.residual_jacobian(q, w)
    for a, b in ((R, R0), (J, J0), (Rw, Rw0)):
        assert np.max(np.abs(a - b)) <= 1e-14 * np.max(np.abs(b))
    if kind == "f3drag":  # the load's slope d'(Ω) u is in ∂R/∂Ω
        assert np.max(np.abs(hb.system.mean_slope(w))) > 0


def _single_equation_pair() -> tuple[RegularisedSystemBalance, RegularisedBalance]:
    """δ'' + c δ' + k g(δ, δ') = F(t) as an n = 1 chain problem and as the scalar problem, with the
    same widths of the smooth steps (H = 24, ε = 0.02 for the chain)."""
    c, k, law, mean, amps, phases = 0.15, 3.0, Clutch(alpha=0.2, b=0.1), 0.15, (0.3, 0.1), (0.4, -1.0)
    fs = single_equation_system(c, k, law, mean, amps, phases).with_friction((CLUTCH_R,))
    opts = HBOptions(harmonics=24)
    pb = RegularisedSystemBalance(fs, regularisation=0.02, options=opts)
    nsys = System.single(damping=c, stiffness=k, law=NonsmoothLaw(elastic=law, friction=Friction(levels=CLUTCH_R)),
                           excitation=Excitation(mean=mean, amplitudes=amps, phases=phases))
    L_ns = nsys.length_scale()  # the scalar problem's own scale: ε rescaled to the same widths
    ref = RegularisedBalance(c, nsys, mean, amps, phases, regularisation=0.02 * pb.length_scale / L_ns,
                             length_scale=L_ns, frequency_scale=math.sqrt(k * 1.0), options=opts)
    return pb, ref


def test_single_equation_is_the_regularised_balance() -> None:
    """δ'' + c δ' + k g(δ, δ') = F(t) as an n = 1 system and as the scalar problem: same numbers."""
    pb, ref = _single_equation_pair()
    assert pb.parameter_scale == pytest.approx(math.sqrt(3.0))
    np.testing.assert_allclose(pb.widths, ref.widths, rtol=1e-14)
    w = 0.6 * pb.parameter_scale
    q = _random_q(pb, w)
    for a, b in zip(pb.residual_jacobian(q, w), ref.residual_jacobian(q, w)):
        assert np.max(np.abs(a - b)) <= 1e-13 * np.max(np.abs(b))


def test_two_inertia_free_chain_agrees_with_the_single_equation() -> None:
    """The free 2-inertia chain f2 is δ'' + c δ' + k g = F with c = C(1/I1 + 1/I2), k = K(1/I1 + 1/I2),
    F = T1/I1 − T2/I2: both solved by Newton at one Ω, the rms agree."""
    fs = _chain("f2").friction_system()
    pb = RegularisedSystemBalance(fs, regularisation=0.02, options=HBOptions(harmonics=32))
    c, k, mean = 0.05 * 3.0, 1.0 * 3.0, 0.05 + 0.05 / 0.5
    nsys = System.single(damping=c, stiffness=k,
                           law=NonsmoothLaw(elastic=Clutch(alpha=0.2, b=0.1), friction=Friction(levels=CLUTCH_R)),
                           excitation=Excitation(mean=mean, amplitudes=(0.3,), phases=(0.4,)))
    L_ns = nsys.length_scale()
    ref = RegularisedBalance(c, nsys, mean, (0.3,), (0.4,), regularisation=0.02 * pb.length_scale / L_ns,
                             length_scale=L_ns, frequency_scale=math.sqrt(k), options=HBOptions(harmonics=32))
    np.testing.assert_allclose(pb.widths, ref.widths, rtol=1e-14)
    w = 0.6 * pb.parameter_scale
    q = _ladder(pb, w)
    res = solve_fixed(ref, q, w)  # the same unknowns (one coordinate)
    assert res.converged
    rms_ref = math.sqrt(res.q[0] ** 2 + 0.5 * np.sum(res.q[1:] ** 2))
    assert pb.element_rms(q)[0] == pytest.approx(rms_ref, rel=1e-12)
    np.testing.assert_allclose(q, res.q, rtol=0, atol=1e-11 * pb.length_scale)


def _regularised_rhs(fs: System, widths: tuple[float, float], omega: float):  # type: ignore[no-untyped-def]
    """z' = f(t, z) of the regularised equations and ∂f/∂z, written out from the formula
    g_ε = f(δ) + r_ε(δ) tanh(δ'/ε_v), r_ε = r_0 + Σ_i (r_{i+1} − r_i)(1 + tanh((δ − d_i)/ε_δ))/2."""
    s = fs.continuous()
    n, A, B, C, K = s.n, s.element_rows, s.element_columns, s.damping, s.stiffness
    ed, ev = widths
    laws = [(tuple(el.breakpoints), tuple(el.slopes), tuple(el.offsets), tuple(fs.friction_levels(e)))
            for e, el in enumerate(s.elements)]

    def g(d: float, v: float, law: tuple) -> tuple[float, float, float]:
        bp, sl, off, r = law
        j = sum(d >= x for x in bp)
        rr, rd = r[0], 0.0
        for i, x in enumerate(bp):
            t = math.tanh((d - x) / ed)
            rr += (r[i + 1] - r[i]) * 0.5 * (1.0 + t)
            rd += (r[i + 1] - r[i]) * 0.5 * (1.0 - t * t) / ed
        tv = math.tanh(v / ev)
        return sl[j] * d + off[j] + rr * tv, sl[j] + rd * tv, rr * (1.0 - tv * tv) / ev

    def forcing(t: float) -> np.ndarray:
        out = s.mean.copy()
        for h in range(s.cos.shape[0]):
            out += math.cos((h + 1) * omega * t) * s.cos[h] + math.sin((h + 1) * omega * t) * s.sin[h]
        return out

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        x, v = z[:n], z[n:]
        d, dv = A @ x, A @ v
        ge = np.array([g(d[e], dv[e], law)[0] for e, law in enumerate(laws)])
        return np.concatenate((v, forcing(t) - C @ v - K @ x - B @ ge))

    def jac(t: float, z: np.ndarray) -> np.ndarray:
        d, dv = A @ z[:n], A @ z[n:]
        parts = np.array([g(d[e], dv[e], law) for e, law in enumerate(laws)])
        out = np.zeros((2 * n, 2 * n))
        out[:n, n:] = np.eye(n)
        out[n:, :n] = -K - (B * parts[:, 1]) @ A
        out[n:, n:] = -C - (B * parts[:, 2]) @ A
        return out

    return rhs, jac


def test_solution_is_the_steady_state_of_the_regularised_equations() -> None:
    """Free 3-inertia chain (n = 2), ε = 0.01, Ω = 0.3 ω_n: the clutch slides through most of the
    period and the gear creeps (|δ'| < 2 ε_v) most of it. Integrated (LSODA, rtol 1e-10) from the
    linear solution's state for 18 periods, the last period's rms of each element's deflection
    match the HB's (H = 64).

    Tolerance 3e-6: the HB's own error at H = 64 is ≤ 5e-7 (H = 128 changes the rms by 4.7e-7,
    truncation and the AFT's sampling of the law's kinks, N = 2048), the transient left in period
    18 is ~2e-7 (the rms changes by 2e-7 from period 16 to 18) and the integrator's error ~1e-9;
    measured 4.0e-7 (7e-8 with H = 128). H = 8 misses by 4e-5 … 8e-5, so the check has teeth."""
    fs = _chain("f3", damping=0.3).friction_system()
    pb = RegularisedSystemBalance(fs, regularisation=0.01, options=HBOptions(harmonics=64))
    w = 0.3 * pb.parameter_scale
    q = _ladder(pb, w)
    _, v = pb.samples(q, w)
    ev = pb.widths[1]
    assert np.mean(np.abs(v[0]) < 2 * ev) < 0.3 and np.mean(np.abs(v[1]) < 2 * ev) > 0.5  # friction matters
    rhs, jac = _regularised_rhs(fs, pb.widths, w)
    T, P = 2 * math.pi / w, 18
    sol = solve_ivp(rhs, (0.0, P * T), pb.state_at_zero(pb.linear_solution(w), w), method="LSODA", jac=jac,
                    rtol=1e-10, atol=1e-12 * pb.length_scale, dense_output=True)
    assert sol.success
    t = (P - 1) * T + np.arange(pb.basis.samples) * (T / pb.basis.samples)
    delta = fs.continuous().element_rows @ sol.sol(t)[: fs.n]
    rms = np.sqrt(np.mean(delta**2, axis=1))
    np.testing.assert_allclose(pb.element_rms(q), rms, rtol=3e-6)
    # The state on the section: the start of the exact shooting (pointwise, so a looser bound).
    assert np.max(np.abs(sol.sol((P - 1) * T) - pb.state_at_zero(q, w))) < 2e-5 * pb.length_scale
    coarse = RegularisedSystemBalance(fs, regularisation=0.01, options=HBOptions(harmonics=8))
    qc = solve_fixed(coarse, pb.resize(q, 8), w)
    assert qc.converged and np.max(np.abs(coarse.element_rms(qc.q) / rms - 1)) > 1e-5


def test_views_and_helpers() -> None:
    fs = _chain("g3").friction_system()
    pb = RegularisedSystemBalance(fs, regularisation=0.05, options=HBOptions(harmonics=6), period=2)
    n, m, S, N = 3, 3, 13, pb.basis.samples
    assert pb.period == 2 and pb.options.harmonics == 6 and pb.size == n * S
    w = 0.8 * pb.parameter_scale
    q = _random_q(pb, w)
    Q = pb.coordinate_series(q)
    assert Q.shape == (n, S) and np.shares_memory(Q, q)
    A = fs.continuous().element_rows
    np.testing.assert_allclose(pb.element_series(q), A @ Q)
    d = pb.element_samples(q)
    assert d.shape == (m, N)
    np.testing.assert_allclose(pb.element_rms(q), np.sqrt(np.mean(d**2, axis=1)), rtol=1e-12)
    # z(0): the series and their derivatives at t = 0 (base frequency Ω/p).
    z0 = pb.state_at_zero(q, w)
    x0 = [pb.basis.evaluate(Q[i], w / 2, np.array([0.0]))[0] for i in range(n)]
    v0 = [pb.basis.evaluate(Q[i], w / 2, np.array([0.0]), derivative=1)[0] for i in range(n)]
    np.testing.assert_allclose(z0, np.concatenate((x0, v0)), rtol=1e-13, atol=1e-15)
    # resize: padding keeps the orbit, truncation back gives q again.
    big = pb.resize(q, 10)
    assert big.shape == (n * 21,)
    np.testing.assert_array_equal(RegularisedSystemBalance(fs, regularisation=0.05, options=HBOptions(harmonics=10),
                                                           period=2).resize(big, 6), q)
    # with_regularisation: same problem, other widths; the original keeps its ε.
    other = pb.with_regularisation(0.01)
    assert other.widths == pytest.approx((pb.widths[0] / 5, pb.widths[1] / 5))
    assert pb.eps == 0.05 and other.eps == 0.01
    assert np.max(np.abs(other.residual(q, w) - pb.residual(q, w))) > 0
    L, wn = fs.length_scale(), fs.frequency_scale()
    assert pb.widths == pytest.approx((0.05 * L, 0.05 * L * wn))
    assert pb.force_scale == fs.continuous().force_scale() and pb.parameter_scale == wn
    # newton_step: the full solve of the Jacobian.
    R, dq = pb.newton_step(q, w)
    _, J, _ = pb.residual_jacobian(q, w)
    np.testing.assert_allclose(J @ dq, -R, atol=1e-10 * np.max(np.abs(R)))


def test_bad_arguments_are_refused() -> None:
    fs = _chain("f3").friction_system()
    with pytest.raises(TypeError, match="`fsys`"):
        RegularisedSystemBalance(fs.continuous(), regularisation=0.1)  # type: ignore[arg-type]
    for bad in (0.0, -0.1, float("nan"), float("inf"), True, "0.1"):
        with pytest.raises(ValueError, match="`regularisation`"):
            RegularisedSystemBalance(fs, regularisation=bad)  # type: ignore[arg-type]
    for bad in (0, -1, 1.0, True):
        with pytest.raises(ValueError, match="`period`"):
            RegularisedSystemBalance(fs, regularisation=0.1, period=bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="`harmonics` must be >= 4"):  # forcing harmonic 2 at period 2
        RegularisedSystemBalance(fs, regularisation=0.1, options=HBOptions(harmonics=3), period=2)
    with pytest.raises(TypeError, match="`options`"):
        RegularisedSystemBalance(fs, regularisation=0.1, options={"harmonics": 8})  # type: ignore[arg-type]
    pb = RegularisedSystemBalance(fs, regularisation=0.1, options=HBOptions(harmonics=4))
    with pytest.raises(ValueError, match="`regularisation`"):
        pb.with_regularisation(0.0)


def test_regularised_monodromy_of_one_coordinate_is_the_single_equations() -> None:
    """The chain's 2n × 2n exponential midpoint rule (scipy's expm) for n = 1 equals the single
    equation's closed-form 2 × 2 one (:func:`regularised_monodromy`) on the same series."""
    from rattle.stability import regularised_monodromy, regularised_system_monodromy

    pb, ref = _single_equation_pair()
    w = 0.6 * pb.parameter_scale
    q = _random_q(pb, w)
    M = regularised_system_monodromy(pb, q, w)
    np.testing.assert_allclose(M, regularised_monodromy(ref, q, w), rtol=0, atol=1e-11 * np.max(np.abs(M)))


def test_regularised_monodromy_is_the_variational_equations() -> None:
    """The free 3-inertia chain of the steady-state test: the HB orbit's regularised monodromy
    (midpoint rule, N = 2048 steps) against an independent integration of z' = f(t, z) and
    Φ' = ∂f/∂z Φ over one period from the HB state (LSODA, rtol 1e-11; f and ∂f/∂z written out
    here). The moduli agree to 1e-4: measured 1.2e-5 at N = 2048 and 3.0e-6 at N = 8192 (the
    rule's own error, falling with N; the HB state's error, 2e-5 L, counts less), while N = 64
    misses by 3.5e-4."""
    from rattle.stability import regularised_system_multipliers

    fs = _chain("f3", damping=0.3).friction_system()
    pb = RegularisedSystemBalance(fs, regularisation=0.01, options=HBOptions(harmonics=64))
    w = 0.3 * pb.parameter_scale
    q = _ladder(pb, w)
    rhs, jac = _regularised_rhs(fs, pb.widths, w)
    n = fs.n

    def ext(t: float, y: np.ndarray) -> np.ndarray:
        z, Phi = y[: 2 * n], y[2 * n :].reshape(2 * n, 2 * n)
        return np.concatenate((rhs(t, z), (jac(t, z) @ Phi).reshape(-1)))

    T = 2 * math.pi / w
    y0 = np.concatenate((pb.state_at_zero(q, w), np.eye(2 * n).reshape(-1)))
    sol = solve_ivp(ext, (0.0, T), y0, method="LSODA", rtol=1e-11, atol=1e-13)
    assert sol.success
    mu_ref = np.linalg.eigvals(sol.y[2 * n :, -1].reshape(2 * n, 2 * n))
    mu_ref = mu_ref[np.argsort(-np.abs(mu_ref))]
    mu = regularised_system_multipliers(pb, q, w)
    assert np.max(np.abs(np.abs(mu) - np.abs(mu_ref))) <= 1e-4
    assert abs(np.prod(mu) - np.prod(mu_ref)) <= 1e-4 * abs(np.prod(mu_ref)) + 1e-12
    coarse = regularised_system_multipliers(pb, q, w, steps=64)
    assert np.max(np.abs(np.abs(coarse) - np.abs(mu_ref))) > 1e-4
