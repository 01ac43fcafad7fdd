"""Compiled pieces of the single-element residual (numba), and the FFTs without their wrappers.

For one coordinate and one element (the single equation of SPEC §1) ``HarmonicBalance`` spends
its time in numpy's per-call cost: some fifty calls on arrays of 2H + 1 numbers per residual and
Jacobian. Here the work between the two FFTs is done in two compiled loops, with the same
floating-point operations in the same order as the array code of ``_residual`` (elementwise
products and sums only), so the results are identical to the last bit:

* :func:`fill_spectrum` — the spectrum of the deflection series for the inverse FFT;
* :func:`force_samples` — f(δ_j) and f'(δ_j) of the samples (the stage by ``searchsorted``'s rule);
* :func:`residual_jacobian` — R, ∂R/∂q (the Toeplitz + Hankel product of the slope spectrum,
  gathered from the same tables, plus the linear part) and ∂R/∂Ω from the two spectra.

The FFTs call numpy's pocketfft ufuncs directly (:func:`rfft`, :func:`irfft`, into buffers, the
normalisation folded in as numpy does), skipping ``numpy.fft``'s argument handling; where that
private module is missing (numpy < 2) the public functions are used.
``AVAILABLE`` is False when numba cannot be imported; ``_residual`` then keeps the array code.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit, numba  # numba is a dependency; the array code stays the fallback (and the reference)

try:  # numpy >= 2: the pocketfft gufuncs behind numpy.fft
    from numpy.fft import _pocketfft_umath as _pfu

    _x = np.arange(8.0)
    _spec = np.empty(5, dtype=complex)
    _pfu.rfft_n_even(_x, 1.0, out=_spec)
    _back = np.empty(8)
    _pfu.irfft(_spec, 1 / 8, out=_back)
    if not (np.array_equal(_spec, np.fft.rfft(_x)) and np.array_equal(_back, np.fft.irfft(_spec, n=8))):
        _pfu = None
except Exception:  # pragma: no cover - older numpy, or a changed private interface
    _pfu = None

AVAILABLE = numba is not None


def rfft(x: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``numpy.fft.rfft(x, axis=-1)`` into ``out`` (..., N//2 + 1)."""
    if _pfu is None:
        out[...] = np.fft.rfft(x, axis=-1)
        return out
    n = x.shape[-1]
    return (_pfu.rfft_n_even if n % 2 == 0 else _pfu.rfft_n_odd)(x, 1.0, out=out)


def irfft(spec: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``numpy.fft.irfft(spec, n=N, axis=-1)`` into ``out`` (..., N)."""
    n = out.shape[-1]
    if _pfu is None:
        out[...] = np.fft.irfft(spec, n=n, axis=-1)
        return out
    return _pfu.irfft(spec, 1.0 / n, out=out)


def _force_samples(delta, bp, slopes, offsets, out):
    """out[0] = f(δ_j) = s_j δ_j + o_j, out[1] = f'(δ_j) = s_j for the stage j of each sample
    (the number of breakpoints ≤ δ; NaN after all, as ``np.searchsorted``)."""
    k = bp.size
    for i in range(delta.size):
        d = delta[i]
        j = 0
        if d != d:
            j = k
        else:
            while j < k and bp[j] <= d:
                j += 1
        g = slopes[j]
        out[1, i] = g
        out[0, i] = g * d + offsets[j]


def _residual_jacobian(q, w, period, spec, n, c, K, has_K, b, wq, forcing, X, j1, j2):
    """R, ∂R/∂q, ∂R/∂Ω of the single equation from ``spec`` (2, ≥ 2H+1) the force and slope
    spectra of n samples (see ``HarmonicBalance.residual_jacobian``: the same operations in the
    same order; numpy divides a complex array by n as a product with 1/n)."""
    S = q.size
    R = np.empty(S)
    Rq = np.empty((S, S))
    Rw = np.empty(S)
    inv = 1.0 / n
    H = (S - 1) // 2
    off = 2 * H
    L = 4 * H + 1
    # Linear part (∇² + C∇ + K) q and its ∂/∂ω.
    R[0] = 0.0
    Rw[0] = 0.0
    for i in range(H):
        kf = float(i + 1)
        kw = kf * w
        m2 = -(kw * kw)
        qa = q[1 + i]
        qb = q[1 + H + i]
        ckw = c * kw
        R[1 + i] = m2 * qa + ckw * qb
        R[1 + H + i] = m2 * qb - ckw * qa
        m2k = (-2.0 * (kf * kf)) * w
        ck = c * kf
        Rw[1 + i] = (m2k * qa + ck * qb) / period
        Rw[1 + H + i] = (m2k * qb - ck * qa) / period
    if has_K:
        for i in range(S):
            R[i] += K * q[i]
    # Element force b Γ*[f]: coefficients of the force spectrum.
    R[0] += b * (spec[0, 0].real * inv)
    for i in range(H):
        R[1 + i] += b * ((spec[0, 1 + i].real * inv) * 2.0)
        R[1 + H + i] += b * ((spec[0, 1 + i].imag * inv) * -2.0)
    for i in range(S):
        R[i] -= forcing[i]
    # Jacobian of the element: J = Γ* diag(f') Γ from the slope spectrum G (tables of _residual).
    for m in range(S):
        gr = spec[1, m].real * inv
        gi = spec[1, m].imag * inv
        X[off + m] = gr
        X[L + off + m] = gi
        if m > 0:
            X[off - m] = gr
            X[L + off - m] = -gi
    for i in range(2 * L):
        X[2 * L + i] = -X[i]
    X[4 * L] = 0.0
    for r in range(S):
        for col in range(S):
            Rq[r, col] = wq * (X[j1[r, col]] + X[j2[r, col]])
    # Linear part of the Jacobian (the entries of _linear_pattern).
    if has_K:
        Rq[0, 0] += K
    for i in range(H):
        kw = float(i + 1) * w
        m2 = -(kw * kw)
        d = m2 + K if has_K else m2
        Rq[1 + i, 1 + i] += d
        Rq[1 + H + i, 1 + H + i] += d
        ckw = c * kw
        Rq[1 + i, 1 + H + i] += ckw
        Rq[1 + H + i, 1 + i] += -ckw
    return R, Rq, Rw


def _fill_spectrum(D, n, spec):
    """spec[0] = the one-sided spectrum n·(a_0, (a_k − i b_k)/2) of the series D, as
    ``HarmonicBalance._synthesize_elements`` writes it (harmonics above H are left as they are)."""
    H = (D.size - 1) // 2
    spec[0, 0] = complex(D[0] * n, spec[0, 0].imag)
    half = 0.5 * n
    for i in range(H):
        spec[0, 1 + i] = complex(D[1 + i] * half, D[1 + H + i] * -half)


if AVAILABLE:
    force_samples = njit(_force_samples)
    residual_jacobian = njit(_residual_jacobian)
    fill_spectrum = njit(_fill_spectrum)
else:  # pragma: no cover
    force_samples = residual_jacobian = fill_spectrum = None

__all__ = ["AVAILABLE", "rfft", "irfft", "fill_spectrum", "force_samples", "residual_jacobian"]
