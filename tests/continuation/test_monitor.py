"""The test-function monitor: no bifurcation stepped over, no step restricted for nothing.

Unit checks of ``check_segment`` on analytic test functions, of the Floquet monitor's slopes
against central differences along the branch, of the overflow-free stage matrices, and the
regression of the issue: the gear example at default settings stepped over a period-doubling
pair (exact: Ω = 0.64016 and 0.65668) whose sign changes cancelled within one step.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

import rattle
from rattle.continuation import ContinuationOptions, ContinuationStepper, MonitorReading, check_segment
from rattle.hb import HarmonicBalance, HBOptions, NewtonOptions
from rattle.stability import FloquetMonitor, stage_transition

OPTS = dict(tolerance=0.5, max_change=1.0, resolved=False)


def _reading(psi, slope, structure=(2, 2), distance=1.0):
    return MonitorReading(np.array([psi]), np.array([slope]), structure, distance)


def test_hidden_pair_is_rejected():
    # ψ(s) = (s − 0.4)(s − 0.6) on [0, 1]: positive at both ends, two zeros inside.
    psi = lambda s: (s - 0.4) * (s - 0.6)  # noqa: E731
    dpsi = lambda s: 2 * s - 1.0  # noqa: E731
    v = check_segment(_reading(psi(0), dpsi(0)), _reading(psi(1), dpsi(1)), 1.0, **OPTS)
    assert not v.accept and "hidden pair" in v.reason
    # ... and accepted once the step is at the resolution floor (nothing more can be resolved).
    v = check_segment(_reading(psi(0), dpsi(0)), _reading(psi(1), dpsi(1)), 1.0, **dict(OPTS, resolved=True))
    assert v.accept


def test_far_from_zero_is_not_restricted():
    # ψ = 10 + 0.1 s: far from zero compared with its variation: the step may double.
    v = check_segment(_reading(10.0, 0.1), _reading(10.1, 0.1), 1.0, **OPTS)
    assert v.accept and v.factor == pytest.approx(2.0)


def test_single_crossing_is_accepted_and_triple_rejected():
    v = check_segment(_reading(0.5, -1.0), _reading(-0.5, -1.0), 1.0, **OPTS)
    assert v.accept
    # Cubic with three zeros in (0, 1): (s − 0.2)(s − 0.5)(s − 0.8), one sign change at the ends.
    c = np.poly([0.2, 0.5, 0.8])
    d = np.polyder(c)
    v = check_segment(_reading(np.polyval(c, 0), np.polyval(d, 0)), _reading(np.polyval(c, 1), np.polyval(d, 1)), 1.0, **OPTS)
    assert not v.accept


def test_near_the_unit_circle_the_step_never_grows():
    # ψ = 1 − s²: modelled exactly by the cubic, so the step could double — unless a multiplier
    # is near its critical value at the new point.
    far = check_segment(_reading(1.0, 0.0), _reading(0.19, -1.8, distance=0.5), 0.9, **OPTS)
    near = check_segment(_reading(1.0, 0.0), _reading(0.19, -1.8, distance=0.05), 0.9, **OPTS)
    assert far.accept and near.accept
    assert far.factor > 1.0 and near.factor <= 1.0


def test_curvature_towards_zero_holds_the_step_back():
    # ψ = 1 − s⁴ on [0, 0.9]: the quadratic models disagree with the cubic, and the error
    # estimate is a good part of the distance from zero: the step grows less than where ψ is
    # linear (ψ = 1 − 0.7 s, same end values), where it may double.
    curved = check_segment(_reading(1.0, 0.0), _reading(1 - 0.9**4, -4 * 0.9**3), 0.9, **OPTS)
    linear = check_segment(_reading(1.0, -0.729), _reading(1 - 0.9**4, -0.729), 0.9, **OPTS)
    assert curved.accept and linear.accept
    assert curved.factor < 1.5 and linear.factor == pytest.approx(2.0)


def test_kink_near_zero_is_rejected_but_not_far_from_it():
    a, b = _reading(0.05, 0.0, (2, 2)), _reading(0.3, 0.0, (2, 4))
    assert not check_segment(a, b, 0.1, **OPTS).accept
    a, b = _reading(5.0, 0.0, (2, 2)), _reading(5.1, 0.0, (2, 4))
    assert check_segment(a, b, 0.1, **OPTS).accept


def test_stage_transition_matches_expm_including_overdamped():
    for kappa, c, tau in [(1.0, 0.05, 2.0), (0.25, 0.05, 7.0), (0.0, 0.05, 3.0), (1.0, 2.0, 1.5),
                          (1e-4, 40.0, 3.0), (2.0, 1e3, 0.01), (1.0, 0.0, 1.0)]:
        A = np.array([[0.0, 1.0], [-kappa, -c]])
        np.testing.assert_allclose(stage_transition(np.array(kappa), c, np.array(tau)), scipy.linalg.expm(A * tau),
                                   rtol=1e-10, atol=1e-14)


def test_overdamped_model_is_stable_with_finite_multipliers():
    # damping = 1e6: the stage exponentials are exp of huge negative arguments; reported NaN
    # multipliers and "unstable" everywhere before (cosh overflow times a vanishing e^{στ}).
    model = rattle.Model(inertia=1.0, damping=1e6, stiffness=1.0, elastic=rattle.Clutch(alpha=0.25, b=0.17),
                         excitation=rattle.Excitation(mean=0.05, amplitudes=(0.03,)))
    frf = rattle.frequency_response(model, omega=(0.5, 1.5), harmonics=8)
    assert np.all(np.isfinite(frf.multipliers))
    assert frf.stable.all()


def test_floquet_slopes_match_central_differences_along_the_branch():
    # The monitor's slope is a difference quotient off the branch along the tangent; here it is
    # checked against central differences between points corrected back onto the branch.
    from rattle.analysis import start_solution

    model = rattle.reference_case()
    hb = HarmonicBalance(model, HBOptions(harmonics=16))
    monitor = FloquetMonitor(hb)
    q0, _ = start_solution(hb, 0.6, NewtonOptions())
    stepper = ContinuationStepper(hb, q0, 0.6, (0.6, 0.7), ContinuationOptions(max_step=0.01), NewtonOptions(), monitor=monitor)
    points = stepper.run()
    corr = stepper.corrector
    h = 1e-5
    for b in points[1:12]:
        y, t = corr.to_scaled(b.q, b.omega), b.tangent
        values = []
        for sign in (1.0, -1.0):
            c = corr.correct(y + sign * h * t, t)
            q, w = corr.unscale(c.y)
            values.append(monitor(q, w, np.zeros_like(q), 0.0).values)
        central = (values[0] - values[1]) / (2 * h)
        np.testing.assert_allclose(b.reading.slopes, central, rtol=1e-3, atol=1e-6 * (1 + np.abs(b.reading.values).max()))


def test_gear_example_period_doubling_pair_at_default_settings():
    path = Path(__file__).resolve().parents[2] / "examples" / "gear_backlash.toml"
    model = rattle.Model.from_toml(path)
    frf = rattle.frequency_response(model, omega=(0.1, 3.0))
    found = {}
    for exact in (0.64016, 0.65668):
        sp = min((s for s in frf.special_points if s.kind == "period_doubling" and s.branch == 0),
                 key=lambda s: abs(s.omega - exact))
        assert abs(sp.omega - exact) < 1e-4, (exact, sp)
        found[exact] = sp.index
    # The rows between the pair (drawn stable before) are unstable: a multiplier below −1.
    lo, hi = sorted(found.values())
    assert hi - lo >= 2
    assert not frf.stable[lo + 1 : hi].any()
    assert np.all(frf.multipliers[lo + 1 : hi, 0].real < -1.0)


def test_a_step_over_which_two_test_functions_change_sign_is_rejected():
    from rattle.continuation._monitor import MonitorReading, check_segment

    a = MonitorReading(np.array([0.3, -0.2]), np.array([-1.0, 1.0]), (2,), 0.2)
    b = MonitorReading(np.array([-0.2, 0.3]), np.array([-1.0, 1.0]), (2,), 0.2)
    verdict = check_segment(a, b, 0.5, tolerance=0.5, max_change=1.0, resolved=False)
    assert not verdict.accept and "two test functions" in verdict.reason
    # One crossing alone is fine; at the resolution floor nothing is rejected.
    one = MonitorReading(np.array([-0.2, -0.3]), np.array([-1.0, -1.0]), (2,), 0.2)
    assert check_segment(MonitorReading(np.array([0.3, -0.2]), np.array([-1.0, -1.0]), (2,), 0.2), one, 0.5,
                         tolerance=0.5, max_change=1.0, resolved=False).accept
    assert check_segment(a, b, 0.5, tolerance=0.5, max_change=1.0, resolved=True).accept


def test_compiled_hermite_scan_is_the_array_code_to_the_last_bit(monkeypatch):
    # The step control reads the cubic model through the compiled scan (continuation._kernels):
    # the same floating-point operations as the array code, so the same verdicts and factors —
    # a continuation path depends on every bit of them.
    from rattle.continuation import _kernels, _monitor

    if not _kernels.AVAILABLE:
        pytest.skip("numba not available: the array code is used")
    rng = np.random.default_rng(7)
    for _ in range(3000):
        pa, ga, pb, gb = rng.standard_normal(4) * 10.0 ** rng.integers(-8, 4, 4)
        length = 10.0 ** rng.uniform(-5, 0)
        sign = 1.0 if pa > 0 else -1.0
        args = (pa, ga, pb, gb, length, sign, 0.5, _monitor._X, _monitor._X2)
        assert tuple(_kernels.hermite_scan(*args)) == _monitor._margins_array(*args)
    # NaN (an overflowing model) propagates through the minima as numpy.min does.
    args = (1e308, 1e308, -1e308, 1e308, 1.0, 1.0, 0.5, _monitor._X, _monitor._X2)
    with np.errstate(all="ignore"):
        got, ref = _kernels.hermite_scan(*args), _monitor._margins_array(*args)
    assert any(np.isnan(ref))
    assert [repr(x) for x in got] == [repr(x) for x in ref]
    # check_segment gives the same verdicts by either.
    cases = [((0.16, -1.0), (0.24, 1.0), 1.0), ((2.0, -0.5), (1.2, -0.3), 0.4), ((1e-3, -1e-2), (2e-3, 3e-2), 0.05)]
    verdicts = [check_segment(_reading(*a), _reading(*b), L, **OPTS) for a, b, L in cases]
    monkeypatch.setattr(_monitor, "_SCAN", _monitor._margins_array)
    assert [check_segment(_reading(*a), _reading(*b), L, **OPTS) for a, b, L in cases] == verdicts
