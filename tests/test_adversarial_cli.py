"""Adversarial command-line cases of issue 28 (faults and damaged state), in-process through
click's CliRunner: hostile files read with bounds before parsing (TOML nesting and dotted keys,
CSV fields, NUL bytes), schedulers that are not Dask, output sets that cannot be replaced or do
not fit. Every case: no traceback, no hang (each bounded by an alarm), one ``rattle: error:``
line, and the previous output set whole. Killed runs are in ``tests/test_adversarial_kill.py``,
the damaged map store in ``tests/maps/test_store_damage.py``, the library in
``tests/test_adversarial_api.py``.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import http.server
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

import rattle.cli.output as cli_output
import rattle.engines._dask as dask_engine
import rattle.files._atomic as atomic
from _cases import clutch_toml  # type: ignore[import-not-found]
from _cli_helpers import assert_bad_input, invoke  # type: ignore[import-not-found]

FAST = clutch_toml((0.5, 0.8), 8)
SLOWEST: list[tuple[float, str]] = []  # (seconds, case) of the refusals, for the report


@contextlib.contextmanager
def bounded(seconds: float, what: str = "") -> Iterator[None]:
    """Fail instead of hanging (SIGALRM); record how long the body took."""

    def expire(_signum: int, _frame: object) -> None:
        raise TimeoutError(f"no answer within {seconds} s: a hang")

    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    t0 = time.perf_counter()
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        SLOWEST.append((time.perf_counter() - t0, what))


@pytest.fixture
def no_solver(monkeypatch: pytest.MonkeyPatch) -> None:
    """Importing the solver fails: a refusal must come before it."""
    monkeypatch.setitem(sys.modules, "rattle.analysis", None)


def _listing(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


# --------------------------------------------------------------------------------------------
# TOML read with bounds: nesting depth and dotted-key length, before tomllib
# --------------------------------------------------------------------------------------------
def _nested_array(depth: int) -> str:
    return FAST.replace("amplitudes = [0.03]", "amplitudes = " + "[" * depth + "0.03" + "]" * depth)


def _nested_inline(depth: int) -> str:
    return FAST + "\n[extra]\nx = " + "{a = " * depth + "1" + "}" * depth + "\n"


def _mixed(depth: int) -> str:
    return FAST + "\n[extra]\nx = " + "[{a = " * (depth // 2) + "1" + "}]" * (depth // 2) + "\n"


def _dotted(parts: int) -> str:
    return FAST + "\n[extra]\n" + ".".join(["k"] * parts) + " = 1\n"


def _dotted_spaced(parts: int) -> str:
    return FAST + "\n[extra]\n" + " . ".join(["k"] * parts) + " = 1\n"


def _dotted_quoted(parts: int) -> str:
    return FAST + "\n[extra]\n" + ".".join(['"k"'] * parts) + " = 1\n"


def _dotted_header(parts: int) -> str:
    return FAST + "\n[" + ".".join(["t"] * parts) + "]\nx = 1\n"


def _dotted_inline(parts: int) -> str:
    return FAST + "\n[extra]\nx = {" + ".".join(["k"] * parts) + " = 1}\n"


def _unclosed_deep(depth: int) -> str:
    return FAST + "\n[extra]\nx = " + "[" * depth + "\n"


TOML_HOSTILE = [
    ("array 33 deep", _nested_array(33), "nest more than 32 levels"),
    ("array 100 deep", _nested_array(100), "nest more than 32 levels"),
    ("array 1000 deep", _nested_array(1000), "nest more than 32 levels"),
    ("array 200 000 deep", _nested_array(200_000), "nest more than 32 levels"),
    ("inline tables 40 deep", _nested_inline(40), "nest more than 32 levels"),
    ("inline tables 5000 deep", _nested_inline(5000), "nest more than 32 levels"),
    ("mixed 5000 deep", _mixed(5000), "nest more than 32 levels"),
    ("unclosed 100 000 deep", _unclosed_deep(100_000), "nest more than 32 levels"),
    ("dotted key 65 parts", _dotted(65), "more than 64 parts"),
    ("dotted key 4 000 parts", _dotted(4000), "more than 64 parts"),
    ("dotted key 100 000 parts", _dotted(100_000), "more than 64 parts"),
    ("dotted key spaced 5000", _dotted_spaced(5000), "more than 64 parts"),
    ("dotted key quoted 5000", _dotted_quoted(5000), "more than 64 parts"),
    ("dotted header 5000", _dotted_header(5000), "more than 64 parts"),
    ("dotted inline key 5000", _dotted_inline(5000), "more than 64 parts"),
]
TOML_COMMANDS = {
    "frf": ["frf", "case.toml"],
    "sweep": ["sweep", "case.toml", "--direction", "up"],
    "orbit": ["orbit", "case.toml", "--omega", "0.6"],
    "compare": ["compare", "case.toml"],
    "map": ["map", "case.toml", "--vary", "alpha=0.1:0.2:2"],
}


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize("command", list(TOML_COMMANDS))
@pytest.mark.parametrize(("text", "fragment"), [c[1:] for c in TOML_HOSTILE], ids=[c[0] for c in TOML_HOSTILE])
def test_hostile_toml_is_refused_before_parsing(tmp_path: Path, command: str, text: str, fragment: str) -> None:
    (tmp_path / "case.toml").write_text(text, encoding="utf-8")
    before = _listing(tmp_path)
    with bounded(30, f"{command} toml {fragment}"):
        result = invoke(TOML_COMMANDS[command], tmp_path)
    assert_bad_input(result, "case.toml", fragment, "line ")
    assert _listing(tmp_path) == before


# Texts whose brackets and dots sit in strings and comments, or stay within the bounds: not
# refused by the bounds (refused later for their unknown key, as any unknown key is).
TOML_BENIGN = [
    ("brackets in a string", FAST + '\n[extra]\nx = "' + "[" * 500 + '"\n'),
    ("brackets in a literal string", FAST + "\n[extra]\nx = '" + "{" * 500 + "'\n"),
    ("brackets in a multi-line string", FAST + '\n[extra]\nx = """\n' + "[" * 500 + '\n"""\n'),
    ("brackets in a multi-line literal", FAST + "\n[extra]\nx = '''\n" + "[" * 500 + "\n'''\n"),
    ("brackets in a comment", FAST + "\n# " + "[" * 500 + "\n[extra]\nx = 1\n"),
    ("dots in a string", FAST + '\n[extra]\nx = "' + "." * 5000 + '"\n'),
    ("dots in a comment", FAST + "\n# " + "." * 5000 + "\n[extra]\nx = 1\n"),
    ("dots in a quoted key", FAST + '\n[extra]\n"' + "a." * 2000 + '" = 1\n'),
    ("array 32 deep", FAST + "\n[extra]\nx = " + "[" * 31 + "1" + "]" * 31 + "\n"),
    ("dotted key 63 parts", _dotted(63)),
    ("many floats", FAST + "\n[extra]\nx = [" + ", ".join(["1.5"] * 5000) + "]\n"),
    ("escaped quote in a string", FAST + '\n[extra]\nx = "a\\"[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["\n'),
]


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize("text", [c[1] for c in TOML_BENIGN], ids=[c[0] for c in TOML_BENIGN])
def test_brackets_and_dots_in_strings_are_not_counted(tmp_path: Path, text: str) -> None:
    (tmp_path / "case.toml").write_text(text, encoding="utf-8")
    with bounded(30, "benign toml"):
        result = invoke(["frf", "case.toml"], tmp_path)
    assert_bad_input(result, "`extra`")  # the unknown table, not a bound
    assert "levels" not in result.stderr and "parts" not in result.stderr


# --------------------------------------------------------------------------------------------
# CSV inputs: a field over 128 KiB or a NUL byte is one refusal naming the file and the line
# --------------------------------------------------------------------------------------------
BIG = "9" * (200 * 1024)
MEASURED_HOSTILE = [
    ("huge header field", f"omega,{BIG}\n0.6,1.0\n", "line 1", "131072"),
    ("huge value", f"omega,acc_p2p\n0.6,{BIG}\n", "line 2", "131072"),
    ("huge quoted value", f'omega,acc_p2p\n0.6,"{BIG}"\n', "line 2", "131072"),
    ("huge comment", f"# {BIG}\nomega,acc_p2p\n0.6,1.0\n", "line 1", "131072"),
    ("huge unclosed quote", f'omega,acc_p2p\n0.6,"{BIG}\n', "line ", "131072"),
    ("NUL in a value", "omega,acc_p2p\n0.6,1\x000\n", "line 2", "must be a number"),
    ("NUL in the header", "ome\x00ga,acc_p2p\n0.6,1.0\n", "line 1", "is not known"),
]


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize(("text", "line", "rule"), [c[1:] for c in MEASURED_HOSTILE], ids=[c[0] for c in MEASURED_HOSTILE])
def test_hostile_measured_csv_is_refused(tmp_path: Path, text: str, line: str, rule: str) -> None:
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    (tmp_path / "run.csv").write_text(text, encoding="utf-8")
    before = _listing(tmp_path)
    with bounded(30, f"measured {rule}"):
        result = invoke(["compare", "case.toml", "--measured", "run.csv"], tmp_path)
    assert_bad_input(result, "`--measured`", "run.csv", line, rule)
    assert _listing(tmp_path) == before


PATH_HOSTILE = [
    ("huge field", f"frequency_hz,magnitude,phase_deg\n10,{BIG},0\n", "line 2", "131072"),
    ("huge header", f"{BIG}\n10,1,0\n", "line 1", "131072"),
    ("huge quoted", f'frequency_hz,magnitude,phase_deg\n"{BIG}",1,0\n', "line 2", "131072"),
    ("NUL", "frequency_hz,magnitude,phase_deg\n10,1\x00,0\n", "line 2", ""),
]
PATH_COMMANDS = {"frf": ["frf", "case.toml"], "compare": ["compare", "case.toml"],
                 "map": ["map", "case.toml", "--vary", "alpha=0.1:0.2:2"]}


@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize("command", list(PATH_COMMANDS))
@pytest.mark.parametrize(("text", "line", "rule"), [c[1:] for c in PATH_HOSTILE], ids=[c[0] for c in PATH_HOSTILE])
def test_hostile_path_table_is_refused(tmp_path: Path, command: str, text: str, line: str, rule: str) -> None:
    config = FAST + '\n[[paths]]\nsource = "delta"\nfile = "path.csv"\n'
    (tmp_path / "case.toml").write_text(config, encoding="utf-8")
    (tmp_path / "path.csv").write_text(text, encoding="utf-8")
    before = _listing(tmp_path)
    with bounded(30, f"path table {rule}"):
        result = invoke(PATH_COMMANDS[command], tmp_path)
    assert_bad_input(result, "path.csv", line, rule)
    assert _listing(tmp_path) == before


# --------------------------------------------------------------------------------------------
# NUL bytes in a path
# --------------------------------------------------------------------------------------------
@pytest.mark.usefixtures("no_solver")
@pytest.mark.parametrize("command", list(PATH_COMMANDS))
def test_nul_in_a_path_table_name_is_refused(tmp_path: Path, command: str) -> None:
    (tmp_path / "case.toml").write_text(
        FAST + '\n[[paths]]\nsource = "delta"\nfile = "pa\\u0000th.csv"\n', encoding="utf-8")
    with bounded(30, "NUL path table"):
        result = invoke(PATH_COMMANDS[command], tmp_path)
    assert_bad_input(result, "NUL byte", "path table")


@pytest.mark.parametrize("args", [["frf", "ca\x00se.toml"], ["compare", "case.toml", "--measured", "ru\x00n.csv"]],
                         ids=["CONFIG", "--measured"])
def test_nul_in_a_path_argument_is_refused(tmp_path: Path, no_solver: None, args: list[str]) -> None:
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    assert_bad_input(invoke(args, tmp_path), "NUL")


def test_nul_in_the_output_folder_is_refused_and_nothing_written(tmp_path: Path) -> None:
    """The front door lets it through (see the report); the output set refuses it, exit 2."""
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    with bounded(120, "NUL -o"):
        result = invoke(["frf", "case.toml", "-o", "o\x00ut"], tmp_path)
    assert result.exit_code == 2, result.stderr
    assert result.stderr.strip().count("\n") == 0 and "NUL byte" in result.stderr
    assert _listing(tmp_path) == ["case.toml"]


# --------------------------------------------------------------------------------------------
# Schedulers that are not Dask: refused within the timeout, one line, never a hang
# --------------------------------------------------------------------------------------------
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


SCHEDULERS = [
    ("garbage", "garbage", "not a Dask scheduler address"),
    ("garbage with colon", "garbage:", "not a Dask scheduler address"),
    ("port text", "tcp://127.0.0.1:port", "not a Dask scheduler address"),
    ("port 0", "tcp://127.0.0.1:0", "not a Dask scheduler address"),
    ("port too large", "tcp://127.0.0.1:70000", "not a Dask scheduler address"),
    ("no host", "tcp://:8786", "not a Dask scheduler address"),
    ("unknown scheme", "foo://127.0.0.1:8786", "scheme 'foo'"),
    ("http scheme", "http://127.0.0.1:8786", "scheme 'http'"),
    ("file scheme", "file:///etc/passwd", "scheme 'file'"),
    ("spaces", "tcp://127.0.0.1 :8786", "spaces"),
    ("control character", "tcp://127.0.0.1:87\x0186", "control characters"),
    ("path in host", "tcp://a/b:8786", "not a Dask scheduler address"),
    ("closed port", "tcp://127.0.0.1:{free}", "connection refused"),
    ("closed port, no scheme", "127.0.0.1:{free}", "connection refused"),
    ("unknown host", "tcp://no-such-host.invalid:8786", "cannot be found"),
    ("ipv6 closed", "tcp://[::1]:{free}", "8786" if False else "no Dask scheduler answered"),
]


@pytest.mark.parametrize(("address", "fragment"), [c[1:] for c in SCHEDULERS], ids=[c[0] for c in SCHEDULERS])
def test_a_scheduler_that_is_not_dask_is_refused(tmp_path: Path, monkeypatch, address: str, fragment: str) -> None:
    monkeypatch.setattr(dask_engine, "CONNECT_TIMEOUT", 2.0)
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    address = address.replace("{free}", str(_free_port()))
    with bounded(60, f"scheduler {address!r}"):
        result = invoke(["map", "case.toml", "--vary", "alpha=0.1:0.2:2", "-q", "--scheduler", address], tmp_path)
    assert_bad_input(result, "`--scheduler`", fragment)
    assert not (tmp_path / "rattle-out" / "map.csv").exists()


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args: object) -> None:
        pass


@pytest.mark.parametrize("kind", ["http", "silent", "talks nonsense", "closes at once"])
def test_a_server_of_another_kind_is_refused_within_the_timeout(tmp_path: Path, monkeypatch, kind: str) -> None:
    """An HTTP server waits for a request (no handshake ever comes); a silent listener; one that
    sends bytes that are not Dask's; one that closes at once."""
    monkeypatch.setattr(dask_engine, "CONNECT_TIMEOUT", 1.0)
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    if kind == "http":
        server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Quiet)
        port = server.server_address[1]
        thread = threading.Thread(target=server.serve_forever, daemon=True)
        thread.start()
        stop = server.shutdown
    else:
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen(8)
        port = listener.getsockname()[1]
        held: list[socket.socket] = []

        def serve() -> None:
            with contextlib.suppress(OSError):
                while True:
                    conn, _ = listener.accept()
                    if kind == "talks nonsense":
                        conn.sendall(b"SSH-2.0-OpenSSH_9.0\r\n")
                    if kind == "closes at once":
                        conn.close()
                    else:
                        held.append(conn)

        threading.Thread(target=serve, daemon=True).start()

        def stop() -> None:
            listener.close()
            for c in held:
                c.close()
    try:
        with bounded(60, f"scheduler {kind}"):
            result = invoke(["map", "case.toml", "--vary", "alpha=0.1:0.2:2", "-q", "--scheduler",
                             f"tcp://127.0.0.1:{port}"], tmp_path)
    finally:
        stop()
    assert_bad_input(result, "`--scheduler`", "no Dask scheduler answered within 1 s")


# --------------------------------------------------------------------------------------------
# Output sets: a member that cannot be replaced, a full disk, no permission — exit 1, one line
# naming the path and the errno, the previous set whole
# --------------------------------------------------------------------------------------------
@pytest.fixture
def stub_figures(monkeypatch: pytest.MonkeyPatch) -> None:
    """PNG files written as a small stub (matplotlib is not what is tested here)."""

    def figure(_draw, path: Path) -> bool:
        path.write_bytes(b"\x89PNG stub " + os.urandom(8))
        return True

    monkeypatch.setattr(cli_output, "save_figure", figure)


def _digest(folder: Path, names: tuple[str, ...]) -> dict[str, str | None]:
    out: dict[str, str | None] = {}
    for n in names:
        p = folder / n
        out[n] = hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() and not p.is_symlink() else None
    return out


def _old_set(folder: Path, names: tuple[str, ...]) -> Path:
    """An earlier output set (its content does not matter, only that it stays whole)."""
    out = folder / "out"
    out.mkdir()
    for n in names:
        (out / n).write_bytes(f"old {n} ".encode() + os.urandom(8))
    return out


def _block_dir(path: Path) -> None:
    path.unlink()
    path.mkdir()


def _block_full_dir(path: Path) -> None:
    path.unlink()
    path.mkdir()
    (path / "mine.txt").write_text("keep")


def _block_fifo(path: Path) -> None:
    path.unlink()
    os.mkfifo(path)


BLOCKERS = {"folder": (_block_dir, "a folder", "EISDIR"), "folder with files": (_block_full_dir, "a folder", "EISDIR"),
            "FIFO": (_block_fifo, "named pipe", "EEXIST")}
SETS = {
    "frf": (["frf", "case.toml", "-o", "out"], ("frf.csv", "frf.json", "frf.png")),
    "orbit": (["orbit", "case.toml", "--omega", "0.6", "-o", "out"], ("orbit.csv", "orbit.json", "orbit.png")),
}


@pytest.mark.usefixtures("stub_figures")
@pytest.mark.parametrize("blocker", list(BLOCKERS))
@pytest.mark.parametrize("member", [0, 1, 2])
@pytest.mark.parametrize("command", list(SETS))
def test_a_member_that_cannot_be_replaced_leaves_the_set_whole(tmp_path: Path, command: str, member: int,
                                                               blocker: str) -> None:
    args, names = SETS[command]
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    out = _old_set(tmp_path, names)
    block, kind, code = BLOCKERS[blocker]
    block(out / names[member])
    before = _digest(out, names)
    listing = _listing(tmp_path)
    with bounded(120, f"{command} blocked {names[member]}"):
        result = invoke([*args, "--omega-max" if command == "frf" else "--harmonics", "0.7" if command == "frf" else "10"],
                        tmp_path)
    assert result.exit_code == 1, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rattle: error: cannot write"), result.stderr
    assert names[member] in lines[0] and kind in lines[0] and code in lines[0], lines[0]
    assert _digest(out, names) == before  # not one member replaced
    assert _listing(tmp_path) == listing  # no staging folder left


def _enospc_on(name: str):
    real = atomic._fsync

    def fsync(path: Path) -> None:
        if Path(path).name == name or Path(path).name.startswith(f".{name}."):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        real(path)

    return fsync


@pytest.mark.usefixtures("stub_figures")
@pytest.mark.parametrize("failing", ["frf.csv", "frf.json", "frf.png", ".commit.json"])
@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EACCES, errno.EIO, errno.EDQUOT])
def test_a_write_that_fails_leaves_the_previous_set(tmp_path: Path, monkeypatch, failing: str, code: int) -> None:
    """Simulated in-process: the write of one member (or of the commit journal) fails with the errno."""
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    names = SETS["frf"][1]
    out = _old_set(tmp_path, names)
    before = _digest(out, names)
    real_open = open
    real_fsync = atomic._fsync

    def failing_fsync(path: Path) -> None:
        if Path(path).name == failing:
            raise OSError(code, os.strerror(code), str(path))
        real_fsync(path)

    def failing_open(file, *args, **kw):  # the journal is written with open()
        if failing == ".commit.json" and str(file).endswith(".commit.json"):
            raise OSError(code, os.strerror(code), str(file))
        return real_open(file, *args, **kw)

    monkeypatch.setattr(atomic, "_fsync", failing_fsync)
    monkeypatch.setattr(atomic, "open", failing_open, raising=False)
    with bounded(120, f"errno {code}"):
        result = invoke(["frf", "case.toml", "-o", "out", "--omega-max", "0.7"], tmp_path)
    assert result.exit_code == 1, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and errno.errorcode[code] in lines[0] and "out" in lines[0], result.stderr
    assert _digest(out, names) == before
    assert not any(p.name.startswith(".rattle-staging-") for p in out.iterdir())


def test_a_rename_that_fails_half_way_is_undone(tmp_path: Path, monkeypatch, stub_figures: None) -> None:
    """The second rename of the commit fails (EPERM, as an immutable file gives): the first is undone."""
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    names = SETS["frf"][1]
    out = _old_set(tmp_path, names)
    before = _digest(out, names)
    real = os.replace
    calls = []

    def replace(src, dst, *a, **kw):
        if ".rattle-staging-" in str(src) and Path(dst).parent.name == "out":
            calls.append(dst)
            if len(calls) == 2:
                raise PermissionError(errno.EPERM, os.strerror(errno.EPERM), str(src), None, str(dst))
        return real(src, dst, *a, **kw)

    monkeypatch.setattr(atomic.os, "replace", replace)
    result = invoke(["frf", "case.toml", "-o", "out", "--omega-max", "0.7"], tmp_path)
    assert result.exit_code == 1 and "EPERM" in result.stderr, result.stderr
    assert _digest(out, names) == before
    assert not any(p.name.startswith(".rattle-staging-") for p in out.iterdir())


def _can_mount() -> bool:
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        return False
    with tempfile.TemporaryDirectory() as d:
        ok = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", d], capture_output=True).returncode == 0
        if ok:
            subprocess.run(["umount", d], capture_output=True)
        return ok


@contextlib.contextmanager
def small_disk(folder: Path, size: str = "200k") -> Iterator[Path]:
    folder.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)], check=True)
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


@pytest.mark.skipif(not _can_mount(), reason="needs root and mount (a real small file system)")
@pytest.mark.parametrize("command", ["frf", "compare"])
def test_a_full_disk_leaves_the_previous_set(tmp_path: Path, command: str) -> None:
    """A real 200 KiB tmpfs: the first run fits, a filler leaves too little for the second's
    staging; exit 1, ENOSPC named, the first set whole, no staging folder left."""
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    names = ("frf.csv", "frf.json", "frf.png") if command == "frf" else ("frf.csv", "sweep.csv", "compare.json",
                                                                          "compare.png")
    args = [command, str(tmp_path / "case.toml"), "-o", "disk/out"]
    if command == "compare":
        args += ["--points", "8"]
    with small_disk(tmp_path / "disk", "400k" if command == "compare" else "200k") as disk:
        with bounded(180, "first run"):
            first = invoke(args, tmp_path)
        assert first.exit_code == 0, first.stderr
        out = disk / "out"
        before = _digest(out, names)
        free = os.statvfs(disk).f_bavail * os.statvfs(disk).f_frsize
        (disk / "filler").write_bytes(b"x" * max(free - 8192, 0))
        with bounded(180, "full disk"):
            result = invoke(args, tmp_path)
        assert result.exit_code == 1, result.stderr
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and "ENOSPC" in lines[0] and "disk/out" in lines[0], result.stderr
        assert _digest(out, names) == before
        assert not any(p.name.startswith(".rattle-staging-") for p in out.iterdir())


@pytest.mark.skipif(not _can_mount(), reason="needs root and mount (a real small file system)")
def test_a_full_disk_under_a_map_keeps_the_finished_parts(tmp_path: Path, monkeypatch) -> None:
    """rattle map into a 200 KiB tmpfs that fills up while parts are stored: exit 1, one line
    naming the part and ENOSPC; the parts stored before are whole and read back by a rerun."""
    import numpy as np

    import rattle.cli.commands as commands
    import rattle.maps._map as map_module
    from _fake_map import synthetic_cell  # type: ignore[import-not-found]

    def compute(task: dict) -> dict:
        grid = np.linspace(*task["omega"], task["omega_points"])
        return synthetic_cell(task["values"], grid).to_dict()

    monkeypatch.setattr(map_module, "compute_cell", compute)
    monkeypatch.setattr(commands, "save_figure", lambda _d, p: bool(p.write_bytes(b"png")) or True)
    (tmp_path / "case.toml").write_text(FAST, encoding="utf-8")
    args = ["map", "case.toml", "--vary", "alpha=0:0.5:40", "--omega-points", "200", "--workers", "1", "-q",
            "-o", "disk/out"]
    with small_disk(tmp_path / "disk"):
        with bounded(120, "map on a full disk"):
            result = invoke(args, tmp_path)
        assert result.exit_code == 1, result.stderr
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and "ENOSPC" in lines[0] and "map.parts" in lines[0] and "resume" in lines[0], lines
        parts = sorted((tmp_path / "disk" / "out" / "map.parts").glob("*.json"))
        assert parts and all(p.read_text().endswith("\n") for p in parts)  # whole parts only
        assert not (tmp_path / "disk" / "out" / "map.csv").exists()
