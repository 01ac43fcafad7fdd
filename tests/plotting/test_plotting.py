"""Plots return (figure, axes) handles, label their axes with units and carry legends."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from rattle.analysis import compare, periodic_orbit, time_sweep  # noqa: E402
from rattle.plotting import compare_plot, orbit_plot, sweep_plot  # noqa: E402
from rattle.plotting._orbit import window_periods  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def sweep(reference_model):
    # 12 frequencies each way over the resonance and the period-2 region
    return time_sweep(reference_model, omega=(0.6, 1.6), points=12, direction="both")


@pytest.fixture(scope="module")
def orbit(reference_model, reference_frf):
    return periodic_orbit(reference_model, 1.41, period=2, frf=reference_frf)


@pytest.fixture(scope="module")
def comparison(reference_model):
    return compare(reference_model, omega=(0.6, 1.6), harmonics=16, points=12)


def _texts(ax: Axes) -> list[str]:
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


def test_sweep_plot_handles_and_labels(sweep) -> None:
    fig, ax = sweep_plot(sweep)
    assert isinstance(fig, Figure) and isinstance(ax, Axes)
    assert ax.get_xlabel() == "forcing frequency Ω (rad/s)"
    assert ax.get_ylabel() == "δ rms (rad)"
    labels = _texts(ax)
    assert labels[:2] == ["sweep up (Ω increasing)", "sweep down (Ω decreasing)"]
    assert "period 2" in labels  # the sub-harmonic points are ringed
    assert any(t.get_text() == "P2" for t in ax.texts)
    # drawing into given axes, another quantity, markers only
    fig2, ax2 = plt.subplots()
    out = sweep_plot(sweep, ax=ax2, quantity="acc_p2p", lines=False, annotate=False)
    assert out == (fig2, ax2)
    assert ax2.get_ylabel() == "δ'' peak-to-peak (rad/s²)"
    assert not ax2.texts


def test_sweep_result_plot_delegates(sweep) -> None:
    fig, ax = sweep.plot()
    assert isinstance(ax, Axes) and ax.get_ylabel() == "δ rms (rad)"


def test_sweep_plot_period_zero_label(sweep) -> None:
    import dataclasses

    period = sweep.period.copy()
    period[3] = 0
    fig, ax = sweep_plot(dataclasses.replace(sweep, period=period))
    assert "no period ≤ 8 (quasi-periodic or chaotic)" in _texts(ax)
    assert any(t.get_text() == "P0" for t in ax.texts)


def test_sweep_plot_rejects_unknown_quantity(sweep) -> None:
    with pytest.raises(ValueError, match="`quantity`"):
        sweep_plot(sweep, quantity="regime")


def test_orbit_plot_handles_and_labels(orbit) -> None:
    fig, axes = orbit.plot()
    assert isinstance(fig, Figure)
    assert set(axes) == {"delta", "velocity", "acceleration", "phase", "spectrum"}
    assert axes["delta"].get_ylabel() == "δ (rad)"
    assert axes["velocity"].get_ylabel() == "δ' (rad/s)"
    assert axes["acceleration"].get_ylabel() == "δ'' (rad/s²)"
    assert axes["acceleration"].get_xlabel().startswith("time t (s)")
    assert (axes["phase"].get_xlabel(), axes["phase"].get_ylabel()) == ("δ (rad)", "δ' (rad/s)")
    assert axes["spectrum"].get_xlabel() == "frequency / Ω"
    assert axes["spectrum"].get_yscale() == "log"
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend[0].startswith("HB 0: period 2, stable") and legend[0].endswith("(selected)")
    assert legend[1].startswith("HB 1: period 1, unstable")
    assert "simulation, period 2" in legend
    # the window covers two forcing periods (a period-2 orbit)
    assert axes["delta"].get_xlim()[1] == pytest.approx(2 * 2 * np.pi / 1.41)
    # unstable solutions are dashed
    styles = {line.get_label(): line.get_linestyle() for line in axes["delta"].get_lines()}
    assert styles[legend[0]] == "-" and styles[legend[1]] == "--"


def test_orbit_plot_into_a_given_figure(orbit) -> None:
    fig = plt.figure()
    out_fig, axes = orbit_plot(orbit, fig=fig, periods=4, samples=32, title="custom")
    assert out_fig is fig and fig._suptitle.get_text() == "custom"
    assert axes["delta"].get_xlim()[1] == pytest.approx(4 * 2 * np.pi / 1.41)


def test_window_periods() -> None:
    assert window_periods([1, 2]) == 2
    assert window_periods([2, 3]) == 6
    assert window_periods([3, 5]) == 5  # lcm 15 > 8: the longest
    assert window_periods([0]) == 1


def test_compare_plot_handles_and_labels(comparison) -> None:
    fig, axes = comparison.plot()
    assert isinstance(fig, Figure)
    ax = axes["frf"]
    assert ax.get_xlabel() == "forcing frequency Ω (rad/s)" and ax.get_ylabel() == "δ rms (rad)"
    labels = _texts(ax)
    assert "branch 0, stable" in labels and "branch 0, unstable" in labels
    assert "sweep up (Ω increasing)" in labels and "sweep down (Ω decreasing)" in labels
    panels = axes["histories"]
    assert len(panels) == len(comparison.at) >= 1
    for panel in panels:
        assert panel.get_xlabel() == "time t (s)"
        assert any(text.startswith("HB P") for text in _texts(panel))
        assert any("sweep" in text for text in _texts(panel))
    assert panels[0].get_ylabel() == "δ (rad)"
    out = compare_plot(comparison, fig=plt.figure(), samples=32, title="t")
    assert out[0]._suptitle.get_text() == "t"
