"""Plots (the only matplotlib importer); every function returns (figure, axes)."""

from ._compare import compare_plot
from ._frf import frequency_response_plot
from ._orbit import orbit_plot
from ._sweep import sweep_plot

__all__ = ["frequency_response_plot", "sweep_plot", "orbit_plot", "compare_plot"]
