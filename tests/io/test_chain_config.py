"""SPEC §5 chain configurations: reading, round trip, refusals with the full key."""

import tomllib

import pytest

from rattle.errors import ConfigError
from rattle.io import config_from_dict, dumps_toml, model_to_toml_dict
from rattle.model import Chain

TWO = """
[model]
inertias = [2.0, 2.0]

[[model.links]]
between = [1, 2]
damping = 0.05

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 1.0
type = "clutch"
alpha = 0.25
b = 0.174533

[[excitation.torques]]
inertia = 1
mean = 0.05
amplitudes = [0.06]

[[excitation.torques]]
inertia = 2
mean = -0.05
"""


def _load(text):
    return config_from_dict(tomllib.loads(text), source_name="chain.toml")


def test_reads_the_spec_example_and_round_trips():
    cfg = _load(TWO)
    assert isinstance(cfg.model, Chain)
    s = cfg.model.system()
    assert s.n == 1 and s.damping[0, 0] == pytest.approx(0.05) and s.mean[0] == pytest.approx(0.05)
    again = _load(dumps_toml(model_to_toml_dict(cfg.model, cfg.analysis)))
    assert again.model.to_dict() == cfg.model.to_dict()
    assert again.analysis == cfg.analysis


@pytest.mark.parametrize(
    "edit, key",
    [
        (("mean = -0.05", "mean = -0.04"), "`excitation.torques`"),
        (("between = [1, 2]\ndamping", "between = [1, 3]\ndamping"), "`model.links.1.between.2`"),
        (("inertia = 2\n", "inertia = 3\n"), "`excitation.torques.2.inertia`"),
        (("alpha = 0.25", "alpha = 1.25"), "`model.elements.1.alpha`"),
        (("type = \"clutch\"", "type = \"clutsh\""), "`model.elements.1.type`"),
        (("damping = 0.05", "dampin = 0.05"), "`model.links.1.dampin`"),
        (("inertias = [2.0, 2.0]", "inertias = [2.0, -2.0]"), "`model.inertias.2`"),
        (("inertias = [2.0, 2.0]", "inertias = [2.0, 2.0]\ninertia = 1.0"), "`model.inertia`"),
        (("stiffness = 1.0\n", "stiffness = \"1\"\n"), "`model.elements.1.stiffness`"),
        (("name = \"clutch\"", "name = \"my clutch\""), "`model.elements.1.name`"),
        (("inertias = [2.0, 2.0]", "inertias = []"), "`model.inertias` must hold at least one"),
        (("b = 0.174533", "b = 0.174533\nfoo = 1"), "allows only name, between, stiffness, type, alpha, b"),
        (("damping = 0.05", "damping = 0.0"), "`model.links`"),
    ],
)
def test_refusals_name_the_key(edit, key):
    old, new = edit
    assert old in TWO
    with pytest.raises(ConfigError) as err:
        _load(TWO.replace(old, new, 1))
    assert key in str(err.value), str(err.value)


@pytest.mark.parametrize(
    "edit, key",
    [
        (("mean = -0.05", "mean = -0.04"), "`excitation.torques`"),
        (("inertias = [2.0, 2.0]", "inertias = [2.0, 0.0]"), "`model.inertias.2`"),
        (("between = [1, 2]\ndamping", "between = [1, 1]\ndamping"), "`model.links.1.between`"),
    ],
)
def test_command_line_refuses_a_bad_chain_with_exit_2_and_writes_nothing(tmp_path, edit, key):
    from _cli_helpers import assert_bad_input, invoke

    old, new = edit
    (tmp_path / "chain.toml").write_text(TWO.replace(old, new, 1), encoding="utf-8")
    result = invoke(["frf", "chain.toml", "-o", "out"], tmp_path)
    assert_bad_input(result, key)
    assert not (tmp_path / "out").exists()
