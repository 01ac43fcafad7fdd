"""Plots (the only matplotlib importer); every function returns (figure, axes).

matplotlib is imported inside the functions, so importing this package stays cheap.
"""

from ._compare import compare_plot
from ._frf import frequency_response_plot
from ._orbit import orbit_plot
from ._paper import hbm_vs_simulation_plot, linear_vs_nonlinear_plot, mean_operating_point_plot, point_plot
from ._sweep import sweep_plot

__all__ = [
    "frequency_response_plot", "sweep_plot", "orbit_plot", "compare_plot",
    "linear_vs_nonlinear_plot", "hbm_vs_simulation_plot", "point_plot", "mean_operating_point_plot",
]
