"""Measured run-ups (``rattle compare --measured``): the CSV read strictly, and the computed
values at the measured points checked against hand interpolation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle.errors import ConfigError
from rattle.io import read_csv, read_measured_csv
from rattle.results import FRF_COLUMNS, FrequencyResponse, MeasuredRun, SweepResult, compare_measured
from rattle.results._measured import hb_largest_stable
from rattle.results._sweep import _ROW_FIELDS


def _write(tmp_path: Path, text: str, name: str = "run.csv") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------
def test_omega_file_read_with_comments_blank_lines_and_spaces(tmp_path: Path) -> None:
    path = _write(tmp_path, "# a rig run\n\nomega , acc_p2p\n0.8, 0.5\n# gap\n 0.9 ,0.75\n1.0,1.25\n")
    run = read_measured_csv(path, omega_range=(0.5, 1.5))
    assert isinstance(run, MeasuredRun)
    assert run.omega.tolist() == [0.8, 0.9, 1.0]
    assert run.values["acc_p2p"].tolist() == [0.5, 0.75, 1.25]
    assert run.speed_rpm is None and run.quantities == ("acc_p2p",)
    assert run.lines == (4, 6, 7) and run.source == "run.csv"


def test_rpm_turns_into_omega_by_the_engine_order(tmp_path: Path) -> None:
    # order 2: Ω = 2 · 2π/60 · rpm; 600 rpm → 40π rad/s, 900 rpm → 60π rad/s
    path = _write(tmp_path, "spl_db,speed_rpm\n71.5,900\n70.0,600\n")  # a run-down, columns in any order
    run = read_measured_csv(path, speed_order=2.0, omega_range=(40 * math.pi, 60 * math.pi), has_paths=True)
    np.testing.assert_allclose(run.omega, [60 * math.pi, 40 * math.pi], rtol=1e-15)
    assert run.speed_rpm.tolist() == [900.0, 600.0]
    assert run.values["spl_db"].tolist() == [71.5, 70.0]


def test_both_quantities_in_file_order(tmp_path: Path) -> None:
    run = read_measured_csv(_write(tmp_path, "omega,spl_db,acc_p2p\n1.0,60,0.2\n"), has_paths=True)
    assert run.quantities == ("acc_p2p", "spl_db")
    assert run.values["spl_db"].tolist() == [60.0] and run.values["acc_p2p"].tolist() == [0.2]


BAD = [
    ("no speed", "acc_p2p\n0.5\n", {}, ["line 1", "no speed column", "speed_rpm", "omega"]),
    ("both speeds", "omega,speed_rpm,acc_p2p\n1,600,0.5\n", {"speed_order": 2.0}, ["line 1", "both speed_rpm and omega"]),
    ("no quantity", "omega\n1.0\n", {}, ["line 1", "no measured quantity", "acc_p2p", "spl_db"]),
    ("unknown column", "omega,acc_p2p,temperature\n1,0.5,80\n", {}, ["line 1, column 3", "'temperature'", "not known"]),
    ("misspelt quantity", "omega,acc_pp\n1,0.5\n", {}, ["line 1, column 2", "'acc_pp'"]),
    ("repeated column", "omega,acc_p2p,acc_p2p\n1,0.5,0.5\n", {}, ["'acc_p2p' appears 2 times"]),
    ("semicolons", "omega;acc_p2p\n1;0.5\n", {}, ["line 1", "not comma-separated"]),
    ("text cell", "omega,acc_p2p\n1.0,0.5\n1.1,loud\n", {}, ["line 3, column `acc_p2p`", "must be a number", "'loud'"]),
    ("empty cell", "omega,acc_p2p\n1.0,\n", {}, ["line 2, column `acc_p2p`", "must be a number", "''"]),
    ("nan", "omega,acc_p2p\n1.0,0.5\nnan,0.6\n", {}, ["line 3, column `omega`", "finite", "'nan'"]),
    ("inf", "omega,acc_p2p\n1.0,inf\n", {}, ["line 2, column `acc_p2p`", "finite"]),
    ("fields", "omega,acc_p2p\n1.0,0.5,3\n", {}, ["line 2 has 3 fields, the header has 2"]),
    ("speed zero", "omega,acc_p2p\n0,0.5\n", {}, ["line 2, column `omega`", "> 0 rad/s"]),
    ("acc zero", "omega,acc_p2p\n1.0,0\n", {}, ["line 2, column `acc_p2p`", "> 0"]),
    ("not monotonic", "omega,acc_p2p\n1.0,0.5\n1.2,0.6\n1.1,0.7\n", {},
     ["line 4, column `omega`", "strictly increasing", "1.1 after 1.2 (line 3)"]),
    ("repeated speed", "speed_rpm,acc_p2p\n900,0.5\n800,0.6\n800,0.7\n", {"speed_order": 2.0},
     ["line 4, column `speed_rpm`", "strictly decreasing", "run-down"]),
    ("outside the range", "omega,acc_p2p\n1.0,0.5\n1.6,0.6\n", {"omega_range": (0.5, 1.5)},
     ["line 3, column `omega`", "1.6 rad/s lies outside the analysis range 0.5 … 1.5 rad/s", "--omega-min/--omega-max"]),
    ("rpm outside the range", "speed_rpm,acc_p2p\n500,0.5\n", {"speed_order": 2.0, "omega_range": (40 * math.pi, 60 * math.pi)},
     ["line 2, column `speed_rpm`", "500 rpm lies outside the analysis range 600 … 900 rpm", "--rpm-min/--rpm-max"]),
    ("rpm without an engine", "speed_rpm,acc_p2p\n900,0.5\n", {}, ["column `speed_rpm`", "no engine", "omega (rad/s)"]),
    ("spl without paths", "omega,spl_db\n1.0,60\n", {}, ["column `spl_db`", "no [[paths]]"]),
    ("header only", "omega,acc_p2p\n", {}, ["has a header but no rows"]),
    ("empty", "# nothing\n\n", {}, ["is empty"]),
]


@pytest.mark.parametrize("text, options, fragments", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_refused_with_line_column_and_rule(tmp_path: Path, text: str, options: dict, fragments: list[str]) -> None:
    with pytest.raises(ConfigError) as info:
        read_measured_csv(_write(tmp_path, text), **options)
    message = str(info.value)
    assert message.startswith("`--measured` (")
    assert "run.csv" in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_missing_file_and_folder_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="does not exist"):
        read_measured_csv(tmp_path / "none.csv")
    with pytest.raises(ConfigError, match="directory"):
        read_measured_csv(tmp_path)


# --------------------------------------------------------------------------------------------
# Interpolation, by hand
# --------------------------------------------------------------------------------------------
def _frf(branch: list[int], omega: list[float], stable: list[bool], acc: list[float],
         spl: list[float] | None = None) -> FrequencyResponse:
    n = len(omega)
    arrays = {name: np.zeros(n) for name in FRF_COLUMNS}
    arrays.update(branch=np.array(branch), period=np.ones(n, int), omega=np.array(omega, float),
                  acc_p2p=np.array(acc, float), stable=np.array(stable, bool), regime=np.array(["impact"] * n),
                  bifurcation=np.array([""] * n), iterations=np.ones(n, int))
    return FrequencyResponse(model=rattle.reference_case(), harmonics=1, coefficients=np.zeros((n, 3)),
                             multipliers=np.zeros((n, 2), complex),
                             extra_columns={} if spl is None else {"spl_db": np.array(spl, float)}, **arrays)


def _sweep(up: tuple[list[float], list[float]], down: tuple[list[float], list[float]] | None = None) -> SweepResult:
    parts = [("up", *up)] + ([("down", *down)] if down else [])
    direction = np.array([d for d, om, _ in parts for _ in om])
    omega = np.array([w for _, om, _ in parts for w in om], float)
    acc = np.array([a for *_, ac in parts for a in ac], float)
    n = omega.size
    rows = {name: np.zeros(n) for name in _ROW_FIELDS}
    rows.update(direction=direction, omega=omega, acc_p2p=acc, period=np.ones(n, int), settled=np.ones(n, bool),
                method=np.array(["shooting"] * n), periods=np.ones(n, int), shooting_periods=np.ones(n, int),
                state0=np.zeros((n, 2)), final_state=np.zeros((n, 2)), multipliers=np.zeros((n, 2), complex))
    return SweepResult(model=rattle.reference_case(), **rows)


def test_hb_value_is_the_largest_stable_segment_interpolated() -> None:
    # branch 0 (continuation order, folding back): 1.0 → 2.0 → 3.0 stable, then 3.0 → 2.5 unstable, 2.5 → 1.5 stable
    frf = _frf(branch=[0, 0, 0, 0, 0, 1, 1],
               omega=[1.0, 2.0, 3.0, 2.5, 1.5, 2.0, 2.4],
               stable=[True, True, True, False, True, True, True],
               acc=[10.0, 20.0, 40.0, 30.0, 5.0, 100.0, 60.0])
    w = [1.25, 2.2, 2.75, 2.45, 0.5, 1.75, 2.0]
    got = hb_largest_stable(frf, "acc_p2p", w)
    # 1.25: on 1→2 only: 10 + 0.25·10 = 12.5
    # 2.2: on 2→3 (20 + 0.2·20 = 24) and branch 1 2→2.4 (100 − 0.5·40 = 80): the largest, 80
    # 2.75: on 2→3: 20 + 0.75·20 = 35 (3→2.5 is unstable, 2.5→1.5 has one unstable end)
    # 2.45: 2→3 gives 29; 2.5→1.5 is left out (its 2.5 end is unstable): 29 (branch 1 ends at 2.4)
    # 0.5: no segment: NaN;  1.75: 1→2 gives 17.5, 2.5→1.5 left out: 17.5
    # 2.0: a shared end: 20 on branch 0, 100 on branch 1 → 100
    np.testing.assert_allclose(got, [12.5, 80.0, 35.0, 29.0, np.nan, 17.5, 100.0], rtol=1e-14)


def test_sweeps_interpolated_and_differences_hand_checked(tmp_path: Path) -> None:
    frf = _frf([0, 0], [1.0, 2.0], [True, True], [10.0, 30.0], spl=[60.0, 70.0])
    sweep = _sweep(up=([1.0, 1.5, 2.0], [10.0, 12.0, 32.0]), down=([2.0, 1.5, 1.0], [30.0, 11.0, 9.0]))
    run = MeasuredRun(omega=[1.2, 1.8], values={"acc_p2p": [11.0, 25.0], "spl_db": [62.0, 69.0]})
    result = compare_measured(run, frf, sweep)
    c = result.columns()
    assert result.column_names() == [
        "omega", "acc_p2p", "acc_p2p_hb", "acc_p2p_sweep_up", "acc_p2p_sweep_down",
        "acc_p2p_rel_hb", "acc_p2p_rel_sweep_up", "acc_p2p_rel_sweep_down",
        "spl_db", "spl_db_hb", "spl_db_sweep_up", "spl_db_sweep_down",
        "spl_db_diff_hb", "spl_db_diff_sweep_up", "spl_db_diff_sweep_down"]
    hb = [10 + 0.2 * 20, 10 + 0.8 * 20]            # 14, 26
    up = [10 + 0.4 * 2, 12 + 0.6 * 20]              # 10.8, 24
    down = [9 + 0.4 * 2, 11 + 0.6 * 19]             # 9.8, 22.4 (the down sweep sorted by Ω)
    np.testing.assert_allclose(c["acc_p2p_hb"], hb, rtol=1e-14)
    np.testing.assert_allclose(c["acc_p2p_sweep_up"], up, rtol=1e-14)
    np.testing.assert_allclose(c["acc_p2p_sweep_down"], down, rtol=1e-14)
    np.testing.assert_allclose(c["acc_p2p_rel_hb"], [14 / 11 - 1, 26 / 25 - 1], rtol=1e-13)
    np.testing.assert_allclose(c["acc_p2p_rel_sweep_down"], [9.8 / 11 - 1, 22.4 / 25 - 1], rtol=1e-13)
    np.testing.assert_allclose(c["spl_db_hb"], [62.0, 68.0], rtol=1e-14)
    np.testing.assert_allclose(c["spl_db_diff_hb"], [0.0, -1.0], atol=1e-12)
    # the sweep result carries no sound pressure: compared against the harmonic balance only
    assert np.all(np.isnan(c["spl_db_sweep_up"])) and np.all(np.isnan(c["spl_db_diff_sweep_down"]))
    assert result.missing == {("spl_db", "sweep_up"): "the sweep result carries no spl_db",
                              ("spl_db", "sweep_down"): "the sweep result carries no spl_db"}
    line = result.summary().splitlines()
    assert line[0].startswith("measured acc_p2p (2 points, measured): largest difference hb +27.3 % at Ω = 1.2")
    assert "sweep down -10.9 % at Ω = 1.2" in line[0]
    assert "hb -1.00 dB at Ω = 1.8" in line[1] and "sweep up: none (the sweep result carries no spl_db)" in line[1]
    # measured.csv: the same columns and values
    back = read_csv(result.to_csv(tmp_path / "measured.csv"))
    assert list(back) == result.column_names()
    np.testing.assert_allclose(back["acc_p2p_sweep_down"], down, rtol=1e-15)
    assert np.all(np.isnan(back["spl_db_sweep_up"]))


def test_outside_the_sweep_and_without_a_direction_nan() -> None:
    frf = _frf([0, 0], [1.0, 2.0], [True, False], [10.0, 30.0])  # no stable segment at all
    sweep = _sweep(up=([1.0, 1.5], [10.0, 12.0]))                   # up only, up to 1.5
    result = compare_measured(MeasuredRun(omega=[1.25, 1.75], values={"acc_p2p": [1.0, 1.0]}), frf, sweep)
    c = result.columns()
    assert np.all(np.isnan(c["acc_p2p_hb"]))
    np.testing.assert_allclose(c["acc_p2p_sweep_up"][:1], [11.0], rtol=1e-15)
    assert math.isnan(c["acc_p2p_sweep_up"][1]) and np.all(np.isnan(c["acc_p2p_sweep_down"]))
    assert result.missing == {("acc_p2p", "sweep_down"): "no down sweep"}
    assert result.summary() == ("measured acc_p2p (2 points, measured): largest difference sweep up +1000.0 % at "
                                "Ω = 1.25; hb: no stable solution computed at 2 point(s); sweep up: outside the "
                                "sweep at 1 point(s); sweep down: none (no down sweep)")


def test_measured_run_checks_its_arguments() -> None:
    with pytest.raises(ValueError, match="strictly monotonic"):
        MeasuredRun(omega=[1.0, 1.0], values={"acc_p2p": [1.0, 2.0]})
    with pytest.raises(ValueError, match="one value per point"):
        MeasuredRun(omega=[1.0, 1.1], values={"acc_p2p": [1.0]})
    with pytest.raises(ValueError, match="may hold only"):
        MeasuredRun(omega=[1.0], values={"acc_p2p": [1.0], "rms": [1.0]})
    with pytest.raises(ValueError, match="no `spl_db` column"):
        compare_measured(MeasuredRun(omega=[1.5], values={"spl_db": [60.0]}),
                         _frf([0, 0], [1.0, 2.0], [True, True], [1.0, 2.0]), _sweep(up=([1.0, 2.0], [1.0, 2.0])))


def test_the_example_run_up_reads_against_its_configuration() -> None:
    from rattle.io import load_config

    examples = Path(__file__).resolve().parents[2] / "examples"
    cfg = load_config(examples / "engine_clutch_si.toml")
    run = read_measured_csv(examples / "engine_clutch_measured.csv", speed_order=cfg.model.speed_order,
                            omega_range=cfg.analysis.omega)
    assert len(run) == 41 and run.quantities == ("acc_p2p",)
    assert run.speed_rpm[0] == 600.0 and run.speed_rpm[-1] == 1400.0
    np.testing.assert_allclose(run.omega, run.speed_rpm * 2.0 * 2.0 * math.pi / 60.0, rtol=1e-15)  # order 2
