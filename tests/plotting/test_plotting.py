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
from rattle.plotting import PlotAxes, compare_plot, orbit_plot, sweep_plot  # noqa: E402
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
    assert isinstance(fig, Figure) and isinstance(ax, PlotAxes) and isinstance(ax.primary, Axes)
    assert ax.get_xlabel() == "forcing frequency Ω (rad/s)"
    assert ax.get_ylabel() == "δ rms (rad)"
    labels = _texts(ax)
    assert labels[:2] == ["sweep up (Ω increasing)", "sweep down (Ω decreasing)"]
    assert "period 2" in labels  # the sub-harmonic points are ringed
    assert any(t.get_text() == "P2" for t in ax.texts)
    # drawing into given axes, another quantity, markers only
    fig2, ax2 = plt.subplots()
    out = sweep_plot(sweep, ax=ax2, quantity="acc_p2p", lines=False, annotate=False)
    assert out[0] is fig2 and out[1].primary is ax2 and dict(out[1]) == {"response": ax2}
    assert ax2.get_ylabel() == "δ'' peak-to-peak (rad/s²)"
    assert not ax2.texts


def test_sweep_result_plot_delegates(sweep) -> None:
    fig, ax = sweep.plot()
    assert isinstance(ax.primary, Axes) and ax.get_ylabel() == "δ rms (rad)"


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
    assert axes.primary is axes["delta"]
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
    assert axes.primary is ax and list(axes) == ["frf"] + [f"history_{c}" for c in "abcdefgh"[: len(comparison.at)]]
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


# --------------------------------------------------------------------------------------------
# One handle type: every plot returns (Figure, PlotAxes) with a primary Axes
# --------------------------------------------------------------------------------------------
def _check_handles(out, keys=None) -> PlotAxes:
    fig, axes = out
    assert isinstance(fig, Figure) and isinstance(axes, PlotAxes)
    assert isinstance(axes.primary, Axes) and axes.primary is axes[axes.primary_name]
    assert len(axes) >= 1 and all(isinstance(a, Axes) and a.figure is fig for a in axes.values())
    assert len({id(a) for a in axes.values()}) == len(axes)  # each panel once
    if keys is not None:
        assert list(axes) == keys
    # attribute access falls through to the primary axes
    assert axes.get_lines() == axes.primary.get_lines()
    axes.set_xlim(0.5, 1.5)
    assert axes.primary.get_xlim() == (0.5, 1.5)
    plt.close(fig)
    return axes


@pytest.fixture(scope="module")
def small(reference_model):
    """Single-element results on a narrow range with few harmonics and points."""
    from rattle.analysis import frequency_response

    return {
        "frf": frequency_response(reference_model, omega=(0.7, 0.9), harmonics=6),
        "sweep": time_sweep(reference_model, omega=(0.7, 0.9), points=2, direction="both"),
        "orbit": periodic_orbit(reference_model, 0.8, harmonics=6, search_range=(0.7, 0.9)),
        "comparison": compare(reference_model, omega=(0.7, 0.9), harmonics=6, points=3),
    }


@pytest.fixture(scope="module")
def chain_results():
    """A two-element chain (clutch and gear mesh), narrow range, few harmonics and points."""
    from test_chains import driveline

    from rattle.analysis import frequency_response

    model = driveline()
    return {
        "frf": frequency_response(model, omega=(1.0, 1.1), harmonics=4),
        "sweep": time_sweep(model, omega=(1.0, 1.1), points=2, direction="up"),
        "orbit": periodic_orbit(model, 1.05, harmonics=4, search_range=(1.0, 1.1), simulate=False),
        "comparison": compare(model, omega=(1.0, 1.1), harmonics=4, points=2, at=[1.05]),
    }


def test_every_plot_returns_figure_and_plot_axes_single_element(small) -> None:
    from rattle.demo import (
        hbm_vs_simulation_plot, level_difference, linear_vs_nonlinear_plot, mean_operating_point_plot, point_plot,
    )
    from rattle.plotting import frequency_response_plot

    frf, sweep, orbit, comparison = small["frf"], small["sweep"], small["orbit"], small["comparison"]
    for out in (frf.plot(), frequency_response_plot(frf), sweep.plot(), sweep_plot(sweep),
                hbm_vs_simulation_plot(frf, sweep)):
        _check_handles(out, ["response"])
    for out in (orbit.plot(samples=32), orbit_plot(orbit, samples=32)):
        assert _check_handles(out, ["delta", "velocity", "acceleration", "phase", "spectrum"]).primary_name == "delta"
    for out in (comparison.plot(samples=32), compare_plot(comparison, samples=32)):
        axes = _check_handles(out)
        assert axes.primary_name == "frf" and axes["histories"] == [axes[k] for k in list(axes)[1:]]
        assert "histories" in axes and "histories" not in list(axes)
    assert list(_check_handles(linear_vs_nonlinear_plot(frf, level_difference(frf, (0.7, 0.9))))) == ["response", "level"]
    assert list(_check_handles(point_plot(orbit, samples=32))) == ["delta", "phase", "spectrum"]
    assert list(_check_handles(mean_operating_point_plot(frf))) == ["mean", "range"]
    # drawing into given axes (also a PlotAxes): the result wraps those axes
    fig, ax = plt.subplots()
    for draw in (frf.plot, sweep.plot, lambda ax: hbm_vs_simulation_plot(frf, sweep, ax=ax)):
        out_fig, out = draw(ax=ax)
        assert out_fig is fig and out.primary is ax and dict(out) == {"response": ax}
        assert draw(ax=out)[1].primary is ax


def test_every_plot_returns_figure_and_plot_axes_two_element_chain(chain_results) -> None:
    from rattle.plotting import frequency_response_plot

    frf, sweep, orbit, comparison = (chain_results[k] for k in ("frf", "sweep", "orbit", "comparison"))
    for out in (frf.plot(), frequency_response_plot(frf), sweep.plot(), sweep_plot(sweep)):
        axes = _check_handles(out, ["clutch", "gear"])
        assert axes.primary_name == "clutch"
    fig, ax = frf.plot()
    assert ax["gear"].get_title() == "element gear" and ax.get_title().endswith("element clutch")
    for out in (orbit.plot(samples=32), orbit_plot(orbit, samples=32)):
        axes = _check_handles(out, ["clutch_delta", "clutch_acceleration", "gear_delta", "gear_acceleration",
                                    "phase", "spectrum"])
        assert axes.primary_name == "clutch_delta" and axes["delta"] is axes["clutch_delta"]
    for out in (comparison.plot(samples=32), compare_plot(comparison, samples=32)):
        axes = _check_handles(out, ["clutch_frf", "gear_frf", "clutch_history_a", "gear_history_a"])
        assert axes.primary_name == "clutch_frf" and axes["frf"] is axes.primary
        assert axes["element_histories"]["gear"] == [axes["gear_history_a"]]
    # a chain drawn into one given axes: one panel
    fig, ax = plt.subplots()
    assert dict(frf.plot(ax=ax)[1]) == {"response": ax} and dict(sweep.plot(ax=ax)[1]) == {"response": ax}


def test_plot_axes_is_a_dict_with_a_primary() -> None:
    fig, (a, b) = plt.subplots(2)
    axes = PlotAxes({"top": a, "bottom": b}, primary="bottom", aliases={"both": [a, b]})
    assert axes.primary is b and axes.primary_name == "bottom" and list(axes) == ["top", "bottom"]
    assert axes["both"] == [a, b] and "both" in axes and axes.get("both") == [a, b] and len(axes) == 2
    axes.set_ylabel("y")  # the primary's
    assert b.get_ylabel() == "y" and a.get_ylabel() == ""
    with pytest.raises(KeyError, match="no panel 'side'"):
        axes["side"]
    with pytest.raises(AttributeError):
        axes.no_such_method  # noqa: B018
    with pytest.raises(ValueError, match="`primary`"):
        PlotAxes({"top": a}, primary="bottom")
    with pytest.raises(ValueError, match="`panels`"):
        PlotAxes({})
    assert "PlotAxes(['top', 'bottom'], primary='bottom')" == repr(axes)


def test_sweep_and_orbit_png_are_the_files_savefig_writes(sweep, orbit) -> None:
    """The command line's PNG drawn once is byte for byte savefig's (see test_png_once.py)."""
    import io

    from rattle.cli.output import FIGURE_DPI, write_png

    for result in (sweep, orbit):
        a, b = io.BytesIO(), io.BytesIO()
        result.plot()[0].savefig(a, format="png", dpi=FIGURE_DPI)
        write_png(result.plot()[0], b, FIGURE_DPI)
        assert a.getvalue()[:8] == b"\x89PNG\r\n\x1a\n" and a.getvalue() == b.getvalue()
