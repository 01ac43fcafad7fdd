"""Adversarial library cases of issue 28: impossible sizes and targets raise a RattleError
subclass (or ValueError/TypeError) naming the argument, before allocating; the reading bounds
(TOML nesting and dotted keys, CSV records, NUL bytes) refuse at once; a progress callback that
raises is named and leaves nothing half-written; scheduler addresses are checked without a hang.
The command line's cases are in ``tests/test_adversarial_cli.py``.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import signal
import socket
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import rattle
import rattle.maps._map as map_module
from rattle import ConfigError, RattleError
from rattle.engines._dask import DaskEngine, check_scheduler_address
from rattle.files import (
    MAX_KEY_PARTS, MAX_TOML_DEPTH, OutputSet, WriteError, atomic_write_text, check_toml_bounds, csv_rows, read_toml,
    write_csv,
)
from rattle.maps import CallbackError, CellResult
from _cases import clutch_toml  # type: ignore[import-not-found]
from _fake_map import synthetic_cell  # type: ignore[import-not-found]


@contextlib.contextmanager
def bounded(seconds: float) -> Iterator[None]:
    def expire(_signum: int, _frame: object) -> None:
        raise TimeoutError(f"no answer within {seconds} s: a hang")

    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@pytest.fixture(scope="module")
def frf():
    return rattle.frequency_response(rattle.reference_case(), omega=(0.5, 0.52), harmonics=8)


@pytest.fixture(scope="module")
def orbit():
    return rattle.periodic_orbit(rattle.reference_case(), 0.51, harmonics=8)


# --------------------------------------------------------------------------------------------
# Time histories: sizes refused before allocating
# --------------------------------------------------------------------------------------------
HISTORY = [
    ("samples 1e12 int", {"samples": 10**12}, ValueError, "`samples`"),
    ("samples 1e12 float", {"samples": 1e12}, TypeError, "`samples` must be an integer"),
    ("samples 2**63", {"samples": 2**63}, ValueError, "`samples`"),
    ("samples 10**40", {"samples": 10**40}, ValueError, "`samples`"),
    ("samples numpy huge", {"samples": np.int64(2**40)}, ValueError, "`samples`"),
    ("samples 0", {"samples": 0}, ValueError, "`samples` must be an integer >= 2"),
    ("samples -1", {"samples": -1}, ValueError, "`samples` must be an integer >= 2"),
    ("samples 1", {"samples": 1}, ValueError, "`samples` must be an integer >= 2"),
    ("samples text", {"samples": "512"}, TypeError, "`samples`"),
    ("samples None", {"samples": None}, TypeError, "`samples`"),
    ("samples bool", {"samples": True}, TypeError, "`samples`"),
    ("samples nan", {"samples": float("nan")}, TypeError, "`samples`"),
    ("periods 1e12", {"periods": 10**12}, ValueError, "`periods`"),
    ("periods 0", {"periods": 0}, ValueError, "`periods`"),
    ("periods float", {"periods": 2.0}, TypeError, "`periods`"),
    ("product too large", {"samples": 10**5, "periods": 10**4}, ValueError, "more than the limit"),
]


@pytest.mark.parametrize(("kwargs", "kind", "fragment"), [c[1:] for c in HISTORY], ids=[c[0] for c in HISTORY])
def test_frequency_response_time_history_bounds(frf, kwargs, kind, fragment) -> None:
    with bounded(10), pytest.raises(kind, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        frf.time_history(0, **kwargs)


@pytest.mark.parametrize(("kwargs", "kind", "fragment"),
                         [c[1:] for c in HISTORY if "periods" not in c[1] and c[0] not in ("samples 1e12 float",
                                                                                            "samples text",
                                                                                            "samples None", "samples nan")],
                         ids=[c[0] for c in HISTORY if "periods" not in c[1] and c[0] not in (
                             "samples 1e12 float", "samples text", "samples None", "samples nan")])
def test_orbit_time_history_bounds(orbit, kwargs, kind, fragment) -> None:
    with bounded(10), pytest.raises((ValueError, TypeError), match="`samples`"):
        orbit.time_history(**kwargs)


def test_time_history_within_the_bounds_works(frf) -> None:
    h = frf.time_history(0, samples=64, periods=2)
    assert h["t"].size == 129 and np.all(np.isfinite(h["delta"]))


@pytest.mark.parametrize("index", ["0", 1.0, None, True])
def test_time_history_index_of_the_wrong_type(frf, index) -> None:
    with pytest.raises(TypeError, match="`index`"):
        frf.time_history(index)


# --------------------------------------------------------------------------------------------
# Writes into impossible places: WriteError (a RattleError and an OSError) naming the path
# --------------------------------------------------------------------------------------------
TARGETS = [
    ("/proc", "/proc/rattle-test.csv", "ENOENT"),
    ("/proc/self", "/proc/self/rattle-test.csv", ""),
    ("/sys", "/sys/rattle-test.csv", ""),
    ("missing folder", "{tmp}/missing/frf.csv", "does not exist"),
    ("missing deep folder", "{tmp}/a/b/c/frf.csv", "does not exist"),
    ("a file as folder", "{tmp}/afile/frf.csv", "is not a folder"),
    ("a folder as the file", "{tmp}/adir", "EISDIR"),
]


def _target(tmp_path: Path, text: str) -> str:
    (tmp_path / "afile").write_text("x")
    (tmp_path / "adir").mkdir(exist_ok=True)
    return text.replace("{tmp}", str(tmp_path))


@pytest.mark.parametrize("writer", ["frf.to_csv", "write_csv", "atomic_write_text", "map.to_csv"])
@pytest.mark.parametrize(("target", "fragment"), [c[1:] for c in TARGETS], ids=[c[0] for c in TARGETS])
def test_a_write_into_an_impossible_place_names_it(tmp_path: Path, frf, writer: str, target: str,
                                                  fragment: str) -> None:
    path = _target(tmp_path, target)
    before = sorted(os.listdir(tmp_path))
    with bounded(10), pytest.raises(WriteError) as info:
        if writer == "frf.to_csv":
            frf.to_csv(path)
        elif writer == "write_csv":
            write_csv(path, {"a": [1.0]}, ["a"])
        elif writer == "atomic_write_text":
            atomic_write_text(path, "x")
        else:
            from _fake_map import synthetic_map  # type: ignore[import-not-found]

            synthetic_map(points=5).to_csv(path)
    assert isinstance(info.value, RattleError) and isinstance(info.value, OSError)
    message = str(info.value)
    assert repr(path) in message and "[Errno" in message and fragment in message, message
    assert "\n" not in message
    assert sorted(os.listdir(tmp_path)) == before


@pytest.mark.parametrize("writer", ["frf.to_csv", "write_csv", "atomic_write_text", "OutputSet"])
def test_a_nul_byte_in_a_target_is_refused(tmp_path: Path, frf, writer: str) -> None:
    path = str(tmp_path / "fr\x00f.csv")
    with pytest.raises(ConfigError, match="NUL byte"):
        if writer == "frf.to_csv":
            frf.to_csv(path)
        elif writer == "write_csv":
            write_csv(path, {"a": [1.0]}, ["a"])
        elif writer == "atomic_write_text":
            atomic_write_text(path, "x")
        else:
            OutputSet(path, ["frf.csv"])
    assert os.listdir(tmp_path) == []


# --------------------------------------------------------------------------------------------
# Reading bounds in the library: read_toml / Model.from_toml / check_toml_bounds / csv_rows
# --------------------------------------------------------------------------------------------
BASE = clutch_toml((0.5, 0.8), 8)
TOML_TEXTS = [
    *[(f"array {d} deep", "x = " + "[" * d + "]" * d, "nest more than") for d in (33, 64, 999, 10_000, 400_000)],
    *[(f"inline {d} deep", "x = " + "{a = " * d + "1" + "}" * d, "nest more than") for d in (33, 2000, 100_000)],
    *[(f"dotted {n}", ".".join(["a"] * n) + " = 1", "parts") for n in (65, 1000, 4000, 10_000, 300_000)],
    *[(f"header {n}", "[" + ".".join(["a"] * n) + "]", "parts") for n in (65, 5000)],
    ("array of tables header", "[[" + ".".join(["a"] * 100) + "]]", "parts"),
]


@pytest.mark.parametrize("via", ["check_toml_bounds", "read_toml", "Model.from_toml", "load_config"])
@pytest.mark.parametrize(("text", "fragment"), [c[1:] for c in TOML_TEXTS], ids=[c[0] for c in TOML_TEXTS])
def test_toml_bounds_refuse_at_once(tmp_path: Path, via: str, text: str, fragment: str) -> None:
    path = tmp_path / "case.toml"
    path.write_text(text, encoding="utf-8")
    t0 = time.perf_counter()
    with bounded(20), pytest.raises(ConfigError, match=fragment) as info:
        if via == "check_toml_bounds":
            check_toml_bounds(text, "case.toml")
        elif via == "read_toml":
            read_toml(path)
        elif via == "Model.from_toml":
            rattle.Model.from_toml(path)
        else:
            from rattle.io import load_config

            load_config(path)
    assert "case.toml" in str(info.value) and "line 1" in str(info.value)
    assert time.perf_counter() - t0 < 20  # bounded above; the measured times are in the report


def test_the_bounds_are_what_the_messages_say() -> None:
    check_toml_bounds("x = " + "[" * MAX_TOML_DEPTH + "]" * MAX_TOML_DEPTH)
    check_toml_bounds(".".join(["a"] * MAX_KEY_PARTS) + " = 1")
    with pytest.raises(ConfigError):
        check_toml_bounds(".".join(["a"] * (MAX_KEY_PARTS + 1)) + " = 1")


def test_a_valid_case_passes_the_bounds() -> None:
    check_toml_bounds(BASE)
    for example in Path(__file__).resolve().parents[1].joinpath("examples").glob("*.toml"):
        check_toml_bounds(example.read_text(encoding="utf-8"), example.name)


CSV_TEXTS = [
    ("field 200 KiB", "a,b\n1," + "9" * 200_000 + "\n", "line 2", "131072"),
    ("field 1 MiB quoted", 'a,b\n1,"' + "9" * (1 << 20) + '"\n', "line 2", "131072"),
    ("first line", "x" * 200_000 + "\n", "line 1", "131072"),
    ("unclosed quote", 'a,b\n1,"' + "9" * 200_000, "line ", "131072"),
]


@pytest.mark.parametrize(("text", "line", "rule"), [c[1:] for c in CSV_TEXTS], ids=[c[0] for c in CSV_TEXTS])
def test_csv_rows_refuse_naming_the_line(text: str, line: str, rule: str) -> None:
    with bounded(10), pytest.raises(ConfigError, match=rule) as info:
        csv_rows(text)
    assert str(info.value).startswith(line)


def test_csv_rows_read_an_ordinary_table() -> None:
    assert csv_rows("a, b\n\n1,2\n") == [(1, ["a", "b"]), (2, []), (3, ["1", "2"])]


@pytest.mark.parametrize("reader", ["read_toml", "Model.from_toml", "read_measured_csv", "read_path_csv"])
def test_a_nul_byte_in_an_input_path_is_refused(tmp_path: Path, reader: str) -> None:
    from rattle.io import read_measured_csv
    from rattle.io._paths import read_path_csv

    path = str(tmp_path / "ca\x00se.toml")
    with bounded(10), pytest.raises(ConfigError, match="NUL byte"):
        {"read_toml": read_toml, "Model.from_toml": rattle.Model.from_toml,
         "read_measured_csv": read_measured_csv, "read_path_csv": lambda p: read_path_csv(p, "delta")}[reader](path)


# --------------------------------------------------------------------------------------------
# A progress callback that raises: named, nothing half-written
# --------------------------------------------------------------------------------------------
@pytest.fixture
def fake_cells(monkeypatch: pytest.MonkeyPatch) -> None:
    def compute(task: dict) -> dict:
        grid = np.linspace(*task["omega"], task["omega_points"])
        return synthetic_cell(task["values"], grid).to_dict()

    monkeypatch.setattr(map_module, "compute_cell", compute)


@pytest.mark.usefixtures("fake_cells")
@pytest.mark.parametrize("when", [0, 1, 2])
@pytest.mark.parametrize("error", [RuntimeError, ValueError, KeyError, ZeroDivisionError])
def test_a_progress_callback_that_raises_is_named(tmp_path: Path, when: int, error: type) -> None:
    calls: list[int] = []

    def progress(done: int, total: int, resumed: int) -> None:
        calls.append(done)
        if len(calls) > when:
            raise error("the bar broke")

    with bounded(30), pytest.raises(CallbackError, match="`progress` raised") as info:
        rattle.response_map(rattle.reference_case(), {"alpha": [0.1, 0.2, 0.3]}, omega=(0.5, 0.8), omega_points=6,
                            harmonics=8, engine="serial", store=tmp_path, progress=progress)
    assert isinstance(info.value, RattleError) and isinstance(info.value.__cause__, error)
    parts = list((tmp_path / "map.parts").glob("*.json")) if (tmp_path / "map.parts").exists() else []
    assert len(parts) == when  # every part stored is whole, none beyond the failure
    for part in parts:
        CellResult.from_dict(json.loads(part.read_text())["result"])
    assert not [p for p in (tmp_path / "map.parts").iterdir() if p.name.startswith(".")] if parts else True


@pytest.mark.parametrize("progress", ["bar", 3, object()])
def test_a_progress_that_is_not_callable_is_refused(tmp_path: Path, progress) -> None:
    with pytest.raises(TypeError, match="`progress`"):
        rattle.response_map(rattle.reference_case(), {"alpha": [0.1]}, omega=(0.5, 0.8), omega_points=6,
                            harmonics=8, engine="serial", progress=progress)


# --------------------------------------------------------------------------------------------
# Scheduler addresses and timeouts
# --------------------------------------------------------------------------------------------
ADDRESSES = [
    "", " ", "garbage", "tcp://", "tcp://host", "tcp://host:", "tcp://host:-1", "tcp://host:65536", "tcp://host:1e3",
    "gopher://h:70", "udp://127.0.0.1:8786", "http://127.0.0.1:8786", "tcp://a b:8786", "tcp://h\n:8786",
    "tcp://h\x00:8786", "tcp:/127.0.0.1:8786", "tcp://127.0.0.1:8786/path",
]


@pytest.mark.parametrize("address", ADDRESSES)
def test_scheduler_addresses_refused_at_once(address: str) -> None:
    with bounded(5), pytest.raises(ConfigError, match="`--scheduler`"):
        check_scheduler_address(address, 2.0)


def test_a_closed_port_is_refused_at_once() -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with bounded(5), pytest.raises(ConfigError, match="connection refused"):
        check_scheduler_address(f"tcp://127.0.0.1:{port}", 2.0)


def test_a_silent_listener_is_refused_within_the_timeout() -> None:
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(1)
        with bounded(10), pytest.raises(ConfigError, match="within 0.5 s"):
            check_scheduler_address(f"tcp://127.0.0.1:{listener.getsockname()[1]}", 0.5)


@pytest.mark.parametrize("timeout", [0, -1, float("nan"), float("inf"), 1e9])
def test_dask_engine_timeout_bounds(timeout: float) -> None:
    with pytest.raises(ValueError, match="`timeout`"):
        DaskEngine("tcp://127.0.0.1:8786", timeout=timeout)


def test_errno_is_kept_on_write_errors(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError) as info:
        atomic_write_text(tmp_path / "missing" / "x.txt", "x")
    assert info.value.errno == errno.ENOENT and isinstance(info.value, WriteError)
