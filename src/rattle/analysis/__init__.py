"""Front ends: one call from a model to a result."""

from ._frequency_response import assemble, frequency_response, start_solution

__all__ = ["frequency_response", "start_solution", "assemble"]

from ._time_sweep import time_sweep  # noqa: E402  (time-domain sweep)
__all__ += ["time_sweep"]

from ._orbit import periodic_orbit  # noqa: E402  (periodic orbits at one frequency)
from ._compare import Comparison, compare  # noqa: E402  (FRF vs time-domain sweep)
__all__ += ["periodic_orbit", "compare", "Comparison"]
