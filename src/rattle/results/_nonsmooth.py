"""The exact-check column group of a discontinuous law's (preload, friction) frequency response.

A :class:`~rattle.results.FrequencyResponse` of a single equation with jumps or friction carries
one :class:`NonsmoothCheck` in ``check``: the rows of its continued branch (and, in ``branches``,
its sub-harmonic ones) with what the exact check measured.

Each row is a point of the regularised harmonic balance (:mod:`rattle.analysis._nonsmooth`) and,
where exact Newton shooting on the event-driven flow found the same orbit (``matched``), that exact
orbit: its SPEC §1 measures, its Floquet multipliers (saltation matrices, a zero multiplier per
stick phase), its stick time. The HB's own rms and multipliers stand beside them, so that the
regularisation's effect is read row by row (``rms_error``). Where a row is not matched, the exact
columns are empty (nan) and ``stable`` is the regularised orbit's.

``bifurcation`` labels a row whose stability differs from the previous matched row's, from the
multiplier that crossed (:func:`rattle.stability.classify_loss`: through +1 a fold, through −1 a
period doubling, a complex pair a Neimark–Sacker point): the change lies between the two rows
(not located).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from ..errors import Status
from ..stability import classify_loss
from ._check import branch_lines, branch_metadata, largest

#: The columns of :meth:`NonsmoothCheck.columns`: the SPEC §3 ones, then the extension.
NONSMOOTH_COLUMNS = ("branch", "period", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "regime", "stable", "bifurcation",
                     "rms_hb", "rms_error", "matched", "stick_time", "mu1_abs", "mu2_abs", "mu1_hb_abs", "mu2_hb_abs", "eps_limit", "rms_hb_limit",
                     "rms_hb_extrapolated", "rms_error_limit", "sticks", "crossings")


@dataclass(frozen=True, slots=True)
class NonsmoothCheck:
    """Rows of a continued branch (arrays of length P) and how the run ended.

    ``omega``; ``rms_hb`` of the regularised HB orbit; from the exact orbit (nan where not
    ``matched``): ``mean``, ``rms``, ``rms_ac``, ``p2p`` and ``acc_p2p`` of δ and δ'', ``regime``,
    ``stick_time`` per period, the switching pattern ``sticks`` (stick and lock phases per period)
    and ``crossings`` (breakpoint crossings per period; −1 where not matched); ``rms_error`` = rms_hb / rms − 1; ``stable`` from the exact
    multipliers ``multipliers`` (P, 2) (the HB's where not matched); ``multipliers_hb`` (P, 2) of
    the HB orbit (by default the non-smooth monodromy of one period of the exact flow from its
    state, saltations included; :class:`~rattle.analysis.RegularisationOptions` ``stability``); ``status``, ``message``; ``regularisation`` ε and ``harmonics`` H.

    The regularisation continued to its limit at the rows ``limit_index`` (evenly spread ones and
    those whose HB missed the exact rms by more than the ``refine`` tolerance): ``limit_eps`` the
    smallest ε reached, ``limit_rms`` the HB rms there, ``limit_richardson`` the Richardson ε → 0
    value (:attr:`limit_error`, :attr:`richardson_error` against the exact rms of the row) and
    ``limit_linear`` whether the ladder's last rungs lie on a line in ε (Richardson's value then
    holds). As columns (nan at the other rows): ``eps_limit``, ``rms_hb_limit``,
    ``rms_hb_extrapolated`` (Richardson's value where linear) and ``rms_error_limit``;
    :attr:`hb_error` is the error of the HB's ε → 0 estimate on every row.

    ``period`` p: the orbits repeat after p forcing periods (1: the primary branch; 2: a
    sub-harmonic branch born at a period doubling, :func:`rattle.analysis._nonsmooth.nonsmooth_subharmonics`);
    ``branch`` its number (0 the primary), ``origin`` where it was born; ``states`` (P, 2) the
    exact orbit's (δ, δ') at t = 0 (nan where not matched). The primary branch carries the
    sub-harmonic ones in ``branches`` (empty unless asked for); :meth:`to_csv` writes them all,
    the primary's rows first. ``followed``: how the branch was continued, ``"harmonic balance"``
    (the regularised HB, every row checked by exact shooting) or ``"exact shooting"`` (a
    sub-harmonic branch the regularised HB has no orbit for: every row an exact orbit, ``matched``
    true, the HB's columns nan). ``labels`` (P,): the special points located on an exact branch
    (:func:`rattle.frequency_response` by exact shooting), "" elsewhere; None: the
    stability changes between rows are named from their multipliers (:attr:`bifurcation`)."""

    omega: FloatArray
    rms_hb: FloatArray
    mean: FloatArray
    rms: FloatArray
    rms_ac: FloatArray
    p2p: FloatArray
    acc_p2p: FloatArray
    regime: np.ndarray
    stable: np.ndarray
    multipliers: ComplexArray
    multipliers_hb: ComplexArray
    stick_time: FloatArray
    matched: np.ndarray
    status: Status
    message: str
    regularisation: float
    harmonics: int
    limit_index: np.ndarray
    limit_eps: FloatArray
    limit_rms: FloatArray
    limit_richardson: FloatArray
    limit_linear: np.ndarray
    sticks: np.ndarray | None = None
    crossings: np.ndarray | None = None
    period: int = 1
    branch: int = 0
    origin: str = ""
    states: FloatArray | None = None
    branches: tuple[NonsmoothCheck, ...] = ()
    followed: str = "harmonic balance"
    labels: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in ("sticks", "crossings"):  # not given: unknown (-1) on every row
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.full(self.omega.size, -1, dtype=np.int64))
        if self.states is None:
            object.__setattr__(self, "states", np.full((self.omega.size, 2), np.nan))

    def __len__(self) -> int:
        return int(self.omega.size)

    @property
    def stick_fraction(self) -> FloatArray:
        """The share of the orbit's period p·2π/Ω that δ sticks or locks, stick_time / (p·2π/Ω):
        the chain's name (:attr:`FrictionCheck.stick_fraction`) for the same measure."""
        return self.stick_time * self.omega / (2.0 * np.pi * self.period)

    @property
    def rms_error(self) -> FloatArray:
        """rms_hb / rms − 1: the regularisation's (and truncation's) effect on the rms, row by row."""
        return self.rms_hb / self.rms - 1.0

    @property
    def limit_error(self) -> FloatArray:
        """limit_rms / rms − 1 at the ladder's rows."""
        return self.limit_rms / self.rms[self.limit_index] - 1.0

    @property
    def richardson_error(self) -> FloatArray:
        """limit_richardson / rms − 1 at the ladder's rows."""
        return self.limit_richardson / self.rms[self.limit_index] - 1.0

    def _per_row(self, values: FloatArray) -> FloatArray:
        out = np.full(len(self), np.nan)
        out[self.limit_index] = values
        return out

    @property
    def rms_hb_estimate(self) -> FloatArray:
        """The HB's ε → 0 estimate of the rms on each row: where the regularisation was continued
        to its limit, Richardson's value if the last rungs are linear in ε, else the rms at the
        smallest ε; elsewhere the rms at ε (``rms_hb``)."""
        ext = self._per_row(np.where(self.limit_linear, self.limit_richardson, np.nan))
        lim = self._per_row(self.limit_rms)
        return np.where(np.isfinite(ext), ext, np.where(np.isfinite(lim), lim, self.rms_hb))

    @property
    def hb_error(self) -> FloatArray:
        """The relative error of :attr:`rms_hb_estimate` against the exact rms (nan where not
        matched)."""
        return self.rms_hb_estimate / self.rms - 1.0

    @property
    def bifurcation(self) -> np.ndarray:
        """The bifurcation between each row and the previous matched row ("" none): a change of
        stability by its kind (:func:`~rattle.stability.classify_loss`: ``fold``,
        ``period_doubling``, ``neimark_sacker``), else a change of the exact orbit's switching
        pattern, a discontinuity-induced bifurcation: ``grazing_sliding`` where a stick (or lock)
        phase appears or vanishes (the number of held phases per period, :attr:`sticks`, changes)
        and ``grazing`` where a pair of breakpoint crossings does (:attr:`crossings`)."""
        out = np.full(len(self), "", dtype=object)
        if self.labels is not None:  # located on the exact branch: the labels; structure changes between rows
            out[:] = self.labels
            for i in range(1, len(self)):
                if not out[i] and not out[i - 1] and self.sticks[i] != self.sticks[i - 1]:
                    out[i] = "grazing_sliding"
                elif not out[i] and not out[i - 1] and self.crossings[i] != self.crossings[i - 1]:
                    out[i] = "grazing"
            return out
        prev = None
        for i in np.flatnonzero(self.matched):
            if prev is not None:
                if bool(self.stable[i]) != bool(self.stable[prev]):
                    out[i] = classify_loss(self.multipliers[prev], self.multipliers[i])
                elif min(self.sticks[i], self.sticks[prev]) >= 0 and self.sticks[i] != self.sticks[prev]:
                    out[i] = "grazing_sliding"
                elif min(self.crossings[i], self.crossings[prev]) >= 0 and self.crossings[i] != self.crossings[prev]:
                    out[i] = "grazing"
            prev = i
        return out

    def columns(self) -> dict[str, np.ndarray]:
        """The rows as columns :data:`NONSMOOTH_COLUMNS`."""
        mu, mu_hb = np.abs(self.multipliers), np.abs(self.multipliers_hb)
        return {
            "branch": np.full(len(self), self.branch, dtype=np.int64),
            "period": np.full(len(self), self.period, dtype=np.int64),
            "omega": self.omega, "mean": self.mean, "rms": self.rms, "rms_ac": self.rms_ac, "p2p": self.p2p,
            "acc_p2p": self.acc_p2p, "regime": self.regime, "stable": self.stable, "bifurcation": self.bifurcation,
            "rms_hb": self.rms_hb, "rms_error": self.rms_error, "matched": self.matched,
            "stick_time": self.stick_time, "mu1_abs": mu[:, 0], "mu2_abs": mu[:, 1], "mu1_hb_abs": mu_hb[:, 0],
            "mu2_hb_abs": mu_hb[:, 1], "eps_limit": self._per_row(self.limit_eps),
            "rms_hb_limit": self._per_row(self.limit_rms),
            "rms_hb_extrapolated": self._per_row(np.where(self.limit_linear, self.limit_richardson, np.nan)),
            "rms_error_limit": np.where(np.isnan(self._per_row(self.limit_rms)), np.nan, self.hb_error),
            "sticks": self.sticks, "crossings": self.crossings,
        }

    def column_names(self) -> list[str]:
        """:data:`NONSMOOTH_COLUMNS`: the names of :meth:`columns` in file order."""
        return list(NONSMOOTH_COLUMNS)

    def all_columns(self) -> dict[str, np.ndarray]:
        """:meth:`columns` of this branch followed by those of each of :attr:`branches`."""
        parts = [self.columns()] + [b.columns() for b in self.branches]
        return {k: np.concatenate([np.asarray(p[k]) for p in parts]) for k in NONSMOOTH_COLUMNS}

    def frf_metadata(self, system: Any, settings: dict[str, Any], timings: dict[str, float]) -> dict[str, Any]:
        """The ``frf.json`` sections (:meth:`FrequencyResponse.metadata`): the method's
        ``settings``, the equation solved (``system``), status and message, the rows (all, matched
        by exact shooting, sticking), the largest and median |rms_error| over the matched rows, the
        stability changes, the sub-harmonic branches and ``timings``."""
        matched = np.asarray(self.matched, dtype=bool)
        err = np.abs(np.asarray(self.rms_error, dtype=float)[matched])
        err = err[np.isfinite(err)]
        stick = np.asarray(self.stick_time, dtype=float)
        labels = self.bifurcation
        return {
            "settings": dict(settings),
            "system": {"damping": system.c, "stiffness": system.k, "law": system.law.to_dict(),
                       "excitation": system.excitation.to_dict()},
            "status": self.status.name.lower(),
            "message": self.message or self.status.message,
            "points": len(self),
            "matched": int(np.count_nonzero(matched)),
            "sticking": int(np.count_nonzero(matched & (np.nan_to_num(stick) > 0))),
            "unstable": int(np.count_nonzero(~np.asarray(self.stable, dtype=bool))),
            "rms_error_max": float(np.max(err)) if err.size else None,
            "rms_error_median": float(np.median(err)) if err.size else None,
            "refined": int(np.size(self.limit_index)),
            "hb_error_max": largest(self.hb_error, matched),
            "bifurcations": [{"kind": str(labels[i]), "index": int(i), "omega": float(self.omega[i])}
                             for i in range(len(self)) if labels[i]],
            "branches": [branch_metadata(b) for b in self.branches],
            "timings": dict(timings),
        }

    def frf_summary(self, settings: dict[str, Any]) -> str:
        """What ``rattle frf`` prints (:meth:`FrequencyResponse.summary`): the rows, how they were
        found, the HB's error against the exact orbits, sticking, the largest exact rms, the
        special points and the sub-harmonic branches (``settings["subharmonics"]``: whether they
        were asked for; ``settings["refine"]``: the refinement tolerance)."""
        n = len(self)
        matched = np.asarray(self.matched, dtype=bool)
        unstable = int(np.count_nonzero(~np.asarray(self.stable, dtype=bool)))
        how = (f"(exact shooting continuation: every row an exact orbit); {unstable} unstable"
               if self.followed == "exact shooting"
               else f"(regularised harmonic balance, H = {self.harmonics}, ε = {self.regularisation:g}); "
                    f"{int(np.count_nonzero(matched))} matched by exact shooting, {unstable} unstable")
        lines = [
            f"{n} points over Ω = {np.min(self.omega):.4g} … {np.max(self.omega):.4g} {how}" if n else "no points",
            f"status: {self.status.name.lower()} — {self.message or self.status.message}",
        ]
        err = np.abs(np.asarray(self.rms_error, dtype=float)[matched])
        err = err[np.isfinite(err)]
        if err.size or matched.any():
            if err.size:
                lines.append(f"rms of the HB against the exact orbit: median error {np.median(err):.2g}, largest "
                             f"{np.max(err):.2g} (at Ω = "
                             f"{self.omega[matched][np.nanargmax(np.abs(self.rms_error[matched]))]:.5g})")
            refined = int(np.size(self.limit_index))
            best = largest(self.hb_error, matched)
            if refined and best is not None:
                lines.append(f"regularisation continued towards its limit at {refined} row(s) (those off by more "
                             f"than {settings.get('refine') or 0:g} and any asked for): largest error at the smallest "
                             f"ε {best:.2g}")
            stick = np.nan_to_num(np.asarray(self.stick_time, dtype=float)[matched])
            if np.any(stick > 0):
                period = 2.0 * np.pi / np.asarray(self.omega, dtype=float)[matched]
                lines.append(f"sticks at {int(np.count_nonzero(stick > 0))} of the matched points (at most "
                             f"{np.max(stick / period):.0%} of the period)")
            i = int(np.nanargmax(np.where(matched, self.rms, np.nan)))
            lines.append(f"largest exact rms {self.rms[i]:.5g} rad at Ω = {self.omega[i]:.5g} ({self.regime[i]})")
        labels = self.bifurcation
        if self.labels is not None:  # located on the exact branch
            changes = [f"{labels[i]} at Ω = {self.omega[i]:.7g}" for i in range(n) if labels[i]]
            head = "special points (located; grazing: a crossing or a stick phase appears or vanishes): "
        else:
            changes = [f"{labels[i]} before Ω = {self.omega[i]:.5g}" for i in range(n) if labels[i]]
            head = "bifurcations (between rows; grazing: a crossing or a stick phase appears or vanishes): "
        if changes:
            lines.append(head + ", ".join(changes))
        lines.extend(branch_lines(self, bool(settings.get("subharmonics"))))
        return "\n".join(lines)



__all__ = ["NONSMOOTH_COLUMNS", "NonsmoothCheck"]
