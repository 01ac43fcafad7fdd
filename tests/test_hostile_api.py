"""Hostile input at the library front ends and in configuration values: every bad argument is
refused before any work with the right exception type and a message naming the argument (or
the file key) in backticks; numpy scalars and extreme-but-valid models are accepted.

The rules are shared (``rattle._limits``, ``rattle._validate``): the same value is refused or
accepted alike from a file, from the command line and from Python.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle import (
    Backlash, Clutch, ConfigError, ContinuationOptions, ConvergenceError, Excitation, HBOptions, Model,
    NewtonOptions, SteadyStateOptions, reference_case,
)
from rattle import _limits
from rattle.analysis._harmonics import adaptive_frequency_response, truncation_error
from rattle.io import config_from_dict, load_config
from rattle.analysis import steady_state
from _cases import clutch_toml  # tests/_cases.py (tests/ is on sys.path through its conftest)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

REF = reference_case()
NARROW = (0.5, 0.52)  # a short stretch of the reference branch without special points: fast


def _model(**kw) -> Model:
    base = dict(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Clutch(alpha=0.25, b=0.174533),
                excitation=Excitation(mean=0.05, amplitudes=(0.03,)))
    base.update(kw)
    return Model(**base)


UNDAMPED = _model(damping=0.0)  # a valid Model (exact integration of undamped motion is allowed)

# --------------------------------------------------------------------------------------------
# Library front ends: (call, error type, fragments of the message)
# --------------------------------------------------------------------------------------------
fr = rattle.frequency_response
API_CASES = [
    # model
    ("frequency_response(None)", lambda: fr(None), TypeError, ["`model` must be a rattle Model", "None"]),
    ("model as a string", lambda: fr("reference"), TypeError, ["`model`"]),
    ("time_sweep(None)", lambda: rattle.time_sweep(None), TypeError, ["`model`"]),
    ("periodic_orbit(None)", lambda: rattle.periodic_orbit(None, 0.8), TypeError, ["`model`"]),
    ("compare(None)", lambda: rattle.compare(None), TypeError, ["`model`"]),
    # harmonics
    ("harmonics string", lambda: fr(REF, harmonics="8"), TypeError, ["`harmonics` must be an integer", "'8'"]),
    ("harmonics bool", lambda: fr(REF, harmonics=True), TypeError, ["`harmonics`", "bool"]),
    ("harmonics float", lambda: fr(REF, harmonics=8.0), TypeError, ["`harmonics`", "float"]),
    ("harmonics None", lambda: fr(REF, harmonics=None), TypeError, ["`harmonics`"]),
    ("harmonics huge int", lambda: fr(REF, harmonics=99999999999999999999), ValueError,
     ["`harmonics` must be <= 256, got 99999999999999999999", "H²"]),
    ("harmonics 10000", lambda: fr(REF, harmonics=10000), ValueError, ["`harmonics` must be <= 256", "got 10000"]),
    ("harmonics numpy too large", lambda: fr(REF, harmonics=np.int64(300)), ValueError, ["`harmonics` must be <= 256"]),
    ("harmonics zero", lambda: fr(REF, harmonics=0), ValueError, ["`harmonics` must be an integer >= 1"]),
    ("harmonics x max_period", lambda: fr(REF, harmonics=256, subharmonics=True), ValueError,
     ["`harmonics` must be <= 128 for branches of period 4"]),
    ("hb.harmonics too large", lambda: fr(REF, hb=HBOptions(harmonics=300)), ValueError, ["`hb.harmonics` must be <= 256"]),
    ("samples too large", lambda: fr(REF, harmonics=8, samples=10**6), ValueError, ["`samples` must be <= 16384"]),
    ("samples float", lambda: fr(REF, harmonics=8, samples=1024.0), TypeError, ["`samples`"]),
    # frequency range
    ("omega nan", lambda: fr(REF, omega=(0.1, math.nan)), ValueError, ["`omega` must be finite"]),
    ("omega inf", lambda: fr(REF, omega=(0.1, math.inf)), ValueError, ["`omega` must be finite"]),
    ("omega string", lambda: fr(REF, omega="0.1 3.0"), TypeError, ["`omega` must be a pair"]),
    ("omega of strings", lambda: fr(REF, omega=("0.1", "3")), TypeError, ["`omega`"]),
    ("omega bool", lambda: fr(REF, omega=(True, 3.0)), TypeError, ["`omega`"]),
    ("omega three values", lambda: fr(REF, omega=(0.1, 1.0, 3.0)), ValueError, ["`omega` must be a pair", "3 values"]),
    ("omega negative", lambda: fr(REF, omega=(-1.0, 3.0)), ValueError, ["`omega` must satisfy 0 < min < max"]),
    ("omega far below the stage", lambda: fr(REF, omega=(np.float64(1e-6), 3.0)), ValueError,
     ["`omega` must be >= 0.001 rad/s", "got 1e-06"]),
    ("omega far above the stage", lambda: fr(REF, omega=(0.1, 1e5)), ValueError, ["`omega` must be <= 1000 rad/s"]),
    # other arguments
    ("subharmonics string", lambda: fr(REF, subharmonics="yes"), TypeError, ["`subharmonics` must be True or False"]),
    ("max_period 9", lambda: fr(REF, max_period=9), ValueError, ["`max_period` must be an integer 1 … 8"]),
    ("start unknown", lambda: fr(REF, start="middle"), ValueError, ["`start` must be one of 'low', 'high', 'both'"]),
    ("stability unknown", lambda: fr(REF, stability="floquet"), ValueError, ["`stability` must be 'monodromy' or 'hill'"]),
    ("newton as dict", lambda: fr(REF, newton={"residual_tol": 1e-9}), TypeError, ["`newton` must be a NewtonOptions"]),
    ("continuation as dict", lambda: fr(REF, continuation={}), TypeError, ["`continuation`"]),
    ("callback not callable", lambda: fr(REF, callback=5), TypeError, ["`callback` must be callable"]),
    ("unknown keyword", lambda: fr(REF, harmonic=8), TypeError, ["harmonic"]),
    ("unknown keyword (sweep)", lambda: rattle.time_sweep(REF, tolerance=1e-6), TypeError, ["tolerance"]),
    # periodic_orbit
    ("orbit omega 1e-6", lambda: rattle.periodic_orbit(REF, 1e-6), ValueError, ["`omega` must be >= 0.001 rad/s"]),
    ("orbit omega string", lambda: rattle.periodic_orbit(REF, "0.8"), TypeError, ["`omega`"]),
    ("orbit omega nan", lambda: rattle.periodic_orbit(REF, math.nan), ValueError, ["`omega`"]),
    ("orbit period 9", lambda: rattle.periodic_orbit(REF, 0.8, period=np.int64(9)), ValueError, ["`period`"]),
    ("orbit simulate int", lambda: rattle.periodic_orbit(REF, 0.8, simulate=1), TypeError, ["`simulate`"]),
    ("orbit x0 nan", lambda: rattle.periodic_orbit(REF, 0.8, x0=(math.nan, 0.0)), ValueError, ["`x0`"]),
    ("orbit x0 string", lambda: rattle.periodic_orbit(REF, 0.8, x0="0 0"), TypeError, ["`x0`"]),
    ("orbit search range too low", lambda: rattle.periodic_orbit(REF, 0.8, search_range=(1e-9, 3.0)), ValueError,
     ["`search_range`"]),
    # time_sweep, compare, steady_state
    ("sweep points 1e9", lambda: rattle.time_sweep(REF, points=1_000_000_000), ValueError,
     ["`points` must be <= 100000"]),
    ("sweep points float", lambda: rattle.time_sweep(REF, points=np.float64(3)), TypeError, ["`points`"]),
    ("sweep workers huge", lambda: rattle.time_sweep(REF, workers=10**6), ValueError, ["`workers` must be <= 64"]),
    ("sweep omega too low", lambda: rattle.time_sweep(REF, omega=(1e-7, 1.0)), ValueError, ["`omega` must be >= 0.001"]),
    ("compare points 1e9", lambda: rattle.compare(REF, points=10**9), ValueError, ["`points` must be <= 100000"]),
    ("compare at strings", lambda: rattle.compare(REF, at=["0.5"]), TypeError, ["`at` must hold numbers"]),
    ("compare harmonics 512", lambda: rattle.compare(REF, harmonics=512), ValueError, ["`harmonics` must be <= 256"]),
    ("steady_state omega 1e-6", lambda: steady_state(REF, 1e-6, (0.0, 0.0)), ValueError, ["`omega` must be >= 0.001"]),
    ("adaptive max_harmonics", lambda: adaptive_frequency_response(REF, max_harmonics=1024), ValueError,
     ["`max_harmonics` must be <= 256"]),
    ("adaptive tolerance string", lambda: adaptive_frequency_response(REF, tolerance="1e-3"), TypeError, ["`tolerance`"]),
    ("truncation_error(None)", lambda: truncation_error(None), TypeError, ["`frf` must be a FrequencyResponse"]),
    # zero damping, at every analysis
    ("zero damping frf", lambda: fr(UNDAMPED), ValueError, ["`model.damping` must be > 0", "small positive damping"]),
    ("zero damping orbit", lambda: rattle.periodic_orbit(UNDAMPED, 0.8), ValueError, ["`model.damping`"]),
    ("zero damping sweep", lambda: rattle.time_sweep(UNDAMPED), ValueError, ["`model.damping`"]),
    ("zero damping compare", lambda: rattle.compare(UNDAMPED), ValueError, ["`model.damping`"]),
    ("zero damping steady", lambda: steady_state(UNDAMPED, 0.8, (0.0, 0.0)), ValueError, ["`model.damping`"]),
    # an overdamped model: the harmonic balance works (below), a simulation would take hours
    ("overdamped simulation", lambda: rattle.time_sweep(_model(damping=1e6)), ValueError,
     ["`omega` must be >= 6283 rad/s for a simulation", "C/I"]),
    # option objects
    ("HBOptions string", lambda: HBOptions(harmonics="8"), TypeError, ["`harmonics`"]),
    ("HBOptions too large", lambda: HBOptions(harmonics=5000), ValueError, ["`harmonics` must be <= 1024"]),
    ("HBOptions samples", lambda: HBOptions(harmonics=8, samples=10**7), ValueError, ["`samples` must be <= 32768"]),
    ("NewtonOptions nan", lambda: NewtonOptions(residual_tol=math.nan), ValueError, ["`residual_tol`"]),
    ("NewtonOptions bool", lambda: NewtonOptions(max_iterations=True), TypeError, ["`max_iterations`"]),
    ("NewtonOptions huge", lambda: NewtonOptions(max_iterations=10**9), ValueError, ["`max_iterations` must be <= 1000"]),
    ("ContinuationOptions max_points", lambda: ContinuationOptions(max_points=10**9), ValueError,
     ["`max_points` must be <= 1000000"]),
    ("SteadyStateOptions max_periods", lambda: SteadyStateOptions(max_periods=10**9), ValueError,
     ["`max_periods` must be <= 100000"]),
    ("SteadyStateOptions period 9", lambda: SteadyStateOptions(max_period_multiple=9), ValueError,
     ["`max_period_multiple`"]),
    # model values
    ("inertia string", lambda: _model(inertia="1.0"), TypeError, ["`inertia` must be a real number"]),
    ("damping bool", lambda: _model(damping=True), TypeError, ["`damping`"]),
    ("mean 1e300", lambda: Excitation(mean=1e300, amplitudes=(0.03,)), ValueError,
     ["`mean` must have magnitude <= 1e+50", "overflow"]),
    ("stiffness beyond float", lambda: _model(stiffness=10**400), ValueError, ["`stiffness`", "401 digits"]),
    ("inertia tiny: K/I overflows", lambda: _model(inertia=1e-60), ValueError, ["`stiffness` / `inertia`", "K/I"]),
    ("b nan", lambda: Backlash(b=math.nan), ValueError, ["`b` must be finite"]),
    ("alpha bool", lambda: Clutch(alpha=True, b=0.1), TypeError, ["`alpha`"]),
    ("too many amplitudes", lambda: Excitation(mean=0.0, amplitudes=[0.01] * 1000), ValueError,
     ["`amplitudes` must hold at most 256"]),
]


@pytest.mark.parametrize(("call", "error", "fragments"), [c[1:] for c in API_CASES], ids=[c[0] for c in API_CASES])
def test_api_refuses_hostile_input(call, error, fragments) -> None:
    with pytest.raises(error) as info:
        call()
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    assert not isinstance(info.value, ConvergenceError)  # refused, not attempted


def test_numpy_scalars_are_accepted_everywhere() -> None:
    """`harmonics=np.int64(8)` used to be refused by the API while a file accepted it."""
    frf = fr(REF, omega=(np.float64(NARROW[0]), np.float32(NARROW[1])), harmonics=np.int64(8),
             continuation=ContinuationOptions(max_points=np.int64(200)), newton=NewtonOptions(max_iterations=np.int32(12)))
    assert len(frf) > 2 and frf.status.success
    assert HBOptions(harmonics=np.int64(8), samples=np.int32(64)) == HBOptions(harmonics=8, samples=64)
    assert type(HBOptions(harmonics=np.int64(8)).harmonics) is int
    model = _model(inertia=np.float32(2.0), damping=np.float64(0.05), stiffness=np.int64(2))
    assert model.inertia == 2.0 and type(model.stiffness) is float
    assert SteadyStateOptions(max_periods=np.int64(100)).max_periods == 100


def test_extreme_but_valid_models_are_accepted() -> None:
    """Scales far from 1 in either direction, and heavy damping, are not refused by the harmonic
    balance (a heavily overdamped model is refused only for a simulation, see above)."""
    for model in (
        _model(inertia=1e-40, stiffness=1e-40, damping=5e-42),
        _model(inertia=1e40, stiffness=1e40, damping=5e38),
        _model(damping=1e6),
    ):
        ws = _limits.stiffest_frequency(model)
        frf = fr(model, omega=(0.5 * ws, 0.52 * ws), harmonics=8, throw=False)
        assert len(frf) > 2 and np.all(np.isfinite(frf.rms))


def test_clearance_in_degrees_warns() -> None:
    with pytest.warns(UserWarning, match=r"`b` = 10 rad is 573°: clearances are in radians .* write 0.174533") as rec:
        Backlash(b=10)
    assert rec[0].filename == __file__  # stacklevel: the warning points at the caller
    with pytest.warns(UserWarning, match=r"`b` = 10 rad"):
        Clutch(alpha=0.25, b=10.0)
    with pytest.warns(UserWarning, match=r"`breakpoints\[1\]` = 5 rad"):  # the Python API: positions from 0
        rattle.Piecewise(breakpoints=(-0.1, 5.0), slopes=(1.0, 0.2, 1.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Backlash(b=_limits.CLEARANCE_WARNING)  # pi/2 itself and below: no warning
        Clutch(alpha=0.25, b=0.174533)


def test_numerical_failure_is_a_convergence_error(monkeypatch) -> None:
    """Should values beyond double precision appear despite the bounds, the front end raises a
    ConvergenceError that says so, not a raw OverflowError."""
    import rattle.analysis._frequency_response as module

    def overflow(*args, **kwargs):
        raise OverflowError("(34, 'Numerical result out of range')")

    monkeypatch.setattr(module, "_frequency_response", overflow)
    with pytest.raises(ConvergenceError, match=r"numerical failure in frequency_response: .*OverflowError"):
        fr(REF, omega=NARROW, harmonics=8)


def test_refusals_come_before_any_work(monkeypatch) -> None:
    """`orbit --omega 1e-6` took 314 s: the check must fire before anything is computed."""
    import rattle.analysis._orbit as orbit_module
    import rattle.analysis._time_sweep as sweep_module

    def forbidden(*args, **kwargs):  # pragma: no cover - reached only if the check is missing
        raise AssertionError("work started before the arguments were checked")

    monkeypatch.setattr(orbit_module, "frequency_response", forbidden)
    monkeypatch.setattr(orbit_module, "_Solver", forbidden)
    with pytest.raises(ValueError, match=r"`omega` must be >= 0.001"):
        rattle.periodic_orbit(REF, 1e-6)
    monkeypatch.setattr(sweep_module, "np", None)  # the grid is never built
    with pytest.raises(ValueError, match=r"`points` must be <= 100000"):
        rattle.time_sweep(REF, points=1_000_000_000)


# --------------------------------------------------------------------------------------------
# Configuration values: the same rules, with the file's key names
# --------------------------------------------------------------------------------------------
VALID = clutch_toml((0.1, 3.0), 32)

FILE_CASES = [
    ("harmonics huge int", "harmonics = 32", "harmonics = 99999999999999999999",
     ["`analysis.harmonics` must be <= 256, got 99999999999999999999"]),
    ("harmonics 10000", "harmonics = 32", "harmonics = 10000", ["`analysis.harmonics` must be <= 256"]),
    ("zero damping", "damping = 0.05", "damping = 0.0", ["`model.damping` must be > 0", "small positive damping"]),
    ("mean 1e300", "mean = 0.05", "mean = 1e300", ["`excitation.mean` must have magnitude <= 1e+50"]),
    ("amplitude 1e300", "amplitudes = [0.03]", "amplitudes = [1e300]", ["`excitation.amplitudes.1`"]),
    ("stiffness beyond float", "stiffness = 1.0", "stiffness = " + "9" * 400, ["`model.stiffness`", "400 digits"]),
    ("K/I overflows", "inertia = 1.0", "inertia = 1e-60", ["`model.stiffness` / `model.inertia`"]),
    ("omega far below", "omega = [0.1, 3.0]", "omega = [1e-6, 3.0]", ["`analysis.omega.1` must be >= 0.001"]),
    ("omega far above", "omega = [0.1, 3.0]", "omega = [0.1, 1e6]", ["`analysis.omega.2` must be <= 1000"]),
    ("too many amplitudes", "amplitudes = [0.03]", "amplitudes = [" + ", ".join(["0.001"] * 300) + "]",
     ["`excitation.amplitudes` must hold at most 256"]),
]


@pytest.mark.parametrize(("old", "new", "fragments"), [c[1:] for c in FILE_CASES], ids=[c[0] for c in FILE_CASES])
def test_config_refuses_hostile_values(old: str, new: str, fragments: list[str]) -> None:
    text = VALID.replace(old, new)
    assert text != VALID
    with pytest.raises(ConfigError) as info:
        config_from_dict(tomllib.loads(text), "case.toml")
    message = str(info.value)
    assert message.startswith("case.toml: ")
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_config_file_with_huge_harmonics(tmp_path: Path) -> None:
    """`harmonics = 99999999999999999999` in a file used to end in a traceback."""
    path = tmp_path / "case.toml"
    path.write_text(VALID.replace("harmonics = 32", "harmonics = 99999999999999999999"), encoding="utf-8")
    with pytest.raises(ConfigError, match=r"`analysis.harmonics` must be <= 256"):
        load_config(path)


def test_config_override_shares_the_rule() -> None:
    """`--harmonics 10000` on top of a valid file: the override is checked by the same rule."""
    config = config_from_dict(tomllib.loads(VALID))
    with pytest.raises(ValueError, match=r"`harmonics` must be <= 256, got 10000"):
        dataclasses.replace(config.analysis, harmonics=10000)
    assert dataclasses.replace(config.analysis, harmonics=np.int64(64)).harmonics == 64


def test_config_accepts_what_the_api_accepts() -> None:
    data = tomllib.loads(VALID)
    data["analysis"]["harmonics"] = np.int64(8)
    data["model"]["inertia"] = np.float64(1.0)
    config = config_from_dict(data)
    assert config.analysis.harmonics == 8 and type(config.analysis.harmonics) is int


def test_config_clearance_in_degrees_warns_with_the_key() -> None:
    with pytest.warns(UserWarning, match=r"case.toml: `model.elastic.b` = 10 rad is 573°"):
        config = config_from_dict(tomllib.loads(VALID.replace("b = 0.174533", "b = 10")), "case.toml")
    assert config.model.elastic.b == 10.0  # a warning, not a refusal


# --------------------------------------------------------------------------------------------
# The command line routes the same rules (exit 2, one line, nothing written)
# --------------------------------------------------------------------------------------------
CLI_CASES = [
    ("frf --harmonics 10000", ["frf", "case.toml", "-o", "out", "--harmonics", "10000"], VALID,
     ["`--harmonics` must be <= 256"]),
    ("sweep --points 1e9", ["sweep", "case.toml", "-o", "out", "--direction", "up", "--points", "1000000000"], VALID,
     ["`--points` must be <= 100000"]),
    ("orbit --omega 1e-6", ["orbit", "case.toml", "-o", "out", "--omega", "1e-6"], VALID,
     ["`--omega` must be >= 0.001"]),
    ("frf mean = 1e300", ["frf", "case.toml", "-o", "out"], VALID.replace("mean = 0.05", "mean = 1e300"),
     ["`excitation.mean`"]),
    ("frf damping = 0", ["frf", "case.toml", "-o", "out"], VALID.replace("damping = 0.05", "damping = 0.0"),
     ["`model.damping`"]),
    ("frf huge harmonics in file", ["frf", "case.toml", "-o", "out"],
     VALID.replace("harmonics = 32", "harmonics = 99999999999999999999"), ["`analysis.harmonics` must be <= 256"]),
]


@pytest.mark.parametrize(("args", "text", "fragments"), [c[1:] for c in CLI_CASES], ids=[c[0] for c in CLI_CASES])
def test_cli_refuses_with_the_shared_rules(tmp_path: Path, args, text, fragments) -> None:
    from _cli_helpers import assert_bad_input, invoke
    (tmp_path / "case.toml").write_text(text, encoding="utf-8")
    result = invoke(args, tmp_path)
    assert_bad_input(result, *fragments)
    assert not (tmp_path / "out").exists()
