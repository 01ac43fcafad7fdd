"""A time-domain sweep keeps going past a frequency whose steady state fails: the row is recorded
as failed (NaN measures, period -1, method "failed", the reason in ``failure``), the sweep carries
on from the last state computed, and the result, its files, its plot and ``rattle sweep`` say so."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest
from click.testing import CliRunner

import rattle.analysis._time_sweep as ts
from rattle.analysis import SteadyStateOptions, steady_state, time_sweep
from rattle.analysis._steady import static_state
from rattle.cli import cli
from rattle.errors import ConfigError, ConvergenceError, Status
from rattle.model import Excitation, Friction, NonsmoothLaw, Preload, SoundPath, System, reference_case
from rattle.results._sweep import FAILED_PERIOD, SWEEP_FAILED
from rattle.timeint import ExactIntegrator, FlowOptions

from _cases import preload_spring_toml  # tests/ is on sys.path through its conftest

#: A budget of switching events per integration small enough that the sticking orbits below
#: Ω ≈ 1 (seven switchings a period, more on the way there) exhaust it, and large enough for the
#: orbits above (four a period).
_BUDGET = 4
_GRID = (0.3, 3.0)  # ten points: 0.3, 0.6, …, 3.0


def _preload() -> System:
    """The preloaded spring with Coulomb friction (T_p = 0.03, r = 0.02, c = 0.05,
    F = 0.05 + 0.03 cos Ωt): it sticks part of every period."""
    law = NonsmoothLaw(elastic=Preload(preload=0.03), friction=Friction(levels=0.02))
    return System.single(damping=0.05, stiffness=1.0, law=law, excitation=Excitation(mean=0.05, amplitudes=(0.03,)))


@pytest.fixture
def small_budget(monkeypatch):
    """The sweep's exact integrator with a budget of ``_BUDGET`` events: the real integrator
    raises its real ConvergenceError at the low frequencies."""
    monkeypatch.setattr(ts, "make_integrator", lambda model: ExactIntegrator(model, FlowOptions(max_events=_BUDGET)))


def _failing_at(monkeypatch, bad: set[float], exc: type[BaseException] = ConvergenceError) -> None:
    """``steady_state`` in the sweep raising ``exc`` at the frequencies ``bad`` (rounded to 6 digits)."""
    real = steady_state  # the library's, also when an earlier call patched the sweep's

    def fake(model, omega, *args, **kwargs):
        if round(omega, 6) in bad:
            raise exc(f"made to fail at {omega:g}")
        return real(model, omega, *args, **kwargs)

    monkeypatch.setattr(ts, "steady_state", fake)


def test_an_exhausted_event_budget_fails_its_rows_and_the_sweep_carries_on(small_budget, caplog):
    ns = _preload()
    with caplog.at_level(logging.WARNING, logger="rattle"):
        r = time_sweep(ns, omega=_GRID, points=10, direction="up")
    assert len(r) == 10
    bad = np.flatnonzero(r.failed)
    np.testing.assert_array_equal(bad, [0, 1, 2])  # Ω = 0.3, 0.6, 0.9
    assert np.all(r.method[bad] == SWEEP_FAILED) and np.all(r.period[bad] == FAILED_PERIOD)
    assert not np.any(r.settled[bad]) and np.all(r.periods[bad] == 0) and np.all(r.shooting_periods[bad] == 0)
    for col in (r.mean, r.rms, r.rms_ac, r.p2p, r.acc_p2p, r.delta_min, r.delta_max, r.extra_columns["stick_fraction"]):
        assert np.all(np.isnan(col[bad]))
    assert np.all(np.isnan(r.state0[bad])) and np.all(np.isnan(r.final_state[bad]))
    np.testing.assert_allclose(r.omega, np.linspace(*_GRID, 10))  # Ω kept on the failed rows
    assert all("max_events" in str(f) for f in r.failure[bad]) and all(f == "" for f in r.failure[3:])
    assert [s for s in r.status[:3]] == [None] * 3 and all(s is Status.CONVERGED for s in r.status[3:])
    assert not r.complete and "no steady state at 3 of 10 frequencies" in r.message
    assert "up sweep Ω = 0.3, 0.6, 0.9" in r.message and "max_events" in r.message
    warned = [rec.getMessage() for rec in caplog.records if rec.levelno == logging.WARNING]
    assert len(warned) == 3 and "Ω = 0.3" in warned[0] and "max_events" in warned[0]
    # the rows after the failures: computed, settled, and from the last state computed (the
    # static state the sweep started from) the same as a sweep started at Ω = 1.2
    ok = slice(3, None)
    assert np.all(r.settled[ok]) and np.all(r.period[ok] == 1) and np.all(np.isfinite(r.rms[ok]))
    fresh = time_sweep(ns, omega=(1.2, 3.0), points=7, direction="up")
    assert fresh.complete
    np.testing.assert_allclose(r.rms[ok], fresh.rms, rtol=1e-9)
    np.testing.assert_allclose(r.state0[ok], fresh.state0, rtol=1e-9, atol=1e-12)
    # effort, periods found and jumps count only the computed rows
    meta = json.loads(json.dumps(r.metadata()))
    assert meta["periods_found"] == {"1": 7} and meta["complete"] is False
    assert [f["omega"] for f in meta["failures"]] == pytest.approx([0.3, 0.6, 0.9])
    assert all(f["direction"] == "up" and "max_events" in f["reason"] for f in meta["failures"])
    assert "failed (no steady state): up sweep Ω = 0.3, 0.6, 0.9" in r.summary()
    assert "3 failed" in repr(r)


def test_a_sweep_without_failures_is_unchanged():
    """Catching failures changes nothing where none happens: the same rows as the plain loop."""
    ns = _preload()
    r = time_sweep(ns, omega=_GRID, points=5, direction="down")
    assert r.complete and r.message == "" and not np.any(r.failed) and list(r.failure) == [""] * 5
    meta = r.metadata()
    assert "failures" not in meta and "complete" not in meta
    x = static_state(ns, float(r.omega[0]))
    integ = ts.make_integrator(ns)
    for i, w in enumerate(r.omega):
        s = steady_state(ns, float(w), x, options=SteadyStateOptions(), integrator=integ)
        assert s.rms == r.rms[i] and s.period == r.period[i] and np.array_equal(s.state0, r.state0[i])
        x = s.final_state


def test_one_failure_in_the_middle_carries_the_last_good_state(monkeypatch):
    ns = _preload()
    full = time_sweep(ns, omega=_GRID, points=10, direction="up")
    _failing_at(monkeypatch, {1.5})
    r = time_sweep(ns, omega=_GRID, points=10, direction="up")
    assert list(np.flatnonzero(r.failed)) == [4] and r.failure[4] == "made to fail at 1.5"
    keep = np.arange(10) != 4
    # before: identical; after: from the state of Ω = 1.2 instead of 1.5, the same stable orbits
    np.testing.assert_array_equal(r.rms[:4], full.rms[:4])
    assert np.all(r.settled[keep]) and np.all(r.period[keep] == 1)
    np.testing.assert_allclose(r.rms[5:], full.rms[5:], rtol=1e-8)
    expected = steady_state(ns, float(r.omega[5]), r.final_state[3])
    assert r.rms[5] == pytest.approx(expected.rms, rel=1e-12)
    # jumps are looked for between the computed rows on either side of the failed one
    assert all(j.omega_before != r.omega[4] and j.omega_after != r.omega[4] for j in r.jumps())
    # a direction of its own: select() keeps the reason with its row
    assert r.select("up").failure[4] == "made to fail at 1.5"


def test_a_flow_that_cannot_be_followed_fails_its_row_with_the_error_named(monkeypatch):
    """The discontinuous laws: a singular step (LinAlgError) or an overflow is numerical trouble
    of that frequency, its reason naming the error's type."""
    _failing_at(monkeypatch, {0.6}, np.linalg.LinAlgError)
    r = time_sweep(_preload(), omega=_GRID, points=10, direction="up")
    assert list(np.flatnonzero(r.failed)) == [1] and r.failure[1] == "made to fail at 0.6 (LinAlgError)"
    assert np.all(np.isfinite(r.rms[2:]))


def test_a_smooth_model_fails_rows_on_rattle_errors_only(monkeypatch):
    model = reference_case()
    _failing_at(monkeypatch, {0.6})
    r = time_sweep(model, omega=(0.5, 0.9), points=5, direction="up")  # 0.5, 0.6, …, 0.9
    assert list(np.flatnonzero(r.failed)) == [1] and r.failure[1] == "made to fail at 0.6"
    assert np.all(r.settled[~r.failed])
    # the sound at the receiver: none for the failed row, the linear reference still there
    path = SoundPath(source="delta", frequency_hz=[1e-6, 1e6], magnitude=[1.0, 1.0], phase_deg=[0.0, 0.0])
    sound = r.with_sound([path]).extra_columns
    assert np.isnan(sound["spl_db"][1]) and np.isnan(sound["spl_dba"][1]) and np.isfinite(sound["spl_linear_db"][1])
    assert np.all(np.isfinite(sound["spl_db"][~r.failed]))
    # a ValueError of the smooth integrators is not taken for numerical trouble: it stops the sweep
    _failing_at(monkeypatch, {0.7}, ValueError)
    with pytest.raises(ValueError, match="made to fail at 0.7"):
        time_sweep(model, omega=(0.5, 0.9), points=5, direction="up")


def test_programming_errors_and_bad_input_still_stop_the_sweep(monkeypatch):
    ns = _preload()
    _failing_at(monkeypatch, {0.6}, TypeError)
    with pytest.raises(TypeError, match="made to fail"):
        time_sweep(ns, omega=_GRID, points=10, direction="up")
    _failing_at(monkeypatch, {0.9}, ConfigError)  # bad input, though a RattleError
    with pytest.raises(ConfigError, match="made to fail"):
        time_sweep(ns, omega=_GRID, points=10, direction="up")


def test_the_parallel_sweep_carries_the_failed_rows_back(small_budget):
    ns = _preload()
    serial = time_sweep(ns, omega=_GRID, points=10, direction="both")
    parallel = time_sweep(ns, omega=_GRID, points=10, direction="both", workers=2)
    assert parallel.settings["workers"] == 2
    np.testing.assert_array_equal(parallel.failed, serial.failed)
    assert int(np.sum(parallel.failed)) == 6  # Ω = 0.3, 0.6, 0.9 of either direction
    np.testing.assert_array_equal(parallel.failure, serial.failure)
    np.testing.assert_array_equal(parallel.rms, serial.rms)  # NaN where failed, equal elsewhere
    np.testing.assert_array_equal(parallel.period, serial.period)


def test_the_files_and_the_plot_cope_with_failed_rows(small_budget, tmp_path):
    r = time_sweep(_preload(), omega=_GRID, points=10, direction="both")
    path = r.to_csv(tmp_path / "sweep.csv")
    lines = path.read_text().splitlines()
    assert lines[0] == "direction,omega,mean,rms,rms_ac,p2p,acc_p2p,period,regime,stick_fraction"
    assert lines[1] == "up,0.3,nan,nan,nan,nan,nan,-1,,nan"  # a failed row has no regime
    assert len(lines) == 21 and sum(line.endswith(",-1,,nan") for line in lines) == 6
    assert set(r.regime[~r.failed]) <= {"no_impact", "single_sided", "double_sided"}
    import matplotlib

    matplotlib.use("Agg")
    fig, axes = r.plot()
    ax = axes.primary
    labels = ax.get_legend_handles_labels()[1]
    assert "no steady state (failed)" in labels and not any("period -1" in s for s in labels)
    assert not any(t.get_text() == "P-1" for t in ax.texts)
    fig.savefig(tmp_path / "sweep.png")
    import matplotlib.pyplot as plt

    plt.close(fig)


_CONFIG = preload_spring_toml((0.3, 3.0))


def test_the_command_writes_its_files_names_the_failures_and_exits_1(small_budget, tmp_path):
    config = tmp_path / "preload.toml"
    config.write_text(_CONFIG)
    out = tmp_path / "out"
    res = CliRunner().invoke(cli, ["sweep", str(config), "--direction", "up", "--points", "10", "-o", str(out), "-q"])
    assert res.exit_code == 1, res.output
    assert {p.name for p in out.iterdir()} == {"sweep.csv", "sweep.json", "sweep.png"}
    err = [line for line in res.output.splitlines() if line.startswith("rattle: error:")]
    assert len(err) == 1 and "no steady state at 3 of 10 frequencies" in err[0]
    assert "up sweep Ω = 0.3, 0.6, 0.9" in err[0] and "max_events" in err[0] and "sweep.csv" in err[0]
    warned = [line for line in res.output.splitlines() if line.startswith("rattle: warning:")]
    assert len(warned) == 3 and warned[0].startswith("rattle: warning: up sweep Ω = 0.3: no steady state")
    assert "failed (no steady state): up sweep Ω = 0.3, 0.6, 0.9" in res.output  # the summary
    meta = json.loads((out / "sweep.json").read_text())
    assert len(meta["failures"]) == 3 and meta["complete"] is False
    rows = (out / "sweep.csv").read_text().splitlines()[1:]
    assert [row.split(",")[7] for row in rows] == ["-1"] * 3 + ["1"] * 7


def test_compare_picks_no_failed_row_and_starts_no_simulation_from_one(monkeypatch):
    """compare on the reference clutch over its hysteresis (multi-valued, 0.75–0.88): a failed
    sweep row there (rms nan) neither becomes the multi-valued pick nor a start state."""
    from rattle.analysis import compare
    from rattle.analysis._compare import pick_frequencies

    model = reference_case()
    grid = np.linspace(0.7, 0.95, 11)
    bad = {round(float(w), 6) for w in grid[3:8]}  # the middle of the multi-valued range, both ways
    _failing_at(monkeypatch, bad)
    cmp = compare(model, omega=(0.7, 0.95), points=11, harmonics=8)
    assert np.sum(cmp.sweep.failed) == 2 * len(bad)
    picks = pick_frequencies(cmp.frf, cmp.sweep)
    assert picks and all(np.isfinite(w) for w, _ in picks)
    for states in cmp.simulations:  # every simulation started from a computed state
        for s in states.values():
            assert np.all(np.isfinite(s.state0)) and s.settled


def test_rattle_compare_writes_its_set_and_exits_1_when_its_sweep_failed(small_budget, tmp_path):
    """`rattle compare` on the preloaded spring (a discontinuous law: the regularised HB beside
    the exact sweep) whose sweep fails at 0.3, 0.6 and 0.9: the set is written, the failures are
    warned of and the run ends as a partial one."""
    config = tmp_path / "preload.toml"
    config.write_text(_CONFIG.replace("omega = [0.3, 3.0]", "omega = [0.3, 1.2]\nharmonics = 16\nrefine = 0"))
    out = tmp_path / "cmp"
    res = CliRunner().invoke(cli, ["compare", str(config), "--points", "4", "-o", str(out), "-q"])
    assert res.exit_code == 1, res.output
    assert {"frf.csv", "sweep.csv", "compare.json"} <= {p.name for p in out.iterdir()}
    err = [line for line in res.output.splitlines() if line.startswith("rattle: error:")]
    assert len(err) == 1 and "sweep incomplete" in err[0] and "Ω = 0.3, 0.6, 0.9" in err[0]
    assert sum(line.startswith("rattle: warning:") for line in res.output.splitlines()) == 6  # up and down
