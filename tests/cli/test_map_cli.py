"""`rattle map`: its refusals (exit 2, one line naming `--vary` or the option, nothing written),
its output set (map.csv per SPEC §7, map.nc, map.json, map.png, map.md) with a stand-in front
end built from synthetic cells, and one small real run."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import rattle.maps
from rattle.io import read_csv
from rattle.maps import MAP_COLUMNS

from _cli_helpers import PNG, assert_bad_input, invoke, write_config
from _fake_map import synthetic_cell
from rattle.maps import ResponseMap


class FakeFrontEnd:
    """Stands in for rattle.maps.response_map: records its arguments, reports progress, returns
    synthetic cells on the requested grid."""

    def __init__(self, fail: bool = False) -> None:
        self.calls: list[dict[str, Any]] = []
        self.fail = fail

    def __call__(self, model, vary, omega=None, omega_points=146, harmonics=32, *, workers=None, scheduler=None,
                 store=None, progress=None, tables=None, **extra):
        self.calls.append({"model": model, "vary": vary, "omega": omega, "omega_points": omega_points,
                           "harmonics": harmonics, "workers": workers, "scheduler": scheduler, "store": store,
                           "tables": tables})
        params = tuple(vary)
        grid = np.linspace(omega[0], omega[1], omega_points)
        import itertools

        cells = []
        combos = list(itertools.product(*(p.values for p in params)))
        if progress is not None:
            progress(0, len(combos), 0)
        for k, combo in enumerate(combos):
            values = {p.name: v for p, v in zip(params, combo)}
            cell = synthetic_cell(values, grid, shift=float(combo[0]))
            if self.fail:
                from dataclasses import replace

                cell = replace(cell, status="failed", message="ConvergenceError: no start")
            cells.append(cell)
            if progress is not None:
                progress(k + 1, len(combos), 0)
        return ResponseMap(parameters=params, omega=grid, cells=tuple(cells),
                           settings={"harmonics": harmonics, "omega_points": omega_points, "engine": "fake"},
                           timings={"wall": 0.5}, config=dict(tables or {}))


@pytest.fixture
def fake(monkeypatch):
    front = FakeFrontEnd()
    monkeypatch.setattr(rattle.maps, "response_map", front, raising=False)
    return front


def _nothing_written(out: Path) -> bool:
    return not out.exists() or not any(out.iterdir())


# --------------------------------------------------------------------------------------------
# Refusals: exit 2, one line, nothing written, nothing computed
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("args, fragments", [
    (["--vary", "alpha"], ["`--vary`", "no `=`"]),
    (["--vary", "alpha=a:0.3:3"], ["`--vary`", "START must be a number"]),
    (["--vary", "alpha=0.1:0.3:0"], ["`--vary`", "COUNT must be an integer >= 1"]),
    (["--vary", "alpha=0.1:0.3:2.5"], ["`--vary`", "COUNT"]),
    (["--vary", "alpha=0.1:nan:3"], ["`--vary`", "finite"]),
    (["--vary", "alpha=0.1:0.3:3", "--vary", "alpha=0.4,0.5"], ["`--vary`", "twice"]),
    (["--vary", "alhpa=0.1:0.3:3"], ["`--vary`", "model.elastic.alpha"]),
    (["--vary", "model.elastic.type=1,2"], ["`--vary`", "not a number"]),
    (["--vary", "excitation.amplitudes.2=0.01,0.02"], ["`--vary`", "does not add harmonics"]),
    (["--vary", "alpha=0.2:1.5:3"], ["`--vary`", "alpha = 1.5", "the model refuses", "0 <= alpha < 1"]),
    (["--vary", "b=-0.1,0.1"], ["`--vary`", "b = -0.1", "must be > 0"]),
    ([], ["`--vary`", "required"]),
    (["--vary", "alpha=0.1,0.2", "--omega-points", "1"], ["`--omega-points`"]),
    (["--vary", "alpha=0.1,0.2", "--workers", "0"], ["`--workers`"]),
    (["--vary", "alpha=0.1,0.2", "--harmonics", "0"], ["`--harmonics`"]),
    (["--vary", "alpha=0.1,0.2", "--omega-min", "2", "--omega-max", "1"], ["`--omega-min`"]),
    (["--vary", "alpha=0.1,0.2", "--scheduler", " "], ["`--scheduler`"]),
])
def test_bad_input_is_refused_before_any_work(tmp_path, fake, args, fragments):
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke(["map", str(config), "-o", str(out), *args], tmp_path)
    assert_bad_input(result, *fragments)
    assert _nothing_written(out), sorted(p.name for p in out.iterdir())
    assert fake.calls == []


def test_a_chain_short_name_that_is_ambiguous_is_refused(tmp_path, fake):
    config = Path(__file__).resolve().parents[2] / "examples" / "chain_two_inertia.toml"
    out = tmp_path / "out"
    result = invoke(["map", str(config), "-o", str(out), "--vary", "mean=0.04,0.05"], tmp_path)
    assert_bad_input(result, "`--vary`", "ambiguous", "excitation.torques.1.mean")
    assert _nothing_written(out) and fake.calls == []


def test_an_angle_in_degrees_is_varied_as_the_case_file_writes_it(tmp_path, fake):
    """``--vary model.elastic.b_deg=…`` (the case file's ``b_deg``): values in degrees, converted
    as the file converts them; the same map as the radian key's, shown in degrees (issue 27)."""
    config = write_config(tmp_path)
    texts = {}
    for arg in ("model.elastic.b_deg=8,12", f"model.elastic.b={math.radians(8.0)!r},{math.radians(12.0)!r}"):
        out = tmp_path / arg.split("=")[0]
        result = invoke(["map", str(config), "-o", str(out), "--vary", arg, "--omega-points", "6", "--report",
                         "-q"], tmp_path)
        assert result.exit_code == 0, result.stderr
        texts[arg.split("=")[0]] = {f: (out / f).read_text() for f in ("map.csv",)}
    deg, rad = fake.calls[0]["vary"][0], fake.calls[1]["vary"][0]
    assert (deg.name, deg.key, deg.values) == (rad.name, rad.key, rad.values)
    assert deg.degrees  # shown in degrees: the file gave b in degrees, or the key did
    assert texts["model.elastic.b_deg"] == texts["model.elastic.b"]  # map.csv identical (rad)
    report = (tmp_path / "model.elastic.b_deg" / "map.md").read_text()
    assert "8 … 12 deg" in report and "| model.elastic.b (deg) |" in report
    bad = invoke(["map", str(config), "-o", str(tmp_path / "bad"), "--vary", "model.elastic.alpha_deg=1,2"], tmp_path)
    assert_bad_input(bad, "`--vary`", "'model.elastic.alpha_deg'")
    assert len(fake.calls) == 2


# --------------------------------------------------------------------------------------------
# The output set
# --------------------------------------------------------------------------------------------
def test_one_parameter_writes_the_set(tmp_path, fake):
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke(["map", str(config), "-o", str(out), "--vary", "alpha=0.1:0.3:3", "--omega-points", "20",
                     "--harmonics", "8", "--omega-min", "0.5", "--omega-max", "2.5", "--workers", "1"], tmp_path)
    assert result.exit_code == 0, result.stderr
    call = fake.calls[0]
    assert call["omega"] == (0.5, 2.5) and call["omega_points"] == 20 and call["harmonics"] == 8
    assert call["workers"] == 1 and Path(call["store"]) == out
    assert [(p.name, p.key, p.values) for p in call["vary"]] == [("alpha", "model.elastic.alpha", (0.1, 0.2, 0.3))]
    assert call["tables"]["analysis"] == {"omega": [0.5, 2.5], "harmonics": 8}
    assert sorted(p.name for p in out.iterdir()) == ["map.csv", "map.json", "map.nc", "map.png"]
    assert (out / "map.png").read_bytes().startswith(PNG)

    # map.csv: the varied NAME then the SPEC §7 columns; one row per (combination, frequency)
    header = (out / "map.csv").read_text().splitlines()[0]
    assert header == "alpha,omega,n_solutions,n_stable,rms_max_stable,rms_ac_max_stable,regime_max_stable," \
                     "periods_stable,rattle"
    assert tuple(header.split(",")[1:]) == MAP_COLUMNS
    cols = read_csv(out / "map.csv")
    assert len(cols["omega"]) == 3 * 20
    assert set(cols["rattle"].tolist()) == {True, False}
    assert cols["alpha"][0] == 0.1 and cols["alpha"][-1] == 0.3
    rows = (out / "map.csv").read_text().splitlines()[1:]
    holes = [r for r in rows if r.split(",")[4] == ""]  # rms empty where no stable period-1 solution
    assert holes and all(r.split(",")[5] == "" for r in holes)
    assert all(r.split(",")[-1] in ("true", "false") for r in rows)

    # map.json: metadata and per combination the design summary
    meta = json.loads((out / "map.json").read_text())
    assert meta["command"] == "map" and meta["version"]
    assert meta["options"]["vary"] == ["alpha=0.1:0.3:3"]
    assert meta["parameters"] == [{"name": "alpha", "key": "model.elastic.alpha", "values": [0.1, 0.2, 0.3]}]
    assert len(meta["combinations"]) == 3
    first = meta["combinations"][0]
    assert first["values"] == {"alpha": 0.1} and first["status"] == "ok" and first["resumed"] is False
    assert {sp["kind"] for sp in first["special_points"]} == {"fold", "period_doubling"}
    assert set(first["intervals"]) == {"impact", "rattle_free", "subharmonic", "nonperiodic"}
    assert "cli_wall_time" in meta["timings"]

    # map.nc: the dataset
    import xarray as xr

    with xr.open_dataset(out / "map.nc", engine="scipy") as ds:
        assert ds["rms_max_stable"].dims == ("alpha", "omega")
        assert ds["rattle"].shape == (3, 20)
        np.testing.assert_array_equal(ds["alpha"].values, [0.1, 0.2, 0.3])
    assert "response map: 3 combinations" in result.stdout


def test_two_parameters_and_the_report(tmp_path, fake):
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke(["map", str(config), "-o", str(out), "--vary", "alpha=0.1,0.2", "--vary", "b=0.1:0.2:3",
                     "--omega-points", "15", "--report", "-q"], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert sorted(p.name for p in out.iterdir()) == ["map.csv", "map.json", "map.md", "map.nc", "map.png",
                                                     "map_b.png"]
    assert (out / "map_b.png").read_bytes().startswith(PNG)
    assert (out / "map.csv").read_text().splitlines()[0].startswith("alpha,b,omega,")
    report = (out / "map.md").read_text()
    assert "## Rattle-free region" in report and "| alpha | b | rattle-free Ω | impacts Ω |" in report
    assert "What it may still miss" in report

    # a rerun without --report removes the old map.md (the set is replaced together)
    result = invoke(["map", str(config), "-o", str(out), "--vary", "alpha=0.1,0.2", "--vary", "b=0.1:0.2:3",
                     "--omega-points", "15"], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert not (out / "map.md").exists()

    # a map of one parameter into the same folder leaves no map_b.png of the earlier one
    result = invoke(["map", str(config), "-o", str(out), "--vary", "alpha=0.1,0.2", "--omega-points", "15"], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert sorted(p.name for p in out.iterdir()) == ["map.csv", "map.json", "map.nc", "map.png"]


def test_scheduler_is_passed_on_and_needs_dask(tmp_path, fake, monkeypatch):
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke(["map", str(config), "-o", str(out), "--vary", "alpha=0.1,0.2", "--omega-points", "5",
                     "--scheduler", "tcp://127.0.0.1:8786"], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert fake.calls[-1]["scheduler"] == "tcp://127.0.0.1:8786" and fake.calls[-1]["workers"] is None

    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "distributed" else real(name, *a))
    out2 = tmp_path / "out2"
    result = invoke(["map", str(config), "-o", str(out2), "--vary", "alpha=0.1,0.2", "--scheduler", "tcp://h:8786"],
                    tmp_path)
    assert_bad_input(result, "`--scheduler`", "rattle[dask]")
    assert _nothing_written(out2) and len(fake.calls) == 1


def test_every_combination_failing_exits_1_with_the_files(tmp_path, monkeypatch):
    front = FakeFrontEnd(fail=True)
    monkeypatch.setattr(rattle.maps, "response_map", front, raising=False)
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke(["map", str(config), "-o", str(out), "--vary", "alpha=0.1,0.2", "--omega-points", "10"],
                    tmp_path)
    assert result.exit_code == 1, result.stderr
    assert "every combination failed" in result.stderr and "no start" in result.stderr
    assert (out / "map.json").is_file()


def test_progress_counts_combinations_with_resumed_ones_at_once(monkeypatch):
    import io
    import sys

    from rattle.cli.output import MapProgress

    buf = io.StringIO()
    buf.isatty = lambda: True  # type: ignore[method-assign]
    monkeypatch.setattr(sys, "stderr", buf)
    bar = MapProgress("map", enabled=True)
    bar(3, 10, 3)
    assert bar._bar.n == 3 and bar._bar.total == 10
    bar(4, 10, 3)
    bar(10, 10, 3)
    assert bar._bar.n == 10
    bar.close()
    text = buf.getvalue()
    assert "3 resumed" in text and "combination" in text


# --------------------------------------------------------------------------------------------
# One real run (the library's response_map, small)
# --------------------------------------------------------------------------------------------
def test_a_small_real_map(tmp_path):
    if not hasattr(rattle.maps, "response_map"):
        pytest.skip("rattle.maps.response_map is not there yet")
    config = write_config(tmp_path)
    out = tmp_path / "out"
    args = ["map", str(config), "-o", str(out), "--vary", "alpha=0.2:0.3:2", "--omega-points", "12",
            "--harmonics", "8", "--omega-min", "1.3", "--omega-max", "1.6", "--workers", "1", "--report"]
    result = invoke(args, tmp_path)
    assert result.exit_code == 0, result.stderr
    cols = read_csv(out / "map.csv")
    assert len(cols["omega"]) == 2 * 12
    assert cols["alpha"].tolist() == [0.2] * 12 + [0.3] * 12
    meta = json.loads((out / "map.json").read_text())
    assert [c["status"] for c in meta["combinations"]] == ["ok", "ok"]
    assert all(not c["resumed"] for c in meta["combinations"])
    # the rerun reads both combinations back and gives the same map.csv
    before = (out / "map.csv").read_text()
    result = invoke(args, tmp_path)
    assert result.exit_code == 0, result.stderr
    meta = json.loads((out / "map.json").read_text())
    assert all(c["resumed"] for c in meta["combinations"])
    assert (out / "map.csv").read_text() == before
    assert "2 read back" in result.stdout
    rms = [float(x) for x in np.atleast_1d(cols["rms_max_stable"]).tolist() if x != ""]
    assert rms and all(math.isfinite(x) and x > 0 for x in rms)


# --------------------------------------------------------------------------------------------
# The front door: a refused `rattle map` needs none of the numerics (as every other command)
# --------------------------------------------------------------------------------------------
_BLOCKED = (
    "import sys\n"
    "for name in ('scipy', 'matplotlib', 'rattle.analysis', 'rattle.continuation', 'rattle.hb'):\n"
    "    sys.modules[name] = None\n"
    "from rattle.cli.main import main\n"
    "main(sys.argv[1:])\n"
)


@pytest.mark.parametrize("args, fragment", [
    (["--vary", "alpha"], "`--vary` 'alpha' has no `=`"),
    (["--vary", "alpha=0.2:1.5:3"], "the model refuses this value"),
])
def test_a_refused_map_needs_no_numerics(tmp_path, args, fragment):
    import os
    import subprocess
    import sys

    config = write_config(tmp_path)
    src = Path(__file__).resolve().parents[2] / "src"
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(src), env.get("PYTHONPATH")]))
    proc = subprocess.run([sys.executable, "-c", _BLOCKED, "map", str(config), "-o", str(tmp_path / "out"), *args],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("rattle: error: ") and fragment in proc.stderr
    assert not (tmp_path / "out").exists()
