"""Time integration: exact piecewise-linear integration, a general event-located integrator and
periodic orbits by shooting — the numerical methods and their raw solution objects
(:class:`Trajectory`, :class:`SystemTrajectory`, :class:`ShootingOrbit`, :class:`SystemOrbit`).

The steady state of a simulation with period detection is an analysis built on these:
:func:`rattle.analysis.steady_state`, returning a :class:`rattle.results.SteadyState`.
"""

from typing import Any

from ._exact import ExactIntegrator, ExactMeasures, ExactTrajectory, StageSolutions, StateSamples, Trajectory
from ._exact_flow import FlowOptions
from ._flow import SystemMeasures, SystemSamples, SystemTrajectory, check_system_state
from ._general import GeneralSolution, integrate_general
from ._friction_chain import CROSSING, LOCK, STICK, FrictionTrajectory
from ._nonsmooth import NonsmoothTrajectory
from ._shooting_problem import (
    FLOW_FAILURES, ShootingProblem, Shot, built_for, make_integrator, monodromy_multipliers, state_scale,
)
from ._shooting import (
    FrictionOrbit, NonsmoothOrbit, ShootingOrbit, ShotOrbit, SystemOrbit, shoot_friction_orbit, shoot_nonsmooth_orbit,
    shoot_periodic_orbit, shoot_system_orbit,
)

__all__ = [
    "ExactIntegrator", "FlowOptions", "ExactTrajectory", "Trajectory", "StateSamples", "ExactMeasures", "StageSolutions",
    "ShootingOrbit", "shoot_periodic_orbit", "ShootingProblem", "monodromy_multipliers", "FLOW_FAILURES",
    "Shot", "ShotOrbit", "state_scale", "make_integrator", "built_for", "check_system_state",
    "integrate_general", "GeneralSolution",
    "SystemTrajectory", "SystemSamples", "SystemMeasures", "SystemOrbit", "shoot_system_orbit",
    "NonsmoothOrbit", "NonsmoothTrajectory", "shoot_nonsmooth_orbit",
    "FrictionOrbit", "FrictionTrajectory", "shoot_friction_orbit",
    "CROSSING", "LOCK", "STICK",  # the segment kinds of a FrictionTrajectory
]

#: Names that moved out of ``rattle.timeint`` (the steady state is an analysis, its result a
#: result). Still served here, with a DeprecationWarning; imported when asked for, so that
#: nothing here depends on the layers above.
_MOVED: dict[str, str] = {
    "steady_state": "rattle.analysis", "SteadyStateOptions": "rattle.analysis", "SteadyState": "rattle.results",
}


#: The per-system integrator classes folded into the one flow :class:`ExactIntegrator` (issue
#: 23), and their options: still served here, with a DeprecationWarning, as that class (which
#: picks the path by the system) and :class:`FlowOptions`.
_FOLDED = {"SystemIntegrator": "ExactIntegrator", "NonsmoothIntegrator": "ExactIntegrator",
           "FrictionIntegrator": "ExactIntegrator", "NonsmoothOptions": "FlowOptions"}


def __getattr__(name: str) -> Any:
    if name in _FOLDED:
        import warnings

        warnings.warn(f"`rattle.timeint.{name}` is deprecated; use `rattle.timeint.{_FOLDED[name]}` (the one exact "
                      "flow of every system and its options)", DeprecationWarning, stacklevel=2)
        return globals()[_FOLDED[name]]
    if name in _MOVED:
        import importlib
        import warnings

        warnings.warn(f"`rattle.timeint.{name}` is deprecated; import it from {_MOVED[name]}", DeprecationWarning,
                      stacklevel=2)
        return getattr(importlib.import_module(_MOVED[name]), name)
    raise AttributeError(f"module 'rattle.timeint' has no attribute {name!r}")
