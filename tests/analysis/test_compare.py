"""compare(): the FRF against the up/down sweep, and the frequencies picked for a closer look."""

from __future__ import annotations

import numpy as np
import pytest

from rattle.analysis import compare
from rattle.analysis._compare import pick_frequencies
from rattle.io import read_csv
from rattle.results import FRF_COLUMNS, SWEEP_COLUMNS, Comparison


@pytest.fixture(scope="module")
def comparison(reference_model) -> Comparison:
    # 20 frequencies each way over the resonance's multi-valued region and the period-2 region
    return compare(reference_model, omega=(0.6, 1.6), harmonics=16, points=20)


def test_picks_one_multivalued_and_one_subharmonic_frequency(comparison: Comparison) -> None:
    assert comparison.reasons == ("multi-valued", "sub-harmonic")
    w_multi, w_sub = comparison.at
    assert 0.755 < w_multi < 0.874  # between the folds of the reference case
    assert 1.24 < w_sub < 1.96  # where the primary orbit is unstable (period doubling)
    grid = np.unique(comparison.sweep.omega)
    assert np.min(np.abs(grid - w_multi)) < 1e-12 and np.min(np.abs(grid - w_sub)) < 1e-12


def test_orbits_and_sweep_states(comparison: Comparison) -> None:
    multi, sub = comparison.orbits
    assert [s.stable for s in multi.solutions] == [True, False, True]
    up, down = comparison.simulations[0]["up"], comparison.simulations[0]["down"]
    # the sweeps sit on the two stable orbits: the big one going up, the small one going down
    assert up.rms == pytest.approx(multi.solutions[0].rms, rel=2e-3)
    assert down.rms == pytest.approx(multi.solutions[2].rms, rel=2e-3)
    assert sub.period == 2 and sub.of_period(2) and sub.of_period(2)[0].stable
    assert comparison.simulations[1]["up"].period == 2


def test_requested_frequencies_and_output(tmp_path, reference_model) -> None:
    c = compare(reference_model, omega=(0.6, 1.6), harmonics=16, points=6, at=[1.41, 0.8])
    assert c.at == (0.8, 1.41) and c.reasons == ("requested", "requested")
    frf_path, sweep_path = c.to_csv(tmp_path)
    assert list(read_csv(frf_path)) == [*FRF_COLUMNS, "harmonics"]  # SPEC §3 + §8
    assert list(read_csv(sweep_path)) == [*SWEEP_COLUMNS, "regime"]
    meta = c.metadata()
    assert [o["omega"] for o in meta["orbits"]] == [0.8, 1.41]
    assert "Ω = 0.8 (requested)" in c.summary()
    assert "Comparison(" in repr(c)


def test_largest_rattle_pick_when_nothing_else(reference_model) -> None:
    # above the resonance and the period-2 region: one stable period-1 orbit everywhere, impacting
    c = compare(reference_model, omega=(2.0, 3.0), harmonics=8, points=5)
    assert c.reasons == ("largest rattle",)
    assert pick_frequencies(c.frf, c.sweep) == [(c.at[0], "largest rattle")]
    # the pick is the largest stable motion about the mean (rms_ac) of an impacting row, not the largest rms
    rows = c.frf.stable & np.isin(c.frf.regime.astype(str), ("single_sided", "double_sided"))
    i = int(np.flatnonzero(rows)[np.argmax(c.frf.rms_ac[rows])])
    grid = np.unique(c.sweep.omega)
    assert c.at[0] == grid[np.argmin(np.abs(grid - c.frf.omega[i]))]


@pytest.mark.parametrize(
    ("at", "error", "match"),
    [([5.0], ValueError, "`at`"), ([], ValueError, "`at`"), ("0.8", TypeError, "`at`"), ([float("nan")], ValueError, "`at`")],
)
def test_bad_at(reference_model, at, error, match) -> None:
    with pytest.raises(error, match=match):
        compare(reference_model, omega=(0.6, 1.6), harmonics=8, points=4, at=at)
