"""Compiled march of the single equation (numba): the loop of
:meth:`~._nonsmooth._ScalarEventFlow._march_events` in scalar loops, for a discontinuous law and
for a continuous one (:class:`~._integrator._ScalarFlow`: the law without jumps or friction, its
stages the modes σ = 0; the saltation at a breakpoint where the field is continuous — no jump, the
same friction level on both sides — is the identity, as in the Python marches). One compiled
march for both scalar paths: one dispatcher whose cache a command loads.

The equation, its modes (slip on a stage with friction sign σ, stick, lock), its events and
their saltation matrices are those of :mod:`._nonsmooth` (its module docstring). On a shooting
continuation the Python march spends its time in the interpreter: some ten events a period, each
a segment in modal form (:class:`~._integrator._Segment`), a scan of the event grid for the
first stop of δ' and another for the first crossing of a breakpoint (:func:`~._roots.resolve_cell`),
their roots by :func:`~._roots.bracketed_newton`, the band exits of a stick or lock. Here the
same steps run compiled, line for line:

* the segment: δ(τ) = P + r τ + ½ a τ² + Re Σ_m A_m e^{μ_m τ} (the stage's eigenvalues and the
  harmonics i nΩ, their phases at the segment's start folded into A_m), its point evaluations
  with the same floating-point operations in the same order as :meth:`_Segment.state`;
* the grid of the searches: the same chunks (:func:`~._roots.grid_chunk`), the same points, the
  same decisions (first stop, tangential returns of σδ', the crossing search with its extrema);
* the roots: Newton's method safeguarded by bisection from the same brackets and starts.

The grid scans sum the modes in a fixed order where numpy's matrix product may not, so a grid
value may differ from the array code's in its last bits; it only seeds a regula falsi start,
and the roots are the same to round-off. A segment near critical damping (the modal amplitudes
blow up; :class:`_Segment` falls back to the transition-matrix form) is not covered: such a law
keeps the Python march (:func:`supported` decides per mode table).

``AVAILABLE`` is False when numba cannot be imported; the flows then keep their Python marches (the
references: :meth:`~._integrator._ScalarFlow._march`, :meth:`~._nonsmooth._ScalarEventFlow._march_events`).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit, numba  # numba is a dependency; the Python march stays the fallback (and the reference)

AVAILABLE = numba is not None

if AVAILABLE:
    from numba import types
    from numba.extending import intrinsic

    @intrinsic
    def _fma(typingctx, a, b, c):  # type: ignore[no-untyped-def]
        """a b + c rounded once (LLVM's fma: the hardware's fused multiply-add)."""
        sig = types.float64(types.float64, types.float64, types.float64)

        def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
            return builder.fma(*args)

        return sig, codegen
else:  # pragma: no cover

    def _fma(a, b, c):  # type: ignore[no-untyped-def]
        return a * b + c

_EPS = float(np.finfo(float).eps)
# Integers passed to the compiled helpers are numpy int64, not Python literals: numba compiles a
# helper once per literal value otherwise (five root finders, three grids …: twice the compile).
_I = np.int64
_STOP_CHUNK = _I(64)  # cells of a chunk of the first-stop grid and the band-exit grid (_nonsmooth._CHUNK)
_FIRST_CHUNK = _I(48)  # first chunk of the crossing search, doubled up to _MAX_CHUNK (_integrator)
_MAX_CHUNK = _I(4096)

SLIP, STICK, LOCK = 0, 1, 2
#: event codes of :func:`march` (the names of NonsmoothTrajectory.event_kind)
EVENT_NAMES = ("crossing", "reversal", "stick", "unstick", "lock", "unlock")
_CROSSING, _REVERSAL, _STICK, _UNSTICK, _LOCK, _UNLOCK = (_I(i) for i in range(6))
#: status of :func:`march`: done, the event budget exceeded, the record's capacity exceeded
DONE, BUDGET, FULL = 0, 1, 2

# the functions whose roots bracketed_newton finds
_VEL, _ACCEL, _GAP, _G_UP, _G_DN, _DF = (_I(i) for i in range(6))
_D0, _D1, _D2 = _I(0), _I(1), _I(2)  # derivative orders of the forcing
_NO_TERMS = _I(0)  # K of a search on the forcing alone


def supported(stage_table: np.ndarray, sigma: float) -> bool:
    """Whether every mode's segment has the modal form (under-damped, or over-damped with its
    two real modes apart: γ > 0.01 σ) — the segments :func:`march` evaluates."""
    for row in stage_table:
        if not (row[0] or row[2] > 0.01 * sigma):
            return False
    return True


# --- forcing ---------------------------------------------------------------------------------
def _force(t, deriv, nw, fc, fs, mean):
    """F(t) or its ``deriv``-th derivative (≤ 2): StageSolutions.force, same operations."""
    out = mean if deriv == 0 else 0.0
    for h in range(nw.size):
        w = nw[h]
        th = w * t
        co = math.cos(th)
        si = math.sin(th)
        if deriv == 0:
            out += fc[h] * co - fs[h] * si
        elif deriv == 1:
            out -= w * (fc[h] * si + fs[h] * co)
        else:
            out -= w * w * (fc[h] * co - fs[h] * si)
    return out


def _forcing(t, deriv, nw, fc, fs, mean):
    """F(t) or F'(t) at one grid point as StageSolutions.forcing writes it (matrix-vector
    products over the harmonics of w·fc and w·fs, w = nw^deriv, summed by fused multiply-adds
    as the BLAS kernels do)."""
    s1 = 0.0
    s2 = 0.0
    for h in range(nw.size):
        th = t * nw[h]
        w = 1.0 if deriv == 0 else nw[h]
        if deriv == 0:
            s1 = _fma(math.cos(th), w * fc[h], s1)
            s2 = _fma(math.sin(th), w * fs[h], s2)
        else:
            s1 = _fma(math.sin(th), w * fc[h], s1)
            s2 = _fma(math.cos(th), w * fs[h], s2)
    if deriv == 0:
        return s1 - s2 + mean
    return -(s1 + s2)


# --- the segment -------------------------------------------------------------------------------
def _seg_init(S, st, sigma, xr, xi, nw, m, ts, delta, velocity):
    """The segment of mode m from (δ, δ') at ts into S (rows μ re/im, A, μA, μ²A re/im): its
    number of terms K, homogeneous part (h0, h1) and round-off floors (as _Segment.__init__)."""
    under = st[m, 0] != 0.0
    wd, lam1, lam2 = st[m, 1], st[m, 3], st[m, 4]
    P, r, a = st[m, 7], st[m, 8], st[m, 9]
    # homogeneous_start: x_s − p(t_s) (StageSolutions._particular_scalar at τ = 0)
    tau = 0.0
    pd = P + tau * (r + 0.5 * a * tau)
    pv = r + a * tau
    for h in range(nw.size):
        th = nw[h] * ts
        co = math.cos(th)
        si = math.sin(th)
        pd += xr[m, h] * co - xi[m, h] * si
        pv -= nw[h] * (xr[m, h] * si + xi[m, h] * co)
    h0 = delta - pd
    h1 = velocity - pv
    if under:
        S[0, 0] = -sigma
        S[1, 0] = wd
        S[2, 0] = h0
        S[3, 0] = -(h1 + sigma * h0) / wd
        K = 1
    else:
        den = lam1 - lam2
        S[0, 0] = lam1
        S[1, 0] = 0.0
        S[2, 0] = (h1 - lam2 * h0) / den
        S[3, 0] = 0.0
        S[0, 1] = lam2
        S[1, 1] = 0.0
        S[2, 1] = (lam1 * h0 - h1) / den
        S[3, 1] = 0.0
        K = 2
    for h in range(nw.size):
        w = nw[h]
        ph = w * ts
        er = math.cos(ph)
        ei = math.sin(ph)
        S[0, K] = 0.0
        S[1, K] = w
        S[2, K] = xr[m, h] * er - xi[m, h] * ei
        S[3, K] = xr[m, h] * ei + xi[m, h] * er
        K += 1
    sa0 = 0.0
    sa1 = 0.0
    for q in range(K):
        mr, mi, ar, ai = S[0, q], S[1, q], S[2, q], S[3, q]
        br = mr * ar - mi * ai
        bi = mr * ai + mi * ar
        S[4, q] = br
        S[5, q] = bi
        S[6, q] = mr * br - mi * bi
        S[7, q] = mr * bi + mi * br
        sa0 += math.hypot(ar, ai)
        sa1 += math.hypot(br, bi)
    d_floor = 8.0 * _EPS * (abs(delta) + abs(P) + sa0)
    v_floor = 8.0 * _EPS * (abs(r) + sa1)
    return K, h0, h1, d_floor, v_floor


def _seg_state(S, K, P, r, a, tau):
    """(δ, δ', δ'') at local time τ (_Segment.state)."""
    d = P + tau * (r + 0.5 * a * tau)
    v = r + a * tau
    acc = a
    for q in range(K):
        l = math.exp(S[0, q] * tau)
        ph = S[1, q] * tau
        er = l * math.cos(ph)
        ei = l * math.sin(ph)
        d += S[2, q] * er - S[3, q] * ei
        v += S[4, q] * er - S[5, q] * ei
        acc += S[6, q] * er - S[7, q] * ei
    return d, v, acc


def _seg_scan(S, K, P, r, a, taus, n, dout, vout):
    """δ and δ' at taus[:n] (_Segment.scan: exp(τ μ) @ amplitudes; the complex matrix product's
    real part summed as the BLAS kernel does, Σ Re·Re and Σ Im·Im by fused multiply-adds, then
    their difference — the same numbers as numpy's product on this machine's OpenBLAS)."""
    ramp = r != 0.0 or a != 0.0
    for i in range(n):
        tau = taus[i]
        rd = 0.0
        id_ = 0.0
        rv = 0.0
        iv = 0.0
        for q in range(K):
            l = math.exp(tau * S[0, q])
            ph = tau * S[1, q]
            er = l * math.cos(ph)
            ei = l * math.sin(ph)
            rd = _fma(er, S[2, q], rd)
            id_ = _fma(ei, S[3, q], id_)
            rv = _fma(er, S[4, q], rv)
            iv = _fma(ei, S[5, q], iv)
        d = (rd - id_) + P
        v = rv - iv
        if ramp:
            d += tau * (r + 0.5 * a * tau)
            v += r + a * tau
        dout[i] = d
        vout[i] = v


def _grid_chunk(start, end, step, cells, out):
    """:func:`~._roots.grid_chunk` into ``out``: the number of points."""
    n = max(1, min(cells, math.ceil((end - start) / step)))
    for i in range(n + 1):
        out[i] = start + step * float(i)
    if n < cells or out[n] >= end:
        out[n] = end
    return n + 1


def _transition(st, sigma, m, tau):
    """(Φ11, Φ12, Φ21, Φ22) of exp(A_m τ) (model.transition_scalar)."""
    kappa = st[m, 5]
    if st[m, 0] != 0.0:
        wd = st[m, 1]
        e = math.exp(-sigma * tau)
        co = math.cos(wd * tau)
        s = math.sin(wd * tau) / wd
        return e * (co + sigma * s), e * s, -kappa * e * s, e * (co - sigma * s)
    gamma, lam1 = st[m, 2], st[m, 3]
    e1 = math.exp(lam1 * tau)
    m1 = math.expm1(-2.0 * gamma * tau)
    p12 = e1 * -m1 / (2.0 * gamma) if gamma > 0.0 else tau * e1
    return e1 - lam1 * p12, p12, -kappa * p12, e1 * (1.0 + m1) + lam1 * p12


# --- roots -------------------------------------------------------------------------------------
def _fx(which, x, S, K, P, r, a, ts, c, ks, bound, nw, fc, fs, mean):
    """(f, f') of the function ``which`` at x (the closures of the Python searches)."""
    if which == _VEL:
        _, v, acc = _seg_state(S, K, P, r, a, x)
        return v, acc
    if which == _ACCEL:
        _, v, acc = _seg_state(S, K, P, r, a, x)
        return acc, _force(ts + x, _D1, nw, fc, fs, mean) - c * acc - ks * v
    if which == _GAP:
        d, v, _ = _seg_state(S, K, P, r, a, x)
        return d - bound, v
    if which == _G_UP:
        return _force(x, _D0, nw, fc, fs, mean) - bound, _force(x, _D1, nw, fc, fs, mean)
    if which == _G_DN:
        return bound - _force(x, _D0, nw, fc, fs, mean), -_force(x, _D1, nw, fc, fs, mean)
    return _force(x, _D1, nw, fc, fs, mean), _force(x, _D2, nw, fc, fs, mean)


def _newton(which, a_, b_, fa, fb, tol, ftol, S, K, P, r, a, ts, c, ks, bound, nw, fc, fs, mean):
    """:func:`~._roots.bracketed_newton` on the function ``which``."""
    if fa == 0.0:
        return a_
    if fb == 0.0:
        return b_
    if fa > 0.0:
        lo, hi = b_, a_
    else:
        lo, hi = a_, b_
    x = 0.5 * (a_ + b_) if fb == fa else a_ - fa * (b_ - a_) / (fb - fa)
    dx_old = dx = abs(b_ - a_)
    for _ in range(200):
        f, df = _fx(which, x, S, K, P, r, a, ts, c, ks, bound, nw, fc, fs, mean)
        if abs(f) <= ftol:
            return x
        if f < 0.0:
            lo = x
        else:
            hi = x
        if ((x - hi) * df - f) * ((x - lo) * df - f) > 0.0 or abs(2.0 * f) > abs(dx_old * df):
            dx_old, dx = dx, 0.5 * (hi - lo)
            x = lo + dx
        else:
            dx_old, dx = dx, f / df
            x -= dx
        if abs(dx) <= tol:
            return x
    return x


# --- event searches -----------------------------------------------------------------------------
def _first_stop(S, K, P, r, a, ts, v_floor, sigma_f, tau_end, step, sps, c, ks, ke, nw, fc, fs, mean,
                taus, dbuf, vbuf, fine, dfine, vfine):
    """First local time in (0, tau_end] where σ δ' reaches 0, NaN when it does not
    (_ScalarEventFlow._first_stop)."""
    if not math.isfinite(step):
        step = max(tau_end, 1e-300) / sps
    tol_t = 4.0 * _EPS * max(tau_end, step) + 1e-300
    tau_a = 0.0
    first = True
    while tau_a < tau_end:
        n = _grid_chunk(tau_a, tau_end, step, _STOP_CHUNK, taus)
        _seg_scan(S, K, P, r, a, taus, n, dbuf, vbuf)
        if first and sigma_f * vbuf[1] <= 0.0 and abs(vbuf[0]) <= v_floor:
            t1 = taus[1]
            stp = t1 / 64.0
            for q in range(1, 65):
                fine[q - 1] = (float(q) / 64.0) * t1 if stp == 0.0 else float(q) * stp + 0.0
            fine[63] = t1
            _seg_scan(S, K, P, r, a, fine, _I(64), dfine, vfine)
            i0 = -1
            for q in range(64):
                if sigma_f * vfine[q] > v_floor:
                    i0 = q
                    break
            if i0 < 0:
                return fine[0]
            ib = -1
            for q in range(i0, 64):
                if sigma_f * vfine[q] <= 0.0:
                    ib = q
                    break
            if ib >= 0:
                return _newton(_VEL, fine[ib - 1], fine[ib], vfine[ib - 1], vfine[ib], tol_t, v_floor,
                               S, K, P, r, a, ts, c, ks, 0.0, nw, fc, fs, mean)
        i_hit = -1
        for q in range(1, n):
            if sigma_f * vbuf[q] <= 0.0:
                i_hit = q
                break
        top = n if i_hit < 0 else i_hit
        # tangential returns of σδ' towards 0 inside a cell before the hit's
        acc_prev = 0.0
        for q in range(top):
            acc_q = _forcing(ts + taus[q], _D0, nw, fc, fs, mean) - c * vbuf[q] - ks * dbuf[q] - ke
            if q > 0:
                i = q - 1
                if (sigma_f * acc_prev < 0.0 and sigma_f * acc_q >= 0.0 and sigma_f * vbuf[i] > 0.0
                        and sigma_f * vbuf[q] > 0.0):
                    tau_m = _newton(_ACCEL, taus[i], taus[q], acc_prev, acc_q, tol_t, 0.0,
                                    S, K, P, r, a, ts, c, ks, 0.0, nw, fc, fs, mean)
                    v_m = _seg_state(S, K, P, r, a, tau_m)[1]
                    if sigma_f * v_m <= 0.0:
                        return _newton(_VEL, taus[i], tau_m, vbuf[i], v_m, tol_t, v_floor,
                                       S, K, P, r, a, ts, c, ks, 0.0, nw, fc, fs, mean)
            acc_prev = acc_q
        if i_hit >= 0:
            va = vbuf[i_hit - 1]
            if sigma_f * va <= 0.0:
                va = sigma_f * 1e-300
            return _newton(_VEL, taus[i_hit - 1], taus[i_hit], va, vbuf[i_hit], tol_t, v_floor,
                           S, K, P, r, a, ts, c, ks, 0.0, nw, fc, fs, mean)
        tau_a = taus[n - 1]
        first = False
    return math.nan


def _resolve_cell(S, K, P, r, a, lo, hi, tau_a, tau_b, d_a, d_b, v_a, v_b, at_start, d_floor, v_floor,
                  nw, fc, fs, mean):
    """:func:`~._roots.resolve_cell`: (τ, direction), direction 0 when δ stays or only grazes."""
    tol = 4.0 * _EPS * tau_b + 1e-300
    end_up = d_b >= hi
    end_down = d_b < lo
    if v_a != 0.0 and (v_a > 0.0) != (v_b > 0.0):
        if v_b == 0.0:
            tau_e = tau_b
        else:
            tau_e = _newton(_VEL, tau_a, tau_b, v_a, v_b, tol, v_floor, S, K, P, r, a, 0.0, 0.0, 0.0, 0.0,
                            nw, fc, fs, mean)
        d_e = _seg_state(S, K, P, r, a, tau_e)[0]
        if v_a > 0.0:
            if d_e - hi > d_floor or end_up:
                up, a_, b_, da, db = True, tau_a, tau_e, d_a, d_e
            elif end_down:
                up, a_, b_, da, db = False, tau_e, tau_b, d_e, d_b
            else:
                return 0.0, 0
        else:
            if lo - d_e > d_floor or end_down:
                up, a_, b_, da, db = False, tau_a, tau_e, d_a, d_e
            elif end_up:
                up, a_, b_, da, db = True, tau_e, tau_b, d_e, d_b
            else:
                return 0.0, 0
    elif end_up or end_down:
        up, a_, b_, da, db = end_up, tau_a, tau_b, d_a, d_b
    else:
        return 0.0, 0
    bound = hi if up else lo
    fa = da - bound
    fb = db - bound
    if (fa >= 0.0) if up else (fa < 0.0):
        if not (at_start and a_ == 0.0):
            return a_, (1 if up else -1)
        fa = -1e-300 if up else 1e-300
    tau_c = _newton(_GAP, a_, b_, fa, fb, tol, d_floor, S, K, P, r, a, 0.0, 0.0, 0.0, bound, nw, fc, fs, mean)
    return tau_c, (1 if up else -1)


def _first_exit(S, K, P, r, a, lo, hi, tau_end, step, sps, d_floor, v_floor, nw, fc, fs, mean, taus, dbuf, vbuf):
    """First local time in (0, tau_end] where δ leaves [lo, hi): (τ, direction ±1, δ' there);
    (tau_end, 0, δ' there) when it stays (_ScalarFlow._first_exit)."""
    if lo > -math.inf or hi < math.inf:
        if not math.isfinite(step):
            step = max(tau_end, 1e-300) / sps
        tau_a = 0.0
        chunk = _FIRST_CHUNK
        while tau_a < tau_end:
            npts = _grid_chunk(tau_a, tau_end, step, chunk, taus)
            n = npts - 1
            _seg_scan(S, K, P, r, a, taus, npts, dbuf, vbuf)
            i_out = n
            for q in range(1, npts):
                if dbuf[q] >= hi or dbuf[q] < lo:
                    i_out = q - 1
                    break
            for i in range(i_out + 1):
                if i == n:
                    break
                d_a, d_b, v_a, v_b = dbuf[i], dbuf[i + 1], vbuf[i], vbuf[i + 1]
                if i != i_out:
                    if (v_a > 0.0) == (v_b > 0.0):
                        continue  # no turn in this cell
                    excursion = 2.0 * (taus[i + 1] - taus[i]) * max(abs(v_a), abs(v_b))
                    if (max(d_a, d_b) + excursion < hi) if v_a > 0.0 else (min(d_a, d_b) - excursion > lo):
                        continue
                tau_c, direction = _resolve_cell(S, K, P, r, a, lo, hi, taus[i], taus[i + 1], d_a, d_b, v_a, v_b,
                                                 i == 0 and tau_a == 0.0, d_floor, v_floor, nw, fc, fs, mean)
                if direction != 0 and tau_c < tau_end:
                    return tau_c, direction, _seg_state(S, K, P, r, a, tau_c)[1]
            tau_a = taus[n]
            chunk = min(2 * chunk, _MAX_CHUNK)
    return tau_end, 0, _seg_state(S, K, P, r, a, tau_end)[1]


def _polish(S, K, P, r, a, bound, tau, tau_max):
    """:func:`~._roots.polish_crossing`: the polished time, NaN when ``tau`` stands."""
    tp = tau
    for _ in range(3):
        dd, vv, _ = _seg_state(S, K, P, r, a, tp)
        if vv == 0.0:
            break
        dt = (dd - bound) / vv
        tp -= dt
        if abs(dt) <= 2.0 * _EPS * abs(tp):
            break
    if 0.0 < tp <= tau_max and abs(tp - tau) <= 1e-6 * max(tau, 1e-300) + 1e-12:
        return tp
    return math.nan


def _band_exit(t0, t1, lo, hi, sps, nw, fc, fs, mean, S, taus, F, F1):
    """First time in (t0, t1] where F(t) leaves [lo, hi]: (time, +1 above / −1 below), (NaN, 0)
    when it stays (_ScalarEventFlow._band_exit)."""
    if nw.size == 0:
        Fm = mean
        if lo <= Fm <= hi:
            return math.nan, 0
        return t0, (1 if Fm > hi else -1)
    wmax = nw[0]
    for h in range(nw.size):
        wmax = max(wmax, nw[h])
    step = 2.0 * math.pi / wmax / sps
    tol = 4.0 * _EPS * max(abs(t1), 1.0)
    ta = t0
    while ta < t1:
        npts = _grid_chunk(ta, t1, step, _STOP_CHUNK, taus)
        n = npts - 1
        for q in range(npts):
            F[q] = _forcing(taus[q], _D0, nw, fc, fs, mean)
            F1[q] = _forcing(taus[q], _D1, nw, fc, fs, mean)
        for i in range(n):
            a_, b_ = taus[i], taus[i + 1]
            found = False
            up = False
            if F[i + 1] > hi:
                found, up = True, True
            elif F[i + 1] < lo:
                found, up = True, False
            elif (F1[i] > 0.0) != (F1[i + 1] > 0.0) and F1[i] != 0.0:
                te = _newton(_DF, a_, b_, F1[i], F1[i + 1], tol, 0.0, S, _NO_TERMS, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                             nw, fc, fs, mean)
                Fe = _force(te, _D0, nw, fc, fs, mean)
                if Fe > hi:
                    found, up, b_ = True, True, te
                elif Fe < lo:
                    found, up, b_ = True, False, te
            if found:
                which = _G_UP if up else _G_DN
                bound = hi if up else lo
                ga = _fx(which, a_, S, _NO_TERMS, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, bound, nw, fc, fs, mean)[0]
                gb = _fx(which, b_, S, _NO_TERMS, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, bound, nw, fc, fs, mean)[0]
                if ga >= 0.0:
                    ga = -1e-300
                te = _newton(which, a_, b_, ga, gb, tol, 0.0, S, _NO_TERMS, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, bound,
                             nw, fc, fs, mean)
                for _ in range(64):
                    ge, dge = _fx(which, te, S, _NO_TERMS, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, bound, nw, fc, fs, mean)
                    if ge >= 0.0 or te >= b_:
                        break
                    te = min(b_, max(np.nextafter(te, math.inf), te - 2.0 * ge / dge if dge > 0 else te))
                return te, (1 if up else -1)
        ta = taus[n]
    return math.nan, 0


# --- the march ---------------------------------------------------------------------------------
def _keep_segment(rec_t, rec_i, rec_x, ns, t, kind, j, sgn, d, v, h0, h1):
    """Segment ``ns`` into the record (one of zero length before it, at the same t, replaced): the
    new count; nothing kept when the record is empty (a march for its end only)."""
    if rec_t.size == 0:
        return ns
    if ns > 0 and rec_t[ns - 1] == t:
        ns -= 1
    rec_t[ns] = t
    rec_i[ns, 0], rec_i[ns, 1], rec_i[ns, 2] = kind, j, sgn
    rec_x[ns, 0], rec_x[ns, 1], rec_x[ns, 2], rec_x[ns, 3] = d, v, h0, h1
    return ns + 1


def _keep_event(ev_t, ev_k, ne, t, code):
    """Event ``ne`` (time, code) into the record: the new count (nothing kept in an empty record)."""
    if ev_t.size == 0:
        return ne
    ev_t[ne], ev_k[ne] = t, code
    return ne + 1


def _march(st, sigma, xr, xi, nw, fc, fs, mean, grid_step, sps, bp, slope, offset, jump, fric, k, c, x_lock,
           max_events, kind, j, sgn, d, v, t0, t1, rec_t, rec_i, rec_x, ev_t, ev_k):
    """The march of _ScalarEventFlow._march_events from (δ, δ') = (d, v) at t0 in the state
    (kind, stage or breakpoint j, friction sign sgn) to t1, recording the segments (start time;
    kind, stage, sign; start state and homogeneous part) and events (time, code of
    :data:`EVENT_NAMES`) — none when the record's arrays are empty (the end state only).
    Returns (status, segments, events, δ, δ', Φ11, Φ12, Φ21, Φ22)."""
    H = nw.size
    S = np.empty((8, H + 2))
    taus = np.empty(_MAX_CHUNK + 1)
    dbuf = np.empty(_MAX_CHUNK + 1)
    vbuf = np.empty(_MAX_CHUNK + 1)
    fine = np.empty(64)
    dfine = np.empty(64)
    vfine = np.empty(64)
    cap = rec_t.size
    ns = 0
    ne = 0
    if kind != SLIP:
        v = 0.0
    t = t0
    m11, m12, m21, m22 = 1.0, 0.0, 0.0, 1.0
    if kind == STICK or (kind == LOCK and jump[j] == 0.0):
        m22 = 0.0
    elif kind == LOCK:
        m11 = m22 = 0.0
    n_events = 0
    while True:
        if cap > 0 and (ns >= cap or ne >= cap):
            return FULL, ns, ne, d, v, m11, m12, m21, m22
        if kind == SLIP:
            mode = 3 * j + sgn + 1
            K, h0, h1, d_floor, v_floor = _seg_init(S, st, sigma, xr, xi, nw, mode, t, d, v)
            P, r, a = st[mode, 7], st[mode, 8], st[mode, 9]
            ks, ke = st[mode, 5], st[mode, 6]
            ns = _keep_segment(rec_t, rec_i, rec_x, ns, t, kind, j, sgn, d, v, h0, h1)
            tau_end = t1 - t
            step = grid_step[mode]
            tau_v = math.nan
            if sgn != 0:
                tau_v = _first_stop(S, K, P, r, a, t, v_floor, float(sgn), tau_end, step, sps, c, ks, ke,
                                    nw, fc, fs, mean, taus, dbuf, vbuf, fine, dfine, vfine)
            stopped = not math.isnan(tau_v)
            lim = tau_v if stopped else tau_end
            lo_m = bp[j - 1] if j > 0 else -math.inf
            hi_m = bp[j] if j < bp.size else math.inf
            tau_c, direction, v_c = _first_exit(S, K, P, r, a, lo_m, hi_m, lim, step, sps, d_floor, v_floor,
                                                nw, fc, fs, mean, taus, dbuf, vbuf)
            tau = tau_c if direction != 0 else lim
            b11, b12, b21, b22 = m11, m12, m21, m22
            f11, f12, f21, f22 = _transition(st, sigma, mode, tau)
            m11, m12, m21, m22 = (f11 * m11 + f12 * m21, f11 * m12 + f12 * m22,
                                  f21 * m11 + f22 * m21, f21 * m12 + f22 * m22)
            if direction == 0 and not stopped:
                d_e, v_e, _ = _seg_state(S, K, P, r, a, tau)
                return DONE, ns, ne, d_e, v_e, m11, m12, m21, m22
            t = t + tau
            F = _force(t, _D0, nw, fc, fs, mean)
            if direction != 0:  # δ reaches breakpoint i
                up = direction > 0
                i = j if up else j - 1
                jn = j + 1 if up else j - 1
                d = bp[i]
                if jump[i] > 0.0 or fric[i] != fric[i + 1]:
                    tau_p = _polish(S, K, P, r, a, d, tau_c, lim)
                    if not math.isnan(tau_p):
                        t = t - tau + tau_p
                        tau = tau_p
                        v_c = _seg_state(S, K, P, r, a, tau)[1]
                        F = _force(t, _D0, nw, fc, fs, mean)
                        m11, m12, m21, m22 = b11, b12, b21, b22
                        f11, f12, f21, f22 = _transition(st, sigma, mode, tau)
                        m11, m12, m21, m22 = (f11 * m11 + f12 * m21, f11 * m12 + f12 * m22,
                                              f21 * m11 + f22 * m21, f21 * m12 + f22 * m22)
                v = v_c
                sn = 0 if fric[jn] == 0.0 else (1 if up else -1)
                lo = k * (slope[i] * d + offset[i] - fric[i])
                hi = k * (slope[i + 1] * d + offset[i + 1] + fric[i + 1])
                a_in = F - c * v - k * ((slope[jn] * d + offset[jn]) + fric[jn] * sn)
                if (lo < F < hi and a_in * v < 0.0 and v * v <= 2.0 * abs(a_in) * x_lock
                        and (jump[i] > 0.0 or fric[i] + fric[jn] > 0.0)):
                    kind, j, v = LOCK, i, 0.0
                    if jump[i] > 0.0:
                        m11, m12, m21, m22 = 0.0, 0.0, 0.0, 0.0
                    else:
                        m21, m22 = 0.0, 0.0
                    ne = _keep_event(ev_t, ev_k, ne, t, _LOCK)
                else:
                    if jump[i] > 0.0 or fric[i] != fric[i + 1]:  # the field jumps: the saltation matrix
                        a_m = F - c * v - k * ((slope[j] * d + offset[j]) + fric[j] * sgn)
                        a_p = F - c * v - k * ((slope[jn] * d + offset[jn]) + fric[jn] * sn)
                        q = (a_p - a_m) / v if v != 0.0 else 0.0
                        m21, m22 = m21 + q * m11, m22 + q * m12
                    j, sgn = jn, sn
                    ne = _keep_event(ev_t, ev_k, ne, t, _CROSSING)
            else:  # δ' = 0 inside stage j with friction
                d = _seg_state(S, K, P, r, a, tau)[0]
                v = 0.0
                R = F - k * (slope[j] * d + offset[j])
                if abs(R) <= k * fric[j]:
                    kind = STICK
                    m21, m22 = 0.0, 0.0
                    ne = _keep_event(ev_t, ev_k, ne, t, _STICK)
                else:
                    sn = 1 if R > 0.0 else -1
                    a_m, a_p = R - k * fric[j] * sgn, R - k * fric[j] * sn
                    if a_m != 0.0:
                        m21, m22 = m21 * (a_p / a_m), m22 * (a_p / a_m)
                    sgn = sn
                    ne = _keep_event(ev_t, ev_k, ne, t, _REVERSAL)
        else:
            ns = _keep_segment(rec_t, rec_i, rec_x, ns, t, kind, j, 0, d, 0.0, 0.0, 0.0)
            if kind == STICK:
                fd = k * (slope[j] * d + offset[j])
                lo, hi = fd - k * fric[j], fd + k * fric[j]
            else:
                lo = k * (slope[j] * bp[j] + offset[j] - fric[j])
                hi = k * (slope[j + 1] * bp[j] + offset[j + 1] + fric[j + 1])
            t_exit, direction = _band_exit(t, t1, lo, hi, sps, nw, fc, fs, mean, S, taus, dbuf, vbuf)
            if direction == 0:
                return DONE, ns, ne, d, 0.0, m11, m12, m21, m22
            up = direction > 0
            t = t_exit
            if kind == STICK:
                sgn = 1 if up else -1
                ne = _keep_event(ev_t, ev_k, ne, t, _UNSTICK)
            else:
                j = j + 1 if up else j
                sgn = 0 if fric[j] == 0.0 else (1 if up else -1)
                ne = _keep_event(ev_t, ev_k, ne, t, _UNLOCK)
            kind, v = SLIP, 0.0
        n_events += 1
        if n_events > max_events:
            return BUDGET, ns, ne, d, v, m11, m12, m21, m22


if AVAILABLE:
    _jit = njit  # rattle._jit: the one compile setting
    _force, _forcing, _transition = _jit(_force), _jit(_forcing), _jit(_transition)
    _seg_init, _seg_state, _seg_scan, _grid_chunk = _jit(_seg_init), _jit(_seg_state), _jit(_seg_scan), _jit(_grid_chunk)
    _fx, _newton, _polish = _jit(_fx), _jit(_newton), _jit(_polish)
    _first_stop, _resolve_cell, _first_exit, _band_exit = (_jit(_first_stop), _jit(_resolve_cell), _jit(_first_exit),
                                                           _jit(_band_exit))
    _keep_segment, _keep_event = _jit(_keep_segment), _jit(_keep_event)
    march = _jit(_march)
else:  # pragma: no cover
    march = None

__all__ = ["AVAILABLE", "EVENT_NAMES", "DONE", "BUDGET", "FULL", "march", "supported"]
