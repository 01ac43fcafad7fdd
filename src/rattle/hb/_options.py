"""Options of the harmonic balance discretisation (the Newton corrector's are in :mod:`rattle.continuation`)."""

from __future__ import annotations

from dataclasses import dataclass

from .._limits import PROBLEM_MAX_HARMONICS, PROBLEM_MAX_SAMPLES
from .._validate import check_int


def default_samples(harmonics: int) -> int:
    """Default AFT time samples per solution period: the power of two ≥ 32 H, at least 512.

    The restoring force of a piecewise-linear law has a kink wherever δ(t) crosses a breakpoint,
    so its samples carry an aliasing (quadrature) error O(N⁻²) in the balanced harmonics. With
    N ≥ 32 H (1024 for H = 32) the rms along the reference case's whole branch changes by less
    than 1e-4 (relative) when N is doubled, ten times below the 0.1 % accuracy target (tested).
    """
    n = max(512, 32 * harmonics)
    return 1 << (n - 1).bit_length()


@dataclass(frozen=True, slots=True, kw_only=True)
class HBOptions:
    """Harmonic balance settings.

    ``harmonics``: H, the harmonics of the solution's base frequency kept (≥ 1).
    ``samples``: N, time samples per solution period in the alternating frequency–time step
    (None: :func:`default_samples`); must be ≥ 4H + 2 so that the Jacobian's harmonics up to 2H
    are not folded.
    ``condense``: solve every Newton step of :func:`~rattle.continuation.solve_fixed` condensed
    onto the element deflections through the linear part's dynamic stiffness
    (:meth:`~rattle.hb.HarmonicBalance.newton_step`; same solution). Off by default: it pays only
    when the elements are few against the coordinates (``benchmarks/bench_hb_system.py``).
    """

    harmonics: int = 32
    samples: int | None = None
    condense: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.condense, bool):
            raise TypeError(f"`condense` must be true or false, got {self.condense!r}")
        # The object's own (hard) bounds are those of any single problem a run may build: the
        # 2H re-location of a branch of period p carries 2·p·H harmonics. The front ends apply the
        # tighter user-facing bounds of rattle._limits (H <= 256, H·period <= 512) before.
        h = check_int("harmonics", self.harmonics, 1)
        if h > PROBLEM_MAX_HARMONICS:
            raise ValueError(
                f"`harmonics` must be <= {PROBLEM_MAX_HARMONICS} in a single harmonic balance problem, got {h}: "
                "the Jacobian grows as H² in memory and H³ in time (H = 512 takes ~1 s per point); "
                "use 32 to 128"
            )
        object.__setattr__(self, "harmonics", h)
        if self.samples is not None:
            n = check_int("samples", self.samples, 1)
            if n < 4 * h + 2:
                raise ValueError(
                    f"`samples` must be >= 4*harmonics + 2 = {4 * h + 2} (so that the Jacobian "
                    f"is not aliased), got {n}"
                )
            if n > PROBLEM_MAX_SAMPLES:
                raise ValueError(
                    f"`samples` must be <= {PROBLEM_MAX_SAMPLES} in a single harmonic balance problem, got {n}: "
                    "the AFT matrices hold samples × (2·harmonics + 1) numbers; leave it out for the default"
                )
            object.__setattr__(self, "samples", n)

    @property
    def n_samples(self) -> int:
        return self.samples if self.samples is not None else default_samples(self.harmonics)


__all__ = ["HBOptions", "default_samples"]
