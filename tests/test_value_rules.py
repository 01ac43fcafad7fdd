"""Values accepted that should not be, and errors that did not name the argument (issue 29): every
case is refused with TypeError/ValueError (or ConfigError) naming the argument or key in
backticks and showing the value received; from the command line the same is one line, exit 2,
nothing written."""

from __future__ import annotations

import os
import math
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle import Backlash, Clutch, ConfigError, Piecewise, reference_case
from rattle.model import SoundPath

from _cases import clutch_toml  # tests/_cases.py (tests/ is on sys.path through its conftest)
from _cli_helpers import assert_bad_input, invoke  # type: ignore[import-not-found]  # tests/cli, via conftest

REF = reference_case()
FAST = clutch_toml((0.5, 0.8), 8)

CHAIN = """\
[model]
inertias = [2.0, 2.0]

[[model.links]]
between = [1, 2]
stiffness = 0.0
damping = 0.05

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 1.0
type = "clutch"
alpha = 0.25
b = 0.174533

[excitation]
torques = []

[analysis]
omega = [0.5, 0.8]
harmonics = 8
"""


# --------------------------------------------------------------------------------------------
# Path tables: finite and physical
# --------------------------------------------------------------------------------------------
def _path(**kw: object) -> SoundPath:
    args: dict[str, object] = dict(source="delta", frequency_hz=[1.0, 100.0], magnitude=[0.1, 0.2],
                                   phase_deg=[0.0, 10.0])
    args.update(kw)
    return SoundPath(**args)  # type: ignore[arg-type]


@pytest.mark.parametrize(("kw", "fragments"), [
    ({"magnitude": [0.1, 1e300]}, ["`magnitude` must be <= 1e+50", "got 1e+300 at row 1"]),
    ({"magnitude": [0.1, 1e51]}, ["`magnitude` must be <= 1e+50", "got 1e+51 at row 1"]),
    ({"magnitude": [-0.1, 0.2]}, ["`magnitude` must be >= 0", "got -0.1 at row 0"]),
    ({"phase_deg": [0.0, 1e300]}, ["`phase_deg` must lie within ±1e+06 degrees", "got 1e+300 at row 1"]),
    ({"phase_deg": [-2e6, 0.0]}, ["`phase_deg`", "got -2000000.0 at row 0"]),
    ({"magnitude": [0.1, math.inf]}, ["`magnitude` must hold finite numbers"]),
])
def test_a_path_table_is_finite_and_physical(kw: dict[str, object], fragments: list[str]) -> None:
    with pytest.raises(ValueError) as info:
        _path(**kw)
    for fragment in fragments:
        assert fragment in str(info.value)


def test_a_path_table_at_the_bounds_is_accepted() -> None:
    path = _path(magnitude=[0.0, 1e50], phase_deg=[-1e6, 36000.0])
    assert abs(path.response(100.0)) == pytest.approx(1e50)


@pytest.mark.parametrize(("row", "fragments"), [
    ("100,1e300,0", ["`paths[0].file` ('path.csv') line 3: `magnitude` must be <= 1e+50", "got 1e+300"]),
    ("100,0.2,1e300", ["`paths[0].file` ('path.csv') line 3: `phase_deg` must lie within", "got 1e+300"]),
    ("100,-0.2,0", ["line 3: `magnitude` must be >= 0", "got -0.2"]),
])
def test_a_path_file_with_an_unphysical_value_is_refused(tmp_path: Path, row: str, fragments: list[str]) -> None:
    (tmp_path / "path.csv").write_text(f"frequency_hz,magnitude,phase_deg\n1,0.1,0\n{row}\n", encoding="utf-8")
    (tmp_path / "case.toml").write_text(FAST + '\n[[paths]]\nsource = "delta"\nfile = "path.csv"\n', encoding="utf-8")
    before = sorted(os.listdir(tmp_path))
    assert_bad_input(invoke(["frf", "case.toml", "-o", "out"], tmp_path), *fragments)
    assert sorted(os.listdir(tmp_path)) == before
    with pytest.raises(ConfigError, match="`magnitude`|`phase_deg`"):  # the same rule for the library
        rattle.load_case(tmp_path / "case.toml")


# --------------------------------------------------------------------------------------------
# A chain's torques: required, and not empty
# --------------------------------------------------------------------------------------------
def test_a_chain_with_torques_empty_is_refused(tmp_path: Path) -> None:
    (tmp_path / "chain.toml").write_text(CHAIN, encoding="utf-8")
    assert_bad_input(invoke(["frf", "chain.toml", "-o", "out"], tmp_path),
                     "`excitation.torques` must hold at least one torque, got none (torques = [])")
    assert sorted(os.listdir(tmp_path)) == ["chain.toml"]
    with pytest.raises(ConfigError, match=r"`excitation\.torques` must hold at least one torque"):
        rattle.load_case(tmp_path / "chain.toml")


def test_a_chain_with_one_torque_is_accepted(tmp_path: Path) -> None:
    text = CHAIN.replace("[excitation]\ntorques = []\n",
                         "[[excitation.torques]]\ninertia = 1\nmean = 0.05\namplitudes = [0.06]\n\n"
                         "[[excitation.torques]]\ninertia = 2\nmean = -0.05\n")
    (tmp_path / "chain.toml").write_text(text, encoding="utf-8")
    assert len(rattle.load_case(tmp_path / "chain.toml").model.torques) == 2


# --------------------------------------------------------------------------------------------
# Types the docs promise
# --------------------------------------------------------------------------------------------
def test_a_set_of_frequencies_is_refused() -> None:
    with pytest.raises(TypeError, match=r"`omega` must be a pair \(min, max\).*\{0\.5, 0\.8\}"):
        rattle.frequency_response(REF, omega={0.5, 0.8}, harmonics=4)


@pytest.mark.parametrize(("vary", "error", "fragments"), [
    ({"alpha": "0.2"}, TypeError, ["`vary['alpha']`", "got '0.2' (str)"]),
    ({"alpha": ["0.2", "0.3"]}, TypeError, ["`vary['alpha']` must hold real numbers", "'0.2'"]),
    ({"alpha": [0.2, None]}, TypeError, ["`vary['alpha']`", "None"]),
    ({"alpha": [True, 0.2]}, TypeError, ["`vary['alpha']`", "True"]),
    ({"alpha": {0.2, 0.3}}, TypeError, ["`vary['alpha']`", "set"]),
    ({"alpha": None}, TypeError, ["`vary['alpha']`", "None"]),
    ({"alpha": np.array(["0.2"])}, TypeError, ["`vary['alpha']`", "dtype"]),
    (None, TypeError, ["`vary` must be a mapping", "got None"]),
    ("alpha=0.2:0.3:2", TypeError, ["`vary` must be a mapping", "'alpha=0.2:0.3:2'"]),
    (7, TypeError, ["`vary`", "got 7"]),
    ([("alpha",)], TypeError, ["`vary` must hold (NAME, values) pairs", "('alpha',)"]),
    ({1: [0.2]}, TypeError, ["`vary` names must be strings", "got 1"]),
    ({}, ConfigError, ["`--vary` is required"]),
])
def test_response_map_refuses_what_vary_cannot_be(vary: object, error: type[Exception], fragments: list[str]) -> None:
    with pytest.raises(error) as info:
        rattle.response_map(REF, vary=vary, omega=(0.5, 0.6), omega_points=3, harmonics=4, workers=1)  # type: ignore[arg-type]
    for fragment in fragments:
        assert fragment in str(info.value), (fragment, str(info.value))


@pytest.mark.parametrize("values", [[0.2, 0.3], (0.2,), 0.2, np.array([0.2, 0.3]), np.float32(0.2), range(1, 2)])
def test_vary_values_that_are_numbers_are_accepted(values: object) -> None:
    from rattle.maps import parameters

    tables = rattle.io.model_to_toml_dict(REF, rattle.io.AnalysisSettings())
    name = "alpha" if not isinstance(values, range) else "amplitude"
    (param,) = parameters(tables, {name: values})
    assert all(isinstance(v, float) for v in param.values)


def test_the_map_progress_callback_is_named() -> None:
    with pytest.raises(TypeError, match=r"`progress` must be a callable .* got 'x'"):
        rattle.response_map(REF, vary={"alpha": [0.2]}, omega=(0.5, 0.6), omega_points=3, harmonics=4, workers=1,
                            progress="x")  # type: ignore[arg-type]


# --------------------------------------------------------------------------------------------
# Errors that name the argument
# --------------------------------------------------------------------------------------------
LAWS = [Clutch(alpha=0.25, b=0.1), Backlash(b=0.1), Piecewise(breakpoints=(-0.1, 0.1), slopes=(1.0, 0.2, 1.0))]


@pytest.mark.parametrize("law", LAWS, ids=lambda law: type(law).__name__)
@pytest.mark.parametrize("method", ["force", "stiffness", "force_and_stiffness", "stage"])
@pytest.mark.parametrize(("value", "shown"), [
    ("x", "'x' (str)"), (None, "None (NoneType)"), (True, "True (bool)"), ([0.1, "a"], "[0.1, 'a']"),
    ([0.1, None], "[0.1, None]"), (np.array([True, False]), "array([ True, False])"), (b"0.1", "b'0.1'"),
])
def test_a_law_names_delta(law: object, method: str, value: object, shown: str) -> None:
    with pytest.raises(TypeError) as info:
        getattr(law, method)(value)
    assert str(info.value).startswith("`delta` must be a deflection in rad"), str(info.value)
    assert shown in str(info.value)


@pytest.mark.parametrize("law", LAWS, ids=lambda law: type(law).__name__)
def test_a_law_takes_numbers_and_arrays_as_before(law: object) -> None:
    x = np.linspace(-0.3, 0.3, 7)
    f = law.force(x)  # type: ignore[attr-defined]
    assert np.array_equal(law.force(list(x)), f)  # type: ignore[attr-defined]
    assert law.force(np.float32(0.2)) == pytest.approx(law.force(0.2))  # type: ignore[attr-defined]
    assert law.force(np.int64(1)) == law.force(1.0)  # type: ignore[attr-defined]
    assert np.array_equal(law.stiffness(np.arange(-2, 3)), law.stiffness(np.arange(-2.0, 3.0)))  # type: ignore[attr-defined]


def test_a_discontinuous_law_names_delta() -> None:
    from rattle.model import Preload

    with pytest.raises(TypeError, match=r"`delta` must be a deflection in rad.*None"):
        Preload(preload=0.03).force(None)


@pytest.mark.parametrize("call", [
    lambda: rattle.load_case(None), lambda: rattle.Model.from_toml(None), lambda: rattle.Chain.from_toml(None),
    lambda: rattle.io.load_config(None), lambda: rattle.Model.from_toml(3),
], ids=["load_case", "Model.from_toml", "Chain.from_toml", "load_config", "from_toml(3)"])
def test_a_file_argument_that_is_no_path_is_named(call) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(TypeError, match=r"`path` must be the path of a TOML configuration file .* got (None|3)"):
        call()


def test_to_csv_without_a_path_is_named() -> None:
    frf = rattle.frequency_response(REF, omega=(0.5, 0.52), harmonics=8)
    with pytest.raises(TypeError, match=r"`path` must be a str or os.PathLike, got NoneType None"):
        frf.to_csv(None)  # type: ignore[arg-type]
