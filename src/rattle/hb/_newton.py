"""Newton–Raphson corrector at fixed forcing frequency: q ← q − (∂R/∂q)⁻¹ R."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .._typing import FloatArray
from ._options import NewtonOptions
from ._residual import HarmonicBalance


def _full_step(problem, q: FloatArray, omega: float) -> tuple[FloatArray, FloatArray | None]:
    R, Rq, _ = problem.residual_jacobian(q, omega)
    _, _, dq, info = scipy.linalg.lapack.dgesv(Rq, -R)
    return R, (dq if info == 0 and np.all(np.isfinite(dq)) else None)


@dataclass(frozen=True, slots=True)
class NewtonResult:
    """Outcome of a Newton solve: ``q``, ``converged``, ``iterations``, scaled ``residual``."""

    q: FloatArray
    converged: bool
    iterations: int
    residual: float
    message: str


def solve_harmonic_balance(
    hb: HarmonicBalance,
    q0: FloatArray,
    omega: float,
    options: NewtonOptions | None = None,
) -> NewtonResult:
    """Solve R(q, Ω) = 0 at fixed Ω from the guess ``q0`` by Newton–Raphson.

    Convergence: ‖R‖∞ / F_s ≤ residual_tol and ‖Δq‖∞ / L ≤ step_tol (scaled, see NewtonOptions).
    """
    options = NewtonOptions() if options is None else options
    q = np.array(q0, dtype=float, copy=True)
    Fs, L = hb.force_scale, hb.length_scale
    # The problem's own step (HarmonicBalance: full LAPACK gesv or condensed, HBOptions.condense);
    # any other problem with residual_jacobian gets the full step.
    step = getattr(hb, "newton_step", None) or (lambda q, w: _full_step(hb, q, w))
    res = np.inf
    for it in range(1, options.max_iterations + 1):
        R, dq = step(q, omega)
        res = float(np.max(np.abs(R))) / Fs
        if not np.isfinite(res):
            return NewtonResult(q, False, it, res, "the residual became non-finite")
        if dq is None:
            return NewtonResult(q, False, it, res, "singular Jacobian")
        q += dq
        if res <= options.residual_tol and float(np.max(np.abs(dq))) / L <= options.step_tol:
            res = float(np.max(np.abs(hb.residual(q, omega)))) / Fs
            return NewtonResult(q, True, it, res, "converged")
    res = float(np.max(np.abs(hb.residual(q, omega)))) / Fs
    ok = res <= options.residual_tol
    return NewtonResult(q, ok, options.max_iterations, res, "converged" if ok else "maximum iterations reached")


__all__ = ["NewtonResult", "solve_harmonic_balance"]
