"""Predictors: where the next trial point of a branch lies, and the plane it is corrected in.

In scaled variables y (see :mod:`._problem`), from the last accepted point y_i with unit tangent
t_i and step Δs, a predictor returns the trial point y_pred and a unit direction d; the corrector
then solves R(y) = 0, d·(y − y_pred) = 0 (Keller's pseudo-arclength condition). A predictor is a
small frozen object the :class:`~rattle.continuation.ContinuationStepper` takes as
``predictor=``; strings are not resolved inside the stepper.

* :class:`Tangent` (default): y_pred = y_i + Δs t_i, d = t_i — the Euler predictor along the
  exact tangent (the null vector of [∂R/∂q L, ∂R/∂p p_s]).
* :class:`Secant`: y_pred = y_i + Δs d, d = (y_i − y_{i−1}) / |y_i − y_{i−1}| — the chord
  through the last two points (the tangent at the first step); it needs no tangent accuracy
  and follows the branch's curvature less tightly.
* :class:`Natural`: y_pred = (q_i, p_i ± Δs), d = the parameter's axis — natural-parameter
  continuation: every point corrected at a fixed parameter from the last one (no extrapolation
  of q); it cannot pass a fold in p, and is for families known to have none where a linear
  prediction of q overshoots (a width narrowed towards its limit: the held elements' ladder of
  :mod:`rattle.analysis._held_limit`).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray


class AbstractPredictor(abc.ABC):
    """The predictor interface: :meth:`predict`."""

    @abc.abstractmethod
    def predict(
        self, y: FloatArray, tangent: FloatArray, step: float, previous: FloatArray | None
    ) -> tuple[FloatArray, FloatArray]:
        """The trial point and the unit normal of the corrector's plane.

        ``y`` the last accepted point, ``tangent`` its unit tangent (oriented along the branch),
        ``step`` Δs > 0, ``previous`` the accepted point before ``y`` (None at the first step);
        all in scaled variables, shape (N + 1,).
        """


@dataclass(frozen=True, slots=True)
class Tangent(AbstractPredictor):
    """Euler predictor along the unit tangent: y_pred = y + Δs t (the default)."""

    def predict(
        self, y: FloatArray, tangent: FloatArray, step: float, previous: FloatArray | None
    ) -> tuple[FloatArray, FloatArray]:
        return y + step * tangent, tangent


@dataclass(frozen=True, slots=True)
class Secant(AbstractPredictor):
    """Predictor along the secant through the last two accepted points (the tangent for the
    first step, or when the two points coincide)."""

    def predict(
        self, y: FloatArray, tangent: FloatArray, step: float, previous: FloatArray | None
    ) -> tuple[FloatArray, FloatArray]:
        if previous is None:
            return y + step * tangent, tangent
        chord = y - previous
        length = float(np.linalg.norm(chord))
        if not length > 0.0:
            return y + step * tangent, tangent
        d = chord / length
        return y + step * d, d


@dataclass(frozen=True, slots=True)
class Natural(AbstractPredictor):
    """Natural-parameter predictor: the last point's q at the parameter moved by Δs (in scaled
    units) the way the tangent goes; the corrector's plane is p = that value (module docstring)."""

    def predict(
        self, y: FloatArray, tangent: FloatArray, step: float, previous: FloatArray | None
    ) -> tuple[FloatArray, FloatArray]:
        d = np.zeros_like(y)
        d[-1] = 1.0 if tangent[-1] >= 0.0 else -1.0
        return y + step * d, d


#: Predictor names accepted at the boundary (configuration, command line) → class.
#: (not :class:`Natural`: a frequency response has folds it cannot pass).
PREDICTORS: dict[str, type[AbstractPredictor]] = {"tangent": Tangent, "secant": Secant}


def predictor(value: object, name: str = "predictor") -> AbstractPredictor:
    """A predictor object from itself or from its name in :data:`PREDICTORS` (the boundary's one
    conversion)."""
    if isinstance(value, AbstractPredictor):
        return value
    if isinstance(value, str) and value in PREDICTORS:
        return PREDICTORS[value]()
    allowed = ", ".join(repr(k) for k in PREDICTORS)
    raise ValueError(
        f"`{name}` must be a predictor ({allowed}, or rattle.continuation.Tangent()/Secant()), got {value!r}"
    )


__all__ = ["AbstractPredictor", "Tangent", "Secant", "Natural", "PREDICTORS", "predictor"]
