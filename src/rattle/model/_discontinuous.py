"""Discontinuous laws: a torque jump (preload) and Coulomb friction (hysteresis) of one coordinate.

The law g of the single equation of SPEC §1 (c = C/I, k = K/I; the equation itself is
the single equation's :class:`~rattle.model.System`, :meth:`~rattle.model.System.single`) and of
every element of a chain with friction (a :class:`~rattle.model.System` with its elements' whole
laws, :mod:`._system`),

    δ'' + c δ' + k g(δ, δ') = F(t) = F_m + Σ_n F_pn cos(n Ω t + φ_n),
    g(δ, δ') = f(δ) + r(δ) sgn(δ'),

where every quantity of g is relative to K (like the slopes of :mod:`._elastic`: a torque is K
times it):

- f is piecewise linear on stages j (d_j ≤ δ < d_{j+1}, d_0 = −∞, d_{k+1} = +∞),
  f(δ) = s_j δ + e_j, but may jump *up* at a breakpoint: J_i = f(d_i⁺) − f(d_i⁻) ≥ 0. The offsets
  e_j follow from e_{j+1} = e_j + (s_j − s_{j+1}) d_i + J_i and from "f(0) = 0", read as the
  midpoint (f(0⁻) + f(0⁺))/2 = 0 when a jump sits at δ = 0.
- r(δ) = r_j ≥ 0 on stage j is a Coulomb friction level (a hysteresis torque K r_j opposing the
  relative velocity δ'); sgn(0) is the Filippov set [−1, 1] (sticking, see
  :mod:`rattle.timeint._nonsmooth`).

Library laws:

- :class:`Preload` — the torque-converter clutch characteristic. The paper's clutch law
  f = α δ (|δ| ≤ b), δ − (1 − α) b sgn δ (|δ| > b) tends, for α → ∞ and b → 0 with α b → T_p
  held fixed, to

      f(δ) = s δ + T_p sgn δ        (a jump 2 T_p at δ = 0),

  the first stage infinitely stiff over zero clearance. With a clearance b > 0 (a free play before
  the preloaded spring engages): f = 0 for |δ| < b, s (δ − b) + T_p for δ > b, s (δ + b) − T_p for
  δ < −b (jumps T_p at ±b).
- :class:`PiecewiseJump` — any law with upward jumps at chosen breakpoints.
- :class:`Friction` — Coulomb levels, one for all stages or one per stage of the law (a multi-stage
  clutch damper whose friction washers act on some stages only).
- :class:`NonsmoothLaw` — an elastic law (continuous :class:`~rattle.model.AbstractElastic` or one
  of the above) together with its friction: the data the exact integrator reads.

The laws know no model: this module imports only the continuous laws of :mod:`._elastic`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .._typing import FloatArray
from ._elastic import AbstractElastic, StageLaw, _check_real, _check_real_sequence, check_delta


@dataclass(frozen=True, slots=True)
class JumpStages:
    """Breakpoints d_i (k,), slopes s_j (k+1,), offsets e_j (k+1,) and upward jumps J_i ≥ 0 (k,)
    of a piecewise-linear law with jumps: f = s_j δ + e_j on stage j (read-only arrays)."""

    breakpoints: FloatArray
    slopes: FloatArray
    offsets: FloatArray
    jumps: FloatArray


def _jump_stages(breakpoints: tuple[float, ...], slopes: tuple[float, ...], jumps: tuple[float, ...]) -> JumpStages:
    d = np.asarray(breakpoints, dtype=float)
    s = np.asarray(slopes, dtype=float)
    J = np.asarray(jumps, dtype=float)
    e = np.zeros_like(s)
    for i in range(len(d)):  # f(d_i⁺) − f(d_i⁻) = J_i
        e[i + 1] = e[i] + (s[i] - s[i + 1]) * d[i] + J[i]
    at_zero = np.flatnonzero(d == 0.0)
    if at_zero.size:  # a jump at 0: the midpoint of the one-sided values is 0
        i = int(at_zero[0])
        e -= 0.5 * (e[i] + e[i + 1])
    else:
        e -= e[int(np.searchsorted(d, 0.0, side="right"))]
    for arr in (d, s, e, J):
        arr.setflags(write=False)
    return JumpStages(d, s, e, J)


def _check_law_data(d: tuple[float, ...], s: tuple[float, ...], J: tuple[float, ...]) -> None:
    if len(s) != len(d) + 1:
        raise ValueError(f"`slopes` must have one more entry than `breakpoints` ({len(d)} breakpoints need "
                         f"{len(d) + 1} slopes), got {len(s)}")
    if len(J) != len(d):
        raise ValueError(f"`jumps` must have one entry per breakpoint ({len(d)}), got {len(J)}")
    for i in range(len(d) - 1):
        if not d[i] < d[i + 1]:
            raise ValueError(f"`breakpoints` must be strictly increasing, got {list(d)!r} "
                             f"(breakpoints[{i}] = {d[i]} is not < breakpoints[{i + 1}] = {d[i + 1]})")
    for i, v in enumerate(s):
        if v < 0:
            raise ValueError(f"`slopes[{i}]` must be >= 0, got {v!r}")
    if s[0] <= 0 or s[-1] <= 0:
        raise ValueError(f"the outer `slopes` (first and last) must be > 0 so that the law confines the motion, "
                         f"got {list(s)!r}")
    for i, v in enumerate(J):
        if v < 0:
            raise ValueError(f"`jumps[{i}]` must be >= 0 (a restoring law jumps up; a downward jump repels "
                             f"the motion from the breakpoint and has no unique solution there), got {v!r}")


class AbstractJumpLaw(StageLaw):
    """Base of the laws with jumps: vectorised f, ∂f/∂δ (away from the jumps; :class:`StageLaw`)
    and the stage data."""

    name: ClassVar[str] = "abstract_jump"

    @property
    def stages(self) -> JumpStages:  # pragma: no cover - overridden
        raise NotImplementedError

    def to_dict(self) -> dict[str, object]:  # pragma: no cover - overridden
        raise NotImplementedError


@dataclass(frozen=True, slots=True, kw_only=True)
class PiecewiseJump(AbstractJumpLaw):
    """Piecewise-linear law with upward jumps ``jumps`` J_i ≥ 0 at ``breakpoints`` d_i and
    ``slopes`` s_0 … s_k (the outer ones > 0); f(0) = 0 (the midpoint if a jump sits at 0).

    ::

        f |          /
          |         |      jump J_i at d_i
          |     ___/
        --+--.-'--------- δ
    """

    name: ClassVar[str] = "piecewise_jump"
    breakpoints: tuple[float, ...]
    slopes: tuple[float, ...]
    jumps: tuple[float, ...]
    _data: JumpStages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        d = _check_real_sequence("breakpoints", self.breakpoints)
        s = _check_real_sequence("slopes", self.slopes)
        J = _check_real_sequence("jumps", self.jumps)
        _check_law_data(d, s, J)
        object.__setattr__(self, "breakpoints", d)
        object.__setattr__(self, "slopes", s)
        object.__setattr__(self, "jumps", J)
        object.__setattr__(self, "_data", _jump_stages(d, s, J))

    @property
    def stages(self) -> JumpStages:
        return self._data

    def to_dict(self) -> dict[str, object]:
        return {"type": "piecewise_jump", "breakpoints": list(self.breakpoints), "slopes": list(self.slopes),
                "jumps": list(self.jumps)}


@dataclass(frozen=True, slots=True, kw_only=True)
class Preload(AbstractJumpLaw):
    """Preloaded spring (torque-converter clutch, the paper's clutch for α → ∞, b → 0, α b → T_p):

        f(δ) = s δ + T_p sgn δ                               (clearance = 0),
        f(δ) = 0 (|δ| < b),  s (δ ∓ b) ± T_p (±δ > b)         (clearance b > 0),

    ``preload`` T_p ≥ 0 (relative to K, like f: K f jumps from −K T_p to +K T_p, by 2 K T_p, across
    δ = 0; with a clearance by K T_p at each of δ = ±b), ``clearance``
    b ≥ 0 (rad), ``slope`` s > 0. T_p = 0 is the linear law (b = 0) or the backlash (b > 0).

    ::

        f |       /
          |      |  T_p
        --+------+------- δ      (b = 0: a jump 2 T_p at δ = 0)
          |  /
    """

    name: ClassVar[str] = "preload"
    preload: float
    clearance: float = 0.0
    slope: float = 1.0
    _data: JumpStages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        tp = _check_real("preload", self.preload)
        b = _check_real("clearance", self.clearance)
        s = _check_real("slope", self.slope)
        if tp < 0:
            raise ValueError(f"`preload` (T_p, half the torque jump) must be >= 0, got {tp!r}")
        if b < 0:
            raise ValueError(f"`clearance` must be >= 0 rad, got {b!r}")
        if s <= 0:
            raise ValueError(f"`slope` must be > 0, got {s!r}")
        object.__setattr__(self, "preload", tp)
        object.__setattr__(self, "clearance", b)
        object.__setattr__(self, "slope", s)
        if b == 0.0:
            data = _jump_stages((0.0,), (s, s), (2.0 * tp,))
        else:
            data = _jump_stages((-b, b), (s, 0.0, s), (tp, tp))
        object.__setattr__(self, "_data", data)

    @property
    def stages(self) -> JumpStages:
        return self._data

    def to_dict(self) -> dict[str, object]:
        return {"type": "preload", "preload": self.preload, "clearance": self.clearance, "slope": self.slope}


@dataclass(frozen=True, slots=True, kw_only=True)
class Friction:
    """Coulomb friction levels r ≥ 0 (relative to K: the hysteresis torque is K r, opposing δ').

    ``levels``: one number (every stage) or one per stage of the law it is combined with
    (:class:`NonsmoothLaw`), e.g. ``(0.0, 0.02, 0.0)`` for friction washers acting on the first
    clutch stage only.
    """

    levels: tuple[float, ...]

    def __post_init__(self) -> None:
        raw = self.levels
        if isinstance(raw, (int, float, np.floating)) and not isinstance(raw, bool):
            raw = (raw,)
        r = _check_real_sequence("levels", raw)
        if not r:
            raise ValueError("`levels` must hold at least one friction level, got []")
        for i, v in enumerate(r):
            if v < 0:
                raise ValueError(f"`levels[{i}]` (Coulomb friction level) must be >= 0, got {v!r}")
        object.__setattr__(self, "levels", r)

    def per_stage(self, n_stages: int) -> FloatArray:
        """The level of every stage, shape (n_stages,)."""
        if len(self.levels) == 1:
            return np.full(n_stages, self.levels[0])
        if len(self.levels) != n_stages:
            raise ValueError(f"`levels` must hold one level or one per stage ({n_stages}), got {len(self.levels)}")
        return np.asarray(self.levels, dtype=float)

    def to_dict(self) -> dict[str, object]:
        return {"levels": list(self.levels)}


def _smooth_step(x: FloatArray, width: float) -> tuple[FloatArray, FloatArray]:
    """H_ε(x) = (1 + tanh(x/ε))/2 and its derivative."""
    t = np.tanh(x / width)
    return 0.5 * (1.0 + t), 0.5 * (1.0 - t * t) / width


@dataclass(frozen=True, slots=True, kw_only=True)
class NonsmoothLaw:
    """g(δ, δ') = f(δ) + r(δ) sgn(δ') (relative to K): an ``elastic`` law (continuous or with
    jumps) and its ``friction`` (None: none). The numerics read :attr:`stages` (breakpoints,
    slopes, offsets, jumps) and :attr:`friction_levels` (one per stage)."""

    elastic: AbstractElastic | AbstractJumpLaw
    friction: Friction | None = None
    _data: JumpStages = field(init=False, repr=False, compare=False)
    _levels: FloatArray = field(init=False, repr=False, compare=False)
    _cont: JumpStages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        el = self.elastic
        if isinstance(el, AbstractJumpLaw):
            data = el.stages
        elif isinstance(el, AbstractElastic):
            st = el.stages
            data = _jump_stages(tuple(st.breakpoints.tolist()), tuple(st.slopes.tolist()),
                                (0.0,) * len(st.breakpoints))
        else:
            raise TypeError(f"`elastic` must be an elastic law (Linear, Backlash, Clutch, Piecewise, Preload, "
                            f"PiecewiseJump), got {el!r}")
        if self.friction is not None and not isinstance(self.friction, Friction):
            raise TypeError(f"`friction` must be a Friction or None, got {self.friction!r}")
        n = len(data.slopes)
        levels = np.zeros(n) if self.friction is None else self.friction.per_stage(n)
        levels.setflags(write=False)
        object.__setattr__(self, "_data", data)
        object.__setattr__(self, "_levels", levels)
        # f without its jumps (f_c(0) = 0), for the regularised law
        object.__setattr__(self, "_cont", _jump_stages(tuple(data.breakpoints.tolist()), tuple(data.slopes.tolist()),
                                                       (0.0,) * len(data.breakpoints)))

    @property
    def stages(self) -> JumpStages:
        return self._data

    @property
    def friction_levels(self) -> FloatArray:
        """r_j per stage, shape (k+1,)."""
        return self._levels

    @property
    def is_smooth(self) -> bool:
        """True when there is neither a jump nor friction (the law of :mod:`._elastic`)."""
        return not (np.any(self._data.jumps > 0) or np.any(self._levels > 0))

    def force(self, delta: FloatArray | float) -> FloatArray:
        """f(δ) (the right limit at a jump); ``delta`` a number or an array of numbers (rad), else
        TypeError naming it."""
        delta = check_delta(delta)
        st = self._data
        j = np.searchsorted(st.breakpoints, delta, side="right")
        return st.slopes[j] * delta + st.offsets[j]

    def friction_level(self, delta: FloatArray | float) -> FloatArray:
        """r(δ) (the right stage's at a breakpoint)."""
        return self._levels[np.searchsorted(self._data.breakpoints, delta, side="right")]

    def potential(self, delta: FloatArray | float) -> FloatArray:
        """V(δ) = ∫_0^δ f (continuous even across jumps), elementwise."""
        st = self._data
        x = np.atleast_1d(np.asarray(delta, dtype=float))
        edges = np.concatenate(([-np.inf], st.breakpoints, [np.inf]))
        out = np.zeros_like(x)
        for j, (s, e) in enumerate(zip(st.slopes, st.offsets)):
            # ∫ over [0, x] ∩ stage j with sign: integrate f from clip(0) to clip(x)
            a = np.clip(0.0, edges[j], edges[j + 1])
            b = np.clip(x, edges[j], edges[j + 1])
            out += 0.5 * s * (b * b - a * a) + e * (b - a)
        return out.reshape(np.shape(delta))

    def regularised(self, delta: FloatArray, velocity: FloatArray, width: float,
                    velocity_width: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """g_ε (relative to K) and its partials ∂g_ε/∂δ, ∂g_ε/∂δ': each jump J_i H(δ − d_i) and each
        friction step replaced by H_ε(x) = (1 + tanh(x/ε))/2, sgn(δ') by tanh(δ'/ε_v):

            g_ε = f_c(δ) + Σ_i J_i [H_ε(δ − d_i) − H(−d_i)] + r_ε(δ) tanh(δ'/ε_v),
            r_ε(δ) = r_0 + Σ_i (r_{i+1} − r_i) H_ε(δ − d_i),

        f_c the continuous part of f (f without its jumps, f_c(0) = 0). Tends to g as ε → 0."""
        st = self._data
        d = np.asarray(delta, dtype=float)
        v = np.asarray(velocity, dtype=float)
        cont = self._cont
        j = np.searchsorted(cont.breakpoints, d, side="right")
        g = cont.slopes[j] * d + cont.offsets[j]
        g_d = cont.slopes[j].astype(float)
        r = np.full(d.shape, float(self._levels[0]))
        r_d = np.zeros(d.shape)
        for i, (di, Ji) in enumerate(zip(st.breakpoints, st.jumps)):
            dr = float(self._levels[i + 1] - self._levels[i])
            if Ji == 0.0 and dr == 0.0:
                continue
            h, dh = _smooth_step(d - di, width)
            if Ji != 0.0:
                g = g + Ji * (h - (1.0 if di < 0 else 0.5 if di == 0 else 0.0))
                g_d = g_d + Ji * dh
            if dr != 0.0:
                r = r + dr * h
                r_d = r_d + dr * dh
        tv = np.tanh(v / velocity_width)
        return g + r * tv, g_d + r_d * tv, r * (1.0 - tv * tv) / velocity_width

    def to_dict(self) -> dict[str, object]:
        return {"elastic": self.elastic.to_dict(),
                "friction": None if self.friction is None else self.friction.to_dict()}


__all__ = ["AbstractJumpLaw", "Friction", "JumpStages", "NonsmoothLaw", "PiecewiseJump", "Preload"]
