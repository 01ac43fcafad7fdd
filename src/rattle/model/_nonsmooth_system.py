"""The single equation with a discontinuous law, per unit inertia: a preload or Coulomb friction.

    δ'' + c δ' + k g(δ, δ') = F(t) = F_m + Σ_n F_pn cos(n Ω t + φ_n),
    g(δ, δ') = f(δ) + r(δ) sgn(δ'),

c = C/I, k = K/I and g relative to K: the law (:class:`~rattle.model.NonsmoothLaw`, with its jumps
and friction levels, :mod:`._discontinuous`) the exact integrator reads
(:mod:`rattle.timeint._nonsmooth`). :meth:`NonsmoothSystem.from_model` gives a
:class:`~rattle.model.Model`'s c, k and excitation a discontinuous law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from ._discontinuous import AbstractJumpLaw, Friction, NonsmoothLaw
from ._elastic import AbstractElastic, _check_real
from ._excitation import Excitation
from ._model import Model


@dataclass(frozen=True, slots=True, kw_only=True)
class NonsmoothSystem:
    """δ'' + c δ' + k g(δ, δ') = F(t), per unit inertia: ``damping`` c = C/I ≥ 0 (1/s),
    ``stiffness`` k = K/I > 0 (1/s²), ``law`` g (:class:`NonsmoothLaw`) and ``excitation`` F."""

    damping: float
    stiffness: float
    law: NonsmoothLaw
    excitation: Excitation

    def __post_init__(self) -> None:
        c = _check_real("damping", self.damping)
        k = _check_real("stiffness", self.stiffness)
        if c < 0:
            raise ValueError(f"`damping` (c = C/I) must be >= 0, got {c!r}")
        if k <= 0:
            raise ValueError(f"`stiffness` (k = K/I) must be > 0, got {k!r}")
        if not isinstance(self.law, NonsmoothLaw):
            raise TypeError(f"`law` must be a NonsmoothLaw, got {self.law!r}")
        if not isinstance(self.excitation, Excitation):
            raise TypeError(f"`excitation` must be an Excitation, got {self.excitation!r}")
        object.__setattr__(self, "damping", c)
        object.__setattr__(self, "stiffness", k)

    @classmethod
    def from_model(cls, model: Model, *, elastic: AbstractElastic | AbstractJumpLaw | None = None,
                   friction: Friction | None = None) -> NonsmoothSystem:
        """The model's c, k and excitation with its law (or ``elastic``) and ``friction``."""
        if not isinstance(model, Model):
            raise TypeError(f"`model` must be a rattle Model, got {model!r}")
        law = NonsmoothLaw(elastic=model.elastic if elastic is None else elastic, friction=friction)
        return cls(damping=model.c, stiffness=model.k, law=law, excitation=model.excitation)

    @property
    def discontinuous(self) -> bool:
        """True: the law jumps or has friction (the front ends solve it exactly, or regularised and
        checked exactly)."""
        return True

    # The equation's coefficients under the names the exact integrator's stage solutions read.
    @property
    def c(self) -> float:
        return self.damping

    @property
    def k(self) -> float:
        return self.stiffness

    def length_scale(self) -> float:
        """A characteristic angle L (rad): breakpoints, the jumps' and friction's deflections and
        the quasi-static dynamic amplitude, whichever is largest."""
        st = self.law.stages
        s_pos = st.slopes[st.slopes > 0]
        exc = self.excitation
        dyn = (abs(exc.mean) + exc.amplitude_scale) / (self.k * float(np.min(s_pos)))
        bp = float(np.max(np.abs(st.breakpoints))) if st.breakpoints.size else 0.0
        jump = float(np.sum(st.jumps) + np.max(self.law.friction_levels)) / float(np.min(s_pos))
        return max(bp, dyn, jump, 1e-300)

    def regularised(self, delta: FloatArray, velocity: FloatArray, width: float,
                    velocity_width: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """k g_ε and its partials (per unit inertia): the ``RegularisedForce`` of
        :mod:`rattle.hb._regularised`."""
        g, gd, gv = self.law.regularised(delta, velocity, width, velocity_width)
        return self.k * g, self.k * gd, self.k * gv


__all__ = ["NonsmoothSystem"]
