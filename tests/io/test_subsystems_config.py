"""Sub-system shapes of the configuration file (rattle.model._table_shapes): each equals its Python
builder; bad physical input refused naming the key (exit 2 on the command line)."""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np

import pytest
import tomllib
from click.testing import CliRunner

from rattle.cli.main import cli
from rattle.errors import ConfigError
from rattle.io import config_from_dict, load_config
from rattle.model import Link, Torque, clutch_damper, gear_pair, hub_spline, loose_gear

DAMPER = """
[model]
units = "SI"
inertias = [0.15, 0.012, 0.02]

[[model.links]]
between = [1, 2]
damping = 0.15

[[model.links]]
between = [3, 0]
stiffness = 1000.0
damping = 0.05

[[model.elements]]
name = "damper"
type = "damper"
between = [1, 2]
drive_stiffness_per_deg = [1.5, 30.0]
drive_angles_deg = [4.0]
coast_stiffness = [57.29577951308232, 1145.9155902616465]
coast_angles_deg = [3.0]
free_play_deg = 0.5

[[model.elements]]
name = "spline"
type = "spline"
between = [2, 3]
stiffness = 8000.0
backlash_deg = 1.0

[[excitation.torques]]
inertia = 1
mean = 5.0
amplitudes = [60.0]

[analysis]
omega = [50.0, 300.0]
harmonics = 8
"""

GEARS = """
[model]
units = "SI"

[model.gear_pair]
base_radii = [0.03, 0.04]
inertias = [5.0e-3, 6.0e-3]
mesh_stiffness = 2.0e8
mesh_damping_ratio = 0.05
backlash_um = 60.0

[[excitation.torques]]
inertia = 1
mean = 20.0
amplitudes = [25.0]

[[excitation.torques]]
inertia = 2
mean = -26.666666666666668
amplitudes = [4.0]

[analysis]
omega = [3000.0, 12000.0]
harmonics = 8
"""

LOOSE = """
[model]
units = "SI"

[model.loose_gear]
base_radii = [0.03, 0.04]
inertia = 2.0e-4
mesh_stiffness = 2.0e8
mesh_damping_ratio = 0.05
backlash_um = 100.0
drag_torque = 0.05
speed_rpm = [600.0, 3000.0]
orders = [2.0, 4.0]
drive_acceleration = [400.0, 100.0]
drive_phases_deg = [0.0, 90.0]

[analysis]
harmonics = 8
"""


def _data(text: str) -> dict:
    return tomllib.loads(text)


def test_damper_and_spline_equal_their_builders():
    cfg = config_from_dict(_data(DAMPER))
    damper, spline = cfg.model.elements
    ref = clutch_damper(drive_stiffness=[1.5 * 180 / math.pi, 30.0 * 180 / math.pi],
                        drive_angles=[math.radians(4.0)], coast_stiffness=[57.29577951308232, 1145.9155902616465],
                        coast_angles=[math.radians(3.0)], free_play=math.radians(0.5))
    assert damper.stiffness == pytest.approx(ref.stiffness, rel=1e-15)
    assert damper.law.breakpoints == pytest.approx(ref.law.breakpoints, rel=1e-15)
    assert damper.law.slopes == pytest.approx(ref.law.slopes, rel=1e-15)
    # by hand: stiffest stage 30 N m/deg = 1718.87 N m/rad; breakpoints −3, −0.25, 0.25, 4 deg
    assert damper.stiffness == pytest.approx(30.0 * 180 / math.pi)
    assert damper.law.breakpoints == pytest.approx(tuple(math.radians(x) for x in (-3.0, -0.25, 0.25, 4.0)))
    assert damper.law.slopes == pytest.approx((20 / 30, 1 / 30, 0.0, 1.5 / 30, 1.0))
    ref_s = hub_spline(backlash=math.radians(1.0), stiffness=8000.0)
    assert spline.law == ref_s.law and spline.stiffness == 8000.0 and spline.between == (2, 3)
    # the file as written is kept for provenance; the resolved configuration is ordinary
    assert cfg.source["model"]["elements"][0]["type"] == "damper"
    resolved = cfg.to_dict()
    assert resolved["model"]["elements"][0]["type"] == "piecewise"
    again = config_from_dict(resolved)
    assert again.model.elements == cfg.model.elements


def test_gear_pair_equals_its_builder_with_gear2_torques_scaled():
    cfg = config_from_dict(_data(GEARS))
    ref = gear_pair(base_radii=[0.03, 0.04], inertias=[5e-3, 6e-3], mesh_stiffness=2e8, mesh_damping_ratio=0.05,
                    backlash=60e-6, torques=[Torque(inertia=1, mean=20.0, amplitudes=[25.0]),
                                             Torque(inertia=2, mean=-26.666666666666668, amplitudes=[4.0])])
    chain = cfg.model
    assert chain.inertias == pytest.approx(ref.chain.inertias, rel=1e-15)
    assert chain.elements == ref.chain.elements
    assert chain.links[0].damping == pytest.approx(ref.damping, rel=1e-15)
    # torque on gear 2 × r1/r2 = 0.75: −20 N m and 3 N m on gear 1's side (hand calculation)
    t2 = next(t for t in chain.torques if t.inertia == 2)
    assert t2.mean == pytest.approx(-20.0, rel=1e-15) and t2.amplitudes == pytest.approx((3.0,))
    assert chain.elements[0].name == "mesh" and chain.elements[0].law.b == pytest.approx(1e-3)
    assert chain.elements[0].stiffness == pytest.approx(1.8e5)
    assert cfg.units == "SI"


def test_loose_gear_equals_its_builder_with_an_engine_axis():
    cfg = config_from_dict(_data(LOOSE))
    ref = loose_gear(base_radii=[0.03, 0.04], inertia=2e-4, mesh_stiffness=2e8, mesh_damping_ratio=0.05,
                     backlash=100e-6, drive_acceleration=[400.0, 100.0], drive_phases=[0.0, math.pi / 2],
                     drag_torque=0.05)
    chain = cfg.model
    assert chain.elements == ref.chain.elements and chain.links == ref.chain.links
    assert not chain.free and chain.speed_order == pytest.approx(2.0)
    (tq,) = chain.torques
    # J2 (r1/r2) A: 2e-4 · 0.75 · 400 = 0.06 N m at order 2 (harmonic 1), 0.015 at order 4; drag as mean
    assert tq.mean == pytest.approx(0.05) and tq.amplitudes == pytest.approx((0.06, 0.015))
    assert tq.phases == pytest.approx((0.0, math.pi / 2))
    # speed axis: Ω = 2 · 2π/60 · rpm
    assert cfg.analysis.omega == pytest.approx((2 * 2 * math.pi / 60 * 600, 2 * 2 * math.pi / 60 * 3000))


def _set(data: dict, path: str, value) -> dict:
    data = copy.deepcopy(data)
    keys = path.split(".")
    node = data
    for k in keys[:-1]:
        node = node[int(k)] if k.isdigit() else node[k]
    if value is _DEL:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value
    return data


_DEL = object()


@pytest.mark.parametrize("text, path, value, fragments", [
    (DAMPER, "model.elements.0.drive_angles_deg", [4.0, 3.0],
     ["`model.elements.1.drive_angles_deg`", "must have one entry fewer"]),
    (DAMPER, "model.elements.0.drive_stiffness_per_deg", [1.5, 30.0, 60.0],
     ["`model.elements.1.drive_angles_deg`", "must have one entry fewer"]),
    (DAMPER, "model.elements.0.drive_stiffness_per_deg", [1.5, -30.0],
     ["`model.elements.1.drive_stiffness_per_deg.2`", "must be > 0"]),
    (DAMPER, "model.elements.0.coast_stiffness", [0.0, 1000.0],
     ["`model.elements.1.coast_stiffness.1`", "must be > 0"]),
    (DAMPER, "model.elements.0.free_play_deg", 7.0,
     ["`model.elements.1.coast_angles_deg.1`", "free_play_deg/2"]),
    (DAMPER, "model.elements.0.stiffness", 100.0, ["`model.elements.1.stiffness` is not a known key"]),
    (DAMPER, "model.elements.0.coast_stiffness", _DEL, ["`model.elements.1.coast_stiffness` is missing"]),
    (DAMPER, "model.elements.0.drive_angles", [0.1],
     ["`model.elements.1.drive_angles` and `model.elements.1.drive_angles_deg` are both given"]),
    (DAMPER, "model.elements.0.type", "dampr", ["`model.elements.1.type` must be one of", 'did you mean "damper"']),
    (DAMPER, "model.elements.1.backlash_deg", -1.0, ["`model.elements.2.backlash_deg`", "must be > 0"]),
    (DAMPER, "model.elements.1.stiffness", 0.0, ["`model.elements.2.stiffness` must be > 0"]),
    (GEARS, "model.gear_pair.base_radii", [0.03, -0.04], ["`model.gear_pair.base_radii.2` must be > 0"]),
    (GEARS, "model.gear_pair.base_radii", [0.03], ["`model.gear_pair.base_radii` must be a pair"]),
    (GEARS, "model.gear_pair.inertias", [0.0, 6e-3], ["`model.gear_pair.inertias.1` must be > 0"]),
    (GEARS, "model.gear_pair.mesh_stiffness", -2e8, ["`model.gear_pair.mesh_stiffness` must be > 0"]),
    (GEARS, "model.gear_pair.mesh_damping_ratio", 0.0, ["`model.gear_pair.mesh_damping_ratio` must be > 0"]),
    (GEARS, "model.gear_pair.backlash_um", 0.0, ["`model.gear_pair.backlash_um` (converted to m) must be > 0"]),
    (GEARS, "model.gear_pair.backlash", 6e-5, ["`model.gear_pair.backlash` and `model.gear_pair.backlash_um`"]),
    (GEARS, "model.gear_pair.mesh_stifness", 1.0, ["`model.gear_pair.mesh_stifness` is not a known key",
                                                   "did you mean `mesh_stiffness`"]),
    (GEARS, "model.gear_pair.name", 3, ["`model.gear_pair.name` must be an identifier"]),
    (GEARS, "model.units", _DEL, ["needs `model.units` = \"SI\""]),
    (GEARS, "model.inertias", [1.0, 1.0], ["`model.inertias` cannot be given with [model.gear_pair]"]),
    (LOOSE, "model.loose_gear.inertia", -2e-4, ["`model.loose_gear.inertia` must be > 0"]),
    (LOOSE, "model.loose_gear.drag_torque", -0.05, ["`model.loose_gear.drag_torque` must be >= 0"]),
    (LOOSE, "model.loose_gear.drive_acceleration", [400.0], ["`model.loose_gear.drive_acceleration` must have one"]),
    (LOOSE, "drag", {"inertia": 1, "speed_rpm": [600.0], "torque": [0.1]}, ["`drag.inertia` is not a key"]),
])
def test_bad_physical_input_is_refused_naming_the_key(text, path, value, fragments):
    with pytest.raises(ConfigError) as info:
        config_from_dict(_set(_data(text), path, value), source_name="case.toml")
    message = str(info.value)
    assert message.startswith("case.toml: ")
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_damper_in_the_single_equation_is_pointed_at_a_chain():
    data = {"model": {"inertia": 1.0, "damping": 0.05, "stiffness": 1.0,
                      "elastic": {"type": "damper", "drive_stiffness": [1.0]}},
            "excitation": {"mean": 0.0, "amplitudes": [0.1]}}
    with pytest.raises(ConfigError, match=r"`model.elastic.type` = \"damper\" is a sub-system of a chain"):
        config_from_dict(data)


def test_refusal_exits_2_on_the_command_line(tmp_path):
    path = tmp_path / "gears.toml"
    path.write_text(GEARS.replace("inertias = [5.0e-3, 6.0e-3]", "inertias = [-5.0e-3, 6.0e-3]"), encoding="utf-8")
    try:
        runner = CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        runner = CliRunner()
    result = runner.invoke(cli, ["frf", str(path), "-o", str(tmp_path / "out")], catch_exceptions=False)
    assert result.exit_code == 2
    assert "`model.gear_pair.inertias.1` must be > 0" in result.stderr
    assert not (tmp_path / "out" / "frf.csv").exists()


def test_load_config_reads_the_shapes_from_a_file(tmp_path):
    path = tmp_path / "damper.toml"
    path.write_text(DAMPER, encoding="utf-8")
    cfg = load_config(path)
    assert [e.name for e in cfg.model.elements] == ["damper", "spline"]
    assert cfg.model.links[1] == Link(between=(3, 0), stiffness=1000.0, damping=0.05)


def test_gear_pair_engine_and_drag_on_gear2_are_scaled():
    data = _data(GEARS)
    del data["excitation"], data["analysis"]
    data["engine"] = {"inertia": 2, "speed_rpm": [1000.0, 5000.0], "orders": [25.0], "amplitudes": [8.0],
                      "mean_torque": 4.0}
    data["excitation"] = {"torques": [{"inertia": 1, "mean": -3.0}]}  # 4 N m on gear 2 = 3 N m on gear 1's side
    cfg = config_from_dict(data)
    (engine,) = [t for t in cfg.model.torques if t.inertia == 2]
    assert engine.mean == pytest.approx(3.0) and engine.amplitudes == pytest.approx((6.0,))
    data = _data(GEARS)
    del data["analysis"]
    data["engine"] = {"inertia": 1, "speed_rpm": [1000.0, 5000.0], "orders": [25.0], "amplitudes": [25.0]}
    data["excitation"] = {"torques": [{"inertia": 1, "mean": 0.0}]}
    data["drag"] = {"inertia": 2, "speed_rpm": [1000.0, 5000.0], "torque": [20.0, 40.0]}  # N m of gear 2
    cfg = config_from_dict(data)
    assert cfg.model.drag.torque == pytest.approx((15.0, 30.0)) and cfg.model.drag.balance == 1


def test_loose_gear_drag_by_speed_enters_its_relative_coordinate_with_a_plus_sign():
    """δ = (r1/r2) θ1 − θ2: the loose gear's drag holds it back, i.e. + D(rpm) on δ — the same
    mean as a constant drag_torque of D(rpm) at every speed."""
    from rattle.io import config_from_dict

    table = _data(LOOSE.replace("drag_torque = 0.05\n", ""))
    table["drag"] = {"speed_rpm": [600.0, 3000.0], "torque": [0.02, 0.08]}
    chain = config_from_dict(table).model
    assert chain.drag.inertia == 0 and chain.drag.balance == 1
    for rpm in (600.0, 1200.0, 2500.0):
        D = 0.02 + 0.06 * (rpm - 600.0) / 2400.0
        const = config_from_dict(_data(LOOSE.replace("drag_torque = 0.05", f"drag_torque = {D!r}"))).model
        w = rpm * chain.speed_order * 2.0 * np.pi / 60.0
        assert chain.system().mean_at(w) == pytest.approx(const.system().mean, rel=1e-12)
    both = _data(LOOSE)
    both["drag"] = {"speed_rpm": [600.0], "torque": [0.02]}
    with pytest.raises(ConfigError, match="`model.loose_gear.drag_torque` and \\[drag\\] are both given"):
        config_from_dict(both)


# --- unit traps: lengths in mm and µm, an implausible backlash, warnings as one plain line ------------
@pytest.mark.parametrize("text, where", [(GEARS, "model.gear_pair"), (LOOSE, "model.loose_gear")])
def test_lengths_in_mm_and_um_are_the_same_model(text, where):
    """``backlash``/``base_radii`` in m, ``KEY_mm`` or ``KEY_um``: the same chain (the divisions are
    correctly rounded, so 0.06 mm and 60 µm are both 6e-05 m exactly as written)."""
    shape = where.split(".")[1]
    ref = config_from_dict(_data(text)).model
    for backlash, radii in ((("backlash_mm", 0.06 if shape == "gear_pair" else 0.1), ("base_radii_mm", [30.0, 40.0])),
                            (("backlash", 6e-5 if shape == "gear_pair" else 1e-4), ("base_radii_um", [3e4, 4e4]))):
        data = _data(text)
        table = data["model"][shape]
        del table["backlash_um"], table["base_radii"]
        table[backlash[0]], table[radii[0]] = backlash[1], radii[1]
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # plausible: no warning
            model = config_from_dict(data).model
        assert model.elements == ref.elements and model.inertias == ref.inertias


@pytest.mark.parametrize("path, value, fragments", [
    ("model.gear_pair.backlash_mm", 0.06, ["`model.gear_pair.backlash_um` and `model.gear_pair.backlash_mm` are both "
                                           "given: one length in µm and in mm"]),
    ("model.gear_pair.base_radii_mm", [30.0, 40.0], ["`model.gear_pair.base_radii` and "
                                                     "`model.gear_pair.base_radii_mm` are both given"]),
    ("model.gear_pair.mesh_stiffness_mm", 1.0, ["`model.gear_pair.mesh_stiffness_mm` is not a known key",
                                                "`mesh_stiffness` is not a length", "backlash_mm"]),
    ("model.gear_pair.backlash_nm", 1.0, ["`model.gear_pair.backlash_nm` is not a known key",
                                          "lengths also as KEY_mm or KEY_um"]),
    ("model.gear_pair.backlash_deg", 1.0, ["`model.gear_pair.backlash_deg` is not a known key: `backlash` is not an "
                                           "angle, so it has no value in degrees"]),
])
def test_length_keys_are_refused_naming_the_key_and_rule(path, value, fragments):
    with pytest.raises(ConfigError) as info:
        config_from_dict(_set(_data(GEARS), path, value), source_name="case.toml")
    for fragment in fragments:
        assert fragment in str(info.value), (fragment, str(info.value))


def test_a_length_suffix_on_an_angle_is_refused():
    """A spline's backlash and a chain element's half-gap are angles: ``_mm`` names that, and how a
    free play measured as a length becomes the angle (or the gear pair that takes a length)."""
    data = _data(DAMPER)
    spline = data["model"]["elements"][1]
    del spline["backlash_deg"]
    spline["backlash_mm"] = 0.1
    with pytest.raises(ConfigError, match=r"`model.elements\.2.backlash_mm` is not a known key: "
                                          r"`model.elements.2.backlash` is an angle, in rad \(or `backlash_deg` in "
                                          r"degrees\), not a length: .* the angle s / r .*\[model.gear_pair\]"):
        config_from_dict(data)
    single = {"model": {"inertia": 1.0, "damping": 0.05, "stiffness": 1.0, "elastic": {"type": "backlash", "b_mm": 0.1}},
              "excitation": {"mean": 0.05, "amplitudes": [0.03]}}
    with pytest.raises(ConfigError, match=r"`model.elastic.b_mm` is not a known key: `model.elastic.b` is an angle"):
        config_from_dict(single)


@pytest.mark.parametrize("key, value, fragments", [
    # 0.12 m meant as mm: 4 × the smaller base radius (0.03 m); the derived half-gap (2 rad) is not warned again
    ("backlash", 0.12, ["`model.gear_pair.backlash` = 0.12 m", "0.1 × the smaller base radius (0.03 m)",
                        "if 0.12 was meant in mm, write `model.gear_pair.backlash_mm` = 0.12"]),
    # 60 µm written as mm: 0.06 m, twice the bound
    ("backlash_mm", 60.0, ["`model.gear_pair.backlash_mm` = 60 mm (0.06 m)",
                           "if 60 was meant in µm, write `model.gear_pair.backlash_um` = 60"]),
])
def test_an_implausible_backlash_warns_once_naming_the_key_and_the_likely_unit(key, value, fragments):
    data = _data(GEARS)
    del data["model"]["gear_pair"]["backlash_um"]
    data["model"]["gear_pair"][key] = value
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        config_from_dict(data, source_name="case.toml")
    assert len(caught) == 1, [str(w.message) for w in caught]
    message = str(caught[0].message)
    assert message.startswith("case.toml: ")
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    # at the threshold (a tenth of the smaller base radius, 3 mm) nothing; just above it, the warning
    for backlash, count in ((3e-3, 0), (3.001e-3, 1)):
        data["model"]["gear_pair"] = {**data["model"]["gear_pair"], key: backlash / (1e-3 if key == "backlash_mm" else 1)}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            config_from_dict(data)
        assert len(caught) == count


def test_the_builders_warn_once_naming_the_argument():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gear_pair(base_radii=[0.03, 0.04], inertias=[5e-3, 6e-3], mesh_stiffness=2e8, mesh_damping_ratio=0.05,
                  backlash=0.12)
        loose_gear(base_radii=[0.03, 0.04], inertia=2e-4, mesh_stiffness=2e8, mesh_damping_ratio=0.05,
                   backlash=0.2, drive_acceleration=[400.0])
    assert [str(w.message)[:30] for w in caught] == ["`backlash` = 0.12 m of play al", "`backlash` = 0.2 m of play alo"]
    assert "pass backlash = 0.00012 (m) instead" in str(caught[0].message)
    assert all(w.filename == __file__ for w in caught)  # the caller's line, not the builder's


def test_the_command_line_shows_the_warning_as_one_plain_line(tmp_path):
    """``rattle: warning: <message>``: the key and the likely unit, no internal file location."""
    path = tmp_path / "gears.toml"
    path.write_text(GEARS.replace("backlash_um = 60.0", "backlash = 0.12").replace("omega = [3000.0, 12000.0]",
                                                                                      "omega = [11000.0, 12000.0]")
                    .replace("harmonics = 8", "harmonics = 2"), encoding="utf-8")
    try:
        runner = CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        runner = CliRunner()
    result = runner.invoke(cli, ["frf", str(path), "-o", str(tmp_path / "out"), "--fixed-harmonics"],
                           catch_exceptions=False)
    warned = [line for line in result.stderr.splitlines() if "warning:" in line]
    assert len(warned) == 1, result.stderr
    assert warned[0].startswith(f"rattle: warning: {path}: `model.gear_pair.backlash` = 0.12 m")
    assert ".py" not in result.stderr and "rattle/" not in result.stderr.replace(str(tmp_path), "")


def test_messages_count_elements_from_1_as_the_map_keys_and_name_the_key_written():
    """One index base (issue 27 item 4): an error about the second element names
    ``model.elements.2`` — the key ``rattle map --vary`` takes for it (SPEC §7 counts positions
    from 1) — and a damper given in N m/deg is named by its ``*_per_deg`` key, never by the N m/rad
    key the reader converted it to."""
    from rattle.maps import parameters

    (p,) = parameters(_data(DAMPER), {"model.elements.spline.stiffness": [8000.0]})
    assert p.key == "model.elements.2.stiffness"
    data = _data(DAMPER)
    data["model"]["elements"][1]["stiffness"] = -1.0
    with pytest.raises(ConfigError, match=r"^case.toml: `model.elements.2.stiffness` must be > 0"):
        config_from_dict(data, source_name="case.toml")
    data = _data(DAMPER)
    data["model"]["elements"][0]["drive_stiffness_per_deg"] = []
    with pytest.raises(ConfigError) as info:
        config_from_dict(data, source_name="case.toml")
    message = str(info.value)
    assert "`model.elements.1.drive_stiffness_per_deg` (converted to N m/rad) must hold at least one stage" in message
    assert "[0]" not in message and "drive_stiffness`" not in message
    data = _data(DAMPER)
    data["model"]["elements"][0]["drive_angles_deg"] = [4.0, 5.0]
    with pytest.raises(ConfigError, match=r"`model.elements.1.drive_angles_deg` \(converted to rad\) must have one "
                                          r"entry fewer than `model.elements.1.drive_stiffness_per_deg`"):
        config_from_dict(data, source_name="case.toml")
