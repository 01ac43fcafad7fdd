"""Discontinuous laws in the configuration file: ``[model.elastic] type = "preload"``, a
``friction`` key on any type, ``[analysis] regularisation``; what they build and what is refused."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from rattle.errors import ConfigError
from rattle.io import config_from_dict
from rattle.model import Model
from rattle.model._discontinuous import Preload


def _base(elastic: dict, **analysis: object) -> dict:
    return {
        "model": {"inertia": 2.0, "damping": 0.1, "stiffness": 3.0, "elastic": elastic},
        "excitation": {"mean": 0.01, "amplitudes": [0.3], "phases": [0.3]},
        "analysis": {"omega": [0.8, 1.6], **analysis},
    }


def test_preload_builds_the_jump_law_with_the_model_coefficients():
    cfg = config_from_dict(_base({"type": "preload", "preload": 0.05}))
    system = cfg.model
    assert system.is_single_equation and cfg.discontinuous
    assert (system.c, system.k) == (0.05, 1.5)  # C/I, K/I
    st = system.law.stages
    np.testing.assert_array_equal(st.breakpoints, [0.0])
    np.testing.assert_array_equal(st.slopes, [1.0, 1.0])
    np.testing.assert_array_equal(st.jumps, [0.1])  # 2 T_p at δ = 0
    np.testing.assert_array_equal(system.law.friction_levels, [0.0, 0.0])
    assert system.excitation.amplitudes == (0.3,) and system.excitation.mean == 0.01
    # the continuous part carries the frequency bounds: slope 1 on both sides of the jump
    assert isinstance(cfg.continuous_model, Model)
    assert cfg.continuous_model.elastic.stages.slopes.tolist() == [1.0, 1.0]


def test_preload_with_clearance_in_degrees_slope_and_stage_friction():
    cfg = config_from_dict(_base({"type": "preload", "preload": 0.04, "clearance_deg": 2.0, "slope": 0.5,
                                  "friction": [0.01, 0.0, 0.02]}))
    law = cfg.model.law
    b = math.radians(2.0)
    assert law.elastic == Preload(preload=0.04, clearance=b, slope=0.5)
    np.testing.assert_allclose(law.stages.breakpoints, [-b, b], rtol=0, atol=0)
    np.testing.assert_array_equal(law.stages.slopes, [0.5, 0.0, 0.5])
    np.testing.assert_array_equal(law.stages.jumps, [0.04, 0.04])
    np.testing.assert_array_equal(law.friction_levels, [0.01, 0.0, 0.02])
    # f just outside the clearance: ±T_p, then slope s
    assert float(law.force(b + 0.1)) == pytest.approx(0.04 + 0.5 * 0.1, abs=1e-15)
    assert float(law.force(-b - 0.1)) == pytest.approx(-0.04 - 0.5 * 0.1, abs=1e-15)


def test_friction_on_a_continuous_law_one_level_or_one_per_stage():
    cfg = config_from_dict(_base({"type": "clutch", "alpha": 0.25, "b": 0.1, "friction": 0.02}))
    assert cfg.discontinuous
    np.testing.assert_array_equal(cfg.model.law.friction_levels, [0.02, 0.02, 0.02])
    np.testing.assert_array_equal(cfg.model.law.stages.jumps, [0.0, 0.0])
    np.testing.assert_array_equal(cfg.model.law.stages.slopes, [1.0, 0.25, 1.0])
    cfg = config_from_dict(_base({"type": "piecewise", "breakpoints": [-0.2, 0.1], "slopes": [1.0, 0.1, 2.0],
                                  "friction": [0.0, 0.005, 0.03]}))
    np.testing.assert_array_equal(cfg.model.law.friction_levels, [0.0, 0.005, 0.03])


def test_si_torques_are_divided_by_the_stiffness():
    data = _base({"type": "preload", "preload": 10.0, "clearance": 0.01, "friction": [2.0, 0.0, 4.0]})
    data["model"].update(units="SI", inertia=0.1, damping=0.5, stiffness=200.0)
    data["analysis"]["omega"] = [20.0, 60.0]
    cfg = config_from_dict(data)
    law = cfg.model.law
    assert law.elastic.preload == pytest.approx(10.0 / 200.0, rel=1e-15)
    np.testing.assert_allclose(law.friction_levels, [2.0 / 200.0, 0.0, 4.0 / 200.0], rtol=1e-15)
    np.testing.assert_allclose(law.stages.jumps, [0.05, 0.05], rtol=1e-15)
    assert (cfg.model.c, cfg.model.k) == (5.0, 2000.0)
    # the torque jump K T_p in N m is the preload as written
    assert 200.0 * law.elastic.preload == pytest.approx(10.0, rel=1e-15)
    # the resolved tables give the torques back in N m, and read back the same system
    again = config_from_dict(cfg.to_dict())
    assert again.model == cfg.model and again.units == "SI"
    assert cfg.to_dict()["model"]["elastic"]["preload"] == pytest.approx(10.0, rel=1e-15)


def test_analysis_defaults_of_a_discontinuous_law_are_the_front_end_defaults():
    from rattle.analysis import RegularisationOptions

    cfg = config_from_dict(_base({"type": "preload", "preload": 0.05}))
    assert cfg.analysis.harmonics == RegularisationOptions().harmonics == 128
    assert cfg.analysis.regularisation == RegularisationOptions().regularisation == 0.01
    assert cfg.analysis.refine == RegularisationOptions().refine == 0.005
    cfg = config_from_dict(_base({"type": "preload", "preload": 0.05}, harmonics=48, regularisation=0.003))
    assert (cfg.analysis.harmonics, cfg.analysis.regularisation) == (48, 0.003)
    assert cfg.analysis.to_dict() == {"omega": [0.8, 1.6], "harmonics": 48, "regularisation": 0.003, "refine": 0.005,
                                      "method": "shooting"}  # the default method of a discontinuous law (SPEC §8)
    assert config_from_dict(cfg.to_dict()).analysis == cfg.analysis
    # a continuous law keeps its defaults and has no regularisation
    smooth = config_from_dict(_base({"type": "linear"}))
    assert (smooth.analysis.harmonics, smooth.analysis.regularisation) == (32, None)
    assert "regularisation" not in smooth.analysis.to_dict()


@pytest.mark.parametrize("elastic", [{"type": "preload", "preload": 0.0},
                                     {"type": "preload", "preload": 0.0, "clearance": 0.1, "friction": 0.0},
                                     {"type": "clutch", "alpha": 0.25, "b": 0.1, "friction": [0.0, 0.0, 0.0]}])
def test_no_jump_and_no_friction_is_the_continuous_model(elastic):
    cfg = config_from_dict(_base(elastic))
    assert isinstance(cfg.model, Model) and not cfg.discontinuous and cfg.analysis.harmonics == 32
    if elastic["type"] == "preload" and "clearance" in elastic:  # the backlash of the same clearance
        np.testing.assert_array_equal(cfg.model.elastic.stages.slopes, [1.0, 0.0, 1.0])
        np.testing.assert_array_equal(cfg.model.elastic.stages.breakpoints, [-0.1, 0.1])


def _refused(data: dict, *fragments: str) -> None:
    with pytest.raises(ConfigError) as info:
        config_from_dict(data, source_name="case.toml")
    message = str(info.value)
    assert message.startswith("case.toml: ")
    for fragment in fragments:
        assert fragment in message, (fragment, message)


@pytest.mark.parametrize(("elastic", "analysis", "fragments"), [
    ({"type": "clutch", "alpha": 0.25, "b": 0.1, "friction": [0.0, 0.02]}, {},
     ["`model.elastic.friction` must hold one level (every stage) or one per stage", 'type = "clutch" has 3 stages',
      "got 2 levels [0.0, 0.02]"]),
    ({"type": "preload", "preload": 0.05, "friction": [0.01, 0.01, 0.01]}, {},
     ["`model.elastic.friction`", 'type = "preload" has 2 stages', "got 3 levels"]),
    ({"type": "preload", "preload": -0.05}, {}, ["`model.elastic.preload`", "must be >= 0", "got -0.05"]),
    ({"type": "preload", "preload": 0.05, "slope": 0.0}, {}, ["`model.elastic.slope` must be > 0, got 0.0"]),
    ({"type": "preload", "preload": 0.05, "clearance": -0.1}, {}, ["`model.elastic.clearance` must be >= 0 rad"]),
    ({"type": "preload", "preload": 0.05, "clearance_deg": 1.0, "clearance": 0.1}, {},
     ["`model.elastic.clearance` and `model.elastic.clearance_deg` are both given"]),
    ({"type": "preload"}, {}, ["`model.elastic.preload` is missing"]),
    ({"type": "preload", "preload": "0.05"}, {}, ["`model.elastic.preload` must be a number", '"0.05"']),
    ({"type": "linear", "friction": -0.01}, {}, ["`model.elastic.friction`", "must be >= 0, got -0.01"]),
    ({"type": "linear", "friction": []}, {}, ["`model.elastic.friction`", "at least one"]),
    ({"type": "linear", "friction": True}, {}, ["`model.elastic.friction` must be a number", "true"]),
    ({"type": "clutch", "alpha": 0.25, "b": 0.1, "preload": 0.05}, {},
     ["`model.elastic.preload` does not belong to type = \"clutch\"", '("preload")']),
    ({"type": "preload", "preload": 0.05, "alpha": 0.25}, {},
     ["`model.elastic.alpha` does not belong to type = \"preload\""]),
    ({"type": "linear"}, {"regularisation": 0.01},
     ["`analysis.regularisation` = 0.01 applies only to a discontinuous law", "remove `analysis.regularisation`"]),
    ({"type": "linear", "friction": 0.0}, {"regularisation": 0.01}, ["`analysis.regularisation`", "continuous"]),
    ({"type": "preload", "preload": 0.05}, {"regularisation": 0.0},
     ["`analysis.regularisation`", "must satisfy 0 < ε < 1, got 0.0"]),
    ({"type": "preload", "preload": 0.05}, {"regularisation": 1.0}, ["`analysis.regularisation`", "got 1.0"]),
    ({"type": "preload", "preload": 0.05}, {"regularisation": "small"},
     ["`analysis.regularisation` must be a number"]),
    ({"type": "preload", "preload": 0.05}, {"harmonics": 0}, ["`analysis.harmonics`"]),
])
def test_refusals_name_the_key_show_the_value_and_state_the_rule(elastic, analysis, fragments):
    _refused(_base(elastic, **analysis), *fragments)


def test_friction_on_a_gear_mesh_is_refused_naming_the_key():
    # friction and type = "preload" on [[model.elements]] are accepted (tests/io/test_config_chain_friction.py)
    data = {"model": {"units": "SI", "gear_pair": {"base_radii": [0.03, 0.05], "inertias": [1e-3, 3e-3],
                                                   "mesh_stiffness": 2e8, "mesh_damping_ratio": 0.05,
                                                   "backlash_um": 60.0, "friction": 0.1}},
            "excitation": {"torques": [{"inertia": 1, "mean": 1.0, "amplitudes": [0.5]}]}}
    _refused(data, "`model.gear_pair.friction`", "a gear mesh takes no preload or Coulomb friction")


def test_sound_paths_with_a_discontinuous_law_are_refused():
    data = _base({"type": "preload", "preload": 0.05})
    data["paths"] = [{"name": "p", "source": "acceleration", "table": "x.csv"}]
    _refused(copy.deepcopy(data), "`paths`", "discontinuous law", "remove [[paths]]")


def test_refine_key_reaches_the_settings_and_is_refused_on_a_continuous_law() -> None:
    base = {"model": {"inertia": 1.0, "damping": 0.05, "stiffness": 1.0,
                      "elastic": {"type": "preload", "preload": 0.05, "friction": 0.02}},
            "excitation": {"mean": 0.01, "amplitudes": [0.3]}}
    assert config_from_dict(base).analysis.refine == 0.005
    cfg = config_from_dict({**base, "analysis": {"refine": 0}})
    assert cfg.analysis.refine == 0.0 and cfg.to_dict()["analysis"]["refine"] == 0.0
    with pytest.raises(ConfigError, match="`analysis.refine`"):
        config_from_dict({**base, "analysis": {"refine": 1.5}})
    with pytest.raises(ConfigError, match="`analysis.refine`"):
        config_from_dict({**base, "analysis": {"refine": "yes"}})
    smooth = {**base, "model": {**base["model"], "elastic": {"type": "linear"}}}
    with pytest.raises(ConfigError, match="`analysis.refine`.*continuous"):
        config_from_dict({**smooth, "analysis": {"refine": 0.01}})
