"""``rattle`` on a chain with Coulomb friction on its elements (``[[model.elements]] friction``):
``rattle frf`` writes the chain's non-smooth response (a FrictionResponse) as one set; sweep,
compare, map and orbit refuse it (exit 2, nothing written) and say that frf solves it."""

from __future__ import annotations

import pytest

from _cli_helpers import assert_bad_input, invoke, write_config

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
"""


@pytest.mark.parametrize("args", [["sweep", "--direction", "up"], ["compare"], ["map", "--vary", "mean=0.04,0.05"],
                                  ["orbit", "--omega", "0.9"]])
def test_commands_other_than_frf_refuse_a_chain_with_friction_and_write_nothing(tmp_path, args):
    config = write_config(tmp_path, CHAIN)
    result = invoke([args[0], str(config), *args[1:], "-o", "out"], tmp_path)
    assert_bad_input(result, "`model.elements[0].friction`", "a chain with Coulomb friction on its elements",
                     f"not supported by `rattle {args[0]}` yet", "use `rattle frf`")
    assert not (tmp_path / "out").exists()


def test_frf_refuses_subharmonics_and_bad_friction_with_nothing_written(tmp_path):
    config = write_config(tmp_path, CHAIN)
    result = invoke(["frf", str(config), "--subharmonics", "-o", "out"], tmp_path)
    assert_bad_input(result, "`--subharmonics`", "`model.elements[0].friction`")
    for old, new, fragments in [
        ("friction = [0.0, 0.03, 0.0]", "friction = [0.03, 0.0]",
         ["`model.elements[0].friction` must hold one level", 'type = "clutch" has 3 stages', "give 3 levels"]),
        ("friction = [0.0, 0.03, 0.0]", "friction = -0.01", ["`model.elements[0].friction`", "must be >= 0"]),
        ("friction = [0.0, 0.03, 0.0]", "friction = [0.0, 0.03, 0.0]\npreload = 0.05",
         ["`model.elements[0].preload`", "solved for the single equation only"]),
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
