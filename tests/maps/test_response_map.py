"""response_map and one combination's pipeline: branches on the grid, attractor search, summary."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import rattle
from rattle.analysis._attractors import AttractorSearch, Census, SimulatedAttractor, find_attractors
from rattle.analysis._grid import GridSolution, section_states, solutions_on_grid
from rattle.analysis._settings import RunSettings
from rattle.errors import ConfigError
from rattle.hb import HBOptions
from rattle.maps import CellResult, response_map
from rattle.maps._cell import summarise
from rattle.model import Clutch
from rattle.timeint import shoot_periodic_orbit

SMALL_SEARCH = AttractorSearch(bands=2, starts=2)


def _clutch(alpha: float) -> rattle.Model:
    m = rattle.reference_case()
    return dataclasses.replace(m, elastic=Clutch(alpha=alpha, b=m.elastic.b))


@pytest.fixture(scope="module")
def small_map() -> rattle.ResponseMap:
    return response_map(rattle.reference_case(), {"alpha": [0.2, 0.3]}, omega=(0.6, 1.2), omega_points=13,
                        harmonics=12, search=SMALL_SEARCH, engine="serial")


def test_map_shape_columns_and_rows(small_map):
    m = small_map
    assert m.shape == (2,) and m.names == ("alpha",)
    assert m.parameters[0].key == "model.elastic.alpha"
    assert [c.values["alpha"] for c in m.cells] == [0.2, 0.3]
    np.testing.assert_array_equal(m.omega, np.linspace(0.6, 1.2, 13))
    rows = m.rows()
    assert len(rows) == 2 * 13
    assert list(rows[0]) == ["alpha", "omega", "n_solutions", "n_stable", "rms_max_stable", "rms_ac_max_stable",
                             "regime_max_stable", "periods_stable", "rattle"]
    ds = m.dataset
    assert ds["rms_max_stable"].dims == ("alpha", "omega")
    for c in m.cells:
        assert c.status == "ok"
        has = c.n_stable > 0
        assert np.all(np.isfinite(c.rms_max_stable[has]))
        assert all("1" in p.split(";") for p in c.periods_stable[has])
        # the resonance of the reference clutch bends: three period-1 solutions inside the fold
        assert c.n_solutions.max() == 3
        assert any(sp["kind"] == "fold" for sp in c.special_points)


def test_grid_solutions_are_exact_orbits():
    """Every grid solution is the HB orbit at exactly that Ω: exact shooting from its section
    state closes an orbit of the same period, same rms (H = 16: truncation ≪ 1e-3) and stability."""
    model = _clutch(0.25)
    run = RunSettings.make(HBOptions(harmonics=16), None, None)
    frf = rattle.frequency_response(model, omega=(0.3, 1.2), harmonics=16, subharmonics=True)
    grid = np.linspace(0.3, 1.2, 19)
    sols = solutions_on_grid(frf, grid, run)
    assert {s.period for s in sols} == {1, 2}
    for s in sols:
        assert s.converged and s.omega == grid[s.index]
        orbit = shoot_periodic_orbit(model, s.omega, s.section[0], period=s.period)
        assert orbit.converged
        assert abs(orbit.rms / s.rms - 1) < 1e-3
        assert bool(orbit.stable) == s.stable
    # inside the fold, three primary solutions at one grid frequency: one unstable between two stable
    by = {}
    for s in sols:
        if s.branch == 0:
            by.setdefault(s.index, []).append(s)
    three = [v for v in by.values() if len(v) == 3]
    assert three and all(sum(x.stable for x in v) == 2 for v in three)


def test_section_states_of_a_series():
    q = np.array([0.1, 0.5, 0.2, 0.3, -0.4])  # a_0, a_1, a_2, b_1, b_2 with base frequency Ω/2
    omega = 1.3
    x = section_states(q, 1, omega, 2)
    w = omega / 2
    for m in range(2):
        t = m * 2 * np.pi / omega
        d = 0.1 + 0.5 * np.cos(w * t) + 0.2 * np.cos(2 * w * t) + 0.3 * np.sin(w * t) - 0.4 * np.sin(2 * w * t)
        v = (-0.5 * w * np.sin(w * t) - 0.4 * w * np.sin(2 * w * t) + 0.3 * w * np.cos(w * t)
             - 0.8 * w * np.cos(2 * w * t))
        np.testing.assert_allclose(x[m], [d, v], atol=1e-14)


def test_search_finds_the_isolated_subharmonics():
    """α = 0.1: stable period-2 and period-3 motions near Ω = 1.36 that no period doubling of
    the primary branch reaches; the multi-start finds them and continues each as a branch."""
    model = _clutch(0.1)
    run = RunSettings.make(HBOptions(harmonics=16), None, None)
    grid = np.linspace(1.3, 1.42, 7)
    frf = rattle.frequency_response(model, omega=(1.3, 1.42), harmonics=16, subharmonics=True)
    assert set(frf.period) == {1}  # nothing but period 1 is connected here
    census = find_attractors(frf, grid, run, AttractorSearch(bands=1, starts=12))
    periods = {f["period"] for f in census.found}
    assert {2, 3} <= periods
    assert all(f["branch"] is not None for f in census.found)
    stable_periods = {s.period for s in census.solutions if s.stable}
    assert {1, 2, 3} <= stable_periods
    # each new branch passes through the simulated orbit it was seeded from (no "note")
    assert not [f for f in census.found if "note" in f]


def _sol(j, branch, period, stable, rms, impacts, regime="double_sided"):
    return GridSolution(index=j, omega=float(j), branch=branch, period=period, stable=stable, rms=rms, rms_ac=rms / 2,
                        p2p=1.0, acc_p2p=1.0, delta_min=0.0, delta_max=1.0, regime=regime, impacts=impacts,
                        section=np.zeros((period, 2)), q=np.zeros(3))


def test_summarise_follows_spec_7():
    grid = np.array([1.0, 2.0, 3.0, 4.0])
    census = Census(solutions=[
        _sol(0, 0, 1, True, 0.1, False, "no_impact"),
        _sol(1, 0, 1, True, 0.2, False, "no_impact"), _sol(1, 0, 1, False, 0.3, True), _sol(1, 0, 1, True, 0.4, True),
        _sol(1, 5, 1, True, 0.5, True),  # an isola's stable period-1 solution: largest rms, not counted in n_*
        _sol(2, 0, 1, False, 0.3, True), _sol(2, 1, 2, True, 0.35, True),
    ], simulated=[SimulatedAttractor(3, 4.0, 0, 0.2, 0.1, "double_sided", True, "test"),
                  SimulatedAttractor(0, 1.0, 1, 0.3, 0.2, "single_sided", True, "budget spent")])
    s = summarise(census, grid)
    np.testing.assert_array_equal(s["n_solutions"], [1, 3, 1, 0])
    np.testing.assert_array_equal(s["n_stable"], [1, 2, 0, 0])
    # grid 0: a period-1 attractor seen by simulation only (its branch not continued) counts too
    np.testing.assert_array_equal(s["rms_max_stable"][:2], [0.3, 0.5])
    assert np.isnan(s["rms_max_stable"][2]) and np.isnan(s["rms_max_stable"][3])
    assert list(s["regime_max_stable"]) == ["single_sided", "double_sided", "", ""]
    assert list(s["periods_stable"]) == ["1", "1", "2", "0"]
    np.testing.assert_array_equal(s["rattle"], [True, True, True, True])
    assert s["intervals"] == {"impact": [[1.0, 4.0]], "rattle_free": [], "subharmonic": [[3.0, 3.0]],
                              "nonperiodic": [[4.0, 4.0]]}


def test_store_resumes_and_settings_change_recomputes(tmp_path):
    kw = dict(omega=(0.8, 1.0), omega_points=5, harmonics=8, search=AttractorSearch(bands=1, starts=1),
              engine="serial")
    seen = []
    first = response_map(rattle.reference_case(), {"alpha": [0.25, 0.3]}, store=tmp_path, **kw)
    again = response_map(rattle.reference_case(), {"alpha": [0.25, 0.3]}, store=tmp_path,
                         progress=lambda d, t, r: seen.append((d, t, r)), **kw)
    assert seen == [(2, 2, 2)]  # everything read back, nothing computed
    assert all(c.resumed for c in again.cells) and again.timings["computed"] == 0
    for a, b in zip(first.cells, again.cells):
        assert json.dumps(a.to_dict()) == json.dumps(b.to_dict())
    other = response_map(rattle.reference_case(), {"alpha": [0.25, 0.3]}, store=tmp_path,
                         **{**kw, "harmonics": 10})
    assert not any(c.resumed for c in other.cells)


def test_bad_vary_is_refused_before_any_work(tmp_path):
    store = tmp_path / "out"
    with pytest.raises(ConfigError, match="--vary"):
        response_map(rattle.reference_case(), {"model.elastic.gamma": [0.1]}, store=store, engine="serial")
    with pytest.raises(ConfigError, match="alpha"):
        response_map(rattle.reference_case(), {"alpha": [0.2, 1.5]}, store=store, engine="serial")
    assert not store.exists()


def test_cell_result_json_round_trip_is_exact(small_map):
    for c in small_map.cells:
        back = CellResult.from_dict(json.loads(c.to_json()))
        for col in ("rms_max_stable", "rms_ac_max_stable"):
            np.testing.assert_array_equal(getattr(back, col), getattr(c, col))
        assert back.intervals == c.intervals and back.special_points == c.special_points


def test_chain_map_finds_the_quasi_periodic_motion_and_its_locking():
    """The grounded two-inertia example has no stable period-1 orbit between its Neimark–Sacker
    points 0.811 and 0.857 (torus ratio ≈ 0.3): simulation decides there. At 0.82 the motion is
    non-periodic (period 0); at 0.84 it locks onto a period-3 orbit (ratio 1/3), which the search
    continues as a branch of its own (born at a fold near 0.8376)."""
    from pathlib import Path

    case = rattle.load_case(Path(__file__).resolve().parents[2] / "examples" / "grounded_two_inertia.toml")
    m = response_map(case, {"model.links.1.damping": [0.02]}, omega=(0.80, 0.84), omega_points=3, harmonics=12,
                     search=AttractorSearch(bands=0), engine="serial")
    c = m.cells[0]
    assert c.status == "ok"
    assert list(c.n_stable) == [1, 0, 0]
    assert list(c.periods_stable) == ["1", "0", "3"]
    assert np.all(np.isnan(c.rms_max_stable[1:]))
    assert np.all(c.rattle[1:])
    np.testing.assert_allclose(c.intervals["nonperiodic"], [[0.82, 0.82]], rtol=1e-12)
    (found,) = c.attractors
    assert found["period"] == 3 and found["branch"] is not None and "note" not in found
    folds = [sp["omega"] for sp in c.special_points if sp["kind"] == "fold" and sp["period"] == 3]
    assert folds and 0.82 < folds[0] < 0.84


def test_result_writes_csv_netcdf_plot_and_report(small_map, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import xarray as xr

    from rattle.io import read_csv

    path = small_map.to_csv(tmp_path / "map.csv")
    table = read_csv(path)
    assert list(table) == small_map.column_names and len(table["omega"]) == 26
    ds = xr.open_dataset(small_map.to_netcdf(tmp_path / "map.nc"), engine="scipy")
    np.testing.assert_array_equal(ds["rms_max_stable"].values, small_map.dataset["rms_max_stable"].values)
    ds.close()
    from rattle.maps import map_report

    text = map_report(small_map)
    assert "Rattle-free region" in text and "alpha" in text
    fig, axes = small_map.plot()
    assert axes.primary is not None


def test_cell_special_points_are_those_frf_locates(small_map):
    """Every fold and period doubling of a combination is the one frequency_response locates
    with the same settings (the same computation, to the bit)."""
    frf = rattle.frequency_response(_clutch(0.2), omega=(0.6, 1.2), harmonics=12, subharmonics=True)
    want = sorted((sp.kind, sp.omega, sp.branch) for sp in frf.special_points)
    got = sorted((sp["kind"], sp["omega"], sp["branch"]) for sp in small_map.cells[0].special_points
                 if sp["branch"] in set(frf.branch.tolist()))
    assert got == want and want


def test_attractors_beyond_the_branch_budget_still_count_where_seen():
    """With no branch budget the isolated period-2/3 motions of α = 0.1 near Ω = 1.36 are not
    continued, but the frequency where the simulations saw them reports their periods and
    impacts, and the count of what was not continued is kept."""
    model = _clutch(0.1)
    run = RunSettings.make(HBOptions(harmonics=16), None, None)
    grid = np.linspace(1.3, 1.42, 7)
    frf = rattle.frequency_response(model, omega=(1.3, 1.42), harmonics=16, subharmonics=True)
    census = find_attractors(frf, grid, run, AttractorSearch(bands=1, starts=12, hb_points=0, max_branches=0))
    assert census.counts["branches"] == 0 and census.counts["not_continued"] >= 2
    seen = {a.period for a in census.simulated if a.index == 3}
    assert {2, 3} <= seen
    s = summarise(census, grid)
    assert {"1", "2", "3"} <= set(s["periods_stable"][3].split(";"))
    assert s["rattle"][3]


def test_map_of_an_engine_config_gives_speed_rpm(tmp_path):
    """A map of an SI configuration with [engine]: the grid also as crankshaft speed (map.csv's
    last column, the dataset's coordinate, the plot's axis), rpm = Ω · 60 / (2π · base order)."""
    from pathlib import Path

    from rattle.io import read_csv

    case = rattle.load_case(Path(__file__).resolve().parents[2] / "examples" / "engine_clutch_si.toml")
    order = case.model.speed_order
    assert order is not None
    lo, hi = case.analysis.omega
    m = response_map(case, {"model.elements.1.alpha": [case.model.elements[0].law.alpha]}, omega=(lo, lo * 1.2),
                     omega_points=4, harmonics=8, search=AttractorSearch(bands=0, hb_points=0, from_unstable=False),
                     engine="serial")
    assert m.speed_order == order
    exact = m.omega * 60 / (2 * np.pi * order)
    # rounded to a millionth of the grid's step (round-off of the conversion gone, nothing else)
    np.testing.assert_allclose(m.speed_rpm, exact, rtol=0, atol=0.5e-6 * (exact[1] - exact[0]))
    assert m.speed_rpm[0] == 400.0 and m.speed_rpm[1] == 426.66667
    table = read_csv(m.to_csv(tmp_path / "map.csv"))
    assert list(table)[-1] == "speed_rpm"
    np.testing.assert_allclose(np.asarray(table["speed_rpm"], float), m.speed_rpm, rtol=1e-12)
    np.testing.assert_allclose(m.dataset["speed_rpm"].values, m.speed_rpm)
    fig, axes = m.plot()
    assert axes.primary.get_xlabel() == "engine speed (rpm)"


def test_the_report_of_an_engine_map_gives_speeds_in_rpm_and_angles_in_degrees(tmp_path):
    """map.md of an engine case whose clearance was given in degrees (``b_deg``): the varied angle
    in degrees, every speed in rpm; map.csv keeps rad and Ω (issue 27 item 3)."""
    import math
    from pathlib import Path

    from rattle.cli.output import map_summary
    from rattle.maps import Parameter, map_report, mark_degrees

    path = Path(__file__).resolve().parents[2] / "examples" / "engine_clutch_si.toml"
    case = rattle.load_case(path)
    source = rattle.io.load_config(path).source
    (p,) = mark_degrees([Parameter(name="b", key="model.elements.1.b", values=(math.radians(4.0),))], source)
    assert p.degrees and p.shown(p.values[0]) == pytest.approx(4.0, rel=1e-15)
    lo = case.analysis.omega[0]
    m = response_map(case, [p], omega=(lo, lo * 1.2), omega_points=4, harmonics=8,
                     search=AttractorSearch(bands=0, hb_points=0, from_unstable=False), engine="serial")
    assert m.parameters[0].degrees  # kept through response_map
    text = map_report(m)
    assert "given in degrees; map.csv in rad): 4 deg" in text and "| b (deg) |" in text and "### b = 4 deg" in text
    assert "speed grid: 4 crankshaft speeds, 400 … 480 rpm" in text and "speed (rpm)" in text
    body = text.split("## Rattle-free region")[1]
    assert "rad/s" not in body and "Ω =" not in body
    assert "rpm" in map_summary(m).splitlines()[-1] or "none" in map_summary(m).splitlines()[-1]
    assert map_summary(m).splitlines()[-1].startswith("speeds rattle-free at every combination: ")
    table = rattle.io.read_csv(m.to_csv(tmp_path / "map.csv"))
    assert float(table["b"][0]) == math.radians(4.0)  # the files keep rad


def test_which_angles_were_given_in_degrees():
    from rattle.maps._vary import given_in_degrees

    damper = {"model": {"elements": [{"type": "damper", "drive_angles_deg": [4.0], "drive_stiffness_per_deg": [1.0]},
                                     {"type": "backlash", "b": 0.1}]}}
    assert given_in_degrees(damper, "model.elements.1.breakpoints.4")
    assert not given_in_degrees(damper, "model.elements.1.stiffness")
    assert not given_in_degrees(damper, "model.elements.2.b") and not given_in_degrees(damper, "model.elements.3.b")
    single = {"model": {"elastic": {"type": "clutch", "alpha": 0.25, "b_deg": 10.0}}}
    assert given_in_degrees(single, "model.elastic.b") and not given_in_degrees(single, "model.elastic.alpha")
    assert not given_in_degrees(single, "excitation.mean") and not given_in_degrees({}, "model.elastic.b")
