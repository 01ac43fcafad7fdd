"""Upper bounds on the sizes of a run, derived from memory and time, and their checks.

One source of rules for the configuration file (``rattle.io``), the command line
(``rattle.cli``) and every library front end: each check takes the value and the name the user
wrote (``harmonics``, ``analysis.harmonics`` or ``--harmonics``) and raises ``TypeError`` (wrong
kind of value) or ``ValueError`` (out of range) with a message that names it in backticks, shows
the value, states the rule with its reason and says the fix. The file and command-line layers
re-raise these as :class:`~rattle.errors.ConfigError` (exit status 2).

This module imports nothing heavy (no numpy, no numerics) so that the command line can check
its options before the numerics are imported.

Why these bounds (measured on the 2-core test machine shared with other jobs, reference clutch;
``python benchmarks/bench_limits.py``; each case in a fresh process, peak memory = VmHWM)
------------------------------------------------------------------------------------------------
``harmonics`` H ≤ 256 per base frequency, H·period ≤ 512 on a branch of period p
    The unknowns are 2H + 1 Fourier coefficients, the AFT uses N = max(512, 32H) samples, and the
    Jacobian is assembled from an N × (2H + 1) matrix: memory grows as H², time per Newton
    iteration as H³ (dense solve) and H² N. Each special point is located again with 2H
    harmonics, so H = 256 means a 512-harmonic (N = 16384) problem there. Frequency response
    over Ω = 0.35 … 0.5 (two period doublings, re-located with 2H):

    ======  ======  ========  =========  =======
    H       points  time (s)  ms/point   peak MB
    ======  ======  ========  =========  =======
    32      71      1.4–2.9   20–41      112
    64      79      1.8–3.5   23–45      127
    128     69      2.4–7.4   35–107     172
    256     79      6–18      76–231     330
    512     79      51        651        998
    ======  ======  ========  =========  =======

    (ranges: repeated runs under varying load). The whole reference range 0.1 … 3 with its 10
    special points: H = 32 4.2 s and 160 MB, H = 256 211 s and 1.3 GB. H = 512 would take ~8×
    that (its re-location is a 1024-harmonic problem); ``--harmonics 10000`` was measured at 20 GB.
``samples`` N ≤ 16384 (= 32 · 512, the default for the 2H re-location at H = 256), N·p ≤ 16384
    The N × (2H + 1) AFT matrices: at N = 16384, H = 256 they take 16384 · 513 · 8 B = 67 MB each.
    A single problem (:class:`~rattle.hb.HBOptions`) is capped at twice the user bounds
    (H ≤ 1024, N ≤ 32768), the size of the 2H re-location of the largest allowed branch.
``period`` / ``max_period`` ≤ 8
    The sweep detects periods 1 … 8 (SPEC §1); a period-p branch carries p·H harmonics.
``points`` (time-domain sweep) ≤ 100 000 per direction
    Each frequency is a steady-state simulation (0.01 s to seconds); 100 000 of them take
    hours already. 10⁹ used to end in a MemoryError after allocating the frequency grid.
``max_points`` (continuation budget) ≤ 1 000 000; ``max_periods`` (settling) ≤ 100 000
    Each accepted point keeps its 2H + 1 coefficients; an exactly integrated forcing period
    costs ~0.5 ms (reference case), so 100 000 periods are ~1 min for one frequency.
Forcing frequency relative to the stiffest stage's natural frequency ω_s = sqrt(K s_max / I):
``1e-3 ω_s ≤ Ω ≤ 1e3 ω_s`` (``MIN_OMEGA_RATIO``, ``MAX_OMEGA_RATIO``)
    A simulation integrates every forcing period 2π/Ω exactly, scanning 40 grid cells per
    fastest time scale min(2π/ω_s, 1/c) for breakpoint crossings: a forcing period costs
    ~40 · ν/Ω cells, ν = max(ω_s, 2π c). One steady state from rest took 0.2 s at Ω = 1e-3 ω_s,
    0.9 s at 1e-4, 9 s at 1e-5 and 328 s at 1e-6 (``orbit --omega 1e-6``: 314 s). Below 1e-3 ω_s
    the response is quasi-static anyway. For a heavily overdamped model (2π c > ω_s) the
    simulations also need Ω ≥ 1e-3 · 2π c (:func:`simulation_rate`); the harmonic balance does
    not. Above 1e3 ω_s the response is a pure mass line (amplitude ~ (ω_s/Ω)² of the static
    one, below 1e-6) and the continuation, measured in Ω/ω_n with steps ≤ 0.08, needs ~13 points
    per unit of Ω/ω_n: Ω = 0.5 … 300 took 4000 points and 17 s (H = 16), up to 1e3 ω_s > 12 000.
Magnitudes ≤ 1e50 (``MAX_MAGNITUDE``)
    Every physical number, and the scales derived from them (k = K/I, c = C/I, the force scale
    |F_m| + Σ|F_pn| and the length scale L), must stay within 1e50 (and the divisors above
    1e-50) so that products of up to six of them (an acceleration squared, k²L² …) stay below
    the double-precision limit 1.8e308. ``mean = 1e300`` used to end in an OverflowError.
    Models with K = I = 1e±40 or C/I = 1e6 are computed (tested).

Hazards of the model that are refused or warned about: :func:`rattle.model.check_analysable_model` (zero
damping refused by every analysis) and :func:`warn_clearance` (b > π/2 rad warned about).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

from ._validate import check_int, check_real, show

#: Harmonics of the solution's base frequency, at most (see the module docstring).
MAX_HARMONICS = 256
#: Harmonics times period (the count of a period-p branch in harmonics of Ω), at most.
MAX_EFFECTIVE_HARMONICS = 512
#: AFT time samples per solution period, at most.
MAX_SAMPLES = 16384
#: Hard bounds of a single harmonic balance problem (HBOptions): the 2H re-location of a
#: branch of the largest effective size, and its default sample count 32 per harmonic.
PROBLEM_MAX_HARMONICS = 2 * MAX_EFFECTIVE_HARMONICS
PROBLEM_MAX_SAMPLES = 32 * PROBLEM_MAX_HARMONICS
#: Newton iterations per corrector call, at most.
MAX_NEWTON_ITERATIONS = 1000
#: Longest period searched or followed, as a multiple of the forcing period (SPEC §1).
MAX_PERIOD = 8
#: Most forcing periods one recorded exact integration (``propagate``) may span: every stage
#: segment is kept, so a span of 1e9 time units would fill the memory before it ended. Steady
#: states and sweeps integrate a period at a time and record a few; ``advance`` records nothing.
MAX_RECORDED_PERIODS = 100_000
#: Frequencies per direction of a time-domain sweep, at most.
MAX_SWEEP_POINTS = 100_000
#: Budget of accepted continuation points, at most.
MAX_CONTINUATION_POINTS = 1_000_000
#: Entries of an elastic law's breakpoints/slopes or of the excitation's amplitudes, at most:
#: the harmonic balance must carry every forcing harmonic (H >= their count, H <= 256).
MAX_LIST_LENGTH = MAX_HARMONICS
#: Forcing periods a steady-state simulation may run while settling (~0.5 ms each), at most.
MAX_SETTLING_PERIODS = 100_000
#: Forcing periods recorded / Poincaré points kept by a steady-state simulation, at most.
MAX_RECORD_PERIODS = 10_000
#: Frequencies examined in detail by ``compare(at=…)`` (a periodic-orbit search each), at most.
MAX_DETAIL_FREQUENCIES = 100
#: Worker processes, at most.
MAX_WORKERS = 64
#: Forcing frequency relative to the stiffest stage's natural frequency, at least / at most.
MIN_OMEGA_RATIO = 1e-3
MAX_OMEGA_RATIO = 1e3
#: Magnitude of any physical number and of the derived scales, at most (and of divisors, at least 1/MAX).
MAX_MAGNITUDE = 1e50
#: A clearance ``b`` above this (rad) is most likely given in degrees: warned about.
CLEARANCE_WARNING = math.pi / 2

#: Measured frequency response over Ω = 0.35 … 0.5 (reference clutch, two special points
#: re-located with 2H; the faster of the runs under load): H -> (points, seconds, peak MB).
HARMONICS_FIGURES: dict[int, tuple[int, float, float]] = {
    32: (71, 1.4, 112), 64: (79, 1.8, 127), 128: (69, 2.4, 172), 256: (79, 6.0, 330), 512: (79, 51.0, 998),
}

_H_REASON = (
    "the harmonic balance Jacobian grows as H² in memory and H³ in time, and each special point is "
    f"located again with 2H harmonics; measured, H = {MAX_HARMONICS} takes 80–230 ms per point and 330 MB "
    "(the whole reference range 211 s, 1.3 GB), H = 512 650 ms per point and 1 GB"
)


def max_harmonics_for(coordinates: int, period: int = 1) -> int:
    """The largest H of a period-``period`` branch of a system of n = ``coordinates`` coordinates:
    its n coordinates share the single equation's effective harmonics,

        n · p · H ≤ MAX_EFFECTIVE_HARMONICS (512),

    and at most ``MAX_HARMONICS``. The harmonic balance has n·(2pH + 1) unknowns and a dense
    Jacobian, and each special point is located again with 2H: n·p·H ≤ 512 keeps that problem
    within the single equation's largest, ~2,050 unknowns (measured on one core: a solve of 2,049
    unknowns 0.6 s and 34 MB, of 4,097 3.9 s and 134 MB; a continuation point needs several).
    Nothing changes for one or two coordinates; a chain of 60 inertias gets H ≤ 8, of 30 H ≤ 17."""
    return max(1, min(MAX_HARMONICS, MAX_EFFECTIVE_HARMONICS // (max(1, coordinates) * max(1, period))))


def check_harmonics(value: object, name: str = "harmonics", *, period: int = 1, coordinates: int = 1) -> int:
    """``harmonics`` H: an integer 1 … ``MAX_HARMONICS``; with ``period`` p > 1 also
    H·p ≤ ``MAX_EFFECTIVE_HARMONICS`` (a period-p branch needs p·H harmonics of Ω); with n =
    ``coordinates`` > 1 (a chain) also n·p·H ≤ ``MAX_EFFECTIVE_HARMONICS`` (:func:`max_harmonics_for`)."""
    h = check_int(name, value, -(10**30))
    if h < 1:
        raise ValueError(f"`{name}` must be an integer >= 1, got {show(h)}; use e.g. 32")
    if h > MAX_HARMONICS:
        raise ValueError(
            f"`{name}` must be <= {MAX_HARMONICS}, got {show(h)}: {_H_REASON}; "
            "use 32 (the default) to 128 — raise it only where the truncation error asks for it"
        )
    if period > 1 and h * period > MAX_EFFECTIVE_HARMONICS:
        raise ValueError(
            f"`{name}` must be <= {MAX_EFFECTIVE_HARMONICS // period} for branches of period {period}, got {show(h)}: "
            f"a period-{period} branch carries {period}·H harmonics of the forcing frequency and "
            f"{period}·H = {h * period} exceeds {MAX_EFFECTIVE_HARMONICS} ({_H_REASON}); "
            f"lower `{name}` or the period"
        )
    top = max_harmonics_for(coordinates, period)
    if coordinates > 1 and h > top:
        raise ValueError(
            f"`{name}` must be <= {top} for a system of {coordinates} coordinates (a chain's inertias, one fewer when "
            "it is free)"
            + (f" on branches of period {period}" if period > 1 else "") + f", got {show(h)}: its coordinates share the "
            f"{MAX_EFFECTIVE_HARMONICS} effective harmonics of one problem (n·p·H = {coordinates * period * h} > "
            f"{MAX_EFFECTIVE_HARMONICS}), as the harmonic balance has n·(2H + 1) unknowns and a dense Jacobian and each "
            f"special point is located again with 2H (a solve of 4,097 unknowns takes ~4 s and 134 MB); lower `{name}` "
            f"to {top} or less, or model fewer inertias"
        )
    return h


def check_interval(t0: object, t1: object, omega: object) -> tuple[float, float]:
    """``t0`` ≤ ``t1``, both finite, spanning at most :data:`MAX_RECORDED_PERIODS` forcing periods
    2π/``omega`` (a recorded exact integration keeps every segment); returns them as floats."""
    a, b = float(t0), float(t1)  # type: ignore[arg-type]
    if not (math.isfinite(a) and math.isfinite(b) and b >= a):
        raise ValueError(f"`t0` and `t1` must be finite with t1 >= t0, got t0={t0!r}, t1={t1!r}")
    w = float(omega)  # type: ignore[arg-type]
    periods = (b - a) * w / (2.0 * math.pi) if math.isfinite(w) and w > 0.0 else 0.0
    if periods > MAX_RECORDED_PERIODS:
        raise ValueError(
            f"`t1` - `t0` = {b - a:.6g} spans {periods:.3g} forcing periods at omega = {w:g}; a recorded exact "
            f"integration keeps every stage segment and takes at most {MAX_RECORDED_PERIODS} periods: integrate "
            "in parts, or use advance() (no record) or steady_state() for a long settling"
        )
    return a, b


def check_samples(value: object, harmonics: int, name: str = "samples", *, period: int = 1) -> int | None:
    """``samples`` N: None (the default count) or an integer 4H + 2 … ``MAX_SAMPLES``; with
    ``period`` p > 1 also N·p ≤ ``MAX_SAMPLES`` (a period-p branch keeps the ratio N/H, so it
    carries p·N samples)."""
    if value is None:
        return None
    n = check_int(name, value, 1)
    low = 4 * harmonics + 2
    if n < low:
        raise ValueError(
            f"`{name}` must be >= 4*harmonics + 2 = {low} (so that the Jacobian's harmonics up to 2H "
            f"are not aliased), got {show(n)}; leave it out for the default"
        )
    limit = MAX_SAMPLES // max(1, period)
    if n > limit:
        extra = f" for branches of period {period} (they carry {period}·N samples)" if period > 1 else ""
        raise ValueError(
            f"`{name}` must be <= {limit}{extra}, got {show(n)}: the AFT matrices hold samples × (2H + 1) "
            f"numbers each ({MAX_SAMPLES} × 513 × 8 B = 67 MB at H = 256, twice that in the 2H "
            "re-location of special points); leave it out for the default (32 per harmonic)"
        )
    return n


def check_hb_settings(
    harmonics: object, samples: object, hb: object = None, *, period: int = 1
) -> tuple[int, int | None]:
    """The harmonic-balance arguments of a front end: ``harmonics`` and ``samples``, or the
    ``hb`` options object (an :class:`~rattle.hb.HBOptions`, whose fields are then checked under
    the names ``hb.harmonics`` / ``hb.samples``), against the user-facing bounds; ``period``:
    the largest period (multiple of the solution's base period) a sub-problem of the run may
    have, so that H·period and N·period stay within the bounds. Returns (H, N or None)."""
    if hb is not None:
        h_value, n_value, h_name, n_name = getattr(hb, "harmonics", None), getattr(hb, "samples", None), \
            "hb.harmonics", "hb.samples"
    else:
        h_value, n_value, h_name, n_name = harmonics, samples, "harmonics", "samples"
    h = check_harmonics(h_value, h_name, period=period)
    return h, check_samples(n_value, h, n_name, period=period)


def check_callback(value: object, name: str = "callback") -> None:
    """None or a callable."""
    if value is not None and not callable(value):
        raise TypeError(f"`{name}` must be callable or None, got {value!r} ({type(value).__name__})")


def check_period(value: object, name: str = "period") -> int:
    """A period as a multiple 1 … ``MAX_PERIOD`` of the forcing period."""
    p = check_int(name, value, 1)
    if p > MAX_PERIOD:
        raise ValueError(
            f"`{name}` must be an integer 1 … {MAX_PERIOD} (multiple of the forcing period), got {show(p)}: "
            f"periods above {MAX_PERIOD} are not detected (SPEC) and a period-p branch needs p·H "
            "harmonics; use 1 for the primary response, n for a 1/n sub-harmonic"
        )
    return p


def check_points(value: object, name: str = "points") -> int:
    """Frequencies per direction of a time-domain sweep: an integer 2 … ``MAX_SWEEP_POINTS``."""
    n = check_int(name, value, 2)
    if n > MAX_SWEEP_POINTS:
        raise ValueError(
            f"`{name}` must be <= {MAX_SWEEP_POINTS} (frequencies per sweep direction), got {show(n)}: each "
            f"frequency is a steady-state simulation of 10 ms to seconds, so {MAX_SWEEP_POINTS} already "
            "take hours; use e.g. 200, or sweep a narrower range"
        )
    return n


def check_max_points(value: object, name: str = "max_points") -> int:
    """Continuation budget: an integer 1 … ``MAX_CONTINUATION_POINTS``."""
    n = check_int(name, value, 1)
    if n > MAX_CONTINUATION_POINTS:
        raise ValueError(
            f"`{name}` must be <= {MAX_CONTINUATION_POINTS}, got {show(n)}: every accepted point keeps its "
            "coefficients and samples in memory; the reference case over Ω = 0.1 … 3 needs ~820 points"
        )
    return n


def check_workers(value: object, name: str = "workers") -> int:
    """Worker processes: an integer 1 … ``MAX_WORKERS``."""
    n = check_int(name, value, 1)
    if n > MAX_WORKERS:
        raise ValueError(f"`{name}` must be <= {MAX_WORKERS} processes, got {show(n)}; use e.g. 2")
    return n


def check_magnitude(value: object, name: str) -> float:
    """A finite real number of magnitude ≤ ``MAX_MAGNITUDE``."""
    x = check_real(value, name)
    if abs(x) > MAX_MAGNITUDE:
        raise ValueError(
            f"`{name}` must have magnitude <= {MAX_MAGNITUDE:g}, got {x!r}: products of the problem's "
            "scales (an acceleration squared) would overflow double precision (1.8e308); "
            "choose units in which the values are moderate (e.g. scale by 1e-3)"
        )
    return x


# --------------------------------------------------------------------------------------------
# Frequencies relative to the model
# --------------------------------------------------------------------------------------------
def stiffest_frequency(model: Any) -> float:
    """ω_s (rad/s), the highest natural frequency of the model's stiffest stage combination:
    sqrt(K s_max / I) for the single equation (every element on its stiffest stage for a chain)."""
    return model.system().stiffest_frequency()


def damping_rate(model: Any) -> float:
    """c (1/s), the largest damping rate per inertia: C/I for the single equation, the spectral
    radius of M⁻¹C for a chain."""
    import numpy as np  # here: the module stays importable without numpy (the command line's checks)

    C = model.system().damping
    return float(np.max(np.abs(np.linalg.eigvals(C)))) if C.size else 0.0


def simulation_rate(model: Any) -> float:
    """ν = max(ω_s, 2π·c) (rad/s): the exact integrator scans every forcing period in steps of
    1/40 of the model's fastest time scale min(2π/ω_s, 1/c), i.e. ~40·ν/Ω steps per period."""
    return max(stiffest_frequency(model), 2.0 * math.pi * damping_rate(model))


def _frequency_rule(model: Any, omega: float, name: str, simulate: bool) -> None:
    ws = stiffest_frequency(model)
    lo, hi = MIN_OMEGA_RATIO * ws, MAX_OMEGA_RATIO * ws
    if omega < lo:
        raise ValueError(
            f"`{name}` must be >= {lo:.4g} rad/s ({MIN_OMEGA_RATIO:g} × the stiffest stage's natural "
            f"frequency {ws:.4g} rad/s), got {show(omega)}: each forcing period 2π/Ω spans "
            f"~{ws / omega:.3g} free oscillations of the stage, all integrated exactly (one steady state "
            "from rest took 0.2 s at 1e-3 × that frequency, 9 s at 1e-5 ×, 330 s at 1e-6 ×); the response there is "
            "quasi-static — "
            f"start the range higher, e.g. {0.1 * ws:.3g}"
        )
    if omega > hi:
        raise ValueError(
            f"`{name}` must be <= {hi:.4g} rad/s ({MAX_OMEGA_RATIO:g} × the stiffest stage's natural "
            f"frequency {ws:.4g} rad/s), got {show(omega)}: the response there is a pure mass line "
            f"(amplitude < 1e-6 of the static one) and the continuation would need over 10⁴ points; "
            f"end the range lower, e.g. {3.0 * ws:.3g}"
        )
    nu = simulation_rate(model)
    if simulate and nu > ws and omega < MIN_OMEGA_RATIO * nu:
        # Heavily overdamped (c > ω_s / 2π): the damping rate, not the stiffness, sets the step.
        raise ValueError(
            f"`{name}` must be >= {MIN_OMEGA_RATIO * nu:.4g} rad/s for a simulation of this model, got "
            f"{show(omega)}: its damping rate C/I = {damping_rate(model):.3g} 1/s sets the exact integrator's time step "
            f"(1/40 of 1/(C/I)), so one forcing period would take ~{40 * 2 * math.pi * damping_rate(model) / omega:.2g} "
            "steps (hours of simulation); the harmonic balance alone (frequency_response, or "
            "periodic_orbit with simulate=False) has no such limit"
        )


def check_frequency(model: Any, omega: object, name: str = "omega", *, simulate: bool = True) -> float:
    """A single forcing frequency within ``MIN_OMEGA_RATIO`` … ``MAX_OMEGA_RATIO`` × ω_s; with
    ``simulate`` also Ω ≥ ``MIN_OMEGA_RATIO`` × ν (:func:`simulation_rate`), which differs from
    the first rule only for a heavily overdamped model."""
    from ._validate import check_omega

    w = check_omega(omega, name)
    _frequency_rule(model, w, name, simulate)
    return w


def check_frequency_range(
    model: Any, omega_min: float, omega_max: float, names: tuple[str, str] = ("omega", "omega"),
    *, simulate: bool = False,
) -> tuple[float, float]:
    """Both ends of an (already type-checked, ordered) range within the bounds relative to ω_s
    (and, with ``simulate``, to ν: see :func:`check_frequency`).

    ``names``: how the two ends are called in messages (``("omega", "omega")`` for the library's
    pair, ``("analysis.omega[0]", "analysis.omega[1]")`` in a file, ``("--omega-min",
    "--omega-max")`` on the command line).
    """
    _frequency_rule(model, float(omega_min), names[0], simulate)
    _frequency_rule(model, float(omega_max), names[1], simulate)
    return float(omega_min), float(omega_max)


# --------------------------------------------------------------------------------------------
# The model: magnitudes, zero damping, a clearance in degrees
# --------------------------------------------------------------------------------------------
def check_scales(model: Any, prefix: str = "") -> None:
    """The derived scales k = K/I, c = C/I, the force scale and the length scale within
    [1/``MAX_MAGNITUDE``, ``MAX_MAGNITUDE``] (zero allowed where a zero is meaningful)."""
    p = prefix

    def bound(value: float, what: str, keys: str, allow_zero: bool = False) -> None:
        if allow_zero and value == 0.0:
            return
        if not (1.0 / MAX_MAGNITUDE <= abs(value) <= MAX_MAGNITUDE):
            raise ValueError(
                f"{keys} give {what} = {value:.3g}, outside {1 / MAX_MAGNITUDE:g} … {MAX_MAGNITUDE:g}: "
                "products of the problem's scales would overflow (or underflow) double precision; "
                "choose units in which the values are moderate"
            )

    bound(model.k, "K/I", f"`{p}stiffness` / `{p}inertia`")
    bound(model.c, "C/I", f"`{p}damping` / `{p}inertia`", allow_zero=True)
    ex = model.excitation
    force = abs(ex.mean) + sum(abs(a) for a in ex.amplitudes)
    bound(force, "the force scale |mean| + Σ|amplitudes|", "`excitation.mean` and `excitation.amplitudes`",
          allow_zero=True)
    st = model.elastic.stages
    length = quasi_static_deflection(st.slopes, st.breakpoints, force, model.k)
    bound(length, "the deflection scale (force scale)/(K/I)",
          f"`excitation.mean`, `excitation.amplitudes` and `{p}stiffness` / `{p}inertia`", allow_zero=True)


#: A scale may exceed the motion it stands for by this factor before the tighter bound replaces
#: it (:func:`bounded_scale`): within an order of magnitude the continuation's scaled tolerances
#: serve (the reference clutch with α = 1e-3, its scale 80 times its orbit, gives α = 0's answer),
#: 10⁹ times they do not; below the factor every law keeps the scale it was solved with.
SCALE_SLACK = 10.0


def bounded_scale(estimate: float, bound: float) -> float:
    """``estimate`` (the quasi-static amplitude on the softest stages), or ``bound`` (an upper
    bound of the motion, :func:`quasi_static_deflection`) where the estimate exceeds it more than
    :data:`SCALE_SLACK` times."""
    return estimate if estimate <= SCALE_SLACK * bound else bound


def quasi_static_deflection(slopes: Any, breakpoints: Any, force: float, k: float) -> float:
    """The quasi-static deflection scale that a force amplitude ``force`` gives on a law of
    stage ``slopes`` (≥ 0, relative to ``k``) between ``breakpoints``: F / (k s_min), s_min the
    softest positive slope — unless it exceeds ten times (:func:`bounded_scale`) the bound

        A = w + F / (k s_out),

    s_out the softer positive slope of the two outer stages, w = max(breakpoints) −
    min(breakpoints) the width of the inner stages: an inner stage holds no more than its width,
    however soft. (F / (k s_min) alone grows without bound as an inner slope — a clutch's α —
    tends to 0, though the motion tends to the backlash limit's.)"""
    slopes = [float(s) for s in slopes]
    bps = [float(b) for b in breakpoints]

    def over(s: float) -> float:  # F / (k s), inf where k s underflows to 0
        ks = k * s
        return force / ks if ks > 0 else math.inf

    out = over(min(s for s in slopes if s > 0)) if any(s > 0 for s in slopes) else math.inf
    outer = [s for s in (slopes[0], slopes[-1]) if s > 0] if slopes else []
    if outer and bps:
        out = bounded_scale(out, (max(bps) - min(bps)) + over(min(outer)))
    return out


def warn_clearance(b: float, name: str = "b", stacklevel: int = 3) -> None:
    """Warn when a clearance ``b`` exceeds ``CLEARANCE_WARNING`` = π/2 rad (90°).

    Clearances are in radians. A drivetrain clearance (gear backlash, clutch first stage) is a
    few degrees at most; π/2 rad = 90° is far beyond anything physical, while b = 10 (the
    reference 10° typed in degrees) is 573°. Not refused: the equation is valid for any b.
    """
    if b > CLEARANCE_WARNING:
        warnings.warn(
            f"`{name}` = {b:g} rad is {math.degrees(b):.0f}°: clearances are in radians — "
            f"if you meant {b:g}°, write {math.radians(b):.6g}",
            UserWarning,
            stacklevel=stacklevel,
        )


__all__ = [
    "MAX_HARMONICS", "MAX_EFFECTIVE_HARMONICS", "MAX_SAMPLES", "MAX_PERIOD", "MAX_RECORDED_PERIODS", "MAX_SWEEP_POINTS",
    "MAX_CONTINUATION_POINTS", "MAX_WORKERS", "MIN_OMEGA_RATIO", "MAX_OMEGA_RATIO", "MAX_MAGNITUDE",
    "CLEARANCE_WARNING", "check_harmonics", "check_interval", "check_samples", "check_period", "check_points",
    "check_max_points", "check_workers", "check_hb_settings", "check_callback", "check_magnitude", "check_frequency", "check_frequency_range",
    "check_scales", "quasi_static_deflection", "bounded_scale", "SCALE_SLACK", "warn_clearance", "max_harmonics_for", "stiffest_frequency", "simulation_rate", "damping_rate",
]
