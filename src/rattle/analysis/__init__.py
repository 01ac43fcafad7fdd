"""Front ends: one call from a model to a result."""

from ._attractors import AttractorSearch, Census
from ._case import Case, case_arguments, load_case, method_options, regularisation_options
from ._census import CellCensus, attractor_census
from ._exact_search import special_points
from ._compare import compare
from ._frequency_response import assemble, frequency_response, start_solution
from ._friction_orbit import friction_orbit
from ._exact_branch import ShootingOptions
from ._nonsmooth import RegularisationOptions
from ._nonsmooth_orbit import nonsmooth_orbit
from ._harmonics import truncation_error
from ._stretches import AdaptiveHarmonics
from ._sweep_check import SweepCheck
from ._orbit import periodic_orbit
from ._regimes import confirm_with_sweep, label_regions
from ._settings import DEFAULT_HARMONICS, RunSettings, StabilityMethod, resolve_hb
from ._steady import SteadyStateOptions, steady_state
from ._time_sweep import time_sweep

__all__ = [
    "load_case", "Case", "frequency_response", "start_solution", "assemble", "time_sweep", "periodic_orbit", "compare",
    "steady_state", "SteadyStateOptions", "RegularisationOptions",
    "nonsmooth_orbit", "friction_orbit",
    "label_regions", "confirm_with_sweep", "truncation_error", "AdaptiveHarmonics",
    "SweepCheck", "ShootingOptions", "method_options", "regularisation_options", "case_arguments",
    # one combination of a response map (rattle.maps): every branch on its grid, every attractor
    "AttractorSearch", "Census", "CellCensus", "attractor_census", "special_points",
    "RunSettings", "DEFAULT_HARMONICS", "StabilityMethod", "resolve_hb",
]
