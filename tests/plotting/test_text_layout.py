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
