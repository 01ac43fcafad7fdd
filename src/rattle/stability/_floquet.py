"""Floquet multipliers of a harmonic-balance orbit from the exact monodromy of its linearisation.

For a :class:`~rattle.model.System` x'' + C x' + K x + Σ_e b_e f_e(a_e·x) = F(t) the variational
equation about a periodic orbit x(t) is, in first-order form z = (y, y'),

    z' = A(t) z,     A(t) = A_s = [[0, I], [−K_s, −C]],  K_s = K + Σ_e k_{e,s_e} b_e a_eᵀ,

where s = (s_1 … s_m) is the stage combination at time t: element e is on the stage of its law
holding its deflection δ_e(t) = a_e·x(t). For piecewise-linear laws A(t) is piecewise constant: it
switches where some δ_e(t) crosses one of ITS breakpoints. Because every law is continuous the
vector field is continuous across each switching surface, so the saltation matrices are the
identity and the monodromy (2n × 2n) is exactly

    M = Φ_S(τ_S) ⋯ Φ_1(τ_1),     Φ_j(τ) = exp(A_{s_j} τ),

over the segments between successive crossings of all elements (merged and sorted per orbit);
the stage combination of a segment is read from the deflections at its mid-point. The crossing
times of each element's deflection series are found on its samples and refined to round-off by
Newton (safeguarded where needed) on the Fourier series.

One core serves every size: for n = 1 (the single equation, A_j = [[0, 1], [−κ_j, −c]])
exp(A τ) is the closed form :func:`stage_transition` of :mod:`rattle.model._stage_matrix`, the one
the exact integrator of :mod:`rattle.timeint` uses too (with one element, the whole monodromy runs
compiled, orbit by orbit, in ``_kernels``: the same formula compiled, without numpy's per-call cost,
which dominates for the one or two orbits of a continuation step); for n > 1 each stage combination met is
diagonalised once, exp(A τ) = V diag(e^{λτ}) V⁻¹ for all its segments, and a combination whose
eigenvector matrix is ill-conditioned (near-defective, e.g. a critically damped mode) goes
through ``scipy.linalg.expm`` instead.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np
import scipy.linalg

from .._typing import ComplexArray, FloatArray
from ..hb import FourierBasis
from ..model import System
from ..model import stage_transition  # the one closed form of exp(A τ) (re-exported)
from . import _kernels

#: A stage combination whose eigenvector matrix has a condition number above this goes through
#: ``scipy.linalg.expm`` instead of V diag(e^{λτ}) V⁻¹ (whose relative error is ~ cond · eps).
EIG_CONDITION_LIMIT = 1e4


def _series_weights(Q: FloatArray, kw: FloatArray) -> FloatArray:
    """Weights W (r, 2H, 2) of the series rows Q (r, 2H+1) with kω rows kw (r, H) such that
    [cos kωt, sin kωt] @ W = [δ(t) − a_0, δ'(t)] (:func:`_series`)."""
    H = kw.shape[1]
    a, b = Q[:, 1 : H + 1], Q[:, H + 1 :]
    W = np.empty((Q.shape[0], 2 * H, 2))
    W[:, :H, 0] = a
    W[:, H:, 0] = b
    np.multiply(kw, b, out=W[:, :H, 1])
    np.multiply(kw, a, out=W[:, H:, 1])
    np.negative(W[:, H:, 1], out=W[:, H:, 1])
    return W


def _series(a0: FloatArray, W: FloatArray, kw: FloatArray, t: FloatArray) -> tuple[FloatArray, FloatArray]:
    """δ(t) and δ'(t) of r series (means ``a0`` (r,), weights ``W`` from :func:`_series_weights`,
    kω rows ``kw`` (r, H)) at the times t (r,): one stacked product for both."""
    H = kw.shape[1]
    ph = kw * t[:, None]
    cs = np.empty((t.size, 1, 2 * H))
    np.cos(ph, out=cs[:, 0, :H])
    np.sin(ph, out=cs[:, 0, H:])
    out = np.matmul(cs, W)[:, 0]
    return a0 + out[:, 0], out[:, 1]


def _crossings(
    Q: FloatArray, omega: FloatArray, samples: FloatArray, levels: FloatArray
) -> tuple[np.ndarray, FloatArray, FloatArray, np.ndarray]:
    """:func:`crossing_times_batch` with per-row levels; also returns each crossing's level column."""
    P, N = samples.shape
    H = (Q.shape[1] - 1) // 2
    levels = np.asarray(levels, dtype=float)
    per_row = levels.ndim == 2
    levels = levels if per_row else np.atleast_1d(levels)
    # Sign of δ − d at every sample for every level at once (a NaN level, padding, never changes
    # sign); a crossing lies between samples j and j + 1 (cyclically).
    above = samples[:, None, :] > (levels[:, :, None] if per_row else levels[None, :, None])  # (P, k, N)
    change = np.empty_like(above)
    np.not_equal(above[:, :, :-1], above[:, :, 1:], out=change[:, :, :-1])
    np.not_equal(above[:, :, -1], above[:, :, 0], out=change[:, :, -1])
    p, col, j = np.nonzero(change)
    lvl = levels[p, col] if per_row else levels[col]
    if p.size == 0:
        return p, np.empty(0), lvl, col
    T = 2 * np.pi / omega[p]
    dt = T / N
    fa = samples[p, j] - lvl
    fb = samples[p, (j + 1) % N] - lvl
    a = j * dt
    b = a + dt
    t = a + dt * fa / (fa - fb)  # linear interpolation of the samples
    kw = np.arange(1, H + 1)[None, :] * omega[p][:, None]
    a0 = Q[p, 0]
    W = _series_weights(Q[p], kw)
    tol = 64 * np.finfo(float).eps * T
    # Fast path: plain Newton from the interpolated guess (quadratic convergence, 2–3 steps for a
    # simple root); only what has not converged inside its bracket goes the safeguarded way.
    t_fast = t.copy()
    done = np.zeros(p.size, dtype=bool)
    for _ in range(4):
        f, fp = _series(a0, W, kw, t_fast)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = (f - lvl) / fp
        t_fast = t_fast - step
        done = np.isfinite(t_fast) & (np.abs(step) <= tol) & (t_fast >= a) & (t_fast <= b)
        if done.all():
            break
    t = np.where(done, t_fast, t)
    fa_val, fb_val = fa.copy(), fb.copy()  # f at the bracket ends
    side = np.zeros(p.size, dtype=int)  # which end moved last (Illinois rule): -1 a, +1 b
    active = np.nonzero(~done)[0]
    for _ in range(60 if active.size else 0):
        f, fp = _series(a0[active], W[active], kw[active], t[active])
        f = f - lvl[active]
        left = (f > 0) == (fa[active] > 0)
        ta = t[active]
        # Illinois: an end kept twice in a row has its value halved, so that regula falsi
        # does not creep towards the root from one side (linear convergence).
        keep_b = left & (side[active] == -1)
        keep_a = ~left & (side[active] == 1)
        fb_val[active] = np.where(keep_b, 0.5 * fb_val[active], fb_val[active])
        fa_val[active] = np.where(keep_a, 0.5 * fa_val[active], fa_val[active])
        a[active] = np.where(left, ta, a[active])
        fa_val[active] = np.where(left, f, fa_val[active])
        b[active] = np.where(left, b[active], ta)
        fb_val[active] = np.where(left, fb_val[active], f)
        side[active] = np.where(left, -1, 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            t_new = ta - f / fp
            # Where Newton leaves the bracket (the series may ripple inside one sample interval
            # near a kink), regula falsi on the bracket; bisection if even that fails.
            t_rf = a[active] - fa_val[active] * (b[active] - a[active]) / (fb_val[active] - fa_val[active])
        # (A step onto a bracket end is allowed: at round-off the root may be that end.)
        bad = ~np.isfinite(t_new) | (t_new < a[active]) | (t_new > b[active])
        bad_rf = ~np.isfinite(t_rf) | (t_rf < a[active]) | (t_rf > b[active])
        t_new = np.where(bad, np.where(bad_rf, 0.5 * (a[active] + b[active]), t_rf), t_new)
        exact = f == 0.0  # landed on the root: keep it (the bracket test would move it)
        t_new = np.where(exact, ta, t_new)
        t[active] = t_new
        moving = (np.abs(t_new - ta) > tol[active]) & ~exact & (b[active] - a[active] > tol[active])
        active = active[moving]
        if active.size == 0:
            break
    t = np.mod(t, T)
    order = np.lexsort((t, p))
    return p[order], t[order], lvl[order], col[order]


def crossing_times_batch(
    Q: FloatArray, omega: FloatArray, samples: FloatArray, levels: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Crossings of many series at once.

    ``Q`` (P, 2H+1) coefficient rows, ``omega`` (P,) base frequencies, ``samples`` (P, N) their
    samples at t_j = j T_p / N, ``levels`` (k,) breakpoints shared by all rows, or (P, k) one
    set per row (NaN pads rows with fewer levels). Sign changes of δ − d between
    successive samples bracket each crossing; Newton from the interpolated samples refines it to
    round-off, and where it does not converge inside the bracket (ripples of the series near a
    kink) Newton safeguarded by Illinois regula falsi and bisection does (δ is C²).

    Returns (row index, crossing time in [0, T_p), level), sorted by row then time.
    """
    p, t, lvl, _ = _crossings(Q, omega, samples, levels)
    return p, t, lvl


# --- the one core: segments between the crossings of all elements ---------------------------
def _padded_levels(breakpoints: Sequence[FloatArray]) -> FloatArray:
    """Breakpoints of m elements as an (m, k_max) array padded with NaN."""
    kmax = max((len(b) for b in breakpoints), default=0)
    out = np.full((len(breakpoints), kmax), np.nan)
    for e, b in enumerate(breakpoints):
        out[e, : len(b)] = b
    return out


def _segments(
    S: FloatArray, omega: FloatArray, samples: FloatArray, breakpoints: Sequence[FloatArray],
    levels: FloatArray | None = None,
) -> tuple[FloatArray, np.ndarray, np.ndarray]:
    """Segments of each orbit between the crossings of all its elements.

    ``S`` (P, m, 2H+1) element deflection series, ``omega`` (P,), ``samples`` (P, m, N) their
    samples, ``breakpoints`` one sorted array per element. Returns ``tau`` (P, G) the segment
    durations (padded with zero-length segments), ``combo`` (P, G) the flat index of each
    segment's stage combination (mixed radix over the elements' stage counts, first element
    most significant) and ``counts`` (P, m, k_max) the crossings per element per breakpoint.
    ``levels`` the breakpoints padded to (m, k_max) with NaN, if already at hand.
    """
    P, m, n_coef = S.shape
    H = (n_coef - 1) // 2
    T = 2 * np.pi / omega
    levels = _padded_levels(breakpoints) if levels is None else levels
    kmax = levels.shape[1]
    if m == 0:  # no element: one segment, the whole period
        p, t, counts_pb = np.empty(0, dtype=np.intp), np.empty(0), np.zeros((P, 0, 0), dtype=np.intp)
    elif m == 1:  # one element: one set of levels for all rows, rows = points (sorted by time)
        p, t, _, col = _crossings(S[:, 0], omega, samples[:, 0], levels[0])
        counts_pb = np.bincount(p * kmax + col, minlength=P * kmax).reshape(P, 1, kmax)
    else:
        rows, t, _, col = _crossings(S.reshape(P * m, n_coef), np.repeat(omega, m),
                                     samples.reshape(P * m, -1), np.tile(levels, (P, 1)))
        counts_pb = np.bincount(rows * kmax + col, minlength=P * m * kmax).reshape(P, m, kmax)
        p = rows // m
        order = np.lexsort((t, p))
        p, t = p[order], t[order]
    counts = np.bincount(p, minlength=P)
    G = int(counts.max()) + 1 if P else 1
    # Segment edges per point, padded with T (zero-length segments give the identity).
    edges = np.repeat(T[:, None], G + 1, axis=1)
    edges[:, 0] = 0.0
    rank = np.arange(p.size) - np.repeat(np.cumsum(counts) - counts, counts)
    edges[p, rank + 1] = t
    tau = np.diff(edges, axis=1)  # (P, G)
    mids = 0.5 * (edges[:, :-1] + edges[:, 1:])
    kw = np.arange(1, H + 1)[None, None, :] * omega[:, None, None]
    ph = kw * mids[:, :, None]
    c, s = np.cos(ph), np.sin(ph)
    combo = np.zeros((P, G), dtype=np.intp)  # no element: the one (empty) combination
    for e, bp in enumerate(breakpoints):
        delta_mid = (
            S[:, None, e, 0]
            + np.einsum("psh,ph->ps", c, S[:, e, 1 : H + 1])
            + np.einsum("psh,ph->ps", s, S[:, e, H + 1 :])
        )
        stage = np.searchsorted(bp, delta_mid, side="right")
        combo = combo * (len(bp) + 1) + stage
    return tau, combo, counts_pb


def _chain_product(phis: FloatArray) -> FloatArray:
    """Φ_G ⋯ Φ_1 of (P, G, k, k) transitions."""
    M = phis[:, 0]
    for s in range(1, phis.shape[1]):
        M = phis[:, s] @ M
    return M


def _combination(system: System, flat: int) -> tuple[int, ...]:
    """The stage combination (one stage per element) of a flat mixed-radix index."""
    out = []
    for c in reversed(system.stage_counts()):
        flat, s = divmod(flat, c)
        out.append(s)
    return tuple(reversed(out))


def _stage_exponentials(system: System, combo: np.ndarray, tau: FloatArray, cache: dict | None = None) -> FloatArray:
    """exp(A_s τ) (..., 2n, 2n) for the flat stage combinations ``combo`` and durations ``tau``.

    n = 1: the closed form :func:`stage_transition`. n > 1: per combination met, its eigen-
    decomposition (cached in ``cache``, keyed by combination) and V diag(e^{λτ}) V⁻¹; where V is
    ill-conditioned (``EIG_CONDITION_LIMIT``), ``scipy.linalg.expm`` of the stacked A_s τ.
    """
    n = system.n
    cache = {} if cache is None else cache
    if n == 1:
        key = ("kappa",)
        kappa = cache.get(key)
        if kappa is None:
            total = int(np.prod(system.stage_counts()))
            kappa = np.array([system.stage_stiffness(_combination(system, i))[0, 0] for i in range(total)])
            cache[key] = kappa
        return stage_transition(kappa[combo], float(system.damping[0, 0]), tau)
    out = np.empty(combo.shape + (2 * n, 2 * n))
    for u in np.unique(combo):
        entry = cache.get(int(u))
        if entry is None:
            A = system.stage_matrix(_combination(system, int(u)))
            lam, V = np.linalg.eig(A)
            try:
                cond = np.linalg.cond(V)
                Vinv = np.linalg.inv(V)
            except np.linalg.LinAlgError:
                cond, Vinv = np.inf, None
            entry = (A, lam, V, Vinv) if cond <= EIG_CONDITION_LIMIT else (A, None, None, None)
            cache[int(u)] = entry
        A, lam, V, Vinv = entry
        sel = combo == u
        tu = tau[sel]
        if lam is None:
            out[sel] = scipy.linalg.expm(A[None, :, :] * tu[:, None, None])
        else:
            with np.errstate(over="ignore", invalid="ignore"):
                E = (V[None, :, :] * np.exp(np.multiply.outer(tu, lam))[:, None, :]) @ Vinv
            out[sel] = E.real
    return out


def element_monodromy_batch(
    system: System, S: FloatArray, omega: FloatArray, samples: FloatArray | None = None,
    n_samples: int | None = None, cache: dict | None = None,
) -> tuple[FloatArray, np.ndarray]:
    """Exact monodromies about orbits given by their element deflection series.

    ``S`` (P, m, 2H+1) the deflection series δ_e = a_e·x of every element ([a_0, a_1..a_H,
    b_1..b_H], FourierBasis convention), ``omega`` (P,) base frequencies (period 2π/ω),
    ``samples`` (P, m, N) their samples at t_j = j T / N (synthesised with ``n_samples`` points,
    default 4(2H+1) rounded up to a power of two, when not given), ``cache`` an optional dict
    keeping the stage combinations' decompositions between calls for the same ``system``.

    Returns ``M`` (P, 2n, 2n) and ``crossings`` (P, m, k_max) the crossings of each element's
    breakpoint j per period (zero where element e has fewer breakpoints than k_max): the orbit's
    crossing structure, which changes where it grazes a breakpoint.
    """
    S = np.asarray(S, dtype=float)
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    if S.ndim != 3 or S.shape[1] != system.m or S.shape[2] % 2 != 1:
        raise ValueError(f"`S` must have shape (P, m={system.m}, 2H+1), got {S.shape}")
    if samples is None:
        H = (S.shape[2] - 1) // 2
        N = n_samples or int(2 ** np.ceil(np.log2(4 * (2 * H + 1))))
        samples = FourierBasis(H, N).synthesize(S)
    if system.n == 1 and system.m == 1 and _kernels.AVAILABLE:  # the single equation: compiled
        cache = {} if cache is None else cache
        kappa = cache.get(("kappa",))
        if kappa is None:
            kappa = cache[("kappa",)] = np.array([system.stage_stiffness((j,))[0, 0]
                                                  for j in range(system.stage_counts()[0])])
        M, counts = _kernels.monodromies(S[:, 0], omega, samples[:, 0], np.asarray(system.elements[0].breakpoints,
                                         dtype=float), kappa, float(system.damping[0, 0]))
        return M, counts[:, None, :]
    tau, combo, counts = _segments(S, omega, samples, [e.breakpoints for e in system.elements])
    return _chain_product(_stage_exponentials(system, combo, tau, cache)), counts


def system_monodromy_batch(
    system: System, X: FloatArray, omega: FloatArray, n_samples: int | None = None, cache: dict | None = None,
) -> tuple[FloatArray, np.ndarray]:
    """Exact monodromies (P, 2n, 2n) and crossings (P, m, k_max) about orbits given by their
    coordinate series ``X`` (P, n, 2H+1) (or (P, n·(2H+1)) coordinate-major rows); see
    :func:`element_monodromy_batch`."""
    X = np.asarray(X, dtype=float)
    if X.ndim == 2:
        X = X.reshape(X.shape[0], system.n, -1)
    if X.ndim != 3 or X.shape[1] != system.n:
        raise ValueError(f"`X` must have shape (P, n={system.n}, 2H+1), got {X.shape}")
    S = np.einsum("en,pnk->pek", system.element_rows, X)
    return element_monodromy_batch(system, S, omega, n_samples=n_samples, cache=cache)


# --- the single-element API (the n = m = 1 case of the core) ---------------------------------
def monodromy_batch(
    Q: FloatArray,
    omega: FloatArray,
    samples: FloatArray,
    stage_breakpoints: FloatArray,
    stage_stiffness: FloatArray,
    damping: float,
) -> FloatArray:
    """Exact monodromies (P, 2, 2) of the linearisation about each orbit over its period 2π/ω.

    ``Q`` (P, 2H+1), ``omega`` (P,) base frequencies, ``samples`` (P, N) the orbits' samples;
    ``stage_breakpoints`` (k,) and ``stage_stiffness`` (k+1,) are the breakpoints and the stage
    stiffnesses k s_j; ``damping`` is c = C/I.
    """
    return monodromy_and_crossings_batch(Q, omega, samples, stage_breakpoints, stage_stiffness, damping)[0]


def monodromy_and_crossings_batch(
    Q: FloatArray,
    omega: FloatArray,
    samples: FloatArray,
    stage_breakpoints: FloatArray,
    stage_stiffness: FloatArray,
    damping: float,
) -> tuple[FloatArray, np.ndarray]:
    """:func:`monodromy_batch` and the number of crossings of each breakpoint per period,
    shape (P, k): the orbit's crossing structure, which changes where it grazes a breakpoint.
    (The single-element case of :func:`element_monodromy_batch`, stage stiffnesses given.)"""
    bp = np.atleast_1d(np.asarray(stage_breakpoints, dtype=float))
    kappa = np.asarray(stage_stiffness, dtype=float)
    if _kernels.AVAILABLE:  # compiled, orbit by orbit (the same formulas; see _kernels)
        return _kernels.monodromies(Q, omega, samples, bp, kappa, damping)
    tau, combo, counts = _segments(Q[:, None, :], omega, samples[:, None, :], (bp,), bp[None, :])
    phis = stage_transition(kappa[combo], damping, tau)
    return _chain_product(phis), counts[:, 0]


def crossing_times(
    basis: FourierBasis, q: FloatArray, omega: float, levels: FloatArray, samples: FloatArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """Times in [0, T) where the series δ(t) (base frequency ``omega``) crosses each level;
    returns (times, level of each crossing) sorted by time (see :func:`crossing_times_batch`)."""
    x = basis.synthesize(q) if samples is None else samples
    _, t, lvl = crossing_times_batch(q[None, :], np.array([omega]), x[None, :], np.asarray(levels, float))
    return t, lvl


def monodromy(
    basis: FourierBasis,
    q: FloatArray,
    omega: float,
    stage_breakpoints: FloatArray,
    stage_stiffness: FloatArray,
    damping: float,
    samples: FloatArray | None = None,
) -> FloatArray:
    """Exact monodromy (2×2) about one orbit q of base frequency ω (see :func:`monodromy_batch`)."""
    x = basis.synthesize(q) if samples is None else samples
    return monodromy_batch(q[None, :], np.array([omega]), x[None, :], stage_breakpoints, stage_stiffness, damping)[0]


# --- multipliers and test functions ----------------------------------------------------------
def multipliers_from_monodromy(M: FloatArray) -> ComplexArray:
    """Eigenvalues of monodromy matrices (..., k, k), sorted by modulus, largest first (..., k).

    Closed form for 2×2: μ = tr/2 ± sqrt(tr²/4 − det); real pairs stay exactly real. Larger
    matrices: LAPACK (real multipliers come out with Im μ = 0 exactly, complex ones in conjugate
    pairs).
    """
    M = np.asarray(M, dtype=float)
    if M.shape[-1] != 2:
        with np.errstate(invalid="ignore"):
            finite = np.all(np.isfinite(M), axis=(-2, -1))
            mu = np.full(M.shape[:-1], np.nan, dtype=complex)
            if np.any(finite):
                mu[finite] = np.linalg.eigvals(M[finite])
        order = np.argsort(-np.abs(mu), axis=-1, kind="stable")
        return np.take_along_axis(mu, order, axis=-1)
    tr = M[..., 0, 0] + M[..., 1, 1]
    det = M[..., 0, 0] * M[..., 1, 1] - M[..., 0, 1] * M[..., 1, 0]
    disc = 0.25 * tr**2 - det
    root = np.sqrt(np.abs(disc))
    real = disc >= 0
    # Avoid cancellation: the larger-modulus real root first, the other from det / μ1.
    big = 0.5 * tr + np.copysign(root, tr)
    with np.errstate(divide="ignore", invalid="ignore"):
        small = np.where(big != 0, det / big, 0.0)
    mu1 = np.where(real, big, 0.5 * tr + 1j * root)
    mu2 = np.where(real, small, 0.5 * tr - 1j * root)
    mu = np.stack([mu1, mu2], axis=-1).astype(complex)
    order = np.argsort(-np.abs(mu), axis=-1, kind="stable")
    return np.take_along_axis(mu, order, axis=-1)


def second_compound(M: FloatArray) -> FloatArray:
    """The bialternate product M ⊙ M (the second compound matrix) of (..., k, k) matrices:
    entry ((i, j), (r, s)), i < j, r < s, is the 2 × 2 minor m_ir m_js − m_is m_jr; shape
    (..., k(k−1)/2, k(k−1)/2). Its eigenvalues are the products μ_i μ_j (i < j) of M's."""
    M = np.asarray(M, dtype=float)
    i, j = np.triu_indices(M.shape[-1], 1)
    a = M[..., i[:, None], i[None, :]] * M[..., j[:, None], j[None, :]]
    b = M[..., i[:, None], j[None, :]] * M[..., j[:, None], i[None, :]]
    return a - b


#: Names of the test functions of :func:`floquet_test_functions`, in order (the last only for n ≥ 2).
TEST_FUNCTIONS = ("fold", "period_doubling", "neimark_sacker")


def neimark_sacker_function(mu: ComplexArray) -> FloatArray:
    """ψ_ns = det(M ⊙ M − I) = Π_{i<j} (μ_i μ_j − 1) from the multipliers μ (..., k) of real
    monodromies (complex ones in exactly conjugate pairs, as LAPACK and
    :func:`multipliers_from_monodromy` give them), in O(k²) after the O(k³) eigenvalues — instead
    of the O(k⁶) determinant of the k(k−1)/2-square bialternate product (:func:`second_compound`,
    2.6 · 10⁸ entries for a 60-inertia chain, k = 120).

    The bialternate product's eigenvalues are the μ_i μ_j (i < j), so the two are the same
    polynomial in M's entries; both are backward stable: this one is ψ_ns of M + E with
    |E| ~ eps |M| (the eigenvalues'), the determinant ψ_ns of M ⊙ M + E'. Where a complex pair
    meets the real axis its members' errors grow to ~ sqrt(eps), but they are opposite and every
    symmetric product (μ_1 μ_2 − 1, (μ_1 μ_j − 1)(μ_2 μ_j − 1)) keeps an error ~ eps, so ψ_ns stays
    smooth enough for the monitor's difference quotient (``_monitor``).

    The factors t = μ_i μ_j − 1 are real (μ_i, μ_j both real, or μ_j = μ̄_i) or come in conjugate
    pairs (product |t|² > 0), so the product is real and its phase Σ arg t a multiple of π (up to
    round-off ~ k² eps, far below π/2):

        ψ_ns = sign(cos Σ arg t) · exp(Σ log |t|),

    a zero factor giving 0, a non-finite μ NaN, and the magnitude without intermediate overflow
    (it overflows to ±inf only where ψ_ns itself exceeds 1.8 · 10³⁰⁸, as the determinant would).
    """
    mu = np.asarray(mu, dtype=complex)
    i, j = _pairs(mu.shape[-1])
    t = mu[..., i] * mu[..., j] - 1.0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        magnitude = np.exp(np.log(np.abs(t)).sum(axis=-1))
        negative = np.cos(np.angle(t).sum(axis=-1)) < 0.0
    return np.where(np.isfinite(t).all(axis=-1), np.where(negative, -magnitude, magnitude), np.nan)


@functools.lru_cache(maxsize=64)
def _pairs(k: int) -> tuple[np.ndarray, np.ndarray]:
    """The index pairs i < j of k multipliers (cached: the monitor asks for the same k each time)."""
    return np.triu_indices(k, 1)


def _eigenvalues(M: FloatArray) -> ComplexArray:
    """Eigenvalues of (..., k, k) matrices, unsorted (NaN for a matrix with a non-finite entry)."""
    finite = np.isfinite(M).all(axis=(-2, -1))
    if np.all(finite):
        return np.linalg.eigvals(M).astype(complex, copy=False)
    mu = np.full(M.shape[:-1], np.nan, dtype=complex)
    if np.any(finite):
        mu[finite] = np.linalg.eigvals(M[finite])
    return mu


def floquet_test_functions(M: FloatArray) -> FloatArray:
    """Floquet test functions of monodromies (..., 2n, 2n), shape (..., 2) for n = 1, (..., 3) else:

        ψ_fold = det(M − I) = Π (μ_k − 1),    ψ_pd = det(M + I) = Π (μ_k + 1),
        ψ_ns = det(M ⊙ M − I) = Π_{i<j} (μ_i μ_j − 1)    (n ≥ 2 only),

    zero at a fold (μ = 1), a period doubling (μ = −1) and a Neimark–Sacker point (μ = e^{±iθ}:
    μ μ̄ = 1) — ψ_ns also vanishes at a neutral saddle (real μ_i μ_j = 1), which
    :func:`~rattle.stability.classify_loss` tells apart. For n = 1, det M = e^{−cT} < 1 and no
    pair reaches the circle: only ψ_fold, ψ_pd. ψ_fold and ψ_pd are LU determinants (O(n³));
    ψ_ns is evaluated from the multipliers (:func:`neimark_sacker_function`, O(n³) for the
    eigenvalues), not as the determinant of the bialternate product (O(n⁶)).
    """
    M = np.asarray(M, dtype=float)
    k = M.shape[-1]
    if k == 2:  # closed form: (m00 ∓ 1)(m11 ∓ 1) − m01 m10
        with np.errstate(over="ignore", invalid="ignore"):
            a, b, c, d = M[..., 0, 0], M[..., 0, 1], M[..., 1, 0], M[..., 1, 1]
            bc = b * c
            return np.stack([(a - 1.0) * (d - 1.0) - bc, (a + 1.0) * (d + 1.0) - bc], axis=-1)
    eye = np.eye(k)
    with np.errstate(over="ignore", invalid="ignore"):
        parts = [np.linalg.det(M - eye), np.linalg.det(M + eye)]
    parts.append(neimark_sacker_function(_eigenvalues(M)))
    return np.stack(parts, axis=-1)


__all__ = [
    "stage_transition", "crossing_times", "crossing_times_batch", "monodromy", "monodromy_batch",
    "monodromy_and_crossings_batch", "element_monodromy_batch", "system_monodromy_batch",
    "multipliers_from_monodromy", "second_compound", "floquet_test_functions", "neimark_sacker_function", "TEST_FUNCTIONS",
    "EIG_CONDITION_LIMIT",
]
