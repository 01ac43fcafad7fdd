"""Which models the analyses accept (:func:`check_analysable_model`): a :class:`~rattle.model.Model`
or a :class:`~rattle.model.Chain`, with some damping (C > 0 in M x'' + C x' + … = F(t); undamped,
no periodic orbit is asymptotically stable). It reads both model classes, so it sits above
:mod:`._model` and :mod:`._chain`.
"""

from __future__ import annotations

import math
from typing import Any

from ._chain import Chain
from ._model import Model


def check_analysable_model(model: object, name: str = "model") -> Any:
    """A model the analyses can treat (:class:`~rattle.model.Model` or
    :class:`~rattle.model.Chain`): refuse zero damping.

    Zero damping is refused (not handled). An undamped forced piecewise-linear oscillator has
    an unbounded response at its linear resonances and no asymptotically stable periodic orbit:
    its Floquet multipliers lie on the unit circle (det M = exp(−c T) = 1), so the stability
    verdicts, the located special points and the settled periods would all be meaningless, and
    the linear start solution divides 0 by 0 at resonance. Give a small positive damping
    instead (ζ = 0.001 … 0.05 is typical of drivetrains). The models themselves accept damping
    0, so that undamped motions can still be integrated exactly
    (:class:`~rattle.timeint.ExactIntegrator`). For a chain, a chain with no damping in any
    link is refused.
    """
    if isinstance(model, Chain):
        if not model.has_damping:
            raise ValueError(
                f"`{name}.links` must give some damping for an analysis, got none: an undamped forced "
                "chain has unbounded resonant response and no asymptotically stable periodic orbit "
                "(Floquet multipliers on the unit circle); give the links a small positive damping"
            )
        return model
    if not isinstance(model, Model):
        raise TypeError(
            f"`{name}` must be a rattle Model or Chain (e.g. rattle.reference_case() or Model.from_toml(path)), "
            f"got {model!r} ({type(model).__name__})"
        )
    if model.damping == 0.0:
        raise ValueError(
            f"`{name}.damping` must be > 0 for an analysis, got 0.0: an undamped forced system has "
            "unbounded resonant response and no asymptotically stable periodic orbit (Floquet "
            "multipliers on the unit circle), so stability and settling verdicts would be meaningless; "
            "give a small positive damping, e.g. a damping ratio of 0.01 "
            f"(damping = {0.02 * math.sqrt(model.stiffness * model.inertia):.3g})"
        )
    return model


__all__ = ["check_analysable_model"]
