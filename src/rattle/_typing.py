"""Type aliases shared across rattle.

Conventions: angles in rad, time in s (or dimensionless time when K = I = 1),
frequencies in rad/s. Arrays are float64 numpy arrays; shapes are given in the
docstrings of the functions that take them.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

# float64 in practice; typed as any floating/integer precision so that numpy's own return types
# (often "floating[Any]" or "signedinteger[Any]") check without casts.
FloatArray = npt.NDArray[np.floating[Any]]
ComplexArray = npt.NDArray[np.complexfloating[Any, Any]]
IntArray = npt.NDArray[np.signedinteger[Any]]
BoolArray = npt.NDArray[np.bool_]

__all__ = ["FloatArray", "ComplexArray", "IntArray", "BoolArray"]
