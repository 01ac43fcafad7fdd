"""The model tables of a configuration file, read in the model layer (rattle.model._tables): the
same model as rattle.io's reader, with the run's tables ([analysis], [[paths]]) left to it."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

from rattle import Chain, Model
from rattle.errors import ConfigError
from rattle.io import config_from_dict, load_config
from rattle.model._tables import ModelTables, model_tables

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _same(a: object, b: object) -> bool:
    """Equal models (a chain by its tables: it caches its reduced system in numpy arrays)."""
    return a.to_dict() == b.to_dict() if isinstance(a, Chain) else a == b

SPEC_EXAMPLE = """
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "clutch"
alpha = 0.25
b = 0.174533

[excitation]
mean = 0.05
amplitudes = [0.03]
phases = [0.0]

[analysis]
omega = [0.1, 3.0]
harmonics = 32
"""


@pytest.mark.parametrize("name", ["reference_clutch.toml", "gear_backlash.toml", "chain_two_inertia.toml",
                                  "engine_clutch_si.toml", "gearbox_loose_gear.toml", "clutch_friction.toml"])
def test_the_model_tables_give_the_model_of_the_configuration(name: str) -> None:
    data = tomllib.loads((EXAMPLES / name).read_text(encoding="utf-8"))
    tables = model_tables(data, name)
    config = load_config(EXAMPLES / name)
    assert isinstance(tables, ModelTables)
    assert _same(tables.model, config.model)
    assert tables.units == config.units
    assert tables.continuous_model == config.continuous_model
    assert tables.discontinuous == config.discontinuous


def test_an_engine_is_resolved_into_its_torque_base_order_and_speed_range() -> None:
    tables = model_tables(tomllib.loads((EXAMPLES / "engine_clutch_si.toml").read_text(encoding="utf-8")))
    engine = tables.engine
    assert engine is not None and tables.units == "SI"
    assert engine.base_order == 2.0  # gcd of orders 2 and 4
    assert engine.harmonics == 2  # order 4 is harmonic 2 of the base order
    assert engine.rpm == (400.0, 1500.0)
    assert tables.model.speed_order == 2.0
    # rattle.io turns the speed range into the analysis range Ω = q0 · 2π/60 · rpm
    config = load_config(EXAMPLES / "engine_clutch_si.toml")
    assert config.analysis.omega == pytest.approx((2.0 * 2.0 * math.pi / 60.0 * 400.0,
                                                   2.0 * 2.0 * math.pi / 60.0 * 1500.0), rel=1e-15)


def test_the_run_tables_are_left_to_the_configuration_reader() -> None:
    data = tomllib.loads(SPEC_EXAMPLE)
    data["analysis"] = {"omeg": [0.1, 3.0]}  # misspelt: rattle.io refuses it, the model tables do not read it
    assert model_tables(data).model == config_from_dict(tomllib.loads(SPEC_EXAMPLE)).model
    with pytest.raises(ConfigError, match="`analysis.omeg` is not a known key"):
        config_from_dict(data)
    with pytest.raises(ConfigError, match="`analysys` is not a known key: the top level allows only model, excitation, "
                                          "analysis, engine, paths, drag"):
        model_tables({**tomllib.loads(SPEC_EXAMPLE), "analysys": {}})


@pytest.mark.parametrize("text", [
    SPEC_EXAMPLE.replace("damping = 0.05", "dampng = 0.05"),
    SPEC_EXAMPLE.replace('type = "clutch"', 'type = "clutchh"'),
    SPEC_EXAMPLE.replace("b = 0.174533", "b_deg = 10.0\nb = 0.1"),
    "[model]\ninertia = 1.0\n",
])
def test_model_from_toml_refuses_with_the_message_of_load_config(tmp_path: Path, text: str) -> None:
    path = tmp_path / "case.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as from_io:
        load_config(path)
    with pytest.raises(ConfigError) as from_model:
        Model.from_toml(path)
    assert str(from_model.value) == str(from_io.value)
    assert str(from_model.value).startswith(f"{path}: `")


def test_model_and_chain_from_toml_read_files_as_load_config(tmp_path: Path) -> None:
    missing = tmp_path / "missing.toml"
    with pytest.raises(ConfigError, match="configuration file .*missing.toml' does not exist"):
        Model.from_toml(missing)
    with pytest.raises(ConfigError, match="not valid TOML"):
        (tmp_path / "bad.toml").write_text("[model\n", encoding="utf-8")
        Chain.from_toml(tmp_path / "bad.toml")
    assert _same(Chain.from_toml(EXAMPLES / "driveline_three_inertia.toml"),
                 load_config(EXAMPLES / "driveline_three_inertia.toml").model)
