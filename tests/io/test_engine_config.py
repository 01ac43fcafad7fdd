"""SPEC §6 configurations: units, angles in degrees, [engine] by order; refusals with exit 2."""

import math
import tomllib

import numpy as np
import pytest
from click.testing import CliRunner

from rattle.cli.main import cli
from rattle.errors import ConfigError
from rattle.io import config_from_dict, dumps_toml, load_config, model_to_toml_dict

#: A two-inertia free clutch chain in SI with a 4-cylinder engine's orders 2 and 4.
SI = """
[model]
units = "SI"
inertias = [0.2, 0.05]

[[model.links]]
between = [1, 2]
damping = 0.25

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 500.0
type = "clutch"
alpha = 0.25
b_deg = 10.0

[engine]
inertia = 1
cylinders = 4
speed_rpm = [600.0, 3000.0]
mean_torque = 25.0
orders = [2.0, 4.0]
amplitudes = [60.0, 15.0]
phases = [0.0, 0.5]

[[excitation.torques]]
inertia = 2
mean = -25.0

[analysis]
harmonics = 8
"""


def _load(text):
    return config_from_dict(tomllib.loads(text), source_name="si.toml")


def test_si_engine_config_reads_as_the_hand_calculation():
    cfg = _load(SI)
    chain = cfg.model
    assert cfg.units == "SI"
    assert chain.elements[0].law.b == math.radians(10.0) == 10.0 * math.pi / 180.0
    assert chain.speed_order == 2.0  # gcd of orders 2 and 4
    # Ω = base order · 2π/60 · rpm
    assert cfg.analysis.omega_min == pytest.approx(2.0 * 2.0 * math.pi / 60.0 * 600.0, rel=1e-15)
    assert cfg.analysis.omega_max == pytest.approx(2.0 * 2.0 * math.pi / 60.0 * 3000.0, rel=1e-15)
    engine = [t for t in chain.torques if t.inertia == 1]
    assert len(engine) == 1
    assert engine[0].mean == 25.0
    assert engine[0].amplitudes == (60.0, 15.0)  # order 2 → harmonic 1, order 4 → harmonic 2
    assert engine[0].phases == (0.0, 0.5)


def test_half_orders_go_to_their_harmonics_with_zeros_between():
    text = SI.replace("orders = [2.0, 4.0]", "orders = [0.5, 1.5, 2.0]").replace(
        "amplitudes = [60.0, 15.0]", "amplitudes = [5.0, 8.0, 60.0]").replace("phases = [0.0, 0.5]\n", "")
    chain = _load(text).model
    assert chain.speed_order == 0.5
    engine = [t for t in chain.torques if t.inertia == 1][0]
    assert engine.amplitudes == (5.0, 0.0, 8.0, 60.0)  # h = 1, 3, 4


def test_engine_torque_adds_to_a_torque_on_the_same_inertia():
    text = SI + "\n[[excitation.torques]]\ninertia = 1\namplitudes = [0.0, 0.0, 3.0]\n"
    chain = _load(text).model
    _, Th = chain.torque_vectors()
    assert Th[0, 0] == pytest.approx(60.0) and Th[2, 0] == pytest.approx(3.0)
    assert Th[1, 0] == pytest.approx(15.0 * complex(math.cos(0.5), math.sin(0.5)))


def test_round_trip_writes_rad_keys_and_keeps_the_speed_order():
    cfg = _load(SI)
    text = dumps_toml(cfg.to_dict())
    assert "b_deg" not in text and "b = 0.17453292519943295" in text and "[engine]" not in text
    again = _load(text)
    assert again.model.to_dict() == cfg.model.to_dict()
    assert again.model.speed_order == 2.0 and again.units == "SI"
    assert again.analysis == cfg.analysis
    plain = config_from_dict(model_to_toml_dict(cfg.model, cfg.analysis))
    assert plain.model.to_dict() == cfg.model.to_dict() and plain.units == "dimensionless"


def test_degree_keys_of_a_piecewise_element_and_with_dimensionless_units():
    text = SI.replace('type = "clutch"\nalpha = 0.25\nb_deg = 10.0',
                      'type = "piecewise"\nbreakpoints_deg = [-20.0, -5.0, 5.0, 10.0]\nslopes = [1.0, 0.3, 0.1, 0.3, 1.0]')
    law = _load(text).model.elements[0].law
    assert np.allclose(law.breakpoints, np.radians([-20.0, -5.0, 5.0, 10.0]), rtol=1e-15, atol=0)
    single = """
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0
[model.elastic]
type = "clutch"
alpha = 0.25
b_deg = 10.0
[excitation]
mean = 0.05
amplitudes = [0.03]
"""
    assert _load(single).model.elastic.b == math.radians(10.0)  # degrees accepted in dimensionless form too


@pytest.mark.parametrize(
    "edit, key",
    [
        (("b_deg = 10.0", "b_deg = 10.0\nb = 0.17"), "`model.elements.1.b` and `model.elements.1.b_deg`"),
        (("b_deg = 10.0", "b_deg = 10.0\nalpha_deg = 3.0"), "`model.elements.1.alpha_deg`"),
        (("b_deg = 10.0", "b_deg = 10.0\ngap_deg = 3.0"), "`model.elements.1.gap_deg`"),
        (("b_deg = 10.0", "b_deg = -10.0"), "`model.elements.1.b_deg`"),
        (('units = "SI"', 'units = "imperial"'), "`model.units`"),
        (('units = "SI"\n', ""), "`engine` needs `model.units`"),
        (("inertias = [0.2, 0.05]", "inertias = [-0.2, 0.05]"), "`model.inertias.1`"),
        (("orders = [2.0, 4.0]", f"orders = [2.0, {2.0 * math.sqrt(2.0)!r}]"), "`engine.orders.2`"),
        (("orders = [2.0, 4.0]", "orders = [2.0, -4.0]"), "`engine.orders.2`"),
        (("orders = [2.0, 4.0]", "orders = [2.0]"), "`engine.amplitudes`"),
        (("orders = [2.0, 4.0]", "orders = [0.25, 100.0]"), "`engine.orders`"),  # harmonic 400 > 256
        (("speed_rpm = [600.0, 3000.0]", "speed_rpm = [3000.0, 600.0]"), "`engine.speed_rpm`"),
        (("speed_rpm = [600.0, 3000.0]", "speed_rpm = [0.0, 600.0]"), "`engine.speed_rpm`"),
        (("inertia = 1\ncylinders", "inertia = 3\ncylinders"), "`engine.inertia`"),
        (("cylinders = 4", "cylinders = 0"), "`engine.cylinders`"),
        (("amplitudes = [60.0, 15.0]", "amplitudes = [60.0, -15.0]"), "`engine.amplitudes.2`"),
        (("mean = -25.0", "mean = -20.0"), "`engine.mean_torque`"),
        (("harmonics = 8", "harmonics = 1"), "`analysis.harmonics`"),
        (("harmonics = 8", "harmonics = 8\nomega = [1.0, 2.0]"), "`analysis.omega` and `engine.speed_rpm`"),
        (("cylinders = 4", "cylinders = 4\nrpm = 3"), "`engine.rpm`"),
    ],
)
def test_refusals_name_the_key(edit, key):
    old, new = edit
    assert old in SI
    with pytest.raises(ConfigError) as err:
        _load(SI.replace(old, new, 1))
    assert key in str(err.value), str(err.value)


def test_engine_on_a_single_equation_config_is_refused():
    text = """
[model]
units = "SI"
inertia = 0.04
damping = 0.22
stiffness = 500.0
[model.elastic]
type = "clutch"
alpha = 0.25
b_deg = 10.0
[excitation]
mean = 0.05
amplitudes = [0.03]
[engine]
inertia = 1
speed_rpm = [600.0, 3000.0]
orders = [2.0]
amplitudes = [60.0]
"""
    with pytest.raises(ConfigError) as err:
        _load(text)
    assert "`engine`" in str(err.value) and "[model] inertias" in str(err.value)


@pytest.mark.parametrize(
    "edit, key",
    [
        (("inertias = [0.2, 0.05]", "inertias = [-0.2, 0.05]"), "`model.inertias.1`"),
        (("b_deg = 10.0", "b_deg = 10.0\nb = 0.17"), "`model.elements.1.b_deg`"),
        (("orders = [2.0, 4.0]", f"orders = [2.0, {2.0 * math.sqrt(2.0)!r}]"), "`engine.orders.2`"),
        (("speed_rpm = [600.0, 3000.0]", "speed_rpm = [3000.0, 3000.0]"), "`engine.speed_rpm`"),
        (("inertia = 1\ncylinders", "inertia = 0\ncylinders"), "`engine.inertia`"),
    ],
)
def test_cli_refuses_with_exit_2(tmp_path, edit, key):
    old, new = edit
    (tmp_path / "case.toml").write_text(SI.replace(old, new, 1), encoding="utf-8")
    try:
        runner = CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        runner = CliRunner()
    result = runner.invoke(cli, ["frf", str(tmp_path / "case.toml"), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    assert key in result.stderr
    assert not (tmp_path / "out" / "frf.csv").exists()


def test_load_config_of_the_example(tmp_path):
    from pathlib import Path

    example = Path(__file__).resolve().parents[2] / "examples" / "engine_clutch_si.toml"
    cfg = load_config(example)
    assert cfg.units == "SI" and cfg.model.speed_order == 2.0


def _invoke(args):
    try:
        runner = CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        runner = CliRunner()
    return runner.invoke(cli, args)


@pytest.mark.parametrize(
    "options, key",
    [
        (["--rpm-min", "700", "--omega-min", "100"], "`--omega-min` and `--rpm-min`"),
        (["--rpm-min", "0"], "`--rpm-min`"),
        (["--rpm-min", "900", "--rpm-max", "800"], "`--rpm-min` must be < `--rpm-max`"),
    ],
)
def test_cli_rpm_options_refused(tmp_path, options, key):
    (tmp_path / "case.toml").write_text(SI, encoding="utf-8")
    result = _invoke(["frf", str(tmp_path / "case.toml"), "-o", str(tmp_path / "out"), *options])
    assert result.exit_code == 2 and key in result.stderr, (result.exit_code, result.stderr)


def test_cli_rpm_options_need_an_engine(tmp_path):
    from pathlib import Path

    example = Path(__file__).resolve().parents[2] / "examples" / "reference_clutch.toml"
    result = _invoke(["frf", str(example), "-o", str(tmp_path / "out"), "--rpm-min", "100"])
    assert result.exit_code == 2 and "`--rpm-min` needs a model with an engine" in result.stderr


def test_cli_frf_in_rpm_writes_speed_rpm(tmp_path):
    import csv

    (tmp_path / "case.toml").write_text(SI, encoding="utf-8")
    result = _invoke(["frf", str(tmp_path / "case.toml"), "-o", str(tmp_path / "out"), "--harmonics", "4",
                      "--rpm-min", "2000", "--rpm-max", "2400"])
    assert result.exit_code == 0, result.stderr
    rows = list(csv.DictReader((tmp_path / "out" / "frf.csv").open()))
    rpm = np.array([float(r["speed_rpm"]) for r in rows])
    omega = np.array([float(r["omega"]) for r in rows])
    assert rpm.min() == pytest.approx(2000.0, rel=1e-12) and rpm.max() == pytest.approx(2400.0, rel=1e-12)
    assert np.allclose(rpm, omega * 60.0 / (2.0 * math.pi * 2.0), rtol=1e-12)
    assert "rpm" in result.stdout


def test_engine_phases_in_degrees():
    chain = _load(SI.replace("phases = [0.0, 0.5]", "phases_deg = [0.0, 90.0]")).model
    engine = [t for t in chain.torques if t.inertia == 1][0]
    assert engine.phases == (0.0, math.pi / 2)
    with pytest.raises(ConfigError, match="`engine.orders_deg`"):
        _load(SI.replace("phases = [0.0, 0.5]", "orders_deg = [1.0]"))
