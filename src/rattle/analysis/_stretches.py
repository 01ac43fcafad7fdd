"""A branch followed with its harmonic count per stretch: H raised where the truncation demands it.

Harmonic balance truncates the motion at H harmonics. Where an orbit passes a stiff stage (a
gear mesh twenty times stiffer than the clutch, a one-sided stop) its contacts are short and the
truncation error grows; where it does not, a few harmonics are exact to round-off. One H for the
whole range is therefore either too few there or wasted elsewhere. :func:`follow_branch` runs the
continuation (:class:`~rattle.continuation.ContinuationStepper` with the Floquet monitor) and
estimates the truncation error every few points by solving the point again with 2H
(:class:`AdaptiveHarmonics`); it doubles H on a stretch that needs it and halves it again where
it is no longer needed. Each stretch keeps its own problem and points; the front end assembles
them into one branch whose rows carry their H (column ``harmonics``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _limits, _validate
from .._typing import FloatArray
from ..continuation import BranchPoint, ContinuationStepper
from ..errors import Status
from ..hb import HarmonicBalance, resize_harmonics
from ..model import Model
from ..results import SpeedText


@dataclass(frozen=True, slots=True)
class AdaptiveHarmonics:
    """Harmonics raised and lowered along a branch, stretch by stretch (the default of
    :func:`~rattle.analysis.frequency_response`; ``adaptive=None`` keeps H fixed).

    Every ``every`` accepted points the truncation error of the current point is estimated by
    solving it again with 2H harmonics (bordered Newton from the padded solution, on the plane
    normal to the branch's tangent): e, the larger relative change of the rms and of the rms
    about the mean of the motion (every coordinate) from H to 2H. Where e > ``tolerance``
    the stretch since the last point that passed is followed again with 2H; where the corrector
    fails even at the smallest step, the branch goes on from its last point with 2H (an orbit
    through a stiff stage needs more harmonics than the rest of the range). Both stop at
    ``max_harmonics`` (times the branch's period, times the n coordinates of a chain, at most
    :data:`rattle._limits.MAX_EFFECTIVE_HARMONICS`: :func:`rattle._limits.max_harmonics_for`).
    With ``lower``, where e < ``tolerance``/16 above the starting H, the point is solved with H/2
    and the branch goes on with H/2 when that changes its rms by less than ``tolerance``/2.

    Parameters
    ----------
    tolerance : float
        Relative rms truncation error allowed, in (0, 0.5) (default 1e-3: the 0.1 % of the
        project's accuracy target).
    max_harmonics : int
        Largest H (default 128: a stretch that needs more — an impact on a stage hundreds of
        times stiffer than the forcing frequency — is a case for the exact time-domain
        commands; the run ends there, naming the part of the range not covered).
    every : int
        Accepted points between two estimates (default 16).
    lower : bool
        Lower H again where the estimate allows (default True).
    """

    tolerance: float = 1e-3
    max_harmonics: int = 128
    every: int = 16
    lower: bool = True

    def __post_init__(self) -> None:
        tol = _validate.check_real(self.tolerance, "tolerance")
        if not 0.0 < tol < 0.5:
            raise ValueError(f"`tolerance` must be in (0, 0.5), got {self.tolerance!r}")
        _limits.check_harmonics(self.max_harmonics, "max_harmonics")
        _validate.check_int("every", self.every, 1)
        _validate.check_bool(self.lower, "lower")


@dataclass(slots=True)
class Stretch:
    """A stretch of a branch followed with one harmonic count: its problem, accepted points and
    the stepper that produced them (status, message, rejected steps), and why it ended
    (``ended``: "" for the last stretch, else "raised" or "lowered")."""

    points: list[BranchPoint]
    stepper: ContinuationStepper
    ended: str = ""

    @property
    def hb(self) -> HarmonicBalance:
        """The stretch's harmonic-balance problem (the stepper's)."""
        return self.stepper.problem  # type: ignore[return-value]


def _rms(q: FloatArray, coordinates: int) -> tuple[float, float]:
    """(rms, rms about the mean) of the coordinates' motion, from their coefficients (mean,
    cosines, sines). A truncation may shift the mean (contacts: the rms changes) or only the
    motion about a large mean (a loose gear held at its flank by drag: the rms hides it)."""
    rows = np.asarray(q, dtype=float).reshape(coordinates, -1)
    ac = float(np.sum(0.5 * rows[:, 1:] ** 2))
    return float(np.sqrt(np.sum(rows[:, 0] ** 2) + ac)), float(np.sqrt(ac))


def _change(a: tuple[float, float], b: tuple[float, float]) -> float:
    """The larger relative change of the rms and of the rms about the mean from ``a`` to ``b``."""
    return max(abs(y / x - 1.0) if x > 0.0 else 0.0 for x, y in zip(a, b))


def _resized_tangent(t: FloatArray, coordinates: int, H_new: int) -> FloatArray:
    q = resize_harmonics(np.asarray(t[:-1], dtype=float).reshape(coordinates, -1), H_new).reshape(-1)
    out = np.concatenate((q, t[-1:]))
    return out / np.linalg.norm(out)


def follow_branch(model: Model, run: Any, q0: FloatArray, omega0: float, omega_range: tuple[float, float], *,
                  period: int = 1, adaptive: AdaptiveHarmonics | None = None,
                  callback: Callable[[BranchPoint], None] | None = None) -> list[Stretch]:
    """Follow the period-``period`` branch through ``q0`` (H = ``run.hb.harmonics``) from the end
    ``omega0`` of ``omega_range`` into it, by pseudo-arclength continuation with the Floquet
    monitor — with ``adaptive``, H per stretch (see :class:`AdaptiveHarmonics`). Returns the
    stretches in order; consecutive stretches share their junction point (solved with either
    H). ``run``: the :class:`~rattle.analysis._settings.RunSettings` of the run."""
    from ..continuation import ArclengthCorrector
    from ._assemble import monitor_of

    lo, hi = omega_range
    H0 = run.hb.harmonics
    text = SpeedText.of(model)
    speed = text.at if text.engine else None  # an engine case's messages in rpm
    # the coordinates share the effective harmonics of one problem (n·p·H ≤ 512, _limits.max_harmonics_for)
    top = min(adaptive.max_harmonics, _limits.max_harmonics_for(q0.size // (2 * H0 + 1), period)) if adaptive else H0

    def stepper_for(H: int, q: FloatArray, w: float, tangent: FloatArray | None) -> ContinuationStepper:
        hb = HarmonicBalance(model, run.for_harmonics(H), period=period)
        return ContinuationStepper(hb, q, w, (lo, hi), run.continuation, run.newton, tangent=tangent,
                                   monitor=monitor_of(hb), speed=speed)

    def solve_with(H: int, pt: BranchPoint, tangent: bool = True) -> tuple[FloatArray, float, FloatArray | None] | None:
        """The point ``pt`` solved with H harmonics — on the plane through it normal to its
        tangent (bordered Newton: also at a fold tip, where Ω cannot be held) — and its tangent
        (None without ``tangent``: an estimate reads only the solution; see ``with_tangent``)."""
        if H not in problems:
            hb = HarmonicBalance(model, run.for_harmonics(H), period=period)
            problems[H] = (hb, ArclengthCorrector(hb, run.newton))
        hb, corrector = problems[H]
        q = resize_harmonics(pt.q.reshape(n_coord, -1), H).reshape(-1)
        t = _resized_tangent(pt.tangent, n_coord, H)
        res = corrector.correct(corrector.to_scaled(q, pt.p), t)
        if res is None:
            return None
        q_new, p_new = corrector.unscale(res.y)
        if not lo <= p_new <= hi:
            return None
        if not tangent:
            pending[:] = [corrector, res, t]
            return q_new, p_new, None
        t_new = corrector.tangent(res.Rq, res.Rp, t)
        return q_new, p_new, (t if t_new is None else t_new)

    def with_tangent(found: tuple[FloatArray, float, FloatArray | None]) -> tuple[FloatArray, float, FloatArray]:
        """The last estimate's solution (``solve_with(..., tangent=False)``) with its tangent, when
        the branch goes on from it."""
        q_new, p_new, t_new = found
        if t_new is not None:
            return q_new, p_new, t_new
        corrector, res, t = pending
        t_new = corrector.tangent(res.Rq, res.Rp, t)
        return q_new, p_new, (t if t_new is None else t_new)

    problems: dict[int, tuple[HarmonicBalance, ArclengthCorrector]] = {}
    pending: list[Any] = []  # the last estimate's corrector, result and plane normal: its tangent if needed
    H = H0
    stepper = stepper_for(H, q0, omega0, None)
    n_coord = stepper.problem.size // (2 * H0 + 1)  # type: ignore[attr-defined]
    stretches: list[Stretch] = []
    good = 0  # index (in stepper.points) of the last point whose estimate passed (or the start)
    since = 0
    quiet = 0  # estimates in a row far below the tolerance
    missed = 0  # estimates in a row whose finer problem did not converge
    raised_at = math.inf  # Ω where H was last raised
    while True:
        pt = stepper.step()
        if pt is None:
            failed = stepper.status is Status.STEP_TOO_SMALL
            if adaptive is None or not failed or 2 * H > top or not stepper.points:
                stretches.append(Stretch(stepper.points, stepper))
                return stretches
            # the corrector fails even at the smallest step: go on from the last point with 2H
            found = None
            for last in stepper.points[-1:-4:-1]:  # the last point, else one of the two before it
                found = solve_with(2 * H, last)
                if found is not None:
                    break
            if found is None:
                stretches.append(Stretch(stepper.points, stepper))
                return stretches
            stretches.append(Stretch(stepper.points, stepper, "raised"))
            H *= 2
            raised_at = found[1]
            stepper = stepper_for(H, *found)
            good, since, quiet = 0, 0, 0
            continue
        if callback is not None:
            callback(pt)
        if adaptive is None:
            continue
        since += 1
        if since < adaptive.every or len(stepper.points) < 2:
            continue
        since = 0
        rms = _rms(pt.q, n_coord)
        if not rms[1] > 0.0:
            continue
        err = np.inf
        if 2 * H <= top:
            fine = solve_with(2 * H, pt, tangent=False)
            if fine is None:
                # the finer problem has no solution near this point: once is a grazing point, twice
                # in a row says the truncation is off here (a solution with H the 2H one is not near)
                missed += 1
                if missed < 2:
                    continue
                fine = (pt.q, pt.p, pt.tangent)
                err = np.inf
            else:
                missed = 0
                err = _change(rms, _rms(fine[0], n_coord))
            if err > adaptive.tolerance:
                # the stretch since the last good point again, with 2H
                start = solve_with(2 * H, stepper.points[good])
                keep = stepper.points[: good + 1]
                if start is None and np.isfinite(err):
                    start, keep = with_tangent(fine), stepper.points
                if start is None:  # no 2H solution to go on from: keep H here
                    missed = 0
                    continue
                stretches.append(Stretch(keep, stepper, "raised"))
                H *= 2
                raised_at = start[1]
                stepper = stepper_for(H, *start)
                good, quiet = 0, 0
                continue
        quiet = quiet + 1 if err < adaptive.tolerance / 32.0 else 0
        if adaptive.lower and H > H0 and quiet >= 4 and abs(pt.p - raised_at) > 0.05 * (hi - lo):
            # four estimates in a row far below the tolerance, well away from where H was raised
            # (a stretch that needed 2H a moment ago would need it again): try H/2
            coarse = solve_with(H // 2, pt)
            if coarse is not None and _change(rms, _rms(coarse[0], n_coord)) < adaptive.tolerance / 8.0:
                stretches.append(Stretch(list(stepper.points), stepper, "lowered"))
                H //= 2
                stepper = stepper_for(H, *coarse)
                good, quiet = 0, 0
                continue
        good = len(stepper.points) - 1


__all__ = ["AdaptiveHarmonics", "Stretch", "follow_branch"]
