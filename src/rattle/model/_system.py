"""The equations of motion every analysis works on: n coordinates, m clearance elements.

    x'' + C x' + K x + Σ_e b_e f_e(a_e · x) = F(t),
    F(t) = F_0 + Σ_{h=1}^{H_f} (F_ch cos hΩt + F_sh sin hΩt),

with x ∈ ℝⁿ the coordinates, C and K (n × n) the linear damping and stiffness per unit inertia,
and for every clearance element e its deflection δ_e = a_e · x, its continuous piecewise-linear
law f_e (``rattle.model._elastic``, f_e(0) = 0, slopes relative to the element's stiffness) and
its force direction b_e (which carries the element stiffness and the inverse inertias).

A :class:`System` is what the numerics see — harmonic balance, Floquet stability and the exact
time integration all work on it and on nothing else. The models build it:

* the single equation of SPEC §1, δ'' + (C/I) δ' + (K/I) f(δ) = F(t), is n = m = 1 with
  C = [[C/I]], K = [[0]], a = [1], b = [K/I];
* a chain of N inertias M θ'' + C_θ θ' + K_θ θ + Σ_e w_eᵀ K_e f_e(w_e · θ) = T(t) (SPEC §5) is
  n = N when grounded (x = θ: C = M⁻¹C_θ, K = M⁻¹K_θ, a_e = w_e, b_e = M⁻¹w_eᵀK_e) and n = N − 1
  when free (relative coordinates x = D θ, x_k = θ_k − θ_{k+1}; θ = Z x + θ_N 1 with Z upper
  triangular ones; C = D M⁻¹C_θ Z, K = D M⁻¹K_θ Z, a_e = w_e Z, b_e = D M⁻¹w_eᵀK_e,
  F = D M⁻¹T): the rigid-body motion drops out exactly because C_θ 1 = K_θ 1 = 0 and w_e 1 = 0.

Within a stage combination s = (s_1 … s_m) (element e on its stage s_e, f_e = k_e δ + o_e there)
the equation is linear:

    x'' + C x' + K_s x = F(t) − Σ_e b_e o_e,       K_s = K + Σ_e k_e b_e a_eᵀ,

and its first-order form z = (x, x') has the stage matrix A_s = [[0, I], [−K_s, −C]].

A system may carry every element's whole law (``laws``, one :class:`~rattle.model.NonsmoothLaw`
per element: jumps — a preload — and Coulomb friction levels r_ej per stage),

    x'' + C x' + K x + Σ_e b_e [f_e(a_e·x) + r_e(a_e·x) sgn(a_e·x')] = F(t),

its elements then carry the continuous part of their law (the same breakpoints and slopes, no
jumps): every smooth analysis reads that part (:meth:`System.continuous`), the exact event flow
and the regularised harmonic balance the whole law. Whether a system needs them is a property
(:attr:`System.discontinuous`, :attr:`System.has_friction`, :attr:`System.has_jumps`), not a class.

The single equation with a discontinuous law (a preload, Coulomb friction),

    δ'' + c δ' + k g(δ, δ') = F(t),      g(δ, δ') = f(δ) + r(δ) sgn(δ'),

is the system with n = m = 1, C = [[c]], K = [[0]], a = [1], b = [k] and the element's whole law
g (:meth:`System.single`, :meth:`System.from_model`); it keeps its
:class:`~rattle.model.Excitation` (``excitation``, :attr:`System.is_single_equation`), and the
exact flow and the analyses take their scalar paths on it (the coefficients ``c``, ``k`` and the
law ``law`` read there).

A speed-dependent mean load (a drag torque tabulated by speed, :mod:`rattle.model._drag`) makes
the mean forcing a function of the forcing frequency, F_0(Ω) = F_0 + d(Ω) u (``load``): every
analysis at frequency Ω uses :meth:`System.mean_at` (the forcing, the static equilibrium, the
exact flow), and the harmonic balance carries d(Ω) and d'(Ω) in its residual.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass, field

import numpy as np

from .._limits import bounded_scale
from .._typing import FloatArray
from ._discontinuous import AbstractJumpLaw, Friction, NonsmoothLaw
from ._drag import SpeedLoad
from ._elastic import AbstractElastic, Piecewise, _check_real
from ._excitation import Excitation


@dataclass(frozen=True, slots=True, eq=False)
class ReducedElement:
    """A clearance element in the coordinates x: δ = ``a`` · x, force ``b`` f(δ) on the
    left-hand side, law ``law`` (its breakpoints and slopes)."""

    name: str
    a: FloatArray  # (n,)
    b: FloatArray  # (n,)
    law: AbstractElastic

    @property
    def breakpoints(self) -> FloatArray:
        return self.law.stages.breakpoints

    @property
    def slopes(self) -> FloatArray:
        return self.law.stages.slopes

    @property
    def offsets(self) -> FloatArray:
        return self.law.stages.offsets


@dataclass(frozen=True, slots=True, eq=False)
class System:
    """Equations of motion x'' + C x' + K x + Σ_e b_e f_e(a_e·x) = F(t) (module docstring).

    ``damping`` C and ``stiffness`` K (n, n); ``elements`` the clearance elements; forcing
    ``mean`` F_0 (n,), ``cos`` and ``sin`` (H_f, n): row h−1 holds F_ch and F_sh of harmonic h.
    ``coordinates`` names the coordinates; ``angles`` Z (N, n) maps x to the inertias' angles
    (relative to the last inertia for a free chain, ``free`` True); ``load`` an optional
    Ω-dependent part of the mean forcing (:class:`~rattle.model.SpeedLoad`, a drag by speed).

    ``laws`` every element's whole law (one :class:`~rattle.model.NonsmoothLaw` per element, in
    order, with the element's breakpoints and slopes: jumps and friction), None for the continuous
    laws of the elements; ``speed_order`` the engine order of Ω (rpm in results), None without an
    engine. Built with laws by :meth:`rattle.model.Chain.friction_system` and
    :meth:`with_friction`. ``excitation`` the single equation's
    :class:`~rattle.model.Excitation` (:meth:`single`, :meth:`from_model`; None for any other
    system): set, the system is the single equation δ'' + c δ' + k g(δ, δ') = F(t) (n = m = 1,
    K = 0, a = [1], b = [k], ``laws`` its whole law g) and its analyses take the scalar paths.
    """

    damping: FloatArray
    stiffness: FloatArray
    elements: tuple[ReducedElement, ...]
    mean: FloatArray
    cos: FloatArray
    sin: FloatArray
    coordinates: tuple[str, ...]
    angles: FloatArray
    free: bool = False
    load: SpeedLoad | None = None
    laws: tuple[NonsmoothLaw, ...] | None = None
    speed_order: float | None = None
    excitation: Excitation | None = None
    _stiffness_cache: dict = field(default_factory=dict, repr=False, compare=False)
    _continuous: System | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.excitation is not None and (self.laws is None or len(self.elements) != 1 or self.n != 1):
            raise ValueError("`excitation` is the single equation's (n = m = 1, with its whole law in `laws`): "
                             "build it with System.single or System.from_model")
        if self.laws is None:
            return
        laws = tuple(self.laws)
        if len(laws) != len(self.elements):
            raise ValueError(f"`laws` must hold one law per element ({len(self.elements)}), got {len(laws)}")
        for e, (law, el) in enumerate(zip(laws, self.elements)):
            if not isinstance(law, NonsmoothLaw):
                raise TypeError(f"`laws[{e}]` must be a NonsmoothLaw, got {law!r}")
            st = law.stages
            if not (np.array_equal(st.breakpoints, el.breakpoints) and np.array_equal(st.slopes, el.slopes)):
                raise ValueError(f"`laws[{e}]` must have the stages of element {el.name!r} of the system")
        object.__setattr__(self, "laws", laws)

    # --- equality: the single equation's by value, any other system by identity -------------
    def __eq__(self, other: object) -> bool:
        if self is other:
            return True
        if not isinstance(other, System):
            return NotImplemented
        if self.excitation is None or other.excitation is None:
            return False
        return (self.c, self.k, self.law, self.excitation) == (other.c, other.k, other.law, other.excitation)

    def __hash__(self) -> int:
        if self.excitation is None:
            return object.__hash__(self)
        return hash((self.c, self.k, self.law, self.excitation))

    # --- the single equation ----------------------------------------------------------------
    @classmethod
    def single(cls, *, damping: float, stiffness: float, law: NonsmoothLaw, excitation: Excitation) -> System:
        """The single equation δ'' + c δ' + k g(δ, δ') = F(t), per unit inertia: ``damping``
        c = C/I ≥ 0 (1/s), ``stiffness`` k = K/I > 0 (1/s²), ``law`` g (a
        :class:`~rattle.model.NonsmoothLaw`: its jumps and friction) and ``excitation`` F; the
        system with n = m = 1, C = [[c]], K = [[0]], a = [1], b = [k]."""
        c = _check_real("damping", damping)
        k = _check_real("stiffness", stiffness)
        if c < 0:
            raise ValueError(f"`damping` (c = C/I) must be >= 0, got {c!r}")
        if k <= 0:
            raise ValueError(f"`stiffness` (k = K/I) must be > 0, got {k!r}")
        if not isinstance(law, NonsmoothLaw):
            raise TypeError(f"`law` must be a NonsmoothLaw, got {law!r}")
        if not isinstance(excitation, Excitation):
            raise TypeError(f"`excitation` must be an Excitation, got {excitation!r}")
        el = law.elastic
        if isinstance(el, AbstractJumpLaw):  # the element carries the law's continuous part
            st = el.stages
            el = Piecewise(breakpoints=tuple(st.breakpoints.tolist()), slopes=tuple(st.slopes.tolist()))
        base = single_equation_system(c, k, el, excitation.mean, excitation.amplitudes, excitation.phases or ())
        out = dataclasses.replace(base, laws=(law,), excitation=excitation)
        object.__setattr__(out, "_continuous", base)
        return out

    @classmethod
    def from_model(cls, model: object, *, elastic: AbstractElastic | AbstractJumpLaw | None = None,
                   friction: Friction | None = None) -> System:
        """The single equation of a :class:`~rattle.model.Model` (its c, k and excitation) with its
        law (or ``elastic``: a law with jumps, :class:`~rattle.model.Preload` …) and ``friction``."""
        # (read by its fields: the Model builds on this module, which does not import it back)
        if not all(hasattr(model, a) for a in ("c", "k", "elastic", "excitation")) or not callable(
                getattr(model, "static_equilibrium", None)):
            raise TypeError(f"`model` must be a rattle Model, got {model!r}")
        law = NonsmoothLaw(elastic=model.elastic if elastic is None else elastic, friction=friction)
        return cls.single(damping=model.c, stiffness=model.k, law=law, excitation=model.excitation)

    @property
    def is_single_equation(self) -> bool:
        """True for the single equation with its whole law (:meth:`single`): n = m = 1, K = 0,
        a = [1], its ``excitation`` kept; the exact flow and the analyses take their scalar paths."""
        return self.excitation is not None

    def _single(self, what: str) -> None:
        if self.excitation is None:
            raise ValueError(f"`{what}` is the single equation's (System.single, System.from_model); this system "
                             f"has n = {self.n} coordinates and m = {self.m} elements: read `damping`, "
                             "`stiffness`, `elements` and `laws`")

    @property
    def c(self) -> float:
        """c = C/I (1/s) of the single equation (:meth:`single`; ValueError on any other system)."""
        self._single("c")
        return float(self.damping[0, 0])

    @property
    def k(self) -> float:
        """k = K/I (1/s²) of the single equation (:meth:`single`; ValueError on any other system)."""
        self._single("k")
        return float(self.elements[0].b[0])

    @property
    def law(self) -> NonsmoothLaw:
        """The single equation's whole law g (:meth:`single`; ValueError on any other system)."""
        self._single("law")
        return self.laws[0]  # type: ignore[index]

    def regularised(self, delta: FloatArray, velocity: FloatArray, width: float,
                    velocity_width: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """k g_ε and its partials (per unit inertia) of the single equation: the
        ``RegularisedForce`` of :mod:`rattle.hb._regularised`."""
        g, gd, gv = self.law.regularised(delta, velocity, width, velocity_width)
        return self.k * g, self.k * gd, self.k * gv

    # --- the elements' whole laws -----------------------------------------------------------
    def with_laws(self, laws: tuple[NonsmoothLaw, ...], speed_order: float | None = None) -> System:
        """This system with every element's whole law ``laws`` (one
        :class:`~rattle.model.NonsmoothLaw` per element, with its breakpoints and slopes) and
        ``speed_order``; its :meth:`continuous` part is this system's."""
        base = self.continuous()
        out = dataclasses.replace(base, laws=tuple(laws), speed_order=speed_order)
        object.__setattr__(out, "_continuous", base)
        return out

    def with_friction(self, levels: tuple[object, ...], *, elastic: tuple[object, ...] | None = None,
                      speed_order: float | None = None) -> System:
        """This system with friction ``levels`` per element (None, a number, or one per stage) and
        optionally ``elastic`` laws per element (None: the element's own law; a law with jumps,
        :class:`~rattle.model.Preload` or :class:`~rattle.model.PiecewiseJump`, with the element's
        breakpoints and slopes: the elements keep its continuous part)."""
        if len(levels) != self.m:
            raise ValueError(f"`levels` must hold one entry per element ({self.m}), got {len(levels)}")
        if elastic is None:
            elastic = (None,) * self.m
        if len(elastic) != self.m:
            raise ValueError(f"`elastic` must hold one entry per element ({self.m}), got {len(elastic)}")
        laws = tuple(NonsmoothLaw(elastic=el.law if law is None else law,  # type: ignore[arg-type]
                                  friction=None if r is None else Friction(levels=r))  # type: ignore[arg-type]
                     for el, r, law in zip(self.elements, levels, elastic))
        return self.with_laws(laws, speed_order=speed_order)

    def continuous(self) -> System:
        """The same equations with the continuous part of every law (no jumps, no friction): the
        system itself when it carries no whole ``laws``; what every smooth analysis reads."""
        if self.laws is None:
            return self
        if self._continuous is None:
            object.__setattr__(self, "_continuous", dataclasses.replace(self, laws=None, speed_order=None, excitation=None))
        return self._continuous  # type: ignore[return-value]

    @property
    def discontinuous(self) -> bool:
        """True when the system carries its elements' whole laws (jumps and friction, possibly
        none): the front ends solve it on the exact event flow, or regularised and checked
        exactly; False for the continuous laws (the smooth analyses)."""
        return self.laws is not None

    @property
    def has_friction(self) -> bool:
        """Some element's law has a friction level > 0."""
        return self.laws is not None and any(bool(np.any(law.friction_levels > 0)) for law in self.laws)

    @property
    def has_jumps(self) -> bool:
        """Some element's law jumps (a preload)."""
        return self.laws is not None and any(bool(np.any(law.stages.jumps > 0)) for law in self.laws)

    @property
    def element_names(self) -> tuple[str, ...]:
        """The elements' names, as the per-element result columns carry them (NAME_rms …); none
        for the single equation (:attr:`is_single_equation`: its measures are the columns
        themselves, as a Model's)."""
        return () if self.excitation is not None else tuple(e.name for e in self.elements)

    def friction_levels(self, e: int) -> FloatArray:
        """r_ej on every stage j of element ``e`` (zeros without ``laws``)."""
        if self.laws is None:
            return np.zeros(len(self.elements[e].slopes))
        return self.laws[e].friction_levels

    def jumps(self, e: int) -> FloatArray:
        """J_ei ≥ 0 at every breakpoint i of element ``e`` (zeros for a continuous law)."""
        if self.laws is None:
            return np.zeros(len(self.elements[e].breakpoints))
        return self.laws[e].stages.jumps

    def frequency_scale(self) -> float:
        """ω_n, the highest natural frequency over the stage combinations (rad/s)."""
        return self.stiffest_frequency()

    def speed_rpm(self, omega: object) -> object:
        """Crankshaft speed (rpm) at forcing frequency ``omega``, or None without an engine."""
        if self.speed_order is None:
            return None
        return np.asarray(omega, dtype=float) * (60.0 / (2.0 * np.pi * self.speed_order))

    # --- sizes --------------------------------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of coordinates."""
        return self.damping.shape[0]

    @property
    def m(self) -> int:
        """Number of clearance elements."""
        return len(self.elements)

    @property
    def forced_harmonics(self) -> int:
        """H_f, the highest forcing harmonic of Ω."""
        return self.cos.shape[0]

    @property
    def element_rows(self) -> FloatArray:
        """A (m, n): δ = A x, one row a_e per element."""
        return np.array([e.a for e in self.elements], dtype=float).reshape(self.m, self.n)

    @property
    def element_columns(self) -> FloatArray:
        """B (n, m): the non-linear force B f(δ), one column b_e per element."""
        return np.array([e.b for e in self.elements], dtype=float).reshape(self.m, self.n).T

    # --- the forcing --------------------------------------------------------------------------
    def mean_at(self, omega: FloatArray | float) -> FloatArray:
        """F_0(Ω) = F_0 + d(Ω) u, shape Ω.shape + (n,) (F_0 itself without a ``load``)."""
        if self.load is None:
            return np.broadcast_to(self.mean, np.shape(omega) + (self.n,)).copy() if np.ndim(omega) else self.mean.copy()
        d = np.asarray(self.load.value(omega), dtype=float)
        return self.mean + d[..., None] * self.load.direction

    def mean_slope(self, omega: float) -> FloatArray:
        """dF_0/dΩ = d'(Ω) u (n,): zero without a ``load``."""
        if self.load is None:
            return np.zeros(self.n)
        return self.load.slope(float(omega)) * self.load.direction

    def forcing(self, t: FloatArray | float, omega: FloatArray | float) -> FloatArray:
        """F(t) at times ``t``: shape t.shape + (n,) (``omega`` a number, or an array broadcasting
        against ``t``)."""
        t = np.asarray(t, dtype=float)
        if self.load is None:
            out = np.empty(t.shape + (self.n,))
            out[...] = self.mean
        else:
            out = np.broadcast_to(self.mean_at(np.broadcast_to(omega, t.shape)), t.shape + (self.n,)).copy()
        for h in range(1, self.forced_harmonics + 1):
            ph = h * omega * t
            out += np.cos(ph)[..., None] * self.cos[h - 1] + np.sin(ph)[..., None] * self.sin[h - 1]
        return out

    # --- stages -------------------------------------------------------------------------------
    def stage_counts(self) -> tuple[int, ...]:
        """Number of stages of every element's law."""
        return tuple(len(e.slopes) for e in self.elements)

    def stage_stiffness(self, stages: tuple[int, ...]) -> FloatArray:
        """K_s = K + Σ_e k_e b_e a_eᵀ for the stage combination ``stages`` (cached)."""
        key = tuple(int(s) for s in stages)
        K = self._stiffness_cache.get(key)
        if K is None:
            K = np.array(self.stiffness, dtype=float)
            for e, s in zip(self.elements, key):
                K = K + e.slopes[s] * np.outer(e.b, e.a)
            self._stiffness_cache[key] = K
        return K

    def stage_offset(self, stages: tuple[int, ...]) -> FloatArray:
        """Σ_e b_e o_e, the constant part of the element forces on the stage combination."""
        out = np.zeros(self.n)
        for e, s in zip(self.elements, stages):
            out = out + e.offsets[int(s)] * e.b
        return out

    def stage_matrix(self, stages: tuple[int, ...]) -> FloatArray:
        """A_s = [[0, I], [−K_s, −C]] (2n, 2n), the first-order stage matrix."""
        n = self.n
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -self.stage_stiffness(stages)
        A[n:, n:] = -self.damping
        return A

    def stages_of(self, x: FloatArray) -> tuple[int, ...]:
        """The stage of every element at coordinates ``x`` (n,)."""
        return tuple(int(np.searchsorted(e.breakpoints, float(e.a @ x), side="right")) for e in self.elements)

    def restoring(self, x: FloatArray) -> FloatArray:
        """K x + Σ_e b_e f_e(a_e·x) for x of shape (..., n)."""
        x = np.asarray(x, dtype=float)
        out = x @ self.stiffness.T
        for e in self.elements:
            out = out + e.law.force(x @ e.a)[..., None] * e.b
        return out

    # --- equilibrium and scales ---------------------------------------------------------------
    def static_equilibrium(self, omega: float | None = None) -> FloatArray:
        """x_s solving K x + Σ_e b_e f_e(a_e·x) = F_0 (F_0(Ω) at ``omega`` with a ``load``;
        without ``omega`` the constant part F_0).

        Every stage combination is linear: K_s x = F_0 − Σ b_e o_e. Starting from the
        combination at x = 0 the solution is iterated (non-smooth Newton: solve on the current
        combination, move to the combination of the solution) and, should that cycle, every
        combination is tried. Where a combination is singular (a backlash gap in a chain with no
        other stiffness) and F_0 balances it, the least-squares solution in the middle of the
        gap is taken.
        """
        F0 = self.mean if omega is None else self.mean_at(float(omega))
        x = np.zeros(self.n)
        seen: set[tuple[int, ...]] = set()
        stages = self.stages_of(x)
        for _ in range(4 * (self.m + 1) + 8):
            sol = self._solve_on(stages, F0)
            if sol is not None and self.stages_of(sol) == stages:
                return sol
            seen.add(stages)
            if sol is None:
                break
            stages = self.stages_of(sol)
            if stages in seen:
                break
        for combo in itertools.product(*(range(c) for c in self.stage_counts())):
            sol = self._solve_on(combo, F0)
            if sol is not None and self._on_stages(sol, combo):
                return sol
        raise ValueError(
            "the static equilibrium K x + Σ b f(a·x) = F_0 has no solution: the mean torques are not "
            "balanced by any stage of the elastic elements (check the links to ground and the mean torques)"
        )

    def _solve_on(self, stages: tuple[int, ...], F0: FloatArray) -> FloatArray | None:
        Ks = self.stage_stiffness(stages)
        rhs = F0 - self.stage_offset(stages)
        try:
            cond = np.linalg.cond(Ks)
        except np.linalg.LinAlgError:
            cond = np.inf
        if np.isfinite(cond) and cond < 1e12:
            return np.linalg.solve(Ks, rhs)
        # Singular: a balanced gap. Least squares plus the move into the middle of the gap.
        x, *_ = np.linalg.lstsq(Ks, rhs, rcond=1e-12)
        if np.linalg.norm(Ks @ x - rhs) > 1e-9 * max(1.0, np.linalg.norm(rhs)):
            return None
        null = np.linalg.svd(Ks)[2][np.linalg.svd(Ks, compute_uv=False) <= 1e-12 * max(1.0, np.abs(Ks).max())]
        for v in null:  # centre every free direction in the gaps it opens
            lo, hi = -np.inf, np.inf
            for e, s in zip(self.elements, stages):
                av = float(e.a @ v)
                if abs(av) < 1e-14:
                    continue
                d = np.concatenate(([-np.inf], e.breakpoints, [np.inf]))
                base = float(e.a @ x)
                t1, t2 = (d[s] - base) / av, (d[s + 1] - base) / av
                lo, hi = max(lo, min(t1, t2)), min(hi, max(t1, t2))
            if np.isfinite(lo) and np.isfinite(hi):
                x = x + 0.5 * (lo + hi) * v
        return x

    def _on_stages(self, x: FloatArray, stages: tuple[int, ...]) -> bool:
        for e, s in zip(self.elements, stages):
            d = float(e.a @ x)
            lo = e.breakpoints[s - 1] if s > 0 else -np.inf
            hi = e.breakpoints[s] if s < len(e.breakpoints) else np.inf
            tol = 1e-12 * max(1.0, abs(d))
            if not (lo - tol <= d <= hi + tol):
                return False
        return True

    def natural_frequencies(self) -> FloatArray:
        """Undamped natural frequencies (rad/s) of the stiffest stage combination (every element
        on its stiffest stage), ascending; zero for rigid-body-like directions."""
        stiffest = tuple(int(np.argmax(e.slopes)) for e in self.elements)
        lam = np.linalg.eigvals(self.stage_stiffness(stiffest))
        return np.sort(np.sqrt(np.maximum(lam.real, 0.0)))

    def stiffest_frequency(self) -> float:
        """The highest natural frequency over the stage combinations (every element on its
        stiffest stage), rad/s."""
        return float(self.natural_frequencies()[-1])

    def force_scale(self) -> float:
        """A characteristic force per inertia: max over coordinates of |F_0| + Σ_h |F_h|."""
        amp = np.abs(self.mean) + np.sum(np.hypot(self.cos, self.sin), axis=0)
        if self.load is not None:
            amp = amp + self.load.largest * np.abs(self.load.direction)
        return max(float(np.max(amp)), 1e-300)

    def length_scale(self) -> float:
        """A characteristic deflection (rad): :meth:`_smooth_length_scale` of the continuous laws;
        with whole ``laws``, the largest deflection of an element's friction and jumps,
        (Σ_i J_ei + max_j r_ej) / min_j s_ej (the widths of its stick and lock bands in
        deflection, as the single equation counts them), when larger."""
        if self.excitation is not None:
            return self._single_length_scale()
        base = self._smooth_length_scale()
        if self.laws is None:
            return base
        fr = 0.0
        for law in self.laws:
            s = law.stages.slopes
            pos = s[s > 0]
            if pos.size:
                width = float(np.sum(law.stages.jumps)) + float(np.max(law.friction_levels))
                fr = max(fr, width / float(np.min(pos)))
        return max(base, fr)

    def _single_length_scale(self) -> float:
        """The single equation's L (rad): breakpoints, the jumps' and friction's deflections and
        the quasi-static dynamic amplitude (|F_m| + Σ|F_pn|) / (k s_min), whichever is largest."""
        law = self.law
        st = law.stages
        s_pos = st.slopes[st.slopes > 0]
        exc = self.excitation
        assert exc is not None
        dyn = (abs(exc.mean) + exc.amplitude_scale) / (self.k * float(np.min(s_pos)))
        bp = float(np.max(np.abs(st.breakpoints))) if st.breakpoints.size else 0.0
        jump = float(np.sum(st.jumps) + np.max(law.friction_levels)) / float(np.min(s_pos))
        return max(bp, dyn, jump, 1e-300)

    def _smooth_length_scale(self) -> float:
        """A characteristic deflection (rad): the static deflection, the breakpoints and the
        quasi-static dynamic amplitude, whichever is largest.

        The quasi-static amplitude of the forcing amplitudes F_a is max|K_soft⁻¹ F_a| (every
        element on its softest positive stage), unless it exceeds ten times the bound
        w + max|K_out⁻¹ F_a| (every element on the softer positive one of its two outer stages;
        w the widest span of an element's breakpoints; ``_limits.bounded_scale``): an inner stage
        holds no more than its width, however soft (see :meth:`rattle.model.Model.length_scale`,
        the same rule for the single equation: a nearly flat inner stage would otherwise make L
        many times the motion).
        """
        xs = self.static_equilibrium()
        if self.load is not None:  # the static deflection under the largest drag of the table
            xs = max((self.static_equilibrium(float(w)) for w in self.load.nodes), key=lambda x: float(np.max(np.abs(x))))
        bp = max((float(np.max(np.abs(e.breakpoints))) for e in self.elements if e.breakpoints.size), default=0.0)
        amp = np.sum(np.hypot(self.cos, self.sin), axis=0)

        def quasi_static(stages: tuple[int, ...]) -> float:
            try:
                return float(np.max(np.abs(np.linalg.solve(self.stage_stiffness(stages), amp)))) if np.any(amp) else 0.0
            except np.linalg.LinAlgError:
                return 0.0

        dyn = quasi_static(tuple(int(np.argmin(np.where(e.slopes > 0, e.slopes, np.inf))) for e in self.elements))
        outer = [min((j for j in (0, len(e.slopes) - 1) if e.slopes[j] > 0), key=lambda j: e.slopes[j], default=None)
                 for e in self.elements]
        span = max((float(np.ptp(e.breakpoints)) for e in self.elements if e.breakpoints.size), default=0.0)
        if span > 0 and all(j is not None for j in outer):
            bound = span + quasi_static(tuple(int(j) for j in outer))  # type: ignore[arg-type]
            if bound > span:  # a singular outer combination (0) bounds nothing
                dyn = bounded_scale(dyn, bound)
        return max(float(np.max(np.abs(xs))) if xs.size else 0.0, bp, dyn, 1e-300)


def single_equation_system(c: float, k: float, law: AbstractElastic, mean: float,
                           amplitudes: tuple[float, ...], phases: tuple[float, ...], name: str = "delta") -> System:
    """The n = m = 1 system of δ'' + c δ' + k f(δ) = F_m + Σ_n F_pn cos(nΩt + φ_n)."""
    amps = np.asarray(amplitudes, dtype=float)
    ph = np.asarray(phases, dtype=float)
    return System(
        damping=np.array([[c]]),
        stiffness=np.zeros((1, 1)),
        elements=(ReducedElement(name, np.array([1.0]), np.array([k]), law),),
        mean=np.array([mean]),
        cos=(amps * np.cos(ph))[:, None],
        sin=(-amps * np.sin(ph))[:, None],
        coordinates=(name,),
        angles=np.array([[1.0], [0.0]]),
        free=True,
    )


__all__ = ["System", "ReducedElement", "single_equation_system"]
