"""Exact shooting continuation, the default method for laws with jumps or friction
(:mod:`rattle.analysis._exact_branch`): every row an exact orbit of an independent integration,
special points located and labelled, a start anywhere in a range, the CLI's default.

References: the independent Filippov integrations of tests/_filippov.py (scipy DOP853, rtol 1e-12,
the mode logic written out again) — not the project's integrators.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from _cases import friction_chain, random_preload  # tests/ is on sys.path through its conftest
from _filippov import chain_reference, single_reference

import rattle
from rattle.analysis import RegularisationOptions, ShootingOptions
from rattle.errors import Status
from rattle.analysis._nonsmooth import nonsmooth_response
from rattle.analysis._exact_branch import start_state
from rattle.continuation import NewtonOptions
from rattle.model import Excitation, NonsmoothLaw, Preload, System
from rattle.results import FrictionCheck, NonsmoothCheck
from rattle.timeint import ShootingProblem

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("seed", range(6))
def test_every_row_is_an_exact_orbit_of_the_independent_integration(seed):
    """Random preload/friction laws: five rows spread over the branch, each integrated over its
    period by the independent reference from the row's z(0), come back to z(0) (the orbit is
    periodic to the reference's accuracy) and follow the row's trajectory at the reference's own
    output times to 1e-7 of the length scale: the same orbit, so the same rms (the rms is the
    trajectory's exact integral)."""
    system, omega = random_preload(seed)
    frf = nonsmooth_response(system, omega)
    assert isinstance(frf, NonsmoothCheck) and frf.followed == "exact shooting"
    assert frf.status.success, frf.message
    assert np.all(np.isnan(frf.rms_hb)) and np.all(frf.matched)
    L = system.length_scale()
    for i in np.unique(np.linspace(0, len(frf) - 1, 5).astype(int)):
        w, z0 = float(frf.omega[i]), frf.states[i]
        T = 2.0 * math.pi / w
        z1, ts, xs = single_reference(system, tuple(z0), T, w)
        assert abs(z1[0] - z0[0]) <= 1e-7 * L
        assert abs(z1[1] - z0[1]) <= 1e-7 * L * max(w, 1.0)
        traj = rattle.timeint.ExactIntegrator(system).propagate(z0, 0.0, T, w)
        d = traj.sample(ts)[0]
        assert np.max(np.abs(d - xs[0])) <= 1e-7 * L
        assert frf.rms[i] == pytest.approx(traj.mean_and_rms()[1], rel=1e-12)


@pytest.mark.slow
def test_a_chain_with_friction_rows_are_exact_orbits_of_the_independent_integration():
    fs = friction_chain()
    frf = nonsmooth_response(fs, (0.6, 0.66))
    assert isinstance(frf, FrictionCheck) and frf.followed == "exact shooting" and frf.status.success
    L = fs.length_scale()
    for i in (0, len(frf) // 2, len(frf) - 1):
        w, z0 = float(frf.omega[i]), frf.states[i]
        z1 = chain_reference(fs, z0, 2.0 * math.pi / w, w)
        assert np.max(np.abs(z1[: fs.n] - z0[: fs.n])) <= 1e-7 * L
        assert np.max(np.abs(z1[fs.n:] - z0[fs.n:])) <= 1e-7 * L * fs.frequency_scale()


def test_the_torque_converter_special_points_are_located_and_named():
    """examples/torque_converter_preload.toml: the special points the regularised HB placed between
    rows (its header) are located on the exact branch; at a smooth one (fold, period doubling) the
    critical multiplier is on the unit circle to 1e-6; the jump at the lower fold is a grazing
    (the exact branch turns where a pair of crossings of the jump vanishes)."""
    case = rattle.load_case(EXAMPLES / "torque_converter_preload.toml")
    frf = nonsmooth_response(case.model, case.analysis.omega)
    assert frf.status.success and frf.labels is not None
    found = [(str(frf.bifurcation[i]), float(frf.omega[i]), i) for i in np.flatnonzero(frf.bifurcation != "")]
    kinds = [k for k, _, _ in found]
    assert kinds.count("period_doubling") == 4 and kinds.count("fold") == 3 and "grazing" in kinds
    between = {"period_doubling": [(0.541, 0.547), (0.559, 0.564), (0.745, 0.752), (0.862, 0.868)],
               "fold": [(0.6244, 0.6248), (1.0192, 1.0196), (1.0247, 1.0251)]}
    for kind, spans in between.items():
        at = sorted(w for k, w, _ in found if k == kind)
        assert all(lo <= w <= hi for w, (lo, hi) in zip(at, spans)), (kind, at)
    for kind, _w, i in found:
        if kind in ("fold", "period_doubling"):
            target = 1.0 if kind == "fold" else -1.0
            mu = np.asarray(frf.multipliers[i])
            assert np.min(np.abs(mu - target)) <= 1e-6
    # the stability on either side of every located smooth point differs
    stable = np.asarray(frf.stable, dtype=bool)
    for kind, _w, i in found:
        if kind in ("fold", "period_doubling") and 0 < i < len(frf) - 1:
            assert stable[i - 1] != stable[i + 1]


@pytest.mark.parametrize("name", ["torque_converter_preload.toml", "clutch_friction.toml"])
def test_a_start_at_every_frequency_of_a_grid_succeeds(name):
    """The exact start (settled, then Newton on the period map) at 20 frequencies over each
    example's range."""
    case = rattle.load_case(EXAMPLES / name)
    problem = ShootingProblem(case.model)
    lo, hi = case.analysis.omega
    for w in np.linspace(lo, hi, 20):
        q = start_state(problem, float(w), ShootingOptions(), NewtonOptions())
        assert q is not None, w
        assert float(np.max(np.abs(problem.residual(q, float(w))))) <= 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("name", ["chain_lockup_clutch.toml", "chain_clutch_friction.toml"])
def test_a_chain_start_at_every_frequency_of_a_grid_succeeds(name):
    """The chain examples, 20 frequencies over each range (second tier: ~20 s and ~60 s). On the
    lock-up chain every orbit is unstable (the settled flow never reaches one): each start is Newton
    from the attractor or continued from a neighbouring frequency."""
    case = rattle.load_case(EXAMPLES / name)
    problem = ShootingProblem(case.model)
    lo, hi = case.analysis.omega
    for w in np.linspace(lo, hi, 20):
        q = start_state(problem, float(w), ShootingOptions(), NewtonOptions())
        assert q is not None, w
        assert float(np.max(np.abs(problem.residual(q, float(w))))) <= 1e-9, w


def test_shooting_and_the_regularised_hb_agree_where_both_apply():
    """The same branch by both methods: at every matched HB row, Newton on the period map from
    the shooting branch's state interpolated to that Ω converges to the HB row's exact orbit."""
    from rattle.analysis._exact_branch import damped_newton

    system, omega = random_preload(4)
    shot = nonsmooth_response(system, omega)
    hb = nonsmooth_response(system, omega, RegularisationOptions(harmonics=64, refine=None))
    problem = ShootingProblem(system)
    ok = np.flatnonzero(hb.matched)
    assert ok.size
    for i in ok[:: max(1, ok.size // 5)]:
        w = float(hb.omega[i])
        guess = np.array([np.interp(w, shot.omega, shot.states[:, k]) for k in range(2)])
        q = damped_newton(problem, guess, w, NewtonOptions())
        assert q is not None
        assert np.max(np.abs(q - hb.states[i]) / problem.length_scale) <= 1e-8


def test_options_are_validated():
    with pytest.raises(ValueError, match="settle_periods"):
        ShootingOptions(settle_periods=-1)
    with pytest.raises(ValueError, match="hops"):
        ShootingOptions(hops=(0.7,))
    with pytest.raises(TypeError, match="locate"):
        ShootingOptions(locate=1)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="check"):
        ShootingOptions(check=16)  # type: ignore[arg-type]


@pytest.mark.slow
def test_where_no_computed_orbit_is_stable_the_attractor_a_sweep_settles_on_is_continued():
    """A random preload (benchmarks/crossval_doors.py seed 1, case 13): the branch from Ω_min covers
    the range but is unstable over Ω 1.04–1.65, a small orbit (rms ~0.006), while exact sweeps
    settle there on a stable one of rms 0.1–0.3. By default the frequencies with no stable row are
    swept exactly and that attractor is continued: stable rows over that stretch, each an
    attractor — an exact simulation started next to the row settles back on it (rms to 1e-6).
    (Measured: with ``check=None`` the response has no stable row there.)"""
    from rattle.analysis import SteadyStateOptions, steady_state

    law = NonsmoothLaw(elastic=Preload(preload=0.0431))
    system = System.single(damping=0.0713, stiffness=1.0, law=law,
                             excitation=Excitation(mean=0.0215, amplitudes=(0.0369,)))
    res = nonsmooth_response(system, (0.3, 2.0))
    found = [b for b in (res, *res.branches)
             if np.sum((b.omega > 1.1) & (b.omega < 1.6) & b.stable & (b.rms > 0.05)) >= 20]
    assert found, "the stable attractor over Ω 1.1–1.6 is not on the response"
    frf = found[0]
    big = (frf.omega > 1.1) & (frf.omega < 1.6) & frf.stable & (frf.rms > 0.05)
    assert np.ptp(frf.omega[big]) > 0.4
    i = int(np.flatnonzero(big)[len(np.flatnonzero(big)) // 2])
    w = float(frf.omega[i])
    settled = steady_state(system, w, x0=tuple(frf.states[i] * (1.0 + 1e-3)),
                           options=SteadyStateOptions(max_period_multiple=1))
    assert settled.period == 1 and settled.rms == pytest.approx(float(frf.rms[i]), rel=1e-6)


def test_the_cli_default_for_a_preload_is_exact_shooting(tmp_path):
    from _cases import preload_spring_toml  # tests/ is on sys.path through its conftest
    from click.testing import CliRunner

    from rattle.cli.main import cli

    (tmp_path / "case.toml").write_text(preload_spring_toml((0.53, 0.575), 64, friction=None))
    result = CliRunner().invoke(cli, ["frf", str(tmp_path / "case.toml"), "-o", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    meta = json.loads((tmp_path / "out" / "frf.json").read_text())
    assert meta["settings"]["method"].startswith("exact shooting continuation")
    assert meta["analysis"]["method"] == "shooting"
    assert "exact shooting continuation" in result.output


def test_progress_reports_the_share_of_the_range_reached():
    system, omega = random_preload(1)
    seen: list[tuple[int, int]] = []
    frf = nonsmooth_response(system, omega, progress=lambda done, total: seen.append((done, total)))
    assert frf.status.success and seen
    done = [d for d, _ in seen]
    assert all(t == 1000 for _, t in seen) and done == sorted(done) and done[-1] >= 900
    with pytest.raises(TypeError, match="progress"):
        nonsmooth_response(system, omega, progress=3)  # type: ignore[arg-type]


def test_a_branch_that_turns_back_at_its_start_is_a_success_when_the_other_end_covers_the_range():
    """A preload (found by benchmarks/crossval_shooting_stability.py, case 12) whose branch from
    Ω_min turns at a fold 0.5 % into the range and leaves it where it started (RETURNED); the branch
    followed down from Ω_max covers the rest. The range is covered, so the response is a success
    (it was reported 'returned': `rattle frf` exit 1 on a complete answer)."""
    system = System.single(damping=0.0466905493687573, stiffness=1.0,
                             law=NonsmoothLaw(elastic=Preload(preload=0.012658012081765974, clearance=0.0,
                                                              slope=1.2245173475023938)),
                             excitation=Excitation(mean=0.04022804749269272,
                                                   amplitudes=(0.06456084894156201, 0.013303750724586439),
                                                   phases=(0.0, 3.4661445697704405)))
    lo, hi = 0.39240141644239235, 0.7848028328847847
    frf = rattle.frequency_response(system, omega=(lo, hi))
    first = frf.check
    assert float(np.max(first.omega)) < lo * 1.01 and "fold" in list(first.labels)  # it turned back
    assert frf.status is Status.SUCCESS, frf.message
    assert "the range is covered with the other branches" in frf.message
    om = np.asarray(frf.omega, dtype=float)
    assert om.min() <= lo * (1 + 1e-9) and om.max() >= hi * (1 - 1e-9)


@pytest.mark.slow
def test_the_branch_from_the_other_end_goes_on_where_it_is_another_orbit():
    """A random preload (benchmarks/crossval_doors.py --kinds preload,preload_friction --seed 11,
    case 04) over Ω 0.4–1: the branch from Ω_min (two crossings of the jump a period) ends at a
    grazing at Ω 0.47603; the branch from Ω_max (four crossings) reaches lower frequencies and
    carries there the stable orbit a run-up settles on at Ω 0.4744 (rms 0.056755, beside the first
    branch's 0.05765). It was stopped on entering the frequencies the first branch covered; now
    only where it joins it, so the stable orbit is on the response — and the exact simulation
    settles back on the row (rms to 1e-6)."""
    from rattle.analysis import SteadyStateOptions, steady_state

    system = System.single(damping=0.0465, stiffness=1.0, law=NonsmoothLaw(elastic=Preload(preload=0.0287)),
                             excitation=Excitation(mean=0.0681, amplitudes=(0.0447,)))
    w = 0.4744
    run_up = rattle.time_sweep(system, omega=(0.3, w), points=4, direction="up")
    assert int(run_up.period[-1]) == 1 and float(run_up.rms[-1]) == pytest.approx(0.056755, rel=1e-4)
    res = nonsmooth_response(system, (0.4, 1.0))
    rows = [(b, i) for b in (res, *res.branches) for i in np.flatnonzero(
        b.stable & (np.abs(b.omega - w) < 2e-3) & (np.abs(b.rms - float(run_up.rms[-1])) < 0.01 * float(run_up.rms[-1])))]
    assert len(rows) >= 2, "the stable orbit of the run-up at Ω 0.4744 is not on the response"
    b, i = min(rows, key=lambda r: abs(float(r[0].omega[r[1]]) - w))
    settled = steady_state(system, float(b.omega[i]), x0=tuple(b.states[i] * (1.0 + 1e-3)),
                           options=SteadyStateOptions(max_period_multiple=1))
    assert settled.period == 1 and settled.rms == pytest.approx(float(b.rms[i]), rel=1e-6)


def _preload_case(preload, damping, mean, amplitude, clearance=0.0, friction=None):
    law = NonsmoothLaw(elastic=Preload(preload=preload, clearance=clearance),
                       friction=None if friction is None else rattle.Friction(levels=friction))
    return System.single(damping=damping, stiffness=1.0, law=law,
                           excitation=Excitation(mean=mean, amplitudes=(amplitude,)))


@pytest.mark.slow
def test_an_attractor_next_to_an_unstable_orbit_is_found_and_continued():
    """A random preload (benchmarks/crossval_doors.py seed 21, case 03): beside the unstable rows
    of the branch from Ω_min (|μ| 5–20 over Ω 0.339–0.346) a stable orbit of eight crossings a
    period (rms 0.0299) lives over Ω 0.344–0.353, between the sweep check's frequencies. The
    unstable orbit pushed along its unstable eigenvector settles on it; it is continued, and the
    exact simulation started next to a row settles back on that row (rms to 1e-6)."""
    system = _preload_case(0.0277, 0.0455, 0.0311, 0.0482)
    res = nonsmooth_response(system, (0.3, 2.0))
    rows = [(b, i) for b in (res, *res.branches) for i in np.flatnonzero(
        b.stable & (b.omega > 0.345) & (b.omega < 0.352) & (np.abs(b.rms - 0.0299) < 0.01 * 0.0299))]
    assert len(rows) >= 3, "the stable orbit of rms 0.0299 over Ω 0.344–0.353 is not on the response"
    _settles_back(system, *rows[len(rows) // 2])


def _settles_back(system, branch, i):
    """The exact simulation started next to row i of ``branch`` settles back on that row (rms to 1e-6)."""
    from rattle.analysis import SteadyStateOptions, steady_state

    settled = steady_state(system, float(branch.omega[i]), x0=tuple(branch.states[i] * (1.0 + 1e-3)),
                           options=SteadyStateOptions(max_period_multiple=1))
    assert settled.period == 1 and settled.rms == pytest.approx(float(branch.rms[i]), rel=1e-6)


@pytest.mark.slow
def test_frequencies_no_branch_covers_are_started_in():
    """A random preload with stage friction (crossval_doors.py seed 21, case 14): the branch from
    Ω_min cannot start past a grazing at Ω 0.3529 and the branches the sweep check seeded each
    spent their budget, leaving Ω 0.988–1.0005 uncovered (exit 1). An exact start in the middle of
    what is uncovered, followed both ways until it joins, covers it: a success."""
    system = _preload_case(0.0431, 0.0311, 0.0281, 0.038, clearance=0.0435, friction=(0.0036, 0.0034, 0.0032))
    frf = rattle.frequency_response(system, omega=(0.3, 2.0))
    assert frf.status is Status.SUCCESS, frf.message
    assert not frf.uncovered


@pytest.mark.slow
def test_a_window_of_periodic_motion_between_chaotic_ones_is_found():
    """The same case: run-ups and run-downs settle on a stable orbit of rms 0.0582 at Ω 0.474,
    inside a stretch of non-periodic motion (Ω ≈ 0.39–0.52) that the sweep check's 16 frequencies
    a way see as non-periodic only (missed before). Its steps with a motion that is not period 1
    are swept again more finely, the state carried: the window's orbit is found and continued,
    and the exact simulation from next to its row settles back on it."""
    system = _preload_case(0.0431, 0.0311, 0.0281, 0.038, clearance=0.0435, friction=(0.0036, 0.0034, 0.0032))
    res = nonsmooth_response(system, (0.3, 2.0))
    rows = [(b, i) for b in (res, *res.branches) for i in np.flatnonzero(
        b.stable & (np.abs(b.omega - 0.47435) < 0.004) & (np.abs(b.rms - 0.058222) < 0.01 * 0.058222))]
    assert rows, "the stable orbit of rms 0.0582 at Ω 0.474 is not on the response"
    _settles_back(system, *rows[len(rows) // 2])


@pytest.mark.slow
def test_a_branch_that_retraces_its_own_arms_ends_there():
    """A random preload with stage friction (crossval_doors.py seed 31, case 09): over Ω
    0.357–0.388 the branch from Ω_min snakes through grazings, and the follower, hopping each,
    followed the same arms over and over until its piece budget (2000 rows, 20 s CPU, the range
    above left uncovered). A piece that runs on rows of the branch's earlier pieces ends it (the
    branch closed on itself); the other rules then cover the rest, and the motion a run-up
    settles on at Ω 0.3436 (rms 0.0978) is on a stable stretch."""
    system = _preload_case(0.0459, 0.06, 0.0577, 0.0446, clearance=0.073, friction=(0.0043, 0.0028, 0.0024))
    frf = rattle.frequency_response(system, omega=(0.3, 2.0))
    first = frf.omega[frf.branch == 0]
    assert first.size < 600, first.size  # 2000+ rows when it went round
    assert np.any(frf.stable & (np.abs(frf.omega - 0.34358) < 0.003) & (np.abs(frf.rms - 0.097835) < 0.01 * 0.097835))
    # what is left uncovered is named, never a success
    assert frf.status.success == (not frf.uncovered), frf.message


@pytest.mark.slow
@pytest.mark.parametrize("params, rms", [
    # crossval_doors.py seed 11 case 06: a run-up from rest at Ω_min settles after 1424 periods
    # (μ = −0.96) on a stable orbit the check's 200 periods did not see
    ((0.0288, 0.0452, 0.022, 0.018), 0.007525),
    # seed 31 case 08: a run-down settles at Ω_min on a stable orbit (rms 0.03103) beside the
    # unstable one of rms 0.03111 the branch had there; the end row's push settles on it
    ((0.0351, 0.0322, 0.0455, 0.0401), 0.031032),
], ids=["from_rest", "end_row"])
def test_the_attractors_at_the_range_s_end_are_found(params, rms):
    system = _preload_case(*params)
    frf = rattle.frequency_response(system, omega=(0.3, 2.0))
    at = frf.stable & (frf.omega <= 0.3 + 1e-9) & (np.abs(frf.rms - rms) < 0.01 * rms)
    assert at.any(), f"the stable orbit of rms {rms} at Ω_min is not on the response"
