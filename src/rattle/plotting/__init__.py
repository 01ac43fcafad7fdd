"""Plots (with :mod:`rattle.demo`'s figures, the only matplotlib importers); every function returns
(figure, axes), ``axes`` a :class:`PlotAxes` (panel name → matplotlib Axes, with a primary one).

matplotlib is imported inside the functions, so importing this package stays cheap. The paper's
own figures (Figures 4–7) are :mod:`rattle.demo`'s, drawn with the pieces here.
"""

from ._axes import PlotAxes
from ._compare import compare_plot
from ._frf import frequency_response_plot
from ._friction import friction_response_plot
from ._friction_orbit import friction_orbit_plot
from ._map import plot_map
from ._nonsmooth import nonsmooth_orbit_plot, nonsmooth_response_plot
from ._orbit import orbit_plot
from ._sweep import sweep_plot

__all__ = [
    "frequency_response_plot", "sweep_plot", "orbit_plot", "compare_plot", "plot_map", "PlotAxes",
    "nonsmooth_response_plot", "nonsmooth_orbit_plot", "friction_response_plot", "friction_orbit_plot",
]
