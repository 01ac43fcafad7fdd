"""The regularisation's limit for a chain element held part of the period: its own steps narrowed.

A chain element held (stuck, or locked at its torque jump) for part of the period moves, the
rest of the time, over a few of the chain's step widths ε_δ = ε L and ε_v = ε L ω_n (L, ω_n
the chain's scales, :class:`~rattle.hb.RegularisedSystemBalance`): its own motion can be a
hundredth of the chain's, and narrowing every element's steps together converges on it only
slowly (a staircase in ε, measured in docs/nonsmooth.md). Here only the held elements' steps
narrow. With a scale s on the held elements (1 on the others, the chain's ε kept),

    sgn(δ_e') → tanh(δ_e' / (s ε_v)),   a step of the law at δ = d → H(δ_e − d) of width s ε_δ,

:func:`held_limit` solves the harmonic balance along a decreasing sequence of s:

1. the orbit at s = 1 with H = ``harmonics`` (raised from the given orbit's) and N = ``samples``
   AFT samples per period;
2. the rungs s_k = ``ratio``^−k are the stations of a
   :class:`~rattle.continuation.ContinuationStepper` on the
   :class:`~rattle.continuation.WidthHomotopy` in u = log s, each corrected at its s from the last
   rung's q (the :class:`~rattle.continuation.Natural` predictor) by damped Newton
   (``NewtonOptions(damped=True)``: backtracking on ‖R‖₂); where Newton fails the stepper shortens
   the step (a rung between), and where the steps fall below 1 % of a rung N doubles (a step much
   narrower in time than T/N is not resolved by the samples, and Newton stalls), up to
   ``max_samples``, the stepper going on from the last rung;
3. it stops when every held element's rms moved by less than ``tol`` (relative) since the last
   rung at least twice as wide (``"converged"``: the regularisation no longer leads the error; what
   is left is the truncation at H), when the steps fall below 1 % of a rung with the most samples
   (``"stalled"``), or at s = ``min_scale`` (``"floor"``).

Measured on the lock-up chain of the tests (docs/nonsmooth.md, "A held element's own
steps"): the held clutch's HB rms, 26–60 % off at ε = 1e-3 with the chain's widths, comes within
0.07–0.34 % of the exact orbit's in 67–292 s a row (H = 256).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from ..continuation import ContinuationOptions, ContinuationStepper, Natural, NewtonOptions, WidthHomotopy
from ..errors import ConvergenceError
from ..hb import HBOptions, RegularisedSystemBalance
from ..hb import MAX_SAMPLES

#: Statuses of :class:`HeldLimit`.
HELD_STATUSES = ("converged", "stalled", "floor")

#: The smallest ``ratio`` between rungs accepted.
MIN_RATIO = 1.02

#: Damped Newton: iterations per rung at most, and what the step control aims for.
NEWTON_ITERATIONS = 40
TARGET_ITERATIONS = 12


@dataclass(frozen=True, slots=True, eq=False)
class HeldLimit:
    """The held elements' ladder at forcing frequency ``omega`` (:func:`held_limit`).

    ``elements``: the held elements narrowed (indices); per rung k: ``scales`` (k,) s, the
    ``element_rms`` (k, m) of every element and the ``samples`` (k,) N; ``harmonics`` H;
    ``status`` one of :data:`HELD_STATUSES`; ``change``: the largest relative change of a held
    element's rms since the last rung at least twice as wide (nan before there is one); ``q`` the
    last rung's coefficients (of :attr:`problem`'s layout); ``problem`` the last rung's
    :class:`~rattle.hb.RegularisedSystemBalance`."""

    omega: float
    elements: tuple[int, ...]
    scales: FloatArray
    element_rms: FloatArray
    samples: np.ndarray
    harmonics: int
    status: str
    change: float
    q: FloatArray
    problem: RegularisedSystemBalance

    @property
    def rms(self) -> FloatArray:
        """Every element's rms at the last rung (m,)."""
        return self.element_rms[-1].copy()

    @property
    def scale(self) -> float:
        """The last rung's s."""
        return float(self.scales[-1])

    @property
    def converged(self) -> bool:
        return self.status == "converged"


def _rung_options(rung: float) -> ContinuationOptions:
    """The stepper's settings on the held elements' ladder, rungs ``rung`` apart in u = log s: a
    step from one rung to the next (cut there: the stepper's ``stations``), up to two rungs,
    shortened by the step control only where Newton needs more than :data:`TARGET_ITERATIONS`
    iterations, down to 1 % of a rung (then the samples double, or the ladder has stalled). The
    natural predictor keeps q: the tangent's turn says nothing of its guess, and is not limited."""
    return ContinuationOptions(initial_step=rung, min_step=0.01 * rung, max_step=2.0 * rung,
                               target_iterations=TARGET_ITERATIONS, max_turn=1.5, target_turn=1.5)


def _change(scales: list[float], rms: list[FloatArray], held: Sequence[int]) -> float:
    """The largest relative change of a held element's rms between the last rung and the last one
    at least twice as wide (nan when there is none)."""
    s = scales[-1]
    wide = [k for k in range(len(scales) - 1) if scales[k] >= 2.0 * s * (1.0 - 1e-12)]
    if not wide:
        return math.nan
    a, b = rms[wide[-1]], rms[-1]
    return max(abs(float(b[e]) / float(a[e]) - 1.0) if a[e] > 0 else math.inf for e in held)


def held_limit(
    problem: RegularisedSystemBalance,
    q: FloatArray,
    omega: float,
    held: Sequence[int],
    *,
    harmonics: int = 256,
    samples: int | None = None,
    ratio: float = 1.5,
    tol: float = 2e-4,
    min_scale: float = 1e-4,
    max_samples: int = 1 << 18,
    newton: NewtonOptions | None = None,
) -> HeldLimit:
    """Narrow the steps of the ``held`` elements of the orbit ``q`` of ``problem`` at ``omega``
    (module docstring): H = max(``harmonics``, the problem's), N = ``samples`` (default 128 H),
    rungs s → s / ``ratio`` until the held elements' rms moves by less than ``tol`` over a halving
    of s, Newton stalls, or s = ``min_scale``.

    Raises :class:`~rattle.errors.ConvergenceError` when the orbit at s = 1 (with H and N) is not
    found from ``q``; ValueError on bad arguments."""
    if not isinstance(problem, RegularisedSystemBalance):
        raise TypeError(f"`problem` must be a rattle.hb.RegularisedSystemBalance, got {problem!r}")
    m = problem.n_elements
    elements = tuple(sorted({int(e) for e in held}))
    if not elements or any(not 0 <= e < m for e in elements):
        raise ValueError(f"`held` must name at least one element index in 0 … {m - 1}, got {held!r}")
    if not (math.isfinite(ratio) and ratio > MIN_RATIO):
        raise ValueError(f"`ratio` must be a number > {MIN_RATIO}, got {ratio!r}")
    if not (math.isfinite(tol) and tol > 0):
        raise ValueError(f"`tol` must be a number > 0, got {tol!r}")
    if not (math.isfinite(min_scale) and 0 < min_scale < 1):
        raise ValueError(f"`min_scale` must be in (0, 1), got {min_scale!r}")
    H = max(int(harmonics), problem.basis.harmonics)
    N = 128 * H if samples is None else int(samples)
    if not 4 * H + 2 <= N <= max_samples <= MAX_SAMPLES:
        raise ValueError(f"need 4H + 2 <= samples <= max_samples <= {MAX_SAMPLES}, got H = {H}, samples = {N}, "
                         f"max_samples = {max_samples}")
    newton = dataclasses.replace(NewtonOptions() if newton is None else newton, max_iterations=NEWTON_ITERATIONS,
                                 damped=True)
    base = problem if H == problem.basis.harmonics else RegularisedSystemBalance(
        problem.fsys, regularisation=problem.eps, options=HBOptions(harmonics=H), period=problem.period)
    scales0 = problem.element_scales
    q = problem.resize(q, H) if H != problem.basis.harmonics else np.asarray(q, dtype=float)
    step = math.log(float(ratio))
    u_min = math.log(float(min_scale))
    rungs = [-k * step for k in range(1, math.ceil(-u_min / step - 1e-9))] + [u_min]
    options = _rung_options(step)

    def family(pb: RegularisedSystemBalance) -> Callable[[float], RegularisedSystemBalance]:
        def at(s: float) -> RegularisedSystemBalance:
            scales = scales0.copy()
            scales[list(elements)] *= s
            return pb.with_element_scales(scales)
        return at

    scales: list[float] = []
    rms: list[FloatArray] = []
    Ns: list[int] = []
    status, change, u = "stalled", math.nan, 0.0
    pb = base.with_element_scales(scales0).with_samples(N)
    while True:  # one run of the stepper per N: where it stalls, the steps are narrower than the samples resolve
        at = family(pb)
        stepper = ContinuationStepper(WidthHomotopy(at, omega, u), q, u, (u_min, u), options, newton,
                                      predictor=Natural(), domain=(-math.inf, math.inf), symbol="log s",
                                      stations=tuple(r for r in rungs if r < u))
        done = False
        for pt in iter(stepper.step, None):
            if scales and pt.p == u:  # a restart with more samples: the same rung, solved again
                q = pt.q
                continue
            if pt.p != u and pt.p not in rungs:
                continue  # a step between rungs
            q, u = pt.q, pt.p
            scales.append(math.exp(u))
            rms.append(at(math.exp(u)).element_rms(q))
            Ns.append(N)
            change = _change(scales, rms, elements)
            if change < tol:
                status, done = "converged", True
                break
            if u <= u_min:
                status, done = "floor", True
                break
        if done:
            break
        if not scales:
            raise ConvergenceError(f"the held elements' ladder at Ω = {omega:g}: no orbit at the chain's widths with "
                                   f"H = {H}, N = {N} from the orbit given ({stepper.message})")
        if 2 * N > max_samples:
            status = "stalled"
            break
        N *= 2
        pb = pb.with_samples(N)
    pb = family(pb)(scales[-1])
    return HeldLimit(omega=float(omega), elements=elements, scales=np.array(scales), element_rms=np.array(rms),
                     samples=np.array(Ns, dtype=int), harmonics=H, status=status, change=float(change), q=q,
                     problem=pb)


__all__ = ["HELD_STATUSES", "HeldLimit", "held_limit"]
