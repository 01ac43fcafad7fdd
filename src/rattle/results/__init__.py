"""Result objects."""

from ._frequency_response import (
    FRF_COLUMNS, FrequencyResponse, LinearResponse, SpecialPoint, linear_frequency_response,
)

__all__ = ["FrequencyResponse", "SpecialPoint", "LinearResponse", "linear_frequency_response", "FRF_COLUMNS"]

from ._sweep import SweepResult  # noqa: E402  (time-domain sweep)
__all__ += ["SweepResult"]

from ._orbit import OrbitSolution, PeriodicOrbit  # noqa: E402  (periodic orbits at one frequency)
__all__ += ["PeriodicOrbit", "OrbitSolution"]
