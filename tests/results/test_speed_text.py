"""Speeds in text (issue 27 item 3): an engine case's summaries, regions and jumps in rpm, a case
without an engine in Ω as before; the rpm of a sweep grid given in rpm as round as it was given."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle.results._speed import SpeedText, round_to_grid, rpm_of_omega

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_speed_text_writes_rpm_with_an_engine_and_omega_without():
    none, engine = SpeedText(), SpeedText(2.0)
    w = 2.0 * 2.0 * math.pi * 1000.0 / 60.0  # 1000 rpm at order 2
    assert rpm_of_omega(w, 2.0) == pytest.approx(1000.0, rel=1e-15)
    assert none.at(0.75432) == "Ω = 0.75432" and none.at(0.75, unit=True) == "Ω = 0.75 rad/s"
    assert engine.at(w) == "1000 rpm" and engine.unit == "rpm" and none.unit == "rad/s"
    assert none.span(0.5, 0.7) == "Ω = 0.5 … 0.7" and engine.span(w, 2 * w) == "1000 … 2000 rpm"
    assert none.spans([(0.5, 0.7), (0.9, 1.0)]) == "Ω = 0.5 … 0.7, 0.9 … 1"
    assert engine.values([w, 1.5 * w]) == "1000, 1500 rpm"
    assert SpeedText.of(rattle.reference_case()).order is None


def test_round_to_grid_removes_the_round_off_of_the_conversion_and_keeps_the_grid():
    order = 2.0
    omega = np.linspace(400, 1500, 12) * order * 2 * math.pi / 60  # the rpm grid 400, 500, … as Ω
    raw = rpm_of_omega(omega, order)
    assert not np.array_equal(raw, np.linspace(400, 1500, 12))  # 799.9999999999999 and the like
    rounded = round_to_grid(raw, float(raw[0]), float(raw[-1]), 12)
    assert rounded.tolist() == np.linspace(400, 1500, 12).tolist()
    # a grid whose points are not round keeps them to a thousandth of its step
    odd = np.linspace(400, 1500, 146)
    np.testing.assert_allclose(round_to_grid(odd * (1 + 1e-15), 400, 1500, 146), odd, rtol=0, atol=0.5e-6 * 1100 / 145)
    assert np.max(np.abs(round_to_grid(odd, 400, 1500, 146) - odd)) > 0  # rounded, not passed through


@pytest.fixture(scope="module")
def engine_case():
    return rattle.load_case(EXAMPLES / "engine_clutch_si.toml")


def test_an_engine_case_summary_gives_every_speed_in_rpm(engine_case):
    model = engine_case.model
    lo, hi = (r * 2 * 2 * math.pi / 60 for r in (700.0, 1200.0))
    frf = rattle.frequency_response(model, omega=(lo, hi), harmonics=8)
    text = frf.summary()
    first, *rest = text.splitlines()
    assert first.startswith(f"{len(frf)} solution points over 700 … 1200 rpm (Ω = ")
    assert "engine speed: Ω = 2 × crankshaft speed" in rest
    assert frf.special_points and "stability changes:" in text
    body = [line for line in rest if not line.startswith("engine speed")]
    assert not any("Ω" in line for line in body), text  # no speed in rad/s after the header
    i = int(np.argmax(frf.rms))
    assert f"largest rms {frf.rms[i]:.5g} rad at {frf.speed_rpm[i]:.5g} rpm" in text
    for s in frf.special_points:
        assert f"{s.kind} at {rpm_of_omega(s.omega, 2.0):.5g} rpm" in text


def test_an_engine_sweep_summary_and_its_rpm_column(engine_case):
    lo, hi = (r * 2 * 2 * math.pi / 60 for r in (900.0, 1100.0))
    sweep = rattle.time_sweep(engine_case.model, omega=(lo, hi), points=9, direction="up")
    assert sweep.speed_rpm.tolist() == [900.0, 925.0, 950.0, 975.0, 1000.0, 1025.0, 1050.0, 1075.0, 1100.0]
    text = sweep.summary()
    assert "up sweep: 9 frequencies over 900 … 1100 rpm" in text and "Ω" not in text
    assert re.search(r"largest rms [0-9.e-]+ rad at \d+ rpm", text)


def test_a_case_without_an_engine_keeps_omega():
    frf = rattle.frequency_response(rattle.reference_case(), omega=(0.5, 1.2), harmonics=8)
    text = frf.summary()
    assert "rpm" not in text and "over Ω = 0.5 … 1.2 (H = " in text and "at Ω = " in text


def test_rattle_orbit_takes_the_speed_in_rpm(tmp_path):
    """``rattle orbit --rpm N`` on an engine case: Ω = order · 2π N/60, the summary in rpm, the
    option recorded in orbit.json; --omega of the same frequency gives the same orbit."""
    import json

    from click.testing import CliRunner

    from rattle.cli import cli

    case = str(EXAMPLES / "engine_clutch_si.toml")
    by_rpm = CliRunner().invoke(cli, ["orbit", case, "--rpm", "955", "-o", str(tmp_path / "rpm")])
    assert by_rpm.exit_code == 0, by_rpm.output
    w = 955.0 * 2.0 * 2.0 * math.pi / 60.0
    assert f"at 955 rpm (Ω = {w:.6g} rad/s; H = 16)" in by_rpm.output
    meta = json.loads((tmp_path / "rpm" / "orbit.json").read_text())
    assert meta["options"]["rpm"] == 955.0 and meta["options"]["omega"] == pytest.approx(w, rel=1e-15)
    by_omega = CliRunner().invoke(cli, ["orbit", case, "--omega", repr(w), "-o", str(tmp_path / "omega")])
    assert by_omega.exit_code == 0
    assert (tmp_path / "rpm" / "orbit.csv").read_text() == (tmp_path / "omega" / "orbit.csv").read_text()
