"""compare(): the harmonic-balance frequency response against the time-domain sweep.

The frequency response (every solution along the branch, stable or not) and the up/down
stepped sweep (what a rig would measure) are computed over the same range. Where the FRF is
multi-valued the two sweeps land on different branches and jump at different frequencies;
where the primary orbit is unstable the sweep shows sub-harmonic or non-periodic motion. A few
frequencies are then examined in detail: every HB orbit there (:func:`periodic_orbit`) next to
the steady states that the up and the down sweep reached.

Frequencies picked automatically (``at=None``), at most one per rule, on the sweep's grid:

1. **multi-valued** — among the grid frequencies where the FRF has three or more solutions,
   the one where the up and down sweeps differ most in rms (if they differ by more than 5 %
   of the largest rms; else the middle of the widest multi-valued stretch);
2. **sub-harmonic** — the middle of the longest run of sweep points (either direction) with a
   period 2 … 8; if there is none, the middle of the longest run with period 0 (no period up
   to 8 found);
3. **largest rattle** — only when fewer than two were found above: the frequency of the
   largest stable motion about the mean (rms_ac) among the FRF's rows that impact (the grid
   point nearest to it); where no stable row impacts, **resonance**: the largest stable rms_ac.
   Not the largest rms: that holds the mean twist, which a drag growing with speed makes
   largest at the end of the range whether or not anything rattles there.

A discontinuous law (single-equation :class:`~rattle.model.System`: jumps and Coulomb friction) or a
chain with friction on its elements (:class:`~rattle.model.System` with its elements' whole laws): the frequency
response is the regularised harmonic balance checked row by row by exact shooting
(:func:`nonsmooth_response`), the sweep runs on the exact event-driven integrator, and the two are
set side by side without detailed orbits (``at`` is refused): every settled period-1 row of the
sweep against the response's exact rms at its frequency (:meth:`Comparison.agreement`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from numbers import Real
from dataclasses import replace

import numpy as np

from .. import _limits, _validate
from ..continuation import ContinuationOptions
from ..hb import HBOptions, NewtonOptions
from ..model import Model, System, check_analysable_model
from ..results import Comparison, FrequencyResponse, PeriodicOrbit, SteadyState, SweepResult
from ._frequency_response import frequency_response
from ._frequency_response import check_range
from ._orbit import MAX_PERIOD, periodic_orbit
from ._regimes import confirm_with_sweep
from ._settings import DEFAULT_HARMONICS, RunSettings, StabilityMethod, resolve_hb
from ._steady import SteadyStateOptions, make_integrator, steady_state
from ._regularisation import RegularisationOptions
from ._time_sweep import _Bounds, time_sweep

#: Automatic picks: the up/down sweeps must differ by this fraction of the largest rms for the
#: multi-valued pick to go where they differ most.
_HYSTERESIS_MIN = 0.05


# --------------------------------------------------------------------------------------------
# Picking frequencies
# --------------------------------------------------------------------------------------------
def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    return list(zip(np.nonzero(edges == 1)[0].tolist(), np.nonzero(edges == -1)[0].tolist()))


def _solution_counts(frf: FrequencyResponse, grid: np.ndarray) -> np.ndarray:
    """How many FRF solutions (all branches) each grid frequency has."""
    counts = np.zeros(grid.size, dtype=int)
    for b in np.unique(frf.branch):
        om = frf.omega[frf.branch == b]
        if om.size < 2:
            continue
        lo, hi = np.minimum(om[:-1], om[1:]), np.maximum(om[:-1], om[1:])
        # half-open stretches, so that a point shared by two stretches counts once
        counts += np.sum((grid[:, None] >= lo[None, :]) & (grid[:, None] < hi[None, :]), axis=1)
    return counts


def pick_frequencies(frf: FrequencyResponse, sweep: SweepResult) -> list[tuple[float, str]]:
    """Frequencies worth a closer look, with the reason (rules in the module docstring)."""
    picks: list[tuple[float, str]] = []
    up = sweep.select("up") if "up" in sweep.directions else None
    down = sweep.select("down") if "down" in sweep.directions else None
    grid = np.unique(sweep.omega)
    # 1. multi-valued region
    multi = _solution_counts(frf, grid) >= 3
    if np.any(multi) and up is not None and down is not None:
        r_up = np.interp(grid, up.omega, up.rms)
        r_down = np.interp(grid, down.omega[::-1], down.rms[::-1])
        diff = np.where(multi, np.abs(r_up - r_down), -1.0)
        diff = np.where(np.isfinite(diff), diff, -1.0)  # next to a failed sweep row (rms nan): no difference known
        i = int(np.argmax(diff))
        top = float(np.nanmax(sweep.rms)) if np.any(np.isfinite(sweep.rms)) else math.inf
        if diff[i] > _HYSTERESIS_MIN * top:
            picks.append((float(grid[i]), "multi-valued"))
        else:
            i0, i1 = max(_runs(multi), key=lambda r: r[1] - r[0])
            picks.append((float(grid[(i0 + i1 - 1) // 2]), "multi-valued"))
    elif np.any(multi):
        i0, i1 = max(_runs(multi), key=lambda r: r[1] - r[0])
        picks.append((float(grid[(i0 + i1 - 1) // 2]), "multi-valued"))
    # 2. sub-harmonic (else non-periodic) motion in the sweep
    for wanted, reason in ((lambda p: p >= 2, "sub-harmonic"), (lambda p: p == 0, "non-periodic")):
        best: tuple[int, float] | None = None
        for part in (up, down):
            if part is None:
                continue
            for i0, i1 in _runs(np.array([wanted(int(p)) for p in part.period], dtype=bool)):
                if best is None or i1 - i0 > best[0]:
                    best = (i1 - i0, float(part.omega[(i0 + i1 - 1) // 2]))
        if best is not None:
            picks.append((best[1], reason))
            break
    # 3. the largest stable rattle (else resonance), when little else is of interest
    if len(picks) < 2 and np.any(frf.stable):
        i, reason = _largest_rattle(frf)
        w = float(grid[int(np.argmin(np.abs(grid - frf.omega[i])))])
        if all(abs(w - p[0]) > 1e-12 for p in picks):
            picks.append((w, reason))
    return sorted(picks)


#: The regimes in which an orbit crosses a breakpoint (it rattles).
_IMPACTING = ("single_sided", "double_sided")


def _largest_rattle(frf: FrequencyResponse) -> tuple[int, str]:
    """The row of the largest stable motion about the mean (``rms_ac``, not ``rms``: the rms
    holds the mean twist, which a drag growing with speed makes largest at the range's end
    whether or not anything rattles there) among the stable rows that impact — ``largest
    rattle`` — or, where no stable row impacts, among the stable rows — ``resonance``. A chain:
    an impact of any element counts, and the motion is the largest of its elements' rms_ac."""
    names = tuple(getattr(frf, "element_names", ()) or ())
    cols = getattr(frf, "element_columns", {}) or {}
    if names:
        motion = np.max([np.asarray(cols[f"{n}_rms_ac"], dtype=float) for n in names], axis=0)
        impact = np.any([np.isin(np.asarray(cols[f"{n}_regime"]).astype(str), _IMPACTING) for n in names], axis=0)
    else:
        motion = np.asarray(frf.rms_ac, dtype=float)
        impact = np.isin(np.asarray(frf.regime).astype(str), _IMPACTING)
    stable = np.asarray(frf.stable, dtype=bool)
    rattle = stable & impact & np.isfinite(motion)
    rows = rattle if np.any(rattle) else stable
    i = int(np.argmax(np.where(rows & np.isfinite(motion), motion, -np.inf)))
    return i, "largest rattle" if np.any(rattle) else "resonance"


def _check_at(at: object, lo: float, hi: float) -> list[float]:
    if isinstance(at, (str, bytes)) or not isinstance(at, Sequence | np.ndarray):
        raise TypeError(f"`at` must be a sequence of frequencies in rad/s, got {at!r}")
    out = []
    for w in at:  # type: ignore[union-attr]
        if _validate._is_bool(w) or not isinstance(w, Real):
            raise TypeError(f"`at` must hold numbers (rad/s), got {w!r} ({type(w).__name__})")
        try:
            x = float(w)
        except OverflowError:
            x = math.inf
        if not (math.isfinite(x) and lo <= x <= hi):
            raise ValueError(
                f"`at` frequencies must be finite and within the range {lo:g} … {hi:g} rad/s, got {w!r}"
            )
        out.append(x)
    if not out:
        raise ValueError("`at` must hold at least one frequency (or be None to pick them automatically)")
    if len(out) > _limits.MAX_DETAIL_FREQUENCIES:
        raise ValueError(
            f"`at` must hold at most {_limits.MAX_DETAIL_FREQUENCIES} frequencies, got {len(out)}: each one is "
            "a periodic-orbit search with simulations (seconds each); use `time_sweep` for many frequencies"
        )
    return sorted(out)


# --------------------------------------------------------------------------------------------
# Front end
# --------------------------------------------------------------------------------------------
@_validate.numerical_failures
def compare(
    model: Model,
    omega: tuple[float, float] = (0.1, 3.0),
    harmonics: int = DEFAULT_HARMONICS,
    points: int = 200,
    at: Sequence[float] | None = None,
    *,
    samples: int | None = None,
    hb: HBOptions | None = None,
    newton: NewtonOptions | None = None,
    continuation: ContinuationOptions | None = None,
    stability: StabilityMethod = "monodromy",
    options: SteadyStateOptions | None = None,
    workers: int = 1,
    callback: Callable[[int, int], None] | None = None,
    regularisation: RegularisationOptions | None = None,
) -> Comparison:
    """Frequency response and time-domain sweep over ``omega``, with orbits at a few frequencies.

    Parameters
    ----------
    model : Model, Chain or System (continuous, or with its whole laws: the single equation's or a chain's)
        A discontinuous law (the last two): the regularised harmonic balance checked by exact
        shooting (:func:`nonsmooth_response` with ``regularisation``) against the exact sweep,
        without detailed orbits (``at`` must be None; ``harmonics`` is then
        ``regularisation.harmonics``).
    omega : (float, float), default (0.1, 3.0)
        Frequency range (rad/s).
    harmonics : int, default 32
        Harmonics of the harmonic balance.
    points : int, default 200
        Frequencies per sweep direction (≥ 2).
    at : sequence of float, optional
        Frequencies (rad/s, within ``omega``) to examine in detail; default: picked by the rules
        in the module docstring.
    samples, hb, newton, continuation, stability
        Harmonic-balance, corrector and continuation settings and the stability method, as in
        :func:`frequency_response`; used unchanged by the frequency response and by every
        orbit examined.
    options : SteadyStateOptions, optional
        Settling settings of the simulations.
    workers : int, default 1
        Processes for the sweep (2: the up and down sweeps at once).
    callback : callable, optional
        ``callback(done, total)`` after each sweep frequency (for a progress bar).
    regularisation : RegularisationOptions, optional
        A discontinuous law's harmonic-balance settings (default those of
        :func:`nonsmooth_response`); refused for a continuous model.

    Returns
    -------
    Comparison
    """
    if isinstance(model, System) and model.discontinuous:
        if samples is not None or hb is not None or stability != "monodromy":
            raise ValueError("`samples`, `hb` and `stability` do not apply to a discontinuous law: give its "
                             "harmonic-balance settings as `regularisation` (RegularisationOptions)")
        if harmonics != DEFAULT_HARMONICS and regularisation is None:
            raise ValueError(f"`harmonics` = {harmonics!r}: give a discontinuous law's harmonics in `regularisation` "
                             "(RegularisationOptions(harmonics=...))")
        return _compare_discontinuous(model, omega, points, at, regularisation, newton, continuation, options,
                                      workers, callback)
    if regularisation is not None:
        raise ValueError("`regularisation` applies only to a discontinuous law (a System with its whole laws)")
    # Argument checks: the rules of rattle._limits / rattle._validate, shared with the file
    # (all of them before the frequency response, so that a bad `points` is not found after it).
    check_analysable_model(model)
    lo, hi = _limits.check_frequency_range(model, *check_range(omega), simulate=True)
    _limits.check_hb_settings(harmonics, samples, hb)
    _limits.check_points(points)
    _limits.check_workers(workers)
    _validate.check_instance(options, "options", SteadyStateOptions, "a SteadyStateOptions")
    _limits.check_callback(callback)
    chosen = None if at is None else _check_at(at, lo, hi)
    run = RunSettings.make(resolve_hb(harmonics, samples, hb), newton, continuation, stability)
    t0 = time.perf_counter()
    frf = frequency_response(model, omega=(lo, hi), hb=run.hb, newton=run.newton, continuation=run.continuation,
                             stability=run.stability, throw=False)
    t1 = time.perf_counter()
    sweep = time_sweep(model, omega=(lo, hi), points=points, direction="both", options=options,
                       workers=workers, callback=callback)
    t2 = time.perf_counter()
    # What the sweep saw in each region (a stretch without a stable computed orbit is labelled
    # by the periods the simulation found there).
    frf = replace(frf, regions=confirm_with_sweep(frf.regions, sweep))
    picks = pick_frequencies(frf, sweep) if chosen is None else [(w, "requested") for w in chosen]
    integ = make_integrator(model)
    grid = np.unique(sweep.omega)
    spacing = float(np.min(np.diff(grid))) if grid.size > 1 else math.inf
    orbits: list[PeriodicOrbit] = []
    sims: list[dict[str, SteadyState]] = []
    for w, _why in picks:
        states: dict[str, SteadyState] = {}
        for d in sweep.directions:
            part = sweep.select(d)
            i = int(np.argmin(np.abs(part.omega - w)))
            if abs(part.omega[i] - w) <= 0.5 * spacing * (1 + 1e-9) and np.all(np.isfinite(part.state0[i])):
                # (a failed sweep row has no state to start from)
                states[d] = steady_state(model, w, part.state0[i], options=options, integrator=integ)
        sweep_periods = [s.period for s in states.values() if 2 <= s.period <= MAX_PERIOD]
        period = sweep_periods[0] if sweep_periods else 1
        x0 = None
        for s in states.values():
            if s.period == period:
                x0 = s.state0
                break
        orbits.append(periodic_orbit(
            model, w, period=period, hb=run.hb, newton=run.newton, continuation=run.continuation,
            stability=run.stability, frf=frf, search_range=(lo, hi), x0=x0, steady_options=options,
        ))
        sims.append(states)
    t3 = time.perf_counter()
    return Comparison(
        model=model, frf=frf, sweep=sweep,
        at=tuple(w for w, _ in picks), reasons=tuple(r for _, r in picks),
        orbits=tuple(orbits), simulations=tuple(sims),
        settings={"omega": [lo, hi], **run.record(), "points": points,
                  "at": None if at is None else list(chosen or []), "workers": workers},
        timings={"frequency_response": t1 - t0, "sweep": t2 - t1, "orbits": t3 - t2, "total": t3 - t0},
    )


def _compare_discontinuous(
    model: System, omega: tuple[float, float], points: int, at: Sequence[float] | None,
    regularisation: RegularisationOptions | None, newton: NewtonOptions | None,
    continuation: ContinuationOptions | None, options: SteadyStateOptions | None, workers: int,
    callback: Callable[[int, int], None] | None,
) -> Comparison:
    """:func:`compare` on a discontinuous law: its response and its exact sweep, side by side."""
    from ._exact_branch import ShootingOptions
    from ._nonsmooth import method_settings, nonsmooth_response

    lo, hi = _limits.check_frequency_range(_Bounds(model), *check_range(omega), simulate=True)
    _limits.check_points(points)
    _limits.check_workers(workers)
    _validate.check_instance(options, "options", SteadyStateOptions, "a SteadyStateOptions")
    _validate.check_instance(regularisation, "regularisation", RegularisationOptions, "a RegularisationOptions")
    _limits.check_callback(callback)
    if at is not None:
        raise ValueError("`at` is not supported for a discontinuous law: its comparison has no detailed orbits "
                         "(use nonsmooth_orbit at a frequency); leave `at` None")
    t0 = time.perf_counter()
    check = nonsmooth_response(model, (lo, hi), regularisation, continuation=continuation, newton=newton)
    t1 = time.perf_counter()
    frf = FrequencyResponse.from_check(
        check, model=model, timings={"frequency_response": t1 - t0},
        settings={**method_settings(regularisation or ShootingOptions(), not model.is_single_equation),
                  "subharmonics": False})
    sweep = time_sweep(model, omega=(lo, hi), points=points, direction="both", options=options,
                       workers=workers, callback=callback)
    t2 = time.perf_counter()
    return Comparison(
        model=model, frf=frf, sweep=sweep, at=(), reasons=(), orbits=(), simulations=(),  # type: ignore[arg-type]
        settings={"omega": [lo, hi], "harmonics": check.harmonics, "regularisation": check.regularisation,
                  "points": points, "at": None, "workers": workers},
        timings={"frequency_response": t1 - t0, "sweep": t2 - t1, "total": t2 - t0},
    )


__all__ = ["compare", "pick_frequencies"]
