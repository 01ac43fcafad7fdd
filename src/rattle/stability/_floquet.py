"""Floquet multipliers of a harmonic-balance orbit from the exact monodromy of its linearisation.

Around a periodic orbit δ(t) the variational equation is

    y'' + c y' + k f'(δ(t)) y = 0,

and for a piecewise-linear law f'(δ(t)) = s_j is piecewise constant in time: it switches where
δ(t) crosses a breakpoint. Because f is continuous the vector field is continuous across the
switching surface, so the saltation matrix is the identity and the monodromy is exactly

    M = Φ_m(Δt_m) ⋯ Φ_1(Δt_1),     Φ_j(τ) = exp(A_j τ),  A_j = [[0, 1], [−k s_j, −c]],

over the segments between successive crossings. The crossing times of the HB orbit are found
on its N samples and refined to round-off by safeguarded Newton on the Fourier series.
"""

from __future__ import annotations

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..hb import FourierBasis


def stage_transition(stiffness: FloatArray, damping: float, tau: FloatArray) -> FloatArray:
    """exp(A τ) for A = [[0, 1], [−κ, −c]], elementwise over κ = ``stiffness`` and ``tau``.

    With σ = −c/2 and D = c²/4 − κ:  exp(Aτ) = e^{στ} [C(τ) I + S(τ) (A − σ I)], where
    C = cosh(√D τ), S = sinh(√D τ)/√D (D > 0); C = cos(√−D τ), S = sin(√−D τ)/√−D (D < 0);
    C = 1, S = τ (D = 0). Overdamped stages are evaluated without overflow (exponentials of
    non-positive arguments only, for stiffness ≥ 0). Returns shape (..., 2, 2).
    """
    kappa = np.asarray(stiffness, dtype=float)
    tau = np.asarray(tau, dtype=float)
    kappa, tau = np.broadcast_arrays(kappa, tau)
    sigma = -0.5 * damping
    D = 0.25 * damping**2 - kappa
    root = np.sqrt(np.abs(D))
    x = root * tau
    over = D > 0
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        # D > 0 (overdamped stage): e^{στ} cosh(√D τ) and e^{στ} sinh(√D τ)/√D written with
        # e^{(σ+√D)τ} and expm1(−2√D τ), which neither overflow (cosh of a large argument times
        # a vanishing e^{στ} would give inf·0) nor cancel for small √D τ.
        grow = np.exp((sigma + root) * tau)
        decay = np.expm1(-2.0 * x)
        eC_over = grow * (1.0 + 0.5 * decay)
        eS_over = grow * (-0.5 * decay) / np.where(root > 0, root, 1.0)
        e = np.exp(sigma * tau)
        eC_osc = e * np.cos(x)
        eS_osc = e * np.sin(x) / np.where(root > 0, root, 1.0)
    eC = np.where(over, eC_over, eC_osc)
    eS = np.where(over, eS_over, eS_osc)
    flat = root == 0  # critically damped stage: C = 1, S = τ
    eC = np.where(flat, e, eC)
    eS = np.where(flat, e * tau, eS)
    out = np.empty(kappa.shape + (2, 2))
    out[..., 0, 0] = eC - sigma * eS
    out[..., 0, 1] = eS
    out[..., 1, 0] = -kappa * eS
    out[..., 1, 1] = eC + sigma * eS
    return out


def _series(Q: FloatArray, kw: FloatArray, t: FloatArray) -> tuple[FloatArray, FloatArray]:
    """δ(t) and δ'(t) of the series rows Q (m, 2H+1) with kω rows kw (m, H) at times t (m,)."""
    H = kw.shape[1]
    ph = kw * t[:, None]
    c, s = np.cos(ph), np.sin(ph)
    a, b = Q[:, 1 : H + 1], Q[:, H + 1 :]
    delta = Q[:, 0] + np.einsum("ij,ij->i", c, a) + np.einsum("ij,ij->i", s, b)
    vel = np.einsum("ij,ij->i", c, kw * b) - np.einsum("ij,ij->i", s, kw * a)
    return delta, vel


def crossing_times_batch(
    Q: FloatArray, omega: FloatArray, samples: FloatArray, levels: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Crossings of many series at once.

    ``Q`` (P, 2H+1) coefficient rows, ``omega`` (P,) base frequencies, ``samples`` (P, N) their
    samples at t_j = j T_p / N, ``levels`` (k,) breakpoints. Sign changes of δ − d between
    successive samples bracket each crossing; Newton from the interpolated samples refines it to
    round-off, and where it does not converge inside the bracket (ripples of the series near a
    kink) Newton safeguarded by Illinois regula falsi and bisection does (δ is C²).

    Returns (point index, crossing time in [0, T_p), level), sorted by point then time.
    """
    P, N = samples.shape
    H = (Q.shape[1] - 1) // 2
    pts, idxs, lvls = [], [], []
    for d in np.atleast_1d(levels):
        s = samples > d
        change = s != np.roll(s, -1, axis=1)
        p, j = np.nonzero(change)
        pts.append(p)
        idxs.append(j)
        lvls.append(np.full(p.size, d))
    if not pts:
        return np.empty(0, dtype=int), np.empty(0), np.empty(0)
    p = np.concatenate(pts)
    j = np.concatenate(idxs)
    lvl = np.concatenate(lvls)
    if p.size == 0:
        return p, np.empty(0), lvl
    T = 2 * np.pi / omega[p]
    dt = T / N
    fa = samples[p, j] - lvl
    fb = samples[p, (j + 1) % N] - lvl
    a = j * dt
    b = a + dt
    t = a + dt * fa / (fa - fb)  # linear interpolation of the samples
    Qp = Q[p]
    kw = np.arange(1, H + 1)[None, :] * omega[p][:, None]
    tol = 64 * np.finfo(float).eps * T
    # Fast path: plain Newton from the interpolated guess (quadratic convergence, 2–3 steps for a
    # simple root); only what has not converged inside its bracket goes the safeguarded way.
    t_fast = t.copy()
    done = np.zeros(p.size, dtype=bool)
    for _ in range(4):
        f, fp = _series(Qp, kw, t_fast)
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
        f, fp = _series(Qp[active], kw[active], t[active])
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
    return p[order], t[order], lvl[order]


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
    shape (P, k): the orbit's crossing structure, which changes where it grazes a breakpoint."""
    P = Q.shape[0]
    H = (Q.shape[1] - 1) // 2
    T = 2 * np.pi / omega
    levels = np.atleast_1d(np.asarray(stage_breakpoints, dtype=float))
    p, t, lvl = crossing_times_batch(Q, omega, samples, levels)
    per_level = np.zeros((P, levels.size), dtype=int)
    if p.size:
        np.add.at(per_level, (p, np.searchsorted(levels, lvl)), 1)
    counts = np.bincount(p, minlength=P)
    n_seg = counts + 1
    S = int(n_seg.max())
    # Segment edges per point, padded with T (zero-length segments give the identity).
    edges = np.repeat(T[:, None], S + 1, axis=1)
    edges[:, 0] = 0.0
    rank = np.arange(p.size) - np.repeat(np.cumsum(counts) - counts, counts)
    edges[p, rank + 1] = t
    tau = np.diff(edges, axis=1)  # (P, S)
    mids = 0.5 * (edges[:, :-1] + edges[:, 1:])
    kw = np.arange(1, H + 1)[None, None, :] * omega[:, None, None]
    ph = kw * mids[:, :, None]
    delta_mid = (
        Q[:, None, 0]
        + np.einsum("psh,ph->ps", np.cos(ph), Q[:, 1 : H + 1])
        + np.einsum("psh,ph->ps", np.sin(ph), Q[:, H + 1 :])
    )
    stage = np.searchsorted(stage_breakpoints, delta_mid, side="right")
    phis = stage_transition(stage_stiffness[stage], damping, tau)  # (P, S, 2, 2)
    M = phis[:, 0]
    for s in range(1, S):
        M = phis[:, s] @ M
    return M, per_level


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


def multipliers_from_monodromy(M: FloatArray) -> ComplexArray:
    """Eigenvalues of monodromy matrices (..., 2, 2), sorted by modulus, largest first (..., 2).

    Closed form for 2×2: μ = tr/2 ± sqrt(tr²/4 − det); real pairs stay exactly real.
    """
    M = np.asarray(M, dtype=float)
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


__all__ = [
    "stage_transition", "crossing_times", "crossing_times_batch", "monodromy", "monodromy_batch",
    "monodromy_and_crossings_batch", "multipliers_from_monodromy",
]
