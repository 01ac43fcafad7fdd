"""``[[model.elements]] friction``: Coulomb friction per stage on a chain's elements, read into the
chain's System with its elements' whole laws (levels relative to the element's stiffness K_e, or N m with units = "SI"),
with the refusals naming the key, showing the value, stating the rule and the fix."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from rattle.analysis import load_case
from rattle.errors import ConfigError
from rattle.io import config_from_dict, dumps_toml
from rattle.model import Chain


def _chain(friction=None, **element) -> dict:
    """Two inertias, the second grounded by a soft link; a clutch (3 stages) between them."""
    el = {"name": "clutch", "between": [1, 2], "stiffness": 1.0, "type": "clutch", "alpha": 0.25, "b": 0.1,
          **element}
    if friction is not None:
        el["friction"] = friction
    return {
        "model": {"inertias": [1.0, 1.0],
                  "links": [{"between": [2, 0], "stiffness": 0.1, "damping": 0.05},
                            {"between": [1, 2], "damping": 0.02}],
                  "elements": [el]},
        "excitation": {"torques": [{"inertia": 1, "mean": 0.05, "amplitudes": [0.06]}]},
        "analysis": {"omega": [0.3, 1.5]},
    }


def _refused(data: dict, *fragments: str) -> str:
    with pytest.raises(ConfigError) as info:
        config_from_dict(data, source_name="case.toml")
    message = str(info.value)
    assert message.startswith("case.toml: ")
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    return message


@pytest.mark.parametrize("friction, levels", [(0.02, [0.02, 0.02, 0.02]), ([0.0, 0.03, 0.01], [0.0, 0.03, 0.01]),
                                              ([0.04], [0.04, 0.04, 0.04])])
def test_friction_on_an_element_makes_the_chain_a_friction_system(friction, levels):
    rc = config_from_dict(_chain(friction))
    assert rc.model.discontinuous
    assert rc.discontinuous and rc.chain_friction
    np.testing.assert_array_equal(rc.model.friction_levels(0), levels)
    assert rc.model.element_names == ("clutch",)
    # the chain without its friction sets the bounds (its smooth system is the whole-law System's continuous part)
    assert isinstance(rc.continuous_model, Chain) and not rc.continuous_model.has_friction
    assert rc.bounds_model is rc.continuous_model
    assert rc.model.continuous().n == rc.continuous_model.system().n == 2
    # the settings of a discontinuous law: the regularised HB's defaults
    assert (rc.analysis.harmonics, rc.analysis.regularisation, rc.analysis.refine) == (128, 0.001, 0.005)


def test_zero_friction_is_the_smooth_chain():
    rc = config_from_dict(_chain([0.0, 0.0, 0.0]))
    assert isinstance(rc.model, Chain) and not rc.discontinuous and not rc.chain_friction
    assert "friction" not in rc.to_dict()["model"]["elements"][0]
    _refused(_chain(0.0) | {"analysis": {"regularisation": 0.01}}, "`analysis.regularisation` = 0.01 applies only",
             "`model.elements.K.friction`")


def test_si_friction_is_a_torque_divided_by_the_element_stiffness():
    data = _chain([0.0, 12.5, 4.0], stiffness=500.0)
    data["model"]["units"] = "SI"
    rc = config_from_dict(data)
    np.testing.assert_allclose(rc.model.friction_levels(0), [0.0, 12.5 / 500.0, 4.0 / 500.0], rtol=0, atol=1e-17)
    # written back as given (N m), and read again into the same levels
    out = rc.to_dict()
    assert out["model"]["units"] == "SI"
    np.testing.assert_allclose(out["model"]["elements"][0]["friction"], [0.0, 12.5, 4.0], rtol=1e-15)
    again = config_from_dict(out)
    np.testing.assert_allclose(again.model.friction_levels(0), rc.model.friction_levels(0), rtol=1e-15)
    assert again.analysis == rc.analysis


def test_the_resolved_configuration_round_trips_through_toml():
    import tomllib

    rc = config_from_dict(_chain([0.0, 0.03, 0.01]))
    again = config_from_dict(tomllib.loads(dumps_toml(rc.to_dict())))
    assert again.model.discontinuous
    np.testing.assert_array_equal(again.model.friction_levels(0), [0.0, 0.03, 0.01])
    assert again.continuous_model.to_dict() == rc.continuous_model.to_dict()
    assert again.to_dict() == rc.to_dict()


def test_a_damper_and_a_spline_take_friction_per_stage_of_their_law():
    """The damper's law has the stages coast outermost … drive outermost (here c2, c1, k1, k2: no
    free play, c1 != k1); K_e is its stiffest stage (200 N m/rad), the spline's its stiffness."""
    data = {
        "model": {"units": "SI", "inertias": [0.2, 0.05, 1.0],
                  "links": [{"between": [3, 0], "stiffness": 50.0, "damping": 5.0},
                            {"between": [1, 2], "damping": 0.5}],
                  "elements": [{"name": "damper", "between": [1, 2], "type": "damper",
                                "drive_stiffness": [20.0, 200.0], "drive_angles_deg": [4.0],
                                "coast_stiffness": [15.0, 150.0], "coast_angles_deg": [3.0],
                                "friction": [5.0, 1.0, 2.0, 5.0]},
                               {"name": "hub", "between": [2, 3], "type": "spline", "stiffness": 500.0,
                                "backlash_deg": 1.0, "friction": 1.0}]},
        "excitation": {"torques": [{"inertia": 1, "mean": 10.0, "amplitudes": [20.0]}]},
        "analysis": {"omega": [5.0, 60.0]},
    }
    rc = config_from_dict(data)
    np.testing.assert_allclose(rc.model.friction_levels(0), np.array([5.0, 1.0, 2.0, 5.0]) / 200.0, rtol=1e-15)
    np.testing.assert_allclose(rc.model.friction_levels(1), [1.0 / 500.0] * 3, rtol=1e-15)
    np.testing.assert_allclose(rc.model.continuous().elements[0].slopes, [0.75, 0.075, 0.1, 1.0], rtol=1e-15)
    bad = copy.deepcopy(data)
    bad["model"]["elements"][0]["friction"] = [1.0, 2.0]
    _refused(bad, "`model.elements.1.friction` must hold one level (every stage) or one per stage of the damper",
             "4 stages (coast stage 2, coast stage 1, drive stage 1, drive stage 2; from the most negative twist)",
             "got 2 levels [1.0, 2.0]", "give 4 levels or a single number")
    bad["model"]["elements"][0].update(free_play_deg=0.5, coast_stiffness=[20.0, 150.0])  # c1 = k1, free play
    _refused(bad, "5 stages (coast stage 2, coast stage 1, free play, drive stage 1, drive stage 2;")
    del bad["model"]["elements"][0]["free_play_deg"]  # c1 = k1 without free play: one stage across zero
    _refused(bad, "3 stages (coast stage 2, coast/drive stage 1, drive stage 2;")
    bad["model"]["elements"][0]["friction"] = [1.0, 2.0, 3.0]
    np.testing.assert_allclose(config_from_dict(bad).model.friction_levels(0), np.array([1.0, 2.0, 3.0]) / 200.0)


@pytest.mark.parametrize("friction, fragments", [
    ([0.0, -0.02, 0.0], ["`model.elements.1.friction.2`", "must be >= 0", "-0.02"]),
    ([0.01, 0.02], ["`model.elements.1.friction` must hold one level (every stage) or one per stage of the law",
                    'type = "clutch" has 3 stages (δ < -0.1, -0.1 < δ < 0.1, δ > 0.1)', "got 2 levels [0.01, 0.02]",
                    "give 3 levels or a single number"]),
    ("0.02", ["`model.elements.1.friction` must be a number", '"0.02"', "e.g. friction = 0.02"]),
    ([0.0, "a", 0.0], ["`model.elements.1.friction.2` must be a number", "e.g. friction = 0.02"]),
    ([], ["`model.elements.1.friction`", "at least one"]),
    (math.inf, ["`model.elements.1.friction` must be a finite number"]),
])
def test_bad_friction_is_refused_naming_the_key(friction, fragments):
    _refused(_chain(friction), *fragments)


def _preload_chain(**element) -> dict:
    data = _chain()
    data["model"]["elements"][0] = {"name": "tc", "between": [1, 2], "stiffness": 2.0, "type": "preload",
                                    "preload": 0.05, **element}
    return data


def test_a_preload_element_makes_the_chain_a_friction_system_with_its_jump():
    """type = "preload" on an element: the torque jump (relative to K_e), optional clearance (also in
    degrees) and friction; the chain without jumps and friction (the laws' continuous parts) sets
    the bounds."""
    from rattle.model import Preload

    rc = config_from_dict(_preload_chain(friction=0.01, clearance_deg=1.0, slope=0.5))
    assert rc.model.discontinuous and rc.model.has_jumps and rc.chain_friction
    b = math.radians(1.0)
    assert rc.model.laws[0].elastic == Preload(preload=0.05, clearance=b, slope=0.5)
    np.testing.assert_array_equal(rc.model.friction_levels(0), [0.01, 0.01, 0.01])
    np.testing.assert_array_equal(rc.model.laws[0].stages.jumps, [0.05, 0.05])
    assert isinstance(rc.continuous_model, Chain) and not rc.continuous_model.discontinuous
    rc.continuous_model.system()  # the smooth chain exists (the bounds read it)
    # a jump's default regularisation is the single equation's (0.001 makes the continuation crawl)
    assert rc.analysis.regularisation == 0.01
    from rattle.analysis._friction_response import chain_regularisation

    assert chain_regularisation(rc.model) == 0.01 and chain_regularisation(config_from_dict(_chain(0.01)).model) == 0.001
    # without friction, the jump alone
    rc = config_from_dict(_preload_chain())
    assert rc.model.discontinuous and rc.model.has_jumps and not rc.model.has_friction
    # a zero preload without friction is the continuous chain
    rc = config_from_dict(_preload_chain(preload=0.0))
    assert isinstance(rc.model, Chain) and not rc.model.discontinuous


def test_a_preload_in_si_is_divided_by_the_element_stiffness():
    data = _preload_chain(preload=3.0, friction=1.0)
    data["model"]["units"] = "SI"
    rc = config_from_dict(data)
    assert rc.model.laws[0].elastic.preload == pytest.approx(3.0 / 2.0, rel=1e-15)
    np.testing.assert_allclose(rc.model.friction_levels(0), [0.5, 0.5], rtol=1e-15)


@pytest.mark.parametrize("element, fragments", [
    ({"preload": -0.01}, ["`model.elements.1.preload`", "must be >= 0"]),
    ({"preload": "0.05"}, ["`model.elements.1.preload` must be a number"]),
    ({"slope": 0.0}, ["`model.elements.1.slope` must be > 0"]),
    ({"friction": [0.01, 0.02, 0.03]}, ["`model.elements.1.friction` must hold one level",
                                        'type = "preload" has 2 stages']),
    ({"b": 0.1}, ["`model.elements.1.b` does not belong to type = \"preload\"", "preload, clearance, slope"]),
])
def test_a_bad_preload_element_is_refused_naming_the_key(element, fragments):
    _refused(_preload_chain(**element), *fragments)


def test_a_preload_key_on_another_law_points_to_the_preload_type():
    _refused(_chain(preload=0.05), "`model.elements.1.preload` does not belong to type = \"clutch\"",
             'choose a type that uses it ("preload")')


def test_an_unknown_element_key_names_friction_among_the_allowed_ones():
    _refused(_chain(0.01, frition=0.01), "`model.elements.1.frition` is not a known key", "(and friction)")


def test_sound_paths_with_chain_friction_are_refused():
    data = _chain(0.01)
    data["paths"] = [{"name": "p", "source": "acceleration", "table": "x.csv"}]
    _refused(data, "`paths`", "`model.elements.K.friction`", "remove [[paths]]")


@pytest.mark.slow
def test_load_case_reads_a_chain_with_friction_with_the_chain_defaults(tmp_path):
    """load_case keeps the chain's settings; its orbit is the chain's (FrictionOrbitResult)."""
    from rattle.results import FrictionOrbitResult

    path = tmp_path / "case.toml"
    path.write_text(dumps_toml(config_from_dict(_chain([0.0, 0.03, 0.0])).to_dict()), encoding="utf-8")
    case = load_case(path)
    assert case.discontinuous and case.model.discontinuous
    opts = case.regularisation_options()
    assert (opts.harmonics, opts.regularisation, opts.refine, opts.limit_harmonics) == (128, 0.001, 0.005, 128)
    orbit = case.periodic_orbit(1.0, options=type(opts)(harmonics=16, regularisation=0.01))
    assert isinstance(orbit, FrictionOrbitResult) and orbit.converged


@pytest.mark.parametrize("units", ["dimensionless", "SI"])
def test_a_preload_element_round_trips(units):
    """to_dict → TOML → config_from_dict gives the same jump law and friction (× K_e back to N m)."""
    import tomllib

    data = _preload_chain(friction=0.01, clearance_deg=0.5, slope=0.4)
    data["model"]["units"] = units
    rc = config_from_dict(data)
    out = rc.to_dict()
    assert out["model"]["elements"][0]["type"] == "preload"
    assert out["model"]["elements"][0]["preload"] == pytest.approx(0.05, rel=1e-15)  # as written
    again = config_from_dict(tomllib.loads(dumps_toml(out)))
    assert again.model.laws == rc.model.laws


def test_limit_harmonics_defaults_to_the_chains_harmonics_and_is_read_checked_and_written():
    """A chain's ladder keeps its H unless the file says otherwise; the single equation keeps the
    library's 256 (None here); a continuous law refuses the key; bad values name it."""
    from rattle.io import config_from_dict as read

    data = _chain(0.01)
    data["analysis"]["harmonics"] = 48
    assert read(data).analysis.limit_harmonics == 48
    data["analysis"]["limit_harmonics"] = 96
    rc = read(data)
    assert rc.analysis.limit_harmonics == 96 and rc.analysis.to_dict()["limit_harmonics"] == 96
    assert read(rc.to_dict()).analysis == rc.analysis  # written and read back whole
    single = {"model": {"inertia": 1.0, "damping": 0.05, "stiffness": 1.0,
                        "elastic": {"type": "preload", "preload": 0.03}},
              "excitation": {"mean": 0.05, "amplitudes": [0.03]}, "analysis": {"omega": [0.3, 1.5]}}
    assert read(single).analysis.limit_harmonics is None
    smooth = _chain()
    smooth["analysis"]["limit_harmonics"] = 64
    _refused(smooth, "`analysis.limit_harmonics`", "applies only to a discontinuous law")
    for bad in (0, 2.5, "64", 10_000):
        data["analysis"]["limit_harmonics"] = bad
        _refused(data, "limit_harmonics")


def test_held_limit_is_read_checked_written_and_carried_into_the_options():
    """`[analysis] held_limit = true` on a chain with friction (or jumps) on its elements: read,
    written back, carried into RegularisationOptions(held=True); refused on a smooth chain and on
    the single equation (no element to narrow), and when not a boolean."""
    from rattle.analysis._case import regularisation_options
    from rattle.io import config_from_dict as read

    data = _chain(0.01)
    assert read(data).analysis.held_limit is None and not regularisation_options(read(data).analysis).held
    data["analysis"]["held_limit"] = True
    rc = read(data)
    assert rc.analysis.held_limit is True and rc.analysis.to_dict()["held_limit"] is True
    assert read(rc.to_dict()).analysis == rc.analysis
    assert regularisation_options(rc.analysis).held
    smooth = _chain()
    smooth["analysis"]["held_limit"] = True
    _refused(smooth, "`analysis.held_limit`", "applies only to a chain with friction or a torque jump")
    single = {"model": {"inertia": 1.0, "damping": 0.05, "stiffness": 1.0,
                        "elastic": {"type": "preload", "preload": 0.03}},
              "excitation": {"mean": 0.05, "amplitudes": [0.03]}, "analysis": {"omega": [0.3, 1.5], "held_limit": True}}
    _refused(single, "`analysis.held_limit`", "applies only to a chain")
    for bad in (1, "yes", 0.0):
        data["analysis"]["held_limit"] = bad
        _refused(data, "held_limit", "true or false")
