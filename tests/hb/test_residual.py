"""Harmonic-balance residual: Jacobians, the linear closed form, sampling and scaling."""

from __future__ import annotations

import numpy as np
import pytest

from rattle.hb import HarmonicBalance, HBOptions, NewtonOptions, solve_harmonic_balance
from rattle.model import Backlash, Clutch, Excitation, Linear, Model, Piecewise, reference_case

ASYMMETRIC = Piecewise(breakpoints=(-0.3, -0.1, 0.05, 0.2), slopes=(1.0, 0.3, 0.05, 0.3, 1.0))


def _model(law, mean=0.05, amplitudes=(0.03,), phases=None):
    return Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=law,
                 excitation=Excitation(mean=mean, amplitudes=amplitudes, phases=phases))


def _central_jacobian(hb, q, omega, h=1e-7):
    n = q.size
    J = np.empty((n, n))
    for i in range(n):
        e = np.zeros(n)
        e[i] = h
        J[:, i] = (hb.residual(q + e, omega) - hb.residual(q - e, omega)) / (2 * h)
    dw = (hb.residual(q, omega + h) - hb.residual(q, omega - h)) / (2 * h)
    return J, dw


@pytest.mark.parametrize("law", [Linear(), Clutch(alpha=0.25, b=0.17), Backlash(b=0.1), ASYMMETRIC])
@pytest.mark.parametrize("period", [1, 2])
def test_jacobians_match_central_differences(rng, law, period):
    model = _model(law, amplitudes=(0.03, 0.01), phases=(0.0, 0.4))
    hb = HarmonicBalance(model, HBOptions(harmonics=8, samples=64), period=period)
    for _ in range(3):
        q = hb.linear_solution(0.8) + 0.05 * rng.standard_normal(hb.size)
        omega = rng.uniform(0.3, 2.0)
        _, Rq, Rw = hb.residual_jacobian(q, omega)
        Jn, dwn = _central_jacobian(hb, q, omega)
        # The discrete residual is piecewise linear in q: the central difference is exact unless a
        # sample crosses a breakpoint within ±h, which the random states make improbable; the
        # tolerance is the difference's round-off, eps·|R|/h ≈ 1e-16·10/1e-7 = 1e-8.
        np.testing.assert_allclose(Rq, Jn, rtol=0, atol=1e-7)
        np.testing.assert_allclose(Rw, dwn, rtol=0, atol=1e-7)


def test_force_jacobian_is_gamma_star_diag_gamma(rng):
    hb = HarmonicBalance(reference_case(), HBOptions(harmonics=6, samples=32))
    q = hb.linear_solution(0.7) + 0.05 * rng.standard_normal(hb.size)
    I_n, I_N = np.eye(hb.size), np.eye(hb.basis.samples)
    Gamma = np.stack([hb.basis.synthesize(I_n[i]) for i in range(hb.size)], axis=1)
    Gamma_star = np.stack([hb.basis.analyze(I_N[j]) for j in range(hb.basis.samples)], axis=1)
    g = hb.stiffness_samples(q)
    explicit = Gamma_star @ np.diag(g) @ Gamma
    np.testing.assert_allclose(hb.force_jacobian_from_stiffness(g), explicit, rtol=0, atol=1e-14)


@pytest.mark.parametrize("omega", [0.3, 0.99, 1.0, 2.5])
def test_linear_law_equals_closed_form_to_round_off(omega):
    model = _model(Linear(), mean=0.2, amplitudes=(0.03, 0.02, 0.01), phases=(0.1, -0.7, 2.0))
    hb = HarmonicBalance(model, HBOptions(harmonics=5))
    # δ = F_m/k + Σ_n Re[F_n e^{iφ_n} e^{inΩt} / (k − (nΩ)² + i c nΩ)], written out by hand.
    expected = np.zeros(hb.size)
    expected[0] = 0.2
    for n, (F, phi) in enumerate(zip((0.03, 0.02, 0.01), (0.1, -0.7, 2.0)), start=1):
        X = F * np.exp(1j * phi) / (1.0 - (n * omega) ** 2 + 1j * 0.05 * n * omega)
        expected[n] = X.real
        expected[5 + n] = -X.imag
    res = solve_harmonic_balance(hb, np.zeros(hb.size), omega)
    assert res.converged and res.iterations <= 2  # linear: one Newton step solves it
    np.testing.assert_allclose(res.q, expected, rtol=0, atol=1e-15 * np.max(np.abs(expected)) * 50)
    np.testing.assert_allclose(hb.residual(expected, omega), 0.0, atol=1e-15)


def test_forcing_sits_at_harmonic_n_times_period():
    model = _model(Linear(), amplitudes=(0.03, 0.02), phases=(0.5, 0.0))
    hb = HarmonicBalance(model, HBOptions(harmonics=6), period=3)
    nz = np.nonzero(hb.forcing)[0]
    H = 6
    assert set(nz) == {0, 3, 6, H + 3}  # cos/sin of harmonic 3 (phase), cos of harmonic 6
    assert hb.forcing[H + 3] == pytest.approx(-0.03 * np.sin(0.5))


def test_too_few_harmonics_for_the_excitation_is_refused():
    model = _model(Linear(), amplitudes=(0.03, 0.02))
    with pytest.raises(ValueError, match=r"`harmonics` must be >= 4"):
        HarmonicBalance(model, HBOptions(harmonics=3), period=2)


@pytest.mark.parametrize("kwargs, match", [
    (dict(harmonics=0), r"`harmonics` must be >= 1"),
    (dict(harmonics=8, samples=20), r"`samples` must be >= 4\*harmonics \+ 2 = 34"),
    (dict(harmonics=2.0), r"`harmonics` must be an integer"),
])
def test_hb_options_validation(kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        HBOptions(**kwargs)


def test_doubling_the_samples_no_longer_changes_the_response(reference_frf):
    """The default sample count is converged: with 2N samples the rms at the reference points
    (the whole branch, thinned) changes by < 1e-4 relative, 10× below the 0.1 % target, and
    the special points (folds, period doublings) move by < 1e-6 in Ω."""
    from rattle import frequency_response

    frf = reference_frf
    N = frf.settings["samples"]
    hb2 = HarmonicBalance(frf.model, HBOptions(harmonics=32, samples=2 * N))
    worst, checked = 0.0, 0
    # At a fold tip Newton at fixed Ω is singular and the rms moves like the square root of the
    # fold's shift: those rows are compared through the fold's location below instead.
    near_fold = np.convolve(frf.bifurcation == "fold", np.ones(7), mode="same") > 0
    rows = [i for i in range(0, len(frf), 5) if not near_fold[i]]
    for i in rows:
        r = solve_harmonic_balance(hb2, frf.coefficients[i], frf.omega[i])
        assert r.converged, (i, frf.omega[i], r.message)
        checked += 1
        rms2 = np.sqrt(r.q[0] ** 2 + 0.5 * np.sum(r.q[1:] ** 2))
        worst = max(worst, abs(rms2 / frf.rms[i] - 1))
    assert checked > 0.9 * len(range(0, len(frf), 5))
    assert worst < 1e-4
    frf2 = frequency_response(frf.model, omega=(0.1, 3.0), harmonics=32, samples=2 * N)
    assert [s.kind for s in frf2.special_points] == [s.kind for s in frf.special_points]
    for a, b in zip(frf.special_points, frf2.special_points):
        assert abs(a.omega - b.omega) < 1e-6, (a.kind, a.omega, b.omega)


@pytest.mark.parametrize("b", [1e-4, 1e-2, 1.0])
@pytest.mark.parametrize("law_type", ["clutch", "backlash"])
def test_small_and_large_clearances_converge(b, law_type):
    """Scaling by the model's length and force scales makes the same tolerances work from
    b = 1e-4 rad (nearly linear) to b = 1 rad (the motion flies through a huge gap)."""
    from rattle import frequency_response

    law = Clutch(alpha=0.25, b=b) if law_type == "clutch" else Backlash(b=b)
    frf = frequency_response(_model(law), omega=(0.1, 3.0), harmonics=16)
    assert frf.status.name == "SUCCESS"
    assert frf.omega[-1] == 3.0
    assert np.all(frf.residual < 1e-10)


@pytest.mark.parametrize("harmonics,samples,period", [(32, None, 1), (16, 100, 1), (12, None, 2)])
def test_compiled_single_element_residual_is_the_array_code_bit_for_bit(harmonics, samples, period):
    """One coordinate, one element: residual_jacobian through hb._kernels gives exactly the
    array code's R, ∂R/∂q, ∂R/∂Ω (the same operations in the same order), sample count odd,
    even or not a power of two, period 1 or 2."""
    import rattle
    from rattle.hb import _kernels

    if not _kernels.AVAILABLE:
        pytest.skip("numba not installed: only the array code runs")
    hb = HarmonicBalance(rattle.reference_case(), HBOptions(harmonics=harmonics, samples=samples), period=period)
    assert hb._compiled
    rng = np.random.default_rng(3)
    k = np.arange(1, harmonics + 1)
    for omega in (0.3, 1.1, 2.7):
        q = hb.linear_solution(omega)
        q[1:] += 0.3 * rng.standard_normal(2 * harmonics) / np.concatenate([k, k]) ** 2
        compiled = hb.residual_jacobian(q, omega)
        hb._compiled = False
        try:
            reference = hb.residual_jacobian(q, omega)
        finally:
            hb._compiled = True
        for a, b in zip(compiled, reference):
            np.testing.assert_array_equal(a, b)
