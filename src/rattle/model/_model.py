"""The sub-system model: one equation in the relative angle δ = θ1 − θ2.

    δ'' + (C/I) δ' + (K/I) f(δ) = F_m + Σ_n F_pn cos(n Ω t + φ_n)

with I the effective inertia I1 I2 / (I1 + I2), C the viscous damping, K the stiffness of the
unit-slope stage and f the elastic law (see ``_elastic``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._limits import check_scales, quasi_static_deflection
from ._elastic import AbstractElastic, _check_real
from ._excitation import Excitation
from ._readers import read_tables
from ._system import System, single_equation_system


@dataclass(frozen=True, slots=True, kw_only=True)
class Model:
    """Frozen, validated model: ``inertia`` I > 0, ``damping`` C ≥ 0, ``stiffness`` K > 0,
    ``elastic`` law and ``excitation``.

    Every number is finite with magnitude ≤ 1e50, and so are the derived scales K/I, C/I, the
    force scale |F_m| + Σ|F_pn| and the deflection scale (products of a few of them must stay
    finite in double precision; see :mod:`rattle._limits`). ``damping`` = 0 is a valid model
    (its motion can be integrated exactly) but the analyses refuse it: an undamped forced system
    has no asymptotically stable periodic orbit (see
    :func:`~rattle.model.check_analysable_model`).
    """

    inertia: float
    damping: float
    stiffness: float
    elastic: AbstractElastic
    excitation: Excitation

    def __post_init__(self) -> None:
        inertia = _check_real("inertia", self.inertia)
        damping = _check_real("damping", self.damping)
        stiffness = _check_real("stiffness", self.stiffness)
        if inertia <= 0:
            raise ValueError(f"`inertia` must be > 0, got {inertia!r}")
        if damping < 0:
            raise ValueError(f"`damping` must be >= 0, got {damping!r}")
        if stiffness <= 0:
            raise ValueError(f"`stiffness` must be > 0, got {stiffness!r}")
        if not isinstance(self.elastic, AbstractElastic):
            raise TypeError(f"`elastic` must be an elastic law (Linear, Backlash, Clutch, Piecewise, Unilateral), got {self.elastic!r}")
        if not isinstance(self.excitation, Excitation):
            raise TypeError(f"`excitation` must be an Excitation, got {self.excitation!r}")
        object.__setattr__(self, "inertia", inertia)
        object.__setattr__(self, "damping", damping)
        object.__setattr__(self, "stiffness", stiffness)
        self.static_equilibrium()  # a one-sided stop the mean load does not hold: refused here
        # k = K/I, c = C/I, the force and deflection scales within 1e-50 … 1e50 (rattle._limits):
        # products of a few of them (an acceleration squared) must stay finite in double precision.
        check_scales(self)

    # --- coefficients of the equation -------------------------------------------------------
    @property
    def c(self) -> float:
        """Damping coefficient per inertia C/I (1/s)."""
        return self.damping / self.inertia

    @property
    def k(self) -> float:
        """Stiffness per inertia K/I (1/s²) of the unit-slope stage."""
        return self.stiffness / self.inertia

    @property
    def natural_frequency(self) -> float:
        """ω_n = sqrt(K/I) (rad/s) of the unit-slope stage."""
        return math.sqrt(self.k)

    @property
    def zeta(self) -> float:
        """Damping ratio ζ = C / (2 sqrt(K I))."""
        return self.damping / (2.0 * math.sqrt(self.stiffness * self.inertia))

    def restoring(self, delta: np.ndarray) -> np.ndarray:
        """(K/I) f(δ), elementwise."""
        return self.k * self.elastic.force(delta)

    def static_equilibrium(self) -> float:
        """δ_s solving (K/I) f(δ_s) = F_m (unique on a stage with positive slope).

        When F_m balances a zero-slope stage exactly (a backlash with F_m = 0), the middle of
        that stage is returned. A law with an outer slope 0 (a one-sided stop, unilateral
        contact) has no isolated equilibrium when F_m does not hold the element against the stop:
        F_m pushing away from it (none at all), or F_m = the law's force on the free side (every
        δ there is one: the mean of the motion is not determined). Both raise ValueError.
        """
        st = self.elastic.stages
        target = self.excitation.mean / self.k
        edges = np.concatenate(([-np.inf], st.breakpoints, [np.inf]))
        free_side = ""
        for j, (s, e) in enumerate(zip(st.slopes, st.offsets)):
            lo, hi = edges[j], edges[j + 1]
            if s > 0:
                with np.errstate(over="ignore"):  # a nearly flat stage (α = 5e-324): x = ±inf, not on it
                    x = (target - e) / s
                if lo <= x <= hi:
                    return float(x)
            elif abs(target - e) <= 1e-15 * max(1.0, abs(target)):
                if np.isfinite(lo + hi):
                    return float(0.5 * (lo + hi))
                free_side = "below" if np.isinf(lo) else "above"
                break
        stop = [f"δ {'>' if st.slopes[0] == 0 else '<'} {st.breakpoints[0 if st.slopes[0] == 0 else -1]:g}"
                ] if st.breakpoints.size else []
        if free_side:
            raise ValueError(
                f"`excitation.mean` = {self.excitation.mean:g}: the law is flat (slope 0) for every δ {free_side} "
                f"{(lo if free_side == 'above' else hi):g} rad and the mean load is zero there, so nothing holds the "
                "element against its one-sided stop: every δ on the free side is a static equilibrium and the mean of "
                "the motion is not determined; give a mean load toward the stop"
                + (f" ({stop[0]})" if stop else "")
            )
        raise ValueError(
            f"`excitation.mean` = {self.excitation.mean:g}: no static equilibrium — the law's force never balances "
            "the mean load (it pushes the element away from its one-sided stop, where the law is flat), so the "
            "element drifts without end; reverse the mean load, or put the stop on the other side (`side`)"
        )

    def length_scale(self) -> float:
        """A characteristic angle L (rad) for scaling: the static deflection, the breakpoints and
        the quasi-static dynamic amplitude, whichever is largest.

        The quasi-static amplitude of the forcing amplitude F_a on the law is F_a / (k s_min), s_min
        the softest positive slope, unless it exceeds ten times the bound

            A = w + F_a / (k s_out),

        s_out the softer positive slope of the two outer stages and w the width of the inner stages
        (the span of the breakpoints; ``_limits.quasi_static_deflection``): an inner stage holds no
        more than its width, however soft. The bound keeps L the size of the motion when an inner
        stage is nearly flat (a clutch of α = 1e-9 would otherwise give L = F_a / (k α), 10⁹ times
        the orbit, and the continuation's scaled tolerances would see no orbit at all).
        """
        st = self.elastic.stages
        dyn = quasi_static_deflection(st.slopes, st.breakpoints, self.excitation.amplitude_scale, self.k)
        bp = float(np.max(np.abs(st.breakpoints))) if st.breakpoints.size else 0.0
        return max(abs(self.static_equilibrium()), bp, dyn, 1e-300)

    def force_scale(self) -> float:
        """A characteristic force per inertia for residual scaling: |F_m| + Σ |F_pn|."""
        return max(abs(self.excitation.mean) + self.excitation.amplitude_scale, 1e-300)

    @property
    def discontinuous(self) -> bool:
        """False: a Model's law is continuous (a law with jumps or friction makes the single
        equation's :class:`~rattle.model.System`, :meth:`~rattle.model.System.from_model`); the
        front ends choose their method by this."""
        return False

    def system(self) -> System:
        """The equations of motion as the numerics see them: the n = m = 1
        :class:`~rattle.model.System` with C = [[C/I]], K = [[0]], a = [1], b = [K/I]."""
        exc = self.excitation
        return single_equation_system(self.c, self.k, self.elastic, exc.mean, exc.amplitudes, exc.phases or ())

    # --- I/O delegates --------------------------------------------------------------------
    @classmethod
    def from_toml(cls, path: str | Path) -> Model:
        """Read the ``[model]`` and ``[excitation]`` tables of a SPEC §2 TOML file.

        A file whose law has a preload or friction describes the single equation's
        :class:`~rattle.model.System` with its whole law, not a Model: ConfigError, pointing to
        ``rattle.load_case(path).model``.

        The model tables are read as :func:`rattle.io.load_config` reads them (the same rules and
        messages); ``[analysis]`` and ``[[paths]]`` are the run's and left alone."""
        from ..errors import ConfigError

        tables = read_tables(path)
        if tables.chain is not None:  # a chain with friction on its elements: the Chain itself
            return tables.chain  # type: ignore[return-value]
        if tables.discontinuous:
            raise ConfigError(f"{path}: the law has a preload or friction (`model.elastic.preload`/`friction`), "
                              f"which makes the single equation's System with its whole law, not a Model: read it with "
                              f"`rattle.load_case({str(path)!r}).model`")
        return tables.model

    def to_dict(self) -> dict[str, object]:
        return {
            "inertia": self.inertia,
            "damping": self.damping,
            "stiffness": self.stiffness,
            "elastic": self.elastic.to_dict(),
            "excitation": self.excitation.to_dict(),
        }


__all__ = ["Model"]
