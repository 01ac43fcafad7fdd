"""Errors and status values.

``ConfigError`` is bad input (command-line exit status 2), ``ConvergenceError`` a numerical
failure that could not be recovered (exit status 1). Long computations report how they ended
with a :class:`Status` value; the front ends raise on failure when ``throw=True``.
"""

from __future__ import annotations

import enum


class RattleError(Exception):
    """Base class of every error rattle raises on purpose."""


class ConfigError(RattleError, ValueError):
    """Bad input: a configuration key or an argument breaks a rule (exit status 2)."""


class ConvergenceError(RattleError, RuntimeError):
    """A numerical failure that could not be recovered (exit status 1).

    ``partial`` holds what was computed before the failure (e.g. a FrequencyResponse), or None.
    """

    def __init__(self, message: str, partial: object | None = None) -> None:
        super().__init__(message)
        self.partial = partial


class Status(enum.Enum):
    """How a computation ended: the one status type of rattle (a value, not an exception).

    ``.message`` explains, ``.success`` tells whether the result is complete. A continuation run
    (``FrequencyResponse.status``, ``ContinuationStepper.status``) ends with ``SUCCESS``,
    ``RETURNED``, ``STOPPED`` (complete), ``MAX_STEPS``, ``MAX_TIME``, ``STEP_TOO_SMALL`` or
    ``START_FAILED``; a frequency response whose branches leave part of the range uncovered
    with ``UNCOVERED``; a Newton solve at a fixed parameter
    (:class:`~rattle.continuation.NewtonResult`) with ``CONVERGED`` (complete), ``SINGULAR``,
    ``NON_FINITE`` or ``MAX_ITERATIONS``; a simulated steady state
    (:class:`~rattle.results.SteadyState`) with ``CONVERGED`` (the orbit polished by Newton
    shooting), ``SETTLED`` (complete) or ``MAX_PERIODS`` (nothing periodic found: period 0).
    """

    SUCCESS = "the branch was followed across the whole frequency range"
    RETURNED = "the branch turned back and left the range at the side it started from"
    MAX_STEPS = "the maximum number of continuation steps was reached before the end of the range"
    MAX_TIME = "the time budget was used up before the end of the range"
    STEP_TOO_SMALL = "the corrector failed even at the smallest allowed step"
    START_FAILED = "no periodic solution could be found at the start of the range"
    STOPPED = "the branch ended where it rejoined another branch"
    UNCOVERED = "part of the frequency range is covered by no branch"
    CONVERGED = "Newton's method converged"
    SINGULAR = "singular Jacobian"
    NON_FINITE = "the residual became non-finite"
    MAX_ITERATIONS = "maximum iterations reached"
    SETTLED = "the simulation settled on a periodic motion"
    MAX_PERIODS = "no periodic motion settled within the maximum number of forcing periods"

    @property
    def message(self) -> str:
        return self.value

    @property
    def success(self) -> bool:
        return self in _COMPLETE


_COMPLETE = frozenset({Status.SUCCESS, Status.RETURNED, Status.STOPPED, Status.CONVERGED, Status.SETTLED})


__all__ = ["RattleError", "ConfigError", "ConvergenceError", "Status"]
