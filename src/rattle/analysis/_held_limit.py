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
2. each rung divides s by ``ratio``, solved by damped Newton (backtracking on ‖R‖₂) from the last
   rung; where Newton fails the factor shrinks (√, down to 1.02), and then N doubles (a step much
   narrower in time than T/N is not resolved by the samples, and Newton stalls), up to
   ``max_samples``;
3. it stops when every held element's rms moved by less than ``tol`` (relative) since the last
   rung at least twice as wide (``"converged"``: the regularisation no longer leads the error; what
   is left is the truncation at H), when Newton fails at the smallest factor with the most samples
   (``"stalled"``), or at s = ``min_scale`` (``"floor"``).

Measured on the lock-up chain of the tests (docs/nonsmooth.md, "A held element's own
steps"): the held clutch's HB rms, 26–60 % off at ε = 1e-3 with the chain's widths, comes within
0.07–0.34 % of the exact orbit's in 67–292 s a row (H = 256).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from ..continuation import NewtonOptions
from ..errors import ConvergenceError
from ..hb import HBOptions, RegularisedSystemBalance
from ..hb import MAX_SAMPLES

#: Statuses of :class:`HeldLimit`.
HELD_STATUSES = ("converged", "stalled", "floor")

#: The smallest factor between rungs before N doubles (or the ladder stalls).
MIN_RATIO = 1.02

#: Damped Newton: iterations per rung, and the smallest step fraction of the backtracking.
NEWTON_ITERATIONS = 40
SMALLEST_STEP = 2.0**-10


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


def _solve(pb: RegularisedSystemBalance, q: FloatArray, omega: float, newton: NewtonOptions) -> FloatArray | None:
    """Damped Newton on R(q, Ω) = 0 from ``q``: the full step, halved while ‖R‖₂ does not fall by
    a quarter of the step fraction; converged on :class:`NewtonOptions`' scaled tolerances. None
    when it does not converge."""
    Fs, L = pb.force_scale, pb.length_scale
    q = np.array(q, dtype=float, copy=True)
    for _ in range(NEWTON_ITERATIONS):
        R, dq = pb.newton_step(q, omega)
        if dq is None or not np.all(np.isfinite(R)):
            return None
        r0 = float(np.linalg.norm(R))
        if float(np.max(np.abs(R))) / Fs <= newton.residual_tol and float(np.max(np.abs(dq))) / L <= newton.step_tol:
            return q
        lam = 1.0
        while True:
            trial = q + lam * dq
            r1 = float(np.linalg.norm(pb.residual(trial, omega)))
            if np.isfinite(r1) and r1 < (1.0 - 0.25 * lam) * r0:
                break
            lam *= 0.5
            if lam < SMALLEST_STEP:
                return None
        q = trial
    R = pb.residual(q, omega)
    return q if float(np.max(np.abs(R))) / Fs <= newton.residual_tol else None


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
    newton = NewtonOptions() if newton is None else newton
    base = problem if H == problem.basis.harmonics else RegularisedSystemBalance(
        problem.fsys, regularisation=problem.eps, options=HBOptions(harmonics=H), period=problem.period)
    scales0 = problem.element_scales
    pb = base.with_element_scales(scales0).with_samples(N)
    q0 = problem.resize(q, H) if H != problem.basis.harmonics else np.asarray(q, dtype=float)
    sol = _solve(pb, q0, omega, newton)
    if sol is None:
        raise ConvergenceError(f"the held elements' ladder at Ω = {omega:g}: no orbit at the chain's widths with "
                               f"H = {H}, N = {N} from the orbit given")
    q = sol
    s = 1.0
    scales, rms, Ns = [s], [pb.element_rms(q)], [N]
    f = float(ratio)
    status, change = "floor", math.nan
    while True:
        if s <= min_scale * (1.0 + 1e-12):
            status = "floor"
            break
        s_new = max(s / f, min_scale)
        trial_scales = scales0.copy()
        trial_scales[list(elements)] *= s_new
        trial = pb.with_element_scales(trial_scales)
        sol = _solve(trial, q, omega, newton)
        if sol is None:
            f = math.sqrt(f)
            if f >= MIN_RATIO:
                continue
            if 2 * N > max_samples:
                status = "stalled"
                break
            N *= 2  # the steps are narrower in time than the samples resolve
            pb = pb.with_samples(N)
            f = math.sqrt(float(ratio))
            continue
        pb, q, s = trial, sol, s_new
        scales.append(s)
        rms.append(pb.element_rms(q))
        Ns.append(N)
        f = min(f * f, float(ratio))  # a step that worked: widen the next one again
        change = _change(scales, rms, elements)
        if change < tol:
            status = "converged"
            break
    return HeldLimit(omega=float(omega), elements=elements, scales=np.array(scales), element_rms=np.array(rms),
                     samples=np.array(Ns, dtype=int), harmonics=H, status=status, change=float(change), q=q,
                     problem=pb)


__all__ = ["HELD_STATUSES", "HeldLimit", "held_limit"]
