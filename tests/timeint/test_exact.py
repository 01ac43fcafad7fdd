"""Exact piecewise-linear integration against closed forms, scipy.linalg.expm and solve_ivp."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from rattle.model import (
    Backlash, Clutch, Excitation, Linear, Model, Piecewise, Unilateral, backlash_case, reference_case,
)
from rattle.timeint import ExactIntegrator, FlowOptions, StageSolutions


def _model(elastic, *, damping=0.05, mean=0.05, amplitudes=(0.03,), phases=None, inertia=1.0, stiffness=1.0):
    return Model(inertia=inertia, damping=damping, stiffness=stiffness, elastic=elastic,
                 excitation=Excitation(mean=mean, amplitudes=amplitudes, phases=phases))


def _stage_matrix(model: Model, j: int) -> np.ndarray:
    return np.array([[0.0, 1.0], [-model.k * model.elastic.stages.slopes[j], -model.c]])


def _reference_solve(model: Model, x0, t1: float, omega: float) -> np.ndarray:
    """DOP853 (rtol 1e-12, atol 1e-14) restarted at every breakpoint crossing (terminal events),
    each stage integrated with its own linear right-hand side."""
    st = model.elastic.stages
    lower = np.concatenate(([-np.inf], st.breakpoints))
    upper = np.concatenate((st.breakpoints, [np.inf]))
    t, x = 0.0, np.array(x0, dtype=float)
    j = int(np.searchsorted(st.breakpoints, x[0], side="right"))
    while t < t1:
        ks, ke = model.k * st.slopes[j], model.k * st.offsets[j]

        def rhs(tt, y, ks=ks, ke=ke):
            return [y[1], model.excitation(tt, omega) - model.c * y[1] - ks * y[0] - ke]

        events = []
        if np.isfinite(lower[j]):
            down = lambda tt, y, d=lower[j]: y[0] - d  # noqa: E731
            down.terminal, down.direction = True, -1
            events.append(down)
        if np.isfinite(upper[j]):
            up = lambda tt, y, d=upper[j]: y[0] - d  # noqa: E731
            up.terminal, up.direction = True, 1
            events.append(up)
        sol = solve_ivp(rhs, (t, t1), x, method="DOP853", rtol=1e-12, atol=1e-14, events=events)
        t, x = sol.t[-1], sol.y[:, -1].copy()
        if sol.status == 1:
            j, x[0] = (j + 1, upper[j]) if x[1] > 0 else (j - 1, lower[j])
    return x


# --- closed-form stage solutions -----------------------------------------------------------------
@pytest.mark.parametrize(
    ("damping", "slopes"),
    [
        (0.05, (1.0, 0.25, 1.0)),  # underdamped stages
        (3.0, (1.0, 0.25, 1.0)),  # overdamped stages
        (2.0, (1.0, 0.25, 1.0)),  # critically damped outer stages (c² = 4 k s)
        (0.05, (1.0, 0.0, 1.0)),  # zero-stiffness (backlash) stage, damped
        (0.0, (1.0, 0.0, 1.0)),  # zero-stiffness stage, undamped (free flight)
    ],
)
def test_transition_matrix_equals_expm(damping, slopes):
    model = _model(Piecewise(breakpoints=(-0.1, 0.1), slopes=slopes), damping=damping)
    sol = StageSolutions(model, 0.7)
    taus = np.array([0.0, 1e-3, 0.37, 2.5, 11.0])
    for j in range(3):
        vec = np.stack(sol.transition(j, taus), axis=-1).reshape(-1, 2, 2)
        for tau, phi in zip(taus, vec):
            expected = scipy.linalg.expm(_stage_matrix(model, j) * tau)
            # expm is accurate to a few ulp of ‖exp(Aτ)‖; the closed forms likewise.
            np.testing.assert_allclose(phi, expected, rtol=0, atol=1e-13)
            np.testing.assert_allclose(np.reshape(sol.transition_scalar(j, tau), (2, 2)), expected, rtol=0, atol=1e-13)


def test_exact_resonance_without_damping_is_refused():
    model = _model(Linear(), damping=0.0)
    with pytest.raises(ValueError, match="exact resonance"):
        ExactIntegrator(model).propagate((0.0, 0.0), 0.0, 1.0, 1.0)


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan])
def test_omega_must_be_positive(bad):
    with pytest.raises(ValueError, match="`omega`"):
        ExactIntegrator(reference_case()).propagate((0.0, 0.0), 0.0, 1.0, bad)


def test_bad_interval_and_state_are_refused():
    integ = ExactIntegrator(reference_case())
    with pytest.raises(ValueError, match="t1 >= t0"):
        integ.propagate((0.0, 0.0), 1.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="`x0`"):
        integ.propagate((0.0, 0.0, 0.0), 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="samples_per_scale"):
        ExactIntegrator(reference_case(), FlowOptions(samples_per_scale=2))


# --- linear law: closed forms -----------------------------------------------------------------------
def _linear_closed_form(model: Model, omega: float, x0: np.ndarray, t: float) -> np.ndarray:
    """Forced response Re[X e^{iΩt}] + F_m/k plus the free decay exp(A t) (x0 − p(0))."""
    amp = model.excitation.amplitudes[0] * np.exp(1j * model.excitation.phases[0])
    X = amp / (model.k - omega**2 + 1j * model.c * omega)

    def particular(tt):
        z = X * np.exp(1j * omega * tt)
        return np.array([model.excitation.mean / model.k + z.real, (1j * omega * z).real])

    A = _stage_matrix(model, 0)
    return particular(t) + scipy.linalg.expm(A * t) @ (x0 - particular(0.0))


@pytest.mark.parametrize("omega", [0.3, 1.1, 2.7])
def test_linear_law_matches_closed_form(omega):
    model = _model(Linear(), damping=0.1, mean=0.2, amplitudes=(0.5,), phases=(0.4,), stiffness=2.0, inertia=0.5)
    integ = ExactIntegrator(model)
    x0 = np.array([0.3, -0.2])
    traj = integ.propagate(x0, 0.0, 17.3, omega)
    assert traj.n_segments == 1
    # Both sides are closed forms evaluated in double precision: agreement to ~1e-13 of the
    # O(1) state (1e-12 leaves room for the expm round-off).
    np.testing.assert_allclose(traj.state1, _linear_closed_form(model, omega, x0, 17.3), rtol=0, atol=1e-12)
    t = np.linspace(0.0, 17.3, 57)
    samples = traj.sample(t)
    expected = np.array([_linear_closed_form(model, omega, x0, tt) for tt in t])
    np.testing.assert_allclose(samples.delta, expected[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(samples.velocity, expected[:, 1], rtol=0, atol=1e-12)
    # δ'' from the equation against the closed form's derivative of the velocity
    acc = model.excitation(t, omega) - model.c * expected[:, 1] - model.k * expected[:, 0]
    np.testing.assert_allclose(samples.acceleration, acc, rtol=0, atol=1e-12)


def test_linear_monodromy_and_multipliers():
    model = _model(Linear(), damping=0.08, stiffness=1.5)
    omega = 0.9
    T = 2 * np.pi / omega
    traj = ExactIntegrator(model).propagate((0.1, 0.0), 0.0, T, omega)
    A = _stage_matrix(model, 0)
    # Sensitivity = exp(A T) exactly; expm and the closed form agree to round-off.
    np.testing.assert_allclose(traj.sensitivity, scipy.linalg.expm(A * T), rtol=0, atol=1e-13)
    lam = np.roots([1.0, model.c, model.k])
    expected = np.sort_complex(np.exp(lam * T))
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(traj.sensitivity)), expected, rtol=0, atol=1e-13)


# --- piecewise laws against an event-restarted DOP853 -----------------------------------------------
@pytest.mark.parametrize(
    ("model", "omega", "x0"),
    [
        (reference_case(), 0.3, (0.18, 0.0)),
        (reference_case(), 0.7, (0.4, 0.14)),
        (reference_case(), 2.0, (-0.3, 0.2)),
        (backlash_case(), 0.7, (0.0, 0.0)),
        (backlash_case(), 1.3, (0.3, -0.5)),
        (_model(Backlash(b=0.1), damping=0.0, mean=0.02, amplitudes=(0.05,)), 0.4, (0.3, -0.5)),
        (_model(Piecewise(breakpoints=(-0.3, -0.1, 0.05, 0.2), slopes=(1, 0.3, 0.0, 0.3, 1)), damping=0.1,
                stiffness=4.0, mean=0.1, amplitudes=(0.2, 0.1, 0.05), phases=(0.0, 1.0, 2.0)), 0.4, (0.0, 0.0)),
        (_model(Clutch(alpha=0.25, b=0.05), damping=2.0, amplitudes=(0.3,)), 1.3, (0.3, -0.5)),  # critical
    ],
)
def test_piecewise_against_solve_ivp(model, omega, x0):
    t1 = 5 * 2 * np.pi / omega
    traj = ExactIntegrator(model).propagate(x0, 0.0, t1, omega)
    assert traj.n_segments > 1
    # DOP853 at rtol 1e-12 over five periods with restarts carries errors up to ~1e-10.
    np.testing.assert_allclose(traj.state1, _reference_solve(model, x0, t1, omega), rtol=0, atol=1e-8)


def test_segments_are_consistent_and_restartable():
    model = reference_case()
    omega = 0.7
    integ = ExactIntegrator(model)
    traj = integ.propagate((0.4, 0.14), 0.0, 30.0, omega)
    st = model.elastic.stages
    # Every segment starts in its stage; every crossing starts exactly on a breakpoint.
    assert np.all(np.isin(traj.crossed_breakpoints, st.breakpoints))
    assert np.all(np.abs(np.diff(traj.stage)) == 1)
    d = traj.sample(0.5 * (traj.t_start + traj.t_end)).delta
    np.testing.assert_array_equal(model.elastic.stage(d), traj.stage)
    # Restarting from a sampled state reproduces the final state (round-off only).
    s = traj.sample(np.array([13.1]))
    again = integ.propagate((s.delta[0], s.velocity[0]), 13.1, 30.0, omega)
    np.testing.assert_allclose(again.state1, traj.state1, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="within the trajectory"):
        traj.sample(31.0)


def test_sensitivity_matches_central_differences():
    model = reference_case()
    omega, T = 0.7, 3 * 2 * np.pi / 0.7
    integ = ExactIntegrator(model)
    x0 = np.array([0.3, 0.1])
    traj = integ.propagate(x0, 0.0, T, omega)
    assert traj.n_segments > 5
    h = 1e-6
    fd = np.empty((2, 2))
    for i in range(2):
        e = np.zeros(2)
        e[i] = h
        plus = integ.propagate(x0 + e, 0.0, T, omega).state1
        minus = integ.propagate(x0 - e, 0.0, T, omega).state1
        fd[:, i] = (plus - minus) / (2 * h)
    # Central differences: truncation O(h²) plus round-off O(eps/h) ~ 1e-10 on O(1) entries.
    np.testing.assert_allclose(traj.sensitivity, fd, rtol=0, atol=1e-8)
    # Liouville: det = exp(−c T) for every trajectory (trace A_j = −c on every stage).
    assert np.linalg.det(traj.sensitivity) == pytest.approx(np.exp(-model.c * T), rel=1e-12)


# --- crossing times against closed forms ------------------------------------------------------------
def test_crossing_times_of_free_motion():
    """Free damped motion (no harmonic forcing, F_m = 0) from δ = 0 inside the clutch's first stage.

    Stage 1 (|δ| < b, slope α): δ = (v0/ω1) e^{−σt} sin ω1 t; it reaches b at the first root t1 of
    that expression. Stage 2 (δ > b, slope 1, offset −(1 − α) b): δ − (1 − α) b is a free
    oscillation from (α b, v1) at t1, which returns to b at t2.
    """
    alpha, b, c = 0.25, 0.1, 0.05
    model = _model(Clutch(alpha=alpha, b=b), damping=c, mean=0.0, amplitudes=(0.0,))
    v0 = 0.2
    sigma = c / 2
    w1 = math.sqrt(alpha - sigma**2)
    x1 = lambda t: v0 / w1 * math.exp(-sigma * t) * math.sin(w1 * t)  # noqa: E731
    v1 = lambda t: v0 / w1 * math.exp(-sigma * t) * (w1 * math.cos(w1 * t) - sigma * math.sin(w1 * t))  # noqa: E731
    t1 = brentq(lambda t: x1(t) - b, 0.0, math.pi / (2 * w1), xtol=1e-15, rtol=1e-15)
    w2 = math.sqrt(1.0 - sigma**2)
    y0, yv = alpha * b, v1(t1)  # y = δ − (1 − α) b on stage 2
    B = (yv + sigma * y0) / w2
    y = lambda s: math.exp(-sigma * s) * (y0 * math.cos(w2 * s) + B * math.sin(w2 * s))  # noqa: E731
    s_max = math.atan2(yv, sigma * B + w2 * y0) / w2  # y' = 0: the maximum of y, before the return
    t2 = t1 + brentq(lambda s: y(s) - alpha * b, s_max, math.pi / w2, xtol=1e-15, rtol=1e-15)

    traj = ExactIntegrator(model).propagate((0.0, v0), 0.0, t2 + 1.0, 1.0)
    np.testing.assert_array_equal(traj.stage[:3], [1, 2, 1])
    # Crossing times to round-off (brentq to ~1e-15 on closed forms; the integrator to ~1e-15
    # of t): 1e-13 allows for the conditioning 1/|δ'| of the root.
    assert traj.crossing_times[0] == pytest.approx(t1, abs=1e-13)
    assert traj.crossing_times[1] == pytest.approx(t2, abs=1e-13)
    assert traj.x_start[1, 1] == pytest.approx(v1(t1), abs=1e-13)


def _grazing_start(model: Model, j: int, x_top: np.ndarray, t_top: float, t0: float) -> np.ndarray:
    """State at t0 of the stage-j free solution (no harmonic forcing) passing through x_top at
    t_top: P + exp(A_j (t0 − t_top)) (x_top − P), by scipy's expm."""
    st = model.elastic.stages
    P = np.array([(model.excitation.mean - model.k * st.offsets[j]) / (model.k * st.slopes[j]), 0.0])
    return P + scipy.linalg.expm(_stage_matrix(model, j) * (t0 - t_top)) @ (x_top - P)


@pytest.mark.parametrize("t_top", [3.2117, 5.0031])  # anywhere inside a grid cell (step ≈ 0.31)
def test_grazing_excursion_switches_twice(t_top):
    """The stage-1 motion peaks 1e-9 above the breakpoint b: the excursion into stage 2 lasts
    ~4e-4 s, a thousandth of a grid cell, and must still be found (two switches)."""
    b = 0.1
    model = _model(Clutch(alpha=0.25, b=b), mean=0.0, amplitudes=(0.0,))
    eps = 1e-9
    x0 = _grazing_start(model, 1, np.array([b + eps, 0.0]), t_top, 0.0)
    traj = ExactIntegrator(model).propagate(x0, 0.0, t_top + 2.0, 1.0)
    np.testing.assert_array_equal(traj.stage, [1, 2, 1])
    t_in, t_out = traj.crossing_times
    # Near the peak δ ≈ b + ε − ½|δ''| (t − t_top)² with |δ''| = k α b: crossings at
    # t_top ± sqrt(2ε/(k α b)) up to O(ε) corrections from the stiffer stage and the damping.
    half = math.sqrt(2 * eps / (0.25 * b))
    assert t_in == pytest.approx(t_top - half, abs=1e-6)
    assert t_out == pytest.approx(t_top + half, abs=1e-6)
    # The peak itself is reproduced (the force jump inside is O(ε), its effect O(ε·Δt²)).
    t = np.linspace(t_in, t_out, 101)
    assert traj.sample(t).delta.max() == pytest.approx(b + eps, abs=1e-14)


@pytest.mark.parametrize("eps", [0.0, -1e-9])
def test_exact_graze_does_not_switch(eps):
    """A peak exactly on the breakpoint (to round-off), or just below it: no stage switch."""
    b = 0.1
    model = _model(Clutch(alpha=0.25, b=b), mean=0.0, amplitudes=(0.0,))
    x0 = _grazing_start(model, 1, np.array([b + eps, 0.0]), 3.2117, 0.0)
    traj = ExactIntegrator(model).propagate(x0, 0.0, 6.0, 1.0)
    np.testing.assert_array_equal(traj.stage, [1])


def test_start_on_breakpoint_follows_direction_of_motion():
    model = backlash_case()
    b = model.elastic.b
    integ = ExactIntegrator(model)
    assert integ.propagate((b, 0.1), 0.0, 0.5, 1.0).stage[0] == 2
    assert integ.propagate((b, -0.1), 0.0, 0.5, 1.0).stage[0] == 1
    # At rest on the breakpoint: F(0) = F_m + F_p1 > 0 pushes into the outer stage.
    assert integ.propagate((b, 0.0), 0.0, 0.5, 1.0).stage[0] == 2


# --- the compiled march against the Python march (the reference) ------------------------------------
def _random_continuous(rng: np.random.Generator, i: int) -> Model:
    """A random continuous law (piecewise with a free stage, clutch, backlash, unilateral stop),
    under-damped or (every fourth) over-damped, forced by up to three harmonics with phases."""
    kind = i % 4
    if kind == 0:
        k = int(rng.integers(1, 5))
        bps = np.sort(rng.uniform(-0.3, 0.3, k))
        slopes = rng.uniform(0.2, 1.5, k + 1)
        if k > 1:
            slopes[rng.integers(1, k)] = 0.0  # an inner free stage
        elastic = Piecewise(breakpoints=tuple(bps), slopes=tuple(slopes))
    elif kind == 1:
        elastic = Clutch(alpha=rng.uniform(0.0, 0.6), b=rng.uniform(0.02, 0.2))
    elif kind == 2:
        elastic = Backlash(b=rng.uniform(0.02, 0.2))
    else:
        elastic = Unilateral(gap=rng.uniform(0.0, 0.1), side="positive")
    h = int(rng.integers(1, 4))
    damping = 3.0 if i % 4 == 3 else rng.uniform(0.01, 0.3)  # over-damped: c² > 4 k s on every stage
    mean = rng.uniform(0.01, 0.08) if kind == 3 else rng.uniform(-0.05, 0.05)  # the stop needs a mean load
    return _model(elastic, damping=damping, stiffness=rng.uniform(0.5, 1.5), mean=mean,
                  amplitudes=tuple(rng.uniform(0.02, 0.3, h)), phases=tuple(rng.uniform(0.0, 6.0, h)))


def _compiled_and_python(model: Model, x0, t0: float, t1: float, omega: float):
    compiled, python = ExactIntegrator(model), ExactIntegrator(model)
    python._compiled = False  # the Python march
    a, b = compiled.propagate(x0, t0, t1, omega), python.propagate(x0, t0, t1, omega)
    assert compiled._compiled
    return a, b, compiled, python


def _assert_same_march(a, b) -> None:
    """The same segments and stages, crossing times, states and sensitivity to round-off."""
    np.testing.assert_array_equal(a.stage, b.stage)
    scale = max(1.0, float(np.max(np.abs(b.x_start))))
    np.testing.assert_allclose(a.t_start, b.t_start, rtol=1e-13, atol=1e-13 * max(1.0, abs(b.t1)))
    np.testing.assert_allclose(a.x_start, b.x_start, rtol=1e-13, atol=1e-13 * scale)
    np.testing.assert_allclose(a.homogeneous, b.homogeneous, rtol=1e-13, atol=1e-13 * scale)
    np.testing.assert_allclose(a.state1, b.state1, rtol=1e-13, atol=1e-13 * scale)
    np.testing.assert_allclose(a.sensitivity, b.sensitivity, rtol=1e-12,
                               atol=1e-13 * max(1.0, float(np.max(np.abs(b.sensitivity)))))


@pytest.mark.parametrize("seed", [3, 17])
def test_compiled_march_is_the_python_march(seed: int) -> None:
    """The compiled march (timeint._event_kernel, the law as a discontinuous one without jumps or
    friction) takes the Python march's steps on random continuous laws: the same stages, crossing
    times, states, homogeneous parts and sensitivity to round-off, over ten periods from a random
    state; ``advance`` gives propagate's end."""
    rng = np.random.default_rng(seed)
    crossings = 0
    for i in range(16):
        model = _random_continuous(rng, i)
        omega = rng.uniform(0.3, 2.5)
        x0 = (rng.uniform(-0.4, 0.4), rng.uniform(-0.3, 0.3))
        t0 = rng.uniform(0.0, 50.0)
        t1 = t0 + 10 * 2 * np.pi / omega
        a, b, compiled, _ = _compiled_and_python(model, x0, t0, t1, omega)
        _assert_same_march(a, b)
        crossings += a.n_segments - 1
        x1, M = compiled.advance(np.array(x0), t0, t1, omega)
        np.testing.assert_array_equal(x1, a.state1)
        np.testing.assert_array_equal(M, a.sensitivity)
    assert crossings > 100


@pytest.mark.parametrize("eps", [1e-9, 1e-12, 0.0, -1e-9])
@pytest.mark.parametrize("t_top", [1.7, 3.2117, 5.0031])
def test_compiled_march_resolves_grazes_as_the_python_march(eps: float, t_top: float) -> None:
    """A stage-1 peak ε above, on or below the breakpoint, anywhere in a grid cell: the compiled
    march finds the short excursion (two crossings) or none, as the Python march."""
    b = 0.1
    model = _model(Clutch(alpha=0.25, b=b), mean=0.0, amplitudes=(0.0,))
    x0 = _grazing_start(model, 1, np.array([b + eps, 0.0]), t_top, 0.0)
    a, ref, _, _ = _compiled_and_python(model, x0, 0.0, t_top + 2.0, 1.0)
    _assert_same_march(a, ref)
    assert list(a.stage[-3:] if eps > 0.0 else a.stage[-1:]) == ([1, 2, 1] if eps > 0.0 else [1])
    assert (2 in a.stage) == (eps > 0.0)


def test_compiled_march_needs_the_modal_form() -> None:
    """A stage near critical damping (the modal form's amplitudes blow up) or free without
    damping (a double zero eigenvalue) keeps the Python march."""
    for model in (_model(Clutch(alpha=0.25, b=0.05), damping=2.0, amplitudes=(0.3,)),
                  _model(Backlash(b=0.1), damping=0.0, mean=0.02, amplitudes=(0.05,))):
        integ = ExactIntegrator(model)
        assert integ.propagate((0.3, -0.5), 0.0, 20.0, 0.7).n_segments > 1
        assert integ._compiled is False


def test_segment_budget_is_kept_by_both_marches() -> None:
    """More crossings than ``max_events`` in one march: ConvergenceError naming the budget, from the
    compiled march and the Python march alike; a march that fits is not refused."""
    from rattle.errors import ConvergenceError

    model = reference_case()
    for compiled in (True, False):
        integ = ExactIntegrator(model, FlowOptions(max_events=20))
        if not compiled:
            integ._compiled = False
        with pytest.raises(ConvergenceError, match="max_segments` = 20"):
            integ.propagate((0.4, 0.14), 0.0, 200.0, 0.7)
        with pytest.raises(ConvergenceError, match="max_segments` = 20"):
            integ.advance(np.array([0.4, 0.14]), 0.0, 200.0, 0.7)
        assert integ.propagate((0.4, 0.14), 0.0, 20.0, 0.7).n_segments <= 21


def test_compiled_record_grows_past_its_capacity() -> None:
    """A march of more segments than the record holds (64 at first) is run again with room for
    them: the same trajectory as the Python march's, and the flow's record kept for the next."""
    model = reference_case()
    a, b, compiled, _ = _compiled_and_python(model, (0.4, 0.14), 0.0, 100 * 2 * np.pi / 0.8, 0.8)
    assert a.n_segments > 64 and compiled._capacity > 64
    _assert_same_march(a, b)
    again = compiled.propagate((0.4, 0.14), 0.0, 2 * np.pi / 0.8, 0.8)  # the kept record, shorter
    np.testing.assert_array_equal(again.t_start, a.t_start[: again.n_segments])
    # advance keeps no record: the same end, and no record made or grown
    fresh = ExactIntegrator(model)
    x1, M = fresh.advance(np.array([0.4, 0.14]), 0.0, 100 * 2 * np.pi / 0.8, 0.8)
    np.testing.assert_array_equal(x1, a.state1)
    np.testing.assert_array_equal(M, a.sensitivity)
    assert fresh._compiled and fresh._buffers is None and fresh._capacity == 64


@pytest.mark.skipif(not hasattr(__import__("signal"), "pthread_sigmask"), reason="no signal masks here")
def test_the_first_compiled_march_of_a_process_holds_the_stopping_signals(monkeypatch) -> None:
    """numba loads (or compiles) the kernel at its first call: SIGINT, SIGTERM and SIGHUP are held
    during that call (rattle._lazy.call_held), not during the later ones."""
    import signal

    from rattle.timeint import _integrator

    integ = ExactIntegrator(reference_case())
    integ.advance(np.array([0.1, 0.05]), 0.0, 1.0, 0.7)  # decides the compiled march
    march, full, budget = integ._kernel
    masks = []

    def spy(*args):
        masks.append(signal.pthread_sigmask(signal.SIG_BLOCK, []))
        return march(*args)

    integ._kernel = (spy, full, budget)
    monkeypatch.setattr(_integrator, "_KERNEL_LOADED", [False])
    for _ in range(2):
        integ.advance(np.array([0.1, 0.05]), 0.0, 1.0, 0.7)
    held = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
    assert held <= set(masks[0]) and not held & set(masks[1])
    assert not held & set(signal.pthread_sigmask(signal.SIG_BLOCK, []))
