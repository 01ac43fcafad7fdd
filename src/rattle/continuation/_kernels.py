"""Compiled scan of the monitor's cubic model (numba), for :func:`._monitor.check_segment`.

Between two readings the monitor models a test function by the cubic Hermite p(x) and bounds its
error by e(x) = max(|p − q₁|, |p − q₂|) on the 33 points x_i = i/32 (``_monitor``). In numpy that
is some twenty calls on arrays of 33 numbers per test function and trial step; here it is one loop
with the same floating-point operations in the same order (Horner's rule as ``numpy.polyval``,
the quadratics term by term as the array expressions), so the verdicts and step factors are
identical to the last bit. It returns what the step control reads:

* min_i sign·p(x_i) (a hidden zero when ≤ 0),
* min over the interior points of sign·p(x_i) − e(x_i) (the model not resolved when ≤ 0),
* min over the interior points with e > 0 of θ sign·p(x_i) / e(x_i) (inf when e = 0 there).

``AVAILABLE`` is False when numba cannot be imported; the array code of ``_monitor`` is then used.
"""

from __future__ import annotations

import math

from .._jit import njit, numba  # numba is a dependency; the array code stays the fallback (and the reference)

AVAILABLE = numba is not None


def _hermite_scan(pa, ga, pb, gb, L, sign, tolerance, X, X2):
    """(min sign·p, min interior sign·p − e, min interior θ sign·p / e over e > 0, any e > 0)
    of the cubic Hermite through (ψ_a, ψ'_a), (ψ_b, ψ'_b) on the grid X (X2 = X²)."""
    ma = ga * L
    mb = gb * L
    c3 = 2 * pa + ma - 2 * pb + mb
    c2 = -3 * pa - 2 * ma + 3 * pb - mb
    d1 = pb - pa - ma
    k2 = mb - (pb - pa)
    d2 = pb - pa - k2
    last = X.size - 1
    min_sp = math.inf
    min_gap = math.inf
    ratio = math.inf
    any_e = False
    # The minima propagate NaN as numpy.min does (v != v: NaN; once NaN a minimum stays NaN).
    for i in range(X.size):
        x = X[i]
        p = (((0.0 * x + c3) * x + c2) * x + ma) * x + pa  # numpy.polyval: y = y·x + c from y = 0
        q1 = (pa + ma * x) + d1 * X2[i]
        q2 = (pa + d2 * x) + k2 * X2[i]
        e1 = abs(p - q1)
        e2 = abs(p - q2)
        e = e1 if (e1 >= e2 or e1 != e1) else e2  # numpy.maximum (NaN wins)
        if e2 != e2:
            e = e2
        sp = sign * p
        if sp < min_sp or sp != sp:
            min_sp = sp
        if 0 < i < last:
            gap = sp - e
            if gap < min_gap or gap != gap:
                min_gap = gap
            if e > 0.0:
                any_e = True
                r = tolerance * sp / e
                if r < ratio or r != r:
                    ratio = r
    return min_sp, min_gap, ratio, any_e


if AVAILABLE:
    hermite_scan = njit(_hermite_scan)
else:  # pragma: no cover
    hermite_scan = None

__all__ = ["AVAILABLE", "hermite_scan"]
