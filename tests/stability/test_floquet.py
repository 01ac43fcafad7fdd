"""Stability: stage transitions, linear multipliers, Hill vs monodromy, classification."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from rattle import frequency_response
from rattle.hb import HarmonicBalance, HBOptions, solve_harmonic_balance
from rattle.model import Excitation, Linear, Model
from rattle.stability import classify_loss, hill_multipliers, monodromy, multipliers_from_monodromy, stage_transition


def set_distance(a, b) -> float:
    """Distance between two pairs of multipliers as unordered sets (max over the best pairing)."""
    a, b = np.asarray(a), np.asarray(b)
    return min(np.max(np.abs(a - b)), np.max(np.abs(a - b[::-1])))


@pytest.mark.parametrize("kappa, c", [(1.0, 0.05), (0.25, 0.05), (0.0, 0.05), (0.0, 0.0), (1e-4, 0.3), (0.0225, 0.3), (2.0, 0.0)])
def test_stage_transition_equals_expm(kappa, c):
    # Under-, over- and critically damped (κ = c²/4 = 0.0225), zero stiffness, undamped.
    A = np.array([[0.0, 1.0], [-kappa, -c]])
    for tau in (0.0, 0.3, 7.0, 40.0):
        np.testing.assert_allclose(stage_transition(kappa, c, tau), scipy.linalg.expm(A * tau), rtol=1e-12, atol=1e-14)


def test_multipliers_closed_form_matches_eig(rng):
    M = rng.standard_normal((200, 2, 2))
    mu = multipliers_from_monodromy(M)
    ref = np.linalg.eigvals(M)
    ref = np.take_along_axis(ref, np.argsort(-np.abs(ref), axis=1, kind="stable"), axis=1)
    np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(ref), rtol=1e-10, atol=1e-12)


def test_linear_multipliers_are_exp_lambda_T():
    model = Model(inertia=1.0, damping=0.1, stiffness=1.0, elastic=Linear(), excitation=Excitation(mean=0.0, amplitudes=(0.05,)))
    frf = frequency_response(model, omega=(0.2, 2.0), harmonics=4)
    lam = np.roots([1.0, 0.1, 1.0])
    for i in range(0, len(frf), 7):
        T = 2 * np.pi / frf.omega[i]
        expected = np.exp(lam * T)
        assert set_distance(frf.multipliers[i], expected) < 1e-13
        # Hill's method with the eigenvector selection gives the same pair.
        hb = HarmonicBalance(model, HBOptions(harmonics=4))
        assert set_distance(hill_multipliers(hb, frf.coefficients[i], frf.omega[i]), expected) < 1e-10


def test_determinant_of_monodromy_is_exp_minus_cT(reference_frf):
    """Every stage matrix has trace −c, so det M = exp(−c T) for every orbit (Liouville)."""
    m = reference_frf.model
    T = 2 * np.pi / reference_frf.omega
    prod = np.prod(reference_frf.multipliers, axis=1)
    np.testing.assert_allclose(prod.real, np.exp(-m.c * T), rtol=1e-10)
    np.testing.assert_allclose(prod.imag, 0.0, atol=1e-12)


def test_no_neimark_sacker_in_a_single_dof_system(reference_frf):
    # det M = exp(−cT) < 1: a complex pair has |μ|² = det M < 1 and never reaches the circle.
    assert "neimark_sacker" not in set(reference_frf.bifurcation)
    complex_pairs = np.abs(reference_frf.multipliers[:, 0].imag) > 0
    assert np.all(np.abs(reference_frf.multipliers[complex_pairs]) < 1.0)


def test_classification_of_crossings():
    assert classify_loss(np.array([0.99, 0.3]), np.array([1.01, 0.3])) == "fold"
    assert classify_loss(np.array([-0.99, 0.3]), np.array([-1.01, 0.3])) == "period_doubling"
    assert classify_loss(np.array([1.01, 0.3]), np.array([0.99, 0.3])) == "fold"  # regaining
    assert classify_loss(np.array([0.99j, -0.99j]), np.array([1.01j, -1.01j])) == "neimark_sacker"


def test_hill_agrees_with_monodromy_away_from_bifurcations(reference_frf):
    """Hill's method (eigenvector-centroid selection) vs the exact monodromy of the HB orbit.

    Hill's truncated spectrum converges slowly for a stiffness that jumps in time: against the
    exact shooting orbits its multipliers are off by 2.7e-3 (median) and up to 3e-2 at H = 32,
    twenty times the monodromy's error (1.4e-4 median) — which is why the monodromy is primary.
    What must agree is the stability verdict wherever the critical multiplier is not within
    that error of the unit circle, and the multipliers within it."""
    frf = reference_frf
    hb = HarmonicBalance(frf.model, HBOptions(harmonics=32))
    checked = 0
    for i in range(0, len(frf), 18):
        mono = frf.multipliers[i]
        if abs(np.abs(mono[0]) - 1.0) < 0.05:
            continue
        hill = hill_multipliers(hb, frf.coefficients[i], frf.omega[i])
        assert (np.max(np.abs(hill)) < 1) == frf.stable[i], (frf.omega[i], mono, hill)
        assert set_distance(hill, mono) < 0.05
        checked += 1
    assert checked > 25


def test_monodromy_single_matches_batch(reference_frf):
    frf = reference_frf
    m = frf.model
    hb = HarmonicBalance(m, HBOptions(harmonics=32))
    st = m.elastic.stages
    for i in (0, len(frf) // 3, len(frf) // 2, len(frf) - 1):
        M = monodromy(hb.basis, frf.coefficients[i], frf.omega[i], st.breakpoints, m.k * st.slopes, m.c)
        np.testing.assert_allclose(multipliers_from_monodromy(M), frf.multipliers[i], rtol=1e-12, atol=1e-14)


def test_crossing_times_are_roots_to_round_off(rng):
    """Every refined crossing satisfies δ(t_c) = d to round-off, over many random orbits (a
    Newton step that lands exactly on the root must not be moved by the bracket update)."""
    from rattle.hb import FourierBasis
    from rattle.stability import crossing_times_batch

    H, N, P = 16, 256, 400
    basis = FourierBasis(H, N)
    k = np.arange(1, H + 1)
    Q = np.zeros((P, 2 * H + 1))
    Q[:, 1:] = rng.standard_normal((P, 2 * H)) / np.concatenate([k, k]) ** 3
    w = rng.uniform(0.2, 3.0, P)
    X = np.array([basis.synthesize(q) for q in Q])
    levels = np.array([-0.3, 0.0, 0.2])
    p, t, lvl = crossing_times_batch(Q, w, X, levels)
    assert p.size > 1000
    values = np.array([basis.evaluate(Q[i], w[i], np.array([ti]))[0] for i, ti in zip(p, t)])
    # Refinement stops when the Newton update is below 64 eps T (≤ 4e-13 s here) and |δ'| ≲ 1.
    np.testing.assert_allclose(values, lvl, rtol=0, atol=1e-12)


def test_hill_multipliers_keep_the_single_dof_structure():
    """Hill's exponent has truncation errors in both parts; without projecting the pair onto the
    admissible structures (a conjugate pair on |μ| = e^{−cT/2}, or two reals with product
    e^{−cT}) a period doubling came out as 'neimark_sacker' (measured at H = 16: Ω 0.407, 0.460)."""
    from rattle import frequency_response, reference_case

    model = reference_case()
    frf = frequency_response(model, omega=(0.3, 0.6), harmonics=16, stability="hill")
    kinds = {s.kind for s in frf.special_points}
    assert "neimark_sacker" not in kinds and "period_doubling" in kinds
    T = 2 * np.pi / frf.omega
    np.testing.assert_allclose(np.prod(frf.multipliers, axis=1).real, np.exp(-model.c * T), rtol=1e-9)
    complex_pair = np.abs(frf.multipliers[:, 0].imag) > 0
    expected = np.exp(-0.5 * model.c * T[complex_pair])[:, None] * np.ones((1, 2))
    np.testing.assert_allclose(np.abs(frf.multipliers[complex_pair]), expected, rtol=1e-9)


@pytest.mark.parametrize("slopes,c", [((1.0, 0.25, 1.0), 0.05), ((1.0, 0.0, 3.0), 0.3), ((0.01, 0.0, 0.01), 0.5)])
def test_compiled_monodromy_matches_array_code(rng, monkeypatch, slopes, c):
    """The compiled single-element kernel (stability._kernels) and the array code of _floquet
    give the same crossings and monodromies (oscillatory, free, overdamped and critically
    damped stages) on random orbits."""
    from rattle.hb import FourierBasis
    from rattle.stability import _kernels, monodromy_and_crossings_batch

    if not _kernels.AVAILABLE:
        pytest.skip("numba not installed: only the array code runs")
    H, N, P = 12, 128, 60
    basis = FourierBasis(H, N)
    k = np.arange(1, H + 1)
    Q = np.zeros((P, 2 * H + 1))
    Q[:, 0] = rng.uniform(-0.2, 0.2, P)
    Q[:, 1:] = rng.standard_normal((P, 2 * H)) / np.concatenate([k, k]) ** 2
    w = rng.uniform(0.2, 3.0, P)
    X = basis.synthesize(Q)
    bp = np.array([-0.1, 0.1])
    kappa = np.array(slopes)
    kappa[1] = c**2 / 4 if slopes[1] == 0.0 and c == 0.5 else kappa[1]  # one critically damped stage
    M_k, n_k = _kernels.monodromies(Q, w, X, bp, kappa, c)
    monkeypatch.setattr(_kernels, "AVAILABLE", False)
    M_a, n_a = monodromy_and_crossings_batch(Q, w, X, bp, kappa, c)
    assert n_k.sum() > P  # the orbits do cross the breakpoints
    np.testing.assert_array_equal(n_k, n_a)
    scale = np.abs(M_a).max(axis=(1, 2), keepdims=True)
    np.testing.assert_allclose(M_k / scale, M_a / scale, rtol=0, atol=1e-12)


def test_single_equation_reading_matches_the_general_one(reference_frf):
    """FloquetMonitor's 2 × 2 closed forms (ψ, slopes, distance) for the single equation agree
    with the general formulas (determinants, multipliers) that chains use."""
    from rattle.stability import FloquetMonitor, critical_distance, floquet_test_functions

    frf = reference_frf
    mon = FloquetMonitor(HarmonicBalance(frf.model, HBOptions(harmonics=32)))
    d = np.linspace(-1.0, 1.0, frf.coefficients.shape[1]) * 1e-3
    for i in range(0, len(frf), 97):
        q, w = frf.coefficients[i], frf.omega[i]
        reading = mon(q, w, d, 1e-3)
        M = mon.monodromy(q, w)
        psi = floquet_test_functions(M)
        np.testing.assert_allclose(reading.values, psi, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(psi, [np.linalg.det(M - np.eye(2)), np.linalg.det(M + np.eye(2))], rtol=1e-10, atol=1e-13)
        slopes = (floquet_test_functions(mon.monodromy(q + 1e-7 * d, w + 1e-10)) - psi) / 1e-7
        np.testing.assert_allclose(reading.slopes, slopes, rtol=1e-6, atol=1e-8)
        assert reading.distance == pytest.approx(critical_distance(multipliers_from_monodromy(M)), rel=1e-12, abs=1e-14)


def test_frequency_response_without_the_compiled_kernels_is_the_same(monkeypatch):
    """Without numba (hb._kernels and stability._kernels unavailable) the array code gives the
    same branch and special points (the compiled kernels are accelerators, not a second method)."""
    from rattle import reference_case
    from rattle.hb import _kernels as hb_kernels
    from rattle.stability import _kernels as st_kernels

    if not (hb_kernels.AVAILABLE and st_kernels.AVAILABLE):
        pytest.skip("numba not installed: only the array code runs")
    model = reference_case()
    compiled = frequency_response(model, omega=(0.3, 1.5), harmonics=12)
    monkeypatch.setattr(hb_kernels, "AVAILABLE", False)
    monkeypatch.setattr(st_kernels, "AVAILABLE", False)
    array = frequency_response(model, omega=(0.3, 1.5), harmonics=12)
    assert len(compiled.special_points) >= 2
    assert [s.kind for s in compiled.special_points] == [s.kind for s in array.special_points]
    # Round-off in the monodromy moves the continuation's steps by ~1e-14; the located points
    # are roots of the test functions, the same to the locator's tolerance.
    np.testing.assert_allclose([s.omega for s in compiled.special_points], [s.omega for s in array.special_points],
                               rtol=0, atol=1e-9)


def test_compiled_monodromy_finds_a_crossing_between_the_last_sample_and_the_period(monkeypatch):
    """A crossing between the last sample t_{N−1} and T (the samples' wrap) is found by the
    compiled scan as by the array code, with the same monodromy."""
    from rattle.hb import FourierBasis
    from rattle.stability import _kernels, monodromy_and_crossings_batch

    if not _kernels.AVAILABLE:
        pytest.skip("numba not installed: only the array code runs")
    H, N = 4, 64
    basis = FourierBasis(H, N)
    phi = 0.3 * 2 * np.pi / N  # δ = 0.15 sin(ωt + φ) crosses 0 upwards at T − φ/ω, after t_{N−1}
    Q = np.zeros((1, 2 * H + 1))
    Q[0, 1], Q[0, H + 1] = 0.15 * np.sin(phi), 0.15 * np.cos(phi)
    w, bp, kappa = np.array([0.7]), np.array([0.0, 0.1]), np.array([1.0, 2.0, 3.0])
    X = basis.synthesize(Q)
    assert X[0, -1] < 0.0 < X[0, 0]
    M_k, n_k = _kernels.monodromies(Q, w, X, bp, kappa, 0.05)
    monkeypatch.setattr(_kernels, "AVAILABLE", False)
    M_a, n_a = monodromy_and_crossings_batch(Q, w, X, bp, kappa, 0.05)
    np.testing.assert_array_equal(n_k, [[2, 2]])
    np.testing.assert_array_equal(n_k, n_a)
    np.testing.assert_allclose(M_k, M_a, rtol=0, atol=1e-12 * np.abs(M_a).max())


def test_a_batch_reads_the_monodromies_the_readings_computed(reference_frf):
    """FloquetMonitor remembers the orbits of its readings and test functions: a batch over
    them (the multipliers of a branch's points) takes those monodromies, identical to a fresh
    computation, and computes the orbits it has not seen."""
    from rattle.stability import FloquetMonitor

    frf = reference_frf
    hb = HarmonicBalance(frf.model, HBOptions(harmonics=32))
    mon = FloquetMonitor(hb)
    d = np.linspace(-1.0, 1.0, frf.coefficients.shape[1]) * 1e-3
    seen = list(range(0, len(frf), 50))
    for i in seen:
        mon(frf.coefficients[i], frf.omega[i], d, 1e-3)
    assert len(mon._memo) >= len(seen)
    rows = np.arange(0, len(frf), 25)  # half of them seen
    M, counts = mon.monodromy_and_crossings(frf.coefficients[rows], frf.omega[rows])
    M0, counts0 = FloquetMonitor(hb).monodromy_and_crossings(frf.coefficients[rows], frf.omega[rows])
    np.testing.assert_array_equal(M, M0)
    np.testing.assert_array_equal(counts, counts0)
