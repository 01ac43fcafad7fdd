"""The markdown design summary of a response map (rattle map --report)."""

from __future__ import annotations

from dataclasses import replace

from rattle.maps import ResponseMap
from rattle.maps._report import common_intervals, format_intervals, map_report

from _fake_map import synthetic_map


def test_format_intervals():
    assert format_intervals([]) == "none"
    assert format_intervals([[0.1, 0.55], [1.2, 1.2]]) == "0.1 – 0.55, 1.2"


def test_report_holds_settings_region_points_intervals_and_search():
    m = synthetic_map(("alpha",), ((0.1, 0.2),), points=30)
    text = map_report(m)
    assert text.startswith("# Response map: design summary")
    assert "- varied `alpha` (`model.elastic.alpha`): 0.1 … 0.2" in text
    assert "30 frequencies, 0.1 … 3 rad/s" in text
    cell = m.cells[0]
    free = format_intervals(cell.intervals["rattle_free"])
    impact = format_intervals(cell.intervals["impact"])
    assert f"| 0.1 | {free} | {impact} |" in text  # the region table row of alpha = 0.1
    assert "### alpha = 0.1" in text and "### alpha = 0.2" in text
    assert "| fold | 0.85 | 0 | 1 | 0.3 |" in text
    assert f"- stable sub-harmonic (period ≥ 2): {format_intervals(cell.intervals['subharmonic'])}" in text
    assert f"- non-periodic attractor (period 0): {format_intervals(cell.intervals['nonperiodic'])}" in text
    assert "period 2 at Ω = 1.7 (from simulation), continued as branch 1" in text
    assert "What it may still miss" in text and "basin" in text
    assert "| 0.1 – 0.7 | 0.1 – 0.2 | none |" in text  # read along Ω: both values rattle-free there
    assert "| 0.8 | 0.2 | 0.1 |" in text  # alpha = 0.1 impacts from 0.8, alpha = 0.2 only from 0.9
    common = common_intervals(m)
    assert f"- Ω rattle-free at every combination: {format_intervals(common['rattle_free_everywhere'])}" in text


def test_common_intervals_intersect_the_combinations():
    m = synthetic_map(("alpha",), ((0.0, 0.3),), points=30)
    common = common_intervals(m)
    omega = m.omega
    free_all = ~(m.cells[0].rattle | m.cells[1].rattle)
    assert sum(int(((omega >= lo) & (omega <= hi)).sum()) for lo, hi in common["rattle_free_everywhere"]) \
        == int(free_all.sum())
    assert common["impact_everywhere"]


def test_failed_and_resumed_combinations_are_said():
    m = synthetic_map(("alpha",), ((0.1, 0.2),), points=10)
    cells = (replace(m.cells[0], status="failed", message="no start"), replace(m.cells[1], resumed=True))
    m2 = ResponseMap(parameters=m.parameters, omega=m.omega, cells=cells, settings=m.settings, timings=m.timings)
    text = map_report(m2)
    assert "Status: **failed** — no start" in text
    assert "1 failed; 1 read back from an earlier run" in text
    assert "| 0.1 | (failed) | (failed) |" in text
