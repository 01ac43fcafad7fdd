"""Stability of N-coordinate systems: exact monodromy of the linearisation about a prescribed
periodic orbit against the variational equation integrated by solve_ivp, the single equation as
the n = 1 case of the same core, test functions, labels with the torus ratio, Hill's method."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from rattle.hb import FourierBasis, HarmonicBalance, HBOptions
from rattle.model import Backlash, Clutch, Linear, ReducedElement, System, reference_case
from rattle.stability import (
    FloquetMonitor, classify_loss, critical_distance, element_monodromy_batch, floquet_test_functions,
    is_stable, monodromy_batch, multipliers_from_monodromy, second_compound, system_monodromy_batch, torus_ratio,
)
from rattle.stability._floquet import _stage_exponentials
from rattle.stability._hill import system_hill_matrices, system_hill_multipliers


def grounded_chain(inertia, ground_k, ground_c, links, elements, torque=None) -> System:
    """M θ'' + C θ' + K θ + Σ w_eᵀ K_e f_e(w_e θ) = T for a grounded chain, as a System (x = θ).

    ``links`` (i, j, k, c) between inertias i and j (j = None: to ground, added to ``ground``
    terms of inertia i); ``elements`` (name, w, K_e, law)."""
    n = len(inertia)
    Minv = np.diag(1.0 / np.asarray(inertia, float))
    Kt = np.zeros((n, n))
    Ct = np.zeros((n, n))
    Kt[0, 0] += ground_k
    Ct[0, 0] += ground_c
    for i, j, k, c in links:
        w = np.zeros(n)
        w[i] = 1.0
        if j is not None:
            w[j] = -1.0
        Kt += k * np.outer(w, w)
        Ct += c * np.outer(w, w)
    elems = tuple(ReducedElement(name, np.asarray(w, float), Minv @ np.asarray(w, float) * Ke, law)
                  for name, w, Ke, law in elements)
    T = np.zeros(n) if torque is None else np.asarray(torque, float)
    return System(damping=Minv @ Ct, stiffness=Minv @ Kt, elements=elems, mean=np.zeros(n),
                  cos=(Minv @ T)[None, :], sin=np.zeros((1, n)), coordinates=tuple(f"x{i}" for i in range(n)),
                  angles=np.eye(n), free=False)


def two_dof() -> System:
    return grounded_chain(
        [1.0, 2.0], 1.0, 0.05, [(0, 1, 0.3, 0.02)],
        [("clutch", [1.0, -1.0], 2.0, Clutch(alpha=0.25, b=0.15)), ("gear", [0.0, 1.0], 1.5, Backlash(b=0.1))],
    )


def three_dof() -> System:
    return grounded_chain(
        [1.0, 1.5, 0.8], 1.0, 0.04, [(0, 1, 0.5, 0.0), (1, 2, 0.0, 0.03), (2, None, 0.2, 0.01)],
        [("clutch", [1.0, -1.0, 0.0], 2.0, Clutch(alpha=0.3, b=0.12)),
         ("gear", [0.0, 1.0, -1.0], 1.2, Backlash(b=0.08)),
         ("spring", [0.0, 0.0, 1.0], 0.7, Linear())],
    )


def one_coordinate_two_elements() -> System:
    return System(damping=np.array([[0.06]]), stiffness=np.array([[0.2]]),
                  elements=(ReducedElement("clutch", np.array([1.0]), np.array([1.0]), Clutch(alpha=0.25, b=0.15)),
                            ReducedElement("stop", np.array([1.0]), np.array([3.0]), Backlash(b=0.35))),
                  mean=np.zeros(1), cos=np.zeros((1, 1)), sin=np.zeros((1, 1)), coordinates=("x",),
                  angles=np.array([[1.0]]), free=False)


def series(n: int, H: int, terms) -> np.ndarray:
    """Coordinate series (n, 2H+1) from {(coordinate, 'a'|'b', harmonic): value} (a_0 at ('a', 0))."""
    X = np.zeros((n, 2 * H + 1))
    for (i, kind, h), v in terms.items():
        X[i, h if kind == "a" else H + h] = v
    return X


ORBITS = {
    2: lambda H: series(2, H, {(0, "a", 0): 0.05, (0, "a", 1): 0.4, (0, "b", 2): 0.1,
                               (1, "a", 0): -0.02, (1, "b", 1): 0.15, (1, "a", 3): 0.05}),
    3: lambda H: series(3, H, {(0, "a", 1): 0.35, (0, "b", 1): 0.1, (1, "a", 0): 0.01, (1, "b", 1): 0.12,
                               (1, "a", 2): 0.04, (2, "a", 1): -0.05, (2, "b", 3): 0.03}),
    1: lambda H: series(1, H, {(0, "a", 0): 0.02, (0, "a", 1): 0.45, (0, "b", 2): 0.08}),
}
SYSTEMS = {1: one_coordinate_two_elements, 2: two_dof, 3: three_dof}


def variational_monodromy(system: System, X: np.ndarray, w: float) -> np.ndarray:
    """Monodromy of y' = A(t) y, A(t) the stage matrix at x(t), by solve_ivp (DOP853, rtol 1e-12,
    atol 1e-14) segment by segment between the crossings (found by brentq on a fine grid)."""
    H = (X.shape[1] - 1) // 2
    basis = FourierBasis(H, 2 * H + 1)
    T = 2 * np.pi / w
    x_of = lambda t: np.array([basis.evaluate(X[i], w, np.atleast_1d(t)) for i in range(system.n)])  # noqa: E731
    grid = np.linspace(0.0, T, 20001)
    xs = x_of(grid)  # (n, len)
    times = [0.0, T]
    for e in system.elements:
        d_e = e.a @ xs
        for level in e.breakpoints:
            f = d_e - level
            for j in np.nonzero(np.sign(f[:-1]) != np.sign(f[1:]))[0]:
                times.append(brentq(lambda t: float(e.a @ x_of(t)[:, 0]) - level, grid[j], grid[j + 1], xtol=1e-15, rtol=1e-15))
    times = np.unique(np.sort(times))
    k = 2 * system.n
    Y = np.eye(k)
    for t0, t1 in zip(times[:-1], times[1:]):
        A = system.stage_matrix(system.stages_of(x_of(0.5 * (t0 + t1))[:, 0]))
        sol = solve_ivp(lambda t, y: (A @ y.reshape(k, k)).ravel(), (t0, t1), Y.ravel(), method="DOP853",
                        rtol=1e-12, atol=1e-14)
        Y = sol.y[:, -1].reshape(k, k)
    return Y


@pytest.mark.parametrize("n", [1, 2, 3])
def test_monodromy_equals_variational_equation(n):
    """Crossings of two (three) elements with their own breakpoints, merged per orbit: the product
    of stage exponentials equals the integrated variational equation, for several orbits at once."""
    system = SYSTEMS[n]()
    H = 4
    X = ORBITS[n](H)
    omegas = np.array([0.7, 1.3, 2.1])
    M, crossings = system_monodromy_batch(system, np.repeat(X[None], 3, axis=0), omegas)
    assert M.shape == (3, 2 * n, 2 * n) and crossings.shape[:2] == (3, system.m)
    # the orbit crosses both breakpoints of the first two elements (twice each per period)
    assert np.all(crossings[:, :2, :2] >= 2), crossings
    for i, w in enumerate(omegas):
        ref = variational_monodromy(system, X, w)
        np.testing.assert_allclose(M[i], ref, rtol=0, atol=1e-9 * max(1.0, np.abs(ref).max()))


def test_eigen_route_equals_expm_and_defective_stage_falls_back():
    system = three_dof()
    combos = np.arange(int(np.prod(system.stage_counts())))
    tau = np.linspace(0.05, 7.0, combos.size)
    E = _stage_exponentials(system, combos[None, :], tau[None, :])[0]
    from rattle.stability._floquet import _combination
    for u, t, e in zip(combos, tau, E):
        np.testing.assert_allclose(e, scipy.linalg.expm(system.stage_matrix(_combination(system, int(u))) * t),
                                   rtol=1e-11, atol=1e-13)
    # A critically damped stage (defective A: V singular) goes through expm.
    crit = System(damping=np.diag([0.2, 0.3]), stiffness=np.diag([0.01, 1.0]),
                  elements=(ReducedElement("c", np.array([1.0, 0.0]), np.array([0.0, 0.0]), Clutch(alpha=0.5, b=0.1)),),
                  mean=np.zeros(2), cos=np.zeros((1, 2)), sin=np.zeros((1, 2)), coordinates=("a", "b"),
                  angles=np.eye(2))
    E = _stage_exponentials(crit, np.array([[0]]), np.array([[3.0]]))[0, 0]
    np.testing.assert_allclose(E, scipy.linalg.expm(crit.stage_matrix((0,)) * 3.0), rtol=1e-12, atol=1e-14)
    # No clearance element at all: the linear system's e^{AT}.
    linear = System(damping=crit.damping, stiffness=np.array([[2.0, -0.5], [-0.5, 1.0]]), elements=(),
                    mean=np.zeros(2), cos=np.zeros((1, 2)), sin=np.zeros((1, 2)), coordinates=("a", "b"),
                    angles=np.eye(2))
    M, crossings = system_monodromy_batch(linear, np.ones((2, 2, 9)), np.array([0.8, 1.9]))
    assert crossings.shape == (2, 0, 0)
    for Mi, w in zip(M, (0.8, 1.9)):
        np.testing.assert_allclose(Mi, scipy.linalg.expm(linear.stage_matrix(()) * 2 * np.pi / w), rtol=1e-11, atol=1e-13)


def test_single_equation_is_the_n1_case_bit_for_bit():
    """The reference model's System through the general core gives the closed-form path's
    monodromy exactly, and the monitor's reading is unchanged (two test functions)."""
    model = reference_case()
    system = model.system()
    basis = FourierBasis(8, 64)
    H = 8
    rng = np.random.default_rng(7)
    k = np.arange(1, H + 1)
    Q = np.zeros((5, 2 * H + 1))
    Q[:, 0] = rng.uniform(-0.1, 0.1, 5)
    Q[:, 1:] = rng.standard_normal((5, 2 * H)) * 0.4 / np.concatenate([k, k]) ** 2
    w = rng.uniform(0.3, 2.0, 5)
    X = basis.synthesize(Q)
    st = model.elastic.stages
    ref = monodromy_batch(Q, w, X, st.breakpoints, model.k * st.slopes, model.c)
    M, crossings = element_monodromy_batch(system, Q[:, None, :], w, X[:, None, :])
    np.testing.assert_array_equal(M, ref)
    assert crossings.shape == (5, 1, 2) and crossings.sum() > 0
    hb = HarmonicBalance(model, HBOptions(harmonics=H, samples=64))
    mon = FloquetMonitor(hb)
    reading = mon(Q[0], w[0], np.zeros(2 * H + 1), 0.0)
    assert reading.values.shape == (2,)
    np.testing.assert_allclose(reading.values, [np.linalg.det(ref[0] - np.eye(2)), np.linalg.det(ref[0] + np.eye(2))],
                               rtol=1e-13)
    assert reading.structure == tuple(int(c) for c in crossings[0, 0])
    assert mon.test_function("fold")(Q[0], w[0]) == pytest.approx(reading.values[0], rel=1e-13)
    # n = 1: the 1 × 1 bialternate product is det M; ψ_ns = det M − 1 = e^{−cT} − 1 < 0 (not monitored)
    assert mon.test_function("neimark_sacker")(Q[0], w[0]) == pytest.approx(np.linalg.det(ref[0]) - 1.0, rel=1e-13)
    np.testing.assert_allclose(second_compound(ref[0]), [[np.linalg.det(ref[0])]], rtol=1e-14)
    with pytest.raises(ValueError, match="`kind`"):
        mon.test_function("torus")


def test_test_functions_are_products_of_multiplier_expressions(rng):
    for k in (2, 4, 6):
        M = rng.standard_normal((20, k, k))
        mu = np.linalg.eigvals(M)
        psi = floquet_test_functions(M)
        assert psi.shape == (20, 2 if k == 2 else 3)
        np.testing.assert_allclose(psi[:, 0], np.prod(mu - 1, axis=1).real, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(psi[:, 1], np.prod(mu + 1, axis=1).real, rtol=1e-9, atol=1e-12)
        if k > 2:
            i, j = np.triu_indices(k, 1)
            np.testing.assert_allclose(psi[:, 2], np.prod(mu[:, i] * mu[:, j] - 1, axis=1).real, rtol=1e-9, atol=1e-12)
            B = second_compound(M)
            assert B.shape == (20, k * (k - 1) // 2, k * (k - 1) // 2)
    # On the chain's exact monodromy as well: ψ_ns vanishes for a pair on the circle.
    M, _ = system_monodromy_batch(two_dof(), ORBITS[2](4)[None], np.array([1.3]))
    mu = multipliers_from_monodromy(M[0])
    assert mu.shape == (4,) and np.all(np.diff(np.abs(mu)) <= 0)
    np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(np.linalg.eigvals(M[0])), rtol=1e-12)
    theta = 0.9
    R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    ns = scipy.linalg.block_diag(R, np.diag([0.3, -0.2]))
    psi = floquet_test_functions(ns)
    assert abs(psi[2]) < 1e-14 and abs(psi[0]) > 0.1 and abs(psi[1]) > 0.1


def _psi_ns_determinant(M):
    """ψ_ns as it was computed before: the LU determinant of M ⊙ M − I (O(k⁶))."""
    B = second_compound(M)
    return np.linalg.det(B - np.eye(B.shape[-1]))


def _factor_scale(M):
    """S = Π_{i<j} (|μ_i||μ_j| + 1): the size of ψ_ns's factors, the scale of its round-off."""
    a = np.abs(np.linalg.eigvals(M))
    i, j = np.triu_indices(M.shape[-1], 1)
    return np.prod(a[..., i] * a[..., j] + 1.0, axis=-1)


def test_neimark_sacker_function_from_multipliers_equals_the_bialternate_determinant(rng):
    """ψ_ns from the multipliers (O(k³)) against det(M ⊙ M − I) (O(k⁶)) on random monodromies:
    the same values up to round-off on the scale S of its factors, hence the same signs, and the
    same zeros (a complex pair on the unit circle, a neutral saddle), changing sign together."""
    for k in (4, 6, 8, 12):
        M = rng.standard_normal((300, k, k)) * rng.uniform(0.3, 1.5, (300, 1, 1)) / np.sqrt(k)
        new, old = floquet_test_functions(M)[:, 2], _psi_ns_determinant(M)
        S = _factor_scale(M)
        # both are backward stable: measured max |new − old| / S = 9e-16 (k = 4 … 12, 300 draws each);
        # 1e-14 leaves a factor 10. Where |ψ_ns| exceeds twice that the signs must agree.
        assert np.all(np.abs(new - old) <= 1e-14 * S)
        clear = np.abs(old) > 2e-14 * S
        assert clear.mean() > 0.8 and np.all(np.sign(new[clear]) == np.sign(old[clear]))
    # zeros: a pair r e^{±iθ} in a random basis, through r = 1; a neutral saddle (μ, 1/μ)
    theta = 0.9
    R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    for k in (4, 8):
        V = rng.standard_normal((k, k))
        rest = np.diag(rng.uniform(-0.8, 0.8, k - 2))
        signs = []
        for r in (0.999, 1.0, 1.001):
            M = V @ scipy.linalg.block_diag(r * R, rest) @ np.linalg.inv(V)
            new, old, S = floquet_test_functions(M)[2], _psi_ns_determinant(M), _factor_scale(M)
            if r == 1.0:
                assert abs(new) <= 1e-11 * S and abs(old) <= 1e-11 * S
            else:
                assert abs(new) > 1e-6 * S and np.sign(new) == np.sign(old)
                signs.append(np.sign(new))
        assert signs[0] == -signs[1]
        saddle = V @ np.diag([2.5, 0.4, *rng.uniform(-0.8, 0.8, k - 2)]) @ np.linalg.inv(V)
        assert abs(floquet_test_functions(saddle)[2]) <= 1e-11 * _factor_scale(saddle)
    # a pair meeting the real axis away from the circle (b c through 0, |μ| ≈ 0.83): no zero, one sign
    for k in (4, 6):
        V = rng.standard_normal((k, k))
        rest = np.diag(rng.uniform(-0.5, 0.5, k - 2))
        vals = []
        for bc in np.linspace(-1e-3, 1e-3, 21):
            M = V @ scipy.linalg.block_diag([[0.83, 1.0], [bc, 0.83]], rest) @ np.linalg.inv(V)
            vals.append((floquet_test_functions(M)[2], _psi_ns_determinant(M)))
        vals = np.array(vals)
        assert len({*np.sign(vals[:, 0])}) == 1 and np.all(np.sign(vals[:, 0]) == np.sign(vals[:, 1]))
        np.testing.assert_allclose(vals[:, 0], vals[:, 1], rtol=1e-12)


def test_classification_and_torus_ratio_of_synthetic_multipliers():
    theta = 2 * np.pi * 0.137
    pair = lambda r: [r * np.exp(1j * theta), r * np.exp(-1j * theta)]  # noqa: E731
    before = np.array(pair(0.98) + [0.5, -0.2])
    after = np.array(pair(1.02) + [0.5, -0.2])
    assert not is_stable(after) and is_stable(before)
    assert classify_loss(before, after) == "neimark_sacker"
    assert classify_loss(after, before) == "neimark_sacker"
    assert torus_ratio(after) == pytest.approx(0.137, abs=1e-12)
    # a pair in the left half plane: θ ∈ (π/2, π), ratio ∈ (0.25, 0.5)
    left = np.array([1.01 * np.exp(2.8j), 1.01 * np.exp(-2.8j), 0.1, 0.05])
    assert torus_ratio(left) == pytest.approx(2.8 / (2 * np.pi), abs=1e-12)
    np.testing.assert_allclose(torus_ratio(np.stack([after, left])), [0.137, 2.8 / (2 * np.pi)], atol=1e-12)
    assert np.isnan(torus_ratio(np.array([0.5, 0.2, -0.3, 0.1])))
    # real multipliers through +1 and −1, with a complex pair inside the circle beside them
    assert classify_loss(np.array(pair(0.6) + [0.99, 0.1]), np.array(pair(0.6) + [1.01, 0.1])) == "fold"
    assert classify_loss(np.array(pair(0.6) + [-0.99, 0.1]), np.array(pair(0.6) + [-1.01, 0.1])) == "period_doubling"
    # distance to the critical set: the complex pair's distance to the circle counts for n ≥ 2
    assert critical_distance(np.array(pair(0.97) + [0.5, 0.1])) == pytest.approx(0.03, abs=1e-12)
    assert critical_distance(np.array([0.97j, -0.97j])) == pytest.approx(abs(0.97j - 1), abs=1e-12)


def _pad(X: np.ndarray, H: int) -> np.ndarray:
    h = (X.shape[1] - 1) // 2
    out = np.zeros((X.shape[0], 2 * H + 1))
    out[:, : h + 1] = X[:, : h + 1]
    out[:, H + 1 : H + 1 + h] = X[:, h + 1 :]
    return out


def test_hill_jacobian_is_the_galerkin_linearisation():
    """J q-derivative check: J equals the finite-difference Jacobian of the N-DOF HB residual
    R(X) = ∇²X + C∇X + KX + Σ b_e Γ*f_e(Γ a_e·X) away from the kinks."""
    system = two_dof()
    H = 5
    basis = FourierBasis(H, 64)
    X = _pad(ORBITS[2](4), H)
    w = 1.1
    J, _ = system_hill_matrices(system, basis, X, w)
    nabla = basis.derivative_matrix(w)

    def residual(x):
        x = x.reshape(2, -1)
        out = x @ (nabla @ nabla).T + system.damping @ x @ nabla.T + system.stiffness @ x
        for e in system.elements:
            out = out + np.outer(e.b, basis.analyze(e.law.force(basis.synthesize(e.a @ x))))
        return out.ravel()

    eps = 1e-7
    fd = np.column_stack([(residual(X.ravel() + eps * v) - residual(X.ravel() - eps * v)) / (2 * eps)
                          for v in np.eye(X.size)])
    np.testing.assert_allclose(J, fd, rtol=0, atol=1e-6)


def test_hill_agrees_with_monodromy_for_two_coordinates():
    """Inside one stage (no crossing) Hill's method is exact: e^{λT}, λ the stage's eigenvalues.
    On an orbit crossing breakpoints of both elements it converges slowly (the stiffness jumps in
    time): the largest relative distance to the exact monodromy's multipliers was measured
    3e-2, 2e-3, 8e-3 at Ω = 0.7, 1.3, 2.1 for H = 24, and 9e-4, 2e-3, 2e-4 for H = 96."""
    system = two_dof()
    H = 24
    basis = FourierBasis(H, 4 * (2 * H + 1))
    w = 1.3
    T = 2 * np.pi / w
    small = _pad(0.01 * ORBITS[2](4), H)
    hill = system_hill_multipliers(system, basis, small, w)
    exact = np.exp(np.linalg.eigvals(system.stage_matrix(system.stages_of(np.zeros(2)))) * T)
    np.testing.assert_allclose(np.sort_complex(hill), np.sort_complex(exact), rtol=1e-9, atol=1e-12)
    M, _ = system_monodromy_batch(system, small[None], np.array([w]))
    np.testing.assert_allclose(np.sort_complex(multipliers_from_monodromy(M[0])), np.sort_complex(exact), atol=1e-12)
    for omega in (0.7, 1.3, 2.1):
        X = _pad(ORBITS[2](4), H)
        hill = system_hill_multipliers(system, basis, X, omega)
        M, _ = system_monodromy_batch(system, X[None], np.array([omega]))
        mono = multipliers_from_monodromy(M[0])
        assert hill.shape == (4,)
        # every exact multiplier has a Hill multiplier next to it
        dist = np.abs(hill[:, None] - mono[None, :]) / np.maximum(1.0, np.abs(mono))
        assert np.max(np.min(dist, axis=0)) < 0.05, (omega, hill, mono)
        assert (np.max(np.abs(hill)) < 1) == (np.max(np.abs(mono)) < 1)


def _stand_in_hb(system: System, H: int, samples: int):
    """What FloquetMonitor reads of a harmonic-balance problem: ``system``, ``basis``, ``period``."""
    from types import SimpleNamespace

    return SimpleNamespace(system=system, basis=FourierBasis(H, samples), period=1, model=None)


def test_monitor_reads_three_test_functions_with_slopes_and_structure():
    system = two_dof()
    H = 6
    hb = _stand_in_hb(system, H, 64)
    mon = FloquetMonitor(hb)
    assert mon.names == ("fold", "period_doubling", "neimark_sacker")
    q = _pad(ORBITS[2](4), H).ravel()
    d = np.zeros_like(q)
    d[[1, 2 * H + 2, 3]] = [0.6, -0.5, 0.3]
    d /= np.linalg.norm(d)
    omega = 1.3
    reading = mon(q, omega, d, 0.2)
    M, crossings = system_monodromy_batch(system, q.reshape(1, 2, -1), np.array([omega]))
    np.testing.assert_allclose(reading.values, floquet_test_functions(M[0]), rtol=1e-10)
    assert reading.structure == tuple(crossings[0].ravel()) and len(reading.structure) == 4
    h = 1e-5
    plus = mon.test_functions(q + h * d, omega + 0.2 * h)
    minus = mon.test_functions(q - h * d, omega - 0.2 * h)
    np.testing.assert_allclose(reading.slopes, (plus - minus) / (2 * h), rtol=1e-4, atol=1e-6)
    assert mon.test_function("neimark_sacker")(q, omega) == pytest.approx(reading.values[2], rel=1e-12)
    mu = multipliers_from_monodromy(M[0])
    assert reading.distance == pytest.approx(critical_distance(mu))


def test_neimark_sacker_located_and_labelled_with_its_torus_ratio():
    """A 2-coordinate system with modal damping c₁ on its first mode: at c₁ = 0 the first mode's
    pair e^{±iω₁T} is on the unit circle. ψ_ns changes sign there (neither ψ_fold nor ψ_pd does),
    the zero located by the monitor's test function is c₁ = 0, the loss is labelled
    neimark_sacker and the torus ratio is ω₁/ω folded into [0, 0.5]."""
    K = np.array([[2.0, -0.5], [-0.5, 1.0]])
    lam, V = np.linalg.eigh(K)
    w1 = np.sqrt(lam[0])
    omega = 1.7

    def system(c1):
        C = V @ np.diag([c1, 0.1]) @ V.T
        far = ReducedElement("clutch", np.array([1.0, -1.0]), np.array([0.0, 0.0]), Clutch(alpha=0.5, b=0.5))
        return System(damping=C, stiffness=K, elements=(far,), mean=np.zeros(2), cos=np.zeros((1, 2)),
                      sin=np.zeros((1, 2)), coordinates=("a", "b"), angles=np.eye(2))

    H = 4
    q = np.zeros(2 * (2 * H + 1))
    q[1] = 0.1  # a small orbit, far from the element's breakpoints

    def psi(c1, kind="neimark_sacker"):
        return FloquetMonitor(_stand_in_hb(system(c1), H, 32)).test_function(kind)(q, omega)

    assert psi(-0.01) * psi(0.01) < 0
    for kind in ("fold", "period_doubling"):
        assert psi(-0.01, kind) * psi(0.01, kind) > 0
    c_star = brentq(psi, -0.01, 0.01, xtol=1e-14)
    assert abs(c_star) < 1e-10
    mon = FloquetMonitor(_stand_in_hb(system(0.01), H, 32))
    before = multipliers_from_monodromy(mon.monodromy(q, omega))
    after = multipliers_from_monodromy(FloquetMonitor(_stand_in_hb(system(-0.01), H, 32)).monodromy(q, omega))
    assert is_stable(before) and not is_stable(after)
    assert classify_loss(before, after) == "neimark_sacker"
    at = multipliers_from_monodromy(FloquetMonitor(_stand_in_hb(system(c_star), H, 32)).monodromy(q, omega))
    ratio = (w1 / omega) % 1.0
    assert torus_ratio(at) == pytest.approx(min(ratio, 1.0 - ratio), abs=1e-10)


def test_on_harmonic_balance_orbits_of_a_forced_chain():
    """On converged HB orbits of the forced two-inertia chain: the Hill matrix built here from the
    System equals the HB problem's own Jacobian ∂R/∂q, the monitor reads the real HB problem
    (``hb.system``, coordinate-major q), and Hill's multipliers agree with the monodromy's. At
    Ω = 1.2 a complex pair is outside the unit circle (ψ_ns < 0; measured |μ| = 1.06)."""
    from rattle.hb import NewtonOptions, solve_harmonic_balance
    from rattle.stability import hill_multipliers

    class Holder:
        def __init__(self, system):
            self._system = system

        def system(self):
            return self._system

    system = grounded_chain([1.0, 2.0], 1.0, 0.05, [(0, 1, 0.3, 0.02)],
                            [("clutch", [1.0, -1.0], 2.0, Clutch(alpha=0.25, b=0.15)),
                             ("gear", [0.0, 1.0], 1.5, Backlash(b=0.1))], torque=[0.3, 0.0])
    hb = HarmonicBalance(Holder(system), HBOptions(harmonics=16))
    signs = []
    for omega in (0.9, 1.2):
        res = solve_harmonic_balance(hb, hb.linear_solution(omega), omega, NewtonOptions())
        assert res.converged
        q = res.q
        X = q.reshape(2, -1)
        J, _ = system_hill_matrices(system, hb.basis, X, omega)
        np.testing.assert_allclose(J, hb.residual_jacobian(q, omega)[1], rtol=0, atol=1e-11)
        M, crossings = system_monodromy_batch(system, X[None], np.array([omega]))
        assert np.all(crossings[0] >= 2)  # both elements cross both breakpoints
        reading = FloquetMonitor(hb)(q, omega, np.eye(q.size)[1], 0.0)
        np.testing.assert_allclose(reading.values, floquet_test_functions(M[0]), rtol=1e-9)
        mono = multipliers_from_monodromy(M[0])
        hill = hill_multipliers(hb, q, omega)
        dist = np.abs(hill[:, None] - mono[None, :])
        assert np.max(np.min(dist, axis=0)) < 1e-2, (omega, hill, mono)
        signs.append(np.sign(reading.values[2]))
    assert signs == [1.0, -1.0]
