"""Event-driven exact integration of one coordinate with a discontinuous law (preload, friction).

The equation (c = C/I, k = K/I, g relative to K; :mod:`rattle.model._discontinuous`)

    δ'' + c δ' + k [f(δ) + r(δ) sgn δ'] = F(t) = F_m + Σ_n F_pn cos(n Ω t + φ_n),

f(δ) = s_j δ + e_j on stage j (jumps J_i ≥ 0 at the breakpoints d_i allowed), r(δ) = r_j ≥ 0.
State x = (δ, δ'), vector field φ(t, x) = (δ', a), a = F − c δ' − k (f + r σ), σ = sgn δ'.

Modes, each linear with constant coefficients, hence solved in closed form by the stage
solutions of :mod:`._stage_solutions` (the law's stage j with the constant offset e_j + σ r_j):

- *slip* on stage j with σ ∈ {−1, +1} (σ = 0 when r_j = 0): δ'' + c δ' + k s_j δ = F − k (e_j + σ r_j);
- *stick* at δ_s inside stage j (r_j > 0): δ ≡ δ_s, δ' ≡ 0, the Filippov solution while the
  force friction must hold stays in its band, |F(t) − k f(δ_s)| ≤ k r_j;
- *lock* at a breakpoint d_i: δ ≡ d_i, δ' ≡ 0 while k (f(d_i⁻) − r_i) ≤ F(t) ≤ k (f(d_i⁺) + r_{i+1})
  (Filippov: 0 lies in the convex hull of the four one-sided fields at (d_i, 0)).

Events (located to round-off by Newton's method safeguarded by bisection, on a bracketing grid;
the δ-crossings by the crossing search of :class:`~rattle.timeint.ExactIntegrator`):

- δ reaches a breakpoint in slip: the next stage; a jump (or a change of friction level) makes the
  field discontinuous, the crossing is transversal (the surface δ = d_i has normal n = (1, 0),
  nᵀφ = δ' the same on both sides) and its saltation matrix is
  S = I + (φ⁺ − φ⁻) nᵀ / (nᵀ φ⁻) = [[1, 0], [(a⁺ − a⁻)/δ', 1]]; where neither (a breakpoint of a
  continuous law) the field is continuous and S = I exactly, not the round-off of f(d_i⁺) − f(d_i⁻);
- δ' reaches 0 in slip with friction: with R = F − k f(δ) (the force friction must balance),
  stick if |R| ≤ k r_j, with saltation [[1, 0], [0, 0]] (entry into the sliding surface δ' = 0,
  whose own flow is [[1, 0], [0, 0]]: δ-perturbations stay, δ'-perturbations are removed); else
  reversal σ → sgn R, transversal through δ' = 0 (n = (0, 1)), S = [[1, 0], [0, a⁺/a⁻]];
- stick ends when R(t) leaves ±k r_j (a time-dependent surface): the slip field there equals the
  stick field (a⁺ = 0 at the band's edge), so S = I; the slip starts with σ = sgn R;
- lock: a jump J_i > 0 with F inside the lock band is approached by a chattering spiral around
  (d_i, 0) (in the relay limit δ'' ≈ −(kJ/2) sgn(δ − d_i) + …, the velocity at the n-th crossing
  drops by O(c δ'²/a) only, with friction by a fixed fraction: Zeno). The integrator follows every
  crossing exactly and snaps into the lock when the next excursion beyond the jump, δ'²/(2|a⁺|)
  (a⁺ the deceleration on the side entered), is below ``lock_excursion`` · L — by default a few
  hundred ulps of the length scale L, where the excursions drown in round-off anyway (the neglected
  motion stays within that excursion and |δ'| ≤ sqrt(2 |a⁺| lock_excursion L)); in the lock all perturbations die
  (the sensitivity is 0, a super-stable phase) and it ends like a stick (S = I).

Between events the sensitivity is the stage transition matrix exp(A τ), A = [[0, 1], [−k s_j, −c]],
so ∂x(t1)/∂x(t0) = Π (exp(A τ) and S) is exact, and so are the Floquet multipliers of
:func:`~rattle.timeint.shoot_nonsmooth_orbit`. Grazing (a tangential touch of a switching surface) is not
resolved: the map is not differentiable there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import pairwise
from types import SimpleNamespace

import numpy as np

from .._limits import check_interval
from .._typing import FloatArray, IntArray
from .._validate import check_omega, check_state
from ..errors import ConvergenceError
from ..model import Stages, System
from ._exact_flow import ExactIntegrator, FlowOptions, takes_single_equation
from ._integrator import _event_kernel, _ScalarFlow, _Segment
from ._trajectory import ExactMeasures, ExactTrajectory
from ._recent import Recent
from ._roots import bracketed_newton, grid_chunk, polish_crossing
from ._stage_solutions import StageSolutions


_EPS = float(np.finfo(float).eps)
_CHUNK = 64
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(16)

SLIP, STICK, LOCK = 0, 1, 2
_KIND_NAMES = ("slip", "stick", "lock")


def _chunk(start: float, end: float, step: float) -> FloatArray:
    """The next at most ``_CHUNK`` cells of the event grid (:func:`~._roots.grid_chunk`)."""
    return grid_chunk(start, end, step, _CHUNK)


def _mode_solutions(system: System, omega: float, samples_per_scale: int) -> StageSolutions:
    """Stage solutions of every mode m = 3 j + σ + 1 (stage j, σ ∈ {−1, 0, 1}): slope s_j and
    offset e_j + σ r_j; the mode's δ-range is its stage's (``lower``/``upper``)."""
    st = system.law.stages
    r = system.law.friction_levels
    n = len(st.slopes)
    slopes = np.repeat(st.slopes, 3)
    offsets = (st.offsets[:, None] + np.array([-1.0, 0.0, 1.0])[None, :] * r[:, None]).ravel()
    table = SimpleNamespace(
        elastic=SimpleNamespace(stages=Stages(np.arange(3 * n - 1, dtype=float), slopes, offsets)),
        excitation=system.excitation, c=system.c, k=system.k)
    sol = StageSolutions(table, omega, samples_per_scale)  # type: ignore[arg-type]
    edges = np.concatenate(([-np.inf], st.breakpoints, [np.inf]))
    sol.lower = np.repeat(edges[:-1], 3)
    sol.upper = np.repeat(edges[1:], 3)
    return sol


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class NonsmoothTrajectory(ExactTrajectory):
    """An exact trajectory from ``t0`` to ``t1``: segments i from ``t_start[i]`` to ``t_end[i]``
    of ``kind[i]`` (0 slip, 1 stick, 2 lock) on ``stage[i]`` with friction sign ``sign[i]``
    (slip only), start state ``x_start[i]`` and homogeneous part ``homogeneous[i]`` (slip);
    ``state0``/``state1`` (2,), ``sensitivity`` ∂x(t1)/∂x(t0) (2×2, with the saltation matrices);
    the switching events ``event_time`` with ``event_kind`` (``crossing``, ``reversal``,
    ``stick``, ``unstick``, ``lock``, ``unlock``)."""

    system: System
    kind: IntArray
    stage: IntArray
    sign: IntArray
    x_start: FloatArray
    homogeneous: FloatArray
    event_time: FloatArray
    event_kind: tuple[str, ...]
    solutions: StageSolutions = field(repr=False)

    def states(self, t: FloatArray | float) -> FloatArray:
        """(δ, δ') at times ``t``, shape t.shape + (2,)."""
        d, v, _ = self.sample(np.asarray(t, dtype=float))
        return np.stack((d, v), axis=-1)

    def measures(self) -> ExactMeasures:
        """The measures of δ (SPEC §1) over the trajectory: mean and rms by its own quadrature
        (:meth:`mean_and_rms`, Gauss–Legendre inside the segments), rms about the
        mean likewise, the extremes of δ and δ'' by :meth:`extremes` (δ'' jumps at a switching: both
        one-sided values count, a stick or lock contributes δ'' = 0)."""
        T = self.t1 - self.t0
        if not T > 0.0:
            raise ValueError("measures need a trajectory of positive duration (t1 > t0)")
        mean, rms = self.mean_and_rms()
        ms_ac = self.integrate(lambda t, d, v, a: (d - mean) ** 2) / T
        dmin, dmax, amin, amax = self.extremes()
        return ExactMeasures(mean=mean, rms=rms, rms_ac=math.sqrt(max(ms_ac, 0.0)), delta_min=dmin, delta_max=dmax,
                             p2p=dmax - dmin, acc_min=amin, acc_max=amax, acc_p2p=amax - amin)

    def sample(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """δ, δ' and δ'' at times ``t`` in [t0, t1] (arrays of t's shape); δ'' on a stick or lock
        is 0, at a switching time the value of the segment starting there."""
        t = np.asarray(t, dtype=float)
        flat = t.ravel()
        idx = self.segment_index(flat)
        d, v, a = np.empty_like(flat), np.zeros_like(flat), np.zeros_like(flat)
        sol = self.solutions
        for i in np.unique(idx):
            sel = idx == i
            if self.kind[i] == SLIP:
                m = 3 * int(self.stage[i]) + int(self.sign[i]) + 1
                h0, h1 = self.homogeneous[i]
                dd, vv, aa = sol.evaluate(m, flat[sel], float(self.t_start[i]), h0, h1, order=2)
                d[sel], v[sel], a[sel] = dd, vv, aa
            else:
                d[sel] = self.x_start[i, 0]
        return d.reshape(t.shape), v.reshape(t.shape), a.reshape(t.shape)

    def _panels(self, panels_per_scale: int):  # type: ignore[no-untyped-def]
        """Every segment's Gauss–Legendre panels: (i, ta, tb, mode m of a slip or None, tq, half)
        with the nodes tq (panels, 16) and the half widths; a slip's mode has ``panels_per_scale``
        panels per its time scale, a stick or lock (δ, δ', δ'' constant) as many per forcing period."""
        sol = self.solutions
        fast = float(sol.nw.max(initial=0.0))
        for i in range(len(self.t_start)):
            ta, tb = float(self.t_start[i]), float(self.t_end[i])
            if tb <= ta:
                continue
            n = max(1, math.ceil((tb - ta) * panels_per_scale * fast / (2.0 * math.pi)))
            m = None
            if self.kind[i] == SLIP:
                m = 3 * int(self.stage[i]) + int(self.sign[i]) + 1
                scale = float(sol.time_scale[m])
                n = 1 if not math.isfinite(scale) else max(1, math.ceil((tb - ta) * panels_per_scale / scale))
            edges = np.linspace(ta, tb, n + 1)
            half = 0.5 * np.diff(edges)
            tq = (0.5 * (edges[:-1] + edges[1:]))[:, None] + half[:, None] * _GAUSS_X[None, :]
            yield i, ta, tb, m, tq, half

    def integrate(self, fun, panels_per_scale: int = 4) -> float:  # type: ignore[no-untyped-def]
        """∫_{t0}^{t1} fun(t, δ, δ', δ'') dt by Gauss–Legendre panels inside every segment (the
        integrand is smooth there; ``panels_per_scale`` panels per time scale of the mode)."""
        total = 0.0
        for _i, ta, tb, _m, tq, half in self._panels(panels_per_scale):
            d, v, a = self.sample(np.clip(tq, ta, tb))
            total += float(np.sum(half[:, None] * _GAUSS_W[None, :] * fun(tq, d, v, a)))
        return total

    def fourier(self, harmonics: int) -> FloatArray:
        """The real Fourier series of δ over [t0, t1] as one period, ω = 2π/(t1 − t0):
        q = [a_0, a_1 … a_H, b_1 … b_H] with δ(t) = a_0 + Σ a_k cos kωt + b_k sin kωt — the
        harmonic balance's unknowns, e.g. to start it on this orbit. The integrals are taken by
        Gauss–Legendre panels inside the segments, at least 2 panels per period of harmonic H, so
        the coefficients are exact to round-off (no aliasing of the kinks of δ')."""
        if isinstance(harmonics, bool) or not isinstance(harmonics, (int, np.integer)) or harmonics < 0:
            raise ValueError(f"`harmonics` must be an integer >= 0, got {harmonics!r}")
        T = self.t1 - self.t0
        w = 2.0 * math.pi / T
        k = np.arange(1, harmonics + 1)
        acc = np.zeros(2 * harmonics + 1)
        sol = self.solutions
        for i in range(len(self.t_start)):
            ta, tb = float(self.t_start[i]), float(self.t_end[i])
            if tb <= ta:
                continue
            n = math.ceil((tb - ta) * max(2 * harmonics, 4) / T)
            if self.kind[i] == SLIP:
                scale = float(sol.time_scale[3 * int(self.stage[i]) + int(self.sign[i]) + 1])
                if math.isfinite(scale):
                    n = max(n, math.ceil((tb - ta) * 4 / scale))
            edges = np.linspace(ta, tb, max(n, 1) + 1)
            half = 0.5 * np.diff(edges)
            tq = ((0.5 * (edges[:-1] + edges[1:]))[:, None] + half[:, None] * _GAUSS_X[None, :]).ravel()
            wq = (half[:, None] * _GAUSS_W[None, :]).ravel()
            d = self.sample(np.clip(tq, ta, tb))[0] * wq
            th = np.outer(k * w, tq)
            acc[0] += d.sum()
            acc[1 : harmonics + 1] += np.cos(th) @ d
            acc[harmonics + 1 :] += np.sin(th) @ d
        acc[0] /= T
        acc[1:] *= 2.0 / T
        return acc

    def friction_dissipation(self) -> float:
        """k ∫ r(δ) |δ'| dt over [t0, t1] (exact: on a slip segment sgn δ' is constant, so
        ∫ |δ'| dt = |δ(end) − δ(start)|)."""
        r = self.system.law.friction_levels
        ends = np.append(self.x_start[1:, 0], self.state1[0])
        slip = self.kind == SLIP
        return float(self.system.k * np.sum(r[self.stage[slip]] * np.abs(ends[slip] - self.x_start[slip, 0])))

    def energy(self, state: FloatArray) -> float:
        """E = δ'²/2 + k V(δ), V = ∫_0^δ f (per unit inertia)."""
        return float(0.5 * state[1] ** 2 + self.system.k * float(self.system.law.potential(np.array([state[0]]))[0]))

    @property
    def stick_time(self) -> float:
        """Total time spent sticking or locked."""
        held = self.kind != SLIP
        return float(np.sum(self.t_end[held] - self.t_start[held]))

    def mean_and_rms(self) -> tuple[float, float]:
        """(1/T)∫δ dt and sqrt((1/T)∫δ² dt) over [t0, t1]."""
        T = self.t1 - self.t0
        s1, s2 = self._moments()
        return s1 / T, math.sqrt(max(s2 / T, 0.0))

    def _moments(self, panels_per_scale: int = 4) -> tuple[float, float]:
        """∫δ dt and ∫δ² dt over [t0, t1] in one pass: :meth:`integrate`'s panels and sums, each
        segment's δ sampled once for both."""
        s1 = s2 = 0.0
        sol = self.solutions
        for i, ta, tb, m, tq, half in self._panels(panels_per_scale):
            w = half[:, None] * _GAUSS_W[None, :]
            if m is not None:
                h0, h1 = self.homogeneous[i]
                d = sol.evaluate(m, np.clip(tq, ta, tb).ravel(), ta, h0, h1, order=0)[0].reshape(tq.shape)
            else:
                d = np.full(tq.shape, self.x_start[i, 0])
            s1 += float(np.sum(w * d))
            s2 += float(np.sum(w * (d * d)))
        return s1, s2

    def extremes(self, samples_per_scale: int = 16) -> tuple[float, float, float, float]:
        """(δ_min, δ_max, δ''_min, δ''_max) over [t0, t1]. δ'' jumps at the switchings: both
        one-sided values count. Inside a slip segment the extrema are the roots of δ' and of the
        jerk F' − c δ'' − k s_j δ', bracketed on a grid and refined by Newton's method."""
        sol = self.solutions
        c = sol.c
        d_lo, d_hi, a_lo, a_hi = math.inf, -math.inf, math.inf, -math.inf
        for i in range(len(self.t_start)):
            ta, tb = float(self.t_start[i]), float(self.t_end[i])
            if self.kind[i] != SLIP:
                d0 = float(self.x_start[i, 0])
                d_lo, d_hi, a_lo, a_hi = min(d_lo, d0), max(d_hi, d0), min(a_lo, 0.0), max(a_hi, 0.0)
                continue
            m = 3 * int(self.stage[i]) + int(self.sign[i]) + 1
            h0, h1 = (float(x) for x in self.homogeneous[i])
            scale = float(sol.time_scale[m])
            n = 2 if not math.isfinite(scale) else max(2, math.ceil((tb - ta) * samples_per_scale / scale) + 1)
            t = np.linspace(ta, tb, n)
            d, v, a, jk = sol.evaluate(m, t, ta, h0, h1, order=3)
            ks = float(sol.ks[m])

            def at(x: float, m: int = m, ta: float = ta, h0: float = h0, h1: float = h1,
                   ks: float = ks) -> tuple[float, float, float, float]:
                dd, vv, aa = sol.point(m, x, ta, h0, h1)
                return dd, vv, aa, sol.force(x, 1) - c * aa - ks * vv

            def vel(x: float) -> tuple[float, float]:
                y = at(x)
                return y[1], y[2]

            def jerk(x: float, ks: float = ks) -> tuple[float, float]:
                y = at(x)
                return y[3], sol.force(x, 2) - c * y[3] - ks * y[2]

            vals_d, vals_a = [float(d[0]), float(d[-1])], [float(a[0]), float(a[-1])]
            tol = 4.0 * _EPS * max(abs(tb), 1.0)
            for q in np.flatnonzero((v[:-1] > 0.0) != (v[1:] > 0.0)).tolist():
                tq = bracketed_newton(vel, float(t[q]), float(t[q + 1]), float(v[q]), float(v[q + 1]), tol)
                vals_d.append(at(tq)[0])
            for q in np.flatnonzero((jk[:-1] > 0.0) != (jk[1:] > 0.0)).tolist():
                tq = bracketed_newton(jerk, float(t[q]), float(t[q + 1]), float(jk[q]), float(jk[q + 1]), tol)
                vals_a.append(at(tq)[2])
            d_lo, d_hi = min(d_lo, *vals_d), max(d_hi, *vals_d)
            a_lo, a_hi = min(a_lo, *vals_a), max(a_hi, *vals_a)
        return d_lo, d_hi, a_lo, a_hi

    def event_structure(self) -> tuple[int, ...]:
        """The switching pattern: the stick or lock phases, then the breakpoint crossings, over the
        trajectory (2 counts, as :meth:`FrictionTrajectory.event_structure` for one element)."""
        kinds = self.event_kind
        return (sum(k in ("stick", "lock") for k in kinds), sum(k == "crossing" for k in kinds))

    @property
    def crossed_breakpoints(self) -> FloatArray:
        """The breakpoints the trajectory crossed or locked on (sorted, unique)."""
        bp = self.system.law.stages.breakpoints
        st, kd = self.stage.tolist(), self.kind.tolist()
        hit = [float(bp[min(a, b)]) for a, b in pairwise(st) if a != b]
        hit += [float(bp[j]) for j, k in zip(st, kd) if k == LOCK]
        return np.unique(np.asarray(hit, dtype=float))


#: The last trajectories :meth:`_ScalarEventFlow.propagate` keeps, by their exact arguments (x0, t0,
#: t1, Ω): a shooting continuation asks again for the period it has just integrated (the row of an
#: accepted point after the corrector's last evaluation there, its event structure).
MEMO = 4


class _ScalarEventFlow(_ScalarFlow, takes=takes_single_equation, kind="the single equation's System (System.single)"):
    """The scalar path of :class:`~rattle.timeint.ExactIntegrator` with events: δ'' + c δ' +
    k [f(δ) + r(δ) sgn δ'] = F(t) (module docstring) for a
    the single equation's :class:`~rattle.model.System`; the δ-crossings by the scalar path's own search
    (``_first_exit`` on the mode table)."""

    _MODE_ROWS = 1  # :meth:`solutions` is the mode table already

    def __init__(self, system: System, options: FlowOptions | None = None) -> None:
        ExactIntegrator.__init__(self, system, options)
        self.model = None  # the modes' table stands for the model (:meth:`solutions`)
        self.max_segments = self.options.budget(events=True)
        self._memo: Recent = Recent(MEMO)  # (x0, t0, t1, Ω) → NonsmoothTrajectory
        st = system.law.stages
        self._d = st.breakpoints.tolist()
        self._s = st.slopes.tolist()
        self._e = st.offsets.tolist()
        self._J = st.jumps.tolist()
        self._r = system.law.friction_levels.tolist()
        self._L = float(system.length_scale())
        self._law_arrays = tuple(np.asarray(x, dtype=float) for x in (self._d, self._s, self._e, self._J, self._r))
        self._x_lock = self.options.lock_excursion * self._L
        self._init_scalar()  # the solutions kept, the compiled march where every mode has the modal form

    def _stage_solutions(self, omega: float) -> StageSolutions:
        """The closed-form solutions of every mode (:func:`_mode_solutions`): the first of
        :meth:`solutions`, the others made from it."""
        return _mode_solutions(self.system, omega, self.samples_per_scale)

    def velocity_scale(self, omega: float) -> float:
        """L ν: the length scale times the larger of Ω and the stiffest stage's natural frequency."""
        sys = self.system
        return self._L * max(omega, math.sqrt(sys.k * max(self._s)))

    # --- helpers -----------------------------------------------------------------------------
    def _f(self, j: int, d: float) -> float:
        return self._s[j] * d + self._e[j]

    def _band(self, i: int) -> tuple[float, float]:
        """The lock band [L, U] of F at breakpoint i."""
        k, d = self.system.k, self._d[i]
        return k * (self._f(i, d) - self._r[i]), k * (self._f(i + 1, d) + self._r[i + 1])

    def _stage_of(self, d: float) -> int:
        return int(np.searchsorted(self._d, d, side="right"))

    def _classify(self, sol: StageSolutions, t: float, d: float, v: float) -> tuple[int, int, int]:
        """(kind, stage or breakpoint, σ) of the state (δ, δ') at t."""
        F = sol.force(t)
        k = self.system.k
        if v == 0.0:
            if d in self._d:
                i = self._d.index(d)
                lo, hi = self._band(i)
                if lo <= F <= hi:
                    return LOCK, i, 0
                j = i + 1 if F > hi else i
                return SLIP, j, (0 if self._r[j] == 0.0 else (1 if F > hi else -1))
            j = self._stage_of(d)
            R = F - k * self._f(j, d)
            if self._r[j] > 0.0:
                if abs(R) <= k * self._r[j]:
                    return STICK, j, 0
                return SLIP, j, (1 if R > 0 else -1)
            return SLIP, j, 0
        j = self._stage_of(d)
        if j > 0 and d == self._d[j - 1] and v < 0.0:
            j -= 1
        return SLIP, j, (0 if self._r[j] == 0.0 else (1 if v > 0 else -1))

    # --- public ------------------------------------------------------------------------------
    def propagate(self, x0: FloatArray | tuple[float, float], t0: float, t1: float, omega: float) -> NonsmoothTrajectory:
        """Integrate exactly from ``x0`` = (δ, δ') at ``t0`` to ``t1`` ≥ t0 at forcing frequency
        ``omega``: the :class:`NonsmoothTrajectory` with its sensitivity ∂x(t1)/∂x(t0)."""
        x0 = check_state(x0)
        omega = check_omega(omega)
        t0, t1 = check_interval(t0, t1, omega)
        key = (float(x0[0]), float(x0[1]), t0, t1, omega)
        memo = self._memo.get(key)
        if memo is not None:
            return memo
        sol = self.solutions(omega)
        if self._use_compiled(sol):
            d, v, M, rec = self._march_compiled(sol, float(x0[0]), float(x0[1]), t0, t1)
        else:
            rec = {k: [] for k in ("t", "kind", "stage", "sign", "x", "h", "et", "ek")}
            d, v, M = self._march_events(sol, float(x0[0]), float(x0[1]), t0, t1, omega, rec)
        t_start = np.asarray(rec["t"], dtype=float)
        traj = NonsmoothTrajectory(
            system=self.system, omega=omega, t0=t0, t1=t1, state0=x0.copy(), state1=np.array([d, v]),
            sensitivity=np.array([[M[0], M[1]], [M[2], M[3]]]), t_start=t_start, t_end=np.append(t_start[1:], t1),
            kind=np.asarray(rec["kind"], dtype=np.int64), stage=np.asarray(rec["stage"], dtype=np.int64),
            sign=np.asarray(rec["sign"], dtype=np.int64), x_start=np.asarray(rec["x"], dtype=float).reshape(-1, 2),
            homogeneous=np.asarray(rec["h"], dtype=float).reshape(-1, 2),
            event_time=np.asarray(rec["et"], dtype=float), event_kind=tuple(rec["ek"]), solutions=sol)
        return self._memo.put(key, traj)

    def advance(self, x0: FloatArray, t0: float, t1: float, omega: float,
                sensitivity: bool = True) -> tuple[FloatArray, FloatArray | None]:
        """The state (δ, δ') at ``t1`` and ∂x(t1)/∂x(t0) (None when ``sensitivity`` is False): the
        period map of a shooting."""
        traj = self.propagate(x0, t0, t1, omega)
        return traj.state1.copy(), (traj.sensitivity.copy() if sensitivity else None)

    # --- the march ---------------------------------------------------------------------------
    def _budget_error(self, t0: float, t1: float) -> ConvergenceError:
        return ConvergenceError(
            f"more than `max_events` = {self.max_segments} switching events between t0 = {t0!r} "
            f"and t1 = {t1!r} (a chattering approach to a lock?): raise `max_events` or `lock_excursion`, "
            "or shorten the interval")

    def _march_compiled(self, sol: StageSolutions, d: float, v: float, t0: float,
                        t1: float) -> tuple[float, float, tuple[float, float, float, float], dict]:
        """:meth:`_march_events` by the compiled march (:mod:`._event_kernel`, the same steps):
        the final state, the sensitivity and the record (arrays, as the Python march's lists)."""
        kind, j, sigma = self._classify(sol, t0, d, v)
        ns, ne, d1, v1, m, rec_t, rec_i, rec_x, ev_t, ev_k = self._run_compiled(sol, kind, j, sigma, d, v, t0, t1)
        names = _event_kernel.EVENT_NAMES
        rec_i = rec_i[:ns].copy()  # the flow's record arrays are written again by the next march
        rec = {"t": rec_t[:ns].copy(), "kind": rec_i[:, 0], "stage": rec_i[:, 1], "sign": rec_i[:, 2],
               "x": rec_x[:ns, :2].copy(), "h": rec_x[:ns, 2:].copy(), "et": ev_t[:ne].copy(),
               "ek": [names[e] for e in ev_k[:ne].tolist()]}
        return d1, v1, m, rec

    def _march_events(self, sol: StageSolutions, d: float, v: float, t0: float, t1: float, omega: float,
               rec: dict[str, list]) -> tuple[float, float, tuple[float, float, float, float]]:
        k, c = self.system.k, self.system.c
        kind, j, sigma = self._classify(sol, t0, d, v)
        if kind != SLIP:
            v = 0.0
        t = t0
        m11, m12, m21, m22 = 1.0, 0.0, 0.0, 1.0
        if kind == STICK or (kind == LOCK and self._J[j] == 0.0):
            m22 = 0.0  # a small initial δ' dies within O(δ') time: the stick's projection
        elif kind == LOCK:
            m11 = m22 = 0.0  # near a locking jump every perturbation spirals into the lock
        x_lock = self.options.lock_excursion * self._L
        n_events = 0
        while True:
            if kind == SLIP:
                mode = 3 * j + sigma + 1
                seg = _Segment(sol, mode, t, d, v)
                self._record(rec, t, SLIP, j, sigma, d, v, (seg.h0, seg.h1))
                tau_end = t1 - t
                tau_v = self._first_stop(sol, seg, sigma, tau_end) if sigma != 0 else None
                tau_c, j_new, _, v_c = self._first_exit(seg, tau_end if tau_v is None else tau_v)
                tau = tau_c if j_new >= 0 else (tau_end if tau_v is None else tau_v)
                m_before = (m11, m12, m21, m22)
                f11, f12, f21, f22 = sol.transition_scalar(mode, tau)
                m11, m12, m21, m22 = (f11 * m11 + f12 * m21, f11 * m12 + f12 * m22,
                                      f21 * m11 + f22 * m21, f21 * m12 + f22 * m22)
                if j_new < 0 and tau_v is None:
                    d_e, v_e, _ = seg.state(tau)
                    return d_e, v_e, (m11, m12, m21, m22)
                t = t + tau
                F = sol.force(t)
                if j_new >= 0:  # δ reaches breakpoint i
                    up = j_new > mode
                    i = j if up else j - 1
                    jn = j + 1 if up else j - 1
                    d = self._d[i]
                    if self._J[i] > 0.0 or self._r[i] != self._r[i + 1]:
                        # The field jumps here: an error dτ of the crossing time becomes an error
                        # (a⁺ − a⁻) dτ of δ'. The search stops at |δ − d_i| ≤ its round-off floor;
                        # polish τ by Newton steps on δ(τ) − d_i to the last bit.
                        tau_p = polish_crossing(seg.state, d, tau_c, tau_end if tau_v is None else tau_v)
                        if tau_p is not None:
                            t = t - tau + tau_p
                            tau = tau_p
                            _, v_c, _ = seg.state(tau)
                            F = sol.force(t)
                            m11, m12, m21, m22 = m_before
                            f11, f12, f21, f22 = sol.transition_scalar(mode, tau)
                            m11, m12, m21, m22 = (f11 * m11 + f12 * m21, f11 * m12 + f12 * m22,
                                                  f21 * m11 + f22 * m21, f21 * m12 + f22 * m22)
                    v = v_c
                    sn = 0 if self._r[jn] == 0.0 else (1 if up else -1)
                    lo, hi = self._band(i)
                    a_in = F - c * v - k * (self._f(jn, d) + self._r[jn] * sn)  # on the side entered
                    if (lo < F < hi and a_in * v < 0.0 and v * v <= 2.0 * abs(a_in) * x_lock
                            and (self._J[i] > 0.0 or self._r[i] + self._r[jn] > 0.0)):
                        kind, j, v = LOCK, i, 0.0
                        m11, m12, m21, m22 = (0.0, 0.0, 0.0, 0.0) if self._J[i] > 0.0 else (m11, m12, 0.0, 0.0)
                        self._event(rec, t, "lock")
                    else:
                        if self._J[i] > 0.0 or self._r[i] != self._r[i + 1]:  # the field jumps: saltation
                            a_m = F - c * v - k * (self._f(j, d) + self._r[j] * sigma)
                            a_p = F - c * v - k * (self._f(jn, d) + self._r[jn] * sn)
                            q = (a_p - a_m) / v if v != 0.0 else 0.0
                            m21, m22 = m21 + q * m11, m22 + q * m12
                        j, sigma = jn, sn
                        self._event(rec, t, "crossing")
                else:  # δ' = 0 inside stage j with friction
                    d, _, _ = seg.state(tau)
                    v = 0.0
                    R = F - k * self._f(j, d)
                    if abs(R) <= k * self._r[j]:
                        kind = STICK
                        m21, m22 = 0.0, 0.0
                        self._event(rec, t, "stick")
                    else:
                        sn = 1 if R > 0.0 else -1
                        a_m, a_p = R - k * self._r[j] * sigma, R - k * self._r[j] * sn
                        if a_m != 0.0:
                            m21, m22 = m21 * (a_p / a_m), m22 * (a_p / a_m)
                        sigma = sn
                        self._event(rec, t, "reversal")
            else:
                self._record(rec, t, kind, j, 0, d, 0.0, (0.0, 0.0))
                if kind == STICK:
                    fd = k * self._f(j, d)
                    lo, hi = fd - k * self._r[j], fd + k * self._r[j]
                else:
                    lo, hi = self._band(j)
                t_exit, up = self._band_exit(sol, t, t1, lo, hi)
                if t_exit is None:
                    return d, 0.0, (m11, m12, m21, m22)
                t = t_exit
                if kind == STICK:
                    sigma = 1 if up else -1
                    self._event(rec, t, "unstick")
                else:
                    j = j + 1 if up else j
                    sigma = 0 if self._r[j] == 0.0 else (1 if up else -1)
                    self._event(rec, t, "unlock")
                kind, v = SLIP, 0.0
            n_events += 1
            if n_events > self.max_segments:
                raise self._budget_error(t0, t1)

    @staticmethod
    def _record(rec: dict[str, list], t: float, kind: int, j: int, sigma: int, d: float, v: float,
                h: tuple[float, float]) -> None:
        if rec["t"] and rec["t"][-1] == t:  # a zero-length segment (two events at one time)
            for key in ("t", "kind", "stage", "sign", "x", "h"):
                rec[key].pop()
        rec["t"].append(t)
        rec["kind"].append(kind)
        rec["stage"].append(j)
        rec["sign"].append(sigma)
        rec["x"].append((d, v))
        rec["h"].append(h)

    @staticmethod
    def _event(rec: dict[str, list], t: float, name: str) -> None:
        rec["et"].append(t)
        rec["ek"].append(name)

    # --- event searches ----------------------------------------------------------------------
    def _first_stop(self, sol: StageSolutions, seg: _Segment, sigma: int, tau_end: float) -> float | None:
        """First local time in (0, tau_end] where σ δ' reaches 0 (None: it does not)."""
        m = seg.j
        step = float(sol.grid_step[m])
        if not math.isfinite(step):
            step = max(tau_end, 1e-300) / self.samples_per_scale
        c, ks, ke = sol.c, float(sol.ks[m]), float(sol.ke[m])

        def vel(tau: float) -> tuple[float, float]:
            _, vv, aa = seg.state(tau)
            return vv, aa

        tol_t = 4.0 * _EPS * max(tau_end, step) + 1e-300
        tau_a = 0.0
        first = True
        while tau_a < tau_end:
            taus = _chunk(tau_a, tau_end, step)
            d, v = seg.scan(taus)
            sv = sigma * v
            if first and sv[1] <= 0.0 and abs(v[0]) <= seg.v_floor:
                # starting from rest and stopping again within the first cell: find a point moving
                fine = np.linspace(0.0, taus[1], 65)[1:]
                _, vf = seg.scan(fine)
                moving = np.flatnonzero(sigma * vf > seg.v_floor)
                if moving.size == 0:
                    return float(fine[0])  # below resolution: stops at once
                i0 = int(moving[0])
                back = np.flatnonzero(sigma * vf[i0:] <= 0.0)
                if back.size:
                    ib = i0 + int(back[0])
                    return bracketed_newton(vel, float(fine[ib - 1]), float(fine[ib]), float(vf[ib - 1]),
                                            float(vf[ib]), tol_t, seg.v_floor)
            start = 1
            hits = np.flatnonzero(sv[start:] <= 0.0)
            i_hit = start + int(hits[0]) if hits.size else None
            # a tangential return of σδ' towards 0 inside a cell: σδ'' from − to + (a minimum); only
            # the cells before the hit's can hold one that comes first
            top = taus.size if i_hit is None else i_hit
            acc = sol.forcing(seg.ts + taus[:top]) - c * v[:top] - ks * d[:top] - ke
            sa = sigma * acc
            mins = np.flatnonzero((sa[:-1] < 0.0) & (sa[1:] >= 0.0) & (sv[:top - 1] > 0.0) & (sv[1:top] > 0.0))
            for i in mins.tolist():

                def accel(tau: float) -> tuple[float, float]:
                    _, vv, aa = seg.state(tau)
                    jerk = sol.force(seg.ts + tau, 1) - c * aa - ks * vv
                    return aa, jerk

                tau_m = bracketed_newton(accel, float(taus[i]), float(taus[i + 1]), float(acc[i]), float(acc[i + 1]),
                                         tol_t)
                v_m = seg.state(tau_m)[1]
                if sigma * v_m <= 0.0:
                    return bracketed_newton(vel, float(taus[i]), tau_m, float(v[i]), v_m, tol_t, seg.v_floor)
            if i_hit is not None:
                a_, b_ = float(taus[i_hit - 1]), float(taus[i_hit])
                va = float(v[i_hit - 1])
                if sigma * va <= 0.0:  # the segment start (v = 0 to round-off)
                    va = sigma * 1e-300
                return bracketed_newton(vel, a_, b_, va, float(v[i_hit]), tol_t, seg.v_floor)
            tau_a = float(taus[-1])
            first = False
        return None

    def _band_exit(self, sol: StageSolutions, t0: float, t1: float, lo: float, hi: float) -> tuple[float | None, bool]:
        """First time in (t0, t1] where F(t) leaves [lo, hi]: (time, True if above); (None, _)
        when it stays. Extrema of F inside a grid cell are refined (a brief excursion is found)."""
        if sol.nw.size == 0:
            F = sol.mean
            return (None, False) if lo <= F <= hi else (t0, F > hi)
        step = 2.0 * math.pi / float(np.max(sol.nw)) / self.samples_per_scale
        tol = 4.0 * _EPS * max(abs(t1), 1.0)

        def g_up(t: float) -> tuple[float, float]:
            return sol.force(t) - hi, sol.force(t, 1)

        def g_dn(t: float) -> tuple[float, float]:
            return lo - sol.force(t), -sol.force(t, 1)

        def dF(t: float) -> tuple[float, float]:
            return sol.force(t, 1), sol.force(t, 2)

        ta = t0
        while ta < t1:
            ts = _chunk(ta, t1, step)
            n = ts.size - 1
            F = sol.forcing(ts)
            F1 = sol.forcing(ts, 1)
            for i in range(n):
                cand: list[tuple[float, float, bool]] = []  # (bracket start, end, up)
                a_, b_ = float(ts[i]), float(ts[i + 1])
                if F[i + 1] > hi:
                    cand.append((a_, b_, True))
                elif F[i + 1] < lo:
                    cand.append((a_, b_, False))
                elif (F1[i] > 0.0) != (F1[i + 1] > 0.0) and F1[i] != 0.0:
                    te = bracketed_newton(dF, a_, b_, float(F1[i]), float(F1[i + 1]), tol)
                    Fe = sol.force(te)
                    if Fe > hi:
                        cand.append((a_, te, True))
                    elif Fe < lo:
                        cand.append((a_, te, False))
                if cand:
                    a_, b_, up = cand[0]
                    g = g_up if up else g_dn
                    ga, gb = g(a_)[0], g(b_)[0]
                    if ga >= 0.0:  # inside the band by construction at the bracket's start
                        ga = -1e-300
                    te = bracketed_newton(g, a_, b_, ga, gb, tol)
                    # The slip must start with F on or beyond the band's edge (else round-off makes
                    # it stop and stick again at once): step up to the first such float.
                    for _ in range(64):
                        ge, dge = g(te)
                        if ge >= 0.0 or te >= b_:
                            break
                        te = min(b_, max(float(np.nextafter(te, math.inf)), te - 2.0 * ge / dge if dge > 0 else te))
                    return te, up
            ta = float(ts[-1])
        return None, False


__all__ = ["NonsmoothTrajectory"]
