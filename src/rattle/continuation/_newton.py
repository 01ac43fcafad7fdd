"""Newton–Raphson at a fixed parameter: q ← q − (∂R/∂q)⁻¹ R(q, p), for any continuation problem."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .._typing import FloatArray
from ..errors import Status
from ._options import NewtonOptions
from ._problem import ContinuationProblem


def _full_step(problem: ContinuationProblem, q: FloatArray, p: float) -> tuple[FloatArray, FloatArray | None]:
    R, Rq, _ = problem.residual_jacobian(q, p)
    _, _, dq, info = scipy.linalg.lapack.dgesv(Rq, -R)
    return R, (dq if info == 0 and np.all(np.isfinite(dq)) else None)


def newton_step(problem: ContinuationProblem, q: FloatArray, p: float) -> tuple[FloatArray, FloatArray | None]:
    """(R, Δq) of one Newton step at the fixed parameter p: the problem's own ``newton_step`` when
    it has one (:class:`~rattle.continuation.SupportsNewtonStep`), else the full LAPACK solve from
    ``residual_jacobian``; Δq None where the step cannot be taken (a singular or non-finite solve)."""
    own = getattr(problem, "newton_step", None)
    return own(q, p) if own is not None else _full_step(problem, q, p)


#: The smallest fraction of a damped Newton step (:attr:`NewtonOptions.damped`).
SMALLEST_FRACTION = 2.0**-10


def backtrack(merit: Callable[[FloatArray], float], x: FloatArray, dx: FloatArray, m0: float) -> float | None:
    """The fraction λ of a damped Newton step (:attr:`NewtonOptions.damped`): the largest of 1, 1/2,
    1/4, … ≥ :data:`SMALLEST_FRACTION` with merit(x + λ dx) < (1 − λ/4) m0 (Armijo's rule on a
    residual norm m0 = merit(x)); None when none descends."""
    lam = 1.0
    while lam >= SMALLEST_FRACTION:
        m1 = merit(x + lam * dx)
        if math.isfinite(m1) and m1 < (1.0 - 0.25 * lam) * m0:
            return lam
        lam /= 2.0
    return None


@dataclass(frozen=True, slots=True)
class NewtonResult:
    """Outcome of a Newton solve: the last iterate ``q``, how it ended (``status``, a
    :class:`~rattle.errors.Status`: ``CONVERGED``, ``SINGULAR``, ``NON_FINITE`` or
    ``MAX_ITERATIONS``), Newton ``iterations`` and the scaled ``residual`` ‖R‖∞ / F_s."""

    q: FloatArray
    status: Status
    iterations: int
    residual: float

    @property
    def converged(self) -> bool:
        """True when the solve converged (``status.success``)."""
        return self.status.success

    @property
    def message(self) -> str:
        """How the solve ended, in words (``status.message``)."""
        return self.status.message


def solve_fixed(
    problem: ContinuationProblem,
    q0: FloatArray,
    parameter: float,
    options: NewtonOptions | None = None,
) -> NewtonResult:
    """Solve R(q, p) = 0 at the fixed parameter p = ``parameter`` from the guess ``q0`` by Newton–Raphson.

    Convergence: ‖R‖∞ / F_s ≤ ``residual_tol`` and max_i |Δq_i| / L_i ≤ ``step_tol`` (F_s, L the
    problem's ``force_scale`` and ``length_scale``; see :class:`NewtonOptions`). The step is the
    problem's own ``newton_step`` when it has one (:class:`~rattle.continuation.SupportsNewtonStep`;
    harmonic balance: full or condensed), else the full LAPACK solve from ``residual_jacobian``.
    A failure is returned, not raised: check ``converged``.
    """
    options = NewtonOptions() if options is None else options
    q = np.array(q0, dtype=float, copy=True)
    Fs, L = problem.force_scale, problem.length_scale
    uniform = np.ndim(L) == 0
    res = np.inf
    for it in range(1, options.max_iterations + 1):
        R, dq = newton_step(problem, q, parameter)
        res = float(np.max(np.abs(R))) / Fs
        if not np.isfinite(res):
            return NewtonResult(q, Status.NON_FINITE, it, res)
        if dq is None:
            return NewtonResult(q, Status.SINGULAR, it, res)
        size = float(np.max(np.abs(dq))) / L if uniform else float(np.max(np.abs(dq) / L))
        if res <= options.residual_tol and size <= options.step_tol:
            q += dq
            res = float(np.max(np.abs(problem.residual(q, parameter)))) / Fs
            return NewtonResult(q, Status.CONVERGED, it, res)
        if options.damped:
            lam = backtrack(lambda x: float(np.linalg.norm(problem.residual(x, parameter))), q, dq,
                            float(np.linalg.norm(R)))
            if lam is None:
                return NewtonResult(q, Status.MAX_ITERATIONS, it, res)
            dq = lam * dq
        q += dq
    res = float(np.max(np.abs(problem.residual(q, parameter)))) / Fs
    ok = res <= options.residual_tol
    return NewtonResult(q, Status.CONVERGED if ok else Status.MAX_ITERATIONS, options.max_iterations, res)


__all__ = ["NewtonResult", "solve_fixed"]
