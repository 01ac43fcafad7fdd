"""Stability of periodic solutions: exact monodromy along the HB orbit, Hill's method, labels."""

from ._classify import COMPLEX_TOL, UNIT_CIRCLE_TOL, classify_loss, critical_distance, is_stable, torus_ratio
from ._floquet import (
    TEST_FUNCTIONS, crossing_times, crossing_times_batch, element_monodromy_batch, floquet_test_functions, monodromy,
    monodromy_and_crossings_batch, monodromy_batch, multipliers_from_monodromy, neimark_sacker_function, second_compound,
    stage_transition, system_monodromy_batch,
)
from ._hill import hill_exponents, hill_multipliers
from ._methods import STABILITY_METHODS, AbstractStabilityMethod, Hill, Monodromy, floquet_monitor, stability_method
from ._monitor import FloquetMonitor, hb_system
from ._regularised import (
    regularised_monodromy,
    regularised_multipliers,
    regularised_system_monodromy,
    regularised_system_multipliers,
)

__all__ = [
    "stage_transition", "crossing_times", "crossing_times_batch", "monodromy", "monodromy_batch",
    "monodromy_and_crossings_batch", "element_monodromy_batch", "system_monodromy_batch",
    "multipliers_from_monodromy", "second_compound", "floquet_test_functions", "neimark_sacker_function", "TEST_FUNCTIONS",
    "hill_exponents", "hill_multipliers", "FloquetMonitor", "hb_system",
    "AbstractStabilityMethod", "Monodromy", "Hill", "STABILITY_METHODS", "stability_method", "floquet_monitor",
    "is_stable", "classify_loss", "torus_ratio", "critical_distance", "UNIT_CIRCLE_TOL", "COMPLEX_TOL",
    "regularised_monodromy", "regularised_multipliers", "regularised_system_monodromy", "regularised_system_multipliers",
]
