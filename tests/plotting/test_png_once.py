"""The command line's PNG, drawn once (``rattle.cli.output.write_png``), is byte for byte the file
``Figure.savefig(format="png", dpi=150)`` writes: a constrained-layout figure (frf; the sweep
and orbit plots in test_plotting.py, with its fixtures), one laid out by ``tight_layout`` at
drawing time, one without a layout, multi-panel ones; and with a matplotlibrc that changes the
picture (tight bounding box, transparent, a coloured background) it is savefig's own file."""

from __future__ import annotations

import io

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from rattle.cli.output import FIGURE_DPI, write_png


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def both(make) -> tuple[bytes, bytes]:
    a, b = io.BytesIO(), io.BytesIO()
    fig = make()
    fig.savefig(a, format="png", dpi=FIGURE_DPI)
    fig = make()
    write_png(fig, b, FIGURE_DPI)
    return a.getvalue(), b.getvalue()


def _lines(layout):
    def make():
        fig, axes = plt.subplots(2, 1, figsize=(6, 4), layout=layout)
        x = np.linspace(0.0, 3.0, 300)
        axes[0].plot(x, np.sin(3 * x), "-", label="stable")
        axes[0].plot(x, np.cos(2 * x), "--", label="unstable")
        axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
        axes[1].semilogy(x, 1 + x**2, "o", ms=2)
        axes[1].set_xlabel("Ω (rad/s)")
        fig.suptitle("Non-linear frequency response (H = 32)")
        if layout is None:
            fig.tight_layout()
        return fig
    return make


@pytest.mark.parametrize("layout", ["constrained", None, "none"])
def test_a_figure_is_the_file_savefig_writes(layout) -> None:
    a, b = both(_lines(layout))
    assert a[:8] == b"\x89PNG\r\n\x1a\n" and a == b


def test_the_reference_frf_plot_is_the_file_savefig_writes(reference_frf) -> None:
    a, b = both(lambda: reference_frf.plot()[0])
    assert a == b


@pytest.mark.parametrize("rc", [{"savefig.bbox": "tight"}, {"savefig.transparent": True},
                                {"savefig.facecolor": "yellow"}])
def test_settings_that_change_the_picture_are_savefigs(rc) -> None:
    with matplotlib.rc_context(rc):
        a, b = both(_lines("constrained"))
    assert a == b
