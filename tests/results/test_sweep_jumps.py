"""Jump detection of a sweep: a jump is a change the trend on neither side explains — also at the
end of a steep flank or at the last row — on every element of a chain."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle.results._sweep import Jump, _jump_steps

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _steps(r, w=None):
    r = np.asarray(r, dtype=float)
    w = np.arange(r.size, dtype=float) if w is None else np.asarray(w, dtype=float)
    return [i for i, _ in _jump_steps(w, r, 0.15)]


def test_a_drop_at_the_end_of_a_steepening_flank_is_a_jump():
    # a down sweep climbing the large branch toward its fold, then off it at the last row
    assert _steps([0.16, 0.19, 0.23, 0.29, 0.36, 0.47, 0.61, 0.82, 1.12, 1.56, 2.21, 0.088]) == [10]
    # the same in the middle of the sweep
    assert _steps([0.36, 0.47, 0.61, 0.82, 1.12, 1.56, 2.21, 0.088, 0.085, 0.083]) == [6]


@pytest.mark.parametrize("r", [
    [0.1, 0.15, 0.22, 0.33, 0.5, 0.75],           # a steep smooth flank
    [0.5, 1.0, 1.6, 1.1, 0.6, 0.4],               # a coarsely sampled peak
    [0.5, 0.5, 0.5, 0.51, 0.5],                   # flat
])
def test_a_smooth_flank_or_a_peak_is_no_jump(r):
    assert _steps(r) == []


def test_uneven_frequency_steps_are_taken_into_account():
    # the same linear trend sampled at uneven steps: no jump
    w = [0.0, 1.0, 1.5, 3.5, 4.0]
    assert _steps([0.1 + 0.3 * x for x in w], w) == []


def test_a_jump_unpacks_as_five_and_names_its_element():
    j = Jump("up", 1.0, 1.1, 0.5, 0.2, "gear")
    assert tuple(j) == ("up", 1.0, 1.1, 0.5, 0.2) and j.element == "gear" and j.kind == "down"
    assert Jump("up", 1.0, 1.1, 0.2, 0.5).element == ""


def test_a_chain_sweep_finds_the_jumps_of_both_directions_with_their_element():
    chain = rattle.Chain.from_toml(EXAMPLES / "chain_two_inertia.toml")
    sweep = rattle.time_sweep(chain, omega=(0.6, 1.0), points=40, direction="both")
    kinds = [(j.direction, j.kind) for j in sweep.jumps()]
    assert ("up", "down") in kinds and ("down", "up") in kinds
    assert all(j.element in chain.element_names for j in sweep.jumps())
    assert "clutch rms" in sweep.summary()
