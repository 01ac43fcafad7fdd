"""``rattle`` on a discontinuous law (preload, friction): ``rattle frf`` writes the non-smooth
response as one set; the commands that cannot solve such a law refuse it (exit 2, nothing written)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from _cases import preload_spring_toml
from _cli_helpers import PNG, assert_bad_input, invoke, write_config
from rattle.io import load_config, read_csv
from rattle.results._nonsmooth import NONSMOOTH_COLUMNS

#: T_p = 0.05 with friction r = 0.02 on every stage, c = 0.05, F = 0.01 + 0.3 cos(Ω t + 0.3): above
#: the primary resonance every orbit crosses the jump twice per period and slips (no stick).
PRELOAD = """\
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "preload"
preload = 0.05
friction = 0.02

[excitation]
mean = 0.01
amplitudes = [0.3]
phases = [0.3]

[analysis]
omega = [1.2, 1.25]
harmonics = 32
method = "hb"            # the regularised harmonic balance, every row checked (the default is exact shooting)
"""


@pytest.fixture(scope="module")
def frf_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("nonsmooth")
    config = write_config(folder, PRELOAD)
    result = invoke(["frf", str(config), "-o", "out"], folder)
    return folder, config, result


def test_frf_writes_the_three_files_as_one_set(frf_run):
    folder, _config, result = frf_run
    assert result.exit_code == 0, (result.stdout, result.stderr)
    out = folder / "out"
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    assert (out / "frf.png").read_bytes()[:8] == PNG
    header = (out / "frf.csv").read_text().splitlines()[0]
    assert header == ",".join(NONSMOOTH_COLUMNS)
    assert "matched by exact shooting" in result.stdout and "wrote frf.csv, frf.json, frf.png" in result.stdout


def test_frf_json_holds_the_settings_and_the_measured_error(frf_run):
    folder, _config, _result = frf_run
    meta = json.loads((folder / "out" / "frf.json").read_text())
    table = read_csv(folder / "out" / "frf.csv")
    matched = np.asarray(table["matched"], dtype=bool)
    err = np.abs(np.asarray(table["rms_error"], dtype=float)[matched])
    assert meta["command"] == "frf" and meta["status"] == "success" and meta["version"]
    assert meta["settings"]["harmonics"] == 32 and meta["settings"]["regularisation"] == 0.01
    assert meta["analysis"] == {"omega": [1.2, 1.25], "harmonics": 32, "regularisation": 0.01, "refine": 0.005,
                                "method": "hb"}
    assert meta["settings"]["refine"] == 0.005
    assert meta["points"] == len(table["omega"]) and meta["matched"] == int(matched.sum()) > 0
    assert meta["rms_error_max"] == pytest.approx(float(np.max(err)), rel=1e-12)
    assert meta["system"]["law"]["friction"] == {"levels": [0.02]}
    assert meta["config"]["model"]["elastic"]["preload"] == 0.05
    assert meta["timings"]["cli_wall_time"] > 0 and "frequency_response" in meta["timings"]
    assert meta["bifurcations"] == []


def test_frf_exact_rms_is_the_independent_exact_orbit(frf_run):
    """The csv's rms is that of the exact orbit: Newton shooting of the event-driven flow from rest
    at the middle row's Ω lands on it to 1e-9."""
    from rattle.timeint import shoot_nonsmooth_orbit

    folder, config, _result = frf_run
    table = read_csv(folder / "out" / "frf.csv")
    i = len(table["omega"]) // 2
    assert bool(table["matched"][i])
    system = load_config(config).model
    orbit = shoot_nonsmooth_orbit(system, float(table["omega"][i]), (0.0, 0.0))
    assert orbit.converged
    assert abs(orbit.rms - float(table["rms"][i])) <= 1e-9
    assert abs(orbit.mean - float(table["mean"][i])) <= 1e-9
    # and the HB's rms beside it differs from it by the rms_error of the row
    assert float(table["rms_hb"][i]) / orbit.rms - 1.0 == pytest.approx(float(table["rms_error"][i]), abs=1e-9)
    assert math.isfinite(float(table["mu1_abs"][i])) and float(table["stick_time"][i]) == 0.0


def test_map_refuses_the_regularised_method_and_writes_nothing(tmp_path):
    """``rattle map`` solves a discontinuous law by exact shooting: PRELOAD asks for the
    regularised HB (``method = "hb"``), which is refused naming the key (exit 2)."""
    config = write_config(tmp_path, PRELOAD)
    result = invoke(["map", str(config), "--vary", "damping=0.04,0.05", "-o", "out"], tmp_path)
    assert_bad_input(result, '`analysis.method` = "hb"', "by exact shooting", 'remove `method = "hb"`')
    assert not (tmp_path / "out").exists()


def test_a_bad_friction_list_is_refused_with_nothing_written(tmp_path):
    config = write_config(tmp_path, PRELOAD.replace("friction = 0.02", "friction = [0.02, 0.0, 0.02]"))
    result = invoke(["frf", str(config), "-o", "out"], tmp_path)
    assert_bad_input(result, "`model.elastic.friction` must hold one level", 'type = "preload" has 2 stages',
                     "got 3 levels")
    assert not (tmp_path / "out").exists()
    config = write_config(tmp_path, PRELOAD.replace("preload = 0.05\nfriction = 0.02", "preload = 0.0")
                          .replace("harmonics = 32", "harmonics = 32\nregularisation = 0.01"))
    result = invoke(["frf", str(config), "-o", "out"], tmp_path)
    assert_bad_input(result, "`analysis.regularisation` = 0.01 applies only to a discontinuous law")
    assert not (tmp_path / "out").exists()


def test_omega_options_override_the_range_of_a_discontinuous_law(tmp_path):
    config = write_config(tmp_path, PRELOAD)
    result = invoke(["frf", str(config), "--omega-min", "1e-9", "-o", "out"], tmp_path)
    assert_bad_input(result, "`--omega-min`")
    result = invoke(["frf", str(config), "--rpm-min", "800", "-o", "out"], tmp_path)
    assert_bad_input(result, "`--rpm-min` needs a model with an engine")
    assert not (tmp_path / "out").exists()


def test_orbit_writes_the_exact_orbit_with_its_stick_phase(tmp_path):
    """The reference clutch with friction 0.02 on the main stage sticks once per period at Ω = 0.35;
    orbit.csv holds the exact orbit (its rms over the period is the json's) with the mode column."""
    from rattle.results import NONSMOOTH_ORBIT_COLUMNS

    text = (Path(__file__).resolve().parents[2] / "examples" / "clutch_friction.toml").read_text()
    config = write_config(tmp_path, text.replace("harmonics = 64", "harmonics = 32"))
    result = invoke(["orbit", str(config), "--omega", "0.35", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["orbit.csv", "orbit.json", "orbit.png"]
    assert (out / "orbit.png").read_bytes()[:8] == PNG
    assert (out / "orbit.csv").read_text().splitlines()[0] == ",".join(NONSMOOTH_ORBIT_COLUMNS)
    table = read_csv(out / "orbit.csv")
    meta = json.loads((out / "orbit.json").read_text())
    assert meta["status"] == "converged" and meta["command"] == "orbit" and meta["settings"]["harmonics"] == 32
    orbit = meta["orbit"]
    assert orbit["matched"] and orbit["stable"] and orbit["period"] == pytest.approx(2 * math.pi / 0.35, rel=1e-15)
    modes = list(table["mode"])
    assert "stick" in modes and "slip" in modes
    # the stick phase: δ' = 0 and δ constant over the rows the csv marks "stick"
    d, v = (np.asarray(table[k], dtype=float) for k in ("delta", "velocity"))
    held = np.array([m == "stick" for m in modes])
    assert np.max(np.abs(v[held])) == 0.0 and np.ptp(d[held]) == 0.0
    (a, b, kind), = orbit["phases"]
    assert kind == "stick" and b - a == pytest.approx(orbit["stick_time"], rel=1e-12)
    assert "sticks or locks 1 time(s) per period" in result.stdout
    # every orbit at Ω beside it (the census of Ω (1 ± 0.05)): the orbit asked for is one of them,
    # with the same rms and stability
    listed = orbit["orbits"]
    assert listed and all(o["period"] >= 1 for o in listed)
    assert any(abs(o["rms"] - orbit["rms"]) <= 1e-9 and o["stable"] for o in listed)
    assert "every orbit at Ω = 0.35 rad/s (exact" in result.stdout


def test_orbit_of_a_discontinuous_law_refuses_period_and_range_options(tmp_path):
    config = write_config(tmp_path, PRELOAD)
    assert_bad_input(invoke(["orbit", str(config), "--omega", "1.2", "--period", "3", "-o", "out"], tmp_path),
                     "`--period` 3", "period 1 or 2")
    assert_bad_input(invoke(["orbit", str(config), "--omega", "1.2", "--omega-min", "1.0", "-o", "out"], tmp_path),
                     "`--omega-min` is not used for a discontinuous law")
    assert_bad_input(invoke(["orbit", str(config), "--omega", "1e-9", "-o", "out"], tmp_path), "`--omega`")
    assert not (tmp_path / "out").exists()


def test_an_incomplete_continuation_writes_its_rows_and_exits_1(tmp_path, monkeypatch):
    """As the smooth frf: the rows computed are written as the set, then exit status 1 naming them."""
    import dataclasses

    import rattle.analysis._nonsmooth as module
    from rattle.errors import Status

    real = module.nonsmooth_response  # the builder under rattle.frequency_response

    def stopped(*args, **kwargs):
        return dataclasses.replace(real(*args, **kwargs), status=Status.MAX_STEPS, message="")

    monkeypatch.setattr(module, "nonsmooth_response", stopped)
    config = write_config(tmp_path, PRELOAD.replace("omega = [1.2, 1.25]", "omega = [1.2, 1.21]"))
    result = invoke(["frf", str(config), "-o", "out"], tmp_path)
    assert result.exit_code == 1, (result.stdout, result.stderr)
    assert "frequency response incomplete: the maximum number of continuation steps" in result.stderr
    assert "were written to" in result.stderr and "frf.csv" in result.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    assert json.loads((tmp_path / "out" / "frf.json").read_text())["status"] == "max_steps"


#: The torque converter's preloaded spring (examples/torque_converter_preload.toml) around its
#: period doublings at Ω ≈ 0.545 and 0.562.
TORQUE_CONVERTER = preload_spring_toml((0.53, 0.575), 64, friction=None) + 'method = "hb"\n'


def test_frf_subharmonics_writes_the_period_two_branch_with_the_primary(tmp_path):
    config = write_config(tmp_path, TORQUE_CONVERTER)
    result = invoke(["frf", str(config), "--subharmonics", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    table = read_csv(tmp_path / "out" / "frf.csv")
    branch, period = np.asarray(table["branch"]), np.asarray(table["period"])
    assert set(branch.tolist()) == {0, 1}
    assert np.all(period[branch == 0] == 1) and np.all(period[branch == 1] == 2)
    assert np.all(np.diff(np.flatnonzero(branch == 1)) == 1)  # the primary's rows first, then the branch's
    two = branch == 1
    matched = np.asarray(table["matched"], dtype=bool)
    assert np.any(two & matched & np.asarray(table["stable"], dtype=bool))
    meta = json.loads((tmp_path / "out" / "frf.json").read_text())
    (b,) = meta["branches"]
    assert b["branch"] == 1 and b["period"] == 2 and b["points"] == int(two.sum())
    assert b["matched"] == int((two & matched).sum()) and b["stable"] > 0 and b["rms_error_max"] < 0.005
    assert meta["options"]["subharmonics"] is True
    assert "branch 1 (period 2" in result.stdout and "stable over Ω" in result.stdout


def test_frf_without_subharmonics_points_to_them_at_a_period_doubling(tmp_path):
    config = write_config(tmp_path, TORQUE_CONVERTER)
    result = invoke(["frf", str(config), "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    assert "run with --subharmonics" in result.stdout
    assert set(np.asarray(read_csv(tmp_path / "out" / "frf.csv")["branch"]).tolist()) == {0}
    assert json.loads((tmp_path / "out" / "frf.json").read_text())["branches"] == []


def test_orbit_period_two_writes_the_period_doubled_orbit(tmp_path):
    """``rattle orbit --period 2`` inside the torque converter's period-2 window: the exact orbit
    over two forcing periods (not the period-1 orbit run twice), stable, with its HB of period 2
    beside it; where the motion has period 1 it exits 1 with nothing written."""
    config = write_config(tmp_path, TORQUE_CONVERTER)
    result = invoke(["orbit", str(config), "--omega", "0.552", "--period", "2", "--single", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    meta = json.loads((tmp_path / "out" / "orbit.json").read_text())
    orbit = meta["orbit"]
    assert orbit["periods"] == 2 and orbit["period"] == pytest.approx(2 * 2 * math.pi / 0.552, rel=1e-12)
    assert orbit["stable"] is True and orbit["matched"] is True and abs(orbit["rms_error"]) < 0.005
    assert meta["settings"]["period"] == 2 and meta["settings"]["harmonics"] == 128
    table = read_csv(tmp_path / "out" / "orbit.csv")
    t, d = (np.asarray(table[k], dtype=float) for k in ("t", "delta"))
    T = 2 * math.pi / 0.552
    half = int(np.argmin(np.abs(t - T)))
    assert t[-1] == pytest.approx(2 * T) and abs(d[half] - d[0]) > 1e-3 * np.ptp(d)
    result = invoke(["orbit", str(config), "--omega", "0.7", "--period", "2", "--single", "-o", "out2"], tmp_path)
    assert result.exit_code == 1 and "no periodic orbit of period 2" in result.stderr
    assert not (tmp_path / "out2").exists()


@pytest.mark.parametrize("option", [["--start", "high"], ["--fixed-harmonics"]])
def test_harmonic_balance_options_are_refused_for_a_jump_law(tmp_path, option):
    """``rattle frf`` is one path for every law: an option of the harmonic balance of a continuous
    law is refused by the one front end (exit 2, the argument named, nothing written), not ignored."""
    config = write_config(tmp_path, PRELOAD)
    result = invoke(["frf", str(config), *option, "-o", "out"], tmp_path)
    assert result.exit_code == 2, (result.stdout, result.stderr)
    assert "must be left at the default for a law with jumps or friction" in result.stderr
    assert result.stderr.startswith(f"rattle: error: `{option[0]}`")  # the option as the user typed it
    assert not (tmp_path / "out").exists()
