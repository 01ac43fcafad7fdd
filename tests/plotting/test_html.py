"""The interactive pages (``rattle.plotting.*_html``, ``--html``): one self-contained HTML file with
plotly.js inside it, the figure as JSON and the summary.

Without a browser: the page holds the data (the embedded figure JSON is parsed and set against
the result's rows), its hover texts, its summary, and loads nothing from the network (no script
``src``). With one (Chromium driven by playwright, skipped where either is missing): the page
draws without a console error, the plot is there with every trace, a hover shows a point's
values, and a screenshot is taken (``RATTLE_SHOTS=DIR`` keeps it there to be looked at).
"""

from __future__ import annotations

import dataclasses
import html
import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rattle.plotting import PLOTLY_MISSING, compare_html, frequency_response_html, map_html, plotly_available
from _cases import clutch_toml, preload_spring_toml  # tests/_cases.py
from _cli_helpers import invoke, write_config  # tests/cli/_cli_helpers.py
from _fake_map import synthetic_map  # tests/_fake_map.py

needs_plotly = pytest.mark.skipif(not plotly_available(), reason='plotly is not installed (pip install "rattle[html]")')


# --------------------------------------------------------------------------------------------
# Reading a page
# --------------------------------------------------------------------------------------------
def figure_of(page: str) -> dict:
    """The figure JSON a page embeds (``<script type="application/json" id="rattle-figure">``)."""
    found = re.findall(r'<script type="application/json" id="rattle-figure">(.*?)</script>', page, flags=re.S)
    assert len(found) == 1
    return json.loads(found[0])


def summary_of(page: str) -> str:
    found = re.findall(r'<pre id="rattle-summary">(.*?)</pre>', page, flags=re.S)
    assert len(found) == 1
    return html.unescape(found[0])


def assert_offline(page: str) -> None:
    """plotly.js inside the page, nothing fetched: no script or stylesheet from an address."""
    assert not re.search(r"<script[^>]*\bsrc\s*=", page, flags=re.I)
    assert not re.search(r"<link[^>]*\bhref\s*=\s*[\"']?https?:", page, flags=re.I)
    assert "Plotly.newPlot" in page and len(page) > 3_000_000  # the bundle is ~4.8 MB


def points(fig: dict, prefix: str, axis: str = "y") -> set[tuple[float, float]]:
    """(x, y) of every point of the traces whose name starts with ``prefix`` on axes ``y`` (y2…)."""
    out = set()
    for tr in fig["data"]:
        if tr.get("name", "").startswith(prefix) and tr.get("yaxis", "y") == axis:
            out |= {(x, y) for x, y in zip(tr["x"], tr["y"]) if x is not None and y is not None}
    return out


def hovers(fig: dict, prefix: str) -> list[str]:
    return [t for tr in fig["data"] if tr.get("name", "").startswith(prefix) for t in tr.get("hovertext") or [] if t]


# --------------------------------------------------------------------------------------------
# Results to draw (small: a few seconds together)
# --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def smooth_frf():
    from rattle import frequency_response
    from rattle.model import reference_case

    return frequency_response(reference_case(), omega=(0.6, 1.4), harmonics=8)  # 2 folds, a period doubling


@pytest.fixture(scope="module")
def engine_chain_frf():
    """A two-element driveline (piecewise clutch, gear with backlash) with an engine order."""
    from rattle import frequency_response
    from rattle.model import Backlash, Chain, Element, Link, Piecewise, Torque

    chain = Chain(
        inertias=(1.0, 0.1, 2.0), links=(Link(between=(1, 2), damping=0.02), Link(between=(2, 3), damping=0.1)),
        elements=(Element(name="clutch", between=(1, 2), stiffness=1.0,
                          law=Piecewise(breakpoints=(-0.12, -0.04, 0.05, 0.15), slopes=(1.0, 0.3, 0.08, 0.4, 1.0))),
                  Element(name="gear", between=(2, 3), stiffness=3.0, law=Backlash(b=0.02))),
        torques=(Torque(inertia=1, mean=0.05, amplitudes=(0.03, 0.015), phases=(0.0, 0.5)),
                 Torque(inertia=3, mean=-0.05)), speed_order=2.0)
    return frequency_response(chain, omega=(1.0, 1.5), harmonics=8, confirm_tori=False)


@pytest.fixture(scope="module")
def preload_frf(tmp_path_factory):
    """The torque converter's preloaded spring by exact shooting, with its period-2 branch."""
    from rattle import frequency_response
    from rattle.analysis import case_arguments
    from rattle.io import load_config

    path = tmp_path_factory.mktemp("preload") / "case.toml"
    path.write_text(preload_spring_toml((0.5, 0.6), harmonics=32, friction=None), encoding="utf-8")
    config = load_config(path)
    return frequency_response(config.model, **case_arguments(config.model, config.analysis, {"subharmonics": True}))


# --------------------------------------------------------------------------------------------
# Without a browser
# --------------------------------------------------------------------------------------------
@needs_plotly
def test_a_smooth_law_page_holds_every_row_with_its_hover(smooth_frf):
    frf = smooth_frf
    page = frequency_response_html(frf)
    assert_offline(page)
    fig = figure_of(page)
    rows = {(float(w), float(r)) for w, r in zip(frf.omega, frf.rms)}
    assert points(fig, "branch 0") == rows  # every row drawn, nothing else on the branch
    stable = {(float(w), float(r)) for w, r, s in zip(frf.omega, frf.rms, frf.stable) if s}
    assert stable <= points(fig, "branch 0, stable")
    text = hovers(fig, "branch 0")
    assert all("Ω = " in t and "period 1" in t and "branch 0" in t and " rms = " not in t for t in text)
    assert any("<br>rms = " in t and "unstable" in t for t in text)
    for kind in ("fold", "period doubling"):
        marked = points(fig, kind)
        expected = {(float(sp.omega), float(frf.rms[sp.index])) for sp in frf.special_points
                    if sp.kind == kind.replace(" ", "_")}
        assert expected and {(x, y) for x, y in marked} == {(frf.omega[i], frf.rms[i]) for i in
                                                             [sp.index for sp in frf.special_points
                                                              if sp.kind == kind.replace(" ", "_")]}
        assert all(f"<b>{kind}</b>" in t for t in hovers(fig, kind))
    assert points(fig, "linear system")  # the linear system in grey
    assert fig["layout"]["xaxis"]["title"]["text"] == "forcing frequency Ω (rad/s)"
    assert summary_of(page) == frf.summary()


@needs_plotly
def test_the_summary_and_the_labels_cannot_break_out_of_the_page(smooth_frf):
    hostile = "</script><script>alert(1)</script> & <b>"
    page = frequency_response_html(smooth_frf, summary=hostile, title=hostile)
    assert "<script>alert(1)" not in page
    assert summary_of(page) == hostile
    assert f"<title>{html.escape(hostile)}</title>" in page


@needs_plotly
@pytest.mark.parametrize("quantity", ["p2p", "acc_p2p", "delta_max", "mean"])
def test_the_quantity_drawn_is_the_column_asked_for(smooth_frf, quantity):
    frf = smooth_frf
    fig = figure_of(frequency_response_html(frf, quantity=quantity))
    assert points(fig, "branch 0") == {(float(w), float(v)) for w, v in zip(frf.omega, getattr(frf, quantity))}
    assert all(f"<br>{quantity} = " in t for t in hovers(fig, "branch 0"))
    assert bool(points(fig, "linear system")) == (quantity == "mean")  # the linear system: mean, rms, rms_ac


@needs_plotly
@pytest.mark.parametrize("quantity, error", [("spl_db", ValueError), ("omega_max", ValueError), (3, TypeError)])
def test_a_quantity_the_result_does_not_carry_is_refused(smooth_frf, quantity, error):
    with pytest.raises(error, match="`quantity`"):
        frequency_response_html(smooth_frf, quantity=quantity)


@needs_plotly
def test_sub_harmonic_branches_are_named_by_their_period(smooth_frf):
    frf = smooth_frf
    half = len(frf) // 2  # the second half as a period-2 branch: the page reads the columns
    branch = np.where(np.arange(len(frf)) < half, 0, 1)
    period = np.where(branch == 1, 2, 1)
    page = frequency_response_html(dataclasses.replace(frf, branch=branch, period=period, special_points=(),
                                                       regions=()))
    fig = figure_of(page)
    assert points(fig, "branch 1 (period 2)") == {(float(w), float(r)) for w, r in zip(frf.omega[half:], frf.rms[half:])}
    assert all("period 2, branch 1" in t for t in hovers(fig, "branch 1 (period 2)"))


@needs_plotly
def test_a_chain_with_an_engine_has_a_panel_per_element_over_rpm(engine_chain_frf):
    frf = engine_chain_frf
    fig = figure_of(frequency_response_html(frf))
    rpm = frf.speed_rpm
    for axis, name in (("y", "clutch"), ("y2", "gear")):
        assert points(fig, "branch 0", axis) == {(float(x), float(y)) for x, y in zip(rpm, frf.element_columns[f"{name}_rms"])}
    assert fig["layout"]["xaxis2"]["title"]["text"] == "engine speed (rpm)"
    text = hovers(fig, "branch 0")
    assert text and all(re.search(r"Ω = [0-9.]+ rad/s \([0-9.]+ rpm\)", t) for t in text)
    assert any("clutch_rms = " in t for t in text) and any("gear_rms = " in t for t in text)
    titles = [a["text"] for a in fig["layout"]["annotations"]]
    assert any("element clutch" in t for t in titles) and any("element gear" in t for t in titles)


@needs_plotly
def test_a_law_with_jumps_draws_its_exact_rows_on_every_branch(preload_frf):
    frf = preload_frf
    check = frf.check
    assert check.branches and check.followed == "exact shooting"  # the case still has its period-2 branch
    fig = figure_of(frequency_response_html(frf))
    ok = check.matched & np.isfinite(check.rms)
    assert points(fig, "exact, period 1") == {(float(w), float(r)) for w, r in zip(check.omega[ok], check.rms[ok])}
    sub = check.branches[0]
    name = f"branch {sub.branch} (period {sub.period}), exact"
    assert points(fig, name) == {(float(w), float(r)) for w, r, m in zip(sub.omega, sub.rms, sub.matched) if m}
    assert all(f"period {sub.period}, branch {sub.branch}" in t for t in hovers(fig, name))
    labels = {str(k) for part in (check, *check.branches) for k in part.bifurcation if k}
    marked = {tr["name"] for tr in fig["data"] if tr["mode"] == "markers"}
    assert labels and marked == {k.replace("_", " ") for k in labels}


@needs_plotly
def test_a_chain_with_friction_and_jumps_draws_each_elements_exact_rows():
    from rattle import frequency_response
    from _cases import lockup_chain

    frf = frequency_response(lockup_chain(), omega=(1.0, 1.1))  # a lock-up clutch (a jump, friction), a gear
    check = frf.check
    assert check.element_names == ("tcc", "gear")
    fig = figure_of(frequency_response_html(frf))
    ok = check.matched
    for e, axis in enumerate(("y", "y2")):
        assert points(fig, "exact, period 1", axis) == {(float(w), float(r)) for w, r in
                                                        zip(check.omega[ok], check.rms[ok, e])}
    titles = [a["text"] for a in fig["layout"]["annotations"]]
    assert any("element tcc" in t for t in titles) and any("element gear" in t for t in titles)
    with pytest.raises(ValueError, match="`quantity`.*rms or mean"):
        frequency_response_html(frf, quantity="p2p")


@needs_plotly
@pytest.mark.parametrize("names, values", [(("alpha",), ((0.1, 0.2, 0.3),)),
                                           (("alpha", "b"), ((0.1, 0.2, 0.3), (0.01, 0.02)))])
def test_a_map_page_holds_every_cell_with_its_hover(names, values):
    response_map = synthetic_map(names, values, points=25)
    page = map_html(response_map, summary="the map's summary")
    assert_offline(page)
    fig = figure_of(page)
    maps = [tr for tr in fig["data"] if tr["type"] == "heatmap"]
    panels = len(values[1]) if len(values) > 1 else 1
    assert len(maps) == panels and [tr["visible"] for tr in maps] == [True] + [False] * (panels - 1)
    first = [c for c in response_map.cells if all(c.values[n] == v[0] for n, v in zip(names[1:], values[1:]))]
    assert maps[0]["z"] == [[None if math.isnan(v) else v for v in c.rms_max_stable] for c in first]
    for row, c in zip(maps[0]["text"], first):
        assert [("impacts (rattle)" in t) for t in row] == c.rattle.tolist()
        assert all("Ω = " in t and "alpha = " in t for t in row)
    menus = fig["layout"].get("updatemenus", [])
    assert len(menus) == (1 if panels > 1 else 0)
    if menus:
        assert [b["label"] for b in menus[0]["buttons"]] == [f"b = {v:.4g}" for v in values[1]]
    assert summary_of(page) == "the map's summary"


@needs_plotly
def test_a_compare_page_has_the_sweep_points_and_the_histories(tmp_path):
    from rattle.analysis import compare
    from rattle.model import reference_case

    result = compare(reference_case(), omega=(0.6, 1.4), harmonics=8, points=12)
    page = compare_html(result)
    assert_offline(page)
    fig = figure_of(page)
    for d in ("up", "down"):
        sel = result.sweep.direction == d
        assert points(fig, f"sweep {d}") == {(float(w), float(r)) for w, r in zip(result.sweep.omega[sel],
                                                                                  result.sweep.rms[sel])}
    assert all("period" in t or "failed" in t for t in hovers(fig, "sweep up"))
    assert len([s for s in fig["layout"]["shapes"] if s["type"] == "line"]) == len(result.at) >= 1
    assert {tr["xaxis"] for tr in fig["data"] if tr["name"].startswith("HB P")} == \
        {f"x{j + 2}" for j in range(len(result.at))}  # one time-history panel per examined frequency
    assert summary_of(page) == result.summary()


@needs_plotly
def test_compare_html_of_a_law_with_jumps_sets_the_exact_rows_against_the_sweep(tmp_path):
    config = write_config(tmp_path, preload_spring_toml((0.5, 0.6), harmonics=32, friction=None))
    out = tmp_path / "out"
    result = invoke(["compare", str(config), "-o", str(out), "--points", "8", "--html"], tmp_path)
    assert result.exit_code == 0, result.stderr
    page = (out / "compare.html").read_text(encoding="utf-8")
    assert_offline(page)
    fig = figure_of(page)
    assert points(fig, "exact, period 1") and points(fig, "regularised HB")
    assert len(points(fig, "sweep up")) + len(points(fig, "sweep down")) == 16
    assert summary_of(page) in result.stdout


def test_importing_the_plotting_layer_and_the_cli_does_not_import_plotly():
    code = "import sys, rattle.plotting, rattle.cli.commands; print('plotly' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


# --------------------------------------------------------------------------------------------
# The command line
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", [["frf"], ["compare"], ["map", "--vary", "alpha=0.2,0.3"]])
def test_html_without_plotly_is_refused_before_anything_is_written(tmp_path, monkeypatch, command):
    monkeypatch.setitem(sys.modules, "plotly", None)  # not importable, as when it is not installed
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke([command[0], str(config), "-o", str(out), *command[1:], "--html"], tmp_path)
    assert result.exit_code == 2, result.stderr
    assert 'pip install "rattle[html]"' in result.stderr and "`--html`" in result.stderr
    assert not out.exists()
    assert 'pip install "rattle[html]"' in PLOTLY_MISSING


@needs_plotly
def test_frf_html_is_written_beside_the_png_and_removed_by_a_run_without_it(tmp_path):
    config = write_config(tmp_path, clutch_toml((0.6, 1.4), 8))
    out = tmp_path / "out"
    result = invoke(["frf", str(config), "-o", str(out), "--html"], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert "frf.html" in result.stdout
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.html", "frf.json", "frf.png"]
    page = (out / "frf.html").read_text(encoding="utf-8")
    assert_offline(page)
    rms = [float(x) for x in (line.split(",")[4] for line in (out / "frf.csv").read_text().splitlines()[1:])]
    assert {y for _, y in points(figure_of(page), "branch 0")} == set(rms)
    assert json.loads((out / "frf.json").read_text())["options"]["html"] is True
    result = invoke(["frf", str(config), "-o", str(out)], tmp_path)  # no page now: the old one goes
    assert result.exit_code == 0, result.stderr
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.json", "frf.png"]


@needs_plotly
def test_map_html_is_written_with_the_set(tmp_path, monkeypatch):
    import rattle.maps

    def front(model, params, *, omega, omega_points, **_):
        return synthetic_map(tuple(p.name for p in params), tuple(tuple(p.values) for p in params), points=omega_points)

    monkeypatch.setattr(rattle.maps, "response_map", front, raising=False)
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke(["map", str(config), "-o", str(out), "--vary", "alpha=0.2,0.3", "--omega-points", "20",
                     "--html"], tmp_path)
    assert result.exit_code == 0, result.stderr
    page = (out / "map.html").read_text(encoding="utf-8")
    assert_offline(page)
    assert len(figure_of(page)["data"][0]["z"]) == 2
    assert summary_of(page).startswith("response map: 2 combinations")


# --------------------------------------------------------------------------------------------
# In a browser
# --------------------------------------------------------------------------------------------
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def _chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.slow
@needs_plotly
def test_the_pages_draw_in_chromium(tmp_path, smooth_frf):
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install playwright)")
    browser_path = _chromium()
    if browser_path is None:
        pytest.skip("Chromium is not installed (apt-get install chromium): the page is not drawn in a browser")
    pages = {"frf": frequency_response_html(smooth_frf),
             "map": map_html(synthetic_map(("alpha", "b"), ((0.1, 0.2, 0.3), (0.01, 0.02)), points=25),
                             summary="a synthetic map")}
    shots = Path(os.environ["RATTLE_SHOTS"]) if os.environ.get("RATTLE_SHOTS") else tmp_path
    shots.mkdir(parents=True, exist_ok=True)
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=browser_path, args=CHROMIUM_ARGS)
        try:
            for name, text in pages.items():
                path = tmp_path / f"{name}.html"
                path.write_text(text, encoding="utf-8")
                page = browser.new_page(viewport={"width": 1280, "height": 900})
                errors: list[str] = []
                fetched: list[str] = []
                page.on("console", lambda m, errors=errors: errors.append(m.text) if m.type == "error" else None)
                page.on("pageerror", lambda e, errors=errors: errors.append(str(e)))
                page.on("request", lambda r, fetched=fetched: fetched.append(r.url)
                        if not r.url.startswith(("file:", "data:", "blob:")) else None)
                page.goto(path.as_uri())
                page.wait_for_selector("#rattle-plot .main-svg", timeout=20_000)
                drawn = page.evaluate("document.getElementById('rattle-plot').data.length")
                assert drawn == len(figure_of(text)["data"])
                # a hover on the first point of the first trace shows that point's values
                if name == "map":  # the mouse over the middle of the heat map
                    box = page.locator("#rattle-plot .nsewdrag").first.bounding_box()
                    page.mouse.move(box["x"] + 0.5 * box["width"], box["y"] + 0.5 * box["height"])
                else:
                    page.evaluate("Plotly.Fx.hover('rattle-plot', [{curveNumber: 0, pointNumber: 0}])")
                page.wait_for_selector(".hoverlayer .hovertext", state="attached", timeout=5_000)
                hover = page.evaluate("document.querySelector('.hoverlayer .hovertext').textContent")
                shot = shots / f"{name}.png"
                page.screenshot(path=str(shot), full_page=True)
                page.close()
                assert errors == [], errors
                assert fetched == [], fetched  # nothing from the network
                assert "Ω = " in hover, hover
                from matplotlib.image import imread

                pixels = imread(str(shot))
                assert pixels.shape[0] >= 800 and len(np.unique(pixels.reshape(-1, pixels.shape[-1]), axis=0)) > 50
        finally:
            browser.close()
