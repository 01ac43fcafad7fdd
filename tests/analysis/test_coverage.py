"""Every door at defaults: harmonics raised where the truncation demands, kinks in one step, a
range not covered never reported as success (issue: every attractor at defaults, items 3–5)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import rattle
from rattle.cli.main import cli
from rattle.errors import Status
from rattle.model import Backlash, Chain, Element, Excitation, Link, Model, Torque, Unilateral

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.slow
def test_harmonics_are_raised_where_the_truncation_demands_it():
    """A one-sided stop 2° from rest. With a tolerance of 1e-4 on the 2H estimate, H is doubled on
    the stretches of hard contacts (the large-excursion branch) and only there; every sampled row
    then passes the estimate with its own H (within a few tolerances: it is checked every 16
    points), and a fixed H stays fixed."""
    from rattle.analysis import AdaptiveHarmonics, truncation_error

    model = Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Unilateral(gap=math.radians(2.0)),
                  excitation=Excitation(mean=0.05, amplitudes=(0.03,)))
    frf = rattle.frequency_response(model, omega=(0.2, 1.0), adaptive=AdaptiveHarmonics(tolerance=1e-4))
    assert frf.status is Status.SUCCESS
    H = frf.extra_columns["harmonics"]
    assert {32, 64} <= set(np.unique(H).tolist())  # raised somewhere, not everywhere
    assert np.mean(H == 32) > 0.3 and np.all(frf.rms[H > 32] > 0.1)  # on the hard contacts
    assert "32–" in frf.harmonics_text()
    rows = np.arange(0, len(frf), 40)
    err = truncation_error(frf, rows)
    assert np.nanmax(err) <= 5e-4, (frf.omega[rows][np.nanargmax(err)], np.nanmax(err))
    fixed = rattle.frequency_response(model, omega=(0.2, 0.3), adaptive=None)
    assert set(np.unique(fixed.extra_columns["harmonics"]).tolist()) == {32}
    assert fixed.settings["adaptive_harmonics"] is None


def test_a_branch_that_returns_is_followed_from_the_other_end():
    """A gap of ±1 rad: the branch through the low end's start turns back at Ω = 0.698 and leaves
    the range where it started (before: "returned", exit 0, 0.3–0.698 of 0.3–2.0 covered). The
    branch through the high end covers the rest; both are kept (they coexist below 0.698)."""
    model = Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Backlash(b=1.0),
                  excitation=Excitation(mean=0.05, amplitudes=(0.03,)))
    frf = rattle.frequency_response(model, omega=(0.3, 2.0))
    assert frf.status is Status.SUCCESS and frf.uncovered == []
    ends = [b["end_status"] for b in frf.settings["branches"]]
    assert ends == ["RETURNED", "SUCCESS"]
    assert frf.omega[frf.branch == 0].max() == pytest.approx(0.698, abs=2e-3)
    assert frf.omega[frf.branch == 1].min() == pytest.approx(0.3) and frf.omega[frf.branch == 1].max() == pytest.approx(2.0)
    # start="high" finds the covering branch first (and, without the sweep check, only it);
    # "both" keeps the returning one too
    high = rattle.frequency_response(model, omega=(0.3, 2.0), start="high", check=None)
    assert high.status is Status.SUCCESS and len(np.unique(high.branch)) == 1
    both = rattle.frequency_response(model, omega=(0.3, 2.0), start="both")
    assert len(np.unique(both.branch)) == 2


def test_a_range_not_covered_exits_1_naming_the_intervals(tmp_path):
    """The loose gear: its impacts on a mesh 160–320 times faster than the forcing cannot be
    resolved even with 128 harmonics between 1276 and 1555 rpm; frf says so (Ω and rpm) in the
    summary, frf.json and the plot, and exits 1."""
    result = CliRunner().invoke(cli, ["frf", str(EXAMPLES / "gearbox_loose_gear.toml"), "-o", str(tmp_path / "out")])
    assert result.exit_code == 1
    meta = json.loads((tmp_path / "out" / "frf.json").read_text())
    ((a, b),) = meta["uncovered"]
    ((ra, rb),) = meta["uncovered_rpm"]
    assert a == pytest.approx(267.21, abs=0.01) and 300.0 < b < 340.0
    assert ra == pytest.approx(1275.8, abs=0.1) and rb == pytest.approx(b * 60 / (4 * math.pi))
    # an engine case names its speeds in rpm, with Ω (the files' unit) beside the uncovered range
    assert f"not covered (no branch found there): {ra:.5g} … {rb:.5g} rpm (Ω = {a:.5g} … {b:.5g})" in result.output
    assert "largest rms" in result.output and " rpm (" in result.output.split("largest rms")[1]
    assert meta["status"] == "step_too_small"
    # not labelled "unstable" there: no branch is known there at all
    assert not [r for r in meta["regions"] if r["omega_max"] > a + 1e-9 and r["omega_min"] < b - 1e-9]


@pytest.mark.slow
def test_kinks_of_the_branch_cost_one_step():
    """NLvib's two-DOF oscillator with a unilateral spring (masses 1, springs 0/1/1, dampers 0.03
    each, stop stiffness 100 at gap 1 on the first mass, force 0.1 on the second; H = 21, Ω 0.8 →
    0.5) written as a chain: the branch kinks wherever the contact switches. Each kink is taken in
    one step once halving no longer reduces the turn: ≤ 2,000 points (was 9,672 with 7,535
    rejected steps) and the same six special points as with tight steps."""
    chain = Chain(
        inertias=(1.0, 1.0),
        links=(Link(between=(1, 2), stiffness=1.0, damping=0.03), Link(between=(2, 0), stiffness=1.0, damping=0.03)),
        elements=(Element(name="stop", between=(1, 0), stiffness=100.0, law=Unilateral(gap=1.0)),),
        torques=(Torque(inertia=2, mean=0.0, amplitudes=(0.1,), phases=(0.0,)),),
    )
    frf = rattle.frequency_response(chain, omega=(0.5, 0.8), harmonics=21, start="high", adaptive=None)
    assert frf.status is Status.SUCCESS and len(frf) <= 2000
    found = sorted((s.kind, round(s.omega, 4)) for s in frf.special_points)
    assert found == sorted([("fold", 0.6534), ("fold", 0.6983), ("period_doubling", 0.726), ("period_doubling", 0.678),
                            ("neimark_sacker", 0.6115), ("neimark_sacker", 0.5819)])
    # the sweep's period-1 motions over the HB's period-doubling stretch (a truncation artefact at
    # H = 21: the exact flow settles there) are seeded once; those on the branch that seed gave are
    # not seeded again (three identical branches before, 12.5 s of the run's CPU against 6.9 s)
    check = frf.settings["sweep_check"]
    assert check["seeded"] == [] and len(check["on_a_seeded_branch"]) >= 1


def test_an_attractor_the_start_misses_is_continued_from_the_sweep():
    """Started at the high end, the continuation follows the branch that covers the range and
    misses the one a run-up from 0.3 settles on (stable, returning at Ω = 0.698). The default
    exact up/down sweep finds its motion unexplained and continues it as a branch; without the
    check it is missing."""
    from rattle.analysis import SweepCheck

    model = Model(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Backlash(b=1.0),
                  excitation=Excitation(mean=0.05, amplitudes=(0.03,)))
    frf = rattle.frequency_response(model, omega=(0.3, 2.0), start="high")
    assert len(np.unique(frf.branch)) == 2
    missed = frf.branch == 1
    assert frf.omega[missed].min() == pytest.approx(0.3) and frf.omega[missed].max() == pytest.approx(0.698, abs=2e-3)
    assert frf.stable[missed].any()
    check = frf.settings["sweep_check"]
    assert check["seeded"] and check["seeded"][0][0] == pytest.approx(0.3)
    without = rattle.frequency_response(model, omega=(0.3, 2.0), start="high", check=None)
    assert len(np.unique(without.branch)) == 1 and without.settings["sweep_check"] is None
    with pytest.raises(ValueError, match="`points`"):
        SweepCheck(points=1)
