"""Closed-form stage solutions of the single equation (c = C/I, k = K/I)

    δ'' + c δ' + k f(δ) = F(t) = F_m + Σ_n F_pn cos(n Ω t + φ_n),

linear on every stage j of the law, f(δ) = s_j δ + e_j:

    δ'' + c δ' + k s_j δ = F(t) − k e_j.

Its solution from a state x_s = (δ_s, δ'_s) at time t_s is, with τ = t − t_s,

    x(t) = p(t) + Φ_j(τ) (x_s − p(t_s)),      Φ_j(τ) = exp(A_j τ),  A_j = [[0, 1], [−k s_j, −c]],

where p is a particular solution: the constant (F_m − k e_j)/(k s_j) (a ramp ((F_m − k e_j)/c) τ on a
zero-stiffness stage with c > 0, a parabola ½ (F_m − k e_j) τ² when also c = 0) plus
Re[X_jn e^{i n Ω t}], X_jn = F_pn e^{iφ_n} / (k s_j − (nΩ)² + i c nΩ) for every harmonic. Φ_j is
the closed form of :mod:`rattle.model._stage_matrix` (under-, critically and over-damped, zero
stiffness), the one shared with the stability layer.
"""

from __future__ import annotations

import bisect
import copy
import math

import numpy as np

from .._typing import FloatArray
from .._validate import check_omega
from ..model import Model, stage_constants, transition_entries, transition_scalar

_EPS = float(np.finfo(float).eps)
_TWO_PI = 2.0 * math.pi


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
        self.samples_per_scale = samples_per_scale
        self.c = c
        self.breakpoints = np.asarray(st.breakpoints, dtype=float)
        self._breakpoints_l = self.breakpoints.tolist()
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
        self._orders = exc.orders[keep].astype(float)
        self.fc = amps[keep] * np.cos(phases[keep])
        self.fs = amps[keep] * np.sin(phases[keep])
        self.mean = float(exc.mean)

        # Homogeneous part: exp(A_j τ) in closed form (rattle.model._stage_matrix, the one
        # formula); eigenvalues of A_j are −σ ± sqrt(σ² − k s_j).
        const = stage_constants(ks, c)
        self.sigma = const.sigma
        self.under, self.wd, self.gamma = const.under, const.wd, const.gamma  # wd: damped natural frequency
        self.lam1, self.lam2 = const.lam1, const.lam2  # slow and fast real eigenvalues (over-damped)
        self._const_j = [const._replace(under=const.under[j], wd=const.wd[j], gamma=const.gamma[j],
                                        lam1=const.lam1[j], lam2=const.lam2[j], kappa=const.kappa[j])
                         for j in range(self.n_stages)]

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
        self._fc_l = self.fc.tolist()
        self._fs_l = self.fs.tolist()
        self._stage_l = [
            (bool(self.under[j]), float(self.wd[j]), float(self.gamma[j]), float(self.lam1[j]),
             float(self.lam2[j]), float(ks[j]), float(ke[j]), float(self.P[j]), float(self.r[j]),
             float(self.a[j]))
            for j in range(self.n_stages)
        ]
        #: Per stage the arguments of transition_scalar but τ (the crossing search's hot loop).
        self._trans_l = [(float(self.sigma), *self._stage_l[j][:6]) for j in range(self.n_stages)]
        self._set_omega(omega)

    def at_omega(self, omega: float) -> StageSolutions:
        """The same stages' solutions at forcing frequency ``omega``: only what depends on Ω (the
        forcing's particular parts and the event grid) computed afresh, equal to
        ``StageSolutions(model, omega, samples_per_scale)``."""
        out = copy.copy(self)
        out._set_omega(check_omega(omega))
        return out

    def _set_omega(self, omega: float) -> None:
        """The parts that depend on Ω: the harmonics' frequencies nΩ, the particular amplitudes X
        and the event grid's steps."""
        self.omega = omega
        self.nw = self._orders * omega
        ks, c = self.ks, self.c
        stiff = ks > 0.0
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
        self.grid_step = scales / self.samples_per_scale

        # Python-float copies for the scalar evaluations of the crossing search.
        self._nw_l = self.nw.tolist()
        self._x_l = [list(zip(self.xr[j].tolist(), self.xi[j].tolist())) for j in range(self.n_stages)]

    # --- stage lookup ------------------------------------------------------------------------
    def stage_of(self, t: float, delta: float, velocity: float) -> int:
        """Stage holding the state (δ, δ') at time t; exactly on a breakpoint the direction of
        motion decides (sign of δ', then of δ'', the upper stage if both vanish)."""
        j = bisect.bisect_right(self._breakpoints_l, delta)  # np.searchsorted(…, side="right")
        if j > 0 and delta == self._breakpoints_l[j - 1]:
            acc = float(self.forcing(np.asarray(t))) - self.c * velocity - self.ks[j] * delta - self.ke[j]
            direction = velocity if velocity != 0.0 else acc
            if direction < 0.0:
                j -= 1
        return j

    # --- scalar evaluations (hot loop of the crossing search) --------------------------------
    def transition_scalar(self, j: int, tau: float) -> tuple[float, float, float, float]:
        """Entries (Φ11, Φ12, Φ21, Φ22) of exp(A_j τ)."""
        return transition_scalar(*self._trans_l[j], tau)

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

    def force(self, t: float, derivative: int = 0) -> float:
        """F(t) or its ``derivative``-th time derivative (0 … 3) at one time, as a float (the
        scalar form of :meth:`forcing`, for the event searches' hot loops)."""
        out = self.mean if derivative == 0 else 0.0
        for nw, fc, fs in zip(self._nw_l, self._fc_l, self._fs_l):
            th = nw * t
            co, si = math.cos(th), math.sin(th)
            if derivative == 0:
                out += fc * co - fs * si
            elif derivative == 1:
                out -= nw * (fc * si + fs * co)
            elif derivative == 2:
                out -= nw * nw * (fc * co - fs * si)
            else:
                out += nw * nw * nw * (fc * si + fs * co)
        return out

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
        return transition_entries(self._const_j[j], tau)

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


__all__ = ["StageSolutions"]
