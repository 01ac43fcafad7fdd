"""The varied parameters of a map: `--vary` parsing, names resolved to configuration keys (single
equation and chains), values applied, every combination's model validated up front."""

from __future__ import annotations

from pathlib import Path

import pytest

from rattle.errors import ConfigError
from rattle.io import load_config
from rattle.maps import Parameter
from rattle.maps import _vary as vary

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def single():
    return load_config(EXAMPLES / "reference_clutch.toml").to_dict()


@pytest.fixture(scope="module")
def chain():
    return load_config(EXAMPLES / "chain_two_inertia.toml").to_dict()


@pytest.fixture(scope="module")
def driveline():
    return load_config(EXAMPLES / "driveline_three_inertia.toml").to_dict()


# --------------------------------------------------------------------------------------------
# parse_vary
# --------------------------------------------------------------------------------------------
def test_range_is_linspace_with_both_ends():
    name, values = vary.parse_vary("alpha=0.1:0.4:4")
    assert name == "alpha"
    assert values == pytest.approx((0.1, 0.2, 0.3, 0.4), abs=1e-15)
    assert values[0] == 0.1 and values[-1] == 0.4


def test_range_values_are_the_decimal_ones_meant():
    _, values = vary.parse_vary("alpha=0:0.5:11")
    assert values == (0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5)


def test_count_one_gives_start_and_a_list_keeps_its_order():
    assert vary.parse_vary("b=0.2:0.9:1") == ("b", (0.2,))
    assert vary.parse_vary("model.elastic.alpha = 0.3, 0.1,0.2") == ("model.elastic.alpha", (0.3, 0.1, 0.2))
    assert vary.parse_vary("mean=-0.05:0.05:3")[1] == pytest.approx((-0.05, 0.0, 0.05))


@pytest.mark.parametrize("text, fragment", [
    ("alpha", "no `=`"),
    ("alpha=", "no values"),
    ("=0:1:2", "NAME"),
    ("alpha=x:1:3", "START must be a number"),
    ("alpha=0:y:3", "STOP must be a number"),
    ("alpha=0:1:z", "COUNT must be an integer"),
    ("alpha=0:1:0", "COUNT must be an integer >= 1"),
    ("alpha=0:1:-2", "COUNT must be an integer >= 1"),
    ("alpha=0:1:2.5", "COUNT must be an integer >= 1"),
    ("alpha=nan:1:3", "START must be finite"),
    ("alpha=0:inf:3", "STOP must be finite"),
    ("alpha=0:1", "START:STOP:COUNT"),
    ("alpha=0.1,nan", "finite"),
    ("alpha=0.1,,0.2", "empty entry"),
    ("alpha=0.1,0.1", "given twice"),
    ("alpha=0.2:0.2:3", "equal"),
    ("alpha=0:1:1000000", "COUNT must be <="),
])
def test_malformed_vary_is_refused_naming_the_option(text, fragment):
    with pytest.raises(ConfigError, match="`--vary`") as info:
        vary.parse_vary(text)
    assert fragment in str(info.value)


def test_the_same_name_twice_is_refused():
    with pytest.raises(ConfigError, match="`--vary` gives 'alpha' twice"):
        vary.parse_all(["alpha=0.1:0.2:2", "alpha=0.3,0.4"])
    with pytest.raises(ConfigError, match="at least one"):
        vary.parse_all([])


# --------------------------------------------------------------------------------------------
# resolve
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, key", [
    ("alpha", "model.elastic.alpha"), ("b", "model.elastic.b"), ("damping", "model.damping"),
    ("mean", "excitation.mean"), ("amplitude", "excitation.amplitudes.1"),
    ("model.elastic.alpha", "model.elastic.alpha"), ("excitation.amplitudes.1", "excitation.amplitudes.1"),
    ("model.stiffness", "model.stiffness"), ("excitation.phases.1", "excitation.phases.1"),
])
def test_short_names_and_keys_on_a_single_equation(single, name, key):
    assert vary.resolve(single, name) == key


@pytest.mark.parametrize("name, key", [
    ("alpha", "model.elements.1.alpha"), ("b", "model.elements.1.b"), ("damping", "model.links.1.damping"),
    ("amplitude", "excitation.torques.1.amplitudes.1"),
    ("model.elements.clutch.alpha", "model.elements.1.alpha"), ("model.elements.1.b", "model.elements.1.b"),
    ("excitation.torques.2.mean", "excitation.torques.2.mean"), ("model.inertias.2", "model.inertias.2"),
])
def test_short_names_and_keys_on_a_chain(chain, name, key):
    assert vary.resolve(chain, name) == key


def test_an_ambiguous_short_name_on_a_chain_lists_the_keys(chain, driveline):
    with pytest.raises(ConfigError, match="ambiguous") as info:
        vary.resolve(chain, "mean")  # the engine torque and the drag torque
    assert "excitation.torques.1.mean" in str(info.value) and "excitation.torques.2.mean" in str(info.value)
    with pytest.raises(ConfigError, match="model.links.1.damping, model.links.2.damping"):
        vary.resolve(driveline, "damping")
    assert vary.resolve(driveline, "b") == "model.elements.2.b"  # only the gear has a b
    assert vary.resolve(driveline, "model.elements.gear.b") == "model.elements.2.b"
    with pytest.raises(ConfigError, match="no elements with `alpha`"):
        vary.resolve(driveline, "alpha")


@pytest.mark.parametrize("name, fragment", [
    ("alhpa", "model.elastic.alpha"),                  # unknown: the nearest keys listed
    ("model.elastic.alhpa", "model.elastic.alpha"),
    ("model.elastic", "is a table, not a number; vary one of its numbers: model.elastic.alpha"),
    ("model.elastic.type", "not a number"),
    ("excitation.amplitudes", "is a list"),
    ("excitation.amplitudes.2", "a map does not add harmonics"),
    ("excitation.amplitudes.0", "positions count from 1"),
    ("model.damping.x", "is a number"),
    ("analysis.harmonics", "--harmonics"),
])
def test_bad_keys_are_refused(single, name, fragment):
    with pytest.raises(ConfigError, match="`--vary`") as info:
        vary.resolve(single, name)
    assert fragment in str(info.value)


def test_chain_refusals(chain):
    with pytest.raises(ConfigError, match="its names are clutch"):
        vary.resolve(chain, "model.elements.gear.b")
    with pytest.raises(ConfigError, match="position 3 is out of range"):
        vary.resolve(chain, "excitation.torques.3.mean")
    with pytest.raises(ConfigError, match="number of the inertia"):
        vary.resolve(chain, "excitation.torques.1.inertia")
    with pytest.raises(ConfigError, match="numbers the inertias"):
        vary.resolve(chain, "model.elements.1.between.1")


# --------------------------------------------------------------------------------------------
# apply, parameters, build_all
# --------------------------------------------------------------------------------------------
def test_apply_is_a_deep_copy_and_never_extends(single, chain):
    before = repr(single)
    out = vary.apply(single, {"alpha": 0.4, "excitation.amplitudes.1": 0.05})
    assert out["model"]["elastic"]["alpha"] == 0.4 and out["excitation"]["amplitudes"] == [0.05]
    assert repr(single) == before
    out = vary.apply(chain, {"model.elements.clutch.alpha": 0.1})
    assert out["model"]["elements"][0]["alpha"] == 0.1 and chain["model"]["elements"][0]["alpha"] == 0.25
    with pytest.raises(ConfigError, match="does not add harmonics"):
        vary.apply(single, {"excitation.amplitudes.2": 0.01})


def test_parameters_and_combinations_in_c_order(single):
    params = vary.parameters(single, {"alpha": [0.1, 0.2], "b": [0.1, 0.2, 0.3]})
    assert params[0] == Parameter("alpha", "model.elastic.alpha", (0.1, 0.2))
    combos = list(vary.combinations(params))
    assert len(combos) == 6
    assert combos[1] == {"model.elastic.alpha": 0.1, "model.elastic.b": 0.2}  # the last varies fastest
    with pytest.raises(ConfigError, match="both set `model.elastic.alpha`"):
        vary.parameters(single, [("alpha", [0.1]), ("model.elastic.alpha", [0.2])])


def test_build_all_gives_every_model(single, chain):
    models = vary.build_all(single, vary.parameters(single, {"alpha": [0.0, 0.2], "b": [0.1, 0.2]}))
    assert [(m.elastic.alpha, m.elastic.b) for m in models] == [(0.0, 0.1), (0.0, 0.2), (0.2, 0.1), (0.2, 0.2)]
    (m,) = vary.build_all(chain, vary.parameters(chain, {"alpha": [0.1]}))
    assert m.elements[0].law.alpha == 0.1


@pytest.mark.parametrize("values, fragment", [
    ({"alpha": [0.2, 1.5]}, "alpha = 1.5 (`model.elastic.alpha`): the model refuses this value: `model.elastic.alpha`"),
    ({"b": [0.1, -0.1]}, "b = -0.1"),
    ({"damping": [0.0]}, "damping = 0"),
    ({"model.inertia": [-1.0]}, "model.inertia = -1"),
])
def test_a_value_the_model_refuses_names_the_parameter_and_rule(single, values, fragment):
    with pytest.raises(ConfigError, match="`--vary`") as info:
        vary.build_all(single, vary.parameters(single, values))
    assert fragment in str(info.value)


def test_a_free_chain_refuses_an_unbalanced_mean(chain):
    with pytest.raises(ConfigError, match="excitation.torques.1.mean = 0.1") as info:
        vary.build_all(chain, vary.parameters(chain, {"excitation.torques.1.mean": [0.05, 0.1]}))
    assert "the model refuses" in str(info.value)


# --------------------------------------------------------------------------------------------
# Angles named in degrees, as the case file writes them (FIELD_deg)
# --------------------------------------------------------------------------------------------
def test_an_angle_named_in_degrees_is_the_radian_key_converted(single, driveline):
    import math

    (deg,) = vary.parameters(single, [("model.elastic.b_deg", [8.0, 12.0])])
    (rad,) = vary.parameters(single, [("model.elastic.b", [math.radians(8.0), math.radians(12.0)])])
    assert (deg.name, deg.key, deg.degrees) == ("model.elastic.b", "model.elastic.b", True)
    assert deg.values == rad.values  # x · π/180, as the case file's b_deg is converted
    assert [deg.shown(v) for v in deg.values] == pytest.approx([8.0, 12.0], rel=1e-15)
    # a breakpoint of a chain's element, by position and by the element's name
    for name in ("model.elements.1.breakpoints_deg.4", "model.elements.clutch.breakpoints_deg.4"):
        (p,) = vary.parameters(driveline, [(name, [5.0])])
        assert p.key == "model.elements.1.breakpoints.4" and p.degrees
        assert p.values == (math.radians(5.0),)
    # the models built are the radian key's
    a = vary.build_all(single, [deg])
    b = vary.build_all(single, [rad])
    assert [m.elastic.stages.breakpoints.tolist() for m in a] == [m.elastic.stages.breakpoints.tolist() for m in b]
    # a Parameter handed back keeps its values (rad already)
    assert vary.parameters(single, [deg]) == (deg,)
    # apply() converts too
    assert vary.apply(single, {"model.elastic.b_deg": 9.0})["model"]["elastic"]["b"] == math.radians(9.0)


@pytest.mark.parametrize("name", ["model.elastic.alpha_deg", "model.elastic.bogus_deg", "model.elements.1.b_deg"])
def test_a_degree_key_that_is_not_an_angle_of_the_case_is_refused_naming_it(single, name):
    with pytest.raises(ConfigError, match=rf"`--vary` '{name}'"):
        vary.parameters(single, [(name, [1.0])])
