"""Pseudo-arclength continuation of any problem R(q, p) = 0 in one parameter, with self-adjusting steps.

A problem is anything that implements :class:`ContinuationProblem` (harmonic balance,
:class:`~rattle.hb.HarmonicBalance`; shooting, :class:`~rattle.timeint.ShootingProblem`); this
package knows nothing of how its residual is computed. :func:`solve_fixed` solves it at a fixed
parameter, :class:`ContinuationStepper` follows its branch (predictor objects :class:`Tangent`,
:class:`Secant`, :class:`Natural`; bordered corrector :class:`ArclengthCorrector`; test-function monitoring
:func:`check_segment`; special points located by :func:`locate_on_segment`).
:class:`ForcingHomotopy` turns a problem at a fixed parameter into one continued in the scale λ
of its forcing (the start of a branch where Newton alone does not converge);
:class:`WidthHomotopy` one continued in the logarithm of a width (the ε-ladder and the held
elements' ladder of the regularised harmonic balance, rungs as the stepper's ``stations``).
"""

from ._corrector import ArclengthCorrector, Corrected
from ._detect import LocatedPoint, locate_on_segment
from ._homotopy import ForcingHomotopy, WidthHomotopy
from ._monitor import Monitor, MonitorReading, SegmentVerdict, check_segment
from ._newton import NewtonResult, solve_fixed
from ._options import ContinuationOptions, NewtonOptions
from ._predictor import PREDICTORS, AbstractPredictor, Natural, Secant, Tangent, predictor
from ._problem import ContinuationProblem, SupportsNewtonStep
from ._stepper import BranchPoint, ContinuationStepper

__all__ = [
    "ContinuationProblem", "SupportsNewtonStep", "ContinuationOptions", "NewtonOptions", "NewtonResult",
    "solve_fixed", "ContinuationStepper", "BranchPoint", "AbstractPredictor", "Tangent", "Secant", "Natural",
    "PREDICTORS", "predictor", "ArclengthCorrector", "Corrected", "LocatedPoint", "locate_on_segment",
    "Monitor", "MonitorReading", "SegmentVerdict", "check_segment", "ForcingHomotopy",
    "WidthHomotopy",
]
