"""Exact time integration of a :class:`~rattle.model.System`: n coordinates, m clearance elements.

    x'' + C x' + K x + Σ_e b_e f_e(a_e·x) = F(t)

is linear on every stage combination (one stage per element); :mod:`._stage_flow` solves it
there in closed form and :mod:`._events` finds the first time any element's deflection
δ_e = a_e·x reaches a breakpoint of its law. The integrator strings the segments together: a
crossing of element e switches e to its neighbouring stage and starts a new segment from the
crossing state (δ_e put exactly on the breakpoint, a round-off-level projection). Nothing is
approximated but the crossing times, located to round-off.

The laws are continuous, so the vector field is continuous across a breakpoint: the saltation
matrices are the identity and the sensitivity ∂z(t1)/∂z(t0) is the product of the stage
transition matrices exp(A_s τ) of the segments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from .._limits import check_interval
from .._typing import FloatArray, IntArray
from .._validate import as_float_array, check_omega
from ..errors import ConvergenceError
from ..model import System
from ._events import first_exit, vector_bracketed_newton
from ._exact_flow import ExactIntegrator, FlowOptions, takes_continuous
from ._trajectory import ExactTrajectory
from ._stage_flow import Segment, SystemStages

_EPS = float(np.finfo(float).eps)
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(12)
_PANELS_PER_SCALE = 4  # Gauss-Legendre panels per stage time scale (integral measures)
_EXTREMA_PER_SCALE = 40  # grid points per stage time scale bracketing the extrema


def _constant_response(A: FloatArray, g: FloatArray, tau: float) -> FloatArray:
    """∫_0^τ exp(A(τ−σ)) (0, g) dσ (2n,): the response of s' = A s + (0, g) from s = 0 (a constant
    forcing of the lower half), from the exponential of the augmented matrix [[A, (0, g)], [0, 0]]
    (exact also for a singular A)."""
    n2 = A.shape[0]
    Ab = np.zeros((n2 + 1, n2 + 1))
    Ab[:n2, :n2] = A
    Ab[n2 // 2 : n2, n2] = g
    return sla.expm(Ab * tau)[:n2, n2]


def check_system_state(value: object, n: int, name: str = "z0") -> FloatArray:
    """A finite state z = (x, x') of shape (2n,)."""
    z = as_float_array(value, name, f"a state (x, x') of {2 * n} numbers")
    if z.shape != (2 * n,) or not np.all(np.isfinite(z)):
        raise ValueError(
            f"`{name}` must be a finite state (x_1 … x_n, x'_1 … x'_n) of shape ({2 * n},) for a system of "
            f"n = {n} coordinates, got {value!r}"
        )
    return z.copy()


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class SystemSamples:
    """Exact samples of a trajectory at times ``t`` (shape S): coordinates ``x``, ``velocity``
    and ``acceleration`` (S + (n,)); element ``deflection`` δ = A x, ``deflection_velocity`` and
    ``deflection_acceleration`` (S + (m,)); the ``stages`` (S + (m,)) of every element."""

    t: FloatArray
    x: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    deflection: FloatArray
    deflection_velocity: FloatArray
    deflection_acceleration: FloatArray
    stages: IntArray


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class SystemMeasures:
    """Response measures of every element's deflection δ_e over [t0, t1], exact to round-off;
    every field is an array of shape (m,), in the order of ``names``.

    ``mean`` (1/T)∫δ dt, ``rms`` sqrt((1/T)∫δ² dt), ``rms_ac`` sqrt((1/T)∫(δ − mean)² dt),
    ``delta_min``/``delta_max`` and ``p2p`` of δ, ``acc_min``/``acc_max`` and ``acc_p2p`` of δ''.
    """

    names: tuple[str, ...]
    mean: FloatArray
    rms: FloatArray
    rms_ac: FloatArray
    delta_min: FloatArray
    delta_max: FloatArray
    p2p: FloatArray
    acc_min: FloatArray
    acc_max: FloatArray
    acc_p2p: FloatArray

    def element(self, which: int | str) -> dict[str, float]:
        """The measures of one element (index or name) as a dict of floats."""
        i = self.names.index(which) if isinstance(which, str) else int(which)
        return {k: float(getattr(self, k)[i]) for k in
                ("mean", "rms", "rms_ac", "delta_min", "delta_max", "p2p", "acc_min", "acc_max", "acc_p2p")}


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class SystemTrajectory(ExactTrajectory):
    """An exact trajectory of a :class:`~rattle.model.System` from ``t0`` to ``t1``.

    Segment i runs from ``t_start[i]`` to ``t_end[i]`` on the stage combination ``stages[i]``
    (one stage per element, shape (S, m)) from the state ``z_start[i]`` = (x, x') (S, 2n).
    ``crossing_times`` (C,) are the times where an element reached a breakpoint,
    ``crossing_elements`` which element, ``crossing_directions`` +1 (up into the next stage) or
    −1, ``crossing_breakpoints`` the breakpoint reached. ``state0``/``state1`` are z at t0/t1,
    ``sensitivity`` the (2n, 2n) matrix ∂z(t1)/∂z(t0) = Π_i exp(A_{s_i} (t_end[i] − t_start[i])).
    """

    system: System
    stages: IntArray
    z_start: FloatArray
    crossing_times: FloatArray
    crossing_elements: IntArray
    crossing_directions: IntArray
    crossing_breakpoints: FloatArray
    segments: tuple[Segment, ...] = field(repr=False, compare=False)

    def states(self, t: FloatArray | float) -> FloatArray:
        """z = (x, x') at times ``t``, shape t.shape + (2n,)."""
        x, v = self.derivatives(np.asarray(t, dtype=float), 1)
        return np.concatenate((x, v), axis=-1)

    def _segment_derivatives(self, i: int, taus: FloatArray, order: int) -> list[FloatArray]:
        """[x, x', …, x^(order)] at local times ``taus`` of segment i, each (N, n); beyond the
        second from the equation: x^(k+2) = F^(k) − C x^(k+1) − K_s x^(k)."""
        seg = self.segments[i]
        sol = seg.sol
        n = sol.flow.n
        z, zd = seg.state(taus)
        out = [z[:, :n], z[:, n:], zd[:, n:]]
        t = seg.ts + taus
        for k in range(3, order + 1):
            out.append(sol.flow.forcing(t, k - 2) - out[k - 1] @ sol.flow.C.T - out[k - 2] @ sol.Ks.T)
        return out[: order + 1]

    def derivatives(self, t: FloatArray | float, order: int = 2, segment: IntArray | None = None) -> list[FloatArray]:
        """[x, x', …, x^(order)] at times ``t`` (any shape, within [t0, t1]), each of shape
        t.shape + (n,); ``order`` ≤ 4. ``segment`` forces the segment of every time (one-sided
        limits at crossings, where x''' jumps)."""
        if not 0 <= int(order) <= 4:
            raise ValueError(f"`order` must be 0 … 4, got {order!r}")
        t = np.asarray(t, dtype=float)
        self.check_times(t)
        n = self.system.n
        flat = t.reshape(-1)
        seg = self.segment_index(flat) if segment is None else np.broadcast_to(segment, t.shape).reshape(-1)
        out = [np.empty((flat.size, n)) for _ in range(order + 1)]
        idx = np.argsort(seg, kind="stable")
        sorted_seg = seg[idx]
        cuts = np.flatnonzero(sorted_seg[1:] != sorted_seg[:-1]) + 1
        for lo_, hi_ in zip(np.concatenate(([0], cuts)).tolist(), np.concatenate((cuts, [flat.size])).tolist()):
            if hi_ <= lo_:
                continue
            sel = idx[lo_:hi_]
            i = int(sorted_seg[lo_])
            vals = self._segment_derivatives(i, flat[sel] - self.t_start[i], order)
            for o, val in zip(out, vals):
                o[sel] = val
        return [o.reshape(t.shape + (n,)) for o in out]

    def deflections(self, t: FloatArray | float, order: int = 2) -> list[FloatArray]:
        """[δ, δ', …, δ^(order)] of every element at times ``t``: each t.shape + (m,)."""
        rows = self.system.element_rows
        return [x @ rows.T for x in self.derivatives(t, order)]

    def sample(self, t: FloatArray | float) -> SystemSamples:
        """x, x', x'' and the element deflections δ, δ', δ'' (exact) at times ``t``."""
        t = np.asarray(t, dtype=float)
        x, v, a = self.derivatives(t, 2)
        rows = self.system.element_rows
        return SystemSamples(
            t=t, x=x, velocity=v, acceleration=a, deflection=x @ rows.T, deflection_velocity=v @ rows.T,
            deflection_acceleration=a @ rows.T, stages=self.stages[self.segment_index(t)],
        )

    @property
    def final_stages(self) -> tuple[int, ...]:
        """The stage combination at t1 (after a crossing exactly at t1: the stages entered)."""
        return tuple(int(s) for s in self.stages[-1])

    def omega_derivative(self, fixed: str = "time") -> FloatArray:
        """∂z(t1)/∂Ω, the derivative of the final state with respect to the forcing frequency
        for the same initial state, shape (2n,).

        ``fixed="time"``: t0 and t1 held fixed. ``fixed="phase"``: Ωt0 and Ωt1 held fixed (t1 =
        p·2π/Ω for a period map; the derivative of a shooting residual φ(z0; Ω) − z0 with
        respect to Ω). Exact: on every segment s = ∂z/∂Ω solves s' = A_s s + ∂F/∂Ω, whose
        particular solution is closed-form; across a crossing s is continuous (the vector field
        is continuous), so s(t1) = Σ over segments of the transition matrices applied to the
        jumps of the particular solutions.
        """
        if fixed not in ("time", "phase"):
            raise ValueError(f"`fixed` must be 'time' or 'phase', got {fixed!r}")
        n2 = 2 * self.system.n
        s = np.zeros(n2)
        slope = self.system.mean_slope(self.omega)  # dF_0/dΩ of a mean load by speed
        for i in range(self.n_segments):
            sol = self.segments[i].sol
            ta, tb = float(self.t_start[i]), float(self.t_end[i])
            s = sol.transition(tb - ta) @ (s - sol.omega_particular(ta)) + sol.omega_particular(tb)
            if np.any(slope):
                s = s + _constant_response(sol.A, slope, tb - ta)
        if fixed == "phase":
            s = s - self._vector_field(self.t1, self.state1) * (self.t1 / self.omega)
            s = s + self.sensitivity @ self._vector_field(self.t0, self.state0) * (self.t0 / self.omega)
        return s

    def _vector_field(self, t: float, z: FloatArray) -> FloatArray:
        """z' = (x', F(t) − C x' − K x − Σ b f(a·x)) at (t, z)."""
        n = self.system.n
        x, v = z[:n], z[n:]
        acc = self.system.forcing(t, self.omega) - self.system.damping @ v - self.system.restoring(x)
        return np.concatenate((v, acc))

    # --- exact measures ---------------------------------------------------------------------
    def measures(self) -> SystemMeasures:
        """Mean, rms, rms_ac, extremes and peak-to-peak of every element's δ and δ'' over
        [t0, t1].

        Integrals by 12-point Gauss–Legendre quadrature on panels of at most a quarter of the
        stage time scale (δ is analytic within a segment: the quadrature error is far below
        round-off); extremes at segment ends and where δ' (for δ) or δ''' (for δ'') vanish inside
        a segment (sign changes on a grid of 40 points per time scale, refined by Newton).
        """
        duration = self.t1 - self.t0
        if not duration > 0.0:
            raise ValueError("measures need a trajectory of positive duration (t1 > t0)")
        rows = self.system.element_rows
        m = rows.shape[0]
        wq_all, dq_all = [], []
        dmin = np.full(m, np.inf)
        dmax = np.full(m, -np.inf)
        amin = np.full(m, np.inf)
        amax = np.full(m, -np.inf)
        for i in range(self.n_segments):
            length = float(self.t_end[i] - self.t_start[i])
            if length < 0.0 or (length == 0.0 and self.n_segments > 1):
                continue
            scale = self.segments[i].sol.time_scale
            if not math.isfinite(scale):
                scale = max(duration, 1.0)
            # Quadrature.
            panels = max(1, math.ceil(length / (scale / _PANELS_PER_SCALE)))
            edges = np.linspace(0.0, length, panels + 1)
            half = 0.5 * np.diff(edges)
            tq = (0.5 * (edges[:-1] + edges[1:]))[:, None] + half[:, None] * _GAUSS_NODES[None, :]
            wq = (half[:, None] * _GAUSS_WEIGHTS[None, :]).reshape(-1)
            xq = self._segment_derivatives(i, tq.reshape(-1), 0)[0]
            wq_all.append(wq)
            dq_all.append(xq @ rows.T)
            # Extremes.
            cells = max(1, math.ceil(length / (scale / _EXTREMA_PER_SCALE)))
            tg = np.linspace(0.0, length, cells + 1)
            vals = [x @ rows.T for x in self._segment_derivatives(i, tg, 4)]
            for order, lo_, hi_ in ((0, dmin, dmax), (2, amin, amax)):
                lo_[:] = np.minimum(lo_, vals[order].min(axis=0))
                hi_[:] = np.maximum(hi_, vals[order].max(axis=0))
            brackets = []
            for order in (0, 2):
                dg = vals[order + 1]
                change = ((dg[:-1] > 0.0) & (dg[1:] <= 0.0)) | ((dg[:-1] < 0.0) & (dg[1:] >= 0.0))
                cell, elem = np.nonzero(change)
                if cell.size:
                    brackets.append((np.full(cell.size, order), cell, elem, dg[cell, elem], dg[cell + 1, elem]))
            if not brackets:
                continue
            which = np.concatenate([b[0] for b in brackets])
            cell = np.concatenate([b[1] for b in brackets])
            elem = np.concatenate([b[2] for b in brackets])
            fa = np.concatenate([b[3] for b in brackets])
            fb = np.concatenate([b[4] for b in brackets])
            a, b = tg[cell], tg[cell + 1]

            def fun(x: FloatArray, idx: IntArray, i: int = i, which: IntArray = which, elem: IntArray = elem) \
                    -> tuple[FloatArray, FloatArray]:
                r = self._segment_derivatives(i, x, 4)
                e = elem[idx]
                o = which[idx]
                f = np.where(o == 0, (r[1] * rows[e]).sum(axis=1), (r[3] * rows[e]).sum(axis=1))
                df = np.where(o == 0, (r[2] * rows[e]).sum(axis=1), (r[4] * rows[e]).sum(axis=1))
                return f, df

            tol = 1e-9 * (b - a) + 4.0 * _EPS * np.maximum(np.abs(a), np.abs(b))
            te = vector_bracketed_newton(fun, a, b, fa, fb, tol)
            r = self._segment_derivatives(i, te, 2)
            at = np.where(which == 0, (r[0] * rows[elem]).sum(axis=1), (r[2] * rows[elem]).sum(axis=1))
            for order, lo_, hi_ in ((0, dmin, dmax), (2, amin, amax)):
                sel = which == order
                np.minimum.at(lo_, elem[sel], at[sel])
                np.maximum.at(hi_, elem[sel], at[sel])
        wq = np.concatenate(wq_all)
        dq = np.concatenate(dq_all, axis=0)
        mean = (wq @ dq) / duration
        ms = (wq @ (dq * dq)) / duration
        ms_ac = (wq @ (dq - mean) ** 2) / duration
        return SystemMeasures(
            names=tuple(e.name for e in self.system.elements), mean=mean, rms=np.sqrt(ms), rms_ac=np.sqrt(ms_ac),
            delta_min=dmin, delta_max=dmax, p2p=dmax - dmin, acc_min=amin, acc_max=amax, acc_p2p=amax - amin,
        )


# ---------------------------------------------------------------------------------------------
# Integrator
# ---------------------------------------------------------------------------------------------
class _StageFlow(ExactIntegrator, takes=takes_continuous, kind="a rattle System with continuous laws"):
    """The stage-matrix path of :class:`~rattle.timeint.ExactIntegrator`: a
    :class:`~rattle.model.System` with continuous laws (module docstring); the grid of
    ``options.samples_per_scale`` points per fastest time scale of a stage combination brackets
    the crossings, ``options.max_events`` is the budget of segments of one ``propagate`` call
    (exceeded: ``ConvergenceError``)."""

    def __init__(self, system: System, options: FlowOptions | None = None) -> None:
        super().__init__(system, options)
        self.max_segments = self.options.budget(events=False)
        self._cache: tuple[float, SystemStages] | None = None
        self._modal: dict = {}  # stage combination -> its Ω-independent modal form (SystemStages)

    def stages(self, omega: float) -> SystemStages:
        """The stage solutions at forcing frequency ``omega`` (the last one is cached)."""
        if self._cache is not None and self._cache[0] == omega:
            return self._cache[1]
        flow = SystemStages(self.system, omega, self.samples_per_scale, modal_cache=self._modal)
        self._cache = (float(omega), flow)
        return flow

    def propagate(self, z0: FloatArray, t0: float, t1: float, omega: float) -> SystemTrajectory:
        """Integrate exactly from state ``z0`` = (x, x') (shape (2n,)) at ``t0`` to ``t1`` ≥ t0 at
        forcing frequency ``omega`` (rad/s): the :class:`SystemTrajectory` with its segments,
        crossings, final state and sensitivity ∂z(t1)/∂z(t0)."""
        z = check_system_state(z0, self.system.n)
        omega = check_omega(omega)
        t0, t1 = check_interval(t0, t1, omega)
        flow = self.stages(omega)
        rec: dict[str, list] = {k: [] for k in ("ts", "st", "zs", "seg", "ct", "ce", "cd", "cb")}
        z1, M = self._march(flow, z, t0, t1, rec)
        t_start = np.asarray(rec["ts"], dtype=float)
        return SystemTrajectory(
            system=self.system, omega=omega, t0=t0, t1=t1, state0=z, state1=z1, sensitivity=M,
            t_start=t_start, t_end=np.append(t_start[1:], t1),
            stages=np.asarray(rec["st"], dtype=np.int64).reshape(len(rec["st"]), self.system.m),
            z_start=np.asarray(rec["zs"], dtype=float).reshape(-1, 2 * self.system.n),
            crossing_times=np.asarray(rec["ct"], dtype=float), crossing_elements=np.asarray(rec["ce"], dtype=np.int64),
            crossing_directions=np.asarray(rec["cd"], dtype=np.int64),
            crossing_breakpoints=np.asarray(rec["cb"], dtype=float), segments=tuple(rec["seg"]),
        )

    def advance(self, z0: FloatArray, t0: float, t1: float, omega: float,
                sensitivity: bool = True) -> tuple[FloatArray, FloatArray | None]:
        """The state at ``t1`` and the sensitivity ∂z(t1)/∂z(t0) (None when ``sensitivity`` is
        False, which skips the transition matrices) only — no record kept, no checks: the hot
        path of a simulation or a shooting that only needs its Poincaré points."""
        return self._march(self.stages(omega), np.asarray(z0, dtype=float), float(t0), float(t1), None,
                           bool(sensitivity))

    def _march(self, flow: SystemStages, z: FloatArray, t0: float, t1: float,
               rec: dict[str, list] | None, sensitivity: bool = True) -> tuple[FloatArray, FloatArray | None]:
        n = flow.n
        rows = flow.rows
        stages = flow.stages_at(t0, z)
        t = t0
        M = np.eye(2 * n)
        n_seg = 0
        stuck = 0  # consecutive crossings without time passing
        while True:
            sol = flow.solution(stages)
            remaining = t1 - t
            tau_lim = min(remaining, sol.max_segment)
            seg = sol.segment(t, z, tau_lim)
            lo, hi = sol.lo, sol.hi
            tau_c, e, direction = first_exit(seg, lo, hi, tau_lim, sol.grid_step, flow.samples_per_scale)
            if rec is not None and (tau_c > 0.0 or (e < 0 and n_seg == 0 and not rec["ts"])):
                rec["ts"].append(t)
                rec["st"].append(stages)
                rec["zs"].append(z)
                rec["seg"].append(seg)
            stuck = 0 if tau_c > 0.0 else stuck + 1
            if stuck > 4 * flow.m + 8:
                raise ConvergenceError(
                    f"the trajectory switches element stages without advancing in time at t = {t!r} (stages "
                    f"{stages}): a state that sits on breakpoints with no direction of motion; perturb the "
                    "initial state `z0` slightly"
                )
            if tau_c > 0.0:
                n_seg += 1
                if sensitivity:
                    M = sol.transition(tau_c) @ M
            zc = seg.end_state(tau_c) if tau_c > 0.0 else z
            if e < 0:
                if tau_lim >= remaining:
                    return zc, (M if sensitivity else None)
                t, z = t + tau_c, zc  # a long segment cut: continue on the same stages
                continue
            bound = float(hi[e] if direction > 0 else lo[e])
            a = rows[e]
            zc = zc.copy()
            zc[:n] += a * ((bound - float(a @ zc[:n])) / float(a @ a))  # δ_e exactly on the breakpoint
            t = t + tau_c
            if rec is not None:
                rec["ct"].append(t)
                rec["ce"].append(e)
                rec["cd"].append(direction)
                rec["cb"].append(bound)
            stages = stages[:e] + (stages[e] + direction,) + stages[e + 1:]
            z = zc
            if n_seg > self.max_segments:
                raise ConvergenceError(
                    f"more than `max_segments` = {self.max_segments} segments between t0 = {t0!r} and "
                    f"t1 = {t1!r}: raise `max_segments` or shorten the interval"
                )



__all__ = ["SystemTrajectory", "SystemSamples", "SystemMeasures", "check_system_state"]
