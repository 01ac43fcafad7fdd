"""Sound pressure of a time-domain sweep (SPEC §6, the paper's eq. 1 on the simulated motions):
a periodic sweep point against the harmonic-balance level of the same orbit, a constant path
against the exact rms of the source acceleration, a record of several periods against one
period, the columns, the CLI and the plot panel."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle.analysis import steady_state, time_sweep
from rattle.model import SoundPath
from rattle.results._sound import motion_sound_pressure

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def config():
    return rattle.io.load_config(EXAMPLES / "clutch_with_paths.toml")


@pytest.fixture(scope="module")
def sweep(config):
    # Ω = 64 … 66 rad/s lies on the stable period-1 stretch below the resonance's fold (75.4 rad/s)
    return time_sweep(config.model, omega=(64.0, 66.0), points=2, direction="up")


@pytest.fixture(scope="module")
def frf(config):
    # the continuation's first and last rows are exactly at 64 and 66 rad/s
    return rattle.frequency_response(config.model, omega=(64.0, 66.0), harmonics=32)


def cut_paths(paths, f_cut: float) -> list[SoundPath]:
    """The paths with only their rows up to f_cut (Hz)."""
    out = []
    for p in paths:
        keep = p.frequency_hz <= f_cut
        out.append(SoundPath(source=p.source, frequency_hz=p.frequency_hz[keep], magnitude=p.magnitude[keep],
                             phase_deg=p.phase_deg[keep]))
    return out


def gauss_rms_ac(traj, T: float) -> float:
    """rms about the mean of δ'' over [0, T] by 12-point Gauss–Legendre on panels within each
    segment (δ'' is analytic there): an independent reference, exact to round-off."""
    x, w = np.polynomial.legendre.leggauss(12)
    t, wt, seg = [], [], []
    for i, (a, b) in enumerate(zip(traj.t_start, traj.t_end)):
        edges = np.linspace(a, b, max(1, int(np.ceil((b - a) / (T / 2000)))) + 1)
        for lo, hi in zip(edges[:-1], edges[1:]):
            t.append(0.5 * (hi - lo) * x + 0.5 * (hi + lo))
            wt.append(0.5 * (hi - lo) * w)
            seg.append(np.full(12, i))
    t, wt, seg = np.concatenate(t), np.concatenate(wt), np.concatenate(seg)
    acc = np.asarray(traj.derivatives(t, 2, segment=seg)[2]).reshape(t.size, -1)[:, 0]
    mean = np.sum(wt * acc) / T
    return float(np.sqrt(np.sum(wt * (acc - mean) ** 2) / T))


# --- a periodic sweep point is the orbit the harmonic balance computes -------------------------
def test_periodic_point_equals_the_hb_level_of_the_same_orbit(config, sweep, frf):
    sp = rattle.sound_pressure(frf, config.paths)
    loud = sweep.with_sound(config.paths)
    assert list(sweep.period) == [1, 1] and frf.stable[0] and frf.stable[-1]
    np.testing.assert_array_equal(sweep.omega, [frf.omega[0], frf.omega[-1]])
    # The example's tables reach 1000 Hz (harmonic ~98 at 64 rad/s): the sweep's exact orbit has
    # them all, the HB series 32 of them; its truncation moves the level by ~2e-5 dB (1.7e-5 and
    # 1.1e-6 dB measured; 4e-3 dB at H = 16), so 1e-3 dB holds with a margin of 50.
    np.testing.assert_allclose(loud.extra_columns["spl_db"], sp.spl_db[[0, -1]], atol=1e-3, rtol=0)
    # the linear reference is the same function as the frf's
    np.testing.assert_allclose(loud.extra_columns["spl_linear_db"], sp.linear_spl_db[[0, -1]], rtol=1e-12)


def test_same_harmonics_give_the_same_level_weighted_or_not(config, sweep, frf):
    """With the tables cut below harmonic 8.5 of 64 rad/s both sides transmit the same harmonics
    k ≤ 8. The plain level agrees to the HB's error (1.7e-5 dB measured); the A-weighting lifts
    harmonics 6 … 8 (60 … 80 Hz) by up to 40 dB over the fundamental, where the HB's relative
    error is largest: 2.4e-4 dB measured at H = 32 (1.7e-5 at H = 64), so 1e-3 dB holds."""
    paths = cut_paths(config.paths, 8.5 * 64.0 / (2 * math.pi))
    with warnings.catch_warnings():  # the cut tables leave the high harmonics out: on purpose
        warnings.simplefilter("ignore")
        loud = sweep.with_sound(paths)
        plain = rattle.sound_pressure(frf, paths, linear=False).spl_db[[0, -1]]
        weighted = rattle.sound_pressure(frf, paths, a_weighting=True, linear=False).spl_db[[0, -1]]
    np.testing.assert_allclose(loud.extra_columns["spl_db"], plain, atol=1e-4, rtol=0)
    np.testing.assert_allclose(loud.extra_columns["spl_dba"], weighted, atol=1e-3, rtol=0)


# --- a constant path: the rms of the source acceleration ---------------------------------------
@pytest.mark.parametrize("omega", [0.8, 1.4])  # period 1, and period 2 (its own base frequency Ω/2)
def test_constant_path_gives_the_exact_acceleration_rms(omega):
    model = rattle.reference_case()
    s = steady_state(model, omega)
    assert s.period == (1 if omega < 1 else 2)
    c = 3e-3
    path = SoundPath(source="delta", frequency_hz=[1e-6, 1e6], magnitude=[c, c], phase_deg=[0.0, 0.0])
    sp = motion_sound_pressure(model, s.trajectory, omega, s.period, [path])
    reference = c * gauss_rms_ac(s.trajectory, s.period * 2 * math.pi / omega)
    # 2^18 samples of a continuous δ'' with slope jumps: 1.4e-12 and 3.2e-12 measured
    assert sp.p_rms[0] == pytest.approx(reference, rel=1e-10)
    assert sp.uncovered[0, 0] == 0.0 and sp.period[0] == s.period
    assert sp.spl_db[0] == pytest.approx(20 * math.log10(reference / 20e-6), abs=1e-9)


@pytest.mark.slow
def test_a_record_of_several_periods_gives_the_level_of_one(config, sweep):
    """The non-periodic treatment (the FFT over a window of w forcing periods, base Ω/w) of a
    periodic motion puts its harmonics on the bins k = m·w and finds the same level; also the
    free chain's inertia source, whose rigid-body part takes the torque harmonic h = k/w."""
    model = config.model
    traj, window = next(sweep.records())
    assert window == 1
    from rattle.timeint import ExactIntegrator

    long = ExactIntegrator(model.system()).propagate(sweep.state0[0], 0.0, 3 * 2 * math.pi / 64.0, 64.0)
    one = motion_sound_pressure(model, traj, 64.0, 1, config.paths)
    three = motion_sound_pressure(model, long, 64.0, 3, config.paths)
    assert three.period[0] == 3
    # 4096 samples over one period, 16384 over three: the folded content differs (~3e-8 relative)
    assert three.spl_db[0] == pytest.approx(one.spl_db[0], abs=1e-6)
    # the bins between the orbit's harmonics are empty but for folded content (16384 samples are
    # not a multiple of 3, so harmonics above N/2 fold onto them): 3e-7 of the largest measured
    off = np.abs(three.pressure[0, np.arange(three.pressure.shape[1]) % 3 != 2])
    assert np.max(off) < 2e-6 * np.max(np.abs(three.pressure))
    # time-domain pressure from the harmonics: its rms is p_rms (Parseval)
    t = np.linspace(0, 3 * 2 * math.pi / 64.0, 4096, endpoint=False)
    k = np.arange(1, three.pressure.shape[1] + 1)
    p = np.real(np.exp(1j * np.outer(t, k) * 64.0 / 3) @ three.pressure[0])
    assert np.sqrt(np.mean(p**2)) == pytest.approx(three.p_rms[0], rel=1e-9)


# --- columns, warnings, CLI, plot ----------------------------------------------------------------
def test_columns_follow_the_spec_columns_and_survive_select(config, sweep):
    loud = sweep.with_sound(config.paths)
    names = list(loud.columns())
    assert names[-3:] == ["spl_db", "spl_dba", "spl_linear_db"]
    assert names[:-3] == list(sweep.columns())
    up = loud.select("up")
    np.testing.assert_array_equal(up.extra_columns["spl_db"], loud.extra_columns["spl_db"])
    # A-weighting at harmonics of ~10 … 400 Hz: some 40 dB lower (the example's header)
    assert np.all(loud.extra_columns["spl_dba"] < loud.extra_columns["spl_db"] - 30)


def test_outside_the_tables_warns_once_naming_the_path(config, sweep):
    narrow = [SoundPath(source="clutch", frequency_hz=[5.0, 25.0], magnitude=[1e-5, 1e-5], phase_deg=[0, 0],
                        name="narrow.csv")]
    with pytest.warns(UserWarning, match="narrow.csv") as seen:
        sweep.with_sound(narrow)
    assert len([w for w in seen if "outside the table" in str(w.message)]) == 1


def test_sources_are_checked(sweep):
    bad = SoundPath(source="gear", frequency_hz=[1.0, 2.0], magnitude=[1.0, 1.0], phase_deg=[0, 0])
    with pytest.raises(ValueError, match="paths\\[0\\].source"):
        sweep.with_sound([bad])


def test_cli_sweep_writes_the_levels_with_paths_only(tmp_path, config):
    from click.testing import CliRunner

    from rattle.cli.main import cli as main

    cfg = EXAMPLES / "clutch_with_paths.toml"
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["sweep", str(cfg), "--direction", "up", "--points", "2", "--omega-min", "64",
                                    "--omega-max", "66", "-o", str(out), "-q"])
    assert res.exit_code == 0, res.output
    header = (out / "sweep.csv").read_text().splitlines()[0].split(",")
    assert header[-3:] == ["spl_db", "spl_dba", "spl_linear_db"]
    rows = np.genfromtxt(out / "sweep.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    ref = time_sweep(config.model, omega=(64.0, 66.0), points=2, direction="up").with_sound(config.paths)
    np.testing.assert_array_equal(rows["spl_db"], ref.extra_columns["spl_db"])
    plain = tmp_path / "plain"
    res = CliRunner().invoke(main, ["sweep", str(EXAMPLES / "chain_two_inertia.toml"), "--direction", "up",
                                    "--points", "2", "--omega-min", "0.64", "--omega-max", "0.66", "-o", str(plain),
                                    "-q"])
    assert res.exit_code == 0, res.output
    assert "spl_db" not in (plain / "sweep.csv").read_text().splitlines()[0]


def test_plot_gets_an_spl_panel_in_rpm_with_an_engine(tmp_path, sweep, config):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = sweep.with_sound(config.paths).plot()
    assert list(axes.keys())[-1] == "spl_db"
    assert "dB" in axes["spl_db"].get_ylabel() and "Ω" in axes["spl_db"].get_xlabel()
    plt.close(fig)
    fig, axes = sweep.plot()
    assert "spl_db" not in axes.keys()
    plt.close(fig)
    # an engine: the x axis is the crankshaft speed
    (tmp_path / "p.csv").write_text("frequency_hz,magnitude,phase_deg\n1,1e-5,0\n100000,1e-5,0\n")
    text = (EXAMPLES / "engine_clutch_si.toml").read_text() + '\n[[paths]]\nsource = "damper"\nfile = "p.csv"\n'
    (tmp_path / "engine.toml").write_text(text)
    engine = rattle.io.load_config(tmp_path / "engine.toml")
    lo = engine.analysis.omega[0]
    s = time_sweep(engine.model, omega=(lo, lo * 1.01), points=2).with_sound(engine.paths)
    fig, axes = s.plot()
    assert axes["spl_db"].get_xlabel() == "engine speed (rpm)"
    x = axes["spl_db"].lines[0].get_xdata()
    np.testing.assert_allclose(x, s.speed_rpm, rtol=1e-12)
    plt.close(fig)


def test_a_non_periodic_row_is_measured_over_its_record(config, sweep):
    """A row of period 0 is taken over the record of ``record_periods`` forcing periods from its
    state (here a periodic motion dressed as period 0 with a record of 3): the level of the
    orbit again, through SweepResult.records' period-0 branch."""
    import dataclasses

    dressed = dataclasses.replace(sweep, period=np.zeros(2, dtype=np.int64),
                                  settings={**sweep.settings, "steady_state": {"record_periods": 3}})
    windows = [w for _, w in dressed.records()]
    assert windows == [3, 3]
    loud = sweep.with_sound(config.paths).extra_columns["spl_db"]
    np.testing.assert_allclose(dressed.with_sound(config.paths).extra_columns["spl_db"], loud, atol=1e-6, rtol=0)
