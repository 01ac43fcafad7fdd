"""The settings of a run, carried whole into every sub-problem.

One options object per concern — :class:`~rattle.hb.HBOptions` (harmonics, AFT samples),
:class:`~rattle.continuation.NewtonOptions`, :class:`~rattle.continuation.ContinuationOptions`
and the stability method object (:class:`~rattle.stability.Monodromy`,
:class:`~rattle.stability.Hill`; a name given at the boundary, ``stability="hill"``, is converted
here, once) — is resolved once by a front end and handed unchanged to every problem it
spawns: the 2H re-location of special points, period-doubling branch switching, seeded and
sweep-seeded branches, the orbits of :func:`~rattle.analysis.periodic_orbit`.

Rule for the sample count of a problem with another harmonic count H' (the 2H re-location, a
period-2p branch with 2H harmonics of Ω/2p, a period-n seed with n·H harmonics): an explicit
``samples`` N given for H is scaled with the harmonic count, N' = ⌈N·H'/H⌉ (the user's ratio
N/H, i.e. the same time resolution per harmonic, is kept; N' ≥ 4H' + 2 follows from
N ≥ 4H + 2); the default (``samples=None``) stays the default, ``default_samples(H')``, which
follows the same ratio rule (32 per harmonic, at least 512).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np

from ..continuation import ContinuationOptions, NewtonOptions
from ..hb import HBOptions
from ..stability import AbstractStabilityMethod, Monodromy, stability_method

#: What a front end accepts as ``stability``: a method object or its name.
StabilityMethod = AbstractStabilityMethod | Literal["monodromy", "hill"]


class _DefaultHarmonics(int):
    """A default harmonic count: an ``int`` that a front end can tell apart from the same
    number given explicitly (so that ``hb=HBOptions(harmonics=16)`` is not refused as a
    conflict with a ``harmonics`` the user never gave)."""

    def __repr__(self) -> str:
        return int.__repr__(self)

    __str__ = __repr__


#: Default ``harmonics`` of the analysis front ends (32; see :class:`_DefaultHarmonics`).
DEFAULT_HARMONICS: int = _DefaultHarmonics(32)
#: Default starting ``harmonics`` of adaptive_frequency_response (8).
DEFAULT_ADAPTIVE_HARMONICS: int = _DefaultHarmonics(8)


def resolve_hb(harmonics: int, samples: int | None, hb: HBOptions | None) -> HBOptions:
    """The HBOptions of a run from the plain ``harmonics``/``samples`` arguments or ``hb``.

    Raises
    ------
    TypeError
        ``hb`` is not an HBOptions.
    ValueError
        ``hb`` is given together with a ``harmonics`` or ``samples`` that disagrees with it.
    """
    # numpy integers (from arrays, or a parsed file) count as integers, as in the file's checks
    if isinstance(harmonics, np.integer):
        harmonics = int(harmonics)
    if isinstance(samples, np.integer):
        samples = int(samples)
    if hb is None:
        if isinstance(harmonics, _DefaultHarmonics):
            harmonics = int(harmonics)  # the marker does not leak into results and settings
        return HBOptions(harmonics=harmonics, samples=samples)
    if not isinstance(hb, HBOptions):
        raise TypeError(f"`hb` must be an HBOptions (rattle.HBOptions(harmonics=…, samples=…)) or None, got {hb!r}")
    if not isinstance(harmonics, _DefaultHarmonics) and harmonics != hb.harmonics:
        raise ValueError(
            f"`harmonics` = {harmonics!r} conflicts with `hb.harmonics` = {hb.harmonics}: give the harmonic "
            "count once, either as `harmonics=` or inside `hb=HBOptions(...)`"
        )
    if samples is not None and samples != hb.samples:
        raise ValueError(
            f"`samples` = {samples!r} conflicts with `hb.samples` = {hb.samples!r}: give the sample count "
            "once, either as `samples=` or inside `hb=HBOptions(...)`"
        )
    return hb


def scaled_hb(hb: HBOptions, harmonics: int) -> HBOptions:
    """``hb`` for a problem with ``harmonics`` harmonics (see the module's sample-count rule)."""
    if harmonics == hb.harmonics:
        return hb
    if hb.samples is None:
        return HBOptions(harmonics=harmonics)
    n = max(math.ceil(hb.samples * harmonics / hb.harmonics), 4 * harmonics + 2)
    return HBOptions(harmonics=harmonics, samples=n)


def check_stability(stability: object) -> AbstractStabilityMethod:
    """The stability method object of ``stability`` (a method object, or ``"monodromy"``/``"hill"``)."""
    return stability_method(stability, "stability")


@dataclass(frozen=True, slots=True)
class RunSettings:
    """The options of one run, handed unchanged to every sub-problem."""

    hb: HBOptions
    newton: NewtonOptions
    continuation: ContinuationOptions
    stability: AbstractStabilityMethod = Monodromy()

    @classmethod
    def make(cls, hb: HBOptions, newton: NewtonOptions | None, continuation: ContinuationOptions | None,
             stability: StabilityMethod = "monodromy") -> "RunSettings":
        """The settings of a run from the front end's arguments: ``None`` options take their
        defaults, a stability method's name becomes its object (the one conversion)."""
        if continuation is not None and not isinstance(continuation, ContinuationOptions):
            raise TypeError(f"`continuation` must be a ContinuationOptions, got {continuation!r}")
        if newton is not None and not isinstance(newton, NewtonOptions):
            raise TypeError(f"`newton` must be a NewtonOptions, got {newton!r}")
        return cls(hb, newton or NewtonOptions(), continuation or ContinuationOptions(), check_stability(stability))

    def for_harmonics(self, harmonics: int) -> HBOptions:
        """The HBOptions of a sub-problem with ``harmonics`` harmonics (sample rule above)."""
        return scaled_hb(self.hb, harmonics)

    def record(self, hb: HBOptions | None = None, **extra: Any) -> dict[str, Any]:
        """The settings actually used by one (sub-)problem, JSON-serialisable."""
        h = self.hb if hb is None else hb
        return {
            "harmonics": h.harmonics, "samples": h.n_samples, "samples_given": h.samples,
            "stability": self.stability.name, "newton": asdict(self.newton), "continuation": asdict(self.continuation),
            **extra,
        }


__all__ = ["DEFAULT_HARMONICS", "DEFAULT_ADAPTIVE_HARMONICS", "RunSettings", "resolve_hb", "scaled_hb", "check_stability", "StabilityMethod"]
