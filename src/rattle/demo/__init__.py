"""The paper's reference case end to end (``rattle demo``): Figures 4–7, the report, the numbers.

Everything that reproduces the paper lives here, above the library it uses (``analysis``,
``results``, ``plotting``, ``io``); nothing below imports it.

- :mod:`._run` — the demo's settings (:data:`DEMO_OMEGA`, points A and B, file names),
  :func:`run_demo` and the :class:`PaperDemo` it returns (figures by key, report, metadata);
- :mod:`._figures` — the paper's figures, each returning ``(figure, axes)``;
- :mod:`._report` — the numbers the paper quotes (level difference, stage intervals) and the
  markdown report, pure.
"""

from ._figures import (
    hbm_vs_simulation_plot, linear_vs_nonlinear_plot, mean_operating_point_plot, point_plot, simulated_window,
)
from ._report import (
    PAPER_BAND, LevelDifference, demo_report, level_difference, linear_acceleration_p2p, stage_intervals,
)
from ._run import (
    DEMO_DATA, DEMO_FIGURES, DEMO_FILES, DEMO_HARMONICS, DEMO_OMEGA, DEMO_POINT_A, DEMO_POINT_B, DEMO_POINTS,
    DEMO_REPORT, DEMO_WORKERS, PaperDemo, demo_case, demo_frequency_response, describe, run_demo,
)

__all__ = [
    "run_demo", "PaperDemo", "demo_case", "demo_frequency_response", "describe",
    "DEMO_OMEGA", "DEMO_HARMONICS", "DEMO_POINTS", "DEMO_WORKERS", "DEMO_POINT_A", "DEMO_POINT_B",
    "DEMO_FIGURES", "DEMO_REPORT", "DEMO_DATA", "DEMO_FILES",
    "linear_vs_nonlinear_plot", "hbm_vs_simulation_plot", "point_plot", "mean_operating_point_plot",
    "simulated_window",
    "LevelDifference", "level_difference", "linear_acceleration_p2p", "stage_intervals", "demo_report", "PAPER_BAND",
]
