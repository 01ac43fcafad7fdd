"""One branch's points into a result: stability, located special points, measures, labels.

``assemble`` turns the points a continuation returned (HB coefficients and Ω along one branch)
into a :class:`~rattle.results.FrequencyResponse`: the Floquet multipliers of every point (the
run's stability method), every change of stability located on the branch as a row of its own
(the zero of its test function — det(M − I), det(M + I), det(M ⊙ M − I) — between the two
points around it, and once more with 2H harmonics for the truncation estimate), the SPEC
measures of every element, and the labels. Used by the primary branch
(:mod:`._frequency_response`) and by every sub-harmonic or seeded branch (:mod:`._branches`).
"""

from __future__ import annotations

import time

import numpy as np

from .._typing import FloatArray
from ..continuation import ArclengthCorrector, BranchPoint
from ..continuation import LocatedPoint, locate_on_segment
from ..errors import Status
from ..hb import HarmonicBalance, HBOptions, NewtonOptions
from ..measures import Measures, system_measures_batch
from ..model import Model
from ..results import FrequencyResponse, SpecialPoint
from ..results import element_columns_from
from ..stability import FloquetMonitor, classify_loss, stability_method, torus_ratio
from ..stability import UNIT_CIRCLE_TOL
from ._settings import StabilityMethod, scaled_hb


def monitor_of(hb: HarmonicBalance) -> FloquetMonitor:
    """The :class:`~rattle.stability.FloquetMonitor` of ``hb`` (one per problem: it caches the
    stage decompositions of a chain)."""
    mon = getattr(hb, "_floquet_monitor", None)
    if mon is None:
        mon = FloquetMonitor(hb)
        hb._floquet_monitor = mon  # type: ignore[attr-defined]
    return mon


def _test_function(kind: str, hb: HarmonicBalance):
    """ψ(q, Ω) whose sign change marks a ``kind`` point (see continuation._detect): det(M − I)
    (fold), det(M + I) (period doubling), det(M ⊙ M − I) (Neimark–Sacker), from the exact
    monodromy of the orbit (``FloquetMonitor.test_function``)."""
    return monitor_of(hb).test_function(kind)


def _locate_with(hb: HarmonicBalance, newton: NewtonOptions, kind: str, qa, wa, qb, wb) -> LocatedPoint | None:
    """The ``kind`` point between two points of the branch (qa, wa), (qb, wb): the zero of its ψ
    on the branch, ψ at the two points evaluated there (they are solutions: not corrected again;
    a branch point's monodromy is the monitor's, remembered)."""
    corrector = ArclengthCorrector(hb, newton)
    psi = _test_function(kind, hb)
    return locate_on_segment(corrector, qa, wa, qb, wb, lambda q, w, corr, d: psi(q, w), ends=(psi(qa, wa), psi(qb, wb)))


def _refine(hb: HarmonicBalance, hb2: HarmonicBalance, newton: NewtonOptions, kind: str, qa, wa, qb, wb) -> LocatedPoint | None:
    """Locate the same special point with the doubled harmonic count hb2 (built with the run's
    HBOptions scaled to 2H: see ``_settings``): the end points are first corrected onto the 2H
    branch (in the plane normal to the secant)."""
    H2 = hb2.basis.harmonics
    corr2 = ArclengthCorrector(hb2, newton)
    ya = corr2.to_scaled(hb.resize(qa, H2), wa)
    yb = corr2.to_scaled(hb.resize(qb, H2), wb)
    d = (yb - ya) / np.linalg.norm(yb - ya)
    ca, cb = corr2.correct(ya, d), corr2.correct(yb, d)
    if ca is None or cb is None:
        return None
    qa2, wa2 = corr2.unscale(ca.y)
    qb2, wb2 = corr2.unscale(cb.y)
    return _locate_with(hb2, newton, kind, qa2, wa2, qb2, wb2)


def _vertex_stretch(Q: FloatArray, hb: HarmonicBalance, rows: range) -> int:
    """How many rows after the first of ``rows`` (a branch-point end, walking inwards) are
    still (nearly) of half the period: the vertex of the period-doubling pitchfork.

    There the doubled-period orbit's critical multiplier is the square of its parent's, ≈ +1,
    and sits on either side of the unit circle within the truncation error; the stability
    changes it shows there are the branch point itself (labelled at the end row), not folds.
    """
    count = 0
    for j in list(rows)[1:-1]:
        if not _is_period_halved(Q[j], hb):
            break
        count += 1
    return count


def _is_period_halved(q: FloatArray, hb: HarmonicBalance, rtol: float = 0.1) -> bool:
    """Whether a solution of even period p is (nearly) of period p/2: its odd harmonics carry
    less than ``rtol`` of the dynamic content. Near the pitchfork where a doubled-period branch
    meets its parent the odd part vanishes like sqrt(|Ω − Ω_pd|); the located +1 crossing there
    has ~1–2 % odd content on the reference case, a genuine fold of a period-2 branch ~95 %."""
    if hb.period % 2:
        return False
    H = hb.basis.harmonics
    k = np.arange(1, H + 1, 2)
    odd = np.concatenate((k, H + k))
    Q = np.asarray(q).reshape(-1, 2 * H + 1)  # one row per coordinate
    return float(np.linalg.norm(Q[:, odd])) <= rtol * max(float(np.linalg.norm(Q[:, 1:])), 1e-300)


def _locate_changes(
    hb: HarmonicBalance, newton: NewtonOptions, Q: FloatArray, Om: FloatArray, mu: np.ndarray, stable: np.ndarray,
    refine: bool,
) -> list[tuple[int, str, LocatedPoint | None, float | None]]:
    """For each change of stability between rows i−1 and i: (i, kind, located point or None,
    Ω located again with 2H harmonics or None). The 2H problem keeps ``hb.options``' sample
    ratio (``RunSettings.for_harmonics``)."""
    found = []
    hb2 = None
    for i in range(1, stable.size):
        if stable[i] == stable[i - 1]:
            continue
        kind = classify_loss(mu[i - 1], mu[i])
        loc = _locate_with(hb, newton, kind, Q[i - 1], Om[i - 1], Q[i], Om[i])
        if kind == "fold" and loc is not None and _is_period_halved(loc.q, hb):
            # +1 at a point that is really of half the period: the pitchfork where this branch
            # meets the branch it doubled from — that branch's period doubling, not a fold.
            kind = "period_doubling"
        omega2 = None
        if loc is not None and refine:
            if hb2 is None:
                hb_opts = hb.options if isinstance(hb.options, HBOptions) else HBOptions(harmonics=hb.basis.harmonics)
                hb2 = HarmonicBalance(hb.model, scaled_hb(hb_opts, 2 * hb.basis.harmonics), period=hb.period)
            loc2 = _refine(hb, hb2, newton, kind, Q[i - 1], Om[i - 1], Q[i], Om[i])
            omega2 = None if loc2 is None else loc2.omega
        found.append((i, kind, loc, omega2))
    return found


def _multipliers(model: Model, hb: HarmonicBalance, Q: FloatArray, Om: FloatArray, X: FloatArray, stability: StabilityMethod) -> np.ndarray:
    """Floquet multipliers (P, 2n), largest modulus first, of the orbits ``Q`` (P, n·(2H+1))."""
    return stability.multipliers(hb, Q, Om)  # a rattle.stability method object


def assemble(
    model: Model,
    hb: HarmonicBalance,
    points: list[BranchPoint],
    *,
    branch_id: int = 0,
    stability: StabilityMethod = "monodromy",
    locate: bool = True,
    refine: bool = True,
    branch_points: tuple[bool, bool] = (False, False),
    newton: NewtonOptions | None = None,
    status: Status = Status.SUCCESS,
    message: str = "",
    settings: dict | None = None,
    timings: dict | None = None,
) -> FrequencyResponse:
    """Stability, located special points, measures and labels for the points of one branch.

    Where stability changes between two points, the special point is located on the branch
    (``locate=True``; see ``continuation._detect``) and inserted between them as a row of its
    own, labelled with its type; its ``stable`` is false (a multiplier sits on the unit circle).
    Without ``locate`` (or if locating fails) the nearer of the two points is labelled.
    With ``refine`` the special point is located once more with 2H harmonics: its
    ``SpecialPoint.omega`` is that value and ``omega_error`` = |Ω(2H) − Ω(H)| estimates the
    truncation error of the row's Ω (the row itself stays the H-harmonic solution).
    ``branch_points`` (first, last) marks end rows that are period-doubling points of another
    branch (a branch born by period doubling): they are labelled so, and the change of
    stability through them (the multiplier −1 of the parent is +1 here) is not reported again.
    """
    t0 = time.perf_counter()
    newton = newton or NewtonOptions()
    P = len(points)
    n = hb.size
    Q = np.array([p.q for p in points]).reshape(P, n)
    Om = np.array([p.omega for p in points], dtype=float)
    its = np.array([p.iterations for p in points], dtype=int)
    res = np.array([p.residual for p in points], dtype=float)
    X = None  # (the monodromy synthesises what it needs)
    stability = stability_method(stability)  # assemble() is public: a name is still accepted
    mu = _multipliers(model, hb, Q, Om, X, stability)
    stable = np.max(np.abs(mu), axis=1) < 1.0 - UNIT_CIRCLE_TOL if P else np.zeros(0, dtype=bool)
    labels = np.full(P, "", dtype=object)
    # A branch-point end row takes the stability of its neighbour for the change detection.
    stable_for_changes = stable.copy()
    if P > 1 and branch_points[0]:
        labels[0] = "period_doubling"
        k = _vertex_stretch(Q, hb, range(P))
        stable_for_changes[: k + 1] = stable[min(k + 1, P - 1)]
    if P > 1 and branch_points[1]:
        labels[P - 1] = "period_doubling"
        k = _vertex_stretch(Q, hb, range(P - 1, -1, -1))
        stable_for_changes[P - 1 - k :] = stable[max(P - 2 - k, 0)]
    changes = _locate_changes(hb, newton, Q, Om, mu, stable_for_changes, refine) if locate and stability.locates else [
        (i, classify_loss(mu[i - 1], mu[i]), None, None) for i in range(1, P) if stable_for_changes[i] != stable_for_changes[i - 1]
    ]
    if P > 1 and branch_points[0]:
        stable[0] = False  # a multiplier on the unit circle
    if P > 1 and branch_points[1]:
        stable[P - 1] = False
    # Insert the located points (in reverse so that the indices stay valid).
    inserted = np.zeros(P, dtype=bool)
    refined: dict[int, float] = {}
    for i, kind, loc, omega2 in reversed(changes):
        if loc is None:
            j = i if abs(np.max(np.abs(mu[i])) - 1.0) <= abs(np.max(np.abs(mu[i - 1])) - 1.0) else i - 1
            labels[j] = kind
            continue
        Q = np.insert(Q, i, loc.q, axis=0)
        Om = np.insert(Om, i, loc.omega)
        its = np.insert(its, i, loc.iterations)
        res = np.insert(res, i, loc.residual)
        labels = np.insert(labels, i, kind)
        stable = np.insert(stable, i, False)
        inserted = np.insert(inserted, i, True)
        refined = {(k + 1 if k >= i else k): v for k, v in refined.items()}
        if omega2 is not None:
            refined[i] = omega2
    if inserted.any():
        mu_new = _multipliers(model, hb, Q[inserted], Om[inserted], None, stability)
        mu_full = np.empty((Q.shape[0], mu.shape[1]), dtype=complex)
        mu_full[~inserted] = mu
        mu_full[inserted] = mu_new
        mu = mu_full
    P = Q.shape[0]
    ends = {0} if P > 1 and branch_points[0] else set()
    if P > 1 and branch_points[1]:
        ends.add(P - 1)
    special = [
        SpecialPoint(
            str(labels[j]), j, float(refined.get(j, Om[j])), branch_id, mu[j].copy(), located=bool(inserted[j]) or j in ends,
            omega_error=abs(refined[j] - float(Om[j])) if j in refined else None,
            torus_ratio=torus_ratio(mu[j]) if labels[j] == "neimark_sacker" else None,
        )
        for j in range(P) if labels[j]
    ]
    t1 = time.perf_counter()
    n_coord = hb.size // hb.basis.size
    per_element = system_measures_batch(model, Q.reshape(P, n_coord, -1), Om / hb.period, Om, hb.basis.samples) if P else None
    meas = per_element[0] if per_element else None
    names = getattr(model, "element_names", None)
    element_cols = element_columns_from(names, per_element) if (names and per_element) else (
        element_columns_from(names, tuple(_empty_measures() for _ in names)) if names else {})
    t2 = time.perf_counter()
    empty = np.zeros(0)
    timings = dict(timings or {})
    timings.update({"stability": t1 - t0, "measures": t2 - t1})
    return FrequencyResponse(
        model=model,
        harmonics=hb.basis.harmonics,
        branch=np.full(P, branch_id, dtype=int),
        period=np.full(P, hb.period, dtype=int),
        omega=Om,
        mean=meas.mean if meas else empty,
        rms=meas.rms if meas else empty,
        rms_ac=meas.rms_ac if meas else empty,
        p2p=meas.p2p if meas else empty,
        acc_p2p=meas.acc_p2p if meas else empty,
        delta_min=meas.delta_min if meas else empty,
        delta_max=meas.delta_max if meas else empty,
        regime=meas.regime if meas else np.zeros(0, dtype=object),
        stable=stable,
        bifurcation=labels,
        iterations=its,
        residual=res,
        coefficients=Q,
        multipliers=mu,
        special_points=tuple(special),
        status=status,
        message=message or status.message,
        settings=dict(settings or {}),
        timings=timings,
        element_columns=element_cols,
        extra_columns={"harmonics": np.full(P, hb.basis.harmonics, dtype=int)},  # H of each row (SPEC §8)
    )


def _empty_measures() -> Measures:
    e = np.zeros(0)
    return Measures(e, e, e, e, e, e, e, np.zeros(0, dtype=object))


__all__ = ["assemble", "monitor_of"]
