"""Engine excitation by order (SPEC §6): orders → harmonics of a base frequency, rpm ↔ Ω.

An engine order q is a multiple of the crankshaft speed n (rpm): its frequency is
q · 2π n / 60 rad/s. The harmonic balance forces at the harmonics h = 1, 2, … of one base
frequency Ω, so the orders of one engine must be integer multiples of a common base order
q_0 (their largest common divisor): Ω = q_0 · 2π n / 60 and order q sits at harmonic
h = q / q_0. Each order is written as a fraction with a denominator of at most
:data:`MAX_DENOMINATOR` (half orders of four-stroke engines are 1/2; a 3-cylinder four-stroke
fires at order 3/2) accepted only when it matches the order given to :data:`ORDER_RTOL`
relative; q_0 is the gcd of the fractions.

No I/O here: the reader of the model tables (:mod:`._tables`) calls :func:`engine_torque`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction

import numpy as np

from .._limits import MAX_HARMONICS
from .._validate import check_positive
from ._chain import Torque

#: Largest denominator of an order written as a fraction (1/2: half orders; up to 1/12).
MAX_DENOMINATOR = 12
#: Relative tolerance within which an order must equal its fraction.
ORDER_RTOL = 1e-9
#: rad/s per rpm of a first-order quantity: 2π / 60.
RAD_PER_S_PER_RPM = 2.0 * math.pi / 60.0


def forcing_frequency(rpm: float | np.ndarray, order: float) -> float | np.ndarray:
    """Ω (rad/s) of engine order ``order`` at crankshaft speed ``rpm``: Ω = order · 2π/60 · rpm."""
    q = check_positive(order, "order")
    return q * RAD_PER_S_PER_RPM * np.asarray(rpm, dtype=float) if np.ndim(rpm) else q * RAD_PER_S_PER_RPM * float(rpm)


def engine_speed(omega: float | np.ndarray, order: float) -> float | np.ndarray:
    """Crankshaft speed (rpm) at which engine order ``order`` has frequency ``omega`` (rad/s):
    rpm = Ω · 60 / (2π · order)."""
    q = check_positive(order, "order")
    return np.asarray(omega, dtype=float) / (q * RAD_PER_S_PER_RPM) if np.ndim(omega) else float(omega) / (q * RAD_PER_S_PER_RPM)


def firing_orders(cylinders: int, strokes: int = 4, count: int = 3) -> tuple[float, ...]:
    """The main firing orders of an engine with ``cylinders`` cylinders, evenly firing:
    the firing order k · cylinders/2 of a four-stroke (one firing per cylinder every two
    revolutions), k · cylinders of a two-stroke, k = 1 … ``count``.

    >>> firing_orders(4)
    (2.0, 4.0, 6.0)
    >>> firing_orders(3, count=2)
    (1.5, 3.0)
    """
    for name, v, lo in (("cylinders", cylinders, 1), ("count", count, 1)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise ValueError(f"`{name}` must be an integer >= {lo}, got {v!r}")
    if strokes not in (2, 4) or isinstance(strokes, bool):
        raise ValueError(f"`strokes` must be 2 or 4, got {strokes!r}")
    per_rev = cylinders / 2.0 if strokes == 4 else float(cylinders)
    return tuple(k * per_rev for k in range(1, int(count) + 1))


def as_fraction(order: float, name: str = "order") -> Fraction:
    """``order`` as a fraction with a denominator <= :data:`MAX_DENOMINATOR`, matching it to
    :data:`ORDER_RTOL` relative; ValueError otherwise."""
    q = check_positive(order, name)
    f = Fraction(q).limit_denominator(MAX_DENOMINATOR)
    if f <= 0 or abs(float(f) - q) > ORDER_RTOL * q:
        raise ValueError(
            f"`{name}` = {q!r} is not a fraction with a denominator of at most {MAX_DENOMINATOR} (to "
            f"{ORDER_RTOL:g} relative; nearest {f}): the engine orders must be multiples of one base order "
            "(e.g. 2, 4, 6 or the half orders 0.5, 1.5, 2); write the order exactly"
        )
    return f


def base_order(orders: Sequence[float], name: str = "orders") -> tuple[Fraction, tuple[int, ...]]:
    """The base order q_0 (largest common divisor of ``orders``) and each order's harmonic
    number h = q / q_0.

    >>> base_order([2.0, 4.0])
    (Fraction(2, 1), (1, 2))
    >>> base_order([0.5, 1.5, 2.0])
    (Fraction(1, 2), (1, 3, 4))

    Raises ValueError (naming ``name``) when an order is not a small-denominator fraction
    (incommensurate orders) or when a harmonic number would exceed
    :data:`rattle._limits.MAX_HARMONICS`.
    """
    if isinstance(orders, (str, bytes)) or not hasattr(orders, "__len__") or len(orders) == 0:
        raise ValueError(f"`{name}` must be a non-empty list of engine orders, got {orders!r}")
    fracs = [as_fraction(q, f"{name}[{i}]") for i, q in enumerate(orders)]
    num = 0
    den = 1
    for f in fracs:
        den = den * f.denominator // math.gcd(den, f.denominator)
    for f in fracs:
        num = math.gcd(num, f.numerator * (den // f.denominator))
    base = Fraction(num, den)
    harmonics = tuple(int(f / base) for f in fracs)
    if len(set(harmonics)) != len(harmonics):
        raise ValueError(f"`{name}` must not repeat an order, got {list(orders)!r}")
    if max(harmonics) > MAX_HARMONICS:
        raise ValueError(
            f"`{name}` = {list(orders)!r} have the base order {base} (their largest common divisor), so the "
            f"highest order is harmonic {max(harmonics)} of it, above the limit of {MAX_HARMONICS} harmonics: "
            "the orders are (nearly) incommensurate; round them to simpler fractions of a common base order"
        )
    return base, harmonics


def engine_torque(
    inertia: int,
    orders: Sequence[float],
    amplitudes: Sequence[float],
    phases: Sequence[float] | None = None,
    mean: float = 0.0,
) -> tuple[Torque, float]:
    """The engine's torque on ``inertia`` as an ordinary :class:`Torque` in harmonics of the
    base order, and that base order (float).

    ``amplitudes`` (N m, >= 0) and ``phases`` (rad, default 0) are one per order; they go to
    the harmonics h = order / base order, zeros between.

    >>> t, q0 = engine_torque(1, [2.0, 4.0], [60.0, 15.0])
    >>> q0, t.amplitudes
    (2.0, (60.0, 15.0))
    """
    base, harmonics = base_order(orders)
    if len(amplitudes) != len(orders):
        raise ValueError(f"`amplitudes` must have one entry per order ({len(orders)}), got {len(amplitudes)}")
    if phases is not None and len(phases) != len(orders):
        raise ValueError(f"`phases` must have one entry per order ({len(orders)}), got {len(phases)}")
    for i, a in enumerate(amplitudes):
        if isinstance(a, bool) or not isinstance(a, (int, float, np.integer, np.floating)) or not math.isfinite(a) or a < 0:
            raise ValueError(f"`amplitudes[{i}]` must be a finite number >= 0 (N m), got {a!r}")
    n = max(harmonics)
    amps = [0.0] * n
    ph = [0.0] * n
    for k, h in enumerate(harmonics):
        amps[h - 1] = float(amplitudes[k])
        ph[h - 1] = float(phases[k]) if phases is not None else 0.0
    return Torque(inertia=inertia, mean=mean, amplitudes=tuple(amps), phases=tuple(ph)), float(base)


__all__ = [
    "firing_orders", "engine_speed", "forcing_frequency", "base_order", "as_fraction", "engine_torque",
    "MAX_DENOMINATOR", "ORDER_RTOL", "RAD_PER_S_PER_RPM",
]
