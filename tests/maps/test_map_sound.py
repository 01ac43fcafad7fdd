"""Response maps with sound paths (SPEC §6 + §7 extension column ``spl_max_stable_db``): the
level against the frequency response's at the same Ω, the columns, the store's key following
the paths' tables, and the command line."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import rattle
from rattle.analysis._attractors import AttractorSearch
from rattle.maps import CellResult, response_map
from rattle.maps._cell import _failed
from rattle.maps._result import MAP_COLUMNS, Parameter, ResponseMap
from rattle.model import SoundPath

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SEARCH = AttractorSearch(bands=1, starts=1)
#: Ω = 64 … 66 rad/s: a stable period-1 stretch of the example, below its fold at 75.4 rad/s.
RANGE = (64.0, 66.0)


@pytest.fixture(scope="module")
def config():
    return rattle.io.load_config(EXAMPLES / "clutch_with_paths.toml")


@pytest.fixture(scope="module")
def sound_map(config):
    return response_map(config, {"model.elements.clutch.alpha": [0.25]}, omega=RANGE, omega_points=3, harmonics=16,
                        search=SEARCH, engine="serial")


def constant(c: float) -> list[SoundPath]:
    return [SoundPath(source="clutch", frequency_hz=[1e-3, 1e5], magnitude=[c, c], phase_deg=[0.0, 0.0])]


def test_level_is_the_frequency_responses_at_the_same_omega(config, sound_map):
    """The map's grid ends are the continuation's first and last rows; there the only (stable,
    period-1) solution is the one frf.csv's spl_db is computed from: the same level to the
    Newton tolerance of the grid's re-solve."""
    frf = rattle.frequency_response(config.model, omega=RANGE, harmonics=16)
    sp = rattle.sound_pressure(frf, config.paths)
    cell = sound_map.cells[0]
    assert list(cell.n_stable) == [1, 1, 1] and list(cell.periods_stable) == ["1", "1", "1"]
    np.testing.assert_array_equal(sound_map.omega[[0, -1]], frf.omega[[0, -1]])
    np.testing.assert_allclose(cell.spl_max_stable_db[[0, -1]], sp.spl_db[[0, -1]], atol=1e-8, rtol=0)
    # the frf's level rises monotonically over the stretch, and so does the map's
    assert np.all(np.diff(cell.spl_max_stable_db) > 0)


def test_columns_dataset_and_round_trip(sound_map, tmp_path):
    assert sound_map.has_sound
    names = sound_map.column_names
    assert names == ["model.elements.clutch.alpha", *MAP_COLUMNS, "spl_max_stable_db"]
    path = sound_map.to_csv(tmp_path / "map.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert header == names
    rows = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    np.testing.assert_array_equal(rows["spl_max_stable_db"], sound_map.cells[0].spl_max_stable_db)
    ds = sound_map.dataset
    assert ds["spl_max_stable_db"].dims == ("model.elements.clutch.alpha", "omega")
    np.testing.assert_array_equal(ds["spl_max_stable_db"].values[0], sound_map.cells[0].spl_max_stable_db)
    cell = sound_map.cells[0]
    back = CellResult.from_dict(cell.to_dict())
    np.testing.assert_array_equal(back.spl_max_stable_db, cell.spl_max_stable_db)  # bit for bit


def test_no_paths_no_column(config):
    plain = response_map(config.model, {"alpha": [0.25]}, omega=(64.0, 64.5), omega_points=2, harmonics=8,
                         search=SEARCH, engine="serial")
    assert not plain.has_sound and plain.cells[0].spl_max_stable_db is None
    assert "spl_max_stable_db" not in plain.column_names and "spl_max_stable_db" not in plain.dataset
    assert "spl_max_stable_db" not in plain.cells[0].to_dict()


def test_a_failed_combination_leaves_the_level_empty():
    grid = np.linspace(1.0, 2.0, 3)
    cell = CellResult.from_dict(_failed({"alpha": 0.2}, grid, "ConvergenceError: x", 0.1, sound=True))
    m = ResponseMap(parameters=(Parameter("alpha", "model.elastic.alpha", (0.2,)),), omega=grid, cells=(cell,),
                    paths=tuple(constant(1.0)))
    assert m.columns()["spl_max_stable_db"] == [None, None, None]


def test_store_key_follows_the_path_tables(config, tmp_path):
    """A rerun with the same paths reads the combination back; a path whose magnitude is doubled
    is a different combination (recomputed), louder by exactly 20 log10 2 dB at every Ω (the
    largest stable solution is the same one)."""
    kw = dict(omega=(64.0, 65.0), omega_points=2, harmonics=8, search=SEARCH, engine="serial", store=tmp_path)
    first = response_map(config.model, {"alpha": [0.25]}, paths=constant(1e-5), **kw)
    again = response_map(config.model, {"alpha": [0.25]}, paths=constant(1e-5), **kw)
    assert first.timings["resumed"] == 0 and again.timings["resumed"] == 1
    np.testing.assert_array_equal(again.cells[0].spl_max_stable_db, first.cells[0].spl_max_stable_db)
    louder = response_map(config.model, {"alpha": [0.25]}, paths=constant(2e-5), **kw)
    assert louder.timings["resumed"] == 0
    np.testing.assert_allclose(louder.cells[0].spl_max_stable_db - first.cells[0].spl_max_stable_db,
                               20 * math.log10(2.0), atol=1e-12, rtol=0)
    none = response_map(config.model, {"alpha": [0.25]}, paths=(), **kw)
    assert none.timings["resumed"] == 0 and not none.has_sound


def test_a_source_the_model_lacks_is_refused(config):
    bad = [SoundPath(source="gear", frequency_hz=[1.0, 2.0], magnitude=[1.0, 1.0], phase_deg=[0.0, 0.0])]
    with pytest.raises(ValueError, match="paths\\[0\\].source"):
        response_map(config.model, {"alpha": [0.25]}, omega=RANGE, omega_points=2, paths=bad, engine="serial")


def test_cli_map_writes_the_column(tmp_path, sound_map):
    from click.testing import CliRunner

    from rattle.cli.main import cli

    out = tmp_path / "out"
    res = CliRunner().invoke(cli, ["map", str(EXAMPLES / "clutch_with_paths.toml"), "--vary",
                                   "model.elements.clutch.alpha=0.25", "--omega-points", "3", "--omega-min", "64",
                                   "--omega-max", "66", "--harmonics", "16", "--workers", "1", "-o", str(out), "-q"])
    assert res.exit_code == 0, res.output
    header = (out / "map.csv").read_text().splitlines()[0].split(",")
    assert header[-1] == "spl_max_stable_db" and header[1:-1] == list(MAP_COLUMNS)
    rows = np.genfromtxt(out / "map.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    # the CLI's search differs from the fixture's, not the stable period-1 solutions found here
    np.testing.assert_allclose(rows["spl_max_stable_db"], sound_map.cells[0].spl_max_stable_db, atol=1e-9, rtol=0)


def test_heat_map_of_the_level(sound_map, config):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = sound_map.plot(quantity="spl")
    mesh = axes["map"].collections[0]
    np.testing.assert_array_equal(np.asarray(mesh.get_array()).ravel(), sound_map.cells[0].spl_max_stable_db)
    assert "sound pressure level" in axes["colorbar"].get_ylabel()
    plt.close(fig)
    plain = dataclasses.replace(sound_map, paths=())
    with pytest.raises(ValueError, match="quantity"):
        plain.plot(quantity="spl")
    with pytest.raises(ValueError, match="quantity"):
        sound_map.plot(quantity="loudness")
