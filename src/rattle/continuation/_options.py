"""Options of the continuation: the Newton corrector and the arc-length step control."""

from __future__ import annotations

import math
from numbers import Integral
from dataclasses import dataclass

from .._limits import MAX_NEWTON_ITERATIONS, check_max_points
from .._validate import check_int, check_real


@dataclass(frozen=True, slots=True, kw_only=True)
class ContinuationOptions:
    """Step control and budgets of the arc-length continuation.

    Arc length is measured in scaled variables (q / L, p / p_s), L and p_s the problem's
    ``length_scale`` and ``parameter_scale`` (harmonic balance: the model's length scale and
    ω_n = sqrt(K/I)), so the defaults suit any unit system.

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


@dataclass(frozen=True, slots=True, kw_only=True)
class NewtonOptions:
    """Newton–Raphson corrector settings.

    Converged when the scaled residual ‖R‖∞ / F_s ≤ ``residual_tol`` and the scaled step
    max_i |Δq_i| / L_i ≤ ``step_tol`` (F_s, L: the problem's ``force_scale`` and
    ``length_scale``, see :class:`~rattle.continuation.ContinuationProblem`; for harmonic
    balance F_s = |F_m| + Σ|F_pn| and L the model's length scale). At most ``max_iterations``
    corrections.

    ``damped``: each correction Δ is taken as λ Δ with the largest λ = 1, 1/2, 1/4, … ≥ 2⁻¹⁰ for
    which the residual's 2-norm falls, ‖R(x + λ Δ)‖₂ < (1 − λ/4) ‖R(x)‖₂ (Armijo backtracking; at
    a fixed parameter on R, in the corrector on R and the plane condition together); no such λ
    fails the solve. For problems whose Newton steps overshoot from a guess far from the solution
    (a regularised step narrowed: :func:`rattle.analysis._held_limit.held_limit`). Default False:
    the full step, as every continuation of a branch takes it.
    """

    residual_tol: float = 1e-10
    step_tol: float = 1e-8
    max_iterations: int = 12
    damped: bool = False

    def __post_init__(self) -> None:
        for name in ("residual_tol", "step_tol"):
            v = check_real(getattr(self, name), name)
            if not 0 < v < 1:
                raise ValueError(f"`{name}` must be a number in (0, 1), got {v!r}")
            object.__setattr__(self, name, v)
        m = check_int("max_iterations", self.max_iterations, 1)
        if m > MAX_NEWTON_ITERATIONS:
            raise ValueError(
                f"`max_iterations` must be <= {MAX_NEWTON_ITERATIONS}, got {m}: Newton converges in 2–5 "
                "iterations where it converges at all, and every iteration is a dense solve; use e.g. 12"
            )
        object.__setattr__(self, "max_iterations", m)
        if not isinstance(self.damped, bool):
            raise TypeError(f"`damped` must be True or False, got {self.damped!r}")


__all__ = ["ContinuationOptions", "NewtonOptions"]
