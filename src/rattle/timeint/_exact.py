"""Exact time integration of the rattle equation for continuous piecewise-linear laws.

The equation (c = C/I, k = K/I)

    δ'' + c δ' + k f(δ) = F(t) = F_m + Σ_n F_pn cos(n Ω t + φ_n)

is linear on every stage j of the law, f(δ) = s_j δ + e_j:

    δ'' + c δ' + k s_j δ = F(t) − k e_j.

Its solution from a state x_s = (δ_s, δ'_s) at time t_s is, with τ = t − t_s,

    x(t) = p(t) + Φ_j(τ) (x_s − p(t_s)),      Φ_j(τ) = exp(A_j τ),  A_j = [[0, 1], [−k s_j, −c]],

where p is a particular solution: the constant (F_m − k e_j)/(k s_j) (a ramp ((F_m − k e_j)/c) τ on a
zero-stiffness stage with c > 0, a parabola ½ (F_m − k e_j) τ² when also c = 0) plus
Re[X_jn e^{i n Ω t}], X_jn = F_pn e^{iφ_n} / (k s_j − (nΩ)² + i c nΩ) for every harmonic. Φ_j is
written in closed form (under-, critically and over-damped, zero stiffness), so nothing here is
approximated: the only numerical step is locating the times where δ(t) reaches a breakpoint,
which is done to round-off.

Crossings are bracketed on a grid of ``samples_per_scale`` points per fastest time scale of the
stage (the period of the highest forcing harmonic, the stage's natural period and the damping
time 1/c). Between grid points the extrema of δ (sign changes of δ') are refined too, so a
trajectory that touches a breakpoint tangentially inside a grid cell is not missed. An excursion
beyond a breakpoint that is below round-off (an exact graze) does not switch the stage.

Because f is continuous, the vector field is continuous across a breakpoint: the saltation matrix
of a crossing is the identity, and the sensitivity ∂x(t1)/∂x(t0) of a trajectory is the product
of the stage transition matrices exp(A_j Δt_j) of its segments.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .._typing import FloatArray, IntArray
from .._validate import check_omega, check_state
from ..errors import ConvergenceError
from ..model import Model

_EPS = float(np.finfo(float).eps)
_TWO_PI = 2.0 * math.pi
_FIRST_CHUNK = 48  # grid cells scanned at once for the first crossing; doubled up to _MAX_CHUNK
_MAX_CHUNK = 4096
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(12)
_PANELS_PER_SCALE = 4  # Gauss-Legendre panels per stage time scale (measures)


# ---------------------------------------------------------------------------------------------
# Closed-form stage solutions
# ---------------------------------------------------------------------------------------------
class StageSolutions:
    """Closed-form solution data of every stage of ``model`` at forcing frequency ``omega``.

    Holds the state-transition matrices Φ_j(τ) = exp(A_j τ) and the particular solutions p_j(t)
    of δ'' + c δ' + k s_j δ = F(t) − k e_j (see the module docstring). A segment of a trajectory
    on stage j starting at (t_s, x_s) is described by its homogeneous part h = x_s − p_j(t_s):
    x(t) = p_j(t) + Φ_j(t − t_s) h.

    Raises ``ValueError`` for an undamped stage in exact resonance with a forcing harmonic
    (k s_j = (nΩ)², c = 0), whose solution grows secularly.
    """

    def __init__(self, model: Model, omega: float, samples_per_scale: int = 40) -> None:
        omega = check_omega(omega)
        st = model.elastic.stages
        exc = model.excitation
        c, k = model.c, model.k
        self.model = model
        self.omega = omega
        self.c = c
        self.breakpoints = np.asarray(st.breakpoints, dtype=float)
        self.lower = np.concatenate(([-np.inf], self.breakpoints))
        self.upper = np.concatenate((self.breakpoints, [np.inf]))
        self.n_stages = len(st.slopes)
        ks = k * np.asarray(st.slopes, dtype=float)
        ke = k * np.asarray(st.offsets, dtype=float)
        self.ks, self.ke = ks, ke

        # Forcing: F(t) = F_m + Σ (fc cos nΩt − fs sin nΩt), harmonics with zero amplitude dropped.
        amps = np.asarray(exc.amplitudes, dtype=float)
        phases = np.asarray(exc.phases, dtype=float)
        keep = amps != 0.0
        self.nw = exc.orders[keep].astype(float) * omega
        self.fc = amps[keep] * np.cos(phases[keep])
        self.fs = amps[keep] * np.sin(phases[keep])
        self.mean = float(exc.mean)

        # Homogeneous part: eigenvalues of A_j are −σ ± sqrt(σ² − k s_j).
        sigma = 0.5 * c
        self.sigma = sigma
        disc = sigma * sigma - ks
        self.under = disc < 0.0
        self.wd = np.sqrt(np.where(self.under, -disc, 0.0))  # damped natural frequency
        self.gamma = np.sqrt(np.where(self.under, 0.0, disc))
        s_plus = sigma + self.gamma
        self.lam2 = -s_plus  # fast real eigenvalue
        # slow real eigenvalue −k s_j / (σ + γ), written without cancellation (0 if k s_j = 0)
        self.lam1 = np.where(s_plus > 0.0, -ks / np.where(s_plus > 0.0, s_plus, 1.0), 0.0)

        # Particular part: P + r τ + ½ a τ² + Re Σ X e^{i nΩ t}.
        rhs = self.mean - ke
        stiff = ks > 0.0
        self.P = np.where(stiff, rhs / np.where(stiff, ks, 1.0), 0.0)
        if c > 0.0:
            self.r = np.where(stiff, 0.0, rhs / c)
            self.a = np.zeros_like(ks)
        else:
            self.r = np.zeros_like(ks)
            self.a = np.where(stiff, 0.0, rhs)
        den = ks[:, None] - self.nw[None, :] ** 2 + 1j * c * self.nw[None, :]
        resonant = np.abs(den) <= 64.0 * _EPS * self.nw[None, :] ** 2
        if np.any(resonant):
            j, n = np.argwhere(resonant)[0]
            raise ValueError(
                f"stage {j} (stiffness k*s = {ks[j]!r}) is in exact resonance with forcing harmonic "
                f"{n + 1} at `omega` = {omega!r} and there is no damping (`damping` = 0): the "
                "response grows without bound; add damping or change `omega`"
            )
        X = (self.fc + 1j * self.fs)[None, :] / den
        self.xr, self.xi = X.real.copy(), X.imag.copy()

        # Grid step per stage: a fraction of its fastest time scale.
        scales = np.full(self.n_stages, np.inf)
        if self.nw.size:
            scales[:] = _TWO_PI / float(np.max(self.nw))
        if c > 0.0:
            scales = np.minimum(scales, 1.0 / c)
        scales = np.where(stiff, np.minimum(scales, _TWO_PI / np.sqrt(np.where(stiff, ks, 1.0))), scales)
        self.time_scale = scales
        self.grid_step = scales / samples_per_scale

        # Python-float copies for the scalar evaluations of the crossing search.
        self._nw_l = self.nw.tolist()
        self._fc_l = self.fc.tolist()
        self._fs_l = self.fs.tolist()
        self._x_l = [list(zip(self.xr[j].tolist(), self.xi[j].tolist())) for j in range(self.n_stages)]
        self._stage_l = [
            (bool(self.under[j]), float(self.wd[j]), float(self.gamma[j]), float(self.lam1[j]),
             float(self.lam2[j]), float(ks[j]), float(ke[j]), float(self.P[j]), float(self.r[j]),
             float(self.a[j]))
            for j in range(self.n_stages)
        ]

    # --- stage lookup ------------------------------------------------------------------------
    def stage_of(self, t: float, delta: float, velocity: float) -> int:
        """Stage holding the state (δ, δ') at time t; exactly on a breakpoint the direction of
        motion decides (sign of δ', then of δ'', the upper stage if both vanish)."""
        j = int(np.searchsorted(self.breakpoints, delta, side="right"))
        if j > 0 and delta == self.breakpoints[j - 1]:
            acc = float(self.forcing(np.asarray(t))) - self.c * velocity - self.ks[j] * delta - self.ke[j]
            direction = velocity if velocity != 0.0 else acc
            if direction < 0.0:
                j -= 1
        return j

    # --- scalar evaluations (hot loop of the crossing search) --------------------------------
    def transition_scalar(self, j: int, tau: float) -> tuple[float, float, float, float]:
        """Entries (Φ11, Φ12, Φ21, Φ22) of exp(A_j τ)."""
        under, wd, gamma, lam1, lam2, ks = self._stage_l[j][:6]
        sigma = self.sigma
        if under:
            e = math.exp(-sigma * tau)
            co = math.cos(wd * tau)
            s = math.sin(wd * tau) / wd
            return e * (co + sigma * s), e * s, -ks * e * s, e * (co - sigma * s)
        e1 = math.exp(lam1 * tau)
        p12 = e1 * (-math.expm1(-2.0 * gamma * tau)) / (2.0 * gamma) if gamma > 0.0 else tau * e1
        return e1 - lam1 * p12, p12, -ks * p12, math.exp(lam2 * tau) + lam1 * p12

    def _particular_scalar(self, j: int, t: float, tau: float) -> tuple[float, float, float]:
        """p(t), p'(t) and F(t) as floats."""
        P, r, a = self._stage_l[j][7:]
        pd = P + tau * (r + 0.5 * a * tau)
        pv = r + a * tau
        force = self.mean
        for nw, fc, fs, (xr, xi) in zip(self._nw_l, self._fc_l, self._fs_l, self._x_l[j]):
            th = nw * t
            co, si = math.cos(th), math.sin(th)
            pd += xr * co - xi * si
            pv -= nw * (xr * si + xi * co)
            force += fc * co - fs * si
        return pd, pv, force

    def homogeneous_start(self, j: int, ts: float, delta: float, velocity: float) -> tuple[float, float]:
        """h = x_s − p_j(t_s): the homogeneous part of a segment starting at (t_s, x_s)."""
        pd, pv, _ = self._particular_scalar(j, ts, 0.0)
        return delta - pd, velocity - pv

    def point(self, j: int, t: float, ts: float, h0: float, h1: float) -> tuple[float, float, float]:
        """(δ, δ', δ'') at time t on a segment of stage j (start ts, homogeneous part h)."""
        tau = t - ts
        f11, f12, f21, f22 = self.transition_scalar(j, tau)
        pd, pv, force = self._particular_scalar(j, t, tau)
        d = pd + f11 * h0 + f12 * h1
        v = pv + f21 * h0 + f22 * h1
        return d, v, force - self.c * v - self._stage_l[j][5] * d - self._stage_l[j][6]

    # --- vectorised evaluations ----------------------------------------------------------------
    def transition(self, j: int, tau: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Entries (Φ11, Φ12, Φ21, Φ22) of exp(A_j τ), elementwise over ``tau``."""
        sigma, ks = self.sigma, self.ks[j]
        if self.under[j]:
            wd = self.wd[j]
            e = np.exp(-sigma * tau)
            co = np.cos(wd * tau)
            s = np.sin(wd * tau) / wd
            es = e * s
            return e * (co + sigma * s), es, -ks * es, e * (co - sigma * s)
        gamma, lam1, lam2 = self.gamma[j], self.lam1[j], self.lam2[j]
        e1 = np.exp(lam1 * tau)
        p12 = e1 * (-np.expm1(-2.0 * gamma * tau)) / (2.0 * gamma) if gamma > 0.0 else tau * e1
        return e1 - lam1 * p12, p12, -ks * p12, np.exp(lam2 * tau) + lam1 * p12

    def forcing(self, t: FloatArray, derivative: int = 0) -> FloatArray:
        """F(t) or its ``derivative``-th time derivative, elementwise."""
        t = np.asarray(t, dtype=float)
        th = np.multiply.outer(t, self.nw)
        co, si = np.cos(th), np.sin(th)
        w = self.nw**derivative
        if derivative % 4 == 0:
            out = co @ (w * self.fc) - si @ (w * self.fs)
        elif derivative % 4 == 1:
            out = -(si @ (w * self.fc) + co @ (w * self.fs))
        elif derivative % 4 == 2:
            out = -(co @ (w * self.fc) - si @ (w * self.fs))
        else:
            out = si @ (w * self.fc) + co @ (w * self.fs)
        return out + self.mean if derivative == 0 else out

    def evaluate(
        self, j: int, t: FloatArray, ts: FloatArray | float, h0: FloatArray | float,
        h1: FloatArray | float, order: int = 1,
    ) -> list[FloatArray]:
        """[δ, δ', …, δ^(order)] at times ``t`` on segments of stage j (``order`` ≤ 4).

        ``ts``, ``h0``, ``h1`` (segment start and homogeneous part) broadcast against ``t``.
        Derivatives beyond the first come from the equation: δ'' = F − c δ' − k s_j δ − k e_j,
        and its time derivatives.
        """
        t = np.asarray(t, dtype=float)
        tau = t - ts
        f11, f12, f21, f22 = self.transition(j, tau)
        th = np.multiply.outer(t, self.nw)
        co, si = np.cos(th), np.sin(th)
        xr, xi, nw = self.xr[j], self.xi[j], self.nw
        d = self.P[j] + tau * (self.r[j] + 0.5 * self.a[j] * tau) + co @ xr - si @ xi + f11 * h0 + f12 * h1
        v = self.r[j] + self.a[j] * tau - si @ (nw * xr) - co @ (nw * xi) + f21 * h0 + f22 * h1
        out = [d, v]
        c, ks = self.c, self.ks[j]
        if order >= 2:
            force = self.mean + co @ self.fc - si @ self.fs
            out.append(force - c * v - ks * d - self.ke[j])
        if order >= 3:
            dforce = -(si @ (nw * self.fc) + co @ (nw * self.fs))
            out.append(dforce - c * out[2] - ks * v)
        if order >= 4:
            ddforce = -(co @ (nw**2 * self.fc) - si @ (nw**2 * self.fs))
            out.append(ddforce - c * out[3] - ks * out[2])
        return out[: order + 1]


# ---------------------------------------------------------------------------------------------
# Root finding
# ---------------------------------------------------------------------------------------------
def _bracketed_newton(
    fun: Callable[[float], tuple[float, float]], a: float, b: float, fa: float, fb: float, tol: float,
    ftol: float = 0.0,
) -> float:
    """Root of ``fun`` in [a, b] (fa·fb ≤ 0) by Newton's method safeguarded by bisection
    (Numerical Recipes' rtsafe); ``fun(x)`` returns (f, f'). Stops when the step is below ``tol``
    or |f| ≤ ``ftol`` (the round-off floor of f)."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if fa > 0.0:  # orient so that f(lo) < 0 < f(hi)
        lo, hi = b, a
    else:
        lo, hi = a, b
    x = a - fa * (b - a) / (fb - fa)  # regula falsi start: good for a transversal crossing
    dx_old = dx = abs(b - a)
    for _ in range(200):
        f, df = fun(x)
        if abs(f) <= ftol:
            return x
        if f < 0.0:
            lo = x
        else:
            hi = x
        if ((x - hi) * df - f) * ((x - lo) * df - f) > 0.0 or abs(2.0 * f) > abs(dx_old * df):
            dx_old, dx = dx, 0.5 * (hi - lo)  # Newton leaves the bracket or converges slowly
            x = lo + dx
        else:
            dx_old, dx = dx, f / df
            x -= dx
        if abs(dx) <= tol:
            return x
    return x


def _vector_bracketed_newton(
    fun: Callable[[FloatArray, IntArray], tuple[FloatArray, FloatArray]],
    a: FloatArray, b: FloatArray, fa: FloatArray, fb: FloatArray, tol: FloatArray,
) -> FloatArray:
    """Roots of ``fun`` in the brackets [a_i, b_i] (fa·fb ≤ 0), all at once: Newton steps, with a
    bisection wherever the step leaves the bracket. ``fun(x, idx)`` evaluates the roots ``idx``."""
    lo = np.where(fa > 0.0, b, a)
    hi = np.where(fa > 0.0, a, b)
    x = np.where(fa == fb, a, a - fa * (b - a) / np.where(fa == fb, 1.0, fb - fa))
    active = np.ones(a.shape, dtype=bool)
    for _ in range(200):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        f, df = fun(x[idx], idx)
        neg = f < 0.0
        lo[idx] = np.where(neg, x[idx], lo[idx])
        hi[idx] = np.where(neg, hi[idx], x[idx])
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = x[idx] - f / df
        # Closed bracket: a converged Newton step may land on the end just updated (round-off).
        inside = np.isfinite(newton) & ((newton - lo[idx]) * (newton - hi[idx]) <= 0.0)
        x_new = np.where(inside, newton, 0.5 * (lo[idx] + hi[idx]))
        done = (f == 0.0) | (np.abs(x_new - x[idx]) <= tol[idx]) | (np.abs(hi[idx] - lo[idx]) <= tol[idx])
        x[idx] = np.where(f == 0.0, x[idx], x_new)
        active[idx[done]] = False
    return x


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class StateSamples:
    """Exact samples of a trajectory: ``t`` (s), ``delta`` δ (rad), ``velocity`` δ' (rad/s),
    ``acceleration`` δ'' (rad/s², from the equation) and the ``stage`` index, all of t's shape."""

    t: FloatArray
    delta: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    stage: IntArray


@dataclass(frozen=True, slots=True, kw_only=True)
class ExactMeasures:
    """Response measures of a trajectory over [t0, t1] (SPEC §1), exact to round-off.

    ``mean`` (1/T)∫δ dt, ``rms`` sqrt((1/T)∫δ² dt), ``rms_ac`` sqrt((1/T)∫(δ − mean)² dt),
    ``delta_min``/``delta_max`` and ``p2p`` of δ, ``acc_min``/``acc_max`` and ``acc_p2p`` of δ''.
    """

    mean: float
    rms: float
    rms_ac: float
    delta_min: float
    delta_max: float
    p2p: float
    acc_min: float
    acc_max: float
    acc_p2p: float


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class Trajectory:
    """An exact trajectory of δ'' + c δ' + k f(δ) = F(t) from ``t0`` to ``t1``.

    It is a sequence of segments, each on one stage of the law: segment i runs from
    ``t_start[i]`` to ``t_end[i]`` on stage ``stage[i]`` from state ``x_start[i]`` = (δ, δ').
    A new segment starts exactly where δ reaches a breakpoint and leaves the stage.
    ``state0``/``state1`` are the states at t0/t1 (shape (2,)), ``sensitivity`` the 2×2 matrix
    ∂x(t1)/∂x(t0) = Π_i exp(A_{stage[i]} (t_end[i] − t_start[i])) (the saltation matrices of the
    crossings are the identity because f is continuous).
    """

    omega: float
    t0: float
    t1: float
    state0: FloatArray
    state1: FloatArray
    sensitivity: FloatArray
    t_start: FloatArray
    t_end: FloatArray
    stage: IntArray
    x_start: FloatArray
    solutions: StageSolutions = field(repr=False, compare=False)
    homogeneous: FloatArray = field(repr=False, compare=False)  # (n, 2): x_start − p(t_start)

    @property
    def n_segments(self) -> int:
        return int(self.t_start.size)

    @property
    def crossing_times(self) -> FloatArray:
        """Times where δ crossed a breakpoint (the segment starts after the first), shape (n−1,)."""
        return self.t_start[1:]

    @property
    def crossed_breakpoints(self) -> FloatArray:
        """The breakpoint crossed at each of ``crossing_times`` (rad), shape (n−1,)."""
        return self.x_start[1:, 0]

    def segment_index(self, t: FloatArray | float) -> IntArray:
        """Index of the segment holding each time (the later one at a crossing)."""
        idx = np.searchsorted(self.t_start, t, side="right") - 1
        return np.clip(idx, 0, self.n_segments - 1)

    def derivatives(self, t: FloatArray | float, order: int = 2, segment: IntArray | None = None) -> list[FloatArray]:
        """[δ, δ', …, δ^(order)] at times ``t`` (any shape, within [t0, t1]); ``order`` ≤ 4.

        ``segment`` forces the segment of every time (to evaluate a segment's one-sided limits
        at its ends, where δ''' and δ'''' jump).
        """
        t = np.asarray(t, dtype=float)
        span = max(abs(self.t0), abs(self.t1), self.t1 - self.t0)
        if t.size and (np.min(t) < self.t0 - 4 * _EPS * span or np.max(t) > self.t1 + 4 * _EPS * span):
            raise ValueError(
                f"`t` must lie within the trajectory's interval [{self.t0!r}, {self.t1!r}], got values "
                f"in [{float(np.min(t))!r}, {float(np.max(t))!r}]"
            )
        seg = self.segment_index(t) if segment is None else np.broadcast_to(segment, t.shape)
        stage = self.stage[seg]
        out = [np.empty(t.shape) for _ in range(order + 1)]
        for j in np.unique(stage):
            m = stage == j
            sm = seg[m]
            vals = self.solutions.evaluate(
                int(j), t[m], self.t_start[sm], self.homogeneous[sm, 0], self.homogeneous[sm, 1], order
            )
            for o, val in zip(out, vals):
                o[m] = val
        return out

    def sample(self, t: FloatArray | float) -> StateSamples:
        """δ, δ', δ'' (exact) at times ``t`` (any shape, s) within [t0, t1]."""
        t = np.asarray(t, dtype=float)
        d, v, a = self.derivatives(t, 2)
        return StateSamples(t=t, delta=d, velocity=v, acceleration=a, stage=self.stage[self.segment_index(t)])

    # --- exact measures ------------------------------------------------------------------------
    def _segment_points(self, per_scale: float) -> tuple[IntArray, FloatArray, FloatArray]:
        """Equally spaced points on every segment, both ends included, at least ``per_scale``
        cells per stage time scale: (segment index, time, cell count of the segment)."""
        length = self.t_end - self.t_start
        step = self.solutions.time_scale[self.stage] / per_scale
        step = np.where(np.isfinite(step), step, np.maximum(self.t1 - self.t0, 1.0) / per_scale)
        cells = np.maximum(np.ceil(length / step), 1).astype(int)
        seg = np.repeat(np.arange(self.n_segments), cells + 1)
        first = np.repeat(np.cumsum(cells + 1) - (cells + 1), cells + 1)
        frac = (np.arange(seg.size) - first) / cells[seg]
        t = self.t_start[seg] + frac * length[seg]
        t[np.cumsum(cells + 1) - 1] = self.t_end  # ends exactly
        return seg, t, cells

    def _extremes(self, order: int, per_scale: float) -> tuple[float, float]:
        """Min and max of δ^(order) over [t0, t1] (see :meth:`_extremes_of`)."""
        return self._extremes_of((order,), per_scale)[0]

    def _extremes_of(self, orders: tuple[int, ...], per_scale: float) -> list[tuple[float, float]]:
        """Min and max of δ^(order) over [t0, t1] for each of ``orders``: at the segment ends and
        where δ^(order+1) = 0 inside a segment (sign changes on a fine grid, refined by bracketed
        Newton, the roots of all orders at once).

        The roots are located to 1e-9 of their grid cell: at an extremum the value is stationary,
        so a location error ε changes it by ½|δ^(order+2)| ε², far below round-off.
        """
        top = max(orders) + 2
        seg, t, _ = self._segment_points(per_scale)
        vals = self.derivatives(t, top, segment=seg)
        same = seg[1:] == seg[:-1]
        brackets = []
        for k, order in enumerate(orders):
            dg = vals[order + 1]
            change = same & (((dg[:-1] > 0.0) & (dg[1:] <= 0.0)) | ((dg[:-1] < 0.0) & (dg[1:] >= 0.0)))
            i = np.flatnonzero(change)
            brackets.append((np.full(i.size, k), i, dg[i], dg[i + 1]))
        which = np.concatenate([b[0] for b in brackets])
        cells = np.concatenate([b[1] for b in brackets])
        roots = np.empty(0)
        if cells.size:
            fa = np.concatenate([b[2] for b in brackets])
            fb = np.concatenate([b[3] for b in brackets])
            s = seg[cells]
            row = np.asarray(orders)[which] + 1  # δ^(order+1) vanishes; δ^(order+2) is its slope

            def fun(x: FloatArray, idx: IntArray) -> tuple[FloatArray, FloatArray]:
                r = np.asarray(self.derivatives(x, top, segment=s[idx]))
                cols = np.arange(idx.size)
                return r[row[idx], cols], r[row[idx] + 1, cols]

            a, b = t[cells], t[cells + 1]
            tol = 1e-9 * (b - a) + 4.0 * _EPS * np.maximum(np.abs(a), np.abs(b))
            te = _vector_bracketed_newton(fun, a, b, fa, fb, tol)
            at_roots = self.derivatives(te, max(orders), segment=s)
            roots = np.asarray(at_roots)[np.asarray(orders)[which], np.arange(te.size)]
        out = []
        for k, order in enumerate(orders):
            allv = np.concatenate((vals[order], roots[which == k]))
            out.append((float(np.min(allv)), float(np.max(allv))))
        return out

    def measures(self) -> ExactMeasures:
        """Mean, rms, rms_ac, extremes and peak-to-peak values of δ and δ'' over [t0, t1].

        Integrals by 12-point Gauss–Legendre quadrature on panels of at most a quarter of the
        stage's fastest time scale (δ is analytic within a segment, so the quadrature error is far
        below round-off); extremes where δ' (for δ) or δ''' (for δ'') vanish inside a segment, or
        at segment ends (δ'' is continuous, δ''' jumps at crossings).
        """
        duration = self.t1 - self.t0
        if not duration > 0.0:
            raise ValueError("measures need a trajectory of positive duration (t1 > t0)")
        seg, tp, cells = self._segment_points(_PANELS_PER_SCALE)
        ends = np.cumsum(cells + 1) - 1
        left = np.delete(np.arange(tp.size), ends)  # panel left ends
        a, b, s = tp[left], tp[left + 1], seg[left]
        half = 0.5 * (b - a)
        tq = (0.5 * (a + b))[:, None] + half[:, None] * _GAUSS_NODES[None, :]
        wq = half[:, None] * _GAUSS_WEIGHTS[None, :]
        dq = self.derivatives(tq, 0, segment=np.broadcast_to(s[:, None], tq.shape))[0]
        mean = float(np.sum(wq * dq)) / duration
        ms = float(np.sum(wq * dq * dq)) / duration
        ms_ac = float(np.sum(wq * (dq - mean) ** 2)) / duration
        (dmin, dmax), (amin, amax) = self._extremes_of((0, 2), 40.0)
        return ExactMeasures(
            mean=mean, rms=math.sqrt(ms), rms_ac=math.sqrt(ms_ac), delta_min=dmin, delta_max=dmax,
            p2p=dmax - dmin, acc_min=amin, acc_max=amax, acc_p2p=amax - amin,
        )


# ---------------------------------------------------------------------------------------------
# One segment of a trajectory (hot loop)
# ---------------------------------------------------------------------------------------------
class _Segment:
    """The exact solution on stage j from (t_s, x_s), in modal form for fast evaluation:

        δ(τ) = P + r τ + ½ a τ² + Re Σ_m A_m e^{μ_m τ},   τ = t − t_s,

    the modes μ_m being the stage's eigenvalue(s) and i nΩ for the forcing harmonics (whose
    phases at t_s are folded into A_m, so the local time τ carries no round-off of large t).
    For an underdamped stage the form is as well conditioned as Φ(τ) h (|A| is the amplitude of
    the free oscillation); near critical damping the two real modes nearly coincide and their
    amplitudes blow up, so there the segment falls back to the transition-matrix form.
    """

    __slots__ = ("sol", "j", "ts", "h0", "h1", "P", "r", "a", "mu", "amp", "mu_l", "a0_l", "a1_l", "a2_l",
                 "d_floor", "v_floor")

    def __init__(self, sol: StageSolutions, j: int, ts: float, delta: float, velocity: float) -> None:
        self.sol, self.j, self.ts = sol, j, ts
        self.h0, self.h1 = h0, h1 = sol.homogeneous_start(j, ts, delta, velocity)
        under, wd, gamma, lam1, lam2, _, _, self.P, self.r, self.a = sol._stage_l[j]
        sigma = sol.sigma
        if under:
            mu = [complex(-sigma, wd)]
            amp = [complex(h0, -(h1 + sigma * h0) / wd)]
        elif gamma > 0.01 * sigma:
            den = lam1 - lam2
            mu = [complex(lam1), complex(lam2)]
            amp = [complex((h1 - lam2 * h0) / den), complex((lam1 * h0 - h1) / den)]
        else:
            mu = None
        if mu is None:
            self.mu = None
            self.d_floor = 8.0 * _EPS * (abs(delta) + abs(self.P) + abs(h0) + abs(h1) * sol.time_scale[j])
            self.v_floor = 8.0 * _EPS * (abs(velocity) + abs(h0) / sol.time_scale[j] + abs(h1))
            return
        for (xr, xi), w in zip(sol._x_l[j], sol._nw_l):
            mu.append(1j * w)
            amp.append(complex(xr, xi) * cmath.exp(1j * w * ts))
        self.mu_l, self.a0_l = mu, amp
        self.a1_l = [m * x for m, x in zip(mu, amp)]
        self.a2_l = [m * x for m, x in zip(mu, self.a1_l)]
        self.mu = np.array(mu)
        self.amp = np.array([amp, self.a1_l]).T  # (K, 2): δ and δ' amplitudes
        # Round-off floors of δ and δ' (for the root finder's stopping test).
        self.d_floor = 8.0 * _EPS * (abs(delta) + abs(self.P) + sum(map(abs, amp)))
        self.v_floor = 8.0 * _EPS * (abs(self.r) + sum(map(abs, self.a1_l)))

    def scan(self, taus: FloatArray) -> tuple[FloatArray, FloatArray]:
        """δ and δ' at local times ``taus`` (vectorised)."""
        if self.mu is None:
            d, v = self.sol.evaluate(self.j, self.ts + taus, self.ts, self.h0, self.h1, order=1)
            return d, v
        z = np.exp(taus[:, None] * self.mu) @ self.amp
        d = z[:, 0].real + self.P
        v = z[:, 1].real
        if self.r != 0.0 or self.a != 0.0:
            d += taus * (self.r + 0.5 * self.a * taus)
            v += self.r + self.a * taus
        return d, v

    def state(self, tau: float) -> tuple[float, float, float]:
        """(δ, δ', δ'') at local time ``tau``."""
        if self.mu is None:
            return self.sol.point(self.j, self.ts + tau, self.ts, self.h0, self.h1)
        d = self.P + tau * (self.r + 0.5 * self.a * tau)
        v = self.r + self.a * tau
        acc = self.a
        for m, x0, x1, x2 in zip(self.mu_l, self.a0_l, self.a1_l, self.a2_l):
            e = cmath.exp(m * tau)
            d += (x0 * e).real
            v += (x1 * e).real
            acc += (x2 * e).real
        return d, v, acc


# ---------------------------------------------------------------------------------------------
# Integrator
# ---------------------------------------------------------------------------------------------
class ExactIntegrator:
    """Exact integrator of δ'' + c δ' + k f(δ) = F(t) for a model with a continuous
    piecewise-linear law (see the module docstring).

    Parameters
    ----------
    model
        The model (c = C/I, k = K/I, law f, excitation F).
    samples_per_scale
        Grid points per fastest time scale of a stage used to bracket crossings (≥ 8).
    max_segments
        Budget of segments of one ``propagate`` call; exceeding it raises ``ConvergenceError``.
    """

    def __init__(self, model: Model, *, samples_per_scale: int = 40, max_segments: int = 1_000_000) -> None:
        if not isinstance(model, Model):
            raise TypeError(f"`model` must be a rattle Model, got {model!r}")
        for name, value, low in (("samples_per_scale", samples_per_scale, 8), ("max_segments", max_segments, 1)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                raise TypeError(f"`{name}` must be an integer, got {value!r}")
            if value < low:
                raise ValueError(f"`{name}` must be >= {low}, got {value!r}")
        self.model = model
        self.samples_per_scale = int(samples_per_scale)
        self.max_segments = int(max_segments)
        self._cache: tuple[float, StageSolutions] | None = None

    def solutions(self, omega: float) -> StageSolutions:
        """The closed-form stage solutions at forcing frequency ``omega`` (the last one is cached)."""
        if self._cache is not None and self._cache[0] == omega:
            return self._cache[1]
        sol = StageSolutions(self.model, omega, self.samples_per_scale)
        self._cache = (float(omega), sol)
        return sol

    def propagate(self, x0: FloatArray | tuple[float, float], t0: float, t1: float, omega: float) -> Trajectory:
        """Integrate exactly from state ``x0`` = (δ, δ') (rad, rad/s) at ``t0`` to ``t1`` ≥ t0 (s)
        at forcing frequency ``omega`` (rad/s).

        Returns the :class:`Trajectory`: its segments, final state and sensitivity ∂x(t1)/∂x0.
        """
        x0 = check_state(x0)
        t0, t1 = float(t0), float(t1)
        if not (math.isfinite(t0) and math.isfinite(t1) and t1 >= t0):
            raise ValueError(f"`t0` and `t1` must be finite with t1 >= t0, got t0={t0!r}, t1={t1!r}")
        sol = self.solutions(omega)
        starts: list[float] = []
        stages: list[int] = []
        states: list[tuple[float, float]] = []
        homog: list[tuple[float, float]] = []
        d, v, m = self._march(sol, float(x0[0]), float(x0[1]), t0, t1, (starts, stages, states, homog))
        t_start = np.asarray(starts)
        t_end = np.append(t_start[1:], t1)
        return Trajectory(
            omega=float(omega), t0=t0, t1=t1, state0=x0.copy(), state1=np.array([d, v]),
            sensitivity=np.array([[m[0], m[1]], [m[2], m[3]]]), t_start=t_start, t_end=t_end,
            stage=np.asarray(stages, dtype=np.int64), x_start=np.asarray(states, dtype=float).reshape(-1, 2),
            solutions=sol, homogeneous=np.asarray(homog, dtype=float).reshape(-1, 2),
        )

    def _advance(self, delta: float, velocity: float, t0: float, t1: float, omega: float) -> tuple[float, float]:
        """The state (δ, δ') at t1 only, from (δ, δ') at t0 (no checks, no record): the hot path of
        a simulation that only needs its Poincaré points."""
        d, v, _ = self._march(self.solutions(omega), delta, velocity, t0, t1, None)
        return d, v

    def _march(
        self, sol: StageSolutions, d: float, v: float, t0: float, t1: float,
        record: tuple[list, list, list, list] | None,
    ) -> tuple[float, float, tuple[float, float, float, float]]:
        """Segment by segment from (δ, δ') = (d, v) at t0 to t1: the final state and the
        sensitivity (Φ11, Φ12, Φ21, Φ22); the segments are appended to ``record`` (starts,
        stages, start states, homogeneous parts) when given."""
        j = sol.stage_of(t0, d, v)
        t = t0
        n_seg = 0
        m11, m12, m21, m22 = 1.0, 0.0, 0.0, 1.0
        while True:
            seg = _Segment(sol, j, t, d, v)
            tau_c, j_new, d_c, v_c = self._first_exit(seg, t1 - t)
            if tau_c > 0.0 or (j_new < 0 and n_seg == 0):  # zero-length segments (round-off) are dropped
                n_seg += 1
                if record is not None:
                    record[0].append(t)
                    record[1].append(j)
                    record[2].append((d, v))
                    record[3].append((seg.h0, seg.h1))
            f11, f12, f21, f22 = sol.transition_scalar(j, tau_c)
            m11, m12, m21, m22 = (f11 * m11 + f12 * m21, f11 * m12 + f12 * m22,
                                  f21 * m11 + f22 * m21, f21 * m12 + f22 * m22)
            if j_new < 0:
                return d_c, v_c, (m11, m12, m21, m22)
            # Exactly on the breakpoint: snap δ (the root is located to round-off).
            d = float(sol.upper[j] if j_new > j else sol.lower[j])
            v = v_c
            j, t = j_new, t + tau_c
            if n_seg > self.max_segments:
                raise ConvergenceError(
                    f"more than `max_segments` = {self.max_segments} segments between t0 = {t0!r} and "
                    f"t1 = {t1!r}: raise `max_segments` or shorten the interval"
                )

    # --- crossing search -----------------------------------------------------------------------
    def _first_exit(self, seg: _Segment, tau_end: float) -> tuple[float, int, float, float]:
        """First local time in (0, tau_end] where δ leaves the segment's stage: (τ, stage entered,
        δ, δ' there); stage −1 and τ = tau_end when it stays.

        The segment start is inside the stage by construction (a crossing enters the new stage),
        whatever round-off says of δ there.
        """
        sol, j = seg.sol, seg.j
        lo, hi = float(sol.lower[j]), float(sol.upper[j])
        if lo > -math.inf or hi < math.inf:
            step = float(sol.grid_step[j])
            if not math.isfinite(step):
                step = max(tau_end, 1e-300) / self.samples_per_scale
            tau_a = 0.0
            chunk = _FIRST_CHUNK
            while tau_a < tau_end:
                n = max(1, min(chunk, math.ceil((tau_end - tau_a) / step)))
                taus = tau_a + step * np.arange(n + 1)  # the cell starts, then the last end
                if n < chunk or taus[-1] >= tau_end:
                    taus[-1] = tau_end
                d, v = seg.scan(taus)
                if lo == -math.inf:
                    outside = d[1:] >= hi
                elif hi == math.inf:
                    outside = d[1:] < lo
                else:
                    outside = (d[1:] >= hi) | (d[1:] < lo)
                i_out = int(outside.argmax())
                if not outside[i_out]:
                    i_out = n
                pos = v > 0.0
                turns = (pos[:-1] != pos[1:]).nonzero()[0].tolist()
                for i in [i for i in turns if i < i_out] + ([i_out] if i_out < n else []):
                    d_a, d_b, v_a, v_b = float(d[i]), float(d[i + 1]), float(v[i]), float(v[i + 1])
                    if i != i_out:
                        # An extremum inside a cell can only reach a breakpoint within the cell's
                        # possible excursion (δ' passes through zero and |δ'| is at most about its
                        # end values; factor 2 for safety): refine only those.
                        excursion = 2.0 * float(taus[i + 1] - taus[i]) * max(abs(v_a), abs(v_b))
                        if (max(d_a, d_b) + excursion < hi) if v_a > 0.0 else (min(d_a, d_b) - excursion > lo):
                            continue
                    hit = self._resolve_cell(seg, lo, hi, float(taus[i]), float(taus[i + 1]), d_a, d_b, v_a, v_b,
                                             at_start=(i == 0 and tau_a == 0.0))
                    if hit is not None and hit[0] < tau_end:
                        return hit
                tau_a = float(taus[-1])
                chunk = min(2 * chunk, _MAX_CHUNK)
        d_end, v_end, _ = seg.state(tau_end)
        return tau_end, -1, d_end, v_end

    @staticmethod
    def _resolve_cell(
        seg: _Segment, lo: float, hi: float, tau_a: float, tau_b: float,
        d_a: float, d_b: float, v_a: float, v_b: float, at_start: bool,
    ) -> tuple[float, int, float, float] | None:
        """The exit from the segment's stage inside the grid cell [tau_a, tau_b], if any:
        (τ, stage entered, δ, δ' there); None when δ stays inside or only grazes a breakpoint
        (an excursion beyond it below round-off)."""
        state = seg.state

        def velocity_and_acceleration(tau: float) -> tuple[float, float]:
            _, v, a = state(tau)
            return v, a

        tol = 4.0 * _EPS * tau_b + 1e-300
        end_up, end_down = d_b >= hi, d_b < lo
        if v_a != 0.0 and (v_a > 0.0) != (v_b > 0.0):
            # δ has an extremum in the cell: refine it (a tangential touch may hide inside).
            tau_e = tau_b if v_b == 0.0 else _bracketed_newton(
                velocity_and_acceleration, tau_a, tau_b, v_a, v_b, tol, seg.v_floor)
            d_e = state(tau_e)[0]
            graze = seg.d_floor
            if v_a > 0.0:  # a maximum: beyond hi, cross before it; else maybe down after it
                if d_e - hi > graze or end_up:
                    up, a_, b_, d_a_, d_b_ = True, tau_a, tau_e, d_a, d_e
                elif end_down:
                    up, a_, b_, d_a_, d_b_ = False, tau_e, tau_b, d_e, d_b
                else:
                    return None
            else:  # a minimum
                if lo - d_e > graze or end_down:
                    up, a_, b_, d_a_, d_b_ = False, tau_a, tau_e, d_a, d_e
                elif end_up:
                    up, a_, b_, d_a_, d_b_ = True, tau_e, tau_b, d_e, d_b
                else:
                    return None
        elif end_up or end_down:
            up, a_, b_, d_a_, d_b_ = end_up, tau_a, tau_b, d_a, d_b
        else:
            return None
        bound = hi if up else lo
        fa, fb = d_a_ - bound, d_b_ - bound
        if (fa >= 0.0) if up else (fa < 0.0):
            if not (at_start and a_ == 0.0):
                tau_c = a_  # round-off at a graze: the crossing is at the bracket's start
            else:
                fa = -1e-300 if up else 1e-300  # the segment start is inside by construction
        if (fa < 0.0) if up else (fa >= 0.0):

            def gap(tau: float) -> tuple[float, float]:
                d, v, _ = state(tau)
                return d - bound, v

            tau_c = _bracketed_newton(gap, a_, b_, fa, fb, tol, seg.d_floor)
        _, v_c, _ = state(tau_c)
        return tau_c, seg.j + 1 if up else seg.j - 1, bound, v_c


__all__ = ["ExactIntegrator", "Trajectory", "StateSamples", "ExactMeasures", "StageSolutions"]
