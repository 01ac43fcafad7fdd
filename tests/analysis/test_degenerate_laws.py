"""Near-degenerate laws (issue 28 item 6), as properties: a clutch whose first-stage slope α tends
to 0 (almost a backlash) and a clearance b tending to 0 (almost linear) give the limit's answer —
the same special points and resonance peak within the size of the degeneracy's own effect — or a
refusal naming the argument and its rule; never a crash, a hang or a silently different response.

Before the fix the continuation's length scale was the quasi-static amplitude on the softest
stage, F_a / (k α): 3·10⁷ rad for α = 1e-9 against an orbit of 0.5 rad, so its scaled tolerances
saw no orbit. α = 1e-4 and 3e-5 then missed folds, α ≤ 1e-9 the whole resonance (peak rms 0.23
instead of 0.51), all with status SUCCESS; α = 1e-100 was refused as an overflowing deflection
scale naming the excitation. The scale now bounds an inner stage by its width
(``rattle._limits.quasi_static_deflection``).

The case: the reference clutch (I = K = 1, C = 0.05, b = 10°, F_m = 0.05, F_p = 0.03) on
Ω ∈ [0.6, 0.9] (its bent resonance: folds at 0.646, 0.698 and 0.835, period doublings at 0.640
and 0.657, peak rms 0.511) with H = 16 fixed, no sweep check: about 0.6 s a run. Each run is
bounded by the continuation's wall-time budget (a hang would end as an error, failing the test).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import rattle
from rattle.continuation import ContinuationOptions
from rattle.model import Backlash, Clutch, Excitation, Linear, Model

B = 0.174533  # the reference clutch's half-width, 10°
#: The wall-time budget of one run (s): a run takes ~0.6 s; a hang ends as ConvergenceError.
BUDGET = 30.0


def _model(law) -> Model:
    return Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=law, excitation=Excitation(mean=0.05, amplitudes=(0.03,)))


def _response(law, omega: tuple[float, float]):
    """(special points [(kind, Ω)], peak rms) of the response; raises on any failure (throw=True)."""
    frf = rattle.frequency_response(_model(law), omega=omega, harmonics=16, adaptive=None, check=None,
                                    continuation=ContinuationOptions(max_time=BUDGET))
    return [(s.kind, s.omega) for s in frf.special_points], float(np.max(frf.rms))


@pytest.fixture(scope="module")
def backlash_limit():
    return _response(Backlash(b=B), (0.6, 0.9))


@pytest.fixture(scope="module")
def linear_limit():
    return _response(Linear(), (0.8, 1.2))


def _refused_by_name(law_factory, name: str):
    """The law, or None after checking that its refusal names ``name`` and a rule."""
    try:
        return law_factory()
    except ValueError as exc:
        assert f"`{name}`" in str(exc) and "must" in str(exc), str(exc)
        return None


@settings(max_examples=4, deadline=None)  # each example is bounded by BUDGET (wall time) instead
@given(alpha=st.one_of(st.floats(-1e-3, 1e-3), st.builds(lambda e: 10.0 ** -e, st.floats(3.0, 323.0))))
@example(alpha=1e-3).via("issue 28")
@example(alpha=1e-4).via("issue 28")
@example(alpha=1e-6).via("issue 28")
@example(alpha=1e-9).via("issue 28")
@example(alpha=1e-12).via("issue 28")
@example(alpha=5e-324).via("the smallest double")
@example(alpha=-1e-300).via("refused")
def test_clutch_tends_to_the_backlash_as_alpha_tends_to_zero(backlash_limit, alpha):
    """Special points (kinds in order, Ω) and the peak rms of the clutch match the backlash
    (α = 0) within α's own effect. Measured against α = 0: the special points move by 1.3 α
    (1.3e-3 at α = 1e-3, 1.3e-6 at 1e-6, < 1e-7 from 1e-9 down), the peak by 0.1 α (9.8e-5 at
    α = 1e-3) plus the sampling of the maximum on different continuation points (6e-7): so
    |ΔΩ| ≤ 2 α + 1e-6 and |Δrms| ≤ 0.2 α + 5e-6."""
    law = _refused_by_name(lambda: Clutch(alpha=alpha, b=B), "alpha")
    if law is None:
        assert alpha < 0
        return
    points, peak = _response(law, (0.6, 0.9))
    ref_points, ref_peak = backlash_limit
    assert [k for k, _ in points] == [k for k, _ in ref_points]
    a = abs(alpha)
    assert max(abs(w - w0) for (_, w), (_, w0) in zip(points, ref_points)) <= 2.0 * a + 1e-6
    assert abs(peak - ref_peak) <= 0.2 * a + 5e-6


@settings(max_examples=4, deadline=None)
@given(b=st.one_of(st.just(0.0), st.builds(lambda e: 10.0 ** -e, st.floats(4.0, 323.0))),
       clutch=st.booleans())
@example(b=1e-3, clutch=False).via("a 1 mrad backlash")
@example(b=1e-12, clutch=True).via("issue 28")
@example(b=5e-324, clutch=False).via("the smallest double")
def test_a_clearance_tending_to_zero_tends_to_the_linear_response(linear_limit, b, clutch):
    """A backlash or a clutch (α = 0.25) of half-width b → 0 is the linear spring: no special
    points and the linear peak rms (0.4273) within b's own effect — measured 4.8e-4 for the
    backlash and 3.5e-4 for the clutch at b = 1e-3, 4e-7 at 1e-6 — so |Δrms| ≤ b + 5e-6. b = 0
    is refused naming `b` (a backlash of no width is `Linear`)."""
    law = _refused_by_name(lambda: Clutch(alpha=0.25, b=b) if clutch else Backlash(b=b), "b")
    if law is None:
        assert b <= 0
        return
    points, peak = _response(law, (0.8, 1.2))
    assert points == linear_limit[0] == []
    assert abs(peak - linear_limit[1]) <= b + 5e-6
    # the linear peak itself: sqrt(F_m² + (F_p / (c Ω))² / 2) at Ω ≈ 1 (rms includes the mean)
    assert linear_limit[1] == pytest.approx(math.sqrt(0.05**2 + (0.03 / 0.05) ** 2 / 2), rel=2e-3)


def test_the_length_scale_of_a_nearly_flat_inner_stage_is_the_motions():
    """The cause, for the single equation and for a chain: the scale of a clutch of α → 0 stays
    the size of its backlash's (at most the width of the gap plus the amplitude on the outer
    stages, w + F_a / (k s_out)), not F_a / (k α)."""
    ref = _model(Backlash(b=B)).length_scale()
    assert ref == pytest.approx(B + 0.05, rel=1e-12)  # the static deflection b + F_m / k
    for alpha in (1e-3, 1e-9, 1e-300, 5e-324):
        assert ref <= _model(Clutch(alpha=alpha, b=B)).length_scale() <= 2 * B + 0.03 + 1e-12 < 2 * ref

    def chain(law):
        return rattle.Chain(inertias=(1.0, 2.0), links=(rattle.Link(between=(1, 2), damping=0.05),),
                            elements=(rattle.Element(name="clutch", between=(1, 2), stiffness=1.0, law=law),),
                            torques=(rattle.Torque(inertia=1, mean=0.05, amplitudes=(0.03,)),
                                     rattle.Torque(inertia=2, mean=-0.05)))
    ref = chain(Backlash(b=B)).length_scale()
    for alpha in (1e-3, 1e-9, 1e-300, 5e-324):
        assert ref <= chain(Clutch(alpha=alpha, b=B)).length_scale() < 2 * ref
