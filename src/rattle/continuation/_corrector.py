"""The bordered Newton corrector of pseudo-arclength continuation, in scaled variables.

Variables y = (q / L, Ω / ω_s) with L the model's length scale and ω_s = sqrt(K/I). Given a
predicted point y_p and a unit direction t, the corrector solves

    R(q, Ω) = 0,    t · (y − y_p) = 0

by Newton on the bordered Jacobian [∂R/∂q L, ∂R/∂Ω ω_s; tᵀ]; the tangent at a solution is the
null vector of [∂R/∂q L, ∂R/∂Ω ω_s], normalised and oriented along a reference direction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .._typing import FloatArray
from ..hb import HarmonicBalance, NewtonOptions

_gesv = scipy.linalg.lapack.dgesv


@dataclass(slots=True)
class Corrected:
    """A converged corrector result: scaled ``y``, Newton ``iterations``, scaled ``residual`` and
    the Jacobians at ``y``."""

    y: FloatArray
    iterations: int
    residual: float
    Rq: FloatArray
    Rw: FloatArray


class ArclengthCorrector:
    """Scaling, bordered solves, tangents and the plane-constrained Newton corrector."""

    def __init__(self, hb: HarmonicBalance, newton: NewtonOptions) -> None:
        self.hb = hb
        self.newton = newton
        n = hb.size
        self.scale = np.empty(n + 1)
        self.scale[:n] = hb.length_scale
        self.scale[n] = hb.model.natural_frequency

    def to_scaled(self, q: FloatArray, omega: float) -> FloatArray:
        y = np.empty(q.size + 1)
        y[:-1] = q
        y[-1] = omega
        return y / self.scale

    def unscale(self, y: FloatArray) -> tuple[FloatArray, float]:
        return y[:-1] * self.scale[:-1], float(y[-1] * self.scale[-1])

    def bordered_solve(self, Rq: FloatArray, Rw: FloatArray, t: FloatArray, rhs: FloatArray) -> FloatArray | None:
        """Solve [∂R/∂q L, ∂R/∂Ω ω_s; tᵀ] x = rhs (LAPACK gesv; None if singular)."""
        n = Rq.shape[0]
        A = np.empty((n + 1, n + 1), order="F")
        np.multiply(Rq, self.scale[0], out=A[:n, :n])
        np.multiply(Rw, self.scale[n], out=A[:n, n])
        A[n] = t
        _, _, x, info = _gesv(A, rhs, overwrite_a=1, overwrite_b=0)
        if info != 0 or not np.all(np.isfinite(x)):
            return None
        return x

    def tangent(self, Rq: FloatArray, Rw: FloatArray, reference: FloatArray) -> FloatArray | None:
        """Unit tangent (scaled) with positive projection on ``reference``."""
        rhs = np.zeros(Rq.shape[0] + 1)
        rhs[-1] = 1.0
        tau = self.bordered_solve(Rq, Rw, reference, rhs)
        return None if tau is None else tau / np.linalg.norm(tau)

    def correct(self, y_pred: FloatArray, t: FloatArray) -> Corrected | None:
        """Newton on R = 0, t·(y − y_pred) = 0 from y_pred; None when it fails."""
        hb, opts = self.hb, self.newton
        Fs = hb.force_scale
        y = y_pred.copy()
        step_norm = np.inf
        n = hb.size
        rhs = np.empty(n + 1)
        first_res = None
        for it in range(opts.max_iterations + 1):
            q, w = self.unscale(y)
            if w <= 0:
                return None
            R, Rq, Rw = hb.residual_jacobian(q, w)
            res = float(np.max(np.abs(R))) / Fs
            if not math.isfinite(res):
                return None
            if first_res is None:
                first_res = res
            elif res > 1e4 * max(first_res, 1e-3):
                return None  # diverging
            if it > 0 and res <= opts.residual_tol and step_norm <= opts.step_tol:
                return Corrected(y, it, res, Rq, Rw)
            if it == opts.max_iterations:
                return None
            rhs[:n] = -R
            rhs[n] = -float(t @ (y - y_pred))
            dy = self.bordered_solve(Rq, Rw, t, rhs)
            if dy is None:
                return None
            y += dy
            step_norm = float(np.max(np.abs(dy)))
        return None  # pragma: no cover


__all__ = ["ArclengthCorrector", "Corrected"]
