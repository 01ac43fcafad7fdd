"""Settings carried whole: every sub-problem a front end spawns gets the user's HB options (the
sample count scaled with the harmonic count: N/H kept), Newton and continuation options and
stability method; ``result.settings`` records them per branch; a case file's [analysis] is
honoured by the library as by the command line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle import ContinuationOptions, HBOptions, NewtonOptions
from rattle.analysis import _assemble as frf_module
from rattle.stability import _methods as methods_module  # Hill.multipliers, used by every analysis
from rattle.analysis._harmonics import adaptive_frequency_response
from rattle.continuation import ContinuationStepper
from rattle.hb import HarmonicBalance
from _cases import clutch_toml  # tests/_cases.py (tests/ is on sys.path through its conftest)

NEWTON = NewtonOptions(residual_tol=2e-10, step_tol=3e-8, max_iterations=11)
CONT = ContinuationOptions(initial_step=0.009, max_step=0.07, max_points=5000)
RATIO = 6  # samples per harmonic, far from the default (32): a dropped setting shows at once


@pytest.fixture
def record(monkeypatch):
    """Record the options every HarmonicBalance, ContinuationStepper and stability computation
    receives: {"hb": [(HBOptions, period)], "stepper": [(cont, newton)], "stability": [method]}."""
    seen: dict[str, list] = {"hb": [], "stepper": [], "stability": []}
    hb_init = HarmonicBalance.__init__
    st_init = ContinuationStepper.__init__
    multipliers = frf_module._multipliers
    hill = methods_module.hill_multipliers

    def hb_spy(self, model, options=None, *, period=1):
        seen["hb"].append((options, period))
        hb_init(self, model, options, period=period)

    def st_spy(self, hb, q0, omega0, omega_range, options=None, newton=None, *args, **kwargs):
        seen["stepper"].append((options, newton))
        st_init(self, hb, q0, omega0, omega_range, options, newton, *args, **kwargs)

    def mu_spy(model, hb, Q, Om, X, stability):
        seen["stability"].append(stability.name)  # a rattle.stability method object
        return multipliers(model, hb, Q, Om, X, stability)

    def hill_spy(hb, q, omega):
        seen["stability"].append("hill")
        return hill(hb, q, omega)

    monkeypatch.setattr(HarmonicBalance, "__init__", hb_spy)
    monkeypatch.setattr(ContinuationStepper, "__init__", st_spy)
    monkeypatch.setattr(frf_module, "_multipliers", mu_spy)
    monkeypatch.setattr(methods_module, "hill_multipliers", hill_spy)
    return seen


def _assert_carried(seen, *, ratio: int = RATIO, min_problems: int = 2) -> None:
    assert len(seen["hb"]) >= min_problems
    for opts, period in seen["hb"]:
        assert isinstance(opts, HBOptions), opts
        assert opts.samples == ratio * opts.harmonics, (opts, period)  # N/H kept in every sub-problem
    assert seen["stepper"], "no continuation ran"
    for cont, newton in seen["stepper"]:
        assert cont is CONT and newton is NEWTON


def test_subharmonic_branches_and_2h_relocation_get_every_option(reference_model, record):
    frf = rattle.frequency_response(
        reference_model, omega=(0.39, 0.48), harmonics=8, samples=8 * RATIO, newton=NEWTON, continuation=CONT,
        subharmonics=True,
    )
    assert 2 in set(frf.period.tolist())  # a period-doubling branch was followed
    _assert_carried(record, min_problems=4)
    problems = {(o.harmonics, p) for o, p in record["hb"]}
    assert {(8, 1), (16, 1), (16, 2), (32, 2)} <= problems  # primary, its 2H, the period-2 branch, its 2H
    assert set(record["stability"]) == {"monodromy"}
    branches = frf.settings["branches"]
    assert [b["branch"] for b in branches] == sorted(set(frf.branch.tolist()))
    for b in branches:
        assert b["samples"] == RATIO * b["harmonics"] and b["stability"] == "monodromy"
        assert b["newton"]["max_iterations"] == 11 and b["continuation"]["max_step"] == 0.07
    assert branches[1]["period"] == 2 and branches[1]["origin"].startswith("period doubling")


def test_seeded_branch_gets_hill_stability_and_samples(reference_model, record):
    ss = rattle.steady_state(reference_model, 1.41, np.array([0.18, 0.0]))
    assert ss.period == 2
    frf = rattle.frequency_response(
        reference_model, omega=(1.39, 1.43), hb=HBOptions(harmonics=8, samples=8 * RATIO), newton=NEWTON,
        continuation=CONT, stability="hill", subharmonics=True, seeds=[(1.41, 2, ss.state0)],
    )
    assert 2 in set(frf.period.tolist())
    _assert_carried(record)
    assert (HBOptions(harmonics=16, samples=16 * RATIO), 2) in record["hb"]  # the seed's problem: 2·H, 2·N
    assert record["stability"] and set(record["stability"]) == {"hill"}
    assert {b["stability"] for b in frf.settings["branches"]} == {"hill"}
    assert frf.settings["branches"][-1]["origin"].startswith("seed")


def test_periodic_orbit_passes_its_options_to_the_primary_branch_and_the_subharmonic(record):
    model = rattle.load_case(Path(__file__).parents[1] / "examples" / "gear_backlash.toml").model
    orbit = rattle.periodic_orbit(
        model, 0.6538, hb=HBOptions(harmonics=16, samples=16 * RATIO), newton=NEWTON, continuation=CONT,
        stability="hill", search_range=(0.6, 0.7),
    )
    assert 2 in {s.period for s in orbit.solutions}  # so the sub-harmonic branch was followed
    _assert_carried(record)
    assert len(record["stepper"]) >= 2  # primary branch + sub-harmonic branch
    assert "hill" in record["stability"] and "monodromy" not in record["stability"]
    assert orbit.settings["stability"] == "hill" and orbit.settings["newton"]["max_iterations"] == 11
    assert orbit.settings["primary_branch_settings"]["samples"] == 16 * RATIO


def test_compare_passes_its_options_on(reference_model, record):
    cmp = rattle.compare(reference_model, omega=(1.39, 1.43), points=3, at=[1.41], harmonics=8, samples=8 * RATIO,
                         newton=NEWTON, continuation=CONT)
    _assert_carried(record)
    assert cmp.settings["samples"] == 8 * RATIO and cmp.frf.settings["samples"] == 8 * RATIO
    assert cmp.orbits[0].settings["newton"]["max_iterations"] == 11


def test_adaptive_frequency_response_keeps_the_ratio(reference_model, record):
    frf = adaptive_frequency_response(reference_model, omega=(0.9, 1.0), harmonics=4, samples=4 * RATIO,
                                      tolerance=1e-4, max_harmonics=16, newton=NEWTON, continuation=CONT)
    _assert_carried(record)
    assert {o.harmonics for o, _ in record["hb"]} >= {4, 8, 16}
    assert frf.settings["samples"] == RATIO * frf.settings["harmonics"]


def test_hb_options_and_plain_arguments_do_not_conflict(reference_model):
    frf = rattle.frequency_response(reference_model, omega=(0.9, 1.0), hb=HBOptions(harmonics=4, samples=40))
    assert frf.settings["harmonics"] == 4 and frf.settings["samples"] == 40
    same = rattle.frequency_response(reference_model, omega=(0.9, 1.0), harmonics=4, samples=40)
    np.testing.assert_array_equal(frf.rms, same.rms)
    rattle.frequency_response(reference_model, omega=(0.9, 1.0), harmonics=4, hb=HBOptions(harmonics=4))
    numpy_int = rattle.frequency_response(reference_model, omega=(0.9, 1.0), harmonics=np.int64(4),
                                          samples=np.int64(40))
    np.testing.assert_array_equal(numpy_int.rms, same.rms)
    with pytest.raises(ValueError, match=r"`harmonics` = 32 conflicts with `hb.harmonics` = 4"):
        rattle.frequency_response(reference_model, omega=(0.9, 1.0), harmonics=32, hb=HBOptions(harmonics=4))
    with pytest.raises(ValueError, match=r"`samples` = 64 conflicts with `hb.samples`"):
        rattle.frequency_response(reference_model, omega=(0.9, 1.0), samples=64, hb=HBOptions(harmonics=4))
    with pytest.raises(TypeError, match=r"`hb"):
        rattle.frequency_response(reference_model, omega=(0.9, 1.0), hb={"harmonics": 4})  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"`harmonics` = 8 conflicts"):
        rattle.periodic_orbit(reference_model, 0.95, harmonics=8, hb=HBOptions(harmonics=4))


CASE = clutch_toml((1.0, 1.1), 5)


def test_case_file_analysis_library_equals_cli(tmp_path):

    from _cli_helpers import invoke
    path = tmp_path / "case.toml"
    path.write_text(CASE, encoding="utf-8")
    result = invoke(["frf", str(path), "-o", str(tmp_path / "out")], tmp_path)
    assert result.exit_code == 0, result.stderr
    case = rattle.load_case(path)
    frf = case.frequency_response()
    assert frf.settings["harmonics"] == 5 and frf.settings["omega"] == [1.0, 1.1]
    frf.to_csv(tmp_path / "lib.csv")
    assert (tmp_path / "lib.csv").read_text() == (tmp_path / "out" / "frf.csv").read_text()
    # Explicit options override the file, as on the command line.
    assert case.frequency_response(omega=(1.0, 1.02), hb=HBOptions(harmonics=4, samples=40)).settings["samples"] == 40
    with pytest.raises(TypeError):
        case.frequency_response(harmonic=4)


def test_sweep_seeded_branch_gets_every_option(record):
    """Backlash b = 1: the period-2 motion a time sweep finds at Ω = 0.65 seeds a branch (period
    doublings not followed: ``max_period=1``), which gets the user's options like every other."""
    model = rattle.Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=rattle.Backlash(b=1.0),
                         excitation=rattle.Excitation(mean=0.05, amplitudes=(0.03,)))
    sweep = rattle.time_sweep(model, omega=(0.55, 0.75), points=21, direction="up")
    assert 2 in set(sweep.period.tolist())
    record["hb"].clear()
    frf = rattle.frequency_response(model, omega=(0.62, 0.70), hb=HBOptions(harmonics=16, samples=16 * RATIO),
                                    newton=NEWTON, continuation=CONT, subharmonics=True, max_period=1, sweep=sweep)
    _assert_carried(record)
    seeded = [b for b in frf.settings["branches"] if b["origin"].startswith("seed")]
    assert seeded and all(b["samples"] == RATIO * b["harmonics"] == RATIO * 32 for b in seeded)
