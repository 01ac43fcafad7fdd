"""``rattle sweep`` and ``rattle compare`` on the discontinuous laws: a preload with friction (the
single equation) and a chain with friction on its elements are swept by their exact event-driven
integrators and written as the usual set (sweep.csv, sweep.json, sweep.png); compare sets the
regularised HB's response (checked by exact shooting) beside that sweep (frf.csv, sweep.csv,
compare.json, compare.png). ``--at`` and ``--measured`` of compare are refused (exit 2, nothing
written)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cases import preload_spring_toml
from _cli_helpers import PNG, assert_bad_input, invoke, write_config
from test_cli_chain_friction import CHAIN as FRICTION_CHAIN
from rattle.io import load_config, read_csv
from rattle.timeint import shoot_friction_orbit, shoot_nonsmooth_orbit

#: The torque converter's preloaded spring (T_p = 0.03) with friction r = 0.02: at Ω = 0.5 … 0.7
#: it sticks part of every period.
PRELOAD = preload_spring_toml((0.5, 0.7), harmonics=32)

#: test_cli_chain_friction.py's chain (two inertias, a clutch with friction on its idle stage) over
#: Ω = 0.55 … 0.65.
CHAIN = FRICTION_CHAIN.replace("omega = [0.9, 0.95]", "omega = [0.55, 0.65]")


def test_sweep_of_a_preload_with_friction_writes_the_set(tmp_path):
    config = write_config(tmp_path, PRELOAD)
    result = invoke(["sweep", str(config), "--direction", "both", "--points", "3", "-q", "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["sweep.csv", "sweep.json", "sweep.png"]
    assert (out / "sweep.png").read_bytes()[:8] == PNG
    table = read_csv(out / "sweep.csv")
    assert list(table)[-1] == "stick_fraction" and len(table["omega"]) == 6
    assert list(table["direction"]) == ["up"] * 3 + ["down"] * 3
    stick = np.asarray(table["stick_fraction"], dtype=float)
    assert np.all((stick > 0.0) & (stick < 1.0))  # it sticks on every row
    assert "held (stuck or locked): 6 of 6 rows" in result.stdout
    meta = json.loads((out / "sweep.json").read_text())
    assert meta["command"] == "sweep" and meta["points"] == 6
    # a row's rms is the exact orbit's from its own state
    system = load_config(config).model
    w = float(table["omega"][1])
    orbit = shoot_nonsmooth_orbit(system, w, (0.0, 0.0))
    assert orbit.converged and abs(orbit.rms - float(table["rms"][1])) <= 1e-9


def test_sweep_of_a_chain_with_friction_writes_per_element_columns(tmp_path):
    config = write_config(tmp_path, CHAIN)
    result = invoke(["sweep", str(config), "--direction", "up", "--points", "2", "-q", "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["sweep.csv", "sweep.json", "sweep.png"]
    table = read_csv(out / "sweep.csv")
    for column in ("clutch_rms", "clutch_acc_p2p", "clutch_stick_fraction"):
        assert column in table
    np.testing.assert_array_equal(table["clutch_rms"], table["rms"])
    system = load_config(config).model
    from rattle.analysis._steady import static_state

    w = float(table["omega"][1])
    orbit = shoot_friction_orbit(system, w, static_state(system, w))
    assert orbit.converged
    assert abs(float(orbit.rms[0]) - float(table["rms"][1])) <= 1e-9
    assert abs(float(orbit.stick_fraction[0]) - float(table["clutch_stick_fraction"][1])) <= 1e-9


def test_compare_of_a_preload_with_friction_writes_the_set(tmp_path):
    config = write_config(tmp_path, PRELOAD.replace("harmonics = 32", "harmonics = 32\nrefine = 0"))
    result = invoke(["compare", str(config), "--points", "3", "--omega-min", "0.6", "--omega-max", "0.65", "-q",
                     "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["compare.json", "compare.png", "frf.csv", "sweep.csv"]
    assert (out / "compare.png").read_bytes()[:8] == PNG
    frf, sweep = read_csv(out / "frf.csv"), read_csv(out / "sweep.csv")
    assert "rms_hb" in frf and "matched" in frf and "stick_fraction" in sweep and len(sweep["omega"]) == 6
    meta = json.loads((out / "compare.json").read_text())
    assert meta["command"] == "compare" and meta["orbits"] == []
    agreement = meta["agreement"]
    assert agreement["rows"] == agreement["compared"] == 6 and agreement["largest"] < 1e-4
    assert "sweep against the response: 6 of 6 settled period-1 rows" in result.stdout


def test_compare_of_a_chain_with_friction_writes_the_set(tmp_path):
    config = write_config(tmp_path, CHAIN)
    result = invoke(["compare", str(config), "--points", "2", "--omega-min", "0.9", "--omega-max", "0.95", "-q",
                     "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["compare.json", "compare.png", "frf.csv", "sweep.csv"]
    assert "clutch_rms_hb" in read_csv(out / "frf.csv") and "clutch_stick_fraction" in read_csv(out / "sweep.csv")
    agreement = json.loads((out / "compare.json").read_text())["agreement"]
    assert agreement["compared"] == agreement["rows"] == 4 and agreement["largest"] < 1e-9


@pytest.mark.parametrize("text, keys", [(PRELOAD, "`model.elastic.preload` and `model.elastic.friction`"),
                                        (CHAIN, "`model.elements.1.friction`")])
@pytest.mark.parametrize("args, fragment", [
    (["compare", "--at", "0.6"], "`--at` is not supported for a discontinuous law"),
    (["compare", "--measured", "run.csv"], "`--measured` is not supported for a discontinuous law"),
])
def test_the_options_and_commands_that_remain_refused_exit_2_and_write_nothing(tmp_path, text, keys, args, fragment):
    config = write_config(tmp_path, text)
    (tmp_path / "run.csv").write_text("omega,acc_p2p\n0.6,0.1\n0.65,0.1\n", encoding="utf-8")
    result = invoke([args[0], str(config), *args[1:], "-o", "out"], tmp_path)
    assert_bad_input(result, keys, fragment)
    assert not (tmp_path / "out").exists()
