"""Elastic laws: invariants (hypothesis) and validation messages."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rattle.model import Backlash, Clutch, Excitation, Linear, Model, Piecewise, Unilateral, reference_case


@st.composite
def piecewise_laws(draw):
    k = draw(st.integers(min_value=1, max_value=5))
    d = sorted(draw(st.lists(st.floats(-1.5, 1.5, allow_nan=False), min_size=k, max_size=k, unique=True)))
    if any(b - a < 1e-6 for a, b in zip(d, d[1:])):
        d = list(np.linspace(-1.0, 1.0, k))
    slopes = draw(st.lists(st.floats(0.0, 3.0, allow_nan=False), min_size=k + 1, max_size=k + 1))
    slopes[0] = max(slopes[0], 0.05)
    slopes[-1] = max(slopes[-1], 0.05)
    return Piecewise(breakpoints=tuple(d), slopes=tuple(slopes))


@given(piecewise_laws())
@settings(max_examples=60, deadline=None)
def test_piecewise_is_continuous_with_f0_zero(law):
    assert law.force(0.0) == 0.0
    for d in law.stages.breakpoints:
        eps = 1e-9 * max(1.0, abs(d))
        # Continuity: the jump across a breakpoint is at most slope × 2 eps (round-off scale).
        assert abs(law.force(d + eps) - law.force(d - eps)) <= 3 * 2 * eps + 1e-12


@given(piecewise_laws(), st.floats(-3, 3, allow_nan=False))
@settings(max_examples=60, deadline=None)
def test_stiffness_is_the_slope_of_force(law, x):
    # Away from breakpoints a central difference of f equals ∂f/∂δ (f is linear there).
    h = 1e-7
    if np.min(np.abs(law.stages.breakpoints - x)) > 2 * h:
        num = (law.force(x + h) - law.force(x - h)) / (2 * h)
        assert num == pytest.approx(float(law.stiffness(x)), abs=1e-6)


@given(st.floats(1e-4, 1.0), st.floats(-0.999, 0.999))
@settings(max_examples=40, deadline=None)
def test_backlash_has_zero_force_in_the_gap(b, frac):
    law = Backlash(b=b)
    assert law.force(frac * b) == 0.0
    assert law.force(2 * b) == pytest.approx(b)
    assert law.force(-2 * b) == pytest.approx(-b)


def test_clutch_matches_definition():
    law = Clutch(alpha=0.25, b=0.2)
    x = np.array([-0.5, -0.2, -0.1, 0.0, 0.1, 0.2, 0.5])
    expected = np.where(np.abs(x) <= 0.2, 0.25 * x, x - 0.75 * 0.2 * np.sign(x))
    np.testing.assert_allclose(law.force(x), expected, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(law.stiffness(np.array([-0.3, 0.0, 0.3])), [1.0, 0.25, 1.0])


def test_linear_law():
    x = np.linspace(-1, 1, 5)
    np.testing.assert_array_equal(Linear().force(x), x)
    assert Linear().stages.breakpoints.size == 0


def test_stage_arrays_are_read_only():
    law = Clutch(alpha=0.25, b=0.2)
    with pytest.raises(ValueError):
        law.stages.slopes[0] = 2.0


@pytest.mark.parametrize(
    "build, match",
    [
        (lambda: Backlash(b=0.0), r"`b` \(backlash\) must be > 0"),
        (lambda: Backlash(b=float("nan")), r"`b` must be finite"),
        (lambda: Clutch(alpha=1.0, b=0.1), r"`alpha` .* 0 <= alpha < 1"),
        (lambda: Clutch(alpha=0.2, b=-0.1), r"`b` \(clutch"),
        (lambda: Clutch(alpha=True, b=0.1), r"`alpha` must be a real number"),
        (lambda: Piecewise(breakpoints=(0.1, 0.0), slopes=(1, 1, 1)), r"`breakpoints` must be strictly increasing"),
        (lambda: Piecewise(breakpoints=(0.1,), slopes=(1, 1, 1)), r"`slopes` must have one more entry"),
        (lambda: Piecewise(breakpoints=(0.1,), slopes=(1, -1)), r"`slopes\[1\]` must be >= 0"),
        (lambda: Piecewise(breakpoints=(0.1,), slopes=(0.0, 0.0)), r"`slopes` must have at least one stage with slope > 0"),
        (lambda: Unilateral(gap=-0.01), r"`gap` must be >= 0"),
        (lambda: Unilateral(gap=0.01, side="left"), r"`side` must be \"positive\" or \"negative\""),
        (lambda: Piecewise(breakpoints="ab", slopes=(1.0,)), r"`breakpoints` must be a list"),
        (lambda: Excitation(mean=0.0, amplitudes=()), r"`amplitudes` must hold at least one"),
        (lambda: Excitation(mean=0.0, amplitudes=(1.0,), phases=(0.0, 1.0)), r"`phases` must have one entry"),
        (lambda: Excitation(mean=math.inf, amplitudes=(1.0,)), r"`mean` must be finite"),
    ],
)
def test_invalid_laws_are_refused_with_a_clear_message(build, match):
    with pytest.raises((ValueError, TypeError), match=match):
        build()


@pytest.mark.parametrize(
    "field, value, match",
    [
        ("inertia", 0.0, r"`inertia` must be > 0"),
        ("stiffness", -1.0, r"`stiffness` must be > 0"),
        ("damping", -0.1, r"`damping` must be >= 0"),
        ("inertia", "1", r"`inertia` must be a real number"),
    ],
)
def test_invalid_model_is_refused(field, value, match):
    kwargs = dict(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Linear(), excitation=Excitation(mean=0.0, amplitudes=(0.1,)))
    kwargs[field] = value
    with pytest.raises((ValueError, TypeError), match=match):
        Model(**kwargs)


def test_model_is_frozen_and_picklable():
    m = reference_case()
    with pytest.raises(AttributeError):
        m.damping = 1.0  # type: ignore[misc]
    assert pickle.loads(pickle.dumps(m)) == m


def test_reference_case_coefficients_and_equilibrium():
    m = reference_case()
    assert m.c == 0.05 and m.k == 1.0 and m.zeta == pytest.approx(0.025)
    # F_m = f(δ_s) on the second stage: δ_s − (1 − α) b = F_m.
    assert m.static_equilibrium() == pytest.approx(0.05 + 0.75 * math.radians(10.0), rel=1e-15)
    assert m.static_equilibrium() > math.radians(10.0)  # "its mean operating point lies on the second stage"


def test_clutch_alpha_zero_is_the_backlash():
    """α = 0 (a design map varies α from 0) is the backlash law of the same gap, exactly."""
    from rattle.model import Backlash, Clutch

    d = np.linspace(-0.6, 0.6, 241)
    np.testing.assert_array_equal(Clutch(alpha=0.0, b=0.2).force(d), Backlash(b=0.2).force(d))
    np.testing.assert_array_equal(Clutch(alpha=0.0, b=0.2).stiffness(d), Backlash(b=0.2).stiffness(d))
