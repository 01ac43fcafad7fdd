"""Harmonic balance of a :class:`~rattle.model.System` (n coordinates, m clearance elements; the
single equation is n = m = 1): Fourier basis, AFT residual with analytic Jacobians. :class:`HarmonicBalance` is a
:class:`~rattle.continuation.ContinuationProblem`: it is solved by :func:`rattle.continuation.solve_fixed`
and continued by :class:`rattle.continuation.ContinuationStepper`."""

from ._basis import FourierBasis, resize_harmonics
from ._options import HBOptions, default_samples
from ._regularised import RegularisedBalance, RegularisedForce
from ._kernels import irfft, rfft
from ._regularised_system import MAX_SAMPLES, RegularisedSystemBalance
from ._residual import HarmonicBalance

__all__ = ["FourierBasis", "resize_harmonics", "HarmonicBalance", "HBOptions", "default_samples",
           "RegularisedBalance", "RegularisedForce", "RegularisedSystemBalance", "MAX_SAMPLES", "rfft", "irfft"]

#: Names whose home moved to :mod:`rattle.continuation` (Newton at a fixed parameter is the same
#: for every continuation problem): still importable from here, resolved when first used, so that
#: this package does not import the continuation layer above it.
_MOVED = {"NewtonOptions": "NewtonOptions", "NewtonResult": "NewtonResult", "solve_harmonic_balance": "solve_fixed"}


def __getattr__(name: str):
    if name in _MOVED:
        import importlib

        return getattr(importlib.import_module("rattle.continuation"), _MOVED[name])
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
