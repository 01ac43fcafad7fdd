"""One periodic orbit of a chain with Coulomb friction on its elements, with its stick phases.

The orbit of x'' + C x' + K x + Σ_e b_e [f_e(δ_e) + r_e(δ_e) sgn δ_e'] = F(t) (n coordinates,
m elements, δ_e = a_e · x) at one forcing frequency Ω, found by exact Newton shooting on the
event-driven flow (:func:`rattle.timeint.shoot_friction_orbit`: every element's sticking exact,
Filippov; the 2n multipliers with saltation matrices), started from the chain's regularised
harmonic balance (:mod:`rattle.analysis._friction_orbit`). Both are kept, per element: the exact
orbit (the answer: rms, mean, the fraction of the period it sticks, its stick phases) sampled over
one period, and the HB series δ_e,HB(t) = a_e0 + Σ_k a_ek cos kΩt + b_ek sin kΩt at the same
times, so the regularisation's effect is read on the whole period, not only on the rms.

The samples: ``t`` holds ``points`` + 1 equally spaced times over [0, T], T = 2π/Ω, together with
every event time of the exact orbit (sorted, unique); at an event time the values (and ``stuck``)
are those of the segment starting there. ``stick_intervals[e]`` lists element e's stick phases
(t_start, t_end) over [0, T], consecutive stuck segments merged; a phase that runs through t = T
continues at t = 0 on the periodic orbit and is listed as two intervals, one at each end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..errors import Status
from ._orbit import OrbitSolution, every_orbit_lines, every_orbit_records
from ._plotter import plot_with

#: The per-element columns of :meth:`FrictionOrbitResult.to_csv`, NAME_ prefixed, after ``t``.
FRICTION_ORBIT_ELEMENT_COLUMNS = ("delta", "velocity", "stuck", "delta_hb")

#: How the exact orbit was reached (``FrictionOrbitResult.start``).
FRICTION_ORBIT_STARTS = ("hb", "x0", "held", "settled", "")


def _num(x: float) -> float | None:
    """A float for JSON: None where not finite."""
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class HeldLimitRecord:
    """The HB with the steps of the elements held part of the period narrowed to their limit
    (:func:`rattle.analysis._held_limit.held_limit`): ``elements`` the names narrowed, ``rms`` (m,)
    every element's HB rms at the last rung, ``status`` ``"converged"`` (the held rms moved by less
    than the tolerance over the last halving of the width), ``"stalled"`` (Newton failed) or
    ``"floor"``; ``scale`` the held steps' width relative to the chain's at the last rung, ``eps``
    the chain's ε, ``harmonics`` H and ``samples`` N of the last rung, ``change`` the held rms's
    last relative change over a halving of the width, ``seconds`` the time it took."""

    elements: tuple[str, ...]
    rms: FloatArray
    status: str
    scale: float
    eps: float
    harmonics: int
    samples: int
    change: float
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        """The record as plain values (nan → None)."""
        return {"elements": list(self.elements), "rms": [_num(v) for v in self.rms], "status": self.status,
                "scale": _num(self.scale), "eps": _num(self.eps), "harmonics": int(self.harmonics),
                "samples": int(self.samples), "change": _num(self.change), "seconds": _num(self.seconds)}


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)  # arrays: identity equality
class FrictionOrbitResult:
    """The exact and regularised orbits of a chain with friction at one forcing frequency (module
    docstring); N samples, m elements, n coordinates.

    ``omega`` Ω (rad/s); ``speed_rpm`` the crankshaft speed (None without an engine order);
    ``element_names`` (m); ``t`` (N,) the sample times over [0, T]; of the exact orbit (nan, and
    ``stuck`` False, without one): ``delta`` and ``velocity`` (N, m) δ_e and δ_e', ``stuck`` (N, m)
    whether element e sticks at t, ``stick_intervals`` per element a tuple of (t_start, t_end),
    ``rms``, ``mean`` and ``stick_fraction`` (m,: the fraction of the period each sticks, exact to
    round-off), ``multipliers`` (2n,) largest modulus first (saltation matrices; a zero one per
    stuck element), ``state0`` (2n,) the orbit's (x, x') at t = 0; ``converged`` an exact orbit was
    found, ``status`` :attr:`~rattle.errors.Status.CONVERGED` or
    :attr:`~rattle.errors.Status.MAX_ITERATIONS`, ``message`` what was tried when it was not
    straightforward; ``start`` how the shooting was started (``"hb"`` from the HB orbit's state at
    t = 0, ``"x0"`` from the state given, ``"held"`` from the HB state with the elements stuck the
    whole period held at the HB's deflection (``held`` their names), ``"settled"`` from the state
    reached after ``settle_periods`` periods of the exact flow, ``""`` none converged).

    Of the regularised HB (ε ``regularisation``, H ``harmonics``; nan where it failed):
    ``coefficients_hb`` (m, 2H+1) every element's series [a_0, a_1 … a_H, b_1 … b_H],
    ``delta_hb`` (N, m) its samples at ``t``, ``rms_hb`` (m,), ``multipliers_hb`` (2n,) the HB
    orbit's (the non-smooth monodromy of one period of the exact flow from the HB state, or the
    regularised chain's monodromy along it, by the options' ``stability``; nan where not found), ``hb_start`` how it was solved (``"linear"``: from the linearised
    chain, ε narrowed from wide steps; ``"exact"``: from the exact orbit's spectrum, after that
    failed; ``""`` failed). ``match``: the largest :attr:`match_distance` for the two orbits to
    count as one (:attr:`matched`). ``periods`` p: the orbit repeats after p forcing periods (1,
    or 2 for a period-doubled orbit, ``friction_orbit(..., period=2)``); ``t`` then spans
    [0, pT], and the HB series (2H harmonics) is one of Ω/p. ``held_limit``: with
    ``RegularisationOptions(held=True)`` and an element held part of the period, the HB with that
    element's own steps narrowed to their limit (:class:`HeldLimitRecord`; None otherwise)."""

    omega: float
    speed_rpm: float | None
    element_names: tuple[str, ...]
    t: FloatArray
    delta: FloatArray
    velocity: FloatArray
    stuck: np.ndarray
    stick_intervals: tuple[tuple[tuple[float, float], ...], ...]
    rms: FloatArray
    mean: FloatArray
    stick_fraction: FloatArray
    multipliers: ComplexArray
    state0: FloatArray
    converged: bool
    status: Status
    message: str
    start: str
    coefficients_hb: FloatArray
    delta_hb: FloatArray
    rms_hb: FloatArray
    multipliers_hb: ComplexArray
    regularisation: float
    harmonics: int
    hb_start: str = "linear"
    match: float = 0.1
    held: tuple[str, ...] = ()
    settle_periods: int = 100
    periods: int = 1
    #: Every orbit at Ω (:func:`rattle.analysis.exact_orbits_at`: exact, stable and unstable, of every
    #: period the census found; empty when not asked for) and the non-periodic attractors there.
    solutions: tuple[OrbitSolution, ...] = ()
    nonperiodic: tuple[Any, ...] = ()
    held_limit: HeldLimitRecord | None = None

    # --- the period and the HB series --------------------------------------------------------
    @property
    def period(self) -> float:
        """The orbit's period p·2π/Ω (s), p = :attr:`periods` forcing periods."""
        return self.periods * 2.0 * math.pi / self.omega

    @property
    def m(self) -> int:
        """The number of elements."""
        return len(self.element_names)

    def sample_hb(self, t: FloatArray | float, derivative: int = 0) -> FloatArray:
        """δ_e,HB (``derivative`` 0) or δ_e,HB' (1) of every element at times ``t``: shape
        t.shape + (m,)."""
        if derivative not in (0, 1):
            raise ValueError(f"`derivative` must be 0 or 1, got {derivative!r}")
        Q = self.coefficients_hb
        H = self.harmonics
        t = np.asarray(t, dtype=float)
        kw = np.arange(1, H + 1) * (self.omega / self.periods)
        ph = np.multiply.outer(t, kw)
        a, b = Q[:, 1 : H + 1].T, Q[:, H + 1 :].T
        if derivative == 0:
            return Q[:, 0] + np.cos(ph) @ a + np.sin(ph) @ b
        return np.cos(ph) @ (kw[:, None] * b) - np.sin(ph) @ (kw[:, None] * a)

    # --- measures ---------------------------------------------------------------------------
    @property
    def element_rms_error(self) -> FloatArray:
        """rms_hb / rms − 1 per element (m,): the regularisation's (and truncation's) effect on the
        rms; nan where the exact rms is 0 or missing."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.rms > 0.0, self.rms_hb / self.rms - 1.0, np.nan)

    @property
    def held_limit_error(self) -> FloatArray:
        """rms_held / rms − 1 per element (m,) of :attr:`held_limit` (nan without it)."""
        if self.held_limit is None:
            return np.full(self.m, np.nan)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.rms > 0.0, self.held_limit.rms / self.rms - 1.0, np.nan)

    @property
    def rms_error(self) -> float:
        """The element error of largest magnitude (signed); nan without an exact orbit."""
        err = self.element_rms_error
        if not np.any(np.isfinite(err)):
            return math.nan
        return float(err[np.nanargmax(np.abs(err))])

    @property
    def stable(self) -> bool | None:
        """Every exact multiplier inside the unit circle, up to 1e-8 (an element stuck the whole
        period gives a neutral multiplier 1: a family of orbits); None without an exact orbit."""
        if not self.converged:
            return None
        return bool(np.max(np.abs(self.multipliers)) < 1.0 + 1e-8)

    @property
    def stable_hb(self) -> bool | None:
        """The HB orbit's stability (its non-smooth monodromy); None where it is not known."""
        mu = np.abs(self.multipliers_hb)
        if not np.all(np.isfinite(mu)):
            return None
        return bool(np.max(mu) < 1.0 + 1e-8)

    @property
    def mu_abs(self) -> float:
        """max |μ| of the exact orbit (nan without one)."""
        return float(np.max(np.abs(self.multipliers)))

    @property
    def match_distance(self) -> float:
        """The largest departure of an exact δ_e(t) from the HB's over the samples, relative to
        the HB δ_e's peak-to-peak, over the elements not ``held`` (0 when all are); nan when
        either orbit is missing."""
        if not self.converged or not np.all(np.isfinite(self.delta_hb)):
            return math.nan
        free = [e for e, name in enumerate(self.element_names) if name not in self.held]
        if not free:
            return 0.0
        ptp = np.ptp(self.delta_hb, axis=0)
        size = np.maximum(ptp, 1e-12 * max(float(np.max(np.abs(self.delta_hb))), 1e-300))
        gap = np.max(np.abs(self.delta - self.delta_hb), axis=0) / size
        return float(np.max(gap[free]))

    @property
    def matched(self) -> bool:
        """The exact orbit is the HB orbit's (:attr:`match_distance` ≤ ``match``): otherwise the
        shooting found another orbit and the rms errors compare two different orbits."""
        return bool(self.match_distance <= self.match)

    # --- tables and plots -------------------------------------------------------------------
    def column_names(self) -> list[str]:
        """``t``, then per element NAME_ + :data:`FRICTION_ORBIT_ELEMENT_COLUMNS`."""
        return ["t"] + [f"{name}_{c}" for name in self.element_names for c in FRICTION_ORBIT_ELEMENT_COLUMNS]

    def columns(self) -> dict[str, np.ndarray]:
        """One period as columns (:meth:`column_names`): t, and per element NAME_delta,
        NAME_velocity, NAME_stuck (of the exact orbit; nan and False without one) and NAME_delta_hb."""
        cols: dict[str, np.ndarray] = {"t": self.t}
        for e, name in enumerate(self.element_names):
            cols[f"{name}_delta"] = self.delta[:, e]
            cols[f"{name}_velocity"] = self.velocity[:, e]
            cols[f"{name}_stuck"] = self.stuck[:, e]
            cols[f"{name}_delta_hb"] = self.delta_hb[:, e]
        return cols

    def to_csv(self, path: str | Path) -> Path:
        """Write :meth:`columns` to ``path`` atomically; returns the path."""
        from ..files import write_csv

        write_csv(path, self.columns(), self.column_names())
        return Path(path)

    def metadata(self) -> dict[str, Any]:
        """The scalars of the orbit as plain Python values (JSON-ready: nan → None): method, omega,
        speed_rpm, period, converged, status, message, start, hb_start, held, regularisation,
        harmonics, stable, stable_hb, mu_abs, multipliers_abs, multipliers_hb_abs, match,
        match_distance, matched, rms_error, and ``elements``: per element its name, rms, mean,
        stick_fraction, rms_hb, rms_error and ``stick_phases`` [[t_start, t_end], …]; ``orbits``: every orbit
        at Ω (:attr:`solutions`), ``nonperiodic``: the non-periodic attractors there."""
        err = self.element_rms_error
        elements = [{"name": name, "rms": _num(self.rms[e]), "mean": _num(self.mean[e]),
                     "stick_fraction": _num(self.stick_fraction[e]), "rms_hb": _num(self.rms_hb[e]),
                     "rms_error": _num(err[e]), "stick_phases": [[a, b] for a, b in self.stick_intervals[e]]}
                    for e, name in enumerate(self.element_names)]
        return {
            "method": "exact event-driven shooting (Filippov sticking, saltation monodromy) started from the "
                      "chain's regularised harmonic balance (rattle.analysis.friction_orbit)",
            "omega": self.omega, "speed_rpm": None if self.speed_rpm is None else _num(self.speed_rpm),
            "period": self.period, "periods": self.periods, "converged": bool(self.converged), "status": self.status.name.lower(),
            "message": self.message, "start": self.start, "hb_start": self.hb_start, "held": list(self.held),
            "regularisation": self.regularisation, "harmonics": self.harmonics,
            "stable": self.stable, "stable_hb": self.stable_hb, "mu_abs": _num(self.mu_abs),
            "multipliers_abs": [_num(v) for v in np.abs(self.multipliers)],
            "multipliers_hb_abs": [_num(v) for v in np.abs(self.multipliers_hb)],
            "match": self.match, "match_distance": _num(self.match_distance), "matched": self.matched,
            "rms_error": _num(self.rms_error), "elements": elements,
            "held_limit": None if self.held_limit is None else {
                **self.held_limit.to_dict(), "rms_error": [_num(v) for v in self.held_limit_error]},
            **every_orbit_records(self.solutions, self.nonperiodic),
        }

    def every_orbit_text(self) -> list[str]:
        """The terminal lines of every orbit found at Ω (:attr:`solutions`, :attr:`nonperiodic`)."""
        return every_orbit_lines(self.omega, self.solutions, self.nonperiodic, self.speed_rpm)

    def summary(self) -> str:
        """A few lines: the orbit, every element's exact and HB rms and stick phases, the stability."""
        lines = [f"orbit at Ω = {self.omega:.6g} rad/s (period {self.period:.6g} s"
                 + ("" if self.periods == 1 else f", {self.periods} forcing periods") + ")"
                 + ("" if self.speed_rpm is None else f", engine speed {self.speed_rpm:.5g} rpm")
                 + f": chain with friction, elements {', '.join(self.element_names)}"]
        hb = f"HB (H = {self.harmonics}, ε = {self.regularisation:g})"
        err = self.element_rms_error
        for e, name in enumerate(self.element_names):
            if self.converged:
                phases = self.stick_intervals[e]
                stick = (f"sticks {self.stick_fraction[e]:.1%} of the period in {len(phases)} phase(s)"
                         if phases else "slips throughout")
                hb_text = (f"{hb} rms {self.rms_hb[e]:.6g} (error {err[e]:+.2g})" if np.isfinite(self.rms_hb[e])
                           else "no HB orbit")
                lines.append(f"{name}: exact rms {self.rms[e]:.6g} rad, mean {self.mean[e]:.6g} rad, {stick}; {hb_text}")
            else:
                lines.append(f"{name}: no exact orbit; {hb} rms {self.rms_hb[e]:.6g}")
        if self.held_limit is not None:
            hl, herr = self.held_limit, self.held_limit_error
            parts = ", ".join(f"{name} rms {hl.rms[e]:.6g} (error {herr[e]:+.2g})" for e, name in enumerate(self.element_names)
                              if name in hl.elements)
            lines.append(f"held elements' own steps narrowed to {hl.scale:.2g} of the chain's (ε = {hl.eps:g}, "
                         f"H = {hl.harmonics}, N = {hl.samples}; {hl.status}, {hl.seconds:.0f} s): {parts}")
        if self.converged:
            how = (f"{'matched' if self.matched else 'NOT matched'} by the HB orbit (distance {self.match_distance:.2g})"
                   if np.isfinite(self.match_distance) else "no HB orbit beside it")
            lines.append(f"{'stable' if self.stable else 'unstable'} (max |μ| = {self.mu_abs:.4g}); exact orbit from "
                         f"{self.start}, {how}")
        if self.message:
            lines.append(self.message)
        lines += self.every_orbit_text()
        return "\n".join(lines)

    def plot(self) -> tuple:
        """δ_e(t) exact and HB, one panel per element, the stick phases shaded; returns
        (figure, PlotAxes). See :func:`rattle.plotting.friction_orbit_plot`."""
        return plot_with("friction_orbit_plot", self)

    def __repr__(self) -> str:
        if not self.converged:
            return f"FrictionOrbitResult(Ω = {self.omega:.6g}, no exact orbit: {self.message})"
        rms = ", ".join(f"{n} {r:.4g}" for n, r in zip(self.element_names, self.rms))
        return (f"FrictionOrbitResult(Ω = {self.omega:.6g}, rms {rms} rad (HB {self.rms_error:+.2e}), "
                f"{'stable' if self.stable else 'unstable'}, from {self.start})")


__all__ = ["FRICTION_ORBIT_ELEMENT_COLUMNS", "FrictionOrbitResult", "HeldLimitRecord"]
