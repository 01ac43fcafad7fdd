"""The example configurations parse, and their stated expectations hold."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import rattle
from rattle.io import load_config

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_example_configurations_parse(name):
    cfg = load_config(EXAMPLES / name)
    assert cfg.analysis.harmonics >= cfg.model.system().forced_harmonics


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


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_example_states_every_special_point_it_has(name):
    """Every special point of the period-1 branch at the example's own settings is stated in its
    header (kind and Ω to 5 decimals), and every stated one is found: none missing, none extra."""
    cfg = load_config(EXAMPLES / name)
    frf = rattle.frequency_response(cfg.model, omega=cfg.analysis.omega, harmonics=cfg.analysis.harmonics)
    found = sorted((s.kind, s.omega) for s in frf.special_points if s.branch == 0)
    stated = _stated_special_points(EXAMPLES / name)
    assert len(found) == len(stated), (found, stated)
    for (kind, w), (kind_s, w_s) in zip(sorted(found, key=lambda x: x[1]), sorted(stated, key=lambda x: x[1])):
        assert kind == kind_s and abs(w - w_s) <= 6e-6, ((kind, w), (kind_s, w_s))
