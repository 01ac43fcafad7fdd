"""Named reference models.

The paper's clutch (K = I = 1, C = 0.05, α = 0.25, b = 10°, F_m = 0.05, F_p1 = 0.03)::

      engine side I1          clutch damper            transmission side I2
     ┌────────┐   K·f(δ), C   ┌────────┐
     │  θ1    ├──/\\/\\/─┤├───┤   θ2   │      δ = θ1 − θ2,  I = I1 I2 / (I1 + I2)
     └────────┘               └────────┘
        T_m + T_p(t) →                         ← drag torque
"""

from __future__ import annotations

import math

from ._elastic import Backlash, Clutch
from ._excitation import Excitation
from ._model import Model

REFERENCE_B = math.radians(10.0)


def reference_case() -> Model:
    """The paper's clutch: K = I = 1, C = 0.05, α = 0.25, b = 10°, F_m = 0.05, F_p1 = 0.03."""
    return Model(
        inertia=1.0,
        damping=0.05,
        stiffness=1.0,
        elastic=Clutch(alpha=0.25, b=REFERENCE_B),
        excitation=Excitation(mean=0.05, amplitudes=(0.03,)),
    )


def backlash_case(b: float = REFERENCE_B) -> Model:
    """The reference case with the first stage removed (α = 0): a gear pair with backlash."""
    return Model(
        inertia=1.0,
        damping=0.05,
        stiffness=1.0,
        elastic=Backlash(b=b),
        excitation=Excitation(mean=0.05, amplitudes=(0.03,)),
    )


__all__ = ["reference_case", "backlash_case", "REFERENCE_B"]
