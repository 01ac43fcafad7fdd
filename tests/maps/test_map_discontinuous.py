"""``rattle map`` on the discontinuous laws (a torque jump, friction): every branch an exact orbit.

The map's cell runs the exact shooting continuation of ``rattle frf`` (its default method), solves
every branch exactly at the grid frequencies and searches the attractors the branches miss by
exact simulation (:func:`rattle.analysis.attractor_census`). Checked here:

- the doors agree: at sampled cells of the torque converter's map over its preload, the map's
  stable rms is the rms of ``rattle frf`` started there (same file, same settings) to 1e-6;
- nothing is missed: an independent multi-start of exact simulations (the project's event-driven
  integrator, other starts than the map's) settles only on attractors the map's census holds
  (same period, rms within 1 %), at the frequencies where the map found what its branches do not
  reach (an isola of period 1, a saddle-node pair of period 3);
- friction: a preloaded spring with Coulomb friction mapped over its friction level end to end
  through the command line, and a chain with friction on an element through the library.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from _cases import preload_spring_toml
from _cli_helpers import invoke, write_config
from rattle.analysis import AttractorSearch, RunSettings, SteadyStateOptions, attractor_census, steady_state
from rattle.hb import HBOptions
from rattle.io import config_from_dict, load_config, read_csv

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "torque_converter_preload.toml"


def _with_preload(preload: float) -> str:
    """The torque-converter example with its preload set to ``preload``."""
    text = EXAMPLE.read_text(encoding="utf-8")
    assert "preload = 0.03 " in text
    return text.replace("preload = 0.03 ", f"preload = {preload!r} ", 1)


def _rows(table: dict, **match: float) -> dict[str, np.ndarray]:
    keep = np.ones(len(table["omega"]), dtype=bool)
    for key, value in match.items():
        keep &= np.isclose(np.asarray(table[key], dtype=float), value, rtol=0, atol=1e-12)
    return {k: np.asarray(v)[keep] for k, v in table.items()}


@pytest.mark.slow
def test_map_of_the_torque_converter_over_its_preload_agrees_with_frf(tmp_path):
    """Two preloads on Ω = 0.58 … 0.66 (5 frequencies; the super-harmonic resonance, where two
    stable period-1 orbits coexist at T_p = 0.03 and an isola joins at T_p = 0.025): at sampled
    cells ``rattle frf --omega-min Ω_j`` (its first row an exact orbit at Ω_j, settled from rest)
    gives a stable orbit whose rms is the map's largest stable rms where the map has one stable
    period-1 orbit, and one of those below it where it has more."""
    result = invoke(["map", str(EXAMPLE), "--vary", "preload=0.025,0.03", "--omega-min", "0.58", "--omega-max", "0.66",
                     "--omega-points", "5", "--workers", "1", "-q", "-o", "map"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    table = read_csv(tmp_path / "map" / "map.csv")
    assert len(table["omega"]) == 10 and set(np.asarray(table["preload"], dtype=float)) == {0.025, 0.03}
    compared = 0
    for preload, sampled in ((0.025, (0.62,)), (0.03, (0.58, 0.6, 0.64))):
        config = tmp_path / f"tc_{preload}.toml"
        config.write_text(_with_preload(preload), encoding="utf-8")
        for w in sampled:
            row = _rows(table, preload=preload, omega=w)
            assert row["omega"].size == 1
            out = f"frf_{preload}_{w}"
            res = invoke(["frf", str(config), "--omega-min", repr(w), "--omega-max", repr(w * 1.005), "-o", out],
                         tmp_path)
            assert res.exit_code == 0, res.stderr
            frf = read_csv(tmp_path / out / "frf.csv")
            assert float(frf["omega"][0]) == w and int(frf["period"][0]) == 1
            assert str(frf["stable"][0]).lower() == "true"  # the orbit settled from rest is an attractor
            rms_frf, rms_map = float(frf["rms"][0]), float(row["rms_max_stable"][0])
            n_stable = int(row["n_stable"][0])
            assert n_stable >= 1
            if n_stable == 1:
                assert abs(rms_map / rms_frf - 1.0) <= 1e-6, (preload, w, rms_map, rms_frf)
                compared += 1
            else:
                assert rms_frf <= rms_map * (1.0 + 1e-6)
    assert compared >= 3


def _census_starts(rest: float, omega: float) -> list[tuple[float, float]]:
    """Starts of the independent census: a 4 × 4 grid of (δ, δ'/Ω) around the rest state, wider
    than every orbit here (rms ≤ 0.06), none of them the map's (rings at golden-ratio angles)."""
    return [(rest + a, omega * v) for a in (-0.12, -0.04, 0.04, 0.12) for v in (-0.1, -0.03, 0.03, 0.1)]


@pytest.mark.slow
@pytest.mark.parametrize("preload, omega, where", [
    (0.025, (0.58, 0.66), (0, 2)),   # an isola of period 1 beside the branch at Ω = 0.58
    (0.03, (0.88, 0.96), (0, 1, 3)),  # a saddle-node pair of period 3 over Ω ≲ 0.914
])
def test_a_multistart_census_finds_no_attractor_the_map_misses(preload, omega, where):
    """The census of the map's cell (5 grid frequencies) against 16 exact simulations per sampled
    frequency from a grid of starts: every attractor they settle on is a stable solution of the
    census (or an attractor it saw by simulation) of the same period with the rms within 1 %."""
    tables = load_config(EXAMPLE).to_dict()
    tables["model"]["elastic"]["preload"] = preload
    tables["analysis"]["omega"] = list(omega)
    system = config_from_dict(tables).model
    grid = np.linspace(*omega, 5)
    run = RunSettings.make(HBOptions(harmonics=64), None, None)
    cell = attractor_census(system, grid, run, AttractorSearch())
    census = cell.census
    assert cell.status == "ok"
    assert census.found and all(f["branch"] is not None for f in census.found)  # the search found a branch
    rest = float(system.excitation.mean) / system.k - preload  # δ_s: k (δ_s + T_p) = F_m (F_m > k T_p here)
    seen: set[tuple[int, int, float]] = set()
    for j in where:
        w = float(grid[j])
        known = [(s.period, s.rms) for s in census.solutions if s.index == j and s.stable]
        known += [(a.period, a.rms) for a in census.simulated if a.index == j]
        for x0 in _census_starts(rest, w):
            state = steady_state(system, w, x0, options=SteadyStateOptions(max_periods=1500))
            assert state.period >= 1, (w, x0)  # no non-periodic motion here
            seen.add((j, int(state.period), float(state.rms)))
            assert any(p == state.period and abs(r / state.rms - 1.0) <= 0.01 for p, r in known), \
                (preload, w, x0, state.period, state.rms, known)
    # and the independent starts reach what the map's search added to its branches: the census is
    # not passed by starts that only ever find the primary branch
    new = {int(b.branch) for b in census.branches}
    targets = [s for s in census.solutions if s.branch in new and s.stable and s.index in where]
    assert targets
    assert any(i == s.index and p == s.period and abs(r / s.rms - 1.0) <= 0.01 for s in targets for i, p, r in seen)


def test_map_of_a_preload_with_friction_through_the_command_line(tmp_path):
    """The preloaded spring with Coulomb friction (it sticks part of every period at Ω = 0.5 …
    0.7), mapped over its friction level: one stable period-1 orbit at every grid frequency, its
    rms at Ω_min that of ``rattle frf``'s first row there (the same exact orbit)."""
    config = write_config(tmp_path, preload_spring_toml((0.5, 0.7)))
    result = invoke(["map", str(config), "--vary", "friction=0.01,0.02", "--omega-points", "3", "--workers", "1",
                     "-q", "-o", "map"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    table = read_csv(tmp_path / "map" / "map.csv")
    assert list(table)[:2] == ["friction", "omega"] and len(table["omega"]) == 6
    assert np.all(np.asarray(table["n_stable"], dtype=int) == 1)
    assert {str(p) for p in table["periods_stable"]} == {"1"}
    rms = np.asarray(table["rms_max_stable"], dtype=float)
    assert np.all(rms[3:] < rms[:3])  # more friction, less motion
    res = invoke(["frf", str(config), "--omega-max", "0.52", "-o", "frf"], tmp_path)
    assert res.exit_code == 0, res.stderr
    frf = read_csv(tmp_path / "frf" / "frf.csv")
    assert float(frf["omega"][0]) == 0.5
    assert abs(rms[3] / float(frf["rms"][0]) - 1.0) <= 1e-9  # friction 0.02 is the file's


def test_map_of_a_chain_with_friction_through_the_library(tmp_path):
    """A chain with friction on an element's idle stage (a System with its elements' whole laws) mapped over that level
    with a small search: every cell ``ok``, its stable rms at Ω_min that of the exact branch's
    first row (:func:`rattle.frequency_response`, what ``rattle frf`` runs)."""
    import rattle
    from test_cli_chain_friction import CHAIN

    config = write_config(tmp_path, CHAIN.replace('method = "hb"', ""))
    case = rattle.load_case(config)
    result = rattle.response_map(case, {"model.elements.clutch.friction.2": [0.03]}, omega_points=2,
                                 search=AttractorSearch(bands=1, starts=1, hb_points=0), engine="serial")
    cell = result.cells[0]
    assert cell.status == "ok", cell.message
    frf = rattle.frequency_response(case.model, case.analysis.omega)
    assert frf.omega[0] == result.omega[0]
    assert abs(cell.rms_max_stable[0] / float(frf.rms[0]) - 1.0) <= 1e-9  # the chain's first element


def test_a_bare_discontinuous_system_needs_its_file():
    import rattle

    system = load_config(EXAMPLE).model
    with pytest.raises(TypeError, match=r"`model`: a law with a torque jump or friction is mapped from its file"):
        rattle.response_map(system, {"preload": [0.03]}, omega=(0.6, 0.7), omega_points=2)
