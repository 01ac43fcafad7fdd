"""Options of the pseudo-arclength continuation in the forcing frequency."""

from __future__ import annotations

import math
from numbers import Integral
from dataclasses import dataclass

from .._limits import check_max_points


@dataclass(frozen=True, slots=True, kw_only=True)
class ContinuationOptions:
    """Step control and budgets of the arc-length continuation.

    Arc length is measured in scaled variables (q / L, Ω / ω_n), L the model's length scale
    and ω_n = sqrt(K/I), so the defaults suit any unit system.

    ``initial_step``, ``min_step``, ``max_step``: arc-length step bounds.
    ``target_iterations``: Newton iterations per point the step controller aims for.
    ``max_turn``: largest angle (rad) between successive tangents accepted; a larger turn is
    rejected and retried with a shorter step (guards against jumping between branches).
    ``target_turn``: turn the controller aims for (the step shrinks when turns are larger).
    ``max_points``: budget of accepted points; ``max_time``: wall-time budget in s (None: none).

    Test-function monitoring (used when the stepper is given a monitor, as every front end of
    rattle does; see ``continuation._monitor``): ``monitor_tolerance`` θ ∈ (0, 1], the fraction
    of a test function's distance from zero that the error of its cubic model between two
    points may use before the step is shortened; ``max_change`` the largest change of a test
    function per step relative to 1 + its size (bounds how far the multipliers move);
    ``resolution`` the arc-length step below which the monitor no longer rejects a step (two
    bifurcations closer than this are not separated).
    """

    initial_step: float = 0.01
    min_step: float = 1e-6
    max_step: float = 0.08
    target_iterations: int = 3
    max_turn: float = 0.3
    target_turn: float = 0.1
    max_points: int = 20000
    max_time: float | None = None
    monitor_tolerance: float = 0.5
    max_change: float = 1.0
    resolution: float = 1e-4

    def __post_init__(self) -> None:
        for name in ("initial_step", "min_step", "max_step", "max_turn", "target_turn", "max_change", "resolution", "monitor_tolerance"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise ValueError(f"`{name}` must be a finite number > 0, got {v!r}")
        if not self.min_step <= self.initial_step <= self.max_step:
            raise ValueError(
                f"steps must satisfy min_step <= initial_step <= max_step, got "
                f"{self.min_step}, {self.initial_step}, {self.max_step}"
            )
        if self.monitor_tolerance > 1.0:
            raise ValueError(f"`monitor_tolerance` must be in (0, 1], got {self.monitor_tolerance}")
        if self.target_turn > self.max_turn:
            raise ValueError(f"`target_turn` ({self.target_turn}) must be <= `max_turn` ({self.max_turn})")
        if self.max_turn >= math.pi / 2:
            raise ValueError(f"`max_turn` must be < pi/2 rad, got {self.max_turn}")
        for name in ("target_iterations", "max_points"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, Integral) or v < 1:
                raise ValueError(f"`{name}` must be an integer >= 1, got {v!r}")
            object.__setattr__(self, name, int(v))  # numpy integers accepted, stored as int
        check_max_points(self.max_points)  # upper bound from memory (rattle._limits)
        if self.max_time is not None and (isinstance(self.max_time, bool) or not isinstance(self.max_time, (int, float)) or not self.max_time > 0):
            raise ValueError(f"`max_time` must be None or a number of seconds > 0, got {self.max_time!r}")


__all__ = ["ContinuationOptions"]
