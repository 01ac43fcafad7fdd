"""``rattle compare CONFIG --measured FILE.csv``: measured points tabled against the computed
curves (measured.csv) and drawn over them (compare.png); every refusal exit 2 with nothing
written, before any computation."""

from __future__ import annotations

import json
import math
import shutil
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from rattle.io import read_csv
from rattle.results._measured import hb_largest_stable
from _cli_helpers import PNG, VALID, assert_bad_input, invoke

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SI = EXAMPLES / "engine_clutch_si.toml"
#: The SI example over a short range after its fold: the up sweep lands on a period-2 rattle there.
SI_RANGE = ["--rpm-min", "1100", "--rpm-max", "1300"]


def _frf_table(path: Path, quantity: str) -> SimpleNamespace:
    """The columns of frf.csv that the HB interpolation reads."""
    cols = read_csv(path)
    return SimpleNamespace(branch=cols["branch"], omega=cols["omega"], stable=np.asarray(cols["stable"], bool),
                           acc_p2p=cols["acc_p2p"], extra_columns={quantity: cols[quantity]})


def test_measured_made_from_the_sweep_itself_differs_by_round_off(tmp_path: Path) -> None:
    # the "measured" run-up: the up sweep's own points (rpm and acc_p2p), written with repr
    sweep = invoke(["sweep", str(SI), "--direction", "up", "--points", "6", *SI_RANGE, "-o", "s", "-q"], tmp_path)
    assert sweep.exit_code == 0, sweep.stderr
    s = read_csv(tmp_path / "s" / "sweep.csv")
    lines = ["# made from rattle sweep --direction up", "speed_rpm,acc_p2p"]
    lines += [f"{float(r)!r},{float(a)!r}" for r, a in zip(s["speed_rpm"], s["acc_p2p"])]
    (tmp_path / "run.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")

    result = invoke(["compare", str(SI), "--points", "6", "--harmonics", "6", *SI_RANGE, "--measured", "run.csv",
                     "-o", "out", "-q"], tmp_path)
    assert result.exit_code == 0, result.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["compare.json", "compare.png", "frf.csv", "measured.csv",
                                                     "sweep.csv"]
    assert "wrote frf.csv, sweep.csv, compare.json, compare.png, measured.csv" in result.stdout
    m = read_csv(out / "measured.csv")
    assert list(m) == ["speed_rpm", "omega", "acc_p2p", "acc_p2p_hb", "acc_p2p_sweep_up", "acc_p2p_sweep_down",
                       "acc_p2p_rel_hb", "acc_p2p_rel_sweep_up", "acc_p2p_rel_sweep_down"]
    np.testing.assert_array_equal(m["speed_rpm"], s["speed_rpm"])
    # engine order 2: Ω = 2 · 2π/60 · rpm
    np.testing.assert_allclose(m["omega"], s["speed_rpm"] * 4.0 * math.pi / 60.0, rtol=1e-15)
    # the same sweep again: the up difference is the round-off of rpm → Ω → interpolation
    assert np.max(np.abs(m["acc_p2p_rel_sweep_up"])) < 1e-12
    c = read_csv(out / "sweep.csv")
    up, down = c["direction"] == "up", c["direction"] == "down"
    np.testing.assert_allclose(m["acc_p2p_sweep_up"], c["acc_p2p"][up], rtol=1e-12)
    np.testing.assert_allclose(m["acc_p2p_sweep_down"], c["acc_p2p"][down][::-1], rtol=1e-12)
    # the HB column is the largest stable value of the frf.csv written beside it, interpolated
    hb = hb_largest_stable(_frf_table(out / "frf.csv", "acc_p2p"), "acc_p2p", m["omega"])
    np.testing.assert_allclose(m["acc_p2p_hb"], hb, rtol=1e-12)
    np.testing.assert_allclose(m["acc_p2p_rel_hb"], hb / m["acc_p2p"] - 1.0, rtol=1e-12, atol=1e-15)
    assert "measured acc_p2p (6 points, run.csv): largest difference hb" in result.stdout
    assert " rpm" in result.stdout.split("measured acc_p2p")[1].splitlines()[0]
    assert (out / "compare.png").read_bytes()[:8] == PNG
    meta = json.loads((out / "compare.json").read_text())
    assert meta["options"]["measured"] == "run.csv"


def test_measured_spl_against_the_harmonic_balance(tmp_path: Path) -> None:
    for name in ("clutch_with_paths.toml", "clutch_path.csv", "gearbox_path.csv"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    (tmp_path / "run.csv").write_text("omega,spl_db,acc_p2p\n101.0,70.0,300.0\n104.5,71.0,310.0\n108.0,72.0,320.0\n",
                                      encoding="utf-8")
    result = invoke(["compare", "clutch_with_paths.toml", "--points", "4", "--harmonics", "6", "--omega-min", "100",
                     "--omega-max", "110", "--at", "105", "--measured", "run.csv", "-o", "out", "-q"], tmp_path)
    assert result.exit_code == 0, result.stderr
    m = read_csv(tmp_path / "out" / "measured.csv")
    assert list(m)[:2] == ["omega", "acc_p2p"] and "speed_rpm" not in m  # no engine: no rpm
    assert m["omega"].tolist() == [101.0, 104.5, 108.0]
    hb = hb_largest_stable(_frf_table(tmp_path / "out" / "frf.csv", "spl_db"), "spl_db", m["omega"])
    assert np.all(np.isfinite(hb))
    np.testing.assert_allclose(m["spl_db_hb"], hb, rtol=1e-12)
    np.testing.assert_allclose(m["spl_db_diff_hb"], hb - np.array([70.0, 71.0, 72.0]), rtol=1e-12)
    # the sweeps carry their sound pressure (SweepResult.with_sound): written in sweep.csv, compared too, in dB
    s = read_csv(tmp_path / "out" / "sweep.csv")
    assert {"spl_db", "spl_dba", "spl_linear_db"} <= set(s) and np.all(np.isfinite(s["spl_db"]))
    assert np.all(np.isfinite(m["spl_db_sweep_up"])) and np.all(np.isfinite(m["spl_db_sweep_down"]))
    np.testing.assert_allclose(m["spl_db_diff_sweep_up"], m["spl_db_sweep_up"] - np.array([70.0, 71.0, 72.0]),
                               rtol=1e-12)
    assert np.all(np.isfinite(m["acc_p2p_sweep_up"]))


# --------------------------------------------------------------------------------------------
# Refusals: exit 2, one line, nothing written, nothing computed
# --------------------------------------------------------------------------------------------
@pytest.fixture
def case(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "case.toml").write_text(VALID, encoding="utf-8")  # the reference clutch over 0.1 … 3 rad/s
    monkeypatch.setitem(sys.modules, "rattle.analysis", None)      # refused before the solver is imported
    return tmp_path


BAD = [
    ("missing file", None, ["`--measured`", "'run.csv' does not exist"]),
    ("no speed column", "acc_p2p\n0.5\n", ["line 1", "no speed column"]),
    ("no quantity column", "omega\n1.0\n", ["line 1", "no measured quantity"]),
    ("unknown column", "omega,acc_p2p,oil_temp\n1,0.5,80\n", ["line 1, column 3", "'oil_temp' is not known"]),
    ("non-numeric", "omega,acc_p2p\n1.0,0.5\n1.1,n/a\n", ["line 3, column `acc_p2p`", "must be a number", "'n/a'"]),
    ("non-finite", "omega,acc_p2p\n1.0,0.5\n1.1,inf\n", ["line 3, column `acc_p2p`", "finite"]),
    ("not monotonic", "omega,acc_p2p\n1.0,0.5\n1.2,0.5\n1.2,0.6\n", ["line 4, column `omega`", "strictly increasing"]),
    ("outside the range", "omega,acc_p2p\n2.5,0.5\n3.5,0.5\n",
     ["line 3, column `omega`", "3.5 rad/s lies outside the analysis range 0.1 … 3 rad/s"]),
    ("rpm without an engine", "speed_rpm,acc_p2p\n900,0.5\n", ["column `speed_rpm`", "no engine"]),
    ("spl without paths", "omega,spl_db\n1.0,70\n", ["column `spl_db`", "no [[paths]]"]),
]


@pytest.mark.parametrize("text, fragments", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_refused_before_anything_is_computed_or_written(case: Path, text: str | None, fragments: list[str]) -> None:
    if text is not None:
        (case / "run.csv").write_text(text, encoding="utf-8")
    result = invoke(["compare", "case.toml", "--measured", "run.csv", "-o", "out"], case)
    assert_bad_input(result, *fragments)
    assert not (case / "out").exists()


def test_range_narrowed_by_an_option_refuses_and_leaves_old_outputs(case: Path) -> None:
    (case / "out").mkdir()
    (case / "out" / "measured.csv").write_text("old", encoding="utf-8")
    (case / "run.csv").write_text("omega,acc_p2p\n0.9,0.5\n1.2,0.6\n", encoding="utf-8")
    result = invoke(["compare", "case.toml", "--omega-max", "1.0", "--measured", "run.csv", "-o", "out"], case)
    assert_bad_input(result, "line 3, column `omega`", "1.2 rad/s lies outside the analysis range 0.1 … 1 rad/s",
                     "--omega-min/--omega-max")
    assert [p.name for p in (case / "out").iterdir()] == ["measured.csv"]
    assert (case / "out" / "measured.csv").read_text() == "old"


def test_measured_is_in_the_help(case: Path) -> None:
    text = invoke(["compare", "--help"], case).stdout
    assert "--measured FILE.csv" in text
