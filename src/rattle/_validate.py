"""Argument checks shared by the front ends (the messages name the argument in backticks)."""

from __future__ import annotations

import math

import numpy as np

from ._typing import FloatArray


def check_omega(value: object, name: str = "omega") -> float:
    """A forcing frequency: a real number, finite and > 0 (rad/s)."""
    if isinstance(value, bool):
        raise TypeError(f"`{name}` must be a forcing frequency in rad/s (a number), got {value!r}")
    try:
        w = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise TypeError(f"`{name}` must be a forcing frequency in rad/s (a number), got {value!r}") from None
    if not (math.isfinite(w) and w > 0.0):
        raise ValueError(f"`{name}` must be a finite forcing frequency > 0 rad/s, got {value!r}; use e.g. 0.8")
    return w


def check_state(value: object, name: str = "x0") -> FloatArray:
    """A state (δ, δ') of shape (2,), finite."""
    x = np.asarray(value, dtype=float)
    if x.shape != (2,) or not np.all(np.isfinite(x)):
        raise ValueError(f"`{name}` must be a finite state (delta, velocity) of shape (2,), got {value!r}")
    return x


def check_int(name: str, value: object, low: int) -> int:
    """An integer (not a bool) >= ``low``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"`{name}` must be an integer, got {value!r} ({type(value).__name__})")
    if value < low:
        raise ValueError(f"`{name}` must be >= {low}, got {value!r}")
    return int(value)


__all__ = ["check_omega", "check_state", "check_int"]
