"""Hostile input at the command line: every case is refused with exit status 2, one line on
stderr naming the option (or the file) and the rule, nothing on stdout, nothing written — before
the solver is imported (``rattle.analysis`` is made unimportable for the in-process cases; the
subprocess cases also make scipy and matplotlib unimportable).

The library and configuration-value side of the issue's hostile sweep is in
``tests/test_hostile_api.py``; signals sent to a running command are in ``tests/test_signals.py``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from _cli_helpers import VALID, assert_bad_input, invoke  # type: ignore[import-not-found]  # tests/cli, via conftest

SRC = Path(__file__).resolve().parents[1] / "src"

FAST = VALID.replace("omega = [0.1, 3.0]", "omega = [0.5, 0.8]").replace("harmonics = 32", "harmonics = 8")
LONG_NAME = "a" * 300
LONG_PATH = "/".join(["d" * 200] * 21)  # 4220 bytes, every name short enough


def _setup_none(tmp: Path) -> None:
    pass


def _file_named(name: str) -> Callable[[Path], None]:
    def setup(tmp: Path) -> None:
        (tmp / name).write_text("keep me")

    return setup


def _dangling(tmp: Path) -> None:
    os.symlink(tmp / "nowhere", tmp / "dangling")


def _link_to_proc(tmp: Path) -> None:
    os.symlink("/proc", tmp / "procs")


def _fifo(tmp: Path) -> None:
    os.mkfifo(tmp / "pipe.toml")


def _big(tmp: Path) -> None:
    with open(tmp / "big.toml", "wb") as fh:
        fh.write(b"# " + b"x" * (1 << 20) + b"\n")


def _link_to_zero(tmp: Path) -> None:
    os.symlink("/dev/zero", tmp / "zero.toml")


def _binary(tmp: Path) -> None:
    (tmp / "bin.toml").write_bytes(b"\xff\xfe\x00model")


def _empty(tmp: Path) -> None:
    (tmp / "empty.toml").write_bytes(b"")


def _subdir(tmp: Path) -> None:
    (tmp / "folder.toml").mkdir()


F = ["frf", "case.toml"]
S = ["sweep", "case.toml", "--direction", "up"]
O = ["orbit", "case.toml", "--omega", "0.6"]
C = ["compare", "case.toml"]

# (id, arguments, set-up in the working folder, fragments of the one error line)
CASES: list[tuple[str, list[str], Callable[[Path], None], list[str]]] = [
    # --- output paths -------------------------------------------------------------------------
    ("-o empty", [*F, "-o", ""], _setup_none, ["`--output` must name a folder", "''"]),
    ("-o blank", [*F, "-o", "   "], _setup_none, ["`--output` must name a folder"]),
    ("-o 300-character name", [*F, "-o", LONG_NAME], _setup_none, ["`--output`", "300 bytes", "255"]),
    ("-o 300-character name below", [*F, "-o", f"out/{LONG_NAME}/x"], _setup_none, ["`--output`", "300 bytes"]),
    ("-o path over PATH_MAX", [*F, "-o", LONG_PATH], _setup_none, ["`--output` is a path of", "4096"]),
    ("-o /proc/x", [*F, "-o", "/proc/x"], _setup_none, ["`--output` '/proc/x'", "proc file system"]),
    ("-o /proc/self", [*F, "-o", "/proc/self"], _setup_none, ["`--output` '/proc/self'", "proc"]),
    ("-o /sys/x", [*F, "-o", "/sys/x"], _setup_none, ["`--output` '/sys/x'", "file system"]),
    ("-o /dev/x", [*F, "-o", "/dev/x"], _setup_none, ["`--output` '/dev/x'", "file system"]),
    ("-o symlink to /proc", [*F, "-o", "procs/x"], _link_to_proc, ["`--output` 'procs/x'", "proc"]),
    ("-o existing file", [*F, "-o", "taken"], _file_named("taken"), ["`--output` must be a directory"]),
    ("-o below a file", [*F, "-o", "taken/sub"], _file_named("taken"), ["`--output`", "'taken' is a file"]),
    ("-o broken symlink", [*F, "-o", "dangling"], _dangling, ["`--output`", "broken symbolic link"]),
    ("-o through broken symlink", [*F, "-o", "dangling/sub"], _dangling, ["`--output`", "broken symbolic link"]),
    ("sweep -o /proc/x", [*S, "-o", "/proc/x"], _setup_none, ["`--output`", "proc"]),
    ("orbit -o long name", [*O, "-o", LONG_NAME], _setup_none, ["`--output`", "300 bytes"]),
    ("compare -o empty", [*C, "-o", ""], _setup_none, ["`--output` must name a folder"]),
    ("demo -o /proc/x", ["demo", "-o", "/proc/x"], _setup_none, ["`--output`", "proc"]),
    ("demo -o empty", ["demo", "-o", ""], _setup_none, ["`--output` must name a folder"]),
    ("-o without a value", [*F, "-o"], _setup_none, ["'-o' requires an argument"]),
    # --- configuration files ------------------------------------------------------------------
    ("/dev/zero", ["frf", "/dev/zero"], _setup_none, ["'/dev/zero' is a character device"]),
    ("/dev/null", ["frf", "/dev/null"], _setup_none, ["'/dev/null' is a character device"]),
    ("symlink to /dev/zero", ["frf", "zero.toml"], _link_to_zero, ["'zero.toml' is a character device"]),
    ("named pipe", ["frf", "pipe.toml"], _fifo, ["'pipe.toml' is a named pipe"]),
    ("over 1 MiB", ["frf", "big.toml"], _big, ["'big.toml' has 1048579 bytes", "limit of 1048576"]),
    ("a folder", ["frf", "folder.toml"], _subdir, ["'folder.toml' is a directory"]),
    ("missing", ["frf", "missing.toml"], _setup_none, ["'missing.toml' does not exist"]),
    ("not UTF-8", ["frf", "bin.toml"], _binary, ["'bin.toml' is not UTF-8"]),
    ("empty file", ["frf", "empty.toml"], _empty, ["empty.toml", "`model` is missing"]),
    ("/proc/version", ["frf", "/proc/version"], _setup_none, ["/proc/version is not valid TOML"]),
    # --- options --------------------------------------------------------------------------------
    ("--harmonics 10^20", [*F, "--harmonics", "99999999999999999999"], _setup_none, ["`--harmonics` must be <="]),
    ("--harmonics 10000", [*F, "--harmonics", "10000"], _setup_none, ["`--harmonics` must be <="]),
    ("--harmonics empty", [*F, "--harmonics", ""], _setup_none, ["'--harmonics'", "not a valid integer"]),
    ("--omega-max 1e300", [*F, "--omega-max", "1e300"], _setup_none, ["`--omega-max`"]),
    ("--omega-min 1e-300", [*F, "--omega-min", "1e-300"], _setup_none, ["`--omega-min`"]),
    ("--omega-min -1", [*F, "--omega-min", "-1"], _setup_none, ["`--omega-min` must be > 0"]),
    ("--subharmonics=yes", [*F, "--subharmonics=yes"], _setup_none, ["'--subharmonics' does not take a value"]),
    ("sweep --points 10^9", [*S, "--points", "1000000000"], _setup_none, ["`--points` must be <="]),
    ("sweep --points 1", [*S, "--points", "1"], _setup_none, ["`--points` must be an integer >= 2"]),
    ("sweep --workers 0", [*S, "--workers", "0"], _setup_none, ["`--workers` must be an integer >= 1"]),
    ("sweep --workers 10^6", [*S, "--workers", "1000000"], _setup_none, ["`--workers` must be <="]),
    ("sweep without --direction", ["sweep", "case.toml"], _setup_none, ["`--direction` is required"]),
    ("sweep --direction sideways", ["sweep", "case.toml", "--direction", "sideways"], _setup_none,
     ["'--direction'", "'sideways'"]),
    ("orbit --omega 1e-6", ["orbit", "case.toml", "--omega", "1e-6"], _setup_none, ["`--omega` must be >="]),
    ("orbit --omega 0", ["orbit", "case.toml", "--omega", "0"], _setup_none, ["`--omega` must be a finite"]),
    ("orbit --omega nan", ["orbit", "case.toml", "--omega", "nan"], _setup_none, ["`--omega` must be a finite"]),
    ("orbit --period 9", [*O, "--period", "9"], _setup_none, ["`--period` must be an integer 1 … 8"]),
    ("compare --at abc", [*C, "--at", "abc"], _setup_none, ["`--at` must hold numbers"]),
    ("compare --at outside", [*C, "--at", "99"], _setup_none, ["`--at` frequencies must be finite and within"]),
    ("compare --at empty item", [*C, "--at", "0.6,,0.7"], _setup_none, ["`--at` must be a comma-separated list"]),
    ("unknown option", [*F, "--bogus"], _setup_none, ["No such option", "--bogus"]),
    ("unknown command", ["simulate", "case.toml"], _setup_none, ["No such command 'simulate'"]),
    ("-v with a bad option", ["frf", "-v", "case.toml", "--harmonics", "0"], _setup_none, ["`--harmonics`"]),
]


@pytest.fixture
def no_solver(monkeypatch: pytest.MonkeyPatch) -> None:
    """Importing the solver fails: a refusal must come before it."""
    monkeypatch.setitem(sys.modules, "rattle.analysis", None)


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize(("args", "setup", "fragments"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_hostile_input_is_refused(tmp_path: Path, args: list[str], setup: Callable[[Path], None],
                                  fragments: list[str]) -> None:
    if sys.platform != "linux" and any(a.startswith(("/proc", "/sys", "/dev")) for a in args):
        pytest.skip("Linux paths")
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    setup(tmp_path)
    before = sorted(os.listdir(tmp_path))
    result = invoke(args, tmp_path)
    assert_bad_input(result, *fragments)
    assert sorted(os.listdir(tmp_path)) == before  # nothing written, no rattle-out


def test_non_writable_output_is_refused(tmp_path: Path, no_solver: None, monkeypatch: pytest.MonkeyPatch) -> None:
    """As root every folder is writable to os.access, so the rule is exercised with os.access
    answering as for an ordinary user."""
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    (tmp_path / "locked").mkdir()
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, mode, **kw: False if str(p).endswith("locked") else real(p, mode, **kw))
    result = invoke(["frf", "case.toml", "-o", "locked/out"], tmp_path)
    assert_bad_input(result, "`--output` 'locked/out': no permission to write in")
    assert list((tmp_path / "locked").iterdir()) == []


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root may write anywhere")
def test_non_writable_output_is_refused_for_real(tmp_path: Path, no_solver: None) -> None:
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        assert_bad_input(invoke(["frf", "case.toml", "-o", "locked/out"], tmp_path), "`--output`", "no permission")
    finally:
        locked.chmod(0o700)


# --------------------------------------------------------------------------------------------
# The real entry point with scipy and matplotlib made unimportable: refusals never need them
# --------------------------------------------------------------------------------------------
_BLOCKED = (
    "import sys\n"
    "for name in ('scipy', 'matplotlib', 'rattle.analysis', 'rattle.continuation', 'rattle.hb'):\n"
    "    sys.modules[name] = None\n"
    "from rattle.cli.main import main\n"
    "main(sys.argv[1:])\n"
)

SUBPROCESS_CASES = [
    ("help", ["--help"], 0, "Usage: rattle"),
    ("version", ["--version"], 0, "rattle "),
    ("frf help", ["frf", "--help"], 0, "Usage: rattle frf"),
    ("frf version", ["frf", "--version"], 0, "rattle "),
    ("bad option", ["frf", "case.toml", "--harmonics", "0"], 2, "rattle: error: `--harmonics`"),
    ("bad value", ["frf", "bad.toml"], 2, "rattle: error: bad.toml: `model.inertia`"),
    ("bad output", ["frf", "case.toml", "-o", "/proc/x"], 2, "rattle: error: `--output` '/proc/x'"),
    ("/dev/zero", ["frf", "/dev/zero"], 2, "rattle: error: configuration file '/dev/zero'"),
]


@pytest.mark.parametrize(("args", "status", "start"), [c[1:] for c in SUBPROCESS_CASES],
                         ids=[c[0] for c in SUBPROCESS_CASES])
def test_front_door_needs_no_numerics(tmp_path: Path, args: list[str], status: int, start: str) -> None:
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    (tmp_path / "bad.toml").write_text(FAST.replace("inertia = 1.0", "inertia = -1.0"), encoding="utf-8")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    proc = subprocess.run([sys.executable, "-c", _BLOCKED, *args], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == status, proc.stderr
    text = proc.stdout if status == 0 else proc.stderr
    assert text.startswith(start), text
    if status:
        assert len(proc.stderr.strip().splitlines()) == 1 and proc.stdout == ""
    assert sorted(os.listdir(tmp_path)) == ["bad.toml", "case.toml"]


def test_importing_rattle_and_the_cli_loads_no_numerics() -> None:
    code = (
        "import sys, rattle, rattle.cli.main\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('scipy', 'matplotlib') or m in "
        "('rattle.analysis', 'rattle.hb', 'rattle.continuation', 'rattle.timeint', 'rattle.plotting'))\n"
        "print(heavy)\n"
        "from rattle import frequency_response, Model, __version__\n"
        "assert callable(frequency_response) and rattle.reference_case().k == 1.0 and __version__\n"
        "assert set(rattle.__all__) <= set(dir(rattle))\n"
    )
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
