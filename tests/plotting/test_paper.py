"""The paper's figures and the numbers behind them: the frequency-response plot with every
branch, special points and regions; Figures 4–7 and the mean operating point (handles, labels);
the linear-vs-non-linear level difference; the markdown report."""

from __future__ import annotations

import dataclasses
import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from rattle import Region, periodic_orbit, time_sweep  # noqa: E402
from rattle.model import Excitation  # noqa: E402
from rattle.demo import (  # noqa: E402
    DEMO_DATA, DEMO_FIGURES, PaperDemo, demo_case, demo_report, hbm_vs_simulation_plot, level_difference, linear_acceleration_p2p, linear_vs_nonlinear_plot,
    mean_operating_point_plot, point_plot, simulated_window, stage_intervals,
)
from rattle.plotting import frequency_response_plot  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def frf(reference_frf_all):
    return reference_frf_all


@pytest.fixture(scope="module")
def sweep(reference_model):
    # 10 frequencies each way across the primary resonance: one jump in each direction
    return time_sweep(reference_model, omega=(0.7, 0.95), points=10, direction="both")


@pytest.fixture(scope="module")
def orbits(reference_model, frf):
    return {name: periodic_orbit(reference_model, w, period=2, frf=frf) for name, w in (("A", 0.44), ("B", 1.41))}


@pytest.fixture(scope="module")
def level(frf):
    return level_difference(frf)


def _legend(ax: Axes) -> list[str]:
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


def _texts(ax: Axes) -> list[str]:
    return [t.get_text() for t in ax.texts]


# --------------------------------------------------------------------------------------------
# frequency_response_plot with every branch
# --------------------------------------------------------------------------------------------
def test_frf_plot_draws_every_branch_special_points_and_regions(frf) -> None:
    fig, ax = frequency_response_plot(frf)
    assert isinstance(fig, Figure) and isinstance(ax.primary, Axes) and list(ax) == ["response"]
    labels = _legend(ax)
    for text in ("branch 0, stable", "branch 0, unstable", "branch 1 (period 2), stable",
                 "branch 2 (period 2), stable", "fold ○", "period doubling □", "linear system (f = δ)",
                 "period 2 stable (1/2 sub-harmonic)"):
        assert text in labels, (text, labels)
    # each branch its colour; unstable stretches dashed
    lines = {l.get_label(): l for l in ax.get_lines()}
    colours = {lines[f"branch {b}{s}, stable"].get_color() for b, s in ((0, ""), (1, " (period 2)"), (2, " (period 2)"))}
    assert len(colours) == 3
    assert lines["branch 0, unstable"].get_linestyle() == "--"
    # every special point is marked: fold ○ and period doubling □ (the branch-birth rows too)
    fold = lines["fold ○"]
    pd = lines["period doubling □"]
    n_fold = sum(sp.kind == "fold" for sp in frf.special_points)
    n_pd = sum(sp.kind == "period_doubling" for sp in frf.special_points)
    assert len(fold.get_xdata()) == n_fold and fold.get_marker() == "o"
    assert len(pd.get_xdata()) == n_pd and pd.get_marker() == "s"
    # the sub-harmonic bands and their labels, the super-harmonic orders at the peaks
    assert _texts(ax).count("period 2") == sum(r.kind == "subharmonic" for r in frf.regions) == 2
    for k in (2, 3, 4):
        assert f"1/{k}" in _texts(ax)
    # the legend sits outside the axes, to the right
    assert ax.get_legend().get_bbox_to_anchor().x0 > ax.get_window_extent().x1 - 1
    assert "H = 32" in ax.get_title()


def test_frf_plot_options(frf) -> None:
    region = Region("no_stable_periodic", 2.2, 2.5, "no stable periodic solution")
    hatched = dataclasses.replace(frf, regions=(region,))
    fig, ax = frequency_response_plot(hatched, legend="inside")
    assert any(p.get_hatch() == "//" for p in ax.patches)
    assert "no stable periodic solution" in _legend(ax)
    assert "no stable\nperiodic" in _texts(ax)
    fig2, ax2 = plt.subplots()
    out = frequency_response_plot(frf, ax=ax2, regions=False, special_points=False, linear=False, legend="none",
                                  quantity="mean", title="t")
    assert out[0] is fig2 and out[1].primary is ax2
    assert not ax2.patches and not ax2.texts and ax2.get_legend() is None
    assert ax2.get_ylabel() == "δ mean δ_m (rad)" and ax2.get_title() == "t"
    # regions given explicitly (e.g. confirmed by a sweep) replace frf.regions
    _f, ax3 = frequency_response_plot(frf, regions=[region])
    assert "period 2" not in _texts(ax3) and "no stable\nperiodic" in _texts(ax3)
    with pytest.raises(ValueError, match="`legend`"):
        frequency_response_plot(frf, legend="left")
    with pytest.raises(ValueError, match="`quantity`"):
        frequency_response_plot(frf, quantity="regime")


# --------------------------------------------------------------------------------------------
# The level difference (Figure 4's numbers)
# --------------------------------------------------------------------------------------------
def test_linear_acceleration_p2p_closed_form(reference_model) -> None:
    # At Ω = 1 = ω_n: |X_1| = F/(cΩ) = 0.03/0.05 = 0.6, so p2p δ'' = 2 Ω² |X_1| = 1.2
    assert linear_acceleration_p2p(reference_model, [1.0])[0] == pytest.approx(1.2, rel=1e-14)
    w = np.array([0.3, 0.7, 2.0])
    x = 0.03 / np.abs(1.0 - w**2 + 0.05j * w)
    np.testing.assert_allclose(linear_acceleration_p2p(reference_model, w), 2 * w**2 * x, rtol=1e-14)
    # two harmonics: sampled; with the second at zero amplitude it equals the closed form
    two = dataclasses.replace(reference_model, excitation=Excitation(mean=0.05, amplitudes=(0.03, 0.0)))
    np.testing.assert_allclose(linear_acceleration_p2p(two, w, samples=4096), 2 * w**2 * x, rtol=1e-6)


def test_level_difference_numbers(frf, level) -> None:
    assert level.band == (0.6, 0.8)
    inside = (frf.omega >= 0.6) & (frf.omega <= 0.8)
    assert level.omega.size == int(inside.sum()) and np.array_equal(level.rows, np.flatnonzero(inside))
    np.testing.assert_allclose(
        level.db, 20 * np.log10(frf.acc_p2p[inside] / linear_acceleration_p2p(frf.model, frf.omega[inside])), rtol=1e-12
    )
    # The numbers the report quotes (acceleration p2p, stable solutions; 0.05 dB: continuation
    # grid and H = 32 truncation)
    assert level.db_max == pytest.approx(17.39, abs=0.05)
    assert level.omega_at_max == pytest.approx(0.652, abs=0.01)
    assert level.db_min == pytest.approx(7.41, abs=0.1)  # the lower stable branch near Ω = 0.8
    assert level.omega_at_min == pytest.approx(0.797, abs=0.005)
    s_lo, s_hi, d_lo, d_hi = level.single_valued_range()
    assert s_lo == pytest.approx(0.6, abs=0.005) and s_hi == pytest.approx(0.7539, abs=0.005)
    assert d_lo == pytest.approx(16.6, abs=0.1) and d_hi == pytest.approx(level.db_max)
    # the paper's "at least 20 dB" is not what the exact solution gives
    assert level.db_max < 20.0
    text = level.summary()
    assert f"{level.db_min:.1f} … {level.db_max:.1f} dB" in text
    with pytest.raises(ValueError, match="`band`"):
        level_difference(frf, band=(0.8, 0.6))
    with pytest.raises(ValueError, match="holds no row"):
        level_difference(frf, band=(3.5, 4.0))


def test_stage_intervals(frf) -> None:
    b = frf.model.elastic.b
    below = stage_intervals(frf, b)
    above = stage_intervals(frf, b, below=False)
    assert below[0][0] == pytest.approx(0.1) and 1.6 < below[-1][1] < 1.8
    assert above[-1][1] == pytest.approx(3.0)


# --------------------------------------------------------------------------------------------
# Figures 4–7 and the mean operating point
# --------------------------------------------------------------------------------------------
def test_linear_vs_nonlinear_plot(frf, level) -> None:
    fig, axes = linear_vs_nonlinear_plot(frf, level)
    assert isinstance(fig, Figure) and set(axes) == {"response", "level"}
    assert "linear system (f = δ)" in _legend(axes["response"])
    ax = axes["level"]
    assert ax.get_xlim() == (0.6, 0.8)
    assert any(np.allclose(l.get_ydata(), 20.0) for l in ax.get_lines())  # the paper's 20 dB
    assert f"max {level.db_max:.1f} dB at Ω = {level.omega_at_max:.3f}" in _texts(ax)
    assert f"min {level.db_min:.1f} dB at Ω = {level.omega_at_min:.3f}" in _texts(ax)


def test_hbm_vs_simulation_plot_annotates_the_jumps(frf, sweep) -> None:
    fig, ax = hbm_vs_simulation_plot(frf, sweep)
    assert isinstance(fig, Figure) and isinstance(ax.primary, Axes)
    labels = _legend(ax)
    assert "sweep up (Ω increasing)" in labels and "sweep down (Ω decreasing)" in labels
    assert "branch 0, unstable" in labels
    jumps = [t for t in _texts(ax) if "jump" in t]
    assert len(jumps) == len(sweep.jumps()) == 2
    assert any("HB fold at Ω = 0.8744" in t for t in jumps) and any("HB fold at Ω = 0.7539" in t for t in jumps)


def test_point_plots(orbits) -> None:
    fig, axes = point_plot(orbits["A"], name="A", note="(the paper: quasi-periodic)")
    assert isinstance(fig, Figure) and set(axes) == {"delta", "phase", "spectrum"}
    title = fig._suptitle.get_text()
    assert "Point A" in title and "period 2" in title and "quasi-periodic" in title
    labels = _legend(axes["delta"])
    assert any(t.startswith("HB period 2, stable") for t in labels)
    assert any(t.startswith("HB period 1, unstable") for t in labels)
    assert any(t.startswith("exact simulation: period 2") for t in labels)
    assert "(2 distinct points)" in _legend(axes["phase"])[0]  # stroboscopic points of a period-2 motion
    fig, axes = point_plot(orbits["B"], name="B", spectrum=False, periods=2)
    assert set(axes) == {"delta", "phase"}


def test_simulated_window_matches_the_period_2_orbit(orbits) -> None:
    for orbit in orbits.values():
        win = simulated_window(orbit, periods=4, samples=128)
        assert win is not None and win["period"] == 2 and win["t"].size == 4 * 128 + 1
        # exact simulation vs HB (H = 32): the same orbit after the shift by whole forcing periods
        assert win["error"] < 1e-4


def test_mean_operating_point_plot(frf) -> None:
    fig, axes = mean_operating_point_plot(frf)
    assert isinstance(fig, Figure) and set(axes) == {"mean", "range"}
    b = frf.model.elastic.b
    ys = [l.get_ydata()[0] for l in axes["range"].get_lines() if len(l.get_ydata()) == 2 and l.get_linestyle() == ":"]
    assert any(math.isclose(y, b) for y in ys) and any(math.isclose(y, -b) for y in ys)
    assert any(t.startswith("static equilibrium") for t in _legend(axes["mean"]))
    assert "first stage (slope 0.25)" in _texts(axes["mean"])


# --------------------------------------------------------------------------------------------
# The report
# --------------------------------------------------------------------------------------------
def test_demo_report_text(frf, sweep, orbits, level) -> None:
    figures = {"frf": "frf.png", "fig4": "fig4_linear_vs_nonlinear.png", "fig5": "fig5_hbm_vs_simulation.png",
               "fig6": "fig6_point_A.png", "fig7": "fig7_point_B.png", "mean": "fig_mean_operating_point.png"}
    text = demo_report(frf, sweep, orbits=orbits, level=level, figures=figures, data_files=["frf.csv"],
                       timings={"frf": 1.2, "sweep": 0.9, "total": 4.0})
    assert text.endswith("\n")
    for name in figures.values():
        assert f"]({name})" in text  # relative links
    for sp in frf.special_points:  # the table: one row per special point
        assert f"| {sp.branch} | {int(frf.period[sp.index])} | {sp.omega:.5f} |" in text
    for w in ("0.7539 (primary resonance)", "0.8744 (primary resonance)", "0.1862 (1/4 super-harmonic)"):
        assert w in text
    assert "period doubling at Ω = 0.4082, 0.4632, 1.2426, 1.9591" in text
    assert f"{level.db_min:.1f} … {level.db_max:.1f} dB" in text
    assert "HB fold at Ω = 0.8744" in text and "HB fold at Ω = 0.7539" in text
    assert "harmonic balance with continuation, stability and sub-harmonic branches 1.20 s" in text
    assert "the exact solution is periodic with period 2" in text
    # figures that were not written are left out
    short = demo_report(frf, sweep, orbits={}, level=level, figures={})
    assert ".png" not in short and "## Special points" in short


# --------------------------------------------------------------------------------------------
# PaperDemo: what `rattle demo` computed, with its figures by key, report and metadata
# --------------------------------------------------------------------------------------------
def test_paper_demo_figures_report_and_metadata(reference_model, frf, sweep, orbits, level) -> None:
    regions = tuple(frf.regions)
    run = PaperDemo(model=reference_model, analysis=demo_case()[1], frf=frf, sweep=sweep, orbits=orbits,
                    regions=regions, level=level, timings={"sweep": 0.5})
    assert set(DEMO_FIGURES) == {"frf", "fig4", "fig5", "fig6", "fig7", "mean"}
    fig, axes = run.figure("fig4")
    assert isinstance(fig, Figure) and set(axes) >= {"response", "level"}
    with pytest.raises(ValueError, match="`key` must be one of"):
        run.figure("fig8")
    figures = {"fig4": "fig4_linear_vs_nonlinear.png"}
    assert run.report(figures=figures, version="x") == demo_report(
        frf, sweep, orbits=orbits, level=level, figures=figures, regions=regions, data_files=list(DEMO_DATA),
        version="x")
    meta = run.metadata()
    assert set(meta) == {"regions_confirmed_by_sweep", "sweep", "orbits", "level_difference"}
    assert meta["orbits"]["A"]["omega"] == orbits["A"].omega and meta["level_difference"]["db_min"] == level.db_min
    lines = run.summary().splitlines()
    assert lines[-1].startswith("linear vs non-linear: ") and any(l.startswith("point B (Omega = 1.41)") for l in lines)
