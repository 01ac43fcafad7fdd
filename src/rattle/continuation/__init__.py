"""Pseudo-arclength continuation in the forcing frequency with self-adjusting steps."""

from ._corrector import ArclengthCorrector, Corrected
from ._monitor import Monitor, MonitorReading, SegmentVerdict, check_segment
from ._options import ContinuationOptions
from ._stepper import BranchPoint, ContinuationStepper

__all__ = [
    "ContinuationOptions", "ContinuationStepper", "BranchPoint", "ArclengthCorrector", "Corrected",
    "Monitor", "MonitorReading", "SegmentVerdict", "check_segment",
]
