"""A chain with Coulomb friction and torque jumps on its clearance elements: the equations the
non-smooth numerics read.

The chain's equations of motion (:mod:`rattle.model._system`) with a friction torque on every
element e, opposing its relative velocity δ_e' = a_e · x', and laws f_e that may jump up at their
breakpoints (a preload: J_ei = f_e(d_i⁺) − f_e(d_i⁻) ≥ 0):

    x'' + C x' + K x + Σ_e b_e [f_e(δ_e) + r_e(δ_e) sgn(δ_e')] = F(t),

r_e(δ) = r_ej ≥ 0 on stage j of the element's law (relative to the element's stiffness K_e, like
its slopes: the hysteresis torque is K_e r_ej; the column b_e carries K_e and the inverse
inertias). sgn(0) is the Filippov set [−1, 1]: an element whose relative velocity reaches zero
may stick, its friction torque then whatever holds δ_e' = 0 within ±K_e r_ej; at a jump the
element may lock, δ_e ≡ d_i, its torque whatever holds it within [f_e(d_i⁻) − r_ei, f_e(d_i⁺) + r_e,i+1]
(:mod:`rattle.timeint._friction_chain`).

A :class:`FrictionSystem` is the smooth :class:`~rattle.model.System` (every analysis of the
continuous chain reads it; an element with jumps carries there its law without the jumps: the same
breakpoints and slopes, continuous) plus one :class:`~rattle.model.NonsmoothLaw` per element (its
whole law, jumps included, and friction levels; the regularised law g_ε of the harmonic balance).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from ._discontinuous import Friction, NonsmoothLaw
from ._system import System


@dataclass(frozen=True, slots=True, eq=False)
class FrictionSystem:
    """``system`` (the smooth equations) with per-element ``laws`` (law and friction levels, one
    :class:`NonsmoothLaw` per element of ``system``, in order); ``speed_order`` the engine order
    of Ω (rpm in results), None without an engine.

    Built by :meth:`rattle.model.Chain.friction_system`; any :class:`System` (the single equation
    included) can be given friction with :meth:`from_system`."""

    system: System
    laws: tuple[NonsmoothLaw, ...]
    speed_order: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.system, System):
            raise TypeError(f"`system` must be a rattle.model.System, got {self.system!r}")
        laws = tuple(self.laws)
        if len(laws) != self.system.m:
            raise ValueError(f"`laws` must hold one law per element ({self.system.m}), got {len(laws)}")
        for e, (law, el) in enumerate(zip(laws, self.system.elements)):
            if not isinstance(law, NonsmoothLaw):
                raise TypeError(f"`laws[{e}]` must be a NonsmoothLaw, got {law!r}")
            st = law.stages
            if not (np.array_equal(st.breakpoints, el.breakpoints) and np.array_equal(st.slopes, el.slopes)):
                raise ValueError(f"`laws[{e}]` must have the stages of element {el.name!r} of the system")
        object.__setattr__(self, "laws", laws)

    @classmethod
    def from_system(cls, system: System, levels: tuple[object, ...], speed_order: float | None = None,
                    elastic: tuple[object, ...] | None = None) -> FrictionSystem:
        """``system`` with friction ``levels`` per element (None, a number, or one per stage) and
        optionally ``elastic`` laws per element (None: the element's own law; a law with jumps,
        :class:`~rattle.model.Preload` or :class:`~rattle.model.PiecewiseJump`, with the element's
        breakpoints and slopes: ``system`` then carries its continuous part)."""
        if len(levels) != system.m:
            raise ValueError(f"`levels` must hold one entry per element ({system.m}), got {len(levels)}")
        if elastic is None:
            elastic = (None,) * system.m
        if len(elastic) != system.m:
            raise ValueError(f"`elastic` must hold one entry per element ({system.m}), got {len(elastic)}")
        laws = tuple(NonsmoothLaw(elastic=el.law if law is None else law,  # type: ignore[arg-type]
                                  friction=None if r is None else Friction(levels=r))  # type: ignore[arg-type]
                     for el, r, law in zip(system.elements, levels, elastic))
        return cls(system=system, laws=laws, speed_order=speed_order)

    # --- sizes and data -------------------------------------------------------------------------
    @property
    def n(self) -> int:
        return self.system.n

    @property
    def m(self) -> int:
        return self.system.m

    @property
    def element_names(self) -> tuple[str, ...]:
        return tuple(e.name for e in self.system.elements)

    def friction_levels(self, e: int) -> FloatArray:
        """r_ej on every stage j of element ``e``."""
        return self.laws[e].friction_levels

    def jumps(self, e: int) -> FloatArray:
        """J_ei ≥ 0 at every breakpoint i of element ``e`` (zeros for a continuous law)."""
        return self.laws[e].stages.jumps

    @property
    def discontinuous(self) -> bool:
        """True: the elements' laws may jump or have friction (the front ends solve the chain
        exactly, or regularised and checked exactly)."""
        return True

    @property
    def has_friction(self) -> bool:
        return any(bool(np.any(law.friction_levels > 0)) for law in self.laws)

    @property
    def has_jumps(self) -> bool:
        """Some element's law jumps (a preload)."""
        return any(bool(np.any(law.stages.jumps > 0)) for law in self.laws)

    # --- scales ---------------------------------------------------------------------------------
    def length_scale(self) -> float:
        """The smooth system's length scale, or the largest deflection of an element's friction and
        jumps, (Σ_i J_ei + max_j r_ej) / min_j s_ej (the widths of its stick and lock bands in
        deflection, as the single equation counts them), when larger."""
        fr = 0.0
        for law in self.laws:
            s = law.stages.slopes
            pos = s[s > 0]
            if pos.size:
                width = float(np.sum(law.stages.jumps)) + float(np.max(law.friction_levels))
                fr = max(fr, width / float(np.min(pos)))
        return max(self.system.length_scale(), fr)

    def frequency_scale(self) -> float:
        """ω_n, the highest natural frequency over the stage combinations (rad/s)."""
        return self.system.stiffest_frequency()

    def speed_rpm(self, omega: object) -> object:
        """Crankshaft speed (rpm) at forcing frequency ``omega``, or None without an engine."""
        if self.speed_order is None:
            return None
        return np.asarray(omega, dtype=float) * (60.0 / (2.0 * np.pi * self.speed_order))


__all__ = ["FrictionSystem"]
