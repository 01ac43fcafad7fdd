"""Period-2 branches of the regularised harmonic balance: shared by the single equation
(:func:`rattle.analysis.nonsmooth_subharmonics`) and the chain with friction
(:func:`rattle.analysis.friction_subharmonics`).

A period-2 orbit is written with H₂ harmonics of ω = Ω/2: its odd harmonics are what the
period-1 orbit run twice does not have. Its share of the fluctuation,

    s(q) = ‖q_odd‖ / ‖q_{k ≥ 1}‖   (over every coordinate's series),

tells a period-2 orbit (s ≥ :data:`ODD_SHARE`) from the period-1 orbit it rejoins at a period
doubling (s → 0, and the odd part changes sign as the branch passes through it).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np

from .._typing import FloatArray
from ..continuation import (
    BranchPoint,
    ContinuationOptions,
    ContinuationProblem,
    ContinuationStepper,
    NewtonOptions,
    solve_fixed,
)
from ..errors import RattleError, Status
from ._branches import odd_indices
from ._regularisation import regularisation_limit

T = TypeVar("T")  # an exact orbit
B = TypeVar("B")  # a branch (a response with ``omega``)

#: A period-2 orbit counts as one (not the period-1 orbit run twice) while its odd harmonics of
#: Ω/2 carry at least this share of δ's fluctuation (rms); a branch that falls below it has
#: rejoined a period-1 branch.
ODD_SHARE = 1e-4


def _odd(q: FloatArray, coordinates: int) -> np.ndarray:
    """The indices of the odd harmonics in ``q`` (``coordinates`` series of 2H + 1, coordinate-major)."""
    return odd_indices((q.size // coordinates - 1) // 2, coordinates)


def odd_share(q: FloatArray, coordinates: int = 1) -> float:
    """s(q) = ‖odd harmonics‖ / ‖all harmonics‖ of ``coordinates`` series of Ω/2 (module
    docstring; 0 for a period-1 orbit)."""
    q = np.asarray(q, dtype=float)
    fluct = q.reshape(coordinates, -1)[:, 1:]
    total = float(np.linalg.norm(fluct))
    return float(np.linalg.norm(q[_odd(q, coordinates)])) / total if total > 0 else 0.0


def beyond_minus_one(multipliers: np.ndarray) -> bool:
    """Whether one of the real ``multipliers`` lies beyond −1: the orbit is unstable by a period
    doubling, and a period-2 orbit is born next to it."""
    mu = np.asarray(multipliers)
    return bool(np.any((mu.real < -1.0) & (np.abs(mu.imag) < 1e-9)))


def doublings(omega: FloatArray, matched: np.ndarray, labels: np.ndarray,
              multipliers: np.ndarray) -> list[tuple[float, float, list[int]]]:
    """The period doublings of a period-1 branch (rows ``omega``, ``matched``, bifurcation
    ``labels``, exact ``multipliers``): per doubling labelled between two matched rows a and b,
    (Ω_a, Ω_b, [a, b] ordered with the row whose multiplier lies beyond −1 first: the side where
    the period-2 orbit is born when the doubling is supercritical)."""
    rows = np.flatnonzero(matched)
    out = []
    for a, b in zip(rows[:-1].tolist(), rows[1:].tolist()):
        if labels[b] != "period_doubling":
            continue
        beyond = [i for i in (a, b) if beyond_minus_one(multipliers[i])]
        out.append((float(omega[a]), float(omega[b]), beyond + [i for i in (a, b) if i not in beyond]))
    return out


#: A period-2 seed is shot from the period-1 state pushed along the eigenvector by these shares of
#: the orbit's peak-to-peak, each either way, in this order.
PUSHES = (0.02, 0.1, 0.3)


def pushed_starts(monodromy: FloatArray, state: FloatArray, scale: FloatArray, size: float,
                  length: float) -> list[FloatArray]:
    """The starts of the shooting for a period-2 orbit next to the period-1 orbit through ``state``
    whose ``monodromy`` has a multiplier near −1: the state pushed along the eigenvector v of the
    negative real multiplier nearest −1 (unit length in the state scaled by ``scale``), by a of
    :data:`PUSHES` times ``size`` (the orbit's peak-to-peak) relative to ``length`` (L), either
    way: z = state ± a · size / L · v. Empty when no multiplier is real and negative."""
    mu, vec = np.linalg.eig(np.asarray(monodromy, dtype=float))
    negative = [k for k in range(mu.size) if mu[k].real < 0.0 and abs(mu[k].imag) <= 1e-9 * max(1.0, abs(mu[k]))]
    if not negative:
        return []
    k = min(negative, key=lambda k: abs(mu[k].real + 1.0))
    v = np.real(vec[:, k]) / scale
    v = v / np.linalg.norm(v) * scale  # unit length in the scaled state
    z1 = np.asarray(state, dtype=float)
    return [z1 + sign * amp * size / length * v for amp in PUSHES for sign in (1.0, -1.0)]


def period_two_hb(make2: Callable[[float, int], Any], q0: FloatArray, omega: float, eps: float, harmonics: int,
                  newton: NewtonOptions | None, coordinates: int = 1) -> FloatArray | None:
    """The regularised HB orbit of period 2 (``make2(ε, H)``'s problem, ``harmonics`` of Ω/2) at ε
    next to the series ``q0`` (an exact period-2 orbit's spectrum): Newton from ``q0`` at ε, else
    the ladder in ε from 4ε or 10ε down; None when none keeps 1e-2 of its fluctuation in the odd
    harmonics (it fell back to the period-1 orbit written twice)."""
    res = solve_fixed(make2(eps, harmonics), q0, omega, newton or NewtonOptions())
    if res.converged and odd_share(res.q, coordinates) >= 100 * ODD_SHARE:
        return res.q
    for wide in (4.0 * eps, 10.0 * eps):
        try:
            q = regularisation_limit(make2, omega, q0, eps_start=min(wide, 0.3), eps_min=eps, harmonics=harmonics,
                                     max_harmonics=harmonics, tail_tol=math.inf, newton=newton).last.q
        except RattleError:
            continue
        if odd_share(q, coordinates) >= 100 * ODD_SHARE:
            return q
    return None


def branches_at_doublings(primary: Any, lo: float, hi: float, seed: Callable[[int], T | None],
                          from_seed: Callable[[float, T, int, str], B | None],
                          exact: Callable[[float, T, FloatArray, int, str], B]) -> tuple[B, ...]:
    """The period-2 branches born at the period doublings of the period-1 branch ``primary`` (rows
    ``omega``, ``matched``, ``bifurcation``, ``multipliers``) within [``lo``, ``hi``], numbered
    1, 2, … in order of Ω (each with ``omega``). Per doubling (:func:`doublings`), row by row in
    the order given there: ``seed(row)`` the exact period-2 orbit next to it (None: none), then
    ``from_seed(Ω, seed, number, origin)`` the branch followed by the regularised HB from it (None:
    the HB has no period-2 orbit there). Where no row gives one, ``exact(Ω, first seed, grid,
    number, origin)`` follows the first seed by exact shooting over the primary's frequencies
    ``grid``. A doubling lying on a branch already found (its other end) starts none; one without
    a seed starts none either."""
    spans: list[tuple[float, float]] = []
    out: list[B] = []
    for w_a, w_b, order in doublings(primary.omega, primary.matched, primary.bifurcation, primary.multipliers):
        if any(s0 <= w <= s1 for s0, s1 in spans for w in (w_a, w_b)):
            continue  # the other end of a branch already followed
        origin = f"period doubling of the period-1 branch between Ω = {min(w_a, w_b):.6g} and {max(w_a, w_b):.6g}"
        branch: B | None = None
        first: tuple[float, T] | None = None
        for i in order:
            orbit = seed(i)
            if orbit is None:
                continue
            w0 = float(primary.omega[i])
            first = first or (w0, orbit)
            branch = from_seed(w0, orbit, len(out) + 1, origin)
            if branch is not None:
                break
        if branch is None and first is not None:  # the regularised HB has no period-2 orbit there
            grid = np.unique(primary.omega[(primary.omega >= lo) & (primary.omega <= hi)])
            branch = exact(first[0], first[1], grid, len(out) + 1, origin)
        if branch is None:
            continue
        spans.append((float(np.min(branch.omega)), float(np.max(branch.omega))))  # type: ignore[attr-defined]
        out.append(branch)
    return tuple(out)


def follow_both_ways(problem: ContinuationProblem, q: FloatArray, omega: float, lo: float, hi: float,
                     continuation: ContinuationOptions | None,
                     newton: NewtonOptions | None) -> tuple[list[BranchPoint], Status, str]:
    """The period-2 branch of ``problem`` (a regularised HB of period 2; a chain's when it has
    ``n_coordinates``) through (q, Ω) continued down to ``lo`` and up to ``hi``, each way until it
    rejoins a period-1 branch (its odd harmonics fall below :data:`ODD_SHARE` of the fluctuation,
    or change sign) or leaves the range: the points in order of the branch."""
    n = int(getattr(problem, "n_coordinates", 1))
    odd = _odd(q, n)
    parts: list[list[BranchPoint]] = []
    ends: list[str] = []
    status = Status.SUCCESS
    for rng in ((lo, omega), (omega, hi)):
        if rng[1] - rng[0] <= 1e-9 * hi:
            parts.append([])
            continue
        prev = {"odd": q[odd].copy()}

        def rejoined(pt: BranchPoint, prev: dict = prev) -> str | None:  # type: ignore[type-arg]
            o = pt.q[odd]
            flipped = float(o @ prev["odd"]) < 0.0
            prev["odd"] = o.copy()
            if flipped or odd_share(pt.q, n) < ODD_SHARE:
                return f"the period-2 branch rejoined a period-1 branch near Ω = {pt.omega:.6g}"
            return None

        stepper = ContinuationStepper(problem, q, omega, rng, options=continuation or ContinuationOptions(),
                                      newton=newton or NewtonOptions(), stop=rejoined)
        pts = stepper.run()
        if stepper.status is Status.STOPPED and pts:
            pts = pts[:-1]  # the point past the rejoin is the period-1 orbit written twice
        parts.append(pts)
        if stepper.message:
            ends.append(stepper.message)
        if stepper.status not in (Status.SUCCESS, Status.STOPPED, None):
            status = stepper.status
    down, up = parts
    points = list(reversed(down[1:])) + up if up else list(reversed(down))
    return points, status, "; ".join(ends)


def follow_exactly(shoot: Callable[[float, T], T | str], seed: T, omega: float,
                   grid: FloatArray) -> tuple[list[tuple[float, T]], list[str]]:
    """An exact branch through the orbit ``seed`` at ``omega`` followed over the frequencies
    ``grid`` each way by natural continuation: ``shoot(Ω, previous orbit)`` gives the orbit at Ω
    from the previous one, or why it failed (a string). Where it fails the step is halved up to
    4 times; the side ends at the first failure left. Returns the (Ω, orbit) pairs in order of Ω
    (the seed included) and why each side ended."""
    ends: list[str] = []

    def advance(prev: T, w0: float, w1: float, depth: int = 0) -> tuple[list[tuple[float, T]], str]:
        got = shoot(w1, prev)
        if not isinstance(got, str):
            return [(w1, got)], ""
        if depth >= 4:
            return [], got
        mid = 0.5 * (w0 + w1)
        first, why = advance(prev, w0, mid, depth + 1)
        if why:
            return first, why
        second, why = advance(first[-1][1], mid, w1, depth + 1)
        return first + second, why

    sides: list[list[tuple[float, T]]] = []
    for ws in (grid[grid < omega][::-1], grid[grid > omega]):
        side: list[tuple[float, T]] = []
        prev, w_prev = seed, omega
        for w in ws.tolist():
            reached, why = advance(prev, w_prev, w)
            side.extend(reached)
            if why:
                ends.append(why)
                break
            prev, w_prev = reached[-1][1], w
        sides.append(side)
    down, up = sides
    return list(reversed(down)) + [(omega, seed)] + up, ends


__all__ = ["ODD_SHARE", "PUSHES", "beyond_minus_one", "branches_at_doublings", "doublings", "follow_both_ways", "follow_exactly",
           "odd_share", "period_two_hb", "pushed_starts"]
