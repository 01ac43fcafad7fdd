"""Drivetrains: a chain of N inertias with linear links and clearance elements (SPEC §5).

    M θ'' + C_θ θ' + K_θ θ + Σ_e w_eᵀ K_e f_e(w_e · θ) = T(t),

θ = (θ_1 … θ_N) the absolute angles, M = diag(I_1 … I_N), C_θ and K_θ assembled from the links
(a link between i and j adds its stiffness k and damping c on δ = θ_i − θ_j; j = 0 is ground),
and every clearance element e (between i and j) acts on δ_e = w_e · θ = θ_i − θ_j with its
stiffness K_e and law f_e. T_i(t) = T_mi + Σ_n T_pni cos(nΩt + φ_ni).

A chain with no link or element to ground is free (semi-definite): it is reduced exactly to the
N − 1 relative coordinates x_k = θ_k − θ_{k+1} (:mod:`rattle.model._system`), and its mean
torques must balance (Σ T_mi = 0), or the whole chain accelerates and has no periodic motion.
A two-inertia free chain with one element is exactly the single equation of SPEC §1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._limits import MAX_MAGNITUDE
from .._typing import FloatArray
from ._discontinuous import AbstractJumpLaw, Friction, NonsmoothLaw
from ._drag import Drag, drag_load
from ._elastic import AbstractElastic, Piecewise, _check_real, _check_real_sequence
from ._readers import read_tables
from ._system import ReducedElement, System

#: Relative tolerance of the mean-torque balance of a free chain.
BALANCE_RTOL = 1e-9


def _pair(name: str, value: object) -> tuple[int, int]:
    """A pair (i, j) of integer inertia numbers (range checked by the chain)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:  # type: ignore[arg-type]
        raise TypeError(f"`{name}` must be a pair [i, j] of inertia numbers (j = 0: ground), got {value!r}")
    out = []
    for k, v in enumerate(value):  # type: ignore[union-attr]
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise TypeError(f"`{name}[{k}]` must be an integer inertia number, got {v!r}")
        out.append(int(v))
    return out[0], out[1]


def _items(name: str, value: object, kind: type) -> tuple:
    """``value`` as a tuple of ``kind`` (a list or tuple of them)."""
    if isinstance(value, kind) or isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise TypeError(f"`{name}` must be a list or tuple of {kind.__name__} objects, got {value!r}")
    return tuple(value)  # type: ignore[call-overload]


def _check_between(name: str, value: object, n_inertias: int) -> tuple[int, int]:
    i, j = _pair(name, value)
    if not 1 <= i <= n_inertias:
        raise ValueError(f"`{name}[0]` must be an inertia number 1 … {n_inertias}, got {i}")
    if not 0 <= j <= n_inertias:
        raise ValueError(f"`{name}[1]` must be an inertia number 1 … {n_inertias} or 0 (ground), got {j}")
    if i == j:
        raise ValueError(f"`{name}` must join two different inertias, got [{i}, {j}]")
    return i, j


@dataclass(frozen=True, slots=True, kw_only=True)
class Link:
    """A linear spring and damper between inertias ``between`` = (i, j) (j = 0: ground)."""

    between: tuple[int, int]
    stiffness: float = 0.0
    damping: float = 0.0

    def __post_init__(self) -> None:
        k = _check_real("stiffness", self.stiffness)
        c = _check_real("damping", self.damping)
        if k < 0:
            raise ValueError(f"`stiffness` of a link must be >= 0, got {k!r}")
        if c < 0:
            raise ValueError(f"`damping` of a link must be >= 0, got {c!r}")
        object.__setattr__(self, "stiffness", k)
        object.__setattr__(self, "damping", c)
        object.__setattr__(self, "between", _pair("between", self.between))

    def to_dict(self) -> dict[str, object]:
        return {"between": list(self.between), "stiffness": self.stiffness, "damping": self.damping}


@dataclass(frozen=True, slots=True, kw_only=True)
class Element:
    """A clearance element ``name`` on δ = θ_i − θ_j (``between`` = (i, j)) with the stiffness
    ``stiffness`` K_e of its unit-slope stage and the piecewise-linear ``law`` f_e (continuous, or
    with upward torque jumps: :class:`~rattle.model.Preload`, :class:`~rattle.model.PiecewiseJump`,
    e.g. a torque-converter clutch); optionally Coulomb ``friction`` r_e (relative to K_e: a
    hysteresis torque K_e r_e opposing δ', one level for every stage or one per stage of the law,
    :class:`~rattle.model.Friction`).

    A chain with friction or a torque jump on any element is solved on
    :meth:`Chain.friction_system` (:func:`rattle.frequency_response`, the exact flow of
    :class:`rattle.timeint.ExactIntegrator`); the smooth analyses refuse it."""

    name: str
    between: tuple[int, int]
    stiffness: float
    law: AbstractElastic | AbstractJumpLaw
    friction: Friction | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(
                f"`name` of an element must be an identifier (letters, digits, underscore; it names "
                f"the output columns NAME_rms …), got {self.name!r}"
            )
        k = _check_real("stiffness", self.stiffness)
        if k <= 0:
            raise ValueError(f"`stiffness` of an element must be > 0, got {k!r}")
        if not isinstance(self.law, (AbstractElastic, AbstractJumpLaw)):
            raise TypeError(f"`law` must be an elastic law (Linear, Backlash, Clutch, Piecewise) or a law with "
                            f"torque jumps (Preload, PiecewiseJump), got {self.law!r}")
        object.__setattr__(self, "stiffness", k)
        object.__setattr__(self, "between", _pair("between", self.between))
        if self.friction is not None:
            if not isinstance(self.friction, Friction):
                raise TypeError(f"`friction` must be a rattle.model.Friction (or None), got {self.friction!r}")
            self.friction.per_stage(len(self.law.stages.slopes))  # one level or one per stage

    @property
    def has_friction(self) -> bool:
        """A friction level > 0 on some stage."""
        return self.friction is not None and any(self.friction.levels)

    @property
    def has_jumps(self) -> bool:
        """The law jumps (a torque jump J > 0 at some breakpoint: a preload)."""
        return isinstance(self.law, AbstractJumpLaw) and bool(np.any(self.law.stages.jumps > 0))

    def continuous_law(self) -> AbstractElastic:
        """The law without its jumps: the same breakpoints and slopes, continuous, f(0) = 0 (the law
        itself when it is continuous). The smooth equations of a chain carry it for an element with
        jumps; the jumps are in the whole law of :meth:`Chain.friction_system`."""
        if isinstance(self.law, AbstractElastic):
            return self.law
        st = self.law.stages
        return Piecewise(breakpoints=tuple(st.breakpoints.tolist()), slopes=tuple(st.slopes.tolist()))

    def friction_levels(self) -> FloatArray:
        """r_e on every stage of the law (zeros without friction)."""
        n = len(self.law.stages.slopes)
        return np.zeros(n) if self.friction is None else self.friction.per_stage(n)

    def to_dict(self) -> dict[str, object]:
        out = {"name": self.name, "between": list(self.between), "stiffness": self.stiffness, **self.law.to_dict()}
        if self.friction is not None:
            out["friction"] = list(self.friction.levels)
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class Torque:
    """T_i(t) = ``mean`` + Σ_n ``amplitudes``[n−1] cos(nΩt + ``phases``[n−1]) on ``inertia`` i."""

    inertia: int
    mean: float = 0.0
    amplitudes: tuple[float, ...] = ()
    phases: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if isinstance(self.inertia, bool) or not isinstance(self.inertia, (int, np.integer)):
            raise TypeError(f"`inertia` of a torque must be an integer inertia number, got {self.inertia!r}")
        mean = _check_real("mean", self.mean)
        amps = _check_real_sequence("amplitudes", self.amplitudes)
        if self.phases is None:
            phases = (0.0,) * len(amps)
        else:
            phases = _check_real_sequence("phases", self.phases)
            if len(phases) != len(amps):
                raise ValueError(f"`phases` must have one entry per amplitude ({len(amps)}), got {len(phases)}")
        object.__setattr__(self, "inertia", int(self.inertia))
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "amplitudes", amps)
        object.__setattr__(self, "phases", phases)

    def to_dict(self) -> dict[str, object]:
        return {"inertia": self.inertia, "mean": self.mean, "amplitudes": list(self.amplitudes),
                "phases": list(self.phases or ())}


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Chain:
    """Frozen, validated drivetrain: ``inertias`` I_1 … I_N > 0, ``links``, clearance
    ``elements`` (at least one) and ``torques`` (module docstring).

    Refused: an inertia joined to nothing, an inertia that cannot reach the rest (two separate
    chains), repeated element names, a free chain whose mean torques do not balance, all damping
    zero in the analyses (:func:`rattle.model.check_analysable_model`).
    """

    inertias: tuple[float, ...]
    links: tuple[Link, ...] = ()
    elements: tuple[Element, ...]
    torques: tuple[Torque, ...] = ()
    #: The engine order of the forcing frequency Ω (set by ``[engine]``, SPEC §6): the crankshaft
    #: speed is rpm = Ω · 60 / (2π · speed_order). None: no engine, results carry no rpm.
    speed_order: float | None = None
    #: A drag torque tabulated by crankshaft speed (``[drag]``, SPEC §6): the mean torques then
    #: depend on Ω (:mod:`rattle.model._drag`); needs ``speed_order``.
    drag: Drag | None = None
    _system: System | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        inertias = _check_real_sequence("inertias", self.inertias)
        if len(inertias) < 1:
            raise ValueError("`inertias` must hold at least one inertia, got []")
        for i, v in enumerate(inertias):
            if v <= 0:
                raise ValueError(f"`inertias[{i}]` must be > 0, got {v!r}")
        N = len(inertias)
        links = _items("links", self.links, Link)
        elements = _items("elements", self.elements, Element)
        torques = _items("torques", self.torques, Torque)
        for k, link in enumerate(links):
            if not isinstance(link, Link):
                raise TypeError(f"`links[{k}]` must be a Link, got {link!r}")
            _check_between(f"links[{k}].between", link.between, N)
        if not elements:
            raise ValueError("`elements` must hold at least one clearance element, got none: a chain of "
                             "linear links alone has no rattle (use a Linear law for a reference run)")
        names = set()
        for k, el in enumerate(elements):
            if not isinstance(el, Element):
                raise TypeError(f"`elements[{k}]` must be an Element, got {el!r}")
            _check_between(f"elements[{k}].between", el.between, N)
            if el.name in names:
                raise ValueError(f"`elements[{k}].name` must be unique, got {el.name!r} twice")
            names.add(el.name)
        for k, tq in enumerate(torques):
            if not isinstance(tq, Torque):
                raise TypeError(f"`torques[{k}]` must be a Torque, got {tq!r}")
            if not 1 <= tq.inertia <= N:
                raise ValueError(f"`torques[{k}].inertia` must be an inertia number 1 … {N}, got {tq.inertia}")
        object.__setattr__(self, "inertias", inertias)
        object.__setattr__(self, "links", links)
        object.__setattr__(self, "elements", elements)
        object.__setattr__(self, "torques", torques)
        if self.speed_order is not None:
            q = _check_real("speed_order", self.speed_order)
            if not q > 0:
                raise ValueError(f"`speed_order` must be > 0 (an engine order), got {q!r}")
            object.__setattr__(self, "speed_order", q)
        if self.drag is not None:
            self._check_drag(N)
        self._check_connected()
        if self.free:
            total = sum(t.mean for t in torques)
            scale = sum(abs(t.mean) for t in torques)
            if abs(total) > BALANCE_RTOL * max(scale, 1e-300) and total != 0.0:
                raise ValueError(
                    f"`torques` of a free chain must have mean torques summing to zero, got Σ mean = {total:.6g} "
                    f"({', '.join(f'inertia {t.inertia}: {t.mean:g}' for t in torques if t.mean)}): "
                    "unbalanced, the whole chain accelerates and no periodic motion exists; add the "
                    "drag torque that balances the engine's mean torque (or a link to ground)"
                )
        object.__setattr__(self, "_system", self._reduce())
        self._check_scales()
        try:
            self._system.static_equilibrium()
            if self._system.load is not None:  # and under every drag of the table
                for w in self._system.load.nodes:
                    self._system.static_equilibrium(float(w))
        except ValueError:
            raise ValueError(
                "`torques`: the mean torques cannot be balanced by the chain's stiffness: no position "
                "of the inertias holds them (an inertia is tied to ground only by dampers or by a "
                "clearance element without stiffness there), so the chain would turn without end and "
                "has no periodic motion; add a stiff link to ground, or balance the mean torques"
            ) from None

    def _check_drag(self, N: int) -> None:
        drag = self.drag
        if not isinstance(drag, Drag):
            raise TypeError(f"`drag` must be a rattle.model.Drag, got {drag!r}")
        if self.speed_order is None:
            raise ValueError("`drag` is tabulated over the crankshaft speed, but the chain has no `speed_order` (the "
                             "engine order of Ω): give an [engine] (or `speed_order`) so that rpm maps to Ω")
        if not 0 <= drag.inertia <= N:
            raise ValueError(f"`drag.inertia` must be an inertia number 1 … {N} (or 0: ground), got {drag.inertia}")
        if drag.balance is not None and not 1 <= drag.balance <= N:
            raise ValueError(f"`drag.balance` must be an inertia number 1 … {N}, got {drag.balance}")
        if self.free and drag.balance is None:
            raise ValueError(
                "`drag.balance` is missing: on a free chain (no link to ground) the drag must be delivered by the "
                "engine at every speed, or the whole chain slows down and has no periodic motion; give the "
                "engine's inertia as `balance` (with [engine] this is automatic)"
            )

    # --- structure --------------------------------------------------------------------------
    @property
    def n_inertias(self) -> int:
        return len(self.inertias)

    @property
    def free(self) -> bool:
        """No link or element to ground: the chain is semi-definite."""
        return not any(0 in x.between for x in (*self.links, *self.elements))

    @property
    def element_names(self) -> tuple[str, ...]:
        return tuple(e.name for e in self.elements)

    @property
    def forced_harmonics(self) -> int:
        return max((len(t.amplitudes) for t in self.torques), default=0)

    def _check_connected(self) -> None:
        N = self.n_inertias
        parent = list(range(N + 1))  # 0 = ground

        def find(a: int) -> int:
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a

        for x in (*self.links, *self.elements):
            i, j = x.between
            parent[find(i)] = find(j)
        roots = {find(i) for i in range(1, N + 1)}
        grounded = not self.free
        if grounded:
            loose = [i for i in range(1, N + 1) if find(i) != find(0)]
            if loose:
                raise ValueError(
                    f"`links`: inertia(s) {loose} are joined neither to ground nor to an inertia that is: every "
                    "inertia of a grounded chain must reach ground through links or elements (a loose "
                    "sub-chain has its own rigid-body motion); add the missing link"
                )
        elif len(roots) > 1:
            raise ValueError(
                "`links`: the inertias form separate chains: every inertia must be joined to the others by a "
                "link or an element; add the missing link or model the chains separately"
            )

    # --- the equations of motion ------------------------------------------------------------
    def _w(self, between: tuple[int, int]) -> np.ndarray:
        w = np.zeros(self.n_inertias)
        i, j = between
        w[i - 1] = 1.0
        if j:
            w[j - 1] = -1.0
        return w

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, C_θ, K_θ (N, N) in absolute angles."""
        N = self.n_inertias
        C = np.zeros((N, N))
        K = np.zeros((N, N))
        for link in self.links:
            w = self._w(link.between)
            C += link.damping * np.outer(w, w)
            K += link.stiffness * np.outer(w, w)
        return np.diag(self.inertias), C, K

    def torque_vectors(self) -> tuple[np.ndarray, np.ndarray]:
        """T_m (N,) and the complex harmonic amplitudes T_h (H_f, N), T_h = Σ amp e^{iφ}."""
        N = self.n_inertias
        Hf = self.forced_harmonics
        Tm = np.zeros(N)
        Th = np.zeros((Hf, N), dtype=complex)
        for t in self.torques:
            Tm[t.inertia - 1] += t.mean
            for h, (a, p) in enumerate(zip(t.amplitudes, t.phases or ())):
                Th[h, t.inertia - 1] += a * complex(math.cos(p), math.sin(p))
        return Tm, Th

    def _reduce(self) -> System:
        N = self.n_inertias
        M, Ct, Kt = self.matrices()
        Minv = np.diag(1.0 / np.asarray(self.inertias))
        Tm, Th = self.torque_vectors()
        if self.free:
            D = np.zeros((N - 1, N))
            D[np.arange(N - 1), np.arange(N - 1)] = 1.0
            D[np.arange(N - 1), np.arange(1, N)] = -1.0
            Z = np.triu(np.ones((N, N - 1)))  # θ_i − θ_N = Σ_{k ≥ i} x_k
            Z[N - 1] = 0.0
            names = tuple(f"theta{k + 1}-theta{k + 2}" for k in range(N - 1))
        else:
            D = np.eye(N)
            Z = np.eye(N)
            names = tuple(f"theta{k + 1}" for k in range(N))
        P = D @ Minv
        elements = tuple(
            ReducedElement(e.name, self._w(e.between) @ Z, P @ self._w(e.between) * e.stiffness, e.continuous_law())
            for e in self.elements
        )
        Fh = Th @ P.T
        load = None
        if self.drag is not None:  # T_m(Ω) = T_m − D(Ω) e_j + D(Ω) e_b
            e = np.zeros(N)
            if self.drag.inertia:  # 0: the ground takes the drag
                e[self.drag.inertia - 1] -= 1.0
            if self.drag.balance is not None:
                e[self.drag.balance - 1] += 1.0
            load = drag_load(self.drag, float(self.speed_order), P @ e)  # type: ignore[arg-type]
        return System(
            damping=P @ Ct @ Z,
            stiffness=P @ Kt @ Z,
            elements=elements,
            mean=P @ Tm,
            cos=Fh.real,
            sin=-Fh.imag,
            coordinates=names,
            angles=Z,
            free=self.free,
            load=load,
        )

    def system(self) -> System:
        """The equations of motion in the coordinates the numerics use (:class:`System`).

        Refused (ValueError) for a chain with friction or with a torque jump (a preload) on an
        element: the smooth analyses would drop them; such a chain is solved on
        :meth:`friction_system`."""
        assert self._system is not None
        if self.has_friction:
            names = ", ".join(e.name for e in self.elements if e.has_friction)
            raise ValueError(
                f"the chain has Coulomb friction on element(s) {names}: the smooth analyses (frf, sweep, "
                "compare, map, orbit) do not hold a torque that jumps at zero relative speed; solve it with "
                "rattle.frequency_response(chain, ...)"
            )
        if self.has_jumps:
            names = ", ".join(e.name for e in self.elements if e.has_jumps)
            raise ValueError(
                f"the chain has a torque jump (preload) in the law of element(s) {names}: the smooth analyses "
                "(frf, sweep, compare, map, orbit) need a continuous law; solve it with "
                "rattle.frequency_response(chain, ...)"
            )
        return self._system

    @property
    def has_friction(self) -> bool:
        """Some element carries Coulomb friction (a level > 0)."""
        return any(e.has_friction for e in self.elements)

    @property
    def has_jumps(self) -> bool:
        """Some element's law has a torque jump (a preload: :class:`~rattle.model.Preload`,
        :class:`~rattle.model.PiecewiseJump` with a jump > 0)."""
        return any(e.has_jumps for e in self.elements)

    @property
    def discontinuous(self) -> bool:
        """Friction or a torque jump on some element: the smooth analyses cannot be used, the chain
        is solved on :meth:`friction_system`."""
        return self.has_friction or self.has_jumps

    def friction_system(self) -> System:
        """The equations of motion with every element's friction and torque jumps: the
        :class:`System` of :meth:`system` carrying every element's whole law (``laws``,
        :class:`NonsmoothLaw`: jumps and friction) and the chain's ``speed_order``; its
        :meth:`System.continuous` part is the continuous part of every law (the law without its
        jumps). Kept apart from :meth:`system`, which refuses such a chain for the smooth analyses."""
        assert self._system is not None
        laws = tuple(NonsmoothLaw(elastic=e.law, friction=e.friction) for e in self.elements)
        return self._system.with_laws(laws, speed_order=self.speed_order)

    def _check_scales(self) -> None:
        sysm = self._system
        assert sysm is not None
        for what, value in (("damping", np.abs(sysm.damping).max()), ("stiffness", np.abs(sysm.stiffness).max()),
                            ("element stiffness", max(np.abs(e.b).max() for e in sysm.elements))):
            if value and not (1.0 / MAX_MAGNITUDE <= value <= MAX_MAGNITUDE):
                raise ValueError(
                    f"the chain's {what} per inertia reaches {value:.3g}, outside {1 / MAX_MAGNITUDE:g} … "
                    f"{MAX_MAGNITUDE:g}: products of the problem's scales would overflow double precision; "
                    "choose units in which the values are moderate"
                )

    # --- what the analyses ask of any model ---------------------------------------------------
    @property
    def has_damping(self) -> bool:
        return any(link.damping > 0 for link in self.links)

    def length_scale(self) -> float:
        assert self._system is not None
        return self._system.length_scale()

    def force_scale(self) -> float:
        assert self._system is not None
        return self._system.force_scale()

    @property
    def natural_frequency(self) -> float:
        """The highest natural frequency (rad/s), every element on its stiffest stage."""
        assert self._system is not None
        return self._system.stiffest_frequency()

    # --- I/O delegates -----------------------------------------------------------------------
    @classmethod
    def from_toml(cls, path: str | Path) -> Any:
        """Read a SPEC §5 TOML file (``[model] inertias``, ``[[model.links]]``, ``[[model.elements]]``,
        ``[[excitation.torques]]``), as :func:`rattle.io.load_config` reads them."""
        tables = read_tables(path)
        return tables.chain if tables.chain is not None else tables.model

    def to_dict(self) -> dict[str, object]:
        return {
            "inertias": list(self.inertias),
            "links": [x.to_dict() for x in self.links],
            "elements": [x.to_dict() for x in self.elements],
            "torques": [x.to_dict() for x in self.torques],
            **({"speed_order": self.speed_order} if self.speed_order is not None else {}),
            **({"drag": self.drag.to_dict()} if self.drag is not None else {}),
        }

    def speed_rpm(self, omega: Any) -> Any:
        """Crankshaft speed (rpm) at forcing frequency ``omega`` (rad/s), or None without an engine."""
        if self.speed_order is None:
            return None
        return np.asarray(omega, dtype=float) * (60.0 / (2.0 * math.pi * self.speed_order))


__all__ = ["BALANCE_RTOL", "Chain", "Element", "Link", "Torque"]
