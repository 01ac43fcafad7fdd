"""FrequencyResponse: measures against brute force, time histories, CSV, plot, linear overlay."""

from __future__ import annotations

import numpy as np
import pytest

from rattle import linear_frequency_response
from rattle.io import read_csv
from rattle.results import FRF_COLUMNS
from rattle.measures import regime_of


def test_measures_match_brute_force_sampling(reference_frf):
    frf = reference_frf
    for i in range(0, len(frf), 37):
        h = frf.time_history(i, samples=20000)
        d, a = h["delta"], h["acceleration"]
        # Dense sampling (20000 per period) bounds the extremes from inside to ~(T/20000)² and
        # the refined values must lie within that gap: 1e-6 relative to the peak-to-peak.
        assert frf.delta_max[i] >= d.max() - 1e-12
        assert frf.delta_min[i] <= d.min() + 1e-12
        assert frf.p2p[i] == pytest.approx(d.max() - d.min(), rel=1e-6)
        # δ'' has kinks at breakpoint crossings: sampled extremes converge to first order,
        # T/20000 · |δ'''| ≲ 1e-4 of the peak-to-peak.
        assert frf.acc_p2p[i] >= (a.max() - a.min()) * (1 - 1e-6)  # grid search resolves T/(64 N)
        assert frf.acc_p2p[i] == pytest.approx(a.max() - a.min(), rel=1e-4)
        # Mean and rms by Parseval equal the trapezoidal (spectrally exact) time averages.
        assert frf.mean[i] == pytest.approx(np.mean(d[:-1]), rel=1e-12)
        assert frf.rms[i] == pytest.approx(np.sqrt(np.mean(d[:-1] ** 2)), rel=1e-12)
        assert frf.rms_ac[i] == pytest.approx(np.std(d[:-1]), rel=1e-10)


def test_time_history_satisfies_the_equation(reference_frf):
    frf = reference_frf
    m = frf.model
    i = int(np.argmax(frf.rms))
    h = frf.time_history(i, samples=4096)
    # Acceleration from the equation vs the second derivative of the series: they differ only
    # by the truncation of the series of δ'' (coefficients ~k⁻², as δ'' has kinks): its tail
    # beyond H = 32 is ~1/H of a leading kink coefficient, below 1 % of the peak-to-peak.
    t = h["t"]
    from rattle.hb import FourierBasis

    basis = FourierBasis(frf.harmonics, 4 * frf.harmonics)
    series_acc = basis.evaluate(frf.coefficients[i], frf.omega[i], t, derivative=2)
    assert np.max(np.abs(series_acc - h["acceleration"])) < 1e-2 * np.ptp(h["acceleration"])
    assert h["delta"][0] == pytest.approx(h["delta"][-1], abs=1e-13)  # periodic
    assert m.c == 0.05


def test_regimes_follow_the_extremes(reference_frf):
    frf = reference_frf
    b = frf.model.elastic.stages.breakpoints  # ±b
    for i in range(len(frf)):
        crosses_up = frf.delta_min[i] < b[1] < frf.delta_max[i]
        crosses_down = frf.delta_min[i] < b[0] < frf.delta_max[i]
        expected = "double_sided" if crosses_up and crosses_down else "single_sided" if crosses_up or crosses_down else "no_impact"
        assert frf.regime[i] == expected
    assert {"no_impact", "single_sided", "double_sided"} <= set(frf.regime)


def test_regime_of_asymmetric_law():
    from rattle.model import Excitation, Model, Piecewise

    law = Piecewise(breakpoints=(-0.3, -0.1, 0.05, 0.2), slopes=(1.0, 0.3, 0.05, 0.3, 1.0))
    m = Model(inertia=1, damping=0.1, stiffness=1, elastic=law, excitation=Excitation(mean=0.0, amplitudes=(0.1,)))
    lo = np.array([0.0, 0.06, 0.0, -0.2])
    hi = np.array([0.04, 0.3, 0.1, 0.1])
    assert list(regime_of(m, lo, hi)) == ["no_impact", "single_sided", "single_sided", "double_sided"]


def test_csv_round_trip_in_spec_column_order(reference_frf, tmp_path):
    path = reference_frf.to_csv(tmp_path / "frf.csv")
    header = path.read_text().splitlines()[0]
    assert header == ",".join((*FRF_COLUMNS, "harmonics"))  # SPEC §3 + §8
    data = read_csv(path)
    np.testing.assert_array_equal(data["omega"], reference_frf.omega)
    np.testing.assert_array_equal(data["rms"], reference_frf.rms)
    assert list(data["stable"]) == list(reference_frf.stable)
    assert set(data["regime"]) <= {"no_impact", "single_sided", "double_sided"}
    assert len(list(tmp_path.iterdir())) == 1  # no temporary file left behind


def test_container_protocol_and_summary(reference_frf):
    frf = reference_frf
    row = frf[10]
    assert list(row) == list(FRF_COLUMNS)
    assert row["omega"] == frf.omega[10]
    assert "unstable" in repr(frf) and "fold" in frf.summary()
    with pytest.raises(IndexError):
        frf.time_history(len(frf))


def test_plot_returns_handles(reference_frf):
    fig, ax = reference_frf.plot()
    labels = [l.get_label() for l in ax.get_lines()]
    assert any("unstable" in l for l in labels) and any("linear" in l for l in labels)
    assert any(l.get_linestyle() == "--" for l in ax.get_lines())
    with pytest.raises(ValueError, match="quantity"):
        reference_frf.plot(quantity="regime")


def test_linear_response_closed_form():
    from rattle.model import reference_case

    m = reference_case()
    lin = linear_frequency_response(m, np.array([1.0]))
    # At Ω = 1 = ω_n: amplitude F/(c Ω) = 0.6, rms_ac = 0.6/√2, mean F_m/k = 0.05.
    assert lin.rms_ac[0] == pytest.approx(0.6 / np.sqrt(2), rel=1e-14)
    assert lin.rms[0] == pytest.approx(np.hypot(0.05, 0.6 / np.sqrt(2)), rel=1e-14)
