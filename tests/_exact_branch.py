"""Exact reference of the special points of the period-1 branch (independent of harmonic balance).

What it does
------------
The period-1 orbits of δ'' + c δ' + k f(δ) = F_m + Σ F_pn cos(nΩt + φ_n) (f continuous, piecewise
linear) are the zeros of the shooting function

    G(x0, Ω) = φ(x0; 0 → 2π/Ω, Ω) − x0,        x0 = (δ(0), δ'(0)) ∈ R²,

φ the flow of :class:`rattle.timeint.ExactIntegrator`: closed-form stage solutions, crossings
located to round-off, ∂φ/∂x0 = M the exact monodromy (product of the stage transition matrices; the
saltation matrices are the identity because f is continuous). Nothing of harmonic balance is used.

1. Variables are scaled: y = (δ0 / L, δ'0 / (L ω_n), Ω / ω_n), L = ``model.length_scale()``,
   ω_n = ``model.natural_frequency``; G is scaled like x0.
2. Start: at Ω_min the orbit is found by Newton shooting from the linear response about the static
   equilibrium. The random cases (:func:`iter_cases`) must have a unique motion there
   (:func:`low_frequency_orbits`: shooting and three simulations agree), so that HB and the
   reference follow the same branch; a case with coexisting motions at Ω_min is rejected.
3. Continuation in (x0, Ω) with SMALL steps: arclength ≤ ``max_step`` (2e-3 scaled) and
   |ΔΩ| ≤ ``max_domega`` (1e-3 ω_n); a step is only ever halved (corrector failure, a turn of the
   secant above 0.1 rad, a corrected point farther than twice the step), never enlarged beyond the
   caps. Predictor: quadratic extrapolation through the last three points (error O(h³) ≈ 1e-8).
   Corrector: where the branch is steep in Ω (|dΩ/ds| > 0.05) Newton on G = 0 at the predicted Ω
   with the exact Jacobian M − I; elsewhere (near folds) pseudo-arclength, Newton on
   [G; d·(y − y_pred)] = 0 in the plane normal to the predictor direction d. ∂G/∂Ω enters only
   that corrector's Jacobian column, by central differences of the exact flow with a step of 1e-6
   in Ω/ω_n (truncation ~h²·|∂³G/∂Ω³|/6 and round-off ~ε/h, both below 1e-8 relative; checked by
   :func:`check_g_omega`): its error slows Newton slightly and has no effect on the solution, which
   is that of the exact G. A Newton iterate is accepted when |G| ≤ 1e-9 (scaled) with a next step
   ≤ 1e-8, or when the Newton step itself is ≤ 1e-7: that last step is then applied without a
   further evaluation (quadratic convergence: the point is within ~1e-14 of the branch) and the
   point keeps the monodromy of the iterate it came from, 1e-7 away — immaterial for the signs of
   ψ except where |ψ| is tiny, which the guard of 5. refines with fresh points anyway. Where the
   orbit grazes a breakpoint while moving slowly, M changes like the square root of the distance
   with a huge constant and the branch turns by a finite angle within ~1e-8 (a corner): after a
   rejected step the retry uses the secant predictor and the pseudo-arclength corrector, and once
   the step is 1000× below its cap a turn up to 1.2 rad is accepted.
4. Test functions from the exact monodromy at every point: ψ_fold = det(M − I) = 1 − tr M + det M
   (a multiplier at +1), ψ_pd = det(M + I) = 1 + tr M + det M (a multiplier at −1). Neimark–Sacker
   cannot occur: one coordinate, so det M = exp(−c T) < 1 for c > 0 and a complex pair lies inside
   the unit circle.
5. Guard against hidden pairs (two sign changes inside one step): a segment between consecutive
   points is bisected in arclength (each midpoint re-corrected onto the branch in the plane normal
   to the segment's secant), recursively, down to ``min_split`` (1e-7 scaled), wherever
   * the number of breakpoint crossings per period (per breakpoint) differs between its ends: the
     orbit grazes a breakpoint in between, where M is not smooth (a square-root change), and a
     border collision can flip the sign of ψ; or
   * a test function does not change sign but one of its end values is small relative to its
     variation, |ψ| ≤ 4·V, V the largest |Δψ| over the segment and its neighbours (a smooth ψ that
     dips through zero and back inside the segment must be near zero at an end in that sense).
   Sub-segments are judged the same way (V halves with the length, the expected variation of a
   smooth ψ).
6. Every sign change of ψ between consecutive (refined) points is located by Brent's method on the
   arclength s along the segment's secant, each trial point corrected onto the branch in the plane
   normal to the secant, to |Δs| ≤ 1e-11 (scaled; |ΔΩ| ≤ |Δs| ω_n). Roots outside [Ω_min, Ω_max]
   are dropped. For a chain (state of dimension 2n ≥ 4) only the sign changes across which the
   stability changes are located — the points rattle labels (its ``bifurcation`` column marks
   where stability changes): a multiplier that crosses the unit circle while another is already
   outside (the fold of an unstable stretch) is a bifurcation of an unstable orbit, not counted.
   A zero of ψ_ns is a Neimark–Sacker point only where the pair is complex (not a neutral saddle).

Why it can be trusted
---------------------
The flow is exact (no truncation), so the located points carry only round-off and the 1e-11
location error. The steps are capped in advance at 2e-3 (HB's continuation allows up to 0.08 in
its own scaled variables) and shortened wherever the branch turns, so a pair of sign changes could
hide only within one such short step, and there the guard of point 5 splits the segment wherever
a hidden pair is possible: a smooth ψ dipping through zero and back within a step has an end value
small compared with the variation over the neighbouring steps (exact for a quadratic ψ), and a
non-smooth one needs a change of the crossing structure, which is bisected to 1e-7. The guard on
its own recovers the gear example's period-doubling pair from a branch sampled only at Ω = 0.62,
0.635, 0.665, 0.68 (a test). The reference reproduces the H-independent exact special points of the
reference clutch and the gear example to < 1e-6, and harmonic balance at H = 32 agrees with it to
~1e-7 typically, 1e-5 at worst (tests/test_random_bifurcations.py, benchmarks/bench_bifurcations.py).
What it does not guard against: three sign changes inside one step (one visible, two hidden); a
smooth ψ that is far from quadratic over three steps of 2e-3; a border collision that flips ψ
without changing the number of crossings of any breakpoint (two grazings at once, codimension
two). A case whose guard could not split a segment (corrector failure) is reported in
``stats["guard_failures"]`` and rejected.

Conventions of the comparison
-----------------------------
On the period-1 branch there are only folds (a multiplier crossing +1; with a generic, non-
symmetric law or F_m ≠ 0 the +1 crossing is a fold, not a pitchfork) and period doublings (a
multiplier crossing −1). rattle labels a +1 crossing at the vertex of a period-doubling pitchfork
``period_doubling`` only on sub-harmonic branches, which this reference does not follow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.optimize

from rattle.model import Model
from rattle.analysis import steady_state
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit, shoot_system_orbit

KINDS = ("fold", "period_doubling", "neimark_sacker")


class ReferenceError(RuntimeError):
    """The reference continuation could not be carried out (the case is rejected)."""


@dataclass(frozen=True, slots=True)
class BranchPoint:
    """A point of the exact branch: scaled ``y``, monodromy ``M``, test functions ``psi`` (fold,
    period doubling), ``signature`` (crossings per period of each breakpoint)."""

    y: np.ndarray
    M: np.ndarray
    psi: tuple[float, float]
    signature: tuple[int, ...]


@dataclass
class ExactBranch:
    """The result: ``special`` [(kind, Ω), …] in the order of the branch (arclength), ``states``
    the orbits' (δ(0), δ'(0)) there, ``points`` of the branch (Ω, δ0, δ'0, ψ_fold, ψ_pd as rows of
    an array), effort counters, the wall time and ``stats["guard_failures"]``: Ω of segments the
    hidden-pair guard wanted to split but whose midpoint could not be corrected (a case with any
    is not trusted: :func:`iter_cases` rejects it)."""

    special: list[tuple[str, float]]
    points: np.ndarray | None
    states: list[np.ndarray] = field(default_factory=list)  # (δ(0), δ'(0)) at each special point
    steps: int = 0
    evaluations: int = 0
    splits: int = 0
    seconds: float = 0.0
    cpu: float = 0.0  # process time (s): the figure to compare on a shared machine
    stats: dict = field(default_factory=dict)


def _bialternate(M: np.ndarray) -> np.ndarray:
    """M ⊙ M: the 2 × 2 minors m_ir m_js − m_is m_jr, i < j, r < s (eigenvalues μ_i μ_j, i < j)."""
    i, j = np.triu_indices(M.shape[0], 1)
    return M[np.ix_(i, i)] * M[np.ix_(j, j)] - M[np.ix_(i, j)] * M[np.ix_(j, i)]


def _psi(M: np.ndarray) -> tuple[float, ...]:
    """ψ_fold = det(M − I), ψ_pd = det(M + I) and, for a state of dimension ≥ 4, ψ_ns =
    det(M ⊙ M − I) (a complex pair on the unit circle; also zero at a neutral saddle, which
    :func:`guard_and_locate` tells apart from the multipliers)."""
    if M.shape[0] == 2:
        tr = M[0, 0] + M[1, 1]
        det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
        return 1.0 - tr + det, 1.0 + tr + det
    eye = np.eye(M.shape[0])
    B = _bialternate(M)
    return (float(np.linalg.det(M - eye)), float(np.linalg.det(M + eye)),
            float(np.linalg.det(B - np.eye(B.shape[0]))))


class _ShootingProblem:
    """G(y) in scaled variables, with the exact monodromy: for a single-equation ``Model`` on the
    closed-form :class:`~rattle.timeint.ExactIntegrator` (state (δ, δ')), for any other model (a
    chain) on the :class:`~rattle.timeint.ExactIntegrator` of its System (state (x, x'), 2n)."""

    def __init__(self, model, fd_step: float = 1e-6) -> None:
        self.model = model
        self.single = isinstance(model, Model)
        system = model.system()
        self.system = system
        self.integ = ExactIntegrator(model) if self.single else ExactIntegrator(system)
        self.L = model.length_scale()
        self.wn = model.natural_frequency
        n = system.n
        self.dim = 2 * n
        self.sx = np.concatenate((np.full(n, self.L), np.full(n, self.L * self.wn)))
        self.fd_step = fd_step
        self.evaluations = 0
        if self.single:
            self._bp = np.asarray(model.elastic.stages.breakpoints, dtype=float)
        else:
            self._bp = [(e, float(b)) for e, el in enumerate(system.elements) for b in el.breakpoints]

    def unscale(self, y: np.ndarray) -> tuple[np.ndarray, float]:
        return y[:-1] * self.sx, float(y[-1] * self.wn)

    def scale(self, x0: np.ndarray, omega: float) -> np.ndarray:
        return np.concatenate((np.asarray(x0, dtype=float) / self.sx, [omega / self.wn]))

    def shoot(self, omega: float, x0: np.ndarray):
        """Newton shooting for the period-1 orbit at ``omega`` from ``x0``."""
        if self.single:
            return shoot_periodic_orbit(self.model, omega, x0, integrator=self.integ)
        return shoot_system_orbit(self.system, omega, x0, integrator=self.integ)

    def evaluate(self, y: np.ndarray):
        """(scaled G, M (unscaled), scaled M, signature)."""
        x0, w = self.unscale(y)
        traj = self.integ.propagate(x0, 0.0, 2.0 * math.pi / w, w)
        self.evaluations += 1
        G = (traj.state1 - x0) / self.sx
        M = traj.sensitivity
        Ms = M * self.sx[None, :] / self.sx[:, None]
        if self.single:
            crossed = traj.crossed_breakpoints
            sig = tuple(int(np.count_nonzero(crossed == b)) for b in self._bp)
        else:
            sig = tuple(int(np.count_nonzero((traj.crossing_elements == e) & (traj.crossing_breakpoints == b)))
                        for e, b in self._bp)
        return G, M, Ms, sig

    def g_omega(self, y: np.ndarray) -> np.ndarray:
        """∂G/∂(Ω/ω_n) (scaled) by central differences of the exact flow, step ``fd_step``."""
        h = self.fd_step * max(1.0, abs(y[-1]))
        yp, ym = y.copy(), y.copy()
        yp[-1] += h
        ym[-1] -= h
        return (self.evaluate(yp)[0] - self.evaluate(ym)[0]) / (2.0 * h)


@dataclass
class _Corrector:
    prob: _ShootingProblem
    tol: float = 1e-11
    max_iter: int = 12
    g_col: np.ndarray | None = None

    def correct(self, y_pred: np.ndarray, d: np.ndarray, y_fix: np.ndarray | None = None,
                tol: float | None = None, last_step: float | None = None) -> BranchPoint | None:
        """Newton on [G(y); d·(y − y_fix)] = 0 from y_pred (y_fix defaults to y_pred), until the
        scaled |G| ≤ ``tol`` (default ``self.tol``) and the next Newton step is below 10·tol, or,
        with ``last_step``, until a Newton step is below it: that step is then taken without a
        further evaluation (Newton's quadratic convergence puts the point within ~|step|² of the
        branch) and the monodromy of the point it started from is kept (|step| away)."""
        tol = self.tol if tol is None else tol
        if self.g_col is None:
            self.g_col = self.prob.g_omega(y_pred)
        p = self._newton(y_pred, d, y_fix, tol, last_step)
        if p is None:  # the ∂G/∂Ω column may come from far away: once more with a fresh one
            self.g_col = self.prob.g_omega(y_pred)
            p = self._newton(y_pred, d, y_fix, tol, last_step)
        return p

    def _newton(self, y_pred: np.ndarray, d: np.ndarray, y_fix: np.ndarray | None, tol: float,
                last_step: float | None) -> BranchPoint | None:
        y = y_pred.copy()
        anchor = y_pred if y_fix is None else y_fix
        refreshed = False
        for it in range(self.max_iter):
            G, M, Ms, sig = self.prob.evaluate(y)
            r = np.concatenate((G, [float(d @ (y - anchor))]))
            k = G.size
            J = np.zeros((k + 1, k + 1))
            J[:k, :k] = Ms - np.eye(k)
            J[:k, k] = self.g_col
            J[k] = d
            try:
                dy = np.linalg.solve(J, -r)
            except np.linalg.LinAlgError:
                return None
            if not np.all(np.isfinite(dy)):
                return None
            if float(np.max(np.abs(G))) <= tol and float(np.max(np.abs(dy))) <= 10.0 * tol:
                return BranchPoint(y, M, _psi(M), sig)
            if last_step is not None and float(np.max(np.abs(dy))) <= last_step:
                return BranchPoint(y + dy, M, _psi(M), sig)
            if it >= 3 and not refreshed:  # slow: the stale ∂G/∂Ω column is the likely cause
                self.g_col = self.prob.g_omega(y)
                refreshed = True
            y = y + dy
            if y[-1] <= 0.0 or float(np.max(np.abs(y - y_pred))) > 0.1:  # diverging
                return None
        return None

    def correct_fixed_omega(self, y_pred: np.ndarray, tol: float | None = None,
                            last_step: float | None = None) -> BranchPoint | None:
        """Newton on G(x0, Ω) = 0 in x0 only, at the predicted Ω (natural parameter): the
        Jacobian Ms − I is exact and the stage solutions are reused (one Ω per step).
        ``tol``, ``last_step``: as for :meth:`correct`."""
        tol = self.tol if tol is None else tol
        y = y_pred.copy()
        for _ in range(self.max_iter):
            G, M, Ms, sig = self.prob.evaluate(y)
            try:
                dx = np.linalg.solve(Ms - np.eye(G.size), -G)
            except np.linalg.LinAlgError:
                return None
            if not np.all(np.isfinite(dx)):
                return None
            if float(np.max(np.abs(G))) <= tol and float(np.max(np.abs(dx))) <= 10.0 * tol:
                return BranchPoint(y, M, _psi(M), sig)
            if last_step is not None and float(np.max(np.abs(dx))) <= last_step:
                y = y.copy()
                y[:-1] += dx
                return BranchPoint(y, M, _psi(M), sig)
            y = y.copy()
            y[:-1] += dx
        return None


def _linear_guess(model, omega: float) -> np.ndarray:
    """(δ(0), δ'(0)) (a chain: (x(0), x'(0))) of the linear response on the stage of the static
    equilibrium (for a chain, from the harmonic-balance problem's closed-form linear solution:
    only a start guess, which the exact shooting then closes)."""
    if not isinstance(model, Model):
        from rattle.hb import HarmonicBalance, HBOptions

        hb = HarmonicBalance(model, HBOptions(harmonics=max(4, model.system().forced_harmonics)))
        Q = hb.coordinate_series(hb.linear_solution(omega))
        return np.array([float(hb.basis.evaluate(r, omega, 0.0, derivative=k)) for k in (0, 1) for r in Q])
    ds = model.static_equilibrium()
    s = float(model.elastic.stiffness(ds))
    ks = model.k * (s if s > 0 else 1.0)
    exc = model.excitation
    d0, v0 = ds, 0.0
    for n, a, ph in zip(exc.orders, exc.amplitudes, exc.phases):
        X = a * np.exp(1j * ph) / (ks - (n * omega) ** 2 + 1j * model.c * n * omega)
        d0 += X.real
        v0 += -n * omega * X.imag
    return np.array([d0, v0])


def low_frequency_orbits(model: Model, omega: float, tol: float = 1e-6) -> list[np.ndarray]:
    """Distinct period-1 states at ``omega`` reached from the linear guess (shooting) and by
    simulations from rest, from the linear guess and from a large-amplitude start: more than one
    entry means the start of the branch is ambiguous (coexisting orbits)."""
    integ = ExactIntegrator(model)
    L = model.length_scale()
    sx = np.array([L, L * model.natural_frequency])
    found: list[np.ndarray] = []

    def add(x):
        if not any(np.max(np.abs((x - f) / sx)) < tol for f in found):
            found.append(np.asarray(x, dtype=float))

    orbit = shoot_periodic_orbit(model, omega, _linear_guess(model, omega), integrator=integ)
    if orbit.converged:
        add(orbit.state0)
    big = np.array([model.static_equilibrium() + 3.0 * L, 0.0])
    for x0 in (np.array([model.static_equilibrium(), 0.0]), _linear_guess(model, omega), big):
        ss = steady_state(model, omega, x0, integrator=integ)
        if ss.period == 1:
            add(np.asarray(ss.state0))
        else:
            found.append(np.full(2, np.nan))  # a non-period-1 attractor also makes the start ambiguous
    return found


def exact_special_points(
    model: Model,
    omega: tuple[float, float],
    *,
    max_step: float = 2e-3,
    max_domega: float = 1e-3,
    min_step: float = 1e-8,
    min_split: float = 1e-7,
    split_factor: float = 4.0,
    xtol: float = 1e-11,
    max_steps: int = 200_000,
    natural_slope: float = 0.05,
    cont_tol: float = 1e-9,
    last_step: float = 1e-7,
    x0: np.ndarray | None = None,
    start: str = "low",
) -> ExactBranch:
    """Folds, period doublings (and, for chains, Neimark–Sacker points) of the period-1 branch of ``model`` over ``omega`` = (Ω_min,
    Ω_max) from the exact flow (module docstring), starting at the ``start`` end ("low": Ω_min,
    "high": Ω_max) from the orbit shot from ``x0`` (default: the linear guess) there. Raises :class:`ReferenceError` if the start
    orbit or a step cannot be computed."""
    import time

    t0, c0 = time.perf_counter(), time.process_time()
    lo, hi = map(float, omega)
    prob = _ShootingProblem(model)
    corr = _Corrector(prob)
    w0 = lo if start == "low" else hi
    orbit = prob.shoot(w0, _linear_guess(model, w0) if x0 is None else np.asarray(x0, dtype=float))
    if not orbit.converged:
        raise ReferenceError(f"no start orbit at Ω = {w0} (the {start} end)")
    y0 = prob.scale(orbit.state0, w0)
    # Initial direction: the null vector of [Ms − I, g_Ω], oriented towards increasing Ω.
    G, M, Ms, sig = prob.evaluate(y0)
    corr.g_col = prob.g_omega(y0)
    J = np.hstack((Ms - np.eye(G.size), corr.g_col[:, None]))
    t = np.linalg.svd(J)[2][-1]
    sense = 1.0 if start == "low" else -1.0  # into the range
    d = t / np.linalg.norm(t) * (sense if t[-1] > 0 else -sense)
    pts = [BranchPoint(y0, M, _psi(M), sig)]
    h = max_step
    steps = 0
    retry = False
    w_lo, w_hi = lo / prob.wn, hi / prob.wn
    while (pts[-1].y[-1] < w_hi) if start == "low" else (pts[-1].y[-1] > w_lo):
        if steps >= max_steps:
            raise ReferenceError(f"more than {max_steps} steps (reached Ω = {pts[-1].y[-1] * prob.wn:.6g})")
        if len(pts) >= 2:
            sec = pts[-1].y - pts[-2].y
            d_new = sec / np.linalg.norm(sec)
        else:
            d_new = d
        hh = min(h, max_step, max_domega / max(abs(d_new[-1]), 1e-300))
        if len(pts) >= 3 and not retry:
            # Quadratic extrapolation through the last three points (chord-length parameter):
            # an O(h³) predictor, so the corrector needs one or two Newton steps.
            y1, y2, y3 = pts[-3].y, pts[-2].y, pts[-1].y
            s1 = -float(np.linalg.norm(y3 - y2)) - float(np.linalg.norm(y2 - y1))
            s2 = -float(np.linalg.norm(y3 - y2))
            s = hh
            y_pred = (y1 * (s - s2) * s / ((s1 - s2) * s1) + y2 * (s - s1) * s / ((s2 - s1) * s2)
                      + y3 * (s - s1) * (s - s2) / (s1 * s2))
            step = y_pred - y3
            d_pred = step / np.linalg.norm(step)
        else:
            y_pred = pts[-1].y + hh * d_new
            d_pred = d_new
        # Away from folds (the branch steep in Ω) the corrector works at the predicted Ω; near a
        # fold, in the plane normal to the predictor direction (pseudo-arclength).
        if abs(d_pred[-1]) > natural_slope and not retry:
            p = corr.correct_fixed_omega(y_pred, tol=cont_tol, last_step=last_step)
        else:
            p = corr.correct(y_pred, d_pred, tol=cont_tol, last_step=last_step)
        ok = p is not None
        if ok:
            sec = p.y - pts[-1].y
            ns = float(np.linalg.norm(sec))
            turn = math.acos(min(1.0, max(-1.0, float(sec @ d_new) / ns))) if ns > 0 else math.pi
            # A turn above 0.1 rad means a jump to another branch — or a corner: where the orbit
            # grazes a breakpoint M changes like the square root of the distance, with a huge
            # constant when the orbit is slow there, so within ~1e-8 the branch turns by a
            # finite angle. Once the step is 1000× below its cap, a turn up to 1.2 rad is taken.
            max_turn = 0.1 if hh > 1e-3 * max_step else 1.2
            ok = ns > 0 and turn < max_turn and ns < 2.0 * hh
        if not ok:
            retry = True  # retry from the secant, in the plane normal to it
            h = 0.5 * hh
            corr.g_col = prob.g_omega(pts[-1].y)
            if h < min_step:
                raise ReferenceError(f"step below {min_step} at Ω = {pts[-1].y[-1] * prob.wn:.8g}")
            continue
        retry = False
        pts.append(p)
        steps += 1
        h = min(2.0 * hh, max_step)

    special, states, refined, splits, guard_failures = guard_and_locate(
        corr, pts, (lo, hi), split_factor=split_factor, min_split=min_split, xtol=xtol, cont_tol=cont_tol,
        last_step=last_step)
    points = np.array([[p.y[-1] * prob.wn, *(p.y[:-1] * prob.sx), *p.psi] for p in refined])
    return ExactBranch(special=special, points=points, states=states, steps=steps, evaluations=prob.evaluations,
                       splits=splits, seconds=time.perf_counter() - t0, cpu=time.process_time() - c0,
                       stats={"guard_failures": guard_failures})


def guard_and_locate(corr: "_Corrector", pts: list[BranchPoint], omega: tuple[float, float], *,
                     split_factor: float = 4.0, min_split: float = 1e-7, xtol: float = 1e-11,
                     cont_tol: float = 1e-9, last_step: float = 1e-7):
    """Steps 5 and 6 of the module docstring on the consecutive branch points ``pts``: the
    hidden-pair guard, then Brent's method on every sign change. Returns (special, states, refined
    points, number of splits, Ω of failed splits)."""
    prob = corr.prob
    lo, hi = omega
    # --- refine (guard against hidden pairs), then locate ----------------------------------
    splits = 0
    guard_failures: list[float] = []  # Ω of midpoints that could not be corrected

    def correct_mid(a: BranchPoint, b: BranchPoint) -> BranchPoint | None:
        sec = b.y - a.y
        dd = sec / np.linalg.norm(sec)
        mid = 0.5 * (a.y + b.y)
        return corr.correct(mid, dd, tol=cont_tol, last_step=last_step)

    def variation(a: BranchPoint, b: BranchPoint) -> np.ndarray:
        return np.abs(np.subtract(b.psi, a.psi))

    def flagged(a: BranchPoint, b: BranchPoint, V: np.ndarray) -> bool:
        if a.signature != b.signature:
            return True
        for k in range(len(a.psi)):
            if np.sign(a.psi[k]) == np.sign(b.psi[k]) and min(abs(a.psi[k]), abs(b.psi[k])) <= split_factor * V[k]:
                return True
        return False

    def refine(a: BranchPoint, b: BranchPoint, V: np.ndarray) -> list[BranchPoint]:
        """Points strictly between a and b added by the guard."""
        nonlocal splits
        length = float(np.linalg.norm(b.y - a.y))
        if length <= min_split or not flagged(a, b, V):
            return []
        m = correct_mid(a, b)
        if m is None:
            guard_failures.append(float(0.5 * (a.y[-1] + b.y[-1]) * prob.wn))
            return []
        splits += 1
        Vh = np.maximum(0.5 * V, np.maximum(variation(a, m), variation(m, b)))
        return refine(a, m, Vh) + [m] + refine(m, b, Vh)

    refined = [pts[0]]
    n = len(pts)
    for i in range(n - 1):
        a, b = pts[i], pts[i + 1]
        V = variation(a, b)
        if i > 0:
            V = np.maximum(V, variation(pts[i - 1], a))
        if i + 2 < n:
            V = np.maximum(V, variation(b, pts[i + 2]))
        refined.extend(refine(a, b, V))
        refined.append(b)

    special: list[tuple[str, float]] = []
    states: list[np.ndarray] = []
    def stable(p: BranchPoint) -> bool:
        return bool(np.max(np.abs(np.linalg.eigvals(p.M))) < 1.0)

    for a, b in zip(refined[:-1], refined[1:]):
        if len(a.psi) > 2 and stable(a) == stable(b):
            # A chain: a multiplier may cross the unit circle while another is already outside
            # (a fold or a torus of an already unstable orbit); as rattle's `bifurcation`
            # column, the reference counts the crossings where stability changes.
            continue
        for k, kind in enumerate(KINDS[: len(a.psi)]):
            if np.sign(a.psi[k]) * np.sign(b.psi[k]) >= 0:
                if a.psi[k] == 0.0 and lo <= a.y[-1] * prob.wn <= hi and _is_crossing(kind, a.M):
                    special.append((kind, float(a.y[-1] * prob.wn)))
                    states.append(a.y[:-1] * prob.sx)
                continue
            p = _locate(corr, a, b, k, xtol)
            w = float(p.y[-1] * prob.wn)
            if lo <= w <= hi and _is_crossing(kind, p.M):
                special.append((kind, w))
                states.append(p.y[:-1] * prob.sx)
    return special, states, refined, splits, guard_failures


def _is_crossing(kind: str, M: np.ndarray) -> bool:
    """A zero of ψ_ns is a Neimark–Sacker point only when the pair with μ_i μ_j = 1 is complex
    (a conjugate pair on the unit circle), not a neutral saddle (two reals, μ_i μ_j = 1)."""
    if kind != "neimark_sacker":
        return True
    mu = np.linalg.eigvals(M)
    i, j = np.triu_indices(mu.size, 1)
    k = int(np.argmin(np.abs(mu[i] * mu[j] - 1.0)))
    return bool(abs(mu[i[k]].imag) > 1e-6 * max(1.0, abs(mu[i[k]])))


def branch_points_at(model: Model, omegas, x0=None) -> tuple["_Corrector", list[BranchPoint]]:
    """Branch points at the given Ω (in order, each shot from the previous orbit, the first from
    ``x0`` or the linear guess) and a corrector: the input of :func:`guard_and_locate` for a
    hand-made coarse branch."""
    prob = _ShootingProblem(model)
    corr = _Corrector(prob)
    x = _linear_guess(model, omegas[0]) if x0 is None else np.asarray(x0, dtype=float)
    pts = []
    for w in omegas:
        orbit = prob.shoot(float(w), x)
        if not orbit.converged:
            raise ReferenceError(f"no orbit at Ω = {w}")
        x = orbit.state0
        y = prob.scale(x, float(w))
        _, M, _, sig = prob.evaluate(y)
        pts.append(BranchPoint(y, M, _psi(M), sig))
    return corr, pts


def _locate(corr: _Corrector, a: BranchPoint, b: BranchPoint, k: int, xtol: float) -> BranchPoint:
    """The branch point at the root of ψ_k on the branch between a and b (Brent on the arclength along
    the secant, trial points corrected in the plane normal to it)."""
    sec = b.y - a.y
    length = float(np.linalg.norm(sec))
    d = sec / length
    corr.g_col = corr.prob.g_omega(a.y)
    last: dict[float, BranchPoint] = {}

    def f(s: float) -> float:
        if s <= 0.0:
            return a.psi[k]
        if s >= length:
            return b.psi[k]
        p = corr.correct(a.y + s * d, d)
        if p is None:
            raise ReferenceError(f"corrector failed while locating at Ω ≈ {a.y[-1]}")
        last[s] = p
        return p.psi[k]

    s = scipy.optimize.brentq(f, 0.0, length, xtol=xtol, rtol=4 * np.finfo(float).eps)
    p = last.get(s)
    if p is None:
        p = corr.correct(a.y + s * d, d) if 0.0 < s < length else (a if s <= 0.0 else b)
    return p


def check_g_omega(model: Model, omega: float) -> float:
    """Relative difference of the central-difference ∂G/∂Ω at steps 1e-6 and 1e-5 (Ω/ω_n) on the
    orbit at ``omega``: the two agree to O(h²) when the step is in the right range."""
    prob = _ShootingProblem(model)
    orbit = shoot_periodic_orbit(model, omega, _linear_guess(model, omega), integrator=prob.integ)
    y = prob.scale(orbit.state0, omega)
    g1 = prob.g_omega(y)
    prob.fd_step = 1e-5
    g2 = prob.g_omega(y)
    return float(np.max(np.abs(g1 - g2)) / np.max(np.abs(g1)))


# ---------------------------------------------------------------------------------------------
# Random cases and the comparison with harmonic balance
# ---------------------------------------------------------------------------------------------
@dataclass
class RandomCase:
    """A random model with its frequency range and a one-line description."""

    model: Model
    omega: tuple[float, float]
    label: str


def random_case(rng: np.random.Generator, omega: tuple[float, float] = (0.2, 2.5)) -> RandomCase:
    """A random continuous piecewise-linear case (ω_n = 1): a backlash, a clutch or an asymmetric
    law with 2–5 breakpoints (slopes in [0, 1.5], the outer ones ≥ 0.3), clearances 0.05–1 rad,
    c = C/I in 0.02–0.12, mean load 0.2–1 × (the first breakpoint's restoring force scale) and up to
    three harmonics with random phases, sized so that the resonance amplitude (~F_p1/c) spans the
    clearance a few times while the off-resonance response stays at the breakpoints' scale."""
    from rattle.model import Backlash, Clutch, Excitation, Piecewise

    kind = ("backlash", "clutch", "piecewise")[int(rng.integers(3))]
    inertia = float(10.0 ** rng.uniform(-1.0, 1.0))  # scale-invariant: K = I keeps ω_n = 1
    c = float(rng.uniform(0.02, 0.12))
    if kind == "backlash":
        b = float(rng.uniform(0.05, 1.0))
        law = Backlash(b=b)
        scale = b
        desc = f"backlash b={b:.4f}"
    elif kind == "clutch":
        b = float(rng.uniform(0.05, 1.0))
        alpha = float(rng.uniform(0.05, 0.6))
        law = Clutch(alpha=alpha, b=b)
        scale = b * alpha + 0.3 * b
        desc = f"clutch alpha={alpha:.4f} b={b:.4f}"
    else:
        nb = int(rng.integers(2, 6))
        lo_b, hi_b = -float(rng.uniform(0.05, 1.0)), float(rng.uniform(0.05, 1.0))
        while True:
            bp = np.sort(rng.uniform(lo_b, hi_b, nb))
            if np.min(np.diff(bp)) > 0.02:
                break
        slopes = rng.uniform(0.0, 1.5, nb + 1)
        slopes[0], slopes[-1] = rng.uniform(0.3, 1.5), rng.uniform(0.3, 1.5)
        slopes[rng.random(nb + 1) < 0.15] = 0.0  # some dead stages
        slopes[0], slopes[-1] = max(slopes[0], 0.3), max(slopes[-1], 0.3)
        law = Piecewise(breakpoints=tuple(float(v) for v in bp), slopes=tuple(float(v) for v in slopes))
        scale = float(np.max(np.abs(bp))) * float(np.mean(slopes))
        desc = ("piecewise bp=[" + ",".join(f"{v:.4f}" for v in bp) + "] s=["
                + ",".join(f"{v:.3f}" for v in slopes) + "]")
    mean = float(rng.uniform(0.2, 1.0)) * scale
    n_h = int(rng.integers(1, 4))
    a1 = float(rng.uniform(0.1, 0.3)) * scale * (c / 0.05) ** 0.5
    amps = [a1] + [a1 * float(rng.uniform(0.1, 0.7)) for _ in range(n_h - 1)]
    phases = [0.0] + [float(rng.uniform(0.0, 2.0 * math.pi)) for _ in range(n_h - 1)]
    model = Model(inertia=inertia, damping=c * inertia, stiffness=inertia, elastic=law,
                  excitation=Excitation(mean=mean, amplitudes=tuple(amps), phases=tuple(phases)))
    label = (f"{desc} c={c:.4f} I=K={inertia:.4g} Fm={mean:.4g} Fp=[" + ",".join(f"{a:.4g}" for a in amps)
             + "] phi=[" + ",".join(f"{p:.3f}" for p in phases) + f"] omega={omega}")
    return RandomCase(model=model, omega=omega, label=label)


def gear_like_case(rng: np.random.Generator, omega: tuple[float, float] = (0.2, 2.5)) -> RandomCase:
    """A random case near examples/gear_backlash.toml, where narrow period-doubling bubbles (a
    multiplier pair touching −1 over ~0.005–0.02 in Ω) are common: K = I = 1, a backlash (or, one
    time in two, a clutch with α in 0.05–0.4), b in 0.05–0.5, c in 0.03–0.07, F_m = 0.2–0.45 b,
    one harmonic F_p1 = 0.1–0.25 b. Before issue 7 the continuation stepped over such a pair in 3
    of the first 80 cases of seed 7 (13, 26, 54)."""
    from rattle.model import Backlash, Clutch, Excitation

    b = float(rng.uniform(0.05, 0.5))
    c = float(rng.uniform(0.03, 0.07))
    alpha = float(rng.choice([0.0, rng.uniform(0.05, 0.4)]))
    mean = float(rng.uniform(0.2, 0.45)) * b
    amp = float(rng.uniform(0.1, 0.25)) * b
    law = Backlash(b=b) if alpha == 0.0 else Clutch(alpha=alpha, b=b)
    model = Model(inertia=1.0, damping=c, stiffness=1.0, elastic=law,
                  excitation=Excitation(mean=mean, amplitudes=(amp,)))
    desc = f"backlash b={b!r}" if alpha == 0.0 else f"clutch alpha={alpha!r} b={b!r}"
    return RandomCase(model=model, omega=omega, label=f"{desc} c={c!r} Fm={mean!r} Fp=[{amp!r}] omega={omega}")


#: Case families of :func:`iter_cases`.
FAMILIES = {"mixed": random_case, "gear": gear_like_case}


@dataclass
class Accepted:
    """An accepted random case with its exact reference."""

    case: RandomCase
    reference: ExactBranch
    index: int  # position in the random stream (accepted or not)


def iter_cases(seed: int, *, family: str = "mixed", max_special: int = 20, **reference_options):
    """Random cases of ``seed`` in order, each yielded as an :class:`Accepted` (unambiguous start,
    reference computed, at most ``max_special`` special points) or as a rejection
    (index, label, reason). ``reference_options`` go to :func:`exact_special_points` (e.g. a
    ``max_steps`` budget)."""
    rng = np.random.default_rng(seed)
    make = FAMILIES[family]
    i = 0
    while True:
        case = make(rng)
        i += 1
        starts = low_frequency_orbits(case.model, case.omega[0])
        if len(starts) != 1:
            other = sum(bool(np.isnan(x).any()) for x in starts)
            yield (i - 1, case.label, f"ambiguous start at Ω_min: {len(starts) - other} period-1 orbit(s) "
                   f"and {other} simulation(s) not settling on period 1")
            continue
        try:
            ref = exact_special_points(case.model, case.omega, **reference_options)
        except ReferenceError as exc:
            yield (i - 1, case.label, f"reference failed: {exc}")
            continue
        if ref.stats.get("guard_failures"):
            yield (i - 1, case.label, "hidden-pair guard could not subdivide near Ω = "
                   + ", ".join(f"{w:.6f}" for w in ref.stats["guard_failures"][:3]))
            continue
        if len(ref.special) > max_special:
            yield (i - 1, case.label, f"{len(ref.special)} special points (> {max_special})")
            continue
        yield Accepted(case, ref, i - 1)


def accepted_cases(seed: int, n: int, *, max_tries: int | None = None, **options
                   ) -> tuple[list[Accepted], list[tuple[int, str, str]]]:
    """The first ``n`` accepted cases of :func:`iter_cases` and the rejected ones before them
    (at most ``max_tries`` cases drawn, default 4n + 10)."""
    out: list[Accepted] = []
    rejected: list[tuple[int, str, str]] = []
    max_tries = 4 * n + 10 if max_tries is None else max_tries
    for item in iter_cases(seed, **options):
        if isinstance(item, Accepted):
            out.append(item)
        else:
            rejected.append(item)
        if len(out) >= n or len(out) + len(rejected) >= max_tries:
            break
    return out, rejected


def hb_special_points(frf) -> list[tuple[str, float]]:
    """(kind, Ω) of the special points on branch 0 of a FrequencyResponse."""
    return [(p.kind, float(p.omega)) for p in frf.special_points if p.branch == 0]


@dataclass
class Matching:
    """Exact points matched to HB points of the same kind within ``tol``: ``pairs`` (exact, HB),
    ``missed`` exact points, ``spurious`` HB points."""

    pairs: list[tuple[tuple[str, float], tuple[str, float]]]
    missed: list[tuple[str, float]]
    spurious: list[tuple[str, float]]

    @property
    def errors(self) -> list[float]:
        return [abs(e[1] - h[1]) for e, h in self.pairs]


def match(exact: list[tuple[str, float]], hb: list[tuple[str, float]], tol: float = 1e-4) -> Matching:
    """One-to-one matching, nearest first, same kind, |ΔΩ| ≤ ``tol``."""
    cand = sorted(
        (abs(e[1] - h[1]), i, j) for i, e in enumerate(exact) for j, h in enumerate(hb)
        if e[0] == h[0] and abs(e[1] - h[1]) <= tol
    )
    used_e: set[int] = set()
    used_h: set[int] = set()
    pairs = []
    for _, i, j in cand:
        if i in used_e or j in used_h:
            continue
        used_e.add(i)
        used_h.add(j)
        pairs.append((exact[i], hb[j]))
    missed = [e for i, e in enumerate(exact) if i not in used_e]
    spurious = [h for j, h in enumerate(hb) if j not in used_h]
    return Matching(pairs, missed, spurious)


def _hb_delta0(frf, rows: np.ndarray) -> np.ndarray:
    """δ(0) of HB rows from their Fourier coefficients [a_0, a_1 … a_H, b_1 … b_H]."""
    q = np.asarray(frf.coefficients)[rows]
    H = (q.shape[1] - 1) // 2
    return q[:, 0] + q[:, 1 : H + 1].sum(axis=1)


def _rows_table(frf, lo_row: int, hi_row: int, d0: dict[int, float]) -> list[str]:
    out = []
    for r in range(lo_row, hi_row + 1):
        mu = np.asarray(frf.multipliers[r])
        tr, det = float(np.sum(mu).real), float(np.prod(mu).real)
        out.append(f"      row {r}: Ω = {frf.omega[r]:.7f}  δ(0) = {d0.get(r, float('nan')):+.5f}  "
                   f"μ = {np.round(mu, 4)}  "
                   f"ψ_fold = {1 - tr + det:+.3e}  ψ_pd = {1 + tr + det:+.3e}  stable = {bool(frf.stable[r])}")
    return out


def diagnose(frf, point: tuple[str, float], exact: list[tuple[str, float]],
             states: list[np.ndarray] | None = None) -> str:
    """What the HB branch (branch 0) did at a special point it missed or made up.

    For an exact point: the HB continuation step whose Ω interval holds it — the pass of the
    branch nearest the exact orbit (its δ(0) from ``states``, parallel to ``exact``) when the
    branch passes that Ω several times — with the step ΔΩ, the rows around it (Ω, δ(0),
    multipliers, test functions, stability) and every exact point inside the same step. For an HB
    point with no exact counterpart: the rows around it."""
    kind, w = point
    rows = np.flatnonzero(np.asarray(frf.branch) == 0)
    first, last = int(rows[0]), int(rows[-1])
    om = np.asarray(frf.omega)[rows]
    d0 = dict(zip(rows.tolist(), _hb_delta0(frf, rows).tolist()))
    lines = [f"  {kind} at Ω = {w:.8f}:"]
    hb_pts = [p for p in frf.special_points if p.branch == 0]
    near = [p for p in hb_pts if abs(p.omega - w) < 5e-3]
    if near:
        lines.append("    HB special points within 5e-3: "
                     + ", ".join(f"{p.kind} {p.omega:.8f} (row {p.index})" for p in near))
    if point not in exact:  # a spurious HB point: show its rows
        for p in hb_pts:
            if p.kind == kind and float(p.omega) == w:
                lines += _rows_table(frf, max(first, p.index - 3), min(last, p.index + 3), d0)
        return "\n".join(lines)
    state = None if states is None else states[exact.index(point)]
    passes = []
    for i in range(len(rows) - 1):
        a, b = om[i], om[i + 1]
        if min(a, b) <= w <= max(a, b) and a != b:
            ia, ib = int(rows[i]), int(rows[i + 1])
            t = (w - a) / (b - a)
            passes.append((ia, ib, (1 - t) * d0[ia] + t * d0[ib]))
    if not passes:
        lines.append("    the HB branch never reaches this Ω")
        return "\n".join(lines)
    if state is not None:
        passes.sort(key=lambda p: abs(p[2] - state[0]))
        lines.append(f"    exact orbit δ(0) = {state[0]:+.5f}; the HB branch passes this Ω {len(passes)} time(s), "
                     "the pass nearest the exact orbit:")
        passes = passes[:1]
    for ia, ib, dd in passes:
        a, b = frf.omega[ia], frf.omega[ib]
        inside = [f"{k} {x:.6f}" for k, x in exact if min(a, b) <= x <= max(a, b)]
        lines.append(f"    HB step rows {ia}->{ib}: Ω {a:.6f} -> {b:.6f} (ΔΩ = {b - a:+.3e}, Δδ(0) = "
                     f"{d0[ib] - d0[ia]:+.3e}; δ(0) interpolated at Ω: {dd:+.5f}); exact points with Ω in this step "
                     f"(any pass): {inside}")
        lines += _rows_table(frf, max(first, ia - 2), min(last, ib + 2), d0)
    return "\n".join(lines)


__all__ = ["ExactBranch", "BranchPoint", "ReferenceError", "exact_special_points", "low_frequency_orbits",
           "check_g_omega", "KINDS", "RandomCase", "random_case", "Accepted", "accepted_cases", "iter_cases",
           "gear_like_case", "FAMILIES",
           "hb_special_points", "Matching", "match", "diagnose", "guard_and_locate", "branch_points_at"]
