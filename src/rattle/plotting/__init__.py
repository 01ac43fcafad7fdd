"""Plots (with :mod:`rattle.demo`'s figures, the only matplotlib importers); every function returns
(figure, axes), ``axes`` a :class:`PlotAxes` (panel name → matplotlib Axes, with a primary one).

matplotlib (and plotly, for the interactive HTML pages of :mod:`._html`) is imported inside the
functions, so importing this package stays cheap. The paper's
own figures (Figures 4–7) are :mod:`rattle.demo`'s, drawn with the pieces here: the building
blocks below the plot functions in ``__all__`` (branch colours and labels, special-point markers,
period colours, spectra) are public for that use.
"""

from ._axes import PlotAxes, fit_ylim, separate_texts, unwrap
from ._compare import compare_plot
from ._frf import (
    branch_colors, branch_label, draw_branches, draw_regions, draw_special_points, frequency_response_plot,
    place_legend, true_runs,
)
from ._friction import friction_response_plot
from ._friction_orbit import friction_orbit_plot
from ._html import PLOTLY_MISSING, compare_html, frequency_response_html, map_html, plotly_available
from ._map import map_plot_names, plot_map
from ..results import held_runs
from ._nonsmooth import nonsmooth_orbit_plot, nonsmooth_response_plot
from ._orbit import amplitude_spectrum, orbit_plot
from ._sweep import PERIOD_COLORS, period_label, sweep_plot

__all__ = [
    "frequency_response_plot", "sweep_plot", "orbit_plot", "compare_plot", "plot_map", "PlotAxes",
    "nonsmooth_response_plot", "nonsmooth_orbit_plot", "friction_response_plot", "friction_orbit_plot",
    # interactive pages (plotly, ``pip install "rattle[html]"``): one self-contained HTML file each
    "frequency_response_html", "compare_html", "map_html", "plotly_available", "PLOTLY_MISSING",
    # the figures ``rattle map`` writes
    "map_plot_names",
    # building blocks (the demo's figures, the command line's summaries)
    "unwrap", "branch_colors", "branch_label", "draw_branches", "draw_regions", "draw_special_points",
    "place_legend", "true_runs", "held_runs", "amplitude_spectrum", "period_label", "PERIOD_COLORS",
    # every point inside the axes, no label over another
    "fit_ylim", "separate_texts",
]
