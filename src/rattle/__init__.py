"""rattle — non-linear frequency response of drivetrain rattle.

Harmonic balance (alternating frequency–time, analytic Jacobians), pseudo-arclength
continuation in the forcing frequency with self-adjusting steps, Floquet stability and
bifurcation labels for torsional sub-systems with clearance non-linearities:

    δ'' + (C/I) δ' + (K/I) f(δ) = F_m + Σ_n F_pn cos(n Ω t + φ_n).

>>> import rattle
>>> model = rattle.reference_case()
>>> frf = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from .analysis import Comparison, compare, frequency_response, periodic_orbit, time_sweep
from .continuation import ContinuationOptions
from .errors import ConfigError, ConvergenceError, RattleError, Status
from .hb import HBOptions, NewtonOptions
from .model import Backlash, Clutch, Excitation, Linear, Model, Piecewise, backlash_case, reference_case
from .results import (
    FrequencyResponse, LinearResponse, PeriodicOrbit, Region, SpecialPoint, SweepResult, linear_frequency_response,
)
from .timeint import SteadyStateOptions, shoot_periodic_orbit, steady_state

try:
    __version__ = version("rattle")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.1.0"

__all__ = [
    "__version__",
    "Model", "Excitation", "Linear", "Backlash", "Clutch", "Piecewise", "reference_case", "backlash_case",
    "frequency_response", "FrequencyResponse", "SpecialPoint", "Region", "LinearResponse", "linear_frequency_response",
    "time_sweep", "SweepResult", "steady_state", "SteadyStateOptions", "shoot_periodic_orbit",
    "periodic_orbit", "PeriodicOrbit", "compare", "Comparison",
    "HBOptions", "NewtonOptions", "ContinuationOptions",
    "Status", "RattleError", "ConfigError", "ConvergenceError",
]
