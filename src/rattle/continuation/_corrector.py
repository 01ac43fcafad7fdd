"""The bordered Newton corrector of pseudo-arclength continuation, in scaled variables.

Variables y = (q / L, p / p_s) with L the problem's ``length_scale`` (a number or one per
unknown) and p_s its ``parameter_scale`` (see :mod:`._problem`). Given a predicted point y_p and a
unit direction t, the corrector solves

    R(q, p) = 0,    t · (y − y_p) = 0

by Newton on the bordered Jacobian [∂R/∂q L, ∂R/∂p p_s; tᵀ] (damped by backtracking when
:attr:`NewtonOptions.damped`); the tangent at a solution is the
null vector of [∂R/∂q L, ∂R/∂p p_s], normalised and oriented along a reference direction.
An iterate whose parameter leaves the problem's open ``domain`` (default p > 0) fails the
correction: the residual is not evaluated there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .._typing import FloatArray
from ._newton import backtrack
from ._options import NewtonOptions
from ._problem import ContinuationProblem

_gesv = scipy.linalg.lapack.dgesv


@dataclass(slots=True)
class Corrected:
    """A converged corrector result: scaled ``y``, Newton ``iterations``, scaled ``residual`` and
    the Jacobians ``Rq`` = ∂R/∂q and ``Rp`` = ∂R/∂p at ``y``."""

    y: FloatArray
    iterations: int
    residual: float
    Rq: FloatArray
    Rp: FloatArray


class ArclengthCorrector:
    """Scaling, bordered solves, tangents and the plane-constrained Newton corrector.

    ``domain`` the open interval of parameters at which ``problem`` may be evaluated (default
    p > 0: a frequency, a forcing scale, a width)."""

    def __init__(
        self, problem: ContinuationProblem, newton: NewtonOptions, domain: tuple[float, float] = (0.0, math.inf)
    ) -> None:
        self.problem = problem
        self.newton = newton
        self.domain = (float(domain[0]), float(domain[1]))
        n = problem.size
        self.scale = np.empty(n + 1)
        L = problem.length_scale
        self.scale[:n] = L
        self.scale[n] = problem.parameter_scale
        # ∂R/∂q L: one number scales every column (the common case), else one per column.
        self._q_scale = self.scale[0] if np.ndim(L) == 0 else self.scale[:n]
        self._unscale_q = self.scale[:n]
        self._unscale_p = self.scale[n]
        # The bordered matrix, Fortran-ordered for LAPACK, filled and factorised in place by each
        # solve (a corrector serves one caller at a time), and its blocks' views.
        self._bordered = np.empty((n + 1, n + 1), order="F")
        self._blocks = (self._bordered[:n, :n], self._bordered[:n, n], self._bordered[n])

    def to_scaled(self, q: FloatArray, p: float) -> FloatArray:
        """y = (q / L, p / p_s) of the point (q, p)."""
        y = np.empty(q.size + 1)
        y[:-1] = q
        y[-1] = p
        return y / self.scale

    def unscale(self, y: FloatArray) -> tuple[FloatArray, float]:
        """(q, p) of the scaled point y."""
        return y[:-1] * self._unscale_q, float(y[-1] * self._unscale_p)

    def bordered_solve(self, Rq: FloatArray, Rp: FloatArray, t: FloatArray, rhs: FloatArray) -> FloatArray | None:
        """Solve [∂R/∂q L, ∂R/∂p p_s; tᵀ] x = rhs (LAPACK gesv; None if singular)."""
        A = self._bordered
        if A.shape[0] != Rq.shape[0] + 1:  # a caller with another size (not the problem's)
            n = Rq.shape[0]
            A = np.empty((n + 1, n + 1), order="F")
            blocks = (A[:n, :n], A[:n, n], A[n])
        else:
            blocks = self._blocks
        Aq, Ap, At = blocks
        np.multiply(Rq, self._q_scale, out=Aq)
        np.multiply(Rp, self._unscale_p, out=Ap)
        At[...] = t
        _, _, x, info = _gesv(A, rhs, overwrite_a=1, overwrite_b=0)
        if info != 0 or not np.isfinite(x).all():
            return None
        return x

    def tangent(self, Rq: FloatArray, Rp: FloatArray, reference: FloatArray) -> FloatArray | None:
        """Unit tangent (scaled) with positive projection on ``reference``."""
        rhs = np.zeros(Rq.shape[0] + 1)
        rhs[-1] = 1.0
        tau = self.bordered_solve(Rq, Rp, reference, rhs)
        return None if tau is None else tau / np.linalg.norm(tau)

    def _merit(self, y: FloatArray, y_pred: FloatArray, t: FloatArray) -> float:
        """‖(R(q, p) / F_s, t·(y − y_pred))‖₂ at the scaled point y (inf outside the domain): what a
        damped correction lowers."""
        q, p = self.unscale(y)
        if not self.domain[0] < p < self.domain[1]:
            return math.inf
        r = float(np.linalg.norm(self.problem.residual(q, p))) / self.problem.force_scale
        return math.hypot(r, float(t @ (y - y_pred)))

    def correct(self, y_pred: FloatArray, t: FloatArray) -> Corrected | None:
        """Newton on R = 0, t·(y − y_pred) = 0 from y_pred; None when it fails."""
        problem, opts = self.problem, self.newton
        Fs = problem.force_scale
        y = y_pred.copy()
        step_norm = np.inf
        n = problem.size
        rhs = np.empty(n + 1)
        rhs_q = rhs[:n]
        first_res = None
        p_lo, p_hi = self.domain
        scale_q, scale_p = self._unscale_q, self._unscale_p
        for it in range(opts.max_iterations + 1):
            q, p = y[:-1] * scale_q, float(y[-1] * scale_p)  # unscale(y)
            if not p_lo < p < p_hi:  # outside the problem's domain (e.g. a frequency <= 0)
                return None
            R, Rq, Rp = problem.residual_jacobian(q, p)
            res = float(np.abs(R).max()) / Fs
            if not math.isfinite(res):
                return None
            if first_res is None:
                first_res = res
            elif res > 1e4 * max(first_res, 1e-3):
                return None  # diverging
            if it > 0 and res <= opts.residual_tol and step_norm <= opts.step_tol:
                return Corrected(y, it, res, Rq, Rp)
            if it == opts.max_iterations:
                return None
            np.negative(R, out=rhs_q)
            rhs[n] = -float(t @ (y - y_pred))
            dy = self.bordered_solve(Rq, Rp, t, rhs)
            if dy is None:
                return None
            if opts.damped and not (res <= opts.residual_tol and float(np.abs(dy).max()) <= opts.step_tol):
                # the step's fraction that lowers R and the plane condition together (a last step
                # within the tolerances is taken whole: at round-off no fraction descends)
                lam = backtrack(lambda x: self._merit(x, y_pred, t), y, dy, math.hypot(
                    float(np.linalg.norm(R)) / Fs, float(rhs[n])))
                if lam is None:
                    return None
                dy *= lam
            y += dy
            step_norm = float(np.abs(dy).max())
        return None  # pragma: no cover


__all__ = ["ArclengthCorrector", "Corrected"]
