"""The compiled scalar path of the exact flow (:class:`~rattle.timeint.ExactIntegrator`): the single
equation δ'' + c δ' + k f(δ) = F(t) (c = C/I, k = K/I) for continuous piecewise-linear laws.

On every stage j of the law, f(δ) = s_j δ + e_j, the equation is linear and its solution from a
state x_s = (δ_s, δ'_s) at t_s is x(t) = p(t) + Φ_j(τ) (x_s − p(t_s)), Φ_j(τ) = exp(A_j τ),
τ = t − t_s, in closed form (:mod:`._stage_solutions`), so nothing here is approximated: the only
numerical step is locating the times where δ(t) reaches a breakpoint, which is done to
round-off. The segment is evaluated in modal form (:class:`_Segment`), the one-coordinate,
one-element fast path.

The march runs compiled: it is the event march of :mod:`._event_kernel` (numba, imported at the
flow's first march), the law seen as a discontinuous one without jumps or friction — stage j is
the kernel's mode 3 j + 1 (friction sign σ = 0), no stop of δ' is searched, no lock can occur, and
the saltation at a breakpoint of a continuous field is the identity. It takes this module's steps
with the same floating-point operations (the same states, crossing times and sensitivities, bit
for bit on this machine's OpenBLAS). The Python march (:meth:`_ScalarFlow._march`, Python floats)
stays the reference and the fallback: without numba, or for a stage near critical damping, whose
segment has no modal form (:func:`~._event_kernel.supported`).

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

import numpy as np

from .._lazy import call_held, lazy_module
from .._limits import check_interval
from .._typing import FloatArray
from .._validate import check_state
from ..errors import ConvergenceError
from ..model import Model, transition_scalar
from ._exact_flow import ExactIntegrator, FlowOptions, takes_model
from ._recent import Recent
from ._roots import grid_chunk, resolve_cell
from ._stage_solutions import StageSolutions
from ._trajectory import Trajectory

_EPS = float(np.finfo(float).eps)
_FIRST_CHUNK = 48  # grid cells scanned at once for the first crossing; doubled up to _MAX_CHUNK
_MAX_CHUNK = 4096
_SLIP = 0  # the compiled march's kind of motion of a continuous law (no stick, no lock)
#: Frequencies whose stage solutions a scalar flow keeps (:meth:`_ScalarFlow.solutions`): a shooting
#: continuation evaluates the period map at Ω and at Ω + h.
SOLUTION_CACHE = 4
#: The compiled march's record when only its end is asked for (:meth:`_ScalarFlow.advance`): empty
#: arrays, nothing kept
_NO_RECORD = (np.empty(0), np.empty((0, 3), dtype=np.int64), np.empty((0, 4)), np.empty(0),
              np.empty(0, dtype=np.int64))

#: the compiled march, imported at the first march of a flow (a command that builds no flow does not
#: pay its import)
_event_kernel = lazy_module("rattle.timeint._event_kernel")
#: Whether this process has called the compiled march: its first call loads the cached code (or
#: compiles it), with the stopping signals held (:func:`~rattle._lazy.call_held`)
_KERNEL_LOADED = [False]


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
class _ScalarFlow(ExactIntegrator, takes=takes_model, kind="a rattle Model"):
    """The compiled scalar path of :class:`~rattle.timeint.ExactIntegrator`: δ'' + c δ' + k f(δ) = F(t)
    for a model with a continuous piecewise-linear law (see the module docstring); the grid of
    ``options.samples_per_scale`` points per fastest time scale of a stage brackets the crossings,
    ``options.max_events`` is the budget of segments of one ``propagate`` call (exceeded:
    ``ConvergenceError``).

    The march runs compiled (:meth:`_run_compiled`: the event march of :mod:`._event_kernel`, the
    law seen as a discontinuous one without jumps or friction) where numba is there and every stage's
    segment has the modal form; else in Python (:meth:`_march`, the reference)."""

    #: rows of the compiled march's mode table per row of :meth:`solutions`: its modes are
    #: m = 3 j + σ + 1 (stage j, friction sign σ); a continuous law has σ = 0 only, so stage j is
    #: row 3 j + 1 of its stages' rows repeated three times (the mode table of the same law as a
    #: discontinuous one, :func:`~._nonsmooth._mode_solutions`, with no friction)
    _MODE_ROWS = 3

    def __init__(self, system: Model, options: FlowOptions | None = None) -> None:
        super().__init__(system, options)
        self.model = self.system
        self.max_segments = self.options.budget(events=False)
        st = self.model.elastic.stages
        n = len(st.slopes)
        # breakpoints, slopes, offsets, jumps (none), friction levels (none): the compiled march's law
        self._law_arrays = (np.array(st.breakpoints, dtype=float), np.array(st.slopes, dtype=float),
                            np.array(st.offsets, dtype=float), np.zeros(n - 1), np.zeros(n))
        self._x_lock = 0.0  # no jumps: no locks
        self._init_scalar()

    def _init_scalar(self) -> None:
        """What both scalar paths keep: the stage solutions of the last :data:`SOLUTION_CACHE`
        frequencies, and the compiled march's state, decided at the first march
        (:meth:`_use_compiled`; the kernel module is imported there, not when the flow is built)."""
        self._solution_cache: Recent = Recent(SOLUTION_CACHE)  # Ω → StageSolutions
        self._template: StageSolutions | None = None
        self._compiled: bool | None = None
        self._stage_table: FloatArray | None = None
        self._kernel: tuple | None = None  # (march, FULL, BUDGET) of the kernel module
        self._capacity = 64  # segments and events of a record (grown when a march needs more)
        self._buffers: tuple | None = None  # the record's arrays, written by every march

    def solutions(self, omega: float) -> StageSolutions:
        """The closed-form stage solutions at forcing frequency ``omega`` (those of the last
        :data:`SOLUTION_CACHE` frequencies kept; a new one made from the first ones, only what
        depends on Ω afresh: :meth:`StageSolutions.at_omega`)."""
        sol = self._solution_cache.get(omega)
        if sol is not None:
            return sol
        if self._template is None:
            sol = self._template = self._stage_solutions(omega)
        else:
            sol = self._template.at_omega(omega)
        return self._solution_cache.put(float(omega), sol)

    def _stage_solutions(self, omega: float) -> StageSolutions:
        """The flow's first stage solutions (its law's stages)."""
        return StageSolutions(self.model, omega, self.samples_per_scale)

    def propagate(self, x0: FloatArray | tuple[float, float], t0: float, t1: float, omega: float) -> Trajectory:
        """Integrate exactly from state ``x0`` = (δ, δ') (rad, rad/s) at ``t0`` to ``t1`` ≥ t0 (s)
        at forcing frequency ``omega`` (rad/s).

        Returns the :class:`Trajectory`: its segments, final state and sensitivity ∂x(t1)/∂x0.
        """
        x0 = check_state(x0)
        t0, t1 = check_interval(t0, t1, omega)
        sol = self.solutions(omega)
        d0, v0 = float(x0[0]), float(x0[1])
        if self._use_compiled(sol):
            ns, _, d, v, m, rec_t, rec_i, rec_x, _, _ = self._run_compiled(
                sol, _SLIP, sol.stage_of(t0, d0, v0), 0, d0, v0, t0, t1)
            if ns > 1 and rec_t[ns - 1] >= t1:
                ns -= 1  # a crossing rounded onto t1: no segment of zero length at the end
            t_start, stage = rec_t[:ns].copy(), rec_i[:ns, 1].copy()
            x_start, homog = rec_x[:ns, :2].copy(), rec_x[:ns, 2:].copy()
        else:
            starts: list[float] = []
            stages: list[int] = []
            states: list[tuple[float, float]] = []
            homs: list[tuple[float, float]] = []
            d, v, m = self._march(sol, d0, v0, t0, t1, (starts, stages, states, homs))
            t_start, stage = np.asarray(starts), np.asarray(stages, dtype=np.int64)
            x_start = np.asarray(states, dtype=float).reshape(-1, 2)
            homog = np.asarray(homs, dtype=float).reshape(-1, 2)
        return Trajectory(
            omega=float(omega), t0=t0, t1=t1, state0=x0.copy(), state1=np.array([d, v]),
            sensitivity=np.array([[m[0], m[1]], [m[2], m[3]]]), t_start=t_start, t_end=np.append(t_start[1:], t1),
            stage=stage, x_start=x_start, solutions=sol, homogeneous=homog,
        )

    def advance(self, x0: FloatArray, t0: float, t1: float, omega: float,
                sensitivity: bool = True) -> tuple[FloatArray, FloatArray | None]:
        """The state (δ, δ') at ``t1`` and the sensitivity ∂x(t1)/∂x(t0) (None when
        ``sensitivity`` is False) only — no record kept, no checks: the period map of a shooting."""
        sol = self.solutions(omega)
        d0, v0, t0 = float(x0[0]), float(x0[1]), float(t0)
        if self._use_compiled(sol):
            _, _, d, v, m, *_ = self._run_compiled(sol, _SLIP, sol.stage_of(t0, d0, v0), 0, d0, v0, t0, float(t1),
                                                   keep=False)
        else:
            d, v, m = self._march(sol, d0, v0, t0, float(t1), None)
        return np.array([d, v]), (np.array([[m[0], m[1]], [m[2], m[3]]]) if sensitivity else None)

    # --- the compiled march ------------------------------------------------------------------
    def _use_compiled(self, sol: StageSolutions) -> bool:
        """Whether the march runs compiled: numba there and every mode's segment in modal form
        (decided once, on the Ω-independent rows of the stage table, ``sol._stage_l``)."""
        if self._compiled is None:
            if not _event_kernel.AVAILABLE:
                self._compiled = False
            else:
                table = np.array([[float(x) for x in row] for row in sol._stage_l], dtype=float)
                self._stage_table = np.repeat(table, self._MODE_ROWS, axis=0)
                self._compiled = bool(_event_kernel.supported(self._stage_table, float(sol.sigma)))
                self._kernel = (_event_kernel.march, _event_kernel.FULL, _event_kernel.BUDGET)
        return self._compiled

    def _budget_error(self, t0: float, t1: float) -> ConvergenceError:
        return ConvergenceError(
            f"more than `max_segments` = {self.max_segments} segments between t0 = {t0!r} and "
            f"t1 = {t1!r}: raise `max_segments` or shorten the interval"
        )

    def _run_compiled(self, sol: StageSolutions, kind: int, j: int, sigma: int, d: float, v: float, t0: float,
                      t1: float, keep: bool = True) -> tuple:
        """The compiled march (:func:`~._event_kernel.march`) from (δ, δ') = (d, v) at t0 in the
        state (``kind``: slip, stick or lock; stage or breakpoint ``j``; friction sign ``sigma``) to t1:
        (segments, events, δ, δ', (Φ11, Φ12, Φ21, Φ22), the record's arrays: segment starts,
        (kind, stage, σ), (δ, δ', h0, h1) of each segment, event times and codes). The record is
        grown and the march run again when it did not fit; the budget exceeded raises. The record's
        arrays are the flow's, written again by the next march: a caller that keeps them copies.
        Not ``keep``: no record (empty arrays), the end state and the sensitivity only."""
        kept = sol.__dict__.get("_kernel_args")  # an at_omega copy starts with its template's: Ω tells
        if kept is not None and kept[0] == sol.omega:
            args = kept[1]
        else:
            rows = self._MODE_ROWS
            args = (
                self._stage_table, float(sol.sigma), np.repeat(sol.xr, rows, axis=0), np.repeat(sol.xi, rows, axis=0),
                np.array(sol.nw, dtype=float), np.array(sol.fc, dtype=float), np.array(sol.fs, dtype=float),
                float(sol.mean), np.repeat(np.asarray(sol.grid_step, dtype=float), rows),
                float(self.samples_per_scale), *self._law_arrays, float(self.system.k), float(self.system.c),
                self._x_lock, self.max_segments)
            sol._kernel_args = (sol.omega, args)
        march, full, budget = self._kernel
        while True:
            record = self._buffers if keep else _NO_RECORD
            if record is None:
                cap = self._capacity
                record = self._buffers = (np.empty(cap), np.empty((cap, 3), dtype=np.int64), np.empty((cap, 4)),
                                         np.empty(cap), np.empty(cap, dtype=np.int64))
            if _KERNEL_LOADED[0]:
                status, ns, ne, d1, v1, m11, m12, m21, m22 = march(*args, kind, j, sigma, d, v, t0, t1, *record)
            else:  # numba loads the kernel: a stop is not to land half-way in its machinery
                status, ns, ne, d1, v1, m11, m12, m21, m22 = call_held(march, *args, kind, j, sigma, d, v, t0, t1,
                                                                       *record)
                _KERNEL_LOADED[0] = True
            if status != full:
                break
            self._capacity *= 4  # a longer record than any so far: again with room for it
            self._buffers = None
        if status == budget:
            raise self._budget_error(t0, t1)
        rec_t, rec_i, rec_x, ev_t, ev_k = record
        return ns, ne, d1, v1, (m11, m12, m21, m22), rec_t, rec_i, rec_x, ev_t, ev_k

    # --- the Python march (the reference) ----------------------------------------------------
    def _march(
        self, sol: StageSolutions, d: float, v: float, t0: float, t1: float,
        record: tuple[list, list, list, list] | None,
    ) -> tuple[float, float, tuple[float, float, float, float]]:
        """Segment by segment from (δ, δ') = (d, v) at t0 to t1: the final state and the
        sensitivity (Φ11, Φ12, Φ21, Φ22); the segments are appended to ``record`` (starts,
        stages, start states, homogeneous parts) when given."""
        j = sol.stage_of(t0, d, v)
        trans = sol._trans_l
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
            f11, f12, f21, f22 = transition_scalar(*trans[j], tau_c)
            m11, m12, m21, m22 = (f11 * m11 + f12 * m21, f11 * m12 + f12 * m22,
                                  f21 * m11 + f22 * m21, f21 * m12 + f22 * m22)
            if j_new < 0:
                return d_c, v_c, (m11, m12, m21, m22)
            # Exactly on the breakpoint: snap δ (the root is located to round-off).
            d = float(sol.upper[j] if j_new > j else sol.lower[j])
            v = v_c
            j, t = j_new, t + tau_c
            if n_seg > self.max_segments:
                raise self._budget_error(t0, t1)

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
                taus = grid_chunk(tau_a, tau_end, step, chunk)  # the cell starts, then the last end
                n = taus.size - 1
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
        (:func:`~._roots.resolve_cell` on the segment's modal form)."""
        hit = resolve_cell(seg.state, lo, hi, tau_a, tau_b, d_a, d_b, v_a, v_b, at_start, seg.d_floor, seg.v_floor)
        if hit is None:
            return None
        tau_c, direction = hit
        return tau_c, seg.j + direction, hi if direction > 0 else lo, seg.state(tau_c)[1]


__all__: list[str] = []
