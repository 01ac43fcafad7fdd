"""Stability methods as objects: how the Floquet multipliers of harmonic-balance orbits are computed.

A front end takes ``stability="monodromy"`` or ``"hill"`` (a name, at the boundary) or the object
itself; :func:`stability_method` converts a name once (``rattle.analysis.RunSettings``), and the
core calls :meth:`AbstractStabilityMethod.multipliers` without looking at names again.

* :class:`Monodromy` — the exact monodromy of the piecewise-linear linearisation about the HB
  orbit (stage transition matrices exp(A_s τ) between the crossings of every element; see
  ``_floquet``). Its test functions det(M ∓ I), det(M ⊙ M − I) are smooth along the branch, so
  special points are located on it (``locates``).
* :class:`Hill` — Hill's method: eigenvalues of the HB Jacobian's quadratic eigenproblem, the
  physical exponents selected by their eigenvectors (Lazarus & Thomas 2010; see ``_hill``).
  Truncated, so a check of the monodromy; special points are labelled at the nearer branch point.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..hb import HarmonicBalance
from ._floquet import multipliers_from_monodromy
from ._hill import hill_multipliers
from ._monitor import FloquetMonitor


def floquet_monitor(hb: HarmonicBalance) -> FloquetMonitor:
    """The :class:`FloquetMonitor` of ``hb``, one per problem (it caches the stage decompositions
    of a chain; the same one the frequency response's continuation uses)."""
    mon = getattr(hb, "_floquet_monitor", None)
    if mon is None:
        mon = FloquetMonitor(hb)
        hb._floquet_monitor = mon  # type: ignore[attr-defined]
    return mon


class AbstractStabilityMethod(abc.ABC):
    """How Floquet multipliers of harmonic-balance orbits are computed.

    ``name`` is the method's name at the boundary (``stability="…"``, the case file, the
    ``stability`` entry of a result's settings); ``locates`` tells whether special points are
    located on the branch from this method's test functions.
    """

    name: ClassVar[str]
    locates: ClassVar[bool]

    @abc.abstractmethod
    def multipliers(self, hb: HarmonicBalance, Q: FloatArray, Om: FloatArray) -> ComplexArray:
        """Floquet multipliers (P, 2n), largest modulus first, of the orbits ``Q`` (P, n·(2H+1),
        coefficients of ``hb``) at the forcing frequencies ``Om`` (P,) in rad/s."""


@dataclass(frozen=True, slots=True)
class Monodromy(AbstractStabilityMethod):
    """The exact monodromy of the piecewise-linear linearisation about each HB orbit (default)."""

    name: ClassVar[str] = "monodromy"
    locates: ClassVar[bool] = True

    def multipliers(self, hb: HarmonicBalance, Q: FloatArray, Om: FloatArray) -> ComplexArray:
        if Q.shape[0] == 0:
            return np.zeros((0, 2 * (hb.size // hb.basis.size)), dtype=complex)
        return multipliers_from_monodromy(floquet_monitor(hb).monodromy_and_crossings(Q, Om)[0])


@dataclass(frozen=True, slots=True)
class Hill(AbstractStabilityMethod):
    """Hill's method on the harmonic-balance Jacobian (a truncated check of :class:`Monodromy`)."""

    name: ClassVar[str] = "hill"
    locates: ClassVar[bool] = False

    def multipliers(self, hb: HarmonicBalance, Q: FloatArray, Om: FloatArray) -> ComplexArray:
        P, k = Q.shape[0], 2 * (hb.size // hb.basis.size)
        if P == 0:
            return np.zeros((0, k), dtype=complex)
        return np.array([hill_multipliers(hb, q, om) for q, om in zip(Q, Om)]).reshape(P, k)


#: Stability method names accepted at the boundary → class (the one registry).
STABILITY_METHODS: dict[str, type[AbstractStabilityMethod]] = {"monodromy": Monodromy, "hill": Hill}


def stability_method(value: object, name: str = "stability") -> AbstractStabilityMethod:
    """The method object for ``value``: a method object as it is, or its name in
    :data:`STABILITY_METHODS` (``"monodromy"``, ``"hill"``).

    Raises
    ------
    ValueError
        ``value`` is neither (the message names ``name`` and lists the allowed names).
    """
    if isinstance(value, AbstractStabilityMethod):
        return value
    if isinstance(value, str) and value in STABILITY_METHODS:
        return STABILITY_METHODS[value]()
    allowed = " or ".join(repr(k) for k in STABILITY_METHODS)
    raise ValueError(
        f"`{name}` must be {allowed} (or a method object, rattle.Monodromy() or rattle.Hill()), got {value!r}"
    )


__all__ = [
    "AbstractStabilityMethod", "Monodromy", "Hill", "STABILITY_METHODS", "stability_method", "floquet_monitor",
]
