"""Trajectories of the single equation from the exact integrator: segments, exact samples and
the SPEC §1 measures (integrals by Gauss–Legendre quadrature, extremes refined by Newton)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._typing import FloatArray, IntArray
from ._roots import vector_bracketed_newton
from ._stage_solutions import StageSolutions

_EPS = float(np.finfo(float).eps)
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(12)
_PANELS_PER_SCALE = 4  # Gauss-Legendre panels per stage time scale (measures)


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
class ExactTrajectory:
    """What every exact integrator returns: the motion from ``t0`` to ``t1`` at forcing frequency
    ``omega``, ``state0``/``state1`` z = (x, x') at t0/t1 ((δ, δ') for the single equation),
    ``sensitivity`` ∂z(t1)/∂z(t0) (the product of the stage transition matrices exp(A τ) and of
    the saltation matrices of the switchings: the identity across a breakpoint of a continuous
    law), and its segments: segment i runs from ``t_start[i]`` to ``t_end[i]`` on one stage (or
    mode) of the law, analytic inside. The law-specific records (stages, events, stick and lock
    flags, the exact segment solutions) are the extras of :class:`Trajectory`,
    :class:`~rattle.timeint.SystemTrajectory`, :class:`~rattle.timeint.NonsmoothTrajectory` and
    :class:`~rattle.timeint.FrictionTrajectory`, which all answer :meth:`states` and :meth:`measures`."""

    omega: float
    t0: float
    t1: float
    state0: FloatArray
    state1: FloatArray
    sensitivity: FloatArray
    t_start: FloatArray
    t_end: FloatArray

    @property
    def n_segments(self) -> int:
        return int(self.t_start.size)

    def segment_index(self, t: FloatArray | float) -> IntArray:
        """Index of the segment holding each time (the later one at a switching)."""
        idx = np.searchsorted(self.t_start, t, side="right") - 1
        return np.clip(idx, 0, self.n_segments - 1)

    def check_times(self, t: FloatArray) -> None:
        """Refuse (ValueError) times outside [t0, t1] (beyond round-off)."""
        span = max(abs(self.t0), abs(self.t1), self.t1 - self.t0)
        if t.size and (np.min(t) < self.t0 - 4 * _EPS * span or np.max(t) > self.t1 + 4 * _EPS * span):
            raise ValueError(
                f"`t` must lie within the trajectory's interval [{self.t0!r}, {self.t1!r}], got values "
                f"in [{float(np.min(t))!r}, {float(np.max(t))!r}]"
            )

    def states(self, t: FloatArray | float) -> FloatArray:
        """The states z(t) = (x, x'), shape t.shape + (2n,) (each kind of trajectory evaluates
        its own exact segments)."""
        raise NotImplementedError

    def measures(self) -> object:
        """The response measures over [t0, t1] (SPEC §1), exact to round-off: an
        :class:`ExactMeasures` of δ for the single equations, a
        :class:`~rattle.timeint.SystemMeasures` of every element for a chain."""
        raise NotImplementedError


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class Trajectory(ExactTrajectory):
    """An exact trajectory of δ'' + c δ' + k f(δ) = F(t) from ``t0`` to ``t1``.

    It is a sequence of segments, each on one stage of the law: segment i runs from
    ``t_start[i]`` to ``t_end[i]`` on stage ``stage[i]`` from state ``x_start[i]`` = (δ, δ').
    A new segment starts exactly where δ reaches a breakpoint and leaves the stage.
    ``state0``/``state1`` are the states at t0/t1 (shape (2,)), ``sensitivity`` the 2×2 matrix
    ∂x(t1)/∂x(t0) = Π_i exp(A_{stage[i]} (t_end[i] − t_start[i])) (the saltation matrices of the
    crossings are the identity because f is continuous).
    """

    stage: IntArray
    x_start: FloatArray
    solutions: StageSolutions = field(repr=False, compare=False)
    homogeneous: FloatArray = field(repr=False, compare=False)  # (n, 2): x_start − p(t_start)

    @property
    def crossing_times(self) -> FloatArray:
        """Times where δ crossed a breakpoint (the segment starts after the first), shape (n−1,)."""
        return self.t_start[1:]

    @property
    def crossed_breakpoints(self) -> FloatArray:
        """The breakpoint crossed at each of ``crossing_times`` (rad), shape (n−1,)."""
        return self.x_start[1:, 0]

    def derivatives(self, t: FloatArray | float, order: int = 2, segment: IntArray | None = None) -> list[FloatArray]:
        """[δ, δ', …, δ^(order)] at times ``t`` (any shape, within [t0, t1]); ``order`` ≤ 4.

        ``segment`` forces the segment of every time (to evaluate a segment's one-sided limits
        at its ends, where δ''' and δ'''' jump).
        """
        t = np.asarray(t, dtype=float)
        self.check_times(t)
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

    def states(self, t: FloatArray | float) -> FloatArray:
        """(δ, δ') at times ``t``, shape t.shape + (2,)."""
        d, v = self.derivatives(t, 1)
        return np.stack((d, v), axis=-1)

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
            te = vector_bracketed_newton(fun, a, b, fa, fb, tol)
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


__all__ = ["StateSamples", "ExactMeasures", "Trajectory"]
