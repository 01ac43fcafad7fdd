"""Speeds in text: a forcing frequency Ω written as the case gave its speeds.

A case without an engine is analysed over Ω (rad/s) and its summaries say ``Ω = …``. A case with
an ``[engine]`` (``speed_order`` q_0: Ω = q_0 × the crankshaft speed) was given in rpm, and every
speed its summaries, regions and reports show is the crankshaft speed

    n = Ω · 60 / (2π q_0)   (rpm).

The files keep Ω (SPEC §6: results in SI; ``speed_rpm`` is a column beside ``omega``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

__all__ = ["SpeedText", "rpm_of_omega", "round_to_grid"]


def rpm_of_omega(omega: Any, order: float) -> Any:
    """The crankshaft speed n = Ω · 60 / (2π q_0) (rpm) of the forcing frequency Ω (rad/s,
    scalar or array) at the engine order ``order`` = q_0."""
    return omega * (60.0 / (2.0 * math.pi * order))


def round_to_grid(values: Any, start: float, stop: float, count: int) -> Any:
    """``values`` (an array) rounded to the decimal digits that tell the points of a grid of
    ``count`` values from ``start`` to ``stop`` apart, plus six (a millionth of its step, at most
    half of it lost): the round-off of a unit conversion (799.9999999999999 rpm of a grid 400,
    500, …; some 1e-16 relative) goes, the grid's own points and every value between them keep
    their information (426.66667 of a grid 400 … 480 in 4 points). A grid of one value: 12
    significant digits of that value."""
    import numpy as np

    a = np.asarray(values, dtype=float)
    span = abs(float(stop) - float(start))
    step = span / (count - 1) if count > 1 and span > 0 else abs(float(start)) or 1.0
    if not math.isfinite(step) or step <= 0:
        return a
    decimals = 6 - math.floor(math.log10(step))
    if count <= 1 or span == 0:
        decimals = 11 - math.floor(math.log10(step))
    return np.round(a, decimals) + 0.0  # + 0.0: no -0.0


@dataclass(frozen=True, slots=True)
class SpeedText:
    """How a result writes a forcing frequency Ω in text: ``Ω = 234.61`` without an engine,
    ``1120.4 rpm`` (the crankshaft speed, :func:`rpm_of_omega`) with one (``order`` = q_0).

    ``SpeedText.of(model)`` reads the model's ``speed_order`` (None: no engine).
    """

    #: The engine order q_0 that turns Ω into the crankshaft speed; None without an engine.
    order: float | None = None

    @classmethod
    def of(cls, model: Any) -> "SpeedText":
        """The speed text of ``model`` (its ``speed_order``, None when it has none)."""
        order = getattr(model, "speed_order", None)
        return cls(None if order is None else float(order))

    @property
    def engine(self) -> bool:
        """True when speeds are written in rpm."""
        return self.order is not None

    @property
    def unit(self) -> str:
        """``rpm`` with an engine, else ``rad/s``."""
        return "rpm" if self.engine else "rad/s"

    def value(self, omega: float) -> float:
        """Ω in this text's unit: the rpm with an engine, else Ω itself."""
        return float(omega) if self.order is None else float(rpm_of_omega(float(omega), self.order))

    def number(self, omega: float, digits: int = 5) -> str:
        """The bare number of :meth:`value` to ``digits`` significant digits."""
        return f"{self.value(omega):.{digits}g}"

    def at(self, omega: float, digits: int = 5, unit: bool = False) -> str:
        """One speed: ``Ω = 234.61`` (``Ω = 234.61 rad/s`` with ``unit``) or ``1120.4 rpm``."""
        if self.engine:
            return f"{self.number(omega, digits)} rpm"
        return f"Ω = {self.number(omega, digits)}" + (" rad/s" if unit else "")

    def span(self, lo: float, hi: float, digits: int = 5, sep: str = " … ", unit: bool = False) -> str:
        """A range: ``Ω = 108.3 … 132.4`` (``… rad/s`` with ``unit``) or ``517.11 … 632.16 rpm``."""
        text = f"{self.number(lo, digits)}{sep}{self.number(hi, digits)}"
        if self.engine:
            return f"{text} rpm"
        return f"Ω = {text}" + (" rad/s" if unit else "")

    def spans(self, pairs: Iterable[tuple[float, float]], digits: int = 5, sep: str = " … ") -> str:
        """Several ranges: ``Ω = 0.5 … 0.7, 0.9 … 1`` or ``500 … 700, 900 … 1000 rpm``."""
        text = ", ".join(f"{self.number(a, digits)}{sep}{self.number(b, digits)}" for a, b in pairs)
        return f"{text} rpm" if self.engine else f"Ω = {text}"

    def values(self, omegas: Iterable[float], digits: int = 5, unit: bool = False) -> str:
        """Several speeds: ``Ω = 0.5, 0.61`` or ``600, 700 rpm``."""
        text = ", ".join(self.number(w, digits) for w in omegas)
        if self.engine:
            return f"{text} rpm"
        return f"Ω = {text}" + (" rad/s" if unit else "")
