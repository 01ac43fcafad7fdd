"""General time integration of δ'' + c δ' + k f(δ) = F(t) with scipy's ``solve_ivp``, restarted
at every breakpoint crossing.

The exact integrator (``_exact``) relies on f being linear between breakpoints. This one only
needs f to be smooth *within* each stage: it integrates stage j with the stage's own smooth
restoring force f_j (for the piecewise-linear laws f_j(δ) = s_j δ + e_j, extended beyond the stage),
stops where δ reaches the stage's lower or upper breakpoint (terminal, direction-aware
``solve_ivp`` events: downwards through the lower one, upwards through the upper one) and
restarts on the neighbouring stage from the located crossing state, with δ set exactly to the
breakpoint. A Runge–Kutta method never steps across the kink of f, so it keeps its order, and
``rtol``/``atol`` control the error as on a smooth problem. It is the independent check of the
exact integrator, and the way to integrate laws that are not piecewise linear.

Grazing: event location sees only sign changes between step ends, so an excursion beyond a
breakpoint that begins and ends within one step would be missed. Every such excursion holds an
extremum of δ beyond the breakpoint, and extrema (δ' = 0) are located as non-terminal events:
one beyond the stage's breakpoint reveals the missed crossing, which is then located on the
dense output of the step that holds the extremum, and the integration restarts there. (Two
extrema within one step would still hide an excursion: ``max_step`` bounds the steps.)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._brent import brent_root
from .._lazy import import_held
from .._typing import FloatArray, IntArray
from .._validate import check_omega, check_state
from ..errors import ConvergenceError
from ..model import Model
from ._exact import StateSamples


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class GeneralSolution:
    """A trajectory from :func:`integrate_general`: segments between breakpoint crossings, each
    with the dense output of ``solve_ivp``.

    Attributes
    ----------
    omega : float
        Forcing frequency Ω (rad/s).
    t0, t1 : float
        Interval (s).
    state0, state1 : ndarray, shape (2,)
        (δ, δ') at t0 and t1 (rad, rad/s).
    t_start, t_end : ndarray, shape (n,)
        Segment ends (s); segment i+1 starts where segment i reached a breakpoint.
    stage : ndarray of int, shape (n,)
        Stage of the law on each segment.
    segments : tuple of scipy OdeSolution
        Dense output of each segment.
    nfev : int
        Right-hand-side evaluations, all segments.
    method : str
        The ``solve_ivp`` method.
    """

    model: Model
    omega: float
    t0: float
    t1: float
    state0: FloatArray
    state1: FloatArray
    t_start: FloatArray
    t_end: FloatArray
    stage: IntArray
    segments: tuple
    nfev: int
    method: str

    @property
    def n_segments(self) -> int:
        return int(self.t_start.size)

    @property
    def crossing_times(self) -> FloatArray:
        """Times where δ crossed a breakpoint, shape (n − 1,)."""
        return self.t_start[1:]

    @property
    def crossed_breakpoints(self) -> FloatArray:
        """The breakpoint crossed at each of ``crossing_times`` (rad)."""
        bp = self.model.elastic.stages.breakpoints
        up = self.stage[1:] > self.stage[:-1]
        # up from stage j crosses breakpoint j; down into stage j crosses breakpoint j as well
        last = max(bp.size - 1, 0)
        return np.where(up, bp[np.clip(self.stage[:-1], 0, last)], bp[np.clip(self.stage[1:], 0, last)])

    def segment_index(self, t: FloatArray | float) -> IntArray:
        """Index of the segment holding each time (the later one at a crossing)."""
        idx = np.searchsorted(self.t_start, t, side="right") - 1
        return np.clip(idx, 0, self.n_segments - 1)

    def __call__(self, t: FloatArray | float) -> FloatArray:
        """States (δ, δ') at times ``t`` (any shape, within [t0, t1]): shape (2,) + t.shape."""
        t = np.asarray(t, dtype=float)
        flat = t.ravel()
        out = np.empty((2, flat.size))
        seg = self.segment_index(flat)
        for i in np.unique(seg):
            m = seg == i
            out[:, m] = self.segments[int(i)](flat[m])
        return out.reshape((2,) + t.shape)

    def sample(self, t: FloatArray | float) -> StateSamples:
        """δ, δ' (dense output) and δ'' (from the equation) at times ``t`` (s)."""
        t = np.asarray(t, dtype=float)
        d, v = self(t)
        stage = self.stage[self.segment_index(t)]
        st = self.model.elastic.stages
        k = self.model.k
        acc = self.model.excitation(t, self.omega) - self.model.c * v - k * (st.slopes[stage] * d + st.offsets[stage])
        return StateSamples(t=t, delta=d, velocity=v, acceleration=acc, stage=stage)


def _stage_force(model: Model, j: int) -> Callable[[float], float]:
    """k f_j(δ): the restoring force of stage j, smooth and extended beyond the stage."""
    st = model.elastic.stages
    ks, ke = model.k * float(st.slopes[j]), model.k * float(st.offsets[j])
    return lambda d: ks * d + ke


def _start_stage(model: Model, t: float, omega: float, d: float, v: float) -> int:
    """Stage holding (δ, δ') at t; exactly on a breakpoint the direction of motion decides."""
    bp = model.elastic.stages.breakpoints
    j = int(np.searchsorted(bp, d, side="right"))
    if j > 0 and d == bp[j - 1]:
        st = model.elastic.stages
        acc = float(model.excitation(t, omega)) - model.c * v - model.k * (st.slopes[j] * d + st.offsets[j])
        if (v if v != 0.0 else acc) < 0.0:
            j -= 1
    return j


def integrate_general(
    model: Model,
    x0: FloatArray | tuple[float, float],
    t0: float,
    t1: float,
    omega: float,
    *,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    method: str = "DOP853",
    max_step: float = math.inf,
    max_segments: int = 1_000_000,
) -> tuple[FloatArray, GeneralSolution]:
    """Integrate δ'' + c δ' + k f(δ) = F(t) from ``x0`` at ``t0`` to ``t1`` with ``solve_ivp``,
    restarting at every breakpoint crossing (module docstring).

    Parameters
    ----------
    model : Model
        The model.
    x0 : array_like, shape (2,)
        (δ, δ') at t0 (rad, rad/s).
    t0, t1 : float
        Interval (s), t1 ≥ t0.
    omega : float
        Forcing frequency Ω (rad/s), > 0.
    rtol, atol : float
        ``solve_ivp`` tolerances (defaults 1e-10, 1e-12: an independent reference).
    method : str
        A ``solve_ivp`` method (default ``"DOP853"``).
    max_step : float
        Largest step (s), default unbounded.
    max_segments : int
        Budget of segments (crossings + 1); exceeding it raises ConvergenceError.

    Returns
    -------
    state1 : ndarray, shape (2,)
        (δ, δ') at t1.
    solution : GeneralSolution
        Segments with dense output.
    """
    if not isinstance(model, Model):
        raise TypeError(f"`model` must be a rattle Model, got {model!r}")
    omega = check_omega(omega)
    x = check_state(x0)
    t0, t1 = float(t0), float(t1)
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 >= t0):
        raise ValueError(f"`t0` and `t1` must be finite with t1 >= t0, got t0={t0!r}, t1={t1!r}")
    methods = import_held("scipy.integrate._ivp.ivp").METHODS  # scipy.integrate: loaded when first used
    if method not in methods:
        raise ValueError(f"`method` must be one of {', '.join(methods)}, got {method!r}")
    for name, value in (("rtol", rtol), ("atol", atol), ("max_step", max_step)):
        if not (isinstance(value, (int, float)) and value > 0.0):
            raise ValueError(f"`{name}` must be a number > 0, got {value!r}")

    bp = np.asarray(model.elastic.stages.breakpoints, dtype=float)
    lower = np.concatenate(([-np.inf], bp))
    upper = np.concatenate((bp, [np.inf]))
    c, exc = model.c, model.excitation
    nw = exc.orders.astype(float) * omega
    amps = np.asarray(exc.amplitudes, dtype=float)
    phases = np.asarray(exc.phases, dtype=float)
    mean = float(exc.mean)

    def forcing(t: float) -> float:
        return mean + float(np.dot(amps, np.cos(nw * t + phases)))

    t, d, v = t0, float(x[0]), float(x[1])
    j = _start_stage(model, t, omega, d, v)
    starts: list[float] = []
    ends: list[float] = []
    stages: list[int] = []
    segments: list = []
    nfev = 0
    while True:
        force = _stage_force(model, j)

        def rhs(tt: float, y: FloatArray, force: Callable[[float], float] = force) -> list[float]:
            return [y[1], forcing(tt) - c * y[1] - force(y[0])]

        events = []
        kinds = []
        if math.isfinite(upper[j]):
            hi = float(upper[j])

            def up(tt: float, y: FloatArray, hi: float = hi) -> float:
                return y[0] - hi

            up.terminal, up.direction = True, 1.0  # type: ignore[attr-defined]
            events.append(up)
            kinds.append(+1)
        if math.isfinite(lower[j]):
            lo = float(lower[j])

            def down(tt: float, y: FloatArray, lo: float = lo) -> float:
                return y[0] - lo

            down.terminal, down.direction = True, -1.0  # type: ignore[attr-defined]
            events.append(down)
            kinds.append(-1)
        # Extrema of δ (δ' = 0), not terminal: an excursion beyond a breakpoint that begins and
        # ends within one step is invisible to the crossing events, but it holds an extremum
        # beyond the breakpoint.
        def extremum(tt: float, y: FloatArray) -> float:
            return y[1]

        events.append(extremum)
        if t1 > t:
            sol = import_held("scipy.integrate").solve_ivp(rhs, (t, t1), [d, v], method=method, rtol=rtol, atol=atol, max_step=max_step,
                            events=events, dense_output=True)
            if sol.status < 0:
                raise ConvergenceError(f"solve_ivp failed at t = {t!r}: {sol.message}")
            nfev += int(sol.nfev)
            dense = sol.sol
        else:
            sol, dense = None, None
        hit = None
        if sol is not None:
            if sol.status == 1:
                for kind, te, ye in zip(kinds, sol.t_events, sol.y_events):
                    if len(te):
                        hit = (kind, float(te[0]), ye[0])
                        break
            t_stop = hit[1] if hit is not None else t1
            for tx, yx in zip(sol.t_events[-1], sol.y_events[-1]):
                if tx >= t_stop:
                    break
                beyond = +1 if yx[0] > upper[j] else (-1 if yx[0] < lower[j] else 0)
                if beyond:
                    hit = _missed_crossing(sol, float(tx), beyond, float(upper[j] if beyond > 0 else lower[j]), t)
                    break
        t_end = hit[1] if hit is not None else t1
        starts.append(t)
        ends.append(t_end)
        stages.append(j)
        segments.append(dense if dense is not None else _Constant(d, v))
        if hit is None:
            state1 = np.array(sol.y[:, -1] if sol is not None else [d, v], dtype=float)
            break
        kind, t, y = hit
        d = float(upper[j] if kind > 0 else lower[j])  # exactly on the breakpoint
        v = float(y[1])
        j += kind
        if len(starts) >= max_segments:
            raise ConvergenceError(
                f"more than `max_segments` = {max_segments} segments between t0 = {t0!r} and t1 = {t1!r}"
            )
    return state1, GeneralSolution(
        model=model, omega=omega, t0=t0, t1=t1, state0=x.copy(), state1=state1,
        t_start=np.asarray(starts), t_end=np.asarray(ends), stage=np.asarray(stages, dtype=np.int64),
        segments=tuple(segments), nfev=nfev, method=method,
    )


def _missed_crossing(sol: object, tx: float, kind: int, bound: float, t_seg: float) -> tuple[int, float, FloatArray]:
    """The crossing of ``bound`` before the extremum at ``tx`` that lies beyond it, located on
    the dense output within the step that holds the extremum (δ is inside at the step start)."""
    steps = np.asarray(sol.t)  # type: ignore[attr-defined]
    k = max(int(np.searchsorted(steps, tx, side="right")) - 1, 0)
    ta = max(float(steps[k]), t_seg)
    dense = sol.sol  # type: ignore[attr-defined]
    gap = lambda tt: float(dense(tt)[0]) - bound  # noqa: E731
    if gap(ta) * gap(tx) > 0.0:  # round-off at the step start: take it as the crossing
        tc = ta
    else:
        tc = brent_root(gap, ta, tx, xtol=4.0 * np.finfo(float).eps * max(abs(tx), 1.0), rtol=4.0 * np.finfo(float).eps)
    return kind, float(tc), dense(tc)


class _Constant:
    """Dense output of a zero-length interval."""

    def __init__(self, d: float, v: float) -> None:
        self.y = np.array([d, v])

    def __call__(self, t: FloatArray) -> FloatArray:
        t = np.asarray(t)
        return np.repeat(self.y[:, None], t.size, axis=1).reshape((2,) + t.shape)


__all__ = ["integrate_general", "GeneralSolution"]
