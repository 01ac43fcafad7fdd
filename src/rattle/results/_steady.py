"""The steady motion reached by simulation at one forcing frequency: :class:`SteadyState`, as
:func:`rattle.analysis.steady_state` returns it (its period, orbit, measures and multipliers,
and how it ended as a :class:`~rattle.errors.Status`).

A result, not a method: it holds the integrator's raw solution objects (:class:`Trajectory`,
:class:`SystemTrajectory`) and their measures, and knows nothing of how the settling ran.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..errors import Status

if TYPE_CHECKING:  # annotations only: loading the results does not load the integrators
    from ..timeint import ExactMeasures, SystemMeasures, SystemTrajectory, Trajectory

#: How a steady state was reached (``SteadyState.method``), each with its :class:`Status`.
METHODS: dict[str, str] = {
    "shooting": "a stable periodic orbit approached by the simulation, polished by Newton shooting",
    "simulation": "the Poincaré sequence of the plain simulation settled to the tolerance",
    "unsettled": "nothing settled within `max_periods` forcing periods (period 0)",
}

#: ``SteadyState.status`` of each method: Newton shooting converged, the plain simulation
#: settled, or the budget of forcing periods ran out (period 0).
METHOD_STATUS: dict[str, Status] = {
    "shooting": Status.CONVERGED,
    "simulation": Status.SETTLED,
    "unsettled": Status.MAX_PERIODS,
}
_STATUS_METHOD: dict[Status, str] = {s: m for m, s in METHOD_STATUS.items()}


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class SteadyState:
    """The steady motion reached from an initial state at one forcing frequency.

    Attributes
    ----------
    omega : float
        Forcing frequency Ω (rad/s).
    period : int
        Period of the motion as a multiple of the forcing period 2π/Ω (1 … ``max_period_multiple``),
        0 when none was found (quasi-periodic, chaotic or longer).
    status : Status
        How the settling ended: ``CONVERGED`` (a stable orbit the simulation approached, polished
        by Newton shooting), ``SETTLED`` (the plain simulation settled on a period) — both
        complete, ``status.success`` — or ``MAX_PERIODS`` (nothing settled within
        ``max_periods`` forcing periods: period 0). ``settled`` and ``method`` are read from it.
    periods : int
        Forcing periods simulated (settling, checks and, for period 0, the record).
    shooting_periods : int
        Forcing periods integrated inside the Newton shooting solves.
    state0 : ndarray, shape (2,) or (2n,)
        (δ, δ') (rad, rad/s) at the start of ``trajectory``, on the Poincaré section (forcing
        phase 0): for a periodic motion, a point of the orbit. A chain: (x, x') of its n
        coordinates (likewise ``final_state``, ``cycle`` and ``poincare`` rows).
    final_state : ndarray, shape (2,)
        The state on the Poincaré section to carry to the next frequency of a sweep.
    cycle : ndarray, shape (period, 2)
        The orbit's section points x(m·2π/Ω), m = 0 … period − 1 (empty for period 0).
    poincare : ndarray, shape (m, 2)
        The latest Poincaré points of the simulation, oldest first (for period 0, those of the
        recorded window).
    trajectory : Trajectory or SystemTrajectory
        Exact trajectory over one orbit period from ``state0`` (period·2π/Ω), or over the
        ``record_periods`` window for period 0 (time starts at 0).
    measures : ExactMeasures or SystemMeasures
        SPEC §1 measures over ``trajectory`` (a chain: of every element; the flat properties
        ``mean``, ``rms``, … are the first element's, ``element_measures`` all of them).
    multipliers : ndarray, shape (2,) or (2n,), complex, or None
        Floquet multipliers of the orbit (largest modulus first); None for period 0.
    residual : float
        Scaled shooting residual (``shooting``), settling distance d_n (``simulation``) or the
        smallest d_n at the end (``unsettled``).
    element_names : tuple of str
        A chain's clearance elements, in order (empty for the single equation).
    """

    omega: float
    period: int
    status: Status
    periods: int
    shooting_periods: int
    state0: FloatArray
    final_state: FloatArray
    cycle: FloatArray
    poincare: FloatArray
    trajectory: Trajectory | SystemTrajectory
    measures: ExactMeasures | SystemMeasures
    multipliers: ComplexArray | None
    residual: float
    element_names: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.status not in _STATUS_METHOD:
            allowed = ", ".join(s.name for s in _STATUS_METHOD)
            raise ValueError(f"`status` of a SteadyState must be one of {allowed}, got {self.status!r}")

    @property
    def settled(self) -> bool:
        """True when a periodic motion was found (period ≥ 1): ``status.success``."""
        return self.status.success

    @property
    def method(self) -> str:
        """``shooting``, ``simulation`` or ``unsettled`` (see :data:`METHODS`): the ``status``
        in words of the settling."""
        return _STATUS_METHOD[self.status]

    # SPEC §1 measures, flat (a chain: of its first element)
    def _first(self, name: str) -> float:
        from ..timeint import SystemMeasures

        value = getattr(self.measures, name)
        return float(value[0]) if isinstance(self.measures, SystemMeasures) else value

    @property
    def mean(self) -> float:
        return self._first("mean")

    @property
    def rms(self) -> float:
        return self._first("rms")

    @property
    def rms_ac(self) -> float:
        return self._first("rms_ac")

    @property
    def p2p(self) -> float:
        return self._first("p2p")

    @property
    def acc_p2p(self) -> float:
        return self._first("acc_p2p")

    @property
    def delta_min(self) -> float:
        return self._first("delta_min")

    @property
    def delta_max(self) -> float:
        return self._first("delta_max")

    @property
    def element_measures(self) -> SystemMeasures:
        """The measures of every clearance element (a chain's, in the order of
        ``element_names``; for the single equation one element, δ, named ``delta``)."""
        from ..timeint import SystemMeasures

        m = self.measures
        if isinstance(m, SystemMeasures):
            return m
        return SystemMeasures(names=self.element_names or ("delta",), **{
            k: np.array([getattr(m, k)]) for k in
            ("mean", "rms", "rms_ac", "delta_min", "delta_max", "p2p", "acc_min", "acc_max", "acc_p2p")})

    def element(self, which: int | str) -> dict[str, float]:
        """The measures of one element (index or name) as a dict of floats."""
        return self.element_measures.element(which)

    @property
    def stable(self) -> bool | None:
        """True when every Floquet multiplier is inside the unit circle; None for period 0."""
        if self.multipliers is None:
            return None
        return bool(np.all(np.abs(self.multipliers) < 1.0))

    def regimes(self) -> tuple[str, ...]:
        """``no_impact``, ``single_sided`` or ``double_sided`` (SPEC §1) of every element over
        ``trajectory``."""
        from ..timeint import FrictionTrajectory, NonsmoothTrajectory, SystemTrajectory

        traj = self.trajectory
        if isinstance(traj, SystemTrajectory):
            m = traj.system.m
            return tuple(_regime_of(traj.crossing_breakpoints[traj.crossing_elements == e]) for e in range(m))
        if isinstance(traj, FrictionTrajectory):  # a jump at δ = 0 is on neither side (as for one orbit)
            return tuple(_regime_of(traj.crossed_breakpoints(e), zero_on_either_side=True)
                         for e in range(traj.system.m))
        return (_regime_of(traj.crossed_breakpoints, zero_on_either_side=isinstance(traj, NonsmoothTrajectory)),)

    @property
    def regime(self) -> str:
        """``no_impact``, ``single_sided`` or ``double_sided`` (SPEC §1) over ``trajectory`` (a
        chain: of its first element)."""
        return self.regimes()[0]

    def __repr__(self) -> str:
        return (
            f"SteadyState(Ω = {self.omega:.6g}, period {self.period}, {self.method}, "
            f"rms {self.rms:.6g}, {self.periods} periods simulated + {self.shooting_periods} shooting)"
        )


def _regime_of(crossed: FloatArray, zero_on_either_side: bool = False) -> str:
    """The regime from the breakpoints crossed; ``zero_on_either_side``: a breakpoint at δ = 0 (a
    discontinuous law's jump) counts with either side, so crossing only it is ``single_sided``."""
    if crossed.size == 0:
        return "no_impact"
    if zero_on_either_side:
        one_side = bool(np.all(crossed >= 0.0) or np.all(crossed <= 0.0))
    else:
        one_side = bool(np.all(crossed > 0.0) or np.all(crossed < 0.0))
    return "single_sided" if one_side else "double_sided"


__all__ = ["SteadyState", "METHODS", "METHOD_STATUS"]
