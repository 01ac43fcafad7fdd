"""The example configurations parse, and their stated expectations hold."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle.io import load_config

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_example_configurations_parse(name):
    cfg = load_config(EXAMPLES / name)
    assert cfg.analysis.harmonics >= cfg.bounds_model.system().forced_harmonics  # a discontinuous law: its continuous part


def test_reference_example_is_the_reference_case():
    model = load_config(EXAMPLES / "reference_clutch.toml").model
    ref = rattle.reference_case()
    assert (model.inertia, model.damping, model.stiffness) == (ref.inertia, ref.damping, ref.stiffness)
    assert model.excitation == ref.excitation
    assert model.elastic.alpha == ref.elastic.alpha  # type: ignore[attr-defined]
    assert model.elastic.b == pytest.approx(ref.elastic.b, abs=5e-7)  # 10° written to 6 decimals


def test_gear_backlash_example_as_stated():
    cfg = load_config(EXAMPLES / "gear_backlash.toml")
    frf = rattle.frequency_response(cfg.model, omega=cfg.analysis.omega, harmonics=cfg.analysis.harmonics)
    folds = sorted(s.omega for s in frf.special_points if s.kind == "fold")
    assert any(0.6 < w < 0.7 for w in folds) and any(0.8 < w < 0.86 for w in folds)
    assert {"single_sided", "double_sided"} <= set(frf.regime)
    pds = [s.omega for s in frf.special_points if s.kind == "period_doubling"]
    assert any(0.46 < w < 0.53 for w in pds)


def _stated_special_points(path: Path) -> list[tuple[str, float]]:
    """The special points an example's header states: '#   fold 0.47061; period_doubling …'."""
    text = path.read_text()
    head = text[text.index("# Special points") :]
    head = head[: head.index("\n[")]
    return [(kind, float(w)) for kind, w in re.findall(r"(fold|period_doubling|neimark_sacker) ([0-9.]+)", head)]


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_example_states_every_special_point_it_has(name):
    """Every special point of the period-1 branch at the example's own settings is stated in its
    header (kind and Ω to 5 decimals), and every stated one is found: none missing, none extra."""
    cfg = load_config(EXAMPLES / name)
    if cfg.discontinuous:  # stated between rows, not located: test_discontinuous_examples_as_stated
        pytest.skip("a discontinuous law (preload or friction): see test_discontinuous_examples_as_stated")
    if "none (the continuation stops first)" in (EXAMPLES / name).read_text():  # a model HB cannot resolve, said so
        stop = re.search(r"rattle frf stops at ([0-9.]+) rpm", (EXAMPLES / name).read_text())
        with pytest.raises(rattle.ConvergenceError, match="frequency response incomplete") as info:
            rattle.frequency_response(cfg.model, omega=cfg.analysis.omega, harmonics=cfg.analysis.harmonics)
        rpm = float(re.search(r"beyond ([0-9.]+) rpm", str(info.value)).group(1))  # an engine case: messages in rpm
        assert abs(rpm - float(stop.group(1))) < 1.0
        return
    frf = rattle.frequency_response(cfg.model, omega=cfg.analysis.omega, harmonics=cfg.analysis.harmonics)
    found = sorted((s.kind, s.omega) for s in frf.special_points if s.branch == 0)
    stated = _stated_special_points(EXAMPLES / name)
    assert len(found) == len(stated), (found, stated)
    for (kind, w), (kind_s, w_s) in zip(sorted(found, key=lambda x: x[1]), sorted(stated, key=lambda x: x[1])):
        assert kind == kind_s and abs(w - w_s) <= 6e-6, ((kind, w), (kind_s, w_s))


def test_loose_gear_example_rattles_below_the_drag_criterion_only():
    """The stated expectation of gearbox_loose_gear.toml: impacts on the drive flank end at
    1595 ± 5 rpm, where the speed-dependent drag first exceeds J2 (r1/r2) A (1600 rpm)."""
    cfg = load_config(EXAMPLES / "gearbox_loose_gear.toml")
    to_omega = 2.0 * (2.0 * np.pi / 60.0)  # Ω per rpm at order 2
    sweep = rattle.time_sweep(cfg.model, omega=(1500.0 * to_omega, 1700.0 * to_omega), points=21, direction="up")
    acc = dict(zip(np.round(cfg.model.speed_rpm(sweep.omega)), sweep.acc_p2p))
    assert acc[1500.0] > 300 and acc[1560.0] > 100 and acc[1590.0] > 20
    assert acc[1600.0] < 1.0 and acc[1610.0] < 1.0 and acc[1700.0] < 1.0
    assert np.max(sweep.p2p) < 2 * 1.25e-3  # never across the gap to the coast flank


def _stated_changes(path: Path) -> list[tuple[str, float, float]]:
    """The stability changes a discontinuous example states between rows: 'fold 0.6246' or
    'period_doubling 0.541-0.547' → (kind, low, high)."""
    text = path.read_text()
    head = text[text.index("# Stability changes") :]
    head = head[: head.index("\n[")]
    return [(kind, float(a), float(b or a)) for kind, a, b in
            re.findall(r"(fold|period_doubling|neimark_sacker) ([0-9.]+)(?:-([0-9.]+))?", head)]


@pytest.mark.slow
@pytest.mark.parametrize(("name", "omega", "stick"), [
    ("torque_converter_preload.toml", (0.58, 0.63), 0.0),
    ("clutch_friction.toml", (0.3, 0.34), 0.1),
    ("clutch_friction.toml", (0.7, 0.76), 0.0),
])
def test_discontinuous_examples_as_stated(name, omega, stick):
    """The stability changes an example with a preload or friction states lie where it says (on a
    part of its range, at its own harmonics and regularisation), and it sticks where it says."""
    from rattle.analysis import RegularisationOptions
    from rattle.analysis._nonsmooth import nonsmooth_response

    cfg = load_config(EXAMPLES / name)
    assert cfg.discontinuous
    result = nonsmooth_response(cfg.model, omega, RegularisationOptions(harmonics=cfg.analysis.harmonics,
                                                                        regularisation=cfg.analysis.regularisation))
    assert result.status.success and np.mean(result.matched) > 0.95  # a few rows at a fold may not match
    labels = result.bifurcation
    found = sorted((str(labels[i]), float(result.omega[i])) for i in range(len(result))
                   if labels[i] in ("fold", "period_doubling", "neimark_sacker"))  # not the grazings
    stated = sorted((k, lo, hi) for k, lo, hi in _stated_changes(EXAMPLES / name) if omega[0] < lo and hi < omega[1])
    assert [k for k, _ in found] == [k for k, _, _ in stated], (found, stated)
    for (_, w), (_, lo, hi) in zip(sorted(found, key=lambda x: x[1]), sorted(stated, key=lambda x: x[1])):
        assert lo - 2e-3 <= w <= hi + 2e-3, (w, lo, hi)
    fraction = np.nan_to_num(result.stick_time) * result.omega / (2.0 * np.pi)
    assert np.max(fraction) == pytest.approx(stick, abs=0.01)  # "up to 10 % of the period at Omega = 0.3"
    assert np.max(np.abs(result.rms_error[result.matched])) < 0.05
