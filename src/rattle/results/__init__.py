"""Result objects: columnar data with their columns (SPEC §3) and provenance.

Results hold data only: ``.to_csv()`` and ``.plot()`` are thin delegates that import
:mod:`rattle.io` and :mod:`rattle.plotting` inside the method, when called; nothing here imports
them when loaded.
"""

from ._columns import FRF_COLUMNS, ORBIT_COLUMNS, SWEEP_COLUMNS
from ._comparison import Comparison
from ._check import held_runs
from ._friction import FRICTION_ELEMENT_COLUMNS, FRICTION_TAIL_COLUMNS, FrictionCheck
from ._friction_orbit import FRICTION_ORBIT_ELEMENT_COLUMNS, FrictionOrbitResult, HeldLimitRecord
from ._frequency_response import element_columns_from, FrequencyResponse, LinearResponse, Region, SpecialPoint, linear_frequency_response
from ._measured import MEASURED_QUANTITIES, MeasuredComparison, MeasuredRun, compare_measured
from ._nonsmooth import NONSMOOTH_COLUMNS, NonsmoothCheck
from ._nonsmooth_orbit import NONSMOOTH_ORBIT_COLUMNS, NonsmoothOrbitResult
from ._orbit import OrbitSolution, PeriodicOrbit
from ._sound import (
    UNCOVERED_WARNING, SoundPressure, a_weighting_db, check_sound_paths, coefficient_sound_pressure,
    linear_sound_pressure, motion_sound_pressure, sound_pressure,
)
from ._plotter import plot_with
from ._speed import SpeedText, round_to_grid, rpm_of_omega
from ._steady import METHODS as STEADY_METHODS, SteadyState
from ._sweep import FAILED_PERIOD, SWEEP_ELEMENT_COLUMNS, SWEEP_FAILED, SweepResult

__all__ = [
    "FrequencyResponse", "element_columns_from", "SpecialPoint", "Region", "LinearResponse", "linear_frequency_response",
    "SweepResult", "FAILED_PERIOD", "SWEEP_FAILED", "SWEEP_ELEMENT_COLUMNS", "SteadyState", "STEADY_METHODS", "PeriodicOrbit", "OrbitSolution", "Comparison",
    "FRF_COLUMNS", "SWEEP_COLUMNS", "ORBIT_COLUMNS",
    "SoundPressure", "sound_pressure", "linear_sound_pressure", "a_weighting_db", "motion_sound_pressure",
    "coefficient_sound_pressure", "check_sound_paths", "UNCOVERED_WARNING",
    "MeasuredRun", "MeasuredComparison", "compare_measured", "MEASURED_QUANTITIES",
    "NonsmoothCheck", "NONSMOOTH_COLUMNS", "FrictionCheck", "FRICTION_ELEMENT_COLUMNS", "FRICTION_TAIL_COLUMNS",
    "held_runs", "SpeedText", "round_to_grid", "rpm_of_omega", "plot_with",
    "NonsmoothOrbitResult", "NONSMOOTH_ORBIT_COLUMNS", "FrictionOrbitResult", "FRICTION_ORBIT_ELEMENT_COLUMNS", "HeldLimitRecord",
]
