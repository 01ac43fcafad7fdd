"""Time integration: exact piecewise-linear integration, a general event-located integrator,
periodic orbits by shooting and the steady state of a simulation with period detection."""

from ._exact import ExactIntegrator, ExactMeasures, StageSolutions, StateSamples, Trajectory
from ._flow import SystemIntegrator, SystemMeasures, SystemSamples, SystemTrajectory
from ._general import GeneralSolution, integrate_general
from ._shooting import ShootingOrbit, shoot_periodic_orbit
from ._shooting_problem import ShootingProblem
from ._steady import SteadyState, SteadyStateOptions, steady_state
from ._system_shooting import SystemOrbit, shoot_system_orbit

__all__ = [
    "ExactIntegrator", "Trajectory", "StateSamples", "ExactMeasures", "StageSolutions",
    "ShootingOrbit", "shoot_periodic_orbit", "ShootingProblem",
    "integrate_general", "GeneralSolution",
    "SteadyStateOptions", "SteadyState", "steady_state",
    "SystemIntegrator", "SystemTrajectory", "SystemSamples", "SystemMeasures", "SystemOrbit", "shoot_system_orbit",
]
