"""The regularisation ladder: one orbit of a preload + friction law followed from ε = 0.1 down,
harmonics raised where the narrower step needs them, the ε-effect measured."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from rattle.analysis._regularisation import regularisation_limit
from rattle.continuation import NewtonOptions
from rattle.errors import ConvergenceError
from rattle.hb import HBOptions, RegularisedBalance

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "hb"))
from test_regularised import C, FM, FP, LAW, _solve  # noqa: E402


def _make(eps: float, H: int) -> RegularisedBalance:
    return RegularisedBalance(C, LAW, FM, (FP,), (0.3,), regularisation=eps, length_scale=0.3, frequency_scale=1.0,
                              options=HBOptions(harmonics=H))


def test_ladder_converges_as_eps_falls_and_raises_harmonics() -> None:
    w = 0.8
    q0 = _solve(_make(0.1, 16), w)
    lim = regularisation_limit(_make, w, q0, eps_start=0.1, eps_min=0.0125, harmonics=16, max_harmonics=128,
                               tail_tol=1e-6)
    eps = [s.eps for s in lim.steps]
    assert eps[0] == 0.1 and eps[-1] == pytest.approx(0.0125) and all(b < a for a, b in zip(eps, eps[1:]))
    H = [s.harmonics for s in lim.steps]
    assert H[0] > 16 and H == sorted(H)  # 16 harmonics do not resolve a step of width 0.1 L
    assert all(s.tail <= 1e-6 or s.harmonics == 128 for s in lim.steps)
    # each rung solves its own problem
    last = lim.last
    assert np.max(np.abs(_make(last.eps, last.harmonics).residual(last.q, w))) < 1e-10
    # the rms settles: the refinements change it less and less (measured 3.2e-5, 3.3e-5, 2.5e-5 of it)
    changes = [abs(b.rms - a.rms) / b.rms for a, b in zip(lim.steps, lim.steps[1:])]
    assert max(changes) < 1e-4 and lim.change == changes[-1]
    assert abs(lim.extrapolated_rms - last.rms) < 2 * abs(last.rms - lim.steps[-2].rms)


def test_ladder_reports_a_failed_start() -> None:
    with pytest.raises(ConvergenceError, match="did not converge"):
        regularisation_limit(_make, 0.8, np.full(_make(0.1, 16).size, 1e6), harmonics=16, max_harmonics=16,
                             newton=NewtonOptions(max_iterations=1))
    with pytest.raises(ValueError, match="eps_min"):
        regularisation_limit(_make, 0.8, np.zeros(33), eps_start=0.01, eps_min=0.1)


def test_richardson_is_trusted_only_where_the_last_rungs_are_linear_in_eps() -> None:
    from rattle.analysis._regularisation import RegularisationLimit, RegularisationStep

    def ladder(rms: list[float], eps: list[float]) -> RegularisationLimit:
        return RegularisationLimit(omega=1.0, steps=tuple(
            RegularisationStep(eps=e, harmonics=32, q=np.zeros(65), mean=0.0, rms=r, p2p=0.0, tail=0.0)
            for r, e in zip(rms, eps)))

    eps = [0.01, 0.005, 0.0025]
    lin = ladder([1.0 + 3.0 * e for e in eps], eps)  # rms = 1 + 3 ε: linear, the limit 1
    assert lin.linear and lin.extrapolated_rms == pytest.approx(1.0, rel=1e-12)
    quad = ladder([1.0 + 300.0 * e * e for e in eps], eps)  # quadratic: the slopes halve
    assert not quad.linear
    flat = ladder([1.0, 1.0 + 1e-12, 1.0 + 2e-12], eps)  # converged: nothing left to extrapolate
    assert flat.linear
    assert not ladder([1.0, 1.01], eps[:2]).linear  # two rungs do not show a line
    turn = ladder([1.0, 1.01, 1.0], eps)  # the change reverses
    assert not turn.linear


def test_the_rungs_are_the_schedules_whatever_steps_the_stepper_takes() -> None:
    """The ladder runs on ContinuationStepper in u = log ε with its rungs as stations: they are
    ε_k = ε_0 ratio^k down to ε_min exactly (the old hand-made ladder inserted rungs where Newton
    failed), each a converged orbit of its own ε."""
    w = 0.8
    q0 = _solve(_make(0.1, 64), w)
    lim = regularisation_limit(_make, w, q0, eps_start=0.1, eps_min=0.01, ratio=0.5, harmonics=64, max_harmonics=64,
                               tail_tol=np.inf)
    assert [s.eps for s in lim.steps] == [0.1, 0.05, 0.025, 0.0125, 0.01]
    for s in lim.steps:
        assert np.max(np.abs(_make(s.eps, 64).residual(s.q, w))) < 1e-9
    one = regularisation_limit(_make, w, q0, eps_start=0.1, eps_min=0.1, harmonics=64, max_harmonics=64)
    assert [s.eps for s in one.steps] == [0.1]


def test_stations_place_points_exactly_on_a_branch() -> None:
    """ContinuationStepper(stations=...): every station becomes an accepted point exactly there,
    in order; one on the range's far end ends the run (here R = q − p², followed down in p)."""
    from rattle.continuation import ContinuationOptions, ContinuationStepper

    class Parabola:
        size, length_scale, parameter_scale, force_scale = 1, 1.0, 1.0, 1.0

        def residual(self, q, p):  # type: ignore[no-untyped-def]
            return q - p * p

        def residual_jacobian(self, q, p):  # type: ignore[no-untyped-def]
            return q - p * p, np.eye(1), np.array([-2.0 * p])

    stations = (0.9, 0.55, 0.31, 0.2)
    st = ContinuationStepper(Parabola(), np.array([1.0]), 1.0, (0.2, 1.0), ContinuationOptions(initial_step=0.05),
                             stations=stations)
    pts = st.run()
    assert st.status.name == "SUCCESS" and pts[-1].p == 0.2
    on = [pt.p for pt in pts if pt.p in stations]
    assert on == list(stations) and all(abs(pt.q[0] - pt.p**2) < 1e-10 for pt in pts)
    with pytest.raises(ValueError, match="stations"):
        ContinuationStepper(Parabola(), np.array([1.0]), 1.0, (0.2, 1.0), stations=(1.5,))
