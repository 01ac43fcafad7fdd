"""The exact-check column group of a chain with Coulomb friction or jumps on its elements.

A :class:`~rattle.results.FrequencyResponse` of such a chain carries one :class:`FrictionCheck` in
``check``: the rows of its continued branch (and, in ``branches``, its sub-harmonic ones).

Each row is a point of the chain's regularised harmonic balance
(:mod:`rattle.analysis._friction_response`) and, where exact Newton shooting on the event-driven
flow found the same orbit (``matched``), that exact orbit: every element's rms, mean and stick
fraction, the 2n Floquet multipliers (saltation matrices; a stuck element contributes zero
multipliers). The HB's own rms (per element) and multipliers (the non-smooth monodromy of one
period of the exact flow from the HB state) stand beside them, so that the regularisation's
effect is read row by row: ``rms_error`` = the largest relative HB error over the elements.
Where a row is not matched the exact columns are nan and ``stable`` is the HB orbit's.

``bifurcation`` labels a row whose stability differs from the previous matched row's by the
multiplier that crossed (:func:`rattle.stability.classify_loss`): fold (+1), period doubling
(−1) or Neimark–Sacker (a complex pair); the change lies between the two rows (not located).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..errors import Status
from ..stability import classify_loss
from ._check import branch_lines, branch_metadata
from ._speed import SpeedText

#: The per-element columns of :meth:`FrictionCheck.columns`, NAME_ prefixed, in this order.
FRICTION_ELEMENT_COLUMNS = ("rms", "rms_hb", "mean", "stick", "rms_error", "rms_hb_limit", "rms_hb_extrapolated",
                            "rms_hb_held")
#: The columns closing each row.
FRICTION_TAIL_COLUMNS = ("matched", "stable", "stable_hb", "mu_abs", "mu_hb_abs", "rms_error", "bifurcation",
                         "eps_limit", "match_distance", "stable_hb_limit")


@dataclass(frozen=True, slots=True, eq=False)
class FrictionCheck:
    """Rows of a continued branch of a chain with friction (P rows, m elements, n coordinates).

    ``omega`` (P,); ``rpm`` (P,) the crankshaft speed, None without an engine order;
    ``element_names`` (m); from the exact orbit (nan where not ``matched``): ``rms``, ``mean`` and
    ``stick_fraction`` (P, m: the fraction of the period each element sticks); ``rms_hb`` (P, m)
    of the regularised HB orbit; ``match_distance`` (P,) the largest departure of an exact δ_e(t)
    from the HB's relative to the HB δ_e's peak-to-peak (nan where the shooting failed);
    ``multipliers`` (P, 2n) the exact orbit's (the HB's where not matched), ``multipliers_hb``
    (P, 2n) the HB orbit's, largest modulus first (nan where none could be found); ``stable``,
    ``stable_hb`` every multiplier inside the unit circle (False where none could be found); ``status``, ``message`` of the continuation; ``regularisation`` ε and
    ``harmonics`` H.

    The regularisation continued to its limit at the rows ``limit_index``: ``limit_eps`` the
    smallest ε reached (nan: the ladder stalled), ``limit_harmonics`` H there, ``limit_rms`` (k, m)
    the HB rms there, ``limit_richardson`` (k, m) Richardson's ε → 0 value, ``limit_linear``
    whether the last three rungs lie on a line in ε for every element (Richardson's value then
    holds), ``limit_multipliers`` (k, 2n) the multipliers of the HB orbit at the smallest ε
    (:attr:`stable_hb_limit`). ``pattern`` (P, 2m): the exact orbit's stick phases (columns 0 … m−1)
    and breakpoint crossings (m … 2m−1) per period of every element, −1 where not matched.

    ``period`` p: the orbits repeat after p forcing periods (1: the primary branch; 2: a
    sub-harmonic branch born at a period doubling, :func:`rattle.analysis._friction_subharmonics.friction_subharmonics`);
    ``branch`` its number (0 the primary), ``origin`` where it was born; ``states`` (P, 2n) the
    exact orbit's z(0) = (x, x') (nan where not matched). The primary branch carries the
    sub-harmonic ones in ``branches`` (empty unless asked for); :meth:`to_csv` writes them all, the
    primary's rows first. ``followed``: how the branch was continued, ``"harmonic balance"`` or
    ``"exact shooting"`` (a sub-harmonic branch the regularised HB has no orbit for: every row an
    exact orbit, the HB columns nan).

    With ``RegularisationOptions(held=True)``: at the matched rows ``held_index`` where the exact
    orbit holds an element part of the period, the HB with that element's own steps narrowed to
    their limit (:func:`rattle.analysis._held_limit.held_limit`): ``held_rms`` (k, m) every
    element's HB rms there (nan: the ladder failed), ``held_status`` (k,) ``"converged"``,
    ``"stalled"``, ``"floor"`` or ``"failed"``, ``held_scale`` (k,) the held steps' width relative
    to the chain's at the last rung. The HB's ε → 0 estimate of a held element
    (:attr:`rms_hb_estimate`) is then that rms. ``labels`` (P,): the special points located on an
    exact branch (exact shooting continuation), "" elsewhere; None: named between rows
    (:attr:`bifurcation`)."""

    omega: FloatArray
    rpm: FloatArray | None
    element_names: tuple[str, ...]
    rms: FloatArray
    rms_hb: FloatArray
    mean: FloatArray
    stick_fraction: FloatArray
    matched: np.ndarray
    match_distance: FloatArray
    stable: np.ndarray
    stable_hb: np.ndarray
    multipliers: ComplexArray
    multipliers_hb: ComplexArray
    status: Status
    message: str
    regularisation: float
    harmonics: int
    limit_index: np.ndarray
    limit_eps: FloatArray
    limit_harmonics: np.ndarray
    limit_rms: FloatArray
    limit_richardson: FloatArray
    limit_linear: np.ndarray
    limit_multipliers: ComplexArray | None = None
    pattern: np.ndarray | None = None
    period: int = 1
    branch: int = 0
    origin: str = ""
    states: FloatArray | None = None
    branches: tuple[FrictionCheck, ...] = ()
    followed: str = "harmonic balance"
    held_index: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    held_rms: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    held_status: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=object))
    held_scale: FloatArray = field(default_factory=lambda: np.zeros(0))
    labels: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.omega.size)

    # --- derived columns ----------------------------------------------------------------------
    @property
    def stick_time(self) -> FloatArray:
        """(P, m): the time each element sticks per orbit period, stick_fraction · p·2π/Ω: the
        single equation's name (:attr:`NonsmoothCheck.stick_time`) for the same measure."""
        return self.stick_fraction * (2.0 * np.pi * self.period / self.omega)[:, None]

    @property
    def element_rms_error(self) -> FloatArray:
        """rms_hb / rms − 1 per row and element (P, m); nan where not matched."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.rms_hb / self.rms - 1.0

    @property
    def rms_error(self) -> FloatArray:
        """Per row the element error of largest magnitude (signed), rms_hb / rms − 1; nan where not
        matched."""
        err = self.element_rms_error
        out = np.full(len(self), np.nan)
        ok = np.all(np.isfinite(err), axis=1)
        if np.any(ok):
            j = np.argmax(np.abs(err[ok]), axis=1)
            out[ok] = err[ok][np.arange(j.size), j]
        return out

    @property
    def mu_abs(self) -> FloatArray:
        """max |μ| of the exact orbit (the HB's where not matched)."""
        return np.abs(self.multipliers).max(axis=1) if self.multipliers.size else np.full(len(self), np.nan)

    @property
    def mu_hb_abs(self) -> FloatArray:
        """max |μ| of the HB orbit."""
        return np.abs(self.multipliers_hb).max(axis=1) if self.multipliers_hb.size else np.full(len(self), np.nan)

    @property
    def stable_hb_limit(self) -> np.ndarray:
        """The HB orbit's stability at its limit: at the ladder's rows that of the orbit at the
        smallest ε, elsewhere :attr:`stable_hb`."""
        out = self.stable_hb.copy()
        if self.limit_multipliers is not None and self.limit_index.size:
            mu = np.abs(self.limit_multipliers).max(axis=1)
            ok = np.isfinite(mu)
            out[self.limit_index[ok]] = mu[ok] < 1.0 + 1e-8
        return out

    @property
    def stability_agrees(self) -> np.ndarray:
        """Per matched row: the exact and the HB orbit's stability agree (False elsewhere)."""
        return self.matched & (self.stable == self.stable_hb)

    @property
    def stability_agrees_limit(self) -> np.ndarray:
        """As :attr:`stability_agrees` with the HB at its limit (:attr:`stable_hb_limit`)."""
        return self.matched & (self.stable == self.stable_hb_limit)

    def _per_row(self, values: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        out = np.full((len(self),) + values.shape[1:], np.nan)
        out[self.limit_index if index is None else index] = values
        return out

    @property
    def rms_hb_held(self) -> FloatArray:
        """(P, m): the HB rms of every element held part of the period with its own steps narrowed
        to their limit (:attr:`held_rms`), nan elsewhere (the elements that move, the rows without)."""
        m = len(self.element_names)
        if not self.held_index.size:
            return np.full((len(self), m), np.nan)
        out = self._per_row(self.held_rms.reshape(-1, m), self.held_index)
        return np.where(self._held_part(), out, np.nan)

    @property
    def rms_hb_limit(self) -> FloatArray:
        """(P, m): the HB rms at the smallest ε of the ladder (nan at the rows without one)."""
        return self._per_row(self.limit_rms.reshape(-1, len(self.element_names)))

    @property
    def rms_hb_extrapolated(self) -> FloatArray:
        """(P, m): Richardson's ε → 0 value where the ladder's last rungs are linear, else nan."""
        rich = np.where(self.limit_linear[:, None], self.limit_richardson.reshape(-1, len(self.element_names)), np.nan)
        return self._per_row(rich)

    @property
    def rms_hb_estimate(self) -> FloatArray:
        """(P, m): the HB's ε → 0 estimate: of an element held part of the period, its rms with its
        own steps narrowed (:attr:`rms_hb_held`) where computed; else Richardson's value where it
        holds, else the rms at the ladder's smallest ε, else ``rms_hb``."""
        ext, lim, held = self.rms_hb_extrapolated, self.rms_hb_limit, self.rms_hb_held
        out = np.where(np.isfinite(ext), ext, np.where(np.isfinite(lim), lim, self.rms_hb))
        return np.where(np.isfinite(held), held, out)

    @property
    def hb_error(self) -> FloatArray:
        """(P,): the largest relative error over the elements of :attr:`rms_hb_estimate`."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.max(np.abs(self.rms_hb_estimate / self.rms - 1.0), axis=1)

    @property
    def bifurcation(self) -> np.ndarray:
        """The bifurcation between each row and the previous matched row ("" none): a change of
        stability by its kind (``fold``, ``period_doubling``, ``neimark_sacker``), else a change of
        the exact orbit's switching pattern (:attr:`pattern`), a discontinuity-induced bifurcation:
        ``grazing_sliding`` where an element's stick phase appears or vanishes, ``grazing`` where a
        pair of its breakpoint crossings does."""
        out = np.full(len(self), "", dtype=object)
        pat = self.pattern
        m = len(self.element_names)
        if self.labels is not None:  # located on the exact branch: the labels; structure changes between rows
            out[:] = self.labels
            if pat is not None:
                for i in range(1, len(self)):
                    if out[i] or out[i - 1]:
                        continue
                    if np.any(pat[i, :m] != pat[i - 1, :m]):
                        out[i] = "grazing_sliding"
                    elif np.any(pat[i, m:] != pat[i - 1, m:]):
                        out[i] = "grazing"
            return out
        prev = None
        for i in np.flatnonzero(self.matched):
            if prev is not None:
                if bool(self.stable[i]) != bool(self.stable[prev]):
                    out[i] = classify_loss(self.multipliers[prev], self.multipliers[i])
                elif pat is not None and min(pat[i].min(), pat[prev].min()) >= 0:
                    if np.any(pat[i, :m] != pat[prev, :m]):
                        out[i] = "grazing_sliding"
                    elif np.any(pat[i, m:] != pat[prev, m:]):
                        out[i] = "grazing"
            prev = i
        return out

    # --- output -------------------------------------------------------------------------------
    def column_names(self) -> list[str]:
        """branch, period, omega, speed_rpm (with an engine order), NAME_ + :data:`FRICTION_ELEMENT_COLUMNS`
        per element, then :data:`FRICTION_TAIL_COLUMNS`."""
        head = ["branch", "period", "omega"] + ([] if self.rpm is None else ["speed_rpm"])
        per = [f"{name}_{c}" for name in self.element_names for c in FRICTION_ELEMENT_COLUMNS]
        return head + per + list(FRICTION_TAIL_COLUMNS)

    def columns(self) -> dict[str, np.ndarray]:
        """The rows as columns, in the order of :meth:`column_names`."""
        cols: dict[str, np.ndarray] = {"branch": np.full(len(self), self.branch, dtype=np.int64),
                                       "period": np.full(len(self), self.period, dtype=np.int64), "omega": self.omega}
        if self.rpm is not None:
            cols["speed_rpm"] = self.rpm
        err = self.element_rms_error
        lim, ext, held = self.rms_hb_limit, self.rms_hb_extrapolated, self.rms_hb_held
        for e, name in enumerate(self.element_names):
            cols[f"{name}_rms"] = self.rms[:, e]
            cols[f"{name}_rms_hb"] = self.rms_hb[:, e]
            cols[f"{name}_mean"] = self.mean[:, e]
            cols[f"{name}_stick"] = self.stick_fraction[:, e]
            cols[f"{name}_rms_error"] = err[:, e]
            cols[f"{name}_rms_hb_limit"] = lim[:, e]
            cols[f"{name}_rms_hb_extrapolated"] = ext[:, e]
            cols[f"{name}_rms_hb_held"] = held[:, e]
        cols.update(matched=self.matched, stable=self.stable, stable_hb=self.stable_hb, mu_abs=self.mu_abs,
                    mu_hb_abs=self.mu_hb_abs, rms_error=self.rms_error, bifurcation=self.bifurcation,
                    eps_limit=self._per_row(self.limit_eps), match_distance=self.match_distance,
                    stable_hb_limit=self.stable_hb_limit)
        return cols

    def all_columns(self) -> dict[str, np.ndarray]:
        """:meth:`columns` of this branch followed by those of each of :attr:`branches`."""
        parts = [self.columns()] + [b.columns() for b in self.branches]
        return {k: np.concatenate([np.asarray(p[k]) for p in parts]) for k in parts[0]}

    def metadata(self) -> dict[str, Any]:
        """A JSON-able summary of the run: settings, counts and the measured HB error."""
        matched = int(np.sum(self.matched))
        err = np.abs(self.rms_error[self.matched])

        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {
            "method": "exact shooting continuation on the event-driven period map (Filippov sticking, saltation "
                      "monodromy)" if self.followed == "exact shooting" else
                      "regularised harmonic balance, checked by exact event-driven shooting (Filippov sticking, "
                      "saltation monodromy)",
            "regularisation": self.regularisation, "harmonics": self.harmonics,
            "elements": list(self.element_names), "rows": len(self), "matched": matched,
            "within_0_5_percent": int(np.sum(err <= 0.005)),
            "within_0_5_percent_moving": int(np.sum(self.moving_rms_error[self.matched] <= 0.005)),
            "within_0_5_percent_moving_estimate": int(np.sum(self.moving_hb_error[self.matched] <= 0.005)),
            "held_rows": int(np.sum(np.any(self._held(), axis=1) & self.matched)),
            "max_rms_error": num(float(np.max(err))) if err.size else None,
            "median_rms_error": num(float(np.median(err))) if err.size else None,
            "stability_agrees": int(np.sum(self.stability_agrees)),
            "stability_agrees_limit": int(np.sum(self.stability_agrees_limit)),
            "unstable_rows": int(np.sum(~self.stable)),
            "sticking_rows": int(np.sum(np.nan_to_num(self.stick_fraction).max(axis=1) > 0)) if len(self) else 0,
            "refined_rows": int(self.limit_index.size),
            **self._held_counts(),
            "refined_max_error": num(float(np.nanmax(self.hb_error[self.limit_index])))
            if self.limit_index.size and np.any(np.isfinite(self.hb_error[self.limit_index])) else None,
            "status": self.status.name,
            "message": self.message,
        }

    def to_dict(self) -> dict[str, Any]:
        """:meth:`metadata` plus the columns as lists (nan → None): JSON-able."""
        def clean(v: Any) -> Any:
            if isinstance(v, (bool, np.bool_)):
                return bool(v)
            if isinstance(v, (float, np.floating)):
                return float(v) if math.isfinite(float(v)) else None
            if isinstance(v, (int, np.integer)):
                return int(v)
            return str(v)

        cols = self.columns()
        return {"metadata": self.metadata(),
                "columns": {k: [clean(v) for v in np.asarray(cols[k]).tolist()] for k in self.column_names()}}

    def _held(self) -> np.ndarray:
        """(P, m): the element is held (stuck or locked) part of the period on the exact orbit."""
        return np.nan_to_num(self.stick_fraction) > 0

    def _held_part(self) -> np.ndarray:
        """(P, m): held part of the period, not all of it (0 < stick fraction < 1)."""
        st = np.nan_to_num(self.stick_fraction)
        return (st > 0) & (st < 1.0)

    def _held_counts(self) -> dict[str, Any]:
        """held_limit_rows (rows with the held elements' own ladder), held_limit_within_0_5_percent
        (of those, the rows where every held element's narrowed HB rms is within 0.5 % of the
        exact one), held_limit_max_error, held_limit_converged."""
        if not self.held_index.size:
            return {"held_limit_rows": 0}
        with np.errstate(invalid="ignore", divide="ignore"):
            err = np.abs(self.rms_hb_held / self.rms - 1.0)[self.held_index]
        part = self._held_part()[self.held_index]
        worst = np.max(np.where(part, np.nan_to_num(err, nan=np.inf), 0.0), axis=1)
        finite = worst[np.isfinite(worst)]
        return {"held_limit_rows": int(self.held_index.size),
                "held_limit_within_0_5_percent": int(np.sum(worst <= 0.005)),
                "held_limit_max_error": float(np.max(finite)) if finite.size else None,
                "held_limit_converged": int(np.sum(self.held_status == "converged"))}

    @property
    def moving_rms_error(self) -> FloatArray:
        """(P,): the largest |rms_hb / rms − 1| over the elements *not held* on the row (nan where
        not matched; 0 where every element is held). A held element (stuck or locked part of the
        period) moves within the regularisation's width of its stuck deflection or jump, where the
        HB resolves it only to a few widths ε_δ: its relative error says little of the orbit."""
        return self._moving(self.rms_hb)

    @property
    def moving_hb_error(self) -> FloatArray:
        """(P,): :attr:`moving_rms_error` of the HB's ε → 0 estimate (:attr:`rms_hb_estimate`)."""
        return self._moving(self.rms_hb_estimate)

    def _moving(self, hb: FloatArray) -> FloatArray:
        if not len(self):
            return np.zeros(0)
        with np.errstate(invalid="ignore", divide="ignore"):
            err = np.abs(hb / self.rms - 1.0)
        out = np.max(np.where(self._held(), 0.0, np.nan_to_num(err, nan=np.inf)), axis=1)
        return np.where(self.matched, out, np.nan)

    @property
    def speed(self) -> SpeedText:
        """Speeds in text: rpm with an engine order (``rpm`` given), else Ω."""
        if self.rpm is None or not len(self) or not self.rpm[0] > 0:
            return SpeedText()
        return SpeedText(float(self.omega[0]) * 60.0 / (2.0 * math.pi * float(self.rpm[0])))

    def summary(self) -> str:
        """A few lines: the branch, how many rows the exact orbit confirmed, the HB's error."""
        md = self.metadata()
        P = len(self)
        lines = [f"chain with friction, elements {', '.join(self.element_names)}: {P} rows, "
                 f"Ω = {self.omega.min():.5g} … {self.omega.max():.5g} rad/s" if P else "no rows"]
        if self.rpm is not None and P:
            lines.append(f"engine speed {self.rpm.min():.5g} … {self.rpm.max():.5g} rpm")
        shooting = self.followed == "exact shooting"
        if shooting:
            lines.append(f"exact shooting continuation: every row an exact orbit; {int(np.sum(~self.stable))} of {P} "
                         "unstable")
        else:
            lines.append(f"regularised HB ε = {self.regularisation:g}, H = {self.harmonics}; exact orbit matched on "
                         f"{md['matched']} of {P} rows")
        if md["matched"] and not shooting:
            lines.append(f"HB rms vs exact (largest over the elements): within 0.5 % on {md['within_0_5_percent']} "
                         f"of {md['matched']} matched rows, max {100 * (md['max_rms_error'] or 0):.3g} %, median "
                         f"{100 * (md['median_rms_error'] or 0):.3g} %")
            if md["held_rows"]:
                lines.append(f"on the {md['held_rows']} rows where an element is held (stuck or locked part of the "
                             f"period) the HB with the chain's widths resolves that element only to their width"
                             + (" (its own steps narrowed below)" if self.held_index.size
                                else " (`held` narrows its own steps)") + "; the elements "
                             f"moving: within 0.5 % on {md['within_0_5_percent_moving']} of {md['matched']} rows"
                             + (f" at ε, on {md['within_0_5_percent_moving_estimate']} with the HB's ε → 0 estimate"
                                if self.limit_index.size else ""))
            lines.append(f"stability (exact vs HB monodromy) agrees on {md['stability_agrees']} of {md['matched']} "
                         f"({md['stability_agrees_limit']} with the HB at its limit where refined)")
        if self.held_index.size:
            worst = md["held_limit_max_error"]
            lines.append(f"held elements' own steps narrowed to their limit on {md['held_limit_rows']} rows "
                         f"({md['held_limit_converged']} converged): their HB rms within 0.5 % of the exact on "
                         f"{md['held_limit_within_0_5_percent']}"
                         + ("" if worst is None else f", max {100 * worst:.3g} %"))
        if self.limit_index.size:
            txt = "n/a" if md["refined_max_error"] is None else f"{100 * md['refined_max_error']:.3g} %"
            lines.append(f"regularisation continued towards ε → 0 on {self.limit_index.size} rows "
                         f"(smallest ε {np.nanmin(self.limit_eps) if np.any(np.isfinite(self.limit_eps)) else math.nan:g}):"
                         f" largest error of the HB's ε → 0 estimate {txt}")
        for e, name in enumerate(self.element_names):
            st = np.nan_to_num(self.stick_fraction[:, e])
            if np.any(st > 0):
                w = self.omega[st > 0]
                lines.append(f"{name} sticks on {int(np.sum(st > 0))} rows ({self.speed.span(w.min(), w.max(), 4)}, "
                             f"up to {st.max():.0%} of the period)")
        labels = self.bifurcation
        where = "at" if self.labels is not None else "near"  # located on an exact branch, or between rows
        for i in np.flatnonzero(labels != ""):
            lines.append(f"{labels[i].replace('_', ' ')} {where} {self.speed.at(self.omega[i], 7)}")
        if not self.status.success:
            lines.append(f"continuation: {self.message}")
        return "\n".join(lines)

    def frf_metadata(self, system: Any, settings: dict[str, Any], timings: dict[str, float]) -> dict[str, Any]:
        """The ``frf.json`` sections (:meth:`FrequencyResponse.metadata`): the method's
        ``settings``, the elements of ``system`` (law, friction level per stage relative to the
        element's stiffness, the matched rows where it sticks), status and message, the rows, this
        group's own counts and measured HB error (:meth:`metadata`), the sub-harmonic branches and
        ``timings``."""
        own = {k: v for k, v in self.metadata().items() if k not in ("method", "regularisation", "harmonics",
                                                                      "status", "message")}
        matched = np.asarray(self.matched, dtype=bool)
        stick = np.nan_to_num(np.asarray(self.stick_fraction, dtype=float).reshape(len(self), -1))
        elements = [{"name": name, "law": law.elastic.to_dict(),
                     "friction": [float(r) for r in system.friction_levels(e)],
                     "sticking_rows": int(np.count_nonzero(matched & (stick[:, e] > 0)))}
                    for e, (name, law) in enumerate(zip(system.element_names, system.laws))]
        return {
            "settings": dict(settings),
            "system": {"coordinates": int(system.n), "elements": elements},
            "status": self.status.name.lower(),
            "message": self.message or self.status.message,
            "points": len(self),
            **own,
            "branches": [branch_metadata(b) for b in self.branches],
            "timings": dict(timings),
        }

    def frf_summary(self, settings: dict[str, Any]) -> str:
        """What ``rattle frf`` prints (:meth:`FrequencyResponse.summary`): :meth:`summary`, the
        continuation's status, every element's largest exact rms, and the sub-harmonic branches
        (``settings["subharmonics"]``: whether they were asked for)."""
        lines = [self.summary(), f"status: {self.status.name.lower()} — {self.message or self.status.message}"]
        matched = np.asarray(self.matched, dtype=bool)
        rms = np.asarray(self.rms, dtype=float).reshape(len(self), -1)
        for e, name in enumerate(self.element_names):
            col = np.where(matched, rms[:, e], np.nan)
            if np.any(np.isfinite(col)):
                j = int(np.nanargmax(col))
                lines.append(f"{name}: largest exact rms {col[j]:.5g} rad at {self.speed.at(self.omega[j])}")
        lines.extend(branch_lines(self, bool(settings.get("subharmonics")), self.speed))
        return "\n".join(lines)


__all__ = ["FRICTION_ELEMENT_COLUMNS", "FRICTION_TAIL_COLUMNS", "FrictionCheck"]
