"""Exact time integration of the single equation δ'' + c δ' + k f(δ) = F(t), by job:

- :mod:`._stage_solutions` — :class:`StageSolutions`, the closed-form solution on every stage
  (exp(A τ) from :mod:`rattle.model._stage_matrix`, particular solutions);
- :mod:`._roots` — Newton's method safeguarded by bisection (crossings, extrema);
- :mod:`._trajectory` — :class:`Trajectory`, its exact samples and measures;
- :mod:`._integrator` — the compiled scalar path of :class:`ExactIntegrator` (:mod:`._exact_flow`),
  segment by segment with the crossings located to round-off.

This module gathers them under their old names (the N-coordinate counterparts are
:mod:`._stage_flow`, :mod:`._events` and :mod:`._flow`).
"""

from . import _integrator  # noqa: F401  (the scalar path registers itself)
from ._exact_flow import ExactIntegrator
from ._stage_solutions import StageSolutions
from ._trajectory import ExactMeasures, ExactTrajectory, StateSamples, Trajectory

__all__ = ["ExactIntegrator", "ExactTrajectory", "Trajectory", "StateSamples", "ExactMeasures", "StageSolutions"]
