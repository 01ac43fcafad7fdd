"""Columnar results of a frequency-response computation."""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from .._validate import as_float_array, check_history_size
from ..errors import Status
from ..hb import resize_harmonics
from ._columns import FRF_COLUMNS
from ._friction import FrictionCheck
from ._nonsmooth import NonsmoothCheck
from ..measures import acceleration_batch, evaluate_batch
from ..model import Model, check_analysable_model
from ._plotter import plot_with
from ._sound import check_sound_paths, sound_pressure
from ._speed import SpeedText, rpm_of_omega

#: Per-element columns of a chain's ``frf.csv`` (SPEC §5): ``NAME_`` + each of these.
ELEMENT_COLUMNS: tuple[str, ...] = ("mean", "rms", "rms_ac", "p2p", "acc_p2p", "min", "max", "regime")


def element_columns_from(names: tuple[str, ...], measures: tuple[Any, ...]) -> dict[str, np.ndarray]:
    """``{NAME_mean: …, …, NAME_regime: …}`` from one :class:`rattle.measures.Measures` per element."""
    out: dict[str, np.ndarray] = {}
    for name, m in zip(names, measures):
        for c, attr in zip(ELEMENT_COLUMNS, ("mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max", "regime")):
            out[f"{name}_{c}"] = getattr(m, attr)
    return out


@dataclass(frozen=True, slots=True)
class SpecialPoint:
    """A point where stability changes: ``kind`` (fold, period_doubling, neimark_sacker), its
    row ``index`` in the result, ``omega``, ``branch`` and ``multipliers``. ``located`` is true
    when the point was located on the branch by solving the test function (a row of its own);
    otherwise it is the computed point nearest the change. When the location was repeated with
    twice the harmonics, ``omega`` is that value and ``omega_error`` = |Ω(2H) − Ω(H)| estimates
    the truncation error of the row's Ω. At a Neimark–Sacker point ``torus_ratio`` = θ/2π of
    the critical pair μ = e^{±iθ} (in [0, ½]): the ratio of the torus' second frequency to the
    orbit's base frequency."""

    kind: str
    index: int
    omega: float
    branch: int
    multipliers: ComplexArray
    located: bool = False
    omega_error: float | None = None
    torus_ratio: float | None = None


@dataclass(frozen=True, slots=True)
class Region:
    """An interval [omega_min, omega_max] of forcing frequency with a ``kind`` and a ``label``.

    ``kind``: ``superharmonic``, ``subharmonic``, or for an interval where no computed orbit is
    stable, by what is known: ``unstable_period_doubling`` (sub-harmonics not computed, a period
    doubling bounds it: a stable period-2p motion is likely), ``unstable_not_computed``
    (sub-harmonics not computed), ``no_stable_computed`` (sub-harmonics computed, none stable)
    and ``no_stable_periodic`` (… and a time sweep found no period ≤ 8 there either). ``detail``
    holds kind-specific data (order, period, branch, the periods a time sweep saw there…).
    """

    kind: str
    omega_min: float
    omega_max: float
    label: str
    detail: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "omega_min": self.omega_min, "omega_max": self.omega_max, "label": self.label, **self.detail}


@dataclass(frozen=True, slots=True)
class LinearResponse:
    """Closed-form response of the linear system (f = δ, same excitation) on a grid ``omega``."""

    omega: FloatArray
    mean: FloatArray
    rms: FloatArray
    rms_ac: FloatArray


def linear_frequency_response(model: Model, omega: FloatArray, element: int = 0) -> LinearResponse:
    """The linear system's response (every element's law replaced by f = δ, same excitation),
    measured on element ``element`` (the first by default).

    For x'' + C x' + K_l x = F(t), K_l = K + Σ_e b_e a_eᵀ: the mean K_l⁻¹F_0 and per forcing
    harmonic h the amplitude X_h = (K_l − (hΩ)² I + i hΩ C)⁻¹ (F_ch − i F_sh); the element's
    δ = a·x. For the single equation this is δ = F_m/k + Σ_n Re[X_n e^{inΩt}],
    X_n = F_pn e^{iφ_n} / (k − (nΩ)² + i c nΩ).

    ``omega``: frequencies (rad/s), finite and > 0, at most 10⁷ of them; the model must be
    damped (the undamped linear response is infinite at resonance)."""

    check_analysable_model(model)
    omega = as_float_array(omega, "omega", "frequencies in rad/s (numbers)")
    if omega.size > 10**7 or not np.all(np.isfinite(omega) & (omega > 0)):
        raise ValueError(f"`omega` must hold at most 10⁷ finite frequencies > 0 rad/s, got {omega.size} values "
                         f"(min {np.min(omega) if omega.size else 'none'})")
    system = model.system()
    a = system.elements[element].a
    K_l = system.stiffness + sum(np.outer(e.b, e.a) for e in system.elements)
    n = system.n
    if system.load is None:
        mean = np.full(omega.shape, float(a @ np.linalg.solve(K_l, system.mean)))
    else:  # the mean torques follow the drag by speed
        mean = (np.linalg.solve(K_l, system.mean_at(omega.ravel()).T).T @ a).reshape(omega.shape)
    ac2 = np.zeros(omega.shape)
    flat = omega.ravel()
    for h in range(1, system.forced_harmonics + 1):
        F = system.cos[h - 1] - 1j * system.sin[h - 1]
        if not np.any(F):
            continue
        w = h * flat
        Z = K_l[None, :, :] - (w**2)[:, None, None] * np.eye(n) + 1j * w[:, None, None] * system.damping[None, :, :]
        X = np.linalg.solve(Z, np.broadcast_to(F, (w.size, n))[..., None])[..., 0]
        ac2 += (0.5 * np.abs(X @ a) ** 2).reshape(omega.shape)
    return LinearResponse(omega, mean, np.sqrt(mean**2 + ac2), np.sqrt(ac2))


@dataclass(frozen=True, slots=True, eq=False)
class FrequencyResponse:
    """Solutions along one or more branches, one row per point in continuation order.

    Columns (numpy arrays of length P): SPEC §3 ``FRF_COLUMNS``. Also ``coefficients`` (P, 2H+1)
    Fourier coefficients [a_0, a_1 … a_H, b_1 … b_H] of δ over the solution period (base
    frequency Ω/period; branches computed with fewer harmonics are padded with zeros), and
    ``multipliers`` (P, 2) Floquet multipliers, largest modulus first.
    """

    model: Model
    harmonics: int
    branch: np.ndarray
    period: np.ndarray
    omega: FloatArray
    mean: FloatArray
    rms: FloatArray
    rms_ac: FloatArray
    p2p: FloatArray
    acc_p2p: FloatArray
    delta_min: FloatArray
    delta_max: FloatArray
    regime: np.ndarray
    stable: np.ndarray
    bifurcation: np.ndarray
    iterations: np.ndarray
    residual: FloatArray
    coefficients: FloatArray
    multipliers: ComplexArray
    special_points: tuple[SpecialPoint, ...] = ()
    regions: tuple[Region, ...] = ()
    status: Status = Status.SUCCESS
    message: str = ""
    settings: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    element_columns: dict[str, np.ndarray] = field(default_factory=dict)
    #: Further per-row columns written after the element columns (``spl_db``: :meth:`with_sound`).
    extra_columns: dict[str, np.ndarray] = field(default_factory=dict)
    #: The exact-check column group of a law with jumps or friction (None for a continuous law).
    check: NonsmoothCheck | FrictionCheck | None = None
    #: The sound paths of :meth:`with_sound` (empty without): frf.png draws the linear system's
    #: level through them on a dense Ω grid (closed form), not only at the rows' Ω.
    sound_paths: tuple[Any, ...] = ()

    @classmethod
    def from_check(cls, check: NonsmoothCheck | FrictionCheck, *, model: Any, settings: dict[str, Any],
                   timings: dict[str, float]) -> "FrequencyResponse":
        """The response of a law with jumps or friction from its exact-check group ``check`` (the
        primary branch, its sub-harmonic branches in ``check.branches``): one row per row of each,
        the primary's first; ``model`` the system solved (a single-equation :class:`~rattle.model.System`
        or :class:`~rattle.model.System` with its elements' whole laws), ``settings`` the method's (JSON-able: written to
        ``frf.json``; ``subharmonics`` and ``refine`` read by :meth:`summary`)."""
        parts = (check, *check.branches)

        def cat(get: Any, dtype: Any = float) -> np.ndarray:
            return np.concatenate([np.asarray(get(p), dtype=dtype) for p in parts])

        chain = isinstance(check, FrictionCheck)  # a chain: the SPEC columns describe its first element (SPEC §5)
        first = (lambda a: np.asarray(a, dtype=float).reshape(len(a), -1)[:, 0]) if chain else (lambda a: a)
        mean, rms = cat(lambda p: first(p.mean)), cat(lambda p: first(p.rms))
        omega = cat(lambda p: p.omega)
        P = omega.size
        bif = cat(lambda p: p.bifurcation, object)
        multipliers = cat(lambda p: p.multipliers, complex)
        branch = cat(lambda p: np.full(len(p), p.branch), np.int64)
        located = cat(lambda p: np.full(len(p), p.labels is not None), bool)
        special = tuple(SpecialPoint(str(bif[i]), int(i), float(omega[i]), int(branch[i]), multipliers[i],
                                     located=bool(located[i]))
                        for i in range(P) if bif[i] in ("fold", "period_doubling", "neimark_sacker"))
        nan = np.full(P, np.nan)
        return cls(
            model=model, harmonics=int(check.harmonics), branch=branch,
            period=cat(lambda p: np.full(len(p), p.period), np.int64), omega=omega, mean=mean, rms=rms,
            rms_ac=np.sqrt(np.maximum(rms**2 - mean**2, 0.0)),
            p2p=nan.copy() if chain else cat(lambda p: p.p2p), acc_p2p=nan.copy() if chain else cat(lambda p: p.acc_p2p),
            delta_min=nan.copy(), delta_max=nan.copy(),
            regime=np.full(P, "", dtype=object) if chain else cat(lambda p: p.regime, object),
            stable=cat(lambda p: p.stable, bool), bifurcation=bif, iterations=np.zeros(P, dtype=np.int64),
            residual=nan.copy(), coefficients=np.zeros((P, 0)), multipliers=multipliers, special_points=special,
            status=check.status, message=check.message, settings=dict(settings), timings=dict(timings), check=check,
        )

    # --- container protocol ----------------------------------------------------------------
    def __len__(self) -> int:
        return int(self.omega.size)

    def __getitem__(self, index: int) -> dict[str, Any]:
        """Row ``index`` as a dict of the SPEC columns."""
        return {name: getattr(self, name)[index] for name in FRF_COLUMNS}

    def __repr__(self) -> str:
        return (
            f"FrequencyResponse({len(self)} points, {len(np.unique(self.branch))} branch(es), "
            f"Ω = {self.omega.min():.4g}…{self.omega.max():.4g}, "
            f"{'exact shooting' if self.check is not None and self.check.followed == 'exact shooting' else f'H = {self.harmonics}'}, "
            f"{int(np.sum(~self.stable))} unstable, special points: "
            f"{', '.join(f'{s.kind}@{s.omega:.4g}' for s in self.special_points) or 'none'}; "
            f"status: {self.status.name})"
        )

    def columns(self) -> dict[str, np.ndarray]:
        """The SPEC columns in order, as a dict of arrays; ``harmonics`` (H of each row, SPEC §8);
        for a chain also, per element NAME, ``NAME_mean … NAME_regime`` (SPEC §5,
        :data:`ELEMENT_COLUMNS`); with an engine (SPEC §6) ``speed_rpm``; then the other extra
        columns (``spl_db``). With an exact-check group (a law with jumps or friction): its
        columns (:meth:`NonsmoothCheck.columns`, :meth:`FrictionCheck.columns`), every branch's."""
        if self.check is not None:
            return self.check.all_columns()
        rpm = self.speed_rpm
        speed = {} if rpm is None else {"speed_rpm": rpm}
        extra = dict(self.extra_columns)
        harmonics = {} if "harmonics" not in extra else {"harmonics": extra.pop("harmonics")}
        return {**{name: getattr(self, name) for name in FRF_COLUMNS}, **harmonics, **self.element_columns, **speed,
                **extra}

    @property
    def column_names(self) -> list[str]:
        """Names of :meth:`columns` in file order: the SPEC §3 columns, ``harmonics`` (H of each
        row, SPEC §8), the element columns, ``speed_rpm``, the other extra columns; with an
        exact-check group, its columns."""
        if self.check is not None:
            return self.check.column_names()
        speed = [] if getattr(self.model, "speed_order", None) is None else ["speed_rpm"]
        harmonics = ["harmonics"] if "harmonics" in self.extra_columns else []
        return [*FRF_COLUMNS, *harmonics, *self.element_columns, *speed,
                *(k for k in self.extra_columns if k != "harmonics")]

    @property
    def speed_rpm(self) -> FloatArray | None:
        """Crankshaft speed (rpm) of each row when the model has an engine (``[engine]``,
        ``Chain.speed_order`` q_0): Ω · 60 / (2π q_0); None otherwise."""
        order = getattr(self.model, "speed_order", None)
        return None if order is None else rpm_of_omega(np.asarray(self.omega, dtype=float), order)

    @property
    def element_names(self) -> tuple[str, ...]:
        """Names of the clearance elements whose columns this result carries (a chain's)."""
        suffix = "_" + ELEMENT_COLUMNS[0]
        return tuple(k[: -len(suffix)] for k in self.element_columns if k.endswith(suffix))

    def element(self, name: str) -> dict[str, np.ndarray]:
        """The SPEC §5 measures of element ``name`` as a dict (``mean``, ``rms``, … ``regime``)."""
        if name not in self.element_names:
            raise KeyError(f"`name` must be one of the elements {list(self.element_names)}, got {name!r}")
        return {c: self.element_columns[f"{name}_{c}"] for c in ELEMENT_COLUMNS}

    def summary(self) -> str:
        """A few lines for the terminal (with an exact-check group, its
        :meth:`~NonsmoothCheck.frf_summary`)."""
        if self.check is not None:
            return self.check.frf_summary(self.settings)
        speed = SpeedText.of(self.model)  # rpm with an engine, else Ω
        over = (f"{speed.span(self.omega.min(), self.omega.max(), 4)} (Ω = {self.omega.min():.4g} … "
                f"{self.omega.max():.4g} rad/s; " if speed.engine
                else f"Ω = {self.omega.min():.4g} … {self.omega.max():.4g} (")
        lines = [
            f"{len(self)} solution points over {over}H = {self.harmonics_text()} harmonics per forcing period), "
            f"{int(np.sum(~self.stable))} unstable",
            f"status: {self.status.name.lower()} — {self.message or self.status.message}",
        ]
        gaps = self.uncovered
        if gaps:
            lines.append("not covered (no branch found there): " + ", ".join(
                speed.span(a, b) + (f" (Ω = {a:.5g} … {b:.5g})" if speed.engine else "") for a, b in gaps))
        if len(np.unique(self.branch)) > 1:
            lines.append("branches: " + ", ".join(
                f"{b} (period {int(self.period[self.branch == b][0])}, "
                f"{speed.span(self.omega[self.branch == b].min(), self.omega[self.branch == b].max(), 4, '…')})"
                for b in np.unique(self.branch)))
        if speed.engine:
            lines.append(f"engine speed: Ω = {speed.order:g} × crankshaft speed")
        if self.special_points:
            lines.append("stability changes: " + ", ".join(f"{s.kind} at {speed.at(s.omega)}"
                                                         for s in self.special_points))
        if self.regions:
            digits = 5 if speed.engine else 4  # rpm as the stability changes give them
            lines.append("regions: " + "; ".join(
                f"{g.label} at {speed.at(g.omega_min, digits)}" if g.omega_min == g.omega_max
                else f"{g.label} {speed.span(g.omega_min, g.omega_max, digits, '…')}"
                for g in self.regions))
        i = int(np.argmax(self.rms))
        lines.append(f"largest rms {self.rms[i]:.5g} rad at {speed.at(self.omega[i])} ({self.regime[i]})")
        if self.timings:
            lines.append("time: " + ", ".join(f"{k} {v:.3g} s" for k, v in self.timings.items()))
        return "\n".join(lines)

    @property
    def uncovered(self) -> list[tuple[float, float]]:
        """The parts (Ω_lo, Ω_hi) of the analysed range that no branch covers (SPEC §8; empty
        when the branches cover all of it)."""
        return [(float(a), float(b)) for a, b in self.settings.get("uncovered", []) or []]

    def harmonics_text(self) -> str:
        """The harmonic count(s) of the rows: ``32``, or ``32–128`` where H adapted along the branch."""
        col = self.extra_columns.get("harmonics")
        if col is None or not len(col):
            return str(self.settings.get("harmonics", self.harmonics))
        lo, hi = int(np.min(col)), int(np.max(col))
        return str(lo) if lo == hi else f"{lo}–{hi}"

    def metadata(self) -> dict[str, Any]:
        """Settings, timings, status, the uncovered parts of the range (``uncovered``, Ω and, with
        an engine, ``uncovered_rpm``) and special points, JSON-serialisable; with an exact-check
        group, its :meth:`~NonsmoothCheck.frf_metadata`."""
        if self.check is not None:
            return self.check.frf_metadata(self.model, self.settings, self.timings)
        order = getattr(self.model, "speed_order", None)
        gaps = self.uncovered
        rpm = {} if order is None else {"uncovered_rpm": [[a * 60.0 / (2.0 * np.pi * order),
                                                         b * 60.0 / (2.0 * np.pi * order)] for a, b in gaps]}
        return {
            "settings": self.settings,
            "timings": self.timings,
            "status": self.status.name.lower(),
            "message": self.message or self.status.message,
            "uncovered": [[a, b] for a, b in gaps], **rpm,
            "points": len(self),
            "regions": [g.to_dict() for g in self.regions],
            "special_points": [
                {"kind": s.kind, "omega": s.omega, "branch": s.branch, "index": s.index, "located": s.located, "omega_error": s.omega_error,
                 **({"torus_ratio": s.torus_ratio} if s.torus_ratio is not None else {}),
                 "multipliers": [[float(m.real), float(m.imag)] for m in s.multipliers]}
                for s in self.special_points
            ],
        }

    @classmethod
    def concatenate(cls, parts: "list[FrequencyResponse]", *, status: Status | None = None, message: str = "",
                    settings: dict[str, Any] | None = None, timings: dict[str, float] | None = None) -> "FrequencyResponse":
        """Join results of one model (e.g. the primary and the sub-harmonic branches) row-wise;
        coefficients are padded to the largest harmonic count, special points re-indexed."""
        if not parts:
            raise ValueError("`parts` must hold at least one FrequencyResponse")
        if any(p.check is not None for p in parts):
            raise ValueError("`parts` must be responses of a continuous law: a law with jumps or friction holds "
                             "all its branches in one response already")
        model = parts[0].model
        H = max(p.harmonics for p in parts)

        offsets = np.cumsum([0] + [len(p) for p in parts[:-1]])
        special = tuple(
            SpecialPoint(sp.kind, sp.index + int(off), sp.omega, sp.branch, sp.multipliers, sp.located, sp.omega_error, sp.torus_ratio)
            for p, off in zip(parts, offsets) for sp in p.special_points
        )
        cat = {name: np.concatenate([getattr(p, name) for p in parts]) for name in (
            "branch", "period", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max",
            "regime", "stable", "bifurcation", "iterations", "residual", "multipliers")}
        cat["element_columns"] = {k: np.concatenate([p.element_columns[k] for p in parts]) for k in parts[0].element_columns}
        cat["extra_columns"] = {k: np.concatenate([p.extra_columns[k] for p in parts]) for k in parts[0].extra_columns
                                if all(k in p.extra_columns for p in parts)}
        n_coord = parts[0].coefficients.shape[1] // (2 * parts[0].harmonics + 1) if len(parts[0]) else 1

        def padded(p: "FrequencyResponse") -> FloatArray:
            L = 2 * p.harmonics + 1
            blocks = p.coefficients.reshape(len(p), n_coord, L)
            return resize_harmonics(blocks, H).reshape(len(p), n_coord * (2 * H + 1))

        return cls(
            model=model, harmonics=H, coefficients=np.concatenate([padded(p) for p in parts]), special_points=special,
            status=status or parts[0].status, message=message or parts[0].message,
            settings=dict(settings or parts[0].settings), timings=dict(timings or parts[0].timings),
            sound_paths=parts[0].sound_paths if all(p.sound_paths == parts[0].sound_paths for p in parts) else (),
            **cat,
        )

    def select(self, branch: int) -> "FrequencyResponse":
        """The rows of one branch as a result of its own (special points re-indexed)."""
        rows = np.nonzero(self.branch == branch)[0]
        if rows.size == 0:
            raise ValueError(f"`branch` {branch} is not in this result (branches: {sorted(set(self.branch.tolist()))})")
        first = int(rows[0])
        fields = {name: getattr(self, name)[rows] for name in (
            "branch", "period", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max",
            "regime", "stable", "bifurcation", "iterations", "residual", "multipliers", "coefficients")}
        special = tuple(
            SpecialPoint(sp.kind, sp.index - first, sp.omega, sp.branch, sp.multipliers, sp.located, sp.omega_error, sp.torus_ratio)
            for sp in self.special_points if sp.branch == branch
        )
        fields["element_columns"] = {k: v[rows] for k, v in self.element_columns.items()}
        fields["extra_columns"] = {k: v[rows] for k, v in self.extra_columns.items()}
        if self.check is not None:  # that branch's own check group
            fields["check"] = replace(next(c for c in (self.check, *self.check.branches) if c.branch == branch),
                                      branches=())
        return type(self)(model=self.model, harmonics=self.harmonics, special_points=special, status=self.status,
                          message=self.message, settings=self.settings, timings=self.timings,
                          sound_paths=self.sound_paths, **fields)

    # --- derived quantities ----------------------------------------------------------------
    def base_frequency(self, index: int) -> float:
        """ω = Ω / period of point ``index``."""
        return float(self.omega[index] / self.period[index])

    def time_history(self, index: int, samples: int = 512, periods: int = 1) -> dict[str, FloatArray]:
        """Time history of point ``index`` over ``periods`` solution periods:
        dict with ``t``, ``delta``, ``velocity``, ``acceleration`` (arrays of length samples·periods + 1)."""
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
            raise TypeError(f"`index` must be an integer, got {index!r}")
        if self.check is not None:
            raise ValueError("a law with jumps or friction has no Fourier coefficients (its orbits are exact "
                             "trajectories): use rattle.analysis.nonsmooth_orbit(system, omega) for one orbit's "
                             "time history")
        if not -len(self) <= index < len(self):
            raise IndexError(f"`index` must be in [0, {len(self)}), got {index}")
        samples, periods = check_history_size(samples, periods, self.coefficients.shape[-1] // 2)
        w = np.array([self.base_frequency(index)])
        Q = self.coefficients[index][None, :]
        T = 2 * np.pi / w[0]
        t = np.linspace(0.0, periods * T, samples * periods + 1)[None, :]
        return {
            "t": t[0],
            "delta": evaluate_batch(Q, w, t)[0],
            "velocity": evaluate_batch(Q, w, t, derivative=1)[0],
            "acceleration": acceleration_batch(self.model, Q, w, self.omega[index : index + 1] if index >= 0 else self.omega[[index]], t)[0],
        }

    def linear_response(self, omega: FloatArray | None = None, points: int = 600, *, element: int = 0) -> LinearResponse:
        """The linear system's (f = δ) closed-form response on element ``element``, by default
        on a uniform grid (a :class:`~rattle.model.Model` or :class:`~rattle.model.Chain`'s)."""
        if self.check is not None:
            raise ValueError("the linear response is that of a Model or Chain; a law with jumps or friction has "
                             "none here: use rattle.linear_frequency_response(model, omega) on its continuous model")
        if omega is None:
            omega = np.linspace(self.omega.min(), self.omega.max(), points)
        return linear_frequency_response(self.model, omega, element)

    def with_sound(self, paths: Any) -> "FrequencyResponse":
        """A copy with the columns of the sound ``paths`` (:class:`rattle.model.SoundPath`
        objects; :func:`rattle.results.sound_pressure`): ``spl_db`` (sound pressure level at the
        receiver, dB re 20 µPa), ``spl_dba`` (A-weighted, dB(A)) and ``spl_linear_db`` (the linear
        system's level at the same Ω)."""
        if self.check is not None:
            raise ValueError("`paths`: the sound pressure needs the Fourier coefficients of a harmonic-balance "
                             "response; a law with jumps or friction has none")
        sp = sound_pressure(self, paths)
        with warnings.catch_warnings():  # the same harmonics: warned about once, above
            warnings.simplefilter("ignore")
            dba = sound_pressure(self, paths, a_weighting=True, linear=False).spl_db
        return replace(self, extra_columns={**self.extra_columns, "spl_db": sp.spl_db, "spl_dba": dba,
                                            "spl_linear_db": sp.linear_spl_db},
                       sound_paths=tuple(check_sound_paths(paths, self.model)))

    # --- output delegates ------------------------------------------------------------------
    def to_csv(self, path: str | Path) -> Path:
        """Write the SPEC columns to ``path`` atomically (see ``rattle.io``)."""
        from ..files import write_csv

        write_csv(path, self.columns(), self.column_names)
        return Path(path)

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """rms vs Ω (stable solid, unstable dashed, bifurcations marked, linear overlaid);
        returns (figure, :class:`rattle.plotting.PlotAxes`). See
        :func:`rattle.plotting.frequency_response_plot`. With an exact-check group: the exact and
        HB rms with the stability changes and the stick fraction
        (:func:`rattle.plotting.nonsmooth_response_plot`, per element for a chain
        :func:`rattle.plotting.friction_response_plot`)."""
        return plot_with("frequency_response_plot", self, ax=ax, **kwargs)




__all__ = ["ELEMENT_COLUMNS", "element_columns_from", "FrequencyResponse", "SpecialPoint", "Region", "LinearResponse", "linear_frequency_response", "FRF_COLUMNS"]
