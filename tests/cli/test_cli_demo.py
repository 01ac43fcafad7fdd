"""Command line: ``rattle frf --subharmonics`` (every branch into frf.csv and frf.png) and
``rattle demo`` (the paper's reference case end to end: data, the paper's figures, report.md)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import Result

from rattle.demo import DEMO_FIGURES
from rattle.io import read_csv
from rattle.results import FRF_COLUMNS, SWEEP_COLUMNS
from _cli_helpers import PNG, VALID, invoke

DEMO_FILES = sorted(["frf.csv", "frf.json", "frf.png", "sweep.csv", "fig4_linear_vs_nonlinear.png",
                     "fig5_hbm_vs_simulation.png", "fig6_point_A.png", "fig7_point_B.png",
                     "fig_mean_operating_point.png", "report.md"])


# --------------------------------------------------------------------------------------------
# rattle frf --subharmonics
# --------------------------------------------------------------------------------------------
def test_frf_subharmonics_writes_every_branch(tmp_path: Path) -> None:
    (tmp_path / "case.toml").write_text(VALID, encoding="utf-8")
    # Ω up to 1.6 holds both period-doubling pairs' first points (0.408 … 0.463, 1.243 …)
    result = invoke(["frf", "case.toml", "--subharmonics", "--omega-max", "1.6", "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["frf.csv", "frf.json", "frf.png"]
    cols = read_csv(out / "frf.csv")
    assert list(cols) == [*FRF_COLUMNS, "harmonics"]  # SPEC §3 + §8
    branch = np.asarray(cols["branch"], dtype=int)
    period = np.asarray(cols["period"], dtype=int)
    assert len(np.unique(branch)) > 1
    assert np.any(period == 2) and np.all(period[branch == 0] == 1)
    assert set(np.asarray(cols["bifurcation"]).tolist()) >= {"fold", "period_doubling"}
    assert (out / "frf.png").read_bytes()[:8] == PNG
    meta = json.loads((out / "frf.json").read_text())
    assert meta["options"] == {"omega_max": 1.6, "subharmonics": True}
    assert meta["settings"]["subharmonics"] is True
    assert "branches: 0 (period 1" in result.stdout and "(period 2" in result.stdout


def test_frf_without_the_flag_keeps_one_branch(tmp_path: Path) -> None:
    (tmp_path / "case.toml").write_text(VALID, encoding="utf-8")
    result = invoke(["frf", "case.toml", "--omega-min", "1.0", "--omega-max", "1.6", "--harmonics", "16",
                     "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    cols = read_csv(tmp_path / "out" / "frf.csv")
    assert set(np.asarray(cols["branch"], dtype=int).tolist()) == {0}
    assert "subharmonics" not in json.loads((tmp_path / "out" / "frf.json").read_text())["options"]
    assert "--subharmonics" in invoke(["frf", "--help"], tmp_path).stdout


# --------------------------------------------------------------------------------------------
# rattle demo
# --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Result]:
    """One real ``rattle demo`` run (about 5 s on two cores), shared by the tests below."""
    cwd = tmp_path_factory.mktemp("demo")
    result = invoke(["demo", "-o", "out", "--quiet"], cwd)
    return cwd / "out", result


def test_demo_writes_every_file(demo: tuple[Path, Result]) -> None:
    out, result = demo
    assert result.exit_code == 0, result.stderr
    assert sorted(p.name for p in out.iterdir()) == DEMO_FILES  # no temporary files left
    for name in DEMO_FIGURES.values():
        assert (out / name).read_bytes()[:8] == PNG, name
    frf = read_csv(out / "frf.csv")
    assert list(frf) == [*FRF_COLUMNS, "harmonics"]  # SPEC §3 + §8
    assert len(set(np.asarray(frf["branch"], dtype=int).tolist())) == 3
    sweep = read_csv(out / "sweep.csv")
    assert list(sweep) == [*SWEEP_COLUMNS, "regime"]
    assert np.sum(np.asarray(sweep["direction"]) == "up") == np.sum(np.asarray(sweep["direction"]) == "down") == 200
    meta = json.loads((out / "frf.json").read_text())
    assert meta["command"] == "demo" and meta["options"]["subharmonics"] is True
    assert meta["config"]["model"]["elastic"]["type"] == "clutch"
    assert {"frf", "sweep", "orbits"} <= {k.removeprefix("demo_") for k in meta["timings"]}
    lev = meta["demo"]["level_difference"]
    assert lev["band"] == [0.6, 0.8] and 7.0 < lev["db_min"] < lev["db_max"] < 20.0
    assert meta["demo"]["orbits"]["A"]["simulation"]["period"] == 2
    # the summary and the files written
    assert "point A (Omega = 0.44): simulation period 2" in result.stdout
    assert "linear vs non-linear: acceleration p2p" in result.stdout
    assert re.search(r"wrote 10 files to out: .*report\.md", result.stdout)
    assert result.stderr == ""  # no progress bar off a terminal, no warnings


def test_demo_report_names_the_special_points(demo: tuple[Path, Result]) -> None:
    out, _ = demo
    text = (out / "report.md").read_text(encoding="utf-8")
    for name in DEMO_FIGURES.values():
        assert f"]({name})" in text and (out / name).exists()  # relative links to written files
    # folds (primary resonance and the super-harmonic pairs) and period doublings with their Ω
    assert "0.7539 (primary resonance)" in text and "0.8744 (primary resonance)" in text
    assert "period doubling at Ω = 0.4082, 0.4632, 1.2426, 1.9591" in text
    table = [line for line in text.splitlines() if line.startswith("| fold") or line.startswith("| period doubling")]
    assert len(table) == 18
    assert "| fold | 0 | 1 | 0.87437 |" in text and "| period doubling | 0 | 1 | 1.24258 |" in text
    # jumps next to the folds, the level difference, what the simulation shows at A and B
    assert "HB fold at Ω = 0.8744" in text and "HB fold at Ω = 0.7539" in text
    assert re.search(r"stable solutions are \d+\.\d … 17\.\d dB louder", text)
    assert "the exact solution is periodic with period 2" in text
    assert "half-order harmonic Ω/2" in text
    assert "Timings: harmonic balance" in text
