"""``rattle`` on a chain with Coulomb friction on its elements (``[[model.elements]] friction``):
``rattle frf`` writes the chain's non-smooth response (a FrequencyResponse with a FrictionCheck) as one set, ``rattle
orbit`` one exact orbit with the regularised HB's beside it (a FrictionOrbitResult); map refuses
it (exit 2, nothing written) and says that frf and orbit solve it (``rattle sweep`` and ``rattle
compare`` on it: test_cli_nonsmooth_sweep.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli_helpers import PNG, assert_bad_input, invoke, write_config
from rattle.io import load_config, read_csv

#: Two inertias, the second grounded by a soft link; a clutch (3 stages) with friction on its
#: first stage (|δ| < b) only; the forcing on inertia 1.
CHAIN = """\
[model]
inertias = [1.0, 1.0]

[[model.links]]
between = [2, 0]
stiffness = 0.1
damping = 0.05

[[model.links]]
between = [1, 2]
damping = 0.02

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 1.0
type = "clutch"
alpha = 0.25
b = 0.1
friction = [0.0, 0.03, 0.0]

[[excitation.torques]]
inertia = 1
mean = 0.05
amplitudes = [0.06]

[analysis]
omega = [0.9, 0.95]
harmonics = 16
method = "hb"            # the regularised harmonic balance, every row checked (the default is exact shooting)
"""


def test_map_refuses_the_regularised_method_on_a_chain_with_friction_and_writes_nothing(tmp_path):
    """CHAIN asks for the regularised HB (``method = "hb"``): ``rattle map`` solves a chain with
    friction by exact shooting and refuses it naming the key (exit 2, nothing written)."""
    config = write_config(tmp_path, CHAIN)
    result = invoke(["map", str(config), "--vary", "mean=0.04,0.05", "-o", "out"], tmp_path)
    assert_bad_input(result, '`analysis.method` = "hb"', "by exact shooting")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("args, fragments", [
    (["--period", "3"], ["`--period` 3", "a chain with friction on its elements", "computed for period 1 or 2"]),
    (["--omega-min", "0.5"], ["`--omega-min` is not used for a chain with friction", "leave it out"]),
    (["--omega-max", "1.5"], ["`--omega-max` is not used for a chain with friction"]),
    (["--harmonics", "0"], ["`--harmonics`"]),
])
def test_orbit_refuses_options_it_does_not_take_on_a_chain_with_friction(tmp_path, args, fragments):
    config = write_config(tmp_path, CHAIN)
    result = invoke(["orbit", str(config), "--omega", "0.9", *args, "-o", "out"], tmp_path)
    assert_bad_input(result, *fragments)
    assert not (tmp_path / "out").exists()


def test_orbit_writes_the_exact_orbit_of_the_chain_as_one_set(tmp_path):
    """``rattle orbit`` on the chain: orbit.csv (t, then clutch_delta, clutch_velocity, clutch_stuck,
    clutch_delta_hb), orbit.json (settings, elements, the orbit's measures) and orbit.png; the csv's
    clutch_delta is the exact orbit's (its rms is the json's, and that of Newton shooting of the
    event-driven flow from rest to 1e-9)."""
    from rattle.results import FRICTION_ORBIT_ELEMENT_COLUMNS
    from rattle.timeint import shoot_friction_orbit

    config = write_config(tmp_path, CHAIN)
    result = invoke(["orbit", str(config), "--omega", "0.9", "--single", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["orbit.csv", "orbit.json", "orbit.png"]
    assert (out / "orbit.png").read_bytes()[:8] == PNG
    header = (out / "orbit.csv").read_text().splitlines()[0].split(",")
    assert header == ["t", *[f"clutch_{c}" for c in FRICTION_ORBIT_ELEMENT_COLUMNS]]
    meta = json.loads((out / "orbit.json").read_text())
    assert meta["command"] == "orbit" and meta["status"] == "converged" and meta["options"] == {"omega": 0.9}
    assert meta["settings"]["harmonics"] == 16 and meta["settings"]["regularisation"] == 0.001
    assert meta["system"] == {"coordinates": 2, "elements": [
        {"name": "clutch", "law": {"type": "clutch", "alpha": 0.25, "b": 0.1}, "friction": [0.0, 0.03, 0.0]}]}
    orbit = meta["orbit"]
    assert orbit["converged"] and orbit["matched"] and orbit["omega"] == 0.9 and "friction_orbit" in meta["timings"]
    clutch = orbit["elements"][0]
    table = read_csv(out / "orbit.csv")
    t, d = np.asarray(table["t"], dtype=float), np.asarray(table["clutch_delta"], dtype=float)
    assert t[0] == 0.0 and t[-1] == pytest.approx(2 * np.pi / 0.9, rel=1e-15)
    assert np.sqrt(np.trapezoid(d**2, t) / t[-1]) == pytest.approx(clutch["rms"], rel=1e-4)
    exact = shoot_friction_orbit(load_config(config).model, 0.9, np.zeros(4))
    assert exact.converged and abs(float(exact.rms[0]) - clutch["rms"]) <= 1e-9
    assert abs(clutch["rms_hb"] / clutch["rms"] - 1.0) <= 0.01  # measured 0.46 % (H = 16)
    assert "clutch: exact rms" in result.stdout and "HB (H = 16, ε = 0.001)" in result.stdout
    assert result.stdout.rstrip().endswith("wrote orbit.csv, orbit.json, orbit.png to out")


def test_frf_refuses_bad_friction_with_nothing_written(tmp_path):
    for old, new, fragments in [
        ("friction = [0.0, 0.03, 0.0]", "friction = [0.03, 0.0]",
         ["`model.elements.1.friction` must hold one level", 'type = "clutch" has 3 stages', "give 3 levels"]),
        ("friction = [0.0, 0.03, 0.0]", "friction = -0.01", ["`model.elements.1.friction`", "must be >= 0"]),
        ("friction = [0.0, 0.03, 0.0]", "friction = [0.0, 0.03, 0.0]\npreload = 0.05",
         ["`model.elements.1.preload` does not belong to type = \"clutch\"", '("preload")']),
        ("harmonics = 16", "harmonics = 16\nregularisation = 1.5", ["`analysis.regularisation`", "0 < ε < 1"]),
    ]:
        assert old in CHAIN
        result = invoke(["frf", str(write_config(tmp_path, CHAIN.replace(old, new))), "-o", "out"], tmp_path)
        assert_bad_input(result, *fragments)
    config = write_config(tmp_path, CHAIN)
    result = invoke(["frf", str(config), "--rpm-min", "800", "-o", "out"], tmp_path)
    assert_bad_input(result, "`--rpm-min` needs a model with an engine")
    result = invoke(["frf", str(config), "--omega-max", "1e9", "-o", "out"], tmp_path)
    assert_bad_input(result, "`--omega-max` must be <=")
    assert not (tmp_path / "out").exists()


#: The same chain with friction 0.02 on every stage, forced harder, over a narrow range above the
#: clutch's first resonance: the element slips through every reversal, the HB matches (0.2 s).
SLIPPING = (CHAIN.replace("friction = [0.0, 0.03, 0.0]", "friction = 0.02")
            .replace("amplitudes = [0.06]", "amplitudes = [0.2]").replace("omega = [0.9, 0.95]", "omega = [0.8, 0.82]").replace("harmonics = 16", "harmonics = 32"))


@pytest.fixture(scope="module")
def frf_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("chain_friction")
    config = write_config(folder, SLIPPING)
    result = invoke(["frf", str(config), "-o", "out"], folder)
    return folder, config, result


def test_frf_writes_the_friction_response_as_one_set(frf_run):
    from rattle.results._friction import FRICTION_ELEMENT_COLUMNS, FRICTION_TAIL_COLUMNS

    folder, _config, result = frf_run
    assert result.exit_code == 0, (result.stdout, result.stderr)
    out = folder / "out"
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    assert (out / "frf.png").read_bytes()[:8] == PNG
    header = (out / "frf.csv").read_text().splitlines()[0].split(",")
    assert header == ["branch", "period", "omega", *[f"clutch_{c}" for c in FRICTION_ELEMENT_COLUMNS],
                      *FRICTION_TAIL_COLUMNS]
    assert "chain with friction, elements clutch" in result.stdout
    assert "status: success" in result.stdout and "clutch: largest exact rms" in result.stdout
    assert result.stdout.rstrip().endswith("wrote frf.csv, frf.json, frf.png to out")


def test_frf_json_holds_the_settings_the_elements_and_the_measured_error(frf_run):
    folder, _config, _result = frf_run
    meta = json.loads((folder / "out" / "frf.json").read_text())
    table = read_csv(folder / "out" / "frf.csv")
    matched = np.asarray(table["matched"], dtype=bool)
    err = np.abs(np.asarray(table["rms_error"], dtype=float)[matched])
    assert meta["command"] == "frf" and meta["status"] == "success" and meta["version"]
    assert meta["analysis"] == {"omega": [0.8, 0.82], "harmonics": 32, "regularisation": 0.001, "refine": 0.005,
                                "limit_harmonics": 32, "method": "hb"}  # a chain's ladder keeps its H by default
    assert meta["settings"]["harmonics"] == 32 and meta["settings"]["regularisation"] == 0.001
    assert meta["system"]["coordinates"] == 2
    assert meta["system"]["elements"] == [{"name": "clutch", "law": {"type": "clutch", "alpha": 0.25, "b": 0.1},
                                           "friction": [0.02, 0.02, 0.02], "sticking_rows": 0}]
    assert meta["points"] == len(table["omega"]) and meta["matched"] == int(matched.sum()) == len(table["omega"])
    assert meta["max_rms_error"] == pytest.approx(float(np.max(err)), rel=1e-12)
    assert meta["config"]["model"]["elements"][0]["friction"] == 0.02
    assert meta["timings"]["cli_wall_time"] > 0 and "frequency_response" in meta["timings"]


def test_frf_exact_rms_is_the_independent_exact_orbit(frf_run):
    """The csv's clutch_rms is the exact orbit's: Newton shooting of the event-driven flow from rest
    at the first row's Ω lands on it to 1e-9, and the HB's rms differs from it by the row's error."""
    from rattle.timeint import shoot_friction_orbit

    folder, config, _result = frf_run
    table = read_csv(folder / "out" / "frf.csv")
    assert bool(table["matched"][0])
    orbit = shoot_friction_orbit(load_config(config).model, float(table["omega"][0]), np.zeros(4))
    assert orbit.converged
    assert abs(float(orbit.rms[0]) - float(table["clutch_rms"][0])) <= 1e-9
    assert abs(float(orbit.mean[0]) - float(table["clutch_mean"][0])) <= 1e-9
    assert float(table["clutch_stick"][0]) == 0.0
    rel = float(table["clutch_rms_hb"][0]) / float(orbit.rms[0]) - 1.0
    assert rel == pytest.approx(float(table["clutch_rms_error"][0]), abs=1e-9)
    assert rel == pytest.approx(float(table["rms_error"][0]), abs=1e-9)  # one element: the row's error


def test_an_incomplete_continuation_writes_its_rows_and_exits_1(tmp_path, monkeypatch):
    import dataclasses

    import rattle.analysis._nonsmooth as module
    from rattle.errors import Status

    real = module.nonsmooth_response  # the builder under rattle.frequency_response

    def stopped(*args, **kwargs):
        return dataclasses.replace(real(*args, **kwargs), status=Status.MAX_STEPS, message="")

    monkeypatch.setattr(module, "nonsmooth_response", stopped)
    config = write_config(tmp_path, SLIPPING.replace("omega = [0.8, 0.82]", "omega = [0.8, 0.805]"))
    result = invoke(["frf", str(config), "-o", "out"], tmp_path)
    assert result.exit_code == 1, (result.stdout, result.stderr)
    assert "frequency response incomplete: the maximum number of continuation steps" in result.stderr
    assert "were written to" in result.stderr and "frf.csv" in result.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    assert json.loads((tmp_path / "out" / "frf.json").read_text())["status"] == "max_steps"


#: A four-cylinder engine driving a two-stage clutch damper (SI): friction 2 N m on the idle stage
#: only (K_e = 1720 N m/rad: r = 2/1720), the engine's mean torque taken by a constant drag.
ENGINE = """\
[model]
units = "SI"
inertias = [0.15, 0.01]

[[model.links]]
between = [1, 2]
damping = 0.15

[[model.elements]]
name = "damper"
between = [1, 2]
stiffness = 1720.0
type = "clutch"
alpha = 0.05
b_deg = 4.0
friction = [0.0, 2.0, 0.0]

[engine]
inertia = 1
cylinders = 4
speed_rpm = [400.0, 1500.0]
mean_torque = 5.0
orders = [2.0, 4.0]
amplitudes = [60.0, 10.0]

[[excitation.torques]]
inertia = 2
mean = -5.0

[analysis]
harmonics = 32
method = "hb"
"""


def test_frf_on_an_engine_chain_with_friction_in_si_takes_rpm_options_and_writes_rpm(tmp_path):
    config = write_config(tmp_path, ENGINE)
    result = invoke(["frf", str(config), "--rpm-min", "1000", "--rpm-max", "1020", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    table = read_csv(tmp_path / "out" / "frf.csv")
    rpm, omega = np.asarray(table["speed_rpm"], dtype=float), np.asarray(table["omega"], dtype=float)
    assert rpm[0] == pytest.approx(1000.0, rel=1e-12) and rpm[-1] == pytest.approx(1020.0, rel=1e-12)
    np.testing.assert_allclose(omega, rpm * 2.0 * 2.0 * np.pi / 60.0, rtol=1e-12)  # base order 2
    meta = json.loads((tmp_path / "out" / "frf.json").read_text())
    np.testing.assert_allclose(meta["system"]["elements"][0]["friction"], [0.0, 2.0 / 1720.0, 0.0], rtol=1e-15)
    assert meta["options"] == {"rpm_min": 1000.0, "rpm_max": 1020.0}
    assert "engine speed 1000 … 1020 rpm" in result.stdout


def test_frf_on_an_engine_chain_with_friction_and_a_drag_by_speed(tmp_path):
    """engine_clutch_drag_si.toml with friction on its damper: the speed-dependent drag joins the
    regularised HB's mean and the exact flow's; the run starts (from the exact orbit's spectrum
    where Newton from the linearised chain fails) and every row is matched."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "examples" / "engine_clutch_drag_si.toml").read_text()
    i = text.index('type = "clutch"')
    j = text.index("\n", i)
    text = text[: j + 1] + "friction = 2.0\n" + text[j + 1:]
    text = text.replace("[analysis]\n", '[analysis]\nmethod = "hb"\n') if "[analysis]\n" in text else \
        text + '\n[analysis]\nmethod = "hb"\n'  # the regularised HB's start is what is tested
    config = write_config(tmp_path, text)
    result = invoke(["frf", str(config), "--rpm-min", "1000", "--rpm-max", "1050", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    table = read_csv(tmp_path / "out" / "frf.csv")
    assert all(table["matched"])
    assert np.nanmax(np.abs(np.asarray(table["rms_error"], dtype=float))) < 0.05


#: CHAIN with a lock-up clutch in place of the damper: a torque jump ±0.03 K_e at δ = 0, friction 0.01.
PRELOAD_CHAIN = CHAIN.replace('type = "clutch"\nalpha = 0.25\nb = 0.1\nfriction = [0.0, 0.03, 0.0]',
                              'type = "preload"\npreload = 0.03\nfriction = 0.01')


def test_a_preload_element_is_solved_by_orbit_and_named_where_refused(tmp_path):
    """``rattle orbit`` on the chain with a preloaded element: the exact orbit (rms that of Newton
    shooting from rest to 1e-9), orbit.json naming the jump law; ``rattle map`` refuses its
    ``method = "hb"``; the default ε of a chain with a jump is 0.01."""
    from rattle.timeint import shoot_friction_orbit

    assert PRELOAD_CHAIN != CHAIN
    config = write_config(tmp_path, PRELOAD_CHAIN)
    result = invoke(["orbit", str(config), "--omega", "0.9", "--single", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    meta = json.loads((tmp_path / "out" / "orbit.json").read_text())
    assert meta["settings"]["regularisation"] == 0.01
    assert meta["system"]["elements"][0]["law"] == {"type": "preload", "preload": 0.03, "clearance": 0.0, "slope": 1.0}
    exact = shoot_friction_orbit(load_config(config).model, 0.9, np.zeros(4))
    assert exact.converged and abs(float(exact.rms[0]) - meta["orbit"]["elements"][0]["rms"]) <= 1e-9
    result = invoke(["map", str(config), "--vary", "mean=0.04,0.05", "-o", "map"], tmp_path)
    assert_bad_input(result, '`analysis.method` = "hb"')  # the map solves it by exact shooting only
    assert not (tmp_path / "map").exists()
