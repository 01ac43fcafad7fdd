"""Event-driven exact integration of a chain with Coulomb friction and torque jumps on its elements (Filippov).

The equations (a :class:`~rattle.model.System` with its elements' whole laws; x ∈ ℝⁿ, m elements, δ_e = a_e·x)

    x'' + C x' + K x + Σ_e b_e [f_e(δ_e) + r_e(δ_e) sgn(δ_e')] = F(t),

f_e piecewise linear (slope k_ej, offset o_ej on stage j: the law's own offsets, so upward jumps
J_ei = f_e(d_i⁺) − f_e(d_i⁻) ≥ 0 at its breakpoints are allowed, a preload), r_e(δ) = r_ej ≥ 0 on
stage j.

**Modes.** Every element with friction either *slips* with a sign σ_e = sgn δ_e' ∈ {−1, +1} or
*sticks* (e ∈ S): δ_e' ≡ 0, its friction torque λ_e whatever holds it, |λ_e| ≤ r_ej (the
Filippov solution: 0 in the convex hull of the one-sided fields). With A_S (rows a_e) and B_S
(columns b_e) of the stuck elements and

    y = F(t) − C x' − K_s x − Σ_e b_e o_ej − Σ_{e slips} b_e σ_e r_ej     (K_s the stage stiffness),

the stuck torques are λ = (A_S B_S)⁻¹ A_S y (from A_S x'' = 0) and the motion is

    x'' = P_S y,   P_S = I − B_S (A_S B_S)⁻¹ A_S,

linear with constant coefficients on every stage combination: the system with C, K, b_e and F
premultiplied by P_S and the slip friction folded into the offsets (o_ej + σ_e r_ej). Each mode is
therefore solved in closed form by the exact stage solutions of :mod:`._stage_flow` (block-modal
matrix exponentials, harmonic particular solutions), unchanged. (A_S B_S is invertible: for a
chain, a_e·M⁻¹a_e K_e > 0, and a set of stuck elements is independent unless they close a loop.)

**Events**, located to round-off (a grid of ``samples_per_scale`` points per fastest time scale
brackets them, Brent's method refines them):

- δ_e reaches a breakpoint (slipping e): the next stage (the crossing search of
  :func:`~._events.first_exit`); the friction level may change there;
- δ_e' reaches 0 (slipping e with friction somewhere on its law; a minimum of σ_e δ_e' inside a
  grid cell is refined too, so that a touch is not missed): the new mode is chosen by the
  active-set rule below with e a candidate to stick;
- λ_e reaches ±r_ej (stuck e): e slips with σ_e = sgn λ_e; a locked e's λ_e leaves its band.

*Active set.* Candidates C (the stuck elements and the one whose velocity vanished): compute λ on C;
while some |λ_e| > r_ej, release the worst one with σ_e = sgn λ_e (then e accelerates the way
sgn λ_e says: e_e'' = (a_e·b_e)(λ_e − σ_e r_ej)) and recompute. Elements at zero velocity at the
start are candidates too.

**Locks at a jump.** An element may be held at a breakpoint d_i where its law jumps (J_ei > 0):
δ_e ≡ d_i, δ_e' ≡ 0, a constraint exactly like a stick (it joins the held set S, its torque is the
same λ_e), with the asymmetric band λ_e ∈ [−r_ei, J_ei + r_e,i+1] (λ relative to the stage-i value
f_e(d_i⁻): the element sits on stage i). It ends when λ_e leaves the band: above, e slips up
(stage i + 1, σ = +1), below, down (stage i, σ = −1); the fields agree there (S = I). It is reached
by a chatter across the jump (Zeno with friction, an exponential decay without): at a crossing of
the jump with speed v, when the acceleration on the side entered points back and the next
excursion v²/(2|δ_e''⁺|) is at most ``lock_excursion`` · L, and the active set keeps e held, the
element locks. The chatter's relay torque acts along b_e and the held elements' reactions, so its
limit removes v along w_e = B_S (A_S B_S)⁻¹ ê_e (a_e·w_e = 1, a_k·w_e = 0 for the other held k):
x' ← x' − w_e (a_e·x'), momentum-conserving. Its saltation, the crossing's with the locked field
as φ⁺ composed with that removal (the 1/v terms lie along w_e and cancel), is
S = blockdiag(Π, Π), Π = I − w_e a_eᵀ (0 for one coordinate: the single equation's lock). An
element at rest on a jump at the start (within round-off, or within the neighbourhood the chatter
snaps from) is a lock candidate. A start in a lock removes a displacement ε = a_e·δx by the
chatter back into it, which moves x along w_e within O(√ε) while the damping acts on that motion:
δx → Π δx, δx' → P_S (δx' + C w_e ε) (P_S = I − B_S (A_S B_S)⁻¹ A_S), to first order in ε.

**Saltation.** Across a switching surface h(z) = 0 (normal n = ∇h) from the field φ⁻ to φ⁺,

    S = I + (φ⁺ − φ⁻) nᵀ / (nᵀ φ⁻),

with h = a_e·x − d (breakpoint; nᵀφ⁻ = δ_e'), h = a_e·x' (velocity zero; nᵀφ⁻ = δ_e''⁻). On entry
into a stick φ⁺ is the sliding field, nᵀφ⁺ = 0, and nᵀ S = 0: the δ_e'-perturbation is removed.
At a release φ⁺ = φ⁻ (λ_e = ±r_ej makes the two fields equal), S = I. A crossing of a jump has
φ⁺ ≠ φ⁻ (the stages on each side) and S ≠ I. Between events the sensitivity is the mode's
exp(A τ). So ∂z(t1)/∂z(t0) = Π (exp(A τ), S) is exact, and so are the Floquet multipliers of
:func:`~rattle.timeint.shoot_friction_orbit`. Not resolved: a tangential touch of a switching surface (grazing: the
map is not differentiable there) and stuck sets closing a loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from .._brent import brent_root
from .._lazy import lazy_module
from .._limits import MAX_PERIOD, check_interval
from .._typing import FloatArray
from .._validate import check_omega
from ..errors import ConvergenceError
from ..model import ReducedElement, System
from ._events import first_exit
from ._roots import grid_chunk, polish_crossing
from ._exact_flow import ExactIntegrator, FlowOptions, takes_discontinuous
from ._trajectory import ExactTrajectory
from ._flow import SystemMeasures, check_system_state
from ._nonsmooth import MEMO
from ._recent import Recent
from ._stage_flow import Segment, StageSolution, SystemStages

optimize = lazy_module("scipy.optimize")  # minimize_scalar, for the extremes of a segment

_EPS = float(np.finfo(float).eps)
_CHUNK = 64
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(16)
_EXTREMA_PER_SCALE = 40  # grid points per time scale bracketing the extrema of a segment (measures)

#: Event kinds of a :class:`FrictionTrajectory` (``lock``/``unlock``: an element held at a jump of
#: its law, ``event_values`` the breakpoint).
CROSSING, STICK, REVERSAL, RELEASE, LOCK, UNLOCK = 0, 1, 2, 3, 4, 5
EVENT_NAMES = ("crossing", "stick", "reversal", "release", "lock", "unlock")

_Key = tuple[tuple[bool, ...], tuple[int, ...]]  # (stuck per element, σ per element: 0 stuck / frictionless)


def _brent(fun, a: float, b: float, fa: float, fb: float) -> float:  # type: ignore[no-untyped-def]
    """The root of ``fun`` in [a, b] (fa, fb of opposite signs or one zero) to round-off."""
    fa, fb = fun(a), fun(b)  # the scalar evaluation: grid samples may differ from it in round-off
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0):  # a sign change within round-off: the end nearer zero
        return a if abs(fa) < abs(fb) else b
    return brent_root(fun, a, b, xtol=4.0 * _EPS * max(abs(b), 1e-300), rtol=4.0 * _EPS, maxiter=200, fa=fa, fb=fb)


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FrictionTrajectory(ExactTrajectory):
    """The exact motion from ``t0`` to ``t1``: ``state0``, ``state1`` (2n,) and the sensitivity
    ∂z(t1)/∂z(t0) (stage transitions and saltation matrices); per segment its start time
    ``t_start`` (and ``t_end``), the element ``stages`` (k, m), the ``stuck`` flags (k, m: held
    by friction or locked at a jump), the ``locked`` flags (k, m: held at a jump of its law, on the
    stage below it) and the exact :class:`~._stage_flow.Segment`; the events (``event_times``,
    ``event_elements``, ``event_kinds`` indexing :data:`EVENT_NAMES`, ``event_values``: the
    breakpoint crossed, locked on or left)."""

    system: System
    stages: np.ndarray
    stuck: np.ndarray
    segments: tuple[Segment, ...]
    event_times: FloatArray
    event_elements: np.ndarray
    event_kinds: np.ndarray
    event_values: FloatArray
    locked: np.ndarray | None = None

    def states(self, t: FloatArray | float) -> FloatArray:
        """z = (x, x') at times ``t``, shape t.shape + (2n,)."""
        return self.sample(t)[0]

    def measures(self) -> SystemMeasures:
        """The measures of every element's deflection δ_e = a_e·x over the
        trajectory: mean and rms by its own quadrature
        (:meth:`element_mean_and_rms`), rms about the mean likewise; the extremes on every segment
        (the motion is analytic there) from a grid of 40 points per time scale that includes both
        segment ends — so δ_e'' counts its one-sided values at every switching — refined where δ_e'
        changes sign (δ extremes, by Brent's method on the segment's exact solution) and at the grid
        extrema of δ_e'' and in the first and last cell of every segment (bounded Brent
        minimisation)."""
        T = self.t1 - self.t0
        if not T > 0.0:
            raise ValueError("measures need a trajectory of positive duration (t1 > t0)")
        fsys = self.system
        A = fsys.element_rows
        n, m = fsys.n, A.shape[0]
        mean, rms = self.element_mean_and_rms()
        ms_ac = self.integrate(lambda z: (z[:, :n] @ A.T - mean) ** 2) / T
        dmin, dmax = np.full(m, np.inf), np.full(m, -np.inf)
        amin, amax = np.full(m, np.inf), np.full(m, -np.inf)
        k_seg = len(self.segments)
        for i, seg in enumerate(self.segments):
            length = float(self.t_end[i] - self.t_start[i])
            if length < 0.0 or (length == 0.0 and k_seg > 1):
                continue
            scale = float(seg.sol.time_scale)
            if not math.isfinite(scale) or scale <= 0.0:
                scale = max(T, 1.0)
            cells = max(2, math.ceil(length / (scale / _EXTREMA_PER_SCALE)))
            tg = np.linspace(0.0, length, cells + 1)
            z, zd = seg.state(tg)
            d, v, a = z[:, :n] @ A.T, z[:, n:] @ A.T, zd[:, n:] @ A.T
            dmin, dmax = np.minimum(dmin, d.min(axis=0)), np.maximum(dmax, d.max(axis=0))
            amin, amax = np.minimum(amin, a.min(axis=0)), np.maximum(amax, a.max(axis=0))
            if length == 0.0:
                continue
            for e in range(m):
                ve, ae = v[:, e], a[:, e]
                for q in np.flatnonzero((ve[:-1] > 0.0) != (ve[1:] > 0.0)).tolist():
                    tq = _brent(lambda x, e=e: seg.element_point(x, e)[1], float(tg[q]), float(tg[q + 1]),
                                0.0, 0.0)
                    val = seg.element_point(tq, e)[0]
                    dmin[e], dmax[e] = min(dmin[e], val), max(dmax[e], val)
                da = np.diff(ae)
                if not np.any(da):
                    continue
                # an interior grid extremum, and both ways the first and the last cell (an extremum
                # next to a segment end leaves no sign change of the grid differences)
                brackets = [(float(tg[q - 1]), float(tg[q + 1]), 1.0 if da[q - 1] < 0.0 else -1.0)
                            for q in (np.flatnonzero(da[:-1] * da[1:] < 0.0) + 1).tolist()]
                for lo_c, hi_c in ((tg[0], tg[1]), (tg[-2], tg[-1])):
                    brackets += [(float(lo_c), float(hi_c), 1.0), (float(lo_c), float(hi_c), -1.0)]
                for lo_c, hi_c, sign in brackets:  # sign +1: a minimum of δ_e'', −1: a maximum
                    res = optimize.minimize_scalar(lambda x, e=e, s=sign: s * seg.element_point(x, e)[2],
                                          bounds=(lo_c, hi_c), method="bounded",
                                          options={"xatol": 1e-12 * max(length, 1.0)})
                    val = seg.element_point(float(res.x), e)[2]
                    amin[e], amax[e] = min(amin[e], val), max(amax[e], val)
        return SystemMeasures(names=fsys.element_names, mean=mean, rms=rms, rms_ac=np.sqrt(np.maximum(ms_ac, 0.0)),
                              delta_min=dmin, delta_max=dmax, p2p=dmax - dmin, acc_min=amin, acc_max=amax,
                              acc_p2p=amax - amin)

    def sample(self, t: FloatArray | float) -> tuple[FloatArray, FloatArray]:
        """z = (x, x') and z' = (x', x'') at times ``t``: shapes t.shape + (2n,) each."""
        t = np.asarray(t, dtype=float)
        flat = t.reshape(-1)
        idx = self.segment_index(flat)
        n2 = self.state0.size
        z = np.empty((flat.size, n2))
        zd = np.empty((flat.size, n2))
        for i in np.unique(idx):
            sel = idx == i
            zi, zdi = self.segments[i].state(flat[sel] - self.t_start[i])
            z[sel], zd[sel] = zi, zdi
        return z.reshape(t.shape + (n2,)), zd.reshape(t.shape + (n2,))

    def element_samples(self, t: FloatArray | float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """δ, δ' and δ'' of every element at times ``t``: shapes t.shape + (m,)."""
        z, zd = self.sample(t)
        A = self.system.element_rows
        n = self.system.n
        return z[..., :n] @ A.T, z[..., n:] @ A.T, zd[..., n:] @ A.T

    def integrate(self, fun, panels_per_scale: int = 4) -> FloatArray:  # type: ignore[no-untyped-def]
        """∫_{t0}^{t1} fun(z) dt for ``fun`` mapping states (N, 2n) to values (N, …): 16-point
        Gauss–Legendre on panels of a quarter of each segment's fastest time scale (the solution
        is analytic on a segment: exact to round-off)."""
        total = None
        for i, seg in enumerate(self.segments):
            ta, tb = float(self.t_start[i]), float(self.t_end[i])
            if tb <= ta:
                continue
            npan = max(1, math.ceil((tb - ta) / (seg.sol.time_scale / panels_per_scale)))
            edges = np.linspace(0.0, tb - ta, npan + 1)
            half = 0.5 * np.diff(edges)
            taus = (0.5 * (edges[:-1] + edges[1:]))[:, None] + half[:, None] * _GAUSS_X[None, :]
            w = (half[:, None] * _GAUSS_W[None, :]).reshape(-1)
            z, _ = seg.state(taus.reshape(-1))
            val = np.tensordot(w, np.asarray(fun(z)), axes=(0, 0))
            total = val if total is None else total + val
        return np.zeros(0) if total is None else total

    def element_mean_and_rms(self) -> tuple[FloatArray, FloatArray]:
        """The time mean and rms of every element's deflection over [t0, t1] (m,) each."""
        A = self.system.element_rows
        n = self.system.n
        T = self.t1 - self.t0
        s = self.integrate(lambda z: np.concatenate((z[:, :n] @ A.T, (z[:, :n] @ A.T) ** 2), axis=1)) / T
        m = A.shape[0]
        return s[:m], np.sqrt(np.maximum(s[m:], 0.0))

    def stick_time(self) -> FloatArray:
        """Time every element spends stuck or locked, (m,)."""
        dur = self.t_end - self.t_start
        return (self.stuck * dur[:, None]).sum(axis=0)

    def lock_time(self) -> FloatArray:
        """Time every element spends locked at a jump of its law, (m,) (part of :meth:`stick_time`)."""
        if self.locked is None:
            return np.zeros(self.stuck.shape[1])
        dur = self.t_end - self.t_start
        return (self.locked * dur[:, None]).sum(axis=0)

    def stick_intervals(self, element: int) -> list[tuple[float, float]]:
        """The [start, end] time intervals where ``element`` sticks (merged)."""
        out: list[tuple[float, float]] = []
        for a, b, s in zip(self.t_start, self.t_end, self.stuck[:, element]):
            if not s or b <= a:
                continue
            if out and abs(out[-1][1] - a) <= 1e-12 * max(1.0, abs(a)):
                out[-1] = (out[-1][0], float(b))
            else:
                out.append((float(a), float(b)))
        return out

    def event_structure(self) -> tuple[int, ...]:
        """The switching pattern: for every element its stick or lock phases, then its breakpoint
        crossings, over the trajectory (2m counts, element-major)."""
        out: list[int] = []
        for e in range(self.stuck.shape[1]):
            mine = self.event_elements == e
            out.append(int(np.sum(mine & np.isin(self.event_kinds, (STICK, LOCK)))))
            out.append(int(np.sum(mine & (self.event_kinds == CROSSING))))
        return tuple(out)

    def crossed_breakpoints(self, element: int) -> FloatArray:
        """The breakpoints ``element`` crossed."""
        sel = (self.event_kinds == CROSSING) & (self.event_elements == element)
        return np.unique(self.event_values[sel])


class _FilippovFlow(ExactIntegrator, takes=takes_discontinuous,
                    kind="a rattle System carrying its elements' whole laws (Chain.friction_system())"):
    """The stage-matrix path of :class:`~rattle.timeint.ExactIntegrator` with the Filippov
    events: a :class:`~rattle.model.System` carrying its elements' whole laws (module docstring); ``options`` the event
    grid, budget and lock snap (:class:`~rattle.timeint.FlowOptions`)."""

    def __init__(self, system: System, options: FlowOptions | None = None) -> None:
        super().__init__(system, options)
        self.max_events = self.options.budget(events=True)
        system = self.system  # a Chain's reduced form
        base = system.continuous()
        self.base = base
        self.n, self.m = base.n, base.m
        self.A = base.element_rows.reshape(self.m, self.n)
        self.B = base.element_columns.reshape(self.n, self.m)
        self.levels = [np.asarray(system.friction_levels(e), dtype=float) for e in range(self.m)]
        self.has_friction = [bool(np.any(r > 0)) for r in self.levels]
        # the law's own stages (jumps included): every mode reads these offsets, not the smooth system's
        self.offsets = [np.asarray(law.stages.offsets, dtype=float) for law in system.laws]
        self.jumps = [np.asarray(law.stages.jumps, dtype=float) for law in system.laws]
        self.breakpoints = [np.asarray(law.stages.breakpoints, dtype=float) for law in system.laws]
        self._modal: dict = {}
        self._flows: Recent = Recent(MEMO)  # Ω → {mode: SystemStages}
        self._modes: dict[_Key, SystemStages] = {}  # every mode's stages at the first Ω it was met
        self._memo: Recent = Recent(MEMO)  # (z0, t0, t1, Ω) → FrictionTrajectory
        # per held set S: (A_S B_S)⁻¹ A_S and B_S (A_S B_S)⁻¹; per (stages, σ): y's constant part, Cᵀ, K_sᵀ
        self._held: dict[tuple, FloatArray] = {}
        self._parts: dict[tuple, tuple[FloatArray, FloatArray, FloatArray]] = {}
        self._watch: dict[tuple, tuple] = {}  # per (mode, stages, locked): _watched
        self._L = float(system.length_scale())  # fixed scales: the event tolerances and grid read them
        self._wn = float(system.frequency_scale())

    # --- modes ----------------------------------------------------------------------------------
    def _mode_system(self, key: _Key, omega: float) -> System:
        stuck, sigma = key
        base = self.base
        S = [e for e in range(self.m) if stuck[e]]
        P = np.eye(self.n)
        if S:
            AS, BS = self.A[S], self.B[:, S]
            P = P - BS @ np.linalg.solve(AS @ BS, AS)
        elements = []
        for e, el in enumerate(base.elements):
            st = el.law.stages  # the law's own offsets (its jumps included) and the slip friction
            law = SimpleNamespace(stages=SimpleNamespace(breakpoints=st.breakpoints, slopes=st.slopes,
                                                         offsets=self.offsets[e] + sigma[e] * self.levels[e]))
            elements.append(ReducedElement(el.name, el.a, P @ el.b, law))  # type: ignore[arg-type]
        return System(damping=P @ base.damping, stiffness=P @ base.stiffness, elements=tuple(elements),
                      mean=P @ base.mean_at(omega), cos=base.cos @ P.T, sin=base.sin @ P.T,
                      coordinates=base.coordinates, angles=base.angles, free=base.free, load=None)

    def _flow(self, key: _Key, omega: float) -> SystemStages:
        """The mode ``key``'s stages at ``omega``: kept for the last :data:`~._nonsmooth.MEMO`
        frequencies (a shooting alternates Ω and Ω + h, its ∂/∂Ω); a mode's system does not depend
        on Ω without a drag by speed, and its stages at a new Ω are then made from those of the
        first (:meth:`SystemStages.at_omega`)."""
        flows = self._flows.get(omega)
        if flows is None:
            flows = self._flows.put(omega, {})
        flow = flows.get(key)
        if flow is None:
            if self.base.load is None:
                first = self._modes.get(key)
                if first is None:
                    first = self._modes[key] = SystemStages(self._mode_system(key, omega), omega,
                                                            self.samples_per_scale, modal_cache=self._modal.setdefault(key, {}))
                flow = first if first.omega == omega else first.at_omega(omega)
            else:
                flow = SystemStages(self._mode_system(key, omega), omega, self.samples_per_scale)
            flows[key] = flow
        return flow

    def _base_step(self, omega: float) -> float:
        """The event grid's step: the fastest time scale of the forcing (its highest harmonic) and
        of the free chain (its highest natural frequency), over ``samples_per_scale`` — a stuck
        mode's own time scale can be far longer than that of the torque that must hold it."""
        fast = max(float(omega) * max(self.base.forced_harmonics, 1), self._wn)
        return 2.0 * math.pi / fast / self.samples_per_scale

    @staticmethod
    def _solution(flow: SystemStages, key: _Key, stages: tuple[int, ...]) -> StageSolution:
        """The mode's stage solution. With a stuck element the mode's matrix has a defective zero
        eigenvalue (δ_e' ≡ const, δ_e linear: a Jordan block, which eigenvalue solvers split by
        ~sqrt(ε)); its transitions are then taken from ``scipy.linalg.expm`` of the augmented
        matrix (exact to round-off), not from the block-modal form, whose cluster basis loses
        about sqrt(ε) there (measured: 3e-6 against expm)."""
        if any(key[0]) and stages not in flow.modal_cache and flow._cache_tag is None:
            A = flow.system.stage_matrix(stages)
            flow.modal_cache[stages] = {"eigenvalues": np.linalg.eigvals(A), "method": "expm"}
        sol = flow.solution(stages)
        if any(key[0]) and sol.method != "expm":  # a drag by speed: no shared cache, set it here
            sol.method = "expm"
            sol.modes = 1j * flow.hw
            sol.modes_l = sol.modes.tolist()
            sol.base_d, sol.base_z = sol.Zh_d, sol.Zh
        return sol

    def velocity_scale(self, omega: float) -> float:
        """L max(Ω, ω_n): the velocity scale of the event tolerances and the shooting residual."""
        return self._L * max(float(omega), self._wn)

    def _free_acceleration(self, key: _Key, stages: tuple[int, ...], t: FloatArray | float, z: FloatArray,
                           omega: float) -> FloatArray:
        """y = F(t) − C x' − K_s x − Σ b_e o_ej − Σ_slip b_e σ_e r_ej, shape t.shape + (n,)
        (z: t.shape + (2n,)); o_ej the law's own offsets (jumps included)."""
        n = self.n
        x, v = z[..., :n], z[..., n:]
        parts = self._parts.get((stages, key[1]))
        if parts is None:
            const = np.zeros(n)
            for e in range(self.m):
                const += (self.offsets[e][stages[e]] + key[1][e] * self.levels[e][stages[e]]) * self.B[:, e]
            parts = self._parts[(stages, key[1])] = (const, self.base.damping.T, self.base.stage_stiffness(stages).T)
        const, CT, KT = parts
        return self.base.forcing(t, omega) - v @ CT - x @ KT - const

    def _lambdas(self, S: list[int], y: FloatArray) -> FloatArray:
        """λ = (A_S B_S)⁻¹ A_S y for y (..., n): shape (..., |S|)."""
        X = self._held.get(("lambda", *S))
        if X is None:
            AS, BS = self.A[S], self.B[:, S]
            X = self._held[("lambda", *S)] = np.linalg.solve(AS @ BS, AS).T
        return y @ X

    def _band(self, e: int, stage: int, locked: bool) -> tuple[float, float]:
        """The band [lo, hi] of a held element's torque λ_e: ±r_ej when stuck on stage j; when
        locked at the jump i above its stage i, [−r_ei, J_ei + r_e,i+1] (λ relative to the stage-i
        value f(d_i⁻), which y holds)."""
        r = self.levels[e]
        if locked:
            return -float(r[stage]), float(self.jumps[e][stage] + r[stage + 1])
        return -float(r[stage]), float(r[stage])

    def _settle(self, t: float, z: FloatArray, stages: tuple[int, ...], candidates: list[int],
                sigma: list[int], omega: float, tol: float = 1e-12,
                locked: tuple[bool, ...] | None = None) -> tuple[_Key, tuple[int, ...], tuple[bool, ...]]:
        """The active-set choice of the held set among ``candidates`` (module docstring): stuck
        elements and elements ``locked`` at a jump; a torque beyond its band by less than ``tol``
        (relative) still holds. A released lock leaves upwards (stage i + 1, σ = +1) when its torque
        exceeds the band, else downwards (stage i, σ = −1). Returns (key, stages, locked)."""
        S = sorted(set(candidates))
        sigma = list(sigma)
        st = list(stages)
        lk = [False] * self.m if locked is None else list(locked)
        for e in range(self.m):
            if e not in S:
                lk[e] = False
        for e in S:
            sigma[e] = 0
        while S:
            key = (tuple(e in S for e in range(self.m)), tuple(sigma))
            lam = self._lambdas(S, self._free_acceleration(key, tuple(st), t, z, omega))
            worst, e_w, up_w = 0.0, -1, False
            for e, lam_e in zip(S, lam.tolist()):
                lo, hi = self._band(e, st[e], lk[e])
                excess = max(lo - lam_e, lam_e - hi)
                if excess > tol * max(hi, -lo, abs(lam_e), 1e-300) and excess > worst:
                    worst, e_w, up_w = excess, e, lam_e > hi
            if e_w < 0:
                break
            S.remove(e_w)
            if lk[e_w]:
                lk[e_w] = False
                if up_w:
                    st[e_w] += 1
            sigma[e_w] = (1 if up_w else -1) if self.has_friction[e_w] else 0
        return (tuple(e in S for e in range(self.m)), tuple(sigma)), tuple(st), tuple(lk)

    def _hold_columns(self, S: list[int]) -> FloatArray:
        """W = B_S (A_S B_S)⁻¹ (n, |S|): column w_e moves element e alone (a_e·w_e = 1, a_k·w_e = 0 for
        the other held k) along the constraint forces."""
        W = self._held.get(("hold", *S))
        if W is None:
            AS, BS = self.A[S], self.B[:, S]
            W = self._held[("hold", *S)] = BS @ np.linalg.inv(AS @ BS)
        return W.copy()

    def _initial_key(self, t: float, z: FloatArray, stages: tuple[int, ...],
                     omega: float) -> tuple[_Key, tuple[int, ...], tuple[bool, ...]]:
        """The mode at the start: friction elements at rest are stick candidates; an element at rest
        on a jump of its law (within round-off, or within the neighbourhood the chatter snaps from:
        ``lock_excursion``) is a lock candidate (on the stage below the jump)."""
        n = self.n
        dv = self.A @ z[n:]
        dd = self.A @ z[:n]
        tol = 64.0 * _EPS * self.velocity_scale(omega)
        # a lock's neighbourhood: where the chatter would snap into it anyway (an excursion of at
        # most lock_excursion · L: |δ_e − d_i| and δ_e'²/(2 L ω²) below it), or round-off
        lx = self.options.lock_excursion
        tol_d = max(64.0 * _EPS, lx)
        tol_v = max(tol, math.sqrt(2.0 * lx) * self.velocity_scale(omega))
        sigma = [0] * self.m
        st = list(stages)
        lk = [False] * self.m
        cands = []
        for e in range(self.m):
            at_rest = abs(dv[e]) <= tol
            bp, J = self.breakpoints[e], self.jumps[e]
            near = np.flatnonzero((J > 0) & (np.abs(bp - dd[e]) <= tol_d * np.maximum(self._L, np.abs(bp))))
            if abs(dv[e]) <= tol_v and near.size:
                st[e], lk[e] = int(near[0]), True
                cands.append(e)
            elif not self.has_friction[e]:
                continue
            elif at_rest:
                cands.append(e)
            else:
                sigma[e] = 1 if dv[e] > 0 else -1
        return self._settle(t, z, tuple(st), cands, sigma, omega, locked=tuple(lk))

    def _field(self, key: _Key, stages: tuple[int, ...], t: float, z: FloatArray, omega: float) -> FloatArray:
        """φ = (x', x'') of the mode ``key`` at (t, z), (2n,)."""
        n = self.n
        y = self._free_acceleration(key, stages, t, z, omega)
        S = [e for e in range(self.m) if key[0][e]]
        if S:
            y = y - self.B[:, S] @ self._lambdas(S, y)
        return np.concatenate((z[n:], y))

    # --- integration ----------------------------------------------------------------------------
    def propagate(self, z0: FloatArray, t0: float, t1: float, omega: float) -> FrictionTrajectory:
        """Integrate exactly from ``z0`` = (x, x') at ``t0`` to ``t1`` ≥ t0 at forcing frequency
        ``omega``: the :class:`FrictionTrajectory` with its segments, events, final state and
        sensitivity ∂z(t1)/∂z(t0). The last :data:`~._nonsmooth.MEMO` trajectories are kept by
        their exact arguments (z0, t0, t1, Ω): a shooting continuation asks again for the period it
        has just integrated (an accepted point's row after the corrector's last evaluation there)."""
        z = check_system_state(z0, self.n)
        omega = check_omega(omega)
        t0, t1 = check_interval(t0, t1, omega)
        key = (z.tobytes(), t0, t1, omega)
        traj = self._memo.get(key)
        if traj is not None:
            return traj
        rec: dict[str, list] = {k: [] for k in ("ts", "st", "sk", "lk", "seg", "et", "ee", "ek", "ev")}
        z1, M = self._march(z, t0, t1, omega, rec)
        ts = np.asarray(rec["ts"], dtype=float)
        traj = FrictionTrajectory(
            system=self.system, omega=omega, t0=t0, t1=t1, state0=z, state1=z1, sensitivity=M, t_start=ts,
            t_end=np.append(ts[1:], t1), stages=np.asarray(rec["st"], dtype=np.int64).reshape(-1, self.m),
            stuck=np.asarray(rec["sk"], dtype=bool).reshape(-1, self.m), segments=tuple(rec["seg"]),
            event_times=np.asarray(rec["et"], dtype=float), event_elements=np.asarray(rec["ee"], dtype=np.int64),
            event_kinds=np.asarray(rec["ek"], dtype=np.int64), event_values=np.asarray(rec["ev"], dtype=float),
            locked=np.asarray(rec["lk"], dtype=bool).reshape(-1, self.m),
        )
        return self._memo.put(key, traj)

    def advance(self, z0: FloatArray, t0: float, t1: float, omega: float,
                sensitivity: bool = True) -> tuple[FloatArray, FloatArray]:
        """The state at ``t1`` and ∂z(t1)/∂z(t0) (copies; the ``sensitivity`` is there for the
        common signature: M is always computed): the period map of a shooting, recorded and kept
        (:meth:`propagate`) over at most an orbit's longest period (``MAX_PERIOD`` forcing
        periods), else marched without a record (a long settling)."""
        t0, t1, omega = float(t0), float(t1), float(omega)
        if (t1 - t0) * omega / (2.0 * math.pi) <= MAX_PERIOD + 0.5:
            traj = self.propagate(z0, t0, t1, omega)
            return traj.state1.copy(), traj.sensitivity.copy()
        return self._march(np.asarray(z0, dtype=float).copy(), t0, t1, omega, None)

    def _march(self, z: FloatArray, t0: float, t1: float, omega: float,
               rec: dict[str, list] | None) -> tuple[FloatArray, FloatArray]:
        n, m = self.n, self.m
        stages = self._flow(((False,) * m, (0,) * m), omega).stages_at(t0, z)
        key, stages, locked = self._initial_key(t0, z, stages, omega)
        t = t0
        M = np.eye(2 * n)
        S = [e for e in range(m) if key[0][e]]
        if S:  # a start in a stick: a perturbation of δ_e' slips and sticks again at once, which
            # removes it (the entry saltation, whichever its sign): δx' → P_S δx'. A start in a lock
            # also removes the perturbation ε = a_e·δx of δ_e: the element chatters back into the
            # same lock, moving along w_e (δx → δx − w_e ε), and the damping acts on that motion,
            # −C ∫x' dt = C w_e ε, of which the held elements keep P_S C w_e ε (first order in ε,
            # while the chatter lasts O(√ε)): δx' → P_S (δx' + C w_e a_e·δx).
            W = self._hold_columns(S)
            P = np.eye(n) - W @ self.A[S]
            D = np.zeros((n, n))
            for k, e in enumerate(S):
                if locked[e]:
                    a = self.A[e]
                    d = float(self.breakpoints[e][stages[e]])
                    z[:n] += a * ((d - float(a @ z[:n])) / float(a @ a))
                    z[n:] -= W[:, k] * float(a @ z[n:])
                    D += np.outer(W[:, k], a)
            M = np.block([[np.eye(n) - D, np.zeros((n, n))], [P @ self.base.damping @ D, P]])
        x_lock = self.options.lock_excursion * self._L
        events = 0
        idle = 0
        last = (-1, -1, math.nan)  # the last event (element, kind, breakpoint): names a chatter
        while True:
            flow = self._flow(key, omega)
            sol = self._solution(flow, key, stages)
            remaining = t1 - t
            tau_lim = min(remaining, sol.max_segment)
            seg = sol.segment(t, z, tau_lim)
            stuck = key[0]
            lo, hi = sol.lo.copy(), sol.hi.copy()
            for e in range(m):
                if stuck[e]:
                    lo[e], hi[e] = -np.inf, np.inf
            if np.any(np.isfinite(lo)) or np.any(np.isfinite(hi)):
                tau_b, e_b, direction = first_exit(seg, lo, hi, tau_lim, sol.grid_step, flow.samples_per_scale)
            else:
                tau_b, e_b, direction = tau_lim, -1, 0
            tau_f, e_f, kind_f, sign_f = self._friction_event(seg, sol, key, stages, tau_b, omega, locked)
            if e_f >= 0 and tau_f <= tau_b:
                tau, e_ev, kind = tau_f, e_f, kind_f
            elif e_b >= 0:
                tau, e_ev, kind = tau_b, e_b, CROSSING
                tau = self._crossing_time(seg, e_ev, direction, lo, hi, stages, tau, tau_lim)
            else:
                tau, e_ev, kind = tau_b, -1, -1
            missed = self._missed_exit(seg, lo, hi, tau, e_ev if kind == CROSSING else -1) if tau > 0.0 else None
            if missed is not None:  # an excursion beyond a breakpoint the crossing search stepped over
                tau, e_ev, direction = missed
                kind = CROSSING
                tau = self._crossing_time(seg, e_ev, direction, lo, hi, stages, tau, tau)
            if rec is not None and (tau > 0.0 or not rec["ts"]):
                rec["ts"].append(t)
                rec["st"].append(stages)
                rec["sk"].append(stuck)
                rec["lk"].append(locked)
                rec["seg"].append(seg)
            if tau > 0.0:
                M = sol.transition(tau) @ M
                zc = seg.end_state(tau)
                idle = 0
            else:
                zc = z.copy()
                idle += 1
                if idle > 4 * m + 8:
                    raise ConvergenceError(
                        f"the motion switches modes without advancing in time at t = {t!r} (stages {stages}, "
                        f"stuck {stuck}): an element at rest whose friction neither holds nor releases it "
                        "consistently (stuck elements closing a loop?); perturb the state `z0` slightly"
                    )
            t = t + tau
            if e_ev < 0:
                if tau_lim >= remaining:
                    return zc, M
                z = zc
                continue
            events += 1
            if events > self.max_events:
                raise ConvergenceError(self._budget_message(t0, t1, last))
            a = self.A[e_ev]
            phi_minus = self._field(key, stages, t, zc, omega)
            value = math.nan
            normal: FloatArray | None = None
            if kind == CROSSING:
                bound = float(hi[e_ev] if direction > 0 else lo[e_ev])
                i_bp = stages[e_ev] if direction > 0 else stages[e_ev] - 1
                zc[:n] += a * ((bound - float(a @ zc[:n])) / float(a @ a))
                value = bound
                new_stages = stages[:e_ev] + (stages[e_ev] + direction,) + stages[e_ev + 1:]
                cands = [e for e in range(m) if stuck[e]]
                new_key, new_stages, new_locked = self._settle(t, zc, new_stages, cands, list(key[1]), omega,
                                                               locked=locked)
                held = self._lock_entry(t, zc, e_ev, i_bp, stages, new_key, new_stages, locked, omega, x_lock) \
                    if self.jumps[e_ev][i_bp] > 0.0 and x_lock > 0.0 else None
                if held is not None:  # the chatter's limit: locked at the jump
                    kind = LOCK
                    new_key, new_stages, new_locked = held
                    S = [e for e in range(m) if new_key[0][e]]
                    w = self._hold_columns(S)[:, S.index(e_ev)]
                    zc[n:] -= w * float(a @ zc[n:])  # the relay torque's momentum along w_e (∝ P b_e)
                    Q = np.eye(n) - np.outer(w, a)
                    M = np.vstack((Q @ M[:n], Q @ M[n:]))  # S = blockdiag(Π, Π): the 1/δ_e' terms cancel
                else:
                    normal = np.concatenate((a, np.zeros(n)))
                stages, locked = new_stages, new_locked
            elif kind == STICK:
                cands = [e for e in range(m) if stuck[e]] + [e_ev]
                # δ_e' = 0 (round-off, or the rest of a chatter), the other held elements left at rest
                zc[n:] -= self._hold_columns(cands)[:, -1] * float(a @ zc[n:])
                # a velocity zero again at once (no time passed): the torque sits on its band's edge
                # (a touch); the round-off that tipped it over must not keep it slipping forever
                new_key, stages, locked = self._settle(t, zc, stages, cands, list(key[1]), omega,
                                                       1e-12 if idle == 0 else 1e-6, locked=locked)
                if not new_key[0][e_ev]:
                    kind = REVERSAL
                normal = np.concatenate((np.zeros(n), a))
            else:  # RELEASE of a stick or a lock: the fields agree at the band's edge
                sigma = list(key[1])
                sigma[e_ev] = sign_f if self.has_friction[e_ev] else 0
                st = list(stages)
                lk = list(locked)
                if lk[e_ev]:
                    kind = UNLOCK
                    value = float(self.breakpoints[e_ev][st[e_ev]])
                    lk[e_ev] = False
                    if sign_f > 0:
                        st[e_ev] += 1
                cands = [e for e in range(m) if stuck[e] and e != e_ev]
                new_key, stages, locked = self._settle(t, zc, tuple(st), cands, sigma, omega, locked=tuple(lk))
                if kind == UNLOCK and not new_key[0][e_ev]:
                    # Released at the band's edge: δ_e' = 0 and δ_e'' = 0 there, growing the way
                    # it leaves (sign_f). Round-off in δ_e' pointing back (~1e-17) would cross
                    # the jump back at once and snap into the lock again for ~1e-13 (a spurious
                    # lock/unlock pair, CPU-dependent). Leave as the reference does: δ_e' not back,
                    # δ_e a hair (64 ε L) on the side it leaves to.
                    vb = float(a @ zc[n:])
                    if vb * sign_f < 0.0:
                        zc[n:] -= self._hold_columns([e_ev])[:, 0] * vb
                    hair = 64.0 * _EPS * max(self._L, abs(value))
                    zc[:n] += a * ((value + sign_f * hair - float(a @ zc[:n])) / float(a @ a))
            if normal is not None:
                phi_plus = self._field(new_key, stages, t, zc, omega)
                denom = float(normal @ phi_minus)
                if denom != 0.0 and math.isfinite(denom):
                    M = (np.eye(2 * n) + np.outer(phi_plus - phi_minus, normal) / denom) @ M
            if rec is not None:
                rec["et"].append(t)
                rec["ee"].append(e_ev)
                rec["ek"].append(kind)
                rec["ev"].append(value)
            last = (e_ev, kind, value)
            key, z = new_key, zc

    def _missed_exit(self, seg: Segment, lo: FloatArray, hi: FloatArray, tau: float,
                     skip: int) -> tuple[float, int, int] | None:
        """The first breakpoint crossing in (0, ``tau``) of an element found outside its stage at
        ``tau`` (other than ``skip``, the element whose crossing ends the segment): (τ, element,
        direction), or None. The crossing search brackets an exit by a change of sign of δ_e' in a
        grid cell, which an element starting at rest (released) does not show when its excursion
        beyond a breakpoint and back fits in the first cell; its velocity zero at the excursion's
        top then ends the segment outside the stage."""
        n = self.n
        d = self.A @ seg.end_state(tau)[:n]
        out = []
        for e in range(self.m):
            if e == skip or not (np.isfinite(lo[e]) or np.isfinite(hi[e])):
                continue
            floor = seg.element_floors(e)[0] + 8.0 * _EPS * max(abs(lo[e]) if np.isfinite(lo[e]) else 0.0,
                                                                  abs(hi[e]) if np.isfinite(hi[e]) else 0.0)
            if d[e] - hi[e] > floor or lo[e] - d[e] > floor:
                out.append(e)
        if not out:
            return None
        taus = np.linspace(0.0, tau, 129)
        dd, _ = seg.scan(taus)
        best: tuple[float, int, int] | None = None
        for e in out:
            beyond = (dd[1:, e] >= hi[e]) | (dd[1:, e] < lo[e])
            i = int(beyond.argmax()) + 1
            up = bool(dd[i, e] >= hi[e])
            bound = float(hi[e] if up else lo[e])

            def gap(t: float, e: int = e, bound: float = bound) -> float:
                return seg.element_point(t, e)[0] - bound

            hit = _brent(gap, float(taus[i - 1]), float(taus[i]), 0.0, 0.0)
            if best is None or hit < best[0]:
                best = (hit, e, 1 if up else -1)
        return best

    def _crossing_time(self, seg: Segment, e: int, direction: int, lo: FloatArray, hi: FloatArray,
                       stages: tuple[int, ...], tau: float, tau_max: float) -> float:
        """The time ``tau`` of element ``e``'s crossing of its stage bound (``hi`` upwards, ``lo``
        downwards), polished (:func:`~._roots.polish_crossing`) where the field jumps there: a jump of
        the law or a change of friction level."""
        i_bp = stages[e] if direction > 0 else stages[e] - 1
        if self.jumps[e][i_bp] > 0.0 or self.levels[e][i_bp] != self.levels[e][i_bp + 1]:
            polished = polish_crossing(lambda x: seg.element_point(x, e), float(hi[e] if direction > 0 else lo[e]),
                                       tau, tau_max)
            return tau if polished is None else polished
        return tau

    def _lock_entry(self, t: float, z: FloatArray, e: int, i: int, stages: tuple[int, ...], key: _Key,
                    new_stages: tuple[int, ...], locked: tuple[bool, ...], omega: float,
                    x_lock: float) -> tuple[_Key, tuple[int, ...], tuple[bool, ...]] | None:
        """At a crossing of the jump i of element ``e`` (state ``z``; the ordinary crossing's mode
        ``key`` on ``new_stages``): the locked mode when the acceleration on the side entered
        points back, the next excursion δ_e'²/(2|δ_e''⁺|) is at most ``x_lock`` and the lock band
        holds the element's torque (the active set keeps it held); else None."""
        n = self.n
        a = self.A[e]
        v = float(a @ z[n:])
        acc = float(a @ self._field(key, new_stages, t, z, omega)[n:])
        if not (acc * v < 0.0 and v * v <= 2.0 * abs(acc) * x_lock):
            return None
        st = list(new_stages)
        st[e] = i
        lk = list(locked)
        lk[e] = True
        cands = [k for k in range(self.m) if key[0][k]] + [e]
        held = self._settle(t, z, tuple(st), cands, list(key[1]), omega, locked=tuple(lk))
        return held if held[2][e] else None

    def _budget_message(self, t0: float, t1: float, last: tuple[int, int, float]) -> str:
        e, kind, value = last
        base = f"more than `max_events` = {self.max_events} events between t0 = {t0!r} and t1 = {t1!r}"
        if kind == CROSSING and e >= 0:
            i = int(np.searchsorted(self.breakpoints[e], value))
            r = self.levels[e]
            if i < self.jumps[e].size and self.jumps[e][i] > 0.0 and r[i] == 0.0 and r[i + 1] == 0.0:
                name = self.base.elements[e].name
                return (f"{base}: element {name!r} chatters into a lock at the jump of its law at δ = {value:g} "
                        "without friction there (its crossings decay only exponentially, at about a third of the "
                        "damping rate; the lock is reached when an excursion falls below `lock_excursion`); raise "
                        "FlowOptions(max_events=...) or `lock_excursion`, or shorten the interval")
        return f"{base} (stick–slip chatter?): raise FlowOptions(max_events=...) or shorten the interval"

    def _friction_event(self, seg: Segment, sol: StageSolution, key: _Key, stages: tuple[int, ...],
                        tau_end: float, omega: float,
                        locked: tuple[bool, ...] | None = None) -> tuple[float, int, int, int]:
        """The first friction event in (0, ``tau_end``]: (τ, element, kind, sign) — a velocity zero
        of a slipping element with friction (kind STICK, refined to a stick or a reversal by the
        caller) or a held element's torque leaving its band (±r stuck, [−r_i, J_i + r_i+1] locked:
        RELEASE, +1 above the band, −1 below); element −1 if none."""
        n = self.n
        setup = self._watch.get((key, stages, locked))
        if setup is None:
            setup = self._watch[(key, stages, locked)] = self._watched(key, stages, locked)
        slip, S, lo_S, hi_S, sg, AslT = setup
        if tau_end <= 0.0 or not (slip or S):
            return tau_end, -1, -1, 0
        step = min(sol.grid_step, self._base_step(omega))
        if S:

            def lam_at(taus: FloatArray, z: FloatArray) -> FloatArray:
                return self._lambdas(S, self._free_acceleration(key, stages, seg.ts + taus, z, omega))
        tau_a = 0.0
        while tau_a < tau_end:
            taus = grid_chunk(tau_a, tau_end, step, _CHUNK)
            z, zd = seg.state(taus)
            best = (math.inf, -1, -1, 0)
            if slip:
                sv = (z[:, n:] @ AslT) * sg  # σ δ' (k+1, |slip|)
                sa = (zd[:, n:] @ AslT) * sg  # σ δ''
                for j, e in enumerate(slip):
                    hit = self._velocity_zero(seg, e, sg[j], taus, sv[:, j], sa[:, j])
                    if hit is not None and hit < best[0]:
                        best = (hit, e, STICK, 0)
            if S:
                lam = lam_at(taus, z)  # (k+1, |S|)
                over = (lam[1:] > hi_S) | (lam[1:] < lo_S)
                for j, e in enumerate(S):
                    if not over[:, j].any():
                        continue
                    i = int(over[:, j].argmax()) + 1
                    s = 1.0 if lam[i, j] > hi_S[j] else -1.0
                    edge = float(hi_S[j] if s > 0 else lo_S[j])
                    if taus[i - 1] >= best[0]:
                        continue

                    def g(tau: float, j: int = j, edge: float = edge) -> float:
                        zz = seg.end_state(tau)[None]
                        return float(lam_at(np.array([tau]), zz)[0, j]) - edge

                    ga = float(lam[i - 1, j]) - edge
                    gb = float(lam[i, j]) - edge
                    if ga * gb > 0:  # at the start already beyond (round-off): release at once
                        hit = float(taus[i - 1])
                    else:
                        hit = _brent(g, float(taus[i - 1]), float(taus[i]), ga, gb)
                    if hit < best[0]:
                        best = (hit, e, RELEASE, int(s))
            if best[1] >= 0:
                return best[0], best[1], best[2], best[3]
            tau_a = float(taus[-1])
        return tau_end, -1, -1, 0

    def _watched(self, key: _Key, stages: tuple[int, ...], locked: tuple[bool, ...] | None) -> tuple:
        """What :meth:`_friction_event` watches in a mode: the slipping elements with friction, the
        held set S, its torques' bands (lo, hi), the slip signs σ and (a_e for the slipping)ᵀ."""
        m = self.m
        stuck, sigma = key
        slip = [e for e in range(m) if self.has_friction[e] and not stuck[e] and sigma[e]]
        S = [e for e in range(m) if stuck[e]]
        lk = (False,) * m if locked is None else locked
        bands = [self._band(e, stages[e], lk[e]) for e in S]
        lo_S = np.array([b[0] for b in bands])
        hi_S = np.array([b[1] for b in bands])
        sl = np.array(slip, dtype=np.intp)
        sg = np.array([sigma[e] for e in slip], dtype=float)
        return slip, S, lo_S, hi_S, sg, self.A[sl].T

    def _velocity_zero(self, seg: Segment, e: int, s: float, taus: FloatArray, sv: FloatArray,
                       sa: FloatArray) -> float | None:
        """The first τ in (taus[0], taus[-1]] where σ δ_e' reaches 0 (``sv`` its samples, ``sa``
        those of σ δ_e''), a minimum inside a cell refined; None if none."""
        a = self.A[e]
        n = self.n

        def vel(tau: float) -> float:
            return s * float(a @ seg.end_state(tau)[n:])

        def acc(tau: float) -> float:
            return s * seg.element_point(tau, e)[2]

        # only the cells that can decide: σ δ' ≤ 0 at their end, or a minimum of σ δ' inside
        cells = (np.flatnonzero((sv[1:] <= 0.0) | ((sa[:-1] < 0.0) & (sa[1:] > 0.0))) + 1).tolist()
        if not cells:
            return None
        floor = 64.0 * _EPS * max(float(np.max(np.abs(sv))), self.velocity_scale(seg.sol.flow.omega))
        for i in cells:
            lo_v, hi_v = float(sv[i - 1]), float(sv[i])
            if hi_v <= 0.0:
                if lo_v > floor or (lo_v > 0.0 and i > 1):
                    return _brent(vel, float(taus[i - 1]), float(taus[i]), lo_v, hi_v)
                if i == 1 and lo_v <= floor:  # starts at rest (a round-off velocity of either sign):
                    # a positive excursion first?
                    if hi_v >= -floor:
                        continue
                    if sa[0] > 0.0 > sa[1]:  # σ δ' rises, turns, and falls through 0 in the cell
                        try:
                            tm = _brent(acc, float(taus[0]), float(taus[1]), float(sa[0]), float(sa[1]))
                        except ValueError:
                            tm = float(taus[0])
                        vm = vel(tm)
                        if vm > floor:
                            return _brent(vel, tm, float(taus[1]), vm, hi_v)
                    return float(taus[0])  # no excursion: the element cannot move this way (a stick)
                return float(taus[i - 1])
            if sa[i - 1] < 0.0 < sa[i]:  # a minimum of σ δ' inside the cell
                try:
                    tm = _brent(acc, float(taus[i - 1]), float(taus[i]), float(sa[i - 1]), float(sa[i]))
                except ValueError:
                    continue
                vm = vel(tm)
                if vm < -floor and lo_v > 0.0:  # a real excursion (a touch at round-off level is not one)
                    return _brent(vel, float(taus[i - 1]), tm, lo_v, vm)
        return None


__all__ = ["EVENT_NAMES", "FrictionTrajectory"]
