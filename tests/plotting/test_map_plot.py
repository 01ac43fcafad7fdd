"""The response map's heat map (plot_map): handles, panels, the hatched impacts, the rattle-free
outline, the grey of no stable period-1 solution, and a PNG written."""

from __future__ import annotations

import numpy as np
import pytest

from rattle.plotting import PlotAxes, plot_map
from rattle.plotting._map import NO_SOLUTION_COLOR, RATTLE_HATCH, _outline, map_plot_names

from _fake_map import synthetic_map


def test_one_parameter_one_panel_with_colorbar(tmp_path):
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, QuadMesh

    m = synthetic_map(("alpha",), ((0.0, 0.1, 0.2, 0.3),), points=25)
    fig, ax = plot_map(m)
    try:
        assert isinstance(ax, PlotAxes) and list(ax) == ["map", "colorbar"] and ax.primary is ax["map"]
        assert ax.get_xlabel() == "Ω (rad/s)" and ax.get_ylabel() == "alpha (model.elastic.alpha)"
        assert "rms" in ax["colorbar"].get_ylabel()
        (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
        data = mesh.get_array()
        assert data.shape == (4, 25) and data.mask.any()  # the NaN holes are masked (drawn grey)
        assert mesh.get_cmap().get_bad()[:3] == pytest.approx([float(NO_SOLUTION_COLOR)] * 3)
        hatched = [p for p in ax.patches if p.get_hatch() == RATTLE_HATCH]
        rattle_runs = sum(len(c.intervals["impact"]) for c in m.cells)
        assert len(hatched) == rattle_runs  # one hatched rectangle per run of impacting cells
        outlines = [c for c in ax.collections if isinstance(c, LineCollection)]
        assert outlines and len(outlines[0].get_segments()) > 0
        fig.savefig(tmp_path / "map.png")
        assert (tmp_path / "map.png").read_bytes().startswith(b"\x89PNG")
    finally:
        plt.close(fig)


def test_two_parameters_one_panel_per_value_of_the_other():
    import matplotlib.pyplot as plt

    m = synthetic_map(("alpha", "b"), ((0.1, 0.2), (0.1, 0.2, 0.3)), points=12)
    fig, ax = plot_map(m)
    try:
        assert list(ax) == ["map_1", "map_2", "map_3", "colorbar"]
        assert ax["map_2"].get_title() == "b = 0.2" and ax["map_1"].get_ylabel().startswith("alpha")
    finally:
        plt.close(fig)
    fig, ax = plot_map(m, parameter="b")
    try:
        assert [ax[k].get_title() for k in ("map_1", "map_2")] == ["alpha = 0.1", "alpha = 0.2"]
    finally:
        plt.close(fig)
    assert map_plot_names(m) == [("map.png", "alpha"), ("map_b.png", "b")]
    with pytest.raises(ValueError, match="`parameter` must be one of"):
        plot_map(m, parameter="damping")


def test_a_single_value_and_a_given_axes():
    import matplotlib.pyplot as plt

    m = synthetic_map(("alpha",), ((0.25,),), points=10)
    fig, own = plt.subplots()
    try:
        fig2, ax = plot_map(m, ax=own)
        assert fig2 is fig and ax.primary is own
        lo, hi = own.get_ylim()
        assert lo < 0.25 < hi
    finally:
        plt.close(fig)


def test_outline_is_the_boundary_between_free_and_impacting_cells():
    free = np.array([[True, True, False], [True, False, False]])
    xe, ye = np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 1.0, 2.0])
    segs = {tuple(map(tuple, s)) for s in _outline(free, xe, ye)}
    assert segs == {((2.0, 0.0), (2.0, 1.0)), ((1.0, 1.0), (1.0, 2.0)), ((1.0, 1.0), (2.0, 1.0))}
    assert _outline(np.ones((2, 3), bool), xe, ye) == []  # all free: the frame is the outline


def test_a_long_key_is_shortened_and_an_angle_has_its_units():
    """Issue 27: "model.elements.damper.breakpoints.4 (model.elements.1.breakpoints.4)" was cut at
    both ends, without a unit; now the NAME without its head, in rad, with degrees on the right."""
    import matplotlib.pyplot as plt

    m = synthetic_map(("model.elements.damper.breakpoints.4",), ((0.05, 0.07, 0.09),),
                      keys=("model.elements.1.breakpoints.4",), points=20)
    fig, ax = plot_map(m)
    try:
        assert ax.get_ylabel() == "damper.breakpoints.4 (rad)"
        fig.canvas.draw()
        label = ax.yaxis.label.get_window_extent(fig.canvas.get_renderer())
        assert label.y0 >= 0 and label.y1 <= fig.bbox.height  # the whole label on the figure
        (right,) = [c for c in ax.child_axes if "deg" in c.get_ylabel()]
        lo, hi = right.get_ylim()
        assert lo == pytest.approx(np.degrees(ax.get_ylim()[0])) and hi == pytest.approx(np.degrees(ax.get_ylim()[1]))
    finally:
        plt.close(fig)
