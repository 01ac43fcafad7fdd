"""The labels of the figures never overlap each other or a tick label (issue 27): the text
boxes of every visible label, measured with the Agg renderer after the figure is drawn."""

from __future__ import annotations

import dataclasses

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.text import Text  # noqa: E402

from rattle import Region, time_sweep  # noqa: E402
from rattle.plotting import frequency_response_plot, sweep_plot  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _boxes(fig, ax):
    fig.canvas.draw()  # the layout as saved
    renderer = fig.canvas.get_renderer()
    labels = [Text.get_window_extent(t, renderer) for t in ax.texts if t.get_visible() and t.get_text()]
    ticks = [t.get_window_extent(renderer) for t in (*ax.get_xticklabels(), *ax.get_yticklabels())
             if t.get_visible() and t.get_text()]
    return labels, ticks, ax.get_window_extent(renderer)


def _assert_apart(fig, axes):
    shown = 0
    for ax in axes:
        labels, ticks, box = _boxes(fig, ax)
        shown += len(labels)
        for i, a in enumerate(labels):
            assert a.y0 >= box.y0 - 1 and a.y1 <= box.y1 + 1 and a.x0 >= box.x0 - 1 and a.x1 <= box.x1 + 1, \
                "a label leaves its axes"
            for b in labels[i + 1:]:
                assert not a.overlaps(b), (a, b)
            for b in ticks:
                assert not a.overlaps(b), ("a label over a tick label", a, b)
    return shown


@pytest.fixture(scope="module")
def crowded_sweep(reference_model):
    """A sweep whose period changes every row or two (as a preload's between Ω 0.45 and 0.95):
    labels P2, P0, P7, P4, P5 side by side."""
    sweep = time_sweep(reference_model, omega=(0.45, 0.95), points=14, direction="both")
    period = np.array([2, 2, 0, 7, 4, 4, 5, 1, 2, 0, 7, 1, 4, 5] * 2)
    return dataclasses.replace(sweep, period=period)


def test_sweep_period_labels_do_not_overlap(crowded_sweep) -> None:
    fig, ax = sweep_plot(crowded_sweep)
    assert _assert_apart(fig, [ax.primary]) >= 3  # labels are kept where there is room


def test_frf_band_and_order_labels_do_not_overlap(reference_frf_all) -> None:
    # the computed regions (period 2 bands, 1/k labels) and crowded hatched ones beside them
    # (the chain's "none stable" next to "sim: P8", a band at the axes' left edge)
    extra = (Region("no_stable_computed", 2.2, 2.3, "none stable", {"sweep_periods": [8]}),
             Region("unstable_not_computed", 2.3, 2.4, "P1 unstable", {"sweep_periods": [0, 8]}),
             Region("subharmonic", 0.1, 0.13, "period 2", {"period": 2}),
             Region("subharmonic", 0.13, 0.16, "period 2", {"period": 2}))
    frf = dataclasses.replace(reference_frf_all, regions=tuple(reference_frf_all.regions) + extra)
    fig, ax = frequency_response_plot(frf)
    assert _assert_apart(fig, [ax.primary]) >= 4
    texts = [t.get_text() for t in ax.texts if t.get_visible()]
    assert texts.count("period 2") <= sum(r.kind == "subharmonic" for r in frf.regions) - 1  # touching bands: one


def test_compare_sweep_points_are_inside_the_axes(reference_frf_all, crowded_sweep) -> None:
    # frequency_response_plot freezes its y limits (room for the band labels); the sweep drawn
    # over it afterwards must still fit
    fig, ax = frequency_response_plot(reference_frf_all, legend="none")
    big = dataclasses.replace(crowded_sweep, rms=crowded_sweep.rms * 3.0)
    sweep_plot(big, ax=ax, lines=False, title="")
    from rattle.plotting import fit_ylim

    fit_ylim(ax.primary)
    lo, hi = ax.primary.get_ylim()
    assert lo <= np.nanmin(big.rms) and hi >= np.nanmax(big.rms)


# --- orbit.png on every law kind (issue 27): points inside, legends over no data, texts apart ---
def _all_axes(fig):
    """The figure's axes and their child axes (a secondary axis in another unit)."""
    out = []
    for ax in fig.axes:
        out += [ax, *ax.child_axes]
    return [a for a in out if a.get_visible()]


def _texts_apart(fig):
    """Every visible text of the figure (titles, axis labels, the tick labels drawn, legend
    entries, the suptitle) overlaps no other, and none leaves the figure."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    texts = [fig._suptitle] if fig._suptitle is not None else []
    for leg in fig.legends:
        texts += leg.get_texts()
    for ax in _all_axes(fig):
        texts += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label]
        if ax.get_legend() is not None:
            texts += ax.get_legend().get_texts()
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            for tick in axis.get_major_ticks():
                if lo - 1e-9 * (hi - lo) <= tick.get_loc() <= hi + 1e-9 * (hi - lo):
                    texts += [t for t in (tick.label1, tick.label2) if t.get_visible()]
    page = fig.bbox
    boxes = []
    for t in texts:
        if t is None or not (t.get_visible() and t.get_text().strip()):
            continue
        bb = Text.get_window_extent(t, renderer)
        assert bb.x0 >= page.x0 - 1 and bb.x1 <= page.x1 + 1 and bb.y0 >= page.y0 - 1 and bb.y1 <= page.y1 + 1, \
            ("a text leaves the figure", t.get_text())
        boxes.append((t.get_text(), bb.shrunk(0.98, 0.9)))
    for i, (a, ba) in enumerate(boxes):
        for b, bb in boxes[i + 1:]:
            assert not ba.overlaps(bb), ("texts overlap", a, b)
    return len(boxes)


def _points_inside_and_legends_clear(fig, axes):
    """Every point of every data line of ``axes`` (markers and vertices) inside its axes' limits,
    and no legend inside an axes covers one of its points."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in axes:
        (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
        pts = []
        for line in ax.get_lines():
            if line.get_transform() != ax.transData or not line.get_visible():
                continue
            x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
            ok = np.isfinite(x) & np.isfinite(y)
            x, y = x[ok], y[ok]
            assert np.all((x >= x0 - 1e-9 * abs(x1 - x0)) & (x <= x1 + 1e-9 * abs(x1 - x0))), \
                ("a point left of or right of its axes", line.get_label())
            assert np.all((y >= y0 - 1e-9 * abs(y1 - y0)) & (y <= y1 + 1e-9 * abs(y1 - y0))), \
                ("a point below or above its axes", line.get_label(), y.min(), y.max(), (y0, y1))
            pts.append(ax.transData.transform(np.column_stack([x, y])))
        legend = ax.get_legend()
        if legend is not None and pts:
            box = legend.get_window_extent(renderer)
            p = np.concatenate(pts)
            inside = (p[:, 0] > box.x0) & (p[:, 0] < box.x1) & (p[:, 1] > box.y0) & (p[:, 1] < box.y1)
            assert not inside.any(), ("a legend covers data", ax.get_title(), int(inside.sum()))


@pytest.fixture(scope="module")
def examples():
    from pathlib import Path

    return Path(__file__).resolve().parents[2] / "examples"


def test_orbit_plot_of_a_smooth_law_and_a_chain(reference_model, examples) -> None:
    from rattle.analysis import periodic_orbit
    from rattle.io import load_config

    for model in (reference_model, load_config(examples / "driveline_three_inertia.toml").model):
        orbit = periodic_orbit(model, 0.85)
        fig, ax = orbit.plot()
        assert len(orbit.solutions) >= 2
        _points_inside_and_legends_clear(fig, list(ax.values()))
        assert _texts_apart(fig) > 20
        plt.close(fig)


def test_orbit_plot_of_an_engine_case_names_rpm_and_degrees(examples) -> None:
    from rattle.analysis import periodic_orbit
    from rattle.io import load_config

    rc = load_config(examples / "engine_clutch_si.toml")  # b_deg = 4: angles given in degrees
    omega = 900.0 * 2.0 * 2.0 * np.pi / 60.0  # 900 rpm, order 2
    orbit = periodic_orbit(rc.model, omega, harmonics=16)
    fig, ax = orbit.plot(degrees=True)
    assert "900 rpm" in fig.get_suptitle()
    labels = [a.get_ylabel() for a in _all_axes(fig)] + [a.get_xlabel() for a in _all_axes(fig)]
    assert "(deg)" in labels and "δ (deg)" in labels  # the δ panels and the phase portrait in degrees too
    _points_inside_and_legends_clear(fig, list(ax.values()))
    _texts_apart(fig)  # the phase portrait's tick labels no longer run into each other
    plt.close(fig)


def test_orbit_plot_of_a_preload_shows_every_orbit_at_the_speed(examples) -> None:
    """torque_converter_preload at Ω = 0.9: three orbits coexist (two of period 3); the phase
    portrait draws each, the legend names its period and stability."""
    from rattle.analysis import nonsmooth_orbit
    from rattle.io import load_config

    rc = load_config(examples / "torque_converter_preload.toml")
    result = nonsmooth_orbit(rc.model, 0.9)
    assert len(result.solutions) >= 2
    fig, ax = result.plot()
    legend = " | ".join(t.get_text() for t in fig.legends[0].get_texts())
    for i, sol in enumerate(result.solutions):
        assert f"orbit [{i}] at Ω: period {sol.period}, {'stable' if sol.stable else 'unstable'}" in legend
    others = [s for s in result.solutions if not (s.period == result.periods and abs(s.rms - result.rms) < 1e-6 * result.rms)]
    drawn = [line for line in ax["phase"].get_lines() if line.get_label().startswith("orbit [")
             and len(line.get_xdata())]
    assert len(drawn) == len(others) >= 1
    assert not ax["delta"].get_legend() and not ax["phase"].get_legend()  # one legend, below the panels
    _points_inside_and_legends_clear(fig, list(ax.values()))
    _texts_apart(fig)
    plt.close(fig)


def test_orbit_plot_of_friction_laws(examples) -> None:
    from rattle.analysis import nonsmooth_orbit
    from rattle.io import load_config

    rc = load_config(examples / "clutch_friction.toml")
    fig, ax = nonsmooth_orbit(rc.model, 0.8).plot()
    _points_inside_and_legends_clear(fig, list(ax.values()))
    _texts_apart(fig)
    plt.close(fig)
