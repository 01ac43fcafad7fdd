"""Result objects: columnar, with .plot() and .to_csv() delegating to plotting and io."""

from ._frequency_response import (
    FRF_COLUMNS, FrequencyResponse, LinearResponse, Region, SpecialPoint, linear_frequency_response,
)
from ._orbit import OrbitSolution, PeriodicOrbit
from ._sweep import SweepResult

__all__ = [
    "FrequencyResponse", "SpecialPoint", "Region", "LinearResponse", "linear_frequency_response", "FRF_COLUMNS",
    "SweepResult", "PeriodicOrbit", "OrbitSolution",
]
