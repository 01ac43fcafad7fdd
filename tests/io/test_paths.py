"""``[[paths]]``: path tables read strictly from CSV (SPEC §6); every refusal a ConfigError naming
the key and the rule, and exit 2 from the command line with nothing written."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from rattle.cli.main import cli
from rattle.errors import ConfigError
from rattle.io import load_config, read_csv, read_path_csv

CHAIN = """\
[model]
inertias = [2.0, 2.0]

[[model.links]]
between = [1, 2]
damping = 0.05

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 1.0
type = "clutch"
alpha = 0.25
b = 0.174533

[[excitation.torques]]
inertia = 1
mean = 0.05
amplitudes = [0.06]

[[excitation.torques]]
inertia = 2
mean = -0.05

[analysis]
omega = [1.0, 1.3]
harmonics = 6
"""

SINGLE = """\
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "clutch"
alpha = 0.25
b = 0.174533

[excitation]
mean = 0.05
amplitudes = [0.03]

[analysis]
omega = [1.0, 1.3]
harmonics = 6
"""

GOOD_CSV = "frequency_hz,magnitude,phase_deg\n0.01,1e-3,0\n0.1,2e-3,90\n1.0,1e-3,-170\n"


def paths_block(source: str = "clutch", file: str = "gear_path.csv") -> str:
    return f'\n[[paths]]\nsource = "{source}"\nfile = "{file}"\n'


def write_case(folder: Path, csv_text: str | None = GOOD_CSV, block: str | None = None, base: str = CHAIN) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    if csv_text is not None:
        (folder / "gear_path.csv").write_text(csv_text, encoding="utf-8")
    case = folder / "case.toml"
    block = paths_block() if block is None else block
    # a top-level key (not a table) must come before the first table
    case.write_text(block + base if block.startswith("\npaths =") else base + block, encoding="utf-8")
    return case


def test_paths_are_read_relative_to_the_configuration_folder(tmp_path, monkeypatch):
    case = write_case(tmp_path / "cases")
    monkeypatch.chdir(tmp_path)  # not the configuration's folder
    cfg = load_config(case)
    (path,) = cfg.paths
    assert path.source == "clutch" and path.name == "gear_path.csv"
    np.testing.assert_array_equal(path.frequency_hz, [0.01, 0.1, 1.0])
    np.testing.assert_array_equal(path.magnitude, [1e-3, 2e-3, 1e-3])
    # the phase -170 after 90 is unwrapped to 190: halfway between 0.1 and 1 Hz it is 140°
    assert path.response(0.55) == pytest.approx(1.5e-3 * complex(math.cos(math.radians(140)), math.sin(math.radians(140))))
    assert cfg.source["paths"] == [{"source": "clutch", "file": "gear_path.csv"}]
    # without [[paths]] nothing changes
    assert load_config(write_case(tmp_path / "plain", block="")).paths == ()


def test_columns_in_any_order_comments_and_spaces(tmp_path):
    text = "# measured 2026, illustrative\nphase_deg, frequency_hz ,magnitude\n\n10, 1.0, 0.5\n# a comment\n20,2.0,0.25\n"
    (tmp_path / "p.csv").write_text(text, encoding="utf-8")
    path = read_path_csv(tmp_path / "p.csv", "inertia:2")
    np.testing.assert_array_equal(path.frequency_hz, [1.0, 2.0])
    np.testing.assert_array_equal(path.phase_deg, [10.0, 20.0])
    assert path.target == 2 and path.kind == "inertia"


BAD_TABLES = [
    ("frequency_hz,magnitude\n1,1\n", "lacks the column(s) phase_deg"),
    ("frequency_hz,magnitude,phase_deg,coherence\n1,1,0,1\n", "column 'coherence' is not known"),
    ("frequency_hz,magnitude,magnitude,phase_deg\n1,1,1,0\n", "appears 2 times"),
    ("frequency_hz,magnitude,phase_deg\n1,abc,0\n", "`magnitude` must be a number, got 'abc'"),
    ("frequency_hz,magnitude,phase_deg\n1,1,nan\n", "`phase_deg` must be a finite number"),
    ("frequency_hz,magnitude,phase_deg\n1,inf,0\n", "`magnitude` must be a finite number"),
    ("frequency_hz,magnitude,phase_deg\n1,-1,0\n", "`magnitude` must be >= 0"),
    ("frequency_hz,magnitude,phase_deg\n2,1,0\n1,1,0\n", "strictly increasing"),
    ("frequency_hz,magnitude,phase_deg\n1,1,0\n1,1,0\n", "strictly increasing"),
    ("frequency_hz,magnitude,phase_deg\n0,1,0\n1,1,0\n", "must be > 0 Hz"),
    ("frequency_hz,magnitude,phase_deg\n-5,1,0\n", "must be > 0 Hz"),
    ("frequency_hz,magnitude,phase_deg\n1,1\n", "has 2 fields, the header has 3"),
    ("frequency_hz,magnitude,phase_deg\n", "no rows"),
    ("", "is empty"),
    ("frequency_hz;magnitude;phase_deg\n1;1;0\n", "is not comma-separated"),
    (b"frequency_hz,magnitude,phase_deg\n1,\xff,0\n", "not UTF-8"),
]


@pytest.mark.parametrize(("text", "fragment"), BAD_TABLES, ids=[f[1][:24] for f in BAD_TABLES])
def test_bad_tables_are_refused_naming_the_key(tmp_path, text, fragment):
    case = write_case(tmp_path, csv_text=None)
    target = tmp_path / "gear_path.csv"
    target.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
    with pytest.raises(ConfigError) as info:
        load_config(case)
    message = str(info.value)
    assert "`paths[0].file`" in message and fragment in message, message
    assert message.startswith(os.fspath(case))


BAD_ENTRIES = [
    (None, "does not exist", "`paths[0].file`"),  # no CSV file written
    (paths_block("gear"), "must name an element of the model ('clutch')", "`paths[0].source`"),
    (paths_block("inertia:3"), "must name an inertia 1 … 2", "`paths[0].source`"),
    (paths_block("inertia:two"), "inertia:N", "`paths[0].source`"),
    ('\n[[paths]]\nsource = "clutch"\n', "is missing", "`paths[0].file`"),
    ('\n[[paths]]\nsource = "clutch"\nfile = "gear_path.csv"\ngain = 2\n', "not a known key", "`paths[0].gain`"),
    ('\n[[paths]]\nsource = 1\nfile = "gear_path.csv"\n', "must be a non-empty string", "`paths[0].source`"),
    ('\npaths = "gear_path.csv"\n', "must be an array of tables", "`paths`"),
    (paths_block() + paths_block(file="missing.csv"), "does not exist", "`paths[1].file`"),
    (paths_block(file="."), "is a directory", "`paths[0].file`"),
]


@pytest.mark.parametrize(("block", "fragment", "key"), BAD_ENTRIES, ids=[f"{e[2]}-{e[1][:16]}" for e in BAD_ENTRIES])
def test_bad_entries_are_refused_naming_the_key(tmp_path, block, fragment, key):
    case = write_case(tmp_path, csv_text=None if fragment == "does not exist" and block is None else GOOD_CSV,
                      block=paths_block() if block is None else block)
    with pytest.raises(ConfigError) as info:
        load_config(case)
    assert key in str(info.value) and fragment in str(info.value), str(info.value)


def test_inertia_source_of_the_single_equation_is_refused(tmp_path):
    case = write_case(tmp_path, block=paths_block("inertia:1"), base=SINGLE)
    with pytest.raises(ConfigError, match=r"`paths\[0\]\.source`.*single-equation model"):
        load_config(case)
    assert load_config(write_case(tmp_path / "ok", block=paths_block("delta"), base=SINGLE)).paths[0].source == "delta"


# --- the command line ----------------------------------------------------------------------------
def _invoke(args: list[str], cwd: Path):
    old = Path.cwd()
    os.chdir(cwd)
    try:
        try:
            runner = CliRunner(mix_stderr=False)  # type: ignore[call-arg]
        except TypeError:
            runner = CliRunner()
        return runner.invoke(cli, args, catch_exceptions=False)
    finally:
        os.chdir(old)


def test_frf_writes_the_spl_column(tmp_path):
    write_case(tmp_path / "case", csv_text="frequency_hz,magnitude,phase_deg\n1e-3,1e-3,0\n100,1e-3,0\n")
    result = _invoke(["frf", "case/case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 0, result.stderr
    table = read_csv(tmp_path / "out" / "frf.csv")
    assert list(table)[-3:] == ["spl_db", "spl_dba", "spl_linear_db"]
    # a constant 1e-3 Pa per rad/s² path on the clutch: spl = 20 log10(1e-3 rms_ac(δ'') / 20 µPa)
    cfg = load_config(tmp_path / "case" / "case.toml")
    import rattle

    frf = rattle.frequency_response(cfg.model, omega=cfg.analysis.omega, harmonics=cfg.analysis.harmonics)
    np.testing.assert_allclose(table["spl_db"], frf.with_sound(cfg.paths).extra_columns["spl_db"], rtol=1e-12)
    assert np.all(np.isfinite(table["spl_db"])) and np.all(table["spl_db"] > 0)


@pytest.mark.parametrize("csv_text", ["frequency_hz,magnitude\n1,1\n", "frequency_hz,magnitude,phase_deg\n1,-1,0\n"])
def test_frf_refuses_a_bad_path_with_exit_2_and_writes_nothing(tmp_path, csv_text):
    write_case(tmp_path / "case", csv_text=csv_text)
    result = _invoke(["frf", "case/case.toml", "-o", "out"], tmp_path)
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    assert "`paths[0].file`" in result.stderr and result.stdout == ""
    assert not (tmp_path / "out" / "frf.csv").exists()
