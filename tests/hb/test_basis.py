"""Fourier basis: DFT round trip and derivative-operator identities."""

from __future__ import annotations

import numpy as np
import pytest

from rattle.hb import FourierBasis


def test_synthesis_analysis_round_trip(rng):
    basis = FourierBasis(12, 64)
    q = rng.standard_normal(basis.size)
    # Analysis of exactly band-limited samples returns the coefficients to round-off.
    np.testing.assert_allclose(basis.analyze(basis.synthesize(q)), q, rtol=0, atol=1e-13)


def test_synthesis_matches_direct_evaluation(rng):
    basis = FourierBasis(7, 40)
    q = rng.standard_normal(basis.size)
    w = 1.3
    t = basis.times(2 * np.pi / w)
    np.testing.assert_allclose(basis.synthesize(q), basis.evaluate(q, w, t), rtol=0, atol=1e-13)


@pytest.mark.parametrize("order", [1, 2, 3, 4])
def test_derivative_operator_matches_analytic_derivatives(rng, order):
    basis = FourierBasis(6, 32)
    q = rng.standard_normal(basis.size)
    w = 0.7
    D = basis.derivative_matrix(w)
    dq = np.linalg.matrix_power(D, order) @ q
    t = rng.uniform(0, 10, 9)
    np.testing.assert_allclose(basis.evaluate(dq, w, t), basis.evaluate(q, w, t, derivative=order), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(basis.derivative(q, w), D @ q, rtol=0, atol=1e-14)


def test_complex_conversion_round_trip(rng):
    basis = FourierBasis(5, 16)
    q = rng.standard_normal(basis.size)
    np.testing.assert_array_equal(basis.from_complex(basis.to_complex(q)), q)


def test_resize_harmonics_pads_truncates_and_embeds(rng):
    from rattle.hb import resize_harmonics

    q = rng.standard_normal(2 * 5 + 1)
    np.testing.assert_array_equal(resize_harmonics(resize_harmonics(q, 9), 5), q)  # pad, truncate
    # Written with base ω/2 (harmonic k → 2k), the series has the same samples over two periods.
    x1 = FourierBasis(5, 64).synthesize(q)
    x2 = FourierBasis(10, 128).synthesize(resize_harmonics(q, 10, factor=2))
    np.testing.assert_allclose(x2, np.concatenate([x1, x1]), rtol=0, atol=1e-13)
    Q = rng.standard_normal((3, 11))
    np.testing.assert_array_equal(resize_harmonics(Q, 8)[1], resize_harmonics(Q[1], 8))  # row-wise
