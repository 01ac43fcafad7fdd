"""Type aliases shared across rattle.

Conventions: angles in rad, time in s (or dimensionless time when K = I = 1),
frequencies in rad/s. Arrays are float64 numpy arrays; shapes are given in the
docstrings of the functions that take them.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
ComplexArray = npt.NDArray[np.complex128]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

__all__ = ["FloatArray", "ComplexArray", "IntArray", "BoolArray"]
