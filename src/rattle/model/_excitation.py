"""Engine excitation: a mean and harmonics of the forcing frequency Ω with phases.

    F(t) = F_m + Σ_{n=1}^{N} F_pn cos(n Ω t + φ_n)

(forces per inertia, the right-hand side of the equation in δ).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from ._elastic import _check_real, _check_real_sequence


@dataclass(frozen=True, slots=True, kw_only=True)
class Excitation:
    """Mean ``mean`` = F_m and harmonic ``amplitudes`` F_p1, F_p2, … with ``phases`` φ_n (rad)."""

    mean: float
    amplitudes: tuple[float, ...]
    phases: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        mean = _check_real("mean", self.mean)
        amps = _check_real_sequence("amplitudes", self.amplitudes)
        if len(amps) == 0:
            raise ValueError("`amplitudes` must hold at least one harmonic amplitude, got []")
        if self.phases is None:
            phases = (0.0,) * len(amps)
        else:
            phases = _check_real_sequence("phases", self.phases)
            if len(phases) != len(amps):
                raise ValueError(
                    f"`phases` must have one entry per amplitude ({len(amps)}), got {len(phases)}"
                )
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "amplitudes", amps)
        object.__setattr__(self, "phases", phases)

    @property
    def orders(self) -> np.ndarray:
        """Harmonic orders n = 1 … N of the forcing, shape (N,)."""
        return np.arange(1, len(self.amplitudes) + 1)

    @property
    def amplitude_scale(self) -> float:
        """Σ |F_pn|, the largest possible dynamic force."""
        return float(np.sum(np.abs(self.amplitudes)))

    def __call__(self, t: FloatArray | float, omega: FloatArray | float) -> FloatArray:
        """F(t) at times ``t`` for forcing frequency ``omega`` (arrays broadcast together)."""
        t = np.asarray(t, dtype=float)
        out = np.full(t.shape, self.mean)
        for n, amp, phi in zip(self.orders, self.amplitudes, self.phases):  # type: ignore[arg-type]
            out = out + amp * np.cos(n * omega * t + phi)
        return out

    def to_dict(self) -> dict[str, object]:
        return {"mean": self.mean, "amplitudes": list(self.amplitudes), "phases": list(self.phases or ())}


__all__ = ["Excitation"]
