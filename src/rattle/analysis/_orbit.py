"""periodic_orbit(): every harmonic-balance orbit at one forcing frequency, and the simulation.

How the coexisting solutions at Ω = W are found
-----------------------------------------------
1. **Primary branch.** The period-1 frequency response is followed over a range containing W
   (the given ``search_range``, widened to include W); every stretch of the branch whose end
   points bracket W gives a start (linear interpolation of the coefficients), which Newton
   polishes at exactly W. A branch that folds over W twice gives three solutions.
2. **Simulation.** Continuation from the linear solution never leaves the primary branch: for
   period N > 1 it would only find the primary motions written with base frequency Ω/N. So the
   steady state is also simulated (exact piecewise-linear integration, from ``x0``, default
   rest). When it settles on period n (1 ≤ n ≤ 8) its orbit is closed by exact shooting,
   sampled at N_s equally spaced points over n forcing periods, transformed to Fourier
   coefficients of base Ω/n and polished by Newton: the HB solution of period n that the
   simulation found. If N > 1 was asked for and the simulation from rest settled elsewhere, it
   is repeated from each unstable primary orbit, slightly perturbed.
3. **Sub-harmonic branch.** A period-n solution (n > 1) from step 2 is continued in Ω in both
   directions until the branch closes on itself (or one of its copies shifted by a forcing
   period) or leaves the range; every other crossing of W on it is polished too. This finds,
   e.g., the unstable sub-harmonic between two sub-harmonic folds.

Every solution is reduced to its least period (a period-2 series whose odd harmonics vanish is
a primary orbit) and polished again there; duplicates (the same orbit, also up to a shift by
whole forcing periods) are dropped. Floquet multipliers come from the exact monodromy of the
piecewise-linear linearisation about each orbit; measures from the series (see
``rattle.measures``).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .._typing import FloatArray
from .. import _limits, _validate
from .._validate import check_state
from ..continuation import ArclengthCorrector, BranchPoint, ContinuationOptions, ContinuationStepper
from ..errors import ConvergenceError
from ..hb import HarmonicBalance, HBOptions, NewtonOptions, resize_harmonics, solve_harmonic_balance
from ..measures import system_measures_batch
from ..model import Model, check_analysable_model
from ..results import FrequencyResponse, OrbitSolution, PeriodicOrbit, SteadyState
from ..stability import UNIT_CIRCLE_TOL, FloquetMonitor, stability_method
from ..timeint import ExactIntegrator, check_system_state, shoot_periodic_orbit, shoot_system_orbit
from ._frequency_response import check_range, frequency_response, refuse_hb_arguments
from ._settings import DEFAULT_HARMONICS, StabilityMethod, check_stability, resolve_hb
from ._steady import SteadyStateOptions, make_integrator, steady_state

logger = logging.getLogger("rattle")

#: Largest period (multiple of the forcing period) that is searched for, as in the sweep.
MAX_PERIOD = 8
# Simulations started next to unstable orbits, at most (besides the one from ``x0``).
_MAX_EXTRA_SIMULATIONS = 6

# Two solutions are the same orbit when their δ(t) differ by less than this fraction of the
# model's length scale everywhere (Newton converges to ~1e-10 of it; distinct coexisting orbits
# differ by far more, except arbitrarily close to a fold, where telling them apart is moot).
_SAME_ORBIT_TOL = 1e-6
# A series has a shorter period d | p when the harmonics that do not fit period d carry less
# than this fraction of its amplitude.
_REDUCE_TOL = 1e-7


def _check_period(period: object) -> int:
    return _limits.check_period(period)


def default_search_range(model: Model, omega: float) -> tuple[float, float]:
    """The range followed for the primary branch when none is given: 0.1 … 3 ω_n (ω_n = sqrt(K/I),
    the SPEC example range for K = I = 1), widened to reach from W/2 to 1.5 W."""
    wn = model.natural_frequency
    return (min(0.1 * wn, 0.5 * omega), max(3.0 * wn, 1.5 * omega))


# --------------------------------------------------------------------------------------------
# Series helpers
# --------------------------------------------------------------------------------------------


def _shift(q: FloatArray, fraction: float, n: int = 1) -> FloatArray:
    """Coefficients of δ(t + fraction·T_p), T_p the series' own period (n coordinate blocks)."""
    if n > 1:
        return np.concatenate([_shift(b, fraction) for b in q.reshape(n, -1)])
    H = (q.size - 1) // 2
    k = np.arange(1, H + 1)
    c, s = np.cos(2 * np.pi * k * fraction), np.sin(2 * np.pi * k * fraction)
    a, b = q[1 : H + 1], q[H + 1 :]
    out = q.copy()
    out[1 : H + 1] = a * c + b * s
    out[H + 1 :] = b * c - a * s
    return out


def _least_period(q: FloatArray, period: int, n: int = 1) -> int:
    """The least d dividing ``period`` for which the series (base Ω/period; n coordinate
    blocks) has period d·2π/Ω."""
    Qb = q.reshape(n, -1)
    H = (Qb.shape[1] - 1) // 2
    amp = np.sqrt(np.sum(Qb[:, 1 : H + 1] ** 2 + Qb[:, H + 1 :] ** 2, axis=0))
    total = float(np.sqrt(np.sum(amp**2)))
    if total == 0.0:
        return 1
    k = np.arange(1, H + 1)
    for d in range(1, period):
        if period % d:
            continue
        m = period // d
        if float(np.sqrt(np.sum(amp[k % m != 0] ** 2))) <= _REDUCE_TOL * total:
            return d
    return period


def _reduce(q: FloatArray, period: int, d: int, n: int = 1) -> FloatArray:
    """Series of base Ω/period with period d·2π/Ω, rewritten with base Ω/d (same H, zero-padded;
    n coordinate blocks)."""
    if n > 1:
        return np.concatenate([_reduce(b, period, d) for b in q.reshape(n, -1)])
    H = (q.size - 1) // 2
    m = period // d
    h = H // m
    out = np.zeros_like(q)
    out[0] = q[0]
    out[1 : h + 1] = q[m : h * m + 1 : m]
    out[H + 1 : H + 1 + h] = q[H + m : H + h * m + 1 : m]
    return out


@dataclass(slots=True)
class _Candidate:
    period: int
    q: FloatArray
    source: str
    iterations: int
    residual: float
    simulated: bool = False  # a simulation settled on this orbit


class _Solver:
    """HB problems per period at one Ω, Newton polish, reduction and de-duplication."""

    def __init__(self, model: Model, omega: float, hb: HBOptions, newton: NewtonOptions) -> None:
        self.model = model
        self.omega = omega
        self.options = hb
        self.harmonics = hb.harmonics
        self.samples = hb.samples
        self.newton = newton
        self._hb: dict[int, HarmonicBalance] = {}
        self.found: list[_Candidate] = []
        self.scale = model.length_scale()
        #: The System of a chain (None: the single equation) and its coordinate count.
        self.system = None if isinstance(model, Model) else model.system()
        self.n = 1 if self.system is None else self.system.n

    def hb(self, period: int) -> HarmonicBalance:
        if period not in self._hb:
            # H harmonics of Ω/period for every period: the same HBOptions throughout.
            self._hb[period] = HarmonicBalance(self.model, self.options, period=period)
        return self._hb[period]

    def polish(self, q0: FloatArray, period: int, source: str) -> _Candidate | None:
        """Newton at Ω from ``q0`` (base Ω/period), reduced to the least period; None on failure."""
        res = solve_harmonic_balance(self.hb(period), q0, self.omega, self.newton)
        if not res.converged:
            logger.info("periodic_orbit: Newton from a %s start failed at Ω = %g (%s)", source, self.omega, res.message)
            return None
        d = _least_period(res.q, period, self.n)
        if d < period:
            res = solve_harmonic_balance(self.hb(d), _reduce(res.q, period, d, self.n), self.omega, self.newton)
            if not res.converged:  # pragma: no cover - the reduced series is already a solution
                return None
            period = d
        return _Candidate(period, res.q, source, res.iterations, res.residual)

    def _samples(self, cand: _Candidate, periods: int, shift: int = 0) -> FloatArray:
        """δ of a candidate on 64 points per forcing period over ``periods`` forcing periods,
        time-shifted by ``shift`` forcing periods."""
        hb = self.hb(cand.period)
        Tf = 2 * np.pi / self.omega
        t = (np.arange(64 * periods) / 64.0 + shift) * Tf
        w = self.omega / cand.period
        return np.concatenate([hb.basis.evaluate(b, w, t) for b in cand.q.reshape(self.n, -1)])

    def same(self, a: _Candidate, b: _Candidate) -> bool:
        """True when a and b are the same orbit (also up to a shift by whole forcing periods)."""
        if a.period != b.period:
            return False  # both are reduced to their least period
        xa = self._samples(a, a.period)
        tol = _SAME_ORBIT_TOL * max(self.scale, float(np.ptp(xa)))
        return any(
            float(np.max(np.abs(xa - self._samples(b, b.period, k)))) <= tol for k in range(b.period)
        )

    def add(self, cand: _Candidate | None) -> bool:
        """Keep ``cand`` unless it duplicates one found before; True if it was new. A duplicate
        of a simulated candidate marks the one kept as simulated too."""
        if cand is None:
            return False
        for c in self.found:
            if self.same(cand, c):
                c.simulated = c.simulated or cand.simulated
                return False
        self.found.append(cand)
        return True


def _brackets(omega: FloatArray, W: float) -> list[tuple[int, float]]:
    """(i, s) for every stretch i → i+1 of a point sequence whose Ω brackets W, with the
    interpolation weight s ∈ [0, 1]."""
    out = []
    for i in range(omega.size - 1):
        a, b = omega[i] - W, omega[i + 1] - W
        if a * b <= 0.0 and not (a == 0.0 and b == 0.0):
            s = 0.0 if a == b else a / (a - b)
            out.append((i, float(min(max(s, 0.0), 1.0))))
    return out


# --------------------------------------------------------------------------------------------
# Simulation seeds
# --------------------------------------------------------------------------------------------
def _simulation_seed(solver: _Solver, steady: Any, integrator: ExactIntegrator | None = None) -> _Candidate | None:
    """HB solution of period n from a steady state that settled on period n (else None)."""
    n = int(getattr(steady, "period", 0) or 0)
    traj = getattr(steady, "trajectory", None)
    if not 1 <= n <= MAX_PERIOD or traj is None:
        return None
    if solver.harmonics < n * _forced_harmonics(solver.model):
        logger.info("periodic_orbit: %d harmonics cannot hold a period-%d orbit; not seeded", solver.harmonics, n)
        return None
    W = solver.omega
    Tf = 2 * np.pi / W
    # A state at a whole forcing period, so that t = 0 of the orbit has the model's forcing phase.
    ts = math.ceil(traj.t0 / Tf - 1e-9) * Tf
    if ts > traj.t1:
        ts = math.floor(traj.t1 / Tf + 1e-9) * Tf
        if ts < traj.t0:
            return None
    ts = min(max(ts, traj.t0), traj.t1)  # round-off may put ts just outside
    integ = make_integrator(solver.model) if integrator is None else integrator
    hb = solver.hb(n)
    t = hb.basis.times(n * Tf)
    if solver.system is None:
        state = traj.sample(ts)
        x_s = np.array([float(state.delta), float(state.velocity)])
        orbit = shoot_periodic_orbit(solver.model, W, x_s, period=n, integrator=integ)
        path = orbit.trajectory if orbit.converged else integ.propagate(x_s, 0.0, n * Tf, W)
        q0 = hb.basis.analyze(np.asarray(path.sample(t).delta))
    else:
        x, v = traj.derivatives(np.array(ts), 1)
        x_s = np.concatenate((x, v))
        orbit = shoot_system_orbit(solver.system, W, x_s, period=n, integrator=integ)
        path = orbit.trajectory if orbit.converged else integ.propagate(x_s, 0.0, n * Tf, W)
        q0 = hb.basis.analyze(path.derivatives(t, 0)[0].T).reshape(-1)  # coordinate-major blocks
    cand = solver.polish(q0, n, "simulation")
    if cand is None and orbit.converged:
        # The simulated motion is a solution whatever Newton on the truncated series does: keep
        # the exact (shooting) orbit's series, with its HB residual for what it is worth.
        R, _, _ = hb.residual_jacobian(q0, W)
        residual = float(np.max(np.abs(R))) / hb.force_scale
        logger.info("periodic_orbit: the simulated period-%d orbit kept unpolished (HB residual %.3g)", n, residual)
        cand = _Candidate(n, q0, "simulation", 0, residual)
    if cand is not None:
        cand.simulated = True
    return cand


def _unstable_not_saddle(mu: np.ndarray) -> bool:
    """A multiplier outside the unit circle that is not a real μ > 1 (a period doubling, μ < −1,
    or a complex pair, Neimark–Sacker): motion nearby may settle on another periodic orbit (of
    doubled period, say) rather than on a coexisting orbit already known."""
    big = mu[np.abs(mu) > 1.0 + UNIT_CIRCLE_TOL]
    return bool(np.any((big.real < 0) | (np.abs(big.imag) > 1e-12)))


def _follow_subharmonic(
    solver: _Solver,
    seed: _Candidate,
    search_range: tuple[float, float],
    continuation: ContinuationOptions,
) -> None:
    """Continue the branch through ``seed`` (period > 1) both ways; polish its other crossings of W."""
    hb = solver.hb(seed.period)
    W = solver.omega
    corrector = ArclengthCorrector(hb, solver.newton)
    _, Rq, Rw = hb.residual_jacobian(seed.q, W)
    closed = False
    for sign in (1.0, -1.0):
        reference = np.zeros(hb.size + 1)
        reference[-1] = sign
        tangent = corrector.tangent(Rq, Rw, reference)
        if tangent is None:
            return
        prev: list[BranchPoint] = []

        def stop(pt: BranchPoint) -> str | None:
            nonlocal closed
            prev.append(pt)
            if len(prev) < 3:  # the first stretch starts on W itself
                return None
            p0, p1 = prev[-2], prev[-1]
            for _, s in _brackets(np.array([p0.omega, p1.omega]), W):
                cand = solver.polish((1 - s) * p0.q + s * p1.q, seed.period, "subharmonic_branch")
                if cand is None:
                    continue
                if solver.same(cand, seed):
                    closed = True
                    return "the sub-harmonic branch closed on itself"
                solver.add(cand)
            return None

        stepper = ContinuationStepper(
            hb, seed.q, W, search_range, continuation, solver.newton, tangent=tangent, stop=stop,
            monitor=FloquetMonitor(hb),
        )
        stepper.run()
        logger.info(
            "periodic_orbit: sub-harmonic branch (period %d) %s after %d points: %s",
            seed.period, "+Ω" if sign > 0 else "−Ω", len(stepper.points), stepper.message,
        )
        if closed:
            return


# --------------------------------------------------------------------------------------------
# Front end
# --------------------------------------------------------------------------------------------
@_validate.numerical_failures
def periodic_orbit(
    model: Model,
    omega: float,
    period: int = 1,
    harmonics: int = DEFAULT_HARMONICS,
    *,
    hb: HBOptions | None = None,
    stability: StabilityMethod = "monodromy",
    simulate: bool = True,
    search_range: tuple[float, float] | None = None,
    frf: FrequencyResponse | None = None,
    x0: FloatArray | tuple[float, float] | None = None,
    samples: int | None = None,
    newton: NewtonOptions | None = None,
    continuation: ContinuationOptions | None = None,
    steady_options: SteadyStateOptions | None = None,
    options: Any = None,
) -> PeriodicOrbit | Any:
    """Every harmonic-balance periodic orbit at the forcing frequency ``omega``, with stability;
    for a law with torque jumps or friction, every exact orbit.

    A law with jumps or friction (a single-equation :class:`~rattle.model.System` with a
    discontinuous law, a :class:`~rattle.model.System` with its elements' whole laws, or a
    :class:`~rattle.model.Chain` with friction or jumps on an element, solved on its
    ``friction_system()``) is the same door as :func:`frequency_response`: its orbits are found by
    :func:`rattle.analysis.nonsmooth_orbit` (exact shooting; every orbit at Ω, stable and
    unstable, of every period, and the non-periodic attractors), ``options`` its
    :class:`~rattle.analysis.RegularisationOptions` (the HB beside the exact orbit), ``x0`` and
    ``period`` apply, and the harmonic-balance arguments must be left at their defaults.

    See the module docstring for how the coexisting solutions are found (primary branch through
    Ω, simulation seed, sub-harmonic branch).

    Parameters
    ----------
    model : Model or Chain
        A chain's solutions carry its n coordinate blocks (``coefficients``), the measures of
        every element (``OrbitSolution.elements``; the flat fields the first element's) and
        its 2n multipliers.
    omega : float
        Forcing frequency Ω (rad/s), finite and > 0.
    period : int, default 1
        The period asked for, as a multiple 1 … 8 of the forcing period 2π/Ω (n: a 1/n
        sub-harmonic). Solutions of other periods that turn up (the primary orbits, or the
        period the simulation settles on) are returned too, after those of this period.
    harmonics : int, default 32
        Harmonics H of each solution's base frequency Ω/period kept in the harmonic balance.
    simulate : bool, default True
        Also simulate the steady state (needed to find sub-harmonics). Without it only the
        primary (period-1) orbits are found.
    search_range : (float, float), optional
        Frequency range (rad/s) over which the primary branch (and a sub-harmonic branch) is
        followed; widened to include ``omega``. Default :func:`default_search_range`.
    frf : FrequencyResponse, optional
        An already computed period-1 frequency response through (or near) Ω to take the
        primary branch from, instead of computing it.
    x0 : (float, float), optional
        Initial state (δ, δ') of the simulation (rad, rad/s), (x, x') (2n numbers) for a chain;
        default rest (zeros).
    samples : int, optional
        AFT samples per solution period (default :func:`rattle.hb.default_samples`).
    hb : HBOptions, optional
        ``harmonics`` and ``samples`` in one object (not together with a ``harmonics`` or
        ``samples`` that disagrees with it).
    stability : {"monodromy", "hill"}, default "monodromy"
        How the Floquet multipliers are computed (as in :func:`frequency_response`).
    newton, continuation : NewtonOptions, ContinuationOptions, optional
        Corrector and continuation settings. These, the HB options and ``stability`` are used
        unchanged by every sub-problem: the primary branch, the Newton polish at Ω and the
        sub-harmonic branches.
    steady_options : SteadyStateOptions, optional
        Settling tolerance and budget of the simulation.

    Returns
    -------
    PeriodicOrbit
        ``solutions`` (each with period, coefficients, stability, multipliers and measures), the
        ``simulation`` (a ``SteadyState``, or None) and the ``selected`` solution.

    Raises
    ------
    ValueError, TypeError
        Bad arguments (the message names the argument).
    ConvergenceError
        If no periodic solution could be found at all.
    """
    if getattr(model, "discontinuous", False):  # a law with jumps or friction: the exact orbits
        refuse_hb_arguments((
            ("harmonics", harmonics, DEFAULT_HARMONICS), ("hb", hb, None), ("stability", stability, "monodromy"),
            ("simulate", simulate, True), ("search_range", search_range, None), ("frf", frf, None),
            ("samples", samples, None), ("newton", newton, None), ("continuation", continuation, None),
            ("steady_options", steady_options, None)),
            "its orbits are exact, and `options` (RegularisationOptions(harmonics=…, regularisation=…)) sets the "
            "harmonic balance beside them")
        from ..model import Chain
        from ._nonsmooth_orbit import nonsmooth_orbit

        system = model.friction_system() if isinstance(model, Chain) else model
        return nonsmooth_orbit(system, omega, options, x0=x0, period=period)
    if options is not None:
        raise TypeError(f"`options` sets the harmonic balance of a law with jumps or friction; this law is continuous "
                        f"(`harmonics`, `hb`, …), so leave `options` None, got {options!r}")
    # Argument checks: the rules of rattle._limits / rattle._validate, shared with the file.
    check_analysable_model(model)
    W = _limits.check_frequency(model, omega, simulate=False)
    period = _check_period(period)
    _limits.check_hb_settings(harmonics, samples, hb)
    hb_opts = resolve_hb(harmonics, samples, hb)  # validates `harmonics` and `samples`
    harmonics = hb_opts.harmonics
    stability = check_stability(stability)
    forced = _forced_harmonics(model)
    if harmonics < forced * period:
        raise ValueError(
            f"`harmonics` must be >= {forced * period} to hold the excitation's harmonic {forced} at "
            f"`period` {period} (harmonics count multiples of Ω/period), got {harmonics}"
        )
    simulate = _validate.check_bool(simulate, "simulate")
    if simulate:
        _limits.check_frequency(model, W, simulate=True)
    if frf is not None and not isinstance(frf, FrequencyResponse):
        raise TypeError(f"`frf` must be a FrequencyResponse or None, got {type(frf).__name__}")
    if newton is not None and not isinstance(newton, NewtonOptions):
        raise TypeError(f"`newton` must be a NewtonOptions, got {newton!r}")
    if continuation is not None and not isinstance(continuation, ContinuationOptions):
        raise TypeError(f"`continuation` must be a ContinuationOptions, got {continuation!r}")
    if steady_options is not None and not isinstance(steady_options, SteadyStateOptions):
        raise TypeError(f"`steady_options` must be a SteadyStateOptions, got {steady_options!r}")
    if search_range is None:
        lo, hi = default_search_range(model, W)
        # Within the frequency bounds relative to the model (W itself is within them).
        ws = _limits.stiffest_frequency(model)
        lo, hi = max(lo, _limits.MIN_OMEGA_RATIO * ws), min(hi, _limits.MAX_OMEGA_RATIO * ws)
    else:
        lo, hi = _limits.check_frequency_range(model, *check_range(search_range, "search_range"),
                                               ("search_range", "search_range"))
    lo, hi = min(lo, W), max(hi, W)
    dim = 2 if isinstance(model, Model) else 2 * model.system().n
    if x0 is None:
        start_state = np.zeros(dim)
    elif dim == 2:
        start_state = check_state(x0)
    else:
        start_state = check_system_state(x0, dim // 2, "x0")
    newton_opts = newton or NewtonOptions()
    cont_opts = continuation or ContinuationOptions()
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    solver = _Solver(model, W, hb_opts, newton_opts)

    # 1. Primary branch through W.
    primary = frf
    if primary is None:
        primary = frequency_response(model, omega=(lo, hi), hb=hb_opts, newton=newton_opts, continuation=cont_opts,
                                     stability=stability, throw=False, confirm_tori=False)
    for b in np.unique(primary.branch):
        sel = np.nonzero(primary.branch == b)[0]
        p_branch = int(primary.period[sel[0]])
        Q = primary.coefficients[sel]
        for i, s in _brackets(primary.omega[sel], W):
            q_start = _resized(solver, (1 - s) * Q[i] + s * Q[i + 1], p_branch, harmonics)
            solver.add(solver.polish(q_start, p_branch, "continuation"))
    t1 = time.perf_counter()
    timings["primary"] = t1 - t0

    # 2. Simulation (and 3. the sub-harmonic branches of its sub-harmonics).
    steady = None
    extra_runs: list[dict[str, Any]] = []  # simulations started next to unstable orbits
    if simulate:
        integ = make_integrator(model)
        runs_done = 0

        def simulate_from(x: FloatArray) -> SteadyState:
            nonlocal runs_done
            runs_done += 1
            return steady_state(model, W, x, options=steady_options, integrator=integ)

        def take(run: SteadyState) -> None:
            seed = _simulation_seed(solver, run, integ)
            if seed is None:
                return
            new = solver.add(seed)
            if new and seed.period > 1:
                _follow_subharmonic(solver, seed, (lo, hi), cont_opts)

        t_sim = 0.0
        ts = time.perf_counter()
        steady = simulate_from(start_state)
        t_sim += time.perf_counter() - ts
        take(steady)
        # From next to each orbit that is unstable by a period doubling or a complex pair: the
        # motion there may settle on an orbit no branch reached (a sub-harmonic, most often).
        # When a period was asked for and not yet found, next to every unstable orbit.
        tried: list[_Candidate] = []
        while runs_done <= _MAX_EXTRA_SIMULATIONS:
            sols = _assembled(model, solver, solver.found, stability)
            want_period = period > 1 and not any(c.period == period for c in solver.found)
            todo = [c for c, sol in zip(solver.found, sols)
                    if not sol.stable and all(c is not t for t in tried)
                    and (want_period and c.period == 1 or _unstable_not_saddle(sol.multipliers))]
            if not todo:
                break
            cand = todo[0]
            tried.append(cand)
            x_start = _state_at_zero(solver, cand)
            x_start[0] += 1e-3 * solver.scale
            ts = time.perf_counter()
            run = simulate_from(x_start)
            t_sim += time.perf_counter() - ts
            q1 = cand.q.reshape(solver.n, -1)[0]
            extra_runs.append({"from_period": cand.period, "from_rms": float(np.sqrt(q1[0] ** 2 + 0.5 * np.sum(q1[1:] ** 2))),
                               "period": int(getattr(run, "period", 0) or 0)})
            take(run)
        timings["simulation"] = t_sim
        timings["subharmonics"] = time.perf_counter() - t1 - t_sim

    if not solver.found:
        raise ConvergenceError(
            f"no periodic solution found at Ω = {W:g}: the primary branch over {lo:g} … {hi:g} rad/s "
            "does not reach it and the simulation gave no start"
        )
    solutions = _assembled(model, solver, solver.found, stability)
    order = sorted(range(len(solutions)), key=lambda i: (solutions[i].period != period, solutions[i].period, -solutions[i].rms))
    timings["total"] = time.perf_counter() - t0
    return PeriodicOrbit(
        model=model,
        omega=W,
        period=period,
        harmonics=harmonics,
        solutions=tuple(solutions[i] for i in order),
        simulation=steady,
        settings={
            "omega": W, "period": period, "harmonics": harmonics, "simulate": simulate,
            "search_range": [lo, hi], "x0": start_state.tolist(),
            "samples": {p: hb.basis.samples for p, hb in solver._hb.items()},
            "samples_given": hb_opts.samples, "stability": stability.name,
            "newton": asdict(newton_opts), "continuation": asdict(cont_opts),
            "primary_branch_status": primary.status.name.lower(),
            "extra_simulations": extra_runs,
            "primary_branch_settings": {k: primary.settings.get(k) for k in (
                "harmonics", "samples", "stability", "newton", "continuation") if k in primary.settings},
        },
        timings=timings,
    )


def _forced_harmonics(model: Any) -> int:
    """The highest forcing harmonic of a Model or a Chain."""
    if isinstance(model, Model):
        return len(model.excitation.amplitudes)
    return int(model.forced_harmonics)


def _resized(solver: _Solver, q: FloatArray, period: int, harmonics: int) -> FloatArray:
    """``q`` (any H) with ``harmonics`` harmonics, block-wise for a chain."""
    if solver.n == 1:
        return resize_harmonics(q, harmonics)
    return np.concatenate([resize_harmonics(b, harmonics) for b in q.reshape(solver.n, -1)])


def _state_at_zero(solver: _Solver, cand: _Candidate) -> FloatArray:
    """(x(0), x'(0)) of a candidate: (δ, δ') for the single equation, (x, x') (2n,) for a chain."""
    basis = solver.hb(cand.period).basis
    w = solver.omega / cand.period
    blocks = cand.q.reshape(solver.n, -1)
    x = [float(basis.evaluate(b, w, 0.0)) for b in blocks]
    v = [float(basis.evaluate(b, w, 0.0, derivative=1)) for b in blocks]
    return np.array(x + v)


def _assembled(model: Model, solver: _Solver, cands: list[_Candidate],
               stability: StabilityMethod = "monodromy") -> list[OrbitSolution]:
    """Floquet multipliers (the stability method's: the exact monodromy of the linearisation
    about each orbit, or Hill's method; 2n per orbit) and the SPEC measures of each candidate,
    batched per period. The flat fields are the first element's; a chain also gets every
    element's measures in ``elements``."""
    method = stability_method(stability)
    out: list[OrbitSolution | None] = [None] * len(cands)
    names = tuple(e.name for e in solver.system.elements) if solver.system is not None else ()
    for p in sorted({c.period for c in cands}):
        idx = [i for i, c in enumerate(cands) if c.period == p]
        hb = solver.hb(p)
        Q = np.array([cands[i].q for i in idx])
        P = len(idx)
        w = np.full(P, solver.omega / p)
        Om = np.full(P, solver.omega)
        mu = method.multipliers(hb, Q, Om)
        stable = np.max(np.abs(mu), axis=1) < 1.0 - UNIT_CIRCLE_TOL
        per_element = system_measures_batch(model, Q.reshape(P, hb.size // hb.basis.size, -1), w, Om,
                                            hb.basis.samples)
        meas = per_element[0]
        for j, i in enumerate(idx):
            elements = {
                name: {k: (str(getattr(m, k)[j]) if k == "regime" else float(getattr(m, k)[j])) for k in
                       ("mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max", "regime")}
                for name, m in zip(names, per_element)
            }
            out[i] = OrbitSolution(
                omega=solver.omega, period=p, coefficients=Q[j].copy(),
                stable=bool(stable[j]), multipliers=mu[j].copy(),
                mean=float(meas.mean[j]), rms=float(meas.rms[j]), rms_ac=float(meas.rms_ac[j]),
                p2p=float(meas.p2p[j]), acc_p2p=float(meas.acc_p2p[j]),
                delta_min=float(meas.delta_min[j]), delta_max=float(meas.delta_max[j]),
                regime=str(meas.regime[j]), source=cands[i].source,
                iterations=int(cands[i].iterations), residual=float(cands[i].residual),
                simulated=bool(cands[i].simulated), elements=elements,
            )
    return [s for s in out if s is not None]


__all__ = ["periodic_orbit", "default_search_range", "MAX_PERIOD"]
