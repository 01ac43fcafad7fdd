"""Time-domain frequency sweeps (state carried over) and their columnar result."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import rattle
from rattle.analysis import time_sweep
from rattle.hb import HarmonicBalance, HBOptions, solve_harmonic_balance
from rattle.io import read_csv
from rattle.results import SWEEP_COLUMNS
from rattle.model import reference_case
from rattle.results import SweepResult
from rattle.analysis import SteadyStateOptions
from rattle.timeint import shoot_periodic_orbit

# The exact fold of the primary resonance's lower branch (shooting: the small orbit exists at
# Ω = 0.7540 and not at 0.7530).
EXACT_LOWER_FOLD = 0.7539


@pytest.fixture(scope="module")
def jump_sweep() -> SweepResult:
    """Both directions over the primary resonance's hysteresis window, 80 points."""
    return time_sweep(reference_case(), (0.5, 1.2), 80, "both")


def _primary_folds(frf) -> tuple[float, float]:
    folds = sorted(s.omega for s in frf.special_points if s.kind == "fold" and 0.7 < s.omega < 0.9)
    assert len(folds) == 2
    return folds[0], folds[1]


def test_up_sweep_drops_at_the_upper_fold_down_sweep_jumps_at_the_lower(jump_sweep, reference_frf):
    lower, upper = _primary_folds(reference_frf)
    assert upper == pytest.approx(0.8744, abs=2e-3) and lower == pytest.approx(EXACT_LOWER_FOLD, abs=2e-3)
    step = 0.7 / 79
    jumps = jump_sweep.jumps()
    assert [(j.direction, j.kind) for j in jumps] == [("up", "down"), ("down", "up")]
    up, down = jumps
    # Up: the large orbit is followed until the upper fold, then the sweep drops.
    assert up.omega_before <= upper + 1e-3 and up.omega_after >= upper - step
    assert up.rms_before > 0.45 and up.rms_after < 0.2
    # Down: the small orbit is followed down to (within one step of) the lower fold.
    assert down.omega_after <= lower + step and down.omega_before >= EXACT_LOWER_FOLD - step
    assert down.rms_before < 0.2 and down.rms_after > 0.3
    # Unpacks as (direction, omega_before, omega_after, rms_before, rms_after).
    direction, w0, w1, r0, r1 = up
    assert (direction, w0, w1, r0, r1) == ("up", up.omega_before, up.omega_after, up.rms_before, up.rms_after)


def test_hysteresis_window_holds_two_different_motions(jump_sweep):
    up, down = jump_sweep.select("up"), jump_sweep.select("down")
    np.testing.assert_array_equal(up.omega, down.omega[::-1])
    inside = (up.omega > 0.77) & (up.omega < 0.86)
    assert np.all(up.rms[inside] > down.rms[::-1][inside] + 0.1)
    outside = (up.omega < 0.74) | (up.omega > 0.89)
    np.testing.assert_allclose(up.rms[outside], down.rms[::-1][outside], rtol=0, atol=1e-9)


def test_period_one_rms_equals_the_stable_hb_branch(reference_frf):
    """Where the sweep is period 1 its rms is that of the HB solution at the same Ω on the
    stable branch (HB with 32 harmonics: truncation error ≲ 2e-6 rad here), and exactly that of
    the shooting orbit started from the HB solution."""
    model = reference_case()
    sweep = time_sweep(model, (0.1, 3.0), 40, "both")
    hb = HarmonicBalance(model, HBOptions(harmonics=32))
    frf = reference_frf
    stable = np.flatnonzero(frf.stable & (frf.period == 1))
    checked = 0
    for w, rms, period, x in zip(sweep.omega, sweep.rms, sweep.period, sweep.state0):
        if period != 1:
            continue
        # the stable HB point closest in (Ω, rms): the branch the sweep is on
        i = stable[np.argmin(np.abs(frf.omega[stable] - w) + np.abs(frf.rms[stable] - rms))]
        sol = solve_harmonic_balance(hb, frf.coefficients[i], float(w))
        assert sol.converged
        q = sol.q
        rms_hb = math.sqrt(q[0] ** 2 + 0.5 * np.sum(q[1:] ** 2))
        assert rms == pytest.approx(rms_hb, abs=5e-6), w
        # Shooting from the HB orbit's start (δ(0), δ'(0)) lands on the sweep's orbit.
        H = (q.size - 1) // 2
        k = np.arange(1, H + 1)
        guess = (q[0] + np.sum(q[1 : H + 1]), float(np.sum(k * w * q[H + 1 :])))
        orbit = shoot_periodic_orbit(model, float(w), guess)
        assert orbit.converged and orbit.stable
        assert rms == pytest.approx(orbit.rms, abs=1e-9)
        np.testing.assert_allclose(x, orbit.state0, rtol=0, atol=1e-9)
        checked += 1
    assert checked >= 60


def test_subharmonic_and_point_a_are_not_period_one():
    model = reference_case()
    sweep = time_sweep(model, (1.3, 1.5), 5, "both")
    np.testing.assert_array_equal(sweep.period, 2)  # point "B": the 1/2 sub-harmonic
    sweep = time_sweep(model, (0.42, 0.45), 4, "both")
    np.testing.assert_array_equal(sweep.period, 2)  # point "A": period doubled


def test_without_acceleration_the_sweep_is_the_same():
    model = reference_case()
    fast = time_sweep(model, (0.6, 1.0), 12, "both")
    slow = time_sweep(model, (0.6, 1.0), 12, "both", options=SteadyStateOptions(accelerate=False))
    np.testing.assert_array_equal(fast.period, slow.period)
    np.testing.assert_allclose(fast.rms, slow.rms, rtol=0, atol=1e-7)
    assert np.sum(fast.periods + fast.shooting_periods) < np.sum(slow.periods)


def test_two_workers_give_identical_results_and_report_progress():
    model = reference_case()
    serial_calls: list[tuple[int, int]] = []
    parallel_calls: list[tuple[int, int]] = []
    serial = time_sweep(model, (0.7, 0.9), 8, "both", callback=lambda d, t: serial_calls.append((d, t)))
    parallel = time_sweep(model, (0.7, 0.9), 8, "both", workers=2,
                          callback=lambda d, t: parallel_calls.append((d, t)))
    for name in ("direction", "omega", "period", "settled", "method", "periods", "shooting_periods"):
        np.testing.assert_array_equal(getattr(parallel, name), getattr(serial, name))
    for name in ("mean", "rms", "rms_ac", "p2p", "acc_p2p", "delta_min", "delta_max", "state0",
                 "final_state", "multipliers"):
        np.testing.assert_array_equal(getattr(parallel, name), getattr(serial, name))  # bitwise
    assert serial_calls == [(i, 16) for i in range(1, 17)]
    assert parallel_calls == [(i, 16) for i in range(1, 17)]
    assert parallel.settings["workers"] == 2 and serial.settings["workers"] == 1


def test_directions_start_from_rest():
    model = reference_case()
    both = time_sweep(model, (0.8, 1.0), 3, "both")
    down = time_sweep(model, (0.8, 1.0), 3, "down")
    up = time_sweep(model, (0.8, 1.0), 3, "up")
    assert list(both.direction) == ["up"] * 3 + ["down"] * 3
    np.testing.assert_array_equal(both.omega, [0.8, 0.9, 1.0, 1.0, 0.9, 0.8])
    np.testing.assert_array_equal(both.select("down").rms, down.rms)
    np.testing.assert_array_equal(both.select("up").rms, up.rms)
    assert down.directions == ("down",) and both.directions == ("up", "down")


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"direction": "sideways"}, ValueError, r"`direction` must be one of 'up', 'down', 'both'"),
        ({"points": 1}, ValueError, r"`points` must be >= 2"),
        ({"points": 2.5}, TypeError, r"`points` must be an integer"),
        ({"omega": (1.0, 0.5)}, ValueError, r"`omega` must satisfy 0 < min < max"),
        ({"omega": (0.0, 1.0)}, ValueError, r"`omega` must satisfy 0 < min < max"),
        ({"omega": (0.1, math.nan)}, ValueError, r"`omega` must be finite"),
        ({"omega": 3.0}, TypeError, r"`omega` must be a pair"),  # a wrong type: TypeError (shared rule)
        ({"workers": 0}, ValueError, r"`workers` must be >= 1"),
        ({"callback": 3}, TypeError, r"`callback` must be callable"),
        ({"options": {"tolerance": 1e-6}}, TypeError, r"`options` must be a SteadyStateOptions"),
        ({"tolerance": 1e-6}, TypeError, r"tolerance"),  # unknown keyword
    ],
)
def test_bad_input_is_refused(kwargs, error, match):
    args = {"omega": (0.5, 1.0), "points": 3, **kwargs}
    with pytest.raises(error, match=match):
        time_sweep(reference_case(), **args)


def test_result_columns_csv_and_metadata(jump_sweep, tmp_path):
    r = jump_sweep
    assert len(r) == 160
    assert tuple(r.columns()) == (*SWEEP_COLUMNS, "regime")
    row = r[0]
    assert tuple(row) == SWEEP_COLUMNS and row["direction"] == "up" and row["omega"] == 0.5
    path = r.to_csv(tmp_path / "sweep.csv")
    assert path.read_text().splitlines()[0] == ",".join((*SWEEP_COLUMNS, "regime"))
    back = read_csv(path)
    np.testing.assert_array_equal(back["omega"], r.omega)
    np.testing.assert_array_equal(back["rms"], r.rms)
    np.testing.assert_array_equal(back["period"], r.period)
    assert list(back["direction"]) == list(r.direction)
    assert list(back["regime"]) == list(r.regime)
    meta = r.metadata()
    json.dumps(meta)  # JSON-serialisable
    assert meta["settings"]["points"] == 80 and meta["settings"]["direction"] == "both"
    assert meta["settings"]["steady_state"]["tolerance"] == 1e-8
    assert len(meta["jumps"]) == 2 and meta["timings"]["total"] > 0
    text = r.summary()
    assert "up sweep" in text and "down sweep" in text and "jumps:" in text
    assert "SweepResult(" in repr(r) and "jumps at" in repr(r)
    assert r.final_state.shape == (160, 2) and r.multipliers.shape == (160, 2)
    assert r.settled.all() and set(r.method) <= {"shooting", "simulation"}
    assert all(st.success for st in r.status) and set(r.status) <= {rattle.Status.CONVERGED, rattle.Status.SETTLED}
    with pytest.raises(ValueError, match="`direction`"):
        r.select("both")
    with pytest.raises(ValueError, match="`threshold`"):
        r.jumps(threshold=0.0)


def test_plot_delegates_to_the_plotting_layer(jump_sweep, monkeypatch):
    import rattle.plotting

    seen = {}

    def fake_sweep_plot(result, ax=None):
        seen["args"] = (result, ax)
        return "fig", "ax"

    monkeypatch.setattr(rattle.plotting, "sweep_plot", fake_sweep_plot, raising=False)
    assert jump_sweep.plot(ax="axes") == ("fig", "ax")
    assert seen["args"] == (jump_sweep, "axes")


def test_exported():
    assert rattle.analysis.time_sweep is time_sweep
    assert rattle.results.SweepResult is SweepResult


def test_every_row_has_the_regime_of_its_steady_motion(jump_sweep):
    """``regime`` (SPEC §1's vocabulary) of each row: from the breakpoints its trajectory crossed,
    the same as frf.csv's rule on the row's extremes for a continuous law; the reference clutch
    crosses its drive-side breakpoint only off resonance, both at the resonance's large orbit."""
    import dataclasses

    r = jump_sweep
    assert set(r.regime) <= {"no_impact", "single_sided", "double_sided"}
    from_extremes = dataclasses.replace(r, regime=None).regime  # frf.csv's rule, on delta_min/delta_max
    assert list(r.regime) == list(from_extremes)
    big = r.rms > 0.3
    assert big.any() and set(r.regime[big]) == {"double_sided"}
    assert "single_sided" in set(r.regime[~big])
    up = r.select("up")
    assert list(up.regime) == list(r.regime[r.direction == "up"])
