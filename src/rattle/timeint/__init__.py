"""Time integration: exact piecewise-linear integration, a general event-located integrator,
periodic orbits by shooting and the steady state of a simulation with period detection."""

from ._exact import ExactIntegrator, ExactMeasures, StageSolutions, StateSamples, Trajectory
from ._general import GeneralSolution, integrate_general
from ._shooting import ShootingOrbit, shoot_periodic_orbit
from ._steady import SteadyState, SteadyStateOptions, steady_state

__all__ = [
    "ExactIntegrator", "Trajectory", "StateSamples", "ExactMeasures", "StageSolutions",
    "ShootingOrbit", "shoot_periodic_orbit",
    "integrate_general", "GeneralSolution",
    "SteadyStateOptions", "SteadyState", "steady_state",
]
