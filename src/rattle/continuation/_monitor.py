"""Test-function monitoring: step control that cannot step over a bifurcation.

A special point of a branch is a zero of a scalar test function ψ(s) of the arc length s (for
periodic orbits ψ_fold = det(M − I), ψ_pd = det(M + I) of the monodromy M; see
``rattle.stability``). The bordered corrector converges happily across any number of them, so
the step control by Newton iterations and tangent turn alone can carry a step over an *even*
number of zeros — a period-doubling pair — whose sign changes cancel: the unstable stretch
between them is then drawn stable. This module decides, for each trial step, whether the test
functions have been resolved. At both ends a of b of a trial step of scaled length L the
monitor supplies ψ and its derivative ψ' along the unit tangent; between them ψ is modelled by
the cubic Hermite interpolant

    p(s) = h00(s/L) ψ_a + h10(s/L) L ψ'_a + h01(s/L) ψ_b + h11(s/L) L ψ'_b,  0 ≤ s ≤ L,

whose error is estimated pointwise by its difference e(s) from the two quadratics that drop one
end slope (a lower-order model's error, which vanishes at both ends). For each test function
(the step is judged by the worst):

* hidden zeros: p has a zero in (0, L) while ψ_a, ψ_b have the same sign (or p has three
  where they show one) → the step is rejected and retried at half the length, so that the
  continuation points themselves bracket every zero and each is located on its own;
* resolution: where ψ keeps its sign the model must keep |p(s)| − e(s) > 0 inside the step
  (else rejected); the next step is scaled by min_s (θ |p(s)| / e(s))^{1/3} (e grows like L³),
  so steps are refined, never coarsened, as a multiplier approaches its critical value, and
  are not restricted where ψ is far from zero compared with its variation;
* non-smooth points: when the opaque ``structure`` of the two ends differs (for piecewise-linear
  laws: the orbit grazed a breakpoint, where M has a square-root singularity and a border
  collision may flip ψ) the slopes do not describe the interior, and the step is rejected
  whenever the variation |ψ_b − ψ_a| + L(|ψ'_a| + |ψ'_b|)/2 could reach zero;
* near the unit circle (a multiplier within ``NEAR_CRITICAL`` of +1 or −1) the step may
  shrink, and grows only while |ψ| / |ψ'| exceeds the present step (at the present rate no
  test function could reach zero within it);
* movement: ψ may change by at most ``max_change`` × (1 + min(|ψ_a|, |ψ_b|)) per step (twice
  that rejects the step): this bounds how far the multipliers move in one step;
* two kinds at once: when two test functions change sign over one step (a fold and a period
  doubling close together, with several multipliers) the step is rejected: their effects on
  stability could cancel between the ends, hiding both changes of stability.

Rejection stops once the step is down to ``resolution``: a pair of zeros closer together than
that is below what a continuation can resolve and is reported by the locator as one interval.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._lazy import import_held
from .._typing import FloatArray

#: A multiplier within this distance of its critical value (+1, −1) is "near the unit circle":
#: the step may shrink but not grow there.
NEAR_CRITICAL = 0.1
#: A test function this small (relative to 1 + |ψ| at the other end) is a zero: the end is a
#: located special point (e.g. the period-doubling point a sub-harmonic branch starts from).
AT_ZERO = 1e-7


@dataclass(frozen=True, slots=True)
class MonitorReading:
    """Test functions at one branch point.

    ``values`` ψ_k (m,), ``slopes`` dψ_k/ds along the unit tangent in scaled arc length (m,),
    ``structure`` an opaque, comparable signature of the smooth piece the point lies on (two
    points with different structures may have a non-smooth ψ between them), ``distance`` the
    distance of the nearest critical multiplier to its critical value (≥ 0; informative).
    """

    values: FloatArray
    slopes: FloatArray
    structure: object = None
    distance: float = math.inf


#: monitor(q, p, dq/ds, dp/ds) → reading; dq/ds, dp/ds the unit tangent in unscaled units.
Monitor = Callable[[FloatArray, float, FloatArray, float], MonitorReading]


@dataclass(frozen=True, slots=True)
class SegmentVerdict:
    """``accept`` the step or not, the step ``factor`` the monitor allows next, and ``reason``."""

    accept: bool
    factor: float
    reason: str = ""


def _hermite_coefficients(pa: float, ga: float, pb: float, gb: float, L: float) -> FloatArray:
    """Coefficients (highest power first) of the cubic Hermite p(x), x = s/L ∈ [0, 1]."""
    ma, mb = ga * L, gb * L
    c3 = 2 * pa + ma - 2 * pb + mb
    c2 = -3 * pa - 2 * ma + 3 * pb - mb
    return np.array([c3, c2, ma, pa])


def _roots_inside(coef: FloatArray) -> int:
    """Number of distinct real roots of the polynomial in the open interval (0, 1)."""
    c = np.trim_zeros(coef, "f")
    if c.size <= 1:
        return 0
    r = np.roots(c)
    real = r[np.abs(r.imag) <= 1e-9 * np.maximum(1.0, np.abs(r))].real
    return int(np.sum((real > 1e-12) & (real < 1 - 1e-12)))


_X = np.linspace(0.0, 1.0, 33)
_X2 = _X**2


def _model_and_error(pa: float, ga: float, pb: float, gb: float, L: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Cubic Hermite coefficients, its values on x ∈ [0, 1] and an error estimate there.

    The error estimate is the larger difference between the cubic and the two quadratics that
    drop one of the end slopes (one matches ψ_a, ψ'_a, ψ_b; the other ψ_a, ψ_b, ψ'_b): the
    error of a lower-order model, a pessimistic bound for the cubic's. It vanishes at the ends,
    so a test function that has just crossed zero at an end does not hold the step back.
    """
    coef = _hermite_coefficients(pa, ga, pb, gb, L)
    p = np.polyval(coef, _X)
    ma, mb = ga * L, gb * L
    q1 = pa + ma * _X + (pb - pa - ma) * _X2  # ψ_a, ψ'_a, ψ_b
    k2 = mb - (pb - pa)  # ψ_a, ψ_b, ψ'_b: q2 = pa + (pb - pa - k2) x + k2 x²
    q2 = pa + (pb - pa - k2) * _X + k2 * _X2
    err = np.maximum(np.abs(p - q1), np.abs(p - q2))
    return coef, p, err


def _margins_array(pa: float, ga: float, pb: float, gb: float, L: float, sign: float, tolerance: float,
                   X: FloatArray, X2: FloatArray) -> tuple[float, float, float, bool]:
    """What the step control reads of the model of a test function that keeps its sign (``sign``):
    min sign·p, min over the interior of sign·p − e, min over the interior points with e > 0 of
    θ sign·p / e (inf without such a point), and whether there is one — by the array code
    (the reference of the compiled ``_kernels.hermite_scan``, which is used when numba is there)."""
    _, p, err = _model_and_error(pa, ga, pb, gb, L)
    sp = sign * p
    inner = slice(1, -1)
    e = err[inner]
    gap = sp - err
    positive = e > 0.0
    ratio = float(np.min(tolerance * sp[inner][positive] / e[positive])) if positive.any() else math.inf
    return float(np.min(sp)), float(np.min(gap[inner])), ratio, bool(positive.any())


_SCAN = None


def _floats(values: FloatArray) -> list[float]:
    """The entries of a reading's array as Python floats."""
    return np.asarray(values, dtype=float).tolist()


def _scan():
    """The compiled Hermite scan (loaded on first use, in the middle of a run: the stop signals
    held during the import, ``import_held``), else the array code."""
    global _SCAN
    if _SCAN is None:
        kernels = import_held("rattle.continuation._kernels")
        _SCAN = kernels.hermite_scan if kernels.AVAILABLE else _margins_array
    return _SCAN


def check_segment(
    a: MonitorReading,
    b: MonitorReading,
    length: float,
    *,
    tolerance: float,
    max_change: float,
    resolved: bool,
) -> SegmentVerdict:
    """Judge a trial step of scaled ``length`` from reading ``a`` to reading ``b``.

    ``tolerance`` θ ∈ (0, 1): the error estimate of the cubic model may use at most this
    fraction of the model's distance from zero before the next step is shortened;
    ``max_change`` the movement bound; ``resolved`` says the step is already at the resolution
    floor (then nothing is rejected; the factor still applies). See the module docstring.
    """
    factor = 2.0
    scan = _scan()
    smooth = a.structure == b.structure
    crossed = 0  # test functions that change sign over the step
    for pa, ga, pb, gb in zip(_floats(a.values), _floats(a.slopes), _floats(b.values), _floats(b.slopes)):
        if not (math.isfinite(pa) and math.isfinite(pb)):
            continue  # no information (an overflowing, strongly unstable monodromy): nothing to bound
        kinked = not smooth or not (math.isfinite(ga) and math.isfinite(gb))  # no usable slope
        change = (pb > 0) != (pa > 0)
        move = abs(pb - pa)
        scale = 1.0 + min(abs(pa), abs(pb))
        if min(abs(pa), abs(pb)) <= AT_ZERO * (1.0 + max(abs(pa), abs(pb))):
            # An end sits on a zero (a branch started at a located special point): its sign is
            # round-off, and a second zero within the same step cannot be told from it.
            continue
        if change:
            crossed += 1
            if crossed >= 2 and not resolved:
                # Two multipliers cross the unit circle within one step (e.g. a fold and a period
                # doubling close together): their effects on stability may cancel between the
                # ends, so the stability of the stretch between them would be hidden.
                return SegmentVerdict(False, 0.5, "two test functions change sign in one step")
        if move > max_change * scale:
            factor = min(factor, max_change * scale / move)
            if move > 2.0 * max_change * scale and not resolved:
                return SegmentVerdict(False, 0.5, "the multipliers moved too far in one step")
        if kinked:
            # A kink between the ends (grazing): the end slopes say nothing about the interior.
            slopes = [abs(g) for g in (ga, gb) if math.isfinite(g)]
            reach = move + 0.5 * length * sum(slopes)
            if not change and reach >= min(abs(pa), abs(pb)) and not resolved:
                return SegmentVerdict(False, 0.5, "non-smooth test function near zero")
            continue
        if change:
            if not resolved and _roots_inside(_hermite_coefficients(pa, ga, pb, gb, length)) >= 3:
                return SegmentVerdict(False, 0.5, "more than one test-function zero in one step")
            continue
        sign = 1.0 if pa > 0 else -1.0
        # min sign·p, min of the distance from zero that the model guarantees (sign·p − e, inside
        # the step), min θ sign·p / e: on the grid x ∈ [0, 1] (_model_and_error), compiled
        min_p, min_gap, ratio, has_error = scan(pa, ga, pb, gb, length, sign, tolerance, _X, _X2)
        if (min_p <= 0.0 or min_gap <= 0.0) and not resolved:
            reason = "hidden pair of test-function zeros" if min_p <= 0.0 else "test function not resolved"
            return SegmentVerdict(False, 0.5, reason)
        if has_error:
            # err grows like L^3: aim for err <= theta x (the model's distance from zero), pointwise.
            factor = min(factor, float(max(ratio, 0.0)) ** (1.0 / 3.0))
    if b.distance < NEAR_CRITICAL and factor > 1.0:
        # Near the unit circle the step grows only while, at the present rate, no test function
        # would reach zero within the present step (a step shrunk for another reason, e.g. a
        # corrector failure at a branch point, is not frozen).
        reach = [abs(v) / (abs(g) * length) for v, g in zip(b.values, b.slopes)
                 if math.isfinite(v) and math.isfinite(g) and g != 0.0 and length > 0.0]
        factor = min(factor, max(1.0, min(reach, default=1.0)))
    return SegmentVerdict(True, factor)


__all__ = ["Monitor", "MonitorReading", "SegmentVerdict", "check_segment"]
