"""What a problem must provide to be solved and continued: the :class:`ContinuationProblem` protocol.

A continuation problem is a square system of N equations in N unknowns q and one parameter p,

    R(q, p) = 0,    R: ℝᴺ × ℝ → ℝᴺ,

with its Jacobians ∂R/∂q (N × N) and ∂R/∂p (N,). The corrector, the stepper, the monitor and the
locator of :mod:`rattle.continuation` see nothing else: they work in the scaled variables

    y = (q / L, p / p_s) ∈ ℝᴺ⁺¹,

L the unknowns' scale (``length_scale``: one number, or one per unknown) and p_s the parameter's
(``parameter_scale``), so that a unit step in y is a comparable change of every component. The
tangent space of the branch {R = 0} carries the Euclidean norm of y: arc length, step bounds,
tangent turns and the locator's secants are all measured in it, so a problem chooses its norm
through its scales (no separate norm method). Residuals are judged relative to ``force_scale``
F_s: Newton has converged when ‖R‖∞ / F_s and max_i |Δq_i| / L_i are below the tolerances of
:class:`~rattle.continuation.NewtonOptions`.

The parameter is whatever the problem makes it; the package assumes nothing of it beyond the
open domain in which the residual may be evaluated (the stepper's ``domain``, by default p > 0).
rattle's frequency responses continue two problems in the forcing frequency p = Ω:

* :class:`~rattle.hb.HarmonicBalance` — q the Fourier coefficients of a periodic orbit, R the
  harmonic-balance residual; L the model's length scale, p_s = ω_n, F_s the forcing's size;
  it has its own :meth:`newton_step` (full or condensed solve);
* :class:`~rattle.timeint.ShootingProblem` — q = z(0) the state (x, x') on the Poincaré section,
  R = (φ_T(z(0)) − z(0)) / s the scaled period-map defect (T = p·2π/Ω), ∂R/∂q = (M − I)/s with
  M the exact monodromy, ∂R/∂Ω from the exact flow;

and the start of a frequency response, where Newton alone fails, continues one in the scale λ of
the forcing at a fixed Ω:

* :class:`~rattle.continuation.ForcingHomotopy` — R(q; λ) = R(q, Ω) + (1 − λ)(F − F_0), the
  harmonic balance with its forcing's harmonics scaled by λ (see ``_homotopy``).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from .._typing import FloatArray


@runtime_checkable
class ContinuationProblem(Protocol):
    """A square system R(q, p) = 0 in N unknowns q and one parameter p (see the module docstring).

    Attributes
    ----------
    size : int
        N, the number of unknowns (and of equations).
    length_scale : float or ndarray, shape (N,)
        L, the scale of the unknowns (units of q): the unknowns enter the scaled variables as q / L.
    parameter_scale : float
        p_s > 0, the scale of the parameter (units of p): it enters the scaled variables as p / p_s.
    force_scale : float
        F_s > 0, the scale of the residual (units of R): Newton's residual test is ‖R‖∞ / F_s.
    """

    @property
    def size(self) -> int: ...

    @property
    def length_scale(self) -> float | FloatArray: ...

    @property
    def parameter_scale(self) -> float: ...

    @property
    def force_scale(self) -> float: ...

    def residual(self, q: FloatArray, p: float) -> FloatArray:
        """R(q, p), shape (N,)."""
        ...

    def residual_jacobian(self, q: FloatArray, p: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """R (N,), ∂R/∂q (N, N) and ∂R/∂p (N,) at (q, p)."""
        ...


@runtime_checkable
class SupportsNewtonStep(ContinuationProblem, Protocol):
    """A :class:`ContinuationProblem` with its own Newton step at a fixed parameter (optional:
    :func:`~rattle.continuation.solve_fixed` uses it when present, else the full LAPACK solve
    of ∂R/∂q Δq = −R from :meth:`residual_jacobian`)."""

    def newton_step(self, q: FloatArray, p: float) -> tuple[FloatArray, FloatArray | None]:
        """R(q, p) and the Newton increment Δq = −(∂R/∂q)⁻¹ R (None when ∂R/∂q is singular)."""
        ...


__all__ = ["ContinuationProblem", "SupportsNewtonStep"]
