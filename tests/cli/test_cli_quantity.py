"""``--quantity`` of frf, sweep, compare and map: refused (exit 2, naming the option and the
rule, nothing written) where the case cannot give it; otherwise the summary's 'largest' line."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from rattle.cli import cli

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize(("args", "rule"), [
    (["frf", "reference_clutch.toml", "--quantity", "spl_db"], "[[paths]]"),
    (["compare", "reference_clutch.toml", "--quantity", "spl_db"], "[[paths]]"),
    (["map", "reference_clutch.toml", "--vary", "b=0.1:0.2:2", "--quantity", "acc_p2p"], "a response map records"),
    (["frf", "torque_converter_preload.toml", "--quantity", "p2p"], "only --quantity rms"),
    (["sweep", "torque_converter_preload.toml", "--direction", "up", "--quantity", "spl_db"], "[[paths]]"),
])
def test_a_quantity_the_case_cannot_give_is_refused(tmp_path, args, rule) -> None:
    out = tmp_path / "out"
    args = [args[0], str(EXAMPLES / args[1]), *args[2:], "-o", str(out)]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2, result.output
    assert "`--quantity" in result.output and rule in result.output
    assert not out.exists()


def test_frf_rms_ac_reports_the_largest_rattle(tmp_path) -> None:
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["frf", str(EXAMPLES / "gear_backlash.toml"), "--quantity", "rms_ac",
                                      "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "largest stable rms_ac" in result.output and (out / "frf.png").is_file()


def test_help_names_the_quantities() -> None:
    for command in ("frf", "sweep", "compare", "map"):
        text = CliRunner().invoke(cli, [command, "--help"]).output
        assert "--quantity" in text and "rms_ac" in text and "spl_db" in text


def test_an_engine_case_frf_and_orbit_print_their_speeds_in_rpm(tmp_path):
    """rattle frf -v and rattle orbit --rpm on an engine case: every line that gives a speed
    gives it in rpm (Ω in rad/s only beside it, in parentheses), and orbit.png's title too."""
    import re

    from _cli_helpers import invoke

    config = Path(__file__).resolve().parents[2] / "examples" / "engine_clutch_si.toml"
    frf = invoke(["frf", str(config), "-v", "-o", str(tmp_path / "frf")], tmp_path)
    orbit = invoke(["orbit", str(config), "--rpm", "900", "-o", str(tmp_path / "orbit")], tmp_path)
    assert frf.exit_code == 0 and orbit.exit_code == 0, (frf.stderr, orbit.stderr)
    lines = [ln for ln in (frf.stdout + frf.stderr + orbit.stdout + orbit.stderr).splitlines()
             if re.search(r"[0-9] rad/s|Ω = [0-9.]+ (…|rad|\)|;|,)", ln)]  # a speed in rad/s
    assert lines  # the ranges' Ω beside the rpm
    for ln in lines:
        assert "rpm" in ln and re.search(r"\(Ω = [0-9.]+", ln), ln  # rpm first, Ω in parentheses
