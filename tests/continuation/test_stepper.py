"""Continuation: closed-form linear branch, budgets, failure status, both start ends."""

from __future__ import annotations

import re

import numpy as np
import pytest

from rattle import ContinuationOptions, ConvergenceError, Status, frequency_response, linear_frequency_response
from rattle.continuation import ContinuationStepper
from rattle.hb import HarmonicBalance, HBOptions, NewtonOptions
from rattle.model import Excitation, Linear, Model, reference_case


def _linear_model():
    return Model(inertia=2.0, damping=0.1, stiffness=2.0, elastic=Linear(),
                 excitation=Excitation(mean=0.1, amplitudes=(0.03, 0.01), phases=(0.0, 1.0)))


@pytest.mark.parametrize("start", ["low", "high"])
def test_linear_branch_equals_closed_form(start):
    model = _linear_model()
    frf = frequency_response(model, omega=(0.2, 2.5), harmonics=4, start=start)
    assert frf.status is Status.SUCCESS
    assert {frf.omega.min(), frf.omega.max()} == {0.2, 2.5}  # ends placed exactly on the bounds
    lin = linear_frequency_response(model, frf.omega)
    # HB with the excited harmonics kept is exact for a linear law: agreement to round-off.
    np.testing.assert_allclose(frf.rms, lin.rms, rtol=1e-12)
    np.testing.assert_allclose(frf.mean, lin.mean, rtol=1e-12)
    assert np.all(frf.stable)
    assert not any(frf.bifurcation)
    # Steps adapt: the resonance at Ω = 1 is resolved more finely than the flanks.
    d = np.abs(np.diff(frf.omega))
    near = np.abs(frf.omega[1:] - 1.0) < 0.05
    assert d[near].mean() < 0.5 * d[~near].mean()


def test_start_from_high_end_gives_the_same_curve(reference_frf, reference_model):
    down = frequency_response(reference_model, omega=(0.1, 3.0), harmonics=32, start="high")
    assert down.status is Status.SUCCESS
    assert down.omega[0] == 3.0 and down.omega[-1] == 0.1
    # The same special points are found, in reverse order, at the same frequencies to within
    # the spacing of the computed points (both runs label the point nearest the change).
    def spacing(frf, i):
        lo, hi = max(i - 1, 0), min(i + 1, len(frf) - 1)
        return max(abs(frf.omega[hi] - frf.omega[i]), abs(frf.omega[i] - frf.omega[lo]))

    up = list(reference_frf.special_points)
    dn = list(down.special_points)[::-1]
    assert [s.kind for s in up] == [s.kind for s in dn]
    for a, b in zip(up, dn):
        assert abs(a.omega - b.omega) <= spacing(reference_frf, a.index) + spacing(down, b.index)


def test_point_budget_ends_with_status_and_keeps_points(reference_model):
    opts = ContinuationOptions(max_points=50)
    frf = frequency_response(reference_model, omega=(0.1, 3.0), harmonics=16, continuation=opts, throw=False)
    assert frf.status is Status.MAX_STEPS
    assert len(frf) == 50
    assert "last Ω" in frf.message
    with pytest.raises(ConvergenceError, match="incomplete") as err:
        frequency_response(reference_model, omega=(0.1, 3.0), harmonics=16, continuation=opts)
    assert len(err.value.partial) == 50  # what was computed is kept


class _NoSolutionAbove(HarmonicBalance):
    """A problem whose residual is undefined above Ω = 0.5 (stands in for a corrector that
    cannot converge there, e.g. a solution that ceases to exist)."""

    def residual_jacobian(self, q, omega):
        R, Rq, Rw = super().residual_jacobian(q, omega)
        if omega > 0.5:
            R = R * np.nan
        return R, Rq, Rw


def test_step_too_small_is_reported_with_where_and_why(reference_model):
    hb = _NoSolutionAbove(reference_model, HBOptions(harmonics=16))
    stepper = ContinuationStepper(hb, hb.linear_solution(0.1), 0.1, (0.1, 3.0),
                                  ContinuationOptions(min_step=1e-4, max_step=0.05))
    points = stepper.run()
    assert stepper.status is Status.STEP_TOO_SMALL
    assert re.search(r"Newton failed to converge beyond Ω = 0\.49\d+ with step", stepper.message)  # where, why
    # Everything up to the failure is kept, and the last point is just below 0.5.
    assert len(points) > 5 and 0.49 < points[-1].omega <= 0.5
    # The halving of the step from its last value down to the floor is bounded.
    assert stepper.rejected < 40


def test_time_budget(reference_model):
    opts = ContinuationOptions(max_time=1e-9)
    frf = frequency_response(reference_model, omega=(0.1, 3.0), harmonics=16, continuation=opts, throw=False)
    assert frf.status is Status.MAX_TIME and len(frf) >= 1


def test_stepper_is_an_iterator_level_api(reference_model):
    hb = HarmonicBalance(reference_model, HBOptions(harmonics=16))
    stepper = ContinuationStepper(hb, hb.linear_solution(0.1), 0.1, (0.1, 0.5))
    first = stepper.step()
    assert first is not None and first.omega == 0.1
    n = 1
    while stepper.step() is not None:
        n += 1
    assert stepper.status is Status.SUCCESS and len(stepper.points) == n
    assert stepper.points[-1].omega == 0.5
    assert stepper.step() is None  # finished: stays finished


@pytest.mark.parametrize("kwargs, match", [
    (dict(min_step=0.1, initial_step=0.01), "min_step <= initial_step"),
    (dict(max_turn=2.0), "max_turn"),
    (dict(max_points=0), "max_points"),
    (dict(max_time=-1.0), "max_time"),
    (dict(target_turn=0.5, max_turn=0.3), "target_turn"),
])
def test_options_validation(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ContinuationOptions(**kwargs)


@pytest.mark.parametrize("kwargs, match", [
    (dict(omega=(1.0, 0.5)), r"`omega` must satisfy 0 < min < max"),
    (dict(omega=(0.0, 1.0)), r"`omega` must satisfy 0 < min < max"),
    (dict(omega=(0.1, float("nan"))), r"`omega` must be finite"),
    (dict(omega="0.1-3"), r"`omega` must be a pair"),
    (dict(start="middle"), r"`start` must be one of 'low', 'high', 'both'"),
    (dict(stability="eig"), r"`stability` must be"),
])
def test_front_end_argument_validation(kwargs, match):
    # A string for `omega` is a wrong type: TypeError (the shared rule); the others ValueError.
    with pytest.raises(TypeError if isinstance(kwargs.get("omega"), str) else ValueError, match=match):
        frequency_response(reference_case(), **kwargs)


def test_unknown_keyword_raises():
    with pytest.raises(TypeError):
        frequency_response(reference_case(), omega=(0.1, 1.0), harmonic=8)  # type: ignore[call-arg]


def test_frequency_response_stopped_by_a_failing_corrector_says_to_raise_the_harmonics(reference_model, monkeypatch):
    from rattle.analysis import _frequency_response as frf_module
    from rattle.analysis import _stretches as harmonics_module

    monkeypatch.setattr(frf_module, "HarmonicBalance", _NoSolutionAbove)
    monkeypatch.setattr(harmonics_module, "HarmonicBalance", _NoSolutionAbove)
    frf = frequency_response(reference_model, omega=(0.1, 3.0), harmonics=16, throw=False, adaptive=None,
                             continuation=ContinuationOptions(min_step=1e-4, max_step=0.05))
    assert frf.status is Status.STEP_TOO_SMALL
    assert "give more harmonics (e.g. 32)" in frf.message
    assert frf.omega.max() <= 0.5  # what was computed is kept
    # the rest of the range is named: no start at the high end either (no solution above 0.5)
    (gap,) = frf.settings["uncovered"]
    assert 0.49 < gap[0] <= 0.5 and gap[1] == 3.0 and "not covered by any branch: Ω = 0.49" in frf.message


def test_a_failing_corrector_raises_the_harmonics_on_that_stretch(reference_model, monkeypatch):
    """With H adapting (the default), the branch goes on from the failure with 2H, 4H … up to
    max_harmonics; a problem that has no solution there with any H still ends, naming it."""
    from rattle.analysis import AdaptiveHarmonics
    from rattle.analysis import _frequency_response as frf_module
    from rattle.analysis import _stretches as harmonics_module

    monkeypatch.setattr(frf_module, "HarmonicBalance", _NoSolutionAbove)
    monkeypatch.setattr(harmonics_module, "HarmonicBalance", _NoSolutionAbove)
    frf = frequency_response(reference_model, omega=(0.1, 3.0), harmonics=16, throw=False,
                             adaptive=AdaptiveHarmonics(max_harmonics=64),
                             continuation=ContinuationOptions(min_step=1e-4, max_step=0.05))
    assert frf.status is Status.STEP_TOO_SMALL
    stretches = frf.settings["branches"][0]["stretches"]
    assert [s["harmonics"] for s in stretches] == [16, 32, 64]
    assert set(np.unique(frf.extra_columns["harmonics"]).tolist()) <= {16, 32, 64}
    assert "with up to 64 harmonics" in frf.message
