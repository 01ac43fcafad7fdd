"""The super-harmonic peaks without scipy.signal: ``prominent_peaks`` is
``scipy.signal.find_peaks(x, prominence=p)`` (peaks and prominences), integer for integer and bit
for bit, on signals with plateaus, ties, NaN and every prominence threshold."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.signal import find_peaks

from rattle.analysis._regimes import prominent_peaks


def _same(x: np.ndarray, prominence: float) -> None:
    expected, props = find_peaks(x, prominence=prominence)
    peaks, proms = prominent_peaks(x, prominence)
    assert peaks.dtype == expected.dtype and np.array_equal(peaks, expected)
    assert proms.dtype == props["prominences"].dtype
    assert np.array_equal(proms, props["prominences"])  # bit for bit


@given(
    st.lists(st.sampled_from([0.0, 0.1, 0.25, 0.3, 1.0, -0.5, 2.0, float("nan")]), min_size=0, max_size=60),
    st.sampled_from([0.0, 0.05, 0.2, 0.7, 1.5]),
)
def test_plateaus_ties_and_nan_as_scipy(values: list[float], prominence: float) -> None:
    _same(np.array(values, dtype=float), prominence)


@given(st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=0, max_size=80), st.floats(0.0, 50.0))
def test_random_signals_as_scipy(values: list[float], prominence: float) -> None:
    _same(np.array(values, dtype=float), prominence)


def test_a_response_curve_as_scipy() -> None:
    om = np.linspace(0.1, 1.0, 400)
    ac = 0.02 / np.abs(1 - (3 * om) ** 2 + 0.1j * om) + 0.05 / np.abs(1 - (2 * om) ** 2 + 0.05j * om) + om
    for p in (0.0, 1e-3, 0.01 * float(np.ptp(ac)), 0.1):
        _same(ac, p)
    assert prominent_peaks(ac, 0.0)[0].size >= 2


def test_refuses_a_matrix() -> None:
    with pytest.raises(ValueError):
        prominent_peaks(np.zeros((3, 3)), 0.1)
