"""Time integration: exact piecewise-linear integration and periodic orbits by shooting."""

from ._exact import ExactIntegrator, ExactMeasures, StageSolutions, StateSamples, Trajectory
from ._shooting import ShootingOrbit, shoot_periodic_orbit

__all__ = [
    "ExactIntegrator", "Trajectory", "StateSamples", "ExactMeasures", "StageSolutions",
    "ShootingOrbit", "shoot_periodic_orbit",
]
