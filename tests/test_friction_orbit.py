"""One periodic orbit of a chain with Coulomb friction: :func:`rattle.analysis.friction_orbit`,
:class:`rattle.results.FrictionOrbitResult` and ``rattle orbit`` on such a chain.

examples/chain_clutch_friction.toml (3 inertias, a four-stage clutch damper with friction on every
stage) at Ω = 0.85 rad/s: the damper sticks once per period (1.8 % of it); the HB (H = 32,
ε = 0.001) rms is within 0.5 % of the exact one (measured 2.1e-5). The 3-inertia chain of
tests/test_friction_response.py at Ω = 3.0: the clutch sticks the whole period (a family of exact
orbits, the member at the HB's mean deflection held).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from _cases import clutch_gear_chain  # tests/ is on sys.path through its conftest

import rattle.analysis._friction_orbit as friction_orbit_module
from rattle.analysis import RegularisationOptions, friction_orbit
from rattle.errors import ConvergenceError, Status
from rattle.io import load_config, read_csv
from rattle.model import System
from rattle.results import FRICTION_ORBIT_ELEMENT_COLUMNS, FrictionOrbitResult
from rattle.timeint import shoot_friction_orbit

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "chain_clutch_friction.toml"
OMEGA = 0.85
OPTIONS = RegularisationOptions(harmonics=32, regularisation=0.001)
#: The HB's rms against the exact orbit's where the damper sticks briefly (measured 2.1e-5).
HB_TOLERANCE = 0.005


@pytest.fixture(scope="module")
def system() -> System:
    fs = load_config(EXAMPLE).model
    assert fs.discontinuous
    return fs


@pytest.fixture(scope="module")
def result(system: System) -> FrictionOrbitResult:
    return friction_orbit(system, OMEGA, OPTIONS, every=False)


def _three_inertias() -> System:
    return clutch_gear_chain().friction_system()


def test_the_exact_orbit_is_the_independent_shooting_from_rest(system, result):
    assert result.converged and result.status is Status.CONVERGED and result.start == "hb"
    assert result.hb_start == "linear" and result.message == ""
    orbit = shoot_friction_orbit(system, OMEGA, np.zeros(2 * system.n))
    assert orbit.converged
    assert abs(float(orbit.rms[0]) - float(result.rms[0])) <= 1e-9
    assert abs(float(orbit.mean[0]) - float(result.mean[0])) <= 1e-9
    assert abs(float(orbit.stick_fraction[0]) - float(result.stick_fraction[0])) <= 1e-9
    np.testing.assert_allclose(np.abs(result.multipliers), np.abs(orbit.multipliers), atol=1e-8)
    assert result.stable is bool(np.max(np.abs(orbit.multipliers)) < 1.0)
    assert result.element_names == ("clutch",) and result.speed_rpm is None


def test_the_hb_rms_is_within_half_a_percent_and_the_orbits_match(result):
    assert abs(result.rms_error) <= HB_TOLERANCE
    assert result.rms_error == pytest.approx(float(result.rms_hb[0] / result.rms[0] - 1.0), rel=1e-12)
    assert result.matched and result.match_distance <= 0.1
    assert result.regularisation == 0.001 and result.harmonics == 32
    assert result.coefficients_hb.shape == (1, 65)
    # the HB samples are the series': rms over the period sampled on the uniform part of t
    np.testing.assert_allclose(result.sample_hb(result.t), result.delta_hb, atol=1e-12)
    assert result.stable_hb is True and result.stable is True
    # the HB orbit's multipliers by the non-smooth monodromy of the flow from its state (default) and
    # by the regularised chain's monodromy along it: both within 1e-3 of the exact max |μ| here
    mu = result.mu_abs
    assert abs(float(np.max(np.abs(result.multipliers_hb))) - mu) <= 1e-3


def test_the_hb_multipliers_by_the_regularised_monodromy(system, result):
    opts = RegularisationOptions(harmonics=32, regularisation=0.001, stability="regularised")
    r = friction_orbit(system, OMEGA, opts, every=False)
    assert abs(float(r.rms[0]) - float(result.rms[0])) <= 1e-9
    assert abs(float(np.max(np.abs(r.multipliers_hb))) - result.mu_abs) <= 1e-3
    assert not np.allclose(r.multipliers_hb, result.multipliers_hb)


def test_the_damper_sticks_and_its_stick_phases_are_exact(result):
    T = result.period
    phases = result.stick_intervals[0]
    assert len(phases) >= 1 and 0.005 < result.stick_fraction[0] < 0.1  # measured 1.8 %
    assert sum(b - a for a, b in phases) / T == pytest.approx(float(result.stick_fraction[0]), rel=1e-9)
    stuck = result.stuck[:, 0]
    assert stuck.any() and not stuck.all()
    # while stuck the twist rate is zero and the twist constant
    assert np.max(np.abs(result.velocity[stuck, 0])) <= 1e-9 * np.max(np.abs(result.velocity[:, 0]))
    for a, b in phases:
        inside = (result.t > a) & (result.t < b)
        assert np.all(stuck[inside])
        assert np.ptp(result.delta[inside, 0]) <= 1e-9 * result.rms[0] if inside.any() else True
    assert result.t[0] == 0.0 and result.t[-1] == pytest.approx(T, rel=1e-15)
    assert np.all(np.diff(result.t) > 0.0)


def test_x0_starts_the_shooting_and_a_failed_hb_falls_back_on_settling(system, result, monkeypatch):
    again = friction_orbit(system, OMEGA, OPTIONS, x0=result.state0 + 1e-3, every=False)
    assert again.start == "x0" and abs(float(again.rms[0]) - float(result.rms[0])) <= 1e-9

    def fails(*_args, **_kwargs):
        raise ConvergenceError("no start")

    monkeypatch.setattr(friction_orbit_module, "_start", fails)
    settled = friction_orbit(system, OMEGA, OPTIONS, every=False)
    assert settled.start == "settled" and settled.hb_start == "exact"
    assert "the regularised HB failed (no start)" in settled.message
    assert abs(float(settled.rms[0]) - float(result.rms[0])) <= 1e-9
    assert float(settled.rms_hb[0]) == pytest.approx(float(result.rms_hb[0]), rel=1e-6)


def test_an_element_stuck_the_whole_period_is_held_at_the_hbs_deflection():
    fs = _three_inertias()
    r = friction_orbit(fs, 3.0, RegularisationOptions(harmonics=32, regularisation=0.001), every=False)
    assert r.converged and r.start == "held" and r.held == ("clutch",)
    assert r.stick_fraction[0] == pytest.approx(1.0, abs=1e-12) and r.stick_fraction[1] == 0.0
    assert r.stick_intervals[0] == ((0.0, pytest.approx(r.period, rel=1e-12)),) and r.stuck[:, 0].all()
    assert r.matched and np.max(np.abs(r.element_rms_error)) <= HB_TOLERANCE
    # the held member is the exact orbit with the clutch stuck at the HB's mean deflection
    orbit = shoot_friction_orbit(fs, 3.0, r.state0, hold={0: float(r.coefficients_hb[0, 0])})
    assert orbit.converged
    np.testing.assert_allclose(orbit.rms, r.rms, atol=1e-9)


@pytest.mark.parametrize("kwargs, error, fragment", [
    ({"system": "chain"}, TypeError, "`system` must be a rattle.model.System with its elements' whole laws"),
    ({"omega": 0.0}, ValueError, "`omega`"),
    ({"omega": math.nan}, ValueError, "`omega`"),
    ({"omega": "fast"}, TypeError, "`omega`"),
    ({"options": {"harmonics": 32}}, TypeError, "`options` must be a RegularisationOptions"),
    ({"x0": np.zeros(3)}, ValueError, "`x0` must be a finite state"),
    ({"x0": [0.0, 0.0, 0.0, 0.0, 0.0, math.inf]}, ValueError, "of shape (6,)"),
    ({"x0": "rest"}, TypeError, "`x0` must be a state"),
])
def test_bad_arguments_raise_naming_the_argument(system, kwargs, error, fragment):
    args = {"system": system, "omega": OMEGA, "options": OPTIONS, **kwargs}
    with pytest.raises(error) as info:
        friction_orbit(args.pop("system"), args.pop("omega"), args.pop("options"), **args, every=False)
    assert fragment in str(info.value)
    with pytest.raises(TypeError):
        friction_orbit(system, OMEGA, OPTIONS, x_0=None, every=False)  # type: ignore[call-arg]


def test_csv_metadata_and_plot(result, tmp_path):
    path = result.to_csv(tmp_path / "orbit.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert header == ["t", *[f"clutch_{c}" for c in FRICTION_ORBIT_ELEMENT_COLUMNS]]
    assert header == ["t", "clutch_delta", "clutch_velocity", "clutch_stuck", "clutch_delta_hb"]
    table = read_csv(path)
    np.testing.assert_allclose(np.asarray(table["clutch_delta"], dtype=float), result.delta[:, 0], rtol=1e-15)
    np.testing.assert_array_equal(np.asarray(table["clutch_stuck"], dtype=bool), result.stuck[:, 0])
    meta = json.loads(json.dumps(result.metadata(), allow_nan=False))
    assert meta["status"] == "converged" and meta["stable"] is True and meta["matched"] is True
    el = meta["elements"][0]
    assert el["name"] == "clutch" and el["rms"] == float(result.rms[0])
    assert el["stick_phases"] == [[a, b] for a, b in result.stick_intervals[0]]
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = result.plot()
    assert list(ax) == ["clutch"] and len(ax["clutch"].patches) == len(result.stick_intervals[0])
    assert len(ax["clutch"].get_lines()) == 2  # exact and HB
    plt.close(fig)


def test_rattle_orbit_writes_the_three_files_with_the_documented_columns(tmp_path):
    from click.testing import CliRunner

    from rattle.cli.main import cli

    try:
        runner = CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        runner = CliRunner()
    out = tmp_path / "out"
    res = runner.invoke(cli, ["orbit", str(EXAMPLE), "--omega", str(OMEGA), "--single", "-o", str(out)], catch_exceptions=False)
    assert res.exit_code == 0, (res.stdout, res.stderr)
    assert sorted(p.name for p in out.iterdir()) == ["orbit.csv", "orbit.json", "orbit.png"]
    header = (out / "orbit.csv").read_text().splitlines()[0]
    assert header == "t,clutch_delta,clutch_velocity,clutch_stuck,clutch_delta_hb"
    docs = (ROOT / "docs" / "outputs.md").read_text(encoding="utf-8")
    assert "`t,NAME_delta,NAME_velocity,NAME_stuck,NAME_delta_hb`" in docs
    for column in FRICTION_ORBIT_ELEMENT_COLUMNS:
        assert f"`NAME_{column}`" in docs
    meta = json.loads((out / "orbit.json").read_text())
    assert meta["status"] == "converged" and meta["orbit"]["elements"][0]["stick_fraction"] > 0.0
    table = read_csv(out / "orbit.csv")
    assert np.any(np.asarray(table["clutch_stuck"], dtype=bool))
    assert "clutch: exact rms" in res.stdout and "sticks" in res.stdout


def test_nonsmooth_orbit_dispatches_a_friction_system(system, result):
    """``nonsmooth_orbit`` takes the chain too (as ``nonsmooth_response`` does): the same orbit."""
    from rattle.analysis import nonsmooth_orbit

    r = nonsmooth_orbit(system, OMEGA, OPTIONS, every=False)
    assert type(r) is type(result)
    np.testing.assert_array_equal(r.rms, result.rms)
    with pytest.raises(TypeError, match="whole laws"):
        nonsmooth_orbit("chain", OMEGA, every=False)  # type: ignore[arg-type]
