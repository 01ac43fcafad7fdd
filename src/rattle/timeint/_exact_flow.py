"""The one exact flow of every rattle system: :class:`ExactIntegrator` and its options.

Every equation of motion rattle integrates is, between events, linear with constant
coefficients, z' = A_s z + g_s(t), so the flow from (t_0, z_0) is written in closed form,
z(t) = p_s(t) + exp(A_s (t − t_0)) (z_0 − p_s(t_0)); the only numerical steps are locating the
events (an element's deflection reaching a breakpoint; with friction a velocity zero or a held
torque leaving its band) to round-off, and the sensitivity ∂z(t1)/∂z(t0) is the product of the
transition matrices exp(A_s τ) and, where the field jumps, the saltation matrices
S = I + (φ⁺ − φ⁻) nᵀ / (nᵀ φ⁻).

``ExactIntegrator(system)`` takes any system and picks the path that computes this flow fastest
(the class it returns is a private subclass, so ``isinstance(integ, ExactIntegrator)`` holds). Every
path declares the systems it takes by a predicate on the system's properties (``takes``), not by
its class; a :class:`~rattle.model.Chain` is first reduced to its
:class:`~rattle.model.System` (:meth:`~rattle.model.Chain.friction_system` when it is
discontinuous):

==========================================  ====================================================
system (predicate)                          path (module)
==========================================  ====================================================
a :class:`~rattle.model.Model`              the compiled scalar path: one coordinate, one
(:func:`takes_model`)                       element, modal closed form (:mod:`._integrator`)
the single equation's                       the same scalar path with the Filippov events:
:class:`~rattle.model.System` (n = m = 1,   jumps, stick, slip, lock (:mod:`._nonsmooth`)
``is_single_equation``;
:func:`takes_single_equation`)
a :class:`~rattle.model.System`, not        the stage-matrix path: n coordinates, m elements,
``discontinuous`` (:func:`takes_continuous`)  continuous laws (:mod:`._flow`)
a :class:`~rattle.model.System`,            the stage-matrix path with the Filippov events and
``discontinuous``, not the single          the active-set choice of the held elements
equation's (:func:`takes_discontinuous`)
                                            (:mod:`._friction_chain`)
==========================================  ====================================================

All answer ``advance(z0, t0, t1, Ω, sensitivity)`` → (z1, ∂z1/∂z0) (the period map of a
shooting, no record) and ``propagate(z0, t0, t1, Ω)`` → an
:class:`~rattle.timeint.ExactTrajectory` (``states(t)``, ``measures()``); ``system`` is the
system the flow was built for (:func:`~rattle.timeint.built_for`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from ..model import Chain, Model, System


@dataclass(frozen=True, slots=True, kw_only=True)
class FlowOptions:
    """Settings of the exact flow.

    ``samples_per_scale`` grid points per fastest time scale to bracket events (≥ 8);
    ``max_events`` the budget of events (segments) of one integration, exceeded:
    ``ConvergenceError`` (None: 1 000 000 on a continuous law, whose only events are crossings;
    200 000 with jumps or friction, where a chatter must be stopped sooner);
    ``lock_excursion`` the excursion beyond a jump (relative to the system's length scale L)
    below which a crossing of a jump whose lock band holds the torque snaps into the lock: the
    chatter around a lock is followed crossing by crossing until its excursions δ'²/(2|a|) reach
    this (default 1e-13, a few hundred ulps: round-off level); 0 never snaps (the chatter is then
    followed to ``max_events``). Continuous laws have no locks and ignore it."""

    samples_per_scale: int = 40
    max_events: int | None = None
    lock_excursion: float = 1e-13

    def __post_init__(self) -> None:
        for name, value, low in (("samples_per_scale", self.samples_per_scale, 8), ("max_events", self.max_events, 1)):
            if value is None and name == "max_events":
                continue
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                raise TypeError(f"`{name}` must be an integer, got {value!r}")
            if value < low:
                raise ValueError(f"`{name}` must be >= {low}, got {value!r}")
        lv = self.lock_excursion
        if isinstance(lv, bool) or not isinstance(lv, (int, float)) or not (math.isfinite(lv) and 0.0 <= lv < 1.0):
            raise ValueError(f"`lock_excursion` must be a number in [0, 1) (relative to the length scale), got {lv!r}")

    def budget(self, events: bool) -> int:
        """``max_events``, or its default for a flow with (``events``) or without jumps/friction."""
        if self.max_events is not None:
            return int(self.max_events)
        return 200_000 if events else 1_000_000


def takes_model(system: Any) -> bool:
    """The compiled scalar path's systems: a :class:`~rattle.model.Model` (continuous law)."""
    return isinstance(system, Model)


def takes_single_equation(system: Any) -> bool:
    """The scalar event path's systems: the single equation with its whole law, a
    :class:`~rattle.model.System` with n = m = 1 in the single-equation form
    (:attr:`~rattle.model.System.is_single_equation`: :meth:`~rattle.model.System.single`)."""
    return isinstance(system, System) and system.is_single_equation


def takes_continuous(system: Any) -> bool:
    """The stage-matrix path's systems: a :class:`~rattle.model.System` with continuous laws."""
    return isinstance(system, System) and not system.discontinuous


def takes_discontinuous(system: Any) -> bool:
    """The Filippov chain path's systems: a :class:`~rattle.model.System` carrying its elements'
    whole laws (``discontinuous``: jumps and friction), but the single equation's."""
    return isinstance(system, System) and system.discontinuous and not system.is_single_equation


def _reduced(system: Any) -> Any:
    """A :class:`~rattle.model.Chain`'s reduced form: its System with the whole laws
    (:meth:`~rattle.model.Chain.friction_system`) when it has friction or a torque jump on an
    element, else its System; any other object as it is."""
    if isinstance(system, Chain):
        return system.friction_system() if system.discontinuous else system.system()
    return system


class ExactIntegrator:
    """The exact flow of ``system`` (module docstring): a :class:`~rattle.model.Model`,
    :class:`~rattle.model.Chain` or :class:`~rattle.model.System` (continuous laws, or carrying its
    elements' whole laws; the single equation's included).

    Parameters
    ----------
    system
        The equations of motion (a Chain: its System, with the elements' whole laws when an
        element has friction or a torque jump).
    options
        :class:`FlowOptions` (the event grid, the event budget, the lock snap).

    Attributes
    ----------
    system
        The system the flow was built for.
    options
        The :class:`FlowOptions`.
    """

    #: Each path's predicate on the systems it takes, and the path (filled by the paths).
    _PATHS: ClassVar[list[tuple[Callable[[Any], bool], type]]] = []
    #: The predicate of the systems this path takes (set on the path's class) and their name.
    _takes: ClassVar[Callable[[Any], bool] | None] = None
    _kind: ClassVar[str] = "rattle system"

    system: Any
    options: FlowOptions

    def __init_subclass__(cls, /, takes: Callable[[Any], bool] | None = None, kind: str = "", **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if takes is not None:
            cls._takes = staticmethod(takes)  # type: ignore[assignment]
            cls._kind = kind
            ExactIntegrator._PATHS.append((takes, cls))

    def __new__(cls, system: Any = None, options: FlowOptions | None = None) -> ExactIntegrator:
        if cls is not ExactIntegrator:  # a path itself (or unpickling one: no arguments)
            return super().__new__(cls)
        system = _reduced(system)
        for takes, path in ExactIntegrator._PATHS:
            if takes(system):
                return super().__new__(path)
        raise TypeError(f"`system` must be a rattle Model, Chain or System, got {system!r}")

    def __init__(self, system: Any, options: FlowOptions | None = None) -> None:
        system = _reduced(system)
        if self._takes is None or not self._takes(system):
            raise TypeError(f"`system` must be {self._kind}, got {system!r}")
        if options is not None and not isinstance(options, FlowOptions):
            raise TypeError(f"`options` must be a FlowOptions (or None), got {options!r}")
        self.system = system
        self.options = FlowOptions() if options is None else options
        self.samples_per_scale = int(self.options.samples_per_scale)

    def built_for(self, system: Any) -> bool:
        """True when this flow was built for ``system`` (the same object, or an equal one)."""
        return self._takes is not None and self._takes(system) and (self.system is system or bool(self.system == system))

    def advance(self, z0: Any, t0: float, t1: float, omega: float,
                sensitivity: bool = True) -> tuple[Any, Any]:  # pragma: no cover - every path defines it
        """The state at ``t1`` and ∂z(t1)/∂z(t0) (None when ``sensitivity`` is False, where the
        path can skip it) from ``z0`` at ``t0``: no record kept, no checks."""
        raise NotImplementedError

    def propagate(self, z0: Any, t0: float, t1: float, omega: float) -> Any:  # pragma: no cover
        """The exact trajectory from ``z0`` at ``t0`` to ``t1`` ≥ t0 at forcing frequency ``omega``."""
        raise NotImplementedError


__all__ = ["ExactIntegrator", "FlowOptions", "takes_model", "takes_single_equation", "takes_continuous",
           "takes_discontinuous"]
