"""The regularisation continued to its limit: one periodic orbit of a discontinuous law at ε → 0.

The harmonic balance of a preload or friction law solves the regularised equation
(:class:`~rattle.hb.RegularisedBalance`, smooth steps of relative width ε). This module follows
one solution at a fixed forcing frequency Ω from a comfortable ε_0 down a geometric ladder
ε_0 > ε_1 > … > ε_min = the branch of R_ε(q, Ω) = 0 followed in u = log ε by
:class:`~rattle.continuation.ContinuationStepper` on a :class:`~rattle.continuation.WidthHomotopy`
(pseudo-arclength, the tangent's guess, the stepper's step control where Newton needs shorter
steps), the rungs ε_k = ε_0 ratio^k its ``stations`` (each solved exactly at its ε, whatever steps
were taken between). A narrower step needs more harmonics: at each rung the spectrum of δ is checked, and while the harmonics in the top half of the basis
carry more than ``tail_tol`` of its fluctuation (rms) H is doubled (up to
``max_harmonics``) and the stepper started again at that rung.

The record (:class:`RegularisationLimit`) holds every rung: ε, H, rms and mean of δ, the
spectral tail. The change of the rms between the last rungs measures what ε still does to the
answer; for an error linear in ε (a jump smeared over a width ε) the Richardson value
rms(ε_k) − ε_k (rms(ε_k) − rms(ε_{k−1}))/(ε_k − ε_{k−1}) estimates the limit — both are reported,
and the exact event-driven orbit (:mod:`rattle.timeint`) is the check.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._typing import FloatArray
from .._validate import check_int, check_positive
from ..continuation import ContinuationOptions, ContinuationStepper, NewtonOptions, WidthHomotopy
from ..errors import ConvergenceError
from ..hb import (
    HBOptions,
    RegularisedBalance,
    RegularisedSystemBalance,
    resize_harmonics,
)


@dataclass(frozen=True, slots=True)
class RegularisationStep:
    """One rung of the ladder: ``eps``, ``harmonics`` H, the coefficients ``q`` of δ, its
    ``mean``, ``rms`` and ``p2p`` (sampled), and ``tail``: the rms of δ's harmonics in the top half
    of the basis relative to the rms of its fluctuation. For a chain
    (:class:`~rattle.hb.RegularisedSystemBalance`) ``element_rms`` (m,) holds every element's rms,
    ``mean``, ``rms`` and ``p2p`` are those of the element with the largest rms and ``tail`` the
    largest over the elements; None for the single equation."""

    eps: float
    harmonics: int
    q: FloatArray
    mean: float
    rms: float
    p2p: float
    tail: float
    element_rms: FloatArray | None = None


@dataclass(frozen=True, slots=True)
class RegularisationLimit:
    """The ladder of one orbit (:func:`regularisation_limit`) at forcing frequency ``omega``."""

    omega: float
    steps: tuple[RegularisationStep, ...]

    @property
    def last(self) -> RegularisationStep:
        return self.steps[-1]

    @property
    def change(self) -> float:
        """|rms(ε_last) − rms(ε_previous)| / rms(ε_last): what the last refinement of ε changed."""
        if len(self.steps) < 2:
            return math.nan
        a, b = self.steps[-2].rms, self.steps[-1].rms
        return abs(b - a) / max(abs(b), 1e-300)

    @property
    def linear(self) -> bool:
        """True when the last three rungs lie on one straight line in ε to within 30 % of its slope
        (or the rms no longer moves, 1e-9): the regime in which Richardson's value holds."""
        if len(self.steps) < 3:
            return False
        a, b, c = self.steps[-3:]
        if c.element_rms is not None and a.element_rms is not None and b.element_rms is not None:
            return all(_linear(a.eps, b.eps, c.eps, x, y, z)
                       for x, y, z in zip(a.element_rms.tolist(), b.element_rms.tolist(), c.element_rms.tolist()))
        return _linear(a.eps, b.eps, c.eps, a.rms, b.rms, c.rms)

    @property
    def extrapolated_rms(self) -> float:
        """Richardson's ε → 0 value of the rms from the last two rungs (error linear in ε)."""
        if len(self.steps) < 2:
            return self.last.rms
        a, b = self.steps[-2], self.steps[-1]
        return b.rms - b.eps * (b.rms - a.rms) / (b.eps - a.eps)

    @property
    def extrapolated_element_rms(self) -> FloatArray:
        """Richardson's ε → 0 value of every element's rms (a chain's ladder; (m,))."""
        b = self.last
        if b.element_rms is None:
            raise ValueError("`extrapolated_element_rms` needs a chain's ladder (RegularisedSystemBalance)")
        if len(self.steps) < 2:
            return b.element_rms.copy()
        a = self.steps[-2]
        assert a.element_rms is not None
        return b.element_rms - b.eps * (b.element_rms - a.element_rms) / (b.eps - a.eps)


def _linear(ea: float, eb: float, ec: float, a: float, b: float, c: float) -> bool:
    """(ε, rms) at three rungs on one line to within 30 % of its slope, or not moving (1e-9)."""
    s1 = (b - a) / (eb - ea)
    s2 = (c - b) / (ec - eb)
    if max(abs(b - a), abs(c - b)) <= 1e-9 * abs(c):
        return True
    return s1 != 0.0 and 0.7 <= s2 / s1 <= 1.3


def _chain_measures(pb: RegularisedSystemBalance, q: FloatArray) -> tuple[float, float, float, float, FloatArray]:
    """A chain's: mean, rms, p2p of the element with the largest rms, the largest tail, every rms."""
    E = pb.element_series(q)
    H = pb.basis.harmonics
    power = E[:, 1 : H + 1] ** 2 + E[:, H + 1 :] ** 2
    total = np.sqrt(np.sum(power, axis=1))
    top = np.sqrt(np.sum(power[:, H // 2 :], axis=1))
    tail = float(np.max(np.where(total > 0, top / np.where(total > 0, total, 1.0), 0.0)))
    rms = pb.element_rms(q)
    i = int(np.argmax(rms))
    delta = pb.basis.synthesize(E[i])
    return float(E[i, 0]), float(rms[i]), float(np.ptp(delta)), tail, rms


def _measures(pb: RegularisedBalance, q: FloatArray, omega: float) -> tuple[float, float, float, float]:
    delta, _ = pb.samples(q, omega)
    H = pb.basis.harmonics
    power = q[1 : H + 1] ** 2 + q[H + 1 :] ** 2  # 2 × the power of harmonic k of δ
    total = math.sqrt(float(np.sum(power)))
    tail = math.sqrt(float(np.sum(power[H // 2 :]))) / total if total > 0 else 0.0
    return float(np.mean(delta)), float(np.sqrt(np.mean(delta**2))), float(np.ptp(delta)), tail


def regularisation_limit(
    problem: Callable[[float, int], RegularisedBalance | RegularisedSystemBalance],
    omega: float,
    q0: FloatArray,
    *,
    eps_start: float = 0.1,
    eps_min: float = 1e-3,
    ratio: float = 0.5,
    harmonics: int = 32,
    max_harmonics: int = 256,
    tail_tol: float = 1e-6,
    newton: NewtonOptions | None = None,
) -> RegularisationLimit:
    """Follow the periodic orbit started at ``q0`` (coefficients with ``harmonics`` harmonics) at
    ``omega`` from ε = ``eps_start`` down to ``eps_min`` (module docstring).

    ``problem(eps, H)`` builds the :class:`RegularisedBalance` at relative width ε with H
    harmonics, or a chain's :class:`~rattle.hb.RegularisedSystemBalance` (``q0`` then its flat
    coordinate series; the spectral tail and the rms are then every element's, linearity and
    Richardson's value per element). Raises :class:`~rattle.errors.ConvergenceError` (with the
    rungs reached) when the first solve fails, or when the stepper's step in log ε shrinks below 1 % of a rung.
    """
    if not (0 < eps_min <= eps_start) or not (0 < ratio < 1):
        raise ValueError(f"need 0 < eps_min <= eps_start and 0 < ratio < 1, got eps_min={eps_min!r}, "
                         f"eps_start={eps_start!r}, ratio={ratio!r}")
    newton = NewtonOptions(max_iterations=30) if newton is None else newton
    rungs = _rungs(float(eps_start), float(eps_min), float(ratio))
    u, lo = next(iter(rungs)), min(rungs)
    step = abs(math.log(ratio))
    options = ladder_options(step, 0.01 * step)
    steps: list[RegularisationStep] = []
    H, q = int(harmonics), np.asarray(q0, dtype=float)
    while True:  # one run of the stepper per H: a rung whose spectral tail asks for more harmonics restarts it
        pb = problem(rungs.get(u, math.exp(u)), H)
        chain = isinstance(pb, RegularisedSystemBalance)
        start = resize_harmonics(np.reshape(q, (pb.n_coordinates, -1)), H).reshape(-1) if chain \
            else resize_harmonics(q, H)
        stepper = ContinuationStepper(WidthHomotopy(pb.with_regularisation, omega, u), start, u,
                                      (lo, u) if u > lo else (lo - 1.0, lo), options, newton,
                                      domain=(-math.inf, math.inf), symbol="log ε",
                                      stations=tuple(r for r in rungs if r < u))
        restart = False
        for pt in iter(stepper.step, None):
            if pt.p not in rungs:
                continue  # a step between rungs
            eps = rungs.get(pt.p, math.exp(pt.p))
            at = pb.with_regularisation(eps)
            mean, rms, p2p, tail, el_rms = _chain_measures(at, pt.q) if chain else (*_measures(at, pt.q, omega), None)
            if tail > tail_tol and 2 * H <= max_harmonics:  # the step is not resolved: more harmonics, same ε
                H, q, u, restart = 2 * H, pt.q, pt.p, True
                break
            steps.append(RegularisationStep(eps=eps, harmonics=H, q=pt.q, mean=mean, rms=rms, p2p=p2p, tail=tail,
                                            element_rms=el_rms))
            if pt.p <= lo:
                return RegularisationLimit(omega=float(omega), steps=tuple(steps))
        if restart:
            continue
        if not steps:
            raise ConvergenceError(f"the regularised orbit at Ω = {omega:g}, ε = {math.exp(u):g} (H = {H}) did not "
                                   f"converge from the start given: {stepper.message}")
        raise ConvergenceError(f"the regularisation ladder at Ω = {omega:g} stalled at ε = "
                               f"{steps[-1].eps:g}: Newton fails for any smaller ε (H = {H}; {stepper.message})")


def ladder_options(rung: float, smallest: float) -> ContinuationOptions:
    """The stepper's settings on a ladder in u = log w whose rungs are ``rung`` apart in u: steps
    in arc length of (q / L, u) from one rung to twice that (every step is cut at the next rung:
    the stepper's ``stations``), shortened by the step control where Newton needs it, down to
    ``smallest`` (then the ladder has stalled). A rung is one Newton solve from the tangent's
    guess where the old hand-made ladder did one from the last rung: up to 6 iterations (the
    target) and a turn of the tangent up to 1.2 rad per step are accepted without shortening."""
    return ContinuationOptions(initial_step=rung, min_step=smallest, max_step=2.0 * rung, target_iterations=6,
                               max_turn=1.2, target_turn=0.6)


def _rungs(eps_start: float, eps_min: float, ratio: float) -> dict[float, float]:
    """The ladder's rungs ε_k = max(ε_{k−1} ratio, ε_min) from ``eps_start`` down to ``eps_min``,
    keyed by u = log ε_k (the stepper's stations)."""
    eps, out = eps_start, {}
    while True:
        out[math.log(eps)] = eps
        if eps <= eps_min * (1 + 1e-12):
            return out
        eps = max(eps * math.exp(math.log(ratio)), eps_min)


@dataclass(frozen=True, slots=True, kw_only=True)
class RegularisationOptions:
    """Settings of the regularised harmonic balance of a law with jumps or friction
    (:func:`rattle.frequency_response` with ``options=RegularisationOptions(...)``).

    ``harmonics`` H and ``regularisation`` ε of the HB (relative widths of the smooth steps);
    ``match``: the largest departure of the exact orbit's δ(t) from the HB's, relative to the HB
    orbit's peak-to-peak, for the two to count as one orbit. The regularisation is continued from
    ε down to ``limit_eps`` (harmonics raised up to ``limit_harmonics``;
    :func:`~rattle.analysis._regularisation.regularisation_limit`) at ``limit`` matched rows evenly
    spread, and at every matched row whose HB rms differs from the exact one by more than
    ``refine`` (relative; None: none); its last and Richardson rms are kept beside the exact one.
    Where such a row is still off by more than ``refine`` at ``limit_eps`` and the ladder's last
    rungs are not yet linear in ε (Richardson's value not yet to be trusted), the ladder goes on
    down to ``deep_eps`` (e.g. 1e-4) with up to ``deep_harmonics`` harmonics; None (default): it
    stops at ``limit_eps``. That costs 20–45 s a row at H = 512 (measured in docs/nonsmooth.md).
    ``stability``: how the HB orbit's own multipliers are found: ``"saltation"`` (default) the
    non-smooth monodromy of one period of the exact flow from the HB orbit's state, saltation
    matrices included; ``"regularised"`` the smooth monodromy of the regularised equation (or
    chain) linearised along the HB orbit (near a slow crossing of a jump, or where a stick phase
    appears, the smoothing misjudges it: measured in docs/nonsmooth.md).
    """

    harmonics: int = 128
    regularisation: float = 0.01
    match: float = 0.1
    limit: int = 0
    limit_eps: float = 1e-3
    limit_harmonics: int = 256
    refine: float | None = 0.005
    deep_eps: float | None = None
    deep_harmonics: int = 512
    stability: str = "saltation"
    held: bool = False
    held_harmonics: int = 256

    def __post_init__(self) -> None:
        if not isinstance(self.held, (bool, np.bool_)):
            raise TypeError(f"`held` must be True or False, got {self.held!r}")
        object.__setattr__(self, "held", bool(self.held))
        for name in ("harmonics", "limit_harmonics", "deep_harmonics", "held_harmonics"):
            object.__setattr__(self, name, check_int(name, getattr(self, name), 1))
            try:
                HBOptions(harmonics=getattr(self, name))  # its bounds
            except ValueError as exc:
                raise ValueError(str(exc).replace("`harmonics`", f"`{name}`", 1)) from None
        for name in ("regularisation", "match", "limit_eps"):
            object.__setattr__(self, name, check_positive(getattr(self, name), name))
        if self.regularisation >= 1.0:
            raise ValueError(f"`regularisation` (relative width ε of the smooth steps) must be < 1, "
                             f"got {self.regularisation!r}; use 0.01")
        object.__setattr__(self, "limit", check_int("limit", self.limit, 0))
        if self.refine is not None:
            object.__setattr__(self, "refine", check_positive(self.refine, "refine"))
        if self.deep_eps is not None:
            object.__setattr__(self, "deep_eps", check_positive(self.deep_eps, "deep_eps"))
        if self.stability not in ("saltation", "regularised"):
            raise ValueError(f"`stability` must be 'saltation' or 'regularised', got {self.stability!r}")


__all__ = ["RegularisationLimit", "RegularisationOptions", "RegularisationStep", "regularisation_limit"]
