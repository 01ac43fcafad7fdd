"""Harmonic-balance residual of a :class:`~rattle.model.System`, with its analytic Jacobians.

The system x'' + C x' + K x + Σ_e b_e f_e(a_e · x) = F(t) has n coordinates and m clearance
elements (``rattle.model._system``). A solution of period p·T (T = 2π/Ω, base frequency
ω = Ω/p; p = 1 for the primary response, p = n for a 1/n sub-harmonic) is stored as
q = vec(Q), Q (n, 2H+1) COORDINATE-MAJOR: row i holds the real series [a_0, a_1…a_H, b_1…b_H]
of x_i (see ``_basis``). The Galerkin residual is

    R_i(q, Ω) = ∇(ω)² q_i + Σ_j C_ij ∇(ω) q_j + Σ_j K_ij q_j + Σ_e b_e,i Γ*[f_e(Γ (a_e · Q))] − F_i,

with Γ the synthesis (samples of a series), Γ* the analysis (real FFT) and F_i the coefficients
of the forcing of coordinate i (its harmonic h sits at harmonic h·p of ω). The element forces
are evaluated by alternating frequency–time (AFT) for all elements at once: one inverse FFT for
all deflections δ_e = a_e · x, one FFT for all force and stiffness samples. The Jacobian is

    ∂R/∂q = I ⊗ ∇² + C ⊗ ∇ + K ⊗ I + Σ_e (b_e a_eᵀ) ⊗ J_e,   J_e = Γ* diag(f_e'(δ_e(t_j))) Γ,

and every J_e is assembled exactly from the DFT coefficients G_m of the sampled slope
g = f_e'(δ_e): in complex form the product g·δ has coefficients Σ_j G_{k−j} Q_j, a Toeplitz +
Hankel matrix in the real basis (O(N log N + H²) instead of O(N H²)), exact for N ≥ 4H + 1.

The single equation of SPEC §1 is the case n = m = 1 (C = [[C/I]], K = [[0]], a = [1],
b = [K/I]); it runs through the same code and gives the same numbers as the scalar formulas.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg

from .._typing import FloatArray
from . import _kernels
from ._basis import FourierBasis, resize_harmonics
from ._options import HBOptions

if TYPE_CHECKING:
    from ..model import SpeedLoad, System

_gesv = scipy.linalg.lapack.dgesv


def _jacobian_gather_tables(H: int) -> tuple[np.ndarray, np.ndarray]:
    """Index tables with J[r, c] = X[j1] + X[j2], X = [Vr, Vi, −Vr, −Vi, 0] (blocks of length
    L = 4H + 1, Vr_m = Re G_m, Vi_m = Im G_m, m = −2H … 2H at position 2H + m; X[4L] = 0).

    From the complex product rule (g δ)_k = Σ_j G_{k−j} Q_j in the real basis:
    row a_0: G0, ½(Gr_{−j} + Gr_j) = Gr_j, ½(Gi_{−j} − Gi_j) = −Gi_j; row cos k: 2Gr_k,
    Gr_{k−j} + Gr_{k+j}, Gi_{k−j} − Gi_{k+j}; row sin k: −2Gi_k, −(Gi_{k−j} + Gi_{k+j}),
    Gr_{k−j} − Gr_{k+j}. Signs sit in X, so J is two gathers and one sum (no products).
    """
    S = 2 * H + 1
    off, L = 2 * H, 4 * H + 1
    R, I, nR, nI, zero = off, L + off, 2 * L + off, 3 * L + off, 4 * L
    j1 = np.empty((S, S), dtype=np.intp)
    j2 = np.empty((S, S), dtype=np.intp)
    k = np.arange(1, H + 1)
    K, J = np.meshgrid(k, k, indexing="ij")
    a, b = slice(1, H + 1), slice(H + 1, S)
    j1[0, 0], j2[0, 0] = R, zero
    j1[0, a], j2[0, a] = R + k, zero
    j1[0, b], j2[0, b] = nI + k, zero
    j1[a, 0], j2[a, 0] = R + k, R + k
    j1[b, 0], j2[b, 0] = nI + k, nI + k
    j1[a, a], j2[a, a] = R + K - J, R + K + J
    j1[a, b], j2[a, b] = I + K - J, nI + K + J
    j1[b, a], j2[b, a] = nI + K - J, nI + K + J
    j1[b, b], j2[b, b] = R + K - J, nR + K + J
    return j1, j2


def product_tables(H: int, k: int) -> tuple[FloatArray, np.ndarray, np.ndarray]:
    """Buffer X (k, 4L+1) and the gather tables of :func:`product_jacobians` for k signals: a fresh
    buffer each call, the (read-only) tables shared by every problem of the same H and k."""
    j1, j2 = _shifted_tables(H, k)
    return np.zeros((k, 4 * (4 * H + 1) + 1)), j1, j2


@functools.lru_cache(maxsize=32)
def _shifted_tables(H: int, k: int) -> tuple[np.ndarray, np.ndarray]:
    j1, j2 = _jacobian_gather_tables(H)
    shift = ((4 * (4 * H + 1) + 1) * np.arange(k))[:, None, None]
    j1, j2 = j1[None] + shift, j2[None] + shift
    j1.flags.writeable = False
    j2.flags.writeable = False
    return j1, j2


def product_jacobians(spec: np.ndarray, samples: int, tables: tuple[FloatArray, np.ndarray, np.ndarray]) -> FloatArray:
    """Γ* diag(g) Γ (k, S, S) — the coefficients of g(t) δ(t) as a linear map of δ's — from the
    rfft spectra (k, ≥ 2H+1) of k signals g sampled at ``samples`` points, with the ``tables`` of
    :func:`product_tables` (see :func:`_jacobian_gather_tables`)."""
    X, j1, j2 = tables
    H = (j1.shape[-1] - 1) // 2
    S = 2 * H + 1
    off, L = 2 * H, 4 * H + 1
    G = spec[:, :S] / samples
    Gr, Gi = G.real, G.imag
    X[:, off:L] = Gr
    X[:, :off] = Gr[:, :0:-1]
    X[:, L + off : 2 * L] = Gi
    np.negative(Gi[:, :0:-1], out=X[:, L : L + off])
    np.negative(X[:, : 2 * L], out=X[:, 2 * L : 4 * L])
    J = np.take(X, j1)
    J += np.take(X, j2)
    return J


def check_forced_harmonics(system: System, harmonics: int, period: int) -> None:
    """Refuse ``harmonics`` too few to hold the excitation's highest harmonic at ``period``."""
    n_forced = system.forced_harmonics
    if harmonics < n_forced * period:
        raise ValueError(
            f"`harmonics` must be >= {n_forced * period} to hold the excitation's harmonic "
            f"{n_forced} at period {period} (harmonic {n_forced}×{period} of the base "
            f"frequency), got {harmonics}"
        )


def system_forcing(system: System, harmonics: int, period: int) -> FloatArray:
    """The forcing coefficients of ``system``, flat (n·(2H+1),), coordinate-major: F_0 at a_0,
    harmonic h of Ω (F_ch cos + F_sh sin) at harmonic h·p of the base frequency."""
    H, S = harmonics, 2 * harmonics + 1
    F = np.zeros((system.n, S))
    F[:, 0] = system.mean
    for h in range(1, system.forced_harmonics + 1):
        r = h * period
        F[:, r] += system.cos[h - 1]
        F[:, H + r] += system.sin[h - 1]
    return F.reshape(-1)


def forcing_with_load(forcing: FloatArray, load: SpeedLoad | None, a0: np.ndarray, omega: float) -> FloatArray:
    """``forcing`` plus a speed-dependent mean load's d(Ω) u at the a_0 slots ``a0`` (``forcing``
    itself without a load)."""
    if load is None:
        return forcing
    F = forcing.copy()
    F[a0] += float(load.value(omega)) * load.direction
    return F


def load_slope(Rw: FloatArray, load: SpeedLoad | None, a0: np.ndarray, omega: float) -> FloatArray:
    """∂R/∂Ω gains −d'(Ω) u at the a_0 slots (in place; returned)."""
    if load is not None:
        Rw[a0] -= load.slope(float(omega)) * load.direction
    return Rw


class HarmonicBalance:
    """The discretised problem R(q, Ω) = 0 for one model, harmonic count and period multiple.

    ``model`` is anything with a ``system()`` method returning a :class:`~rattle.model.System`
    (a :class:`~rattle.model.Model`, a :class:`~rattle.model.Chain`); all numerics use
    :attr:`system`. Unknowns q: n·(2H+1) numbers, coordinate-major (:meth:`coordinate_series`).
    """

    def __init__(self, model, options: HBOptions | None = None, *, period: int = 1) -> None:
        options = HBOptions() if options is None else options
        if isinstance(period, bool) or not isinstance(period, int) or period < 1:
            raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
        system = model.system()
        check_forced_harmonics(system, options.harmonics, period)
        self.model = model
        self.system = system
        self.options = options
        self.period = period
        self.basis = FourierBasis(options.harmonics, options.n_samples)
        H = options.harmonics
        S = 2 * H + 1
        n, m = system.n, system.m
        self.n_coordinates = n
        self.n_elements = m
        self._S = S
        self._k2 = self.basis.k**2
        self.length_scale = system.length_scale()
        self.force_scale = system.force_scale()
        self.forcing = system_forcing(system, H, period)  # flat (n·(2H+1),); analyses may rescale it (homotopy)
        # A speed-dependent mean load (drag by speed): d(Ω) u joins the a_0 terms of the forcing,
        # −d'(Ω) u the Ω-derivative of the residual (``_load_at``); the homotopy leaves it alone.
        self._load = system.load
        self._a0 = np.arange(n) * S
        # Linear part.
        C = np.asarray(system.damping, dtype=float)
        K = np.asarray(system.stiffness, dtype=float)
        self._C, self._K = C, K
        self._has_K = bool(np.any(K != 0.0))
        self._lin_index = self._linear_pattern()
        self._c_scalar = float(C[0, 0]) if n == 1 else None
        self._ck = C[0, 0] * self.basis.k if n == 1 else None
        self._m2k2 = -2.0 * self._k2
        self._tables: dict[int, tuple] = {}
        # Spectrum buffer of the element deflections (harmonics above H stay zero).
        self._synth = np.zeros((m, self.basis.samples // 2 + 1), dtype=complex)
        self._synth_re, self._synth_im = self._synth.real, self._synth.imag
        # Elements: δ = A x, force B f(δ); W_e = b_e a_eᵀ.
        A = system.element_rows.reshape(m, n)
        B = system.element_columns.reshape(n, m)
        self._A, self._B = A, B
        self._W = np.einsum("ie,ej->eij", B, A) if m else np.zeros((0, n, n))
        self._W_entries = [(int(e), int(i), int(j), float(self._W[e, i, j])) for e, i, j in zip(*np.nonzero(self._W))]
        # Elements whose a_e picks one coordinate (a unit row): δ_e is a row of Q, no product.
        unit = [int(np.flatnonzero(a)[0]) for a in A if np.count_nonzero(a) == 1 and a[np.flatnonzero(a)[0]] == 1.0]
        self._select = np.array(unit, dtype=np.intp) if len(unit) == m else None
        if self._select is not None and m and np.array_equal(self._select, np.arange(unit[0], unit[0] + m)):
            self._select = slice(unit[0], unit[0] + m)  # consecutive coordinates: a view
        self._laws = [
            (np.asarray(e.breakpoints, dtype=float), np.asarray(e.slopes, dtype=float), np.asarray(e.offsets, dtype=float))
            for e in system.elements
        ]
        # One coordinate, one element: residual and Jacobian through the compiled kernels
        # (``_kernels``; the same operations, identical results), with their buffers.
        self._compiled = n == 1 and m == 1 and _kernels.AVAILABLE
        if self._compiled:
            N = self.basis.samples
            self._delta = np.empty((1, N))
            self._fg = np.empty((2, N))
            self._spec = np.empty((2, N // 2 + 1), dtype=complex)
            X, j1, j2 = self._product_tables(1)
            self._kernel_tables = (X[0], j1[0], j2[0])
            self._kernel_scalars = (float(C[0, 0]), float(K[0, 0]), self._has_K, float(B[0, 0]), float(self._W[0, 0, 0]))

    # --- sizes and views -----------------------------------------------------------------------
    @property
    def size(self) -> int:
        """Number of real unknowns n·(2H+1)."""
        return self.n_coordinates * self._S

    @property
    def parameter_scale(self) -> float:
        """Scale of the continuation parameter Ω: the model's natural frequency ω_n (a
        :class:`~rattle.continuation.ContinuationProblem` with ``length_scale`` and ``force_scale``)."""
        return self.model.natural_frequency

    @property
    def element_weights(self) -> FloatArray:
        """W_e = b_e a_eᵀ (m, n, n): element e adds f_e'(δ_e) W_e to the tangent stiffness."""
        return self._W

    def base_frequency(self, omega: float) -> float:
        """ω = Ω / p."""
        return omega / self.period

    def coordinate_series(self, q: FloatArray) -> FloatArray:
        """Q (n, 2H+1): row i is the real series of coordinate x_i (a view of ``q``)."""
        return np.asarray(q).reshape(self.n_coordinates, self._S)

    def element_series(self, q: FloatArray) -> FloatArray:
        """The deflection series of every element, A Q, shape (m, 2H+1)."""
        Q = self.coordinate_series(q)
        if self._select is not None:
            return Q[self._select]
        return self._A @ Q

    def element_samples(self, q: FloatArray) -> FloatArray:
        """δ_e(t_j) at the N sample times of the base period, shape (m, N)."""
        return self.basis.synthesize(self.element_series(q))

    def coordinate_samples(self, q: FloatArray) -> FloatArray:
        """x_i(t_j) at the N sample times of the base period, shape (n, N)."""
        return self.basis.synthesize(self.coordinate_series(q))

    def static_forcing(self) -> FloatArray:
        """The forcing with its harmonics removed (only every coordinate's mean F_0 at a_0), flat;
        the start of an amplitude homotopy ``forcing = static + λ (forcing − static)``."""
        F = np.zeros((self.n_coordinates, self._S))
        F[:, 0] = self.forcing.reshape(self.n_coordinates, self._S)[:, 0]
        return F.reshape(-1)

    def resize(self, q: FloatArray, harmonics: int, factor: int = 1) -> FloatArray:
        """:func:`~rattle.hb.resize_harmonics` of every coordinate's series of ``q`` (flat in, flat out)."""
        return resize_harmonics(self.coordinate_series(q), harmonics, factor).reshape(-1)

    # --- linear part ---------------------------------------------------------------------------
    def _linear_pattern(self) -> np.ndarray:
        """Flat positions in the (n·S, n·S) Jacobian of the linear part's entries, in the order of
        the value buffer ``_lin_values`` (filled by :meth:`_linear_values`): the inertia diagonals
        of the harmonic rows (with K_ii folded in), the rest of K, then the damping entries
        (a_k, b_k) and (b_k, a_k)."""
        n, S, H = self.n_coordinates, self._S, self.basis.harmonics
        nS = n * S
        rows = np.arange(1, S)
        c = np.arange(n)[:, None]
        pos = [((c * S + rows) * nS + c * S + rows).ravel()]  # (n, 2H)
        K = self._K
        kvals = []
        for i, j in zip(*np.nonzero(K)):
            rr = np.arange(S) if i != j else np.array([0])
            pos.append((i * S + rr) * nS + j * S + rr)
            kvals.append(np.full(rr.size, K[i, j]))
        ci, cj = np.nonzero(self._C)
        self._C_nonzero = self._C[ci, cj][:, None]  # (p, 1)
        a = np.arange(1, H + 1)
        pos.append(((ci[:, None] * S + a) * nS + cj[:, None] * S + a + H).ravel())
        pos.append(((ci[:, None] * S + a + H) * nS + cj[:, None] * S + a).ravel())
        # The value buffer and its parts (views), refilled at every call.
        nd, nk, p = n * 2 * H, sum(v.size for v in kvals), ci.size
        vals = np.zeros(nd + nk + 2 * p * H)
        if kvals:
            vals[nd : nd + nk] = np.concatenate(kvals)
        self._lin_values = vals
        self._lin_diag = vals[:nd].reshape(n, 2, H)
        self._lin_c1 = vals[nd + nk : nd + nk + p * H].reshape(p, H)
        self._lin_c2 = vals[nd + nk + p * H :].reshape(p, H)
        self._K_diag = np.diagonal(K)[:, None, None].copy()
        return np.concatenate(pos)

    def _linear_values(self, kw: FloatArray, m2: FloatArray) -> FloatArray:
        """Values at ``_lin_index`` of I ⊗ ∇(ω)² + C ⊗ ∇(ω) + K ⊗ I, from kw = kω and m2 = −(kω)².
        Returns the (reused) buffer: add it at once."""
        d = self._lin_diag
        d[:] = m2
        if self._has_K:
            d += self._K_diag
        np.multiply(self._C_nonzero, kw, out=self._lin_c1)
        np.negative(self._lin_c1, out=self._lin_c2)
        return self._lin_values

    def _linear_part(self, Q: FloatArray, kw: FloatArray, m2: FloatArray) -> FloatArray:
        """(∇² + C ∇ + K) Q for the series Q (n, S), with kw = kω and m2 = −(kω)²."""
        H = self.basis.harmonics
        Qa, Qb = Q[:, 1 : H + 1], Q[:, H + 1 :]
        out = np.empty_like(Q)
        out[:, 0] = 0.0
        oa, ob = out[:, 1 : H + 1], out[:, H + 1 :]
        np.multiply(m2, Qa, out=oa)
        np.multiply(m2, Qb, out=ob)
        if self._c_scalar is not None:  # one coordinate: c kω as a scalar product
            ckw = self._c_scalar * kw
            oa += ckw * Qb
            ob -= ckw * Qa
        else:
            oa += self._C @ (kw * Qb)
            ob -= self._C @ (kw * Qa)
        if self._has_K:
            out += self._K @ Q
        return out

    def _linear_part_dw(self, Q: FloatArray, w: float) -> FloatArray:
        """∂/∂ω of :meth:`_linear_part`."""
        H = self.basis.harmonics
        Qa, Qb = Q[:, 1 : H + 1], Q[:, H + 1 :]
        out = np.empty_like(Q)
        out[:, 0] = 0.0
        m2k = self._m2k2 * w
        oa, ob = out[:, 1 : H + 1], out[:, H + 1 :]
        np.multiply(m2k, Qa, out=oa)
        np.multiply(m2k, Qb, out=ob)
        if self._c_scalar is not None:
            oa += self._ck * Qb
            ob -= self._ck * Qa
        else:
            k = self.basis.k
            oa += self._C @ (k * Qb)
            ob -= self._C @ (k * Qa)
        return out

    def linear_matrix(self, omega: float) -> FloatArray:
        """I ⊗ ∇² + C ⊗ ∇ + K ⊗ I at forcing frequency Ω, shape (n·(2H+1), n·(2H+1))."""
        nS = self.size
        kw = self.basis.k * self.base_frequency(omega)
        L = np.zeros(nS * nS)
        L[self._lin_index] = self._linear_values(kw, -(kw**2))
        return L.reshape(nS, nS)

    # --- element forces (AFT, all elements at once) ----------------------------------------------
    def _synthesize_elements(self, D: FloatArray) -> FloatArray:
        """δ_e(t_j) (m, N) of the deflection series D (m, S): one inverse real FFT for all."""
        H, N = self.basis.harmonics, self.basis.samples
        re, im = self._synth_re, self._synth_im
        np.multiply(D[:, :1], N, out=re[:, :1])
        np.multiply(D[:, 1 : H + 1], 0.5 * N, out=re[:, 1 : H + 1])
        np.multiply(D[:, H + 1 :], -0.5 * N, out=im[:, 1 : H + 1])
        if D.shape[0] == 1:
            return np.fft.irfft(self._synth[0], n=N)[None]
        return np.fft.irfft(self._synth, n=N, axis=1)

    def _element_samples(self, delta: FloatArray) -> FloatArray:
        """Rows 0…m−1: f_e(δ_e(t_j)); rows m…2m−1: f_e'(δ_e(t_j)); shape (2m, N)."""
        m = self.n_elements
        out = np.empty((2 * m, delta.shape[-1]))
        for e, (bp, sl, off) in enumerate(self._laws):
            d = delta[e]
            j = np.searchsorted(bp, d, side="right")
            g = np.take(sl, j, out=out[m + e])
            np.multiply(g, d, out=out[e])
            out[e] += off[j]
        return out

    def _force_samples(self, delta: FloatArray) -> tuple[FloatArray, FloatArray]:
        """f_e(δ) and f_e'(δ) for the samples δ (m, N) (or (N,) for one element)."""
        d = np.asarray(delta, dtype=float)
        fg = self._element_samples(d.reshape(self.n_elements, -1))
        m = self.n_elements
        return fg[:m].reshape(d.shape), fg[m:].reshape(d.shape)

    def _element_forces(self, spec: np.ndarray) -> FloatArray:
        """Σ_e b_e P_e (n, S) from the force spectra in the first m rows of ``spec``."""
        m = self.n_elements
        P = self.basis.from_complex(spec[:m, : self.basis.harmonics + 1] / self.basis.samples)
        return self._B * P if m == 1 else self._B @ P  # (n, 1) * (1, S): b P

    def _forces(self, q: FloatArray) -> FloatArray:
        """Σ_e b_e Γ* f_e(Γ a_e·Q), shape (n, S)."""
        delta = self._synthesize_elements(self.element_series(q))
        if self.n_elements == 1:  # fast path of one element: 1-D transforms, b P as an outer product
            bp, sl, off = self._laws[0]
            d = delta[0]
            j = np.searchsorted(bp, d, side="right")
            spec = np.fft.rfft(sl[j] * d + off[j])[: self.basis.harmonics + 1] / self.basis.samples
            return self._B * self.basis.from_complex(spec)
        rows = []
        for d, (bp, sl, off) in zip(delta, self._laws):
            j = np.searchsorted(bp, d, side="right")
            rows.append(sl[j] * d + off[j])
        return self._element_forces(np.fft.rfft(np.stack(rows), axis=1))

    def nonlinear_force(self, q: FloatArray) -> FloatArray:
        """Σ_e b_e Γ* f_e(Γ a_e·Q): coefficients of the element forces by AFT, flat (n·(2H+1),)."""
        if not self.n_elements:
            return np.zeros(self.size)
        return self._forces(q).reshape(-1)

    def force_jacobian_from_stiffness(self, g: FloatArray) -> FloatArray:
        """Γ* diag(g) Γ for slope samples g (N,) → (2H+1, 2H+1), or rows (k, N) → (k, 2H+1, 2H+1);
        assembled from the DFT of g."""
        g = np.asarray(g, dtype=float)
        J = self._jacobians_from_spectra(np.fft.rfft(g.reshape(-1, g.shape[-1]), axis=1))
        return J[0] if g.ndim == 1 else J

    def _product_tables(self, k: int) -> tuple[FloatArray, np.ndarray, np.ndarray]:
        """Buffer X (k, 4L+1) and gather tables for k signals at once (cached per k)."""
        got = self._tables.get(k)
        if got is None:
            got = self._tables[k] = product_tables(self.basis.harmonics, k)
        return got

    def _jacobians_from_spectra(self, spec: np.ndarray) -> FloatArray:
        """J_e = Γ* diag(g_e) Γ (k, S, S) from the rfft spectra (k, ≥ 2H+1) of k slope signals
        (see :func:`_jacobian_gather_tables`)."""
        return product_jacobians(spec, self.basis.samples, self._product_tables(spec.shape[0]))

    def _assemble(self, Je: FloatArray) -> FloatArray:
        """Σ_e W_e ⊗ J_e (n·S, n·S) from the element blocks J_e (m, S, S)."""
        n, S, m = self.n_coordinates, self._S, self.n_elements
        nS = n * S
        if m == 0:
            return np.zeros((nS, nS))
        if n == 1 and m == 1:  # w J in one product
            return np.multiply(self._W[0][:, None, :, None], Je[0][None, :, None, :]).reshape(nS, nS)
        # Only the non-zero entries of the W_e (a chain element touches 2 × 2 blocks).
        out = np.zeros((n, S, n, S))
        for e, i, j, wij in self._W_entries:
            out[i, :, j, :] += wij * Je[e]
        return out.reshape(nS, nS)

    # --- residual and Jacobians ----------------------------------------------------------------
    def residual(self, q: FloatArray, omega: float) -> FloatArray:
        """R(q, Ω), shape (n·(2H+1),)."""
        kw = self.basis.k * (omega / self.period)
        R = self._linear_part(np.asarray(q).reshape(self.n_coordinates, self._S), kw, -(kw**2))
        if self.n_elements:
            R += self._forces(q)
        return R.reshape(-1) - self._forcing_at(omega)

    def _forcing_at(self, omega: float) -> FloatArray:
        """The forcing coefficients at Ω: :attr:`forcing` plus the load's d(Ω) u at the a_0 slots."""
        return forcing_with_load(self.forcing, self._load, self._a0, omega)

    def _load_slope(self, Rw: FloatArray, omega: float) -> FloatArray:
        """∂R/∂Ω gains −d'(Ω) u at the a_0 slots (in place; returned)."""
        return load_slope(Rw, self._load, self._a0, omega)

    def residual_jacobian(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R (n·S,), ∂R/∂q (n·S, n·S) and ∂R/∂Ω (n·S,) in one AFT pass (S = 2H+1)."""
        if self._compiled:
            return self._residual_jacobian_compiled(q, omega)
        w = self.base_frequency(omega)
        m = self.n_elements
        Q = self.coordinate_series(q)
        kw = self.basis.k * w
        m2 = -(kw**2)
        R = self._linear_part(Q, kw, m2)
        if m:
            fg = self._element_samples(self._synthesize_elements(self.element_series(q)))
            spec = np.fft.rfft(fg, axis=1)  # one FFT call for every element's force and slope
            R += self._element_forces(spec)
            Rq = self._assemble(self._jacobians_from_spectra(spec[m:]))
        else:
            Rq = np.zeros((self.size, self.size))
        R = R.reshape(-1)
        R -= self._forcing_at(omega)
        Rq.reshape(-1)[self._lin_index] += self._linear_values(kw, m2)
        Rw = self._linear_part_dw(Q, w).reshape(-1)
        Rw /= self.period
        return R, Rq, self._load_slope(Rw, omega)

    def _residual_jacobian_compiled(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:meth:`residual_jacobian` of one coordinate and one element: the samples and spectra by
        the FFTs into buffers, the rest in the compiled kernels (``_kernels``), bit-identical."""
        N = self.basis.samples
        q = np.ascontiguousarray(q, dtype=float)
        D = self.element_series(q)
        _kernels.fill_spectrum(np.ascontiguousarray(D[0]), N, self._synth)
        _kernels.irfft(self._synth, self._delta)
        bp, sl, off = self._laws[0]
        _kernels.force_samples(self._delta[0], bp, sl, off, self._fg)
        _kernels.rfft(self._fg, self._spec)
        c, K, has_K, b, wq = self._kernel_scalars
        X, j1, j2 = self._kernel_tables
        R, Rq, Rw = _kernels.residual_jacobian(q, omega / self.period, float(self.period), self._spec, N, c, K, has_K,
                                               b, wq, self._forcing_at(omega), X, j1, j2)
        return R, Rq, self._load_slope(Rw, omega)

    # --- Newton steps: full or condensed onto the element deflections ---------------------------
    def newton_step(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray | None]:
        """R(q, Ω) and the Newton increment dq = −(∂R/∂q)⁻¹ R (None when the Jacobian is singular).

        With ``options.condense`` (and a condensable system, see :meth:`_dynamic_receptance`) the
        step is solved on the m·S element deflections instead of the n·S coordinates: writing
        ∂R/∂q = L + U J V (L = I⊗∇² + C⊗∇ + K⊗I, U = B⊗I, V = A⊗I, J = diag(J_e)) and y = V dq,
        (I + G J) y = V z with z = −L⁻¹R and G = V L⁻¹ U, then dq = z − L⁻¹U J y. L is
        block-diagonal over the harmonics (Z_k = K − (kω)² I + i kω C, one n × n complex solve
        per harmonic), so only an (m·S)² system is factorised.
        """
        if self.options.condense and self.n_elements and self.n_elements < self.n_coordinates:
            out = self._condensed_step(q, omega)
            if out is not None:
                return out
        R, Rq, _ = self.residual_jacobian(q, omega)
        _, _, dq, info = _gesv(Rq, -R)
        if info != 0 or not np.all(np.isfinite(dq)):
            return R, None
        return R, dq

    def _dynamic_receptance(self, w: float) -> tuple[FloatArray, np.ndarray] | None:
        """K⁻¹ (n, n) and Z_k⁻¹ (H, n, n) complex, or None when K or some Z_k is singular
        (a chain held only through its clearances: no condensation)."""
        H, n = self.basis.harmonics, self.n_coordinates
        kw = self.basis.k * w
        Z = self._K[None] - (kw**2)[:, None, None] * np.eye(n) + 1j * kw[:, None, None] * self._C[None]
        try:
            K_inv, Z_inv = np.linalg.inv(self._K), np.linalg.inv(Z)
        except np.linalg.LinAlgError:
            return None
        # 1-norm condition numbers from the inverses (cheap): refuse near-singular blocks.
        cond_K = np.abs(self._K).sum(0).max() * np.abs(K_inv).sum(0).max()
        cond_Z = np.abs(Z).sum(1).max(1) * np.abs(Z_inv).sum(1).max(1)
        if not (np.isfinite(cond_K) and cond_K < 1e12 and np.all(np.isfinite(cond_Z)) and cond_Z.max() < 1e12):
            return None
        return K_inv, Z_inv

    def _apply_inverse(self, K_inv: FloatArray, Z_inv: np.ndarray, X: FloatArray) -> FloatArray:
        """L⁻¹ X for series X (n, S, r) → (n, S, r): a_0 by K⁻¹, harmonic k by Z_k⁻¹ on a − i b."""
        H = self.basis.harmonics
        out = np.empty_like(X)
        out[:, 0] = K_inv @ X[:, 0]
        Xc = X[:, 1 : H + 1] - 1j * X[:, H + 1 :]  # (n, H, r)
        Y = (Z_inv @ Xc.transpose(1, 0, 2)).transpose(1, 0, 2)
        out[:, 1 : H + 1] = Y.real
        out[:, H + 1 :] = -Y.imag
        return out

    def _condensed_step(self, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray] | None:
        """R and dq by condensation (:meth:`newton_step`); None when L or I + G J is singular."""
        w = self.base_frequency(omega)
        inv = self._dynamic_receptance(w)
        if inv is None:
            return None
        K_inv, Z_inv = inv
        n, m, S, H = self.n_coordinates, self.n_elements, self._S, self.basis.harmonics
        Q = self.coordinate_series(q)
        kw = self.basis.k * w
        R = self._linear_part(Q, kw, -(kw**2))
        fg = self._element_samples(self._synthesize_elements(self.element_series(q)))
        spec = np.fft.rfft(fg, axis=1)
        R += self._element_forces(spec)
        R = R.reshape(-1) - self._forcing_at(omega)
        Je = self._jacobians_from_spectra(spec[m:])  # (m, S, S)
        # Receptance of the elements' deflections to their forces, per harmonic: g_k = A Z_k⁻¹ B.
        g0 = self._A @ K_inv @ self._B  # (m, m)
        gk = (self._A @ Z_inv @ self._B).transpose(1, 0, 2)  # (m, H, m): [e', k, e]
        gr, gi = gk.real[:, :, :, None], gk.imag[:, :, :, None]
        # M = I + G J, block (e', e) = G_{e'e} J_e with G_{e'e} 2×2 rotations per harmonic.
        Ja = Je[:, 1 : H + 1, :].transpose(1, 0, 2)[None]  # (1, H, m, S)
        Jb = Je[:, H + 1 :, :].transpose(1, 0, 2)[None]
        M = np.empty((m, S, m, S))
        M[:, 0] = g0[:, :, None] * Je[None, :, 0, :]
        M[:, 1 : H + 1] = gr * Ja + gi * Jb
        M[:, H + 1 :] = gr * Jb - gi * Ja
        M = M.reshape(m * S, m * S)
        M[np.diag_indices(m * S)] += 1.0
        z = self._apply_inverse(K_inv, Z_inv, -R.reshape(n, S, 1))[:, :, 0]
        _, _, y, info = _gesv(M, (self._A @ z).reshape(-1))
        if info != 0 or not np.all(np.isfinite(y)):
            return None
        Jy = (Je @ y.reshape(m, S, 1))[:, :, 0]  # (m, S)
        dq = z - self._apply_inverse(K_inv, Z_inv, (self._B @ Jy)[:, :, None])[:, :, 0]
        return R, dq.reshape(-1)

    # --- slopes along an orbit -----------------------------------------------------------------
    def element_slopes(self, q: FloatArray) -> FloatArray:
        """f_e'(δ_e(t_j)) (m, N): every element's law slope at the N sample times of the orbit."""
        return self._element_samples(self.element_samples(q))[self.n_elements :]

    def tangent_stiffness_samples(self, q: FloatArray) -> FloatArray:
        """K + Σ_e f_e'(δ_e(t_j)) b_e a_eᵀ at the N sample times, shape (N, n, n)."""
        g = self.element_slopes(q)
        return self._K + np.tensordot(g.T, self._W, axes=(1, 0))

    def stiffness_samples(self, q: FloatArray) -> FloatArray:
        """The single coordinate's tangent stiffness K + Σ_e b_e a_e f_e'(δ_e) at the N sample
        times (N,) — for the single equation k ∂f/∂δ; n = 1 only (else
        :meth:`tangent_stiffness_samples`)."""
        if self.n_coordinates != 1:
            raise ValueError(
                f"`stiffness_samples` is the n = 1 form; this system has n = {self.n_coordinates} "
                "coordinates: use `tangent_stiffness_samples` (N, n, n) or `element_slopes` (m, N)"
            )
        g = self.element_slopes(q)
        w = self._W[:, 0, 0]
        out = w[0] * g[0] if self.n_elements == 1 else w @ g
        return out + self._K[0, 0] if self._has_K else out

    # --- linear response -----------------------------------------------------------------------
    def linear_solution(
        self, omega: float, stiffness_slope: float | FloatArray | None = None, center: float | FloatArray | None = None,
    ) -> FloatArray:
        """Closed-form steady state of the system linearised about a stage combination.

        About the centre x_c (default: the static equilibrium), every element is replaced by its
        stage holding a_e·x_c (or the slopes ``stiffness_slope``, one per element), so that
        K_s = K + Σ_e s_e b_e a_eᵀ, and every forcing harmonic h of ω gives
        X_h = (K_s − (hω)² I + i hω C)⁻¹ F_h; the mean is x_c. For n = m = 1: X = F/(k s − (hω)² + i c hω).
        """
        system = self.system
        n, H = self.n_coordinates, self.basis.harmonics
        xc = system.static_equilibrium(omega) if center is None else np.asarray(center, dtype=float).reshape(n)
        if stiffness_slope is None:
            stages = system.stages_of(xc)
            slopes = np.array([e.slopes[s] for e, s in zip(system.elements, stages)])
        else:
            slopes = np.asarray(stiffness_slope, dtype=float).reshape(self.n_elements)
        Ks = self._K + np.tensordot(slopes, self._W, axes=(0, 0)) if self.n_elements else self._K.copy()
        w = self.base_frequency(omega)
        hw = self.basis.k * w
        F = self.forcing.reshape(n, self._S)
        Fc = F[:, 1 : H + 1] - 1j * F[:, H + 1 :]  # (n, H)
        if n == 1:
            X = Fc / (Ks[0, 0] - hw**2 + 1j * self._C[0, 0] * hw)
        else:
            Z = Ks[None] - (hw**2)[:, None, None] * np.eye(n) + 1j * hw[:, None, None] * self._C[None]
            X = np.linalg.solve(Z, Fc.T[:, :, None])[:, :, 0].T
        Q = np.zeros((n, self._S))
        Q[:, 0] = xc
        Q[:, 1 : H + 1] = X.real
        Q[:, H + 1 :] = -X.imag
        return Q.reshape(-1)


__all__ = ["HarmonicBalance"]
