"""Harmonic balance of a :class:`~rattle.model.System` (n coordinates, m clearance elements; the
single equation is n = m = 1): Fourier basis, AFT residual with analytic Jacobians, Newton corrector."""

from ._basis import FourierBasis, resize_harmonics
from ._newton import NewtonResult, solve_harmonic_balance
from ._options import HBOptions, NewtonOptions, default_samples
from ._residual import HarmonicBalance

__all__ = [
    "FourierBasis", "resize_harmonics", "HarmonicBalance", "HBOptions", "NewtonOptions", "NewtonResult",
    "solve_harmonic_balance", "default_samples",
]
