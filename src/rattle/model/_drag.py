"""Drag torque by speed (SPEC §6 ``[drag]``): a mean load that changes with the forcing frequency.

The transmission's drag torque D(n) (churning, bearing and seal losses) grows with the
crankshaft speed n and acts on one inertia j against the mean motion. It is tabulated at speeds
n_1 < … < n_K and interpolated linearly, constant outside the table:

    D(n) = D_k + (D_{k+1} − D_k) (n − n_k)/(n_{k+1} − n_k),   n_k ≤ n ≤ n_{k+1},

and, with the engine order q_0 of the forcing frequency (Ω = q_0 · 2π/60 · n), it is a function of
Ω. The mean torques of the chain then depend on Ω:

    T_m(Ω) = T_m − D(Ω) e_j + D(Ω) e_b,

where e_b is the inertia whose mean torque balances the drag (``balance``): on a free chain (no
link to ground) the engine must deliver the drag at every speed — otherwise the whole chain
accelerates — so the engine's mean torque is D(Ω) on its inertia b ("no power" balance, SPEC §1).
On a grounded chain ``balance`` may be left out: the ground holds the drag.

A :class:`Drag` is part of a :class:`~rattle.model.Chain`; the chain reduces it to a
:class:`~rattle.model.SpeedLoad` of its :class:`~rattle.model.System` (F_0(Ω) = F_0 + D(Ω) u with
u = D M⁻¹ (e_b − e_j)), which the harmonic balance carries in its residual (the a_0 terms and the
Ω-derivative) and every time-domain analysis evaluates at its Ω.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from ._elastic import _check_real_sequence

#: rad/s per rpm of a first-order quantity: 2π / 60.
_RAD_PER_S_PER_RPM = 2.0 * math.pi / 60.0


def _inertia_number(name: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"`{name}` must be an integer inertia number, got {value!r}")
    if value < 0:
        raise ValueError(f"`{name}` must be an inertia number >= 1 (or 0: ground), got {value!r}")
    return int(value)


@dataclass(frozen=True, slots=True, kw_only=True)
class Drag:
    """Drag torque ``torque`` (N m, ≥ 0) at crankshaft speeds ``speed_rpm`` (strictly increasing,
    > 0) on inertia ``inertia``, opposing the mean motion; linear interpolation, constant outside.
    ``balance``: the inertia whose mean torque delivers the drag at every speed (required on a
    free chain: the engine's inertia). ``inertia = 0`` (ground, with a ``balance``) is a drag
    whose reaction the ground takes: + D on ``balance`` only — the form a drag takes in a
    relative coordinate (a loose gear's δ = (r1/r2) θ1 − θ2, :func:`~rattle.model.loose_gear`)."""

    inertia: int
    speed_rpm: tuple[float, ...]
    torque: tuple[float, ...]
    balance: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia", _inertia_number("inertia", self.inertia))
        if self.inertia == 0 and self.balance is None:
            raise ValueError("`inertia` = 0 (ground) needs a `balance`: the inertia on which the drag acts through "
                             "its reaction; give the inertia the drag acts on, or a balance")
        if self.balance is not None:
            object.__setattr__(self, "balance", _inertia_number("balance", self.balance))
            if self.balance == 0:
                raise ValueError("`balance` must be an inertia number >= 1, got 0: ground takes a drag's reaction "
                                 "when `balance` is left out")
            if self.balance == self.inertia:
                raise ValueError(f"`balance` must be another inertia than the drag's `inertia` ({self.inertia}): the "
                                 "drag and the torque that delivers it on the same inertia cancel")
        rpm = _check_real_sequence("speed_rpm", self.speed_rpm)
        torque = _check_real_sequence("torque", self.torque)
        if not rpm:
            raise ValueError("`speed_rpm` must hold at least one speed, got []")
        if len(torque) != len(rpm):
            raise ValueError(f"`torque` must have one entry per speed of `speed_rpm` ({len(rpm)}), got {len(torque)}")
        for k, v in enumerate(rpm):
            if not v > 0:
                raise ValueError(f"`speed_rpm[{k}]` must be > 0 rpm, got {v!r}")
        for k in range(1, len(rpm)):
            if not rpm[k] > rpm[k - 1]:
                raise ValueError(
                    f"`speed_rpm` must be strictly increasing (a table of the drag by speed), but speed_rpm[{k}] = "
                    f"{rpm[k]!r} follows {rpm[k - 1]!r}; sort the table by speed and give each speed once"
                )
        for k, v in enumerate(torque):
            if v < 0:
                raise ValueError(f"`torque[{k}]` must be >= 0 (the drag's magnitude; it always opposes the mean "
                                 f"motion), got {v!r}")
        object.__setattr__(self, "speed_rpm", rpm)
        object.__setattr__(self, "torque", torque)

    def at_rpm(self, rpm: FloatArray | float) -> FloatArray:
        """D at crankshaft speeds ``rpm`` (linear interpolation, constant outside the table)."""
        return np.interp(np.asarray(rpm, dtype=float), self.speed_rpm, self.torque)

    def to_dict(self) -> dict[str, object]:
        out: dict[str, object] = {"inertia": self.inertia, "speed_rpm": list(self.speed_rpm), "torque": list(self.torque)}
        if self.balance is not None:
            out["balance"] = self.balance
        return out


@dataclass(frozen=True, slots=True, eq=False)
class SpeedLoad:
    """The Ω-dependent part of a system's mean forcing: F_0(Ω) = F_0 + d(Ω) ``direction``, with
    d(Ω) interpolated linearly between ``values`` at the frequencies ``nodes`` (strictly
    increasing, rad/s) and constant outside; d'(Ω) is the slope of the segment holding Ω (the
    right-hand one at a node, 0 outside)."""

    nodes: FloatArray
    values: FloatArray
    direction: FloatArray

    def value(self, omega: FloatArray | float) -> FloatArray:
        """d(Ω)."""
        return np.interp(omega, self.nodes, self.values)

    def slope(self, omega: float) -> float:
        """d'(Ω) (piecewise constant)."""
        nodes = self.nodes
        if nodes.size < 2 or not nodes[0] <= omega < nodes[-1]:
            return 0.0
        k = int(np.searchsorted(nodes, omega, side="right")) - 1
        return float((self.values[k + 1] - self.values[k]) / (nodes[k + 1] - nodes[k]))

    @property
    def largest(self) -> float:
        """max |d| over the table."""
        return float(np.max(np.abs(self.values))) if self.values.size else 0.0


def drag_load(drag: Drag, speed_order: float, direction: FloatArray) -> SpeedLoad:
    """The :class:`SpeedLoad` of ``drag`` with forcing frequency Ω = ``speed_order`` · 2π/60 · rpm and
    reduced force ``direction`` u per unit drag torque."""
    nodes = np.asarray(drag.speed_rpm, dtype=float) * (speed_order * _RAD_PER_S_PER_RPM)
    return SpeedLoad(nodes=nodes, values=np.asarray(drag.torque, dtype=float), direction=np.asarray(direction, dtype=float))


__all__ = ["Drag", "SpeedLoad", "drag_load"]
