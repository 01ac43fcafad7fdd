"""rattle.io: the strict configuration reader (every rule has a message test), its round trip,
and the writers it shares with the command line (atomic writes, CSV, metadata)."""

from __future__ import annotations

import dataclasses
import datetime as dt
import enum
import json
import math
import os
import stat
import tomllib
from pathlib import Path

import numpy as np
import pytest

from rattle.errors import ConfigError
from rattle.io import (
    DEFAULT_HARMONICS,
    DEFAULT_OMEGA,
    AnalysisSettings,
    RunConfig,
    atomic_path,
    atomic_write_bytes,
    atomic_write_text,
    config_from_dict,
    dumps_toml,
    format_csv,
    load_config,
    metadata_document,
    model_to_toml_dict,
    rattle_version,
    read_csv,
    rename_keys,
    to_jsonable,
    write_csv,
    write_metadata,
)
from rattle.model import Backlash, Clutch, Excitation, Linear, Model, Piecewise, Unilateral, reference_case
from rattle.results import FRF_COLUMNS, ORBIT_COLUMNS, SWEEP_COLUMNS

# The SPEC §2 example, verbatim (comments included).
SPEC_EXAMPLE = """\
[model]
inertia = 1.0          # I  (kg m^2, or 1 for dimensionless)
damping = 0.05         # C
stiffness = 1.0        # K  (stiffness of the unit-slope stage)

[model.elastic]
type = "clutch"        # linear | backlash | clutch | piecewise
alpha = 0.25
b = 0.174533           # rad
# type = "piecewise": breakpoints = [-0.3, -0.1, 0.05, 0.2]; slopes = [1.0, 0.3, 0.05, 0.3, 1.0]

[excitation]
mean = 0.05            # F_m, the equation's right-hand side (torque per inertia)
amplitudes = [0.03]    # F_p1, F_p2, ... for harmonics 1, 2, ... of the forcing frequency
phases = [0.0]         # rad, cosine convention; optional, default 0

[analysis]
omega = [0.1, 3.0]     # forcing frequency range Ω in rad/s (= Ω̄ when K = I = 1)
harmonics = 32         # harmonics kept in the harmonic balance
"""

# A compact valid file whose lines the broken cases below replace one at a time.
MODEL = "[model]\ninertia = 1.0\ndamping = 0.05\nstiffness = 1.0\n"
CLUTCH = '[model.elastic]\ntype = "clutch"\nalpha = 0.25\nb = 0.174533\n'
BACKLASH = '[model.elastic]\ntype = "backlash"\nb = 0.1\n'
PIECEWISE = (
    '[model.elastic]\ntype = "piecewise"\n'
    "breakpoints = [-0.3, -0.1, 0.05, 0.2]\nslopes = [1.0, 0.3, 0.05, 0.3, 1.0]\n"
)
EXCITATION = "[excitation]\nmean = 0.05\namplitudes = [0.03]\nphases = [0.0]\n"
ANALYSIS = "[analysis]\nomega = [0.1, 3.0]\nharmonics = 32\n"
VALID = MODEL + CLUTCH + EXCITATION + ANALYSIS


def edit(old: str, new: str, base: str = VALID) -> str:
    """``base`` with its one occurrence of ``old`` replaced by ``new``."""
    assert base.count(old) == 1, (old, base)  # a guard on the test table itself
    return base.replace(old, new)


def write(tmp_path: Path, text: str, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------
# Valid files
# --------------------------------------------------------------------------------------------
def test_spec_example_parses_to_the_reference_case(tmp_path: Path) -> None:
    config = load_config(write(tmp_path, SPEC_EXAMPLE))
    ref = reference_case()
    model = config.model
    assert isinstance(config, RunConfig)
    assert isinstance(model.elastic, Clutch)
    assert (model.inertia, model.damping, model.stiffness) == (ref.inertia, ref.damping, ref.stiffness)
    assert model.elastic.alpha == ref.elastic.alpha
    # The file gives b = 0.174533 rad, 10° to the 6 digits written.
    assert model.elastic.b == pytest.approx(ref.elastic.b, abs=5e-7)
    assert model.excitation == ref.excitation
    assert config.analysis == AnalysisSettings(omega_min=0.1, omega_max=3.0, harmonics=32)
    assert config.analysis.omega == (0.1, 3.0)
    assert config.source == tomllib.loads(SPEC_EXAMPLE)
    assert config.source_name == str(tmp_path / "case.toml")


def test_model_from_toml_reads_the_model_of_load_config(tmp_path: Path) -> None:
    path = write(tmp_path, SPEC_EXAMPLE)
    assert Model.from_toml(path) == load_config(path).model
    assert Model.from_toml(str(path)) == load_config(path).model


def test_optional_tables_and_keys_get_documented_defaults(tmp_path: Path) -> None:
    text = MODEL + CLUTCH + "[excitation]\nmean = 0.05\namplitudes = [0.03, 0.01]\n"
    config = load_config(write(tmp_path, text))
    assert config.analysis.omega == DEFAULT_OMEGA == (0.1, 3.0)
    assert config.analysis.harmonics == DEFAULT_HARMONICS == 32
    assert config.model.excitation.phases == (0.0, 0.0)


def test_analysis_table_may_give_only_one_key(tmp_path: Path) -> None:
    config = load_config(write(tmp_path, MODEL + CLUTCH + EXCITATION + "[analysis]\nharmonics = 8\n"))
    assert config.analysis == AnalysisSettings(omega_min=0.1, omega_max=3.0, harmonics=8)


@pytest.mark.parametrize(
    ("elastic_text", "expected"),
    [
        ('[model.elastic]\ntype = "linear"\n', Linear()),
        (BACKLASH, Backlash(b=0.1)),
        (CLUTCH, Clutch(alpha=0.25, b=0.174533)),
        (PIECEWISE, Piecewise(breakpoints=(-0.3, -0.1, 0.05, 0.2), slopes=(1.0, 0.3, 0.05, 0.3, 1.0))),
    ],
    ids=["linear", "backlash", "clutch", "piecewise"],
)
def test_every_elastic_type_parses(tmp_path: Path, elastic_text: str, expected: object) -> None:
    config = load_config(write(tmp_path, MODEL + elastic_text + EXCITATION))
    assert config.model.elastic == expected


def test_integers_are_accepted_where_numbers_are_expected(tmp_path: Path) -> None:
    text = edit("inertia = 1.0", "inertia = 2", edit("omega = [0.1, 3.0]", "omega = [1, 3]"))
    config = load_config(write(tmp_path, text))
    assert config.model.inertia == 2.0 and isinstance(config.model.inertia, float)
    assert config.analysis.omega == (1.0, 3.0)


def test_config_from_dict_for_library_users() -> None:
    data = tomllib.loads(VALID)
    config = config_from_dict(data)
    assert config.model.elastic == Clutch(alpha=0.25, b=0.174533)
    assert config.source_name == "<dict>"
    # The provenance copy is independent of the caller's dict.
    data["model"]["inertia"] = 99.0
    assert config.source["model"]["inertia"] == 1.0
    with pytest.raises(ConfigError, match=r"^<dict>: `model.inertia` must be > 0"):
        config_from_dict(tomllib.loads(edit("inertia = 1.0", "inertia = -1.0")))
    with pytest.raises(ConfigError, match=r"my-case: `model.inertia`"):
        config_from_dict(tomllib.loads(edit("inertia = 1.0", "inertia = -1.0")), source_name="my-case")


def test_config_from_dict_refuses_a_non_mapping() -> None:
    with pytest.raises(ConfigError, match="must be a table of tables, got an array"):
        config_from_dict([1, 2])  # type: ignore[arg-type]


def test_run_config_is_frozen() -> None:
    config = config_from_dict(tomllib.loads(VALID))
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.model = reference_case()  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.analysis.harmonics = 3  # type: ignore[misc]


# --------------------------------------------------------------------------------------------
# Broken files: one table row per rule, each checked for the key, value, rule (and fix)
# --------------------------------------------------------------------------------------------
BROKEN: list[tuple[str, str, list[str]]] = [
    # --- unknown keys, at every level, listing the allowed ones
    ("unknown top-level table", VALID + "[solver]\ntol = 1e-8\n",
     ["`solver` is not a known key", "allows only model, excitation, analysis"]),
    ("unknown model key (typo)", edit("damping = 0.05", "dampin = 0.05"),
     ["`model.dampin` is not a known key", "inertia, damping, stiffness, elastic", "did you mean `damping`?"]),
    ("unknown excitation key", edit("mean = 0.05", "mean = 0.05\noffset = 1.0"),
     ["`excitation.offset` is not a known key", "mean, amplitudes, phases"]),
    ("unknown analysis key", edit("harmonics = 32", "harmonics = 32\npoints = 200"),
     ["`analysis.points` is not a known key", "omega, harmonics"]),
    ("unknown elastic key", edit("b = 0.174533", "b = 0.174533\nwidth = 0.1"),
     ["`model.elastic.width` is not a known key", 'type = "clutch" allows only type, alpha, b']),
    # --- keys belonging to another elastic type
    ("alpha with backlash", edit("b = 0.1", "b = 0.1\nalpha = 0.25", MODEL + BACKLASH + EXCITATION),
     ['`model.elastic.alpha` does not belong to type = "backlash"', "parameters are: b", '"clutch"']),
    ("breakpoints with clutch", edit("b = 0.174533", "b = 0.174533\nbreakpoints = [0.1]"),
     ['`model.elastic.breakpoints` does not belong to type = "clutch"', '"piecewise"']),
    ("b with linear", MODEL + '[model.elastic]\ntype = "linear"\nb = 0.1\n' + EXCITATION,
     ['`model.elastic.b` does not belong to type = "linear"', "parameters are: (none)"]),
    # --- missing required keys and tables
    ("missing model", EXCITATION, ["`model` is missing", "requires model, excitation"]),
    ("missing inertia", edit("inertia = 1.0\n", ""), ["`model.inertia` is missing", "add e.g. inertia = 1.0"]),
    ("missing damping", edit("damping = 0.05\n", ""), ["`model.damping` is missing", "damping = 0.05"]),
    ("missing stiffness", edit("stiffness = 1.0\n", ""), ["`model.stiffness` is missing"]),
    ("missing elastic table", MODEL + EXCITATION, ["`model.elastic` is missing", '[model.elastic] with type = "clutch"']),
    ("missing elastic type", edit('type = "clutch"\n', ""),
     ["`model.elastic.type` is missing", '"linear", "backlash", "clutch", "piecewise"']),
    ("missing clutch b", edit("b = 0.174533\n", ""),
     ['`model.elastic.b` is missing: type = "clutch" requires alpha, b', "b = 0.174533"]),
    ("missing piecewise slopes", edit("slopes = [1.0, 0.3, 0.05, 0.3, 1.0]\n", "", MODEL + PIECEWISE + EXCITATION),
     ["`model.elastic.slopes` is missing", "requires breakpoints, slopes"]),
    ("missing excitation", MODEL + CLUTCH, ["`excitation` is missing"]),
    ("missing mean", edit("mean = 0.05\n", ""), ["`excitation.mean` is missing", "mean = 0.05"]),
    ("missing amplitudes", edit("amplitudes = [0.03]\n", ""), ["`excitation.amplitudes` is missing"]),
    # --- tables and values of the wrong TOML type
    ("model not a table", "model = 3\n" + EXCITATION, ["`model` must be a table, got 3 (an integer)"]),
    ("elastic not a table", edit("stiffness = 1.0\n", 'stiffness = 1.0\nelastic = "clutch"\n', MODEL) + EXCITATION,
     ['`model.elastic` must be a table, got "clutch" (a string)']),
    ("analysis not a table", "analysis = 5\n" + MODEL + CLUTCH + EXCITATION, ["`analysis` must be a table, got 5"]),
    ("boolean inertia", edit("inertia = 1.0", "inertia = true"),
     ["`model.inertia` must be a number, got true (a boolean)", "booleans are not numbers"]),
    ("string damping", edit("damping = 0.05", 'damping = "0.05"'),
     ['`model.damping` must be a number, got "0.05" (a string)', "remove the quotes", "damping = 0.05"]),
    ("array stiffness", edit("stiffness = 1.0", "stiffness = [1.0]"),
     ["`model.stiffness` must be a number, got [1.0] (an array)", "single number"]),
    ("date inertia", edit("inertia = 1.0", "inertia = 1979-05-27"),
     ["`model.inertia` must be a number, got 1979-05-27 (a date/time)"]),
    ("table mean", edit("mean = 0.05", "mean = {value = 0.05}"),
     ["`excitation.mean` must be a number, got {value = 0.05} (a table)"]),
    ("string clutch alpha", edit("alpha = 0.25", 'alpha = "0.25"'), ['`model.elastic.alpha` must be a number, got "0.25"']),
    ("array backlash b", edit("b = 0.1", "b = [0.1]", MODEL + BACKLASH + EXCITATION),
     ["`model.elastic.b` must be a number, got [0.1] (an array)"]),
    ("scalar breakpoints", edit("breakpoints = [-0.3, -0.1, 0.05, 0.2]", "breakpoints = 0.1", MODEL + PIECEWISE + EXCITATION),
     ["`model.elastic.breakpoints` must be an array of numbers, got 0.1 (a float)"]),
    ("string in slopes", edit("slopes = [1.0, 0.3, 0.05, 0.3, 1.0]", 'slopes = [1.0, "x", 1.0]', MODEL + PIECEWISE + EXCITATION),
     ['`model.elastic.slopes.2` must be a number, got "x" (a string)']),
    ("scalar amplitudes", edit("amplitudes = [0.03]", "amplitudes = 0.03"),
     ["`excitation.amplitudes` must be an array of numbers, got 0.03 (a float)", "amplitudes = [0.03]"]),
    ("boolean in amplitudes", edit("amplitudes = [0.03]", "amplitudes = [0.03, false]"),
     ["`excitation.amplitudes.2` must be a number, got false (a boolean)"]),
    ("scalar phases", edit("phases = [0.0]", "phases = 0.0"), ["`excitation.phases` must be an array of numbers"]),
    # --- NaN and infinity (TOML allows the literals)
    ("nan inertia", edit("inertia = 1.0", "inertia = nan"), ["`model.inertia` must be a finite number, got nan (TOML's not-a-number literal)", "inertia = 1.0"]),
    ("inf damping", edit("damping = 0.05", "damping = inf"), ["`model.damping` must be a finite number, got inf (TOML's infinity literal)"]),
    ("nan mean", edit("mean = 0.05", "mean = nan"), ["`excitation.mean` must be a finite number, got nan"]),
    ("-inf amplitude", edit("amplitudes = [0.03]", "amplitudes = [-inf]"), ["`excitation.amplitudes.1` must be a finite number, got -inf"]),
    ("nan phase", edit("phases = [0.0]", "phases = [nan]"), ["`excitation.phases.1` must be a finite number"]),
    ("nan clutch b", edit("b = 0.174533", "b = nan"), ["`model.elastic.b` must be a finite number, got nan"]),
    ("inf breakpoint", edit("0.2]", "inf]", MODEL + PIECEWISE + EXCITATION), ["`model.elastic.breakpoints.4` must be a finite number, got inf"]),
    ("nan omega", edit("omega = [0.1, 3.0]", "omega = [0.1, nan]"), ["`analysis.omega.2` must be a finite number, got nan"]),
    # --- physical ranges (the model dataclasses' rules, with the full key)
    ("negative inertia", edit("inertia = 1.0", "inertia = -1.0"), ["`model.inertia` must be > 0, got -1.0"]),
    ("zero inertia", edit("inertia = 1.0", "inertia = 0.0"), ["`model.inertia` must be > 0, got 0.0"]),
    ("zero stiffness", edit("stiffness = 1.0", "stiffness = 0"), ["`model.stiffness` must be > 0, got 0.0"]),
    ("negative stiffness", edit("stiffness = 1.0", "stiffness = -2.0"), ["`model.stiffness` must be > 0, got -2.0"]),
    ("negative damping", edit("damping = 0.05", "damping = -0.05"), ["`model.damping` must be >= 0, got -0.05"]),
    # --- elastic types and their parameters
    ("unknown elastic type", edit('type = "clutch"', 'type = "spring"'),
     ['`model.elastic.type` must be one of "linear", "backlash", "clutch", "piecewise", "unilateral", "preload", got "spring" (a string)']),
    ("elastic type wrong case", edit('type = "clutch"', 'type = "Clutch"'), ['got "Clutch"', 'did you mean "clutch"?']),
    ("elastic type not a string", edit('type = "clutch"', "type = 3"), ["`model.elastic.type` must be one of", "got 3 (an integer)"]),
    ("clutch alpha = 1", edit("alpha = 0.25", "alpha = 1.0"),
     ["`model.elastic.alpha` (clutch first-stage slope) must satisfy 0 <= alpha < 1, got 1.0", 'type = "piecewise"']),
    ("clutch alpha < 0", edit("alpha = 0.25", "alpha = -0.5"), ["`model.elastic.alpha`", "0 <= alpha < 1, got -0.5"]),
    ("clutch b = 0", edit("b = 0.174533", "b = 0.0"), ["`model.elastic.b` (clutch first-stage half-width) must be > 0 rad, got 0.0"]),
    ("backlash b < 0", edit("b = 0.1", "b = -0.1", MODEL + BACKLASH + EXCITATION), ["`model.elastic.b` (backlash) must be > 0 rad, got -0.1"]),
    ("breakpoints not increasing",
     edit("breakpoints = [-0.3, -0.1, 0.05, 0.2]", "breakpoints = [-0.3, 0.05, -0.1, 0.2]", MODEL + PIECEWISE + EXCITATION),
     ["`model.elastic.breakpoints` must be strictly increasing, got [-0.3, 0.05, -0.1, 0.2]", "breakpoints.2 = 0.05"]),
    ("breakpoints repeated",
     edit("breakpoints = [-0.3, -0.1, 0.05, 0.2]", "breakpoints = [-0.3, -0.1, -0.1, 0.2]", MODEL + PIECEWISE + EXCITATION),
     ["`model.elastic.breakpoints` must be strictly increasing"]),
    ("slopes count wrong",
     edit("slopes = [1.0, 0.3, 0.05, 0.3, 1.0]", "slopes = [1.0, 0.3, 1.0]", MODEL + PIECEWISE + EXCITATION),
     ["`model.elastic.slopes` must have one more entry than `model.elastic.breakpoints`", "4 breakpoints need 5 slopes), got 3"]),
    ("negative slope",
     edit("slopes = [1.0, 0.3, 0.05, 0.3, 1.0]", "slopes = [1.0, 0.3, -0.05, 0.3, 1.0]", MODEL + PIECEWISE + EXCITATION),
     ["`model.elastic.slopes.3` must be >= 0, got -0.05"]),
    ("every slope zero",
     edit("slopes = [1.0, 0.3, 0.05, 0.3, 1.0]", "slopes = [0.0, 0.0, 0.0, 0.0, 0.0]", MODEL + PIECEWISE + EXCITATION),
     ["`model.elastic.slopes` must have at least one stage with slope > 0"]),
    ("zero outer slope, the mean load pushing away from the stop",
     edit("slopes = [1.0, 0.3, 0.05, 0.3, 1.0]", "slopes = [1.0, 0.3, 0.05, 0.3, 0.0]", MODEL + PIECEWISE + EXCITATION)
     .replace("mean = 0.05", "mean = 0.9"),
     ["`excitation.mean` = 0.9: no static equilibrium", "one-sided stop"]),
    # --- excitation
    ("empty amplitudes", edit("amplitudes = [0.03]\nphases = [0.0]", "amplitudes = []"),
     ["`excitation.amplitudes` must hold at least one harmonic amplitude, got []"]),
    ("phases longer than amplitudes", edit("phases = [0.0]", "phases = [0.0, 1.0]"),
     ["`excitation.phases` must have one entry per amplitude (1), got 2"]),
    ("phases empty", edit("phases = [0.0]", "phases = []"), ["`excitation.phases` must have one entry per amplitude (1), got 0"]),
    # --- analysis
    ("omega one number", edit("omega = [0.1, 3.0]", "omega = [0.1]"),
     ["`analysis.omega` must be a list of two numbers [min, max] (rad/s), got [0.1] (1 number)", "omega = [0.1, 3.0]"]),
    ("omega three numbers", edit("omega = [0.1, 3.0]", "omega = [0.1, 1.0, 3.0]"), ["`analysis.omega` must be a list of two numbers"]),
    ("omega scalar", edit("omega = [0.1, 3.0]", "omega = 3.0"), ["`analysis.omega` must be an array of numbers, got 3.0"]),
    ("omega string item", edit("omega = [0.1, 3.0]", 'omega = ["0.1", 3.0]'), ['`analysis.omega.1` must be a number, got "0.1"']),
    ("omega reversed (empty range)", edit("omega = [0.1, 3.0]", "omega = [3.0, 0.1]"),
     ["`analysis.omega.1` must be < `analysis.omega.2`", "= 3.0 and", "= 0.1", "the frequency range is empty"]),
    ("omega equal (empty range)", edit("omega = [0.1, 3.0]", "omega = [1.0, 1.0]"), ["the frequency range is empty"]),
    ("omega min zero", edit("omega = [0.1, 3.0]", "omega = [0.0, 3.0]"), ["`analysis.omega.1` must be > 0 rad/s", "got 0.0"]),
    ("omega min negative", edit("omega = [0.1, 3.0]", "omega = [-1.0, 3.0]"), ["`analysis.omega.1` must be > 0 rad/s", "got -1.0"]),
    ("harmonics zero", edit("harmonics = 32", "harmonics = 0"), ["`analysis.harmonics` must be an integer >= 1, got 0"]),
    ("harmonics negative", edit("harmonics = 32", "harmonics = -3"), ["`analysis.harmonics` must be an integer >= 1, got -3"]),
    ("harmonics float", edit("harmonics = 32", "harmonics = 32.0"),
     ["`analysis.harmonics` must be an integer, got 32.0 (a float)", "harmonics = 32"]),
    ("harmonics boolean", edit("harmonics = 32", "harmonics = true"), ["`analysis.harmonics` must be an integer, got true (a boolean)"]),
    ("harmonics string", edit("harmonics = 32", 'harmonics = "32"'), ['`analysis.harmonics` must be an integer, got "32" (a string)']),
]


@pytest.mark.parametrize(("text", "fragments"), [row[1:] for row in BROKEN], ids=[row[0] for row in BROKEN])
def test_broken_config_is_refused_with_a_message_naming_the_key(
    tmp_path: Path, text: str, fragments: list[str]
) -> None:
    path = write(tmp_path, text)
    tomllib.loads(text)  # every case is valid TOML: the schema, not the parser, refuses it
    with pytest.raises(ConfigError, match=f"^{_re_escape(str(path))}: ") as info:
        load_config(path)
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    assert "\n" not in message  # one line


def _re_escape(text: str) -> str:
    import re

    return re.escape(text)


def test_every_rule_of_the_brief_has_a_row() -> None:
    """Guard against rows being dropped from the table."""
    assert len(BROKEN) >= 70
    assert len({row[0] for row in BROKEN}) == len(BROKEN)


def test_structure_is_checked_before_values(tmp_path: Path) -> None:
    # A misspelt key is reported even when another value is also wrong.
    text = edit("inertia = 1.0", "inertia = -1.0", edit("damping = 0.05", "dampng = 0.05"))
    with pytest.raises(ConfigError, match=r"`model.dampng` is not a known key"):
        load_config(write(tmp_path, text))


# --------------------------------------------------------------------------------------------
# Unreadable files
# --------------------------------------------------------------------------------------------
def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nope.toml"
    with pytest.raises(ConfigError, match=r"configuration file '.*nope\.toml' does not exist; check the path"):
        load_config(path)


def test_directory_instead_of_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"is a directory; give the path of a \.toml file"):
        load_config(tmp_path)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (MODEL + "damping 0.05\n", "line 5"),  # missing '='
        (VALID + "[model]\ninertia = 2.0\n", "line"),  # table defined twice
        (edit("inertia = 1.0", "inertia = 1.0\ninertia = 2.0"), "line 3"),  # duplicate key
        ("[model\n", "line 1"),
    ],
    ids=["missing equals", "duplicate table", "duplicate key", "unclosed bracket"],
)
def test_invalid_toml_reports_the_parser_line(tmp_path: Path, text: str, fragment: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ConfigError, match=r"is not valid TOML: .*\(at line \d+, column \d+\); correct the syntax") as info:
        load_config(path)
    assert fragment in str(info.value)


def test_non_utf8_file(tmp_path: Path) -> None:
    path = tmp_path / "latin1.toml"
    path.write_bytes("# Ω-range\n".encode("utf-16"))
    with pytest.raises(ConfigError, match="is not UTF-8 text"):
        load_config(path)


# --------------------------------------------------------------------------------------------
# AnalysisSettings, key renaming, round trip
# --------------------------------------------------------------------------------------------
def test_analysis_settings_validate_themselves() -> None:
    assert AnalysisSettings() == AnalysisSettings(omega_min=0.1, omega_max=3.0, harmonics=32)
    with pytest.raises(ValueError, match=r"`harmonics` must be an integer >= 1, got 0"):
        AnalysisSettings(harmonics=0)
    with pytest.raises(TypeError, match=r"`harmonics` must be an integer, got 2.5"):
        AnalysisSettings(harmonics=2.5)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"`omega_min` must be < `omega_max`"):
        AnalysisSettings(omega_min=2.0, omega_max=1.0)
    with pytest.raises(ValueError, match=r"`omega_min` must be > 0"):
        AnalysisSettings(omega_min=-1.0)
    with pytest.raises(TypeError, match=r"`omega_max` must be a real number"):
        AnalysisSettings(omega_max="3")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        AnalysisSettings(0.1, 3.0, 32)  # type: ignore[misc]  # keyword-only
    assert AnalysisSettings(harmonics=np.int64(8)).harmonics == 8
    assert type(AnalysisSettings(harmonics=np.int64(8)).harmonics) is int


def test_rename_keys() -> None:
    names = {"slopes": "model.elastic.slopes", "b": "model.elastic.b"}
    assert rename_keys("`slopes[2]` must be >= 0", names) == "`model.elastic.slopes[2]` must be >= 0"
    assert rename_keys("`b` and `alpha`", names) == "`model.elastic.b` and `alpha`"
    assert rename_keys("b is not backticked", names) == "b is not backticked"


MODELS = [
    reference_case(),
    Model(inertia=2.5, damping=1e-3, stiffness=3.0, elastic=Linear(), excitation=Excitation(mean=0.0, amplitudes=(0.1,))),
    Model(inertia=1.0, damping=0.1, stiffness=1.0, elastic=Backlash(b=1e-3),
          excitation=Excitation(mean=-0.05, amplitudes=(0.03, 0.01, 1 / 3), phases=(0.0, math.pi, -1e-7))),
    Model(inertia=0.5, damping=0.02, stiffness=4.0,
          elastic=Piecewise(breakpoints=(-0.3, -0.1, 0.05, 0.2), slopes=(1.0, 0.3, 0.05, 0.3, 1.0)),
          excitation=Excitation(mean=0.05, amplitudes=(0.03,))),
    Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Unilateral(gap=0.02, side="negative"),
          excitation=Excitation(mean=-0.05, amplitudes=(0.03,))),
]


@pytest.mark.parametrize("model", MODELS, ids=["clutch", "linear", "backlash", "piecewise", "unilateral"])
def test_toml_round_trip(tmp_path: Path, model: Model) -> None:
    analysis = AnalysisSettings(omega_min=0.2, omega_max=2.0 / 3.0, harmonics=7)
    text = dumps_toml(model_to_toml_dict(model, analysis))
    config = load_config(write(tmp_path, text))
    assert config.model == model  # exact: floats are written with repr
    assert config.analysis == analysis
    assert config.to_dict() == model_to_toml_dict(model, analysis)
    assert "analysis" not in model_to_toml_dict(model)


def test_dumps_toml_formats_scalars() -> None:
    text = dumps_toml({"a": {"flag": True, "n": 3, "x": float("inf"), "s": 'q"uote', "weird key": [1, 2.5]}})
    assert tomllib.loads(text) == {"a": {"flag": True, "n": 3, "x": math.inf, "s": 'q"uote', "weird key": [1, 2.5]}}
    with pytest.raises(TypeError, match="cannot write"):
        dumps_toml({"a": {"when": dt.date(2020, 1, 1)}})


# --------------------------------------------------------------------------------------------
# Atomic writes
# --------------------------------------------------------------------------------------------
def test_atomic_write_text_and_bytes(tmp_path: Path) -> None:
    target = tmp_path / "out.txt"
    atomic_write_text(target, "Ω = 1\nline 2\r\n")
    assert target.read_bytes() == "Ω = 1\nline 2\r\n".encode()  # no newline translation
    atomic_write_bytes(target, b"\x00\x01")
    assert target.read_bytes() == b"\x00\x01"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask  # not mkstemp's 0o600


def test_failing_write_leaves_no_file_and_no_temp(tmp_path: Path) -> None:
    target = tmp_path / "frf.png"
    with pytest.raises(RuntimeError, match="disk on fire"):
        with atomic_path(target) as tmp:
            assert tmp.parent == tmp_path and tmp.suffix == ".png"  # savefig infers the format
            tmp.write_bytes(b"half a fi")
            raise RuntimeError("disk on fire")
    assert list(tmp_path.iterdir()) == []


def test_failing_write_keeps_the_old_file(tmp_path: Path) -> None:
    target = tmp_path / "frf.csv"
    target.write_text("old\n")
    with pytest.raises(KeyboardInterrupt):
        with atomic_path(target) as tmp:
            tmp.write_text("new, incompl")
            raise KeyboardInterrupt
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["frf.csv"]


def test_failing_rename_leaves_no_temp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def broken_replace(src: object, dst: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="No space left"):
        write_csv(tmp_path / "frf.csv", {"a": [1.0]}, ["a"])
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_into_missing_directory_creates_nothing(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        atomic_write_text(tmp_path / "missing" / "x.txt", "x")
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_type_checks(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match="`text` must be a str"):
        atomic_write_text(tmp_path / "x", b"bytes")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="`data` must be bytes"):
        atomic_write_bytes(tmp_path / "x", "text")  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------------------------
# CSV
# --------------------------------------------------------------------------------------------
def test_column_constants_match_the_spec() -> None:
    assert ",".join(FRF_COLUMNS) == (
        "branch,period,omega,mean,rms,rms_ac,p2p,acc_p2p,delta_min,delta_max,regime,stable,"
        "bifurcation,iterations,residual"
    )
    assert ",".join(SWEEP_COLUMNS) == "direction,omega,mean,rms,rms_ac,p2p,acc_p2p,period"
    assert ORBIT_COLUMNS == ("t", "delta", "velocity", "acceleration")


def _frf_columns(n: int = 4) -> dict[str, object]:
    rng = np.random.default_rng(7)
    cols: dict[str, object] = {name: rng.standard_normal(n) for name in FRF_COLUMNS}
    cols["branch"] = np.zeros(n, dtype=np.int64)
    cols["period"] = np.array([1, 1, 2, 2])
    cols["iterations"] = [3, 2, np.int32(5), 1]
    cols["regime"] = np.array(["no_impact", "single_sided", "double_sided", "double_sided"])
    cols["stable"] = np.array([True, False, True, False])
    cols["bifurcation"] = ["", "fold", "", "period_doubling"]
    cols["omega"] = np.array([0.1, 1 / 3, 1e-300, 2.0])
    cols["residual"] = np.array([np.nan, np.inf, -0.0, 5e-17])
    return cols


def test_csv_round_trip_in_spec_order(tmp_path: Path) -> None:
    cols = _frf_columns()
    shuffled = dict(reversed(list(cols.items())))  # dict order must not matter, `order` does
    path = tmp_path / "frf.csv"
    write_csv(path, shuffled, FRF_COLUMNS)
    lines = path.read_text().splitlines()
    assert lines[0] == ",".join(FRF_COLUMNS)
    assert lines[1].split(",")[FRF_COLUMNS.index("stable")] == "true"
    assert lines[2].split(",")[FRF_COLUMNS.index("stable")] == "false"
    assert lines[1].split(",")[FRF_COLUMNS.index("omega")] == "0.1"  # shortest round-trip repr
    back = read_csv(path)
    assert list(back) == list(FRF_COLUMNS)
    assert back["stable"].dtype == bool and back["stable"].tolist() == [True, False, True, False]
    assert back["period"].dtype == np.int64 and back["period"].tolist() == [1, 1, 2, 2]
    assert back["iterations"].tolist() == [3, 2, 5, 1]
    assert back["bifurcation"].tolist() == ["", "fold", "", "period_doubling"]
    assert back["regime"].tolist() == list(cols["regime"])  # type: ignore[call-overload]
    for name in ("omega", "mean", "rms", "p2p"):
        np.testing.assert_array_equal(back[name], cols[name])  # bit-exact
    np.testing.assert_array_equal(back["residual"], [np.nan, np.inf, -0.0, 5e-17])
    assert list(tmp_path.iterdir()) == [path]


def test_csv_quotes_strings_with_commas(tmp_path: Path) -> None:
    path = tmp_path / "x.csv"
    write_csv(path, {"s": ['a,b', 'say "hi"'], "x": [1.5, 2.5]}, ["s", "x"])
    assert read_csv(path)["s"].tolist() == ["a,b", 'say "hi"']


def test_csv_with_no_rows(tmp_path: Path) -> None:
    path = tmp_path / "empty.csv"
    write_csv(path, {name: np.array([]) for name in SWEEP_COLUMNS}, SWEEP_COLUMNS)
    assert path.read_text() == ",".join(SWEEP_COLUMNS) + "\n"
    assert all(v.size == 0 for v in read_csv(path).values())


@pytest.mark.parametrize(
    ("columns", "order", "error", "fragment"),
    [
        ({"a": [1.0]}, ["a", "b"], ValueError, "missing ['b']"),
        ({"a": [1.0], "b": [2.0]}, ["a"], ValueError, "not in `order` ['b']"),
        ({"a": [1.0]}, ["a", "a"], ValueError, "duplicates ['a']"),
        ({"a": [1.0, 2.0], "b": [1.0]}, ["a", "b"], ValueError, "same length"),
        ({"a": np.ones((2, 2))}, ["a"], ValueError, "one-dimensional"),
        ({"a": "abc"}, ["a"], TypeError, "1-D array or list"),
        ({"a": [object()]}, ["a"], TypeError, "cannot write"),
    ],
)
def test_csv_refuses_bad_columns_without_writing(
    tmp_path: Path, columns: dict[str, object], order: list[str], error: type[Exception], fragment: str
) -> None:
    with pytest.raises(error) as info:
        write_csv(tmp_path / "x.csv", columns, order)
    assert fragment in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_format_csv_writes_none_as_empty() -> None:
    assert format_csv({"a": [None, 1], "b": [True, np.bool_(False)]}, ["b", "a"]) == "b,a\ntrue,\nfalse,1\n"


# --------------------------------------------------------------------------------------------
# Metadata
# --------------------------------------------------------------------------------------------
class _Colour(enum.Enum):
    RED = "red"


def test_write_metadata_is_strict_json_with_provenance(tmp_path: Path) -> None:
    path = tmp_path / "frf.json"
    config = tomllib.loads(SPEC_EXAMPLE)
    doc = write_metadata(
        path,
        config=config,
        settings={"harmonics": np.int64(32), "omega": np.array([0.1, 3.0]), "tol": np.float32(0.5)},
        timings={"continuation": 1.25, "bad": float("nan")},
        extra={"path": Path("a/b"), "colour": _Colour.RED, "set": {2, 1}, "z": 1 + 2j,
               "model": reference_case(), "flag": np.bool_(True), "analysis": AnalysisSettings()},
    )

    def refuse(constant: str) -> None:
        raise AssertionError(f"non-standard JSON constant {constant}")

    loaded = json.loads(path.read_text(), parse_constant=refuse)
    assert loaded == doc
    assert loaded["version"] == rattle_version() != ""
    assert loaded["config"] == config
    assert loaded["settings"] == {"harmonics": 32, "omega": [0.1, 3.0], "tol": 0.5}
    assert loaded["timings"] == {"continuation": 1.25, "bad": None}
    assert loaded["extra"]["path"] == os.path.join("a", "b")
    assert loaded["extra"]["colour"] == "red"
    assert loaded["extra"]["set"] == [1, 2]
    assert loaded["extra"]["z"] == [1.0, 2.0]
    assert loaded["extra"]["flag"] is True
    assert loaded["extra"]["model"]["elastic"] == {"type": "clutch", "alpha": 0.25, "b": math.radians(10)}
    assert loaded["extra"]["analysis"] == {"omega": [0.1, 3.0], "harmonics": 32}
    created = dt.datetime.fromisoformat(loaded["created"])
    assert created.utcoffset() == dt.timedelta(0)
    assert abs((dt.datetime.now(dt.timezone.utc) - created).total_seconds()) < 60
    env = loaded["environment"]
    assert env["numpy"] == np.__version__
    assert {"python", "scipy", "platform"} <= set(env)
    assert [p.name for p in tmp_path.iterdir()] == ["frf.json"]


def test_metadata_sections_may_replace_defaults() -> None:
    doc = metadata_document(version="9.9", environment={"custom": 1})
    assert doc["version"] == "9.9" and doc["environment"] == {"custom": 1}


def test_to_jsonable_falls_back_to_repr() -> None:
    class Opaque:
        def __repr__(self) -> str:
            return "<opaque>"

    assert to_jsonable({"o": Opaque(), 1: (np.float64(-np.inf),)}) == {"o": "<opaque>", "1": [None]}
