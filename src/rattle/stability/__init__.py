"""Stability of periodic solutions: exact monodromy along the HB orbit, Hill's method, labels."""

from ._classify import UNIT_CIRCLE_TOL, classify_loss, is_stable
from ._floquet import (
    crossing_times, crossing_times_batch, monodromy, monodromy_and_crossings_batch, monodromy_batch,
    multipliers_from_monodromy,
    stage_transition,
)
from ._hill import hill_exponents, hill_multipliers
from ._monitor import FloquetMonitor

__all__ = [
    "stage_transition", "crossing_times", "crossing_times_batch", "monodromy", "monodromy_batch", "monodromy_and_crossings_batch", "multipliers_from_monodromy",
    "hill_exponents", "hill_multipliers", "FloquetMonitor", "is_stable", "classify_loss", "UNIT_CIRCLE_TOL",
]
